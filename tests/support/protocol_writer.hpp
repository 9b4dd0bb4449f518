// Shared helpers of the wire protocol tests (net_protocol_test.cpp, net_protocol_decode_test.cpp):
// an independent writer of the layout in protocol.hpp (little-endian integers, LEB128 varints,
// zigzag frame differences, run-length tokens) sealed with XXH3, the exact sizes of its parts as
// functions of a packet's values, sample packets and a field-by-field packet comparison.
//
// Nothing here calls encode() or decode(): expected bytes and sizes come from the layout alone.
#pragma once

#include <xxhash.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/net/protocol.hpp>

namespace detsim::net::protocol::test_support {

using Bytes = std::vector<std::uint8_t>;

inline constexpr std::uint32_t max_u32 = std::numeric_limits<std::uint32_t>::max();
inline constexpr std::uint64_t max_u64 = std::numeric_limits<std::uint64_t>::max();
/// The most bytes a varint of the layout takes (35 bits: a u32, or a zigzag-coded difference).
inline constexpr std::size_t max_varint_size = 5;
inline constexpr std::array<std::size_t, 5> fuzz_input_sizes = {1, 3, 4, 64, max_unit_size};

constexpr std::uint8_t byte(std::uint64_t v) {
  return static_cast<std::uint8_t>(v);
}

// --- Varints ------------------------------------------------------------------------------------

/// Bytes of the LEB128 varint of `v`: one per 7-bit group up to the highest non-zero one.
constexpr std::size_t varint_size(std::uint64_t v) {
  std::size_t n = 1;
  while (n < 10 && (v >> (7 * n)) != 0)
    ++n;
  return n;
}
static_assert(varint_size(0) == 1 && varint_size(127) == 1 && varint_size(128) == 2);
static_assert(varint_size((std::uint64_t{1} << 28) - 1) == 4);
static_assert(varint_size(std::uint64_t{1} << 28) == 5 && varint_size(max_u32) == 5);

/// The zigzag code of d = frame - ack: 2d for d >= 0, -2d - 1 for d < 0.
constexpr std::uint64_t zigzag(std::uint32_t frame, std::uint32_t ack) {
  return frame >= ack ? 2 * std::uint64_t{frame - ack} : 2 * std::uint64_t{ack - frame} - 1;
}
static_assert(zigzag(5, 5) == 0 && zigzag(4, 5) == 1 && zigzag(6, 5) == 2 && zigzag(3, 5) == 3);
static_assert(zigzag(0, max_u32) == 2 * std::uint64_t{max_u32} - 1);
static_assert(zigzag(max_u32, 0) == 2 * std::uint64_t{max_u32});

/// Bytes of a frame field written against `ack`.
constexpr std::size_t frame_size(std::uint32_t frame, std::uint32_t ack) {
  return varint_size(zigzag(frame, ack));
}

// --- An independent writer of the documented layout ----------------------------------------------

class Writer {
 public:
  Writer& u8(std::uint64_t v) { return le(v, 1); }
  Writer& u16(std::uint64_t v) { return le(v, 2); }
  Writer& u32(std::uint64_t v) { return le(v, 4); }
  Writer& u64(std::uint64_t v) { return le(v, 8); }
  /// LEB128: the 7-bit groups of `v`, low first, every byte but the last with its top bit set.
  Writer& varint(std::uint64_t v) {
    const std::size_t n = varint_size(v);
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint64_t group = (v >> (7 * i)) & 0x7FU;
      bytes_.push_back(byte(i + 1 < n ? group | 0x80U : group));
    }
    return *this;
  }
  /// A frame field: the zigzag-coded difference from ack_frame as a varint.
  Writer& frame(std::uint32_t value, std::uint32_t ack) { return varint(zigzag(value, ack)); }
  Writer& raw(std::span<const std::uint8_t> b) {
    bytes_.insert(bytes_.end(), b.begin(), b.end());
    return *this;
  }
  Writer& header(std::uint8_t type, std::uint64_t session, std::uint16_t sequence) {
    return u8('D').u8('N').u8(version).u8(type).u64(session).u16(sequence);
  }
  /// The bytes so far followed by the trailer: the low 32 bits of XXH3-64 over them.
  [[nodiscard]] Bytes sealed() const {
    Bytes out = bytes_;
    const auto sum = static_cast<std::uint32_t>(XXH3_64bits(out.data(), out.size()));
    for (std::size_t i = 0; i < 4; ++i)
      out.push_back(static_cast<std::uint8_t>(sum >> (8 * i)));
    return out;
  }
  [[nodiscard]] const Bytes& bytes() const { return bytes_; }

