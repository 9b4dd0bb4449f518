// libFuzzer target for the session wire protocol decoder (clang: `scripts/fuzz.sh SECONDS packet`
// builds and runs it).
//
// The first input byte picks how the rest is used; bit 1 clear, the plain framing:
// - bit 0 clear: as a datagram, byte for byte. Most mutations break the checksum, which exercises
//   the length, magic, version, type and checksum checks;
// - bit 0 set: the last 4 bytes are replaced by the checksum of the bytes before them first, so
//   that mutations reach the body decoder (fields, run-length tokens, checks).
// The datagram is decoded with input sizes 1, 3, 4 and 64 (players' inputs) and max_unit_size
// (spectator frames). Whenever it decodes, the packet must re-encode, that encoding must decode to
// the same packet, be no longer than the datagram (the encoder's tokens are the shortest, and the
// decoder accepts frame varints only in their shortest form), equal it byte for byte for every
// type but input (whose tokens the decoder accepts in any split), and encode again to itself.
//
// Bit 1 set, the sealed framing (protocol version 5 and later), with a fixed match key:
// - bit 0 clear: as a sealed datagram, through what a session does on receipt (header, replay
//   window, tag; protection.hpp): the rejection paths, and the window's bookkeeping for the
//   seeds' own sealed bytes, which open;
// - bit 0 set: the rest is a sealed header's type byte and a plaintext body, sealed with the key
//   (as a peer holding the key may send anything): it must open to exactly that body, and the body
//   is then held to the same round trip as above, through the sealed encoder.
// A violation traps; the sanitizers and libFuzzer's limits catch the rest.
#include <xxhash.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <detsim/net/protection.hpp>
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
             a.input.gone == b.input.gone && a.input.back == b.input.back;
    case protocol::PacketType::ping:
    case protocol::PacketType::pong:
      return a.ping.time_us == b.ping.time_us;
    case protocol::PacketType::state_request:
      return a.state_request.offset == b.state_request.offset;
    case protocol::PacketType::state_chunk:
      return a.state_chunk.total == b.state_chunk.total &&
             a.state_chunk.offset == b.state_chunk.offset &&
             a.state_chunk.data == b.state_chunk.data;
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

// The fuzzer's match key, and the sender and receiver sessions of its data key (make_packet_seeds
// seals its sealed seeds with the same).
constexpr std::uint64_t sender_session = 0x5E'4D'E7ULL;
constexpr std::uint64_t receiver_session = 0x7EC'E1E7ULL;
detsim::net::MatchKey match_key() {
  detsim::net::MatchKey key{};
  for (std::size_t i = 0; i < key.size(); ++i)
    key[i] = static_cast<std::uint8_t>(i * 7 + 1);
  return key;
}

/// A receiver's path for a sealed datagram: the packet, or false when it is dropped.
bool receive_sealed(const std::vector<std::uint8_t>& bytes, std::size_t input_size,
                    protocol::Packet& packet) {
  namespace protection = detsim::net::protection;
  protocol::SealedHeader h;
  if (protocol::decode_sealed_header(bytes, h) != protocol::DecodeError::none) return false;
  const bool handshake =
      h.type == protocol::PacketType::hello || h.type == protocol::PacketType::hello_reply;
  const protection::Key key =
      handshake ? protection::handshake_key(match_key(), h.session)
                : protection::data_key(match_key(), sender_session, receiver_session);
  protection::ReplayWindow window;
  const std::uint64_t sequence = window.expand(h.sequence);
  if (!window.fresh(sequence)) __builtin_trap();  // an empty window refuses nothing
  std::vector<std::uint8_t> body;
  if (!protection::open(key, sequence, h.size, bytes, body)) return false;
  window.accept(sequence);
  if (window.fresh(sequence)) __builtin_trap();  // a duplicate must now be refused
  packet.header.session = h.session;
  return protocol::decode_body(h.type, body, input_size, packet) == protocol::DecodeError::none;
}

/// `type` and `body` sealed with the fuzzer's keys (sequence 7), as a peer with the key would.
std::vector<std::uint8_t> seal_raw(std::uint8_t type, const std::uint8_t* body, std::size_t size) {
  namespace protection = detsim::net::protection;
  std::vector<std::uint8_t> d = {
      protocol::magic0, protocol::sealed_magic1, protocol::version, type, 7, 0, 0, 0};
  const auto t = static_cast<protocol::PacketType>(type);
  const bool handshake = t == protocol::PacketType::hello || t == protocol::PacketType::hello_reply;
  if (handshake)
    for (std::size_t i = 0; i < 8; ++i)
      d.push_back(static_cast<std::uint8_t>(sender_session >> (8 * i)));
  const std::size_t header = d.size();
  d.insert(d.end(), body, body + size);
  const protection::Key key =
      handshake ? protection::handshake_key(match_key(), sender_session)
                : protection::data_key(match_key(), sender_session, receiver_session);
  if (!protection::seal(key, 7, header, d)) __builtin_trap();
  std::vector<std::uint8_t> opened;
  if (!protection::open(key, 7, header, d, opened)) __builtin_trap();
  if (!std::equal(opened.begin(), opened.end(), body, body + size) || opened.size() != size)
    __builtin_trap();
  return d;
}

// A body sealed with the key that the receiver takes must round-trip through the sealed encoder.
void check_sealed(const std::vector<std::uint8_t>& bytes, std::size_t input_size) {
  protocol::Packet packet;
  if (!receive_sealed(bytes, input_size, packet)) return;
  std::vector<std::uint8_t> again;
  if (!protocol::encode_sealed_plaintext(packet, 7, input_size, again)) __builtin_trap();
  const std::size_t header = protocol::sealed_header_size(packet.header.type);
  protocol::Packet back;
  if (protocol::decode_body(packet.header.type,
                            std::span<const std::uint8_t>(again).subspan(header), input_size,
                            back) != protocol::DecodeError::none)
    __builtin_trap();
  back.header = packet.header;
  if (!same(packet, back)) __builtin_trap();
  if (again.size() + protocol::sealed_tag_size > bytes.size()) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  if ((data[0] & 2U) != 0) {
    if (!detsim::net::protection::available()) return 0;
    const bool raw = (data[0] & 1U) == 0;
    if (raw) {
      const std::vector<std::uint8_t> bytes(data + 1, data + size);
      for (const std::size_t input_size : {std::size_t{4}, protocol::max_unit_size}) {
        protocol::Packet packet;
        // Only a seed's exact sealed bytes open; anything else the fuzzer made must not.
        (void)receive_sealed(bytes, input_size, packet);
      }
      return 0;
    }
    if (size < 2 || size - 2 > detsim::net::max_datagram) return 0;
    const std::vector<std::uint8_t> bytes = seal_raw(data[1], data + 2, size - 2);
    for (const std::size_t input_size : {std::size_t{1}, std::size_t{4}, protocol::max_unit_size})
      check_sealed(bytes, input_size);
    return 0;
  }
  std::vector<std::uint8_t> bytes(data + 1, data + size);
  if ((data[0] & 1U) != 0) reseal(bytes);
  for (const std::size_t input_size :
       {std::size_t{1}, std::size_t{3}, std::size_t{4}, std::size_t{64}, protocol::max_unit_size})
    check(bytes, input_size);
  return 0;
}
