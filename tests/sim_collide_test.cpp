// The narrowphase: contact manifolds for every pair of shapes (sim/src/collide.hpp).
//
// Every expected value is worked out from the geometry in the comment beside it: where the
// surfaces are, which features touch, how far apart they are along the normal. Scenes are placed
// far from the origin (up to 10^4 m) so that the relative-coordinate arithmetic is exercised.
#include <array>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "support/collide_helpers.hpp"

namespace {

using namespace detsim;
using namespace detsim::literals;
using namespace detsim::collide_test;

TEST(CollideFeatures, EncodingIsInjectiveAndMirrorsBySwappingHalves) {
  // Within each shape every feature has its own code (shapes may share codes with each other).
  std::vector<std::uint16_t> round{kWhole, kPlane, kCore, kBottom, kTop};
  std::sort(round.begin(), round.end());
  EXPECT_EQ(std::adjacent_find(round.begin(), round.end()), round.end());
  std::vector<std::uint16_t> box;
  for (int i = 0; i < 6; ++i)
    box.push_back(nf::box_face(i / 2, i % 2 == 0));
  for (unsigned v = 0; v < 8; ++v)
    box.push_back(vertex((v & 1U) != 0, (v & 2U) != 0, (v & 4U) != 0));
  // An edge ignores its own axis' sign: 24 sign patterns name the 12 edges.
  std::vector<std::uint16_t> edges;
  for (int axis = 0; axis < 3; ++axis)
    for (unsigned v = 0; v < 8; ++v)
      edges.push_back(edge(axis, (v & 1U) != 0, (v & 2U) != 0, (v & 4U) != 0));
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  EXPECT_EQ(edges.size(), 12U);
  box.insert(box.end(), edges.begin(), edges.end());
  std::sort(box.begin(), box.end());
  EXPECT_EQ(std::adjacent_find(box.begin(), box.end()), box.end());  // 26 distinct box features
  EXPECT_EQ(nf::mirror_feature(pair(kTop, kPlane)), pair(kPlane, kTop));
  EXPECT_EQ(nf::mirror_feature(nf::mirror_feature(0x12345678U)), 0x12345678U);
}

// ---- Dispatcher ---------------------------------------------------------------------------------

TEST(CollideDispatch, PlaneAgainstPlaneAndUnknownTypesGiveNothing) {
  const Manifold m = collide(Shape::plane(), at({}), Shape::plane(), at({}), kMargin);
  EXPECT_EQ(m.count, 0U);
  Shape bogus = Shape::sphere(1_fx);
  // In the pair table's range but no type (9 is the compound now).
  bogus.type = static_cast<ShapeType>(15);
  EXPECT_EQ(collide(bogus, at({}), Shape::sphere(1_fx), at({}), kMargin).count, 0U);
  EXPECT_EQ(collide(Shape::box({1_fx, 1_fx, 1_fx}), at({}), bogus, at({}), kMargin).count, 0U);
}

// ---- Sphere - sphere ----------------------------------------------------------------------------

// a: radius 0.5 at `base`; b: radius 0.25 at base + dir (0.75 + gap) with dir = (0.6, 0.8, 0).
// The surfaces are at distances 0.5 and 0.5 + gap from a's centre along dir.
struct SphereSphere : ::testing::Test {
  const Vec3 base = v3(10000_fx, -5000_fx, 3000_fx);
  const Vec3 dir = v3(0.6_fx, 0.8_fx, 0_fx);
  const Shape a = Shape::sphere(0.5_fx);
  const Shape b = Shape::sphere(0.25_fx);
  Pose pb(Fixed gap) const { return at(base + dir * (0.75_fx + gap)); }
};

TEST_F(SphereSphere, BeyondMarginNothing) {
  EXPECT_EQ(collide(a, at(base), b, pb(0.3_fx), kMargin).count, 0U);
  EXPECT_EQ(collide(a, at(base), b, pb(0.101_fx), kMargin).count, 0U);
}

TEST_F(SphereSphere, WithinMarginSpeculativePoint) {
  const Manifold m = collide(a, at(base), b, pb(0.05_fx), kMargin);
  ASSERT_EQ(m.count, 1U);
  EXPECT_TRUE(near(m.normal, dir));
  EXPECT_TRUE(near(m.points[0].separation, 0.05_fx));
  EXPECT_TRUE(near(m.points[0].point, base + dir * 0.525_fx));  // between 0.5 and 0.55
  EXPECT_EQ(m.points[0].feature, pair(kWhole, kWhole));
  expect_features_stable(a, at(base), b, pb(0.05_fx), v3(0.0001_fx, -0.0001_fx, 0.0001_fx));
}

TEST_F(SphereSphere, OverlapNormalSeparationMidpoint) {
  const Manifold m = collide(a, at(base), b, pb(-0.1_fx), kMargin);
  ASSERT_EQ(m.count, 1U);
  EXPECT_TRUE(near(m.normal, dir));
  EXPECT_TRUE(near(m.points[0].separation, -0.1_fx));
  EXPECT_TRUE(near(m.points[0].point, base + dir * 0.45_fx));  // between 0.5 and 0.4
  expect_well_formed(m, kMargin);
  expect_mirrored(a, at(base), b, pb(-0.1_fx));
}

TEST_F(SphereSphere, CoincidentCentresUseUpAndAreDeterministic) {
  const Manifold m = collide(a, at(base), b, at(base), kMargin);
  ASSERT_EQ(m.count, 1U);
  EXPECT_EQ(m.normal, Vec3::unit_y());
  EXPECT_EQ(m.points[0].separation, -0.75_fx);
  EXPECT_TRUE(identical(m, collide(a, at(base), b, at(base), kMargin)));
}

// ---- Sphere - box -------------------------------------------------------------------------------

// Box half extents (1, 0.5, 2) at `centre`, turned 30 degrees about y. Sphere positions and the
// expected points are given in the box frame and mapped with the box's rotation.
struct SphereBox : ::testing::Test {
  const Vec3 centre = v3(100_fx, 20_fx, -50_fx);
  const Pose box_pose = at(centre, about(Vec3::unit_y(), Fixed::pi() / 6_fx));
  const Shape box = Shape::box({1_fx, 0.5_fx, 2_fx});
  Vec3 world(Vec3 local) const { return centre + box_pose.rotation * local; }
  Vec3 world_dir(Vec3 local) const { return box_pose.rotation * local; }
  Manifold hit(Fixed radius, Vec3 local_centre, Fixed margin = kMargin) const {
    return collide(Shape::sphere(radius), at(world(local_centre)), box, box_pose, margin);
  }
};

TEST_F(SphereBox, AboveTheTopFace) {
  // Sphere radius 0.25 whose lowest point is `gap` above the top face y = 0.5.
  EXPECT_EQ(hit(0.25_fx, v3(0.3_fx, 0.95_fx, -1_fx)).count, 0U);  // gap 0.2
  const Manifold m = hit(0.25_fx, v3(0.3_fx, 0.8_fx, -1_fx));     // gap 0.05
  ASSERT_EQ(m.count, 1U);
  EXPECT_TRUE(
      near(m.normal, world_dir(v3(0_fx, -1_fx, 0_fx))));  // from the sphere down into the box
  EXPECT_TRUE(near(m.points[0].separation, 0.05_fx));
  EXPECT_TRUE(near(m.points[0].point, world(v3(0.3_fx, 0.525_fx, -1_fx))));
  EXPECT_EQ(m.points[0].feature, pair(kWhole, nf::box_face(1, true)));
  const Manifold deep = hit(0.25_fx, v3(0.3_fx, 0.65_fx, -1_fx));  // lowest point at 0.4
  ASSERT_EQ(deep.count, 1U);
  EXPECT_TRUE(near(deep.points[0].separation, -0.1_fx));
  EXPECT_TRUE(near(deep.points[0].point, world(v3(0.3_fx, 0.45_fx, -1_fx))));
  expect_mirrored(Shape::sphere(0.25_fx), at(world(v3(0.3_fx, 0.65_fx, -1_fx))), box, box_pose);
}

TEST_F(SphereBox, NearAnEdge) {
  // Centre (1.3, 0.9, 0.5): the closest box point is (1, 0.5, 0.5) on the edge along z at +x +y,
  // 0.5 away along (0.6, 0.8, 0). Radius 0.4 leaves a gap of 0.1, within a margin of 0.2.
  const Manifold m = hit(0.4_fx, v3(1.3_fx, 0.9_fx, 0.5_fx), 0.2_fx);
  ASSERT_EQ(m.count, 1U);
  EXPECT_TRUE(near(m.normal, world_dir(v3(-0.6_fx, -0.8_fx, 0_fx))));
  EXPECT_TRUE(near(m.points[0].separation, 0.1_fx));
  // Sphere surface at (1.3, 0.9) - 0.4 (0.6, 0.8) = (1.06, 0.58); midway to (1, 0.5): (1.03, 0.54).
  EXPECT_TRUE(near(m.points[0].point, world(v3(1.03_fx, 0.54_fx, 0.5_fx))));
  EXPECT_EQ(m.points[0].feature, pair(kWhole, edge(2, true, true, false)));
  // A 1e-4 m nudge along the edge and outwards keeps the same features.
  const Manifold nudged = hit(0.4_fx, v3(1.3001_fx, 0.9_fx, 0.5001_fx), 0.2_fx);
  EXPECT_EQ(features(nudged), features(m));
}

TEST_F(SphereBox, NearACorner) {
  // Centre (1.2, 0.7, 2.1) is (0.2, 0.2, 0.1) from the corner (1, 0.5, 2): distance 0.3, so radius
  // 0.25 leaves 0.05. The point is 0.025 out from the corner along (2, 2, 1) / 3.
  const Manifold m = hit(0.25_fx, v3(1.2_fx, 0.7_fx, 2.1_fx));
  ASSERT_EQ(m.count, 1U);
  EXPECT_TRUE(near(m.points[0].separation, 0.05_fx));
  const Vec3 out = v3(2_fx, 2_fx, 1_fx) / 3_fx;
  EXPECT_TRUE(near(m.normal, world_dir(-out)));
  EXPECT_TRUE(near(m.points[0].point, world(v3(1_fx, 0.5_fx, 2_fx) + out * 0.025_fx)));
  EXPECT_EQ(m.points[0].feature, pair(kWhole, vertex(true, true, true)));
}

TEST_F(SphereBox, CentreInsidePushesOutThroughNearestFace) {
  // Centre (0.9, 0, 0): 0.1 below the +x face, farther from all others. The sphere leaves through
  // +x, so the box moves along -x: separation -(0.1 + 0.25), the point midway between the sphere's
  // far surface point x = 0.65 and the face x = 1.
  const Manifold m = hit(0.25_fx, v3(0.9_fx, 0_fx, 0_fx));
  ASSERT_EQ(m.count, 1U);
  EXPECT_TRUE(near(m.normal, world_dir(v3(-1_fx, 0_fx, 0_fx))));
  EXPECT_TRUE(near(m.points[0].separation, -0.35_fx));
  EXPECT_TRUE(near(m.points[0].point, world(v3(0.825_fx, 0_fx, 0_fx))));
  EXPECT_EQ(m.points[0].feature, pair(kWhole, nf::box_face(0, true)));
}

TEST_F(SphereBox, CoincidentCentresAreFiniteAndDeterministic) {
  // Nearest faces are y = +-0.5 (depth 0.5); +y comes first in face order.
  const Manifold m = hit(0.25_fx, {});
  ASSERT_EQ(m.count, 1U);
  EXPECT_TRUE(near(m.normal, world_dir(v3(0_fx, -1_fx, 0_fx))));
  EXPECT_TRUE(near(m.points[0].separation, -0.75_fx));
  EXPECT_TRUE(identical(m, hit(0.25_fx, {})));
}

// ---- Sphere - capsule ---------------------------------------------------------------------------

// Capsule radius 0.25, half height 1, turned a quarter about x so its core runs along world z.
struct SphereCapsule : ::testing::Test {
  const Vec3 q = v3(-7_fx, 3_fx, 2_fx);
  const Shape capsule = Shape::capsule(0.25_fx, 1_fx);
  const Pose capsule_pose = at(q, about(Vec3::unit_x(), quarter_turn));
  const Shape sphere = Shape::sphere(0.5_fx);
};

TEST_F(SphereCapsule, BesideTheCore) {
  // Centre 0.75 + gap from the core point (0, 0, 0.3): normal from the sphere toward -x.
  EXPECT_EQ(collide(sphere, at(q + v3(1_fx, 0_fx, 0.3_fx)), capsule, capsule_pose, kMargin).count,
            0U);  // gap 0.25
  const Manifold m =
      collide(sphere, at(q + v3(0.8_fx, 0_fx, 0.3_fx)), capsule, capsule_pose, kMargin);
  ASSERT_EQ(m.count, 1U);
  EXPECT_TRUE(near(m.normal, v3(-1_fx, 0_fx, 0_fx)));
  EXPECT_TRUE(near(m.points[0].separation, 0.05_fx));
  EXPECT_TRUE(near(m.points[0].point, q + v3(0.275_fx, 0_fx, 0.3_fx)));  // between 0.3 and 0.25
  EXPECT_EQ(m.points[0].feature, pair(kWhole, kCore));
  expect_mirrored(sphere, at(q + v3(0.7_fx, 0_fx, 0.3_fx)), capsule, capsule_pose);
  expect_features_stable(capsule, capsule_pose, sphere, at(q + v3(0.7_fx, 0_fx, 0.3_fx)),
                         v3(0.0001_fx, 0.0001_fx, 0.0001_fx));
}

TEST_F(SphereCapsule, BeyondTheTopEnd) {
  // The core's +y end is at q + (0, 0, 1); the sphere centre 0.7 beyond it overlaps by 0.05.
  const Manifold m =
      collide(sphere, at(q + v3(0_fx, 0_fx, 1.7_fx)), capsule, capsule_pose, kMargin);
  ASSERT_EQ(m.count, 1U);
  EXPECT_TRUE(near(m.normal, v3(0_fx, 0_fx, -1_fx)));
  EXPECT_TRUE(near(m.points[0].separation, -0.05_fx));
  EXPECT_TRUE(near(m.points[0].point, q + v3(0_fx, 0_fx, 1.225_fx)));  // between 1.2 and 1.25
  EXPECT_EQ(m.points[0].feature, pair(kWhole, kTop));
}

TEST_F(SphereCapsule, CentreOnTheCoreLeavesSideways) {
  const Manifold m =
      collide(sphere, at(q + v3(0_fx, 0_fx, 0.5_fx)), capsule, capsule_pose, kMargin);
  ASSERT_EQ(m.count, 1U);
  EXPECT_TRUE(near(m.points[0].separation, -0.75_fx));
  EXPECT_TRUE(near(m.normal.z, 0_fx));  // perpendicular to the core
  EXPECT_TRUE(near(length(m.normal), 1_fx));
  EXPECT_TRUE(identical(
      m, collide(sphere, at(q + v3(0_fx, 0_fx, 0.5_fx)), capsule, capsule_pose, kMargin)));
}

TEST_F(SphereCapsule, ZeroHalfHeightIsASphere) {
  // A capsule of half height 0 is a sphere of its radius: 0.6 between centres, 0.75 of radii.
  const Shape ball = Shape::capsule(0.25_fx, 0_fx);
  const Manifold m = collide(sphere, at(q), ball, at(q + v3(0_fx, 0.6_fx, 0_fx)), kMargin);
  ASSERT_EQ(m.count, 1U);
  EXPECT_TRUE(near(m.normal, Vec3::unit_y()));
  EXPECT_TRUE(near(m.points[0].separation, -0.15_fx));
  EXPECT_EQ(m.points[0].feature, pair(kWhole, kBottom));
}

// ---- Sphere - plane -----------------------------------------------------------------------------

// Plane through (5, 1, -3), turned 30 degrees about z: normal up = (-sin 30, cos 30, 0), in-plane
// direction along = (cos 30, sin 30, 0).
struct SpherePlane : ::testing::Test {
  const Vec3 origin = v3(5_fx, 1_fx, -3_fx);
  const Fixed angle = Fixed::pi() / 6_fx;
  const Pose plane_pose = at(origin, about(Vec3::unit_z(), angle));
  const Vec3 up = v3(-sin(angle), cos(angle), 0_fx);
  const Vec3 along = v3(cos(angle), sin(angle), 0_fx);
  const Shape sphere = Shape::sphere(0.5_fx);
  // Centre far along the plane (7 m and 4 m sideways) at height 0.5 + gap.
  Vec3 centre(Fixed gap) const {
    return origin + along * 7_fx + v3(0_fx, 0_fx, 4_fx) + up * (0.5_fx + gap);
  }
};

TEST_F(SpherePlane, GapsAndOverlap) {
  EXPECT_EQ(collide(sphere, at(centre(0.2_fx)), Shape::plane(), plane_pose, kMargin).count, 0U);
  for (const Fixed gap : {0.05_fx, 0_fx, -0.2_fx}) {
    const Manifold m = collide(sphere, at(centre(gap)), Shape::plane(), plane_pose, kMargin);
    ASSERT_EQ(m.count, 1U);
    EXPECT_TRUE(near(m.normal, -up));  // from the sphere into the half-space
    EXPECT_TRUE(near(m.points[0].separation, gap));
    // Lowest sphere point at height gap, the plane at 0: midway at gap / 2.
    EXPECT_TRUE(near(m.points[0].point, centre(gap) - up * (0.5_fx + gap / 2_fx)));
    EXPECT_EQ(m.points[0].feature, pair(kWhole, kPlane));
  }
  expect_mirrored(sphere, at(centre(-0.2_fx)), Shape::plane(), plane_pose);
  expect_features_stable(Shape::plane(), plane_pose, sphere, at(centre(-0.2_fx)),
                         v3(0.0001_fx, 0.0001_fx, -0.0001_fx));
}

// ---- Capsule - capsule --------------------------------------------------------------------------

// Capsules of radius 0.25 and half height 1 near o.
struct CapsuleCapsule : ::testing::Test {
  const Vec3 o = v3(50_fx, 60_fx, 70_fx);
  const Shape capsule = Shape::capsule(0.25_fx, 1_fx);
  const Quat along_z = about(Vec3::unit_x(), quarter_turn);
  const Quat along_x = about(Vec3::unit_z(), -quarter_turn);
};

TEST_F(CapsuleCapsule, CrossingAtRightAngles) {
  // a along y, b along z at (0.5 + gap, 0.3, -0.2): closest core points (0, 0.3, 0) and
  // (0.5 + gap, 0.3, 0).
  EXPECT_EQ(
      collide(capsule, at(o), capsule, at(o + v3(0.7_fx, 0.3_fx, -0.2_fx), along_z), kMargin).count,
      0U);
  const Manifold m =
      collide(capsule, at(o), capsule, at(o + v3(0.45_fx, 0.3_fx, -0.2_fx), along_z), kMargin);
  ASSERT_EQ(m.count, 1U);
  EXPECT_TRUE(near(m.normal, Vec3::unit_x()));
  EXPECT_TRUE(near(m.points[0].separation, -0.05_fx));
  EXPECT_TRUE(near(m.points[0].point, o + v3(0.225_fx, 0.3_fx, 0_fx)));
  EXPECT_EQ(m.points[0].feature, pair(kCore, kCore));
  expect_mirrored(capsule, at(o), capsule, at(o + v3(0.45_fx, 0.3_fx, -0.2_fx), along_z));
  expect_features_stable(capsule, at(o), capsule, at(o + v3(0.45_fx, 0.3_fx, -0.2_fx), along_z),
                         v3(0.0001_fx, 0.0001_fx, 0.0001_fx));
  // 0.06 apart: a speculative point.
  const Manifold near_miss =
      collide(capsule, at(o), capsule, at(o + v3(0.56_fx, 0.3_fx, -0.2_fx), along_z), kMargin);
  ASSERT_EQ(near_miss.count, 1U);
  EXPECT_TRUE(near(near_miss.points[0].separation, 0.06_fx));
  EXPECT_TRUE(near(near_miss.points[0].point, o + v3(0.28_fx, 0.3_fx, 0_fx)));
}

TEST_F(CapsuleCapsule, SideBySideGivesTheEndsOfTheOverlap) {
  // Both upright; b 0.5 + gap away in x and 0.5 higher: a's core spans y in [-1, 1], b's
  // [-0.5, 1.5]. The overlap [-0.5, 1] is bounded by b's bottom end and a's top end.
  const Fixed gap = -0.02_fx;
  const Manifold m = collide(capsule, at(o), capsule, at(o + v3(0.48_fx, 0.5_fx, 0_fx)), kMargin);
  ASSERT_EQ(m.count, 2U);
  EXPECT_EQ(m.normal, Vec3::unit_x());
  const ContactPoint* low = find_feature(m, pair(kCore, kBottom));
  const ContactPoint* high = find_feature(m, pair(kTop, kCore));
  ASSERT_NE(low, nullptr);
  ASSERT_NE(high, nullptr);
  EXPECT_EQ(low->separation, gap);
  EXPECT_EQ(high->separation, gap);
  EXPECT_TRUE(near(low->point, o + v3(0.24_fx, -0.5_fx, 0_fx)));
  EXPECT_TRUE(near(high->point, o + v3(0.24_fx, 1_fx, 0_fx)));
  expect_mirrored(capsule, at(o), capsule, at(o + v3(0.48_fx, 0.5_fx, 0_fx)));
  const Manifold moved =
      collide(capsule, at(o), capsule, at(o + v3(0.4801_fx, 0.5001_fx, 0.0001_fx)), kMargin);
  EXPECT_EQ(features(moved), features(m));
}

TEST_F(CapsuleCapsule, LyingOnAnotherDoesNotPivot) {
  // Both along x; b on top of a, shifted 0.5 along x: two points at x = -0.5 and x = 1.
  const Manifold m = collide(capsule, at(o, along_x), capsule,
                             at(o + v3(0.5_fx, 0.49_fx, 0_fx), along_x), kMargin);
  ASSERT_EQ(m.count, 2U);
  EXPECT_TRUE(near(m.normal, Vec3::unit_y()));
  const ContactPoint* low = find_feature(m, pair(kCore, kBottom));
  const ContactPoint* high = find_feature(m, pair(kTop, kCore));
  ASSERT_NE(low, nullptr);
  ASSERT_NE(high, nullptr);
  EXPECT_TRUE(near(low->separation, -0.01_fx));
  EXPECT_TRUE(near(high->separation, -0.01_fx));
  EXPECT_TRUE(near(low->point, o + v3(-0.5_fx, 0.245_fx, 0_fx)));
  EXPECT_TRUE(near(high->point, o + v3(1_fx, 0.245_fx, 0_fx)));
}

TEST_F(CapsuleCapsule, EndToEnd) {
  // Coaxial, b's core starting 0.5 + gap above a's top end: one point between the caps.
  const Manifold m = collide(capsule, at(o), capsule, at(o + v3(0_fx, 2.47_fx, 0_fx)), kMargin);
  ASSERT_EQ(m.count, 1U);
  EXPECT_EQ(m.normal, Vec3::unit_y());
  EXPECT_TRUE(near(m.points[0].separation, -0.03_fx));
  EXPECT_TRUE(near(m.points[0].point, o + v3(0_fx, 1.235_fx, 0_fx)));  // caps at 1.25 and 1.22
  EXPECT_EQ(m.points[0].feature, pair(kTop, kBottom));
}

TEST_F(CapsuleCapsule, DegenerateInputs) {
  // Identical capsules: coincident cores, any perpendicular is as shallow as any other.
  const Manifold same = collide(capsule, at(o), capsule, at(o), kMargin);
  ASSERT_EQ(same.count, 2U);
  expect_well_formed(same, kMargin);
  EXPECT_EQ(same.normal.y, 0_fx);
  for (std::size_t i = 0; i < 2; ++i)
    EXPECT_TRUE(near(same.points[i].separation, -0.5_fx));
  EXPECT_TRUE(identical(same, collide(capsule, at(o), capsule, at(o), kMargin)));
  // Cores crossing at their centres: the normal is perpendicular to both, y x z = x.
  const Manifold crossing = collide(capsule, at(o), capsule, at(o, along_z), kMargin);
  ASSERT_EQ(crossing.count, 1U);
  EXPECT_TRUE(near(crossing.normal, Vec3::unit_x()));
  EXPECT_TRUE(near(crossing.points[0].separation, -0.5_fx));
  // Half height 0 on both sides: two spheres 0.4 apart along z.
  const Shape ball = Shape::capsule(0.25_fx, 0_fx);
  const Manifold balls = collide(ball, at(o), ball, at(o + v3(0_fx, 0_fx, 0.4_fx)), kMargin);
  ASSERT_EQ(balls.count, 1U);
  EXPECT_EQ(balls.normal, Vec3::unit_z());
  EXPECT_TRUE(near(balls.points[0].separation, -0.1_fx));
  EXPECT_EQ(balls.points[0].feature, pair(kBottom, kBottom));
}

// ---- Capsule - plane ----------------------------------------------------------------------------

struct CapsulePlane : ::testing::Test {
  const Vec3 o = v3(-8000_fx, 2_fx, 6000_fx);
  const Shape capsule = Shape::capsule(0.25_fx, 1_fx);
};

TEST_F(CapsulePlane, LyingGivesBothEnds) {
  const Quat along_x = about(Vec3::unit_z(), -quarter_turn);
  EXPECT_EQ(
      collide(capsule, at(o + v3(2_fx, 0.4_fx, 3_fx), along_x), Shape::plane(), at(o), kMargin)
          .count,
      0U);
  const Manifold m =
      collide(capsule, at(o + v3(2_fx, 0.23_fx, 3_fx), along_x), Shape::plane(), at(o), kMargin);
  ASSERT_EQ(m.count, 2U);
  EXPECT_EQ(m.normal, -Vec3::unit_y());
  // The core's -y end maps to x = 2 - 1, its +y end to x = 3.
  const ContactPoint* low = find_feature(m, pair(kBottom, kPlane));
  const ContactPoint* high = find_feature(m, pair(kTop, kPlane));
  ASSERT_NE(low, nullptr);
  ASSERT_NE(high, nullptr);
  EXPECT_TRUE(near(low->separation, -0.02_fx));
  EXPECT_TRUE(near(high->separation, -0.02_fx));
  EXPECT_TRUE(near(low->point, o + v3(1_fx, -0.01_fx, 3_fx)));
  EXPECT_TRUE(near(high->point, o + v3(3_fx, -0.01_fx, 3_fx)));
  expect_mirrored(capsule, at(o + v3(2_fx, 0.23_fx, 3_fx), along_x), Shape::plane(), at(o));
  const Manifold moved = collide(capsule, at(o + v3(2.0001_fx, 0.2301_fx, 3_fx), along_x),
                                 Shape::plane(), at(o), kMargin);
  EXPECT_EQ(features(moved), features(m));
}

TEST_F(CapsulePlane, StandingGivesTheLowerEnd) {
  const Manifold m =
      collide(capsule, at(o + v3(0_fx, 1.3_fx, 0_fx)), Shape::plane(), at(o), kMargin);
  ASSERT_EQ(m.count, 1U);
  EXPECT_TRUE(near(m.points[0].separation, 0.05_fx));
  EXPECT_TRUE(near(m.points[0].point, o + v3(0_fx, 0.025_fx, 0_fx)));
  EXPECT_EQ(m.points[0].feature, pair(kBottom, kPlane));
}

TEST_F(CapsulePlane, ZeroHalfHeightGivesOnePoint) {
  // Both ends coincide: one point, not two identical ones. Centre 0.2 up, radius 0.25.
  const Shape ball = Shape::capsule(0.25_fx, 0_fx);
  const Manifold m = collide(ball, at(o + v3(0_fx, 0.2_fx, 0_fx)), Shape::plane(), at(o), kMargin);
  ASSERT_EQ(m.count, 1U);
  EXPECT_TRUE(near(m.points[0].separation, -0.05_fx));
  EXPECT_EQ(m.points[0].feature, pair(kBottom, kPlane));
}

TEST_F(CapsulePlane, StandingOnATiltedPlane) {
  // Capsule turned with the plane, so its core is along the normal; centre 1.25 + gap above.
  const Fixed angle = Fixed::pi() / 6_fx;
  const Quat q = about(Vec3::unit_z(), angle);
  const Vec3 up = v3(-sin(angle), cos(angle), 0_fx);
  const Manifold m = collide(capsule, at(o + up * 1.2_fx, q), Shape::plane(), at(o, q), kMargin);
  ASSERT_EQ(m.count, 1U);
  EXPECT_TRUE(near(m.normal, -up));
  EXPECT_TRUE(near(m.points[0].separation, -0.05_fx));
  EXPECT_TRUE(near(m.points[0].point, o - up * 0.025_fx));
}

// ---- Extreme scales -----------------------------------------------------------------------------

TEST(CollideScale, MillimetreBoxOnAHugeTurnedGroundFarAway) {
  // Ground: half extents (5000, 1, 5000) turned 30 degrees about y, centred near (9000, -1, -9000)
  // so that its top face is y = 0. A cube of half extent 1e-3 sits on it 8000 m from the ground's
  // centre, sunk by 2e-4. Every separation is -2e-4 and every point 1e-4 below the surface.
  const Quat turn = about(Vec3::unit_y(), Fixed::pi() / 6_fx);
  const Pose ground_pose = at(v3(9000_fx, -1_fx, -9000_fx), turn);
  const Shape ground = Shape::box({5000_fx, 1_fx, 5000_fx});
  const Shape tiny = Shape::box({0.001_fx, 0.001_fx, 0.001_fx});
  const Vec3 spot =
      v3(9000_fx, 0_fx, -9000_fx) + ground_pose.rotation * v3(3000_fx, 0_fx, -1000_fx);
  const Pose tiny_pose = at(spot + v3(0_fx, 0.0008_fx, 0_fx), turn);
  const Manifold m = collide(ground, ground_pose, tiny, tiny_pose, kMargin);
  ASSERT_EQ(m.count, 4U);
  EXPECT_TRUE(near(m.normal, Vec3::unit_y()));
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_TRUE(near(m.points[i].separation, -0.0002_fx));
    EXPECT_TRUE(near(m.points[i].point.y, -0.0001_fx));
    // The corners are 1e-3 sqrt 2 from the cube's centre, in the ground plane.
    const Vec3 d = m.points[i].point - spot;
    EXPECT_TRUE(near(length(v3(d.x, 0_fx, d.z)), Fixed::sqrt2() * 0.001_fx));
  }
  expect_well_formed(m, kMargin);
}

