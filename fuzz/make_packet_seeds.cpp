// Writes the packet fuzzer's seed corpus: one valid datagram of every packet type, and input
// datagrams of every input size the fuzzer decodes with, each twice (a leading 0 byte: read as is;
// a leading 1: checksum recomputed; see net_packet_fuzz.cpp).
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <detsim/net/protocol.hpp>

namespace protocol = detsim::net::protocol;

namespace {

/// `count` inputs of `size` bytes as a game might send them: byte 0 a stick that moves every
/// frame, byte 1 buttons held for 8 frames at a time, the rest rarely changing; delta-coded
/// against an all-zero reference.
std::vector<std::uint8_t> sample_deltas(std::size_t size, std::size_t count) {
  std::vector<std::uint8_t> inputs(size * count);
  for (std::size_t f = 0; f < count; ++f) {
    for (std::size_t i = 0; i < size; ++i) {
      std::size_t v = 0;
      if (i == 0) v = f * 3 + 1;
      if (i == 1) v = f / 8 % 2 == 0 ? 0x05 : 0x00;
      if (i >= 2) v = (f / 32 + i) % 5 == 0 ? i : 0;
      inputs[f * size + i] = static_cast<std::uint8_t>(v);
    }
  }
  std::vector<std::uint8_t> deltas;
  protocol::delta_encode(std::vector<std::uint8_t>(size, 0), inputs, deltas);
  return deltas;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_packet_seeds DIR\n");
    return 2;
  }
  const std::string dir = argv[1];
  struct Seed {
    std::string name;
    protocol::Packet packet;
    std::size_t input_size;
  };
  std::vector<Seed> seeds;
  protocol::Packet p;
  p.header = {protocol::PacketType::hello, 0x1234'5678'9ABC'DEF0ULL, 1};
  p.hello = {0x0123456789ABCDEFULL, 2, 1, 4, 0xC0FFEE};
  seeds.push_back({"hello", p, 4});
  p.hello.player = protocol::spectator_player;
  seeds.push_back({"hello_spectator", p, 4});
  p.header.type = protocol::PacketType::hello_reply;
  p.hello_reply.challenge = 0xC0FFEE'0000C0FFEEULL;
  seeds.push_back({"hello_reply", p, 4});
  p.ping.time_us = 1'000'000;
  p.header.type = protocol::PacketType::ping;
  seeds.push_back({"ping", p, 4});
  p.header.type = protocol::PacketType::pong;
  seeds.push_back({"pong", p, 4});

  struct InputSeed {
    std::size_t input_size;
    std::size_t count;
    std::size_t checks;
  };
  const InputSeed inputs[] = {{4, 0, 0},  {1, 40, 1}, {3, 30, 2},
                              {4, 60, 8}, {64, 6, 3}, {protocol::max_unit_size, 2, 1}};
  for (const InputSeed& s : inputs) {
    protocol::Packet q;
    q.header = {protocol::PacketType::input, 0x1234'5678'9ABC'DEF0ULL, 7};
    q.input.ack_frame = 100;
    q.input.check_ack = 90;
    q.input.current_frame = 104;
    q.input.advantage = -2;
    q.input.start_frame = 101;
    q.input.count = static_cast<std::uint8_t>(s.count);
    q.input.deltas = sample_deltas(s.input_size, s.count);
    for (std::size_t c = 0; c < s.checks; ++c)
      q.input.checks.push_back(
          {static_cast<std::uint32_t>(60 + 10 * c), 0x9E3779B97F4A7C15ULL * c});
    seeds.push_back(
        {"input_" + std::to_string(s.input_size) + "x" + std::to_string(s.count), q, s.input_size});
  }

  for (const Seed& s : seeds) {
    std::vector<std::uint8_t> bytes;
    if (!protocol::encode(s.packet, s.input_size, bytes)) {
      std::fprintf(stderr, "make_packet_seeds: %s does not encode\n", s.name.c_str());
      return 1;
    }
    for (const char mode : {'\0', '\1'}) {
      std::ofstream out(dir + "/" + s.name + (mode == 0 ? ".raw" : ".resealed"), std::ios::binary);
      out.put(mode);
      out.write(reinterpret_cast<const char*>(bytes.data()),
                static_cast<std::streamsize>(bytes.size()));
    }
  }
  return 0;
}
