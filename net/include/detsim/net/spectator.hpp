// detsim::net::SpectatorSession: watches a match by receiving its confirmed frames from one host
// (a player's Session that lists this spectator in SessionConfig::spectators). A spectator never
// predicts and never rolls back: it simulates exactly the confirmed inputs, so it reproduces every
// player's confirmed state. It may lag behind the players; when frames have piled up it simulates
// several per call, catching up faster than real time.
//
//     spectator.poll(now_us);
//     spectator.advance();   // 0, 1, or up to catch_up_frames frames
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include <detsim/core/status.hpp>
#include <detsim/net/game.hpp>
#include <detsim/net/protection.hpp>
#include <detsim/net/session.hpp>
#include <detsim/net/transport.hpp>

namespace detsim::net {

struct SpectatorConfig {
  std::uint32_t players = 2;      ///< of the match: 1 .. 8
  std::uint32_t input_size = 4;   ///< of the match: 1 .. protocol::max_input_size
  std::uint64_t fingerprint = 0;  ///< the match's (SessionConfig::fingerprint)
  PeerId host = 0;                ///< the player session that serves this spectator
  /// The match's key (SessionConfig::match_key): the host must have the same, or none if absent.
  std::optional<MatchKey> match_key;
  /// More frames than this waiting: advance() simulates up to catch_up_frames at once.
  std::uint32_t catch_up_threshold = 2;
  std::uint32_t catch_up_frames = 8;  ///< 1 .. 1000
  std::uint64_t hello_interval_us = 200'000;
  std::uint64_t keepalive_us = 100'000;
  std::uint64_t disconnect_timeout_us = 5'000'000;
};

struct SpectatorStats {
  std::uint64_t frames = 0;          ///< simulated
  std::uint64_t catch_up_calls = 0;  ///< advance() calls that simulated more than one frame
  std::uint64_t packets_received = 0;
  std::uint64_t bytes_received = 0;
  std::uint64_t dropped = 0;  ///< malformed, foreign, or out of the window (all of them)
  std::uint64_t dropped_unauthenticated = 0;  ///< of those: a tag that failed (a match key)
  std::uint64_t dropped_replayed = 0;         ///< of those: a duplicate or an old datagram
};

class SpectatorSession {
 public:
  /// Frames received ahead of the simulation that a spectator holds at most.
  static constexpr std::uint64_t max_buffered_frames = 1 << 16;

  /// Errors name the first invalid field of `config`; `game` and `transport` must outlive it.
  static Expected<SpectatorSession> create(const SpectatorConfig& config, Game& game,
                                           Transport& transport);
  SpectatorSession(SpectatorSession&&) noexcept;
  SpectatorSession& operator=(SpectatorSession&&) noexcept;
  ~SpectatorSession();

  /// Receives frames, acknowledges them, handshakes and keeps alive; raises a disconnect event when
  /// the host was silent for disconnect_timeout_us.
  void poll(std::uint64_t now_us);
  /// Simulates the received frames due now (see the file comment); returns how many.
  std::uint32_t advance();

  void set_confirmed_listener(std::function<void(const ConfirmedFrame&)> listener);
  [[nodiscard]] std::vector<Event> take_events();
  [[nodiscard]] bool running() const noexcept;
  /// The next frame to simulate.
  [[nodiscard]] std::uint64_t current_frame() const noexcept;
  /// Frames received and not yet simulated.
  [[nodiscard]] std::uint64_t frames_behind() const noexcept;
  [[nodiscard]] const SpectatorStats& stats() const noexcept;

 private:
  struct Impl;
  explicit SpectatorSession(std::unique_ptr<Impl> impl) noexcept;
  std::unique_ptr<Impl> impl_;
};

}  // namespace detsim::net
