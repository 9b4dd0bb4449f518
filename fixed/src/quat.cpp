// Quaternion normalisation, construction from an axis and angle, and orientation integration.
#include <array>
#include <cstdint>

#include <detsim/fixed/exact_sum.hpp>
#include <detsim/fixed/math.hpp>
#include <detsim/fixed/quat.hpp>

#include "normalize.hpp"

namespace detsim {

Quat normalize(Quat q) noexcept {
  std::array c{q.w.raw(), q.x.raw(), q.y.raw(), q.z.raw()};
  if (!detail::normalize_raw(c)) return Quat::identity();
  return {Fixed::from_raw(c[0]), Fixed::from_raw(c[1]), Fixed::from_raw(c[2]),
          Fixed::from_raw(c[3])};
}

Quat from_axis_angle(Vec3 axis, Fixed angle) noexcept {
  const Vec3 n = normalize(axis);
  if (n == Vec3::zero()) return Quat::identity();
  const SinCos half = sincos(angle >> 1);
  // sin and cos are each within 1 ulp (sincos is faithful), n within 0.5 ulp, and the products add
  // 0.5 ulp; renormalising restores the unit length that those errors disturb.
  return normalize(Quat{half.cos, n.x * half.sin, n.y * half.sin, n.z * half.sin});
}

Quat integrate(Quat q, Vec3 angular_velocity, Fixed dt) noexcept {
  // a = (dt / 2) omega: the exact product omega_i dt, halved by rounding 33 bits off instead of 32.
  const auto half_step = [dt](Fixed omega) {
    detail::ProductSum s;
    s.add_product(omega.raw(), dt.raw());
    return s.round_to_raw(Fixed::fraction_bits + 1);
  };
  const std::int64_t ax = half_step(angular_velocity.x);
  const std::int64_t ay = half_step(angular_velocity.y);
  const std::int64_t az = half_step(angular_velocity.z);

  // q + (0, a) q = (w - a . u, u + w a + a x u), each component one exact sum rounded once.
  detail::ProductSum w;
  w.add_scaled(q.w.raw(), Fixed::fraction_bits);
  w.sub_product(ax, q.x.raw());
  w.sub_product(ay, q.y.raw());
  w.sub_product(az, q.z.raw());
  const auto vector_part = [&q](Fixed ui, std::int64_t ai, std::int64_t p, Fixed r, std::int64_t s,
                                Fixed t) {
    detail::ProductSum sum;  // u_i + a_i w + (p r - s t)
    sum.add_scaled(ui.raw(), Fixed::fraction_bits);
    sum.add_product(ai, q.w.raw());
    sum.add_product(p, r.raw());
    sum.sub_product(s, t.raw());
    return sum.to_fixed();
  };
  return normalize(Quat{w.to_fixed(), vector_part(q.x, ax, ay, q.z, az, q.y),
                        vector_part(q.y, ay, az, q.x, ax, q.z),
                        vector_part(q.z, az, ax, q.y, ay, q.x)});
}

}  // namespace detsim
