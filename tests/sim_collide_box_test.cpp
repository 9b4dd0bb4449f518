// The narrowphase for pairs with a box: box - box, box - capsule and box - plane manifolds
// (sim/src/collide_box.cpp). Every expected value is worked out from the geometry in the comment
// beside it, as in sim_collide_test.cpp; the helpers are in support/collide_helpers.hpp.
#include <array>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "support/collide_helpers.hpp"

namespace {

using namespace detsim;
using namespace detsim::literals;
using namespace detsim::collide_test;

// ---- Box - box ----------------------------------------------------------------------------------

// Ground box a: half extents (2, 0.5, 2) at g; its top face is y = 0.5 in g's frame. Box b: half
// extents 0.5, its centre at height 1 + gap, so its bottom face is `gap` above a's top face.
struct BoxBox : ::testing::Test {
  const Vec3 g = v3(1000_fx, -2_fx, 500_fx);
  const Shape ground = Shape::box({2_fx, 0.5_fx, 2_fx});
  const Shape cube = Shape::box({0.5_fx, 0.5_fx, 0.5_fx});
  Pose cube_at(Fixed x, Fixed gap, Fixed z, Quat q = {}) const {
    return at(g + v3(x, 1_fx + gap, z), q);
  }
};

TEST_F(BoxBox, RestingFlatGivesFourEqualPoints) {
  const Fixed gap = -0.01_fx;
  const Manifold m = collide(ground, at(g), cube, cube_at(0.3_fx, gap, -0.2_fx), kMargin);
  ASSERT_EQ(m.count, 4U);
  EXPECT_EQ(m.normal, Vec3::unit_y());
  // Corners of b's bottom face: x = 0.3 +- 0.5, z = -0.2 +- 0.5; midway in height at 0.5 + gap/2.
  for (const bool px : {false, true}) {
    for (const bool pz : {false, true}) {
      const Vec3 p = g + v3(px ? 0.8_fx : -0.2_fx, 0.495_fx, pz ? 0.3_fx : -0.7_fx);
      const ContactPoint* c = find_point(m, p);
      ASSERT_NE(c, nullptr) << to_string(p.x) << " " << to_string(p.z);
      EXPECT_EQ(c->separation, gap);  // bitwise: every value here is exact
      EXPECT_EQ(c->feature, pair(nf::box_face(1, true), vertex(px, false, pz)));
    }
  }
  expect_well_formed(m, kMargin);
}

TEST_F(BoxBox, SpeculativeAndSeparated) {
  EXPECT_EQ(collide(ground, at(g), cube, cube_at(0.3_fx, 0.2_fx, 0_fx), kMargin).count, 0U);
  const Manifold m = collide(ground, at(g), cube, cube_at(0.3_fx, 0.05_fx, 0_fx), kMargin);
  ASSERT_EQ(m.count, 4U);
  for (std::size_t i = 0; i < 4; ++i)
    EXPECT_EQ(m.points[i].separation, 0.05_fx);
  // Diagonally apart: corner to corner 0.3 in x and in y, beyond every axis' margin.
  EXPECT_EQ(collide(ground, at(g), cube, at(g + v3(2.8_fx, 1.3_fx, 0_fx)), kMargin).count, 0U);
}

TEST_F(BoxBox, OverhangIsClippedAtTheReferenceEdge) {
  // b at x = 1.8 spans x in [1.3, 2.3]; a's top face ends at x = 2. Two points are b's corners at
  // x = 1.3, two are where b's bottom edges along x cross a's side plane x = 2.
  const Manifold m = collide(ground, at(g), cube, cube_at(1.8_fx, -0.02_fx, 0_fx), kMargin);
  ASSERT_EQ(m.count, 4U);
  for (const bool pz : {false, true}) {
    const Fixed z = pz ? 0.5_fx : -0.5_fx;
    const ContactPoint* inner = find_point(m, g + v3(1.3_fx, 0.49_fx, z));
    ASSERT_NE(inner, nullptr);
    EXPECT_EQ(inner->feature, pair(nf::box_face(1, true), vertex(false, false, pz)));
    const ContactPoint* clipped = find_point(m, g + v3(2_fx, 0.49_fx, z));
    ASSERT_NE(clipped, nullptr);
    // a: its top face's edge along z at +x; b: its bottom edge along x on side z.
    EXPECT_EQ(clipped->feature, pair(edge(2, true, true, false), edge(0, false, false, pz)));
    EXPECT_EQ(clipped->separation, -0.02_fx);
  }
}

TEST_F(BoxBox, SwappedPairMirrors) {
  expect_mirrored(ground, at(g), cube, cube_at(0.3_fx, -0.01_fx, -0.2_fx));
  expect_mirrored(ground, at(g), cube, cube_at(1.8_fx, -0.02_fx, 0_fx));
}

TEST_F(BoxBox, FeaturesSurviveATinyMove) {
  const Manifold m = collide(ground, at(g), cube, cube_at(0.3_fx, -0.01_fx, -0.2_fx), kMargin);
  const Manifold moved =
      collide(ground, at(g), cube, cube_at(0.3001_fx, -0.0101_fx, -0.1999_fx), kMargin);
  ASSERT_EQ(moved.count, 4U);
  EXPECT_EQ(features(moved), features(m));
}

TEST_F(BoxBox, TurnedAboutYRestsOnFourCorners) {
  // b turned 45 degrees about y: its bottom corners are at distance 0.5 sqrt 2 from its centre
  // along +-x and +-z. A turn about y keeps every height exact, so the separations are exact.
  const Fixed gap = -0.01_fx;
  const Manifold m = collide(ground, at(g), cube,
                             cube_at(0_fx, gap, 0_fx, about(Vec3::unit_y(), eighth_turn)), kMargin);
  ASSERT_EQ(m.count, 4U);
  EXPECT_EQ(m.normal, Vec3::unit_y());
  const Fixed r = half_sqrt2;
  for (const Vec3 c :
       {v3(r, 0_fx, 0_fx), v3(-r, 0_fx, 0_fx), v3(0_fx, 0_fx, r), v3(0_fx, 0_fx, -r)}) {
    const ContactPoint* p = find_point(m, g + c + v3(0_fx, 0.495_fx, 0_fx));
    ASSERT_NE(p, nullptr) << to_string(c.x) << " " << to_string(c.z);
    EXPECT_EQ(p->separation, gap);
  }
}

TEST_F(BoxBox, OctagonIsReducedToFourSpreadPoints) {
  // b (half extents 0.6, turned 45 degrees about y) on a cube of half extent 0.5: b's bottom face
  // is a diamond |x| + |z| <= 0.6 sqrt 2 ~ 0.8485, clipped by the square |x|, |z| <= 0.5 into an
  // octagon of area 1 - 4 (0.5 - 0.3485)^2 / 2 ~ 0.954. Four points must survive, and the
  // quadrilateral they span must keep most of that area (alternate vertices give ~0.74).
  const Shape wide = Shape::box({0.6_fx, 0.5_fx, 0.6_fx});
  const Manifold m =
      collide(cube, at(g), wide,
              at(g + v3(0_fx, 0.99_fx, 0_fx), about(Vec3::unit_y(), eighth_turn)), kMargin);
  ASSERT_EQ(m.count, 4U);
  expect_well_formed(m, kMargin);
  std::vector<Vec3> p;
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_TRUE(near(m.points[i].separation, -0.01_fx));
    const Vec3 local = m.points[i].point - g;
    // Every point is an octagon vertex: on the square's boundary and on the diamond's.
    EXPECT_TRUE(near(max(abs(local.x), abs(local.z)), 0.5_fx, 1e-5_fx));
    EXPECT_TRUE(near(abs(local.x) + abs(local.z), Fixed::sqrt2() * 0.6_fx, 1e-5_fx));
    p.push_back(local);
  }
  // Area of the convex hull of the four points: sort by angle around their centroid (the quadrant
  // order suffices here), then the shoelace formula.
  const Vec3 centroid = (p[0] + p[1] + p[2] + p[3]) / 4_fx;
  std::sort(p.begin(), p.end(), [&](Vec3 u, Vec3 w) {
    const auto quadrant = [&](Vec3 x) {
      const Vec3 d = x - centroid;
      return d.x >= 0_fx ? (d.z >= 0_fx ? 0 : 3) : (d.z >= 0_fx ? 1 : 2);
    };
    return quadrant(u) < quadrant(w);
  });
  Fixed twice_area;
  for (std::size_t i = 0; i < 4; ++i) {
    const Vec3 u = p[i];
    const Vec3 w = p[(i + 1) % 4];
    twice_area += u.x * w.z - w.x * u.z;
  }
  EXPECT_GT(abs(twice_area), 1.4_fx);  // area > 0.7
}

