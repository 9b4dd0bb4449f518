// golden/fixed.txt: for every operation and function of the fixed layer, the XXH3-64 of its outputs
// (raw values, 8 bytes little-endian each) over a fixed, seeded set of inputs. Any change to any
// result on any machine fails here, naming the function. Changing a result is a breaking change:
// the file is rewritten only on purpose, with
//   DETSIM_UPDATE_GOLDEN=1 <build>/tests/fixed_golden_test
#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <xxhash.h>
#include <detsim/fixed.hpp>

#include "support/golden.hpp"

#if defined(DETSIM_NO_INT128)
static_assert(DETSIM_HAS_INT128 == 0, "the portable golden build must not use __int128");
#endif

namespace detsim {
namespace {

constexpr std::size_t kInputs = 131072;
const char* const kGoldenPath = DETSIM_SOURCE_DIR "/golden/fixed.txt";

// SplitMix64 (Steele, Lea, Flood 2014): the input generator is part of the golden definition, so it
// is written out here rather than taken from <random>, whose distributions differ by library.
struct SplitMix64 {
  std::uint64_t state;
  std::uint64_t next() {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15U);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9U;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBU;
    return z ^ (z >> 31);
  }
};

// A third of the inputs uniform over all raw values, a third with log-uniform magnitude, a third
// uniform in [-32, 32) where most functions do their interesting work.
std::vector<Fixed> inputs(std::uint64_t seed) {
  SplitMix64 rng{seed};
  std::vector<Fixed> v;
  v.reserve(kInputs);
  for (std::size_t i = 0; i < kInputs; ++i) {
    const std::uint64_t bits = rng.next();
    std::uint64_t raw = bits;
    if (i % 3 == 1) {
      const std::uint64_t magnitude = (bits >> 1) >> (rng.next() % 63);
      raw = (bits & 1U) != 0 ? 0U - magnitude : magnitude;
    }
    if (i % 3 == 2) raw = static_cast<std::uint64_t>(static_cast<std::int64_t>(bits) >> 26);
    v.push_back(Fixed::from_raw(static_cast<std::int64_t>(raw)));
  }
  return v;
}

void append_le(std::vector<unsigned char>& out, Fixed x) {
  const auto bits = static_cast<std::uint64_t>(x.raw());
  for (int i = 0; i < 8; ++i)
    out.push_back(static_cast<unsigned char>(bits >> (8 * i)));
}

using Unary = std::function<Fixed(Fixed)>;
using Binary = std::function<Fixed(Fixed, Fixed)>;

std::map<std::string, std::uint64_t> compute_hashes() {
  const std::vector<Fixed> x = inputs(1);
  const std::vector<Fixed> y = inputs(2);
  const std::vector<std::pair<const char*, Unary>> unary = {
      {"sqrt", [](Fixed a) { return sqrt(a); }},
      {"rsqrt", [](Fixed a) { return rsqrt(a); }},
      {"sin", [](Fixed a) { return sin(a); }},
      {"cos", [](Fixed a) { return cos(a); }},
      {"tan", [](Fixed a) { return tan(a); }},
      {"asin", [](Fixed a) { return asin(a >> 31); }},
      {"acos", [](Fixed a) { return acos(a >> 31); }},
      {"atan", [](Fixed a) { return atan(a); }},
      {"exp", [](Fixed a) { return exp(a); }},
      {"exp2", [](Fixed a) { return exp2(a); }},
      {"log", [](Fixed a) { return log(a); }},
      {"log2", [](Fixed a) { return log2(a); }},
      {"floor", [](Fixed a) { return floor(a); }},
      {"ceil", [](Fixed a) { return ceil(a); }},
      {"round", [](Fixed a) { return round(a); }},
      {"neg", [](Fixed a) { return -a; }},
  };
  const std::vector<std::pair<const char*, Binary>> binary = {
      {"add", [](Fixed a, Fixed b) { return a + b; }},
      {"sub", [](Fixed a, Fixed b) { return a - b; }},
      {"mul", [](Fixed a, Fixed b) { return a * b; }},
      {"div", [](Fixed a, Fixed b) { return a / b; }},
      {"hypot", [](Fixed a, Fixed b) { return hypot(a, b); }},
      {"atan2", [](Fixed a, Fixed b) { return atan2(a, b); }},
      {"pow", [](Fixed a, Fixed b) { return pow(a, b >> 27); }},
      {"lerp", [](Fixed a, Fixed b) { return lerp(a, b, b >> 30); }},
  };
  std::map<std::string, std::uint64_t> hashes;
  std::vector<unsigned char> bytes;
  for (const auto& [name, f] : unary) {
    bytes.clear();
    for (const Fixed a : x)
      append_le(bytes, f(a));
    hashes[name] = XXH3_64bits(bytes.data(), bytes.size());
  }
  for (const auto& [name, f] : binary) {
    bytes.clear();
    for (std::size_t i = 0; i < kInputs; ++i)
      append_le(bytes, f(x[i], y[i]));
    hashes[name] = XXH3_64bits(bytes.data(), bytes.size());
  }
  bytes.clear();
  for (const Fixed a : x) {
    const SinCos sc = sincos(a);
    append_le(bytes, sc.sin);
    append_le(bytes, sc.cos);
  }
  hashes["sincos"] = XXH3_64bits(bytes.data(), bytes.size());

  // The vector layer, which the simulation's results pass through: vectors from three consecutive
  // inputs scaled into +-2^20 (the documented no-overflow range), angles and steps from y.
  const auto vec_shifted = [&x](std::size_t i, int shift) {
    return Vec3{x[i % kInputs] >> shift, x[(i + 1) % kInputs] >> shift,
                x[(i + 2) % kInputs] >> shift};
  };
  const auto vec = [&vec_shifted](std::size_t i) { return vec_shifted(i, 11); };
  const auto quat = [&y](std::size_t i) {
    return Quat{y[i % kInputs] >> 28, y[(i + 1) % kInputs] >> 28, y[(i + 2) % kInputs] >> 28,
                y[(i + 3) % kInputs] >> 28};
  };
  const auto hash_vectors = [&bytes](const char* name, auto&& f, auto& out) {
    bytes.clear();
    for (std::size_t i = 0; i < kInputs; ++i) {
      for (const Fixed c : f(i))
        append_le(bytes, c);
    }
    out[name] = XXH3_64bits(bytes.data(), bytes.size());
  };
  const auto v3 = [](Vec3 v) { return std::array<Fixed, 3>{v.x, v.y, v.z}; };
  const auto q4 = [](Quat q) { return std::array<Fixed, 4>{q.w, q.x, q.y, q.z}; };
  const auto m9 = [](const Mat3& m) {
    std::array<Fixed, 9> a;
    for (std::size_t r = 0; r < 3; ++r) {
      a[3 * r] = m.rows[r].x;
      a[3 * r + 1] = m.rows[r].y;
      a[3 * r + 2] = m.rows[r].z;
    }
    return a;
  };
  const auto mat = [&vec_shifted](std::size_t i) {
    return Mat3{{vec_shifted(i, 27), vec_shifted(i + 3, 27), vec_shifted(i + 6, 27)}};
  };
  hash_vectors(
      "vec3_cross", [&](std::size_t i) { return v3(cross(vec(i), vec(i + 5))); }, hashes);
  hash_vectors(
      "vec3_length", [&](std::size_t i) { return std::array<Fixed, 1>{length(vec(i))}; }, hashes);
  hash_vectors(
      "vec3_dot_sum",
      [&](std::size_t i) {
        return std::array<Fixed, 1>{
            DotSum{}.add(vec(i), vec(i + 5)).add(vec(i + 9), vec_shifted(i + 13, 19)).result()};
      },
      hashes);
  hash_vectors(
      "vec3_sum",
      [&](std::size_t i) {
        return v3(Vec3Sum{vec(i)}
                      .add(y[i] >> 24, vec(i + 5))
                      .add(y[(i + 1) % kInputs] >> 24, vec(i + 9))
                      .result());
      },
      hashes);
  hash_vectors(
      "vec3_normalize", [&](std::size_t i) { return v3(normalize(vec(i))); }, hashes);
  hash_vectors(
      "quat_normalize", [&](std::size_t i) { return q4(normalize(quat(i))); }, hashes);
  hash_vectors(
      "quat_product",
      [&](std::size_t i) { return q4(normalize(quat(i)) * normalize(quat(i + 7))); }, hashes);
  hash_vectors(
      "quat_rotate",
      [&](std::size_t i) { return v3(rotate(normalize(quat(i)), vec_shifted(i, 19))); }, hashes);
  hash_vectors(
      "quat_from_axis_angle",
      [&](std::size_t i) { return q4(from_axis_angle(vec(i), y[i] >> 24)); }, hashes);
  hash_vectors(
      "quat_integrate",
      [&](std::size_t i) {
        return q4(integrate(normalize(quat(i)), vec_shifted(i, 23), Fixed::from_raw(71582788)));
      },
      hashes);
  hash_vectors(
      "quat_to_mat3", [&](std::size_t i) { return m9(to_mat3(normalize(quat(i)))); }, hashes);
  hash_vectors(
      "mat3_inverse", [&](std::size_t i) { return m9(inverse(mat(i))); }, hashes);
  hash_vectors(
      "mat3_rotate_inertia",
      [&](std::size_t i) { return m9(rotate_inertia(to_mat3(normalize(quat(i))), mat(i))); },
      hashes);
  return hashes;
}

TEST(FixedGolden, EveryFunctionReproducesItsGoldenHash) {
  test::check_golden(
      kGoldenPath,
      "# XXH3-64 of the little-endian raw outputs of each fixed-layer function over " +
          std::to_string(kInputs) +
          " seeded inputs\n# (tests/fixed_golden_test.cpp). Every machine must reproduce these. "
          "A change is a breaking\n# change: regenerate only on purpose with "
          "DETSIM_UPDATE_GOLDEN=1 <build>/tests/fixed_golden_test\n",
      compute_hashes());
}

}  // namespace
}  // namespace detsim
