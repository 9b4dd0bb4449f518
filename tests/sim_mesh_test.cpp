// Static triangle meshes and heightfields (sim/src/geometry/mesh.hpp, heightfield.hpp, bvh.hpp,
// triangle.hpp): the builders' refusals and degenerate counts, adjacency, the BVH's determinism,
// raycasts against a brute-force loop over every triangle and against an analytic plane, box
// overlaps against brute force, and the canonical encodings. Every expected value is derived here
// (a loop over all triangles, a plane equation, a hand-worked fold), never read back from a run.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <detsim/core/bytes.hpp>
#include <detsim/core/rng.hpp>
#include <detsim/fixed/math.hpp>

#include "sim/src/geometry/bvh.hpp"
#include "sim/src/geometry/heightfield.hpp"
#include "sim/src/geometry/mesh.hpp"
#include "support/vector_print.hpp"

namespace detsim::sim_detail {
inline void PrintTo(const TriangleHit& h, std::ostream* os) {
  *os << "{t ";
  PrintTo(h.t, os);
  *os << ", triangle " << h.triangle << ", point ";
  PrintTo(h.point, os);
  *os << ", normal ";
  PrintTo(h.normal, os);
  *os << "}";
}
}  // namespace detsim::sim_detail

namespace {

using namespace detsim;
using namespace detsim::literals;
using namespace detsim::sim_detail;

Fixed fx(std::int32_t n) {
  return Fixed::from_int(n);
}

// ---- Test geometry ------------------------------------------------------------------------------

/// A bumpy landscape: a g x g grid of samples 1.5 m apart centred on the origin, each sample moved
/// off the grid by up to 0.25 m in x and z, at height 3 sin(x/7) cos(z/5) + 0.7 sin((x+z)/3);
/// each cell split along a diagonal that alternates with the cell's parity. 2 (g-1)^2 triangles.
struct Landscape {
  std::vector<Vec3> vertices;
  std::vector<std::uint32_t> indices;
};

Landscape landscape(std::uint32_t g) {
  Landscape l;
  const Fixed step = 1.5_fx;
  const Fixed start = -(step * fx(static_cast<std::int32_t>(g - 1))) / fx(2);
  for (std::uint32_t i = 0; i < g; ++i) {
    for (std::uint32_t j = 0; j < g; ++j) {
      const Fixed fi = fx(static_cast<std::int32_t>(i));
      const Fixed fj = fx(static_cast<std::int32_t>(j));
      const Fixed x = start + step * fj + sin(fi * 0.7_fx + fj * 1.3_fx) / fx(4);
      const Fixed z = start + step * fi + cos(fi * 1.1_fx - fj * 0.4_fx) / fx(4);
      const Fixed y = fx(3) * sin(x / fx(7)) * cos(z / fx(5)) + 0.7_fx * sin((x + z) / fx(3));
      l.vertices.push_back({x, y, z});
    }
  }
  for (std::uint32_t i = 0; i + 1 < g; ++i) {
    for (std::uint32_t j = 0; j + 1 < g; ++j) {
      const std::uint32_t a = i * g + j;        // (i, j)
      const std::uint32_t b = (i + 1) * g + j;  // (i + 1, j): +z
      const std::uint32_t c = (i + 1) * g + j + 1;
      const std::uint32_t d = i * g + j + 1;  // (i, j + 1): +x
      // Counter-clockwise seen from +y (x right, z towards the viewer): a, b, c and a, c, d.
      if ((i + j) % 2 == 0) {
        l.indices.insert(l.indices.end(), {a, b, c, a, c, d});
      } else {
        l.indices.insert(l.indices.end(), {a, b, d, b, c, d});
      }
    }
  }
  return l;
}

/// A heightfield of rows x columns samples with the landscape's height formula.
HeightfieldDef bumpy_def(std::uint32_t rows, std::uint32_t columns, Fixed cell) {
  HeightfieldDef def{rows, columns, cell, {}};
  for (std::uint32_t r = 0; r < rows; ++r) {
    for (std::uint32_t c = 0; c < columns; ++c) {
      const Fixed x = fx(static_cast<std::int32_t>(c)) * cell;
      const Fixed z = fx(static_cast<std::int32_t>(r)) * cell;
      def.heights.push_back(fx(3) * sin(x / fx(7)) * cos(z / fx(5)) +
                            0.7_fx * sin((x + z) / fx(3)));
    }
  }
  return def;
}

/// Every triangle with its normal and bounds, the input of the brute-force loops.
struct Soup {
  std::vector<std::array<Vec3, 3>> triangles;
  std::vector<Vec3> normals;
  std::vector<Bounds> bounds;
};

Soup soup_of(const Mesh& m) {
  Soup s;
  for (std::uint32_t t = 0; t < triangle_count(m); ++t) {
    const TriangleData d = triangle(m, t);
    s.triangles.push_back(d.vertices);
    s.normals.push_back(d.normal);
    s.bounds.push_back(triangle_bounds(d.vertices[0], d.vertices[1], d.vertices[2]));
  }
  return s;
}

Soup soup_of(const Heightfield& hf) {
  Soup s;
  for (std::uint32_t t = 0; t < triangle_count(hf); ++t) {
    const auto v = triangle_vertices(hf, t);
    s.triangles.push_back(v);
    s.normals.push_back(triangle_normal(v[0], v[1], v[2]).value());
    s.bounds.push_back(triangle_bounds(v[0], v[1], v[2]));
  }
  return s;
}

/// The reference: every triangle whose bounds meet the segment's box (grown by 2^-10 m, far above
/// any rounding) is tested with the one per-triangle test; the closest hit wins, ties to the lower
/// index.
std::optional<TriangleHit> brute_force(const Soup& s, Vec3 p, Vec3 v, Fixed max_t) {
  const Vec3 q = Vec3Sum{p}.add(max_t, v).result();
  const Fixed grow = Fixed::from_raw(Fixed::one_raw >> 10);
  const Vec3 lo{min(p.x, q.x) - grow, min(p.y, q.y) - grow, min(p.z, q.z) - grow};
  const Vec3 hi{max(p.x, q.x) + grow, max(p.y, q.y) + grow, max(p.z, q.z) + grow};
  std::optional<TriangleHit> best;
  for (std::uint32_t t = 0; t < s.triangles.size(); ++t) {
    if (!overlaps(s.bounds[t], lo, hi)) continue;
    const auto& tri = s.triangles[t];
    const auto hit = ray_triangle(p, v, tri[0], tri[1], tri[2], s.normals[t], t, max_t);
    if (hit && (!best || closer(*hit, *best))) best = hit;
  }
  return best;
}

struct Ray {
  Vec3 p;
  Vec3 v;
  Fixed max_t;
};

/// Rays from a box around the geometry: half of them pointing downwards (ground probes), half in
/// any direction; lengths up to 200 m, one in 16 unbounded.
Ray random_ray(Rng& rng, const Bounds& around) {
  Ray r;
  r.p = {rng.uniform(around.min.x - fx(10), around.max.x + fx(10)),
         rng.uniform(around.min.y - fx(5), around.max.y + fx(10)),
         rng.uniform(around.min.z - fx(10), around.max.z + fx(10))};
  r.v = rng.unit_vector();
  if (rng.below(2) == 0 && r.v.y > Fixed::zero()) r.v.y = -r.v.y;
  r.max_t = rng.below(16) == 0 ? Fixed::max() : rng.uniform(Fixed::zero(), fx(200));
  return r;
}

/// Hits equal (hit or miss, t, point, normal, triangle), except that a different triangle is
/// accepted at the same t (a tie, which the brute force resolves by index among the hits it saw).
::testing::AssertionResult same_hit(const std::optional<TriangleHit>& got,
                                    const std::optional<TriangleHit>& want) {
  if (got.has_value() != want.has_value()) {
    return ::testing::AssertionFailure()
           << (got ? "hit where brute force misses" : "miss where brute force hits");
  }
  if (!got) return ::testing::AssertionSuccess();
  const Fixed tol = want->t / fx(1 << 24) + Fixed::from_raw(1);
  if (abs(got->t - want->t) > tol) {
    return ::testing::AssertionFailure()
           << "t " << to_string(got->t) << " (triangle " << got->triangle << ") vs brute force "
           << to_string(want->t) << " (triangle " << want->triangle << ")";
  }
  if (got->triangle != want->triangle && got->t != want->t) {
    return ::testing::AssertionFailure()
           << "triangle " << got->triangle << " vs " << want->triangle << " at different t";
  }
  return ::testing::AssertionSuccess();
}

// ---- Building a mesh ----------------------------------------------------------------------------

TEST(MeshBuild, RefusesAnIndexCountNotAMultipleOfThree) {
  const std::vector<Vec3> v = {{}, {fx(1), {}, {}}, {{}, {}, fx(1)}};
  const std::vector<std::uint32_t> i = {0, 1, 2, 0};
  const auto m = build_mesh(v, i);
  ASSERT_FALSE(m.ok());
  EXPECT_EQ(m.message(), "mesh: the index count must be a multiple of 3, got 4");
}

TEST(MeshBuild, RefusesAnOutOfRangeIndexNamingTriangleAndIndex) {
  const std::vector<Vec3> v = {{}, {fx(1), {}, {}}, {{}, {}, fx(1)}};
  const std::vector<std::uint32_t> i = {0, 2, 1, 0, 1, 3};
  const auto m = build_mesh(v, i);
  ASSERT_FALSE(m.ok());
  EXPECT_EQ(m.message(), "mesh: triangle 1: index 2 is 3, but there are 3 vertices");
}

TEST(MeshBuild, RefusesOversizeInputBeforeLookingAtIt) {
  const std::vector<Vec3> v = {{}, {fx(1), {}, {}}, {{}, {}, fx(1)}};
  const std::vector<std::uint32_t> many((max_mesh_triangles + 1) * 3, 0);
  const auto m = build_mesh(v, many);
  ASSERT_FALSE(m.ok());
  EXPECT_EQ(m.message(), "mesh: 1048577 triangles, at most 1048576");
  const std::vector<Vec3> lots(max_mesh_vertices + 1);
  const std::vector<std::uint32_t> one = {0, 1, 2};
  const auto n = build_mesh(lots, one);
  ASSERT_FALSE(n.ok());
  EXPECT_EQ(n.message(), "mesh: 1048577 vertices, at most 1048576");
}

TEST(MeshBuild, RefusesCoordinatesOutsideTheRangeIncludingSaturated) {
  const std::vector<std::uint32_t> i = {0, 1, 2};
  for (const Fixed bad : {Fixed::max(), Fixed::min(), 10000.5_fx, -10001_fx}) {
    const std::vector<Vec3> v = {{}, {fx(1), bad, {}}, {{}, {}, fx(1)}};
    const auto m = build_mesh(v, i);
    ASSERT_FALSE(m.ok());
    EXPECT_EQ(m.message().rfind("mesh: vertex 1 y is ", 0), 0U) << m.message();
  }
  // The limit itself is accepted.
  const std::vector<Vec3> edge = {{fx(-10000), {}, {}}, {fx(10000), {}, {}}, {{}, {}, fx(10000)}};
  EXPECT_TRUE(build_mesh(edge, i).ok());
}

// One good triangle and four degenerate ones: repeated indices, collinear points, two vertices at
// one position (different indices), and a right triangle with legs of 2^-13 m (twice its area is
// 2^-26 m^2 < 2^-24). A right triangle with legs of 2^-12 m (2^-24 m^2) is kept.
TEST(MeshBuild, DropsAndCountsDegenerateTriangles) {
  const Fixed tiny = Fixed::from_raw(Fixed::one_raw >> 13);
  const Fixed small = Fixed::from_raw(Fixed::one_raw >> 12);
  const std::vector<Vec3> v = {{},
                               {{}, {}, fx(1)},
                               {fx(1), {}, fx(1)},
                               {fx(2), {}, fx(2)},  // on the line through 0 and 2
                               {fx(1), {}, fx(1)},  // the position of 2
                               {{}, {}, tiny},
                               {tiny, {}, tiny},
                               {{}, {}, small},
                               {small, {}, small}};
  const std::vector<std::uint32_t> i = {0, 1, 2,   // good
                                        0, 1, 1,   // repeated
                                        0, 2, 3,   // collinear
                                        0, 2, 4,   // coincident
                                        0, 5, 6,   // below the threshold
                                        0, 7, 8};  // at the threshold: kept
  const auto m = build_mesh(v, i);
  ASSERT_TRUE(m.ok()) << m.message();
  EXPECT_EQ(m->dropped_triangles, 4U);
  ASSERT_EQ(triangle_count(*m), 2U);
  EXPECT_EQ(m->triangles[0], (std::array<std::uint32_t, 3>{0, 1, 2}));
  EXPECT_EQ(m->triangles[1], (std::array<std::uint32_t, 3>{0, 7, 8}));
  EXPECT_EQ(m->normals[0], Vec3::unit_y());  // exact: an axis-aligned normal normalizes exactly
  EXPECT_EQ(m->normals[1], Vec3::unit_y());
}

TEST(MeshBuild, RefusesAMeshWithNothingLeft) {
  const std::vector<Vec3> v = {{}, {fx(1), {}, {}}, {fx(2), {}, {}}};
  const std::vector<std::uint32_t> i = {0, 1, 2, 0, 0, 1};
  const auto m = build_mesh(v, i);
  ASSERT_FALSE(m.ok());
  EXPECT_EQ(m.message(), "mesh: no triangle left after dropping 2 degenerate ones");
  EXPECT_FALSE(build_mesh(v, std::vector<std::uint32_t>{}).ok());
}

// ---- Adjacency ----------------------------------------------------------------------------------

// The unit square in x-z split along 0-2 into T0 = (0, 3, 2) and T1 = (0, 2, 1), normals +y; the
// shared edge is T0's edge 2 (2 -> 0) and T1's edge 0 (0 -> 2). Vertex 1 at height y bends T1 up
// (y > 0: a valley seen from either side, concave) or down (y < 0: a ridge, convex).
Mesh folded_square(Fixed y, bool duplicate_shared) {
  std::vector<Vec3> v = {{}, {fx(1), y, {}}, {fx(1), {}, fx(1)}, {{}, {}, fx(1)}};
  std::vector<std::uint32_t> i = {0, 3, 2, 0, 2, 1};
  if (duplicate_shared) {  // T1 uses copies of 0 and 2: the edge is matched by position
    v.push_back(v[0]);
    v.push_back(v[2]);
    i = {0, 3, 2, 4, 5, 1};
  }
  return build_mesh(v, i).value();
}

TEST(MeshEdges, SharedEdgeKindFollowsTheFold) {
  for (const bool dup : {false, true}) {
    for (const auto& [y, kind] :
         {std::pair{Fixed::zero(), EdgeKind::flat}, std::pair{0.5_fx, EdgeKind::concave},
          std::pair{-0.5_fx, EdgeKind::convex}}) {
      const Mesh m = folded_square(y, dup);
      EXPECT_EQ(m.edges[0][2], (MeshEdge{1, kind})) << to_string(y);
      EXPECT_EQ(m.edges[1][0], (MeshEdge{0, kind})) << to_string(y);
      for (const auto& [t, k] :
           {std::pair{0U, 0U}, std::pair{0U, 1U}, std::pair{1U, 1U}, std::pair{1U, 2U}}) {
        EXPECT_EQ(m.edges[t][k], MeshEdge{}) << t << " " << k;  // the square's outline
      }
      const TriangleData d = triangle(m, 0);
      EXPECT_EQ(d.edges[2].kind, kind);
      EXPECT_EQ(d.edges[2].neighbour_normal, m.normals[1]);
      EXPECT_EQ(d.edges[2].uses_face_normal(), kind != EdgeKind::convex);
      EXPECT_EQ(d.edges[0].neighbour_normal, Vec3::zero());
    }
  }
}

TEST(MeshEdges, InconsistentWindingOrThreeTrianglesMakeABoundary) {
  const std::vector<Vec3> v = {
      {}, {fx(1), {}, {}}, {fx(1), {}, fx(1)}, {{}, {}, fx(1)}, {fx(1), fx(1), {}}};
  // T1 runs along 0 -> 2 like T0's reversed edge would not: same direction as T0 (2 -> 0 flipped).
  const auto flipped = build_mesh(v, std::vector<std::uint32_t>{0, 3, 2, 2, 0, 1});
  EXPECT_EQ(flipped->edges[0][2], MeshEdge{});
  // Three triangles on the edge 0-2.
  const auto fan = build_mesh(v, std::vector<std::uint32_t>{0, 3, 2, 0, 2, 1, 0, 2, 4});
  EXPECT_EQ(fan->edges[0][2], MeshEdge{});
  EXPECT_EQ(fan->edges[1][0], MeshEdge{});
}

// A heightfield's computed triangles equal those of a mesh built from the same triangles (same
// vertices, same order): vertices, normals and every edge's kind and neighbour normal.
TEST(HeightfieldTriangles, EqualAMeshOfTheSameTriangles) {
  const auto hf = build_heightfield(bumpy_def(9, 7, 0.75_fx));
  ASSERT_TRUE(hf.ok()) << hf.message();
  std::vector<Vec3> v;
  std::vector<std::uint32_t> idx;
  for (std::uint32_t t = 0; t < triangle_count(*hf); ++t) {
    for (const Vec3& p : triangle_vertices(*hf, t)) {
      idx.push_back(static_cast<std::uint32_t>(v.size()));
      v.push_back(p);
    }
  }
  const auto m = build_mesh(v, idx);
  ASSERT_TRUE(m.ok());
  ASSERT_EQ(triangle_count(*m), triangle_count(*hf));
  EXPECT_EQ(triangle_count(*hf), 2U * 8U * 6U);
  int convex = 0;
  int concave = 0;
  for (std::uint32_t t = 0; t < triangle_count(*hf); ++t) {
    const TriangleData a = triangle(*hf, t);
    EXPECT_EQ(a, triangle(*m, t)) << "triangle " << t;
    for (const EdgeInfo& e : a.edges) {
      convex += e.kind == EdgeKind::convex ? 1 : 0;
      concave += e.kind == EdgeKind::concave ? 1 : 0;
    }
  }
  EXPECT_GT(convex, 0);  // the formula has ridges and valleys
  EXPECT_GT(concave, 0);
  // Index layout: triangle 2 (row * (columns - 1) + col) + k.
  const auto tri = triangle_vertices(*hf, 2 * (3 * 6 + 4) + 1);
  EXPECT_EQ(tri[0].x, fx(4) * 0.75_fx);
  EXPECT_EQ(tri[0].z, fx(3) * 0.75_fx);
  EXPECT_EQ(tri[2].x, fx(5) * 0.75_fx);  // k = 1: (r, c), (r + 1, c + 1), (r, c + 1)
  EXPECT_EQ(tri[2].z, fx(3) * 0.75_fx);
  EXPECT_EQ(tri[0].y, hf->def.heights[3 * 7 + 4]);
}

// ---- The BVH ------------------------------------------------------------------------------------

bool holds(const Bounds& outer, const Bounds& inner) {
  return outer.min.x <= inner.min.x && outer.min.y <= inner.min.y && outer.min.z <= inner.min.z &&
         outer.max.x >= inner.max.x && outer.max.y >= inner.max.y && outer.max.z >= inner.max.z;
}

TEST(MeshBvh, IsDeterministicBoundedAndCoversEveryTriangleOnce) {
  const Landscape l = landscape(31);
  const auto a = build_mesh(l.vertices, l.indices);
  const auto b = build_mesh(l.vertices, l.indices);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_TRUE(same_geometry(*a, *b));
  EXPECT_EQ(a->bvh, b->bvh);
  const Bvh& bvh = a->bvh;
  const std::uint32_t n = triangle_count(*a);
  EXPECT_LE(bvh.depth, bvh_max_depth);
  EXPECT_GE(bvh.depth, 9U);  // at least ceil(log2(ceil(n / 4))) levels hold n items by fours
  std::vector<int> seen(n, 0);
  for (std::size_t i = 0; i < bvh.nodes.size(); ++i) {
    const BvhNode& node = bvh.nodes[i];
    if (node.count == 0) {
      for (const std::size_t child : {i + 1, std::size_t{node.first}}) {
        EXPECT_TRUE(holds(node.bounds, bvh.nodes[child].bounds));
      }
      continue;
    }
    EXPECT_LE(node.count, bvh_leaf_size);
    for (std::uint32_t k = node.first; k < node.first + node.count; ++k) {
      const std::uint32_t t = bvh.items[k];
      ++seen[t];
      const auto& tri = a->triangles[t];
      const Bounds tb =
          triangle_bounds(a->vertices[tri[0]], a->vertices[tri[1]], a->vertices[tri[2]]);
      EXPECT_TRUE(holds(node.bounds, tb));
    }
  }
  EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), static_cast<std::ptrdiff_t>(n));
}

