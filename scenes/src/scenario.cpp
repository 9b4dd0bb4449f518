// The scenario registry, the Scenario driver, player inputs, and the scenes without game logic.
#include <algorithm>
#include <array>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

#include <detsim/fixed/math.hpp>
#include <detsim/fixed/quat.hpp>
#include <detsim/scenes/scenario.hpp>

#include "scenario_scenes.hpp"

namespace detsim {

namespace {

using namespace detsim::literals;

struct Entry {
  ScenarioInfo info;
  void (*build)(World&, const ScenarioParams&);
  void (*control)(World&, std::span<const PlayerInput>, const ScenarioParams&);
};

void build_pile_boxes(World& w, const ScenarioParams& p) {
  scenes_detail::build_pile(w, p, false);
}
void build_pile_spheres(World& w, const ScenarioParams& p) {
  scenes_detail::build_pile(w, p, true);
}

namespace scenes {

// The built-in scenarios, sorted by name.
constexpr std::array entries{
    Entry{{"arena",
           "2-64 player-controlled spheres pushing crates in a walled arena; RNG-driven crate "
           "spawns and kicks",
           3600, 2, 64, 2, 0, 0, true},
          scenes_detail::build_arena,
          scenes_detail::control_arena},
    Entry{{"bounce", "five spheres dropped from 5 m with restitution 0, 0.25, 0.5, 0.75 and 1", 600,
           0, 0, 0, 0, 0, false},
          scenes_detail::build_bounce,
          nullptr},
    Entry{{"bridge",
           "N planks (default 20) hinged end to end between two banks; a heavy frictionless box "
           "pushed across at 2 m/s",
           900, 0, 0, 0, 20, 100, false, "planks"},
          scenes_detail::build_bridge,
          scenes_detail::control_bridge},
    Entry{{"bullet_wall",
           "a 0.1 m sphere (CCD) at 1000 m/s towards a 0.2 m thick static wall 10 m away", 120, 0,
           0, 0, 0, 0, false},
          scenes_detail::build_bullet_wall,
          nullptr},
    Entry{{"chain",
           "N capsule links (default 30) on ball joints, hanging from a static block, released "
           "horizontally",
           1200, 0, 0, 0, 30, 1000, false, "links"},
          scenes_detail::build_chain,
          nullptr},
    Entry{{"characters",
           "N character controllers (default 8) walking, jumping, climbing stairs, kept off a "
           "steep slope, riding a sliding and a turning platform and pushing crates in a walled "
           "yard; inputs drawn from the RNG each second",
           600, 0, 0, 0, 8, 100, true, "characters"},
          scenes_detail::build_characters,
          scenes_detail::control_characters},
    Entry{{"cubes",
           "N small cubes (default 900, a 30 x 30 grid) resting on a plane, asleep until one of "
           "the 1-8 players' large cubes (stick: roll and push; jump) reaches them",
           600, 1, 8, 1, scenes_detail::cubes::default_count, scenes_detail::cubes::max_count, true,
           "small cubes"},
          scenes_detail::build_cubes,
          scenes_detail::control_cubes},
    Entry{{"dam_break",
           "a block of water N particles wide, 2N high and 2N deep (default 10: 4000 particles) "
           "released at one end of a tank with an obstacle",
           600, 0, 0, 0, 10, 16, false, "particles across the block"},
          scenes_detail::build_dam_break,
          nullptr},
    Entry{{"dominoes", "30 dominoes in a row; the first is tipped over", 600, 0, 0, 0, 0, 0, false},
          scenes_detail::build_dominoes,
          nullptr},
    Entry{{"drape",
           "an N x N sheet of cloth (default 24) falls over a sphere and a box on the ground", 600,
           0, 0, 0, 24, 100, false, "particles per side"},
          scenes_detail::build_drape,
          nullptr},
    Entry{{"flag",
           "a 12 x 8 cloth pinned along a pole, in gusts of wind drawn from the RNG each frame",
           600, 0, 0, 0, 0, 0, true},
          scenes_detail::build_flag,
          scenes_detail::control_flag},
    Entry{{"furniture",
           "N sets of compounds with offset centres of mass (default 4): a chair tipped back, a "
           "hammer leaning towards its head, an upright chair",
           600, 0, 0, 0, 4, 200, false, "sets"},
          scenes_detail::build_furniture,
          nullptr},
    Entry{{"jelly",
           "N soft cubes (default 4; 2 kg, 4 x 4 x 4 particles) dropped turning onto a flight of "
           "five stairs, where they land, wobble and come to rest",
           600, 0, 0, 0, 4, 50, false, "cubes"},
          scenes_detail::build_jelly,
          nullptr},
    Entry{{"level",
           "N each (default 8) of boxes, convex rocks, capsules and compound tables onto a "
           "triangle-mesh level with a ramp and stairs",
           600, 0, 0, 0, 8, 16, true, "bodies of each kind"},
          scenes_detail::build_level,
          nullptr},
    Entry{{"motors",
           "two cars driven by four hinge motors each: one on sphere wheels, one on capsule wheels",
           600, 0, 0, 0, 0, 0, false},
          scenes_detail::build_motors,
          nullptr},
    Entry{{"pendulum",
           "three 2 m pendulums started at 10 degrees: on a ball joint, a hinge and a distance rod",
           1200, 0, 0, 0, 0, 0, false},
          scenes_detail::build_pendulum,
          nullptr},
    Entry{{"pile_boxes",
           "N 1 m boxes (mass 1) on a cubic lattice, spacing 1.1 m, dropped on a plane "
           "(the scene benchmarked against Bullet)",
           600, 0, 0, 0, 1000, 100000, false},
          build_pile_boxes,
          nullptr},
    Entry{{"pile_spheres",
           "N spheres of radius 0.5 m (mass 1) on a cubic lattice, spacing 1.1 m, dropped on a "
           "plane (the scene benchmarked against Bullet)",
           600, 0, 0, 0, 1000, 100000, false},
          build_pile_spheres,
          nullptr},
    Entry{{"pyramid", "a pyramid of 1 m boxes on a plane, N rows (20 rows: 210 boxes)", 1200, 0, 0,
           0, 20, 100, false, "rows"},
          scenes_detail::build_pyramid,
          nullptr},
    Entry{{"ragdolls",
           "N ragdolls (default 4; ball, hinge and swing-twist joints) pushed down a flight of "
           "stairs",
           600, 0, 0, 0, 4, 100, true, "ragdolls"},
          scenes_detail::build_ragdolls,
          nullptr},
    Entry{{"rocks",
           "N random convex hulls (default 500; 12 RNG points each) dropped onto a heightfield of "
           "rolling hills",
           600, 0, 0, 0, 500, 5000, true, "rocks"},
          scenes_detail::build_rocks,
          nullptr},
    Entry{{"rope_bridge",
           "N planks (default 8) hung between two posts by short ropes at both sides; three "
           "crates dropped on the deck",
           600, 0, 0, 0, 8, 60, false, "planks"},
          scenes_detail::build_rope_bridge,
          nullptr},
    Entry{
        {"slope", "boxes of friction 0.2 to 1.0 on a 30-degree slope: those with tan 30 > mu slide",
         600, 0, 0, 0, 0, 0, false},
        scenes_detail::build_slope,
        nullptr},
    Entry{{"soccar",
           "car soccer: 2-8 players' cars (throttle, brake, steering, jump, boost) and a 30 kg "
           "ball in a walled 40 x 60 m arena with a goal at each end; a goal scores and resets "
           "the ball",
           3600, 2, 8, 4, 0, 0, true},
          scenes_detail::build_soccar,
          scenes_detail::control_soccar},
    Entry{{"spray",
           "RNG-driven spawns of spheres, boxes and capsules onto a rotating paddle and a "
           "moving platform (kinematic)",
           1200, 0, 0, 0, 0, 0, true},
          scenes_detail::build_spray,
          scenes_detail::control_spray},
    Entry{{"stack", "10 boxes of 1 m stacked on a plane", 1200, 0, 0, 0, 0, 0, false},
          scenes_detail::build_stack,
          nullptr},
    Entry{{"vehicles",
           "four cars (rear-driven, 1200 kg, sphere-cast suspension, magic-formula tires) "
           "driven by inputs drawn from the RNG each second over a walled lot with ramps and "
           "speed bumps",
           600, 0, 0, 0, 0, 0, true},
          scenes_detail::build_vehicles,
          scenes_detail::control_vehicles},
    Entry{{"wrecking_ball",
           "a 500 kg ball on a chain swings into a wall of bricks welded by breakable fixed joints",
           600, 0, 0, 0, 0, 0, false},
          scenes_detail::build_wrecking_ball,
          nullptr},
    Entry{{"wrecking_rope",
           "a 200 kg ball on a 6 m rope, released level with the pivot, swings into a stack of "
           "boxes",
           600, 0, 0, 0, 0, 0, false},
          scenes_detail::build_wrecking_rope,
          nullptr},
};

}  // namespace scenes

bool valid_scenario_name(std::string_view name) {
  return !name.empty() && name.size() <= 32 && std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
  });
}

}  // namespace

