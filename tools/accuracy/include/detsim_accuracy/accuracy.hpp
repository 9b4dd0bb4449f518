// Accuracy of the fixed-point functions, measured against MPFR. One implementation behind both
// tests/mpfr/fixed_accuracy_test.cpp (pass/fail) and `detsim accuracy` (the table in
// docs/ACCURACY.md).
//
// Definitions (docs/ACCURACY.md explains them at length):
// - exact value v: the function of the exact inputs (raw / 2^32), computed by MPFR with
//   reference_precision bits;
// - error_ulp = |result - v| * 2^32 (one ulp is 2^-32, the spacing of Q32.32 values);
// - relative error = |result - v| / |v|.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <detsim/fixed/fixed.hpp>

namespace detsim::accuracy {

/// What a function promises.
enum class Contract : std::uint8_t {
  /// The result is v rounded to the nearest Q32.32 value, ties to even, then saturated; so
  /// error_ulp <= 0.5 everywhere. sqrt, hypot, and the core operations *, / and lerp.
  correctly_rounded,
  /// error_ulp < 1 where |v| < 2^16; relative error < 2^-46 where |v| >= 2^16 (where an ulp is
  /// below 2^-48 of the value, so that bound is still within a few ulp). Everything else.
  faithful,
};

/// Beyond the Fixed range (v > Fixed::max() or v < Fixed::min()) every function must saturate to
/// the nearer extreme. A faithful function may instead return a value within relative error
/// 2^-46 of v: that only matters within 2^-46 of the threshold, where the result may land on
/// either side of it.
inline constexpr int large_threshold_log2 = 16;  ///< |v| >= 2^16: the relative bound applies
inline constexpr int relative_bound_log2 = -46;  ///< faithful: relative error < 2^-46 there

/// A function under test, as the table and the command line name it.
struct FunctionSpec {
  std::string_view name;                         ///< "sin", "atan2", "mul", ...
  std::string_view signature;                    ///< "sin(x)", "atan2(y, x)", "a * b", ...
  int arity = 1;                                 ///< number of Fixed arguments (1..3)
  std::array<std::string_view, 3> parameters{};  ///< their names, in call order
  Contract contract = Contract::faithful;
  std::string_view inputs;  ///< how the random inputs are drawn, one sentence
};

/// Every function measured, in table order.
[[nodiscard]] std::span<const FunctionSpec> functions() noexcept;

/// The function called `name`, or nullptr.
[[nodiscard]] const FunctionSpec* find_function(std::string_view name) noexcept;

/// The contract in a few words: "<= 0.5 ulp, ties to even" or "< 1 ulp, rel < 2^-46".
[[nodiscard]] std::string_view describe(Contract contract) noexcept;

/// One evaluated input: what was computed, against what.
struct Case {
  std::array<Fixed, 3> args{};
  std::string_view component;  ///< "sin" or "cos" for sincos, empty otherwise
  Fixed result;
  std::string exact;     ///< v in decimal, or the documented value for a domain input
  bool measured = true;  ///< false for documented values and the sincos identity (no error)
  double error_ulp = 0;  ///< |result - v| * 2^32
  double relative = 0;   ///< |result - v| / |v| (0 when both are 0)
  std::string why;       ///< for a failure: the rule it broke
};

/// Everything measured for one function.
struct Report {
  const FunctionSpec* function = nullptr;
  std::uint64_t seed = 0;
  std::uint64_t random_inputs = 0;  ///< seeded pseudo-random inputs
  std::uint64_t edge_inputs = 0;    ///< listed edge inputs (zeros, extremes, thresholds, ...)
  /// A hash of every input in order (FNV-1a over the raw bits): equal digests mean the same inputs.
  std::uint64_t input_digest = 0;

  // Result checks by kind (sincos checks two results per input).
  std::uint64_t small_checks = 0;      ///< |v| < 2^16
  std::uint64_t large_checks = 0;      ///< 2^16 <= |v| <= the Fixed range
  std::uint64_t saturated_checks = 0;  ///< v beyond the Fixed range
  std::uint64_t domain_checks = 0;     ///< documented values (log(0), sqrt(-1), x / 0, ...)
  std::uint64_t ties = 0;              ///< correctly rounded: v exactly halfway between two values
  std::uint64_t identity_checks = 0;   ///< sincos: sin^2 + cos^2 <= 1

  /// Worst error in ulp where the ulp bound applies: |v| < 2^16 for faithful functions, the whole
  /// Fixed range for correctly rounded ones.
  double worst_ulp = 0;
  std::optional<Case> worst_ulp_case;
  /// Worst relative error where |v| >= 2^16 (within the Fixed range); 0 if exact or none.
  double worst_relative = 0;
  std::optional<Case> worst_relative_case;

  std::uint64_t failures = 0;
  std::vector<Case> first_failures;  ///< the first few, in the order found

  [[nodiscard]] std::uint64_t inputs() const noexcept { return random_inputs + edge_inputs; }
  [[nodiscard]] bool passed() const noexcept { return failures == 0; }
};

inline constexpr std::uint64_t default_samples = 1'000'000;
inline constexpr std::uint64_t default_seed = 0x6465'7473'696d'2121;  // "detsim!!"

struct Options {
  /// Random inputs per function (edge inputs come on top). Half are uniform over the function's
  /// domain, half log-uniform in magnitude.
  std::uint64_t samples = default_samples;
  /// Every function draws from its own stream derived from this seed and its name, so measuring
  /// one function alone gives the same numbers as measuring all.
  std::uint64_t seed = default_seed;
  /// Failures kept in Report::first_failures (all are counted).
  std::size_t failures_kept = 8;
  /// Called now and then with (inputs done, inputs in total).
  std::function<void(std::uint64_t, std::uint64_t)> progress;
};

/// Measures one function. Deterministic: the same options give the same report.
[[nodiscard]] Report measure(const FunctionSpec& function, const Options& options);

/// DETSIM_ACCURACY_SAMPLES if set (a positive decimal integer), else `fallback`. Returns nullopt
/// and fills `error` when the variable is set but not a positive integer.
[[nodiscard]] std::optional<std::uint64_t> samples_from_environment(std::uint64_t fallback,
                                                                    std::string* error);

/// The arguments of a case as "x = 1.5 (raw 0x0000000180000000)", "y = ..., x = ...".
[[nodiscard]] std::string describe_input(const FunctionSpec& function, const Case& c);

/// One line for a case: the call, its result, the exact value, the error and (if any) why it
/// failed. Every Fixed is shown in decimal and raw hex.
[[nodiscard]] std::string describe_case(const FunctionSpec& function, const Case& c);

/// The worst relative error as a power of two ("2^-52.3"), "0" if exact, "-" if no case had
/// |v| >= 2^16.
[[nodiscard]] std::string format_relative(const Report& report);

/// The worst ulp error for a table ("0.5000", "3.1e+09").
[[nodiscard]] std::string format_ulp(double ulp);

}  // namespace detsim::accuracy
