// The convex hull builder (sim/src/geometry/hull_build.cpp), its solid properties
// (hull_mass.cpp) and the principal frames of inertia tensors (inertia.cpp). Every expected
// value comes from a closed form (a box's, a regular tetrahedron's, an octahedron's), never from a
// recorded run.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>
#include <detsim/fixed/exact_sum.hpp>

#include "sim/src/geometry/hull.hpp"
#include "sim/src/geometry/inertia.hpp"
#include "support/vector_print.hpp"

namespace detsim {
namespace {

using namespace detsim::literals;
using sim_detail::build_hull;
using sim_detail::Hull;
using sim_detail::HullFace;

double d(Fixed x) {
  return x.to_double();
}

/// The largest relative error expect_close saw (printed by the last test, for the record).
double worst_relative = 0;

/// |a - b| <= rel * scale.
void expect_close(Fixed a, double b, double rel, double scale, const std::string& what) {
  worst_relative = std::max(worst_relative, std::abs(d(a) - b) / scale);
  EXPECT_LE(std::abs(d(a) - b), rel * scale) << what << ": " << d(a) << " vs " << b;
}

std::vector<Vec3> box_corners(Vec3 h, Vec3 at = {}) {
  std::vector<Vec3> out;
  for (int i = 0; i < 8; ++i) {
    out.push_back(
        at + Vec3{(i & 1) != 0 ? h.x : -h.x, (i & 2) != 0 ? h.y : -h.y, (i & 4) != 0 ? h.z : -h.z});
  }
  return out;
}

void expect_same_hull(const Hull& a, const Hull& b) {
  EXPECT_EQ(a.vertices, b.vertices);
  ASSERT_EQ(a.faces.size(), b.faces.size());
  for (std::size_t i = 0; i < a.faces.size(); ++i) {
    EXPECT_EQ(a.faces[i].normal, b.faces[i].normal);
    EXPECT_EQ(a.faces[i].offset, b.faces[i].offset);
    EXPECT_EQ(a.faces[i].first, b.faces[i].first);
    EXPECT_EQ(a.faces[i].count, b.faces[i].count);
  }
  EXPECT_EQ(a.face_vertices, b.face_vertices);
  ASSERT_EQ(a.edges.size(), b.edges.size());
  for (std::size_t i = 0; i < a.edges.size(); ++i) {
    EXPECT_EQ(a.edges[i].a, b.edges[i].a);
    EXPECT_EQ(a.edges[i].b, b.edges[i].b);
    EXPECT_EQ(a.edges[i].face_0, b.edges[i].face_0);
    EXPECT_EQ(a.edges[i].face_1, b.edges[i].face_1);
  }
  EXPECT_EQ(a.solid.volume, b.solid.volume);
  EXPECT_EQ(a.solid.centroid, b.solid.centroid);
  EXPECT_EQ(a.solid.inertia_per_mass, b.solid.inertia_per_mass);
  EXPECT_EQ(a.solid.principal, b.solid.principal);
  EXPECT_EQ(a.solid.principal_axes, b.solid.principal_axes);
  EXPECT_EQ(a.aabb_min, b.aabb_min);
  EXPECT_EQ(a.aabb_max, b.aabb_max);
  EXPECT_EQ(a.bounding_radius, b.bounding_radius);
  EXPECT_EQ(a.inner_radius, b.inner_radius);
}

void shuffle(std::vector<Vec3>& v, Rng& rng) {
  for (std::size_t i = v.size(); i > 1; --i)
    std::swap(v[i - 1], v[rng.below(i)]);
}

/// The box's inertia per unit mass about its centre: (b^2 + c^2) / 3, ...
std::array<double, 3> box_moments(Vec3 h) {
  const double x = d(h.x) * d(h.x);
  const double y = d(h.y) * d(h.y);
  const double z = d(h.z) * d(h.z);
  return {(y + z) / 3, (x + z) / 3, (x + y) / 3};
}

void expect_tensor(const Mat3& m, const std::array<std::array<double, 3>, 3>& want, double rel,
                   const std::string& what) {
  double scale = 0;
  for (const auto& row : want) {
    for (const double x : row)
      scale = std::max(scale, std::abs(x));
  }
  for (std::size_t i = 0; i < 3; ++i) {
    const std::array<Fixed, 3> row{m.rows[i].x, m.rows[i].y, m.rows[i].z};
    for (std::size_t j = 0; j < 3; ++j)
      expect_close(row[j], want[i][j], rel, scale,
                   what + " [" + std::to_string(i) + "][" + std::to_string(j) + "]");
  }
}

std::array<std::array<double, 3>, 3> diagonal(std::array<double, 3> m) {
  return {{{m[0], 0, 0}, {0, m[1], 0}, {0, 0, m[2]}}};
}

/// Every structural promise of hull.hpp, checked against the input points.
void expect_valid_hull(const Hull& hull, const std::vector<Vec3>& points) {
  const std::size_t v = hull.vertices.size();
  const std::size_t f = hull.faces.size();
  const std::size_t e = hull.edges.size();
  EXPECT_EQ(v + f, e + 2) << "Euler: V - E + F = 2";
  Fixed extent;
  for (const Vec3 p : points)
    extent = max(extent, length(p - hull.vertices[0]));
  const double tol = d(sim_detail::hull_tolerance(extent));
  for (std::size_t i = 0; i + 1 < v; ++i) {
    const auto key = [](Vec3 p) { return std::array{p.x.raw(), p.y.raw(), p.z.raw()}; };
    EXPECT_LT(key(hull.vertices[i]), key(hull.vertices[i + 1])) << "vertices ascending";
  }
  for (const Vec3 p : hull.vertices)
    EXPECT_NE(std::find(points.begin(), points.end(), p), points.end()) << "vertex not an input";
  std::vector<int> faces_at(v, 0);
  for (const HullFace& face : hull.faces) {
    ASSERT_GE(face.count, 3);
    EXPECT_NEAR(d(length(face.normal)), 1.0, 1e-8);
    const std::uint16_t* loop = hull.face_vertices.data() + face.first;
    for (std::uint16_t k = 0; k < face.count; ++k) {
      ++faces_at[loop[k]];
      const Vec3 a = hull.vertices[loop[k]];
      const Vec3 b = hull.vertices[loop[(k + 1) % face.count]];
      const Vec3 c = hull.vertices[loop[(k + 2) % face.count]];
      // Planar: every vertex on the plane; convex and counter-clockwise: every turn is a left
      // turn about the outward normal.
      EXPECT_LE(std::abs(d(dot(face.normal, a)) - d(face.offset)), 2 * tol) << "planar";
      EXPECT_GT(d(dot(cross(b - a, c - b), face.normal)), 0.0) << "convex";
    }
    // Outward: the centroid is below every face, and every input point is inside or within the
    // tolerance.
    EXPECT_GT(d(face.offset - dot(face.normal, hull.solid.centroid)), 0.0);
    for (const Vec3 p : points)
      EXPECT_LE(d(dot(face.normal, p)), d(face.offset) + 4 * tol) << "a point outside";
    for (const Vec3 p : hull.vertices)
      EXPECT_LE(dot(face.normal, p), face.offset) << "a vertex above a face plane";
  }
  for (std::size_t i = 0; i < v; ++i)
    EXPECT_GE(faces_at[i], 3) << "vertex " << i << " no corner";
  for (std::size_t i = 0; i < e; ++i) {
    const auto& edge = hull.edges[i];
    EXPECT_LT(edge.a, edge.b);
    if (i > 0) {
      EXPECT_LT(std::pair(hull.edges[i - 1].a, hull.edges[i - 1].b), std::pair(edge.a, edge.b));
    }
    const auto runs = [&hull](std::uint16_t index, std::uint16_t from, std::uint16_t to) {
      const HullFace& face = hull.faces[index];
      const std::uint16_t* loop = hull.face_vertices.data() + face.first;
      for (std::uint16_t k = 0; k < face.count; ++k) {
        if (loop[k] == from && loop[(k + 1) % face.count] == to) return true;
      }
      return false;
    };
    EXPECT_TRUE(runs(edge.face_0, edge.a, edge.b));
    EXPECT_TRUE(runs(edge.face_1, edge.b, edge.a));
  }
  EXPECT_GT(hull.inner_radius, Fixed::zero());
  EXPECT_GT(hull.solid.volume, Fixed::zero());
}

TEST(Hull, UnitCubeWithInteriorDuplicateFaceAndEdgePoints) {
  const Fixed h = 1_fx;
  std::vector<Vec3> points = box_corners({h, h, h});
  Rng rng(1);
  for (int i = 0; i < 200; ++i)
    points.push_back({rng.uniform(-h, h), rng.uniform(-h, h), rng.uniform(-h, h)});
  for (int i = 0; i < 8; ++i)
    points.push_back(points[static_cast<std::size_t>(i)]);  // duplicates
  for (const Fixed s : {-h, h}) {                           // face centres and points on the faces
    points.push_back({s, 0_fx, 0_fx});
    points.push_back({0_fx, s, 0_fx});
    points.push_back({0_fx, 0_fx, s});
    points.push_back({s, rng.uniform(-h, h), rng.uniform(-h, h)});
    for (const Fixed t : {-h, h}) {  // edge midpoints
      points.push_back({s, t, 0_fx});
      points.push_back({s, 0_fx, t});
      points.push_back({0_fx, s, t});
    }
  }
  const auto built = build_hull(points);
  ASSERT_TRUE(built.ok()) << built.message();
  const Hull& hull = *built;
  std::vector<Vec3> corners = box_corners({h, h, h});
  std::sort(corners.begin(), corners.end(), [](Vec3 a, Vec3 b) {
    return std::array{a.x.raw(), a.y.raw(), a.z.raw()} <
           std::array{b.x.raw(), b.y.raw(), b.z.raw()};
  });
  EXPECT_EQ(hull.vertices, corners);
  ASSERT_EQ(hull.faces.size(), 6U);
  for (const HullFace& face : hull.faces) {
    EXPECT_EQ(face.count, 4);
    EXPECT_EQ(face.offset, h);
    EXPECT_EQ(abs(face.normal.x) + abs(face.normal.y) + abs(face.normal.z), 1_fx);
  }
  EXPECT_EQ(hull.edges.size(), 12U);
  expect_valid_hull(hull, points);
  EXPECT_EQ(hull.solid.volume, 8_fx);  // 8 h^3
  EXPECT_EQ(hull.solid.centroid, Vec3{});
  const double m = 2.0 / 3.0;  // 1/3 (b^2 + c^2)
  expect_tensor(hull.solid.inertia_per_mass, diagonal({m, m, m}), 1e-6, "cube inertia");
  EXPECT_EQ(hull.aabb_min, (Vec3{-h, -h, -h}));
  EXPECT_EQ(hull.aabb_max, (Vec3{h, h, h}));
  EXPECT_NEAR(d(hull.bounding_radius), std::sqrt(3.0), 1e-9);
  EXPECT_NEAR(d(hull.inner_radius), 1.0, 1e-9);

  // Any order of the same points: the same hull, bit for bit.
  for (int trial = 0; trial < 3; ++trial) {
    std::vector<Vec3> permuted = points;
    shuffle(permuted, rng);
    const auto again = build_hull(permuted);
    ASSERT_TRUE(again.ok()) << again.message();
    expect_same_hull(hull, *again);
  }
}

// The most degenerate input there is: a full lattice, every face and edge crowded with coplanar
// and collinear points. Its hull is the box of 8 corners.
TEST(Hull, LatticeOfCoplanarAndCollinearPointsGivesTheBox) {
  std::vector<Vec3> points;
  for (int i = 0; i < 16; ++i) {
    for (int j = 0; j < 16; ++j) {
      for (int k = 0; k < 16; ++k)
        points.push_back(Vec3{Fixed::from_int(i), Fixed::from_int(j), Fixed::from_int(k)} * 0.1_fx);
    }
  }
  ASSERT_EQ(points.size(), sim_detail::max_hull_points);
  const auto built = build_hull(points);
  ASSERT_TRUE(built.ok()) << built.message();
  EXPECT_EQ(built->vertices.size(), 8U);
  EXPECT_EQ(built->faces.size(), 6U);
  EXPECT_EQ(built->edges.size(), 12U);
  expect_valid_hull(*built, points);
  const double side = 1.5;
  const Vec3 h{0.75_fx, 0.75_fx, 0.75_fx};
  expect_close(built->solid.volume, side * side * side, 1e-6, side * side * side, "volume");
  expect_tensor(built->solid.inertia_per_mass, diagonal(box_moments(h)), 1e-6, "lattice box");
}

TEST(Hull, OffCentreBoxHasItsCentroidAtTheOffsetAndTheBoxInertia) {
  const Vec3 h{0.5_fx, 1.25_fx, 2_fx};
  const Vec3 at{3_fx, -7_fx, 11.5_fx};
  const std::vector<Vec3> points = box_corners(h, at);
  const auto built = build_hull(points);
  ASSERT_TRUE(built.ok()) << built.message();
  expect_valid_hull(*built, points);
  EXPECT_EQ(built->faces.size(), 6U);
  const double vol = 8 * d(h.x) * d(h.y) * d(h.z);
  expect_close(built->solid.volume, vol, 1e-6, vol, "volume");
  expect_close(built->solid.centroid.x, 3, 1e-9, 1, "centroid x");
  expect_close(built->solid.centroid.y, -7, 1e-9, 1, "centroid y");
  expect_close(built->solid.centroid.z, 11.5, 1e-9, 1, "centroid z");
  expect_tensor(built->solid.inertia_per_mass, diagonal(box_moments(h)), 1e-6, "box inertia");
}

TEST(Hull, RegularTetrahedronAndOctahedronMatchTheirClosedForms) {
  // Edge a = 2 sqrt(2): volume a^3 / (6 sqrt 2) = 8/3, inertia m a^2 / 20 about every axis.
  const std::vector<Vec3> tetra{
      {1_fx, 1_fx, 1_fx}, {1_fx, -1_fx, -1_fx}, {-1_fx, 1_fx, -1_fx}, {-1_fx, -1_fx, 1_fx}};
  const auto t = build_hull(tetra);
  ASSERT_TRUE(t.ok()) << t.message();
  expect_valid_hull(*t, tetra);
  EXPECT_EQ(t->vertices.size(), 4U);
  EXPECT_EQ(t->faces.size(), 4U);
  EXPECT_EQ(t->edges.size(), 6U);
  expect_close(t->solid.volume, 8.0 / 3.0, 1e-6, 8.0 / 3.0, "tetrahedron volume");
  expect_tensor(t->solid.inertia_per_mass, diagonal({0.4, 0.4, 0.4}), 1e-6, "tetrahedron");
  EXPECT_NEAR(d(t->inner_radius), 1.0 / std::sqrt(3.0), 1e-8);  // the inradius a / sqrt(24)

  // Vertices at r on the axes: volume 4/3 r^3, inertia m r^2 / 5 about every axis.
  const double r = 1.5;
  std::vector<Vec3> octa;
  for (const Fixed s : {-1.5_fx, 1.5_fx}) {
    octa.push_back({s, 0_fx, 0_fx});
    octa.push_back({0_fx, s, 0_fx});
    octa.push_back({0_fx, 0_fx, s});
  }
  const auto o = build_hull(octa);
  ASSERT_TRUE(o.ok()) << o.message();
  expect_valid_hull(*o, octa);
  EXPECT_EQ(o->vertices.size(), 6U);
  EXPECT_EQ(o->faces.size(), 8U);
  EXPECT_EQ(o->edges.size(), 12U);
  expect_close(o->solid.volume, 4.0 / 3.0 * r * r * r, 1e-6, 4.5, "octahedron volume");
  const double m = r * r / 5;
  expect_tensor(o->solid.inertia_per_mass, diagonal({m, m, m}), 1e-6, "octahedron");
}

TEST(Hull, RotatedBoxHasTheBoxPrincipalMomentsAndAxesThatReproduceTheTensor) {
  const Vec3 h{0.5_fx, 1_fx, 1.5_fx};
  Rng rng(5);
  for (int trial = 0; trial < 5; ++trial) {
    // Drawn one statement at a time: the order of a call's arguments is unspecified, and the
    // test must draw the same numbers with every compiler.
    const Vec3 axis = rng.unit_vector();
    const Quat q = from_axis_angle(axis, rng.uniform(0_fx, 3_fx));
    const Vec3 at{rng.uniform(-5_fx, 5_fx), rng.uniform(-5_fx, 5_fx), rng.uniform(-5_fx, 5_fx)};
    std::vector<Vec3> points;
    for (const Vec3 c : box_corners(h))
      points.push_back(at + rotate(q, c));
    const auto built = build_hull(points);
    ASSERT_TRUE(built.ok()) << built.message();
    expect_valid_hull(*built, points);
    EXPECT_EQ(built->vertices.size(), 8U);
    EXPECT_EQ(built->faces.size(), 6U) << "coplanar triangles merge within the tolerance";
    const auto& solid = built->solid;
    // The tensor is R diag(box) R^T for the box's rotation R.
    const std::array<double, 3> box = box_moments(h);
    const Mat3 r = to_mat3(q);
    std::array<std::array<double, 3>, 3> want{};
    for (std::size_t i = 0; i < 3; ++i) {
      for (std::size_t j = 0; j < 3; ++j) {
        for (std::size_t k = 0; k < 3; ++k) {
          const auto at_rc = [&r](std::size_t row, std::size_t col) {
            return d(col == 0 ? r.rows[row].x : (col == 1 ? r.rows[row].y : r.rows[row].z));
          };
          want[i][j] += at_rc(i, k) * box[k] * at_rc(j, k);
        }
      }
    }
    expect_tensor(solid.inertia_per_mass, want, 1e-6, "rotated box tensor");
    // Principal moments: the box's, in some order.
    std::array<double, 3> got{d(solid.principal.x), d(solid.principal.y), d(solid.principal.z)};
    std::array<double, 3> sorted_box = box;
    std::sort(got.begin(), got.end());
    std::sort(sorted_box.begin(), sorted_box.end());
    for (std::size_t i = 0; i < 3; ++i)
      EXPECT_LE(std::abs(got[i] - sorted_box[i]), 1e-6 * sorted_box[2]);
    // principal_axes maps them back: R' diag R'^T is the tensor.
    const Mat3 back = to_mat3(solid.principal_axes);
    const Mat3 rebuilt = back *
                         Mat3::diagonal(solid.principal.x, solid.principal.y, solid.principal.z) *
                         transpose(back);
    expect_tensor(rebuilt, want, 1e-6, "R diag R^T");
  }
}

TEST(Hull, RandomCloudsGiveValidHulls) {
  Rng rng(9);
  int built_count = 0;
  for (int trial = 0; trial < 12; ++trial) {
    const int n = 20 + static_cast<int>(rng.below(400));
    const Fixed size = trial % 3 == 0 ? 0.05_fx : (trial % 3 == 1 ? 2_fx : 300_fx);
    std::vector<Vec3> points;
    for (int i = 0; i < n; ++i) {
      const Vec3 p = trial % 2 == 0 ? Vec3{rng.uniform(-size, size), rng.uniform(-size, size),
                                           rng.uniform(-size, size)}
                                    : rng.unit_vector() * size;
      const Fixed shell = rng.uniform(0.9_fx, 1_fx);  // round clouds: in a shell, not on a sphere
      points.push_back((trial % 2 == 0 ? p : p * shell) + Vec3{7_fx, -3_fx, 1_fx});
    }
    const auto built = build_hull(points);
    if (!built.ok()) {
      // Round clouds may have more corners than a hull keeps: that refusal is the only one.
      EXPECT_NE(built.message().find("corners"), std::string::npos) << built.message();
      continue;
    }
    SCOPED_TRACE("trial " + std::to_string(trial));
    ++built_count;
    expect_valid_hull(*built, points);
    std::vector<Vec3> permuted = points;
    shuffle(permuted, rng);
    expect_same_hull(*built, *build_hull(permuted));
  }
  EXPECT_GE(built_count, 8);
}

TEST(Hull, RefusesWhatCannotBeAHull) {
  const auto refused = [](const std::vector<Vec3>& points, const std::string& words) {
    const auto r = build_hull(points);
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.message().find(words), std::string::npos) << r.message();
  };
  refused({{0_fx, 0_fx, 0_fx}, {1_fx, 0_fx, 0_fx}, {0_fx, 1_fx, 0_fx}},
          "fewer than 4 distinct points (3)");
  Rng rng(3);
  std::vector<Vec3> flat;
  for (int i = 0; i < 1000; ++i) {
    const Fixed x = rng.uniform(-2_fx, 2_fx);
    const Fixed y = rng.uniform(-2_fx, 2_fx);
    flat.push_back({x, y, x * 0.25_fx - y * 0.5_fx + 1_fx});  // the plane z = x/4 - y/2 + 1
  }
  refused(flat, "flat");
  std::vector<Vec3> slab;  // 0.1 mm thin
  for (int i = 0; i < 200; ++i)
    slab.push_back(
        {rng.uniform(-1_fx, 1_fx), rng.uniform(0_fx, 0.0001_fx), rng.uniform(-1_fx, 1_fx)});
  refused(slab, "flat");
  std::vector<Vec3> thick = slab;  // 2 mm is enough
  thick.push_back({0_fx, 0.002_fx, 0_fx});
  EXPECT_TRUE(build_hull(thick).ok());
  std::vector<Vec3> line;
  for (int i = 0; i < 10; ++i)
    line.push_back(Vec3{1_fx, 2_fx, 3_fx} * Fixed::from_int(i));
  refused(line, "line");
  std::vector<Vec3> many(4097, Vec3{});
  refused(many, "too many points: 4097");
  std::vector<Vec3> far = box_corners({1_fx, 1_fx, 1_fx});
  far[5].y = 20000_fx;
  refused(far, "point 5 has y = 20000");
  std::vector<Vec3> sphere;
  for (int i = 0; i < 600; ++i)
    sphere.push_back(rng.unit_vector() * 3_fx);
  refused(sphere, "corners");
  std::vector<Vec3> big_sphere;  // the most points, all corners: refused early, quickly
  for (std::size_t i = 0; i < sim_detail::max_hull_points; ++i)
    big_sphere.push_back(rng.unit_vector() * 100_fx);
  refused(big_sphere, "corners");
  std::vector<Vec3> sphere300(sphere.begin(), sphere.begin() + 300);
  refused(sphere300, "more than 256");
}

TEST(Hull, SupportIsTheFarthestVertexWithTiesToTheLowestIndex) {
  const auto built = build_hull(box_corners({1_fx, 2_fx, 3_fx}));
  ASSERT_TRUE(built.ok());
  const Hull& hull = *built;  // vertices sorted: index bit 2 = x, bit 1 = y, bit 0 = z
  EXPECT_EQ(sim_detail::hull_support(hull, {1_fx, 1_fx, 1_fx}), 7);
  EXPECT_EQ(sim_detail::hull_support(hull, {-1_fx, -1_fx, -1_fx}), 0);
  EXPECT_EQ(sim_detail::hull_support(hull, {1_fx, 0_fx, 0_fx}), 4);   // 4 tied: the lowest
  EXPECT_EQ(sim_detail::hull_support(hull, {0_fx, -1_fx, 0_fx}), 0);  // 4 tied
  EXPECT_EQ(sim_detail::hull_support(hull, {0_fx, 0_fx, 1_fx}), 1);
  // Any length: a huge or a tiny direction picks the same vertex.
  EXPECT_EQ(sim_detail::hull_support(hull, {1000000_fx, -1000000_fx, 1000000_fx}), 5);
  EXPECT_EQ(sim_detail::hull_support(hull, {Fixed::epsilon(), -Fixed::epsilon(), Fixed::epsilon()}),
            5);
}

// The support search prunes with a 64-bit estimate before comparing exactly: it must give the
// exact scan's answer (the lowest index of the exactly farthest vertices) for every direction,
// whatever its length, along face normals (ties) included, on hulls small and large.
TEST(Hull, SupportEqualsTheExactScanForAnyDirection) {
  const auto reference = [](const Hull& h, Vec3 d) {
    std::size_t best = 0;
    for (std::size_t i = 1; i < h.vertices.size(); ++i) {
      detsim::detail::ExactSum<3> s;
      s.add_product(d.x.raw(), h.vertices[i].x.raw() - h.vertices[best].x.raw());
      s.add_product(d.y.raw(), h.vertices[i].y.raw() - h.vertices[best].y.raw());
      s.add_product(d.z.raw(), h.vertices[i].z.raw() - h.vertices[best].z.raw());
      if (!s.negative() && !s.is_zero()) best = i;
    }
    return static_cast<std::uint16_t>(best);
  };
  Rng rng(21);
  int checked = 0;
  for (const int points : {8, 12, 40, 200}) {
    std::vector<Vec3> cloud;
    for (int i = 0; i < points; ++i)
      cloud.push_back(rng.unit_vector() * rng.uniform(0.2_fx, 900_fx));
    if (points == 8) cloud = box_corners({0.5_fx, 5000_fx, 0.05_fx});
    const auto built = build_hull(cloud);
    ASSERT_TRUE(built.ok()) << built.message();
    const Hull& hull = *built;
    std::vector<Vec3> directions;
    for (int i = 0; i < 400; ++i) {
      const Vec3 u = rng.unit_vector();
      directions.push_back(u);
      directions.push_back(u * Fixed::from_raw(rng.uniform(1_fx, 4_fx).raw() << 30));  // huge
      directions.push_back(Vec3{Fixed::from_raw(u.x.raw() >> 28), Fixed::from_raw(u.y.raw() >> 28),
                                Fixed::from_raw(u.z.raw() >> 28)});  // a few raw units
    }
    // Edge directions between vertices, turned a quarter: orthogonal to an edge, ties likely.
    for (std::size_t i = 0; i + 1 < hull.vertices.size() && i < 60; ++i)
      directions.push_back(cross(hull.vertices[i + 1] - hull.vertices[i], Vec3::unit_y()));
    for (const Vec3 d : directions) {
      ASSERT_EQ(sim_detail::hull_support(hull, d), reference(hull, d))
          << points << " points, direction " << to_string(d.x) << " " << to_string(d.y) << " "
          << to_string(d.z);
      ++checked;
    }
  }
  EXPECT_GT(checked, 4000);
}

TEST(Hull, WorstRelativeErrorOfTheClosedFormChecks) {
  std::printf("hull solid properties: worst relative error %.3g\n", worst_relative);
  EXPECT_LT(worst_relative, 1e-6);
}

TEST(Inertia, DiagonalTensorsKeepTheIdentityExactly) {
  const auto frame = sim_detail::principal_frame(Mat3::diagonal(1.5_fx, 0.25_fx, 7_fx));
  EXPECT_EQ(frame.axes, Quat::identity());
  EXPECT_EQ(frame.moments, (Vec3{1.5_fx, 0.25_fx, 7_fx}));
  EXPECT_EQ(sim_detail::quat_from_rotation(Mat3::identity()), Quat::identity());
}

TEST(Inertia, RandomSymmetricTensorsAreReconstructed) {
  Rng rng(21);
  double worst = 0;
  for (int trial = 0; trial < 200; ++trial) {
    // Drawn one statement at a time: the order of a call's arguments is unspecified, and the
    // test must draw the same numbers with every compiler.
    const Vec3 axis = rng.unit_vector();
    const Quat q = from_axis_angle(axis, rng.uniform(0_fx, 3_fx));
    const Fixed scale = trial % 3 == 0 ? 0.001_fx : (trial % 3 == 1 ? 1_fx : 1000_fx);
    const Vec3 m{rng.uniform(0.1_fx, 10_fx) * scale, rng.uniform(0.1_fx, 10_fx) * scale,
                 rng.uniform(0.1_fx, 10_fx) * scale};
    const Mat3 r = to_mat3(q);
    const Mat3 tensor = r * Mat3::diagonal(m.x, m.y, m.z) * transpose(r);
    const auto frame = sim_detail::principal_frame(tensor);
    const Mat3 back = to_mat3(frame.axes);
    const Mat3 rebuilt =
        back * Mat3::diagonal(frame.moments.x, frame.moments.y, frame.moments.z) * transpose(back);
    const double largest = std::max({d(m.x), d(m.y), d(m.z)});
    for (std::size_t i = 0; i < 3; ++i) {
      const Vec3 a = tensor.rows[i];
      const Vec3 b = rebuilt.rows[i];
      for (const double e : {d(a.x - b.x), d(a.y - b.y), d(a.z - b.z)})
        worst = std::max(worst, std::abs(e) / largest);
    }
    EXPECT_NEAR(d(length_squared(Vec3{frame.axes.x, frame.axes.y, frame.axes.z})) +
                    d(frame.axes.w) * d(frame.axes.w),
                1.0, 1e-8);
  }
  EXPECT_LT(worst, 1e-6);
  RecordProperty("worst_relative_error", std::to_string(worst));
  std::printf("principal_frame: worst relative reconstruction error %.3g\n", worst);
}

TEST(Inertia, ShiftInertiaIsTheParallelAxisTheorem) {
  // A unit cube (half extent 1) about a corner: I_c + |d|^2 E - d d^T with d = (1, 1, 1).
  const Fixed c = Fixed::from_int(2) / Fixed::from_int(3);
  const Mat3 shifted = sim_detail::shift_inertia(Mat3::diagonal(c, c, c), {1_fx, 1_fx, 1_fx});
  const double diag = 2.0 / 3.0 + 2;
  expect_tensor(shifted, {{{diag, -1, -1}, {-1, diag, -1}, {-1, -1, diag}}}, 1e-9, "shifted");
}

}  // namespace
}  // namespace detsim
