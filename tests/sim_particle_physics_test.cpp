// Particles (docs/PARTICLES.md): ropes and cloth against the physics — a catenary, a pendulum's
// period, an inextensible sheet's strain, a compliant rope's stretch under a load, a rope that
// stops a body, tearing above and only above its strain. Every expectation is derived from a
// formula stated beside it, never read back from a run.
#include <cmath>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

#include "support/sim_helpers.hpp"

namespace detsim {
namespace {

using namespace detsim::literals;

using test::add;
using test::make_world;
using test::state;

double d(Fixed x) {
  return x.to_double();
}

BodyId add_post(World& w, Vec3 at) {
  BodyDef post;
  post.type = BodyType::static_body;
  post.shape = Shape::sphere(0.05_fx);
  post.position = at;
  return add(w, post);
}

std::vector<Vec3> positions(const World& w, ParticleGroupId id) {
  auto p = w.particle_positions(id);
  EXPECT_TRUE(p.ok()) << p.message();
  return p.ok() ? *p : std::vector<Vec3>{};
}

// A rope of length L hanging between two points at the same height, a span S apart, takes the
// catenary y = a cosh(x / a) + c with L = 2 a sinh(S / 2a): its sag is a (cosh(S / 2a) - 1).
// Every particle lies on that curve within 2 % of the sag.
TEST(Rope, HangsAsTheCatenaryOfItsLength) {
  World w = make_world();
  const double span = 4.0;
  const double rope_length = 5.0;
  const BodyId left = add_post(w, {-2_fx, 5_fx, 0_fx});
  const BodyId right = add_post(w, {2_fx, 5_fx, 0_fx});
  RopeDef rope;
  rope.start = {-2_fx, 5_fx, 0_fx};
  rope.end = {2_fx, 5_fx, 0_fx};
  rope.length = 5_fx;
  rope.segments = 60;
  rope.mass = 1_fx;
  rope.attach_start = left;
  rope.attach_end = right;
  rope.settings.damping = 2_fx;
  rope.settings.mask = 0;  // hangs free of the posts
  auto id = w.create_rope(rope);
  ASSERT_TRUE(id.ok()) << id.message();
  for (int i = 0; i < 600; ++i)
    w.step();
  // a from L = 2 a sinh(S / 2a), by bisection (the right side falls as a grows).
  double lo = 0.1;
  double hi = 100.0;
  for (int i = 0; i < 200; ++i) {
    const double a = (lo + hi) / 2;
    (2 * a * std::sinh(span / (2 * a)) > rope_length ? lo : hi) = a;
  }
  const double a = (lo + hi) / 2;
  const double sag = a * (std::cosh(span / (2 * a)) - 1);
  const std::vector<Vec3> p = positions(w, *id);
  double worst = 0;
  for (const Vec3& q : p) {
    const double x = d(q.x);
    const double expected = 5.0 - sag + a * (std::cosh(x / a) - 1);
    worst = std::max(worst, std::abs(d(q.y) - expected));
  }
  EXPECT_LT(worst, 0.02 * sag) << "sag " << sag << " m, lowest particle at "
                               << d(p[p.size() / 2].y);
}

// A heavy ball on a light inextensible rope swings with the simple pendulum's period
// 2 pi sqrt(L / g) at a small angle (the amplitude's correction, theta^2 / 16, is 1.6e-4 at
// 0.05 rad): within 1 %.
TEST(Rope, PendulumSwingsWithThePeriodOfItsLength) {
  World w = make_world();
  const Fixed length = 2_fx;
  const double theta = 0.05;
  const BodyId post = add_post(w, {0_fx, 5_fx, 0_fx});
  BodyDef ball;
  ball.shape = Shape::sphere(0.1_fx);
  ball.mass = 10_fx;
  ball.position = {length * sin(0.05_fx), 5_fx - length * cos(0.05_fx), 0_fx};
  const BodyId bob = add(w, ball);
  RopeDef rope;
  rope.start = {0_fx, 5_fx, 0_fx};
  rope.end = ball.position;
  rope.length = length;
  rope.segments = 16;
  rope.mass = 0.01_fx;
  rope.attach_start = post;
  rope.attach_end = bob;
  rope.settings.mask = 0;
  ASSERT_TRUE(w.create_rope(rope).ok());
  // Upward zero crossings of x: the period is the mean spacing of the crossings.
  std::vector<double> crossings;
  double previous = d(state(w, bob).position.x);
  const double dt = d(w.def().dt);
  for (int i = 1; i <= 60 * 12; ++i) {
    w.step();
    const double x = d(state(w, bob).position.x);
    if (previous < 0 && x >= 0) crossings.push_back(dt * (i - 1 + previous / (previous - x)));
    previous = x;
  }
  ASSERT_GE(crossings.size(), 3U);
  const double period = (crossings.back() - crossings.front()) / double(crossings.size() - 1);
  const double expected = 2 * M_PI * std::sqrt(2.0 / 9.81) * (1 + theta * theta / 16);
  EXPECT_NEAR(period, expected, 0.01 * expected);
}

// A sheet pinned at two corners at stretch compliance 0 (and some air drag, so that it stops
// swinging), after 5 s: no edge longer than its rest length by 2 % at any frame of the last
// second, and the sheet hangs its full 2 m below the pins.
TEST(Cloth, PinnedSheetHoldsItsEdgesWithinTwoPercent) {
  World w = make_world();
  ClothDef cloth;
  cloth.origin = {0_fx, 5_fx, 0_fx};
  cloth.axis_u = {2_fx, 0_fx, 0_fx};
  cloth.axis_v = {0_fx, 0_fx, 2_fx};
  cloth.columns = 20;
  cloth.rows = 20;
  cloth.mass = 1_fx;
  cloth.pinned = {0, 19};
  cloth.settings.damping = 1_fx;
  auto id = w.create_cloth(cloth);
  ASSERT_TRUE(id.ok()) << id.message();
  double worst = 0;
  for (int i = 1; i <= 300; ++i) {
    w.step();
    auto stats = w.particle_group_stats(*id);
    ASSERT_TRUE(stats.ok());
    if (i > 240) worst = std::max(worst, d(stats->max_strain));
  }
  EXPECT_LT(worst, 0.02);
  // The corner under a pin hangs the sheet's length below it (inextensible, straight down).
  EXPECT_NEAR(d(positions(w, *id)[399].y), 3.0, 0.04);
}

// A 10 kg box on a rope of compliance c stretches it by m g c (the rope's own 10 g adds at most
// 0.1 %): within 3 % of that stretch.
TEST(Rope, CompliantRopeStretchesByTheLoadTimesItsCompliance) {
  World w = make_world();
  const BodyId post = add_post(w, {0_fx, 5_fx, 0_fx});
  BodyDef box;
  box.shape = Shape::box({0.1_fx, 0.1_fx, 0.1_fx});
  box.mass = 10_fx;
  box.position = {0_fx, 3_fx, 0_fx};
  box.linear_damping = 1_fx;
  const BodyId load = add(w, box);
  RopeDef rope;
  rope.start = {0_fx, 5_fx, 0_fx};
  rope.end = {0_fx, 3.1_fx, 0_fx};
  rope.segments = 20;
  rope.mass = 0.01_fx;
  rope.compliance = 0.001_fx;
  rope.attach_start = post;
  rope.attach_end = load;
  rope.settings.mask = 0;
  rope.settings.damping = 2_fx;
  ASSERT_TRUE(w.create_rope(rope).ok());
  for (int i = 0; i < 600; ++i)
    w.step();
  const double stretch = 3.0 - d(state(w, load).position.y);
  const double expected = 10 * 9.81 * 0.001;
  EXPECT_NEAR(stretch, expected, 0.03 * expected);
}

// A body thrown away from a post it is tied to stops at the rope's length: the rope takes its
// momentum (without gravity).
TEST(Rope, StopsABodyAtItsLength) {
  WorldDef def;
  def.gravity = {};
  World w = make_world(def);
  const BodyId post = add_post(w, {0_fx, 0_fx, 0_fx});
  BodyDef ball;
  ball.shape = Shape::sphere(0.1_fx);
  ball.mass = 1_fx;
  ball.position = {1_fx, 0_fx, 0_fx};
  ball.linear_velocity = {3_fx, 0_fx, 0_fx};
  const BodyId body = add(w, ball);
  RopeDef rope;
  rope.start = {};
  rope.end = ball.position;
  rope.length = 2_fx;
  rope.segments = 20;
  rope.mass = 0.01_fx;
  rope.attach_start = post;
  rope.attach_end = body;
  rope.settings.mask = 0;
  ASSERT_TRUE(w.create_rope(rope).ok());
  double farthest = 0;
  for (int i = 0; i < 120; ++i) {
    w.step();
    farthest = std::max(farthest, d(state(w, body).position.x));
  }
  EXPECT_LT(farthest, 2.0 * 1.01);
  EXPECT_GT(farthest, 1.9);
  EXPECT_LE(d(state(w, body).linear_velocity.x), 0.01);
}

// A rope hanging from a dynamic body pulls it: a free body in zero gravity with a rope whose far
// end is held by a force moves towards that force (momentum conserved: the pulled body and rope
// together gain what the force gives).
TEST(Rope, PullsTheBodyItIsAttachedTo) {
  WorldDef def;
  def.gravity = {};
  World w = make_world(def);
  BodyDef ball;
  ball.shape = Shape::sphere(0.1_fx);
  ball.mass = 1_fx;
  const BodyId body = add(w, ball);
  RopeDef rope;
  rope.start = {};
  rope.end = {1_fx, 0_fx, 0_fx};
  rope.segments = 10;
  rope.mass = 0.1_fx;
  rope.attach_start = body;
  rope.settings.mask = 0;
  auto id = w.create_rope(rope);
  ASSERT_TRUE(id.ok());
  // 1.1 N on the rope's 11 particles (0.1 N each, the attached one's passed to the body) for 1 s:
  // 1.1 N s shared by a 1.1 kg system, about 1 m/s for all of it once the rope is taut.
  for (int i = 0; i < 60; ++i) {
    ASSERT_TRUE(w.apply_particle_force(*id, {1.1_fx, 0_fx, 0_fx}).ok());
    w.step();
  }
  const double v = d(state(w, body).linear_velocity.x);
  EXPECT_GT(v, 0.5);
  EXPECT_LT(v, 1.2);
}

// A sheet hung by its top row, of stretch compliance c, pulled down by F: across the top row's
// gap, its C vertical edges take delta / c each and its 2 (C - 1) diagonals delta cos^2(theta) / c
// vertically (theta from the vertical), so delta = F c / (C + 2 (C - 1) cos^2 theta) and the
// edges' strain is delta / s. With C = 3, s = u = 0.2 m (cos^2 = 1/2), c = 0.001 m/N: strain =
// F * 0.001. It tears (at tear_strain 0.1) under F = 400 N (strain 0.4) and never under
// F = 40 N (strain 0.04), the force ramped in over a second so that nothing overshoots.
Fixed pulled_until_torn(Fixed force) {
  World w = make_world();
  ClothDef cloth;
  cloth.origin = {0_fx, 5_fx, 0_fx};
  cloth.axis_u = {0.4_fx, 0_fx, 0_fx};
  cloth.axis_v = {0_fx, -1_fx, 0_fx};
  cloth.columns = 3;
  cloth.rows = 6;
  cloth.mass = 0.1_fx;
  cloth.stretch_compliance = 0.001_fx;
  cloth.bend_compliance = 1000_fx;
  cloth.tear_strain = 0.1_fx;
  cloth.pinned = {0, 1, 2};
  cloth.settings.damping = 5_fx;
  auto id = w.create_cloth(cloth);
  EXPECT_TRUE(id.ok()) << id.message();
  if (!id.ok()) return {};
  for (int i = 1; i <= 180; ++i) {
    const Fixed ramp = min(Fixed::from_int(i) / 60_fx, 1_fx);
    EXPECT_TRUE(w.apply_particle_force(*id, {0_fx, -force * ramp, 0_fx}).ok());
    w.step();
  }
  const ParticleGroupStats st = w.particle_group_stats(*id).value();
  return Fixed::from_int(static_cast<std::int32_t>(st.broken_count));
}

TEST(Cloth, TearsUnderAPullBeyondItsTearStrainAndNeverBelow) {
  EXPECT_EQ(pulled_until_torn(40_fx), 0_fx);
  EXPECT_GT(pulled_until_torn(400_fx), 0_fx);
}

// A soft cube dropped on the ground, at volume compliance 0, after 5 s: its volume within 3 % of
// its rest volume, and still (no particle faster than 1 mm/s) on the ground (its lowest particle
// a particle radius, half a cell, above it).
TEST(SoftBody, RestsOnTheGroundKeepingItsVolumeWithoutJitter) {
  World w = make_world();
  BodyDef ground;
  ground.type = BodyType::static_body;
  ground.shape = Shape::plane();
  add(w, ground);
  SoftBodyDef cube;
  cube.shape = Shape::box({0.25_fx, 0.25_fx, 0.25_fx});
  cube.position = {0_fx, 1_fx, 0_fx};
  cube.orientation = from_axis_angle({1_fx, 0_fx, 0_fx}, 0.3_fx);
  cube.resolution = 5;
  cube.mass = 5_fx;
  cube.edge_compliance = 0.001_fx;
  cube.settings.damping = 1_fx;
  auto id = w.create_soft_body(cube);
  ASSERT_TRUE(id.ok()) << id.message();
  for (int i = 0; i < 300; ++i)
    w.step();
  const ParticleGroupStats st = w.particle_group_stats(*id).value();
  EXPECT_EQ(st.particle_count, 125U);
  EXPECT_NEAR(d(st.volume), d(st.rest_volume), 0.03 * d(st.rest_volume));
  // The rest volume is the lattice's: 4^3 cells of 0.1 m, as the cube's cells are 0.5 / 5 m.
  EXPECT_NEAR(d(st.rest_volume), 0.064, 1e-6);
  EXPECT_LT(d(st.max_speed), 0.001);
  double lowest = 1e9;
  for (const Vec3& p : positions(w, *id))
    lowest = std::min(lowest, d(p.y));
  EXPECT_NEAR(lowest, 0.05, 0.005);
}

// Under a 20 kg box, a soft cube at volume compliance 0 keeps its volume within 3 %, and carries
// the box: each of its 4 x 4 columns of 3 edges takes 196 N / 16 = 12 N, which compresses an edge
// of compliance 10^-4 m/N by 1.2 mm, so the box sinks by millimetres, not centimetres (2 cm
// allowed).
TEST(SoftBody, KeepsItsVolumeUnderALoad) {
  World w = make_world();
  BodyDef ground;
  ground.type = BodyType::static_body;
  ground.shape = Shape::plane();
  add(w, ground);
  SoftBodyDef cube;
  cube.shape = Shape::box({0.25_fx, 0.25_fx, 0.25_fx});
  cube.position = {0_fx, 0.25_fx, 0_fx};
  cube.resolution = 4;
  cube.mass = 2_fx;
  cube.edge_compliance = 0.0001_fx;
  cube.settings.damping = 2_fx;
  auto id = w.create_soft_body(cube);
  ASSERT_TRUE(id.ok()) << id.message();
  BodyDef load;
  load.shape = Shape::box({0.4_fx, 0.05_fx, 0.4_fx});
  load.position = {0_fx, 0.56_fx, 0_fx};
  load.mass = 20_fx;
  const BodyId box = add(w, load);
  for (int i = 0; i < 300; ++i)
    w.step();
  const ParticleGroupStats st = w.particle_group_stats(*id).value();
  EXPECT_NEAR(d(st.volume), d(st.rest_volume), 0.03 * d(st.rest_volume));
  // The cube's top is at 0.5 m, the box's half height 0.05 m.
  EXPECT_GT(d(state(w, box).position.y), 0.55 - 0.02);
}

}  // namespace
}  // namespace detsim
