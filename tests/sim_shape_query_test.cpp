// The World's shape queries: shape_cast (where a moving shape first meets a body) and
// shape_contacts / contacts_of (what touches a shape or a body, with normals, depths and points).
//
// Expected values come from the geometry: where two shapes first touch along a line (a sphere on
// a plane, two offset spheres, a box against a wall, a hull's lowest vertex), how deep a placed
// shape overlaps. A cast stops with the shapes apart by between half the world's linear_slop and
// linear_slop (docs/SIM.md, "Queries"); `kSlop` is that, and kEps = 2^-20 m covers the rounding
// of metre-sized quantities. A random test checks the two promises on hundreds of casts among 24
// bodies against a sampled path: nothing overlaps the shape anywhere before its hit (never passes a
// body), and the hit body is within the slop at the hit (never stops at nothing).
#include <algorithm>
#include <cstdint>
#include <optional>
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
using test::near_vec;
using test::static_placed;

const Fixed kSlop = WorldDef{}.linear_slop;
constexpr Fixed kEps = Fixed::from_raw(Fixed::one_raw >> 20);
const Vec3 kUp{0_fx, 1_fx, 0_fx};

/// A hit on `body` whose travel (fraction * |translation|) stops short of `touch`, the distance
/// along the cast at which the surfaces meet, by between slop / 2 and slop: valid where the
/// motion is along the normal, so that distance along the cast is distance between surfaces.
testing::AssertionResult stops_short(const std::optional<ShapeHit>& hit, BodyId body,
                                     Vec3 translation, Fixed touch) {
  if (!hit) return testing::AssertionFailure() << "no hit";
  if (hit->body != body)
    return testing::AssertionFailure() << "hit body " << hit->body.value << ", not " << body.value;
  const Fixed travelled = hit->fraction * length(translation);
  const Fixed gap = touch - travelled;
  if (gap < (kSlop >> 1) - kEps || gap > kSlop + kEps)
    return testing::AssertionFailure()
           << "stopped " << to_string(gap) << " m short of the touch at " << to_string(touch);
  return testing::AssertionSuccess();
}

TEST(ShapeCast, ASphereDroppedOnAPlaneStopsItsRadiusAbove) {
  World w = make_world();
  const BodyId ground = add_ground(w);
  const Vec3 down{0_fx, -10_fx, 0_fx};
  const auto hit = w.shape_cast(Shape::sphere(0.5_fx), {1_fx, 5_fx, 2_fx}, {}, down);
  EXPECT_TRUE(stops_short(hit, ground, down, 4.5_fx));
  ASSERT_TRUE(hit);
  EXPECT_TRUE(near_vec(hit->normal, kUp, kEps));
  EXPECT_TRUE(near_vec(hit->point, {1_fx, 0_fx, 2_fx}, kEps));
}

TEST(ShapeCast, OffsetSpheresMeetWhereTheirCentresAreTheSumOfTheRadiiApart) {
  // A 0.5 m ball cast along x past a 1 m ball 0.9 m off its line: the centres are 1.5 m apart
  // first at x = 5 - sqrt(1.5^2 - 0.9^2) = 3.8.
  World w = make_world();
  const Vec3 c2{5_fx, 0.9_fx, 0_fx};
  const BodyId ball = add(w, static_placed(Shape::sphere(1_fx), c2));
  const Vec3 along{10_fx, 0_fx, 0_fx};
  const auto hit = w.shape_cast(Shape::sphere(0.5_fx), {}, {}, along);
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->body, ball);
  const Vec3 c1 = along * hit->fraction;
  const Fixed gap = distance(c1, c2) - 1.5_fx;
  EXPECT_GE(gap, (kSlop >> 1) - kEps);
  EXPECT_LE(gap, kSlop + kEps);
  EXPECT_TRUE(near(c1.x, 3.8_fx, 2_fx * kSlop));
  EXPECT_TRUE(near_vec(hit->normal, normalize(c1 - c2), 0.001_fx));
  EXPECT_TRUE(near(distance(hit->point, c2), 1_fx, kEps));

  // 1.6 m off the line: the balls pass each other.
  World apart = make_world();
  add(apart, static_placed(Shape::sphere(1_fx), {5_fx, 1.6_fx, 0_fx}));
  EXPECT_FALSE(apart.shape_cast(Shape::sphere(0.5_fx), {}, {}, along));
}

