// Packet protection (issue 31, point 2; docs/NET.md, "Packet protection"): the keys, the AEAD and
// the replay window on their own, then whole matches whose datagrams a relay rewrites, replays,
// reorders, strips or drops, and peers with another key. A relay without the match key can only
// drop: every match ends with the honest hashes, or with a detected error on both sides.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <optional>

#include <detsim/net/protection.hpp>
#include <detsim/net/protocol.hpp>
#include <detsim/net/session.hpp>

#include "support/net_match.hpp"

namespace detsim {
namespace {

namespace protection = net::protection;
namespace protocol = net::protocol;
using net::EventType;
using test::Match;
using test::MatchOptions;

#define REQUIRE_SODIUM()                                                            \
  if (!protection::available()) GTEST_SKIP() << "built without libsodium: no keys"; \
  static_assert(true)

using Bytes = std::vector<std::uint8_t>;

/// A sealed datagram as a session writes it: `packet` under `key` with `sequence`.
Bytes sealed(const protocol::Packet& packet, const protection::Key& key, std::uint64_t sequence) {
  Bytes out;
  EXPECT_TRUE(
      protocol::encode_sealed_plaintext(packet, static_cast<std::uint32_t>(sequence), 4, out));
  EXPECT_TRUE(
      protection::seal(key, sequence, protocol::sealed_header_size(packet.header.type), out));
  return out;
}

protocol::Packet sample_input() {
  protocol::Packet p;
  p.header.type = protocol::PacketType::input;
  p.input.ack_frame = 1000;
  p.input.check_ack = 990;
  p.input.current_frame = 1002;
  p.input.start_frame = 1001;
  p.input.count = 2;
  p.input.deltas = {0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77, 0x88};
  p.input.held_frame = 1000;
  p.input.checks = {{990, 0x0123'4567'89AB'CDEFULL}};
  return p;
}

// ---- keys ----

TEST(NetProtection, EachDirectionSessionAndMatchHasItsOwnKey) {
  REQUIRE_SODIUM();
  const net::MatchKey k = test::test_match_key();
  const net::MatchKey other = test::test_match_key(1);
  const auto a = protection::data_key(k, 1, 2).bytes;
  EXPECT_EQ(a, protection::data_key(k, 1, 2).bytes);      // both sides derive the same
  EXPECT_NE(a, protection::data_key(k, 2, 1).bytes);      // the other direction
  EXPECT_NE(a, protection::data_key(k, 1, 3).bytes);      // another receiver session
  EXPECT_NE(a, protection::data_key(k, 3, 2).bytes);      // another sender session
  EXPECT_NE(a, protection::data_key(other, 1, 2).bytes);  // another match
  EXPECT_NE(a, protection::handshake_key(k, 1).bytes);    // the handshake's
  EXPECT_NE(protection::handshake_key(k, 1).bytes, protection::handshake_key(k, 2).bytes);
  EXPECT_NE(protection::handshake_key(k, 1).bytes, protection::handshake_key(other, 1).bytes);
}

// ---- the AEAD ----

TEST(NetProtection, ASealedDatagramOpensOnlyUnchangedUnderItsKeyAndSequence) {
  REQUIRE_SODIUM();
  const protection::Key key = protection::data_key(test::test_match_key(), 7, 9);
  const protocol::Packet p = sample_input();
  const Bytes d = sealed(p, key, 41);
  ASSERT_EQ(d[1], protocol::sealed_magic1);
  Bytes plain;
  ASSERT_TRUE(protocol::encode(p, 4, plain));
  // 8-byte header and 16-byte tag for the plain framing's 14 and 4: 6 bytes more.
  EXPECT_EQ(d.size(), plain.size() + 6);

  Bytes body;
  ASSERT_TRUE(protection::open(key, 41, protocol::sealed_data_header_size, d, body));
  protocol::Packet back;
  ASSERT_EQ(protocol::decode_body(protocol::PacketType::input, body, 4, back),
            protocol::DecodeError::none);
  EXPECT_EQ(back.input.deltas, p.input.deltas);
  EXPECT_EQ(back.input.checks, p.input.checks);
  // Encrypted: the inputs and the hash are nowhere in the clear.
  const auto has = [&d](const Bytes& needle) {
    return std::search(d.begin(), d.end(), needle.begin(), needle.end()) != d.end();
  };
  EXPECT_FALSE(has({0x11, 0x22, 0x33}));
  EXPECT_FALSE(has({0xEF, 0xCD, 0xAB, 0x89}));

  // Every single-bit change anywhere (header, ciphertext, tag) fails, as does another sequence,
  // another key, or any truncation.
  for (std::size_t i = 0; i < d.size(); ++i) {
    for (int bit = 0; bit < 8; ++bit) {
      Bytes e = d;
      e[i] ^= static_cast<std::uint8_t>(1U << bit);
      EXPECT_FALSE(protection::open(key, 41, protocol::sealed_data_header_size, e, body))
          << "byte " << i << " bit " << bit;
      EXPECT_TRUE(body.empty());
    }
  }
  EXPECT_FALSE(protection::open(key, 42, protocol::sealed_data_header_size, d, body));
  EXPECT_FALSE(protection::open(protection::data_key(test::test_match_key(), 9, 7), 41,
                                protocol::sealed_data_header_size, d, body));
  for (std::size_t n = 0; n < d.size(); ++n)
    EXPECT_FALSE(protection::open(key, 41, protocol::sealed_data_header_size,
                                  std::span<const std::uint8_t>(d).first(n), body));
}

TEST(NetProtection, SealedHeadersAreCheckedBeforeAnyKeyIsUsed) {
  REQUIRE_SODIUM();
  protocol::Packet hello;
  hello.header.type = protocol::PacketType::hello;
  hello.header.session = 0x1122'3344'5566'7788ULL;
  hello.hello = {0xF1, 2, 1, 4, 0xC4A1};
  const Bytes d = sealed(hello, protection::handshake_key(test::test_match_key(), 5), 3);
  protocol::SealedHeader h;
  ASSERT_EQ(protocol::decode_sealed_header(d, h), protocol::DecodeError::none);
  EXPECT_EQ(h.type, protocol::PacketType::hello);
  EXPECT_EQ(h.sequence, 3U);
  EXPECT_EQ(h.session, hello.header.session);  // in the clear: the receiver derives the key
  EXPECT_EQ(h.size, protocol::sealed_handshake_header_size);

  const auto error = [](Bytes b) {
    protocol::SealedHeader x;
    return protocol::decode_sealed_header(b, x);
  };
  EXPECT_EQ(error(Bytes(d.begin(), d.begin() + 23)), protocol::DecodeError::too_short);
  EXPECT_EQ(error(Bytes(net::max_datagram + 1, 0)), protocol::DecodeError::too_long);
  Bytes e = d;
  e[1] = 'N';
  EXPECT_EQ(error(e), protocol::DecodeError::bad_magic);
  e = d;
  e[2] = protocol::version - 1;
  EXPECT_EQ(error(e), protocol::DecodeError::bad_version);
  e = d;
  e[3] = 9;
  EXPECT_EQ(error(e), protocol::DecodeError::bad_type);
  // The plain decoder refuses the sealed framing, and the sealed one the plain framing.
  protocol::Packet p;
  EXPECT_EQ(protocol::decode(d, 4, p), protocol::DecodeError::bad_magic);
  Bytes plain;
  ASSERT_TRUE(protocol::encode(sample_input(), 4, plain));
  EXPECT_EQ(error(plain), protocol::DecodeError::bad_magic);
}

// ---- the replay window ----

TEST(NetProtection, TheReplayWindowRefusesDuplicatesAndOldSequencesAndAcceptsReordering) {
  protection::ReplayWindow w;
  EXPECT_TRUE(w.fresh(0));
  w.accept(100);
  EXPECT_FALSE(w.fresh(100));  // a duplicate
  EXPECT_TRUE(w.fresh(101));
  // Reordered within the window: each earlier sequence is accepted once.
  for (std::uint64_t s = 99; s > 100 - protection::ReplayWindow::size; --s) {
    EXPECT_TRUE(w.fresh(s)) << s;
    w.accept(s);
    EXPECT_FALSE(w.fresh(s)) << s;
  }
  EXPECT_FALSE(w.fresh(100 - protection::ReplayWindow::size));  // older than the window
  EXPECT_FALSE(w.fresh(0));
  // A jump forward beyond the window forgets everything behind it: all of it is now too old.
  w.accept(1000);
  EXPECT_FALSE(w.fresh(1000 - 64));
  EXPECT_TRUE(w.fresh(1000 - 63));
  EXPECT_TRUE(w.fresh(999));
  EXPECT_FALSE(w.fresh(1000));
}

TEST(NetProtection, SequencesAreRebuiltFromTheirLow32BitsAcrossWraps) {
  protection::ReplayWindow w;
  EXPECT_EQ(w.expand(0), 0U);
  EXPECT_EQ(w.expand(5), 5U);
  const std::uint64_t wrap = std::uint64_t{1} << 32;
  w.accept(wrap - 2);
  EXPECT_EQ(w.expand(0xFFFF'FFFFU), wrap - 1);
  EXPECT_EQ(w.expand(0), wrap);  // past the wrap
  EXPECT_EQ(w.expand(3), wrap + 3);
  EXPECT_EQ(w.expand(0xFFFF'FFF0U), wrap - 16);  // a late one from before it
  w.accept(wrap + 10);
  EXPECT_EQ(w.expand(0xFFFF'FFFEU), wrap - 2);
  EXPECT_EQ(w.expand(11), wrap + 11);
  EXPECT_EQ(w.expand(0x8000'0000U), wrap + 0x8000'0000ULL);
}

// ---- sessions ----

TEST(NetProtection, AZeroKeyIsRefused) {
  REQUIRE_SODIUM();
  test::CounterGame game;
  auto network = net::SimNetwork::create(2, 1, {});
  net::SessionConfig c;
  c.remotes = {{1, 1}};
  c.match_key = net::MatchKey{};
  auto s = net::Session::create(c, game, network.value().endpoint(0));
  ASSERT_FALSE(s);
  EXPECT_NE(s.message().find("match_key"), std::string::npos) << s.message();
}

/// A relay on peer p's path: sees each datagram p sends and may drop it (false) or change its
/// bytes. It holds no key.
class Relay final : public net::Transport {
 public:
  using Edit = std::function<bool(net::PeerId to, Bytes& bytes, std::uint64_t n)>;
  Relay(net::Transport& inner, Edit edit) : inner_(inner), edit_(std::move(edit)) {}
  void send(net::PeerId to, std::span<const std::uint8_t> bytes) override {
    Bytes b(bytes.begin(), bytes.end());
    if (edit_(to, b, count_++)) inner_.send(to, b);
  }
  void receive(std::vector<net::Datagram>& out) override { inner_.receive(out); }

 private:
  net::Transport& inner_;
  Edit edit_;
  std::uint64_t count_ = 0;
};

MatchOptions::Wrap relay(Relay::Edit edit) {
  return [edit](std::uint32_t, net::Transport& inner) -> std::unique_ptr<net::Transport> {
    return std::make_unique<Relay>(inner, edit);
  };
}

std::uint64_t dropped_total(const net::SessionStats& s) {
  std::uint64_t n = s.dropped_unauthenticated + s.dropped_replayed;
  for (const std::uint64_t m : s.dropped_malformed)
    n += m;
  return n;
}

bool is_input(const Bytes& b) {
  return b.size() > 3 && b[3] == static_cast<std::uint8_t>(protocol::PacketType::input);
}

TEST(NetProtection, ARelayThatChangesAnyByteOnlyGetsTheDatagramDropped) {
  // Both ways, after the first 40, every third input datagram gets one byte changed, the byte
  // moving through every position (header, ciphertext, tag) and the change through every value.
  // Each such datagram is dropped and counted — none is taken — and the match is the honest one.
  REQUIRE_SODIUM();
  std::uint64_t changed = 0;
  MatchOptions o;
  o.frames = 1500;
  o.link.latency_us = 30'000;
  o.wrap = relay([&changed](net::PeerId, Bytes& b, std::uint64_t n) {
    if (!is_input(b) || n < 40 || n % 3 != 0) return true;
    b[(n / 3) % b.size()] ^= static_cast<std::uint8_t>(1 + (n / 7) % 255);
    ++changed;
    return true;
  });
  Match m(o);
  ASSERT_TRUE(m.run()) << m.compare();
  EXPECT_EQ(m.compare(), "");
  EXPECT_EQ(m.checks_complete(), "");
  ASSERT_GT(changed, 500U);
  const net::SessionStats& s0 = m.session(0).stats();
  const net::SessionStats& s1 = m.session(1).stats();
  // A perfect link: every changed datagram arrived, and each was dropped (most by the tag; a
  // changed magic, version or type by the header, a changed sequence by the window or the tag).
  // Those still in flight when the match ended are the only ones not counted.
  EXPECT_LE(dropped_total(s0) + dropped_total(s1), changed);
  EXPECT_GE(dropped_total(s0) + dropped_total(s1), changed - 4);
  EXPECT_GT(s0.dropped_unauthenticated + s1.dropped_unauthenticated, changed * 9 / 10);
  EXPECT_FALSE(m.record(0).has(EventType::desync));
  EXPECT_FALSE(m.record(1).has(EventType::desync));
}

/// Peer 0's transport: delivers what the network delivers, then again every earlier datagram of
/// peer 1's that it kept (its first pong and first 20 input datagrams) with every receive.
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
      if (d.bytes[3] == static_cast<std::uint8_t>(protocol::PacketType::pong) && !pong_)
        pong_ = d.bytes;
      if (is_input(d.bytes) && inputs_.size() < 20) inputs_.push_back(d.bytes);
    }
    if (pong_) {
      out.push_back({1, *pong_});
      ++replayed;
    }
    for (const auto& old : inputs_)
      out.push_back({1, old});
    replayed += inputs_.size();
  }
  std::uint64_t replayed = 0;

 private:
  net::Transport& inner_;
  std::optional<Bytes> pong_;
  std::vector<Bytes> inputs_;
};

TEST(NetProtection, ReplayedDatagramsAreDroppedBeforeTheyTouchTheSession) {
  // The plain framing's version of this attack reached the session, which had to discard the
  // stale pong and the old frames itself (net_attack_test); sealed, the window drops every copy
  // before it is decrypted: not one stale pong is even seen.
  REQUIRE_SODIUM();
  Replayer* replayer = nullptr;
  MatchOptions o;
  o.frames = 1200;
  o.link.latency_us = 30'000;
  o.wrap = [&replayer](std::uint32_t p, net::Transport& inner) -> std::unique_ptr<net::Transport> {
    if (p != 0) return nullptr;
    auto made = std::make_unique<Replayer>(inner);
    replayer = made.get();
    return made;
  };
  Match m(o);
  ASSERT_TRUE(m.run()) << m.compare();
  EXPECT_EQ(m.compare(), "");
  EXPECT_EQ(m.checks_complete(), "");
  ASSERT_NE(replayer, nullptr);
  ASSERT_GT(replayer->replayed, 20'000U);
  const net::SessionStats& s = m.session(0).stats();
  EXPECT_EQ(s.dropped_replayed, replayer->replayed);  // every copy, and nothing else
  EXPECT_EQ(s.dropped_stale_pongs, 0U);               // none reached the session
  EXPECT_EQ(s.dropped_unauthenticated, 0U);
  const auto peer = m.session(0).peer_stats(1);
  EXPECT_GT(peer->ping_us, 50'000U);  // 60 ms round trip: genuine pongs only
  EXPECT_LT(peer->ping_us, 80'000U);
  EXPECT_EQ(peer->packets_lost, 0U);
}

/// Delivers each receive's datagrams after the next receive's, each batch reversed: every
/// datagram arrives behind a few later ones (well within the 64 of the window).
class Reorderer final : public net::Transport {
 public:
  explicit Reorderer(net::Transport& inner) : inner_(inner) {}
  void send(net::PeerId to, std::span<const std::uint8_t> bytes) override {
    inner_.send(to, bytes);
  }
  void receive(std::vector<net::Datagram>& out) override {
    std::vector<net::Datagram> batch;
    inner_.receive(batch);
    std::reverse(batch.begin(), batch.end());
    if (++calls_ % 2 == 1) {
      held_ = std::move(batch);
      return;
    }
    out.insert(out.end(), batch.begin(), batch.end());
    out.insert(out.end(), held_.begin(), held_.end());
    held_.clear();
  }

 private:
  net::Transport& inner_;
  std::vector<net::Datagram> held_;
  std::uint64_t calls_ = 0;
};

TEST(NetProtection, DatagramsReorderedWithinTheWindowAreAccepted) {
  REQUIRE_SODIUM();
  MatchOptions o;
  o.frames = 1200;
  o.link.latency_us = 20'000;
  o.link.jitter_us = 25'000;  // reorders on its own too
  o.wrap = [](std::uint32_t, net::Transport& inner) -> std::unique_ptr<net::Transport> {
    return std::make_unique<Reorderer>(inner);
  };
  Match m(o);
  ASSERT_TRUE(m.run()) << m.compare();
  EXPECT_EQ(m.compare(), "");
  EXPECT_EQ(m.checks_complete(), "");
  for (std::uint32_t p = 0; p < 2; ++p) {
    const net::SessionStats& s = m.session(p).stats();
    EXPECT_EQ(s.dropped_replayed, 0U);
    EXPECT_EQ(s.dropped_unauthenticated, 0U);
    EXPECT_EQ(m.session(p).peer_stats(1 - p)->packets_lost, 0U);  // late ones filled the gaps
  }
}

TEST(NetProtection, ARelayThatRewritesInputsAndDropsTheChecksCannotSplitTheMatch) {
  // The attack that split plain matches silently (net_attack_test): rewrite player 1's inputs,
  // strip every hash check. Sealed, the relay can neither read nor edit: it changes bytes where
  // the inputs would be, and, knowing only sizes, drops every datagram 9 bytes (a check's) or
  // more longer than the shortest it saw. No frame is ever confirmed differently; what the relay
  // can do — hold checks back, stall — ends in a detected error on both sides.
  REQUIRE_SODIUM();
  MatchOptions o;
  o.frames = 900;
  // The victim plays on alone after the disconnect (a two-player match's default is to end:
  // SessionConfig::partition), which is what this test watches.
  o.configure = [](std::uint32_t, net::SessionConfig& c) {
    c.partition = net::PartitionPolicy::play_on;
  };
  o.max_ticks = 3000;
  o.link.latency_us = 20'000;
  o.wrap = [](std::uint32_t p, net::Transport& inner) -> std::unique_ptr<net::Transport> {
    auto shortest = std::make_shared<std::size_t>(net::max_datagram);
    return std::make_unique<Relay>(inner, [p, shortest](net::PeerId, Bytes& b, std::uint64_t n) {
      if (!is_input(b)) return true;
      *shortest = std::min(*shortest, b.size());
      if (b.size() >= *shortest + 9) return false;  // most likely a check in it
      if (p == 1 && n % 2 == 0) b[protocol::sealed_data_header_size + 9] ^= 0x10;
      return true;
    });
  };
  Match m(o);
  m.run();
  // No split: what both peers confirmed is the same, frame by frame, up to the first frame either
  // took the other as gone (the progress guard's "no progress", a detected end: from there each
  // plays on alone, as a two-player match with PartitionPolicy::play_on does).
  const test::PeerRecord& a = m.record(0);
  const test::PeerRecord& b = m.record(1);
  std::size_t common = std::min(a.hashes.size(), b.hashes.size());
  for (const test::PeerRecord* r : {&a, &b})
    for (std::size_t i = 0; i < r->status.size(); ++i)
      if (r->status[i] == net::InputStatus::disconnected) common = std::min(common, i / 2);
  EXPECT_GT(common, 20U);
  EXPECT_TRUE(std::equal(a.hashes.begin(), a.hashes.begin() + static_cast<std::ptrdiff_t>(common),
                         b.hashes.begin()));
  const bool honest = m.compare().empty();
  for (std::uint32_t p = 0; p < 2; ++p) {
    SCOPED_TRACE("peer " + std::to_string(p));
    const test::PeerRecord& r = m.record(p);
    EXPECT_FALSE(r.has(EventType::desync));
    // Checked or detected, never a silent pass.
    const bool detected = r.has(EventType::check_missing) || r.has(EventType::disconnected);
    EXPECT_TRUE(detected || m.session(p).stats().checks_compared > 0);
    if (!honest) {
      EXPECT_TRUE(detected) << m.compare();
    }
  }
  EXPECT_GT(m.session(0).stats().dropped_unauthenticated, 10U);  // the rewrites, all caught
}

TEST(NetProtection, PeersWithAnotherKeyOrNoneNeverPlayAndSaySo) {
  REQUIRE_SODIUM();
  struct Case {
    std::optional<net::MatchKey> key1;
    std::string_view reason0, reason1;
  };
  const Case cases[] = {
      {test::test_match_key(1), "not authenticated", "not authenticated"},
      {std::nullopt, "not sealed", "sealed"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(std::string(c.reason0));
    MatchOptions o;
    o.frames = 20;
    o.max_ticks = 300;  // 5 s: the match must not start, and run() must come back
    o.configure = [&c](std::uint32_t p, net::SessionConfig& config) {
      if (p == 1) config.match_key = c.key1;
    };
    Match m(o);
    EXPECT_FALSE(m.run());
    for (std::uint32_t p = 0; p < 2; ++p) {
      EXPECT_FALSE(m.session(p).running());
      EXPECT_EQ(m.record(p).hashes.size(), 0U);
      std::size_t reports = 0;
      for (const net::Event& e : m.record(p).events) {
        if (e.type != EventType::hello_rejected) continue;
        ++reports;
        EXPECT_EQ(e.reason, p == 0 ? c.reason0 : c.reason1);
      }
      EXPECT_EQ(reports, 1U) << "peer " << p;
    }
    EXPECT_GT(m.session(0).stats().dropped_unauthenticated, 10U);
  }
}

TEST(NetProtection, ASpectatorWithAnotherKeyIsNeverServed) {
  REQUIRE_SODIUM();
  MatchOptions o;
  o.frames = 300;
  o.spectators = 1;
  o.configure_spectator = [](std::uint32_t, net::SpectatorConfig& c) {
    c.match_key = test::test_match_key(2);
  };
  o.max_ticks = 1500;
  Match m(o);
  EXPECT_FALSE(m.run());  // the spectator never gets a frame
  EXPECT_EQ(m.compare(), "");
  EXPECT_GE(m.record(0).hashes.size(), o.frames);  // the players play on
  EXPECT_FALSE(m.spectator(0).running());
  EXPECT_EQ(m.spectator(0).current_frame(), 0U);
  EXPECT_GT(m.spectator(0).stats().dropped_unauthenticated, 5U);
  EXPECT_GT(m.session(0).stats().dropped_unauthenticated, 5U);
}

}  // namespace
}  // namespace detsim
