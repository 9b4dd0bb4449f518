// The generic convex narrowphase (sim/src/geometry/convex*.cpp): hulls, boxes, spheres, capsules
// and cylinders against each other and against a plane. Every expected value is worked out from
// the geometry in the comment beside it; hulls are made by hand (support/hull_by_hand.hpp).
#include <array>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "sim/src/geometry/convex_internal.hpp"
#include "support/convex_helpers.hpp"

namespace {

using namespace detsim;
using namespace detsim::literals;
using namespace detsim::collide_test;
using sim_detail::collide_convex;
using sim_detail::convex_plane;
using sim_detail::ConvexView;
using sim_detail::Hull;
namespace cv = sim_detail::convex;

// ---- Against box_box ----------------------------------------------------------------------------

// Ground: half extents (2, 0.5, 2) at g, top face y = 0.5; a unit cube above it, as in
// sim_collide_box_test.cpp. The hand-built box hulls must give box_box's contacts, and the box
// view its feature IDs too.
struct VersusBoxBox : ::testing::Test {
  const Vec3 g = v3(1000_fx, -2_fx, 500_fx);
  const Shape ground = Shape::box({2_fx, 0.5_fx, 2_fx});
  const Shape cube = Shape::box({0.5_fx, 0.5_fx, 0.5_fx});
  void check(const Shape& sa, const Hull& ha, const Pose& pa, const Shape& sb, const Hull& hb,
             const Pose& pb) const {
    const Manifold want = collide(sa, pa, sb, pb, kMargin);
    const Manifold hulls =
        collide_convex(ConvexView::of_hull(ha), pa, ConvexView::of_hull(hb), pb, kMargin);
    expect_same_contacts(hulls, want);
    expect_well_formed(hulls, kMargin);
    const Manifold views = collide_convex(ConvexView::of(sa), pa, ConvexView::of(sb), pb, kMargin);
    expect_same_contacts(views, want);
    EXPECT_EQ(features(views), features(want));
  }
};

TEST_F(VersusBoxBox, RestingSeparatedOverhangAndTilted) {
  const Shapes& s = shapes();
  // Resting 0.01 deep; 0.05 apart (speculative); hanging over a's +x edge; turned 0.1 rad about z
  // with its centre at 1.04 (lowest corner 1.04 - 0.5 (cos 0.1 + sin 0.1) ~ 0.4926 below the top
  // face at 0.5, the other bottom corner ~0.092 above it, within the margin).
  for (const Pose& pb : {at(g + v3(0.3_fx, 0.99_fx, -0.2_fx)), at(g + v3(0.3_fx, 1.05_fx, 0_fx)),
                         at(g + v3(1.8_fx, 0.98_fx, 0_fx)),
                         at(g + v3(0.2_fx, 1.04_fx, 0.1_fx), about(Vec3::unit_z(), 0.1_fx))}) {
    SCOPED_TRACE(to_string(pb.position.x));
    check(ground, s.ground, at(g), cube, s.cube, pb);
  }
}

TEST_F(VersusBoxBox, OctagonReducedLikeBoxBox) {
  // b (half extents 0.6, turned 45 degrees about y) on a unit cube: the octagon of
  // sim_collide_box_test.cpp, reduced to the same four points.
  const Shapes& s = shapes();
  check(cube, s.cube, at(g), Shape::box({0.6_fx, 0.5_fx, 0.6_fx}), s.wide,
        at(g + v3(0_fx, 0.99_fx, 0_fx), about(Vec3::unit_y(), eighth_turn)));
}

TEST_F(VersusBoxBox, EdgeAgainstEdge) {
  // a turned 45 degrees about z: top edge along z at height 0.5 sqrt 2. b turned 45 degrees about
  // x: bottom edge along x, 0.5 sqrt 2 below its centre. Centre heights sqrt 2 + gap apart, b
  // shifted (0.1, 0.2) along the edges: they cross at (0, 0.5 sqrt 2 + gap / 2, 0.2), gap apart.
  const Shapes& s = shapes();
  for (const Fixed gap : {-0.01_fx, 0.05_fx}) {
    const Pose pa = at(g, about(Vec3::unit_z(), eighth_turn));
    const Pose pb =
        at(g + v3(0.1_fx, Fixed::sqrt2() + gap, 0.2_fx), about(Vec3::unit_x(), eighth_turn));
    check(cube, s.cube, pa, cube, s.cube, pb);
    const Manifold m =
        collide_convex(ConvexView::of_hull(s.cube), pa, ConvexView::of_hull(s.cube), pb, kMargin);
    ASSERT_EQ(m.count, 1U);
    EXPECT_TRUE(near(m.normal, Vec3::unit_y()));
    EXPECT_TRUE(near(m.points[0].separation, gap));
    EXPECT_TRUE(near(m.points[0].point, g + v3(0_fx, half_sqrt2 + (gap >> 1), 0.2_fx)));
  }
}

// ---- Hulls -------------------------------------------------------------------------------------

TEST(ConvexHull, TetrahedronVertexIntoABoxFace) {
  // The apex (local (0, -0.5, 0)) 0.02 below the ground's top face y = 0.5: one point, the apex
  // against the face, separation -0.02, midway at height 0.49; normal +y (ground into tetra).
  const Shapes& s = shapes();
  const Vec3 g = v3(-20_fx, 3_fx, 7_fx);
  const Vec3 apex = g + v3(0.2_fx, 0.48_fx, 0.1_fx);
  const Manifold m =
      collide_convex(ConvexView::box({2_fx, 0.5_fx, 2_fx}), at(g), ConvexView::of_hull(s.tetra),
                     at(apex + v3(0_fx, 0.5_fx, 0_fx)), kMargin);
  ASSERT_EQ(m.count, 1U);
  EXPECT_EQ(m.normal, Vec3::unit_y());
  EXPECT_EQ(m.points[0].separation, -0.02_fx);
  EXPECT_TRUE(near(m.points[0].point, apex + v3(0_fx, 0.01_fx, 0_fx)));
  const unsigned i = index_of_vertex(s.tetra, v3(0_fx, -0.5_fx, 0_fx));
  EXPECT_EQ(m.points[0].feature, pair(nf::box_face(1, true), hull_vertex(i)));
}

TEST(ConvexHull, WedgeSlopeOnABoxEdge) {
  // The wedge's slope is the plane y + z = 0 (local), outward normal (0, 1, 1) / sqrt 2. With its
  // centre at (0, -0.5 - d, -0.5 - d) the slope is y + z = -1 - 2 d, and the unit cube's edge
  // along x at (y, z) = (-0.5, -0.5) (y + z = -1) is 2 d / sqrt 2 = d sqrt 2 from it. The wedge's
  // slope is the reference; the cube's bottom face, clipped by it, keeps that edge's two ends
  // (x = +-0.5); the normal points from the cube into the wedge: (0, -1, -1) / sqrt 2.
  const Shapes& s = shapes();
  const Fixed d = -0.01_fx;
  const Manifold m =
      collide_convex(ConvexView::of_hull(s.cube), at({}), ConvexView::of_hull(s.wedge),
                     at(v3(0_fx, -0.5_fx - d, -0.5_fx - d)), kMargin);
  ASSERT_EQ(m.count, 2U);
  EXPECT_TRUE(near(m.normal, v3(0_fx, -half_sqrt2, -half_sqrt2)));
  for (const Fixed x : {-0.5_fx, 0.5_fx}) {
    // Midway between the edge's end and the slope: half the separation along the normal.
    const ContactPoint* c = find_point(
        m, v3(x, -0.5_fx, -0.5_fx) + v3(0_fx, -half_sqrt2, -half_sqrt2) * (d * half_sqrt2));
    ASSERT_NE(c, nullptr) << to_string(x);
    EXPECT_TRUE(near(c->separation, d * Fixed::sqrt2()));
  }
  expect_well_formed(m, kMargin);
}

TEST(ConvexHull, SphereAndCapsuleAgainstHulls) {
  const Shapes& s = shapes();
  const ConvexView ball = ConvexView::sphere(0.25_fx);
  // Above the tetra's top face (y = 0.5) at (-0.2, z = 0) inside its triangle: 0.03 apart.
  Manifold m = collide_convex(ball, at(v3(-0.2_fx, 0.78_fx, 0_fx)), ConvexView::of_hull(s.tetra),
                              at({}), kMargin);
  ASSERT_EQ(m.count, 1U);
  EXPECT_EQ(m.normal, -Vec3::unit_y());
  EXPECT_EQ(m.points[0].separation, 0.03_fx);
  EXPECT_TRUE(near(m.points[0].point, v3(-0.2_fx, 0.515_fx, 0_fx)));
  // Off the cube's corner by (0.1, 0.1, 0.1): distance 0.1 sqrt 3 - 0.25 (< 0: overlapping), the
  // normal along the diagonal; and the same as sphere_box.
  const Pose corner = at(v3(0.6_fx, 0.6_fx, 0.6_fx));
  m = collide_convex(ball, corner, ConvexView::of_hull(s.cube), at({}), kMargin);
  ASSERT_EQ(m.count, 1U);
  EXPECT_TRUE(near(m.points[0].separation, 0.1_fx * sqrt(3_fx) - 0.25_fx));
  EXPECT_TRUE(near(m.normal, -normalize(v3(1_fx, 1_fx, 1_fx))));
  expect_same_contacts(m, collide(Shape::sphere(0.25_fx), corner,
                                  Shape::box({0.5_fx, 0.5_fx, 0.5_fx}), at({}), kMargin));
  // Centre inside, 0.1 below the top face: out through the top, separation -(0.1 + 0.25).
  m = collide_convex(ball, at(v3(0.1_fx, 0.4_fx, 0_fx)), ConvexView::of_hull(s.cube), at({}),
                     kMargin);
  ASSERT_EQ(m.count, 1U);
  EXPECT_TRUE(near(m.points[0].separation, -0.35_fx));
  EXPECT_TRUE(near(m.normal, -Vec3::unit_y()));
  // A capsule (r 0.25, half 0.3) lying along x on the cube's top face, `gap` above it: two points
  // at x = +-0.3, each `gap` apart; the cube is a, so the normal is +y.
  const Fixed gap = 0.02_fx;
  m = collide_convex(ConvexView::of_hull(s.cube), at({}), ConvexView::capsule(0.25_fx, 0.3_fx),
                     at(v3(0_fx, 0.75_fx + gap, 0_fx), about(Vec3::unit_z(), -quarter_turn)),
                     kMargin);
  ASSERT_EQ(m.count, 2U);
  EXPECT_TRUE(near(m.normal, Vec3::unit_y()));
  for (const Fixed x : {-0.3_fx, 0.3_fx}) {
    const ContactPoint* p = find_point(m, v3(x, 0.5_fx + (gap >> 1), 0_fx));
    ASSERT_NE(p, nullptr);
    EXPECT_TRUE(near(p->separation, gap));
  }
}

TEST(ConvexHull, RockAgainstBoxIsWellFormedAndRepeatable) {
  const Shapes& s = shapes();
  const Pose pb = at(v3(0.1_fx, 0.5_fx + 0.3_fx * kPhi - 0.01_fx, 0_fx));
  const ConvexView ground = ConvexView::box({2_fx, 0.5_fx, 2_fx});
  const Manifold m = collide_convex(ground, at({}), ConvexView::of_hull(s.rock), pb, kMargin);
  ASSERT_GT(m.count, 0U);
  expect_well_formed(m, kMargin);
  // Its lowest vertices (+-0.3, -0.3 phi, 0) are 0.01 into the top face.
  EXPECT_TRUE(near(deepest(m), -0.01_fx));
  EXPECT_TRUE(
      identical(m, collide_convex(ground, at({}), ConvexView::of_hull(s.rock), pb, kMargin)));
}

TEST(ConvexHull, ManySidedPrismRestsOnFourOfItsCorners) {
  // A 24-sided prism (radius 0.5, half height 0.3: 48 vertices, 72 edges, more than the SAT's
  // 64-edge cache, so its edges are posed as they are read) resting `gap` into a box's top face:
  // its 24-gon bottom face reduces to four corners, each at `gap`, on the circle of radius 0.5.
  // Coincident with itself, it is finite and repeatable.
  std::vector<Vec3> p;
  for (int k = 0; k < 24; ++k) {
    const SinCos sc = sincos(Fixed::two_pi() * Fixed::from_int(k) / 24_fx);
    p.push_back(v3(sc.cos * 0.5_fx, -0.3_fx, sc.sin * 0.5_fx));
    p.push_back(v3(sc.cos * 0.5_fx, 0.3_fx, sc.sin * 0.5_fx));
  }
  const Hull prism = hull_by_hand(p);
  ASSERT_EQ(prism.edges.size(), 72U);
  const Fixed gap = -0.005_fx;
  const ConvexView ground = ConvexView::box({2_fx, 0.5_fx, 2_fx});
  const Manifold m = collide_convex(ground, at({}), ConvexView::of_hull(prism),
                                    at(v3(0_fx, 0.8_fx + gap, 0_fx)), kMargin);
  ASSERT_EQ(m.count, 4U);
  EXPECT_EQ(m.normal, Vec3::unit_y());
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_TRUE(near(m.points[i].separation, gap));
    EXPECT_TRUE(near(length(v3(m.points[i].point.x, 0_fx, m.points[i].point.z)), 0.5_fx, 1e-5_fx));
  }
  const ConvexView view = ConvexView::of_hull(prism);
  const Manifold self = collide_convex(view, at({}), view, at({}), kMargin);
  ASSERT_GT(self.count, 0U);
  expect_well_formed(self, kMargin);
  EXPECT_TRUE(identical(self, collide_convex(view, at({}), view, at({}), kMargin)));
}

