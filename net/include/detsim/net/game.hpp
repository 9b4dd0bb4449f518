// detsim::net::Game: the small interface through which every session drives a game. A session
// owns the frame loop: it decides when the game saves, loads and advances, and with which inputs.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace detsim::net {

/// Where a player's input for a frame comes from.
enum class InputStatus : std::uint8_t {
  confirmed = 0,     ///< received from its player (or local): final
  predicted = 1,     ///< a guess; the frame is re-simulated if the guess was wrong
  disconnected = 2,  ///< the player is gone: the input is all zero bytes from now on
};

/// The inputs of one frame: input_size bytes per player, in player order, and each one's status.
struct FrameInputs {
  std::uint64_t frame = 0;  ///< the frame being simulated (0 is the first step)
  std::size_t input_size = 0;
  std::span<const std::uint8_t> bytes;  ///< players * input_size
  std::span<const InputStatus> status;  ///< one per player

  [[nodiscard]] std::size_t players() const noexcept { return status.size(); }
  /// Player `player`'s input bytes.
  [[nodiscard]] std::span<const std::uint8_t> input(std::size_t player) const noexcept {
    return bytes.subspan(player * input_size, input_size);
  }
};

/// What a game implements for a session. The session calls these only from inside its own calls
/// (advance_frame), never from another thread.
class Game {
 public:
  virtual ~Game() = default;

  /// Writes the current state's canonical bytes to `state` (replacing its contents; the buffer is
  /// reused between calls) and returns the state's hash. Two machines in the same state must
  /// write the same hash; the bytes need only be what load() reads back.
  virtual std::uint64_t save(std::vector<std::uint8_t>& state) = 0;

  /// Returns the game to a state that save() wrote (earlier in this session).
  virtual void load(std::span<const std::uint8_t> state) = 0;

  /// Simulates one frame with every player's input. `resimulating` is true when the frame is
  /// being simulated again after a rollback: a game skips sounds and effects it already played.
  virtual void advance(const FrameInputs& inputs, bool resimulating) = 0;

  /// Optional, for a server's state snapshots (docs/SERVER.md, "Snapshots"): writes to `delta`
  /// the state `state` coded against an earlier state `base` that the receiver holds (both save()
  /// bytes, or both a StateView's), in a form that compresses better, and returns true. The
  /// default returns false, and the state goes as it is (compressed against the base). A World's
  /// game returns detsim::encode_state_delta's bytes (ScenarioGame does). Both ends of a match
  /// must code alike: the server's game encodes, each client's game decodes.
  virtual bool encode_delta(std::span<const std::uint8_t> state, std::span<const std::uint8_t> base,
                            std::vector<std::uint8_t>& delta) {
    (void)state;
    (void)base;
    (void)delta;
    return false;
  }
  /// The state that encode_delta coded as `delta` against `base`, written to `state`, bit for bit;
  /// false when `delta` is not a delta this game reads (the snapshot is then dropped).
  virtual bool decode_delta(std::span<const std::uint8_t> delta, std::span<const std::uint8_t> base,
                            std::vector<std::uint8_t>& state) {
    (void)delta;
    (void)base;
    (void)state;
    return false;
  }
};

}  // namespace detsim::net
