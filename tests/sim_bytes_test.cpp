// ByteWriter / ByteReader: the canonical byte encoding every saved state, replay and packet is
// built from (docs/DETERMINISM.md rule 6: explicit little-endian, field by field). The expected
// byte vectors here are written out by hand from the definition of little-endian two's complement
// and Q32.32 (raw = value * 2^32), never produced by the code under test.
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <detsim/core/bytes.hpp>
#include <detsim/fixed/decimal.hpp>

#include "support/vector_print.hpp"

namespace detsim {
namespace {

using namespace detsim::literals;
using Bytes = std::vector<std::uint8_t>;

Bytes written(void (*write)(ByteWriter&)) {
  ByteWriter w;
  write(w);
  return w.bytes();
}

// ---- ByteWriter: exact bytes ----

TEST(ByteWriter, IntegersAreLittleEndian) {
  EXPECT_EQ(written([](ByteWriter& w) { w.u8(0xAB); }), (Bytes{0xAB}));
  EXPECT_EQ(written([](ByteWriter& w) { w.u16(0x1234); }), (Bytes{0x34, 0x12}));
  EXPECT_EQ(written([](ByteWriter& w) { w.u32(0x12345678); }), (Bytes{0x78, 0x56, 0x34, 0x12}));
  EXPECT_EQ(written([](ByteWriter& w) { w.u64(0x0102030405060708U); }),
            (Bytes{0x08, 0x07, 0x06, 0x05, 0x04, 0x03, 0x02, 0x01}));
  EXPECT_EQ(written([](ByteWriter& w) { w.u64(0xFEDCBA9876543210U); }),
            (Bytes{0x10, 0x32, 0x54, 0x76, 0x98, 0xBA, 0xDC, 0xFE}));
  // Two's complement, whatever the host does.
  EXPECT_EQ(written([](ByteWriter& w) { w.i64(-2); }),
            (Bytes{0xFE, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF}));
  EXPECT_EQ(written([](ByteWriter& w) { w.i64(std::numeric_limits<std::int64_t>::min()); }),
            (Bytes{0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x80}));
  EXPECT_EQ(written([](ByteWriter& w) { w.i64(0x0000012345678901); }),
            (Bytes{0x01, 0x89, 0x67, 0x45, 0x23, 0x01, 0x00, 0x00}));
  EXPECT_EQ(written([](ByteWriter& w) {
              w.boolean(true);
              w.boolean(false);
            }),
            (Bytes{0x01, 0x00}));
}

TEST(ByteWriter, FixedIsItsRawInt64) {
  // 1.5 = 0x1'8000'0000 raw.
  EXPECT_EQ(written([](ByteWriter& w) { w.fixed(1.5_fx); }),
            (Bytes{0x00, 0x00, 0x00, 0x80, 0x01, 0x00, 0x00, 0x00}));
  // -1 = -2^32 raw = 0xFFFF'FFFF'0000'0000.
  EXPECT_EQ(written([](ByteWriter& w) { w.fixed(-1_fx); }),
            (Bytes{0x00, 0x00, 0x00, 0x00, 0xFF, 0xFF, 0xFF, 0xFF}));
  // The smallest step, 2^-32 = raw 1.
  EXPECT_EQ(written([](ByteWriter& w) { w.fixed(Fixed::epsilon()); }),
            (Bytes{0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}));
}

TEST(ByteWriter, Vec3IsXYZAndQuatIsWXYZ) {
  const Bytes one{0x00, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00};
  const Bytes two{0x00, 0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00};
  const Bytes minus_half{0x00, 0x00, 0x00, 0x80, 0xFF, 0xFF, 0xFF, 0xFF};  // -2^31 raw
  const Bytes zero(8, 0x00);
  const auto cat = [](std::initializer_list<Bytes> parts) {
    Bytes out;
    for (const Bytes& p : parts)
      out.insert(out.end(), p.begin(), p.end());
    return out;
  };
  EXPECT_EQ(written([](ByteWriter& w) {
              w.vec3({1_fx, 2_fx, -0.5_fx});
            }),
            cat({one, two, minus_half}));
  EXPECT_EQ(written([](ByteWriter& w) { w.quat(Quat{}); }), cat({one, zero, zero, zero}));
  EXPECT_EQ(written([](ByteWriter& w) {
              w.quat({-0.5_fx, 1_fx, 0_fx, 2_fx});
            }),
            cat({minus_half, one, zero, two}));
}

TEST(ByteWriter, AppendsRawAndManagesItsBuffer) {
  ByteWriter w;
  EXPECT_EQ(w.size(), 0U);
  w.u16(0xBEEF);
  const Bytes blob{1, 2, 3};
  w.raw(blob);
  w.raw({});
  EXPECT_EQ(w.bytes(), (Bytes{0xEF, 0xBE, 1, 2, 3}));
  EXPECT_EQ(w.size(), 5U);
  const Bytes taken = w.take();
  EXPECT_EQ(taken, (Bytes{0xEF, 0xBE, 1, 2, 3}));
  w.clear();
  EXPECT_EQ(w.size(), 0U);
  w.u8(9);
  EXPECT_EQ(w.bytes(), (Bytes{9}));
}

// ---- ByteReader: round trips ----

TEST(ByteReader, ReadsBackEveryType) {
  const Quat q{-0.5_fx, 0.5_fx, -Fixed::epsilon(), Fixed::max()};
  const Vec3 v{Fixed::min(), 0_fx, 123.456_fx};
  ByteWriter w;
  w.u8(0xFE);
  w.u16(0xFFFF);
  w.u32(0x80000001U);
  w.u64(0xFFFFFFFFFFFFFFFFU);
  w.i64(std::numeric_limits<std::int64_t>::min());
  w.i64(-1);
  w.boolean(true);
  w.boolean(false);
  w.fixed(-3.25_fx);
  w.vec3(v);
  w.quat(q);
  w.raw(Bytes{7, 8});

  ByteReader r(w.bytes());
  EXPECT_TRUE(r.ok());
  EXPECT_EQ(r.u8("a"), 0xFE);
  EXPECT_EQ(r.u16("b"), 0xFFFF);
  EXPECT_EQ(r.u32("c"), 0x80000001U);
  EXPECT_EQ(r.u64("d"), 0xFFFFFFFFFFFFFFFFU);
  EXPECT_EQ(r.i64("e"), std::numeric_limits<std::int64_t>::min());
  EXPECT_EQ(r.i64("f"), -1);
  EXPECT_TRUE(r.boolean("g"));
  EXPECT_FALSE(r.boolean("h"));
  EXPECT_EQ(r.fixed("i"), -3.25_fx);
  EXPECT_EQ(r.vec3("j"), v);
  EXPECT_EQ(r.quat("k"), q);
  const auto tail = r.raw(2, "l");
  EXPECT_EQ(Bytes(tail.begin(), tail.end()), (Bytes{7, 8}));
  EXPECT_TRUE(r.ok());
  EXPECT_TRUE(r.at_end());
  EXPECT_EQ(r.remaining(), 0U);
  EXPECT_EQ(r.offset(), w.size());
  EXPECT_EQ(r.error(), "");
}

TEST(ByteReader, ReadsLittleEndianFromHandWrittenBytes) {
  const Bytes data{0x78, 0x56, 0x34, 0x12, 0x00, 0x00, 0x00, 0x80, 0x01, 0x00, 0x00, 0x00};
  ByteReader r(data);
  EXPECT_EQ(r.u32("word"), 0x12345678U);
  EXPECT_EQ(r.fixed("value"), 1.5_fx);
  EXPECT_TRUE(r.at_end());
}

// ---- ByteReader: failures ----

TEST(ByteReader, ReadingPastTheEndFailsAtTheOffsetOfTheRead) {
  const Bytes data{1, 2, 3, 4, 5, 6};
  ByteReader r(data);
  EXPECT_EQ(r.u16("header"), 0x0201);
  EXPECT_EQ(r.u64("frame number"), 0U);  // 4 bytes remain: too few
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.error(), "byte 2: frame number: expected more bytes (the data ends here)");
  // A failed read consumes nothing.
  EXPECT_EQ(r.offset(), 2U);
  EXPECT_EQ(r.remaining(), 4U);
}

TEST(ByteReader, AfterAFailureEveryReadReturnsZeroAndTheFirstErrorIsKept) {
  const Bytes data{0xAA, 0xBB, 0xCC, 0xDD, 0xEE, 0xFF, 0x11, 0x22, 0x33};
  ByteReader r(data);
  EXPECT_EQ(r.u8("tag"), 0xAA);
  EXPECT_EQ(r.raw(100, "payload").size(), 0U);
  ASSERT_FALSE(r.ok());
  const std::string first = r.error();
  EXPECT_EQ(first, "byte 1: payload: expected more bytes");
  // Plenty of bytes remain for each of these, yet every one returns zero and fails.
  EXPECT_EQ(r.u8("x"), 0U);
  EXPECT_EQ(r.u16("x"), 0U);
  EXPECT_EQ(r.u32("x"), 0U);
  EXPECT_EQ(r.u64("x"), 0U);
  EXPECT_EQ(r.i64("x"), 0);
  EXPECT_FALSE(r.boolean("x"));
  EXPECT_EQ(r.fixed("x"), Fixed::zero());
  EXPECT_EQ(r.vec3("x"), Vec3{});
  EXPECT_EQ(r.quat("x"), (Quat{Fixed::zero(), Fixed::zero(), Fixed::zero(), Fixed::zero()}));
  EXPECT_EQ(r.raw(0, "x").size(), 0U);
  r.fail("later", "something else");
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.error(), first);
  EXPECT_EQ(r.offset(), 1U);
}

