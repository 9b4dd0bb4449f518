// UdpTransport and parse_endpoint: real sockets on the loopback interface.
//
// Datagrams on loopback arrive quickly but not instantly on every system, so a test that expects
// one polls receive() with a generous deadline (5 s) and fails with a message if it never comes;
// no test measures time.
#include <detsim/net/udp.hpp>

#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <thread>
#include <tuple>
#include <utility>
#include <vector>

#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

namespace detsim::net {
namespace {

constexpr auto deadline = std::chrono::seconds(5);

std::vector<std::uint8_t> bytes_of(std::string_view text) {
  return {text.begin(), text.end()};
}

Endpoint parsed(std::string_view text) {
  const Expected<Endpoint> e = parse_endpoint(text);
  EXPECT_TRUE(e.ok()) << e.message();
  return e.ok() ? e.value() : Endpoint{};
}

// Opens a transport on the loopback address of `family`, port 0, with no peers, as `name`; fails
// the test (returning from the function) when it cannot.
#define OPEN_LOOPBACK(name, ...)                                     \
  Expected<UdpTransport> name##_opened = open_loopback(__VA_ARGS__); \
  ASSERT_TRUE(name##_opened.ok()) << name##_opened.message();        \
  UdpTransport& name = name##_opened.value()

Expected<UdpTransport> open_loopback(IpFamily family, const UdpOptions& options = {}) {
  return UdpTransport::open(Endpoint::loopback(family, 0), {}, options);
}

bool ipv6_loopback_available(std::string& why) {
  const Expected<UdpTransport> t = UdpTransport::open(Endpoint::loopback(IpFamily::v6, 0), {});
  why = t.message();
  return t.ok();
}

// Calls receive() until `done(received so far)` holds or the deadline passes.
std::vector<Datagram> receive_until(UdpTransport& t,
                                    const std::function<bool(const std::vector<Datagram>&)>& done) {
  std::vector<Datagram> all;
  const auto stop = std::chrono::steady_clock::now() + deadline;
  while (!done(all) && std::chrono::steady_clock::now() < stop) {
    t.receive(all);
    if (!done(all)) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return all;
}

std::vector<Datagram> receive_count(UdpTransport& t, std::size_t count) {
  return receive_until(t, [count](const std::vector<Datagram>& d) { return d.size() >= count; });
}

// Receives until stats() satisfy `done`, discarding datagrams; false if the deadline passed.
bool poll_stats(UdpTransport& t, const std::function<bool(const UdpStats&)>& done) {
  std::vector<Datagram> ignored;
  const auto stop = std::chrono::steady_clock::now() + deadline;
  while (!done(t.stats())) {
    if (std::chrono::steady_clock::now() >= stop) return false;
    t.receive(ignored);
    if (!done(t.stats())) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

// A plain socket bound to loopback port 0, for sending what a UdpTransport refuses to send.
class RawSocket {
 public:
  RawSocket() {
    fd_ = ::socket(AF_INET, SOCK_DGRAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (fd_ < 0 || ::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
      ADD_FAILURE() << "raw socket: cannot bind 127.0.0.1:0";
      return;
    }
    socklen_t length = sizeof a;
    ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &length);
    port_ = ntohs(a.sin_port);
  }
  ~RawSocket() {
    if (fd_ >= 0) ::close(fd_);
  }
  RawSocket(const RawSocket&) = delete;
  RawSocket& operator=(const RawSocket&) = delete;

  Endpoint endpoint() const { return Endpoint::ipv4(127, 0, 0, 1, port_); }
  bool send_to(const Endpoint& to, const std::vector<std::uint8_t>& bytes) const {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = htons(to.port);
    return ::sendto(fd_, bytes.data(), bytes.size(), 0, reinterpret_cast<sockaddr*>(&a),
                    sizeof a) == static_cast<ssize_t>(bytes.size());
  }

 private:
  int fd_ = -1;
  std::uint16_t port_ = 0;
};

// ----------------------------------------------------------------------------------------------
// parse_endpoint

TEST(NetUdpEndpoint, AcceptsNumericAddressesAndPrintsThemCanonically) {
  struct Case {
    std::string_view text;
    std::string_view printed;  // to_string() of the result
  };
  const Case cases[] = {
      {"127.0.0.1:7000", "127.0.0.1:7000"},
      {"0.0.0.0:0", "0.0.0.0:0"},
      {"255.255.255.255:65535", "255.255.255.255:65535"},
      {"10.0.0.1:00080", "10.0.0.1:80"},
      {"[::1]:7000", "[::1]:7000"},
      {"[::]:0", "[::]:0"},
      {"[2001:DB8:0:0:0:0:0:1]:443", "[2001:db8::1]:443"},
      {"[2001:db8:0:1:0:0:0:1]:1", "[2001:db8:0:1::1]:1"},       // the longer zero run is shortened
      {"[2001:db8:0:0:1:0:0:1]:1", "[2001:db8::1:0:0:1]:1"},     // equal runs: the first
      {"[2001:db8:0:1:1:1:1:1]:1", "[2001:db8:0:1:1:1:1:1]:1"},  // a single zero group stays
      {"[::ffff:192.0.2.1]:9", "[::ffff:192.0.2.1]:9"},
      {"[fe80::abcd:ef01]:5", "[fe80::abcd:ef01]:5"},
  };
  for (const Case& c : cases) {
    const Expected<Endpoint> e = parse_endpoint(c.text);
    ASSERT_TRUE(e.ok()) << c.text << ": " << e.message();
    EXPECT_EQ(e.value().to_string(), c.printed) << c.text;
    const Expected<Endpoint> again = parse_endpoint(e.value().to_string());
    ASSERT_TRUE(again.ok()) << again.message();
    EXPECT_EQ(again.value(), e.value()) << "round trip of " << c.text;
  }
  EXPECT_EQ(parsed("127.0.0.1:7000"), Endpoint::ipv4(127, 0, 0, 1, 7000));
  EXPECT_EQ(parsed("[::1]:7000"), Endpoint::loopback(IpFamily::v6, 7000));
  EXPECT_EQ(parsed("[::1]:7000").family, IpFamily::v6);
}

// Endpoints order by family (IPv4 first), then address bytes, then port: the order of the tuple
// (family, address, port), checked against std::tuple's on every pair of a small set.
TEST(NetUdpEndpoint, OrdersByFamilyThenAddressThenPort) {
  std::array<std::uint8_t, 16> low{};
  std::array<std::uint8_t, 16> high{};
  high[0] = 0x20;
  const std::vector<Endpoint> all = {Endpoint::ipv4(10, 0, 0, 1, 7000),
                                     Endpoint::ipv4(10, 0, 0, 1, 7001),
                                     Endpoint::ipv4(10, 0, 0, 2, 1),
                                     Endpoint::ipv4(9, 255, 255, 255, 65535),
                                     Endpoint::ipv6(low, 7000),
                                     Endpoint::ipv6(high, 1),
                                     Endpoint::ipv6(high, 0)};
  for (const Endpoint& a : all) {
    for (const Endpoint& b : all) {
      const auto tuple = [](const Endpoint& e) {
        return std::make_tuple(static_cast<int>(e.family), e.address, e.port);
      };
      EXPECT_EQ(a < b, tuple(a) < tuple(b)) << a.to_string() << " vs " << b.to_string();
      EXPECT_EQ(a == b, tuple(a) == tuple(b)) << a.to_string() << " vs " << b.to_string();
      EXPECT_EQ((a <=> b) == 0, a == b);
    }
  }
}

TEST(NetUdpEndpoint, RejectsMalformedTextNamingTheProblem) {
  struct Case {
    std::string_view text;
    std::string_view problem;  // a part of the message
  };
  const Case cases[] = {
      {"", "empty"},
      {"127.0.0.1", "missing port"},
      {"127.0.0.1:", "missing port"},
      {"127.0.0.1:70000", "port 70000 is out of range 0..65535"},
      {"127.0.0.1:99999999999999999999", "out of range"},
      {"127.0.0.1:-1", "port \"-1\" is not a decimal number"},
      {"127.0.0.1:7a", "not a decimal number"},
      {"127.0.0.1: 7", "not a decimal number"},
      {"256.0.0.1:1", "octet 1 is 256, must be 0..255"},
      {"1.2.3:1", "bad IPv4 address \"1.2.3\""},
      {"1.2.3.4.5:1", "expected four decimal octets"},
      {"1..3.4:1", "expected four decimal octets"},
      {"01.2.3.4:1", "leading zero"},
      {":7000", "bad IPv4 address"},
      {"localhost:80", "host names are not resolved"},
      {"::1:7000", "must be in brackets"},
      {"::1", "must be in brackets"},
      {"[::1]", "missing port"},
      {"[::1]:", "missing port"},
      {"[::1:7000", "missing ']'"},
      {"[::1]7000", "expected ':'"},
      {"[1.2.3.4]:1", "bad IPv6 address \"1.2.3.4\""},
      {"[]:1", "bad IPv6 address"},
      {"[::g]:1", "bad IPv6 address"},
      {"[fe80::1%eth0]:1", "zone IDs"},
      {"[::1]:65536", "out of range"},
  };
  for (const Case& c : cases) {
    const Expected<Endpoint> e = parse_endpoint(c.text);
    ASSERT_FALSE(e.ok()) << "accepted \"" << c.text << "\" as " << e.value().to_string();
    EXPECT_NE(e.message().find("endpoint \"" + std::string(c.text) + "\""), std::string::npos)
        << "message does not name the text: " << e.message();
    EXPECT_NE(e.message().find(c.problem), std::string::npos)
        << "for \"" << c.text << "\" expected \"" << c.problem << "\" in: " << e.message();
  }
}

// ----------------------------------------------------------------------------------------------
// Exchanging datagrams

// Two transports on the loopback address of `family` send to each other both ways.
void exchange_both_ways(IpFamily family) {
  OPEN_LOOPBACK(a, family);
  OPEN_LOOPBACK(b, family);
  ASSERT_NE(a.local_endpoint().port, 0) << "port 0 must be replaced by the bound port";
  ASSERT_NE(a.local_endpoint(), b.local_endpoint());
  ASSERT_TRUE(a.add_peer({7, b.local_endpoint()}).ok());
  ASSERT_TRUE(b.add_peer({3, a.local_endpoint()}).ok());

  a.send(7, bytes_of("hello b"));
  a.send(7, bytes_of("again"));
  const std::vector<Datagram> at_b = receive_count(b, 2);
  ASSERT_EQ(at_b.size(), 2U) << "b received " << at_b.size() << " of 2 datagrams within 5 s";
  EXPECT_EQ(at_b[0].from, 3U);
  EXPECT_EQ(at_b[0].bytes, bytes_of("hello b"));
  EXPECT_EQ(at_b[1].bytes, bytes_of("again"));

  std::vector<std::uint8_t> largest(max_datagram);
  for (std::size_t i = 0; i < largest.size(); ++i)
    largest[i] = static_cast<std::uint8_t>(i * 7);
  b.send(3, largest);
  b.send(3, {});  // an empty datagram is a datagram too
  const std::vector<Datagram> at_a = receive_count(a, 2);
  ASSERT_EQ(at_a.size(), 2U) << "a received " << at_a.size() << " of 2 datagrams within 5 s";
  EXPECT_EQ(at_a[0].from, 7U);
  EXPECT_EQ(at_a[0].bytes, largest);
  EXPECT_TRUE(at_a[1].bytes.empty());

  EXPECT_EQ(a.stats().sent, 2U);
  EXPECT_EQ(a.stats().sent_bytes, 12U);
  EXPECT_EQ(a.stats().received, 2U);
  EXPECT_EQ(a.stats().received_bytes, max_datagram);
  EXPECT_EQ(b.stats().received, 2U);
  EXPECT_EQ(b.stats().send_errors, 0U) << b.last_error();
  EXPECT_TRUE(a.last_error().empty()) << a.last_error();
}

TEST(NetUdpTransport, ExchangesDatagramsOverIpv4Loopback) {
  exchange_both_ways(IpFamily::v4);
}

TEST(NetUdpTransport, ExchangesDatagramsOverIpv6Loopback) {
  std::string why;
  if (!ipv6_loopback_available(why)) GTEST_SKIP() << "IPv6 loopback unavailable: " << why;
  exchange_both_ways(IpFamily::v6);
}

TEST(NetUdpTransport, PeersGivenToOpenAreUsed) {
  OPEN_LOOPBACK(b, IpFamily::v4);
  const UdpPeer peers[] = {{2, b.local_endpoint()}, {1, Endpoint::ipv4(127, 0, 0, 1, 9)}};
  Expected<UdpTransport> a = UdpTransport::open(parsed("127.0.0.1:0"), peers);
  ASSERT_TRUE(a.ok()) << a.message();
  ASSERT_EQ(a.value().peers().size(), 2U);
  EXPECT_EQ(a.value().peers()[0].id, 1U) << "peers() is ascending by PeerId";
  ASSERT_TRUE(b.add_peer({5, a.value().local_endpoint()}).ok());
  a.value().send(2, bytes_of("x"));
  const std::vector<Datagram> got = receive_count(b, 1);
  ASSERT_EQ(got.size(), 1U) << "nothing arrived within 5 s";
  EXPECT_EQ(got[0].from, 5U);
}

TEST(NetUdpTransport, DropsAndCountsDatagramsFromUnknownSenders) {
  OPEN_LOOPBACK(a, IpFamily::v4);
  OPEN_LOOPBACK(b, IpFamily::v4);
  OPEN_LOOPBACK(stranger, IpFamily::v4);
  ASSERT_TRUE(a.add_peer({1, b.local_endpoint()}).ok());
  ASSERT_TRUE(b.add_peer({2, a.local_endpoint()}).ok());
  ASSERT_TRUE(stranger.add_peer({1, b.local_endpoint()}).ok());  // b does not know the stranger

  stranger.send(1, bytes_of("let me in"));
  ASSERT_TRUE(poll_stats(b, [](const UdpStats& s) { return s.dropped_unknown_sender >= 1; }))
      << "the stranger's datagram was never counted";
  // A known peer is still delivered, and the stranger's bytes never were.
  a.send(1, bytes_of("friend"));
  const std::vector<Datagram> got = receive_count(b, 1);
  ASSERT_EQ(got.size(), 1U) << "nothing arrived within 5 s";
  EXPECT_EQ(got[0].from, 2U);
  EXPECT_EQ(got[0].bytes, bytes_of("friend"));
  EXPECT_EQ(b.stats().dropped_unknown_sender, 1U);
  EXPECT_EQ(b.stats().received, 1U);

  // After remove_peer, the same sender is a stranger.
  EXPECT_TRUE(b.remove_peer(2));
  EXPECT_FALSE(b.remove_peer(2));
  a.send(1, bytes_of("forgotten"));
  ASSERT_TRUE(poll_stats(b, [](const UdpStats& s) { return s.dropped_unknown_sender >= 2; }))
      << "a datagram from a removed peer was never counted as unknown";
  EXPECT_EQ(b.stats().received, 1U);
}

TEST(NetUdpTransport, AServerSocketAdmitsUnknownSendersUpToItsLimit) {
  UdpOptions options;
  options.admit_unknown_senders = 2;
  OPEN_LOOPBACK(server, IpFamily::v4, options);
  OPEN_LOOPBACK(c1, IpFamily::v4);
  OPEN_LOOPBACK(c2, IpFamily::v4);
  OPEN_LOOPBACK(c3, IpFamily::v4);
  for (UdpTransport* c : {&c1, &c2, &c3})
    ASSERT_TRUE(c->add_peer({0, server.local_endpoint()}).ok());
  c1.send(0, bytes_of("one"));
  ASSERT_EQ(receive_count(server, 1).size(), 1U);
  c2.send(0, bytes_of("two"));
  const std::vector<Datagram> second = receive_count(server, 1);
  ASSERT_EQ(second.size(), 1U);
  // Registered in arrival order, from first_admitted_peer up, and answerable.
  EXPECT_EQ(second[0].from, first_admitted_peer + 1);
  ASSERT_EQ(server.peers().size(), 2U);
  EXPECT_EQ(server.peers()[0].endpoint, c1.local_endpoint());
  server.send(first_admitted_peer, bytes_of("hello one"));
  const std::vector<Datagram> answer = receive_count(c1, 1);
  ASSERT_EQ(answer.size(), 1U);
  EXPECT_EQ(answer[0].bytes, bytes_of("hello one"));
  // The limit is reached: a third stranger is dropped, until the program frees a peer.
  c3.send(0, bytes_of("three"));
  ASSERT_TRUE(poll_stats(server, [](const UdpStats& s) { return s.dropped_unknown_sender >= 1; }));
  EXPECT_EQ(server.admitted_peers(), 2U);
  EXPECT_TRUE(server.remove_peer(first_admitted_peer));
  c3.send(0, bytes_of("three again"));
  const std::vector<Datagram> third = receive_count(server, 1);
  ASSERT_EQ(third.size(), 1U);
  EXPECT_EQ(third[0].from, first_admitted_peer + 2);
  EXPECT_EQ(server.stats().admitted_senders, 3U);
}

TEST(NetUdpTransport, DropsAndCountsOversizeDatagrams) {
  OPEN_LOOPBACK(b, IpFamily::v4);
  const RawSocket raw;
  ASSERT_TRUE(b.add_peer({9, raw.endpoint()}).ok());
  ASSERT_TRUE(raw.send_to(b.local_endpoint(), std::vector<std::uint8_t>(max_datagram + 1, 0xAB)));
  ASSERT_TRUE(raw.send_to(b.local_endpoint(), std::vector<std::uint8_t>(4000, 0xCD)));
  ASSERT_TRUE(raw.send_to(b.local_endpoint(), std::vector<std::uint8_t>(max_datagram, 0xEF)));
  const std::vector<Datagram> got = receive_until(b, [&](const std::vector<Datagram>& d) {
    return !d.empty() && b.stats().dropped_oversize >= 2;
  });
  EXPECT_EQ(b.stats().dropped_oversize, 2U);
  ASSERT_EQ(got.size(), 1U) << "exactly max_datagram bytes must be delivered";
  EXPECT_EQ(got[0].from, 9U);
  EXPECT_EQ(got[0].bytes, std::vector<std::uint8_t>(max_datagram, 0xEF));
}

TEST(NetUdpTransport, CountsSendsToUnknownPeersAndOversizeSends) {
  OPEN_LOOPBACK(a, IpFamily::v4);
  OPEN_LOOPBACK(b, IpFamily::v4);
  ASSERT_TRUE(a.add_peer({1, b.local_endpoint()}).ok());
  a.send(2, bytes_of("nobody"));
  a.send(1, std::vector<std::uint8_t>(max_datagram + 1, 1));
  EXPECT_EQ(a.stats().dropped_unknown_peer, 1U);
  EXPECT_EQ(a.stats().dropped_oversize_send, 1U);
  EXPECT_EQ(a.stats().sent, 0U);
  EXPECT_EQ(a.stats().sent_bytes, 0U);
}

TEST(NetUdpTransport, ReceiveWithNothingPendingReturnsAtOnceAndAppends) {
  OPEN_LOOPBACK(a, IpFamily::v4);
  std::vector<Datagram> out(1);
  out[0].from = 42;
  a.receive(out);  // a blocking socket would hang here and the test would time out
  ASSERT_EQ(out.size(), 1U) << "receive() must append, not replace";
  EXPECT_EQ(out[0].from, 42U);
  EXPECT_EQ(a.stats(), UdpStats{});
}

TEST(NetUdpTransport, ReceiveReadsAtMostTheConfiguredNumberPerCall) {
  UdpOptions options;
  options.max_datagrams_per_receive = 3;
  OPEN_LOOPBACK(a, IpFamily::v4);
  OPEN_LOOPBACK(b, IpFamily::v4, options);
  ASSERT_TRUE(a.add_peer({1, b.local_endpoint()}).ok());
  ASSERT_TRUE(b.add_peer({2, a.local_endpoint()}).ok());
  for (int i = 0; i < 10; ++i)
    a.send(1, std::vector<std::uint8_t>{static_cast<std::uint8_t>(i)});
  std::vector<Datagram> all;
  const auto stop = std::chrono::steady_clock::now() + deadline;
  while (all.size() < 10 && std::chrono::steady_clock::now() < stop) {
    const std::size_t before = all.size();
    b.receive(all);
    ASSERT_LE(all.size() - before, 3U) << "one receive() read more than the limit";
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_EQ(all.size(), 10U) << "received " << all.size() << " of 10 within 5 s";
  for (std::size_t i = 0; i < all.size(); ++i) {
    EXPECT_EQ(all[i].bytes, std::vector<std::uint8_t>{static_cast<std::uint8_t>(i)})
        << "loopback keeps order";
  }
}

TEST(NetUdpTransport, MovedTransportKeepsWorkingAndTheSourceIsClosed) {
  OPEN_LOOPBACK(a, IpFamily::v4);
  OPEN_LOOPBACK(b, IpFamily::v4);
  ASSERT_TRUE(a.add_peer({1, b.local_endpoint()}).ok());
  ASSERT_TRUE(b.add_peer({2, a.local_endpoint()}).ok());
  const Endpoint a_endpoint = a.local_endpoint();

  UdpTransport moved(std::move(a));
  EXPECT_EQ(moved.local_endpoint(), a_endpoint);
  EXPECT_FALSE(a.is_open());  // NOLINT(bugprone-use-after-move): the documented moved-from state
  a.send(1, bytes_of("from the husk"));
  EXPECT_EQ(a.stats().send_errors, 1U);
  std::vector<Datagram> none;
  a.receive(none);
  EXPECT_TRUE(none.empty());

  moved.send(1, bytes_of("moved"));
  std::vector<Datagram> got = receive_count(b, 1);
  ASSERT_EQ(got.size(), 1U) << "nothing arrived within 5 s";
  EXPECT_EQ(got[0].from, 2U);
  EXPECT_EQ(got[0].bytes, bytes_of("moved"));

  // Move assignment closes the target's own socket and takes the source's.
  OPEN_LOOPBACK(assigned, IpFamily::v4);
  assigned = std::move(b);
  moved.send(1, bytes_of("assigned"));
  got = receive_count(assigned, 1);
  ASSERT_EQ(got.size(), 1U) << "nothing arrived within 5 s";
  EXPECT_EQ(got[0].bytes, bytes_of("assigned"));

  // The moved-into transport still owns a bound port: a second bind to it fails.
  const Expected<UdpTransport> again = UdpTransport::open(a_endpoint, {});
  EXPECT_FALSE(again.ok()) << "the moved socket was closed";
}

TEST(NetUdpTransport, ClosingReleasesThePort) {
  Endpoint was;
  {
    OPEN_LOOPBACK(a, IpFamily::v4);
    was = a.local_endpoint();
    OPEN_LOOPBACK(b, IpFamily::v4);
    const Endpoint b_endpoint = b.local_endpoint();
    b = std::move(a);  // closes b's own socket
    const Expected<UdpTransport> reopened = UdpTransport::open(b_endpoint, {});
    EXPECT_TRUE(reopened.ok()) << "move assignment left the old socket open: "
                               << reopened.message();
  }
  const Expected<UdpTransport> reopened = UdpTransport::open(was, {});
  EXPECT_TRUE(reopened.ok()) << "the destructor left the socket open: " << reopened.message();
}

TEST(NetUdpTransport, Ipv6SocketsAreIpv6OnlySoBothFamiliesCanShareAPort) {
  std::string why;
  if (!ipv6_loopback_available(why)) GTEST_SKIP() << "IPv6 loopback unavailable: " << why;
  const Expected<UdpTransport> six = UdpTransport::open(parsed("[::]:0"), {});
  ASSERT_TRUE(six.ok()) << six.message();
  // Without IPV6_V6ONLY the IPv6 wildcard socket would also hold the IPv4 port on Linux.
  Endpoint four = parsed("0.0.0.0:0");
  four.port = six.value().local_endpoint().port;
  const Expected<UdpTransport> t = UdpTransport::open(four, {});
  EXPECT_TRUE(t.ok()) << t.message();
}

TEST(NetUdpTransport, Ipv4EndpointsAreNormalised) {
  OPEN_LOOPBACK(a, IpFamily::v4);
  Endpoint noisy = Endpoint::ipv4(127, 0, 0, 1, 7000);
  noisy.address[9] = 0x55;  // bytes 4..15 of an IPv4 endpoint carry nothing
  ASSERT_TRUE(a.add_peer({1, noisy}).ok());
  ASSERT_EQ(a.peers().size(), 1U);
  EXPECT_EQ(a.peers()[0].endpoint, Endpoint::ipv4(127, 0, 0, 1, 7000));
  EXPECT_FALSE(a.add_peer({2, Endpoint::ipv4(127, 0, 0, 1, 7000)}).ok())
      << "the same address must be recognised as a duplicate";
}

// ----------------------------------------------------------------------------------------------
// Errors from open() and add_peer()

TEST(NetUdpTransport, BindingAPortInUseNamesTheAddress) {
  OPEN_LOOPBACK(first, IpFamily::v4);
  const Expected<UdpTransport> second = UdpTransport::open(first.local_endpoint(), {});
  ASSERT_FALSE(second.ok()) << "two sockets bound to " << first.local_endpoint().to_string();
  EXPECT_NE(second.message().find("bind " + first.local_endpoint().to_string()), std::string::npos)
      << second.message();
}

TEST(NetUdpTransport, RejectsPeersOfTheOtherFamily) {
  const UdpPeer v6_peer[] = {{1, parsed("[::1]:7000")}};
  const Expected<UdpTransport> t = UdpTransport::open(parsed("127.0.0.1:0"), v6_peer);
  ASSERT_FALSE(t.ok());
  EXPECT_NE(t.message().find("peer 1 ([::1]:7000): is IPv6 but the transport is bound to IPv4"),
            std::string::npos)
      << t.message();

  std::string why;
  if (!ipv6_loopback_available(why)) GTEST_SKIP() << "IPv6 loopback unavailable: " << why;
  OPEN_LOOPBACK(six, IpFamily::v6);
  const Status s = six.add_peer({2, parsed("127.0.0.1:7000")});
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("is IPv4 but the transport is bound to IPv6"), std::string::npos)
      << s.message();
  const Status mapped = six.add_peer({3, parsed("[::ffff:127.0.0.1]:7000")});
  ASSERT_FALSE(mapped.ok());
  EXPECT_NE(mapped.message().find("IPv4-mapped"), std::string::npos) << mapped.message();
  EXPECT_TRUE(six.peers().empty()) << "a rejected peer must not be registered";
}

TEST(NetUdpTransport, RejectsDuplicateAndUnreachablePeers) {
  struct Case {
    std::vector<UdpPeer> peers;
    std::string_view problem;
  };
  const Endpoint x = Endpoint::ipv4(127, 0, 0, 1, 7001);
  const Endpoint y = Endpoint::ipv4(127, 0, 0, 1, 7002);
  const Case cases[] = {
      {{{1, x}, {1, y}}, "peer 1 (127.0.0.1:7002): PeerId 1 is already 127.0.0.1:7001"},
      {{{1, x}, {2, x}}, "peer 2 (127.0.0.1:7001): endpoint already belongs to peer 1"},
      {{{1, Endpoint::ipv4(127, 0, 0, 1, 0)}}, "port 0 cannot be sent to"},
      {{{1, Endpoint::ipv4(0, 0, 0, 0, 7000)}}, "the unspecified address cannot be sent to"},
  };
  for (const Case& c : cases) {
    const Expected<UdpTransport> t = UdpTransport::open(parsed("127.0.0.1:0"), c.peers);
    ASSERT_FALSE(t.ok()) << "expected: " << c.problem;
    EXPECT_NE(t.message().find(c.problem), std::string::npos) << t.message();
    EXPECT_EQ(t.message().rfind("open 127.0.0.1:0: ", 0), 0U) << t.message();
  }

  // add_peer leaves the transport unchanged on error.
  OPEN_LOOPBACK(a, IpFamily::v4);
  ASSERT_TRUE(a.add_peer({1, x}).ok());
  EXPECT_FALSE(a.add_peer({1, y}).ok());
  EXPECT_FALSE(a.add_peer({2, x}).ok());
  ASSERT_EQ(a.peers().size(), 1U);
  EXPECT_EQ(a.peers()[0], (UdpPeer{1, x}));
}

TEST(NetUdpTransport, RejectsAZeroReceiveLimit) {
  UdpOptions options;
  options.max_datagrams_per_receive = 0;
  const Expected<UdpTransport> t = UdpTransport::open(parsed("127.0.0.1:0"), {}, options);
  ASSERT_FALSE(t.ok());
  EXPECT_NE(t.message().find("max_datagrams_per_receive"), std::string::npos) << t.message();
}

}  // namespace
}  // namespace detsim::net
