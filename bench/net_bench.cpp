// Session costs (docs/NET.md, "Performance"): what a session adds to a game's frame, what it
// sends, and what a rollback costs. Reported, never asserted.
//
//   session_frame/P     poll + advance_frame of every peer of a P-player match over a perfect
//                       simulated network, with a game whose step, save and load cost nothing:
//                       the session's own overhead per peer and frame
//   session_frame_internet/P   the same at 100 ms RTT, jitter and 5% loss (rollbacks included)
//   step_pile_1000      one World::step of the 1000-box pile, mid-fall: the reference
//   rollback_8          ScenarioGame on that pile: load, then 8 x (advance + save) - what a
//                       session does for an 8-frame rollback
//   bandwidth           a 60 s, 4-player match (4-byte inputs, 5% loss, 100 ms RTT): payload
//                       bytes per second peer 0 sends, per remote peer and in all (counters;
//                       the time is irrelevant)
#include <benchmark/benchmark.h>

#include <array>
#include <memory>
#include <optional>
#include <vector>

#include <detsim/net/session.hpp>
#include <detsim/net/sim_network.hpp>
#include <detsim/scenario_net/scenario_game.hpp>
#include <detsim/scenes/scenario.hpp>

namespace {

using namespace detsim;

/// A game that costs (almost) nothing: the session's overhead is all that is measured.
class NullGame final : public net::Game {
 public:
  std::uint64_t save(std::vector<std::uint8_t>& state) override {
    state.assign(8, static_cast<std::uint8_t>(frame_));
    return frame_ * 0x9E3779B97F4A7C15ULL + acc_;
  }
  void load(std::span<const std::uint8_t> state) override { frame_ = state.empty() ? 0 : state[0]; }
  void advance(const net::FrameInputs& inputs, bool) override {
    for (std::uint8_t b : inputs.bytes)
      acc_ += b;
    ++frame_;
  }

 private:
  std::uint64_t frame_ = 0;
  std::uint64_t acc_ = 0;
};

/// P sessions over one SimNetwork, ticked in virtual time.
struct Match {
  std::optional<net::SimNetwork> network;
  std::vector<std::unique_ptr<NullGame>> games;
  std::vector<net::Session> sessions;
  std::uint64_t tick = 0;

  Match(std::uint32_t players, const net::LinkConditions& link) {
    network.emplace(net::SimNetwork::create(players, 3, link).value());
    for (std::uint32_t p = 0; p < players; ++p) {
      games.push_back(std::make_unique<NullGame>());
      net::SessionConfig c;
      c.players = players;
      c.local_player = p;
      c.input_size = 4;
      for (std::uint32_t q = 0; q < players; ++q)
        if (q != p) c.remotes.push_back({q, q});
      sessions.push_back(net::Session::create(c, *games.back(), network->endpoint(p)).value());
    }
  }

  void step() {
    const std::uint64_t now = tick * 16'667;
    network->advance_to(now);
    std::array<std::uint8_t, 4> input{};
    for (std::uint32_t p = 0; p < sessions.size(); ++p) {
      const PlayerInput bot = scripted_input(5, tick, p);
      encode_input(bot, std::span<std::uint8_t, 3>(input.data(), 3));
      sessions[p].poll(now);
      (void)sessions[p].advance_frame(input);
    }
    ++tick;
  }
};

void session_frame(benchmark::State& state, const net::LinkConditions& link) {
  const auto players = static_cast<std::uint32_t>(state.range(0));
  Match m(players, link);
  for (int i = 0; i < 120; ++i)
    m.step();  // past the handshake
  for (auto _ : state)
    m.step();
  state.counters["per_peer_frame_ns"] = benchmark::Counter(
      static_cast<double>(players),
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["rollbacks_per_frame"] = benchmark::Counter(
      static_cast<double>(m.sessions[0].stats().rollbacks) / static_cast<double>(m.tick));
}

void session_frame_perfect(benchmark::State& state) {
  session_frame(state, {});
}
void session_frame_internet(benchmark::State& state) {
  session_frame(state, net::internet_link());
}
BENCHMARK(session_frame_perfect)->Name("session_frame")->Arg(2)->Arg(4)->Arg(8);
BENCHMARK(session_frame_internet)->Name("session_frame_internet")->Arg(2)->Arg(4)->Arg(8);

/// The 1000-box pile at frame 60 (falling, in contact with the ground and each other).
std::vector<std::uint8_t> pile_state() {
  ScenarioParams params;
  params.count = 1000;
  Scenario scenario = Scenario::create("pile_boxes", params).value();
  for (int i = 0; i < 60; ++i)
    scenario.step();
  return scenario.world().save();
}

void step_pile_1000(benchmark::State& state) {
  const std::vector<std::uint8_t> saved = pile_state();
  ScenarioParams params;
  params.count = 1000;
  Scenario scenario = Scenario::create("pile_boxes", params).value();
  for (auto _ : state) {
    state.PauseTiming();
    (void)scenario.world().restore(saved);
    state.ResumeTiming();
    scenario.step();
  }
}
BENCHMARK(step_pile_1000)->Unit(benchmark::kMillisecond);

void rollback_8(benchmark::State& state) {
  const std::vector<std::uint8_t> saved = pile_state();
  ScenarioParams params;
  params.count = 1000;
  Scenario scenario = Scenario::create("pile_boxes", params).value();
  net::ScenarioGame game(scenario);
  std::vector<std::uint8_t> buffer;
  for (auto _ : state) {
    game.load(saved);
    for (int i = 0; i < 8; ++i) {
      game.advance(net::FrameInputs{}, true);
      benchmark::DoNotOptimize(game.save(buffer));
    }
  }
}
BENCHMARK(rollback_8)->Unit(benchmark::kMillisecond);

void bandwidth(benchmark::State& state) {
  for (auto _ : state) {
    Match m(4, net::internet_link());
    for (int i = 0; i < 60 * 60; ++i)
      m.step();
    std::uint64_t bytes = 0;
    std::uint64_t packets = 0;
    for (std::uint32_t q = 1; q < 4; ++q) {
      bytes += m.sessions[0].peer_stats(q)->bytes_sent;
      packets += m.sessions[0].peer_stats(q)->packets_sent;
    }
    // Peer 0's sends, per remote peer (a link) and in all (to three peers).
    state.counters["bytes_per_s_per_link"] = static_cast<double>(bytes) / 3.0 / 60.0;
    state.counters["bytes_per_s_per_peer"] = static_cast<double>(bytes) / 60.0;
    state.counters["packets_per_s_per_link"] = static_cast<double>(packets) / 3.0 / 60.0;
    state.counters["bytes_per_packet"] = static_cast<double>(bytes) / static_cast<double>(packets);
  }
}
BENCHMARK(bandwidth)->Iterations(1)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
