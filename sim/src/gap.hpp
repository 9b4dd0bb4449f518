// A proven lower bound of the distance between two convex shapes, for the passes that advance by
// it (shape casts: query_shapes.cpp; continuous collision: ccd.cpp). Internal to detsim::sim.
//
// The narrowphase's manifold is made for the solver, not as a distance bound: box-box and
// box-capsule clip a face's points and measure them along its normal, which for shapes far apart
// sideways can be several times their distance. Here GJK's closest points give a direction n,
// and the gap between the two shapes' projections on n is the bound: a lower bound of the
// distance for any n (nearly the distance itself for GJK's n), exactly linear in a translation
// along a fixed n. GJK's own |v| bounds the distance from above, not below.
#pragma once

#include <optional>

#include <detsim/fixed/vec3.hpp>
#include <detsim/sim/shape.hpp>

#include "collide.hpp"
#include "geometry/convex.hpp"

namespace detsim::sim_detail {

/// Two shapes as measured at one moment: a lower bound of their distance, the direction it is
/// measured along (unit, from a into b) and the point of b's surface nearest a.
struct Gap {
  Fixed separation;
  Vec3 normal;
  Vec3 point;
};

/// The convex view of a shape, if it has one (sphere, box, capsule, cylinder, hull).
[[nodiscard]] std::optional<ConvexView> convex_view(const Shape& shape, const Geometry* g);

/// The gap of a and b, whose views are va and vb. Cores that meet have no closest points: the
/// narrowphase's normal and depth then (a zero normal if it has none: touching exactly).
[[nodiscard]] Gap convex_gap(const PosedShape& a, const ConvexView& va, const PosedShape& b,
                             const ConvexView& vb);

}  // namespace detsim::sim_detail
