// The session wire protocol (net/include/detsim/net/protocol.hpp), encoding side: every packet type
// encodes to the documented layout and decodes back with fields at their extremes; frame fields
// are LEB128 varints (zigzag differences from ack_frame) of the exact documented bytes at every
// 7-bit group boundary, so a typical input packet is small; the run-length coder at its token
// boundaries and within its size bound; encode refuses inconsistent packets and accepts exactly up
// to max_datagram; delta coding of inputs. Decoding hostile bytes: net_protocol_decode_test.cpp.
//
// Expected bytes are built with the independent writer in support/protocol_writer.hpp and sealed
// with XXH3, never taken from encode().
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <random>
#include <span>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/net/protocol.hpp>

#include "support/protocol_writer.hpp"

namespace detsim::net::protocol {
namespace {

using namespace test_support;

// --- Round trips at the extremes ----------------------------------------------------------------

TEST(NetProtocolRoundTrip, HelloAtExtremes) {
  for (const bool high : {false, true}) {
    const std::uint16_t sequence = high ? 0xFFFF : 0;
    Packet p = make(PacketType::hello, high ? max_u64 : 0, sequence);
    p.hello = high ? Hello{max_u64, 0xFF, spectator_player, 0xFF, max_u64} : Hello{};
    const Bytes expected = plain_bytes(p);
    EXPECT_EQ(expected.size(), header_size + 8 + 1 + 1 + 1 + 8 + trailer_size);
    for (const std::size_t size : {std::size_t{1}, max_input_size, max_unit_size})
      expect_round_trip(p, size, expected);
  }
}

TEST(NetProtocolRoundTrip, HelloReplyPingPongAtExtremes) {
  for (const bool high : {false, true}) {
    const std::uint16_t sequence = high ? 0xFFFF : 0;
    Packet reply = make(PacketType::hello_reply, high ? max_u64 : 0, sequence);
    reply.hello_reply.challenge = high ? max_u64 : 0;
    expect_round_trip(reply, 4, plain_bytes(reply));
    for (const PacketType type : {PacketType::ping, PacketType::pong}) {
      Packet p = make(type, high ? max_u64 : 0, sequence);
      p.ping.time_us = high ? max_u64 : 0;
      const Bytes expected = plain_bytes(p);
      EXPECT_EQ(expected.size(), header_size + 8 + trailer_size);
      expect_round_trip(p, 4, expected);
    }
  }
}

TEST(NetProtocolRoundTrip, StateRequestAndChunkAtTheirBounds) {
  for (const std::uint32_t offset :
       {0U, 1U, 127U, 128U, static_cast<std::uint32_t>(max_state_transfer)}) {
    Packet request = make(PacketType::state_request, 3, 4);
    request.state_request.offset = offset;
    expect_round_trip(request, 4, plain_bytes(request));
  }
  for (const std::size_t length : {std::size_t{1}, max_state_chunk}) {
    Packet chunk = make(PacketType::state_chunk, max_u64, 0xFFFF);
    chunk.state_chunk.total = static_cast<std::uint32_t>(max_state_transfer);
    chunk.state_chunk.offset = static_cast<std::uint32_t>(max_state_transfer - length);
    chunk.state_chunk.data.resize(length);
    for (std::size_t i = 0; i < length; ++i)
      chunk.state_chunk.data[i] = static_cast<std::uint8_t>(i * 131 + 7);
    const Bytes expected = plain_bytes(chunk);
    EXPECT_LE(expected.size(), max_datagram);
    expect_round_trip(chunk, 4, expected);
  }
}

TEST(NetProtocolRoundTrip, StateFieldsOutOfBoundsAreBadFieldsAndNeverEncode) {
  const auto chunk = [](std::uint32_t total, std::uint32_t offset, std::size_t length) {
    Packet p = make(PacketType::state_chunk, 1, 2);
    p.state_chunk.total = total;
    p.state_chunk.offset = offset;
    p.state_chunk.data.assign(length, 0xAB);
    return p;
  };
  const auto too_big = static_cast<std::uint32_t>(max_state_transfer + 1);
  for (const Packet& bad : {chunk(0, 0, 1), chunk(10, 0, 0), chunk(10, 5, 6), chunk(too_big, 0, 1),
                            chunk(5000, 0, max_state_chunk + 1)}) {
    Bytes out;
    EXPECT_FALSE(encode(bad, 4, out));
    EXPECT_EQ(decode_bytes(plain_bytes(bad), 4), DecodeError::bad_field);
  }
  Packet request = make(PacketType::state_request, 1, 2);
  request.state_request.offset = too_big;
  Bytes out;
  EXPECT_FALSE(encode(request, 4, out));
  EXPECT_EQ(decode_bytes(plain_bytes(request), 4), DecodeError::bad_field);
}

TEST(NetProtocolRoundTrip, HeaderFieldsAreLittleEndian) {
  Packet p = make(PacketType::ping, 0x1122334455667788ULL, 0xE5F6);
  p.ping.time_us = 0x0102030405060708ULL;
  Bytes out;
  ASSERT_TRUE(encode(p, 1, out));
  const Bytes head(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(header_size + 8));
  EXPECT_EQ(head, (Bytes{'D',  'N',  version, 4,    0x88, 0x77, 0x66, 0x55, 0x44, 0x33, 0x22,
                         0x11, 0xF6, 0xE5,    0x08, 0x07, 0x06, 0x05, 0x04, 0x03, 0x02, 0x01}));
}

TEST(NetProtocolRoundTrip, EmptyInputAtMinimum) {
  Packet p = input_packet(0, {});
  p.header = {PacketType::input, 0, 0};
  p.input.ack_frame = p.input.check_ack = p.input.current_frame = p.input.start_frame =
      p.input.held_frame = 0;
  p.input.advantage = std::numeric_limits<std::int8_t>::min();
  const Bytes expected = input_bytes(p, {});
  // ack_frame 0 and every difference 0: one varint byte each (ack, check_ack, current, start,
  // held); advantage, count, checks count, gone count.
  EXPECT_EQ(expected.size(), header_size + 5 + 1 + 1 + 1 + 1 + trailer_size);
  for (const std::size_t size : {std::size_t{1}, max_input_size, max_unit_size})
    expect_round_trip(p, size, expected);
}

TEST(NetProtocolRoundTrip, FullInputAtMaximum) {
  // 255 inputs of one byte, every delta 0xFF (two literal tokens), 8 checks, every field at its
  // maximum; then every frame as far from ack_frame as u32 allows (5 varint bytes each).
  Packet p = input_packet(255, Bytes(255, 0xFF), max_checks());
  p.header = {PacketType::input, max_u64, 0xFFFF};
  p.input.ack_frame = p.input.check_ack = p.input.current_frame = p.input.start_frame =
      p.input.held_frame = max_u32;
  for (std::uint8_t player = 0; player < max_gone_reports; ++player) {
    p.input.gone.push_back({player, max_u32 - player});
    p.input.back.push_back({player, max_u32 - 2U * player, max_u32 - player});
  }
  p.input.advantage = std::numeric_limits<std::int8_t>::max();
  expect_round_trip(p, 1, input_bytes(p, literal_tokens(p.input.deltas)));
  far_frames(p);
  const Bytes expected = input_bytes(p, literal_tokens(p.input.deltas));
  // Both lists full: 8 gone reports (player, frame) and 8 back reports (player, from, until).
  EXPECT_EQ(expected.size(), header_size + 4 * max_varint_size + 2 + 255 + 2 + 1 +
                                 max_checks_per_packet * (max_varint_size + 8) + max_varint_size +
                                 1 + max_gone_reports * (1 + max_varint_size) +
                                 max_gone_reports * (1 + 2 * max_varint_size) + trailer_size);
  EXPECT_LE(expected.size(), max_datagram);
  expect_round_trip(p, 1, expected);
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

// --- Varint frame fields ------------------------------------------------------------------------

/// A frame value and its varint bytes, written out by hand from the LEB128 definition.
struct VarintCase {
  std::uint64_t value;
  Bytes bytes;
};

/// An empty input packet with every frame at `ack`: each difference is 0, one byte.
Packet frames_at(std::uint32_t ack) {
  Packet p = input_packet(0, {});
  p.input.ack_frame = p.input.check_ack = p.input.current_frame = p.input.start_frame =
      p.input.held_frame = ack;
  return p;
}

Bytes slice(const Bytes& b, std::size_t at, std::size_t n) {
  if (at + n > b.size()) return {};
  return Bytes(b.begin() + static_cast<std::ptrdiff_t>(at),
               b.begin() + static_cast<std::ptrdiff_t>(at + n));
}

TEST(NetProtocolVarint, AckFrameAtEveryGroupBoundary) {
  const std::array<VarintCase, 8> cases = {{
      {0, {0x00}},
      {127, {0x7F}},
      {128, {0x80, 0x01}},
      {16383, {0xFF, 0x7F}},
      {16384, {0x80, 0x80, 0x01}},
      {(1U << 28) - 1, {0xFF, 0xFF, 0xFF, 0x7F}},
      {1U << 28, {0x80, 0x80, 0x80, 0x80, 0x01}},
      {max_u32, {0xFF, 0xFF, 0xFF, 0xFF, 0x0F}},
  }};
  for (const VarintCase& c : cases) {
    const Packet p = frames_at(static_cast<std::uint32_t>(c.value));
    const Bytes expected = input_bytes(p, {});
    EXPECT_EQ(slice(expected, header_size, c.bytes.size()), c.bytes) << c.value;
    // The ack, four zero differences (check_ack, current, start, held), advantage, count 0, gone
    // count 0, checks count 0.
    EXPECT_EQ(expected.size(), header_size + c.bytes.size() + 4 + 4 + trailer_size) << c.value;
    expect_round_trip(p, 4, expected);
  }
}

TEST(NetProtocolVarint, FrameDifferencesBothWaysInEveryField) {
  // ack 2^31 (5 bytes) leaves room for every difference from -2^31 to 2^31 - 1. The zigzag codes
  // cross each 7-bit group boundary from both sides.
  constexpr std::uint32_t ack = 1U << 31;
  struct Difference {
    std::int64_t d;
    Bytes bytes;
  };
  const std::array<Difference, 16> differences = {{
      {0, {0x00}},
      {-1, {0x01}},
      {1, {0x02}},
      {63, {0x7E}},
      {-64, {0x7F}},
      {64, {0x80, 0x01}},
      {-65, {0x81, 0x01}},
      {8191, {0xFE, 0x7F}},
      {-8192, {0xFF, 0x7F}},
      {8192, {0x80, 0x80, 0x01}},
      {-8193, {0x81, 0x80, 0x01}},
      {(1 << 27) - 1, {0xFE, 0xFF, 0xFF, 0x7F}},
      {-(1 << 27), {0xFF, 0xFF, 0xFF, 0x7F}},
      {1 << 27, {0x80, 0x80, 0x80, 0x80, 0x01}},
      {std::int64_t{ack} - 1, {0xFE, 0xFF, 0xFF, 0xFF, 0x0F}},
      {-std::int64_t{ack}, {0xFF, 0xFF, 0xFF, 0xFF, 0x0F}},
  }};
  // Where each frame field starts when every frame before it is at ack (one byte each): check_ack,
  // current_frame, start_frame (after advantage), held_frame (after count), the first check's
  // frame (after the gone count and the checks count; no deltas).
  const std::array<std::size_t, 5> offsets = {5, 6, 8, 10, 13};
  for (const Difference& d : differences) {
    const auto frame = static_cast<std::uint32_t>(std::int64_t{ack} + d.d);
    for (std::size_t field = 0; field < offsets.size(); ++field) {
      Packet p = frames_at(ack);
      p.input.checks = {{ack, 0x0123456789ABCDEFULL}};
      const std::array<std::uint32_t*, 5> targets = {&p.input.check_ack, &p.input.current_frame,
                                                     &p.input.start_frame, &p.input.held_frame,
                                                     &p.input.checks[0].frame};
      *targets[field] = frame;
      const Bytes expected = input_bytes(p, {});
      EXPECT_EQ(slice(expected, header_size + offsets[field], d.bytes.size()), d.bytes)
          << "difference " << d.d << ", field " << field;
      // The ack, the four other frames, advantage, count, gone count, checks count, the hash.
      EXPECT_EQ(expected.size(), header_size + 5 + 4 + 4 + 8 + d.bytes.size() + trailer_size);
      expect_round_trip(p, 4, expected);
    }
  }
}

TEST(NetProtocolVarint, ExtremeDifferences) {
  // Frame 0 against ack 2^32 - 1 (difference -(2^32 - 1), zigzag 2^33 - 3) and frame 2^32 - 1
  // against ack 0 (difference 2^32 - 1, zigzag 2^33 - 2): the longest frame fields, 5 bytes.
  const VarintCase down = {2 * std::uint64_t{max_u32} - 1, {0xFD, 0xFF, 0xFF, 0xFF, 0x1F}};
  const VarintCase up = {2 * std::uint64_t{max_u32}, {0xFE, 0xFF, 0xFF, 0xFF, 0x1F}};
  for (const bool falling : {true, false}) {
    const std::uint32_t ack = falling ? max_u32 : 0;
    const std::uint32_t frame = falling ? 0 : max_u32;
    const VarintCase& c = falling ? down : up;
    ASSERT_EQ(zigzag(frame, ack), c.value);
    Packet p = frames_at(ack);
    p.input.check_ack = p.input.current_frame = p.input.start_frame = p.input.held_frame = frame;
    p.input.checks.assign(max_checks_per_packet, HashCheck{frame, max_u64});
    const Bytes expected = input_bytes(p, {});
    // check_ack after the ack, current_frame, start_frame after advantage, held_frame after
    // count, the first check's frame after the gone count and the checks count.
    const std::size_t after_ack = header_size + (falling ? 5 : 1);
    for (const std::size_t at :
         {after_ack, after_ack + 5, after_ack + 11, after_ack + 17, after_ack + 24})
      EXPECT_EQ(slice(expected, at, 5), c.bytes) << "falling " << falling << ", at " << at;
    EXPECT_EQ(expected.size(),
              after_ack + 4 * 5 + 4 + max_checks_per_packet * (5 + 8) + trailer_size);
    expect_round_trip(p, 4, expected);
  }
}

TEST(NetProtocolVarint, TypicalInputPacketIsAtMostThirtyBytes) {
  // What a player sends every frame: ack_frame around 100000 (about half an hour at 60 Hz), the
  // other frames within 60 of it, two held inputs of 4 bytes, no checks, no player gone. Version 1
  // took 34 bytes (four u32 frames); now the ack takes 3 bytes and each difference 1 (zigzag <=
  // 120 < 128); version 3 added the held frame and the gone count (one byte each).
  const Bytes held = {0x10, 0x00, 0x7F, 0x01};
  const Bytes inputs = {0x10, 0x00, 0x7F, 0x01, 0x10, 0x00, 0x7F, 0x01};
  Bytes deltas;
  delta_encode(held, inputs, deltas);
  ASSERT_EQ(deltas, Bytes(8, 0));
  std::size_t largest = 0;
  for (const std::uint32_t ack : {99'000U, 100'000U, 101'000U}) {
    for (std::int64_t d = -60; d <= 60; ++d) {
      Packet p = input_packet(2, deltas);
      p.input.ack_frame = ack;
      p.input.check_ack = ack - 60;
      p.input.current_frame = ack + 60;
      p.input.advantage = 3;
      p.input.start_frame = static_cast<std::uint32_t>(std::int64_t{ack} + d);
      p.input.held_frame = ack - 2;
      // The ack, four one-byte differences, advantage, count, gone count, the tokens, checks count.
      const std::size_t expected_size = header_size + varint_size(ack) + 4 + 1 + 1 + 1 +
                                        zero_tokens(deltas.size()).size() + 1 + trailer_size;
      ASSERT_EQ(expected_size, input_datagram_size(p.input, zero_tokens(deltas.size()).size()));
      Bytes out;
      ASSERT_TRUE(encode(p, 4, out));
      EXPECT_EQ(out, input_bytes(p, zero_tokens(deltas.size())));
      EXPECT_EQ(out.size(), expected_size) << "ack " << ack << ", start " << d;
      largest = std::max(largest, out.size());
    }
  }
  EXPECT_EQ(largest, 30U);  // version 4: the 64-bit session id added 4 bytes
  EXPECT_LE(largest, 30U);
  RecordProperty("typical_input_bytes", std::to_string(largest));
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
  const auto rle = rle_part(out, p);
  return Bytes(rle.begin(), rle.end());
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
      EXPECT_LE(rle_part(out, p).size(), literal_bound(length)) << "input_size " << size;
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
      Bytes b;
      for (std::size_t i = 0; i < n; ++i)
        b.push_back(byte((bits >> i & 1U) != 0 ? 0x33 : 0));
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
    ASSERT_EQ(rle_part(out, p).size(), shortest_coding(deltas))
        << "length " << deltas.size() << ", first byte " << int{deltas[0]};
  }
}

TEST(NetProtocolRunLength, InputsOfOneByteMorePerInputAlwaysFitWithEightChecks) {
  // The literal bound makes the datagram size a function of count and input_size alone: count
  // inputs cost at most count * (input_size + 1) bytes. Whenever that and 8 checks fit in
  // max_datagram, the packet encodes, whatever the inputs are (here the worst case for a coder
  // that gives each lone zero a token: alternating zero and non-zero bytes), and its frames as far
  // apart as u32 allows (every frame varint at its longest).
  const std::size_t overhead = header_size + 5 * max_varint_size + 3 + 1 +
                               max_checks_per_packet * (max_varint_size + 8) + trailer_size;
  for (const std::size_t size : all_sizes()) {
    const std::size_t count =
        std::min<std::size_t>(max_inputs_per_packet, (max_datagram - overhead) / (size + 1));
    Bytes deltas(count * size);
    for (std::size_t i = 0; i < deltas.size(); ++i)
      deltas[i] = byte(i % 2 == 0 ? 0x40 : 0);
    Packet p = input_packet(static_cast<std::uint8_t>(count), deltas, max_checks());
    far_frames(p);
    ASSERT_EQ(input_datagram_size(p.input, 0), overhead);
    Bytes out;
    EXPECT_TRUE(encode(p, size, out)) << "input_size " << size << ", count " << count;
  }
}

TEST(NetProtocolRunLength, InputSizeOneAndSixtyFourCountZeroAndMaximum) {
  for (const std::size_t size : {std::size_t{1}, max_input_size, max_unit_size}) {
    const Packet none = input_packet(0, {});
    Bytes empty;
    ASSERT_TRUE(encode(none, size, empty));
    EXPECT_TRUE(rle_part(empty, none).empty());
    // The largest count of non-zero inputs that fits: derived from the layout and the literal
    // token cost, then checked to be the largest that encodes.
    const std::size_t fixed = input_datagram_size(none.input, 0);
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
  constexpr auto unknown = static_cast<std::uint8_t>(PacketType::state_chunk) + 1;
  for (const std::uint8_t type : {std::uint8_t{0}, std::uint8_t{unknown}, std::uint8_t{255}}) {
    hello.header.type = static_cast<PacketType>(type);
    expect_refused(hello, 4, "type " + std::to_string(type));
  }
}

TEST(NetProtocolEncode, RefusesWhatExceedsMaxDatagramAndAcceptsUpToIt) {
  // Non-zero deltas are coded as literal tokens, so the datagram size of count inputs with c
  // checks is known from the layout and the varint sizes of the frames: encode must succeed
  // exactly when it is <= max_datagram. Frames close together (a byte each) and as far apart as
  // u32 allows (5 bytes each).
  for (const bool far : {false, true}) {
    bool hit_max = false;
    bool hit_over = false;
    for (const std::size_t size : {1U, 2U, 3U, 4U, 5U, 6U, 7U, 8U, 64U}) {
      for (std::size_t count = 0; count <= max_inputs_per_packet; ++count) {
        Packet p =
            input_packet(static_cast<std::uint8_t>(count), non_zero_run(count * size, count));
        const std::size_t tokens = literal_bound(p.input.deltas.size());
        for (std::size_t c = 0; c <= max_checks_per_packet; ++c) {
          p.input.checks.assign(c, HashCheck{5, 6});
          if (far) far_frames(p);
          const std::size_t expected_size = input_datagram_size(p.input, tokens);
          if (expected_size < max_datagram - 40 || expected_size > max_datagram + 40) continue;
          Bytes out = {9};
          const bool ok = encode(p, size, out);
          EXPECT_EQ(ok, expected_size <= max_datagram) << far << " " << size << " " << count;
          EXPECT_EQ(out.size(), ok ? expected_size : 0U) << far << " " << size << " " << count;
          hit_max = hit_max || expected_size == max_datagram;
          hit_over = hit_over || expected_size == max_datagram + 1;
        }
      }
    }
    EXPECT_TRUE(hit_max) << "no case of exactly max_datagram bytes, far " << far;
    EXPECT_TRUE(hit_over) << "no case of max_datagram + 1 bytes, far " << far;
  }
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
  EXPECT_EQ(rle_part(out, p).size(), 1U);  // 40 zero bytes: one token
}

}  // namespace
}  // namespace detsim::net::protocol
