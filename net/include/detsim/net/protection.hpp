// Packet protection (docs/NET.md, "Packet protection"): authenticated encryption of every datagram
// between two sessions that share a match key, and the replay window that drops duplicates and
// old datagrams before they are decrypted.
//
// - Keys: a 32-byte match key that the matchmaker hands every player of a match (netcode.io's
//   connect token, without the token) — whoever holds it is a member. Each sender's handshake
//   datagrams are sealed under handshake_key(match key, sender session); once the handshake bound
//   both session ids, each direction has its own key, data_key(match key, sender session,
//   receiver session). Both come from crypto_kdf_derive_from_key (BLAKE2b), so a datagram cannot
//   be reflected to its sender, moved to another peer, or replayed into another match or session.
// - AEAD: ChaCha20-Poly1305-IETF (RFC 8439). The nonce is the sender's 64-bit sequence number
//   under that key, which never repeats (so XChaCha20's random 192-bit nonces would buy nothing
//   but 8 more bytes of nonce to think about); session ids are 64 random bits, so two sessions
//   never share a key. The cleartext header is the associated data.
// - Replay window: the highest sequence accepted and a 64-bit bitmap behind it (RFC 6479):
//   checked before decrypting, moved only after the tag verified.
//
// Everything here needs libsodium (DETSIM_WITH_SODIUM). A build without it (cross builds only)
// has available() == false: sessions refuse a match key rather than play unprotected, and seal()
// and open() always fail.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace detsim::net {

/// The secret every player of a match holds (SessionConfig::match_key): 32 bytes from a CSPRNG,
/// handed out by the matchmaker with the addresses and settings. Never all zero.
using MatchKey = std::array<std::uint8_t, 32>;

}  // namespace detsim::net

namespace detsim::net::protection {

inline constexpr std::size_t key_size = 32;
/// The Poly1305 tag each sealed datagram ends with.
inline constexpr std::size_t tag_size = 16;

/// Whether this build can protect packets (it was built with libsodium).
[[nodiscard]] bool available() noexcept;

/// One direction's (or one sender's handshake) ChaCha20-Poly1305 key.
struct Key {
  std::array<std::uint8_t, key_size> bytes{};
};

/// The key a session with id `sender_session` seals its hellos and hello replies under (to every
/// peer: their nonces come from one counter).
[[nodiscard]] Key handshake_key(const MatchKey& match_key, std::uint64_t sender_session) noexcept;
/// The key of everything else `sender_session` sends to `receiver_session`.
[[nodiscard]] Key data_key(const MatchKey& match_key, std::uint64_t sender_session,
                           std::uint64_t receiver_session) noexcept;

/// Encrypts `datagram[header_size:]` in place and appends the tag; the first header_size bytes
/// are authenticated, not encrypted. `sequence` is the nonce: never twice under one key. False
/// (datagram unspecified) without libsodium.
[[nodiscard]] bool seal(const Key& key, std::uint64_t sequence, std::size_t header_size,
                        std::vector<std::uint8_t>& datagram);

/// Checks the tag of `datagram` (header, ciphertext, tag) under `key` and `sequence` and writes
/// the plaintext body to `body`. False, `body` empty, when anything was changed, the key or the
/// sequence is another, or the datagram is shorter than header and tag.
[[nodiscard]] bool open(const Key& key, std::uint64_t sequence, std::size_t header_size,
                        std::span<const std::uint8_t> datagram, std::vector<std::uint8_t>& body);

/// The replay window of one key (RFC 6479's idea with a single 64-bit word): sequences older than
/// the 64 below the highest accepted, and any accepted before, are refused.
class ReplayWindow {
 public:
  static constexpr std::uint64_t size = 64;

  /// The 64-bit sequence a datagram carrying its low 32 bits most likely has: the one nearest the
  /// highest accepted (QUIC's packet-number recovery). 0-based before anything was accepted.
  [[nodiscard]] std::uint64_t expand(std::uint32_t low) const noexcept;
  /// Whether `sequence` may still be accepted: not a duplicate, not older than the window.
  [[nodiscard]] bool fresh(std::uint64_t sequence) const noexcept;
  /// Marks `sequence` accepted (call only after its tag verified).
  void accept(std::uint64_t sequence) noexcept;
  /// Whether `sequence` is above everything accepted so far.
  [[nodiscard]] bool newest(std::uint64_t sequence) const noexcept {
    return !any_ || sequence > highest_;
  }

 private:
  std::uint64_t highest_ = 0;
  std::uint64_t seen_ = 0;  ///< bit i: highest_ - i was accepted
  bool any_ = false;
};

}  // namespace detsim::net::protection
