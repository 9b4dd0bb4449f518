// Physical behaviour of the stepper: each test builds a small scene through the public API and
// checks a law of motion or a promise of the solver, with expected values derived from physics
// (stated beside each), never from a previous run's output.
#include <cstdint>
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
using test::state;

Fixed kinetic_energy(const World& w) {
  Fixed e;
  for (const BodyId id : w.body_ids()) {
    const BodyState b = state(w, id);
    if (b.type != BodyType::dynamic) continue;
    const Vec3 wl = transpose(to_mat3(b.orientation)) * b.angular_velocity;  // body frame
    e += b.mass * length_squared(b.linear_velocity) / 2_fx;
    e += (b.inertia.x * wl.x * wl.x + b.inertia.y * wl.y * wl.y + b.inertia.z * wl.z * wl.z) / 2_fx;
  }
  return e;
}

TEST(SimFreeFall, FollowsTheExactParabola) {
  // Constant acceleration: v(t) = g t and y(t) = y0 + g t^2 / 2. The integrator moves positions by
  // the mean velocity of each sub-step, so both hold at every sub-step up to rounding: one rounding
  // of g h per sub-step for v, and of each position increment for y (n sub-steps, a few ulp each).
  World w = make_world();
  BodyDef d;
  d.position = {0_fx, 100_fx, 0_fx};
  const BodyId ball = add(w, d);
  const std::int32_t steps = 60;
  for (std::int32_t i = 0; i < steps; ++i)
    w.step();
  const std::int32_t n = steps * static_cast<std::int32_t>(w.def().substeps);
  const Fixed t = w.def().dt * Fixed::from_int(steps);
  const Fixed g = w.def().gravity.y;
  const BodyState b = state(w, ball);
  const Fixed tolerance = Fixed::from_raw(4 * n);
  EXPECT_TRUE(near(b.linear_velocity.y, g * t, tolerance));
  EXPECT_TRUE(near(b.position.y, 100_fx + g * t * t / 2_fx, tolerance));
  EXPECT_EQ(b.position.x, 0_fx);
  EXPECT_EQ(b.linear_velocity.x, 0_fx);
  // The same with a horizontal launch and a constant force: x(t) = v0 t + F t^2 / (2 m).
  World w2 = make_world();
  d.linear_velocity = {3_fx, 0_fx, 0_fx};
  d.mass = 2_fx;
  const BodyId thrown = add(w2, d);
  for (std::int32_t i = 0; i < steps; ++i) {
    ASSERT_TRUE(w2.apply_force(thrown, {4_fx, 0_fx, 0_fx}).ok());
    w2.step();
  }
  const BodyState b2 = state(w2, thrown);
  EXPECT_TRUE(near(b2.position.x, 3_fx * t + 4_fx * t * t / 4_fx, tolerance));
  EXPECT_TRUE(near(b2.linear_velocity.x, 3_fx + 2_fx * t, tolerance));
}

TEST(SimContact, SphereComesToRestOnThePlaneAndSleeps) {
  World w = make_world();
  add_ground(w);
  BodyDef d;
  d.position = {0_fx, 2_fx, 0_fx};
  const BodyId ball = add(w, d);
  for (int i = 0; i < 180; ++i)
    w.step();
  BodyState b = state(w, ball);
  // Resting: sunk by the linear slop plus the soft contact's sag under the ball's weight,
  // g / omega^2 with omega = 2 pi 60 Hz against a static body (0.07 mm); within one sag of that.
  const Fixed omega = Fixed::two_pi() * 60_fx;
  const Fixed sag = 9.81_fx / (omega * omega);
  EXPECT_TRUE(near(b.position.y, 0.5_fx - w.def().linear_slop - sag, sag))
      << to_string(b.position.y);
  EXPECT_LT(abs(b.linear_velocity.y), 0.05_fx);
  for (int i = 0; i < 120 && b.awake; ++i) {
    w.step();
    b = state(w, ball);
  }
  EXPECT_FALSE(b.awake) << "a sphere at rest on the ground must fall asleep";
  EXPECT_EQ(b.linear_velocity, Vec3{});
}

