// The stock detsim binary: the library's command line (run_cli) with the built-in scenarios, and
// `detsim accuracy`.
#include "cli_app.hpp"

int main(int argc, char** argv) {
  return detsim::cli::detail::run(argc, argv, "detsim", detsim::cli::detail::add_accuracy_command);
}
