// Matches that survive (docs/NET.md, "Partitions" and "Rejoining after a restart"): what a
// two-player partition does under each PartitionPolicy, a restarted player's way back from a
// snapshot, a late joiner in an open seat, and the snapshot and handshake under attack. Sessions
// over the simulated network in virtual time (support/net_match.hpp); the same over UDP between
// processes is in cli_netplay_test.cpp.
#include <algorithm>
#include <optional>

#include <gtest/gtest.h>

#include <detsim/net/protection.hpp>
#include <detsim/net/protocol.hpp>
#include <detsim/net/session.hpp>
#include <detsim/net/sim_network.hpp>

#include "support/net_match.hpp"

namespace detsim {
namespace {

using net::EventType;
using test::Match;
using test::MatchOptions;

// ---- partitions ----

TEST(NetPartition, ATwoPlayerPartitionEndsTheMatchOnBothSidesWithTheSameFrames) {
  // The 8-second outage between two players: before, each marked the other gone and
  // played on alone, ending with different hashes and no event. Now both end where they stood.
  MatchOptions o;
  o.frames = 1200;
  o.link.latency_us = 20'000;
  o.max_ticks = 1800;
  o.setup = [](net::SimNetwork& n) { ASSERT_TRUE(n.add_outage(1, 4'000'000, 12'000'000).ok()); };
  Match m(o);
  EXPECT_FALSE(m.run()) << "the first advance after the end fails, and so does the match";
  m.idle(600);  // past the outage: nothing more is delivered, the end stands
  const std::vector<std::uint8_t> input(4, 0);
  for (std::uint32_t p = 0; p < 2; ++p) {
    SCOPED_TRACE("peer " + std::to_string(p));
    EXPECT_TRUE(m.record(p).has(EventType::disconnected));
    const net::Event* end = nullptr;
    for (const net::Event& e : m.record(p).events)
      if (e.type == EventType::match_ended) end = &e;
    ASSERT_NE(end, nullptr);
    EXPECT_EQ(end->reason, "no majority");
    EXPECT_EQ(end->frame, m.record(p).hashes.size()) << "nothing delivered after the end";
    auto refused = m.session(p).advance_frame(input);
    ASSERT_FALSE(refused.ok());
    EXPECT_NE(refused.message().find("the match ended: this machine is left with 1 of 2 players"),
              std::string::npos)
        << refused.message();
    EXPECT_GT(m.record(p).hashes.size(), 200U) << "the 4 s before the outage were delivered";
    EXPECT_LT(m.record(p).hashes.size(), 300U);
  }
  // Every frame either side delivered, both delivered alike, and as an offline replay of their
  // inputs gives it: two records of one match that stopped, not two matches.
  const std::size_t common = std::min(m.record(0).hashes.size(), m.record(1).hashes.size());
  for (std::size_t f = 0; f < common; ++f)
    ASSERT_EQ(m.record(0).hashes[f], m.record(1).hashes[f]) << "frame " << f;
  for (std::uint32_t p = 0; p < 2; ++p)
    EXPECT_EQ(m.offline_hashes(p), m.record(p).hashes) << "peer " << p;
}

TEST(NetPartition, PlayOnKeepsBothSidesOfAPartitionPlayingAlone) {
  // The old behaviour, chosen: each side zeroes the other's inputs and goes on to the end.
  MatchOptions o;
  o.frames = 1200;
  o.link.latency_us = 20'000;
  o.max_ticks = 4000;
  o.setup = [](net::SimNetwork& n) { ASSERT_TRUE(n.add_outage(1, 4'000'000, 12'000'000).ok()); };
  o.configure = [](std::uint32_t, net::SessionConfig& c) {
    c.partition = net::PartitionPolicy::play_on;
  };
  Match m(o);
  EXPECT_TRUE(m.run());
  for (std::uint32_t p = 0; p < 2; ++p) {
    EXPECT_TRUE(m.record(p).has(EventType::disconnected));
    EXPECT_FALSE(m.record(p).has(EventType::match_ended));
    EXPECT_GE(m.record(p).hashes.size(), 1200U);
  }
}

TEST(NetPartition, PauseWaitsOutTheEightSecondOutageAndBothSidesGoOnAsOneMatch) {
  // The 8-second outage under PartitionPolicy::pause: neither side disconnects the other;
  // both stand still, then resume and finish the one match, every frame agreed and checked.
  MatchOptions o;
  o.frames = 1200;
  o.link.latency_us = 20'000;
  o.max_ticks = 4000;
  o.setup = [](net::SimNetwork& n) { ASSERT_TRUE(n.add_outage(1, 4'000'000, 12'000'000).ok()); };
  o.configure = [](std::uint32_t, net::SessionConfig& c) {
    c.partition = net::PartitionPolicy::pause;
  };
  Match m(o);
  ASSERT_TRUE(m.run()) << m.compare();
  m.idle(120);
  EXPECT_EQ(m.compare(), "");
  EXPECT_EQ(m.checks_complete(), "");
  for (std::uint32_t p = 0; p < 2; ++p) {
    SCOPED_TRACE("peer " + std::to_string(p));
    const net::Event* paused = nullptr;
    for (const net::Event& e : m.record(p).events)
      if (e.type == EventType::paused) paused = &e;
    ASSERT_NE(paused, nullptr);
    EXPECT_EQ(paused->reason, "no majority");
    EXPECT_EQ(paused->player, 1 - p);
    EXPECT_TRUE(m.record(p).has(EventType::resumed));
    EXPECT_FALSE(m.record(p).has(EventType::disconnected));
    EXPECT_FALSE(m.record(p).has(EventType::match_ended));
    EXPECT_FALSE(m.record(p).has(EventType::check_missing));
    // Nobody's input was zeroed: the match never lost a player.
    for (const net::InputStatus status : m.record(p).status)
      ASSERT_EQ(status, net::InputStatus::confirmed);
  }
  // The outage is in the ticks: the match took 8 s longer than its 1200 frames.
  EXPECT_GT(m.ticks(), 1200U + 8 * 60 - 60);
}

// ---- rejoining after a restart ----

/// Checks a match in which peer 1's process restarted: peer 0 delivered every frame; what peer 1
/// delivered before the restart and after it agrees with that, input for input and hash for hash;
/// both sides name the same snapshot frame; hash checks compare again after it.
void expect_rejoined_match(Match& m, std::uint64_t frames) {
  const test::PeerRecord& a = m.record(0);
  const test::PeerRecord& before = m.earlier_record();
  const test::PeerRecord& after = m.record(1);
  const std::size_t unit = 2 * m.session(0).config().input_size;
  ASSERT_GE(a.hashes.size(), frames);
  EXPECT_EQ(m.offline_hashes(0), a.hashes) << "peer 0's record is one match an offline run gives";
  ASSERT_FALSE(before.hashes.empty());
  for (std::size_t f = 0; f < before.hashes.size(); ++f)
    ASSERT_EQ(before.hashes[f], a.hashes[f]) << "frame " << f << ", before the restart";
  ASSERT_GE(after.first_frame + after.hashes.size(), frames);
  for (std::size_t i = 0; i < after.hashes.size(); ++i) {
    const std::size_t f = after.first_frame + i;
    ASSERT_EQ(after.hashes[i], a.hashes[f]) << "frame " << f << ", after the rejoin";
    ASSERT_TRUE(std::equal(after.inputs.begin() + static_cast<std::ptrdiff_t>(i * unit),
                           after.inputs.begin() + static_cast<std::ptrdiff_t>((i + 1) * unit),
                           a.inputs.begin() + static_cast<std::ptrdiff_t>(f * unit)))
        << "frame " << f;
  }
  // Both sides name the snapshot's frame: the rejoined session delivers from there.
  std::optional<std::uint64_t> stayer_saw;
  std::optional<std::uint64_t> rejoiner_saw;
  for (const net::Event& e : a.events)
    if (e.type == EventType::rejoined && e.player == 1) stayer_saw = e.frame;
  for (const net::Event& e : after.events)
    if (e.type == EventType::rejoined && e.player == 1) rejoiner_saw = e.frame;
  ASSERT_TRUE(stayer_saw && rejoiner_saw);
  EXPECT_EQ(*stayer_saw, *rejoiner_saw);
  EXPECT_EQ(after.first_frame, *rejoiner_saw);
  EXPECT_GE(before.hashes.size() + 60, after.first_frame) << "a snapshot near the restart";
  EXPECT_EQ(m.session(0).stats().snapshots_served, 1U);
  for (const test::PeerRecord* r : {&a, &before, &after}) {
    EXPECT_FALSE(r->has(EventType::desync));
    EXPECT_FALSE(r->has(EventType::disconnected));
    EXPECT_FALSE(r->has(EventType::check_missing));
  }
  // Desync detection goes on after the rejoin: the new session's checks were compared.
  const std::uint64_t interval = m.session(0).config().check_interval;
  const std::uint64_t expected = (frames - after.first_frame) / interval;
  EXPECT_GE(m.session(1).stats().checks_compared + 2, expected);
  EXPECT_EQ(m.session(1).stats().checks_skipped, 0U);
}

TEST(NetRejoin, ARestartedPlayerRejoinsFromASnapshotAndBothEndOnTheSameFrames) {
  for (const bool sealed : {false, true}) {
    SCOPED_TRACE(sealed ? "sealed" : "plain framing");
    if (sealed && !net::protection::available()) continue;
    MatchOptions o;
    if (!sealed) o.match_key.reset();
    o.frames = 900;
    o.link.latency_us = 20'000;
    o.max_ticks = 3000;
    o.restart_peer = 1;  // down for one second: within the other's disconnect timeout
    o.restart_tick = 300;
    o.rejoin_tick = 360;
    Match m(o);
    ASSERT_TRUE(m.run());
    m.idle(60);
    expect_rejoined_match(m, o.frames);
  }
}

TEST(NetRejoin, UnderPauseARestartedPlayerRejoinsAfterAnyAbsence) {
  // Down for 8 s, past the disconnect timeout: the other side paused instead of ending.
  MatchOptions o;
  o.frames = 900;
  o.link = net::internet_link();
  o.max_ticks = 4000;
  o.restart_peer = 1;
  o.restart_tick = 300;
  o.rejoin_tick = 300 + 8 * 60;
  o.configure = [](std::uint32_t, net::SessionConfig& c) {
    c.partition = net::PartitionPolicy::pause;
  };
  Match m(o);
  ASSERT_TRUE(m.run());
  m.idle(60);
  EXPECT_TRUE(m.record(0).has(EventType::paused));
  expect_rejoined_match(m, o.frames);
}

/// Peer 1's process down from tick 300 to 360, back with rejoin_replays_match.
MatchOptions replaying_restart(std::uint64_t max_ticks) {
  MatchOptions o;
  o.frames = 900;
  o.link.latency_us = 20'000;
  o.max_ticks = max_ticks;
  o.restart_peer = 1;
  o.restart_tick = 300;
  o.rejoin_tick = 360;
  o.configure = [](std::uint32_t p, net::SessionConfig& c) {
    if (p == 1) c.rejoin_replays_match = c.rejoin;
  };
  return o;
}

TEST(NetRejoin, ReplayingTheMatchTheRejoinedSessionDeliversEveryFrameFromTheStart) {
  // rejoin_replays_match: the new session re-simulates frames 0 .. S from the snapshot's log
  // before it plays, so its listener sees the whole match, exactly as the other side's did.
  MatchOptions o = replaying_restart(3000);
  Match m(o);
  ASSERT_TRUE(m.run());
  m.idle(60);
  const test::PeerRecord& a = m.record(0);
  const test::PeerRecord& after = m.record(1);
  EXPECT_EQ(after.first_frame, 0U);
  ASSERT_GE(after.hashes.size(), o.frames);
  ASSERT_GE(a.hashes.size(), o.frames);
  for (std::size_t f = 0; f < o.frames; ++f)
    ASSERT_EQ(after.hashes[f], a.hashes[f]) << "frame " << f;
  EXPECT_TRUE(std::equal(a.inputs.begin(),
                         a.inputs.begin() + static_cast<std::ptrdiff_t>(o.frames * 2 * 4),
                         after.inputs.begin()));
  EXPECT_TRUE(std::equal(a.status.begin(),
                         a.status.begin() + static_cast<std::ptrdiff_t>(o.frames * 2),
                         after.status.begin()));
  EXPECT_TRUE(after.has(EventType::rejoined));
  EXPECT_FALSE(after.has(EventType::desync));
}

TEST(NetRejoin, ReplayingTheMatchRefusesASnapshotItsOwnFramesDoNotGive) {
  // Peer 0's game goes wrong at frame 100 (its peer saw the desync), so its snapshot's state is
  // not what the frames in it give: the replaying session refuses it by name.
  MatchOptions o = replaying_restart(1500);
  o.fault_peer = 0;
  o.fault_frame = 100;
  Match m(o);
  EXPECT_FALSE(m.run());
  EXPECT_TRUE(m.earlier_record().has(EventType::desync));
  const net::Event* end = nullptr;
  for (const net::Event& e : m.record(1).events)
    if (e.type == EventType::match_ended) end = &e;
  ASSERT_NE(end, nullptr);
  EXPECT_EQ(end->reason, "rejoin failed");
  EXPECT_FALSE(m.record(1).has(EventType::rejoined));
  const std::vector<std::uint8_t> input(4, 0);
  auto refused = m.session(1).advance_frame(input);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.message().find("rejoin: the snapshot player 0 sent does not follow from its "
                                   "own frames"),
            std::string::npos)
      << refused.message();
}

TEST(NetRejoin, ARestartAfterTheSeatWasGivenUpNeverRejoins) {
  // end_match: 8 s down ends the match on the side that stayed; the new session is not let in.
  MatchOptions o;
  o.frames = 900;
  o.link.latency_us = 20'000;
  o.max_ticks = 1200;
  o.restart_peer = 1;
  o.restart_tick = 300;
  o.rejoin_tick = 300 + 8 * 60;
  Match m(o);
  EXPECT_FALSE(m.run());
  ASSERT_LT(m.ticks(), o.rejoin_tick) << "the match ended before the restarted process came up";
  m.idle(300);
  ASSERT_GT(m.ticks(), o.rejoin_tick + 100);
  EXPECT_TRUE(m.record(0).has(EventType::match_ended));
  EXPECT_FALSE(m.record(0).has(EventType::rejoined));
  EXPECT_FALSE(m.session(1).running()) << "still waiting for a snapshot nobody sends";
  EXPECT_TRUE(m.record(1).hashes.empty());
  EXPECT_EQ(m.session(0).stats().snapshots_served, 0U);
}

/// Checks a match in which peer 1 joined an open seat late (or came back to a seat given up):
/// peer 0 delivered every frame, and shows player 1 away (zero input, InputStatus::disconnected)
/// exactly over [away_from, R) for the R the join named, playing before and after it; peer 1's
/// new session delivered from the snapshot's frame on, alike. Returns R.
std::uint64_t expect_joined_match(Match& m, std::uint64_t frames, std::uint64_t away_from) {
  const test::PeerRecord& a = m.record(0);
  const test::PeerRecord& b = m.record(1);
  const std::size_t size = m.session(0).config().input_size;
  EXPECT_GE(a.hashes.size(), frames);
  EXPECT_EQ(m.offline_hashes(0), a.hashes);
  std::optional<std::uint64_t> joined;
  for (const net::Event& e : b.events)
    if (e.type == EventType::rejoined && e.player == 1) joined = e.frame;
  EXPECT_TRUE(joined.has_value());
  if (!joined) return 0;
  EXPECT_EQ(b.first_frame, *joined);
  EXPECT_GE(b.first_frame + b.hashes.size(), frames);
  for (std::size_t i = 0; i < b.hashes.size() && b.first_frame + i < a.hashes.size(); ++i) {
    const std::size_t f = b.first_frame + i;
    EXPECT_EQ(b.hashes[i], a.hashes[f]) << "frame " << f;
    EXPECT_EQ(b.status[2 * i + 1], a.status[2 * f + 1]) << "frame " << f;
  }
  // Player 1 away from `away_from` to R, then back for good.
  std::uint64_t back = away_from;
  while (back < a.hashes.size() && a.status[2 * back + 1] == net::InputStatus::disconnected)
    ++back;
  std::size_t wrong = 0;
  for (std::uint64_t f = 0; f < a.hashes.size(); ++f) {
    const bool away = f >= away_from && f < back;
    if (a.status[2 * f + 1] !=
        (away ? net::InputStatus::disconnected : net::InputStatus::confirmed))
      ++wrong;
    for (std::size_t k = 0; away && k < size; ++k)
      if (a.inputs[(2 * f + 1) * size + k] != 0) ++wrong;
  }
  EXPECT_EQ(wrong, 0U) << "player 1 away over [" << away_from << ", " << back << ") only";
  EXPECT_GE(back, *joined) << "the join takes effect at the present, after the snapshot's frame";
  EXPECT_LT(back, *joined + 60);
  EXPECT_FALSE(a.has(EventType::desync));
  EXPECT_FALSE(b.has(EventType::desync));
  EXPECT_FALSE(a.has(EventType::check_missing));
  EXPECT_GE(m.session(1).stats().checks_compared + 2,
            (frames - b.first_frame) / m.session(0).config().check_interval);
  return back;
}

TEST(NetRejoin, ALateJoinerTakesAnOpenSeatAtThePresentAndEveryFrameAgrees) {
  // Player 0 starts alone with player 1's seat open; 5 s in, player 1's session joins (a
  // spectator turned player, or a latecomer) and plays from the present on.
  MatchOptions o;
  o.frames = 900;
  o.link.latency_us = 20'000;
  o.max_ticks = 3000;
  o.restart_peer = 1;  // down from the start: its first session never says anything
  o.restart_tick = 0;
  o.rejoin_tick = 300;
  o.configure = [](std::uint32_t p, net::SessionConfig& c) {
    if (p == 0) c.open_seats = {1};
  };
  Match m(o);
  ASSERT_TRUE(m.run());
  m.idle(60);
  const std::uint64_t back = expect_joined_match(m, o.frames, 0);
  EXPECT_GT(back, 250U) << "player 0 played alone until the join";
  EXPECT_FALSE(m.record(0).has(EventType::disconnected)) << "an open seat is not a disconnect";
}

TEST(NetRejoin, AnOpenSeatNobodyTakesLeavesTheMatchToThePlayerAlone) {
  MatchOptions o;
  o.frames = 600;
  o.max_ticks = 900;
  o.restart_peer = 1;
  o.restart_tick = 0;
  o.rejoin_tick = ~std::uint64_t{0};
  o.configure = [](std::uint32_t p, net::SessionConfig& c) {
    if (p == 0) c.open_seats = {1};
  };
  Match m(o);
  EXPECT_FALSE(m.run()) << "peer 1 never finishes: it never comes";
  const test::PeerRecord& a = m.record(0);
  ASSERT_GE(a.hashes.size(), 600U);
  EXPECT_EQ(m.offline_hashes(0), a.hashes);
  for (std::size_t f = 0; f < a.hashes.size(); ++f)
    ASSERT_EQ(a.status[2 * f + 1], net::InputStatus::disconnected) << "frame " << f;
  EXPECT_TRUE(m.session(0).running());
  EXPECT_FALSE(a.has(EventType::disconnected));
  EXPECT_FALSE(a.has(EventType::match_ended));
}

TEST(NetRejoin, UnderPlayOnARestartedPlayerComesBackToTheSeatItLost) {
  // Down 8 s: player 0 takes it as gone after 5 and plays on alone (play_on); the restarted
  // process then joins the seat again, from the present.
  MatchOptions o;
  o.frames = 1200;
  o.link.latency_us = 20'000;
  o.max_ticks = 4000;
  o.restart_peer = 1;
  o.restart_tick = 300;
  o.rejoin_tick = 300 + 8 * 60;
  o.configure = [](std::uint32_t, net::SessionConfig& c) {
    c.partition = net::PartitionPolicy::play_on;
  };
  Match m(o);
  ASSERT_TRUE(m.run());
  m.idle(60);
  EXPECT_TRUE(m.record(0).has(EventType::disconnected));
  std::optional<std::uint64_t> gone;
  for (const net::Event& e : m.record(0).events)
    if (e.type == EventType::disconnected && e.player == 1) gone = e.frame;
  ASSERT_TRUE(gone.has_value());
  // Gone from the frame its inputs ended (the agreed frame can only be that or earlier).
  std::uint64_t away_from = 0;
  while (m.record(0).status[2 * away_from + 1] != net::InputStatus::disconnected)
    ++away_from;
  EXPECT_LE(away_from, *gone);
  const std::uint64_t back = expect_joined_match(m, o.frames, away_from);
  EXPECT_GT(back, away_from + 150) << "at least 3 s away";
  // Before the restart, peer 1's first session saw the same frames.
  const test::PeerRecord& before = m.earlier_record();
  for (std::size_t f = 0; f < before.hashes.size(); ++f)
    ASSERT_EQ(before.hashes[f], m.record(0).hashes[f]) << "frame " << f;
}

TEST(NetRejoin, AnAlteredSnapshotIsRefusedWithAReasonAndLoadsNothing) {
  MatchOptions o;
  o.match_key.reset();
  o.frames = 900;
  o.link.latency_us = 20'000;
  o.max_ticks = 1500;
  o.restart_peer = 1;
  o.restart_tick = 300;
  o.rejoin_tick = 360;
  // Every snapshot slice peer 0 sends is altered on the way (the plain framing: a peer on the
  // path).
  std::uint64_t altered = 0;
  o.wrap = test::tamper(0, [&altered](net::PeerId, net::protocol::Packet& p, std::uint64_t) {
    if (p.header.type == net::protocol::PacketType::state_chunk) {
      p.state_chunk.data[p.state_chunk.data.size() / 2] ^= 0x40U;
      ++altered;
    }
    return true;
  });
  Match m(o);
  EXPECT_FALSE(m.run());
  EXPECT_GT(altered, 0U);
  const net::Event* end = nullptr;
  for (const net::Event& e : m.record(1).events)
    if (e.type == EventType::match_ended) end = &e;
  ASSERT_NE(end, nullptr);
  EXPECT_EQ(end->reason, "rejoin failed");
  EXPECT_FALSE(m.record(1).has(EventType::rejoined));
  EXPECT_TRUE(m.record(1).hashes.empty()) << "nothing delivered from a refused snapshot";
  const std::vector<std::uint8_t> input(4, 0);
  auto refused = m.session(1).advance_frame(input);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.message().find("rejoin: the snapshot player 0 sent is invalid"),
            std::string::npos)
      << refused.message();
  EXPECT_EQ(m.session(1).failure(), refused.message()) << "the same reason, without advancing";
  EXPECT_EQ(m.session(0).failure(), "") << "the side that stayed goes on";
}