// ---- Planes -------------------------------------------------------------------------------------

TEST(ConvexPlane, HullRestingFlatAndTilted) {
  const Shapes& s = shapes();
  const Vec3 p = v3(30_fx, -5_fx, 12_fx);
  const Fixed gap = -0.01_fx;
  // Flat: the four bottom corners, each exactly `gap` from the plane, midway at height gap / 2.
  Manifold m = convex_plane(ConvexView::of_hull(s.cube), at(p + v3(0_fx, 0.5_fx + gap, 0_fx)),
                            at(p), kMargin);
  ASSERT_EQ(m.count, 4U);
  EXPECT_EQ(m.normal, -Vec3::unit_y());
  for (const Fixed x : {-0.5_fx, 0.5_fx}) {
    for (const Fixed z : {-0.5_fx, 0.5_fx}) {
      const ContactPoint* c = find_point(m, p + v3(x, gap >> 1, z));
      ASSERT_NE(c, nullptr);
      EXPECT_EQ(c->separation, gap);
      EXPECT_EQ(c->feature, pair(hull_vertex(index_of_vertex(s.cube, v3(x, -0.5_fx, z))), kPlane));
    }
  }
  // Turned 0.3 rad about z, centre at height 1: the lowest corner is 0.5 (cos 0.3 + sin 0.3)
  // below the centre, and the deepest point's separation is its height.
  const Fixed theta = 0.3_fx;
  m = convex_plane(ConvexView::of_hull(s.cube),
                   at(p + v3(0_fx, 1_fx, 0_fx), about(Vec3::unit_z(), theta)), at(p), 0.5_fx);
  ASSERT_GT(m.count, 0U);
  EXPECT_TRUE(near(m.points[0].separation, 1_fx - ((cos(theta) + sin(theta)) >> 1)));
  // The wedge flat on its bottom: four points; the rock: its two lowest vertices at 0.3 phi.
  m = convex_plane(ConvexView::of_hull(s.wedge), at(p + v3(0_fx, 0.5_fx, 0_fx)), at(p), kMargin);
  EXPECT_EQ(m.count, 4U);
  m = convex_plane(ConvexView::of_hull(s.rock), at(p + v3(0_fx, 0.3_fx * kPhi + gap, 0_fx)), at(p),
                   kMargin);
  ASSERT_EQ(m.count, 2U);
  for (std::size_t i = 0; i < 2; ++i)
    EXPECT_TRUE(near(m.points[i].separation, gap));
}

