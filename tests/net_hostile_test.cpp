// Hostile datagrams reaching a session: garbage, truncations, corruptions, other versions, foreign
// session ids, replayed stale packets and well-formed packets with out-of-window frames. Each is
// dropped and counted by kind, and the match still ends with every peer equal to an offline replay.
#include <gtest/gtest.h>

#include <random>

#include <detsim/net/protocol.hpp>
#include <detsim/net/session.hpp>

#include "support/net_match.hpp"

namespace detsim {
namespace {

using net::protocol::DecodeError;
using test::Match;
using test::MatchOptions;

/// Datagrams peer 1 really sent to peer 0, for crafting believable forgeries.
struct Captured {
  std::vector<std::vector<std::uint8_t>> inputs;  ///< input packets, in send order
};

/// Peer 1's transport: passes everything through and keeps copies of its input packets to 0.
class Recorder final : public net::Transport {
 public:
  Recorder(net::Transport& inner, Captured& captured) : inner_(inner), captured_(captured) {}
  void send(net::PeerId to, std::span<const std::uint8_t> bytes) override {
    if (to == 0 && bytes.size() > 3 &&
        bytes[3] == static_cast<std::uint8_t>(net::protocol::PacketType::input))
      captured_.inputs.emplace_back(bytes.begin(), bytes.end());
    inner_.send(to, bytes);
  }
  void receive(std::vector<net::Datagram>& out) override { inner_.receive(out); }

 private:
  net::Transport& inner_;
  Captured& captured_;
};

/// Peer 0's transport: delivers what the network delivers plus a few forged datagrams "from
/// peer 1" every call.
class Injector final : public net::Transport {
 public:
  Injector(net::Transport& inner, const Captured& captured, std::uint32_t input_size)
      : inner_(inner), captured_(captured), input_size_(input_size) {}
  void send(net::PeerId to, std::span<const std::uint8_t> bytes) override {
    inner_.send(to, bytes);
  }
  void receive(std::vector<net::Datagram>& out) override {
    inner_.receive(out);
    ++calls_;
    // Plain garbage of every length class.
    out.push_back({1, random_bytes(rng_() % 14)});                           // too short
    out.push_back({1, random_bytes(14 + rng_() % 200)});                     // bad magic, mostly
    out.push_back({1, random_bytes(net::max_datagram + 1 + rng_() % 100)});  // too long
    out.push_back({7, random_bytes(40)});                                    // an unknown peer id
    if (captured_.inputs.size() < 2) return;
    const std::vector<std::uint8_t>& real = captured_.inputs[rng_() % captured_.inputs.size()];
    // A corrupted copy: one flipped bit (checksum), a truncation, another version.
    std::vector<std::uint8_t> flipped = real;
    flipped[rng_() % flipped.size()] ^= static_cast<std::uint8_t>(1U << (rng_() % 8));
    out.push_back({1, flipped});
    out.push_back({1, std::vector<std::uint8_t>(real.begin(), real.begin() + 12)});
    std::vector<std::uint8_t> other_version = real;
    other_version[2] = net::protocol::version + 1;
    out.push_back({1, other_version});
    // A stale packet replayed as it was (valid, duplicate frames: harmless by design).
    out.push_back({1, real});
    // Well-formed forgeries with a valid checksum, built from a real packet.
    net::protocol::Packet p;
    if (net::protocol::decode(real, input_size_, p) != DecodeError::none) return;
    net::protocol::Packet foreign = p;
    foreign.header.session ^= 0x5A5A5A5AU;  // another session's id
    push_encoded(out, foreign);
    net::protocol::Packet far = p;  // inputs far beyond any window
    far.input.start_frame += 100'000;
    push_encoded(out, far);
    net::protocol::Packet bad_check = p;  // a hash check at a frame no interval produces
    bad_check.input.checks = {{31, 0x1234}};
    push_encoded(out, bad_check);
  }
  std::uint64_t calls() const { return calls_; }

