// Session ids and challenges must be unguessable by anyone off the path (docs/NET.md,
// "Handshake"): they come from the operating system's CSPRNG, never from a seeded generator.
#include "secure_random.hpp"

#if DETSIM_WITH_SODIUM
#include <sodium.h>
#else
#include <sys/random.h>

#include <cerrno>
#include <cstddef>
#endif

namespace detsim::net::detail {

#if DETSIM_WITH_SODIUM

Status secure_random_ready() {
  // sodium_init is idempotent and thread-safe; -1 means no usable entropy source.
  if (sodium_init() < 0) return Status::error("libsodium could not be initialised (no CSPRNG)");
  return Status::success();
}

std::uint64_t secure_random_u64() noexcept {
  std::uint64_t v = 0;
  while (v == 0)
    randombytes_buf(&v, sizeof v);
  return v;
}

#else

namespace {
#ifdef __EMSCRIPTEN__
// WebAssembly: Emscripten's getentropy draws from the host's crypto.getRandomValues (a browser)
// or crypto.randomFillSync (node); it has no getrandom.
bool fill(void* out, std::size_t size) noexcept {
  auto* bytes = static_cast<unsigned char*>(out);
  while (size > 0) {
    const std::size_t n = size < 256 ? size : 256;  // getentropy's most per call
    if (getentropy(bytes, n) != 0) return false;
    bytes += n;
    size -= n;
  }
  return true;
}
#else
bool fill(void* out, std::size_t size) noexcept {
  auto* bytes = static_cast<unsigned char*>(out);
  while (size > 0) {
    const ssize_t got = getrandom(bytes, size, 0);
    if (got < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    bytes += got;
    size -= static_cast<std::size_t>(got);
  }
  return true;
}
#endif
}  // namespace

Status secure_random_ready() {
  std::uint64_t probe = 0;
  if (!fill(&probe, sizeof probe)) return Status::error("getrandom failed (no CSPRNG)");
  return Status::success();
}

std::uint64_t secure_random_u64() noexcept {
  std::uint64_t v = 0;
  while (v == 0)
    if (!fill(&v, sizeof v)) v = 0;
  return v;
}

#endif

}  // namespace detsim::net::detail
