// One record of a match, a replay or a desync report, loaded for the tools that compare and
// re-simulate records (bisect.cpp, view.cpp): its fingerprint, every step's inputs, the state
// hashes of the frames it holds (a replay: every frame; a desync report: the frames whose states it
// carries) and the states it can give (a report's states, a replay's keyframes).
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <detsim/core/status.hpp>
#include <detsim/replay/replay.hpp>
#include <detsim/sim/world.hpp>

namespace detsim::replay::detail {

using State = std::vector<std::uint8_t>;

/// One record (a replay or a desync report) as the tools that re-simulate it need it.
struct Record {
  std::string path;
  std::string kind;
  std::string label;  ///< "A" or "B"
  Fingerprint fp;
  std::uint64_t last = 0;                 ///< state frames 0 .. last
  std::vector<StateHashes> hashes;        ///< by frame
  std::vector<std::uint8_t> known;        ///< 1 where hashes[frame] was recorded
  std::vector<std::uint8_t> inputs;       ///< steps 0 .. last - 1, players * input_size bytes each
  std::vector<std::uint8_t> gone;         ///< a report's "disconnected" byte per step; else empty
  std::map<std::uint64_t, State> states;  ///< a report's states by frame
  std::optional<ReplayReader> replay;     ///< for keyframes

  // Frames index vectors: a frame count is bounded by the bytes read, so it fits size_t.
  [[nodiscard]] static std::size_t at(std::uint64_t f) { return static_cast<std::size_t>(f); }
  [[nodiscard]] bool has(std::uint64_t f) const { return f <= last && known[at(f)] != 0; }
  [[nodiscard]] const StateHashes& hash(std::uint64_t f) const { return hashes[at(f)]; }
  void set_hash(std::uint64_t f, const StateHashes& h) {
    hashes[at(f)] = h;
    known[at(f)] = 1;
  }
  /// The "disconnected" byte of a report's step (0 for a replay).
  [[nodiscard]] std::uint8_t gone_at(std::uint64_t step) const {
    return gone.empty() ? std::uint8_t{0} : gone[at(step)];
  }
  [[nodiscard]] std::size_t unit() const { return std::size_t{fp.players} * fp.input_size; }

  /// The state this side stored at frame f (a report's, or a replay's keyframe), if any.
  [[nodiscard]] std::optional<State> stored(std::uint64_t f) const {
    if (auto it = states.find(f); it != states.end()) return it->second;
    if (!replay) return std::nullopt;
    for (const KeyframeInfo& k : replay->keyframes()) {
      if (k.frame != f) continue;
      auto s = replay->keyframe_state(k);
      if (s) return std::move(s).value();
    }
    return std::nullopt;
  }
  /// Frames with a stored state, ascending.
  [[nodiscard]] std::vector<std::uint64_t> stored_frames() const {
    std::vector<std::uint64_t> out;
    for (const auto& [f, s] : states)
      out.push_back(f);
    if (replay)
      for (const KeyframeInfo& k : replay->keyframes())
        out.push_back(k.frame);
    return out;
  }
};

/// Whether `path` starts with a desync report's magic (else it is read as a replay).
bool is_report(const std::string& path);

/// A world holding the geometry of the record's scenario (what its states are restored against:
/// a state names its geometry by hash, World::restore needs the world to hold it); a world without
/// geometry when this build cannot create the scenario (its states restore if they name none).
World geometry_world(const Fingerprint& fp, const std::string& path);

/// Loads and validates `path`, a replay or a desync report told apart by its magic; `label` ("A",
/// "B") names the record in errors ("side A: ...") when not empty.
Expected<Record> load_record(const std::string& path, const char* label);

}  // namespace detsim::replay::detail
