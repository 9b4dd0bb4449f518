// The "vehicles" section of the canonical state (docs/STATE.md): the next vehicle ID, then one
// record per vehicle, in ascending ID order: its ID step, its own fields (vehicle table), the
// torque curve (count, then rpm and torque per point), the gear ratios (count, then each), the
// wheels (count, then per wheel its definition's fields and its state's), the axles (count, then
// each one's fields); the tables are in vehicle_fields.hpp, encoded by record_fields.hpp. An
// optional section: written only by a world that has had a vehicle, so every other world's state
// is what it was.
#include <string>

#include "state_io.hpp"
#include "vehicle_fields.hpp"

namespace detsim::sim_detail {

namespace {

#define DETSIM_VEHICLE_REF(type, member) [](VehicleState& v) -> type& { return v.member; }
#define DETSIM_WHEEL_REF(type, member) [](WheelDef& w) -> type& { return w.member; }
#define DETSIM_WHEEL_STATE_REF(type, member) [](WheelState& w) -> type& { return w.member; }
#define DETSIM_AXLE_REF(type, member) [](AxleDef& a) -> type& { return a.member; }

constexpr VehicleField kVehicleFields[] = {
    u32_field<VehicleState>("chassis", "vehicle chassis",
                            DETSIM_VEHICLE_REF(std::uint32_t, def.chassis.value)),
    fixed_field<VehicleState>("engine.idle_rpm", "vehicle engine idle rpm",
                              DETSIM_VEHICLE_REF(Fixed, def.engine.idle_rpm)),
    fixed_field<VehicleState>("engine.max_rpm", "vehicle engine max rpm",
                              DETSIM_VEHICLE_REF(Fixed, def.engine.max_rpm)),
    fixed_field<VehicleState>("engine.inertia", "vehicle engine inertia",
                              DETSIM_VEHICLE_REF(Fixed, def.engine.inertia)),
    fixed_field<VehicleState>("reverse_ratio", "vehicle reverse ratio",
                              DETSIM_VEHICLE_REF(Fixed, def.reverse_ratio)),
    fixed_field<VehicleState>("final_drive", "vehicle final drive",
                              DETSIM_VEHICLE_REF(Fixed, def.final_drive)),
    flag_field<VehicleState>("automatic", "vehicle automatic",
                             DETSIM_VEHICLE_REF(bool, def.automatic)),
    fixed_field<VehicleState>("tire.longitudinal.b", "vehicle tire longitudinal b",
                              DETSIM_VEHICLE_REF(Fixed, def.tire.longitudinal.b)),
    fixed_field<VehicleState>("tire.longitudinal.c", "vehicle tire longitudinal c",
                              DETSIM_VEHICLE_REF(Fixed, def.tire.longitudinal.c)),
    fixed_field<VehicleState>("tire.longitudinal.d", "vehicle tire longitudinal d",
                              DETSIM_VEHICLE_REF(Fixed, def.tire.longitudinal.d)),
    fixed_field<VehicleState>("tire.longitudinal.e", "vehicle tire longitudinal e",
                              DETSIM_VEHICLE_REF(Fixed, def.tire.longitudinal.e)),
    fixed_field<VehicleState>("tire.lateral.b", "vehicle tire lateral b",
                              DETSIM_VEHICLE_REF(Fixed, def.tire.lateral.b)),
    fixed_field<VehicleState>("tire.lateral.c", "vehicle tire lateral c",
                              DETSIM_VEHICLE_REF(Fixed, def.tire.lateral.c)),
    fixed_field<VehicleState>("tire.lateral.d", "vehicle tire lateral d",
                              DETSIM_VEHICLE_REF(Fixed, def.tire.lateral.d)),
    fixed_field<VehicleState>("tire.lateral.e", "vehicle tire lateral e",
                              DETSIM_VEHICLE_REF(Fixed, def.tire.lateral.e)),
    fixed_field<VehicleState>("throttle", "vehicle throttle",
                              DETSIM_VEHICLE_REF(Fixed, input.throttle)),
    fixed_field<VehicleState>("brake", "vehicle brake", DETSIM_VEHICLE_REF(Fixed, input.brake)),
    fixed_field<VehicleState>("steering", "vehicle steering",
                              DETSIM_VEHICLE_REF(Fixed, input.steering)),
    flag_field<VehicleState>("handbrake", "vehicle handbrake",
                             DETSIM_VEHICLE_REF(bool, input.handbrake)),
    u32_field<VehicleState>("gear", "vehicle gear", DETSIM_VEHICLE_REF(std::uint32_t, gear)),
    fixed_field<VehicleState>("engine_rpm", "vehicle engine rpm",
                              DETSIM_VEHICLE_REF(Fixed, engine_rpm)),
    fixed_field<VehicleState>("forward_speed", "vehicle forward speed",
                              DETSIM_VEHICLE_REF(Fixed, forward_speed)),
};

constexpr WheelDefField kWheelDefFields[] = {
    vec3_field<WheelDef>("attachment", "wheel attachment", DETSIM_WHEEL_REF(Vec3, attachment)),
    fixed_field<WheelDef>("radius", "wheel radius", DETSIM_WHEEL_REF(Fixed, radius)),
    fixed_field<WheelDef>("suspension_rest_length", "wheel suspension rest length",
                          DETSIM_WHEEL_REF(Fixed, suspension_rest_length)),
    fixed_field<WheelDef>("suspension_stiffness", "wheel suspension stiffness",
                          DETSIM_WHEEL_REF(Fixed, suspension_stiffness)),
    fixed_field<WheelDef>("suspension_damping", "wheel suspension damping",
                          DETSIM_WHEEL_REF(Fixed, suspension_damping)),
    fixed_field<WheelDef>("max_steer_angle", "wheel max steer angle",
                          DETSIM_WHEEL_REF(Fixed, max_steer_angle)),
    flag_field<WheelDef>("driven", "wheel driven", DETSIM_WHEEL_REF(bool, driven)),
    fixed_field<WheelDef>("max_brake_torque", "wheel max brake torque",
                          DETSIM_WHEEL_REF(Fixed, max_brake_torque)),
    flag_field<WheelDef>("handbrake", "wheel handbrake", DETSIM_WHEEL_REF(bool, handbrake)),
    fixed_field<WheelDef>("inertia", "wheel inertia", DETSIM_WHEEL_REF(Fixed, inertia)),
};

constexpr WheelStateField kWheelStateFields[] = {
    fixed_field<WheelState>("angular_velocity", "wheel angular velocity",
                            DETSIM_WHEEL_STATE_REF(Fixed, angular_velocity)),
    fixed_field<WheelState>("steer_angle", "wheel steer angle",
                            DETSIM_WHEEL_STATE_REF(Fixed, steer_angle)),
    fixed_field<WheelState>("compression", "wheel compression",
                            DETSIM_WHEEL_STATE_REF(Fixed, compression)),
    flag_field<WheelState>("contact", "wheel contact", DETSIM_WHEEL_STATE_REF(bool, contact)),
    vec3_field<WheelState>("contact_point", "wheel contact point",
                           DETSIM_WHEEL_STATE_REF(Vec3, contact_point)),
    vec3_field<WheelState>("contact_normal", "wheel contact normal",
                           DETSIM_WHEEL_STATE_REF(Vec3, contact_normal)),
    u32_field<WheelState>("contact_body", "wheel contact body",
                          DETSIM_WHEEL_STATE_REF(std::uint32_t, contact_body.value)),
    fixed_field<WheelState>("slip_ratio", "wheel slip ratio",
                            DETSIM_WHEEL_STATE_REF(Fixed, slip_ratio)),
    fixed_field<WheelState>("slip_angle", "wheel slip angle",
                            DETSIM_WHEEL_STATE_REF(Fixed, slip_angle)),
    fixed_field<WheelState>("suspension_force", "wheel suspension force",
                            DETSIM_WHEEL_STATE_REF(Fixed, suspension_force)),
    fixed_field<WheelState>("longitudinal_force", "wheel longitudinal force",
                            DETSIM_WHEEL_STATE_REF(Fixed, longitudinal_force)),
    fixed_field<WheelState>("lateral_force", "wheel lateral force",
                            DETSIM_WHEEL_STATE_REF(Fixed, lateral_force)),
};

constexpr AxleField kAxleFields[] = {
    u32_field<AxleDef>("left_wheel", "axle left wheel", DETSIM_AXLE_REF(std::uint32_t, left_wheel)),
    u32_field<AxleDef>("right_wheel", "axle right wheel",
                       DETSIM_AXLE_REF(std::uint32_t, right_wheel)),
    fixed_field<AxleDef>("anti_roll_stiffness", "axle anti-roll stiffness",
                         DETSIM_AXLE_REF(Fixed, anti_roll_stiffness)),
};

#undef DETSIM_VEHICLE_REF
#undef DETSIM_WHEEL_REF
#undef DETSIM_WHEEL_STATE_REF
#undef DETSIM_AXLE_REF

// The smallest record: ID step, flags, one byte per value (22), and the four lists' counts.
constexpr std::size_t kMinVehicleBytes = 1 + 1 + 22 + 4;
constexpr std::uint32_t kMaxListEntries = 16;

/// A list's count, refused above `most` (the reader's failure names it).
std::uint32_t read_count(ByteReader& r, const char* what, std::uint32_t most) {
  const std::size_t at = r.offset();
  const std::uint32_t n = r.var32(what);
  if (r.ok() && n > most) r.fail_at(at, what, "a count within the limits of create_vehicle");
  return n;
}

}  // namespace

std::span<const VehicleField> vehicle_fields() noexcept {
  return kVehicleFields;
}
std::span<const WheelDefField> wheel_def_fields() noexcept {
  return kWheelDefFields;
}
std::span<const WheelStateField> wheel_state_fields() noexcept {
  return kWheelStateFields;
}
std::span<const AxleField> axle_fields() noexcept {
  return kAxleFields;
}

bool has_vehicles(const WorldState& s) {
  return s.next_vehicle_id != 1;
}

void clear_vehicles(WorldState& s) {
  s.vehicles.clear();
  s.next_vehicle_id = 1;
}

void write_vehicles(const WorldState& s, ByteWriter& w) {
  write_id_records(s.next_vehicle_id, s.vehicles, w, [](const VehicleState& v, ByteWriter& out) {
    write_record_fields<VehicleState>(kVehicleFields, v, out);
    out.var(v.def.engine.torque_curve.size());
    for (const TorquePoint& p : v.def.engine.torque_curve) {
      out.var_fixed(p.rpm);
      out.var_fixed(p.torque);
    }
    out.var(v.def.gear_ratios.size());
    for (const Fixed g : v.def.gear_ratios)
      out.var_fixed(g);
    out.var(v.def.wheels.size());
    for (std::size_t i = 0; i < v.def.wheels.size(); ++i) {
      write_record_fields<WheelDef>(kWheelDefFields, v.def.wheels[i], out);
      write_record_fields<WheelState>(kWheelStateFields, v.wheels[i], out);
    }
    out.var(v.def.axles.size());
    for (const AxleDef& a : v.def.axles)
      write_record_fields<AxleDef>(kAxleFields, a, out);
  });
}

bool read_vehicles(std::span<const std::uint8_t>, ByteReader& r, WorldState& s,
                   std::string& error) {
  return read_id_records(
      r, "vehicle", 2, kMinVehicleBytes, s.next_vehicle_id, s.vehicles, error,
      [&](VehicleState& v, std::size_t at) {
        if (!read_record_fields<VehicleState>(kVehicleFields, "vehicle flags", v, r, error))
          return false;
        v.def.engine.torque_curve.resize(read_count(r, "torque curve points", kMaxListEntries));
        for (TorquePoint& p : v.def.engine.torque_curve) {
          p.rpm = r.var_fixed("torque curve rpm");
          p.torque = r.var_fixed("torque curve torque");
        }
        v.def.gear_ratios.resize(read_count(r, "gear ratios", kMaxListEntries));
        for (Fixed& g : v.def.gear_ratios)
          g = r.var_fixed("gear ratio");
        const std::uint32_t wheels = read_count(r, "wheels", kMaxListEntries);
        v.def.wheels.resize(wheels);
        v.wheels.resize(wheels);
        for (std::uint32_t i = 0; i < wheels && r.ok(); ++i) {
          if (!read_record_fields<WheelDef>(kWheelDefFields, "wheel flags", v.def.wheels[i], r,
                                            error) ||
              !read_record_fields<WheelState>(kWheelStateFields, "wheel state flags", v.wheels[i],
                                              r, error))
            return false;
        }
        v.def.axles.resize(read_count(r, "axles", kMaxListEntries));
        for (AxleDef& a : v.def.axles)
          if (!read_record_fields<AxleDef>(kAxleFields, "axle flags", a, r, error)) return false;
        if (!r.ok()) return false;
        if (auto e = check_vehicle_record(s, v); !e.empty()) {
          error =
              "byte " + std::to_string(at) + ": vehicle " + std::to_string(v.id.value) + ": " + e;
          return false;
        }
        return true;
      });
}

}  // namespace detsim::sim_detail
