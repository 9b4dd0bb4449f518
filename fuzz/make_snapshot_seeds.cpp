// Writes the snapshot fuzzer's seed corpus (net_snapshot_fuzz.cpp): valid snapshots of a
// two-player match with 4-byte inputs, compressed and not — at frame 0, mid-match with a frame
// log, and with a player who was away.
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "net/src/snapshot.hpp"

namespace detail = detsim::net::detail;

namespace {

detail::Snapshot snapshot(std::uint64_t frame, std::uint64_t present, bool away) {
  detail::Snapshot s;
  s.frame = frame;
  s.present = present;
  s.input_size = 4;
  const std::uint64_t first = frame == 0 ? 0 : frame - 1;
  for (std::uint32_t p = 0; p < 2; ++p) {
    detail::SnapshotPlayer& player = s.players.emplace_back();
    player.first = first;
    for (std::uint64_t f = first; f < present + 2; ++f)
      for (std::uint32_t k = 0; k < 4; ++k)
        player.inputs.push_back(static_cast<std::uint8_t>(f * 3 + p * 17 + k));
    if (away && p == 1) {
      player.absent_from = frame / 2;
      player.absent_until = present;
    }
  }
  for (std::uint64_t f = 0; f < frame; ++f) {
    s.log.push_back(away && f >= frame / 2 ? 2 : 0);
    for (std::uint32_t k = 0; k < 8; ++k)
      s.log.push_back(static_cast<std::uint8_t>(f + k));
  }
  for (std::uint32_t i = 0; i < 300; ++i)
    s.state.push_back(static_cast<std::uint8_t>(i % 7 == 0 ? i : 0));
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_snapshot_seeds DIR\n");
    return 2;
  }
  int n = 0;
  for (const detail::Snapshot& s :
       {snapshot(0, 0, false), snapshot(40, 52, false), snapshot(120, 130, true)}) {
    for (const bool compress : {false, true}) {
      const std::vector<std::uint8_t> bytes = detail::encode_snapshot(s, compress);
      std::ofstream out(std::string(argv[1]) + "/snapshot" + std::to_string(n++), std::ios::binary);
      out.write(reinterpret_cast<const char*>(bytes.data()),
                static_cast<std::streamsize>(bytes.size()));
    }
  }
  return 0;
}
