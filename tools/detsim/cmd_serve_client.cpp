// detsim netplay --server: a client of a server-authoritative match (net::Client over UDP;
// docs/SERVER.md). The server is `detsim serve` (cmd_serve.cpp).
//
// The client learns the scenario, seed and players from the server's welcome, predicts with the
// scripted bot's input (--bot) or none, keeps its inputs a couple of frames ahead of the server
// (Client::recommended_frame_adjust: one frame extra or skipped, one tick in three), and stops once
// it has simulated the last frame with the server's inputs and compared the server's hash of the
// last state.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <detsim/net/client.hpp>
#include <detsim/net/server_protocol.hpp>
#include <detsim/net/udp.hpp>
#include <detsim/replay/desync_report.hpp>
#include <detsim/replay/replay.hpp>
#include <detsim/scenario_net/scenario_game.hpp>

#include "commands.hpp"
#include "netplay_plan.hpp"
#include "output.hpp"
#include "scenario_args.hpp"
#include "serve_match.hpp"

namespace detsim::cli {

namespace {

namespace sp = net::server_protocol;
using namespace serve_detail;

class ServerClient {
 public:
  explicit ServerClient(const NetplayArgs& args) : args_(args) {}
  int run();

 private:
  Status begin();
  /// Builds the scenario the welcome describes and starts the client on it.
  Status start_game();
  void say(const std::string& line) const {
    if (!args_.json) std::printf("%s\n", line.c_str());
    std::fflush(stdout);
  }
  void advance();
  /// --desync-report: this machine's side of its first desync, for `detsim bisect` beside the
  /// server's replay.
  void write_desync_report();
  int report(double seconds);