TEST_F(BoxBox, EdgeAgainstEdge) {
  // a: a unit cube turned 45 degrees about z, so its top edge (along z, at local +x +y) is at
  // height 0.5 sqrt 2. b: a unit cube turned 45 degrees about x, so its bottom edge (along x, at
  // local -y +z) is 0.5 sqrt 2 below its centre. They cross at right angles above a's centre.
  const Fixed gap = -0.01_fx;
  const Vec3 c = v3(-40_fx, 7_fx, 9000_fx);
  const Pose pa = at(c, about(Vec3::unit_z(), eighth_turn));
  const Pose pb = at(c + v3(0_fx, Fixed::sqrt2() + gap, 0_fx), about(Vec3::unit_x(), eighth_turn));
  const Manifold m = collide(cube, pa, cube, pb, kMargin);
  ASSERT_EQ(m.count, 1U);
  EXPECT_TRUE(near(m.normal, Vec3::unit_y()));
  EXPECT_TRUE(near(m.points[0].separation, gap));
  EXPECT_TRUE(near(m.points[0].point, c + v3(0_fx, half_sqrt2 + gap / 2_fx, 0_fx)));
  EXPECT_EQ(m.points[0].feature, pair(edge(2, true, true, false), edge(0, false, false, true)));
  expect_mirrored(cube, pa, cube, pb);
  // Slide b 1e-4 m along both edges: the same edges touch, the point follows.
  const Pose nudged =
      at(pb.position + v3(0.0001_fx, 0_fx, 0.0001_fx), about(Vec3::unit_x(), eighth_turn));
  const Manifold n = collide(cube, pa, cube, nudged, kMargin);
  ASSERT_EQ(n.count, 1U);
  EXPECT_EQ(features(n), features(m));
  // a's edge runs along z at x = 0, b's along x at z = 1e-4: they now cross at z = 1e-4.
  EXPECT_TRUE(near(n.points[0].point, m.points[0].point + v3(0_fx, 0_fx, 0.0001_fx)));
  // Within the margin but apart: one speculative point.
  const Manifold apart = collide(
      cube, pa, cube, at(pb.position + v3(0_fx, 0.06_fx, 0_fx), about(Vec3::unit_x(), eighth_turn)),
      kMargin);
  ASSERT_EQ(apart.count, 1U);
  EXPECT_TRUE(near(apart.points[0].separation, 0.05_fx));
}

