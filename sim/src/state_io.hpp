// The sections of the canonical state (docs/STATE.md), internal to detsim::sim: what state_io.cpp
// (the container, globals, rng, contacts), state_bodies.cpp (the bodies) and state_joints.cpp
// (the joints) share.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include <detsim/core/bytes.hpp>

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

}  // namespace detsim::sim_detail