TEST(SimContact, BoxRestsFlatOnThePlaneWithoutDrift) {
  World w = make_world();
  add_ground(w);
  BodyDef d;
  d.shape = Shape::box({0.5_fx, 0.5_fx, 0.5_fx});
  d.position = {0_fx, 0.5_fx, 0_fx};
  const BodyId box = add(w, d);
  for (int i = 0; i < 300; ++i)
    w.step();
  const BodyState b = state(w, box);
  EXPECT_TRUE(near(b.position.y, (0.5_fx), (0.006_fx)));
  EXPECT_LT(abs(b.position.x), 0.001_fx);
  EXPECT_LT(abs(b.position.z), 0.001_fx);
  // Still upright: the local y axis stays within ~0.06 degrees of world y.
  EXPECT_GT(to_mat3(b.orientation).rows[1].y, 0.999999_fx);
}

// Drops a sphere of restitution e from height h0 (bottom 2 m above the ground at rest) and
// returns the highest point of its centre after the first bounce.
Fixed rebound_height(Fixed restitution) {
  WorldDef def;
  def.enable_sleep = false;
  World w = make_world(def);
  BodyDef g;
  g.type = BodyType::static_body;
  g.shape = Shape::plane();
  g.restitution = restitution;
  add(w, g);
  BodyDef d;
  d.position = {0_fx, 2.5_fx, 0_fx};
  d.restitution = restitution;
  const BodyId ball = add(w, d);
  bool bounced = false;
  Fixed peak;
  for (int i = 0; i < 240; ++i) {
    w.step();
    const BodyState b = state(w, ball);
    if (b.linear_velocity.y > 0_fx) bounced = true;
    if (bounced) peak = max(peak, b.position.y);
    if (bounced && b.linear_velocity.y < 0_fx) break;
  }
  return peak;
}

TEST(SimContact, ElasticSphereReboundsToItsDropHeight) {
  // e = 1: energy is conserved through the bounce, so the centre returns to 2.5 m (the bottom to
  // 2 m). The issue asks for >= 99% of the drop height of 2 m: centre >= 0.5 + 1.98.
  const Fixed peak = rebound_height(1_fx);
  EXPECT_GE(peak, 2.48_fx);
  EXPECT_LE(peak, 2.52_fx) << "a bounce must not add energy";
}

TEST(SimContact, InelasticSphereDoesNotBounce) {
  // e = 0: the normal velocity is removed at impact; the centre stays at the radius (+ slop).
  const Fixed peak = rebound_height(0_fx);
  EXPECT_LT(peak, 0.51_fx);
}

TEST(SimContact, MomentumIsConservedInAFreeCollision) {
  // Zero gravity, two spheres of different mass meet head on and off-centre: the total linear
  // momentum m1 v1 + m2 v2 is unchanged (only internal impulses act), to within rounding.
  WorldDef def;
  def.gravity = {};
  World w = make_world(def);
  BodyDef a;
  a.position = {-2_fx, 0_fx, 0_fx};
  a.linear_velocity = {3_fx, 0_fx, 0_fx};
  a.mass = 2_fx;
  a.restitution = 0.5_fx;
  BodyDef b = a;
  b.position = {2_fx, 0.3_fx, 0.1_fx};
  b.linear_velocity = {-1_fx, 0_fx, 0.5_fx};
  b.mass = 5_fx;
  const BodyId ia = add(w, a);
  const BodyId ib = add(w, b);
  const Vec3 before = a.linear_velocity * a.mass + b.linear_velocity * b.mass;
  bool touched = false;
  for (int i = 0; i < 120; ++i) {
    w.step();
    const BodyState sa = state(w, ia);
    const BodyState sb = state(w, ib);
    if (sa.linear_velocity != a.linear_velocity) touched = true;
    const Vec3 p = sa.linear_velocity * sa.mass + sb.linear_velocity * sb.mass;
    EXPECT_TRUE(near(p.x, before.x, (0.00001_fx))) << "step " << i;
    EXPECT_TRUE(near(p.y, before.y, (0.00001_fx))) << "step " << i;
    EXPECT_TRUE(near(p.z, before.z, (0.00001_fx))) << "step " << i;
  }
  EXPECT_TRUE(touched) << "the spheres must collide for this test to mean anything";
}

