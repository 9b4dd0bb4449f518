// detsim::Shape: the collision shapes of a body, in the body's local frame.
//
// One plain tagged struct rather than a class hierarchy: it is copied into the world, recorded into
// snapshots field by field and compared bitwise, and the narrowphase dispatches on `type`.
#pragma once

#include <compare>
#include <cstdint>

#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/vec3.hpp>

namespace detsim {

/// Geometry registered with a World (World::create_convex_hull, ...): immutable, referred to by
/// shapes through this ID. IDs are assigned in creation order (1, 2, 3, ...) and never reused;
/// zero is the null ID. A geometry ID means something only in the world that made it.
struct GeometryId {
  std::uint32_t value = 0;

  [[nodiscard]] constexpr bool is_null() const noexcept { return value == 0; }
  friend constexpr auto operator<=>(GeometryId, GeometryId) noexcept = default;
};

/// The kinds of shape. The numeric values are part of the canonical state encoding: never
/// renumber, only append.
enum class ShapeType : std::uint8_t {
  sphere = 1,       ///< centred on the body's origin
  box = 2,          ///< oriented box centred on the body's origin
  capsule = 3,      ///< segment along the body's local y axis, swept by a sphere
  plane = 4,        ///< half-space below the body's local y = 0 plane; static bodies only
  cylinder = 5,     ///< flat-ended cylinder along the body's local y axis
  convex = 6,       ///< a convex hull registered with the world (World::create_convex_hull)
  mesh = 7,         ///< a triangle mesh registered with the world (World::create_mesh); static only
  heightfield = 8,  ///< a heightfield registered with the world (World::create_heightfield);
                    ///< static only
  compound = 9,     ///< parts placed in the body's frame, registered (World::create_compound)
};

/// A shape in the body's local frame (lengths in metres).
/// - sphere: `radius` > 0.
/// - box: every component of `half_extents` > 0.
/// - capsule: `radius` > 0, `half_height` >= 0: the core segment runs from (0, -half_height, 0) to
///   (0, +half_height, 0).
/// - cylinder: `radius` > 0, `half_height` > 0: the axis runs from (0, -half_height, 0) to
///   (0, +half_height, 0), with flat ends.
/// - plane: no parameters. Solid below the plane through the body's position whose outward normal
///   is the body's local +y axis, rotated by its orientation. Only a static body can have one.
/// - convex: `geometry`, a convex hull of the body's world (its points are in the body's frame;
///   its centre of mass need not be the body's origin).
/// - mesh: `geometry`, a triangle mesh of the body's world; heightfield: `geometry`, a heightfield
///   of the body's world. Surfaces, not solids: two-sided, no inside, no volume or mass. Only a
///   static body can have one.
/// - compound: `geometry`, a compound of the body's world: primitives and convex hulls placed in
///   the body's frame (its centre of mass is wherever the parts put it).
/// Fields that a type does not use are zero. Build shapes with the named constructors.
struct Shape {
  ShapeType type = ShapeType::sphere;
  Fixed radius{};
  Fixed half_height{};
  Vec3 half_extents{};
  GeometryId geometry{};

  [[nodiscard]] static constexpr Shape sphere(Fixed radius) noexcept {
    return {ShapeType::sphere, radius, {}, {}, {}};
  }
  [[nodiscard]] static constexpr Shape box(Vec3 half_extents) noexcept {
    return {ShapeType::box, {}, {}, half_extents, {}};
  }
  [[nodiscard]] static constexpr Shape capsule(Fixed radius, Fixed half_height) noexcept {
    return {ShapeType::capsule, radius, half_height, {}, {}};
  }
  [[nodiscard]] static constexpr Shape plane() noexcept {
    return {ShapeType::plane, {}, {}, {}, {}};
  }
  [[nodiscard]] static constexpr Shape convex(GeometryId hull) noexcept {
    return {ShapeType::convex, {}, {}, {}, hull};
  }
  [[nodiscard]] static constexpr Shape cylinder(Fixed radius, Fixed half_height) noexcept {
    return {ShapeType::cylinder, radius, half_height, {}, {}};
  }
  [[nodiscard]] static constexpr Shape mesh(GeometryId mesh) noexcept {
    return {ShapeType::mesh, {}, {}, {}, mesh};
  }
  [[nodiscard]] static constexpr Shape heightfield(GeometryId heightfield) noexcept {
    return {ShapeType::heightfield, {}, {}, {}, heightfield};
  }
  [[nodiscard]] static constexpr Shape compound(GeometryId compound) noexcept {
    return {ShapeType::compound, {}, {}, {}, compound};
  }

  friend constexpr bool operator==(const Shape&, const Shape&) noexcept = default;
};

}  // namespace detsim
