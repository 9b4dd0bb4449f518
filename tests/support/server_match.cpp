// The game-server test harness (server_match.hpp).
#include "support/server_match.hpp"

#include <stdexcept>

namespace detsim::test {

namespace {

net::SimNetwork make_network(const ServerMatchOptions& o) {
  auto n = net::SimNetwork::create(o.clients + 1, o.seed, o.link);
  if (!n.ok()) throw std::runtime_error(n.message());
  return std::move(n.value());
}

}  // namespace

ServerMatch::Side ServerMatch::make_side() const {
  Side side;
  if (options_.make_game) {
    side.game = options_.make_game();
    return side;
  }
  if (options_.scenario.empty()) {
    side.game = std::make_unique<CounterGame>();
    return side;
  }
  ScenarioParams params;
  params.seed = options_.seed;
  params.players = options_.players;
  auto scenario = Scenario::create(options_.scenario, params);
  if (!scenario.ok()) throw std::runtime_error(scenario.message());
  side.scenario = std::make_unique<Scenario>(std::move(scenario.value()));
  side.game = std::make_unique<net::ScenarioGame>(*side.scenario);
  return side;
}

ServerMatch::ServerMatch(const ServerMatchOptions& options)
    : options_(options), network_(make_network(options)), clients_(options.clients) {
  if (options_.players == 0) options_.players = options_.clients;
  server_game_ = make_side();
  if (!options_.scenario.empty()) {
    options_.input_size = server_game_.scenario->info().input_size;
    if (!options_.input) {
      const Scenario* scenario = server_game_.scenario.get();
      const std::uint64_t seed = options_.seed;
      options_.input = [scenario, seed](std::uint32_t c, std::uint64_t f,
                                        std::span<std::uint8_t> out) {
        scenario->scripted(seed + 1, f, c, out);
      };
    }
    if (!options_.record.empty()) {
      auto recorder = net::ScenarioRecorder::create(
          options_.record, static_cast<net::ScenarioGame&>(*server_game_.game));
      if (!recorder.ok()) throw std::runtime_error(recorder.message());
      recorder_.emplace(std::move(recorder.value()));
    }
  }
  if (options_.start_clients == 0) options_.start_clients = options_.clients;
  if (options_.setup) options_.setup(network_);
  net::ServerConfig config;
  config.players = options_.players;
  config.input_size = options_.input_size;
  config.game = 0x5E4E'0001;
  config.frames = options_.frames;
  config.authority = options_.authority;
  config.update_interval = options_.update_interval;
  config.snapshot_interval = options_.snapshot_interval;
  config.start_clients = options_.start_clients;
  config.description = {'t', 'e', 's', 't'};
  if (options_.configure_server) options_.configure_server(config);
  auto s = net::Server::create(config, *server_game_.game, network_.endpoint(0));
  if (!s.ok()) throw std::runtime_error(s.message());
  server_ = std::make_unique<net::Server>(std::move(s.value()));
  const auto listen = [this](const net::ConfirmedFrame& f) { hashes_.push_back(f.hash); };
  if (recorder_) {
    recorder_->attach(*server_, listen);
  } else {
    server_->set_confirmed_listener(listen);
  }
  if (!options_.input) {
    options_.input = [](std::uint32_t c, std::uint64_t f, std::span<std::uint8_t> out) {
      for (std::size_t k = 0; k < out.size(); ++k)
        out[k] = static_cast<std::uint8_t>((f / 8) * (c + 1) + k);
    };
  }
}

ServerMatch::~ServerMatch() = default;

void ServerMatch::connect(std::uint32_t c) {
  Seat& seat = clients_[c];
  seat.side = make_side();
  net::Transport* transport = &network_.endpoint(c + 1);
  if (options_.wrap && !seat.wrapped) seat.wrapped = options_.wrap(c, *transport);
  if (seat.wrapped) transport = seat.wrapped.get();
  net::ClientConfig config;
  config.game = 0x5E4E'0001;
  config.server = 0;
  if (options_.configure_client) options_.configure_client(c, config);
  auto client = net::Client::create(config, *transport);
  if (!client.ok()) throw std::runtime_error(client.message());
  seat.client = std::make_unique<net::Client>(std::move(client.value()));
  seat.killed = false;
  seat.next_frame_us = now_ms_ * 1000;
}

void ServerMatch::tick_client(std::uint32_t c) {
  Seat& seat = clients_[c];
  net::Client& client = *seat.client;
  const std::uint64_t now_us = now_ms_ * 1000;
  client.poll(now_us);
  if (client.welcome() != nullptr && !client.started()) {
    if (!client.start(*seat.side.game).ok()) throw std::runtime_error("client start failed");
  }
  if (!client.running() || now_us < seat.next_frame_us) return;
  const std::uint32_t frame_us = client.welcome()->frame_us;
  seat.next_frame_us += frame_us;
  if (seat.next_frame_us < now_us) seat.next_frame_us = now_us;  // fell behind: no burst
  seat.ticks += 1;
  std::vector<std::uint8_t> input(client.welcome()->input_size);
  // Time sync: one frame extra, or one skipped, on one tick in three while it is asked for.
  const std::int32_t adjust = client.recommended_frame_adjust();
  int runs = 1;
  if (seat.ticks % 3 == 0 && adjust > 0) runs = adjust > 4 ? 3 : 2;
  if (seat.ticks % 3 == 0 && adjust < 0) runs = 0;
  for (int r = 0; r < runs; ++r) {
    options_.input(c, client.current_frame(), input);
    if (!client.advance_frame(input).ok()) throw std::runtime_error("advance_frame failed");
  }
}

bool ServerMatch::run() {
  const std::uint64_t max_ms =
      options_.max_ms != 0 ? options_.max_ms : std::uint64_t{options_.frames} * 17 * 4 + 10'000;
  while (now_ms_ < max_ms)
    if (tick()) return true;
  return false;
}

bool ServerMatch::run_for(std::uint64_t ms) {
  bool ended = false;
  for (std::uint64_t i = 0; i < ms; ++i)
    ended = tick();
  return ended;
}

bool ServerMatch::tick() {
  const std::uint64_t now_us = now_ms_ * 1000;
  network_.advance_to(now_us);
  for (const ServerMatchOptions::Restart& r : options_.restarts) {
    if (now_ms_ == r.kill_ms) {
      clients_[r.client].client.reset();
      clients_[r.client].side = {};
      clients_[r.client].killed = true;
    }
    if (now_ms_ == r.restart_ms) connect(r.client);
  }
  for (std::uint32_t c = 0; c < options_.clients; ++c) {
    const std::uint64_t join = c < options_.join_ms.size() ? options_.join_ms[c] : 0;
    if (now_ms_ == join && !clients_[c].client && !clients_[c].killed) connect(c);
  }
  // A server that settled lingers half a second, then stops, as `detsim serve` does: a client
  // that still needed something from it never ends.
  if (!settled_at_ms_ && server_->settled()) settled_at_ms_ = now_ms_;
  if (!settled_at_ms_ || now_ms_ < *settled_at_ms_ + 500) {
    server_->poll(now_us);
    server_->advance(now_us);
    server_->poll(now_us);
  }
  bool all_ended = server_->settled();
  for (std::uint32_t c = 0; c < options_.clients; ++c) {
    if (!clients_[c].client) {
      if (!clients_[c].killed) all_ended = false;
      continue;
    }
    tick_client(c);
    if (!clients_[c].client->ended()) all_ended = false;
  }
  ++now_ms_;
  return all_ended;
}

}  // namespace detsim::test
