// A particle group as the world holds it: its definition, its particles (structure of arrays) and
// the constraints built from the definition. Internal to detsim::sim.
//
// Saved state (docs/STATE.md, the "particles" section): the definition, every particle's position
// and velocity, the attachments' body-frame points, which constraints are broken, the accumulated
// force, the sleep state and the rope tether's warm-start impulse. The constraints themselves are
// rebuilt from the definition (build_group), never saved: the same definition builds the same
// constraints, bit for bit, on every machine.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <variant>
#include <vector>

#include <detsim/sim/particles.hpp>

namespace detsim::sim_detail {

struct WorldState;

/// What a distance constraint does: a rope's segment only resists stretching; the others hold
/// their rest length both ways.
enum class LinkKind : std::uint8_t {
  stretch = 0,  ///< a cloth's edge (two-sided)
  shear = 1,    ///< a cloth's diagonal (two-sided)
  bend = 2,     ///< every other particle (two-sided)
  rope = 3,     ///< a rope's segment (stretching only)
};

/// A distance constraint between particles a < b, at rest length `rest`.
struct Link {
  std::uint32_t a = 0;
  std::uint32_t b = 0;
  Fixed rest;
  Fixed compliance;  ///< m/N of this one constraint
  LinkKind kind = LinkKind::stretch;
};

/// A particle that follows a body: where it is in the body's frame (relative to the body's
/// origin). Part of the state.
struct Attachment {
  std::uint32_t particle = 0;
  std::uint32_t body = 0;  ///< BodyId value
  Vec3 local;

  friend constexpr bool operator==(const Attachment&, const Attachment&) noexcept = default;
};

/// A long-range attachment (Kim et al., 2012): particle `particle` stays within `max` of particle
/// `anchor`, which is held in place (pinned, or attached to a body that does not move under the
/// particles). It only pulls: it keeps a chain of light particles hanging from a fixed point from
/// stretching however few passes the solver makes.
struct Tether {
  std::uint32_t particle = 0;
  std::uint32_t anchor = 0;
  Fixed max;
};

/// A soft body's tetrahedron: its corners, and six times its rest volume (the scalar triple
/// product (x1 - x0) . ((x2 - x0) x (x3 - x0)) at rest), which its volume constraint holds.
struct Tetrahedron {
  std::array<std::uint32_t, 4> corners{};
  Fixed rest_triple;
};

struct ParticleGroup {
  ParticleGroupId id{};
  ParticleGroupType type = ParticleGroupType::rope;
  std::variant<RopeDef, ClothDef, SoftBodyDef, FluidDef> def;

  // State: the particles, parallel arrays by index.
  std::vector<Vec3> positions;
  std::vector<Vec3> velocities;
  std::vector<Attachment> attachments;  ///< ascending particle
  std::vector<std::uint32_t> broken;    ///< indices into links, ascending
  Vec3 force;                           ///< N, spread over the particles; cleared by the step
  bool awake = true;
  Fixed sleep_time;
  /// A rope attached at both ends: the tether between the two bodies' attachment points (its
  /// velocity row's accumulated impulse, N s per solver sub-step), for the next step's warm start.
  Fixed tether_impulse;

  // Built from the definition (never saved).
  Fixed particle_mass;                  ///< kg, every particle's
  Fixed inverse_mass;                   ///< 1 / particle_mass
  Fixed radius;                         ///< m, for collisions
  std::vector<Link> links;              ///< ascending (a, b), by kind within a particle pair's
  std::vector<Tether> tethers;          ///< ascending particle
  std::vector<Tetrahedron> tetrahedra;  ///< a soft body's, by cube then Freudenthal order
  std::vector<bool> pinned;             ///< held in space (cloth's pinned without a body)
  std::vector<bool> link_broken;        ///< parallel to links, from `broken`
  // A fluid's kernel (fluid.hpp): its support H (two spacings), the kernel's sum over a particle
  // and its neighbours at rest (what a particle's density is divided by), and the relaxation
  // added to each density constraint's denominator (1/m^2).
  Fixed kernel_radius;
  Fixed kernel_rest_sum;
  Fixed kernel_relaxation;

  // Step scratch (not saved; stale between steps): the bodies whose boxes overlap the group's
  // (indices into WorldState::bodies, ascending), found by prepare_particles.
  std::vector<std::uint32_t> near_bodies;

  [[nodiscard]] const ParticleSettings& settings() const noexcept;
  [[nodiscard]] std::size_t size() const noexcept { return positions.size(); }
};

/// Checks a definition against the world (its bodies, the limits): "" when valid, else the
/// message naming the field. Without `bodies` (a restored group, whose attached bodies may have
/// been destroyed since it was created: its attachments say what holds), the attach fields are
/// not looked up.
[[nodiscard]] std::string check_rope_def(const WorldState& s, const RopeDef& def,
                                         bool bodies = true);
[[nodiscard]] std::string check_cloth_def(const WorldState& s, const ClothDef& def,
                                          bool bodies = true);
[[nodiscard]] std::string check_soft_body_def(const WorldState& s, const SoftBodyDef& def);
[[nodiscard]] std::string check_fluid_def(const FluidDef& def);

/// The particle count a valid definition makes.
[[nodiscard]] std::uint32_t particle_count(const RopeDef& def) noexcept;
[[nodiscard]] std::uint32_t particle_count(const ClothDef& def) noexcept;
/// A soft body's particle count depends on its shape's geometry (a hull's cells).
[[nodiscard]] std::uint32_t particle_count(const WorldState& s, const SoftBodyDef& def);
/// A fluid's: its particles along each axis, multiplied (0 for a definition that makes none, or
/// more than max_particles_per_group).
[[nodiscard]] std::uint32_t particle_count(const FluidDef& def) noexcept;

/// A new group of a valid definition: particles at rest where the definition lays them out,
/// attachments in the bodies' frames at their present poses, and the constraints.
[[nodiscard]] ParticleGroup make_group(const WorldState& s, ParticleGroupId id, const RopeDef& def);
[[nodiscard]] ParticleGroup make_group(const WorldState& s, ParticleGroupId id,
                                       const ClothDef& def);
[[nodiscard]] ParticleGroup make_group(const WorldState& s, ParticleGroupId id,
                                       const SoftBodyDef& def);
[[nodiscard]] ParticleGroup make_group(const WorldState& s, ParticleGroupId id,
                                       const FluidDef& def);

/// The particles' rest layout of a definition (where make_group puts them).
[[nodiscard]] std::vector<Vec3> rest_positions(const RopeDef& def);
[[nodiscard]] std::vector<Vec3> rest_positions(const ClothDef& def);
[[nodiscard]] std::vector<Vec3> rest_positions(const WorldState& s, const SoftBodyDef& def);
[[nodiscard]] std::vector<Vec3> rest_positions(const FluidDef& def);

/// Rebuilds what is derived from the definition and `broken` (mass, radius, links, tethers,
/// pins): what make_group and restore both do, so that a restored group steps exactly like the
/// one that was saved.
void build_group(const WorldState& s, ParticleGroup& g);

/// The group's statistics (World::particle_group_stats).
[[nodiscard]] ParticleGroupStats group_stats(const ParticleGroup& g);

/// Whether particle i is held still by the group itself (pinned in space).
[[nodiscard]] inline bool is_pinned(const ParticleGroup& g, std::uint32_t i) noexcept {
  return !g.pinned.empty() && g.pinned[i];
}

}  // namespace detsim::sim_detail
