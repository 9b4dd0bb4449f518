// The built-in scenes: named scenarios (piles, stacks, the arena, ...) with their game logic and
// the players' input type, shared by the tests, the `detsim` command, the golden files and the
// benchmarks.
#pragma once

#include <detsim/scenes/scenario.hpp>