 private:
  Writer& le(std::uint64_t v, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i)
      bytes_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
    return *this;
  }
  Bytes bytes_;
};

/// Replaces the last 4 bytes of `b` with the checksum of the bytes before them.
inline void reseal(Bytes& b) {
  if (b.size() < 4) return;
  const std::size_t n = b.size() - 4;
  const auto sum = static_cast<std::uint32_t>(XXH3_64bits(b.data(), n));
  for (std::size_t i = 0; i < 4; ++i)
    b[n + i] = static_cast<std::uint8_t>(sum >> (8 * i));
}

/// Zero-run tokens for `n` zero bytes, by the token definition: t >= 128 is t - 127 zeros.
inline Bytes zero_tokens(std::size_t n) {
  Bytes out;
  while (n > 0) {
    const std::size_t k = std::min<std::size_t>(n, 128);
    out.push_back(static_cast<std::uint8_t>(127 + k));
    n -= k;
  }
  return out;
}

/// Literal tokens for `bytes`, by the token definition: t < 128 is t + 1 literal bytes.
inline Bytes literal_tokens(std::span<const std::uint8_t> bytes) {
  Bytes out;
  for (std::size_t at = 0; at < bytes.size(); at += 128) {
    const std::size_t k = std::min<std::size_t>(bytes.size() - at, 128);
    out.push_back(static_cast<std::uint8_t>(k - 1));
    out.insert(out.end(), bytes.begin() + static_cast<std::ptrdiff_t>(at),
               bytes.begin() + static_cast<std::ptrdiff_t>(at + k));
  }
  return out;
}

/// The size bound the encoder keeps: never longer than all-literal tokens.
inline std::size_t literal_bound(std::size_t length) {
  return length + (length + 127) / 128;
}

/// The bytes of an input packet whose deltas are run-length coded as `tokens`.
inline Bytes input_bytes(const Packet& p, std::span<const std::uint8_t> tokens) {
  const InputBody& b = p.input;
  Writer w;
  w.header(static_cast<std::uint8_t>(PacketType::input), p.header.session, p.header.sequence)
      .varint(b.ack_frame)
      .frame(b.check_ack, b.ack_frame)
      .frame(b.current_frame, b.ack_frame)
      .u8(static_cast<std::uint8_t>(b.advantage))
      .frame(b.start_frame, b.ack_frame)
      .u8(b.count)
      .frame(b.held_frame, b.ack_frame)
      .u8(b.gone.size() | b.back.size() << 4);
  for (const GoneReport& g : b.gone)
    w.u8(g.player).frame(g.frame, b.ack_frame);
  for (const BackReport& r : b.back)
    w.u8(r.player).frame(r.from, b.ack_frame).frame(r.until, b.ack_frame);
  w.raw(tokens).u8(b.checks.size());
  for (const HashCheck& c : b.checks)
    w.frame(c.frame, b.ack_frame).u64(c.hash);
  return w.sealed();
}

