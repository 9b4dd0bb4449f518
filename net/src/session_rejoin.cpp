// A restarted player's way back into a match (docs/NET.md, "Rejoining").
//
// The side that stayed keeps the seat (within the disconnect timeout, or indefinitely under
// PartitionPolicy::pause). The restarted process's session (SessionConfig::rejoin) says hello with
// a new session id. The hello is answered like any other, and met with a challenge of our own:
// only the reply to it — sent to the peer's address, which a third party off the path never sees,
// and under a match key sealed with a key only a player has — moves the seat to the new session.
// The stayer then snapshots the match (snapshot.hpp): the state of delivered_frame(), which every
// peer holds as final, the confirmed frames before it, and every input it holds since. The
// rejoining side asks for it in slices (state_request, resent until the snapshot is whole: its
// own acknowledgement), loads it, fills its own inputs from where the stayer's copy of them ends
// to the stayer's present with zeros (the restart lost them), re-simulates to the present and
// plays on. The stayer re-simulates those frames when the zeros arrive, as after any
// misprediction: both sides end on the same frames, the hash checks compare them again.
//
// With three or more players, several machines hold the seat, each with its own share of the old
// session's inputs, so a return cannot simply pick up where one of them stands. It goes through
// the absence path instead, which is also how a late joiner takes an open seat:
//   1. Each peer that binds the new session takes the old one as gone from its own holdings (a
//      peer that does not hear from it times it out); the gone reports converge on one frame D,
//      the lowest any peer holds, as for any disconnect.
//   2. The peer the joiner asks (the lowest-numbered one that answered) waits until every peer
//      reports D, then picks R: no earlier than its present, D + 1, and every held frame it ever
//      reported, so no peer can have delivered a frame from R on (a peer's delivery waits for
//      every peer's held frame). It readmits the player — away over [D, R), playing from R — and
//      snapshots the match.
//   3. Every input datagram carries a back report (player, D, R) for every player that came
//      back. A peer that takes the player as gone from D readmits it at R too, re-simulating
//      from R if it is past it; the joiner's own datagrams carry it as well. Until a peer has,
//      it says it still takes the player as gone from D, and its held frame counts for nothing
//      from R on; the joiner ignores what it acknowledges until its back report arrives.
#include <algorithm>
#include <string>

#include <detsim/core/assert.hpp>

#include "secure_random.hpp"
#include "session_impl.hpp"
#include "snapshot.hpp"

