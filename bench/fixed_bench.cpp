// Throughput of detsim::Fixed against glibc double and libfixmath (Q16.16), measured in the same
// run on the same inputs: mul, div, sqrt, sin, cos, atan2, exp, log.
//
// Method (docs/BENCHMARKS.md repeats it for readers of the figures):
// - Each function has one seeded pool of inputs inside a domain all three types can represent.
//   Every value is rounded to a multiple of 2^-16 first, so the double, the Q32.32 and the Q16.16
//   inputs are the SAME real numbers, converted exactly.
// - One benchmark iteration computes out[i] = f(in[i]) over a block of 4096 inputs; the output is
//   escaped (DoNotOptimize + ClobberMemory) so no call can be dropped or hoisted. Items/s counts
//   calls.
// - libfixmath memoises sin (and so cos), atan2 and exp (which its log calls) in 4096-entry
//   direct-mapped caches. Re-running one 4096-input block would time many cache hits (about a third
//   for sin), which a simulation (whose inputs rarely repeat exactly) does not see. So those
//   functions cycle through 16 blocks (65536 distinct inputs) for all three types: a value's cache
//   slot has been overwritten about 16 times before it comes back. "<fn>/libfixmath_repeat" re-runs
//   one block to show what the memo caches are worth. mul, div and sqrt have no cache and use one
//   block, which stays in L1/L2.
// - A counter "max_abs_err" (the largest |result - glibc double result| over the inputs used) is a
//   sanity check that the benchmark computes what it claims; it is not an accuracy measurement.
// Bench code is not simulation code: double is used freely here.

#include <benchmark/benchmark.h>
#include <libfixmath/fixmath.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <bench_config.hpp>
#include <detsim/detsim.hpp>
#include <detsim/fixed/math.hpp>

namespace {

using detsim::Fixed;

constexpr std::size_t kBlock = 4096;
constexpr std::size_t kMemoDefeatingBlocks = 16;
constexpr double kPi = 3.14159265358979323846;

// ---- Inputs -------------------------------------------------------------------------------------

/// Rounds to the nearest multiple of 2^-16, the coarsest grid of the three types.
double quantise(double v) {
  return std::nearbyint(v * 65536.0) / 65536.0;
}

/// Deterministic samples: mt19937_64's sequence is fixed by the standard, and the mapping to [0, 1)
/// is ours (std::uniform_real_distribution's algorithm is implementation-defined).
class Sampler {
 public:
  explicit Sampler(std::uint64_t seed) : engine_(seed) {}

  double unit() { return static_cast<double>(engine_() >> 11) * 0x1p-53; }
  double uniform(double lo, double hi) { return quantise(lo + (hi - lo) * unit()); }
  double log_uniform(double lo, double hi) {
    return quantise(std::exp(std::log(lo) + (std::log(hi) - std::log(lo)) * unit()));
  }
  bool coin() { return (engine_() >> 63) != 0; }

 private:
  std::mt19937_64 engine_;
};

/// One function's inputs, shared by all implementations, and glibc's double results on them.
struct Case {
  std::string name;
  std::string domain;
  std::size_t blocks = 1;
  std::vector<double> a;
  std::vector<double> b;  // empty for unary functions
  std::vector<double> expected;
};

template <class Generate, class Reference>
std::shared_ptr<const Case> make_case(std::string name, std::string domain, std::size_t blocks,
                                      std::uint64_t seed, Generate generate, Reference reference) {
  auto c = std::make_shared<Case>();
  c->name = std::move(name);
  c->domain = std::move(domain);
  c->blocks = blocks;
  Sampler sampler(seed);
  const std::size_t n = blocks * kBlock;
  for (std::size_t i = 0; i < n; ++i)
    generate(sampler, *c);
  c->expected.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    if constexpr (std::is_invocable_v<Reference, double>) {
      c->expected[i] = reference(c->a[i]);
    } else {
      c->expected[i] = reference(c->a[i], c->b[i]);
    }
  }
  return c;
}

// ---- The three representations ------------------------------------------------------------------

template <class T>
struct Repr;

template <>
struct Repr<double> {
  static double from(double v) { return v; }
  static double to(double v) { return v; }
};

template <>
struct Repr<Fixed> {
  // Exact: inputs are multiples of 2^-16 with magnitude below 2^31.
  static Fixed from(double v) { return Fixed::from_raw(static_cast<std::int64_t>(v * 0x1p32)); }
  static double to(Fixed v) { return v.to_double(); }
};

