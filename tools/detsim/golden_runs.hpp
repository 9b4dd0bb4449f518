// The golden scenario runs: what `detsim golden` hashes into golden/scenarios.txt and what
// tests/sim_field_identity_test.cpp records into golden/fields.txt, one list for both.
#pragma once

#include <cstdint>

#include <detsim/scenes/scenario.hpp>

namespace detsim::golden {

/// Every scenario, each long enough to have a hash at frame 1000, and small enough for the
/// emulated 32-bit legs of the determinism matrix, which run ~50x slower than x86-64: the piles
/// have 64 bodies, the pyramid 8 rows, the rocks 30 hulls, the drape a 12 x 12 sheet, the dam
/// break 108 particles, and the resting scenes fall asleep long before their last frame, after
/// which a frame costs almost nothing.
struct GoldenRun {
  const char* scenario;
  ScenarioParams params;
  std::uint64_t frames;
};

inline constexpr GoldenRun runs[] = {
    {"arena", {.seed = 1, .players = 4, .count = 0}, 1200},
    {"bounce", {.seed = 1, .players = 0, .count = 0}, 1000},
    {"bridge", {.seed = 1, .players = 0, .count = 20}, 1000},
    {"bullet_wall", {.seed = 1, .players = 0, .count = 0}, 1000},
    {"chain", {.seed = 1, .players = 0, .count = 30}, 1200},
    {"characters", {.seed = 1, .players = 0, .count = 8}, 1000},
    {"cubes", {.seed = 1, .players = 2, .count = 100}, 1000},
    {"dam_break", {.seed = 1, .players = 0, .count = 3}, 1000},
    {"dominoes", {.seed = 1, .players = 0, .count = 0}, 1000},
    {"drape", {.seed = 1, .players = 0, .count = 12}, 1000},
    {"flag", {.seed = 1, .players = 0, .count = 0}, 1000},
    {"furniture", {.seed = 1, .players = 0, .count = 4}, 1000},
    {"jelly", {.seed = 1, .players = 0, .count = 2}, 1000},
    {"level", {.seed = 1, .players = 0, .count = 4}, 1000},
    {"motors", {.seed = 1, .players = 0, .count = 0}, 1000},
    {"pendulum", {.seed = 1, .players = 0, .count = 0}, 1200},
    {"pile_boxes", {.seed = 1, .players = 0, .count = 64}, 1000},
    {"pile_spheres", {.seed = 1, .players = 0, .count = 64}, 1000},
    {"pyramid", {.seed = 1, .players = 0, .count = 8}, 1000},
    {"ragdolls", {.seed = 3, .players = 0, .count = 4}, 1000},
    {"rocks", {.seed = 1, .players = 0, .count = 30}, 1000},
    {"rope_bridge", {.seed = 1, .players = 0, .count = 4}, 1000},
    {"slope", {.seed = 1, .players = 0, .count = 0}, 1000},
    {"soccar", {.seed = 1, .players = 4, .count = 0}, 1000},
    {"spray", {.seed = 3, .players = 0, .count = 0}, 1200},
    {"stack", {.seed = 1, .players = 0, .count = 0}, 1200},
    {"vehicles", {.seed = 1, .players = 0, .count = 0}, 1000},
    {"wrecking_ball", {.seed = 1, .players = 0, .count = 0}, 1000},
    {"wrecking_rope", {.seed = 1, .players = 0, .count = 0}, 1000},
};

}  // namespace detsim::golden
