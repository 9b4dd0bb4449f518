// detsim netplay --spectate: this machine watches a match (the `arena`, or --scenario), receiving
// every confirmed frame from one player (the host, which lists this machine with --spectator)
// through a net::SpectatorSession. It simulates exactly the confirmed inputs, so it reaches the
// players' final hash and, with --record, writes the same replay bytes as they do.
//
// The loop: every iteration polls the session; every 1/fps seconds it advances, which simulates
// one received frame, or several when frames have piled up (the session catches up by itself);
// at --fps 0 it simulates everything received at once. After the last frame a short linger
// keeps acknowledging, so that the host learns this machine has every frame.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <detsim/net/spectator.hpp>
#include <detsim/net/udp.hpp>
#include <detsim/scenario_net/scenario_game.hpp>
#include <detsim/scenario_net/scenario_recorder.hpp>

#include "netplay_plan.hpp"
#include "output.hpp"
#include "scenario_args.hpp"

namespace detsim::cli {

namespace {

class Spectate {
 public:
  Spectate(const NetplayArgs& args, const NetplayPlan& plan)
      : args_(args), plan_(plan), host_(plan.peers.front()) {}
  int run();

 private:
  using Clock = std::chrono::steady_clock;

  Status start();
  [[nodiscard]] std::uint64_t now_us() const {
    return static_cast<std::uint64_t>(
        std::chrono::duration_cast<std::chrono::microseconds>(Clock::now() - start_).count());
  }
  [[nodiscard]] std::string host_name() const {
    return "player " + std::to_string(host_.id) + " at " + host_.endpoint.to_string();
  }
  void say(const std::string& line) const {
    if (!args_.json) std::printf("%s\n", line.c_str());
    std::fflush(stdout);
  }
  /// Handles the session's events; false (with failure_ set) when the host left too early.
  bool handle_events();
  /// The handshake did not complete in time: what to tell the user.
  [[nodiscard]] std::string handshake_failure() const;
  int report(double handshake_seconds, double match_seconds) const;

