// The game server's figures (docs/SERVER.md, "Figures"; issue 25): bandwidth per client under
// each authority, what a slow client does to the others, and what the server costs per client.
// Every match runs a server and its clients over the simulated network in virtual time (1 ms
// ticks), each client with its own game and its own scripted bot; the counters are the figures,
// the time is only the run's.
//
//   inputs_arena/8         input authority, arena, 8 clients, 60 s (3600 frames), 50 ms each way,
//                          10 ms jitter, 2% loss, updates at 20 Hz: bytes per second down and up
//                          per client, corrections per client
//   slow_client/8/MS       the same match, 1200 frames, with client 7 MS ms away each way (the
//                          others 25 ms): the most any other client re-simulated, and client 7's
//   state_cubes/MODE/U     state authority, the cubes scene (900 cubes), one client driving the
//                          large cube, 60 snapshots per second, 60 s, 50 ms each way, 1% loss:
//                          kbit/s down, bit-exact (its final state hashes as the server's, no
//                          desync); snapshots coded as the state against the newest acknowledged
//                          (MODE 0), as the game's delta against it (1), as the game's delta
//                          chained to the one sent before (2, the default); units and hashes every
//                          U frames
//   p2p_arena/8/MODE       the inputs_arena match played peer to peer instead, rollback (0) or
//                          lockstep (1) sessions, input delay 2: the same figures per peer
//   server_cost/64         input authority, arena with 64 players, 64 clients, 300 frames: the
//                          server's CPU time per client per frame beside one step of the scene
//                          (the server's game timed apart from the rest of the server's work),
//                          and the bytes per client
// Bench code is not simulation code: double and the clock are used freely here.
#include <benchmark/benchmark.h>

#include <time.h>  // clock_gettime, CLOCK_THREAD_CPUTIME_ID (POSIX)

#include <algorithm>
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <detsim/net/client.hpp>
#include <detsim/net/server.hpp>
#include <detsim/net/session.hpp>
#include <detsim/net/sim_network.hpp>
#include <detsim/scenario_net/scenario_game.hpp>
#include <detsim/scenes/scenario.hpp>

namespace {

using namespace detsim;
namespace sp = net::server_protocol;

double thread_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + double(t.tv_nsec) * 1e-9;
}

/// A game that times what it is asked to do (the server's simulation, apart from its network).
class TimedGame final : public net::Game {
 public:
  explicit TimedGame(net::Game& inner) : inner_(inner) {}
  std::uint64_t save(std::vector<std::uint8_t>& state) override {
    const double t0 = thread_seconds();
    const std::uint64_t h = inner_.save(state);
    seconds += thread_seconds() - t0;
    return h;
  }
  void load(std::span<const std::uint8_t> state) override { inner_.load(state); }
  void advance(const net::FrameInputs& inputs, bool resimulating) override {
    const double t0 = thread_seconds();
    inner_.advance(inputs, resimulating);
    const double t = thread_seconds() - t0;
    seconds += t;
    step_seconds += t;
  }
  bool encode_delta(std::span<const std::uint8_t> state, std::span<const std::uint8_t> base,
                    std::vector<std::uint8_t>& delta) override {
    const double t0 = thread_seconds();
    const bool coded = code_deltas && inner_.encode_delta(state, base, delta);
    delta_seconds += thread_seconds() - t0;
    return coded;
  }
  bool decode_delta(std::span<const std::uint8_t> delta, std::span<const std::uint8_t> base,
                    std::vector<std::uint8_t>& state) override {
    return inner_.decode_delta(delta, base, state);
  }
  double seconds = 0;        ///< in advance and save
  double step_seconds = 0;   ///< in advance alone
  double delta_seconds = 0;  ///< in encode_delta
  bool code_deltas = true;

 private:
  net::Game& inner_;
};

struct Side {
  std::unique_ptr<Scenario> scenario;
  std::unique_ptr<net::ScenarioGame> game;
};

