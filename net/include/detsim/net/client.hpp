// detsim::net::Client: one player of a server-authoritative match (server.hpp, docs/SERVER.md).
// It predicts: its own input applies at once, the others' are their last known ones. When the
// server's word for frame N arrives it compares: a prediction that was right costs nothing (the
// state it saved at N hashes to the server's); a wrong one is corrected exactly — it re-simulates
// from the first mispredicted frame with the server's inputs (Authority::inputs), or loads the
// server's state (Authority::state), and re-applies its own inputs up to the present. Because the
// simulation is deterministic, every correction is explained by a mispredicted input; a state
// that differs from the server's where every input was right is a desync, and is reported.
//
//     client.poll(now_us);                          // connect, receive updates and snapshots
//     if (client.welcome() && !client.started())    // build the game the welcome describes
//       client.start(game);
//     client.advance_frame(local_input);            // predict one frame (or hold)
//
// The game's loop runs at the server's frame rate and applies recommended_frame_adjust(): the
// client keeps its inputs arriving a little ahead of the server's simulation (target_lead).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include <detsim/core/status.hpp>
#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/vec3.hpp>
#include <detsim/net/game.hpp>
#include <detsim/net/server_protocol.hpp>
#include <detsim/net/session.hpp>
#include <detsim/net/transport.hpp>

namespace detsim::net {

struct ClientConfig {
  /// The game's fingerprint (ServerConfig::game): the server turns another away.
  std::uint64_t game = 0;
  PeerId server = 0;  ///< the transport peer of the server
  /// The seat to take (a player index), or server_protocol::any_seat for any free one.
  std::uint8_t seat = server_protocol::any_seat;
  /// The most frames predicted beyond what the server confirmed: 1 .. 1000 (states kept).
  std::uint32_t max_prediction = 64;
  /// How many frames ahead of the server's simulation its inputs should arrive: 0 .. 30.
  std::int32_t target_lead = 2;
  std::uint64_t connect_interval_us = 200'000;  ///< connect resend interval
  std::uint64_t keepalive_us = 100'000;         ///< the longest silence towards the server
  std::uint64_t timeout_us = 5'000'000;         ///< server silence before it is lost
  /// The server's ServerConfig::view (the same function), and how this client puts a view of the
  /// server's state into its own (server_protocol.hpp). Both or neither.
  StateView view;
  MergeView merge_view;
};

enum class ClientEventType : std::uint8_t {
  welcomed,     ///< the server admitted it: Client::welcome() has the seat and the match
  rejected,     ///< the server turned it away (`reason`)
  running,      ///< it plays from state frame `frame` (the game's start, or a snapshot)
  desync,       ///< its state at `frame` hashed `local_hash`, the server's `remote_hash`,
                ///< with every input of the frames before it right: the simulation differs
  server_lost,  ///< nothing from the server for timeout_us
};

struct ClientEvent {
  ClientEventType type = ClientEventType::welcomed;
  std::uint64_t frame = 0;
  std::uint64_t local_hash = 0;
  std::uint64_t remote_hash = 0;
  std::string_view reason;  ///< string literals: never dangle
};

struct ClientStats {
  std::uint64_t frames = 0;              ///< simulated for the first time
  std::uint64_t resimulated_frames = 0;  ///< simulated again after a correction
  /// Frames simulated with a unit (some player's input, or who was present) that the server's
  /// differed from: what every correction must be explained by.
  std::uint64_t mispredictions = 0;
  /// Corrections made: re-simulations from a mispredicted frame, or server states loaded.
  std::uint64_t corrections = 0;
  std::uint64_t desyncs = 0;        ///< corrections no misprediction explains
  std::uint64_t checks_passed = 0;  ///< server hashes its own state matched
  std::uint64_t prediction_limit_waits = 0;
  std::uint64_t packets_sent = 0;
  std::uint64_t packets_received = 0;
  std::uint64_t bytes_sent = 0;  ///< payload bytes, without IP/UDP headers
  std::uint64_t bytes_received = 0;
  std::uint64_t snapshots_received = 0;  ///< whole snapshots decoded
  std::uint64_t snapshot_bytes_received = 0;
  std::uint64_t dropped = 0;  ///< datagrams malformed, not the server's, or not usable
  std::uint64_t rtt_ms = 0;   ///< the latest round trip to the server
  std::int32_t lead = 0;      ///< the server's latest word on how early its inputs arrive
};

class Client {
 public:
  /// A client that connects to `config.server` over `transport` (which must outlive it). Errors
  /// name the first invalid field.
  static Expected<Client> create(const ClientConfig& config, Transport& transport);
  Client(Client&&) noexcept;
  Client& operator=(Client&&) noexcept;
  ~Client();

