// detsim::net::ScenarioRecorder: records a session's confirmed frames of a scenario match as a
// replay (replay/FORMAT.md) that `detsim verify` re-simulates: the confirmed inputs of every
// player, the state hashes after each frame, and a keyframe every keyframe_interval frames.
//
// It reads the hashes and keyframe states the ScenarioGame already computed when the session
// saved them, so recording simulates nothing twice.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include <detsim/core/status.hpp>
#include <detsim/net/server.hpp>
#include <detsim/net/session.hpp>
#include <detsim/net/spectator.hpp>
#include <detsim/replay/desync_report.hpp>
#include <detsim/replay/replay.hpp>
#include <detsim/scenario_net/scenario_game.hpp>

namespace detsim::net {

class ScenarioRecorder {
 public:
  /// Creates `path` for a match of `game`'s scenario, which must still be at frame 0 (the
  /// fingerprint records its initial state). keyframe_interval: 16 .. 100000.
  static Expected<ScenarioRecorder> create(
      const std::string& path, ScenarioGame& game,
      std::uint32_t keyframe_interval = replay::default_keyframe_interval);
  ScenarioRecorder(ScenarioRecorder&&) noexcept;
  ScenarioRecorder& operator=(ScenarioRecorder&&) noexcept;
  ~ScenarioRecorder();

  /// Records `session`'s confirmed frames from now on (it replaces the session's confirmed
  /// listener; `listener`, if given, is still called for each frame). The recorder must outlive
  /// the session's use of it: keep both alive together, or attach before a move only.
  void attach(Session& session, std::function<void(const ConfirmedFrame&)> listener = {});
  /// The same for a spectator: it records exactly the file the players record.
  void attach(SpectatorSession& spectator,
              std::function<void(const ConfirmedFrame&)> listener = {});
  /// The same for a game server (net::Server): every frame it simulates, as it simulates it.
  void attach(Server& server, std::function<void(const ConfirmedFrame&)> listener = {});

  /// Frames recorded so far.
  [[nodiscard]] std::uint64_t frames() const noexcept;
  /// The first error (a write failed, or a hash the game no longer remembered); recording stops
  /// at it. Success while all is well.
  [[nodiscard]] Status status() const;
  /// Writes the end marker and closes the file; returns status() or the write's error.
  Status finish();

 private:
  struct Impl;
  explicit ScenarioRecorder(std::unique_ptr<Impl> impl) noexcept;
  std::unique_ptr<Impl> impl_;
};

/// The desync report of this machine's side (`evidence` from Session::desync_evidence()) in a
/// scenario match with `fingerprint` (replay::fingerprint_of the scenario at frame 0), written by
/// player `reporter`: adds the per-body hashes of both states. Write it with
/// replay::write_desync_report().
Expected<replay::DesyncReport> desync_report(const replay::Fingerprint& fingerprint,
                                             std::uint32_t reporter,
                                             const DesyncEvidence& evidence);

/// The same, with this machine's state at every frame between the agreed and the divergent one
/// (DesyncReport::intermediate_states), so that bisection can name the exact first divergent frame
/// and its fields whatever the check interval: `game` (this machine's, its after-step hook
/// included) re-simulates them from the agreed state and is left as it was. When the
/// re-simulation does not reproduce the divergent frame's hash (the machine is not repeatable),
/// the report has no intermediate states.
Expected<replay::DesyncReport> desync_report(const replay::Fingerprint& fingerprint,
                                             std::uint32_t reporter, const DesyncEvidence& evidence,
                                             ScenarioGame& game);

}  // namespace detsim::net
