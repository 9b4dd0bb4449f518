// libFuzzer target for the session wire protocol decoder (clang: `scripts/fuzz.sh SECONDS packet`
// builds and runs it).
//
// The first input byte picks how the rest is used:
// - even: as a datagram, byte for byte. Most mutations break the checksum, which exercises the
//   length, magic, version, type and checksum checks;
// - odd: the last 4 bytes are replaced by the checksum of the bytes before them first, so that
//   mutations reach the body decoder (fields, run-length tokens, checks).
// The datagram is decoded with input sizes 1, 3, 4 and 64 (players' inputs) and max_unit_size
// (spectator frames). Whenever it decodes, the packet must re-encode, that encoding must decode to
// the same packet, be no longer than the datagram (the encoder's tokens are the shortest, and the
// decoder accepts frame varints only in their shortest form), equal it byte for byte for every
// type but input (whose tokens the decoder accepts in any split), and encode again to itself. A
// violation traps; the sanitizers and libFuzzer's limits catch the rest.
#include <xxhash.h>

#include <cstddef>
#include <cstdint>
#include <vector>

#include <detsim/net/protocol.hpp>

namespace {

namespace protocol = detsim::net::protocol;

void reseal(std::vector<std::uint8_t>& b) {
  if (b.size() < 4) return;
  const std::size_t n = b.size() - 4;
  const auto sum = static_cast<std::uint32_t>(XXH3_64bits(b.data(), n));
  for (std::size_t i = 0; i < 4; ++i)
    b[n + i] = static_cast<std::uint8_t>(sum >> (8 * i));
}

bool same(const protocol::Packet& a, const protocol::Packet& b) {
  if (a.header.type != b.header.type || a.header.session != b.header.session ||
      a.header.sequence != b.header.sequence)
    return false;
  switch (a.header.type) {
    case protocol::PacketType::hello:
      return a.hello.fingerprint == b.hello.fingerprint && a.hello.players == b.hello.players &&
             a.hello.player == b.hello.player && a.hello.input_size == b.hello.input_size &&
             a.hello.challenge == b.hello.challenge;
    case protocol::PacketType::hello_reply:
      return a.hello_reply.challenge == b.hello_reply.challenge;
    case protocol::PacketType::input:
      return a.input.ack_frame == b.input.ack_frame && a.input.check_ack == b.input.check_ack &&
             a.input.current_frame == b.input.current_frame &&
             a.input.advantage == b.input.advantage && a.input.start_frame == b.input.start_frame &&
             a.input.count == b.input.count && a.input.deltas == b.input.deltas &&
             a.input.checks == b.input.checks && a.input.held_frame == b.input.held_frame &&
             a.input.gone == b.input.gone;
    case protocol::PacketType::ping:
    case protocol::PacketType::pong:
      return a.ping.time_us == b.ping.time_us;
  }
  return false;
}

void check(const std::vector<std::uint8_t>& bytes, std::size_t input_size) {
  protocol::Packet packet;
  if (protocol::decode(bytes, input_size, packet) != protocol::DecodeError::none) return;
  std::vector<std::uint8_t> again;
  if (!protocol::encode(packet, input_size, again)) __builtin_trap();
  protocol::Packet back;
  if (protocol::decode(again, input_size, back) != protocol::DecodeError::none) __builtin_trap();
  if (!same(packet, back)) __builtin_trap();
  if (again.size() > bytes.size()) __builtin_trap();
  if (packet.header.type != protocol::PacketType::input && again != bytes) __builtin_trap();
  std::vector<std::uint8_t> third;
  if (!protocol::encode(back, input_size, third) || third != again) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  std::vector<std::uint8_t> bytes(data + 1, data + size);
  if ((data[0] & 1U) != 0) reseal(bytes);
  for (const std::size_t input_size :
       {std::size_t{1}, std::size_t{3}, std::size_t{4}, std::size_t{64}, protocol::max_unit_size})
    check(bytes, input_size);
  return 0;
}
