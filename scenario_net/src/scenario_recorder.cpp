// Replays of session matches (scenario_recorder.hpp).
#include <detsim/scenario_net/scenario_recorder.hpp>

#include <utility>

#include <detsim/replay/scenario_replay.hpp>

namespace detsim::net {

struct ScenarioRecorder::Impl {
  replay::ReplayWriter writer;
  ScenarioGame* game = nullptr;
  std::uint32_t keyframe_interval = 0;
  std::function<void(const ConfirmedFrame&)> listener;
  Status error;

  void record(const ConfirmedFrame& f) {
    if (listener) listener(f);
    if (!error.ok()) return;
    const std::uint64_t frame = f.frame + 1;  // replay frames count states after each step
    const std::optional<StateHashes> hashes = game->hashes_at(frame);
    if (!hashes || hashes->total != f.hash) {
      error = Status::error("recording: the game no longer holds the hashes of frame " +
                            std::to_string(frame));
      return;
    }
    if (Status s = writer.frame(f.inputs, *hashes); !s) {
      error = s;
      return;
    }
    if (frame % keyframe_interval == 0) {
      const std::vector<std::uint8_t>* state = game->keyframe_at(frame);
      if (state == nullptr) {
        error = Status::error("recording: the game no longer holds the keyframe of frame " +
                              std::to_string(frame));
        return;
      }
      if (Status s = writer.keyframe(frame, *state); !s) error = s;
    }
  }
};

Expected<ScenarioRecorder> ScenarioRecorder::create(const std::string& path, ScenarioGame& game,
                                                    std::uint32_t keyframe_interval) {
  if (keyframe_interval < 16 || keyframe_interval > 100'000)
    return Status::error("recording: keyframe interval must be 16 .. 100000, got " +
                         std::to_string(keyframe_interval));
  if (game.scenario().world().frame() != 0)
    return Status::error("recording: the scenario must be at frame 0, it is at frame " +
                         std::to_string(game.scenario().world().frame()));
  auto writer = replay::ReplayWriter::create(
      path, replay::fingerprint_of(game.scenario(), keyframe_interval));
  if (!writer) return writer.status();
  game.keep_keyframes(keyframe_interval);
  auto impl = std::make_unique<Impl>(
      Impl{std::move(writer.value()), &game, keyframe_interval, {}, Status::success()});
  return ScenarioRecorder(std::move(impl));
}

ScenarioRecorder::ScenarioRecorder(std::unique_ptr<Impl> impl) noexcept : impl_(std::move(impl)) {}
ScenarioRecorder::ScenarioRecorder(ScenarioRecorder&&) noexcept = default;
ScenarioRecorder& ScenarioRecorder::operator=(ScenarioRecorder&&) noexcept = default;
ScenarioRecorder::~ScenarioRecorder() = default;

void ScenarioRecorder::attach(Session& session,
                              std::function<void(const ConfirmedFrame&)> listener) {
  impl_->listener = std::move(listener);
  Impl* impl = impl_.get();  // stable across moves of the recorder
  session.set_confirmed_listener([impl](const ConfirmedFrame& f) { impl->record(f); });
}

void ScenarioRecorder::attach(SpectatorSession& spectator,
                              std::function<void(const ConfirmedFrame&)> listener) {
  impl_->listener = std::move(listener);
  Impl* impl = impl_.get();
  spectator.set_confirmed_listener([impl](const ConfirmedFrame& f) { impl->record(f); });
}

void ScenarioRecorder::attach(Server& server, std::function<void(const ConfirmedFrame&)> listener) {
  impl_->listener = std::move(listener);
  Impl* impl = impl_.get();
  server.set_confirmed_listener([impl](const ConfirmedFrame& f) { impl->record(f); });
}

std::uint64_t ScenarioRecorder::frames() const noexcept {
  return impl_->writer.frames();
}

Status ScenarioRecorder::status() const {
  return impl_->error;
}

Status ScenarioRecorder::finish() {
  if (!impl_->error.ok()) return impl_->error;
  return impl_->writer.finish();
}

Expected<replay::DesyncReport> desync_report(const replay::Fingerprint& fingerprint,
                                             std::uint32_t reporter,
                                             const DesyncEvidence& evidence) {
  replay::DesyncReport r;
  r.fingerprint = fingerprint;
  r.reporter = reporter;
  r.other = evidence.player;
  r.agreed_frame = evidence.agreed_frame;
  r.divergent_frame = evidence.divergent_frame;
  r.local_hash = evidence.local_hash;
  r.remote_hash = evidence.remote_hash;
  r.confirmed_frames = evidence.confirmed_frames;
  r.agreed_state = evidence.agreed_state;
  r.divergent_state = evidence.divergent_state;
  // The states name the scenario's geometry by hash: restore them against the scenario's world.
  auto scenario = replay::scenario_of(fingerprint, "desync report");
  const World geometry = scenario ? scenario.value().world() : World();
  auto agreed = replay::body_hashes(geometry, r.agreed_state);
  if (!agreed) return Status::error("desync report: the agreed state: " + agreed.message());
  auto divergent = replay::body_hashes(geometry, r.divergent_state);
  if (!divergent)
    return Status::error("desync report: the divergent state: " + divergent.message());
  r.agreed_bodies = std::move(agreed).value();
  r.divergent_bodies = std::move(divergent).value();
  return r;
}

Expected<replay::DesyncReport> desync_report(const replay::Fingerprint& fingerprint,
                                             std::uint32_t reporter, const DesyncEvidence& evidence,
                                             ScenarioGame& game) {
  auto report = desync_report(fingerprint, reporter, evidence);
  if (!report) return report;
  replay::DesyncReport& r = report.value();
  const std::size_t unit = 1 + std::size_t{fingerprint.players} * fingerprint.input_size;
  if (r.confirmed_frames.size() / unit < r.divergent_frame) return report;  // log cut short
  const std::span<const std::uint8_t> steps =
      std::span<const std::uint8_t>(r.confirmed_frames)
          .subspan(static_cast<std::size_t>(r.agreed_frame) * unit,
                   static_cast<std::size_t>(r.divergent_frame - r.agreed_frame) * unit);
  auto states = game.resimulate(r.agreed_state, steps);
  if (!states) return Status::error("desync report: " + states.message());
  std::vector<std::vector<std::uint8_t>>& s = states.value();
  if (s.empty() || s.back() != r.divergent_state) return report;  // not repeatable here
  for (std::size_t i = 0; i + 1 < s.size(); ++i)
    r.intermediate_states.push_back({r.agreed_frame + 1 + i, std::move(s[i])});
  return report;
}

}  // namespace detsim::net
