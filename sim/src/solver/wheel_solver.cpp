// Vehicles' wheels (wheel_solver.hpp): the suspension, the engine and gearbox, the brakes and the
// tires, per sub-step.
//
// The tire's grip, per unit load, is Pacejka's magic formula of the slip, times the ground body's
// friction (the contact material): along the wheel of the slip ratio (rim speed - ground speed) /
// |ground speed|, across it of the slip angle atan(lateral speed / |forward speed|), both taken
// from the velocities at the step's start. Below 1 m/s of slip and of speed over the ground the
// slip is ill-defined (it divides by a speed near zero) and a tire at rest grips with the curve's
// peak, like static friction: a parked car on a slope stays. Each row is bounded by its grip times
// the wheel's load in the sub-step, independently (no friction ellipse yet).
#include "wheel_solver.hpp"

#include <detsim/fixed/math.hpp>
#include <detsim/fixed/quat.hpp>

#include "../query_util.hpp"

namespace detsim::sim_detail {

namespace {

using namespace detsim::literals;

constexpr Fixed kStaticSpeed = 1_fx;  ///< m/s: below it, the tire grips with its peak
/// The cosine of the steepest ground a wheel stands on (60 degrees from the chassis' up).
constexpr Fixed kSteepestGround = 0.5_fx;
/// m/s: slower than this, a car is stopped (the automatic gearbox may select reverse).
constexpr Fixed kStoppedSpeed = 0.1_fx;

/// The magic formula d sin(c atan(b x - e (b x - atan(b x)))).
Fixed magic(const TireCurve& t, Fixed x) {
  const Fixed bx = t.b * x;
  return t.d * sin(t.c * atan(bx - t.e * (bx - atan(bx))));
}

/// The curve's highest value: d once c atan(.) can reach pi/2 (c >= 1), else d sin(c pi/2).
Fixed peak(const TireCurve& t) {
  return t.c >= Fixed::one() ? t.d : t.d * sin(t.c * Fixed::half_pi());
}

/// Full-throttle torque at `rpm` from the curve: linear between points, flat beyond the ends.
Fixed curve_torque(const EngineDef& e, Fixed rpm) {
  const std::vector<TorquePoint>& c = e.torque_curve;
  if (rpm <= c.front().rpm) return c.front().torque;
  for (std::size_t i = 1; i < c.size(); ++i) {
    if (rpm > c[i].rpm) continue;
    const Fixed t = (rpm - c[i - 1].rpm) / (c[i].rpm - c[i - 1].rpm);
    return c[i - 1].torque + (c[i].torque - c[i - 1].torque) * t;
  }
  return c.back().torque;
}

/// rad/s of the wheels to rpm of the engine, per unit of total ratio.
constexpr Fixed kRpmPerRadPerSecond = 9.5492965855_fx;  // 60 / (2 pi)

Vec3 axis_y(Quat q) {
  return rotate(q, {Fixed::zero(), Fixed::one(), Fixed::zero()});
}

/// The gearbox's total ratio now: the gear's and the final drive's; negative in reverse.
Fixed total_ratio(const VehicleState& v) {
  const Fixed gear = v.gear == 0 ? -v.def.reverse_ratio : v.def.gear_ratios[v.gear - 1];
  return gear * v.def.final_drive;
}

/// What drives the engine: the throttle, or in reverse the brake pedal. The other pedal brakes:
/// in reverse the throttle (until the car stops and the gearbox takes first).
Fixed accelerator(const VehicleState& v) {
  return v.gear == 0 ? v.input.brake : v.input.throttle;
}
Fixed brake_pedal(const VehicleState& v) {
  return v.gear == 0 ? v.input.throttle : v.input.brake;
}

std::uint32_t driven_count(const VehicleDef& d) {
  std::uint32_t n = 0;
  for (const WheelDef& w : d.wheels)
    n += w.driven ? 1U : 0U;
  return n;
}

}  // namespace

WheelSolver::WheelSolver(WorldState& s, SolverBodies& bodies) : s_(s), bodies_(bodies) {}

void WheelSolver::prepare() {
  wheels_.clear();
  std::size_t total = 0;
  for (const VehicleState& v : s_.vehicles)
    total += v.def.wheels.size();
  wheels_.reserve(total);
  for (std::size_t vi = 0; vi < s_.vehicles.size(); ++vi) {
    VehicleState& v = s_.vehicles[vi];
    const std::ptrdiff_t c = s_.find(v.def.chassis.value);
    if (c < 0) continue;
    const BodyState& chassis = s_.bodies[static_cast<std::size_t>(c)];
    if (chassis.type != BodyType::dynamic || !chassis.awake) continue;
    bodies_.in_contact[static_cast<std::size_t>(c)] = true;
    const Fixed ratio = total_ratio(v);
    const std::uint32_t driven = driven_count(v.def);
    for (std::size_t wi = 0; wi < v.def.wheels.size(); ++wi) {
      WheelConstraint& k = wheels_.emplace_back();
      k.vehicle = vi;
      k.wheel = wi;
      const WheelDef& w = v.def.wheels[wi];
      k.inertia = w.inertia;
      if (w.driven && driven > 0)
        k.inertia += v.def.engine.inertia * ratio * ratio /
                     Fixed::from_int(static_cast<std::int32_t>(driven));
      const Fixed brake = w.handbrake && v.input.handbrake ? Fixed::one() : brake_pedal(v);
      k.brake_torque = w.max_brake_torque * brake;
      prepare_wheel(k, static_cast<std::size_t>(c));
    }
  }
}

void WheelSolver::prepare_wheel(WheelConstraint& k, std::size_t c) {
  VehicleState& v = s_.vehicles[k.vehicle];
  const WheelDef& w = v.def.wheels[k.wheel];
  WheelState& out = v.wheels[k.wheel];
  const BodyState& chassis = s_.bodies[c];
  const Vec3 up = axis_y(chassis.orientation);
  const Vec3 top = chassis.position + rotate(chassis.orientation, w.attachment);
  out.steer_angle = w.max_steer_angle * v.input.steering;
  // The wheel's sphere down its suspension: where it meets the ground is its compression.
  const QueryFilter filter{chassis.layer, chassis.mask, false, chassis.id};
  const Vec3 travel = -up * w.suspension_rest_length;
  std::optional<ShapeHit> hit =
      cast_shape(s_, Shape::sphere(w.radius), top, Quat::identity(), travel, filter);
  // A surface steeper than 60 degrees to the chassis is a wall, not ground: the wheel would
  // climb it. The chassis' own shape meets walls; the wheel looks for the ground past it (a
  // second cast that leaves the wall out, and the chassis, which it starts inside and leaves).
  if (hit && dot(hit->normal, up) < kSteepestGround) {
    std::optional<ShapeHit> past =
        cast_shape(s_, Shape::sphere(w.radius), top, Quat::identity(), travel,
                   {chassis.layer, chassis.mask, false, hit->body});
    if (past && (past->body == chassis.id || dot(past->normal, up) < kSteepestGround)) past.reset();
    hit = past;
  }
  k.contact = hit.has_value();
  out.contact = k.contact;
  if (!hit) {
    k.compression = Fixed::zero();
    out.compression = Fixed::zero();
    out.contact_point = {};
    out.contact_normal = {};
    out.contact_body = {};
    out.slip_ratio = Fixed::zero();
    out.slip_angle = Fixed::zero();
    k.bodies = bodies_.pair(c, c);
    return;
  }
  const std::size_t g = static_cast<std::size_t>(s_.find(hit->body.value));
  const Vec3 n = hit->normal;
  k.compression = w.suspension_rest_length - w.suspension_rest_length * hit->fraction;
  out.contact_point = hit->point;
  out.contact_normal = n;
  out.contact_body = hit->body;
  k.bodies = bodies_.pair(c, g);
  if (s_.bodies[g].type == BodyType::dynamic) bodies_.in_contact[g] = true;
  // The wheel's heading, turned by its steering about the chassis' up, laid in the contact plane.
  const Quat steer = from_axis_angle(up, out.steer_angle);
  const Vec3 heading =
      rotate(steer * chassis.orientation, {Fixed::zero(), Fixed::zero(), Fixed::one()});
  const Vec3 along = normalize(heading - n * dot(heading, n));
  const Vec3 left = cross(n, along);
  const Derived& da = s_.derived[c];
  const Derived& dg = s_.derived[g];
  const Vec3 ra = hit->point - da.center;
  const Vec3 rb = hit->point - dg.center;
  k.up = make_direction(da, dg, -n);
  k.up_row = make_row(da, dg, ra, rb, -n);
  k.along = make_direction(da, dg, along);
  k.along_row = make_row(da, dg, ra, rb, along);
  k.across = make_direction(da, dg, left);
  k.across_row = make_row(da, dg, ra, rb, left);
  const Fixed inverse_row =
      k.along_row.mass > Fixed::zero() ? Fixed::one() / k.along_row.mass : Fixed::zero();
  k.along_mass = inverse_or_zero(inverse_row + w.radius * w.radius / k.inertia);
  k.rate = compression_rate(k);
  // The slip at the step's start: the contact point's velocity over the ground's.
  const Velocity& vc = bodies_.velocities[c];
  const Velocity& vg = bodies_.velocities[g];
  const Vec3 relative = (vc.linear + cross(vc.angular, ra)) - (vg.linear + cross(vg.angular, rb));
  const Fixed forward = dot(relative, along);
  const Fixed sideways = dot(relative, left);
  const Fixed rim = out.angular_velocity * w.radius;
  const Fixed friction = s_.bodies[g].friction;
  const TireDef& tire = v.def.tire;
  const Fixed reference = max(abs(forward), kStaticSpeed);
  k.slip_ratio = (rim - forward) / reference;
  k.slip_angle = atan2(sideways, reference);
  out.slip_ratio = k.slip_ratio;
  out.slip_angle = k.slip_angle;
  const bool at_rest = abs(forward) < kStaticSpeed && abs(sideways) < kStaticSpeed &&
                       abs(rim - forward) < kStaticSpeed;
  k.grip_along =
      friction * (at_rest ? peak(tire.longitudinal) : abs(magic(tire.longitudinal, k.slip_ratio)));
  k.grip_across =
      friction * (at_rest ? peak(tire.lateral) : abs(magic(tire.lateral, k.slip_angle)));
}

void WheelSolver::warm_start() {
  const Fixed h = bodies_.h;
  std::vector<Velocity>& velocity = bodies_.velocities;
  for (std::size_t first = 0; first < wheels_.size();) {
    VehicleState& v = s_.vehicles[wheels_[first].vehicle];
    std::size_t last = first;
    while (last < wheels_.size() && wheels_[last].vehicle == wheels_[first].vehicle)
      ++last;
    // The engine: its rpm from the driven wheels' mean spin, its torque shared among them.
    const std::uint32_t driven = driven_count(v.def);
    const Fixed ratio = total_ratio(v);
    if (driven > 0) {
      Fixed spin = Fixed::zero();
      for (std::size_t i = first; i < last; ++i)
        if (v.def.wheels[wheels_[i].wheel].driven)
          spin += v.wheels[wheels_[i].wheel].angular_velocity;
      const Fixed n = Fixed::from_int(static_cast<std::int32_t>(driven));
      const Fixed rpm = max(v.def.engine.idle_rpm, abs(spin / n) * ratio * kRpmPerRadPerSecond);
      v.engine_rpm = rpm;
      const Fixed torque = rpm >= v.def.engine.max_rpm
                               ? Fixed::zero()
                               : curve_torque(v.def.engine, rpm) * accelerator(v);
      const Fixed per_wheel = torque * ratio / n;
      for (std::size_t i = first; i < last; ++i) {
        WheelConstraint& k = wheels_[i];
        if (v.def.wheels[k.wheel].driven)
          v.wheels[k.wheel].angular_velocity += per_wheel * h / k.inertia;
      }
    }
    // The suspension: compression from the contact's relative velocity along the normal, then
    // spring, damper and anti-roll bars as one impulse per wheel.
    for (std::size_t i = first; i < last; ++i) {
      WheelConstraint& k = wheels_[i];
      k.along_impulse = Fixed::zero();
      k.across_impulse = Fixed::zero();
      k.brake_impulse = Fixed::zero();
      k.load = Fixed::zero();
      if (!k.contact) continue;
      const WheelDef& w = v.def.wheels[k.wheel];
      k.load = w.suspension_stiffness * k.compression + w.suspension_damping * k.rate;
    }
    for (const AxleDef& axle : v.def.axles) {
      WheelConstraint& l = wheels_[first + axle.left_wheel];
      WheelConstraint& r = wheels_[first + axle.right_wheel];
      if (!l.contact && !r.contact) continue;
      const Fixed roll = axle.anti_roll_stiffness * (l.compression - r.compression);
      if (l.contact) l.load += roll;
      if (r.contact) r.load -= roll;
    }
    for (std::size_t i = first; i < last; ++i) {
      WheelConstraint& k = wheels_[i];
      if (!k.contact) continue;
      k.load = max(k.load, Fixed::zero());  // a spring pushes, never pulls
      apply_impulse(velocity, k.bodies, k.up, k.up_row, k.load * h);
    }
    first = last;
  }
}

void WheelSolver::solve_all() {
  const Fixed h = bodies_.h;
  for (WheelConstraint& k : wheels_) {
    VehicleState& v = s_.vehicles[k.vehicle];
    const WheelDef& w = v.def.wheels[k.wheel];
    Fixed& spin = v.wheels[k.wheel].angular_velocity;
    if (k.contact && k.load > Fixed::zero()) solve_tire(k, w, spin);
    // The brake, last: the spin towards zero with at most its torque.
    if (k.brake_torque > Fixed::zero()) {
      const Fixed most = k.brake_torque * h;
      const Fixed total = clamp(k.brake_impulse - spin * k.inertia, -most, most);
      spin += (total - k.brake_impulse) / k.inertia;
      k.brake_impulse = total;
    }
  }
}

void WheelSolver::solve_tire(WheelConstraint& k, const WheelDef& w, Fixed& spin) {
  const Fixed h = bodies_.h;
  std::vector<Velocity>& velocity = bodies_.velocities;
  // Along: the rim's speed against the ground's (the row's speed is the ground's over the
  // chassis' along the heading, so the slip is row speed + rim speed).
  {
    const Fixed slip = row_speed(velocity, k.bodies, k.along, k.along_row) + spin * w.radius;
    const Fixed most = k.grip_along * k.load * h;
    const Fixed total = clamp(k.along_impulse - slip * k.along_mass, -most, most);
    const Fixed delta = total - k.along_impulse;
    k.along_impulse = total;
    apply_impulse(velocity, k.bodies, k.along, k.along_row, delta);
    spin += delta * w.radius / k.inertia;
  }
  // Across: no sliding sideways.
  {
    const Fixed slip = row_speed(velocity, k.bodies, k.across, k.across_row);
    const Fixed most = k.grip_across * k.load * h;
    const Fixed total = clamp(k.across_impulse - slip * k.across_row.mass, -most, most);
    const Fixed delta = total - k.across_impulse;
    k.across_impulse = total;
    apply_impulse(velocity, k.bodies, k.across, k.across_row, delta);
  }
}

void WheelSolver::solve() {
  solve_all();
}

void WheelSolver::restitution() {
  // The sub-step's end: the compression moves with the velocity the positions moved by, and its
  // rate is what the next sub-step's damper sees (not this one's velocity before the solve, which
  // holds gravity's kick for the sub-step and would damp a car at rest).
  for (WheelConstraint& k : wheels_) {
    if (!k.contact) continue;
    const WheelDef& w = s_.vehicles[k.vehicle].def.wheels[k.wheel];
    k.rate = compression_rate(k);
    k.compression =
        clamp(k.compression + k.rate * bodies_.h, Fixed::zero(), w.suspension_rest_length);
  }
}

Fixed WheelSolver::compression_rate(const WheelConstraint& k) const {
  return -row_speed(bodies_.velocities, k.bodies, k.up, k.up_row);  // compressing: > 0
}

void WheelSolver::relax() {
  solve_all();
}

void WheelSolver::store_impulses() {
  const Fixed inv_h = bodies_.inv_h;
  for (const WheelConstraint& k : wheels_) {
    VehicleState& v = s_.vehicles[k.vehicle];
    WheelState& out = v.wheels[k.wheel];
    out.compression = k.compression;
    out.suspension_force = k.load;
    // The tire's force on the chassis: a positive row impulse slows it along the row.
    out.longitudinal_force = -k.along_impulse * inv_h;
    out.lateral_force = -k.across_impulse * inv_h;
  }
  for (std::size_t first = 0; first < wheels_.size();) {
    VehicleState& v = s_.vehicles[wheels_[first].vehicle];
    std::size_t last = first;
    while (last < wheels_.size() && wheels_[last].vehicle == wheels_[first].vehicle)
      ++last;
    const std::size_t c = wheels_[first].bodies.a;
    const Vec3 forward =
        rotate(s_.bodies[c].orientation, {Fixed::zero(), Fixed::zero(), Fixed::one()});
    v.forward_speed = dot(bodies_.velocities[c].linear, forward);
    // A car whose engine drives or whose wheels still turn is not parked: it does not sleep
    // (pushing against a wall with its wheels spinning, its chassis is still).
    bool running = accelerator(v) > Fixed::zero();
    for (std::size_t i = first; i < last; ++i)
      running = running || abs(v.wheels[wheels_[i].wheel].angular_velocity) > kStaticSpeed;
    if (running) s_.bodies[c].sleep_time = Fixed::zero();
    if (v.def.automatic) {
      // Reverse when (nearly) stopped with the brake held and no throttle, forward again with
      // the throttle; up above 0.9 max_rpm, down below 0.35 max_rpm.
      const Fixed rpm = v.engine_rpm;
      const auto gears = static_cast<std::uint32_t>(v.def.gear_ratios.size());
      const bool stopped = abs(v.forward_speed) < kStoppedSpeed;
      if (v.gear != 0 && stopped && v.input.brake > Fixed::zero() &&
          v.input.throttle == Fixed::zero()) {
        v.gear = 0;
      } else if (v.gear == 0) {
        if (v.input.throttle > Fixed::zero() && v.forward_speed > -kStaticSpeed) v.gear = 1;
      } else if (rpm >= v.def.engine.max_rpm * 0.9_fx && v.gear < gears) {
        ++v.gear;
      } else if (rpm < v.def.engine.max_rpm * 0.35_fx && v.gear > 1) {
        --v.gear;
      }
    }
    first = last;
  }
}

}  // namespace detsim::sim_detail
