// Replay files (replay/FORMAT.md): a fingerprint of the run, then every frame's inputs and state
// hashes, and a keyframe snapshot every K frames, in little-endian chunks that each carry an XXH3
// checksum.
//
// ReplayWriter appends and flushes whole chunks, so a recording killed at any moment reads back up
// to its last complete chunk. ReplayReader checks the whole file once when it opens it (structure,
// checksums, frame continuity), keeps only an index of its chunks, and streams frames from there.
// Every error names the file, the byte offset and what was expected; no size read from a file is
// allocated before it has been checked against the bytes that remain.
#pragma once

#include <cstdint>
#include <cstdio>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <detsim/core/status.hpp>
#include <detsim/scenes/scenario.hpp>
#include <detsim/sim/world.hpp>

namespace detsim::replay {

/// The version of the replay format this build writes and reads.
inline constexpr std::uint32_t format_version = 2;
/// Keyframe interval used when a caller does not choose one.
inline constexpr std::uint32_t default_keyframe_interval = 300;
/// Frames per FRAM chunk: what a killed recording can lose at most.
inline constexpr std::uint32_t frames_per_chunk = 60;
/// The largest chunk payload a reader accepts (a keyframe of ~150,000 bodies).
inline constexpr std::uint32_t max_chunk_payload = 64U << 20;

/// Everything that must match to reproduce a run.
struct Fingerprint {
  std::string detsim_version;              ///< of the build that recorded
  std::uint32_t fixed_fraction_bits = 32;  ///< Q32.32
  std::uint32_t state_version = 0;         ///< canonical state encoding (keyframes)
  /// The sections of the run's state, in order (at most 32): each frame records one hash per
  /// section, in this order, after the state's hash.
  std::vector<std::string> state_sections;
  std::string scenario;   ///< a registered scenario's name, or a game's own name
  ScenarioParams params;  ///< seed, players, count, with defaults filled in
  Fixed dt;               ///< the world's step and solver settings
  std::uint32_t substeps = 0;
  std::uint32_t iterations = 0;
  std::uint32_t players = 0;     ///< inputs per frame
  std::uint32_t input_size = 0;  ///< bytes per input
  std::uint32_t keyframe_interval = default_keyframe_interval;
  std::uint64_t initial_hash = 0;  ///< state hash at frame 0, before the first step

  friend bool operator==(const Fingerprint&, const Fingerprint&) = default;
};

/// The fingerprint of a scenario's run as this build would record it (state at frame 0).
[[nodiscard]] Fingerprint fingerprint_of(
    const Scenario& scenario, std::uint32_t keyframe_interval = default_keyframe_interval);

/// What the peers of a session must agree on before they play (net::SessionConfig::fingerprint):
/// XXH3-64 of every field of `f` but keyframe_interval (each machine's own choice), followed by
/// `match`: bytes the game adds for what the fingerprint does not hold (the session mode, the
/// match's length, its own rules and settings). Peers with different values refuse each other at
/// the handshake, naming the fingerprint, instead of desyncing at the first frame.
[[nodiscard]] std::uint64_t session_fingerprint(const Fingerprint& f,
                                                std::span<const std::uint8_t> match = {});

/// One frame: the inputs of the step that produced it (players * input_size bytes, player order)
/// and the hashes of the state after that step. Frame numbers start at 1.
struct FrameRecord {
  std::uint64_t frame = 0;
  std::vector<std::uint8_t> inputs;
  StateHashes hashes;
};

/// Appends a replay file. Frames are buffered and written as one chunk per frames_per_chunk
/// frames; keyframes and finish() write what is pending first. Each chunk is flushed to the
/// operating system when written.
class ReplayWriter {
 public:
  /// Creates (or truncates) `path` and writes the header and the fingerprint.
  static Expected<ReplayWriter> create(const std::string& path, const Fingerprint& fingerprint);