// No gravity, no friction, restitution 1 everywhere: twelve bodies rattle around a closed box of
// six planes for 10 s. Returns the initial kinetic energy and the largest seen after any step.
std::pair<Fixed, Fixed> rattle(bool spheres_only) {
  WorldDef def;
  def.gravity = {};
  def.enable_sleep = false;
  World w = make_world(def);
  const Vec3 axes[3] = {Vec3::unit_x(), Vec3::unit_y(), Vec3::unit_z()};
  for (int axis = 0; axis < 3; ++axis) {
    for (const Fixed sign : {1_fx, -1_fx}) {
      // A plane whose normal (its local +y) points inward, 3 m from the centre: the rotation
      // taking +y to n is the normalised quaternion (1 + y.n, y x n); for n = -y, a half turn.
      const Vec3 normal = axes[axis] * sign;
      BodyDef g;
      g.type = BodyType::static_body;
      g.shape = Shape::plane();
      g.orientation = normal.y == -1_fx
                          ? Quat{0_fx, 1_fx, 0_fx, 0_fx}
                          : normalize(Quat{1_fx + normal.y, normal.z, 0_fx, -normal.x});
      g.position = normal * -3_fx;
      g.friction = 0_fx;
      g.restitution = 1_fx;
      add(w, g);
    }
  }
  Rng rng(7);
  for (int i = 0; i < 12; ++i) {
    BodyDef d;
    d.shape =
        spheres_only || i % 2 == 0 ? Shape::sphere(0.3_fx) : Shape::box({0.25_fx, 0.2_fx, 0.3_fx});
    d.position = Vec3{Fixed::from_int(i % 3) - 1_fx, Fixed::from_int((i / 3) % 2) - 0.5_fx,
                      Fixed::from_int(i / 6) - 0.5_fx} *
                 1.5_fx;
    d.linear_velocity = rng.unit_vector() * 4_fx;
    d.friction = 0_fx;
    d.restitution = 1_fx;
    d.mass = 1_fx;
    add(w, d);
  }
  const Fixed initial = kinetic_energy(w);
  Fixed most = initial;
  for (int i = 0; i < 600; ++i) {
    w.step();
    most = max(most, kinetic_energy(w));
  }
  return {initial, most};
}

TEST(SimContact, EnergyNeverGrowsAmongElasticSpheres) {
  // Every collision is a single point: the energy may only fall (the soft contacts damp), apart
  // from rounding (a few ulp per step over 600 steps).
  const auto [initial, most] = rattle(true);
  EXPECT_LE(most, initial + 0.000001_fx);
}

TEST(SimContact, EnergyGrowthAmongElasticBoxesIsBounded) {
  // Boxes meet with several points at once; restitution acts at the centroid of a contact's
  // points. Measured: the energy can exceed the initial by about 0.5% transiently (an impact on an
  // edge that is still rotating onto a face). The bound here is 1%: docs/SIM.md lists this gap to
  // the "never grows".
  const auto [initial, most] = rattle(false);
  EXPECT_LE(most, initial + initial / 100_fx);
}

