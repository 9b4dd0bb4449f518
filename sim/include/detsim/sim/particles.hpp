// Particles: ropes, cloth, soft bodies and fluids stepped by extended position-based dynamics
// (XPBD) inside World::step, coupled both ways with rigid bodies (docs/PARTICLES.md).
//
// A particle group is one rope, sheet of cloth, soft body or fluid: its particles are arrays of
// their own (structure of arrays), stepped in small sub-steps of one constraint pass each (Macklin
// et al., "Small Steps in Physics Simulation", 2019), in ascending group and particle index order.
// Groups have IDs of their own, never reused, assigned in creation order. Everything a group does
// is saved, hashed and diffed like a body ("particles" state section, docs/STATE.md).
#pragma once

#include <compare>
#include <cstdint>
#include <vector>

#include <detsim/fixed/decimal.hpp>
#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/quat.hpp>
#include <detsim/fixed/vec3.hpp>
#include <detsim/sim/body.hpp>
#include <detsim/sim/shape.hpp>

namespace detsim {

/// A particle group's identity: a value, never reused within a world, assigned in creation order
/// (1, 2, 3, ...). Zero is the null ID.
struct ParticleGroupId {
  std::uint32_t value = 0;

  [[nodiscard]] constexpr bool is_null() const noexcept { return value == 0; }
  friend constexpr auto operator<=>(ParticleGroupId, ParticleGroupId) noexcept = default;
};

/// The numeric values are part of the canonical state encoding (append, never renumber).
enum class ParticleGroupType : std::uint8_t {
  rope = 0,
  cloth = 1,
  soft_body = 2,
  fluid = 3,
};

/// Hard limits (refused beyond them, with a message naming the field).
inline constexpr std::uint32_t max_particles_per_group = 65536;
inline constexpr std::uint32_t max_particles_per_world = 262144;
inline constexpr std::uint32_t max_particle_groups = 4096;

/// What every group shares: its material and how finely it is stepped.
struct ParticleSettings {
  /// Coulomb coefficient against bodies, >= 0 (mixed with the body's as sqrt(a * b), as two
  /// bodies' are).
  Fixed friction = Fixed::half();
  /// 1/s, >= 0: every particle's velocity *= 1 / (1 + h * damping) per small step.
  Fixed damping{};
  /// XPBD small steps per solver sub-step (WorldDef::substeps), 1..16: more is stiffer and
  /// costs proportionally more.
  std::uint32_t substeps = 4;
  /// Collision filtering against bodies, as between two bodies.
  std::uint32_t layer = 1;
  std::uint32_t mask = 0xFFFFFFFFU;

  friend constexpr bool operator==(const ParticleSettings&,
                                   const ParticleSettings&) noexcept = default;
};

/// A rope: segments + 1 particles from `start` to `end`, laid out on the straight line between
/// them. Each segment is length / segments long at rest; a rope longer than the span starts slack
/// and falls into its hanging shape. A segment resists stretching only (a rope can be pushed
/// together), with `compliance`.
struct RopeDef {
  Vec3 start{};
  Vec3 end{Fixed::one(), Fixed::zero(), Fixed::zero()};
  std::uint32_t segments = 16;  ///< 1 .. max_particles_per_group - 1
  /// Metres, >= |end - start| (slack allowed); 0: exactly the span.
  Fixed length{};
  Fixed mass = Fixed::one();  ///< kg, of the whole rope, spread evenly over its particles
  Fixed radius = 0.05_fx;     ///< m, each particle's, for collisions with bodies
  /// m/N, >= 0, of the whole rope: a tension T stretches it by T * compliance. 0 = inextensible.
  Fixed compliance{};
  /// Of the bending constraint between every other particle (m/N), >= 0: 0 = a stiff rod.
  Fixed bending_compliance = Fixed::one();
  /// A body (of any type) each end is attached to, at `start` / `end` in that body's frame at
  /// creation; null: a free end. An attached end follows its body and pulls it (two-way).
  BodyId attach_start{};
  BodyId attach_end{};
  ParticleSettings settings{};