TEST(ConvexPlane, RoundCoresAndATurnedPlaneMatchThePrimitivePairs) {
  // A sphere and a lying capsule on a plane turned 0.3 rad about z, and the cube hull on it:
  // the same contacts as sphere_plane, capsule_plane and box_plane (collide() with the plane as b).
  const Shapes& s = shapes();
  const Pose plane = at(v3(3_fx, 1_fx, -2_fx), about(Vec3::unit_z(), 0.3_fx));
  const Vec3 up = plane.rotation.column(1);
  const Pose above = at(plane.position + up * 0.52_fx, about(Vec3::unit_z(), 0.3_fx));
  const Shape ball = Shape::sphere(0.5_fx);
  const Shape capsule = Shape::capsule(0.5_fx, 0.7_fx);
  const Shape box = Shape::box({0.5_fx, 0.5_fx, 0.5_fx});
  expect_same_contacts(convex_plane(ConvexView::of(ball), above, plane, kMargin),
                       collide(ball, above, Shape::plane(), plane, kMargin));
  const Pose lying = at(above.position, about(Vec3::unit_z(), 0.3_fx + quarter_turn));
  expect_same_contacts(convex_plane(ConvexView::of(capsule), lying, plane, kMargin),
                       collide(capsule, lying, Shape::plane(), plane, kMargin));
  const Manifold hull = convex_plane(ConvexView::of_hull(s.cube), above, plane, kMargin);
  expect_same_contacts(hull, collide(box, above, Shape::plane(), plane, kMargin));
  ASSERT_EQ(hull.count, 4U);
  for (std::size_t i = 0; i < 4; ++i)
    EXPECT_TRUE(near(hull.points[i].separation, 0.02_fx));
}

