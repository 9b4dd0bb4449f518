#include <detsim/core/hash.hpp>

#include <xxhash.h>
#include <new>

namespace detsim {

std::uint64_t hash_bytes(std::span<const std::uint8_t> bytes) noexcept {
  return XXH3_64bits(bytes.data(), bytes.size());
}

struct Hash64Stream::Impl {
  XXH3_state_t* state = XXH3_createState();
  Impl() {
    if (state == nullptr) throw std::bad_alloc();
    XXH3_64bits_reset(state);
  }
  Impl(const Impl& other) : Impl() { XXH3_copyState(state, other.state); }
  Impl& operator=(const Impl&) = delete;
  ~Impl() { XXH3_freeState(state); }
};

Hash64Stream::Hash64Stream() : impl_(std::make_unique<Impl>()) {}
Hash64Stream::Hash64Stream(const Hash64Stream& other)
    : impl_(std::make_unique<Impl>(*other.impl_)) {}
Hash64Stream& Hash64Stream::operator=(const Hash64Stream& other) {
  if (this != &other) XXH3_copyState(impl_->state, other.impl_->state);
  return *this;
}
Hash64Stream::~Hash64Stream() = default;

void Hash64Stream::update(std::span<const std::uint8_t> bytes) noexcept {
  XXH3_64bits_update(impl_->state, bytes.data(), bytes.size());
}

std::uint64_t Hash64Stream::digest() const noexcept {
  return XXH3_64bits_digest(impl_->state);
}

}  // namespace detsim