/// The bytes of a hello, hello_reply, ping, pong, state_request or state_chunk packet.
inline Bytes plain_bytes(const Packet& p) {
  Writer w;
  w.header(static_cast<std::uint8_t>(p.header.type), p.header.session, p.header.sequence);
  switch (p.header.type) {
    case PacketType::hello:
      w.u64(p.hello.fingerprint)
          .u8(p.hello.players)
          .u8(p.hello.player)
          .u8(p.hello.input_size)
          .u64(p.hello.challenge);
      break;
    case PacketType::hello_reply:
      w.u64(p.hello_reply.challenge);
      break;
    case PacketType::ping:
    case PacketType::pong:
      w.u64(p.ping.time_us);
      break;
    case PacketType::state_request:
      w.varint(p.state_request.offset);
      break;
    case PacketType::state_chunk:
      w.varint(p.state_chunk.total)
          .varint(p.state_chunk.offset)
          .varint(p.state_chunk.data.size())
          .raw(p.state_chunk.data);
      break;
    case PacketType::input:
      ADD_FAILURE() << "plain_bytes of an input packet";
      break;
  }
  return w.sealed();
}

// --- Exact sizes of an input packet's parts
// -------------------------------------------------------

/// held_frame, the list counts, the gone reports and the back reports.
inline std::size_t status_size(const InputBody& b) {
  std::size_t n = frame_size(b.held_frame, b.ack_frame) + 1;
  for (const GoneReport& g : b.gone)
    n += 1 + frame_size(g.frame, b.ack_frame);
  for (const BackReport& r : b.back)
    n += 1 + frame_size(r.from, b.ack_frame) + frame_size(r.until, b.ack_frame);
  return n;
}

/// ack_frame, check_ack, current_frame, advantage, start_frame, count, held_frame and the gone
/// reports: everything before the deltas.
inline std::size_t input_fields_size(const InputBody& b) {
  return varint_size(b.ack_frame) + frame_size(b.check_ack, b.ack_frame) +
         frame_size(b.current_frame, b.ack_frame) + 1 + frame_size(b.start_frame, b.ack_frame) + 1 +
         status_size(b);
}

/// The checks count and the checks.
inline std::size_t checks_size(const InputBody& b) {
  std::size_t n = 1;
  for (const HashCheck& c : b.checks)
    n += frame_size(c.frame, b.ack_frame) + 8;
  return n;
}

/// The datagram of `b` when its deltas take `tokens` bytes.
inline std::size_t input_datagram_size(const InputBody& b, std::size_t tokens) {
  return header_size + input_fields_size(b) + tokens + checks_size(b) + trailer_size;
}

/// The run-length coded deltas inside `encoded`, the encoding of `p`.
inline std::span<const std::uint8_t> rle_part(const Bytes& encoded, const Packet& p) {
  const std::size_t begin = header_size + input_fields_size(p.input);
  const std::size_t end = encoded.size() - trailer_size - checks_size(p.input);
  EXPECT_LE(begin, end) << "not the encoding of this packet";
  return std::span<const std::uint8_t>(encoded).subspan(begin, std::max(begin, end) - begin);
}

// --- Packets ------------------------------------------------------------------------------------

/// Every input size a player uses, and some of the larger whole-frame units a host sends
/// spectators (up to max_unit_size).
inline std::vector<std::size_t> all_sizes() {
  std::vector<std::size_t> sizes;
  for (std::size_t size = 1; size <= max_input_size; ++size)
    sizes.push_back(size);
  for (const std::size_t size : {65U, 100U, 128U, 255U, 256U, 257U, 511U, 512U})
    sizes.push_back(size);
  sizes.push_back(max_unit_size);
  return sizes;
}

inline Packet make(PacketType type, std::uint64_t session, std::uint16_t sequence) {
  Packet p;
  p.header = {type, session, sequence};
  return p;
}

/// An input packet whose frames lie a few frames apart (one varint byte each).
inline Packet input_packet(std::uint8_t count, Bytes deltas, std::vector<HashCheck> checks = {}) {
  Packet p = make(PacketType::input, 0x01020304, 0x0506);
  p.input.ack_frame = 11;
  p.input.check_ack = 22;
  p.input.current_frame = 33;
  p.input.advantage = -5;
  p.input.start_frame = 44;
  p.input.count = count;
  p.input.deltas = std::move(deltas);
  p.input.checks = std::move(checks);
  p.input.held_frame = 9;
  return p;
}

