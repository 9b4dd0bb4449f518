// detsim::net::SyncTestSession: GGPO's sync test as a session backend. Every frame it simulates,
// then rolls back check_distance frames and re-simulates them with the same inputs, comparing each
// re-simulated frame's hash with the first pass. A state that save() misses, or any dependence on
// history that load() does not restore, shows up as a mismatch at a named frame, with both states
// kept for a field-level diff. `detsim synctest` runs it on the scenarios.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include <detsim/core/status.hpp>
#include <detsim/net/game.hpp>

namespace detsim::net {

struct SyncTestConfig {
  std::uint32_t players = 2;         ///< 1 .. 128
  std::uint32_t input_size = 4;      ///< 1 .. 64
  std::uint32_t check_distance = 8;  ///< frames rolled back every frame: 1 .. 600
};

/// The first re-simulated frame whose hash differs from the first pass.
struct SyncTestMismatch {
  std::uint64_t frame = 0;          ///< the state frame (after `frame` steps)
  std::uint64_t expected_hash = 0;  ///< first pass
  std::uint64_t actual_hash = 0;    ///< re-simulation
  std::vector<std::uint8_t> expected_state;
  std::vector<std::uint8_t> actual_state;
};

class SyncTestSession {
 public:
  /// Errors name the first invalid field; `game` must outlive the session. Saves frame 0.
  static Expected<SyncTestSession> create(const SyncTestConfig& config, Game& game);
  SyncTestSession(SyncTestSession&&) noexcept;
  SyncTestSession& operator=(SyncTestSession&&) noexcept;
  ~SyncTestSession();

  /// Simulates the next frame with every player's input (players * input_size bytes, player
  /// order, all confirmed), then checks the last check_distance frames as the file comment says.
  /// Returns true while every hash matched; after the first mismatch it returns false and
  /// simulates nothing more. An error (nothing changes) for inputs of the wrong size.
  Expected<bool> advance_frame(std::span<const std::uint8_t> inputs);

  [[nodiscard]] std::uint64_t current_frame() const noexcept;
  [[nodiscard]] std::uint64_t resimulated_frames() const noexcept;
  /// The hash of the current state.
  [[nodiscard]] std::uint64_t current_hash() const noexcept;
  [[nodiscard]] const SyncTestMismatch* mismatch() const noexcept;

 private:
  struct Impl;
  explicit SyncTestSession(std::unique_ptr<Impl> impl) noexcept;
  std::unique_ptr<Impl> impl_;
};

}  // namespace detsim::net
