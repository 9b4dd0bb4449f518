// SimNetwork: per-receiver inboxes ordered by (arrival time, send sequence), per-link random
// streams, and exact bandwidth queues. The order of decisions and draws in send() is the one the
// header documents; changing it changes every seeded test run, so it is part of the contract.
#include <detsim/net/sim_network.hpp>

#include <algorithm>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <detsim/core/rng.hpp>

namespace detsim::net {

// Unity builds put several sources in one translation unit: a named namespace keeps these helpers
// from meeting another file's anonymous ones.
namespace simnet {

constexpr std::uint32_t ppm_one = 1'000'000;
constexpr std::uint64_t us_per_s = 1'000'000;
// Keeps busy_fraction + max_datagram * us_per_s far below 2^64 (see Link).
constexpr std::uint64_t max_bandwidth = 1'000'000'000'000'000;

std::uint64_t add_saturating(std::uint64_t a, std::uint64_t b) noexcept {
  constexpr std::uint64_t top = std::numeric_limits<std::uint64_t>::max();
  return a > top - b ? top : a + b;
}

// The SplitMix64 finaliser (Steele, Lea and Flood, 2014): a bijection that spreads every input bit
// over the output, so link seeds for neighbouring node IDs are unrelated.
std::uint64_t mix64(std::uint64_t z) noexcept {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9U;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBU;
  return z ^ (z >> 31);
}

std::string node_missing(const char* function, PeerId node, std::size_t nodes) {
  return std::string(function) + ": node " + std::to_string(node) +
         " does not exist (the network has " + std::to_string(nodes) + " nodes, 0 .. " +
         std::to_string(nodes - 1) + ")";
}

Status validate(const LinkConditions& c, const std::string& where) {
  const auto bad = [&](const char* field, std::uint64_t value, const char* rule) {
    return Status::error(where + ": " + field + " must be " + rule + ", got " +
                         std::to_string(value));
  };
  if (c.loss_ppm > ppm_one) return bad("loss_ppm", c.loss_ppm, "at most 1000000");
  if (c.duplicate_ppm > ppm_one) return bad("duplicate_ppm", c.duplicate_ppm, "at most 1000000");
  if (c.reorder_ppm > ppm_one) return bad("reorder_ppm", c.reorder_ppm, "at most 1000000");
  if (c.bandwidth_bytes_per_s > max_bandwidth) {
    return bad("bandwidth_bytes_per_s", c.bandwidth_bytes_per_s,
               "0 (unlimited) or at most 1000000000000000");
  }
  return Status::success();
}

// One copy of a datagram on its way to a node, or arrived and waiting for receive().
struct Copy {
  std::uint64_t arrival_us = 0;
  std::uint64_t sequence = 0;  // global, +1 per copy enqueued: unique, so the order is total
  PeerId from = 0;
  std::vector<std::uint8_t> bytes;
};

// The heap comparator: "a arrives after b". std::*_heap keep the greatest element at the front,
// which under this order is the earliest (arrival, sequence).
bool arrives_after(const Copy& a, const Copy& b) noexcept {
  if (a.arrival_us != b.arrival_us) return a.arrival_us > b.arrival_us;
  return a.sequence > b.sequence;
}

struct Outage {
  std::uint64_t start_us = 0;
  std::uint64_t end_us = 0;  // exclusive
};

// One direction of one link.
struct Link {
  LinkConditions conditions;
  Rng rng;
  // With a bandwidth cap, the link is busy until busy_us + busy_fraction / bandwidth microseconds
  // (busy_fraction < bandwidth). Keeping the fraction makes the spacing of a long burst exact:
  // the k-th datagram of a burst ends at the ceiling of the exact sum, never a rounded-up sum.
  std::uint64_t busy_us = 0;
  std::uint64_t busy_fraction = 0;
};

bool in_outage(const std::vector<Outage>& outages, std::uint64_t t) noexcept {
  return std::any_of(outages.begin(), outages.end(),
                     [t](const Outage& o) { return o.start_us <= t && t < o.end_us; });
}

}  // namespace simnet

struct SimNetwork::Impl {
  using Copy = simnet::Copy;
  using Link = simnet::Link;
  using Outage = simnet::Outage;

  class Endpoint final : public Transport {
   public:
    Endpoint(Impl& network, PeerId self) noexcept : network_(network), self_(self) {}
    void send(PeerId to, std::span<const std::uint8_t> bytes) override {
      network_.send(self_, to, bytes);
    }
    void receive(std::vector<Datagram>& out) override { network_.receive(self_, out); }

   private:
    Impl& network_;
    PeerId self_;
  };

  struct Node {
    std::vector<Copy> inbox;  // a heap under simnet::arrives_after
    std::vector<Outage> outages;
    NodeStats stats;
  };

  Impl(std::uint32_t node_count, std::uint64_t network_seed, const LinkConditions& all_links)
      : seed(network_seed), default_conditions(all_links), nodes(node_count) {
    endpoints.reserve(node_count);
    for (PeerId id = 0; id < node_count; ++id)
      endpoints.push_back(std::make_unique<Endpoint>(*this, id));
  }
  Impl(const Impl&) = delete;  // endpoints hold a reference to this Impl: it never moves
  Impl& operator=(const Impl&) = delete;

