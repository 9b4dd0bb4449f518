// net::Client (client.hpp): prediction and exact reconciliation.
//
// Frames, all on the server's numbering:
//   verified <= authoritative (auth_end) and verified <= present
//   [verified, present): simulated; the state before each is kept (states), with the unit used
//   [.., auth_end): the server's units are known (known); frames before `verified` were compared
//   present: the game's state; the own inputs of [input_ack, present) are resent until acked
// On an update: its units join `known`; every simulated frame below auth_end is compared with
// the unit it used; the first that differs is where the game loads its state and re-simulates
// to the present (the server's units where known, predictions after). The server's hash of a
// state frame is compared once this client holds its own state of that frame.
#include <detsim/net/client.hpp>

#include <detsim/core/hash.hpp>
#include <detsim/fixed/math.hpp>

#include <algorithm>
#include <deque>
#include <optional>
#include <string>
#include <utility>

#include "secure_random.hpp"
#include "server_snapshot.hpp"

namespace detsim::net {

namespace sp = server_protocol;

namespace {

Status client_invalid(const std::string& field, const std::string& why) {
  return Status::error("ClientConfig: " + field + " " + why);
}

Status check_client(const ClientConfig& c) {
  if (c.max_prediction < 1 || c.max_prediction > 1000)
    return client_invalid("max_prediction",
                          "must be 1 .. 1000, got " + std::to_string(c.max_prediction));
  if (c.target_lead < 0 || c.target_lead > 30)
    return client_invalid("target_lead", "must be 0 .. 30, got " + std::to_string(c.target_lead));
  if (c.connect_interval_us == 0) return client_invalid("connect_interval_us", "must be above 0");
  if (c.keepalive_us == 0) return client_invalid("keepalive_us", "must be above 0");
  if (c.timeout_us == 0) return client_invalid("timeout_us", "must be above 0");
  if (static_cast<bool>(c.view) != static_cast<bool>(c.merge_view))
    return client_invalid("view", "and merge_view come together: both or neither");
  return Status::success();
}

}  // namespace

/// The most bytes of units a client logs for desync evidence (about 10 hours of an 8-player match
/// of 3-byte inputs at 60 Hz); beyond, it keeps playing without evidence.
constexpr std::size_t max_log_bytes = std::size_t{64} << 20;

namespace detail {

/// A ring of byte blocks of one size, by frame.
class FrameRing {
 public:
  void reset(std::size_t frames, std::size_t block) {
    block_ = block;
    bytes_.assign(frames * block, 0);
    frames_ = frames;
  }
  std::span<std::uint8_t> at(std::uint64_t frame) {
    return std::span<std::uint8_t>(bytes_).subspan(
        static_cast<std::size_t>(frame % frames_) * block_, block_);
  }

 private:
  std::vector<std::uint8_t> bytes_;
  std::size_t frames_ = 1;
  std::size_t block_ = 0;
};

}  // namespace detail

struct Client::Impl {
  enum class Phase : std::uint8_t { connecting, welcomed, waiting, running, failed };

  ClientConfig config;
  Transport* transport;
  Game* game = nullptr;
  Phase phase = Phase::connecting;
  std::uint64_t nonce = 0;
  std::uint64_t token = 0;
  sp::Welcome welcomed;
  bool has_welcome = false;
  sp::Sizes sizes;
  std::size_t unit_bytes = 0;
  std::size_t mask_bytes = 0;
  std::uint64_t now_us = 0;
  std::uint64_t last_connect_us = 0;
  bool connect_sent = false;
  std::uint64_t last_sent_us = 0;
  std::uint64_t last_heard_us = 0;
  std::uint16_t sequence = 0;