/// Adds a hello from another session of player 1 (the plain framing: anyone can send one) to
/// what peer 0 receives, every 10th receive.
class HelloForger final : public net::Transport {
 public:
  HelloForger(net::Transport& inner, std::uint64_t fingerprint)
      : inner_(inner), fingerprint_(fingerprint) {}
  void send(net::PeerId to, std::span<const std::uint8_t> bytes) override {
    inner_.send(to, bytes);
  }
  void receive(std::vector<net::Datagram>& out) override {
    inner_.receive(out);
    if (++calls_ % 10 != 0) return;
    net::protocol::Packet p;
    p.header.type = net::protocol::PacketType::hello;
    p.header.session = 0xF0'12'6E'D0'00ULL + calls_;  // a new session id each time
    p.hello = net::protocol::Hello{fingerprint_, 2, 1, 4, calls_ * 77};
    std::vector<std::uint8_t> bytes;
    ASSERT_TRUE(net::protocol::encode(p, 4, bytes));
    out.push_back(net::Datagram{1, std::move(bytes)});
    ++forged;
  }
  std::uint64_t forged = 0;

 private:
  net::Transport& inner_;
  std::uint64_t fingerprint_;
  std::uint64_t calls_ = 0;
};

TEST(NetRejoin, HellosFromOtherSessionsOfAPlayerNeverTakeItsSeat) {
  // Off the path, a forger can name any session id, but the challenge that would move the seat
  // goes to the player's address, where the genuine session answers with its own id.
  MatchOptions o;
  o.match_key.reset();
  o.frames = 600;
  o.link.latency_us = 20'000;
  HelloForger* forger = nullptr;
  o.wrap = [&forger](std::uint32_t p, net::Transport& inner) -> std::unique_ptr<net::Transport> {
    if (p != 0) return nullptr;
    auto t = std::make_unique<HelloForger>(inner, 0xD5'1A'77ULL + 2);
    forger = t.get();
    return t;
  };
  Match m(o);
  ASSERT_TRUE(m.run()) << m.compare();
  m.idle(60);
  EXPECT_EQ(m.compare(), "");
  EXPECT_EQ(m.checks_complete(), "");
  ASSERT_NE(forger, nullptr);
  EXPECT_GT(forger->forged, 50U);
  EXPECT_FALSE(m.record(0).has(EventType::rejoined));
  EXPECT_EQ(m.session(0).stats().snapshots_served, 0U);
  EXPECT_GE(m.session(0).stats().dropped_wrong_session, forger->forged);
}

}  // namespace
}  // namespace detsim
