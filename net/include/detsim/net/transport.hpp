// detsim::net::Transport: how a session sends and receives datagrams. Sessions never open sockets
// themselves: a game passes a transport (UdpTransport, SimNetwork's endpoints, or its own over
// Steam, WebRTC or a relay) and the session only calls send() and receive().
//
// A transport is unreliable by contract: datagrams may be lost, duplicated, reordered or corrupted
// and may come from anyone. The session's protocol (<detsim/net/protocol.hpp>) validates every byte
// and resends what matters; a transport only has to deliver whole datagrams or nothing.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace detsim::net {

/// A remote endpoint as the game and its transport name it: for sessions, usually the remote
/// player's index; the transport maps it to an address. Chosen by the game, never by the network.
using PeerId = std::uint32_t;

/// The largest datagram a session sends or a transport delivers: below the IPv6 minimum MTU
/// (1280) minus IP and UDP headers, so no datagram is ever fragmented.
inline constexpr std::size_t max_datagram = 1200;

/// One received datagram.
struct Datagram {
  PeerId from = 0;
  std::vector<std::uint8_t> bytes;
};

class Transport {
 public:
  virtual ~Transport() = default;
  Transport() = default;
  Transport(const Transport&) = delete;
  Transport& operator=(const Transport&) = delete;

  /// Sends one datagram of at most max_datagram bytes to `to`, best effort: never blocks, never
  /// throws; a datagram that cannot be sent (unknown peer, too long, a full socket buffer) is
  /// dropped and counted by the transport.
  virtual void send(PeerId to, std::span<const std::uint8_t> bytes) = 0;

  /// Appends every datagram received since the last call to `out`, in arrival order. Datagrams
  /// from senders the transport does not know, or longer than max_datagram, are dropped and
  /// counted, never delivered. Never blocks.
  virtual void receive(std::vector<Datagram>& out) = 0;
};

}  // namespace detsim::net