namespace scenes_detail {

/// A scenario the registry can create: a built-in (its strings are literals) or a game's own
/// (register_scenario: its strings are owned here and `info` views them).
struct ScenarioEntry {
  ScenarioInfo info;
  std::string name;
  std::string summary;
  std::string count_unit;
  WorldDef world;
  std::function<void(World&, const ScenarioParams&)> build;
  std::function<void(World&, std::span<const PlayerInput>, const ScenarioParams&)> control;
  std::function<void(World&, std::span<const std::uint8_t>, const ScenarioParams&)> control_bytes;
  std::function<void(std::uint64_t, std::uint64_t, std::uint32_t, std::span<std::uint8_t>)> script;
};

}  // namespace scenes_detail

namespace {

using scenes_detail::ScenarioEntry;

/// Every scenario: the built-ins, then the games registered in this process. Entries are only
/// appended (a deque keeps their addresses), so the info pointers and the entries Scenario objects
/// point to stay valid.
struct Registry {
  std::mutex mutex;
  std::deque<ScenarioEntry> entries;

  Registry() {
    for (const Entry& e : scenes::entries) {
      ScenarioEntry& added = entries.emplace_back();
      added.info = e.info;
      added.build = e.build;
      if (e.control != nullptr) added.control = e.control;
    }
  }
  const ScenarioEntry* find(std::string_view name) {
    const std::lock_guard lock(mutex);
    return find_locked(name);
  }
  const ScenarioEntry* find_locked(std::string_view name) const {
    for (const ScenarioEntry& e : entries)
      if (e.info.name == name) return &e;
    return nullptr;
  }
  std::vector<ScenarioInfo> infos() {
    const std::lock_guard lock(mutex);
    std::vector<ScenarioInfo> out;
    for (const ScenarioEntry& e : entries)
      out.push_back(e.info);
    std::sort(out.begin(), out.end(),
              [](const ScenarioInfo& a, const ScenarioInfo& b) { return a.name < b.name; });
    return out;
  }
};

Registry& registry() {
  static Registry r;
  return r;
}

std::string known_names() {
  std::string s;
  for (const ScenarioInfo& info : registry().infos()) {
    if (!s.empty()) s += ", ";
    s += info.name;
  }
  return s;
}

// SplitMix64's finaliser: a strong 64-bit mix, for scripted inputs.
constexpr std::uint64_t mix(std::uint64_t z) noexcept {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9U;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBU;
  return z ^ (z >> 31);
}

}  // namespace

