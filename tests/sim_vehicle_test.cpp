// Vehicles (World::create_vehicle): a chassis on sphere-cast wheels with spring-damper suspension,
// an engine and gearbox, brakes and magic-formula tires, solved in the sub-steps.
//
// Expected values come from the physics: a chassis of mass m on four springs of stiffness k sags
// m g / (4 k); wheels locked from 20 m/s stop the car in v^2 / (2 mu g), mu the tire curve's
// sliding value times the ground's friction; at low speed a car steered by delta turns on the
// radius wheelbase / tan(delta) (its centre on sqrt(R^2 + (wheelbase / 2)^2)); sliding on a
// skid-pad its lateral acceleration is the lateral curve's grip times g; a car at 100 m/s does not
// pass a 0.1 m wall.
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

#include "support/sim_helpers.hpp"

namespace detsim {
namespace {

using namespace detsim::literals;

using test::add;
using test::add_ground;
using test::make_world;
using test::state;

double to_d(Fixed x) {
  return x.to_double();
}

constexpr double kG = 9.81;
constexpr double kWheelbase = 2.6;  // front axle at z = +1.3, rear at -1.3
constexpr double kChassisMass = 1200;

/// A rear-driven car on the plane: a 1.8 x 0.8 x 4 m chassis of 1200 kg, four wheels of radius
/// 0.35 m on 0.3 m of suspension, the front two steered.
struct Car {
  World w = make_world();
  BodyId ground;
  BodyId chassis;
  VehicleId id;