// Triangles whose gaps shrink geometrically (x_i = 9000 (1 - 0.995^i)): a skewed input still gives
// a bounded tree, and every ray finds what brute force finds.
TEST(MeshBvh, DepthIsBoundedOnSkewedInput) {
  std::vector<Vec3> v;
  std::vector<std::uint32_t> idx;
  Fixed x = Fixed::zero();
  Fixed gap = fx(45);
  for (std::uint32_t i = 0; i < 3000; ++i) {
    const auto base = static_cast<std::uint32_t>(v.size());
    v.insert(v.end(), {{x, {}, {}}, {x, {}, fx(1)}, {x + 0.01_fx, fx(1), {}}});
    idx.insert(idx.end(), {base, base + 1, base + 2});
    x += gap;
    gap = gap * 0.995_fx;
  }
  const Mesh m = build_mesh(v, idx).value();
  EXPECT_LE(m.bvh.depth, bvh_max_depth);
  const Soup s = soup_of(m);
  Rng rng(1);
  for (int i = 0; i < 2000; ++i) {
    const Ray r = random_ray(rng, m.bounds);
    ASSERT_TRUE(same_hit(raycast(m, r.p, r.v, r.max_t), brute_force(s, r.p, r.v, r.max_t)))
        << "ray " << i;
  }
}

