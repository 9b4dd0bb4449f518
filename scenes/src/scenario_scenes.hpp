// The scenario builders and their per-frame logic, shared by scenario.cpp (the registry) and
// scenario_play.cpp (the scenes with game logic). Internal to detsim::scenes.
#pragma once

#include <span>

#include <detsim/scenes/scenario.hpp>

namespace detsim::scenes_detail {

// Adds a body to a scenario's world. Scenario definitions are constants checked by the tests: a
// refusal is a bug here.
inline BodyId add(World& w, const BodyDef& def) {
  return w.create_body(def).value();
}

// Each builder fills an empty World made from the scenario's WorldDef.
void build_pile(World& w, const ScenarioParams& p, bool spheres);
void build_stack(World& w, const ScenarioParams& p);
void build_pyramid(World& w, const ScenarioParams& p);
void build_dominoes(World& w, const ScenarioParams& p);
void build_bullet_wall(World& w, const ScenarioParams& p);
void build_bounce(World& w, const ScenarioParams& p);
void build_slope(World& w, const ScenarioParams& p);
void build_spray(World& w, const ScenarioParams& p);
void build_arena(World& w, const ScenarioParams& p);

// Per-frame logic, run before each step. Reads only the World and the inputs.
void control_spray(World& w, std::span<const PlayerInput> inputs, const ScenarioParams& p);
void control_arena(World& w, std::span<const PlayerInput> inputs, const ScenarioParams& p);

// Tags in BodyDef::user_data by which game logic finds its bodies again (the World is the whole
// scenario state, so nothing else may remember them). A player's tag is player_tag + index.
inline constexpr std::uint64_t player_tag = 0x504C'4159'0000'0000ULL;  // "PLAY"
inline constexpr std::uint64_t platform_tag = 0x504C'4154'0000'0000ULL;
inline constexpr std::uint64_t spawned_tag = 0x5350'4157'0000'0000ULL;
inline constexpr std::uint64_t crate_tag = 0x4352'4154'0000'0000ULL;

}  // namespace detsim::scenes_detail
