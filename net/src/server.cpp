// net::Server (server.hpp): seats, stamping, history and what each client is sent.
//
// Data flow, per frame F:
//   datagrams -> handle_connect (a seat, a token, a welcome; a snapshot when the match is under
//   way) / handle_input (the client's inputs into its ring by tag; its acknowledgements)
//   advance -> each seat's input for F (stamp) -> the unit -> Game::advance -> Game::save (hash,
//   and the state a snapshot is cut from) -> history (unit, hash) -> the confirmed listener
//   send_due -> per client: a snapshot's slices while it has none, else an update (the units
//   since its acknowledgement, the hash after them), every update_interval frames or 100 ms.
#include <detsim/net/server.hpp>

#include <algorithm>
#include <deque>
#include <string>
#include <utility>

#include <detsim/core/hash.hpp>

#include "secure_random.hpp"
#include "server_snapshot.hpp"

namespace detsim::net {

namespace sp = server_protocol;

namespace {

/// Late inputs (tagged before the frame being simulated) the server still takes: older ones
/// are dropped as stale.
constexpr std::uint64_t late_window = 64;
/// The longest a client waits for something from the server (an update with nothing new).
constexpr std::uint64_t keepalive_us = 100'000;
/// How long a snapshot's slices rest after a full round before they are sent again.
constexpr std::uint64_t snapshot_resend_us = 100'000;
/// Gone clients whose statistics a server keeps (client_stats()).
constexpr std::size_t max_gone_clients = 256;
/// A connect from the peer of a client heard from within this is not a restart: ignored.
constexpr std::uint64_t restart_quiet_us = 1'000'000;

Status server_invalid(const std::string& field, const std::string& why) {
  return Status::error("ServerConfig: " + field + " " + why);
}

Status check_server(const ServerConfig& c) {
  if (c.players < 1 || c.players > sp::max_players)
    return server_invalid("players", "must be 1 .. " + std::to_string(sp::max_players) + ", got " +
                                         std::to_string(c.players));
  if (c.input_size < 1 || c.input_size > protocol::max_input_size)
    return server_invalid("input_size", "must be 1 .. " + std::to_string(protocol::max_input_size) +
                                            ", got " + std::to_string(c.input_size));
  if (sp::unit_size(c.players, c.input_size) > sp::max_unit_size)
    return server_invalid("players", "* input_size is too large: a frame's inputs take " +
                                         std::to_string(sp::unit_size(c.players, c.input_size)) +
                                         " bytes, at most " + std::to_string(sp::max_unit_size));
  if (c.description.size() > sp::max_description)
    return server_invalid("description", "must be at most " + std::to_string(sp::max_description) +
                                             " bytes, got " + std::to_string(c.description.size()));
  if (c.authority != sp::Authority::inputs && c.authority != sp::Authority::state)
    return server_invalid("authority", "is not inputs or state");
  if (c.frame_us < 1000 || c.frame_us > 1'000'000)
    return server_invalid("frame_us", "must be 1000 .. 1000000, got " + std::to_string(c.frame_us));
  if (c.start_clients > c.players)
    return server_invalid("start_clients", "must be at most players (" + std::to_string(c.players) +
                                               "), got " + std::to_string(c.start_clients));
  if (c.update_interval < 1 || c.update_interval > 60)
    return server_invalid("update_interval",
                          "must be 1 .. 60, got " + std::to_string(c.update_interval));
  if (c.snapshot_interval < 1 || c.snapshot_interval > 600)
    return server_invalid("snapshot_interval",
                          "must be 1 .. 600, got " + std::to_string(c.snapshot_interval));
  if (c.input_window < 1 || c.input_window > 1000)
    return server_invalid("input_window",
                          "must be 1 .. 1000, got " + std::to_string(c.input_window));
  if (c.history < 16 || c.history > 100'000)
    return server_invalid("history", "must be 16 .. 100000, got " + std::to_string(c.history));
  if (c.client_timeout_us == 0) return server_invalid("client_timeout_us", "must be above 0");
  if (c.view && c.authority != sp::Authority::state)
    return server_invalid("view",
                          "is for Authority::state (input authority sends inputs, which "
                          "every client simulates)");
  if (c.snapshot_burst < 1 || c.snapshot_burst > 4096)
    return server_invalid("snapshot_burst",
                          "must be 1 .. 4096, got " + std::to_string(c.snapshot_burst));
  return Status::success();
}

}  // namespace

struct Server::Impl {
  /// A snapshot on its way to one client, in slices.
  struct Outgoing {
    bool pending = false;
    std::uint32_t frame = 0;
    std::uint32_t base = 0;  ///< base frame + 1; 0: full
    std::uint64_t hash = 0;
    std::vector<std::uint8_t> bytes;
    std::size_t cursor = 0;  ///< the next slice's offset
    std::uint64_t rest_until_us = 0;
  };

