// detsim netplay: this machine plays one player of a match (the `arena`, or --scenario) against
// peers over UDP, with a net::Session in rollback or lockstep mode, optionally recording the
// confirmed frames as a replay that every peer writes byte for byte alike, and serving spectators
// (--spectator). With
// --spectate it watches instead (cmd_spectate.cpp); netplay_plan.cpp checks the command line.
//
// The loop: every iteration polls the session (network in and out, timers); every 1/fps seconds
// it advances one frame with the bot's input (or a neutral one), skipping an advance now and then
// while the session recommends waiting for slower peers. After the last frame it keeps polling
// until every frame is confirmed here, every peer has reached the last frame and every connected
// spectator has every frame, then a short linger so that the peers receive our last inputs and
// acknowledgements.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <detsim/net/session.hpp>
#include <detsim/net/udp.hpp>
#include <detsim/replay/desync_report.hpp>
#include <detsim/replay/replay.hpp>
#include <detsim/scenario_net/scenario_game.hpp>
#include <detsim/scenario_net/scenario_recorder.hpp>

#include "commands.hpp"
#include "netplay_plan.hpp"
#include "output.hpp"
#include "scenario_args.hpp"

namespace detsim::cli {

namespace {

/// One match: the scenario, the session over UDP, the optional recorder, and what happened.
class Netplay {
 public:
  Netplay(const NetplayArgs& args, NetplayPlan plan) : args_(args), plan_(std::move(plan)) {}
  int run();

 private:
  using Clock = std::chrono::steady_clock;

  Status start();
  [[nodiscard]] std::uint64_t now_us() const {
    return static_cast<std::uint64_t>(
        std::chrono::duration_cast<std::chrono::microseconds>(Clock::now() - start_).count());
  }
  /// "player 1 at 127.0.0.1:7001" or "spectator 0 at 127.0.0.1:7100", by event player number.
  [[nodiscard]] std::string who(std::uint32_t player) const;
  void say(const std::string& line) const {
    if (!args_.json) std::printf("%s\n", line.c_str());
    std::fflush(stdout);
  }
  /// Why a player was disconnected, in words: the event's reason with its limit.
  [[nodiscard]] std::string disconnect_reason(std::string_view reason) const {
    const net::SessionConfig& c = session_->config();
    if (reason == "silent") return "silent for " + milliseconds(c.disconnect_timeout_us);
    if (reason == "no progress")
      return "no progress: it held the match back for " + milliseconds(c.progress_timeout_us);
    return std::string(reason);
  }
  /// Handles the session's events; false (with failure_ set) when the match ended here: a player
  /// disconnected and no majority is left (--partition end), or a rejoin failed. A player that
  /// leaves a match that goes on (a majority stays, or --partition play-on) is reported only.
  bool handle_events();
  void write_desync_report();
  void advance();
  [[nodiscard]] bool peers_at_end() const;
  /// Whether player `id` plays in the match as this machine sees it now: neither disconnected nor
  /// an open seat nobody took (on a joiner, any player gone in its snapshot that never came).
  [[nodiscard]] bool in_match(const std::optional<net::PeerStats>& stats) const;
  /// The connected players whose hash checks of the match's frames have not all arrived ("" when
  /// every one has): a frame whose check never arrives is unverified, never a pass.
  [[nodiscard]] std::string checks_behind() const;
  [[nodiscard]] std::string unconfirmed_players() const;
  /// Spectator `player` (players + k) acknowledged every frame of the match.
  [[nodiscard]] bool has_every_frame(std::uint32_t player) const {
    const auto stats = session_->peer_stats(player);
    return stats && stats->acknowledged_frame >= args_.frames;
  }
  /// The connected spectators that lack frames ("" when none does).
  [[nodiscard]] std::string spectators_behind() const;
  int report(double handshake_seconds, double match_seconds);
  void print_text_report(double handshake_seconds, double match_seconds) const;