  // Frames (file comment).
  std::uint64_t present = 0;
  std::uint64_t verified = 0;
  std::uint64_t auth_end = 0;
  std::uint64_t base_frame = 0;  ///< the state frame it started from
  bool need_snapshot = false;    ///< it joined a match under way: it starts from a snapshot
  std::uint32_t input_ack = 0;
  std::size_t window = 0;  ///< ring sizes: max_prediction + 1 states, twice that units
  std::vector<std::vector<std::uint8_t>> states;  ///< by frame % window: the state before it
  std::vector<std::uint64_t> state_hashes;
  detail::FrameRing used;  ///< by frame: the unit simulated
  detail::FrameRing
      known;              ///< by frame: the server's unit (frames [auth_end - 2 window, auth_end))
  detail::FrameRing own;  ///< by frame: this client's input
  std::vector<std::uint8_t> base_unit;  ///< the unit of base_frame - 1
  // The server's hashes of state frames this client has not reached yet, oldest first.
  std::deque<std::pair<std::uint64_t, std::uint64_t>> checks;
  std::uint64_t server_hash = 0;
  std::uint64_t server_hash_frame = 0;
  // Evidence of the first desync (DesyncEvidence): the server's units of every frame from 0 (the
  // log, while it is whole: a client that joined late, or skipped frames, has none), and the
  // state of the last frame whose hash matched the server's.
  std::vector<std::uint8_t> log;
  bool log_whole = true;
  std::uint64_t agreed_frame = 0;
  std::vector<std::uint8_t> agreed_state;
  std::optional<DesyncEvidence> evidence;
  std::vector<std::uint8_t> initial_state;  ///< the game's state at frame 0
  // Time sync: the server's frame as its newest update told it, when that arrived, and the
  // smoothed round trip (7/8 old, 1/8 new, as TCP's).
  std::uint64_t server_frame = 0;
  std::uint64_t server_frame_at_us = 0;
  std::uint64_t smoothed_rtt_us = 0;
  std::uint64_t checked = 0;

  // The snapshot being assembled, and the newest one held whole (a delta's base).
  struct Assembly {
    bool active = false;
    std::uint32_t frame = 0;
    std::uint32_t base = 0;
    std::uint64_t hash = 0;
    std::vector<std::uint8_t> bytes;
    std::vector<bool> have;  ///< by slice
    std::size_t missing = 0;
  } assembly;
  std::uint32_t snapshot_ack = 0;
  /// The states of the newest snapshots held whole (frame, state), oldest first: the server
  /// codes each snapshot against the newest one it heard acknowledged, which may be older than
  /// this client's newest by a round trip.
  std::deque<std::pair<std::uint32_t, std::vector<std::uint8_t>>> snapshot_states;
  std::optional<detail::ServerSnapshot> ready;  ///< decoded this poll, applied after the updates

  std::vector<std::uint8_t> unit;  ///< scratch
  std::vector<std::uint8_t> view_scratch;
  std::vector<std::uint8_t> datagram;
  std::vector<Datagram> received;
  std::vector<InputStatus> status;
  std::vector<ClientEvent> events;
  ClientStats stats;
  std::string failure;

  Impl(const ClientConfig& c, Transport& t) : config(c), transport(&t) {}

  // --- sending ---------------------------------------------------------------------------------

  void send(sp::Packet& p) {
    p.header.token = token;
    p.header.sequence = sequence++;
    if (!sp::encode(p, sizes, datagram)) return;
    transport->send(config.server, datagram);
    last_sent_us = now_us;
    stats.packets_sent += 1;
    stats.bytes_sent += datagram.size();
  }

  void send_connect() {
    sp::Packet p;
    p.header.type = sp::PacketType::connect;
    p.connect = {config.game, nonce, config.seat};
    send(p);
    last_connect_us = now_us;
    connect_sent = true;
  }

  void send_inputs() {
    sp::Packet p;
    p.header.type = sp::PacketType::input;
    sp::ClientInput& in = p.input;
    in.ack = static_cast<std::uint32_t>(auth_end);
    in.snapshot_ack = snapshot_ack;
    in.time_ms = static_cast<std::uint32_t>(now_us / 1000);
    const std::uint64_t first =
        std::max<std::uint64_t>(input_ack, present > window ? present - window + 1 : 0);
    const std::uint64_t count =
        present > first ? std::min<std::uint64_t>(present - first, sp::max_frames_per_packet) : 0;
    in.start = static_cast<std::uint32_t>(first);
    in.count = static_cast<std::uint8_t>(count);
    in.inputs.clear();
    for (std::uint64_t f = first; f < first + count; ++f) {
      const std::span<const std::uint8_t> i = own.at(f);
      in.inputs.insert(in.inputs.end(), i.begin(), i.end());
    }
    send(p);
  }

