// The session wire protocol (docs/NET.md, "Protocol"): what one datagram between two sessions
// carries, and its canonical little-endian encoding.
//
// decode() is the gate every received byte passes through. It is pure (no session state) and
// checks every field before the session sees it: magic, version, type, lengths, counts and the
// trailing XXH3 checksum. A datagram that fails is dropped and counted by its DecodeError; nothing
// in a session changes. The checksum catches corruption, not attackers: the session ids (bound to
// the handshake's challenges) and the frame windows in the session are what keep stale and foreign
// datagrams out.
//
// Two framings of the same bodies. Plain (no match key: LAN tests and the simulated network;
// docs/NET.md says what it gives up), all integers little-endian:
//
//     header   magic "DN" | version u8 | type u8 | sender session u64 | sequence u16  (14 bytes)
//     body     by type (below)
//     trailer  low 32 bits of XXH3-64 over header and body                             (4 bytes)
//
// Sealed (SessionConfig::match_key; <detsim/net/protection.hpp> has the keys and the AEAD):
//
//     header   magic "DS" | version u8 | type u8 | sequence u32                        (8 bytes)
//              hello and hello_reply only: + sender session u64                         (16 bytes)
//     body     by type (below), encrypted with ChaCha20-Poly1305-IETF
//     tag      Poly1305 over header (associated data) and ciphertext                   (16 bytes)
//
// A sealed datagram's sequence is the low 32 bits of the sender's 64-bit sequence under that key
// (the nonce); the receiver rebuilds the rest from the highest it accepted. Its data datagrams
// carry no session id: their key is bound to both sessions' ids (protection.hpp), so the tag
// proves the sender's session. The header is in the clear, and authenticated.
//
//     hello        fingerprint u64 | players u8 | player u8 | input_size u8 | challenge u64
//     hello_reply  challenge u64 (the hello's, echoed; the header carries the replier's session)
//     input        ack_frame v | check_ack z | current_frame z | advantage i8 | start_frame z |
//                  count u8 | held_frame z | lists u8 (gone count, low nibble; back count,
//                  high nibble) | gone x (player u8, frame z) | back x (player u8, from z,
//                  until z) | deltas: run-length coded bytes (below) | checks u8 | checks x (frame
//                  z, hash u64)
//     ping, pong   time u64 (microseconds of the pinging side's clock)
//     state_request  offset v (the snapshot bytes the rejoining sender holds)
//     state_chunk    total v | offset v | length v | length bytes (a slice of the snapshot)
//
// Frame numbers are u32 values. `v` is an unsigned LEB128 varint (7 bits per byte, low first, at
// most 5 bytes, no redundant trailing zero byte); `z` is the frame minus ack_frame, zigzag-coded
// (0, -1, 1, -2, ... as 0, 1, 2, 3, ...) as such a varint: the frames of one packet lie close
// together, so each costs one byte instead of four. A value outside u32, an over-long or
// redundant varint is a bad field.
//
// Input deltas: the count inputs, each XORed with the one before it (the first with the input the
// receiver already holds for start_frame - 1), so a held button costs nothing; then the
// count * input_size XOR bytes in tokens: t < 128 is t + 1 literal bytes that follow, t >= 128 is
// t - 127 zero bytes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include <detsim/net/transport.hpp>

