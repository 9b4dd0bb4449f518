// The command line as the library builds it (run_cli), with a hook for commands only the stock
// detsim binary has (`accuracy`, which needs MPFR). Internal: CLI11 stays out of the installed
// header <detsim/cli.hpp>.
#pragma once

#include <functional>
#include <string_view>

#include <CLI/CLI.hpp>

namespace detsim::cli::detail {

/// Adds commands to the app; sets exit_code from their callbacks.
using ExtraCommands = std::function<void(CLI::App& app, int& exit_code)>;

/// run_cli with `extra` commands.
int run(int argc, char** argv, std::string_view program, const ExtraCommands& extra);

/// `detsim accuracy` (cmd_accuracy.cpp).
void add_accuracy_command(CLI::App& app, int& exit_code);

}  // namespace detsim::cli::detail
