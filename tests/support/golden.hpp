// Golden files (golden/*.txt): "name hash" lines of XXH3-64 values that every machine must
// reproduce. check_golden compares, naming each entry that differs with the hash it got (so an
// update is a conscious act), or rewrites the file when DETSIM_UPDATE_GOLDEN=1.
#pragma once

#include <cinttypes>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

namespace detsim::test {

inline std::string hex(std::uint64_t h) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016" PRIx64, h);
  return buf;
}

/// `header` is written as-is above the entries when updating (each line starting with "# ").
inline void check_golden(const std::string& path, const std::string& header,
                         const std::map<std::string, std::uint64_t>& actual) {
  const char* update = std::getenv("DETSIM_UPDATE_GOLDEN");
  if (update != nullptr && std::string(update) == "1") {
    std::ofstream out(path);
    out << header;
    for (const auto& [name, h] : actual)
      out << name << ' ' << hex(h) << '\n';
    ASSERT_TRUE(out.good()) << "could not write " << path;
    GTEST_SKIP() << "rewrote " << path;
  }
  std::ifstream in(path);
  ASSERT_TRUE(in) << "missing " << path;
  std::map<std::string, std::string> expected;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::string name;
    std::string value;
    fields >> name >> value;
    expected[name] = value;
  }
  for (const auto& [name, h] : actual) {
    const auto it = expected.find(name);
    if (it == expected.end()) {
      ADD_FAILURE() << name << ": no golden hash in " << path << " (actual " << hex(h) << ")";
    } else {
      EXPECT_EQ(it->second, hex(h))
          << name << ": results changed (expected " << it->second << ", actual " << hex(h) << ")";
    }
  }
  for (const auto& [name, value] : expected)
    EXPECT_TRUE(actual.count(name) != 0) << path << " names unknown entry " << name;
}

}  // namespace detsim::test
