// detsim::core's hash and error values. hash_bytes and Hash64Stream are the one hash every module
// uses (state hashes, checksums, replay hash chains), so they are checked against xxHash's own
// XXH3-64 called directly; Expected's operators are checked for reaching the value in place.
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <xxhash.h>

#include <detsim/core/hash.hpp>
#include <detsim/core/status.hpp>

namespace detsim {
namespace {

std::vector<std::uint8_t> counting_bytes(std::size_t n) {
  std::vector<std::uint8_t> bytes(n);
  for (std::size_t i = 0; i < n; ++i)
    bytes[i] = static_cast<std::uint8_t>(i * 31 + 7);
  return bytes;
}

TEST(Hash64, IsXxh3WithSeedZero) {
  // Lengths around XXH3's internal boundaries (16, 128, 240 bytes, one stripe block).
  for (std::size_t n : {0U, 1U, 3U, 8U, 16U, 17U, 128U, 129U, 240U, 241U, 1024U, 5000U}) {
    const auto bytes = counting_bytes(n);
    EXPECT_EQ(hash_bytes(bytes), XXH3_64bits(bytes.data(), bytes.size())) << n << " bytes";
  }
}

TEST(Hash64Stream, EqualsTheHashOfTheConcatenation) {
  const auto bytes = counting_bytes(3000);
  Hash64Stream stream;
  EXPECT_EQ(stream.digest(), hash_bytes({}));
  std::size_t at = 0;
  for (std::size_t piece : {0U, 1U, 7U, 64U, 500U, 1000U, 1428U}) {
    stream.update({bytes.data() + at, piece});
    at += piece;
    EXPECT_EQ(stream.digest(), hash_bytes({bytes.data(), at})) << at << " bytes";
  }
  EXPECT_EQ(at, bytes.size());
}

TEST(Hash64Stream, CopiesContinueIndependently) {
  const auto bytes = counting_bytes(100);
  Hash64Stream a;
  a.update({bytes.data(), 40});
  Hash64Stream b = a;
  a.update({bytes.data() + 40, 60});
  EXPECT_EQ(a.digest(), hash_bytes(bytes));
  EXPECT_EQ(b.digest(), hash_bytes({bytes.data(), 40}));
  b = a;
  EXPECT_EQ(b.digest(), hash_bytes(bytes));
}

TEST(Expected, NonConstAccessChangesTheValueInPlace) {
  Expected<std::vector<int>> e(std::vector<int>{1, 2});
  e->push_back(3);
  (*e)[0] = 10;
  EXPECT_EQ(e.value(), (std::vector<int>{10, 2, 3}));
  const Expected<std::vector<int>>& c = e;
  EXPECT_EQ(c->size(), 3U);
  EXPECT_EQ((*c)[0], 10);
  EXPECT_EQ(std::move(e).value().size(), 3U);
}

TEST(Expected, ErrorNamesWhatIsWrong) {
  const Expected<int> e(Status::error("body 7: mass must be > 0"));
  EXPECT_FALSE(e.ok());
  EXPECT_EQ(e.message(), "body 7: mass must be > 0");
  EXPECT_EQ(e.status().message(), e.message());
}

}  // namespace
}  // namespace detsim