// The median split (what the build uses below bvh_sah_levels, here from the root): a balanced
// tree of depth ceil(log2(ceil(n / 4))) = 9 for 1800 triangles, which finds the same hits.
TEST(MeshBvh, MedianSplitsAreBalancedAndFindTheSameHits) {
  const Landscape l = landscape(31);
  Mesh m = build_mesh(l.vertices, l.indices).value();
  const Soup s = soup_of(m);
  m.bvh = build_bvh(s.bounds, 0);
  EXPECT_EQ(m.bvh.depth, 9U);
  EXPECT_EQ(m.bvh, build_bvh(s.bounds, 0));
  Rng rng(3);
  for (int i = 0; i < 5000; ++i) {
    const Ray r = random_ray(rng, m.bounds);
    ASSERT_TRUE(same_hit(raycast(m, r.p, r.v, r.max_t), brute_force(s, r.p, r.v, r.max_t)))
        << "ray " << i;
  }
}

// A permutation of the triangles (a deterministic shuffle) builds a different tree but finds the
// same hits: the same t and the same triangle through the permutation (or one tied at that t).
TEST(MeshBvh, APermutationOfTheTrianglesGivesTheSameHits) {
  const Landscape l = landscape(31);
  const std::uint32_t n = static_cast<std::uint32_t>(l.indices.size() / 3);
  std::vector<std::uint32_t> perm(n);  // new position k holds old triangle perm[k]
  for (std::uint32_t i = 0; i < n; ++i)
    perm[i] = i;
  Rng shuffle(7);
  for (std::uint32_t i = n - 1; i > 0; --i)
    std::swap(perm[i], perm[static_cast<std::size_t>(shuffle.below(i + 1))]);
  std::vector<std::uint32_t> permuted;
  for (const std::uint32_t old : perm)
    permuted.insert(permuted.end(), l.indices.begin() + 3 * old, l.indices.begin() + 3 * old + 3);
  const Mesh a = build_mesh(l.vertices, l.indices).value();
  const Mesh b = build_mesh(l.vertices, permuted).value();
  Rng rng(11);
  int hits = 0;
  for (int i = 0; i < 20000; ++i) {
    const Ray r = random_ray(rng, a.bounds);
    const auto x = raycast(a, r.p, r.v, r.max_t);
    auto y = raycast(b, r.p, r.v, r.max_t);
    if (y) y->triangle = perm[y->triangle];
    ASSERT_TRUE(same_hit(y, x)) << "ray " << i;
    if (x && y) {
      EXPECT_EQ(x->t, y->t);
    }
    hits += x ? 1 : 0;
  }
  EXPECT_GT(hits, 2000);
}