  // --- units -----------------------------------------------------------------------------------

  [[nodiscard]] std::uint32_t player() const noexcept { return welcomed.player; }

  /// The server's unit of frame f - 1 for f = auth_end: the newest known (or the base unit).
  std::span<const std::uint8_t> newest_known() {
    if (auth_end == base_frame) return base_unit;
    return known.at(auth_end - 1);
  }

  /// The unit this client predicts for frame f >= auth_end: the newest known one, with its own
  /// input (and its seat present).
  void predict(std::uint64_t f, std::span<std::uint8_t> out) {
    const std::span<const std::uint8_t> last = newest_known();
    std::copy(last.begin(), last.end(), out.begin());
    out[player() / 8] = static_cast<std::uint8_t>(out[player() / 8] & ~(1U << (player() % 8)));
    const std::span<const std::uint8_t> mine = own.at(f);
    std::copy(mine.begin(), mine.end(),
              out.begin() + static_cast<std::ptrdiff_t>(mask_bytes + player() * sizes.input_size));
  }

  /// The unit to simulate frame f with: the server's when known, else the prediction.
  void unit_for(std::uint64_t f, std::span<std::uint8_t> out) {
    if (f < auth_end) {
      const std::span<const std::uint8_t> k = known.at(f);
      std::copy(k.begin(), k.end(), out.begin());
    } else {
      predict(f, out);
    }
  }

  /// Simulates frame `present` with `u`, saving the state before it (and checking the server's
  /// hash of it, when one is waiting).
  void simulate(std::span<const std::uint8_t> u, bool resimulating) {
    const std::size_t slot = static_cast<std::size_t>(present % window);
    state_hashes[slot] = game->save(states[slot]);
    std::copy(u.begin(), u.end(), used.at(present).begin());
    for (std::size_t p = 0; p < sizes.players; ++p)
      status[p] = (u[p / 8] >> (p % 8)) & 1U ? InputStatus::disconnected : InputStatus::confirmed;
    game->advance(FrameInputs{present, sizes.input_size, u.subspan(mask_bytes), status},
                  resimulating);
    present += 1;
    if (verified + 1 == present && verified < auth_end) verified = present;
  }

  /// Re-simulates from frame m (its state is kept) to the present.
  void rewind_to(std::uint64_t m) {
    const std::uint64_t end = present;
    game->load(states[static_cast<std::size_t>(m % window)]);
    present = m;
    verified = std::min(verified, m);
    stats.corrections += 1;
    while (present < end) {
      unit_for(present, unit);
      simulate(unit, true);
      stats.resimulated_frames += 1;
    }
  }

