// detsim netplay: this machine plays one player of an `arena` match against peers over UDP, with a
// net::Session in rollback or lockstep mode, optionally recording the confirmed frames as a replay
// that every peer writes byte for byte alike.
//
// The loop: every iteration polls the session (network in and out, timers); every 1/fps seconds
// it advances one frame with the bot's input (or a neutral one), skipping an advance now and then
// while the session recommends waiting for slower peers. After the last frame it keeps polling
// until every frame is confirmed here and every peer has reached the last frame, then a short
// linger so that the peers receive our last inputs and acknowledgements.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <detsim/net/scenario_game.hpp>
#include <detsim/net/scenario_recorder.hpp>
#include <detsim/net/session.hpp>
#include <detsim/net/udp.hpp>

#include "commands.hpp"
#include "output.hpp"
#include "scenario_args.hpp"

namespace detsim::cli {

namespace {

constexpr std::string_view netplay_name = "netplay";
/// Polling after the last frame once everything is confirmed, so that peers get our last
/// inputs and acknowledgements (they are resent every frame until acknowledged).
constexpr std::uint64_t linger_us = 500'000;
/// The pause between polls while there is nothing to advance.
constexpr std::uint64_t idle_sleep_us = 1'000;

/// The netplay_name line, checked: where to bind, and every peer's player and address.
struct Plan {
  net::Endpoint bind;
  std::vector<net::UdpPeer> peers;  ///< ascending player; PeerId = player index
  net::SessionMode mode = net::SessionMode::rollback;
};

Expected<net::UdpPeer> parse_peer(const std::string& text, const NetplayArgs& a) {
  const auto eq = text.find('=');
  if (eq == std::string::npos)
    return Status::error("--peer \"" + text + "\": expected J=IP:PORT, e.g. 1=127.0.0.1:7001");
  const std::string index = text.substr(0, eq);
  std::uint32_t player = 0;
  const bool digits =
      !index.empty() && index.size() <= 3 &&
      std::all_of(index.begin(), index.end(), [](char c) { return c >= '0' && c <= '9'; });
  if (digits) player = static_cast<std::uint32_t>(std::stoul(index));
  if (!digits || player >= a.players)
    return Status::error("--peer \"" + text + "\": player \"" + index +
                         "\" is not a player of this match (0 .. " + std::to_string(a.players - 1) +
                         ")");
  if (player == a.me)
    return Status::error("--peer \"" + text + "\": player " + index + " is this machine (--me " +
                         std::to_string(a.me) + ")");
  auto endpoint = net::parse_endpoint(std::string_view(text).substr(eq + 1));
  if (!endpoint) return Status::error("--peer " + index + ": " + endpoint.message());
  return net::UdpPeer{player, endpoint.value()};
}

Expected<Plan> plan_of(const NetplayArgs& a) {
  if (a.players < 2 || a.players > 8)
    return Status::error("--players must be 2 .. 8 (the arena scenario's range), got " +
                         std::to_string(a.players));
  if (a.me >= a.players)
    return Status::error("--me " + std::to_string(a.me) + " must be below --players " +
                         std::to_string(a.players) + " (players are numbered 0 .. " +
                         std::to_string(a.players - 1) + ")");
  Plan plan;
  if (a.mode == "rollback") {
    plan.mode = net::SessionMode::rollback;
  } else if (a.mode == "lockstep") {
    plan.mode = net::SessionMode::lockstep;
  } else {
    return Status::error("--mode must be rollback or lockstep, got \"" + a.mode + "\"");
  }
  auto bind = net::parse_endpoint(a.bind);
  if (!bind) return Status::error("--bind: " + bind.message());
  plan.bind = bind.value();
  std::vector<std::optional<net::UdpPeer>> by_player(a.players);
  for (const std::string& text : a.peers) {
    auto peer = parse_peer(text, a);
    if (!peer) return peer.status();
    std::optional<net::UdpPeer>& slot = by_player[peer->id];
    if (slot)
      return Status::error("--peer " + std::to_string(peer->id) + " is given twice (" +
                           slot->endpoint.to_string() + " and " + peer->endpoint.to_string() + ")");
    slot = peer.value();
  }
  for (std::uint32_t p = 0; p < a.players; ++p) {
    if (p == a.me) continue;
    if (!by_player[p])
      return Status::error("missing --peer for player " + std::to_string(p) +
                           ": every player but --me " + std::to_string(a.me) +
                           " needs one, e.g. --peer " + std::to_string(p) + "=127.0.0.1:7001");
    plan.peers.push_back(*by_player[p]);
  }
  return plan;
}

std::uint64_t random_seed() {
  std::random_device device;
  return (std::uint64_t{device()} << 32) ^ device();
}

std::string milliseconds(std::uint64_t us) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f ms", static_cast<double>(us) / 1000.0);
  return text;
}

/// One match: the scenario, the session over UDP, the optional recorder, and what happened.
class Netplay {
 public:
  Netplay(const NetplayArgs& args, Plan plan) : args_(args), plan_(std::move(plan)) {}
  int run();

