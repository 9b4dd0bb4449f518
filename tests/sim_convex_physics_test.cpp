// Convex hulls and cylinders in the step: expectations from the physics (a hull of a box's corners
// is a box; a solid cylinder rolls down a slope at (2/3) g sin(theta); resting bodies stay put),
// never from a recorded run.
#include <cmath>
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

std::vector<Vec3> cube_corners(Fixed h) {
  std::vector<Vec3> out;
  for (const int i : {0, 1, 2, 3, 4, 5, 6, 7})
    out.push_back({(i & 1) != 0 ? h : -h, (i & 2) != 0 ? h : -h, (i & 4) != 0 ? h : -h});
  return out;
}

GeometryId cube_hull(World& w) {
  auto g = w.create_convex_hull(cube_corners(0.5_fx));
  EXPECT_TRUE(g.ok()) << g.message();
  return g.ok() ? *g : GeometryId{};
}

BodyDef at(Shape shape, Vec3 position, Quat orientation = {}) {
  return test::placed(shape, position, orientation);
}

// Dropped side by side from 10 cm onto a plane and onto a static box, the hull of a unit cube's
// corners and the unit box come to rest at the same height (within 1 mm), upright.
TEST(ConvexPhysics, AHullOfACubesCornersRestsLikeABox) {
  World w = make_world();
  add_ground(w);
  const GeometryId g = cube_hull(w);
  BodyDef table = at(Shape::box({3_fx, 0.5_fx, 3_fx}), {20_fx, 0.5_fx, 0_fx});
  table.type = BodyType::static_body;
  add(w, table);
  const BodyId box = add(w, at(Shape::box({0.5_fx, 0.5_fx, 0.5_fx}), {0_fx, 0.6_fx, 0_fx}));
  const BodyId hull = add(w, at(Shape::convex(g), {3_fx, 0.6_fx, 0_fx}));
  const BodyId box_up = add(w, at(Shape::box({0.5_fx, 0.5_fx, 0.5_fx}), {19_fx, 1.6_fx, 0_fx}));
  const BodyId hull_up = add(w, at(Shape::convex(g), {21_fx, 1.6_fx, 0_fx}));
  for (int i = 0; i < 300; ++i)
    w.step();
  for (const auto& [b, h] : {std::pair{box, hull}, std::pair{box_up, hull_up}}) {
    const BodyState sb = state(w, b);
    const BodyState sh = state(w, h);
    EXPECT_TRUE(near(sh.position.y, sb.position.y, 0.001_fx));
    EXPECT_LT(abs(sh.position.z), 0.001_fx);
    EXPECT_GT(to_mat3(sh.orientation).rows[1].y, 0.99999_fx);  // still upright
    EXPECT_FALSE(sh.awake) << "a hull at rest falls asleep like the box";
  }
}

// On a plane tilted by atan(1/2) with friction below tan(theta) the hull slides as far as the box
// (within 2 %); with friction above it, neither moves.
TEST(ConvexPhysics, AHullOfACubesCornersSlidesLikeABox) {
  const Fixed theta = atan(0.5_fx);
  const Quat tilt = from_axis_angle(Vec3::unit_z(), theta);
  const Vec3 normal = rotate(tilt, Vec3::unit_y());
  const auto slide = [&](bool as_hull, Fixed mu) {
    World w = make_world();
    add_ground(w, tilt, mu);
    const GeometryId g = cube_hull(w);
    BodyDef d = at(as_hull ? Shape::convex(g) : Shape::box({0.5_fx, 0.5_fx, 0.5_fx}),
                   normal * 0.5_fx, tilt);
    d.friction = mu;
    const BodyId body = add(w, d);
    for (int i = 0; i < 120; ++i)
      w.step();
    return length(state(w, body).position - normal * 0.5_fx).to_double();
  };
  for (const Fixed mu : {0_fx, 0.3_fx}) {
    const double box = slide(false, mu);
    const double hull = slide(true, mu);
    EXPECT_GT(box, 1.0);
    EXPECT_NEAR(hull, box, 0.02 * box) << "mu " << mu.to_double();
  }
  EXPECT_LT(slide(true, 0.6_fx), 0.01);
}

