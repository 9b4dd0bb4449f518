// The server's snapshots (server_snapshot.hpp).
#include "server_snapshot.hpp"

#include <string>

#include <detsim/net/server_protocol.hpp>

#include "envelope.hpp"
#include "wire.hpp"

namespace detsim::net::detail {
namespace {

constexpr EnvelopeMagic server_magic{'D', 'G', 'S', 'N'};

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
                                                 const std::vector<std::uint8_t>* base) {
  std::vector<std::uint8_t> payload;
  payload.reserve(32 + s.unit.size() + s.state.size());
  put(payload, s.frame, 8);
  put(payload, players, 1);
  put(payload, input_size, 1);
  payload.insert(payload.end(), s.unit.begin(), s.unit.end());
  put(payload, s.state.size(), 8);
  payload.insert(payload.end(), s.state.begin(), s.state.end());
  return seal_envelope(
      server_magic, payload, true,
      base != nullptr ? std::span<const std::uint8_t>(*base) : std::span<const std::uint8_t>());
}

Expected<ServerSnapshot> decode_server_snapshot(std::span<const std::uint8_t> bytes,
                                                std::uint32_t players, std::uint32_t input_size,
                                                const std::vector<std::uint8_t>* base) {
  Expected<std::vector<std::uint8_t>> opened = open_envelope(
      server_magic, bytes, max_server_state + 64 + server_protocol::max_unit_size,
      "server snapshot",
      base != nullptr ? std::span<const std::uint8_t>(*base) : std::span<const std::uint8_t>());
  if (!opened) return opened.status();
  std::vector<std::uint8_t>& payload = *opened;
  const std::size_t unit = server_protocol::unit_size(players, input_size);
  const std::size_t header = 8 + 1 + 1;
  if (payload.size() < header + unit + 8) return Status::error("server snapshot: truncated");
  ServerSnapshot s;
  s.frame = snapshot_get(payload, 0, 8);
  if (snapshot_get(payload, 8, 1) != players || snapshot_get(payload, 9, 1) != input_size)
    return Status::error("server snapshot: for " + std::to_string(snapshot_get(payload, 8, 1)) +
                         " players with " + std::to_string(snapshot_get(payload, 9, 1)) +
                         "-byte inputs, this match has " + std::to_string(players) + " with " +
                         std::to_string(input_size));
  if (s.frame > 0xFFFF'FFFFU)
    return Status::error("server snapshot: frame " + std::to_string(s.frame) + " beyond u32");
  s.unit.assign(payload.begin() + static_cast<std::ptrdiff_t>(header),
                payload.begin() + static_cast<std::ptrdiff_t>(header + unit));
  const std::uint64_t size = snapshot_get(payload, header + unit, 8);
  const std::size_t at = header + unit + 8;
  if (size != payload.size() - at)
    return Status::error("server snapshot: the state holds " + std::to_string(payload.size() - at) +
                         " bytes, its header says " + std::to_string(size));
  s.state.assign(payload.begin() + static_cast<std::ptrdiff_t>(at), payload.end());
  return s;
}

}  // namespace detsim::net::detail
