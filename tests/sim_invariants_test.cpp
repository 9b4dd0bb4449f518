// World::validate() and the checked-invariant machinery (core/include/detsim/core/assert.hpp):
// every scenario keeps the invariants at every frame, and a broken one is named.
#include <algorithm>
#include <string>

#include <gtest/gtest.h>
#include <detsim/core/assert.hpp>
#include <detsim/detsim.hpp>

#include "support/mixed_scene.hpp"
#include "support/scenario_counts.hpp"

namespace detsim {
namespace {

TEST(WorldInvariants, HoldAfterEveryStepOfEveryScenario) {
  for (const ScenarioInfo& info : scenario_list()) {
    ScenarioParams params;
    params.players = info.default_players;
    params.count = test::scenario_test_count(info, 27);  // 0: the scene takes no count
    auto scenario = Scenario::create(info.name, params);
    ASSERT_TRUE(scenario.ok()) << info.name << ": " << scenario.message();
    std::vector<PlayerInput> inputs(params.players);
    for (std::uint64_t frame = 1; frame <= 400; ++frame) {
      for (std::uint32_t p = 0; p < params.players; ++p)
        inputs[p] = scripted_input(1, frame, p);
      scenario->step(inputs);
      const Status s = scenario->world().validate();
      ASSERT_TRUE(s.ok()) << info.name << " frame " << frame << ": " << s.message();
    }
  }
  test::run_mixed_scene([](const World& w, int frame) {
    const Status s = w.validate();
    ASSERT_TRUE(s.ok()) << "mixed scene frame " << frame << ": " << s.message();
  });
}

// A settled pile sleeps as one island; waking one box by hand (a fault injection, not the API,
// which wakes whole islands at the next step) splits it, and validate() names the pair.
TEST(WorldInvariants, ASplitIslandIsNamed) {
  auto scenario = Scenario::create("pile_boxes", {.seed = 1, .players = 0, .count = 8}).value();
  World& w = scenario.world();
  for (int i = 0; i < 600; ++i)
    scenario.step();
  ASSERT_TRUE(w.validate().ok());
  const BodyId box = w.body_ids().back();
  ASSERT_FALSE(w.body(box)->awake) << "the pile should be asleep by now";
  const auto injection =
      parse_injection(std::to_string(w.frame()) + ":" + std::to_string(box.value) + ":awake:1");
  ASSERT_TRUE(injection.ok()) << injection.message();
  ASSERT_TRUE(apply_injection(w, injection.value()).ok());
  const Status s = w.validate();
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("an island is split"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find(std::to_string(box.value)), std::string::npos) << s.message();
  // The next step wakes the whole island: the invariant holds again.
  scenario.step();
  EXPECT_TRUE(w.validate().ok()) << w.validate().message();
}

TEST(CheckedInvariants, AFailedOneAbortsNamingWhatAndWhere) {
  EXPECT_DEATH(invariant_failed("the ring holds frame 7", "session.cpp", 42),
               "invariant failed at session.cpp:42: the ring holds frame 7");
#if DETSIM_CHECKS
  EXPECT_DEATH(DETSIM_ASSERT(1 + 1 == 3), "1 \\+ 1 == 3");
#else
  DETSIM_ASSERT(1 + 1 == 3);  // compiled out: nothing happens
  EXPECT_FALSE(checks_enabled);
#endif
}

}  // namespace
}  // namespace detsim
