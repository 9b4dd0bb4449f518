// invariant_failed (assert.hpp).
#include <detsim/core/assert.hpp>

#include <cstdio>
#include <cstdlib>

namespace detsim {

void invariant_failed(const char* what, const char* file, int line) noexcept {
  std::fprintf(stderr, "detsim: invariant failed at %s:%d: %s\n", file, line, what);
  std::fflush(stderr);
  std::abort();
}

}  // namespace detsim
