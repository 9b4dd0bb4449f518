// detsim demo, the main job: a 4-player match of bots (the arena, or --scenario: soccar), each
// player with its own game and rollback session, over one simulated network with a 100 ms round
// trip, jitter, loss, duplication and reordering, in virtual time. Player 0 records its confirmed
// frames; the replay is then verified, and the summary says whether every peer confirmed the same
// hash at every frame.
#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <system_error>
#include <vector>

#include <detsim/net/session.hpp>
#include <detsim/net/sim_network.hpp>
#include <detsim/replay/scenario_replay.hpp>
#include <detsim/scenario_net/scenario_game.hpp>
#include <detsim/scenario_net/scenario_recorder.hpp>

#include "commands.hpp"
#include "output.hpp"
#include "scenario_args.hpp"

namespace detsim::cli {

namespace {

constexpr std::string_view demo_name = "demo";
constexpr std::uint32_t demo_players = 4;
constexpr std::uint64_t demo_frame_us = 16'667;  // 60 Hz
constexpr std::uint32_t demo_input_delay = 2;
/// Ticks the match goes on after every peer confirmed every frame, so that the last hash checks
/// are exchanged and compared (half a second of virtual time).
constexpr std::uint64_t demo_linger_ticks = 30;

/// One player's machine: its own scenario, game adapter and session, and what it confirmed.
struct Peer {
  std::unique_ptr<Scenario> scenario;
  std::unique_ptr<net::ScenarioGame> game;
  std::optional<net::Session> session;
  std::vector<std::uint64_t> hashes;  ///< per confirmed frame
  std::vector<net::Event> desyncs;
  std::uint64_t bytes_sent = 0;  ///< to every other peer, payload only
};

struct MatchResult {
  bool completed = false;
  std::uint64_t virtual_us = 0;
  std::optional<std::uint64_t> first_disagreement;  ///< a frame (1-based state) peers differ at
  std::size_t desyncs = 0;
};

/// The first frame (the state after it, 1-based) at which some peer's confirmed hash differs
/// from player 0's, or where some peer confirmed fewer frames.
std::optional<std::uint64_t> first_disagreement(const std::vector<Peer>& peers,
                                                std::uint64_t frames) {
  for (std::uint64_t f = 0; f < frames; ++f) {
    for (const Peer& p : peers) {
      const auto i = static_cast<std::size_t>(f);  // f < hashes.size() before indexing
      if (p.hashes.size() <= f || p.hashes[i] != peers[0].hashes[i]) return f + 1;
    }
  }
  return std::nullopt;
}

std::string temp_replay_path() {
  std::error_code ec;
  const std::filesystem::path dir = std::filesystem::temp_directory_path(ec);
  std::random_device device;
  return (dir / ("detsim-demo-" + hex(device()).substr(8) + ".dsr")).string();
}

class Demo {
 public:
  explicit Demo(const DemoArgs& args) : args_(args) {}
  int run();

 private:
  Status set_up(const std::string& replay_path);
  MatchResult play();
  int report(const MatchResult& match, const replay::VerifyResult& verified,
             std::uint64_t replay_bytes, double match_seconds, double verify_seconds);

