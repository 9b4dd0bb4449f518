// detsim::net::UdpTransport: the Transport over one non-blocking UDP socket, IPv4 or IPv6.
//
// A transport knows its peers by address: the game gives it the PeerId and the endpoint of every
// remote player (UdpPeer), and a datagram is delivered only when its source address and port match
// a known peer exactly. Everything else is dropped and counted in UdpStats, never delivered:
// datagrams from strangers, datagrams longer than max_datagram, sends to unknown peers. Socket
// errors are counted too (and the latest is kept as text); nothing throws and nothing blocks.
//
// Addresses are numeric only: parse_endpoint never resolves names (no DNS), so parsing is fast,
// cannot hang and gives the same answer on every machine. An IPv6 transport sets IPV6_V6ONLY and
// talks to IPv6 peers only, the same on every OS; use an IPv4 transport for IPv4 peers.
//
// Typical use:
//
//   auto bind = parse_endpoint("0.0.0.0:7000");
//   auto peer = parse_endpoint("192.0.2.10:7000");
//   if (!bind || !peer) { report(bind ? peer.message() : bind.message()); return; }
//   const UdpPeer peers[] = {{1, peer.value()}};
//   auto udp = UdpTransport::open(bind.value(), peers);
//   if (!udp) { report(udp.message()); return; }   // "bind 0.0.0.0:7000: Address already in use"
//   Transport& transport = udp.value();              // what a session sends and receives through
#pragma once

#include <array>
#include <compare>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <detsim/core/status.hpp>
#include <detsim/net/transport.hpp>

namespace detsim::net {

/// The address family of an endpoint and of the socket a transport opens.
enum class IpFamily : std::uint8_t {
  v4 = 4,
  v6 = 6,
};

/// A numeric UDP address and port. Plain data: comparable, ordered (family, address, port) and
/// printable; it never holds a host name.
struct Endpoint {
  IpFamily family = IpFamily::v4;
  /// Network byte order. IPv4 uses bytes 0..3 and keeps bytes 4..15 zero (the factories and
  /// parse_endpoint do; a transport zeroes them in the endpoints it is given).
  std::array<std::uint8_t, 16> address{};
  std::uint16_t port = 0;  ///< host byte order; 0 in a bind endpoint means "any free port"

  /// a.b.c.d:port
  [[nodiscard]] static constexpr Endpoint ipv4(std::uint8_t a, std::uint8_t b, std::uint8_t c,
                                               std::uint8_t d, std::uint16_t port) noexcept {
    Endpoint e;
    e.family = IpFamily::v4;
    e.address[0] = a;
    e.address[1] = b;
    e.address[2] = c;
    e.address[3] = d;
    e.port = port;
    return e;
  }
  /// [address]:port, the 16 bytes in network order.
  [[nodiscard]] static constexpr Endpoint ipv6(const std::array<std::uint8_t, 16>& address,
                                               std::uint16_t port) noexcept {
    Endpoint e;
    e.family = IpFamily::v6;
    e.address = address;
    e.port = port;
    return e;
  }
  /// 127.0.0.1:port and [::1]:port.
  [[nodiscard]] static constexpr Endpoint loopback(IpFamily family, std::uint16_t port) noexcept {
    if (family == IpFamily::v4) return ipv4(127, 0, 0, 1, port);
    std::array<std::uint8_t, 16> one{};
    one[15] = 1;
    return ipv6(one, port);
  }

  /// "127.0.0.1:7000" or "[2001:db8::1]:7000": IPv6 in the RFC 5952 canonical form (lower case,
  /// the longest run of two or more zero groups shortened to "::"), identical on every OS.
  /// parse_endpoint(e.to_string()) == e.
  [[nodiscard]] std::string to_string() const;

