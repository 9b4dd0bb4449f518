// The built-in scenes: named scenarios (piles, stacks, the arena, ...) with their game logic, the
// players' input type and the ragdoll figure, shared by the tests, the `detsim` command, the golden
// files and the benchmarks.
#pragma once

#include <detsim/scenes/ragdoll.hpp>
#include <detsim/scenes/scenario.hpp>