TEST(CollideScale, MillimetreCapsuleOnAPlaneFarAway) {
  // Capsule of radius 1e-3 and half height 2e-3 lying along x, 10^4 m out, sunk by 1e-4.
  const Vec3 o = v3(-10000_fx, 5_fx, 10000_fx);
  const Shape capsule = Shape::capsule(0.001_fx, 0.002_fx);
  const Manifold m =
      collide(capsule, at(o + v3(0_fx, 0.0009_fx, 0_fx), about(Vec3::unit_z(), -quarter_turn)),
              Shape::plane(), at(o), kMargin);
  ASSERT_EQ(m.count, 2U);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_TRUE(near(m.points[i].separation, -0.0001_fx));
    EXPECT_TRUE(near(abs(m.points[i].point.x - o.x), 0.002_fx));
  }
}

// ---- Determinism and robustness -----------------------------------------------------------------

// A fixed pseudo-random sequence (64-bit LCG, Knuth's MMIX constants): reproducible everywhere.
struct Lcg {
  std::uint64_t state = 0x853C49E6748FEA9BULL;
  std::uint64_t next() {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return state >> 11;
  }
  // A Fixed in [lo, hi) with 32 random fraction bits.
  Fixed in(Fixed lo, Fixed hi) {
    const auto r = static_cast<std::int64_t>(next() & 0xFFFFFFFFU);  // [0, 1) as a raw fraction
    return lo + (hi - lo) * Fixed::from_raw(r);
  }
};

