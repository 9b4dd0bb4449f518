// Joints, continued from sim_joint_test.cpp (docs/SIM.md, "Joints"): set_joint_motor, the joint
// reaction, joint events, the slider's limit and motor, and the loads of issue 17's tests —
// motors against loads, limits against torques, breaking, random torques on a shoulder, a hanging
// chain and a wrecking ball a hundred times heavier than its links. Every expectation is derived
// from a formula stated beside it, never read back from a previous run.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

#include "support/joint_helpers.hpp"
#include "support/sim_helpers.hpp"

namespace detsim {
namespace {

using namespace detsim::literals;

using test::add;
using test::anchor_gap;
using test::join;
using test::make_world;
using test::near;
using test::post_at;
using test::sphere_at;
using test::state;

// The rotation of a body about world z from identity, radians (for bodies that turn about z only).
double angle_about_z(const BodyState& b) {
  return 2.0 * std::atan2(b.orientation.z.to_double(), b.orientation.w.to_double());
}

// A 10 kg sphere of radius 0.5 m (I = 2/5 m r^2 = 1 kg m^2) at (0, 5, 0), hinged at its centre
// about z to a static post: a wheel whose motor's torque is its angular acceleration.
struct Wheel {
  World w = make_world();
  BodyId post;
  BodyId body;
  JointId joint;