TEST(ByteReader, ExplicitFailIsRecordedAtTheCurrentOffset) {
  const Bytes data{1, 0, 0, 0, 9};
  ByteReader r(data);
  EXPECT_EQ(r.u32("count"), 1U);
  r.fail("count", "at most 0");
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.error(), "byte 4: count: expected at most 0");
  EXPECT_EQ(r.u8("next"), 0U);
}

TEST(ByteReader, BooleanAcceptsOnlyZeroAndOne) {
  for (int v = 0; v < 256; ++v) {
    const Bytes data{0x00, static_cast<std::uint8_t>(v)};
    ByteReader r(data);
    EXPECT_FALSE(r.boolean("pad"));
    const bool b = r.boolean("sensor flag");
    if (v <= 1) {
      EXPECT_TRUE(r.ok()) << v;
      EXPECT_EQ(b, v == 1);
    } else {
      EXPECT_FALSE(r.ok()) << v;
      EXPECT_FALSE(b) << v;
      // A bad value is reported at the offset of the byte that holds it (byte 1), not past it.
      EXPECT_EQ(r.error(), "byte 1: sensor flag: expected 0 or 1") << v;
    }
  }
}

TEST(ByteReader, RawChecksItsBounds) {
  const Bytes data{10, 20, 30};
  {
    ByteReader r(data);
    EXPECT_EQ(r.raw(0, "nothing").size(), 0U);
    EXPECT_TRUE(r.ok());
    const auto all = r.raw(3, "all");
    EXPECT_TRUE(r.ok());
    EXPECT_EQ(Bytes(all.begin(), all.end()), data);
    EXPECT_TRUE(r.at_end());
    EXPECT_EQ(r.raw(0, "empty at the end").size(), 0U);
    EXPECT_TRUE(r.ok());
    EXPECT_EQ(r.raw(1, "one more").size(), 0U);
    EXPECT_FALSE(r.ok());
    EXPECT_EQ(r.error(), "byte 3: one more: expected more bytes");
  }
  {
    ByteReader r(data);
    EXPECT_EQ(r.raw(4, "too many").size(), 0U);
    EXPECT_FALSE(r.ok());
    EXPECT_EQ(r.offset(), 0U);
  }
  {
    // A hostile length: no overflow in the bounds check, no read.
    ByteReader r(data);
    (void)r.u8("first");
    EXPECT_EQ(r.raw(std::numeric_limits<std::size_t>::max(), "huge").size(), 0U);
    EXPECT_FALSE(r.ok());
    EXPECT_EQ(r.error(), "byte 1: huge: expected more bytes");
  }
}

