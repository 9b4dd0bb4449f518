// The snapshots a net::Server sends its clients (docs/SERVER.md, "Snapshots"): a client joining a
// match in progress gets a full one; under Authority::state every client gets one every
// snapshot_interval frames, delta-coded against the newest it acknowledged.
//
//     envelope  magic "DGSN", zstd-compressed (envelope.hpp) with the base state as its prefix
//               (a full snapshot: none)
//     payload   frame u64 | players u8 | input_size u8 | unit of frame - 1 (unit_size bytes) |
//               state_size u64 | state bytes
//
// A canonical state changes little between two snapshots: zstd codes every run of the state
// that the base holds too as a reference into the base, a few bytes a run wherever the run moved
// to (a state's records are of varying length, so a byte-wise XOR against the base would be
// misaligned after the first record that changed length). What is left is what moved. Integers
// little-endian; decode checks every field and bounds what it allocates, whatever the bytes say.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <detsim/core/status.hpp>

namespace detsim::net::detail {

/// Authority::state: the snapshot states a server keeps as bases, and a client keeps to decode
/// against. A client acknowledges one within a round trip; the server codes each snapshot against
/// the newest it heard acknowledged (older than the client's newest by up to a round trip), and a
/// client whose newest acknowledged one is older than these gets a full snapshot.
inline constexpr std::size_t kept_snapshot_states = 32;

/// The largest state a server snapshot carries, uncompressed.
inline constexpr std::size_t max_server_state = std::size_t{256} << 20;

struct ServerSnapshot {
  std::uint64_t frame = 0;
  std::vector<std::uint8_t> unit;   ///< the unit of frame - 1 (all zero, all absent, for frame 0)
  std::vector<std::uint8_t> state;  ///< Game::save at `frame`
};

/// The snapshot's bytes, delta-coded against `base` (a state the client holds) when given.
/// A build without zstd sends the state whole.
[[nodiscard]] std::vector<std::uint8_t> encode_server_snapshot(
    const ServerSnapshot& snapshot, std::uint32_t players, std::uint32_t input_size,
    const std::vector<std::uint8_t>* base);

/// The snapshot in `bytes`, for a match of `players` with `input_size`-byte inputs, undoing the
/// delta against `base` when the sender coded one; errors say which field is wrong.
[[nodiscard]] Expected<ServerSnapshot> decode_server_snapshot(
    std::span<const std::uint8_t> bytes, std::uint32_t players, std::uint32_t input_size,
    const std::vector<std::uint8_t>* base);

}  // namespace detsim::net::detail