Side make_side(const std::string& name, std::uint32_t players, std::uint32_t count) {
  ScenarioParams params;
  params.seed = 1;
  params.players = players;
  params.count = count;
  Side s;
  s.scenario = std::make_unique<Scenario>(Scenario::create(name, params).value());
  s.game = std::make_unique<net::ScenarioGame>(*s.scenario);
  return s;
}

struct MatchSetup {
  std::string scenario = "arena";
  std::uint32_t count = 0;
  std::uint32_t clients = 8;
  std::uint32_t frames = 3600;
  sp::Authority authority = sp::Authority::inputs;
  std::uint32_t update_interval = 3;
  std::uint32_t snapshot_interval = 1;
  net::LinkConditions link{};
  std::optional<std::pair<std::uint32_t, std::uint32_t>> slow;  ///< (client, latency us)
  /// Client c's bot: scripted input (seed c + 1); `drive_only_first` leaves the others idle.
  bool drive_only_first = false;
  bool chain_snapshots = true;  ///< ServerConfig::chain_snapshots
  bool game_deltas = true;      ///< the server's game codes deltas (Game::encode_delta)
};

struct MatchResult {
  bool agreed = true;  ///< every client ended on the server's final hash, no desync
  std::vector<net::ServerClientStats> server_side;
  std::vector<net::ClientStats> clients;
  double server_seconds = 0;  ///< the server's CPU time, its game included
  double game_seconds = 0;    ///< its game's (advance and save)
  double step_seconds = 0;    ///< its game's advance alone
  double delta_seconds = 0;   ///< its game's encode_delta
  std::uint64_t frames = 0;
};

MatchResult play(const MatchSetup& m) {
  auto network = net::SimNetwork::create(m.clients + 1, 7, m.link).value();
  if (m.slow) {
    net::LinkConditions slow = m.link;
    slow.latency_us = m.slow->second;
    (void)network.set_link(0, m.slow->first + 1, slow);
    (void)network.set_link(m.slow->first + 1, 0, slow);
  }
  Side server_side = make_side(m.scenario, m.clients, m.count);
  TimedGame timed(*server_side.game);
  timed.code_deltas = m.game_deltas;
  net::ServerConfig config;
  config.players = m.clients;
  config.input_size = server_side.game->input_size();
  config.game = 25;
  config.frames = m.frames;
  config.authority = m.authority;
  config.update_interval = m.update_interval;
  config.snapshot_interval = m.snapshot_interval;
  config.chain_snapshots = m.chain_snapshots;
  config.start_clients = m.clients;
  net::Server server = net::Server::create(config, timed, network.endpoint(0)).value();
  std::vector<Side> sides;
  std::vector<net::Client> clients;
  for (std::uint32_t c = 0; c < m.clients; ++c) {
    sides.push_back(make_side(m.scenario, m.clients, m.count));
    net::ClientConfig cc;
    cc.game = 25;
    clients.push_back(net::Client::create(cc, network.endpoint(c + 1)).value());
  }
  std::vector<std::uint64_t> next(m.clients, 0);
  std::vector<std::uint64_t> ticks(m.clients, 0);
  std::vector<std::uint8_t> input(server_side.game->input_size());
  MatchResult r;
  const std::uint64_t max_ms = std::uint64_t{m.frames} * 17 * 3 + 20'000;
  std::optional<std::uint64_t> settled;
  for (std::uint64_t ms = 0; ms < max_ms; ++ms) {
    const std::uint64_t now = ms * 1000;
    network.advance_to(now);
    if (!settled || ms < *settled + 500) {
      const double t0 = thread_seconds();
      server.poll(now);
      server.advance(now);
      server.poll(now);
      r.server_seconds += thread_seconds() - t0;
      if (!settled && server.settled()) settled = ms;
    }
    bool all = server.settled();
    for (std::uint32_t c = 0; c < m.clients; ++c) {
      net::Client& client = clients[c];
      client.poll(now);
      if (client.welcome() != nullptr && !client.started()) (void)client.start(*sides[c].game);
      if (client.running() && now >= next[c]) {
        next[c] = std::max(next[c] + client.welcome()->frame_us, now);
        ++ticks[c];
        const std::int32_t adjust = client.recommended_frame_adjust();
        int runs = 1;
        if (ticks[c] % 3 == 0 && adjust > 0) runs = adjust > 4 ? 3 : 2;
        if (ticks[c] % 3 == 0 && adjust < 0) runs = 0;
        for (int k = 0; k < runs; ++k) {
          std::fill(input.begin(), input.end(), std::uint8_t{0});
          if (!m.drive_only_first || c == 0)
            sides[c].scenario->scripted(c + 1, client.current_frame(), c, input);
          (void)client.advance_frame(input);
        }
      }
      all = all && client.ended();
    }
    if (all) break;
  }
  r.frames = server.current_frame();
  r.game_seconds = timed.seconds;
  r.step_seconds = timed.step_seconds;
  r.delta_seconds = timed.delta_seconds;
  r.server_side = server.client_stats();
  for (std::uint32_t c = 0; c < m.clients; ++c) {
    std::vector<std::uint8_t> state;
    r.agreed = r.agreed && clients[c].ended() && clients[c].stats().desyncs == 0 &&
               sides[c].game->save(state) == server.current_hash();
    r.clients.push_back(clients[c].stats());
  }
  return r;
}

