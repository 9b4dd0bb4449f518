// pushball-tool: the detsim command line for pushball's runs — `pushball-tool run --scenario
// pushball --record match.dsr`, `verify`, `synctest`, `diff`, `bisect` with its own score fields.
#include <cstdio>

#include <detsim/cli.hpp>

#include "pushball.hpp"

int main(int argc, char** argv) {
  if (const detsim::Status s = detsim::register_scenario(pushball::definition()); !s) {
    std::fprintf(stderr, "pushball-tool: %s\n", s.message().c_str());
    return 2;
  }
  return detsim::cli::run_cli(argc, argv, "pushball-tool");
}
