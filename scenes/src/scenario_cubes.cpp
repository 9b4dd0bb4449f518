// Cubes, after Glenn Fiedler's networked-physics demo (Gaffer On Games, "Networked Physics",
// 2014-2015): a grid of small cubes resting on a plane and one large cube per player that rolls,
// pushes and jumps through them. The small cubes start at rest, a gap apart, so they fall asleep
// within a second and stay asleep until a large cube (or a cube it knocked) reaches them: the scene
// the state-authority benchmark uses, where resting cubes cost nothing in a delta snapshot.
#include <cstdint>

#include <detsim/fixed/math.hpp>

#include "scenario_scenes.hpp"

namespace detsim::scenes_detail {

namespace {

/// The smallest s with s^2 >= n (n >= 1): the grid's side.
std::uint32_t grid_side(std::uint32_t n) {
  std::uint32_t s = 1;
  while (std::uint64_t{s} * s < n)
    ++s;
  return s;
}

/// Player p's start of `players`: spread evenly along a square around the grid, `half` from its
/// centre, beginning at the middle of the -z side (player 0) and going on towards +x. For eight
/// players or fewer (max_scenario_players) two starts are at least `half` apart along the square,
/// so at least half / sqrt 2 apart in the plane: more than a large cube's diagonal (2 sqrt 2 m)
/// when half is 6 m or more.
Vec3 large_cube_start(std::uint32_t player, std::uint32_t players, Fixed half) {
  // The distance along the square from (0, -half), in units of half: the square is 8 long.
  const Fixed t = Fixed::from_int(static_cast<std::int32_t>(8 * player)) /
                  Fixed::from_int(static_cast<std::int32_t>(players));
  Fixed x;
  Fixed z;
  if (t <= 1_fx) {  // the -z side, going +x
    x = t;
    z = -1_fx;
  } else if (t <= 3_fx) {  // the +x side, going +z
    x = 1_fx;
    z = t - 2_fx;
  } else if (t <= 5_fx) {  // the +z side, going -x
    x = 4_fx - t;
    z = 1_fx;
  } else if (t <= 7_fx) {  // the -x side, going -z
    x = -1_fx;
    z = 6_fx - t;
  } else {  // the -z side again, going +x to the start
    x = t - 8_fx;
    z = -1_fx;
  }
  return {x * half, cubes::large_half, z * half};
}

/// The stick's axis, -127 .. 127 (-128 counts as -127), as -1 .. 1.
Fixed stick_axis(std::int8_t value) {
  return Fixed::from_int(value < -127 ? -127 : value) / Fixed::from_int(127);
}

}  // namespace

Fixed cubes::grid_half(std::uint32_t count) {
  return Fixed::from_int(static_cast<std::int32_t>(grid_side(count)) - 1) * cubes::spacing / 2_fx;
}

void build_cubes(World& w, const ScenarioParams& p) {
  add(w, {.type = BodyType::static_body, .shape = Shape::plane(), .friction = cubes::friction});
  // The large cubes first: their IDs are the lowest after the ground's, so control_cubes finds
  // them without reading the small cubes. They start on a square start_gap outside the grid, and
  // at least 6 m from the middle, so that eight starts around a small grid are 4.2 m apart.
  const Fixed start_half = max(
      cubes::grid_half(p.count) + cubes::small_half + cubes::start_gap + cubes::large_half, 6_fx);
  for (std::uint32_t player = 0; player < p.players; ++player) {
    add(w, {.shape = Shape::box({cubes::large_half, cubes::large_half, cubes::large_half}),
            .position = large_cube_start(player, p.players, start_half),
            .mass = cubes::large_mass,
            .friction = cubes::friction,
            .linear_damping = cubes::large_linear_damping,
            .angular_damping = cubes::large_angular_damping,
            .user_data = player_tag + player});
  }
  // The small cubes: row by row along x, centred on the origin, exactly resting on the plane.
  const std::uint32_t side = grid_side(p.count);
  const Fixed corner = -cubes::grid_half(p.count);
  for (std::uint32_t i = 0; i < p.count; ++i) {
    const Fixed x = corner + Fixed::from_int(static_cast<std::int32_t>(i % side)) * cubes::spacing;
    const Fixed z = corner + Fixed::from_int(static_cast<std::int32_t>(i / side)) * cubes::spacing;
    add(w, {.shape = Shape::box({cubes::small_half, cubes::small_half, cubes::small_half}),
            .position = {x, cubes::small_half, z},
            .mass = cubes::small_mass,
            .friction = cubes::friction,
            .user_data = cubes::small_tag});
  }
}

void control_cubes(World& w, std::span<const PlayerInput> inputs, const ScenarioParams&) {
  std::size_t found = 0;
  for (const BodyId id : w.body_ids()) {
    if (found == inputs.size()) break;  // the large cubes come first: the rest are small ones
    const BodyState b = w.body(id).value();
    if (b.user_data < player_tag || b.user_data - player_tag >= inputs.size()) continue;
    ++found;
    const PlayerInput& in = inputs[static_cast<std::size_t>(b.user_data - player_tag)];
    const Vec3 stick{stick_axis(in.move_x), 0_fx, stick_axis(in.move_z)};
    // Only a moved stick pushes: a force, even a zero one, wakes the body, and an idle large cube
    // must be able to sleep like the small ones.
    if (stick != Vec3{}) {
      (void)w.apply_force(b.id, stick * (b.mass * cubes::drive_acceleration));
      // Rolling towards the stick turns about up x stick (a ball rolling along +x turns about -z).
      (void)w.apply_torque(b.id,
                           cross(Vec3{0_fx, 1_fx, 0_fx}, stick) * (b.mass * cubes::roll_torque));
    }
    const bool near_ground = b.position.y < cubes::jump_height && abs(b.linear_velocity.y) < 1_fx;
    if ((in.buttons & PlayerInput::jump) != 0 && near_ground)
      (void)w.apply_linear_impulse(b.id, {0_fx, b.mass * cubes::jump_speed, 0_fx});
  }
}

}  // namespace detsim::scenes_detail
