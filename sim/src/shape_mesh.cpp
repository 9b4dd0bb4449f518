// The surfaces: a triangle mesh (World::create_mesh) and a heightfield (World::create_heightfield),
// registered with the world and referred to by geometry ID. Their data (triangles, BVH, height
// pyramid) is the Mesh of geometry/mesh.hpp and the Heightfield of geometry/heightfield.hpp; this
// file answers the shape questions from it, for both kinds alike.
//
// A surface is not a solid: it has no inside, no volume and no mass, and only a static body may
// have one (static_only). So `contains` is false everywhere (a ray that starts on the surface hits
// it at t = 0 through `ray`; a point query, a zero-length ray, never hits it), `volume` and the
// mass entries are zero, and `smallest_dimension` is 0 (continuous collision asks it of moving
// bodies only, and a surface never moves).
#include <algorithm>
#include <cstddef>

#include <detsim/fixed/math.hpp>

#include "shapes.hpp"

namespace detsim::sim_detail {

// Named, not anonymous: unity builds put the shape files in one translation unit.
namespace surface_shape {

/// The geometry's data of type Data (Mesh or Heightfield); check_shape has checked the type.
template <class Data>
const Data& data_of(const Geometry* g) noexcept {
  return *std::get_if<Data>(&g->data);
}

// The geometry (its type included) is checked by check_shape; the shape has no fields of its own.
std::string check(const Shape&) {
  return {};
}

Fixed volume(const Shape&, const Geometry*) noexcept {
  return Fixed::zero();
}

MassProperties mass_properties(const Shape&, const Geometry*, Fixed) noexcept {
  return {};
}

Checked checked_volume(const Shape&, const Geometry*) noexcept {
  return Checked(Fixed::zero());
}

std::array<Checked, 3> checked_inertia(const Shape&, const Geometry*, Fixed) noexcept {
  return {Checked(Fixed::zero()), Checked(Fixed::zero()), Checked(Fixed::zero())};
}

/// The eight corners of the local bounds, corner i taking max on axis k when bit k of i is set.
std::array<Vec3, 8> corners(const Bounds& b) noexcept {
  std::array<Vec3, 8> out;
  for (std::size_t i = 0; i < 8; ++i)
    out[i] = {(i & 1U) != 0 ? b.max.x : b.min.x, (i & 2U) != 0 ? b.max.y : b.min.y,
              (i & 4U) != 0 ? b.max.z : b.min.z};
  return out;
}

// The farthest corner of the bounds: every triangle lies in the box, and a point of a box is no
// farther from the origin than its farthest corner. Components are within 10^4 m, so the squares
// stay far inside the Fixed range. The origin is also the "centre of mass" (a surface has none).
template <class Data>
Fixed bounding_radius(const Shape&, const Geometry* g) noexcept {
  Fixed r = Fixed::zero();
  for (const Vec3 c : corners(data_of<Data>(g).bounds))
    r = max(r, length(c));
  return r;
}

Fixed smallest_dimension(const Shape&, const Geometry*) noexcept {
  return Fixed::zero();
}

// The local bounds as a box (centre c, half extents e), turned: |R| e about R c.
template <class Data>
Vec3 aabb_extent(const Shape&, const Geometry* g, const Mat3& r) noexcept {
  const Bounds& b = data_of<Data>(g).bounds;
  const Vec3 c = (b.min + b.max) / Fixed::from_int(2);
  const Vec3 e = (b.max - b.min) / Fixed::from_int(2);
  const Vec3 rc = r * c;
  const auto row = [&e](Vec3 m) { return abs(m.x) * e.x + abs(m.y) * e.y + abs(m.z) * e.z; };
  return {row(r.rows[0]) + abs(rc.x), row(r.rows[1]) + abs(rc.y), row(r.rows[2]) + abs(rc.z)};
}

// The geometry's own raycast: two-sided, the closest hit (ties to the lower triangle), its normal
// the face's turned against the ray. No length limit here: the query compares t with its own.
template <class Data>
std::optional<LocalHit> ray(const Shape&, const Geometry* g, Vec3 p, Vec3 v) noexcept {
  const auto hit = raycast(data_of<Data>(g), p, v, Fixed::max());
  if (!hit) return std::nullopt;
  return LocalHit{hit->t, hit->point, hit->normal};
}

bool contains(const Shape&, const Geometry*, Vec3) noexcept {
  return false;
}

void write(const Shape& s, ByteWriter& w) {
  w.var(s.geometry.value);
}

Shape read_mesh_shape(ByteReader& r) {
  return Shape::mesh(GeometryId{r.var32("triangle mesh geometry ID")});
}

Shape read_heightfield_shape(ByteReader& r) {
  return Shape::heightfield(GeometryId{r.var32("heightfield geometry ID")});
}

/// The triangles (the first max_outline_triangles) and the bounds' corners, placed.
template <class Data>
void outline(const Shape&, const Geometry* g, Vec3 position, Quat orientation, ShapeOutline& out) {
  const Data& data = data_of<Data>(g);
  const auto place = [&](Vec3 v) { return position + rotate(orientation, v); };
  out.points.clear();
  for (const Vec3 c : corners(data.bounds))
    out.points.push_back(place(c));
  out.radius = Fixed::zero();
  out.surface_triangles = triangle_count(data);
  const auto drawn = static_cast<std::uint32_t>(
      std::min<std::size_t>(out.surface_triangles, max_outline_triangles));
  out.triangles.clear();
  out.triangles.reserve(drawn);
  for (std::uint32_t i = 0; i < drawn; ++i) {
    const TriangleData t = triangle(data, i);
    out.triangles.push_back({place(t.vertices[0]), place(t.vertices[1]), place(t.vertices[2])});
  }
}

}  // namespace surface_shape

const ShapeKind mesh_kind{ShapeType::mesh,
                          "triangle mesh",
                          true,
                          true,
                          surface_shape::check,
                          surface_shape::volume,
                          surface_shape::mass_properties,
                          surface_shape::checked_volume,
                          surface_shape::checked_inertia,
                          surface_shape::bounding_radius<Mesh>,
                          surface_shape::smallest_dimension,
                          surface_shape::aabb_extent<Mesh>,
                          surface_shape::ray<Mesh>,
                          surface_shape::contains,
                          surface_shape::write,
                          surface_shape::read_mesh_shape,
                          surface_shape::outline<Mesh>,
                          GeometryType::mesh};

const ShapeKind heightfield_kind{ShapeType::heightfield,
                                 "heightfield",
                                 true,
                                 true,
                                 surface_shape::check,
                                 surface_shape::volume,
                                 surface_shape::mass_properties,
                                 surface_shape::checked_volume,
                                 surface_shape::checked_inertia,
                                 surface_shape::bounding_radius<Heightfield>,
                                 surface_shape::smallest_dimension,
                                 surface_shape::aabb_extent<Heightfield>,
                                 surface_shape::ray<Heightfield>,
                                 surface_shape::contains,
                                 surface_shape::write,
                                 surface_shape::read_heightfield_shape,
                                 surface_shape::outline<Heightfield>,
                                 GeometryType::heightfield};

}  // namespace detsim::sim_detail