Shape random_shape(Lcg& rng, ShapeType type) {
  const Fixed small = 0.001_fx;  // the smallest size the engine supports
  switch (type) {
    case ShapeType::sphere:
      return Shape::sphere(rng.in(small, 1_fx));
    case ShapeType::box:
      return Shape::box({rng.in(small, 1_fx), rng.in(small, 1_fx), rng.in(small, 1_fx)});
    case ShapeType::capsule:
      return Shape::capsule(rng.in(small, 0.5_fx), rng.in(0_fx, 1_fx));
    case ShapeType::plane:
    default:  // the primitives of this test only
      return Shape::plane();
    case ShapeType::cylinder:  // no pair functions yet: not among kTypes below
      return Shape::cylinder(rng.in(small, 0.5_fx), rng.in(small, 1_fx));
  }
  return Shape::plane();
}

Pose random_pose(Lcg& rng, Vec3 around, Fixed spread) {
  const Vec3 offset{rng.in(-spread, spread), rng.in(-spread, spread), rng.in(-spread, spread)};
  const Vec3 axis{rng.in(-1_fx, 1_fx), rng.in(-1_fx, 1_fx), rng.in(-1_fx, 1_fx)};
  // A third of the poses keep an axis-aligned orientation: the exactly parallel cases.
  if (rng.next() % 3 == 0) return at(around + offset);
  return at(around + offset, about(axis, rng.in(-Fixed::pi(), Fixed::pi())));
}

