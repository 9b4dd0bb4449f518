// The session wire protocol (net/include/detsim/net/protocol.hpp): every packet type encodes to the
// documented little-endian layout and decodes back with fields at their extremes; the run-length
// coder at its token boundaries and within its size bound; encode refuses inconsistent packets;
// decode refuses every truncation, every single-bit flip and hand-made datagrams with a correct
// checksum but bad contents, each with the right DecodeError; seeded random and mutated datagrams
// never crash the decoder, and whatever it accepts re-encodes to an equal packet.
//
// Expected bytes are built here from the layout in protocol.hpp with an independent little-endian
// writer and sealed with XXH3, never taken from encode().
#include <xxhash.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <random>
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/net/protocol.hpp>

namespace detsim::net::protocol {
namespace {

using Bytes = std::vector<std::uint8_t>;

constexpr std::uint32_t max_u32 = std::numeric_limits<std::uint32_t>::max();
constexpr std::uint64_t max_u64 = std::numeric_limits<std::uint64_t>::max();
/// ack_frame, check_ack, current_frame, advantage, start_frame, count.
constexpr std::size_t input_fixed_size = 4 + 4 + 4 + 1 + 4 + 1;
constexpr std::size_t check_size = 4 + 8;
constexpr std::array<std::size_t, 5> fuzz_input_sizes = {1, 3, 4, 64, max_unit_size};

constexpr std::uint8_t byte(std::uint64_t v) {
  return static_cast<std::uint8_t>(v);
}

/// Every input size a player uses, and some of the larger whole-frame units a host sends
/// spectators (up to max_unit_size).
std::vector<std::size_t> all_sizes() {
  std::vector<std::size_t> sizes;
  for (std::size_t size = 1; size <= max_input_size; ++size)
    sizes.push_back(size);
  for (const std::size_t size : {65U, 100U, 128U, 255U, 256U, 257U, 511U, 512U})
    sizes.push_back(size);
  sizes.push_back(max_unit_size);
  return sizes;
}

// --- An independent writer of the documented layout ----------------------------------------------

class Writer {
 public:
  Writer& u8(std::uint64_t v) { return le(v, 1); }
  Writer& u16(std::uint64_t v) { return le(v, 2); }
  Writer& u32(std::uint64_t v) { return le(v, 4); }
  Writer& u64(std::uint64_t v) { return le(v, 8); }
  Writer& raw(std::span<const std::uint8_t> b) {
    bytes_.insert(bytes_.end(), b.begin(), b.end());
    return *this;
  }
  Writer& header(std::uint8_t type, std::uint32_t nonce, std::uint16_t sequence) {
    return u8('D').u8('N').u8(version).u8(type).u32(nonce).u16(sequence);
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
void reseal(Bytes& b) {
  if (b.size() < 4) return;
  const std::size_t n = b.size() - 4;
  const auto sum = static_cast<std::uint32_t>(XXH3_64bits(b.data(), n));
  for (std::size_t i = 0; i < 4; ++i)
    b[n + i] = static_cast<std::uint8_t>(sum >> (8 * i));
}

/// Zero-run tokens for `n` zero bytes, by the token definition: t >= 128 is t - 127 zeros.
Bytes zero_tokens(std::size_t n) {
  Bytes out;
  while (n > 0) {
    const std::size_t k = std::min<std::size_t>(n, 128);
    out.push_back(static_cast<std::uint8_t>(127 + k));
    n -= k;
  }
  return out;
}

/// Literal tokens for `bytes`, by the token definition: t < 128 is t + 1 literal bytes.
Bytes literal_tokens(std::span<const std::uint8_t> bytes) {
  Bytes out;
  for (std::size_t at = 0; at < bytes.size(); at += 128) {
    const std::size_t k = std::min<std::size_t>(bytes.size() - at, 128);
    out.push_back(static_cast<std::uint8_t>(k - 1));
    out.insert(out.end(), bytes.begin() + static_cast<std::ptrdiff_t>(at),
               bytes.begin() + static_cast<std::ptrdiff_t>(at + k));
  }
  return out;
}

/// The bytes of an input packet whose deltas are run-length coded as `tokens`.
Bytes input_bytes(const Packet& p, std::span<const std::uint8_t> tokens) {
  const InputBody& b = p.input;
  Writer w;
  w.header(static_cast<std::uint8_t>(PacketType::input), p.header.nonce, p.header.sequence)
      .u32(b.ack_frame)
      .u32(b.check_ack)
      .u32(b.current_frame)
      .u8(static_cast<std::uint8_t>(b.advantage))
      .u32(b.start_frame)
      .u8(b.count)
      .raw(tokens)
      .u8(b.checks.size());
  for (const HashCheck& c : b.checks)
    w.u32(c.frame).u64(c.hash);
  return w.sealed();
}

/// The bytes of a hello, hello_reply, ping or pong packet.
Bytes plain_bytes(const Packet& p) {
  Writer w;
  w.header(static_cast<std::uint8_t>(p.header.type), p.header.nonce, p.header.sequence);
  switch (p.header.type) {
    case PacketType::hello:
      w.u64(p.hello.fingerprint)
          .u8(p.hello.players)
          .u8(p.hello.player)
          .u8(p.hello.input_size)
          .u32(p.hello.challenge);
      break;
    case PacketType::hello_reply:
      w.u32(p.hello_reply.challenge);
      break;
    case PacketType::ping:
    case PacketType::pong:
      w.u64(p.ping.time_us);
      break;
    case PacketType::input:
      ADD_FAILURE() << "plain_bytes of an input packet";
      break;
  }
  return w.sealed();
}

/// The run-length coded deltas inside an encoded input packet.
std::span<const std::uint8_t> rle_part(const Bytes& encoded, std::size_t checks) {
  const std::size_t begin = header_size + input_fixed_size;
  const std::size_t end = encoded.size() - trailer_size - 1 - checks * check_size;
  return std::span<const std::uint8_t>(encoded).subspan(begin, end - begin);
}

// --- Packets ----------------------------------------------------------------------------------

Packet make(PacketType type, std::uint32_t nonce, std::uint16_t sequence) {
  Packet p;
  p.header = {type, nonce, sequence};
  return p;
}

Packet input_packet(std::uint8_t count, Bytes deltas, std::vector<HashCheck> checks = {}) {
  Packet p = make(PacketType::input, 0x01020304, 0x0506);
  p.input.ack_frame = 11;
  p.input.check_ack = 22;
  p.input.current_frame = 33;
  p.input.advantage = -5;
  p.input.start_frame = 44;
  p.input.count = count;
  p.input.deltas = std::move(deltas);
  p.input.checks = std::move(checks);
  return p;
}

std::vector<HashCheck> max_checks() {
  std::vector<HashCheck> checks;
  for (std::size_t i = 0; i < max_checks_per_packet; ++i)
    checks.push_back({max_u32 - static_cast<std::uint32_t>(i), max_u64 - i});
  return checks;
}

/// Compares the header and the body that header.type says is meaningful.
testing::AssertionResult same_packet(const Packet& a, const Packet& b) {
  if (a.header.type != b.header.type) return testing::AssertionFailure() << "type differs";
  if (a.header.nonce != b.header.nonce) return testing::AssertionFailure() << "nonce differs";
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
      break;
    }
    case PacketType::ping:
    case PacketType::pong:
      if (a.ping.time_us != b.ping.time_us)
        return testing::AssertionFailure() << "ping body differs";
      break;
  }
  return testing::AssertionSuccess();
}

DecodeError decode_bytes(const Bytes& bytes, std::size_t input_size) {
  Packet p;
  return decode(bytes, input_size, p);
}

/// Encodes `p`, checks the bytes against `expected`, decodes them and compares with `p`.
void expect_round_trip(const Packet& p, std::size_t input_size, const Bytes& expected) {
  Bytes out;
  ASSERT_TRUE(encode(p, input_size, out));
  EXPECT_EQ(out, expected);
  Packet back;
  ASSERT_EQ(decode(out, input_size, back), DecodeError::none);
  EXPECT_TRUE(same_packet(p, back));
}

// --- Round trips at the extremes ----------------------------------------------------------------

TEST(NetProtocolRoundTrip, HelloAtExtremes) {
  for (const bool high : {false, true}) {
    const std::uint16_t sequence = high ? 0xFFFF : 0;
    Packet p = make(PacketType::hello, high ? max_u32 : 0, sequence);
    p.hello = high ? Hello{max_u64, 0xFF, spectator_player, 0xFF, max_u32} : Hello{};
    const Bytes expected = plain_bytes(p);
    EXPECT_EQ(expected.size(), header_size + 8 + 1 + 1 + 1 + 4 + trailer_size);
    for (const std::size_t size : {std::size_t{1}, max_input_size, max_unit_size})
      expect_round_trip(p, size, expected);
  }
}

TEST(NetProtocolRoundTrip, HelloReplyPingPongAtExtremes) {
  for (const bool high : {false, true}) {
    const std::uint16_t sequence = high ? 0xFFFF : 0;
    Packet reply = make(PacketType::hello_reply, high ? max_u32 : 0, sequence);
    reply.hello_reply.challenge = high ? max_u32 : 0;
    expect_round_trip(reply, 4, plain_bytes(reply));
    for (const PacketType type : {PacketType::ping, PacketType::pong}) {
      Packet p = make(type, high ? max_u32 : 0, sequence);
      p.ping.time_us = high ? max_u64 : 0;
      const Bytes expected = plain_bytes(p);
      EXPECT_EQ(expected.size(), header_size + 8 + trailer_size);
      expect_round_trip(p, 4, expected);
    }
  }
}

TEST(NetProtocolRoundTrip, HeaderFieldsAreLittleEndian) {
  Packet p = make(PacketType::ping, 0xA1B2C3D4, 0xE5F6);
  p.ping.time_us = 0x0102030405060708ULL;
  Bytes out;
  ASSERT_TRUE(encode(p, 1, out));
  const Bytes head(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(header_size + 8));
  EXPECT_EQ(head, (Bytes{'D', 'N', version, 4, 0xD4, 0xC3, 0xB2, 0xA1, 0xF6, 0xE5, 0x08, 0x07, 0x06,
                         0x05, 0x04, 0x03, 0x02, 0x01}));
}

TEST(NetProtocolRoundTrip, EmptyInputAtMinimum) {
  Packet p = input_packet(0, {});
  p.header = {PacketType::input, 0, 0};
  p.input.ack_frame = p.input.check_ack = p.input.current_frame = p.input.start_frame = 0;
  p.input.advantage = std::numeric_limits<std::int8_t>::min();
  const Bytes expected = input_bytes(p, {});
  EXPECT_EQ(expected.size(), header_size + input_fixed_size + 1 + trailer_size);
  for (const std::size_t size : {std::size_t{1}, max_input_size, max_unit_size})
    expect_round_trip(p, size, expected);
}

TEST(NetProtocolRoundTrip, FullInputAtMaximum) {
  // 255 inputs of one byte, every delta 0xFF (two literal tokens), 8 checks, every field at its
  // maximum.
  Packet p = input_packet(255, Bytes(255, 0xFF), max_checks());
  p.header = {PacketType::input, max_u32, 0xFFFF};
  p.input.ack_frame = p.input.check_ack = p.input.current_frame = p.input.start_frame = max_u32;
  p.input.advantage = std::numeric_limits<std::int8_t>::max();
  expect_round_trip(p, 1, input_bytes(p, literal_tokens(p.input.deltas)));
}

TEST(NetProtocolRoundTrip, LargestInputsAllHeld) {
  // 255 unchanged inputs of the largest size: every 128 zero deltas in one token.
  for (const std::size_t size : {max_input_size, max_unit_size}) {
    const std::size_t length = 255 * size;
    Packet p = input_packet(255, Bytes(length, 0), max_checks());
    const Bytes tokens = zero_tokens(length);
    EXPECT_EQ(tokens.size(), (length + 127) / 128);
    expect_round_trip(p, size, input_bytes(p, tokens));
  }
}

TEST(NetProtocolRoundTrip, RandomInputsOfEverySize) {
  std::mt19937_64 rng(101);
  for (const std::size_t size : all_sizes()) {
    const std::size_t count = std::min<std::size_t>(255, 600 / size);
    Bytes deltas(count * size);
    for (std::uint8_t& d : deltas)  // about half zero, so both token kinds appear
      d = rng() % 2 == 0 ? 0 : byte(rng());
    std::vector<HashCheck> checks;
    for (std::size_t i = 0; i < size % 9; ++i)
      checks.push_back({static_cast<std::uint32_t>(rng()), rng()});
    const Packet p = input_packet(static_cast<std::uint8_t>(count), deltas, checks);
    Bytes out;
    ASSERT_TRUE(encode(p, size, out)) << "input_size " << size;
    Packet back;
    ASSERT_EQ(decode(out, size, back), DecodeError::none) << "input_size " << size;
    EXPECT_TRUE(same_packet(p, back)) << "input_size " << size;
  }
}

// --- The run-length coder -------------------------------------------------------------------

/// An input_size and count whose product is `length` (1 byte inputs up to 255, else 4 bytes).
std::size_t size_for(std::size_t length) {
  return length <= 255 ? 1 : 4;
}

/// Round-trips `deltas` (padded by the caller to a multiple of size_for) and returns the encoded
/// run-length part.
Bytes rle_round_trip(const Bytes& deltas) {
  const std::size_t size = size_for(deltas.size());
  EXPECT_EQ(deltas.size() % size, 0U);
  const Packet p = input_packet(static_cast<std::uint8_t>(deltas.size() / size), deltas);
  Bytes out;
  EXPECT_TRUE(encode(p, size, out)) << "length " << deltas.size();
  if (out.empty()) return {};
  Packet back;
  EXPECT_EQ(decode(out, size, back), DecodeError::none) << "length " << deltas.size();
  EXPECT_TRUE(same_packet(p, back)) << "length " << deltas.size();
  const auto rle = rle_part(out, 0);
  return Bytes(rle.begin(), rle.end());
}

Bytes non_zero_run(std::size_t n, std::size_t salt) {
  Bytes b(n);
  for (std::size_t i = 0; i < n; ++i)
    b[i] = static_cast<std::uint8_t>((i + salt) % 255 + 1);
  return b;
}

/// The size bound the encoder keeps: never longer than all-literal tokens.
std::size_t literal_bound(std::size_t length) {
  return length + (length + 127) / 128;
}

constexpr std::array<std::size_t, 6> boundary_runs = {1, 127, 128, 129, 255, 256};

TEST(NetProtocolRunLength, PureRunsAtTokenBoundaries) {
  for (const std::size_t n : boundary_runs) {
    EXPECT_EQ(rle_round_trip(Bytes(n, 0)), zero_tokens(n)) << n << " zeros";
    const Bytes run = non_zero_run(n, n);
    EXPECT_EQ(rle_round_trip(run), literal_tokens(run)) << n << " non-zero bytes";
  }
}

TEST(NetProtocolRunLength, AdjacentRunsAtTokenBoundaries) {
  // Every pair of boundary runs, zeros then non-zeros and the reverse. A zero run of two or more
  // next to a literal run is coded on its own, so the expected tokens are those of each run.
  for (const std::size_t a : boundary_runs) {
    for (const std::size_t b : boundary_runs) {
      const std::size_t size = size_for(a + b);
      const std::size_t pad = (size - (a + b) % size) % size;
      const Bytes literal = non_zero_run(b + pad, a);
      Bytes zeros_first(a, 0);
      zeros_first.insert(zeros_first.end(), literal.begin(), literal.end());
      Bytes expected = zero_tokens(a);
      const Bytes lit = literal_tokens(literal);
      expected.insert(expected.end(), lit.begin(), lit.end());
      EXPECT_EQ(rle_round_trip(zeros_first), expected) << a << " zeros, " << b << " non-zero";

      const Bytes head = non_zero_run(a + pad, b);
      Bytes literal_first = head;
      literal_first.insert(literal_first.end(), b, 0);
      expected = literal_tokens(head);
      const Bytes zt = zero_tokens(b);
      if (b >= 2) {
        expected.insert(expected.end(), zt.begin(), zt.end());
        EXPECT_EQ(rle_round_trip(literal_first), expected) << a << " non-zero, " << b << " zeros";
      } else {
        const Bytes rle = rle_round_trip(literal_first);
        EXPECT_LE(rle.size(), literal_bound(literal_first.size()));
      }
    }
  }
}

TEST(NetProtocolRunLength, AlternatingBytesStayWithinTheLiteralBound) {
  // x 0 x 0 ... and 0 x 0 x ...: coding every single zero as its own token would cost 1.5 bytes per
  // byte; the encoder never exceeds all-literal tokens.
  for (const std::size_t length :
       {std::size_t{2}, std::size_t{255}, std::size_t{256}, std::size_t{1020}}) {
    for (const std::size_t phase : {0U, 1U}) {
      Bytes deltas(length);
      for (std::size_t i = 0; i < length; ++i)
        deltas[i] = byte((i + phase) % 2 == 0 ? i % 200 + 1 : 0);
      const Bytes rle = rle_round_trip(deltas);
      EXPECT_LE(rle.size(), literal_bound(length)) << "length " << length << " phase " << phase;
    }
  }
}

TEST(NetProtocolRunLength, NeverLongerThanAllLiteralTokens) {
  // Patterns of every period up to 9 (one zero in each, or one non-zero in each) and random
  // bytes, at every input size: the coded deltas never exceed length + ceil(length / 128).
  std::mt19937_64 rng(7);
  for (const std::size_t size : all_sizes()) {
    const std::size_t count = std::min<std::size_t>(255, 1020 / size);
    const std::size_t length = count * size;
    std::vector<Bytes> patterns;
    for (std::size_t period = 2; period <= 9; ++period) {
      Bytes one_zero(length), one_set(length);
      for (std::size_t i = 0; i < length; ++i) {
        one_zero[i] = byte(i % period == 0 ? 0 : i % 251 + 1);
        one_set[i] = byte(i % period == 0 ? i % 251 + 1 : 0);
      }
      patterns.push_back(one_zero);
      patterns.push_back(one_set);
    }
    Bytes random(length);
    for (std::uint8_t& b : random)
      b = byte(rng() % 3 == 0 ? 0 : rng() % 255 + 1);
    patterns.push_back(random);
    for (const Bytes& deltas : patterns) {
      const Packet p = input_packet(static_cast<std::uint8_t>(count), deltas);
      Bytes out;
      ASSERT_TRUE(encode(p, size, out)) << "input_size " << size;
      EXPECT_LE(rle_part(out, 0).size(), literal_bound(length)) << "input_size " << size;
      Packet back;
      ASSERT_EQ(decode(out, size, back), DecodeError::none);
      EXPECT_TRUE(same_packet(p, back)) << "input_size " << size;
    }
  }
}

/// The fewest token bytes that code `bytes` (dynamic programming over every split into tokens of
/// at most 128 bytes: literal runs cost 1 + length, zero runs 1).
std::size_t shortest_coding(std::span<const std::uint8_t> bytes) {
  std::vector<std::size_t> best(bytes.size() + 1, std::numeric_limits<std::size_t>::max());
  best[0] = 0;
  std::size_t zeros = 0;  // zero bytes ending at i
  for (std::size_t i = 1; i <= bytes.size(); ++i) {
    zeros = bytes[i - 1] == 0 ? zeros + 1 : 0;
    for (std::size_t k = 1; k <= std::min<std::size_t>(128, i); ++k) {
      best[i] = std::min(best[i], best[i - k] + 1 + k);
      if (k <= zeros) best[i] = std::min(best[i], best[i - k] + 1);
    }
  }
  return best[bytes.size()];
}

TEST(NetProtocolRunLength, TokensAreTheShortest) {
  // Every string of up to 12 zero and non-zero bytes, and long random strings of several zero
  // densities: the encoder's tokens are as short as any the decoder accepts. So a datagram that
  // decodes always re-encodes within its own length.
  std::vector<Bytes> cases;
  for (std::size_t n = 1; n <= 12; ++n) {
    for (std::size_t bits = 0; bits < (std::size_t{1} << n); ++bits) {
      Bytes b(n);
      for (std::size_t i = 0; i < n; ++i)
        b[i] = byte((bits >> i & 1U) != 0 ? 0x33 : 0);
      cases.push_back(b);
    }
  }
  std::mt19937_64 rng(5);
  for (int i = 0; i < 200; ++i) {
    Bytes b(rng() % 1020 + 1);
    if (b.size() > 255) b.resize(b.size() / 4 * 4);  // whole inputs of size_for()
    const std::uint64_t odds = rng() % 6 + 1;
    for (std::uint8_t& x : b)
      x = byte(rng() % odds == 0 ? 0 : rng() % 255 + 1);
    cases.push_back(b);
  }
  for (const Bytes& deltas : cases) {
    const Packet p =
        input_packet(static_cast<std::uint8_t>(deltas.size() / size_for(deltas.size())), deltas);
    Bytes out;
    ASSERT_TRUE(encode(p, size_for(deltas.size()), out));
    ASSERT_EQ(rle_part(out, 0).size(), shortest_coding(deltas))
        << "length " << deltas.size() << ", first byte " << int{deltas[0]};
  }
}

TEST(NetProtocolRunLength, InputsOfOneByteMorePerInputAlwaysFitWithEightChecks) {
  // The literal bound makes the datagram size a function of count and input_size alone: count
  // inputs cost at most count * (input_size + 1) bytes. Whenever that and 8 checks fit in
  // max_datagram, the packet encodes, whatever the inputs are (here the worst case for a coder
  // that gives each lone zero a token: alternating zero and non-zero bytes).
  const std::size_t overhead =
      header_size + input_fixed_size + 1 + max_checks_per_packet * check_size + trailer_size;
  for (const std::size_t size : all_sizes()) {
    const std::size_t count =
        std::min<std::size_t>(max_inputs_per_packet, (max_datagram - overhead) / (size + 1));
    Bytes deltas(count * size);
    for (std::size_t i = 0; i < deltas.size(); ++i)
      deltas[i] = byte(i % 2 == 0 ? 0x40 : 0);
    const Packet p = input_packet(static_cast<std::uint8_t>(count), deltas, max_checks());
    Bytes out;
    EXPECT_TRUE(encode(p, size, out)) << "input_size " << size << ", count " << count;
  }
}

TEST(NetProtocolRunLength, InputSizeOneAndSixtyFourCountZeroAndMaximum) {
  for (const std::size_t size : {std::size_t{1}, max_input_size, max_unit_size}) {
    Bytes empty;
    ASSERT_TRUE(encode(input_packet(0, {}), size, empty));
    EXPECT_TRUE(rle_part(empty, 0).empty());
    // The largest count of non-zero inputs that fits: derived from the layout and the literal
    // token cost, then checked to be the largest that encodes.
    const std::size_t fixed = header_size + input_fixed_size + 1 + trailer_size;
    std::size_t largest = 0;
    for (std::size_t count = 0; count <= max_inputs_per_packet; ++count) {
      const std::size_t length = count * size;
      if (fixed + literal_bound(length) <= max_datagram) largest = count;
    }
    for (const std::size_t count : {largest, largest + 1}) {
      if (count > max_inputs_per_packet) continue;
      const Packet p =
          input_packet(static_cast<std::uint8_t>(count), non_zero_run(count * size, 3));
      Bytes out;
      EXPECT_EQ(encode(p, size, out), count == largest) << "input_size " << size << " " << count;
      if (count == largest) {
        Packet back;
        ASSERT_EQ(decode(out, size, back), DecodeError::none);
        EXPECT_TRUE(same_packet(p, back));
        EXPECT_EQ(out, input_bytes(p, literal_tokens(p.input.deltas)));
      }
    }
    if (size == 1) {
      EXPECT_EQ(largest, max_inputs_per_packet);
    } else {
      EXPECT_LT(largest, max_inputs_per_packet);
    }
  }
}

// --- encode refuses ------------------------------------------------------------------------------

void expect_refused(const Packet& p, std::size_t input_size, const std::string& what) {
  Bytes out = {1, 2, 3};
  EXPECT_FALSE(encode(p, input_size, out)) << what;
  EXPECT_TRUE(out.empty()) << what;
}

TEST(NetProtocolEncode, RefusesInconsistentPackets) {
  const Packet good = input_packet(3, Bytes(12, 7), {{1, 2}});
  Bytes out;
  ASSERT_TRUE(encode(good, 4, out));

  Packet p = good;
  p.input.deltas.pop_back();
  expect_refused(p, 4, "deltas one short");
  p = good;
  p.input.deltas.push_back(7);
  expect_refused(p, 4, "deltas one long");
  expect_refused(good, 3, "deltas of another input_size");
  p = good;
  p.input.count = 0;
  expect_refused(p, 4, "count 0 with deltas");
  p = good;
  p.input.checks.assign(max_checks_per_packet + 1, HashCheck{1, 2});
  expect_refused(p, 4, "9 checks");

  Packet hello = make(PacketType::hello, 1, 2);
  for (const Packet& q : {good, hello}) {
    expect_refused(q, 0, "input_size 0");
    expect_refused(q, max_unit_size + 1, "input_size max_unit_size + 1");
  }
  for (const std::uint8_t type : {std::uint8_t{0}, std::uint8_t{6}, std::uint8_t{255}}) {
    hello.header.type = static_cast<PacketType>(type);
    expect_refused(hello, 4, "type " + std::to_string(type));
  }
}

TEST(NetProtocolEncode, RefusesWhatExceedsMaxDatagramAndAcceptsUpToIt) {
  // Non-zero deltas are coded as literal tokens, so the datagram size of count inputs with c
  // checks is known from the layout: encode must succeed exactly when it is <= max_datagram.
  bool hit_max = false;
  bool hit_over = false;
  for (const std::size_t size : {1U, 2U, 3U, 4U, 5U, 6U, 7U, 8U, 64U}) {
    for (std::size_t count = 0; count <= max_inputs_per_packet; ++count) {
      const Bytes deltas = non_zero_run(count * size, count);
      for (std::size_t c = 0; c <= max_checks_per_packet; ++c) {
        const std::size_t expected_size = header_size + input_fixed_size +
                                          literal_bound(deltas.size()) + 1 + c * check_size +
                                          trailer_size;
        if (expected_size < max_datagram - 40 || expected_size > max_datagram + 40) continue;
        const Packet p = input_packet(static_cast<std::uint8_t>(count), deltas,
                                      std::vector<HashCheck>(c, HashCheck{5, 6}));
        Bytes out = {9};
        const bool ok = encode(p, size, out);
        EXPECT_EQ(ok, expected_size <= max_datagram) << size << " " << count << " " << c;
        EXPECT_EQ(out.size(), ok ? expected_size : 0U) << size << " " << count << " " << c;
        hit_max = hit_max || expected_size == max_datagram;
        hit_over = hit_over || expected_size == max_datagram + 1;
      }
    }
  }
  EXPECT_TRUE(hit_max) << "no case of exactly max_datagram bytes";
  EXPECT_TRUE(hit_over) << "no case of max_datagram + 1 bytes";
}

// --- decode refuses ------------------------------------------------------------------------------

struct Sample {
  std::string name;
  Packet packet;
  std::size_t input_size;
};

std::vector<Sample> samples() {
  std::vector<Sample> out;
  Packet hello = make(PacketType::hello, 0xDEADBEEF, 77);
  hello.hello = {0x0123456789ABCDEFULL, 4, 2, 3, 0xCAFEF00D};
  out.push_back({"hello", hello, 3});
  Packet reply = make(PacketType::hello_reply, 5, 6);
  reply.hello_reply.challenge = 0xCAFEF00D;
  out.push_back({"hello_reply", reply, 1});
  for (const PacketType type : {PacketType::ping, PacketType::pong}) {
    Packet ping = make(type, 9, 10);
    ping.ping.time_us = 123456789012345ULL;
    out.push_back({type == PacketType::ping ? "ping" : "pong", ping, 64});
  }
  out.push_back({"input empty", input_packet(0, {}), 4});
  Bytes mixed(20);
  for (std::size_t i = 0; i < mixed.size(); ++i)
    mixed[i] = byte(i % 5 < 2 ? 0 : i * 37 + 1);
  out.push_back({"input mixed", input_packet(5, mixed, {{1, 2}, {3, 4}, {5, 6}}), 4});
  out.push_back({"input 255 literal", input_packet(255, non_zero_run(255, 0)), 1});
  out.push_back({"input 64 held", input_packet(255, Bytes(255 * 64, 0), max_checks()), 64});
  return out;
}

TEST(NetProtocolDecode, SamplesDecode) {
  for (const Sample& s : samples()) {
    Bytes bytes;
    ASSERT_TRUE(encode(s.packet, s.input_size, bytes)) << s.name;
    Packet back;
    ASSERT_EQ(decode(bytes, s.input_size, back), DecodeError::none) << s.name;
    EXPECT_TRUE(same_packet(s.packet, back)) << s.name;
  }
}

TEST(NetProtocolDecode, EveryTruncationIsRefused) {
  for (const Sample& s : samples()) {
    Bytes bytes;
    ASSERT_TRUE(encode(s.packet, s.input_size, bytes)) << s.name;
    for (std::size_t n = 0; n < bytes.size(); ++n) {
      const Bytes prefix(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(n));
      // Magic, version and type are intact in every prefix that holds a header and a trailer;
      // the last 4 bytes of a prefix are not the checksum of what precedes them.
      const DecodeError expected =
          n < header_size + trailer_size ? DecodeError::too_short : DecodeError::bad_checksum;
      EXPECT_EQ(decode_bytes(prefix, s.input_size), expected) << s.name << ", " << n << " bytes";
    }
  }
}

TEST(NetProtocolDecode, EverySingleBitFlipIsRefused) {
  for (const Sample& s : samples()) {
    Bytes bytes;
    ASSERT_TRUE(encode(s.packet, s.input_size, bytes)) << s.name;
    for (std::size_t i = 0; i < bytes.size(); ++i) {
      for (unsigned bit = 0; bit < 8; ++bit) {
        Bytes flipped = bytes;
        flipped[i] = static_cast<std::uint8_t>(flipped[i] ^ (1U << bit));
        DecodeError expected = DecodeError::bad_checksum;
        if (i < 2) expected = DecodeError::bad_magic;
        if (i == 2) expected = DecodeError::bad_version;
        if (i == 3 && (flipped[3] < 1 || flipped[3] > 5)) expected = DecodeError::bad_type;
        const DecodeError got = decode_bytes(flipped, s.input_size);
        ASSERT_NE(got, DecodeError::none) << s.name << ", byte " << i << " bit " << bit;
        EXPECT_EQ(got, expected) << s.name << ", byte " << i << " bit " << bit;
      }
    }
  }
}

TEST(NetProtocolDecode, LengthLimits) {
  Bytes small = Writer().header(4, 1, 2).bytes();
  small.resize(header_size + trailer_size - 1, 0);
  EXPECT_EQ(decode_bytes(small, 4), DecodeError::too_short);
  EXPECT_EQ(decode_bytes({}, 4), DecodeError::too_short);
  // A sealed header with no body: long enough to check, too short for any body.
  for (std::uint8_t type = 1; type <= 5; ++type)
    EXPECT_EQ(decode_bytes(Writer().header(type, 1, 2).sealed(), 4), DecodeError::bad_length)
        << "type " << int{type};
  // A ping with trailing bytes up to exactly max_datagram is checked to the end (bad_length); one
  // byte more is too_long before anything else.
  Writer w;
  w.header(4, 1, 2).u64(3);
  Bytes body = w.bytes();
  body.resize(max_datagram - trailer_size, 0xAB);
  Writer full;
  full.raw(body);
  const Bytes at_max = full.sealed();
  ASSERT_EQ(at_max.size(), max_datagram);
  EXPECT_EQ(decode_bytes(at_max, 4), DecodeError::bad_length);
  body.push_back(0xAB);
  Writer over;
  over.raw(body);
  const Bytes too_long = over.sealed();
  ASSERT_EQ(too_long.size(), max_datagram + 1);
  EXPECT_EQ(decode_bytes(too_long, 4), DecodeError::too_long);
}

TEST(NetProtocolDecode, WrongMagicVersionAndType) {
  const std::array<std::array<std::uint8_t, 2>, 4> magics = {
      {{'D', 'X'}, {'X', 'N'}, {'d', 'n'}, {0, 0}}};
  for (const auto& magic : magics) {
    Writer w;
    w.u8(magic[0]).u8(magic[1]).u8(version).u8(4).u32(1).u16(2).u64(3);
    EXPECT_EQ(decode_bytes(w.sealed(), 4), DecodeError::bad_magic);
  }
  for (const std::uint8_t v : {std::uint8_t{0}, std::uint8_t{version + 1}, std::uint8_t{255}}) {
    Writer w;
    w.u8('D').u8('N').u8(v).u8(4).u32(1).u16(2).u64(3);
    EXPECT_EQ(decode_bytes(w.sealed(), 4), DecodeError::bad_version) << "version " << int{v};
  }
  for (const std::uint8_t type : {std::uint8_t{0}, std::uint8_t{6}, std::uint8_t{255}}) {
    Writer w;
    w.header(type, 1, 2).u64(3);
    EXPECT_EQ(decode_bytes(w.sealed(), 4), DecodeError::bad_type) << "type " << int{type};
  }
}

TEST(NetProtocolDecode, InputSizeOutOfRangeIsABadField) {
  for (const Sample& s : samples()) {
    Bytes bytes;
    ASSERT_TRUE(encode(s.packet, s.input_size, bytes));
    EXPECT_EQ(decode_bytes(bytes, 0), DecodeError::bad_field) << s.name;
    EXPECT_EQ(decode_bytes(bytes, max_unit_size + 1), DecodeError::bad_field) << s.name;
  }
}

TEST(NetProtocolDecode, BodyShorterOrLongerThanItsType) {
  for (const Sample& s : samples()) {
    if (s.packet.header.type == PacketType::input) continue;
    Bytes bytes;
    ASSERT_TRUE(encode(s.packet, s.input_size, bytes));
    Bytes body(bytes.begin(), bytes.end() - static_cast<std::ptrdiff_t>(trailer_size));
    Bytes shorter = body;
    shorter.pop_back();
    Bytes longer = body;
    longer.push_back(0);
    EXPECT_EQ(decode_bytes(Writer().raw(shorter).sealed(), s.input_size), DecodeError::bad_length)
        << s.name;
    EXPECT_EQ(decode_bytes(Writer().raw(longer).sealed(), s.input_size), DecodeError::bad_length)
        << s.name;
  }
}

/// An input datagram of `count` inputs whose deltas are the raw `tokens`, then `tail` (the checks
/// count and checks, or whatever the test wants), sealed.
Bytes crafted_input(std::uint8_t count, const Bytes& tokens, const Bytes& tail) {
  Writer w;
  w.header(3, 1, 2).u32(10).u32(20).u32(30).u8(0).u32(40).u8(count).raw(tokens).raw(tail);
  return w.sealed();
}

TEST(NetProtocolDecode, InputCraftedWithACorrectChecksum) {
  const Bytes no_checks = {0};
  // The reference: 2 inputs of 4 bytes, coded as 1 literal byte + 7 zeros.
  EXPECT_EQ(decode_bytes(crafted_input(2, {0, 9, 127 + 7}, no_checks), 4), DecodeError::none);

  // A run past the end of the deltas, by a zero token or a literal token.
  EXPECT_EQ(decode_bytes(crafted_input(2, {0, 9, 127 + 8}, no_checks), 4), DecodeError::bad_field);
  EXPECT_EQ(decode_bytes(crafted_input(1, {255}, no_checks), 4), DecodeError::bad_field);
  EXPECT_EQ(decode_bytes(crafted_input(1, {4, 1, 2, 3, 4, 5}, no_checks), 4),
            DecodeError::bad_field);
  // A literal run longer than what remains of the datagram (also "a run past the end").
  EXPECT_EQ(decode_bytes(crafted_input(2, {7, 1, 2}, {}), 4), DecodeError::bad_field);
  // Deltas that stop short: the datagram ends after the first token, or after all of them with
  // no checks count.
  EXPECT_EQ(decode_bytes(crafted_input(2, {127 + 4}, {}), 4), DecodeError::bad_length);
  EXPECT_EQ(decode_bytes(crafted_input(2, {127 + 8}, {}), 4), DecodeError::bad_length);
  // The fixed fields stop short.
  {
    Writer w;
    w.header(3, 1, 2).u32(10).u32(20).u32(30).u8(0).u32(40);
    EXPECT_EQ(decode_bytes(w.sealed(), 4), DecodeError::bad_length);
  }

  // Checks: 9 is a bad field (with or without their bytes); missing or extra bytes a bad length.
  const Bytes deltas = {127 + 8};
  Bytes nine = {9};
  EXPECT_EQ(decode_bytes(crafted_input(2, deltas, nine), 4), DecodeError::bad_field);
  nine.resize(1 + 9 * check_size, 0x11);
  EXPECT_EQ(decode_bytes(crafted_input(2, deltas, nine), 4), DecodeError::bad_field);
  Bytes two = {2};
  two.resize(1 + 2 * check_size, 0x22);
  EXPECT_EQ(decode_bytes(crafted_input(2, deltas, two), 4), DecodeError::none);
  Bytes missing = two;
  missing.pop_back();
  EXPECT_EQ(decode_bytes(crafted_input(2, deltas, missing), 4), DecodeError::bad_length);
  missing.resize(1 + check_size);
  EXPECT_EQ(decode_bytes(crafted_input(2, deltas, missing), 4), DecodeError::bad_length);
  Bytes trailing = two;
  trailing.push_back(0);
  EXPECT_EQ(decode_bytes(crafted_input(2, deltas, trailing), 4), DecodeError::bad_length);
  EXPECT_EQ(decode_bytes(crafted_input(2, deltas, {0, 0}), 4), DecodeError::bad_length);

  // A count the deltas do not cover (count 255 of 64 bytes, 1 token) runs out of bytes; with a
  // checks count after it, that byte is read as a literal token whose byte is missing.
  EXPECT_EQ(decode_bytes(crafted_input(255, deltas, {}), 64), DecodeError::bad_length);
  EXPECT_EQ(decode_bytes(crafted_input(255, deltas, no_checks), 64), DecodeError::bad_field);
}

TEST(NetProtocolDecode, NonCanonicalTokensAreAcceptedAndReencodeCanonically) {
  // The decoder accepts any tokens that produce exactly count * input_size bytes: a literal token
  // covering zeros, or a zero run split in two. encode() then writes the canonical tokens, so the
  // bytes differ while the packet is the same.
  const Bytes literal_zeros = crafted_input(1, {3, 0, 0, 0, 0}, {0});
  const Bytes split_zeros = crafted_input(1, {127 + 1, 127 + 3}, {0});
  const Bytes canonical = crafted_input(1, {127 + 4}, {0});
  Packet reference;
  ASSERT_EQ(decode(canonical, 4, reference), DecodeError::none);
  EXPECT_EQ(reference.input.deltas, Bytes(4, 0));
  for (const Bytes& bytes : {literal_zeros, split_zeros}) {
    Packet p;
    ASSERT_EQ(decode(bytes, 4, p), DecodeError::none);
    EXPECT_TRUE(same_packet(p, reference));
    Bytes again;
    ASSERT_TRUE(encode(p, 4, again));
    EXPECT_EQ(again, canonical);
    EXPECT_NE(again, bytes);
  }
}

TEST(NetProtocolDecode, ErrorNamesAreDistinct) {
  std::set<std::string_view> names;
  for (std::size_t e = 0; e < decode_error_count; ++e) {
    const std::string_view name = to_string(static_cast<DecodeError>(e));
    EXPECT_FALSE(name.empty());
    EXPECT_NE(name, "unknown") << e;
    names.insert(name);
  }
  EXPECT_EQ(names.size(), decode_error_count);
  EXPECT_EQ(to_string(DecodeError::bad_checksum), "bad_checksum");
  EXPECT_EQ(names.count(to_string(static_cast<DecodeError>(decode_error_count))), 0U);
}

// --- Input deltas ----------------------------------------------------------------------------

TEST(NetProtocolDeltas, EncodeAndDecodeAreInversesForRandomInputs) {
  std::mt19937_64 rng(2024);
  for (const std::size_t size : {1U, 2U, 3U, 4U, 7U, 16U, 64U}) {
    for (const std::size_t count : {0U, 1U, 2U, 17U, 255U}) {
      Bytes reference(size), inputs(count * size);
      for (std::uint8_t& b : reference)
        b = static_cast<std::uint8_t>(rng());
      for (std::size_t i = 0; i < inputs.size(); ++i)  // held bytes are common: copy often
        inputs[i] =
            (i >= size && rng() % 2 == 0) ? inputs[i - size] : static_cast<std::uint8_t>(rng());
      Bytes deltas;
      delta_encode(reference, inputs, deltas);
      ASSERT_EQ(deltas.size(), inputs.size());
      for (std::size_t i = 0; i < inputs.size(); ++i) {
        const std::uint8_t previous = i < size ? reference[i] : inputs[i - size];
        EXPECT_EQ(deltas[i], byte(inputs[i] ^ previous)) << size << " " << count << " " << i;
      }
      delta_decode(reference, deltas);
      EXPECT_EQ(deltas, inputs) << "input_size " << size << ", count " << count;
    }
  }
}

TEST(NetProtocolDeltas, HeldInputsCostNothing) {
  const Bytes reference = {1, 2, 3, 4};
  Bytes inputs;
  for (int i = 0; i < 10; ++i)
    inputs.insert(inputs.end(), reference.begin(), reference.end());
  Bytes deltas;
  delta_encode(reference, inputs, deltas);
  EXPECT_EQ(deltas, Bytes(inputs.size(), 0));
  const Packet p = input_packet(10, deltas);
  Bytes out;
  ASSERT_TRUE(encode(p, 4, out));
  EXPECT_EQ(rle_part(out, 0).size(), 1U);  // 40 zero bytes: one token
}

// --- Random and mutated datagrams ------------------------------------------------------------

/// A random valid packet whose inputs (if any) are `size` bytes.
Packet random_packet(std::mt19937_64& rng, std::size_t size) {
  const auto type = static_cast<PacketType>(rng() % 5 + 1);
  Packet p = make(type, static_cast<std::uint32_t>(rng()), static_cast<std::uint16_t>(rng()));
  p.hello = {rng(), static_cast<std::uint8_t>(rng()), static_cast<std::uint8_t>(rng()),
             static_cast<std::uint8_t>(rng()), static_cast<std::uint32_t>(rng())};
  p.hello_reply.challenge = static_cast<std::uint32_t>(rng());
  p.ping.time_us = rng();
  InputBody& b = p.input;
  b.ack_frame = static_cast<std::uint32_t>(rng());
  b.check_ack = static_cast<std::uint32_t>(rng());
  b.current_frame = static_cast<std::uint32_t>(rng());
  b.advantage = static_cast<std::int8_t>(static_cast<std::uint8_t>(rng()));
  b.start_frame = static_cast<std::uint32_t>(rng());
  const std::size_t most = std::min<std::size_t>(max_inputs_per_packet, 700 / size);
  b.count = static_cast<std::uint8_t>(rng() % (most + 1));
  b.deltas.resize(std::size_t{b.count} * size);
  const std::uint64_t zero_odds = rng() % 4 + 1;  // 1 in zero_odds bytes is non-zero
  for (std::uint8_t& d : b.deltas)
    d = byte(rng() % zero_odds == 0 ? rng() : 0);
  b.checks.resize(rng() % (max_checks_per_packet + 1));
  for (HashCheck& c : b.checks)
    c = {static_cast<std::uint32_t>(rng()), rng()};
  return p;
}

/// 1 to 4 random edits: bit flips, byte writes, insertions, deletions, truncation, duplication.
void mutate(std::mt19937_64& rng, Bytes& b) {
  const std::uint64_t edits = rng() % 4 + 1;
  for (std::uint64_t e = 0; e < edits; ++e) {
    const std::size_t at = b.empty() ? 0 : rng() % b.size();
    switch (rng() % 6) {
      case 0:
        if (!b.empty()) b[at] = static_cast<std::uint8_t>(b[at] ^ (1U << (rng() % 8)));
        break;
      case 1:
        if (!b.empty()) b[at] = static_cast<std::uint8_t>(rng());
        break;
      case 2:
        b.insert(b.begin() + static_cast<std::ptrdiff_t>(at), static_cast<std::uint8_t>(rng()));
        break;
      case 3:
        if (!b.empty()) b.erase(b.begin() + static_cast<std::ptrdiff_t>(at));
        break;
      case 4:
        b.resize(at);
        break;
      default: {
        const std::size_t n = std::min<std::size_t>(rng() % 16, b.size() - at);
        const Bytes chunk(b.begin() + static_cast<std::ptrdiff_t>(at),
                          b.begin() + static_cast<std::ptrdiff_t>(at + n));
        b.insert(b.begin() + static_cast<std::ptrdiff_t>(at), chunk.begin(), chunk.end());
        break;
      }
    }
  }
}

struct Accepted {
  std::uint64_t count = 0;
  std::uint64_t same_bytes = 0;  ///< re-encoded to exactly the received bytes
};

/// A datagram that decoded: its packet re-encodes within the datagram's length, the re-encoding
/// decodes to the same packet, and (every type but input, whose tokens need not be canonical) is
/// the same bytes.
void check_accepted(const Bytes& bytes, std::size_t size, const Packet& p, Accepted& accepted) {
  ++accepted.count;
  Bytes again;
  ASSERT_TRUE(encode(p, size, again)) << "a decoded packet does not re-encode";
  EXPECT_LE(again.size(), bytes.size());
  Packet back;
  ASSERT_EQ(decode(again, size, back), DecodeError::none);
  EXPECT_TRUE(same_packet(p, back));
  if (again == bytes) ++accepted.same_bytes;
  if (p.header.type != PacketType::input) {
    EXPECT_EQ(again, bytes);
  }
}

TEST(NetProtocolRandom, RandomBytesNeverCrashTheDecoder) {
  std::mt19937_64 rng(99);
  std::array<std::uint64_t, decode_error_count> seen{};
  Accepted accepted;
  for (int i = 0; i < 200'000; ++i) {
    Bytes bytes(rng() % 1301);
    for (std::uint8_t& b : bytes)
      b = static_cast<std::uint8_t>(rng());
    // Half of them start like a detsim datagram so they get past the header checks.
    if (i % 2 == 0 && bytes.size() >= 4) {
      bytes[0] = 'D';
      bytes[1] = 'N';
      bytes[2] = version;
      bytes[3] = static_cast<std::uint8_t>(rng() % 5 + 1);
    }
    const std::size_t size = fuzz_input_sizes[rng() % fuzz_input_sizes.size()];
    Packet p;
    const DecodeError e = decode(bytes, size, p);
    ++seen[static_cast<std::size_t>(e)];
    if (e == DecodeError::none) check_accepted(bytes, size, p, accepted);
  }
  // Every early check was reached.
  for (const DecodeError e : {DecodeError::too_short, DecodeError::too_long, DecodeError::bad_magic,
                              DecodeError::bad_checksum})
    EXPECT_GT(seen[static_cast<std::size_t>(e)], 0U) << to_string(e);
}

TEST(NetProtocolRandom, MutatedResealedPacketsDecodeOrAreRefused) {
  // Valid packets, mutated, with the checksum recomputed so that the mutations reach the field
  // checks. Whatever decodes must re-encode to an equal packet.
  std::mt19937_64 rng(31337);
  std::array<std::uint64_t, decode_error_count> seen{};
  Accepted accepted;
  for (int i = 0; i < 200'000; ++i) {
    const std::size_t size = fuzz_input_sizes[rng() % fuzz_input_sizes.size()];
    Bytes bytes;
    ASSERT_TRUE(encode(random_packet(rng, size), size, bytes));
    mutate(rng, bytes);
    if (rng() % 8 != 0) reseal(bytes);
    // Usually decoded with the sender's input size, sometimes with another.
    const std::size_t decode_size =
        rng() % 4 == 0 ? fuzz_input_sizes[rng() % fuzz_input_sizes.size()] : size;
    Packet p;
    const DecodeError e = decode(bytes, decode_size, p);
    ++seen[static_cast<std::size_t>(e)];
    if (e == DecodeError::none) check_accepted(bytes, decode_size, p, accepted);
    if (testing::Test::HasFatalFailure()) return;
  }
  // The loop reached every outcome a mutation can produce (too_long needs more growth than these
  // edits give).
  for (std::size_t e = 0; e < decode_error_count; ++e) {
    if (static_cast<DecodeError>(e) == DecodeError::too_long) continue;
    EXPECT_GT(seen[e], 0U) << to_string(static_cast<DecodeError>(e));
  }
  EXPECT_GT(accepted.same_bytes, 0U);
  RecordProperty("accepted", std::to_string(accepted.count));
  RecordProperty("accepted_same_bytes", std::to_string(accepted.same_bytes));
}

}  // namespace
}  // namespace detsim::net::protocol
