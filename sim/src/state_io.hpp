// The sections of the canonical state (docs/STATE.md), internal to detsim::sim: what state_io.cpp
// (the container, globals, rng, contacts), state_bodies.cpp (the bodies) and state_joints.cpp
// (the joints) share.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include <detsim/core/bytes.hpp>
#include <detsim/core/status.hpp>
#include <detsim/sim/state_sections.hpp>

#include "world_state.hpp"

namespace detsim::sim_detail {

/// The "bodies" section's payload.
void write_geometry(const WorldState& s, ByteWriter& w);
bool read_geometry(std::span<const std::uint8_t> bytes, ByteReader& r, WorldState& s,
                   std::string& error);
void write_bodies(const WorldState& s, ByteWriter& w);
/// Reads the "bodies" payload into s.bodies (s.next_id already read), validating every field;
/// on failure returns false with `error` set ("byte N: ...") or the reader failed.
bool read_bodies(std::span<const std::uint8_t> bytes, ByteReader& r, WorldState& s,
                 std::string& error);
/// The "joints" payload (state_joints.cpp), and its reader (bodies already read).
void write_joints(const WorldState& s, ByteWriter& w);
bool read_joints(std::span<const std::uint8_t> bytes, ByteReader& r, WorldState& s,
                 std::string& error);
/// The "particles" payload (state_particles.cpp), and its reader (bodies already read).
void write_particles(const WorldState& s, ByteWriter& w);
/// One group's record (its ID step from `previous_id`), as write_particles writes it.
void write_particle_group(const ParticleGroup& g, std::uint32_t previous_id, ByteWriter& w);
bool read_particles(std::span<const std::uint8_t> bytes, ByteReader& r, WorldState& s,
                    std::string& error);
/// The optional "vehicles" payload (state_vehicles.cpp), written when the world has had a
/// vehicle; its reader (bodies already read), and what a state without it reads as.
void write_vehicles(const WorldState& s, ByteWriter& w);
bool read_vehicles(std::span<const std::uint8_t> bytes, ByteReader& r, WorldState& s,
                   std::string& error);
[[nodiscard]] bool has_vehicles(const WorldState& s);
void clear_vehicles(WorldState& s);
/// The optional "characters" payload (state_characters.cpp), written when the world has had a
/// character; its reader (bodies already read), and what a state without it reads as.
void write_characters(const WorldState& s, ByteWriter& w);
bool read_characters(std::span<const std::uint8_t> bytes, ByteReader& r, WorldState& s,
                     std::string& error);
[[nodiscard]] bool has_characters(const WorldState& s);
void clear_characters(WorldState& s);
/// The checks restore() makes of a joint against the bodies of `s` ("" when valid): what --inject
/// must keep.
[[nodiscard]] std::string check_joint_record(const WorldState& s, const JointState& j);
/// The checks restore() makes of a particle group's state (attachments, particles, force, sleep
/// time, tether impulse) against the bodies of `s` ("" when valid): what --inject must keep.
[[nodiscard]] std::string check_particle_record(const WorldState& s, const ParticleGroup& g);
/// The checks restore() makes of a body's motion fields ("" when valid): what --inject must keep.
[[nodiscard]] std::string check_body_record(const BodyState& b);

// ---- Delta coding (state_delta.cpp) ----

/// `v` plus (`add`) or minus `by`, wrapping: a delta's difference is any 64-bit pattern, and the
/// opposite shift undoes it exactly.
[[nodiscard]] inline Fixed shifted_value(Fixed v, Fixed by, bool add) noexcept {
  const auto a = static_cast<std::uint64_t>(v.raw());
  const auto b = static_cast<std::uint64_t>(by.raw());
  return Fixed::from_raw(static_cast<std::int64_t>(add ? a + b : a - b));
}

/// The sections of `bytes` whose first four bytes are `magic` (a state's "DSIM", a delta's
/// "DSDL"); `expected` names the magic in the error.
[[nodiscard]] Expected<std::vector<StateSection>> read_sections(std::span<const std::uint8_t> bytes,
                                                                std::uint32_t magic,
                                                                const char* expected);
/// The frame and the step time in a "globals" section.
bool read_frame_and_step(std::span<const std::uint8_t> bytes, const StateSection& globals,
                         std::uint64_t& frame, Fixed& dt, std::string& error);
/// Writes the "bodies" payload `section` of `bytes` with every body's motion values moved by
/// (`add`) or less (not `add`) its prediction from the body of the same ID in the base's payload
/// `base`: the base's values, its position carried on for `ahead` seconds at its velocity. A body
/// the base lacks is written as it is. The payloads are read without their semantic checks.
bool shift_bodies(std::span<const std::uint8_t> bytes, const StateSection& section,
                  std::span<const std::uint8_t> base_bytes, const StateSection& base, Fixed ahead,
                  bool add, ByteWriter& out, std::string& error);
/// The same for the "contacts" payload: each point's impulses against the base's at the same
/// feature of the same pair of sub-shapes.
bool shift_contacts(std::span<const std::uint8_t> bytes, const StateSection& section,
                    std::span<const std::uint8_t> base_bytes, const StateSection& base, bool add,
                    ByteWriter& out, std::string& error);

}  // namespace detsim::sim_detail
