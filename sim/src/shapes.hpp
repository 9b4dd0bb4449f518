// One home per shape type. Internal to detsim::sim.
//
// Everything the library does with a shape that depends on its type lives in that type's file
// (shape_sphere.cpp, shape_box.cpp, shape_capsule.cpp, shape_plane.cpp, shape_cylinder.cpp,
// shape_convex.cpp, shape_mesh.cpp for meshes and heightfields, shape_compound.cpp) as one
// ShapeKind: its checks, mass properties, bounds, ray and containment tests, canonical encoding and
// outline. The rest of the library asks the kind (shape_kind(type)) and never switches on
// ShapeType, so a new type is its file, a row in shapes.cpp's table and its rows in the collision
// pair table (collide.cpp) — docs/ARCHITECTURE.md has the checklist. Pair functions, which belong
// to two types, stay in the narrowphase files.
//
// Precision rules shared by every kind: sizes are at most 10^4 m (check), so squares and products
// of sizes stay far inside the Fixed range; each function keeps its own precision argument.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <span>
#include <string>

#include <detsim/core/bytes.hpp>
#include <detsim/fixed/mat3.hpp>
#include <detsim/fixed/quat.hpp>
#include <detsim/fixed/vec3.hpp>
#include <detsim/sim/body.hpp>
#include <detsim/sim/mass.hpp>
#include <detsim/sim/shape.hpp>
#include <detsim/sim/shape_outline.hpp>

#include "geometry/geometry.hpp"
#include "limits.hpp"

namespace detsim::sim_detail {

/// Where a ray p + v t (t >= 0, v a unit vector, both in the shape's frame) first meets a shape:
/// the t, the point and the outward unit normal there (shape frame).
struct LocalHit {
  Fixed t;
  Vec3 point;
  Vec3 normal;
};

/// The four mass entries of a ShapeKind (volume, mass_properties, checked_volume,
/// checked_inertia) from a kind's formulas, written once as templates over the number type:
/// `Formulas::volume<N>(shape)` and `Formulas::inertia<N>(shape, mass)` (the moments about x, y
/// and z), for N = Fixed (what the simulation uses) and N = Checked (the limits, the same bits).
template <class Formulas>
struct MassEntries {
  static Fixed volume(const Shape& s, const Geometry*) noexcept {
    return Formulas::template volume<Fixed>(s);
  }
  static MassProperties mass_properties(const Shape& s, const Geometry*, Fixed mass) noexcept {
    const std::array<Fixed, 3> i = Formulas::template inertia<Fixed>(s, mass);
    return {mass, {i[0], i[1], i[2]}};
  }
  static Checked checked_volume(const Shape& s, const Geometry*) noexcept {
    return Formulas::template volume<Checked>(s);
  }
  static std::array<Checked, 3> checked_inertia(const Shape& s, const Geometry*,
                                                Fixed mass) noexcept {
    return Formulas::template inertia<Checked>(s, mass);
  }
};

/// What the library does with one type of shape. Every function takes a shape of this type that
/// `check` has accepted, except `check` itself and `read`, and the geometry it refers to
/// (shape_geometry: nullptr for the primitives, which ignore it).
struct ShapeKind {
  ShapeType type;
  const char* name;  ///< "sphere": in messages and the encoding's description
  bool static_only;  ///< only a static body may have it (a plane)
  bool bounded;      ///< false: no finite extent (a plane), so no bounding box or radius

