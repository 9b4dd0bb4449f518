// The box, centred on the body's origin: every component of `half_extents` > 0.
#include <detsim/fixed/decimal.hpp>
#include <detsim/fixed/math.hpp>

#include "collide_util.hpp"
#include "shapes.hpp"

namespace detsim::sim_detail {

// Named, not anonymous: unity builds put the four shape files in one translation unit.
namespace box_shape {

using namespace detsim::literals;
using narrow::axis_vector;
using narrow::component;
using narrow::set_component;

std::string check(const Shape& s) {
  if (auto e = check_positive_size("box half extent x", s.half_extents.x); !e.empty()) return e;
  if (auto e = check_positive_size("box half extent y", s.half_extents.y); !e.empty()) return e;
  return check_positive_size("box half extent z", s.half_extents.z);
}

// The formulas once, for Fixed (the simulation) and Checked (the limits): the same bits.
// Integers as from_int, not _fx: clang does not always evaluate a consteval literal operator in a
// function template (an undefined reference at link time).
struct Formulas {
  template <class N>
  static N volume(const Shape& s) noexcept {
    const Vec3 h = s.half_extents;
    return Fixed::from_int(8) * (N(h.x) * h.y * h.z);
  }

  template <class N>
  static std::array<N, 3> inertia(const Shape& s, N mass) noexcept {
    // m/3 (b^2 + c^2) about each axis, with half extents.
    const Vec3 h = s.half_extents;
    const N x2 = N(h.x) * h.x;
    const N y2 = N(h.y) * h.y;
    const N z2 = N(h.z) * h.z;
    const N third = mass / Fixed::from_int(3);
    return {third * (y2 + z2), third * (x2 + z2), third * (x2 + y2)};
  }
};

Fixed bounding_radius(const Shape& s, const Geometry*) noexcept {
  return length(s.half_extents);
}

Fixed smallest_dimension(const Shape& s, const Geometry*) noexcept {
  return min(s.half_extents.x, min(s.half_extents.y, s.half_extents.z));
}

Vec3 aabb_extent(const Shape& s, const Geometry*, const Mat3& r) noexcept {
  const Vec3 h = s.half_extents;
  const auto row = [&h](Vec3 m) { return abs(m.x) * h.x + abs(m.y) * h.y + abs(m.z) * h.z; };
  return {row(r.rows[0]), row(r.rows[1]), row(r.rows[2])};
}

/// Slabs (Kay and Kajiya): the ray is inside the box for t in [max of the entries, min of the
/// exits] over the three axes. The entry face is the axis of the largest entry, ties to the lower
/// axis. A ray parallel to a slab (v_i == 0 exactly) is inside it for every t or for none; tiny
/// nonzero v_i need no special case, as the quotients saturate to +-max() like infinities.
std::optional<LocalHit> ray(const Shape& s, const Geometry*, Vec3 p, Vec3 v) noexcept {
  const Vec3 h = s.half_extents;
  Fixed enter = Fixed::min();
  Fixed exit = Fixed::max();
  int face_axis = 0;
  for (int i = 0; i < 3; ++i) {
    const Fixed pi = component(p, i);
    const Fixed vi = component(v, i);
    const Fixed hi = component(h, i);
    if (vi == Fixed::zero()) {
      if (abs(pi) > hi) return std::nullopt;
      continue;
    }
    const bool increasing = vi > Fixed::zero();
    const Fixed near = ((increasing ? -hi : hi) - pi) / vi;
    const Fixed far = ((increasing ? hi : -hi) - pi) / vi;
    if (near > enter) {
      enter = near;
      face_axis = i;
    }
    exit = min(exit, far);
  }
  // The box is behind the ray (exit < 0) or beside it (enter > exit). Otherwise, as p is outside,
  // the entry is >= 0 in exact arithmetic; the clamp only guards against rounding.
  if (exit < Fixed::zero() || enter > exit) return std::nullopt;
  enter = max(enter, Fixed::zero());
  Vec3 q = p + v * enter;
  for (int i = 0; i < 3; ++i) {
    const Fixed hi = component(h, i);
    set_component(q, i, clamp(component(q, i), -hi, hi));  // rounding may step off the surface
  }
  const bool entering_positive_face = component(v, face_axis) < Fixed::zero();
  const Fixed hf = component(h, face_axis);
  set_component(q, face_axis, entering_positive_face ? hf : -hf);  // exactly on the face
  return LocalHit{enter, q, axis_vector(face_axis, entering_positive_face)};
}

bool contains(const Shape& s, const Geometry*, Vec3 p) noexcept {
  return abs(p.x) <= s.half_extents.x && abs(p.y) <= s.half_extents.y &&
         abs(p.z) <= s.half_extents.z;
}

void write(const Shape& s, ByteWriter& w) {
  w.var_vec3(s.half_extents);
}

Shape read(ByteReader& r) {
  return Shape::box(r.var_vec3("box half extents"));
}

/// The eight corners; corner i has local coordinate k at +h_k when bit k of i is set.
void outline(const Shape& s, const Geometry*, Vec3 position, Quat orientation, ShapeOutline& out) {
  const Vec3 h = s.half_extents;
  out.points.clear();
  for (const int i : {0, 1, 2, 3, 4, 5, 6, 7}) {
    const Vec3 local{(i & 1) != 0 ? h.x : -h.x, (i & 2) != 0 ? h.y : -h.y,
                     (i & 4) != 0 ? h.z : -h.z};
    out.points.push_back(position + rotate(orientation, local));
  }
  out.radius = Fixed::zero();
}

}  // namespace box_shape

const ShapeKind box_kind{ShapeType::box,
                         "box",
                         false,
                         true,
                         box_shape::check,
                         MassEntries<box_shape::Formulas>::volume,
                         MassEntries<box_shape::Formulas>::mass_properties,
                         MassEntries<box_shape::Formulas>::checked_volume,
                         MassEntries<box_shape::Formulas>::checked_inertia,
                         box_shape::bounding_radius,
                         box_shape::smallest_dimension,
                         box_shape::aabb_extent,
                         box_shape::ray,
                         box_shape::contains,
                         box_shape::write,
                         box_shape::read,
                         box_shape::outline,
                         std::nullopt};

}  // namespace detsim::sim_detail
