// Session matches recorded as replays (net/scenario_recorder.hpp): every peer writes the same
// file, and `verify` re-simulates it to the same hashes.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <iterator>

#include <detsim/replay/scenario_replay.hpp>
#include <detsim/scenario_net/scenario_recorder.hpp>

#include "support/net_match.hpp"

namespace detsim {
namespace {

std::vector<char> file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string temp_path(const std::string& name) {
  std::string path = DETSIM_BINARY_DIR;
  path.append("/tests/net_replay_").append(name).append(".dsr");
  return path;
}

TEST(NetReplay, EveryPeerRecordsTheSameReplayAndItVerifies) {
  constexpr std::uint32_t players = 3;
  constexpr std::uint64_t frames = 700;  // two keyframes at the interval of 300
  net::LinkConditions link;
  link.latency_us = 50'000;
  link.jitter_us = 20'000;
  link.loss_ppm = 50'000;
  auto created = net::SimNetwork::create(players + 1, 5, link);  // node 3: a spectator
  ASSERT_TRUE(created.ok());
  net::SimNetwork network = std::move(created.value());
  std::vector<std::unique_ptr<Scenario>> scenarios;
  std::vector<std::unique_ptr<net::ScenarioGame>> games;
  std::vector<net::ScenarioRecorder> recorders;
  std::vector<net::Session> sessions;
  for (std::uint32_t p = 0; p < players; ++p) {
    ScenarioParams params;
    params.players = players;
    params.seed = 9;
    scenarios.push_back(std::make_unique<Scenario>(Scenario::create("arena", params).value()));
    games.push_back(std::make_unique<net::ScenarioGame>(*scenarios.back()));
    auto recorder = net::ScenarioRecorder::create(temp_path(std::to_string(p)), *games.back());
    ASSERT_TRUE(recorder.ok()) << recorder.message();
    recorders.push_back(std::move(recorder.value()));
    net::SessionConfig c;
    c.players = players;
    c.local_player = p;
    c.input_size = games.back()->input_size();
    for (std::uint32_t q = 0; q < players; ++q)
      if (q != p) c.remotes.push_back({q, q});
    if (p == 0) c.spectators = {players};
    auto s = net::Session::create(c, *games.back(), network.endpoint(p));
    ASSERT_TRUE(s.ok()) << s.message();
    sessions.push_back(std::move(s.value()));
  }
  for (std::uint32_t p = 0; p < players; ++p)
    recorders[p].attach(sessions[p]);
  // The spectator records too: the same file, from the confirmed frames it is sent.
  ScenarioParams watched;
  watched.players = players;
  watched.seed = 9;
  Scenario spectator_scenario = Scenario::create("arena", watched).value();
  net::ScenarioGame spectator_game(spectator_scenario);
  auto spectator_recorder =
      net::ScenarioRecorder::create(temp_path("spectator"), spectator_game).value();
  net::SpectatorConfig sc;
  sc.players = players;
  sc.input_size = spectator_game.input_size();
  sc.host = 0;
  auto spectator =
      net::SpectatorSession::create(sc, spectator_game, network.endpoint(players)).value();
  spectator_recorder.attach(spectator);
  std::array<std::uint8_t, 3> input{};
  for (std::uint64_t tick = 0; tick < frames * 3; ++tick) {
    network.advance_to(tick * 16'667);
    bool done = true;
    for (std::uint32_t p = 0; p < players; ++p) {
      sessions[p].poll(tick * 16'667);
      if (sessions[p].current_frame() < frames) {
        encode_input(scripted_input(3, tick, p), input);
        ASSERT_TRUE(sessions[p].advance_frame(input).ok());
      }
      if (recorders[p].frames() < frames) done = false;
    }
    spectator.poll(tick * 16'667);
    spectator.advance();
    if (spectator_recorder.frames() < frames) done = false;
    if (done) break;
  }
  for (std::uint32_t p = 0; p < players; ++p) {
    ASSERT_TRUE(recorders[p].status().ok()) << recorders[p].status().message();
    // Peers stop at the same frame count only if told to: record exactly `frames` of each.
    EXPECT_GE(recorders[p].frames(), frames);
    ASSERT_TRUE(recorders[p].finish().ok());
  }
  const std::vector<char> first = file_bytes(temp_path("0"));
  ASSERT_FALSE(first.empty());
  for (std::uint32_t p = 1; p < players; ++p)
    EXPECT_EQ(file_bytes(temp_path(std::to_string(p))), first) << "peer " << p;
  ASSERT_TRUE(spectator_recorder.finish().ok());
  EXPECT_EQ(spectator_recorder.frames(), frames);
  EXPECT_EQ(file_bytes(temp_path("spectator")), first) << "the spectator's replay";
  std::remove(temp_path("spectator").c_str());
  auto reader = replay::ReplayReader::open(temp_path("0"));
  ASSERT_TRUE(reader.ok()) << reader.message();
  EXPECT_EQ(reader->keyframes().size(), 2U);
  auto verified = replay::verify(reader.value());
  ASSERT_TRUE(verified.ok()) << verified.message();
  EXPECT_TRUE(verified->ok) << verified->note;
  EXPECT_EQ(verified->frames, frames);
  for (std::uint32_t p = 0; p < players; ++p)
    std::remove(temp_path(std::to_string(p)).c_str());
}

TEST(NetReplay, RecorderRefusesAScenarioPastFrameZeroOrABadInterval) {
  Scenario scenario = Scenario::create("arena").value();
  net::ScenarioGame game(scenario);
  auto bad = net::ScenarioRecorder::create(temp_path("bad"), game, 5);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.message().find("keyframe interval"), std::string::npos) << bad.message();
  scenario.step();
  auto late = net::ScenarioRecorder::create(temp_path("late"), game);
  ASSERT_FALSE(late.ok());
  EXPECT_NE(late.message().find("frame 0"), std::string::npos) << late.message();
}

}  // namespace
}  // namespace detsim
