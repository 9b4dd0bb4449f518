// Axis locks (BodyDef::lock_translation, lock_rotation): a locked world axis is infinite mass or
// inertia along it, in every row of the solver, so nothing moves the body along or about it.
//
// Expected values come from the physics: a locked coordinate stays exactly where it was (bit for
// bit: nothing may add to it); a body with all rotation locked slides down a slope with
// a = g (sin t - mu cos t) instead of rolling with (5/7) g sin t; a pendulum held in its plane by
// a lock swings with the plane pendulum's period; a body locked along the vertical is a floor to
// what lands on it; and a lock along an axis nothing moves along changes a motion by rounding
// only. Locks are state: saved, restored, hashed, named by diff and taken by --inject.
#include <array>
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
using test::near;
using test::placed;
using test::state;

Quat about(Vec3 axis, Fixed angle) {
  return from_axis_angle(axis, angle);
}

const Vec3 kX{1_fx, 0_fx, 0_fx};
const Vec3 kY{0_fx, 1_fx, 0_fx};
const Vec3 kZ{0_fx, 0_fx, 1_fx};

// A planar game's body (2D in the x-y plane): no motion along z, no turning about x or y. On a
// floor tilted both ways, an unlocked box would slide off along x and z; the locked one keeps its
// z and turns only about z, bit for bit, while it slides along x.
TEST(AxisLocks, APlanarBodyKeepsItsZAndTurnsOnlyAboutZ) {
  World w = make_world();
  add_ground(w, about(kZ, 0.3_fx) * about(kX, -0.3_fx), 0.2_fx);
  BodyDef d = placed(Shape::box({0.5_fx, 0.25_fx, 0.4_fx}), {0_fx, 2_fx, 0.75_fx});
  d.lock_translation.z = true;
  d.lock_rotation = {true, true, false};
  d.angular_velocity = {1_fx, 2_fx, 0.5_fx};  // the x and y parts are dropped at the first step
  const BodyId box = add(w, d);
  for (int i = 0; i < 300; ++i) {
    w.step();
    const BodyState b = state(w, box);
    ASSERT_EQ(b.position.z, 0.75_fx) << "frame " << i;
    ASSERT_EQ(b.orientation.x, 0_fx) << "frame " << i;
    ASSERT_EQ(b.orientation.y, 0_fx) << "frame " << i;
    ASSERT_EQ(b.linear_velocity.z, 0_fx);
    ASSERT_EQ(b.angular_velocity.x, 0_fx);
    ASSERT_EQ(b.angular_velocity.y, 0_fx);
  }
  EXPECT_LT(state(w, box).position.x, -1_fx);  // it did slide down the x slope
  EXPECT_TRUE(w.validate().ok());
}

// A sphere whose rotation is locked cannot roll: on a 30 degree slope with friction 0.1 it slides
// with a = g (sin t - mu cos t); unlocked, it rolls with (5/7) g sin t (mu = 0.1 is enough to
// roll without slipping: mu >= (2/7) tan t = 0.165... is not met, so the free one is not
// checked against rolling; only that it turns).
TEST(AxisLocks, ASphereWithRotationLockedSlidesInsteadOfRolling) {
  const Fixed theta = Fixed::pi() / 6_fx;
  const Fixed mu = 0.1_fx;
  World w = make_world();
  const Quat tilt = about(kZ, theta);
  add_ground(w, tilt, mu);
  const Vec3 normal = rotate(tilt, kY);
  const Vec3 down_slope = rotate(tilt, {-1_fx, 0_fx, 0_fx});
  BodyDef d = placed(Shape::sphere(0.5_fx), normal * 0.5_fx);
  d.friction = mu;
  d.lock_rotation = {true, true, true};
  const BodyId ball = add(w, d);
  // Settle onto the slope for a step, then measure 1 s of sliding from there.
  w.step();
  const Vec3 start = state(w, ball).position;
  const Fixed v0 = dot(state(w, ball).linear_velocity, down_slope);
  for (int i = 0; i < 60; ++i)
    w.step();
  const BodyState b = state(w, ball);
  const Fixed g = 9.80665_fx;
  const Fixed a = g * (sin(theta) - mu * cos(theta));
  const Fixed expected = v0 + a / 2_fx;  // v0 t + a t^2 / 2 at t = 1 s
  EXPECT_TRUE(near(dot(b.position - start, down_slope), expected, expected / 50_fx));
  EXPECT_EQ(b.orientation, Quat{});
  EXPECT_EQ(b.angular_velocity, Vec3::zero());
}

