// Vehicles (vehicle.hpp; docs/SIM.md, "Vehicles"): the World's calls. The wheels are solved as a
// constraint kind (solver/wheel_solver.cpp).
#include <algorithm>
#include <string>

#include <detsim/fixed/decimal.hpp>
#include <detsim/fixed/math.hpp>

#include "limits.hpp"
#include "vehicle_fields.hpp"
#include "world_state.hpp"

namespace detsim {

namespace sim_detail {

std::ptrdiff_t WorldState::find_vehicle(std::uint32_t id) const noexcept {
  const auto it = std::lower_bound(
      vehicles.begin(), vehicles.end(), id,
      [](const VehicleState& v, std::uint32_t value) { return v.id.value < value; });
  if (it == vehicles.end() || it->id.value != id) return -1;
  return it - vehicles.begin();
}

namespace {

constexpr std::size_t kMaxWheels = 16;
constexpr std::size_t kMaxCurvePoints = 16;
constexpr std::size_t kMaxGears = 8;
constexpr std::size_t kMaxAxles = 8;

std::string range(const std::string& what, Fixed v, Fixed lo, Fixed hi, const char* unit) {
  if (v >= lo && v <= hi) return {};
  return what + " must be within " + to_string(lo) + " .. " + to_string(hi) + " " + unit +
         ", got " + to_string(v);
}

std::string check_wheel(const WheelDef& w, std::size_t i) {
  const std::string at = "wheels[" + std::to_string(i) + "].";
  const Fixed big = Fixed::from_int(1000000000);
  if (auto e =
          check_components((at + "attachment").c_str(), w.attachment, Fixed::from_int(1000), "m");
      !e.empty())
    return e;
  if (auto e = range(at + "radius", w.radius, Fixed::from_raw(Fixed::one_raw >> 10),
                     Fixed::from_int(100), "m");
      !e.empty())
    return e;
  if (auto e = range(at + "suspension_rest_length", w.suspension_rest_length,
                     Fixed::from_raw(Fixed::one_raw >> 10), Fixed::from_int(100), "m");
      !e.empty())
    return e;
  if (auto e =
          range(at + "suspension_stiffness", w.suspension_stiffness, Fixed::zero(), big, "N/m");
      !e.empty())
    return e;
  if (auto e = range(at + "suspension_damping", w.suspension_damping, Fixed::zero(), big, "N s/m");
      !e.empty())
    return e;
  if (auto e = range(at + "max_steer_angle", w.max_steer_angle, -Fixed::half_pi(), Fixed::half_pi(),
                     "rad");
      !e.empty())
    return e;
  if (auto e = range(at + "max_brake_torque", w.max_brake_torque, Fixed::zero(), big, "N m");
      !e.empty())
    return e;
  return range(at + "inertia", w.inertia, Fixed::from_raw(Fixed::one_raw >> 16),
               Fixed::from_int(1000000), "kg m^2");
}

std::string check_vehicle_def(const WorldState& s, const VehicleDef& d, bool require_dynamic) {
  const std::ptrdiff_t c = s.find(d.chassis.value);
  if (c < 0) return "chassis: no body with ID " + std::to_string(d.chassis.value);
  if (require_dynamic && s.bodies[static_cast<std::size_t>(c)].type != BodyType::dynamic)
    return "chassis: body " + std::to_string(d.chassis.value) + " is not dynamic";
  if (d.wheels.empty() || d.wheels.size() > kMaxWheels)
    return "wheels: 1 .. 16 wheels, got " + std::to_string(d.wheels.size());
  for (std::size_t i = 0; i < d.wheels.size(); ++i)
    if (auto e = check_wheel(d.wheels[i], i); !e.empty()) return e;
  const EngineDef& e = d.engine;
  if (e.torque_curve.empty() || e.torque_curve.size() > kMaxCurvePoints)
    return "engine.torque_curve: 1 .. 16 points, got " + std::to_string(e.torque_curve.size());
  for (std::size_t i = 0; i < e.torque_curve.size(); ++i) {
    const TorquePoint& p = e.torque_curve[i];
    const std::string at = "engine.torque_curve[" + std::to_string(i) + "]";
    if (auto m = range(at + ".rpm", p.rpm, Fixed::zero(), Fixed::from_int(100000), "rpm");
        !m.empty())
      return m;
    if (auto m = range(at + ".torque", p.torque, Fixed::zero(), Fixed::from_int(100000), "N m");
        !m.empty())
      return m;
    if (i > 0 && p.rpm <= e.torque_curve[i - 1].rpm) return at + ".rpm must ascend";
  }
  if (auto m = range("engine.max_rpm", e.max_rpm, Fixed::one(), Fixed::from_int(100000), "rpm");
      !m.empty())
    return m;
  if (auto m = range("engine.idle_rpm", e.idle_rpm, Fixed::zero(), e.max_rpm, "rpm"); !m.empty())
    return m;
  if (auto m = range("engine.inertia", e.inertia, Fixed::zero(), Fixed::from_int(1000), "kg m^2");
      !m.empty())
    return m;
  if (d.gear_ratios.empty() || d.gear_ratios.size() > kMaxGears)
    return "gear_ratios: 1 .. 8 gears, got " + std::to_string(d.gear_ratios.size());
  for (std::size_t i = 0; i < d.gear_ratios.size(); ++i)
    if (auto m = range("gear_ratios[" + std::to_string(i) + "]", d.gear_ratios[i],
                       Fixed::from_raw(Fixed::one_raw >> 8), Fixed::from_int(100), "");
        !m.empty())
      return m;
  if (auto m = range("reverse_ratio", d.reverse_ratio, Fixed::from_raw(Fixed::one_raw >> 8),
                     Fixed::from_int(100), "");
      !m.empty())
    return m;
  if (auto m = range("final_drive", d.final_drive, Fixed::from_raw(Fixed::one_raw >> 8),
                     Fixed::from_int(100), "");
      !m.empty())
    return m;
  if (d.axles.size() > kMaxAxles) return "axles: at most 8, got " + std::to_string(d.axles.size());
  for (std::size_t i = 0; i < d.axles.size(); ++i) {
    const AxleDef& a = d.axles[i];
    const std::string at = "axles[" + std::to_string(i) + "]";
    if (a.left_wheel >= d.wheels.size() || a.right_wheel >= d.wheels.size() ||
        a.left_wheel == a.right_wheel)
      return at + ": left_wheel and right_wheel must be two different wheels of the " +
             std::to_string(d.wheels.size());
    if (auto m = range(at + ".anti_roll_stiffness", a.anti_roll_stiffness, Fixed::zero(),
                       Fixed::from_int(1000000000), "N/m");
        !m.empty())
      return m;
  }
  for (const auto& [name, t] : {std::pair{"tire.longitudinal", d.tire.longitudinal},
                                std::pair{"tire.lateral", d.tire.lateral}}) {
    const Fixed most = Fixed::from_int(1000);
    for (const auto& [field, value] :
         {std::pair{".b", t.b}, std::pair{".c", t.c}, std::pair{".d", t.d}}) {
      if (auto m = range(std::string(name) + field, value, Fixed::zero(), most, ""); !m.empty())
        return m;
    }
    if (auto m = range(std::string(name) + ".e", t.e, -most, most, ""); !m.empty()) return m;
  }
  return {};
}

std::string check_vehicle_input(const VehicleInput& in) {
  if (auto e = range("throttle", in.throttle, Fixed::zero(), Fixed::one(), ""); !e.empty())
    return e;
  if (auto e = range("brake", in.brake, Fixed::zero(), Fixed::one(), ""); !e.empty()) return e;
  return range("steering", in.steering, -Fixed::one(), Fixed::one(), "");
}

void wake_chassis(WorldState& s, BodyId chassis) {
  const std::ptrdiff_t i = s.find(chassis.value);
  if (i < 0) return;
  BodyState& b = s.bodies[static_cast<std::size_t>(i)];
  b.awake = true;
  b.sleep_time = Fixed::zero();
}

Status unknown_vehicle(VehicleId id) {
  return Status::error("no vehicle with ID " + std::to_string(id.value));
}

}  // namespace

std::string check_vehicle_record(const WorldState& s, const VehicleState& v) {
  if (auto e = check_vehicle_def(s, v.def, false); !e.empty()) return e;
  if (auto e = check_vehicle_input(v.input); !e.empty()) return "input." + e;
  if (v.gear > v.def.gear_ratios.size())
    return "gear must be within 0 (reverse) .. " + std::to_string(v.def.gear_ratios.size()) +
           ", got " + std::to_string(v.gear);
  if (v.wheels.size() != v.def.wheels.size())
    return std::to_string(v.wheels.size()) + " wheel states for " +
           std::to_string(v.def.wheels.size()) + " wheels";
  const Fixed most = max_velocity;
  if (auto e = range("engine_rpm", v.engine_rpm, Fixed::zero(), Fixed::from_int(1000000), "rpm");
      !e.empty())
    return e;
  if (auto e = range("forward_speed", v.forward_speed, -most, most, "m/s"); !e.empty()) return e;
  for (std::size_t i = 0; i < v.wheels.size(); ++i) {
    const WheelState& w = v.wheels[i];
    const std::string at = "wheel[" + std::to_string(i) + "].";
    if (auto e = range(at + "angular_velocity", w.angular_velocity, -most, most, "rad/s");
        !e.empty())
      return e;
    if (auto e = range(at + "compression", w.compression, Fixed::zero(),
                       v.def.wheels[i].suspension_rest_length, "m");
        !e.empty())
      return e;
    if (auto e = check_position(w.contact_point); !e.empty()) return at + "contact_" + e;
    if (!w.contact_body.is_null() && s.find(w.contact_body.value) < 0)
      return at + "contact_body " + std::to_string(w.contact_body.value) + " does not exist";
    if (w.contact && w.contact_normal == Vec3{}) return at + "contact without a contact normal";
    if (w.contact_normal != Vec3{})
      if (auto e = check_unit_vector((at + "contact_normal").c_str(), w.contact_normal); !e.empty())
        return e;
  }
  return {};
}

void forget_vehicles_of(WorldState& s, BodyId body) {
  std::erase_if(s.vehicles, [body](const VehicleState& v) { return v.def.chassis == body; });
  for (VehicleState& v : s.vehicles)
    for (WheelState& w : v.wheels)
      if (w.contact_body == body) w.contact_body = {};
}

}  // namespace sim_detail

Expected<VehicleId> World::create_vehicle(const VehicleDef& def) {
  if (auto e = sim_detail::check_vehicle_def(*s_, def, true); !e.empty())
    return Status::error("invalid vehicle definition: " + e);
  for (const VehicleState& v : s_->vehicles)
    if (v.def.chassis == def.chassis)
      return Status::error("invalid vehicle definition: chassis: body " +
                           std::to_string(def.chassis.value) + " is already vehicle " +
                           std::to_string(v.id.value) + "'s");
  if (s_->next_vehicle_id == 0xFFFFFFFFU) return Status::error("vehicle IDs are used up");
  VehicleState v;
  v.id = VehicleId{s_->next_vehicle_id++};
  v.def = def;
  v.wheels.resize(def.wheels.size());
  v.engine_rpm = def.engine.idle_rpm;
  s_->vehicles.push_back(std::move(v));
  sim_detail::wake_chassis(*s_, def.chassis);
  return s_->vehicles.back().id;
}

Status World::destroy_vehicle(VehicleId id) {
  const std::ptrdiff_t i = s_->find_vehicle(id.value);
  if (i < 0) return sim_detail::unknown_vehicle(id);
  sim_detail::wake_chassis(*s_, s_->vehicles[static_cast<std::size_t>(i)].def.chassis);
  s_->vehicles.erase(s_->vehicles.begin() + i);
  return Status::success();
}

Status World::set_vehicle_input(VehicleId id, const VehicleInput& input) {
  const std::ptrdiff_t i = s_->find_vehicle(id.value);
  if (i < 0) return sim_detail::unknown_vehicle(id);
  if (auto e = sim_detail::check_vehicle_input(input); !e.empty())
    return Status::error("vehicle " + std::to_string(id.value) + ": " + e);
  VehicleState& v = s_->vehicles[static_cast<std::size_t>(i)];
  if (v.input != input) sim_detail::wake_chassis(*s_, v.def.chassis);
  v.input = input;
  return Status::success();
}

Expected<VehicleState> World::vehicle(VehicleId id) const {
  const std::ptrdiff_t i = s_->find_vehicle(id.value);
  if (i < 0) return sim_detail::unknown_vehicle(id);
  return s_->vehicles[static_cast<std::size_t>(i)];
}

std::vector<VehicleId> World::vehicle_ids() const {
  std::vector<VehicleId> ids;
  ids.reserve(s_->vehicles.size());
  for (const VehicleState& v : s_->vehicles)
    ids.push_back(v.id);
  return ids;
}

}  // namespace detsim
