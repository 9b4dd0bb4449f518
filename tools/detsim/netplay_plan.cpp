// The netplay command line checked into a NetplayPlan (netplay_plan.hpp), for both roles: a player
// names every other player with --peer and may serve spectators (--spectator); a spectator
// (--spectate) names only the player that serves it.
#include "netplay_plan.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <optional>

#include <detsim/replay/desync_report.hpp>
#include <detsim/scenario_net/scenario_recorder.hpp>

namespace detsim::cli {

namespace {

Expected<net::UdpPeer> parse_peer(const std::string& text, const NetplayArgs& a) {
  const auto eq = text.find('=');
  if (eq == std::string::npos)
    return Status::error("--peer \"" + text + "\": expected J=IP:PORT, e.g. 1=127.0.0.1:7001");
  const std::string index = text.substr(0, eq);
  std::uint32_t player = 0;
  const bool digits =
      !index.empty() && index.size() <= 3 &&
      std::all_of(index.begin(), index.end(), [](char c) { return c >= '0' && c <= '9'; });
  if (digits) player = static_cast<std::uint32_t>(std::stoul(index));
  if (!digits || player >= a.players)
    return Status::error("--peer \"" + text + "\": player \"" + index +
                         "\" is not a player of this match (0 .. " + std::to_string(a.players - 1) +
                         ")");
  if (!a.spectate && player == a.me)
    return Status::error("--peer \"" + text + "\": player " + index + " is this machine (--me " +
                         std::to_string(a.me) + ")");
  auto endpoint = net::parse_endpoint(std::string_view(text).substr(eq + 1));
  if (!endpoint) return Status::error("--peer " + index + ": " + endpoint.message());
  return net::UdpPeer{player, endpoint.value()};
}

/// The role's own rules, before any address is parsed.
Status check_role(const NetplayArgs& a) {
  if (!a.spectate) {
    if (a.me >= a.players)
      return Status::error("--me " + std::to_string(a.me) + " must be below --players " +
                           std::to_string(a.players) + " (players are numbered 0 .. " +
                           std::to_string(a.players - 1) + ")");
    if (a.open_seat && a.rejoin)
      return Status::error(
          "--open-seat and --rejoin: the player that opens a seat waits for the one that joins");
    if ((a.rejoin || a.open_seat) && a.players < 2)
      return Status::error(std::string(a.rejoin ? "--rejoin" : "--open-seat") +
                           " needs a match of two or more players (--players 1)");
    if (a.rejoin && !a.spectators.empty())
      return Status::error(
          "--rejoin cannot be combined with --spectator: spectators follow the earlier process");
    if (a.spectators.size() > max_spectators)
      return Status::error("at most " + std::to_string(max_spectators) +
                           " --spectator addresses, got " + std::to_string(a.spectators.size()));
    return Status::success();
  }
  if (a.me_given)
    return Status::error("--me cannot be combined with --spectate: a spectator plays no player");
  if (a.rejoin)
    return Status::error("--rejoin cannot be combined with --spectate: a spectator holds no seat");
  if (a.open_seat)
    return Status::error("--open-seat cannot be combined with --spectate: a spectator has no seat");
  if (!a.spectators.empty())
    return Status::error(
        "--spectator cannot be combined with --spectate: only players serve spectators");
  if (a.bot)
    return Status::error("--bot cannot be combined with --spectate: a spectator has no input");
  if (!a.desync_report.empty())
    return Status::error(
        "--desync-report cannot be combined with --spectate: a spectator checks no hashes");
  if (a.peers.size() != 1)
    return Status::error(
        "--spectate needs exactly one --peer J=IP:PORT, the player J that lists "
        "this machine with --spectator; got " +
        std::to_string(a.peers.size()));
  return Status::success();
}

bool unspecified(const net::Endpoint& e) {
  return std::all_of(e.address.begin(), e.address.end(), [](std::uint8_t b) { return b == 0; });
}

/// The --spectator addresses, checked against the bind address and the players' addresses.
Status add_spectators(const NetplayArgs& a, NetplayPlan& plan) {
  for (const std::string& text : a.spectators) {
    const std::string name = "--spectator \"" + text + "\"";
    auto endpoint = net::parse_endpoint(text);
    if (!endpoint) return Status::error(name + ": " + endpoint.message());
    const net::Endpoint& e = endpoint.value();
    if (e.family != plan.bind.family)
      return Status::error(name + ": not the address family of --bind " + plan.bind.to_string() +
                           " (one address family per machine: IPv4 or IPv6)");
    if (e.port == 0) return Status::error(name + ": port 0 cannot be sent to");
    if (unspecified(e))
      return Status::error(name +
                           ": the unspecified address cannot be sent to; give the "
                           "spectator's own address");
    for (const net::UdpPeer& p : plan.peers)
      if (p.endpoint == e)
        return Status::error(name + ": that is player " + std::to_string(p.id) + "'s address");
    for (const net::UdpPeer& s : plan.spectators)
      if (s.endpoint == e) return Status::error(name + " is given twice");
    const auto k = static_cast<net::PeerId>(plan.spectators.size());
    plan.spectators.push_back(net::UdpPeer{first_spectator_peer + k, e});
  }
  return Status::success();
}

/// --key or --key-file into plan.match_key.
Status read_key(const NetplayArgs& a, NetplayPlan& plan) {
  if (!a.key.empty() && !a.key_file.empty())
    return Status::error("--key and --key-file: give one of them, not both");
  if (!a.key.empty()) {
    auto key = parse_match_key(a.key);
    if (!key) return Status::error("--key: " + key.message());
    plan.match_key = key.value();
  } else if (!a.key_file.empty()) {
    std::ifstream in(a.key_file, std::ios::binary);
    if (!in) return Status::error("--key-file " + a.key_file + ": cannot be read");
    std::string text(128, '\0');  // a key file is short: read a little more than the longest
    in.read(text.data(), static_cast<std::streamsize>(text.size()));
    text.resize(static_cast<std::size_t>(in.gcount()));
    if (text.size() == net::MatchKey{}.size()) {  // 32 raw bytes
      net::MatchKey key{};
      std::copy(text.begin(), text.end(), key.begin());
      plan.match_key = key;
    } else {
      auto key = parse_match_key(text);
      if (!key)
        return Status::error("--key-file " + a.key_file + ": " + key.message() +
                             " (or exactly 32 raw bytes)");
      plan.match_key = key.value();
    }
  }
  if (plan.match_key && !net::protection::available())
    return Status::error(
        "--key: this detsim was built without libsodium (DETSIM_WITH_SODIUM=OFF) and cannot "
        "protect packets");
  if (plan.match_key &&
      std::all_of(plan.match_key->begin(), plan.match_key->end(), [](auto b) { return b == 0; }))
    return Status::error("--key: all zero is not a key");
  return Status::success();
}

}  // namespace

Expected<net::MatchKey> parse_match_key(std::string_view text) {
  const auto space = [](char c) { return c == ' ' || c == '\n' || c == '\r' || c == '\t'; };
  while (!text.empty() && space(text.front()))
    text.remove_prefix(1);
  while (!text.empty() && space(text.back()))
    text.remove_suffix(1);
  net::MatchKey key{};
  if (text.size() != 2 * key.size())
    return Status::error("a match key is 64 hex digits (32 bytes), got " +
                         std::to_string(text.size()) + " characters");
  const auto digit = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
  };
  for (std::size_t i = 0; i < key.size(); ++i) {
    const int hi = digit(text[2 * i]);
    const int lo = digit(text[2 * i + 1]);
    if (hi < 0 || lo < 0)
      return Status::error("a match key is 64 hex digits; character " +
                           std::to_string(hi < 0 ? 2 * i + 1 : 2 * i + 2) + " is not one");
    key[i] = static_cast<std::uint8_t>(hi * 16 + lo);
  }
  return key;
}