TEST(ShapeCast, ABoxSlidingOnTheFloorMeetsTheWallAheadNotTheFloor) {
  World w = make_world();
  add_ground(w);
  const BodyId wall = add(w, static_placed(Shape::box({0.5_fx, 1_fx, 2_fx}), {5_fx, 1_fx, 0_fx}));
  const Vec3 along{10_fx, 0_fx, 0_fx};
  // Resting on the floor, and sunk 1 mm into it: the floor is passed by either way.
  for (const Fixed y : {0.5_fx, 0.499_fx}) {
    const auto hit = w.shape_cast(Shape::box({0.5_fx, 0.5_fx, 0.5_fx}), {0_fx, y, 0_fx}, {}, along);
    EXPECT_TRUE(stops_short(hit, wall, along, 4_fx)) << "y " << to_string(y);
    ASSERT_TRUE(hit);
    EXPECT_TRUE(near_vec(hit->normal, {-1_fx, 0_fx, 0_fx}, kEps));
    EXPECT_TRUE(near(hit->point.x, 4.5_fx, kEps));
  }
}

TEST(ShapeCast, AShapeStartingInsideMeetsTheBodyOnlyWhereItMovesDeeper) {
  World w = make_world();
  const BodyId ground = add_ground(w);
  const Vec3 start{0_fx, 0.3_fx, 0_fx};  // a 0.5 m ball 0.2 m into the floor
  EXPECT_FALSE(w.shape_cast(Shape::sphere(0.5_fx), start, {}, {0_fx, 1_fx, 0_fx}));
  EXPECT_FALSE(w.shape_cast(Shape::sphere(0.5_fx), start, {}, {3_fx, 0_fx, 0_fx}));
  const auto deeper = w.shape_cast(Shape::sphere(0.5_fx), start, {}, {0_fx, -1_fx, 0_fx});
  ASSERT_TRUE(deeper);
  EXPECT_EQ(deeper->body, ground);
  EXPECT_EQ(deeper->fraction, 0_fx);
  EXPECT_TRUE(near_vec(deeper->normal, kUp, kEps));
}

TEST(ShapeCast, CapsulesHullsAndBoxesLandOnMeshesHeightfieldsAndTurnedBoxes) {
  World w = make_world();
  // A 20 m square mesh floor at y = 1 (two triangles, facing up).
  const std::vector<Vec3> v{
      {-10_fx, 1_fx, -10_fx}, {10_fx, 1_fx, -10_fx}, {10_fx, 1_fx, 10_fx}, {-10_fx, 1_fx, 10_fx}};
  const std::vector<std::uint32_t> idx{0, 2, 1, 0, 3, 2};
  auto mesh = w.create_mesh(v, idx);
  ASSERT_TRUE(mesh.ok()) << mesh.message();
  const BodyId floor = add(w, static_placed(Shape::mesh(*mesh), {}));
  const Vec3 down{0_fx, -8_fx, 0_fx};
  // An upright capsule (half height 0.5, radius 0.3): its lowest point is 0.8 below its centre.
  EXPECT_TRUE(
      stops_short(w.shape_cast(Shape::capsule(0.3_fx, 0.5_fx), {2_fx, 5_fx, 1_fx}, {}, down), floor,
                  down, 5_fx - 0.8_fx - 1_fx));
  // The hull's lowest vertex is the lowest of its points.
  const std::vector<Vec3> rock = test::test_rock();
  Fixed lowest = 0_fx;
  for (const Vec3& p : rock)
    lowest = min(lowest, p.y);
  auto hull = w.create_convex_hull(rock);
  ASSERT_TRUE(hull.ok()) << hull.message();
  EXPECT_TRUE(stops_short(w.shape_cast(Shape::convex(*hull), {-3_fx, 5_fx, 0_fx}, {}, down), floor,
                          down, 5_fx + lowest - 1_fx));

  // A heightfield at height 2 everywhere, under a box turned 45 degrees about z: its lowest edge
  // is half its diagonal, 0.5 * sqrt 2, below its centre.
  World hw = make_world();
  HeightfieldDef hd;
  hd.rows = 4;
  hd.columns = 4;
  hd.cell_size = 2_fx;
  hd.heights.assign(16, 2_fx);
  auto field = hw.create_heightfield(hd);
  ASSERT_TRUE(field.ok()) << field.message();
  const BodyId land = add(hw, static_placed(Shape::heightfield(*field), {}));
  const Quat turned = from_axis_angle({0_fx, 0_fx, 1_fx}, Fixed::pi() / 4_fx);
  EXPECT_TRUE(stops_short(
      hw.shape_cast(Shape::box({0.5_fx, 0.5_fx, 0.5_fx}), {3_fx, 6_fx, 3_fx}, turned, down), land,
      down, 6_fx - (Fixed::sqrt2() >> 1) - 2_fx));
}

