// Car soccer: each player's car (World::create_vehicle) and a large ball in a walled arena with a
// goal at each end. A player's input is a PlayerInput: the stick's z is throttle (forward) or
// brake (back, which reverses a stopped car), its x the steering, the jump button a jump from the
// wheels, the dash button a boost. A ball whose centre enters a goal scores for the other team
// and goes back to the centre spot. The score lives in the goals' user data, so it is state:
// saved, hashed, rolled back.
#include <cstdint>

#include <detsim/fixed/math.hpp>
#include <detsim/fixed/quat.hpp>

#include "scenario_scenes.hpp"

namespace detsim::scenes_detail {

namespace {

using namespace soccar;

BodyDef arena_solid(Shape shape, Vec3 position) {
  BodyDef d;
  d.type = BodyType::static_body;
  d.shape = shape;
  d.position = position;
  d.friction = 1_fx;
  d.restitution = 0.3_fx;
  return d;
}

/// The ball's centre is inside goal `end` (-1: the goal at -z, +1: at +z).
bool in_goal(Vec3 ball, Fixed end) {
  return abs(ball.x) < goal_half_width && ball.y < goal_height &&
         ball.z * end > half_length - goal_depth;
}

std::int32_t team_of(std::uint32_t player) {
  return static_cast<std::int32_t>(player % 2);
}

/// Player p's kickoff spot: team 0 at -z facing +z, team 1 at +z facing -z, spread across x.
Vec3 kickoff_spot(std::uint32_t player, std::uint32_t players) {
  const std::uint32_t team_size = (players + 1 - static_cast<std::uint32_t>(team_of(player))) / 2;
  const std::uint32_t slot = player / 2;
  const Fixed x = (Fixed::from_int(static_cast<std::int32_t>(slot)) -
                   Fixed::from_int(static_cast<std::int32_t>(team_size) - 1) / 2_fx) *
                  car_spacing;
  return {x, 1_fx, team_of(player) == 0 ? -kickoff_z : kickoff_z};
}

}  // namespace

void build_soccar(World& w, const ScenarioParams& p) {
  (void)add(w, arena_solid(Shape::plane(), {}));
  const Fixed wall_half = 0.5_fx;
  // Side walls, and the end walls in two pieces either side of the goal mouths.
  for (const Fixed side : {1_fx, -1_fx}) {
    (void)add(w, arena_solid(Shape::box({wall_half, wall_height, half_length}),
                             {side * (half_width + wall_half), wall_height, 0_fx}));
    const Fixed piece = (half_width - goal_half_width) / 2_fx;
    for (const Fixed across : {1_fx, -1_fx}) {
      (void)add(w, arena_solid(Shape::box({piece, wall_height, wall_half}),
                               {across * (goal_half_width + piece), wall_height,
                                side * (half_length + wall_half)}));
    }
    // The goal: a sensor in the mouth, a back wall and a crossbar above it.
    BodyDef goal =
        arena_solid(Shape::box({goal_half_width, goal_height / 2_fx, goal_depth / 2_fx}),
                    {0_fx, goal_height / 2_fx, side * (half_length - goal_depth / 2_fx)});
    goal.sensor = true;
    goal.user_data = goal_tag | (side > 0_fx ? goal_plus : 0U);
    (void)add(w, goal);
    (void)add(w, arena_solid(Shape::box({goal_half_width, wall_height, wall_half}),
                             {0_fx, wall_height, side * (half_length + 2_fx + wall_half)}));
    (void)add(w,
              arena_solid(Shape::box({goal_half_width, wall_height - goal_height / 2_fx, 1_fx}),
                          {0_fx, wall_height + goal_height / 2_fx, side * (half_length + 1_fx)}));
    for (const Fixed across : {1_fx, -1_fx})
      (void)add(w, arena_solid(Shape::box({wall_half, wall_height, 1_fx}),
                               {across * (goal_half_width + wall_half), wall_height,
                                side * (half_length + 1_fx)}));
  }
  BodyDef ball;
  ball.shape = Shape::sphere(ball_radius);
  ball.position = {0_fx, ball_radius, 0_fx};
  ball.mass = ball_mass;
  ball.restitution = 0.6_fx;
  ball.friction = 0.5_fx;
  ball.linear_damping = 0.1_fx;
  ball.angular_damping = 0.1_fx;
  ball.ccd = true;
  ball.user_data = ball_tag;
  (void)add(w, ball);
  for (std::uint32_t player = 0; player < p.players; ++player) {
    const Fixed heading = team_of(player) == 0 ? 0_fx : Fixed::pi();
    (void)add_car(w, kickoff_spot(player, p.players), from_axis_angle({0_fx, 1_fx, 0_fx}, heading),
                  player_tag + player);
  }
}

void control_soccar(World& w, std::span<const PlayerInput> inputs, const ScenarioParams&) {
  // Goals first: a ball in a goal scores (the goal's user data counts what it let in) and goes
  // back to the centre spot.
  BodyId ball;
  Vec3 ball_at;
  for (const BodyId id : w.body_ids()) {
    const BodyState b = w.body(id).value();
    if (b.user_data == ball_tag) {
      ball = id;
      ball_at = b.position;
    }
  }
  for (const BodyId id : w.body_ids()) {
    const BodyState b = w.body(id).value();
    if ((b.user_data & ~goal_count_mask) != goal_tag &&
        (b.user_data & ~goal_count_mask) != (goal_tag | goal_plus))
      continue;
    const Fixed end = (b.user_data & goal_plus) != 0 ? 1_fx : -1_fx;
    if (ball.is_null() || !in_goal(ball_at, end)) continue;
    (void)w.set_user_data(id, b.user_data + 1);
    (void)w.set_transform(ball, {0_fx, ball_radius, 0_fx}, Quat::identity());
    (void)w.set_linear_velocity(ball, {});
    (void)w.set_angular_velocity(ball, {});
  }
  // The players' cars.
  for (const VehicleId id : w.vehicle_ids()) {
    const VehicleState v = w.vehicle(id).value();
    const BodyState chassis = w.body(v.def.chassis).value();
    const std::uint64_t player = chassis.user_data - player_tag;
    if (player >= inputs.size()) continue;
    const PlayerInput& in = inputs[static_cast<std::size_t>(player)];
    const auto axis = [](std::int8_t value) {
      return Fixed::from_int(value < -127 ? -127 : value) / Fixed::from_int(127);
    };
    const Fixed stick_z = axis(in.move_z);
    VehicleInput drive;
    drive.throttle = max(stick_z, 0_fx);
    drive.brake = max(-stick_z, 0_fx);
    drive.steering = -axis(in.move_x);  // the stick to the right steers right
    (void)w.set_vehicle_input(id, drive);
    std::uint32_t on_ground = 0;
    for (const WheelState& wheel : v.wheels)
      on_ground += wheel.contact ? 1U : 0U;
    const Vec3 up = rotate(chassis.orientation, {0_fx, 1_fx, 0_fx});
    if ((in.buttons & PlayerInput::jump) != 0 && on_ground >= 3)
      (void)w.apply_linear_impulse(v.def.chassis, up * (chassis.mass * car_jump_speed));
    if ((in.buttons & PlayerInput::dash) != 0) {
      const Vec3 forward = rotate(chassis.orientation, {0_fx, 0_fx, 1_fx});
      (void)w.apply_force(v.def.chassis, forward * (chassis.mass * boost_acceleration));
    }
  }
}

}  // namespace detsim::scenes_detail
