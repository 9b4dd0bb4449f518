// Named scenarios: the scenes that tests, the `detsim` command, the golden files and the
// benchmarks share (docs/SCENARIOS.md describes each).
//
// A scenario is a World built from a name and a few parameters, plus the per-frame game logic that
// drives it (player inputs, scripted movers, RNG-driven events). That logic reads only the World
// (its frame, bodies and RNG) and the frame's inputs, so the World's saved state is the scenario's
// whole state: restoring a World restores the scenario.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <detsim/core/status.hpp>
#include <detsim/sim/world.hpp>

namespace detsim {

/// One player's input for one frame: a small plain struct with a fixed 3-byte canonical encoding
/// (buttons, then the two axes as two's complement bytes).
struct PlayerInput {
  static constexpr std::uint8_t jump = 1U;  ///< buttons bit 0: an upward impulse when grounded
  static constexpr std::uint8_t dash = 2U;  ///< buttons bit 1: a burst along the stick
  static constexpr std::size_t encoded_size = 3;

  std::uint8_t buttons = 0;
  std::int8_t move_x = 0;  ///< stick, -127 .. 127 (-128 counts as -127)
  std::int8_t move_z = 0;

  friend constexpr bool operator==(const PlayerInput&, const PlayerInput&) noexcept = default;
};

/// What a scenario is and which parameters it takes.
struct ScenarioInfo {
  std::string_view name;
  std::string_view summary;
  std::uint32_t default_frames = 600;
  std::uint32_t min_players = 0;  ///< 0 .. 0: takes no players
  std::uint32_t max_players = 0;
  std::uint32_t default_players = 0;
  std::uint32_t default_count = 0;  ///< 0: no `count` parameter; else its default
  std::uint32_t max_count = 0;
  bool uses_seed = false;  ///< whether the seed changes anything but the RNG's unused state
  std::string_view count_unit = "bodies";  ///< what `count` counts: "bodies", "rows", "links", ...
  /// Bytes of one player's input for one frame, as replays and sessions carry it: a PlayerInput's
  /// 3 for the built-ins, a game's own size for one registered with ScenarioDefinition::input_size.
  std::uint32_t input_size = PlayerInput::encoded_size;
};

/// Parameters of a scenario; zero means "the scenario's default".
struct ScenarioParams {
  std::uint64_t seed = 1;
  std::uint32_t players = 0;
  std::uint32_t count = 0;  ///< the scene's size, where it has one: bodies (piles), rows (pyramid),
                            ///< links (chain), planks (bridge), ragdolls

  friend constexpr bool operator==(const ScenarioParams&, const ScenarioParams&) noexcept = default;
};

/// The most players a scenario takes: what a game server's match (net::Server) and a replay
/// allow. A peer-to-peer session plays at most 8 of them.
inline constexpr std::uint32_t max_scenario_players = 64;
/// The largest input a game's own scenario may take, in bytes (what a session datagram carries).
inline constexpr std::uint32_t max_scenario_input_size = 64;

/// A game's own scenario, for register_scenario(): how to build its scene and run its frames.
/// Like the built-ins, its logic reads only the World (bodies, RNG, and the game's own state kept
/// in it with World::set_game_state) and the frame's inputs, so the World's saved state is the
/// game's whole state, and every tool that works on scenarios works on it.
struct ScenarioDefinition {
  std::string name;     ///< 1..32 characters of a-z, 0-9 and _; a replay records it
  std::string summary;  ///< one line, for `detsim scenarios`
  std::uint32_t default_frames = 600;
  std::uint32_t min_players = 0;  ///< 0 .. max_players; 0 .. 0: takes no players
  std::uint32_t max_players = 0;  ///< at most max_scenario_players
  std::uint32_t default_players = 0;
  std::uint32_t default_count = 0;  ///< 0: no `count` parameter; else its default
  std::uint32_t max_count = 0;
  bool uses_seed = false;
  std::string count_unit = "bodies";
  /// The world's settings (step, solver, gravity); its seed is replaced by the parameters'.
  WorldDef world;
  /// Builds the scene at frame 0 into the new, empty world: bodies, joints, the game state.
  std::function<void(World&, const ScenarioParams&)> build;
  /// A frame's game logic, before the world steps: one input per player (players() of them).
  /// Required when the scenario takes players, unless the game has its own input (below).
  std::function<void(World&, std::span<const PlayerInput>, const ScenarioParams&)> control;

