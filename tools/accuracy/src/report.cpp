#include <detsim_accuracy/report.hpp>
#include <detsim_tools/json_text.hpp>

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <vector>

#include <detsim_accuracy/mpfr.hpp>

namespace detsim::accuracy {

namespace {

struct Row {
  std::string function;
  std::string inputs;
  std::string ulp;
  std::string relative;
  std::string contract;
  std::string result;
  std::string worst_input;
};

const Case* worst_case(const Report& r) {
  if (r.worst_ulp_case) return &*r.worst_ulp_case;
  if (r.worst_relative_case) return &*r.worst_relative_case;
  return nullptr;
}

Row make_row(const Report& r) {
  const FunctionSpec& f = *r.function;
  Row row;
  row.function = std::string(f.name);
  row.inputs = std::to_string(r.inputs());
  row.ulp = r.worst_ulp_case ? format_ulp(r.worst_ulp) : "-";
  row.relative = format_relative(r);
  row.contract = std::string(describe(f.contract));
  row.result = r.passed() ? "pass" : "FAIL (" + std::to_string(r.failures) + ")";
  if (const Case* c = worst_case(r)) {
    row.worst_input = describe_input(f, *c);
    if (!c->component.empty()) row.worst_input += " [" + std::string(c->component) + "]";
  }
  return row;
}

const Row header{"function", "inputs", "worst ulp",  "worst rel",
                 "contract", "result", "worst input"};

std::string seed_text(std::uint64_t seed) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "0x%016" PRIx64, seed);
  return buffer;
}

std::string preamble(std::span<const Report> reports, const Options& options) {
  return "Accuracy of " + std::to_string(reports.size()) + " fixed-point functions against MPFR (" +
         std::to_string(reference_precision) +
         "-bit reference): " + std::to_string(options.samples) +
         " random inputs each plus edge inputs, seed " + seed_text(options.seed) + ".\n";
}

constexpr const char* legend =
    "ulp = 2^-32, the spacing of Q32.32 values. worst ulp: largest |result - exact| * 2^32 where\n"
    "|exact| < 2^16 (everywhere in range for the correctly rounded functions); worst rel: largest\n"
    "|result - exact| / |exact| where |exact| >= 2^16 ('-' if no input got there).\n";

std::size_t passed_count(std::span<const Report> reports) {
  return static_cast<std::size_t>(
      std::count_if(reports.begin(), reports.end(), [](const Report& r) { return r.passed(); }));
}

std::string summary(std::span<const Report> reports) {
  return std::to_string(passed_count(reports)) + " of " + std::to_string(reports.size()) +
         " functions meet their contract.\n";
}

// ---- JSON --------------------------------------------------------------------------------------

std::string json_string(std::string_view s) {
  return tools::json_quote(s);
}

std::string json_number(double v) {
  if (!std::isfinite(v)) return "null";
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.17g", v);
  return buffer;
}

std::string json_fixed(Fixed x) {
  Mp value;
  set_fixed(value.get(), x);
  char raw[32];
  std::snprintf(raw, sizeof raw, "0x%016" PRIx64, static_cast<std::uint64_t>(x.raw()));
  return "{\"decimal\": " + json_string(to_decimal(value.get(), 20)) +
         ", \"raw\": " + json_string(raw) + "}";
}

std::string json_case(const FunctionSpec& f, const Case& c) {
  std::string out = "{\"args\": {";
  for (int i = 0; i < f.arity; ++i) {
    const auto index = static_cast<std::size_t>(i);
    if (i > 0) out += ", ";
    out += json_string(f.parameters[index]) + ": " + json_fixed(c.args[index]);
  }
  out += "}, \"component\": " + json_string(c.component) + ", \"result\": " + json_fixed(c.result) +
         ", \"exact\": " + json_string(c.exact);
  if (c.measured) {
    out += ", \"error_ulp\": " + json_number(c.error_ulp) +
           ", \"relative\": " + json_number(c.relative);
  }
  if (!c.why.empty()) out += ", \"why\": " + json_string(c.why);
  return out + ", \"text\": " + json_string(describe_case(f, c)) + "}";
}

