// Accuracy of every function of the fixed layer against MPFR: one test per function, each
// asserting the contract of <detsim/fixed/math.hpp> over >= 1,000,000 seeded inputs plus the edge
// inputs (DETSIM_ACCURACY_SAMPLES sets the count). `detsim accuracy` prints the same measurement
// as a table; docs/ACCURACY.md explains it.
//
// The AccuracyHarness tests check the judge itself on hand-made results whose errors are known
// exactly, so a harness that accepts everything cannot pass.
#include <gtest/gtest.h>

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <string>
#include <vector>

#include <detsim_accuracy/accuracy.hpp>
#include <detsim_accuracy/check.hpp>

namespace {

using namespace detsim::accuracy;
using detsim::Fixed;

void expect_contract(std::string_view name) {
  const FunctionSpec* function = find_function(name);
  ASSERT_NE(function, nullptr) << "no function called " << name;
  std::string error;
  const auto samples = samples_from_environment(default_samples, &error);
  ASSERT_TRUE(samples.has_value()) << error;

  Options options;
  options.samples = *samples;
  const Report r = measure(*function, options);

  std::printf("%s: %" PRIu64 " inputs (%" PRIu64 " random, %" PRIu64 " edge), contract %s\n",
              std::string(function->signature).c_str(), r.inputs(), r.random_inputs, r.edge_inputs,
              std::string(describe(function->contract)).c_str());
  std::printf("  checks: %" PRIu64 " |v| < 2^16, %" PRIu64 " |v| >= 2^16, %" PRIu64
              " saturated, %" PRIu64 " documented, %" PRIu64 " ties, %" PRIu64 " identity\n",
              r.small_checks, r.large_checks, r.saturated_checks, r.domain_checks, r.ties,
              r.identity_checks);
  if (r.worst_ulp_case) {
    std::printf("  worst error %s ulp at %s\n", format_ulp(r.worst_ulp).c_str(),
                describe_case(*function, *r.worst_ulp_case).c_str());
  }
  if (r.worst_relative_case) {
    std::printf("  worst relative error %s at %s\n", format_relative(r).c_str(),
                describe_case(*function, *r.worst_relative_case).c_str());
  }
  ::testing::Test::RecordProperty("inputs", std::to_string(r.inputs()));
  ::testing::Test::RecordProperty("worst_ulp", format_ulp(r.worst_ulp));
  ::testing::Test::RecordProperty("worst_relative", format_relative(r));

  std::string failures;
  for (const Case& c : r.first_failures)
    failures += "  " + describe_case(*function, c) + "\n";
  EXPECT_TRUE(r.passed()) << function->signature << " breaks its contract ("
                          << describe(function->contract) << ") on " << r.failures << " of "
                          << r.inputs() << " inputs; the first " << r.first_failures.size() << ":\n"
                          << failures;
  EXPECT_GT(r.edge_inputs, 0U) << "every function has edge inputs";
}

// One test per function, so that ctest runs them in parallel.
TEST(FixedAccuracy, sqrt) {
  expect_contract("sqrt");
}
TEST(FixedAccuracy, rsqrt) {
  expect_contract("rsqrt");
}
TEST(FixedAccuracy, hypot) {
  expect_contract("hypot");
}
TEST(FixedAccuracy, sin) {
  expect_contract("sin");
}
TEST(FixedAccuracy, cos) {
  expect_contract("cos");
}
TEST(FixedAccuracy, sincos) {
  expect_contract("sincos");
}
TEST(FixedAccuracy, tan) {
  expect_contract("tan");
}
TEST(FixedAccuracy, asin) {
  expect_contract("asin");
}
TEST(FixedAccuracy, acos) {
  expect_contract("acos");
}
TEST(FixedAccuracy, atan) {
  expect_contract("atan");
}
TEST(FixedAccuracy, atan2) {
  expect_contract("atan2");
}
TEST(FixedAccuracy, exp) {
  expect_contract("exp");
}
TEST(FixedAccuracy, exp2) {
  expect_contract("exp2");
}
TEST(FixedAccuracy, log) {
  expect_contract("log");
}
TEST(FixedAccuracy, log2) {
  expect_contract("log2");
}
TEST(FixedAccuracy, pow) {
  expect_contract("pow");
}
TEST(FixedAccuracy, mul) {
  expect_contract("mul");
}
TEST(FixedAccuracy, div) {
  expect_contract("div");
}
TEST(FixedAccuracy, lerp) {
  expect_contract("lerp");
}

TEST(FixedAccuracy, EveryMeasuredFunctionHasATest) {
  // Keep in step with the TESTs above: a function added to the harness must get its test.
  const std::vector<std::string_view> tested = {
      "sqrt",  "rsqrt", "hypot", "sin", "cos",  "sincos", "tan", "asin", "acos", "atan",
      "atan2", "exp",   "exp2",  "log", "log2", "pow",    "mul", "div",  "lerp"};
  std::vector<std::string_view> measured;
  for (const FunctionSpec& f : functions())
    measured.push_back(f.name);
  EXPECT_EQ(measured, tested);
}

// ---- The judge, on results whose errors are known exactly --------------------------------------

constexpr std::int64_t one = Fixed::one_raw;

/// exact = (whole + numerator / 2^bits) ulp, built exactly.
class HarnessTest : public ::testing::Test {
 protected:
  mpfr_srcptr ulps(std::int64_t whole, std::int64_t numerator = 0, unsigned bits = 0) {
    mpfr_set_sj(exact_.get(), numerator, MPFR_RNDN);
    mpfr_div_2ui(exact_.get(), exact_.get(), bits, MPFR_RNDN);
    mpfr_add_si(exact_.get(), exact_.get(), whole, MPFR_RNDN);
    mpfr_div_2ui(exact_.get(), exact_.get(), 32, MPFR_RNDN);
    return exact_.get();
  }
  /// exact = 2^e + (numerator / 2^bits) ulp.
  mpfr_srcptr power_plus(long e, std::int64_t numerator, unsigned bits) {
    Mp offset;
    mpfr_set_sj(offset.get(), numerator, MPFR_RNDN);
    mpfr_div_2ui(offset.get(), offset.get(), bits + 32, MPFR_RNDN);
    mpfr_set_si_2exp(exact_.get(), 1, e, MPFR_RNDN);
    mpfr_add(exact_.get(), exact_.get(), offset.get(), MPFR_RNDN);
    return exact_.get();
  }
  bool pass(Contract c, std::int64_t result_raw, mpfr_srcptr exact) {
    return checker_.check(c, Fixed::from_raw(result_raw), exact).pass;
  }

