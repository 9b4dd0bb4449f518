// libFuzzer target for the rejoin snapshot's decoder (net/src/snapshot.hpp; `scripts/fuzz.sh
// SECONDS snapshot`): the bytes a rejoining session loads after the peer sent them in slices.
//
// The input is decoded as a snapshot of a two-player match with 4-byte inputs and a 256-input
// window, as a session would. Whatever the bytes, decoding must neither crash nor allocate beyond
// its bounds (the sanitizers and libFuzzer's limits catch that). A snapshot it accepts must encode
// again, compressed and not, to bytes that decode to the same snapshot; a violation traps.
#include <cstddef>
#include <cstdint>
#include <span>

#include "net/src/snapshot.hpp"

namespace {

namespace detail = detsim::net::detail;

bool same(const detail::Snapshot& a, const detail::Snapshot& b) {
  if (a.frame != b.frame || a.present != b.present || a.input_size != b.input_size ||
      a.log != b.log || a.state != b.state || a.players.size() != b.players.size())
    return false;
  for (std::size_t p = 0; p < a.players.size(); ++p) {
    const detail::SnapshotPlayer& x = a.players[p];
    const detail::SnapshotPlayer& y = b.players[p];
    if (x.disconnect != y.disconnect || x.absent_from != y.absent_from ||
        x.absent_until != y.absent_until || x.first != y.first || x.inputs != y.inputs)
      return false;
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  auto decoded = detail::decode_snapshot(std::span<const std::uint8_t>(data, size), 2, 4, 256);
  if (!decoded) return 0;
  for (const bool compress : {false, true}) {
    auto back = detail::decode_snapshot(detail::encode_snapshot(*decoded, compress), 2, 4, 256);
    if (!back || !same(*decoded, *back)) __builtin_trap();
  }
  return 0;
}
