// The server's snapshots (server_snapshot.hpp).
#include "server_snapshot.hpp"

#include <algorithm>
#include <string>

#include <detsim/net/game.hpp>
#include <detsim/net/server_protocol.hpp>

#include "envelope.hpp"
#include "wire.hpp"

namespace detsim::net::detail {
namespace {

constexpr EnvelopeMagic state_magic{'D', 'G', 'S', 'N'};
constexpr EnvelopeMagic delta_magic{'D', 'G', 'S', 'D'};
constexpr std::size_t payload_header = 8 + 1 + 1;

using wire::put;

std::uint64_t snapshot_get(std::span<const std::uint8_t> bytes, std::size_t at, std::size_t n) {
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < n; ++i)
    v |= std::uint64_t{bytes[at + i]} << (8 * i);
  return v;
}

}  // namespace

std::vector<std::uint8_t> encode_server_snapshot(const ServerSnapshot& s, std::uint32_t players,
                                                 std::uint32_t input_size,
                                                 const std::vector<std::uint8_t>* base,
                                                 Game& game) {
  // The game's delta where it codes one, with the base's delta against itself as the prefix:
  // what did not move is zeros in both, in the same places.
  std::vector<std::uint8_t> delta;
  std::vector<std::uint8_t> prefix;
  const bool coded = base != nullptr && game.encode_delta(s.state, *base, delta) &&
                     game.encode_delta(*base, *base, prefix);
  const std::vector<std::uint8_t>& state = coded ? delta : s.state;
  std::vector<std::uint8_t> payload;
  payload.reserve(32 + s.unit.size() + state.size());
  put(payload, s.frame, 8);
  put(payload, players, 1);
  put(payload, input_size, 1);
  payload.insert(payload.end(), s.unit.begin(), s.unit.end());
  put(payload, state.size(), 8);
  payload.insert(payload.end(), state.begin(), state.end());
  std::span<const std::uint8_t> against;
  if (coded) {
    against = prefix;
  } else if (base != nullptr) {
    against = *base;
  }
  return seal_envelope(coded ? delta_magic : state_magic, payload, true, against,
                       snapshot_compression_level);
}

bool is_game_delta(std::span<const std::uint8_t> bytes) noexcept {
  return bytes.size() >= delta_magic.size() &&
         std::equal(delta_magic.begin(), delta_magic.end(), bytes.begin());
}

Expected<ServerSnapshot> decode_server_snapshot(std::span<const std::uint8_t> bytes,
                                                std::uint32_t players, std::uint32_t input_size,
                                                const std::vector<std::uint8_t>* base, Game& game) {
  // The magic says how the state is coded, and so what the prefix is.
  const bool coded = is_game_delta(bytes);
  std::vector<std::uint8_t> prefix;
  if (coded && base == nullptr)
    return Status::error("server snapshot: a game's delta without a base");
  if (coded && !game.encode_delta(*base, *base, prefix))
    return Status::error(
        "server snapshot: coded by the server's game as a delta (Game::encode_delta), which this "
        "client's game does not code");
  std::span<const std::uint8_t> against;
  if (coded) {
    against = prefix;
  } else if (base != nullptr) {
    against = *base;
  }
  Expected<std::vector<std::uint8_t>> opened = open_envelope(
      coded ? delta_magic : state_magic, bytes,
      max_server_state + 64 + server_protocol::max_unit_size, "server snapshot", against);
  if (!opened) return opened.status();
  std::vector<std::uint8_t>& payload = *opened;
  const std::size_t unit = server_protocol::unit_size(players, input_size);
  if (payload.size() < payload_header + unit + 8)
    return Status::error("server snapshot: truncated");
  ServerSnapshot s;
  s.frame = snapshot_get(payload, 0, 8);
  if (snapshot_get(payload, 8, 1) != players || snapshot_get(payload, 9, 1) != input_size)
    return Status::error("server snapshot: for " + std::to_string(snapshot_get(payload, 8, 1)) +
                         " players with " + std::to_string(snapshot_get(payload, 9, 1)) +
                         "-byte inputs, this match has " + std::to_string(players) + " with " +
                         std::to_string(input_size));
  if (s.frame > 0xFFFF'FFFFU)
    return Status::error("server snapshot: frame " + std::to_string(s.frame) + " beyond u32");
  s.unit.assign(payload.begin() + static_cast<std::ptrdiff_t>(payload_header),
                payload.begin() + static_cast<std::ptrdiff_t>(payload_header + unit));
  const std::uint64_t size = snapshot_get(payload, payload_header + unit, 8);
  const std::size_t at = payload_header + unit + 8;
  if (size != payload.size() - at)
    return Status::error("server snapshot: the state holds " + std::to_string(payload.size() - at) +
                         " bytes, its header says " + std::to_string(size));
  const std::span<const std::uint8_t> state(payload.data() + at, payload.size() - at);
  if (!coded) {
    s.state.assign(state.begin(), state.end());
  } else if (!game.decode_delta(state, *base, s.state)) {
    return Status::error("server snapshot: the game does not decode its delta");
  } else if (s.state.size() > max_server_state) {
    return Status::error("server snapshot: the decoded state holds " +
                         std::to_string(s.state.size()) + " bytes, more than " +
                         std::to_string(max_server_state));
  }
  return s;
}

}  // namespace detsim::net::detail
