// The replay file: chunk framing, the writer and the validating reader (replay/FORMAT.md).
//
// Layout: a 16-byte header ("DSREPLAY", format version, flags), then chunks. A chunk is its type
// (four ASCII bytes), its payload length (u32), the payload, and an XXH3-64 of those three. The
// reader accepts a file that ends inside a chunk (a recording cut short) and reports the ignored
// tail; any complete chunk that is malformed is an error.
#include <stdio.h>      // fmemopen, fseeko, ftello (POSIX)
#include <sys/types.h>  // off_t
#include <algorithm>

#include <cerrno>
#include <cstring>
#include <limits>
#include <new>
#include <utility>

#include <detsim/core/bytes.hpp>
#include <detsim/core/hash.hpp>
#include <detsim/replay/replay.hpp>

#include "replay_detail.hpp"

namespace detsim::replay {

namespace detail {

std::string hex64(std::uint64_t v) {
  static constexpr char digits[] = "0123456789abcdef";
  std::string s(16, '0');
  for (int i = 15; i >= 0; --i, v >>= 4)
    s[static_cast<std::size_t>(i)] = digits[v & 0xFU];
  return s;
}

std::string chunk_name(std::uint32_t type) {
  std::string s;
  for (int i = 0; i < 4; ++i) {
    const auto c = static_cast<char>((type >> (8 * i)) & 0xFFU);
    s += (c >= 0x20 && c < 0x7F) ? c : '?';
  }
  return s;
}

void write_fingerprint(const Fingerprint& f, ByteWriter& w) {
  const auto str = [&w](const std::string& s) {
    w.u8(static_cast<std::uint8_t>(s.size()));
    w.raw({reinterpret_cast<const std::uint8_t*>(s.data()), s.size()});
  };
  str(f.detsim_version);
  w.u32(f.fixed_fraction_bits);
  w.u32(f.state_version);
  w.u8(static_cast<std::uint8_t>(f.state_sections.size()));
  for (const std::string& name : f.state_sections)
    str(name);
  str(f.scenario);
  w.u64(f.params.seed);
  w.u32(f.params.players);
  w.u32(f.params.count);
  w.fixed(f.dt);
  w.u32(f.substeps);
  w.u32(f.iterations);
  w.u32(f.players);
  w.u32(f.input_size);
  w.u32(f.keyframe_interval);
  w.u64(f.initial_hash);
}

}  // namespace detail

std::uint64_t session_fingerprint(const Fingerprint& f, std::span<const std::uint8_t> match) {
  Fingerprint shared = f;
  shared.keyframe_interval = 0;
  ByteWriter w;
  w.raw({reinterpret_cast<const std::uint8_t*>("detsim session"), 14});
  detail::write_fingerprint(shared, w);
  w.raw(match);
  return hash_bytes(w.bytes());
}

namespace detail {

bool read_fingerprint(ByteReader& r, Fingerprint& f) {
  const auto str = [&r](const char* what) {
    const std::uint8_t n = r.u8(what);
    const auto bytes = r.raw(n, what);
    std::string s(bytes.begin(), bytes.end());
    for (const char c : s) {
      if (c < 0x20 || c > 0x7E) r.fail(what, "printable ASCII");
    }
    return s;
  };
  f.detsim_version = str("detsim version");
  f.fixed_fraction_bits = r.u32("Fixed fraction bits");
  f.state_version = r.u32("state encoding version");
  const std::size_t sections_at = r.offset();
  const std::uint8_t sections = r.u8("state section count");
  if (r.ok() && (sections == 0 || sections > max_state_sections))
    r.fail_at(sections_at, "state section count", "1..32");
  f.state_sections.clear();
  for (std::uint8_t i = 0; i < sections && r.ok(); ++i) {
    const std::size_t at = r.offset();
    f.state_sections.push_back(str("state section name"));
    if (r.ok() && !valid_section_name(f.state_sections.back()))
      r.fail_at(at, "state section name", "1..32 bytes of a-z, 0-9, '_' and '.'");
    for (std::size_t k = 0; r.ok() && k + 1 < f.state_sections.size(); ++k) {
      if (f.state_sections[k] == f.state_sections.back())
        r.fail_at(at, "state section name", "a name not listed before");
    }
  }
  f.scenario = str("scenario name");
  f.params.seed = r.u64("seed");
  f.params.players = r.u32("players parameter");
  f.params.count = r.u32("count parameter");
  f.dt = r.fixed("dt");
  f.substeps = r.u32("substeps");
  f.iterations = r.u32("iterations");
  const std::size_t players_at = r.offset();
  f.players = r.u32("player count");
  if (r.ok() && f.players > max_players) r.fail_at(players_at, "player count", "at most 64");
  const std::size_t size_at = r.offset();
  f.input_size = r.u32("input size");
  if (r.ok() && f.input_size > max_input_size)
    r.fail_at(size_at, "input size", "at most 1024 bytes");
  const std::size_t interval_at = r.offset();
  f.keyframe_interval = r.u32("keyframe interval");
  if (r.ok() && f.keyframe_interval == 0) r.fail_at(interval_at, "keyframe interval", "at least 1");
  f.initial_hash = r.u64("initial state hash");
  if (r.ok() && !r.at_end()) r.fail("fingerprint", "no bytes after the initial state hash");
  return r.ok();
}

void encode_hashes(const StateHashes& h, ByteWriter& w) {
  w.u64(h.total);
  for (const SectionHash& section : h.sections)
    w.u64(section.hash);
}

StateHashes decode_hashes(ByteReader& r, const std::vector<std::string>& sections) {
  StateHashes h;
  h.total = r.u64("frame hash");
  h.sections.reserve(sections.size());
  for (const std::string& name : sections)
    h.sections.push_back({name, r.u64("state section hash")});
  return h;
}

}  // namespace detail

using namespace detail;

// ---- HashChain ----------------------------------------------------------------------------------

struct HashChain::Impl {
  Hash64Stream stream;
};

HashChain::HashChain() : impl_(std::make_unique<Impl>()) {}
HashChain::HashChain(const HashChain& other) : impl_(std::make_unique<Impl>(*other.impl_)) {}
HashChain& HashChain::operator=(const HashChain& other) {
  if (this != &other) impl_->stream = other.impl_->stream;
  return *this;
}
HashChain::~HashChain() = default;

void HashChain::add(std::uint64_t frame_hash) noexcept {
  std::uint8_t bytes[8];
  for (int i = 0; i < 8; ++i)
    bytes[i] = static_cast<std::uint8_t>(frame_hash >> (8 * i));
  impl_->stream.update(bytes);
}

std::uint64_t HashChain::value() const noexcept {
  return impl_->stream.digest();
}

// ---- Files --------------------------------------------------------------------------------------

// File and FrameChunk are members of the writer's and reader's Impl, so they live in a named
// namespace (a unity build would otherwise warn of members of anonymous types).
namespace detail {

struct FileCloser {
  void operator()(std::FILE* f) const noexcept { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

/// A FRAM chunk: where its payload is and which frames it holds.
struct FrameChunk {
  std::uint64_t offset = 0;  ///< of the chunk
  std::uint32_t length = 0;  ///< payload bytes
  std::uint64_t first = 0;
  std::uint32_t count = 0;
};

}  // namespace detail

using detail::File;
using detail::FrameChunk;

namespace {

std::string os_error() {
  return std::strerror(errno);
}

bool known_chunk(std::uint32_t type) {
  return type == kChunkHead || type == kChunkFrames || type == kChunkKeyframe || type == kChunkEnd;
}

}  // namespace

// ---- Writer -------------------------------------------------------------------------------------

struct ReplayWriter::Impl {
  File file;
  std::string path;
  Fingerprint fingerprint;
  std::uint64_t frames = 0;
  std::uint64_t last_keyframe = 0;
  bool has_keyframe = false;
  ByteWriter pending;  ///< FRAM payload after its first-frame and count fields
  std::uint32_t pending_count = 0;
  HashChain chain;
  bool finished = false;

