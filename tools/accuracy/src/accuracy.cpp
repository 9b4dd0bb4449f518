// The measurement loop: every edge input, then the seeded random inputs, each checked against
// its MPFR reference (or its documented value) with the same Checker.
#include <detsim_accuracy/accuracy.hpp>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <detsim/fixed/wide.hpp>
#include <detsim_accuracy/check.hpp>
#include "catalog.hpp"

namespace detsim::accuracy {

namespace {

const detail::Entry* entry_of(const FunctionSpec& function) {
  for (const detail::Entry& e : detail::entries()) {
    if (e.spec.name == function.name) return &e;
  }
  return nullptr;
}

/// sin^2 + cos^2 <= 1 in exact arithmetic: raw_s^2 + raw_c^2 <= 2^64. Each square is below
/// 2^126, so the 128-bit sum cannot wrap.
bool within_unit_circle(Fixed s, Fixed c) {
  const std::uint64_t ms = detsim::detail::magnitude(s.raw());
  const std::uint64_t mc = detsim::detail::magnitude(c.raw());
  const wide::U128 sum = wide::add(wide::Default::mul(ms, ms), wide::Default::mul(mc, mc));
  return sum.hi == 0 || (sum.hi == 1 && sum.lo == 0);
}

/// Evaluates inputs for one function and accumulates its report. Owns every MPFR object the
/// evaluation needs, so the per-input path never allocates (except to record a new worst case
/// or a failure).
class Run {
 public:
  Run(const detail::Entry& entry, const Options& options, Report& report)
      : entry_(entry), options_(options), report_(report) {
    for (std::size_t i = 0; i < in_.size(); ++i)
      in_ptrs_[i] = in_[i].get();
    for (std::size_t i = 0; i < out_.size(); ++i)
      out_ptrs_[i] = out_[i].get();
  }

  void evaluate(const detail::Args& args) {
    for (int i = 0; i < entry_.spec.arity; ++i) {
      const auto bits = static_cast<std::uint64_t>(args[static_cast<std::size_t>(i)].raw());
      for (int byte = 0; byte < 8; ++byte) {
        digest_ = (digest_ ^ ((bits >> (8 * byte)) & 0xFFU)) * 0x100000001B3U;
      }
    }
    report_.input_digest = digest_;
    Fixed results[2];
    entry_.compute(args, results);
    if (entry_.documented != nullptr) {
      Fixed value;
      const char* rule = "";
      if (entry_.documented(args, &value, &rule)) {
        ++report_.domain_checks;
        if (results[0] != value && keep_failure()) {
          Case c = make_case(args, 0, results[0]);
          c.exact = describe_fixed(value) + ", documented: " + rule;
          c.measured = false;
          c.why = "not the documented value";
          report_.first_failures.push_back(std::move(c));
        }
        return;
      }
    }
    for (int i = 0; i < entry_.spec.arity; ++i) {
      const auto index = static_cast<std::size_t>(i);
      set_fixed(in_ptrs_[index], args[index]);
    }
    entry_.reference(in_ptrs_.data(), out_ptrs_.data(), scratch_);
    for (int r = 0; r < entry_.results; ++r)
      check_result(args, r, results[r]);
    if (entry_.results == 2) {
      ++report_.identity_checks;
      if (!within_unit_circle(results[0], results[1]) && keep_failure()) {
        Case c = make_case(args, 0, results[0]);
        c.component = "";
        c.exact = "sin = " + describe_fixed(results[0]) + ", cos = " + describe_fixed(results[1]);
        c.measured = false;
        c.why = "sin^2 + cos^2 > 1";
        report_.first_failures.push_back(std::move(c));
      }
    }
  }

 private:
  Case make_case(const detail::Args& args, int result_index, Fixed result) const {
    Case c;
    c.args = args;
    c.component = entry_.result_names[static_cast<std::size_t>(result_index)];
    c.result = result;
    return c;
  }

  void check_result(const detail::Args& args, int r, Fixed result) {
    mpfr_srcptr exact = out_ptrs_[static_cast<std::size_t>(r)];
    if (mpfr_nan_p(exact) != 0) {
      if (keep_failure()) {
        Case c = make_case(args, r, result);
        c.exact = "NaN";
        c.measured = false;
        c.why = "the reference is NaN: an input outside the domain without a documented value";
        report_.first_failures.push_back(std::move(c));
      }
      return;
    }
    const Contract contract = entry_.spec.contract;
    const Verdict v = checker_.check(contract, result, exact);
    switch (v.region) {
      case Region::small:
        ++report_.small_checks;
        break;
      case Region::large:
        ++report_.large_checks;
        break;
      case Region::beyond:
        ++report_.saturated_checks;
        break;
    }
    if (v.tie) ++report_.ties;

    const bool ulp_applies = contract == Contract::correctly_rounded ? v.region != Region::beyond
                                                                     : v.region == Region::small;
    if (ulp_applies && (!report_.worst_ulp_case || v.error_ulp > report_.worst_ulp)) {
      report_.worst_ulp = v.error_ulp;
      report_.worst_ulp_case = full_case(args, r, result, exact, v);
    }
    if (v.region == Region::large &&
        (!report_.worst_relative_case || v.relative > report_.worst_relative)) {
      report_.worst_relative = v.relative;
      report_.worst_relative_case = full_case(args, r, result, exact, v);
    }
    if (!v.pass && keep_failure()) {
      Case c = full_case(args, r, result, exact, v);
      c.why = v.why;
      if (contract == Contract::correctly_rounded) {
        c.why += "; the correctly rounded result is " + describe_fixed(v.expected);
      }
      report_.first_failures.push_back(std::move(c));
    }
  }

