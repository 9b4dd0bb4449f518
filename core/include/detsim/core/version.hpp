// The project's version, in core so that every module above fixed (and a replay's fingerprint) can
// name it. tests/cli_test.cpp checks that it equals the version in CMakeLists.txt.
#pragma once

#include <string_view>

namespace detsim {

/// The release of detsim this build is ("MAJOR.MINOR.PATCH", as in CMakeLists.txt's project()).
inline constexpr std::string_view version = "0.1.0";

}  // namespace detsim