// ---- Cylinders ----------------------------------------------------------------------------------

// Radius 0.4, half height 0.5; lying = turned a quarter about z (its axis along world x).
struct Cylinder : ::testing::Test {
  const ConvexView cyl = ConvexView::cylinder(0.4_fx, 0.5_fx);
  const Vec3 p = v3(-7_fx, 2_fx, 300_fx);
  const Quat lying = about(Vec3::unit_z(), quarter_turn);
  static void expect_on_rim(const Manifold& m, Vec3 axis_point, Fixed r, Fixed gap) {
    ASSERT_EQ(m.count, 4U);
    std::vector<std::uint32_t> f = features(m);
    EXPECT_EQ(std::unique(f.begin(), f.end()), f.end());
    for (std::size_t i = 0; i < 4; ++i) {
      const Vec3 d = m.points[i].point - axis_point;
      EXPECT_TRUE(near(d.y, gap >> 1));
      EXPECT_TRUE(near(length(v3(d.x, 0_fx, d.z)), r));
      EXPECT_TRUE(near(m.points[i].separation, gap));
    }
  }
};

TEST_F(Cylinder, SupportAndSupportingFaces) {
  // Local axis y: along +y the cap (16 rim points at y = h, radius r, counter-clockwise or not,
  // normal +y); along +x the side line (two points at x = r, y = -+h); a tilted direction's
  // support is the rim point below it. A capsule's core + radius is its support too.
  const cv::Face cap = cv::supporting_face(cyl, v3(0.1_fx, 1_fx, 0_fx));
  ASSERT_EQ(cap.count, 16U);
  EXPECT_EQ(cap.normal, Vec3::unit_y());
  EXPECT_EQ(cap.feature, cv::convex_feature(static_cast<unsigned>(nf::Kind::face), 0));
  for (unsigned i = 0; i < 16; ++i) {
    EXPECT_EQ(cap.points[i].y, 0.5_fx);
    EXPECT_TRUE(near(length(v3(cap.points[i].x, 0_fx, cap.points[i].z)), 0.4_fx));
  }
  const cv::Face side = cv::supporting_face(cyl, v3(1_fx, 0.2_fx, 0_fx));
  ASSERT_EQ(side.count, 2U);
  EXPECT_TRUE(near(side.points[0], v3(0.4_fx, -0.5_fx, 0_fx)));
  EXPECT_TRUE(near(side.points[1], v3(0.4_fx, 0.5_fx, 0_fx)));
  EXPECT_TRUE(near(cv::support(cyl, at(p), v3(0_fx, -1_fx, 1_fx)), p + v3(0_fx, -0.5_fx, 0.4_fx)));
  EXPECT_TRUE(near(cv::support(ConvexView::capsule(0.25_fx, 0.5_fx), at(p), v3(1_fx, 0_fx, 0_fx)),
                   p + v3(0.25_fx, 0.5_fx, 0_fx)));
}