void report_bandwidth(benchmark::State& state, const MatchResult& r) {
  const double seconds = static_cast<double>(r.frames) / 60.0;
  double down = 0;
  double up = 0;
  double corrections = 0;
  for (const net::ServerClientStats& c : r.server_side) {
    down += static_cast<double>(c.bytes_sent);
    up += static_cast<double>(c.bytes_received);
  }
  for (const net::ClientStats& c : r.clients)
    corrections += static_cast<double>(c.corrections);
  double resimulated = 0;
  for (const net::ClientStats& c : r.clients)
    resimulated += static_cast<double>(c.resimulated_frames);
  const double n = static_cast<double>(r.server_side.size());
  state.counters["resimulated_per_client"] = resimulated / n;
  state.counters["down_bytes_per_s"] = down / n / seconds;
  state.counters["down_kbit_per_s"] = down / n / seconds * 8 / 1000;
  state.counters["up_bytes_per_s"] = up / n / seconds;
  state.counters["corrections_per_client"] = corrections / n;
  state.counters["agreed"] = r.agreed ? 1 : 0;
}

void BM_InputsArena(benchmark::State& state) {
  MatchSetup m;
  m.clients = static_cast<std::uint32_t>(state.range(0));
  m.link.latency_us = 50'000;
  m.link.jitter_us = 10'000;
  m.link.loss_ppm = 20'000;
  MatchResult r;
  for (auto _ : state)
    r = play(m);
  report_bandwidth(state, r);
}
BENCHMARK(BM_InputsArena)->Name("inputs_arena")->Arg(8)->Iterations(1)->Unit(benchmark::kSecond);

void BM_SlowClient(benchmark::State& state) {
  MatchSetup m;
  m.clients = 8;
  m.frames = 1200;
  m.link.latency_us = 25'000;
  m.link.jitter_us = 5'000;
  m.slow = std::make_pair(7U, static_cast<std::uint32_t>(state.range(0)) * 1000);
  MatchResult r;
  for (auto _ : state)
    r = play(m);
  double others = 0;
  for (std::size_t c = 0; c + 1 < r.clients.size(); ++c)
    others = std::max(others, static_cast<double>(r.clients[c].resimulated_frames));
  state.counters["most_resimulated_by_others"] = others;
  state.counters["slow_client_resimulated"] =
      static_cast<double>(r.clients.back().resimulated_frames);
  state.counters["slow_client_inputs_late"] = static_cast<double>(r.server_side.back().inputs_late);
  state.counters["agreed"] = r.agreed ? 1 : 0;
}
BENCHMARK(BM_SlowClient)
    ->Name("slow_client/8")
    ->Arg(50)
    ->Arg(200)
    ->Iterations(1)
    ->Unit(benchmark::kSecond);

