// `detsim accuracy`: every fixed-point function measured against MPFR. Only the stock detsim
// binary has it (detsim_main.cpp): MPFR is a test reference, not something a game's tool built on
// detsim::cli::run_cli should link.
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <detsim/detsim.hpp>

#include "cli_app.hpp"
#include "output.hpp"

#if DETSIM_WITH_ACCURACY
#include <detsim_accuracy/accuracy.hpp>
#include <detsim_accuracy/report.hpp>
#endif

#if __has_include(<unistd.h>)
#include <unistd.h>
#define DETSIM_HAVE_ISATTY 1
#else
#define DETSIM_HAVE_ISATTY 0
#endif

namespace {

[[maybe_unused]] constexpr int exit_usage = detsim::cli::exit_usage;  // without MPFR

// ---- detsim accuracy ---------------------------------------------------------------------------

struct AccuracyArgs {
  std::uint64_t samples = 1'000'000;
  std::uint64_t seed = 0;
  std::vector<std::string> functions;
  bool json = false;
  bool markdown = false;
};

constexpr const char* accuracy_footer = R"(
What is measured
  Each function is run on N seeded random inputs (half uniform over its domain, half log-uniform
  in magnitude) plus a fixed list of edge inputs (0, +-1 ulp, +-1, domain ends, min, max,
  multiples of pi/2, poles, saturation and underflow thresholds, exact ties, ...). Every result is
  compared with the exact value computed by MPFR at 160 bits from the exact inputs.

  ulp: "unit in the last place", here 2^-32 (about 2.3e-10), the spacing between two adjacent
  Q32.32 values. The error of a result in ulp is |result - exact| * 2^32. The relative error is
  |result - exact| / |exact|.

Contract (what "pass" means, from <detsim/fixed/math.hpp>)
  sqrt, hypot, mul (*), div (/), lerp: correctly rounded - the nearest Q32.32 value, ties to even,
    so <= 0.5 ulp.
  all others: faithful - error < 1 ulp where |exact| < 2^16, relative error < 2^-46 where
    |exact| >= 2^16 (exp, exp2, pow, tan near its poles, rsqrt near 0).
  Exact values beyond the Fixed range must give Fixed::max() / Fixed::min(); inputs outside a
  function's domain (log of x <= 0, sqrt of x < 0, x / 0, ...) must give their documented value.

Exit status: 0 every function meets its contract, 1 at least one does not, 2 bad usage.
docs/ACCURACY.md explains the method and holds the current table.)";

#if DETSIM_WITH_ACCURACY

bool stderr_is_terminal() {
#if DETSIM_HAVE_ISATTY
  return isatty(STDERR_FILENO) != 0;
#else
  return false;
#endif
}

int run_accuracy(const AccuracyArgs& args) {
  namespace acc = detsim::accuracy;
  std::vector<const acc::FunctionSpec*> selected;
  if (args.functions.empty()) {
    for (const acc::FunctionSpec& f : acc::functions())
      selected.push_back(&f);
  } else {
    for (const std::string& name : args.functions) {
      const acc::FunctionSpec* f = acc::find_function(name);
      bool seen = false;
      for (const acc::FunctionSpec* s : selected)
        seen = seen || s == f;
      if (f != nullptr && !seen) selected.push_back(f);
    }
  }

  acc::Options options;
  options.samples = args.samples;
  options.seed = args.seed;
  const bool progress = stderr_is_terminal();
  std::vector<acc::Report> reports;
  for (std::size_t i = 0; i < selected.size(); ++i) {
    const acc::FunctionSpec& f = *selected[i];
    if (progress) {
      options.progress = [&](std::uint64_t done, std::uint64_t total) {
        std::fprintf(
            stderr, "\r[%zu/%zu] %-8s %3d%%", i + 1, selected.size(), std::string(f.name).c_str(),
            static_cast<int>(100.0 * static_cast<double>(done) / static_cast<double>(total)));
        std::fflush(stderr);
      };
    }
    reports.push_back(acc::measure(f, options));
  }
  if (progress) std::fputs("\r\033[K", stderr);

  const std::string text = args.json       ? acc::format_json(reports, options)
                           : args.markdown ? acc::format_markdown(reports, options)
                                           : acc::format_table(reports, options);
  std::fputs(text.c_str(), stdout);
  for (const acc::Report& r : reports) {
    if (!r.passed()) return 1;
  }
  return 0;
}

std::string known_functions() {
  std::string out;
  for (const detsim::accuracy::FunctionSpec& f : detsim::accuracy::functions()) {
    if (!out.empty()) out += ", ";
    out += f.name;
  }
  return out;
}

#endif

void add_accuracy(CLI::App& app, AccuracyArgs& args, int& exit_code) {
  auto* cmd = app.add_subcommand(
      "accuracy", "Measure every fixed-point function against MPFR and print the accuracy table");
  cmd->footer(accuracy_footer);
#if DETSIM_WITH_ACCURACY
  args.samples = detsim::accuracy::default_samples;
  args.seed = detsim::accuracy::default_seed;
  const CLI::Validator positive(
      [](std::string& text) -> std::string {
        std::uint64_t value = 0;
        const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
        if (ec != std::errc{} || end != text.data() + text.size() || value == 0) {
          return "must be a positive integer (random inputs per function), got '" + text + "'";
        }
        return {};
      },
      "", "positive");
  const CLI::Validator function_name(
      [](std::string& name) -> std::string {
        if (detsim::accuracy::find_function(name) != nullptr) return {};
        return "unknown function '" + name + "'; known: " + known_functions();
      },
      "", "function");
  cmd->add_option("--samples", args.samples,
                  "Random inputs per function (default 1000000); edge inputs come on top")
      ->type_name("N")
      ->check(positive);
  cmd->add_option("--function", args.functions,
                  "Measure only this function (repeatable). One of: " + known_functions())
      ->type_name("NAME")
      ->check(function_name);
  cmd->add_option("--seed", args.seed, "Seed of the random inputs (default fixed: reproducible)")
      ->type_name("S");
  auto* json = cmd->add_flag("--json", args.json, "Print one JSON object instead of the table");
  auto* markdown =
      cmd->add_flag("--markdown", args.markdown, "Print the table as Markdown (docs/ACCURACY.md)");
  json->excludes(markdown);
  cmd->callback([&args, &exit_code] { exit_code = run_accuracy(args); });
#else
  (void)args;
  cmd->allow_extras();
  cmd->callback([&exit_code] {
    std::fputs("detsim accuracy: this detsim was built without MPFR (Debian: libmpfr-dev)\n",
               stderr);
    exit_code = exit_usage;
  });
#endif
}

}  // namespace

namespace detsim::cli::detail {

void add_accuracy_command(CLI::App& app, int& exit_code) {
  static AccuracyArgs args;  // the parsed options live as long as the command line
  add_accuracy(app, args, exit_code);
}

}  // namespace detsim::cli::detail
