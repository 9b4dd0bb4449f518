// The World's spatial queries: ray casts and shape overlaps on the current state.
//
// Poses come from each BodyState (position, to_mat3(orientation)), never from WorldState::derived,
// which is rebuilt only at the start of a step and so is stale after set_transform, create_body or
// restore. Bodies are visited in ascending ID order, and every choice between equal candidates goes
// to the first in a fixed order, so the results are the same bits on every machine.
//
// Ray precision and range. A ray is carried as a unit direction u = normalize(translation) and a
// length L = |translation| (correctly rounded): squaring the translation itself would leave the
// Fixed range (2^31) for components above ~2.6e4 m, while u and L stay exact to an ulp for any
// translation. Each body then gets the ray restarted just outside its bounding sphere (at t0, see
// cast_body), so the exact shape tests only ever see coordinates of the order of the shape's size
// (<= 10^4 m by check_shape): their squares and products stay in range, and their rounding errors
// are ulps of that size. What remains is u's own error, about 2^-32 per metre travelled: a ray of
// 10^6 m places its hit within ~2.4e-4 m, the same as the resolution of `fraction` (2^-32 L).
#include <algorithm>
#include <optional>
#include <vector>

#include <detsim/fixed/math.hpp>
#include <detsim/fixed/quat.hpp>
#include <detsim/fixed/vec3.hpp>

#include "collide.hpp"
#include "collide_util.hpp"
#include "world_state.hpp"

