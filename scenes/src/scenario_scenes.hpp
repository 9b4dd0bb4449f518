// The scenario builders and their per-frame logic, shared by scenario.cpp (the registry) and
// scenario_play.cpp (the scenes with game logic). Internal to detsim::scenes.
#pragma once

#include <cstdint>
#include <span>

#include <detsim/scenes/scenario.hpp>

namespace detsim::scenes_detail {

// Adds a body to a scenario's world. Scenario definitions are constants checked by the tests: a
// refusal is a bug here.
inline BodyId add(World& w, const BodyDef& def) {
  return w.create_body(def).value();
}

// Each builder fills an empty World made from the scenario's WorldDef.
void build_pile(World& w, const ScenarioParams& p, bool spheres);
void build_stack(World& w, const ScenarioParams& p);
void build_pyramid(World& w, const ScenarioParams& p);
void build_dominoes(World& w, const ScenarioParams& p);
void build_bullet_wall(World& w, const ScenarioParams& p);
void build_bounce(World& w, const ScenarioParams& p);
void build_slope(World& w, const ScenarioParams& p);
void build_spray(World& w, const ScenarioParams& p);
void build_arena(World& w, const ScenarioParams& p);
// The scenes with joints (scenario_joints.cpp).
void build_pendulum(World& w, const ScenarioParams& p);
void build_chain(World& w, const ScenarioParams& p);
void build_ragdolls(World& w, const ScenarioParams& p);
void build_bridge(World& w, const ScenarioParams& p);
void build_wrecking_ball(World& w, const ScenarioParams& p);
void build_motors(World& w, const ScenarioParams& p);
// The scenes of registered geometry (scenario_shapes.cpp).
void build_rocks(World& w, const ScenarioParams& p);
void build_level(World& w, const ScenarioParams& p);
void build_furniture(World& w, const ScenarioParams& p);
// The scenes with particles (scenario_particles.cpp).
void build_rope_bridge(World& w, const ScenarioParams& p);
void build_flag(World& w, const ScenarioParams& p);
void build_drape(World& w, const ScenarioParams& p);
void build_wrecking_rope(World& w, const ScenarioParams& p);
void build_jelly(World& w, const ScenarioParams& p);
void build_dam_break(World& w, const ScenarioParams& p);

// The scene of character controllers (scenario_characters.cpp).
void build_characters(World& w, const ScenarioParams& p);
// The scene of vehicles (scenario_vehicles.cpp), and the car it (and a game) builds: a chassis
// tagged `tag`, four wheels, the rear two driven, at `position` turned by `heading`.
void build_vehicles(World& w, const ScenarioParams& p);
VehicleId add_car(World& w, Vec3 position, Quat heading, std::uint64_t tag);
// Car soccer (scenario_soccar.cpp): the players' cars, a ball, two goals.
void build_soccar(World& w, const ScenarioParams& p);
// Gaffer On Games' cubes (scenario_cubes.cpp): a grid of small cubes and a large cube per player.
void build_cubes(World& w, const ScenarioParams& p);

// Per-frame logic, run before each step. Reads only the World and the inputs.
void control_spray(World& w, std::span<const PlayerInput> inputs, const ScenarioParams& p);
void control_arena(World& w, std::span<const PlayerInput> inputs, const ScenarioParams& p);
void control_bridge(World& w, std::span<const PlayerInput> inputs, const ScenarioParams& p);
void control_flag(World& w, std::span<const PlayerInput> inputs, const ScenarioParams& p);
void control_characters(World& w, std::span<const PlayerInput> inputs, const ScenarioParams& p);
void control_vehicles(World& w, std::span<const PlayerInput> inputs, const ScenarioParams& p);
void control_soccar(World& w, std::span<const PlayerInput> inputs, const ScenarioParams& p);
void control_cubes(World& w, std::span<const PlayerInput> inputs, const ScenarioParams& p);

// Tags in BodyDef::user_data by which game logic finds its bodies again (the World is the whole
// scenario state, so nothing else may remember them). A player's tag is player_tag + index.
inline constexpr std::uint64_t player_tag = 0x504C'4159'0000'0000ULL;  // "PLAY"
inline constexpr std::uint64_t platform_tag = 0x504C'4154'0000'0000ULL;
inline constexpr std::uint64_t spawned_tag = 0x5350'4157'0000'0000ULL;
inline constexpr std::uint64_t crate_tag = 0x4352'4154'0000'0000ULL;
inline constexpr std::uint64_t ragdoll_tag = 0x5241'4744'0000'0000ULL;  // + ragdoll index
inline constexpr std::uint64_t load_tag = 0x4C4F'4144'0000'0000ULL;     // the bridge's box
inline constexpr std::uint64_t brick_tag = 0x4252'4943'0000'0000ULL;
inline constexpr std::uint64_t ball_tag = 0x4241'4C4C'0000'0000ULL;     // the wrecking ball
inline constexpr std::uint64_t chassis_tag = 0x4341'5220'0000'0000ULL;  // + car index

// The joint scenes' dimensions (m, kg, s), shared with tests/sim_scenario_physics_test.cpp, which
// derives from them what each scene must do.
using namespace detsim::literals;

namespace pendulum {
inline constexpr Fixed pivot_y = 5_fx;
inline constexpr Fixed length = 2_fx;  ///< pivot to the bob's centre
inline constexpr Fixed bob_radius = 0.1_fx;
inline constexpr Fixed bob_mass = 1_fx;
inline constexpr Fixed start_angle = Fixed::pi() / 18_fx;  ///< 10 degrees
}  // namespace pendulum

namespace chain {
inline constexpr Vec3 top{0_fx, 40_fx, 0_fx};  ///< the first joint, below a static block
inline constexpr Fixed link = 0.4_fx;          ///< joint to joint
inline constexpr Fixed radius = 0.05_fx;
inline constexpr Fixed link_mass = 1_fx;
inline constexpr Fixed damping = 0.5_fx;  ///< linear, 1/s: the swing dies out in tens of seconds
}  // namespace chain

namespace ragdolls {
inline constexpr std::int32_t steps = 8;  ///< the landing's height is steps * rise
inline constexpr Fixed rise = 0.3_fx;
inline constexpr Fixed run = 0.3_fx;
inline constexpr Fixed spacing = 1.2_fx;  ///< between ragdolls along z
/// Every part's, 1/s: a ragdoll's usual setting; it also stops a head spinning freely on its
/// ball joint on the ground for ever.
inline constexpr Fixed angular_damping = 0.5_fx;
}  // namespace ragdolls

namespace bridge {
inline constexpr Vec3 left{0_fx, 4_fx, 0_fx};  ///< the left end hinge, on the planks' mid-line
inline constexpr Fixed plank = 0.5_fx;         ///< hinge to hinge
inline constexpr Fixed thickness = 0.1_fx;
inline constexpr Fixed plank_mass = 5_fx;
/// The planks are laid in a shallow V (down, then up at this angle), so that the chain of planks
/// is longer than the gap it spans by a factor 1 / cos(slack_angle).
inline constexpr Fixed slack_angle = 0.2_fx;
inline constexpr Fixed box_mass = 50_fx;    ///< ten planks
inline constexpr Fixed box_speed = 2_fx;    ///< m/s, the cruise control's target
inline constexpr Fixed cruise_rate = 4_fx;  ///< 1/s: the push per m/s short of box_speed
inline constexpr Fixed push_limit = 1_fx;   ///< the push's most, in units of the box's weight
/// Hinge k (0 .. planks) of a bridge of `planks` planks, world space.
Vec3 hinge_point(std::uint32_t planks, std::uint32_t k);
}  // namespace bridge

namespace wrecking_ball {
inline constexpr std::int32_t rows = 6;
inline constexpr std::int32_t columns = 6;
inline constexpr Vec3 brick_half{0.25_fx, 0.25_fx, 0.5_fx};
inline constexpr Fixed brick_mass = 20_fx;
inline constexpr Fixed wall_x = 0.95_fx;  ///< the wall's mid-plane; its face to the ball at 0.7
/// Three times the largest load a joint carries at rest (five bricks hang on the lowest
/// vertical joint of a column: 5 * 20 * 9.81 = 981 N).
inline constexpr Fixed break_force = 3000_fx;
inline constexpr Vec3 pivot{0_fx, 6.2_fx, 0_fx};
inline constexpr std::int32_t links = 5;
inline constexpr Fixed link = 0.8_fx;
inline constexpr Fixed link_mass = 5_fx;
inline constexpr Fixed ball_radius = 0.6_fx;
inline constexpr Fixed ball_mass = 500_fx;
inline constexpr Fixed release_angle = Fixed::pi() / 3_fx;  ///< 60 degrees
}  // namespace wrecking_ball

namespace motors {
inline constexpr Fixed wheel_radius = 0.3_fx;
inline constexpr Fixed capsule_half_height = 0.1_fx;  ///< the capsule wheels' half width
inline constexpr Fixed wheel_mass = 10_fx;
inline constexpr Fixed wheel_speed = 10_fx;    ///< rad/s: the car should run at 3 m/s
inline constexpr Fixed motor_torque = 100_fx;  ///< N m per wheel
inline constexpr Vec3 chassis_half{1_fx, 0.2_fx, 0.5_fx};
inline constexpr Fixed chassis_mass = 100_fx;
inline constexpr Fixed ride_height = 0.3_fx;  ///< the chassis' centre above the axles
inline constexpr Fixed axle_x = 0.8_fx;
inline constexpr Fixed track_z = 0.9_fx;
inline constexpr Fixed car_spacing = 5_fx;
}  // namespace motors

// The particle scenes' dimensions (m, kg, N), shared with the tests that derive what each must do.
namespace rope_bridge {
inline constexpr Fixed height = 4_fx;  ///< the posts' tops and the deck at rest
inline constexpr Fixed plank_width = 0.5_fx;
inline constexpr Fixed gap = 0.3_fx;     ///< between planks: each rope spans one gap
inline constexpr Fixed slack = 1.2_fx;   ///< a rope's length over its gap
inline constexpr Fixed side_z = 0.7_fx;  ///< the ropes' distance from the middle
inline constexpr Fixed plank_mass = 4_fx;
/// 1/s, linear and angular: a chain of planks on ropes sways for a long time without it.
inline constexpr Fixed plank_damping = 0.5_fx;
inline constexpr Fixed crate_mass = 10_fx;
}  // namespace rope_bridge

namespace flag {
inline constexpr Fixed pole_height = 4_fx;
inline constexpr Fixed width = 1.5_fx;
inline constexpr Fixed height = 1_fx;
inline constexpr std::uint32_t columns = 12;
inline constexpr std::uint32_t rows = 8;
inline constexpr Fixed wind_min = 2_fx;  ///< N on the whole 0.5 kg sheet
inline constexpr Fixed wind_max = 8_fx;
inline constexpr Fixed wind_side = 1_fx;
}  // namespace flag

namespace drape {
inline constexpr Fixed size = 4_fx;  ///< the sheet's side
inline constexpr Fixed drop_height = 2.5_fx;
inline constexpr Fixed sphere_radius = 0.7_fx;
inline constexpr Vec3 sphere_at{-0.9_fx, 0.7_fx, 0_fx};
inline constexpr Vec3 box_half{0.5_fx, 0.6_fx, 0.5_fx};
inline constexpr Vec3 box_at{1_fx, 0.6_fx, 0_fx};
}  // namespace drape

namespace jelly {
inline constexpr std::int32_t steps = 5;
inline constexpr Fixed rise = 0.3_fx;
inline constexpr Fixed run = 0.6_fx;
inline constexpr Fixed width = 6_fx;
inline constexpr Fixed half = 0.2_fx;  ///< the cubes' half side
inline constexpr std::uint32_t resolution = 4;
inline constexpr Fixed mass = 2_fx;
inline constexpr Fixed edge_compliance = 0.001_fx;
}  // namespace jelly

namespace dam_break {
inline constexpr Fixed spacing = 0.05_fx;  ///< m, between the fluid's particles
inline constexpr Fixed wall = 0.1_fx;      ///< half the tank walls' thickness
/// The tank, inside: tank_length block widths long, tank_depth wide; the obstacle a block width
/// from the dam.
inline constexpr std::int32_t tank_length = 6;
inline constexpr Vec3 obstacle_half{0.1_fx, 0.2_fx, 0.15_fx};
}  // namespace dam_break

namespace wrecking_rope {
inline constexpr Vec3 pivot{0_fx, 7_fx, 0_fx};
inline constexpr Fixed length = 6_fx;
inline constexpr std::uint32_t segments = 24;
inline constexpr Fixed ball_radius = 0.4_fx;
inline constexpr Fixed ball_mass = 200_fx;
}  // namespace wrecking_rope

namespace cars {
inline constexpr Fixed lot = 30_fx;  ///< the walls' inner faces are at +-lot in x and z
inline constexpr Vec3 chassis_half{0.9_fx, 0.4_fx, 2_fx};
inline constexpr Fixed chassis_mass = 1200_fx;
inline constexpr Fixed track = 0.8_fx;  ///< the wheels' x, either side
inline constexpr Fixed axle = 1.3_fx;   ///< the axles' z, front and rear
inline constexpr Fixed max_steer = 0.5_fx;
inline constexpr Fixed anti_roll = 20000_fx;
}  // namespace cars

namespace soccar {
inline constexpr Fixed half_width = 20_fx;   ///< the side walls' inner faces at +-half_width (x)
inline constexpr Fixed half_length = 30_fx;  ///< the end walls' inner faces at +-half_length (z)
inline constexpr Fixed wall_height = 2_fx;   ///< half the walls' height
inline constexpr Fixed goal_half_width = 4_fx;
inline constexpr Fixed goal_height = 3_fx;
inline constexpr Fixed goal_depth = 1_fx;  ///< the scoring zone inside the mouth
inline constexpr Fixed ball_radius = 1_fx;
inline constexpr Fixed ball_mass = 30_fx;
inline constexpr Fixed kickoff_z = 20_fx;
inline constexpr Fixed car_spacing = 6_fx;
inline constexpr Fixed car_jump_speed = 5_fx;       ///< m/s, along the chassis' up
inline constexpr Fixed boost_acceleration = 10_fx;  ///< m/s^2, along the chassis' forward
inline constexpr std::uint64_t goal_tag = 0x474F'414C'0000'0000ULL;   // "GOAL"
inline constexpr std::uint64_t goal_plus = 0x0000'0001'0000'0000ULL;  ///< the goal at +z
inline constexpr std::uint64_t goal_count_mask = 0xFFFF'FFFFULL;      ///< goals let in
}  // namespace soccar

namespace cubes {
inline constexpr std::uint32_t default_count = 900;  ///< small cubes: a 30 x 30 grid
inline constexpr std::uint32_t max_count = 10000;    ///< a 100 x 100 grid
inline constexpr Fixed small_half = 0.25_fx;         ///< the small cubes' half side
inline constexpr Fixed small_mass = 1_fx;
inline constexpr Fixed spacing = 1_fx;     ///< centre to centre: a 0.5 m gap between resting cubes
inline constexpr Fixed large_half = 1_fx;  ///< the large (player) cubes' half side
inline constexpr Fixed large_mass = 100_fx;
/// 1/s: under the full stick (below) a large cube tumbles along at about 5 m/s, and a tumble
/// dies out once the stick is let go.
inline constexpr Fixed large_linear_damping = 1_fx;
inline constexpr Fixed large_angular_damping = 2_fx;
inline constexpr Fixed friction = 0.5_fx;  ///< every body's, the plane's too
inline constexpr Fixed start_gap = 2_fx;   ///< at least, between the grid and a large cube's face
/// The stick at full: a force of drive_acceleration * mass along it at the centre, and a torque of
/// roll_torque * mass about up x stick. Neither alone tips a large cube over its leading edge (that
/// takes g * large_half = 9.81 N m per kg); together (6 + 6 * large_half) they do: it rolls.
inline constexpr Fixed drive_acceleration = 6_fx;  ///< m/s^2
inline constexpr Fixed roll_torque = 6_fx;         ///< N m per kg
inline constexpr Fixed jump_speed = 6_fx;          ///< m/s: the jump's impulse per kg
/// A large cube may jump while its centre is below this (m; 1 on a face, sqrt 3 on a corner, 1.5
/// on a small cube) and it moves up or down slower than 1 m/s.
inline constexpr Fixed jump_height = 2_fx;
inline constexpr std::uint64_t small_tag = 0x4355'4245'0000'0000ULL;  // "CUBE"
/// Half the side of the square the small cubes' centres fill, for `count` small cubes.
Fixed grid_half(std::uint32_t count);
}  // namespace cubes

namespace characters {
inline constexpr Fixed yard = 12_fx;  ///< the walls' inner faces are at +-yard in x and z
inline constexpr std::int32_t stair_count = 6;
inline constexpr Fixed stair_rise = 0.2_fx;  ///< below the characters' step height (0.3 m)
inline constexpr Fixed stair_run = 0.4_fx;
inline constexpr Fixed stairs_z = -7_fx;
inline constexpr Fixed ramp_z = -2_fx;
inline constexpr Fixed steep_z = 2_fx;
inline constexpr Fixed walkable_slope = 0.436332313_fx;  ///< 25 degrees
inline constexpr Fixed steep_slope = 1.047197551_fx;     ///< 60 degrees: above max_slope (45)
inline constexpr Fixed platform_half_thickness = 0.2_fx;
inline constexpr Vec3 slide_at{-7_fx, 0.6_fx, 7_fx};
inline constexpr Fixed slide_speed = 2_fx;
inline constexpr std::uint64_t slide_period = 120;  ///< frames each way
inline constexpr Vec3 spin_at{6_fx, 0.4_fx, 7_fx};
inline constexpr Fixed spin_rate = 0.8_fx;  ///< rad/s
inline constexpr Fixed crates_z = -4_fx;
inline constexpr Fixed crate_half = 0.4_fx;
inline constexpr Fixed crate_mass = 20_fx;
inline constexpr Fixed max_walk_speed = 3_fx;
inline constexpr Fixed jump_speed = 4.5_fx;
}  // namespace characters

}  // namespace detsim::scenes_detail