// The test's own geometry, written for clarity rather than speed: how far x lies outside a shape
// (negative inside), and a shape's support (its largest coordinate along a unit direction).
Fixed outside(const Shape& s, const Pose& p, Vec3 x) {
  const Vec3 l = transpose(p.rotation) * (x - p.position);
  switch (s.type) {
    case ShapeType::sphere:
      return length(l) - s.radius;
    case ShapeType::capsule:
      return length(l - v3(0_fx, clamp(l.y, -s.half_height, s.half_height), 0_fx)) - s.radius;
    case ShapeType::plane:
      return l.y;
    case ShapeType::box: {
      const Vec3 h = s.half_extents;
      const Vec3 q{clamp(l.x, -h.x, h.x), clamp(l.y, -h.y, h.y), clamp(l.z, -h.z, h.z)};
      if (q != l) return length(l - q);
      return max(abs(l.x) - h.x, max(abs(l.y) - h.y, abs(l.z) - h.z));
    }
    case ShapeType::cylinder: {
      const Fixed across = hypot(l.x, l.z) - s.radius;
      const Fixed along = abs(l.y) - s.half_height;
      if (across <= 0_fx && along <= 0_fx) return max(across, along);
      return hypot(max(across, 0_fx), max(along, 0_fx));
    }
    default:  // the primitives of this test only
      break;
  }
  return 0_fx;
}

