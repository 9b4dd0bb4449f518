// The convex hull: a polyhedron registered with the world (World::create_convex_hull) and
// referred to by its geometry ID. Its data (corners, faces, solid properties) is the Hull of
// geometry/hull.hpp, built once; this file answers the shape questions from it.
#include <detsim/fixed/math.hpp>

#include "shapes.hpp"

namespace detsim::sim_detail {

// Named, not anonymous: unity builds put the shape files in one translation unit.
namespace convex_shape {

const Hull& hull_of(const Geometry* g) noexcept {
  return g->hull();
}

// The geometry (its type included) is checked by check_shape; the shape has no fields of its own.
std::string check(const Shape&) {
  return {};
}

Fixed volume(const Shape&, const Geometry* g) noexcept {
  return hull_of(g).solid.volume;
}

MassProperties mass_properties(const Shape&, const Geometry* g, Fixed mass) noexcept {
  const SolidProperties& solid = hull_of(g).solid;
  return {mass, solid.principal * mass, solid.centroid, solid.principal_axes};
}

Checked checked_volume(const Shape&, const Geometry* g) noexcept {
  return Checked(hull_of(g).solid.volume);
}

std::array<Checked, 3> checked_inertia(const Shape&, const Geometry* g, Fixed mass) noexcept {
  const Vec3 p = hull_of(g).solid.principal;
  return {Checked(p.x) * mass, Checked(p.y) * mass, Checked(p.z) * mass};
}

// The farthest corner from the origin, plus the centre of mass's distance from it: a point's
// distance from the centre is at most the sum (the triangle inequality), so the one radius bounds
// the shape about either point.
Fixed bounding_radius(const Shape&, const Geometry* g) noexcept {
  const Hull& h = hull_of(g);
  return h.bounding_radius + length(h.solid.centroid);
}

Fixed smallest_dimension(const Shape&, const Geometry* g) noexcept {
  return hull_of(g).inner_radius;
}

// The local bounds as a box (centre c, half extents e), turned: |R| e about R c.
Vec3 aabb_extent(const Shape&, const Geometry* g, const Mat3& r) noexcept {
  const Hull& h = hull_of(g);
  const Vec3 c = (h.aabb_min + h.aabb_max) / Fixed::from_int(2);
  const Vec3 e = (h.aabb_max - h.aabb_min) / Fixed::from_int(2);
  const Vec3 rc = r * c;
  const auto row = [&e](Vec3 m) { return abs(m.x) * e.x + abs(m.y) * e.y + abs(m.z) * e.z; };
  return {row(r.rows[0]) + abs(rc.x), row(r.rows[1]) + abs(rc.y), row(r.rows[2]) + abs(rc.z)};
}

/// Cyrus–Beck: the ray is inside the hull for t in [largest entry, smallest exit] over the face
/// planes. Entry face ties go to the lower face index. A ray parallel to a face (dot == 0 exactly)
/// is inside that face's half-space for every t or for none.
std::optional<LocalHit> ray(const Shape&, const Geometry* g, Vec3 p, Vec3 v) noexcept {
  const Hull& h = hull_of(g);
  Fixed enter = Fixed::min();
  Fixed exit = Fixed::max();
  std::size_t entry_face = h.faces.size();
  for (std::size_t f = 0; f < h.faces.size(); ++f) {
    const HullFace& face = h.faces[f];
    const Fixed height = dot(face.normal, p) - face.offset;  // > 0: outside this face
    const Fixed speed = dot(face.normal, v);
    if (speed == Fixed::zero()) {
      if (height > Fixed::zero()) return std::nullopt;
      continue;
    }
    const Fixed t = -height / speed;
    if (speed < Fixed::zero()) {
      if (t > enter) {
        enter = t;
        entry_face = f;
      }
    } else {
      exit = min(exit, t);
    }
  }
  // Behind the ray, beside it, or (rounding) no entering face. As p is outside, the entry is >= 0
  // in exact arithmetic; the clamp only guards against rounding.
  if (entry_face == h.faces.size() || exit < Fixed::zero() || enter > exit) return std::nullopt;
  enter = max(enter, Fixed::zero());
  return LocalHit{enter, p + v * enter, h.faces[entry_face].normal};
}

bool contains(const Shape&, const Geometry* g, Vec3 p) noexcept {
  for (const HullFace& face : hull_of(g).faces) {
    if (dot(face.normal, p) > face.offset) return false;
  }
  return true;
}

void write(const Shape& s, ByteWriter& w) {
  w.var(s.geometry.value);
}

Shape read(ByteReader& r) {
  return Shape::convex(GeometryId{r.var32("convex hull geometry ID")});
}

/// The corners: the hull of the outline's points is the shape.
void outline(const Shape&, const Geometry* g, Vec3 position, Quat orientation, ShapeOutline& out) {
  out.points.clear();
  for (const Vec3 v : hull_of(g).vertices)
    out.points.push_back(position + rotate(orientation, v));
  out.radius = Fixed::zero();
}

}  // namespace convex_shape

const ShapeKind convex_kind{ShapeType::convex,
                            "convex hull",
                            false,
                            true,
                            convex_shape::check,
                            convex_shape::volume,
                            convex_shape::mass_properties,
                            convex_shape::checked_volume,
                            convex_shape::checked_inertia,
                            convex_shape::bounding_radius,
                            convex_shape::smallest_dimension,
                            convex_shape::aabb_extent,
                            convex_shape::ray,
                            convex_shape::contains,
                            convex_shape::write,
                            convex_shape::read,
                            convex_shape::outline,
                            GeometryType::convex_hull};

}  // namespace detsim::sim_detail
