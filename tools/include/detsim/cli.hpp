// The detsim command line as a library: a game links it into its own tool binary, registers its
// scenario (register_scenario, <detsim/scenes/scenario.hpp>) and gets every subcommand — run,
// verify, diff, bisect, synctest, golden, demo, netplay, scenarios — for its own replays and
// desync reports:
//
//     int main(int argc, char** argv) {
//       if (detsim::Status s = detsim::register_scenario(mygame::definition()); !s) return 2;
//       return detsim::cli::run_cli(argc, argv, "mygame-tool");
//     }
//
// CMake: target_link_libraries(mygame-tool PRIVATE detsim::cli).
#pragma once

#include <string_view>

namespace detsim::cli {

/// Parses `argv` and runs the subcommand it names, for the scenarios this process knows (the
/// built-ins and every registered one); `program` names the tool in its help. Returns the exit
/// status: 0 success, 1 a check failed (a hash mismatch, a desync, an unverified frame), 2 bad
/// usage or bad input (the message on stderr names what is wrong). Writes to stdout and stderr.
int run_cli(int argc, char** argv, std::string_view program = "detsim");

}  // namespace detsim::cli
