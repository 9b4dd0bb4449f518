// DETSIM_TEST_SCALE=P (a percentage, 1..100; default 100) shrinks the heaviest randomised loops.
// scripts/test.sh sets it for the sanitizer build, where the same tests look for undefined
// behaviour at a fraction of the volume; the optimised build always runs the full counts.
#pragma once

#include <cstddef>
#include <cstdlib>

namespace detsim::test {

inline std::size_t scaled(std::size_t full) {
  const char* text = std::getenv("DETSIM_TEST_SCALE");
  if (text == nullptr) return full;
  const long percent = std::strtol(text, nullptr, 10);
  if (percent <= 0 || percent >= 100) return full;
  const std::size_t n = full / 100 * static_cast<std::size_t>(percent);
  return n > 0 ? n : 1;
}

}  // namespace detsim::test