namespace detsim::net {
namespace {

/// Slices sent per request: 16 KB, a round trip's worth on any link a match is played over.
constexpr std::size_t chunks_per_request = 16;

}  // namespace

void Session::Impl::handle_rejoin_hello(detail::Peer& peer, const protocol::Packet& p) {
  if (peer.spectator) return;
  // Answered (the sender may be a new session of the peer that waits for our id; a reply goes
  // to the peer's address only), so the genuine peer is never starved of it by forged hellos.
  protocol::Packet reply;
  reply.header.type = protocol::PacketType::hello_reply;
  reply.hello_reply.challenge = p.hello.challenge;
  send(peer, reply);
  // A hello from the session we know asks nothing more; nor does any hello once the match cannot
  // take a player back (over, broken, or the seat given up).
  if (p.header.session == peer.remote_session || !seat_takeable(peer) || awaiting_state) return;
  // One challenge outstanding, the same until answered (a flood of forged hellos cannot replace
  // the one the genuine peer is answering), resent at most once per hello interval.
  if (!peer.rechallenge) peer.rechallenge = detail::secure_random_u64();
  if (peer.last_rechallenge_us && now_us - *peer.last_rechallenge_us < config.hello_interval_us)
    return;
  peer.last_rechallenge_us = now_us;
  send_hello(peer, *peer.rechallenge);
}

void Session::Impl::rebind(detail::Peer& peer, std::uint64_t session) {
  if (peer.returning) {
    // A back report took the player back already (readmit): the new session plays at once.
    peer.returning = false;
    peer.rejoining = false;
  } else {
    peer.rejoining = true;  // served a snapshot when it asks (take_snapshot), then plays
    // Three or more players: the old session is gone from what this machine holds of it, and
    // the player returns through the absence path (the file comment).
    if (shared() && disconnect_frame[peer.player] == detail::never) disconnect(peer, "rejoining");
  }
  peer.remote_session = session;
  peer.answered = true;  // our rechallenge, answered, binds it as the first challenge would
  if (protection) {      // new keys both ways, and a fresh window for the new session's sequence
    protection->bind(peer.channel, session);
    peer.channel.window = {};
  }
  peer.snapshot = {};
  peer.knows_us = false;  // until the new session sends beyond the handshake
  peer.last_sequence.reset();
  peer.ping_out.reset();
  peer.needs_ack = false;
  peer.acked_inputs = 0;  // its first input datagram says what it holds of ours
  peer.reported_held = std::min(peer.reported_held, next_emit);
}

bool Session::Impl::snapshot_ready(const detail::Peer& peer) const noexcept {
  if (!shared()) return true;
  return disconnect_frame[peer.player] != detail::never && gone_final(peer.player);
}

void Session::Impl::readmit(std::uint32_t player, std::uint64_t from, std::uint64_t until) {
  absent_from[player] = from;
  absent_until[player] = until;
  disconnect_frame[player] = detail::never;
  detail::InputQueue& q = queues[player];
  q.truncate(from);
  std::fill(scratch_input.begin(), scratch_input.end(), std::uint8_t{0});
  while (q.next_confirmed() < until)
    q.confirm(scratch_input);
  const std::uint64_t interval = config.check_interval;
  for (detail::Peer& peer : peers) {
    peer.reported_gone[player] = detail::never;  // reports about the absence are old news
    if (peer.player != player) continue;
    std::fill(peer.reported_gone.begin(), peer.reported_gone.end(), detail::never);
    peer.disconnected = false;
    peer.stats.disconnected = false;
    peer.interrupted = false;
    peer.last_receive_us = now_us;  // its timeout counts from its return
    // Hash checks start over from the return (the snapshot's server moves them to its frame).
    peer.checks_through = interval == 0 ? 0 : until / interval * interval;
    peer.acked_checks = peer.checks_through;
    peer.pending_checks.clear();
    peer.desynced = false;
    peer.check_missing = false;
  }
  // Frames from `until` on were simulated with the player gone: it plays in them now.
  if (until < current) first_incorrect = std::min(first_incorrect.value_or(until), until);
}

void Session::Impl::take_back(detail::Peer& peer, const protocol::BackReport& r) {
  const std::uint32_t player = r.player;
  if (player >= config.players) {
    ++stats.ignored_back_reports;
    return;
  }
  if (player == config.local_player) {  // the peer took this machine back: it speaks of us now
    if (peer.awaiting_back && r.from == absent_from[player] && r.until == absent_until[player])
      peer.awaiting_back = false;
    return;
  }
  // Nothing to do about a player that is with us, nor about an absence that is over.
  if (disconnect_frame[player] == detail::never || r.until <= absent_until[player]) return;
  // The return must start where every peer took the player as gone, and at a frame this machine
  // has not delivered yet and can hold: else it cannot be taken as the others take it.
  if (disconnect_frame[player] != r.from || r.until <= r.from || r.until < next_emit ||
      r.until > window_start() + detail::input_capacity) {
    ++stats.ignored_back_reports;
    return;
  }
  readmit(player, r.from, r.until);
  for (detail::Peer& returning : peers) {
    if (returning.player != player) continue;
    if (returning.rejoining) {
      returning.rejoining = false;  // its new session is bound: it plays from `until`
      returning.snapshot = {};
    } else {
      returning.returning = true;  // the old session is bound: the next handshake replaces it
      returning.knows_us = true;   // so that a new session's hello is met with a rechallenge
    }
  }
  raise(Event{EventType::rejoined, player, r.until, 0, 0, {}});
}

void Session::Impl::take_snapshot(detail::Peer& peer) {
  const std::uint32_t joiner = peer.player;
  if (disconnect_frame[joiner] != detail::never) {
    // An open seat (never taken, or given up): the player is away from where every peer took it
    // as gone to R, and plays from there. R is no earlier than the present, nor than any held
    // frame this machine ever reported (the file comment says why).
    const std::uint64_t from = disconnect_frame[joiner];
    const std::uint64_t until = std::max({from + 1, current, max_held_sent, confirmed_frame()});
    readmit(joiner, from, until);
  }
  // The state of the oldest frame not yet delivered (final everywhere: every peer holds its
  // inputs, no correction reaches back to it), from the input just before it on.
  const std::uint64_t frame = next_emit;
  const std::uint64_t first = frame == 0 ? 0 : frame - 1;
  const detail::State& state = state_slot(frame);
  DETSIM_ASSERT(state.frame == frame);  // the ring holds every frame not yet delivered
  detail::Snapshot snapshot;
  snapshot.frame = frame;
  snapshot.present = std::max(current, absent_until[joiner]);  // the joiner plays from R on
  snapshot.input_size = config.input_size;
  for (std::uint32_t p = 0; p < config.players; ++p) {
    const detail::InputQueue& q = queues[p];
    detail::SnapshotPlayer& player = snapshot.players.emplace_back();
    player.disconnect = disconnect_frame[p];
    player.absent_from = absent_from[p];
    player.absent_until = absent_until[p];
    player.first = first;
    for (std::uint64_t f = first; f < q.next_confirmed(); ++f) {
      // The queues span every frame not yet delivered (input_capacity); a frame they no longer
      // hold would be a session bug: its input goes as zero rather than out of another frame.
      const std::span<const std::uint8_t> input =
          q.holds(f) ? q.confirmed(f) : std::span<const std::uint8_t>(scratch_input);
      player.inputs.insert(player.inputs.end(), input.begin(), input.end());
    }
  }
  snapshot.log = frame_log;
  snapshot.state = state.bytes;
  peer.snapshot = detail::encode_snapshot(snapshot);
  ++stats.snapshots_served;
  // Hash checks start over after the snapshot's frame on both sides (load_snapshot does the
  // same): the new session compares nothing before it, and took this machine's state there.
  const std::uint64_t interval = config.check_interval;
  const std::uint64_t through = interval == 0 ? 0 : frame / interval * interval;
  peer.checks_through = through;
  peer.acked_checks = through;
  peer.pending_checks.clear();
  peer.reported_held = std::min(peer.reported_held, frame);
  raise(Event{EventType::rejoined, joiner, frame, 0, 0, {}});
  retire_checks();
}

void Session::Impl::serve_state(detail::Peer& peer, std::uint32_t offset) {
  if (peer.snapshot.empty()) {
    if (!snapshot_ready(peer)) return;  // the joiner asks again
    take_snapshot(peer);
  }
  const std::vector<std::uint8_t>& bytes = peer.snapshot;
  if (offset >= bytes.size()) return;  // it has everything (its inputs are on their way)
  protocol::Packet p;
  p.header.type = protocol::PacketType::state_chunk;
  p.state_chunk.total = static_cast<std::uint32_t>(bytes.size());
  std::size_t at = offset;
  for (std::size_t k = 0; k < chunks_per_request && at < bytes.size(); ++k) {
    const std::size_t n = std::min(protocol::max_state_chunk, bytes.size() - at);
    p.state_chunk.offset = static_cast<std::uint32_t>(at);
    p.state_chunk.data.assign(bytes.begin() + static_cast<std::ptrdiff_t>(at),
                              bytes.begin() + static_cast<std::ptrdiff_t>(at + n));
    send(peer, p);
    stats.snapshot_bytes_sent += n;
    at += n;
  }
}

detail::Peer* Session::Impl::snapshot_server() noexcept {
  if (!server_index) {
    for (std::size_t i = 0; i < peers.size() && !server_index; ++i)
      if (peers[i].synchronized) server_index = i;
    if (!server_index) return nullptr;
  }
  return &peers[*server_index];
}

void Session::Impl::request_state() {
  detail::Peer* chosen = snapshot_server();
  if (chosen == nullptr || !broken.empty()) return;
  detail::Peer& server = *chosen;
  // Asked again when what was asked for arrived (receive_state), or after two round trips (or
  // two frames) without it: lost slices are asked for anew from the first missing byte.
  const std::uint64_t wait = std::max<std::uint64_t>(2 * config.frame_us, server.rtt_x16 / 8);
  if (last_request_us && now_us - *last_request_us < wait) return;
  protocol::Packet p;
  p.header.type = protocol::PacketType::state_request;
  p.state_request.offset = static_cast<std::uint32_t>(incoming.size());
  send(server, p);
  last_request_us = now_us;
}

void Session::Impl::receive_state(detail::Peer& peer, const protocol::StateChunk& chunk) {
  if (!awaiting_state || !server_index || &peer != &peers[*server_index]) {
    ++stats.dropped_implausible;  // nobody asked this machine's session for a snapshot
    return;
  }
  if (incoming_total == 0) incoming_total = chunk.total;
  if (chunk.total != incoming_total) {
    ++stats.dropped_implausible;
    return;
  }
  if (chunk.offset != incoming.size()) return;  // a resend, or out of order: asked for again
  incoming.insert(incoming.end(), chunk.data.begin(), chunk.data.end());
  if (incoming.size() < incoming_total) {
    if (incoming.size() % (chunks_per_request * protocol::max_state_chunk) == 0) {
      last_request_us.reset();  // the whole window arrived: ask for the next one now
      request_state();
    }
    return;
  }
  if (Status s = load_snapshot(peer); !s) {
    broken = s.message();
    raise(Event{EventType::match_ended, config.local_player, 0, 0, 0, "rejoin failed"});
  }
}

Status Session::Impl::load_snapshot(detail::Peer& from) {
  Expected<detail::Snapshot> decoded =
      detail::decode_snapshot(incoming, config.players, config.input_size, detail::input_capacity);
  incoming = {};
  if (!decoded)
    return Status::error("rejoin: the snapshot player " + std::to_string(from.player) +
                         " sent is invalid (" + decoded.status().message() +
                         "); start this player again to retry");
  const detail::Snapshot& s = *decoded;
  const detail::SnapshotPlayer& own = s.players[config.local_player];
  if (shared() && (own.disconnect != detail::never || own.absent_until == 0))
    return Status::error("rejoin: the snapshot player " + std::to_string(from.player) +
                         " sent does not take this player back (a match of " +
                         std::to_string(config.players) +
                         " players returns it from an agreed frame); start this player again");

  if (config.rejoin_replays_match) {
    if (Status replayed = replay_match(s, from.player); !replayed) return replayed;
  }
  game->load(s.state);
  current = s.frame;
  next_emit = s.frame;
  detail::State& saved = state_slot(s.frame);
  saved.frame = s.frame;
  saved.hash = game->save(saved.bytes);
  agreed_frame = s.frame;
  agreed_state = saved.bytes;
  frame_log = s.log;
  const std::size_t size = config.input_size;
  for (std::uint32_t p = 0; p < config.players; ++p) {
    detail::InputQueue& q = queues[p];
    const detail::SnapshotPlayer& player = s.players[p];
    q.restart_at(player.first);
    for (std::size_t at = 0; at < player.inputs.size(); at += size)
      q.confirm(std::span<const std::uint8_t>(player.inputs).subspan(at, size));
    disconnect_frame[p] = player.disconnect;
    absent_from[p] = player.absent_from;
    absent_until[p] = player.absent_until;
  }
  // The peer holds our inputs up to here; the restart lost the rest, which are zeros up to the
  // peer's present (the first input of this session goes after them).
  detail::InputQueue& mine = queues[config.local_player];
  from.acked_inputs = mine.next_confirmed();
  std::fill(scratch_input.begin(), scratch_input.end(), std::uint8_t{0});
  while (mine.next_confirmed() < s.present)
    mine.confirm(scratch_input);
  const std::uint64_t interval = config.check_interval;
  const std::uint64_t through = interval == 0 ? 0 : s.frame / interval * interval;
  from.checks_through = through;
  from.acked_checks = through;
  from.pending_checks.clear();
  from.reported_held = s.frame;
  // The other peers take this player back at R when the server's back report (or ours)
  // reaches them; what they acknowledge counts from then, and their hash checks from R on.
  const std::uint64_t back = absent_until[config.local_player];
  const std::uint64_t back_through = interval == 0 ? 0 : back / interval * interval;
  for (detail::Peer& peer : peers) {
    // A player gone in the snapshot is an open seat to this session (never synchronized, so it
    // has no say): a new session of it may still join, through any peer.
    if (&peer == &from || !shared() || disconnect_frame[peer.player] != detail::never) continue;
    peer.awaiting_back = true;
    peer.acked_inputs = back;
    peer.checks_through = back_through;
    peer.acked_checks = back_through;
    peer.pending_checks.clear();
    peer.reported_held = s.frame;
  }

  awaiting_state = false;
  running = true;
  window_start_us = now_us;
  raise(Event{EventType::rejoined, config.local_player, s.frame, 0, 0, {}});
  raise(Event{EventType::running, 0, current, 0, 0, {}});
  // Re-simulate to the peer's present, as far as the window allows (advance_frame goes on).
  while (current < s.present && current + 2 - next_emit <= states.size() &&
         current < confirmed_frame() + max_prediction) {
    simulate(current, false);
    ++stats.frames;
  }
  for (detail::Peer& peer : peers)
    send_inputs(peer);
  return Status::success();
}

Status Session::Impl::replay_match(const detail::Snapshot& s, std::uint32_t server) {
  // The game is as the session found it at creation (nothing was simulated before the snapshot):
  // the state every peer started from.
  std::vector<std::uint8_t> state = state_slot(0).bytes;
  const std::size_t size = config.input_size;
  for (std::uint64_t frame = 0; frame < s.frame; ++frame) {
    const auto unit = s.log.begin() + static_cast<std::ptrdiff_t>(frame * unit_size);
    for (std::uint32_t p = 0; p < config.players; ++p)
      frame_status[p] =
          (unit[0] >> p & 1U) != 0 ? InputStatus::disconnected : InputStatus::confirmed;
    std::copy(unit + 1, unit + static_cast<std::ptrdiff_t>(unit_size), frame_inputs.begin());
    game->advance(FrameInputs{frame, size, frame_inputs, frame_status}, false);
    const std::uint64_t hash = game->save(state);
    if (confirmed_listener)
      confirmed_listener(ConfirmedFrame{frame, frame_inputs, frame_status, hash});
  }
  if (state != s.state)
    return Status::error("rejoin: the snapshot player " + std::to_string(server) +
                         " sent does not follow from its own frames: re-simulated from the start, "
                         "they give another state at frame " +
                         std::to_string(s.frame) +
                         " (a peer that is not deterministic, or one that lies); start this "
                         "player again to retry");
  return Status::success();
}

}  // namespace detsim::net
