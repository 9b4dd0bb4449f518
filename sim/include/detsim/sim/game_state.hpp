// A game's own state beside the bodies (World::set_game_state): scores, timers, cooldowns, whose
// turn it is. The World keeps it as the "game" section of its state, so everything that works
// on World states (save, restore, hashes, replays' keyframes, desync reports, diff, bisect, the
// sync test) works on it too. A description of its fields lets diff and bisect name them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace detsim {

/// The most bytes a game state holds.
inline constexpr std::size_t max_game_state_size = std::size_t{1} << 20;

/// How a described field of a game state is encoded: little-endian integers of 1, 2, 4 or 8 bytes,
/// or a Q32.32 Fixed's 8 raw bytes.
enum class GameFieldType : std::uint8_t { u8, u16, u32, u64, i8, i16, i32, i64, fixed };

/// The bytes a field of `type` takes.
[[nodiscard]] constexpr std::size_t game_field_size(GameFieldType type) noexcept {
  switch (type) {
    case GameFieldType::u8:
    case GameFieldType::i8:
      return 1;
    case GameFieldType::u16:
    case GameFieldType::i16:
      return 2;
    case GameFieldType::u32:
    case GameFieldType::i32:
      return 4;
    default:
      return 8;
  }
}

/// One field of a game state, for diff and bisect to name ("score.player1").
struct GameField {
  std::string name;          ///< 1..64 characters of A-Z a-z 0-9 _ . [ ]; unique in a description
  std::uint32_t offset = 0;  ///< its first byte in the game state
  GameFieldType type = GameFieldType::u32;

  friend bool operator==(const GameField&, const GameField&) = default;
};

}  // namespace detsim
