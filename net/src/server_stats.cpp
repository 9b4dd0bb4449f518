// ServerStats' tick lateness (server.hpp): the histogram Server::advance fills, and its
// percentiles.
#include <algorithm>
#include <cstddef>
#include <cstdint>

#include <detsim/net/server.hpp>

namespace detsim::net {

void ServerStats::count_tick_lateness(std::uint64_t late_us) noexcept {
  const std::uint64_t bucket =
      std::min<std::uint64_t>(late_us / tick_lateness_bucket_us, tick_lateness.size() - 1);
  ++tick_lateness[static_cast<std::size_t>(bucket)];
  tick_lateness_max_us = std::max(tick_lateness_max_us, late_us);
}

std::uint64_t ServerStats::tick_lateness_percentile_us(std::uint32_t per_mille) const noexcept {
  std::uint64_t total = 0;
  for (const std::uint64_t n : tick_lateness)
    total += n;
  if (total == 0) return 0;
  // The first bucket by which the count reaches ceil(total × per_mille / 1000).
  const std::uint64_t want = (total * std::min(per_mille, 1000U) + 999) / 1000;
  std::uint64_t seen = 0;
  for (std::size_t i = 0; i < tick_lateness.size(); ++i) {
    seen += tick_lateness[i];
    if (seen >= want && seen != 0)
      return i + 1 == tick_lateness.size() ? tick_lateness_max_us
                                           : (i + 1) * tick_lateness_bucket_us;
  }
  return tick_lateness_max_us;
}

}  // namespace detsim::net