/// Moves every frame of `p` as far from ack_frame as u32 allows (ack max_u32, the others 0), so
/// each frame field takes max_varint_size bytes.
inline void far_frames(Packet& p) {
  p.input.ack_frame = max_u32;
  p.input.check_ack = p.input.current_frame = p.input.start_frame = p.input.held_frame = 0;
  for (HashCheck& c : p.input.checks)
    c.frame = 0;
  for (GoneReport& g : p.input.gone)
    g.frame = 0;
  for (BackReport& r : p.input.back)
    r.from = r.until = 0;
}

inline std::vector<HashCheck> max_checks() {
  std::vector<HashCheck> checks;
  for (std::size_t i = 0; i < max_checks_per_packet; ++i)
    checks.push_back({max_u32 - static_cast<std::uint32_t>(i), max_u64 - i});
  return checks;
}

inline Bytes non_zero_run(std::size_t n, std::size_t salt) {
  Bytes b(n);
  for (std::size_t i = 0; i < n; ++i)
    b[i] = static_cast<std::uint8_t>((i + salt) % 255 + 1);
  return b;
}

/// Compares the header and the body that header.type says is meaningful.
inline testing::AssertionResult same_packet(const Packet& a, const Packet& b) {
  if (a.header.type != b.header.type) return testing::AssertionFailure() << "type differs";
  if (a.header.session != b.header.session) return testing::AssertionFailure() << "session differs";
  if (a.header.sequence != b.header.sequence)
    return testing::AssertionFailure() << "sequence differs";
  switch (a.header.type) {
    case PacketType::hello:
      if (a.hello.fingerprint != b.hello.fingerprint || a.hello.players != b.hello.players ||
          a.hello.player != b.hello.player || a.hello.input_size != b.hello.input_size ||
          a.hello.challenge != b.hello.challenge)
        return testing::AssertionFailure() << "hello body differs";
      break;
    case PacketType::hello_reply:
      if (a.hello_reply.challenge != b.hello_reply.challenge)
        return testing::AssertionFailure() << "hello_reply body differs";
      break;
    case PacketType::input: {
      const InputBody& x = a.input;
      const InputBody& y = b.input;
      if (x.ack_frame != y.ack_frame || x.check_ack != y.check_ack ||
          x.current_frame != y.current_frame || x.advantage != y.advantage ||
          x.start_frame != y.start_frame || x.count != y.count)
        return testing::AssertionFailure() << "input fields differ";
      if (x.deltas != y.deltas) return testing::AssertionFailure() << "input deltas differ";
      if (x.checks != y.checks) return testing::AssertionFailure() << "input checks differ";
      if (x.held_frame != y.held_frame || x.gone != y.gone || x.back != y.back)
        return testing::AssertionFailure() << "input held frame, gone or back reports differ";
      break;
    }
    case PacketType::ping:
    case PacketType::pong:
      if (a.ping.time_us != b.ping.time_us)
        return testing::AssertionFailure() << "ping body differs";
      break;
    case PacketType::state_request:
      if (a.state_request.offset != b.state_request.offset)
        return testing::AssertionFailure() << "state_request body differs";
      break;
    case PacketType::state_chunk:
      if (a.state_chunk.total != b.state_chunk.total ||
          a.state_chunk.offset != b.state_chunk.offset || a.state_chunk.data != b.state_chunk.data)
        return testing::AssertionFailure() << "state_chunk body differs";
      break;
  }
  return testing::AssertionSuccess();
}

inline DecodeError decode_bytes(const Bytes& bytes, std::size_t input_size) {
  Packet p;
  return decode(bytes, input_size, p);
}

/// Encodes `p`, checks the bytes against `expected`, decodes them and compares with `p`.
inline void expect_round_trip(const Packet& p, std::size_t input_size, const Bytes& expected) {
  Bytes out;
  ASSERT_TRUE(encode(p, input_size, out));
  EXPECT_EQ(out, expected);
  Packet back;
  ASSERT_EQ(decode(out, input_size, back), DecodeError::none);
  EXPECT_TRUE(same_packet(p, back));
}

}  // namespace detsim::net::protocol::test_support