TEST(ShapeCast, TheNearestBodyIsHitAndFiltersLeaveBodiesOut) {
  World w = make_world();
  BodyDef near_wall = static_placed(Shape::box({0.5_fx, 2_fx, 2_fx}), {3_fx, 0_fx, 0_fx});
  near_wall.layer = 2;
  const BodyId first = add(w, near_wall);
  const BodyId second = add(w, static_placed(Shape::box({0.5_fx, 2_fx, 2_fx}), {5_fx, 0_fx, 0_fx}));
  BodyDef sensor = static_placed(Shape::box({0.5_fx, 2_fx, 2_fx}), {1.5_fx, 0_fx, 0_fx});
  sensor.sensor = true;
  add(w, sensor);
  const Vec3 along{10_fx, 0_fx, 0_fx};
  const Shape ball = Shape::sphere(0.25_fx);
  EXPECT_TRUE(stops_short(w.shape_cast(ball, {}, {}, along), first, along, 2.25_fx));
  QueryFilter skip_first;
  skip_first.ignore = first;
  EXPECT_TRUE(stops_short(w.shape_cast(ball, {}, {}, along, skip_first), second, along, 4.25_fx));
  const auto ray = w.raycast_closest({}, along, skip_first);  // rays honour `ignore` too
  ASSERT_TRUE(ray);
  EXPECT_EQ(ray->body, second);
  QueryFilter layer_one;
  layer_one.mask = 1;  // the first wall is on layer 2
  EXPECT_TRUE(stops_short(w.shape_cast(ball, {}, {}, along, layer_one), second, along, 4.25_fx));
  QueryFilter with_sensors;
  with_sensors.include_sensors = true;
  const auto hit = w.shape_cast(ball, {}, {}, along, with_sensors);
  ASSERT_TRUE(hit);
  EXPECT_TRUE(near(hit->fraction * 10_fx, 0.75_fx, kSlop));

  // Two identical walls in one place: the tie goes to the lower ID.
  World twins = make_world();
  const BodyId lower =
      add(twins, static_placed(Shape::box({0.5_fx, 2_fx, 2_fx}), {3_fx, 0_fx, 0_fx}));
  add(twins, static_placed(Shape::box({0.5_fx, 2_fx, 2_fx}), {3_fx, 0_fx, 0_fx}));
  const auto tie = twins.shape_cast(ball, {}, {}, along);
  ASSERT_TRUE(tie);
  EXPECT_EQ(tie->body, lower);
}

TEST(ShapeCast, ShapesABodyCouldNotHaveAndZeroTranslationsMeetNothing) {
  World w = make_world();
  add_ground(w);
  const Vec3 down{0_fx, -10_fx, 0_fx};
  const Vec3 at{0_fx, 5_fx, 0_fx};
  EXPECT_TRUE(w.shape_cast(Shape::sphere(0.5_fx), at, {}, down));  // the valid query hits
  EXPECT_FALSE(w.shape_cast(Shape::plane(), at, {}, down));
  EXPECT_FALSE(w.shape_cast(Shape::sphere(0_fx), at, {}, down));
  EXPECT_FALSE(w.shape_cast(Shape::sphere(0.5_fx), at, Quat{2_fx, 0_fx, 0_fx, 0_fx}, down));
  EXPECT_FALSE(w.shape_cast(Shape::sphere(0.5_fx), {0_fx, 0.2_fx, 0_fx}, {}, Vec3::zero()));
}

