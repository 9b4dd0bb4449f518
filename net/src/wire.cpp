// Wire-format pieces shared by both protocols (wire.hpp).
#include "wire.hpp"

#include <detsim/core/hash.hpp>

namespace detsim::net::wire {

// LEB128: 7 bits per byte, low first; the top bit says another byte follows.
void put_varint(std::vector<std::uint8_t>& out, std::uint64_t v) {
  while (v >= 0x80) {
    out.push_back(static_cast<std::uint8_t>(v | 0x80U));
    v >>= 7;
  }
  out.push_back(static_cast<std::uint8_t>(v));
}

// A frame relative to ack_frame, zigzag-coded: small distances either way are small numbers.
void put_frame(std::vector<std::uint8_t>& out, std::uint32_t frame, std::uint32_t ack) {
  const std::int64_t d = std::int64_t{frame} - std::int64_t{ack};
  put_varint(out, d >= 0 ? static_cast<std::uint64_t>(d) << 1
                         : (static_cast<std::uint64_t>(-(d + 1)) << 1) | 1U);
}

void put(std::vector<std::uint8_t>& out, std::uint64_t v, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i)
    out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}

std::uint32_t checksum(std::span<const std::uint8_t> bytes) noexcept {
  return static_cast<std::uint32_t>(hash_bytes(bytes));
}

// Run-length tokens over the XOR deltas: t < 128 -> t + 1 literals follow; t >= 128 -> t - 127
// zero bytes. Inputs are small and mostly unchanged between frames, so zero runs dominate.
//
// A lone zero between non-zero bytes stays inside the literal run: a token of its own would cost
// as much as the byte and the literal after it another token (x 0 x 0 ... would take 1.5 bytes a
// byte). So a zero token is only written for a zero run that saves bytes, and n bytes never take
// more than n + ceil(n / 128): what the session's packet budget (count * (input_size + 1)) assumes.
void run_length_encode(std::span<const std::uint8_t> bytes, std::vector<std::uint8_t>& out) {
  std::size_t i = 0;
  while (i < bytes.size()) {
    if (bytes[i] == 0) {
      std::size_t run = 1;
      while (i + run < bytes.size() && bytes[i + run] == 0 && run < 128)
        ++run;
      out.push_back(static_cast<std::uint8_t>(127 + run));
      i += run;
    } else {
      std::size_t run = 1;
      while (i + run < bytes.size() && run < 128 &&
             (bytes[i + run] != 0 || (i + run + 1 < bytes.size() && bytes[i + run + 1] != 0)))
        ++run;
      out.push_back(static_cast<std::uint8_t>(run - 1));
      out.insert(out.end(), bytes.begin() + static_cast<std::ptrdiff_t>(i),
                 bytes.begin() + static_cast<std::ptrdiff_t>(i + run));
      i += run;
    }
  }
}

// Decodes tokens until exactly `length` bytes are produced; a run that would pass `length` is
// a bad field, never a write past the buffer.
bool run_length_decode(Reader& in, std::size_t length, std::vector<std::uint8_t>& out) {
  out.assign(length, 0);
  std::size_t at = 0;
  while (at < length) {
    const std::uint8_t token = in.u8();
    if (!in.ok()) return false;
    if (token >= 128) {
      const std::size_t run = token - 127U;
      if (run > length - at) return false;
      at += run;  // already zero
    } else {
      const std::size_t run = token + 1U;
      if (run > length - at || run > in.remaining()) return false;
      for (std::size_t k = 0; k < run; ++k)
        out[at + k] = in.u8();
      at += run;
    }
  }
  return true;
}

void put_slice(std::vector<std::uint8_t>& out, std::uint32_t total, std::uint32_t offset,
               std::span<const std::uint8_t> data) {
  put_varint(out, total);
  put_varint(out, offset);
  put_varint(out, data.size());
  out.insert(out.end(), data.begin(), data.end());
}

protocol::DecodeError read_slice(Reader& in, std::size_t max_total, std::size_t max_chunk,
                                 std::uint32_t& total, std::uint32_t& offset,
                                 std::vector<std::uint8_t>& data) {
  using protocol::DecodeError;
  bool bad = false;
  const std::uint64_t t = in.varint(bad);
  const std::uint64_t o = in.varint(bad);
  const std::uint64_t length = in.varint(bad);
  if (!in.ok()) return DecodeError::bad_length;
  // Every bound before the copy: at most max_chunk bytes, inside the transfer.
  if (bad || t == 0 || t > max_total || length == 0 || length > max_chunk || o + length > t)
    return DecodeError::bad_field;
  total = static_cast<std::uint32_t>(t);
  offset = static_cast<std::uint32_t>(o);
  data.resize(static_cast<std::size_t>(length));
  for (std::uint8_t& b : data)
    b = in.u8();
  return DecodeError::none;
}

protocol::DecodeError check_plain(std::span<const std::uint8_t> bytes,
                                  const PlainFraming& f) noexcept {
  using protocol::DecodeError;
  constexpr std::size_t header = 14;
  constexpr std::size_t trailer = 4;
  if (bytes.size() > max_datagram) return DecodeError::too_long;
  if (bytes.size() < header + trailer) return DecodeError::too_short;
  if (bytes[0] != f.magic0 || bytes[1] != f.magic1) return DecodeError::bad_magic;
  if (bytes[2] != f.version) return DecodeError::bad_version;
  if (bytes[3] < f.first_type || bytes[3] > f.last_type) return DecodeError::bad_type;
  Reader sum(bytes.last(trailer));
  if (sum.u32() != checksum(bytes.first(bytes.size() - trailer))) return DecodeError::bad_checksum;
  return DecodeError::none;
}

}  // namespace detsim::net::wire