  [[nodiscard]] bool has(PeerId node) const noexcept { return node < nodes.size(); }

  static std::uint32_t link_key(PeerId from, PeerId to) noexcept { return from * max_nodes + to; }

  Link& link_state(PeerId from, PeerId to) {
    const auto [it, added] = links.try_emplace(link_key(from, to));
    if (added) {
      it->second.conditions = default_conditions;
      // Depends only on the seed and the two IDs, not on when the link was first used.
      const std::uint64_t direction = (std::uint64_t{from} << 32) | to;
      it->second.rng = Rng(simnet::mix64(seed ^ simnet::mix64(direction + 1)));
    }
    return it->second;
  }

  // Reserves the link for `size` bytes from now (after what is queued) and returns the end of
  // transmission in whole microseconds, rounded up; nullopt when the wait exceeds max_queue_us.
  std::optional<std::uint64_t> transmit(Link& link, std::size_t size) noexcept {
    const std::uint64_t bandwidth = link.conditions.bandwidth_bytes_per_s;
    if (link.busy_us < now_us || (link.busy_us == now_us && link.busy_fraction == 0)) {
      link.busy_us = now_us;  // idle: transmission starts now
      link.busy_fraction = 0;
    } else {
      const std::uint64_t wait_us = link.busy_us - now_us;  // plus busy_fraction / bandwidth
      const std::uint64_t limit = link.conditions.max_queue_us;
      if (wait_us > limit || (wait_us == limit && link.busy_fraction != 0)) return std::nullopt;
    }
    link.busy_fraction += std::uint64_t{size} * simnet::us_per_s;  // < 2 * 10^15: no overflow
    link.busy_us = simnet::add_saturating(link.busy_us, link.busy_fraction / bandwidth);
    link.busy_fraction %= bandwidth;
    return link.busy_fraction == 0 ? link.busy_us : simnet::add_saturating(link.busy_us, 1);
  }

  void send(PeerId from, PeerId to, std::span<const std::uint8_t> bytes) {
    NodeStats& stats = nodes[from].stats;
    ++stats.sent;
    stats.sent_bytes += bytes.size();
    if (!has(to) || to == from || bytes.size() > max_datagram) {
      ++stats.dropped_invalid;
      return;
    }
    if (simnet::in_outage(nodes[from].outages, now_us) ||
        simnet::in_outage(nodes[to].outages, now_us)) {
      ++stats.dropped_outage;
      return;
    }
    Link& link = link_state(from, to);
    const LinkConditions& c = link.conditions;
    std::uint64_t departure_us = now_us;  // when the last byte has left the sender
    if (c.bandwidth_bytes_per_s != 0) {
      const std::optional<std::uint64_t> end = transmit(link, bytes.size());
      if (!end) {
        ++stats.dropped_queue;
        return;
      }
      departure_us = *end;
    }
    if (c.loss_ppm != 0 && link.rng.below(simnet::ppm_one) < c.loss_ppm) {
      ++stats.lost;
      return;
    }
    const bool duplicate =
        c.duplicate_ppm != 0 && link.rng.below(simnet::ppm_one) < c.duplicate_ppm;
    if (duplicate) ++stats.duplicated;
    for (int copy = 0; copy < (duplicate ? 2 : 1); ++copy) {
      std::uint64_t delay_us = c.latency_us;
      if (c.jitter_us != 0) {
        const std::int64_t latency = c.latency_us;
        const std::int64_t jitter = c.jitter_us;
        delay_us = static_cast<std::uint64_t>(
            std::max<std::int64_t>(0, link.rng.range(latency - jitter, latency + jitter)));
      }
      const bool held_back = c.reorder_ppm != 0 && link.rng.below(simnet::ppm_one) < c.reorder_ppm;
      if (held_back) delay_us += c.reorder_delay_us;
      // Checked after the draws, so that a full network does not shift the link's random stream.
      if (in_flight >= max_in_flight) {
        ++stats.dropped_capacity;
        continue;
      }
      if (held_back) ++stats.reordered;
      std::vector<Copy>& inbox = nodes[to].inbox;
      inbox.push_back(Copy{simnet::add_saturating(departure_us, delay_us), next_sequence++, from,
                           std::vector<std::uint8_t>(bytes.begin(), bytes.end())});
      std::push_heap(inbox.begin(), inbox.end(), simnet::arrives_after);
      ++in_flight;
    }
  }

  void receive(PeerId self, std::vector<Datagram>& out) {
    Node& node = nodes[self];
    while (!node.inbox.empty() && node.inbox.front().arrival_us <= now_us) {
      std::pop_heap(node.inbox.begin(), node.inbox.end(), simnet::arrives_after);
      Copy copy = std::move(node.inbox.back());
      node.inbox.pop_back();
      --in_flight;
      if (simnet::in_outage(node.outages, copy.arrival_us)) {
        ++nodes[copy.from].stats.dropped_outage;
        continue;
      }
      ++node.stats.delivered;
      node.stats.delivered_bytes += copy.bytes.size();
      out.push_back(Datagram{copy.from, std::move(copy.bytes)});
    }
  }