  explicit Wheel(const JointDef& extra) {
    post = add(w, post_at({0_fx, 5_fx, 0_fx}));
    body = add(w, sphere_at({0_fx, 5_fx, 0_fx}, 0.5_fx, 10_fx));
    JointDef d = extra;
    d.type = JointType::hinge;
    d.body_a = post;
    d.body_b = body;
    d.anchor = {0_fx, 5_fx, 0_fx};
    d.axis = {0_fx, 0_fx, 1_fx};
    joint = join(w, d);
  }
};

// ---- set_joint_motor ----

TEST(SimJointMotor, SetJointMotorRefusesBadCallsAndChangesNothing) {
  Wheel wheel{JointDef{}};
  World& w = wheel.w;
  const BodyId other = add(w, sphere_at({3_fx, 5_fx, 0_fx}, 0.1_fx, 1_fx));
  JointDef ball;
  ball.body_a = wheel.post;
  ball.body_b = other;
  ball.anchor = {3_fx, 5_fx, 0_fx};
  const JointId ball_joint = join(w, ball);
  // At rest, the bodies fall asleep: a refused call must not wake them either.
  for (std::int32_t i = 0; i < 120; ++i)
    w.step();
  ASSERT_FALSE(state(w, wheel.body).awake);
  const std::vector<std::uint8_t> before = w.save();
  const JointState hinge_before = *w.joint(wheel.joint);
  struct Case {
    JointId id;
    Fixed speed;
    Fixed max_force;
    const char* named;
  };
  const Case cases[] = {
      {JointId{99}, 1_fx, 1_fx, "no joint with ID 99"},
      {ball_joint, 1_fx, 1_fx, "no motor"},
      {wheel.joint, 1_fx, -1_fx, "motor_max_force"},
      {wheel.joint, 1_fx, Fixed::max(), "motor_max_force"},
      {wheel.joint, Fixed::max(), 1_fx, "motor_speed"},
      {wheel.joint, Fixed::min(), 1_fx, "motor_speed"},
  };
  for (const Case& c : cases) {
    const Status s = w.set_joint_motor(c.id, c.speed, c.max_force);
    ASSERT_FALSE(s.ok()) << c.named;
    EXPECT_NE(s.message().find(c.named), std::string::npos) << s.message();
    EXPECT_EQ(w.save(), before) << c.named;
    EXPECT_EQ(*w.joint(wheel.joint), hinge_before) << c.named;
  }
  // create_joint refuses the same saturated values, naming the field.
  JointDef saturated;
  saturated.type = JointType::hinge;
  saturated.body_a = wheel.post;
  saturated.body_b = other;
  saturated.motor_speed = Fixed::max();
  EXPECT_NE(w.create_joint(saturated).message().find("motor_speed"), std::string::npos);
  saturated.motor_speed = 1_fx;
  saturated.motor_max_force = Fixed::max();
  EXPECT_NE(w.create_joint(saturated).message().find("motor_max_force"), std::string::npos);
}

TEST(SimJointMotor, SetJointMotorDrivesTheWheelAndZeroForceSwitchesItOff) {
  // The wheel asleep, without a motor; set_joint_motor(5 rad/s, 2 N m) enables the motor and
  // wakes it: it spins up at tau / I = 2 rad/s^2, 2 rad/s after 1 s. Then max_force 0 switches
  // the motor off: nothing acts about the axis, and the wheel keeps its speed.
  Wheel wheel{JointDef{}};
  World& w = wheel.w;
  for (std::int32_t i = 0; i < 60; ++i)
    w.step();
  ASSERT_FALSE(state(w, wheel.body).awake);
  ASSERT_TRUE(w.set_joint_motor(wheel.joint, 5_fx, 2_fx).ok());
  EXPECT_TRUE(state(w, wheel.body).awake);
  const JointDef def = w.joint(wheel.joint)->def;
  EXPECT_TRUE(def.motor_enabled);
  EXPECT_EQ(def.motor_speed, 5_fx);
  EXPECT_EQ(def.motor_max_force, 2_fx);
  for (std::int32_t i = 0; i < 60; ++i)
    w.step();
  const Fixed spun = state(w, wheel.body).angular_velocity.z;
  EXPECT_TRUE(near(spun, 2_fx, 0.04_fx));
  ASSERT_TRUE(w.set_joint_motor(wheel.joint, 5_fx, 0_fx).ok());
  EXPECT_FALSE(w.joint(wheel.joint)->def.motor_enabled);
  for (std::int32_t i = 0; i < 60; ++i)
    w.step();
  EXPECT_TRUE(near(state(w, wheel.body).angular_velocity.z, spun, 0.001_fx));
  EXPECT_EQ(w.joint_reaction(wheel.joint)->torque.z, 0_fx);
}

TEST(SimJointMotor, LoweringTheForceLimitsTheNextStepsTorque) {
  // A motor holding the wheel against a 3 N m torque at speed 0, its force then lowered to 1 N m:
  // from the next step the motor gives at most 1 N m (its warm start is limited too), so the
  // wheel turns up at (3 - 1) / I = 2 rad/s^2.
  JointDef motor;
  motor.motor_enabled = true;
  motor.motor_max_force = 10_fx;
  Wheel wheel{motor};
  World& w = wheel.w;
  for (std::int32_t i = 0; i < 30; ++i) {
    ASSERT_TRUE(w.apply_torque(wheel.body, {0_fx, 0_fx, 3_fx}).ok());
    w.step();
  }
  EXPECT_TRUE(near(state(w, wheel.body).angular_velocity.z, 0_fx, 0.01_fx));
  EXPECT_TRUE(near(w.joint_reaction(wheel.joint)->torque.z, -3_fx, 0.03_fx));
  ASSERT_TRUE(w.set_joint_motor(wheel.joint, 0_fx, 1_fx).ok());
  const Fixed start = state(w, wheel.body).angular_velocity.z;
  for (std::int32_t i = 0; i < 30; ++i) {
    ASSERT_TRUE(w.apply_torque(wheel.body, {0_fx, 0_fx, 3_fx}).ok());
    w.step();
  }
  EXPECT_TRUE(near(state(w, wheel.body).angular_velocity.z - start, 1_fx, 0.02_fx));
  EXPECT_TRUE(near(w.joint_reaction(wheel.joint)->torque.z, -1_fx, 0.001_fx));
}

// ---- The joint reaction ----

TEST(SimJointReaction, HangingWeightsPullWithTheirWeight) {
  // At rest, the joint carries the weight of what hangs from it: the force on body b is -m g
  // (upward), with no torque for a weight below the anchor. A beam welded at its end (centre
  // 1 m out) also needs the couple m g x 1 m about +z to hold its far end up.
  const Fixed g = 9.81_fx;
  for (const JointType type : {JointType::ball, JointType::distance, JointType::fixed}) {
    World w = make_world();
    const BodyId top = add(w, post_at({0_fx, 10_fx, 0_fx}));
    const BodyId bob = add(w, sphere_at({0_fx, 8_fx, 0_fx}, 0.1_fx, 3_fx));
    JointDef d;
    d.type = type;
    d.body_a = top;
    d.body_b = bob;
    d.anchor = {0_fx, 10_fx, 0_fx};
    const JointId joint = join(w, d);
    for (std::int32_t i = 0; i < 60; ++i)
      w.step();
    const JointReaction r = *w.joint_reaction(joint);
    EXPECT_TRUE(near(r.force.y, 3_fx * g, 0.03_fx)) << static_cast<int>(type);
    EXPECT_TRUE(near(r.force.x, 0_fx, 0.001_fx));
    EXPECT_LT(length(r.torque), 0.01_fx);
  }
  World w = make_world();
  const BodyId wall = add(w, post_at({0_fx, 5_fx, 0_fx}));
  BodyDef beam;
  beam.shape = Shape::box({1_fx, 0.1_fx, 0.1_fx});
  beam.position = {1.2_fx, 5_fx, 0_fx};
  beam.mass = 10_fx;
  const BodyId body = add(w, beam);
  JointDef d;
  d.type = JointType::fixed;
  d.body_a = wall;
  d.body_b = body;
  d.anchor = {0.2_fx, 5_fx, 0_fx};
  const JointId joint = join(w, d);
  for (std::int32_t i = 0; i < 60; ++i)
    w.step();
  const JointReaction r = *w.joint_reaction(joint);
  EXPECT_TRUE(near(r.force.y, 10_fx * g, 0.1_fx));
  EXPECT_TRUE(near(r.torque.z, 10_fx * g, 0.1_fx));  // m g x 1 m
  EXPECT_FALSE(w.joint_reaction(JointId{7}).ok());
  EXPECT_NE(w.joint_reaction(JointId{7}).message().find("no joint with ID 7"), std::string::npos);
}

// ---- Joint events ----

TEST(SimJointEvents, DestroyingABodyReportsItsJointsInAscendingOrder) {
  World w = make_world();
  const BodyId top = add(w, post_at({0_fx, 10_fx, 0_fx}));
  const BodyId a = add(w, sphere_at({0_fx, 9_fx, 0_fx}, 0.1_fx, 1_fx));
  const BodyId b = add(w, sphere_at({0_fx, 8_fx, 0_fx}, 0.1_fx, 1_fx));
  JointDef d;
  d.body_a = top;
  d.body_b = a;
  d.anchor = {0_fx, 10_fx, 0_fx};
  d.user_data = 11;
  const JointId first = join(w, d);
  d.body_a = top;
  d.body_b = b;
  d.type = JointType::distance;
  d.user_data = 12;
  const JointId unrelated = join(w, d);
  d.type = JointType::ball;
  d.body_a = a;
  d.body_b = b;
  d.anchor = {0_fx, 8.5_fx, 0_fx};
  d.user_data = 13;
  const JointId third = join(w, d);
  for (std::int32_t i = 0; i < 10; ++i)
    w.step();
  EXPECT_TRUE(w.joint_events().empty());
  // destroy_joint is the game's own doing: no event.
  ASSERT_TRUE(w.destroy_joint(unrelated).ok());
  EXPECT_TRUE(w.joint_events().empty());
  const JointReaction carried = *w.joint_reaction(first);
  ASSERT_TRUE(w.destroy_body(a).ok());
  const std::vector<JointEvent> events(w.joint_events().begin(), w.joint_events().end());
  ASSERT_EQ(events.size(), 2U);
  EXPECT_EQ(events[0].kind, JointEvent::Kind::destroyed);
  EXPECT_EQ(events[0].joint, first);
  EXPECT_EQ(events[0].body_a, top);
  EXPECT_EQ(events[0].body_b, a);
  EXPECT_EQ(events[0].user_data, 11U);
  EXPECT_EQ(events[0].reaction, carried);
  EXPECT_EQ(events[1].joint, third);
  EXPECT_EQ(events[1].user_data, 13U);
  w.step();  // a new step, a new list
  EXPECT_TRUE(w.joint_events().empty());
}

TEST(SimJointEvents, BreaksAreReportedOnceInAscendingJointOrderAndRestoreClearsThem) {
  // Three spheres of 1 kg on ball joints rated 5 N (joint 1), 20 N (2) and 5 N (3): the first and
  // the third break under the weight (9.81 N) in the same step, reported in joint order; the
  // second holds. Later steps report nothing more.
  World w = make_world();
  std::vector<JointId> joints;
  for (std::int32_t i = 0; i < 3; ++i) {
    const Fixed x = Fixed::from_int(2 * i);
    const BodyId top = add(w, post_at({x, 10_fx, 0_fx}));
    const BodyId bob = add(w, sphere_at({x, 9_fx, 0_fx}, 0.1_fx, 1_fx));
    JointDef d;
    d.body_a = top;
    d.body_b = bob;
    d.anchor = {x, 10_fx, 0_fx};
    d.break_force = i == 1 ? 20_fx : 5_fx;
    joints.push_back(join(w, d));
  }
  std::vector<JointEvent> events;
  for (std::int32_t i = 0; i < 60; ++i) {
    w.step();
    events.insert(events.end(), w.joint_events().begin(), w.joint_events().end());
    if (i == 0) {
      ASSERT_EQ(w.joint_events().size(), events.size());
    }
  }
  ASSERT_EQ(events.size(), 2U);
  EXPECT_EQ(events[0].joint, joints[0]);
  EXPECT_EQ(events[1].joint, joints[2]);
  for (const JointEvent& e : events) {
    EXPECT_EQ(e.kind, JointEvent::Kind::broke);
    EXPECT_GT(length(e.reaction.force), 5_fx);
    EXPECT_TRUE(w.joint(e.joint)->broken);
    EXPECT_EQ(*w.joint_reaction(e.joint), JointReaction{});  // broken: applies nothing
  }
  EXPECT_FALSE(w.joint(joints[1])->broken);
  // restore() clears the list (events are output, not state).
  World again = make_world();
  for (std::int32_t i = 0; i < 3; ++i) {
    const Fixed x = Fixed::from_int(2 * i);
    const BodyId top = add(again, post_at({x, 10_fx, 0_fx}));
    const BodyId bob = add(again, sphere_at({x, 9_fx, 0_fx}, 0.1_fx, 1_fx));
    JointDef d;
    d.body_a = top;
    d.body_b = bob;
    d.anchor = {x, 10_fx, 0_fx};
    d.break_force = 5_fx;
    join(again, d);
  }
  while (again.joint_events().empty() && again.frame() < 60)
    again.step();
  ASSERT_FALSE(again.joint_events().empty());
  ASSERT_TRUE(again.restore(again.save()).ok());
  EXPECT_TRUE(again.joint_events().empty());
}

// ---- Hinge motor ----

TEST(SimHingeMotor, ReachesItsSpeedWithin2PercentIn1SecondWhenTheTorqueAllows) {
  // The wheel (I = 1 kg m^2), motor 5 rad/s with at most 10 N m: it needs t = I w / tau = 0.5 s
  // at full torque; at 1 s it turns at 5 rad/s within 2 %, about z only.
  JointDef motor;
  motor.motor_enabled = true;
  motor.motor_speed = 5_fx;
  motor.motor_max_force = 10_fx;
  Wheel wheel{motor};
  for (std::int32_t i = 0; i < 60; ++i)
    wheel.w.step();
  const Vec3 spin = state(wheel.w, wheel.body).angular_velocity;
  EXPECT_TRUE(near(spin.z, 5_fx, 0.1_fx));
  EXPECT_LT(hypot(spin.x, spin.y), 0.001_fx);
  std::cout << "[ hinge motor ] " << to_string(spin.z) << " rad/s at 1 s (target 5)\n";
}

// An arm: a 1 kg sphere of radius 0.1 m whose centre is L = 1 m out along +x from a hinge
// about z on a static post, held horizontal by the hinge's motor at speed 0.
struct Arm {
  World w = make_world();
  BodyId body;
  JointId joint;
  Vec3 pivot{0_fx, 10_fx, 0_fx};

