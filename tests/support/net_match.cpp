#include "support/net_match.hpp"

#include <algorithm>
#include <sstream>

namespace detsim::test {

Match::Match(const MatchOptions& options) : options_(options) {
  auto network = net::SimNetwork::create(options.players + options.spectators,
                                         options.seed * 7919 + 13, options.link);
  network_.emplace(std::move(network.value()));  // the test's own settings: always valid
  if (options.setup) options.setup(*network_);
  records_.resize(options.players);
  sessions_.resize(options.players);
  for (std::uint32_t p = 0; p < options.players; ++p) {
    games_.push_back(make_game(p));
    net::Transport* transport = &network_->endpoint(p);
    if (options.wrap) {
      wrappers_.push_back(options.wrap(p, *transport));
      if (wrappers_.back()) transport = wrappers_.back().get();
    }
    transports_.push_back(transport);
    start_session(p, false);
  }
}

void Match::start_session(std::uint32_t p, bool rejoin) {
  net::SessionConfig config;
  config.mode = options_.mode;
  config.players = options_.players;
  config.local_player = p;
  config.input_size = options_.arena ? PlayerInput::encoded_size : 4;
  config.input_delay = options_.input_delay;
  config.max_prediction = options_.max_prediction;
  config.check_interval = options_.check_interval;
  config.fingerprint = 0xD5'1A'77ULL + options_.players;
  config.match_key = options_.match_key;
  config.rejoin = rejoin;
  for (std::uint32_t q = 0; q < options_.players; ++q)
    if (q != p) config.remotes.push_back(net::RemotePlayer{q, q});
  if (p == 0 && !rejoin)
    for (std::uint32_t k = 0; k < options_.spectators; ++k)
      config.spectators.push_back(options_.players + k);
  if (options_.configure) options_.configure(p, config);
  auto session = net::Session::create(config, *games_[p], *transports_[p]);
  sessions_[p].emplace(std::move(session.value()));
  PeerRecord& record = records_[p];
  sessions_[p]->set_confirmed_listener([&record](const net::ConfirmedFrame& f) {
    if (record.hashes.empty()) record.first_frame = f.frame;
    record.hashes.push_back(f.hash);
    record.inputs.insert(record.inputs.end(), f.inputs.begin(), f.inputs.end());
    record.status.insert(record.status.end(), f.status.begin(), f.status.end());
  });
}

bool Match::restarted_peer_up(std::uint32_t p) {
  std::vector<MatchOptions::Restart> restarts = options_.more_restarts;
  if (options_.restart_peer)
    restarts.push_back({*options_.restart_peer, options_.restart_tick, options_.rejoin_tick});
  for (const MatchOptions::Restart& r : restarts) {
    if (r.peer != p) continue;
    if (tick_ == r.restart_tick && sessions_[p]) {  // the process dies: all of it is lost
      sessions_[p].reset();
      games_[p].reset();
      if (options_.restart_peer == p) earlier_record_ = std::move(records_[p]);
      records_[p] = PeerRecord{};
    }
    if (tick_ == r.rejoin_tick && !sessions_[p]) {
      games_[p] = make_game(p);
      start_session(p, true);
    }
  }
  return sessions_[p].has_value();
}

std::unique_ptr<net::Game> Match::make_game(std::uint32_t p) {
  if (options_.arena) {
    ScenarioParams params;
    params.seed = options_.seed;
    params.players = options_.players;
    params.count = options_.arena_count;
    auto scenario = Scenario::create("arena", params);
    scenarios_.push_back(std::make_unique<Scenario>(std::move(scenario.value())));
    return std::make_unique<net::ScenarioGame>(*scenarios_.back());
  }
  auto game = std::make_unique<CounterGame>();
  if (options_.fault_frame && p == options_.fault_peer) game->fault_frame = options_.fault_frame;
  return game;
}

void Match::add_spectators() {
  spectator_records_.resize(options_.spectators);
  for (std::uint32_t k = 0; k < options_.spectators; ++k) {
    spectator_games_.push_back(make_game(options_.players + k));
    net::SpectatorConfig config;
    config.players = options_.players;
    config.input_size = sessions_[0]->config().input_size;
    config.fingerprint = sessions_[0]->config().fingerprint;
    config.host = 0;
    config.match_key = options_.match_key;
    if (options_.configure_spectator) options_.configure_spectator(k, config);
    auto s = net::SpectatorSession::create(config, *spectator_games_.back(),
                                           network_->endpoint(options_.players + k));
    spectator_sessions_.emplace_back(std::move(s.value()));
    PeerRecord& record = spectator_records_[k];
    spectator_sessions_[k]->set_confirmed_listener([&record](const net::ConfirmedFrame& f) {
      record.hashes.push_back(f.hash);
      record.inputs.insert(record.inputs.end(), f.inputs.begin(), f.inputs.end());
      record.status.insert(record.status.end(), f.status.begin(), f.status.end());
    });
  }
}

bool Match::run() {
  if (spectator_sessions_.size() < options_.spectators) add_spectators();
  const std::uint64_t frame_us = 16'667;
  const std::uint64_t limit = options_.max_ticks ? options_.max_ticks : options_.frames * 4 + 2000;
  std::vector<std::uint8_t> input(sessions_[0]->config().input_size);
  for (; tick_ < limit; ++tick_) {
    const std::uint64_t now = tick_ * frame_us;
    network_->advance_to(now);
    bool done = true;
    for (std::uint32_t p = 0; p < options_.players; ++p) {
      if (!restarted_peer_up(p)) {
        done = false;
        continue;
      }
      net::Session& s = *sessions_[p];
      s.poll(now);
      if (options_.on_tick) options_.on_tick(p, tick_, s);
      const bool active = !options_.active || options_.active(p, tick_);
      if (active && s.current_frame() < options_.frames) {
        // Time sync: a peer that is ahead skips a tick, as a game would.
        if (!options_.time_sync || s.recommended_wait_frames() == 0 || tick_ % 4 != 0) {
          const PlayerInput bot = scripted_input(options_.seed, tick_, p);
          if (options_.arena) {
            encode_input(bot, std::span<std::uint8_t, PlayerInput::encoded_size>(input.data(), 3));
          } else if (options_.zero_input_peer == p) {
            std::fill(input.begin(), input.end(), std::uint8_t{0});
          } else {
            for (std::size_t i = 0; i < input.size(); ++i)
              input[i] = static_cast<std::uint8_t>(
                  (bot.buttons + i * static_cast<std::uint8_t>(bot.move_x)) & 0xFFU);
          }
          auto result = s.advance_frame(input);
          if (!result.ok()) {  // the session stopped (a match that ended): keep what it said
            for (std::uint32_t q = 0; q < options_.players; ++q)
              if (sessions_[q])
                for (const net::Event& e : sessions_[q]->take_events())
                  records_[q].events.push_back(e);
            return false;
          }
        }
      }
      for (const net::Event& e : s.take_events())
        records_[p].events.push_back(e);
      const bool gone = !active;
      if (!gone && records_[p].first_frame + records_[p].hashes.size() < options_.frames)
        done = false;
    }
    for (std::uint32_t k = 0; k < options_.spectators; ++k) {
      if (tick_ < options_.spectator_join_tick) {
        done = false;
        continue;
      }
      net::SpectatorSession& s = *spectator_sessions_[k];
      s.poll(now);
      s.advance();
      for (const net::Event& e : s.take_events())
        spectator_records_[k].events.push_back(e);
      if (spectator_records_[k].hashes.size() < options_.frames) done = false;
    }
    if (done) return true;
  }
  return false;
}

void Match::idle(std::uint64_t ticks) {
  for (const std::uint64_t end = tick_ + ticks; tick_ < end; ++tick_) {
    const std::uint64_t now = tick_ * 16'667;
    network_->advance_to(now);
    for (std::uint32_t p = 0; p < options_.players; ++p) {
      if (!restarted_peer_up(p)) continue;
      sessions_[p]->poll(now);
      for (const net::Event& e : sessions_[p]->take_events())
        records_[p].events.push_back(e);
    }
  }
}

std::vector<std::uint64_t> Match::offline_hashes(std::uint32_t p) const {
  const PeerRecord& r = records_[p];
  const std::size_t size = sessions_[p]->config().input_size;
  const std::size_t players = options_.players;
  std::unique_ptr<Scenario> scenario;
  std::unique_ptr<net::Game> game;
  if (options_.arena) {
    ScenarioParams params;
    params.seed = options_.seed;
    params.players = options_.players;
    params.count = options_.arena_count;
    scenario = std::make_unique<Scenario>(Scenario::create("arena", params).value());
    game = std::make_unique<net::ScenarioGame>(*scenario);
  } else {
    game = std::make_unique<CounterGame>();
  }
  std::vector<std::uint64_t> hashes;
  std::vector<std::uint8_t> state;
  for (std::size_t f = 0; f < r.hashes.size(); ++f) {
    net::FrameInputs in{
        f, size,
        std::span<const std::uint8_t>(r.inputs).subspan(f * players * size, players * size),
        std::span<const net::InputStatus>(r.status).subspan(f * players, players)};
    game->advance(in, false);
    hashes.push_back(game->save(state));
  }
  return hashes;
}

std::string Match::checks_complete() const {
  std::ostringstream out;
  if (options_.check_interval == 0) return "";
  const std::uint64_t per_peer = options_.frames / options_.check_interval;
  const std::uint64_t expected = (per_peer > 2 ? per_peer - 2 : 0) * (options_.players - 1);
  for (std::uint32_t p = 0; p < options_.players; ++p) {
    const net::SessionStats& s = sessions_[p]->stats();
    if (s.checks_compared < expected || s.checks_skipped != 0 || s.checks_missing != 0)
      out << "peer " << p << " compared " << s.checks_compared << " checks (expected at least "
          << expected << "), skipped " << s.checks_skipped << " and missed " << s.checks_missing
          << "; ";
  }
  return out.str();
}

std::string Match::compare() const {
  std::ostringstream out;
  std::size_t common = records_[0].hashes.size();
  for (const PeerRecord& r : records_)
    common = std::min(common, r.hashes.size());
  if (common < options_.frames) out << "only " << common << " frames confirmed by every peer; ";
  const std::size_t players = options_.players;
  const std::size_t frame_bytes = players * sessions_[0]->config().input_size;
  for (std::uint32_t p = 1; p < options_.players; ++p) {
    for (std::size_t f = 0; f < common; ++f) {
      const bool inputs_equal = std::equal(
          records_[p].inputs.begin() + static_cast<std::ptrdiff_t>(f * frame_bytes),
          records_[p].inputs.begin() + static_cast<std::ptrdiff_t>((f + 1) * frame_bytes),
          records_[0].inputs.begin() + static_cast<std::ptrdiff_t>(f * frame_bytes));
      if (!inputs_equal || records_[p].hashes[f] != records_[0].hashes[f]) {
        out << "peer " << p << " differs from peer 0 at frame " << f
            << (inputs_equal ? " (hash)" : " (inputs)") << "; ";
        break;
      }
    }
  }
  // Peers agree with peer 0 (above), so peer 0's offline replay stands for all.
  for (std::uint32_t p = 0; p < 1; ++p) {
    const std::vector<std::uint64_t> offline = offline_hashes(p);
    for (std::size_t f = 0; f < offline.size(); ++f) {
      if (offline[f] != records_[p].hashes[f]) {
        out << "peer " << p << " differs from its offline replay at frame " << f << "; ";
        break;
      }
    }
  }
  for (std::uint32_t p = 0; p < options_.players; ++p)
    if (records_[p].has(net::EventType::desync)) out << "peer " << p << " raised a desync; ";
  return out.str();
}

}  // namespace detsim::test
