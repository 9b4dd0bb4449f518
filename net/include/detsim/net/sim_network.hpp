// detsim::net::SimNetwork: a seeded, deterministic network of N nodes in one process, for tests,
// sync tests under bad conditions and reproducible bug reports.
//
// Each node has an endpoint (a Transport) that a session uses exactly as it would a UdpTransport.
// Every direction of every link has its own LinkConditions: latency, jitter, loss, duplication,
// reordering and a bandwidth cap with a bounded queue; nodes can be cut off for windows of time
// (outages). Time is virtual: nothing is delivered until the test moves the clock with
// advance_to(), so a test controls time exactly and never sleeps.
//
// Determinism: the same seed and the same sequence of calls (create, set_link, add_outage, send,
// advance_to, receive) give the same deliveries bit for bit on every machine. Each direction of
// each link draws from its own Rng (xoshiro256**), seeded from the network's seed and the two node
// IDs, so traffic on one link never changes what happens on another. Datagrams arrive in the order
// (arrival time, global send sequence number): ties between senders are broken by which send()
// came first, never by an address or a hash.
//
// Per datagram, send() decides in this order, drawing random numbers only for enabled features:
//   1. invalid (unknown destination, the sender itself, more than max_datagram bytes): dropped;
//   2. sender or destination in an outage now: dropped;
//   3. bandwidth: the datagram waits for the link (tail-dropped if it would wait more than
//      max_queue_us), then occupies it for size / bandwidth;
//   4. loss: one draw, below(1'000'000) < loss_ppm;
//   5. duplication: one draw, below(1'000'000) < duplicate_ppm gives a second copy;
//   6. per copy: delay = range(latency - jitter, latency + jitter) clamped at 0 (one draw if
//      jitter > 0), plus reorder_delay_us if below(1'000'000) < reorder_ppm (one draw if
//      reorder_ppm > 0); arrival = end of transmission + delay;
//   7. a copy beyond max_in_flight datagrams in the whole network is dropped.
// On delivery, a copy whose arrival time falls in an outage of its destination is dropped, even
// when the outage was added after the send.
//
// Typical use:
//
//   auto net = SimNetwork::create(2, /*seed=*/42, {.latency_us = 30'000, .loss_ppm = 20'000});
//   if (!net) { report(net.message()); return; }
//   Transport& a = net.value().endpoint(0);  // give each to its side: Session::create(.., a)
//   Transport& b = net.value().endpoint(1);
//   for (std::uint64_t t = 0; t < 10'000'000; t += 1'000) {
//     net.value().advance_to(t);  // delivers what is due by virtual time t
//     session_a.poll(t);          // each side reads its endpoint, on the same clock
//     session_b.poll(t);
//   }
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

#include <detsim/core/status.hpp>
#include <detsim/net/transport.hpp>

namespace detsim::net {

/// One direction of one link. Integers only; plain data with defaults (a perfect link).
struct LinkConditions {
  /// Base one-way delay in microseconds.
  std::uint32_t latency_us = 0;
  /// Each copy's delay is uniform in [latency_us - jitter_us, latency_us + jitter_us], clamped at
  /// 0, drawn independently per copy: jitter alone reorders datagrams sent closer together than
  /// the spread.
  std::uint32_t jitter_us = 0;
  /// Probability, in parts per million (0 .. 1'000'000), that a datagram is lost.
  std::uint32_t loss_ppm = 0;
  /// Probability (ppm) that a datagram arrives twice; the copy gets its own delay and reorder draw.
  std::uint32_t duplicate_ppm = 0;
  /// Probability (ppm) that a copy is held back an extra reorder_delay_us, so that datagrams sent
  /// after it overtake it.
  std::uint32_t reorder_ppm = 0;
  /// The extra delay of a reordered copy, in microseconds. The default is a little more than one
  /// frame at 60 Hz, so a held-back datagram is overtaken by the next frame's.
  std::uint32_t reorder_delay_us = 20'000;
  /// Payload bytes per second the link carries (no IP/UDP header overhead); 0 means unlimited,
  /// otherwise 1 .. 10^15. A datagram occupies the link for size * 10^6 / bandwidth microseconds,
  /// kept exactly (no rounding drift over many datagrams); datagrams queue behind each other.
  std::uint64_t bandwidth_bytes_per_s = 0;
  /// With a bandwidth cap: a datagram that would wait longer than this before it starts to
  /// transmit is tail-dropped (counted in dropped_queue). 0 drops every datagram that would wait.
  std::uint32_t max_queue_us = 250'000;

