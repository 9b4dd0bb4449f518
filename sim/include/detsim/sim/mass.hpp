// Mass properties of the shapes: volume, and the principal moments of inertia per body.
#pragma once

#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/vec3.hpp>
#include <detsim/sim/shape.hpp>

namespace detsim {

/// A body's mass (kg) and principal moments of inertia about its local x, y and z axes through
/// its origin (kg m^2). Every shape here is symmetric about its local axes, so the inertia tensor
/// is diagonal in the body frame.
struct MassProperties {
  Fixed mass;
  Vec3 inertia;

  friend constexpr bool operator==(const MassProperties&, const MassProperties&) noexcept = default;
};

/// The volume of a shape in m^3 (0 for a plane; saturates for absurdly large shapes). Rounded to
/// the Fixed grid, so shapes smaller than about a millimetre have a volume that is mostly rounding:
/// give such bodies a mass rather than a density.
[[nodiscard]] Fixed volume(const Shape& shape) noexcept;

/// The mass properties of `shape` with total mass `mass` spread uniformly: solid sphere
/// (2/5 m r^2), solid box (m/3 (b^2 + c^2) with half extents), capsule (cylinder plus two
/// hemispheres, the mass split by their volumes). A plane, or a non-positive mass, gives zero.
[[nodiscard]] MassProperties mass_properties(const Shape& shape, Fixed mass) noexcept;

}  // namespace detsim
