// A compound's geometry: parts (primitives and convex hulls of the same world) placed in the
// compound's frame, and the solid they make. Internal to detsim::sim.
//
// Immutable once built (build_compound, compound.cpp). A part's hull is held by pointer to its
// Geometry (shared with the world's table), so a compound answers every question without the
// table. The parts are assumed not to overlap: the solid is their sum (an overlap counts twice).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <detsim/core/status.hpp>
#include <detsim/fixed/mat3.hpp>
#include <detsim/fixed/quat.hpp>
#include <detsim/fixed/vec3.hpp>
#include <detsim/sim/geometry.hpp>
#include <detsim/sim/shape.hpp>

#include "hull.hpp"

namespace detsim::sim_detail {

struct Geometry;

/// The most parts a compound may have: a part's index is one byte of a contact's sub-shape key.
inline constexpr std::size_t max_compound_parts = 64;

/// One part, as given, with its geometry (nullptr for a primitive) and its pose.
struct CompoundPart {
  CompoundChild child;                       ///< as given (the content hash covers it)
  std::shared_ptr<const Geometry> geometry;  ///< the part's hull; nullptr for a primitive
  Quat orientation = Quat::identity();       ///< child.orientation normalised
  Mat3 rotation = Mat3::identity();          ///< to_mat3(orientation): part frame -> compound
  Fixed volume;                              ///< m^3
  Vec3 centroid;                             ///< the part's centroid, compound frame
};

struct Compound {
  std::vector<CompoundPart> parts;
  SolidProperties solid;  ///< of the union, each part of the same density (parts must not overlap)
  Vec3 aabb_min;          ///< local-frame bounds of the parts
  Vec3 aabb_max;
  Fixed bounding_radius;  ///< as ShapeKind::bounding_radius: about the origin and the centroid
  Fixed inner_radius;     ///< the largest part's smallest dimension (continuous collision's "fast")
};

/// A part's shape and the geometry its kind reads (nullptr for a primitive).
[[nodiscard]] inline const Geometry* part_geometry(const CompoundPart& part) noexcept {
  return part.geometry.get();
}

}  // namespace detsim::sim_detail