  struct Client {
    PeerId peer = 0;
    std::uint64_t token = 0;
    std::uint64_t nonce = 0;
    std::uint32_t player = 0;
    bool connected = true;
    std::uint64_t last_heard_us = 0;
    std::uint64_t last_sent_us = 0;
    std::uint64_t joined_frame = 0;
    // Inputs by tag: ring slot tag % ring_size holds the input tagged ring_tag[slot].
    std::vector<std::uint8_t> ring;
    std::vector<std::int64_t> ring_tag;
    std::int64_t last_used_tag = -1;
    std::uint32_t input_ack = 0;  ///< every input tagged before it is held (or past)
    std::uint64_t ack = 0;        ///< it holds every unit before this frame
    std::uint64_t last_update_frame = 0;
    std::uint32_t echo_ms = 0;
    std::int32_t lead = 0;
    std::uint16_t sequence = 0;
    Outgoing snapshot;
    std::uint32_t snapshot_ack = 0;         ///< the newest snapshot it holds whole, + 1
    std::uint64_t last_snapshot_frame = 0;  ///< Authority::state: the last one sent, + 1
    /// Authority::state: the snapshots sent since the newest it acknowledged (frame, when sent).
    std::vector<std::pair<std::uint32_t, std::uint64_t>> unacknowledged;
    /// The first snapshot of the present chain: from it on, each is coded against the one sent
    /// before it; it against the newest acknowledged one.
    std::uint32_t chain_from = 0;
    /// From a snapshot's sending to its acknowledgement, smoothed (0: none acknowledged yet).
    std::uint64_t snapshot_rtt_us = 0;
    ServerClientStats stats;
  };

  struct Seat {
    std::int64_t client = -1;  ///< index into clients; -1: absent
    std::vector<std::uint8_t> last_input;
  };

  ServerConfig config;
  Game* game;
  Transport* transport;
  std::size_t unit_bytes;
  std::size_t mask_bytes;
  std::size_t ring_size;
  std::vector<Client> clients;  ///< by slot; a gone client's slot is reused
  std::deque<ServerClientStats> gone;
  std::vector<Seat> seats;
  std::uint64_t frame = 0;
  bool started = false;
  std::uint64_t start_us = 0;
  std::uint64_t now_us = 0;
  // History: units of frames [frame - history, frame), hashes of state frames
  // [frame - history, frame].
  std::vector<std::uint8_t> units;
  std::vector<std::uint64_t> hashes;
  std::vector<std::uint8_t> state;  ///< Game::save at `frame`
  /// Authority::state: the states of the recent snapshot frames (every snapshot_interval-th),
  /// oldest first: each client's newest acknowledged one is its next snapshot's base.
  std::vector<std::pair<std::uint64_t, std::vector<std::uint8_t>>> snapshot_states;
  /// The encodings of the newest snapshot, by (seat, base frame + 1; 0: full), with the hash of
  /// what they carry: clients with the same base share one (without a view, the seat is any_seat).
  struct Encoded {
    std::uint32_t seat = 0;
    std::uint32_t base = 0;
    std::uint64_t hash = 0;
    std::vector<std::uint8_t> bytes;
  };
  std::vector<Encoded> encoded;
  std::uint64_t encoded_frame = ~std::uint64_t{0};
  std::vector<std::uint8_t> base_view_scratch;
  std::uint64_t state_hash = 0;
  std::uint64_t initial_hash = 0;
  std::vector<std::uint8_t> unit;  ///< scratch: the frame being simulated
  std::vector<InputStatus> status;
  std::vector<std::uint8_t> datagram;
  std::vector<Datagram> received;
  std::function<void(const ConfirmedFrame&)> listener;
  std::vector<ServerEvent> events;
  ServerStats stats;