// ---- Raycasts against brute force ---------------------------------------------------------------

// 10^5 rays against a ~10k-triangle landscape: the BVH's answer equals the loop over every
// triangle (hit or miss, t, triangle unless tied).
TEST(MeshRaycast, EqualsBruteForceOnALandscape) {
  const Landscape l = landscape(71);
  const auto m = build_mesh(l.vertices, l.indices);
  ASSERT_TRUE(m.ok()) << m.message();
  ASSERT_EQ(triangle_count(*m), 9800U);
  const Soup s = soup_of(*m);
  Rng rng(2026);
  int hits = 0;
  int failures = 0;
  for (int i = 0; i < 100000 && failures < 5; ++i) {
    const Ray r = random_ray(rng, m->bounds);
    const auto want = brute_force(s, r.p, r.v, r.max_t);
    const auto got = raycast(*m, r.p, r.v, r.max_t);
    const auto same = same_hit(got, want);
    EXPECT_TRUE(same) << "ray " << i;
    failures += same ? 0 : 1;
    if (got && want && got->triangle == want->triangle) {
      EXPECT_EQ(*got, *want);  // one per-triangle test: the same bits
      const Vec3 n = m->normals[got->triangle];
      EXPECT_EQ(got->normal, dot(r.v, n) < Fixed::zero() ? n : -n);
      EXPECT_LT(dot(got->normal, r.v), Fixed::zero());  // faces the origin
    }
    hits += got ? 1 : 0;
  }
  EXPECT_GT(hits, 30000);  // the test exercises hits, not only misses
}

