// detsim::net::Session: a peer-to-peer match in rollback (GGPO-style) or lockstep mode, for 1 to 8
// players, one of them local, over any Transport (docs/NET.md has a complete integration example).
//
// Each tick the game calls
//
//     session.poll(now_us);                              // network in and out, timers
//     auto r = session.advance_frame(local_input);       // may load, re-simulate and advance
//     for (const net::Event& e : session.take_events()) ...
//
// Rollback mode: the local input is queued for frame current + input_delay and sent to every peer;
// a remote input not yet received is predicted (the player's last confirmed input, or a custom
// predictor); when a confirmed input differs from the prediction the game simulated, the session
// loads the state of that first incorrect frame and re-simulates to the present, inside the same
// advance_frame() call. At most max_prediction frames run ahead of the last frame every input is
// confirmed for; at that limit advance_frame() returns Advance::prediction_limit and simulates
// nothing new, but still performs any pending rollback (so the limit never loses a correction).
//
// Lockstep mode: frame F is simulated only when every player's input for F is confirmed; nothing is
// predicted and nothing is rolled back.
//
// Desync detection compares only confirmed frames: every check_interval frames each peer sends the
// hash of its state after the frame whose inputs were all confirmed, reliably (resent until
// acknowledged). A different hash raises Event::desync with both hashes, and the session keeps this
// machine's state at the last agreed frame and at the divergent one (desync_evidence()).
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
#include <detsim/net/protection.hpp>
#include <detsim/net/protocol.hpp>
#include <detsim/net/transport.hpp>