TEST(ByteReader, EmptyInput) {
  ByteReader r(std::span<const std::uint8_t>{});
  EXPECT_TRUE(r.at_end());
  EXPECT_EQ(r.remaining(), 0U);
  EXPECT_EQ(r.u8("magic"), 0U);
  EXPECT_EQ(r.error(), "byte 0: magic: expected more bytes (the data ends here)");
}

TEST(ByteReader, EveryTruncationOfAMultiFieldRecordFails) {
  ByteWriter w;
  w.u32(0xDEADBEEF);
  w.vec3({1_fx, -2_fx, 3_fx});
  w.quat(Quat{});
  w.boolean(true);
  const Bytes& full = w.bytes();
  for (std::size_t n = 0; n < full.size(); ++n) {
    ByteReader r(std::span<const std::uint8_t>(full.data(), n));
    (void)r.u32("id");
    (void)r.vec3("position");
    (void)r.quat("orientation");
    (void)r.boolean("awake");
    EXPECT_FALSE(r.ok()) << n;
    EXPECT_EQ(r.error().rfind("byte ", 0), 0U) << r.error();
    // The failing field is the first one that does not fit.
    const char* expected_field = n < 4    ? "id"
                                 : n < 28 ? "position"
                                 : n < 60 ? "orientation"
                                          : "awake";
    EXPECT_NE(r.error().find(expected_field), std::string::npos) << n << ": " << r.error();
  }
}