TEST_F(BoxBox, CoincidentBoxesAreFiniteAndDeterministic) {
  const Manifold m = collide(cube, at(g), cube, at(g), kMargin);
  ASSERT_GT(m.count, 0U);
  expect_well_formed(m, kMargin);
  // Whatever face is chosen, the boxes must move apart by a full width: 1.
  for (std::size_t i = 0; i < m.count; ++i)
    EXPECT_TRUE(near(m.points[i].separation, -1_fx));
  EXPECT_TRUE(identical(m, collide(cube, at(g), cube, at(g), kMargin)));
}

// ---- Box - capsule ------------------------------------------------------------------------------

// Box half extents (1, 0.5, 1) at p; top face y = 0.5. Capsules of radius 0.25 lying along x are
// a quarter turn about -z (local +y maps to world +x, so the core's -y end is its -x end).
struct BoxCapsule : ::testing::Test {
  const Vec3 p = v3(-300_fx, 40_fx, 70_fx);
  const Shape box = Shape::box({1_fx, 0.5_fx, 1_fx});
  const Quat along_x = about(Vec3::unit_z(), -quarter_turn);
  const Quat along_z = about(Vec3::unit_x(), quarter_turn);
};

TEST_F(BoxCapsule, LyingOnTheTopFaceGivesTwoPoints) {
  const Shape capsule = Shape::capsule(0.25_fx, 0.5_fx);
  // Core at height 0.75 + gap: its surface is `gap` above the face.
  EXPECT_EQ(
      collide(box, at(p), capsule, at(p + v3(0.2_fx, 1.05_fx, 0.3_fx), along_x), kMargin).count,
      0U);
  for (const Fixed gap : {0.05_fx, -0.01_fx}) {
    const Manifold m =
        collide(box, at(p), capsule, at(p + v3(0.2_fx, 0.75_fx + gap, 0.3_fx), along_x), kMargin);
    ASSERT_EQ(m.count, 2U);
    EXPECT_TRUE(near(m.normal, Vec3::unit_y()));
    // The core's ends at x = 0.2 -+ 0.5, both over the face.
    const ContactPoint* low = find_feature(m, pair(nf::box_face(1, true), kBottom));
    const ContactPoint* high = find_feature(m, pair(nf::box_face(1, true), kTop));
    ASSERT_NE(low, nullptr);
    ASSERT_NE(high, nullptr);
    EXPECT_TRUE(near(low->point, p + v3(-0.3_fx, 0.5_fx + gap / 2_fx, 0.3_fx)));
    EXPECT_TRUE(near(high->point, p + v3(0.7_fx, 0.5_fx + gap / 2_fx, 0.3_fx)));
    EXPECT_TRUE(near(low->separation, gap));
    EXPECT_TRUE(near(high->separation, gap));
  }
  const Pose resting = at(p + v3(0.2_fx, 0.74_fx, 0.3_fx), along_x);
  expect_mirrored(box, at(p), capsule, resting);
  const Manifold m = collide(box, at(p), capsule, resting, kMargin);
  const Manifold moved =
      collide(box, at(p), capsule, at(p + v3(0.2001_fx, 0.7401_fx, 0.3_fx), along_x), kMargin);
  EXPECT_EQ(features(moved), features(m));
}