  /// Written out rather than defaulted: a defaulted one needs std::array's operator<=>, which
  /// some standard libraries lack (Emscripten 3.1.6's libc++ deletes it).
  friend constexpr std::strong_ordering operator<=>(const Endpoint& a, const Endpoint& b) noexcept {
    if (a.family != b.family)
      return static_cast<int>(a.family) < static_cast<int>(b.family)
                 ? std::strong_ordering::less
                 : std::strong_ordering::greater;
    for (std::size_t i = 0; i < a.address.size(); ++i)
      if (a.address[i] != b.address[i])
        return a.address[i] < b.address[i] ? std::strong_ordering::less
                                           : std::strong_ordering::greater;
    return a.port <=> b.port;
  }
  friend constexpr bool operator==(const Endpoint&, const Endpoint&) noexcept = default;
};

/// Parses "a.b.c.d:port" or "[ipv6]:port", numeric only, port 0..65535. IPv4 is four decimal
/// octets 0..255 without leading zeros ("010" could mean 8 or 10, so it is refused). IPv6 is any
/// form inet_pton accepts, in brackets; zone IDs ("%eth0") are refused. The error names the text
/// and the problem, e.g. `endpoint "::1:7000": an IPv6 address must be in brackets, e.g.
/// [::1]:7000`.
[[nodiscard]] Expected<Endpoint> parse_endpoint(std::string_view text);

/// A remote player as the transport knows it.
struct UdpPeer {
  PeerId id = 0;
  Endpoint endpoint;

  friend bool operator==(const UdpPeer&, const UdpPeer&) noexcept = default;
};

/// Counters since open(); they only grow. A datagram is counted in exactly one of: sent,
/// dropped_unknown_peer, dropped_oversize_send, send_errors (on the sending side); received,
/// dropped_unknown_sender, dropped_oversize (on the receiving side).
struct UdpStats {
  std::uint64_t sent = 0;                   ///< datagrams the OS accepted
  std::uint64_t sent_bytes = 0;             ///< their payload bytes (no IP/UDP headers)
  std::uint64_t dropped_unknown_peer = 0;   ///< send() to a PeerId the transport does not know
  std::uint64_t dropped_oversize_send = 0;  ///< send() of more than max_datagram bytes
  std::uint64_t send_errors = 0;  ///< sendto failed (full buffer, unreachable, closed socket ...)
  std::uint64_t received = 0;     ///< datagrams delivered by receive()
  std::uint64_t received_bytes = 0;
  std::uint64_t dropped_unknown_sender = 0;  ///< from an address and port that is no peer
  std::uint64_t admitted_senders = 0;        ///< unknown senders registered (admit_unknown_senders)
  std::uint64_t dropped_oversize = 0;        ///< longer than max_datagram
  std::uint64_t receive_errors = 0;          ///< recvfrom failed with anything but "no more data"

  friend bool operator==(const UdpStats&, const UdpStats&) noexcept = default;
};

/// Socket settings with defaults that suit a game; recordable plain data.
struct UdpOptions {
  /// receive() reads at most this many datagrams per call (delivered and dropped together), so a
  /// flood cannot keep the caller inside receive(); the rest wait for the next call. >= 1.
  std::size_t max_datagrams_per_receive = 1024;
  /// SO_RCVBUF and SO_SNDBUF in bytes; 0 keeps the OS default. The OS may round or cap it.
  std::uint32_t socket_buffer_bytes = 0;
  /// A server's socket: a datagram from an unknown sender registers it as a new peer (PeerIds
  /// from first_admitted_peer up, in arrival order), until this many are registered that way;
  /// beyond that, unknown senders are dropped as usual. 0: none (every peer is registered by
  /// the program). The program frees the ones it is done with (remove_peer): a game server the
  /// peers that are not, or no longer, its clients.
  std::uint32_t admit_unknown_senders = 0;
};

/// The first PeerId an admitting transport gives an unknown sender (UdpOptions): far above the
/// small ids programs choose for the peers they register themselves.
inline constexpr PeerId first_admitted_peer = 0x8000'0000U;

class UdpTransport final : public Transport {
 public:
  /// Opens a UDP socket bound to `bind` (port 0: the OS picks one, see local_endpoint()),
  /// non-blocking and close-on-exec, IPV6_V6ONLY for IPv6, and registers `peers`. No
  /// SO_REUSEADDR: a port in use is an error. Errors name the endpoint and the OS's reason
  /// ("bind 127.0.0.1:7000: Address already in use"), or the peer that is rejected: another
  /// family than `bind`, a duplicate PeerId or endpoint, port 0, an unspecified address (0.0.0.0,
  /// ::), or an IPv4-mapped IPv6 address (unreachable from a V6ONLY socket).
  [[nodiscard]] static Expected<UdpTransport> open(const Endpoint& bind,
                                                   std::span<const UdpPeer> peers,
                                                   const UdpOptions& options = {});

