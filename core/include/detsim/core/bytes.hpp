// Canonical bytes: explicit little-endian, field by field, never a memcpy of a struct.
//
// Two kinds of number: fixed-width little-endian integers, and `var`s — unsigned LEB128 (seven bits
// per byte, lowest first, top bit = more follows), with Fixed written as the var of its zigzag form
// (v << 1) ^ (v >> 63) so that small magnitudes of either sign are short. The reader accepts only
// the shortest form of a var, so every value has exactly one encoding.
//
// ByteWriter appends; ByteReader reads with bounds checks and remembers the first failure (offset
// and what was expected), after which every read returns zero and fails. Callers read a whole
// record, then check `ok()` once — and check counts against `remaining()` before allocating.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/quat.hpp>
#include <detsim/fixed/vec3.hpp>

namespace detsim {

class ByteWriter {
 public:
  ByteWriter() = default;
  /// Writes into `buffer` from its start, reusing its capacity (a session saves every frame).
  explicit ByteWriter(std::vector<std::uint8_t> buffer) noexcept : bytes_(std::move(buffer)) {}
  void u8(std::uint8_t v) {
    *room(1) = v;
    ++size_;
  }
  void u16(std::uint16_t v) { put(v, 2); }
  void u32(std::uint32_t v) { put(v, 4); }
  void u64(std::uint64_t v) { put(v, 8); }
  void i64(std::int64_t v) { put(static_cast<std::uint64_t>(v), 8); }
  void boolean(bool v) { u8(v ? 1 : 0); }
  void fixed(Fixed v) { i64(v.raw()); }
  void vec3(Vec3 v) {
    fixed(v.x);
    fixed(v.y);
    fixed(v.z);
  }
  void quat(Quat q) {
    fixed(q.w);
    fixed(q.x);
    fixed(q.y);
    fixed(q.z);
  }
  /// Unsigned LEB128: 1 byte below 2^7, 2 below 2^14, ..., 10 for the top of the 64-bit range.
  void var(std::uint64_t v) {
    std::uint8_t* out = room(10);
    std::size_t n = 0;
    while (v >= 0x80U) {
      out[n++] = static_cast<std::uint8_t>(v | 0x80U);
      v >>= 7;
    }
    out[n++] = static_cast<std::uint8_t>(v);
    size_ += n;
  }
  void var_fixed(Fixed v) { var(zigzag(v.raw())); }
  void var_vec3(Vec3 v) {
    var_fixed(v.x);
    var_fixed(v.y);
    var_fixed(v.z);
  }
  void var_quat(Quat q) {
    var_fixed(q.w);
    var_fixed(q.x);
    var_fixed(q.y);
    var_fixed(q.z);
  }
  static constexpr std::uint64_t zigzag(std::int64_t v) noexcept {
    return (static_cast<std::uint64_t>(v) << 1) ^ static_cast<std::uint64_t>(v >> 63);
  }
  void raw(std::span<const std::uint8_t> data) {
    if (data.empty()) return;
    std::memcpy(room(data.size()), data.data(), data.size());
    size_ += data.size();
  }

  /// Overwrites the four bytes at `at` (written before) with `v`: a length known only after what
  /// it counts has been written.
  void patch_u32(std::size_t at, std::uint32_t v) noexcept {
    for (std::size_t i = 0; i < 4; ++i)
      bytes_[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
  }

  /// What was written (valid until the next write).
  [[nodiscard]] const std::vector<std::uint8_t>& bytes() const {
    bytes_.resize(size_);  // never more than it holds: no allocation
    return bytes_;
  }
  [[nodiscard]] std::vector<std::uint8_t> take() noexcept {
    bytes_.resize(size_);
    size_ = 0;
    return std::move(bytes_);
  }
  [[nodiscard]] std::size_t size() const noexcept { return size_; }
  void clear() noexcept { size_ = 0; }
  void reserve(std::size_t n) { bytes_.reserve(n); }

 private:
  // The vector's size is how far it has been grown (its bytes past size_ are scratch), so a field
  // is a bounds check and plain stores: no insert() or resize() call per field, which cost more
  // than the encoding itself when a state is hashed every frame.
  std::uint8_t* room(std::size_t n) {
    if (bytes_.size() - size_ < n) grow(n);
    return bytes_.data() + size_;
  }
  void grow(std::size_t n) {
    bytes_.resize(std::max({size_ + n, bytes_.capacity(), 2 * bytes_.size(), std::size_t{64}}));
  }
  void put(std::uint64_t v, int n) {
    std::uint8_t* out = room(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i)
      out[i] = static_cast<std::uint8_t>(v >> (8 * i));
    size_ += static_cast<std::size_t>(n);
  }
  mutable std::vector<std::uint8_t> bytes_;
  std::size_t size_ = 0;
};

class ByteReader {
 public:
  explicit ByteReader(std::span<const std::uint8_t> data) noexcept : data_(data) {}
  /// Reads data[offset..]: offsets in errors stay those of the whole of `data` (a part of a larger
  /// encoding read on its own, bounded by data's end). offset <= data.size().
  ByteReader(std::span<const std::uint8_t> data, std::size_t offset) noexcept
      : data_(data), offset_(offset) {}