  void handle_update(const sp::Update& u) {
    input_ack = std::max(input_ack,
                         std::min<std::uint32_t>(u.input_ack, static_cast<std::uint32_t>(present)));
    stats.lead = u.lead;
    const std::uint64_t now_ms = now_us / 1000;
    if (u.echo_ms != 0 && now_ms >= u.echo_ms && now_ms - u.echo_ms < 10'000) {
      stats.rtt_ms = now_ms - u.echo_ms;
      const std::uint64_t sample = stats.rtt_ms * 1000;
      smoothed_rtt_us = smoothed_rtt_us == 0 ? sample : (7 * smoothed_rtt_us + sample) / 8;
    }
    if (u.frame >= server_frame) {
      server_frame = u.frame;
      server_frame_at_us = now_us;
    }
    if (phase == Phase::waiting && !need_snapshot && u.start == 0 && u.count > 0) {
      phase = Phase::running;  // the match's first frames: it plays from the game's start
      events.push_back({ClientEventType::running, 0, 0, 0, "start"});
    }
    if (phase != Phase::running || u.count == 0) return;
    // Units follow on from what it holds (start == auth_end), or overlap it by a resend.
    if (u.start > auth_end || u.start < base_frame) {
      stats.dropped += 1;
      return;
    }
    if (u.start + std::uint64_t{u.count} <= auth_end) return;  // nothing new
    if (auth_end - u.start >= 2 * window) return;
    std::vector<std::uint8_t> units = u.units;
    std::vector<std::uint8_t> reference(unit_bytes);
    const std::span<const std::uint8_t> r =
        u.start == base_frame ? std::span<const std::uint8_t>(base_unit) : known.at(u.start - 1);
    std::copy(r.begin(), r.end(), reference.begin());
    sp::unchain(reference, units);
    // New units up to the most a ring holds beyond what is checked.
    const std::uint64_t end =
        std::min<std::uint64_t>(u.start + std::uint64_t{u.count}, verified + window);
    for (std::uint64_t f = auth_end; f < end; ++f) {
      const std::span<const std::uint8_t> src = std::span<const std::uint8_t>(units).subspan(
          static_cast<std::size_t>(f - u.start) * unit_bytes, unit_bytes);
      std::copy(src.begin(), src.end(), known.at(f).begin());
      if (log_whole && log.size() + unit_bytes <= max_log_bytes) {
        log.insert(log.end(), src.begin(), src.end());
      } else {
        log_whole = false;
      }
    }
    if (end <= auth_end) return;
    auth_end = end;
    if (end == u.start + std::uint64_t{u.count}) {
      checks.emplace_back(end, u.hash);
      server_hash = u.hash;
      server_hash_frame = end;
    }
    // Compare every simulated frame the server's units now cover.
    const std::uint64_t covered = std::min(auth_end, present);
    std::optional<std::uint64_t> first_wrong;
    for (std::uint64_t f = verified; f < covered; ++f) {
      const std::span<const std::uint8_t> a = used.at(f);
      const std::span<const std::uint8_t> b = known.at(f);
      if (!std::equal(a.begin(), a.end(), b.begin())) {
        stats.mispredictions += 1;
        if (!first_wrong) first_wrong = f;
      }
    }
    if (first_wrong) rewind_to(*first_wrong);
    verified = std::max(verified, covered);
    check_current();
  }

  /// Checks waiting for state frames up to the present, against the states kept (and the
  /// present's, saved for it).
  void check_current() {
    while (!checks.empty()) {
      const auto [frame, hash] = checks.front();
      if (frame > verified) return;  // not simulated with the server's units yet
      std::uint64_t mine = 0;
      if (frame == present) {
        std::vector<std::uint8_t>& slot = states[static_cast<std::size_t>(present % window)];
        mine = game->save(slot);
        state_hashes[static_cast<std::size_t>(present % window)] = mine;
      } else if (frame + window > present) {
        mine = state_hashes[static_cast<std::size_t>(frame % window)];
      } else {
        checks.pop_front();  // long gone: not compared
        continue;
      }
      checks.pop_front();
      checked = std::max(checked, frame);
      if (mine == hash) {
        passed(frame);
      } else {
        diverged(frame, mine, hash);
      }
    }
  }

  /// The server's hash of state frame `frame` matched this client's (kept in the ring).
  void passed(std::uint64_t frame) {
    stats.checks_passed += 1;
    if (evidence || !log_whole) return;
    agreed_frame = frame;
    agreed_state = states[static_cast<std::size_t>(frame % window)];
  }

  /// It did not, with every input before it right: a desync; the first one's evidence is kept
  /// (for a desync report: both states, and every frame's units before it).
  void diverged(std::uint64_t frame, std::uint64_t mine, std::uint64_t theirs) {
    stats.desyncs += 1;
    events.push_back({ClientEventType::desync, frame, mine, theirs, "desync"});
    // The report's frames carry one byte of absent players: 8 seats at most.
    if (evidence || !log_whole || sizes.players > 8 || log.size() < frame * unit_bytes) return;
    DesyncEvidence e;
    e.player = static_cast<std::uint32_t>(sizes.players);  // the server: no seat of its own
    e.agreed_frame = agreed_frame;
    e.agreed_state = agreed_frame == 0 && agreed_state.empty() ? initial_state : agreed_state;
    e.divergent_frame = frame;
    e.divergent_state = states[static_cast<std::size_t>(frame % window)];
    e.local_hash = mine;
    e.remote_hash = theirs;
    e.confirmed_frames.assign(log.begin(),
                              log.begin() + static_cast<std::ptrdiff_t>(frame * unit_bytes));
    evidence = std::move(e);
  }

