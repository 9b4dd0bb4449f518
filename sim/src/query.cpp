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
#include "query_util.hpp"
#include "shapes.hpp"
#include "world_state.hpp"

namespace detsim {

namespace {

using sim_detail::bounding_radius;
using sim_detail::cull_slack;
using sim_detail::Manifold;
using sim_detail::passes;
using sim_detail::Pose;
using sim_detail::pose_of;
using sim_detail::narrow::to_local;

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
std::optional<RayHit> cast_body(const sim_detail::WorldState& s, const BodyState& b,
                                const Ray& ray) noexcept {
  const sim_detail::ShapeKind& kind = sim_detail::shape_kind(b.shape.type);
  const sim_detail::Geometry* g = s.geometry(b.shape);
  const Mat3 rotation = to_mat3(b.orientation);
  const Vec3 offset = b.position - ray.origin;
  Fixed t0 = Fixed::zero();
  if (kind.bounded) {
    const Fixed bound = kind.bounding_radius(b.shape, g);
    const Fixed along = dot(offset, ray.direction);
    const Fixed nearest = clamp(along, Fixed::zero(), ray.length);
    if (length(offset - ray.direction * nearest) > bound + cull_slack(along)) return std::nullopt;
    // One metre before the bounding sphere: the restarted origin is still outside the shape, so
    // an origin that is inside the shape always has t0 == 0 and is found by the test below.
    t0 = max(along - bound - Fixed::one(), Fixed::zero());
  }
  const Vec3 p = to_local(rotation, ray.direction * t0 - offset);
  if (t0 == Fixed::zero() && kind.contains(b.shape, g, p)) {
    return RayHit{b.id, ray.origin, Vec3::zero(), Fixed::zero()};
  }
  if (ray.length == Fixed::zero()) return std::nullopt;  // a point: only containment can hit
  const auto hit = kind.ray(b.shape, g, p, to_local(rotation, ray.direction));
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

std::optional<RayHit> sim_detail::ray_body(const WorldState& s, const BodyState& b, Vec3 origin,
                                           Vec3 translation) {
  return cast_body(s, b, make_ray(origin, translation));
}

std::optional<RayHit> World::raycast_closest(Vec3 origin, Vec3 translation,
                                             const QueryFilter& filter) const {
  // The same per-body test as raycast_all, so the result is always raycast_all's first hit: a
  // later body replaces the best only with a strictly lower fraction (ties to the lower ID).
  const Ray ray = make_ray(origin, translation);
  std::optional<RayHit> best;
  for (const BodyState& b : s_->bodies) {
    if (!passes(b, filter)) continue;
    const auto hit = cast_body(*s_, b, ray);
    if (hit && (!best || hit->fraction < best->fraction)) best = hit;
  }
  return best;
}

std::optional<ParticleRayHit> World::raycast_particles(Vec3 origin, Vec3 translation,
                                                       const QueryFilter& filter) const {
  // Each particle is tested as a ball body would be (the same cull, containment and exact test),
  // in ascending group and particle order; a later particle replaces the best only with a
  // strictly lower fraction.
  const Ray ray = make_ray(origin, translation);
  std::optional<ParticleRayHit> best;
  for (const sim_detail::ParticleGroup& g : s_->particle_groups) {
    BodyState ball;
    ball.shape = Shape::sphere(g.radius);
    ball.layer = g.settings().layer;
    ball.mask = g.settings().mask;
    if (!passes(ball, filter)) continue;
    for (std::size_t i = 0; i < g.size(); ++i) {
      ball.position = g.positions[i];
      const auto hit = cast_body(*s_, ball, ray);
      if (hit && (!best || hit->fraction < best->fraction))
        best = ParticleRayHit{g.id, static_cast<std::uint32_t>(i), hit->point, hit->normal,
                              hit->fraction};
    }
  }
  return best;
}

std::vector<RayHit> World::raycast_all(Vec3 origin, Vec3 translation,
                                       const QueryFilter& filter) const {
  const Ray ray = make_ray(origin, translation);
  std::vector<RayHit> hits;
  for (const BodyState& b : s_->bodies) {
    if (!passes(b, filter)) continue;
    if (const auto hit = cast_body(*s_, b, ray)) hits.push_back(*hit);
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
  if (!sim_detail::check_shape(s_->geometries, shape, BodyType::dynamic).empty() ||
      !sim_detail::check_orientation(orientation).empty()) {
    return ids;
  }
  const Pose query{position, to_mat3(orientation)};
  const sim_detail::Geometry* shape_geometry = s_->geometry(shape);
  const Fixed reach = bounding_radius(shape, shape_geometry);
  // Reused between queries (one list per thread): a query allocates only its result.
  thread_local std::vector<sim_detail::SubManifold> manifolds;
  for (const BodyState& b : s_->bodies) {
    if (!passes(b, filter)) continue;
    if (sim_detail::shape_kind(b.shape.type).bounded) {
      const Fixed gap = distance(b.position, position);
      if (gap > reach + sim_detail::cull_radius(b.shape, s_->geometry(b.shape)) + cull_slack(gap))
        continue;
    }
    // collide() accepts its shapes in either order (it swaps them into its canonical one); the
    // normal's direction, the only thing the order changes, does not matter here.
    const Pose pose = pose_of(b);
    sim_detail::collide_all({shape, shape_geometry, query}, {b.shape, s_->geometry(b.shape), pose},
                            Fixed::zero(), manifolds);
    if (std::any_of(manifolds.begin(), manifolds.end(),
                    [](const sim_detail::SubManifold& m) { return touches(m.manifold); })) {
      ids.push_back(b.id);
    }
  }
  return ids;
}

}  // namespace detsim
