// The row machinery that every constraint kind shares (contacts now; joints and the couplings of
// particles to bodies later): Jacobian rows, their effective masses, soft constraint coefficients,
// and the two operations a sub-step is made of, a row's speed and an impulse along it. Internal
// to detsim::sim.
//
// A constraint row between bodies a and b in direction d (a unit axis for a linear row) has, per
// body, a linear part and an angular part: for anchors r_a and r_b, body a's is (-d, d x r_a) and
// body b's (d, r_b x d), with the responses M^-1 J^T (the linear part times the inverse mass, the
// angular part times the world inverse inertia). The parts are split in two structs because
// several rows share their linear parts: every point of a contact has the contact's normal and
// tangents (`Direction`, per constraint), while the angular parts depend on each point's anchors
// (`Row`, per point). A joint's three point-to-point rows are the same pair per world axis (Jolt's
// AxisConstraintPart is this pair, with the effective mass); an angular row (Jolt's
// AngleConstraintPart) is a `Row` alone.
//
// Exactness: a row's speed J v is one exact sum of every product, rounded once (DotSum), and an
// impulse moves each velocity component by v + lambda M^-1 J^T rounded once (Vec3Sum). The order
// of the terms is part of the result, and every kind reuses these functions so that it cannot
// differ between kinds. A wide (SIMD) version of these helpers must give the same bits lane by
// lane: the exact sums make that possible, since they do not depend on how the products are
// grouped.
//
// Inlining: the helpers run per row and per iteration, in the hottest loops of the step; they
// are defined here, `inline`, so that each kind's translation unit inlines them as if they were
// its own. row_speed is also `always_inline`: GCC 12 at -O2 otherwise calls it out of line from
// every site of the contact kind's passes, which cost the 1000-box pile 0.8 % more instructions
// per step than when the contact solver was one class (callgrind); inlined, the step is back to
// the same count.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include <detsim/fixed/decimal.hpp>
#include <detsim/fixed/math.hpp>

#include "../world_state.hpp"