  Impl(const ServerConfig& c, Game& g, Transport& t)
      : config(c),
        game(&g),
        transport(&t),
        unit_bytes(sp::unit_size(c.players, c.input_size)),
        mask_bytes((c.players + 7) / 8),
        ring_size(c.input_window + late_window + 2),
        seats(c.players),
        units(std::size_t{c.history} * unit_bytes),
        hashes(std::size_t{c.history} + 1),
        unit(unit_bytes),
        status(c.players) {
    for (Seat& s : seats)
      s.last_input.assign(c.input_size, 0);
    state_hash = game->save(state);
    initial_hash = state_hash;
    hashes[0] = state_hash;
  }

  [[nodiscard]] sp::Sizes sizes() const noexcept { return {config.players, config.input_size}; }

  std::span<std::uint8_t> unit_at(std::uint64_t f) {
    return std::span<std::uint8_t>(units).subspan(
        static_cast<std::size_t>(f % config.history) * unit_bytes, unit_bytes);
  }
  std::uint64_t& hash_at(std::uint64_t state_frame) {
    return hashes[static_cast<std::size_t>(state_frame % (std::uint64_t{config.history} + 1))];
  }
  /// The unit of frame f - 1: what a client holds before frame f's (before frame 0: every seat
  /// absent).
  std::vector<std::uint8_t> unit_before(std::uint64_t f) {
    std::vector<std::uint8_t> out(unit_bytes, 0);
    if (f > 0) {
      const std::span<const std::uint8_t> u = unit_at(f - 1);
      std::copy(u.begin(), u.end(), out.begin());
    } else {
      for (std::size_t p = 0; p < config.players; ++p)
        out[p / 8] |= static_cast<std::uint8_t>(1U << (p % 8));
    }
    return out;
  }
  /// The oldest frame whose unit the history holds.
  [[nodiscard]] std::uint64_t oldest() const noexcept {
    return frame > config.history ? frame - config.history : 0;
  }

  std::size_t connected_count() const {
    return static_cast<std::size_t>(
        std::count_if(clients.begin(), clients.end(), [](const Client& c) { return c.connected; }));
  }

  Client* find(PeerId peer) {
    for (Client& c : clients)
      if (c.connected && c.peer == peer) return &c;
    return nullptr;
  }

  void send(Client& c, sp::Packet& p) {
    p.header.token = c.token;
    p.header.sequence = c.sequence++;
    if (!sp::encode(p, sizes(), datagram)) return;
    transport->send(c.peer, datagram);
    c.last_sent_us = now_us;
    c.stats.packets_sent += 1;
    c.stats.bytes_sent += datagram.size();
    stats.bytes_sent += datagram.size();
  }

  void reject(PeerId peer, std::uint64_t nonce, sp::RejectReason reason) {
    sp::Packet p;
    p.header.type = sp::PacketType::reject;
    p.reject = {nonce, reason};
    if (!sp::encode(p, sizes(), datagram)) return;
    transport->send(peer, datagram);
    stats.bytes_sent += datagram.size();
    stats.rejects += 1;
  }

  void welcome(Client& c) {
    sp::Packet p;
    p.header.type = sp::PacketType::welcome;
    sp::Welcome& w = p.welcome;
    w.nonce = c.nonce;
    w.player = static_cast<std::uint8_t>(c.player);
    w.players = static_cast<std::uint8_t>(config.players);
    w.input_size = static_cast<std::uint8_t>(config.input_size);
    w.authority = config.authority;
    w.frame_us = config.frame_us;
    w.frames = config.frames;
    w.start_frame = static_cast<std::uint32_t>(c.joined_frame);
    w.initial_hash = initial_hash;
    w.description = config.description;
    send(c, p);
  }

  /// A full snapshot of the current state for `c` (it joins at `frame`).
  void cut_snapshot(Client& c, const std::vector<std::uint8_t>* base, std::uint32_t base_frame) {
    detail::ServerSnapshot s;
    s.frame = frame;
    s.unit = unit_before(frame);
    s.state = state;
    Outgoing& o = c.snapshot;
    o.pending = true;
    o.frame = static_cast<std::uint32_t>(frame);
    o.base = base == nullptr ? 0 : base_frame + 1;
    o.hash = state_hash;
    o.bytes = detail::encode_server_snapshot(s, config.players, config.input_size, base, *game);
    o.cursor = 0;
    o.rest_until_us = 0;
    c.stats.snapshots_sent += 1;
  }