  explicit Arm(const JointDef& extra) {
    const BodyId post = add(w, post_at(pivot));
    body = add(w, sphere_at(pivot + Vec3{1_fx, 0_fx, 0_fx}, 0.1_fx, 1_fx));
    JointDef d = extra;
    d.type = JointType::hinge;
    d.body_a = post;
    d.body_b = body;
    d.anchor = pivot;
    d.axis = {0_fx, 0_fx, 1_fx};
    joint = join(w, d);
  }
  // The arm's angle above the horizontal, radians.
  [[nodiscard]] double angle() const {
    const Vec3 p = state(w, body).position - pivot;
    return std::atan2(p.y.to_double(), p.x.to_double());
  }
};

TEST(SimHingeMotor, HoldsALoadBelowItsTorqueAndSlipsUnderOneAbove) {
  // Gravity's torque on the arm about the hinge is m g L cos(theta) = 9.81 N m at the horizontal.
  // A motor at speed 0 with 1.25 times that holds the arm where it is (within 0.01 rad, the
  // point rows' give). With 0.8 times, the motor slips at its full torque and the arm falls as
  // I theta'' = -(m g L cos(theta) - tau), I = m L^2 + 2/5 m r^2 (the sphere turns with the
  // arm), integrated here by RK4: its angle at 0.5 s within 3 %.
  const double g = 9.81;
  const double tau_g = 1.0 * g * 1.0;
  for (const double share : {1.25, 0.8}) {
    JointDef motor;
    motor.motor_enabled = true;
    motor.motor_max_force = Fixed::from_raw(std::llround(share * tau_g * 4294967296.0));
    Arm arm{motor};
    double lowest = 0.0;
    for (std::int32_t i = 0; i < 30; ++i) {
      arm.w.step();
      lowest = std::min(lowest, arm.angle());
    }
    if (share > 1.0) {
      for (std::int32_t i = 0; i < 90; ++i) {
        arm.w.step();
        lowest = std::min(lowest, arm.angle());
      }
      EXPECT_GT(lowest, -0.01) << "the motor holds";
      EXPECT_LT(length(state(arm.w, arm.body).linear_velocity), 0.01_fx);
      std::cout << "[ hinge motor hold ] lowest angle " << lowest << " rad over 2 s\n";
      continue;
    }
    const double inertia = 1.0 + 0.4 * 0.01;
    const double tau = motor.motor_max_force.to_double();
    double theta = 0.0;
    double omega = 0.0;
    const double h = 1.0 / 6000.0;
    const auto accel = [&](double t) { return -(g * std::cos(t) - tau) / inertia; };
    for (std::int32_t i = 0; i < 3000; ++i) {
      const double k1t = omega, k1w = accel(theta);
      const double k2t = omega + h / 2 * k1w, k2w = accel(theta + h / 2 * k1t);
      const double k3t = omega + h / 2 * k2w, k3w = accel(theta + h / 2 * k2t);
      const double k4t = omega + h * k3w, k4w = accel(theta + h * k3t);
      theta += h / 6 * (k1t + 2 * k2t + 2 * k3t + k4t);
      omega += h / 6 * (k1w + 2 * k2w + 2 * k3w + k4w);
    }
    const double measured = arm.angle();
    EXPECT_LT(std::abs(measured - theta), 0.03 * std::abs(theta))
        << "measured " << measured << " rad, expected " << theta << " rad";
    std::cout << "[ hinge motor slip ] " << measured << " rad at 0.5 s, formula " << theta
              << " rad\n";
  }
}

// ---- Hinge limits ----

TEST(SimHingeLimit, HoldsWithin001RadUnderATorquePushingPastIt) {
  // The wheel (I = 1 kg m^2) limited to +-0.5 rad, driven by 20 N m one way for 1 s, then the
  // other: it reaches each end (at 20 rad/s^2, within 0.23 s) and stays within 0.01 rad of it,
  // the limit then pushing back with the whole 20 N m.
  JointDef limit;
  limit.limit_enabled = true;
  limit.limit_lower = -0.5_fx;
  limit.limit_upper = 0.5_fx;
  Wheel wheel{limit};
  World& w = wheel.w;
  for (const Fixed torque : {20_fx, -20_fx}) {
    double most = 0.0;
    for (std::int32_t i = 0; i < 60; ++i) {
      ASSERT_TRUE(w.apply_torque(wheel.body, {0_fx, 0_fx, torque}).ok());
      w.step();
      const double angle = angle_about_z(state(w, wheel.body));
      most = torque > 0_fx ? std::max(most, angle) : std::min(most, angle);
    }
    const double end = torque > 0_fx ? 0.5 : -0.5;
    EXPECT_LT(std::abs(most) - 0.5, 0.01) << "torque " << to_string(torque);
    EXPECT_LT(std::abs(angle_about_z(state(w, wheel.body)) - end), 0.01);
    EXPECT_TRUE(near(w.joint_reaction(wheel.joint)->torque.z, -torque, 0.2_fx));
    std::cout << "[ hinge limit ] torque " << to_string(torque) << " N m: furthest " << most
              << " rad (end " << end << ")\n";
  }
  // The arm: gravity's torque (9.81 N m at the horizontal) swings it down onto its lower end,
  // -0.3 rad, which holds it within 0.01 rad.
  JointDef arm_limit;
  arm_limit.limit_enabled = true;
  arm_limit.limit_lower = -0.3_fx;
  arm_limit.limit_upper = 0.3_fx;
  Arm arm{arm_limit};
  double lowest = 0.0;
  for (std::int32_t i = 0; i < 120; ++i) {
    arm.w.step();
    lowest = std::min(lowest, arm.angle());
  }
  EXPECT_GT(lowest, -0.31);
  EXPECT_LT(std::abs(arm.angle() + 0.3), 0.01);
  std::cout << "[ hinge limit ] arm under gravity: lowest " << lowest << " rad (end -0.3)\n";
}

// ---- Slider limit and motor ----

// A 2 kg box on a horizontal slider along x from a static rail (gravity across the axis, held by
// the slider's rows), at x = 0.
struct Slide {
  World w = make_world();
  BodyId body;
  JointId joint;