namespace detsim::net {

enum class SessionMode : std::uint8_t { rollback, lockstep };

/// What a session does when a disconnect leaves it with no strict majority of the match's players
/// (itself included) — in a two-player match, whenever the other player is gone: from its side
/// a partition of the network looks exactly like the other player leaving, and both sides would
/// play on alone, each sure it is right.
enum class PartitionPolicy : std::uint8_t {
  /// Raise Event::match_ended and stop: advance_frame() fails from then on. Every side of a
  /// partition ends, and their delivered frames (delivered_frame(): held by every peer) agree.
  end_match,
  /// Play on with the gone players' inputs zeroed (for games where a player may drop and the rest
  /// go on against bots); a partition then splits the match into two that never compare.
  play_on,
  /// Wait: a silent player whose loss would leave no majority is never disconnected. The match
  /// stands still (advance_frame() holds at the prediction limit, or waits in lockstep) with
  /// Event::paused, and goes on when the player is heard again — after an outage of any length —
  /// or rejoins from a restarted process (SessionConfig::rejoin). Ending a match that stays
  /// paused is the game's call.
  pause,
};

/// A remote player and the transport peer that plays it.
struct RemotePlayer {
  std::uint32_t player = 0;
  PeerId peer = 0;
};

/// A session's settings: plain data with defaults. create() names the first invalid field.
struct SessionConfig {
  SessionMode mode = SessionMode::rollback;
  std::uint32_t players = 2;          ///< 1 .. 8
  std::uint32_t local_player = 0;     ///< 0 .. players - 1
  std::uint32_t input_size = 4;       ///< bytes per input: 1 .. protocol::max_input_size
  std::uint32_t input_delay = 2;      ///< frames: 0 .. 16 (set_input_delay() changes it later)
  std::uint32_t max_prediction = 8;   ///< rollback mode: 1 .. 32 frames; lockstep ignores it
  std::uint32_t check_interval = 30;  ///< desync check every N confirmed frames; 0: none
  /// What every peer must agree on to play together (the game's settings, version, scenario): a
  /// hello with another fingerprint is rejected. Use a hash of the replay fingerprint.
  std::uint64_t fingerprint = 0;
  std::uint32_t frame_us = 16'667;  ///< the nominal frame duration (time sync): 1000 .. 1'000'000
  std::uint64_t hello_interval_us = 200'000;        ///< handshake resend interval
  std::uint64_t keepalive_us = 100'000;             ///< the longest silence towards a peer
  std::uint64_t ping_interval_us = 1'000'000;       ///< round-trip measurement
  std::uint64_t disconnect_warning_us = 500'000;    ///< silence before Event::interrupted
  std::uint64_t disconnect_timeout_us = 5'000'000;  ///< silence before Event::disconnected
  /// The longest a peer that keeps talking may hold the match back (docs/NET.md, "Progress"),
  /// and the longest its hash check of a frame this machine confirmed may take to arrive
  /// (Event::check_missing):
  /// over a window of this length in which this machine's game wanted to advance but ran less
  /// than a third of the time, the peers it waited on are disconnected ("no progress"). Must
  /// exceed disconnect_timeout_us (a silent peer is the disconnect timeout's to handle).
  std::uint64_t progress_timeout_us = 10'000'000;
  /// The match's secret (docs/NET.md, "Packet protection"): every datagram is then sealed with
  /// ChaCha20-Poly1305 under per-direction keys derived from it, and replays are dropped; a peer
  /// with another key (or none) never synchronises. Absent: the plain framing, which anyone on
  /// the path can read, forge and rewrite — for LAN tests and the simulated network only. A
  /// build without libsodium refuses a key (create() fails) rather than play unprotected.
  std::optional<MatchKey> match_key;
  /// When a disconnect leaves this machine with no strict majority of the players.
  PartitionPolicy partition = PartitionPolicy::end_match;
  /// This session takes the place of an earlier one of the same player in a match that is under
  /// way (the process was restarted; docs/NET.md, "Rejoining"). It does not start from the game's
  /// state: after the handshake the peer sends a snapshot (the state of the last frame every
  /// peer holds as final, the confirmed frames before it and every input since, compressed),
  /// which the session loads, re-simulating to the peer's present; advance_frame() reports
  /// Advance::synchronizing until then, and Event::rejoined says it is done. The peer must still
  /// hold the seat (within disconnect_timeout_us of the old session's last word, or paused).
  /// The same session joins an open seat (open_seats on the other side, or a player the other
  /// side took as gone under PartitionPolicy::play_on): its inputs count from the peer's present
  /// on, and were zero (InputStatus::disconnected) before. In a match of three or more players
  /// every return goes that way: the peers take the old session as gone, agree on the frame
  /// (as for any disconnect), and the lowest-numbered peer that answers serves the snapshot and
  /// names the frame R the player is back from, which it and the snapshot carry to every other
  /// peer (docs/NET.md, "Rejoining").
  bool rejoin = false;
  /// With `rejoin`: before it plays, the session re-simulates the whole match from the game's
  /// state at creation (frame 0) through the snapshot's confirmed frames, delivering each to the
  /// confirmed listener — so a recorder writes the whole match, as the other players' do — and
  /// the snapshot's state must be the one those frames give, else the rejoin fails. It costs the
  /// simulation of every frame so far, inside the poll() that completes the snapshot.
  bool rejoin_replays_match = false;
  /// Players whose seat is open at the start: the match runs without them, their inputs zero
  /// (InputStatus::disconnected), until a session of theirs joins with `rejoin` — a late joiner,
  /// or a spectator turned player. Every peer of the match lists the same open seats.
  std::vector<std::uint32_t> open_seats;
  std::vector<RemotePlayer> remotes;  ///< every other player, each exactly once
  /// Spectators this machine serves (at most 16; ids distinct from the remotes'): each receives
  /// every confirmed frame's inputs from here (SpectatorSession). Events about spectator k use
  /// player = players + k.
  std::vector<PeerId> spectators;
};

/// What advance_frame() did.
enum class Advance : std::uint8_t {
  advanced,            ///< simulated one new frame (after any rollback)
  synchronizing,       ///< the handshake with some peer is not done; nothing simulated
  prediction_limit,    ///< rollback: max_prediction frames ahead of the confirmed inputs
  waiting_for_inputs,  ///< lockstep: some input of the next frame has not arrived
};

enum class EventType : std::uint8_t {
  synchronized,  ///< the handshake with `player` completed
  running,       ///< every peer is synchronized: frames can advance
  interrupted,   ///< `player` has been silent for disconnect_warning_us
  resumed,       ///< `player` was heard from again after an interruption
  disconnected,  ///< `player` is gone (`reason`: "silent", "no progress", "reported gone", or
                 ///< "rejoining": a new session of it came, in a match of three or more):
                 ///< its inputs are zero from `frame` on (InputStatus::disconnected)
  desync,        ///< `player` hashed confirmed frame `frame` differently
  /// a hello from `player`'s peer did not match this session (`reason`: what differed, or "not
  /// authenticated" / "sealed" / "not sealed" when the peers' match keys differ or one has none)
  hello_rejected,
  /// `player`'s hash check of confirmed frame `frame` did not arrive within progress_timeout_us
  /// of this machine confirming it (or can no longer be compared): that frame, and every later
  /// one, is unverified with that peer. Raised once per peer. A relay that strips checks, or a
  /// peer that does not send them, ends here instead of passing unchecked.
  check_missing,
  /// The match ended on this machine (`reason`: "no majority"): a disconnect left it with no
  /// strict majority of the match's players, so it cannot tell a partition from players leaving
  /// (SessionConfig::partition). `frame`: delivered_frame() then — the frames every side agrees
  /// on. advance_frame() fails from then on; poll() still answers the peers.
  match_ended,
  /// The match waits (PartitionPolicy::pause): `player` is silent, and this machine without it
  /// would have no majority (`reason`: "no majority"). Event::resumed or Event::rejoined for that
  /// player says it goes on. `frame`: delivered_frame() then.
  paused,
  /// A restarted process took `player`'s seat again, or a late joiner an open seat
  /// (SessionConfig::rejoin), from a snapshot of state frame `frame`: on the joining machine
  /// `player` is its own, on the others the one that came. In a match of three or more, the
  /// peers that did not serve the snapshot raise it when they take the player back, with
  /// `frame` the first frame it plays in again.
  rejoined,
};

struct Event {
  EventType type = EventType::running;
  std::uint32_t player = 0;
  std::uint64_t frame = 0;
  std::uint64_t local_hash = 0;   ///< desync: this machine's hash of `frame`
  std::uint64_t remote_hash = 0;  ///< desync: the peer's
  /// hello_rejected: what differed; disconnected: why (string literals: never dangle)
  std::string_view reason;
};

/// A frame whose inputs are all final, in frame order, each once: what a replay records.
struct ConfirmedFrame {
  std::uint64_t frame = 0;  ///< the step (0 is the first); the state after it is frame + 1
  std::span<const std::uint8_t> inputs;  ///< players * input_size
  std::span<const InputStatus> status;
  std::uint64_t hash = 0;  ///< of the state after the step (0 only if a bug lost that state)
};

/// This machine's side of the first desync: what a desync report needs.
struct DesyncEvidence {
  std::uint32_t player = 0;        ///< the peer that disagreed
  std::uint64_t agreed_frame = 0;  ///< the last state frame every peer agreed on (0: the start)
  std::vector<std::uint8_t> agreed_state;  ///< this machine's state at agreed_frame
  std::uint64_t divergent_frame = 0;
  std::vector<std::uint8_t> divergent_state;
  std::uint64_t local_hash = 0;
  std::uint64_t remote_hash = 0;
  /// Every confirmed frame before divergent_frame, in order, each 1 + players * input_size
  /// bytes: a byte whose bit p says player p was disconnected, then every player's input.
  std::vector<std::uint8_t> confirmed_frames;
};

struct PeerStats {
  std::uint32_t player = 0;
  bool synchronized = false;
  bool disconnected = false;
  std::uint64_t ping_us = 0;       ///< smoothed round-trip time
  std::uint64_t jitter_us = 0;     ///< smoothed deviation of the round-trip time
  std::int64_t frames_ahead = 0;   ///< how many frames this machine is ahead of the peer (estimate)
  std::uint64_t remote_frame = 0;  ///< the peer's frame as last reported
  /// The peer holds every local input before this frame (spectators: every confirmed frame).
  std::uint64_t acknowledged_frame = 0;
  /// Every hash check of the peer up to this frame has arrived (players only; 0: none yet).
  std::uint64_t checks_received_through = 0;
  std::uint64_t packets_sent = 0;
  std::uint64_t packets_received = 0;
  std::uint64_t packets_lost = 0;  ///< gaps in the peer's sequence numbers
  std::uint64_t bytes_sent = 0;    ///< payload bytes (without IP/UDP headers)
  std::uint64_t bytes_received = 0;
};

struct SessionStats {
  std::uint64_t frames = 0;  ///< frames simulated for the first time
  std::uint64_t rollbacks = 0;
  std::uint64_t resimulated_frames = 0;
  std::uint64_t prediction_limit_waits = 0;  ///< advance_frame() calls that hit the limit
  std::uint64_t dropped_inputs = 0;          ///< local inputs dropped when the input delay shrank
  /// Peers' confirmed-frame hashes compared with this machine's (desync detection at work), and
  /// those that could not be (this machine's hash was no longer kept).
  std::uint64_t checks_compared = 0;
  std::uint64_t checks_skipped = 0;
  /// Received datagrams dropped by the decoder, by protocol::DecodeError.
  std::array<std::uint64_t, protocol::decode_error_count> dropped_malformed{};
  std::uint64_t dropped_wrong_session = 0;  ///< a nonce or peer this session does not know
  std::uint64_t dropped_out_of_window = 0;  ///< frames outside what the session can hold
  /// Input datagrams dropped whole for a field no honest peer sends: a held frame beyond the
  /// inputs it acknowledges, a current frame outside what its inputs and ours allow.
  std::uint64_t dropped_implausible = 0;
  /// Pongs that answer no ping this session has outstanding (replayed or forged).
  std::uint64_t dropped_stale_pongs = 0;
  /// Gone reports ignored: about this machine's own player, or about a player it still hears.
  std::uint64_t ignored_gone_reports = 0;
  /// Peers whose hash check of some confirmed frame never arrived (Event::check_missing).
  std::uint64_t checks_missing = 0;
  /// With a match key: datagrams whose tag did not verify (forged, altered on the way, another
  /// key) or that came in the plain framing; and datagrams dropped by the replay window (a
  /// duplicate, or older than the 64 before the newest), before decryption.
  std::uint64_t dropped_unauthenticated = 0;
  std::uint64_t dropped_replayed = 0;
  /// Rejoining peers this machine sent a snapshot to, and the snapshot bytes sent (resends too).
  std::uint64_t snapshots_served = 0;
  std::uint64_t snapshot_bytes_sent = 0;
  /// Back reports (a player taken back at a frame) that could not be taken: about a player this
  /// machine does not take as gone from the report's frame, or naming a frame it has delivered
  /// already or cannot hold.
  std::uint64_t ignored_back_reports = 0;
};

/// Predicts a remote player's input for a frame not received yet: writes the prediction to `out`
/// given the player's last confirmed input (all zero before the first). Must be a pure function of
/// its arguments, so that every re-simulation predicts alike.
using Predictor = std::function<void(std::uint32_t player, std::span<const std::uint8_t> last,
                                     std::span<std::uint8_t> out)>;

class Session {
 public:
  /// A session driving `game` over `transport`; both must outlive it. Saves the game's state as
  /// frame 0. Errors name the first invalid field of `config`.
  static Expected<Session> create(const SessionConfig& config, Game& game, Transport& transport);
  Session(Session&&) noexcept;
  Session& operator=(Session&&) noexcept;
  ~Session();