  const NetplayArgs& args_;
  Clock::time_point start_ = Clock::now();
  std::optional<net::UdpTransport> transport_;
  std::optional<net::Client> client_;
  std::optional<Scenario> scenario_;
  std::optional<net::ScenarioGame> game_;
  std::optional<replay::Fingerprint> initial_fingerprint_;
  bool report_written_ = false;
  std::vector<net::ClientEvent> desyncs_;
  std::uint64_t ticks_ = 0;
  std::string failure_;
};

Status ServerClient::begin() {
  auto bind = net::parse_endpoint(args_.bind);
  if (!bind) return Status::error("--bind " + args_.bind + ": " + bind.message());
  auto server = net::parse_endpoint(args_.server);
  if (!server) return Status::error("--server " + args_.server + ": " + server.message());
  const net::UdpPeer peer{0, server.value()};
  auto transport = net::UdpTransport::open(bind.value(), std::span<const net::UdpPeer>(&peer, 1));
  if (!transport) return transport.status();
  transport_.emplace(std::move(transport.value()));
  net::ClientConfig config;
  config.game = game_fingerprint();
  config.server = 0;
  if (args_.seat_given) config.seat = static_cast<std::uint8_t>(args_.me);
  auto client = net::Client::create(config, *transport_);
  if (!client) return client.status();
  client_.emplace(std::move(client.value()));
  return Status::success();
}

Status ServerClient::start_game() {
  const sp::Welcome& w = *client_->welcome();
  auto d = parse_description(w.description);
  if (!d) return d.status();
  auto scenario = build(d.value());
  if (!scenario)
    return Status::error("the server's scenario does not build here: " + scenario.message());
  scenario_.emplace(std::move(scenario.value()));
  game_.emplace(*scenario_);
  if (game_->input_size() != w.input_size)
    return Status::error("the server's inputs are " + std::to_string(w.input_size) +
                         " bytes, this scenario's " + std::to_string(game_->input_size()));
  auto injections = parse_injections(args_.injections);
  if (!injections) return injections.status();
  if (!injections->empty()) {
    game_->set_after_step([list = std::move(injections).value()](Scenario& s) {
      return apply_injections(s.world(), list);
    });
  }
  // A desync report names the match by the fingerprint of the scenario at frame 0.
  if (!args_.desync_report.empty()) initial_fingerprint_ = replay::fingerprint_of(*scenario_);
  if (Status s = client_->start(*game_); !s) return s;
  say(d->scenario + " (seed " + std::to_string(d->seed) + ", " + std::to_string(d->players) +
      " players): player " + std::to_string(w.player) + " of the server at " + args_.server +
      (w.start_frame > 0 ? ", joining at frame " + std::to_string(w.start_frame) : ""));
  return Status::success();
}

void ServerClient::write_desync_report() {
  const Status written = write_desync_side(
      args_.desync_report, *initial_fingerprint_, client_->welcome()->player,
      client_->desync_evidence(), *game_,
      "this client kept no evidence of the desync (it joined the match under way, or the match "
      "has more than 8 seats)");
  if (!written) {
    std::fprintf(stderr, "detsim netplay: --desync-report %s: %s\n", args_.desync_report.c_str(),
                 written.message().c_str());
    return;
  }
  report_written_ = true;
  say("desync report written to " + args_.desync_report);
}

void ServerClient::advance() {
  ++ticks_;
  const sp::Welcome& w = *client_->welcome();
  const std::int32_t adjust = client_->recommended_frame_adjust();
  int runs = 1;
  if (ticks_ % 3 == 0 && adjust > 0) runs = adjust > 4 ? 3 : 2;
  if (ticks_ % 3 == 0 && adjust < 0) runs = 0;
  std::vector<std::uint8_t> input(w.input_size);
  for (int r = 0; r < runs; ++r) {
    std::fill(input.begin(), input.end(), std::uint8_t{0});
    if (args_.bot) scenario_->scripted(args_.bot_seed, client_->current_frame(), w.player, input);
    if (!client_->advance_frame(input).ok()) return;
  }
}

int ServerClient::run() {
  if (Status s = begin(); !s) return usage_error(netplay_name, s.message());
  say("connecting to " + args_.server + " from " + transport_->local_endpoint().to_string());
  const auto timeout_us = static_cast<std::uint64_t>(args_.timeout_seconds * 1e6);
  std::optional<std::uint64_t> running_at;
  std::optional<std::uint64_t> ended_at;
  std::uint64_t next_tick = 0;
  for (;;) {
    const std::uint64_t now = micros_since(start_);
    client_->poll(now);
    for (const net::ClientEvent& e : client_->take_events()) {
      if (e.type == net::ClientEventType::desync) {
        desyncs_.push_back(e);
        if (args_.json)
          std::fprintf(stderr, "detsim netplay: DESYNC with the server at frame %llu\n",
                       static_cast<unsigned long long>(e.frame));
        say("DESYNC at frame " + std::to_string(e.frame) + ": this machine " + hex(e.local_hash) +
            ", the server " + hex(e.remote_hash));
        if (!args_.desync_report.empty() && desyncs_.size() == 1) write_desync_report();
      } else if (e.type == net::ClientEventType::running) {
        say("running from frame " + std::to_string(e.frame));
      }
    }
    if (!client_->failure().empty()) {
      failure_ = std::string(client_->failure());
      if (client_->started())
        failure_ += " (at frame " + std::to_string(client_->current_frame()) +
                    "; the server's inputs held up to frame " +
                    std::to_string(client_->authoritative_frame()) + ", its hashes checked up to " +
                    std::to_string(client_->checked_frame()) + ")";
      break;
    }
    if (client_->welcome() != nullptr && !client_->started()) {
      if (Status s = start_game(); !s) {
        failure_ = s.message();
        break;
      }
    }
    if (!client_->running()) {
      if (now >= timeout_us) {
        failure_ = client_->welcome() == nullptr
                       ? "no answer from the server at " + args_.server + " within " +
                             milliseconds(timeout_us)
                       : "no state from the server within " + milliseconds(timeout_us);
        break;
      }
      std::this_thread::sleep_for(std::chrono::microseconds(netplay_idle_sleep_us));
      continue;
    }
    if (!running_at) running_at = next_tick = now;
    if (client_->ended()) {
      if (!ended_at) ended_at = now;
      if (now - *ended_at >= netplay_linger_us) break;  // the server has our last acknowledgement
    }
    const std::uint64_t period = client_->welcome()->frame_us;
    if (now >= next_tick) {
      next_tick = now - next_tick > 4 * period ? now + period : next_tick + period;
      advance();
    } else {
      std::this_thread::sleep_for(
          std::chrono::microseconds(std::min(next_tick - now, netplay_idle_sleep_us)));
    }
  }
  if (!failure_.empty()) return usage_error(netplay_name, failure_);
  const std::uint64_t end = micros_since(start_);
  return report(static_cast<double>(ended_at.value_or(end) - running_at.value_or(end)) / 1e6);
}

int ServerClient::report(double seconds) {
  const net::ClientStats& s = client_->stats();
  const int code = desyncs_.empty() && s.desyncs == 0 ? exit_ok : exit_check_failed;
  const double per_second = seconds > 0 ? static_cast<double>(s.bytes_received) / seconds : 0.0;
  if (args_.json) {
    Json j;
    j.str("server", args_.server)
        .num("player", client_->welcome()->player)
        .num("frames", client_->current_frame())
        .hash("final_hash", client_->server_hash())
        .num("mispredictions", s.mispredictions)
        .num("corrections", s.corrections)
        .num("resimulated_frames", s.resimulated_frames)
        .num("desyncs", s.desyncs)
        .num("checks_passed", s.checks_passed)
        .num("snapshots_received", s.snapshots_received)
        .num("bytes_received", s.bytes_received)
        .real("bytes_received_per_second", per_second)
        .num("bytes_sent", s.bytes_sent)
        .num("rtt_ms", s.rtt_ms)
        .real("match_seconds", seconds);
    if (report_written_) {
      j.str("desync_report", args_.desync_report);
    } else {
      j.null("desync_report");
    }
    j.print();
    return code;
  }
  std::printf("frames       %llu, final hash %s\n",
              static_cast<unsigned long long>(client_->current_frame()),
              hex(client_->server_hash()).c_str());
  std::printf("predictions  %llu frames mispredicted, %llu corrections, %llu re-simulated\n",
              static_cast<unsigned long long>(s.mispredictions),
              static_cast<unsigned long long>(s.corrections),
              static_cast<unsigned long long>(s.resimulated_frames));
  std::printf("desyncs      %llu (%llu server hashes matched)\n",
              static_cast<unsigned long long>(s.desyncs),
              static_cast<unsigned long long>(s.checks_passed));
  std::printf("down         %.0f bytes/s; round trip %llu ms\n", per_second,
              static_cast<unsigned long long>(s.rtt_ms));
  if (report_written_) std::printf("desync report %s\n", args_.desync_report.c_str());
  return code;
}

}  // namespace

int server_client_command(const NetplayArgs& args) {
  if (!args.peers.empty() || args.spectate || !args.spectators.empty() || args.rejoin ||
      args.open_seat || !args.key.empty() || !args.key_file.empty())
    return usage_error(netplay_name,
                       "--server plays against a server: --peer, --spectate, --spectator, "
                       "--rejoin, --open-seat and --key are for peer-to-peer matches");
  if (!args.record.empty())
    return usage_error(netplay_name,
                       "--record with --server: the server records the match (detsim serve "
                       "--record)");
  if (!(args.timeout_seconds > 0 && args.timeout_seconds <= 86'400))
    return usage_error(netplay_name, "--timeout must be more than 0 and at most 86400 seconds");
  ServerClient client(args);
  return client.run();
}

}  // namespace detsim::cli
