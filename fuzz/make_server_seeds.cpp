// Writes the server fuzzer's seed corpus (net_server_fuzz.cpp has the modes): one valid datagram
// of every packet type as a datagram (a leading 0 byte) and with its checksum to recompute (1),
// and strangers' sequences (3): connects for the match's game and another, inputs, updates and
// leaves under made-up tokens, garbage.
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <detsim/net/server_protocol.hpp>

namespace sp = detsim::net::server_protocol;

namespace {

std::vector<sp::Packet> samples() {
  std::vector<sp::Packet> out;
  sp::Packet p;
  p.header = {sp::PacketType::connect, 0, 1};
  p.connect = {0xF022, 0x1234, sp::any_seat};
  out.push_back(p);
  p = {};
  p.header = {sp::PacketType::welcome, 0x77, 1};
  p.welcome.nonce = 0x1234;
  p.welcome.player = 0;
  p.welcome.players = 1;
  p.welcome.input_size = 3;
  p.welcome.frame_us = 16'667;
  p.welcome.frames = 40;
  p.welcome.description = {'t', 'e', 's', 't'};
  out.push_back(p);
  p = {};
  p.header = {sp::PacketType::reject, 0, 2};
  p.reject = {0x1234, sp::RejectReason::full};
  out.push_back(p);
  p = {};
  p.header = {sp::PacketType::input, 0x77, 3};
  p.input.ack = 10;
  p.input.snapshot_ack = 0;
  p.input.time_ms = 100;
  p.input.start = 12;
  p.input.count = 2;
  p.input.inputs = {3, 1, 2, 3, 1, 2};
  out.push_back(p);
  p = {};
  p.header = {sp::PacketType::update, 0x77, 4};
  p.update.frame = 14;
  p.update.input_ack = 14;
  p.update.start = 10;
  p.update.count = 2;
  p.update.units = {0, 2, 1, 2, 0, 3, 1, 2};
  p.update.hash = 0xABCD;
  out.push_back(p);
  p = {};
  p.header = {sp::PacketType::snapshot, 0x77, 5};
  p.snapshot = {14, 0, 0xABCD, 10, 0, std::vector<std::uint8_t>(10, 0x42)};
  out.push_back(p);
  p = {};
  p.header = {sp::PacketType::leave, 0x77, 6};
  out.push_back(p);
  return out;
}

void write(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()),
             static_cast<std::streamsize>(bytes.size()));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_server_seeds DIR\n");
    return 2;
  }
  const std::string dir = argv[1];
  int n = 0;
  std::vector<std::uint8_t> sequence = {3};
  for (const sp::Packet& p : samples()) {
    for (const sp::Sizes sizes : {sp::Sizes{1, 3}, sp::Sizes{3, 4}}) {
      std::vector<std::uint8_t> bytes;
      if (!sp::encode(p, sizes, bytes)) continue;  // inputs and units of the other size
      for (const std::uint8_t mode : {std::uint8_t{0}, std::uint8_t{1}}) {
        std::vector<std::uint8_t> seed = {mode};
        seed.insert(seed.end(), bytes.begin(), bytes.end());
        write(dir + "/seed_" + std::to_string(n++), seed);
      }
      if (sizes.players == 1 && bytes.size() < 256) {
        sequence.push_back(static_cast<std::uint8_t>(bytes.size()));
        sequence.insert(sequence.end(), bytes.begin(), bytes.end());
      }
    }
  }
  write(dir + "/seed_" + std::to_string(n++), sequence);
  std::printf("make_server_seeds: wrote %d seeds to %s\n", n, dir.c_str());
  return 0;
}