template <>
struct Repr<fix16_t> {
  // Exact: inputs are multiples of 2^-16 with magnitude below 2^15.
  static fix16_t from(double v) { return static_cast<fix16_t>(v * 0x1p16); }
  static double to(fix16_t v) { return static_cast<double>(v) * 0x1p-16; }
};

template <class T>
std::vector<T> convert(const std::vector<double>& values) {
  std::vector<T> out;
  out.reserve(values.size());
  for (const double v : values)
    out.push_back(Repr<T>::from(v));
  return out;
}

// ---- The measured loop --------------------------------------------------------------------------

template <class T, class Op>
T apply(Op& op, const std::vector<T>& a, const std::vector<T>& b, std::size_t i) {
  if constexpr (std::is_invocable_v<Op&, T>) {
    static_cast<void>(b);
    return op(a[i]);
  } else {
    return op(a[i], b[i]);
  }
}

/// Registers "<case>/<impl>": out[i] = op(in[i]) over `blocks` blocks of the case's inputs, one
/// block per iteration.
template <class T, class Op>
void add(const std::shared_ptr<const Case>& c, const std::string& impl, std::size_t blocks, Op op) {
  const std::string name = c->name + "/" + impl;
  benchmark::RegisterBenchmark(name.c_str(), [c, blocks, op](benchmark::State& state) mutable {
    const std::vector<T> a = convert<T>(c->a);
    const std::vector<T> b = convert<T>(c->b);
    std::vector<T> out(kBlock);
    std::size_t block = 0;
    for (auto _ : state) {
      const std::size_t base = block * kBlock;
      T* dst = out.data();
      if constexpr (std::is_invocable_v<Op&, T>) {
        const T* in = a.data() + base;
        for (std::size_t i = 0; i < kBlock; ++i)
          dst[i] = op(in[i]);
      } else {
        const T* in_a = a.data() + base;
        const T* in_b = b.data() + base;
        for (std::size_t i = 0; i < kBlock; ++i)
          dst[i] = op(in_a[i], in_b[i]);
      }
      benchmark::DoNotOptimize(dst);
      benchmark::ClobberMemory();
      block = block + 1 == blocks ? 0 : block + 1;
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) *
                            static_cast<std::int64_t>(kBlock));

    // Sanity, outside the timed loop: how far the results are from glibc's on the inputs used.
    double max_err = 0.0;
    for (std::size_t i = 0; i < blocks * kBlock; ++i) {
      const double err = std::fabs(Repr<T>::to(apply(op, a, b, i)) - c->expected[i]);
      if (!(err <= max_err)) max_err = err;  // also catches NaN
    }
    state.counters["max_abs_err"] = benchmark::Counter(max_err);
    state.SetLabel(c->domain);
  });
}

/// double (glibc), detsim Fixed and libfixmath on the same case.
template <class DoubleOp, class FixedOp, class Fix16Op>
void add_all(const std::shared_ptr<const Case>& c, DoubleOp d, FixedOp f, Fix16Op q, bool memo) {
  add<double>(c, "double", c->blocks, d);
  add<Fixed>(c, "detsim", c->blocks, f);
  add<fix16_t>(c, "libfixmath", c->blocks, q);
  if (memo) add<fix16_t>(c, "libfixmath_repeat", 1, q);
}

