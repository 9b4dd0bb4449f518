// Test support for net/: games a session can drive, and a match of N sessions over a SimNetwork
// stepped in virtual time, recording every peer's confirmed frames for comparison.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <detsim/net/game.hpp>
#include <detsim/net/protection.hpp>
#include <detsim/net/protocol.hpp>
#include <detsim/net/session.hpp>
#include <detsim/net/sim_network.hpp>
#include <detsim/net/spectator.hpp>
#include <detsim/scenario_net/scenario_game.hpp>
#include <detsim/scenes/scenario.hpp>

namespace detsim::test {

/// A cheap deterministic game: its state is the frame and an accumulator that mixes in every
/// input byte and whether each player was there (InputStatus::disconnected or not), so any
/// difference in any input of any frame changes every later hash. `fault_frame`
/// perturbs the state on this machine only (a stand-in for non-determinism).
class CounterGame final : public net::Game {
 public:
  /// Called for each peer every tick before it advances (mid-match changes).
  std::function<void(std::uint32_t peer, std::uint64_t tick, net::Session&)> on_tick;
  std::optional<std::uint64_t> fault_frame;

  static std::uint64_t mix(std::uint64_t x) {  // splitmix64's finaliser
    x ^= x >> 30;
    x *= 0xBF58476D1CE4E5B9ULL;
    x ^= x >> 27;
    x *= 0x94D049BB133111EBULL;
    return x ^ (x >> 31);
  }
  std::uint64_t save(std::vector<std::uint8_t>& state) override {
    state.resize(16);
    for (int i = 0; i < 8; ++i) {
      state[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(frame_ >> (8 * i));
      state[static_cast<std::size_t>(8 + i)] = static_cast<std::uint8_t>(acc_ >> (8 * i));
    }
    return mix(acc_ ^ mix(frame_));
  }
  void load(std::span<const std::uint8_t> state) override {
    frame_ = acc_ = 0;
    for (int i = 0; i < 8; ++i) {
      frame_ |= std::uint64_t{state[static_cast<std::size_t>(i)]} << (8 * i);
      acc_ |= std::uint64_t{state[static_cast<std::size_t>(8 + i)]} << (8 * i);
    }
  }
  void advance(const net::FrameInputs& inputs, bool resimulating) override {
    for (std::size_t i = 0; i < inputs.bytes.size(); ++i)
      acc_ = mix(acc_ + inputs.bytes[i] + i);
    for (std::size_t p = 0; p < inputs.status.size(); ++p)
      if (inputs.status[p] == net::InputStatus::disconnected) acc_ = mix(acc_ ^ (p + 1));
    if (fault_frame && *fault_frame == frame_) acc_ += 1;
    ++frame_;
    ++(resimulating ? resimulated : simulated);
  }
  std::uint64_t simulated = 0;
  std::uint64_t resimulated = 0;

 private:
  std::uint64_t frame_ = 0;
  std::uint64_t acc_ = 0;
};

/// What one peer confirmed.
struct PeerRecord {
  std::uint64_t first_frame = 0;         ///< the frame of hashes[0] (a rejoined session's is late)
  std::vector<std::uint64_t> hashes;     ///< per confirmed frame
  std::vector<std::uint8_t> inputs;      ///< every confirmed frame's inputs, concatenated
  std::vector<net::InputStatus> status;  ///< per confirmed frame and player
  std::vector<net::Event> events;
  bool has(net::EventType type) const {
    for (const net::Event& e : events)
      if (e.type == type) return true;
    return false;
  }
};

/// A match key for tests (any 32 bytes not all zero), `salt` making another one.
inline net::MatchKey test_match_key(std::uint8_t salt = 0) {
  net::MatchKey key{};
  for (std::size_t i = 0; i < key.size(); ++i)
    key[i] = static_cast<std::uint8_t>((0xA5 ^ (i * 29)) + salt);
  return key;
}
/// The key test matches play with: test_match_key(), or none in a build without libsodium
/// (DETSIM_WITH_SODIUM=OFF), which refuses keys.
inline std::optional<net::MatchKey> default_match_key() {
  if (!net::protection::available()) return std::nullopt;
  return test_match_key();
}

struct MatchOptions {
  std::uint32_t players = 2;
  /// Every peer's and spectator's SessionConfig::match_key: sealed datagrams by default, as a real
  /// match plays. Tests that edit datagrams as a malicious peer would (it holds the key) reset it
  /// and edit the plain framing, which carries the same fields.
  std::optional<net::MatchKey> match_key = default_match_key();
  net::SessionMode mode = net::SessionMode::rollback;
  net::LinkConditions link{};
  std::uint64_t frames = 600;
  std::uint64_t seed = 1;
  std::uint32_t input_delay = 2;
  std::uint32_t max_prediction = 8;
  std::uint32_t check_interval = 30;
  bool arena = false;             ///< the arena scenario through ScenarioGame; else CounterGame
  std::uint32_t arena_count = 0;  ///< the arena's size (0: its default)
  /// Called once with the network before the match (outages, per-link conditions).
  std::function<void(net::SimNetwork&)> setup;
  /// Called for each peer's config (per-peer tweaks).
  std::function<void(std::uint32_t peer, net::SessionConfig&)> configure;
  /// Whether peer p simulates (advances) at all: a peer that never advances still polls.
  std::function<bool(std::uint32_t peer, std::uint64_t tick)> active;
  /// Called for each peer every tick before it advances (mid-match changes).
  std::function<void(std::uint32_t peer, std::uint64_t tick, net::Session&)> on_tick;
  /// A peer whose player presses nothing: its input is all zero.
  std::optional<std::uint32_t> zero_input_peer;
  /// Wraps peer p's transport (hostile-datagram tests); nullptr keeps the network's endpoint.
  using Wrap =
      std::function<std::unique_ptr<net::Transport>(std::uint32_t peer, net::Transport& inner)>;
  Wrap wrap;
  std::optional<std::uint64_t> fault_frame;  ///< CounterGame fault on peer fault_peer
  std::uint32_t fault_peer = 0;
  std::uint64_t max_ticks = 0;  ///< 0: frames * 4 + 2000
  /// Peers follow recommended_wait_frames() (skip one tick in four while it is above 0).
  bool time_sync = true;
  /// Spectators served by player 0 (network nodes players .. players + spectators - 1), each
  /// joining (first polling) at spectator_join_tick.
  std::uint32_t spectators = 0;
  std::uint64_t spectator_join_tick = 0;
  std::function<void(std::uint32_t spectator, net::SpectatorConfig&)> configure_spectator;
  /// A restart of one player's process: at restart_tick its session and game are destroyed and
  /// it falls silent; at rejoin_tick a new game (at frame 0) and a session with
  /// SessionConfig::rejoin take the seat, with a new record (earlier_record() keeps the old one).
  std::optional<std::uint32_t> restart_peer;
  std::uint64_t restart_tick = 0;
  std::uint64_t rejoin_tick = 0;
  /// More restarts like restart_peer's, of other peers (their earlier records are not kept).
  struct Restart {
    std::uint32_t peer = 0;
    std::uint64_t restart_tick = 0;
    std::uint64_t rejoin_tick = 0;
  };
  std::vector<Restart> more_restarts;
};

/// A peer's transport that rewrites what it sends (the plain framing: what a malicious peer, or
/// a relay, could do): `edit(to, packet, n)` sees the n-th decoded datagram to `to` and may change
/// it (or return false to drop it). Datagrams it cannot decode pass unchanged.
class Tamper final : public net::Transport {
 public:
  using Edit = std::function<bool(net::PeerId to, net::protocol::Packet& packet, std::uint64_t n)>;
  Tamper(net::Transport& inner, Edit edit, std::size_t input_size = 4)
      : inner_(inner), edit_(std::move(edit)), input_size_(input_size) {}
  void send(net::PeerId to, std::span<const std::uint8_t> bytes) override {
    net::protocol::Packet p;
    if (net::protocol::decode(bytes, input_size_, p) != net::protocol::DecodeError::none) {
      inner_.send(to, bytes);
      return;
    }
    if (!edit_(to, p, count_++)) return;
    std::vector<std::uint8_t> out;
    if (net::protocol::encode(p, input_size_, out)) inner_.send(to, out);
  }
  void receive(std::vector<net::Datagram>& out) override { inner_.receive(out); }

