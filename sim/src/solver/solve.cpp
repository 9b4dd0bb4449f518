// The solver: a fixed list of stages, run once per sub-step ("soft step", Catto, Box2D v3, 2024;
// docs/SIM.md, stage 5 of the step).
//
// Per step, each constraint kind prepares its rows (prepare). Then, for each of `substeps`
// sub-steps of length h = dt / substeps: integrate velocities (gravity, forces, damping, speed
// clamp) -> warm start (apply the accumulated impulses) -> solve (soft constraints with a
// position bias, `iterations` passes) -> hold (hard limits, from the ground up) -> push out
// (overlap beyond a constraint's soft range, on push-out velocities that move positions and are
// then dropped, `iterations` passes) -> clamp speeds -> integrate positions (velocity plus push-out
// velocity; each kind then updates what depends on positions: a contact's separations) -> relax
// (the same constraints without bias, `iterations` passes, removing the velocity the bias added) ->
// restitution (contacts that took their first impulse in this sub-step bounce, once per step, so a
// bouncing body moves away for the rest of the step instead of resting on the surface until the
// step ends) -> clamp speeds. Once per step, after the last sub-step, each kind stores its impulses
// for the next step's warm start, and the velocities go back to the bodies.
//
// The body stages (SolverBodies, bodies.hpp) run every body in ascending ID order; the constraint
// stages run every kind in a fixed order (the `kinds` list below), each kind all of its
// constraints in ascending ID order, through the ConstraintKind interface (constraint_kind.hpp).
// Contacts are the first kind, joints (joint_solver.cpp) the second, rope tethers
// (tether_solver.cpp) the third: each pass solves every contact, then every joint (Box2D v3's stage
// list prepares joints before contacts; here they come after, so that a world without joints gives
// the bits it gave before joints existed; the order is part of the results, and fixed now that it
// is chosen). Particle groups (particles/xpbd.cpp) are stepped after the bodies' positions move in
// each sub-step, in small steps of their own, and pass what they push on bodies to the bodies'
// velocities before the kinds see the new positions. Vehicles' wheels (wheel_solver.cpp) are the
// fourth kind. Wide
// (SIMD) rows do not change this file: a kind's stage function will loop over batches of
// constraints (4 or 8 side by side, from a deterministic graph colouring, each lane giving the
// scalar path's bits) instead of one constraint at a time; the stage order and the kind order stay
// as they are here.
#include <array>
#include <cstdint>

#include "../particles/xpbd.hpp"
#include "../world_state.hpp"
#include "bodies.hpp"
#include "constraint_kind.hpp"
#include "contact_solver.hpp"
#include "joint_solver.hpp"
#include "tether_solver.hpp"
#include "wheel_solver.hpp"

namespace detsim::sim_detail {

namespace {

using Kinds = std::array<ConstraintKind*, 4>;

// One stage of every kind, in kind order.
void each_kind(const Kinds& kinds, void (ConstraintKind::*stage)()) {
  for (ConstraintKind* kind : kinds)
    (kind->*stage)();
}

// The iterated stages (solve, relax): each pass runs every kind before the next pass begins.
void each_kind(const Kinds& kinds, void (ConstraintKind::*stage)(), std::uint32_t passes) {
  for (std::uint32_t i = 0; i < passes; ++i)
    each_kind(kinds, stage);
}

}  // namespace

void solve(WorldState& s) {
  SolverBodies bodies(s);
  ContactSolver contacts(s, bodies);
  JointSolver joints(s, bodies);
  TetherSolver tethers(s, bodies);
  WheelSolver wheels(s, bodies);
  ParticleStepper particles(s, bodies);
  // The kind order: part of the results.
  const Kinds kinds{&contacts, &joints, &tethers, &wheels};
  const std::uint32_t iterations = s.def.iterations;

  each_kind(kinds, &ConstraintKind::prepare);
  particles.prepare();
  for (std::uint32_t sub = 0; sub < s.def.substeps; ++sub) {
    bodies.integrate_velocities();
    each_kind(kinds, &ConstraintKind::warm_start);
    each_kind(kinds, &ConstraintKind::solve, iterations);
    each_kind(kinds, &ConstraintKind::hold);
    each_kind(kinds, &ConstraintKind::push_out, iterations);
    bodies.clamp_speeds();
    bodies.integrate_positions();
    particles.substep();
    each_kind(kinds, &ConstraintKind::positions_moved);
    each_kind(kinds, &ConstraintKind::relax, iterations);
    each_kind(kinds, &ConstraintKind::restitution);
    bodies.clamp_speeds();
  }
  each_kind(kinds, &ConstraintKind::store_impulses);
  bodies.store_velocities();
}

}  // namespace detsim::sim_detail
