// The vehicles scene: four cars (World::create_vehicle) driven by inputs drawn from the world's RNG
// over a walled lot with ramps and speed bumps.
#include <cstdint>

#include <detsim/fixed/math.hpp>
#include <detsim/fixed/quat.hpp>

#include "scenario_scenes.hpp"

namespace detsim::scenes_detail {

namespace {

using namespace cars;

BodyDef lot_solid(Shape shape, Vec3 position, Quat orientation = {}) {
  BodyDef d;
  d.type = BodyType::static_body;
  d.shape = shape;
  d.position = position;
  d.orientation = orientation;
  d.friction = 1_fx;
  return d;
}

const Vec3 kLotX{1_fx, 0_fx, 0_fx};
const Vec3 kLotY{0_fx, 1_fx, 0_fx};

}  // namespace

VehicleId add_car(World& w, Vec3 position, Quat heading, std::uint64_t tag) {
  BodyDef c;
  c.shape = Shape::box(chassis_half);
  c.position = position;
  c.orientation = heading;
  c.mass = chassis_mass;
  c.friction = 0.3_fx;
  c.user_data = tag;
  c.ccd = true;  // a car at speed into a thin wall stops at it
  VehicleDef d;
  d.chassis = add(w, c);
  for (const Fixed x : {track, -track}) {
    for (const Fixed z : {axle, -axle}) {
      WheelDef wheel;
      wheel.attachment = {x, -chassis_half.y / 2_fx, z};
      wheel.max_steer_angle = z > 0_fx ? max_steer : 0_fx;
      wheel.driven = z < 0_fx;
      wheel.handbrake = z < 0_fx;
      d.wheels.push_back(wheel);
    }
  }
  // Wheels 0 and 2 are the front pair, 1 and 3 the rear: a bar on each axle.
  d.axles = {{0, 2, anti_roll}, {1, 3, anti_roll}};
  return w.create_vehicle(d).value();
}

void build_vehicles(World& w, const ScenarioParams&) {
  (void)add(w, lot_solid(Shape::plane(), {}));
  const Fixed wall_half = 0.5_fx;
  for (const Vec3 at : {Vec3{lot + wall_half, 1_fx, 0_fx}, Vec3{-lot - wall_half, 1_fx, 0_fx}})
    (void)add(w, lot_solid(Shape::box({wall_half, 1_fx, lot}), at));
  for (const Vec3 at : {Vec3{0_fx, 1_fx, lot + wall_half}, Vec3{0_fx, 1_fx, -lot - wall_half}})
    (void)add(w, lot_solid(Shape::box({lot, 1_fx, wall_half}), at));
  // Two ramps (10 degrees, 6 m long, 4 m wide) facing each other across the middle.
  for (const Fixed side : {1_fx, -1_fx}) {
    const Quat tilt = from_axis_angle(kLotX, -side * 0.1745329252_fx);
    (void)add(w, lot_solid(Shape::box({2_fx, 0.25_fx, 3_fx}), {0_fx, 0.27_fx, side * 10_fx}, tilt));
  }
  // Speed bumps: capsules lying across the lot, 0.12 m high above the ground.
  for (const Fixed z : {-20_fx, -4_fx, 4_fx, 20_fx}) {
    (void)add(w, lot_solid(Shape::capsule(0.12_fx, 6_fx), {-14_fx, 0_fx, z},
                           from_axis_angle(Vec3{0_fx, 0_fx, 1_fx}, Fixed::half_pi())));
    (void)add(w, lot_solid(Shape::capsule(0.12_fx, 6_fx), {14_fx, 0_fx, z},
                           from_axis_angle(Vec3{0_fx, 0_fx, 1_fx}, Fixed::half_pi())));
  }
  // Four cars at the lot's quarters, heading round it.
  const Vec3 car_starts[4] = {
      {-14_fx, 1_fx, -10_fx}, {14_fx, 1_fx, 10_fx}, {-14_fx, 1_fx, 10_fx}, {14_fx, 1_fx, -10_fx}};
  const Fixed car_headings[4] = {0_fx, Fixed::pi(), Fixed::pi(), 0_fx};
  for (std::uint32_t k = 0; k < 4; ++k)
    (void)add_car(w, car_starts[k], from_axis_angle(kLotY, car_headings[k]), chassis_tag + k);
}

void control_vehicles(World& w, std::span<const PlayerInput>, const ScenarioParams&) {
  // Each car chooses anew once a second, at its own frame: throttle, steering, and now and then
  // the brake (which reverses a stopped car) or the handbrake; a car stuck with the throttle
  // down brakes, and so backs off. Drawn in statement order from the world's RNG.
  const std::uint64_t frame = w.frame();
  Rng& rng = w.rng();
  for (const VehicleId id : w.vehicle_ids()) {
    if ((frame + 15 * id.value) % 60 != 0) continue;
    const VehicleState v = w.vehicle(id).value();
    VehicleInput in;
    in.throttle = rng.uniform(0.3_fx, 1_fx);
    in.steering = rng.uniform(-1_fx, 1_fx);
    const Fixed roll = rng.uniform(0_fx, 1_fx);
    // Stuck (against a wall, on a bump) with a pedal down: the other way for a second (the brake
    // reverses a stopped car; in reverse the throttle takes it forward).
    const bool reversing = v.gear == 0;
    const bool stuck =
        (reversing ? v.input.brake : v.input.throttle) > 0_fx && abs(v.forward_speed) < 0.5_fx;
    if (stuck && reversing) {
      // forwards: the throttle drawn above
    } else if (stuck || roll < 0.15_fx) {
      in.throttle = 0_fx;
      in.brake = 1_fx;
    } else if (roll < 0.25_fx) {
      in.handbrake = true;
    }
    (void)w.set_vehicle_input(id, in);
  }
}

}  // namespace detsim::scenes_detail
