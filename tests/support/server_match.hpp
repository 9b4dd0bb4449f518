// Test support for the game server (net/server.hpp, net/client.hpp): a server and N clients, each
// with its own game, over a SimNetwork stepped in virtual time (1 ms a tick). Clients join at a
// chosen time, may be killed and restarted (a new client and a new game at frame 0), and play
// scripted inputs; everything the server simulates is recorded.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <detsim/net/client.hpp>
#include <detsim/net/server.hpp>
#include <detsim/net/sim_network.hpp>
#include <detsim/scenario_net/scenario_game.hpp>
#include <detsim/scenario_net/scenario_recorder.hpp>
#include <detsim/scenes/scenario.hpp>

#include "support/net_match.hpp"

namespace detsim::test {

struct ServerMatchOptions {
  /// A scenario every side plays (through ScenarioGame; its input size and the scripted bots'
  /// inputs, seeded with `seed`), with `players` seats; empty: CounterGame.
  std::string scenario;
  /// Another game for every side (neither CounterGame nor a scenario); its input size must be
  /// input_size.
  std::function<std::unique_ptr<net::Game>()> make_game;
  /// With a scenario: the server records the match to this replay file.
  std::string record;
  std::uint32_t clients = 2;
  std::uint32_t players = 0;  ///< seats (0: as many as clients)
  std::uint32_t input_size = 4;
  std::uint32_t frames = 300;
  std::uint64_t seed = 1;
  net::server_protocol::Authority authority = net::server_protocol::Authority::inputs;
  std::uint32_t update_interval = 3;
  std::uint32_t snapshot_interval = 1;
  std::uint32_t start_clients = 0;  ///< ServerConfig::start_clients (0: as many as clients)
  net::LinkConditions link{};       ///< every link, both ways
  /// Client c's first poll (ms); 0 for every client not listed.
  std::vector<std::uint64_t> join_ms;
  /// A kill of client c at kill_ms: its client and game are destroyed and it falls silent; at
  /// restart_ms a new client and game (at frame 0) connect from the same network node.
  struct Restart {
    std::uint32_t client = 0;
    std::uint64_t kill_ms = 0;
    std::uint64_t restart_ms = 0;
  };
  std::vector<Restart> restarts;
  /// Client c's input for frame f (input_size bytes); default: changes every 8 frames.
  std::function<void(std::uint32_t client, std::uint64_t frame, std::span<std::uint8_t> out)> input;
  /// Called with the network before the match (per-link conditions, outages).
  std::function<void(net::SimNetwork&)> setup;
  /// Wraps client c's transport (forged-packet tests); nullptr keeps the endpoint.
  std::function<std::unique_ptr<net::Transport>(std::uint32_t client, net::Transport& inner)> wrap;
  std::function<void(net::ServerConfig&)> configure_server;
  std::function<void(std::uint32_t client, net::ClientConfig&)> configure_client;
  std::uint64_t max_ms = 0;  ///< 0: frames * 17 * 4 + 10000
};

/// Node 0 is the server, node c + 1 client c.
class ServerMatch {
 public:
  explicit ServerMatch(const ServerMatchOptions& options);
  ~ServerMatch();

  /// Ticks until the server settled and every live client ended (or max_ms); true if so.
  bool run();
  /// Ticks `ms` times (1 ms each); true if everything ended on the last one.
  bool run_for(std::uint64_t ms);

  net::Server& server() { return *server_; }
  net::Game& server_game() { return *server_game_.game; }
  /// The server's CounterGame (nullptr with a scenario).
  CounterGame* server_counter() { return dynamic_cast<CounterGame*>(server_game_.game.get()); }
  net::SimNetwork& network() { return network_; }
  /// Client c's current client and game (after a restart: the new ones); nullptr while killed.
  net::Client* client(std::uint32_t c) { return clients_[c].client.get(); }
  net::Game* game(std::uint32_t c) { return clients_[c].side.game.get(); }
  /// Client c's CounterGame (nullptr with a scenario, or while killed).
  CounterGame* counter(std::uint32_t c) {
    return dynamic_cast<CounterGame*>(clients_[c].side.game.get());
  }
  /// The server's recorder (with options.record), to finish.
  net::ScenarioRecorder* recorder() { return recorder_ ? &*recorder_ : nullptr; }
  /// The frames the server simulated: each one's inputs and hash, in order.
  const std::vector<std::uint64_t>& server_hashes() const { return hashes_; }
  std::uint64_t now_ms() const { return now_ms_; }

 private:
  /// One side's game: a CounterGame, or a scenario and its adapter.
  struct Side {
    std::unique_ptr<Scenario> scenario;
    std::unique_ptr<net::Game> game;
  };
  Side make_side() const;
  struct Seat {
    Side side;
    std::unique_ptr<net::Transport> wrapped;
    std::unique_ptr<net::Client> client;
    std::uint64_t next_frame_us = 0;
    std::uint64_t ticks = 0;
    bool killed = false;
  };
  void connect(std::uint32_t c);
  /// One millisecond: restarts and joins due, the server, every client; true once the server
  /// settled and every live client ended.
  bool tick();
  void tick_client(std::uint32_t c);

  ServerMatchOptions options_;
  net::SimNetwork network_;
  Side server_game_;
  std::optional<net::ScenarioRecorder> recorder_;
  std::unique_ptr<net::Server> server_;
  std::vector<Seat> clients_;
  std::vector<std::uint64_t> hashes_;
  std::uint64_t now_ms_ = 0;
  std::optional<std::uint64_t> settled_at_ms_;
};

}  // namespace detsim::test