  /// The shape's own fields (sizes); "" when valid, else a message naming the field and value.
  std::string (*check)(const Shape& shape);
  /// m^3 (0 for an unbounded shape).
  Fixed (*volume)(const Shape& shape, const Geometry* g) noexcept;
  /// Mass properties of the solid with total mass `mass` > 0 spread uniformly.
  MassProperties (*mass_properties)(const Shape& shape, const Geometry* g, Fixed mass) noexcept;
  /// `volume` in Checked arithmetic (the same formula, the same bits): whether any step of it
  /// leaves the limits of limits.hpp.
  Checked (*checked_volume)(const Shape& shape, const Geometry* g) noexcept;
  /// The moments of inertia of `mass_properties` (about x, y, z) in Checked arithmetic.
  std::array<Checked, 3> (*checked_inertia)(const Shape& shape, const Geometry* g,
                                            Fixed mass) noexcept;
  /// The radius of a ball about the body's origin that holds the shape, and no smaller than any
  /// point's distance from the centre of mass (the two agree for the primitives, centred on the
  /// origin); 0 when unbounded.
  Fixed (*bounding_radius)(const Shape& shape, const Geometry* g) noexcept;
  /// The smallest distance across the shape from its centre (continuous collision's "fast").
  Fixed (*smallest_dimension)(const Shape& shape, const Geometry* g) noexcept;
  /// Half extents of a world-space box about the body's origin that holds the shape under
  /// `rotation` (bounded only).
  Vec3 (*aabb_extent)(const Shape& shape, const Geometry* g, const Mat3& rotation) noexcept;
  /// The first hit of the ray p + v t from a point p outside the shape (shape frame).
  std::optional<LocalHit> (*ray)(const Shape& shape, const Geometry* g, Vec3 p, Vec3 v) noexcept;
  /// Whether the closed shape contains p (shape frame; surfaces included).
  bool (*contains)(const Shape& shape, const Geometry* g, Vec3 p) noexcept;
  /// The canonical encoding of the shape's fields (the type byte is written by the caller).
  void (*write)(const Shape& shape, ByteWriter& w);
  Shape (*read)(ByteReader& r);
  /// What a viewer draws (detsim/sim/shape_outline.hpp), placed at position and orientation.
  void (*outline)(const Shape& shape, const Geometry* g, Vec3 position, Quat orientation,
                  ShapeOutline& out);
  /// The type of geometry its shapes refer to (Shape::geometry), or none: a primitive, whose
  /// fields are the whole shape and whose geometry ID is null.
  std::optional<GeometryType> geometry;
};

extern const ShapeKind sphere_kind;
extern const ShapeKind box_kind;
extern const ShapeKind capsule_kind;
extern const ShapeKind plane_kind;
extern const ShapeKind cylinder_kind;
extern const ShapeKind convex_kind;
extern const ShapeKind mesh_kind;
extern const ShapeKind heightfield_kind;
extern const ShapeKind compound_kind;

/// Every kind, ascending by type.
[[nodiscard]] std::span<const ShapeKind* const> shape_kinds() noexcept;
/// The kind of type `t`, or nullptr for a value that names no type.
[[nodiscard]] const ShapeKind* find_shape_kind(ShapeType t) noexcept;
/// The kind of a shape that has been checked (every shape in a world has).
[[nodiscard]] inline const ShapeKind& shape_kind(ShapeType t) noexcept {
  return *find_shape_kind(t);
}

/// The radius of a ball about the body's origin that holds a checked shape (0 when unbounded).
[[nodiscard]] inline Fixed bounding_radius(const Shape& shape, const Geometry* g) noexcept {
  return shape_kind(shape.type).bounding_radius(shape, g);
}

/// An upper bound of bounding_radius with no square root, for culling queries body by body: a
/// box's and a cylinder's half sizes summed (|h| <= |h.x| + |h.y| + |h.z|); the other kinds'
/// radius (a stored number or a sum already). Never smaller, so a cull by it keeps every body
/// the exact radius keeps: only the culling's cost changes, never a query's result.
[[nodiscard]] Fixed cull_radius(const Shape& shape, const Geometry* g) noexcept;

// Ray pieces shared by the round kinds (shape_sphere.cpp).

/// Where the ray enters the ball of radius r about the origin, for p outside it.
[[nodiscard]] std::optional<Fixed> enter_ball(Vec3 p, Vec3 v, Fixed r) noexcept;
/// The hit of the ray on the ball of radius r about the origin, for p outside it.
[[nodiscard]] std::optional<LocalHit> ray_ball(Vec3 p, Vec3 v, Fixed r) noexcept;

/// The common refusal of a size: "<what> must be > 0, got x" or "<what> must be <= 10000, got x";
/// "" when 0 < x <= 10^4 m.
[[nodiscard]] std::string check_positive_size(const char* what, Fixed x);
/// The largest size the simulation accepts (m): bounding boxes and products of lengths stay far
/// from the Fixed range (2^31).
inline constexpr Fixed max_shape_size = Fixed::from_int(10000);

}  // namespace detsim::sim_detail