TEST_F(Cylinder, StandingOnAPlaneAndABox) {
  // The -y cap `gap` above the plane / the box's top face (y = 0.5): four rim points at gap.
  const Fixed gap = -0.005_fx;
  Manifold m = convex_plane(cyl, at(p + v3(0_fx, 0.5_fx + gap, 0_fx)), at(p), kMargin);
  expect_on_rim(m, p, 0.4_fx, gap);
  for (std::size_t i = 0; i < 4; ++i)
    EXPECT_EQ(m.points[i].separation, gap);  // exact: every height here is exact
  const ConvexView box = ConvexView::box({2_fx, 0.5_fx, 2_fx});
  m = collide_convex(box, at(p), cyl, at(p + v3(0.1_fx, 1_fx + gap, 0_fx)), kMargin);
  EXPECT_EQ(m.normal, Vec3::unit_y());
  expect_on_rim(m, p + v3(0.1_fx, 0.5_fx, 0_fx), 0.4_fx, gap);
}

TEST_F(Cylinder, LyingOnItsSide) {
  // Axis along x, centre at height r + gap: the side line touches, two points at x = +-0.5.
  const Fixed gap = 0.02_fx;
  const Pose pose = at(p + v3(0_fx, 0.4_fx + gap, 0_fx), lying);
  for (const Manifold& m : {convex_plane(cyl, pose, at(p), kMargin),
                            collide_convex(cyl, pose, ConvexView::box({2_fx, 0.5_fx, 2_fx}),
                                           at(p - v3(0_fx, 0.5_fx, 0_fx)), kMargin)}) {
    ASSERT_EQ(m.count, 2U);
    EXPECT_TRUE(near(m.normal, -Vec3::unit_y()));
    for (const Fixed x : {-0.5_fx, 0.5_fx}) {
      const ContactPoint* c = find_point(m, p + v3(x, gap >> 1, 0_fx));
      ASSERT_NE(c, nullptr) << to_string(x);
      EXPECT_TRUE(near(c->separation, gap));
    }
  }
}

TEST_F(Cylinder, CrossedAtRightAngles) {
  // a along x, b along z above it: their sides are r_a + r_b + gap - (r_a + r_b) = gap apart at
  // the crossing point, midway at height r_a + gap / 2 over a's centre.
  const ConvexView thin = ConvexView::cylinder(0.3_fx, 0.6_fx);
  for (const Fixed gap : {-0.01_fx, 0.04_fx}) {
    const Pose pb = at(p + v3(0_fx, 0.7_fx + gap, 0_fx), about(Vec3::unit_x(), quarter_turn));
    const Manifold m = collide_convex(cyl, at(p, lying), thin, pb, kMargin);
    ASSERT_EQ(m.count, 1U);
    EXPECT_TRUE(near(m.normal, Vec3::unit_y()));
    EXPECT_TRUE(near(m.points[0].separation, gap));
    EXPECT_TRUE(near(m.points[0].point, p + v3(0_fx, 0.4_fx + (gap >> 1), 0_fx)));
  }
}

