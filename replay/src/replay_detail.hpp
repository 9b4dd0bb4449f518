// Internals of the replay format shared by its reader, writer and the scenario layer.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <detsim/core/bytes.hpp>
#include <detsim/replay/replay.hpp>

namespace detsim::replay::detail {

inline constexpr char kFileMagic[9] = "DSREPLAY";
inline constexpr std::size_t kFileHeaderSize = 16;

/// A chunk type: four ASCII bytes, read as a little-endian u32.
constexpr std::uint32_t chunk_type(const char (&name)[5]) noexcept {
  return static_cast<std::uint32_t>(static_cast<unsigned char>(name[0])) |
         static_cast<std::uint32_t>(static_cast<unsigned char>(name[1])) << 8 |
         static_cast<std::uint32_t>(static_cast<unsigned char>(name[2])) << 16 |
         static_cast<std::uint32_t>(static_cast<unsigned char>(name[3])) << 24;
}

inline constexpr std::uint32_t kChunkHead = chunk_type("HEAD");
inline constexpr std::uint32_t kChunkFrames = chunk_type("FRAM");
inline constexpr std::uint32_t kChunkKeyframe = chunk_type("KEYF");
inline constexpr std::uint32_t kChunkEnd = chunk_type("END ");

inline constexpr std::uint32_t max_players = 64;
/// The most state sections a fingerprint lists.
inline constexpr std::size_t max_state_sections = 32;
inline constexpr std::uint32_t max_input_size = 1024;

/// 16 lowercase hex digits.
std::string hex64(std::uint64_t v);
/// A chunk type as text ('?' for bytes that are not printable).
std::string chunk_name(std::uint32_t type);

void write_fingerprint(const Fingerprint& f, ByteWriter& w);
/// Reads and validates a fingerprint payload; false with the reader's error set.
bool read_fingerprint(ByteReader& r, Fingerprint& f);
/// One frame's inputs of a scenario (players inputs of input_size bytes) into `out`, with the
/// inputs of every player whose bit is set in `gone` (a desync report's "disconnected" byte) zero:
/// what Scenario::step_encoded takes.
void gone_zeroed(std::span<const std::uint8_t> bytes, std::size_t input_size, std::uint8_t gone,
                 std::vector<std::uint8_t>& out);
void encode_hashes(const StateHashes& h, ByteWriter& w);
StateHashes decode_hashes(ByteReader& r, const std::vector<std::string>& sections);

}  // namespace detsim::replay::detail
