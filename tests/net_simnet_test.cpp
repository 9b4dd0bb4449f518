// SimNetwork: exact latency on a perfect link, jitter bounds and the reordering it causes, loss,
// duplication and reordering at their configured rates, bandwidth spacing and tail drops, outages
// in both directions, bit-for-bit determinism per seed and per link, invalid arguments, invalid
// datagrams, the in-flight cap, and moves.
//
// Arrival times are measured exactly: the tests advance the virtual clock one microsecond at a time
// and receive at every node on every tick. Rates are checked against the binomial distribution:
// the count must lie within 5 standard deviations of n * p, computed in integers. Every run is
// seeded, so such a check passes or fails the same way every time.
#include <algorithm>
#include <cstdint>
#include <iterator>
#include <map>
#include <ostream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/net/sim_network.hpp>

namespace detsim::net {
namespace {

struct Arrival {
  std::uint64_t time_us = 0;
  PeerId to = 0;
  PeerId from = 0;
  std::vector<std::uint8_t> bytes;

  friend bool operator==(const Arrival&, const Arrival&) = default;
};

std::ostream& operator<<(std::ostream& os, const Arrival& a) {
  return os << "{t=" << a.time_us << " " << a.from << "->" << a.to << " " << a.bytes.size()
            << " bytes}";
}

// A payload of `size` bytes (at least 4) that starts with `index`, little-endian.
std::vector<std::uint8_t> payload(std::uint32_t index, std::size_t size = 8) {
  std::vector<std::uint8_t> bytes(std::max<std::size_t>(size, 4));
  for (std::size_t i = 0; i < bytes.size(); ++i)
    bytes[i] = static_cast<std::uint8_t>(i < 4 ? index >> (8 * i) : index + i);
  return bytes;
}

std::uint32_t index_of(const std::vector<std::uint8_t>& bytes) {
  std::uint32_t index = 0;
  for (std::size_t i = 0; i < 4; ++i)
    index |= std::uint32_t{bytes.at(i)} << (8 * i);
  return index;
}

SimNetwork make(std::uint32_t nodes, std::uint64_t seed, const LinkConditions& links = {}) {
  auto net = SimNetwork::create(nodes, seed, links);
  if (!net) throw std::runtime_error(net.message());
  return std::move(net.value());
}

// Runs the clock from now_us() to end_us one microsecond at a time. On every tick it calls
// on_tick(t) (the sends of that tick), then receives at every node and logs what arrived.
template <class OnTick>
std::vector<Arrival> simulate(SimNetwork& net, std::uint64_t end_us, OnTick on_tick) {
  std::vector<Arrival> log;
  std::vector<Datagram> got;
  for (std::uint64_t t = net.now_us(); t <= end_us; ++t) {
    net.advance_to(t);
    on_tick(t);
    for (PeerId node = 0; node < net.nodes(); ++node) {
      got.clear();
      net.endpoint(node).receive(got);
      for (Datagram& d : got)
        log.push_back(Arrival{t, node, d.from, std::move(d.bytes)});
    }
  }
  return log;
}

std::vector<Arrival> only(const std::vector<Arrival>& log, PeerId from, PeerId to) {
  std::vector<Arrival> out;
  std::copy_if(log.begin(), log.end(), std::back_inserter(out),
               [&](const Arrival& a) { return a.from == from && a.to == to; });
  return out;
}

std::uint64_t isqrt_ceil(std::uint64_t x) {
  std::uint64_t lo = 0;
  std::uint64_t hi = std::uint64_t{1} << 32;
  while (lo < hi) {  // the least r with r * r >= x
    const std::uint64_t mid = lo + (hi - lo) / 2;
    if (mid * mid >= x) {
      hi = mid;
    } else {
      lo = mid + 1;
    }
  }
  return lo;
}

// 5 standard deviations of a binomial(n, ppm / 10^6) count, rounded up:
// sqrt(25 n p (1 - p)) = sqrt(25 n ppm (10^6 - ppm)) / 10^6.
std::uint64_t binomial_tolerance(std::uint64_t n, std::uint64_t ppm) {
  return (isqrt_ceil(25 * n * ppm * (1'000'000 - ppm)) + 999'999) / 1'000'000;
}

void expect_rate(std::uint64_t count, std::uint64_t n, std::uint64_t ppm, const char* what) {
  const std::uint64_t expected = n * ppm / 1'000'000;
  const std::uint64_t tolerance = binomial_tolerance(n, ppm);
  EXPECT_LE(count, expected + tolerance) << what;
  EXPECT_GE(count + tolerance, expected) << what;
}

// Arrival pairs (earlier arrival, later arrival) whose payload indices are out of order.
std::size_t inversions(const std::vector<Arrival>& log) {
  std::size_t count = 0;
  for (std::size_t i = 1; i < log.size(); ++i)
    if (index_of(log[i].bytes) < index_of(log[i - 1].bytes)) ++count;
  return count;
}

// Whole-network conservation: every send and every duplicate ends up counted exactly once.
void expect_conserved(const SimNetwork& net) {
  std::uint64_t in = 0;
  std::uint64_t out = net.in_flight();
  for (PeerId node = 0; node < net.nodes(); ++node) {
    const NodeStats& s = net.stats(node);
    in += s.sent + s.duplicated;
    out += s.delivered + s.lost + s.dropped_invalid + s.dropped_outage + s.dropped_queue +
           s.dropped_capacity;
  }
  EXPECT_EQ(in, out);
}

TEST(SimNetwork, PerfectLinkDeliversEverythingInOrderAfterExactlyTheLatency) {
  SimNetwork net = make(2, 1, {.latency_us = 2'500});
  const auto log = simulate(net, 13'000, [&](std::uint64_t t) {
    if (t % 100 != 0 || t >= 10'000) return;
    const auto index = static_cast<std::uint32_t>(t / 100);
    net.endpoint(0).send(1, payload(index, 4 + index));
    net.endpoint(1).send(0, payload(index));
  });
  for (const auto& [from, to] : {std::pair<PeerId, PeerId>{0, 1}, {1, 0}}) {
    const auto link = only(log, from, to);
    ASSERT_EQ(link.size(), 100U);
    for (std::uint32_t i = 0; i < 100; ++i) {
      EXPECT_EQ(link[i].time_us, i * 100 + 2'500) << link[i];
      EXPECT_EQ(link[i].bytes, from == 0 ? payload(i, 4 + i) : payload(i));
    }
  }
  EXPECT_EQ(net.stats(0).sent, 100U);
  EXPECT_EQ(net.stats(1).delivered, 100U);
  EXPECT_EQ(net.stats(1).delivered_bytes, net.stats(0).sent_bytes);
  EXPECT_EQ(net.in_flight(), 0U);
  expect_conserved(net);
}

TEST(SimNetwork, SimultaneousArrivalsComeInSendOrder) {
  // Equal arrival times are ordered by send sequence, across senders too: 0 -> 2 with 300 us and
  // 1 -> 2 with 100 us, 1 sending 200 us later, land on the same microseconds.
  SimNetwork net = make(3, 1);
  ASSERT_TRUE(net.set_link(0, 2, {.latency_us = 300}).ok());
  ASSERT_TRUE(net.set_link(1, 2, {.latency_us = 100}).ok());
  for (std::uint32_t i = 0; i < 500; ++i)
    net.endpoint(0).send(2, payload(i));
  net.advance_to(200);
  for (std::uint32_t i = 500; i < 1'000; ++i)
    net.endpoint(1).send(2, payload(i));
  const auto log = simulate(net, 400, [](std::uint64_t) {});
  ASSERT_EQ(log.size(), 1'000U);
  for (std::uint32_t i = 0; i < 1'000; ++i) {
    EXPECT_EQ(log[i].time_us, 300U);
    EXPECT_EQ(index_of(log[i].bytes), i) << log[i];
    EXPECT_EQ(log[i].from, i < 500 ? 0U : 1U);
  }
}

TEST(SimNetwork, ZeroLatencyDeliversAtTheSameInstantAndTheClockNeverGoesBack) {
  SimNetwork net = make(2, 1);
  net.advance_to(500);
  net.advance_to(100);
  EXPECT_EQ(net.now_us(), 500U);
  net.endpoint(0).send(1, payload(7));
  std::vector<Datagram> got;
  net.endpoint(0).receive(got);
  EXPECT_TRUE(got.empty());  // not addressed to node 0
  net.endpoint(1).receive(got);
  ASSERT_EQ(got.size(), 1U);
  EXPECT_EQ(got[0].from, 0U);
  EXPECT_EQ(got[0].bytes, payload(7));
}

TEST(SimNetwork, JitterStaysWithinItsBoundsAndReorders) {
  constexpr std::uint32_t sends = 2'000;
  SimNetwork net = make(2, 7, {.latency_us = 10'000, .jitter_us = 3'000});
  const auto log = simulate(net, sends * 50 + 13'000, [&](std::uint64_t t) {
    if (t % 50 == 0 && t / 50 < sends) net.endpoint(0).send(1, payload(std::uint32_t(t / 50)));
  });
  ASSERT_EQ(log.size(), sends);
  std::uint64_t min_delay = ~std::uint64_t{0};
  std::uint64_t max_delay = 0;
  std::vector<int> seen(sends);
  for (const Arrival& a : log) {
    const std::uint32_t index = index_of(a.bytes);
    ASSERT_LT(index, sends);
    ++seen[index];
    const std::uint64_t delay = a.time_us - std::uint64_t{index} * 50;
    EXPECT_GE(delay, 7'000U) << a;
    EXPECT_LE(delay, 13'000U) << a;
    min_delay = std::min(min_delay, delay);
    max_delay = std::max(max_delay, delay);
  }
  EXPECT_EQ(static_cast<std::uint32_t>(std::count(seen.begin(), seen.end(), 1)), sends);
  // 2,000 draws over 6,001 values reach within 50 of both ends (a miss has odds ~ e^-16).
  EXPECT_LE(min_delay, 7'050U);
  EXPECT_GE(max_delay, 12'950U);
  EXPECT_GT(inversions(log), 100U);
  EXPECT_EQ(net.stats(0).reordered, 0U);  // jitter reorders without the reorder feature

  // A narrow range is hit exactly at both ends and nowhere outside: every delay in 97 .. 103.
  SimNetwork narrow = make(2, 8, {.latency_us = 100, .jitter_us = 3});
  const auto few = simulate(narrow, 1'000 * 10 + 200, [&](std::uint64_t t) {
    if (t % 10 == 0 && t / 10 < 1'000) narrow.endpoint(0).send(1, payload(std::uint32_t(t / 10)));
  });
  std::map<std::uint64_t, int> delays;
  for (const Arrival& a : few)
    ++delays[a.time_us - std::uint64_t{index_of(a.bytes)} * 10];
  ASSERT_EQ(delays.size(), 7U);
  EXPECT_EQ(delays.begin()->first, 97U);
  EXPECT_EQ(delays.rbegin()->first, 103U);
}

TEST(SimNetwork, JitterLargerThanTheLatencyClampsAtZero) {
  SimNetwork net = make(2, 3, {.latency_us = 1'000, .jitter_us = 4'000});
  std::uint32_t zero_delay = 0;
  const auto log = simulate(net, 100 * 100 + 5'000, [&](std::uint64_t t) {
    if (t % 100 == 0 && t / 100 < 100) net.endpoint(0).send(1, payload(std::uint32_t(t / 100)));
  });
  ASSERT_EQ(log.size(), 100U);
  for (const Arrival& a : log) {
    const std::uint64_t delay = a.time_us - std::uint64_t{index_of(a.bytes)} * 100;
    EXPECT_LE(delay, 5'000U) << a;
    zero_delay += delay == 0 ? 1 : 0;
  }
  // P(delay 0) = 3001 / 8001: about 37 of 100.
  EXPECT_GT(zero_delay, 15U);
  EXPECT_LT(zero_delay, 60U);
}

TEST(SimNetwork, LossMatchesItsRate) {
  for (const std::uint32_t ppm : {0U, 1'000U, 100'000U, 500'000U, 1'000'000U}) {
    constexpr std::uint32_t n = 100'000;
    SimNetwork net = make(2, 11, {.loss_ppm = ppm});
    std::vector<Datagram> got;
    std::uint64_t received = 0;
    for (std::uint32_t i = 0; i < n; ++i) {
      net.endpoint(0).send(1, payload(i));
      if (i % 1'000 == 999) {
        got.clear();
        net.endpoint(1).receive(got);
        received += got.size();
      }
    }
    const NodeStats& s = net.stats(0);
    expect_rate(s.lost, n, ppm, "lost");
    EXPECT_EQ(s.lost + received, n) << "loss_ppm " << ppm;
    EXPECT_EQ(net.stats(1).delivered, received);
    if (ppm == 0) {
      EXPECT_EQ(s.lost, 0U);
    }
    if (ppm == 1'000'000) {
      EXPECT_EQ(received, 0U);
    }
    expect_conserved(net);
  }
}

TEST(SimNetwork, DuplicatesArriveTwiceAtTheirRateWithIndependentDelays) {
  constexpr std::uint32_t n = 50'000;
  constexpr std::uint32_t ppm = 200'000;
  SimNetwork net = make(2, 5, {.duplicate_ppm = ppm});
  std::map<std::uint32_t, int> copies;
  std::vector<Datagram> got;
  for (std::uint32_t i = 0; i < n; ++i) {
    net.endpoint(0).send(1, payload(i));
    got.clear();
    net.endpoint(1).receive(got);
    for (const Datagram& d : got) {
      EXPECT_EQ(d.bytes, payload(i));
      ++copies[index_of(d.bytes)];
    }
  }
  ASSERT_EQ(copies.size(), n);
  const auto twice = std::count_if(copies.begin(), copies.end(),
                                   [](const auto& entry) { return entry.second == 2; });
  const auto once = std::count_if(copies.begin(), copies.end(),
                                  [](const auto& entry) { return entry.second == 1; });
  EXPECT_EQ(static_cast<std::uint64_t>(twice + once), n);
  EXPECT_EQ(static_cast<std::uint64_t>(twice), net.stats(0).duplicated);
  EXPECT_EQ(net.stats(1).delivered, n + net.stats(0).duplicated);
  expect_rate(net.stats(0).duplicated, n, ppm, "duplicated");

  // With jitter, the two copies of one datagram arrive at independently drawn times.
  SimNetwork jittery = make(2, 5, {.latency_us = 5'000, .jitter_us = 2'000, .duplicate_ppm = ppm});
  const auto log = simulate(jittery, 1'000 * 10 + 7'000, [&](std::uint64_t t) {
    if (t % 10 == 0 && t / 10 < 1'000) jittery.endpoint(0).send(1, payload(std::uint32_t(t / 10)));
  });
  std::map<std::uint32_t, std::vector<std::uint64_t>> times;
  for (const Arrival& a : log)
    times[index_of(a.bytes)].push_back(a.time_us);
  const auto apart = std::count_if(times.begin(), times.end(), [](const auto& entry) {
    return entry.second.size() == 2 && entry.second[0] != entry.second[1];
  });
  EXPECT_GT(apart, 100);  // ~200 pairs; equal times have odds 1 / 4001 each
}

TEST(SimNetwork, ReorderHoldsBackTheChosenDatagramsSoLaterOnesOvertake) {
  constexpr std::uint32_t n = 5'000;
  constexpr std::uint32_t ppm = 100'000;
  SimNetwork net = make(2, 9, {.latency_us = 1'000, .reorder_ppm = ppm, .reorder_delay_us = 500});
  const auto log = simulate(net, n * 100 + 2'000, [&](std::uint64_t t) {
    if (t % 100 == 0 && t / 100 < n) net.endpoint(0).send(1, payload(std::uint32_t(t / 100)));
  });
  ASSERT_EQ(log.size(), n);
  std::uint64_t held = 0;
  for (const Arrival& a : log) {
    const std::uint64_t delay = a.time_us - std::uint64_t{index_of(a.bytes)} * 100;
    EXPECT_TRUE(delay == 1'000 || delay == 1'500) << a;
    held += delay == 1'500 ? 1 : 0;
  }
  EXPECT_EQ(held, net.stats(0).reordered);
  expect_rate(held, n, ppm, "reordered");
  // A held datagram is overtaken by the (up to) four sent after it in the next 400 us.
  EXPECT_GE(inversions(log), held / 2);
  EXPECT_GT(held, 0U);
}

TEST(SimNetwork, BandwidthSpacesArrivalsAndTailDropsBeyondTheQueue) {
  // 1000 bytes at 100,000 B/s occupy the link 10,000 us; the sixth waits 50,000 us (allowed),
  // the seventh would wait 60,000 us.
  SimNetwork net =
      make(2, 1, {.latency_us = 5'000, .bandwidth_bytes_per_s = 100'000, .max_queue_us = 50'000});
  for (std::uint32_t i = 0; i < 10; ++i)
    net.endpoint(0).send(1, payload(i, 1'000));
  EXPECT_EQ(net.stats(0).dropped_queue, 4U);
  auto log = simulate(net, 200'000, [&](std::uint64_t t) {
    if (t == 200'000) net.endpoint(0).send(1, payload(99, 1'000));  // the link is idle again
  });
  const auto more = simulate(net, 220'000, [](std::uint64_t) {});
  log.insert(log.end(), more.begin(), more.end());
  ASSERT_EQ(log.size(), 7U);
  for (std::uint32_t i = 0; i < 6; ++i) {
    EXPECT_EQ(index_of(log[i].bytes), i);
    EXPECT_EQ(log[i].time_us, 15'000 + 10'000 * i) << log[i];
  }
  EXPECT_EQ(index_of(log[6].bytes), 99U);
  EXPECT_EQ(log[6].time_us, 215'000U);
  expect_conserved(net);

  // A transmission time that is not a whole number of microseconds does not drift: the k-th of a
  // burst arrives at the ceiling of the exact k * 300 bytes / 7,000 B/s.
  SimNetwork exact = make(2, 1, {.bandwidth_bytes_per_s = 7'000, .max_queue_us = 4'000'000});
  for (std::uint32_t i = 0; i < 40; ++i)
    exact.endpoint(0).send(1, payload(i, 300));
  const auto burst = simulate(exact, 2'000'000, [](std::uint64_t) {});
  ASSERT_EQ(burst.size(), 40U);
  for (std::uint64_t k = 1; k <= 40; ++k)
    EXPECT_EQ(burst[k - 1].time_us, (k * 300 * 1'000'000 + 6'999) / 7'000) << "k = " << k;
}

TEST(SimNetwork, OutageDropsBothDirectionsDuringTheWindowOnly) {
  SimNetwork net = make(3, 1, {.latency_us = 1'000});
  ASSERT_TRUE(net.add_outage(1, 10'000, 20'000).ok());
  const auto log = simulate(net, 31'000, [&](std::uint64_t t) {
    if (t % 100 != 0 || t >= 30'000) return;
    const auto index = static_cast<std::uint32_t>(t);  // the send time
    for (const auto& [from, to] : {std::pair<PeerId, PeerId>{0, 1}, {1, 0}, {0, 2}, {2, 0}})
      net.endpoint(from).send(to, payload(index));
  });
  const auto sent_times = [](const std::vector<Arrival>& link) {
    std::vector<std::uint32_t> times;
    for (const Arrival& a : link)
      times.push_back(index_of(a.bytes));
    return times;
  };
  std::vector<std::uint32_t> to_1;
  std::vector<std::uint32_t> from_1;
  std::vector<std::uint32_t> all;
  for (std::uint32_t t = 0; t < 30'000; t += 100) {
    all.push_back(t);
    // Sent during the outage, or arriving during it (t + 1000 in the window).
    if (t < 9'000 || t >= 20'000) to_1.push_back(t);
    // Sent during the outage; sent just before it, it still reaches node 0.
    if (t < 10'000 || t >= 20'000) from_1.push_back(t);
  }
  EXPECT_EQ(sent_times(only(log, 0, 1)), to_1);
  EXPECT_EQ(sent_times(only(log, 1, 0)), from_1);
  EXPECT_EQ(sent_times(only(log, 0, 2)), all);
  EXPECT_EQ(sent_times(only(log, 2, 0)), all);
  EXPECT_EQ(net.stats(0).dropped_outage, 110U);
  EXPECT_EQ(net.stats(1).dropped_outage, 100U);
  EXPECT_EQ(net.stats(2).dropped_outage, 0U);

  // An outage added while a datagram is in flight drops it on arrival.
  net.endpoint(0).send(1, payload(1));
  ASSERT_TRUE(net.add_outage(1, 31'500, 32'500).ok());
  net.endpoint(0).send(2, payload(2));
  const auto late = simulate(net, 33'000, [](std::uint64_t) {});
  ASSERT_EQ(late.size(), 1U);
  EXPECT_EQ(late[0].to, 2U);
  EXPECT_EQ(net.stats(0).dropped_outage, 111U);
  expect_conserved(net);
}

// Three nodes, every impairment, traffic in every direction of varied sizes, invalid sends and an
// outage: the log of every arrival with its exact time.
std::vector<Arrival> busy_run(std::uint64_t seed, NodeStats* stats_of_0 = nullptr) {
  const LinkConditions rough{.latency_us = 2'000,
                             .jitter_us = 1'500,
                             .loss_ppm = 50'000,
                             .duplicate_ppm = 50'000,
                             .reorder_ppm = 50'000,
                             .reorder_delay_us = 3'000,
                             .bandwidth_bytes_per_s = 1'000'000,
                             .max_queue_us = 20'000};
  SimNetwork net = make(3, seed, rough);
  LinkConditions slow = rough;
  slow.latency_us = 9'000;
  slow.bandwidth_bytes_per_s = 60'000;
  EXPECT_TRUE(net.set_link(2, 0, slow).ok());
  EXPECT_TRUE(net.add_outage(2, 20'000, 25'000).ok());
  std::uint32_t index = 0;
  auto log = simulate(net, 160'000, [&](std::uint64_t t) {
    if (t % 250 != 0 || t >= 95'000) return;
    for (PeerId from = 0; from < 3; ++from) {
      for (PeerId to = 0; to < 4; ++to) {  // 4: an unknown node; from == to: to itself
        ++index;
        net.endpoint(from).send(to, payload(index, 4 + index % 1'100));
      }
    }
  });
  expect_conserved(net);
  EXPECT_EQ(net.in_flight(), 0U);
  if (stats_of_0 != nullptr) *stats_of_0 = net.stats(0);
  return log;
}

TEST(SimNetwork, TheSameSeedGivesTheSameDeliveriesAndAnotherSeedDoesNot) {
  NodeStats first_stats;
  NodeStats again_stats;
  NodeStats other_stats;
  const auto first = busy_run(42, &first_stats);
  const auto again = busy_run(42, &again_stats);
  const auto other = busy_run(43, &other_stats);
  EXPECT_GT(first.size(), 500U);
  EXPECT_EQ(first, again);
  EXPECT_EQ(first_stats, again_stats);
  EXPECT_NE(first, other);
  EXPECT_GT(first_stats.lost, 0U);
  EXPECT_GT(first_stats.duplicated, 0U);
  EXPECT_GT(first_stats.reordered, 0U);
  EXPECT_GT(first_stats.dropped_queue, 0U);
  EXPECT_GT(first_stats.dropped_invalid, 0U);
}

TEST(SimNetwork, TrafficOnOneLinkDoesNotChangeAnother) {
  const LinkConditions rough{
      .latency_us = 3'000, .jitter_us = 2'000, .loss_ppm = 100'000, .duplicate_ppm = 100'000};
  const auto run = [&](bool other_traffic) {
    SimNetwork net = make(3, 77, rough);
    return only(simulate(net, 30'000,
                         [&](std::uint64_t t) {
                           if (t % 100 != 0 || t >= 25'000) return;
                           net.endpoint(0).send(1, payload(std::uint32_t(t)));
                           if (other_traffic) {
                             net.endpoint(2).send(1, payload(std::uint32_t(t)));
                             net.endpoint(1).send(0, payload(std::uint32_t(t)));
                           }
                         }),
                0, 1);
  };
  const auto alone = run(false);
  EXPECT_GT(alone.size(), 200U);
  EXPECT_EQ(alone, run(true));

  // Links draw from different streams: the same traffic on 0 -> 1 and 2 -> 1 loses different
  // datagrams.
  SimNetwork net = make(3, 77, {.loss_ppm = 500'000});
  const auto both = simulate(net, 1'000, [&](std::uint64_t t) {
    net.endpoint(0).send(1, payload(std::uint32_t(t)));
    net.endpoint(2).send(1, payload(std::uint32_t(t)));
  });
  const auto indices = [](const std::vector<Arrival>& link) {
    std::vector<std::uint32_t> out;
    for (const Arrival& a : link)
      out.push_back(index_of(a.bytes));
    return out;
  };
  EXPECT_NE(indices(only(both, 0, 1)), indices(only(both, 2, 1)));
}

TEST(SimNetwork, InvalidArgumentsGiveErrorsNamingTheProblemAndChangeNothing) {
  const auto error_of = [](const auto& result) {
    return result.ok() ? std::string("(ok)") : result.message();
  };
  EXPECT_NE(error_of(SimNetwork::create(0, 1)).find("nodes must be 1 .. 256, got 0"),
            std::string::npos);
  EXPECT_NE(error_of(SimNetwork::create(257, 1)).find("got 257"), std::string::npos);
  EXPECT_TRUE(SimNetwork::create(256, 1).ok());
  const std::pair<LinkConditions, std::string> bad_conditions[] = {
      {{.loss_ppm = 1'000'001}, "loss_ppm must be at most 1000000, got 1000001"},
      {{.duplicate_ppm = 2'000'000}, "duplicate_ppm must be at most 1000000, got 2000000"},
      {{.reorder_ppm = 1'000'001}, "reorder_ppm must be at most 1000000, got 1000001"},
      {{.bandwidth_bytes_per_s = 1'000'000'000'000'001},
       "bandwidth_bytes_per_s must be 0 (unlimited) or at most 1000000000000000, got "
       "1000000000000001"},
  };
  for (const auto& [conditions, message] : bad_conditions) {
    const std::string created = error_of(SimNetwork::create(2, 1, conditions));
    EXPECT_NE(created.find("all_links: " + message), std::string::npos) << created;
  }

  const LinkConditions good{.latency_us = 1'000};
  SimNetwork net = make(3, 1, good);
  const auto status_of = [](const Status& s) { return s.ok() ? std::string("(ok)") : s.message(); };
  EXPECT_NE(status_of(net.set_link(0, 5, {})).find("node 5 does not exist"), std::string::npos);
  EXPECT_NE(status_of(net.set_link(9, 0, {})).find("node 9 does not exist"), std::string::npos);
  EXPECT_NE(status_of(net.set_link(1, 1, {})).find("both node 1"), std::string::npos);
  for (const auto& [conditions, message] : bad_conditions) {
    const std::string set = status_of(net.set_link(0, 1, conditions));
    EXPECT_NE(set.find("set_link 0 -> 1: " + message), std::string::npos) << set;
  }
  EXPECT_EQ(net.link(0, 1), good);
  EXPECT_NE(status_of(net.add_outage(3, 0, 10)).find("node 3 does not exist"), std::string::npos);
  EXPECT_NE(
      status_of(net.add_outage(0, 10, 10)).find("end_us (10) must be greater than start_us (10)"),
      std::string::npos);
  EXPECT_FALSE(net.add_outage(1, 10, 5).ok());
  EXPECT_THROW((void)net.endpoint(3), std::out_of_range);
  EXPECT_THROW((void)net.stats(3), std::out_of_range);
  EXPECT_THROW((void)net.link(2, 2), std::out_of_range);

  // Nothing changed: the link still has 1,000 us latency and no outage covers [5, 10).
  const auto log = simulate(net, 2'000, [&](std::uint64_t t) {
    if (t == 7) net.endpoint(0).send(1, payload(1));
  });
  ASSERT_EQ(log.size(), 1U);
  EXPECT_EQ(log[0].time_us, 1'007U);

  for (std::size_t i = 0; i < SimNetwork::max_outages_per_node; ++i)
    ASSERT_TRUE(net.add_outage(2, 100'000 + i, 100'001 + i).ok());
  EXPECT_NE(status_of(net.add_outage(2, 0, 1)).find("already has 1024 outages"), std::string::npos);
}

TEST(SimNetwork, DatagramsToUnknownNodesToItselfOrOversizeAreDroppedAndCounted) {
  SimNetwork net = make(3, 1);
  net.endpoint(0).send(3, payload(1));
  net.endpoint(0).send(0, payload(2));
  net.endpoint(0).send(2, std::vector<std::uint8_t>(max_datagram + 1));
  net.endpoint(0).send(2, std::vector<std::uint8_t>(max_datagram, 0xAB));
  net.endpoint(0).send(2, {});
  const NodeStats& s = net.stats(0);
  EXPECT_EQ(s.sent, 5U);
  EXPECT_EQ(s.sent_bytes, 8 + 8 + (max_datagram + 1) + max_datagram);
  EXPECT_EQ(s.dropped_invalid, 3U);
  std::vector<Datagram> got;
  net.endpoint(2).receive(got);
  ASSERT_EQ(got.size(), 2U);
  EXPECT_EQ(got[0].bytes, std::vector<std::uint8_t>(max_datagram, 0xAB));
  EXPECT_TRUE(got[1].bytes.empty());
  net.endpoint(0).receive(got);
  net.endpoint(1).receive(got);
  EXPECT_EQ(got.size(), 2U);
  expect_conserved(net);
}

TEST(SimNetwork, InFlightCopiesAreCappedAndCounted) {
  SimNetwork net = make(2, 1, {.latency_us = 10});
  const std::uint8_t byte[] = {1};
  for (std::size_t i = 0; i < SimNetwork::max_in_flight + 10; ++i)
    net.endpoint(0).send(1, byte);
  EXPECT_EQ(net.in_flight(), SimNetwork::max_in_flight);
  EXPECT_EQ(net.stats(0).dropped_capacity, 10U);
  net.advance_to(10);
  std::vector<Datagram> got;
  net.endpoint(1).receive(got);
  EXPECT_EQ(got.size(), SimNetwork::max_in_flight);
  EXPECT_EQ(net.in_flight(), 0U);
  net.endpoint(0).send(1, byte);
  EXPECT_EQ(net.in_flight(), 1U);
  expect_conserved(net);
}

TEST(SimNetwork, AMovedNetworkKeepsItsStateAndItsEndpoints) {
  SimNetwork original = make(2, 1, {.latency_us = 100});
  Transport& a = original.endpoint(0);
  Transport& b = original.endpoint(1);
  a.send(1, payload(1));
  SimNetwork moved(std::move(original));
  moved.advance_to(100);
  std::vector<Datagram> got;
  b.receive(got);
  ASSERT_EQ(got.size(), 1U);
  EXPECT_EQ(got[0].bytes, payload(1));

  SimNetwork assigned = make(5, 2);
  a.send(1, payload(2));
  assigned = std::move(moved);
  EXPECT_EQ(assigned.nodes(), 2U);
  EXPECT_EQ(&assigned.endpoint(0), &a);
  assigned.advance_to(200);
  got.clear();
  b.receive(got);
  ASSERT_EQ(got.size(), 1U);
  EXPECT_EQ(got[0].bytes, payload(2));
  EXPECT_EQ(assigned.stats(0).sent, 2U);
  EXPECT_EQ(assigned.stats(1).delivered, 2U);
}

}  // namespace
}  // namespace detsim::net