// ---- Vars: LEB128 and zigzag, canonical only ----
//
// Expected bytes from the definition: seven bits per byte, lowest group first, top bit = more
// follows; a Fixed is the var of (raw << 1) ^ (raw >> 63).

TEST(ByteWriter, VarIsLeb128) {
  EXPECT_EQ(written([](ByteWriter& w) { w.var(0); }), (Bytes{0x00}));
  EXPECT_EQ(written([](ByteWriter& w) { w.var(127); }), (Bytes{0x7F}));
  EXPECT_EQ(written([](ByteWriter& w) { w.var(128); }), (Bytes{0x80, 0x01}));
  EXPECT_EQ(written([](ByteWriter& w) { w.var(300); }), (Bytes{0xAC, 0x02}));
  EXPECT_EQ(written([](ByteWriter& w) { w.var(0xFFFFFFFFU); }),
            (Bytes{0xFF, 0xFF, 0xFF, 0xFF, 0x0F}));
  EXPECT_EQ(written([](ByteWriter& w) { w.var(~std::uint64_t{0}); }),
            (Bytes{0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0x01}));
}

TEST(ByteWriter, VarFixedIsTheVarOfItsZigzagRaw) {
  EXPECT_EQ(written([](ByteWriter& w) { w.var_fixed(Fixed::zero()); }), (Bytes{0x00}));
  EXPECT_EQ(written([](ByteWriter& w) { w.var_fixed(Fixed::from_raw(-1)); }), (Bytes{0x01}));
  EXPECT_EQ(written([](ByteWriter& w) { w.var_fixed(Fixed::from_raw(1)); }), (Bytes{0x02}));
  EXPECT_EQ(written([](ByteWriter& w) { w.var_fixed(Fixed::from_raw(-64)); }), (Bytes{0x7F}));
  EXPECT_EQ(written([](ByteWriter& w) { w.var_fixed(Fixed::from_raw(64)); }), (Bytes{0x80, 0x01}));
  // 1.0 = 2^32 -> 2^33: 33 bits in five groups of seven, the last holding bits 28..32 (= 2).
  EXPECT_EQ(written([](ByteWriter& w) { w.var_fixed(1_fx); }),
            (Bytes{0x80, 0x80, 0x80, 0x80, 0x20}));
  // The extremes: max -> 2^64 - 2, min -> 2^64 - 1; ten bytes each.
  EXPECT_EQ(written([](ByteWriter& w) { w.var_fixed(Fixed::max()); }),
            (Bytes{0xFE, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0x01}));
  EXPECT_EQ(written([](ByteWriter& w) { w.var_fixed(Fixed::min()); }),
            (Bytes{0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0x01}));
}

