// The module map of docs/ARCHITECTURE.md, enforced: each module's sources and public headers
// include the public headers of the modules below it only (and never another module's src/).
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace {

namespace fs = std::filesystem;

// What each module may include (itself included), as docs/ARCHITECTURE.md lists it.
const std::map<std::string, std::set<std::string>>& allowed() {
  static const std::map<std::string, std::set<std::string>> floors{
      {"fixed", {"fixed"}},
      {"core", {"core", "fixed"}},
      {"sim", {"sim", "core", "fixed"}},
      {"scenes", {"scenes", "sim", "core", "fixed"}},
      {"replay", {"replay", "scenes", "sim", "core", "fixed"}},
      {"net", {"net", "core", "fixed"}},
      {"scenario_net", {"scenario_net", "net", "replay", "scenes", "sim", "core", "fixed"}},
      // The C API's own header is <detsim/detsim.h>, which names no module of its own.
      {"c", {"detsim", "sim", "net", "core", "fixed"}},
  };
  return floors;
}

// <detsim/X/...> or <detsim/X.hpp> names module X; <detsim/detsim.hpp> is the umbrella (above all);
// <detsim/version.hpp>-style names are looked up as modules too.
std::string module_of(const std::string& path) {
  const std::size_t slash = path.find('/');
  std::string first = slash == std::string::npos ? path : path.substr(0, slash);
  if (const std::size_t dot = first.find('.'); dot != std::string::npos) first.resize(dot);
  return first;
}

TEST(ModuleFloors, EveryModuleIncludesOnlyTheModulesBelowIt) {
  const std::regex include(R"(#\s*include\s*<detsim/([^>]+)>)");
  const std::regex internal(R"(#\s*include\s*"\.\./\.\./)");
  std::vector<std::string> violations;
  std::size_t files = 0;
  for (const auto& [module, may] : allowed()) {
    const fs::path root = fs::path(DETSIM_SOURCE_DIR) / module;
    ASSERT_TRUE(fs::is_directory(root)) << root;
    for (const auto& entry : fs::recursive_directory_iterator(root)) {
      const std::string ext = entry.path().extension().string();
      if (ext != ".cpp" && ext != ".hpp" && ext != ".h") continue;
      ++files;
      std::ifstream in(entry.path());
      std::string line;
      int number = 0;
      while (std::getline(in, line)) {
        ++number;
        std::smatch m;
        const std::string where = entry.path().string() + ":" + std::to_string(number) + ": ";
        if (std::regex_search(line, m, include)) {
          const std::string target = module_of(m[1].str());
          if (may.count(target) == 0) violations.push_back(where + line);
        }
        if (std::regex_search(line, internal)) violations.push_back(where + line);
      }
    }
  }
  EXPECT_GT(files, 100U);
  for (const std::string& v : violations)
    ADD_FAILURE() << "includes a module above its own: " << v;
}

TEST(ModuleFloors, TheCheckSeesAnIncludeFromAbove) {
  EXPECT_EQ(module_of("sim/world.hpp"), "sim");
  EXPECT_EQ(module_of("net.hpp"), "net");
  EXPECT_EQ(module_of("detsim.hpp"), "detsim");
  EXPECT_EQ(allowed().at("net").count("sim"), 0U);
  EXPECT_EQ(allowed().at("sim").count("scenes"), 0U);
}

}  // namespace