namespace detsim::net::protocol {

/// Changes whenever the layout above changes; peers of different versions drop each other's
/// datagrams (counted as bad_version) and never synchronise. Version 5 added the sealed framing,
/// version 6 the state transfer that lets a restarted player rejoin (state_request, state_chunk),
/// version 7 the back reports that take a player back into a match of three or more.
inline constexpr std::uint8_t version = 7;
inline constexpr std::uint8_t magic0 = 'D';
inline constexpr std::uint8_t magic1 = 'N';
inline constexpr std::size_t header_size = 14;
inline constexpr std::size_t trailer_size = 4;
/// The sealed framing's second magic byte ("DS"), headers and tag.
inline constexpr std::uint8_t sealed_magic1 = 'S';
inline constexpr std::size_t sealed_data_header_size = 8;
inline constexpr std::size_t sealed_handshake_header_size = 16;
inline constexpr std::size_t sealed_tag_size = 16;
/// The largest input a player sends, in bytes.
inline constexpr std::size_t max_input_size = 64;
/// The largest unit an input packet carries: players send their input; a host sends spectators
/// whole frames (a byte of disconnected players, then every player's input: 1 + 8 * 64 bytes).
inline constexpr std::size_t max_unit_size = 1 + 8 * max_input_size;
/// The most inputs and hash checks one datagram carries.
inline constexpr std::size_t max_inputs_per_packet = 255;
inline constexpr std::size_t max_checks_per_packet = 8;
/// The player byte of a spectator's hello.
inline constexpr std::uint8_t spectator_player = 0xFF;

enum class PacketType : std::uint8_t {
  hello = 1,
  hello_reply = 2,
  input = 3,
  ping = 4,
  pong = 5,
  state_request = 6,
  state_chunk = 7,
};

/// The most snapshot bytes one state_chunk carries, and the largest snapshot a transfer allows
/// (compressed): a bound on what a rejoining session allocates, whatever a peer says.
inline constexpr std::size_t max_state_chunk = 1024;
inline constexpr std::size_t max_state_transfer = std::size_t{64} << 20;

struct Header {
  PacketType type = PacketType::hello;
  /// The sender's session id: 64 random bits (a CSPRNG), learned only from a hello_reply that
  /// echoes the receiver's challenge, and fixed from then on.
  std::uint64_t session = 0;
  std::uint16_t sequence = 0;  ///< per destination, +1 per datagram (loss statistics)
};

/// "I am `player` of a match of `players` with these settings; answer my challenge."
struct Hello {
  std::uint64_t fingerprint = 0;  ///< what both sides must agree on (SessionConfig::fingerprint)
  std::uint8_t players = 0;
  std::uint8_t player = 0;  ///< spectator_player for a spectator
  std::uint8_t input_size = 0;
  std::uint64_t challenge = 0;  ///< 64 random bits (a CSPRNG), sent only to the peer's address
};

struct HelloReply {
  std::uint64_t challenge = 0;  ///< the challenge of the hello it answers
};

/// A confirmed-frame state hash, sent for desync detection until acknowledged.
struct HashCheck {
  std::uint32_t frame = 0;
  std::uint64_t hash = 0;

  friend constexpr bool operator==(const HashCheck&, const HashCheck&) noexcept = default;
};

/// "I take `player` as gone from `frame` on" (its inputs are all zero from there): how peers
/// agree on one disconnect frame (docs/NET.md, "Disconnects").
struct GoneReport {
  std::uint8_t player = 0;
  std::uint32_t frame = 0;

  friend constexpr bool operator==(const GoneReport&, const GoneReport&) noexcept = default;
};

/// The most players a session has, and so gone reports one datagram carries.
inline constexpr std::size_t max_gone_reports = 8;

/// "`player` was away over [from, until) and plays again from `until`": how the peers of a match
/// of three or more take a rejoining player back at the one frame its snapshot's server chose
/// (docs/NET.md, "Rejoining"). `from` is the disconnect frame they agreed on.
struct BackReport {
  std::uint8_t player = 0;
  std::uint32_t from = 0;
  std::uint32_t until = 0;