TEST_F(Cylinder, LogsSideBySide) {
  // Two lying cylinders (axes along x), b's centre r_a + r_b + gap above a's: their side lines
  // touch along the whole length, two points at x = +-0.5 (the overlap's ends), each `gap` apart.
  for (const Fixed gap : {-0.01_fx, 0.05_fx}) {
    SCOPED_TRACE(to_string(gap));
    const Manifold m = collide_convex(cyl, at(p, lying), cyl,
                                      at(p + v3(0_fx, 0.8_fx + gap, 0_fx), lying), kMargin);
    ASSERT_EQ(m.count, 2U);
    EXPECT_TRUE(near(m.normal, Vec3::unit_y()));
    for (const Fixed x : {-0.5_fx, 0.5_fx}) {
      const ContactPoint* c = find_point(m, p + v3(x, 0.4_fx + (gap >> 1), 0_fx));
      ASSERT_NE(c, nullptr) << to_string(x);
      EXPECT_TRUE(near(c->separation, gap));
    }
  }
}

TEST_F(Cylinder, TiltedOnAPlaneTouchesAtItsLowestRimPoint) {
  // Tilted 0.4 rad about z with its centre at height 1: the lowest rim point is
  // h cos 0.4 + r sin 0.4 below the centre.
  const Fixed t = 0.4_fx;
  const Manifold m =
      convex_plane(cyl, at(p + v3(0_fx, 1_fx, 0_fx), about(Vec3::unit_z(), t)), at(p), 0.5_fx);
  ASSERT_GT(m.count, 0U);
  expect_well_formed(m, 0.5_fx);
  EXPECT_TRUE(near(m.points[0].separation, 1_fx - 0.5_fx * cos(t) - 0.4_fx * sin(t)));
}

// ---- Properties ---------------------------------------------------------------------------------

TEST(ConvexProperties, SwappedPairsMirror) {
  const Shapes& s = shapes();
  const ConvexView ground = ConvexView::box({2_fx, 0.5_fx, 2_fx});
  const ConvexView cube = ConvexView::of_hull(s.cube);
  expect_convex_mirrored(ground, at({}), cube, at(v3(0.3_fx, 0.99_fx, -0.2_fx)));
  expect_convex_mirrored(ground, at({}), ConvexView::cylinder(0.4_fx, 0.5_fx),
                         at(v3(0.1_fx, 0.995_fx, 0_fx)));
  expect_convex_mirrored(ConvexView::sphere(0.25_fx), at(v3(-0.2_fx, 0.78_fx, 0_fx)),
                         ConvexView::of_hull(s.tetra), at({}));
  expect_convex_mirrored(
      cube, at({}, about(Vec3::unit_z(), eighth_turn)), cube,
      at(v3(0.1_fx, Fixed::sqrt2() - 0.01_fx, 0.2_fx), about(Vec3::unit_x(), eighth_turn)));
  expect_convex_mirrored(ground, at({}), ConvexView::of_hull(s.rock),
                         at(v3(0.1_fx, 0.5_fx + 0.3_fx * kPhi - 0.01_fx, 0_fx)));
}

TEST(ConvexProperties, OneUlpKeepsTheFeatures) {
  const Shapes& s = shapes();
  const Vec3 ulp = v3(Fixed::epsilon(), Fixed::epsilon(), Fixed::epsilon());
  const ConvexView ground = ConvexView::box({2_fx, 0.5_fx, 2_fx});
  const auto stable = [&](const ConvexView& a, const Pose& pa, const ConvexView& b, Pose pb) {
    const Manifold m = collide_convex(a, pa, b, pb, kMargin);
    pb.position += ulp;
    const Manifold moved = collide_convex(a, pa, b, pb, kMargin);
    ASSERT_EQ(m.count, 4U);
    EXPECT_EQ(features(moved), features(m));
  };
  stable(ground, at({}), ConvexView::of_hull(s.cube), at(v3(0.3_fx, 0.99_fx, -0.2_fx)));
  stable(ground, at({}), ConvexView::cylinder(0.4_fx, 0.5_fx), at(v3(0.1_fx, 0.995_fx, 0_fx)));
  const Pose on_plane = at(v3(0_fx, 0.49_fx, 0_fx));
  const Manifold m = convex_plane(ConvexView::of_hull(s.cube), on_plane, at({}), kMargin);
  const Manifold moved =
      convex_plane(ConvexView::of_hull(s.cube), at(on_plane.position + ulp), at({}), kMargin);
  ASSERT_EQ(m.count, 4U);
  EXPECT_EQ(features(moved), features(m));
}

TEST(ConvexProperties, AHairOffLevelKeepsTheFeatures) {
  // A cylinder's cap (16 rim points reduced to four) standing on a box, level and then tilted by
  // 1e-5 rad about three axes: the rim's heights now differ by up to 0.4 * 2e-5 = 8e-6 m, less
  // than the 2^-16 m within which depths count as equal, so the same four points are kept.
  const ConvexView ground = ConvexView::box({2_fx, 0.5_fx, 2_fx});
  const ConvexView cyl = ConvexView::cylinder(0.4_fx, 0.5_fx);
  const Vec3 centre = v3(0.1_fx, 0.995_fx, 0_fx);
  const Manifold level = collide_convex(ground, at({}), cyl, at(centre), kMargin);
  ASSERT_EQ(level.count, 4U);
  for (const Vec3 axis :
       {normalize(v3(1_fx, 0_fx, 1_fx)), normalize(v3(1_fx, 0_fx, -3_fx)), Vec3::unit_z()}) {
    const Manifold off =
        collide_convex(ground, at({}), cyl, at(centre, about(axis, 0.00001_fx)), kMargin);
    EXPECT_EQ(features(off), features(level));
  }
}