  // --- snapshots -------------------------------------------------------------------------------

  void handle_chunk(const sp::SnapshotChunk& c) {
    Assembly& a = assembly;
    if (c.frame + 1U <= snapshot_ack) return;  // one it holds, or older
    if (!a.active || c.frame > a.frame || (c.frame == a.frame && c.total != a.bytes.size())) {
      if (a.active && c.frame < a.frame) return;
      a.active = true;
      a.frame = c.frame;
      a.base = c.base;
      a.hash = c.hash;
      a.bytes.assign(c.total, 0);
      const std::size_t slices = (c.total + sp::max_snapshot_chunk - 1) / sp::max_snapshot_chunk;
      a.have.assign(slices, false);
      a.missing = slices;
    } else if (c.frame < a.frame) {
      return;
    }
    if (c.offset % sp::max_snapshot_chunk != 0 || c.base != a.base) {
      stats.dropped += 1;
      return;
    }
    const std::size_t slice = c.offset / sp::max_snapshot_chunk;
    if (slice >= a.have.size() || a.have[slice]) return;
    std::copy(c.data.begin(), c.data.end(),
              a.bytes.begin() + static_cast<std::ptrdiff_t>(c.offset));
    a.have[slice] = true;
    a.missing -= 1;
    if (a.missing > 0) return;
    a.active = false;
    stats.snapshot_bytes_received += a.bytes.size();
    const std::vector<std::uint8_t>* base = nullptr;
    if (a.base != 0) {
      for (const auto& [frame, state] : snapshot_states)
        if (frame + 1U == a.base) base = &state;
      if (base == nullptr) {  // against a state this client no longer holds
        stats.dropped += 1;
        return;
      }
    }
    Expected<detail::ServerSnapshot> s =
        detail::decode_server_snapshot(a.bytes, static_cast<std::uint32_t>(sizes.players),
                                       static_cast<std::uint32_t>(sizes.input_size), base, *game);
    if (!s || s->frame != a.frame) {
      stats.dropped += 1;
      return;
    }
    stats.snapshots_received += 1;
    if (snapshot_states.size() >= detail::kept_snapshot_states) snapshot_states.pop_front();
    snapshot_states.emplace_back(a.frame, s->state);
    snapshot_ack = a.frame + 1;
    ready = std::move(*s);
    ready_hash = a.hash;
  }
  std::uint64_t ready_hash = 0;

  /// Plays from a snapshot: the game takes its state, and frames from there on are predicted.
  /// What this client loads of a server snapshot's state, given its own state `own`: the
  /// server's whole state, or (a view: ClientConfig::view) its own with the server's view put in.
  std::vector<std::uint8_t> to_load(const std::vector<std::uint8_t>& from_server,
                                    std::vector<std::uint8_t> own_state) const {
    if (!config.merge_view) return from_server;
    config.merge_view(from_server, own_state);
    return own_state;
  }

  /// What a server snapshot's hash covers, of this client's own state `state` (whose Game::save
  /// hash is `hash`): the whole state, or this seat's view of it.
  std::uint64_t snapshot_hash_of(std::span<const std::uint8_t> state, std::uint64_t hash) {
    if (!config.view) return hash;
    config.view(player(), state, view_scratch);
    return hash_bytes(view_scratch);
  }

