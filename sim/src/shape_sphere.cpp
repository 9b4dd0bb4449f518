// The sphere, centred on the body's origin: `radius` > 0. Also the ball pieces that the capsule's
// ray test shares.
#include <detsim/fixed/decimal.hpp>
#include <detsim/fixed/math.hpp>

#include "shapes.hpp"

namespace detsim::sim_detail {

using namespace detsim::literals;

/// The closest approach is found first and the half chord taken from the perpendicular distance
/// (never from |p|^2 - r^2, which loses everything to cancellation when the ray passes far from
/// the centre).
std::optional<Fixed> enter_ball(Vec3 p, Vec3 v, Fixed r) noexcept {
  if (length(p) <= r) return std::nullopt;  // an origin inside has no entry
  const Fixed along = -dot(p, v);           // t of the closest approach
  // From outside a ball, moving away from its centre never reaches it.
  if (along < Fixed::zero()) return std::nullopt;
  const Fixed r2 = r * r;
  const Fixed d2 = length_squared(p + v * along);
  if (d2 > r2) return std::nullopt;
  // Grazing (d2 == r2) enters at the closest approach. Rounding cannot make an outside origin
  // enter behind itself: the entry is at least 0.
  return max(along - sqrt(r2 - d2), Fixed::zero());
}

std::optional<LocalHit> ray_ball(Vec3 p, Vec3 v, Fixed r) noexcept {
  const auto t = enter_ball(p, v, r);
  if (!t) return std::nullopt;
  const Vec3 q = p + v * *t;
  return LocalHit{*t, q, normalize_or(q, -v)};
}

// Named, not anonymous: unity builds put the four shape files in one translation unit.
namespace sphere_shape {

std::string check(const Shape& s) {
  return check_positive_size("sphere radius", s.radius);
}

// The formulas once, for Fixed (the simulation) and Checked (the limits): the same bits.
// Integers as from_int, not _fx: clang does not always evaluate a consteval literal operator in a
// function template (an undefined reference at link time).
struct Formulas {
  template <class N>
  static N volume(const Shape& s) noexcept {
    // 4/3 pi r^3
    return (Fixed::from_int(4) * Fixed::pi() / Fixed::from_int(3)) *
           (N(s.radius * s.radius) * s.radius);
  }

  template <class N>
  static std::array<N, 3> inertia(const Shape& s, N mass) noexcept {
    const N i =
        Fixed::from_int(2) * mass * (s.radius * s.radius) / Fixed::from_int(5);  // 2/5 m r^2
    return {i, i, i};
  }
};

Fixed radius(const Shape& s, const Geometry*) noexcept {
  return s.radius;
}

Vec3 aabb_extent(const Shape& s, const Geometry*, const Mat3&) noexcept {
  return {s.radius, s.radius, s.radius};
}

std::optional<LocalHit> ray(const Shape& s, const Geometry*, Vec3 p, Vec3 v) noexcept {
  return ray_ball(p, v, s.radius);
}

bool contains(const Shape& s, const Geometry*, Vec3 p) noexcept {
  return length(p) <= s.radius;
}

void write(const Shape& s, ByteWriter& w) {
  w.var_fixed(s.radius);
}

Shape read(ByteReader& r) {
  return Shape::sphere(r.var_fixed("sphere radius"));
}

void outline(const Shape& s, const Geometry*, Vec3 position, Quat, ShapeOutline& out) {
  out.points = {position};
  out.radius = s.radius;
}

}  // namespace sphere_shape

const ShapeKind sphere_kind{ShapeType::sphere,
                            "sphere",
                            false,
                            true,
                            sphere_shape::check,
                            MassEntries<sphere_shape::Formulas>::volume,
                            MassEntries<sphere_shape::Formulas>::mass_properties,
                            MassEntries<sphere_shape::Formulas>::checked_volume,
                            MassEntries<sphere_shape::Formulas>::checked_inertia,
                            sphere_shape::radius,
                            sphere_shape::radius,
                            sphere_shape::aabb_extent,
                            sphere_shape::ray,
                            sphere_shape::contains,
                            sphere_shape::write,
                            sphere_shape::read,
                            sphere_shape::outline,
                            std::nullopt};

}  // namespace detsim::sim_detail
