// World state: restore() refuses corrupt, truncated and hostile bytes with a message naming the
// byte, and a refused restore leaves the world exactly as it was (its save() bytes and hashes are
// compared before and after every rejected restore). Docs/DETERMINISM.md rule 7.
//
// Worlds are built through the public API only.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "support/state_helpers.hpp"

namespace detsim {
namespace {

using namespace detsim::literals;
using namespace detsim::state_test;

// ======================================================================================
// Corrupt input changes nothing
// ======================================================================================

class RejectedRestore : public testing::Test {
 protected:
  void SetUp() override {
    source_ = settled();
    state_ = source_.save();
    decoded_ = decode(state_);
    ASSERT_TRUE(decoded_.ok) << decoded_.error;
    ASSERT_GE(decoded_.contacts.size(), 3U);
    // The target holds a different state, so that "unchanged" means something.
    target_ = played_once(22, 120);
    target_state_ = target_.save();
    target_hashes_ = target_.hashes();
  }

  World source_;
  Bytes state_;
  Decoded decoded_;
  World target_;
  Bytes target_state_;
  StateHashes target_hashes_;
};

TEST_F(RejectedRestore, EveryTruncation) {
  for (std::size_t n = 0; n < state_.size(); ++n) {
    const Status st = target_.restore(std::span<const std::uint8_t>(state_.data(), n));
    ASSERT_FALSE(st.ok()) << "a " << n << "-byte prefix of a " << state_.size()
                          << "-byte state was accepted";
    ASSERT_TRUE(contains(st.message(), "byte")) << n << ": " << st.message();
    // Checking every prefix's effect by bytes is the cost driver; the hashes are compared on a
    // sample (they are a function of the same state).
    ASSERT_TRUE(target_.save() == target_state_) << "prefix " << n << " changed the state";
    if (n % 97 == 0) {
      ASSERT_EQ(target_.hashes(), target_hashes_) << "prefix " << n;
    }
  }
  // The untruncated state is fine.
  ASSERT_TRUE(target_.restore(state_).ok());
  EXPECT_EQ(target_.save(), state_);
}

TEST_F(RejectedRestore, EveryBitFlipInTheHeader) {
  // The header: magic, version, globals, RNG and the body count.
  const std::size_t header = decoded_.body_count_at + 4;
  std::size_t accepted = 0;
  Bytes flipped = state_;
  for (std::size_t at = 0; at < header; ++at) {
    for (int bit = 0; bit < 8; ++bit) {
      flipped[at] = static_cast<std::uint8_t>(state_[at] ^ (1U << bit));
      const std::string what = "byte " + std::to_string(at) + " bit " + std::to_string(bit);
      if (restore_outcome_is_sound(target_, flipped, target_state_, target_hashes_, what))
        ++accepted;
      flipped[at] = state_[at];
    }
  }
  // Magic, version and the body count can never flip to a valid state; the frame number, the
  // seed and most of the RNG state always do.
  EXPECT_GT(accepted, 64U * 3);
  EXPECT_LT(accepted, header * 8 - (4 + 4 + 4) * 8);
}

TEST_F(RejectedRestore, BitFlipsAcrossBodiesAndContacts) {
  // Every bit of every contact byte and of the first three body records (a plane, a sphere and a
  // box), and every bit of every third byte of the other bodies (record sizes are not multiples of
  // 3, so the sampled phase shifts from body to body).
  std::vector<std::size_t> positions;
  const std::size_t dense_until = decoded_.body_at[3];
  for (std::size_t at = decoded_.body_count_at + 4; at < decoded_.contact_count_at; ++at) {
    if (at < dense_until || at % 3 == 0) positions.push_back(at);
  }
  for (std::size_t at = decoded_.contact_count_at; at < state_.size(); ++at)
    positions.push_back(at);
  std::size_t accepted = 0;
  std::size_t refused = 0;
  Bytes flipped = state_;
  for (const std::size_t at : positions) {
    for (int bit = 0; bit < 8; ++bit) {
      flipped[at] = static_cast<std::uint8_t>(state_[at] ^ (1U << bit));
      const std::string what = "byte " + std::to_string(at) + " bit " + std::to_string(bit);
      if (restore_outcome_is_sound(target_, flipped, target_state_, target_hashes_, what)) {
        ++accepted;
      } else {
        ++refused;
      }
      flipped[at] = state_[at];
    }
  }
  EXPECT_GT(accepted, 0U);
  EXPECT_GT(refused, 0U);
}

TEST_F(RejectedRestore, RandomByteStrings) {
  Rng rng(0xBAD5EED);
  const Bytes prefix(state_.begin(), state_.begin() + 8);  // a valid magic and version
  for (int i = 0; i < 10000; ++i) {
    Bytes junk(rng.below(600));
    for (std::uint8_t& b : junk)
      b = static_cast<std::uint8_t>(rng.next_u64());
    // A third plain junk, a third behind a valid magic and version, a third behind a real header
    // (so that the body and contact readers see garbage too).
    if (i % 3 == 1) junk.insert(junk.begin(), prefix.begin(), prefix.end());
    if (i % 3 == 2) {
      junk.insert(junk.begin(), state_.begin(),
                  state_.begin() + static_cast<std::ptrdiff_t>(decoded_.body_count_at));
    }
    restore_outcome_is_sound(target_, junk, target_state_, target_hashes_,
                             "random string " + std::to_string(i));
    if (testing::Test::HasFailure()) break;
  }
}

TEST_F(RejectedRestore, GarbageAfterAValidState) {
  Rng rng(4);
  for (std::size_t extra = 1; extra <= 64; ++extra) {
    Bytes longer = state_;
    for (std::size_t i = 0; i < extra; ++i)
      longer.push_back(static_cast<std::uint8_t>(rng.next_u64()));
    const std::string message = expect_rejected(target_, longer);
    EXPECT_TRUE(contains(message, "byte " + std::to_string(state_.size()))) << message;
  }
  Bytes twice = state_;
  twice.insert(twice.end(), state_.begin(), state_.end());
  expect_rejected(target_, twice);
  Bytes zero_tail = state_;
  zero_tail.push_back(0);
  expect_rejected(target_, zero_tail);
}

TEST_F(RejectedRestore, HugeCountsInFewBytesFailWithoutAllocating) {
  // The header of a real state, then a body count of 2^32 - 1 and a handful of bytes.
  for (const std::uint32_t count : {0xFFFFFFFFU, 0x10000000U, 100000U, 5U}) {
    Bytes hostile(state_.begin(),
                  state_.begin() + static_cast<std::ptrdiff_t>(decoded_.body_count_at));
    hostile.resize(hostile.size() + 4 + 64, 0x01);
    put_u32(hostile, decoded_.body_count_at, count);
    g_largest_allocation = 0;
    const std::string message = expect_rejected(target_, hostile);
    EXPECT_LT(g_largest_allocation.load(), std::size_t{64} * 1024)
        << "body count " << count << ": largest allocation " << g_largest_allocation.load();
    EXPECT_TRUE(contains(message, "byte")) << message;
  }
  // The same for the contact count, after the real bodies.
  for (const std::uint32_t count : {0xFFFFFFFFU, 0x01000000U}) {
    Bytes hostile(state_.begin(),
                  state_.begin() + static_cast<std::ptrdiff_t>(decoded_.contact_count_at));
    hostile.resize(hostile.size() + 4 + 32, 0x02);
    put_u32(hostile, decoded_.contact_count_at, count);
    g_largest_allocation = 0;
    expect_rejected(target_, hostile);
    EXPECT_LT(g_largest_allocation.load(), std::size_t{64} * 1024 + state_.size() * 4)
        << "contact count " << count << ": largest allocation " << g_largest_allocation.load();
  }
  // A count just within what the bytes could hold if bodies were tiny: the allocation stays
  // proportional to the input.
  Bytes padded(state_.begin(),
               state_.begin() + static_cast<std::ptrdiff_t>(decoded_.body_count_at));
  padded.resize(padded.size() + 4 + 100000, 0x00);
  put_u32(padded, decoded_.body_count_at, 100000U / 46);
  g_largest_allocation = 0;
  expect_rejected(target_, padded);
  EXPECT_LT(g_largest_allocation.load(), padded.size() * 16);
}

TEST_F(RejectedRestore, WrongMagicOrVersion) {
  Bytes bad = state_;
  bad[0] = 'X';
  std::string message = expect_rejected(target_, bad);
  EXPECT_TRUE(contains(message, "magic")) << message;

  for (const std::uint32_t version : {0U, 2U, 0xFFFFFFFFU, 0x01000000U}) {
    bad = state_;
    put_u32(bad, 4, version);
    message = expect_rejected(target_, bad);
    EXPECT_TRUE(contains(message, "version " + std::to_string(version))) << message;
  }
  expect_rejected(target_, Bytes{'D', 'S', 'I', 'M'});
  expect_rejected(target_, Bytes{});
}

TEST_F(RejectedRestore, BodyIdsMustBeAscendingUniqueAndKnown) {
  const std::vector<std::size_t>& at = decoded_.body_at;
  ASSERT_GE(at.size(), 3U);
  const std::uint32_t first = decoded_.bodies[0].id.value;
  const std::uint32_t second = decoded_.bodies[1].id.value;

  Bytes bad = state_;
  put_u32(bad, at[1], first);  // a duplicate
  std::string message = expect_rejected(target_, bad);
  EXPECT_TRUE(contains(message, "ascending")) << message;
  EXPECT_TRUE(contains(message, "byte " + std::to_string(at[1]))) << message;

  bad = state_;
  put_u32(bad, at[0], second);  // 2, 2, ...
  put_u32(bad, at[1], first);   // then 1: descending
  expect_rejected(target_, bad);

  bad = state_;
  put_u32(bad, at[2], 0);  // the null ID
  expect_rejected(target_, bad);

  bad = state_;
  put_u32(bad, at.back(), decoded_.next_id);  // not yet issued
  message = expect_rejected(target_, bad);
  EXPECT_TRUE(contains(message, "byte")) << message;
}

TEST_F(RejectedRestore, UnknownShapeOrBodyType) {
  const std::size_t body = decoded_.body_at[1];
  for (const std::uint8_t type :
       {std::uint8_t{0}, std::uint8_t{5}, std::uint8_t{0x80}, std::uint8_t{0xFF}}) {
    Bytes bad = state_;
    bad[body + kShapeTypeAt] = type;
    const std::string message = expect_rejected(target_, bad);
    EXPECT_TRUE(contains(message, "shape type")) << message;
  }
  for (const std::uint8_t type : {std::uint8_t{3}, std::uint8_t{0xFF}}) {
    Bytes bad = state_;
    bad[body + kBodyTypeAt] = type;
    const std::string message = expect_rejected(target_, bad);
    EXPECT_TRUE(contains(message, "body type")) << message;
  }
  // A dynamic plane.
  Bytes bad = state_;
  ASSERT_EQ(decoded_.bodies[0].shape.type, ShapeType::plane);
  bad[decoded_.body_at[0] + kBodyTypeAt] = 2;
  expect_rejected(target_, bad);
}

TEST_F(RejectedRestore, NonUnitQuaternion) {
  // Body 2 is a sphere: its orientation follows its 8-byte radius.
  ASSERT_EQ(decoded_.bodies[1].shape.type, ShapeType::sphere);
  const std::size_t q = decoded_.body_at[1] + kSphereOrientationAt;
  for (const std::int64_t w : {std::int64_t{0}, 2 * Fixed::one_raw, -(std::int64_t{1} << 62)}) {
    Bytes bad = state_;
    put_i64(bad, q, w);
    put_i64(bad, q + 8, 0);
    put_i64(bad, q + 16, 0);
    put_i64(bad, q + 24, 0);
    const std::string message = expect_rejected(target_, bad);
    EXPECT_TRUE(contains(message, "unit quaternion")) << message;
    EXPECT_TRUE(contains(message, "byte " + std::to_string(decoded_.body_at[1]))) << message;
  }
  // Just outside the tolerance (|q|^2 - 1 > 2^-20) is refused; the identity is fine.
  Bytes bad = state_;
  put_i64(bad, q, Fixed::one_raw + (Fixed::one_raw >> 19));
  put_i64(bad, q + 8, 0);
  put_i64(bad, q + 16, 0);
  put_i64(bad, q + 24, 0);
  expect_rejected(target_, bad);
  Bytes good = bad;
  put_i64(good, q, Fixed::one_raw);
  ASSERT_TRUE(target_.restore(good).ok());
  EXPECT_EQ(target_.save(), good);
}

TEST_F(RejectedRestore, ContactsMustNameExistingBodiesInOrder) {
  const DecodedContact& last = decoded_.contacts.back();
  Bytes bad = state_;
  put_u32(bad, last.at + 4, 0xFFFFFFF0U);  // b: no such body (and still ascending)
  std::string message = expect_rejected(target_, bad);
  EXPECT_TRUE(contains(message, "does not exist")) << message;

  // A body ID that was once issued, but not to a body in this state.
  World gap = source_;
  const BodyId removed = gap.body_ids()[4];
  const Bytes with_gap_bytes = [&] {
    EXPECT_TRUE(gap.destroy_body(removed).ok());
    return gap.save();
  }();
  const Decoded with_gap = decode(with_gap_bytes);
  ASSERT_TRUE(with_gap.ok);
  ASSERT_FALSE(with_gap.contacts.empty());
  bad = with_gap_bytes;
  const DecodedContact& c = with_gap.contacts.front();
  ASSERT_LT(c.a, removed.value);
  put_u32(bad, c.at + 4, removed.value);
  expect_rejected(target_, bad);

  bad = state_;  // a == b
  put_u32(bad, last.at + 4, last.a);
  expect_rejected(target_, bad);

  bad = state_;  // the pair reversed
  put_u32(bad, last.at, last.b);
  put_u32(bad, last.at + 4, last.a);
  expect_rejected(target_, bad);

  // A duplicate pair: the first contact written twice.
  const DecodedContact& c0 = decoded_.contacts[0];
  const std::size_t c0_end = decoded_.contacts[1].at;
  bad.assign(state_.begin(), state_.end());
  bad.insert(bad.begin() + static_cast<std::ptrdiff_t>(c0_end),
             state_.begin() + static_cast<std::ptrdiff_t>(c0.at),
             state_.begin() + static_cast<std::ptrdiff_t>(c0_end));
  put_u32(bad, decoded_.contact_count_at, static_cast<std::uint32_t>(decoded_.contacts.size() + 1));
  message = expect_rejected(target_, bad);
  EXPECT_TRUE(contains(message, "ascending")) << message;

  // More than four points.
  bad = state_;
  bad[last.at + 9] = 5;
  expect_rejected(target_, bad);
}

TEST_F(RejectedRestore, ContactFlagsMustBeConsistent) {
  const auto with_points = std::find_if(decoded_.contacts.begin(), decoded_.contacts.end(),
                                        [](const DecodedContact& c) { return c.point_count > 0; });
  ASSERT_NE(with_points, decoded_.contacts.end());
  for (const int flags : {4, 0x81, 0xFF}) {  // bits that mean nothing
    Bytes bad = state_;
    bad[with_points->at + 8] = static_cast<std::uint8_t>(flags);
    const std::string message = expect_rejected(target_, bad);
    EXPECT_TRUE(contains(message, "contact flags")) << message;
  }
  // The same contact without its points (the record is then consistent with flags 0): reported
  // as touching (bit 1) without points, and touching (bit 0) without points, are refused.
  Bytes no_points = state_;
  const auto points_at = static_cast<std::ptrdiff_t>(with_points->at + 10);
  no_points.erase(no_points.begin() + points_at,
                  no_points.begin() + points_at + 28 * with_points->point_count);
  no_points[with_points->at + 9] = 0;
  no_points[with_points->at + 8] = 0;
  {
    World w;
    EXPECT_TRUE(w.restore(no_points).ok()) << "the edited record itself should be valid";
  }
  for (const int flags : {2, 3}) {
    Bytes bad = no_points;
    bad[with_points->at + 8] = static_cast<std::uint8_t>(flags);
    const std::string message = expect_rejected(target_, bad);
    EXPECT_TRUE(contains(message, "without contact points") || contains(message, "point count"))
        << message;
  }
  // Points but not touching.
  Bytes bad = state_;
  bad[with_points->at + 8] = 0;
  expect_rejected(target_, bad);
}

TEST_F(RejectedRestore, NextIdZeroIsRefused) {
  // The ID counter of a real world starts at 1 and stops at 2^32 - 1 (create_body refuses there),
  // so 0 never occurs. With bodies present, restore refuses it (every ID must be below it); with
  // none, it must be refused too, or the next create_body hands out the null ID 0 ("Zero is the
  // null ID", body.hpp).
  Bytes bad = World().save();
  put_u32(bad, 8 + 8, 0);  // after magic, version and the frame
  World w;
  if (w.restore(bad).ok()) {
    const Expected<BodyId> id = w.create_body(BodyDef{});
    ASSERT_TRUE(id.ok()) << id.message();
    ADD_FAILURE() << "a state with next body ID 0 (and no bodies) was accepted; create_body then "
                     "returned ID "
                  << id.value().value << (id.value().is_null() ? " (the null ID)" : "");
    return;
  }
  expect_rejected(target_, bad);
}

TEST_F(RejectedRestore, OtherInvalidValues) {
  Bytes bad = state_;
  for (std::size_t i = 0; i < 32; ++i)
    bad[decoded_.rng_at + i] = 0;  // the one state xoshiro cannot leave
  std::string message = expect_rejected(target_, bad);
  EXPECT_TRUE(contains(message, "rng")) << message;

  bad = state_;
  put_i64(bad, decoded_.globals_at + 12 + 24, 0);  // dt = 0
  message = expect_rejected(target_, bad);
  EXPECT_TRUE(contains(message, "dt")) << message;

  bad = state_;
  put_u32(bad, decoded_.globals_at + 12 + 24 + 8, 0);  // substeps = 0
  expect_rejected(target_, bad);

  // A static body (the ground) marked awake.
  ASSERT_EQ(decoded_.bodies[0].type, BodyType::static_body);
  bad = state_;
  const std::size_t plane_awake_at =
      decoded_.body_at[0] + 6 + 24 + 32 + 24 + 24 + 8 + 24 + 32 + 4 + 4 + 1 + 1 + 8;
  ASSERT_EQ(bad[plane_awake_at], 0);
  bad[plane_awake_at] = 1;
  expect_rejected(target_, bad);
  bad[plane_awake_at] = 2;  // not a bool
  message = expect_rejected(target_, bad);
  EXPECT_TRUE(contains(message, "awake")) << message;

  // A dynamic sphere with negative mass.
  bad = state_;
  const std::size_t mass_at = decoded_.body_at[1] + kSpherePositionAt + 24 + 32 + 24 + 24;
  put_i64(bad, mass_at, -Fixed::one_raw);
  expect_rejected(target_, bad);
}

}  // namespace
}  // namespace detsim