  void handle_connect(PeerId peer, const sp::Connect& connect) {
    if (Client* known = find(peer)) {
      if (known->nonce == connect.nonce) {
        welcome(*known);  // its welcome was lost
        return;
      }
      // Another process on the same address: a restart, once the old one has gone quiet.
      if (now_us - known->last_heard_us < restart_quiet_us) {
        stats.dropped_unknown += 1;
        return;
      }
      leave(*known, "restarted");
    }
    if (connect.game != config.game) {
      reject(peer, connect.nonce, sp::RejectReason::wrong_game);
      return;
    }
    if (ended()) {
      reject(peer, connect.nonce, sp::RejectReason::ended);
      return;
    }
    std::int64_t seat = -1;
    if (connect.seat != sp::any_seat) {
      if (connect.seat < config.players && seats[connect.seat].client < 0) seat = connect.seat;
    } else {
      for (std::size_t s = 0; s < seats.size() && seat < 0; ++s)
        if (seats[s].client < 0) seat = static_cast<std::int64_t>(s);
    }
    if (seat < 0) {
      reject(peer, connect.nonce, sp::RejectReason::full);
      return;
    }
    Client c;
    c.peer = peer;
    c.token = detail::secure_random_u64();
    c.nonce = connect.nonce;
    c.player = static_cast<std::uint32_t>(seat);
    c.last_heard_us = now_us;
    c.joined_frame = frame;
    c.ack = frame;
    c.last_update_frame = frame;
    c.input_ack = static_cast<std::uint32_t>(frame);
    c.ring.assign(ring_size * config.input_size, 0);
    c.ring_tag.assign(ring_size, -1);
    c.stats.player = c.player;
    c.stats.peer = peer;
    c.stats.connected = true;
    c.stats.joined_frame = frame;
    std::size_t slot = clients.size();  // the first slot a gone client left, or a new one
    for (std::size_t i = 0; i < clients.size() && slot == clients.size(); ++i)
      if (!clients[i].connected) slot = i;
    seats[static_cast<std::size_t>(seat)].client = static_cast<std::int64_t>(slot);
    seats[static_cast<std::size_t>(seat)].last_input.assign(config.input_size, 0);
    stats.connects += 1;
    events.push_back({ServerEventType::joined, c.player, frame, peer, "joined"});
    if (slot == clients.size()) {
      clients.push_back(std::move(c));
    } else {
      clients[slot] = std::move(c);
    }
    Client& added = clients[slot];
    welcome(added);
    // Joining a match under way: a snapshot of now (Authority::state sends its own).
    if (started && config.authority == sp::Authority::inputs) cut_snapshot(added, nullptr, 0);
  }

  void leave(Client& c, std::string_view reason) {
    c.connected = false;
    c.stats.connected = false;
    seats[c.player].client = -1;
    events.push_back({ServerEventType::left, c.player, frame, c.peer, reason});
    // Its statistics are kept (a bounded number of them), its buffers go, and its slot is the
    // next client's: clients that come and go for days cost a bounded amount of memory.
    if (gone.size() >= max_gone_clients) gone.pop_front();
    gone.push_back(c.stats);
    c.ring = {};
    c.ring_tag = {};
    c.snapshot = {};
  }

  /// Takes the inputs of `in` into c's ring. A datagram carrying an input beyond the window (no
  /// honest client runs that far ahead) is dropped whole, its acknowledgement and timing too.
  void take_inputs(Client& c, const sp::ClientInput& in) {
    const std::uint64_t newest_allowed = frame + config.input_window;
    if (in.count > 0 && std::uint64_t{in.start} + in.count - 1 > newest_allowed) {
      c.stats.packets_rejected += 1;
      return;
    }
    for (std::uint32_t k = 0; k < in.count; ++k) {
      const std::uint64_t tag = std::uint64_t{in.start} + k;
      // Before it joined, or already decided: a duplicate or a resend.
      if (tag < c.joined_frame || static_cast<std::int64_t>(tag) <= c.last_used_tag) continue;
      if (tag + late_window < frame) continue;  // too stale to use
      const std::size_t slot = static_cast<std::size_t>(tag % ring_size);
      c.ring_tag[slot] = static_cast<std::int64_t>(tag);
      std::copy_n(in.inputs.begin() + static_cast<std::ptrdiff_t>(k * config.input_size),
                  config.input_size,
                  c.ring.begin() + static_cast<std::ptrdiff_t>(slot * config.input_size));
    }
    if (in.count == 0) return;
    const std::uint64_t end = std::uint64_t{in.start} + in.count;
    if (in.start <= c.input_ack && end > c.input_ack) c.input_ack = static_cast<std::uint32_t>(end);
    const std::int64_t lead = static_cast<std::int64_t>(end) - 1 - static_cast<std::int64_t>(frame);
    c.lead = static_cast<std::int32_t>(std::clamp<std::int64_t>(lead, -128, 127));
    c.stats.lead = c.lead;
  }

