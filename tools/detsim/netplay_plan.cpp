// The netplay command line checked into a NetplayPlan (netplay_plan.hpp), for both roles: a player
// names every other player with --peer and may serve spectators (--spectator); a spectator
// (--spectate) names only the player that serves it.
#include "netplay_plan.hpp"

#include <algorithm>
#include <cstdio>
#include <optional>

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
    if (a.spectators.size() > max_spectators)
      return Status::error("at most " + std::to_string(max_spectators) +
                           " --spectator addresses, got " + std::to_string(a.spectators.size()));
    return Status::success();
  }
  if (a.me_given)
    return Status::error("--me cannot be combined with --spectate: a spectator plays no player");
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

}  // namespace

Expected<NetplayPlan> netplay_plan(const NetplayArgs& a) {
  if (a.players < 2 || a.players > 8)
    return Status::error("--players must be 2 .. 8 (the arena scenario's range), got " +
                         std::to_string(a.players));
  if (Status s = check_role(a); !s) return s;
  NetplayPlan plan;
  if (a.mode == "rollback") {
    plan.mode = net::SessionMode::rollback;
  } else if (a.mode == "lockstep") {
    plan.mode = net::SessionMode::lockstep;
  } else {
    return Status::error("--mode must be rollback or lockstep, got \"" + a.mode + "\"");
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
  return plan;
}

std::string milliseconds(std::uint64_t us) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f ms", static_cast<double>(us) / 1000.0);
  return text;
}

}  // namespace detsim::cli
