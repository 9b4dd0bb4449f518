// The session's frame loop: local inputs, prediction, rollback, confirmed frames and desync checks.
// The network side (handshake, packets, timers) is session_wire.cpp.
//
// Frame numbering: the game's state is "at frame F" after F steps; step F turns state F into
// F + 1 using every player's input for frame F. After each step the session saves state F + 1 in a
// ring of 2 * max_prediction + emission_slack states, and waits rather than outgrow it, so the
// oldest frame a correction or a disconnect can reach is always held.
#include <algorithm>
#include <string>

#include <detsim/core/assert.hpp>

#include "secure_random.hpp"
#include "session_impl.hpp"

namespace detsim::net {
namespace {

using detail::max_input_delay;
using detail::max_prediction_limit;
using detail::never;
constexpr std::uint32_t max_players = 8;

Status validate(const SessionConfig& c) {
  const auto bad = [](const std::string& what) { return Status::error("session config: " + what); };
  if (c.players < 1 || c.players > max_players)
    return bad("players must be 1 .. 8, got " + std::to_string(c.players));
  if (c.partition != PartitionPolicy::end_match && c.partition != PartitionPolicy::play_on &&
      c.partition != PartitionPolicy::pause)
    return bad("partition must be end_match, play_on or pause, got " +
               std::to_string(static_cast<unsigned>(c.partition)));
  if (c.rejoin && c.players < 2)
    return bad("rejoin needs a match of two or more players (this one has 1)");
  if (c.rejoin_replays_match && !c.rejoin)
    return bad("rejoin_replays_match is for a rejoining session (set rejoin too)");
  if (c.rejoin && !c.spectators.empty())
    return bad("a rejoining session serves no spectators (they followed the earlier one)");
  if (!c.open_seats.empty() && c.rejoin)
    return bad("open_seats: a joining session (rejoin) takes a seat, it opens none");
  for (std::size_t i = 0; i < c.open_seats.size(); ++i) {
    const std::uint32_t p = c.open_seats[i];
    if (p >= c.players || p == c.local_player ||
        std::find(c.open_seats.begin(), c.open_seats.begin() + static_cast<std::ptrdiff_t>(i), p) !=
            c.open_seats.begin() + static_cast<std::ptrdiff_t>(i))
      return bad("open_seats: player " + std::to_string(p) +
                 " is out of range, this machine's own, or listed twice");
  }
  if (c.local_player >= c.players)
    return bad("local_player must be below players (" + std::to_string(c.players) + "), got " +
               std::to_string(c.local_player));
  if (c.input_size < 1 || c.input_size > protocol::max_input_size)
    return bad("input_size must be 1 .. 64 bytes, got " + std::to_string(c.input_size));
  if (c.input_delay > max_input_delay)
    return bad("input_delay must be 0 .. 16 frames, got " + std::to_string(c.input_delay));
  if (c.mode == SessionMode::rollback &&
      (c.max_prediction < 1 || c.max_prediction > max_prediction_limit))
    return bad("max_prediction must be 1 .. 32 frames in rollback mode, got " +
               std::to_string(c.max_prediction));
  if (c.frame_us < 1000 || c.frame_us > 1'000'000)
    return bad("frame_us must be 1000 .. 1000000, got " + std::to_string(c.frame_us));
  if (c.hello_interval_us == 0 || c.keepalive_us == 0 || c.ping_interval_us == 0)
    return bad("hello_interval_us, keepalive_us and ping_interval_us must be > 0");
  if (c.disconnect_warning_us == 0 || c.disconnect_timeout_us <= c.disconnect_warning_us)
    return bad("disconnect_timeout_us must exceed disconnect_warning_us, which must be > 0");
  if (c.progress_timeout_us <= c.disconnect_timeout_us)
    return bad("progress_timeout_us must exceed disconnect_timeout_us");
  if (c.remotes.size() != c.players - 1)
    return bad("remotes must list every other player once: expected " +
               std::to_string(c.players - 1) + ", got " + std::to_string(c.remotes.size()));
  std::vector<bool> seen(c.players, false);
  seen[c.local_player] = true;
  std::vector<PeerId> ids;
  for (const RemotePlayer& r : c.remotes) {
    if (r.player >= c.players || seen[r.player])
      return bad("remotes: player " + std::to_string(r.player) +
                 " is out of range, local, or listed twice");
    seen[r.player] = true;
    ids.push_back(r.peer);
  }
  if (c.spectators.size() > 16)
    return bad("at most 16 spectators, got " + std::to_string(c.spectators.size()));
  ids.insert(ids.end(), c.spectators.begin(), c.spectators.end());
  std::sort(ids.begin(), ids.end());
  if (std::adjacent_find(ids.begin(), ids.end()) != ids.end())
    return bad("remotes and spectators: two share one peer id");
  return Status::success();
}

}  // namespace

Session::Impl::Impl(const SessionConfig& c, Game& g, Transport& t)
    : config(c),
      game(&g),
      transport(&t),
      max_prediction(c.mode == SessionMode::lockstep ? 0 : c.max_prediction),
      session_id(detail::secure_random_u64()) {
  if (c.match_key) protection.emplace(*c.match_key, session_id);
  for (std::uint32_t p = 0; p < c.players; ++p)
    queues.emplace_back(c.input_size, detail::input_capacity);
  disconnect_frame.assign(c.players, never);
  absent_from.assign(c.players, 0);
  absent_until.assign(c.players, 0);
  for (const std::uint32_t p : c.open_seats)
    disconnect_frame[p] = 0;  // away from the start, until a session of theirs joins
  std::vector<RemotePlayer> remotes = c.remotes;
  std::sort(remotes.begin(), remotes.end(),
            [](const RemotePlayer& a, const RemotePlayer& b) { return a.player < b.player; });
  for (const RemotePlayer& r : remotes) {
    detail::Peer peer;
    peer.player = r.player;
    peer.reported_gone.assign(c.players, never);
    peer.id = r.peer;
    peer.challenge = detail::secure_random_u64();
    peer.stats.player = r.player;
    peers.push_back(std::move(peer));
  }
  for (std::size_t k = 0; k < c.spectators.size(); ++k) {
    detail::Peer spectator;
    spectator.player = c.players + static_cast<std::uint32_t>(k);
    spectator.spectator = true;
    spectator.id = c.spectators[k];
    spectator.challenge = detail::secure_random_u64();
    spectator.stats.player = spectator.player;
    spectators.push_back(std::move(spectator));
  }
  unit_size = 1 + std::size_t{c.players} * c.input_size;
  states.resize(2U * max_prediction + detail::emission_slack);
  frame_inputs.resize(std::size_t{c.players} * c.input_size);
  frame_status.resize(c.players);
  scratch_input.resize(c.input_size);
  // Nobody to wait for: no peers, or only open seats.
  running = std::all_of(peers.begin(), peers.end(), [&](const detail::Peer& peer) {
    return disconnect_frame[peer.player] == 0;
  });
  detail::State& zero = state_slot(0);
  zero.frame = 0;
  zero.hash = game->save(zero.bytes);
  agreed_state = zero.bytes;  // every peer starts from the same state (the fingerprint says so)
  awaiting_state = c.rejoin;  // the match's state comes from a peer instead
}

bool Session::Impl::gone_final(std::uint32_t player) const noexcept {
  for (const detail::Peer& peer : peers) {
    if (!seated(peer)) continue;
    if (peer.reported_gone[player] != disconnect_frame[player]) return false;
  }
  return true;
}

std::uint64_t Session::Impl::confirmed_frame() const noexcept {
  std::uint64_t frame = never;
  for (std::uint32_t p = 0; p < config.players; ++p) {
    if (disconnect_frame[p] == never) {
      frame = std::min(frame, queues[p].next_confirmed());
    } else if (!gone_final(p)) {
      frame = std::min(frame, disconnect_frame[p]);  // peers may still move it earlier
    }
  }
  return frame == never ? current : frame;
}

std::uint64_t Session::Impl::emit_limit() const noexcept {
  std::uint64_t limit =
      std::min({confirmed_frame(), current, first_incorrect.value_or(detail::never)});
  for (const detail::Peer& peer : peers)
    if (seated(peer)) limit = std::min(limit, peer.reported_held);
  return limit;
}

std::uint64_t Session::Impl::window_start() const noexcept {
  const std::uint64_t oldest = std::min(next_emit, current);
  return oldest == 0 ? 0 : oldest - 1;
}

void Session::Impl::add_local_input(std::span<const std::uint8_t> input) {
  detail::InputQueue& q = queues[config.local_player];
  const std::uint64_t target = current + config.input_delay;
  if (target < q.next_confirmed()) {
    ++stats.dropped_inputs;  // the delay shrank: this frame already has an input
    return;
  }
  while (q.next_confirmed() <= target)
    q.confirm(input);  // fills the gap when the delay grew
}

void Session::Impl::simulate(std::uint64_t frame, bool resimulating) {
  const std::size_t size = config.input_size;
  for (std::uint32_t p = 0; p < config.players; ++p) {
    detail::InputQueue& q = queues[p];
    std::span<const std::uint8_t> input;
    if (gone_at(p, frame)) {
      // Zero, and recorded as what the frame used: an input that arrives for it after the
      // player is taken back (session_rejoin.cpp) is compared with what was simulated.
      const std::span<std::uint8_t> used = q.used_mut(frame);
      std::fill(used.begin(), used.end(), std::uint8_t{0});
      input = used;
      frame_status[p] = InputStatus::disconnected;
    } else if (frame < q.next_confirmed()) {
      input = q.confirmed(frame);
      frame_status[p] = InputStatus::confirmed;
    } else {
      const std::span<std::uint8_t> guess = q.used_mut(frame);
      if (predictor) {
        predictor(p, q.last_confirmed(), guess);
      } else {
        const std::span<const std::uint8_t> last = q.last_confirmed();
        std::copy(last.begin(), last.end(), guess.begin());
      }
      input = guess;
      frame_status[p] = InputStatus::predicted;
    }
    std::copy(input.begin(), input.end(),
              frame_inputs.begin() + static_cast<std::ptrdiff_t>(p * size));
  }
  game->advance(FrameInputs{frame, size, frame_inputs, frame_status}, resimulating);
  current = frame + 1;
  detail::State& saved = state_slot(current);
  saved.frame = current;
  saved.hash = game->save(saved.bytes);
}

Status Session::Impl::rollback() {
  const std::uint64_t from = *first_incorrect;
  first_incorrect.reset();
  const detail::State& saved = state_slot(from);
  // The window guarantees the state is held: a correction is never older than the oldest
  // unconfirmed frame, and the ring spans the whole prediction window. If that ever failed, the
  // session could not correct its prediction: it stops with an error instead of going on wrong.
  DETSIM_ASSERT(saved.frame == from);
  if (saved.frame != from) {
    broken = "rollback to frame " + std::to_string(from) +
             ": its state is no longer in the ring of saved states (a session bug; the match "
             "cannot continue in step with its peers)";
    return Status::error(broken);
  }
  game->load(saved.bytes);
  const std::uint64_t end = current;
  for (std::uint64_t frame = from; frame < end; ++frame)
    simulate(frame, true);
  ++stats.rollbacks;
  stats.resimulated_frames += end - from;
  return Status::success();
}

void Session::Impl::emit_confirmed() {
  // A frame is final once its inputs are all confirmed, it was simulated, no pending correction
  // reaches back to it (states after first_incorrect are re-simulated first), and every peer holds
  // every input of it (so a disconnect can never be agreed before it).
  // A match that ended for want of a majority delivers nothing more: past this point, frames
  // are no longer held by every peer, and the sides of a partition would tell them differently.
  if (ended) return;
  const std::uint64_t limit = emit_limit();
  const std::size_t size = config.input_size;
  for (; next_emit < limit; ++next_emit) {
    const std::uint64_t frame = next_emit;
    for (std::uint32_t p = 0; p < config.players; ++p) {
      const bool gone = gone_at(p, frame);
      frame_status[p] = gone ? InputStatus::disconnected : InputStatus::confirmed;
      const auto out = frame_inputs.begin() + static_cast<std::ptrdiff_t>(p * size);
      if (gone) {
        std::fill_n(out, size, std::uint8_t{0});
      } else {
        const std::span<const std::uint8_t> input = queues[p].confirmed(frame);
        std::copy(input.begin(), input.end(), out);
      }
    }
    const detail::State& after = state_slot(frame + 1);
    const bool held = after.frame == frame + 1;
    DETSIM_ASSERT(held);  // the ring spans every frame not yet emitted (advance_frame waits)
    const std::uint64_t hash = held ? after.hash : 0;
    if (confirmed_listener)
      confirmed_listener(ConfirmedFrame{frame, frame_inputs, frame_status, hash});
    {  // the log spectators are served from and desync evidence carries
      std::uint8_t gone = 0;
      for (std::uint32_t p = 0; p < config.players; ++p)
        if (frame_status[p] == InputStatus::disconnected)
          gone = static_cast<std::uint8_t>(gone | (1U << p));
      frame_log.push_back(gone);
      frame_log.insert(frame_log.end(), frame_inputs.begin(), frame_inputs.end());
    }
    if (config.check_interval != 0 && (frame + 1) % config.check_interval == 0 && held)
      add_local_check(frame + 1, hash, &after);
  }
}

void Session::Impl::add_local_check(std::uint64_t frame, std::uint64_t hash,
                                    const detail::State* state) {
  if (peers.empty()) return;
  if (local_checks.size() >= detail::max_pending_checks) {
    // A peer whose check of the dropped frame has not arrived can no longer be compared with it.
    for (detail::Peer& peer : peers)
      if (seated(peer) && peer.checks_through < local_checks.front().frame)
        check_missing(peer, local_checks.front().frame);
    local_checks.pop_front();
  }
  local_checks.push_back(detail::LocalCheck{frame, hash, state->bytes, now_us});
  for (detail::Peer& peer : peers)
    compare_checks(peer);
  retire_checks();
}

void Session::Impl::compare_checks(detail::Peer& peer) {
  while (!peer.pending_checks.empty()) {
    const protocol::HashCheck remote = peer.pending_checks.front();
    if (local_checks.empty() || remote.frame > local_checks.back().frame) return;  // not yet here
    const auto local =
        std::find_if(local_checks.begin(), local_checks.end(),
                     [&](const detail::LocalCheck& c) { return c.frame == remote.frame; });
    peer.pending_checks.pop_front();
    if (local == local_checks.end()) {
      ++stats.checks_skipped;  // ours was dropped (more than max_pending_checks outstanding)
      continue;
    }
    ++stats.checks_compared;
    if (local->hash == remote.hash || peer.desynced) continue;
    peer.desynced = true;
    raise(Event{EventType::desync, peer.player, remote.frame, local->hash, remote.hash, {}});
    if (!evidence) {
      evidence = DesyncEvidence{peer.player,  agreed_frame, agreed_state, remote.frame,
                                local->state, local->hash,  remote.hash,  {}};
      const std::size_t logged = std::min<std::size_t>(frame_log.size() / unit_size, remote.frame);
      evidence->confirmed_frames.assign(
          frame_log.begin(), frame_log.begin() + static_cast<std::ptrdiff_t>(logged * unit_size));
    }
  }
}

void Session::Impl::check_missing(detail::Peer& peer, std::uint64_t frame) {
  if (peer.check_missing) return;
  peer.check_missing = true;
  ++stats.checks_missing;
  raise(Event{EventType::check_missing, peer.player, frame, 0, 0, {}});
}

void Session::Impl::check_deadlines() {
  for (detail::Peer& peer : peers) {
    if (!seated(peer) || peer.check_missing) continue;
    // Checks arrive in frame order: the first local check beyond what arrived is the one due.
    for (const detail::LocalCheck& c : local_checks) {
      if (c.frame <= peer.checks_through) continue;
      if (now_us - c.confirmed_us >= config.progress_timeout_us) check_missing(peer, c.frame);
      break;
    }
  }
}

void Session::Impl::retire_checks() {
  while (!local_checks.empty()) {
    const std::uint64_t frame = local_checks.front().frame;
    bool everyone = true;
    for (const detail::Peer& peer : peers) {
      if (!seated(peer)) continue;
      // Kept until the peer's hash was compared with it here AND the peer acknowledged ours:
      // retiring it earlier would leave a slower peer without our hash for the frame (its
      // checks arrive in order, so it would then never compare another).
      const bool compared =
          peer.checks_through >= frame &&
          (peer.pending_checks.empty() || peer.pending_checks.front().frame > frame);
      if (!compared || peer.acked_checks < frame || peer.desynced) everyone = false;
    }
    if (!everyone) return;
    agreed_frame = frame;
    agreed_state = std::move(local_checks.front().state);
    local_checks.pop_front();
  }
}

void Session::Impl::receive_input(detail::Peer& peer, std::uint64_t frame,
                                  std::span<const std::uint8_t> input) {
  detail::InputQueue& q = queues[peer.player];
  if (frame < current && !std::equal(input.begin(), input.end(), q.used(frame).begin()))
    first_incorrect = std::min(first_incorrect.value_or(frame), frame);
  q.confirm(input);
}

bool Session::Impl::majority_without(std::uint32_t player) const noexcept {
  std::uint32_t staying = 0;
  for (std::uint32_t p = 0; p < config.players; ++p)
    if (p != player && disconnect_frame[p] == never) ++staying;
  return 2 * staying > config.players;
}

void Session::Impl::restart_clocks() {
  window_start_us = now_us;
  window_advanced = 0;
  window_held = 0;
  for (detail::LocalCheck& c : local_checks)
    c.confirmed_us = std::max(c.confirmed_us, now_us);
}

void Session::Impl::disconnect(detail::Peer& peer, std::string_view reason) {
  player_gone(peer.player, queues[peer.player].next_confirmed(), reason);
}

bool Session::Impl::hears(std::uint32_t player) const noexcept {
  for (const detail::Peer& peer : peers)
    if (peer.player == player)
      return peer.synchronized && !peer.disconnected &&
             now_us - peer.last_receive_us < config.disconnect_timeout_us;
  return false;
}

bool Session::Impl::holds_back(const detail::Peer& peer) const noexcept {
  const std::uint64_t confirmed = confirmed_frame();
  // Its inputs are the oldest this machine lacks.
  if (disconnect_frame[peer.player] == never &&
      queues[peer.player].next_confirmed() <= std::min(confirmed, current))
    return true;
  // Its held frame is what keeps the frames this machine confirmed from being final.
  if (peer.reported_held <= next_emit && next_emit < std::min(confirmed, current)) return true;
  // It has not agreed to a disconnect frame this machine waits on.
  for (std::uint32_t p = 0; p < config.players; ++p)
    if (disconnect_frame[p] != never && peer.reported_gone[p] != disconnect_frame[p]) return true;
  return false;
}

void Session::Impl::end_without_majority() {
  if (config.partition != PartitionPolicy::end_match || !broken.empty()) return;
  std::uint32_t staying = 0;
  for (std::uint32_t p = 0; p < config.players; ++p)
    if (disconnect_frame[p] == never) ++staying;
  if (2 * staying > config.players) return;
  ended = true;
  broken = "the match ended: this machine is left with " + std::to_string(staying) + " of " +
           std::to_string(config.players) +
           " players, no majority (a partition and players leaving look alike from here; "
           "SessionConfig::partition)";
  raise(Event{EventType::match_ended, config.local_player, next_emit, 0, 0, "no majority"});
}

void Session::Impl::player_gone(std::uint32_t player, std::uint64_t frame,
                                std::string_view reason) {
  // Frames already emitted are final: no peer can report an earlier frame unless the network is
  // partitioned, and then the hash checks will tell.
  frame = std::max(frame, next_emit);
  if (disconnect_frame[player] == never && config.partition == PartitionPolicy::pause &&
      !majority_without(player)) {
    // The match waits for the player instead (it may come back, or rejoin).
    if (!paused) {
      paused = true;
      raise(Event{EventType::paused, player, next_emit, 0, 0, "no majority"});
    }
    return;
  }
  if (disconnect_frame[player] == never) {
    // From now on this machine takes no input of the player: its holdings are frozen.
    frame = std::min(frame, queues[player].next_confirmed());
    disconnect_frame[player] = frame;
    for (detail::Peer& peer : peers) {
      if (peer.player != player) continue;
      peer.disconnected = true;
      peer.stats.disconnected = true;
    }
    raise(Event{EventType::disconnected, player, frame, 0, 0, reason});
    retire_checks();
    end_without_majority();
  } else if (frame < disconnect_frame[player]) {
    disconnect_frame[player] = frame;
  } else {
    return;
  }
  // Frames from `frame` on were simulated with predictions or inputs; they now take zero inputs.
  if (frame < current) first_incorrect = std::min(first_incorrect.value_or(frame), frame);
}

// ---- the public face ----

Expected<Session> Session::create(const SessionConfig& config, Game& game, Transport& transport) {
  if (Status s = validate(config); !s) return s;
  if (Status s = detail::check_match_key(config.match_key, "session config: match_key"); !s)
    return s;
  if (Status s = detail::secure_random_ready(); !s) return s;
  return Session(std::make_unique<Impl>(config, game, transport));
}

Session::Session(std::unique_ptr<Impl> impl) noexcept : impl_(std::move(impl)) {}
Session::Session(Session&&) noexcept = default;
Session& Session::operator=(Session&&) noexcept = default;
Session::~Session() = default;

Expected<Advance> Session::advance_frame(std::span<const std::uint8_t> local_input) {
  Impl& s = *impl_;
  if (local_input.size() != s.config.input_size)
    return Status::error("advance_frame: the local input must be " +
                         std::to_string(s.config.input_size) + " bytes, got " +
                         std::to_string(local_input.size()));
  if (!s.broken.empty()) return Status::error(s.broken);
  if (!s.running) return Advance::synchronizing;
  const std::uint64_t before = s.queues[s.config.local_player].next_confirmed();
  s.add_local_input(local_input);
  if (s.queues[s.config.local_player].next_confirmed() != before)
    for (detail::Peer& peer : s.peers)
      if (peer.synchronized && !peer.disconnected) s.send_inputs(peer);
  if (s.first_incorrect) {
    if (Status st = s.rollback(); !st) return st;
  }
  s.emit_confirmed();
  // The ring must hold every state from the oldest frame not yet emitted to the one about to be
  // saved (rollbacks and emission read them).
  const bool ring_full = s.current + 2 - s.next_emit > s.states.size();
  if (s.current >= s.confirmed_frame() + s.max_prediction || ring_full) {
    ++s.window_held;
    s.last_advance_held = true;
    if (s.max_prediction == 0) return Advance::waiting_for_inputs;
    ++s.stats.prediction_limit_waits;
    return Advance::prediction_limit;
  }
  ++s.window_advanced;
  s.last_advance_held = false;
  s.simulate(s.current, false);
  ++s.stats.frames;
  s.emit_confirmed();
  return Advance::advanced;
}

Status Session::set_input_delay(std::uint32_t frames) {
  if (frames > max_input_delay)
    return Status::error("input delay must be 0 .. 16 frames, got " + std::to_string(frames));
  impl_->config.input_delay = frames;
  return Status::success();
}

void Session::set_predictor(Predictor predictor) {
  impl_->predictor = std::move(predictor);
}

void Session::set_confirmed_listener(std::function<void(const ConfirmedFrame&)> listener) {
  impl_->confirmed_listener = std::move(listener);
}

std::vector<Event> Session::take_events() {
  std::vector<Event> out;
  out.swap(impl_->events);
  return out;
}

const SessionConfig& Session::config() const noexcept {
  return impl_->config;
}
bool Session::running() const noexcept {
  return impl_->running;
}
std::uint64_t Session::current_frame() const noexcept {
  return impl_->current;
}
std::uint64_t Session::confirmed_frame() const noexcept {
  return impl_->confirmed_frame();
}
std::uint64_t Session::delivered_frame() const noexcept {
  return impl_->next_emit;
}
const SessionStats& Session::stats() const noexcept {
  return impl_->stats;
}

std::string_view Session::failure() const noexcept {
  return impl_->broken;
}

const DesyncEvidence* Session::desync_evidence() const noexcept {
  return impl_->evidence ? &*impl_->evidence : nullptr;
}

}  // namespace detsim::net
