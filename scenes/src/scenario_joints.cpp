// The scenes with joints: pendulum, chain, ragdolls, bridge, wrecking_ball and motors
// (docs/SCENARIOS.md). Their sizes and constants are in scenario_scenes.hpp, where the physics
// tests read them to derive what each scene must do.
#include <detsim/fixed/math.hpp>
#include <detsim/scenes/ragdoll.hpp>

#include "scenario_scenes.hpp"

namespace detsim::scenes_detail {

namespace {

using namespace detsim::literals;

JointId join(World& w, const JointDef& def) {
  return w.create_joint(def).value();
}

BodyId add_plane(World& w, Fixed friction) {
  return add(w, {.type = BodyType::static_body, .shape = Shape::plane(), .friction = friction});
}

// A direction at `angle` from straight down, turned towards +x (positive) or -x (negative), in
// the x-y plane.
Vec3 hanging_at(Fixed angle) {
  return {sin(angle), -cos(angle), 0_fx};
}

}  // namespace

// ---- pendulum ----

void build_pendulum(World& w, const ScenarioParams&) {
  // A static beam along z; three bobs hang 2 m below it at z = 0, 1, 2, started 10 degrees
  // towards +x: on a ball joint, a hinge about z, and a rigid distance rod (to the bob's centre).
  const BodyId beam = add(w, {.type = BodyType::static_body,
                              .shape = Shape::box({0.1_fx, 0.1_fx, 1.5_fx}),
                              .position = {0_fx, pendulum::pivot_y + 0.1_fx, 1_fx}});
  const Vec3 arm = hanging_at(pendulum::start_angle) * pendulum::length;
  const JointType types[3] = {JointType::ball, JointType::hinge, JointType::distance};
  for (int i = 0; i < 3; ++i) {
    const Vec3 pivot{0_fx, pendulum::pivot_y, Fixed::from_int(i)};
    const BodyId bob = add(w, {.shape = Shape::sphere(pendulum::bob_radius),
                               .position = pivot + arm,
                               .mass = pendulum::bob_mass});
    join(w, {.type = types[i],
             .body_a = beam,
             .body_b = bob,
             .anchor = pivot,
             .axis = {0_fx, 0_fx, 1_fx}});
  }
}

// ---- chain ----

void build_chain(World& w, const ScenarioParams& p) {
  // N capsule links (chain::link long, anchors at their ends) hanging from a static block at
  // chain::top, released horizontally towards +x. No ground: the chain swings down and hangs.
  const Vec3 top = chain::top;
  BodyId previous = add(w, {.type = BodyType::static_body,
                            .shape = Shape::box({0.1_fx, 0.1_fx, 0.1_fx}),
                            .position = top + Vec3{0_fx, 0.1_fx, 0_fx}});
  // Capsules run along local y: a quarter turn about -z lays them along +x.
  const Quat along_x = from_axis_angle({0_fx, 0_fx, -1_fx}, Fixed::pi() / 2_fx);
  for (std::uint32_t i = 0; i < p.count; ++i) {
    const Fixed x = chain::link * Fixed::from_int(static_cast<std::int32_t>(i));
    const BodyId link =
        add(w, {.shape = Shape::capsule(chain::radius, chain::link / 2_fx - chain::radius),
                .position = top + Vec3{x + chain::link / 2_fx, 0_fx, 0_fx},
                .orientation = along_x,
                .mass = chain::link_mass,
                .linear_damping = chain::damping});
    join(w, {.type = JointType::ball,
             .body_a = previous,
             .body_b = link,
             .anchor = top + Vec3{x, 0_fx, 0_fx}});
    previous = link;
  }
}

// ---- ragdolls ----

void build_ragdolls(World& w, const ScenarioParams& p) {
  // A landing, then ragdolls::steps steps down towards +x (each ragdolls::run deep and
  // ragdolls::rise high), then the ground. The stairs are as wide as the row of ragdolls.
  add_plane(w, 0.6_fx);
  const Fixed width = Fixed::from_int(static_cast<std::int32_t>(p.count)) * ragdolls::spacing;
  const Fixed half_width = width / 2_fx + 1_fx;
  const Fixed top = ragdolls::rise * Fixed::from_int(ragdolls::steps);
  add(w, {.type = BodyType::static_body,
          .shape = Shape::box({1_fx, top / 2_fx, half_width}),
          .position = {-1_fx, top / 2_fx, 0_fx}});
  for (std::int32_t k = 1; k < ragdolls::steps; ++k) {
    const Fixed height = top - ragdolls::rise * Fixed::from_int(k);
    add(w, {.type = BodyType::static_body,
            .shape = Shape::box({ragdolls::run / 2_fx, height / 2_fx, half_width}),
            .position = {ragdolls::run * Fixed::from_int(k) - ragdolls::run / 2_fx, height / 2_fx,
                         0_fx}});
  }
  // Each ragdoll stands on the landing, 0.4 m from its edge, pitched forwards and pushed over
  // the edge; the world's RNG varies the push, the tip and a small turn about y.
  Rng& rng = w.rng();
  for (std::uint32_t i = 0; i < p.count; ++i) {
    const Fixed z = Fixed::from_int(static_cast<std::int32_t>(i)) * ragdolls::spacing -
                    width / 2_fx + ragdolls::spacing / 2_fx;
    const Fixed speed = rng.uniform(0.5_fx, 1.5_fx);
    const Fixed tip = rng.uniform(0.5_fx, 1.5_fx);
    const Fixed yaw = rng.uniform(-0.3_fx, 0.3_fx);
    (void)add_ragdoll(w, {.position = {-0.4_fx, top, z},
                          .orientation = from_axis_angle({0_fx, 1_fx, 0_fx}, yaw),
                          .linear_velocity = {speed, 0_fx, 0_fx},
                          .angular_velocity = {0_fx, 0_fx, -tip},
                          .angular_damping = ragdolls::angular_damping,
                          .user_data = ragdoll_tag + i})
        .value();
  }
}

// ---- bridge ----

Vec3 bridge::hinge_point(std::uint32_t planks, std::uint32_t k) {
  // Walk k planks from the left hinge: down at `slack_angle` over the first half, level across
  // the middle plank of an odd count, up over the second half.
  Vec3 at = left;
  const Fixed c = cos(slack_angle);
  const Fixed s = sin(slack_angle);
  for (std::uint32_t i = 0; i < k; ++i) {
    const std::uint32_t twice = 2 * i + 1;
    const Fixed dy = twice < planks ? -s : (twice == planks ? 0_fx : s);
    at = at + Vec3{twice == planks ? 1_fx : c, dy, 0_fx} * plank;
  }
  return at;
}

void build_bridge(World& w, const ScenarioParams& p) {
  add_plane(w, 0.6_fx);
  const Vec3 left = bridge::left;
  const Vec3 right = bridge::hinge_point(p.count, p.count);
  // The abutments' tops are level with the planks' tops at the end hinges.
  const Fixed deck = left.y + bridge::thickness / 2_fx;
  const Fixed half_height = deck / 2_fx;
  const BodyId left_bank = add(w, {.type = BodyType::static_body,
                                   .shape = Shape::box({2_fx, half_height, 2_fx}),
                                   .position = {left.x - 2_fx, half_height, 0_fx}});
  const BodyId right_bank = add(w, {.type = BodyType::static_body,
                                    .shape = Shape::box({2_fx, half_height, 2_fx}),
                                    .position = {right.x + 2_fx, half_height, 0_fx}});
  // A wall at the far end of the right bank stops the box.
  add(w, {.type = BodyType::static_body,
          .shape = Shape::box({0.25_fx, 1_fx, 2_fx}),
          .position = {right.x + 4.25_fx, deck + 1_fx, 0_fx}});
  BodyId previous = left_bank;
  for (std::uint32_t i = 0; i < p.count; ++i) {
    const Vec3 a = bridge::hinge_point(p.count, i);
    const Vec3 b = bridge::hinge_point(p.count, i + 1);
    const Fixed slope =
        b.y < a.y ? -bridge::slack_angle : (b.y == a.y ? 0_fx : bridge::slack_angle);
    const BodyId plank =
        add(w, {.shape = Shape::box({bridge::plank / 2_fx, bridge::thickness / 2_fx, 1_fx}),
                .position = (a + b) / 2_fx,
                .orientation = from_axis_angle({0_fx, 0_fx, 1_fx}, slope),
                .mass = bridge::plank_mass,
                .friction = 0.6_fx});
    join(w, {.type = JointType::hinge,
             .body_a = previous,
             .body_b = plank,
             .anchor = a,
             .axis = {0_fx, 0_fx, 1_fx}});
    previous = plank;
  }
  join(w, {.type = JointType::hinge,
           .body_a = previous,
           .body_b = right_bank,
           .anchor = right,
           .axis = {0_fx, 0_fx, 1_fx}});
  // The heavy box starts on the left bank, frictionless (a pair's friction is the geometric mean
  // of the two bodies', so zero), and control_bridge drives it towards +x.
  add(w, {.shape = Shape::box({0.5_fx, 0.5_fx, 0.5_fx}),
          .position = {left.x - 1.5_fx, deck + 0.5_fx, 0_fx},
          .mass = bridge::box_mass,
          .friction = 0_fx,
          .user_data = load_tag});
}

void control_bridge(World& w, std::span<const PlayerInput>, const ScenarioParams&) {
  // Cruise control: a horizontal push of box_mass * (box_speed - v_x) per second, between 0 and
  // push_limit * g * box_mass, so the box climbs out of the dip it makes in the bridge.
  for (const BodyId id : w.body_ids()) {
    const BodyState b = w.body(id).value();
    if (b.user_data != load_tag) continue;
    const Fixed accel = clamp((bridge::box_speed - b.linear_velocity.x) * bridge::cruise_rate, 0_fx,
                              bridge::push_limit * -w.def().gravity.y);
    (void)w.apply_force(id, {b.mass * accel, 0_fx, 0_fx});
  }
}

// ---- wrecking_ball ----

void build_wrecking_ball(World& w, const ScenarioParams&) {
  using namespace wrecking_ball;
  add_plane(w, 0.6_fx);
  // The wall: columns along z, rows up y, each brick welded to its right and upper neighbours
  // by a fixed joint that breaks under break_force. The bottom row stands on the ground.
  BodyId bricks[rows][columns];
  for (std::int32_t r = 0; r < rows; ++r) {
    for (std::int32_t c = 0; c < columns; ++c) {
      bricks[r][c] = add(w, {.shape = Shape::box(brick_half),
                             .position = {wall_x, brick_half.y * Fixed::from_int(2 * r + 1),
                                          brick_half.z * Fixed::from_int(2 * c + 1 - columns)},
                             .mass = brick_mass,
                             .user_data = brick_tag});
    }
  }
  for (std::int32_t r = 0; r < rows; ++r) {
    for (std::int32_t c = 0; c < columns; ++c) {
      const Vec3 centre{wall_x, brick_half.y * Fixed::from_int(2 * r + 1),
                        brick_half.z * Fixed::from_int(2 * c + 1 - columns)};
      if (c + 1 < columns)
        join(w, {.type = JointType::fixed,
                 .body_a = bricks[r][c],
                 .body_b = bricks[r][c + 1],
                 .anchor = centre + Vec3{0_fx, 0_fx, brick_half.z},
                 .break_force = break_force});
      if (r + 1 < rows)
        join(w, {.type = JointType::fixed,
                 .body_a = bricks[r][c],
                 .body_b = bricks[r + 1][c],
                 .anchor = centre + Vec3{0_fx, brick_half.y, 0_fx},
                 .break_force = break_force});
    }
  }
  // The ball on its chain, laid out straight at release_angle from straight down, away from
  // the wall (towards -x).
  const BodyId pivot_block = add(w, {.type = BodyType::static_body,
                                     .shape = Shape::box({0.2_fx, 0.2_fx, 0.2_fx}),
                                     .position = pivot + Vec3{0_fx, 0.2_fx, 0_fx}});
  const Vec3 d = hanging_at(-release_angle);
  const Quat tilt = from_axis_angle({0_fx, 0_fx, 1_fx}, -release_angle);  // local -y along d
  BodyId previous = pivot_block;
  for (std::int32_t i = 0; i < links; ++i) {
    const Fixed from = link * Fixed::from_int(i);
    const BodyId l = add(w, {.shape = Shape::capsule(0.08_fx, link / 2_fx - 0.08_fx),
                             .position = pivot + d * (from + link / 2_fx),
                             .orientation = tilt,
                             .mass = link_mass});
    join(w, {.type = JointType::ball, .body_a = previous, .body_b = l, .anchor = pivot + d * from});
    previous = l;
  }
  const Fixed chain_length = link * Fixed::from_int(links);
  const BodyId ball = add(w, {.shape = Shape::sphere(ball_radius),
                              .position = pivot + d * (chain_length + ball_radius),
                              .mass = ball_mass,
                              .user_data = ball_tag});
  join(w, {.type = JointType::ball,
           .body_a = previous,
           .body_b = ball,
           .anchor = pivot + d * chain_length});
}

// ---- motors ----

void build_motors(World& w, const ScenarioParams&) {
  using namespace motors;
  add_plane(w, 1_fx);
  // Two cars side by side, driving towards +x: the first on sphere wheels, the second on capsule
  // wheels (lying along z, rolling like cylinders). Each wheel is hinged to the chassis about z
  // at its centre, its motor at -wheel_speed (turning about -z rolls it towards +x).
  for (std::int32_t car = 0; car < 2; ++car) {
    const Fixed z = Fixed::from_int(car) * car_spacing;
    const Vec3 centre{0_fx, wheel_radius + ride_height, z};
    const BodyId chassis = add(w, {.shape = Shape::box(chassis_half),
                                   .position = centre,
                                   .mass = chassis_mass,
                                   .user_data = chassis_tag + static_cast<std::uint64_t>(car)});
    for (std::int32_t k = 0; k < 4; ++k) {
      const Vec3 at{Fixed::from_int(k < 2 ? 1 : -1) * axle_x, wheel_radius,
                    z + Fixed::from_int(k % 2 == 0 ? 1 : -1) * track_z};
      BodyDef wheel{.position = at, .mass = wheel_mass, .friction = 1_fx};
      if (car == 0) {
        wheel.shape = Shape::sphere(wheel_radius);
      } else {
        wheel.shape = Shape::capsule(wheel_radius, capsule_half_height);
        wheel.orientation = from_axis_angle({1_fx, 0_fx, 0_fx}, Fixed::pi() / 2_fx);
      }
      const BodyId id = add(w, wheel);
      join(w, {.type = JointType::hinge,
               .body_a = chassis,
               .body_b = id,
               .anchor = at,
               .axis = {0_fx, 0_fx, 1_fx},
               .motor_enabled = true,
               .motor_speed = -wheel_speed,
               .motor_max_force = motor_torque});
    }
  }
}

}  // namespace detsim::scenes_detail
