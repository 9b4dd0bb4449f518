// Session internals shared by session.cpp (the frame loop: inputs, rollback, confirmed frames,
// desync checks) and session_wire.cpp (the network: handshake, packets in and out, timers).
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <optional>
#include <vector>

#include <detsim/net/session.hpp>

#include "channel.hpp"
#include "input_queue.hpp"

namespace detsim::net::detail {
struct Snapshot;
}  // namespace detsim::net::detail

namespace detsim::net::detail {

/// Frames of inputs each player's queue holds: enough for the prediction window, the input delay,
/// the confirmed frames not yet emitted and the oldest input a peer's delta may refer to. A remote
/// input further ahead than this is out of the window and dropped.
inline constexpr std::size_t input_capacity = 256;
/// Hash checks this side keeps for comparison, and accepts ahead from one peer.
inline constexpr std::size_t max_pending_checks = 64;
/// The largest input delay and prediction window a session may be configured with.
inline constexpr std::uint32_t max_input_delay = 16;
inline constexpr std::uint32_t max_prediction_limit = 32;
/// "No frame": a connected player's disconnect frame.
inline constexpr std::uint64_t never = ~std::uint64_t{0};
/// States the ring keeps beyond twice the prediction window: room for the frames between the last
/// emitted confirmed frame and the present (emission waits for every peer's holdings, a one-way
/// trip later). The session waits rather than let that span outgrow the ring.
inline constexpr std::size_t emission_slack = 24;

/// One confirmed-frame hash this machine computed, kept until every peer's hash was compared.
struct LocalCheck {
  std::uint64_t frame = 0;
  std::uint64_t hash = 0;
  std::vector<std::uint8_t> state;  ///< this machine's state at `frame` (desync evidence)
  std::uint64_t confirmed_us = 0;   ///< when this machine confirmed it (the peers' deadline)
};

/// A remote player's connection.
struct Peer {
  std::uint32_t player = 0;  ///< a spectator's is players + its index
  bool spectator = false;
  PeerId id = 0;
  // Handshake (docs/NET.md, "Handshake"): synchronized once the peer answered our challenge; its
  // session id comes from that answer only and never changes after.
  std::uint64_t challenge = 0;  ///< 64 random bits, sent only to the peer's address
  bool answered = false;        ///< the peer replied to our challenge
  std::uint64_t remote_session = 0;
  bool synchronized = false;
  /// A datagram beyond the handshake arrived from the peer's session: it knows our id, so its
  /// hellos need no more answers (nor does a flood of forged ones get any).
  bool knows_us = false;
  std::uint64_t last_hello_us = 0;
  bool hello_sent = false;
  bool hello_rejected = false;  ///< reported once
  Channel channel;              ///< packet protection (a match key only)
  // What the peer holds: every player's input before reported_held (from its latest packet), and
  // the frame from which it takes each player as gone (never: connected; only ever lowered).
  std::uint64_t reported_held = 0;
  std::vector<std::uint64_t> reported_gone;
  // Inputs and checks the peer holds of ours.
  std::uint64_t acked_inputs = 0;  ///< the peer holds our inputs before this frame
  std::uint64_t acked_checks = 0;  ///< the peer holds our checks up to this frame
  // Checks received from the peer.
  std::uint64_t checks_through = 0;  ///< every check of the peer up to this frame received
  std::deque<protocol::HashCheck> pending_checks;  ///< received, not yet compared
  bool desynced = false;
  bool check_missing = false;  ///< Event::check_missing raised (once per peer)
  // Liveness and statistics.
  std::uint64_t last_receive_us = 0;
  std::uint64_t last_send_us = 0;
  std::uint64_t last_ping_us = 0;
  /// The time our latest ping carried, until its pong arrives: the only pong accepted (a replayed
  /// or forged pong would otherwise make up a round-trip time).
  std::optional<std::uint64_t> ping_out;
  bool interrupted = false;
  bool disconnected = false;
  // Rejoin (docs/NET.md, "Rejoining"), on the side that stayed. A hello naming another session of
  // the peer's player is answered, and met with a challenge of our own (one per hello interval);
  // only a reply to it, which comes from the peer's address, rebinds the peer to a new session,
  // which is then served `snapshot` until its first input datagram.
  std::optional<std::uint64_t> rechallenge;
  std::optional<std::uint64_t> last_rechallenge_us;
  std::vector<std::uint8_t> snapshot;
  bool rejoining = false;
  /// Three or more players: a back report took the player back before a new session of it was
  /// bound here. Until one is (rebind), the old session's datagrams are dropped.
  bool returning = false;
  /// On a rejoining machine, three or more players: this peer has not yet taken us back (no back
  /// report of ours from it yet), so what it says it holds of ours is about the old session.
  bool awaiting_back = false;
  bool needs_ack = false;  ///< received data since the last packet we sent
  std::uint16_t send_sequence = 0;
  std::optional<std::uint16_t> last_sequence;
  std::uint64_t rtt_x16 = 0;     ///< smoothed round-trip time, times 16
  std::uint64_t jitter_x16 = 0;  ///< smoothed |rtt - smoothed rtt|, times 16
  std::uint64_t remote_frame = 0;
  std::int64_t advantage_x16 = 0;  ///< smoothed frames we are ahead of the peer, times 16
  std::int64_t remote_advantage_x16 = 0;
  PeerStats stats;
};

struct State {
  std::uint64_t frame = ~std::uint64_t{0};
  std::uint64_t hash = 0;
  std::vector<std::uint8_t> bytes;
};

}  // namespace detsim::net::detail

