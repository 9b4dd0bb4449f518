// pushball: a two-player game built on detsim, as a studio would write one — two pucks pushing a
// ball into goals in a walled arena, with scores, dash cooldowns and a kickoff pause kept in the
// World's game state. It is registered as a scenario, so its own tool binary (tool_main.cpp) has
// every detsim subcommand for its replays and desync reports.
#pragma once

#include <cstdint>
#include <vector>

#include <detsim/detsim.hpp>

namespace pushball {

/// The rules, in SI units and frames of 1/60 s.
inline constexpr std::uint16_t dash_cooldown_frames = 90;
inline constexpr std::uint16_t kickoff_frames = 90;  ///< the pause after a goal
/// The goal lines: a ball whose centre passes x = +goal_line scores for player 1, -goal_line
/// for player 2 (the goal mouths are the gaps |z| < goal_half_width in the end walls at x = +-10).
inline const detsim::Fixed goal_line = detsim::Fixed::from_int(21) / detsim::Fixed::from_int(2);
inline const detsim::Fixed goal_half_width = detsim::Fixed::from_int(2);

/// The game's own state beside the bodies, and its canonical encoding (15 bytes, little-endian).
struct State {
  std::uint32_t score[2] = {0, 0};
  std::uint16_t cooldown[2] = {0, 0};  ///< frames until each player may dash again
  std::uint16_t kickoff = 0;           ///< frames until play resumes after a goal
  std::uint8_t last_scorer = 0;        ///< 0 none yet, 1 or 2

  [[nodiscard]] std::vector<std::uint8_t> encode() const;
  [[nodiscard]] static State decode(std::span<const std::uint8_t> bytes);
};

/// A player's input for one frame: the game's own, 5 bytes (little-endian), finer than a
/// PlayerInput's stick. Replays, sessions, reports and every tool carry these bytes as they are
/// (ScenarioDefinition::input_size); all zero is "nothing pressed", which a gone player gets.
struct Input {
  static constexpr std::size_t size = 5;
  static constexpr std::uint8_t dash = 1;  ///< buttons bit 0
  std::int16_t aim_x = 0;                  ///< -32767 .. 32767: the push, towards +x
  std::int16_t aim_z = 0;
  std::uint8_t buttons = 0;

  /// Writes the 5 bytes to out[0 .. 4].
  void encode(std::span<std::uint8_t> out) const;
  [[nodiscard]] static Input decode(std::span<const std::uint8_t> in);
};
/// One frame's inputs, both players', as Scenario::step_encoded takes them.
[[nodiscard]] std::vector<std::uint8_t> encode_frame(const Input& player1, const Input& player2);
/// The scripted stand-in player (the tools' --bot and runs without inputs): it holds an aim for a
/// quarter of a second and dashes at the start of one decision in four.
[[nodiscard]] Input scripted(std::uint64_t seed, std::uint64_t frame, std::uint32_t player);

/// The fields diff and bisect name (score.player1, cooldown.player2, ...).
[[nodiscard]] std::vector<detsim::GameField> state_fields();

/// The bodies' user data: how the rules find them.
inline constexpr std::uint64_t ball_tag = 100;
inline constexpr std::uint64_t player_tag = 1;  ///< player p's puck: player_tag + p

/// The scenario "pushball": 2 players, 3600 frames by default.
[[nodiscard]] detsim::ScenarioDefinition definition();

/// The game's state in `world`.
[[nodiscard]] State state_of(const detsim::World& world);
/// The body tagged `tag` (ball_tag, player_tag + p), or the null ID.
[[nodiscard]] detsim::BodyId find(const detsim::World& world, std::uint64_t tag);

}  // namespace pushball
