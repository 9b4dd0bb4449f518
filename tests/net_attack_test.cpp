// Attacks by a malicious peer, or a relay on its path, on a live match (issue 31): each datagram it
// sends is decoded, edited and resealed (the checksum is unkeyed, so a relay can do the same).
// Every attack ends either with every honest peer on the honest hashes, or with a clear, detected
// error (an event naming the player and why) — never a hijacked seat, a kicked player, a silent
// split or a hang.
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <memory>
#include <random>

#include <detsim/net/protocol.hpp>
#include <detsim/net/session.hpp>

#include "support/net_match.hpp"

namespace detsim {
namespace {

using net::EventType;
using net::protocol::Packet;
using net::protocol::PacketType;
using test::Match;
using test::MatchOptions;
using test::Tamper;
using test::tamper;

constexpr std::uint32_t input_size = 4;  // CounterGame's

const net::Event* find(const test::PeerRecord& r, EventType type) {
  for (const net::Event& e : r.events)
    if (e.type == type) return &e;
  return nullptr;
}

// ---- the challenge-bound handshake ----

/// A third party with a spoofed source address: every receive of the victim's transport also
/// delivers, "from" the other player's peer, `hellos` hellos with the match's public settings and
/// random session ids and challenges, replies to random challenges, and input datagrams of its
/// own session carrying junk inputs for the frames around the victim's.
class Spoofer final : public net::Transport {
 public:
  Spoofer(net::Transport& inner, net::PeerId as, std::uint8_t player, std::uint64_t fingerprint,
          std::size_t hellos)
      : inner_(inner), as_(as), player_(player), fingerprint_(fingerprint), hellos_(hellos) {}
  void send(net::PeerId to, std::span<const std::uint8_t> bytes) override {
    inner_.send(to, bytes);
  }
  void receive(std::vector<net::Datagram>& out) override {
    ++calls_;
    for (std::size_t i = 0; i < hellos_; ++i) {
      Packet hello;
      hello.header = {PacketType::hello, rng_(), static_cast<std::uint16_t>(rng_())};
      hello.hello = {fingerprint_, 2, player_, input_size, rng_()};
      push(out, hello);
    }
    Packet reply;
    reply.header = {PacketType::hello_reply, attacker_, static_cast<std::uint16_t>(calls_)};
    reply.hello_reply.challenge = rng_();
    push(out, reply);
    Packet input;
    input.header = {PacketType::input, attacker_, static_cast<std::uint16_t>(calls_)};
    input.input.ack_frame = static_cast<std::uint32_t>(calls_);
    input.input.current_frame = static_cast<std::uint32_t>(calls_);
    input.input.start_frame = static_cast<std::uint32_t>(calls_ > 4 ? calls_ - 4 : 0);
    input.input.held_frame = static_cast<std::uint32_t>(calls_);
    input.input.count = 8;
    input.input.deltas.assign(8 * input_size, 0x5A);
    push(out, input);
    inner_.receive(out);  // the genuine datagrams after the forged ones: the worst order
  }

