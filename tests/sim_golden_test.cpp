// golden/sim.txt: the state hashes of a mixed scene every 60 frames. Every compiler, optimisation
// level and machine must reproduce them (this test runs in the gcc -O3 and the clang sanitizer
// builds alike). A change is a change of the simulation's results: regenerate only on purpose,
//   DETSIM_UPDATE_GOLDEN=1 <build>/tests/sim_golden_test
// and say in the commit why the results changed.
#include <map>
#include <string>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

#include "support/golden.hpp"
#include "support/mixed_scene.hpp"

namespace detsim {
namespace {

using namespace detsim::literals;

const char* const kGoldenPath = DETSIM_SOURCE_DIR "/golden/sim.txt";

std::map<std::string, std::uint64_t> run_scene() {
  std::map<std::string, std::uint64_t> hashes;
  test::run_mixed_scene([&](const World& w, int frame) {
    if (frame % 60 == 0)
      hashes["frame_" + std::to_string(1000 + frame).substr(1)] = w.hashes().total;
  });
  return hashes;
}

TEST(SimGolden, MixedSceneReproducesItsGoldenHashes) {
  test::check_golden(kGoldenPath,
                     "# World state hashes (XXH3-64 of the canonical state) of the mixed scene "
                     "in\n# tests/sim_golden_test.cpp every 60 frames. Every machine must "
                     "reproduce these.\n# Regenerate only on purpose: DETSIM_UPDATE_GOLDEN=1 "
                     "<build>/tests/sim_golden_test\n",
                     run_scene());
}

}  // namespace
}  // namespace detsim