  void start_from(const detail::ServerSnapshot& s) {
    log_whole = s.frame == 0;  // a late joiner holds no units of the frames before it
    // A view goes into the game's state at frame 0 (what else a late joiner has is the game's).
    game->load(to_load(s.state, initial_state));
    present = s.frame;
    verified = s.frame;
    auth_end = s.frame;
    base_frame = s.frame;
    base_unit = s.unit;
    input_ack = std::max<std::uint32_t>(input_ack, static_cast<std::uint32_t>(s.frame));
    checks.clear();
  }

  /// A snapshot decoded this poll: the start of play, or (Authority::state) the server's state
  /// to compare with, and to load when they differ.
  void apply_snapshot() {
    if (!ready) return;
    detail::ServerSnapshot s = std::move(*ready);
    ready.reset();
    std::vector<std::uint8_t> scratch;
    if (phase == Phase::waiting) {
      start_from(s);
      const std::uint64_t saved = game->save(scratch);
      if (snapshot_hash_of(scratch, saved) != ready_hash) {
        fail("the server's snapshot does not load to its hash here");
        return;
      }
      phase = Phase::running;
      events.push_back({ClientEventType::running, s.frame, 0, 0, "snapshot"});
      return;
    }
    if (phase != Phase::running) return;
    if (s.frame > present) {
      // The server is ahead of this client: its state is simply the one to go on from (frames
      // this client never simulated were never predicted).
      game->save(scratch);
      game->load(to_load(s.state, scratch));
      present = s.frame;
      verified = s.frame;
      if (auth_end < s.frame) {
        log_whole = false;  // frames it never had the units of
        auth_end = s.frame;
        base_frame = s.frame;
        base_unit = s.unit;
      }
      while (!checks.empty() && checks.front().first < s.frame)
        checks.pop_front();
      return;
    }
    if (s.frame + window <= present) return;  // too old to compare
    const std::size_t slot = static_cast<std::size_t>(s.frame % window);
    if (s.frame == present) state_hashes[slot] = game->save(states[slot]);
    const std::uint64_t mine = snapshot_hash_of(states[slot], state_hashes[slot]);
    if (mine == ready_hash) {
      passed(s.frame);
      return;
    }
    // Differs. With every input before it right, that is a desync; else a misprediction the
    // server's units have not told yet. Either way the server's state is the one.
    if (s.frame <= verified) diverged(s.frame, mine, ready_hash);
    const std::uint64_t end = present;
    game->load(to_load(s.state, states[slot]));
    state_hashes[slot] = game->save(states[slot]);
    present = s.frame;
    verified = std::min(verified, s.frame);
    stats.corrections += 1;
    while (present < end) {
      unit_for(present, unit);
      simulate(unit, true);
      stats.resimulated_frames += 1;
    }
  }

  // --- receiving -------------------------------------------------------------------------------

  void fail(const char* why) {
    phase = Phase::failed;
    failure = why;
  }

  void handle_welcome(const sp::Packet& p) {
    if (phase != Phase::connecting || p.welcome.nonce != nonce) {
      stats.dropped += 1;
      return;
    }
    welcomed = p.welcome;
    has_welcome = true;
    token = p.header.token;
    sizes = {welcomed.players, welcomed.input_size};
    unit_bytes = sp::unit_size(sizes.players, sizes.input_size);
    mask_bytes = (sizes.players + 7) / 8;
    window = std::size_t{config.max_prediction} + 1;
    states.assign(window, {});
    state_hashes.assign(window, 0);
    used.reset(window, unit_bytes);
    known.reset(2 * window, unit_bytes);
    own.reset(window, sizes.input_size);
    unit.assign(unit_bytes, 0);
    status.assign(sizes.players, InputStatus::confirmed);
    phase = Phase::welcomed;
    events.push_back({ClientEventType::welcomed, welcomed.start_frame, 0, 0, "welcomed"});
  }

