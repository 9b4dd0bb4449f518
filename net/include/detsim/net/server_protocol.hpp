// The game-server wire protocol (docs/SERVER.md, "Protocol"): what one datagram between a
// net::Server and a net::Client carries, and its canonical little-endian encoding. The framing is
// the session protocol's plain one with its own magic ("DG"), so the two never read each other's
// datagrams:
//
//     header   magic "DG" | version u8 | type u8 | token u64 | sequence u16          (14 bytes)
//     body     by type (below)
//     trailer  low 32 bits of XXH3-64 over header and body                           (4 bytes)
//
// The token is the client's: 0 in a connect, then the 64 random bits (a CSPRNG) the server chose
// in its welcome, carried both ways. The server takes a datagram from a client only with the token
// and the transport peer (the address) it admitted; decode() checks every field first, so nothing
// malformed reaches either side.
//
//     connect    game u64 | nonce u64 | seat u8 (a player index, or any_seat)
//     welcome    nonce u64 | player u8 | players u8 | input_size u8 | authority u8 |
//                frame_us u32 | frames u32 | start_frame u32 | initial_hash u64 |
//                description v + bytes
//     reject     nonce u64 | reason u8
//     input      ack v | snapshot_ack z | time u32 | start z | count u8 | deltas
//     update     frame v | input_ack z | lead i8 | echo u32 | start z | count u8 | units |
//                hash u64 (count > 0 only)
//     snapshot   frame v | base z | hash u64 | total v | offset v | length v | bytes
//     leave      (empty)
//
// `v` is an unsigned LEB128 varint of at most 5 bytes; `z` a frame relative to the packet's first
// frame field (ack, frame), zigzag-coded — the session protocol's encodings (protocol.hpp).
//
// input: the client's own inputs for frames start .. start + count - 1 (every input the server
// has not acknowledged, resent until it has), XOR-chained (the first with zero) and run-length
// coded; `ack`: the client holds the match's units of every frame before it; `snapshot_ack`: the
// newest snapshot it holds whole, plus one (0: none); `time`: the client's clock in milliseconds,
// echoed by the server (round trips).
//
// update: the match's units of frames start .. start + count - 1, each a unit (a bit per player
// that is absent, then every player's input), XOR-chained from the unit of frame start - 1 (which
// the client holds: start is its ack) and run-length coded; `hash`: the server's state hash after
// the last of them (state frame start + count). `frame`: the server's next frame to simulate;
// `input_ack`: the server holds the client's inputs of every frame before it; `lead`: how many
// frames ahead of the server's simulation the client's newest input arrived (negative: late).
//
// snapshot: a slice of a snapshot of the server's state at frame `frame` (server_snapshot.hpp has
// the bytes), delta-coded against the client's snapshot of frame `base` - 1 (0: a full one).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string_view>
#include <vector>

#include <detsim/net/protocol.hpp>
#include <detsim/net/transport.hpp>

namespace detsim::net {

/// Per-client relevancy under Authority::state (ServerConfig::view, ClientConfig::view): the part
/// of a state (Game::save's bytes) that seat `player` is sent and checked against, written to
/// `out`. The same function on the server and on that client: the server sends the view of its
/// state, delta-coded against the view of the client's base, with the view's hash; the client
/// compares it with the view of its own state, and on a difference merges the server's view into
/// its own state (ClientConfig::merge_view) and loads that. What a partial state means is the
/// game's to say (a scene's far parts, a player's hidden cards).
using StateView = std::function<void(std::uint32_t player, std::span<const std::uint8_t> state,
                                     std::vector<std::uint8_t>& out)>;
/// The client's side of a view: `state` (a state this client saved) with `view` (the server's
/// view of its state at the same frame) put in, in place.
using MergeView =
    std::function<void(std::span<const std::uint8_t> view, std::vector<std::uint8_t>& state)>;

}  // namespace detsim::net