// A locked vertical axis is a floor: gravity does not move the body, and a ball dropped on it
// comes to rest on top of it as on a static box, the locked box not moving at all.
TEST(AxisLocks, ABodyLockedVerticallyHoldsWhatLandsOnIt) {
  World w = make_world();
  BodyDef shelf = placed(Shape::box({1_fx, 0.1_fx, 1_fx}), {0_fx, 1_fx, 0_fx});
  shelf.lock_translation = {true, true, true};
  shelf.lock_rotation = {true, true, true};
  shelf.mass = 1_fx;  // far lighter than the ball: only the locks hold it
  const BodyId held = add(w, shelf);
  BodyDef ball = placed(Shape::sphere(0.25_fx), {0.3_fx, 3_fx, 0_fx});
  ball.mass = 100_fx;
  const BodyId dropped = add(w, ball);
  for (int i = 0; i < 240; ++i)
    w.step();
  const BodyState s = state(w, held);
  const Vec3 placed_at{0_fx, 1_fx, 0_fx};
  EXPECT_EQ(s.position, placed_at);
  EXPECT_EQ(s.orientation, Quat{});
  // At rest on the top face (y = 1.1) within the contact's soft range.
  const BodyState b = state(w, dropped);
  EXPECT_TRUE(near(b.position.y, 1.35_fx, w.def().speculative_distance));
  EXPECT_LT(length(b.linear_velocity), 0.01_fx);
}

// A pendulum bob locked to the x-y plane, started with a sideways (z) push that the lock drops,
// swings in the plane with the period 2 pi sqrt(L / g) (1 + theta0^2 / 16) of a plane pendulum.
TEST(AxisLocks, APendulumHeldInItsPlaneKeepsThePlanePendulumsPeriod) {
  World w = make_world();
  BodyDef pivot_def = placed(Shape::sphere(0.05_fx), {0_fx, 5_fx, 0_fx});
  pivot_def.type = BodyType::static_body;
  const BodyId pivot = add(w, pivot_def);
  const Fixed length_m = 2_fx;
  const Fixed theta0 = 0.2_fx;
  BodyDef bob_def =
      placed(Shape::sphere(0.05_fx), {length_m * sin(theta0), 5_fx - length_m * cos(theta0), 0_fx});
  bob_def.lock_translation.z = true;
  bob_def.lock_rotation = {true, true, false};
  bob_def.linear_velocity = {0_fx, 0_fx, 3_fx};
  const BodyId bob = add(w, bob_def);
  JointDef j;
  j.type = JointType::ball;
  j.body_a = pivot;
  j.body_b = bob;
  j.anchor = {0_fx, 5_fx, 0_fx};
  ASSERT_TRUE(w.create_joint(j).ok());
  // Time between the first two crossings of x = 0 from + to -: one period.
  std::vector<Fixed> crossings;
  Fixed last_x = state(w, bob).position.x;
  for (int i = 0; i < 600 && crossings.size() < 2; ++i) {
    w.step();
    const BodyState b = state(w, bob);
    ASSERT_EQ(b.position.z, 0_fx);
    if (last_x > 0_fx && b.position.x <= 0_fx) {
      // Linear interpolation within the frame.
      const Fixed f = last_x / (last_x - b.position.x);
      crossings.push_back((Fixed::from_int(i) + f) * w.def().dt);
    }
    last_x = b.position.x;
  }
  ASSERT_EQ(crossings.size(), 2U);
  const Fixed g = 9.80665_fx;
  // The bob is a small ball: I = (2/5) m r^2 adds (2/5) r^2 / L^2 = 0.0125 % to L; left out.
  const Fixed period = Fixed::two_pi() * sqrt(length_m / g) * (1_fx + theta0 * theta0 / 16_fx);
  EXPECT_TRUE(near(crossings[1] - crossings[0], period, period / 100_fx));
}

