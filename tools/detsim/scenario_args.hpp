// Building a scenario from command-line arguments, with errors that say what is allowed.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <detsim/core/status.hpp>
#include <detsim/net/session.hpp>
#include <detsim/replay/replay.hpp>
#include <detsim/scenes/scenario.hpp>
#include <detsim/sim/inject.hpp>

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

/// The --inject options, parsed (errors name the option and what is wrong).
Expected<std::vector<Injection>> parse_injections(const std::vector<std::string>& specs);

/// "arena (seed 1, 2 players)" / "pile_boxes (seed 1, 1000 bodies)".
std::string describe(const Scenario& scenario);
/// The same for the scenario a replay's fingerprint names.
std::string describe(const replay::Fingerprint& fingerprint);

/// Every scenario's name, comma-separated.
std::string scenario_names();

/// What the peers of a session must share to play together (SessionConfig::fingerprint):
/// replay::session_fingerprint of the scenario's replay fingerprint, with the session mode and the
/// match's length in frames (peers that stop at different frames would record different replays).
std::uint64_t session_fingerprint(const Scenario& scenario, net::SessionMode mode,
                                  std::uint64_t frames);

}  // namespace detsim::cli
