// Helpers for replay tests: temporary files, whole-file bytes, and a chunk walker that lets a test
// rewrite one chunk's payload with a valid checksum (to craft files that are well formed but
// wrong).
#pragma once

#include <unistd.h>  // getpid
#include <xxhash.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace detsim::test {

/// A file path under the system's temporary directory, removed when this goes out of scope.
class TempFile {
 public:
  explicit TempFile(const std::string& name) {
    static int counter = 0;
    path_ =
        (std::filesystem::temp_directory_path() / ("detsim_test_" + std::to_string(::getpid()) +
                                                   "_" + std::to_string(counter++) + "_" + name))
            .string();
  }
  ~TempFile() {
    std::error_code ignored;
    std::filesystem::remove(path_, ignored);
  }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  [[nodiscard]] const std::string& path() const { return path_; }

 private:
  std::string path_;
};

inline std::vector<std::uint8_t> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline void write_bytes(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
}

inline std::uint32_t get_u32(const std::vector<std::uint8_t>& b, std::size_t at) {
  return static_cast<std::uint32_t>(b[at]) | static_cast<std::uint32_t>(b[at + 1]) << 8 |
         static_cast<std::uint32_t>(b[at + 2]) << 16 | static_cast<std::uint32_t>(b[at + 3]) << 24;
}

inline void put_u32(std::vector<std::uint8_t>& b, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i)
    b[at + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(v >> (8 * i));
}

inline void put_u64(std::vector<std::uint8_t>& b, std::size_t at, std::uint64_t v) {
  for (int i = 0; i < 8; ++i)
    b[at + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(v >> (8 * i));
}

inline std::uint64_t get_u64(const std::vector<std::uint8_t>& b, std::size_t at) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i)
    v |= std::uint64_t{b[at + static_cast<std::size_t>(i)]} << (8 * i);
  return v;
}

/// One chunk of a replay file, as the bytes of the whole file locate it.
struct ChunkAt {
  std::size_t offset = 0;  ///< of its type field
  std::string type;
  std::uint32_t length = 0;
  [[nodiscard]] std::size_t payload() const { return offset + 8; }
  [[nodiscard]] std::size_t end() const { return offset + 16 + length; }
};

/// The complete chunks of a replay file's bytes (after the 16-byte header).
inline std::vector<ChunkAt> chunks_of(const std::vector<std::uint8_t>& b) {
  std::vector<ChunkAt> out;
  std::size_t at = 16;
  while (at + 16 <= b.size()) {
    ChunkAt c;
    c.offset = at;
    c.type.assign(b.begin() + static_cast<std::ptrdiff_t>(at),
                  b.begin() + static_cast<std::ptrdiff_t>(at + 4));
    c.length = get_u32(b, at + 4);
    if (c.end() > b.size()) break;
    out.push_back(c);
    at = c.end();
  }
  return out;
}

/// Recomputes the checksum of the chunk at `c` after its payload was edited in place.
inline void reseal(std::vector<std::uint8_t>& b, const ChunkAt& c) {
  put_u64(b, c.offset + 8 + c.length, XXH3_64bits(b.data() + c.offset, 8 + std::size_t{c.length}));
}

/// A whole chunk's bytes with a valid checksum.
inline std::vector<std::uint8_t> make_chunk(const char (&type)[5],
                                            const std::vector<std::uint8_t>& payload) {
  // Sized once: type, length, payload, checksum.
  std::vector<std::uint8_t> c(8 + payload.size() + 8);
  std::copy(type, type + 4, c.begin());
  put_u32(c, 4, static_cast<std::uint32_t>(payload.size()));
  std::copy(payload.begin(), payload.end(), c.begin() + 8);
  put_u64(c, 8 + payload.size(), XXH3_64bits(c.data(), 8 + payload.size()));
  return c;
}

}  // namespace detsim::test