 private:
  using Clock = std::chrono::steady_clock;

  Status start();
  [[nodiscard]] std::uint64_t now_us() const {
    return static_cast<std::uint64_t>(
        std::chrono::duration_cast<std::chrono::microseconds>(Clock::now() - start_).count());
  }
  [[nodiscard]] std::string address(std::uint32_t player) const;
  void say(const std::string& line) const {
    if (!args_.json) std::printf("%s\n", line.c_str());
    std::fflush(stdout);
  }
  /// Handles the session's events; false (with failure_ set) when a peer disconnected.
  bool handle_events();
  void advance();
  [[nodiscard]] bool peers_at_end() const;
  [[nodiscard]] std::string unconfirmed_players() const;
  int report(double handshake_seconds, double match_seconds);

  const NetplayArgs& args_;
  Plan plan_;
  Clock::time_point start_ = Clock::now();
  std::optional<Scenario> scenario_;
  std::optional<net::ScenarioGame> game_;
  std::optional<net::UdpTransport> transport_;
  std::optional<net::ScenarioRecorder> recorder_;
  std::optional<net::Session> session_;
  std::vector<std::string> rejected_;  ///< per player: why its hello was rejected, if it was
  std::vector<net::Event> desyncs_;
  std::string failure_;
  std::uint64_t confirmed_ = 0;
  std::optional<std::uint64_t> final_hash_;
  std::uint64_t ticks_ = 0;
  std::uint64_t skipped_ = 0;  ///< advances skipped to let slower peers catch up
  std::uint64_t stalled_ = 0;  ///< advances that simulated nothing: prediction limit, or
                               ///< (lockstep) waiting for inputs
};

std::string Netplay::address(std::uint32_t player) const {
  for (const net::UdpPeer& p : plan_.peers)
    if (p.id == player) return p.endpoint.to_string();
  return "?";
}

Status Netplay::start() {
  ScenarioParams params;
  params.seed = args_.seed;
  params.players = args_.players;
  auto scenario = Scenario::create("arena", params);
  if (!scenario) return scenario.status();
  scenario_.emplace(std::move(scenario.value()));
  game_.emplace(*scenario_);
  auto transport = net::UdpTransport::open(plan_.bind, plan_.peers);
  if (!transport) return transport.status();
  transport_.emplace(std::move(transport.value()));
  // The recorder must see the scenario at frame 0, before the session saves and steps it.
  if (!args_.record.empty()) {
    auto recorder = net::ScenarioRecorder::create(args_.record, *game_);
    if (!recorder) return recorder.status();
    recorder_.emplace(std::move(recorder.value()));
  }
  net::SessionConfig config;
  config.mode = plan_.mode;
  config.players = args_.players;
  config.local_player = args_.me;
  config.input_size = net::ScenarioGame::input_size;
  config.input_delay = args_.input_delay;
  config.fingerprint = session_fingerprint(*scenario_, plan_.mode, args_.frames);
  config.random_seed = random_seed();
  config.frame_us =
      args_.fps == 0 ? 1000 : std::clamp<std::uint32_t>(1'000'000 / args_.fps, 1000, 1'000'000);
  for (const net::UdpPeer& p : plan_.peers)
    config.remotes.push_back(net::RemotePlayer{p.id, p.id});
  auto session = net::Session::create(config, *game_, *transport_);
  if (!session) return session.status();
  session_.emplace(std::move(session.value()));
  const auto on_confirmed = [this](const net::ConfirmedFrame& f) {
    ++confirmed_;
    if (f.frame + 1 == args_.frames) final_hash_ = f.hash;
  };
  if (recorder_) {
    recorder_->attach(*session_, on_confirmed);
  } else {
    session_->set_confirmed_listener(on_confirmed);
  }
  rejected_.assign(args_.players, {});
  return Status::success();
}

bool Netplay::handle_events() {
  for (const net::Event& e : session_->take_events()) {
    const std::string who = "player " + std::to_string(e.player) + " at " + address(e.player);
    switch (e.type) {
      case net::EventType::synchronized:
        say(who + " connected");
        break;
      case net::EventType::running:
        say("running: every peer is connected");
        break;
      case net::EventType::interrupted:
        std::fprintf(stderr, "detsim netplay: %s has been silent for %s\n", who.c_str(),
                     milliseconds(session_->config().disconnect_warning_us).c_str());
        break;
      case net::EventType::resumed:
        std::fprintf(stderr, "detsim netplay: %s is back\n", who.c_str());
        break;
      case net::EventType::hello_rejected:
        rejected_[e.player] = std::string(e.reason);
        std::fprintf(stderr,
                     "detsim netplay: %s plays with other settings (%s): check --players, "
                     "--seed, --mode, --frames and the detsim version on both sides\n",
                     who.c_str(), std::string(e.reason).c_str());
        break;
      case net::EventType::desync:
        desyncs_.push_back(e);
        if (args_.json) {
          std::fprintf(stderr, "detsim netplay: DESYNC with %s at frame %llu\n", who.c_str(),
                       static_cast<unsigned long long>(e.frame));
        }
        say("DESYNC at frame " + std::to_string(e.frame) + " with " + who + ": this machine " +
            hex(e.local_hash) + ", player " + std::to_string(e.player) + " " + hex(e.remote_hash));
        break;
      case net::EventType::disconnected:
        failure_ = who + " disconnected at frame " + std::to_string(e.frame) + " (silent for " +
                   milliseconds(session_->config().disconnect_timeout_us) + ")";
        return false;
    }
  }
  return true;
}

void Netplay::advance() {
  net::Session& s = *session_;
  ++ticks_;
  // Time sync: a machine ahead of its peers skips every third advance until it is in time (not
  // when running as fast as possible: there is no frame rate to keep).
  if (args_.fps != 0 && s.recommended_wait_frames() > 0 && ticks_ % 3 == 0) {
    ++skipped_;
    return;
  }
  PlayerInput input;
  // The bot plays by frame, not by time: the inputs, and so the final hash, depend only on the
  // arguments, never on the network's timing.
  if (args_.bot)
    input = scripted_input(args_.bot_seed, s.current_frame() + args_.input_delay, args_.me);
  std::array<std::uint8_t, PlayerInput::encoded_size> bytes{};
  encode_input(input, bytes);
  auto result = s.advance_frame(bytes);
  if (result.ok() && result.value() != net::Advance::advanced) {
    ++stalled_;
    if (args_.fps == 0) std::this_thread::yield();  // nothing to do until the peers catch up
  }
}

bool Netplay::peers_at_end() const {
  for (const net::UdpPeer& p : plan_.peers) {
    const auto stats = session_->peer_stats(p.id);
    if (!stats || stats->remote_frame < args_.frames) return false;
  }
  return true;
}

std::string Netplay::unconfirmed_players() const {
  std::string out;
  for (const net::UdpPeer& p : plan_.peers) {
    const auto stats = session_->peer_stats(p.id);
    if (stats && stats->remote_frame >= args_.frames) continue;
    if (!out.empty()) out += ", ";
    out += "player " + std::to_string(p.id) + " at " + p.endpoint.to_string() + " (at frame " +
           std::to_string(stats ? stats->remote_frame : 0) + ")";
  }
  return out;
}

int Netplay::run() {
  if (Status s = start(); !s) return usage_error(netplay_name, s.message());
  say("arena (seed " + std::to_string(args_.seed) + ", " + std::to_string(args_.players) +
      " players): player " + std::to_string(args_.me) + " on " +
      transport_->local_endpoint().to_string() + ", " + args_.mode + ", input delay " +
      std::to_string(args_.input_delay) + ", " + std::to_string(args_.frames) + " frames");
  for (const net::UdpPeer& p : plan_.peers)
    say("waiting for player " + std::to_string(p.id) + " at " + p.endpoint.to_string());

  const auto timeout_us = static_cast<std::uint64_t>(args_.timeout_seconds * 1e6);
  const std::uint64_t period_us = args_.fps == 0 ? 0 : 1'000'000 / args_.fps;
  std::optional<std::uint64_t> running_at;  // when the handshake completed
  std::optional<std::uint64_t> ended_at;    // when the last frame was simulated
  std::optional<std::uint64_t> settled_at;  // when everything was confirmed everywhere
  std::uint64_t next_tick = 0;
  Progress progress("netplay");
  for (;;) {
    const std::uint64_t now = now_us();
    session_->poll(now);
    if (!handle_events()) break;
    if (!session_->running()) {
      if (now >= timeout_us) {
        failure_ = "handshake timed out";
        for (const net::UdpPeer& p : plan_.peers) {
          const auto stats = session_->peer_stats(p.id);
          if (stats && stats->synchronized) continue;
          failure_ = "handshake timed out waiting for player " + std::to_string(p.id) + " at " +
                     p.endpoint.to_string();
          if (!rejected_[p.id].empty())
            failure_ += " (its settings differ: " + rejected_[p.id] + ")";
          break;
        }
        break;
      }
      std::this_thread::sleep_for(std::chrono::microseconds(idle_sleep_us));
      continue;
    }
    if (!running_at) running_at = next_tick = now;
    if (session_->current_frame() < args_.frames) {
      if (now >= next_tick) {
        // Keep the frame rate; after a long stall start afresh rather than race to catch up.
        next_tick = now - next_tick > 4 * period_us ? now + period_us : next_tick + period_us;
        advance();
        progress.update(session_->current_frame(), args_.frames);
      } else {
        std::this_thread::sleep_for(
            std::chrono::microseconds(std::min(next_tick - now, idle_sleep_us)));
      }
      continue;
    }
    if (!ended_at) ended_at = now;
    if (confirmed_ >= args_.frames && peers_at_end()) {
      if (!settled_at) settled_at = now;
      if (now - *settled_at >= linger_us) break;
    } else if (now - *ended_at >= timeout_us) {
      const std::string behind = unconfirmed_players();
      failure_ = "timed out after the last frame: " + std::to_string(confirmed_) + " of " +
                 std::to_string(args_.frames) + " frames confirmed; waiting for " +
                 (behind.empty() ? "the peers' last inputs" : behind);
      break;
    }
    std::this_thread::sleep_for(std::chrono::microseconds(idle_sleep_us));
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

int Netplay::report(double handshake_seconds, double match_seconds) {
  const net::SessionStats& st = session_->stats();
  const int code = desyncs_.empty() ? exit_ok : exit_check_failed;
  if (args_.json) {
    std::vector<std::string> peers;
    for (const net::UdpPeer& p : plan_.peers) {
      const net::PeerStats s = session_->peer_stats(p.id).value_or(net::PeerStats{});
      peers.push_back(Json()
                          .num("player", p.id)
                          .str("address", p.endpoint.to_string())
                          .real("ping_ms", static_cast<double>(s.ping_us) / 1000.0)
                          .num("packets_sent", s.packets_sent)
                          .num("packets_received", s.packets_received)
                          .num("packets_lost", s.packets_lost)
                          .num("bytes_sent", s.bytes_sent)
                          .num("bytes_received", s.bytes_received)
                          .text());
    }
    std::vector<std::string> desyncs;
    for (const net::Event& e : desyncs_)
      desyncs.push_back(Json()
                            .num("player", e.player)
                            .num("frame", e.frame)
                            .hash("local_hash", e.local_hash)
                            .hash("remote_hash", e.remote_hash)
                            .text());
    Json j;
    j.str("scenario", "arena")
        .num("seed", args_.seed)
        .num("players", args_.players)
        .num("player", args_.me)
        .str("mode", args_.mode)
        .num("input_delay", args_.input_delay)
        .num("frames", confirmed_);
    if (final_hash_) {
      j.hash("final_hash", *final_hash_);
    } else {
      j.null("final_hash");
    }
    j.num("rollbacks", st.rollbacks)
        .num("resimulated_frames", st.resimulated_frames)
        .num("stalled_advances", stalled_)
        .num("skipped_advances", skipped_)
        .num("desyncs", desyncs_.size())
        .raw("desync_events", Json::array(desyncs))
        .raw("peers", Json::array(peers));
    if (args_.record.empty()) {
      j.null("record");
    } else {
      j.str("record", args_.record);
    }
    j.real("handshake_seconds", handshake_seconds).real("match_seconds", match_seconds).print();
    return code;
  }
  std::printf("frames       %llu, final hash %s\n", static_cast<unsigned long long>(confirmed_),
              final_hash_ ? hex(*final_hash_).c_str() : "-");
  std::printf("rollbacks    %llu, %llu frames re-simulated\n",
              static_cast<unsigned long long>(st.rollbacks),
              static_cast<unsigned long long>(st.resimulated_frames));
  std::printf("desyncs      %zu\n", desyncs_.size());
  for (const net::UdpPeer& p : plan_.peers) {
    const net::PeerStats s = session_->peer_stats(p.id).value_or(net::PeerStats{});
    std::printf(
        "player %-5u %s: ping %s, packets %llu sent, %llu received, %llu lost; %llu bytes sent\n",
        p.id, p.endpoint.to_string().c_str(), milliseconds(s.ping_us).c_str(),
        static_cast<unsigned long long>(s.packets_sent),
        static_cast<unsigned long long>(s.packets_received),
        static_cast<unsigned long long>(s.packets_lost),
        static_cast<unsigned long long>(s.bytes_sent));
  }
  if (!args_.record.empty()) std::printf("replay       %s\n", args_.record.c_str());
  std::printf("time         handshake %.2f s, match %.2f s (%.0f frames/s)\n", handshake_seconds,
              match_seconds,
              match_seconds > 0 ? static_cast<double>(args_.frames) / match_seconds : 0.0);
  return code;
}

}  // namespace

int netplay_command(const NetplayArgs& args) {
  if (args.frames == 0 || args.frames > 100'000'000)
    return usage_error(netplay_name,
                       "--frames must be 1 .. 100000000, got " + std::to_string(args.frames));
  if (!(args.timeout_seconds > 0 && args.timeout_seconds <= 86'400))
    return usage_error(netplay_name, "--timeout must be more than 0 and at most 86400 seconds");
  auto plan = plan_of(args);
  if (!plan) return usage_error(netplay_name, plan.message());
  Netplay match(args, std::move(plan.value()));
  return match.run();
}

}  // namespace detsim::cli
