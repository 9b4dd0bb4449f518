// Spoofed source addresses over real UDP (issue 31): a third party off the path sends datagrams
// whose IP source is a genuine peer's address and port, built whole and sent through a raw socket.
// The transport's source-address filter passes them (it cannot tell), so what must stop them is the
// session: the challenge-bound handshake without a match key, and the tag with one. Each match
// ends with both peers confirming exactly the inputs the genuine players sent.
//
// A raw socket needs CAP_NET_RAW (root, as the README's commands run): where the machine refuses
// one, these tests are skipped with a message saying so. net_attack_test plays the same attacks
// on the simulated network everywhere.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include <detsim/net/protection.hpp>
#include <detsim/net/protocol.hpp>
#include <detsim/net/session.hpp>
#include <detsim/net/udp.hpp>

#include "support/net_match.hpp"

namespace detsim {
namespace {

using net::protocol::Packet;
using net::protocol::PacketType;
using Bytes = std::vector<std::uint8_t>;

constexpr std::uint32_t input_size = 4;
constexpr std::uint64_t fingerprint = 0x5B00F'0000ULL;  // the match's public settings
constexpr std::uint32_t input_delay = 2;

/// Sends UDP datagrams over IPv4 with any source address and port: the IP and UDP headers are
/// written here (IPPROTO_RAW implies IP_HDRINCL), so the kernel delivers them as the source's.
class SpoofSocket {
 public:
  /// The socket, or why the machine refuses one.
  static std::unique_ptr<SpoofSocket> open(std::string& why) {
    const int fd = ::socket(AF_INET, SOCK_RAW, IPPROTO_RAW);
    if (fd < 0) {
      why = "raw sockets need CAP_NET_RAW (" + std::generic_category().message(errno) +
            "): spoofed-source tests skipped";
      return nullptr;
    }
    return std::unique_ptr<SpoofSocket>(new SpoofSocket(fd));
  }
  ~SpoofSocket() { ::close(fd_); }
  SpoofSocket(const SpoofSocket&) = delete;
  SpoofSocket& operator=(const SpoofSocket&) = delete;

  /// One datagram "from" `from` to `to` (both IPv4); false if the kernel did not take it.
  bool send(const net::Endpoint& from, const net::Endpoint& to, const Bytes& payload) {
    constexpr std::size_t ip_size = 20;
    constexpr std::size_t udp_size = 8;
    const std::size_t total = ip_size + udp_size + payload.size();
    frame_.assign(total, 0);
    std::uint8_t* ip = frame_.data();
    ip[0] = 0x45;  // version 4, 5 words of header
    put16(ip + 2, static_cast<std::uint16_t>(total));
    put16(ip + 4, ++id_);
    ip[6] = 0x40;  // don't fragment
    ip[8] = 64;    // time to live
    ip[9] = IPPROTO_UDP;
    std::memcpy(ip + 12, from.address.data(), 4);
    std::memcpy(ip + 16, to.address.data(), 4);
    put16(ip + 10, checksum(ip, ip_size));
    std::uint8_t* udp = ip + ip_size;
    put16(udp + 0, from.port);
    put16(udp + 2, to.port);
    put16(udp + 4, static_cast<std::uint16_t>(udp_size + payload.size()));
    // udp + 6: checksum 0, "none", which IPv4 allows
    std::memcpy(udp + udp_size, payload.data(), payload.size());
    sockaddr_in dest{};
    dest.sin_family = AF_INET;
    std::memcpy(&dest.sin_addr, to.address.data(), 4);
    return ::sendto(fd_, frame_.data(), frame_.size(), 0, reinterpret_cast<sockaddr*>(&dest),
                    sizeof dest) == static_cast<ssize_t>(frame_.size());
  }

