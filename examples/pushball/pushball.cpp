// The pushball scene and rules (pushball.hpp). Everything the rules read is in the World — the
// bodies and the game state — so the World's saved state is the whole game.
#include "pushball.hpp"

namespace pushball {

using namespace detsim::literals;
using detsim::BodyDef;
using detsim::BodyId;
using detsim::BodyType;
using detsim::Fixed;
using detsim::Shape;
using detsim::Vec3;
using detsim::World;

namespace {

void put(std::vector<std::uint8_t>& out, std::uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i)
    out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}

std::uint64_t get(std::span<const std::uint8_t> in, std::size_t at, int bytes) {
  std::uint64_t v = 0;
  for (int i = 0; i < bytes; ++i)
    if (at + static_cast<std::size_t>(i) < in.size())
      v |= std::uint64_t{in[at + static_cast<std::size_t>(i)]} << (8 * i);
  return v;
}

void wall(World& w, Vec3 half, Vec3 at) {
  BodyDef d;
  d.type = BodyType::static_body;
  d.shape = Shape::box(half);
  d.position = at;
  (void)w.create_body(d);
}

const Vec3 ball_start{0_fx, 0.5_fx, 0_fx};
Vec3 player_start(std::uint32_t p) {
  return {p == 0 ? -5_fx : 5_fx, 0.6_fx, 0_fx};
}

void place(World& w, BodyId id, Vec3 at) {
  (void)w.set_transform(id, at, {});
  (void)w.set_linear_velocity(id, {});
  (void)w.set_angular_velocity(id, {});
}

void build(World& w, const detsim::ScenarioParams&) {
  BodyDef ground;
  ground.type = BodyType::static_body;
  ground.shape = Shape::plane();
  (void)w.create_body(ground);
  // Side walls, the end walls beside the goal mouths, and each goal's back and sides.
  for (const Fixed z : {-8.5_fx, 8.5_fx})
    wall(w, {14_fx, 1_fx, 0.5_fx}, {0_fx, 1_fx, z});
  for (const Fixed x : {-10.5_fx, 10.5_fx}) {
    for (const Fixed z : {-5_fx, 5_fx})
      wall(w, {0.5_fx, 1_fx, 3_fx}, {x, 1_fx, z});
  }
  for (const Fixed x : {-13.5_fx, 13.5_fx})
    wall(w, {0.5_fx, 1_fx, 3_fx}, {x, 1_fx, 0_fx});
  for (const Fixed x : {-12_fx, 12_fx}) {
    for (const Fixed z : {-2.5_fx, 2.5_fx})
      wall(w, {1.5_fx, 1_fx, 0.5_fx}, {x, 1_fx, z});
  }
  BodyDef ball;
  ball.shape = Shape::sphere(0.5_fx);
  ball.position = ball_start;
  ball.mass = 1_fx;
  ball.user_data = ball_tag;
  (void)w.create_body(ball);
  for (std::uint32_t p = 0; p < 2; ++p) {
    BodyDef puck;
    puck.shape = Shape::sphere(0.6_fx);
    puck.position = player_start(p);
    puck.mass = 4_fx;
    puck.linear_damping = 0.5_fx;
    puck.user_data = player_tag + p;
    (void)w.create_body(puck);
  }
  (void)w.set_game_state(State{}.encode());
  const std::vector<detsim::GameField> fields = state_fields();
  (void)w.describe_game_state(fields);
}

void control(World& w, std::span<const std::uint8_t> inputs, const detsim::ScenarioParams&) {
  State s = state_of(w);
  const BodyId ball = find(w, ball_tag);
  if (s.kickoff > 0) {
    if (--s.kickoff == 0) {  // play resumes from the start positions
      place(w, ball, ball_start);
      for (std::uint32_t p = 0; p < 2; ++p)
        place(w, find(w, player_tag + p), player_start(p));
    }
  } else {
    for (std::uint32_t p = 0; p < 2 && (p + 1) * Input::size <= inputs.size(); ++p) {
      const BodyId puck = find(w, player_tag + p);
      const Input in = Input::decode(inputs.subspan(p * Input::size, Input::size));
      const Vec3 stick{Fixed::from_int(in.aim_x) / 32767_fx, 0_fx,
                       Fixed::from_int(in.aim_z) / 32767_fx};
      (void)w.apply_force(puck, stick * 40_fx);
      if (s.cooldown[p] > 0) {
        --s.cooldown[p];
      } else if ((in.buttons & Input::dash) != 0) {
        const Vec3 toward = stick == Vec3{} ? Vec3{p == 0 ? 1_fx : -1_fx, 0_fx, 0_fx} : stick;
        (void)w.apply_linear_impulse(puck, toward * 8_fx);
        s.cooldown[p] = dash_cooldown_frames;
      }
    }
    const Vec3 at = w.body(ball)->position;
    const bool in_mouth = detsim::abs(at.z) < goal_half_width;
    if (in_mouth && (at.x > goal_line || at.x < -goal_line)) {
      const std::uint8_t scorer = at.x > goal_line ? 1 : 2;
      ++s.score[scorer - 1];
      s.last_scorer = scorer;
      s.kickoff = kickoff_frames;
    }
  }
  (void)w.set_game_state(s.encode());
}

// SplitMix64's finaliser: the scripted player's decisions.
std::uint64_t mix(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9U;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBU;
  return z ^ (z >> 31);
}

}  // namespace

