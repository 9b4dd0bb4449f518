// The sections of the canonical state (docs/STATE.md), internal to detsim::sim: what state_io.cpp
// (the container, globals, rng, contacts) and state_bodies.cpp (the bodies) share.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include <detsim/core/bytes.hpp>

#include "world_state.hpp"

namespace detsim::sim_detail {

/// The "bodies" section's payload.
void write_bodies(const WorldState& s, ByteWriter& w);
/// Reads the "bodies" payload into s.bodies (s.next_id already read), validating every field;
/// on failure returns false with `error` set ("byte N: ...") or the reader failed.
bool read_bodies(std::span<const std::uint8_t> bytes, ByteReader& r, WorldState& s,
                 std::string& error);
/// The checks restore() makes of a body's motion fields ("" when valid): what --inject must keep.
[[nodiscard]] std::string check_body_record(const BodyState& b);

}  // namespace detsim::sim_detail
