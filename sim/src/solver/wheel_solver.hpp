// Vehicles' wheels as a constraint kind (wheel_solver.cpp), run after rope tethers in every stage
// (solve.cpp). Internal to detsim::sim.
//
// Per step (prepare), each wheel of each vehicle whose chassis is awake casts a sphere of its
// radius down its suspension and, on the ground, gets three rows at the contact point between the
// chassis and the ground body: the suspension along the contact normal, and the tire along and
// across the wheel (in the contact plane). Per sub-step (warm_start) the engine turns the driven
// wheels, and the suspension pushes: spring and damper, an explicit force k x + c dx/dt on a
// compression integrated from the contact's relative velocity at each sub-step's end
// (restitution, the last stage), plus the anti-roll bars. The
// iterations (solve, relax) then solve the tire rows and the brakes: the longitudinal row couples
// the chassis with the wheel's spin (the rim's speed against the ground's), each row bounded by the
// tire curve's grip times the wheel's load for the sub-step; a brake holds the wheel's spin with
// at most its torque. Impulses are not carried between steps: a wheel's load changes with every
// sub-step, and its bounds with it.
#pragma once

#include <cstddef>
#include <vector>

#include "../world_state.hpp"
#include "bodies.hpp"
#include "constraint_kind.hpp"
#include "rows.hpp"

namespace detsim::sim_detail {

/// One wheel of a vehicle being solved this step.
struct WheelConstraint {
  std::size_t vehicle;  ///< index in WorldState::vehicles
  std::size_t wheel;    ///< index in its def.wheels
  bool contact = false;
  BodyPair bodies{};  ///< the chassis (a) and the ground (b); b == a without contact
  Direction up;       ///< along -normal: a positive impulse pushes the chassis out of the ground
  Row up_row;
  Direction along;  ///< the wheel's forward direction in the contact plane
  Row along_row;
  Direction across;  ///< the wheel's left in the contact plane
  Row across_row;
  Fixed along_mass;   ///< 1 / (1 / along_row.mass + r^2 / inertia): the chassis and the spin
  Fixed compression;  ///< m, integrated through the sub-steps
  Fixed rate;         ///< m/s, the compression's at the end of the last sub-step
  Fixed load;         ///< N, the suspension's force in this sub-step
  Fixed grip_along;   ///< the tire's grip per unit load, along and across
  Fixed grip_across;
  Fixed along_impulse;  ///< accumulated in this sub-step
  Fixed across_impulse;
  Fixed brake_impulse;
  Fixed brake_torque;  ///< N m
  Fixed inertia;       ///< kg m^2: the wheel's, and the engine's share when driven
  Fixed slip_ratio;
  Fixed slip_angle;
};

/// The wheels of the step's awake vehicles, in ascending vehicle ID, each vehicle's in order.
class WheelSolver final : public ConstraintKind {
 public:
  WheelSolver(WorldState& s, SolverBodies& bodies);

  void prepare() override;
  void warm_start() override;
  void solve() override;
  void hold() override {}
  void push_out() override {}
  void positions_moved() override {}
  void relax() override;
  void restitution() override;
  void store_impulses() override;

 private:
  void prepare_wheel(WheelConstraint& k, std::size_t chassis);
  void solve_all();
  void solve_tire(WheelConstraint& k, const WheelDef& w, Fixed& spin);
  /// How fast the suspension compresses now: the contact's relative velocity along the normal.
  [[nodiscard]] Fixed compression_rate(const WheelConstraint& k) const;

  WorldState& s_;
  SolverBodies& bodies_;
  std::vector<WheelConstraint> wheels_;
};

}  // namespace detsim::sim_detail
