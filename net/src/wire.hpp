// Wire-format pieces shared by the session protocol (protocol.cpp) and the server protocol
// (server_protocol.cpp): a bounds-checked little-endian reader, LEB128 varints, frames relative
// to a reference frame, the XXH3 checksum of the plain framing, and the run-length coding of XOR
// deltas. Written by hand: the bytes are part of the determinism contract, and every read is
// checked before it is used.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <detsim/net/protocol.hpp>

namespace detsim::net::wire {

class Reader {
 public:
  explicit Reader(std::span<const std::uint8_t> bytes) noexcept : bytes_(bytes) {}

  [[nodiscard]] bool ok() const noexcept { return ok_; }
  [[nodiscard]] std::size_t remaining() const noexcept { return bytes_.size() - at_; }
  [[nodiscard]] bool at_end() const noexcept { return at_ == bytes_.size(); }

  std::uint64_t get(std::size_t n) noexcept {
    if (!ok_ || n > remaining()) {
      ok_ = false;
      return 0;
    }
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < n; ++i)
      v |= std::uint64_t{bytes_[at_ + i]} << (8 * i);
    at_ += n;
    return v;
  }
  std::uint8_t u8() noexcept { return static_cast<std::uint8_t>(get(1)); }
  std::uint16_t u16() noexcept { return static_cast<std::uint16_t>(get(2)); }
  std::uint32_t u32() noexcept { return static_cast<std::uint32_t>(get(4)); }
  std::uint64_t u64() noexcept { return get(8); }

  /// An unsigned LEB128 varint of at most 5 bytes (35 bits) in its shortest form; anything else
  /// sets `bad`, a datagram that ends inside one fails like any short read.
  std::uint64_t varint(bool& bad) noexcept {
    std::uint64_t v = 0;
    for (int i = 0; i < 5; ++i) {
      const std::uint8_t b = u8();
      if (!ok_) return 0;
      v |= std::uint64_t{b & 0x7FU} << (7 * i);
      if ((b & 0x80U) == 0) {
        if (b == 0 && i > 0) bad = true;  // a redundant trailing zero byte
        return v;
      }
    }
    bad = true;  // longer than any u32 frame distance needs
    return 0;
  }
  /// A frame written by put_frame against `ack`; `bad` when it falls outside u32.
  std::uint32_t frame(std::uint32_t ack, bool& bad) noexcept {
    const std::uint64_t z = varint(bad);
    const std::int64_t d =
        (z & 1U) != 0 ? -static_cast<std::int64_t>(z >> 1) - 1 : static_cast<std::int64_t>(z >> 1);
    const std::int64_t frame = std::int64_t{ack} + d;
    if (frame < 0 || frame > 0xFFFF'FFFFLL) {
      bad = true;
      return 0;
    }
    return static_cast<std::uint32_t>(frame);
  }

 private:
  std::span<const std::uint8_t> bytes_;
  std::size_t at_ = 0;
  bool ok_ = true;
};

/// LEB128: 7 bits per byte, low first; the top bit says another byte follows.
void put_varint(std::vector<std::uint8_t>& out, std::uint64_t v);
/// `frame` relative to `ack`, zigzag-coded: small distances either way are small numbers.
void put_frame(std::vector<std::uint8_t>& out, std::uint32_t frame, std::uint32_t ack);
/// The low `n` bytes of v, little-endian.
void put(std::vector<std::uint8_t>& out, std::uint64_t v, std::size_t n);
/// The low 32 bits of XXH3-64 over `bytes`: the plain framing's trailer.
[[nodiscard]] std::uint32_t checksum(std::span<const std::uint8_t> bytes) noexcept;
/// Run-length tokens over XOR deltas (wire.cpp says how), appended to `out`: n bytes never take
/// more than n + ceil(n / 128).
void run_length_encode(std::span<const std::uint8_t> bytes, std::vector<std::uint8_t>& out);
/// Decodes tokens from `in` until exactly `length` bytes are produced into `out`; false for a run
/// past `length` or a short read (never a write past the buffer).
[[nodiscard]] bool run_length_decode(Reader& in, std::size_t length,
                                     std::vector<std::uint8_t>& out);

/// A slice of a larger transfer (a snapshot): total v | offset v | length v | length bytes.
void put_slice(std::vector<std::uint8_t>& out, std::uint32_t total, std::uint32_t offset,
               std::span<const std::uint8_t> data);
/// Reads a slice, every bound checked before the copy: a total of 1 .. max_total, 1 .. max_chunk
/// bytes, lying inside the total. bad_length for a short read, bad_field for a bound.
[[nodiscard]] protocol::DecodeError read_slice(Reader& in, std::size_t max_total,
                                               std::size_t max_chunk, std::uint32_t& total,
                                               std::uint32_t& offset,
                                               std::vector<std::uint8_t>& data);

/// A plain framing: magic (2 bytes) | version | type (first_type .. last_type) | the rest of a
/// 14-byte header | body | the 4-byte checksum trailer. The session protocol's ("DN") and the
/// server protocol's ("DG").
struct PlainFraming {
  std::uint8_t magic0;
  std::uint8_t magic1;
  std::uint8_t version;
  std::uint8_t first_type;
  std::uint8_t last_type;
};

/// Checks a datagram's framing: its length (a 14-byte header and the trailer, at most
/// max_datagram), magic, version, type and checksum, in that order; DecodeError::none when all
/// hold (the header's other fields and the body are the caller's to read).
[[nodiscard]] protocol::DecodeError check_plain(std::span<const std::uint8_t> bytes,
                                                const PlainFraming& framing) noexcept;

}  // namespace detsim::net::wire