// A lock along an axis that nothing moves the body along changes its motion by rounding only: a
// ball rolling and a box sliding down a slope in the x-y plane, with and without z (and, for the
// box, x and y rotation) locked, end within a millimetre of each other after 2 s.
TEST(AxisLocks, ALockNothingPushesAgainstChangesOnlyRounding) {
  const auto run = [](const Shape& shape, Quat orientation, bool locked) {
    World w = make_world();
    const Quat tilt = about(kZ, 0.4_fx);
    add_ground(w, tilt, 0.2_fx);
    BodyDef d = placed(shape, rotate(tilt, {0_fx, 0.5_fx, 0_fx}), tilt * orientation);
    d.friction = 0.2_fx;
    d.lock_translation.z = locked;
    d.lock_rotation = {locked && shape.type == ShapeType::box,
                       locked && shape.type == ShapeType::box, false};
    const BodyId body = add(w, d);
    for (int i = 0; i < 120; ++i)
      w.step();
    return state(w, body).position;
  };
  for (const Shape& shape : {Shape::sphere(0.5_fx), Shape::box({0.5_fx, 0.5_fx, 0.5_fx})}) {
    const Vec3 free = run(shape, {}, false);
    const Vec3 locked = run(shape, {}, true);
    EXPECT_TRUE(near(locked.x, free.x, 0.001_fx)) << static_cast<int>(shape.type);
    EXPECT_TRUE(near(locked.y, free.y, 0.001_fx)) << static_cast<int>(shape.type);
    EXPECT_EQ(locked.z, 0_fx);
    EXPECT_LT(free.x, -2_fx);  // it did move down the slope
  }
}

// Locks are state: a world saved mid-motion restores to the same hashes as the uninterrupted run,
// and diff names a lock that differs (like every property, a lock is not an --inject field).
TEST(AxisLocks, LocksAreSavedHashedAndDiffed) {
  const auto build = [](AxisLocks rotation) {
    World w = make_world();
    add_ground(w, about(kZ, 0.3_fx), 0.3_fx);
    BodyDef d = placed(Shape::capsule(0.2_fx, 0.4_fx), {0_fx, 2_fx, 0_fx}, about(kX, 0.5_fx));
    d.lock_translation.z = true;
    d.lock_rotation = rotation;
    add(w, d);
    return w;
  };
  const AxisLocks x_and_z{true, false, true};
  World straight = build(x_and_z);
  World resumed = build(x_and_z);
  for (int i = 0; i < 40; ++i) {
    straight.step();
    resumed.step();
  }
  const std::vector<std::uint8_t> mid = resumed.save();
  World restored = make_world();
  ASSERT_TRUE(restored.restore(mid).ok());
  for (int i = 0; i < 80; ++i) {
    straight.step();
    restored.step();
    ASSERT_EQ(straight.hashes(), restored.hashes()) << "frame " << i;
  }

  // The same world with one lock more differs in exactly that field of that body.
  const World other = build({true, true, true});
  const BodyId capsule = other.body_ids()[1];
  const auto diff = diff_states(build(x_and_z).save(), other.save());
  ASSERT_TRUE(diff.ok()) << diff.message();
  ASSERT_EQ(diff->fields.size(), 1U);
  EXPECT_EQ(diff->fields[0].field, "lock_rotation_y");
  EXPECT_EQ(diff->fields[0].body, capsule.value);
}

}  // namespace
}  // namespace detsim
