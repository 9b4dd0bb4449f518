// Writes the packet fuzzer's seed corpus: one valid datagram of every packet type, and input
// datagrams of every input size the fuzzer decodes with, each four times (net_packet_fuzz.cpp
// has the modes): a leading 0 byte, the plain datagram read as is; 1, its checksum recomputed;
// 2, the packet sealed with the fuzzer's key; 3, its type byte and plaintext body, to be sealed.
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <detsim/net/protection.hpp>
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

// net_packet_fuzz.cpp's key and sessions.
constexpr std::uint64_t sender_session = 0x5E'4D'E7ULL;
constexpr std::uint64_t receiver_session = 0x7EC'E1E7ULL;
detsim::net::MatchKey match_key() {
  detsim::net::MatchKey key{};
  for (std::size_t i = 0; i < key.size(); ++i)
    key[i] = static_cast<std::uint8_t>(i * 7 + 1);
  return key;
}

/// `p` sealed as a session with the fuzzer's key sends it (sequence 7); empty without libsodium.
std::vector<std::uint8_t> sealed(protocol::Packet p, std::size_t input_size) {
  namespace protection = detsim::net::protection;
  std::vector<std::uint8_t> out;
  const bool handshake = p.header.type == protocol::PacketType::hello ||
                         p.header.type == protocol::PacketType::hello_reply;
  p.header.session = sender_session;
  if (!protocol::encode_sealed_plaintext(p, 7, input_size, out)) return {};
  const protection::Key key =
      handshake ? protection::handshake_key(match_key(), sender_session)
                : protection::data_key(match_key(), sender_session, receiver_session);
  if (!protection::seal(key, 7, protocol::sealed_header_size(p.header.type), out)) return {};
  return out;
}

void write(const std::string& path, char mode, const std::vector<std::uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.put(mode);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
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
  p.header.type = protocol::PacketType::state_request;
  p.state_request.offset = 16 * 1024;
  seeds.push_back({"state_request", p, 4});
  p.header.type = protocol::PacketType::state_chunk;
  p.state_chunk.total = 40'000;
  p.state_chunk.offset = 16 * 1024;
  for (std::size_t i = 0; i < protocol::max_state_chunk; ++i)
    p.state_chunk.data.push_back(static_cast<std::uint8_t>(i * 13 + 5));
  seeds.push_back({"state_chunk", p, 4});

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
    if (s.checks >= 2) {  // a player gone, and one taken back after an absence
      q.input.gone = {{1, 95}};
      q.input.back = {{2, 80, 99}};
    }
    seeds.push_back(
        {"input_" + std::to_string(s.input_size) + "x" + std::to_string(s.count), q, s.input_size});
  }

  for (const Seed& s : seeds) {
    std::vector<std::uint8_t> bytes;
    if (!protocol::encode(s.packet, s.input_size, bytes)) {
      std::fprintf(stderr, "make_packet_seeds: %s does not encode\n", s.name.c_str());
      return 1;
    }
    write(dir + "/" + s.name + ".raw", '\0', bytes);
    write(dir + "/" + s.name + ".resealed", '\1', bytes);
    const std::vector<std::uint8_t> sealed_bytes = sealed(s.packet, s.input_size);
    if (sealed_bytes.empty()) continue;  // no libsodium: the plain seeds only
    write(dir + "/" + s.name + ".sealed", '\2', sealed_bytes);
    // The type byte and the plain framing's body (between its header and its checksum).
    std::vector<std::uint8_t> body(
        bytes.begin() + static_cast<std::ptrdiff_t>(protocol::header_size - 1),
        bytes.end() - static_cast<std::ptrdiff_t>(protocol::trailer_size));
    body[0] = bytes[3];
    write(dir + "/" + s.name + ".body", '\3', body);
  }
  return 0;
}