TEST(SimFriction, BoxOnASlopeSlidesExactlyWhenTanAngleExceedsMu) {
  // A plane tilted by theta about z with tan(theta) = 0.5 (theta = atan 0.5). A box at rest on it
  // stays when mu >= 0.5 and slides when mu < 0.5; the mixed friction is sqrt(mu_box mu_ground),
  // so both are set to mu.
  const Fixed theta = atan(0.5_fx);
  const Quat tilt = from_axis_angle(Vec3::unit_z(), theta);
  const Vec3 normal = rotate(tilt, Vec3::unit_y());
  const auto slide = [&](Fixed mu) {
    World w = make_world();
    add_ground(w, tilt, mu);
    BodyDef d;
    d.shape = Shape::box({0.5_fx, 0.5_fx, 0.5_fx});
    d.orientation = tilt;
    d.position = normal * 0.5_fx;
    d.friction = mu;
    const BodyId box = add(w, d);
    for (int i = 0; i < 120; ++i)
      w.step();
    return length(state(w, box).position - normal * 0.5_fx);
  };
  EXPECT_LT(slide(0.6_fx), 0.01_fx) << "mu = 0.6 > tan = 0.5: the box must hold";
  EXPECT_GT(slide(0.4_fx), 0.5_fx) << "mu = 0.4 < tan = 0.5: the box must slide";
  // Without friction it accelerates at g sin(theta) = 9.81 / sqrt(5) ~ 4.387 m/s^2: after 2 s,
  // s = a t^2 / 2 ~ 8.77 m (semi-implicit Euler adds a fraction of a percent).
  EXPECT_TRUE(near(slide(0_fx), (8.775_fx), (0.1_fx)));
}

TEST(SimStack, TenBoxesStandForTwentySecondsAndSleep) {
  // Ten 1 m boxes stacked on the ground. Soft contacts settle each box a few millimetres into the
  // one below within the first second; from then on nothing may move by 1 cm or more (no creep,
  // no jitter), no box may slide sideways by 1 cm, and the stack falls asleep.
  World w = make_world();
  add_ground(w);
  std::vector<BodyId> boxes;
  for (int i = 0; i < 10; ++i) {
    BodyDef d;
    d.shape = Shape::box({0.5_fx, 0.5_fx, 0.5_fx});
    d.position = {0_fx, Fixed::from_int(i) + 0.5_fx, 0_fx};
    boxes.push_back(add(w, d));
  }
  for (int i = 0; i < 60; ++i)
    w.step();
  std::vector<Vec3> settled;
  for (const BodyId id : boxes)
    settled.push_back(state(w, id).position);
  for (int i = 60; i < 20 * 60; ++i)
    w.step();
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const BodyState b = state(w, boxes[i]);
    EXPECT_LT(length(b.position - settled[i]), 0.01_fx) << "box " << i << " drifted";
    EXPECT_LT(abs(b.position.x), 0.01_fx) << "box " << i << " slid";
    EXPECT_LT(abs(b.position.z), 0.01_fx) << "box " << i << " slid";
    // Settling sinks each contact by the slop and the soft contact's give under its load.
    EXPECT_GT(b.position.y, Fixed::from_int(static_cast<std::int32_t>(i)) + 0.5_fx - 0.1_fx);
    EXPECT_FALSE(b.awake) << "box " << i << " is still awake after 20 s";
  }
}

TEST(SimDeterminism, SameInputsGiveTheSameHashesEveryFrame) {
  const auto run = [] {
    World w = make_world();
    add_ground(w);
    Rng rng(42);
    for (int i = 0; i < 20; ++i) {
      BodyDef d;
      d.shape = i % 3 == 0   ? Shape::sphere(0.4_fx)
                : i % 3 == 1 ? Shape::box({0.3_fx, 0.4_fx, 0.5_fx})
                             : Shape::capsule(0.25_fx, 0.4_fx);
      d.position = {rng.uniform(-2_fx, 2_fx), rng.uniform(1_fx, 8_fx), rng.uniform(-2_fx, 2_fx)};
      d.orientation = from_axis_angle(rng.unit_vector(), rng.uniform(0_fx, 3_fx));
      add(w, d);
    }
    std::vector<std::uint64_t> hashes;
    for (int i = 0; i < 300; ++i) {
      w.step();
      hashes.push_back(w.hashes().total);
    }
    return hashes;
  };
  EXPECT_EQ(run(), run());
}

}  // namespace
}  // namespace detsim
