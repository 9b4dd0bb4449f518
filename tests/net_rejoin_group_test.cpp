// Rejoining and late joining in matches of three or more players (docs/NET.md, "Rejoining"):
// every peer takes the old session as gone from one agreed frame D, the snapshot's server names
// the frame R the player is back from, and its back report takes the player back at R on every
// other peer. Sessions over the simulated network in virtual time (support/net_match.hpp); the
// two-player cases are in net_rejoin_test.cpp, the same over UDP in cli_netplay_survive_test.cpp.
#include <algorithm>
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include <detsim/net/protection.hpp>
#include <detsim/net/protocol.hpp>
#include <detsim/net/session.hpp>
#include <detsim/net/sim_network.hpp>

#include "support/net_match.hpp"

namespace detsim {
namespace {

using net::EventType;
using net::InputStatus;
using test::Match;
using test::MatchOptions;

/// The interval [from, until) over which `record` shows `player` away (disconnected, zero input)
/// after its first frames: from its first disconnected frame to the next confirmed one.
struct Away {
  std::uint64_t from = 0;
  std::uint64_t until = 0;
};
Away away_of(const test::PeerRecord& r, std::uint32_t players, std::uint32_t player) {
  const std::size_t frames = r.hashes.size();
  Away a;
  while (a.from < frames && r.status[a.from * players + player] != InputStatus::disconnected)
    ++a.from;
  a.until = a.from;
  while (a.until < frames && r.status[a.until * players + player] == InputStatus::disconnected)
    ++a.until;
  return a;
}

/// Checks a match of m.players() in which `joiner` came (back) once: every other peer delivered
/// `frames` frames, all alike input for input and hash for hash, and one match an offline run
/// gives; the joiner is away over one interval [D, R) everywhere, confirmed before and after it;
/// the joiner's sessions delivered the same frames; every peer named the return; nobody saw a
/// desync or a missing check, and checks were compared again after the return. `away`: [D, R)
/// as the first peer other than the joiner delivered it.
void check_group_return(Match& m, std::uint64_t frames, std::uint32_t joiner, const Away& away) {
  const std::uint32_t n = m.players();
  const std::uint32_t ref = joiner == 0 ? 1 : 0;
  const test::PeerRecord& a = m.record(ref);
  const std::size_t size = m.session(ref).config().input_size;
  const std::size_t unit = n * size;
  EXPECT_GE(a.hashes.size(), frames);
  EXPECT_EQ(m.offline_hashes(ref), a.hashes) << "peer " << ref << "'s record is one match";
  EXPECT_LT(away.from, away.until) << "the joiner was away for a while";
  for (std::uint64_t f = 0; f < a.hashes.size(); ++f) {
    const bool gone = f >= away.from && f < away.until;
    ASSERT_EQ(a.status[f * n + joiner], gone ? InputStatus::disconnected : InputStatus::confirmed)
        << "frame " << f << ": away over [" << away.from << ", " << away.until << ") only";
  }
  // Every other peer delivered the very same frames.
  for (std::uint32_t p = 0; p < n; ++p) {
    if (p == ref || p == joiner) continue;
    const test::PeerRecord& b = m.record(p);
    EXPECT_GE(b.hashes.size(), frames);
    const std::size_t common = std::min(a.hashes.size(), b.hashes.size());
    for (std::size_t f = 0; f < common; ++f) {
      ASSERT_EQ(b.hashes[f], a.hashes[f]) << "peer " << p << ", frame " << f;
      ASSERT_TRUE(std::equal(b.inputs.begin() + static_cast<std::ptrdiff_t>(f * unit),
                             b.inputs.begin() + static_cast<std::ptrdiff_t>((f + 1) * unit),
                             a.inputs.begin() + static_cast<std::ptrdiff_t>(f * unit)))
          << "peer " << p << ", frame " << f;
    }
  }
  // The joiner's sessions: the earlier one (if it played) up to where it stopped, the new one
  // from its snapshot on.
  const test::PeerRecord& before = m.earlier_record();
  for (std::size_t f = 0; f < before.hashes.size(); ++f)
    ASSERT_EQ(before.hashes[f], a.hashes[f]) << "frame " << f << ", before the restart";
  EXPECT_GE(away.from, before.hashes.size()) << "no frame it delivered is taken from it";
  const test::PeerRecord& after = m.record(joiner);
  EXPECT_GE(after.first_frame + after.hashes.size(), frames);
  EXPECT_LE(after.first_frame, away.until) << "the snapshot is of a frame before the return";
  for (std::size_t i = 0; i < after.hashes.size() && after.first_frame + i < a.hashes.size(); ++i) {
    const std::size_t f = after.first_frame + i;
    ASSERT_EQ(after.hashes[i], a.hashes[f]) << "frame " << f << ", after the return";
    ASSERT_TRUE(std::equal(after.inputs.begin() + static_cast<std::ptrdiff_t>(i * unit),
                           after.inputs.begin() + static_cast<std::ptrdiff_t>((i + 1) * unit),
                           a.inputs.begin() + static_cast<std::ptrdiff_t>(f * unit)))
        << "frame " << f;
  }
  // Every peer named the return: one served the snapshot (its frame), the others took the
  // player back at R; the joiner names the snapshot's frame.
  std::uint32_t served = 0;
  for (std::uint32_t p = 0; p < n; ++p) {
    std::optional<std::uint64_t> named;
    for (const net::Event& e : m.record(p).events)
      if (e.type == EventType::rejoined && e.player == joiner) named = e.frame;
    EXPECT_TRUE(named.has_value()) << "peer " << p << " raised no rejoined event";
    if (!named || p == joiner) continue;
    if (m.session(p).stats().snapshots_served == 1) {
      ++served;
      EXPECT_EQ(*named, after.first_frame) << "the server names its snapshot's frame";
    } else {
      EXPECT_EQ(*named, away.until) << "peer " << p << " took the player back at R";
    }
  }
  EXPECT_EQ(served, 1U) << "exactly one peer served the snapshot";
  for (std::uint32_t p = 0; p < n; ++p) {
    EXPECT_FALSE(m.record(p).has(EventType::desync)) << "peer " << p;
    EXPECT_FALSE(m.record(p).has(EventType::check_missing)) << "peer " << p;
    EXPECT_EQ(m.session(p).stats().ignored_back_reports, 0U) << "peer " << p;
  }
  // Checks compared again after the return: the joiner with each other peer from R on.
  const std::uint64_t interval = m.session(ref).config().check_interval;
  const std::uint64_t from_r = frames > away.until ? (frames - away.until) / interval : 0;
  EXPECT_GE(m.session(joiner).stats().checks_compared + 2 * (n - 1), from_r * (n - 1));
  EXPECT_EQ(m.session(joiner).stats().checks_skipped, 0U);
}

/// check_group_return, returning [D, R).
Away expect_group_return(Match& m, std::uint64_t frames, std::uint32_t joiner) {
  const Away away = away_of(m.record(joiner == 0 ? 1 : 0), m.players(), joiner);
  check_group_return(m, frames, joiner, away);
  return away;
}

MatchOptions group(std::uint32_t players, std::uint32_t restarted) {
  MatchOptions o;
  o.players = players;
  o.frames = 900;
  o.link.latency_us = 20'000;
  o.max_ticks = 4000;
  o.restart_peer = restarted;
  o.restart_tick = 300;
  o.rejoin_tick = 360;  // down for one second: within everyone's disconnect timeout
  return o;
}

TEST(NetRejoinGroup, ARestartedPlayerOfThreeComesBackAtOneFrameOnEveryPeer) {
  for (const bool sealed : {false, true}) {
    SCOPED_TRACE(sealed ? "sealed" : "plain framing");
    if (sealed && !net::protection::available()) continue;
    MatchOptions o = group(3, 2);
    if (!sealed) o.match_key.reset();
    Match m(o);
    ASSERT_TRUE(m.run());
    m.idle(60);
    const Away away = expect_group_return(m, o.frames, 2);
    // Taken as gone when its new session came, not after the 5 s timeout.
    EXPECT_LT(away.until, away.from + 120) << "[" << away.from << ", " << away.until << ")";
    for (std::uint32_t p = 0; p < 2; ++p) {
      std::size_t gone = 0;
      for (const net::Event& e : m.record(p).events)
        if (e.type == EventType::disconnected && e.player == 2) ++gone;
      EXPECT_EQ(gone, 1U) << "peer " << p << ": one disconnect, of the old session";
    }
  }
}

TEST(NetRejoinGroup, OverALossyLinkEveryJoinerOfThreeComesBackAlike) {
  // Each player in turn, restarted within the timeout or joining an open seat, over a link that
  // loses, reorders and jitters; the joiner's first session sent its inputs further ahead
  // (input delay 10 against 2), so the peers hold different shares of them when it goes.
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const auto joiner = static_cast<std::uint32_t>(seed % 3);
    MatchOptions o = group(3, joiner);
    o.seed = seed;
    o.link = net::internet_link();
    o.max_ticks = 6000;
    const bool open_seat = seed % 2 == 0;
    if (open_seat) {
      o.restart_tick = 0;
      o.rejoin_tick = 300;
    }
    o.configure = [joiner, open_seat](std::uint32_t p, net::SessionConfig& c) {
      if (p == joiner) c.input_delay = 10;
      if (p != joiner && open_seat) c.open_seats = {joiner};
    };
    Match m(o);
    ASSERT_TRUE(m.run());
    m.idle(120);
    expect_group_return(m, o.frames, joiner);
  }
}

TEST(NetRejoinGroup, APeerPastTheReturnSimulatesItAgainFromThere) {
  // The joiner presses nothing: its inputs after the return equal what the peers simulated while
  // it was gone (zero), so only taking it back at R — not a misprediction — makes a peer that
  // had simulated past R simulate those frames again, now with the player there.
  MatchOptions o = group(3, 2);
  o.zero_input_peer = 2;
  o.max_prediction = 16;
  Match m(o);
  ASSERT_TRUE(m.run());
  m.idle(60);
  expect_group_return(m, o.frames, 2);
}

TEST(NetRejoinGroup, APeerThatHeldLessOfTheOldProcessSetsTheFrameOfTheReturn) {
  // Player 2's datagrams to player 1 are lost for the last second before its process dies, so
  // peer 1 holds fewer of its inputs than peer 0. Peer 0 binds the new session first; the return
  // must still start where peer 1's share ends (the lowest), which peer 0 learns only from peer
  // 1's gone report: it serves the snapshot once every peer reported the same frame.
  MatchOptions o = group(3, 2);
  o.match_key.reset();
  Match* match = nullptr;
  o.on_tick = [&match](std::uint32_t p, std::uint64_t tick, net::Session&) {
    if (p != 0 || match == nullptr) return;
    net::LinkConditions link;
    link.latency_us = 20'000;
    if (tick == 240) link.loss_ppm = 1'000'000;
    if (tick == 240 || tick == 330) {
      ASSERT_TRUE(match->network().set_link(2, 1, link).ok());
    }
  };
  Match m(o);
  match = &m;
  ASSERT_TRUE(m.run());
  m.idle(60);
  const Away away = expect_group_return(m, o.frames, 2);
  // What peer 0 alone held of the old process's inputs was dropped: the return starts earlier.
  const test::PeerRecord& before = m.earlier_record();
  EXPECT_LE(away.from, 245U) << "peer 1's share ended when the loss began";
  EXPECT_GT(before.hashes.size() + 60, away.from);
}

TEST(NetRejoinGroup, InLockstepARestartedPlayerOfThreeComesBackAlike) {
  MatchOptions o = group(3, 1);
  o.mode = net::SessionMode::lockstep;
  Match m(o);
  ASSERT_TRUE(m.run());
  m.idle(60);
  expect_group_return(m, o.frames, 1);
}

TEST(NetRejoinGroup, WhenPlayerZeroRestartsTheNextPlayerServesTheSnapshot) {
  MatchOptions o = group(3, 0);
  Match m(o);
  ASSERT_TRUE(m.run());
  m.idle(60);
  expect_group_return(m, o.frames, 0);
  EXPECT_EQ(m.session(1).stats().snapshots_served, 1U);
  EXPECT_EQ(m.session(2).stats().snapshots_served, 0U);
}

TEST(NetRejoinGroup, FourPlayersOverALossyLinkTakeBackAPlayerDownPastTheTimeout) {
  // Down 8 s: the others time it out and agree on its frame (a majority stays); its new session
  // then comes back through the same path, over a link that loses, reorders and jitters.
  for (const std::uint64_t seed : {1U, 2U, 3U, 4U}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    MatchOptions o = group(4, 1);
    o.seed = seed;
    o.frames = 1200;
    o.link = net::internet_link();
    o.max_ticks = 6000;
    o.rejoin_tick = 300 + 8 * 60;
    Match m(o);
    ASSERT_TRUE(m.run());
    m.idle(120);
    const Away away = expect_group_return(m, o.frames, 1);
    // The others waited out the 5 s timeout (the match holds at the prediction limit), then
    // played 3 s without it: about 180 frames.
    EXPECT_GT(away.until, away.from + 150) << "[" << away.from << ", " << away.until << ")";
    for (std::uint32_t p : {0U, 2U, 3U})
      EXPECT_TRUE(m.record(p).has(EventType::disconnected)) << "peer " << p;
  }
}

TEST(NetRejoinGroup, ALateJoinerTakesAnOpenSeatOfAThreePlayerMatch) {
  // Players 0 and 1 start with player 2's seat open; 5 s in, player 2's session joins.
  MatchOptions o = group(3, 2);
  o.restart_tick = 0;  // its first session never says anything
  o.rejoin_tick = 300;
  o.configure = [](std::uint32_t p, net::SessionConfig& c) {
    if (p != 2) c.open_seats = {2};
  };
  Match m(o);
  ASSERT_TRUE(m.run());
  m.idle(60);
  const Away away = expect_group_return(m, o.frames, 2);
  EXPECT_EQ(away.from, 0U);
  EXPECT_GT(away.until, 250U) << "players 0 and 1 played without it until the join";
  for (std::uint32_t p = 0; p < 2; ++p)
    EXPECT_FALSE(m.record(p).has(EventType::disconnected)) << "an open seat is not a disconnect";
}

TEST(NetRejoinGroup, TwoLateJoinersTakeTheirOpenSeatsOneAfterTheOther) {
  // Player 0 starts alone with both other seats open. Player 1 joins after 3 s: its snapshot has
  // player 2's seat open too. Player 2 joins after 6 s, through whichever of the two answers
  // first (player 0; or player 1, which joined late itself, when player 2's link to player 0 is
  // slow); the other takes it back by the back report.
  for (const bool slow_to_zero : {false, true}) {
    SCOPED_TRACE(slow_to_zero ? "player 1 serves" : "player 0 serves");
    MatchOptions o;
    o.players = 3;
    o.frames = 900;
    o.link.latency_us = 20'000;
    o.max_ticks = 4000;
    o.restart_peer = 1;
    o.restart_tick = 0;
    o.rejoin_tick = 180;
    o.more_restarts = {{2, 0, 360}};
    o.configure = [](std::uint32_t p, net::SessionConfig& c) {
      if (p == 0) c.open_seats = {1, 2};
    };
    if (slow_to_zero) {
      o.setup = [](net::SimNetwork& network) {
        net::LinkConditions slow;
        slow.latency_us = 300'000;
        ASSERT_TRUE(network.set_link(0, 2, slow).ok());
        ASSERT_TRUE(network.set_link(2, 0, slow).ok());
      };
    }
    Match m(o);
    ASSERT_TRUE(m.run());
    m.idle(60);
    const test::PeerRecord& a = m.record(0);
    ASSERT_GE(a.hashes.size(), o.frames);
    EXPECT_EQ(m.offline_hashes(0), a.hashes);
    const Away one = away_of(a, 3, 1);
    const Away two = away_of(a, 3, 2);
    EXPECT_EQ(one.from, 0U);
    EXPECT_EQ(two.from, 0U);
    EXPECT_GT(one.until, 120U);
    EXPECT_GT(two.until, one.until + 120) << "player 2 came 3 s after player 1";
    for (std::uint32_t p : {1U, 2U}) {
      const test::PeerRecord& b = m.record(p);
      EXPECT_GE(b.first_frame + b.hashes.size(), o.frames) << "peer " << p;
      for (std::size_t i = 0; i < b.hashes.size() && b.first_frame + i < a.hashes.size(); ++i)
        ASSERT_EQ(b.hashes[i], a.hashes[b.first_frame + i]) << "peer " << p << ", frame " << i;
      EXPECT_TRUE(m.record(p).has(EventType::rejoined)) << "peer " << p;
    }
    EXPECT_EQ(m.session(slow_to_zero ? 1 : 0).stats().snapshots_served, slow_to_zero ? 1U : 2U);
    // Player 1 took player 2 back too, whether it served the snapshot or got the back report.
    bool saw_two = false;
    for (const net::Event& e : m.record(1).events)
      saw_two = saw_two || (e.type == EventType::rejoined && e.player == 2);
    EXPECT_TRUE(saw_two);
    for (std::uint32_t p = 0; p < 3; ++p) {
      EXPECT_FALSE(m.record(p).has(EventType::desync)) << "peer " << p;
      EXPECT_FALSE(m.record(p).has(EventType::check_missing)) << "peer " << p;
      EXPECT_FALSE(m.record(p).has(EventType::disconnected)) << "peer " << p;
    }
  }
}

TEST(NetRejoinGroup, ABackReportFromAnotherFrameThanTheAgreedOneIsIgnored) {
  // Player 2 falls silent for good; peer 1 hears, from peer 0's datagrams, that it is back from
  // a frame nobody took it as gone at. It stays gone on both; they agree on every frame.
  MatchOptions o;
  o.players = 3;
  o.match_key.reset();
  o.frames = 700;
  o.max_ticks = 3000;
  o.link.latency_us = 20'000;
  o.restart_peer = 2;  // its process ends at tick 200 and never comes back
  o.restart_tick = 200;
  o.rejoin_tick = ~std::uint64_t{0};
  // Peer 0's input datagrams to peer 1, once player 2 is gone on peer 0, say it is back from a
  // frame after the agreed one (the plain framing: a peer that lies, or one on the path).
  std::uint64_t forged = 0;
  o.wrap = test::tamper(0, [&forged](net::PeerId to, net::protocol::Packet& p, std::uint64_t) {
    if (to != 1 || p.header.type != net::protocol::PacketType::input) return true;
    for (const net::protocol::GoneReport& g : p.input.gone) {
      if (g.player != 2) continue;
      p.input.back = {{2, g.frame + 1, p.input.current_frame + 1}};
      ++forged;
    }
    return true;
  });
  Match m(o);
  EXPECT_FALSE(m.run()) << "player 2 never finishes";
  EXPECT_GT(forged, 100U);
  EXPECT_GT(m.session(1).stats().ignored_back_reports, 100U);
  EXPECT_FALSE(m.record(1).has(EventType::rejoined));
  const test::PeerRecord& a = m.record(0);
  const test::PeerRecord& b = m.record(1);
  ASSERT_GE(a.hashes.size(), 700U);
  ASSERT_GE(b.hashes.size(), 700U);
  for (std::size_t f = 0; f < 700; ++f)
    ASSERT_EQ(a.hashes[f], b.hashes[f]) << "frame " << f;
  const Away away = away_of(b, 3, 2);
  EXPECT_EQ(away.until, b.hashes.size()) << "gone for good";
  EXPECT_FALSE(b.has(EventType::desync));
}

}  // namespace
}  // namespace detsim