namespace detsim::net {

struct Session::Impl {
  Impl(const SessionConfig& c, Game& g, Transport& t);

  // session.cpp: the frame loop.
  void add_local_input(std::span<const std::uint8_t> input);
  void simulate(std::uint64_t frame, bool resimulating);
  /// Loads the first incorrect frame's state and re-simulates to the present; an error (and
  /// `broken` set) when that state is no longer held.
  Status rollback();
  void emit_confirmed();
  /// Ends the match (Event::match_ended, `broken`) when the players still in it are no strict
  /// majority and the config says to (SessionConfig::partition).
  void end_without_majority();
  void add_local_check(std::uint64_t frame, std::uint64_t hash, const detail::State* state);
  void compare_checks(detail::Peer& peer);
  void retire_checks();
  /// Raises Event::check_missing for `peer` about `frame` (once per peer).
  void check_missing(detail::Peer& peer, std::uint64_t frame);
  /// Every peer's check of each frame this machine confirmed must arrive within
  /// progress_timeout_us: a missing one is an error, never a pass.
  void check_deadlines();
  void receive_input(detail::Peer& peer, std::uint64_t frame, std::span<const std::uint8_t> input);
  /// Takes the peer's player as gone from its first input this machine does not hold; `reason`
  /// (a string literal) goes into the event.
  void disconnect(detail::Peer& peer, std::string_view reason);
  /// Takes `player` as gone from `frame` (or from the frame of its first input this machine does
  /// not hold, if earlier); a later call can only move the frame earlier. Peers converge on the
  /// lowest frame any of them reports (docs/NET.md, "Disconnects").
  void player_gone(std::uint32_t player, std::uint64_t frame, std::string_view reason);
  /// Whether this machine heard from `player`'s peer within disconnect_timeout_us (a gone report
  /// about such a player is not believed).
  [[nodiscard]] bool hears(std::uint32_t player) const noexcept;
  /// Whether the match waits on `peer` now: its inputs are the oldest missing, its held frame is
  /// what keeps frames from being final, or it has not agreed to a disconnect frame.
  [[nodiscard]] bool holds_back(const detail::Peer& peer) const noexcept;
  /// The progress guard (docs/NET.md, "Progress"): at the end of each window of
  /// progress_timeout_us, disconnects the peers that held the match back through it.
  void check_progress();
  /// Every player's input before this frame is held, or known final (zero) for a gone player whose
  /// disconnect frame every connected peer reports: what this machine may simulate as confirmed.
  [[nodiscard]] std::uint64_t confirmed_frame() const noexcept;
  /// The frames before this one are final everywhere: confirmed here and held by every connected
  /// peer (so no peer can still take a player as gone from an earlier frame).
  [[nodiscard]] std::uint64_t emit_limit() const noexcept;
  [[nodiscard]] bool gone_final(std::uint32_t player) const noexcept;
  [[nodiscard]] std::uint64_t window_start() const noexcept;
  [[nodiscard]] detail::State& state_slot(std::uint64_t frame) noexcept {
    return states[static_cast<std::size_t>(frame % states.size())];
  }
  void raise(Event e) { events.push_back(e); }
  /// Whether `player` takes no part in `frame`: gone from its disconnect frame on, or away in the
  /// interval before it joined an open seat.
  [[nodiscard]] bool gone_at(std::uint32_t player, std::uint64_t frame) const noexcept {
    return frame >= disconnect_frame[player] ||
           (frame >= absent_from[player] && frame < absent_until[player]);
  }
  /// Whether a new session of `peer`'s player may take its seat: a match still going.
  [[nodiscard]] bool seat_takeable(const detail::Peer& peer) const noexcept {
    return !peer.spectator && broken.empty();
  }
  /// A match of three or more players: a return goes through a disconnect, then a back report.
  [[nodiscard]] bool shared() const noexcept { return config.players > 2; }
  /// Whether `peer` has a say in what is final (disconnect frames, emission, hash checks): in
  /// step with us, and not a new session that has not been given the match yet.
  [[nodiscard]] bool seated(const detail::Peer& peer) const noexcept {
    return peer.synchronized && !peer.disconnected && !peer.returning &&
           !(peer.rejoining && peer.snapshot.empty());
  }
  /// Whether the players other than `player` that are still in the match are a strict majority.
  [[nodiscard]] bool majority_without(std::uint32_t player) const noexcept;
  /// The match goes on after a pause (PartitionPolicy::pause) or an outage: the progress guard
  /// and the hash-check deadlines count from now, not from before the silence.
  void restart_clocks();

