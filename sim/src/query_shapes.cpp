// The World's shape queries: a shape cast (the first body a moving shape meets) and contacts (what
// a placed shape or a body touches, with normals and depths), on the current state. What a
// character controller or a vehicle's wheel asks before it moves (docs/SIM.md, "Queries").
//
// Contacts are the narrowphase's own manifolds (collide_all, margin 0), so a query sees exactly
// the normals and depths the solver would, one per pair of sub-shapes.
//
// The cast is conservative advancement along the translation, body by body (ascending ID), with
// the fraction t of the translation as time. Each pair of the cast shape and a body (or one of its
// parts or triangle patches) is measured as a Gap: a lower bound of their distance, along a unit
// direction n from the shape into the body.
// - A convex body (sphere, box, capsule, cylinder, hull): GJK's closest points give n, and the
//   bound is the gap between the two shapes' projections on n. Along a fixed n that gap is a
//   lower bound of the distance at every t, and exactly linear in t, shrinking at
//   a = dot(n, translation) per unit t. So from gap d the shapes cannot come within target / 2
//   before t + (d - target / 2) / a, and if a <= 0 the projections never get closer: the pair is
//   never met. (The narrowphase's manifold is not such a bound: box-box clipping measures its
//   points along a face normal, which for boxes far apart sideways is several times the distance;
//   the random test in tests/sim_shape_query_test.cpp found a cast passing a box that way.)
// - A plane: the narrowphase's depth of the deepest point, exact.
// - A surface (mesh, heightfield) or a compound: the narrowphase's manifolds within `margin`, one
//   per part or patch, each with its normal. These are the solver's own separations, not proven
//   lower bounds away from contact (see above); near contact, where a cast ends, they are exact to
//   the narrowphase's precision.
// A pair not shrinking now is not met: the shape resting on a floor and cast along it passes the
// floor by and meets the wall ahead, and a shape that starts inside a body and moves out is not
// stopped by it. A pair already in touch is met only when the motion goes into it by more than
// 2^-14 of its length (about 0.0035 degrees): a motion along a surface it touches slides along it
// whatever the last bits of GJK's direction say, and may end at most that much deeper. Every
// advance is the smallest bound over the pairs, and (surfaces, compounds) for pairs beyond
// `margin`, (margin - target / 2) / |translation|. The cast stops when some shrinking pair is
// within `target` (the world's linear_slop): the shape is then apart from the body by between about
// target / 2 and target. A fixed number of iterations bounds the work; a cast that runs out stops
// where it was, short of the body (it never ends inside anything). Bodies are visited in ascending
// ID order and a later body replaces the best hit only with a strictly lower fraction, so the
// result is the same bits on every machine.
#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include <detsim/fixed/math.hpp>
#include <detsim/fixed/quat.hpp>
#include <detsim/fixed/vec3.hpp>

#include "collide.hpp"
#include "gap.hpp"
#include "query_util.hpp"
#include "shapes.hpp"
#include "world_state.hpp"