namespace detsim {

namespace {

using sim_detail::Manifold;
using sim_detail::Pose;
using sim_detail::narrow::axis_vector;
using sim_detail::narrow::component;
using sim_detail::narrow::set_component;
using sim_detail::narrow::to_local;

bool passes(const BodyState& b, const QueryFilter& f) noexcept {
  return (b.layer & f.mask) != 0 && (f.layer & b.mask) != 0 && (!b.sensor || f.include_sensors);
}

Pose pose_of(const BodyState& b) noexcept {
  return {b.position, to_mat3(b.orientation)};
}

/// Radius of a sphere about the body's origin that holds the whole shape (planes have none and
/// are never asked). At most ~2e4 m for shapes check_shape accepts.
Fixed bounding_radius(const Shape& s) noexcept {
  switch (s.type) {
    case ShapeType::sphere:
      return s.radius;
    case ShapeType::box:
      return length(s.half_extents);
    case ShapeType::capsule:
      return s.half_height + s.radius;
    case ShapeType::plane:
      break;
  }
  return Fixed::max();
}

/// A cull must never reject what the exact test would accept. The exact tests see the same
/// quantities after a few more roundings of at most a few ulps of the shape's size plus 2^-32 of
/// the distance travelled; 2^-10 m plus 2^-24 of the distance is far above both and still tight.
Fixed cull_slack(Fixed distance) noexcept {
  return Fixed::from_raw(Fixed::one_raw >> 10) + (abs(distance) >> 24);
}

// ---- Rays in a shape's frame
// ----------------------------------------------------------------------
//
// A local ray is p + v t for t >= 0: p the origin in the shape's frame (outside the shape: the
// caller has tested containment first), v a unit direction. The functions return the first t at
// which the ray meets the closed shape, with the point and the outward normal there (shape frame).

struct LocalHit {
  Fixed t;
  Vec3 point;
  Vec3 normal;
};

/// Where the ray enters the ball of radius r about the origin, for p outside it. The closest
/// approach is found first and the half chord taken from the perpendicular distance (never from
/// |p|^2 - r^2, which loses everything to cancellation when the ray passes far from the centre).
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

std::optional<LocalHit> ray_sphere(Vec3 p, Vec3 v, Fixed r) noexcept {
  const auto t = enter_ball(p, v, r);
  if (!t) return std::nullopt;
  const Vec3 q = p + v * *t;
  return LocalHit{*t, q, normalize_or(q, -v)};
}

/// Slabs (Kay and Kajiya): the ray is inside the box for t in [max of the entries, min of the
/// exits] over the three axes. The entry face is the axis of the largest entry, ties to the lower
/// axis. A ray parallel to a slab (v_i == 0 exactly) is inside it for every t or for none; tiny
/// nonzero v_i need no special case, as the quotients saturate to +-max() like infinities.
std::optional<LocalHit> ray_box(Vec3 p, Vec3 v, Vec3 h) noexcept {
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

/// A capsule is the union of its two end balls and the cylinder between them, and the first entry
/// into a union is the earliest entry into any piece. The cylinder's flat ends lie inside the
/// balls, so only its side needs testing: a 2D ball test in the xz plane, valid when the hit is
/// within the core's height. Candidates are taken side, bottom, top, each replacing only an
/// earlier one strictly: ties at the seams go the same way everywhere. half_height == 0 gives two
/// equal balls and a side of zero height: a sphere.
std::optional<LocalHit> ray_capsule(Vec3 p, Vec3 v, Fixed r, Fixed half_height) noexcept {
  std::optional<LocalHit> best;
  const Vec3 p2{p.x, Fixed::zero(), p.z};
  const Vec3 v2{v.x, Fixed::zero(), v.z};
  const Fixed speed2 = length(v2);  // of the ray across the axis, per unit of t
  if (speed2 > Fixed::zero()) {
    // The 2D test runs with a unit direction so that its numbers stay those of the capsule's
    // size; s / speed2 converts its distance back to t (saturating for rays nearly along the
    // axis, whose side hits, if any, are then beyond any height and rejected below).
    if (const auto s = enter_ball(p2, normalize(v2), r)) {
      const Fixed t = *s / speed2;
      const Fixed y = p.y + v.y * t;
      if (y >= -half_height && y <= half_height) {
        const Vec3 q = p + v * t;
        best = LocalHit{t, q, normalize_or(Vec3{q.x, Fixed::zero(), q.z}, -v2)};
      }
    }
  }
  for (const bool top : {false, true}) {
    const Vec3 centre{Fixed::zero(), top ? half_height : -half_height, Fixed::zero()};
    const auto hit = ray_sphere(p - centre, v, r);
    if (hit && (!best || hit->t < best->t))
      best = LocalHit{hit->t, hit->point + centre, hit->normal};
  }
  return best;
}

/// The solid half-space y <= 0.
std::optional<LocalHit> ray_plane(Vec3 p, Vec3 v) noexcept {
  if (v.y >= Fixed::zero()) return std::nullopt;  // parallel or leaving
  const Fixed t = p.y / -v.y;                     // saturates for nearly parallel rays
  Vec3 q = p + v * t;
  q.y = Fixed::zero();
  return LocalHit{t, q, Vec3::unit_y()};
}

std::optional<LocalHit> ray_shape(const Shape& s, Vec3 p, Vec3 v) noexcept {
  switch (s.type) {
    case ShapeType::sphere:
      return ray_sphere(p, v, s.radius);
    case ShapeType::box:
      return ray_box(p, v, s.half_extents);
    case ShapeType::capsule:
      return ray_capsule(p, v, s.radius, s.half_height);
    case ShapeType::plane:
      return ray_plane(p, v);
  }
  return std::nullopt;
}

/// Whether the closed shape contains the point p of its frame (surfaces included, as overlap()
/// counts touching as overlapping).
bool contains(const Shape& s, Vec3 p) noexcept {
  switch (s.type) {
    case ShapeType::sphere:
      return length(p) <= s.radius;
    case ShapeType::box:
      return abs(p.x) <= s.half_extents.x && abs(p.y) <= s.half_extents.y &&
             abs(p.z) <= s.half_extents.z;
    case ShapeType::capsule: {
      const Fixed y = clamp(p.y, -s.half_height, s.half_height);
      return length(Vec3{p.x, p.y - y, p.z}) <= s.radius;
    }
    case ShapeType::plane:
      return p.y <= Fixed::zero();
  }
  return false;
}

struct Ray {
  Vec3 origin;
  Vec3 direction;  ///< unit, or zero for a zero translation
  Fixed length;    ///< metres
};

Ray make_ray(Vec3 origin, Vec3 translation) noexcept {
  return {origin, normalize(translation), length(translation)};
}

/// The ray against one body: the bounding-sphere cull, the containment test, then the exact test
/// on a ray restarted at t0 (see the file comment).
std::optional<RayHit> cast_body(const BodyState& b, const Ray& ray) noexcept {
  const Mat3 rotation = to_mat3(b.orientation);
  const Vec3 offset = b.position - ray.origin;
  Fixed t0 = Fixed::zero();
  if (b.shape.type != ShapeType::plane) {
    const Fixed bound = bounding_radius(b.shape);
    const Fixed along = dot(offset, ray.direction);
    const Fixed nearest = clamp(along, Fixed::zero(), ray.length);
    if (length(offset - ray.direction * nearest) > bound + cull_slack(along)) return std::nullopt;
    // One metre before the bounding sphere: the restarted origin is still outside the shape, so
    // an origin that is inside the shape always has t0 == 0 and is found by the test below.
    t0 = max(along - bound - Fixed::one(), Fixed::zero());
  }
  const Vec3 p = to_local(rotation, ray.direction * t0 - offset);
  if (t0 == Fixed::zero() && contains(b.shape, p)) {
    return RayHit{b.id, ray.origin, Vec3::zero(), Fixed::zero()};
  }
  if (ray.length == Fixed::zero()) return std::nullopt;  // a point: only containment can hit
  const auto hit = ray_shape(b.shape, p, to_local(rotation, ray.direction));
  if (!hit || hit->t > ray.length - t0) return std::nullopt;
  const Fixed t = t0 + hit->t;
  return RayHit{b.id, b.position + rotation * hit->point,
                normalize_or(rotation * hit->normal, -ray.direction),
                min(t / ray.length, Fixed::one())};
}

/// Touching counts: with a margin of zero, the narrowphase reports points of separation <= 0.
bool touches(const Manifold& m) noexcept {
  for (std::uint8_t i = 0; i < m.count; ++i) {
    if (m.points[i].separation <= Fixed::zero()) return true;
  }
  return false;
}

}  // namespace

std::optional<RayHit> World::raycast_closest(Vec3 origin, Vec3 translation,
                                             const QueryFilter& filter) const {
  // The same per-body test as raycast_all, so the result is always raycast_all's first hit: a
  // later body replaces the best only with a strictly lower fraction (ties to the lower ID).
  const Ray ray = make_ray(origin, translation);
  std::optional<RayHit> best;
  for (const BodyState& b : s_->bodies) {
    if (!passes(b, filter)) continue;
    const auto hit = cast_body(b, ray);
    if (hit && (!best || hit->fraction < best->fraction)) best = hit;
  }
  return best;
}

std::vector<RayHit> World::raycast_all(Vec3 origin, Vec3 translation,
                                       const QueryFilter& filter) const {
  const Ray ray = make_ray(origin, translation);
  std::vector<RayHit> hits;
  for (const BodyState& b : s_->bodies) {
    if (!passes(b, filter)) continue;
    if (const auto hit = cast_body(b, ray)) hits.push_back(*hit);
  }
  // (fraction, ID) is a total order (IDs are unique), so the sort has no ties to leave open.
  std::sort(hits.begin(), hits.end(), [](const RayHit& x, const RayHit& y) {
    return x.fraction != y.fraction ? x.fraction < y.fraction : x.body < y.body;
  });
  return hits;
}

std::vector<BodyId> World::overlap(const Shape& shape, Vec3 position, Quat orientation,
                                   const QueryFilter& filter) const {
  std::vector<BodyId> ids;
  // The query shape follows the rules of a moving body's shape (so never a plane) and the
  // orientation those of create_body; anything else matches nothing.
  if (!sim_detail::check_shape(shape, BodyType::dynamic).empty() ||
      !sim_detail::check_orientation(orientation).empty()) {
    return ids;
  }
  const Pose query{position, to_mat3(orientation)};
  const Fixed reach = bounding_radius(shape);
  for (const BodyState& b : s_->bodies) {
    if (!passes(b, filter)) continue;
    if (b.shape.type != ShapeType::plane) {
      const Fixed gap = distance(b.position, position);
      if (gap > reach + bounding_radius(b.shape) + cull_slack(gap)) continue;
    }
    // collide() accepts its shapes in either order (it swaps them into its canonical one); the
    // normal's direction, the only thing the order changes, does not matter here.
    if (touches(sim_detail::collide(shape, query, b.shape, pose_of(b), Fixed::zero()))) {
      ids.push_back(b.id);
    }
  }
  return ids;
}

}  // namespace detsim