TEST(HeightfieldRaycast, EqualsBruteForceAndTheSameMesh) {
  const auto hf = build_heightfield(bumpy_def(71, 64, 1.5_fx));
  ASSERT_TRUE(hf.ok()) << hf.message();
  const Soup s = soup_of(*hf);
  // The mesh of the same triangles must find the same hits, bit for bit (the same test).
  std::vector<Vec3> v;
  std::vector<std::uint32_t> idx;
  for (const auto& tri : s.triangles) {
    for (const Vec3& p : tri) {
      idx.push_back(static_cast<std::uint32_t>(v.size()));
      v.push_back(p);
    }
  }
  const Mesh m = build_mesh(v, idx).value();
  Rng rng(99);
  int hits = 0;
  int failures = 0;
  for (int i = 0; i < 100000 && failures < 5; ++i) {
    const Ray r = random_ray(rng, hf->bounds);
    const auto want = brute_force(s, r.p, r.v, r.max_t);
    const auto got = raycast(*hf, r.p, r.v, r.max_t);
    const auto same = same_hit(got, want);
    EXPECT_TRUE(same) << "ray " << i;
    failures += same ? 0 : 1;
    if (i % 8 == 0) {
      const auto by_mesh = raycast(m, r.p, r.v, r.max_t);
      EXPECT_TRUE(same_hit(by_mesh, got)) << "ray " << i;
    }
    hits += got ? 1 : 0;
  }
  EXPECT_GT(hits, 30000);
}