std::string json_report(const Report& r) {
  const FunctionSpec& f = *r.function;
  std::string out =
      "{\"name\": " + json_string(f.name) + ", \"signature\": " + json_string(f.signature) +
      ", \"contract\": " +
      json_string(f.contract == Contract::correctly_rounded ? "correctly_rounded" : "faithful") +
      ", \"contract_text\": " + json_string(describe(f.contract)) +
      ", \"passed\": " + (r.passed() ? "true" : "false") +
      ", \"inputs\": " + std::to_string(r.inputs()) +
      ", \"random_inputs\": " + std::to_string(r.random_inputs) +
      ", \"edge_inputs\": " + std::to_string(r.edge_inputs) +
      ", \"input_distribution\": " + json_string(f.inputs) +
      ", \"input_digest\": " + json_string(seed_text(r.input_digest));
  out += ", \"checks\": {\"small\": " + std::to_string(r.small_checks) +
         ", \"large\": " + std::to_string(r.large_checks) +
         ", \"saturated\": " + std::to_string(r.saturated_checks) +
         ", \"domain\": " + std::to_string(r.domain_checks) +
         ", \"ties\": " + std::to_string(r.ties) +
         ", \"identity\": " + std::to_string(r.identity_checks) + "}";
  out += ", \"worst_ulp\": " + (r.worst_ulp_case ? json_number(r.worst_ulp) : "null");
  out += ", \"worst_ulp_case\": " + (r.worst_ulp_case ? json_case(f, *r.worst_ulp_case) : "null");
  out +=
      ", \"worst_relative\": " + (r.worst_relative_case ? json_number(r.worst_relative) : "null");
  out += ", \"worst_relative_log2\": " + (r.worst_relative_case && r.worst_relative > 0
                                              ? json_number(std::log2(r.worst_relative))
                                              : "null");
  out += ", \"worst_relative_case\": " +
         (r.worst_relative_case ? json_case(f, *r.worst_relative_case) : "null");
  out += ", \"failures\": " + std::to_string(r.failures) + ", \"first_failures\": [";
  for (std::size_t i = 0; i < r.first_failures.size(); ++i) {
    if (i > 0) out += ", ";
    out += json_case(f, r.first_failures[i]);
  }
  return out + "]}";
}

}  // namespace

std::string format_table(std::span<const Report> reports, const Options& options) {
  std::vector<Row> rows{header};
  for (const Report& r : reports)
    rows.push_back(make_row(r));
  std::array<std::size_t, 6> width{};
  for (const Row& row : rows) {
    const std::array<const std::string*, 6> cells = {&row.function, &row.inputs,   &row.ulp,
                                                     &row.relative, &row.contract, &row.result};
    for (std::size_t i = 0; i < cells.size(); ++i)
      width[i] = std::max(width[i], cells[i]->size());
  }
  std::string out = preamble(reports, options) + legend + "\n";
  for (const Row& row : rows) {
    const auto pad = [&](const std::string& s, std::size_t w, bool right) {
      const std::string fill(w - s.size(), ' ');
      out += right ? fill + s : s + fill;
      out += "  ";
    };
    pad(row.function, width[0], false);
    pad(row.inputs, width[1], true);
    pad(row.ulp, width[2], true);
    pad(row.relative, width[3], true);
    pad(row.contract, width[4], false);
    pad(row.result, width[5], false);
    out += row.worst_input + "\n";
  }
  for (const Report& r : reports) {
    if (r.passed()) continue;
    out += "\n" + std::string(r.function->name) + ": " + std::to_string(r.failures) +
           " failures; the first " + std::to_string(r.first_failures.size()) + ":\n";
    for (const Case& c : r.first_failures)
      out += "  " + describe_case(*r.function, c) + "\n";
  }
  return out + "\n" + summary(reports);
}

std::string format_markdown(std::span<const Report> reports, const Options& options) {
  std::string out = preamble(reports, options) + "\n";
  out += "| function | inputs | worst ulp | worst rel | contract | result | worst input |\n";
  out += "|---|--:|--:|--:|---|---|---|\n";
  for (const Report& r : reports) {
    const Row row = make_row(r);
    out += "| `" + row.function + "` | " + row.inputs + " | " + row.ulp + " | " + row.relative +
           " | " + row.contract + " | " + (r.passed() ? "pass" : "**" + row.result + "**") + " | " +
           row.worst_input + " |\n";
  }
  return out + "\n" + summary(reports);
}

std::string format_json(std::span<const Report> reports, const Options& options) {
  std::string out = "{\"reference_bits\": " + std::to_string(reference_precision) +
                    ", \"samples\": " + std::to_string(options.samples) +
                    ", \"seed\": " + json_string(seed_text(options.seed)) + ", \"passed\": " +
                    (passed_count(reports) == reports.size() ? "true" : "false") +
                    ", \"functions\": [";
  for (std::size_t i = 0; i < reports.size(); ++i) {
    out += i > 0 ? ",\n  " : "\n  ";
    out += json_report(reports[i]);
  }
  return out + "\n]}\n";
}

}  // namespace detsim::accuracy
