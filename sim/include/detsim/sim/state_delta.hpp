// Delta coding of saved states (docs/STATE.md, "Deltas"): a state coded against an earlier state
// of the same world, for sending it where the earlier one is held (a server's snapshots to its
// clients, docs/SERVER.md).
//
// A delta has the state's container and sections ("DSDL" in place of "DSIM"). The "bodies" and
// "contacts" sections hold every number that moves as its difference from a prediction made from
// the base: a body's motion from the base's body of the same ID (its position carried on at its
// velocity for the frames between the two states), a contact point's impulses from the base's at
// the same feature of the same pair. A body or contact point the base lacks is as in the state;
// every other section is copied. Nothing is lost: decode_state_delta(encode_state_delta(s, b), b)
// is s, byte for byte. What the delta gains is size after a general compressor: a body at rest
// codes as zeros, a moving body as the few bits by which it left its predicted path, where its
// absolute position and velocity are eight bytes of noise each.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <detsim/core/status.hpp>

namespace detsim {

/// `state` coded against `base` (both World::save bytes of this build's encoding; any two states,
/// though the closer they are the smaller the delta). Errors name what is not a state.
[[nodiscard]] Expected<std::vector<std::uint8_t>> encode_state_delta(
    std::span<const std::uint8_t> state, std::span<const std::uint8_t> base);

/// The state `delta` was coded from, given the same `base`; errors name what is wrong. Its size
/// is at most ten times the delta's plus the base's. A delta against another base gives another
/// state, which a state hash (not this function) tells apart.
[[nodiscard]] Expected<std::vector<std::uint8_t>> decode_state_delta(
    std::span<const std::uint8_t> delta, std::span<const std::uint8_t> base);

}  // namespace detsim