  Status fail(const std::string& what) const { return Status::error(path + ": " + what); }

  Status write_chunk(std::uint32_t type, std::span<const std::uint8_t> payload) {
    ByteWriter w;
    w.reserve(payload.size() + 16);
    w.u32(type);
    w.u32(static_cast<std::uint32_t>(payload.size()));
    w.raw(payload);
    w.u64(hash_bytes(w.bytes()));
    if (std::fwrite(w.bytes().data(), 1, w.size(), file.get()) != w.size() ||
        std::fflush(file.get()) != 0)
      return fail("cannot write: " + os_error());
    return Status::success();
  }

  Status flush_frames() {
    if (pending_count == 0) return Status::success();
    ByteWriter w;
    w.reserve(pending.size() + 12);
    w.u64(frames - pending_count + 1);
    w.u32(pending_count);
    w.raw(pending.bytes());
    pending.clear();
    pending_count = 0;
    return write_chunk(kChunkFrames, w.bytes());
  }
};

ReplayWriter::ReplayWriter(std::unique_ptr<Impl> impl) noexcept : impl_(std::move(impl)) {}
ReplayWriter::ReplayWriter(ReplayWriter&&) noexcept = default;
ReplayWriter& ReplayWriter::operator=(ReplayWriter&&) noexcept = default;

ReplayWriter::~ReplayWriter() {
  if (impl_ && impl_->file && !impl_->finished) (void)impl_->flush_frames();
}

Expected<ReplayWriter> ReplayWriter::create(const std::string& path,
                                            const Fingerprint& fingerprint) {
  if (fingerprint.players > max_players || fingerprint.input_size > max_input_size)
    return Status::error(path + ": fingerprint: at most 64 players and 1024 bytes per input");
  if (fingerprint.keyframe_interval == 0)
    return Status::error(path + ": fingerprint: the keyframe interval must be at least 1");
  if (fingerprint.state_sections.empty() || fingerprint.state_sections.size() > max_state_sections)
    return Status::error(path + ": fingerprint: the state has 1 to 32 sections, listed " +
                         std::to_string(fingerprint.state_sections.size()));
  for (const std::string& name : fingerprint.state_sections) {
    if (!valid_section_name(name))
      return Status::error(path + ": fingerprint: \"" + name + "\" is not a section name");
  }
  if (fingerprint.detsim_version.size() > 255 || fingerprint.scenario.size() > 255)
    return Status::error(path + ": fingerprint: names are at most 255 bytes");
  auto impl = std::make_unique<Impl>();
  impl->path = path;
  impl->fingerprint = fingerprint;
  impl->file.reset(std::fopen(path.c_str(), "wb"));
  if (!impl->file) return Status::error(path + ": cannot create: " + os_error());
  ByteWriter header;
  header.raw({reinterpret_cast<const std::uint8_t*>(kFileMagic), 8});
  header.u32(format_version);
  header.u32(0);  // flags
  if (std::fwrite(header.bytes().data(), 1, header.size(), impl->file.get()) != header.size())
    return Status::error(path + ": cannot write: " + os_error());
  ByteWriter head;
  write_fingerprint(fingerprint, head);
  if (Status s = impl->write_chunk(kChunkHead, head.bytes()); !s) return s;
  return ReplayWriter(std::move(impl));
}

Status ReplayWriter::frame(std::span<const std::uint8_t> inputs, const StateHashes& hashes) {
  Impl& m = *impl_;
  if (m.finished) return m.fail("frame after finish()");
  const std::size_t expected = std::size_t{m.fingerprint.players} * m.fingerprint.input_size;
  if (inputs.size() != expected)
    return m.fail(
        "frame " + std::to_string(m.frames + 1) + ": expected " + std::to_string(expected) +
        " input bytes (" + std::to_string(m.fingerprint.players) + " players x " +
        std::to_string(m.fingerprint.input_size) + "), got " + std::to_string(inputs.size()));
  const std::vector<std::string>& sections = m.fingerprint.state_sections;
  bool same_sections = hashes.sections.size() == sections.size();
  for (std::size_t i = 0; same_sections && i < sections.size(); ++i)
    same_sections = hashes.sections[i].name == sections[i];
  if (!same_sections) {
    std::string got;
    for (const SectionHash& h : hashes.sections)
      got += (got.empty() ? "" : ", ") + h.name;
    const bool game = got.find("game") != std::string::npos ||
                      std::find(sections.begin(), sections.end(), "game") != sections.end();
    return m.fail("frame " + std::to_string(m.frames + 1) + ": the state's sections (" + got +
                  ") are not the fingerprint's" +
                  (game ? std::string(" (a game's own state must be set before the first frame, "
                                      "in its scenario's build, and kept for the run)")
                        : std::string()));
  }
  m.pending.raw(inputs);
  encode_hashes(hashes, m.pending);
  ++m.pending_count;
  ++m.frames;
  m.chain.add(hashes.total);
  if (m.pending_count == frames_per_chunk) return m.flush_frames();
  return Status::success();
}

Status ReplayWriter::keyframe(std::uint64_t frame, std::span<const std::uint8_t> state) {
  Impl& m = *impl_;
  if (m.finished) return m.fail("keyframe after finish()");
  if (frame != m.frames)
    return m.fail("keyframe at frame " + std::to_string(frame) + ": keyframes are of the last " +
                  "frame appended, " + std::to_string(m.frames));
  if (m.has_keyframe && frame <= m.last_keyframe)
    return m.fail("keyframe at frame " + std::to_string(frame) + " repeats frame " +
                  std::to_string(m.last_keyframe));
  if (state.size() + 8 > max_chunk_payload)
    return m.fail("keyframe at frame " + std::to_string(frame) + ": " +
                  std::to_string(state.size()) + " state bytes exceed the chunk limit");
  if (Status s = m.flush_frames(); !s) return s;
  ByteWriter w;
  w.reserve(state.size() + 8);
  w.u64(frame);
  w.raw(state);
  if (Status s = m.write_chunk(kChunkKeyframe, w.bytes()); !s) return s;
  m.last_keyframe = frame;
  m.has_keyframe = true;
  return Status::success();
}

Status ReplayWriter::finish() {
  Impl& m = *impl_;
  if (m.finished) return m.fail("finish() called twice");
  if (Status s = m.flush_frames(); !s) return s;
  ByteWriter w;
  w.u64(m.frames);
  w.u64(m.chain.value());
  if (Status s = m.write_chunk(kChunkEnd, w.bytes()); !s) return s;
  m.finished = true;
  if (std::fclose(m.file.release()) != 0) return m.fail("cannot close: " + os_error());
  return Status::success();
}

std::uint64_t ReplayWriter::frames() const noexcept {
  return impl_->frames;
}
const std::string& ReplayWriter::path() const noexcept {
  return impl_->path;
}

// ---- Reader -------------------------------------------------------------------------------------

struct ReplayReader::Impl {
  std::vector<std::uint8_t> memory;  ///< the bytes of a replay read from memory
  File file;
  std::string path;
  std::uint64_t size = 0;
  Fingerprint fingerprint;
  std::vector<FrameChunk> chunks;
  std::vector<KeyframeInfo> keyframes;
  std::uint64_t frames = 0;
  bool complete = false;
  std::uint64_t chain = 0;
  std::uint64_t ignored = 0;
  std::string tail_note;

