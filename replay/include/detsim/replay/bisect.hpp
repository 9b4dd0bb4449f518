// Desync bisection: from two machines' records of the same match (replays and/or desync reports)
// to the first frame whose state differs, the subsystems, bodies and fields that differ there with
// both values, the last frame both agreed on and the inputs in between.
//
// The records are compared in this order: the fingerprints (a different run is reported as such),
// the inputs (differing inputs are not a desync), then the per-frame state hashes. Where a side has
// a hash but no state at a frame, this machine re-simulates the frame from the last state both
// sides agree on and says which side it agrees with; the field-level diff is taken at the first
// divergent frame when both sides' states there are known (stored, or re-simulated here with the
// side's recorded hash), else at the first later frame where they are, with the `detsim verify`
// command that would give the exact frame.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <detsim/core/status.hpp>
#include <detsim/sim/shape.hpp>
#include <detsim/sim/shape_outline.hpp>
#include <detsim/sim/state_diff.hpp>
#include <detsim/sim/world.hpp>

namespace detsim::replay {

/// What bisection found.
enum class BisectOutcome {
  identical,       ///< every frame both sides hold agrees
  diverged,        ///< the states differ from first_divergent_frame on
  inputs_differ,   ///< the sides recorded different inputs (not a desync)
  different_runs,  ///< the fingerprints differ: not the same match
};

/// A stretch of frames and whether the two sides' hashes agree on it.
struct AgreementSpan {
  enum class State { agree, differ, unknown };  ///< unknown: a side holds no hash there
  std::uint64_t first = 0;
  std::uint64_t last = 0;
  State state = State::unknown;
};

/// A body as the scene plot draws it (top-down: x to the right, z downwards).
struct ScenePose {
  std::uint32_t id = 0;
  BodyType type = BodyType::dynamic;
  Shape shape;
  Vec3 position;
  Quat orientation;
  bool differs = false;  ///< one of the diff's bodies
  /// What is drawn: the body's outline from its world (World::body_outline: hulls, surfaces and
  /// compounds too); when absent, shape_outline(shape, position, orientation), which draws
  /// primitives only.
  std::optional<ShapeOutline> outline;
};

/// The inputs of one frame (the step that produced state frame `frame`), from side A.
struct FrameInputsRecord {
  std::uint64_t frame = 0;
  std::vector<std::uint8_t> inputs;  ///< players * input_size bytes
};

struct BisectResult {
  BisectOutcome outcome = BisectOutcome::identical;
  std::string a;  ///< side A's file
  std::string b;
  std::string a_kind;  ///< "replay" or "desync report"
  std::string b_kind;
  std::uint32_t players = 0;
  std::uint32_t input_size = 0;

  /// different_runs: one line per differing fingerprint field ("seed: 1 vs 2").
  std::vector<std::string> fingerprint_differences;
  /// inputs_differ: the first state frame whose step had different inputs, and the first player
  /// whose input differs, with both inputs as hex bytes.
  std::uint64_t input_frame = 0;
  std::uint32_t input_player = 0;
  std::string input_a;
  std::string input_b;

  /// Frames each side covers (state frames 0 .. these).
  std::uint64_t frames_a = 0;
  std::uint64_t frames_b = 0;
  /// diverged: the first frame whose hashes differ; last_agreed_frame the last one before it whose
  /// hashes both sides hold and agree on. exact: nothing lies between them.
  std::optional<std::uint64_t> first_divergent_frame;
  std::optional<std::uint64_t> last_agreed_frame;
  bool exact = false;
  StateHashes hashes_a;  ///< at first_divergent_frame
  StateHashes hashes_b;
  std::vector<std::string> subsystems;  ///< differing at first_divergent_frame: "globals", ...

  /// Which side this machine's re-simulation agrees with at first_divergent_frame: "A", "B",
  /// "neither", or "" when it re-simulated nothing.
  std::string local_agrees_with;

  /// The frame of the field-level diff (first_divergent_frame when exact states were known).
  std::optional<std::uint64_t> diff_frame;
  /// The first known frame after the divergence where both sides' states are equal again (the
  /// divergence healed: a field the next step overwrites), when that came before any frame that
  /// differs; then there is no diff_frame.
  std::optional<std::uint64_t> healed_frame;
  std::string diff_source_a;  ///< where A's state came from: "desync report", "keyframe", ...
  std::string diff_source_b;
  std::vector<FieldDiff> diffs;
  std::size_t diffs_omitted = 0;
  /// What to run to get the exact frame's diff when diff_frame != first_divergent_frame (or the
  /// diff is missing), e.g. "detsim verify B.replay --report B.report --at 1234"; else empty.
  std::string advice;
  std::vector<std::string> notes;  ///< anything else worth knowing (gaps, re-simulation)

  /// The frames after last_agreed_frame up to first_divergent_frame, with their inputs (at most
  /// max_input_frames, the first ones).
  std::vector<FrameInputsRecord> inputs_between;

  /// Agreement over frames 0 .. max(frames_a, frames_b), in order, adjacent spans merged.
  std::vector<AgreementSpan> timeline;
  /// Both sides' bodies at diff_frame, then their particles (body ID 0; at most 1000 a group)
  /// (empty without a diff).
  std::vector<ScenePose> scene_a;
  std::vector<ScenePose> scene_b;
};

struct BisectOptions {
  std::size_t max_diffs = 1000;
  std::size_t max_input_frames = 64;
};

/// Bisects two records (each a replay file or a desync report file, told apart by their magic).
/// Errors: a file that does not open or validate (named), a record this build cannot re-simulate
/// when re-simulation is needed.
Expected<BisectResult> bisect(const std::string& a, const std::string& b,
                              const BisectOptions& options = {});

/// One self-contained HTML page (no scripts or files from elsewhere, opens offline) showing
/// `result`: the files, the outcome, the agreement timeline, the diff table and a top-down plot
/// (x right, z down) of both sides' scenes at diff_frame with the differing bodies highlighted.
/// Coordinates are computed in Fixed and printed as decimals (no floating point).
[[nodiscard]] std::string bisect_html(const BisectResult& result);

}  // namespace detsim::replay