Fixed support(const Shape& s, const Pose& p, Vec3 n) {
  const Fixed c = dot(p.position, n);
  const auto along = [&](std::size_t k) { return abs(dot(p.rotation.column(k), n)); };
  switch (s.type) {
    case ShapeType::sphere:
      return c + s.radius;
    case ShapeType::capsule:
      return c + s.half_height * along(1) + s.radius;
    case ShapeType::plane:
      return c;  // only asked along the plane's own normal
    case ShapeType::box:
      return c + s.half_extents.x * along(0) + s.half_extents.y * along(1) +
             s.half_extents.z * along(2);
    case ShapeType::cylinder:
      return c + s.half_height * along(1) + s.radius * hypot(along(0), along(2));
    default:  // the primitives of this test only
      break;
  }
  return 0_fx;
}

// The geometric contract of a manifold, checked against the test's own geometry above:
// - each point moved half its separation back along the normal lies on a's surface, and moved half
//   forward lies on b's (a capsule's point may lie inside it: it is the contact of the sphere at a
//   core point, pushed out along the normal, which a tilted capsule covers);
// - no point is deeper than the overlap of the shapes' projections on the normal, and where the
//   deepest feature is never clipped away (pairs with a sphere or a plane) the deepest point is
//   exactly that overlap;
// - a sphere with no contact is farther than the margin from the other shape.
void expect_geometry(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, Fixed margin,
                     const Manifold& m) {
  const Fixed tol = 2e-5_fx;
  if (m.count == 0) {
    if (a.type == ShapeType::sphere) {
      EXPECT_GT(outside(b, pb, pa.position) - a.radius, margin - tol);
    }
    if (b.type == ShapeType::sphere) {
      EXPECT_GT(outside(a, pa, pb.position) - b.radius, margin - tol);
    }
    return;
  }
  const Fixed gap = -support(b, pb, -m.normal) - support(a, pa, m.normal);
  Fixed deepest = Fixed::max();
  for (std::size_t k = 0; k < m.count; ++k) {
    const ContactPoint& c = m.points[k];
    EXPECT_GE(c.separation, gap - tol) << "point " << k << " deeper than the overlap";
    deepest = min(deepest, c.separation);
    const Vec3 half = m.normal * (c.separation / 2_fx);
    const Fixed out_a = outside(a, pa, c.point - half);
    const Fixed out_b = outside(b, pb, c.point + half);
    EXPECT_LE(out_a, tol) << "point " << k << " outside a";
    EXPECT_LE(out_b, tol) << "point " << k << " outside b";
    if (a.type != ShapeType::capsule) {
      EXPECT_GE(out_a, -tol) << "point " << k << " inside a";
    }
    if (b.type != ShapeType::capsule) {
      EXPECT_GE(out_b, -tol) << "point " << k << " inside b";
    }
  }
  const bool unclipped = a.type == ShapeType::sphere || b.type == ShapeType::sphere ||
                         a.type == ShapeType::plane || b.type == ShapeType::plane;
  if (unclipped) {
    EXPECT_TRUE(near(deepest, gap, tol)) << "deepest point misses the overlap";
  }
}

