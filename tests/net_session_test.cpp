// Sessions (net/session.hpp) over the simulated network with a cheap game: the rollback and
// lockstep rules, desync detection, handshakes, timeouts and hostile datagrams. The heavy runs
// (arena, 10,000 frames, bad networks) are in net_conditions_test.cpp.
#include <gtest/gtest.h>

#include <detsim/net/protocol.hpp>
#include <detsim/net/session.hpp>
#include <detsim/net/sim_network.hpp>

#include "support/net_match.hpp"

namespace detsim {
namespace {

using net::EventType;

template <class T>
T take(Expected<T> e) {
  EXPECT_TRUE(e.ok()) << e.message();
  return std::move(e.value());
}
using test::Match;
using test::MatchOptions;

// ---- configuration ----

TEST(NetSession, RejectsInvalidConfigsNamingTheField) {
  test::CounterGame game;
  auto network = take(net::SimNetwork::create(2, 1));
  const auto error_of = [&](auto&& edit) {
    net::SessionConfig c;
    c.remotes = {{1, 1}};
    edit(c);
    auto s = net::Session::create(c, game, network.endpoint(0));
    return s.ok() ? std::string() : s.message();
  };
  EXPECT_EQ(error_of([](net::SessionConfig&) {}), "");
  EXPECT_NE(error_of([](net::SessionConfig& c) { c.players = 9; }).find("players"),
            std::string::npos);
  EXPECT_NE(error_of([](net::SessionConfig& c) { c.players = 0; }).find("players"),
            std::string::npos);
  EXPECT_NE(error_of([](net::SessionConfig& c) { c.local_player = 2; }).find("local_player"),
            std::string::npos);
  EXPECT_NE(error_of([](net::SessionConfig& c) { c.input_size = 0; }).find("input_size"),
            std::string::npos);
  EXPECT_NE(error_of([](net::SessionConfig& c) { c.input_size = 65; }).find("input_size"),
            std::string::npos);
  EXPECT_NE(error_of([](net::SessionConfig& c) { c.input_delay = 17; }).find("input_delay"),
            std::string::npos);
  EXPECT_NE(error_of([](net::SessionConfig& c) { c.max_prediction = 0; }).find("max_prediction"),
            std::string::npos);
  EXPECT_EQ(error_of([](net::SessionConfig& c) {
              c.max_prediction = 0;
              c.mode = net::SessionMode::lockstep;
            }),
            "");
  EXPECT_NE(error_of([](net::SessionConfig& c) { c.remotes = {}; }).find("remotes"),
            std::string::npos);
  EXPECT_NE(error_of([](net::SessionConfig& c) {
              c.remotes = {{0, 1}};
            }).find("player 0"),
            std::string::npos);
  EXPECT_NE(error_of([](net::SessionConfig& c) {
              c.players = 3;
              c.remotes = {{1, 5}, {2, 5}};
            }).find("share"),
            std::string::npos);
  EXPECT_NE(error_of([](net::SessionConfig& c) {
              c.disconnect_timeout_us = c.disconnect_warning_us;
            }).find("disconnect_timeout_us"),
            std::string::npos);
  EXPECT_NE(error_of([](net::SessionConfig& c) {
              c.partition = static_cast<net::PartitionPolicy>(7);
            }).find("partition must be end_match, play_on or pause, got 7"),
            std::string::npos);
  EXPECT_NE(error_of([](net::SessionConfig& c) {
              c.rejoin = true;
              c.players = 3;
              c.remotes = {{1, 1}, {2, 2}};
            }).find("rejoin is for two-player matches only (this one has 3 players)"),
            std::string::npos);
  EXPECT_NE(error_of([](net::SessionConfig& c) {
              c.rejoin = true;
              c.spectators = {5};
            }).find("a rejoining session serves no spectators"),
            std::string::npos);
  EXPECT_NE(error_of([](net::SessionConfig& c) {
              c.players = 3;
              c.remotes = {{1, 1}, {2, 2}};
              c.open_seats = {2};
            }).find("open_seats are for two-player matches only"),
            std::string::npos);
  EXPECT_NE(error_of([](net::SessionConfig& c) {
              c.open_seats = {0};
            }).find("open_seats: player 0 is out of range, this machine's own, or listed twice"),
            std::string::npos);
  EXPECT_NE(error_of([](net::SessionConfig& c) {
              c.open_seats = {1};
              c.rejoin = true;
            }).find("a joining session (rejoin) takes a seat, it opens none"),
            std::string::npos);
}

TEST(NetSession, WrongLocalInputSizeIsAnErrorAndChangesNothing) {
  test::CounterGame game;
  auto network = take(net::SimNetwork::create(1, 1));
  net::SessionConfig c;
  c.players = 1;
  auto session = take(net::Session::create(c, game, network.endpoint(0)));
  const std::vector<std::uint8_t> wrong(3, 0);
  auto r = session.advance_frame(wrong);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.message().find("4 bytes, got 3"), std::string::npos) << r.message();
  EXPECT_EQ(session.current_frame(), 0U);
  EXPECT_EQ(game.simulated, 0U);
}

TEST(NetSession, SinglePlayerRunsWithoutNetworkAndConfirmsEveryFrame) {
  MatchOptions o;
  o.players = 1;
  o.frames = 200;
  Match m(o);
  ASSERT_TRUE(m.run());
  EXPECT_EQ(m.compare(), "");
  EXPECT_EQ(m.record(0).hashes.size(), 200U);
  EXPECT_EQ(m.session(0).stats().rollbacks, 0U);
}

// ---- rollback ----

TEST(NetSession, TwoPlayersOnAPerfectNetworkAgreeWithoutRollingBack) {
  MatchOptions o;
  o.frames = 600;
  Match m(o);
  ASSERT_TRUE(m.run()) << m.compare();
  EXPECT_EQ(m.compare(), "");
  // With no latency every remote input arrives before its frame is simulated, except at the very
  // start: the peer that completes the handshake first predicts the other's first frames.
  for (std::uint32_t p = 0; p < 2; ++p) {
    EXPECT_LE(m.session(p).stats().rollbacks, 1U);
    EXPECT_LE(m.session(p).stats().resimulated_frames, 2U);
  }
  EXPECT_TRUE(m.record(0).has(EventType::running));
  EXPECT_TRUE(m.record(0).has(EventType::synchronized));
}

TEST(NetSession, DeliveredFrameCountsWhatTheListenerGotAndReachesTheEndByPollingAlone) {
  // Delivered frames trail the confirmed ones while the peers' holds travel back; after the last
  // advance, polling alone delivers the rest of the match.
  MatchOptions o;
  o.frames = 400;
  o.link = net::internet_link();
  std::vector<std::size_t> delivered(2, 0);
  std::uint64_t trailing = 0;
  bool consistent = true;
  Match* match = nullptr;
  o.on_tick = [&](std::uint32_t p, std::uint64_t, net::Session& s) {
    if (match == nullptr) return;
    consistent = consistent && match->record(p).hashes.size() == s.delivered_frame() &&
                 s.delivered_frame() <= s.confirmed_frame();
    if (s.delivered_frame() < s.confirmed_frame()) ++trailing;
  };
  Match m(o);
  match = &m;
  ASSERT_TRUE(m.run()) << m.compare();
  EXPECT_TRUE(consistent) << "the listener got exactly the frames before delivered_frame()";
  EXPECT_GT(trailing, 0U) << "on a 100 ms link the holds take a while";
  for (std::uint32_t p = 0; p < 2; ++p) {
    EXPECT_GE(m.session(p).delivered_frame(), o.frames);
    EXPECT_EQ(m.record(p).hashes.size(), m.session(p).delivered_frame());
  }
  EXPECT_EQ(m.compare(), "");
}

TEST(NetSession, LatencyCausesRollbacksThatEndIdentical) {
  MatchOptions o;
  o.frames = 1200;
  o.input_delay = 0;
  o.link.latency_us = 60'000;
  Match m(o);
  ASSERT_TRUE(m.run()) << m.compare();
  EXPECT_EQ(m.compare(), "");
  EXPECT_EQ(m.checks_complete(), "");
  const net::SessionStats& s = m.session(0).stats();
  EXPECT_GT(s.rollbacks, 10U);
  EXPECT_GT(s.resimulated_frames, s.rollbacks);
  const auto peer = m.session(0).peer_stats(1);
  ASSERT_TRUE(peer.has_value());
  EXPECT_GT(peer->ping_us, 100'000U);  // 120 ms round trip, measured
  EXPECT_LT(peer->ping_us, 160'000U);
  EXPECT_FALSE(m.session(0).peer_stats(0).has_value());  // the local player is no peer
  // Once the last acknowledgements arrived, peer 1 holds every input peer 0 sent.
  m.idle(30);
  EXPECT_GE(m.session(0).peer_stats(1)->acknowledged_frame, o.frames);
}

TEST(NetSession, FourAndEightPlayersOnABadNetworkAgree) {
  for (std::uint32_t players : {4U, 8U}) {
    MatchOptions o;
    o.players = players;
    o.frames = 1500;
    o.link = net::internet_link();
    o.seed = players;
    Match m(o);
    ASSERT_TRUE(m.run()) << players << " players: " << m.compare();
    EXPECT_EQ(m.compare(), "") << players << " players";
    EXPECT_EQ(m.checks_complete(), "") << players << " players";
    EXPECT_GT(m.session(0).stats().rollbacks, 0U);
  }
}

TEST(NetSession, PredictionLimitWaitsAndNeverLosesACorrection) {
  // Peer 1's datagrams take 400 ms (24 frames) one way: far past the 8-frame window, so both
  // peers spend most of the match at the limit, with corrections arriving while they wait.
  MatchOptions o;
  o.frames = 900;
  o.input_delay = 0;
  o.max_ticks = 20'000;
  o.setup = [](net::SimNetwork& n) {
    net::LinkConditions slow;
    slow.latency_us = 400'000;
    slow.jitter_us = 30'000;
    ASSERT_TRUE(n.set_link(1, 0, slow).ok());
  };
  Match m(o);
  ASSERT_TRUE(m.run()) << m.compare();
  EXPECT_EQ(m.compare(), "");
  EXPECT_GT(m.session(0).stats().prediction_limit_waits, 100U);
  EXPECT_GT(m.session(1).stats().prediction_limit_waits, 100U);
  EXPECT_GT(m.session(0).stats().rollbacks, 0U);
}

TEST(NetSession, InputDelayChangesMidMatchStayConsistent) {
  // Peer 0 grows its delay 2 -> 6 at tick 200 and shrinks it 6 -> 1 at tick 500; peer 1 shrinks
  // 2 -> 0 at tick 300. Growing repeats inputs; shrinking drops exactly the overlap.
  MatchOptions o;
  o.frames = 900;
  o.link.latency_us = 30'000;
  o.on_tick = [](std::uint32_t p, std::uint64_t tick, net::Session& s) {
    if (p == 0 && tick == 200) {
      ASSERT_TRUE(s.set_input_delay(6).ok());
    } else if (p == 0 && tick == 500) {
      ASSERT_TRUE(s.set_input_delay(1).ok());
    } else if (p == 1 && tick == 300) {
      ASSERT_TRUE(s.set_input_delay(0).ok());
    }
  };
  Match m(o);
  EXPECT_FALSE(m.session(0).set_input_delay(17).ok());
  ASSERT_TRUE(m.run()) << m.compare();
  EXPECT_EQ(m.compare(), "");
  EXPECT_EQ(m.session(0).stats().dropped_inputs, 5U);
  EXPECT_EQ(m.session(1).stats().dropped_inputs, 2U);
}

TEST(NetSession, TimeSyncKeepsAFastPeerFromRunningIntoThePredictionLimit) {
  // Peer 1 is a slower machine: it misses every eighth tick. Without time sync peer 0 runs ahead
  // until the prediction window stops it, again and again; following recommended_wait_frames()
  // it slows down early and rarely reaches the limit.
  const auto run = [](bool time_sync) {
    MatchOptions o;
    o.frames = 1800;
    o.link.latency_us = 30'000;
    o.time_sync = time_sync;
    o.active = [](std::uint32_t p, std::uint64_t tick) { return p != 1 || tick % 8 != 0; };
    Match m(o);
    EXPECT_TRUE(m.run()) << m.compare();
    EXPECT_EQ(m.compare(), "");
    return m.session(0).stats().prediction_limit_waits;
  };
  const std::uint64_t without = run(false);
  const std::uint64_t with = run(true);
  EXPECT_GT(without, 100U);
  EXPECT_LT(with * 4, without) << "with time sync " << with << ", without " << without;
}

// ---- lockstep ----

TEST(NetSession, LockstepNeverPredictsAndEndsIdentical) {
  MatchOptions o;
  o.players = 4;
  o.mode = net::SessionMode::lockstep;
  o.frames = 600;
  o.link = net::internet_link();
  o.max_ticks = 30'000;
  Match m(o);
  ASSERT_TRUE(m.run()) << m.compare();
  EXPECT_EQ(m.compare(), "");
  for (std::uint32_t p = 0; p < 4; ++p) {
    EXPECT_EQ(m.session(p).stats().rollbacks, 0U);
    for (net::InputStatus s : m.record(p).status)
      EXPECT_EQ(s, net::InputStatus::confirmed);
  }
}

// ---- desync detection ----

TEST(NetSession, InjectedNonDeterminismIsDetectedWithinOneCheckInterval) {
  MatchOptions o;
  o.players = 3;
  o.frames = 600;
  o.link = net::internet_link();
  o.fault_frame = 200;  // peer 2's state differs from frame 201 on
  o.fault_peer = 2;
  Match m(o);
  m.run();
  bool detected = false;
  for (std::uint32_t p = 0; p < 3; ++p) {
    for (const net::Event& e : m.record(p).events) {
      if (e.type != EventType::desync) continue;
      detected = true;
      // The first check at or after frame 201 (checks every 30 frames: 210) names it.
      EXPECT_EQ(e.frame, 210U) << "peer " << p;
      EXPECT_NE(e.local_hash, e.remote_hash);
      EXPECT_EQ(p == 2 || e.player == 2, true) << "healthy peers blame peer 2";
    }
  }
  EXPECT_TRUE(detected);
  const net::DesyncEvidence* evidence = m.session(0).desync_evidence();
  ASSERT_NE(evidence, nullptr);
  EXPECT_EQ(evidence->player, 2U);
  EXPECT_EQ(evidence->agreed_frame, 180U);
  EXPECT_EQ(evidence->divergent_frame, 210U);
  EXPECT_EQ(evidence->agreed_state.size(), 16U);
  EXPECT_EQ(evidence->divergent_state.size(), 16U);
  // Peers 0 and 1 agree with each other: no desync between them.
  for (const net::Event& e : m.record(0).events)
    if (e.type == EventType::desync) {
      EXPECT_EQ(e.player, 2U);
    }
}

TEST(NetSession, NoFalseDesyncFromPredictedFrames) {
  // Heavy misprediction (no input delay, long latency), checks every frame: a session that
  // compared predicted frames would report a desync here.
  MatchOptions o;
  o.frames = 900;
  o.input_delay = 0;
  o.check_interval = 1;
  o.link = net::internet_link();
  o.link.latency_us = 80'000;
  Match m(o);
  ASSERT_TRUE(m.run()) << m.compare();
  EXPECT_EQ(m.compare(), "");
  EXPECT_GT(m.session(0).stats().rollbacks, 50U);
}

// ---- handshake, timeouts ----

TEST(NetSession, MismatchedFingerprintIsRejectedAndNeverRuns) {
  MatchOptions o;
  o.frames = 50;
  o.max_ticks = 300;
  o.configure = [](std::uint32_t p, net::SessionConfig& c) { c.fingerprint += p; };
  Match m(o);
  EXPECT_FALSE(m.run());
  for (std::uint32_t p = 0; p < 2; ++p) {
    EXPECT_FALSE(m.session(p).running());
    EXPECT_EQ(m.session(p).current_frame(), 0U);
    bool rejected = false;
    for (const net::Event& e : m.record(p).events)
      if (e.type == EventType::hello_rejected) rejected = e.reason == "fingerprint";
    EXPECT_TRUE(rejected) << "peer " << p;
  }
}

TEST(NetSession, AnOutageWarnsThenRecoversWithoutDesync) {
  MatchOptions o;
  o.players = 3;
  o.frames = 900;
  o.link = net::internet_link();
  o.setup = [](net::SimNetwork& n) { ASSERT_TRUE(n.add_outage(1, 5'000'000, 7'000'000).ok()); };
  Match m(o);
  ASSERT_TRUE(m.run()) << m.compare();
  EXPECT_EQ(m.compare(), "");
  for (std::uint32_t p : {0U, 2U}) {
    EXPECT_TRUE(m.record(p).has(EventType::interrupted)) << p;
    EXPECT_TRUE(m.record(p).has(EventType::resumed)) << p;
    EXPECT_FALSE(m.record(p).has(EventType::disconnected)) << p;
  }
}

TEST(NetSession, ASilentPeerIsDisconnectedAndTheOthersGoOnTogether) {
  MatchOptions o;
  o.players = 3;
  o.frames = 900;
  o.link.latency_us = 20'000;
  o.max_ticks = 5000;
  // Peer 2 goes away for good after 4 s: the others keep playing with its inputs zeroed.
  o.setup = [](net::SimNetwork& n) { ASSERT_TRUE(n.add_outage(2, 4'000'000, ~0ULL >> 1).ok()); };
  o.active = [](std::uint32_t p, std::uint64_t tick) { return p != 2 || tick < 240; };
  Match m(o);
  m.run();
  const std::size_t common = std::min(m.record(0).hashes.size(), m.record(1).hashes.size());
  ASSERT_GE(common, 900U);
  EXPECT_EQ(m.record(0).hashes, m.record(1).hashes);
  EXPECT_TRUE(m.record(0).has(EventType::disconnected));
  EXPECT_TRUE(m.record(1).has(EventType::disconnected));
  EXPECT_EQ(m.record(0).status.back(), net::InputStatus::disconnected);  // player 2, last frame
  // Two of three are a majority and go on; the one cut off alone ends its match.
  EXPECT_FALSE(m.record(0).has(EventType::match_ended));
  EXPECT_FALSE(m.record(1).has(EventType::match_ended));
  EXPECT_TRUE(m.record(2).has(EventType::match_ended));
}

TEST(NetSession, ATwoPlayerPartitionEndsTheMatchOnBothSidesWithTheSameFrames) {
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

TEST(NetSession, PlayOnKeepsBothSidesOfAPartitionPlayingAlone) {
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

TEST(NetSession, PauseWaitsOutTheEightSecondOutageAndBothSidesGoOnAsOneMatch) {
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

TEST(NetSession, ARestartedPlayerRejoinsFromASnapshotAndBothEndOnTheSameFrames) {
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

TEST(NetSession, UnderPauseARestartedPlayerRejoinsAfterAnyAbsence) {
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

TEST(NetSession, ARestartAfterTheSeatWasGivenUpNeverRejoins) {
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

TEST(NetSession, ALateJoinerTakesAnOpenSeatAtThePresentAndEveryFrameAgrees) {
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

TEST(NetSession, AnOpenSeatNobodyTakesLeavesTheMatchToThePlayerAlone) {
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

TEST(NetSession, UnderPlayOnARestartedPlayerComesBackToTheSeatItLost) {
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

/// Alters every snapshot slice peer 1 receives (the plain framing: a peer on the path).
class SnapshotCorrupter final : public net::Transport {
 public:
  explicit SnapshotCorrupter(net::Transport& inner) : inner_(inner) {}
  void send(net::PeerId to, std::span<const std::uint8_t> bytes) override {
    inner_.send(to, bytes);
  }
  void receive(std::vector<net::Datagram>& out) override {
    const std::size_t from = out.size();
    inner_.receive(out);
    for (std::size_t i = from; i < out.size(); ++i) {
      net::protocol::Packet p;
      if (net::protocol::decode(out[i].bytes, 4, p) != net::protocol::DecodeError::none ||
          p.header.type != net::protocol::PacketType::state_chunk)
        continue;
      p.state_chunk.data[p.state_chunk.data.size() / 2] ^= 0x40U;
      std::vector<std::uint8_t> bytes;
      ASSERT_TRUE(net::protocol::encode(p, 4, bytes));
      out[i].bytes = std::move(bytes);
      ++altered;
    }
  }
  std::size_t altered = 0;

 private:
  net::Transport& inner_;
};

TEST(NetSession, AnAlteredSnapshotIsRefusedWithAReasonAndLoadsNothing) {
  MatchOptions o;
  o.match_key.reset();
  o.frames = 900;
  o.link.latency_us = 20'000;
  o.max_ticks = 1500;
  o.restart_peer = 1;
  o.restart_tick = 300;
  o.rejoin_tick = 360;
  SnapshotCorrupter* corrupter = nullptr;
  o.wrap = [&corrupter](std::uint32_t p, net::Transport& inner) -> std::unique_ptr<net::Transport> {
    if (p != 1) return nullptr;
    auto t = std::make_unique<SnapshotCorrupter>(inner);
    corrupter = t.get();
    return t;
  };
  Match m(o);
  EXPECT_FALSE(m.run());
  ASSERT_NE(corrupter, nullptr);
  EXPECT_GT(corrupter->altered, 0U);
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

TEST(NetSession, HellosFromOtherSessionsOfAPlayerNeverTakeItsSeat) {
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

/// The frame from which `record` shows player `player` as disconnected, or the record's length.
std::size_t gone_from(const test::PeerRecord& record, std::uint32_t players, std::uint32_t player) {
  const std::size_t frames = record.status.size() / players;
  for (std::size_t f = 0; f < frames; ++f)
    if (record.status[f * players + player] == net::InputStatus::disconnected) return f;
  return frames;
}

/// Peer 1's transport, which stops delivering player 3's datagrams once `cut` is set.
class CutOff final : public net::Transport {
 public:
  CutOff(net::Transport& inner, const bool& cut) : inner_(inner), cut_(cut) {}
  void send(net::PeerId to, std::span<const std::uint8_t> bytes) override {
    inner_.send(to, bytes);
  }
  void receive(std::vector<net::Datagram>& out) override {
    const std::size_t before = out.size();
    inner_.receive(out);
    if (!cut_) return;
    out.erase(std::remove_if(out.begin() + static_cast<std::ptrdiff_t>(before), out.end(),
                             [](const net::Datagram& d) { return d.from == 3; }),
              out.end());
  }

 private:
  net::Transport& inner_;
  const bool& cut_;
};

TEST(NetSession, PeersAgreeOnOneDisconnectFrameWhenTheyHeldDifferentInputs) {
  // Player 3 leaves for good after 4 s (tick 240), but peer 1 stops hearing it 15 frames earlier,
  // so peers 0 and 2 hold ~15 more frames of its inputs than peer 1. Each peer taking it as gone
  // from its own last held input would give player 3 real inputs on two peers and zero inputs on
  // the third for those frames: a desync. The peers must agree on one frame (the lowest any of
  // them holds), roll back to it where needed, and confirm nothing beyond what every peer holds
  // meanwhile.
  bool cut = false;
  MatchOptions o;
  o.players = 4;
  o.frames = 900;
  o.link.latency_us = 10'000;
  o.max_ticks = 5000;
  o.setup = [](net::SimNetwork& n) { ASSERT_TRUE(n.add_outage(3, 4'000'000, ~0ULL >> 1).ok()); };
  o.active = [](std::uint32_t p, std::uint64_t tick) { return p != 3 || tick < 240; };
  o.on_tick = [&cut](std::uint32_t, std::uint64_t tick, net::Session&) {
    if (tick == 225) cut = true;
  };
  o.wrap = [&cut](std::uint32_t p, net::Transport& inner) -> std::unique_ptr<net::Transport> {
    if (p != 1) return nullptr;
    return std::make_unique<CutOff>(inner, cut);
  };
  Match m(o);
  m.run();
  std::size_t common = m.record(0).hashes.size();
  for (std::uint32_t p : {1U, 2U})
    common = std::min(common, m.record(p).hashes.size());
  ASSERT_GE(common, 900U);
  const std::size_t gone = gone_from(m.record(0), 4, 3);
  EXPECT_GT(gone, 150U);
  EXPECT_LT(gone, 260U);
  for (std::uint32_t p : {0U, 1U, 2U}) {
    SCOPED_TRACE("peer " + std::to_string(p));
    EXPECT_TRUE(m.record(p).has(EventType::disconnected));
    EXPECT_FALSE(m.record(p).has(EventType::desync));
    EXPECT_EQ(gone_from(m.record(p), 4, 3), gone) << "one disconnect frame for every peer";
    const auto frames = static_cast<std::ptrdiff_t>(common);
    EXPECT_TRUE(std::equal(m.record(0).hashes.begin(), m.record(0).hashes.begin() + frames,
                           m.record(p).hashes.begin()));
    // CounterGame inputs are 4 bytes: 16 bytes a frame.
    EXPECT_TRUE(std::equal(m.record(0).inputs.begin(), m.record(0).inputs.begin() + frames * 16,
                           m.record(p).inputs.begin()));
  }
  // The agreed frame is peer 1's: the lowest holdings, 15 frames behind the others'.
  const std::uint64_t from_peer_1 = [&] {
    for (const net::Event& e : m.record(1).events)
      if (e.type == EventType::disconnected && e.player == 3) return e.frame;
    return std::uint64_t{0};
  }();
  EXPECT_EQ(gone, from_peer_1);
  EXPECT_EQ(m.compare().find("raised a desync"), std::string::npos);
}

}  // namespace
}  // namespace detsim