TEST(ConvexProperties, MarginIsRespected) {
  const Shapes& s = shapes();
  const Fixed in = kMargin * 0.9_fx;
  const Fixed out = kMargin * 1.1_fx;
  const ConvexView ground = ConvexView::box({2_fx, 0.5_fx, 2_fx});
  const ConvexView cube = ConvexView::of_hull(s.cube);
  const ConvexView cyl = ConvexView::cylinder(0.4_fx, 0.5_fx);
  for (const auto& [gap, expect_points] : {std::pair{in, true}, std::pair{out, false}}) {
    SCOPED_TRACE(to_string(gap));
    const Manifold m[] = {
        collide_convex(ground, at({}), cube, at(v3(0.3_fx, 1_fx + gap, 0_fx)), kMargin),
        convex_plane(cyl, at(v3(0_fx, 0.5_fx + gap, 0_fx)), at({}), kMargin),
        convex_plane(cube, at(v3(0_fx, 0.5_fx + gap, 0_fx)), at({}), kMargin),
        collide_convex(ConvexView::sphere(0.25_fx), at(v3(-0.2_fx, 0.75_fx + gap, 0_fx)),
                       ConvexView::of_hull(s.tetra), at({}), kMargin),
        collide_convex(cyl, at({}, about(Vec3::unit_z(), quarter_turn)), cyl,
                       at(v3(0_fx, 0.8_fx + gap, 0_fx), about(Vec3::unit_x(), quarter_turn)),
                       kMargin),
    };
    for (const Manifold& x : m) {
      EXPECT_EQ(x.count > 0, expect_points);
      expect_well_formed(x, kMargin);
    }
  }
}

// Random poses (a fixed-seed LCG): box hulls and box views give box_box's contacts (the same
// point set and separations within 2^-20; the views also its feature IDs), and a sphere against a
// box hull gives sphere_box's. box_box prefers its first box's faces and collide_convex the
// first of its canonical order, so near a tie between two faces the contacts are box_box's in
// one order or the other. 600 poses, 524 of them touching or within the margin.
TEST(ConvexProperties, RandomPosesAgreeWithThePrimitivePairs) {
  const Shapes& s = shapes();
  Lcg next{12345};
  const Shape cube = Shape::box({0.5_fx, 0.5_fx, 0.5_fx});
  const Shape ground = Shape::box({2_fx, 0.5_fx, 2_fx});
  const Shape ball = Shape::sphere(0.3_fx);
  int touching = 0;
  int other_order = 0;
  for (int i = 0; i < 600; ++i) {
    SCOPED_TRACE(i);
    const bool big = i % 2 == 0;
    const Shape& sa = big ? ground : cube;
    const Hull& ha = big ? s.ground : s.cube;
    const auto [pa, pb] = random_pair(next, v3(5_fx, 1_fx, -3_fx), big ? 1.6_fx : 1.05_fx);
    const Manifold want = collide(sa, pa, cube, pb, kMargin);
    const Manifold want_swapped = mirrored(collide(cube, pb, sa, pa, kMargin));
    touching += want.count > 0 ? 1 : 0;
    const Manifold hulls =
        collide_convex(ConvexView::of_hull(ha), pa, ConvexView::of_hull(s.cube), pb, kMargin);
    const Manifold views =
        collide_convex(ConvexView::of(sa), pa, ConvexView::of(cube), pb, kMargin);
    const bool first = same_contacts(views, want);
    other_order += first ? 0 : 1;
    EXPECT_TRUE(first || same_contacts(views, want_swapped));
    EXPECT_EQ(features(views), features(first ? want : want_swapped));
    EXPECT_TRUE(same_contacts(hulls, first ? want : want_swapped));
    expect_same_contacts(
        collide_convex(ConvexView::of(ball), pb, ConvexView::of_hull(ha), pa, kMargin),
        collide(ball, pb, sa, pa, kMargin));
  }
  EXPECT_GT(touching, 500);
  EXPECT_LT(other_order, 30);  // near ties only (7 of 600 when written)
}

