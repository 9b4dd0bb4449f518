// Vehicles: a dynamic chassis on wheels with suspension, an engine and a gearbox, and tires whose
// grip follows Pacejka's magic formula (docs/SIM.md, "Vehicles").
//
// A wheel is not a body: each step it casts a sphere of its radius down its suspension from its
// attachment on the chassis (a sphere rides over kerbs and edges that a ray would catch), and in
// each sub-step the solver pushes the chassis up with the suspension's spring and damper and holds
// it with the tire's grip, as rows of a constraint kind beside contacts and joints. The chassis'
// frame: +z forward, +y up, +x to its left. Vehicles have IDs of their own, never reused,
// assigned in creation order.
#pragma once

#include <compare>
#include <cstdint>
#include <vector>

#include <detsim/fixed/decimal.hpp>
#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/vec3.hpp>
#include <detsim/sim/body.hpp>

namespace detsim {

/// A vehicle's identity: a value, never reused within a world, assigned in creation order (1, 2,
/// 3, ...). Zero is the null ID.
struct VehicleId {
  std::uint32_t value = 0;

  [[nodiscard]] constexpr bool is_null() const noexcept { return value == 0; }
  friend constexpr auto operator<=>(VehicleId, VehicleId) noexcept = default;
};

/// One wheel. Defaults: a road car's.
struct WheelDef {
  /// The top of the suspension, in the chassis' frame (from its origin): the wheel's centre hangs
  /// suspension_rest_length below it, along the chassis' -y, when nothing loads it.
  Vec3 attachment{};
  Fixed radius = 0.35_fx;  ///< m
  /// m: how far the spring reaches unloaded; the wheel's travel from there to the bump stop (the
  /// wheel's centre at the attachment).
  Fixed suspension_rest_length = 0.3_fx;
  Fixed suspension_stiffness = 40000_fx;  ///< N/m
  Fixed suspension_damping = 4000_fx;     ///< N s/m
  /// rad: the input's steering of 1 turns the wheel this far to the left (about the chassis' +y);
  /// 0: not steered.
  Fixed max_steer_angle{};
  bool driven = false;               ///< the engine turns it (through the gearbox)
  Fixed max_brake_torque = 2000_fx;  ///< N m, at brake 1
  bool handbrake = false;            ///< the handbrake locks it (with max_brake_torque)
  Fixed inertia = 1_fx;              ///< kg m^2, about its axle

  friend constexpr bool operator==(const WheelDef&, const WheelDef&) noexcept = default;
};

/// A point of the engine's torque curve: at `rpm`, full throttle gives `torque` (N m).
struct TorquePoint {
  Fixed rpm;
  Fixed torque;

  friend constexpr bool operator==(const TorquePoint&, const TorquePoint&) noexcept = default;
};

struct EngineDef {
  /// Full-throttle torque against rpm, ascending rpm (1 to 16 points): linear between points,
  /// flat beyond the ends.
  std::vector<TorquePoint> torque_curve{{1000_fx, 300_fx}, {4500_fx, 420_fx}, {6500_fx, 320_fx}};
  Fixed idle_rpm = 1000_fx;  ///< the least the engine turns
  Fixed max_rpm = 6500_fx;   ///< no torque at or above it (the limiter)
  /// kg m^2: it adds inertia * (gear ratio * final drive)^2, shared, to the driven wheels.
  Fixed inertia = 0.5_fx;

  friend bool operator==(const EngineDef&, const EngineDef&) = default;
};

/// Pacejka's magic formula: the grip, as a fraction of the load, at slip x is
/// friction * d * sin(c * atan(b x - e (b x - atan(b x)))), `friction` the ground body's.
struct TireCurve {
  Fixed b;
  Fixed c;
  Fixed d;
  Fixed e;

