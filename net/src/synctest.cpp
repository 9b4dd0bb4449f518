// GGPO's sync test (synctest.hpp). Frame f >= K: load the state of frame f - K, re-simulate frames
// f - K .. f - 1 with the inputs they had, and compare the hash after each with the first pass; the
// run then goes on from the re-simulated state, so every frame is re-simulated K times in all.
#include <detsim/net/synctest.hpp>

#include <string>

namespace detsim::net {

struct SyncTestSession::Impl {
  struct Frame {
    std::vector<std::uint8_t> state;  ///< after this frame (first pass)
    std::uint64_t hash = 0;
    std::vector<std::uint8_t> inputs;  ///< of the step that led to the next frame
  };

  SyncTestConfig config;
  Game* game = nullptr;
  std::vector<Frame> ring;  ///< check_distance + 1 frames, by frame number
  std::vector<InputStatus> status;
  std::vector<std::uint8_t> scratch;
  std::uint64_t current = 0;
  std::uint64_t resimulated = 0;
  std::optional<SyncTestMismatch> mismatch;

  Frame& at(std::uint64_t frame) { return ring[static_cast<std::size_t>(frame % ring.size())]; }

  void step(std::uint64_t frame, std::span<const std::uint8_t> inputs, bool again) {
    game->advance(FrameInputs{frame, config.input_size, inputs, status}, again);
  }
};

Expected<SyncTestSession> SyncTestSession::create(const SyncTestConfig& c, Game& game) {
  const auto bad = [](const std::string& what) { return Status::error("synctest: " + what); };
  if (c.players < 1 || c.players > 128)
    return bad("players must be 1 .. 128, got " + std::to_string(c.players));
  if (c.input_size < 1 || c.input_size > 64)
    return bad("input_size must be 1 .. 64 bytes, got " + std::to_string(c.input_size));
  if (c.check_distance < 1 || c.check_distance > 600)
    return bad("check distance must be 1 .. 600 frames, got " + std::to_string(c.check_distance));
  auto impl = std::make_unique<Impl>();
  impl->config = c;
  impl->game = &game;
  impl->ring.resize(std::size_t{c.check_distance} + 1);
  impl->status.assign(c.players, InputStatus::confirmed);
  Impl::Frame& zero = impl->at(0);
  zero.hash = game.save(zero.state);
  return SyncTestSession(std::move(impl));
}

SyncTestSession::SyncTestSession(std::unique_ptr<Impl> impl) noexcept : impl_(std::move(impl)) {}
SyncTestSession::SyncTestSession(SyncTestSession&&) noexcept = default;
SyncTestSession& SyncTestSession::operator=(SyncTestSession&&) noexcept = default;
SyncTestSession::~SyncTestSession() = default;

Expected<bool> SyncTestSession::advance_frame(std::span<const std::uint8_t> inputs) {
  Impl& s = *impl_;
  const std::size_t size = std::size_t{s.config.players} * s.config.input_size;
  if (inputs.size() != size)
    return Status::error("synctest: inputs must be " + std::to_string(size) + " bytes, got " +
                         std::to_string(inputs.size()));
  if (s.mismatch) return false;
  // First pass: frame `current` -> state current + 1.
  const std::uint64_t frame = s.current;
  s.at(frame).inputs.assign(inputs.begin(), inputs.end());
  s.step(frame, inputs, false);
  Impl::Frame& after = s.at(frame + 1);
  after.hash = s.game->save(after.state);
  s.current = frame + 1;
  const std::uint64_t distance = s.config.check_distance;
  if (s.current < distance) return true;
  // Roll back to state current - distance and simulate the same frames again.
  const std::uint64_t from = s.current - distance;
  s.game->load(s.at(from).state);
  for (std::uint64_t f = from; f < s.current; ++f) {
    s.step(f, s.at(f).inputs, true);
    ++s.resimulated;
    const Impl::Frame& want = s.at(f + 1);
    const std::uint64_t hash = s.game->save(s.scratch);
    if (hash != want.hash) {
      s.mismatch = SyncTestMismatch{f + 1, want.hash, hash, want.state, s.scratch};
      return false;
    }
  }
  return true;
}

std::uint64_t SyncTestSession::current_frame() const noexcept {
  return impl_->current;
}
std::uint64_t SyncTestSession::resimulated_frames() const noexcept {
  return impl_->resimulated;
}
std::uint64_t SyncTestSession::current_hash() const noexcept {
  return impl_->at(impl_->current).hash;
}
const SyncTestMismatch* SyncTestSession::mismatch() const noexcept {
  return impl_->mismatch ? &*impl_->mismatch : nullptr;
}

}  // namespace detsim::net
