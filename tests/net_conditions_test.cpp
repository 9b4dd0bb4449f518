// Sessions under hostile simulated networks (issue: 2, 4 and 8 players, 100 ms RTT, +-20 ms
// jitter, 5% loss, 1% duplication and reordering, 10,000 frames): every peer confirms the same
// inputs and hashes at every frame, equal to an offline replay, with no desync event.
//
// Every combination of 2, 4 and 8 players with 5% loss, 20% loss and a 2 s outage of one peer runs
// twice: with `arena` (real detsim worlds through ScenarioGame) and with the cheap CounterGame,
// whose length the sanitizer build does not shorten. The sanitizer build runs a tenth of the arena
// frames (DETSIM_TEST_SCALE).
#include <gtest/gtest.h>

#include <cstdio>

#include <detsim/net/session.hpp>
#include <detsim/net/sim_network.hpp>
#include <detsim/replay/scenario_replay.hpp>
#include <detsim/scenario_net/scenario_game.hpp>
#include <detsim/scenario_net/scenario_recorder.hpp>

#include "support/net_match.hpp"
#include "support/scale.hpp"

namespace detsim {
namespace {

using net::EventType;
using test::Match;
using test::MatchOptions;

const std::uint64_t full_match = test::scaled(10'000);

void expect_clean(const Match& m, const std::string& what) {
  EXPECT_EQ(m.compare(), "") << what;
  EXPECT_EQ(m.checks_complete(), "") << what;
  for (std::uint32_t p = 0; p < m.players(); ++p)
    EXPECT_FALSE(m.record(p).has(EventType::disconnected)) << what << ", peer " << p;
}

struct Network {
  const char* name;
  std::uint32_t loss_ppm;
  bool outage;
};

const Network networks[] = {
    {"5% loss", 50'000, false}, {"20% loss", 200'000, false}, {"2 s outage", 50'000, true}};

std::string param_name(std::uint32_t players, const Network& n) {
  const char* kind = n.outage ? "outage" : (n.loss_ppm > 100'000 ? "loss20" : "loss5");
  return std::to_string(players) + "players_" + kind;
}

class ArenaOnBadNetworks : public testing::TestWithParam<std::tuple<std::uint32_t, Network>> {};

TEST_P(ArenaOnBadNetworks, EveryPeerAgreesAtEveryConfirmedFrame) {
  const auto [players, network] = GetParam();
  MatchOptions o;
  o.players = players;
  o.frames = full_match;
  o.arena = true;
  o.link = net::internet_link(network.loss_ppm);
  o.seed = 100 + players;
  // Player 1 is cut off for 2 s: 20 s in at full length, 5 s in at the sanitizer build's tenth.
  const std::uint64_t outage_at = full_match >= 2000 ? 20'000'000 : 5'000'000;
  if (network.outage) {
    o.setup = [outage_at](net::SimNetwork& n) {
      ASSERT_TRUE(n.add_outage(1, outage_at, outage_at + 2'000'000).ok());
    };
  }
  Match m(o);
  const std::string what = param_name(players, network);
  ASSERT_TRUE(m.run()) << what << ": " << m.compare();
  expect_clean(m, what);
  // The network really was bad: the sessions predicted wrongly and rolled back, and lost packets.
  EXPECT_GT(m.session(0).stats().rollbacks, 0U) << what;
  EXPECT_GT(m.session(0).peer_stats(1)->packets_lost, 0U) << what;
  if (network.outage) {
    EXPECT_TRUE(m.record(0).has(EventType::interrupted)) << what;
    EXPECT_TRUE(m.record(0).has(EventType::resumed)) << what;
  }
}

INSTANTIATE_TEST_SUITE_P(Networks, ArenaOnBadNetworks,
                         testing::Combine(testing::Values(2U, 4U, 8U), testing::ValuesIn(networks)),
                         [](const testing::TestParamInfo<ArenaOnBadNetworks::ParamType>& param) {
                           return param_name(std::get<0>(param.param), std::get<1>(param.param));
                         });

class CounterOnBadNetworks : public testing::TestWithParam<std::tuple<std::uint32_t, Network>> {};

TEST_P(CounterOnBadNetworks, EveryPeerAgreesAtEveryConfirmedFrame) {
  const auto [players, network] = GetParam();
  MatchOptions o;
  o.players = players;
  o.frames = 10'000;
  o.link = net::internet_link(network.loss_ppm);
  o.seed = 200 + players;
  if (network.outage) {
    // Peer 1 is cut off for 2 s, from 30 s in: a warning, then recovery.
    o.setup = [](net::SimNetwork& n) { ASSERT_TRUE(n.add_outage(1, 30'000'000, 32'000'000).ok()); };
  }
  Match m(o);
  const std::string what = std::to_string(players) + " players, " + network.name;
  ASSERT_TRUE(m.run()) << what << ": " << m.compare();
  expect_clean(m, what);
  if (network.outage) {
    for (std::uint32_t p = 0; p < players; ++p) {
      if (p == 1) continue;
      EXPECT_TRUE(m.record(p).has(EventType::interrupted)) << what << ", peer " << p;
      EXPECT_TRUE(m.record(p).has(EventType::resumed)) << what << ", peer " << p;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Networks, CounterOnBadNetworks,
                         testing::Combine(testing::Values(2U, 4U, 8U), testing::ValuesIn(networks)),
                         [](const testing::TestParamInfo<CounterOnBadNetworks::ParamType>& param) {
                           return param_name(std::get<0>(param.param), std::get<1>(param.param));
                         });

TEST(NetConditions, LockstepArenaOnTheInternetEndsIdentical) {
  MatchOptions o;
  o.players = 4;
  o.mode = net::SessionMode::lockstep;
  o.frames = test::scaled(3000);
  o.arena = true;
  o.link = net::internet_link();
  o.max_ticks = o.frames * 20;
  Match m(o);
  ASSERT_TRUE(m.run()) << m.compare();
  expect_clean(m, "lockstep");
  for (std::uint32_t p = 0; p < 4; ++p)
    EXPECT_EQ(m.session(p).stats().rollbacks, 0U);
}

TEST(NetConditions, ArenaHeldAtThePredictionLimitNeverDesyncs) {
  // One slow direction (350 ms one way) keeps both peers at the 8-frame limit most of the time,
  // with corrections arriving while they wait (the GGRS #70/#75 kind of bug).
  MatchOptions o;
  o.frames = test::scaled(3000);
  o.arena = true;
  o.input_delay = 0;
  o.max_ticks = o.frames * 30;
  o.setup = [](net::SimNetwork& n) {
    net::LinkConditions slow = net::internet_link();
    slow.latency_us = 350'000;
    ASSERT_TRUE(n.set_link(1, 0, slow).ok());
  };
  Match m(o);
  ASSERT_TRUE(m.run()) << m.compare();
  expect_clean(m, "at the prediction limit");
  EXPECT_GT(m.session(0).stats().prediction_limit_waits, o.frames / 10);
}

/// A ScenarioGame whose world is nudged at one frame on this machine only: a body's velocity
/// changes by one raw unit, the smallest non-determinism there is.
class NudgedGame final : public net::Game {
 public:
  NudgedGame(Scenario& scenario, std::uint64_t frame) : inner_(scenario), frame_(frame) {}
  std::uint64_t save(std::vector<std::uint8_t>& state) override { return inner_.save(state); }
  void load(std::span<const std::uint8_t> state) override { inner_.load(state); }
  void advance(const net::FrameInputs& inputs, bool resimulating) override {
    World& world = inner_.scenario().world();
    if (inputs.frame == frame_) {
      const BodyId id = inner_.scenario().player_body(0);
      BodyState body = world.body(id).value();
      body.linear_velocity.x = body.linear_velocity.x + Fixed::from_raw(1);
      EXPECT_TRUE(world.set_linear_velocity(id, body.linear_velocity).ok());
    }
    inner_.advance(inputs, resimulating);
  }

 private:
  net::ScenarioGame inner_;
  std::uint64_t frame_;
};

TEST(NetConditions, ANudgedBodyIsDetectedWithinOneCheckInterval) {
  // Four arena peers with their own sessions; peer 3's world is nudged at a seeded frame.
  constexpr std::uint32_t players = 4;
  constexpr std::uint32_t interval = 30;
  const std::uint64_t nudge = 500 + std::uint64_t{scripted_input(7, 0, 0).buttons} * 37 % 300;
  auto created = net::SimNetwork::create(players, 77, net::internet_link());
  ASSERT_TRUE(created.ok()) << created.message();
  net::SimNetwork network = std::move(created.value());
  std::vector<std::unique_ptr<Scenario>> scenarios;
  std::vector<std::unique_ptr<net::Game>> games;
  std::vector<net::Session> sessions;
  for (std::uint32_t p = 0; p < players; ++p) {
    ScenarioParams params;
    params.players = players;
    scenarios.push_back(std::make_unique<Scenario>(Scenario::create("arena", params).value()));
    if (p == 3)
      games.push_back(std::make_unique<NudgedGame>(*scenarios.back(), nudge));
    else
      games.push_back(std::make_unique<net::ScenarioGame>(*scenarios.back()));
    net::SessionConfig c;
    c.players = players;
    c.local_player = p;
    c.input_size = scenarios.back()->info().input_size;
    c.check_interval = interval;
    for (std::uint32_t q = 0; q < players; ++q)
      if (q != p) c.remotes.push_back({q, q});
    auto s = net::Session::create(c, *games.back(), network.endpoint(p));
    ASSERT_TRUE(s.ok()) << s.message();
    sessions.push_back(std::move(s.value()));
  }
  std::array<std::uint8_t, 3> input{};
  std::vector<std::vector<net::Event>> desyncs(players);
  for (std::uint64_t tick = 0; tick < 2000; ++tick) {
    network.advance_to(tick * 16'667);
    for (std::uint32_t p = 0; p < players; ++p) {
      sessions[p].poll(tick * 16'667);
      encode_input(scripted_input(7, tick, p), input);
      ASSERT_TRUE(sessions[p].advance_frame(input).ok());
      for (const net::Event& e : sessions[p].take_events())
        if (e.type == EventType::desync) desyncs[p].push_back(e);
    }
  }
  // The first check after the nudge (state frame nudge + 1 or later) is the one that differs.
  const std::uint64_t expected = (nudge + 1 + interval - 1) / interval * interval;
  for (std::uint32_t p = 0; p < players; ++p) {
    ASSERT_FALSE(desyncs[p].empty()) << "peer " << p << " never noticed";
    EXPECT_EQ(desyncs[p].front().frame, expected) << "peer " << p;
    if (p != 3) {
      EXPECT_EQ(desyncs[p].size(), 1U) << "healthy peers blame only peer 3";
      EXPECT_EQ(desyncs[p].front().player, 3U);
    }
    const net::DesyncEvidence* evidence = sessions[p].desync_evidence();
    ASSERT_NE(evidence, nullptr);
    EXPECT_EQ(evidence->divergent_frame, expected);
    EXPECT_EQ(evidence->agreed_frame, expected - interval);
    // The evidence is this machine's state: it restores, and hashes as reported.
    World check;
    ASSERT_TRUE(check.restore(evidence->divergent_state).ok());
    EXPECT_EQ(check.hashes().total, evidence->local_hash);
  }
  // The desync reports of a healthy peer and of the nudged one: they agree on every body at the
  // agreed frame and disagree at the divergent one, starting with the nudged player's body.
  const replay::Fingerprint fingerprint = replay::fingerprint_of(*scenarios[0]);
  std::vector<replay::DesyncReport> reports;
  for (std::uint32_t p : {0U, 3U}) {
    auto report = net::desync_report(fingerprint, p, *sessions[p].desync_evidence());
    ASSERT_TRUE(report.ok()) << report.message();
    std::string path = DETSIM_BINARY_DIR;
    path.append("/tests/net_desync_").append(std::to_string(p)).append(".dsd");
    ASSERT_TRUE(replay::write_desync_report(path, report.value()).ok());
    auto back = replay::read_desync_report(path);
    ASSERT_TRUE(back.ok()) << back.message();
    EXPECT_EQ(back.value(), report.value());
    EXPECT_EQ(back->confirmed_frames.size(), expected * (1 + players * 3U));
    reports.push_back(std::move(back).value());
    std::remove(path.c_str());
  }
  EXPECT_EQ(reports[0].agreed_bodies, reports[1].agreed_bodies);
  EXPECT_EQ(reports[0].confirmed_frames, reports[1].confirmed_frames);
  ASSERT_EQ(reports[0].divergent_bodies.size(), reports[1].divergent_bodies.size());
  const BodyId nudged = scenarios[0]->player_body(0);
  for (std::size_t i = 0; i < reports[0].divergent_bodies.size(); ++i) {
    if (reports[0].divergent_bodies[i].id != nudged.value) continue;
    EXPECT_NE(reports[0].divergent_bodies[i].hash, reports[1].divergent_bodies[i].hash);
  }
}

}  // namespace
}  // namespace detsim