  std::uint8_t u8(const char* what) noexcept { return static_cast<std::uint8_t>(get(1, what)); }
  std::uint16_t u16(const char* what) noexcept { return static_cast<std::uint16_t>(get(2, what)); }
  std::uint32_t u32(const char* what) noexcept { return static_cast<std::uint32_t>(get(4, what)); }
  std::uint64_t u64(const char* what) noexcept { return get(8, what); }
  std::int64_t i64(const char* what) noexcept { return static_cast<std::int64_t>(get(8, what)); }
  /// A bool byte: 0 or 1; any other value fails.
  bool boolean(const char* what) noexcept {
    const std::size_t at = offset_;
    const std::uint8_t v = u8(what);
    if (v > 1) fail_at(at, what, "0 or 1");
    return v == 1;
  }
  Fixed fixed(const char* what) noexcept { return Fixed::from_raw(i64(what)); }
  /// A var of at most `bits` bits (32 or 64): refused when longer than its shortest form or when
  /// the value does not fit.
  std::uint64_t var(const char* what, unsigned bits = 64) noexcept {
    if (!ok_) return 0;
    const std::size_t at = offset_;
    std::uint64_t v = 0;
    for (unsigned shift = 0;; shift += 7) {
      if (offset_ == data_.size()) {
        fail(what, "more bytes (the data ends here)");
        return 0;
      }
      const std::uint8_t byte = data_[offset_++];
      const std::uint64_t group = byte & 0x7FU;
      if (shift >= bits || (shift > 0 && (group >> (bits - shift)) != 0 && bits - shift < 7)) {
        fail_at(at, what, bits == 32 ? "a var of at most 32 bits" : "a var of at most 64 bits");
        return 0;
      }
      v |= group << shift;
      if ((byte & 0x80U) == 0) {
        if (byte == 0 && shift > 0) fail_at(at, what, "the shortest form of a var");
        return ok_ ? v : 0;
      }
    }
  }
  std::uint32_t var32(const char* what) noexcept {
    return static_cast<std::uint32_t>(var(what, 32));
  }
  Fixed var_fixed(const char* what) noexcept {
    const std::uint64_t z = var(what);
    return Fixed::from_raw(static_cast<std::int64_t>((z >> 1) ^ (~(z & 1U) + 1U)));
  }
  Vec3 var_vec3(const char* what) noexcept {
    const Fixed x = var_fixed(what);
    const Fixed y = var_fixed(what);
    return {x, y, var_fixed(what)};
  }
  Quat var_quat(const char* what) noexcept {
    const Fixed w = var_fixed(what);
    const Fixed x = var_fixed(what);
    const Fixed y = var_fixed(what);
    return {w, x, y, var_fixed(what)};
  }
  Vec3 vec3(const char* what) noexcept {
    const Fixed x = fixed(what);
    const Fixed y = fixed(what);
    return {x, y, fixed(what)};
  }
  Quat quat(const char* what) noexcept {
    const Fixed w = fixed(what);
    const Fixed x = fixed(what);
    const Fixed y = fixed(what);
    return {w, x, y, fixed(what)};
  }
  /// `n` raw bytes (empty and failing if fewer remain).
  std::span<const std::uint8_t> raw(std::size_t n, const char* what) noexcept {
    if (!ok_ || n > remaining()) {
      fail(what, "more bytes");
      return {};
    }
    const auto s = data_.subspan(offset_, n);
    offset_ += n;
    return s;
  }

  /// Records a semantic failure at the current offset: `what` was read but is not `expected`.
  /// Only the first failure is kept.
  void fail(const char* what, const char* expected) noexcept { fail_at(offset_, what, expected); }
  /// The same, naming the offset where the offending field starts.
  void fail_at(std::size_t offset, const char* what, const char* expected) noexcept {
    if (!ok_) return;
    ok_ = false;
    error_offset_ = offset;
    error_what_ = what;
    error_expected_ = expected;
  }

  [[nodiscard]] bool ok() const noexcept { return ok_; }
  [[nodiscard]] std::size_t offset() const noexcept { return offset_; }
  [[nodiscard]] std::size_t remaining() const noexcept { return data_.size() - offset_; }
  [[nodiscard]] bool at_end() const noexcept { return offset_ == data_.size(); }
  /// "byte 132: body orientation: expected a unit quaternion" or "" while ok().
  [[nodiscard]] std::string error() const;
  /// Where the first failure is, and what it is without the offset ("body orientation: expected a
  /// unit quaternion"), for callers that report offsets within a larger file.
  [[nodiscard]] std::size_t error_offset() const noexcept { return error_offset_; }
  [[nodiscard]] std::string error_detail() const;

 private:
  std::uint64_t get(std::size_t n, const char* what) noexcept {
    if (!ok_) return 0;
    if (n > remaining()) {
      fail(what, "more bytes (the data ends here)");
      return 0;
    }
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < n; ++i)
      v |= std::uint64_t{data_[offset_ + i]} << (8 * i);
    offset_ += n;
    return v;
  }

  std::span<const std::uint8_t> data_;
  std::size_t offset_ = 0;
  bool ok_ = true;
  std::size_t error_offset_ = 0;
  const char* error_what_ = "";
  const char* error_expected_ = "";
};

}  // namespace detsim