void BM_StateCubes(benchmark::State& state) {
  MatchSetup m;
  m.scenario = "cubes";
  m.clients = 1;
  m.authority = sp::Authority::state;
  m.snapshot_interval = 1;
  m.update_interval = static_cast<std::uint32_t>(state.range(1));
  m.link.latency_us = 50'000;
  m.link.jitter_us = 5'000;
  m.link.loss_ppm = 10'000;
  m.game_deltas = state.range(0) >= 1;
  m.chain_snapshots = state.range(0) >= 2;
  MatchResult r;
  for (auto _ : state)
    r = play(m);
  report_bandwidth(state, r);
  double received = 0;
  double received_bytes = 0;
  for (const net::ClientStats& c : r.clients) {
    received += static_cast<double>(c.snapshots_received);
    received_bytes += static_cast<double>(c.snapshot_bytes_received);
  }
  double sent = 0;
  double coded = 0;
  double chained = 0;
  for (const net::ServerClientStats& c : r.server_side) {
    sent += static_cast<double>(c.snapshots_sent);
    coded += static_cast<double>(c.snapshots_game_coded);
    chained += static_cast<double>(c.snapshots_chained);
  }
  state.counters["snapshots_sent"] = sent;
  state.counters["snapshots_received"] = received;
  state.counters["snapshots_game_coded"] = coded;
  state.counters["snapshots_chained"] = chained;
  // Every snapshot that arrived whole, decodable or not.
  state.counters["bytes_per_snapshot"] = sent > 0 ? received_bytes / sent : 0;
  // The server's own work per snapshot (its game's step and save apart): coding and compressing.
  state.counters["server_ms_per_snapshot"] =
      sent > 0 ? (r.server_seconds - r.game_seconds) / sent * 1e3 : 0;
  state.counters["delta_ms_per_snapshot"] = sent > 0 ? r.delta_seconds / sent * 1e3 : 0;
  state.counters["step_ms"] = r.step_seconds / static_cast<double>(r.frames) * 1e3;
}
BENCHMARK(BM_StateCubes)
    ->Name("state_cubes")
    ->ArgsProduct({{0, 1, 2}, {1}})
    ->Args({2, 3})
    ->Iterations(1)
    ->Unit(benchmark::kSecond);