  const NetplayArgs& args_;
  const NetplayPlan& plan_;
  net::UdpPeer host_;
  Clock::time_point start_ = Clock::now();
  std::optional<Scenario> scenario_;
  std::optional<net::ScenarioGame> game_;
  std::optional<net::UdpTransport> transport_;
  std::optional<net::ScenarioRecorder> recorder_;
  std::optional<net::SpectatorSession> session_;
  std::string failure_;
  std::uint64_t confirmed_ = 0;
  std::optional<std::uint64_t> final_hash_;
};

Status Spectate::start() {
  ScenarioParams params;
  params.seed = args_.seed;
  params.players = args_.players;
  auto scenario = Scenario::create(args_.scenario, params);
  if (!scenario) return scenario.status();
  scenario_.emplace(std::move(scenario.value()));
  game_.emplace(*scenario_);
  auto transport = net::UdpTransport::open(plan_.bind, plan_.peers);
  if (!transport) return transport.status();
  transport_.emplace(std::move(transport.value()));
  // The recorder must see the scenario at frame 0 (its fingerprint holds the initial state).
  if (!args_.record.empty()) {
    auto recorder = net::ScenarioRecorder::create(args_.record, *game_);
    if (!recorder) return recorder.status();
    recorder_.emplace(std::move(recorder.value()));
  }
  net::SpectatorConfig config;
  config.players = args_.players;
  config.input_size = game_->input_size();
  // The players' own fingerprint: a spectator of another match (or length) is never served.
  config.fingerprint = session_fingerprint(*scenario_, plan_.mode, args_.frames);
  config.host = host_.id;
  config.match_key = plan_.match_key;
  auto session = net::SpectatorSession::create(config, *game_, *transport_);
  if (!session) return session.status();
  session_.emplace(std::move(session.value()));
  // Confirmed frame F-1 is the step that produces the state after frame F: the final hash.
  const auto on_confirmed = [this](const net::ConfirmedFrame& f) {
    ++confirmed_;
    if (f.frame + 1 == args_.frames) final_hash_ = f.hash;
  };
  if (recorder_) {
    recorder_->attach(*session_, on_confirmed);
  } else {
    session_->set_confirmed_listener(on_confirmed);
  }
  return Status::success();
}

bool Spectate::handle_events() {
  for (const net::Event& e : session_->take_events()) {
    switch (e.type) {
      case net::EventType::synchronized:
        say(host_name() + " connected");
        break;
      case net::EventType::running:
        say("running: receiving the confirmed frames");
        break;
      case net::EventType::disconnected: {
        // A host that sent every frame may leave while this machine still simulates them.
        const std::uint64_t received = session_->current_frame() + session_->frames_behind();
        if (received >= args_.frames) break;
        failure_ = host_name() + " disconnected at frame " + std::to_string(received) + " of " +
                   std::to_string(args_.frames);
        return false;
      }
      default:  // a spectator raises no other events
        break;
    }
  }
  return true;
}

std::string Spectate::handshake_failure() const {
  std::string text = "handshake timed out waiting for " + host_name() +
                     ": it must list this machine (" + transport_->local_endpoint().to_string() +
                     ") with --spectator";
  // Packets from the host arrive but are refused: another key, or a hello for another match.
  if (session_->stats().dropped_unauthenticated > 0)
    text += std::string("; ") + key_mismatch("not authenticated");
  else if (session_->stats().dropped > 0)
    text +=
        "; its packets were refused (another match?): check --players, --seed, --mode, "
        "--frames and the detsim version on both sides";
  return text;
}

int Spectate::run() {
  if (Status s = start(); !s) return usage_error(netplay_name, s.message());
  say(args_.scenario + " (seed " + std::to_string(args_.seed) + ", " +
      std::to_string(args_.players) + " players): spectator on " +
      transport_->local_endpoint().to_string() + ", " + args_.mode + ", " +
      std::to_string(args_.frames) + " frames");
  say(protection_line(plan_));
  say("waiting for " + host_name());

  const auto timeout_us = static_cast<std::uint64_t>(args_.timeout_seconds * 1e6);
  const std::uint64_t period_us = args_.fps == 0 ? 0 : 1'000'000 / args_.fps;
  std::optional<std::uint64_t> running_at;  // when the handshake completed
  std::optional<std::uint64_t> ended_at;    // when the last frame was simulated
  std::uint64_t next_tick = 0;
  Progress progress("netplay");
  for (;;) {
    const std::uint64_t now = now_us();
    session_->poll(now);
    if (!handle_events()) break;
    if (!session_->running()) {
      if (now >= timeout_us) {
        failure_ = handshake_failure();
        break;
      }
      std::this_thread::sleep_for(std::chrono::microseconds(netplay_idle_sleep_us));
      continue;
    }
    if (!running_at) running_at = next_tick = now;
    if (session_->current_frame() < args_.frames) {
      if (period_us == 0) {  // everything received, now
        while (session_->current_frame() < args_.frames && session_->advance() > 0) {
        }
      } else if (now >= next_tick) {
        next_tick = now - next_tick > 4 * period_us ? now + period_us : next_tick + period_us;
        session_->advance();
      }
      progress.update(session_->current_frame(), args_.frames);
      const std::uint64_t wait = next_tick > now ? next_tick - now : netplay_idle_sleep_us;
      std::this_thread::sleep_for(std::chrono::microseconds(std::min(wait, netplay_idle_sleep_us)));
      continue;
    }
    if (!ended_at) ended_at = now;
    if (now - *ended_at >= netplay_linger_us) break;
    std::this_thread::sleep_for(std::chrono::microseconds(netplay_idle_sleep_us));
  }
  progress.done();
  const std::uint64_t end = now_us();
  if (recorder_) {
    if (Status s = recorder_->finish(); !s && failure_.empty()) failure_ = s.message();
  }
  if (!failure_.empty()) return usage_error(netplay_name, failure_);
  const double handshake = static_cast<double>(running_at.value_or(end)) / 1e6;
  const double match = static_cast<double>(ended_at.value_or(end) - running_at.value_or(end)) / 1e6;
  return report(handshake, match);
}

int Spectate::report(double handshake_seconds, double match_seconds) const {
  const net::SpectatorStats& st = session_->stats();
  if (args_.json) {
    const std::string host = Json()
                                 .num("player", host_.id)
                                 .str("address", host_.endpoint.to_string())
                                 .num("packets_received", st.packets_received)
                                 .num("bytes_received", st.bytes_received)
                                 .num("packets_dropped", st.dropped)
                                 .text();
    Json j;
    j.str("scenario", args_.scenario)
        .num("seed", args_.seed)
        .num("players", args_.players)
        .null("player")
        .boolean("spectator", true)
        .num("host", host_.id)
        .str("mode", args_.mode)
        .num("frames", confirmed_);
    if (final_hash_) {
      j.hash("final_hash", *final_hash_);
    } else {
      j.null("final_hash");
    }
    // A spectator simulates confirmed inputs only: nothing to roll back, no hashes to compare.
    j.num("rollbacks", 0)
        .num("resimulated_frames", 0)
        .num("catch_up_advances", st.catch_up_calls)
        .num("desyncs", 0)
        .raw("desync_events", "[]")
        .raw("peers", Json::array({host}));
    if (args_.record.empty()) {
      j.null("record");
    } else {
      j.str("record", args_.record);
    }
    j.real("handshake_seconds", handshake_seconds).real("match_seconds", match_seconds).print();
    return exit_ok;
  }
  std::printf("frames       %llu, final hash %s\n", static_cast<unsigned long long>(confirmed_),
              final_hash_ ? hex(*final_hash_).c_str() : "-");
  std::printf(
      "rollbacks    0 (a spectator simulates confirmed frames only); %llu catch-up "
      "advances\n",
      static_cast<unsigned long long>(st.catch_up_calls));
  std::printf("player %-5u %s (host): packets %llu received, %llu bytes received\n", host_.id,
              host_.endpoint.to_string().c_str(),
              static_cast<unsigned long long>(st.packets_received),
              static_cast<unsigned long long>(st.bytes_received));
  if (!args_.record.empty()) std::printf("replay       %s\n", args_.record.c_str());
  std::printf("time         handshake %.2f s, match %.2f s (%.0f frames/s)\n", handshake_seconds,
              match_seconds,
              match_seconds > 0 ? static_cast<double>(args_.frames) / match_seconds : 0.0);
  return exit_ok;
}

}  // namespace

int spectate(const NetplayArgs& args, const NetplayPlan& plan) {
  Spectate watch(args, plan);
  return watch.run();
}

}  // namespace detsim::cli
