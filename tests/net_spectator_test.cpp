// Spectators (net/spectator.hpp): served by one player's session, they reproduce every confirmed
// frame, may lag, and catch up faster than real time.
#include <gtest/gtest.h>

#include <detsim/net/spectator.hpp>

#include "support/net_match.hpp"

namespace detsim {
namespace {

using test::Match;
using test::MatchOptions;

void expect_same_frames(const test::PeerRecord& player, const test::PeerRecord& spectator,
                        std::size_t frames, const std::string& who) {
  ASSERT_GE(spectator.hashes.size(), frames) << who;
  ASSERT_GE(player.hashes.size(), frames) << who;
  for (std::size_t f = 0; f < frames; ++f) {
    ASSERT_EQ(spectator.hashes[f], player.hashes[f]) << who << " differs at frame " << f;
  }
  EXPECT_TRUE(
      std::equal(player.status.begin(), player.status.end(), spectator.status.begin(),
                 spectator.status.begin() + static_cast<std::ptrdiff_t>(player.status.size())))
      << who;
}

TEST(NetSpectator, SpectatorsReproduceEveryConfirmedFrameAndALateOneCatchesUp) {
  MatchOptions o;
  o.players = 3;
  o.frames = 2400;
  o.link = net::internet_link();
  o.spectators = 2;
  Match m(o);
  ASSERT_TRUE(m.run()) << m.compare();
  EXPECT_EQ(m.compare(), "");
  for (std::uint32_t k = 0; k < 2; ++k)
    expect_same_frames(m.record(0), m.spectator_record(k), o.frames,
                       "spectator " + std::to_string(k));
  EXPECT_EQ(m.spectator(0).frames_behind(), 0U);
}

TEST(NetSpectator, ALateSpectatorCatchesUpFasterThanRealTime) {
  // The spectator first polls 20 s (1200 ticks) into a 2400-frame match: it must simulate more
  // than one frame per tick to finish within the time the players take plus a little.
  MatchOptions o;
  o.frames = 2400;
  o.link = net::internet_link();
  o.spectators = 1;
  o.spectator_join_tick = 1200;
  Match m(o);
  ASSERT_TRUE(m.run()) << m.compare();
  expect_same_frames(m.record(0), m.spectator_record(0), o.frames, "late spectator");
  EXPECT_GT(m.spectator(0).stats().catch_up_calls, 100U);
  // 1200 frames behind at 8 frames per tick: caught up well before the players finish + 1 s.
  EXPECT_LT(m.ticks(), o.frames + 200);
  const auto served = m.session(0).peer_stats(2);  // spectator 0 is "player" players + 0
  ASSERT_TRUE(served.has_value());
  EXPECT_TRUE(served->synchronized);
}

TEST(NetSpectator, ASpectatorOfAnotherMatchNeverRuns) {
  MatchOptions o;
  o.frames = 120;
  o.spectators = 1;
  o.max_ticks = 400;
  o.configure_spectator = [](std::uint32_t, net::SpectatorConfig& c) {
    c.fingerprint += 1;  // the spectator expects another match than the host plays
  };
  Match m(o);
  EXPECT_FALSE(m.run());
  EXPECT_FALSE(m.spectator(0).running());
  EXPECT_EQ(m.spectator(0).current_frame(), 0U);
  EXPECT_GT(m.spectator(0).stats().dropped, 0U);
}

TEST(NetSpectator, RejectsInvalidConfigs) {
  test::CounterGame game;
  auto network = net::SimNetwork::create(2, 1).value();
  net::SpectatorConfig c;
  c.players = 9;
  auto s = net::SpectatorSession::create(c, game, network.endpoint(1));
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("players"), std::string::npos);
  c.players = 2;
  c.catch_up_frames = 0;
  s = net::SpectatorSession::create(c, game, network.endpoint(1));
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("catch_up_frames"), std::string::npos);
}

}  // namespace
}  // namespace detsim
