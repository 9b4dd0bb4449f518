// Packet protection (protection.hpp): key derivation, ChaCha20-Poly1305-IETF sealing and opening
// through libsodium, and the replay window.
#include <detsim/net/protection.hpp>

#if DETSIM_WITH_SODIUM
#include <sodium.h>
#endif

namespace detsim::net::protection {
namespace {

#if DETSIM_WITH_SODIUM
static_assert(crypto_aead_chacha20poly1305_ietf_KEYBYTES == key_size);
static_assert(crypto_aead_chacha20poly1305_ietf_ABYTES == tag_size);
static_assert(crypto_kdf_KEYBYTES == key_size);

// The 96-bit IETF nonce: the 64-bit sequence, little-endian, then four zero bytes. Each key has
// one sender, whose sequence only grows, so no nonce repeats under a key.
std::array<unsigned char, crypto_aead_chacha20poly1305_ietf_NPUBBYTES> nonce(
    std::uint64_t sequence) noexcept {
  std::array<unsigned char, crypto_aead_chacha20poly1305_ietf_NPUBBYTES> n{};
  for (std::size_t i = 0; i < 8; ++i)
    n[i] = static_cast<unsigned char>(sequence >> (8 * i));
  return n;
}

// crypto_kdf's contexts are 8 characters; one per use, so no two uses share a subkey.
Key derive(const std::uint8_t* parent, std::uint64_t id, const char (&context)[9]) noexcept {
  Key k;
  crypto_kdf_derive_from_key(k.bytes.data(), k.bytes.size(), id, context, parent);
  return k;
}
#endif

}  // namespace

bool available() noexcept {
#if DETSIM_WITH_SODIUM
  return sodium_init() >= 0;
#else
  return false;
#endif
}

Key handshake_key(const MatchKey& match_key, std::uint64_t sender_session) noexcept {
#if DETSIM_WITH_SODIUM
  return derive(match_key.data(), sender_session, "dsHello1");
#else
  (void)match_key;
  (void)sender_session;
  return {};
#endif
}

Key data_key(const MatchKey& match_key, std::uint64_t sender_session,
             std::uint64_t receiver_session) noexcept {
#if DETSIM_WITH_SODIUM
  // Two steps: crypto_kdf's subkey id is 64 bits, and the direction is named by two session ids.
  const Key sender = derive(match_key.data(), sender_session, "dsSend01");
  return derive(sender.bytes.data(), receiver_session, "dsRecv01");
#else
  (void)match_key;
  (void)sender_session;
  (void)receiver_session;
  return {};
#endif
}

bool seal(const Key& key, std::uint64_t sequence, std::size_t header_size,
          std::vector<std::uint8_t>& datagram) {
#if DETSIM_WITH_SODIUM
  if (datagram.size() < header_size) return false;
  const std::size_t body = datagram.size() - header_size;
  datagram.resize(datagram.size() + tag_size);
  unsigned char* text = datagram.data() + header_size;
  const auto n = nonce(sequence);
  // In place (libsodium allows the message and ciphertext to be the same buffer).
  unsigned long long written = 0;
  crypto_aead_chacha20poly1305_ietf_encrypt(text, &written, text, body, datagram.data(),
                                            header_size, nullptr, n.data(), key.bytes.data());
  return written == body + tag_size;
#else
  (void)key;
  (void)sequence;
  (void)header_size;
  (void)datagram;
  return false;
#endif
}

bool open(const Key& key, std::uint64_t sequence, std::size_t header_size,
          std::span<const std::uint8_t> datagram, std::vector<std::uint8_t>& body) {
  body.clear();
#if DETSIM_WITH_SODIUM
  if (datagram.size() < header_size + tag_size) return false;
  const std::size_t sealed = datagram.size() - header_size;
  body.resize(sealed - tag_size);
  const auto n = nonce(sequence);
  unsigned long long written = 0;
  if (crypto_aead_chacha20poly1305_ietf_decrypt(
          body.data(), &written, nullptr, datagram.data() + header_size, sealed, datagram.data(),
          header_size, n.data(), key.bytes.data()) != 0 ||
      written != body.size()) {
    body.clear();
    return false;
  }
  return true;
#else
  (void)key;
  (void)sequence;
  (void)header_size;
  (void)datagram;
  return false;
#endif
}

std::uint64_t ReplayWindow::expand(std::uint32_t low) const noexcept {
  constexpr std::uint64_t span = std::uint64_t{1} << 32;
  constexpr std::uint64_t half = span / 2;
  const std::uint64_t expected = any_ ? highest_ + 1 : 0;
  std::uint64_t candidate = (expected & ~(span - 1)) | low;
  if (candidate + half <= expected && candidate <= ~std::uint64_t{0} - span)
    candidate += span;
  else if (candidate > expected + half && candidate >= span)
    candidate -= span;
  return candidate;
}

bool ReplayWindow::fresh(std::uint64_t sequence) const noexcept {
  if (!any_ || sequence > highest_) return true;
  const std::uint64_t behind = highest_ - sequence;
  if (behind >= size) return false;  // older than the window: it may have been accepted
  return ((seen_ >> behind) & 1U) == 0;
}

void ReplayWindow::accept(std::uint64_t sequence) noexcept {
  if (!any_) {
    any_ = true;
    highest_ = sequence;
    seen_ = 1;
  } else if (sequence > highest_) {
    const std::uint64_t shift = sequence - highest_;
    seen_ = shift >= size ? 1 : (seen_ << shift) | 1U;
    highest_ = sequence;
  } else if (highest_ - sequence < size) {
    seen_ |= std::uint64_t{1} << (highest_ - sequence);
  }
}

}  // namespace detsim::net::protection
