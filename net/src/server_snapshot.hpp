// The snapshots a net::Server sends its clients (docs/SERVER.md, "Snapshots"): a client joining a
// match in progress gets a full one; under Authority::state every client gets one every
// snapshot_interval frames, delta-coded against the newest it acknowledged.
//
//     envelope  magic "DGSN", compressed (envelope.hpp)
//     payload   frame u64 | players u8 | input_size u8 | unit of frame - 1 (unit_size bytes) |
//               state_size u64 | state bytes, XORed with the base state over their common length
//               (a full snapshot: the bytes as they are)
//
// A canonical state changes little between two snapshots, so the XORed bytes are zero wherever
// nothing moved and compress to almost nothing. Integers little-endian; decode checks every field
// and bounds what it allocates, whatever the bytes say.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <detsim/core/status.hpp>

namespace detsim::net::detail {

/// The largest state a server snapshot carries, uncompressed.
inline constexpr std::size_t max_server_state = std::size_t{256} << 20;

struct ServerSnapshot {
  std::uint64_t frame = 0;
  std::vector<std::uint8_t> unit;   ///< the unit of frame - 1 (all zero, all absent, for frame 0)
  std::vector<std::uint8_t> state;  ///< Game::save at `frame`
};

/// The snapshot's bytes, delta-coded against `base` (a state the client holds) when given.
[[nodiscard]] std::vector<std::uint8_t> encode_server_snapshot(
    const ServerSnapshot& snapshot, std::uint32_t players, std::uint32_t input_size,
    const std::vector<std::uint8_t>* base);

/// The snapshot in `bytes`, for a match of `players` with `input_size`-byte inputs, undoing the
/// delta against `base` when the sender coded one; errors say which field is wrong.
[[nodiscard]] Expected<ServerSnapshot> decode_server_snapshot(
    std::span<const std::uint8_t> bytes, std::uint32_t players, std::uint32_t input_size,
    const std::vector<std::uint8_t>* base);

}  // namespace detsim::net::detail
