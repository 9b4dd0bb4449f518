// The session wire protocol (net/include/detsim/net/protocol.hpp), decoding side: decode refuses
// every truncation, every single-bit flip and hand-made datagrams with a correct checksum but bad
// contents (run-length tokens, checks, and varint frame fields that are redundant, over-long, out
// of u32 or cut short), each with the right DecodeError; seeded random and mutated datagrams never
// crash the decoder, and whatever it accepts re-encodes to an equal packet. Encoding, the varint
// layout and the run-length coder: net_protocol_test.cpp.
//
// Hand-made datagrams are built with the independent writer in support/protocol_writer.hpp.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <random>
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/net/protocol.hpp>

#include "support/protocol_writer.hpp"

namespace detsim::net::protocol {
namespace {

using namespace test_support;

// --- decode refuses ------------------------------------------------------------------------------

struct Sample {
  std::string name;
  Packet packet;
  std::size_t input_size;
};

/// The highest packet type: every one above is unknown.
constexpr std::uint8_t last_type = static_cast<std::uint8_t>(PacketType::state_chunk);

std::vector<Sample> samples() {
  std::vector<Sample> out;
  Packet hello = make(PacketType::hello, 0xDEADBEEF, 77);
  hello.hello = {0x0123456789ABCDEFULL, 4, 2, 3, 0xCAFEF00D};
  out.push_back({"hello", hello, 3});
  Packet reply = make(PacketType::hello_reply, 5, 6);
  reply.hello_reply.challenge = 0xCAFEF00D'0BADBEEFULL;
  out.push_back({"hello_reply", reply, 1});
  for (const PacketType type : {PacketType::ping, PacketType::pong}) {
    Packet ping = make(type, 9, 10);
    ping.ping.time_us = 123456789012345ULL;
    out.push_back({type == PacketType::ping ? "ping" : "pong", ping, 64});
  }
  Packet request = make(PacketType::state_request, 11, 12);
  request.state_request.offset = 70'000;
  out.push_back({"state_request", request, 4});
  Packet chunk = make(PacketType::state_chunk, 13, 14);
  chunk.state_chunk.total = 5000;
  chunk.state_chunk.offset = 1024;
  for (std::size_t i = 0; i < 40; ++i)
    chunk.state_chunk.data.push_back(byte(i * 29 + 3));
  out.push_back({"state_chunk", chunk, 4});
  out.push_back({"input empty", input_packet(0, {}), 4});
  Bytes mixed(20);
  for (std::size_t i = 0; i < mixed.size(); ++i)
    mixed[i] = byte(i % 5 < 2 ? 0 : i * 37 + 1);
  out.push_back({"input mixed", input_packet(5, mixed, {{1, 2}, {3, 4}, {5, 6}}), 4});
  out.push_back({"input 255 literal", input_packet(255, non_zero_run(255, 0)), 1});
  out.push_back({"input 64 held", input_packet(255, Bytes(255 * 64, 0), max_checks()), 64});
  // Every frame varint at its longest, and frames across several 7-bit group boundaries.
  Packet far = input_packet(5, mixed, {{1, 2}, {3, 4}});
  far_frames(far);
  out.push_back({"input far frames", far, 4});
  Packet near = input_packet(2, {0, 1}, {{16'320, 7}});
  near.input.ack_frame = 16'384;
  near.input.check_ack = 16'383;
  near.input.current_frame = 16'384 + 64;
  near.input.start_frame = 16'384 - 65;
  out.push_back({"input group boundaries", near, 1});
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
        if (i == 3 && (flipped[3] < 1 || flipped[3] > last_type)) expected = DecodeError::bad_type;
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
  for (std::uint8_t type = 1; type <= last_type; ++type)
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
  for (const std::uint8_t type :
       {std::uint8_t{0}, std::uint8_t{last_type + 1}, std::uint8_t{255}}) {
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
    ASSERT_GT(bytes.size(), trailer_size);
    Bytes body(bytes.begin(), bytes.end() - static_cast<std::ptrdiff_t>(trailer_size));
    Bytes shorter(body.begin(), body.end() - 1);
    Bytes longer = body;
    longer.push_back(0);
    EXPECT_EQ(decode_bytes(Writer().raw(shorter).sealed(), s.input_size), DecodeError::bad_length)
        << s.name;
    EXPECT_EQ(decode_bytes(Writer().raw(longer).sealed(), s.input_size), DecodeError::bad_length)
        << s.name;
  }
}

/// The header and the fields before the deltas of crafted datagrams: ack_frame 10, the other
/// frames a few frames from it (a varint byte each), no gone reports.
Writer& crafted_fields(Writer& w, std::uint8_t count) {
  return w.header(3, 1, 2)
      .varint(10)
      .frame(20, 10)
      .frame(30, 10)
      .u8(0)
      .frame(40, 10)
      .u8(count)
      .frame(10, 10)
      .u8(0);
}

/// An input datagram of `count` inputs whose deltas are the raw `tokens`, then `tail` (the checks
/// count and checks, or whatever the test wants), sealed.
Bytes crafted_input(std::uint8_t count, const Bytes& tokens, const Bytes& tail) {
  Writer w;
  crafted_fields(w, count).raw(tokens).raw(tail);
  return w.sealed();
}

/// A check whose frame is 8 frames before ack_frame 10: one varint byte, then the hash.
constexpr std::size_t crafted_check_size = 1 + 8;
Bytes crafted_checks(std::size_t declared, std::size_t present) {
  Writer w;
  w.u8(declared);
  for (std::size_t i = 0; i < present; ++i)
    w.frame(2, 10).u64(0x2222222222222222ULL * i);
  return w.bytes();
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
  // The fields before the deltas stop short: every resealed prefix of them.
  {
    Writer w;
    const Bytes fields = crafted_fields(w, 2).bytes();
    for (std::size_t n = header_size; n < fields.size(); ++n) {
      Writer prefix;
      prefix.raw(std::span<const std::uint8_t>(fields).first(n));
      EXPECT_EQ(decode_bytes(prefix.sealed(), 4), DecodeError::bad_length) << n << " bytes";
    }
  }

  // Checks: 9 is a bad field (with or without their bytes); missing or extra bytes a bad length.
  const Bytes deltas = {127 + 8};
  EXPECT_EQ(decode_bytes(crafted_input(2, deltas, crafted_checks(9, 0)), 4),
            DecodeError::bad_field);
  EXPECT_EQ(decode_bytes(crafted_input(2, deltas, crafted_checks(9, 9)), 4),
            DecodeError::bad_field);
  const Bytes two = crafted_checks(2, 2);
  ASSERT_EQ(two.size(), 1 + 2 * crafted_check_size);
  EXPECT_EQ(decode_bytes(crafted_input(2, deltas, two), 4), DecodeError::none);
  Bytes missing = two;
  missing.pop_back();
  EXPECT_EQ(decode_bytes(crafted_input(2, deltas, missing), 4), DecodeError::bad_length);
  missing.resize(1 + crafted_check_size);
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

TEST(NetProtocolDecode, GoneReportsAreBoundedAndNamePlayersBelowEight) {
  // The fields before the gone reports, then `gone`, then no deltas and no checks.
  const auto crafted = [](const Bytes& gone) {
    Writer w;
    w.header(3, 1, 2).varint(10).frame(20, 10).frame(30, 10).u8(0).frame(40, 10).u8(0);
    w.frame(10, 10).raw(gone).u8(0);
    return w.sealed();
  };
  Packet p;
  ASSERT_EQ(decode(crafted({2, 3, 0, 7, 1}), 4, p), DecodeError::none);  // players 3 and 7
  ASSERT_EQ(p.input.gone.size(), 2U);
  EXPECT_EQ(p.input.gone[0], (GoneReport{3, 10}));
  EXPECT_EQ(p.input.gone[1], (GoneReport{7, 9}));
  EXPECT_EQ(decode(crafted({1, 8, 0}), 4, p), DecodeError::bad_field);  // player 8
  Bytes nine = {9};
  for (std::uint8_t player = 0; player < 9; ++player)
    nine.insert(nine.end(), {static_cast<std::uint8_t>(player % 8), 0});
  EXPECT_EQ(decode(crafted(nine), 4, p), DecodeError::bad_field);        // more than 8 reports
  EXPECT_EQ(decode(crafted({2, 3, 0}), 4, p), DecodeError::bad_length);  // one report missing
  // encode() refuses what decode() refuses.
  Packet many = input_packet(0, {});
  many.input.gone.assign(max_gone_reports + 1, GoneReport{1, 11});
  Bytes out;
  EXPECT_FALSE(encode(many, 4, out));
}

TEST(NetProtocolDecode, BackReportsShareTheCountByteAndAreBounded) {
  // The list byte: gone count in the low nibble, back count in the high one; each back report
  // is a player and two frames relative to ack_frame (10 here).
  const auto crafted = [](const Bytes& lists) {
    Writer w;
    w.header(3, 1, 2).varint(10).frame(20, 10).frame(30, 10).u8(0).frame(40, 10).u8(0);
    w.frame(10, 10).raw(lists).u8(0);
    return w.sealed();
  };
  Packet p;
  // One gone report (player 1 from 9), two back reports: player 2 over [10, 15), 5 over [9, 9).
  ASSERT_EQ(decode(crafted({0x21, 1, 1, 2, 0, 10, 5, 1, 1}), 4, p), DecodeError::none);
  ASSERT_EQ(p.input.gone.size(), 1U);
  EXPECT_EQ(p.input.gone[0], (GoneReport{1, 9}));
  ASSERT_EQ(p.input.back.size(), 2U);
  EXPECT_EQ(p.input.back[0], (BackReport{2, 10, 15}));
  EXPECT_EQ(p.input.back[1], (BackReport{5, 9, 9}));
  EXPECT_EQ(decode(crafted({0x10, 8, 0, 0}), 4, p), DecodeError::bad_field);  // player 8
  Bytes nine = {0x90};
  for (std::uint8_t player = 0; player < 9; ++player)
    nine.insert(nine.end(), {static_cast<std::uint8_t>(player % 8), 0, 0});
  EXPECT_EQ(decode(crafted(nine), 4, p), DecodeError::bad_field);           // 9 back reports
  EXPECT_EQ(decode(crafted({0x10, 2, 0}), 4, p), DecodeError::bad_length);  // `until` missing
  EXPECT_EQ(decode(crafted({0xF0}), 4, p), DecodeError::bad_field);         // 15 back reports
  Packet many = input_packet(0, {});
  many.input.back.assign(max_gone_reports + 1, BackReport{1, 11, 12});
  Bytes out;
  EXPECT_FALSE(encode(many, 4, out));
  many.input.back.assign(1, BackReport{8, 11, 12});
  EXPECT_FALSE(encode(many, 4, out));
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

// --- Varints refused ----------------------------------------------------------------------------

/// The raw bytes of the five frame fields in layout order: ack_frame, check_ack, current_frame,
/// start_frame and the frame of the one check.
using FrameFields = std::array<Bytes, 5>;

/// An input datagram of no inputs and one check whose frame fields are `f`, sealed.
Bytes crafted_frames(const FrameFields& f) {
  Writer w;
  // ... start_frame, count 0, held_frame = ack_frame, no gone reports, no deltas, one check.
  w.header(3, 1, 2).raw(f[0]).raw(f[1]).raw(f[2]).u8(0).raw(f[3]).u8(0).u8(0).u8(0).u8(1).raw(f[4]);
  return w.u64(0x5555555555555555ULL).sealed();
}

/// `f` with field `i` replaced by `bytes`.
FrameFields with(FrameFields f, std::size_t i, Bytes bytes) {
  f[i] = std::move(bytes);
  return f;
}

TEST(NetProtocolDecodeVarint, CanonicalFieldsDecode) {
  // ack 2^32 - 1 and every other frame 0 (the longest zigzag code that is in range), and the
  // reverse; written out by hand from the LEB128 and zigzag definitions.
  const Bytes max = {0xFF, 0xFF, 0xFF, 0xFF, 0x0F};
  const Bytes down = {0xFD, 0xFF, 0xFF, 0xFF, 0x1F};  // -(2^32 - 1)
  const Bytes up = {0xFE, 0xFF, 0xFF, 0xFF, 0x1F};    // +(2^32 - 1)
  Packet p;
  ASSERT_EQ(decode(crafted_frames({{max, down, down, down, down}}), 4, p), DecodeError::none);
  EXPECT_EQ(p.input.ack_frame, max_u32);
  EXPECT_EQ(p.input.check_ack, 0U);
  EXPECT_EQ(p.input.current_frame, 0U);
  EXPECT_EQ(p.input.start_frame, 0U);
  EXPECT_EQ(p.input.checks, (std::vector<HashCheck>{{0, 0x5555555555555555ULL}}));
  ASSERT_EQ(decode(crafted_frames({{{0x00}, up, up, up, up}}), 4, p), DecodeError::none);
  EXPECT_EQ(p.input.ack_frame, 0U);
  EXPECT_EQ(p.input.check_ack, max_u32);
  EXPECT_EQ(p.input.current_frame, max_u32);
  EXPECT_EQ(p.input.start_frame, max_u32);
  EXPECT_EQ(p.input.checks.at(0).frame, max_u32);
  // Small values: ack 300 (0xAC 0x02), differences -1, +1, 0, +64.
  ASSERT_EQ(decode(crafted_frames({{{0xAC, 0x02}, {0x01}, {0x02}, {0x00}, {0x80, 0x01}}}), 4, p),
            DecodeError::none);
  EXPECT_EQ(p.input.ack_frame, 300U);
  EXPECT_EQ(p.input.check_ack, 299U);
  EXPECT_EQ(p.input.current_frame, 301U);
  EXPECT_EQ(p.input.start_frame, 300U);
  EXPECT_EQ(p.input.checks.at(0).frame, 364U);
}

TEST(NetProtocolDecodeVarint, RedundantAndOverlongVarintsAreBadFields) {
  const FrameFields good = {{{0x0A}, {0x00}, {0x00}, {0x00}, {0x00}}};
  ASSERT_EQ(decode_bytes(crafted_frames(good), 4), DecodeError::none);
  const std::array<Bytes, 6> refused = {{
      {0x80, 0x00},                          // 0 with a redundant trailing zero byte
      {0x8A, 0x80, 0x00},                    // 10 with two
      {0xFF, 0xFF, 0xFF, 0xFF, 0x00},        // 2^28 - 1 in 5 bytes
      {0x80, 0x80, 0x80, 0x80, 0x80, 0x01},  // 6 bytes
      {0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0x7F},  // 6 bytes
      {0x80, 0x80, 0x80, 0x80, 0x80, 0x00},  // 6 bytes, the last redundant
  }};
  for (std::size_t field = 0; field < good.size(); ++field) {
    for (const Bytes& bytes : refused) {
      EXPECT_EQ(decode_bytes(crafted_frames(with(good, field, bytes)), 4), DecodeError::bad_field)
          << "field " << field << ", " << bytes.size() << " bytes";
    }
  }
  // A continuation bit on the fifth byte is enough to refuse: the decoder reads no sixth byte. A
  // check whose frame has one and whose hash then has 7 bytes fits the datagram exactly if the
  // varint stops at 5 bytes, so it is a bad field, not a body that ends short.
  Bytes datagram = crafted_frames(with(good, 4, {0x80, 0x80, 0x80, 0x80, 0x80, 0x01}));
  datagram.erase(datagram.end() - static_cast<std::ptrdiff_t>(trailer_size + 1),
                 datagram.end() - static_cast<std::ptrdiff_t>(trailer_size));
  reseal(datagram);
  EXPECT_EQ(decode_bytes(datagram, 4), DecodeError::bad_field);
}

TEST(NetProtocolDecodeVarint, FramesOutsideU32AreBadFields) {
  // The ack itself: 2^32, and the largest 5-byte value 2^35 - 1.
  const FrameFields zeros = {{{0x00}, {0x00}, {0x00}, {0x00}, {0x00}}};
  EXPECT_EQ(decode_bytes(crafted_frames(with(zeros, 0, {0x80, 0x80, 0x80, 0x80, 0x10})), 4),
            DecodeError::bad_field);
  EXPECT_EQ(decode_bytes(crafted_frames(with(zeros, 0, {0xFF, 0xFF, 0xFF, 0xFF, 0x7F})), 4),
            DecodeError::bad_field);
  // A difference that leads below 0 or above 2^32 - 1, in every frame field.
  const Bytes max = {0xFF, 0xFF, 0xFF, 0xFF, 0x0F};
  const FrameFields at_max = {{max, {0x00}, {0x00}, {0x00}, {0x00}}};
  ASSERT_EQ(decode_bytes(crafted_frames(zeros), 4), DecodeError::none);
  ASSERT_EQ(decode_bytes(crafted_frames(at_max), 4), DecodeError::none);
  for (std::size_t field = 1; field < zeros.size(); ++field) {
    const std::string where = "field " + std::to_string(field);
    // ack 0: -1, -(2^32), +2^32, the largest 5-byte zigzag code.
    for (const Bytes& bytes :
         {Bytes{0x01}, Bytes{0xFF, 0xFF, 0xFF, 0xFF, 0x1F}, Bytes{0x80, 0x80, 0x80, 0x80, 0x20},
          Bytes{0xFF, 0xFF, 0xFF, 0xFF, 0x7F}})
      EXPECT_EQ(decode_bytes(crafted_frames(with(zeros, field, bytes)), 4), DecodeError::bad_field)
          << where << ", ack 0";
    // ack 2^32 - 1: +1, +(2^32 - 1), -(2^32).
    for (const Bytes& bytes :
         {Bytes{0x02}, Bytes{0xFE, 0xFF, 0xFF, 0xFF, 0x1F}, Bytes{0xFF, 0xFF, 0xFF, 0xFF, 0x1F}})
      EXPECT_EQ(decode_bytes(crafted_frames(with(at_max, field, bytes)), 4), DecodeError::bad_field)
          << where << ", ack 2^32 - 1";
    // Just inside: ack 2^32 - 1 and -(2^32 - 1) reaches frame 0.
    EXPECT_EQ(decode_bytes(crafted_frames(with(at_max, field, {0xFD, 0xFF, 0xFF, 0xFF, 0x1F})), 4),
              DecodeError::none)
        << where;
  }
}

TEST(NetProtocolDecodeVarint, ADatagramEndingInsideAVarintIsABadLength) {
  // Frames whose varints are all 5 bytes long; every resealed prefix of the body (no deltas) is
  // short, whether it ends inside a varint, between fields or inside the hash.
  const Bytes down = {0xFD, 0xFF, 0xFF, 0xFF, 0x1F};
  const Bytes full = crafted_frames({{{0xFF, 0xFF, 0xFF, 0xFF, 0x0F}, down, down, down, down}});
  ASSERT_EQ(decode_bytes(full, 4), DecodeError::none);
  const std::size_t body_end = full.size() - trailer_size;
  std::size_t inside_varint = 0;
  for (std::size_t n = header_size; n < body_end; ++n) {
    Writer prefix;
    prefix.raw(std::span<const std::uint8_t>(full).first(n));
    EXPECT_EQ(decode_bytes(prefix.sealed(), 4), DecodeError::bad_length) << n << " bytes";
    if ((full[n - 1] & 0x80U) != 0) ++inside_varint;
  }
  EXPECT_EQ(inside_varint, 5U * 4U);  // 4 continuation bytes in each of the 5 varints
  // A lone continuation byte in each field, at the end of the datagram.
  const FrameFields good = {{{0x0A}, {0x00}, {0x00}, {0x00}, {0x00}}};
  // Where each field starts in the body: after advantage, count and the checks count as they come.
  const std::array<std::size_t, 5> at = {0, 1, 2, 4, 7};
  for (std::size_t field = 0; field < good.size(); ++field) {
    Bytes bytes = crafted_frames(with(good, field, {0x80}));
    bytes.resize(header_size + at[field] + 1);
    bytes.resize(bytes.size() + trailer_size);
    reseal(bytes);
    EXPECT_EQ(decode_bytes(bytes, 4), DecodeError::bad_length) << "field " << field;
  }
}

// --- Random and mutated datagrams ------------------------------------------------------------

/// A frame a few frames from `ack` (as sessions send them) or anywhere in u32.
std::uint32_t random_frame(std::mt19937_64& rng, std::uint32_t ack) {
  if (rng() % 2 == 0) return static_cast<std::uint32_t>(rng());
  const std::int64_t frame = std::int64_t{ack} + static_cast<std::int64_t>(rng() % 257) - 128;
  return frame < 0 || frame > std::int64_t{max_u32} ? ack : static_cast<std::uint32_t>(frame);
}

/// A random valid packet whose inputs (if any) are `size` bytes.
Packet random_packet(std::mt19937_64& rng, std::size_t size) {
  const auto type = static_cast<PacketType>(rng() % 5 + 1);
  Packet p = make(type, static_cast<std::uint32_t>(rng()), static_cast<std::uint16_t>(rng()));
  p.hello = {rng(), static_cast<std::uint8_t>(rng()), static_cast<std::uint8_t>(rng()),
             static_cast<std::uint8_t>(rng()), static_cast<std::uint32_t>(rng())};
  p.hello_reply.challenge = rng();
  p.ping.time_us = rng();
  InputBody& b = p.input;
  b.ack_frame = static_cast<std::uint32_t>(rng() % 2 == 0 ? rng() : rng() % 20'000);
  b.check_ack = random_frame(rng, b.ack_frame);
  b.current_frame = random_frame(rng, b.ack_frame);
  b.advantage = static_cast<std::int8_t>(static_cast<std::uint8_t>(rng()));
  b.start_frame = random_frame(rng, b.ack_frame);
  const std::size_t most = std::min<std::size_t>(max_inputs_per_packet, 700 / size);
  b.count = static_cast<std::uint8_t>(rng() % (most + 1));
  b.deltas.resize(std::size_t{b.count} * size);
  const std::uint64_t zero_odds = rng() % 4 + 1;  // 1 in zero_odds bytes is non-zero
  for (std::uint8_t& d : b.deltas)
    d = byte(rng() % zero_odds == 0 ? rng() : 0);
  b.checks.resize(rng() % (max_checks_per_packet + 1));
  for (HashCheck& c : b.checks)
    c = {random_frame(rng, b.ack_frame), rng()};
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