std::vector<ScenarioInfo> scenario_list() {
  return registry().infos();
}

const ScenarioInfo* find_scenario(std::string_view name) noexcept {
  const ScenarioEntry* e = registry().find(name);
  return e == nullptr ? nullptr : &e->info;
}

Status register_scenario(const ScenarioDefinition& d) {
  const std::string which = "register_scenario \"" + d.name + "\": ";
  if (!valid_scenario_name(d.name))
    return Status::error(which + "a name is 1..32 characters of a-z, 0-9 and _");
  if (!d.build) return Status::error(which + "build is empty: it makes the scene at frame 0");
  if (d.default_frames == 0) return Status::error(which + "default_frames must be >= 1");
  if (d.max_players > max_scenario_players)
    return Status::error(which + "at most " + std::to_string(max_scenario_players) +
                         " players, got max_players " + std::to_string(d.max_players));
  if (d.min_players > d.max_players || d.default_players < d.min_players ||
      d.default_players > d.max_players)
    return Status::error(which +
                         "players must satisfy min_players <= default_players <= "
                         "max_players, got " +
                         std::to_string(d.min_players) + ", " + std::to_string(d.default_players) +
                         ", " + std::to_string(d.max_players));
  if (d.default_count > d.max_count)
    return Status::error(which + "default_count " + std::to_string(d.default_count) +
                         " exceeds max_count " + std::to_string(d.max_count));
  if (d.input_size > max_scenario_input_size)
    return Status::error(which + "input_size is at most " +
                         std::to_string(max_scenario_input_size) + " bytes, got " +
                         std::to_string(d.input_size));
  if (d.input_size == 0 && (d.control_bytes || d.script))
    return Status::error(which +
                         "control_bytes and script are for a game's own input: set input_size "
                         "(its bytes per player), or use control with PlayerInput");
  if (d.input_size > 0 && d.control)
    return Status::error(which + "a game with its own input (input_size " +
                         std::to_string(d.input_size) +
                         ") takes control_bytes, not control (which takes PlayerInput)");
  if (d.max_players > 0 && d.input_size == 0 && !d.control)
    return Status::error(which + "a scenario with players needs control: their inputs go there");
  if (d.max_players > 0 && d.input_size > 0 && !d.control_bytes)
    return Status::error(which +
                         "a scenario with players needs control_bytes: their inputs go "
                         "there");
  if (Status s = World::create(d.world).status(); !s)
    return Status::error(which + "world: " + s.message());
  Registry& r = registry();
  const std::string known = known_names();
  // One lock for the check and the insertion: two threads registering one name cannot both win.
  const std::lock_guard lock(r.mutex);
  if (r.find_locked(d.name) != nullptr)
    return Status::error(which + "a scenario of that name exists (known: " + known + ")");
  ScenarioEntry& e = r.entries.emplace_back();
  e.name = d.name;
  e.summary = d.summary;
  e.count_unit = d.count_unit;
  e.info =
      ScenarioInfo{e.name,
                   e.summary,
                   d.default_frames,
                   d.min_players,
                   d.max_players,
                   d.default_players,
                   d.default_count,
                   d.max_count,
                   d.uses_seed,
                   e.count_unit,
                   d.input_size == 0 ? std::uint32_t{PlayerInput::encoded_size} : d.input_size};
  e.world = d.world;
  e.build = d.build;
  e.control = d.control;
  e.control_bytes = d.control_bytes;
  e.script = d.script;
  return Status::success();
}

