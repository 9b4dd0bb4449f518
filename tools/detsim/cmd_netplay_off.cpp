// detsim netplay in a build without UDP (DETSIM_WITH_UDP=OFF): the command still parses, so that a
// script gets this message and exit status 2 rather than "unknown subcommand".
#include <cstdio>

#include "commands.hpp"

namespace detsim::cli {

int netplay_command(const NetplayArgs& /*args*/) {
  std::fputs("detsim netplay: built without UDP (DETSIM_WITH_UDP=OFF)\n", stderr);
  return 2;
}

int serve_command(const ServeArgs& /*args*/) {
  std::fputs("detsim serve: built without UDP (DETSIM_WITH_UDP=OFF)\n", stderr);
  return 2;
}

}  // namespace detsim::cli
