// Packet protection as a session uses it (docs/NET.md, "Packet protection"): this side's keys and
// one Channel per peer, shared by Session and SpectatorSession. The order of checks on receipt is
// the point: header, then the replay window (before any decryption), then the tag, and only then
// does the window move and the body reach the decoder and the session.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include <detsim/core/status.hpp>

#include <detsim/net/protection.hpp>
#include <detsim/net/protocol.hpp>

namespace detsim::net::detail {

/// One peer's protection state.
struct Channel {
  /// The peer's session id is known (its reply to our challenge): data keys derived both ways.
  bool keyed = false;
  std::uint64_t peer_session = 0;
  protection::Key send_key;     ///< ours to the peer
  protection::Key receive_key;  ///< the peer's to us
  std::uint64_t send_sequence = 0;
  protection::ReplayWindow window;  ///< of receive_key
  // The peer's handshake key, derived from the session id its handshake datagrams name; kept for
  // the last one that verified (so a flood of forged ids costs one derivation each, no more).
  bool handshake_cached = false;
  std::uint64_t handshake_session = 0;
  protection::Key handshake_key;
  protection::ReplayWindow handshake_window;
};

/// What became of a received datagram.
enum class Opened : std::uint8_t {
  ok,               ///< verified; the body is the peer's
  malformed,        ///< its sealed header is bad (`error` says how)
  no_key,           ///< a data datagram before the handshake gave us the peer's session
  replayed,         ///< a duplicate, or older than the window: dropped before decryption
  unauthenticated,  ///< the tag failed: forged, altered, or sealed under another match key
};

/// This side's protection: the match key, this session's id and handshake key and sequence.
struct Protection {
  MatchKey match_key{};
  std::uint64_t session = 0;
  protection::Key handshake_key;
  std::uint64_t handshake_sequence = 0;

  Protection() = default;
  Protection(const MatchKey& key, std::uint64_t session_id);

  /// Derives the data keys with the peer whose session id the handshake bound.
  void bind(Channel& channel, std::uint64_t peer_session) const;
  /// `packet` sealed for the channel's peer into `out`: hellos and replies under our handshake
  /// key (packet.header.session is ours), the rest under the channel's send key (keyed only).
  /// False (nothing to send) when the packet does not encode or the channel has no key yet.
  bool seal(Channel& channel, const protocol::Packet& packet, std::size_t input_size,
            std::vector<std::uint8_t>& out);
  /// Checks `bytes` from the channel's peer as the file comment says. On Opened::ok, `header`
  /// has the type, the session (a handshake datagram's own; else the channel's peer session) and
  /// the low 16 bits of the sequence, and `body` the plaintext for protocol::decode_body().
  Opened open(Channel& channel, std::span<const std::uint8_t> bytes, protocol::Header& header,
              protocol::DecodeError& error, std::vector<std::uint8_t>& body) const;
};

/// A configured match key's problems (`field` names it in the message): all zero (never
/// initialised), or a build without libsodium, which refuses rather than play unprotected.
[[nodiscard]] Status check_match_key(const std::optional<MatchKey>& key, std::string_view field);

/// Whether `bytes` is framed as sealed ("DS") rather than plain ("DN") — to tell a peer that
/// has a match key from one that has none, in the events.
[[nodiscard]] bool looks_sealed(std::span<const std::uint8_t> bytes) noexcept;
/// Whether `bytes` begins like a handshake datagram of either framing.
[[nodiscard]] bool looks_like_handshake(std::span<const std::uint8_t> bytes) noexcept;

}  // namespace detsim::net::detail