namespace detsim::net::server_protocol {

/// Changes whenever the layout above changes; a client of another version is dropped.
inline constexpr std::uint8_t version = 2;
inline constexpr std::uint8_t magic0 = 'D';
inline constexpr std::uint8_t magic1 = 'G';
inline constexpr std::size_t header_size = 14;
inline constexpr std::size_t trailer_size = 4;

/// The most players a server's match has (a unit's absent bits fit 16 bytes).
inline constexpr std::size_t max_players = 128;
/// The largest unit (absent bits and every player's input): it must fit one datagram whatever the
/// inputs are (a server refuses a match whose unit is larger).
inline constexpr std::size_t max_unit_size = 1024;
/// The most inputs or units one datagram carries.
inline constexpr std::size_t max_frames_per_packet = 255;
/// The longest game description a welcome carries.
inline constexpr std::size_t max_description = 512;
/// The most snapshot bytes one datagram carries, and the largest snapshot (encoded).
inline constexpr std::size_t max_snapshot_chunk = 1024;
inline constexpr std::size_t max_snapshot_size = std::size_t{64} << 20;
/// The seat byte of a connect that takes any free seat.
inline constexpr std::uint8_t any_seat = 0xFF;

enum class PacketType : std::uint8_t {
  connect = 1,
  welcome = 2,
  reject = 3,
  input = 4,
  update = 5,
  snapshot = 6,
  leave = 7,
};

/// Who decides what the clients' states are (docs/SERVER.md, "Authority").
enum class Authority : std::uint8_t {
  inputs = 0,  ///< the server's inputs and a hash: clients re-simulate a misprediction
  state = 1,   ///< the server's state, delta-coded: clients load it on a misprediction
};

/// Why a server turned a client away.
enum class RejectReason : std::uint8_t {
  wrong_game = 1,  ///< the connect's game fingerprint is not the server's
  full = 2,        ///< no free seat (or the seat asked for is taken)
  ended = 3,       ///< the match is over
};

inline constexpr std::size_t unit_size(std::size_t players, std::size_t input_size) noexcept {
  return (players + 7) / 8 + players * input_size;
}

struct Header {
  PacketType type = PacketType::connect;
  std::uint64_t token = 0;
  std::uint16_t sequence = 0;  ///< per direction, +1 per datagram (loss statistics)
};

struct Connect {
  std::uint64_t game = 0;   ///< the game's fingerprint: both sides must run the same game
  std::uint64_t nonce = 0;  ///< 64 random bits, echoed by the welcome or reject
  std::uint8_t seat = any_seat;
};

struct Welcome {
  std::uint64_t nonce = 0;
  std::uint8_t player = 0;
  std::uint8_t players = 0;
  std::uint8_t input_size = 0;
  Authority authority = Authority::inputs;
  std::uint32_t frame_us = 0;
  std::uint32_t frames = 0;        ///< the match's length in frames (0: open-ended)
  std::uint32_t start_frame = 0;   ///< 0: start from the game's initial state; else a snapshot's
  std::uint64_t initial_hash = 0;  ///< the hash of the server's state at frame 0
  std::vector<std::uint8_t> description;  ///< the game's own (the CLI: scenario, seed, players)
};

struct Reject {
  std::uint64_t nonce = 0;
  RejectReason reason = RejectReason::full;
};

struct ClientInput {
  std::uint32_t ack = 0;
  std::uint32_t snapshot_ack = 0;
  std::uint32_t time_ms = 0;
  std::uint32_t start = 0;
  std::uint8_t count = 0;
  std::vector<std::uint8_t> inputs;  ///< count * input_size, decoded (not XOR-coded)
};

struct Update {
  std::uint32_t frame = 0;
  std::uint32_t input_ack = 0;
  std::int8_t lead = 0;
  std::uint32_t echo_ms = 0;
  std::uint32_t start = 0;
  std::uint8_t count = 0;
  std::vector<std::uint8_t> units;  ///< count * unit_size, XOR-coded as on the wire
  std::uint64_t hash = 0;
};

struct SnapshotChunk {
  std::uint32_t frame = 0;
  std::uint32_t base = 0;  ///< the base snapshot's frame + 1; 0: a full snapshot
  std::uint64_t hash = 0;  ///< of the state
  std::uint32_t total = 0;
  std::uint32_t offset = 0;
  std::vector<std::uint8_t> data;
};

/// One decoded datagram. Only the body of `header.type` is meaningful.
struct Packet {
  Header header;
  Connect connect;
  Welcome welcome;
  Reject reject;
  ClientInput input;
  Update update;
  SnapshotChunk snapshot;
};

/// What a decoder on one side knows: the match's sizes (0 for a client not yet welcomed, which
/// then reads only welcomes and rejects; a server reads connects with any sizes).
struct Sizes {
  std::size_t players = 0;
  std::size_t input_size = 0;
};

using protocol::DecodeError;

/// Decodes `bytes`. On success fills `out` and returns DecodeError::none; otherwise `out` is
/// unspecified. Inputs and units are checked against `sizes`.
[[nodiscard]] DecodeError decode(std::span<const std::uint8_t> bytes, const Sizes& sizes,
                                 Packet& out);
/// Encodes `packet` into `out`, replacing its contents; false (out empty) when it would exceed
/// max_datagram or a field is inconsistent with `sizes` (a bug of the caller, never input).
[[nodiscard]] bool encode(const Packet& packet, const Sizes& sizes, std::vector<std::uint8_t>& out);

/// XOR-chains `units` (whole units of unit_size bytes) from `reference` (the unit before the
/// first), in place: what Update::units carries. unchain() is its inverse.
void chain(std::span<const std::uint8_t> reference, std::span<std::uint8_t> units) noexcept;
void unchain(std::span<const std::uint8_t> reference, std::span<std::uint8_t> units) noexcept;

}  // namespace detsim::net::server_protocol
