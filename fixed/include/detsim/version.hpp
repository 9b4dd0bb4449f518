// The project's version, in the lowest module so that every module (and a replay's fingerprint)
// can name it. tests/cli_test.cpp checks that it equals the version in CMakeLists.txt.
#pragma once

#include <string_view>

namespace detsim {

inline constexpr std::string_view version = "0.1.0";

}  // namespace detsim