 private:
  void push(std::vector<net::Datagram>& out, const Packet& p) {
    std::vector<std::uint8_t> bytes;
    if (net::protocol::encode(p, input_size, bytes)) out.push_back({as_, bytes});
  }
  net::Transport& inner_;
  net::PeerId as_;
  std::uint8_t player_;
  std::uint64_t fingerprint_;
  std::size_t hellos_;
  std::mt19937_64 rng_{31};
  std::uint64_t attacker_ = 0xA77AC6E5'5E55100DULL;  // the session id it plays under
  std::uint64_t calls_ = 0;
};

constexpr std::uint64_t two_player_fingerprint = 0xD5'1A'77ULL + 2;  // net_match's

TEST(NetAttack, ASpoofedHelloCannotTakeASeat) {
  // From before the first genuine hello to the end, a third party spoofing player 1's address
  // offers its own session to peer 0 (hellos, guessed replies) and plays under it. Peer 0 learns
  // player 1's session only from the reply to its own challenge, so it plays the whole match
  // with the genuine peer: the honest hashes, every forged datagram dropped.
  MatchOptions o;
  o.match_key.reset();  // the plain framing: what a peer with the key could send sealed
  o.frames = 900;
  o.link = net::internet_link();
  o.wrap = [](std::uint32_t p, net::Transport& inner) -> std::unique_ptr<net::Transport> {
    if (p != 0) return nullptr;
    return std::make_unique<Spoofer>(inner, 1, 1, two_player_fingerprint, 4);
  };
  Match m(o);
  ASSERT_TRUE(m.run()) << m.compare();
  EXPECT_EQ(m.compare(), "");
  EXPECT_EQ(m.checks_complete(), "");
  EXPECT_GT(m.session(0).stats().dropped_wrong_session, 2 * m.ticks());
  EXPECT_FALSE(m.record(0).has(EventType::hello_rejected));
}

TEST(NetAttack, AHelloFloodCannotStopTheMatchFromStarting) {
  // 200 forged hellos before every genuine datagram, both ways: each is answered (to the genuine
  // peer's address) and changes nothing, so the genuine hellos' answers still get through.
  std::vector<std::uint64_t> running_at(2, 0);
  MatchOptions o;
  o.match_key.reset();  // the plain framing: what a peer with the key could send sealed
  o.frames = 600;
  o.link.latency_us = 30'000;
  o.wrap = [](std::uint32_t p, net::Transport& inner) -> std::unique_ptr<net::Transport> {
    return std::make_unique<Spoofer>(inner, 1 - p, static_cast<std::uint8_t>(1 - p),
                                     two_player_fingerprint, 200);
  };
  o.on_tick = [&running_at](std::uint32_t p, std::uint64_t tick, net::Session& s) {
    if (running_at[p] == 0 && s.running()) running_at[p] = tick;
  };
  Match m(o);
  ASSERT_TRUE(m.run()) << m.compare();
  EXPECT_EQ(m.compare(), "");
  for (std::uint32_t p = 0; p < 2; ++p) {
    EXPECT_GT(running_at[p], 0U);
    EXPECT_LE(running_at[p], 10U) << "peer " << p;  // a round trip or two, as without the flood
  }
}

// ---- corroborated disconnects ----

TEST(NetAttack, AGoneReportAboutTheReceiverOrAPlayerItStillHearsIsIgnored) {
  // Peer 2 tells everyone, in every input datagram, that players 0 and 1 are gone from frame 5,
  // and that it is gone itself. Without corroboration one such packet ends the match for all.
  MatchOptions o;
  o.match_key.reset();  // the plain framing: what a peer with the key could send sealed
  o.players = 3;
  o.frames = 900;
  o.link = net::internet_link();
  o.wrap = tamper(2, [](net::PeerId, Packet& p, std::uint64_t) {
    if (p.header.type == PacketType::input) p.input.gone = {{0, 5}, {1, 5}, {2, 5}};
    return true;
  });
  Match m(o);
  ASSERT_TRUE(m.run()) << m.compare();
  EXPECT_EQ(m.compare(), "");
  EXPECT_EQ(m.checks_complete(), "");
  for (std::uint32_t p = 0; p < 2; ++p) {
    SCOPED_TRACE("peer " + std::to_string(p));
    EXPECT_FALSE(m.record(p).has(EventType::disconnected));
    EXPECT_GT(m.session(p).stats().ignored_gone_reports, 500U);
    for (net::InputStatus s : m.record(p).status)
      ASSERT_EQ(s, net::InputStatus::confirmed);
  }
}

// ---- range guards ----

TEST(NetAttack, ImplausibleFramesAreDroppedWholeAndTheMatchEndsHonest) {
  // Every third input datagram of peer 1 claims a held frame beyond what it acknowledges, or a
  // current frame far ahead of (or far behind) the inputs it carries.
  MatchOptions o;
  o.match_key.reset();  // the plain framing: what a peer with the key could send sealed
  o.frames = 1200;
  o.link = net::internet_link();
  o.wrap = tamper(1, [](net::PeerId, Packet& p, std::uint64_t n) {
    if (p.header.type != PacketType::input || n % 3 != 0) return true;
    net::protocol::InputBody& b = p.input;
    switch (n / 3 % 3) {
      case 0:
        b.held_frame = b.ack_frame + 1000;
        break;
      case 1:
        b.current_frame += 100'000;
        break;
      default:
        b.current_frame = b.start_frame + b.count > 40 ? b.start_frame + b.count - 40 : 0;
        if (b.start_frame + b.count <= 40) b.held_frame = b.ack_frame + 1;
        break;
    }
    return true;
  });
  Match m(o);
  ASSERT_TRUE(m.run()) << m.compare();
  EXPECT_EQ(m.compare(), "");
  EXPECT_GT(m.session(0).stats().dropped_implausible, 200U);
  EXPECT_EQ(m.session(1).stats().dropped_implausible, 0U);  // honest datagrams always pass
  const auto stats = m.session(0).peer_stats(1);
  ASSERT_TRUE(stats.has_value());
  EXPECT_LE(stats->remote_frame, o.frames + 40);  // never the absurd one
}

TEST(NetAttack, ALyingFrameAdvantageCannotSlowTheMatch) {
  // Peer 1 claims in every datagram to be as far behind as the field allows (-127 frames), which
  // asks peer 0 to wait ~63 frames. Peer 0 trusts it only as far as its own measurement agrees.
  std::uint32_t most_wait = 0;
  MatchOptions o;
  o.match_key.reset();  // the plain framing: what a peer with the key could send sealed
  o.frames = 1200;
  o.link.latency_us = 30'000;
  o.wrap = tamper(1, [](net::PeerId, Packet& p, std::uint64_t) {
    if (p.header.type == PacketType::input) p.input.advantage = -127;
    return true;
  });
  o.on_tick = [&most_wait](std::uint32_t p, std::uint64_t, net::Session& s) {
    if (p == 0) most_wait = std::max(most_wait, s.recommended_wait_frames());
  };
  Match m(o);
  ASSERT_TRUE(m.run()) << m.compare();
  EXPECT_EQ(m.compare(), "");
  EXPECT_LE(most_wait, 6U);  // the tolerance (8 frames) halved, plus the honest advantage
}

/// Peer 0's transport: delivers what the network delivers, keeps peer 1's first pong and first
/// input datagrams, and delivers them again (stale) with every later receive.
class Replayer final : public net::Transport {
 public:
  explicit Replayer(net::Transport& inner) : inner_(inner) {}
  void send(net::PeerId to, std::span<const std::uint8_t> bytes) override {
    inner_.send(to, bytes);
  }
  void receive(std::vector<net::Datagram>& out) override {
    const std::size_t before = out.size();
    inner_.receive(out);
    for (std::size_t i = before; i < out.size(); ++i) {
      const net::Datagram& d = out[i];
      if (d.from != 1 || d.bytes.size() < 4) continue;
      if (d.bytes[3] == static_cast<std::uint8_t>(PacketType::pong) && !pong_) pong_ = d.bytes;
      if (d.bytes[3] == static_cast<std::uint8_t>(PacketType::input) && inputs_.size() < 20)
        inputs_.push_back(d.bytes);
    }
    if (pong_) out.push_back({1, *pong_});
    for (const auto& old : inputs_)
      out.push_back({1, old});
  }