  Case full_case(const detail::Args& args, int r, Fixed result, mpfr_srcptr exact,
                 const Verdict& v) const {
    Case c = make_case(args, r, result);
    c.exact = to_decimal(exact);
    c.error_ulp = v.error_ulp;
    c.relative = v.relative;
    return c;
  }

  /// Counts a failure; true if it is among the first few, whose description is kept (the
  /// others are only counted: describing costs more than checking).
  bool keep_failure() {
    ++report_.failures;
    return report_.first_failures.size() < options_.failures_kept;
  }

  const detail::Entry& entry_;
  const Options& options_;
  Report& report_;
  std::array<Mp, 3> in_;
  std::array<Mp, 2> out_;
  std::array<mpfr_ptr, 3> in_ptrs_{};
  std::array<mpfr_ptr, 2> out_ptrs_{};
  detail::Scratch scratch_;
  Checker checker_;
  std::uint64_t digest_ = 0xCBF29CE484222325U;
};

}  // namespace

std::span<const FunctionSpec> functions() noexcept {
  static const std::vector<FunctionSpec> specs = [] {
    std::vector<FunctionSpec> out;
    for (const detail::Entry& e : detail::entries())
      out.push_back(e.spec);
    return out;
  }();
  return specs;
}

const FunctionSpec* find_function(std::string_view name) noexcept {
  for (const FunctionSpec& f : functions()) {
    if (f.name == name) return &f;
  }
  return nullptr;
}

std::string_view describe(Contract contract) noexcept {
  return contract == Contract::correctly_rounded ? "<= 0.5 ulp, ties to even"
                                                 : "< 1 ulp, rel < 2^-46";
}

Report measure(const FunctionSpec& function, const Options& options) {
  use_widest_exponent_range();
  Report report;
  report.function = find_function(function.name);
  const detail::Entry* entry = entry_of(function);
  if (entry == nullptr || report.function == nullptr) return report;

  detail::ArgsList edges;
  entry->edges(edges);
  report.edge_inputs = edges.size();
  report.random_inputs = options.samples;
  report.seed = options.seed;
  const std::uint64_t total = report.inputs();
  constexpr std::uint64_t progress_every = 1U << 16;

  Run run(*entry, options, report);
  std::uint64_t done = 0;
  const auto tick = [&] {
    ++done;
    if (options.progress && done % progress_every == 0) options.progress(done, total);
  };
  for (const detail::Args& args : edges) {
    run.evaluate(args);
    tick();
  }
  // Alternate the two distributions so any prefix of the stream is balanced.
  detail::Rng rng(detail::stream_seed(options.seed, function.name));
  detail::Args args{};
  for (std::uint64_t i = 0; i < options.samples; ++i) {
    entry->sample(rng, (i & 1U) != 0, args);
    run.evaluate(args);
    tick();
  }
  if (options.progress) options.progress(total, total);
  return report;
}

std::optional<std::uint64_t> samples_from_environment(std::uint64_t fallback, std::string* error) {
  const char* text = std::getenv("DETSIM_ACCURACY_SAMPLES");
  if (text == nullptr || *text == '\0') return fallback;
  const std::string_view s(text);
  std::uint64_t value = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (ec != std::errc{} || end != s.data() + s.size() || value == 0) {
    if (error != nullptr) {
      *error = "DETSIM_ACCURACY_SAMPLES must be a positive integer, got '" + std::string(s) + "'";
    }
    return std::nullopt;
  }
  return value;
}

std::string describe_input(const FunctionSpec& function, const Case& c) {
  std::string out;
  for (int i = 0; i < function.arity; ++i) {
    const auto index = static_cast<std::size_t>(i);
    if (i > 0) out += ", ";
    out += std::string(function.parameters[index]) + " = " + describe_fixed(c.args[index]);
  }
  return out;
}

std::string describe_case(const FunctionSpec& function, const Case& c) {
  std::string out(function.signature);
  if (!c.component.empty()) out.append(".").append(c.component);
  out.append(" at ").append(describe_input(function, c));
  out.append(": got ").append(describe_fixed(c.result)).append(", exact ").append(c.exact);
  if (c.measured) {
    char buffer[96];
    std::snprintf(buffer, sizeof buffer, "; error %.12g ulp, relative %.3g", c.error_ulp,
                  c.relative);
    out += buffer;
  }
  if (!c.why.empty()) out += "; FAILS: " + c.why;
  return out;
}

std::string format_ulp(double ulp) {
  char buffer[32];
  if (ulp < 1000) {
    // Truncated, not rounded, so that an error just below a bound (0.99999999998 ulp against
    // "< 1") never prints as the bound itself.
    const auto ten_thousandths = static_cast<long long>(std::floor(ulp * 10000.0));
    std::snprintf(buffer, sizeof buffer, "%lld.%04lld", ten_thousandths / 10000,
                  ten_thousandths % 10000);
  } else {
    std::snprintf(buffer, sizeof buffer, "%.3g", ulp);
  }
  return buffer;
}

std::string format_relative(const Report& report) {
  if (!report.worst_relative_case) return "-";
  if (report.worst_relative == 0) return "0";
  if (!std::isfinite(report.worst_relative)) return "inf";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "2^%.1f", std::log2(report.worst_relative));
  return buffer;
}

}  // namespace detsim::accuracy