  // session_wire.cpp: the network.
  void receive_all();
  /// Opens a sealed datagram from `peer` into `packet` (match key only); false when dropped.
  bool open(detail::Peer& peer, std::span<const std::uint8_t> bytes);
  /// Raises hello_rejected for `peer` once, with `reason`.
  void reject(detail::Peer& peer, std::string_view reason);
  void handle(detail::Peer& peer, const protocol::Packet& packet);
  /// Answers a hello that matches this session with a reply echoing its challenge. Changes no
  /// handshake state: a hello, forged or not, can neither set nor reset the peer's session id.
  void handle_hello(detail::Peer& peer, const protocol::Packet& packet);
  /// `fresh`: the datagram is newer than every one handled before from this peer. False (nothing
  /// changed) when a field is implausible.
  bool handle_input(detail::Peer& peer, const protocol::InputBody& body, bool fresh);
  /// Whether an input datagram's fields are what an honest peer can send (checked before any is
  /// used): its held frame within the inputs it acknowledges, its current frame within what its
  /// inputs and ours allow.
  [[nodiscard]] bool plausible(const detail::Peer& peer, const protocol::InputBody& body) const;
  void send_due();
  void send_inputs(detail::Peer& peer);
  void send_frames(detail::Peer& spectator);
  void send_hello(detail::Peer& peer, std::uint64_t challenge);
  void send(detail::Peer& peer, protocol::Packet& packet);
  void check_timeouts();
  [[nodiscard]] detail::Peer* peer_by_id(PeerId id) noexcept;
  // session_rejoin.cpp: a restarted player's way back (docs/NET.md, "Rejoining").
  /// A hello that names a new session of a synchronized peer's player: answered, and met with
  /// a challenge of our own (at most one per hello interval).
  void handle_rejoin_hello(detail::Peer& peer, const protocol::Packet& packet);
  /// The peer answered our rechallenge from `session`: a new session takes its seat.
  void rebind(detail::Peer& peer, std::uint64_t session);
  void serve_state(detail::Peer& peer, std::uint32_t offset);
  /// The snapshot for `peer`, taken at its first request: the state of delivered_frame() and
  /// what comes with it. A player whose seat was open (gone, or never there) joins at the
  /// present: its absence ends there.
  void take_snapshot(detail::Peer& peer);
  void receive_state(detail::Peer& peer, const protocol::StateChunk& chunk);
  /// Whether `peer`'s snapshot may be taken now: in a match of three or more, once every peer
  /// agrees on the frame its old session is gone from (a return starts from there).
  [[nodiscard]] bool snapshot_ready(const detail::Peer& peer) const noexcept;
  /// Takes `player` back into the match: away over [from, until), its inputs from `until` on to
  /// come from its new session. What its old session sent from `from` on is forgotten.
  void readmit(std::uint32_t player, std::uint64_t from, std::uint64_t until);
  /// A back report from `peer` (which plays with us): about this machine's own player, it says
  /// the peer took us back; about another, the player is readmitted here at the same frame.
  void take_back(detail::Peer& peer, const protocol::BackReport& report);
  /// The peer a rejoining session asks for the snapshot: the lowest-numbered player that
  /// answered (chosen once); nullptr until one did.
  [[nodiscard]] detail::Peer* snapshot_server() noexcept;
  /// Loads the whole snapshot received from `from`; an error (and `broken`) when it is invalid.
  Status load_snapshot(detail::Peer& from);
  /// SessionConfig::rejoin_replays_match: re-simulates `snapshot`'s frames from the game's state
  /// at creation, delivering each; an error when they do not give the snapshot's state.
  Status replay_match(const detail::Snapshot& snapshot, std::uint32_t server);
  void request_state();

