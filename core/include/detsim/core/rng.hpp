// detsim::Rng: the simulation's one source of randomness, part of the world state.
//
// xoshiro256** (Blackman and Vigna, 2018): 256 bits of state, period 2^256 - 1, passes BigCrush
// and PractRand, and is a handful of 64-bit operations written out here so that every platform and
// standard library gives the same stream (<random>'s distributions are implementation-defined). The
// state is seeded from one 64-bit seed through SplitMix64, as the authors recommend.
#pragma once

#include <array>
#include <cstdint>

#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/vec3.hpp>

namespace detsim {

class Rng {
 public:
  using State = std::array<std::uint64_t, 4>;

  /// The generator seeded from `seed` (every seed, 0 included, gives a valid, distinct stream).
  explicit constexpr Rng(std::uint64_t seed = 0) noexcept : state_(seed_state(seed)) {}

  /// The next 64 uniformly distributed bits.
  constexpr std::uint64_t next_u64() noexcept {
    const std::uint64_t result = rotl(state_[1] * 5U, 7) * 9U;
    const std::uint64_t t = state_[1] << 17;
    state_[2] ^= state_[0];
    state_[3] ^= state_[1];
    state_[1] ^= state_[2];
    state_[0] ^= state_[3];
    state_[2] ^= t;
    state_[3] = rotl(state_[3], 45);
    return result;
  }

  /// A uniformly distributed integer in [0, bound), exactly unbiased (Lemire's multiply-and-reject,
  /// 2019). bound == 0 returns 0 and draws nothing.
  std::uint64_t below(std::uint64_t bound) noexcept;

  /// A uniformly distributed integer in [low, high] (inclusive); returns low when high <= low.
  std::int64_t range(std::int64_t low, std::int64_t high) noexcept;

  /// A Fixed uniform in [0, 1): every one of the 2^32 values in that range equally likely.
  Fixed unit() noexcept { return Fixed::from_raw(static_cast<std::int64_t>(next_u64() >> 32)); }

  /// A Fixed uniform over [low, high) on the Fixed grid (exactly uniform over the raw values);
  /// returns low when high <= low.
  Fixed uniform(Fixed low, Fixed high) noexcept;

  /// A unit vector uniformly distributed over the sphere (rejection sampling in the cube, then
  /// normalised): |v|^2 within 2 ulp of 1.
  Vec3 unit_vector() noexcept;

  /// The raw state, for saving, hashing and restoring.
  [[nodiscard]] constexpr const State& state() const noexcept { return state_; }
  /// Replaces the state. The all-zero state is the one state xoshiro cannot leave; it is refused
  /// (returns false, nothing changes).
  constexpr bool set_state(const State& state) noexcept {
    if ((state[0] | state[1] | state[2] | state[3]) == 0) return false;
    state_ = state;
    return true;
  }

  friend constexpr bool operator==(const Rng&, const Rng&) noexcept = default;

 private:
  static constexpr std::uint64_t rotl(std::uint64_t x, int k) noexcept {
    return (x << k) | (x >> (64 - k));
  }
  static constexpr State seed_state(std::uint64_t seed) noexcept {
    State s{};
    for (std::uint64_t& word : s) {  // SplitMix64: never yields four zero words
      seed += 0x9E3779B97F4A7C15U;
      std::uint64_t z = seed;
      z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9U;
      z = (z ^ (z >> 27)) * 0x94D049BB133111EBU;
      word = z ^ (z >> 31);
    }
    return s;
  }

  State state_;
};

}  // namespace detsim