 private:
  std::vector<std::uint8_t> random_bytes(std::size_t n) {
    std::vector<std::uint8_t> bytes(n);
    for (std::uint8_t& b : bytes)
      b = static_cast<std::uint8_t>(rng_());
    return bytes;
  }
  void push_encoded(std::vector<net::Datagram>& out, const net::protocol::Packet& p) {
    std::vector<std::uint8_t> bytes;
    if (net::protocol::encode(p, input_size_, bytes)) out.push_back({1, bytes});
  }

  net::Transport& inner_;
  const Captured& captured_;
  std::uint32_t input_size_;
  std::mt19937_64 rng_{2026};
  std::uint64_t calls_ = 0;
};

TEST(NetHostile, ForgedAndBrokenDatagramsAreDroppedAndCountedAndChangeNothing) {
  Captured captured;
  Injector* injector = nullptr;
  MatchOptions o;
  o.match_key.reset();  // the plain framing's decoder, checksum and session ids
  o.frames = 1200;
  o.check_interval = 30;
  o.link.latency_us = 40'000;
  o.link.jitter_us = 10'000;
  o.link.loss_ppm = 20'000;
  o.wrap = [&](std::uint32_t p, net::Transport& inner) -> std::unique_ptr<net::Transport> {
    if (p == 1) return std::make_unique<Recorder>(inner, captured);
    auto made = std::make_unique<Injector>(inner, captured, 4);
    injector = made.get();
    return made;
  };
  Match m(o);
  ASSERT_TRUE(m.run()) << m.compare();
  EXPECT_EQ(m.compare(), "");  // peers equal each other and an offline replay; no desync
  ASSERT_NE(injector, nullptr);
  ASSERT_GT(injector->calls(), 1000U);

  const net::SessionStats& s = m.session(0).stats();
  const auto dropped = [&](DecodeError e) {
    return s.dropped_malformed[static_cast<std::size_t>(e)];
  };
  EXPECT_GE(dropped(DecodeError::too_short), injector->calls() * 2 - 10);
  EXPECT_GE(dropped(DecodeError::too_long), injector->calls() - 5);
  EXPECT_GT(dropped(DecodeError::bad_magic), injector->calls() / 2);
  EXPECT_GT(dropped(DecodeError::bad_checksum), 500U);
  EXPECT_GT(dropped(DecodeError::bad_version), 500U);
  EXPECT_GT(s.dropped_wrong_session, 1000U);  // unknown peer ids and foreign session ids
  EXPECT_GT(s.dropped_out_of_window, 1000U);  // far frames and impossible check frames
  EXPECT_EQ(dropped(DecodeError::none), 0U);
  // Nothing forged reached the game: peer 0 never saw a desync nor a rollback storm.
  EXPECT_FALSE(m.record(0).has(net::EventType::desync));
  EXPECT_FALSE(m.record(1).has(net::EventType::desync));
}

TEST(NetHostile, AHelloFromAnotherMatchIsRejectedAndReportedOnce) {
  // Peer 1 believes it is player 0 of a 2-player match as well (a misconfigured peer).
  MatchOptions o;
  o.frames = 20;
  o.max_ticks = 200;
  o.configure = [](std::uint32_t p, net::SessionConfig& c) {
    if (p == 1) {
      c.local_player = 0;
      c.remotes = {{1, 0}};
    }
  };
  Match m(o);
  EXPECT_FALSE(m.run());
  std::size_t reports = 0;
  for (const net::Event& e : m.record(0).events) {
    if (e.type != net::EventType::hello_rejected) continue;
    ++reports;
    EXPECT_EQ(e.reason, "player index");
  }
  EXPECT_EQ(reports, 1U);
  EXPECT_FALSE(m.session(0).running());
  EXPECT_GT(m.session(0).stats().dropped_wrong_session, 5U);
}

}  // namespace
}  // namespace detsim