  const NetplayArgs& args_;
  NetplayPlan plan_;
  Clock::time_point start_ = Clock::now();
  std::optional<Scenario> scenario_;
  std::optional<net::ScenarioGame> game_;
  std::optional<net::UdpTransport> transport_;
  std::optional<net::ScenarioRecorder> recorder_;
  std::optional<net::Session> session_;
  /// The scenario's fingerprint at frame 0, kept for a desync report (--desync-report).
  std::optional<replay::Fingerprint> initial_fingerprint_;
  bool report_written_ = false;
  /// Every frame confirmed here and every player at the end (this machine may still be serving
  /// its spectators).
  bool match_complete_ = false;
  /// Per player, then per spectator: why its hello was rejected, if it was.
  std::vector<std::string> rejected_;
  std::vector<net::Event> desyncs_;
  /// Hash checks that never arrived (Event::check_missing, or still missing at the end).
  std::vector<std::string> unverified_;
  std::string failure_;
  std::optional<std::uint64_t> final_hash_;
  std::uint64_t ticks_ = 0;
  std::uint64_t skipped_ = 0;  ///< advances skipped to let slower peers catch up
  std::uint64_t stalled_ = 0;  ///< advances that simulated nothing: prediction limit, or
                               ///< (lockstep) waiting for inputs
};

std::string Netplay::who(std::uint32_t player) const {
  if (player >= args_.players) {
    const std::size_t k = player - args_.players;
    const std::string address =
        k < plan_.spectators.size() ? plan_.spectators[k].endpoint.to_string() : "?";
    return "spectator " + std::to_string(k) + " at " + address;
  }
  for (const net::UdpPeer& p : plan_.peers)
    if (p.id == player) return "player " + std::to_string(player) + " at " + p.endpoint.to_string();
  return "player " + std::to_string(player);
}

Status Netplay::start() {
  ScenarioParams params;
  params.seed = args_.seed;
  params.players = args_.players;
  auto scenario = Scenario::create(args_.scenario, params);
  if (!scenario) return scenario.status();
  scenario_.emplace(std::move(scenario.value()));
  game_.emplace(*scenario_);
  auto injections = parse_injections(args_.injections);
  if (!injections) return injections.status();
  for (const Injection& i : injections.value())
    if (i.frame > args_.frames)
      return Status::error("--inject " + i.text() + ": frame " + std::to_string(i.frame) +
                           " is beyond the match's " + std::to_string(args_.frames) + " frames");
  if (!injections->empty()) {
    game_->set_after_step([list = std::move(injections).value()](Scenario& s) {
      return apply_injections(s.world(), list);
    });
  }
  // A desync report names the run by the fingerprint of the scenario at frame 0.
  if (!args_.desync_report.empty()) initial_fingerprint_ = replay::fingerprint_of(*scenario_);
  auto transport = net::UdpTransport::open(plan_.bind, plan_.peers);
  if (!transport) return transport.status();
  transport_.emplace(std::move(transport.value()));
  for (const net::UdpPeer& s : plan_.spectators) {
    if (Status added = transport_->add_peer(s); !added)
      return Status::error("--spectator " + s.endpoint.to_string() + ": " + added.message());
  }
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
  config.input_size = game_->input_size();
  config.input_delay = args_.input_delay;
  config.fingerprint = session_fingerprint(*scenario_, plan_.mode, args_.frames);
  config.match_key = plan_.match_key;
  config.partition = plan_.partition;
  config.rejoin = args_.rejoin;
  // A rejoining player records the whole match too: it re-simulates the frames before its return
  // from the snapshot's log (which must then give the snapshot's state).
  config.rejoin_replays_match = args_.rejoin && recorder_.has_value();
  if (args_.open_seat)
    for (const net::UdpPeer& p : plan_.peers)
      config.open_seats.push_back(p.id);
  config.frame_us =
      args_.fps == 0 ? 1000 : std::clamp<std::uint32_t>(1'000'000 / args_.fps, 1000, 1'000'000);
  for (const net::UdpPeer& p : plan_.peers)
    config.remotes.push_back(net::RemotePlayer{p.id, p.id});
  for (const net::UdpPeer& s : plan_.spectators)
    config.spectators.push_back(s.id);
  auto session = net::Session::create(config, *game_, *transport_);
  if (!session) return session.status();
  session_.emplace(std::move(session.value()));
  const auto on_confirmed = [this](const net::ConfirmedFrame& f) {
    if (f.frame + 1 == args_.frames) final_hash_ = f.hash;
  };
  if (recorder_) {
    recorder_->attach(*session_, on_confirmed);
  } else {
    session_->set_confirmed_listener(on_confirmed);
  }
  rejected_.assign(args_.players + plan_.spectators.size(), {});
  return Status::success();
}

bool Netplay::handle_events() {
  std::vector<std::string> gone;  // players that left, while the match may go on without them
  for (const net::Event& e : session_->take_events()) {
    const std::string who = this->who(e.player);
    const bool spectator = e.player >= args_.players;
    // Peers that go quiet once they have everything have simply left.
    const bool left = spectator ? has_every_frame(e.player) : match_complete_;
    switch (e.type) {
      case net::EventType::synchronized:
        say(who + " connected");
        break;
      case net::EventType::running:
        say("running: every peer is connected");
        break;
      case net::EventType::interrupted:
        if (left) break;
        std::fprintf(stderr, "detsim netplay: %s has been silent for %s\n", who.c_str(),
                     milliseconds(session_->config().disconnect_warning_us).c_str());
        break;
      case net::EventType::resumed:
        if (left) break;
        std::fprintf(stderr, "detsim netplay: %s is back\n", who.c_str());
        break;
      case net::EventType::hello_rejected:
        if (e.player < rejected_.size()) rejected_[e.player] = std::string(e.reason);
        if (const char* keys = key_mismatch(e.reason)) {
          std::fprintf(stderr, "detsim netplay: %s: %s\n", who.c_str(), keys);
          break;
        }
        std::fprintf(stderr,
                     "detsim netplay: %s %s with other settings (%s): check --players, "
                     "--seed, --mode, --frames and the detsim version on both sides\n",
                     who.c_str(), spectator ? "watches" : "plays", std::string(e.reason).c_str());
        break;
      case net::EventType::desync:
        desyncs_.push_back(e);
        if (args_.json) {
          std::fprintf(stderr, "detsim netplay: DESYNC with %s at frame %llu\n", who.c_str(),
                       static_cast<unsigned long long>(e.frame));
        }
        say("DESYNC at frame " + std::to_string(e.frame) + " with " + who + ": this machine " +
            hex(e.local_hash) + ", player " + std::to_string(e.player) + " " + hex(e.remote_hash));
        if (!args_.desync_report.empty() && desyncs_.size() == 1) write_desync_report();
        break;
      case net::EventType::check_missing: {
        const std::string line = who + ": its hash check of frame " + std::to_string(e.frame) +
                                 " did not arrive within " +
                                 milliseconds(session_->config().progress_timeout_us);
        unverified_.push_back(line);
        std::fprintf(stderr, "detsim netplay: UNVERIFIED: %s\n", line.c_str());
        break;
      }
      case net::EventType::paused:
        std::fprintf(stderr,
                     "detsim netplay: paused at frame %llu: %s is silent, and without it no "
                     "majority is left (--partition pause); waiting for it to come back or "
                     "rejoin\n",
                     static_cast<unsigned long long>(e.frame), who.c_str());
        break;
      case net::EventType::rejoined:
        if (e.player == args_.me) {
          say("rejoined the match at frame " + std::to_string(e.frame) + " (" +
              std::to_string(session_->current_frame()) + " now)");
        } else {
          std::fprintf(stderr, "detsim netplay: %s rejoined at frame %llu\n", who.c_str(),
                       static_cast<unsigned long long>(e.frame));
        }
        break;
      case net::EventType::disconnected:
        if (left) break;
        if (spectator) {  // the match goes on without it
          std::fprintf(stderr, "detsim netplay: %s disconnected at frame %llu\n", who.c_str(),
                       static_cast<unsigned long long>(e.frame));
          break;
        }
        if (e.reason == "rejoining") {  // its process restarted (--rejoin): it comes back
          std::fprintf(stderr,
                       "detsim netplay: %s restarted: its old process is gone from frame %llu, "
                       "and it rejoins\n",
                       who.c_str(), static_cast<unsigned long long>(e.frame));
          break;
        }
        // The session says whether the match goes on without it: a match_ended right after
        // (no majority left, --partition end) ends this one with this disconnect as the reason.
        gone.push_back(who + " disconnected at frame " + std::to_string(e.frame) + " (" +
                       disconnect_reason(e.reason) + ")");
        break;
      case net::EventType::match_ended:
        if (failure_.empty() && e.reason != "rejoin failed" && !gone.empty()) failure_ = gone[0];
        if (failure_.empty())
          failure_ =
              e.reason == "rejoin failed"
                  ? "rejoining failed: " + std::string(session_->failure())
                  : "the match ended at frame " + std::to_string(e.frame) + ": no majority left";
        return false;
    }
  }
  for (const std::string& line : gone)
    std::fprintf(stderr,
                 "detsim netplay: %s; the match goes on without it (it may come back with "
                 "--rejoin)\n",
                 line.c_str());
  return true;
}

void Netplay::write_desync_report() {
  // The session keeps this machine's side of the first desync only; that is what is written,
  // with the states of every frame between the agreed and the divergent one, re-simulated.
  const Status written = write_desync_side(args_.desync_report, *initial_fingerprint_, args_.me,
                                           session_->desync_evidence(), *game_,
                                           "the session kept no evidence of the desync");
  if (!written) {
    std::fprintf(stderr, "detsim netplay: --desync-report %s: %s\n", args_.desync_report.c_str(),
                 written.message().c_str());
    return;
  }
  report_written_ = true;
  if (args_.json)
    std::fprintf(stderr, "detsim netplay: desync report written to %s\n",
                 args_.desync_report.c_str());
  say("desync report written to " + args_.desync_report);
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
  // The bot plays by frame, not by time: the inputs, and so the final hash, depend only on the
  // arguments, never on the network's timing. Without one the player's input is all zero (no
  // button pressed).
  std::vector<std::uint8_t> bytes(game_->input_size());
  if (args_.bot)
    scenario_->scripted(args_.bot_seed, s.current_frame() + args_.input_delay, args_.me, bytes);
  auto result = s.advance_frame(bytes);
  if (result.ok() && result.value() != net::Advance::advanced) {
    ++stalled_;
    if (args_.fps == 0) std::this_thread::yield();  // nothing to do until the peers catch up
  }
}

bool Netplay::in_match(const std::optional<net::PeerStats>& stats) const {
  if (!stats || stats->disconnected) return false;
  return stats->synchronized || !(args_.open_seat || args_.rejoin);
}

bool Netplay::peers_at_end() const {
  for (const net::UdpPeer& p : plan_.peers) {
    const auto stats = session_->peer_stats(p.id);
    if (!in_match(stats)) continue;  // gone, or a seat nobody took
    if (stats->remote_frame < args_.frames) return false;
  }
  return true;
}

std::string Netplay::checks_behind() const {
  const std::uint32_t interval = session_->config().check_interval;
  if (interval == 0) return "";
  const std::uint64_t last = args_.frames / interval * interval;
  std::string out;
  for (const net::UdpPeer& p : plan_.peers) {
    const auto stats = session_->peer_stats(p.id);
    if (!in_match(stats) || stats->checks_received_through >= last) continue;
    if (!out.empty()) out += ", ";
    out += who(p.id) + " (checks of frames " + std::to_string(stats->checks_received_through + 1) +
           " .. " + std::to_string(last) + ")";
  }
  return out;
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

std::string Netplay::spectators_behind() const {
  std::string out;
  for (std::size_t k = 0; k < plan_.spectators.size(); ++k) {
    const auto player = args_.players + static_cast<std::uint32_t>(k);
    const net::PeerStats s = session_->peer_stats(player).value_or(net::PeerStats{});
    if (s.disconnected || s.acknowledged_frame >= args_.frames) continue;
    if (!out.empty()) out += ", ";
    out += who(player) + (s.synchronized ? " (has " + std::to_string(s.acknowledged_frame) +
                                               " of " + std::to_string(args_.frames) + " frames)"
                                         : " (never connected)");
  }
  return out;
}

int Netplay::run() {
  if (Status s = start(); !s) return usage_error(netplay_name, s.message());
  say(args_.scenario + " (seed " + std::to_string(args_.seed) + ", " +
      std::to_string(args_.players) + " players): player " + std::to_string(args_.me) + " on " +
      transport_->local_endpoint().to_string() + ", " + args_.mode + ", input delay " +
      std::to_string(args_.input_delay) + ", " + std::to_string(args_.frames) + " frames");
  say(protection_line(plan_));
  for (const net::UdpPeer& p : plan_.peers)
    say(args_.open_seat
            ? "player " + std::to_string(p.id) + "'s seat is open: it may join at " +
                  p.endpoint.to_string() + " at any time (--join)"
            : "waiting for player " + std::to_string(p.id) + " at " + p.endpoint.to_string());
  for (std::size_t k = 0; k < plan_.spectators.size(); ++k)
    say("serving " + who(args_.players + static_cast<std::uint32_t>(k)));

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
          if (const char* keys = key_mismatch(rejected_[p.id]))
            failure_ += std::string(" (") + keys + ")";
          else if (!rejected_[p.id].empty())
            failure_ += " (its settings differ: " + rejected_[p.id] + ")";
          break;
        }
        break;
      }
      std::this_thread::sleep_for(std::chrono::microseconds(netplay_idle_sleep_us));
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
            std::chrono::microseconds(std::min(next_tick - now, netplay_idle_sleep_us)));
      }
      continue;
    }
    if (!ended_at) ended_at = now;
    if (!match_complete_ && session_->delivered_frame() >= args_.frames && peers_at_end()) {
      if (checks_behind().empty()) {
        match_complete_ = true;
      } else if (now - *ended_at >= timeout_us) {  // every frame is here, some checks never came
        unverified_.push_back("no hash check arrived from " + checks_behind());
        std::fprintf(stderr, "detsim netplay: UNVERIFIED: %s\n", unverified_.back().c_str());
        match_complete_ = true;
      }
    }
    if (match_complete_ && spectators_behind().empty()) {
      if (!settled_at) settled_at = now;
      if (now - *settled_at >= netplay_linger_us) break;
    } else if (now - *ended_at >= timeout_us) {
      if (match_complete_) {  // the match is complete: a spectator that lags is only warned about
        std::fprintf(stderr, "detsim netplay: stopped serving %s after the last frame\n",
                     spectators_behind().c_str());
        break;
      }
      const std::string behind = unconfirmed_players();
      failure_ = "timed out after the last frame: " + std::to_string(session_->delivered_frame()) +
                 " of " + std::to_string(args_.frames) + " frames confirmed; waiting for " +
                 (behind.empty() ? "the peers' last inputs" : behind);
      break;
    }
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

