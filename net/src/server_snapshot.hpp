// The snapshots a net::Server sends its clients (docs/SERVER.md, "Snapshots"): a client joining a
// match in progress gets a full one; under Authority::state every client gets one every
// snapshot_interval frames, delta-coded against the newest it acknowledged.
//
//     envelope  magic "DGSN" (the state) or "DGSD" (the game's delta of the state against the
//               base, Game::encode_delta), zstd-compressed (envelope.hpp, level 9) with a
//               prefix: none for a full snapshot; else the base state ("DGSN") or the game's
//               delta of the base against itself ("DGSD")
//     payload   frame u64 | players u8 | input_size u8 | unit of frame - 1 (unit_size bytes) |
//               size u64 | the state, or its delta
//
// A canonical state changes little between two snapshots: zstd codes every run of the state
// that the prefix holds too as a reference into it, a few bytes a run wherever the run moved to
// (a state's records are of varying length, so a byte-wise XOR against the base would be
// misaligned after the first record that changed length). What is left is what moved. A game that
// codes deltas (a World's: detsim::encode_state_delta) sends what moved as its difference from a
// prediction, and everything that did not as zeros, which the base's delta against itself holds
// in the same places. Integers little-endian; decode checks every field and bounds what it
// allocates, whatever the bytes say.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <detsim/core/status.hpp>

namespace detsim::net {
class Game;
}  // namespace detsim::net

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

/// The zstd level of snapshots: at 9 a 100 KB state against its base compresses in about 1.5 ms
/// and to 0.78 of level 3's bytes (docs/SERVER.md, "Figures").
inline constexpr int snapshot_compression_level = 9;

/// The snapshot's bytes, delta-coded against `base` (a state the client holds) when given, by
/// `game`'s encode_delta where it codes one. A build without zstd sends the state whole.
[[nodiscard]] std::vector<std::uint8_t> encode_server_snapshot(
    const ServerSnapshot& snapshot, std::uint32_t players, std::uint32_t input_size,
    const std::vector<std::uint8_t>* base, Game& game);

/// Whether encode_server_snapshot coded `bytes` as the game's delta.
[[nodiscard]] bool is_game_delta(std::span<const std::uint8_t> bytes) noexcept;

/// The snapshot in `bytes`, for a match of `players` with `input_size`-byte inputs, undoing the
/// delta against `base` when the sender coded one (a game's delta by `game`'s decode_delta);
/// errors say which field is wrong.
[[nodiscard]] Expected<ServerSnapshot> decode_server_snapshot(std::span<const std::uint8_t> bytes,
                                                              std::uint32_t players,
                                                              std::uint32_t input_size,
                                                              const std::vector<std::uint8_t>* base,
                                                              Game& game);

}  // namespace detsim::net::detail