  /// Receives and handles every pending datagram (welcome, updates, snapshot slices; a correction
  /// that arrived is applied here), then sends what is due (connects, inputs, keepalives).
  void poll(std::uint64_t now_us);

  /// The server's welcome, once it came: the seat, the match's sizes and the game's description.
  [[nodiscard]] const server_protocol::Welcome* welcome() const noexcept;
  /// Takes the game the welcome describes, at its initial state (frame 0), which must hash as the
  /// server's did (else an error naming both hashes). The client plays from there, or from the
  /// snapshot the server sends when the match is under way. Once only.
  Status start(Game& game);
  [[nodiscard]] bool started() const noexcept;
  /// It has a state (the start, or a snapshot) and simulates.
  [[nodiscard]] bool running() const noexcept;
  /// The match has a length, this client simulated all of it with the server's inputs, and the
  /// server's hash of its last state was compared (stats().desyncs says how it went).
  [[nodiscard]] bool ended() const noexcept;

  /// Queues `local_input` (input_size bytes) for the current frame, sends it, and predicts the
  /// frame: Advance::advanced, Advance::synchronizing (no state yet), Advance::prediction_limit
  /// (max_prediction frames beyond the server's word: nothing simulated, the input dropped), or
  /// Advance::waiting_for_inputs once the match's last frame is simulated (the server's word on
  /// the last frames may still change them). An error, nothing changed, for an input of the wrong
  /// size or before start().
  Expected<Advance> advance_frame(std::span<const std::uint8_t> local_input);

  /// Frames to run extra (positive) or to skip (negative) to keep the inputs target_lead frames
  /// ahead of the server (a policy that works: one frame, one tick in three, while it is not 0).
  [[nodiscard]] std::int32_t recommended_frame_adjust() const noexcept;
  /// Tells the server this client leaves (its seat is free from the server's next frame).
  void leave();

  /// The next frame to simulate: the game's state is at this frame.
  [[nodiscard]] std::uint64_t current_frame() const noexcept;
  /// The server's inputs of every frame before this one are held (and checked against).
  [[nodiscard]] std::uint64_t authoritative_frame() const noexcept;
  /// The hash of the server's state at the newest frame it named (and that frame).
  [[nodiscard]] std::uint64_t server_hash() const noexcept;
  [[nodiscard]] std::uint64_t server_hash_frame() const noexcept;
  /// Every server hash up to this frame has been compared with this client's own state.
  [[nodiscard]] std::uint64_t checked_frame() const noexcept;
  [[nodiscard]] const ClientStats& stats() const noexcept;
  [[nodiscard]] std::vector<ClientEvent> take_events();
  /// This client's side of its first desync (as a peer session keeps it: net::desync_report
  /// makes a desync report of it, which `detsim bisect` compares with the server's replay): the
  /// state of the last frame whose hash matched the server's, the divergent state, and the
  /// server's units of every frame before it. `player` is the number of seats (the server has
  /// none). nullptr before a desync, and for a client that cannot give every frame's units: one
  /// that joined a match under way, or of more than 8 seats (a report's frames carry one byte of
  /// absent players).
  [[nodiscard]] const DesyncEvidence* desync_evidence() const noexcept;
  /// Why the client stopped (rejected, server lost), or empty.
  [[nodiscard]] std::string_view failure() const noexcept;

 private:
  struct Impl;
  explicit Client(std::unique_ptr<Impl> impl) noexcept;
  std::unique_ptr<Impl> impl_;
};

/// A display-side smoothing of corrections (outside the synced state): when a correction moves
/// something the player sees, tell it the jump (new simulated position - old), draw the simulated
/// position plus offset(), and call frame() once per displayed frame: the offset starts at minus
/// the jump (the view stays where it was) and halves every `half_life_frames`. In Fixed, as all of
/// net/ is (a renderer converts the offset as it converts positions).
class CorrectionSmoother {
 public:
  /// `half_life_frames`: frames in which the offset halves, > 0 (default 3).
  explicit CorrectionSmoother(Fixed half_life_frames = Fixed::from_int(3)) noexcept;
  void corrected(Vec3 jump) noexcept { offset_ -= jump; }
  /// One displayed frame passed: the offset decays.
  void frame() noexcept { offset_ = offset_ * keep_; }
  [[nodiscard]] Vec3 offset() const noexcept { return offset_; }

 private:
  Fixed keep_;  ///< 2^(-1 / half_life_frames)
  Vec3 offset_{};
};

}  // namespace detsim::net