Expected<Scenario> Scenario::create(std::string_view name, const ScenarioParams& params) {
  const ScenarioEntry* e = registry().find(name);
  if (e == nullptr)
    return Status::error("unknown scenario '" + std::string(name) + "' (known: " + known_names() +
                         ")");
  const ScenarioInfo& info = e->info;
  ScenarioParams p = params;
  if (p.players == 0) p.players = info.default_players;
  if (p.players < info.min_players || p.players > info.max_players) {
    if (info.max_players == 0)
      return Status::error("scenario '" + std::string(name) + "' takes no players, got " +
                           std::to_string(p.players));
    return Status::error(
        "scenario '" + std::string(name) + "' takes " + std::to_string(info.min_players) + " to " +
        std::to_string(info.max_players) + " players, got " + std::to_string(p.players));
  }
  if (p.count == 0) p.count = info.default_count;
  if (p.count > info.max_count) {
    if (info.max_count == 0)
      return Status::error("scenario '" + std::string(name) + "' takes no body count, got " +
                           std::to_string(p.count));
    return Status::error("scenario '" + std::string(name) + "' takes 1 to " +
                         std::to_string(info.max_count) + " " + std::string(info.count_unit) +
                         ", got " + std::to_string(p.count));
  }
  WorldDef def = e->world;
  def.seed = p.seed;
  auto world = World::create(def);
  if (!world) return world.status();
  e->build(world.value(), p);
  return Scenario(*e, p, std::move(world.value()));
}

