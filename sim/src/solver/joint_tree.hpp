// The point blocks of the joints that form trees, solved exactly in one pass (joint_tree.cpp).
// Internal to detsim::sim.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <detsim/fixed/mat3.hpp>

#include "../world_state.hpp"
#include "bodies.hpp"
#include "rows.hpp"

namespace detsim::sim_detail {

struct JointConstraint;

/// The trees of point blocks among a step's joint constraints: joints with a point block (ball,
/// hinge, fixed, swing-twist) whose graph over the bodies that take impulses (static, kinematic
/// bodies cut it) has no cycle, two or more joints to a tree. Found once per step (find), solved
/// in every solve and relax pass (solve).
class JointTrees {
 public:
  /// Finds the trees among `constraints` (ascending joint ID), from the lowest body index of
  /// each, joints in ascending index at each body.
  void find(const std::vector<JointConstraint>& constraints, std::size_t body_count);
  /// Whether constraint c's point block is solved by a tree (not by its own block).
  [[nodiscard]] bool holds(std::size_t c) const { return !held_.empty() && held_[c]; }
  [[nodiscard]] bool empty() const { return nodes_.empty(); }
  /// A's blocks between joints on one body, from the joints' present rows: after every change of
  /// the rows (prepare, positions_moved), before solve. The solve pass and the relax pass at the
  /// same rows share them; each kind of pass factorizes the system once per change of the rows
  /// (with iterations > 1, the later passes of a sub-step reuse it).
  void update_couplings(const std::vector<JointConstraint>& constraints, const WorldState& s);
  /// Solves every tree's point blocks at once: (J M^-1 J^T + D) lambda = rhs, exactly (within
  /// rounding), and applies the impulses. With `soft`, each joint's block is its soft
  /// constraint (D_j = (1 / mass_scale - 1) K_j, rhs_j = -(J_j v + bias_rate C_j) -
  /// impulse_scale / mass_scale K_j lambda_j): the fixed point of the joints' soft blocks solved
  /// one after another until they agree. Without, rigid: D = 0, rhs = -J v.
  void solve(std::vector<JointConstraint>& constraints, SolverBodies& bodies, const Softness* soft);

 private:
  /// A joint of a tree, in elimination order (leaves first).
  struct Node {
    std::size_t constraint;
    std::size_t body;           ///< the body it shares with the nodes after it (toward the root)
    bool body_is_a;             ///< body is the constraint's body a
    std::uint32_t links_begin;  ///< its later neighbours: links_[links_begin, links_end)
    std::uint32_t links_end;
    Mat3 pivot;  ///< its diagonal block, then that block less the eliminated nodes' part (factor)
    Vec3 rhs;
    Vec3 lambda;
  };
  /// A later neighbour of a node (a joint on the same body, eliminated after it).
  struct Link {
    std::uint32_t node;
    Mat3 coupling;  ///< A_jk = J_j,body M^-1 J_k,body^T (update_couplings)
    Mat3 block;     ///< A_jk less the eliminated nodes' part (factor)
  };
  /// An LDL^T factorization of the trees' system: per node its pivot's inverse, per link
  /// pivot_j^-1 A_jk (less the eliminated nodes' part).
  struct Factor {
    std::vector<Mat3> inverse;
    std::vector<Mat3> gain;
    bool valid = false;
  };
  void factor(const std::vector<JointConstraint>& constraints, const Softness* soft, Factor& f);

  std::vector<bool> held_;  ///< per constraint
  std::vector<Node> nodes_;
  std::vector<Link> links_;
  Factor soft_factor_;   ///< (A + D): the solve passes', at the present rows
  Factor rigid_factor_;  ///< A: the relax passes', at the present rows
};

}  // namespace detsim::sim_detail
