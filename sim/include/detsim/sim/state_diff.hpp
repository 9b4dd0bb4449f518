// Field-level comparison of two saved World states (World::save() bytes): which subsystem differs,
// which bodies, which fields, with both values in decimal and raw hex. What `detsim diff` prints
// and what desync bisection reports at the first divergent frame.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <detsim/core/status.hpp>
#include <detsim/sim/world.hpp>

namespace detsim {

/// One difference between state A and state B.
struct FieldDiff {
  /// The state section the field is in (a World's: "globals", "geometry", "rng", "bodies",
  /// "contacts", "joints", "particles", and "game" for a game's own state).
  std::string subsystem;
  /// The body the field belongs to, in any section ("bodies": the body; "contacts": the pair's
  /// lower ID); 0 for a field of no body (a joint's). A section's own "hash" line has 0.
  std::uint32_t body = 0;
  /// e.g. "position.y", "orientation.w", "angular_velocity.x", "sleep_time", "frame", "state[2]";
  /// "present" when the body exists on one side only; for a contact of `body` with body 23:
  /// "contact[23].point[0].normal_impulse", "contact[23].touching", "contact[23].present"; a
  /// contact between sub-shapes (a compound's part, a surface's triangle) other than 0 and 0 names
  /// them after the other body: "contact[23/2/0].touching" (sub-shape 2 of `body` against
  /// sub-shape 0 of body 23), the syntax --inject takes (inject.hpp); for joint 7:
  /// "joint[7].linear_impulse.x", "joint[7].broken", "joint[7].present"; for the geometry that
  /// the state names (registered geometry 3): "geometry[3]", with the values as the type and
  /// content hash ("convex hull, content hash 0x..." or "absent"); in the game's own state
  /// (body 0): a described field by its name ("score.player1"), "size", and runs of bytes no
  /// field describes as "bytes[12..15]" with their hex digits.
  std::string field;
  std::string a;  ///< the value in A: decimal, then the raw bits ("0.5 (0x0000000080000000)")
  std::string b;  ///< the value in B, alike; "absent" for a body missing on that side
};

struct StateDiff {
  StateHashes a;  ///< of state A
  StateHashes b;
  std::uint64_t frame_a = 0;
  std::uint64_t frame_b = 0;
  /// In order: globals, rng, bodies by ascending ID (fields in declaration order), contacts,
  /// joints by ascending ID.
  std::vector<FieldDiff> fields;
  /// Differences found beyond max_fields (not listed).
  std::size_t omitted = 0;
  /// Empty when every section was compared. Otherwise why only some were: the states name
  /// different geometry ("geometry[N]" lines) and one of them does not restore against the world
  /// given, so only the geometry and the sections' hashes are listed.
  std::string note;

  [[nodiscard]] bool equal() const noexcept { return a == b; }
};

/// The sections whose hashes differ (or that one side lacks), in A's order, then B's extras.
[[nodiscard]] std::vector<std::string> differing_subsystems(const StateHashes& a,
                                                            const StateHashes& b);

/// Compares two saved states field by field, listing at most `max_fields` differences. Each state
/// is restored into a copy of `geometry`, so that world must hold the geometry the states name
/// (registered in the same order: the scenario's or game's world that saved them; its bodies do
/// not matter). Where the states name different geometry, the differing entries are listed
/// ("geometry[N]": type and content hash on each side) first; if one side then cannot be restored,
/// the diff lists only those and the sections' hashes, and says so in `note`. An error names the
/// side ("state A: byte 12: ...") when a state does not restore for any other reason (a corrupt
/// state, or geometry the world lacks).
Expected<StateDiff> diff_states(const World& geometry, std::span<const std::uint8_t> a,
                                std::span<const std::uint8_t> b, std::size_t max_fields = 1000);
/// diff_states against a world without geometry: enough for states that name none.
Expected<StateDiff> diff_states(std::span<const std::uint8_t> a, std::span<const std::uint8_t> b,
                                std::size_t max_fields = 1000);

}  // namespace detsim
