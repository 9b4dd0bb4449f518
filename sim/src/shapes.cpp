// The table of shape kinds (shapes.hpp), and the library's shape functions that go through it:
// the checks, the public mass properties and outlines.
#include <array>

#include <detsim/fixed/decimal.hpp>

#include "shapes.hpp"
#include "world_state.hpp"

namespace detsim {

namespace sim_detail {

namespace {

/// Every kind, ascending by type: a new shape type is a row here.
constexpr std::array<const ShapeKind*, 9> kKinds = {
    &sphere_kind, &box_kind,  &capsule_kind,     &plane_kind,   &cylinder_kind,
    &convex_kind, &mesh_kind, &heightfield_kind, &compound_kind};

}  // namespace

std::span<const ShapeKind* const> shape_kinds() noexcept {
  return kKinds;
}

Fixed cull_radius(const Shape& shape, const Geometry* g) noexcept {
  switch (shape.type) {
    case ShapeType::box:
      return shape.half_extents.x + shape.half_extents.y + shape.half_extents.z;
    case ShapeType::cylinder:
      return shape.radius + shape.half_height;
    default:
      return bounding_radius(shape, g);
  }
}

const ShapeKind* find_shape_kind(ShapeType t) noexcept {
  for (const ShapeKind* kind : kKinds) {
    if (kind->type == t) return kind;
  }
  return nullptr;
}

std::string check_positive_size(const char* what, Fixed x) {
  if (x <= Fixed::zero()) return std::string(what) + " must be > 0, got " + to_string(x);
  if (x > max_shape_size) return std::string(what) + " must be <= 10000, got " + to_string(x);
  return {};
}

std::string check_shape(const GeometryTable& geometries, const Shape& shape, BodyType type) {
  const ShapeKind* kind = find_shape_kind(shape.type);
  if (kind == nullptr)
    return "unknown shape type " + std::to_string(static_cast<unsigned>(shape.type));
  if (kind->static_only && type != BodyType::static_body)
    return std::string("a ") + kind->name + " shape needs a static body";
  if (kind->geometry) {
    const Geometry* g = find_geometry(geometries, shape.geometry);
    if (g == nullptr)
      return std::string("a ") + kind->name + " shape's geometry ID " +
             std::to_string(shape.geometry.value) + " is not registered with this world (" +
             std::to_string(geometries.size()) + " geometries)";
    if (g->type != *kind->geometry)
      return std::string("a ") + kind->name + " shape's geometry ID " +
             std::to_string(shape.geometry.value) + " is a " + geometry_type_name(g->type);
  } else if (!shape.geometry.is_null()) {
    return std::string("a ") + kind->name + " shape has no geometry, got geometry ID " +
           std::to_string(shape.geometry.value);
  }
  return kind->check(shape);
}

}  // namespace sim_detail

Fixed volume(const Shape& shape) noexcept {
  const sim_detail::ShapeKind* kind = sim_detail::find_shape_kind(shape.type);
  return kind != nullptr && !kind->geometry ? kind->volume(shape, nullptr) : Fixed::zero();
}

MassProperties mass_properties(const Shape& shape, Fixed mass) noexcept {
  if (mass <= Fixed::zero()) return {};
  const sim_detail::ShapeKind* kind = sim_detail::find_shape_kind(shape.type);
  return kind != nullptr && !kind->geometry ? kind->mass_properties(shape, nullptr, mass)
                                            : MassProperties{};
}

ShapeOutline shape_outline(const Shape& shape, Vec3 position, Quat orientation) {
  ShapeOutline out;
  const sim_detail::ShapeKind* kind = sim_detail::find_shape_kind(shape.type);
  if (kind != nullptr && !kind->geometry) kind->outline(shape, nullptr, position, orientation, out);
  return out;
}

}  // namespace detsim