namespace detsim::sim_detail {

/// A body's velocities as the solver moves them through the sub-steps.
struct Velocity {
  Vec3 linear;
  Vec3 angular;
};

/// A row's part for the two bodies' angular velocities, and what a unit impulse along it does to
/// them.
struct Row {
  Vec3 angular_a;   ///< d x r_a
  Vec3 angular_b;   ///< r_b x d
  Vec3 response_a;  ///< I_a^-1 angular_a
  Vec3 response_b;  ///< I_b^-1 angular_b
  Fixed mass;       ///< 1 / (J M^-1 J^T), the effective mass; zero when nothing can move
};

/// A row's part for the two bodies' linear velocities, and their response.
struct Direction {
  Vec3 linear_a;    ///< -d
  Vec3 linear_b;    ///< d
  Vec3 response_a;  ///< -d m_a^-1
  Vec3 response_b;  ///< d m_b^-1
};

/// The two bodies of a constraint (indices into WorldState::bodies and the solver's velocities),
/// and what the row helpers may skip for each. An impulse on a body of zero inverse mass and zero
/// inverse inertia changes nothing, bit for bit, and a still body (zero velocity that nothing
/// changes) adds exactly zero to a row's speed: the helpers skip that arithmetic instead of
/// computing zeros.
struct BodyPair {
  std::size_t a;
  std::size_t b;
  bool takes_impulse_a;
  bool takes_impulse_b;
  bool still_a;
  bool still_b;
};

/// Soft constraint coefficients (Box2D v3 b2MakeSoft): a spring of `hertz` with damping ratio
/// `zeta`, discretised implicitly for a time step h.
struct Softness {
  Fixed bias_rate;
  Fixed mass_scale;
  Fixed impulse_scale;
};

inline Softness make_soft(Fixed hertz, Fixed zeta, Fixed h) {
  using namespace detsim::literals;
  const Fixed omega = Fixed::two_pi() * hertz;
  const Fixed a1 = 2_fx * zeta + h * omega;
  const Fixed a2 = h * omega * a1;
  const Fixed a3 = Fixed::one() / (Fixed::one() + a2);
  return {omega / a1, a2 * a3, a3};
}

/// A body's linear response to a unit impulse along d, M^-1 d: d m^-1, with the components
/// along its locked translation axes (BodyDef::lock_translation) zero.
inline Vec3 linear_response(const Derived& b, Vec3 d) {
  if (!b.translation_locks.any()) return d * b.inverse_mass;
  return without_locked(d, b.translation_locks) * b.inverse_mass;
}

/// A body's linear share of the effective mass of a row along unit d, d . M^-1 d: m^-1, or with
/// locked translation axes m^-1 times the square of d's free part.
inline Fixed linear_share(const Derived& b, Vec3 d) {
  if (!b.translation_locks.any()) return b.inverse_mass;
  const Vec3 free = without_locked(d, b.translation_locks);
  return dot(free, d) * b.inverse_mass;
}

/// The linear parts of the rows of direction d.
inline Direction make_direction(const Derived& a, const Derived& b, Vec3 d) {
  return {-d, d, -linear_response(a, d), linear_response(b, d)};
}

/// The row of direction d at anchors r_a and r_b, with its effective mass
/// 1 / (m_a^-1 + m_b^-1 + (d x r_a) . I_a^-1 (d x r_a) + (r_b x d) . I_b^-1 (r_b x d)).
inline Row make_row(const Derived& a, const Derived& b, Vec3 ra, Vec3 rb, Vec3 d) {
  Row r;
  r.angular_a = cross(d, ra);
  r.angular_b = cross(rb, d);
  r.response_a = a.inverse_inertia_world * r.angular_a;
  r.response_b = b.inverse_inertia_world * r.angular_b;
  const Fixed angular =
      DotSum{}.add(r.response_a, r.angular_a).add(r.response_b, r.angular_b).result();
  r.mass = inverse_or_zero(linear_share(a, d) + linear_share(b, d) + angular);
  return r;
}

/// The speed of a row, J v: one exact sum rounded once, a's terms first. A still body's
/// velocities are zero and add exact zeros, which are skipped.
[[gnu::always_inline]] inline Fixed row_speed(const std::vector<Velocity>& v, const BodyPair& k,
                                              const Direction& d, const Row& r) {
  DotSum sum;
  if (!k.still_a) sum.add(d.linear_a, v[k.a].linear).add(r.angular_a, v[k.a].angular);
  if (!k.still_b) sum.add(d.linear_b, v[k.b].linear).add(r.angular_b, v[k.b].angular);
  return sum.result();
}

/// A body's response to a unit impulse along a row: M^-1 J^T.
struct Response {
  Vec3 linear;
  Vec3 angular;
};

/// v += impulse * response, each velocity component rounded once.
inline void push(Velocity& v, Fixed impulse, Response r) {
  v.linear = Vec3Sum{v.linear}.add(impulse, r.linear).result();
  v.angular = Vec3Sum{v.angular}.add(impulse, r.angular).result();
}

/// v += impulse_1 * response_1 + impulse_2 * response_2, each velocity component rounded once.
inline void push(Velocity& v, Fixed impulse_1, Response r1, Fixed impulse_2, Response r2) {
  v.linear = Vec3Sum{v.linear}.add(impulse_1, r1.linear).add(impulse_2, r2.linear).result();
  v.angular = Vec3Sum{v.angular}.add(impulse_1, r1.angular).add(impulse_2, r2.angular).result();
}

/// An impulse along one row. A zero impulse, or the side of a body that takes no impulses (zero
/// responses), would leave every bit as it is: both are skipped.
inline void apply_impulse(std::vector<Velocity>& v, const BodyPair& k, const Direction& d,
                          const Row& r, Fixed impulse) {
  if (impulse == Fixed::zero()) return;
  if (k.takes_impulse_a) push(v[k.a], impulse, {d.response_a, r.response_a});
  if (k.takes_impulse_b) push(v[k.b], impulse, {d.response_b, r.response_b});
}

/// Impulses along two rows at once (a contact point's two friction rows, a joint's pair of
/// perpendicular axes), each velocity component rounded once for both.
inline void apply_impulses(std::vector<Velocity>& v, const BodyPair& k, const Direction& d1,
                           const Row& r1, Fixed impulse_1, const Direction& d2, const Row& r2,
                           Fixed impulse_2) {
  if (impulse_1 == Fixed::zero() && impulse_2 == Fixed::zero()) return;
  if (k.takes_impulse_a) {
    push(v[k.a], impulse_1, {d1.response_a, r1.response_a}, impulse_2,
         {d2.response_a, r2.response_a});
  }
  if (k.takes_impulse_b) {
    push(v[k.b], impulse_1, {d1.response_b, r1.response_b}, impulse_2,
         {d2.response_b, r2.response_b});
  }
}

/// Impulses along three rows at once (a joint's point rows along x, y and z), each velocity
/// component rounded once for all three.
inline void apply_impulses(std::vector<Velocity>& v, const BodyPair& k,
                           const std::array<Direction, 3>& d, const std::array<Row, 3>& r,
                           Vec3 impulse) {
  if (impulse == Vec3{}) return;
  const auto push3 = [&](Velocity& velocity, auto linear, auto angular) {
    velocity.linear = Vec3Sum{velocity.linear}
                          .add(impulse.x, linear(0))
                          .add(impulse.y, linear(1))
                          .add(impulse.z, linear(2))
                          .result();
    velocity.angular = Vec3Sum{velocity.angular}
                           .add(impulse.x, angular(0))
                           .add(impulse.y, angular(1))
                           .add(impulse.z, angular(2))
                           .result();
  };
  if (k.takes_impulse_a)
    push3(
        v[k.a], [&](std::size_t i) { return d[i].response_a; },
        [&](std::size_t i) { return r[i].response_a; });
  if (k.takes_impulse_b)
    push3(
        v[k.b], [&](std::size_t i) { return d[i].response_b; },
        [&](std::size_t i) { return r[i].response_b; });
}

}  // namespace detsim::sim_detail
