// The session's network side: the handshake, every received datagram's validation and handling,
// what is sent when (inputs, acks, hash checks, pings, keepalives), and the silence timeouts.
//
// Reliability is by redundancy, as in GGPO: every input packet carries all of this machine's
// inputs the peer has not acknowledged and all unacknowledged hash checks, so a lost packet costs
// nothing once any later one arrives. Acknowledgements are cumulative (frame numbers).
#include <algorithm>
#include <limits>

#include "session_impl.hpp"

namespace detsim::net {
namespace {

// Smoothing by 1/8 per sample (TCP's SRTT gain), in integers scaled by 16.
std::uint64_t smooth(std::uint64_t average_x16, std::uint64_t sample, bool first) {
  const std::uint64_t target = sample * 16;
  if (first) return target;
  return target >= average_x16 ? average_x16 + (target - average_x16) / 8
                               : average_x16 - (average_x16 - target) / 8;
}

std::int64_t smooth_signed(std::int64_t average_x16, std::int64_t sample) {
  return average_x16 + (sample * 16 - average_x16) / 8;
}

std::uint32_t wire_frame(std::uint64_t frame) {
  return static_cast<std::uint32_t>(std::min<std::uint64_t>(frame, 0xFFFF'FFFFU));
}

}  // namespace

detail::Peer* Session::Impl::peer_by_id(PeerId id) noexcept {
  for (detail::Peer& peer : peers)
    if (peer.id == id) return &peer;
  for (detail::Peer& spectator : spectators)
    if (spectator.id == id) return &spectator;
  return nullptr;
}

void Session::Impl::receive_all() {
  inbox.clear();
  transport->receive(inbox);
  for (const Datagram& d : inbox) {
    detail::Peer* peer = peer_by_id(d.from);
    // A gone player's datagrams are dropped, but for the handshake of a new session of it that
    // may take its seat again (session_rejoin.cpp; handle() lets nothing else through).
    if (peer == nullptr || (peer->disconnected && !seat_takeable(*peer))) {
      ++stats.dropped_wrong_session;
      continue;
    }
    if (protection) {
      if (!open(*peer, d.bytes)) continue;
    } else {
      const protocol::DecodeError error = protocol::decode(d.bytes, config.input_size, packet);
      if (error != protocol::DecodeError::none) {
        if (detail::looks_sealed(d.bytes) && detail::looks_like_handshake(d.bytes) &&
            !peer->synchronized)
          reject(*peer, "sealed");  // the peer has a match key, this session none
        ++stats.dropped_malformed[static_cast<std::size_t>(error)];
        continue;
      }
    }
    peer->stats.bytes_received += d.bytes.size();
    handle(*peer, packet);
  }
  inbox.clear();
}

bool Session::Impl::open(detail::Peer& peer, std::span<const std::uint8_t> bytes) {
  // Header, replay window, tag (channel.hpp): a datagram that fails any of them changes nothing
  // but a counter. Before the handshake completes, a hello that fails authentication is the
  // usual sign of a peer with another key, so it is reported (once).
  protocol::DecodeError error = protocol::DecodeError::none;
  switch (protection->open(peer.channel, bytes, packet.header, error, scratch_body)) {
    case detail::Opened::ok:
      break;
    case detail::Opened::malformed:
      if (error == protocol::DecodeError::bad_magic && !detail::looks_sealed(bytes)) {
        ++stats.dropped_unauthenticated;  // the plain framing: no protection at all
        if (!peer.synchronized && detail::looks_like_handshake(bytes)) reject(peer, "not sealed");
      } else {
        ++stats.dropped_malformed[static_cast<std::size_t>(error)];
      }
      return false;
    case detail::Opened::no_key:
      ++stats.dropped_wrong_session;
      return false;
    case detail::Opened::replayed:
      ++stats.dropped_replayed;
      return false;
    case detail::Opened::unauthenticated:
      ++stats.dropped_unauthenticated;
      if (!peer.synchronized && detail::looks_like_handshake(bytes))
        reject(peer, "not authenticated");
      return false;
  }
  // A peer that holds the key may still send any body: it is decoded as strictly as ever.
  error = protocol::decode_body(packet.header.type, scratch_body, config.input_size, packet);
  if (error != protocol::DecodeError::none) {
    ++stats.dropped_malformed[static_cast<std::size_t>(error)];
    return false;
  }
  return true;
}

void Session::Impl::reject(detail::Peer& peer, std::string_view reason) {
  if (peer.hello_rejected) return;
  peer.hello_rejected = true;
  raise(Event{EventType::hello_rejected, peer.player, current, 0, 0, reason});
}

void Session::Impl::handle(detail::Peer& peer, const protocol::Packet& p) {
  using protocol::PacketType;
  if (((peer.disconnected && !peer.rejoining) || peer.returning) &&
      p.header.type != PacketType::hello && p.header.type != PacketType::hello_reply) {
    // The session that was taken as gone stays gone; so does one whose player came back.
    ++stats.dropped_wrong_session;
    return;
  }
  if (p.header.type == PacketType::hello) {
    // Answered, never believed: a hello proves nothing about who sent it (its source address can
    // be spoofed), so it is not a sign of life either.
    handle_hello(peer, p);
    return;
  } else if (p.header.type == PacketType::hello_reply && peer.rechallenge &&
             p.hello_reply.challenge == *peer.rechallenge) {
    // The answer to a rechallenge (session_rejoin.cpp): from the session we know, nothing
    // changes; from a new one, a restarted process of the peer's player takes the seat.
    peer.rechallenge.reset();
    if (p.header.session == peer.remote_session) return;
    rebind(peer, p.header.session);
  } else if (p.header.type == PacketType::hello_reply) {
    // The peer's session id is taken from the reply to our own challenge only — 64 random bits
    // sent to its address alone, which a third party off the path never sees — and once.
    if (p.hello_reply.challenge != peer.challenge ||
        (peer.answered && p.header.session != peer.remote_session)) {
      ++stats.dropped_wrong_session;
      return;
    }
    if (peer.answered) return;  // a duplicate: nothing new
    peer.answered = true;
    peer.remote_session = p.header.session;
    if (protection) protection->bind(peer.channel, peer.remote_session);
  } else {
    if (!peer.synchronized || p.header.session != peer.remote_session) {
      ++stats.dropped_wrong_session;
      return;
    }
    peer.knows_us = true;
    // Fresh: newer than every datagram handled from the peer (sequence numbers modulo 2^16).
    const auto step = static_cast<std::uint16_t>(
        p.header.sequence - peer.last_sequence.value_or(std::uint16_t(p.header.sequence - 1)));
    const bool fresh = step != 0 && step < 0x8000U;
    if (p.header.type == PacketType::ping) {
      protocol::Packet pong;
      pong.header.type = PacketType::pong;
      pong.ping.time_us = p.ping.time_us;
      send(peer, pong);
    } else if (p.header.type == PacketType::pong) {
      // Only the pong of the ping we have outstanding measures anything: a replayed or forged
      // one (any time it carries) would make up a round-trip time and with it the frame advantage.
      if (!peer.ping_out || p.ping.time_us != *peer.ping_out) {
        ++stats.dropped_stale_pongs;
        return;
      }
      peer.ping_out.reset();
      const std::uint64_t rtt = now_us - p.ping.time_us;
      const bool first = peer.rtt_x16 == 0;
      const std::uint64_t deviation =
          rtt * 16 > peer.rtt_x16 ? rtt * 16 - peer.rtt_x16 : peer.rtt_x16 - rtt * 16;
      peer.rtt_x16 = smooth(peer.rtt_x16, rtt, first);
      peer.jitter_x16 = smooth(peer.jitter_x16, deviation / 16, first);
    } else if (p.header.type == PacketType::state_request) {
      if (!peer.rejoining) {  // only a peer that rejoined is served a snapshot
        ++stats.dropped_implausible;
        return;
      }
      serve_state(peer, p.state_request.offset);
    } else if (p.header.type == PacketType::state_chunk) {
      receive_state(peer, p.state_chunk);
    } else if (!handle_input(peer, p.input, fresh)) {
      ++stats.dropped_implausible;
      return;
    }
    ++peer.stats.packets_received;
    // Loss statistics from the sequence numbers (a late one fills a gap).
    if (fresh) {
      if (peer.last_sequence) peer.stats.packets_lost += step - 1U;
      peer.last_sequence = p.header.sequence;
    } else if (step >= 0x8000U && peer.stats.packets_lost > 0) {
      --peer.stats.packets_lost;
    }
    // A duplicate or a late datagram says nothing about the peer now (a relay replaying old
    // packets must not keep a departed peer alive).
    if (!fresh) return;
  }
  if (p.header.type == PacketType::hello || p.header.type == PacketType::hello_reply)
    ++peer.stats.packets_received;
  peer.last_receive_us = now_us;
  if (peer.interrupted) {
    peer.interrupted = false;
    raise(Event{EventType::resumed, peer.player, current, 0, 0, {}});
    // A pause ends when every player is heard again; the clocks start anew from here.
    if (paused && std::none_of(peers.begin(), peers.end(),
                               [](const detail::Peer& x) { return x.interrupted; })) {
      paused = false;
      restart_clocks();
    }
  }
  if (!peer.synchronized && peer.answered) {
    peer.synchronized = true;
    peer.stats.synchronized = true;
    peer.returning = false;  // a player taken back plays with the session this handshake bound
    raise(Event{EventType::synchronized, peer.player, current, 0, 0, {}});
    // A rejoining session runs once the snapshot is loaded (load_snapshot), not before; one
    // that joins an open seat here asks for it, and the match was running already.
    if (!peer.spectator && disconnect_frame[peer.player] != detail::never && seat_takeable(peer))
      peer.rejoining = true;
    // An open seat is not waited for.
    if (!peer.spectator && !awaiting_state && !running &&
        std::all_of(peers.begin(), peers.end(), [&](const detail::Peer& x) {
          return x.synchronized || disconnect_frame[x.player] != detail::never;
        })) {
      running = true;
      window_start_us = now_us;  // the progress guard counts from here
      raise(Event{EventType::running, 0, current, 0, 0, {}});
    }
  }
}

void Session::Impl::handle_hello(detail::Peer& peer, const protocol::Packet& p) {
  const protocol::Hello& h = p.hello;
  std::string_view reason;
  if (h.fingerprint != config.fingerprint)
    reason = "fingerprint";
  else if (h.players != config.players)
    reason = "player count";
  else if (h.input_size != config.input_size)
    reason = "input size";
  else if (peer.spectator ? h.player != protocol::spectator_player : h.player != peer.player)
    reason = peer.spectator ? "not a spectator" : "player index";
  if (!reason.empty()) {
    ++stats.dropped_wrong_session;
    reject(peer, reason);
    return;
  }
  if (peer.knows_us) {
    // The genuine peer has our id already: this hello is stale, forged, or from a restarted
    // process of the peer's player (session_rejoin.cpp). It is not believed, only answered.
    ++stats.dropped_wrong_session;
    handle_rejoin_hello(peer, p);
    return;
  }
  // Every matching hello is answered (to the peer's address, whoever sent it): a flood of forged
  // hellos cannot crowd out the genuine one's answer, and a reply to a forged challenge is
  // dropped by the genuine peer.
  protocol::Packet reply;
  reply.header.type = protocol::PacketType::hello_reply;
  reply.hello_reply.challenge = h.challenge;
  send(peer, reply);
}

bool Session::Impl::plausible(const detail::Peer& peer, const protocol::InputBody& b) const {
  // The sender's held frame counts our inputs (it plays with us, or it would not send to us),
  // so it cannot exceed the inputs of ours it acknowledges in the same datagram.
  if (b.held_frame > b.ack_frame) return false;
  // Its current frame: at most max_prediction_limit beyond the inputs of ours it can hold, and at
  // most max_input_delay + 1 behind the inputs it sent (its own input runs that far ahead).
  const std::uint64_t ours = queues[config.local_player].next_confirmed();
  if (b.current_frame > ours + detail::max_prediction_limit) return false;
  const std::uint64_t sent =
      std::max<std::uint64_t>(queues[peer.player].next_confirmed(), b.start_frame + b.count);
  return std::uint64_t{b.current_frame} + detail::max_input_delay + 1 >= sent;
}

bool Session::Impl::handle_input(detail::Peer& peer, const protocol::InputBody& b, bool fresh) {
  if (peer.spectator) {  // a spectator only acknowledges frames
    const std::uint64_t logged = frame_log.size() / unit_size;
    if (b.ack_frame <= logged)
      peer.acked_inputs = std::max<std::uint64_t>(peer.acked_inputs, b.ack_frame);
    peer.remote_frame = b.current_frame;
    peer.stats.remote_frame = b.current_frame;
    return true;
  }
  // Nothing is taken before this rejoining session has the match (load_snapshot).
  if (awaiting_state) return true;
  // Every field is checked before any is used: an implausible datagram changes nothing.
  if (fresh && !plausible(peer, b)) return false;
  // Back reports first (session_rejoin.cpp): one may say the peer took this machine back, so
  // that what it acknowledges below is about this session; a new session that has not been
  // given the match yet speaks for itself only.
  for (const protocol::BackReport& r : b.back)
    if (seated(peer) || r.player == peer.player) take_back(peer, r);
  const detail::InputQueue& mine = queues[config.local_player];
  // Acknowledgements never move backwards, nor beyond what was sent. From a peer that has not
  // taken this rejoined machine back yet, they are about its old session: not ours.
  if (b.ack_frame <= mine.next_confirmed() && !peer.awaiting_back)
    peer.acked_inputs = std::max<std::uint64_t>(peer.acked_inputs, b.ack_frame);
  const std::uint64_t last_check = local_checks.empty() ? agreed_frame : local_checks.back().frame;
  if (b.check_ack <= std::max(last_check, peer.acked_checks) && !peer.awaiting_back)
    peer.acked_checks = std::max<std::uint64_t>(peer.acked_checks, b.check_ack);
  if (fresh) {  // time sync from the newest datagram only: a late one's frames are out of date
    peer.remote_frame = b.current_frame;
    peer.stats.remote_frame = b.current_frame;
    peer.remote_advantage_x16 = smooth_signed(peer.remote_advantage_x16, b.advantage);
    const std::uint64_t half_rtt_frames = peer.rtt_x16 / 32 / config.frame_us;
    const auto ahead = static_cast<std::int64_t>(current) -
                       static_cast<std::int64_t>(b.current_frame + half_rtt_frames);
    peer.advantage_x16 = smooth_signed(peer.advantage_x16, ahead);
  }

  if (peer.rejoining) {
    // The rejoined session has the snapshot: it plays from here. One that never asked for it
    // (a session without SessionConfig::rejoin in an open seat) is not let in.
    if (peer.snapshot.empty()) return true;
    peer.rejoining = false;
    peer.snapshot = {};
  }
  detail::InputQueue& q = queues[peer.player];
  if (b.count > 0 && disconnect_frame[peer.player] == detail::never) {
    const std::uint64_t start = b.start_frame;
    const std::uint64_t end = start + b.count;
    if (start > q.next_confirmed() || (start > 0 && !q.holds(start - 1)) ||
        end > window_start() + detail::input_capacity) {
      ++stats.dropped_out_of_window;
    } else if (end > q.next_confirmed()) {
      scratch_deltas.assign(b.deltas.begin(), b.deltas.end());
      protocol::delta_decode(q.reference(start), scratch_deltas);
      const std::size_t size = config.input_size;
      for (std::uint64_t frame = q.next_confirmed(); frame < end; ++frame) {
        const auto offset = static_cast<std::size_t>(frame - start) * size;
        receive_input(peer, frame,
                      std::span<const std::uint8_t>(scratch_deltas).subspan(offset, size));
      }
    }
    peer.needs_ack = true;
  }
  if (!b.checks.empty()) peer.needs_ack = true;
  for (const protocol::HashCheck& c : b.checks) {
    if (peer.awaiting_back) break;  // compared from the frame it takes us back at
    if (config.check_interval == 0 || c.frame == 0 || c.frame % config.check_interval != 0) {
      ++stats.dropped_out_of_window;
      break;
    }
    if (c.frame == peer.checks_through + config.check_interval &&
        peer.pending_checks.size() < detail::max_pending_checks) {
      peer.pending_checks.push_back(c);
      peer.checks_through = c.frame;
    }
  }
  compare_checks(peer);
  retire_checks();
  // Disconnect agreement, with the peers this machine still plays with only.
  if (peer.disconnected) return true;
  if (fresh && !peer.awaiting_back) {  // a late datagram's may be out of date
    // A peer that still takes a player as gone from before that player's return holds none of
    // its inputs from the return on, whatever frame it says it holds.
    std::uint64_t held = b.held_frame;
    for (const protocol::GoneReport& g : b.gone)
      if (g.player < config.players && g.frame < absent_until[g.player])
        held = std::min(held, absent_until[g.player]);
    peer.reported_held = held;
  }
  for (const protocol::GoneReport& g : b.gone) {
    if (g.player >= config.players) {
      ++stats.dropped_out_of_window;
      continue;
    }
    // About an absence that is over (the player came back after it): old news.
    if (g.frame < absent_until[g.player]) continue;
    // Corroborated disconnects: a report about this machine's own player, or about a player it
    // still hears from (the sender itself included), is not believed. One peer alone cannot
    // remove a player the others still play with; a peer this machine no longer hears either is
    // gone here too, and the report only moves its frame earlier.
    if (g.player == config.local_player || hears(g.player)) {
      ++stats.ignored_gone_reports;
      continue;
    }
    peer.reported_gone[g.player] = std::min<std::uint64_t>(peer.reported_gone[g.player], g.frame);
    player_gone(g.player, g.frame, "reported gone");
  }
  return true;
}

void Session::Impl::send(detail::Peer& peer, protocol::Packet& p) {
  p.header.session = session_id;
  p.header.sequence = peer.send_sequence++;
  const std::size_t unit = peer.spectator && p.header.type == protocol::PacketType::input
                               ? unit_size
                               : config.input_size;
  const bool encoded = protection ? protection->seal(peer.channel, p, unit, outbuf)
                                  : protocol::encode(p, unit, outbuf);
  if (!encoded) return;
  transport->send(peer.id, outbuf);
  ++peer.stats.packets_sent;
  peer.stats.bytes_sent += outbuf.size();
  peer.last_send_us = now_us;
}

void Session::Impl::send_inputs(detail::Peer& peer) {
  const detail::InputQueue& mine = queues[config.local_player];
  protocol::Packet& p = packet;
  p.header.type = protocol::PacketType::input;
  protocol::InputBody& b = p.input;
  b.ack_frame = wire_frame(queues[peer.player].next_confirmed());
  b.check_ack = wire_frame(peer.checks_through);
  b.current_frame = wire_frame(current);
  b.advantage =
      static_cast<std::int8_t>(std::clamp<std::int64_t>(peer.advantage_x16 / 16, -127, 127));
  std::uint64_t start = std::min(peer.acked_inputs, mine.next_confirmed());
  if ((start > 0 && !mine.holds(start - 1)) ||
      (start < mine.next_confirmed() && !mine.holds(start)))
    start = mine.next_confirmed();  // too far behind (or not known yet): its acks will say
  const std::size_t size = config.input_size;
  const std::size_t most = std::min<std::size_t>(protocol::max_inputs_per_packet, 900 / (size + 1));
  const auto count =
      static_cast<std::size_t>(std::min<std::uint64_t>(mine.next_confirmed() - start, most));
  b.start_frame = wire_frame(start);
  b.count = static_cast<std::uint8_t>(count);
  scratch_inputs.resize(count * size);
  for (std::size_t i = 0; i < count; ++i) {
    const std::span<const std::uint8_t> input = mine.confirmed(start + i);
    std::copy(input.begin(), input.end(),
              scratch_inputs.begin() + static_cast<std::ptrdiff_t>(i * size));
  }
  protocol::delta_encode(mine.reference(start), scratch_inputs, b.deltas);
  b.checks.clear();
  for (const detail::LocalCheck& c : local_checks) {
    if (c.frame <= peer.acked_checks) continue;
    if (b.checks.size() == protocol::max_checks_per_packet) break;
    b.checks.push_back(protocol::HashCheck{wire_frame(c.frame), c.hash});
  }
  const std::uint64_t held = confirmed_frame();
  max_held_sent = std::max(max_held_sent, held);
  b.held_frame = wire_frame(held);
  b.gone.clear();
  b.back.clear();
  for (std::uint32_t q = 0; q < config.players; ++q) {
    const auto player = static_cast<std::uint8_t>(q);
    if (disconnect_frame[q] != detail::never)
      b.gone.push_back({player, wire_frame(disconnect_frame[q])});
    if (absent_until[q] != 0)
      b.back.push_back({player, wire_frame(absent_from[q]), wire_frame(absent_until[q])});
  }
  peer.needs_ack = false;
  send(peer, p);
}

void Session::Impl::send_hello(detail::Peer& peer, std::uint64_t challenge) {
  protocol::Packet hello;
  hello.header.type = protocol::PacketType::hello;
  hello.hello = protocol::Hello{config.fingerprint, static_cast<std::uint8_t>(config.players),
                                static_cast<std::uint8_t>(config.local_player),
                                static_cast<std::uint8_t>(config.input_size), challenge};
  send(peer, hello);
}

void Session::Impl::send_frames(detail::Peer& spectator) {
  // Every confirmed frame the spectator lacks, as whole-frame units delta-coded against the
  // frame before: a spectator that fell behind gets up to a packet of frames per send.
  const std::uint64_t logged = frame_log.size() / unit_size;
  const std::uint64_t start = std::min(spectator.acked_inputs, logged);
  const std::size_t most =
      std::min<std::size_t>(protocol::max_inputs_per_packet, 900 / (unit_size + 1));
  const auto count = static_cast<std::size_t>(std::min<std::uint64_t>(logged - start, most));
  protocol::Packet& p = packet;
  p.header.type = protocol::PacketType::input;
  protocol::InputBody& b = p.input;
  b = protocol::InputBody{};
  b.current_frame = wire_frame(current);
  b.start_frame = wire_frame(start);
  b.count = static_cast<std::uint8_t>(count);
  const auto at = [&](std::uint64_t frame) {
    return frame_log.begin() + static_cast<std::ptrdiff_t>(frame * unit_size);
  };
  scratch_inputs.assign(at(start), at(start + count));
  scratch_deltas.assign(unit_size, 0);
  if (start > 0) scratch_deltas.assign(at(start - 1), at(start));
  protocol::delta_encode(scratch_deltas, scratch_inputs, b.deltas);
  spectator.needs_ack = false;
  send(spectator, p);
}

void Session::Impl::send_due() {
  if (awaiting_state) request_state();
  const detail::InputQueue& mine = queues[config.local_player];
  const std::uint64_t logged = unit_size ? frame_log.size() / unit_size : 0;
  for (std::vector<detail::Peer>* group : {&peers, &spectators}) {
    for (detail::Peer& peer : *group) {
      // A new session bound to a gone player's seat is kept alive (below) until it plays.
      if (peer.disconnected && !peer.rejoining) continue;
      // A rejoining session says hello until the peer has bound it (it then sends more than the
      // handshake): the peer's challenge that binds it answers a hello, and either may be lost.
      const bool unbound = !peer.answered || (config.rejoin && !peer.knows_us);
      if (unbound &&
          (!peer.hello_sent || now_us - peer.last_hello_us >= config.hello_interval_us)) {
        send_hello(peer, peer.challenge);
        peer.hello_sent = true;
        peer.last_hello_us = now_us;
      }
      if (!peer.synchronized) continue;
      // A rejoining session gets no inputs from here until it plays: pings keep it hearing us.
      const bool keepalive = peer.rejoining && now_us - peer.last_send_us >= config.keepalive_us;
      if (now_us - peer.last_ping_us >= config.ping_interval_us || keepalive) {
        protocol::Packet ping;
        ping.header.type = protocol::PacketType::ping;
        ping.ping.time_us = now_us;
        send(peer, ping);
        peer.last_ping_us = now_us;
        peer.ping_out = now_us;
      }
      const std::uint64_t quiet = now_us - peer.last_send_us;
      if (peer.spectator) {
        if ((peer.acked_inputs < logged && quiet >= config.frame_us) ||
            quiet >= config.keepalive_us)
          send_frames(peer);
        continue;
      }
      // A rejoining session has no inputs yet, and a peer rejoining here none of ours: until its
      // first input datagram it is sent the snapshot it asks for instead (session_rejoin.cpp).
      if (awaiting_state || peer.rejoining) continue;
      // advance_frame() sends each new local input at once; here only what it did not cover: a
      // stall (waiting at the limit adds no input), acknowledgements, resends and keepalives.
      // Waiting a frame and a half first keeps the normal flow at one datagram per frame.
      const bool unacked = peer.acked_inputs < mine.next_confirmed() ||
                           (!local_checks.empty() && local_checks.back().frame > peer.acked_checks);
      const std::uint64_t resend_us = config.frame_us + config.frame_us / 2;
      if (((unacked || peer.needs_ack) && quiet >= resend_us) || quiet >= config.keepalive_us)
        send_inputs(peer);
    }
  }
}

void Session::Impl::check_timeouts() {
  for (std::vector<detail::Peer>* group : {&peers, &spectators}) {
    for (detail::Peer& peer : *group) {
      if (!peer.synchronized || peer.disconnected) continue;
      const std::uint64_t silence = now_us - peer.last_receive_us;
      if (silence >= config.disconnect_timeout_us) {
        if (peer.spectator) {
          peer.disconnected = true;
          peer.stats.disconnected = true;
          raise(Event{EventType::disconnected, peer.player, current, 0, 0, "silent"});
        } else {
          disconnect(peer, "silent");
        }
      } else if (silence >= config.disconnect_warning_us && !peer.interrupted) {
        peer.interrupted = true;
        raise(Event{EventType::interrupted, peer.player, current, 0, 0, {}});
      }
    }
  }
}

void Session::Impl::check_progress() {
  if (!running || now_us - window_start_us < config.progress_timeout_us) return;
  // Held back: the game asked to advance at least twice as often as it could (it ran less than a
  // third of the time through the window), and cannot now. Honest peers keep a match far above
  // that however slow their link (a 400 ms one-way trip still confirms a frame per frame), and a
  // silent one is disconnected by the shorter disconnect timeout first.
  const bool held_back = last_advance_held && window_held > 2 * window_advanced;
  window_start_us = now_us;
  window_advanced = 0;
  window_held = 0;
  if (!held_back) return;
  std::vector<detail::Peer*> blamed;
  for (detail::Peer& peer : peers)
    if (seated(peer) && holds_back(peer)) blamed.push_back(&peer);
  for (detail::Peer* peer : blamed)
    disconnect(*peer, "no progress");
}

void Session::poll(std::uint64_t now_us) {
  Impl& s = *impl_;
  s.now_us = std::max(s.now_us, now_us);
  s.receive_all();
  s.check_timeouts();
  s.check_progress();
  s.check_deadlines();
  if (s.running) {
    // As GGPO does while idle: a correction received here is applied now, so a game that stops
    // advancing (at a match's end, or waiting) still gets its confirmed frames out.
    // A failed rollback stops the session: advance_frame reports it (Session::Impl::broken).
    if (!s.first_incorrect || s.rollback().ok()) s.emit_confirmed();
  }
  s.send_due();
}

std::uint32_t Session::recommended_wait_frames() const noexcept {
  // The peer's own estimate of its advantage should mirror ours; it is trusted only within
  // `tolerance` frames of that, so a lying peer can hold this machine back by at most
  // tolerance / 2 frames beyond what its (range-checked) frame numbers show.
  constexpr std::int64_t tolerance_x16 = 8 * 16;
  std::int64_t wait_x16 = 0;
  for (const detail::Peer& peer : impl_->peers) {
    if (!peer.synchronized || peer.disconnected) continue;
    const std::int64_t mirror = -peer.advantage_x16;
    const std::int64_t remote =
        std::clamp(peer.remote_advantage_x16, mirror - tolerance_x16, mirror + tolerance_x16);
    wait_x16 = std::max(wait_x16, (peer.advantage_x16 - remote) / 2);
  }
  return static_cast<std::uint32_t>(wait_x16 / 16);
}

std::optional<PeerStats> Session::peer_stats(std::uint32_t player) const {
  const bool spectator = player >= impl_->config.players;
  for (const detail::Peer& peer : spectator ? impl_->spectators : impl_->peers) {
    if (peer.player != player) continue;
    PeerStats stats = peer.stats;
    stats.ping_us = peer.rtt_x16 / 16;
    stats.jitter_us = peer.jitter_x16 / 16;
    stats.frames_ahead = peer.advantage_x16 / 16;
    stats.acknowledged_frame = peer.acked_inputs;
    stats.checks_received_through = peer.spectator ? 0 : peer.checks_through;
    return stats;
  }
  return std::nullopt;
}

}  // namespace detsim::net
