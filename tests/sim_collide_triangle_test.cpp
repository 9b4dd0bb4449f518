// A convex shape against one triangle of a static surface (sim/src/geometry/convex_triangle.cpp):
// resting contacts, internal (flat) and real (ridge) edges, round cores over the face, an edge and
// a vertex, one-sidedness, the margin, feature stability and determinism. Every expected value is
// worked out from the geometry in the comment beside it.
#include <array>
#include <cstdint>

#include <gtest/gtest.h>

#include "sim/src/geometry/convex.hpp"
#include "sim/src/geometry/triangle.hpp"
#include "support/convex_helpers.hpp"

namespace {

using namespace detsim;
using namespace detsim::literals;
using namespace detsim::collide_test;
using sim_detail::collide_triangle;
using sim_detail::ConvexView;
using sim_detail::EdgeKind;
using sim_detail::TriangleData;

const Fixed kExact = Fixed::from_raw(Fixed::one_raw >> 20);  // 2^-20

std::uint16_t tri_face() {
  return nf::feature(nf::Kind::face, 0);
}
std::uint16_t tri_edge(unsigned k) {
  return nf::feature(nf::Kind::edge, k);
}
std::uint16_t tri_vertex(unsigned k) {
  return nf::feature(nf::Kind::vertex, k);
}
std::uint16_t on_triangle(const ContactPoint& p) {
  return static_cast<std::uint16_t>(p.feature >> 16);
}

TriangleData triangle(Vec3 a, Vec3 b, Vec3 c) {
  TriangleData t;
  t.vertices = {a, b, c};
  t.normal = *sim_detail::triangle_normal(a, b, c);
  return t;
}

void expect_normal_everywhere(const Manifold& m, Vec3 normal, Fixed separation, Fixed tol = kTol) {
  expect_well_formed(m, kMargin);
  EXPECT_TRUE(near(m.normal, normal, kExact));
  for (std::size_t i = 0; i < m.count; ++i)
    EXPECT_TRUE(near(m.points[i].separation, separation, tol)) << "point " << i;
}

// A large floor triangle (normal +y in its frame), posed far from the origin and turned 0.3 rad
// about (1, 1, 0) / sqrt 2. Shapes are placed in the surface's frame and posed with it.
struct Floor : ::testing::Test {
  const TriangleData tri =
      triangle(v3(-10_fx, 0_fx, 10_fx), v3(10_fx, 0_fx, 10_fx), v3(0_fx, 0_fx, -10_fx));
  const Pose surface = at(v3(300000000_fx, -200000000_fx, 100000000_fx),
                          about(normalize(v3(1_fx, 1_fx, 0_fx)), 0.3_fx));
  Vec3 world_up() const { return surface.rotation * Vec3::unit_y(); }
  Pose place(Vec3 local, Quat turn = Quat::identity()) const {
    return {surface.position + surface.rotation * local, surface.rotation * to_mat3(turn)};
  }
  Manifold hit(const ConvexView& v, const Pose& p, Fixed margin = kMargin) const {
    return collide_triangle(v, p, tri, surface, margin);
  }
};

TEST_F(Floor, BoxRestsFlatWithFourPoints) {
  // Half extents (0.5, 0.25, 0.5), bottom face 0.01 above the plane (centre at 0.26), turned
  // 0.4 rad about the normal: its four bottom corners, each 0.01 from the plane along -up.
  const ConvexView box = ConvexView::box({0.5_fx, 0.25_fx, 0.5_fx});
  const Pose p = place(v3(1_fx, 0.26_fx, 2_fx), about(Vec3::unit_y(), 0.4_fx));
  const Manifold m = hit(box, p);
  ASSERT_EQ(m.count, 4U);
  expect_normal_everywhere(m, -world_up(), 0.01_fx);
  for (std::size_t i = 0; i < m.count; ++i) {
    EXPECT_EQ(on_triangle(m.points[i]), tri_face());
    EXPECT_EQ(nf::kind_of(static_cast<std::uint16_t>(m.points[i].feature)), nf::Kind::vertex);
    // Midway: 0.005 above the plane.
    const Vec3 rel = m.points[i].point - surface.position;
    EXPECT_TRUE(near(dot(rel, world_up()), 0.005_fx));
  }
  // A 1-ulp move keeps the features; the same call gives the same bits.
  Pose moved = p;
  moved.position.x += Fixed::epsilon();
  EXPECT_EQ(features(hit(box, moved)), features(m));
  EXPECT_TRUE(identical(hit(box, p), m));
}

TEST_F(Floor, SphereOverFaceEdgeAndVertex) {
  const ConvexView ball = ConvexView::sphere(0.5_fx);
  // Over the interior at height 0.55: separation 0.55 - 0.5 = 0.05, the face normal.
  Manifold m = hit(ball, place(v3(1_fx, 0.55_fx, 1_fx)));
  ASSERT_EQ(m.count, 1U);
  expect_normal_everywhere(m, -world_up(), 0.05_fx);
  EXPECT_EQ(on_triangle(m.points[0]), tri_face());
  // Beyond boundary edge 0 (z = 10) at (0, 0.3, 10.3): nearest edge point (0, 0, 10), distance
  // 0.3 sqrt 2 = 0.424264, separation -0.075736, normal (0, -1, -1) / sqrt 2 in the surface frame.
  m = hit(ball, place(v3(0_fx, 0.3_fx, 10.3_fx)));
  ASSERT_EQ(m.count, 1U);
  expect_normal_everywhere(m, surface.rotation * v3(0_fx, -half_sqrt2, -half_sqrt2), -0.075736_fx,
                           2e-6_fx);
  EXPECT_EQ(on_triangle(m.points[0]), tri_edge(0));
  // Beyond vertex 2 (0, 0, -10) at (0, 0.3, -10.4): distance 0.5, separation 0, normal
  // (0, -0.6, 0.8).
  m = hit(ball, place(v3(0_fx, 0.3_fx, -10.4_fx)));
  ASSERT_EQ(m.count, 1U);
  expect_normal_everywhere(m, surface.rotation * v3(0_fx, -0.6_fx, 0.8_fx), 0_fx);
  EXPECT_EQ(on_triangle(m.points[0]), tri_vertex(2));
}

TEST_F(Floor, CapsuleCylinderAndRock) {
  // A capsule (r 0.2, half 1) lying along x at height 0.25: its two ends, 0.05 off the face.
  Manifold m = hit(ConvexView::capsule(0.2_fx, 1_fx),
                   place(v3(0_fx, 0.25_fx, 0_fx), about(Vec3::unit_z(), quarter_turn)));
  ASSERT_EQ(m.count, 2U);
  expect_normal_everywhere(m, -world_up(), 0.05_fx);
  // A cylinder (r 0.5, half 0.5) standing 0.02 above: its cap's rim reduced to four points.
  const ConvexView cyl = ConvexView::cylinder(0.5_fx, 0.5_fx);
  m = hit(cyl, place(v3(0_fx, 0.52_fx, 0_fx)));
  ASSERT_EQ(m.count, 4U);
  expect_normal_everywhere(m, -world_up(), 0.02_fx);
  // Lying (axis along z) 0.02 above: the side line, two points at z = +-0.5.
  m = hit(cyl, place(v3(0_fx, 0.52_fx, 0_fx), about(Vec3::unit_x(), quarter_turn)));
  ASSERT_EQ(m.count, 2U);
  expect_normal_everywhere(m, -world_up(), 0.02_fx);
  // The icosahedron rock rests on its lowest edge, (+-0.3, -0.3 phi, 0): centre 0.3 phi + 0.02
  // above the face, two points 0.02 off.
  const ConvexView rock = ConvexView::of_hull(shapes().rock);
  m = hit(rock, place(v3(2_fx, 0.3_fx * kPhi + 0.02_fx, -1_fx)));
  ASSERT_EQ(m.count, 2U);
  expect_normal_everywhere(m, -world_up(), 0.02_fx);
}

TEST_F(Floor, OneSided) {
  const ConvexView ball = ConvexView::sphere(0.5_fx);
  // Below the triangle (centre 0.2 and 0.6 behind the plane, beyond the 0.1 margin): nothing,
  // though the first overlaps the plane.
  EXPECT_EQ(hit(ball, place(v3(1_fx, -0.2_fx, 1_fx))).count, 0U);
  EXPECT_EQ(hit(ball, place(v3(1_fx, -0.6_fx, 1_fx))).count, 0U);
  // A unit box half through, its centre 0.1 above the plane and over boundary edge 0 (z = 10,
  // the box spans z 9.2 .. 10.2): only the face normal, its bottom corners 0.4 deep.
  const Manifold m =
      hit(ConvexView::box({0.5_fx, 0.5_fx, 0.5_fx}), place(v3(0_fx, 0.1_fx, 9.7_fx)));
  ASSERT_GT(m.count, 0U);
  expect_normal_everywhere(m, -world_up(), -0.4_fx);
}

TEST_F(Floor, Margin) {
  // A sphere over the face at 0.9 and 1.1 margins; a box likewise.
  const ConvexView ball = ConvexView::sphere(0.5_fx);
  EXPECT_EQ(hit(ball, place(v3(1_fx, 0.59_fx, 1_fx))).count, 1U);
  EXPECT_EQ(hit(ball, place(v3(1_fx, 0.61_fx, 1_fx))).count, 0U);
  const ConvexView box = ConvexView::box({0.5_fx, 0.5_fx, 0.5_fx});
  EXPECT_EQ(hit(box, place(v3(1_fx, 0.59_fx, 1_fx))).count, 4U);
  EXPECT_EQ(hit(box, place(v3(1_fx, 0.61_fx, 1_fx))).count, 0U);
}

// Two triangles of one surface sharing the edge x = 0 from P (0, 0, -10) to Q (0, 0, 10): `left`
// (P, R, Q) over x < 0, its edge 2 is Q -> P; `right` (P, Q, S) over x > 0, its edge 0 is P -> Q.
// S is (10, 0, 0) when they are coplanar, or tilted 30 degrees down, (10 cos 30, -5, 0), a ridge.
struct Shared : ::testing::Test {
  const Vec3 p = v3(0_fx, 0_fx, -10_fx);
  const Vec3 q = v3(0_fx, 0_fx, 10_fx);
  const Vec3 r = v3(-10_fx, 0_fx, 0_fx);
  const Pose surface = at(v3(-5000_fx, 20_fx, 7000_fx));
  TriangleData left;
  TriangleData right;
  void make(bool ridge, EdgeKind kind) {
    const Vec3 s = ridge ? v3(8.660254038_fx, -5_fx, 0_fx) : v3(10_fx, 0_fx, 0_fx);
    left = triangle(p, r, q);
    right = triangle(p, q, s);
    left.edges[2] = {kind, right.normal};
    right.edges[0] = {kind, left.normal};
  }
  Pose place(Vec3 local, Quat turn = Quat::identity()) const {
    return {surface.position + local, to_mat3(turn)};
  }
};

TEST_F(Shared, BoxStraddlingFlatEdgeKeepsFaceNormal) {
  // A unit box 0.005 into the floor, centred at x = 0.1 and turned 0.3 rad about y: each
  // triangle's part of its bottom face, with the face normal -y and separation -0.005.
  make(false, EdgeKind::flat);
  const ConvexView box = ConvexView::box({0.5_fx, 0.5_fx, 0.5_fx});
  const Pose b = place(v3(0.1_fx, 0.495_fx, 0_fx), about(Vec3::unit_y(), 0.3_fx));
  for (const TriangleData* t : {&left, &right}) {
    const Manifold m = collide_triangle(box, b, *t, surface, kMargin);
    ASSERT_GT(m.count, 0U);
    expect_normal_everywhere(m, -Vec3::unit_y(), -0.005_fx);
  }
}

TEST_F(Shared, SphereOverFlatEdge) {
  make(false, EdgeKind::flat);
  const ConvexView ball = ConvexView::sphere(0.5_fx);
  // Centred over the shared edge at height 0.55: both triangles, face normal, 0.55 - 0.5.
  for (const TriangleData* t : {&left, &right}) {
    const Manifold m = collide_triangle(ball, place(v3(0_fx, 0.55_fx, 1_fx)), *t, surface, kMargin);
    ASSERT_EQ(m.count, 1U);
    expect_normal_everywhere(m, -Vec3::unit_y(), 0.05_fx);
  }
  // Centre (-0.05, 0.45, 1), over `left`: left's face gives 0.45 - 0.5 = -0.05; right's nearest
  // point is on the shared edge, distance d = sqrt(0.05^2 + 0.45^2) = 0.452769, tilted by
  // cos = 0.45 / d = 0.993884; flat, so the face normal and (d - 0.5) cos = -0.046942.
  const Pose c = place(v3(-0.05_fx, 0.45_fx, 1_fx));
  Manifold m = collide_triangle(ball, c, left, surface, kMargin);
  ASSERT_EQ(m.count, 1U);
  expect_normal_everywhere(m, -Vec3::unit_y(), -0.05_fx);
  m = collide_triangle(ball, c, right, surface, kMargin);
  ASSERT_EQ(m.count, 1U);
  expect_normal_everywhere(m, -Vec3::unit_y(), -0.046942_fx, 2e-6_fx);
  EXPECT_EQ(on_triangle(m.points[0]), tri_edge(0));
  // The same edge as a boundary keeps its true normal (0.05, -0.45, 0) / d and d - 0.5.
  make(false, EdgeKind::boundary);
  m = collide_triangle(ball, c, right, surface, kMargin);
  ASSERT_EQ(m.count, 1U);
  expect_normal_everywhere(m, v3(0.110432_fx, -0.993884_fx, 0_fx), -0.047231_fx, 2e-6_fx);
}

TEST_F(Shared, BoxTiltedOntoRidgeKeepsEdgeNormal) {
  // The right triangle bends 30 degrees down: its normal (0.5, cos 30, 0). A unit box turned
  // -15 degrees about z has its bottom normal along -(sin 15, cos 15, 0), the bisector of the two
  // face normals; centred 0.51 along the bisector from the ridge, its bottom face is 0.01 from
  // the ridge line and rests on it alone (its far corners are 0.5 sin 15 ~ 0.13 off either
  // face). Left triangle: the ridge clipped by the box's sides at z = +-0.5, two points 0.01
  // apart along the box's normal, named by the ridge edge (2).
  make(true, EdgeKind::convex);
  const Fixed deg15 = Fixed::pi() / 12_fx;
  const Vec3 bisector = v3(sin(deg15), cos(deg15), 0_fx);
  const ConvexView box = ConvexView::box({0.5_fx, 0.5_fx, 0.5_fx});
  const Pose b = place(bisector * 0.51_fx, about(Vec3::unit_z(), -deg15));
  Manifold m = collide_triangle(box, b, left, surface, kMargin);
  ASSERT_EQ(m.count, 2U);
  expect_normal_everywhere(m, -bisector, 0.01_fx);
  for (std::size_t i = 0; i < m.count; ++i)
    EXPECT_EQ(on_triangle(m.points[i]), tri_edge(2));
  // The right triangle sees the same ridge, its edge 0.
  m = collide_triangle(box, b, right, surface, kMargin);
  ASSERT_EQ(m.count, 2U);
  expect_normal_everywhere(m, -bisector, 0.01_fx);
  // Were the edge flat, the left triangle would give its face normal, 0.01 cos 15 = 0.009659.
  left.edges[2].kind = EdgeKind::flat;
  m = collide_triangle(box, b, left, surface, kMargin);
  ASSERT_EQ(m.count, 2U);
  expect_normal_everywhere(m, -Vec3::unit_y(), 0.009659_fx);
}

TEST_F(Shared, DeterministicAndStable) {
  // The straddling box of the flat case, moved by one ulp along x: the same features; twice:
  // the same bits.
  make(false, EdgeKind::flat);
  const ConvexView box = ConvexView::box({0.5_fx, 0.5_fx, 0.5_fx});
  const Pose b = place(v3(0.1_fx, 0.495_fx, 0_fx), about(Vec3::unit_y(), 0.3_fx));
  Pose moved = b;
  moved.position.x += Fixed::epsilon();
  for (const TriangleData* t : {&left, &right}) {
    const Manifold m = collide_triangle(box, b, *t, surface, kMargin);
    EXPECT_EQ(features(collide_triangle(box, moved, *t, surface, kMargin)), features(m));
    EXPECT_TRUE(identical(collide_triangle(box, b, *t, surface, kMargin), m));
  }
}

TEST_F(Shared, NoGhostNormalsOnAFlatFloor) {
  // Random boxes, cylinders, rocks and capsules near the shared edge, turned anyhow about y and
  // tilted up to ~0.1 rad, their lowest point between 0.02 deep and 0.05 above the floor: on a
  // flat floor every manifold of either triangle has the face normal -y (within 2^-20) and no
  // separation below the lowest point's height d. With the edge a boundary instead, some contacts
  // on it must tilt (the ghost bumps this removes).
  const ConvexView box = ConvexView::box({0.5_fx, 0.25_fx, 0.5_fx});
  const ConvexView cyl = ConvexView::cylinder(0.4_fx, 0.3_fx);
  const ConvexView rock = ConvexView::of_hull(shapes().rock);
  const ConvexView capsule = ConvexView::capsule(0.2_fx, 0.6_fx);
  Lcg next{0x7121A9u};
  int tilted_on_boundary = 0;
  int contacts = 0;
  for (int i = 0; i < 400; ++i) {
    const ConvexView& v = i % 4 == 0 ? box : (i % 4 == 1 ? cyl : (i % 4 == 2 ? rock : capsule));
    const Quat turn =
        normalize(about(Vec3::unit_y(), next() * Fixed::pi()) *
                  about(normalize(v3(next(), 0_fx, next())), next() * 0.1_fx) *
                  (i % 4 == 3 ? about(Vec3::unit_z(), quarter_turn) : Quat::identity()));
    const Fixed d = 0.015_fx + next() * 0.035_fx;
    Pose pose = place(v3(next() * 0.6_fx, 0_fx, next() * 2_fx), turn);
    const Vec3 low = sim_detail::convex::support(v, pose, -Vec3::unit_y());
    pose.position.y += surface.position.y - low.y + d;
    for (const bool flat : {true, false}) {
      make(false, flat ? EdgeKind::flat : EdgeKind::boundary);
      for (const TriangleData* t : {&left, &right}) {
        const Manifold m = collide_triangle(v, pose, *t, surface, kMargin);
        expect_well_formed(m, kMargin);
        if (m.count == 0) continue;
        if (!flat) {
          tilted_on_boundary += near(m.normal, -Vec3::unit_y(), kExact) ? 0 : 1;
          continue;
        }
        ++contacts;
        EXPECT_TRUE(near(m.normal, -Vec3::unit_y(), kExact)) << "case " << i;
        for (std::size_t k = 0; k < m.count; ++k)
          EXPECT_GE(m.points[k].separation, d - 1e-5_fx)
              << "case " << i << ", feature " << std::hex << m.points[k].feature;
      }
    }
  }
  EXPECT_GT(contacts, 400);
  EXPECT_GT(tilted_on_boundary, 0);
}

TEST_F(Shared, RidgeContactsPointIntoTheBack) {
  // Random shapes over the 30-degree ridge, up to 0.05 into either face: every manifold is well
  // formed, its normal points into the back side of its triangle (dot with -face normal > 0),
  // and a second call gives the same bits.
  make(true, EdgeKind::convex);
  const ConvexView box = ConvexView::box({0.5_fx, 0.25_fx, 0.5_fx});
  const ConvexView rock = ConvexView::of_hull(shapes().rock);
  const ConvexView ball = ConvexView::sphere(0.4_fx);
  Lcg next{0x5EED5u};
  int contacts = 0;
  for (int i = 0; i < 300; ++i) {
    const ConvexView& v = i % 3 == 0 ? box : (i % 3 == 1 ? rock : ball);
    const Quat turn = normalize(Quat{next(), next(), next(), next()});
    const Pose pose = place(v3(next() * 0.8_fx, 0.45_fx + next() * 0.1_fx, next() * 2_fx), turn);
    for (const TriangleData* t : {&left, &right}) {
      const Manifold m = collide_triangle(v, pose, *t, surface, kMargin);
      expect_well_formed(m, kMargin);
      EXPECT_TRUE(identical(collide_triangle(v, pose, *t, surface, kMargin), m));
      if (m.count == 0) continue;
      ++contacts;
      EXPECT_GT(dot(m.normal, -t->normal), Fixed::zero()) << "case " << i;
    }
  }
  EXPECT_GT(contacts, 100);
}

}  // namespace