  void handle_input(Client& c, const sp::ClientInput& in) {
    // An acknowledgement beyond what was sent is no honest client's: the whole datagram goes.
    if (in.ack > frame || in.ack < c.joined_frame ||
        (in.count > 0 && std::uint64_t{in.start} + in.count - 1 > frame + config.input_window)) {
      c.stats.packets_rejected += 1;
      return;
    }
    c.ack = std::max<std::uint64_t>(c.ack, in.ack);
    c.stats.acknowledged_frame = c.ack;
    c.echo_ms = in.time_ms;
    if (c.snapshot.pending && in.snapshot_ack == c.snapshot.frame + 1U) {
      c.snapshot.pending = false;
      c.ack = std::max<std::uint64_t>(c.ack, c.snapshot.frame);
    }
    // The newest snapshot it holds: its next one's base. Units go on from its own ack: a client
    // predicts with them, whatever state it holds.
    if (in.snapshot_ack > c.snapshot_ack && in.snapshot_ack <= frame + 1) {
      c.snapshot_ack = in.snapshot_ack;
      acknowledged_snapshot(c);
    }
    take_inputs(c, in);
  }

  void receive() {
    received.clear();
    transport->receive(received);
    sp::Packet p;
    for (const Datagram& d : received) {
      stats.bytes_received += d.bytes.size();
      const sp::DecodeError e = sp::decode(d.bytes, sizes(), p);
      Client* c = find(d.from);
      if (e != sp::DecodeError::none) {
        stats.dropped_malformed[static_cast<std::size_t>(e)] += 1;
        if (c != nullptr) c->stats.packets_rejected += 1;
        continue;
      }
      if (p.header.type == sp::PacketType::connect) {
        handle_connect(d.from, p.connect);
        continue;
      }
      if (c == nullptr || p.header.token != c->token) {
        stats.dropped_unknown += 1;
        if (c != nullptr) c->stats.packets_rejected += 1;
        continue;
      }
      c->last_heard_us = now_us;
      c->stats.packets_received += 1;
      c->stats.bytes_received += d.bytes.size();
      if (p.header.type == sp::PacketType::input) {
        handle_input(*c, p.input);
      } else if (p.header.type == sp::PacketType::leave) {
        stats.clients_left += 1;
        leave(*c, "left");
      } else {
        c->stats.packets_rejected += 1;  // a server's packet type, from a client
      }
    }
  }

  /// Seat s's input for frame f (its client's stamped input, or the last one again).
  void stamp(Seat& seat, std::uint64_t f, std::span<std::uint8_t> out) {
    Client& c = clients[static_cast<std::size_t>(seat.client)];
    const std::int64_t lowest = std::max<std::int64_t>(
        c.last_used_tag + 1, static_cast<std::int64_t>(f) - static_cast<std::int64_t>(late_window));
    for (std::int64_t tag = static_cast<std::int64_t>(f); tag >= lowest; --tag) {
      const std::size_t slot = static_cast<std::size_t>(tag) % ring_size;
      if (c.ring_tag[slot] != tag) continue;
      std::copy_n(c.ring.begin() + static_cast<std::ptrdiff_t>(slot * config.input_size),
                  config.input_size, seat.last_input.begin());
      if (tag < static_cast<std::int64_t>(f)) c.stats.inputs_late += 1;
      c.last_used_tag = tag;
      std::copy(seat.last_input.begin(), seat.last_input.end(), out.begin());
      return;
    }
    c.stats.inputs_missing += 1;
    std::copy(seat.last_input.begin(), seat.last_input.end(), out.begin());
  }

