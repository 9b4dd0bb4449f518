// Quat: Hamilton product, conjugate, normalisation, rotation of vectors, rotation matrices,
// axis-angle construction and orientation integration. Expected values come from exact 128-bit
// arithmetic, exact identities and error bounds derived in the comments (ulp = 2^-32; |v| in Fixed
// units).
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <random>
#include <utility>

#include <gtest/gtest.h>
#include <detsim/fixed/math.hpp>
#include <detsim/fixed/quat.hpp>

#include "support/vector_print.hpp"

namespace detsim {
namespace {

using test::i128;
using test::is_rounded;
using test::product;
using test::u128;

constexpr std::int64_t kOne = Fixed::one_raw;
const i128 kOneSquared = i128{1} << 64;  // 1 in the Q64.64 units of an exact product of raws

Fixed raw(std::int64_t r) {
  return Fixed::from_raw(r);
}
Fixed num(std::int32_t i) {
  return Fixed::from_int(i);
}

i128 sum_of_squares(Quat q) {
  return product(q.w, q.w) + product(q.x, q.x) + product(q.y, q.y) + product(q.z, q.z);
}

i128 abs128(i128 v) {
  return v < 0 ? -v : v;
}

// The header's unit bound: | |q|^2 - 1 | < 2^-31 + 2^-56, i.e. 2^33 + 2^8 in Q64.64 units.
const i128 kUnitBound = (i128{1} << 33) + (i128{1} << 8);

Quat random_unit(std::mt19937_64& rng) {
  for (;;) {
    const auto c = [&rng] { return raw(static_cast<std::int64_t>(rng() >> 31) - kOne); };
    const Quat q{c(), c(), c(), c()};
    if (q != Quat{Fixed::zero(), Fixed::zero(), Fixed::zero(), Fixed::zero()}) return normalize(q);
  }
}

Vec3 random_vec(std::mt19937_64& rng, int bits) {
  const auto c = [&] {
    return raw(static_cast<std::int64_t>(rng() >> (31 - bits)) - (std::int64_t{1} << (32 + bits)));
  };
  return {c(), c(), c()};
}

// Products, rotation and matrices are constexpr.
static_assert(rotate(Quat{Fixed::zero(), Fixed::zero(), Fixed::zero(), Fixed::one()},
                     Vec3::unit_x()) == -Vec3::unit_x());
static_assert(to_mat3(Quat::identity()) == Mat3::identity());
static_assert(Quat{Fixed::zero(), Fixed::one(), Fixed::zero(), Fixed::zero()} *
                  Quat{Fixed::zero(), Fixed::zero(), Fixed::one(), Fixed::zero()} ==
              Quat{Fixed::zero(), Fixed::zero(), Fixed::zero(), Fixed::one()});

// ---- Algebra -----------------------------------------------------------------------------------

TEST(Quat, DefaultIsTheIdentity) {
  EXPECT_EQ(Quat{}, Quat::identity());
  EXPECT_EQ(Quat::identity(), (Quat{Fixed::one(), Fixed::zero(), Fixed::zero(), Fixed::zero()}));
  const Quat q{num(2), num(-3), Fixed::half(), raw(12345)};
  EXPECT_EQ(Quat::identity() * q, q);
  EXPECT_EQ(q * Quat::identity(), q);
  EXPECT_EQ(q.vector(), (Vec3{num(-3), Fixed::half(), raw(12345)}));
}

TEST(Quat, HamiltonProductOfTheBasis) {
  const Fixed o = Fixed::zero();
  const Fixed l = Fixed::one();
  const Quat i{o, l, o, o};
  const Quat j{o, o, l, o};
  const Quat k{o, o, o, l};
  const Quat minus_one{-l, o, o, o};
  EXPECT_EQ(i * j, k);
  EXPECT_EQ(j * k, i);
  EXPECT_EQ(k * i, j);
  EXPECT_EQ(j * i, (Quat{o, o, o, -l}));
  EXPECT_EQ(i * i, minus_one);
  EXPECT_EQ(j * j, minus_one);
  EXPECT_EQ(k * k, minus_one);
  EXPECT_EQ(i * j * k, minus_one);
}

// Components below 2^20: four products up to 2^104 each fit the 128-bit reference.
TEST(Quat, ProductDotAndLengthSquaredAreTheExactValuesRoundedOnce) {
  std::mt19937_64 rng(201);
  const auto c = [&rng] {
    const int width = static_cast<int>(rng() % 52) + 1;
    const auto mag = static_cast<std::int64_t>(rng() >> (64 - width));
    return raw(test::maybe_coarse((rng() & 1) != 0 ? -mag : mag, rng));
  };
  for (int n = 0; n < 200000; ++n) {
    const Quat a{c(), c(), c(), c()};
    const Quat b{c(), c(), c(), c()};
    const Quat p = a * b;
    const i128 w = product(a.w, b.w) - product(a.x, b.x) - product(a.y, b.y) - product(a.z, b.z);
    const i128 x = product(a.w, b.x) + product(a.x, b.w) + product(a.y, b.z) - product(a.z, b.y);
    const i128 y = product(a.w, b.y) - product(a.x, b.z) + product(a.y, b.w) + product(a.z, b.x);
    const i128 z = product(a.w, b.z) + product(a.x, b.y) - product(a.y, b.x) + product(a.z, b.w);
    ASSERT_TRUE(is_rounded(p.w.raw(), w, 32) && is_rounded(p.x.raw(), x, 32) &&
                is_rounded(p.y.raw(), y, 32) && is_rounded(p.z.raw(), z, 32))
        << testing::PrintToString(a) << " * " << testing::PrintToString(b) << " = "
        << testing::PrintToString(p);
    const i128 d = product(a.w, b.w) + product(a.x, b.x) + product(a.y, b.y) + product(a.z, b.z);
    ASSERT_TRUE(is_rounded(dot(a, b).raw(), d, 32));
    ASSERT_TRUE(is_rounded(length_squared(a).raw(), sum_of_squares(a), 32));
  }
}

// q q* = (w^2 + x^2 + y^2 + z^2, -w x + x w - y z + z y, ...): the vector part is exactly zero
// before rounding and the scalar part is exactly what length_squared rounds.
TEST(Quat, ProductWithTheConjugateIsExactlyTheSquaredLength) {
  std::mt19937_64 rng(202);
  for (int n = 0; n < 100000; ++n) {
    const int shift = n % 40;
    const auto c = [&] { return raw(static_cast<std::int64_t>(rng()) >> shift); };
    const Quat q{c(), c(), c(), c()};
    if (q.x == Fixed::min() || q.y == Fixed::min() || q.z == Fixed::min()) continue;
    const Fixed o = Fixed::zero();
    ASSERT_EQ(q * conjugate(q), (Quat{length_squared(q), o, o, o})) << testing::PrintToString(q);
    ASSERT_EQ(conjugate(q) * q, (Quat{length_squared(q), o, o, o})) << testing::PrintToString(q);
  }
  // conjugate saturates like Fixed negation.
  EXPECT_EQ(conjugate(Quat{Fixed::min(), Fixed::min(), Fixed::one(), Fixed::zero()}),
            (Quat{Fixed::min(), Fixed::max(), -Fixed::one(), Fixed::zero()}));
}

// ---- Normalisation -----------------------------------------------------------------------------

TEST(Quat, NormalizeOfZeroIsTheIdentity) {
  const Fixed o = Fixed::zero();
  EXPECT_EQ(normalize(Quat{o, o, o, o}), Quat::identity());
}

TEST(Quat, NormalizeOfExactCasesIsExact) {
  const Fixed o = Fixed::zero();
  const Fixed h = Fixed::half();
  EXPECT_EQ(normalize(Quat{num(5), o, o, o}), Quat::identity());
  EXPECT_EQ(normalize(Quat{o, o, raw(-1), o}), (Quat{o, o, -Fixed::one(), o}));
  // |(m, m, m, m)| = 2 |m|: each component is exactly 1/2; m = min() takes the halving path.
  for (const Fixed m : {Fixed::min(), Fixed::max(), raw(1), raw(-3), num(1000)}) {
    const Fixed e = m.raw() < 0 ? -h : h;
    EXPECT_EQ(normalize(Quat{m, m, m, m}), (Quat{e, e, e, e})) << testing::PrintToString(m);
  }
  EXPECT_EQ(normalize(Quat{Fixed::min(), Fixed::min(), Fixed::max(), Fixed::max()}),
            (Quat{-h, -h, h, h}));
  // (3, 0, 4, 0) / 5 has no exact representation: 3/5 and 4/5 rounded to nearest.
  const Quat q = normalize(Quat{num(3), o, num(-4), o});
  EXPECT_EQ(q.w, raw(2576980378));   // round(0.6 2^32) = round(2576980377.6)
  EXPECT_EQ(q.y, raw(-3435973837));  // round(0.8 2^32) = round(3435973836.8)
}

TEST(Quat, NormalizeGivesUnitLengthWithinTheStatedBound) {
  std::mt19937_64 rng(203);
  i128 worst = 0;
  for (int n = 0; n < 300000; ++n) {
    const int shift = n % 63;
    const auto c = [&] { return raw(static_cast<std::int64_t>(rng()) >> shift); };
    const Quat q{c(), c(), c(), n % 5 == 0 ? Fixed::min() : c()};
    const Quat u = normalize(q);
    const i128 dev = abs128(sum_of_squares(u) - kOneSquared);
    worst = dev > worst ? dev : worst;
    ASSERT_LE(dev, kUnitBound) << testing::PrintToString(q) << " -> " << testing::PrintToString(u);
  }
  RecordProperty("worst_unit_deviation_in_ulp_times_1000",
                 static_cast<int>(worst * 1000 / (i128{1} << 32)));
}

// ---- Rotation ----------------------------------------------------------------------------------

TEST(Quat, RotateByExactQuaternions) {
  const Fixed o = Fixed::zero();
  const Fixed l = Fixed::one();
  const Vec3 v{num(3), num(-5), Fixed::half()};
  EXPECT_EQ(rotate(Quat::identity(), v), v);
  // Half turns about the axes: (0, 0, 0, 1) is pi about z, (x, y, z) -> (-x, -y, z).
  EXPECT_EQ(rotate(Quat{o, o, o, l}, v), (Vec3{num(-3), num(5), Fixed::half()}));
  EXPECT_EQ(rotate(Quat{o, l, o, o}, v), (Vec3{num(3), num(5), -Fixed::half()}));
  EXPECT_EQ(rotate(Quat{o, o, l, o}, v), (Vec3{num(-3), num(-5), -Fixed::half()}));
  // (1/2)(1, 1, 1, 1) is a third of a turn about (1, 1, 1): it cycles x -> y -> z -> x.
  const Fixed h = Fixed::half();
  EXPECT_EQ(rotate(Quat{h, h, h, h}, v), (Vec3{Fixed::half(), num(3), num(-5)}));
  EXPECT_EQ(to_mat3(Quat{h, h, h, h}), (Mat3{{Vec3{o, o, l}, Vec3{l, o, o}, Vec3{o, l, o}}}));
  EXPECT_EQ(to_mat3(Quat::identity()), Mat3::identity());
}

// The header's bound for rotate: |v' - R v| <= 2.1 ulp + 2 |eps| |v|. Lengths: | |v'| - |v| | is at
// most that, plus the 1/2 ulp rounding of each of the two length() calls.
TEST(Quat, RotatePreservesLengthWithinTheStatedBound) {
  std::mt19937_64 rng(204);
  for (int n = 0; n < 100000; ++n) {
    const Quat q = random_unit(rng);
    const Vec3 v = random_vec(rng, n % 12);
    const long double eps =
        static_cast<long double>(abs128(sum_of_squares(q) - kOneSquared)) / 0x1p64L;
    const long double v_len = length(v).to_double();
    const long double bound = 2.1L + 1.0L + 2.0L * eps * v_len * 0x1p32L;
    const long double diff =
        std::fabs(static_cast<long double>(length(rotate(q, v)).raw() - length(v).raw()));
    ASSERT_LE(diff, bound) << testing::PrintToString(q) << " " << testing::PrintToString(v);
    // And back: rotating by the conjugate undoes the rotation within twice the bound per step.
    const Vec3 back = rotate(conjugate(q), rotate(q, v));
    for (const auto& [a, b] :
         {std::pair{back.x, v.x}, std::pair{back.y, v.y}, std::pair{back.z, v.z}}) {
      ASSERT_LE(std::fabs(static_cast<long double>(a.raw() - b.raw())),
                2 * (2.1L + 2.0L * eps * (v_len + 1) * 0x1p32L))
          << testing::PrintToString(q) << " " << testing::PrintToString(v);
    }
  }
}

// to_mat3(q) v and rotate(q, v) are the same polynomial map of (q, v) evaluated with different
// roundings. Per component: rotate is within 1/2 ulp (final rounding) + (1/2)(|w| + |u_j| + |u_k|)
// <= 1/2 + (sqrt(3)/2)|q| < 1.37 ulp of the exact map; the matrix product within 1/2 ulp per entry
// times |v_j|, summed, plus its own 1/2 ulp rounding. Bound: 1.9 ulp + (1/2) ||v||_1.
TEST(Quat, ToMat3AgreesWithRotate) {
  std::mt19937_64 rng(205);
  for (int n = 0; n < 100000; ++n) {
    const Quat q = random_unit(rng);
    const Vec3 v = random_vec(rng, n % 12);
    const Vec3 a = to_mat3(q) * v;
    const Vec3 b = rotate(q, v);
    const long double l1 =
        std::fabs(v.x.to_double()) + std::fabs(v.y.to_double()) + std::fabs(v.z.to_double());
    const long double bound = 1.9L + 0.5L * l1;
    for (const auto& [x, y] : {std::pair{a.x, b.x}, std::pair{a.y, b.y}, std::pair{a.z, b.z}}) {
      ASSERT_LE(std::fabs(static_cast<long double>(x.raw() - y.raw())), bound)
          << testing::PrintToString(q) << " " << testing::PrintToString(v);
    }
  }
}

// to_mat3(q) = R + eps (R - I) + E with |E_ij| <= 1/2 ulp, so every entry of M M^T - I is at most
// 4 |eps| + sqrt(3) ulp plus second-order terms below 2^-58 (header). Checked on the exact product
// (entries near 1: raws below 2^33, products below 2^66) with eps measured exactly from q.
TEST(Quat, RotationMatricesAreOrthogonalWithinTheDerivedBound) {
  std::mt19937_64 rng(206);
  i128 worst = 0;
  for (int n = 0; n < 100000; ++n) {
    const Quat q = random_unit(rng);
    const Mat3 m = to_mat3(q);
    const i128 eps = abs128(sum_of_squares(q) - kOneSquared);
    const i128 bound = 4 * eps + (i128{17321} << 32) / 10000 + (i128{1} << 8);
    for (std::size_t i = 0; i < 3; ++i) {
      for (std::size_t j = 0; j < 3; ++j) {
        const Vec3 a = m.rows[i];
        const Vec3 b = m.rows[j];
        const i128 exact = product(a.x, b.x) + product(a.y, b.y) + product(a.z, b.z);
        const i128 dev = abs128(exact - (i == j ? kOneSquared : 0));
        worst = dev > worst ? dev : worst;
        ASSERT_LE(dev, bound) << testing::PrintToString(q) << "\n" << testing::PrintToString(m);
      }
    }
  }
  RecordProperty("worst_orthogonality_error_in_ulp_times_1000",
                 static_cast<int>(worst * 1000 / (i128{1} << 32)));
}

TEST(Quat, ToMat3IsTheSameForQAndMinusQ) {
  std::mt19937_64 rng(207);
  for (int n = 0; n < 10000; ++n) {
    const Quat q = random_unit(rng);
    ASSERT_EQ(to_mat3(q), to_mat3(Quat{-q.w, -q.x, -q.y, -q.z}));
  }
}

// ---- Axis and angle ----------------------------------------------------------------------------

TEST(Quat, FromAxisAngleWithAZeroAxisOrAngleIsTheIdentity) {
  EXPECT_EQ(from_axis_angle(Vec3::zero(), num(1)), Quat::identity());
  // sin(0) = 0 and cos(0) = 1 are exact, and a faithful result equals an exact one.
  EXPECT_EQ(from_axis_angle(Vec3::unit_y(), Fixed::zero()), Quat::identity());
}

// Quarter turn about z. Errors (ulp): half_pi() is within 1/2 ulp of pi/2 (delta) and halves
// exactly; sincos is faithful (< 1 ulp each) and the unit axis is exact, so the unnormalised
// (c, 0, 0, s) is within sqrt(2) of the exact quaternion, its projection onto the unit sphere
// within 2 sqrt(2) and the rounded normalisation within 2 sqrt(2) + sqrt(2)/2 = 3.54 (Euclidean).
// rotate computes (1 - 2 z^2, 2 w z, 0) from q = (w, 0, 0, z): |dx| = 4 |z dz| <= 2.83 |dq| and
// |dy| = 2 |z dw + w dz| <= 2 |dq| (Cauchy-Schwarz, |(w, z)| = 1). So x is within
// 2.83 * 3.54 + 1.37 (rotate's rounding) + 0.5 (delta) = 11.9 ulp of 0 and y within
// 2 * 3.54 + 1.37 = 8.5 ulp of 1.
// The z component is exactly 0: every term of it has a zero factor.
TEST(Quat, FromAxisAngleQuarterTurnMapsXToY) {
  const Quat q = from_axis_angle(Vec3::unit_z(), Fixed::half_pi());
  const Vec3 y = rotate(q, Vec3::unit_x());
  EXPECT_LE(std::abs(y.x.raw()), 12)
      << testing::PrintToString(q) << " " << testing::PrintToString(y);
  EXPECT_LE(std::abs(y.y.raw() - kOne), 9)
      << testing::PrintToString(q) << " " << testing::PrintToString(y);
  EXPECT_EQ(y.z, Fixed::zero());
  // The axis length does not matter.
  EXPECT_EQ(from_axis_angle(Vec3{Fixed::zero(), Fixed::zero(), num(7)}, Fixed::half_pi()), q);
  EXPECT_LE(abs128(sum_of_squares(q) - kOneSquared), kUnitBound);
}

// from_axis_angle(z, a) from_axis_angle(z, b) vs from_axis_angle(z, a + b): each construction is
// within 4.95 ulp (Euclidean) of the exact quaternion Q(angle / 2): the half angle's rounding
// (1/2 ulp) and sincos (< 1 ulp) put (c, 0, 0, s) within 1.5 sqrt(2) = 2.12, the projection onto
// the unit sphere doubles that and normalize's rounding adds sqrt(2)/2. Q(a) Q(b) = Q(a + b)
// exactly, and the computed product is within 4.95 + 4.95 + 0.71 (its rounding) of it, so the two
// results differ by at most 4.95 * 3 + 0.71 < 16 ulp.
TEST(Quat, FromAxisAngleComposesAboutOneAxis) {
  std::mt19937_64 rng(208);
  for (int n = 0; n < 20000; ++n) {
    const Fixed a = raw(static_cast<std::int64_t>(rng() >> 30) - (std::int64_t{1} << 33));
    const Fixed b = raw(static_cast<std::int64_t>(rng() >> 30) - (std::int64_t{1} << 33));
    const Quat ab = from_axis_angle(Vec3::unit_z(), a) * from_axis_angle(Vec3::unit_z(), b);
    const Quat c = from_axis_angle(Vec3::unit_z(), a + b);
    ASSERT_LE(std::abs(ab.w.raw() - c.w.raw()), 16)
        << testing::PrintToString(a) << " " << testing::PrintToString(b);
    ASSERT_LE(std::abs(ab.z.raw() - c.z.raw()), 16)
        << testing::PrintToString(a) << " " << testing::PrintToString(b);
    ASSERT_EQ(ab.x, Fixed::zero());
    ASSERT_EQ(ab.y, Fixed::zero());
  }
}

TEST(Quat, FromAxisAngleGivesUnitQuaternionsThatFixTheAxis) {
  std::mt19937_64 rng(209);
  for (int n = 0; n < 20000; ++n) {
    const Vec3 axis = random_vec(rng, 4);
    if (axis == Vec3::zero()) continue;
    const Fixed angle = raw(static_cast<std::int64_t>(rng()) >> 28);  // |angle| < 2^3
    const Quat q = from_axis_angle(axis, angle);
    ASSERT_LE(abs128(sum_of_squares(q) - kOneSquared), kUnitBound) << testing::PrintToString(q);
    // The axis is fixed. With n the normalised axis, q's vector part u is parallel to n up to e,
    // the part of the rounding errors perpendicular to n: the products n_i s (1/2 ulp each,
    // sqrt(3)/2 in all) and normalize (the same again), |e| <= 1.74 ulp. Exactly,
    // rotate(q, n) - n = 2 w (e x n) + 2 u x (e x n), at most 2 |e| (|w| + |u|) <= 2 sqrt(2) |e|
    // = 4.93 ulp, and rotate's rounding adds 1.37 ulp per component: below 7 ulp.
    const Vec3 n_axis = normalize(axis);
    const Vec3 r = rotate(q, n_axis);
    for (const auto& [x, y] :
         {std::pair{r.x, n_axis.x}, std::pair{r.y, n_axis.y}, std::pair{r.z, n_axis.z}}) {
      ASSERT_LE(std::abs(x.raw() - y.raw()), 7)
          << testing::PrintToString(axis) << " " << testing::PrintToString(angle);
    }
  }
}

// ---- Integration -------------------------------------------------------------------------------

Fixed sixtieth() {
  return Fixed::one() / num(60);
}

// Every step ends in normalize, whose bound does not depend on the input, so |q|^2 stays within
// 2^-31 + 2^-56 of 1 at every step, however long the run. 10^6 steps at 60 Hz is 4.6 hours of a
// body spinning at |omega| = 18.4 rad/s (about 3 turns per second), about a changing axis.
TEST(Quat, IntegrationKeepsUnitLengthForAMillionSteps) {
  const Fixed dt = sixtieth();
  Quat q = Quat::identity();
  i128 worst = 0;
  for (int n = 0; n < 1000000; ++n) {
    // A slowly wobbling large angular velocity, so the axis keeps changing.
    const Vec3 omega{num(7) + raw(static_cast<std::int64_t>(n % 1000) << 22), num(-11), num(13)};
    q = integrate(q, omega, dt);
    const i128 dev = abs128(sum_of_squares(q) - kOneSquared);
    worst = dev > worst ? dev : worst;
    ASSERT_LE(dev, kUnitBound) << "step " << n << ": " << testing::PrintToString(q);
  }
  RecordProperty("worst_unit_deviation_in_ulp_times_1000",
                 static_cast<int>(worst * 1000 / (i128{1} << 32)));
}

// About a fixed axis z from the identity, every step keeps q = (cos phi, 0, 0, sin phi) exactly in
// x and y, and multiplies it by (1, 0, 0, a) / sqrt(1 + a^2) with a = round(omega dt / 2): a turn
// of the half angle by atan(a). After n steps phi = n atan(a). Each step adds at most ~3 ulp of
// rounding (1/2 ulp per component before and after normalising, doubled by the projection) and left
// multiplication by a unit quaternion preserves errors, so after 60 steps the error is below 180
// ulp.
TEST(Quat, IntegrationAboutAFixedAxisFollowsTheExactRecurrence) {
  const Fixed dt = sixtieth();
  const Fixed omega = Fixed::pi();  // half a turn per second
  // a = omega dt / 2 rounded to nearest: the exact product shifted by 33 bits.
  const i128 exact = product(omega, dt);
  std::int64_t a_raw = static_cast<std::int64_t>(exact >> 33);
  const i128 rest = exact - (static_cast<i128>(a_raw) << 33);
  if (rest > (i128{1} << 32) || (rest == (i128{1} << 32) && (a_raw & 1) != 0)) ++a_raw;
  const long double phi = std::atan(static_cast<long double>(a_raw) / 0x1p32L);
  Quat q = Quat::identity();
  for (int n = 1; n <= 60; ++n) {
    q = integrate(q, Vec3{Fixed::zero(), Fixed::zero(), omega}, dt);
    ASSERT_EQ(q.x, Fixed::zero());
    ASSERT_EQ(q.y, Fixed::zero());
    const long double bound = 3.0L * n;
    ASSERT_LE(std::fabs(static_cast<long double>(q.w.raw()) - std::cos(n * phi) * 0x1p32L), bound)
        << "step " << n << ": " << testing::PrintToString(q);
    ASSERT_LE(std::fabs(static_cast<long double>(q.z.raw()) - std::sin(n * phi) * 0x1p32L), bound)
        << "step " << n << ": " << testing::PrintToString(q);
  }
  // After one second the body has turned by 2 * 60 * atan(pi / 120), just under pi.
  EXPECT_LT(q.w.to_double(), 0.01);
}

// About a general axis from a general start, q_n = P^n q_0 with P = (1, a) / sqrt(1 + |a|^2): the
// angular velocity is in world space, so each step multiplies on the left. The reference runs the
// same recurrence in long double (error far below an ulp) with the exactly rounded a; the bound
// is the same 3 ulp per step as above (left multiplication by a unit quaternion preserves errors).
TEST(Quat, IntegrationMultipliesOnTheLeftByTheWorldSpaceStep) {
  const Fixed dt = sixtieth();
  const Vec3 omega{Fixed::from_int(3) / num(2), num(-2), Fixed::from_int(7) / num(10)};
  const auto half_step = [dt](Fixed w) {
    const i128 exact = product(w, dt);
    std::int64_t r = static_cast<std::int64_t>(exact >> 33);
    const i128 rest = exact - (static_cast<i128>(r) << 33);
    if (rest > (i128{1} << 32) || (rest == (i128{1} << 32) && (r & 1) != 0)) ++r;
    return static_cast<long double>(r) / 0x1p32L;
  };
  const long double ax = half_step(omega.x);
  const long double ay = half_step(omega.y);
  const long double az = half_step(omega.z);
  const long double norm = std::sqrt(1 + ax * ax + ay * ay + az * az);
  const long double p[4] = {1 / norm, ax / norm, ay / norm, az / norm};
  Quat q = normalize(Quat{num(1), num(2), num(3), num(4)});
  long double e[4] = {q.w.raw() / 0x1p32L, q.x.raw() / 0x1p32L, q.y.raw() / 0x1p32L,
                      q.z.raw() / 0x1p32L};
  for (int n = 1; n <= 120; ++n) {
    q = integrate(q, omega, dt);
    const long double w = p[0] * e[0] - p[1] * e[1] - p[2] * e[2] - p[3] * e[3];
    const long double x = p[0] * e[1] + p[1] * e[0] + p[2] * e[3] - p[3] * e[2];
    const long double y = p[0] * e[2] - p[1] * e[3] + p[2] * e[0] + p[3] * e[1];
    const long double z = p[0] * e[3] + p[1] * e[2] - p[2] * e[1] + p[3] * e[0];
    e[0] = w;
    e[1] = x;
    e[2] = y;
    e[3] = z;
    const long double bound = 3.0L * n;
    for (const auto& [got, want] :
         {std::pair{q.w, w}, std::pair{q.x, x}, std::pair{q.y, y}, std::pair{q.z, z}}) {
      ASSERT_LE(std::fabs(static_cast<long double>(got.raw()) - want * 0x1p32L), bound)
          << "step " << n << ": " << testing::PrintToString(q);
    }
  }
}

TEST(Quat, IntegrationWithoutAngularVelocityLeavesTheIdentity) {
  EXPECT_EQ(integrate(Quat::identity(), Vec3::zero(), sixtieth()), Quat::identity());
  EXPECT_EQ(integrate(Quat::identity(), Vec3{num(5), num(5), num(5)}, Fixed::zero()),
            Quat::identity());
}

}  // namespace
}  // namespace detsim