  friend constexpr bool operator==(const BackReport&, const BackReport&) noexcept = default;
};

struct InputBody {
  std::uint32_t ack_frame = 0;       ///< the sender holds every input of the receiver before it
  std::uint32_t check_ack = 0;       ///< the sender holds every hash check of the receiver up to it
  std::uint32_t current_frame = 0;   ///< the sender's next frame to simulate (time sync)
  std::int8_t advantage = 0;         ///< the sender's frame advantage over the receiver
  std::uint32_t start_frame = 0;     ///< frame of the first input carried
  std::uint8_t count = 0;            ///< inputs carried (0: an ack or keepalive only)
  std::vector<std::uint8_t> deltas;  ///< count * input_size XOR deltas (see the file comment)
  std::vector<HashCheck> checks;
  /// The sender holds every player's input (or knows it gone for good) before this frame.
  std::uint32_t held_frame = 0;
  std::vector<GoneReport> gone;  ///< every player the sender takes as gone, ascending player
  /// Every player the sender took back after an absence (its latest one), ascending player.
  std::vector<BackReport> back;
};

struct PingBody {
  std::uint64_t time_us = 0;
};

/// "Send me the match's snapshot from this byte on" (a rejoining session; docs/NET.md,
/// "Rejoining"): resent until the snapshot is whole, and its own acknowledgement.
struct StateRequest {
  std::uint32_t offset = 0;
};

/// A slice of the snapshot a rejoining peer asked for.
struct StateChunk {
  std::uint32_t total = 0;  ///< the whole snapshot's size: 1 .. max_state_transfer
  std::uint32_t offset = 0;
  std::vector<std::uint8_t> data;  ///< 1 .. max_state_chunk bytes, offset + size <= total
};

/// One decoded datagram. Only the body of `header.type` is meaningful.
struct Packet {
  Header header;
  Hello hello;
  HelloReply hello_reply;
  InputBody input;
  PingBody ping;  ///< ping and pong
  StateRequest state_request;
  StateChunk state_chunk;
};

/// Why a datagram was dropped.
enum class DecodeError : std::uint8_t {
  none = 0,
  too_short,     ///< shorter than a header and trailer
  too_long,      ///< longer than max_datagram
  bad_magic,     ///< not a detsim datagram
  bad_version,   ///< another protocol version
  bad_type,      ///< an unknown packet type
  bad_checksum,  ///< corrupted on the way
  bad_length,    ///< the body is shorter or longer than its fields say
  bad_field,     ///< a field out of its range (a count, an input size, a run past the end)
};
inline constexpr std::size_t decode_error_count = 9;

/// A short name for logs and statistics ("bad_checksum").
[[nodiscard]] std::string_view to_string(DecodeError error) noexcept;

/// Decodes `bytes`, whose inputs (if any) are `input_size` bytes each (1 .. max_unit_size).
/// On success fills `out` and returns DecodeError::none; otherwise `out` is unspecified.
[[nodiscard]] DecodeError decode(std::span<const std::uint8_t> bytes, std::size_t input_size,
                                 Packet& out);

/// Encodes `packet` (the body of packet.header.type) into `out`, replacing its contents. Returns
/// false, leaving `out` empty, when it would exceed max_datagram or a field is out of range
/// (count or deltas inconsistent with input_size, too many checks): a session bug, never input.
[[nodiscard]] bool encode(const Packet& packet, std::size_t input_size,
                          std::vector<std::uint8_t>& out);

/// The cleartext header of a sealed datagram, readable without a key (and not to be trusted
/// before the tag verified).
struct SealedHeader {
  PacketType type = PacketType::hello;
  std::uint32_t sequence = 0;  ///< the low 32 bits of the sender's sequence under the key
  std::uint64_t session = 0;   ///< hello and hello_reply: the sender's session id; else 0
  std::size_t size = 0;        ///< of the header: sealed_data_header_size or ..._handshake_...
};

/// The size of a sealed header of this type.
[[nodiscard]] std::size_t sealed_header_size(PacketType type) noexcept;

/// Checks a sealed datagram's length, magic, version and type and reads its header. Says nothing
/// about the rest: protection::open() checks the tag, decode_body() the body.
[[nodiscard]] DecodeError decode_sealed_header(std::span<const std::uint8_t> bytes,
                                               SealedHeader& out);

/// Writes a sealed datagram before sealing: its header (`sequence`, and packet.header.session for
/// a handshake type) and the plaintext body; protection::seal() then encrypts the body in place
/// and appends the tag. False, `out` empty, as encode().
[[nodiscard]] bool encode_sealed_plaintext(const Packet& packet, std::uint32_t sequence,
                                           std::size_t input_size, std::vector<std::uint8_t>& out);

/// Decodes an opened sealed datagram's body (every field checked, as decode() does: a peer that
/// holds the key may still send anything) into `out`; out.header's session and sequence are the
/// caller's to fill.
[[nodiscard]] DecodeError decode_body(PacketType type, std::span<const std::uint8_t> body,
                                      std::size_t input_size, Packet& out);

/// The XOR deltas of `inputs` (whole inputs of input_size bytes) against `reference` (one input,
/// the receiver's input before the first) and each input against the one before it.
void delta_encode(std::span<const std::uint8_t> reference, std::span<const std::uint8_t> inputs,
                  std::vector<std::uint8_t>& deltas);
/// The inverse of delta_encode: `deltas` back into inputs, in place.
void delta_decode(std::span<const std::uint8_t> reference, std::span<std::uint8_t> deltas);

}  // namespace detsim::net::protocol
