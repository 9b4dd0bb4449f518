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

namespace detsim::sim_detail {

namespace {

using namespace detsim::literals;

// The joint spring: 60 Hz, damping ratio 2 (Box2D v3's joint softness: stiff, overdamped), at
// most a quarter of the sub-step rate, beyond which the implicit discretisation stops damping it.
constexpr Fixed joint_hertz = Fixed::from_int(60);
constexpr Fixed joint_damping_ratio = Fixed::from_int(2);

Vec3 axis(std::size_t i) {
  Vec3 v;
  if (i == 0) v.x = Fixed::one();
  if (i == 1) v.y = Fixed::one();
  if (i == 2) v.z = Fixed::one();
  return v;
}

// A unit vector perpendicular to the unit vector n, chosen by n's components only (the contact
// kind's, contact_solver.cpp).
Vec3 perpendicular(Vec3 n) {
  const Fixed threshold = Fixed::from_raw(2479700525);  // 0.57735 ~ 1/sqrt(3)
  if (abs(n.x) >= threshold) return normalize(Vec3{n.y, -n.x, Fixed::zero()});
  return normalize(Vec3{Fixed::zero(), n.z, -n.y});
}

// The row of a relative rotation about the unit vector u: J = (0, -u, 0, u). Its linear parts
// are a zero Direction. Its own effective mass is left zero: every angular row is solved in a
// block (hinge axes, weld) or with the point rows held (twist, swing), whose masses are computed
// beside it.
Row angular_row(const Derived& a, const Derived& b, Vec3 u) {
  Row r;
  r.angular_a = -u;
  r.angular_b = u;
  r.response_a = a.inverse_inertia_world * r.angular_a;
  r.response_b = b.inverse_inertia_world * r.angular_b;
  return r;
}

// make_row without the row's own effective mass (left zero), for rows solved in a block (the
// point rows, the slider's rows across its axis): the division and the sum it needs are skipped.
Row block_row(const Derived& a, const Derived& b, Vec3 ra, Vec3 rb, Vec3 d) {
  Row r;
  r.angular_a = cross(d, ra);
  r.angular_b = cross(rb, d);
  r.response_a = a.inverse_inertia_world * r.angular_a;
  r.response_b = b.inverse_inertia_world * r.angular_b;
  return r;
}

const Direction no_direction{};

// A block whose bodies cannot move along one of its rows (a locked axis: BodyDef::lock_translation
// or lock_rotation) has a zero diagonal entry there, and since the block is positive semi-definite
// its whole row and column are zero: no impulse along it can do anything. A unit diagonal entry
// there leaves the other rows' inverse as it was and makes the block invertible (its own impulse
// then moves nothing). A block without such a row is returned as it is, bit for bit.
Mat3 immobile_rows_unit(Mat3 K) {
  if (K.rows[0].x == Fixed::zero()) K.rows[0].x = Fixed::one();
  if (K.rows[1].y == Fixed::zero()) K.rows[1].y = Fixed::one();
  if (K.rows[2].z == Fixed::zero()) K.rows[2].z = Fixed::one();
  return K;
}

// The inverse of the symmetric 2x2 block [[k11, k12], [k12, k22]], as the upper left of a 3x3
// with a unit third row and column: each entry the exact cofactor over the exact determinant
// (try_inverse), however small the block is.
Mat3 inverse_2x2(Fixed k11, Fixed k12, Fixed k22) {
  const Mat3 K{{Vec3{k11, k12, Fixed::zero()}, Vec3{k12, k22, Fixed::zero()},
                Vec3{Fixed::zero(), Fixed::zero(), Fixed::one()}}};
  return inverse(immobile_rows_unit(K));
}

}  // namespace

JointSolver::JointSolver(WorldState& s, SolverBodies& bodies) : s_(s), bodies_(bodies) {
  soft_ = make_soft(min(joint_hertz, bodies.inv_h >> 2), joint_damping_ratio, bodies.h);
}

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
