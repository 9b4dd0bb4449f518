// Rope tethers as a constraint kind (tether_solver.cpp), run after joints in every stage
// (solve.cpp). Internal to detsim::sim.
//
// A rope attached at both ends to bodies also holds those two bodies within its length, as one
// velocity row between its attachment points (a rope joint, Box2D's b2RopeJoint): the particles
// alone are far lighter than what hangs on them, and one pass per small step cannot carry a heavy
// body's weight through a chain of light particles (the mass ratio problem). The row only pulls;
// an inextensible rope's row is rigid, a rope with compliance c is a spring of stiffness 1 / c
// (critically damped) once taut, so that a tension T stretches it by T c, as the particles' links
// do.
#pragma once

#include <cstddef>
#include <vector>

#include "../world_state.hpp"
#include "bodies.hpp"
#include "constraint_kind.hpp"
#include "rows.hpp"

namespace detsim::sim_detail {

struct TetherConstraint {
  std::size_t group;  ///< index in WorldState::particle_groups
  BodyPair bodies;
  Vec3 local_a;  ///< the attachment points in each body's frame, from its origin
  Vec3 local_b;
  Vec3 anchor_a;  ///< from each body's centre of mass, world frame, at the present poses
  Vec3 anchor_b;
  Direction axial;
  Row row;
  Fixed length;      ///< the attachment points' present distance
  Fixed max_length;  ///< the rope's length
  Fixed impulse;     ///< accumulated, >= 0 (pulling together)
  bool spring;       ///< compliance > 0
  Softness spring_soft;
};

/// The rope tethers of the step, in ascending group ID.
class TetherSolver final : public ConstraintKind {
 public:
  TetherSolver(WorldState& s, SolverBodies& bodies);

  void prepare() override;
  void warm_start() override;
  void solve() override;
  void hold() override {}
  void push_out() override {}
  void positions_moved() override;
  void relax() override;
  void restitution() override {}
  void store_impulses() override;

 private:
  void update(TetherConstraint& k);
  void solve_all(bool use_bias);

  WorldState& s_;
  SolverBodies& bodies_;
  Softness soft_;
  std::vector<TetherConstraint> constraints_;
};

}  // namespace detsim::sim_detail