  void simulate() {
    std::fill(unit.begin(), unit.end(), std::uint8_t{0});
    for (std::size_t p = 0; p < seats.size(); ++p) {
      const std::span<std::uint8_t> input = std::span<std::uint8_t>(unit).subspan(
          mask_bytes + p * config.input_size, config.input_size);
      if (seats[p].client < 0) {
        unit[p / 8] |= static_cast<std::uint8_t>(1U << (p % 8));
        status[p] = InputStatus::disconnected;
      } else {
        stamp(seats[p], frame, input);
        status[p] = InputStatus::confirmed;
      }
    }
    const std::span<const std::uint8_t> inputs =
        std::span<const std::uint8_t>(unit).subspan(mask_bytes);
    game->advance(FrameInputs{frame, config.input_size, inputs, status}, false);
    state_hash = game->save(state);
    const std::span<std::uint8_t> slot = unit_at(frame);
    std::copy(unit.begin(), unit.end(), slot.begin());
    hash_at(frame + 1) = state_hash;
    if (listener) listener(ConfirmedFrame{frame, inputs, status, state_hash});
    frame += 1;
    stats.frames += 1;
    if (config.authority == sp::Authority::state && frame % config.snapshot_interval == 0) {
      if (snapshot_states.size() >= detail::kept_snapshot_states)
        snapshot_states.erase(snapshot_states.begin());
      snapshot_states.emplace_back(frame, state);
    }
  }

  [[nodiscard]] bool ended() const noexcept { return config.frames > 0 && frame >= config.frames; }

  std::uint32_t advance(std::uint64_t now, std::uint32_t max_frames) {
    now_us = std::max(now_us, now);
    if (!started) {
      if (connected_count() < config.start_clients) return 0;
      started = true;
      start_us = now_us;
      events.push_back({ServerEventType::started, 0, 0, 0, "started"});
    }
    std::uint32_t n = 0;
    while (n < max_frames && !ended() && start_us + frame * config.frame_us <= now_us) {
      stats.count_tick_lateness(now_us - (start_us + frame * config.frame_us));
      simulate();
      ++n;
    }
    return n;
  }

  void send_snapshot_slices(Client& c) {
    Outgoing& o = c.snapshot;
    if (now_us < o.rest_until_us) return;
    for (std::uint32_t k = 0; k < config.snapshot_burst; ++k) {
      sp::Packet p;
      p.header.type = sp::PacketType::snapshot;
      sp::SnapshotChunk& chunk = p.snapshot;
      chunk.frame = o.frame;
      chunk.base = o.base;
      chunk.hash = o.hash;
      chunk.total = static_cast<std::uint32_t>(o.bytes.size());
      chunk.offset = static_cast<std::uint32_t>(o.cursor);
      const std::size_t length = std::min(sp::max_snapshot_chunk, o.bytes.size() - o.cursor);
      chunk.data.assign(o.bytes.begin() + static_cast<std::ptrdiff_t>(o.cursor),
                        o.bytes.begin() + static_cast<std::ptrdiff_t>(o.cursor + length));
      send(c, p);
      c.stats.snapshot_bytes_sent += datagram.size();
      o.cursor += length;
      if (o.cursor >= o.bytes.size()) {
        o.cursor = 0;
        o.rest_until_us = now_us + snapshot_resend_us;
        return;
      }
    }
  }

  void send_update(Client& c) {
    sp::Packet p;
    p.header.type = sp::PacketType::update;
    sp::Update& u = p.update;
    u.frame = static_cast<std::uint32_t>(frame);
    u.input_ack = c.input_ack;
    u.lead = static_cast<std::int8_t>(c.lead);
    u.echo_ms = c.echo_ms;
    u.start = static_cast<std::uint32_t>(c.ack);
    std::uint64_t count = std::min<std::uint64_t>(frame - c.ack, sp::max_frames_per_packet);
    // As many units as one datagram holds: halve until it encodes.
    for (;;) {
      u.count = static_cast<std::uint8_t>(count);
      u.units.resize(static_cast<std::size_t>(count) * unit_bytes);
      for (std::uint64_t k = 0; k < count; ++k) {
        const std::span<const std::uint8_t> src = unit_at(c.ack + k);
        std::copy(src.begin(), src.end(),
                  u.units.begin() + static_cast<std::ptrdiff_t>(k * unit_bytes));
      }
      sp::chain(unit_before(c.ack), u.units);
      u.hash = count > 0 ? hash_at(c.ack + count) : 0;
      p.header.token = c.token;
      if (sp::encode(p, sizes(), datagram) || count == 0) break;
      count /= 2;
    }
    send(c, p);
    c.last_update_frame = frame;
  }

