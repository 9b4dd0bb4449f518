// The canonical state as a list of sections (docs/STATE.md): the container that World::save()
// writes, and that replays, desync reports, diff and bisect read without knowing what each section
// holds.
//
//   u32 magic "DSIM", u32 encoding version (5), var section count, then each section:
//   var name length, the name (1..32 bytes of a-z 0-9 _ .), var section version, u32 payload
//   length, the payload.
//
// A section's hash is the XXH3-64 of its whole record (name, version, length and payload), so a
// change of a section's version changes its hash; the state's hash is the XXH3-64 of all bytes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <detsim/core/status.hpp>

namespace detsim {

/// The version of the canonical state encoding that World::save() writes and World::restore()
/// reads. Replays record it: a keyframe can be restored only by a build that reads it.
inline constexpr std::uint32_t state_encoding_version = 6;

/// The longest section name.
inline constexpr std::size_t max_section_name = 32;

/// One section of a state, as found in its bytes (views into them).
struct StateSection {
  std::string_view name;
  std::uint32_t version = 0;
  std::size_t offset = 0;  ///< of the section's record (its name length) in the state's bytes
  std::span<const std::uint8_t> record;   ///< the whole record: what the section's hash covers
  std::span<const std::uint8_t> payload;  ///< the section's own bytes
  std::size_t payload_offset = 0;         ///< of the payload in the state's bytes
};

/// The sections of `bytes`, in order, checking the container only (magic, version, names, lengths,
/// no two sections of one name, nothing after the last): the payloads are not decoded. Errors
/// name the byte ("byte 17: section name: expected ...").
[[nodiscard]] Expected<std::vector<StateSection>> read_state_sections(
    std::span<const std::uint8_t> bytes);

/// Whether `name` may name a section: 1..32 bytes, each a-z, 0-9, '_' or '.'.
[[nodiscard]] bool valid_section_name(std::string_view name) noexcept;

/// XXH3-64 of a section's record (its hash in StateHashes).
[[nodiscard]] std::uint64_t section_hash(const StateSection& section) noexcept;

}  // namespace detsim
