// The scenarios with game logic: `spray` (RNG-driven spawns, kinematic movers) and `arena`
// (player-controlled bodies and RNG events). Their per-frame logic reads the World only — its
// frame number, its bodies (found again by their user-data tags) and its RNG — so a saved World
// is a saved scenario.
#include <vector>

#include <detsim/fixed/math.hpp>

#include "scenario_scenes.hpp"

namespace detsim::scenes_detail {

namespace {

using namespace detsim::literals;

void add_wall(World& w, Vec3 half, Vec3 at) {
  add(w, {.type = BodyType::static_body, .shape = Shape::box(half), .position = at});
}

// The bodies carrying a tag in [tag, tag + 2^32), ascending by ID.
std::vector<BodyState> tagged(const World& w, std::uint64_t tag) {
  std::vector<BodyState> out;
  for (const BodyId id : w.body_ids()) {
    const BodyState b = w.body(id).value();
    if ((b.user_data >> 32) == (tag >> 32)) out.push_back(b);
  }
  return out;
}

// ---- spray ----

constexpr std::uint64_t spray_interval = 6;     // frames between spawns
constexpr std::size_t spray_capacity = 120;     // spawned bodies alive at most
constexpr std::uint64_t platform_period = 180;  // frames per platform sweep

Shape random_shape(Rng& rng) {
  const Fixed size = rng.uniform(0.15_fx, 0.4_fx);
  switch (rng.below(3)) {
    case 0:
      return Shape::sphere(size);
    case 1:
      return Shape::box({size, rng.uniform(0.15_fx, 0.4_fx), rng.uniform(0.15_fx, 0.4_fx)});
    default:
      return Shape::capsule(size, rng.uniform(0.1_fx, 0.5_fx));
  }
}

}  // namespace

void build_spray(World& w, const ScenarioParams&) {
  add(w, {.type = BodyType::static_body, .shape = Shape::plane()});
  for (const int side : {-1, 1}) {
    add_wall(w, {0.5_fx, 2_fx, 12_fx}, {Fixed::from_int(12 * side), 2_fx, 0_fx});
    add_wall(w, {12_fx, 2_fx, 0.5_fx}, {0_fx, 2_fx, Fixed::from_int(12 * side)});
  }
  // A paddle turning about y at 1 rad/s, and a platform sliding back and forth along x.
  add(w, {.type = BodyType::kinematic,
          .shape = Shape::box({4_fx, 0.25_fx, 0.5_fx}),
          .position = {0_fx, 1_fx, 0_fx},
          .angular_velocity = {0_fx, 1_fx, 0_fx}});
  add(w, {.type = BodyType::kinematic,
          .shape = Shape::box({2_fx, 0.2_fx, 2_fx}),
          .position = {-6_fx, 0.5_fx, 5_fx},
          .user_data = platform_tag});
}

void control_spray(World& w, std::span<const PlayerInput>, const ScenarioParams&) {
  const std::uint64_t frame = w.frame();
  // The platform's velocity is a function of the frame: +2 m/s for one period, -2 for the next.
  const bool forward = (frame / platform_period) % 2 == 0;
  for (const BodyState& b : tagged(w, platform_tag)) {
    (void)w.set_linear_velocity(b.id, {forward ? 2_fx : -2_fx, 0_fx, 0_fx});
  }
  if (frame % spray_interval != 0) return;
  // Keep the population bounded: the oldest spawned body (the lowest ID) makes room.
  const std::vector<BodyState> spawned = tagged(w, spawned_tag);
  if (spawned.size() >= spray_capacity) (void)w.destroy_body(spawned.front().id);
  Rng& rng = w.rng();
  // Drawn in statement order: C++ leaves the order of argument evaluation unspecified.
  const Shape shape = random_shape(rng);
  const Vec3 direction = rng.unit_vector();
  const Fixed speed = rng.uniform(2_fx, 6_fx);
  const Fixed x = rng.uniform(-2_fx, 2_fx);
  const Fixed z = rng.uniform(-2_fx, 2_fx);
  add(w, {.shape = shape,
          .position = {x, 8_fx, z},
          .linear_velocity = direction * speed + Vec3{0_fx, 3_fx, 0_fx},
          .restitution = 0.3_fx,
          .user_data = spawned_tag | frame});
}

// ---- arena ----

namespace {

constexpr std::int32_t arena_half = 15;        // m: the floor is 30 x 30
constexpr std::uint64_t kick_interval = 120;   // frames between RNG kicks of a crate
constexpr std::uint64_t spawn_interval = 300;  // frames between RNG crate spawns
constexpr std::size_t crate_capacity = 60;

// The eight start positions, on a circle of radius 8 (45-degree steps; 8 / sqrt 2 = 5.657).
constexpr std::int64_t diagonal_raw = 24296004000;  // 8 / sqrt 2 = 5.656854249492 in Q32.32
const Vec3 starts[8] = {
    {8_fx, 0.5_fx, 0_fx},
    {-8_fx, 0.5_fx, 0_fx},
    {0_fx, 0.5_fx, 8_fx},
    {0_fx, 0.5_fx, -8_fx},
    {Fixed::from_raw(diagonal_raw), 0.5_fx, Fixed::from_raw(diagonal_raw)},
    {-Fixed::from_raw(diagonal_raw), 0.5_fx, -Fixed::from_raw(diagonal_raw)},
    {Fixed::from_raw(diagonal_raw), 0.5_fx, -Fixed::from_raw(diagonal_raw)},
    {-Fixed::from_raw(diagonal_raw), 0.5_fx, Fixed::from_raw(diagonal_raw)},
};

/// Player i's start: the eight above first; then 24 on a ring of radius 11 m and 32 on one of
/// 13 m (players 8 .. 31 and 32 .. 63), evenly spaced, clear of the crates and the walls (the
/// floor's half side is 15 m) and at least 2.5 m apart.
Vec3 arena_start(std::uint32_t i) {
  if (i < 8) return starts[i];
  const bool inner = i < 32;
  const std::int32_t k = static_cast<std::int32_t>(inner ? i - 8 : i - 32);
  const std::int32_t n = inner ? 24 : 32;
  const Fixed radius = inner ? 11_fx : 13_fx;
  const Fixed angle = Fixed::two_pi() * Fixed::from_int(k) / Fixed::from_int(n);
  return {radius * cos(angle), 0.5_fx, radius * sin(angle)};
}

}  // namespace

void build_arena(World& w, const ScenarioParams& p) {
  const Fixed h = Fixed::from_int(arena_half);
  add(w, {.type = BodyType::static_body,
          .shape = Shape::box({h, 0.5_fx, h}),
          .position = {0_fx, -0.5_fx, 0_fx}});
  for (const int side : {-1, 1}) {
    add_wall(w, {0.5_fx, 1.5_fx, h}, {Fixed::from_int(side) * (h + 0.5_fx), 1.5_fx, 0_fx});
    add_wall(w, {h, 1.5_fx, 0.5_fx}, {0_fx, 1.5_fx, Fixed::from_int(side) * (h + 0.5_fx)});
  }
  for (std::uint32_t i = 0; i < p.players; ++i) {
    add(w, {.shape = Shape::sphere(0.5_fx),
            .position = arena_start(i),
            .mass = 80_fx,
            .friction = 0.8_fx,
            .linear_damping = 0.5_fx,
            .angular_damping = 2_fx,
            .user_data = player_tag + i});
  }
  // A 6 x 6 grid of crates around the centre.
  for (int i = 0; i < 36; ++i) {
    const Fixed x = Fixed::from_int(i % 6 - 3) * 1.5_fx + 0.75_fx;
    const Fixed z = Fixed::from_int(i / 6 - 3) * 1.5_fx + 0.75_fx;
    add(w, {.shape = Shape::box({0.4_fx, 0.4_fx, 0.4_fx}),
            .position = {x, 0.4_fx, z},
            .mass = 20_fx,
            .user_data = crate_tag});
  }
}

void control_arena(World& w, std::span<const PlayerInput> inputs, const ScenarioParams&) {
  for (const BodyState& b : tagged(w, player_tag)) {
    const std::uint64_t player = b.user_data - player_tag;
    if (player >= inputs.size()) continue;
    const PlayerInput& in = inputs[static_cast<std::size_t>(player)];
    // The stick: -127 .. 127 maps to +-1 (-128 is clamped), times a 1600 N drive.
    const auto axis = [](std::int8_t v) {
      return Fixed::from_int(v < -127 ? -127 : v) / Fixed::from_int(127);
    };
    const Vec3 stick{axis(in.move_x), 0_fx, axis(in.move_z)};
    if (stick != Vec3{}) (void)w.apply_force(b.id, stick * 1600_fx);
    // Jump only from the floor: low and not already moving up or down.
    const bool grounded = b.position.y < 0.55_fx && abs(b.linear_velocity.y) < 0.5_fx;
    if ((in.buttons & PlayerInput::jump) != 0 && grounded)
      (void)w.apply_linear_impulse(b.id, {0_fx, 400_fx, 0_fx});
    if ((in.buttons & PlayerInput::dash) != 0 && stick != Vec3{})
      (void)w.apply_linear_impulse(b.id, stick * 300_fx);
  }
  const std::uint64_t frame = w.frame();
  if (frame > 0 && frame % kick_interval == 0) {
    // An RNG event: a random crate is kicked upwards and sideways.
    const std::vector<BodyState> crates = tagged(w, crate_tag);
    if (!crates.empty()) {
      Rng& rng = w.rng();
      const BodyId target = crates[static_cast<std::size_t>(rng.below(crates.size()))].id;
      const Fixed sideways = rng.uniform(-60_fx, 60_fx);
      const Fixed up = rng.uniform(80_fx, 160_fx);
      (void)w.apply_linear_impulse(target, {sideways, up, 0_fx});
    }
  }
  if (frame > 0 && frame % spawn_interval == 0 && tagged(w, crate_tag).size() < crate_capacity) {
    Rng& rng = w.rng();
    const Fixed x = rng.uniform(-10_fx, 10_fx);
    const Fixed z = rng.uniform(-10_fx, 10_fx);
    add(w, {.shape = Shape::box({0.4_fx, 0.4_fx, 0.4_fx}),
            .position = {x, 4_fx, z},
            .mass = 20_fx,
            .user_data = crate_tag});
  }
}

}  // namespace detsim::scenes_detail