 private:
  explicit SpoofSocket(int fd) : fd_(fd) {}
  static void put16(std::uint8_t* at, std::uint16_t v) {
    at[0] = static_cast<std::uint8_t>(v >> 8);
    at[1] = static_cast<std::uint8_t>(v & 0xFF);
  }
  static std::uint16_t checksum(const std::uint8_t* bytes, std::size_t size) {
    std::uint32_t sum = 0;
    for (std::size_t i = 0; i + 1 < size; i += 2)
      sum += static_cast<std::uint32_t>(bytes[i] << 8 | bytes[i + 1]);
    while (sum >> 16)
      sum = (sum & 0xFFFF) + (sum >> 16);
    return static_cast<std::uint16_t>(~sum & 0xFFFF);
  }
  int fd_;
  std::uint16_t id_ = 0;
  Bytes frame_;
};

/// What the third party sends each round, "from" one player's address to the other's.
struct Forgery {
  std::size_t hellos = 4;       ///< plain hellos with the public settings, random ids
  bool replies = true;          ///< a plain reply to a guessed challenge
  bool inputs = true;           ///< plain inputs of its own session, junk for the frames around
  std::size_t sealed = 0;       ///< hellos sealed under a match key of its own
  std::size_t sealed_junk = 0;  ///< random bytes behind a sealed data header
};

/// Builds the third party's datagrams. It knows the match's public settings (fingerprint,
/// players, input size) and the addresses, never a session id, a challenge or the match key.
class Forger {
 public:
  explicit Forger(Forgery what) : what_(what) {}
  void round(std::uint8_t as_player, std::uint64_t n, std::vector<Bytes>& out) {
    for (std::size_t i = 0; i < what_.hellos; ++i) {
      Packet hello;
      hello.header = {PacketType::hello, rng_(), static_cast<std::uint16_t>(rng_())};
      hello.hello = {fingerprint, 2, as_player, input_size, rng_()};
      push(hello, out);
    }
    if (what_.replies) {
      Packet reply;
      reply.header = {PacketType::hello_reply, own_session_, static_cast<std::uint16_t>(n)};
      reply.hello_reply.challenge = rng_();
      push(reply, out);
    }
    if (what_.inputs) {
      Packet input;
      input.header = {PacketType::input, own_session_, static_cast<std::uint16_t>(n)};
      const auto frame = static_cast<std::uint32_t>(n);
      input.input.ack_frame = frame;
      input.input.current_frame = frame;
      input.input.start_frame = frame > 4 ? frame - 4 : 0;
      input.input.held_frame = frame;
      input.input.count = 8;
      input.input.deltas.assign(8 * input_size, 0x5A);
      push(input, out);
    }
    for (std::size_t i = 0; i < what_.sealed; ++i) {
      Packet hello;
      const std::uint64_t session = rng_();
      hello.header = {PacketType::hello, session, 0};
      hello.hello = {fingerprint, 2, as_player, input_size, rng_()};
      Bytes bytes;
      if (!net::protocol::encode_sealed_plaintext(hello, sealed_sequence_, input_size, bytes))
        continue;
      const net::protection::Key key = net::protection::handshake_key(own_key_, session);
      if (net::protection::seal(key, sealed_sequence_++,
                                net::protocol::sealed_handshake_header_size, bytes))
        out.push_back(std::move(bytes));
    }
    for (std::size_t i = 0; i < what_.sealed_junk; ++i) {
      Bytes bytes(40 + rng_() % 40);
      for (std::uint8_t& b : bytes)
        b = static_cast<std::uint8_t>(rng_());
      Packet input;
      input.header = {PacketType::input, 0, 0};
      Bytes header;
      if (net::protocol::encode_sealed_plaintext(input, static_cast<std::uint32_t>(n), input_size,
                                                 header))
        std::copy_n(header.begin(), net::protocol::sealed_data_header_size, bytes.begin());
      out.push_back(std::move(bytes));
    }
  }

 private:
  void push(const Packet& p, std::vector<Bytes>& out) {
    Bytes bytes;
    if (net::protocol::encode(p, input_size, bytes)) out.push_back(std::move(bytes));
  }
  Forgery what_;
  std::mt19937_64 rng_{0x5B00F};
  std::uint64_t own_session_ = 0xA77AC6E5'5E55100DULL;
  net::MatchKey own_key_ = test::test_match_key(99);
  std::uint32_t sealed_sequence_ = 0;
};

/// The input player p gives when its session is at `frame` (queued for frame + input_delay).
std::array<std::uint8_t, input_size> honest_input(std::uint32_t p, std::uint64_t frame) {
  std::array<std::uint8_t, input_size> in{};
  for (std::uint32_t i = 0; i < input_size; ++i)
    in[i] = static_cast<std::uint8_t>((frame * 7 + p * 101 + i * 13) % 251 + 1);  // never 0
  return in;
}

/// One genuine player: a UDP socket on 127.0.0.1, a game, a session, what it confirmed.
struct Player {
  net::UdpTransport transport;
  test::CounterGame game;
  std::optional<net::Session> session;
  std::vector<std::uint64_t> hashes;
  Bytes inputs;  ///< every confirmed frame's inputs, concatenated
  std::vector<net::Event> events;
  std::optional<std::chrono::steady_clock::duration> running_after;
};

struct Outcome {
  bool finished = false;
  std::uint64_t forged_sent = 0;
};

/// Two players over loopback UDP for `frames` frames while the third party sends `what` both
/// ways (each round, both directions) from the other player's address; gives up after 30 s.
class SpoofedMatch {
 public:
  SpoofedMatch(Forgery what, std::optional<net::MatchKey> key, std::uint64_t frames)
      : forger_(what), frames_(frames) {
    for (std::uint32_t p = 0; p < 2; ++p) {
      auto t = net::UdpTransport::open(net::Endpoint::loopback(net::IpFamily::v4, 0), {});
      if (!t) {
        ADD_FAILURE() << t.status().message();
        return;
      }
      players_.push_back(
          std::make_unique<Player>(Player{std::move(t.value()), {}, {}, {}, {}, {}, std::nullopt}));
    }
    for (std::uint32_t p = 0; p < 2; ++p) {
      Player& me = *players_[p];
      const Player& other = *players_[1 - p];
      EXPECT_TRUE(me.transport.add_peer({1 - p, other.transport.local_endpoint()}).ok());
      net::SessionConfig config;
      config.players = 2;
      config.local_player = p;
      config.input_size = input_size;
      config.input_delay = input_delay;
      config.fingerprint = fingerprint;
      config.match_key = key;
      config.remotes.push_back(net::RemotePlayer{1 - p, 1 - p});
      auto s = net::Session::create(config, me.game, me.transport);
      if (!s) {
        ADD_FAILURE() << s.status().message();
        return;
      }
      me.session.emplace(std::move(s.value()));
      me.session->set_confirmed_listener([&me](const net::ConfirmedFrame& f) {
        me.hashes.push_back(f.hash);
        me.inputs.insert(me.inputs.end(), f.inputs.begin(), f.inputs.end());
      });
    }
  }