// Every pair of kinds (sphere, capsule, box, cylinder, and the cube, tetrahedron and rock hulls)
// at 100 random poses each, about half of them touching: every manifold well formed and the
// same when computed again, the swapped pair its exact mirror, overlapping cores reported as
// overlapping (no positive separation), and, where the cores are apart,
// the deepest point as far as GJK's distance of the cores less the radii (within 2^-12 m: the
// faces kept are the nearest features) and never farther (a lower bound, as the time-of-impact
// sweep needs, but for the 2^-16 m within which a level face's depths count as equal).
TEST(ConvexProperties, EveryPairOfKindsIsConsistent) {
  const Shapes& s = shapes();
  const std::array<ConvexView, 7> views = {ConvexView::sphere(0.35_fx),
                                           ConvexView::capsule(0.25_fx, 0.4_fx),
                                           ConvexView::box({0.6_fx, 0.3_fx, 0.4_fx}),
                                           ConvexView::cylinder(0.4_fx, 0.5_fx),
                                           ConvexView::of_hull(s.cube),
                                           ConvexView::of_hull(s.tetra),
                                           ConvexView::of_hull(s.rock)};
  Lcg next{4242};
  int touching = 0;
  for (std::size_t i = 0; i < views.size(); ++i) {
    for (std::size_t j = i; j < views.size(); ++j) {
      for (int k = 0; k < 100; ++k) {
        SCOPED_TRACE(testing::Message() << i << " " << j << " " << k);
        const auto [pa, pb] = random_pair(next, v3(10_fx, -4_fx, 2_fx), 0.9_fx);
        const Manifold m = collide_convex(views[i], pa, views[j], pb, kMargin);
        expect_well_formed(m, kMargin);
        EXPECT_TRUE(identical(m, collide_convex(views[i], pa, views[j], pb, kMargin)));
        EXPECT_TRUE(identical(mirrored(m), collide_convex(views[j], pb, views[i], pa, kMargin)));
        if (m.count == 0) continue;
        ++touching;
        const cv::Body a = cv::make_body(views[i], pa, pa.position);
        const cv::Body b = cv::make_body(views[j], pb, pa.position);
        const cv::Closest c = cv::gjk_closest(a, b);
        if (c.overlap) {  // cores that meet: the shapes overlap
          EXPECT_LE(deepest(m), nf::core_epsilon);
          continue;
        }
        const Fixed measured = c.distance - a.radius - b.radius;  // an upper bound
        EXPECT_TRUE(near(deepest(m), measured, 0.000245_fx));
        EXPECT_LE(deepest(m), measured + nf::core_epsilon);  // lower bounds, but for level ties
      }
    }
  }
  EXPECT_GT(touching, 1000);
}

// A cylinder near a box at random poses, apart: the manifold's deepest separation is the sampled
// distance (never above it by more than rounding; below it by less than the sampling's ~1e-3).
// In a one-off run with 1440 x 200 samples, 223 such poses agreed within 6e-5.
TEST(ConvexProperties, CylinderBoxDistanceMatchesSampling) {
  Lcg next{999};
  const Vec3 half = v3(0.7_fx, 0.3_fx, 0.5_fx);
  int checked = 0;
  for (int i = 0; i < 60; ++i) {
    SCOPED_TRACE(i);
    const auto [pa, pb] = random_pair_apart(next, v3(1_fx, 2_fx, 3_fx), 1.6_fx, 0.3_fx);
    const Fixed sampled = sampled_cylinder_box_distance(0.4_fx, 0.5_fx, pb, half, pa);
    if (sampled <= 0.002_fx || sampled > 0.45_fx) continue;
    ++checked;
    const Manifold m =
        collide_convex(ConvexView::box(half), pa, ConvexView::cylinder(0.4_fx, 0.5_fx), pb, 0.5_fx);
    ASSERT_GT(m.count, 0U);
    EXPECT_LE(deepest(m), sampled + 0.00001_fx);
    EXPECT_GE(deepest(m), sampled - 0.001_fx);
  }
  EXPECT_GT(checked, 25);
}

// Two cylinders overlapping a little at random poses: the penetration is minus the largest gap of
// the projections over all directions, sampled here on a 100 x 200 grid (a lower bound of that
// largest gap). The manifold's depth may exceed it by the finite axis set's error only: 0.0036 m
// at worst over 38 such poses (r = 0.4) in a one-off run against a finer grid.
TEST(ConvexProperties, CylinderPenetrationIsNearTheLeastOverlap) {
  Lcg next{31337};
  const ConvexView cyl = ConvexView::cylinder(0.4_fx, 0.5_fx);
  int checked = 0;
  for (int i = 0; i < 60 && checked < 12; ++i) {
    SCOPED_TRACE(i);
    const auto [pa, pb] = random_pair_apart(next, v3(1_fx, 2_fx, 3_fx), 0.9_fx, 0.2_fx);
    const Fixed least_overlap = largest_sampled_gap(cv::make_body(cyl, pa, pa.position),
                                                    cv::make_body(cyl, pb, pa.position), 100);
    if (least_overlap >= Fixed::zero() || least_overlap < -0.1_fx) continue;
    ++checked;
    const Manifold m = collide_convex(cyl, pa, cyl, pb, kMargin);
    ASSERT_GT(m.count, 0U);
    EXPECT_GE(deepest(m), least_overlap - 0.006_fx);
  }
  EXPECT_GE(checked, 8);
}

}  // namespace
