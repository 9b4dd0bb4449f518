// The solver's view of the bodies for one step: their velocities as the sub-steps move them, and
// the per-body stages of the sub-step (integrate velocities, clamp speeds, integrate positions).
// Constraint kinds read and push these velocities through the row helpers (rows.hpp); they never
// touch a body's position, which only integrate_positions moves. Internal to detsim::sim.
//
// The velocities are one contiguous array parallel to WorldState::bodies (Box2D v3's body
// states): what a constraint gathers by index now, and what a wide row batch will gather lanes
// from later.
#pragma once

#include <cstddef>
#include <vector>

#include "../world_state.hpp"
#include "rows.hpp"

namespace detsim::sim_detail {

/// v, or v scaled down to length `limit` when it is longer (the bodies' speed limit, for the
/// particles' velocities too).
[[nodiscard]] Vec3 limit_speed(Vec3 v, Fixed limit);

/// Per-step solver data of every body, and the body stages of a sub-step.
struct SolverBodies {
  /// Loads every body's velocities and the step's constants (h = dt / substeps).
  explicit SolverBodies(WorldState& s);

  /// Whether an impulse can change body i's velocity (non-zero inverse mass or inertia).
  [[nodiscard]] bool takes_impulse(std::size_t i) const;
  /// Whether body i is still: no velocity, and none to come (integrate_velocities and
  /// clamp_speeds touch only awake dynamic bodies, impulses only bodies that take them).
  [[nodiscard]] bool still(std::size_t i) const;
  /// Bodies a and b of a constraint, with what the row helpers may skip for each.
  [[nodiscard]] BodyPair pair(std::size_t a, std::size_t b) const;

  /// Gravity, forces, torques, implicit damping and the speed limits, for one sub-step.
  void integrate_velocities();
  /// The speed limits, again: contact impulses (a crushed light body) can exceed what gravity
  /// could.
  void clamp_speeds();
  /// Positions and orientations by one sub-step (velocity plus push-out velocity), and the
  /// motion since the step began; the push-out velocities go back to zero.
  void integrate_positions();
  /// Writes the velocities back to the awake bodies (once, after the last sub-step).
  void store_velocities();

  WorldState& s;
  Fixed h;            ///< the sub-step, dt / substeps
  Fixed inv_h;        ///< substeps / dt
  Vec3 gravity_kick;  ///< gravity * h: the velocity change of a body without forces
  std::vector<Velocity> velocities;
  /// Overlap recovery's velocities for the current sub-step (split impulses): they move the
  /// positions apart in integrate_positions, limited to contact_push_max, and are then dropped,
  /// so pushing overlapping bodies apart never gives them kinetic energy.
  std::vector<Velocity> push;
  std::vector<Vec3> half_kick;  ///< half of this sub-step's velocity change from gravity and forces
  /// The body has contact points or solved joints this step (set by the contact and joint kinds'
  /// prepare): it moves by plain semi-implicit Euler.
  std::vector<bool> in_contact;
  /// The bodies the per-body stages visit, in ascending index (ID) order, so that a sleeping
  /// body costs them nothing: awake non-static ones (positions, stored velocities) and of those
  /// the dynamic ones (gravity, forces, speed limits).
  std::vector<std::uint32_t> solvable_bodies;
  std::vector<std::uint32_t> awake_dynamic_bodies;
};

}  // namespace detsim::sim_detail