// Random casts among random boxes, balls and capsules, checked against the path sampled every
// 1/400 of the way: the shape overlaps nothing before its hit (the cast passes no body), and at
// its hit, the same shape grown by the slop touches the hit body (the cast stops at something).
// Growing a box's half extents, a ball's or a capsule's radius by d covers every point within d.
TEST(ShapeCast, NeverPassesABodyAndNeverStopsAtNothing) {
  World w = make_world();
  Rng rng(21);
  const auto coordinate = [&] { return rng.uniform(-6_fx, 6_fx); };
  const auto size = [&] { return rng.uniform(0.1_fx, 1_fx); };
  for (int k = 0; k < 24; ++k) {
    const Vec3 p{coordinate(), coordinate(), coordinate()};
    const Vec3 axis = rng.unit_vector();
    const Fixed angle = rng.uniform(0_fx, Fixed::pi());
    const Quat q = from_axis_angle(axis, angle);
    const Fixed a = size();
    const Fixed b = size();
    const Fixed c = size();
    const Shape shape = k % 3 == 0   ? Shape::box({a, b, c})
                        : k % 3 == 1 ? Shape::sphere(a)
                                     : Shape::capsule(a, b);
    add(w, static_placed(shape, p, q));
  }
  int hits = 0;
  int checked = 0;
  for (int cast = 0; cast < 600; ++cast) {
    const Fixed a = size() / 2_fx;
    const Fixed b = size() / 2_fx;
    const Fixed c = size() / 2_fx;
    const int kind = cast % 3;
    const auto query_shape = [&](Fixed grow) {
      return kind == 0   ? Shape::box({a + grow, b + grow, c + grow})
             : kind == 1 ? Shape::sphere(a + grow)
                         : Shape::capsule(a + grow, b);
    };
    const Vec3 axis = rng.unit_vector();
    const Fixed angle = rng.uniform(0_fx, Fixed::pi());
    const Quat q = from_axis_angle(axis, angle);
    const Vec3 start{coordinate(), coordinate(), coordinate()};
    const Vec3 end{coordinate(), coordinate(), coordinate()};
    const Vec3 translation = end - start;
    if (!w.overlap(query_shape(0_fx), start, q).empty()) continue;  // starts free
    ++checked;
    const auto hit = w.shape_cast(query_shape(0_fx), start, q, translation);
    const Fixed until = hit ? hit->fraction : 1_fx;
    constexpr int samples = 400;
    for (int s = 0; s <= samples; ++s) {
      const Fixed f = Fixed::from_int(s) / Fixed::from_int(samples);
      if (f > until) break;
      const auto touching = w.overlap(query_shape(0_fx), start + translation * f, q);
      ASSERT_TRUE(touching.empty())
          << "cast " << cast << " passes body " << touching[0].value << " at fraction "
          << to_string(f) << " before its hit at " << to_string(until) << " (body "
          << (hit ? hit->body.value : 0U) << ", query kind " << kind << ")";
    }
    if (!hit) continue;
    ++hits;
    const auto grown = w.overlap(query_shape(kSlop + kEps), start + translation * hit->fraction, q);
    EXPECT_NE(std::find(grown.begin(), grown.end(), hit->body), grown.end())
        << "cast " << cast << " stops at fraction " << to_string(hit->fraction) << " without body "
        << hit->body.value << " within the slop";
  }
  // The check saw many casts, and hits as well as misses.
  EXPECT_GE(checked, 300);
  EXPECT_GE(hits, 100);
  EXPECT_LT(hits, checked);
}

TEST(ShapeContacts, ABoxSunkIntoAPlaneReportsItsDepthNormalAndFourPoints) {
  World w = make_world();
  const BodyId ground = add_ground(w);
  const auto contacts =
      w.shape_contacts(Shape::box({0.5_fx, 0.5_fx, 0.5_fx}), {0_fx, 0.4_fx, 0_fx}, {});
  ASSERT_EQ(contacts.size(), 1U);
  const ShapeContact& c = contacts[0];
  EXPECT_EQ(c.body, ground);
  EXPECT_TRUE(near_vec(c.normal, kUp, kEps));
  EXPECT_TRUE(near(c.depth, 0.1_fx, kEps));
  ASSERT_EQ(c.point_count, 4);
  for (std::uint8_t k = 0; k < c.point_count; ++k) {
    EXPECT_TRUE(near(c.points[k].y, -0.05_fx, kEps));  // midway between -0.1 and 0
    EXPECT_TRUE(near(abs(c.points[k].x), 0.5_fx, kEps));
  }

  // Just touching counts, with depth 0; just apart does not.
  EXPECT_EQ(w.shape_contacts(Shape::sphere(0.5_fx), {0_fx, 0.5_fx, 0_fx}, {}).size(), 1U);
  EXPECT_TRUE(w.shape_contacts(Shape::sphere(0.5_fx), {0_fx, 0.5_fx + kEps, 0_fx}, {}).empty());
}

