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
              c.players = 1;
              c.remotes = {};
            }).find("rejoin needs a match of two or more players (this one has 1)"),
            std::string::npos);
  EXPECT_NE(error_of([](net::SessionConfig& c) {
              c.rejoin = true;
              c.spectators = {5};
            }).find("a rejoining session serves no spectators"),
            std::string::npos);
  EXPECT_NE(error_of([](net::SessionConfig& c) {
              c.players = 3;
              c.remotes = {{1, 1}, {2, 2}};
              c.open_seats = {3};
            }).find("open_seats: player 3 is out of range, this machine's own, or listed twice"),
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