TEST_F(BoxCapsule, LongCapsuleAcrossIsClippedAtTheBoxEdges) {
  // Half height 2: the core spans x in [-2, 2], the face only [-1, 1]. The points are where the
  // core crosses the face's side planes x = +-1, over the face's edges along z.
  const Shape capsule = Shape::capsule(0.25_fx, 2_fx);
  const Manifold m =
      collide(box, at(p), capsule, at(p + v3(0_fx, 0.73_fx, -0.4_fx), along_x), kMargin);
  ASSERT_EQ(m.count, 2U);
  for (const bool px : {false, true}) {
    const ContactPoint* c = find_feature(m, pair(edge(2, px, true, false), kCore));
    ASSERT_NE(c, nullptr);
    EXPECT_TRUE(near(c->point, p + v3(px ? 1_fx : -1_fx, 0.49_fx, -0.4_fx)));
    EXPECT_TRUE(near(c->separation, -0.02_fx));
  }
}

TEST_F(BoxCapsule, ParallelToABoxEdgeGivesTwoPoints) {
  // Core along z at (1.3, 0.9): 0.5 from the edge along z at x = 1, y = 0.5, in direction
  // (0.6, 0.8, 0). Radius 0.45 leaves 0.05. The core spans z in [-0.3, 0.7], inside the edge.
  const Shape capsule = Shape::capsule(0.45_fx, 0.5_fx);
  const Manifold m =
      collide(box, at(p), capsule, at(p + v3(1.3_fx, 0.9_fx, 0.2_fx), along_z), kMargin);
  ASSERT_EQ(m.count, 2U);
  const Vec3 n = v3(0.6_fx, 0.8_fx, 0_fx);
  EXPECT_TRUE(near(m.normal, n));
  for (const bool top : {false, true}) {
    const ContactPoint* c = find_feature(m, pair(edge(2, true, true, false), top ? kTop : kBottom));
    ASSERT_NE(c, nullptr);
    EXPECT_TRUE(near(c->separation, 0.05_fx));
    EXPECT_TRUE(near(c->point, p + v3(1_fx, 0.5_fx, top ? 0.7_fx : -0.3_fx) + n * 0.025_fx));
  }
}