  /// Receives and handles every pending datagram, then sends what is due (handshake, inputs,
  /// acknowledgements, hash checks, pings, keepalives) and raises timeouts. A correction that
  /// arrived is applied here (the game loads and re-simulates), and newly confirmed frames are
  /// handed to the confirmed listener. `now_us` is a
  /// monotonic clock in microseconds; it must not go backwards (an earlier value counts as the
  /// last one).
  void poll(std::uint64_t now_us);

  /// Queues `local_input` (input_size bytes) for frame current_frame() + input_delay, performs a
  /// pending rollback, and simulates the next frame if the mode allows. An input for a frame that
  /// already has one (while waiting, or after the delay shrank) is dropped. An error (nothing
  /// changes) when the input has the wrong size.
  Expected<Advance> advance_frame(std::span<const std::uint8_t> local_input);

  /// Changes the input delay from the next local input on (0 .. 16). Growing it repeats that
  /// input to fill the gap; shrinking it drops local inputs until the gap closes.
  Status set_input_delay(std::uint32_t frames);
  /// A custom prediction of remote inputs (default: repeat the last confirmed input).
  void set_predictor(Predictor predictor);
  /// Called for every confirmed frame, in order (what replays record).
  void set_confirmed_listener(std::function<void(const ConfirmedFrame&)> listener);

