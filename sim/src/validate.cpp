// Validation of definitions: every refusal names the field and the value it got, so a user can
// fix the call without reading the source.
#include <array>
#include <cstdint>
#include <string>

#include <detsim/fixed/decimal.hpp>
#include <detsim/fixed/math.hpp>
#include <detsim/fixed/wide.hpp>

#include "limits.hpp"
#include "shapes.hpp"
#include "world_state.hpp"

namespace detsim::sim_detail {

namespace {

std::string str(Fixed x) {
  return to_string(x);
}

// A unit quaternion must be this close: | |q|^2 - 1 | <= 2^-20.
constexpr Fixed kUnitTolerance = Fixed::from_raw(Fixed::one_raw >> 20);

std::string non_negative(const char* what, Fixed x) {
  if (x < Fixed::zero()) return std::string(what) + " must be >= 0, got " + str(x);
  return {};
}

}  // namespace

std::string above_limit(const std::string& quantity, Checked value, Fixed limit, const char* unit) {
  const std::string tail = ", above the limit " + str(limit) + " " + unit;
  const Fixed v = value.value();
  if (v == Fixed::max() || v == Fixed::min())
    return quantity + " would be at least " + (v < Fixed::zero() ? "-" : "") + "2147483648 " +
           unit + " (it saturates Q32.32)" + tail;
  if (beyond(v, limit)) return quantity + " would be " + str(v) + " " + unit + tail;
  return quantity + " would be above the limit " + str(limit) + " " + unit +
         " (a step of its formula leaves the Q32.32 range)";
}

namespace {

std::string below_limit(const std::string& quantity, Fixed value, const char* unit) {
  return quantity + " would be " + str(value) + " " + unit + ", below the limit " + str(min_mass) +
         " " + unit + " (the smallest whose inverse fits in Q32.32)";
}

}  // namespace

std::string check_components(const char* what, Vec3 v, Fixed limit, const char* unit) {
  const char* axes[] = {"x", "y", "z"};
  const Fixed c[] = {v.x, v.y, v.z};
  for (int i = 0; i < 3; ++i) {
    if (beyond(c[i], limit))
      return std::string(what) + " " + axes[i] + " must be within +-" + str(limit) + " " + unit +
             ", got " + str(c[i]);
  }
  return {};
}

std::string check_position(Vec3 p) {
  return check_components("position", p, max_position, "m");
}

std::string check_angular_velocity(const Shape& shape, const Geometry* g, Vec3 w,
                                   const char* what) {
  if (auto e = check_components(what, w, max_velocity, "rad/s"); !e.empty()) return e;
  // What prepare_body computes for the contact margins, before any speed limit applies.
  const Fixed radius = bounding_radius(shape, g);
  const Checked rim = Checked(length(w)) * radius;
  if (rim.over())
    return above_limit("rim speed (|angular velocity| * bounding radius " + str(radius) + " m)",
                       rim, max_quantity, "m/s");
  return {};
}

namespace {

/// a * b for a, b >= 0 as text, exactly (the product of two Q32.32 values has 64 fraction bits
/// and fits in 128 bits), rounded to an integer when it is beyond the Q32.32 range.
std::string product_text(Fixed a, Fixed b) {
  const wide::U128 p =
      wide::Default::mul(static_cast<std::uint64_t>(a.raw()), static_cast<std::uint64_t>(b.raw()));
  if (p.hi <= static_cast<std::uint64_t>(max_quantity.to_int())) return str(a * b);
  return std::to_string(p.hi + (p.lo >> 63));  // round half up: display only
}

std::string check_mass_properties(const Geometry* g, const BodyDef& def) {
  const ShapeKind& kind = shape_kind(def.shape.type);
  // The same arithmetic as body_mass, checked at every step.
  Checked mass = def.mass;
  if (def.mass <= Fixed::zero()) {
    const Checked volume = kind.checked_volume(def.shape, g);
    if (volume.over())
      return above_limit(std::string("volume of the ") + kind.name, volume, max_quantity, "m^3");
    mass = Checked(def.density) * volume;
    if (mass.over())
      return "mass would be " + product_text(def.density, volume.value()) + " kg (density " +
             str(def.density) + " kg/m^3 * volume " + str(volume.value()) +
             " m^3), above the limit " + str(max_quantity) + " kg" +
             (def.type == BodyType::dynamic
                  ? ""
                  : "; a body that never becomes dynamic can have density 0 (no mass)");
  } else if (mass.over()) {
    return above_limit("mass", mass, max_quantity, "kg");
  }
  const std::array<Checked, 3> inertia = kind.checked_inertia(def.shape, g, mass.value());
  const char* axes[] = {"x", "y", "z"};
  for (std::size_t i = 0; i < 3; ++i) {
    if (inertia[i].over())
      return above_limit(std::string("moment of inertia about ") + axes[i] + " (mass " +
                             str(mass.value()) + " kg, " + kind.name + ")",
                         inertia[i], max_quantity, "kg m^2");
  }
  return {};
}

}  // namespace

std::string check_unit_vector(const char* what, Vec3 v) {
  const Fixed l2 = length_squared(v);
  if (abs(l2 - Fixed::one()) > kUnitTolerance)
    return std::string(what) + " must be a unit vector (|" + what +
           "|^2 within 2^-20 of 1), got |" + what + "|^2 = " + str(l2);
  return {};
}

std::string check_orientation(Quat q) {
  const Fixed l2 = length_squared(q);
  if (abs(l2 - Fixed::one()) > kUnitTolerance)
    return "orientation must be a unit quaternion (|q|^2 within 2^-20 of 1), got |q|^2 = " +
           str(l2);
  return {};
}

std::string check_body_def(const WorldState& s, const BodyDef& def) {
  if (def.type != BodyType::static_body && def.type != BodyType::kinematic &&
      def.type != BodyType::dynamic)
    return "unknown body type " + std::to_string(static_cast<unsigned>(def.type));
  if (auto e = check_shape(s.geometries, def.shape, def.type); !e.empty()) return e;
  const Geometry* g = s.geometry(def.shape);
  if (auto e = check_orientation(def.orientation); !e.empty()) return e;
  if (auto e = check_position(def.position); !e.empty()) return e;
  if (def.type != BodyType::static_body) {  // a static body's velocities are ignored (zero)
    if (auto e = check_components("linear velocity", def.linear_velocity, max_velocity, "m/s");
        !e.empty())
      return e;
    if (auto e = check_angular_velocity(def.shape, g, def.angular_velocity, "angular velocity");
        !e.empty())
      return e;
  }
  if (auto e = non_negative("mass", def.mass); !e.empty()) return e;
  if (auto e = non_negative("density", def.density); !e.empty()) return e;
  if (auto e = non_negative("friction", def.friction); !e.empty()) return e;
  if (auto e = non_negative("restitution", def.restitution); !e.empty()) return e;
  if (def.restitution > Fixed::one())
    return "restitution must be <= 1, got " + str(def.restitution);
  if (auto e = non_negative("linear damping", def.linear_damping); !e.empty()) return e;
  if (auto e = non_negative("angular damping", def.angular_damping); !e.empty()) return e;
  if (auto e = check_mass_properties(g, def); !e.empty()) return e;
  if (def.type == BodyType::dynamic) {
    const MassProperties m = body_mass(s, def);
    if (m.mass <= Fixed::zero())
      return "a dynamic body needs a positive mass: mass is 0 and density * volume rounds to " +
             str(m.mass);
    if (m.inertia.x <= Fixed::zero() || m.inertia.y <= Fixed::zero() ||
        m.inertia.z <= Fixed::zero())
      return "the body's moments of inertia round to zero (shape too small for its mass); give "
             "it a larger mass or shape";
    return check_dynamic_mass(m);
  }
  return {};
}

std::string check_dynamic_mass(const MassProperties& m) {
  if (m.mass < min_mass) return below_limit("mass", m.mass, "kg");
  const char* axes[] = {"x", "y", "z"};
  const Fixed moments[] = {m.inertia.x, m.inertia.y, m.inertia.z};
  for (int i = 0; i < 3; ++i) {
    if (moments[i] < min_mass)
      return below_limit(std::string("moment of inertia about ") + axes[i], moments[i], "kg m^2");
  }
  return {};
}

namespace {

std::string check_joint_body(const WorldState& s, const char* field, BodyId id) {
  if (id.is_null()) return std::string(field) + " must name a body, got the null ID 0";
  if (s.find(id.value) < 0)
    return std::string(field) + " names no body: no body with ID " + std::to_string(id.value);
  return {};
}

}  // namespace

std::string check_joint_motor(Fixed speed, Fixed max_force) {
  if (beyond(speed, max_velocity))
    return "motor_speed must be within +-" + str(max_velocity) + ", got " + str(speed);
  if (auto e = non_negative("motor_max_force", max_force); !e.empty()) return e;
  if (max_force > max_quantity)
    return "motor_max_force must be <= " + str(max_quantity) + ", got " + str(max_force);
  return {};
}

std::string check_joint_def(const WorldState& s, const JointDef& def) {
  if (auto e = check_joint_fields(s, def); !e.empty()) return e;
  const BodyState& a = s.bodies[static_cast<std::size_t>(s.find(def.body_a.value))];
  const BodyState& b = s.bodies[static_cast<std::size_t>(s.find(def.body_b.value))];
  if (a.type == BodyType::static_body && b.type == BodyType::static_body)
    return "body_a (" + std::to_string(def.body_a.value) + ") and body_b (" +
           std::to_string(def.body_b.value) + ") are both static: at most one may be";
  return {};
}

std::string check_joint_fields(const WorldState& s, const JointDef& def) {
  if (static_cast<unsigned>(def.type) > static_cast<unsigned>(JointType::swing_twist))
    return "unknown joint type " + std::to_string(static_cast<unsigned>(def.type));
  if (auto e = check_joint_body(s, "body_a", def.body_a); !e.empty()) return e;
  if (auto e = check_joint_body(s, "body_b", def.body_b); !e.empty()) return e;
  if (def.body_a == def.body_b)
    return "body_a and body_b must differ, both are body " + std::to_string(def.body_a.value);
  if (auto e = check_components("anchor", def.anchor, max_position, "m"); !e.empty()) return e;
  if (auto e = check_unit_vector("axis", def.axis); !e.empty()) return e;
  if (def.limit_lower > def.limit_upper)
    return "limit_lower must be <= limit_upper, got limit_lower " + str(def.limit_lower) +
           " > limit_upper " + str(def.limit_upper);
  if (auto e = non_negative("swing_limit", def.swing_limit); !e.empty()) return e;
  if (def.swing_limit > Fixed::pi())
    return "swing_limit must be <= pi, got " + str(def.swing_limit);
  if (auto e = check_joint_motor(def.motor_speed, def.motor_max_force); !e.empty()) return e;
  if (auto e = non_negative("min_length", def.min_length); !e.empty()) return e;
  if (auto e = non_negative("max_length", def.max_length); !e.empty()) return e;
  if (def.min_length > def.max_length)
    return "min_length must be <= max_length, got min_length " + str(def.min_length) +
           " > max_length " + str(def.max_length);
  if (auto e = non_negative("spring_frequency", def.spring_frequency); !e.empty()) return e;
  if (auto e = non_negative("spring_damping_ratio", def.spring_damping_ratio); !e.empty()) return e;
  if (auto e = non_negative("break_force", def.break_force); !e.empty()) return e;
  if (auto e = non_negative("break_torque", def.break_torque); !e.empty()) return e;
  return {};
}

std::string check_world_def(const WorldDef& def) {
  if (def.dt <= Fixed::zero() || def.dt > Fixed::one())
    return "dt must be in (0, 1] seconds, got " + str(def.dt);
  if (def.substeps < 1 || def.substeps > 64)
    return "substeps must be in 1..64, got " + std::to_string(def.substeps);
  if (def.iterations < 1 || def.iterations > 64)
    return "iterations must be in 1..64, got " + std::to_string(def.iterations);
  const Fixed g_limit = Fixed::from_int(100000);
  if (abs(def.gravity.x) > g_limit || abs(def.gravity.y) > g_limit || abs(def.gravity.z) > g_limit)
    return "gravity components must be within +-100000 m/s^2";
  if (def.max_linear_speed <= Fixed::zero() || def.max_linear_speed > Fixed::from_int(100000))
    return "max linear speed must be in (0, 100000] m/s, got " + str(def.max_linear_speed);
  if (def.max_angular_speed <= Fixed::zero() || def.max_angular_speed > Fixed::from_int(10000))
    return "max angular speed must be in (0, 10000] rad/s, got " + str(def.max_angular_speed);
  if (def.contact_hertz <= Fixed::zero() || def.contact_hertz > Fixed::from_int(1000))
    return "contact hertz must be in (0, 1000], got " + str(def.contact_hertz);
  if (auto e = non_negative("contact damping ratio", def.contact_damping_ratio); !e.empty())
    return e;
  if (def.contact_push_max <= Fixed::zero())
    return "contact push max must be > 0, got " + str(def.contact_push_max);
  if (auto e = non_negative("restitution threshold", def.restitution_threshold); !e.empty())
    return e;
  if (auto e = non_negative("linear slop", def.linear_slop); !e.empty()) return e;
  if (auto e = non_negative("speculative distance", def.speculative_distance); !e.empty()) return e;
  if (def.speculative_distance > Fixed::one())
    return "speculative distance must be <= 1 m, got " + str(def.speculative_distance);
  if (auto e = non_negative("sleep linear speed", def.sleep_linear_speed); !e.empty()) return e;
  if (auto e = non_negative("sleep angular speed", def.sleep_angular_speed); !e.empty()) return e;
  if (auto e = non_negative("time to sleep", def.time_to_sleep); !e.empty()) return e;
  return {};
}

MassProperties body_mass(const WorldState& s, const BodyDef& def) noexcept {
  const ShapeKind& kind = shape_kind(def.shape.type);
  const Geometry* g = s.geometry(def.shape);
  const Fixed mass = def.mass > Fixed::zero() ? def.mass : def.density * kind.volume(def.shape, g);
  if (mass <= Fixed::zero()) return {};
  return kind.mass_properties(def.shape, g, mass);
}

Fixed inverse_or_zero(Fixed x) noexcept {
  return x > Fixed::zero() ? Fixed::one() / x : Fixed::zero();
}

}  // namespace detsim::sim_detail
