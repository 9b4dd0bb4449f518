// Mat3: products, transpose, determinant, inverse and inertia-tensor rotation. Expected values come
// from exact 128-bit arithmetic in the test (rounding inequalities), exact identities and error
// bounds derived in the comments (ulp = 2^-32).
#include <cstdint>
#include <limits>
#include <random>
#include <utility>

#include <gtest/gtest.h>
#include <detsim/fixed/exact_sum.hpp>
#include <detsim/fixed/mat3.hpp>
#include <detsim/fixed/quat.hpp>

#include "support/vector_print.hpp"

namespace detsim {
namespace {

using test::i128;
using test::is_rounded;
using test::product;

constexpr std::int64_t kOne = Fixed::one_raw;

Fixed raw(std::int64_t r) {
  return Fixed::from_raw(r);
}
Fixed num(std::int32_t i) {
  return Fixed::from_int(i);
}

Fixed entry(const Mat3& m, std::size_t i, std::size_t j) {
  const Vec3 r = m.rows[i];
  return j == 0 ? r.x : (j == 1 ? r.y : r.z);
}

// Entries with |value| < 2^bits.
Mat3 random_mat(std::mt19937_64& rng, int bits) {
  const auto c = [&] {
    return raw(test::maybe_coarse(
        static_cast<std::int64_t>(rng() >> (31 - bits)) - (std::int64_t{1} << (32 + bits)), rng));
  };
  return {{Vec3{c(), c(), c()}, Vec3{c(), c(), c()}, Vec3{c(), c(), c()}}};
}

Quat random_unit(std::mt19937_64& rng) {
  const auto c = [&rng] { return raw(static_cast<std::int64_t>(rng() >> 31) - kOne); };
  return normalize(Quat{c(), c(), c(), c()});
}

static_assert(determinant(Mat3::diagonal(Fixed::from_int(2), Fixed::from_int(3),
                                         Fixed::from_int(4))) == Fixed::from_int(24));
static_assert(Mat3::identity() * Mat3::identity() == Mat3::identity());

// ---- Elementary operations ---------------------------------------------------------------------

TEST(Mat3, ConstructionTransposeAndEntrywiseOperators) {
  const Fixed o = Fixed::zero();
  const Fixed l = Fixed::one();
  EXPECT_EQ(Mat3{}, Mat3::zero());
  EXPECT_EQ(Mat3::identity(), Mat3::diagonal(l, l, l));
  const Mat3 m{
      {Vec3{num(1), num(2), num(3)}, Vec3{num(4), num(5), num(6)}, Vec3{num(7), num(8), num(9)}}};
  EXPECT_EQ(transpose(m), (Mat3{{Vec3{num(1), num(4), num(7)}, Vec3{num(2), num(5), num(8)},
                                 Vec3{num(3), num(6), num(9)}}}));
  EXPECT_EQ(transpose(transpose(m)), m);
  EXPECT_EQ(m.column(1), (Vec3{num(2), num(5), num(8)}));
  EXPECT_EQ(m + m, m * num(2));
  EXPECT_EQ(m - m, Mat3::zero());
  EXPECT_EQ(num(3) * m, m * num(3));
  EXPECT_EQ(Mat3::identity() * m, m);
  EXPECT_EQ(m * Mat3::identity(), m);
  EXPECT_EQ((m * Vec3{l, o, o}), m.column(0));
  EXPECT_EQ((m * Vec3{num(1), num(-1), num(2)}), (Vec3{num(5), num(11), num(17)}));
  EXPECT_EQ(m * m, (Mat3{{Vec3{num(30), num(36), num(42)}, Vec3{num(66), num(81), num(96)},
                          Vec3{num(102), num(126), num(150)}}}));
}

// Entries below 2^20: each entry of a product is at most 3 2^104 exactly, within the reference.
TEST(Mat3, ProductsAreTheExactValuesRoundedOnce) {
  std::mt19937_64 rng(301);
  for (int n = 0; n < 30000; ++n) {
    const Mat3 a = random_mat(rng, n % 21);
    const Mat3 b = random_mat(rng, 20 - n % 21);
    const Mat3 p = a * b;
    for (std::size_t i = 0; i < 3; ++i) {
      for (std::size_t j = 0; j < 3; ++j) {
        i128 exact = 0;
        for (std::size_t k = 0; k < 3; ++k)
          exact += product(entry(a, i, k), entry(b, k, j));
        ASSERT_TRUE(is_rounded(entry(p, i, j).raw(), exact, 32))
            << testing::PrintToString(a) << "\n"
            << testing::PrintToString(b);
      }
    }
    const Vec3 v = b.rows[0];
    const Vec3 av = a * v;
    ASSERT_TRUE(is_rounded(
        av.y.raw(),
        product(a.rows[1].x, v.x) + product(a.rows[1].y, v.y) + product(a.rows[1].z, v.z), 32));
  }
}

// ---- Determinant -------------------------------------------------------------------------------

TEST(Mat3, DeterminantOfExactCases) {
  const Fixed o = Fixed::zero();
  EXPECT_EQ(determinant(Mat3::identity()), Fixed::one());
  EXPECT_EQ(determinant(Mat3::zero()), Fixed::zero());
  EXPECT_EQ(determinant(Mat3::diagonal(num(2), num(-3), num(4))), num(-24));
  // Swapping two rows flips the sign.
  EXPECT_EQ(determinant(Mat3{
                {Vec3{o, Fixed::one(), o}, Vec3{Fixed::one(), o, o}, Vec3{o, o, Fixed::one()}}}),
            -Fixed::one());
  // Rows (1 2 3), (4 5 6), (7 8 9) are linearly dependent: exactly 0.
  EXPECT_EQ(determinant(Mat3{{Vec3{num(1), num(2), num(3)}, Vec3{num(4), num(5), num(6)},
                              Vec3{num(7), num(8), num(9)}}}),
            Fixed::zero());
}

TEST(Mat3, DeterminantHasNoIntermediateOverflow) {
  const Fixed p = num(1 << 20);
  const Fixed tiny = raw(std::int64_t{1} << 12);  // 2^-20
  // 2^20 2^20 2^-20: the partial product 2^40 is far beyond Fixed.
  EXPECT_EQ(determinant(Mat3::diagonal(p, p, tiny)), p);
  // 2^20 (2^20 + 2^-32) - 2^20 2^20 = 2^-12.
  const Fixed o = Fixed::zero();
  EXPECT_EQ(determinant(
                Mat3{{Vec3{p, p, o}, Vec3{p, p + Fixed::epsilon(), o}, Vec3{o, o, Fixed::one()}}}),
            raw(std::int64_t{1} << 20));
  // Full range: det diag(max, max, max) saturates; diag(min, min, min) saturates negative.
  EXPECT_EQ(determinant(Mat3::diagonal(Fixed::max(), Fixed::max(), Fixed::max())), Fixed::max());
  EXPECT_EQ(determinant(Mat3::diagonal(Fixed::min(), Fixed::min(), Fixed::min())), Fixed::min());
  // min * min * 2^-62... : (-2^31)(-2^31)(2^-32) = 2^30 exactly, through a 2^62 partial product.
  EXPECT_EQ(determinant(Mat3::diagonal(Fixed::min(), Fixed::min(), Fixed::epsilon())),
            num(1 << 30));
}

// Ties of the Q96.96 sums: the raw result is a b c / 2^64 for raws a, b, c, and
// 2^31 2^31 (2 k) / 2^64 = k / 2, so odd k gives exact halves that must go to even.
TEST(Mat3, DeterminantRoundsTiesToEven) {
  const Fixed h = Fixed::half();  // raw 2^31
  const std::pair<std::int64_t, std::int64_t> cases[] = {{1, 0},  {3, 2},   {5, 2},   {7, 4},
                                                         {-1, 0}, {-3, -2}, {-5, -2}, {-7, -4}};
  for (const auto& [k, expected] : cases) {
    EXPECT_EQ(determinant(Mat3::diagonal(h, h, raw(2 * k))), raw(expected)) << k;
  }
}

// With R = s I, R I R^T = s^2 I; for s = 2^-16 (raw 2^16) an entry of raw value t becomes t / 2^32,
// so t = k 2^31 with odd k is a tie. Off-diagonal entries take the paired-product path.
TEST(Mat3, RotateInertiaRoundsTiesToEven) {
  const Fixed s = raw(std::int64_t{1} << 16);
  const Mat3 r = Mat3::diagonal(s, s, s);
  const auto t = [](std::int64_t k) { return raw(k * (std::int64_t{1} << 31)); };
  const Mat3 inertia{{Vec3{t(1), t(3), t(-5)}, Vec3{t(3), t(5), t(7)}, Vec3{t(-5), t(7), t(-3)}}};
  EXPECT_EQ(rotate_inertia(r, inertia),
            (Mat3{{Vec3{raw(0), raw(2), raw(-2)}, Vec3{raw(2), raw(2), raw(4)},
                   Vec3{raw(-2), raw(4), raw(-2)}}}));
}

// Entries below 2^4 (raws below 2^36): each of the six products is below 2^108 and their sum below
// 2^111; the determinant (below 6 2^12) times 2^64 stays below 2^127.
TEST(Mat3, DeterminantIsTheExactValueRoundedOnce) {
  std::mt19937_64 rng(302);
  for (int n = 0; n < 100000; ++n) {
    const Mat3 m = random_mat(rng, n % 5);
    const Vec3 a = m.rows[0];
    const Vec3 b = m.rows[1];
    const Vec3 c = m.rows[2];
    const auto t = [](Fixed x, Fixed y, Fixed z) { return product(x, y) * z.raw(); };
    const i128 exact = t(a.x, b.y, c.z) + t(a.y, b.z, c.x) + t(a.z, b.x, c.y) - t(a.x, b.z, c.y) -
                       t(a.y, b.x, c.z) - t(a.z, b.y, c.x);
    ASSERT_TRUE(is_rounded(determinant(m).raw(), exact, 64)) << testing::PrintToString(m);
  }
}

// ---- Inverse -----------------------------------------------------------------------------------

TEST(Mat3, InverseOfExactCases) {
  EXPECT_EQ(inverse(Mat3::identity()), Mat3::identity());
  EXPECT_EQ(inverse(Mat3::diagonal(num(2), num(4), num(-8))),
            Mat3::diagonal(Fixed::half(), raw(kOne / 4), raw(-kOne / 8)));
  // 1/3 rounded: 2^32 / 3 = 1431655765.33.
  const Fixed third = raw(1431655765);
  EXPECT_EQ(inverse(Mat3::diagonal(num(3), num(3), num(-3))), Mat3::diagonal(third, third, -third));
  // A rotation's inverse is its transpose; for this signed permutation every entry is exact.
  const Fixed o = Fixed::zero();
  const Fixed l = Fixed::one();
  const Mat3 r{{Vec3{o, -l, o}, Vec3{o, o, l}, Vec3{-l, o, o}}};
  EXPECT_EQ(inverse(r), transpose(r));
  // [[2, 1], [1, 1]] (+ 1 in the corner) has inverse [[1, -1], [-1, 2]].
  const Mat3 m{{Vec3{num(2), num(1), o}, Vec3{num(1), num(1), o}, Vec3{o, o, l}}};
  EXPECT_EQ(inverse(m),
            (Mat3{{Vec3{num(1), num(-1), o}, Vec3{num(-1), num(2), o}, Vec3{o, o, l}}}));
  // Tiny but regular: diag(2^-20) has the representable inverse diag(2^20).
  const Fixed tiny = raw(std::int64_t{1} << 12);
  EXPECT_EQ(inverse(Mat3::diagonal(tiny, tiny, tiny)),
            Mat3::diagonal(num(1 << 20), num(1 << 20), num(1 << 20)));
}

TEST(Mat3, InverseOfSingularOrOverflowingMatricesIsTheDocumentedValue) {
  const Mat3 sentinel = Mat3::diagonal(num(7), num(7), num(7));
  const Fixed o = Fixed::zero();
  const Mat3 singular[] = {
      Mat3::zero(),
      Mat3{{Vec3{num(1), num(2), num(3)}, Vec3{num(4), num(5), num(6)},
            Vec3{num(7), num(8), num(9)}}},
      Mat3::diagonal(num(1), num(1), o),
      // Rank one, huge entries.
      Mat3{{Vec3{Fixed::max(), Fixed::max(), Fixed::max()},
            Vec3{Fixed::max(), Fixed::max(), Fixed::max()}, Vec3{o, o, o}}},
  };
  for (const Mat3& m : singular) {
    EXPECT_EQ(inverse(m), Mat3::zero()) << testing::PrintToString(m);
    Mat3 out = sentinel;
    EXPECT_FALSE(try_inverse(m, out));
    EXPECT_EQ(out, sentinel) << "a failed try_inverse must leave its output unchanged";
  }
  // Regular, but an entry of the inverse does not fit: 1 / 2^-32 = 2^32, 1 / 2^-31 = 2^31 (one ulp
  // beyond max()), and -2^31 (which the header documents as overflow too).
  const Fixed half_ulp_inverse = raw(2);  // 2^-31
  for (const Mat3& m : {Mat3::diagonal(Fixed::epsilon(), num(1), num(1)),
                        Mat3::diagonal(num(1), half_ulp_inverse, num(1)),
                        Mat3::diagonal(num(1), num(1), -half_ulp_inverse)}) {
    EXPECT_EQ(inverse(m), Mat3::zero()) << testing::PrintToString(m);
    Mat3 out = sentinel;
    EXPECT_FALSE(try_inverse(m, out));
    EXPECT_EQ(out, sentinel);
  }
  // 1 / 2^-30 = 2^30 fits.
  Mat3 out;
  EXPECT_TRUE(try_inverse(Mat3::diagonal(num(1), raw(4), num(1)), out));
  EXPECT_EQ(out, Mat3::diagonal(num(1), num(1 << 30), num(1)));
}

// M = D + E with D a diagonal of magnitude 8..12 and |E_ij| < 2: diagonally dominant, so M is well
// conditioned and |M^-1| is below 1/(8 - 4) per row sum. X = M^-1 + F with |F_ik| <= 1/2 ulp +
// 2^-61 |X_ik| (header), so (X M)_ij - delta_ij = (F M)_ij, at most sum_k |F_ik| |M_kj|. The test
// checks the exact product (raws below 2^36: products below 2^72) against that bound.
TEST(Mat3, InverseTimesMatrixIsTheIdentityWithinTheDerivedBound) {
  std::mt19937_64 rng(303);
  i128 worst = 0;
  for (int n = 0; n < 100000; ++n) {
    Mat3 m = random_mat(rng, 1);
    const auto diag = [&rng] {
      const auto d = raw(static_cast<std::int64_t>(rng() >> 30) % (4 * kOne) + 8 * kOne);
      return (rng() & 1) != 0 ? -d : d;
    };
    m.rows[0].x = diag();
    m.rows[1].y = diag();
    m.rows[2].z = diag();
    Mat3 x;
    ASSERT_TRUE(try_inverse(m, x)) << testing::PrintToString(m);
    ASSERT_EQ(inverse(m), x);
    for (std::size_t i = 0; i < 3; ++i) {
      for (std::size_t j = 0; j < 3; ++j) {
        i128 exact = 0;
        i128 bound = 1;  // second-order terms
        for (std::size_t k = 0; k < 3; ++k) {
          exact += product(entry(x, i, k), entry(m, k, j));
          const i128 mk = test::abs64(entry(m, k, j).raw());
          // (1/2 ulp + 2^-61 |X_ik|) |M_kj| in Q64.64 units: |X| < 1 so 2^-61 |X| < 2^-29 ulp.
          bound += mk / 2 + (mk >> 29) + 1;
        }
        const i128 dev = exact - (i == j ? (i128{1} << 64) : 0);
        const i128 abs_dev = dev < 0 ? -dev : dev;
        worst = abs_dev > worst ? abs_dev : worst;
        ASSERT_LE(abs_dev, bound) << testing::PrintToString(m) << "\n" << testing::PrintToString(x);
      }
    }
  }
  RecordProperty("worst_identity_error_in_ulp_times_1000",
                 static_cast<int>(worst * 1000 / (i128{1} << 32)));
}

// ---- Inertia rotation --------------------------------------------------------------------------

Mat3 random_symmetric(std::mt19937_64& rng, int bits) {
  Mat3 m = random_mat(rng, bits);
  m.rows[1].x = m.rows[0].y;
  m.rows[2].x = m.rows[0].z;
  m.rows[2].y = m.rows[1].z;
  return m;
}

TEST(Mat3, RotateInertiaIsExactlySymmetricAndReadsOnlyTheUpperTriangle) {
  std::mt19937_64 rng(304);
  for (int n = 0; n < 50000; ++n) {
    const Mat3 r = n % 2 == 0 ? to_mat3(random_unit(rng)) : random_mat(rng, 8);
    const Mat3 inertia = random_symmetric(rng, n % 20);
    const Mat3 w = rotate_inertia(r, inertia);
    ASSERT_EQ(w, transpose(w)) << testing::PrintToString(r) << "\n"
                               << testing::PrintToString(inertia);
    Mat3 scrambled = inertia;
    scrambled.rows[1].x = raw(static_cast<std::int64_t>(rng()));
    scrambled.rows[2].x = raw(static_cast<std::int64_t>(rng()));
    scrambled.rows[2].y = raw(static_cast<std::int64_t>(rng()));
    ASSERT_EQ(rotate_inertia(r, scrambled), w);
  }
}

// R entries up to 1 (raws up to 2^32 + small) and I entries below 2^8 (raws below 2^40): each of
// the nine triple products R_ik I_kl R_jl is below 2^106 and their sum below 2^110, within the
// reference.
TEST(Mat3, RotateInertiaIsTheExactValueRoundedOnce) {
  std::mt19937_64 rng(305);
  for (int n = 0; n < 50000; ++n) {
    const Mat3 r = to_mat3(random_unit(rng));
    const Mat3 inertia = random_symmetric(rng, n % 9);
    const Mat3 w = rotate_inertia(r, inertia);
    for (std::size_t i = 0; i < 3; ++i) {
      for (std::size_t j = 0; j < 3; ++j) {
        i128 exact = 0;
        for (std::size_t k = 0; k < 3; ++k) {
          for (std::size_t l = 0; l < 3; ++l) {
            exact += product(entry(r, i, k), entry(inertia, k, l)) * entry(r, j, l).raw();
          }
        }
        ASSERT_TRUE(is_rounded(entry(w, i, j).raw(), exact, 64))
            << testing::PrintToString(r) << "\n"
            << testing::PrintToString(inertia);
      }
    }
  }
}

// Diagonal and isotropic tensors (every body's inverse inertia; isotropic for spheres and cubes)
// take shortcuts in rotate_inertia: over the whole raw range, each entry must still be the sum of
// all nine triple products, zero terms included, rounded once.
TEST(Mat3, RotateInertiaOfDiagonalAndIsotropicTensorsIsTheExactSumRoundedOnce) {
  std::mt19937_64 rng(308);
  for (int n = 0; n < 20000; ++n) {
    const auto any = [&rng] { return raw(static_cast<std::int64_t>(rng())); };
    const Mat3 r = n % 3 == 0   ? to_mat3(random_unit(rng))
                   : n % 3 == 1 ? random_mat(rng, n % 31)
                                : Mat3{{Vec3{any(), any(), any()}, Vec3{any(), any(), any()},
                                        Vec3{any(), any(), any()}}};
    const Fixed d = raw(static_cast<std::int64_t>(rng()) >> (rng() % 64));
    const Mat3 inertia = n % 2 == 0 ? Mat3::diagonal(d, d, d)
                                    : Mat3::diagonal(d, raw(static_cast<std::int64_t>(rng())), d);
    const Mat3 w = rotate_inertia(r, inertia);
    for (std::size_t i = 0; i < 3; ++i) {
      for (std::size_t j = 0; j < 3; ++j) {
        detail::TripleProductSum exact;
        for (std::size_t k = 0; k < 3; ++k) {
          for (std::size_t l = 0; l < 3; ++l)
            exact.add_product(entry(r, i, k).raw(), entry(inertia, k, l).raw(),
                              entry(r, j, l).raw());
        }
        ASSERT_EQ(entry(w, i, j).raw(), exact.round_to_raw(64)) << testing::PrintToString(r) << "\n"
                                                                << testing::PrintToString(inertia);
      }
    }
  }
}

TEST(Mat3, RotateInertiaByAPermutationPermutesExactly) {
  // R maps x -> y, y -> z, z -> x (the third of a turn about (1, 1, 1)): W = R I R^T has
  // W_ij = I_{p(i) p(j)} with p = R's column of the 1 in row i: p(0) = 2, p(1) = 0, p(2) = 1.
  const Fixed o = Fixed::zero();
  const Fixed l = Fixed::one();
  const Mat3 r{{Vec3{o, o, l}, Vec3{l, o, o}, Vec3{o, l, o}}};
  const Mat3 inertia{
      {Vec3{num(1), num(4), num(5)}, Vec3{num(4), num(2), num(6)}, Vec3{num(5), num(6), num(3)}}};
  EXPECT_EQ(rotate_inertia(r, inertia),
            (Mat3{{Vec3{num(3), num(5), num(6)}, Vec3{num(5), num(1), num(4)},
                   Vec3{num(6), num(4), num(2)}}}));
  EXPECT_EQ(rotate_inertia(Mat3::identity(), inertia), inertia);
  // A multiple of the identity is unchanged by an exact rotation.
  const Mat3 sphere = Mat3::diagonal(num(2), num(2), num(2));
  EXPECT_EQ(rotate_inertia(r, sphere), sphere);
  // No intermediate overflow: I = 2^20 diag, rotation by the permutation.
  const Mat3 big = Mat3::diagonal(num(1 << 20), num(-(1 << 20)), num(1 << 19));
  EXPECT_EQ(rotate_inertia(r, big), Mat3::diagonal(num(1 << 19), num(1 << 20), num(-(1 << 20))));
}

}  // namespace
}  // namespace detsim
