// The size (a scene's `count`) that a test running every scenario gives each one.
#pragma once

#include <algorithm>
#include <cstdint>

#include <detsim/scenes/scenario.hpp>

namespace detsim::test {

/// `wanted`, within the scene's max_count (0 for a scene without a count), except the dam break's
/// block, at most 3 particles across (108 particles): its default, 10 across, is 4000 fluid
/// particles, seconds a frame under the sanitizers.
inline std::uint32_t scenario_test_count(const ScenarioInfo& info, std::uint32_t wanted) {
  const std::uint32_t n = std::min(wanted, info.max_count);
  return info.name == "dam_break" ? std::min(n, 3U) : n;
}

}  // namespace detsim::test
