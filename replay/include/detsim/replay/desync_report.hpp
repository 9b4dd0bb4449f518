// Desync reports (replay/FORMAT.md, "Desync reports"): one machine's side of a desync, as a
// session writes it when a peer hashed a confirmed frame differently. It carries what the
// bisection tool needs to find the first divergent body and field without that machine: the run's
// fingerprint, every confirmed frame's inputs up to the divergence, this machine's full state at
// the last agreed frame and at the first divergent one, and per-body hashes of both states.
//
// The file is checked whole when read (magic, version, sizes against the bytes that remain,
// an XXH3 checksum of the payload); errors name the file, the byte offset and what was expected.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <detsim/core/status.hpp>
#include <detsim/replay/replay.hpp>
#include <detsim/sim/world.hpp>

namespace detsim::replay {

/// The version written; version 1 (without `origin` and `intermediate_states`) is still read.
inline constexpr std::uint32_t desync_report_version = 2;
/// The largest report file read_desync_report() reads (two states of ~150,000 bodies and hours
/// of inputs fit).
inline constexpr std::size_t max_desync_report_size = std::size_t{256} << 20;

struct BodyHash {
  std::uint32_t id = 0;
  std::uint64_t hash = 0;

  friend constexpr bool operator==(const BodyHash&, const BodyHash&) noexcept = default;
};

/// One machine's state at one frame.
struct FrameState {
  std::uint64_t frame = 0;
  std::vector<std::uint8_t> state;  ///< World::save()

  friend bool operator==(const FrameState&, const FrameState&) = default;
};

/// Who wrote a report.
enum class ReportOrigin : std::uint8_t {
  session = 0,  ///< a peer of a net session that saw a peer's hash differ
  verify = 1,   ///< `detsim verify --report`: this machine's re-simulation of a replay
};

struct DesyncReport {
  Fingerprint fingerprint;
  ReportOrigin origin = ReportOrigin::session;
  std::uint32_t reporter = 0;  ///< the player whose machine wrote the report (0 for verify)
  std::uint32_t other = 0;     ///< the player it disagreed with (0 for verify)
  std::uint64_t agreed_frame = 0;
  std::uint64_t divergent_frame = 0;
  std::uint64_t local_hash = 0;   ///< this machine's hash of divergent_frame
  std::uint64_t remote_hash = 0;  ///< the other's
  /// Confirmed frames 0 .. divergent_frame - 1, each 1 + players * input_size bytes: a byte whose
  /// bit p says player p was disconnected, then every player's input.
  std::vector<std::uint8_t> confirmed_frames;
  std::vector<std::uint8_t> agreed_state;     ///< World::save() at agreed_frame
  std::vector<std::uint8_t> divergent_state;  ///< World::save() at divergent_frame
  std::vector<BodyHash> agreed_bodies;        ///< ascending ID
  std::vector<BodyHash> divergent_bodies;
  /// This machine's states at the frames strictly between agreed_frame and divergent_frame,
  /// ascending: either every one of them or none (then bisection knows only the two ends).
  std::vector<FrameState> intermediate_states;

  friend bool operator==(const DesyncReport&, const DesyncReport&) = default;
};

/// The per-body hashes of a saved World state, ascending ID, restored into a copy of `geometry`:
/// a world that holds the geometry the state names (the scenario's); an error if it does not
/// restore.
Expected<std::vector<BodyHash>> body_hashes(const World& geometry,
                                            std::span<const std::uint8_t> state);
/// The same against a world without geometry: for states that name none.
Expected<std::vector<BodyHash>> body_hashes(std::span<const std::uint8_t> state);

/// Writes `report` to `path` (replacing it).
Status write_desync_report(const std::string& path, const DesyncReport& report);
/// Reads and validates a report.
Expected<DesyncReport> read_desync_report(const std::string& path);
/// The same from bytes; `name` stands for the file in messages.
Expected<DesyncReport> parse_desync_report(std::span<const std::uint8_t> bytes,
                                           const std::string& name);

}  // namespace detsim::replay
