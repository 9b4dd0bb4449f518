// detsim serve: the server of a server-authoritative match of a scenario over UDP (net::Server;
// docs/SERVER.md).
//
// The server binds a socket that admits unknown senders, builds the scenario, and runs the match
// on its clock: it starts when --wait-for clients are in (default: every seat), simulates frame
// after frame without waiting for anyone, and stops once the last frame is simulated and every
// connected client has acknowledged it (or --timeout after the last frame). Clients learn the
// scenario, seed and players from its welcome: the description "scenario=NAME seed=S players=N
// count=C", space-separated.
//
// Its clients, `detsim netplay --server`, are in cmd_serve_client.cpp.
//
// SIGTERM ends the server's match where it is: the replay is closed, the report printed, exit 0.
// With --agones the server also speaks to the Agones SDK sidecar (agones.hpp): ready once bound,
// health while it makes progress, the outcome as annotations, then shutdown.
#include <signal.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <detsim/core/hash.hpp>
#include <detsim/core/version.hpp>
#include <detsim/net/client.hpp>
#include <detsim/net/server.hpp>
#include <detsim/net/udp.hpp>
#include <detsim/replay/desync_report.hpp>
#include <detsim/replay/replay.hpp>
#include <detsim/scenario_net/scenario_game.hpp>
#include <detsim/scenario_net/scenario_recorder.hpp>

#include "commands.hpp"
#include "netplay_plan.hpp"
#if DETSIM_WITH_AGONES
#include "agones.hpp"
#endif
#include "output.hpp"
#include "scenario_args.hpp"
#include "serve_match.hpp"

namespace detsim::cli {

namespace {

namespace sp = net::server_protocol;
using namespace serve_detail;

/// This process's CPU time so far (user and system), in seconds.
double cpu_seconds() {
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0.0;
  const auto seconds = [](const timeval& t) {
    return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_usec) / 1e6;
  };
  return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

// ---- the server --------------------------------------------------------------------------------

/// The longest pause between a server's polls while no frame is due: 4 ms, or 1 ms under state
/// authority (whose snapshots go out as slices a few per poll).
std::uint64_t serve_idle_us(const ServeArgs& args) {
  return args.authority == "state" ? netplay_idle_sleep_us : 4 * netplay_idle_sleep_us;
}

volatile std::sig_atomic_t sigterm_received = 0;

void on_sigterm(int) {
  sigterm_received = 1;
}

/// SIGTERM sets sigterm_received while the server runs; the previous handler comes back after.
class SigtermFlag {
 public:
  SigtermFlag() {
    sigterm_received = 0;
    struct sigaction action {};
    action.sa_handler = on_sigterm;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESTART;
    sigaction(SIGTERM, &action, &previous_);
  }
  ~SigtermFlag() { sigaction(SIGTERM, &previous_, nullptr); }
  SigtermFlag(const SigtermFlag&) = delete;
  SigtermFlag& operator=(const SigtermFlag&) = delete;

 private:
  struct sigaction previous_ {};
};

class Serve {
 public:
  explicit Serve(const ServeArgs& args) : args_(args) {}
  int run();

 private:
  Status start();
  void say(const std::string& line) const {
    if (!args_.json) std::printf("%s\n", line.c_str());
    std::fflush(stdout);
  }
  /// Frees transport peers that are no client of the server's (strangers, clients gone): a
  /// peer that stayed a stranger for two sweeps in a row.
  void sweep_peers();
  void handle_events();
  /// --agones: the client, and ready (the socket is bound).
  void agones_start();
  /// --agones: what the loop tells the client each time round (see AgonesClient).
  void agones_progress();
  /// --agones: the outcome as annotations, then shutdown (at most 5 s).
  void agones_finish(const std::string& outcome);
  /// --agones: the report's "agones" object, or its text line when `json` is false.
  [[nodiscard]] std::string agones_report(bool json) const;
  int report(double match_seconds);