  friend constexpr bool operator==(const TireCurve&, const TireCurve&) noexcept = default;
};

struct TireDef {
  /// Along the wheel, of the slip ratio (rim speed - ground speed) / |ground speed|: its peak
  /// near 0.1, its sliding value at -1 (a locked wheel) 0.91 d.
  TireCurve longitudinal{10_fx, 1.9_fx, 1_fx, 0.97_fx};
  /// Across the wheel, of the slip angle (rad): its peak near 0.22 rad.
  TireCurve lateral{12_fx, 1.3_fx, 1_fx, 0_fx};

  friend constexpr bool operator==(const TireDef&, const TireDef&) noexcept = default;
};

/// Two wheels across the chassis, joined by an anti-roll bar: it moves load from the more
/// compressed wheel's spring to the other's by anti_roll_stiffness * (difference of compression).
struct AxleDef {
  std::uint32_t left_wheel = 0;  ///< indices into VehicleDef::wheels
  std::uint32_t right_wheel = 1;
  Fixed anti_roll_stiffness{};  ///< N/m; 0: no bar

  friend constexpr bool operator==(const AxleDef&, const AxleDef&) noexcept = default;
};

struct VehicleDef {
  BodyId chassis{};              ///< a dynamic body of the world
  std::vector<WheelDef> wheels;  ///< 1 to 16
  EngineDef engine;
  /// Forward gears, first to top (1 to 8), each > 0: wheel rpm * ratio * final_drive is the
  /// engine's rpm.
  std::vector<Fixed> gear_ratios{3.6_fx, 2.2_fx, 1.5_fx, 1.1_fx, 0.9_fx};
  Fixed reverse_ratio = 3.6_fx;  ///< > 0: reverse turns the wheels backwards by this ratio
  Fixed final_drive = 3.5_fx;
  /// The gearbox shifts on its own: up above 0.9 max_rpm, down below 0.35 max_rpm, into reverse
  /// when the car is stopped (below 0.1 m/s) with the brake held and no throttle: the brake pedal
  /// then drives it backwards and the throttle brakes, as in most driving games, until the throttle
  /// finds it stopped and takes first. Without it the gear stays as it is (first, at creation).
  bool automatic = true;
  std::vector<AxleDef> axles;  ///< 0 to 8
  TireDef tire;

  friend bool operator==(const VehicleDef&, const VehicleDef&) = default;
};

/// What a game sends each frame (World::set_vehicle_input): kept until changed.
struct VehicleInput {
  Fixed throttle{};  ///< 0 .. 1
  Fixed brake{};     ///< 0 .. 1
  Fixed steering{};  ///< -1 (right) .. 1 (left)
  bool handbrake = false;

  friend constexpr bool operator==(const VehicleInput&, const VehicleInput&) noexcept = default;
};

/// A wheel as the last step left it.
struct WheelState {
  Fixed angular_velocity{};  ///< rad/s about its axle, positive rolling forward
  Fixed steer_angle{};       ///< rad
  Fixed compression{};       ///< m, 0 .. suspension_rest_length
  bool contact = false;      ///< on the ground
  Vec3 contact_point{};      ///< world space, on the ground
  Vec3 contact_normal{};     ///< unit, out of the ground
  BodyId contact_body{};
  Fixed slip_ratio{};          ///< (rim speed - ground speed) / |ground speed|
  Fixed slip_angle{};          ///< rad
  Fixed suspension_force{};    ///< N, along the contact normal
  Fixed longitudinal_force{};  ///< N, the tire's along the wheel (positive: pushing forward)
  Fixed lateral_force{};       ///< N, across the wheel (positive: to the left)

  friend constexpr bool operator==(const WheelState&, const WheelState&) noexcept = default;
};

struct VehicleState {
  VehicleId id{};
  VehicleDef def;
  VehicleInput input;
  std::vector<WheelState> wheels;  ///< as def.wheels
  std::uint32_t gear = 1;          ///< 1 .. gear_ratios.size(); 0: reverse
  Fixed engine_rpm{};
  Fixed forward_speed{};  ///< m/s, the chassis' velocity along its +z

  friend bool operator==(const VehicleState&, const VehicleState&) = default;
};

}  // namespace detsim
