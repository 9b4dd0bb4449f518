// Joints, the second constraint kind (after contacts, solve.cpp): soft point constraints of the
// sub-stepped solver, as Box2D v3 solves its joints, in 3D (docs/SIM.md, "Joints": each type,
// the choices made and what is not done yet).
//
// Unlike a contact, whose anchors stay fixed for the step, a joint's anchors turn with its bodies:
// after every sub-step's position update (positions_moved) the anchors are rotated from each
// body's frame by its present orientation, the rows are rebuilt at them, and the position error
// is measured from the present poses. The rows' directions (world x, y, z for a ball joint) and
// the world inverse inertia stay those of the step's start.
//
// A ball joint is three point rows, along world x, y and z, solved together as one block: the
// impulse is -K^-1 (J v + bias) with K the rows' 3x3 effective mass matrix (Box2D's and Jolt's
// point constraint). Solved one after another instead (Gauss-Seidel within the joint), the rows
// fight: for a small body on a long arm, an impulse across the arm mostly spins the body, which
// moves the anchor along the other rows, and a 2 m pendulum of a 0.1 m sphere then lost 18 % of
// its amplitude in ten swings and ran 1.5 % slow. The rows are warm started with last step's
// impulses. In solve, the block is a soft constraint (a damped spring of joint_hertz and
// joint_damping_ratio on the anchors' separation, Box2D v3's joint softness); in relax, a rigid
// one without bias, which removes the velocity the spring added.
//
// The point blocks of joints that form a tree (JointTrees, joint_tree.cpp) are solved together,
// exactly, in each solve and relax pass, between their joints' rows that come before the point
// block (hinge axes, weld) and those after it (motor, limits): Gauss-Seidel passed a load one
// joint per pass, and a heavy body on a light chain flailed with one iteration.
//
// A hinge joint is a ball joint plus two angular rows about the directions across its axis (as
// body a carries it), solved as one 2x2 block before the point block (Jolt's hinge: rotation,
// then point), soft in the same way. Their error is the small angle between the axis as each
// body carries it, (axis_a x axis_b) across each direction. Rotation about the axis is free.
//
// A hinge's motor and limit are rows about its axis ("twist"), applied with the point rows held
// (apply_held), after the point block: the motor, without bias and clamped to its torque, then
// the limit, one-sided at each end. (Box2D solves its motor first, before the point: here the
// point block, soft and with a tiny effective mass across an arm whose body is small, then
// spins the body about its own centre and has the last word; a motor at speed 0 holding a 1 m
// arm with 1.25 times the torque its weight needs let it sink 0.4 rad in 2 s. Solved after it,
// the motor holds the arm, its point rows held, to the point spring's 5 mm sag.)
//
// A swing-twist joint is a ball joint plus, with limit_enabled, the hinge's twist limit about its
// axis and a cone limit (the angle between the axis as each body carries it, at most
// swing_limit) about the direction the axes part in, both after the point block and with the
// point rows held.
//
// A fixed joint is a ball joint plus three angular rows about world x, y and z holding body b's
// orientation relative to body a at creation, solved as a 3x3 block before the point block. The
// error is the small-angle vector of the rotation from where b should be to where it is.
//
// A slider is the fixed joint's three angular rows plus two linear rows across its axis (as body
// a carries it), from body a's centre to body b's anchor (Box2D's prismatic rows), solved as a
// 2x2 block after the angular block. Translation along the axis is free, unless a motor (first)
// or a limit (last) acts on it: one row along the axis at the same anchors, like the hinge's
// twist row but linear.
//
// A distance joint is one row along the anchors' direction. With min_length == max_length it is a
// rigid rod (soft as above, either sign), or with spring_frequency > 0 a spring of that rest
// length; otherwise each end of the range is a one-sided row: the lower pushes (length >=
// min_length), the upper pulls (length <= max_length), a rope being the upper alone (slack below
// max_length). An end not reached is speculative: it lets the bodies close the gap within the
// sub-step, no further.
#include "joint_solver.hpp"