const ScenarioInfo& Scenario::info() const noexcept {
  return entry_->info;
}

void Scenario::step(std::span<const PlayerInput> inputs) {
  if (entry_->control) {
    std::array<PlayerInput, max_scenario_players> frame{};  // missing inputs are neutral
    const std::size_t n = std::min<std::size_t>({inputs.size(), params_.players, frame.size()});
    std::copy_n(inputs.begin(), n, frame.begin());
    entry_->control(world_, std::span<const PlayerInput>(frame.data(), params_.players), params_);
  } else if (entry_->control_bytes) {
    step_encoded({});
    return;
  }
  world_.step();
}

void Scenario::step_encoded(std::span<const std::uint8_t> inputs) {
  const std::size_t size = entry_->info.input_size;
  if (entry_->control_bytes) {
    std::array<std::uint8_t, max_scenario_players * max_scenario_input_size> frame{};
    const std::size_t used = std::size_t{params_.players} * size;
    std::copy_n(inputs.begin(), std::min(inputs.size(), used), frame.begin());
    entry_->control_bytes(world_, std::span<const std::uint8_t>(frame.data(), used), params_);
  } else if (entry_->control) {
    std::array<PlayerInput, max_scenario_players> frame{};
    for (std::uint32_t p = 0; p < params_.players; ++p) {
      std::array<std::uint8_t, PlayerInput::encoded_size> bytes{};  // missing: neutral
      const std::size_t at = std::size_t{p} * size;
      if (at < inputs.size())
        std::copy_n(inputs.begin() + static_cast<std::ptrdiff_t>(at),
                    std::min(size, inputs.size() - at), bytes.begin());
      frame[p] = decode_input(bytes);
    }
    entry_->control(world_, std::span<const PlayerInput>(frame.data(), params_.players), params_);
  }
  world_.step();
}

bool Scenario::takes_player_input() const noexcept {
  return !entry_->control_bytes;
}

void Scenario::scripted(std::uint64_t seed, std::uint64_t frame, std::uint32_t player,
                        std::span<std::uint8_t> out) const {
  if (entry_->script) {
    entry_->script(seed, frame, player, out);
    return;
  }
  if (!entry_->control_bytes) {
    std::array<std::uint8_t, PlayerInput::encoded_size> bytes{};
    encode_input(scripted_input(seed, frame, player), bytes);
    std::copy_n(bytes.begin(), std::min(out.size(), bytes.size()), out.begin());
    return;
  }
  // A game's own input without a script: a hash of (seed, player, decision), a decision every
  // quarter second, 8 bytes of it at a time.
  const std::uint64_t decision =
      mix(mix(seed ^ 0x13198A2E03707344U) ^ (std::uint64_t{player} << 48) ^ (frame / 15));
  for (std::size_t i = 0; i < out.size(); ++i) {
    const std::uint64_t word = mix(decision + i / 8);
    out[i] = static_cast<std::uint8_t>(word >> (8 * (i % 8)));
  }
}

BodyId Scenario::player_body(std::uint32_t player) const {
  if (player >= params_.players) return {};
  const std::uint64_t tag = scenes_detail::player_tag + player;
  for (const BodyId id : world_.body_ids()) {
    if (world_.body(id)->user_data == tag) return id;
  }
  return {};
}