  Outcome run(SpoofSocket& spoof) {
    Outcome outcome;
    if (players_.size() != 2 || !players_[0]->session || !players_[1]->session) return outcome;
    const auto start = std::chrono::steady_clock::now();
    std::vector<Bytes> forged;
    for (std::uint64_t round = 0;; ++round) {
      const auto elapsed = std::chrono::steady_clock::now() - start;
      if (elapsed > std::chrono::seconds(30)) return outcome;
      for (std::uint32_t victim = 0; victim < 2; ++victim) {
        forged.clear();
        forger_.round(static_cast<std::uint8_t>(1 - victim), round, forged);
        for (const Bytes& b : forged)
          if (spoof.send(players_[1 - victim]->transport.local_endpoint(),
                         players_[victim]->transport.local_endpoint(), b))
            ++outcome.forged_sent;
      }
      const auto now_us = static_cast<std::uint64_t>(
          std::chrono::duration_cast<std::chrono::microseconds>(elapsed).count());
      bool done = true;
      for (std::uint32_t p = 0; p < 2; ++p) {
        Player& me = *players_[p];
        me.session->poll(now_us);
        if (me.session->running() && !me.running_after) me.running_after = elapsed;
        const std::uint64_t frame = me.session->current_frame();
        if (frame < frames_) (void)me.session->advance_frame(honest_input(p, frame));
        for (const net::Event& e : me.session->take_events())
          me.events.push_back(e);
        if (me.hashes.size() < frames_) done = false;
      }
      if (done) {
        outcome.finished = true;
        return outcome;
      }
      std::this_thread::sleep_for(std::chrono::microseconds(500));
    }
  }

  Player& player(std::uint32_t p) { return *players_[p]; }

  /// Empty when both confirmed the same hashes, and every input of every frame they confirmed
  /// is the one its genuine player gave (its first input fills the input delay); else what differs.
  std::string honest() const {
    std::string problems;
    const Player& a = *players_[0];
    const Player& b = *players_[1];
    for (std::uint64_t f = 0; f < frames_; ++f) {
      if (a.hashes[f] != b.hashes[f]) return "hashes differ from frame " + std::to_string(f);
      for (std::uint32_t p = 0; p < 2; ++p) {
        const auto expected = honest_input(p, f >= input_delay ? f - input_delay : 0);
        for (const Player* who : {&a, &b}) {
          const auto at = static_cast<std::ptrdiff_t>((f * 2 + p) * input_size);
          if (!std::equal(expected.begin(), expected.end(), who->inputs.begin() + at))
            return "player " + std::to_string(p) + "'s input of frame " + std::to_string(f) +
                   " is not the one it sent";
        }
      }
    }
    return problems;
  }

