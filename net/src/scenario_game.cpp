// The Game adapter for detsim scenarios (scenario_game.hpp).
#include <detsim/net/scenario_game.hpp>

namespace detsim::net {

std::uint64_t ScenarioGame::save(std::vector<std::uint8_t>& state) {
  const World& world = scenario_->world();
  const StateHashes hashes = world.save(state);  // one encoding gives the bytes and every hash
  const std::uint64_t frame = world.frame();
  remembered_[static_cast<std::size_t>(frame % remembered_hashes)] = Remembered{frame, hashes};
  if (keyframe_interval_ != 0 && frame % keyframe_interval_ == 0) {
    Keyframe& k = keyframes_[static_cast<std::size_t>((frame / keyframe_interval_) % 2)];
    k.frame = frame;
    k.state.assign(state.begin(), state.end());
  }
  return hashes.total;
}

void ScenarioGame::load(std::span<const std::uint8_t> state) {
  if (!scenario_->world().restore(state)) ++failed_loads_;
}

void ScenarioGame::advance(const FrameInputs& inputs, bool resimulating) {
  inputs_.assign(inputs.players(), PlayerInput{});
  if (inputs.input_size == input_size) {
    for (std::size_t p = 0; p < inputs.players(); ++p) {
      if (inputs.status[p] == InputStatus::disconnected) continue;
      inputs_[p] = decode_input(inputs.input(p).first<PlayerInput::encoded_size>());
    }
  }
  scenario_->step(inputs_);
  ++(resimulating ? resimulated_ : simulated_);
}

std::optional<StateHashes> ScenarioGame::hashes_at(std::uint64_t frame) const noexcept {
  const Remembered& r = remembered_[static_cast<std::size_t>(frame % remembered_hashes)];
  if (r.frame != frame) return std::nullopt;
  return r.hashes;
}

const std::vector<std::uint8_t>* ScenarioGame::keyframe_at(std::uint64_t frame) const noexcept {
  if (keyframe_interval_ == 0 || frame % keyframe_interval_ != 0) return nullptr;
  const Keyframe& k = keyframes_[static_cast<std::size_t>((frame / keyframe_interval_) % 2)];
  return k.frame == frame ? &k.state : nullptr;
}

}  // namespace detsim::net
