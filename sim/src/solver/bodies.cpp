// The per-body stages of a sub-step (solver/bodies.hpp). Their arithmetic is the integration of
// the soft step (solve.cpp): each body on its own, in ascending ID order.
#include "bodies.hpp"

namespace detsim::sim_detail {

namespace {

Vec3 halve(Vec3 v) {
  return {v.x >> 1, v.y >> 1, v.z >> 1};
}

// The result's length never exceeds the limit: v * (limit / |v|) can round a few ulp above it, so
// the factor steps down by one ulp until it does not (one or two steps; each shortens the result
// by |v| ulp, more than the rounding it makes up for). A v whose length would saturate (beyond
// about 2^31, which a solve that saturated can leave) is first halved until it is within 2^30:
// with |v| saturated the factor came out too large and the loop took ~10^5 steps (found by the
// API fuzzer). Halving keeps the direction to an ulp, and the result is scaled to the limit
// anyway. Out of line: it is the rare path.
[[gnu::noinline]] Vec3 scale_to_limit(Vec3 v, Fixed limit) {
  const Fixed within = Fixed::from_int(1 << 30);
  while (length_exceeds(v, within))
    v = {Fixed::from_raw(v.x.raw() >> 1), Fixed::from_raw(v.y.raw() >> 1),
         Fixed::from_raw(v.z.raw() >> 1)};
  Fixed factor = limit / length(v);
  Vec3 r = v * factor;
  int steps = 0;
  while (length_exceeds(r, limit)) {
    if (++steps <= 4) {
      factor -= Fixed::from_raw(1);
      r = v * factor;
      continue;
    }
    // A v of a few ulp (a limit of a few ulp): an ulp of the factor no longer moves the rounded
    // result (it took ~2^31 steps). Each component then goes one ulp towards zero per step,
    // which ends within a few steps of the limit (or at zero, within any limit).
    const auto toward_zero = [](Fixed c) {
      return Fixed::from_raw(c.raw() > 0 ? c.raw() - 1 : c.raw() < 0 ? c.raw() + 1 : 0);
    };
    r = {toward_zero(r.x), toward_zero(r.y), toward_zero(r.z)};
  }
  return r;
}

// `inline`: called twice per body per sub-step; the hint keeps the common case (within the limit)
// inlined as it was when it was a member function defined in its class.
inline Vec3 clamp_speed(Vec3 v, Fixed limit) {
  if (!length_exceeds(v, limit)) return v;  // length(v) <= limit, most often: no root needed
  return scale_to_limit(v, limit);
}

bool solvable(const BodyState& b) {
  return b.type != BodyType::static_body && b.awake;
}

bool awake_dynamic(const BodyState& b) {
  return b.type == BodyType::dynamic && b.awake;
}

}  // namespace

SolverBodies::SolverBodies(WorldState& state) : s(state) {
  const Fixed substeps = Fixed::from_int(static_cast<std::int32_t>(s.def.substeps));
  h = s.def.dt / substeps;
  inv_h = substeps / s.def.dt;
  gravity_kick = s.def.gravity * h;
  velocities.resize(s.bodies.size());
  half_kick.resize(s.bodies.size());
  push.resize(s.bodies.size());
  in_contact.assign(s.bodies.size(), false);
  for (std::size_t i = 0; i < s.bodies.size(); ++i) {
    const BodyState& b = s.bodies[i];
    velocities[i] = {b.linear_velocity, b.angular_velocity};
    // No stage of the solve wakes or puts to sleep a body: the lists hold for the whole step.
    if (solvable(b)) solvable_bodies.push_back(static_cast<std::uint32_t>(i));
    if (awake_dynamic(b)) awake_dynamic_bodies.push_back(static_cast<std::uint32_t>(i));
  }
}

bool SolverBodies::takes_impulse(std::size_t i) const {
  const Derived& d = s.derived[i];
  return d.inverse_mass != Fixed::zero() || d.inverse_inertia_world != Mat3::zero();
}

bool SolverBodies::still(std::size_t i) const {
  return !awake_dynamic(s.bodies[i]) && !takes_impulse(i) && velocities[i].linear == Vec3{} &&
         velocities[i].angular == Vec3{};
}

BodyPair SolverBodies::pair(std::size_t a, std::size_t b) const {
  return {a, b, takes_impulse(a), takes_impulse(b), still(a), still(b)};
}

void SolverBodies::integrate_velocities() {
  const WorldDef& def = s.def;
  for (const std::uint32_t i : awake_dynamic_bodies) {
    const BodyState& b = s.bodies[i];
    const Derived& d = s.derived[i];
    Velocity& v = velocities[i];
    // Locked axes (BodyDef::lock_translation, lock_rotation): a velocity the game set along them
    // is dropped here, and gravity and the force below; the solver's rows keep them at zero.
    if (d.translation_locks.any()) v.linear = without_locked(v.linear, d.translation_locks);
    if (d.rotation_locks.any()) v.angular = without_locked(v.angular, d.rotation_locks);
    // Without a force, the kick is gravity's (g + 0 m = g exactly), the same for every body; a
    // zero torque adds exactly zero (M 0 h = 0).
    const Vec3 start = v.linear;
    if (b.force == Vec3{}) {
      v.linear += gravity_kick;
    } else {
      v.linear += (def.gravity + b.force * d.inverse_mass) * h;
    }
    if (b.torque != Vec3{}) v.angular += (d.inverse_inertia_world * b.torque) * h;
    if (d.translation_locks.any()) v.linear = without_locked(v.linear, d.translation_locks);
    // Implicit damping, unconditionally stable: v /= 1 + h c.
    if (b.linear_damping > Fixed::zero()) v.linear /= Fixed::one() + h * b.linear_damping;
    if (b.angular_damping > Fixed::zero()) v.angular /= Fixed::one() + h * b.angular_damping;
    v.linear = clamp_speed(v.linear, def.max_linear_speed);
    v.angular = clamp_speed(v.angular, def.max_angular_speed);
    // Half of the velocity change the body actually got: after damping and the speed limit, so
    // that the trapezoidal position step below stays between the old and the new velocity (half
    // of the unclamped kick of a huge force moved a body backwards by far more than the limit).
    // Without damping or clamping it is half of the kick itself, bit for bit ((v + k) - v = k in
    // fixed point, where nothing saturates).
    half_kick[i] = halve(v.linear - start);
  }
}

// The speed limits hold for every velocity a body moves with and keeps, not only after forces.
Vec3 limit_speed(Vec3 v, Fixed limit) {
  return clamp_speed(v, limit);
}

void SolverBodies::clamp_speeds() {
  for (const std::uint32_t i : awake_dynamic_bodies) {
    Velocity& v = velocities[i];
    v.linear = clamp_speed(v.linear, s.def.max_linear_speed);
    v.angular = clamp_speed(v.angular, s.def.max_angular_speed);
  }
}

void SolverBodies::integrate_positions() {
  for (const std::uint32_t i : solvable_bodies) {
    BodyState& b = s.bodies[i];
    Derived& d = s.derived[i];
    const Velocity& v = velocities[i];
    // In free flight, x += h (v - a h / 2): with v already including this sub-step's a h, the
    // position moves by the trapezoidal mean velocity, so a body under constant gravity and
    // forces follows the exact parabola (semi-implicit Euler alone loses v h / 2 of height per
    // flight). A body with contact points keeps plain semi-implicit Euler, whose resting
    // equilibrium the soft contacts are tuned for (the shifted one creeps sideways).
    Vec3 dp = in_contact[i] ? v.linear * h : (v.linear - half_kick[i]) * h;
    Vec3 angular = v.angular;
    Velocity& p = push[i];
    if (p.linear != Vec3{} || p.angular != Vec3{}) {
      // Overlap recovery moves the body by at most contact_push_max per second (and turns it no
      // faster than the angular speed limit), however many bodies it overlaps.
      const Vec3 pushed = clamp_speed(p.linear, s.def.contact_push_max) * h;
      dp += pushed;
      d.pushed_out += pushed;
      angular += clamp_speed(p.angular, s.def.max_angular_speed);
      p = {};
    }
    // The centre of mass moves; the body turns about it, and its origin follows. A body whose
    // centre is its origin moves its position by the same dp (the same bits, no rotation).
    d.center += dp;
    d.delta_position += dp;
    if (angular != Vec3{}) {
      b.orientation = integrate(b.orientation, angular, h);
      d.delta_angle += angular * h;
    }
    if (b.center_of_mass == Vec3{}) {
      b.position += dp;
    } else {
      b.position = d.center - rotate(b.orientation, b.center_of_mass);
    }
  }
}

void SolverBodies::store_velocities() {
  for (const std::uint32_t i : solvable_bodies) {
    BodyState& b = s.bodies[i];
    b.linear_velocity = velocities[i].linear;
    b.angular_velocity = velocities[i].angular;
  }
}

}  // namespace detsim::sim_detail
