// What the solver's stages ask of each kind of constraint (contacts now; joints, wheel contacts
// and particle couplings later). Internal to detsim::sim.
//
// A kind owns its constraints for the step, in ascending ID order, and runs all of them in each
// call: one virtual call per kind per stage, never per row, so the per-row work stays inlined
// inside the kind's own loops. That loop is also where a kind will switch to wide rows (a batch of
// 4 or 8 constraints from a deterministic graph colouring, solved lane by lane) without the
// stage list in solve.cpp changing.
#pragma once

namespace detsim::sim_detail {

/// One kind of constraint, as the sub-step stages (solve.cpp) call it. Every function handles
/// all of the kind's constraints, in ascending ID order, and reads and pushes velocities only
/// through SolverBodies and the row helpers (rows.hpp).
class ConstraintKind {
 public:
  ConstraintKind() = default;
  ConstraintKind(const ConstraintKind&) = delete;
  ConstraintKind& operator=(const ConstraintKind&) = delete;
  virtual ~ConstraintKind() = default;

  /// Once per step, before the first sub-step: rows, effective masses and accumulated impulses
  /// (from the warm-start cache) for the step's constraints.
  virtual void prepare() = 0;
  /// Once per sub-step: applies the accumulated impulses.
  virtual void warm_start() = 0;
  /// `iterations` times per sub-step: one pass over the velocity constraints.
  virtual void solve() = 0;
  /// Once per sub-step, after solve: the hard limits of the kind's constraints (a contact's end
  /// of range), enforced from the ground up with the body nearer the ground held still (shock
  /// propagation), so that a heavy body cannot drive a light one past them while the
  /// accumulated impulses catch up.
  virtual void hold() = 0;
  /// `iterations` times per sub-step, after hold: one pass of position error recovery on the
  /// push-out velocities (SolverBodies::push), which move positions and are never kept.
  virtual void push_out() = 0;
  /// Once per sub-step, after the bodies moved: updates what depends on their positions (a
  /// contact's separations).
  virtual void positions_moved() = 0;
  /// `iterations` times per sub-step, after the positions moved: one more pass over the velocity
  /// constraints, at the new positions.
  virtual void relax() = 0;
  /// Once per sub-step, after relaxing: restitution (bounces).
  virtual void restitution() = 0;
  /// Once per step, after the last sub-step: the accumulated impulses into the warm-start cache.
  virtual void store_impulses() = 0;
};

}  // namespace detsim::sim_detail