// Watertightness: rays aimed exactly at the grid's shared edges and vertices (every sample, the
// midpoint of every side and of every diagonal), straight down and slanted, all hit: no ray slips
// between two triangles that share an edge. The heightfield's interior covers every target.
TEST(HeightfieldRaycast, NoRayPassesBetweenTriangles) {
  const Heightfield hf = build_heightfield(bumpy_def(17, 19, fx(1))).value();
  const Vec3 slanted = normalize(Vec3{fx(1), fx(-3), fx(2)});
  int rays = 0;
  for (std::uint32_t r = 0; r + 1 < hf.def.rows; ++r) {
    for (std::uint32_t c = 0; c + 1 < hf.def.columns; ++c) {
      const Fixed x = fx(static_cast<std::int32_t>(c));
      const Fixed z = fx(static_cast<std::int32_t>(r));
      const auto h = [&hf](std::uint32_t row, std::uint32_t column) {
        return hf.def.heights[row * hf.def.columns + column];
      };
      // Each target on the surface: a sample, or the midpoint of the edge between two.
      const Fixed h00 = h(r, c);
      for (const Vec3 at : {Vec3{x, h00, z}, Vec3{x + 0.5_fx, (h00 + h(r, c + 1)) / fx(2), z},
                            Vec3{x, (h00 + h(r + 1, c)) / fx(2), z + 0.5_fx},
                            Vec3{x + 0.5_fx, (h00 + h(r + 1, c + 1)) / fx(2), z + 0.5_fx}}) {
        if (at.x == Fixed::zero() || at.z == Fixed::zero()) continue;  // the outline's own edges
        const auto down = raycast(hf, {at.x, fx(50), at.z}, -Vec3::unit_y(), Fixed::max());
        EXPECT_TRUE(down.has_value()) << to_string(at.x) << ", " << to_string(at.z);
        const auto tilted = raycast(hf, at - slanted * fx(20), slanted, Fixed::max());
        EXPECT_TRUE(tilted.has_value()) << to_string(at.x) << ", " << to_string(at.z);
        rays += 2;
      }
    }
  }
  EXPECT_EQ(rays, 2 * (16 * 18 * 4 - 67));  // less 32 targets at x = 0, 36 at z = 0, 1 at both
}