TEST(ByteReader, VarsReadBackEveryValueTheyWrite) {
  const std::vector<std::int64_t> raws = {0,
                                          1,
                                          -1,
                                          63,
                                          -64,
                                          64,
                                          -65,
                                          Fixed::one_raw,
                                          -Fixed::one_raw,
                                          std::numeric_limits<std::int64_t>::max(),
                                          std::numeric_limits<std::int64_t>::min(),
                                          0x123456789ABCDEF0,
                                          -0x123456789ABCDEF0};
  ByteWriter w;
  for (const std::int64_t raw : raws) {
    w.var_fixed(Fixed::from_raw(raw));
    w.var(static_cast<std::uint64_t>(raw));
  }
  w.var(0xFFFFFFFFU);
  w.var_vec3({1_fx, -2_fx, 0.5_fx});
  w.var_quat(Quat{});
  ByteReader r(w.bytes());
  for (const std::int64_t raw : raws) {
    EXPECT_EQ(r.var_fixed("f").raw(), raw);
    EXPECT_EQ(r.var("u"), static_cast<std::uint64_t>(raw));
  }
  EXPECT_EQ(r.var32("u32"), 0xFFFFFFFFU);
  EXPECT_EQ(r.var_vec3("v"), (Vec3{1_fx, -2_fx, 0.5_fx}));
  EXPECT_EQ(r.var_quat("q"), Quat{});
  EXPECT_TRUE(r.ok()) << r.error();
  EXPECT_TRUE(r.at_end());
}

// Every value has one encoding: longer forms of the same number, and numbers too wide for the
// field, are refused at the var's first byte.
TEST(ByteReader, VarRefusesAllButTheShortestFormAndValuesTooWide) {
  const auto refused = [](const Bytes& bytes, unsigned bits) {
    ByteReader r(bytes);
    if (bits == 32)
      (void)r.var32("count");
    else
      (void)r.var("count");
    return r.ok() ? std::string("accepted") : r.error();
  };
  EXPECT_EQ(refused({0x80, 0x00}, 64), "byte 0: count: expected the shortest form of a var");
  EXPECT_EQ(refused({0x81, 0x80, 0x00}, 64), "byte 0: count: expected the shortest form of a var");
  EXPECT_EQ(refused({0x80, 0x80, 0x80, 0x80, 0x10}, 32),
            "byte 0: count: expected a var of at most 32 bits");  // 2^32
  EXPECT_EQ(refused({0x80, 0x80, 0x80, 0x80, 0x80, 0x01}, 32),
            "byte 0: count: expected a var of at most 32 bits");  // six bytes
  EXPECT_EQ(refused({0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0x02}, 64),
            "byte 0: count: expected a var of at most 64 bits");  // 2^64
  EXPECT_EQ(refused({0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x00}, 64),
            "byte 0: count: expected a var of at most 64 bits");  // eleven bytes
  EXPECT_EQ(refused({0x80}, 64), "byte 1: count: expected more bytes (the data ends here)");
  EXPECT_EQ(refused({0xFF, 0xFF, 0xFF, 0xFF, 0x0F}, 32), "accepted");
  EXPECT_EQ(refused({0x00}, 32), "accepted");
}

// Every encoding the writer can produce for a var of one or two bytes, and every two-byte input:
// the reader accepts exactly the writer's outputs.
TEST(ByteReader, AcceptedTwoByteVarsAreExactlyTheWritersOutputs) {
  for (unsigned b0 = 0; b0 < 256; ++b0) {
    for (unsigned b1 = 0; b1 < 256; ++b1) {
      const Bytes bytes{static_cast<std::uint8_t>(b0), static_cast<std::uint8_t>(b1)};
      ByteReader r(bytes);
      const std::uint64_t v = r.var("v");
      const bool one_byte = b0 < 0x80;
      if (one_byte) {
        ASSERT_TRUE(r.ok());
        ASSERT_EQ(r.offset(), 1U);
        ASSERT_EQ(v, b0);
        continue;
      }
      if (!r.ok()) continue;
      ByteWriter w;
      w.var(v);
      ASSERT_EQ(w.bytes(), bytes) << b0 << " " << b1;
    }
  }
}

}  // namespace
}  // namespace detsim