#include <array>

#include <detsim/fixed/math.hpp>

#include "joint_rows.hpp"

namespace detsim::sim_detail {

using namespace joint_rows;

namespace {

using namespace detsim::literals;

// The joint spring: 60 Hz, damping ratio 2 (Box2D v3's joint softness: stiff, overdamped), at
// most a quarter of the sub-step rate, beyond which the implicit discretisation stops damping it.
constexpr Fixed joint_hertz = Fixed::from_int(60);
constexpr Fixed joint_damping_ratio = Fixed::from_int(2);

}  // namespace

JointSolver::JointSolver(WorldState& s, SolverBodies& bodies) : s_(s), bodies_(bodies) {
  soft_ = make_soft(min(joint_hertz, bodies.inv_h >> 2), joint_damping_ratio, bodies.h);
}

// prepare(), prepare_weld() and update_geometry() are in joint_prepare.cpp.

void JointSolver::warm_start() {
  for (JointConstraint& k : constraints_) {
    // An end of a range (a hinge limit, a rope's length) that the bodies have come away from
    // carries no load: re-applying its old impulse (an impact's, most often) would throw the
    // bodies back a second time, as the contact kind's warm start says of points that separated.
    // A hinge whose limit stopped a 3 m/s swing rebounded at 5 m/s before this rule.
    if ((k.type == JointType::hinge || k.type == JointType::swing_twist) &&
        s_.joints[k.joint].def.limit_enabled) {
      const JointDef& def = s_.joints[k.joint].def;
      Fixed dropped;  // the twist impulse dropped, whose point compensation goes with it
      if (k.angle > def.limit_lower) {
        dropped += k.lower_limit_impulse;
        k.lower_limit_impulse = Fixed::zero();
      }
      if (k.angle < def.limit_upper) {
        dropped -= k.upper_limit_impulse;
        k.upper_limit_impulse = Fixed::zero();
      }
      k.impulse += k.twist_coupling * dropped;
      if (k.type == JointType::swing_twist && k.swing_angle < def.swing_limit) {
        k.impulse -= k.swing_coupling * k.swing_impulse;  // its impulse was -swing_impulse
        k.swing_impulse = Fixed::zero();
      }
    }
    if (k.type == JointType::distance && k.min_length < k.max_length) {
      if (k.length > k.min_length) k.lower_impulse = Fixed::zero();
      if (k.length < k.max_length) k.upper_impulse = Fixed::zero();
    }
    if (k.type == JointType::hinge) {
      apply_impulses(bodies_.velocities, k.bodies, no_direction, k.angular_rows[0],
                     k.angular_impulse_1, no_direction, k.angular_rows[1], k.angular_impulse_2);
      const Fixed twist = k.motor_impulse + k.lower_limit_impulse - k.upper_limit_impulse;
      if (twist != Fixed::zero())
        apply_impulse(bodies_.velocities, k.bodies, no_direction, k.twist_row, twist);
    }
    if (k.type == JointType::fixed || k.type == JointType::slider) {
      const std::array<Direction, 3> none{};
      apply_impulses(bodies_.velocities, k.bodies, none, k.weld_rows, k.weld_impulse);
    }
    if (k.type == JointType::slider) {
      apply_impulses(bodies_.velocities, k.bodies, k.slide_directions[0], k.slide_rows[0],
                     k.slide_impulse_1, k.slide_directions[1], k.slide_rows[1], k.slide_impulse_2);
      const JointDef& def = s_.joints[k.joint].def;
      if (def.limit_enabled) {  // the hinge's rule: an end the bodies left carries no load
        if (k.translation > def.limit_lower) k.lower_limit_impulse = Fixed::zero();
        if (k.translation < def.limit_upper) k.upper_limit_impulse = Fixed::zero();
      }
      const Fixed along = k.motor_impulse + k.lower_limit_impulse - k.upper_limit_impulse;
      apply_impulse(bodies_.velocities, k.bodies, k.axial, k.axial_row, along);
      continue;
    }
    if (k.type == JointType::swing_twist && s_.joints[k.joint].def.limit_enabled) {
      const Fixed twist = k.lower_limit_impulse - k.upper_limit_impulse;
      if (twist != Fixed::zero())
        apply_impulse(bodies_.velocities, k.bodies, no_direction, k.twist_row, twist);
      if (k.swing_impulse != Fixed::zero())
        apply_impulse(bodies_.velocities, k.bodies, no_direction, k.swing_row, -k.swing_impulse);
    }
    if (k.type == JointType::ball || k.type == JointType::hinge || k.type == JointType::fixed ||
        k.type == JointType::swing_twist) {
      apply_impulses(bodies_.velocities, k.bodies, k.axes, k.rows, k.impulse);
      continue;
    }
    const Fixed axial = k.rigid_impulse + k.lower_impulse - k.upper_impulse;
    apply_impulse(bodies_.velocities, k.bodies, k.axial, k.axial_row, axial);
  }
}

inline void JointSolver::solve_ball(JointConstraint& k, bool use_bias) {
  const Vec3 cdot{row_speed(bodies_.velocities, k.bodies, k.axes[0], k.rows[0]),
                  row_speed(bodies_.velocities, k.bodies, k.axes[1], k.rows[1]),
                  row_speed(bodies_.velocities, k.bodies, k.axes[2], k.rows[2])};
  const Vec3 impulse =
      use_bias ? -(k.point_mass * (cdot + k.separation * soft_.bias_rate)) * soft_.mass_scale -
                     k.impulse * soft_.impulse_scale
               : -(k.point_mass * cdot);
  k.impulse += impulse;
  apply_impulses(bodies_.velocities, k.bodies, k.axes, k.rows, impulse);
}

// The hinge's two angular rows as one block: -K^-1 (J w + bias), soft like the point rows.
inline void JointSolver::solve_hinge_axes(JointConstraint& k, bool use_bias) {
  const Vec3 cdot{row_speed(bodies_.velocities, k.bodies, no_direction, k.angular_rows[0]),
                  row_speed(bodies_.velocities, k.bodies, no_direction, k.angular_rows[1]),
                  Fixed::zero()};
  const Vec3 accumulated{k.angular_impulse_1, k.angular_impulse_2, Fixed::zero()};
  const Vec3 error{k.angular_error_1, k.angular_error_2, Fixed::zero()};
  const Vec3 impulse =
      use_bias ? -(k.angular_mass * (cdot + error * soft_.bias_rate)) * soft_.mass_scale -
                     accumulated * soft_.impulse_scale
               : -(k.angular_mass * cdot);
  k.angular_impulse_1 += impulse.x;
  k.angular_impulse_2 += impulse.y;
  apply_impulses(bodies_.velocities, k.bodies, no_direction, k.angular_rows[0], impulse.x,
                 no_direction, k.angular_rows[1], impulse.y);
}

// An impulse about the hinge's axis together with the point impulses that keep the anchors'
// relative velocity as it was (booked to the point rows' accumulated impulses, so that the warm
// start carries them too). Alone, an impulse about the axis on a body at the end of an arm
// mostly spins the body about its own centre, which the point rows then undo: a limit on a 2 m
// pendulum let it swing 2.5 times past its end.
void JointSolver::apply_held(JointConstraint& k, const Row& row, Vec3 coupling, Fixed impulse) {
  if (impulse == Fixed::zero()) return;
  const Vec3 point = -(coupling * impulse);
  k.impulse += point;
  apply_impulses(bodies_.velocities, k.bodies, k.axes, k.rows, point);
  apply_impulse(bodies_.velocities, k.bodies, no_direction, row, impulse);
}

void JointSolver::apply_twist(JointConstraint& k, Fixed impulse) {
  apply_held(k, k.twist_row, k.twist_coupling, impulse);
}

// One end of a range (a limit's end, a distance joint's), with c >= 0 held and cdot the speed
// away from the end: speculative while apart (c > 0), soft at the end while biased, rigid in relax;
// the accumulated impulse pushes only. Returns the impulse to apply now.
Fixed JointSolver::one_sided_impulse(Fixed c, Fixed cdot, Fixed mass, bool use_bias,
                                     Fixed& accumulated) const {
  Fixed impulse;
  if (c > Fixed::zero()) {
    impulse = -mass * (cdot + c * bodies_.inv_h);
  } else if (use_bias) {
    impulse =
        -mass * soft_.mass_scale * (cdot + soft_.bias_rate * c) - soft_.impulse_scale * accumulated;
  } else {
    impulse = -mass * cdot;
  }
  const Fixed next = max(accumulated + impulse, Fixed::zero());
  impulse = next - accumulated;
  accumulated = next;
  return impulse;
}

// Swing-twist's cone: the angle between the axes at most swing_limit, one-sided like the hinge
// limit's ends, about the direction the axes part in.
inline void JointSolver::solve_swing_limit(JointConstraint& k, bool use_bias) {
  const JointDef& def = s_.joints[k.joint].def;
  const Fixed c = def.swing_limit - k.swing_angle;
  const Fixed cdot = -row_speed(bodies_.velocities, k.bodies, no_direction, k.swing_row);
  const Fixed impulse = one_sided_impulse(c, cdot, k.swing_mass, use_bias, k.swing_impulse);
  apply_held(k, k.swing_row, k.swing_coupling, -impulse);
}

// The hinge motor: drives the relative speed about the axis to motor_speed with at most
// motor_max_force (a torque, N m) over each sub-step (Box2D v3's revolute motor).
inline void JointSolver::solve_hinge_motor(JointConstraint& k) {
  const JointDef& def = s_.joints[k.joint].def;
  const Fixed speed = row_speed(bodies_.velocities, k.bodies, no_direction, k.twist_row);
  const Fixed max_impulse = def.motor_max_force * bodies_.h;
  const Fixed next =
      clamp(k.motor_impulse - k.twist_mass * (speed - def.motor_speed), -max_impulse, max_impulse);
  const Fixed impulse = next - k.motor_impulse;
  k.motor_impulse = next;
  apply_twist(k, impulse);
}

// The hinge limit: each end a one-sided row about the axis, as the distance joint's range
// (speculative while apart from the end, soft at it while biased, rigid in relax). Solved with
// the other rows, not yet held in hold() from the ground up.
inline void JointSolver::solve_hinge_limit(JointConstraint& k, bool use_bias) {
  const JointDef& def = s_.joints[k.joint].def;
  const Row& row = k.twist_row;
  const Fixed mass = k.twist_mass;
  const auto one_sided = [&](Fixed c, Fixed sign, Fixed& accumulated) {
    const Fixed cdot = sign * row_speed(bodies_.velocities, k.bodies, no_direction, row);
    const Fixed impulse = one_sided_impulse(c, cdot, mass, use_bias, accumulated);
    apply_twist(k, sign * impulse);
  };
  one_sided(k.angle - def.limit_lower, Fixed::one(), k.lower_limit_impulse);
  one_sided(def.limit_upper - k.angle, -Fixed::one(), k.upper_limit_impulse);
}

// The fixed joint's three angular rows as one block, soft like the point rows.
inline void JointSolver::solve_weld(JointConstraint& k, bool use_bias) {
  const Vec3 cdot{row_speed(bodies_.velocities, k.bodies, no_direction, k.weld_rows[0]),
                  row_speed(bodies_.velocities, k.bodies, no_direction, k.weld_rows[1]),
                  row_speed(bodies_.velocities, k.bodies, no_direction, k.weld_rows[2])};
  const Vec3 impulse =
      use_bias ? -(k.weld_mass * (cdot + k.weld_error * soft_.bias_rate)) * soft_.mass_scale -
                     k.weld_impulse * soft_.impulse_scale
               : -(k.weld_mass * cdot);
  k.weld_impulse += impulse;
  const std::array<Direction, 3> none{};
  apply_impulses(bodies_.velocities, k.bodies, none, k.weld_rows, impulse);
}

// The slider's two rows across its axis as one block, soft like the point rows.
inline void JointSolver::solve_slide(JointConstraint& k, bool use_bias) {
  const Vec3 cdot{row_speed(bodies_.velocities, k.bodies, k.slide_directions[0], k.slide_rows[0]),
                  row_speed(bodies_.velocities, k.bodies, k.slide_directions[1], k.slide_rows[1]),
                  Fixed::zero()};
  const Vec3 accumulated{k.slide_impulse_1, k.slide_impulse_2, Fixed::zero()};
  const Vec3 error{k.slide_error_1, k.slide_error_2, Fixed::zero()};
  const Vec3 impulse = use_bias
                           ? -(k.slide_mass * (cdot + error * soft_.bias_rate)) * soft_.mass_scale -
                                 accumulated * soft_.impulse_scale
                           : -(k.slide_mass * cdot);
  k.slide_impulse_1 += impulse.x;
  k.slide_impulse_2 += impulse.y;
  apply_impulses(bodies_.velocities, k.bodies, k.slide_directions[0], k.slide_rows[0], impulse.x,
                 k.slide_directions[1], k.slide_rows[1], impulse.y);
}

// The slider motor: drives the speed along the axis to motor_speed with at most motor_max_force
// (N) over each sub-step, as the hinge motor does about its axis.
inline void JointSolver::solve_slide_motor(JointConstraint& k) {
  const JointDef& def = s_.joints[k.joint].def;
  const Fixed speed = row_speed(bodies_.velocities, k.bodies, k.axial, k.axial_row);
  const Fixed max_impulse = def.motor_max_force * bodies_.h;
  const Fixed next = clamp(k.motor_impulse - k.axial_row.mass * (speed - def.motor_speed),
                           -max_impulse, max_impulse);
  const Fixed impulse = next - k.motor_impulse;
  k.motor_impulse = next;
  apply_impulse(bodies_.velocities, k.bodies, k.axial, k.axial_row, impulse);
}

// The slider limit: each end of limit_lower..limit_upper (m along the axis) a one-sided row, as
// the hinge limit's ends (speculative while apart, soft at the end while biased, rigid in relax).
inline void JointSolver::solve_slide_limit(JointConstraint& k, bool use_bias) {
  const JointDef& def = s_.joints[k.joint].def;
  const Row& row = k.axial_row;
  const auto one_sided = [&](Fixed c, Fixed sign, Fixed& accumulated) {
    const Fixed cdot = sign * row_speed(bodies_.velocities, k.bodies, k.axial, row);
    const Fixed impulse = one_sided_impulse(c, cdot, row.mass, use_bias, accumulated);
    apply_impulse(bodies_.velocities, k.bodies, k.axial, row, sign * impulse);
  };
  one_sided(k.translation - def.limit_lower, Fixed::one(), k.lower_limit_impulse);
  one_sided(def.limit_upper - k.translation, -Fixed::one(), k.upper_limit_impulse);
}

inline void JointSolver::solve_distance(JointConstraint& k, bool use_bias) {
  const Row& row = k.axial_row;
  const Fixed mass = row.mass;
  if (k.min_length == k.max_length) {
    const Fixed cdot = row_speed(bodies_.velocities, k.bodies, k.axial, row);
    const Fixed c = k.length - k.min_length;
    // A spring (spring_frequency > 0) is the same row with the spring's own softness, in solve
    // and relax alike: its give is the physics, not an error for relax to remove (Box2D v3's
    // distance spring).
    const Softness& soft = k.spring ? k.spring_soft : soft_;
    const Fixed impulse = use_bias || k.spring
                              ? -mass * soft.mass_scale * (cdot + soft.bias_rate * c) -
                                    soft.impulse_scale * k.rigid_impulse
                              : -mass * cdot;
    k.rigid_impulse += impulse;
    apply_impulse(bodies_.velocities, k.bodies, k.axial, row, impulse);
    return;
  }
  // One end of the range: c >= 0 is held, speed along `sign` * the row. Apart from the end
  // (c > 0) the row is speculative, else soft while biased, rigid in relax.
  const auto one_sided = [&](Fixed c, Fixed sign, Fixed& accumulated) {
    const Fixed cdot = sign * row_speed(bodies_.velocities, k.bodies, k.axial, row);
    const Fixed impulse = one_sided_impulse(c, cdot, mass, use_bias, accumulated);
    apply_impulse(bodies_.velocities, k.bodies, k.axial, row, sign * impulse);
  };
  if (k.min_length > Fixed::zero())
    one_sided(k.length - k.min_length, Fixed::one(), k.lower_impulse);
  one_sided(k.max_length - k.length, -Fixed::one(), k.upper_impulse);
}

void JointSolver::solve_before_point(JointConstraint& k, bool use_bias) {
  if (k.type == JointType::hinge) solve_hinge_axes(k, use_bias);
  if (k.type == JointType::fixed) solve_weld(k, use_bias);
}

void JointSolver::solve_after_point(JointConstraint& k, bool use_bias) {
  const JointDef& def = s_.joints[k.joint].def;
  if (k.type == JointType::hinge) {
    if (def.motor_enabled) solve_hinge_motor(k);
    if (def.limit_enabled) solve_hinge_limit(k, use_bias);
  } else if (k.type == JointType::swing_twist && def.limit_enabled) {
    solve_hinge_limit(k, use_bias);
    solve_swing_limit(k, use_bias);
  }
}

// A pass: each joint in ascending ID, except that the point blocks of the joints in trees are
// solved together, exactly (joint_tree.cpp), after every joint's rows that come before its point
// block and before those that come after it.
void JointSolver::solve_joints(bool use_bias) {
  for (std::size_t c = 0; c < constraints_.size(); ++c) {
    JointConstraint& k = constraints_[c];
    if (trees_.holds(c)) {
      solve_before_point(k, use_bias);
      continue;
    }
    if (k.type == JointType::hinge) {
      const JointDef& def = s_.joints[k.joint].def;
      solve_hinge_axes(k, use_bias);
      solve_ball(k, use_bias);
      if (def.motor_enabled) solve_hinge_motor(k);
      if (def.limit_enabled) solve_hinge_limit(k, use_bias);
    } else if (k.type == JointType::slider) {
      const JointDef& def = s_.joints[k.joint].def;
      if (def.motor_enabled) solve_slide_motor(k);
      solve_weld(k, use_bias);
      solve_slide(k, use_bias);
      if (def.limit_enabled) solve_slide_limit(k, use_bias);
    } else if (k.type == JointType::fixed) {
      solve_weld(k, use_bias);
      solve_ball(k, use_bias);
    } else if (k.type == JointType::swing_twist) {
      solve_ball(k, use_bias);
      if (s_.joints[k.joint].def.limit_enabled) {
        solve_hinge_limit(k, use_bias);
        solve_swing_limit(k, use_bias);
      }
    } else if (k.type == JointType::ball) {
      solve_ball(k, use_bias);
    } else {
      solve_distance(k, use_bias);
    }
  }
  if (trees_.empty()) return;
  trees_.solve(constraints_, bodies_, use_bias ? &soft_ : nullptr);
  for (std::size_t c = 0; c < constraints_.size(); ++c) {
    if (trees_.holds(c)) solve_after_point(constraints_[c], use_bias);
  }
}

void JointSolver::solve() {
  solve_joints(true);
}

// Not yet: the limits (hinge, slider, swing-twist) are soft rows in solve and relax, not held here
// from the ground up like the contact kind's end of range (docs/SIM.md, "Joints", "Not yet").
void JointSolver::hold() {}

// Not yet: position error beyond the spring's range (a chain stretched by a huge load) will be
// recovered here on the push-out velocities, like the contact kind's overlap.
void JointSolver::push_out() {}

void JointSolver::positions_moved() {
  for (std::size_t c = 0; c < constraints_.size(); ++c)
    update_geometry(constraints_[c], trees_.holds(c));
  trees_.update_couplings(constraints_, s_);
}

void JointSolver::relax() {
  solve_joints(false);
}

// Joints do not bounce. This is the sub-step's last stage: a breakable joint adds up the load it
// carried in the sub-step, for store_impulses to compare the step's mean with its limits.
void JointSolver::restitution() {
  for (JointConstraint& k : constraints_) {
    const JointDef& def = s_.joints[k.joint].def;
    if (def.break_force == Fixed::zero() && def.break_torque == Fixed::zero()) continue;
    const JointReaction r = reaction(k);
    k.force_sum += r.force;
    k.torque_sum += r.torque;
  }
}

namespace {

// A constraint's accumulated impulses as the joint keeps them (world vectors where its rows turn
// with body a; a range's two ends as one signed impulse).
void store(const JointConstraint& k, JointState& j) {
  j.linear_impulse = k.impulse;
  if (k.type == JointType::hinge)
    j.angular_impulse = k.across[0] * k.angular_impulse_1 + k.across[1] * k.angular_impulse_2;
  if (k.type == JointType::fixed || k.type == JointType::slider) j.angular_impulse = k.weld_impulse;
  if (k.type == JointType::slider)
    j.linear_impulse = k.across[0] * k.slide_impulse_1 + k.across[1] * k.slide_impulse_2;
  if (k.type == JointType::hinge || k.type == JointType::swing_twist ||
      k.type == JointType::slider) {
    j.motor_impulse = k.motor_impulse;
    j.limit_impulse = k.lower_limit_impulse - k.upper_limit_impulse;
  }
  j.axial_impulse = k.type == JointType::swing_twist
                        ? k.swing_impulse
                        : k.rigid_impulse + k.lower_impulse - k.upper_impulse;
}

}  // namespace

JointReaction JointSolver::reaction(const JointConstraint& k) const {
  JointState j = s_.joints[k.joint];
  store(k, j);
  return joint_reaction_of(s_, j);
}

// Breaking: the accumulated impulses act once per sub-step (warm start, then each pass's
// correction), so the force a joint carries in a sub-step is its impulse times the sub-step rate
// (Box2D v3's constraint force, joint_reaction_of). Breaking compares the mean of the step's
// sub-steps with break_force and break_torque: the last sub-step's alone overshoots when a load
// comes on suddenly (a beam welded at rest under gravity: 27 % above m g in its first step, as
// the soft joint stops the sag it let through), while the mean is the step's momentum balance.
// Beyond either, the joint breaks at the end of the step, reported as a joint event in ascending
// joint ID: it stays in the list with `broken` set, and is no longer solved, nor joins its
// bodies' islands, nor keeps them from colliding.
void JointSolver::store_impulses() {
  const Fixed substeps = Fixed::from_int(static_cast<std::int32_t>(s_.def.substeps));
  for (const JointConstraint& k : constraints_) {
    JointState& j = s_.joints[k.joint];
    store(k, j);
    if (j.def.break_force == Fixed::zero() && j.def.break_torque == Fixed::zero()) continue;
    const JointReaction mean{k.force_sum / substeps, k.torque_sum / substeps};
    if ((j.def.break_force > Fixed::zero() && length(mean.force) > j.def.break_force) ||
        (j.def.break_torque > Fixed::zero() && length(mean.torque) > j.def.break_torque)) {
      j.broken = true;
      s_.joint_events.push_back(
          {JointEvent::Kind::broke, j.id, j.def.body_a, j.def.body_b, j.def.user_data, mean});
    }
  }
}

}  // namespace detsim::sim_detail
