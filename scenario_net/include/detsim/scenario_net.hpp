// The built-in scenes played through net sessions: the Game adapter for a Scenario and the recorder
// that writes a session's confirmed frames as a replay.
#pragma once

#include <detsim/scenario_net/scenario_game.hpp>
#include <detsim/scenario_net/scenario_recorder.hpp>
