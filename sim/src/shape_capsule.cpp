// The capsule: a core segment along the body's local y axis, from (0, -half_height, 0) to
// (0, +half_height, 0), swept by a ball of `radius` > 0; half_height >= 0 (0 is a sphere).
#include <detsim/fixed/decimal.hpp>
#include <detsim/fixed/math.hpp>

#include "shapes.hpp"

namespace detsim::sim_detail {

// Named, not anonymous: unity builds put the four shape files in one translation unit.
namespace capsule_shape {

using namespace detsim::literals;

std::string check(const Shape& s) {
  if (auto e = check_positive_size("capsule radius", s.radius); !e.empty()) return e;
  if (s.half_height < Fixed::zero())
    return "capsule half height must be >= 0, got " + to_string(s.half_height);
  if (s.half_height > max_shape_size) return "capsule half height must be <= 10000";
  return {};
}

// The formulas once, for Fixed (the simulation) and Checked (the limits): the same bits.
// Integers as from_int, not _fx: clang does not always evaluate a consteval literal operator in a
// function template (an undefined reference at link time).
struct Formulas {
  template <class N>
  static N volume(const Shape& s) noexcept {
    const N r2 = N(s.radius) * s.radius;
    // pi r^2 (2 h) + 4/3 pi r^3 = pi r^2 (2 h + 4/3 r)
    return Fixed::pi() * r2 *
           (Fixed::from_int(2) * N(s.half_height) +
            Fixed::from_int(4) * N(s.radius) / Fixed::from_int(3));
  }

  /// The moments about x, y (the axis) and z.
  template <class N>
  static std::array<N, 3> inertia(const Shape& s, N mass) noexcept {
    // Cylinder of half height h and two hemispheres of radius r. Their volumes are in the ratio
    // 2 h : 4/3 r = 3 h : 2 r, so the cylinder carries 3h / (3h + 2r) of the mass.
    const N r = s.radius;
    const N h = s.half_height;
    const N r2 = r * r;
    const N h2 = h * h;
    const N parts = Fixed::from_int(3) * h + Fixed::from_int(2) * r;
    const N cylinder = mass * (Fixed::from_int(3) * h) / parts;
    const N caps = mass - cylinder;
    // About the axis: cylinder m r^2 / 2, hemispheres 2/5 m r^2.
    const N axial =
        cylinder * r2 / Fixed::from_int(2) + Fixed::from_int(2) * caps * r2 / Fixed::from_int(5);
    // Across the axis: cylinder m (r^2 / 4 + (2h)^2 / 12); the hemisphere pair, whose centres
    // of mass sit 3r/8 beyond the segment ends, m (2/5 r^2 + h^2 + 3/4 h r) (parallel axes).
    const N across = cylinder * (r2 / Fixed::from_int(4) + h2 / Fixed::from_int(3)) +
                     caps * (Fixed::from_int(2) * r2 / Fixed::from_int(5) + h2 +
                             Fixed::from_int(3) * h * r / Fixed::from_int(4));
    return {across, axial, across};
  }
};

Fixed bounding_radius(const Shape& s, const Geometry*) noexcept {
  return s.radius + s.half_height;
}

Fixed smallest_dimension(const Shape& s, const Geometry*) noexcept {
  return s.radius;
}

Vec3 aabb_extent(const Shape& s, const Geometry*, const Mat3& r) noexcept {
  const Vec3 axis = r.column(1);  // the core segment's direction
  const Fixed h = s.half_height;
  return {abs(axis.x) * h + s.radius, abs(axis.y) * h + s.radius, abs(axis.z) * h + s.radius};
}

/// A capsule is the union of its two end balls and the cylinder between them, and the first entry
/// into a union is the earliest entry into any piece. The cylinder's flat ends lie inside the
/// balls, so only its side needs testing: a 2D ball test in the xz plane, valid when the hit is
/// within the core's height. Candidates are taken side, bottom, top, each replacing only an
/// earlier one strictly: ties at the seams go the same way everywhere. half_height == 0 gives two
/// equal balls and a side of zero height: a sphere.
std::optional<LocalHit> ray(const Shape& s, const Geometry*, Vec3 p, Vec3 v) noexcept {
  const Fixed r = s.radius;
  const Fixed half_height = s.half_height;
  std::optional<LocalHit> best;
  const Vec3 p2{p.x, Fixed::zero(), p.z};
  const Vec3 v2{v.x, Fixed::zero(), v.z};
  const Fixed speed2 = length(v2);  // of the ray across the axis, per unit of t
  if (speed2 > Fixed::zero()) {
    // The 2D test runs with a unit direction so that its numbers stay those of the capsule's
    // size; s / speed2 converts its distance back to t (saturating for rays nearly along the
    // axis, whose side hits, if any, are then beyond any height and rejected below).
    if (const auto across = enter_ball(p2, normalize(v2), r)) {
      const Fixed t = *across / speed2;
      const Fixed y = p.y + v.y * t;
      if (y >= -half_height && y <= half_height) {
        const Vec3 q = p + v * t;
        best = LocalHit{t, q, normalize_or(Vec3{q.x, Fixed::zero(), q.z}, -v2)};
      }
    }
  }
  for (const bool top : {false, true}) {
    const Vec3 centre{Fixed::zero(), top ? half_height : -half_height, Fixed::zero()};
    const auto hit = ray_ball(p - centre, v, r);
    if (hit && (!best || hit->t < best->t))
      best = LocalHit{hit->t, hit->point + centre, hit->normal};
  }
  return best;
}

bool contains(const Shape& s, const Geometry*, Vec3 p) noexcept {
  const Fixed y = clamp(p.y, -s.half_height, s.half_height);
  return length(Vec3{p.x, p.y - y, p.z}) <= s.radius;
}

void write(const Shape& s, ByteWriter& w) {
  w.var_fixed(s.radius);
  w.var_fixed(s.half_height);
}

Shape read(ByteReader& r) {
  const Fixed radius = r.var_fixed("capsule radius");
  return Shape::capsule(radius, r.var_fixed("capsule half height"));
}

void outline(const Shape& s, const Geometry*, Vec3 position, Quat orientation, ShapeOutline& out) {
  const Vec3 axis = rotate(orientation, Vec3{Fixed::zero(), s.half_height, Fixed::zero()});
  out.points = {position - axis, position + axis};
  out.radius = s.radius;
}

}  // namespace capsule_shape

const ShapeKind capsule_kind{ShapeType::capsule,
                             "capsule",
                             false,
                             true,
                             capsule_shape::check,
                             MassEntries<capsule_shape::Formulas>::volume,
                             MassEntries<capsule_shape::Formulas>::mass_properties,
                             MassEntries<capsule_shape::Formulas>::checked_volume,
                             MassEntries<capsule_shape::Formulas>::checked_inertia,
                             capsule_shape::bounding_radius,
                             capsule_shape::smallest_dimension,
                             capsule_shape::aabb_extent,
                             capsule_shape::ray,
                             capsule_shape::contains,
                             capsule_shape::write,
                             capsule_shape::read,
                             capsule_shape::outline,
                             std::nullopt};

}  // namespace detsim::sim_detail
