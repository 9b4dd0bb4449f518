// The detsim command.
#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>
#include <detsim/detsim.hpp>

int main(int argc, char** argv) {
  CLI::App app{"detsim: deterministic fixed-point simulation core"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("detsim 0.1.0"));
  auto* version = app.add_subcommand("version", "Print the detsim version");
  version->callback([] { std::puts("detsim 0.1.0"); });
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  return 0;
}