  SessionConfig config;
  Game* game;
  Transport* transport;
  std::uint32_t max_prediction = 0;  ///< 0 in lockstep
  std::uint64_t session_id = 0;      ///< this session's id: 64 random bits from a CSPRNG
  std::optional<detail::Protection> protection;  ///< with a match key
  std::uint64_t now_us = 0;
  bool running = false;

  std::vector<detail::InputQueue> queues;       ///< one per player
  std::vector<std::uint64_t> disconnect_frame;  ///< per player; ~0: connected
  /// Per player, the frames [absent_from, absent_until) it was away before it (re)joined an open
  /// seat: its inputs there are zero with InputStatus::disconnected (empty: never away).
  std::vector<std::uint64_t> absent_from;
  std::vector<std::uint64_t> absent_until;
  std::vector<detail::Peer> peers;       ///< by ascending player
  std::vector<detail::Peer> spectators;  ///< in configuration order
  /// Every confirmed frame as a spectator receives it and desync evidence carries it (unit_size
  /// bytes each: a mask of disconnected players, then every input). Grows with the match by
  /// 1 + players * input_size bytes per frame (7 bytes at 2 players of 3 bytes: 1.5 MB an hour).
  std::vector<std::uint8_t> frame_log;
  std::size_t unit_size = 0;
  std::vector<detail::State> states;  ///< ring of saved states
  /// Set when the session cannot go on (a broken invariant): advance_frame returns it from then on.
  std::string broken;
  /// The match ended without a majority (end_without_majority): nothing more is delivered.
  bool ended = false;
  std::uint64_t current = 0;
  std::optional<std::uint64_t> first_incorrect;
  std::uint64_t next_emit = 0;  ///< the next frame to hand to the confirmed listener
  // The progress guard's window: since when, and how many advance_frame() calls simulated a new
  // frame or were held at the prediction limit (or waited, in lockstep) during it.
  std::uint64_t window_start_us = 0;
  std::uint64_t window_advanced = 0;
  std::uint64_t window_held = 0;
  bool last_advance_held = false;

  // Scratch for simulate(), sized once.
  std::vector<std::uint8_t> frame_inputs;
  std::vector<InputStatus> frame_status;
  std::vector<std::uint8_t> scratch_input;

  std::deque<detail::LocalCheck> local_checks;
  std::optional<DesyncEvidence> evidence;
  // Rejoin, on the rejoining side: the snapshot as it arrives, until it is whole and loaded.
  bool awaiting_state = false;
  std::vector<std::uint8_t> incoming;
  std::uint32_t incoming_total = 0;
  std::optional<std::uint64_t> last_request_us;
  std::optional<std::size_t>
      server_index;  ///< index in `peers` of the snapshot's server, once asked
  /// The highest held frame this machine ever told a peer: a player taken back returns no
  /// earlier, so no peer can have delivered a frame with it gone that it plays in.
  std::uint64_t max_held_sent = 0;
  /// PartitionPolicy::pause: Event::paused was raised and no silent player came back yet.
  bool paused = false;
  std::uint64_t agreed_frame = 0;
  std::vector<std::uint8_t> agreed_state;

  Predictor predictor;
  std::function<void(const ConfirmedFrame&)> confirmed_listener;
  std::vector<Event> events;
  SessionStats stats;

  // Scratch for the wire.
  std::vector<Datagram> inbox;
  std::vector<std::uint8_t> outbuf;
  std::vector<std::uint8_t> scratch_deltas;
  std::vector<std::uint8_t> scratch_inputs;
  std::vector<std::uint8_t> scratch_body;
  protocol::Packet packet;
};

}  // namespace detsim::net
