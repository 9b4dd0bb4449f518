// What `detsim serve` (cmd_serve.cpp) and its clients, `detsim netplay --server`
// (cmd_serve_client.cpp), share: the game's fingerprint, the match's description in the welcome
// ("scenario=NAME seed=S players=N count=C", space-separated), and the clock.
#pragma once

#include <chrono>
#include <cstdint>
#include <exception>
#include <span>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <detsim/core/hash.hpp>
#include <detsim/core/status.hpp>
#include <detsim/core/version.hpp>
#include <detsim/scenes/scenario.hpp>

namespace detsim::cli::serve_detail {

using Clock = std::chrono::steady_clock;

inline constexpr std::string_view serve_name = "serve";

/// What a server and its clients must both run: this detsim's built-in scenarios.
inline std::uint64_t game_fingerprint() {
  const std::string text = "detsim serve " + std::string(version);
  return hash_bytes(std::span<const std::uint8_t>(
      reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
}

struct Description {
  std::string scenario;
  std::uint64_t seed = 1;
  std::uint32_t players = 0;
  std::uint32_t count = 0;
};

inline std::vector<std::uint8_t> describe(const Description& d) {
  const std::string text = "scenario=" + d.scenario + " seed=" + std::to_string(d.seed) +
                           " players=" + std::to_string(d.players) +
                           " count=" + std::to_string(d.count);
  return {text.begin(), text.end()};
}

inline Expected<Description> parse_description(std::span<const std::uint8_t> bytes) {
  std::istringstream in(std::string(bytes.begin(), bytes.end()));
  Description d;
  std::string field;
  bool named = false;
  while (in >> field) {
    const std::size_t eq = field.find('=');
    if (eq == std::string::npos) return Status::error("the server's description is malformed");
    const std::string key = field.substr(0, eq);
    const std::string value = field.substr(eq + 1);
    try {
      if (key == "scenario") {
        d.scenario = value;
        named = true;
      } else if (key == "seed") {
        d.seed = std::stoull(value);
      } else if (key == "players") {
        d.players = static_cast<std::uint32_t>(std::stoul(value));
      } else if (key == "count") {
        d.count = static_cast<std::uint32_t>(std::stoul(value));
      }
    } catch (const std::exception&) {
      return Status::error("the server's description has a bad " + key);
    }
  }
  if (!named) return Status::error("the server's description names no scenario");
  return d;
}

inline Expected<Scenario> build(const Description& d) {
  ScenarioParams params;
  params.seed = d.seed;
  params.players = d.players;
  params.count = d.count;
  return Scenario::create(d.scenario, params);
}

inline std::uint64_t micros_since(Clock::time_point start) {
  return static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::microseconds>(Clock::now() - start).count());
}

}  // namespace detsim::cli::serve_detail