  const ServeArgs& args_;
  Clock::time_point start_ = Clock::now();
  std::optional<Scenario> scenario_;
  std::optional<net::ScenarioGame> game_;
  std::optional<net::UdpTransport> transport_;
  std::optional<net::ScenarioRecorder> recorder_;
  std::optional<net::Server> server_;
  std::set<net::PeerId> strangers_;
  std::string failure_;
  bool stopped_ = false;  ///< SIGTERM ended the match
#if DETSIM_WITH_AGONES
  std::optional<AgonesClient> agones_;
  AgonesStats agones_stats_;
#endif
};

Status Serve::start() {
  Description d{args_.scenario, args_.seed, args_.players, args_.count};
  auto scenario = build(d);
  if (!scenario) return scenario.status();
  if (scenario->info().max_players == 0)
    return Status::error("--scenario " + args_.scenario + " takes no players");
  scenario_.emplace(std::move(scenario.value()));
  game_.emplace(*scenario_);
  auto bind = net::parse_endpoint(args_.bind);
  if (!bind) return Status::error("--bind " + args_.bind + ": " + bind.message());
  net::UdpOptions options;
  options.admit_unknown_senders = 4 * args_.players + 64;
  auto transport = net::UdpTransport::open(bind.value(), {}, options);
  if (!transport) return transport.status();
  transport_.emplace(std::move(transport.value()));
  if (!args_.record.empty()) {
    auto recorder = net::ScenarioRecorder::create(args_.record, *game_);
    if (!recorder) return recorder.status();
    recorder_.emplace(std::move(recorder.value()));
  }
  net::ServerConfig config;
  config.players = args_.players;
  config.input_size = game_->input_size();
  config.game = game_fingerprint();
  config.description = describe(d);
  config.authority = args_.authority == "state" ? sp::Authority::state : sp::Authority::inputs;
  config.frame_us = 1'000'000 / args_.fps;
  config.frames = static_cast<std::uint32_t>(args_.frames);
  config.start_clients = args_.wait_for;
  const auto interval = static_cast<std::uint32_t>(
      std::clamp(static_cast<double>(args_.fps) / args_.snapshot_rate + 0.5, 1.0, 60.0));
  config.update_interval = interval;
  config.snapshot_interval = interval;
  auto server = net::Server::create(config, *game_, *transport_);
  if (!server) return server.status();
  server_.emplace(std::move(server.value()));
  if (recorder_) recorder_->attach(*server_);
  return Status::success();
}

void Serve::sweep_peers() {
  std::set<net::PeerId> clients;
  for (const net::ServerClientStats& c : server_->client_stats())
    if (c.connected) clients.insert(c.peer);
  std::set<net::PeerId> now;
  std::vector<net::PeerId> remove;
  for (const net::UdpPeer& p : transport_->peers()) {
    if (clients.count(p.id) != 0) continue;
    if (strangers_.count(p.id) != 0) {
      remove.push_back(p.id);
    } else {
      now.insert(p.id);
    }
  }
  for (const net::PeerId id : remove)
    transport_->remove_peer(id);
  strangers_ = std::move(now);
}

void Serve::handle_events() {
  for (const net::ServerEvent& e : server_->take_events()) {
    switch (e.type) {
      case net::ServerEventType::started:
        say("the match starts");
        break;
      case net::ServerEventType::joined:
        say("player " + std::to_string(e.player) + " joined at frame " + std::to_string(e.frame));
        break;
      case net::ServerEventType::left:
        say("player " + std::to_string(e.player) + " left at frame " + std::to_string(e.frame) +
            " (" + std::string(e.reason) + ")");
        break;
    }
  }
}

#if DETSIM_WITH_AGONES
void Serve::agones_start() {
  if (!args_.agones) return;
  AgonesOptions options;
  options.port = agones_port_from_environment().value();  // serve_command checked it
  options.note = [](const std::string& line) {
    std::fprintf(stderr, "%s serve: agones: %s\n", program_name().c_str(), line.c_str());
  };
  agones_.emplace(std::move(options));
  agones_->ready();
}

void Serve::agones_progress() {
  if (!agones_) return;
  if (server_->current_frame() > 0 && !server_->ended()) {
    agones_->advanced(server_->current_frame());
  } else {
    agones_->heartbeat();  // waiting for players, or for the last acknowledgements
  }
}

void Serve::agones_finish(const std::string& outcome) {
  if (!agones_) return;
  agones_->annotation("detsim.final-hash", hex(server_->current_hash()));
  agones_->annotation("detsim.frames", std::to_string(server_->current_frame()));
  agones_->annotation("detsim.outcome", outcome);
  agones_->shutdown();
  agones_stats_ = agones_->stats();
  agones_.reset();
}

std::string Serve::agones_report(bool json) const {
  const AgonesStats& a = agones_stats_;
  if (json)
    return Json()
        .boolean("ready", a.ready)
        .num("health_pings", a.health_pings)
        .boolean("shutdown", a.shutdown)
        .num("calls_sent", a.calls_sent)
        .num("calls_failed", a.calls_failed)
        .num("calls_dropped", a.calls_dropped)
        .text();
  return std::string(a.ready ? "ready" : "never ready") + ", " + std::to_string(a.health_pings) +
         " health pings, " + (a.shutdown ? "shut down" : "shutdown not delivered") + "; " +
         std::to_string(a.calls_sent) + " calls sent, " + std::to_string(a.calls_failed) +
         " failed, " + std::to_string(a.calls_dropped) + " dropped";
}
#else
void Serve::agones_start() {}
void Serve::agones_progress() {}
void Serve::agones_finish(const std::string&) {}
std::string Serve::agones_report(bool) const {
  return {};
}
#endif

int Serve::run() {
  const SigtermFlag sigterm;
  if (Status s = start(); !s) return usage_error(serve_name, s.message());
  agones_start();
  say(args_.scenario + " (seed " + std::to_string(args_.seed) + ", " +
      std::to_string(args_.players) + " seats) served on " +
      transport_->local_endpoint().to_string() + ", authority " + args_.authority + ", " +
      std::to_string(args_.frames) + " frames at " + std::to_string(args_.fps) +
      " fps; waiting for " + std::to_string(args_.wait_for) + " clients");
  const auto timeout_us = static_cast<std::uint64_t>(args_.timeout_seconds * 1e6);
  std::optional<std::uint64_t> started_at;
  std::optional<std::uint64_t> ended_at;
  std::uint64_t next_sweep = 1'000'000;
  const std::uint64_t frame_us = 1'000'000 / args_.fps;
  for (;;) {
    if (sigterm_received != 0) {
      stopped_ = true;
      break;
    }
    const std::uint64_t now = micros_since(start_);
    server_->poll(now);
    server_->advance(now);
    server_->poll(now);
    handle_events();
    agones_progress();
    if (now >= next_sweep) {
      sweep_peers();
      next_sweep = now + 1'000'000;
    }
    if (!started_at && server_->current_frame() > 0) started_at = now;
    if (!started_at && now >= timeout_us) {
      failure_ = "no match: fewer than " + std::to_string(args_.wait_for) +
                 " clients came within " + milliseconds(timeout_us);
      break;
    }
    if (server_->ended()) {
      if (!ended_at) ended_at = now;
      if (server_->settled()) {
        // A last round of updates so that every client has the last frame's acknowledgement.
        const std::uint64_t linger_end = now + netplay_linger_us;
        while (micros_since(start_) < linger_end) {
          server_->poll(micros_since(start_));
          std::this_thread::sleep_for(std::chrono::microseconds(netplay_idle_sleep_us));
        }
        break;
      }
      if (now - *ended_at >= timeout_us) {
        std::fprintf(stderr,
                     "detsim serve: stopped %s after the last frame with clients that had not "
                     "acknowledged it\n",
                     milliseconds(timeout_us).c_str());
        break;
      }
    }
    const std::uint64_t next = started_at ? *started_at + server_->current_frame() * frame_us : 0;
    const std::uint64_t after = micros_since(start_);
    // Until the next frame is due, polling at least every serve_idle_us meanwhile: a server wakes
    // a few hundred times a second rather than a thousand, which is what lets one machine hold
    // dozens of matches (docs/SCALE.md, "Density"). Inputs that arrive in between wait in the
    // socket until the frame's poll, which stamps them no later than polling every millisecond.
    const std::uint64_t idle = serve_idle_us(args_);
    std::this_thread::sleep_for(
        std::chrono::microseconds(next > after ? std::min(next - after, idle) : idle));
  }
  if (recorder_) {
    if (Status s = recorder_->finish(); !s && failure_.empty()) failure_ = s.message();
  }
  agones_finish(stopped_ ? "stopped" : started_at ? "ended" : "no-match");
  if (!failure_.empty()) return usage_error(serve_name, failure_);
  const std::uint64_t end = micros_since(start_);
  return report(static_cast<double>(ended_at.value_or(end) - started_at.value_or(end)) / 1e6);
}

int Serve::report(double match_seconds) {
  const std::vector<net::ServerClientStats> clients = server_->client_stats();
  std::uint64_t sent = 0;
  std::vector<std::string> rows;
  for (const net::ServerClientStats& c : clients) {
    sent += c.bytes_sent;
    const net::UdpPeer* peer = nullptr;
    for (const net::UdpPeer& p : transport_->peers())
      if (p.id == c.peer) peer = &p;
    rows.push_back(Json()
                       .num("player", c.player)
                       .str("address", peer != nullptr ? peer->endpoint.to_string() : "")
                       .boolean("connected", c.connected)
                       .num("joined_frame", c.joined_frame)
                       .num("acknowledged_frame", c.acknowledged_frame)
                       .num("bytes_sent", c.bytes_sent)
                       .num("bytes_received", c.bytes_received)
                       .num("inputs_late", c.inputs_late)
                       .num("inputs_missing", c.inputs_missing)
                       .num("packets_rejected", c.packets_rejected)
                       .num("snapshots_sent", c.snapshots_sent)
                       .text());
  }
  const double per_client =
      clients.empty() || match_seconds <= 0
          ? 0.0
          : static_cast<double>(sent) / static_cast<double>(clients.size()) / match_seconds;
  const net::ServerStats& st = server_->stats();
  std::uint64_t malformed = 0;
  for (const std::uint64_t n : st.dropped_malformed)
    malformed += n;
  if (args_.json) {
    Json j;
    j.str("scenario", args_.scenario)
        .num("seed", args_.seed)
        .num("players", args_.players)
        .str("authority", args_.authority)
        .num("frames", server_->current_frame())
        .hash("final_hash", server_->current_hash())
        .raw("clients", Json::array(rows))
        .real("bytes_sent_per_client_per_second", per_client)
        .num("dropped_malformed", malformed)
        .num("dropped_unknown", st.dropped_unknown)
        .real("match_seconds", match_seconds)
        .raw("tick_lateness_us", Json()
                                     .num("p50", st.tick_lateness_percentile_us(500))
                                     .num("p99", st.tick_lateness_percentile_us(990))
                                     .num("max", st.tick_lateness_max_us)
                                     .text())
        .real("cpu_seconds", cpu_seconds());
    if (args_.record.empty()) {
      j.null("record");
    } else {
      j.str("record", args_.record);
    }
    if (stopped_) j.str("stopped", "SIGTERM");
    if (args_.agones) j.raw("agones", agones_report(true));
    j.print();
    return exit_ok;
  }
  std::printf("frames       %llu, final hash %s\n",
              static_cast<unsigned long long>(server_->current_frame()),
              hex(server_->current_hash()).c_str());
  for (const net::ServerClientStats& c : clients)
    std::printf(
        "player %-4u  %s; %llu bytes sent, %llu received; inputs %llu late, %llu "
        "missing; %llu packets rejected\n",
        c.player, c.connected ? "connected" : "gone", static_cast<unsigned long long>(c.bytes_sent),
        static_cast<unsigned long long>(c.bytes_received),
        static_cast<unsigned long long>(c.inputs_late),
        static_cast<unsigned long long>(c.inputs_missing),
        static_cast<unsigned long long>(c.packets_rejected));
  std::printf("down         %.0f bytes/s per client; dropped %llu malformed, %llu unknown\n",
              per_client, static_cast<unsigned long long>(malformed),
              static_cast<unsigned long long>(st.dropped_unknown));
  std::printf(
      "ticks        late by %llu us or less for 99%% of frames (at most %llu us); %.2f s "
      "of CPU\n",
      static_cast<unsigned long long>(st.tick_lateness_percentile_us(990)),
      static_cast<unsigned long long>(st.tick_lateness_max_us), cpu_seconds());
  if (!args_.record.empty()) std::printf("replay       %s\n", args_.record.c_str());
  if (stopped_)
    std::printf("stopped      by SIGTERM at frame %llu of %llu\n",
                static_cast<unsigned long long>(server_->current_frame()),
                static_cast<unsigned long long>(args_.frames));
  if (args_.agones) std::printf("agones       %s\n", agones_report(false).c_str());
  return exit_ok;
}

}  // namespace

int serve_command(const ServeArgs& args) {
  if (args.frames == 0 || args.frames > 100'000'000)
    return usage_error(serve_name,
                       "--frames must be 1 .. 100000000, got " + std::to_string(args.frames));
  if (args.players < 1 || args.players > sp::max_players)
    return usage_error(serve_name, "--players must be 1 .. " + std::to_string(sp::max_players) +
                                       ", got " + std::to_string(args.players));
  if (args.wait_for > args.players)
    return usage_error(
        serve_name, "--wait-for must be at most --players (" + std::to_string(args.players) + ")");
  if (args.authority != "inputs" && args.authority != "state")
    return usage_error(serve_name,
                       "--authority must be inputs or state, got '" + args.authority + "'");
  if (args.fps < 1 || args.fps > 1000)
    return usage_error(serve_name, "--fps must be 1 .. 1000, got " + std::to_string(args.fps));
  if (!(args.snapshot_rate > 0 && args.snapshot_rate <= static_cast<double>(args.fps)))
    return usage_error(serve_name, "--snapshot-rate must be above 0 and at most --fps");
  if (!(args.timeout_seconds > 0 && args.timeout_seconds <= 86'400))
    return usage_error(serve_name, "--timeout must be more than 0 and at most 86400 seconds");
#if DETSIM_WITH_AGONES
  if (args.agones) {
    if (auto port = agones_port_from_environment(); !port)
      return usage_error(serve_name, "--agones: " + port.message());
  }
#else
  if (args.agones)
    return usage_error(serve_name,
                       "--agones: built without cpp-httplib (Debian libcpp-httplib-dev)");
#endif
  Serve serve(args);
  return serve.run();
}

}  // namespace detsim::cli
