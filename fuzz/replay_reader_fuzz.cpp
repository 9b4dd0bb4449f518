// libFuzzer target for the replay reader (clang: scripts/fuzz.sh builds and runs it).
//
// The first input byte picks how the rest is used:
// - even: as a replay file, byte for byte. Most mutations break a checksum, which exercises the
//   framing and the error paths.
// - odd: as a sequence of chunks whose checksums are recomputed first, so that mutations reach the
//   payload parsers (fingerprint, frames, keyframes, end marker) and, through them, verify() and
//   seek() with whatever the fingerprint names.
// Either way a reader that opens is then read completely. The properties checked are the
// sanitizers' (no crash, no undefined behaviour, no leak) and libFuzzer's (-rss_limit_mb,
// -timeout: no unbounded allocation, no hang).
#include <xxhash.h>

#include <cstddef>
#include <cstdint>
#include <vector>

#include <detsim/replay.hpp>

namespace {

/// Recomputes the checksum of every complete chunk after the 16-byte header.
void reseal(std::vector<std::uint8_t>& b) {
  std::size_t at = 16;
  while (at + 16 <= b.size()) {
    const std::uint32_t length =
        static_cast<std::uint32_t>(b[at + 4]) | static_cast<std::uint32_t>(b[at + 5]) << 8 |
        static_cast<std::uint32_t>(b[at + 6]) << 16 | static_cast<std::uint32_t>(b[at + 7]) << 24;
    if (std::size_t{length} + 16 > b.size() - at) return;
    const std::uint64_t sum = XXH3_64bits(b.data() + at, 8 + std::size_t{length});
    for (int i = 0; i < 8; ++i)
      b[at + 8 + length + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(sum >> (8 * i));
    at += std::size_t{length} + 16;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  std::vector<std::uint8_t> bytes(data + 1, data + size);
  const bool resealed = (data[0] & 1U) != 0;
  if (resealed) reseal(bytes);
  auto reader = detsim::replay::ReplayReader::from_bytes(std::move(bytes), "fuzz.dsr");
  if (!reader) return 0;
  const detsim::replay::ReplayReader& r = reader.value();
  std::uint64_t frames = 0;
  (void)r.for_each_frame(1, r.frame_count(), [&frames](const detsim::replay::FrameRecord&) {
    ++frames;
    return true;
  });
  for (const detsim::replay::KeyframeInfo& k : r.keyframes())
    (void)r.keyframe_state(k);
  // Re-simulation is bounded: only short recordings of small scenes are verified and sought.
  const detsim::replay::Fingerprint& f = r.fingerprint();
  if (resealed && r.frame_count() <= 64 && f.params.count <= 64) {
    (void)detsim::replay::verify(r);
    (void)detsim::replay::seek(r, r.frame_count() / 2);
  }
  return 0;
}