  Car() {
    ground = add_ground(w, {}, Fixed::one());
    BodyDef c;
    c.shape = Shape::box({0.9_fx, 0.4_fx, 2_fx});
    c.position = {0_fx, 0.8_fx, 0_fx};
    c.mass = Fixed::from_int(static_cast<std::int32_t>(kChassisMass));
    c.friction = 0.2_fx;
    chassis = add(w, c);
    VehicleDef d;
    d.chassis = chassis;
    for (const Fixed x : {0.8_fx, -0.8_fx}) {
      for (const Fixed z : {1.3_fx, -1.3_fx}) {
        WheelDef wheel;
        wheel.attachment = {x, -0.2_fx, z};
        wheel.max_steer_angle = z > 0_fx ? 0.5_fx : 0_fx;
        wheel.driven = z < 0_fx;
        wheel.handbrake = z < 0_fx;
        d.wheels.push_back(wheel);
      }
    }
    auto v = w.create_vehicle(d);
    EXPECT_TRUE(v.ok()) << v.message();
    id = v.ok() ? *v : VehicleId{};
  }
  void input(const VehicleInput& in) { ASSERT_TRUE(w.set_vehicle_input(id, in).ok()); }
  void run(int frames) {
    for (int i = 0; i < frames; ++i)
      w.step();
  }
  [[nodiscard]] VehicleState vehicle() const { return w.vehicle(id).value(); }
  [[nodiscard]] BodyState body() const { return state(w, chassis); }
};

/// The magic formula in double, for expectations.
double magic(const TireCurve& t, double x) {
  const double bx = to_d(t.b) * x;
  return to_d(t.d) * std::sin(to_d(t.c) * std::atan(bx - to_d(t.e) * (bx - std::atan(bx))));
}

TEST(Vehicle, AChassisSagsByItsWeightOverFourSprings) {
  Car car;
  car.run(240);
  const VehicleState v = car.vehicle();
  const double k = to_d(WheelDef{}.suspension_stiffness);
  const double expected = kChassisMass * kG / (4 * k);
  for (const WheelState& wheel : v.wheels) {
    EXPECT_TRUE(wheel.contact);
    EXPECT_NEAR(to_d(wheel.compression), expected, 0.02 * expected);
    EXPECT_NEAR(to_d(wheel.suspension_force), kChassisMass * kG / 4, 0.02 * kChassisMass * kG / 4);
  }
  EXPECT_LT(std::abs(to_d(car.body().linear_velocity.y)), 0.01) << "at rest";
}

TEST(Vehicle, LockedWheelsStopItInVSquaredOverTwoMuG) {
  Car car;
  car.run(120);
  const double z0 = to_d(car.body().position.z);
  ASSERT_TRUE(car.w.set_linear_velocity(car.chassis, {0_fx, 0_fx, 20_fx}).ok());
  VehicleInput in;
  in.brake = 1_fx;
  in.handbrake = true;
  car.input(in);
  int frames = 0;
  while (to_d(car.body().linear_velocity.z) > 0.01 && frames < 1200) {
    car.w.step();
    ++frames;
    if (car.body().linear_velocity.z < 0.5_fx) continue;  // stopped: reverse may engage
    for (const WheelState& wheel : car.vehicle().wheels)
      ASSERT_LT(abs(wheel.angular_velocity), 0.001_fx) << "locked, frame " << frames;
  }
  const double mu = std::abs(magic(TireDef{}.longitudinal, -1.0));  // ground friction 1
  const double expected = 20.0 * 20.0 / (2 * mu * kG);
  EXPECT_NEAR(to_d(car.body().position.z) - z0, expected, 0.05 * expected);
}

TEST(Vehicle, AtLowSpeedItTurnsOnWheelbaseOverTanDelta) {
  Car car;
  car.run(120);
  VehicleInput in;
  in.steering = 0.4_fx;  // 0.2 rad on the front wheels
  car.input(in);
  ASSERT_TRUE(car.w.set_linear_velocity(car.chassis, {0_fx, 0_fx, 3_fx}).ok());
  car.run(60);  // into the turn
  // Three points a third of a circle apart: their circumcircle is the path's.
  std::vector<Vec3> points;
  for (int i = 0; i < 3; ++i) {
    points.push_back(car.body().position);
    car.run(300);
  }
  const auto x = [&](int i) { return to_d(points[static_cast<std::size_t>(i)].x); };
  const auto z = [&](int i) { return to_d(points[static_cast<std::size_t>(i)].z); };
  const double a = std::hypot(x(1) - x(0), z(1) - z(0));
  const double b = std::hypot(x(2) - x(1), z(2) - z(1));
  const double c = std::hypot(x(2) - x(0), z(2) - z(0));
  const double area2 = std::abs((x(1) - x(0)) * (z(2) - z(0)) - (x(2) - x(0)) * (z(1) - z(0)));
  const double radius = a * b * c / (2 * area2);
  const double rear = kWheelbase / std::tan(0.2);
  const double expected = std::sqrt(rear * rear + kWheelbase * kWheelbase / 4);
  EXPECT_NEAR(radius, expected, 0.05 * expected);
}

TEST(Vehicle, OnASkidPadItsLateralAccelerationIsTheTiresGripTimesG) {
  Car car;
  car.run(120);
  VehicleInput in;
  in.steering = 0.6_fx;
  car.input(in);
  ASSERT_TRUE(car.w.set_linear_velocity(car.chassis, {0_fx, 0_fx, 25_fx}).ok());
  car.run(30);
  // Sliding round: the perpendicular part of the acceleration, over half a second.
  double sum = 0;
  int n = 0;
  Vec3 before = car.body().linear_velocity;
  for (int i = 0; i < 30; ++i) {
    car.w.step();
    const Vec3 now = car.body().linear_velocity;
    const double vx = to_d(now.x);
    const double vz = to_d(now.z);
    const double speed = std::hypot(vx, vz);
    const double ax = (vx - to_d(before.x)) * 60;
    const double az = (vz - to_d(before.z)) * 60;
    sum += std::abs(ax * vz - az * vx) / speed;  // |a x v| / |v|
    ++n;
    before = now;
  }
  const double grip = 1.0;  // the lateral curve's peak d, on ground of friction 1
  EXPECT_NEAR(sum / n, grip * kG, 0.1 * grip * kG);
}

TEST(Vehicle, AtAHundredMetresASecondItDoesNotPassATenCentimetreWall) {
  Car car;
  car.run(60);
  BodyDef wall;
  wall.type = BodyType::static_body;
  wall.shape = Shape::box({5_fx, 2_fx, 0.05_fx});
  wall.position = {0_fx, 2_fx, 30_fx};
  add(car.w, wall);
  // The chassis is a body like any other: its continuous collision stops it at the wall.
  BodyState b = car.body();
  ASSERT_TRUE(car.w.set_linear_velocity(car.chassis, {0_fx, 0_fx, 100_fx}).ok());
  for (int i = 0; i < 120; ++i) {
    car.w.step();
    b = car.body();
    ASSERT_LT(to_d(b.position.z), 30.0 - 0.05) << "frame " << i;
  }
}

/// A car driven by a script of inputs: throttle, steering both ways, braking, the handbrake.
void drive(Car& car, int from, int to) {
  for (int f = from; f < to; ++f) {
    VehicleInput in;
    const int phase = (f / 40) % 5;
    in.throttle = phase < 3 ? 0.8_fx : 0_fx;
    in.steering = phase == 1 ? 0.7_fx : (phase == 2 ? -0.5_fx : 0_fx);
    in.brake = phase == 3 ? 0.6_fx : 0_fx;
    in.handbrake = phase == 4;
    car.input(in);
    car.w.step();
  }
}

TEST(Vehicle, RestoredMidManoeuvreItDrivesOnLikeTheUninterruptedRun) {
  Car a;
  drive(a, 0, 130);
  const std::vector<std::uint8_t> saved = a.w.save();
  std::vector<StateHashes> expected;
  for (int f = 130; f < 260; ++f) {
    drive(a, f, f + 1);
    expected.push_back(a.w.hashes());
  }
  Car b;
  ASSERT_TRUE(b.w.restore(saved).ok());
  for (int f = 130; f < 260; ++f) {
    drive(b, f, f + 1);
    ASSERT_EQ(b.w.hashes(), expected[static_cast<std::size_t>(f - 130)]) << "frame " << f;
  }
  EXPECT_EQ(a.vehicle(), b.vehicle());
  EXPECT_GT(to_d(a.vehicle().forward_speed), 1.0) << "the script drove it";
}

TEST(Vehicle, TheVehiclesSectionIsWrittenOnlyByAWorldThatHasHadOneAndDiffNamesAWheel) {
  World plain = make_world();
  add_ground(plain);
  EXPECT_EQ(plain.hashes().section("vehicles"), 0U);
  Car car;
  drive(car, 0, 50);
  EXPECT_NE(car.w.hashes().section("vehicles"), 0U);
  const std::vector<std::uint8_t> before = car.w.save();
  auto injection = parse_injection("50:0:vehicle[1].wheel[2].angular_velocity:0.5");
  ASSERT_TRUE(injection.ok()) << injection.message();
  ASSERT_TRUE(apply_injection(car.w, *injection).ok());
  const StateDiff d = diff_states(car.w, before, car.w.save()).value();
  ASSERT_EQ(d.fields.size(), 1U);
  EXPECT_EQ(d.fields[0].subsystem, "vehicles");
  EXPECT_EQ(d.fields[0].field, "vehicle[1].wheel[2].angular_velocity");
  // What restore would refuse is refused, and changes nothing.
  const std::vector<std::uint8_t> now = car.w.save();
  EXPECT_FALSE(apply_injection(car.w, *parse_injection("50:0:vehicle[1].gear:9")).ok());
  EXPECT_FALSE(apply_injection(car.w, *parse_injection("50:0:vehicle[1].wheel[7].radius:1")).ok());
  EXPECT_FALSE(apply_injection(car.w, *parse_injection("50:0:vehicle[1].throttle:2")).ok());
  EXPECT_FALSE(parse_injection("50:0:vehicle[1].wheel[0].wobble:1").ok());
  EXPECT_EQ(car.w.save(), now);
  // A restore keeps every field: a saved state reads back to the same bytes.
  World copy = car.w;
  ASSERT_TRUE(copy.restore(now).ok());
  EXPECT_EQ(copy.save(), now);
  EXPECT_EQ(copy.vehicle(car.id).value(), car.vehicle());
}

TEST(Vehicle, AParkedCarSleepsAndAnInputWakesIt) {
  Car car;
  car.run(240);
  EXPECT_FALSE(car.body().awake) << "parked on its wheels, it sleeps";
  const Vec3 parked = car.body().position;
  car.run(60);
  EXPECT_EQ(car.body().position, parked) << "asleep, nothing moves it";
  VehicleInput in;
  in.throttle = 1_fx;
  car.input(in);
  EXPECT_TRUE(car.body().awake);
  car.run(60);
  EXPECT_GT(to_d(car.vehicle().forward_speed), 2.0) << "and it drives off";
  EXPECT_GT(to_d(car.body().position.z), to_d(parked.z) + 1.0);
}

TEST(Vehicle, StoppedWithTheBrakeHeldItReversesAndTheThrottleTakesItForwardAgain) {
  Car car;
  car.run(60);
  VehicleInput in;
  in.brake = 1_fx;
  car.input(in);
  car.run(120);
  EXPECT_EQ(car.vehicle().gear, 0U) << "reverse";
  EXPECT_LT(to_d(car.vehicle().forward_speed), -1.0) << "backwards";
  in = {};
  in.throttle = 1_fx;
  car.input(in);
  car.run(180);
  EXPECT_GE(car.vehicle().gear, 1U);
  EXPECT_GT(to_d(car.vehicle().forward_speed), 1.0) << "forwards again";
}

TEST(Vehicle, DestroyingItsChassisRemovesTheVehicle) {
  Car car;
  car.run(10);
  ASSERT_TRUE(car.w.destroy_body(car.chassis).ok());
  EXPECT_TRUE(car.w.vehicle_ids().empty());
  EXPECT_FALSE(car.w.vehicle(car.id).ok());
  car.run(10);  // and the world steps on
  ASSERT_TRUE(car.w.validate().ok());
}

TEST(Vehicle, BadDefinitionsAndInputsAreRefusedNamingTheField) {
  World w = make_world();
  add_ground(w);
  BodyDef c;
  c.shape = Shape::box({1_fx, 0.5_fx, 2_fx});
  const BodyId chassis = add(w, c);
  BodyDef s = c;
  s.type = BodyType::static_body;
  s.position = {10_fx, 0_fx, 0_fx};
  const BodyId fixed_body = add(w, s);
  const std::vector<std::uint8_t> before = w.save();
  const auto refused = [&](const VehicleDef& d, const char* field) {
    auto v = w.create_vehicle(d);
    ASSERT_FALSE(v.ok()) << field;
    EXPECT_NE(v.message().find(field), std::string::npos) << v.message();
  };
  VehicleDef d;
  d.chassis = chassis;
  refused(d, "wheels");  // none
  d.wheels.push_back({});
  d.chassis = fixed_body;
  refused(d, "not dynamic");
  d.chassis = BodyId{99};
  refused(d, "chassis");
  d.chassis = chassis;
  d.wheels[0].radius = 0_fx;
  refused(d, "wheels[0].radius");
  d.wheels[0] = {};
  d.engine.torque_curve = {{3000_fx, 100_fx}, {2000_fx, 100_fx}};
  refused(d, "ascend");
  d.engine = {};
  d.gear_ratios = {};
  refused(d, "gear_ratios");
  d.gear_ratios = {1_fx};
  d.axles = {{0, 0, 1000_fx}};
  refused(d, "axles[0]");
  d.axles = {};
  EXPECT_EQ(w.save(), before) << "a refused vehicle changes nothing";
  const VehicleId v = w.create_vehicle(d).value();
  EXPECT_EQ(v.value, 1U) << "refusals use up no ID";
  EXPECT_FALSE(w.create_vehicle(d).ok()) << "one vehicle per chassis";
  EXPECT_FALSE(w.set_vehicle_input(v, {2_fx, 0_fx, 0_fx, false}).ok());
  EXPECT_FALSE(w.set_vehicle_input(v, {0_fx, -1_fx, 0_fx, false}).ok());
  EXPECT_FALSE(w.set_vehicle_input(v, {0_fx, 0_fx, 1.5_fx, false}).ok());
  EXPECT_FALSE(w.set_vehicle_input(VehicleId{5}, {}).ok());
  EXPECT_EQ(w.vehicle(v)->input, VehicleInput{});
}

}  // namespace
}  // namespace detsim
