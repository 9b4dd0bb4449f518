// The sync test session (net/synctest.hpp): a deterministic game passes; a game whose save()
// misses part of its state fails at the first frame where that part matters, with both states.
#include <gtest/gtest.h>

#include <detsim/net/synctest.hpp>
#include <detsim/scenario_net/scenario_game.hpp>

#include "support/net_match.hpp"

namespace detsim {
namespace {

/// CounterGame, except that save() forgets a hidden counter that advance() mixes in from frame
/// `leak_from` on: a re-simulation from a loaded state sees another value.
class LeakyGame final : public net::Game {
 public:
  explicit LeakyGame(std::uint64_t leak_from) : leak_from_(leak_from) {}
  std::uint64_t save(std::vector<std::uint8_t>& state) override { return inner_.save(state); }
  void load(std::span<const std::uint8_t> state) override { inner_.load(state); }
  void advance(const net::FrameInputs& inputs, bool resimulating) override {
    ++hidden_;
    std::vector<std::uint8_t> bytes(inputs.bytes.begin(), inputs.bytes.end());
    if (inputs.frame >= leak_from_) bytes[0] = static_cast<std::uint8_t>(bytes[0] + hidden_);
    inner_.advance(net::FrameInputs{inputs.frame, inputs.input_size, bytes, inputs.status},
                   resimulating);
  }

 private:
  test::CounterGame inner_;
  std::uint64_t leak_from_;
  std::uint64_t hidden_ = 0;
};

std::vector<std::uint8_t> inputs_of(std::uint64_t frame) {
  return {static_cast<std::uint8_t>(frame),
          static_cast<std::uint8_t>(frame * 7),
          1,
          2,
          static_cast<std::uint8_t>(frame / 3),
          0,
          0,
          9};
}

TEST(NetSyncTest, ADeterministicGamePassesAndEveryFrameIsResimulatedKTimes) {
  test::CounterGame game;
  auto s = net::SyncTestSession::create({2, 4, 7}, game).value();
  for (std::uint64_t f = 0; f < 100; ++f)
    ASSERT_TRUE(s.advance_frame(inputs_of(f)).value()) << f;
  EXPECT_EQ(s.mismatch(), nullptr);
  EXPECT_EQ(s.current_frame(), 100U);
  EXPECT_EQ(s.resimulated_frames(), (100U - 7 + 1) * 7);
  EXPECT_EQ(game.resimulated, s.resimulated_frames());
  // The final state is that of a plain run with the same inputs.
  test::CounterGame plain;
  std::vector<std::uint8_t> state;
  std::vector<net::InputStatus> status(2, net::InputStatus::confirmed);
  for (std::uint64_t f = 0; f < 100; ++f)
    plain.advance(net::FrameInputs{f, 4, inputs_of(f), status}, false);
  EXPECT_EQ(s.current_hash(), plain.save(state));
}

TEST(NetSyncTest, StateThatSaveMissesIsCaughtAtItsFirstFrameWithBothStates) {
  LeakyGame game(40);
  auto s = net::SyncTestSession::create({2, 4, 5}, game).value();
  std::uint64_t f = 0;
  while (s.advance_frame(inputs_of(f)).value())
    ++f;
  const net::SyncTestMismatch* m = s.mismatch();
  ASSERT_NE(m, nullptr);
  // The first step using the hidden counter is step 40 (to state 41). Every frame re-simulates the
  // last 5 steps, step 40 included as soon as it ran: the mismatch names state 41, found at once.
  EXPECT_EQ(m->frame, 41U);
  EXPECT_EQ(s.current_frame(), 41U);
  EXPECT_NE(m->expected_hash, m->actual_hash);
  EXPECT_EQ(m->expected_state.size(), 16U);
  EXPECT_NE(m->expected_state, m->actual_state);
  // Nothing more is simulated after a mismatch.
  EXPECT_FALSE(s.advance_frame(inputs_of(f)).value());
  EXPECT_EQ(s.current_frame(), 41U);
}

TEST(NetSyncTest, BadConfigsAndInputsAreErrors) {
  test::CounterGame game;
  EXPECT_NE(net::SyncTestSession::create({2, 4, 0}, game).message().find("check distance"),
            std::string::npos);
  EXPECT_NE(net::SyncTestSession::create({129, 4, 8}, game).message().find("players"),
            std::string::npos);
  auto s = net::SyncTestSession::create({2, 4, 8}, game).value();
  const std::vector<std::uint8_t> short_inputs(7, 0);
  auto r = s.advance_frame(short_inputs);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.message().find("8 bytes, got 7"), std::string::npos) << r.message();
  EXPECT_EQ(s.current_frame(), 0U);
}

TEST(NetSyncTest, ArenaPassesThroughTheScenarioAdapter) {
  ScenarioParams params;
  params.players = 4;
  Scenario scenario = Scenario::create("arena", params).value();
  net::ScenarioGame game(scenario);
  auto s = net::SyncTestSession::create({4, 3, 8}, game).value();
  std::vector<std::uint8_t> inputs(12);
  for (std::uint64_t f = 0; f < 120; ++f) {
    for (std::uint32_t p = 0; p < 4; ++p)
      encode_input(scripted_input(3, f, p),
                   std::span<std::uint8_t, 3>(inputs.data() + std::size_t{p} * 3, 3));
    ASSERT_TRUE(s.advance_frame(inputs).value()) << f;
  }
}

}  // namespace
}  // namespace detsim