TEST_F(BoxCapsule, AcrossAVerticalEdgeGivesOnePoint) {
  // The edge along y at x = z = 1. A horizontal core along (1, 0, -1) / sqrt 2 passes 0.6 from it
  // at height 0.1, in direction n = (1, 0, 1) / sqrt 2; radius 0.5 leaves 0.1 (margin 0.2).
  const Shape capsule = Shape::capsule(0.5_fx, 1_fx);
  const Quat turn = about(Vec3::unit_y(), eighth_turn) * along_x;  // +y -> +x -> (1, 0, -1)/sqrt 2
  const Vec3 n = v3(half_sqrt2, 0_fx, half_sqrt2);
  const Vec3 on_edge = v3(1_fx, 0.1_fx, 1_fx);
  const Manifold m = collide(box, at(p), capsule, at(p + on_edge + n * 0.6_fx, turn), 0.2_fx);
  ASSERT_EQ(m.count, 1U);
  EXPECT_TRUE(near(m.normal, n));
  EXPECT_TRUE(near(m.points[0].separation, 0.1_fx));
  EXPECT_TRUE(near(m.points[0].point, p + on_edge + n * 0.05_fx));
  EXPECT_EQ(m.points[0].feature, pair(edge(1, true, false, true), kCore));
}

TEST_F(BoxCapsule, StandingOnTheFaceGivesOnePoint) {
  // Upright core from y = 0.75 + gap to 2.75 + gap: only its lower end is within the margin.
  const Shape capsule = Shape::capsule(0.25_fx, 1_fx);
  const Manifold m = collide(box, at(p), capsule, at(p + v3(0.3_fx, 1.72_fx, -0.4_fx)), kMargin);
  ASSERT_EQ(m.count, 1U);
  EXPECT_EQ(m.normal, Vec3::unit_y());
  EXPECT_TRUE(near(m.points[0].separation, -0.03_fx));
  EXPECT_TRUE(near(m.points[0].point, p + v3(0.3_fx, 0.485_fx, -0.4_fx)));
  EXPECT_EQ(m.points[0].feature, pair(nf::box_face(1, true), kBottom));
}

TEST_F(BoxCapsule, CoreInsideTheBoxUsesTheShallowestFace) {
  // Core along x at height 0.4, inside the box: the shallowest way out is up through y = 0.5.
  // The capsule's lowest surface is at 0.4 - 0.25 = 0.15, so the separation is 0.15 - 0.5 = -0.35
  // at both ends x = +-0.5.
  const Shape capsule = Shape::capsule(0.25_fx, 0.5_fx);
  const Manifold m = collide(box, at(p), capsule, at(p + v3(0_fx, 0.4_fx, 0_fx), along_x), kMargin);
  ASSERT_EQ(m.count, 2U);
  EXPECT_TRUE(near(m.normal, Vec3::unit_y()));
  for (const bool top : {false, true}) {
    const ContactPoint* c = find_feature(m, pair(nf::box_face(1, true), top ? kTop : kBottom));
    ASSERT_NE(c, nullptr);
    EXPECT_TRUE(near(c->separation, -0.35_fx));
    // Midway between the face (0.5) and the capsule's lowest surface point (0.15).
    EXPECT_TRUE(near(c->point, p + v3(top ? 0.5_fx : -0.5_fx, 0.325_fx, 0_fx)));
  }
  expect_mirrored(box, at(p), capsule, at(p + v3(0_fx, 0.4_fx, 0_fx), along_x));
}

TEST_F(BoxCapsule, ZeroHalfHeightBehavesLikeASphere) {
  // The same corner case as SphereBox.NearACorner, unrotated: a gap of 0.05 off the corner.
  const Shape ball = Shape::capsule(0.25_fx, 0_fx);
  const Manifold m = collide(box, at(p), ball, at(p + v3(1.2_fx, 0.7_fx, 1.1_fx)), kMargin);
  ASSERT_EQ(m.count, 1U);
  EXPECT_TRUE(near(m.points[0].separation, 0.05_fx));
  EXPECT_TRUE(near(m.normal, v3(2_fx, 2_fx, 1_fx) / 3_fx));
  EXPECT_EQ(m.points[0].feature, pair(vertex(true, true, true), kBottom));
  // And fully inside: out through the nearest face, +y (0.3 below it): -(0.3 + 0.25).
  const Manifold in = collide(box, at(p), ball, at(p + v3(0_fx, 0.2_fx, 0_fx)), kMargin);
  ASSERT_EQ(in.count, 1U);
  EXPECT_TRUE(near(in.normal, Vec3::unit_y()));
  EXPECT_TRUE(near(in.points[0].separation, -0.55_fx));
}