  /// Moves the events raised since the last call out, oldest first.
  [[nodiscard]] std::vector<Event> take_events();

  [[nodiscard]] const SessionConfig& config() const noexcept;
  [[nodiscard]] bool running() const noexcept;
  /// The next frame to simulate: the game's state is at this frame.
  [[nodiscard]] std::uint64_t current_frame() const noexcept;
  /// Every frame before this one has all inputs confirmed (disconnected players count as
  /// confirmed).
  [[nodiscard]] std::uint64_t confirmed_frame() const noexcept;
  /// Every frame before this one has been handed to the confirmed listener: confirmed here, final
  /// (no correction pending) and held by every connected peer, so no disconnect can be agreed
  /// before it. It trails confirmed_frame() by the round trip in which the peers say they hold it.
  /// At the end of a match of N frames, keep calling poll() (without advancing) until it reaches
  /// N — the peers' last acknowledgements arrive — then linger a few polls so that they get yours;
  /// a peer that left or stays silent is disconnected by the timeouts, which also ends the wait.
  [[nodiscard]] std::uint64_t delivered_frame() const noexcept;
  /// Frames the game should skip (not advance) to let slower peers catch up: 0 when in time.
  /// A policy that works: while it is above 0, skip advance_frame() on one tick in three (a
  /// skipped tick still polls), so the correction is spread out and never visible as a stall.
  [[nodiscard]] std::uint32_t recommended_wait_frames() const noexcept;
  [[nodiscard]] const SessionStats& stats() const noexcept;
  /// The statistics of the peer playing `player` (spectator k: players + k); nothing for the
  /// local player or an unknown one.
  [[nodiscard]] std::optional<PeerStats> peer_stats(std::uint32_t player) const;
  /// This machine's side of the first desync, once one was detected.
  [[nodiscard]] const DesyncEvidence* desync_evidence() const noexcept;
  /// Why the session stopped — the error advance_frame() returns from then on (a rejoin that
  /// failed, a match that ended without a majority, a broken invariant) — or empty while it goes
  /// on.
  [[nodiscard]] std::string_view failure() const noexcept;

 private:
  struct Impl;
  explicit Session(std::unique_ptr<Impl> impl) noexcept;
  std::unique_ptr<Impl> impl_;
};

}  // namespace detsim::net
