// What the two roles of `detsim netplay` share: a player (cmd_netplay.cpp) and a spectator
// (cmd_spectate.cpp, --spectate). The command line is checked once into a NetplayPlan; both loops
// use the same pacing constants.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <detsim/core/status.hpp>
#include <detsim/net/session.hpp>
#include <detsim/net/udp.hpp>
#include <detsim/replay/replay.hpp>
#include <detsim/scenario_net/scenario_game.hpp>

#include "commands.hpp"

namespace detsim::cli {

inline constexpr std::string_view netplay_name = "netplay";
/// Polling after the last frame once everything is confirmed, so that peers get our last
/// inputs and acknowledgements (they are resent every frame until acknowledged).
inline constexpr std::uint64_t netplay_linger_us = 500'000;
/// The pause between polls while there is nothing to do.
inline constexpr std::uint64_t netplay_idle_sleep_us = 1'000;
/// SessionConfig::players allows 8.
inline constexpr std::uint32_t max_session_players = 8;
/// SessionConfig::spectators allows 16.
inline constexpr std::size_t max_spectators = 16;
/// Spectator k's PeerId on the serving player's transport: above every player index (0 .. 7).
inline constexpr net::PeerId first_spectator_peer = 100;

/// The netplay command line, checked: where to bind, whom to talk to.
struct NetplayPlan {
  net::Endpoint bind;
  /// A player: every other player, ascending, PeerId = player index. A spectator: the host alone.
  std::vector<net::UdpPeer> peers;
  /// The spectators this player serves (--spectator), PeerId first_spectator_peer + k.
  std::vector<net::UdpPeer> spectators;
  net::SessionMode mode = net::SessionMode::rollback;
  /// --key or --key-file: every datagram sealed (docs/NET.md, "Packet protection"); absent: the
  /// plain framing, unauthenticated (a trusted network only).
  std::optional<net::MatchKey> match_key;
  /// --partition: what a player left without a majority does.
  net::PartitionPolicy partition = net::PartitionPolicy::end_match;
};

/// A match key from 64 hex digits (either case; surrounding whitespace ignored); errors say why.
Expected<net::MatchKey> parse_match_key(std::string_view text);

/// Checks `args` (player or --spectate) into a plan; errors name the option and the problem.
Expected<NetplayPlan> netplay_plan(const NetplayArgs& args);

/// What a hello_rejected reason about keys means for the user ("--key differs ..."), or nullptr
/// for the other reasons (settings).
const char* key_mismatch(std::string_view reason);

/// The line netplay prints about packet protection.
std::string protection_line(const NetplayPlan& plan);

/// Writes this machine's side of a desync to `path` (a player's or a server client's: `evidence`
/// from desync_evidence(), with the states between the agreed and the divergent frame
/// re-simulated by `game`); `missing` is the error when there is no evidence.
Status write_desync_side(const std::string& path, const replay::Fingerprint& fingerprint,
                         std::uint32_t player, const net::DesyncEvidence* evidence,
                         net::ScenarioGame& game, const char* missing);

/// "12.3 ms"
std::string milliseconds(std::uint64_t us);

/// Watches the match as a spectator of plan.peers[0] (`detsim netplay --spectate`); the exit code.
int spectate(const NetplayArgs& args, const NetplayPlan& plan);

}  // namespace detsim::cli
