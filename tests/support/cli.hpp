// Running the built `detsim` executable from a test: its exit code, stdout and stderr, and reading
// the flat JSON objects it prints with --json.
#pragma once

#include <sys/wait.h>

#include <cstdlib>
#include <string>

#include <gtest/gtest.h>

#include "support/replay_files.hpp"

namespace detsim::test {

/// The detsim executable of this build.
inline std::string detsim_binary() {
  return std::string(DETSIM_BINARY_DIR) + "/tools/detsim";
}

struct CliResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

inline std::string read_text(const std::string& path) {
  const auto bytes = read_bytes(path);
  return {bytes.begin(), bytes.end()};
}

/// Runs `<binary> <args>` with stdin from /dev/null, capturing stdout and stderr.
inline CliResult run_program(const std::string& binary, const std::string& args) {
  TempFile out("out.txt");
  TempFile err("err.txt");
  const std::string command =
      binary + " " + args + " </dev/null >" + out.path() + " 2>" + err.path();
  const int status = std::system(command.c_str());
  CliResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = read_text(out.path());
  r.err = read_text(err.path());
  return r;
}

/// Runs `detsim <args>` with stdin from /dev/null, capturing stdout and stderr.
inline CliResult detsim_cli(const std::string& args) {
  return run_program(detsim_binary(), args);
}

inline bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// One JSON object on one line, and nothing else.
inline void expect_one_json_object(const std::string& out) {
  ASSERT_FALSE(out.empty());
  EXPECT_EQ(out.front(), '{') << out;
  EXPECT_EQ(out.substr(out.size() - 2), "}\n") << out;
  EXPECT_EQ(out.find('\n'), out.size() - 1) << out;
}

/// The value of "key": in a flat JSON object (a string without quotes, or a literal); the first
/// occurrence, so a key of a nested object counts only when the top level has none before it.
inline std::string json_value(const std::string& json, const std::string& key) {
  const std::string k = "\"" + key + "\":";
  const auto at = json.find(k);
  if (at == std::string::npos) return "<missing>";
  std::size_t from = at + k.size();
  if (json[from] == '"') {
    const auto end = json.find('"', from + 1);
    return json.substr(from + 1, end - from - 1);
  }
  const auto end = json.find_first_of(",}", from);
  return json.substr(from, end - from);
}

}  // namespace detsim::test