  explicit Slide(const JointDef& extra) {
    const BodyId rail = add(w, post_at({-1_fx, 10_fx, 0_fx}));
    BodyDef box;
    box.shape = Shape::box({0.2_fx, 0.1_fx, 0.1_fx});
    box.position = {0_fx, 10_fx, 0_fx};
    box.mass = 2_fx;
    body = add(w, box);
    JointDef d = extra;
    d.type = JointType::slider;
    d.body_a = rail;
    d.body_b = body;
    d.anchor = {0_fx, 10_fx, 0_fx};
    d.axis = {1_fx, 0_fx, 0_fx};
    joint = join(w, d);
  }
};

TEST(SimSliderLimit, HoldsWithin1CmUnderAForcePushingPastIt) {
  // Limited to +-0.5 m, pushed by 200 N one way for 1 s, then the other: the box reaches each end
  // (at 100 m/s^2, within 0.1 s, hitting it at up to 10 m/s) and stays within 1 cm of it, the
  // limit then pushing back with the whole 200 N.
  JointDef limit;
  limit.limit_enabled = true;
  limit.limit_lower = -0.5_fx;
  limit.limit_upper = 0.5_fx;
  Slide slide{limit};
  World& w = slide.w;
  for (const Fixed force : {200_fx, -200_fx}) {
    Fixed most;
    for (std::int32_t i = 0; i < 60; ++i) {
      ASSERT_TRUE(w.apply_force(slide.body, {force, 0_fx, 0_fx}).ok());
      w.step();
      const Fixed x = state(w, slide.body).position.x;
      most = force > 0_fx ? max(most, x) : min(most, x);
    }
    const Fixed end = force > 0_fx ? 0.5_fx : -0.5_fx;
    EXPECT_LT(abs(most) - 0.5_fx, 0.01_fx) << "force " << to_string(force);
    EXPECT_TRUE(near(state(w, slide.body).position.x, end, 0.01_fx));
    EXPECT_TRUE(near(w.joint_reaction(slide.joint)->force.x, -force, 2_fx));
    EXPECT_TRUE(near(state(w, slide.body).position.y, 10_fx, 0.005_fx));
    std::cout << "[ slider limit ] force " << to_string(force) << " N: furthest " << to_string(most)
              << " m (end " << to_string(end) << ")\n";
  }
}

TEST(SimSliderMotor, ReachesItsSpeedAtItsForce) {
  // Motor 3 m/s with at most 10 N on the 2 kg box: it accelerates at F / m = 5 m/s^2 (2 m/s at
  // 0.4 s), reaches 3 m/s at 0.6 s and keeps it (within 2 %).
  JointDef motor;
  motor.motor_enabled = true;
  motor.motor_speed = 3_fx;
  motor.motor_max_force = 10_fx;
  Slide slide{motor};
  World& w = slide.w;
  for (std::int32_t i = 0; i < 24; ++i)
    w.step();
  EXPECT_TRUE(near(state(w, slide.body).linear_velocity.x, 2_fx, 0.04_fx));
  for (std::int32_t i = 0; i < 36; ++i)
    w.step();
  const Vec3 v = state(w, slide.body).linear_velocity;
  EXPECT_TRUE(near(v.x, 3_fx, 0.06_fx));
  EXPECT_LT(hypot(v.y, v.z), 0.01_fx);
  std::cout << "[ slider motor ] " << to_string(v.x) << " m/s at 1 s (target 3)\n";
}

// ---- Breaking ----

// Steps `w` for `steps` steps, gathering its joint events.
std::vector<JointEvent> run_gathering_events(World& w, std::int32_t steps) {
  std::vector<JointEvent> events;
  for (std::int32_t i = 0; i < steps; ++i) {
    w.step();
    events.insert(events.end(), w.joint_events().begin(), w.joint_events().end());
  }
  return events;
}

TEST(SimJointBreaking, FixedJointHolds08FAndBreaksUnder12FWithOneEvent) {
  // A fixed joint with break_force F = 50 N, a sphere hanging 1 m below its anchor: a weight of
  // 0.8 F holds for 2 s (no event); 1.2 F breaks it within 1 s, reported by exactly one event,
  // and the sphere then falls freely.
  const Fixed force = 50_fx;
  const Fixed g = 9.81_fx;
  for (const Fixed share : {0.8_fx, 1.2_fx}) {
    World w = make_world();
    const BodyId top = add(w, post_at({0_fx, 10_fx, 0_fx}));
    const BodyId bob = add(w, sphere_at({0_fx, 9_fx, 0_fx}, 0.1_fx, share * force / g));
    JointDef d;
    d.type = JointType::fixed;
    d.body_a = top;
    d.body_b = bob;
    d.anchor = {0_fx, 10_fx, 0_fx};
    d.break_force = force;
    const JointId joint = join(w, d);
    const std::vector<JointEvent> early = run_gathering_events(w, 60);
    const std::vector<JointEvent> later = run_gathering_events(w, 60);
    if (share < 1_fx) {
      EXPECT_TRUE(early.empty());
      EXPECT_TRUE(later.empty());
      EXPECT_FALSE(w.joint(joint)->broken);
      EXPECT_TRUE(near(w.joint_reaction(joint)->force.y, share * force, 0.5_fx));
    } else {
      ASSERT_EQ(early.size(), 1U);
      EXPECT_TRUE(later.empty());
      EXPECT_EQ(early[0].joint, joint);
      EXPECT_EQ(early[0].kind, JointEvent::Kind::broke);
      EXPECT_GT(length(early[0].reaction.force), force);
      EXPECT_LT(state(w, bob).position.y, 9_fx - 2_fx);  // falling freely (> g t^2 / 2 for 1 s)
    }
  }
}

TEST(SimJointBreaking, CantileverHolds08TAndBreaksUnder12TWithOneEvent) {
  // A beam (2 m x 0.2 m x 0.2 m) welded at its end, horizontal: the weld's couple is m g x 1 m
  // (the centre's distance from the anchor). With break_torque T = 40 N m, a beam of
  // m = 0.8 T / (g x 1 m) holds for 2 s; one of 1.2 T / (g x 1 m) breaks within 1 s, reported by
  // exactly one event.
  const Fixed torque = 40_fx;
  const Fixed g = 9.81_fx;
  for (const Fixed share : {0.8_fx, 1.2_fx}) {
    World w = make_world();
    const BodyId wall = add(w, post_at({0_fx, 5_fx, 0_fx}));
    BodyDef beam;
    beam.shape = Shape::box({1_fx, 0.1_fx, 0.1_fx});
    beam.position = {1.2_fx, 5_fx, 0_fx};
    beam.mass = share * torque / g;
    const BodyId body = add(w, beam);
    JointDef d;
    d.type = JointType::fixed;
    d.body_a = wall;
    d.body_b = body;
    d.anchor = {0.2_fx, 5_fx, 0_fx};
    d.break_torque = torque;
    const JointId joint = join(w, d);
    const std::vector<JointEvent> early = run_gathering_events(w, 60);
    const std::vector<JointEvent> later = run_gathering_events(w, 60);
    if (share < 1_fx) {
      EXPECT_TRUE(early.empty());
      EXPECT_TRUE(later.empty());
      EXPECT_FALSE(w.joint(joint)->broken);
      EXPECT_TRUE(near(w.joint_reaction(joint)->torque.z, share * torque, 0.4_fx));
    } else {
      ASSERT_EQ(early.size(), 1U);
      EXPECT_TRUE(later.empty());
      EXPECT_EQ(early[0].joint, joint);
      EXPECT_GT(length(early[0].reaction.torque), torque);
      EXPECT_LT(state(w, body).position.y, 5_fx - 2_fx);
    }
  }
}

// ---- Swing-twist under random torques ----

TEST(SimSwingTwistJoint, ShoulderHoldsItsConeAndTwistUnderRandomTorques) {
  // A ragdoll's shoulder: a 3 kg upper arm (a box 0.6 m x 0.12 m x 0.12 m) on a swing-twist joint
  // at its end, the twist axis along the arm (+x), cone 0.6 rad, twist +-0.4 rad, the torso
  // static. Gravity and a random torque (each component uniform in +-4 N m, a new one every 10
  // steps, from a seeded detsim Rng) throw it about for 10 s. The swing (the angle between the
  // axis as the torso and as the arm carry it) stays within the cone and the twist (the arm's
  // rotation about its axis, the swing taken out) within its range, each to 0.01 rad; the
  // shoulder's anchors within 5 mm.
  World w = make_world();
  const Vec3 shoulder{0_fx, 10_fx, 0_fx};
  const BodyId torso = add(w, post_at(shoulder));
  BodyDef arm;
  arm.shape = Shape::box({0.3_fx, 0.06_fx, 0.06_fx});
  arm.position = shoulder + Vec3{0.3_fx, 0_fx, 0_fx};
  arm.mass = 3_fx;
  const BodyId body = add(w, arm);
  JointDef d;
  d.type = JointType::swing_twist;
  d.body_a = torso;
  d.body_b = body;
  d.anchor = shoulder;
  d.axis = {1_fx, 0_fx, 0_fx};
  d.limit_enabled = true;
  d.swing_limit = 0.6_fx;
  d.limit_lower = -0.4_fx;
  d.limit_upper = 0.4_fx;
  const JointId joint = join(w, d);
  Rng rng(17);
  Vec3 torque;
  double swing = 0.0;
  double twist = 0.0;
  Fixed gap;
  for (std::int32_t i = 0; i < 600; ++i) {
    if (i % 10 == 0)
      torque = {rng.uniform(-4_fx, 4_fx), rng.uniform(-4_fx, 4_fx), rng.uniform(-4_fx, 4_fx)};
    ASSERT_TRUE(w.apply_torque(body, torque).ok());
    w.step();
    // The torso does not turn and the arm was created unrotated: the arm's orientation q is the
    // joint's rotation. Its swing is the angle between x and q x; its twist 2 atan2(q.v . x, q.w)
    // (the swing, about an axis across x, adds nothing along x).
    const Quat q = state(w, body).orientation;
    const Vec3 along = rotate(q, Vec3{1_fx, 0_fx, 0_fx});
    swing = std::max(swing, std::acos(std::min(1.0, along.x.to_double())));
    twist = std::max(twist, std::abs(2.0 * std::atan2(q.x.to_double(), q.w.to_double())));
    gap = max(gap, anchor_gap(w, joint));
  }
  EXPECT_LT(swing, 0.61);
  EXPECT_LT(twist, 0.41);
  EXPECT_GT(swing, 0.55);  // the torques did push it to its limits
  EXPECT_GT(twist, 0.35);
  EXPECT_LT(gap, 0.005_fx);
  EXPECT_TRUE(w.validate().ok()) << w.validate().message();
  std::cout << "[ shoulder ] largest swing " << swing << " rad (cone 0.6), twist " << twist
            << " rad (range 0.4), anchor gap " << to_string(gap) << " m\n";
}

// ---- Chains ----

// A chain of `links` 1 kg spheres (radius 0.1 m) hanging from a static body at `top` along
// `down`, `link` apart, the first joint at `top` and each next one half a link below a centre;
// with `end_mass` > 0, a sphere of that mass (radius 0.5 m) hangs 0.5 m below the last joint.
struct Chain {
  World w;
  std::vector<BodyId> bodies;
  std::vector<JointId> joints;
  std::vector<Fixed> masses;  ///< of bodies[i]