// Runs the whole contract on one scene: determinism, well-formedness, exact mirroring by the
// dispatcher for pairs of different types, and the geometry.
void check_scene(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, Fixed margin,
                 int& contacts) {
  const Manifold m = collide(a, pa, b, pb, margin);
  EXPECT_TRUE(identical(m, collide(a, pa, b, pb, margin)));
  expect_well_formed(m, margin);
  if (a.type != b.type) {
    // The dispatcher mirrors one computation: bit for bit.
    const Manifold w = collide(b, pb, a, pa, margin);
    ASSERT_EQ(w.count, m.count);
    EXPECT_EQ(w.normal, -m.normal);
    for (std::size_t k = 0; k < m.count; ++k) {
      EXPECT_EQ(w.points[k].point, m.points[k].point);
      EXPECT_EQ(w.points[k].separation, m.points[k].separation);
      EXPECT_EQ(w.points[k].feature, nf::mirror_feature(m.points[k].feature));
    }
  }
  expect_geometry(a, pa, b, pb, margin, m);
  contacts += m.count > 0 ? 1 : 0;
}

const std::array<ShapeType, 4> kTypes{ShapeType::sphere, ShapeType::box, ShapeType::capsule,
                                      ShapeType::plane};

TEST(CollideFuzz, RandomScenes) {
  Lcg rng;
  int contacts = 0;
  for (int i = 0; i < 10000; ++i) {
    const ShapeType ta = kTypes[rng.next() % 4];
    const ShapeType tb = kTypes[rng.next() % 4];
    const Shape a = random_shape(rng, ta);
    const Shape b = random_shape(rng, tb);
    const Vec3 around{rng.in(-10000_fx, 10000_fx), rng.in(-100_fx, 100_fx),
                      rng.in(-10000_fx, 10000_fx)};
    const Pose pa = random_pose(rng, around, 0_fx);
    const Pose pb = random_pose(rng, around, 1.5_fx);
    const Fixed margin = rng.in(0_fx, 0.2_fx);
    SCOPED_TRACE(::testing::Message() << "scene " << i << " types " << static_cast<int>(ta) << ","
                                      << static_cast<int>(tb));
    check_scene(a, pa, b, pb, margin, contacts);
  }
  EXPECT_GT(contacts, 3500);  // the scenes do collide often
}