/// The inputs_arena match, peer to peer: 8 sessions over the same links, each with its own game
/// and bot, in virtual time; per peer what it sends and receives, its rollbacks and stalls.
void BM_PeerToPeer(benchmark::State& state) {
  const std::uint32_t players = 8;
  const bool lockstep = state.range(0) != 0;
  net::LinkConditions link;
  link.latency_us = 50'000;
  link.jitter_us = 10'000;
  link.loss_ppm = 20'000;
  const std::uint64_t frames = 3600;
  double sent = 0;
  double received = 0;
  double rollbacks = 0;
  double resimulated = 0;
  double stalls = 0;
  bool agreed = true;
  for (auto _ : state) {
    auto network = net::SimNetwork::create(players, 7, link).value();
    std::vector<Side> sides;
    std::vector<net::Session> sessions;
    std::vector<std::uint64_t> final_hash(players, 0);
    for (std::uint32_t p = 0; p < players; ++p) {
      sides.push_back(make_side("arena", players, 0));
      net::SessionConfig c;
      c.mode = lockstep ? net::SessionMode::lockstep : net::SessionMode::rollback;
      c.players = players;
      c.local_player = p;
      c.input_size = sides.back().game->input_size();
      c.max_prediction = 16;
      for (std::uint32_t q = 0; q < players; ++q)
        if (q != p) c.remotes.push_back({q, q});
      sessions.push_back(net::Session::create(c, *sides.back().game, network.endpoint(p)).value());
      sessions.back().set_confirmed_listener(
          [&final_hash, p, frames](const net::ConfirmedFrame& f) {
            if (f.frame + 1 == frames) final_hash[p] = f.hash;
          });
    }
    std::vector<std::uint64_t> next(players, 0);
    std::vector<std::uint64_t> ticks(players, 0);
    std::vector<std::uint8_t> input(sides[0].game->input_size());
    for (std::uint64_t ms = 0; ms < frames * 17 * 3 + 20'000; ++ms) {
      const std::uint64_t now = ms * 1000;
      network.advance_to(now);
      bool done = true;
      for (std::uint32_t p = 0; p < players; ++p) {
        net::Session& s = sessions[p];
        s.poll(now);
        done = done && s.delivered_frame() >= frames;
        if (!s.running() || s.current_frame() >= frames || now < next[p]) continue;
        next[p] = std::max(next[p] + 16'667, now);
        if (s.recommended_wait_frames() > 0 && ++ticks[p] % 3 == 0) continue;
        sides[p].scenario->scripted(p + 1, s.current_frame() + 2, p, input);
        auto r = s.advance_frame(input);
        if (r.ok() && r.value() != net::Advance::advanced) stalls += 1;
      }
      if (done) break;
    }
    for (std::uint32_t p = 0; p < players; ++p) {
      for (std::uint32_t q = 0; q < players; ++q) {
        if (q == p) continue;
        const net::PeerStats st = sessions[p].peer_stats(q).value();
        sent += static_cast<double>(st.bytes_sent);
        received += static_cast<double>(st.bytes_received);
      }
      rollbacks += static_cast<double>(sessions[p].stats().rollbacks);
      resimulated += static_cast<double>(sessions[p].stats().resimulated_frames);
      agreed = agreed && final_hash[p] != 0 && final_hash[p] == final_hash[0];
    }
  }
  const double seconds = static_cast<double>(frames) / 60.0;
  state.counters["down_bytes_per_s"] = received / players / seconds;
  state.counters["up_bytes_per_s"] = sent / players / seconds;
  state.counters["rollbacks_per_peer"] = rollbacks / players;
  state.counters["resimulated_per_peer"] = resimulated / players;
  state.counters["stalls_per_peer"] = stalls / players;
  state.counters["agreed"] = agreed ? 1 : 0;
}
BENCHMARK(BM_PeerToPeer)
    ->Name("p2p_arena/8")
    ->Arg(0)
    ->Arg(1)
    ->Iterations(1)
    ->Unit(benchmark::kSecond);

void BM_ServerCost(benchmark::State& state) {
  MatchSetup m;
  m.clients = static_cast<std::uint32_t>(state.range(0));
  m.frames = 300;
  m.link.latency_us = 30'000;
  m.link.jitter_us = 5'000;
  m.link.loss_ppm = 10'000;
  MatchResult r;
  for (auto _ : state)
    r = play(m);
  const double frames = static_cast<double>(r.frames);
  const double per_client_frame =
      (r.server_seconds - r.game_seconds) / frames / static_cast<double>(m.clients);
  const double step = r.step_seconds / frames;
  state.counters["step_us"] = step * 1e6;
  state.counters["server_us_per_client_per_frame"] = per_client_frame * 1e6;
  state.counters["per_client_percent_of_step"] = 100.0 * per_client_frame / step;
  state.counters["save_us"] = (r.game_seconds - r.step_seconds) / frames * 1e6;
  report_bandwidth(state, r);  // bytes per client (and agreed)
}
BENCHMARK(BM_ServerCost)->Name("server_cost")->Arg(64)->Iterations(1)->Unit(benchmark::kSecond);

}  // namespace

BENCHMARK_MAIN();
