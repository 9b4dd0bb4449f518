// The joint kind's small geometric helpers, shared by its preparation (joint_prepare.cpp) and
// its solving (joint_solver.cpp): world axes, a perpendicular, angular and block rows without
// their own effective mass, and the inverses of the joint blocks.
#pragma once

#include <cstddef>

#include <detsim/fixed/mat3.hpp>
#include <detsim/fixed/math.hpp>

#include "bodies.hpp"
#include "rows.hpp"

namespace detsim::sim_detail::joint_rows {

inline Vec3 axis(std::size_t i) {
  Vec3 v;
  if (i == 0) v.x = Fixed::one();
  if (i == 1) v.y = Fixed::one();
  if (i == 2) v.z = Fixed::one();
  return v;
}

// A unit vector perpendicular to the unit vector n, chosen by n's components only (the contact
// kind's, contact_solver.cpp).
inline Vec3 perpendicular(Vec3 n) {
  const Fixed threshold = Fixed::from_raw(2479700525);  // 0.57735 ~ 1/sqrt(3)
  if (abs(n.x) >= threshold) return normalize(Vec3{n.y, -n.x, Fixed::zero()});
  return normalize(Vec3{Fixed::zero(), n.z, -n.y});
}

// The row of a relative rotation about the unit vector u: J = (0, -u, 0, u). Its linear parts
// are a zero Direction. Its own effective mass is left zero: every angular row is solved in a
// block (hinge axes, weld) or with the point rows held (twist, swing), whose masses are computed
// beside it.
inline Row angular_row(const Derived& a, const Derived& b, Vec3 u) {
  Row r;
  r.angular_a = -u;
  r.angular_b = u;
  r.response_a = a.inverse_inertia_world * r.angular_a;
  r.response_b = b.inverse_inertia_world * r.angular_b;
  return r;
}

// make_row without the row's own effective mass (left zero), for rows solved in a block (the
// point rows, the slider's rows across its axis): the division and the sum it needs are skipped.
inline Row block_row(const Derived& a, const Derived& b, Vec3 ra, Vec3 rb, Vec3 d) {
  Row r;
  r.angular_a = cross(d, ra);
  r.angular_b = cross(rb, d);
  r.response_a = a.inverse_inertia_world * r.angular_a;
  r.response_b = b.inverse_inertia_world * r.angular_b;
  return r;
}

inline const Direction no_direction{};

// A block whose bodies cannot move along one of its rows (a locked axis: BodyDef::lock_translation
// or lock_rotation) has a zero diagonal entry there, and since the block is positive semi-definite
// its whole row and column are zero: no impulse along it can do anything. A unit diagonal entry
// there leaves the other rows' inverse as it was and makes the block invertible (its own impulse
// then moves nothing). A block without such a row is returned as it is, bit for bit.
inline Mat3 immobile_rows_unit(Mat3 K) {
  if (K.rows[0].x == Fixed::zero()) K.rows[0].x = Fixed::one();
  if (K.rows[1].y == Fixed::zero()) K.rows[1].y = Fixed::one();
  if (K.rows[2].z == Fixed::zero()) K.rows[2].z = Fixed::one();
  return K;
}

// The inverse of the symmetric 2x2 block [[k11, k12], [k12, k22]], as the upper left of a 3x3
// with a unit third row and column: each entry the exact cofactor over the exact determinant
// (try_inverse), however small the block is.
inline Mat3 inverse_2x2(Fixed k11, Fixed k12, Fixed k22) {
  const Mat3 K{{Vec3{k11, k12, Fixed::zero()}, Vec3{k12, k22, Fixed::zero()},
                Vec3{Fixed::zero(), Fixed::zero(), Fixed::one()}}};
  return inverse(immobile_rows_unit(K));
}

}  // namespace detsim::sim_detail::joint_rows
