// The detsim subcommands, each a function of its parsed arguments returning the exit code. main.cpp
// parses the command line (CLI11, in that one file); these files do the work.
#pragma once

#include <cstdint>
#include <string>

namespace detsim::cli {

/// Scenario selection shared by run and synctest; 0 means "the scenario's default".
struct ScenarioArgs {
  std::string scenario;
  std::uint64_t frames = 0;
  std::uint64_t seed = 1;
  std::uint32_t players = 0;
  std::uint32_t count = 0;
};

struct ScenariosArgs {
  bool json = false;
};
int scenarios_command(const ScenariosArgs& args);

struct RunArgs {
  ScenarioArgs scene;
  std::string record;  ///< replay file to write, or empty
  std::uint32_t keyframe_interval = 300;
  bool json = false;
};
int run_command(const RunArgs& args);

struct VerifyArgs {
  std::string file;
  bool json = false;
};
int verify_command(const VerifyArgs& args);

struct InfoArgs {
  std::string file;
  bool json = false;
};
int info_command(const InfoArgs& args);

struct SynctestArgs {
  ScenarioArgs scene;
  std::uint32_t check_distance = 8;
  bool json = false;
};
int synctest_command(const SynctestArgs& args);

struct GoldenArgs {
  std::string dir;  ///< the golden directory (default: the source tree's golden/)
  bool update = false;
  bool json = false;
};
int golden_command(const GoldenArgs& args);

/// The main job of scripts/run.sh: run a scenario, record it, verify the replay, summarise.
struct DemoArgs {
  ScenarioArgs scene;
  std::string record;  ///< empty: a temporary file
  bool json = false;
};
int demo_command(const DemoArgs& args);

}  // namespace detsim::cli