PlayerInput scripted_input(std::uint64_t seed, std::uint64_t frame, std::uint32_t player) noexcept {
  // A player holds a decision for a quarter of a second (15 frames), like a person would, and
  // each decision is a hash of (seed, player, decision number): a pure function, no state.
  const std::uint64_t h =
      mix(mix(seed ^ 0x243F6A8885A308D3U) ^ (std::uint64_t{player} << 48) ^ (frame / 15));
  PlayerInput in;
  in.move_x = static_cast<std::int8_t>(static_cast<int>(h & 0xFFU) - 128);
  in.move_z = static_cast<std::int8_t>(static_cast<int>((h >> 8) & 0xFFU) - 128);
  // Buttons are pressed on the first frame of a decision only, 1 in 4 and 1 in 8 of the time.
  if (frame % 15 == 0) {
    if (((h >> 16) & 3U) == 0) in.buttons |= PlayerInput::jump;
    if (((h >> 18) & 7U) == 0) in.buttons |= PlayerInput::dash;
  }
  return in;
}

void encode_input(const PlayerInput& input,
                  std::span<std::uint8_t, PlayerInput::encoded_size> out) noexcept {
  out[0] = input.buttons;
  out[1] = static_cast<std::uint8_t>(input.move_x);
  out[2] = static_cast<std::uint8_t>(input.move_z);
}

PlayerInput decode_input(std::span<const std::uint8_t, PlayerInput::encoded_size> in) noexcept {
  return {in[0], static_cast<std::int8_t>(in[1]), static_cast<std::int8_t>(in[2])};
}