TEST_F(BoxCapsule, CoincidentCentresAreFiniteAndDeterministic) {
  // An upright capsule (half height 0.3, radius 0.25) centred in the box. Ways out: along y,
  // 0.5 + 0.3 + 0.25 = 1.05; along x or z, 1 + 0.25 = 1.25. So +y (the centre is at y = 0, which
  // counts as the + side), with the core's ends at depths 1.05 (bottom) and 0.45 (top).
  const Shape capsule = Shape::capsule(0.25_fx, 0.3_fx);
  const Manifold m = collide(box, at(p), capsule, at(p), kMargin);
  ASSERT_EQ(m.count, 2U);
  expect_well_formed(m, kMargin);
  EXPECT_EQ(m.normal, Vec3::unit_y());
  const ContactPoint* low = find_feature(m, pair(nf::box_face(1, true), kBottom));
  const ContactPoint* high = find_feature(m, pair(nf::box_face(1, true), kTop));
  ASSERT_NE(low, nullptr);
  ASSERT_NE(high, nullptr);
  EXPECT_TRUE(near(low->separation, -1.05_fx));
  EXPECT_TRUE(near(high->separation, -0.45_fx));
  EXPECT_TRUE(identical(m, collide(box, at(p), capsule, at(p), kMargin)));
}

TEST_F(BoxCapsule, OnATurnedBox) {
  // The lying case in the frame of a box turned 30 degrees about y.
  const Pose box_pose = at(p, about(Vec3::unit_y(), Fixed::pi() / 6_fx));
  const Quat turn = about(Vec3::unit_y(), Fixed::pi() / 6_fx) * along_x;
  const Shape capsule = Shape::capsule(0.25_fx, 0.5_fx);
  const Vec3 local = v3(0.2_fx, 0.74_fx, 0.3_fx);
  const Manifold m =
      collide(box, box_pose, capsule, at(p + box_pose.rotation * local, turn), kMargin);
  ASSERT_EQ(m.count, 2U);
  EXPECT_TRUE(near(m.normal, Vec3::unit_y()));
  const ContactPoint* low = find_feature(m, pair(nf::box_face(1, true), kBottom));
  ASSERT_NE(low, nullptr);
  EXPECT_TRUE(near(low->separation, -0.01_fx));
  EXPECT_TRUE(near(low->point, p + box_pose.rotation * v3(-0.3_fx, 0.495_fx, 0.3_fx)));
}

// ---- Box - plane --------------------------------------------------------------------------------

// Ground plane through (0, -1, 0). Box half extents (0.5, 0.25, 1) with its centre 0.25 + gap
// above it.
struct BoxPlane : ::testing::Test {
  const Vec3 o = v3(0_fx, -1_fx, 0_fx);
  const Pose plane_pose = at(o);
  const Shape box = Shape::box({0.5_fx, 0.25_fx, 1_fx});
  Pose box_at(Fixed gap, Quat q = {}) const { return at(o + v3(3_fx, 0.25_fx + gap, 7_fx), q); }
};

TEST_F(BoxPlane, FlatGivesTheFourBottomCorners) {
  EXPECT_EQ(collide(box, box_at(0.2_fx), Shape::plane(), plane_pose, kMargin).count, 0U);
  for (const Fixed gap : {0.05_fx, -0.02_fx}) {
    const Manifold m = collide(box, box_at(gap), Shape::plane(), plane_pose, kMargin);
    ASSERT_EQ(m.count, 4U);
    EXPECT_EQ(m.normal, -Vec3::unit_y());
    for (const bool px : {false, true}) {
      for (const bool pz : {false, true}) {
        const ContactPoint* c = find_feature(m, pair(vertex(px, false, pz), kPlane));
        ASSERT_NE(c, nullptr);
        EXPECT_EQ(c->separation, gap);
        // Midway in height at gap / 2; half of an odd raw gap rounds to even, so allow an ulp.
        EXPECT_TRUE(near(c->point, o + v3(px ? 3.5_fx : 2.5_fx, gap / 2_fx, pz ? 8_fx : 6_fx),
                         Fixed::epsilon()));
      }
    }
  }
  expect_mirrored(box, box_at(-0.02_fx), Shape::plane(), plane_pose);
  const Manifold m = collide(box, box_at(-0.02_fx), Shape::plane(), plane_pose, kMargin);
  const Manifold moved =
      collide(box, at(box_at(-0.02_fx).position + v3(0.0001_fx, 0.0001_fx, 0_fx)), Shape::plane(),
              plane_pose, kMargin);
  EXPECT_EQ(features(moved), features(m));
}