void register_benchmarks() {
  std::uint64_t seed = 0x5EED'DE75'1A00'0000;
  const auto unary = [](auto draw) {
    return [draw](Sampler& s, Case& c) mutable { c.a.push_back(draw(s)); };
  };

  {
    const auto c = make_case(
        "mul", "a, b uniform in [-100, 100]", 1, ++seed,
        [](Sampler& s, Case& k) {
          k.a.push_back(s.uniform(-100.0, 100.0));
          k.b.push_back(s.uniform(-100.0, 100.0));
        },
        [](double x, double y) { return x * y; });
    add_all(
        c, [](double x, double y) { return x * y; }, [](Fixed x, Fixed y) { return x * y; },
        [](fix16_t x, fix16_t y) { return fix16_mul(x, y); }, false);
  }
  {
    const auto c = make_case(
        "div", "a uniform in [-100, 100], |b| uniform in [0.5, 100], random sign", 1, ++seed,
        [](Sampler& s, Case& k) {
          k.a.push_back(s.uniform(-100.0, 100.0));
          const double magnitude = s.uniform(0.5, 100.0);
          k.b.push_back(s.coin() ? -magnitude : magnitude);
        },
        [](double x, double y) { return x / y; });
    add_all(
        c, [](double x, double y) { return x / y; }, [](Fixed x, Fixed y) { return x / y; },
        [](fix16_t x, fix16_t y) { return fix16_div(x, y); }, false);
  }
  {
    const auto c = make_case("sqrt", "x uniform in [0, 10000]", 1, ++seed,
                             unary([](Sampler& s) { return s.uniform(0.0, 10000.0); }),
                             [](double x) { return std::sqrt(x); });
    add_all(
        c, [](double x) { return std::sqrt(x); }, [](Fixed x) { return detsim::sqrt(x); },
        [](fix16_t x) { return fix16_sqrt(x); }, false);
  }
  {
    const auto c = make_case("sin", "x uniform in [-pi, pi]", kMemoDefeatingBlocks, ++seed,
                             unary([](Sampler& s) { return s.uniform(-kPi, kPi); }),
                             [](double x) { return std::sin(x); });
    add_all(
        c, [](double x) { return std::sin(x); }, [](Fixed x) { return detsim::sin(x); },
        [](fix16_t x) { return fix16_sin(x); }, true);
  }
  {
    const auto c = make_case("cos", "x uniform in [-pi, pi]", kMemoDefeatingBlocks, ++seed,
                             unary([](Sampler& s) { return s.uniform(-kPi, kPi); }),
                             [](double x) { return std::cos(x); });
    add_all(
        c, [](double x) { return std::cos(x); }, [](Fixed x) { return detsim::cos(x); },
        [](fix16_t x) { return fix16_cos(x); }, true);
  }
  {
    const auto c = make_case(
        "atan2", "y, x uniform in [-100, 100]", kMemoDefeatingBlocks, ++seed,
        [](Sampler& s, Case& k) {
          k.a.push_back(s.uniform(-100.0, 100.0));
          k.b.push_back(s.uniform(-100.0, 100.0));
        },
        [](double y, double x) { return std::atan2(y, x); });
    add_all(
        c, [](double y, double x) { return std::atan2(y, x); },
        [](Fixed y, Fixed x) { return detsim::atan2(y, x); },
        [](fix16_t y, fix16_t x) { return fix16_atan2(y, x); }, true);
  }
  {
    // e^10 ~ 22026 still fits Q16.16 (max ~32768).
    const auto c = make_case("exp", "x uniform in [-10, 10]", kMemoDefeatingBlocks, ++seed,
                             unary([](Sampler& s) { return s.uniform(-10.0, 10.0); }),
                             [](double x) { return std::exp(x); });
    add_all(
        c, [](double x) { return std::exp(x); }, [](Fixed x) { return detsim::exp(x); },
        [](fix16_t x) { return fix16_exp(x); }, true);
  }
  {
    const auto c = make_case("log", "x log-uniform in [2^-8, 2^14]", kMemoDefeatingBlocks, ++seed,
                             unary([](Sampler& s) { return s.log_uniform(0x1p-8, 0x1p14); }),
                             [](double x) { return std::log(x); });
    add_all(
        c, [](double x) { return std::log(x); }, [](Fixed x) { return detsim::log(x); },
        [](fix16_t x) { return fix16_log(x); }, true);
  }
  {
    // Beyond Q16.16's range: detsim's exact range reduction over the whole Fixed range. glibc
    // switches to its slow (Payne-Hanek) reduction above about 1e8, so most inputs take it.
    const auto c = make_case(
        "sin_wide",
        "x uniform in [-2^31 + 1, 2^31 - 1] (the Fixed range; not representable in Q16.16)",
        kMemoDefeatingBlocks, ++seed,
        unary([](Sampler& s) { return s.uniform(-2147483647.0, 2147483647.0); }),
        [](double x) { return std::sin(x); });
    add<double>(c, "double", c->blocks, [](double x) { return std::sin(x); });
    add<Fixed>(c, "detsim", c->blocks, [](Fixed x) { return detsim::sin(x); });
  }
}

}  // namespace

int main(int argc, char** argv) {
  register_benchmarks();
  benchmark::AddCustomContext("detsim_compiler", DETSIM_BENCH_COMPILER);
  benchmark::AddCustomContext("detsim_cxx_flags", DETSIM_BENCH_CXX_FLAGS);
  benchmark::AddCustomContext("detsim_build_type", DETSIM_BENCH_BUILD_TYPE);
  benchmark::AddCustomContext("detsim_fixed_bench_flags", DETSIM_FIXED_BENCH_FLAGS);
  benchmark::AddCustomContext("detsim_block_size", std::to_string(kBlock));
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