 private:
  Forger forger_;
  std::uint64_t frames_;
  std::vector<std::unique_ptr<Player>> players_;
};

bool has_event(const Player& p, net::EventType type) {
  for (const net::Event& e : p.events)
    if (e.type == type) return true;
  return false;
}

#define OPEN_SPOOF_SOCKET(name)       \
  std::string why;                    \
  auto name = SpoofSocket::open(why); \
  if (!name) GTEST_SKIP() << why;

TEST(NetSpoof, ARawSocketDeliversADatagramAsTheGenuinePeers) {
  // The premise of the others: the transport takes a spoofed datagram as player 1's, so only
  // the session stands between it and the match.
  OPEN_SPOOF_SOCKET(spoof);
  auto genuine = net::UdpTransport::open(net::Endpoint::loopback(net::IpFamily::v4, 0), {});
  ASSERT_TRUE(genuine.ok());
  const net::UdpPeer peers[] = {{1, genuine.value().local_endpoint()}};
  auto victim = net::UdpTransport::open(net::Endpoint::loopback(net::IpFamily::v4, 0), peers);
  ASSERT_TRUE(victim.ok());
  const Bytes payload = {'s', 'p', 'o', 'o', 'f'};
  ASSERT_TRUE(
      spoof->send(genuine.value().local_endpoint(), victim.value().local_endpoint(), payload));
  std::vector<net::Datagram> got;
  for (int i = 0; i < 1000 && got.empty(); ++i) {
    victim.value().receive(got);
    if (got.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_EQ(got.size(), 1U) << "the spoofed datagram never arrived";
  EXPECT_EQ(got[0].from, 1U);
  EXPECT_EQ(got[0].bytes, payload);
  EXPECT_EQ(victim.value().stats().dropped_unknown_sender, 0U);
}

TEST(NetSpoof, SpoofedHellosRepliesAndInputsCannotTakeASeatOrInject) {
  // Without a match key: from before the first genuine hello to the end, each player receives,
  // "from" the other's address, hellos with the public settings, replies to guessed challenges
  // and inputs of the attacker's own session. A player learns the other's session id only from
  // the reply to its own challenge, so every forged datagram is dropped.
  OPEN_SPOOF_SOCKET(spoof);
  SpoofedMatch m(Forgery{}, std::nullopt, 600);
  const Outcome o = m.run(*spoof);
  ASSERT_TRUE(o.finished) << "the match did not finish in 30 s";
  EXPECT_GT(o.forged_sent, 2000U);
  EXPECT_EQ(m.honest(), "");
  for (std::uint32_t p = 0; p < 2; ++p) {
    SCOPED_TRACE("player " + std::to_string(p));
    const net::SessionStats& st = m.player(p).session->stats();
    EXPECT_GT(st.dropped_wrong_session, 400U);
    EXPECT_GT(st.checks_compared, 0U);
    EXPECT_EQ(st.checks_missing, 0U);
    EXPECT_FALSE(has_event(m.player(p), net::EventType::hello_rejected));
    EXPECT_FALSE(has_event(m.player(p), net::EventType::desync));
    EXPECT_FALSE(has_event(m.player(p), net::EventType::disconnected));
  }
}

TEST(NetSpoof, AFloodOfSpoofedHellosDoesNotDelayTheStart) {
  // 100 forged hellos each way per round, each answered (to the genuine address) and changing
  // nothing: the genuine handshake still completes at once. Without the flood it takes a round
  // trip on loopback; 2 s is a bound for a loaded machine, not a measurement.
  OPEN_SPOOF_SOCKET(spoof);
  Forgery flood;
  flood.hellos = 100;
  SpoofedMatch m(flood, std::nullopt, 300);
  const Outcome o = m.run(*spoof);
  ASSERT_TRUE(o.finished) << "the match did not finish in 30 s";
  EXPECT_EQ(m.honest(), "");
  for (std::uint32_t p = 0; p < 2; ++p) {
    ASSERT_TRUE(m.player(p).running_after.has_value());
    EXPECT_LT(*m.player(p).running_after, std::chrono::seconds(2)) << "player " << p;
  }
}

TEST(NetSpoof, WithAMatchKeyNothingSpoofedAuthenticates) {
  // Sealed: the same plain forgeries, hellos sealed under another key, and random bytes behind a
  // sealed header. None authenticates; the match is the genuine one. (A plain or foreign-key
  // hello before the handshake may raise one hello_rejected report: a report, nothing more.)
  if (!net::protection::available()) GTEST_SKIP() << "built without libsodium: no match key";
  OPEN_SPOOF_SOCKET(spoof);
  Forgery sealed;
  sealed.sealed = 2;
  sealed.sealed_junk = 2;
  SpoofedMatch m(sealed, test::test_match_key(), 600);
  const Outcome o = m.run(*spoof);
  ASSERT_TRUE(o.finished) << "the match did not finish in 30 s";
  EXPECT_EQ(m.honest(), "");
  for (std::uint32_t p = 0; p < 2; ++p) {
    SCOPED_TRACE("player " + std::to_string(p));
    const net::SessionStats& st = m.player(p).session->stats();
    EXPECT_GT(st.dropped_unauthenticated, 400U);
    EXPECT_GT(st.checks_compared, 0U);
    EXPECT_EQ(st.checks_missing, 0U);
    EXPECT_FALSE(has_event(m.player(p), net::EventType::desync));
    EXPECT_FALSE(has_event(m.player(p), net::EventType::disconnected));
  }
}

}  // namespace
}  // namespace detsim