  std::uint64_t seed;
  LinkConditions default_conditions;
  std::vector<Node> nodes;
  std::vector<std::unique_ptr<Endpoint>> endpoints;
  // Only links that were configured or used. Looked up by key, never iterated.
  std::map<std::uint32_t, Link> links;
  std::uint64_t now_us = 0;
  std::uint64_t next_sequence = 0;
  std::size_t in_flight = 0;
};

Expected<SimNetwork> SimNetwork::create(std::uint32_t nodes, std::uint64_t seed,
                                        const LinkConditions& all_links) {
  if (nodes < 1 || nodes > max_nodes) {
    return Status::error("SimNetwork::create: nodes must be 1 .. " + std::to_string(max_nodes) +
                         ", got " + std::to_string(nodes));
  }
  if (Status valid = simnet::validate(all_links, "SimNetwork::create: all_links"); !valid)
    return valid;
  return SimNetwork(std::make_unique<Impl>(nodes, seed, all_links));
}

SimNetwork::SimNetwork(std::unique_ptr<Impl> impl) noexcept : impl_(std::move(impl)) {}
SimNetwork::SimNetwork(SimNetwork&&) noexcept = default;
SimNetwork& SimNetwork::operator=(SimNetwork&&) noexcept = default;
SimNetwork::~SimNetwork() = default;

Status SimNetwork::set_link(PeerId from, PeerId to, const LinkConditions& conditions) {
  const std::size_t count = impl_->nodes.size();
  if (!impl_->has(from)) return Status::error(simnet::node_missing("set_link", from, count));
  if (!impl_->has(to)) return Status::error(simnet::node_missing("set_link", to, count));
  if (from == to) {
    return Status::error("set_link: from and to are both node " + std::to_string(from) +
                         "; a node has no link to itself");
  }
  const std::string where = "set_link " + std::to_string(from) + " -> " + std::to_string(to);
  if (Status valid = simnet::validate(conditions, where); !valid) return valid;
  Impl::Link& link = impl_->link_state(from, to);
  if (conditions.bandwidth_bytes_per_s != link.conditions.bandwidth_bytes_per_s &&
      link.busy_fraction != 0) {
    // The fraction is in units of the old bandwidth: round the queue up to a whole microsecond.
    link.busy_us = simnet::add_saturating(link.busy_us, 1);
    link.busy_fraction = 0;
  }
  link.conditions = conditions;
  return Status::success();
}

Status SimNetwork::add_outage(PeerId node, std::uint64_t start_us, std::uint64_t end_us) {
  if (!impl_->has(node)) {
    return Status::error(simnet::node_missing("add_outage", node, impl_->nodes.size()));
  }
  if (end_us <= start_us) {
    return Status::error("add_outage: node " + std::to_string(node) + ": end_us (" +
                         std::to_string(end_us) + ") must be greater than start_us (" +
                         std::to_string(start_us) + ")");
  }
  std::vector<Impl::Outage>& outages = impl_->nodes[node].outages;
  if (outages.size() >= max_outages_per_node) {
    return Status::error("add_outage: node " + std::to_string(node) + " already has " +
                         std::to_string(outages.size()) + " outages, the most one node may have");
  }
  outages.push_back(Impl::Outage{start_us, end_us});
  return Status::success();
}

Transport& SimNetwork::endpoint(PeerId node) {
  if (!impl_->has(node)) {
    throw std::out_of_range(
        simnet::node_missing("SimNetwork::endpoint", node, impl_->nodes.size()));
  }
  return *impl_->endpoints[node];
}

void SimNetwork::advance_to(std::uint64_t now_us) noexcept {
  impl_->now_us = std::max(impl_->now_us, now_us);
}

std::uint64_t SimNetwork::now_us() const noexcept {
  return impl_->now_us;
}

std::uint32_t SimNetwork::nodes() const noexcept {
  return static_cast<std::uint32_t>(impl_->nodes.size());
}

const LinkConditions& SimNetwork::link(PeerId from, PeerId to) const {
  const std::size_t count = impl_->nodes.size();
  if (!impl_->has(from))
    throw std::out_of_range(simnet::node_missing("SimNetwork::link", from, count));
  if (!impl_->has(to)) throw std::out_of_range(simnet::node_missing("SimNetwork::link", to, count));
  if (from == to) {
    throw std::out_of_range("SimNetwork::link: node " + std::to_string(from) +
                            " has no link to itself");
  }
  const auto it = impl_->links.find(Impl::link_key(from, to));
  return it == impl_->links.end() ? impl_->default_conditions : it->second.conditions;
}

const NodeStats& SimNetwork::stats(PeerId node) const {
  if (!impl_->has(node)) {
    throw std::out_of_range(simnet::node_missing("SimNetwork::stats", node, impl_->nodes.size()));
  }
  return impl_->nodes[node].stats;
}

std::size_t SimNetwork::in_flight() const noexcept {
  return impl_->in_flight;
}

}  // namespace detsim::net