  const DemoArgs& args_;
  std::optional<net::SimNetwork> network_;
  std::vector<Peer> peers_;
  std::optional<net::ScenarioRecorder> recorder_;
  std::string path_;
};

Status Demo::set_up(const std::string& replay_path) {
  const ScenarioInfo* info = find_scenario(args_.scenario);
  if (info == nullptr)
    return Status::error("unknown scenario '" + args_.scenario + "' (detsim scenarios lists them)");
  if (info->min_players > demo_players || info->max_players < demo_players ||
      info->input_size != PlayerInput::encoded_size)
    return Status::error("scenario '" + args_.scenario +
                         "' does not take 4 players of built-in input; the demo's bots need one "
                         "that does (arena, soccar)");
  auto network =
      net::SimNetwork::create(demo_players, args_.seed * 7919 + 13, net::internet_link());
  if (!network) return network.status();
  network_.emplace(std::move(network.value()));
  peers_.resize(demo_players);  // never resized again: sessions and listeners point into it
  ScenarioParams params;
  params.seed = args_.seed;
  params.players = demo_players;
  for (std::uint32_t p = 0; p < demo_players; ++p) {
    Peer& peer = peers_[p];
    auto scenario = Scenario::create(args_.scenario, params);
    if (!scenario) return scenario.status();
    peer.scenario = std::make_unique<Scenario>(std::move(scenario.value()));
    peer.game = std::make_unique<net::ScenarioGame>(*peer.scenario);
    if (p == 0) {  // the recorder sees the scenario at frame 0, before the session saves it
      auto recorder = net::ScenarioRecorder::create(replay_path, *peer.game);
      if (!recorder) return recorder.status();
      recorder_.emplace(std::move(recorder.value()));
    }
    net::SessionConfig config;
    config.mode = net::SessionMode::rollback;
    config.players = demo_players;
    config.local_player = p;
    config.input_size = peer.game->input_size();
    config.input_delay = demo_input_delay;
    config.fingerprint = session_fingerprint(*peer.scenario, config.mode, args_.frames);
    for (std::uint32_t q = 0; q < demo_players; ++q)
      if (q != p) config.remotes.push_back(net::RemotePlayer{q, q});
    auto session = net::Session::create(config, *peer.game, network_->endpoint(p));
    if (!session) return session.status();
    peer.session.emplace(std::move(session.value()));
    std::vector<std::uint64_t>& hashes = peer.hashes;
    const auto on_confirmed = [&hashes](const net::ConfirmedFrame& f) { hashes.push_back(f.hash); };
    if (p == 0) {
      recorder_->attach(*peer.session, on_confirmed);
    } else {
      peer.session->set_confirmed_listener(on_confirmed);
    }
  }
  return Status::success();
}

MatchResult Demo::play() {
  MatchResult result;
  const std::uint64_t frames = args_.frames;
  const std::uint64_t max_ticks = frames * 4 + 2000;
  std::optional<std::uint64_t> done_at;
  std::array<std::uint8_t, PlayerInput::encoded_size> input{};
  Progress progress("demo");
  std::uint64_t tick = 0;
  for (; tick < max_ticks; ++tick) {
    const std::uint64_t now = tick * demo_frame_us;
    network_->advance_to(now);
    bool done = true;
    for (std::uint32_t p = 0; p < demo_players; ++p) {
      Peer& peer = peers_[p];
      net::Session& s = *peer.session;
      s.poll(now);
      // A peer ahead of the others skips every third tick until it is in time, as a game would.
      const bool wait = s.recommended_wait_frames() > 0 && tick % 3 == 0;
      if (s.current_frame() < frames && !wait) {
        // The bots play by frame: the match's inputs do not depend on the network's timing.
        encode_input(scripted_input(args_.seed, s.current_frame() + demo_input_delay, p), input);
        (void)s.advance_frame(input);  // the only error is an input of the wrong size
      }
      for (const net::Event& e : s.take_events())
        if (e.type == net::EventType::desync) peer.desyncs.push_back(e);
      if (peer.hashes.size() < frames) done = false;
    }
    progress.update(peers_[0].hashes.size(), frames);
    if (done && !done_at) done_at = tick;
    if (done_at && tick - *done_at >= demo_linger_ticks) break;
  }
  progress.done();
  result.completed = done_at.has_value();
  result.virtual_us = tick * demo_frame_us;
  result.first_disagreement = first_disagreement(peers_, frames);
  for (std::uint32_t p = 0; p < demo_players; ++p) {
    for (std::uint32_t q = 0; q < demo_players; ++q) {
      if (q == p) continue;
      if (const auto stats = peers_[p].session->peer_stats(q))
        peers_[p].bytes_sent += stats->bytes_sent;
    }
    result.desyncs += peers_[p].desyncs.size();
  }
  return result;
}

int Demo::run() {
  path_ = args_.record.empty() ? temp_replay_path() : args_.record;
  struct RemoveTemporary {
    const std::string* path;
    bool active;
    ~RemoveTemporary() {
      std::error_code ignored;
      if (active) std::filesystem::remove(*path, ignored);
    }
  } remove_temporary{&path_, args_.record.empty()};

  if (Status s = set_up(path_); !s) return usage_error(demo_name, s.message());
  auto start = std::chrono::steady_clock::now();
  const MatchResult match = play();
  const double match_seconds = seconds_since(start);
  if (Status s = recorder_->finish(); !s) return usage_error(demo_name, s.message());

  auto reader = replay::ReplayReader::open(path_);
  if (!reader) return usage_error(demo_name, reader.message());
  Progress verify_progress("verify");
  start = std::chrono::steady_clock::now();
  auto verified = replay::verify(reader.value(), [&](std::uint64_t done, std::uint64_t total) {
    verify_progress.update(done, total);
    return true;
  });
  const double verify_seconds = seconds_since(start);
  verify_progress.done();
  if (!verified) return usage_error(demo_name, verified.message());
  return report(match, verified.value(), reader->file_size(), match_seconds, verify_seconds);
}

int Demo::report(const MatchResult& match, const replay::VerifyResult& verified,
                 std::uint64_t replay_bytes, double match_seconds, double verify_seconds) {
  const std::uint64_t frames = args_.frames;
  const bool agree = match.completed && !match.first_disagreement && match.desyncs == 0;
  const bool verified_ok = verified.ok && verified.frames == frames;
  const std::vector<std::uint64_t>& hashes0 = peers_[0].hashes;
  const bool have_final = hashes0.size() >= frames;
  const std::uint64_t final_hash = have_final ? hashes0[static_cast<std::size_t>(frames - 1)] : 0;
  const double virtual_seconds = static_cast<double>(match.virtual_us) / 1e6;
  const auto per_second = [&](std::uint64_t bytes) {
    return virtual_seconds > 0 ? static_cast<double>(bytes) / virtual_seconds : 0.0;
  };
  std::uint64_t rollbacks = 0;
  std::uint64_t resimulated = 0;
  for (const Peer& p : peers_) {
    rollbacks += p.session->stats().rollbacks;
    resimulated += p.session->stats().resimulated_frames;
  }
  const int code = agree && verified_ok ? exit_ok : exit_check_failed;

  if (args_.json) {
    std::vector<std::string> peers;
    for (std::uint32_t p = 0; p < demo_players; ++p) {
      const net::SessionStats& st = peers_[p].session->stats();
      peers.push_back(Json()
                          .num("player", p)
                          .num("confirmed_frames", peers_[p].hashes.size())
                          .num("rollbacks", st.rollbacks)
                          .num("resimulated_frames", st.resimulated_frames)
                          .num("bytes_sent", peers_[p].bytes_sent)
                          .real("bytes_per_second", per_second(peers_[p].bytes_sent))
                          .num("desyncs", peers_[p].desyncs.size())
                          .text());
    }
    Json j;
    j.str("scenario", args_.scenario)
        .num("seed", args_.seed)
        .num("players", demo_players)
        .num("frames", frames);
    if (have_final) {
      j.hash("final_hash", final_hash);
    } else {
      j.null("final_hash");
    }
    j.num("rollbacks", rollbacks)
        .num("resimulated_frames", resimulated)
        .raw("peers", Json::array(peers))
        .boolean("completed", match.completed)
        .boolean("peers_agree", agree)
        .frame("first_disagreement", match.first_disagreement)
        .num("desyncs", match.desyncs)
        .boolean("verified", verified_ok)
        .frame("first_mismatch", verified.first_mismatch)
        .str("replay", path_)
        .boolean("replay_kept", !args_.record.empty())
        .num("replay_bytes", replay_bytes)
        .real("virtual_seconds", virtual_seconds)
        .real("match_seconds", match_seconds)
        .real("verify_seconds", verify_seconds)
        .print();
    return code;
  }
  std::printf("match        %s (seed %llu, 4 bots), %llu frames, rollback, input delay %u\n",
              args_.scenario.c_str(), static_cast<unsigned long long>(args_.seed),
              static_cast<unsigned long long>(frames), demo_input_delay);
  std::printf(
      "network      simulated: 50 ms each way (100 ms round trip), 20 ms jitter, 5%% loss, "
      "1%% duplicated, 1%% reordered\n");
  for (std::uint32_t p = 0; p < demo_players; ++p) {
    const net::SessionStats& st = peers_[p].session->stats();
    const auto ping = peers_[p].session->peer_stats(p == 0 ? 1 : 0);
    std::printf(
        "player %u     %llu rollbacks, %llu frames re-simulated, sends %.0f bytes/s (to the 3 "
        "others), ping %.0f ms\n",
        p, static_cast<unsigned long long>(st.rollbacks),
        static_cast<unsigned long long>(st.resimulated_frames), per_second(peers_[p].bytes_sent),
        ping ? static_cast<double>(ping->ping_us) / 1000.0 : 0.0);
  }
  std::printf("final hash   %s\n", have_final ? hex(final_hash).c_str() : "-");
  if (agree) {
    std::printf("peers agree  yes: all 4 confirmed the same hash at every one of %llu frames\n",
                static_cast<unsigned long long>(frames));
  } else if (!match.completed) {
    std::printf("peers agree  NO: the match did not complete (player 0 confirmed %zu of %llu)\n",
                hashes0.size(), static_cast<unsigned long long>(frames));
  } else {
    std::printf("peers agree  NO: first difference at frame %llu, %zu desync events\n",
                static_cast<unsigned long long>(match.first_disagreement.value_or(0)),
                match.desyncs);
  }
  std::printf("replay       %s (%llu bytes, player 0's confirmed frames%s)\n", path_.c_str(),
              static_cast<unsigned long long>(replay_bytes),
              args_.record.empty() ? ", removed afterwards" : "");
  if (verified_ok) {
    std::printf("verify       ok: every frame's hash reproduced\n");
  } else if (verified.first_mismatch) {
    std::printf("verify       MISMATCH at frame %llu\n",
                static_cast<unsigned long long>(*verified.first_mismatch));
  } else {
    std::printf("verify       FAILED: %llu frames verified%s%s\n",
                static_cast<unsigned long long>(verified.frames), verified.note.empty() ? "" : ": ",
                verified.note.c_str());
  }
  std::printf("time         match %.2f s for %.1f s of virtual time, verify %.2f s\n",
              match_seconds, virtual_seconds, verify_seconds);
  return code;
}

}  // namespace

int demo_command(const DemoArgs& args) {
  Demo demo(args);
  return demo.run();
}

}  // namespace detsim::cli