  /// The newest snapshot for seat `seat` against base frame + 1 `base` (0: full), encoded once a
  /// frame per seat and base: the whole state, or (ServerConfig::view) the seat's view of it.
  const Encoded& encoded_against(std::uint32_t seat, std::uint32_t base) {
    const auto& [snapshot_frame, snapshot] = snapshot_states.back();
    if (encoded_frame != snapshot_frame) {
      encoded.clear();
      encoded_frame = snapshot_frame;
    }
    if (!config.view) seat = sp::any_seat;
    for (const Encoded& e : encoded)
      if (e.seat == seat && e.base == base) return e;
    const std::vector<std::uint8_t>* base_state = nullptr;
    for (const auto& [f, st] : snapshot_states)
      if (base != 0 && f + 1 == base) base_state = &st;
    detail::ServerSnapshot s;
    s.frame = snapshot_frame;
    s.unit = unit_before(snapshot_frame);
    Encoded e{seat, base, hash_at(snapshot_frame), {}};
    if (config.view) {
      config.view(seat, snapshot, s.state);
      e.hash = hash_bytes(s.state);
      if (base_state != nullptr) {
        config.view(seat, *base_state, base_view_scratch);
        base_state = &base_view_scratch;
      }
    } else {
      s.state = snapshot;
    }
    e.bytes =
        detail::encode_server_snapshot(s, config.players, config.input_size, base_state, *game);
    encoded.push_back(std::move(e));
    return encoded.back();
  }

  /// Authority::state: the newest snapshot to `c`, against the newest it acknowledged (when the
  /// server still keeps that state), all its slices at once.
  /// Authority::state: the snapshots the client now holds are no longer awaited; the newest of
  /// them times the round trip.
  void acknowledged_snapshot(Client& c) {
    const std::uint32_t held = c.snapshot_ack - 1;
    std::size_t n = 0;
    for (; n < c.unacknowledged.size() && c.unacknowledged[n].first <= held; ++n) {
      if (c.unacknowledged[n].first != held) continue;
      const std::uint64_t sample = now_us - c.unacknowledged[n].second;
      c.snapshot_rtt_us = c.snapshot_rtt_us == 0 ? sample : (7 * c.snapshot_rtt_us + sample) / 8;
    }
    c.unacknowledged.erase(c.unacknowledged.begin(),
                           c.unacknowledged.begin() + static_cast<std::ptrdiff_t>(n));
  }

  /// Whether the server still keeps the snapshot state of frame `f`.
  [[nodiscard]] bool keeps_snapshot(std::uint64_t f) const {
    for (const auto& [kept, st] : snapshot_states)
      if (kept == f) return true;
    return false;
  }

  /// The base (its frame + 1; 0: none) of the snapshot of frame `next` to `c`. The newest one
  /// sent: the client holds it a round trip before it can say so, and a state one snapshot
  /// apart codes smaller than one a round trip apart. Unless a snapshot of the present chain is
  /// overdue (lost, so everything coded after it is undecodable), or no acknowledgement has timed
  /// the round trip yet: then the newest acknowledged one, and a new chain starts.
  std::uint32_t snapshot_base(Client& c, std::uint32_t next) {
    const std::uint64_t overdue_us = c.snapshot_rtt_us + c.snapshot_rtt_us / 4 + config.frame_us;
    bool chained = config.chain_snapshots && c.snapshot_rtt_us != 0 && !c.unacknowledged.empty() &&
                   c.unacknowledged.size() < detail::kept_snapshot_states &&
                   c.unacknowledged.back().first >= c.chain_from &&
                   keeps_snapshot(c.unacknowledged.back().first);
    for (const auto& [f, sent] : c.unacknowledged)
      chained = chained && (f < c.chain_from || now_us - sent <= overdue_us);
    if (chained) return c.unacknowledged.back().first + 1;
    c.chain_from = next;
    return c.snapshot_ack != 0 && keeps_snapshot(c.snapshot_ack - 1U) ? c.snapshot_ack : 0;
  }

