// The plane: the solid half-space below the body's local y = 0 plane, its outward normal the
// body's local +y axis. No parameters; static bodies only; no extent (no bounding box or radius,
// no volume or mass).
#include <detsim/fixed/math.hpp>

#include "shapes.hpp"

namespace detsim::sim_detail {

// Named, not anonymous: unity builds put the four shape files in one translation unit.
namespace plane_shape {

std::string check(const Shape&) {
  return {};
}

Fixed zero(const Shape&, const Geometry*) noexcept {
  return Fixed::zero();
}

MassProperties mass_properties(const Shape&, const Geometry*, Fixed) noexcept {
  return {};
}

Checked checked_zero(const Shape&, const Geometry*) noexcept {
  return {};
}

std::array<Checked, 3> checked_inertia(const Shape&, const Geometry*, Fixed) noexcept {
  return {};
}

Vec3 aabb_extent(const Shape&, const Geometry*, const Mat3&) noexcept {
  return {};
}

/// The solid half-space y <= 0.
std::optional<LocalHit> ray(const Shape&, const Geometry*, Vec3 p, Vec3 v) noexcept {
  if (v.y >= Fixed::zero()) return std::nullopt;  // parallel or leaving
  const Fixed t = p.y / -v.y;                     // saturates for nearly parallel rays
  Vec3 q = p + v * t;
  q.y = Fixed::zero();
  return LocalHit{t, q, Vec3::unit_y()};
}

bool contains(const Shape&, const Geometry*, Vec3 p) noexcept {
  return p.y <= Fixed::zero();
}

void write(const Shape&, ByteWriter&) {}

Shape read(ByteReader&) {
  return Shape::plane();
}

void outline(const Shape&, const Geometry*, Vec3 position, Quat orientation, ShapeOutline& out) {
  out.half_space = true;
  out.points = {position};
  out.radius = Fixed::zero();
  out.normal = rotate(orientation, Vec3::unit_y());
}

}  // namespace plane_shape

const ShapeKind plane_kind{ShapeType::plane,
                           "plane",
                           true,
                           false,
                           plane_shape::check,
                           plane_shape::zero,
                           plane_shape::mass_properties,
                           plane_shape::checked_zero,
                           plane_shape::checked_inertia,
                           plane_shape::zero,
                           plane_shape::zero,
                           plane_shape::aabb_extent,
                           plane_shape::ray,
                           plane_shape::contains,
                           plane_shape::write,
                           plane_shape::read,
                           plane_shape::outline,
                           std::nullopt};

}  // namespace detsim::sim_detail
