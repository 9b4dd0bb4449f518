// The cylinder: its axis along the body's local y, from (0, -half_height, 0) to
// (0, +half_height, 0), of `radius` > 0 and half_height > 0, with flat ends.
//
// Collisions: no pair function is registered for a cylinder (collide.cpp's kPairs has no rows
// for it), so collide() returns no contact for any pair with one for now; the generic convex
// narrowphase will collide cylinders through their support function.
#include <detsim/fixed/decimal.hpp>
#include <detsim/fixed/math.hpp>

#include "shapes.hpp"

namespace detsim::sim_detail {

// Named, not anonymous: unity builds put the shape files in one translation unit.
namespace cylinder_shape {

using namespace detsim::literals;

std::string check(const Shape& s) {
  if (auto e = check_positive_size("cylinder radius", s.radius); !e.empty()) return e;
  return check_positive_size("cylinder half height", s.half_height);
}

// The formulas once, for Fixed (the simulation) and Checked (the limits): the same bits.
// Integers as from_int, not _fx: clang does not always evaluate a consteval literal operator in a
// function template (an undefined reference at link time).
struct Formulas {
  template <class N>
  static N volume(const Shape& s) noexcept {
    // pi r^2 (2 h)
    return Fixed::pi() * (N(s.radius) * s.radius) * (Fixed::from_int(2) * N(s.half_height));
  }

  /// The moments about x, y (the axis) and z.
  template <class N>
  static std::array<N, 3> inertia(const Shape& s, N mass) noexcept {
    // About the axis m r^2 / 2; across it m (3 r^2 + H^2) / 12 with the full height H = 2 h,
    // that is m (r^2 / 4 + h^2 / 3).
    const N r2 = N(s.radius) * s.radius;
    const N h2 = N(s.half_height) * s.half_height;
    const N axial = mass * r2 / Fixed::from_int(2);
    const N across = mass * (r2 / Fixed::from_int(4) + h2 / Fixed::from_int(3));
    return {across, axial, across};
  }
};

Fixed bounding_radius(const Shape& s, const Geometry*) noexcept {
  return hypot(s.radius, s.half_height);  // to a rim point; correctly rounded
}

Fixed smallest_dimension(const Shape& s, const Geometry*) noexcept {
  return min(s.radius, s.half_height);
}

/// Exact for a cylinder: along world axis i, the axis segment reaches h |R_iy| and an end circle
/// r sqrt(1 - R_iy^2) = r sqrt(R_ix^2 + R_iz^2) (a row of a rotation is a unit vector). The
/// second form, a correctly rounded hypot, avoids the cancellation of 1 - R_iy^2 near 1.
Vec3 aabb_extent(const Shape& s, const Geometry*, const Mat3& r) noexcept {
  const auto row = [&s](Vec3 m) { return abs(m.y) * s.half_height + s.radius * hypot(m.x, m.z); };
  return {row(r.rows[0]), row(r.rows[1]), row(r.rows[2])};
}

/// The first entry into the intersection of the infinite cylinder x^2 + z^2 <= r^2 and the slab
/// |y| <= h: through the side (a 2D ball test in the xz plane, valid when the hit is within the
/// slab) or through an end (a plane test, valid when the hit is within the circle). Candidates
/// are taken side, bottom, top, each replacing only an earlier one strictly.
std::optional<LocalHit> ray(const Shape& s, const Geometry*, Vec3 p, Vec3 v) noexcept {
  const Fixed r = s.radius;
  const Fixed h = s.half_height;
  std::optional<LocalHit> best;
  const Vec3 p2{p.x, Fixed::zero(), p.z};
  const Vec3 v2{v.x, Fixed::zero(), v.z};
  const Fixed speed2 = length(v2);  // of the ray across the axis, per unit of t
  if (speed2 > Fixed::zero()) {
    // As for the capsule: a unit direction in the plane keeps the numbers those of the size, and
    // s / speed2 converts the distance back to t.
    if (const auto across = enter_ball(p2, normalize(v2), r)) {
      const Fixed t = *across / speed2;
      const Fixed y = p.y + v.y * t;
      if (y >= -h && y <= h) {
        const Vec3 q = p + v * t;
        best = LocalHit{t, q, normalize_or(Vec3{q.x, Fixed::zero(), q.z}, -v2)};
      }
    }
  }
  for (const bool top : {false, true}) {
    const Fixed plane = top ? h : -h;
    // Only an end the ray is outside of and moving toward.
    if (top ? !(p.y > h && v.y < Fixed::zero()) : !(p.y < -h && v.y > Fixed::zero())) continue;
    const Fixed t = (plane - p.y) / v.y;
    Vec3 q = p + v * t;
    q.y = plane;  // exactly on the end
    if (hypot(q.x, q.z) > r) continue;
    if (!best || t < best->t)
      best = LocalHit{t, q, Vec3{Fixed::zero(), top ? Fixed::one() : -Fixed::one(), Fixed::zero()}};
  }
  return best;
}

bool contains(const Shape& s, const Geometry*, Vec3 p) noexcept {
  return abs(p.y) <= s.half_height && hypot(p.x, p.z) <= s.radius;
}

void write(const Shape& s, ByteWriter& w) {
  w.var_fixed(s.radius);
  w.var_fixed(s.half_height);
}

Shape read(ByteReader& r) {
  const Fixed radius = r.var_fixed("cylinder radius");
  return Shape::cylinder(radius, r.var_fixed("cylinder half height"));
}

/// The two end circles, 16 points each (every 22.5 degrees), radius 0: a viewer draws their hull
/// (the circles and the lines between them). For display only.
void outline(const Shape& s, const Geometry*, Vec3 position, Quat orientation, ShapeOutline& out) {
  out.points.clear();
  for (const Fixed y : {-s.half_height, s.half_height}) {
    for (int k = 0; k < 16; ++k) {
      const SinCos sc = sincos(Fixed::pi() * Fixed::from_int(k) / Fixed::from_int(8));
      const Vec3 local{s.radius * sc.cos, y, s.radius * sc.sin};
      out.points.push_back(position + rotate(orientation, local));
    }
  }
  out.radius = Fixed::zero();
}

}  // namespace cylinder_shape

const ShapeKind cylinder_kind{ShapeType::cylinder,
                              "cylinder",
                              false,
                              true,
                              cylinder_shape::check,
                              MassEntries<cylinder_shape::Formulas>::volume,
                              MassEntries<cylinder_shape::Formulas>::mass_properties,
                              MassEntries<cylinder_shape::Formulas>::checked_volume,
                              MassEntries<cylinder_shape::Formulas>::checked_inertia,
                              cylinder_shape::bounding_radius,
                              cylinder_shape::smallest_dimension,
                              cylinder_shape::aabb_extent,
                              cylinder_shape::ray,
                              cylinder_shape::contains,
                              cylinder_shape::write,
                              cylinder_shape::read,
                              cylinder_shape::outline,
                              std::nullopt};

}  // namespace detsim::sim_detail
