// The match snapshot a session sends a rejoining player (docs/NET.md, "Rejoining"): the state of
// the oldest frame every peer holds as final, and every input the sender holds from just before
// it on, so the rejoining side can re-simulate to the present and go on sending its own inputs
// where the peers' copy of them ends.
//
//     envelope  magic "DSNP" | compression u8 (0: none, 1: zstd) | size u64 (of the payload
//               uncompressed) | payload
//     payload   frame u64 | present u64 | players u8 | input_size u8 |
//               per player: disconnect u64 (~0: connected) | absent_from u64 |
//                           absent_until u64 | first u64 | count u32 |
//                           count * input_size bytes (the inputs of frames first ..) |
//               log_size u64 | log bytes (every confirmed frame before `frame`, as a session's
//                              frame log holds them: 1 + players * input_size bytes each) |
//               state_size u64 | state bytes (Game::save of `frame`)
//
// Integers little-endian. decode_snapshot() checks every field against the receiving session
// before anything is used, and bounds what it allocates whatever the bytes say.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <detsim/core/status.hpp>

namespace detsim::net::detail {

/// The largest snapshot payload accepted, uncompressed.
inline constexpr std::size_t max_snapshot_payload = std::size_t{256} << 20;

struct SnapshotPlayer {
  std::uint64_t disconnect = ~std::uint64_t{0};  ///< the player's disconnect frame, or ~0
  std::uint64_t absent_from = 0;     ///< the frames it was away before joining an open seat
  std::uint64_t absent_until = 0;    ///< (empty when from == until)
  std::uint64_t first = 0;           ///< the frame of inputs[0]
  std::vector<std::uint8_t> inputs;  ///< whole inputs from `first` on
};

struct Snapshot {
  std::uint64_t frame = 0;    ///< the state's frame: every frame before it is final everywhere
  std::uint64_t present = 0;  ///< the sender's current frame when it was taken
  std::uint32_t input_size = 0;
  std::vector<SnapshotPlayer> players;
  std::vector<std::uint8_t> log;  ///< frames 0 .. frame - 1: a mask of gone players, the inputs
  std::vector<std::uint8_t> state;
};

/// The snapshot's bytes: zstd-compressed where the build has zstd and `compress` says so.
[[nodiscard]] std::vector<std::uint8_t> encode_snapshot(const Snapshot& snapshot,
                                                        bool compress = true);

/// The snapshot in `bytes`, checked against a session of `players` players with inputs of
/// `input_size` bytes holding `capacity` inputs per player; errors say which field is wrong.
[[nodiscard]] Expected<Snapshot> decode_snapshot(std::span<const std::uint8_t> bytes,
                                                 std::uint32_t players, std::uint32_t input_size,
                                                 std::size_t capacity);

}  // namespace detsim::net::detail