 private:
  net::Transport& inner_;
  Edit edit_;
  std::size_t input_size_;
  std::uint64_t count_ = 0;
};

/// MatchOptions::wrap that puts a Tamper on peer `who`'s transport (CounterGame's inputs).
inline MatchOptions::Wrap tamper(std::uint32_t who, Tamper::Edit edit) {
  return [who, edit](std::uint32_t p, net::Transport& inner) -> std::unique_ptr<net::Transport> {
    if (p != who) return nullptr;
    return std::make_unique<Tamper>(inner, edit);
  };
}

/// N peers, each with its own game and session, over one SimNetwork.
class Match {
 public:
  explicit Match(const MatchOptions& options);

  /// Ticks until every peer confirmed options.frames frames (or max_ticks); true if they did.
  bool run();

  /// Polls every peer for `ticks` more ticks without advancing (acknowledgements settle; a
  /// restart_peer comes back up at its rejoin_tick here too).
  void idle(std::uint64_t ticks);

  std::uint32_t players() const { return options_.players; }
  net::Session& session(std::uint32_t p) { return *sessions_[p]; }
  net::SimNetwork& network() { return *network_; }
  const PeerRecord& record(std::uint32_t p) const { return records_[p]; }
  /// The record of restart_peer's session before the restart.
  const PeerRecord& earlier_record() const { return earlier_record_; }
  const PeerRecord& spectator_record(std::uint32_t k) const { return spectator_records_[k]; }
  net::SpectatorSession& spectator(std::uint32_t k) { return *spectator_sessions_[k]; }
  std::uint64_t ticks() const { return tick_; }
  /// The hashes of an offline run of peer p's confirmed inputs, frame by frame.
  std::vector<std::uint64_t> offline_hashes(std::uint32_t p) const;
  /// An empty string when every peer confirmed the same inputs and hashes for every frame they all
  /// confirmed, and that matches an offline replay; else what differs.
  std::string compare() const;
  /// An empty string when every peer compared (nearly) every confirmed-frame hash check of every
  /// other peer — frames / interval each, but for the last two, which may still be in flight — and
  /// skipped none; else which peer did not. Desync detection that silently stops comparing would
  /// pass compare() but not this.
  std::string checks_complete() const;

 private:
  std::unique_ptr<net::Game> make_game(std::uint32_t p);
  /// Creates peer p's session (config.rejoin as given) and points its listener at records_[p].
  void start_session(std::uint32_t p, bool rejoin);
  /// Takes restart_peer down or back up at this tick; false while it is down.
  bool restarted_peer_up(std::uint32_t p);
  PeerRecord earlier_record_;
  std::vector<net::Transport*> transports_;
  void add_spectators();

  MatchOptions options_;
  std::optional<net::SimNetwork> network_;
  std::vector<std::unique_ptr<Scenario>> scenarios_;
  std::vector<std::unique_ptr<net::Game>> games_;
  std::vector<std::unique_ptr<net::Transport>> wrappers_;
  std::vector<std::optional<net::Session>> sessions_;
  std::vector<PeerRecord> records_;
  std::vector<std::unique_ptr<net::Game>> spectator_games_;
  std::vector<std::optional<net::SpectatorSession>> spectator_sessions_;
  std::vector<PeerRecord> spectator_records_;
  std::uint64_t tick_ = 0;
};

}  // namespace detsim::test
