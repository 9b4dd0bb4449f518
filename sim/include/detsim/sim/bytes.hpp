// Canonical bytes: explicit little-endian, field by field, never a memcpy of a struct.
//
// ByteWriter appends; ByteReader reads with bounds checks and remembers the first failure (offset
// and what was expected), after which every read returns zero and fails. Callers read a whole
// record, then check `ok()` once — and check counts against `remaining()` before allocating.
#pragma once

#include <cstddef>
#include <cstdint>
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
  explicit ByteWriter(std::vector<std::uint8_t> buffer) noexcept : bytes_(std::move(buffer)) {
    bytes_.clear();
  }
  void u8(std::uint8_t v) { bytes_.push_back(v); }
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
  void raw(std::span<const std::uint8_t> data) {
    bytes_.insert(bytes_.end(), data.begin(), data.end());
  }

  [[nodiscard]] const std::vector<std::uint8_t>& bytes() const noexcept { return bytes_; }
  [[nodiscard]] std::vector<std::uint8_t> take() noexcept { return std::move(bytes_); }
  [[nodiscard]] std::size_t size() const noexcept { return bytes_.size(); }
  void clear() noexcept { bytes_.clear(); }
  void reserve(std::size_t n) { bytes_.reserve(n); }

 private:
  // One resize per field, then byte stores the compiler merges into one store on little-endian
  // hosts (a push_back per byte re-checked the capacity eight times per Fixed).
  void put(std::uint64_t v, int n) {
    const std::size_t at = bytes_.size();
    bytes_.resize(at + static_cast<std::size_t>(n));
    std::uint8_t* out = bytes_.data() + at;
    for (int i = 0; i < n; ++i)
      out[i] = static_cast<std::uint8_t>(v >> (8 * i));
  }
  std::vector<std::uint8_t> bytes_;
};

class ByteReader {
 public:
  explicit ByteReader(std::span<const std::uint8_t> data) noexcept : data_(data) {}

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
