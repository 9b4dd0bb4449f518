// The rejoin snapshot's encoding (snapshot.hpp).
#include "snapshot.hpp"

#include <string>

#if DETSIM_WITH_ZSTD
#include <zstd.h>
#endif

namespace detsim::net::detail {
namespace {

constexpr std::uint8_t magic[4] = {'D', 'S', 'N', 'P'};
constexpr std::size_t envelope_size = 4 + 1 + 8;
constexpr std::uint8_t uncompressed = 0;
constexpr std::uint8_t zstd_compressed = 1;

void put(std::vector<std::uint8_t>& out, std::uint64_t v, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i)
    out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}

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

  std::vector<std::uint8_t> out(magic, magic + 4);
#if DETSIM_WITH_ZSTD
  if (!compress) {
    out.push_back(uncompressed);
    put(out, payload.size(), 8);
    out.insert(out.end(), payload.begin(), payload.end());
    return out;
  }
  out.push_back(zstd_compressed);
  put(out, payload.size(), 8);
  const std::size_t bound = ZSTD_compressBound(payload.size());
  out.resize(envelope_size + bound);
  // Level 3 (zstd's default): a 100 KB world state compresses in about a millisecond. With the
  // frame's checksum, so a snapshot altered on the way fails to decompress instead of loading.
  ZSTD_CCtx* context = ZSTD_createCCtx();
  std::size_t written = 1;
  if (context != nullptr) {
    ZSTD_CCtx_setParameter(context, ZSTD_c_compressionLevel, 3);
    ZSTD_CCtx_setParameter(context, ZSTD_c_checksumFlag, 1);
    written =
        ZSTD_compress2(context, out.data() + envelope_size, bound, payload.data(), payload.size());
    ZSTD_freeCCtx(context);
  }
  if (context != nullptr && !ZSTD_isError(written)) {
    out.resize(envelope_size + written);
    return out;
  }
  out.resize(4);  // out of memory, or a zstd error: send it uncompressed then
#else
  (void)compress;
#endif
  out.push_back(uncompressed);
  put(out, payload.size(), 8);
  out.insert(out.end(), payload.begin(), payload.end());
  return out;
}

Expected<Snapshot> decode_snapshot(std::span<const std::uint8_t> bytes, std::uint32_t players,
                                   std::uint32_t input_size, std::size_t capacity) {
  if (bytes.size() < envelope_size || !std::equal(magic, magic + 4, bytes.begin()))
    return bad("not a snapshot (no DSNP header)");
  Reader envelope(bytes.subspan(4));
  std::uint64_t compression = 0;
  std::uint64_t size = 0;
  envelope.get(compression, 1);
  envelope.get(size, 8);
  if (size > max_snapshot_payload)
    return bad("payload of " + std::to_string(size) + " bytes is over the limit of " +
               std::to_string(max_snapshot_payload));
  const std::span<const std::uint8_t> body = bytes.subspan(envelope_size);
  std::vector<std::uint8_t> payload;
  if (compression == uncompressed) {
    if (body.size() != size) return bad("payload size differs from its header");
    payload.assign(body.begin(), body.end());
  } else if (compression == zstd_compressed) {
#if DETSIM_WITH_ZSTD
    const unsigned long long content = ZSTD_getFrameContentSize(body.data(), body.size());
    if (content != size) return bad("compressed payload size differs from its header");
    payload.resize(static_cast<std::size_t>(size));
    const std::size_t got =
        ZSTD_decompress(payload.data(), payload.size(), body.data(), body.size());
    if (ZSTD_isError(got) || got != size)
      return bad("compressed payload does not decompress (corrupt)");
#else
    return bad("compressed with zstd, and this build has no zstd (DETSIM_WITH_ZSTD=OFF)");
#endif
  } else {
    return bad("unknown compression " + std::to_string(compression));
  }

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
