// Position-based fluids (Macklin and Mueller, "Position Based Fluids", 2013) in fixed point: the
// neighbour search, the density constraint and XSPH viscosity of a fluid group (xpbd.cpp steps
// them; docs/PARTICLES.md, "Fluids"). Internal to detsim::sim.
//
// The kernel is W(q) = (1 - q)^3 for q = r / H < 1 (the shape of Mueller's "spiky" kernel, whose
// gradient does not vanish as two particles meet), H two spacings, used for the density and its
// gradient alike, so that every correction is the exact gradient step of the constraint it
// solves. A particle's density
// is 1 + the sum of W over its neighbours, divided by that sum on the rest lattice
// (kernel_rest_sum): 1 at rest, inside the fluid, on every machine, with no pi and no H^9 to keep
// in range. A wall adds the density of the lattice continued beyond it (WallKernel).
//
// Neighbours: a hashed grid of cells of the search reach, filled by a counting sort in ascending
// particle order; a particle's 27 cells name at most 27 buckets, taken once each in ascending
// order, and the pairs (i < j) within reach come out in ascending i, bucket, j. Each particle
// keeps at most kMaxFluidNeighbours pairs with higher particles (a fluid crushed into a point must
// not need n^2 memory); found once per solver sub-step with a skin of a quarter spacing.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/vec3.hpp>

namespace detsim::sim_detail {

struct ParticleGroup;

/// The most pairs a particle makes with higher-indexed particles (a lattice at rest makes 13
/// within two spacings; a fluid compressed to half its volume about 26).
inline constexpr std::uint32_t kMaxFluidNeighbours = 128;

/// A body's surface near a fluid particle, as a plane (world frame): the fluid continues beyond it
/// as if the lattice went on (a wall neither pulls the fluid nor lets it pack against it).
struct FluidWall {
  Vec3 normal;             ///< out of the body
  Vec3 point;              ///< on its surface
  std::uint32_t body = 0;  ///< index into WorldState::bodies
  /// What the wall's share of the density constraints moved its particle by, summed over the
  /// sub-step's small steps (m): the body takes the opposite push (two-way: buoyancy, pressure).
  Vec3 moved;
  Vec3 gradient;  ///< scratch: the wall's density gradient at the particle, this small step
};

/// The density the fluid beyond a wall adds to a particle at t spacings from it, t in [0, 2],
/// and its derivative in t, tabulated at t = k / 32 (build_fluid_kernel fills it once).
struct WallKernel {
  static constexpr std::int32_t steps_per_spacing = 32;
  std::vector<Fixed> value;
  std::vector<Fixed> slope;
};

/// A fluid group's working arrays (scratch: never saved, rebuilt from positions).
struct FluidScratch {
  // The grid.
  std::vector<std::uint32_t> bucket_of;     ///< per particle
  std::vector<std::uint32_t> bucket_start;  ///< per bucket, and one past the last
  std::vector<std::uint32_t> by_bucket;     ///< particle indices, bucket by bucket, ascending
  // The pairs within reach.
  std::vector<std::uint32_t> pair_a;
  std::vector<std::uint32_t> pair_b;
  /// The density pass's scratch: the gradient at one particle of each of its neighbour entries.
  std::vector<Vec3> gradient;
  // Per particle.
  std::vector<Fixed> density;  ///< 1 + the sum of W over the neighbours (the statistics only)
  std::vector<Vec3> delta;
  // Each particle's neighbours (both ways), particle by particle.
  std::vector<std::uint32_t> neighbour_start;
  std::vector<std::uint32_t> neighbours;
  std::vector<Fixed> entry_weight;  ///< per neighbour entry: W from the last density pass
  // Each particle's walls, particle by particle.
  std::vector<std::uint32_t> wall_start;
  std::vector<FluidWall> walls;
  std::vector<bool> buried;  ///< per particle: its centre is behind one of its walls
};

/// The kernel's constants for a fluid of `spacing`: sets g.kernel_radius, kernel_rest_sum and
/// kernel_relaxation (from the lattice of the rest layout).
void build_fluid_kernel(ParticleGroup& g, Fixed spacing);

/// The wall kernel's table (shared by every fluid: it is in units of the spacing).
[[nodiscard]] const WallKernel& wall_kernel();

/// Finds the pairs of `positions` closer than `reach` (into sc.pair_a / pair_b).
void find_fluid_pairs(std::span<const Vec3> positions, Fixed reach, FluidScratch& sc);

/// Each particle's neighbours from the pairs.
void build_fluid_neighbours(std::size_t n, FluidScratch& sc);

/// One Gauss-Seidel pass of the density constraints, in ascending particle order (the velocities
/// are the small step's predicted ones): moves the particles; what a particle moves beyond its own
/// motion in the small step (|v| h) plus `push_step` moves its `previous` position too (a
/// correction of position that does not become velocity).
void solve_fluid_density(ParticleGroup& g, FluidScratch& sc, std::span<Vec3> previous, Fixed h,
                         Fixed push_step);

/// XSPH viscosity: each particle's velocity moves `viscosity` of the way towards its neighbours'
/// kernel-weighted mean (with the weights the last density pass found), symmetrically, so that
/// momentum is kept.
void apply_fluid_viscosity(ParticleGroup& g, FluidScratch& sc, Fixed viscosity);

/// Every particle's density over the rest density (World::particle_group_stats), from a fresh
/// neighbour search.
[[nodiscard]] std::vector<Fixed> fluid_densities(const ParticleGroup& g);

}  // namespace detsim::sim_detail
