// Building a scenario from command-line arguments, with errors that say what is allowed.
#pragma once

#include <cstdint>
#include <string>

#include <detsim/sim/scenario.hpp>
#include <detsim/sim/status.hpp>

#include "commands.hpp"

namespace detsim::cli {

/// The largest --frames any command accepts (about 19 days at 60 Hz).
inline constexpr std::uint64_t max_frames = 100'000'000;

/// The scenario named in `args` (unknown names list the known ones), and its frame count (the
/// scenario's default when args.frames is 0).
struct ChosenScenario {
  Scenario scenario;
  std::uint64_t frames = 0;
};
Expected<ChosenScenario> choose_scenario(const ScenarioArgs& args);

/// "arena (seed 1, 2 players)" / "pile_boxes (seed 1, 1000 bodies)".
std::string describe(const Scenario& scenario);

/// Every scenario's name, comma-separated.
std::string scenario_names();

}  // namespace detsim::cli