// A rock of 12 points resting on the ground neither jitters nor creeps: over 5 s after settling its
// position moves less than 0.5 mm, and it sleeps.
TEST(ConvexPhysics, ARestingRockStaysPut) {
  World w = make_world();
  add_ground(w);
  auto g = w.create_convex_hull(test::test_rock());
  ASSERT_TRUE(g.ok()) << g.message();
  const BodyId id = add(w, at(Shape::convex(*g), {0_fx, 1_fx, 0_fx}));
  for (int i = 0; i < 180; ++i)
    w.step();
  const Vec3 settled = state(w, id).position;
  for (int i = 0; i < 300; ++i)
    w.step();
  const BodyState end = state(w, id);
  EXPECT_LT(length(end.position - settled), 0.0005_fx);
  EXPECT_FALSE(end.awake);
}

// Five hull cubes stacked on the ground stand for ten seconds (none moves more than a centimetre
// sideways) and sleep.
TEST(ConvexPhysics, AStackOfHullsStands) {
  World w = make_world();
  add_ground(w);
  const GeometryId g = cube_hull(w);
  std::vector<BodyId> ids;
  for (int i = 0; i < 5; ++i)
    ids.push_back(add(w, at(Shape::convex(g), {0_fx, Fixed::from_int(i) + 0.5_fx, 0_fx})));
  for (int i = 0; i < 600; ++i)
    w.step();
  for (int i = 0; i < 5; ++i) {
    const BodyState b = state(w, ids[static_cast<std::size_t>(i)]);
    EXPECT_LT(length(Vec3{b.position.x, 0_fx, b.position.z}), 0.01_fx) << "cube " << i;
    EXPECT_TRUE(near(b.position.y, Fixed::from_int(i) + 0.5_fx, 0.02_fx)) << "cube " << i;
    EXPECT_FALSE(b.awake);
  }
}

// A cylinder standing on its end rests at its half height; lying on its side on a slope of angle
// theta (friction enough to roll: mu >= tan(theta) / 3), it rolls with a = (2/3) g sin(theta), the
// acceleration of a solid cylinder (I = m r^2 / 2) rolling without slipping.
TEST(ConvexPhysics, ACylinderStandsAndRollsDownASlopeAtTwoThirdsGSinTheta) {
  {
    World w = make_world();
    add_ground(w);
    const BodyId c = add(w, at(Shape::cylinder(0.4_fx, 0.6_fx), {0_fx, 0.65_fx, 0_fx}));
    for (int i = 0; i < 240; ++i)
      w.step();
    const BodyState b = state(w, c);
    EXPECT_TRUE(near(b.position.y, 0.6_fx, 0.006_fx));
    EXPECT_GT(to_mat3(b.orientation).rows[1].y, 0.9999_fx);
  }
  const Fixed theta = atan(0.3_fx);
  const Quat tilt = from_axis_angle(Vec3::unit_z(), theta);
  const Vec3 normal = rotate(tilt, Vec3::unit_y());
  WorldDef def;
  def.enable_sleep = false;
  World w = make_world(def);
  add_ground(w, tilt, 0.8_fx);
  // Axis along world z (the slope's level direction): the local y axis turned onto z.
  const Quat lying = tilt * from_axis_angle(Vec3::unit_x(), Fixed::half_pi());
  BodyDef d = at(Shape::cylinder(0.4_fx, 0.5_fx), normal * 0.4_fx, lying);
  d.friction = 0.8_fx;
  const BodyId c = add(w, d);
  const double g = 9.81;
  const double sin_theta = 0.3 / std::sqrt(1.09);
  const double a = 2.0 / 3.0 * g * sin_theta;
  // Settle on the slope for a few frames, then time the roll from rest-like start.
  for (int i = 0; i < 6; ++i)
    w.step();
  const Vec3 p0 = state(w, c).position;
  const double v0 = length(state(w, c).linear_velocity).to_double();
  const int frames = 90;
  for (int i = 0; i < frames; ++i)
    w.step();
  const double t = frames / 60.0;
  const double travelled = length(state(w, c).position - p0).to_double();
  const double expected = v0 * t + a * t * t / 2;
  EXPECT_NEAR(travelled, expected, 0.03 * expected) << "a = " << a;
  // Rolling, not sliding: the rim speed matches the centre's speed.
  const BodyState end = state(w, c);
  const double spin = length(end.angular_velocity).to_double() * 0.4;
  EXPECT_NEAR(spin, length(end.linear_velocity).to_double(), 0.03 * spin);
}

}  // namespace
}  // namespace detsim