  /// A game whose input is not a PlayerInput sets its size in bytes (1 ..
  /// max_scenario_input_size) and gives control_bytes instead of control; 0: PlayerInput. Every
  /// tool carries the bytes as they are (replays, sessions, reports, bisect, the sync test).
  std::uint32_t input_size = 0;
  /// A frame's game logic for a game with its own input: `inputs` holds players() inputs of
  /// input_size bytes each, in player order. A player without an input (gone from a session, or
  /// not given) has all zero bytes: the game must read that as "nothing pressed".
  std::function<void(World&, std::span<const std::uint8_t> inputs, const ScenarioParams&)>
      control_bytes;
  /// The scripted stand-in player for a game's own input (record without an input source, the
  /// tools' --bot, the sync test): writes out.size() == input_size bytes for `player` at `frame`
  /// of a match seeded with `seed`. Must be a pure function of the three. Empty: bytes of a hash
  /// of (seed, player, frame / 15), a new decision every quarter second.
  std::function<void(std::uint64_t seed, std::uint64_t frame, std::uint32_t player,
                     std::span<std::uint8_t> out)>
      script;
};

/// Adds a game's own scenario to this process's registry, so that Scenario::create, replays
/// (record, verify, seek), desync reports, bisect's re-simulation, the sync test, the session
/// adapters and the `detsim` commands run through detsim::cli::run_cli know it by name. Register
/// before anything creates scenarios (at the start of main). An error, registering nothing, names
/// the problem: a bad or taken name, an empty build, inconsistent player or count ranges, a world
/// definition World::create refuses.
Status register_scenario(const ScenarioDefinition& definition);

/// Every scenario known to this process (the built-ins and the registered), sorted by name.
[[nodiscard]] std::vector<ScenarioInfo> scenario_list();
/// The scenario called `name`, or nullptr.
[[nodiscard]] const ScenarioInfo* find_scenario(std::string_view name) noexcept;

namespace scenes_detail {
struct ScenarioEntry;
}  // namespace scenes_detail

class Scenario {
 public:
  /// The scenario `name` with `params` (defaults filled in). Unknown names and out-of-range
  /// parameters are errors naming what is wrong and what is allowed.
  static Expected<Scenario> create(std::string_view name, const ScenarioParams& params = {});

  [[nodiscard]] const ScenarioInfo& info() const noexcept;
  /// The parameters with the defaults filled in.
  [[nodiscard]] const ScenarioParams& params() const noexcept { return params_; }
  [[nodiscard]] World& world() noexcept { return world_; }
  [[nodiscard]] const World& world() const noexcept { return world_; }

  /// Runs the frame's game logic with one input per player (missing inputs count as neutral,
  /// extra ones are ignored), then steps the world. A game with its own input (info().input_size
  /// from ScenarioDefinition::input_size) takes step_encoded instead; here its players have zero
  /// bytes.
  void step(std::span<const PlayerInput> inputs = {});
  /// The same with every player's input in its bytes: players() inputs of info().input_size bytes
  /// each, in player order (what replays and sessions carry); missing bytes count as zero, extra
  /// ones are ignored.
  void step_encoded(std::span<const std::uint8_t> inputs);
  /// Whether the frame's logic takes PlayerInput (the built-ins, and control) rather than the
  /// game's own bytes (control_bytes).
  [[nodiscard]] bool takes_player_input() const noexcept;
  /// The scripted stand-in's input for `player` at `frame` in its bytes (out.size() must be
  /// info().input_size): scripted_input for PlayerInput scenarios, the game's own script else.
  void scripted(std::uint64_t seed, std::uint64_t frame, std::uint32_t player,
                std::span<std::uint8_t> out) const;

  /// The body a player controls (players 0 .. params().players - 1), or the null ID.
  [[nodiscard]] BodyId player_body(std::uint32_t player) const;

 private:
  Scenario(const scenes_detail::ScenarioEntry& entry, const ScenarioParams& params, World world)
      : entry_(&entry), params_(params), world_(std::move(world)) {}

  const scenes_detail::ScenarioEntry* entry_;  ///< in the registry, which never removes one
  ScenarioParams params_;
  World world_;
};

/// A deterministic stand-in for a human player, for headless runs, tests and golden files: the
/// input of `player` at `frame` for a match seeded with `seed` (a pure function of the three).
[[nodiscard]] PlayerInput scripted_input(std::uint64_t seed, std::uint64_t frame,
                                         std::uint32_t player) noexcept;

/// The 3-byte canonical encoding of an input, and back.
void encode_input(const PlayerInput& input,
                  std::span<std::uint8_t, PlayerInput::encoded_size> out) noexcept;
[[nodiscard]] PlayerInput decode_input(
    std::span<const std::uint8_t, PlayerInput::encoded_size> in) noexcept;

}  // namespace detsim
