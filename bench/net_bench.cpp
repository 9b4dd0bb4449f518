// Session costs (docs/NET.md, "Performance"): what a session adds to a game's frame, what it
// sends, and what a rollback costs. Reported, never asserted.
//
//   session_frame/P     poll + advance_frame of every peer of a P-player match over a perfect
//                       simulated network, with a game whose step, save and load cost nothing:
//                       the session's own overhead per peer and frame
//   session_frame_internet/P   the same at 100 ms RTT, jitter and 5% loss (rollbacks included)
//   ..._sealed/P        the same two with a match key: every datagram sealed and opened
//                       (ChaCha20-Poly1305, the replay window)
//   seal_open           sealing, then checking the window of and opening, one typical input
//                       datagram (a 15-byte body): the protection's cost per datagram
//   step_pile_1000      one World::step of the 1000-box pile, mid-fall: the reference
//   rollback_8          ScenarioGame on that pile: load, then 8 x (advance + save) - what a
//                       session does for an 8-frame rollback
//   bandwidth/P/S       a 60 s, P-player match (4-byte inputs, 5% loss, 100 ms RTT), plain
//                       (S = 0) or sealed (S = 1): payload bytes per second peer 0 sends, per
//                       remote peer and in all (counters; the time is irrelevant)
#include <benchmark/benchmark.h>

#include <array>
#include <memory>
#include <optional>
#include <vector>

#include <detsim/net/protection.hpp>
#include <detsim/net/protocol.hpp>
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

  Match(std::uint32_t players, const net::LinkConditions& link, bool sealed = false) {
    network.emplace(net::SimNetwork::create(players, 3, link).value());
    for (std::uint32_t p = 0; p < players; ++p) {
      games.push_back(std::make_unique<NullGame>());
      net::SessionConfig c;
      c.players = players;
      c.local_player = p;
      c.input_size = 4;
      if (sealed) {
        c.match_key.emplace();
        for (std::size_t i = 0; i < c.match_key->size(); ++i)
          (*c.match_key)[i] = static_cast<std::uint8_t>(i + 1);
      }
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

void session_frame(benchmark::State& state, const net::LinkConditions& link, bool sealed = false) {
  const auto players = static_cast<std::uint32_t>(state.range(0));
  Match m(players, link, sealed);
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
void session_frame_perfect_sealed(benchmark::State& state) {
  session_frame(state, {}, true);
}
void session_frame_internet_sealed(benchmark::State& state) {
  session_frame(state, net::internet_link(), true);
}
BENCHMARK(session_frame_perfect)->Name("session_frame")->Arg(2)->Arg(4)->Arg(8);
BENCHMARK(session_frame_internet)->Name("session_frame_internet")->Arg(2)->Arg(4)->Arg(8);
BENCHMARK(session_frame_perfect_sealed)->Name("session_frame_sealed")->Arg(2)->Arg(4)->Arg(8);
BENCHMARK(session_frame_internet_sealed)
    ->Name("session_frame_internet_sealed")
    ->Arg(2)
    ->Arg(4)
    ->Arg(8);

void seal_open(benchmark::State& state) {
  namespace protection = net::protection;
  net::MatchKey match_key{};
  match_key[0] = 1;
  const protection::Key key = protection::data_key(match_key, 1, 2);
  net::protocol::Packet p;  // a typical input datagram: two held 4-byte inputs, nothing else
  p.header.type = net::protocol::PacketType::input;
  p.input.ack_frame = 1000;
  p.input.check_ack = 990;
  p.input.current_frame = 1003;
  p.input.start_frame = 1002;
  p.input.count = 2;
  p.input.deltas = {3, 0, 0, 0, 1, 0, 0, 0};
  p.input.held_frame = 1000;
  std::vector<std::uint8_t> datagram;
  std::vector<std::uint8_t> body;
  protection::ReplayWindow window;
  std::uint64_t sequence = 0;
  for (auto _ : state) {
    (void)net::protocol::encode_sealed_plaintext(p, static_cast<std::uint32_t>(sequence), 4,
                                                 datagram);
    (void)protection::seal(key, sequence, net::protocol::sealed_data_header_size, datagram);
    const std::uint64_t s = window.expand(static_cast<std::uint32_t>(sequence));
    if (window.fresh(s) &&
        protection::open(key, s, net::protocol::sealed_data_header_size, datagram, body))
      window.accept(s);
    ++sequence;
  }
  state.counters["bytes"] = static_cast<double>(datagram.size());
  if (!protection::available()) state.SkipWithError("built without libsodium");
}
BENCHMARK(seal_open);

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
  const auto players = static_cast<std::uint32_t>(state.range(0));
  const bool sealed = state.range(1) != 0;
  for (auto _ : state) {
    Match m(players, net::internet_link(), sealed);
    for (int i = 0; i < 60 * 60; ++i)
      m.step();
    std::uint64_t bytes = 0;
    std::uint64_t packets = 0;
    for (std::uint32_t q = 1; q < players; ++q) {
      bytes += m.sessions[0].peer_stats(q)->bytes_sent;
      packets += m.sessions[0].peer_stats(q)->packets_sent;
    }
    const double links = players - 1.0;
    // Peer 0's sends, per remote peer (a link) and in all (to every other peer).
    state.counters["bytes_per_s_per_link"] = static_cast<double>(bytes) / links / 60.0;
    state.counters["bytes_per_s_per_peer"] = static_cast<double>(bytes) / 60.0;
    state.counters["packets_per_s_per_link"] = static_cast<double>(packets) / links / 60.0;
    state.counters["bytes_per_packet"] = static_cast<double>(bytes) / static_cast<double>(packets);
  }
}
BENCHMARK(bandwidth)->Args({2, 0})->Args({2, 1})->Args({4, 0})->Args({4, 1})->Iterations(1)->Unit(
    benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
