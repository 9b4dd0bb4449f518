// The project's one hash: XXH3-64 (seed 0) of canonical bytes. State hashes, replay and report
// checksums, the hash chain of a replay and the network datagram checksum all use it, so every
// module computes the same value for the same bytes, and only core links xxHash.
#pragma once

#include <cstdint>
#include <memory>
#include <span>

namespace detsim {

/// XXH3-64 with seed 0 of `bytes` (the empty span included): what a game whose state lives beside
/// the World returns from net::Game::save() for its own bytes, so its hashes are detsim's.
[[nodiscard]] std::uint64_t hash_bytes(std::span<const std::uint8_t> bytes) noexcept;

/// XXH3-64 of bytes that arrive in pieces: after any sequence of update() calls, digest() equals
/// hash_bytes() of their concatenation. Copies continue independently from the same point.
class Hash64Stream {
 public:
  /// An empty stream (digest() == hash_bytes({})). Throws std::bad_alloc when out of memory.
  Hash64Stream();
  Hash64Stream(const Hash64Stream& other);
  Hash64Stream& operator=(const Hash64Stream& other);
  ~Hash64Stream();

  /// Appends `bytes` to what the stream has hashed.
  void update(std::span<const std::uint8_t> bytes) noexcept;
  /// The hash of everything appended so far; the stream may continue afterwards.
  [[nodiscard]] std::uint64_t digest() const noexcept;

 private:
  struct Impl;  // owns the XXH3 state, so that xxhash.h stays out of the public headers
  std::unique_ptr<Impl> impl_;
};

}  // namespace detsim