  [[nodiscard]] std::size_t record_size() const noexcept { return input_bytes() + hash_bytes(); }
  [[nodiscard]] std::size_t input_bytes() const noexcept {
    return std::size_t{fingerprint.players} * fingerprint.input_size;
  }
  /// The state's hash, then one per section.
  [[nodiscard]] std::size_t hash_bytes() const noexcept {
    return 8 * (1 + fingerprint.state_sections.size());
  }

  Status error_at(std::uint64_t offset, const std::string& what) const {
    return Status::error(path + ": byte " + std::to_string(offset) + ": " + what);
  }

  bool read_at(std::uint64_t offset, std::uint8_t* out, std::size_t n) const {
    if (offset > static_cast<std::uint64_t>(std::numeric_limits<off_t>::max())) return false;
    if (fseeko(file.get(), static_cast<off_t>(offset), SEEK_SET) != 0) return false;
    return std::fread(out, 1, n, file.get()) == n;
  }

  /// Reads the complete chunk at `offset` (whose header was validated) and checks its checksum.
  Expected<std::vector<std::uint8_t>> read_chunk(std::uint64_t offset, std::uint32_t type,
                                                 std::uint32_t length) const {
    std::vector<std::uint8_t> bytes(std::size_t{length} + 16);
    if (!read_at(offset, bytes.data(), bytes.size()))
      return error_at(offset, "cannot read the chunk (" + os_error() + ")");
    ByteReader r(bytes);
    const std::uint32_t t = r.u32("type");
    const std::uint32_t n = r.u32("length");
    if (t != type || n != length)
      return error_at(offset, "the chunk changed since the file was opened");
    const std::size_t body = std::size_t{length} + 8;
    std::uint64_t stored = 0;
    for (int i = 0; i < 8; ++i)
      stored |= std::uint64_t{bytes[body + static_cast<std::size_t>(i)]} << (8 * i);
    const std::uint64_t computed = detsim::hash_bytes({bytes.data(), body});
    if (stored != computed)
      return error_at(offset, "chunk " + chunk_name(type) + " of " + std::to_string(length) +
                                  " bytes: checksum " + hex64(stored) +
                                  " stored, the bytes hash to " + hex64(computed) +
                                  " (the chunk is corrupt)");
    bytes.erase(bytes.begin() + static_cast<std::ptrdiff_t>(body), bytes.end());
    bytes.erase(bytes.begin(), bytes.begin() + 8);
    return bytes;
  }