  ReplayWriter(ReplayWriter&&) noexcept;
  ReplayWriter& operator=(ReplayWriter&&) noexcept;
  /// Writes pending frames (not the end marker) and closes the file.
  ~ReplayWriter();

  /// Appends the next frame (frame numbers run 1, 2, ...). `inputs` must hold players * input_size
  /// bytes.
  Status frame(std::span<const std::uint8_t> inputs, const StateHashes& hashes);
  /// Appends the state at `frame` (World::save()), which must be the last frame appended.
  Status keyframe(std::uint64_t frame, std::span<const std::uint8_t> state);
  /// Writes pending frames and the end marker, and closes the file. Nothing may follow.
  Status finish();

  [[nodiscard]] std::uint64_t frames() const noexcept;
  [[nodiscard]] const std::string& path() const noexcept;

 private:
  struct Impl;
  explicit ReplayWriter(std::unique_ptr<Impl> impl) noexcept;
  std::unique_ptr<Impl> impl_;
};

/// Where a keyframe is.
struct KeyframeInfo {
  std::uint64_t frame = 0;
  std::uint64_t offset = 0;  ///< of its chunk
  std::uint32_t size = 0;    ///< state bytes
};

/// Reads a replay file. open() validates every chunk; afterwards reads can still fail only if the
/// file changes underneath.
class ReplayReader {
 public:
  static Expected<ReplayReader> open(const std::string& path);
  /// Reads a replay held in memory (a network buffer, a test, a fuzzer); `name` stands for the
  /// path in messages.
  static Expected<ReplayReader> from_bytes(std::vector<std::uint8_t> bytes,
                                           const std::string& name);

  ReplayReader(ReplayReader&&) noexcept;
  ReplayReader& operator=(ReplayReader&&) noexcept;
  ~ReplayReader();

  [[nodiscard]] const std::string& path() const noexcept;
  [[nodiscard]] const Fingerprint& fingerprint() const noexcept;
  /// Frames recorded (the last is frame_count(); 0 when none).
  [[nodiscard]] std::uint64_t frame_count() const noexcept;
  [[nodiscard]] const std::vector<KeyframeInfo>& keyframes() const noexcept;
  /// Whether the end marker is present (absent: the recording stopped early, e.g. was killed).
  [[nodiscard]] bool complete() const noexcept;
  /// The end marker's hash of the chain of per-frame hashes, when complete().
  [[nodiscard]] std::optional<std::uint64_t> chain_hash() const noexcept;
  /// Bytes after the last complete chunk that were ignored (a recording cut short), and why.
  [[nodiscard]] std::uint64_t ignored_tail_bytes() const noexcept;
  [[nodiscard]] const std::string& tail_note() const noexcept;
  /// File size in bytes.
  [[nodiscard]] std::uint64_t file_size() const noexcept;

  /// Calls `visit` for frames first .. last in order (clamped to the recording), one chunk in
  /// memory at a time; stops early when `visit` returns false.
  Status for_each_frame(std::uint64_t first, std::uint64_t last,
                        const std::function<bool(const FrameRecord&)>& visit) const;
  /// One frame (1 .. frame_count()).
  [[nodiscard]] Expected<FrameRecord> frame(std::uint64_t n) const;
  /// The state bytes of a keyframe.
  [[nodiscard]] Expected<std::vector<std::uint8_t>> keyframe_state(const KeyframeInfo& k) const;

 private:
  struct Impl;
  explicit ReplayReader(std::unique_ptr<Impl> impl) noexcept;
  std::unique_ptr<Impl> impl_;
};

/// XXH3-64 of the per-frame total hashes in order, each as 8 little-endian bytes: one number that
/// covers every frame of a run (what the end marker and golden/ store).
class HashChain {
 public:
  HashChain();
  HashChain(const HashChain&);
  HashChain& operator=(const HashChain&);
  ~HashChain();
  void add(std::uint64_t frame_hash) noexcept;
  [[nodiscard]] std::uint64_t value() const noexcept;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace detsim::replay
