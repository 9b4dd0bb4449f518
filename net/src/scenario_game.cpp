// The Game adapter for detsim scenarios (scenario_game.hpp).
#include <detsim/net/scenario_game.hpp>

#include <xxhash.h>

namespace detsim::net {

std::uint64_t ScenarioGame::save(std::vector<std::uint8_t>& state) {
  state = scenario_->world().save();
  // The World's state hash is XXH3-64 of exactly these bytes (docs/STATE.md): hashing them here
  // saves a second encoding of the state.
  return XXH3_64bits(state.data(), state.size());
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

}  // namespace detsim::net
