// The compound: parts (primitives and convex hulls) placed in the body's frame, registered with
// the world (World::create_compound) and referred to by its geometry ID. Its data (the parts and
// the solid they make) is the Compound of geometry/compound.hpp, built once; this file answers the
// shape questions by asking each part's kind in the part's own frame. No collision pairs yet (the
// narrowphase that collides each part comes next).
#include <detsim/fixed/math.hpp>

#include "shapes.hpp"

namespace detsim::sim_detail {

// Named, not anonymous: unity builds put the shape files in one translation unit.
namespace compound_shape {

const Compound& compound_of(const Geometry* g) noexcept {
  return g->compound();
}

const ShapeKind& kind_of(const CompoundPart& part) noexcept {
  return shape_kind(part.child.shape.type);
}

/// A point of the compound's frame in the part's frame: R^T (p - position).
Vec3 to_part(const CompoundPart& part, Vec3 p) noexcept {
  return transpose(part.rotation) * (p - part.child.position);
}

// The geometry (its type included) is checked by check_shape, the parts when the compound was
// built; the shape has no fields of its own.
std::string check(const Shape&) {
  return {};
}

// The sum of the parts' volumes: the parts are assumed not to overlap (World::create_compound).
Fixed volume(const Shape&, const Geometry* g) noexcept {
  return compound_of(g).solid.volume;
}

MassProperties mass_properties(const Shape&, const Geometry* g, Fixed mass) noexcept {
  const SolidProperties& solid = compound_of(g).solid;
  return {mass, solid.principal * mass, solid.centroid, solid.principal_axes};
}

Checked checked_volume(const Shape&, const Geometry* g) noexcept {
  return Checked(compound_of(g).solid.volume);
}

std::array<Checked, 3> checked_inertia(const Shape&, const Geometry* g, Fixed mass) noexcept {
  const Vec3 p = compound_of(g).solid.principal;
  return {Checked(p.x) * mass, Checked(p.y) * mass, Checked(p.z) * mass};
}

// Max over the parts of |position| + the part's radius, plus |centroid| (compound.cpp).
Fixed bounding_radius(const Shape&, const Geometry* g) noexcept {
  return compound_of(g).bounding_radius;
}

// The largest part's: a body moving less than it per step cannot pass through that part.
Fixed smallest_dimension(const Shape&, const Geometry* g) noexcept {
  return compound_of(g).inner_radius;
}

// The union of the parts' boxes, each about R * position with its kind's half extents under the
// part's rotation turned by R, made symmetric about the origin: |R p| + e per axis.
Vec3 aabb_extent(const Shape&, const Geometry* g, const Mat3& r) noexcept {
  Vec3 out{};
  for (const CompoundPart& part : compound_of(g).parts) {
    const Vec3 c = r * part.child.position;
    const Vec3 e =
        kind_of(part).aabb_extent(part.child.shape, part_geometry(part), r * part.rotation);
    out = {max(out.x, abs(c.x) + e.x), max(out.y, abs(c.y) + e.y), max(out.z, abs(c.z) + e.z)};
  }
  return out;
}

/// The closest hit over the parts, each asked in its own frame (the ray starts outside the
/// compound, so outside every part); ties go to the lower part index. A rotation keeps lengths,
/// so a part's t is the compound's.
std::optional<LocalHit> ray(const Shape&, const Geometry* g, Vec3 p, Vec3 v) noexcept {
  std::optional<LocalHit> best;
  for (const CompoundPart& part : compound_of(g).parts) {
    const Mat3 back = transpose(part.rotation);
    const auto hit =
        kind_of(part).ray(part.child.shape, part_geometry(part), to_part(part, p), back * v);
    if (!hit || (best && hit->t >= best->t)) continue;
    best = LocalHit{hit->t, part.child.position + part.rotation * hit->point,
                    part.rotation * hit->normal};
  }
  return best;
}

bool contains(const Shape&, const Geometry* g, Vec3 p) noexcept {
  for (const CompoundPart& part : compound_of(g).parts) {
    if (kind_of(part).contains(part.child.shape, part_geometry(part), to_part(part, p)))
      return true;
  }
  return false;
}

void write(const Shape& s, ByteWriter& w) {
  w.var(s.geometry.value);
}

Shape read(ByteReader& r) {
  return Shape::compound(GeometryId{r.var32("compound geometry ID")});
}

/// One outline per part, each the part's own at the part's pose.
void outline(const Shape&, const Geometry* g, Vec3 position, Quat orientation, ShapeOutline& out) {
  out.points.clear();
  out.radius = Fixed::zero();
  out.parts.clear();
  for (const CompoundPart& part : compound_of(g).parts) {
    ShapeOutline o;
    kind_of(part).outline(part.child.shape, part_geometry(part),
                          position + rotate(orientation, part.child.position),
                          orientation * part.orientation, o);
    out.parts.push_back(std::move(o));
  }
}

}  // namespace compound_shape

const ShapeKind compound_kind{ShapeType::compound,
                              "compound",
                              false,
                              true,
                              compound_shape::check,
                              compound_shape::volume,
                              compound_shape::mass_properties,
                              compound_shape::checked_volume,
                              compound_shape::checked_inertia,
                              compound_shape::bounding_radius,
                              compound_shape::smallest_dimension,
                              compound_shape::aabb_extent,
                              compound_shape::ray,
                              compound_shape::contains,
                              compound_shape::write,
                              compound_shape::read,
                              compound_shape::outline,
                              GeometryType::compound};

}  // namespace detsim::sim_detail