  Checker checker_;
  Mp exact_;
};

TEST_F(HarnessTest, CorrectlyRoundedAcceptsOnlyTheNearestValue) {
  constexpr auto cr = Contract::correctly_rounded;
  EXPECT_TRUE(pass(cr, one, ulps(one, 3, 3)));  // 1 + 3/8 ulp
  EXPECT_FALSE(pass(cr, one + 1, ulps(one, 3, 3)));
  EXPECT_TRUE(pass(cr, one + 1, ulps(one, 5, 3)));  // 1 + 5/8 ulp
  EXPECT_FALSE(pass(cr, one, ulps(one, 5, 3)));
  EXPECT_TRUE(pass(cr, -one, ulps(-one, -3, 3)));
  EXPECT_FALSE(pass(cr, -one - 1, ulps(-one, -3, 3)));
  const Verdict v = checker_.check(cr, Fixed::from_raw(one), ulps(one, 3, 3));
  EXPECT_DOUBLE_EQ(v.error_ulp, 0.375);
  EXPECT_EQ(v.region, Region::small);
}

TEST_F(HarnessTest, TiesGoToTheEvenNeighbour) {
  constexpr auto cr = Contract::correctly_rounded;
  EXPECT_TRUE(pass(cr, 2, ulps(2, 1, 1)));  // 2.5 ulp -> 2
  EXPECT_FALSE(pass(cr, 3, ulps(2, 1, 1)));
  EXPECT_TRUE(pass(cr, 4, ulps(3, 1, 1)));  // 3.5 ulp -> 4
  EXPECT_FALSE(pass(cr, 3, ulps(3, 1, 1)));
  EXPECT_TRUE(pass(cr, -2, ulps(-2, -1, 1)));  // -2.5 ulp -> -2
  EXPECT_FALSE(pass(cr, -3, ulps(-2, -1, 1)));
  EXPECT_TRUE(checker_.check(cr, Fixed::from_raw(2), ulps(2, 1, 1)).tie);
  EXPECT_FALSE(checker_.check(cr, Fixed::from_raw(2), ulps(2, 1, 2)).tie);
  // Just off a tie is not a tie: 2.5 ulp + 2^-100 rounds up.
  EXPECT_TRUE(pass(cr, 3, power_plus(-31, (std::int64_t{1} << 61) + 1, 62)));
}

TEST_F(HarnessTest, CorrectlyRoundedSaturates) {
  constexpr auto cr = Contract::correctly_rounded;
  const std::int64_t max = Fixed::max().raw();
  EXPECT_TRUE(pass(cr, max, power_plus(31, 0, 0)));  // 2^31 is just beyond max()
  EXPECT_FALSE(pass(cr, max - 1, power_plus(31, 0, 0)));
  EXPECT_TRUE(pass(cr, max, power_plus(40, 0, 0)));
  EXPECT_FALSE(pass(cr, Fixed::min().raw(), power_plus(31, 0, 0)));
  mpfr_neg(exact_.get(), power_plus(31, 1, 4), MPFR_RNDN);  // -(2^31 + 1/16 ulp)
  EXPECT_TRUE(pass(cr, Fixed::min().raw(), exact_.get()));
  EXPECT_FALSE(pass(cr, Fixed::min().raw() + 1, exact_.get()));
}

TEST_F(HarnessTest, FaithfulAllowsLessThanOneUlp) {
  constexpr auto f = Contract::faithful;
  EXPECT_TRUE(pass(f, one, ulps(one, 255, 8)));  // 1 + 255/256 ulp: either neighbour
  EXPECT_TRUE(pass(f, one + 1, ulps(one, 255, 8)));
  EXPECT_FALSE(pass(f, one - 1, ulps(one, 255, 8)));  // 1.996 ulp away
  EXPECT_FALSE(pass(f, one + 2, ulps(one, 255, 8)));
  // An exact value on the grid admits only itself: its neighbours are exactly 1 ulp away.
  EXPECT_TRUE(pass(f, one, ulps(one)));
  EXPECT_FALSE(pass(f, one + 1, ulps(one)));
  EXPECT_FALSE(pass(f, -1, ulps(0)));
}

TEST_F(HarnessTest, FaithfulIsRelativeFromTwoToTheSixteen) {
  constexpr auto f = Contract::faithful;
  const std::int64_t v = one << 20;  // 2^20: 2^-46 of it is 2^-26 = 64 ulp
  EXPECT_TRUE(pass(f, v + 63, power_plus(20, 0, 0)));
  EXPECT_FALSE(pass(f, v + 64, power_plus(20, 0, 0)));
  EXPECT_FALSE(pass(f, v - 65, power_plus(20, 0, 0)));
  const Verdict verdict = checker_.check(f, Fixed::from_raw(v + 32), power_plus(20, 0, 0));
  EXPECT_EQ(verdict.region, Region::large);
  EXPECT_DOUBLE_EQ(verdict.relative, 0x1p-47);
  // Just below 2^16 the ulp rule still applies.
  EXPECT_FALSE(pass(f, (one << 16) - 3, power_plus(16, -1, 0)));
}

TEST_F(HarnessTest, FaithfulSaturatesBeyondTheRange) {
  constexpr auto f = Contract::faithful;
  const std::int64_t max = Fixed::max().raw();
  EXPECT_TRUE(pass(f, max, power_plus(32, 0, 0)));
  EXPECT_FALSE(pass(f, 0, power_plus(32, 0, 0)));
  EXPECT_FALSE(pass(f, max - 1, power_plus(32, 0, 0)));  // 2^31 below 2^32: not close
  // Within 2^-46 relative of the threshold, a result on the other side of it is still faithful.
  EXPECT_TRUE(pass(f, max - 1, power_plus(31, 1, 0)));
  EXPECT_EQ(checker_.check(f, Fixed::max(), power_plus(31, 1, 0)).region, Region::beyond);
}

TEST_F(HarnessTest, RoundToFixedIsTiesToEvenAndSaturates) {
  Mp scratch;
  bool tie = false;
  EXPECT_EQ(round_to_fixed(ulps(6, 1, 1), scratch.get(), &tie).raw(), 6);
  EXPECT_TRUE(tie);
  EXPECT_EQ(round_to_fixed(ulps(7, 1, 1), scratch.get(), &tie).raw(), 8);
  EXPECT_EQ(round_to_fixed(ulps(-7, -1, 1), scratch.get(), &tie).raw(), -8);
  EXPECT_EQ(round_to_fixed(ulps(7, 1, 2), scratch.get(), &tie).raw(), 7);
  EXPECT_FALSE(tie);
  EXPECT_EQ(round_to_fixed(power_plus(31, -1, 1), scratch.get()), Fixed::max());  // rounds up: 2^31
  EXPECT_EQ(round_to_fixed(power_plus(31, -3, 1), scratch.get()).raw(), Fixed::max().raw() - 1);
}

TEST(AccuracyHarness, MeasurementIsDeterministic) {
  const FunctionSpec* mul = find_function("mul");
  ASSERT_NE(mul, nullptr);
  Options options;
  options.samples = 5000;
  const Report a = measure(*mul, options);
  const Report b = measure(*mul, options);
  EXPECT_EQ(a.inputs(), b.inputs());
  EXPECT_EQ(a.worst_ulp, b.worst_ulp);
  ASSERT_TRUE(a.worst_ulp_case && b.worst_ulp_case);
  EXPECT_EQ(a.worst_ulp_case->args, b.worst_ulp_case->args);
  EXPECT_EQ(a.ties, b.ties);
  EXPECT_GT(a.ties, 0U) << "the edge inputs must exercise exact ties";
  EXPECT_EQ(a.input_digest, b.input_digest);
  options.seed ^= 1;
  const Report c = measure(*mul, options);
  EXPECT_NE(a.input_digest, c.input_digest) << "another seed draws other inputs";
  EXPECT_EQ(a.edge_inputs, c.edge_inputs);
}

TEST(AccuracyHarness, EdgeInputsReachEveryKindOfCheck) {
  // The core operations are exact integer code already, so their runs show what the edge lists
  // reach: documented values (x / 0), saturation, and exact ties for the tie-breaking rule.
  Options options;
  options.samples = 2000;
  for (const std::string_view name : {"mul", "div", "lerp"}) {
    const FunctionSpec* f = find_function(name);
    ASSERT_NE(f, nullptr);
    const Report r = measure(*f, options);
    EXPECT_GT(r.saturated_checks, 0U) << name;
    EXPECT_GT(r.ties, 0U) << name;
    EXPECT_GT(r.small_checks, 0U) << name;
    EXPECT_GT(r.large_checks, 0U) << name;
    if (name == "div") {
      EXPECT_GT(r.domain_checks, 0U) << "x / 0 must be among the edge inputs";
    }
  }
}

}  // namespace