  Chain(const WorldDef& def, std::int32_t links, Fixed link, Fixed end_mass, Vec3 top, Vec3 down)
      : w(make_world(def)) {
    BodyId previous = add(w, post_at(top));
    Vec3 at = top;
    for (std::int32_t i = 0; i <= links; ++i) {
      const bool end = i == links;
      if (end && end_mass == 0_fx) break;
      const Fixed reach = end ? 0.5_fx : link / 2_fx;
      const Fixed mass = end ? end_mass : 1_fx;
      const BodyId body = add(w, sphere_at(at + down * reach, end ? 0.5_fx : 0.1_fx, mass));
      JointDef d;
      d.body_a = previous;
      d.body_b = body;
      d.anchor = at;
      joints.push_back(join(w, d));
      bodies.push_back(body);
      masses.push_back(mass);
      previous = body;
      at = at + down * link;
    }
  }

  [[nodiscard]] Fixed largest_gap() const {
    Fixed gap;
    for (const JointId j : joints)
      gap = max(gap, anchor_gap(w, j));
    return gap;
  }
  [[nodiscard]] Fixed largest_speed() const {
    Fixed speed;
    for (const BodyId b : bodies)
      speed = max(speed, length(state(w, b).linear_velocity));
    return speed;
  }
  // The give of joint i hanging at rest. The soft point block in its steady state holds a load F
  // with the anchors F / (m (2 pi f)^2) apart: its solve pass, after a warm start that cancels
  // gravity, adds -m s (bias_rate C) - i lambda = 0, and i / (s bias_rate) = 1 / (h omega^2)
  // (rows.hpp's make_soft), with lambda = F h. m is the joint's effective mass along the chain,
  // 1 / (1 / m_a + 1 / m_b) (the rows pass through both centres: no turning), F the weight below
  // it, f the joint spring's 60 Hz (joint_solver.cpp; at most a quarter of the sub-step rate).
  // A chain is a tree of joints, solved exactly (joint_tree.cpp): the steady state is the same
  // (the tree's right-hand side, -(bias_rate C_j) - i / s K_j lambda_j, is zero for every joint
  // at once), but it is reached slowly. Each sub-step the anchors part by h A (A + D)^-1 rhs:
  // for the chain stretching as a whole (the ball sinking), A's eigenvalue is far below the
  // softness D = (1 / s - 1) K_j, and the stretch relaxes with a time constant of seconds (30
  // links: 1.8 mm of 4.0 at 0.5 s, 3.9 at 5 s; the wrecking ball: 2.3 mm of 15 at 0.5 s, 14.2 at
  // 10 s, 15.0 at 20 s). The relax pass then takes the velocity away, so a body asleep after 0.5 s
  // keeps the smaller gap: the tests of the give run without sleep, long enough to reach it.
  [[nodiscard]] double resting_gap(std::size_t i) const {
    const double g = -w.def().gravity.y.to_double();
    double below = 0.0;
    for (std::size_t b = i; b < masses.size(); ++b)
      below += masses[b].to_double();
    const double m_b = masses[i].to_double();
    const double effective = i == 0 ? m_b : 1.0 / (1.0 / masses[i - 1].to_double() + 1.0 / m_b);
    const double rate = w.def().substeps / w.def().dt.to_double();
    const double omega = 2.0 * M_PI * std::min(60.0, rate / 4.0);
    return below * g / (effective * omega * omega);
  }
};

TEST(SimBallJoint, ThirtyLinkChainHangsStillFor10Seconds) {
  // 30 links of 0.5 m hanging: asleep at 10 s with every joint's anchors within its spring's give
  // and 5 mm, no body faster than 0.05 m/s (no jitter, no energy gained); and without sleep, at
  // 20 s, each within 5 % of its spring's give under the weight below it (resting_gap: 4.0 mm at
  // the second joint, 29 kg over 0.5 kg of effective mass; reached slowly, see resting_gap).
  {
    Chain asleep(WorldDef{}, 30, 0.5_fx, 0_fx, {0_fx, 20_fx, 0_fx}, {0_fx, -1_fx, 0_fx});
    for (std::int32_t i = 0; i < 600; ++i)
      asleep.w.step();
    for (std::size_t i = 0; i < asleep.joints.size(); ++i) {
      const double gap = anchor_gap(asleep.w, asleep.joints[i]).to_double();
      EXPECT_LT(gap, 1.05 * asleep.resting_gap(i)) << "joint " << i + 1;
      EXPECT_LT(gap, 0.005) << "joint " << i + 1;
    }
    EXPECT_LT(asleep.largest_speed(), 0.05_fx);
    std::cout << "[ hanging chain ] asleep at 10 s: largest anchor gap "
              << to_string(asleep.largest_gap()) << " m\n";
  }
  WorldDef def;
  def.enable_sleep = false;
  Chain chain(def, 30, 0.5_fx, 0_fx, {0_fx, 20_fx, 0_fx}, {0_fx, -1_fx, 0_fx});
  Fixed transient;
  for (std::int32_t i = 0; i < 1200; ++i) {
    chain.w.step();
    transient = max(transient, chain.largest_gap());
  }
  double largest = 0.0;
  for (std::size_t i = 0; i < chain.joints.size(); ++i) {
    const double gap = anchor_gap(chain.w, chain.joints[i]).to_double();
    const double expected = chain.resting_gap(i);
    EXPECT_LT(std::abs(gap - expected), 0.05 * expected) << "joint " << i + 1;
    EXPECT_LT(gap, 0.005) << "joint " << i + 1;
    largest = std::max(largest, gap);
  }
  EXPECT_LT(chain.largest_speed(), 0.05_fx);
  EXPECT_TRUE(chain.w.validate().ok()) << chain.w.validate().message();
  std::cout << "[ hanging chain ] largest anchor gap at 20 s " << largest << " m (formula "
            << chain.resting_gap(1) << " m), " << to_string(transient)
            << " m at most on the way; fastest body at 20 s " << to_string(chain.largest_speed())
            << " m/s\n";
}

TEST(SimBallJoint, WreckingBallOnALightChainHangsAtItsSpringsGive) {
  // Mass ratio 1:100 across a joint: ten 1 kg links of 0.5 m and a 100 kg ball, hanging at rest
  // for 40 s without sleep: every joint at its spring's give (resting_gap, within 5 %: 15 mm at
  // the second joint, 109 kg over 0.5 kg; reached slowly, see resting_gap), nothing moving.
  WorldDef def;
  def.enable_sleep = false;
  Chain chain(def, 10, 0.5_fx, 100_fx, {0_fx, 20_fx, 0_fx}, {0_fx, -1_fx, 0_fx});
  for (std::int32_t i = 0; i < 2400; ++i)
    chain.w.step();
  double largest = 0.0;
  for (std::size_t i = 0; i < chain.joints.size(); ++i) {
    const double gap = anchor_gap(chain.w, chain.joints[i]).to_double();
    EXPECT_LT(std::abs(gap - chain.resting_gap(i)), 0.05 * chain.resting_gap(i))
        << "joint " << i + 1;
    largest = std::max(largest, gap);
  }
  EXPECT_LT(chain.largest_speed(), 0.05_fx);
  std::cout << "[ wrecking ball ] hanging: largest anchor gap " << largest << " m (formula "
            << chain.resting_gap(1) << " m)\n";
}

TEST(SimBallJoint, WreckingBallSwingsAsAPendulum) {
  // The same chain and ball released from 30 degrees (straight): a pendulum of L = 5.5 m. The
  // ball's speed is at most sqrt(2 g L (1 - cos 30)) = 3.84 m/s, and no link, nearer the pivot,
  // may go faster (10 % allowed); the joints' give stays within 1.5 times that of the largest
  // load, the ball's weight and centripetal force at the bottom, M g (3 - 2 cos 30), over the
  // light joints' effective mass (resting_gap scaled); the ball never rises above its start.
  // With the default single iteration of Gauss-Seidel the light links flailed (27 m/s, anchors
  // 0.53 m apart; docs/SIM.md, "Joints", "Trees"): the chain is a tree, its point blocks solved
  // exactly.
  const WorldDef def;
  const Fixed angle = Fixed::pi() / 6_fx;
  Chain chain(def, 10, 0.5_fx, 100_fx, {0_fx, 20_fx, 0_fx}, {sin(angle), -cos(angle), 0_fx});
  const BodyId ball = chain.bodies.back();
  const Fixed start = state(chain.w, ball).position.y;
  const double g = -def.gravity.y.to_double();
  const double cos0 = std::cos(M_PI / 6.0);
  const double top_speed = std::sqrt(2.0 * g * 5.5 * (1.0 - cos0));
  const double largest_give = chain.resting_gap(1) * (3.0 - 2.0 * cos0);
  double gap = 0.0;
  double fastest = 0.0;
  Fixed highest = start;
  for (std::int32_t i = 0; i < 600; ++i) {
    chain.w.step();
    gap = std::max(gap, chain.largest_gap().to_double());
    fastest = std::max(fastest, chain.largest_speed().to_double());
    if (i > 60) highest = max(highest, state(chain.w, ball).position.y);
  }
  EXPECT_LT(fastest, 1.1 * top_speed);
  EXPECT_LT(gap, 1.5 * largest_give);
  EXPECT_LT(highest, start + 0.01_fx);
  EXPECT_TRUE(chain.w.validate().ok()) << chain.w.validate().message();
  std::cout << "[ wrecking ball ] swinging: largest anchor gap " << gap << " m (give at the "
            << "largest load " << largest_give << " m), fastest body " << fastest
            << " m/s (ball at most " << top_speed << "), highest " << to_string(highest - start)
            << " m above its start\n";
}

}  // namespace
}  // namespace detsim
