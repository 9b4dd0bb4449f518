// The accuracy table in the three forms `detsim accuracy` prints: plain text for a terminal,
// Markdown for docs/ACCURACY.md, JSON for scripts.
#pragma once

#include <span>
#include <string>

#include <detsim_accuracy/accuracy.hpp>

namespace detsim::accuracy {

/// Aligned columns: function, inputs, worst ulp, worst relative error, contract, pass/fail, worst
/// input; then the first failures of every failing function.
[[nodiscard]] std::string format_table(std::span<const Report> reports, const Options& options);

/// The same table as GitHub Markdown, with a line naming the sample count and seed.
[[nodiscard]] std::string format_markdown(std::span<const Report> reports, const Options& options);

/// One JSON object: {"samples": N, "seed": S, "reference_bits": B, "passed": bool,
/// "functions": [{...}, ...]}. Non-finite numbers are written as null.
[[nodiscard]] std::string format_json(std::span<const Report> reports, const Options& options);

}  // namespace detsim::accuracy