TEST_F(BoxPlane, TurnedAboutYKeepsFourEqualPoints) {
  const Manifold m = collide(box, box_at(-0.01_fx, about(Vec3::unit_y(), eighth_turn)),
                             Shape::plane(), plane_pose, kMargin);
  ASSERT_EQ(m.count, 4U);
  // Bottom corners (+-0.5, +-1) turned 45 degrees about y: x' = (x + z)/sqrt 2, z' = (z -
  // x)/sqrt 2.
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(m.points[i].separation, -0.01_fx);
    const Vec3 d = m.points[i].point - (o + v3(3_fx, 0_fx, 7_fx));
    EXPECT_TRUE(near(d.y, -0.005_fx));
    EXPECT_TRUE(near(d.x * d.x + d.z * d.z, 1.25_fx, 1e-5_fx));  // 0.5^2 + 1^2
  }
  EXPECT_NE(
      find_point(m, o + v3(3_fx + 1.5_fx * half_sqrt2, -0.005_fx, 7_fx + 0.5_fx * half_sqrt2)),
      nullptr);
}

TEST_F(BoxPlane, TurnedAboutAnArbitraryAxis) {
  // The lowest point of a box is its centre height minus its support along the normal:
  // sum_i h_i |up . axis_i|, where axis_i are the rotation's columns (so up . axis_i is row 1).
  const Mat3 r = to_mat3(about(v3(1_fx, 2_fx, 3_fx), 0.7_fx));
  const Vec3 h = box.half_extents;
  const Fixed support = h.x * abs(r.rows[1].x) + h.y * abs(r.rows[1].y) + h.z * abs(r.rows[1].z);
  const Vec3 centre = o + v3(-20_fx, support - 0.01_fx, 4_fx);
  // Each other vertex is higher by at least twice the smallest h_i |up . axis_i|.
  const Fixed step =
      2_fx * min(h.x * abs(r.rows[1].x), min(h.y * abs(r.rows[1].y), h.z * abs(r.rows[1].z)));
  ASSERT_GT(step, 0.05_fx);
  const Manifold m = collide(box, Pose{centre, r}, Shape::plane(), plane_pose, 0_fx);
  ASSERT_EQ(m.count, 1U);
  EXPECT_TRUE(near(m.points[0].separation, -0.01_fx));
  // That vertex: each coordinate on the side that goes down, -sign(up . axis_i) h_i.
  const Vec3 corner{r.rows[1].x > 0_fx ? -h.x : h.x, r.rows[1].y > 0_fx ? -h.y : h.y,
                    r.rows[1].z > 0_fx ? -h.z : h.z};
  const Vec3 low = centre + r * corner;
  EXPECT_TRUE(near(m.points[0].point, low + v3(0_fx, 0.005_fx, 0_fx)));
  EXPECT_EQ(m.points[0].feature,
            pair(vertex(corner.x > 0_fx, corner.y > 0_fx, corner.z > 0_fx), kPlane));
  // With a margin covering more vertices, the deepest comes first and at most four are kept.
  const Manifold wide = collide(box, Pose{centre, r}, Shape::plane(), plane_pose, 10_fx);
  ASSERT_EQ(wide.count, 4U);
  for (std::size_t i = 0; i < 4; ++i)
    EXPECT_GE(wide.points[i].separation, -0.01_fx - kTol);
  EXPECT_TRUE(near(wide.points[0].separation, -0.01_fx));
}

TEST_F(BoxPlane, OnATiltedPlane) {
  // Plane and box turned together 30 degrees about z; the box centre 0.25 + gap along the normal.
  const Fixed angle = Fixed::pi() / 6_fx;
  const Quat q = about(Vec3::unit_z(), angle);
  const Vec3 up = v3(-sin(angle), cos(angle), 0_fx);
  const Vec3 along = v3(cos(angle), sin(angle), 0_fx);
  const Pose tilted = at(o, q);
  const Manifold m =
      collide(box, at(o + along * 50_fx + up * 0.24_fx, q), Shape::plane(), tilted, kMargin);
  ASSERT_EQ(m.count, 4U);
  EXPECT_TRUE(near(m.normal, -up));
  for (std::size_t i = 0; i < 4; ++i)
    EXPECT_TRUE(near(m.points[i].separation, -0.01_fx));
}

}  // namespace
