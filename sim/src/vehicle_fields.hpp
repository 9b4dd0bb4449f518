// A vehicle's fields, listed once (the mechanism: record_fields.hpp). Internal to detsim::sim.
//
// A vehicle is a record with lists in it, so it has four tables: the vehicle's own scalars (its
// chassis, engine, gearbox, tire, input, gear and outputs), a wheel's definition, a wheel's state
// and an axle. The "vehicles" state section (state_vehicles.cpp), the field-level diff
// (state_diff.cpp) and fault injection (inject.cpp) walk them; the torque curve and the gear
// ratios are lists of plain numbers beside them.
#pragma once

#include <span>
#include <string>

#include <detsim/sim/vehicle.hpp>

#include "record_fields.hpp"

namespace detsim::sim_detail {

struct WorldState;

using VehicleField = RecordField<VehicleState>;
using WheelDefField = RecordField<WheelDef>;
using WheelStateField = RecordField<WheelState>;
using AxleField = RecordField<AxleDef>;

[[nodiscard]] std::span<const VehicleField> vehicle_fields() noexcept;
[[nodiscard]] std::span<const WheelDefField> wheel_def_fields() noexcept;
[[nodiscard]] std::span<const WheelStateField> wheel_state_fields() noexcept;
[[nodiscard]] std::span<const AxleField> axle_fields() noexcept;

/// What a saved vehicle must satisfy against the bodies of `s` ("" when it does): every check
/// create_vehicle makes of its definition except that the chassis be dynamic (set_type may change
/// it later; the solver then leaves the vehicle be), and its state's ranges.
[[nodiscard]] std::string check_vehicle_record(const WorldState& s, const VehicleState& v);

}  // namespace detsim::sim_detail
