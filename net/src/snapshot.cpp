// The rejoin snapshot's encoding (snapshot.hpp).
#include "snapshot.hpp"

#include <string>

#include "envelope.hpp"
#include "wire.hpp"

namespace detsim::net::detail {
namespace {

constexpr EnvelopeMagic rejoin_magic{'D', 'S', 'N', 'P'};

using wire::put;

class Reader {
 public:
  explicit Reader(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}
  bool get(std::uint64_t& v, std::size_t n) {
    if (bytes_.size() - at_ < n) return false;
    v = 0;
    for (std::size_t i = 0; i < n; ++i)
      v |= std::uint64_t{bytes_[at_ + i]} << (8 * i);
    at_ += n;
    return true;
  }
  /// The next `n` bytes, or nothing when fewer are left.
  bool take(std::span<const std::uint8_t>& out, std::uint64_t n) {
    if (bytes_.size() - at_ < n) return false;
    out = bytes_.subspan(at_, static_cast<std::size_t>(n));
    at_ += static_cast<std::size_t>(n);
    return true;
  }
  [[nodiscard]] bool at_end() const { return at_ == bytes_.size(); }

 private:
  std::span<const std::uint8_t> bytes_;
  std::size_t at_ = 0;
};

Status bad(const std::string& what) {
  return Status::error(what);
}

}  // namespace

std::vector<std::uint8_t> encode_snapshot(const Snapshot& s, bool compress) {
  std::vector<std::uint8_t> payload;
  put(payload, s.frame, 8);
  put(payload, s.present, 8);
  put(payload, s.players.size(), 1);
  put(payload, s.input_size, 1);
  for (const SnapshotPlayer& p : s.players) {
    put(payload, p.disconnect, 8);
    put(payload, p.absent_from, 8);
    put(payload, p.absent_until, 8);
    put(payload, p.first, 8);
    put(payload, s.input_size == 0 ? 0 : p.inputs.size() / s.input_size, 4);
    payload.insert(payload.end(), p.inputs.begin(), p.inputs.end());
  }
  put(payload, s.log.size(), 8);
  payload.insert(payload.end(), s.log.begin(), s.log.end());
  put(payload, s.state.size(), 8);
  payload.insert(payload.end(), s.state.begin(), s.state.end());

  return seal_envelope(rejoin_magic, payload, compress);
}

Expected<Snapshot> decode_snapshot(std::span<const std::uint8_t> bytes, std::uint32_t players,
                                   std::uint32_t input_size, std::size_t capacity) {
  Expected<std::vector<std::uint8_t>> opened =
      open_envelope(rejoin_magic, bytes, max_snapshot_payload, "snapshot");
  if (!opened) return opened.status();
  const std::vector<std::uint8_t>& payload = *opened;
  Reader in(payload);
  Snapshot s;
  std::uint64_t count_players = 0;
  std::uint64_t size_of_input = 0;
  if (!in.get(s.frame, 8) || !in.get(s.present, 8) || !in.get(count_players, 1) ||
      !in.get(size_of_input, 1))
    return bad("truncated header");
  if (count_players != players || size_of_input != input_size)
    return bad("for " + std::to_string(count_players) + " players with " +
               std::to_string(size_of_input) + "-byte inputs, this match has " +
               std::to_string(players) + " with " + std::to_string(input_size));
  if (s.frame > max_snapshot_payload)  // each frame has a log entry of at least 2 bytes
    return bad("state frame " + std::to_string(s.frame) + " is beyond any payload's log");
  if (s.present < s.frame || s.present - s.frame > capacity)
    return bad("present frame " + std::to_string(s.present) + " is not within " +
               std::to_string(capacity) + " frames after the state's frame " +
               std::to_string(s.frame));
  s.input_size = input_size;
  const std::uint64_t first = s.frame == 0 ? 0 : s.frame - 1;
  s.players.resize(players);
  for (std::uint32_t p = 0; p < players; ++p) {
    SnapshotPlayer& player = s.players[p];
    std::uint64_t count = 0;
    std::span<const std::uint8_t> inputs;
    if (!in.get(player.disconnect, 8) || !in.get(player.absent_from, 8) ||
        !in.get(player.absent_until, 8) || !in.get(player.first, 8) || !in.get(count, 4))
      return bad("truncated at player " + std::to_string(p));
    if (player.absent_from > player.absent_until || player.absent_until > s.present)
      return bad("player " + std::to_string(p) + "'s absence " +
                 std::to_string(player.absent_from) + " .. " + std::to_string(player.absent_until) +
                 " is not an interval before the present");
    if (player.first != first)
      return bad("player " + std::to_string(p) + "'s inputs start at frame " +
                 std::to_string(player.first) + ", not " + std::to_string(first));
    if (count > capacity)
      return bad("player " + std::to_string(p) + " has " + std::to_string(count) +
                 " inputs, more than a session holds (" + std::to_string(capacity) + ")");
    if (player.disconnect != ~std::uint64_t{0} && player.disconnect > first + count)
      return bad("player " + std::to_string(p) + "'s disconnect frame is beyond its inputs");
    if (!in.take(inputs, count * input_size))
      return bad("truncated in player " + std::to_string(p) + "'s inputs");
    player.inputs.assign(inputs.begin(), inputs.end());
  }
  std::uint64_t log_size = 0;
  std::span<const std::uint8_t> log;
  if (!in.get(log_size, 8) || !in.take(log, log_size)) return bad("truncated frame log");
  const std::uint64_t unit = 1 + std::uint64_t{players} * input_size;
  if (log_size != s.frame * unit)
    return bad("the frame log holds " + std::to_string(log_size) + " bytes, not " +
               std::to_string(s.frame) + " frames of " + std::to_string(unit));
  s.log.assign(log.begin(), log.end());
  std::uint64_t state_size = 0;
  std::span<const std::uint8_t> state;
  if (!in.get(state_size, 8) || !in.take(state, state_size)) return bad("truncated state");
  if (!in.at_end()) return bad("bytes after the state");
  s.state.assign(state.begin(), state.end());
  return s;
}

}  // namespace detsim::net::detail