namespace detsim {

namespace {

using sim_detail::bounding_radius;
using sim_detail::collide_all;
using sim_detail::convex_gap;
using sim_detail::convex_view;
using sim_detail::ConvexView;
using sim_detail::cull_slack;
using sim_detail::Gap;
using sim_detail::Geometry;
using sim_detail::passes;
using sim_detail::Pose;
using sim_detail::pose_of;
using sim_detail::PosedShape;
using sim_detail::shape_kind;
using sim_detail::SubManifold;
using sim_detail::WorldState;

constexpr int max_cast_iterations = 32;

/// The query shape, checked: the rules of a moving body's shape (so never a plane) and of
/// create_body's orientations. nullopt when it breaks them (the query then finds nothing).
struct Query {
  const Shape& shape;
  const Geometry* geometry;
  Pose pose;
  Fixed reach;                     ///< bounding radius
  std::optional<ConvexView> view;  ///< the shapes a cast takes (not a compound)
  bool bounded = true;  ///< false for a plane (contacts_of a plane body): reaches everything
};

std::optional<Query> checked_query(const WorldState& s, const Shape& shape, Vec3 position,
                                   Quat orientation) {
  if (!sim_detail::check_shape(s.geometries, shape, BodyType::dynamic).empty() ||
      !sim_detail::check_orientation(orientation).empty()) {
    return std::nullopt;
  }
  const Geometry* g = s.geometry(shape);
  return Query{
      shape, g, {position, to_mat3(orientation)}, bounding_radius(shape, g), convex_view(shape, g),
      true};
}

/// The smallest separation among a manifold's points, and that point's index.
struct Nearest {
  Fixed separation;
  std::uint8_t index = 0;
};

Nearest nearest_point(const sim_detail::Manifold& m) {
  Nearest n{m.points[0].separation, 0};
  for (std::uint8_t k = 1; k < m.count; ++k) {
    if (m.points[k].separation < n.separation) n = {m.points[k].separation, k};
  }
  return n;
}

/// Every touching manifold of `query` against body b, appended to `out` as ShapeContacts (normals
/// out of b). `manifolds` is scratch.
void touches_of(const WorldState& s, const Query& query, const BodyState& b,
                std::vector<SubManifold>& manifolds, std::vector<ShapeContact>& out) {
  const sim_detail::ShapeKind& kind = shape_kind(b.shape.type);
  const Geometry* g = s.geometry(b.shape);
  if (kind.bounded && query.bounded) {
    const Fixed gap = distance(b.position, query.pose.position);
    if (gap > query.reach + sim_detail::cull_radius(b.shape, g) + cull_slack(gap)) return;
  }
  const Pose pose = pose_of(b);
  collide_all({query.shape, query.geometry, query.pose}, {b.shape, g, pose}, Fixed::zero(),
              manifolds);
  for (const SubManifold& sub : manifolds) {
    const sim_detail::Manifold& m = sub.manifold;
    ShapeContact c;
    c.body = b.id;
    c.sub_shape = sub.sub_b;
    c.normal = -m.normal;  // the narrowphase's points from the query shape into b
    c.depth = max(-nearest_point(m).separation, Fixed::zero());
    for (std::uint8_t k = 0; k < m.count; ++k) {
      // Margin 0 reports touching points only, but a patch merged from several triangles may
      // carry one a little apart: keep those that touch.
      if (m.points[k].separation > Fixed::zero()) continue;
      c.points[c.point_count++] = m.points[k].point;
    }
    if (c.point_count > 0) out.push_back(c);
  }
}

/// A cast's motion: the translation, its length and its direction (translation / travel), the
/// last two once per cast rather than once per body.
struct CastSweep {
  Vec3 translation;
  Fixed travel;
  Vec3 direction;
};

/// The earliest fraction at which the cast of `query` along `sweep` meets body b, below `before`,
/// or nothing.
std::optional<ShapeHit> cast_against(const WorldState& s, const Query& query,
                                     const CastSweep& sweep, const BodyState& b, Fixed before,
                                     std::vector<SubManifold>& manifolds, std::vector<Gap>& gaps) {
  const Vec3 translation = sweep.translation;
  const Fixed travel = sweep.travel;
  const sim_detail::ShapeKind& kind = shape_kind(b.shape.type);
  const Geometry* g = s.geometry(b.shape);
  const Fixed target = s.def.linear_slop;
  const Fixed half_target = target >> 1;
  if (kind.bounded) {
    // The swept ball of the query shape against b's bounding ball.
    const Vec3 offset = b.position - query.pose.position;
    const Vec3 direction = sweep.direction;
    const Fixed along = dot(offset, direction);
    const Fixed nearest = clamp(along, Fixed::zero(), travel);
    // Squared, without a root per body: the square's rounding (2^-32 m^2) is far inside the
    // slack, and a square that saturates is only ever of a gap far beyond the reach (or of a
    // reach so large that both saturate, and then nothing is culled).
    const Vec3 gap = offset - direction * nearest;
    const Fixed reach =
        query.reach + sim_detail::cull_radius(b.shape, g) + target + cull_slack(along);
    if (dot(gap, gap) > reach * reach) return std::nullopt;
  }
  const Pose pose = pose_of(b);
  const std::optional<ConvexView> body_view = convex_view(b.shape, g);
  // Otherwise the narrowphase measures the pairs within `margin`: the rest of the travel, but no
  // more than a few times the shape's size (a long cast over a mesh would otherwise gather every
  // triangle along its path at every iteration).
  const Fixed window = max(query.reach * Fixed::from_int(4), Fixed::one());
  Fixed t = Fixed::zero();
  for (int iteration = 0; iteration < max_cast_iterations; ++iteration) {
    const Pose at{query.pose.position + translation * t, query.pose.rotation};
    const Fixed remaining = travel - travel * t;
    const bool covers_rest = remaining <= window;
    const Fixed margin = (covers_rest ? remaining : window) + target;
    // How far t may go with nothing in reach (pairs beyond the margin).
    Fixed advance = covers_rest ? Fixed::one() : (margin - half_target) / travel;
    gaps.clear();
    if (body_view) {
      gaps.push_back(convex_gap({query.shape, query.geometry, at}, *query.view, {b.shape, g, pose},
                                *body_view));
      advance = Fixed::one();  // the gap bounds the whole pair
    } else {
      collide_all({query.shape, query.geometry, at}, {b.shape, g, pose}, margin, manifolds);
      for (const SubManifold& sub : manifolds) {
        const sim_detail::Manifold& m = sub.manifold;
        const Nearest n = nearest_point(m);
        const sim_detail::ContactPoint& p = m.points[n.index];
        // The point lies midway between the surfaces; b's surface is half the separation on.
        gaps.push_back({n.separation, m.normal, p.point + m.normal * (p.separation >> 1)});
      }
    }
    const Gap* hit = nullptr;
    for (const Gap& gap : gaps) {
      const Fixed approach = dot(gap.normal, translation);  // per unit t
      if (approach <= Fixed::zero()) continue;  // not shrinking now, so never (convexity)
      if (gap.separation <= target) {
        // In touch but grazing (deeper by at most 2^-14 of the motion): sliding along, not into
        // it. GJK's direction is good to a few 10^-6, so a motion along a face it touches (a
        // character's capsule moving down beside a wall) must not read as into it.
        if (approach <= (travel >> 14)) continue;
        if (hit == nullptr || gap.separation < hit->separation) hit = &gap;
        continue;
      }
      advance = min(advance, (gap.separation - half_target) / approach);
    }
    if (hit != nullptr) {
      if (body_view) {
        // GJK's direction is good to its tolerance (a few 10^-6 on a flat face): the normal and
        // point reported are the narrowphase's, as the solver would see them, when it has them.
        const sim_detail::Manifold m = sim_detail::collide(
            PosedShape{query.shape, query.geometry, at}, PosedShape{b.shape, g, pose}, target);
        if (m.count > 0 && dot(m.normal, translation) > Fixed::zero()) {
          const sim_detail::ContactPoint& p = m.points[nearest_point(m).index];
          return ShapeHit{b.id, t, p.point + m.normal * (p.separation >> 1), -m.normal};
        }
      }
      return ShapeHit{b.id, t, hit->point, -hit->normal};
    }
    t += advance;
    if (t >= before || t > Fixed::one()) return std::nullopt;
  }
  // Out of iterations: stop where the cast got to, short of the body (see the file comment).
  return ShapeHit{b.id, t, query.pose.position + translation * t, -normalize(translation)};
}

}  // namespace

namespace sim_detail {

std::optional<ShapeHit> cast_shape(const WorldState& s, const Shape& shape, Vec3 position,
                                   Quat orientation, Vec3 translation, const QueryFilter& filter) {
  const std::optional<Query> query = checked_query(s, shape, position, orientation);
  const Fixed travel = length(translation);
  if (!query || !query->view || travel == Fixed::zero()) return std::nullopt;
  thread_local std::vector<SubManifold> manifolds;  // reused between queries
  thread_local std::vector<Gap> gaps;
  const CastSweep sweep{translation, travel, translation / travel};
  std::optional<ShapeHit> best;
  for (const BodyState& b : s.bodies) {
    if (!passes(b, filter)) continue;
    const Fixed before = best ? best->fraction : Fixed::one() + Fixed::from_raw(1);
    if (auto hit = cast_against(s, *query, sweep, b, before, manifolds, gaps)) {
      best = hit;
    }
  }
  return best;
}

std::vector<ShapeContact> contacts_with(const WorldState& s, const Shape& shape, Vec3 position,
                                        Quat orientation, const QueryFilter& filter) {
  std::vector<ShapeContact> out;
  const std::optional<Query> query = checked_query(s, shape, position, orientation);
  if (!query) return out;
  thread_local std::vector<SubManifold> manifolds;
  for (const BodyState& b : s.bodies) {
    if (passes(b, filter)) touches_of(s, *query, b, manifolds, out);
  }
  return out;
}

}  // namespace sim_detail

std::optional<ShapeHit> World::shape_cast(const Shape& shape, Vec3 position, Quat orientation,
                                          Vec3 translation, const QueryFilter& filter) const {
  return sim_detail::cast_shape(*s_, shape, position, orientation, translation, filter);
}

std::vector<ShapeContact> World::shape_contacts(const Shape& shape, Vec3 position, Quat orientation,
                                                const QueryFilter& filter) const {
  return sim_detail::contacts_with(*s_, shape, position, orientation, filter);
}

Expected<std::vector<ShapeContact>> World::contacts_of(BodyId id) const {
  const std::ptrdiff_t i = s_->find(id.value);
  if (i < 0) return Status::error("no body with ID " + std::to_string(id.value));
  const BodyState& self = s_->bodies[static_cast<std::size_t>(i)];
  // A plane's bounding radius is 0: Query::bounded keeps it from being culled by distance.
  const Query query{self.shape,    s_->geometry(self.shape),
                    pose_of(self), bounding_radius(self.shape, s_->geometry(self.shape)),
                    std::nullopt,  shape_kind(self.shape.type).bounded};
  const QueryFilter filter{self.layer, self.mask, false, id};
  std::vector<ShapeContact> out;
  thread_local std::vector<SubManifold> manifolds;
  for (const BodyState& b : s_->bodies) {
    if (passes(b, filter)) touches_of(*s_, query, b, manifolds, out);
  }
  return out;
}

}  // namespace detsim
