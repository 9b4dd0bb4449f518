// Recording, verifying and seeking replays of the registered scenarios
// (<detsim/scenes/scenario.hpp>): what `detsim run --record`, `detsim verify` and the golden
// replays use.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include <detsim/core/status.hpp>
#include <detsim/replay/desync_report.hpp>
#include <detsim/replay/replay.hpp>
#include <detsim/scenes/scenario.hpp>

namespace detsim::replay {

/// Called after each frame with (frames done, frames in all); return false to stop early.
using Progress = std::function<bool(std::uint64_t done, std::uint64_t total)>;

/// The inputs of every player at a frame (player order). Default: scripted_input with the
/// scenario's seed.
using InputSource = std::function<void(std::uint64_t frame, std::span<PlayerInput> out)>;
/// The same in the scenario's input bytes (players * info().input_size, player order): the way
/// to feed a game with its own input (ScenarioDefinition::input_size). Default: Scenario::scripted.
using InputBytesSource = std::function<void(std::uint64_t frame, std::span<std::uint8_t> out)>;

/// Called after each step, before the frame's hashes are taken (scenario.world().frame() is the
/// frame just made): a fault injection (<detsim/sim/inject.hpp>) for tests and demos. An error
/// stops the run with that error.
using AfterStep = std::function<Status(Scenario& scenario)>;

struct RecordOptions {
  std::uint32_t frames = 0;  ///< 0: the scenario's default
  std::uint32_t keyframe_interval = default_keyframe_interval;
  InputSource inputs;  ///< empty: scripted_input(seed, frame, player); PlayerInput games only
  InputBytesSource input_bytes;  ///< any game; takes precedence over `inputs`
  Progress progress;             ///< optional
  AfterStep after_step;          ///< optional
};

struct RecordResult {
  std::uint64_t frames = 0;
  std::uint64_t final_hash = 0;
  std::uint64_t chain_hash = 0;
};

/// Runs `scenario` from its current state (which must be frame 0) for options.frames frames and
/// records the replay to `path` (unless `path` is empty: then it only runs).
Expected<RecordResult> record(Scenario& scenario, const std::string& path,
                              const RecordOptions& options = {});

/// What verification found.
struct VerifyResult {
  bool ok = false;
  std::uint64_t frames = 0;                     ///< frames re-simulated and compared
  std::optional<std::uint64_t> first_mismatch;  ///< the first frame whose hash differs
  StateHashes expected;                         ///< at first_mismatch (from the file)
  StateHashes actual;                           ///< at first_mismatch (re-simulated)
  std::uint64_t final_hash = 0;                 ///< re-simulated hash of the last frame compared
  std::string note;  ///< e.g. the file ended early, or a keyframe disagreed; empty otherwise
  /// When asked for (VerifyOptions::report): this machine's side at the first mismatch or at
  /// report_at, as a desync report (origin verify) with the states of that frame and the one
  /// before; empty when there was nothing to report (no mismatch, or a mismatch at frame 0).
  std::optional<DesyncReport> report;
};

struct VerifyOptions {
  Progress progress;     ///< optional
  AfterStep after_step;  ///< optional, as in RecordOptions
  /// Keep this machine's side of the first mismatch as VerifyResult::report.
  bool report = false;
  /// Report this frame (1 .. frame_count()) instead, whether or not verification passes: frames
  /// are re-simulated up to it even after a mismatch. Implies report.
  std::optional<std::uint64_t> report_at;
};

/// Re-creates the recorded scenario and re-simulates every frame with the recorded inputs,
/// comparing each frame's hashes; also checks every keyframe's state against its frame's hash and
/// the end marker's chain hash. Errors (not mismatches): a fingerprint this build cannot reproduce
/// (unknown scenario, other Fixed format or input size), which the message names.
Expected<VerifyResult> verify(const ReplayReader& reader, const VerifyOptions& options);
Expected<VerifyResult> verify(const ReplayReader& reader, const Progress& progress = {});

/// The recorded scenario at frame `frame` (0 .. frame_count()): restores the nearest keyframe at
/// or before it and re-simulates the rest with the recorded inputs (at most one keyframe interval).
/// `resimulated`, when given, receives the number of frames stepped.
Expected<Scenario> seek(const ReplayReader& reader, std::uint64_t frame,
                        std::uint64_t* resimulated = nullptr);

/// The scenario a replay was recorded from, at frame 0 (checks the fingerprint, as verify does).
Expected<Scenario> scenario_of(const ReplayReader& reader);
/// The same from a fingerprint (of a replay or a desync report); `name` names it in messages.
Expected<Scenario> scenario_of(const Fingerprint& fingerprint, const std::string& name);

}  // namespace detsim::replay
