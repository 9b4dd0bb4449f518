// The Game adapter for detsim scenarios (scenario_game.hpp).
#include <detsim/scenario_net/scenario_game.hpp>

#include <detsim/sim/state_delta.hpp>

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

bool ScenarioGame::encode_delta(std::span<const std::uint8_t> state,
                                std::span<const std::uint8_t> base,
                                std::vector<std::uint8_t>& delta) {
  Expected<std::vector<std::uint8_t>> coded = encode_state_delta(state, base);
  if (!coded) return false;
  delta = std::move(*coded);
  return true;
}

bool ScenarioGame::decode_delta(std::span<const std::uint8_t> delta,
                                std::span<const std::uint8_t> base,
                                std::vector<std::uint8_t>& state) {
  Expected<std::vector<std::uint8_t>> decoded = decode_state_delta(delta, base);
  if (!decoded) return false;
  state = std::move(*decoded);
  return true;
}

void ScenarioGame::advance(const FrameInputs& inputs, bool resimulating) {
  // Inputs of another size than the scenario's (a session misconfigured) count as neutral.
  const std::size_t size = input_size();
  inputs_.assign(inputs.players() * size, 0);
  if (inputs.input_size == size) {
    for (std::size_t p = 0; p < inputs.players(); ++p) {
      if (inputs.status[p] == InputStatus::disconnected) continue;
      const std::span<const std::uint8_t> input = inputs.input(p);
      std::copy(input.begin(), input.end(),
                inputs_.begin() + static_cast<std::ptrdiff_t>(p * size));
    }
  }
  step_and_hook();
  ++(resimulating ? resimulated_ : simulated_);
}

void ScenarioGame::step_and_hook() {
  scenario_->step_encoded(inputs_);
  if (after_step_) {
    Status s = after_step_(*scenario_);
    if (!s && after_step_status_.ok()) after_step_status_ = std::move(s);
  }
}

Expected<std::vector<std::vector<std::uint8_t>>> ScenarioGame::resimulate(
    std::span<const std::uint8_t> state, std::span<const std::uint8_t> frames) {
  World& world = scenario_->world();
  const std::size_t players = scenario_->params().players;
  const std::size_t size = input_size();
  const std::size_t unit = 1 + players * size;
  if (frames.size() % unit != 0)
    return Status::error("re-simulation: confirmed frames are not whole frames of " +
                         std::to_string(unit) + " bytes");
  const World kept = world;
  if (Status s = world.restore(state); !s) return Status::error("re-simulation: " + s.message());
  std::vector<std::vector<std::uint8_t>> out;
  out.reserve(frames.size() / unit);
  for (std::size_t at = 0; at < frames.size(); at += unit) {
    const std::uint8_t disconnected = frames[at];
    inputs_.assign(frames.begin() + static_cast<std::ptrdiff_t>(at + 1),
                   frames.begin() + static_cast<std::ptrdiff_t>(at + unit));
    for (std::size_t p = 0; p < players && p < 8; ++p)
      if (((disconnected >> p) & 1U) != 0)
        std::fill_n(inputs_.begin() + static_cast<std::ptrdiff_t>(p * size), size, std::uint8_t{0});
    step_and_hook();
    out.emplace_back();
    world.save(out.back());
  }
  world = kept;
  return out;
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