int Netplay::report(double handshake_seconds, double match_seconds) {
  const net::SessionStats& st = session_->stats();
  const int code = desyncs_.empty() && unverified_.empty() ? exit_ok : exit_check_failed;
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
    std::vector<std::string> spectators;
    for (std::size_t k = 0; k < plan_.spectators.size(); ++k) {
      const auto player = args_.players + static_cast<std::uint32_t>(k);
      const net::PeerStats s = session_->peer_stats(player).value_or(net::PeerStats{});
      spectators.push_back(Json()
                               .num("spectator", k)
                               .str("address", plan_.spectators[k].endpoint.to_string())
                               .boolean("connected", s.synchronized)
                               .num("acknowledged_frames", s.acknowledged_frame)
                               .num("packets_sent", s.packets_sent)
                               .num("bytes_sent", s.bytes_sent)
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
    j.str("scenario", args_.scenario)
        .num("seed", args_.seed)
        .num("players", args_.players)
        .num("player", args_.me)
        .boolean("spectator", false)
        .boolean("protected", plan_.match_key.has_value())
        .str("mode", args_.mode)
        .num("input_delay", args_.input_delay)
        .num("frames", session_->delivered_frame());
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
        .num("unverified", unverified_.size())
        .num("dropped_unauthenticated", st.dropped_unauthenticated)
        .num("dropped_replayed", st.dropped_replayed)
        .raw("desync_events", Json::array(desyncs))
        .raw("peers", Json::array(peers))
        .raw("spectators", Json::array(spectators));
    if (args_.record.empty()) {
      j.null("record");
    } else {
      j.str("record", args_.record);
    }
    if (report_written_) {
      j.str("desync_report", args_.desync_report);
    } else {
      j.null("desync_report");
    }
    j.real("handshake_seconds", handshake_seconds).real("match_seconds", match_seconds).print();
    return code;
  }
  print_text_report(handshake_seconds, match_seconds);
  return code;
}

void Netplay::print_text_report(double handshake_seconds, double match_seconds) const {
  const net::SessionStats& st = session_->stats();
  std::printf("frames       %llu, final hash %s\n",
              static_cast<unsigned long long>(session_->delivered_frame()),
              final_hash_ ? hex(*final_hash_).c_str() : "-");
  std::printf("rollbacks    %llu, %llu frames re-simulated\n",
              static_cast<unsigned long long>(st.rollbacks),
              static_cast<unsigned long long>(st.resimulated_frames));
  std::printf("desyncs      %zu\n", desyncs_.size());
  if (plan_.match_key)
    std::printf("protection   sealed; dropped %llu unauthenticated, %llu replayed\n",
                static_cast<unsigned long long>(st.dropped_unauthenticated),
                static_cast<unsigned long long>(st.dropped_replayed));
  for (const std::string& line : unverified_)
    std::printf("UNVERIFIED   %s\n", line.c_str());
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
  for (std::size_t k = 0; k < plan_.spectators.size(); ++k) {
    const auto player = args_.players + static_cast<std::uint32_t>(k);
    const net::PeerStats s = session_->peer_stats(player).value_or(net::PeerStats{});
    std::printf(
        "spectator %-2zu %s: %llu of %llu frames acknowledged; packets %llu sent, %llu "
        "bytes sent\n",
        k, plan_.spectators[k].endpoint.to_string().c_str(),
        static_cast<unsigned long long>(s.acknowledged_frame),
        static_cast<unsigned long long>(args_.frames),
        static_cast<unsigned long long>(s.packets_sent),
        static_cast<unsigned long long>(s.bytes_sent));
  }
  if (!args_.record.empty()) std::printf("replay       %s\n", args_.record.c_str());
  if (report_written_) std::printf("desync report %s\n", args_.desync_report.c_str());
  std::printf("time         handshake %.2f s, match %.2f s (%.0f frames/s)\n", handshake_seconds,
              match_seconds,
              match_seconds > 0 ? static_cast<double>(args_.frames) / match_seconds : 0.0);
}

}  // namespace

int netplay_command(const NetplayArgs& args) {
  if (!args.server.empty()) return server_client_command(args);
  if (args.frames == 0 || args.frames > 100'000'000)
    return usage_error(netplay_name,
                       "--frames must be 1 .. 100000000, got " + std::to_string(args.frames));
  if (!(args.timeout_seconds > 0 && args.timeout_seconds <= 86'400))
    return usage_error(netplay_name, "--timeout must be more than 0 and at most 86400 seconds");
  auto plan = netplay_plan(args);
  if (!plan) return usage_error(netplay_name, plan.message());
  if (args.spectate) return spectate(args, plan.value());
  Netplay match(args, std::move(plan.value()));
  return match.run();
}

}  // namespace detsim::cli
