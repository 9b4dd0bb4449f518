// What a replay viewer shows: one record of a match (a replay or a desync report), or two records
// of the same match overlaid, re-simulated on this machine frame by frame and handed to a sink as
// each body's pose, each particle's position, the frame's state hash and its inputs.
//
// Each record is re-simulated from frame 0 with its own inputs and re-anchored at every state it
// stores (a replay's keyframes, a desync report's states): at those frames the record's own state
// is restored and shown. One record re-simulated here reproduces its keyframes exactly (or
// `detsim verify` fails), so the anchoring changes nothing; for two records of a desynced match it
// is what makes each side show its own machine's world: from the first state it stored after the
// divergence on, side B shows B's bodies where B's machine had them. A body is marked as differing
// from the first divergent frame (found as `detsim bisect` finds it) wherever the two sides' poses
// or velocities differ, it exists on one side only, or bisection's field diff names it.
//
// `detsim view` (tools/detsim/cmd_view.cpp) turns the frames into one self-contained HTML page
// (docs/VIEWER.md); a game's own tool that links detsim::cli gets the same command.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <detsim/core/status.hpp>
#include <detsim/replay/replay.hpp>
#include <detsim/sim/shape_outline.hpp>
#include <detsim/sim/world.hpp>

namespace detsim::replay {

/// A body as a viewer draws it: its outline in the body's own frame (placed at the origin with the
/// identity orientation; a pose moves it).
struct ViewBody {
  std::uint32_t id = 0;
  BodyType type = BodyType::dynamic;
  ShapeOutline outline;
};

/// Where a body is at one frame.
struct ViewPose {
  std::uint32_t id = 0;
  Vec3 position;
  Quat orientation;
  /// Two records, from the first divergent frame on: the body differs between the two sides.
  bool differs = false;
};

/// A particle group at one frame (ropes, cloth, soft bodies, fluid).
struct ViewParticles {
  std::uint32_t group = 0;
  Fixed radius;
  std::vector<Vec3> positions;  ///< every particle, by index
};

/// One record's world at one frame.
struct ViewSide {
  /// The state's total hash: of this machine's re-simulation, or of the record's own state where
  /// it stores one (`stored`).
  std::uint64_t hash = 0;
  /// The hash the record holds for this frame, where it holds one (a replay: every frame).
  std::optional<std::uint64_t> recorded_hash;
  bool stored = false;                   ///< the record's own state was restored at this frame
  std::vector<ViewBody> new_bodies;      ///< bodies first seen at this frame (IDs are never reused)
  std::vector<ViewPose> bodies;          ///< every body, ascending ID
  std::vector<ViewParticles> particles;  ///< every particle group, ascending ID
};

/// One frame of every record.
struct ViewFrame {
  std::uint64_t frame = 0;
  /// The first record's inputs of the step that made this frame (players * input_size bytes,
  /// player order; empty at frame 0), and its "disconnected" bits (a desync report's; else 0).
  std::span<const std::uint8_t> inputs;
  std::uint8_t gone = 0;
  std::vector<ViewSide> sides;  ///< one per record, in the order given
};

struct ViewRecordInfo {
  std::string path;
  std::string kind;          ///< "replay" or "desync report"
  std::uint64_t frames = 0;  ///< its last frame
};

/// What the sink learns before the first frame.
struct ViewInfo {
  std::vector<ViewRecordInfo> records;
  Fingerprint fingerprint;     ///< the first record's
  bool player_inputs = false;  ///< inputs are PlayerInput (decode_input); else a game's own bytes
  std::uint64_t first_frame = 0;  ///< the frames the sink will receive: first .. last
  std::uint64_t last_frame = 0;
  /// Two records: "identical", "diverged" or "inputs_differ" (bisect's outcome); one: "single".
  std::string outcome = "single";
  /// Two records that diverged: the first frame whose state hashes differ.
  std::optional<std::uint64_t> first_divergent_frame;
  std::vector<std::string> notes;  ///< worth telling the viewer (e.g. where the sides end)
};

struct ViewOptions {
  std::uint64_t first = 0;            ///< the first frame handed to the sink
  std::optional<std::uint64_t> last;  ///< the last one (default: the records' common end)
};

/// Receives the frames, in order. An error from it stops view_records with that error.
class ViewSink {
 public:
  virtual ~ViewSink() = default;
  virtual Status begin(const ViewInfo& info) = 0;
  virtual Status frame(const ViewFrame& frame) = 0;
};

/// Loads one or two records (each a replay or a desync report), re-simulates them and hands every
/// frame from options.first to options.last to `sink`. Errors, before any frame: no record or more
/// than two, a file that does not open or validate, two records of different matches (their
/// fingerprints differ: named), a scenario this build cannot re-create, a range outside the
/// records.
Status view_records(std::span<const std::string> paths, const ViewOptions& options, ViewSink& sink);

}  // namespace detsim::replay