namespace scenes_detail {

namespace {

void add_ground(World& w, Fixed friction) {
  add(w, {.type = BodyType::static_body, .shape = Shape::plane(), .friction = friction});
}

// The smallest s with s^3 >= n (n >= 1).
std::uint32_t cube_side(std::uint32_t n) {
  std::uint32_t s = 1;
  while (std::uint64_t{s} * s * s < n)
    ++s;
  return s;
}

}  // namespace

void build_pile(World& w, const ScenarioParams& p, bool spheres) {
  add_ground(w, 0.5_fx);
  const std::uint32_t side = cube_side(p.count);
  const Fixed spacing = 1.1_fx;
  const auto centred = [&](std::uint32_t k) {
    return Fixed::from_int(static_cast<std::int32_t>(k) - static_cast<std::int32_t>(side / 2)) *
           spacing;
  };
  for (std::uint32_t i = 0; i < p.count; ++i) {
    const std::uint32_t x = i % side;
    const std::uint32_t z = (i / side) % side;
    const std::uint32_t y = i / (side * side);
    add(w, {.shape = spheres ? Shape::sphere(0.5_fx) : Shape::box({0.5_fx, 0.5_fx, 0.5_fx}),
            .position = {centred(x), 1_fx + Fixed::from_int(static_cast<std::int32_t>(y)) * spacing,
                         centred(z)},
            .mass = 1_fx,
            .friction = 0.5_fx,
            .restitution = 0_fx});
  }
}

void build_stack(World& w, const ScenarioParams&) {
  add_ground(w, 0.6_fx);
  for (int i = 0; i < 10; ++i) {
    add(w, {.shape = Shape::box({0.5_fx, 0.5_fx, 0.5_fx}),
            .position = {0_fx, 0.5_fx + Fixed::from_int(i), 0_fx}});
  }
}

void build_pyramid(World& w, const ScenarioParams& p) {
  add_ground(w, 0.6_fx);
  const int rows = static_cast<int>(p.count);
  for (int row = 0; row < rows; ++row) {
    const int n = rows - row;
    for (int i = 0; i < n; ++i) {
      // Row r is centred on x = 0: boxes at i - (n - 1) / 2, half a box in from the row below.
      const Fixed x = Fixed::from_int(2 * i - (n - 1)) / 2_fx;
      add(w, {.shape = Shape::box({0.5_fx, 0.5_fx, 0.5_fx}),
              .position = {x, 0.5_fx + Fixed::from_int(row), 0_fx}});
    }
  }
}

void build_dominoes(World& w, const ScenarioParams&) {
  add_ground(w, 0.6_fx);
  for (int i = 0; i < 30; ++i) {
    BodyDef d{.shape = Shape::box({0.1_fx, 0.5_fx, 0.25_fx}),
              .position = {Fixed::from_int(i) * 0.6_fx, 0.5_fx, 0_fx}};
    if (i == 0) {
      // The first one starts leaning 0.3 rad towards the others (turned about -z: its top moves
      // towards +x), on its bottom edge at x = 0.1: the centre sits at that edge plus the rotated
      // half diagonal (-0.1, 0.5) -> (-0.1 cos a + 0.5 sin a, 0.1 sin a + 0.5 cos a), lifted by
      // 1 mm so that it starts just clear of the ground.
      const Fixed angle = 0.3_fx;
      const Fixed c = cos(angle);
      const Fixed s = sin(angle);
      d.orientation = from_axis_angle({0_fx, 0_fx, -1_fx}, angle);
      d.position = {0.1_fx - 0.1_fx * c + 0.5_fx * s, 0.1_fx * s + 0.5_fx * c + 0.001_fx, 0_fx};
    }
    add(w, d);
  }
}

void build_bullet_wall(World& w, const ScenarioParams&) {
  add_ground(w, 0.6_fx);
  add(w, {.type = BodyType::static_body,
          .shape = Shape::box({0.1_fx, 1_fx, 1_fx}),
          .position = {10_fx, 1_fx, 0_fx}});
  add(w, {.shape = Shape::sphere(0.05_fx),
          .position = {0_fx, 1_fx, 0_fx},
          .linear_velocity = {1000_fx, 0_fx, 0_fx},
          .density = 7800_fx,  // steel
          .ccd = true});
}

void build_bounce(World& w, const ScenarioParams&) {
  add_ground(w, 0.6_fx);
  for (int i = 0; i < 5; ++i) {
    add(w, {.shape = Shape::sphere(0.25_fx),
            .position = {Fixed::from_int(i), 5_fx, 0_fx},
            .restitution = Fixed::from_int(i) / 4_fx});
  }
}

void build_slope(World& w, const ScenarioParams&) {
  add_ground(w, 0.6_fx);
  // A slab tilted 30 degrees about z; its surface normal is n = (-sin 30, cos 30, 0). Contact
  // friction is the geometric mean of the two bodies': the slab has friction 1 and each box mu^2,
  // so that the pairs have mu = 0.2, 0.4, 0.6, 0.8 and 1.0 against tan 30 = 0.577.
  const Quat tilt = from_axis_angle({0_fx, 0_fx, 1_fx}, Fixed::pi() / 6_fx);
  const Vec3 normal = rotate(tilt, Vec3{0_fx, 1_fx, 0_fx});
  const Vec3 along = rotate(tilt, Vec3{1_fx, 0_fx, 0_fx});
  const Vec3 centre{0_fx, 5_fx, 0_fx};
  add(w, {.type = BodyType::static_body,
          .shape = Shape::box({8_fx, 0.25_fx, 4_fx}),
          .position = centre,
          .orientation = tilt,
          .friction = 1_fx});
  for (int i = 0; i < 5; ++i) {
    const Fixed mu = Fixed::from_int(i + 1) / 5_fx;  // 0.2, 0.4, 0.6, 0.8, 1.0 (pair: sqrt)
    const Vec3 at = centre + normal * 0.501_fx + along * 3_fx +
                    Vec3{0_fx, 0_fx, Fixed::from_int(2 * i - 4) * 0.75_fx};
    add(w, {.shape = Shape::box({0.25_fx, 0.25_fx, 0.25_fx}),
            .position = at,
            .orientation = tilt,
            .friction = mu * mu});
  }
}

}  // namespace scenes_detail
}  // namespace detsim
