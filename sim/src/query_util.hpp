// What the World's query files share (query.cpp: rays and overlaps; query_shapes.cpp: shape casts
// and contacts). Internal to detsim::sim.
#pragma once

#include <optional>
#include <vector>

#include <detsim/fixed/math.hpp>
#include <detsim/fixed/quat.hpp>
#include <detsim/sim/world.hpp>

#include "collide.hpp"

namespace detsim::sim_detail {

/// Whether a query with this filter considers body b.
[[nodiscard]] inline bool passes(const BodyState& b, const QueryFilter& f) noexcept {
  return (b.layer & f.mask) != 0 && (f.layer & b.mask) != 0 && (!b.sensor || f.include_sensors) &&
         (f.ignore.is_null() || b.id != f.ignore);
}

/// A body's pose from its state (never WorldState::derived, which is stale between steps).
[[nodiscard]] inline Pose pose_of(const BodyState& b) noexcept {
  return {b.position, to_mat3(b.orientation)};
}

/// A cull must never reject what the exact test would accept. The exact tests see the same
/// quantities after a few more roundings of at most a few ulps of the shape's size plus 2^-32 of
/// the distance travelled; 2^-10 m plus 2^-24 of the distance is far above both and still tight.
[[nodiscard]] inline Fixed cull_slack(Fixed distance) noexcept {
  return Fixed::from_raw(Fixed::one_raw >> 10) + (abs(distance) >> 24);
}

struct WorldState;

/// World::shape_cast and World::shape_contacts on a world's state (query_shapes.cpp): what the
/// step's own movers (characters) ask, between stages, of the bodies' present poses.
[[nodiscard]] std::optional<ShapeHit> cast_shape(const WorldState& s, const Shape& shape,
                                                 Vec3 position, Quat orientation, Vec3 translation,
                                                 const QueryFilter& filter);
/// World::raycast_closest against body b alone (query.cpp).
[[nodiscard]] std::optional<RayHit> ray_body(const WorldState& s, const BodyState& b, Vec3 origin,
                                             Vec3 translation);
[[nodiscard]] std::vector<ShapeContact> contacts_with(const WorldState& s, const Shape& shape,
                                                      Vec3 position, Quat orientation,
                                                      const QueryFilter& filter);

}  // namespace detsim::sim_detail
