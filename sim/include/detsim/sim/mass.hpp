// Mass properties of the shapes: volume, and the principal moments of inertia per body.
#pragma once

#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/quat.hpp>
#include <detsim/fixed/vec3.hpp>
#include <detsim/sim/shape.hpp>

namespace detsim {

/// A body's mass (kg), centre of mass and principal moments of inertia (kg m^2).
/// - `center`: the centre of mass in the body's frame. The primitives are centred on the origin
///   (zero); a convex hull's is its centroid; a compound's the volume-weighted mean of its parts'.
/// - `inertia`: the principal moments, about the axes of `inertia_axes` through the centre.
/// - `inertia_axes`: the rotation from the principal axes to the body's axes, so that the tensor
///   in the body frame is R diag(inertia) R^T with R = to_mat3(inertia_axes). The identity for
///   every primitive (symmetric about its local axes) and for a hull whose tensor is diagonal.
struct MassProperties {
  Fixed mass;
  Vec3 inertia;
  Vec3 center{};
  Quat inertia_axes{};

  friend constexpr bool operator==(const MassProperties&, const MassProperties&) noexcept = default;
};

/// The volume of a shape in m^3 (0 for a plane; saturates for absurdly large shapes). Rounded to
/// the Fixed grid, so shapes smaller than about a millimetre have a volume that is mostly rounding:
/// give such bodies a mass rather than a density.
[[nodiscard]] Fixed volume(const Shape& shape) noexcept;

/// The mass properties of `shape` with total mass `mass` spread uniformly: solid sphere
/// (2/5 m r^2), solid box (m/3 (b^2 + c^2) with half extents), capsule (cylinder plus two
/// hemispheres, the mass split by their volumes). A plane, a shape whose geometry is registered
/// with a world (a convex hull or a compound: ask the world, World::mass_properties), or a
/// non-positive mass gives zero.
[[nodiscard]] MassProperties mass_properties(const Shape& shape, Fixed mass) noexcept;

}  // namespace detsim