  void receive() {
    received.clear();
    transport->receive(received);
    sp::Packet p;
    for (const Datagram& d : received) {
      if (d.from != config.server) {
        stats.dropped += 1;
        continue;
      }
      if (sp::decode(d.bytes, sizes, p) != sp::DecodeError::none) {
        stats.dropped += 1;
        continue;
      }
      const bool handshake =
          p.header.type == sp::PacketType::welcome || p.header.type == sp::PacketType::reject;
      if (!handshake && (phase == Phase::connecting || p.header.token != token)) {
        stats.dropped += 1;
        continue;
      }
      stats.packets_received += 1;
      stats.bytes_received += d.bytes.size();
      last_heard_us = now_us;
      switch (p.header.type) {
        case sp::PacketType::welcome:
          handle_welcome(p);
          break;
        case sp::PacketType::reject:
          if (phase == Phase::connecting && p.reject.nonce == nonce) {
            events.push_back({ClientEventType::rejected, 0, 0, 0, reject_reason(p.reject.reason)});
            fail(reject_reason(p.reject.reason));
          }
          break;
        case sp::PacketType::update:
          handle_update(p.update);
          break;
        case sp::PacketType::snapshot:
          if ((phase == Phase::waiting && need_snapshot) || phase == Phase::running)
            handle_chunk(p.snapshot);
          break;
        default:
          stats.dropped += 1;
      }
    }
    apply_snapshot();
  }

  static const char* reject_reason(sp::RejectReason r) noexcept {
    switch (r) {
      case sp::RejectReason::wrong_game:
        return "the server runs another game";
      case sp::RejectReason::full:
        return "the server has no free seat";
      case sp::RejectReason::ended:
        return "the match is over";
    }
    return "rejected";
  }

  void poll(std::uint64_t now) {
    now_us = std::max(now_us, now);
    if (phase == Phase::failed) return;
    receive();
    if (phase == Phase::failed) return;
    if (phase == Phase::connecting) {
      if (!connect_sent || now_us >= last_connect_us + config.connect_interval_us) send_connect();
      return;
    }
    if (now_us > last_heard_us + config.timeout_us) {
      events.push_back({ClientEventType::server_lost, present, 0, 0, "server silent"});
      fail("the server has been silent");
      return;
    }
    if (now_us >= last_sent_us + config.keepalive_us) send_inputs();
  }

  Status start(Game& g) {
    if (phase != Phase::welcomed) return Status::error("Client::start: not welcomed (or started)");
    const std::uint64_t hash = g.save(initial_state);
    if (hash != welcomed.initial_hash)
      return Status::error("Client::start: this game's initial state hashes " +
                           std::to_string(hash) + ", the server's " +
                           std::to_string(welcomed.initial_hash) + ": not the same game");
    game = &g;
    // It waits for the match's first frames (a match not started yet: who is present at frame 0
    // is the server's word, not a guess) or for a snapshot of now (a match under way).
    phase = Phase::waiting;
    need_snapshot = welcomed.start_frame > 0;
    base_frame = welcomed.start_frame;
    auth_end = welcomed.start_frame;
    present = welcomed.start_frame;
    verified = welcomed.start_frame;
    base_unit.assign(unit_bytes, 0);
    for (std::size_t p = 0; p < sizes.players; ++p)
      base_unit[p / 8] |= static_cast<std::uint8_t>(1U << (p % 8));
    input_ack = welcomed.start_frame;
    send_inputs();
    return Status::success();
  }

