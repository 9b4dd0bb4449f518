// Joints (docs/SIM.md, "Joints"): the API's promises (refusals name the field and
// change nothing, IDs ascend, a destroyed body takes its joints along) and the physics of the
// solved joint types, with expectations derived from formulas (stated beside each), never from a
// previous run's output.
#include <cmath>
#include <cstdint>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

#include "support/sim_helpers.hpp"

namespace detsim {
namespace {

using namespace detsim::literals;

using test::add;
using test::make_world;
using test::near;
using test::state;

BodyDef ball_at(Vec3 p, Fixed radius, Fixed mass) {
  BodyDef d;
  d.shape = Shape::sphere(radius);
  d.position = p;
  d.mass = mass;
  return d;
}

// (Overloads, not default arguments: clang refuses a consteval literal in a default argument.)
BodyDef ball_at(Vec3 p, Fixed radius) {
  return ball_at(p, radius, 1_fx);
}

BodyDef ball_at(Vec3 p) {
  return ball_at(p, 0.1_fx, 1_fx);
}

BodyDef anchor_at(Vec3 p) {
  BodyDef d = ball_at(p);
  d.type = BodyType::static_body;
  return d;
}

JointId join(World& w, const JointDef& def) {
  auto id = w.create_joint(def);
  EXPECT_TRUE(id.ok()) << id.message();
  return id.ok() ? *id : JointId{};
}

// ---- The API ----

struct Refusal {
  const char* field;  // what the message must name
  JointDef def;
};

TEST(SimJoint, RefusesInvalidDefinitionsNamingTheFieldAndChangesNothing) {
  World w = make_world();
  const BodyId ground = add(w, anchor_at({0_fx, 5_fx, 0_fx}));
  const BodyId other_static = add(w, anchor_at({3_fx, 5_fx, 0_fx}));
  const BodyId ball = add(w, ball_at({0_fx, 3_fx, 0_fx}));
  JointDef good;
  good.body_a = ground;
  good.body_b = ball;
  good.anchor = {0_fx, 5_fx, 0_fx};
  const JointId first = join(w, good);
  const std::vector<std::uint8_t> before = w.save();

  std::vector<Refusal> cases;
  const auto with = [&](const char* field, auto change) {
    JointDef d = good;
    change(d);
    cases.push_back({field, d});
  };
  with("body_a", [](JointDef& d) { d.body_a = BodyId{}; });
  with("body_a", [](JointDef& d) { d.body_a = BodyId{99}; });
  with("body_b", [](JointDef& d) { d.body_b = BodyId{42}; });
  with("body_a and body_b", [&](JointDef& d) { d.body_a = ball; });
  with("both static", [&](JointDef& d) { d.body_b = other_static; });
  with("axis", [](JointDef& d) { d.axis = {}; });
  with("axis", [](JointDef& d) { d.axis = {1_fx, 1_fx, 0_fx}; });
  with("limit_lower", [](JointDef& d) {
    d.limit_lower = 1_fx;
    d.limit_upper = -1_fx;
  });
  with("swing_limit", [](JointDef& d) { d.swing_limit = -0.5_fx; });
  with("motor_max_force", [](JointDef& d) { d.motor_max_force = -1_fx; });
  with("min_length", [](JointDef& d) { d.min_length = -1_fx; });
  with("max_length", [](JointDef& d) { d.max_length = -1_fx; });
  with("min_length", [](JointDef& d) {
    d.min_length = 2_fx;
    d.max_length = 1_fx;
  });
  with("spring_frequency", [](JointDef& d) { d.spring_frequency = -1_fx; });
  with("spring_damping_ratio", [](JointDef& d) { d.spring_damping_ratio = -1_fx; });
  with("break_force", [](JointDef& d) { d.break_force = -1_fx; });
  with("break_torque", [](JointDef& d) { d.break_torque = -1_fx; });
  with("anchor", [](JointDef& d) { d.anchor = {0_fx, Fixed::max(), 0_fx}; });

  for (const Refusal& r : cases) {
    auto id = w.create_joint(r.def);
    ASSERT_FALSE(id.ok()) << "expected a refusal naming " << r.field;
    EXPECT_NE(id.message().find(r.field), std::string::npos)
        << "the message must name " << r.field << ": " << id.message();
    EXPECT_EQ(w.save(), before) << r.field;
    EXPECT_EQ(w.joint_ids(), std::vector<JointId>{first}) << r.field;
  }
}

TEST(SimJoint, IdsAscendInCreationOrderAndAreNeverReused) {
  World w = make_world();
  const BodyId ground = add(w, anchor_at({0_fx, 5_fx, 0_fx}));
  std::vector<BodyId> balls;
  for (std::int32_t i = 0; i < 3; ++i)
    balls.push_back(add(w, ball_at({Fixed::from_int(i), 3_fx, 0_fx})));
  JointDef d;
  d.body_a = ground;
  d.anchor = {0_fx, 5_fx, 0_fx};
  std::vector<JointId> ids;
  for (const BodyId b : balls) {
    d.body_b = b;
    ids.push_back(join(w, d));
  }
  EXPECT_EQ(ids, (std::vector<JointId>{{1}, {2}, {3}}));
  EXPECT_EQ(w.joint_ids(), ids);
  EXPECT_TRUE(w.destroy_joint(ids[1]).ok());
  EXPECT_FALSE(w.destroy_joint(ids[1]).ok());
  EXPECT_FALSE(w.joint(ids[1]).ok());
  d.body_b = balls[1];
  EXPECT_EQ(join(w, d), JointId{4});  // never reused
  EXPECT_EQ(w.joint_ids(), (std::vector<JointId>{{1}, {3}, {4}}));
  // The state keeps the definition and the anchor in each body's frame.
  const JointState j = *w.joint(JointId{4});
  EXPECT_EQ(j.def.body_b, balls[1]);
  EXPECT_EQ(j.local_anchor_a, Vec3{});
  EXPECT_EQ(j.local_anchor_b, (Vec3{-1_fx, 2_fx, 0_fx}));
  EXPECT_FALSE(j.broken);
}

TEST(SimJoint, DestroyingABodyRemovesItsJoints) {
  World w = make_world();
  const BodyId ground = add(w, anchor_at({0_fx, 5_fx, 0_fx}));
  const BodyId a = add(w, ball_at({0_fx, 4_fx, 0_fx}));
  const BodyId b = add(w, ball_at({0_fx, 3_fx, 0_fx}));
  JointDef d;
  d.body_a = ground;
  d.body_b = a;
  d.anchor = {0_fx, 5_fx, 0_fx};
  const JointId top = join(w, d);
  d.body_a = a;
  d.body_b = b;
  d.anchor = {0_fx, 3.5_fx, 0_fx};
  const JointId middle = join(w, d);
  d.body_a = ground;
  d.anchor = {0_fx, 5_fx, 0_fx};
  const JointId side = join(w, d);
  EXPECT_TRUE(w.destroy_body(a).ok());
  EXPECT_EQ(w.joint_ids(), std::vector<JointId>{side});
  EXPECT_FALSE(w.joint(top).ok());
  EXPECT_FALSE(w.joint(middle).ok());
}

TEST(SimJoint, ACopiedWorldStepsLikeTheOriginal) {
  // A world copy carries its joints (definitions and warm-start impulses): the copy and the
  // original give the same bytes and the same joint states step after step. (So does a save and
  // restore: tests/sim_joint_state_test.cpp.)
  World w = make_world();
  BodyId previous = add(w, anchor_at({0_fx, 10_fx, 0_fx}));
  for (std::int32_t i = 0; i < 5; ++i) {
    const BodyId body = add(w, ball_at({Fixed::from_int(i) + 0.5_fx, 10_fx, 0_fx}));
    JointDef d;
    d.type = i % 2 == 0 ? JointType::ball : JointType::hinge;
    d.axis = {0_fx, 0_fx, 1_fx};
    d.body_a = previous;
    d.body_b = body;
    d.anchor = {Fixed::from_int(i), 10_fx, 0_fx};
    join(w, d);
    previous = body;
  }
  for (std::int32_t i = 0; i < 30; ++i)
    w.step();
  World copy = w;
  for (std::int32_t i = 0; i < 60; ++i) {
    w.step();
    copy.step();
  }
  EXPECT_EQ(copy.save(), w.save());
  for (const JointId id : w.joint_ids())
    EXPECT_EQ(*copy.joint(id), *w.joint(id));
  EXPECT_NE(w.joint(JointId{1})->linear_impulse, Vec3{});  // the joints carry load
}

// ---- Ball joints ----

// The anchors' distance, world space: where the joint's anchor is on body a, and on body b.
Fixed anchor_gap(const World& w, JointId id) {
  const JointState j = *w.joint(id);
  const BodyState a = state(w, j.def.body_a);
  const BodyState b = state(w, j.def.body_b);
  const Vec3 pa = a.position + rotate(a.orientation, j.local_anchor_a);
  const Vec3 pb = b.position + rotate(b.orientation, j.local_anchor_b);
  return length(pb - pa);
}

TEST(SimBallJoint, PendulumSwingsWithThePeriodOfThePendulumFormula) {
  // A 1 kg sphere of radius r on a ball joint L = 2 m above its centre, released at rest 10
  // degrees from the vertical: a physical pendulum about the joint, with I = m L^2 + 2/5 m r^2
  // (the sphere turns with the swing). Small-amplitude period 2 pi sqrt(I / (m g L)), corrected
  // for the amplitude by (1 + theta0^2 / 16) (the next term, 11 theta0^4 / 3072, is 3e-6 here).
  // No damping: the amplitude should stay (the soft joint's spring may lose a little).
  World w = make_world();
  const Vec3 pivot{0_fx, 10_fx, 0_fx};
  const Fixed length = 2_fx;
  const Fixed radius = 0.1_fx;
  const Fixed theta0 = Fixed::pi() / 18_fx;  // 10 degrees
  const BodyId top = add(w, anchor_at(pivot));
  const BodyId bob =
      add(w, ball_at(pivot + Vec3{length * sin(theta0), -length * cos(theta0), 0_fx}, radius));
  JointDef d;
  d.body_a = top;
  d.body_b = bob;
  d.anchor = pivot;
  const JointId joint = join(w, d);

  const double g = -w.def().gravity.y.to_double();
  const double L = length.to_double();
  const double r = radius.to_double();
  const double t0 = theta0.to_double();
  const double inertia = L * L + 0.4 * r * r;  // per kg
  const double period = 2.0 * M_PI * std::sqrt(inertia / (g * L)) * (1.0 + t0 * t0 / 16.0);
  const double dt = w.def().dt.to_double();

  // The angle from the vertical, sampled every step; upward zero crossings (theta from < 0 to
  // >= 0) are timed by linear interpolation between the two steps.
  const auto angle = [&] {
    const Vec3 p = state(w, bob).position - pivot;
    return std::atan2(p.x.to_double(), -p.y.to_double());
  };
  std::vector<double> crossings;
  double previous = angle();
  double first_peak = 0.0;
  double last_peak = 0.0;
  const std::int32_t steps = static_cast<std::int32_t>(11.5 * period / dt);
  for (std::int32_t i = 1; i <= steps; ++i) {
    w.step();
    const double theta = angle();
    if (previous < 0.0 && theta >= 0.0)
      crossings.push_back(dt * (i - 1 + previous / (previous - theta)));
    if (crossings.empty()) first_peak = std::max(first_peak, std::abs(theta));
    if (crossings.size() >= 10) last_peak = std::max(last_peak, std::abs(theta));
    previous = theta;
  }
  ASSERT_GE(crossings.size(), 11U);
  const double measured = (crossings[10] - crossings[0]) / 10.0;
  const double period_error = std::abs(measured - period) / period;
  EXPECT_LT(period_error, 0.01) << "measured " << measured << " s, expected " << period << " s";
  // The first swing starts at theta0 itself; the peaks after ten swings are those of the eleventh.
  const double loss = 1.0 - last_peak / first_peak;
  EXPECT_LT(loss, 0.02) << "first peak " << first_peak << ", after ten swings " << last_peak;
  EXPECT_LT(anchor_gap(w, joint), 0.005_fx);
  std::cout << "[ pendulum ] period " << measured << " s, formula " << period << " s, error "
            << period_error * 100.0 << " %, amplitude loss " << loss * 100.0 << " %\n";
}

TEST(SimBallJoint, ThirtyLinkChainHoldsTogether) {
  // 30 links (1 kg spheres, anchors half a link either side of the centre), the first joined to a
  // static body, released horizontally: after 10 s of swinging down and hanging, every joint's
  // anchors are within 5 mm (the joint is a stiff spring: its sag under the whole chain's weight
  // is a fraction of a millimetre).
  World w = make_world();
  const Fixed link = 0.5_fx;
  const Vec3 top{0_fx, 20_fx, 0_fx};
  BodyId previous = add(w, anchor_at(top));
  std::vector<JointId> joints;
  for (std::int32_t i = 0; i < 30; ++i) {
    const Fixed x = link * Fixed::from_int(i);
    const BodyId body = add(w, ball_at(top + Vec3{x + link / 2_fx, 0_fx, 0_fx}));
    JointDef d;
    d.body_a = previous;
    d.body_b = body;
    d.anchor = top + Vec3{x, 0_fx, 0_fx};
    joints.push_back(join(w, d));
    previous = body;
  }
  Fixed worst;
  for (std::int32_t i = 0; i < 600; ++i) {
    w.step();
    for (const JointId j : joints)
      worst = max(worst, anchor_gap(w, j));
  }
  EXPECT_TRUE(w.validate().ok()) << w.validate().message();
  Fixed end;
  for (const JointId j : joints) {
    const Fixed gap = anchor_gap(w, j);
    EXPECT_LT(gap, 0.005_fx) << "joint " << j.value;
    end = max(end, gap);
  }
  std::cout << "[ chain ] largest anchor gap at 10 s " << to_string(end)
            << " m, largest during the run " << to_string(worst) << " m\n";
}

TEST(SimJoint, JoinedBodiesCollideOnlyWhenCollideConnected) {
  // Two overlapping spheres (0.5 m apart, radius 0.5): a contact, unless a joint joins them
  // without collide_connected.
  for (const bool collide : {false, true}) {
    WorldDef def;
    def.gravity = {};
    World w = make_world(def);
    const BodyId a = add(w, ball_at({0_fx, 0_fx, 0_fx}, 0.5_fx));
    const BodyId b = add(w, ball_at({0.5_fx, 0_fx, 0_fx}, 0.5_fx));
    JointDef d;
    d.body_a = a;
    d.body_b = b;
    d.anchor = {0.25_fx, 0_fx, 0_fx};
    d.collide_connected = collide;
    join(w, d);
    w.step();
    EXPECT_EQ(w.contacts().size(), collide ? 1U : 0U) << "collide_connected " << collide;
    // Without a contact, the joint holds them where they are.
    if (!collide) {
      EXPECT_EQ(state(w, b).position, (Vec3{0.5_fx, 0_fx, 0_fx}));
    }
  }
}

TEST(SimJoint, JoinedBodiesSleepAndWakeAsOneIsland) {
  // Two spheres hanging in a line from a static body, at rest: they fall asleep together (the
  // invariants hold after every step), and waking the lower one wakes the upper one at the next
  // step, though they never touch.
  World w = make_world();
  const BodyId top = add(w, anchor_at({0_fx, 10_fx, 0_fx}));
  const BodyId upper = add(w, ball_at({0_fx, 9_fx, 0_fx}));
  const BodyId lower = add(w, ball_at({0_fx, 8_fx, 0_fx}));
  JointDef d;
  d.body_a = top;
  d.body_b = upper;
  d.anchor = {0_fx, 10_fx, 0_fx};
  join(w, d);
  d.body_a = upper;
  d.body_b = lower;
  d.anchor = {0_fx, 8.5_fx, 0_fx};
  join(w, d);
  std::int32_t steps = 0;
  while (state(w, upper).awake && steps < 600) {
    w.step();
    ++steps;
    ASSERT_TRUE(w.validate().ok()) << w.validate().message();
  }
  EXPECT_FALSE(state(w, upper).awake);
  EXPECT_FALSE(state(w, lower).awake);
  EXPECT_TRUE(w.apply_linear_impulse(lower, {1_fx, 0_fx, 0_fx}).ok());
  EXPECT_FALSE(state(w, upper).awake);
  w.step();
  EXPECT_TRUE(state(w, upper).awake);
  EXPECT_TRUE(w.validate().ok()) << w.validate().message();
}

// ---- Distance joints ----

TEST(SimDistanceJoint, RigidRodSwingsWithTheSimplePendulumPeriod) {
  // A distance joint holds the sphere's centre L = 2 m from the pivot and leaves its rotation
  // free: a simple pendulum, period 2 pi sqrt(L / g) (1 + theta0^2 / 16) at 10 degrees.
  World w = make_world();
  const Vec3 pivot{0_fx, 10_fx, 0_fx};
  const Fixed length = 2_fx;
  const Fixed theta0 = Fixed::pi() / 18_fx;
  const BodyId top = add(w, anchor_at(pivot));
  const BodyId bob =
      add(w, ball_at(pivot + Vec3{length * sin(theta0), -length * cos(theta0), 0_fx}));
  JointDef d;
  d.type = JointType::distance;
  d.body_a = top;
  d.body_b = bob;
  d.anchor = pivot;
  const JointId joint = join(w, d);
  EXPECT_TRUE(near(w.joint(joint)->length, length, 0.000001_fx));

  const double g = -w.def().gravity.y.to_double();
  const double L = length.to_double();
  const double t0 = theta0.to_double();
  const double period = 2.0 * M_PI * std::sqrt(L / g) * (1.0 + t0 * t0 / 16.0);
  const double dt = w.def().dt.to_double();
  const auto angle = [&] {
    const Vec3 p = state(w, bob).position - pivot;
    return std::atan2(p.x.to_double(), -p.y.to_double());
  };
  std::vector<double> crossings;
  double previous = angle();
  double first_peak = 0.0;
  double last_peak = 0.0;
  const std::int32_t steps = static_cast<std::int32_t>(11.5 * period / dt);
  for (std::int32_t i = 1; i <= steps; ++i) {
    w.step();
    const double theta = angle();
    if (previous < 0.0 && theta >= 0.0)
      crossings.push_back(dt * (i - 1 + previous / (previous - theta)));
    if (crossings.empty()) first_peak = std::max(first_peak, std::abs(theta));
    if (crossings.size() >= 10) last_peak = std::max(last_peak, std::abs(theta));
    previous = theta;
  }
  ASSERT_GE(crossings.size(), 11U);
  const double measured = (crossings[10] - crossings[0]) / 10.0;
  const double period_error = std::abs(measured - period) / period;
  const double loss = 1.0 - last_peak / first_peak;
  EXPECT_LT(period_error, 0.01) << "measured " << measured << " s, expected " << period << " s";
  EXPECT_LT(loss, 0.02) << "first peak " << first_peak << ", after ten swings " << last_peak;
  EXPECT_TRUE(near(distance(state(w, bob).position, pivot), length, 0.005_fx));
  std::cout << "[ rod ] period " << measured << " s, formula " << period << " s, error "
            << period_error * 100.0 << " %, amplitude loss " << loss * 100.0 << " %\n";
}

TEST(SimDistanceJoint, ImpulsesCarryTheWeight) {
  // A 1 kg sphere hanging at rest on a rod, then on a rope: the joint carries its weight, so
  // the accumulated impulse per sub-step times the sub-step rate is m g = 9.81 N (pulling: the
  // rod's impulse is negative, the rope's upper end's too). A warm start that counted the impulse
  // twice once made a rod's grow step after step.
  for (const Fixed max_length : {0_fx, 2_fx}) {
    World w = make_world();
    const BodyId top = add(w, anchor_at({0_fx, 10_fx, 0_fx}));
    const BodyId bob = add(w, ball_at({0_fx, 8_fx, 0_fx}));
    JointDef d;
    d.type = JointType::distance;
    d.body_a = top;
    d.body_b = bob;
    d.anchor = {0_fx, 10_fx, 0_fx};
    d.max_length = max_length;
    const JointId joint = join(w, d);
    for (std::int32_t i = 0; i < 60; ++i)
      w.step();
    const Fixed rate = Fixed::from_int(static_cast<std::int32_t>(w.def().substeps)) / w.def().dt;
    const Fixed force = w.joint(joint)->axial_impulse * rate;
    EXPECT_TRUE(near(force, w.def().gravity.y, 0.1_fx)) << "max_length " << to_string(max_length);
  }
}

TEST(SimDistanceJoint, RopeIsSlackBelowItsLengthAndHoldsAtIt) {
  // A rope of 2 m (min_length 0, max_length 2) to a sphere released at rest 1 m below the pivot:
  // slack, so the sphere falls freely, y(t) = y0 - g t^2 / 2, until it has fallen 1 m
  // (t = sqrt(2 / g) = 0.45 s); then the rope holds it 2 m below the pivot.
  World w = make_world();
  const Vec3 pivot{0_fx, 10_fx, 0_fx};
  const BodyId top = add(w, anchor_at(pivot));
  const BodyId bob = add(w, ball_at(pivot - Vec3{0_fx, 1_fx, 0_fx}));
  JointDef d;
  d.type = JointType::distance;
  d.body_a = top;
  d.body_b = bob;
  d.anchor = pivot;
  d.min_length = 0_fx;
  d.max_length = 2_fx;
  join(w, d);
  const Fixed g = -w.def().gravity.y;
  for (std::int32_t i = 1; i <= 24; ++i) {  // 0.4 s: still falling freely
    w.step();
    const Fixed t = w.def().dt * Fixed::from_int(i);
    EXPECT_TRUE(near(state(w, bob).position.y, 9_fx - g * t * t / 2_fx, 0.0001_fx)) << i;
  }
  for (std::int32_t i = 0; i < 300; ++i)
    w.step();
  EXPECT_TRUE(near(state(w, bob).position.y, 8_fx, 0.005_fx));
  EXPECT_TRUE(w.validate().ok()) << w.validate().message();
}

TEST(SimDistanceJoint, SpringOscillatesWithItsFrequencyAndSettlesAtItsStretch) {
  // A 1 kg sphere hanging 2 m below a static body on a distance spring of 1 Hz (k = m (2 pi f)^2),
  // released at the spring's rest length: it oscillates about the stretched equilibrium
  // 2 + g / (2 pi f)^2 below the pivot with period 1 / f = 1 s; with damping ratio 0.5 it then
  // settles there.
  for (const Fixed zeta : {0_fx, 0.5_fx}) {
    World w = make_world();
    const Vec3 pivot{0_fx, 10_fx, 0_fx};
    const BodyId top = add(w, anchor_at(pivot));
    const BodyId bob = add(w, ball_at({0_fx, 8_fx, 0_fx}));
    JointDef d;
    d.type = JointType::distance;
    d.body_a = top;
    d.body_b = bob;
    d.anchor = pivot;
    d.spring_frequency = 1_fx;
    d.spring_damping_ratio = zeta;
    join(w, d);
    const double g = -w.def().gravity.y.to_double();
    const double omega = 2.0 * M_PI;
    const double equilibrium = 8.0 - g / (omega * omega);
    const double dt = w.def().dt.to_double();
    if (zeta == 0_fx) {
      // Upward crossings of the equilibrium, timed by linear interpolation.
      std::vector<double> crossings;
      double previous = state(w, bob).position.y.to_double() - equilibrium;
      for (std::int32_t i = 1; i <= 330; ++i) {
        w.step();
        const double y = state(w, bob).position.y.to_double() - equilibrium;
        if (previous < 0.0 && y >= 0.0)
          crossings.push_back(dt * (i - 1 + previous / (previous - y)));
        previous = y;
      }
      ASSERT_GE(crossings.size(), 5U);
      const double period = (crossings[4] - crossings[0]) / 4.0;
      EXPECT_LT(std::abs(period - 1.0), 0.01) << "period " << period << " s";
      std::cout << "[ spring ] period " << period << " s, formula 1 s\n";
    } else {
      for (std::int32_t i = 0; i < 600; ++i)
        w.step();
      EXPECT_LT(std::abs(state(w, bob).position.y.to_double() - equilibrium), 0.002);
    }
  }
}

// ---- Hinge joints ----

TEST(SimHingeJoint, PendulumAboutItsAxisSwingsWithThePendulumFormula) {
  // The ball joint's pendulum on a hinge about z, the axis it swings about: the hinge leaves that
  // rotation free, so the period is the same physical pendulum's, 2 pi sqrt(I / (m g L))
  // (1 + theta0^2 / 16) with I = m L^2 + 2/5 m r^2.
  World w = make_world();
  const Vec3 pivot{0_fx, 10_fx, 0_fx};
  const Fixed length = 2_fx;
  const Fixed radius = 0.1_fx;
  const Fixed theta0 = Fixed::pi() / 18_fx;
  const BodyId top = add(w, anchor_at(pivot));
  const BodyId bob =
      add(w, ball_at(pivot + Vec3{length * sin(theta0), -length * cos(theta0), 0_fx}, radius));
  JointDef d;
  d.type = JointType::hinge;
  d.body_a = top;
  d.body_b = bob;
  d.anchor = pivot;
  d.axis = {0_fx, 0_fx, 1_fx};
  const JointId joint = join(w, d);
  const double g = -w.def().gravity.y.to_double();
  const double L = length.to_double();
  const double r = radius.to_double();
  const double t0 = theta0.to_double();
  const double period =
      2.0 * M_PI * std::sqrt((L * L + 0.4 * r * r) / (g * L)) * (1.0 + t0 * t0 / 16.0);
  const double dt = w.def().dt.to_double();
  const auto angle = [&] {
    const Vec3 p = state(w, bob).position - pivot;
    return std::atan2(p.x.to_double(), -p.y.to_double());
  };
  std::vector<double> crossings;
  double previous = angle();
  const std::int32_t steps = static_cast<std::int32_t>(10.5 * period / dt);
  for (std::int32_t i = 1; i <= steps; ++i) {
    w.step();
    const double theta = angle();
    if (previous < 0.0 && theta >= 0.0)
      crossings.push_back(dt * (i - 1 + previous / (previous - theta)));
    previous = theta;
  }
  ASSERT_GE(crossings.size(), 10U);
  const double measured = (crossings[9] - crossings[0]) / 9.0;
  EXPECT_LT(std::abs(measured - period) / period, 0.01)
      << "measured " << measured << " s, expected " << period << " s";
  EXPECT_LT(anchor_gap(w, joint), 0.005_fx);
  // It stays in the plane across the axis.
  EXPECT_LT(abs(state(w, bob).position.z), 0.001_fx);
}

TEST(SimHingeJoint, DoorHoldsItsAxisAndTurnsFreelyAboutIt) {
  // A 10 kg door (1 m x 2 m x 0.1 m) on a vertical hinge along its edge, spun at 1 rad/s about
  // the hinge: gravity pulls the door's far edge down (a torque of m g 0.5 m across the axis),
  // which the hinge holds, and nothing acts about the axis, so the door keeps turning at 1 rad/s
  // (angular momentum about a fixed axis) with its axis vertical.
  World w = make_world();
  const BodyId post = add(w, anchor_at({0_fx, 1_fx, 0_fx}));
  BodyDef door;
  door.shape = Shape::box({0.5_fx, 1_fx, 0.05_fx});
  door.position = {0.6_fx, 1_fx, 0_fx};
  door.mass = 10_fx;
  const BodyId body = add(w, door);
  JointDef d;
  d.type = JointType::hinge;
  d.body_a = post;
  d.body_b = body;
  d.anchor = {0.1_fx, 1_fx, 0_fx};
  d.axis = {0_fx, 1_fx, 0_fx};
  const JointId joint = join(w, d);
  // The door's velocities for 1 rad/s about the hinge line: w = (0, 1, 0), v = w x (c - anchor).
  EXPECT_TRUE(w.set_angular_velocity(body, {0_fx, 1_fx, 0_fx}).ok());
  EXPECT_TRUE(
      w.set_linear_velocity(body, cross(Vec3{0_fx, 1_fx, 0_fx}, Vec3{0.5_fx, 0_fx, 0_fx})).ok());
  for (std::int32_t i = 0; i < 180; ++i) {
    w.step();
    const BodyState b = state(w, body);
    const Vec3 up = rotate(b.orientation, Vec3{0_fx, 1_fx, 0_fx});
    // Within 1 degree of vertical: cos(1 deg) = 0.99985.
    ASSERT_GT(up.y, 0.99985_fx) << "step " << i;
  }
  EXPECT_LT(anchor_gap(w, joint), 0.005_fx);
  EXPECT_TRUE(near(state(w, body).angular_velocity.y, 1_fx, 0.02_fx));
  EXPECT_TRUE(near(state(w, body).position.y, 1_fx, 0.005_fx));
}

TEST(SimJoint, BreaksBeyondItsBreakForce) {
  // A 1 kg sphere hanging on a ball joint with break_force 20 N: its weight (9.81 N) does not
  // break it; pulled down by 15 N more (24.81 N in all) it breaks, and the sphere then falls
  // freely (over 1 s, at least g / 2 * 1 s^2 = 4.9 m, more with the extra force).
  World w = make_world();
  const Vec3 pivot{0_fx, 10_fx, 0_fx};
  const BodyId top = add(w, anchor_at(pivot));
  const BodyId bob = add(w, ball_at({0_fx, 8_fx, 0_fx}));
  JointDef d;
  d.body_a = top;
  d.body_b = bob;
  d.anchor = pivot;
  d.break_force = 20_fx;
  const JointId joint = join(w, d);
  for (std::int32_t i = 0; i < 60; ++i)
    w.step();
  EXPECT_FALSE(w.joint(joint)->broken);
  EXPECT_TRUE(near(state(w, bob).position.y, 8_fx, 0.005_fx));
  std::int32_t steps = 0;
  while (!w.joint(joint)->broken && steps < 30) {
    EXPECT_TRUE(w.apply_force(bob, {0_fx, -15_fx, 0_fx}).ok());
    w.step();
    ++steps;
  }
  EXPECT_TRUE(w.joint(joint)->broken);
  EXPECT_LT(steps, 10);  // the spring takes up the extra load within a few steps
  for (std::int32_t i = 0; i < 60; ++i)
    w.step();
  EXPECT_LT(state(w, bob).position.y, 8_fx - 4.9_fx);
  EXPECT_TRUE(w.validate().ok()) << w.validate().message();
}

TEST(SimHingeJoint, MotorSpinsUpAtItsMaxTorqueThenHoldsItsSpeed) {
  // A 10 kg sphere of radius 0.5 m (I = 2/5 m r^2 = 1 kg m^2) hinged at its centre about z, its
  // motor at 5 rad/s with at most 2 N m: it spins up at tau / I = 2 rad/s^2 (2 rad/s at 1 s),
  // reaches 5 rad/s at 2.5 s and holds it.
  World w = make_world();
  const BodyId post = add(w, anchor_at({0_fx, 5_fx, 0_fx}));
  const BodyId wheel = add(w, ball_at({0_fx, 5_fx, 0_fx}, 0.5_fx, 10_fx));
  JointDef d;
  d.type = JointType::hinge;
  d.body_a = post;
  d.body_b = wheel;
  d.anchor = {0_fx, 5_fx, 0_fx};
  d.axis = {0_fx, 0_fx, 1_fx};
  d.motor_enabled = true;
  d.motor_speed = 5_fx;
  d.motor_max_force = 2_fx;
  const JointId joint = join(w, d);
  for (std::int32_t i = 0; i < 60; ++i)
    w.step();
  EXPECT_TRUE(near(state(w, wheel).angular_velocity.z, 2_fx, 0.04_fx));
  for (std::int32_t i = 0; i < 180; ++i)
    w.step();
  EXPECT_TRUE(near(state(w, wheel).angular_velocity.z, 5_fx, 0.01_fx));
  EXPECT_TRUE(near(state(w, wheel).angular_velocity.x, 0_fx, 0.001_fx));
  EXPECT_LT(anchor_gap(w, joint), 0.005_fx);
}

TEST(SimHingeJoint, LimitStopsTheSwing) {
  // A hinge pendulum (L = 2 m) hanging at rest, its limit +-0.1 rad, kicked sideways at 3 m/s:
  // free, it would swing to acos(1 - v^2 / (2 g L)) = 0.69 rad; the limit stops it at 0.1 rad
  // (within 0.01 rad, the soft stop's give) on both sides.
  World w = make_world();
  const Vec3 pivot{0_fx, 10_fx, 0_fx};
  const BodyId top = add(w, anchor_at(pivot));
  BodyDef bob = ball_at({0_fx, 8_fx, 0_fx});
  bob.linear_velocity = {3_fx, 0_fx, 0_fx};
  const BodyId body = add(w, bob);
  JointDef d;
  d.type = JointType::hinge;
  d.body_a = top;
  d.body_b = body;
  d.anchor = pivot;
  d.axis = {0_fx, 0_fx, 1_fx};
  d.limit_enabled = true;
  d.limit_lower = -0.1_fx;
  d.limit_upper = 0.1_fx;
  join(w, d);
  double largest = 0.0;
  double smallest = 0.0;
  for (std::int32_t i = 0; i < 180; ++i) {
    w.step();
    const Vec3 p = state(w, body).position - pivot;
    const double theta = std::atan2(p.x.to_double(), -p.y.to_double());
    largest = std::max(largest, theta);
    smallest = std::min(smallest, theta);
  }
  EXPECT_LT(largest, 0.11);
  EXPECT_GT(largest, 0.09);  // it did reach the limit
  EXPECT_GT(smallest, -0.11);
  // The stops take energy out (soft, damped), never put it in: the bob is slower than its kick.
  EXPECT_LT(length(state(w, body).linear_velocity), 3_fx);
  std::cout << "[ limit ] swing between " << smallest << " and " << largest << " rad, speed at 3 s "
            << to_string(length(state(w, body).linear_velocity)) << " m/s\n";
}

// ---- Slider joints ----

TEST(SimSliderJoint, SlidesDownItsAxisWithoutFrictionAndHoldsEverythingElse) {
  // A 2 kg box on a slider from a static body, the axis 30 degrees below horizontal, released at
  // rest: the slider carries the weight across the axis, so the box slides along it with the
  // frictionless incline's acceleration g sin 30 = g / 2, s(t) = g t^2 / 4, without turning or
  // leaving the axis (the joint spring's give: 5 mm).
  World w = make_world();
  const Vec3 start{0_fx, 10_fx, 0_fx};
  const BodyId rail = add(w, anchor_at({-1_fx, 10_fx, 0_fx}));
  BodyDef box;
  box.shape = Shape::box({0.2_fx, 0.1_fx, 0.1_fx});
  box.position = start;
  box.mass = 2_fx;
  const BodyId body = add(w, box);
  const Fixed angle = Fixed::pi() / 6_fx;
  const Vec3 axis{cos(angle), -sin(angle), 0_fx};
  JointDef d;
  d.type = JointType::slider;
  d.body_a = rail;
  d.body_b = body;
  d.anchor = start;
  d.axis = axis;
  join(w, d);
  for (std::int32_t i = 0; i < 60; ++i)
    w.step();
  const BodyState b = state(w, body);
  const Vec3 moved = b.position - start;
  const Fixed g = -w.def().gravity.y;
  const Fixed expected = g / 4_fx;  // t = 1 s
  EXPECT_TRUE(near(dot(moved, axis), expected, expected * 0.01_fx));
  EXPECT_LT(length(moved - axis * dot(moved, axis)), 0.005_fx);
  EXPECT_GT(abs(b.orientation.w), 0.99998_fx);  // turned by less than 0.5 degree
}

// ---- Swing-twist joints ----

TEST(SimSwingTwistJoint, ConeAndTwistLimitsHold) {
  // A sphere hanging 2 m below a swing-twist joint whose axis points down at it: kicked sideways
  // at 3 m/s (free, it would swing out to 0.69 rad), the cone of half-angle 0.2 rad stops it; spun
  // about the vertical at 5 rad/s, the twist range +-0.3 rad stops the spin. Without limits
  // (limit_enabled false) the joint is a ball joint and both go past.
  for (const bool limited : {true, false}) {
    World w = make_world();
    const Vec3 pivot{0_fx, 10_fx, 0_fx};
    const BodyId top = add(w, anchor_at(pivot));
    BodyDef bob = ball_at({0_fx, 8_fx, 0_fx});
    bob.linear_velocity = {3_fx, 0_fx, 0_fx};
    bob.angular_velocity = {0_fx, 5_fx, 0_fx};
    const BodyId body = add(w, bob);
    JointDef d;
    d.type = JointType::swing_twist;
    d.body_a = top;
    d.body_b = body;
    d.anchor = pivot;
    d.axis = {0_fx, -1_fx, 0_fx};
    d.limit_enabled = limited;
    d.swing_limit = 0.2_fx;
    d.limit_lower = -0.3_fx;
    d.limit_upper = 0.3_fx;
    join(w, d);
    double swing = 0.0;
    double twist = 0.0;
    for (std::int32_t i = 0; i < 120; ++i) {
      w.step();
      const BodyState b = state(w, body);
      const Vec3 p = b.position - pivot;
      swing = std::max(swing, std::acos(-p.y.to_double() / length(p).to_double()));
      // The twist: the body's rotation about its own hanging axis (the body's y through the
      // pivot), from its orientation's part along that axis.
      const Vec3 down = rotate(b.orientation, Vec3{0_fx, -1_fx, 0_fx});
      const double along = dot(b.orientation.vector(), down).to_double();
      twist = std::max(twist, std::abs(2.0 * std::atan2(-along, b.orientation.w.to_double())));
    }
    if (limited) {
      EXPECT_LT(swing, 0.21);
      EXPECT_GT(swing, 0.19);
      EXPECT_LT(twist, 0.31);
      EXPECT_GT(twist, 0.29);
      EXPECT_TRUE(w.validate().ok()) << w.validate().message();
      std::cout << "[ swing-twist ] largest swing " << swing << " rad (cone 0.2), twist " << twist
                << " rad (range 0.3)\n";
    } else {
      EXPECT_GT(swing, 0.5);
      EXPECT_GT(twist, 1.0);
    }
  }
}

// ---- Fixed joints ----

TEST(SimFixedJoint, CantileverHoldsItsPoseUnderGravity) {
  // A 10 kg beam (2 m x 0.2 m x 0.2 m) welded at its end to a static body, horizontal: the weld
  // carries its weight and the torque m g 1 m, so the beam stays where it was made (within the
  // joint spring's give: its anchors within 5 mm, its axis within 1 degree of horizontal).
  World w = make_world();
  const BodyId wall = add(w, anchor_at({0_fx, 5_fx, 0_fx}));
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
  for (std::int32_t i = 0; i < 120; ++i) {
    w.step();
    const Vec3 along = rotate(state(w, body).orientation, Vec3{1_fx, 0_fx, 0_fx});
    ASSERT_GT(along.x, 0.99985_fx) << "step " << i;  // cos(1 degree)
  }
  EXPECT_LT(anchor_gap(w, joint), 0.005_fx);
  EXPECT_TRUE(w.validate().ok()) << w.validate().message();
}

TEST(SimFixedJoint, WeldedPairTumblesAsOneBody) {
  // Two spheres welded side by side, thrown spinning in zero gravity: they keep their relative
  // pose (the second stays 1 m from the first along the first's x axis, within 5 mm).
  WorldDef def;
  def.gravity = {};
  World w = make_world(def);
  const BodyId a = add(w, ball_at({0_fx, 0_fx, 0_fx}, 0.3_fx));
  const BodyId b = add(w, ball_at({1_fx, 0_fx, 0_fx}, 0.3_fx));
  JointDef d;
  d.type = JointType::fixed;
  d.body_a = a;
  d.body_b = b;
  d.anchor = {0.5_fx, 0_fx, 0_fx};
  join(w, d);
  // Spinning about z through the pair's centre at 2 rad/s: v = w x r for each.
  const Vec3 spin{0_fx, 0_fx, 2_fx};
  for (const auto& [id, r] :
       {std::pair{a, Vec3{-0.5_fx, 0_fx, 0_fx}}, std::pair{b, Vec3{0.5_fx, 0_fx, 0_fx}}}) {
    EXPECT_TRUE(w.set_angular_velocity(id, spin).ok());
    EXPECT_TRUE(w.set_linear_velocity(id, cross(spin, r) + Vec3{1_fx, 0_fx, 0_fx}).ok());
  }
  for (std::int32_t i = 0; i < 120; ++i)
    w.step();
  const BodyState sa = state(w, a);
  const BodyState sb = state(w, b);
  const Vec3 expected = sa.position + rotate(sa.orientation, Vec3{1_fx, 0_fx, 0_fx});
  EXPECT_LT(length(sb.position - expected), 0.005_fx);
  // The orientations agree, and the pair has turned as one rigid body: 2 rad/s for 2 s, 4 rad
  // about z.
  const Quat relative = conjugate(sa.orientation) * sb.orientation;
  EXPECT_GT(abs(relative.w), 0.9999_fx);
  const Vec3 along = rotate(sa.orientation, Vec3{1_fx, 0_fx, 0_fx});
  EXPECT_TRUE(near(along.x, cos(4_fx), 0.02_fx));
  EXPECT_TRUE(near(along.y, sin(4_fx), 0.02_fx));
}

}  // namespace
}  // namespace detsim
