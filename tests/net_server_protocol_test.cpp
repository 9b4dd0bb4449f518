// The game-server wire protocol (net/server_protocol.hpp): every packet type round-trips, and the
// decoder refuses every malformed datagram — truncated, lengthened, a field out of its range, a
// count that disagrees with the bytes — with an error, never a crash or an allocation beyond the
// packet's bounds.
#include <gtest/gtest.h>

#include <random>

#include <detsim/core/hash.hpp>
#include <detsim/net/server_protocol.hpp>

namespace detsim {
namespace {

namespace sp = net::server_protocol;
using sp::DecodeError;

constexpr sp::Sizes sizes{3, 4};  // 3 players, 4-byte inputs: a unit is 1 + 12 bytes

/// Re-signs a datagram whose bytes a test changed, so that the decoder reaches the fields.
void resign(std::vector<std::uint8_t>& d) {
  d.resize(d.size() - sp::trailer_size);
  const auto sum = static_cast<std::uint32_t>(hash_bytes(d));
  for (int i = 0; i < 4; ++i)
    d.push_back(static_cast<std::uint8_t>(sum >> (8 * i)));
}

std::vector<sp::Packet> samples() {
  std::vector<sp::Packet> out;
  sp::Packet p;
  p.header = {sp::PacketType::connect, 0, 7};
  p.connect = {0x1122'3344'5566'7788ULL, 0xABCDEF, 2};
  out.push_back(p);
  p = {};
  p.header = {sp::PacketType::welcome, 0x5555, 1};
  p.welcome.nonce = 0xABCDEF;
  p.welcome.player = 2;
  p.welcome.players = 3;
  p.welcome.input_size = 4;
  p.welcome.authority = sp::Authority::state;
  p.welcome.frame_us = 16'667;
  p.welcome.frames = 3600;
  p.welcome.start_frame = 120;
  p.welcome.initial_hash = 0x0123'4567'89AB'CDEFULL;
  p.welcome.description = {'a', 'r', 'e', 'n', 'a'};
  out.push_back(p);
  p = {};
  p.header = {sp::PacketType::reject, 0, 2};
  p.reject = {0xABCDEF, sp::RejectReason::full};
  out.push_back(p);
  p = {};
  p.header = {sp::PacketType::input, 0x5555, 3};
  p.input.ack = 1000;
  p.input.snapshot_ack = 990;
  p.input.time_ms = 123'456;
  p.input.start = 1002;
  p.input.count = 3;
  p.input.inputs = {1, 2, 3, 4, 1, 2, 3, 4, 0, 0, 9, 9};
  out.push_back(p);
  p = {};
  p.header = {sp::PacketType::update, 0x5555, 4};
  p.update.frame = 1010;
  p.update.input_ack = 1005;
  p.update.lead = -3;
  p.update.echo_ms = 123'000;
  p.update.start = 1000;
  p.update.count = 2;
  p.update.units.assign(2 * sp::unit_size(3, 4), 0);
  p.update.units[0] = 0x04;
  p.update.units[5] = 0x77;
  p.update.hash = 0xFEED'FACE'CAFE'BEEFULL;
  out.push_back(p);
  p = {};
  p.header = {sp::PacketType::snapshot, 0x5555, 5};
  p.snapshot = {1010, 991, 0xDEAD'BEEFULL, 5000, 1024, std::vector<std::uint8_t>(1024, 0x5A)};
  out.push_back(p);
  p = {};
  p.header = {sp::PacketType::leave, 0x5555, 6};
  out.push_back(p);
  return out;
}

TEST(NetServerProtocol, EveryPacketTypeRoundTrips) {
  for (const sp::Packet& p : samples()) {
    SCOPED_TRACE(static_cast<int>(p.header.type));
    std::vector<std::uint8_t> bytes;
    ASSERT_TRUE(sp::encode(p, sizes, bytes));
    sp::Packet q;
    ASSERT_EQ(sp::decode(bytes, sizes, q), DecodeError::none);
    EXPECT_EQ(q.header.type, p.header.type);
    EXPECT_EQ(q.header.token, p.header.token);
    EXPECT_EQ(q.header.sequence, p.header.sequence);
    switch (p.header.type) {
      case sp::PacketType::connect:
        EXPECT_EQ(q.connect.game, p.connect.game);
        EXPECT_EQ(q.connect.nonce, p.connect.nonce);
        EXPECT_EQ(q.connect.seat, p.connect.seat);
        break;
      case sp::PacketType::welcome:
        EXPECT_EQ(q.welcome.player, 2);
        EXPECT_EQ(q.welcome.authority, sp::Authority::state);
        EXPECT_EQ(q.welcome.start_frame, 120U);
        EXPECT_EQ(q.welcome.initial_hash, p.welcome.initial_hash);
        EXPECT_EQ(q.welcome.description, p.welcome.description);
        break;
      case sp::PacketType::reject:
        EXPECT_EQ(q.reject.reason, sp::RejectReason::full);
        break;
      case sp::PacketType::input:
        EXPECT_EQ(q.input.ack, 1000U);
        EXPECT_EQ(q.input.snapshot_ack, 990U);
        EXPECT_EQ(q.input.start, 1002U);
        EXPECT_EQ(q.input.inputs, p.input.inputs);  // chained on the wire, plain here
        break;
      case sp::PacketType::update:
        EXPECT_EQ(q.update.lead, -3);
        EXPECT_EQ(q.update.start, 1000U);
        EXPECT_EQ(q.update.units, p.update.units);
        EXPECT_EQ(q.update.hash, p.update.hash);
        break;
      case sp::PacketType::snapshot:
        EXPECT_EQ(q.snapshot.base, 991U);
        EXPECT_EQ(q.snapshot.offset, 1024U);
        EXPECT_EQ(q.snapshot.data, p.snapshot.data);
        break;
      case sp::PacketType::leave:
        break;
    }
  }
}

TEST(NetServerProtocol, HeldInputsCostAlmostNothing) {
  // The inputs are XOR-chained and run-length coded: 100 frames of one held input take a few
  // bytes beyond the first.
  sp::Packet p;
  p.header.type = sp::PacketType::input;
  p.input.count = 100;
  for (int k = 0; k < 100; ++k)
    p.input.inputs.insert(p.input.inputs.end(), {7, 0, 200, 1});
  std::vector<std::uint8_t> bytes;
  ASSERT_TRUE(sp::encode(p, sizes, bytes));
  EXPECT_LT(bytes.size(), sp::header_size + sp::trailer_size + 20 + 10);
}

TEST(NetServerProtocol, TruncatedAndLengthenedDatagramsAreRefused) {
  for (const sp::Packet& p : samples()) {
    std::vector<std::uint8_t> bytes;
    ASSERT_TRUE(sp::encode(p, sizes, bytes));
    sp::Packet q;
    for (std::size_t n = 0; n < bytes.size(); ++n) {
      std::vector<std::uint8_t> cut(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(n));
      if (cut.size() >= sp::header_size + sp::trailer_size) resign(cut);
      EXPECT_NE(sp::decode(cut, sizes, q), DecodeError::none) << n;
    }
    std::vector<std::uint8_t> longer = bytes;
    longer.insert(longer.end() - sp::trailer_size, 0);
    resign(longer);
    EXPECT_EQ(sp::decode(longer, sizes, q), DecodeError::bad_length);
  }
}

TEST(NetServerProtocol, TheFramingIsChecked) {
  std::vector<std::uint8_t> bytes;
  ASSERT_TRUE(sp::encode(samples()[0], sizes, bytes));
  sp::Packet q;
  std::vector<std::uint8_t> d = bytes;
  d[1] = 'N';  // the session protocol's magic
  EXPECT_EQ(sp::decode(d, sizes, q), DecodeError::bad_magic);
  d = bytes;
  d[2] = sp::version + 1;
  EXPECT_EQ(sp::decode(d, sizes, q), DecodeError::bad_version);
  d = bytes;
  d[3] = 0;
  EXPECT_EQ(sp::decode(d, sizes, q), DecodeError::bad_type);
  d[3] = 8;
  EXPECT_EQ(sp::decode(d, sizes, q), DecodeError::bad_type);
  d = bytes;
  d[sp::header_size] ^= 1;  // a flipped bit in the body
  EXPECT_EQ(sp::decode(d, sizes, q), DecodeError::bad_checksum);
  EXPECT_EQ(sp::decode(std::vector<std::uint8_t>(1201, 0), sizes, q), DecodeError::too_long);
}

TEST(NetServerProtocol, FieldsOutOfRangeAreRefused) {
  sp::Packet q;
  const auto field_error = [&](const sp::Packet& p, std::size_t at, std::uint8_t value,
                               const sp::Sizes& s = sizes) {
    std::vector<std::uint8_t> bytes;
    EXPECT_TRUE(sp::encode(p, s, bytes));
    bytes.at(sp::header_size + at) = value;
    resign(bytes);
    return sp::decode(bytes, s, q);
  };
  const std::vector<sp::Packet> all = samples();
  // welcome: player (at 8) beyond players; players 0; authority (11) unknown; input size 0.
  EXPECT_EQ(field_error(all[1], 8, 3), DecodeError::bad_field);
  EXPECT_EQ(field_error(all[1], 9, 0), DecodeError::bad_field);
  EXPECT_EQ(field_error(all[1], 10, 0), DecodeError::bad_field);
  EXPECT_EQ(field_error(all[1], 10, 65), DecodeError::bad_field);
  EXPECT_EQ(field_error(all[1], 11, 2), DecodeError::bad_field);
  // reject: reason 0 and 4.
  EXPECT_EQ(field_error(all[2], 8, 0), DecodeError::bad_field);
  EXPECT_EQ(field_error(all[2], 8, 4), DecodeError::bad_field);
  // snapshot: a total of 0 (total is the varint after frame (2 bytes), base (1) and hash (8)).
  EXPECT_EQ(field_error(all[5], 11, 0), DecodeError::bad_field);
  // input and update need the match's sizes: a client not yet welcomed reads neither.
  std::vector<std::uint8_t> bytes;
  ASSERT_TRUE(sp::encode(all[3], sizes, bytes));
  EXPECT_EQ(sp::decode(bytes, {}, q), DecodeError::bad_field);
  ASSERT_TRUE(sp::encode(all[4], sizes, bytes));
  EXPECT_EQ(sp::decode(bytes, {}, q), DecodeError::bad_field);
  // Inputs of another size than the match's: the run-length tokens do not end where they should.
  ASSERT_TRUE(sp::encode(all[3], sizes, bytes));
  EXPECT_NE(sp::decode(bytes, {3, 5}, q), DecodeError::none);
}

TEST(NetServerProtocol, EncodeRefusesWhatNoDatagramHolds) {
  std::vector<std::uint8_t> bytes;
  sp::Packet p = samples()[3];
  p.input.count = 4;  // the inputs hold 3
  EXPECT_FALSE(sp::encode(p, sizes, bytes));
  EXPECT_TRUE(bytes.empty());
  p = samples()[1];
  p.welcome.description.assign(sp::max_description + 1, 'x');
  EXPECT_FALSE(sp::encode(p, sizes, bytes));
  p = samples()[5];
  p.snapshot.data.assign(sp::max_snapshot_chunk + 1, 0);
  EXPECT_FALSE(sp::encode(p, sizes, bytes));
  // 255 units of 1000 random-ish bytes: more than a datagram.
  p = samples()[4];
  const sp::Sizes big{100, 10};
  p.update.count = 255;
  p.update.units.assign(255 * sp::unit_size(100, 10), 0);
  for (std::size_t i = 0; i < p.update.units.size(); ++i)
    p.update.units[i] = static_cast<std::uint8_t>(i * 131 + 7);
  EXPECT_FALSE(sp::encode(p, big, bytes));
}

TEST(NetServerProtocol, RandomBytesNeverCrashTheDecoder) {
  std::mt19937_64 random(25);
  sp::Packet q;
  std::size_t decoded = 0;
  for (int i = 0; i < 20'000; ++i) {
    // Half of them valid samples with a few bytes changed and re-signed, half pure noise.
    std::vector<std::uint8_t> d;
    if (i % 2 == 0) {
      const std::vector<sp::Packet> all = samples();
      // Every sample but the last (leave), whose body is empty.
      ASSERT_TRUE(sp::encode(all[static_cast<std::size_t>(i / 2) % (all.size() - 1)], sizes, d));
      for (int k = 0; k < 3; ++k)
        d[sp::header_size + random() % (d.size() - sp::header_size - sp::trailer_size)] =
            static_cast<std::uint8_t>(random());
      resign(d);
    } else {
      d.resize(random() % 1300);
      for (std::uint8_t& b : d)
        b = static_cast<std::uint8_t>(random());
    }
    if (sp::decode(d, sizes, q) == DecodeError::none) ++decoded;
  }
  EXPECT_GT(decoded, 0U);  // changed values in range decode; the rest are refused, none crash
}

TEST(NetServerProtocol, ChainAndUnchainAreInverse) {
  std::vector<std::uint8_t> units = {1, 2, 3, 1, 2, 3, 9, 9, 9};
  const std::vector<std::uint8_t> reference = {1, 2, 0};
  std::vector<std::uint8_t> chained = units;
  sp::chain(reference, chained);
  EXPECT_EQ(chained, (std::vector<std::uint8_t>{0, 0, 3, 0, 0, 0, 8, 11, 10}));
  sp::unchain(reference, chained);
  EXPECT_EQ(chained, units);
}

}  // namespace
}  // namespace detsim
