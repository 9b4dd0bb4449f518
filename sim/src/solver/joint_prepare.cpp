// The joint kind's preparation (JointSolver::prepare, once a step) and its rows' geometry
// (update_geometry, after every sub-step's position update), and the reaction a joint's stored
// impulses stand for: what joint_solver.cpp's header describes, type by type.
#include <array>

#include <detsim/fixed/math.hpp>

#include "joint_rows.hpp"
#include "joint_solver.hpp"

namespace detsim::sim_detail {

using namespace joint_rows;

void JointSolver::prepare() {
  constraints_.clear();
  constraints_.reserve(s_.joints.size());
  for (std::size_t ji = 0; ji < s_.joints.size(); ++ji) {
    const JointState& j = s_.joints[ji];
    if (j.broken) continue;
    const std::size_t ia = s_.joint_bodies[ji][0];
    const std::size_t ib = s_.joint_bodies[ji][1];
    const BodyState& a = s_.bodies[ia];
    const BodyState& b = s_.bodies[ib];
    const bool dynamic_a = a.type == BodyType::dynamic && a.awake;
    const bool dynamic_b = b.type == BodyType::dynamic && b.awake;
    if (!dynamic_a && !dynamic_b) continue;
    JointConstraint& k = constraints_.emplace_back();
    k.joint = ji;
    k.bodies = bodies_.pair(ia, ib);
    k.type = j.def.type;
    const Derived& da = s_.derived[ia];
    const Derived& db = s_.derived[ib];
    for (std::size_t i = 0; i < 3; ++i)
      k.axes[i] = make_direction(da, db, axis(i));
    k.impulse = j.linear_impulse;
    k.min_length = j.def.min_length;
    k.max_length = j.def.max_length;
    if (k.max_length == Fixed::zero()) {  // both zero: the distance at creation, rigid
      k.min_length = j.length;
      k.max_length = j.length;
    }
    // axial_impulse is a rod's (or spring's) impulse, or a range's lower end's minus its upper
    // end's (only one end can carry load).
    const bool range = k.min_length < k.max_length;
    const bool distance = k.type == JointType::distance;
    k.rigid_impulse = distance && !range ? j.axial_impulse : Fixed::zero();
    k.lower_impulse = distance && range ? max(j.axial_impulse, Fixed::zero()) : Fixed::zero();
    k.upper_impulse = distance && range ? max(-j.axial_impulse, Fixed::zero()) : Fixed::zero();
    // A rod with spring_frequency > 0 is a spring of that rest length (a spring on a range, with
    // its own rest length, is not supported yet).
    k.spring = k.type == JointType::distance && k.min_length == k.max_length &&
               j.def.spring_frequency > Fixed::zero();
    if (k.spring)
      k.spring_soft = make_soft(j.def.spring_frequency, j.def.spring_damping_ratio, bodies_.h);
  }
  // The trees first (they need only the bodies and types): a joint whose point block a tree
  // solves needs no inverse of its own block (update_geometry).
  trees_.find(constraints_, s_.bodies.size());
  for (std::size_t c = 0; c < constraints_.size(); ++c) {
    JointConstraint& k = constraints_[c];
    const JointState& j = s_.joints[k.joint];
    if (k.type == JointType::fixed || k.type == JointType::slider) prepare_weld(k);
    update_geometry(k, trees_.holds(c));
    // Angular impulses are kept as a world vector. A fixed joint's rows are the world axes: the
    // vector is its impulse. A hinge's rows turn with body a: last step's impulse is projected
    // onto this step's.
    k.weld_impulse = j.angular_impulse;
    if (k.type == JointType::slider) {  // its linear rows turn with body a too
      k.slide_impulse_1 = dot(j.linear_impulse, k.across[0]);
      k.slide_impulse_2 = dot(j.linear_impulse, k.across[1]);
    }
    if (k.type == JointType::swing_twist && j.def.limit_enabled) {
      k.lower_limit_impulse = max(j.limit_impulse, Fixed::zero());
      k.upper_limit_impulse = max(-j.limit_impulse, Fixed::zero());
      k.swing_impulse = j.axial_impulse;
    }
    if (k.type == JointType::hinge) {
      k.angular_impulse_1 = dot(j.angular_impulse, k.across[0]);
      k.angular_impulse_2 = dot(j.angular_impulse, k.across[1]);
    }
    if (k.type == JointType::hinge || k.type == JointType::slider) {
      // The motor's warm start within its present force (set_joint_motor may have lowered it).
      const Fixed most = j.def.motor_max_force * bodies_.h;
      k.motor_impulse = j.def.motor_enabled ? clamp(j.motor_impulse, -most, most) : Fixed::zero();
      k.lower_limit_impulse =
          j.def.limit_enabled ? max(j.limit_impulse, Fixed::zero()) : Fixed::zero();
      k.upper_limit_impulse =
          j.def.limit_enabled ? max(-j.limit_impulse, Fixed::zero()) : Fixed::zero();
    }
    // Bodies held by a joint move by plain semi-implicit Euler, like bodies in contact
    // (bodies.hpp): the trapezoidal step of free flight would sink a hanging body by half a
    // gravity kick per sub-step, for the spring to hold up again. A slack rope (no end of its
    // range reached at the step's start) holds nothing: its bodies fly freely.
    const bool slack = k.type == JointType::distance && k.min_length < k.max_length &&
                       k.length > k.min_length + s_.def.linear_slop &&
                       k.length < k.max_length - s_.def.linear_slop;
    if (!slack) {
      bodies_.in_contact[k.bodies.a] = true;
      bodies_.in_contact[k.bodies.b] = true;
    }
  }
  trees_.update_couplings(constraints_, s_);
}

// The weld's three angular rows about world x, y, z and their block's inverse: K = I_a^-1 +
// I_b^-1 (world), from the rows as for the point block. The rows' directions are fixed and the
// world inverse inertia is the step's start's, so they are the same at every sub-step: built once
// per step.
void JointSolver::prepare_weld(JointConstraint& k) {
  const Derived& da = s_.derived[k.bodies.a];
  const Derived& db = s_.derived[k.bodies.b];
  for (std::size_t i = 0; i < 3; ++i)
    k.weld_rows[i] = angular_row(da, db, axis(i));
  Mat3 K;
  for (std::size_t i = 0; i < 3; ++i) {
    Fixed entries[3];
    for (std::size_t c = 0; c < 3; ++c) {
      const Row& ri = k.weld_rows[i];
      const Row& rc = k.weld_rows[c];
      entries[c] =
          DotSum{}.add(ri.angular_a, rc.response_a).add(ri.angular_b, rc.response_b).result();
    }
    K.rows[i] = {entries[0], entries[1], entries[2]};
  }
  k.weld_mass = inverse(immobile_rows_unit(K));
}

// The anchors, the rows and the position error at the bodies' present poses. `held`: a tree
// solves the joint's point block, so the block's own inverse is needed only for the rows solved
// with the point rows held (twist, swing).
void JointSolver::update_geometry(JointConstraint& k, bool held) {
  const JointState& j = s_.joints[k.joint];
  const BodyState& a = s_.bodies[k.bodies.a];
  const BodyState& b = s_.bodies[k.bodies.b];
  const Derived& da = s_.derived[k.bodies.a];
  const Derived& db = s_.derived[k.bodies.b];
  // The anchors relative to each body's centre of mass (the lever arms); local anchors are kept
  // relative to the origin, which is the centre for every primitive (x - 0 = x exactly).
  k.anchor_a = rotate(a.orientation, j.local_anchor_a - a.center_of_mass);
  k.anchor_b = rotate(b.orientation, j.local_anchor_b - b.center_of_mass);
  const Vec3 separation = (db.center + k.anchor_b) - (da.center + k.anchor_a);
  // The twist (hinge motor and limit, swing-twist's twist range) and the swing (swing-twist's
  // cone) at the present poses.
  const bool twists =
      (k.type == JointType::hinge && (j.def.motor_enabled || j.def.limit_enabled)) ||
      (k.type == JointType::swing_twist && j.def.limit_enabled);
  if (twists) {
    k.axis_a = rotate(a.orientation, j.local_axis_a);
    k.axis_b = rotate(b.orientation, j.local_axis_b);
    // A swing-twist's twist turns about the direction half-way between the two axes: the twist
    // angle below changes at w . (a + b) / (1 + a . b), w the relative angular velocity (the
    // swing, about a x b, is across both). Along axis_a alone, the row was off by half the swing
    // angle, and under random torques the twist passed its end by 0.028 rad at a 0.6 rad swing.
    // A hinge's axes stay together: axis_a is that direction.
    const Vec3 twist_axis =
        k.type == JointType::swing_twist ? normalize_or(k.axis_a + k.axis_b, k.axis_a) : k.axis_a;
    k.twist_row = angular_row(da, db, twist_axis);
    // The rotation from b's pose at creation relative to a to its present one, about axis_a:
    // twice the angle of the error quaternion's part along the axis (the shorter way round).
    const Quat e = b.orientation * conjugate(a.orientation * j.relative_orientation);
    const Fixed along = dot(e.vector(), k.axis_a);
    k.angle = e.w < Fixed::zero() ? atan2(-along, -e.w) * Fixed::from_int(2)
                                  : atan2(along, e.w) * Fixed::from_int(2);
  }
  if (k.type == JointType::swing_twist && j.def.limit_enabled) {
    const Vec3 parting = cross(k.axis_a, k.axis_b);
    k.swing_angle = atan2(length(parting), dot(k.axis_a, k.axis_b));
    k.swing_row = angular_row(da, db, normalize_or(parting, perpendicular(k.axis_a)));
  }
  if (k.type == JointType::hinge) {
    k.axis_a = rotate(a.orientation, j.local_axis_a);
    k.axis_b = rotate(b.orientation, j.local_axis_b);
    k.across[0] = perpendicular(k.axis_a);
    k.across[1] = cross(k.axis_a, k.across[0]);
    Fixed entries[2][2];
    for (std::size_t i = 0; i < 2; ++i)
      k.angular_rows[i] = angular_row(da, db, k.across[i]);
    for (std::size_t i = 0; i < 2; ++i) {
      for (std::size_t c = 0; c < 2; ++c) {
        const Row& ri = k.angular_rows[i];
        const Row& rc = k.angular_rows[c];
        entries[i][c] =
            DotSum{}.add(ri.angular_a, rc.response_a).add(ri.angular_b, rc.response_b).result();
      }
    }
    // The 2x2 block inverted as the upper left of a 3x3 with a unit third row and column: each
    // entry the exact cofactor over the exact determinant (try_inverse), however small K is.
    const Mat3 K{{Vec3{entries[0][0], entries[0][1], Fixed::zero()},
                  Vec3{entries[1][0], entries[1][1], Fixed::zero()},
                  Vec3{Fixed::zero(), Fixed::zero(), Fixed::one()}}};
    k.angular_mass = inverse(immobile_rows_unit(K));
    const Vec3 misalignment = cross(k.axis_a, k.axis_b);
    k.angular_error_1 = dot(misalignment, k.across[0]);
    k.angular_error_2 = dot(misalignment, k.across[1]);
  }
  if (k.type == JointType::slider) {
    k.axis_a = rotate(a.orientation, j.local_axis_a);
    k.across[0] = perpendicular(k.axis_a);
    k.across[1] = cross(k.axis_a, k.across[0]);
    // Box2D's prismatic rows: at body a, the arm reaches b's anchor (anchor_a + separation).
    const Vec3 arm_a = k.anchor_a + separation;
    for (std::size_t i = 0; i < 2; ++i) {
      k.slide_directions[i] = make_direction(da, db, k.across[i]);
      k.slide_rows[i] = block_row(da, db, arm_a, k.anchor_b, k.across[i]);
    }
    Fixed entries[2][2];
    for (std::size_t i = 0; i < 2; ++i) {
      for (std::size_t c = 0; c < 2; ++c) {
        const Row& ri = k.slide_rows[i];
        const Row& rc = k.slide_rows[c];
        entries[i][c] = DotSum{}
                            .add(k.slide_directions[i].linear_a, k.slide_directions[c].response_a)
                            .add(k.slide_directions[i].linear_b, k.slide_directions[c].response_b)
                            .add(ri.angular_a, rc.response_a)
                            .add(ri.angular_b, rc.response_b)
                            .result();
      }
    }
    k.slide_mass = inverse_2x2(entries[0][0], entries[0][1], entries[1][1]);
    k.slide_error_1 = dot(separation, k.across[0]);
    k.slide_error_2 = dot(separation, k.across[1]);
    if (j.def.motor_enabled || j.def.limit_enabled) {
      k.axial = make_direction(da, db, k.axis_a);
      k.axial_row = make_row(da, db, arm_a, k.anchor_b, k.axis_a);
      k.translation = dot(separation, k.axis_a);
    }
  }
  if (k.type == JointType::fixed || k.type == JointType::slider) {
    // The weld's rows and block: prepare_weld, once per step. The rotation from where b should be
    // (q_a times the relative orientation at creation) to where it is, q_b conj(q_a q_rel), as a
    // small-angle vector 2 vec(q) (the shorter way round).
    const Quat e = b.orientation * conjugate(a.orientation * j.relative_orientation);
    const Vec3 v = e.vector() * Fixed::from_int(2);
    k.weld_error = e.w < Fixed::zero() ? -v : v;
  }
  if (k.type == JointType::ball || k.type == JointType::hinge || k.type == JointType::fixed ||
      k.type == JointType::swing_twist) {
    k.separation = separation;
    for (std::size_t i = 0; i < 3; ++i)
      k.rows[i] = block_row(da, db, k.anchor_a, k.anchor_b, axis(i));
    // K_ij = (m_a^-1 + m_b^-1) d_i . d_j + angular_i . response_j on each side; the directions
    // are the world axes, so the linear part is diagonal (a locked axis's share zero).
    const std::array<Fixed, 3> linear_shares{linear_share(da, axis(0)) + linear_share(db, axis(0)),
                                             linear_share(da, axis(1)) + linear_share(db, axis(1)),
                                             linear_share(da, axis(2)) + linear_share(db, axis(2))};
    Mat3 K;
    for (std::size_t i = 0; i < 3; ++i) {
      Fixed entries[3];
      for (std::size_t c = 0; c < 3; ++c) {
        const Row& ri = k.rows[i];
        const Row& rc = k.rows[c];
        entries[c] =
            DotSum{}.add(ri.angular_a, rc.response_a).add(ri.angular_b, rc.response_b).result();
        if (c == i) entries[c] += linear_shares[i];
      }
      K.rows[i] = {entries[0], entries[1], entries[2]};
    }
    k.point_k = immobile_rows_unit(K);
    const bool swings = k.type == JointType::swing_twist && j.def.limit_enabled;
    // K is positive definite: one body is dynamic. A tree's joint without twist or swing rows
    // never reads its inverse.
    if (!held || twists || swings) k.point_mass = inverse(k.point_k);
    // An angular row's coupling to the point rows, b_i = J_point_i M^-1 J_row^T (the row has no
    // linear part), as K^-1 b, and the row's effective mass with the point rows held,
    // 1 / (c - b . K^-1 b).
    const auto hold_point = [&](const Row& t, Vec3& compensation, Fixed& mass) {
      Vec3 coupling;
      Fixed* entries[3] = {&coupling.x, &coupling.y, &coupling.z};
      for (std::size_t i = 0; i < 3; ++i)
        *entries[i] = DotSum{}
                          .add(k.rows[i].angular_a, t.response_a)
                          .add(k.rows[i].angular_b, t.response_b)
                          .result();
      compensation = k.point_mass * coupling;
      const Fixed own =
          DotSum{}.add(t.angular_a, t.response_a).add(t.angular_b, t.response_b).result();
      mass = inverse_or_zero(own - dot(coupling, compensation));
    };
    if (twists) hold_point(k.twist_row, k.twist_coupling, k.twist_mass);
    if (swings) hold_point(k.swing_row, k.swing_coupling, k.swing_mass);
    return;
  }
  if (k.type != JointType::distance) return;  // a slider: done above
  // Distance: along the anchors' direction (any fixed one when they coincide).
  k.length = length(separation);
  const Vec3 d = normalize_or(separation, Vec3{Fixed::zero(), Fixed::one(), Fixed::zero()});
  k.axial = make_direction(da, db, d);
  k.axial_row = make_row(da, db, k.anchor_a, k.anchor_b, d);
}

// The reaction from the stored impulses: each row's impulse along (or about) its direction, at
// the bodies' present poses (the directions that turn with body a are where the last sub-step's
// rows had them), times the sub-step rate. The rows' signs: a positive impulse pushes body b
// along the row's direction (rows.hpp), so each impulse is the push on b.
JointReaction joint_reaction_of(const WorldState& s, const JointState& j) {
  if (j.broken) return {};
  const BodyState& a = s.bodies[static_cast<std::size_t>(s.find(j.def.body_a.value))];
  const BodyState& b = s.bodies[static_cast<std::size_t>(s.find(j.def.body_b.value))];
  const Vec3 axis_a = rotate(a.orientation, j.local_axis_a);
  Vec3 linear = j.linear_impulse;
  Vec3 angular;
  switch (j.def.type) {
    case JointType::ball:
      break;
    case JointType::hinge:
      angular = j.angular_impulse + axis_a * (j.motor_impulse + j.limit_impulse);
      break;
    case JointType::slider:
      linear = linear + axis_a * (j.motor_impulse + j.limit_impulse);
      angular = j.angular_impulse;
      break;
    case JointType::fixed:
      angular = j.angular_impulse;
      break;
    case JointType::distance: {
      const Vec3 separation = (b.position + rotate(b.orientation, j.local_anchor_b)) -
                              (a.position + rotate(a.orientation, j.local_anchor_a));
      linear = normalize_or(separation, Vec3{Fixed::zero(), Fixed::one(), Fixed::zero()}) *
               j.axial_impulse;
      break;
    }
    case JointType::swing_twist: {
      // The twist limit about the axes' half-way direction; the cone's row about the direction
      // the axes part in, its impulse applied negated (solve_swing_limit).
      const Vec3 axis_b = rotate(b.orientation, j.local_axis_b);
      const Vec3 parting = normalize_or(cross(axis_a, axis_b), perpendicular(axis_a));
      angular = normalize_or(axis_a + axis_b, axis_a) * j.limit_impulse - parting * j.axial_impulse;
      break;
    }
  }
  const Fixed substeps = Fixed::from_int(static_cast<std::int32_t>(s.def.substeps));
  const Fixed rate = substeps / s.def.dt;  // SolverBodies::inv_h
  return {linear * rate, angular * rate};
}

}  // namespace detsim::sim_detail
