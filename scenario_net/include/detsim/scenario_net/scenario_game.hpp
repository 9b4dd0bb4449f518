// detsim::net::ScenarioGame: the Game adapter that lets a session drive a detsim Scenario (and so
// its World) directly: save and load are World::save / World::restore, the hash is the frame's
// state hash, and each player's input is the scenario's input bytes (a PlayerInput's 3-byte
// canonical encoding, or a game's own input: ScenarioDefinition::input_size).
//
// It also remembers the per-part hashes of the states it saved recently, and the states at
// keyframe frames, so that a ScenarioRecorder can write a replay of the confirmed frames without
// simulating anything twice.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include <detsim/core/status.hpp>
#include <detsim/net/game.hpp>
#include <detsim/scenes/scenario.hpp>
#include <detsim/sim/world.hpp>

namespace detsim::net {

class ScenarioGame final : public Game {
 public:
  /// How many recent saves' hashes are remembered (more than any prediction window).
  static constexpr std::size_t remembered_hashes = 64;

  /// Drives `scenario`, which must outlive this adapter.
  explicit ScenarioGame(Scenario& scenario) noexcept : scenario_(&scenario) {}

  /// The input size of a session playing this scenario (SessionConfig::input_size): the
  /// scenario's info().input_size.
  [[nodiscard]] std::uint32_t input_size() const noexcept { return scenario_->info().input_size; }

  std::uint64_t save(std::vector<std::uint8_t>& state) override;
  /// Restores a state save() wrote. A state that does not restore (never the case for bytes this
  /// adapter saved) leaves the world unchanged and is counted by failed_loads().
  void load(std::span<const std::uint8_t> state) override;
  /// Steps the scenario with every player's input; a disconnected player's is all zero (neutral).
  void advance(const FrameInputs& inputs, bool resimulating) override;
  /// A server's state snapshots: detsim::encode_state_delta and decode_state_delta
  /// (<detsim/sim/state_delta.hpp>); false for bytes that are not states (a StateView's).
  bool encode_delta(std::span<const std::uint8_t> state, std::span<const std::uint8_t> base,
                    std::vector<std::uint8_t>& delta) override;
  bool decode_delta(std::span<const std::uint8_t> delta, std::span<const std::uint8_t> base,
                    std::vector<std::uint8_t>& state) override;

  /// A debug hook run after each step, before the state is saved or hashed: a fault injection
  /// (<detsim/sim/inject.hpp>) that makes this machine's game differ, for tests and demos. It runs
  /// on every simulation of a frame, re-simulations included. Its first error is kept.
  void set_after_step(std::function<Status(Scenario&)> hook) { after_step_ = std::move(hook); }
  /// The after-step hook's first error (success when none).
  [[nodiscard]] const Status& after_step_status() const noexcept { return after_step_status_; }

  /// Re-simulates from `state` (a state save() wrote) through `frames` (confirmed frames as in
  /// DesyncEvidence::confirmed_frames, one step each, the after-step hook included) and returns
  /// the state after each step. The game's current state is kept (restored afterwards).
  Expected<std::vector<std::vector<std::uint8_t>>> resimulate(std::span<const std::uint8_t> state,
                                                              std::span<const std::uint8_t> frames);

  [[nodiscard]] Scenario& scenario() noexcept { return *scenario_; }
  [[nodiscard]] std::uint64_t failed_loads() const noexcept { return failed_loads_; }
  /// Frames stepped for the first time, and again after rollbacks.
  [[nodiscard]] std::uint64_t frames_simulated() const noexcept { return simulated_; }
  [[nodiscard]] std::uint64_t frames_resimulated() const noexcept { return resimulated_; }

  /// The hashes of the state most recently saved at `frame`, if it is among the last
  /// remembered_hashes saves' frames.
  [[nodiscard]] std::optional<StateHashes> hashes_at(std::uint64_t frame) const noexcept;
  /// Keep the state bytes of frames that are multiples of `interval` (0: none).
  void keep_keyframes(std::uint32_t interval) noexcept { keyframe_interval_ = interval; }
  /// The state most recently saved at keyframe frame `frame`, or nullptr.
  [[nodiscard]] const std::vector<std::uint8_t>* keyframe_at(std::uint64_t frame) const noexcept;

 private:
  struct Remembered {
    std::uint64_t frame = ~std::uint64_t{0};
    StateHashes hashes;
  };
  struct Keyframe {
    std::uint64_t frame = ~std::uint64_t{0};
    std::vector<std::uint8_t> state;
  };

  void step_and_hook();

  Scenario* scenario_;
  std::function<Status(Scenario&)> after_step_;
  Status after_step_status_;
  std::vector<std::uint8_t> inputs_;
  std::array<Remembered, remembered_hashes> remembered_{};
  std::array<Keyframe, 2> keyframes_{};
  std::uint32_t keyframe_interval_ = 0;
  std::uint64_t failed_loads_ = 0;
  std::uint64_t simulated_ = 0;
  std::uint64_t resimulated_ = 0;
};

}  // namespace detsim::net