  Expected<Advance> advance_frame(std::span<const std::uint8_t> input) {
    if (game == nullptr) return Status::error("Client::advance_frame: start() first");
    if (input.size() != sizes.input_size)
      return Status::error("Client::advance_frame: the input has " + std::to_string(input.size()) +
                           " bytes, the match " + std::to_string(sizes.input_size));
    if (phase != Phase::running) return Advance::synchronizing;
    if (welcomed.frames > 0 && present >= welcomed.frames) {
      send_inputs();  // the acknowledgements the server waits for
      return Advance::waiting_for_inputs;
    }
    if (present >= verified + config.max_prediction) {
      stats.prediction_limit_waits += 1;
      send_inputs();
      return Advance::prediction_limit;
    }
    std::copy(input.begin(), input.end(), own.at(present).begin());
    unit_for(present, unit);
    simulate(unit, false);
    stats.frames += 1;
    check_current();
    send_inputs();
    return Advance::advanced;
  }
};

Expected<Client> Client::create(const ClientConfig& config, Transport& transport) {
  if (Status s = check_client(config); !s.ok()) return s;
  if (Status s = detail::secure_random_ready(); !s.ok()) return s;
  auto impl = std::make_unique<Impl>(config, transport);
  impl->nonce = detail::secure_random_u64();
  return Client(std::move(impl));
}

Client::Client(std::unique_ptr<Impl> impl) noexcept : impl_(std::move(impl)) {}
Client::Client(Client&&) noexcept = default;
Client& Client::operator=(Client&&) noexcept = default;
Client::~Client() = default;

void Client::poll(std::uint64_t now_us) {
  impl_->poll(now_us);
}

const server_protocol::Welcome* Client::welcome() const noexcept {
  return impl_->has_welcome ? &impl_->welcomed : nullptr;
}

Status Client::start(Game& game) {
  return impl_->start(game);
}

bool Client::started() const noexcept {
  return impl_->game != nullptr;
}

bool Client::ended() const noexcept {
  const Impl& i = *impl_;
  return i.phase == Impl::Phase::running && i.welcomed.frames > 0 &&
         i.present >= i.welcomed.frames && i.verified >= i.welcomed.frames &&
         i.checked >= i.welcomed.frames;
}

bool Client::running() const noexcept {
  return impl_->phase == Impl::Phase::running;
}

Expected<Advance> Client::advance_frame(std::span<const std::uint8_t> local_input) {
  return impl_->advance_frame(local_input);
}

std::int32_t Client::recommended_frame_adjust() const noexcept {
  const Impl& i = *impl_;
  if (i.phase != Impl::Phase::running) return 0;
  // Behind the server's own word: catch up at once.
  if (i.auth_end > i.present) return static_cast<std::int32_t>(i.auth_end - i.present) + 1;
  if (i.server_frame_at_us == 0) return i.config.target_lead - i.stats.lead;
  // Where an input sent now lands: the server's frame now (its last word, half a round trip
  // old when it arrived, plus the time since) plus half a round trip more. The client keeps its
  // present target_lead frames beyond that. Measured from the server's own frame counter, not
  // from its word on how early the inputs came (which is a round trip late, and oscillates).
  const std::uint64_t frame_us = i.welcomed.frame_us;
  const std::uint64_t ahead_us = i.smoothed_rtt_us + (i.now_us - i.server_frame_at_us);
  const std::uint64_t lands = i.server_frame + (ahead_us + frame_us - 1) / frame_us;
  const std::int64_t lead = static_cast<std::int64_t>(i.present) - static_cast<std::int64_t>(lands);
  return static_cast<std::int32_t>(
      std::clamp<std::int64_t>(std::int64_t{i.config.target_lead} - lead, -30, 30));
}

void Client::leave() {
  sp::Packet p;
  p.header.type = sp::PacketType::leave;
  impl_->send(p);
}

std::uint64_t Client::current_frame() const noexcept {
  return impl_->present;
}

std::uint64_t Client::authoritative_frame() const noexcept {
  return impl_->auth_end;
}

std::uint64_t Client::server_hash() const noexcept {
  return impl_->server_hash;
}

std::uint64_t Client::server_hash_frame() const noexcept {
  return impl_->server_hash_frame;
}

std::uint64_t Client::checked_frame() const noexcept {
  return impl_->checked;
}

const ClientStats& Client::stats() const noexcept {
  return impl_->stats;
}

std::vector<ClientEvent> Client::take_events() {
  return std::exchange(impl_->events, {});
}

const DesyncEvidence* Client::desync_evidence() const noexcept {
  return impl_->evidence ? &*impl_->evidence : nullptr;
}

std::string_view Client::failure() const noexcept {
  return impl_->failure;
}

CorrectionSmoother::CorrectionSmoother(Fixed half_life_frames) noexcept
    : keep_(half_life_frames > Fixed::zero() ? exp2(-(Fixed::one() / half_life_frames))
                                             : Fixed::zero()) {}

}  // namespace detsim::net
