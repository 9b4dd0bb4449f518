// Everything detsim offers a game, in one include.
#pragma once

#include <detsim/core.hpp>
#include <detsim/fixed.hpp>
#include <detsim/net.hpp>
#include <detsim/replay.hpp>
#include <detsim/scenario_net.hpp>
#include <detsim/scenes.hpp>
#include <detsim/sim.hpp>
