// detsim::net::Server: a server-authoritative match (docs/SERVER.md). The server owns the match:
// it admits clients (net::Client) into seats, stamps each client's inputs to the frames it
// simulates — never waiting for a slow client — and tells every client what happened: the inputs
// of every player and a hash of its state (Authority::inputs), or its state itself, delta-coded
// (Authority::state). A client predicts and reconciles exactly (client.hpp).
//
// Each tick the server's program calls
//
//     server.poll(now_us);        // network in: connects, inputs, acknowledgements
//     server.advance(now_us);     // simulates every frame due by the clock (frame_us each)
//     server.poll(now_us);        // network out: updates, snapshots
//
// Stamping: a client tags each input with the frame it is for. Frame F takes, for each seat, the
// client's input tagged F if it has arrived; else the newest one that arrived late (tagged before
// F, never used); else the seat's last input again. An input tagged beyond F + input_window, or
// before a frame already simulated with a newer one, is dropped and counted. Seats without a client
// are absent: their inputs are zero, and the unit says so (InputStatus::disconnected).
//
// Trust: a client is its transport peer (its address) and the 64-bit token the welcome gave it.
// A datagram from another peer, or with another token, never changes a thing; a client's inputs
// only ever fill its own seat; the server never rolls back. Everything it refuses is counted.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include <detsim/core/status.hpp>
#include <detsim/net/game.hpp>
#include <detsim/net/server_protocol.hpp>
#include <detsim/net/session.hpp>
#include <detsim/net/transport.hpp>

namespace detsim::net {

/// A server's settings: plain data with defaults. Server::create() names the first invalid field.
struct ServerConfig {
  std::uint32_t players = 2;     ///< seats: 1 .. server_protocol::max_players
  std::uint32_t input_size = 4;  ///< bytes per input: 1 .. protocol::max_input_size
  /// The game's fingerprint: a connect naming another is rejected (RejectReason::wrong_game).
  std::uint64_t game = 0;
  /// Handed to every client in its welcome (at most server_protocol::max_description bytes): what
  /// a client needs to build the game (the CLI: the scenario, its seed and player count).
  std::vector<std::uint8_t> description;
  server_protocol::Authority authority = server_protocol::Authority::inputs;
  std::uint32_t frame_us = 16'667;  ///< the frame's duration: 1000 .. 1'000'000
  std::uint32_t frames = 0;         ///< the match's length (0: until the program stops it)
  /// The match starts (frame 0 is simulated) once this many clients are in (0 .. players: 0
  /// starts at once); the rest join in progress.
  std::uint32_t start_clients = 0;
  /// An update (inputs, hash) to each client every this many frames: 1 .. 60.
  std::uint32_t update_interval = 3;
  /// Authority::state: a snapshot to each client every this many frames: 1 .. 600.
  std::uint32_t snapshot_interval = 1;
  /// The furthest ahead of the server's simulation a client's input may be tagged: 1 .. 1000.
  std::uint32_t input_window = 120;
  /// Frames whose units and hashes the server keeps: a client whose acknowledgement falls
  /// further behind gets a snapshot instead. 16 .. 100000.
  std::uint32_t history = 512;
  /// Silence after which a client is gone and its seat free (absent from the next frame).
  std::uint64_t client_timeout_us = 3'000'000;
  /// Snapshot slices sent to one client per poll while it has none of the current one.
  std::uint32_t snapshot_burst = 32;
  /// Authority::state: code each snapshot against the one sent before it, which the client holds
  /// a round trip before it can say so, rather than against the newest it acknowledged (a round
  /// trip older, so a larger delta). A lost snapshot makes the ones after it undecodable until
  /// the server misses its acknowledgement (a round trip and a quarter) and codes against the
  /// acknowledged one again. On by default: on the cubes benchmark (1 % loss, 100 ms round trip)
  /// it sends 11 % fewer bytes and delivers 11 % fewer snapshots (docs/SERVER.md, "Figures").
  bool chain_snapshots = true;
  /// Authority::state: per-client relevancy (server_protocol.hpp, StateView): each client is sent
  /// the view of the state this gives for its seat. Empty: the whole state to everyone. Its
  /// clients need the same function and a MergeView (ClientConfig).
  StateView view;
};

/// One client as the server sees it.
struct ServerClientStats {
  std::uint32_t player = 0;
  PeerId peer = 0;
  bool connected = false;
  std::uint64_t joined_frame = 0;  ///< the first frame its seat was present
  std::uint64_t bytes_sent = 0;    ///< payload bytes, without IP/UDP headers
  std::uint64_t bytes_received = 0;
  std::uint64_t packets_sent = 0;
  std::uint64_t packets_received = 0;
  /// Its inputs used in a later frame than their tag (they arrived after that frame ran).
  std::uint64_t inputs_late = 0;
  /// Frames that repeated its last input (nothing new had arrived).
  std::uint64_t inputs_missing = 0;
  /// Its datagrams dropped: malformed, outside the input window, or implausible.
  std::uint64_t packets_rejected = 0;
  std::uint64_t acknowledged_frame = 0;  ///< it holds every frame's unit before this
  std::int32_t lead = 0;  ///< how far ahead of the simulation its inputs arrive (frames)
  std::uint64_t snapshots_sent = 0;
  std::uint64_t snapshot_bytes_sent = 0;
  /// Authority::state: snapshots coded as the game's delta (Game::encode_delta), and those coded
  /// against a snapshot the client had not acknowledged yet (ServerConfig::chain_snapshots).
  std::uint64_t snapshots_game_coded = 0;
  std::uint64_t snapshots_chained = 0;
};

struct ServerStats {
  std::uint64_t frames = 0;  ///< simulated
  std::uint64_t connects = 0;
  std::uint64_t rejects = 0;
  std::uint64_t bytes_sent = 0;
  std::uint64_t bytes_received = 0;
  /// Datagrams dropped before reaching a client: malformed (by protocol::DecodeError), or from a
  /// peer or with a token that is no admitted client's.
  std::array<std::uint64_t, protocol::decode_error_count> dropped_malformed{};
  std::uint64_t dropped_unknown = 0;
  std::uint64_t clients_timed_out = 0;
  std::uint64_t clients_left = 0;
  /// How late frames were simulated: frame F is due at the match's start + F × frame_us, and a
  /// frame whose advance() came later (the loop woke late, or the machine is too busy) counts
  /// the delay, in buckets of tick_lateness_bucket_us (the last: that much or more).
  static constexpr std::uint64_t tick_lateness_bucket_us = 100;
  std::array<std::uint64_t, 512> tick_lateness{};
  std::uint64_t tick_lateness_max_us = 0;
  /// The lateness (a bucket's upper edge, µs) that at least per_mille / 1000 of the frames
  /// simulated were within; 0 before any frame. per_mille 990: the 99th percentile.
  [[nodiscard]] std::uint64_t tick_lateness_percentile_us(std::uint32_t per_mille) const noexcept;
  /// Counts one frame simulated `late_us` after its time (Server::advance does, per frame).
  void count_tick_lateness(std::uint64_t late_us) noexcept;
};

enum class ServerEventType : std::uint8_t {
  joined,   ///< a client took seat `player` from frame `frame`
  left,     ///< seat `player` is free from frame `frame` (`reason`: "left", "silent")
  started,  ///< frame 0 is about to be simulated
};

struct ServerEvent {
  ServerEventType type = ServerEventType::joined;
  std::uint32_t player = 0;
  std::uint64_t frame = 0;
  PeerId peer = 0;
  std::string_view reason;  ///< string literals: never dangle
};

class Server {
 public:
  /// A server driving `game` (at its initial state: frame 0) over `transport`; both must outlive
  /// it. Errors name the first invalid field of `config`.
  static Expected<Server> create(const ServerConfig& config, Game& game, Transport& transport);
  Server(Server&&) noexcept;
  Server& operator=(Server&&) noexcept;
  ~Server();

