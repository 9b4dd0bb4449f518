// Determinism rule 1 (docs/DETERMINISM.md): no binary floating point in anything that reaches
// simulation state. This test reads the sources of the simulation modules and fails on any `float`,
// `double` or `long double` token outside the display conversions (a line that defines or calls
// to_double), and on any include of <cmath> or <math.h>.
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace {

namespace fs = std::filesystem;

struct Finding {
  std::string where;
  std::string line;
};

// Comments are scanned too, so that a reader never has to wonder whether a mention is code.
std::vector<Finding> scan(const std::string& name, std::istream& in) {
  static const std::regex floating(R"(\b(float|double)\b)");
  static const std::regex math_header(R"(#\s*include\s*[<"](cmath|math\.h)[>"])");
  std::vector<Finding> findings;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const bool display_conversion = line.find("to_double") != std::string::npos;
    if ((std::regex_search(line, floating) && !display_conversion) ||
        std::regex_search(line, math_header)) {
      findings.push_back({name + ":" + std::to_string(number), line});
    }
  }
  return findings;
}

TEST(SourceScan, TheScannerFindsWhatItMustAndOnlyThat) {
  std::istringstream bad(
      "int a;\nfloat b;\n  double c = 1;\nlong double d;\n#include <cmath>\n"
      "# include \"math.h\"\n");
  EXPECT_EQ(scan("bad", bad).size(), 5U);
  std::istringstream good(
      "int a;\ndouble to_double() const;\nint doubled = 2;\n"
      "// floating point\nstd::int64_t floaty;\n#include <cstdint>\n");
  EXPECT_TRUE(scan("good", good).empty());
}

TEST(SourceScan, SimulationModulesUseNoFloatingPoint) {
  const fs::path root = DETSIM_SOURCE_DIR;
  std::size_t files = 0;
  std::vector<Finding> findings;
  for (const char* module : {"fixed", "core", "sim", "scenes", "replay", "net", "scenario_net"}) {
    const fs::path dir = root / module;
    if (!fs::exists(dir)) continue;
    for (const auto& entry : fs::recursive_directory_iterator(dir)) {
      const auto ext = entry.path().extension();
      if (!entry.is_regular_file() || (ext != ".hpp" && ext != ".cpp" && ext != ".h")) continue;
      std::ifstream in(entry.path());
      ASSERT_TRUE(in) << entry.path();
      const auto found = scan(fs::relative(entry.path(), root).string(), in);
      findings.insert(findings.end(), found.begin(), found.end());
      ++files;
    }
  }
  EXPECT_GT(files, 5U) << "the scan found too few sources: is DETSIM_SOURCE_DIR right?";
  for (const auto& f : findings)
    ADD_FAILURE() << f.where << ": " << f.line;
}

}  // namespace
