// The scenario registry and every scenario's determinism: each runs twice with identical hashes in
// every frame, and through save/restore (saved at frame k, stepped to n, restored, stepped to n
// again) with the hashes of the uninterrupted run. The scenes' physical promises are in
// sim_scenario_physics_test.cpp.
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

#include "support/scale.hpp"
#include "support/scenario_counts.hpp"

namespace detsim {
namespace {

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(ScenarioRegistry, ListsEveryScenarioOnceSortedByName) {
  const auto list = scenario_list();
  const std::vector<std::string> expected{
      "arena",   "bounce",    "bridge",   "bullet_wall",   "chain",        "characters",
      "cubes",   "dam_break", "dominoes", "drape",         "flag",         "furniture",
      "jelly",   "level",     "motors",   "pendulum",      "pile_boxes",   "pile_spheres",
      "pyramid", "ragdolls",  "rocks",    "rope_bridge",   "slope",        "soccar",
      "spray",   "stack",     "vehicles", "wrecking_ball", "wrecking_rope"};
  ASSERT_EQ(list.size(), expected.size());
  for (std::size_t i = 0; i < list.size(); ++i) {
    EXPECT_EQ(std::string(list[i].name), expected[i]);
    EXPECT_FALSE(list[i].summary.empty()) << list[i].name;
    EXPECT_GT(list[i].default_frames, 0U) << list[i].name;
    EXPECT_LE(list[i].min_players, list[i].default_players);
    EXPECT_LE(list[i].default_players, list[i].max_players);
    EXPECT_LE(list[i].default_count, list[i].max_count);
    const ScenarioInfo* found = find_scenario(list[i].name);
    ASSERT_NE(found, nullptr) << list[i].name;
    EXPECT_EQ(found->name, list[i].name);
    EXPECT_EQ(found->summary, list[i].summary);
    EXPECT_EQ(found->default_frames, list[i].default_frames);
  }
  EXPECT_EQ(find_scenario("nope"), nullptr);
  EXPECT_EQ(find_scenario(""), nullptr);
}

TEST(ScenarioRegistry, BadNamesAndParametersAreErrorsThatSayWhatIsAllowed) {
  auto bad = Scenario::create("pyramids");
  ASSERT_FALSE(bad.ok());
  EXPECT_TRUE(contains(bad.message(), "unknown scenario 'pyramids'")) << bad.message();
  EXPECT_TRUE(contains(bad.message(), "pyramid,")) << bad.message();  // the known names

  bad = Scenario::create("arena", {.players = 65});
  ASSERT_FALSE(bad.ok());
  EXPECT_TRUE(contains(bad.message(), "2 to 64 players, got 65")) << bad.message();
  bad = Scenario::create("arena", {.players = 1});
  EXPECT_FALSE(bad.ok());
  bad = Scenario::create("stack", {.players = 2});
  ASSERT_FALSE(bad.ok());
  EXPECT_TRUE(contains(bad.message(), "takes no players")) << bad.message();
  bad = Scenario::create("pile_boxes", {.count = 100001});
  ASSERT_FALSE(bad.ok());
  EXPECT_TRUE(contains(bad.message(), "1 to 100000 bodies")) << bad.message();
  bad = Scenario::create("pyramid", {.count = 101});
  ASSERT_FALSE(bad.ok());
  EXPECT_TRUE(contains(bad.message(), "1 to 100 rows")) << bad.message();
  bad = Scenario::create("chain", {.count = 1001});
  ASSERT_FALSE(bad.ok());
  EXPECT_TRUE(contains(bad.message(), "1 to 1000 links")) << bad.message();
  bad = Scenario::create("bounce", {.count = 3});
  ASSERT_FALSE(bad.ok());
  EXPECT_TRUE(contains(bad.message(), "takes no body count")) << bad.message();
}

TEST(ScenarioRegistry, DefaultsAreFilledIn) {
  auto arena = Scenario::create("arena");
  ASSERT_TRUE(arena.ok()) << arena.message();
  EXPECT_EQ(arena->params().players, 2U);
  EXPECT_FALSE(arena->player_body(0).is_null());
  EXPECT_FALSE(arena->player_body(1).is_null());
  EXPECT_NE(arena->player_body(0), arena->player_body(1));
  EXPECT_TRUE(arena->player_body(2).is_null());

  auto pile = Scenario::create("pile_spheres", {.count = 27});
  ASSERT_TRUE(pile.ok()) << pile.message();
  EXPECT_EQ(pile->world().body_count(), 28U);  // the ground and 27 spheres
  auto full = Scenario::create("pile_boxes");
  ASSERT_TRUE(full.ok());
  EXPECT_EQ(full->params().count, 1000U);
  EXPECT_EQ(full->world().body_count(), 1001U);
  EXPECT_EQ(full->world().def().seed, 1U);
  // The pyramid's count is its rows: n rows hold n (n + 1) / 2 boxes.
  auto pyramid = Scenario::create("pyramid");
  ASSERT_TRUE(pyramid.ok());
  EXPECT_EQ(pyramid->params().count, 20U);
  EXPECT_EQ(pyramid->world().body_count(), 211U);  // the ground and 210 boxes
  auto small = Scenario::create("pyramid", {.count = 8});
  ASSERT_TRUE(small.ok());
  EXPECT_EQ(small->world().body_count(), 37U);
  // The joint scenes: a ragdoll is 11 bodies and 10 joints; the chain hangs N links.
  auto ragdolls = Scenario::create("ragdolls", {.count = 3});
  ASSERT_TRUE(ragdolls.ok()) << ragdolls.message();
  EXPECT_EQ(ragdolls->world().joint_ids().size(), 30U);
  auto chain = Scenario::create("chain", {.count = 12});
  ASSERT_TRUE(chain.ok()) << chain.message();
  EXPECT_EQ(chain->world().body_count(), 13U);  // the static block and 12 links
  EXPECT_EQ(chain->world().joint_ids().size(), 12U);
  auto seeded = Scenario::create("spray", {.seed = 77});
  ASSERT_TRUE(seeded.ok());
  EXPECT_EQ(seeded->world().def().seed, 77U);
}

TEST(PlayerInputs, EncodeInThreeBytesAndBack) {
  std::array<std::uint8_t, PlayerInput::encoded_size> bytes{};
  for (int b = 0; b < 256; b += 51) {
    for (int x = -128; x < 128; x += 17) {
      const PlayerInput in{static_cast<std::uint8_t>(b), static_cast<std::int8_t>(x),
                           static_cast<std::int8_t>(-x - 1)};
      encode_input(in, bytes);
      EXPECT_EQ(bytes[0], in.buttons);
      EXPECT_EQ(bytes[1], static_cast<std::uint8_t>(x & 0xFF));  // two's complement
      EXPECT_EQ(decode_input(bytes), in);
    }
  }
}

TEST(PlayerInputs, ScriptedInputIsAPureFunctionThatVaries) {
  int changes = 0;
  int jumps = 0;
  for (std::uint64_t f = 0; f < 600; ++f) {
    EXPECT_EQ(scripted_input(5, f, 1), scripted_input(5, f, 1));
    const PlayerInput now = scripted_input(5, f, 1);
    if (f > 0) {
      const PlayerInput before = scripted_input(5, f - 1, 1);
      if (now.move_x != before.move_x || now.move_z != before.move_z) ++changes;
    }
    // Buttons are pressed on a decision's first frame only.
    if (f % 15 != 0) {
      EXPECT_EQ(now.buttons, 0) << "frame " << f;
    }
    jumps += (now.buttons & PlayerInput::jump) != 0 ? 1 : 0;
  }
  // The stick holds a decision for 15 frames: 39 boundaries in 600 frames, nearly all of which
  // move it.
  EXPECT_GE(changes, 30);
  EXPECT_LE(changes, 39);
  EXPECT_GE(jumps, 3);  // 1 in 4 decisions on average: 10 expected
  EXPECT_FALSE(scripted_input(5, 0, 1) == scripted_input(6, 0, 1) &&
               scripted_input(5, 15, 1) == scripted_input(6, 15, 1));
  EXPECT_FALSE(scripted_input(5, 0, 0) == scripted_input(5, 0, 1) &&
               scripted_input(5, 15, 0) == scripted_input(5, 15, 1));
}

// ---- Every scenario: twice, and through save/restore ----

struct Recorded {
  std::vector<std::uint64_t> hashes;  // after each step
  std::vector<std::uint8_t> saved;    // the state after step k
};

// The piles at 5^3 bodies: the same code paths as 1000 in a test-sized run (the pyramid keeps its
// default 20 rows); the rocks, whose hulls cost more per pair, at 30.
std::uint32_t test_count(const ScenarioInfo& info) {
  return test::scenario_test_count(info,
                                   std::min(info.default_count, info.name == "rocks" ? 30U : 125U));
}

ScenarioParams small(const ScenarioInfo& info) {
  return {.seed = 7, .players = info.max_players, .count = test_count(info)};
}

std::uint32_t frames_for(const ScenarioInfo& info) {
  return static_cast<std::uint32_t>(test::scaled(std::min<std::size_t>(info.default_frames, 360)));
}

void step_with_inputs(Scenario& s) {
  std::vector<PlayerInput> inputs(s.params().players);
  for (std::uint32_t p = 0; p < inputs.size(); ++p)
    inputs[p] = scripted_input(s.params().seed, s.world().frame(), p);
  s.step(inputs);
}

Recorded record(const ScenarioInfo& info, std::uint32_t frames, std::uint32_t save_at) {
  auto created = Scenario::create(info.name, small(info));
  EXPECT_TRUE(created.ok()) << created.message();
  Recorded r;
  if (!created.ok()) return r;
  Scenario s = std::move(created.value());
  for (std::uint32_t f = 0; f < frames; ++f) {
    step_with_inputs(s);
    r.hashes.push_back(s.world().hashes().total);
    if (f + 1 == save_at) r.saved = s.world().save();
  }
  return r;
}

class EveryScenario : public testing::TestWithParam<std::string> {};

TEST_P(EveryScenario, RunsIdenticallyTwiceAndThroughSaveRestore) {
  const ScenarioInfo& info = *find_scenario(GetParam());
  const std::uint32_t n = frames_for(info);
  const std::uint32_t k = n / 3;
  const Recorded first = record(info, n, k);
  const Recorded second = record(info, n, k);
  ASSERT_EQ(first.hashes.size(), n);
  for (std::uint32_t f = 0; f < n; ++f)
    ASSERT_EQ(first.hashes[f], second.hashes[f]) << info.name << ": runs differ at frame " << f + 1;
  EXPECT_NE(first.hashes.front(), first.hashes.back()) << info.name << ": nothing happened";

  // Restore frame k into the scenario (made fresh, then overwritten) and step to n again.
  auto created = Scenario::create(info.name, small(info));
  ASSERT_TRUE(created.ok());
  Scenario s = std::move(created.value());
  ASSERT_TRUE(s.world().restore(first.saved).ok());
  ASSERT_EQ(s.world().frame(), k);
  ASSERT_EQ(s.world().hashes().total, first.hashes[k - 1]);
  for (std::uint32_t f = k; f < n; ++f) {
    step_with_inputs(s);
    ASSERT_EQ(s.world().hashes().total, first.hashes[f])
        << info.name << ": after restoring frame " << k << ", frame " << f + 1 << " differs";
  }
}

std::vector<std::string> names() {
  std::vector<std::string> out;
  for (const ScenarioInfo& info : scenario_list())
    out.emplace_back(info.name);
  return out;
}

INSTANTIATE_TEST_SUITE_P(Scenarios, EveryScenario, testing::ValuesIn(names()),
                         [](const testing::TestParamInfo<std::string>& p) { return p.param; });

TEST(ScenarioSeeds, TheSeedChangesTheRunOfSeededScenarios) {
  for (const ScenarioInfo& info : scenario_list()) {
    if (!info.uses_seed) continue;
    auto a = Scenario::create(info.name, {.seed = 1, .count = test_count(info)});
    auto b = Scenario::create(info.name, {.seed = 2, .count = test_count(info)});
    ASSERT_TRUE(a.ok() && b.ok());
    for (int f = 0; f < 320; ++f) {
      step_with_inputs(a.value());
      step_with_inputs(b.value());
    }
    // What moves differs: the bodies, or the particles (the flag's wind moves only its cloth).
    const StateHashes ha = a->world().hashes();
    const StateHashes hb = b->world().hashes();
    EXPECT_TRUE(ha.section("bodies") != hb.section("bodies") ||
                ha.section("particles") != hb.section("particles"))
        << info.name;
  }
}

}  // namespace
}  // namespace detsim