Expected<NetplayPlan> netplay_plan(const NetplayArgs& a) {
  const ScenarioInfo* info = find_scenario(a.scenario);
  if (info == nullptr) return Status::error("--scenario: unknown scenario \"" + a.scenario + "\"");
  const std::uint32_t lowest = std::max(2U, info->min_players);
  if (info->max_players < 2)
    return Status::error("--scenario " + a.scenario + " takes no players to play over a network");
  // A peer-to-peer session plays at most 8 (a game server, detsim serve, up to 64).
  const std::uint32_t highest = std::min(info->max_players, max_session_players);
  if (a.players < lowest || a.players > highest)
    return Status::error("--players must be " + std::to_string(lowest) + " .. " +
                         std::to_string(highest) + " (the " + a.scenario + " scenario's range" +
                         (info->max_players > max_session_players
                              ? " in a peer-to-peer match; detsim serve takes up to " +
                                    std::to_string(info->max_players)
                              : std::string()) +
                         "), got " + std::to_string(a.players));
  if (Status s = check_role(a); !s) return s;
  NetplayPlan plan;
  if (a.mode == "rollback") {
    plan.mode = net::SessionMode::rollback;
  } else if (a.mode == "lockstep") {
    plan.mode = net::SessionMode::lockstep;
  } else {
    return Status::error("--mode must be rollback or lockstep, got \"" + a.mode + "\"");
  }
  if (a.partition == "end") {
    plan.partition = net::PartitionPolicy::end_match;
  } else if (a.partition == "pause") {
    plan.partition = net::PartitionPolicy::pause;
  } else if (a.partition == "play-on") {
    plan.partition = net::PartitionPolicy::play_on;
  } else {
    return Status::error("--partition must be end, pause or play-on, got \"" + a.partition + "\"");
  }
  auto bind = net::parse_endpoint(a.bind);
  if (!bind) return Status::error("--bind: " + bind.message());
  plan.bind = bind.value();
  std::vector<std::optional<net::UdpPeer>> by_player(a.players);
  for (const std::string& text : a.peers) {
    auto peer = parse_peer(text, a);
    if (!peer) return peer.status();
    std::optional<net::UdpPeer>& slot = by_player[peer->id];
    if (slot)
      return Status::error("--peer " + std::to_string(peer->id) + " is given twice (" +
                           slot->endpoint.to_string() + " and " + peer->endpoint.to_string() + ")");
    slot = peer.value();
  }
  for (std::uint32_t p = 0; p < a.players; ++p) {
    if (a.spectate) {
      if (by_player[p]) plan.peers.push_back(*by_player[p]);
      continue;
    }
    if (p == a.me) continue;
    if (!by_player[p])
      return Status::error("missing --peer for player " + std::to_string(p) +
                           ": every player but --me " + std::to_string(a.me) +
                           " needs one, e.g. --peer " + std::to_string(p) + "=127.0.0.1:7001");
    plan.peers.push_back(*by_player[p]);
  }
  if (Status s = add_spectators(a, plan); !s) return s;
  if (Status s = read_key(a, plan); !s) return s;
  return plan;
}

const char* key_mismatch(std::string_view reason) {
  if (reason == "not authenticated")
    return "its packets fail authentication: every peer and spectator needs the same --key";
  if (reason == "sealed")
    return "it seals its packets with a --key and this machine has none: give every peer the "
           "same --key";
  if (reason == "not sealed")
    return "it sends unprotected packets (no --key) and this machine has one: give every peer "
           "the same --key";
  return nullptr;
}

std::string protection_line(const NetplayPlan& plan) {
  return plan.match_key
             ? "packets sealed with the match key (ChaCha20-Poly1305, per-direction keys)"
             : "packets NOT protected (no --key): anyone on the path can read and rewrite them; "
               "for a trusted network only";
}

std::string milliseconds(std::uint64_t us) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f ms", static_cast<double>(us) / 1000.0);
  return text;
}

Status write_desync_side(const std::string& path, const replay::Fingerprint& fingerprint,
                         std::uint32_t player, const net::DesyncEvidence* evidence,
                         net::ScenarioGame& game, const char* missing) {
  if (evidence == nullptr) return Status::error(missing);
  auto report = net::desync_report(fingerprint, player, *evidence, game);
  return report ? replay::write_desync_report(path, report.value()) : report.status();
}

}  // namespace detsim::cli
