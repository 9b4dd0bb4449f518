// Unpredictable 64-bit values for session ids and handshake challenges (docs/NET.md,
// "Handshake"): libsodium's randombytes_buf (the operating system's CSPRNG), or, in a build
// without libsodium (DETSIM_WITH_SODIUM=OFF: cross builds only), getrandom(2) directly.
#pragma once

#include <cstdint>

#include <detsim/core/status.hpp>

namespace detsim::net::detail {

/// Initialises the source once (thread-safe); an error when the operating system has none.
[[nodiscard]] Status secure_random_ready();

/// A uniformly random value, never 0 (0 means "none" in the handshake). secure_random_ready()
/// must have succeeded.
[[nodiscard]] std::uint64_t secure_random_u64() noexcept;

}  // namespace detsim::net::detail