  friend bool operator==(const RopeDef&, const RopeDef&) = default;
};

/// A rectangular sheet: columns x rows particles at origin + axis_u * c / (columns - 1) +
/// axis_v * r / (rows - 1); particle index = row * columns + column. Its edges, diagonals
/// (shear) and every-other-particle links (bending) are distance constraints at their lengths at
/// creation.
struct ClothDef {
  Vec3 origin{};
  Vec3 axis_u{Fixed::one(), Fixed::zero(), Fixed::zero()};  ///< the sheet's side along columns
  Vec3 axis_v{Fixed::zero(), Fixed::zero(), Fixed::one()};  ///< along rows
  std::uint32_t columns = 16;                               ///< >= 2
  std::uint32_t rows = 16;                                  ///< >= 2
  Fixed mass = Fixed::one();   ///< kg, of the whole sheet, spread evenly
  Fixed thickness = 0.02_fx;   ///< m, > 0: each particle is a ball of this diameter
  Fixed stretch_compliance{};  ///< m/N per edge and diagonal, >= 0
  Fixed bend_compliance = Fixed::from_int(100);  ///< m/N, >= 0
  /// Particle indices held fixed: in space where they are at creation, or, when attach_body is
  /// set, at their place in that body's frame (they follow it and pull it).
  std::vector<std::uint32_t> pinned;
  BodyId attach_body{};
  /// A constraint whose strain (length / rest length - 1) passes this at the end of a small step
  /// breaks for good (the sheet tears); 0 = never tears. >= 0.
  Fixed tear_strain{};
  ParticleSettings settings{};

  friend bool operator==(const ClothDef&, const ClothDef&) = default;
};

/// A soft body: a volume of particles filling `shape` (a box, or a convex hull registered with the
/// world) placed at `position` with `orientation`. The particles sit at the centres of the cells
/// of a cubic lattice of `resolution` cells along the shape's longest side, each a ball of half
/// the cell's side, so that together they fill the shape (a hull keeps the cells whose corners are
/// all inside it). Each cell is six tetrahedra (Freudenthal's split along its main diagonal):
/// their edges are distance constraints of `edge_compliance`, their volumes volume constraints of
/// `volume_compliance` (0: the volume is held).
struct SoftBodyDef {
  Shape shape = Shape::box({Fixed::half(), Fixed::half(), Fixed::half()});
  Vec3 position{};
  Quat orientation{};            ///< a unit quaternion, as a body's
  std::uint32_t resolution = 4;  ///< cells along the longest side, 1..40
  Fixed mass = Fixed::one();     ///< kg, spread evenly
  Fixed edge_compliance{};       ///< m/N per edge, >= 0
  Fixed volume_compliance{};     ///< per tetrahedron (m^3 per N m), >= 0
  ParticleSettings settings{};

  friend constexpr bool operator==(const SoftBodyDef&, const SoftBodyDef&) noexcept = default;
};

/// A fluid: a block of particles filling the box [min, max] at `spacing` (particle centres at
/// min + spacing * (i + 1/2) along each axis, as many as fit whole), stepped as position-based
/// fluids (Macklin and Mueller, 2013): each particle's density, estimated from its neighbours
/// within two spacings, is held at `rest_density` (compressions only: a free surface does not
/// pull), with XSPH viscosity. Each particle weighs rest_density * spacing^3. Neighbours are found
/// within the group only: two fluid groups pass through each other.
struct FluidDef {
  Vec3 min{};
  Vec3 max{Fixed::one(), Fixed::one(), Fixed::one()};
  /// m, between neighbouring particles at rest: 2^-7 (7.8 mm) .. 10 m.
  Fixed spacing = 0.1_fx;
  Fixed rest_density = Fixed::from_int(1000);  ///< kg/m^3, 1 .. 100000 (water: 1000)
  /// XSPH viscosity, 0 .. 1: the fraction of the difference from its neighbours' mean velocity a
  /// particle gives up per small step (0: inviscid; water: about 0.01).
  Fixed viscosity = 0.01_fx;
  /// m, each particle's against bodies, 0 < radius <= spacing (half the spacing: the particles
  /// touch at rest).
  Fixed particle_radius = 0.05_fx;
  ParticleSettings settings{};

  friend constexpr bool operator==(const FluidDef&, const FluidDef&) noexcept = default;
};

/// What World::particle_group_stats reports for a group.
struct ParticleGroupStats {
  ParticleGroupType type = ParticleGroupType::rope;
  std::uint32_t particle_count = 0;
  std::uint32_t constraint_count = 0;  ///< distance constraints, broken ones included
  std::uint32_t broken_count = 0;      ///< constraints torn (cloth with tear_strain)
  Fixed radius{};                      ///< m, each particle's, against bodies (what a viewer draws)
  Fixed kinetic_energy{};              ///< J, sum of m v^2 / 2 over the particles
  /// The largest relative stretch of an unbroken edge (|d| / rest - 1, 0 when none is stretched):
  /// how well the constraints hold.
  Fixed max_strain{};
  Fixed max_speed{};  ///< m/s, the fastest particle
  /// A soft body's volume (m^3, the sum of its tetrahedra's) now and at rest; zero for the others.
  Fixed volume{};
  Fixed rest_volume{};
  /// A fluid's constraint error: its most compressed particle's density over the rest density,
  /// minus one (0 when none is compressed); zero for the others.
  Fixed max_density_error{};
  bool awake = true;

  friend constexpr bool operator==(const ParticleGroupStats&,
                                   const ParticleGroupStats&) noexcept = default;
};

}  // namespace detsim