  void send_state_snapshot(Client& c) {
    const std::uint64_t newest = snapshot_states.back().first;
    const std::uint32_t base = snapshot_base(c, static_cast<std::uint32_t>(newest));
    if (c.unacknowledged.size() >= 2 * detail::kept_snapshot_states)  // a client gone quiet
      c.unacknowledged.erase(c.unacknowledged.begin());
    c.unacknowledged.emplace_back(static_cast<std::uint32_t>(newest), now_us);
    Outgoing& o = c.snapshot;
    const Encoded& e = encoded_against(c.player, base);
    if (detail::is_game_delta(e.bytes)) c.stats.snapshots_game_coded += 1;
    if (base != 0 && base != c.snapshot_ack) c.stats.snapshots_chained += 1;
    o.frame = static_cast<std::uint32_t>(newest);
    o.base = base;
    o.hash = e.hash;
    o.bytes = e.bytes;
    o.cursor = 0;
    o.rest_until_us = 0;
    c.stats.snapshots_sent += 1;
    while (true) {
      send_snapshot_slices(c);
      if (o.cursor == 0) break;
    }
    c.last_snapshot_frame = newest + 1;
  }

  void send_due() {
    for (Client& c : clients) {
      if (!c.connected) continue;
      if (c.snapshot.pending) {
        send_snapshot_slices(c);
        continue;
      }
      const bool state_authority = config.authority == sp::Authority::state;
      if (state_authority && !snapshot_states.empty() &&
          c.last_snapshot_frame < snapshot_states.back().first + 1)
        send_state_snapshot(c);
      // A client so far behind that its next unit left the history: a snapshot instead (under
      // Authority::state, the next state snapshot).
      if (c.ack < oldest()) {
        if (state_authority) continue;
        cut_snapshot(c, nullptr, 0);
        send_snapshot_slices(c);
        continue;
      }
      const bool due = frame >= c.last_update_frame + config.update_interval ||
                       now_us >= c.last_sent_us + keepalive_us;
      if (due) send_update(c);
    }
  }

  void time_out() {
    for (Client& c : clients) {
      if (c.connected && now_us - c.last_heard_us > config.client_timeout_us) {
        stats.clients_timed_out += 1;
        leave(c, "silent");
      }
    }
  }

  void poll(std::uint64_t now) {
    now_us = std::max(now_us, now);
    receive();
    time_out();
    send_due();
  }
};

Expected<Server> Server::create(const ServerConfig& config, Game& game, Transport& transport) {
  if (Status s = check_server(config); !s.ok()) return s;
  if (Status s = detail::secure_random_ready(); !s.ok()) return s;
  return Server(std::make_unique<Impl>(config, game, transport));
}

Server::Server(std::unique_ptr<Impl> impl) noexcept : impl_(std::move(impl)) {}
Server::Server(Server&&) noexcept = default;
Server& Server::operator=(Server&&) noexcept = default;
Server::~Server() = default;

void Server::poll(std::uint64_t now_us) {
  impl_->poll(now_us);
}

std::uint32_t Server::advance(std::uint64_t now_us, std::uint32_t max_frames) {
  return impl_->advance(now_us, max_frames);
}

void Server::set_confirmed_listener(std::function<void(const ConfirmedFrame&)> listener) {
  impl_->listener = std::move(listener);
}

std::vector<ServerEvent> Server::take_events() {
  return std::exchange(impl_->events, {});
}

const ServerConfig& Server::config() const noexcept {
  return impl_->config;
}

std::uint64_t Server::current_frame() const noexcept {
  return impl_->frame;
}

std::uint64_t Server::current_hash() const noexcept {
  return impl_->state_hash;
}

bool Server::ended() const noexcept {
  return impl_->ended();
}

bool Server::settled() const noexcept {
  if (!impl_->ended()) return false;
  return std::all_of(impl_->clients.begin(), impl_->clients.end(), [&](const Impl::Client& c) {
    return !c.connected || (!c.snapshot.pending && c.ack >= impl_->frame);
  });
}

const ServerStats& Server::stats() const noexcept {
  return impl_->stats;
}

std::vector<ServerClientStats> Server::client_stats() const {
  std::vector<ServerClientStats> out(impl_->gone.begin(), impl_->gone.end());
  for (const Impl::Client& c : impl_->clients)
    if (c.connected) out.push_back(c.stats);
  return out;
}

}  // namespace detsim::net