  friend constexpr bool operator==(const LinkConditions&, const LinkConditions&) noexcept = default;
};

/// A node's counters since create(); they only grow. Send-side counters are kept by the sender,
/// delivered/delivered_bytes by the receiver. Over the whole network,
///   sum(sent + duplicated) == sum(delivered + lost + dropped_invalid + dropped_outage +
///                                 dropped_queue + dropped_capacity) + in_flight().
/// An ordinary bad internet link, one direction: 50 ms (100 ms round trip) +- 20 ms jitter, 1%
/// duplication and reordering, and `loss_ppm` loss (default 5%). What detsim's network tests, the
/// benchmarks and `detsim demo` play over.
constexpr LinkConditions internet_link(std::uint32_t loss_ppm = 50'000) noexcept {
  LinkConditions link;
  link.latency_us = 50'000;
  link.jitter_us = 20'000;
  link.loss_ppm = loss_ppm;
  link.duplicate_ppm = 10'000;
  link.reorder_ppm = 10'000;
  return link;
}

struct NodeStats {
  std::uint64_t sent = 0;        ///< send() calls, valid or not
  std::uint64_t sent_bytes = 0;  ///< their payload bytes
  std::uint64_t delivered = 0;   ///< copies handed out by this node's receive()
  std::uint64_t delivered_bytes = 0;
  std::uint64_t lost = 0;              ///< dropped by the loss draw
  std::uint64_t duplicated = 0;        ///< extra copies created by the duplicate draw
  std::uint64_t reordered = 0;         ///< copies held back by reorder_delay_us
  std::uint64_t dropped_invalid = 0;   ///< unknown destination, to itself, or oversize
  std::uint64_t dropped_outage = 0;    ///< sent during an outage, or arriving during one
  std::uint64_t dropped_queue = 0;     ///< tail-dropped by a bandwidth-capped link
  std::uint64_t dropped_capacity = 0;  ///< the network already held max_in_flight copies

  friend constexpr bool operator==(const NodeStats&, const NodeStats&) noexcept = default;
};

class SimNetwork {
 public:
  /// The most nodes a network has.
  static constexpr std::uint32_t max_nodes = 256;
  /// The most datagram copies held at once (in flight or arrived but not yet received), over the
  /// whole network: with max_datagram bytes each, at most ~80 MB. Beyond it copies are dropped
  /// and counted in dropped_capacity. Link state grows with the links used (at most
  /// max_nodes^2 entries of ~100 bytes) and outages are capped by max_outages_per_node.
  static constexpr std::size_t max_in_flight = 65'536;
  /// The most outages one node may have.
  static constexpr std::size_t max_outages_per_node = 1'024;

  /// A network of `nodes` nodes (IDs 0 .. nodes - 1, 1 <= nodes <= max_nodes), every link in
  /// both directions with `all_links`, the clock at 0. Errors name the field and its value
  /// ("all_links: loss_ppm must be at most 1000000, got 1000001").
  [[nodiscard]] static Expected<SimNetwork> create(std::uint32_t nodes, std::uint64_t seed,
                                                   const LinkConditions& all_links = {});

  /// Moving keeps every endpoint valid: endpoint references taken before the move keep working
  /// with the moved-to network. A moved-from network may only be destroyed or assigned to.
  SimNetwork(SimNetwork&&) noexcept;
  SimNetwork& operator=(SimNetwork&&) noexcept;
  ~SimNetwork();

  /// Sets the conditions of the direction from -> to, for datagrams sent from now on (copies
  /// already in flight keep their arrival times; the link's queue and random stream continue).
  /// Unknown node, from == to, or invalid conditions: an error naming them, and nothing changes.
  Status set_link(PeerId from, PeerId to, const LinkConditions& conditions);

  /// Cuts `node` off during [start_us, end_us) in both directions: datagrams it sends, datagrams
  /// sent to it, and datagrams that would arrive at it in that window are dropped. Datagrams it
  /// sent before the window are still delivered to the others. Windows may overlap and may lie
  /// in the past (then they affect only copies still waiting to be received). Unknown node,
  /// end_us <= start_us, or more than max_outages_per_node: an error, and nothing changes.
  Status add_outage(PeerId node, std::uint64_t start_us, std::uint64_t end_us);

  /// Node `node`'s view of the network: send(to, bytes) sends to node `to`; receive() appends the
  /// copies addressed to `node` whose arrival time is <= now_us(), ordered by (arrival time, send
  /// sequence), with `from` = the sender's node ID. The reference stays valid for the network's
  /// lifetime, across moves. Throws std::out_of_range when node >= nodes().
  [[nodiscard]] Transport& endpoint(PeerId node);

  /// Moves the virtual clock to `now_us`. The clock never goes backwards: an earlier value is
  /// ignored. Nothing is delivered until an endpoint's receive() is called.
  void advance_to(std::uint64_t now_us) noexcept;
  [[nodiscard]] std::uint64_t now_us() const noexcept;

  [[nodiscard]] std::uint32_t nodes() const noexcept;
  /// The current conditions of the direction from -> to. Throws std::out_of_range for an unknown
  /// node or from == to.
  [[nodiscard]] const LinkConditions& link(PeerId from, PeerId to) const;
  /// Throws std::out_of_range when node >= nodes().
  [[nodiscard]] const NodeStats& stats(PeerId node) const;
  /// Copies held by the network: in flight, or arrived and not yet received.
  [[nodiscard]] std::size_t in_flight() const noexcept;

 private:
  struct Impl;  // the network's state; endpoints point to it, so it never moves
  explicit SimNetwork(std::unique_ptr<Impl> impl) noexcept;
  std::unique_ptr<Impl> impl_;
};

}  // namespace detsim::net