TEST(ShapeContacts, OverlappingBallsReportTheSumOfRadiiLessTheirDistance) {
  World w = make_world();
  const Vec3 c2{1_fx, 0.5_fx, 0_fx};
  const BodyId ball = add(w, static_placed(Shape::sphere(0.75_fx), c2));
  const auto contacts = w.shape_contacts(Shape::sphere(0.5_fx), {}, {});
  ASSERT_EQ(contacts.size(), 1U);
  EXPECT_EQ(contacts[0].body, ball);
  EXPECT_TRUE(near(contacts[0].depth, 1.25_fx - distance(Vec3::zero(), c2), kEps));
  EXPECT_TRUE(near_vec(contacts[0].normal, normalize(Vec3::zero() - c2), kEps));
}

TEST(ContactsOf, ABoxInACornerOfAMeshTouchesItsFloorAndItsWallWithTheirOwnNormals) {
  World w = make_world();
  // Floor y = 0 (facing up) and wall x = 1 (facing -x), two triangles each.
  const std::vector<Vec3> v{{-5_fx, 0_fx, -5_fx}, {1_fx, 0_fx, -5_fx}, {1_fx, 0_fx, 5_fx},
                            {-5_fx, 0_fx, 5_fx},  {1_fx, 5_fx, -5_fx}, {1_fx, 5_fx, 5_fx}};
  const std::vector<std::uint32_t> idx{0, 2, 1, 0, 3, 2, 1, 2, 5, 1, 5, 4};
  auto mesh = w.create_mesh(v, idx);
  ASSERT_TRUE(mesh.ok()) << mesh.message();
  const BodyId corner = add(w, static_placed(Shape::mesh(*mesh), {}));
  // 1 cm into the floor and 2 cm into the wall.
  const BodyId box =
      add(w, test::placed(Shape::box({0.5_fx, 0.5_fx, 0.5_fx}), {0.52_fx, 0.49_fx, 0_fx}));
  BodyDef sensor = static_placed(Shape::sphere(2_fx), {});
  sensor.sensor = true;
  add(w, sensor);  // sensors are left out
  const auto contacts = w.contacts_of(box);
  ASSERT_TRUE(contacts.ok()) << contacts.message();
  ASSERT_EQ(contacts->size(), 2U);
  bool floor_seen = false;
  bool wall_seen = false;
  for (const ShapeContact& c : *contacts) {
    EXPECT_EQ(c.body, corner);
    if (c.normal.y > 0.9_fx) {
      floor_seen = true;
      EXPECT_TRUE(near_vec(c.normal, kUp, kEps));
      EXPECT_TRUE(near(c.depth, 0.01_fx, kEps));
    } else {
      wall_seen = true;
      EXPECT_TRUE(near_vec(c.normal, {-1_fx, 0_fx, 0_fx}, kEps));
      EXPECT_TRUE(near(c.depth, 0.02_fx, kEps));
    }
  }
  EXPECT_TRUE(floor_seen && wall_seen);
  EXPECT_LT((*contacts)[0].sub_shape, (*contacts)[1].sub_shape);

  EXPECT_FALSE(w.contacts_of(BodyId{99}).ok());
}

TEST(ContactsOf, APlaneBodyListsWhatRestsOnItAscendingWithNormalsOutOfEach) {
  World w = make_world();
  const BodyId ground = add_ground(w);
  const BodyId far = add(w, test::placed(Shape::sphere(0.5_fx), {100_fx, 0.49_fx, 0_fx}));
  const BodyId above = add(w, test::placed(Shape::sphere(0.5_fx), {0_fx, 0.6_fx, 0_fx}));
  const BodyId box = add(w, test::placed(Shape::box({1_fx, 0.25_fx, 1_fx}), {-3_fx, 0.2_fx, 0_fx}));
  const auto contacts = w.contacts_of(ground);
  ASSERT_TRUE(contacts.ok()) << contacts.message();
  ASSERT_EQ(contacts->size(), 2U);
  EXPECT_EQ((*contacts)[0].body, far);
  EXPECT_EQ((*contacts)[1].body, box);
  EXPECT_NE((*contacts)[0].body, above);
  for (const ShapeContact& c : *contacts)
    EXPECT_TRUE(near_vec(c.normal, {0_fx, -1_fx, 0_fx}, kEps));
  EXPECT_TRUE(near((*contacts)[0].depth, 0.01_fx, kEps));
  EXPECT_TRUE(near((*contacts)[1].depth, 0.05_fx, kEps));
}

}  // namespace
}  // namespace detsim
