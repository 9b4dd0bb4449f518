// Packet protection as a session uses it (channel.hpp).
#include "channel.hpp"

#include <string>

namespace detsim::net::detail {

Protection::Protection(const MatchKey& key, std::uint64_t session_id)
    : match_key(key),
      session(session_id),
      handshake_key(protection::handshake_key(key, session_id)) {}

void Protection::bind(Channel& channel, std::uint64_t peer_session) const {
  channel.keyed = true;
  channel.peer_session = peer_session;
  channel.send_key = protection::data_key(match_key, session, peer_session);
  channel.receive_key = protection::data_key(match_key, peer_session, session);
}

bool Protection::seal(Channel& channel, const protocol::Packet& packet, std::size_t input_size,
                      std::vector<std::uint8_t>& out) {
  const bool handshake = packet.header.type == protocol::PacketType::hello ||
                         packet.header.type == protocol::PacketType::hello_reply;
  if (!handshake && !channel.keyed) return false;
  std::uint64_t& sequence = handshake ? handshake_sequence : channel.send_sequence;
  protocol::Packet p = packet;
  p.header.session = session;
  if (!protocol::encode_sealed_plaintext(p, static_cast<std::uint32_t>(sequence), input_size, out))
    return false;
  const protection::Key& key = handshake ? handshake_key : channel.send_key;
  const bool sealed =
      protection::seal(key, sequence, protocol::sealed_header_size(p.header.type), out);
  ++sequence;  // a nonce is never used twice, even for a datagram that failed
  if (!sealed) out.clear();
  return sealed;
}

Opened Protection::open(Channel& channel, std::span<const std::uint8_t> bytes,
                        protocol::Header& header, protocol::DecodeError& error,
                        std::vector<std::uint8_t>& body) const {
  protocol::SealedHeader h;
  error = protocol::decode_sealed_header(bytes, h);
  if (error != protocol::DecodeError::none) return Opened::malformed;
  const bool handshake =
      h.type == protocol::PacketType::hello || h.type == protocol::PacketType::hello_reply;
  if (!handshake && !channel.keyed) return Opened::no_key;

  // The key and window: the data key's, or the handshake key of the session the header names
  // (derived anew, with an empty window, for a session not seen verified before).
  protection::Key fresh_key;
  protection::ReplayWindow fresh_window;
  const protection::Key* key = &channel.receive_key;
  protection::ReplayWindow* window = &channel.window;
  const bool cached = channel.handshake_cached && channel.handshake_session == h.session;
  if (handshake) {
    if (cached) {
      key = &channel.handshake_key;
      window = &channel.handshake_window;
    } else {
      fresh_key = protection::handshake_key(match_key, h.session);
      key = &fresh_key;
      window = &fresh_window;
    }
  }
  // Replays are dropped before decryption: nothing of theirs is read, nothing changes.
  const std::uint64_t sequence = window->expand(h.sequence);
  if (!window->fresh(sequence)) return Opened::replayed;
  if (!protection::open(*key, sequence, h.size, bytes, body)) return Opened::unauthenticated;
  window->accept(sequence);
  if (handshake && !cached) {
    channel.handshake_cached = true;
    channel.handshake_session = h.session;
    channel.handshake_key = fresh_key;
    channel.handshake_window = fresh_window;
  }
  header.type = h.type;
  header.session = handshake ? h.session : channel.peer_session;
  header.sequence = static_cast<std::uint16_t>(sequence);
  return Opened::ok;
}

Status check_match_key(const std::optional<MatchKey>& key, std::string_view field) {
  if (!key) return Status::success();
  if (!protection::available())
    return Status::error(std::string(field) +
                         ": packet protection needs libsodium, and this build has none "
                         "(DETSIM_WITH_SODIUM=OFF); play without a key only on a trusted network");
  bool zero = true;
  for (const std::uint8_t b : *key)
    zero = zero && b == 0;
  if (zero) return Status::error(std::string(field) + " is all zero (never set?)");
  return Status::success();
}

bool looks_sealed(std::span<const std::uint8_t> bytes) noexcept {
  return bytes.size() >= 2 && bytes[0] == protocol::magic0 && bytes[1] == protocol::sealed_magic1;
}

bool looks_like_handshake(std::span<const std::uint8_t> bytes) noexcept {
  return bytes.size() >= 4 && bytes[0] == protocol::magic0 &&
         (bytes[3] == static_cast<std::uint8_t>(protocol::PacketType::hello) ||
          bytes[3] == static_cast<std::uint8_t>(protocol::PacketType::hello_reply));
}

}  // namespace detsim::net::detail