// A tilted flat heightfield y = x/4 - z/8 + 1 (exact at every sample: cell 0.5 m): every hit lies
// on that plane, with t from the plane equation and the plane's normal facing the origin. Rays
// whose plane point is well inside the grid must hit; those well outside must miss.
TEST(HeightfieldRaycast, MatchesAnAnalyticPlane) {
  const Fixed cell = 0.5_fx;
  HeightfieldDef def{33, 41, cell, {}};
  for (std::uint32_t r = 0; r < def.rows; ++r) {
    for (std::uint32_t c = 0; c < def.columns; ++c) {
      const Fixed x = fx(static_cast<std::int32_t>(c)) * cell;
      const Fixed z = fx(static_cast<std::int32_t>(r)) * cell;
      def.heights.push_back(x / fx(4) - z / fx(8) + fx(1));
    }
  }
  const Heightfield hf = build_heightfield(def).value();
  const Vec3 plane_normal = normalize(Vec3{-0.25_fx, fx(1), 0.125_fx});
  const Fixed width = fx(40) * cell;
  const Fixed depth = fx(32) * cell;
  const Fixed margin = 0.001_fx;
  Rng rng(5);
  int hits = 0;
  for (int i = 0; i < 20000; ++i) {
    const Ray r = random_ray(rng, hf.bounds);
    // p.y + v.y t = (p.x + v.x t)/4 - (p.z + v.z t)/8 + 1, solved for t.
    const Fixed denom = r.v.y - r.v.x / fx(4) + r.v.z / fx(8);
    if (abs(denom) < 0.05_fx) continue;  // grazing: t is ill-conditioned for both
    const Fixed t = (r.p.x / fx(4) - r.p.z / fx(8) + fx(1) - r.p.y) / denom;
    const auto got = raycast(hf, r.p, r.v, r.max_t);
    const Vec3 q = r.p + r.v * t;
    const bool inside =
        q.x > margin && q.x < width - margin && q.z > margin && q.z < depth - margin;
    const bool outside =
        q.x < -margin || q.x > width + margin || q.z < -margin || q.z > depth + margin;
    const bool reachable = t >= margin && t <= r.max_t - margin;
    const bool unreachable = t < -margin || t > r.max_t + margin;
    if (inside && reachable) {
      ASSERT_TRUE(got.has_value()) << "ray " << i;
    }
    if (outside || unreachable) {
      ASSERT_FALSE(got.has_value()) << "ray " << i;
    }
    if (!got) continue;
    ++hits;
    EXPECT_LE(abs(got->t - t), t / fx(1 << 24) + Fixed::from_raw(1 << 8)) << "ray " << i;
    const Vec3 facing = denom < Fixed::zero() ? plane_normal : -plane_normal;
    EXPECT_LE(length(got->normal - facing), Fixed::from_raw(1 << 4)) << "ray " << i;
  }
  EXPECT_GT(hits, 1000);
}

// ---- Overlap ------------------------------------------------------------------------------------

template <class Geometry>
void expect_overlap_is_brute_force(const Geometry& g, const Soup& s, std::uint64_t seed) {
  Rng rng(seed);
  std::vector<std::uint32_t> got;
  for (int i = 0; i < 300; ++i) {
    const Bounds& b = g.bounds;
    Vec3 lo{rng.uniform(b.min.x - fx(5), b.max.x + fx(5)), rng.uniform(b.min.y - fx(2), b.max.y),
            rng.uniform(b.min.z - fx(5), b.max.z + fx(5))};
    const Fixed size = rng.below(4) == 0 ? fx(0) : rng.uniform(Fixed::zero(), fx(12));
    if (i % 10 == 0)
      lo = s.triangles[static_cast<std::size_t>(rng.below(s.triangles.size()))]
                      [0];  // touching a vertex
    const Vec3 hi = lo + Vec3{size, rng.uniform(Fixed::zero(), fx(3)), size / fx(2)};
    overlap(g, lo, hi, got);
    std::vector<std::uint32_t> want;
    for (std::uint32_t t = 0; t < s.bounds.size(); ++t) {
      if (overlaps(s.bounds[t], lo, hi)) want.push_back(t);
    }
    ASSERT_EQ(got, want) << "box " << i;
  }
}

TEST(MeshOverlap, ReturnsExactlyTheTrianglesWhoseBoundsMeetTheBoxAscending) {
  const Landscape l = landscape(41);
  const Mesh m = build_mesh(l.vertices, l.indices).value();
  expect_overlap_is_brute_force(m, soup_of(m), 3);
}

TEST(HeightfieldOverlap, ReturnsExactlyTheTrianglesWhoseBoundsMeetTheBoxAscending) {
  const Heightfield hf = build_heightfield(bumpy_def(37, 45, 0.625_fx)).value();
  expect_overlap_is_brute_force(hf, soup_of(hf), 4);
}

// ---- Heightfield refusals -----------------------------------------------------------------------

TEST(HeightfieldBuild, RefusesBadDefinitionsNamingTheField) {
  const auto message = [](HeightfieldDef d) { return build_heightfield(std::move(d)).message(); };
  EXPECT_EQ(message({1, 3, fx(1), std::vector<Fixed>(3)}),
            "heightfield: rows must be in 2..4096, got 1");
  EXPECT_EQ(message({2, 4097, fx(1), {}}), "heightfield: columns must be in 2..4096, got 4097");
  EXPECT_EQ(message({2, 2, fx(1), std::vector<Fixed>(3)}),
            "heightfield: heights must hold rows * columns = 4 values, got 3");
  EXPECT_EQ(message({2, 2, Fixed::zero(), std::vector<Fixed>(4)}),
            "heightfield: cell_size must be >= 2^-10, got 0");
  EXPECT_EQ(message({2, 3, fx(5001), std::vector<Fixed>(6)}),
            "heightfield: (max(rows, columns) - 1) * cell_size must be <= 10000, got cell_size "
            "5001 over 2 cells");
  std::vector<Fixed> h(6);
  h[4] = Fixed::max();
  EXPECT_EQ(message({2, 3, fx(1), h}).rfind("heightfield: height at row 1, column 1 is ", 0), 0U);
  EXPECT_TRUE(build_heightfield({2, 3, fx(5000), std::vector<Fixed>(6)}).ok());
}