  Status scan();
  Status parse_frames(std::uint64_t offset, std::span<const std::uint8_t> payload);
  Status parse_keyframe(std::uint64_t offset, std::span<const std::uint8_t> payload);
  Status parse_end(std::uint64_t offset, std::span<const std::uint8_t> payload);
};

Status ReplayReader::Impl::scan() {
  if (size < kFileHeaderSize)
    return Status::error(path + ": " + std::to_string(size) + " bytes, shorter than the " +
                         std::to_string(kFileHeaderSize) + "-byte replay header");
  std::uint8_t header[kFileHeaderSize];
  if (!read_at(0, header, sizeof header)) return error_at(0, "cannot read (" + os_error() + ")");
  if (std::memcmp(header, kFileMagic, 8) != 0)
    return error_at(0, "expected the magic \"DSREPLAY\" (this is not a detsim replay)");
  ByteReader hr({header + 8, 8});
  const std::uint32_t version = hr.u32("format version");
  const std::uint32_t flags = hr.u32("flags");
  if (version != format_version)
    return error_at(8, "format version " + std::to_string(version) + ", this build reads " +
                           std::to_string(format_version));
  if (flags != 0) return error_at(12, "flags " + std::to_string(flags) + ", expected 0");

  bool have_head = false;
  std::uint64_t offset = kFileHeaderSize;
  while (offset < size) {
    const std::uint64_t remaining = size - offset;
    if (remaining < 16) {
      ignored = remaining;
      tail_note = "the last " + std::to_string(remaining) +
                  " bytes are not a whole chunk (the recording stopped early)";
      break;
    }
    std::uint8_t head[8];
    if (!read_at(offset, head, sizeof head))
      return error_at(offset, "cannot read (" + os_error() + ")");
    ByteReader cr(head);
    const std::uint32_t type = cr.u32("type");
    const std::uint32_t length = cr.u32("length");
    if (length > max_chunk_payload)
      return error_at(offset, "chunk " + chunk_name(type) + " declares " + std::to_string(length) +
                                  " payload bytes, more than the limit of " +
                                  std::to_string(max_chunk_payload));
    if (std::uint64_t{length} + 16 > remaining) {
      ignored = remaining;
      tail_note = "the chunk " + chunk_name(type) + " at byte " + std::to_string(offset) +
                  " declares " + std::to_string(length) + " payload bytes but only " +
                  std::to_string(remaining) +
                  " bytes remain with its header and checksum (the recording stopped early)";
      break;
    }
    auto chunk = read_chunk(offset, type, length);
    if (!chunk) return chunk.status();
    const std::span<const std::uint8_t> payload = chunk.value();
    if (!have_head && type != kChunkHead)
      return error_at(offset,
                      "chunk " + chunk_name(type) + ": expected the fingerprint chunk HEAD first");
    if (complete && known_chunk(type))  // only a later format's chunks may follow the end
      return error_at(offset, "chunk " + chunk_name(type) + " after the end marker");
    if (type == kChunkHead) {
      if (have_head) return error_at(offset, "a second fingerprint chunk HEAD");
      ByteReader r(payload);
      if (!read_fingerprint(r, fingerprint))
        return error_at(offset + 8 + r.error_offset(), "fingerprint: " + r.error_detail());
      have_head = true;
    } else if (type == kChunkFrames) {
      if (Status s = parse_frames(offset, payload); !s) return s;
    } else if (type == kChunkKeyframe) {
      if (Status s = parse_keyframe(offset, payload); !s) return s;
    } else if (type == kChunkEnd) {
      if (Status s = parse_end(offset, payload); !s) return s;
    }
    // Any other type is a later format's addition: skipped (its checksum was still checked).
    offset += std::uint64_t{length} + 16;
  }
  if (!have_head)
    return Status::error(path + ": no fingerprint chunk (the file holds only its header)");
  return Status::success();
}

Status ReplayReader::Impl::parse_frames(std::uint64_t offset,
                                        std::span<const std::uint8_t> payload) {
  ByteReader r(payload);
  const std::uint64_t first = r.u64("first frame");
  const std::uint32_t count = r.u32("frame count");
  if (!r.ok()) return error_at(offset + 8 + r.error_offset(), "frames: " + r.error_detail());
  if (first != frames + 1)
    return error_at(offset + 8, "frames chunk starts at frame " + std::to_string(first) +
                                    ", expected frame " + std::to_string(frames + 1));
  const std::uint64_t expected = 12 + std::uint64_t{count} * record_size();
  if (count == 0 || payload.size() != expected)
    return error_at(offset + 8 + 8, "frames chunk: " + std::to_string(count) + " frames of " +
                                        std::to_string(record_size()) +
                                        " bytes need a payload of " + std::to_string(expected) +
                                        " bytes, the chunk has " + std::to_string(payload.size()) +
                                        (count == 0 ? " (and no frames)" : ""));
  chunks.push_back({offset, static_cast<std::uint32_t>(payload.size()), first, count});
  frames += count;
  return Status::success();
}

Status ReplayReader::Impl::parse_keyframe(std::uint64_t offset,
                                          std::span<const std::uint8_t> payload) {
  ByteReader r(payload);
  const std::uint64_t frame = r.u64("keyframe frame");
  if (!r.ok()) return error_at(offset + 8 + r.error_offset(), "keyframe: " + r.error_detail());
  if (frame != frames)
    return error_at(offset + 8, "keyframe of frame " + std::to_string(frame) +
                                    ", expected the last frame recorded before it, " +
                                    std::to_string(frames));
  if (!keyframes.empty() && frame <= keyframes.back().frame)
    return error_at(offset + 8, "keyframe of frame " + std::to_string(frame) +
                                    " does not follow the keyframe of frame " +
                                    std::to_string(keyframes.back().frame));
  keyframes.push_back({frame, offset, static_cast<std::uint32_t>(payload.size() - 8)});
  return Status::success();
}

Status ReplayReader::Impl::parse_end(std::uint64_t offset, std::span<const std::uint8_t> payload) {
  ByteReader r(payload);
  const std::uint64_t count = r.u64("frame count");
  const std::uint64_t chain_hash = r.u64("chain hash");
  if (r.ok() && !r.at_end()) r.fail("end marker", "16 bytes");
  if (!r.ok()) return error_at(offset + 8 + r.error_offset(), "end marker: " + r.error_detail());
  if (count != frames)
    return error_at(offset + 8, "end marker counts " + std::to_string(count) +
                                    " frames, the file holds " + std::to_string(frames));
  complete = true;
  chain = chain_hash;
  return Status::success();
}

ReplayReader::ReplayReader(std::unique_ptr<Impl> impl) noexcept : impl_(std::move(impl)) {}
ReplayReader::ReplayReader(ReplayReader&&) noexcept = default;
ReplayReader& ReplayReader::operator=(ReplayReader&&) noexcept = default;
ReplayReader::~ReplayReader() = default;

Expected<ReplayReader> ReplayReader::open(const std::string& path) {
  auto impl = std::make_unique<Impl>();
  impl->path = path;
  impl->file.reset(std::fopen(path.c_str(), "rb"));
  if (!impl->file) return Status::error(path + ": cannot open: " + os_error());
  if (fseeko(impl->file.get(), 0, SEEK_END) != 0)
    return Status::error(path + ": cannot seek: " + os_error());
  const off_t size = ftello(impl->file.get());
  if (size < 0) return Status::error(path + ": not a regular file (" + os_error() + ")");
  impl->size = static_cast<std::uint64_t>(size);
  if (Status s = impl->scan(); !s) return s;
  return ReplayReader(std::move(impl));
}

Expected<ReplayReader> ReplayReader::from_bytes(std::vector<std::uint8_t> bytes,
                                                const std::string& name) {
  auto impl = std::make_unique<Impl>();
  impl->path = name;
  impl->size = bytes.size();
  if (bytes.empty()) {
    if (Status s = impl->scan(); !s) return s;  // names the missing header
  }
  impl->memory = std::move(bytes);
  impl->file.reset(fmemopen(impl->memory.data(), impl->memory.size(), "rb"));
  if (!impl->file) return Status::error(name + ": cannot read from memory: " + os_error());
  if (Status s = impl->scan(); !s) return s;
  return ReplayReader(std::move(impl));
}

const std::string& ReplayReader::path() const noexcept {
  return impl_->path;
}
const Fingerprint& ReplayReader::fingerprint() const noexcept {
  return impl_->fingerprint;
}
std::uint64_t ReplayReader::frame_count() const noexcept {
  return impl_->frames;
}
const std::vector<KeyframeInfo>& ReplayReader::keyframes() const noexcept {
  return impl_->keyframes;
}
bool ReplayReader::complete() const noexcept {
  return impl_->complete;
}
std::optional<std::uint64_t> ReplayReader::chain_hash() const noexcept {
  if (!impl_->complete) return std::nullopt;
  return impl_->chain;
}
std::uint64_t ReplayReader::ignored_tail_bytes() const noexcept {
  return impl_->ignored;
}
const std::string& ReplayReader::tail_note() const noexcept {
  return impl_->tail_note;
}
std::uint64_t ReplayReader::file_size() const noexcept {
  return impl_->size;
}

Status ReplayReader::for_each_frame(std::uint64_t first, std::uint64_t last,
                                    const std::function<bool(const FrameRecord&)>& visit) const {
  const Impl& m = *impl_;
  first = std::max<std::uint64_t>(first, 1);
  last = std::min(last, m.frames);
  if (first > last) return Status::success();
  // The first chunk whose last frame is >= first.
  auto it = std::lower_bound(
      m.chunks.begin(), m.chunks.end(), first,
      [](const FrameChunk& c, std::uint64_t f) { return c.first + c.count - 1 < f; });
  const std::size_t input_bytes = m.input_bytes();
  FrameRecord record;
  for (; it != m.chunks.end() && it->first <= last; ++it) {
    auto payload = m.read_chunk(it->offset, kChunkFrames, it->length);
    if (!payload) return payload.status();
    ByteReader r(payload.value());
    r.u64("first frame");
    r.u32("frame count");
    for (std::uint32_t i = 0; i < it->count; ++i) {
      record.frame = it->first + i;
      const auto inputs = r.raw(input_bytes, "inputs");
      record.hashes = decode_hashes(r, m.fingerprint.state_sections);
      if (!r.ok())
        return m.error_at(it->offset + 8 + r.error_offset(), "frames: " + r.error_detail());
      if (record.frame < first) continue;
      if (record.frame > last) return Status::success();
      record.inputs.assign(inputs.begin(), inputs.end());
      if (!visit(record)) return Status::success();
    }
  }
  return Status::success();
}

Expected<FrameRecord> ReplayReader::frame(std::uint64_t n) const {
  if (n == 0 || n > impl_->frames)
    return Status::error(impl_->path + ": no frame " + std::to_string(n) + " (the replay holds " +
                         "frames 1 to " + std::to_string(impl_->frames) + ")");
  FrameRecord out;
  if (Status s = for_each_frame(n, n,
                                [&out](const FrameRecord& r) {
                                  out = r;
                                  return false;
                                });
      !s)
    return s;
  return out;
}

Expected<std::vector<std::uint8_t>> ReplayReader::keyframe_state(const KeyframeInfo& k) const {
  auto payload = impl_->read_chunk(k.offset, kChunkKeyframe, k.size + 8);
  if (!payload) return payload.status();
  std::vector<std::uint8_t> state(payload.value().begin() + 8, payload.value().end());
  return state;
}

}  // namespace detsim::replay