// The point of a bounded shape that is farthest along unit n.
Vec3 support_point(const Shape& s, const Pose& p, Vec3 n) {
  const auto side = [&](std::size_t k, Fixed h) {
    const Vec3 axis = p.rotation.column(k);
    return dot(axis, n) >= 0_fx ? axis * h : -(axis * h);
  };
  switch (s.type) {
    case ShapeType::sphere:
      return p.position + n * s.radius;
    case ShapeType::capsule:
      return p.position + side(1, s.half_height) + n * s.radius;
    case ShapeType::box:
      return p.position + side(0, s.half_extents.x) + side(1, s.half_extents.y) +
             side(2, s.half_extents.z);
    case ShapeType::cylinder: {
      const Vec3 axis = p.rotation.column(1);
      const Vec3 rim = normalize_or(n - axis * dot(axis, n), Vec3{});
      return p.position + side(1, s.half_height) + rim * s.radius;
    }
    case ShapeType::plane:
    default:  // the primitives of this test only
      break;
  }
  return p.position;
}

TEST(CollideFuzz, NearlyTouchingScenes) {
  // b's extreme point toward -n is put `gap` beyond a's extreme point toward n: resting, grazing,
  // vertex-on-face, edge-on-edge and corner-to-corner cases. The shapes are then at most `gap`
  // apart, so a gap within the margin must give a (possibly speculative) contact.
  Lcg rng;
  int contacts = 0;
  for (int i = 0; i < 10000; ++i) {
    const ShapeType ta = kTypes[rng.next() % 3];  // bounded shapes only
    const ShapeType tb = kTypes[rng.next() % 3];
    const Shape a = random_shape(rng, ta);
    const Shape b = random_shape(rng, tb);
    const Vec3 around{rng.in(-10000_fx, 10000_fx), rng.in(-100_fx, 100_fx),
                      rng.in(-10000_fx, 10000_fx)};
    const Pose pa = random_pose(rng, around, 0_fx);
    Pose pb = random_pose(rng, around, 0_fx);
    const Vec3 n = normalize_or(Vec3{rng.in(-1_fx, 1_fx), rng.in(-1_fx, 1_fx), rng.in(-1_fx, 1_fx)},
                                Vec3::unit_y());
    const Fixed gap = rng.in(-0.05_fx, 0.1_fx);
    pb.position = pb.position + (support_point(a, pa, n) + n * gap - support_point(b, pb, -n));
    const Fixed margin = rng.in(0_fx, 0.1_fx);
    SCOPED_TRACE(::testing::Message() << "scene " << i << " types " << static_cast<int>(ta) << ","
                                      << static_cast<int>(tb) << " gap " << to_string(gap)
                                      << " margin " << to_string(margin));
    const int before = contacts;
    check_scene(a, pa, b, pb, margin, contacts);
    if (gap < margin - kTol) {
      EXPECT_GT(contacts, before) << "shapes within the margin without a contact";
    }
  }
  EXPECT_GT(contacts, 5500);
}

}  // namespace
