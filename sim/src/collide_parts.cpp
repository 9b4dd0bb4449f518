// The narrowphase of shapes with sub-shapes (collide.hpp, collide_all): a compound's parts and a
// surface's triangles each make their own manifold, so that a body pair can touch with several
// normals at once (a box on a stair's tread and riser, a chair's four legs on uneven ground).
//
// - Two shapes without sub-shapes: collide()'s one manifold, as sub-shapes (0, 0).
// - Compounds: every pair of parts (a whole shape is its own single part) whose bounding balls
//   come within the margin, through collide(), ascending by (part of a, part of b).
// - A surface (mesh, heightfield; static, so never both sides): each part of the other shape
//   against the triangles under its bounding box (the surface's overlap query, ascending), through
//   collide_triangle, which is one-sided and gives internal edges the face normal.
// Everything is in ascending index order, so the list depends only on the shapes and their poses.
#include <algorithm>
#include <span>

#include <detsim/fixed/math.hpp>

#include "collide.hpp"
#include "collide_util.hpp"
#include "geometry/convex.hpp"
#include "geometry/convex_internal.hpp"
#include "geometry/geometry.hpp"
#include "shapes.hpp"

namespace detsim::sim_detail {

namespace {

bool is_surface(const Geometry* g) noexcept {
  return g != nullptr && (g->type == GeometryType::mesh || g->type == GeometryType::heightfield);
}

bool is_compound(const Geometry* g) noexcept {
  return g != nullptr && g->type == GeometryType::compound;
}

// One part placed in the world: a whole shape is its own part 0.
struct PlacedPart {
  const Shape* shape;
  const Geometry* geometry;
  Pose pose;
  std::uint32_t index;
};

// The parts of a shape that is not a surface, placed by its pose.
void parts_of(const PosedShape& s, std::vector<PlacedPart>& out) {
  out.clear();
  if (!is_compound(s.geometry)) {
    out.push_back({&s.shape, s.geometry, s.pose, 0});
    return;
  }
  const Compound& c = s.geometry->compound();
  for (std::size_t i = 0; i < c.parts.size(); ++i) {
    const CompoundPart& part = c.parts[i];
    out.push_back({&part.child.shape, part.geometry.get(),
                   Pose{s.pose.position + s.pose.rotation * part.child.position,
                        s.pose.rotation * part.rotation},
                   static_cast<std::uint32_t>(i)});
  }
}

// The working lists of collide_all, reused from call to call (a pair of a compound and a surface
// would otherwise allocate several lists per step): one set per thread, as worlds may step on
// different threads. They hold nothing between calls; the results depend only on the inputs.
struct PartsScratch {
  std::vector<PlacedPart> parts_a;
  std::vector<PlacedPart> parts_b;
  std::vector<std::uint32_t> triangles;
  std::vector<SubManifold> per_triangle;
  std::vector<convex::Candidate> candidates;
  std::vector<convex::Candidate> unique;
  std::vector<bool> taken;
};

PartsScratch& parts_scratch() {
  thread_local PartsScratch scratch;
  return scratch;
}

Fixed part_radius(const PlacedPart& p) noexcept {
  return shape_kind(p.shape->type).bounding_radius(*p.shape, p.geometry);
}

ConvexView view_of_part(const PlacedPart& p) noexcept {
  return p.geometry != nullptr ? ConvexView::of_hull(p.geometry->hull()) : ConvexView::of(*p.shape);
}

void mirror(Manifold& m) noexcept {
  m.normal = -m.normal;
  for (std::uint8_t i = 0; i < m.count; ++i)
    m.points[i].feature = narrow::mirror_feature(m.points[i].feature);
}

// The triangle half of a merged point's feature: the patch's face, whatever triangle holds it.
constexpr std::uint16_t kPatchFace = narrow::feature(narrow::Kind::face, 0);

// Merges the (part, triangle) manifolds `tri` of one part, ascending by triangle, into `out`: the
// manifolds whose normals agree with the first of a patch (the lowest triangle) become one
// manifold of that normal, keyed by that triangle, of at most four of their points (reduce_into:
// the deepest, the farthest, the most area), each named by the part's feature alone. So a box on
// a floor of many triangles has the four points it has on a plane, and they keep their impulses
// as it slides from triangle to triangle (collide_group matches a patch by its normal); the
// snapshot does not grow with the number of triangles under a body.
void merge_patches(std::span<const SubManifold> tri, Vec3 origin, std::vector<SubManifold>& out) {
  PartsScratch& scratch = parts_scratch();
  std::vector<bool>& taken = scratch.taken;
  taken.assign(tri.size(), false);
  std::vector<convex::Candidate>& candidates = scratch.candidates;
  for (std::size_t i = 0; i < tri.size(); ++i) {
    if (taken[i]) continue;
    const Vec3 n = tri[i].manifold.normal;
    std::size_t members = 0;
    candidates.clear();
    for (std::size_t j = i; j < tri.size(); ++j) {
      if (taken[j] || dot(tri[j].manifold.normal, n) < surface_patch_cos) continue;
      taken[j] = true;
      ++members;
      const Manifold& m = tri[j].manifold;
      for (std::uint8_t k = 0; k < m.count; ++k) {
        const ContactPoint& p = m.points[k];
        candidates.push_back(
            {p.point - origin, p.separation,
             narrow::pair_feature(static_cast<std::uint16_t>(p.feature & 0xFFFFU), kPatchFace)});
      }
    }
    if (members == 1) {
      out.push_back(tri[i]);
      continue;
    }
    // Points of two triangles on their shared edge or vertex are one point: keep the first.
    std::vector<convex::Candidate>& unique = scratch.unique;
    unique.clear();
    for (const convex::Candidate& c : candidates) {
      const bool seen = std::any_of(unique.begin(), unique.end(), [&c](const convex::Candidate& u) {
        return u.point == c.point;
      });
      if (!seen) unique.push_back(c);
    }
    SubManifold merged{tri[i].sub_a, tri[i].sub_b, Manifold{}};
    merged.manifold.normal = n;
    convex::reduce_into(unique, n, origin, merged.manifold);
    out.push_back(merged);
  }
}

// Every part of `x` against the triangles of `surface` near it: (part, triangle) manifolds, each
// part's merged into patches of one normal (merge_patches).
void against_surface(const PosedShape& x, const PosedShape& surface, Fixed margin,
                     std::vector<SubManifold>& out) {
  PartsScratch& scratch = parts_scratch();
  std::vector<PlacedPart>& parts = scratch.parts_a;
  parts_of(x, parts);
  const Mat3 to_surface = transpose(surface.pose.rotation);
  const Geometry& g = *surface.geometry;
  const bool mesh = g.type == GeometryType::mesh;
  std::vector<std::uint32_t>& triangles = scratch.triangles;
  std::vector<SubManifold>& per_triangle = scratch.per_triangle;
  for (const PlacedPart& part : parts) {
    // The part's world box, in the surface's frame: its centre moved in, its extent turned.
    const ShapeKind& kind = shape_kind(part.shape->type);
    const Vec3 e = kind.aabb_extent(*part.shape, part.geometry, part.pose.rotation) +
                   Vec3{margin, margin, margin};
    const Vec3 c = to_surface * (part.pose.position - surface.pose.position);
    const auto row = [&e](Vec3 m) { return abs(m.x) * e.x + abs(m.y) * e.y + abs(m.z) * e.z; };
    const Vec3 extent{row(to_surface.rows[0]), row(to_surface.rows[1]), row(to_surface.rows[2])};
    triangles.clear();
    if (mesh) {
      overlap(g.mesh(), c - extent, c + extent, triangles);
    } else {
      overlap(g.heightfield(), c - extent, c + extent, triangles);
    }
    const ConvexView view = view_of_part(part);
    per_triangle.clear();
    for (const std::uint32_t t : triangles) {
      const TriangleData tri = mesh ? triangle(g.mesh(), t) : triangle(g.heightfield(), t);
      const Manifold m = collide_triangle(view, part.pose, tri, surface.pose, margin);
      if (m.count > 0) per_triangle.push_back({part.index, t, m});
    }
    merge_patches(per_triangle, part.pose.position, out);
  }
}

}  // namespace

std::uint32_t sub_shape_count(const Shape&, const Geometry* g) noexcept {
  if (g == nullptr) return 1;
  switch (g->type) {
    case GeometryType::convex_hull:
      return 1;
    case GeometryType::mesh:
      return triangle_count(g->mesh());
    case GeometryType::heightfield:
      return triangle_count(g->heightfield());
    case GeometryType::compound:
      return static_cast<std::uint32_t>(g->compound().parts.size());
  }
  return 1;
}

bool has_triangles(const PosedShape& s) noexcept {
  return is_surface(s.geometry);
}

bool has_sub_shapes(const PosedShape& s) noexcept {
  return is_surface(s.geometry) || is_compound(s.geometry);
}

void collide_all(const PosedShape& a, const PosedShape& b, Fixed margin,
                 std::vector<SubManifold>& out) {
  out.clear();
  if (!has_sub_shapes(a) && !has_sub_shapes(b)) {
    const Manifold m = collide(a, b, margin);
    if (m.count > 0) out.push_back({0, 0, m});
    return;
  }
  if (is_surface(b.geometry)) {
    if (is_surface(a.geometry)) return;  // two static surfaces never touch
    against_surface(a, b, margin, out);
    return;
  }
  if (is_surface(a.geometry)) {
    against_surface(b, a, margin, out);
    for (SubManifold& m : out) {
      std::swap(m.sub_a, m.sub_b);
      mirror(m.manifold);
    }
    std::sort(out.begin(), out.end(), [](const SubManifold& x, const SubManifold& y) {
      return x.sub_a != y.sub_a ? x.sub_a < y.sub_a : x.sub_b < y.sub_b;
    });
    return;
  }
  // Compounds: part against part, culled by bounding balls (an unbounded shape, a plane, has
  // radius 0 and is never culled).
  PartsScratch& scratch = parts_scratch();
  std::vector<PlacedPart>& parts_a = scratch.parts_a;
  std::vector<PlacedPart>& parts_b = scratch.parts_b;
  parts_of(a, parts_a);
  parts_of(b, parts_b);
  for (const PlacedPart& pa : parts_a) {
    const Fixed ra = part_radius(pa);
    for (const PlacedPart& pb : parts_b) {
      const Fixed rb = part_radius(pb);
      const bool bounded = ra > Fixed::zero() && rb > Fixed::zero();
      if (bounded && distance(pa.pose.position, pb.pose.position) > ra + rb + margin) continue;
      const Manifold m =
          collide({*pa.shape, pa.geometry, pa.pose}, {*pb.shape, pb.geometry, pb.pose}, margin);
      if (m.count > 0) out.push_back({pa.index, pb.index, m});
    }
  }
}

}  // namespace detsim::sim_detail