  /// Moving transfers the socket; the moved-from transport is closed: its send() counts a
  /// send_error, its receive() delivers nothing.
  UdpTransport(UdpTransport&& other) noexcept;
  UdpTransport& operator=(UdpTransport&& other) noexcept;
  ~UdpTransport() override;  ///< closes the socket

  /// Sends one datagram to the peer's endpoint without blocking. Unknown peer, more than
  /// max_datagram bytes, or a failing sendto (EAGAIN when the socket buffer is full, ECONNREFUSED
  /// after an ICMP error, ...): the datagram is dropped and counted. An empty datagram is sent.
  void send(PeerId to, std::span<const std::uint8_t> bytes) override;

  /// Appends to `out`, in arrival order, the datagrams waiting on the socket, reading until the
  /// socket has no more or max_datagrams_per_receive have been read. A sender is mapped to its
  /// PeerId by exact address and port; unknown senders and datagrams longer than max_datagram
  /// are dropped and counted. Returns at once when nothing is waiting.
  void receive(std::vector<Datagram>& out) override;

  /// Registers one more peer, with the same checks as open(); the transport is unchanged on error.
  /// Useful when ports are learned after binding port 0.
  Status add_peer(const UdpPeer& peer);
  /// Forgets a peer; its later datagrams are dropped as unknown. False if `id` was not known.
  bool remove_peer(PeerId id);
  /// How many registered peers have PeerIds at or above first_admitted_peer: those the transport
  /// registered itself (UdpOptions::admit_unknown_senders) and still holds.
  [[nodiscard]] std::size_t admitted_peers() const noexcept;
  /// The registered peers, ascending by PeerId.
  [[nodiscard]] const std::vector<UdpPeer>& peers() const noexcept { return peers_by_id_; }

  /// The bound address and the actual port (the OS's choice when bound to port 0).
  [[nodiscard]] const Endpoint& local_endpoint() const noexcept { return local_; }
  [[nodiscard]] const UdpStats& stats() const noexcept { return stats_; }
  /// The most recent socket error as text ("sendto 127.0.0.1:7001: Connection refused"); empty
  /// when none happened.
  [[nodiscard]] const std::string& last_error() const noexcept { return last_error_; }
  /// False after the transport was moved from.
  [[nodiscard]] bool is_open() const noexcept { return socket_ >= 0; }

 private:
  UdpTransport(int socket, const Endpoint& local, const UdpOptions& options) noexcept;
  void close_socket() noexcept;
  [[nodiscard]] const UdpPeer* find_peer(PeerId id) const noexcept;
  [[nodiscard]] const UdpPeer* find_peer(const Endpoint& endpoint) const noexcept;

  int socket_ = -1;  // a POSIX file descriptor; -1 when closed
  Endpoint local_;
  UdpOptions options_;
  std::vector<UdpPeer> peers_by_id_;        // ascending PeerId: lookup for send()
  std::vector<UdpPeer> peers_by_endpoint_;  // ascending Endpoint: lookup for receive()
  std::vector<std::uint8_t> buffer_;        // max_datagram + 1 bytes: a longer read is oversize
  PeerId next_admitted_ = first_admitted_peer;
  UdpStats stats_;
  std::string last_error_;
};

}  // namespace detsim::net
