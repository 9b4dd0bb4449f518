// Joints as a constraint kind (joint_prepare.cpp, joint_solver.cpp), run after contacts in every
// stage (solve.cpp). All six joint types (docs/SIM.md, "Joints": what each holds, and what is not
// done yet). Internal to detsim::sim.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include <detsim/fixed/mat3.hpp>

#include "../world_state.hpp"
#include "bodies.hpp"
#include "constraint_kind.hpp"
#include "joint_tree.hpp"
#include "rows.hpp"

namespace detsim::sim_detail {

/// One joint's constraint for the step.
struct JointConstraint {
  std::size_t joint;  ///< index in WorldState::joints
  BodyPair bodies;
  JointType type;
  Vec3 anchor_a;  ///< the anchor relative to body a's centre, world frame, at the present pose
  Vec3 anchor_b;
  /// Ball: the anchors' separation (b's minus a's), world frame, at the present poses.
  Vec3 separation;
  /// Ball: the point rows along world x, y and z (directions fixed for the step, rows at the
  /// present anchors).
  std::array<Direction, 3> axes;
  std::array<Row, 3> rows;
  /// Ball: K^-1, the inverse of the point constraint's 3x3 effective mass matrix
  /// K_ij = J_i M^-1 J_j^T at the present anchors.
  Mat3 point_mass;
  Mat3 point_k;  ///< K itself (the diagonal block of a tree of joints, joint_tree.cpp)
  Vec3 impulse;  ///< ball, hinge: accumulated along x, y, z
  // Hinge: two angular rows about the directions perpendicular to body a's axis, at the present
  // poses, solved as one 2x2 block.
  Vec3 axis_a;                 ///< the hinge axis as body a carries it, world frame
  Vec3 axis_b;                 ///< as body b carries it
  std::array<Vec3, 2> across;  ///< unit, perpendicular to axis_a and to each other
  std::array<Row, 2> angular_rows;
  Mat3 angular_mass;      ///< the 2x2 block's inverse (upper left; the rest is the identity)
  Fixed angular_error_1;  ///< (axis_a x axis_b) . across: the small angle between the axes
  Fixed angular_error_2;
  Fixed angular_impulse_1;
  Fixed angular_impulse_2;
  // Hinge motor and limit: one row about axis_a.
  Row twist_row;
  /// The twist row with the point rows held: point impulses -twist_coupling per unit of twist
  /// impulse keep the anchors' relative velocity as it was, and twist_mass is the effective mass
  /// of the pair, 1 / (c - b . K^-1 b) (the Schur complement of the point block).
  Vec3 twist_coupling;
  Fixed twist_mass;
  Fixed angle;  ///< b's rotation about axis_a since creation, radians in [-pi, pi]
  Fixed motor_impulse;
  Fixed lower_limit_impulse;  ///< >= 0
  Fixed upper_limit_impulse;  ///< >= 0
  // Swing-twist: the cone limit, one row about axis_a x axis_b (the direction the axes part in),
  // with the point rows held like the twist row.
  Row swing_row;
  Vec3 swing_coupling;
  Fixed swing_mass;
  Fixed swing_angle;    ///< between axis_a and axis_b, radians in [0, pi]
  Fixed swing_impulse;  ///< >= 0
  // Fixed: three angular rows about world x, y, z, solved as one 3x3 block.
  std::array<Row, 3> weld_rows;
  Mat3 weld_mass;     ///< K^-1 of the three angular rows
  Vec3 weld_error;    ///< the small rotation from where body b should be to where it is, world
  Vec3 weld_impulse;  ///< accumulated about x, y, z
  // Slider: two linear rows across the axis (as body a carries it), from body a's centre to body
  // b's anchor, solved as one 2x2 block; its rotation is held by the fixed joint's rows.
  std::array<Direction, 2> slide_directions;
  std::array<Row, 2> slide_rows;
  Mat3 slide_mass;      ///< the 2x2 block's inverse (upper left; the rest is the identity)
  Fixed slide_error_1;  ///< the anchors' separation across the axis
  Fixed slide_error_2;
  Fixed slide_impulse_1;
  Fixed slide_impulse_2;
  // Distance: one row along the anchors' direction, at the present poses. Slider with a motor or
  // a limit: one row along its axis (as body a carries it), at the slide rows' anchors.
  Direction axial;
  Row axial_row;
  Fixed translation;  ///< slider: b's anchor from a's along the axis, m (0 at creation)
  Fixed length;       ///< the anchors' present distance
  Fixed min_length;   ///< the range held; equal ends: a rigid rod
  Fixed max_length;
  Fixed lower_impulse;  ///< pushing apart (length >= min_length), >= 0
  Fixed upper_impulse;  ///< pulling together (length <= max_length), >= 0
  Fixed rigid_impulse;  ///< a rigid rod's (or a spring's), either sign
  bool spring;          ///< a rod with spring_frequency > 0: a spring of its length
  Softness spring_soft;
  // Breakable joints: the sum over the step's sub-steps of the load each carried (the reaction of
  // its accumulated impulses at the sub-step's end), for the mean that breaking compares.
  Vec3 force_sum;
  Vec3 torque_sum;
};

/// The joints of the step, in ascending joint ID.
class JointSolver final : public ConstraintKind {
 public:
  JointSolver(WorldState& s, SolverBodies& bodies);

  void prepare() override;
  void warm_start() override;
  void solve() override;
  void hold() override;
  void push_out() override;
  void positions_moved() override;
  void relax() override;
  void restitution() override;
  void store_impulses() override;

 private:
  void prepare_weld(JointConstraint& k);
  void update_geometry(JointConstraint& k, bool held);
  void solve_joints(bool use_bias);
  void solve_ball(JointConstraint& k, bool use_bias);
  /// The rows a joint of a tree solves before (hinge axes, weld) and after (motor, limits) the
  /// tree's point blocks.
  void solve_before_point(JointConstraint& k, bool use_bias);
  void solve_after_point(JointConstraint& k, bool use_bias);
  void solve_hinge_axes(JointConstraint& k, bool use_bias);
  void solve_hinge_motor(JointConstraint& k);
  void solve_hinge_limit(JointConstraint& k, bool use_bias);
  /// The impulse of one end of a range this pass (accumulated updated, clamped to push only).
  Fixed one_sided_impulse(Fixed c, Fixed cdot, Fixed mass, bool use_bias, Fixed& accumulated) const;
  void apply_twist(JointConstraint& k, Fixed impulse);
  void apply_held(JointConstraint& k, const Row& row, Vec3 coupling, Fixed impulse);
  void solve_swing_limit(JointConstraint& k, bool use_bias);
  void solve_weld(JointConstraint& k, bool use_bias);
  void solve_slide(JointConstraint& k, bool use_bias);
  void solve_slide_motor(JointConstraint& k);
  void solve_slide_limit(JointConstraint& k, bool use_bias);
  void solve_distance(JointConstraint& k, bool use_bias);
  /// The reaction of k's accumulated impulses, at the bodies' present poses.
  [[nodiscard]] JointReaction reaction(const JointConstraint& k) const;

  WorldState& s_;
  SolverBodies& bodies_;
  Softness soft_;
  std::vector<JointConstraint> constraints_;
  JointTrees trees_;
};

}  // namespace detsim::sim_detail