 private:
  net::Transport& inner_;
  std::optional<std::vector<std::uint8_t>> pong_;
  std::vector<std::vector<std::uint8_t>> inputs_;
};

TEST(NetAttack, ReplayedPongsAndOldDatagramsChangeNoTimeSync) {
  std::uint64_t remote_frame_went_back = 0;
  std::uint64_t last_remote_frame = 0;
  MatchOptions o;
  o.match_key.reset();  // the plain framing: what a peer with the key could send sealed
  o.frames = 1200;
  o.link.latency_us = 30'000;
  o.wrap = [](std::uint32_t p, net::Transport& inner) -> std::unique_ptr<net::Transport> {
    if (p != 0) return nullptr;
    return std::make_unique<Replayer>(inner);
  };
  o.on_tick = [&](std::uint32_t p, std::uint64_t, net::Session& s) {
    if (p != 0) return;
    const auto peer = s.peer_stats(1);
    if (peer->remote_frame < last_remote_frame) ++remote_frame_went_back;
    last_remote_frame = peer->remote_frame;
  };
  Match m(o);
  ASSERT_TRUE(m.run()) << m.compare();
  EXPECT_EQ(m.compare(), "");
  EXPECT_GT(m.session(0).stats().dropped_stale_pongs, 1000U);
  EXPECT_EQ(remote_frame_went_back, 0U);
  const auto peer = m.session(0).peer_stats(1);
  EXPECT_GE(peer->remote_frame, o.frames - 10);  // the newest datagram's, not a replayed one's
  EXPECT_GT(peer->ping_us, 50'000U);  // 60 ms round trip, measured from genuine pongs only
  EXPECT_LT(peer->ping_us, 80'000U);
}

// ---- every confirmed check accounted for ----

TEST(NetAttack, ARelayThatRewritesInputsAndStripsChecksIsCaughtNotASilentSplit) {
  // The relay between peers 0 and 1 flips a bit of player 1's inputs on their way to peer 0 and
  // removes every hash check both ways: the peers confirm different frames, and before this
  // guard both ended "fine" with different final hashes. Now each raises check_missing for the
  // other, about the first check (frame 30), once the deadline passes.
  MatchOptions o;
  o.match_key.reset();  // the plain framing: what a peer with the key could send sealed
  o.frames = 1200;
  o.link.latency_us = 20'000;
  o.wrap = [](std::uint32_t p, net::Transport& inner) -> std::unique_ptr<net::Transport> {
    return std::make_unique<Tamper>(inner, [p](net::PeerId, Packet& packet, std::uint64_t) {
      if (packet.header.type != PacketType::input) return true;
      packet.input.checks.clear();
      if (p == 1 && !packet.input.deltas.empty()) packet.input.deltas[0] ^= 0x10;
      return true;
    });
  };
  Match m(o);
  ASSERT_TRUE(m.run());
  EXPECT_NE(m.compare(), "");  // the split happened...
  for (std::uint32_t p = 0; p < 2; ++p) {
    SCOPED_TRACE("peer " + std::to_string(p));
    const net::Event* missing = find(m.record(p), EventType::check_missing);
    ASSERT_NE(missing, nullptr);  // ...and is reported, not passed
    EXPECT_EQ(missing->player, 1 - p);
    EXPECT_EQ(missing->frame, 30U);
    EXPECT_EQ(m.session(p).stats().checks_missing, 1U);
    EXPECT_EQ(m.session(p).stats().checks_compared, 0U);
  }
}

TEST(NetAttack, ChecksStrippedOneWayAreMissingOnTheSideThatLacksThem) {
  // Only peer 1's checks are removed: peer 0 cannot verify anything and says so; peer 1 compares
  // peer 0's checks as usual and raises nothing.
  MatchOptions o;
  o.match_key.reset();  // the plain framing: what a peer with the key could send sealed
  o.frames = 1200;
  o.link = net::internet_link();
  o.wrap = tamper(1, [](net::PeerId, Packet& p, std::uint64_t) {
    if (p.header.type == PacketType::input) p.input.checks.clear();
    return true;
  });
  Match m(o);
  ASSERT_TRUE(m.run()) << m.compare();
  EXPECT_EQ(m.compare(), "");
  EXPECT_TRUE(m.record(0).has(EventType::check_missing));
  EXPECT_FALSE(m.record(1).has(EventType::check_missing));
  EXPECT_GT(m.session(1).stats().checks_compared, 30U);
  EXPECT_EQ(m.session(0).peer_stats(1)->checks_received_through, 0U);
}

// ---- progress ----

/// The tick at which peer 0 first shows player 1 as disconnected, via on_tick.
struct DisconnectWatch {
  std::optional<std::uint64_t> tick;
  void operator()(std::uint32_t p, std::uint64_t t, net::Session& s) {
    if (p == 0 && !tick && s.peer_stats(1)->disconnected) tick = t;
  }
};

/// Ticks of the progress guard's window at the default 10 s.
constexpr std::uint64_t window_ticks = 10'000'000 / 16'667 + 1;

TEST(NetAttack, AHeldFrameOfZeroCannotStallTheMatch) {
  // Peer 1 plays, but claims in every datagram to hold no frame at all: no frame is ever final
  // on peer 0, its ring of states fills and it cannot advance. The progress guard disconnects
  // player 1 within two windows, naming why, and peer 0 plays on.
  auto watch = std::make_shared<DisconnectWatch>();
  MatchOptions o;
  o.match_key.reset();  // the plain framing: what a peer with the key could send sealed
  o.frames = 2400;
  // The victim plays on alone after the disconnect (a two-player match's default is to end:
  // SessionConfig::partition), which is what this test watches.
  o.configure = [](std::uint32_t, net::SessionConfig& c) {
    c.partition = net::PartitionPolicy::play_on;
  };
  o.max_ticks = 6000;
  o.link.latency_us = 20'000;
  o.wrap = tamper(1, [](net::PeerId, Packet& p, std::uint64_t) {
    if (p.header.type == PacketType::input) p.input.held_frame = 0;
    return true;
  });
  o.on_tick = [watch](std::uint32_t p, std::uint64_t t, net::Session& s) { (*watch)(p, t, s); };
  Match m(o);
  m.run();
  const net::Event* gone = find(m.record(0), EventType::disconnected);
  ASSERT_NE(gone, nullptr);
  EXPECT_EQ(gone->player, 1U);
  EXPECT_EQ(gone->reason, "no progress");
  ASSERT_TRUE(watch->tick.has_value());
  EXPECT_LE(*watch->tick, 2 * window_ticks + 60);
  EXPECT_GE(m.record(0).hashes.size(), o.frames);  // and peer 0 went on to the end
}

TEST(NetAttack, APeerThatTalksButNeverAdvancesIsDisconnectedForNoProgress) {
  // Peer 1 stops advancing at tick 300 but keeps polling: it acknowledges, answers pings and sends
  // keepalives, so it is never silent. Peer 0 waits at the prediction limit until the progress
  // guard disconnects player 1.
  auto watch = std::make_shared<DisconnectWatch>();
  MatchOptions o;
  o.frames = 1800;
  // The victim plays on alone after the disconnect (a two-player match's default is to end:
  // SessionConfig::partition), which is what this test watches.
  o.configure = [](std::uint32_t, net::SessionConfig& c) {
    c.partition = net::PartitionPolicy::play_on;
  };
  o.max_ticks = 6000;
  o.link.latency_us = 20'000;
  o.active = [](std::uint32_t p, std::uint64_t tick) { return p != 1 || tick < 300; };
  o.on_tick = [watch](std::uint32_t p, std::uint64_t t, net::Session& s) { (*watch)(p, t, s); };
  Match m(o);
  m.run();
  const net::Event* gone = find(m.record(0), EventType::disconnected);
  ASSERT_NE(gone, nullptr);
  EXPECT_EQ(gone->player, 1U);
  EXPECT_EQ(gone->reason, "no progress");
  EXPECT_FALSE(m.record(0).has(EventType::interrupted));  // it never went silent
  ASSERT_TRUE(watch->tick.has_value());
  EXPECT_GT(*watch->tick, 300U);
  EXPECT_LE(*watch->tick, 300 + 2 * window_ticks);
  EXPECT_GE(m.record(0).hashes.size(), o.frames);
  // Every frame both confirmed before player 1 was gone is the same on both.
  const std::size_t common = std::min(m.record(0).hashes.size(), m.record(1).hashes.size());
  EXPECT_GT(common, 250U);
  EXPECT_TRUE(std::equal(m.record(1).hashes.begin(),
                         m.record(1).hashes.begin() + static_cast<std::ptrdiff_t>(common),
                         m.record(0).hashes.begin()));
}

TEST(NetAttack, HonestSlowLinksAreNeverTakenForNoProgress) {
  // 400 ms one way (24 frames, three times the prediction window) for 60 s of match: the peers
  // sit at the limit much of the time, but progress never stops.
  MatchOptions o;
  o.frames = 3600;
  o.input_delay = 0;
  o.max_ticks = 40'000;
  o.link.latency_us = 400'000;
  o.link.jitter_us = 30'000;
  Match m(o);
  ASSERT_TRUE(m.run()) << m.compare();
  EXPECT_EQ(m.compare(), "");
  EXPECT_FALSE(m.record(0).has(EventType::disconnected));
  EXPECT_FALSE(m.record(1).has(EventType::disconnected));
  EXPECT_GT(m.session(0).stats().prediction_limit_waits, 100U);
}

}  // namespace
}  // namespace detsim