void Input::encode(std::span<std::uint8_t> out) const {
  out[0] = static_cast<std::uint8_t>(static_cast<std::uint16_t>(aim_x));
  out[1] = static_cast<std::uint8_t>(static_cast<std::uint16_t>(aim_x) >> 8);
  out[2] = static_cast<std::uint8_t>(static_cast<std::uint16_t>(aim_z));
  out[3] = static_cast<std::uint8_t>(static_cast<std::uint16_t>(aim_z) >> 8);
  out[4] = buttons;
}

Input Input::decode(std::span<const std::uint8_t> in) {
  const auto axis = [&](std::size_t at) {
    const auto raw = static_cast<std::uint16_t>(get(in, at, 2));
    // Two's complement; -32768 counts as -32767 so that every aim has an opposite.
    return static_cast<std::int16_t>(raw == 0x8000U ? -32767 : static_cast<std::int16_t>(raw));
  };
  return {axis(0), axis(2), static_cast<std::uint8_t>(get(in, 4, 1))};
}

std::vector<std::uint8_t> encode_frame(const Input& player1, const Input& player2) {
  std::vector<std::uint8_t> out(2 * Input::size);
  player1.encode(std::span<std::uint8_t>(out).first(Input::size));
  player2.encode(std::span<std::uint8_t>(out).subspan(Input::size));
  return out;
}

Input scripted(std::uint64_t seed, std::uint64_t frame, std::uint32_t player) {
  const std::uint64_t h =
      mix(mix(seed ^ 0x5C1A7B0E11D00DULL) ^ (std::uint64_t{player} << 48) ^ (frame / 15));
  Input in;
  in.aim_x = static_cast<std::int16_t>(static_cast<std::int32_t>(h & 0xFFFFU) - 32768);
  in.aim_z = static_cast<std::int16_t>(static_cast<std::int32_t>((h >> 16) & 0xFFFFU) - 32768);
  if (frame % 15 == 0 && ((h >> 32) & 3U) == 0) in.buttons = Input::dash;
  return in;
}

std::vector<std::uint8_t> State::encode() const {
  std::vector<std::uint8_t> out;
  put(out, score[0], 4);
  put(out, score[1], 4);
  put(out, cooldown[0], 2);
  put(out, cooldown[1], 2);
  put(out, kickoff, 2);
  put(out, last_scorer, 1);
  return out;
}

State State::decode(std::span<const std::uint8_t> bytes) {
  State s;
  s.score[0] = static_cast<std::uint32_t>(get(bytes, 0, 4));
  s.score[1] = static_cast<std::uint32_t>(get(bytes, 4, 4));
  s.cooldown[0] = static_cast<std::uint16_t>(get(bytes, 8, 2));
  s.cooldown[1] = static_cast<std::uint16_t>(get(bytes, 10, 2));
  s.kickoff = static_cast<std::uint16_t>(get(bytes, 12, 2));
  s.last_scorer = static_cast<std::uint8_t>(get(bytes, 14, 1));
  return s;
}

std::vector<detsim::GameField> state_fields() {
  using detsim::GameFieldType;
  return {{"score.player1", 0, GameFieldType::u32},    {"score.player2", 4, GameFieldType::u32},
          {"cooldown.player1", 8, GameFieldType::u16}, {"cooldown.player2", 10, GameFieldType::u16},
          {"kickoff", 12, GameFieldType::u16},         {"last_scorer", 14, GameFieldType::u8}};
}

detsim::ScenarioDefinition definition() {
  detsim::ScenarioDefinition d;
  d.name = "pushball";
  d.summary =
      "two pucks push a ball into goals; scores, dash cooldowns and kickoffs in the game state";
  d.default_frames = 3600;
  d.min_players = 2;
  d.max_players = 2;
  d.default_players = 2;
  d.uses_seed = false;
  d.build = build;
  d.input_size = Input::size;
  d.control_bytes = control;
  d.script = [](std::uint64_t seed, std::uint64_t frame, std::uint32_t player,
                std::span<std::uint8_t> out) { scripted(seed, frame, player).encode(out); };
  return d;
}

State state_of(const World& world) {
  return State::decode(world.game_state());
}

BodyId find(const World& world, std::uint64_t tag) {
  for (const BodyId id : world.body_ids())
    if (world.body(id)->user_data == tag) return id;
  return {};
}

}  // namespace pushball