  /// Receives and handles every pending datagram, then sends what is due (welcomes, updates,
  /// snapshots) and frees the seats of silent clients. `now_us`: a monotonic clock.
  void poll(std::uint64_t now_us);
  /// Simulates every frame whose time has come (frame F at start + F * frame_us, the start being
  /// the first call once the match may start), at most `max_frames`; returns how many. Nothing
  /// after the match's last frame.
  std::uint32_t advance(std::uint64_t now_us, std::uint32_t max_frames = 8);

  /// Called for every frame simulated, in order, with its inputs, statuses and the state's hash
  /// after it (what a replay records: ScenarioRecorder::attach).
  void set_confirmed_listener(std::function<void(const ConfirmedFrame&)> listener);
  [[nodiscard]] std::vector<ServerEvent> take_events();

  [[nodiscard]] const ServerConfig& config() const noexcept;
  /// The next frame to simulate: the game's state is at this frame.
  [[nodiscard]] std::uint64_t current_frame() const noexcept;
  /// The hash of the state at current_frame().
  [[nodiscard]] std::uint64_t current_hash() const noexcept;
  /// The match ran its `frames` (never for an open-ended match).
  [[nodiscard]] bool ended() const noexcept;
  /// ended(), and every connected client has acknowledged the last frame.
  [[nodiscard]] bool settled() const noexcept;
  [[nodiscard]] const ServerStats& stats() const noexcept;
  /// The clients that left (the newest 256, oldest first), then those connected now. Without
  /// comings and goings: every client, in the order they were admitted.
  [[nodiscard]] std::vector<ServerClientStats> client_stats() const;

 private:
  struct Impl;
  explicit Server(std::unique_ptr<Impl> impl) noexcept;
  std::unique_ptr<Impl> impl_;
};

}  // namespace detsim::net
