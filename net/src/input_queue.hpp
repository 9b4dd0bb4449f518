// One player's inputs in a session: the confirmed ones (received, or local) and the ones the game
// actually simulated each frame with (a prediction until the confirmed input arrives), in a ring
// of `capacity` frames. Kept apart from the ring of saved states (GGPO's split): this answers
// "which input does frame F use and was it a guess", the state ring answers "where do we go back".
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace detsim::net::detail {

class InputQueue {
 public:
  InputQueue(std::size_t input_size, std::size_t capacity)
      : input_size_(input_size),
        capacity_(capacity),
        confirmed_(input_size * capacity, 0),
        used_(input_size * capacity, 0),
        zero_(input_size, 0) {}

  [[nodiscard]] std::size_t input_size() const noexcept { return input_size_; }
  [[nodiscard]] std::size_t capacity() const noexcept { return capacity_; }
  /// Every frame before this one has a confirmed input.
  [[nodiscard]] std::uint64_t next_confirmed() const noexcept { return next_confirmed_; }

  /// Whether the confirmed input of `frame` is still held (not overwritten by the ring).
  [[nodiscard]] bool holds(std::uint64_t frame) const noexcept {
    return frame < next_confirmed_ && next_confirmed_ - frame <= capacity_;
  }
  /// The confirmed input of `frame`, which must be held; frame "-1" (before the first) is zeros.
  [[nodiscard]] std::span<const std::uint8_t> confirmed(std::uint64_t frame) const noexcept {
    return {confirmed_.data() + slot(frame), input_size_};
  }
  /// The input before frame `frame` that delta coding refers to: zeros for frame 0.
  [[nodiscard]] std::span<const std::uint8_t> reference(std::uint64_t frame) const noexcept {
    return frame == 0 ? std::span<const std::uint8_t>(zero_) : confirmed(frame - 1);
  }
  /// The last confirmed input (zeros before the first): what "repeat the last" predicts.
  [[nodiscard]] std::span<const std::uint8_t> last_confirmed() const noexcept {
    return reference(next_confirmed_);
  }

  /// Empties the queue so that the next confirmed input is `frame`'s (a rejoining session, which
  /// starts from a snapshot instead of frame 0).
  void restart_at(std::uint64_t frame) noexcept {
    std::fill(confirmed_.begin(), confirmed_.end(), std::uint8_t{0});
    std::fill(used_.begin(), used_.end(), std::uint8_t{0});
    next_confirmed_ = frame;
  }

  /// Forgets the confirmed inputs from `frame` on (a player taken back into a match after an
  /// absence: what its earlier session sent beyond the agreed disconnect frame never counted).
  /// No-op when the queue holds none from `frame`.
  void truncate(std::uint64_t frame) noexcept {
    next_confirmed_ = std::min(next_confirmed_, frame);
  }

  /// Appends the confirmed input of frame next_confirmed().
  void confirm(std::span<const std::uint8_t> input) noexcept {
    std::copy(input.begin(), input.end(),
              confirmed_.begin() + static_cast<std::ptrdiff_t>(slot(next_confirmed_)));
    ++next_confirmed_;
  }

  /// What frame `frame` was simulated with.
  [[nodiscard]] std::span<const std::uint8_t> used(std::uint64_t frame) const noexcept {
    return {used_.data() + slot(frame), input_size_};
  }
  [[nodiscard]] std::span<std::uint8_t> used_mut(std::uint64_t frame) noexcept {
    return {used_.data() + slot(frame), input_size_};
  }

 private:
  [[nodiscard]] std::size_t slot(std::uint64_t frame) const noexcept {
    return static_cast<std::size_t>(frame % capacity_) * input_size_;
  }

  std::size_t input_size_;
  std::size_t capacity_;
  std::uint64_t next_confirmed_ = 0;
  std::vector<std::uint8_t> confirmed_;
  std::vector<std::uint8_t> used_;
  std::vector<std::uint8_t> zero_;
};

}  // namespace detsim::net::detail