// ---- Encoding -----------------------------------------------------------------------------------

TEST(MeshEncoding, RoundTripsAndRefusesTruncatedOrHostileBytes) {
  const Landscape l = landscape(12);
  const Mesh m = build_mesh(l.vertices, l.indices).value();
  ByteWriter w;
  write(m, w);
  {
    ByteReader r(w.bytes());
    const auto back = read_mesh(r);
    ASSERT_TRUE(back.ok()) << back.message();
    EXPECT_TRUE(same_geometry(*back, m));
    EXPECT_TRUE(r.at_end());
  }
  for (std::size_t n = 0; n < w.size(); n += 1 + n / 8) {
    const std::vector<std::uint8_t> cut(w.bytes().begin(),
                                        w.bytes().begin() + static_cast<std::ptrdiff_t>(n));
    ByteReader r(cut);
    const auto back = read_mesh(r);
    EXPECT_FALSE(back.ok()) << n;
    EXPECT_EQ(back.message().rfind("mesh: ", 0), 0U) << back.message();
  }
  const auto read_bytes = [](const ByteWriter& b) {
    ByteReader r(b.bytes());
    return read_mesh(r).message();
  };
  ByteWriter version;
  version.u8(2);
  EXPECT_EQ(read_bytes(version), "mesh: byte 0: mesh version: expected version 1");
  ByteWriter huge;  // a count far beyond the bytes: refused before any allocation
  huge.u8(1);
  huge.var(0xFFFFFFFFU);
  EXPECT_EQ(read_bytes(huge), "mesh: byte 6: mesh vertex count: expected at most 2^20 vertices");
  ByteWriter more;
  more.u8(1);
  more.var(1000);
  more.var(0);
  EXPECT_EQ(read_bytes(more),
            "mesh: byte 3: mesh vertex count: expected a count the data can hold");
  ByteWriter bad_index;  // valid bytes, invalid mesh: build_mesh's message
  bad_index.u8(1);
  bad_index.var(3);
  for (const Vec3 p : {Vec3{}, Vec3{fx(1), {}, {}}, Vec3{{}, {}, fx(1)}})
    bad_index.var_vec3(p);
  bad_index.var(1);
  for (const std::uint32_t i : {0U, 2U, 9U})
    bad_index.var(i);
  EXPECT_EQ(read_bytes(bad_index), "mesh: triangle 0: index 2 is 9, but there are 3 vertices");
  ByteWriter degenerate;  // not canonical: write() never writes a dropped triangle
  degenerate.u8(1);
  degenerate.var(3);
  for (const Vec3 p : {Vec3{}, Vec3{fx(1), {}, {}}, Vec3{{}, {}, fx(1)}})
    degenerate.var_vec3(p);
  degenerate.var(2);
  for (const std::uint32_t i : {0U, 2U, 1U, 0U, 0U, 1U})
    degenerate.var(i);
  EXPECT_EQ(read_bytes(degenerate), "mesh: the encoding holds 1 degenerate triangles");
}

TEST(HeightfieldEncoding, RoundTripsAndRefusesTruncatedOrHostileBytes) {
  const Heightfield hf = build_heightfield(bumpy_def(6, 9, 0.5_fx)).value();
  ByteWriter w;
  write(hf, w);
  {
    ByteReader r(w.bytes());
    const auto back = read_heightfield(r);
    ASSERT_TRUE(back.ok()) << back.message();
    EXPECT_EQ(*back, hf);
    EXPECT_TRUE(r.at_end());
  }
  for (std::size_t n = 0; n < w.size(); ++n) {
    const std::vector<std::uint8_t> cut(w.bytes().begin(),
                                        w.bytes().begin() + static_cast<std::ptrdiff_t>(n));
    ByteReader r(cut);
    const auto back = read_heightfield(r);
    EXPECT_FALSE(back.ok()) << n;
    EXPECT_EQ(back.message().rfind("heightfield: ", 0), 0U) << back.message();
  }
  const auto read_bytes = [](const ByteWriter& b) {
    ByteReader r(b.bytes());
    return read_heightfield(r).message();
  };
  ByteWriter big;
  big.u8(1);
  big.var(4096);
  big.var(4096);
  big.var_fixed(fx(1));
  EXPECT_EQ(read_bytes(big),
            "heightfield: byte 10: heightfield heights: expected a count the data can hold");
  ByteWriter wide;
  wide.u8(1);
  wide.var(5000);
  wide.var(2);
  EXPECT_EQ(read_bytes(wide),
            "heightfield: byte 4: heightfield size: expected 2..4096 rows and columns");
  ByteWriter flat;  // valid bytes, invalid definition: build_heightfield's message
  flat.u8(1);
  flat.var(2);
  flat.var(2);
  flat.var_fixed(Fixed::zero());
  for (int i = 0; i < 4; ++i)
    flat.var_fixed(Fixed::zero());
  EXPECT_EQ(read_bytes(flat), "heightfield: cell_size must be >= 2^-10, got 0");
}

}  // namespace
