// Desync report files (desync_report.hpp; layout in replay/FORMAT.md).
#include <detsim/replay/desync_report.hpp>

#include <cstdio>
#include <memory>

#include <detsim/core/hash.hpp>
#include <detsim/sim/world.hpp>

#include "replay_detail.hpp"

namespace detsim::replay {
namespace {

constexpr char kMagic[9] = "DSDESYNC";
constexpr std::size_t kHeaderSize = 8 + 4 + 8;  // magic, version, payload size
constexpr std::size_t kTrailerSize = 8;         // XXH3-64 of the payload

void write_bytes(ByteWriter& w, const std::vector<std::uint8_t>& bytes) {
  w.u64(bytes.size());
  w.raw(bytes);
}

void write_bodies(ByteWriter& w, const std::vector<BodyHash>& bodies) {
  w.u64(bodies.size());
  for (const BodyHash& b : bodies) {
    w.u32(b.id);
    w.u64(b.hash);
  }
}

// Sizes are checked against the bytes that remain before anything is allocated.
std::vector<std::uint8_t> read_bytes(ByteReader& r, const char* what) {
  const std::size_t at = r.offset();
  const std::uint64_t n = r.u64(what);
  if (!r.ok()) return {};
  if (n > r.remaining()) {
    r.fail_at(at, what, "a length within the file");
    return {};
  }
  const auto bytes = r.raw(static_cast<std::size_t>(n), what);
  return {bytes.begin(), bytes.end()};
}

std::vector<BodyHash> read_bodies(ByteReader& r, const char* what) {
  const std::size_t at = r.offset();
  const std::uint64_t n = r.u64(what);
  if (!r.ok()) return {};
  if (n > r.remaining() / 12) {
    r.fail_at(at, what, "a body count within the file");
    return {};
  }
  std::vector<BodyHash> bodies(static_cast<std::size_t>(n));
  std::uint32_t previous = 0;
  for (BodyHash& b : bodies) {
    const std::size_t id_at = r.offset();
    b.id = r.u32(what);
    b.hash = r.u64(what);
    if (r.ok() && (b.id == 0 || b.id <= previous))
      r.fail_at(id_at, what, "ascending nonzero body IDs");
    previous = b.id;
  }
  return bodies;
}

// Either none or every frame strictly between the agreed and the divergent frame, ascending.
void read_intermediate(ByteReader& r, DesyncReport& report) {
  const std::size_t at = r.offset();
  const std::uint64_t n = r.u64("intermediate state count");
  if (!r.ok()) return;
  const std::uint64_t between = report.divergent_frame - report.agreed_frame - 1;
  if (n != 0 && n != between) {
    r.fail_at(at, "intermediate state count",
              "0 or one per frame between the agreed and the divergent frame");
    return;
  }
  if (n > r.remaining() / 16) {
    r.fail_at(at, "intermediate state count", "a count within the file");
    return;
  }
  report.intermediate_states.resize(static_cast<std::size_t>(n));
  std::uint64_t expected = report.agreed_frame + 1;
  for (FrameState& f : report.intermediate_states) {
    const std::size_t frame_at = r.offset();
    f.frame = r.u64("intermediate state frame");
    if (r.ok() && f.frame != expected)
      r.fail_at(frame_at, "intermediate state frame", "consecutive frames after the agreed frame");
    f.state = read_bytes(r, "intermediate state");
    if (!r.ok()) return;
    ++expected;
  }
}

}  // namespace

Expected<std::vector<BodyHash>> body_hashes(const World& geometry,
                                            std::span<const std::uint8_t> state) {
  World world(geometry);
  if (Status s = world.restore(state); !s) return s;
  std::vector<BodyHash> out;
  for (const BodyId id : world.body_ids())
    out.push_back({id.value, world.body_hash(id).value()});
  return out;
}

Expected<std::vector<BodyHash>> body_hashes(std::span<const std::uint8_t> state) {
  return body_hashes(World(), state);
}

Status write_desync_report(const std::string& path, const DesyncReport& report) {
  ByteWriter payload;
  ByteWriter fingerprint;
  detail::write_fingerprint(report.fingerprint, fingerprint);
  write_bytes(payload, fingerprint.bytes());
  payload.u32(report.reporter);
  payload.u32(report.other);
  payload.u64(report.agreed_frame);
  payload.u64(report.divergent_frame);
  payload.u64(report.local_hash);
  payload.u64(report.remote_hash);
  write_bytes(payload, report.confirmed_frames);
  write_bytes(payload, report.agreed_state);
  write_bytes(payload, report.divergent_state);
  write_bodies(payload, report.agreed_bodies);
  write_bodies(payload, report.divergent_bodies);
  payload.u8(static_cast<std::uint8_t>(report.origin));
  payload.u64(report.intermediate_states.size());
  for (const FrameState& f : report.intermediate_states) {
    payload.u64(f.frame);
    write_bytes(payload, f.state);
  }

  ByteWriter file;
  file.raw({reinterpret_cast<const std::uint8_t*>(kMagic), 8});
  file.u32(desync_report_version);
  file.u64(payload.size());
  file.raw(payload.bytes());
  file.u64(hash_bytes(payload.bytes()));

  std::unique_ptr<std::FILE, int (*)(std::FILE*)> out(std::fopen(path.c_str(), "wb"), &std::fclose);
  if (!out) return Status::error("desync report " + path + ": cannot create the file");
  if (std::fwrite(file.bytes().data(), 1, file.size(), out.get()) != file.size() ||
      std::fflush(out.get()) != 0)
    return Status::error("desync report " + path + ": write failed");
  return Status::success();
}

Expected<DesyncReport> parse_desync_report(std::span<const std::uint8_t> bytes,
                                           const std::string& name) {
  const auto fail = [&](std::size_t offset, const std::string& what) {
    return Status::error("desync report " + name + ": byte " + std::to_string(offset) + ": " +
                         what);
  };
  if (bytes.size() < kHeaderSize + kTrailerSize)
    return fail(bytes.size(), "the file ends before its header and checksum (" +
                                  std::to_string(kHeaderSize + kTrailerSize) + " bytes)");
  if (!std::equal(bytes.begin(), bytes.begin() + 8, kMagic))
    return fail(0, "expected the magic \"DSDESYNC\" (not a desync report)");
  ByteReader head(bytes.subspan(8, 12));
  const std::uint32_t version = head.u32("version");
  const std::uint64_t size = head.u64("payload size");
  if (version != 1 && version != desync_report_version)
    return fail(8, "version " + std::to_string(version) + ", this build reads version " +
                       std::to_string(desync_report_version) + " (and version 1)");
  if (size != bytes.size() - kHeaderSize - kTrailerSize)
    return fail(12, "payload size " + std::to_string(size) + ", but the file holds " +
                        std::to_string(bytes.size() - kHeaderSize - kTrailerSize) +
                        " payload bytes (truncated or extended)");
  // size equals what the file holds (checked above), so it fits size_t on every target.
  const std::span<const std::uint8_t> payload =
      bytes.subspan(kHeaderSize, static_cast<std::size_t>(size));
  ByteReader trailer(bytes.last(kTrailerSize));
  if (trailer.u64("checksum") != hash_bytes(payload))
    return fail(bytes.size() - kTrailerSize,
                "the payload's XXH3 checksum does not match (corrupted)");

  DesyncReport report;
  ByteReader r(payload);
  const std::vector<std::uint8_t> fingerprint = read_bytes(r, "fingerprint");
  if (r.ok()) {
    ByteReader fr(fingerprint);
    if (!detail::read_fingerprint(fr, report.fingerprint))
      return fail(kHeaderSize + 8 + fr.error_offset(), fr.error_detail());
  }
  report.reporter = r.u32("reporter");
  report.other = r.u32("other player");
  report.agreed_frame = r.u64("agreed frame");
  const std::size_t divergent_at = r.offset();
  report.divergent_frame = r.u64("divergent frame");
  if (r.ok() && report.divergent_frame <= report.agreed_frame)
    r.fail_at(divergent_at, "divergent frame", "a frame after the agreed frame");
  report.local_hash = r.u64("local hash");
  report.remote_hash = r.u64("remote hash");
  const std::size_t frames_at = r.offset();
  report.confirmed_frames = read_bytes(r, "confirmed frames");
  const std::uint64_t unit =
      1 + std::uint64_t{report.fingerprint.players} * report.fingerprint.input_size;
  if (r.ok() && report.confirmed_frames.size() % unit != 0)
    r.fail_at(frames_at, "confirmed frames", "whole frames of 1 + players * input size bytes");
  if (r.ok() && report.confirmed_frames.size() / unit != report.divergent_frame)
    r.fail_at(frames_at, "confirmed frames", "one frame per step before the divergent frame");
  report.agreed_state = read_bytes(r, "agreed state");
  report.divergent_state = read_bytes(r, "divergent state");
  report.agreed_bodies = read_bodies(r, "agreed body hashes");
  report.divergent_bodies = read_bodies(r, "divergent body hashes");
  if (version >= 2) {
    const std::size_t origin_at = r.offset();
    const std::uint8_t origin = r.u8("origin");
    if (r.ok() && origin > static_cast<std::uint8_t>(ReportOrigin::verify))
      r.fail_at(origin_at, "origin", "0 (a session) or 1 (verify)");
    report.origin = static_cast<ReportOrigin>(origin);
    read_intermediate(r, report);
  }
  if (r.ok() && !r.at_end()) r.fail("report", "no bytes after the last field");
  if (!r.ok()) return fail(kHeaderSize + r.error_offset(), r.error_detail());
  return report;
}

Expected<DesyncReport> read_desync_report(const std::string& path) {
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> in(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!in) return Status::error("desync report " + path + ": cannot open the file");
  std::vector<std::uint8_t> bytes;
  std::uint8_t buffer[1 << 16];
  std::size_t n = 0;
  while ((n = std::fread(buffer, 1, sizeof buffer, in.get())) > 0) {
    if (bytes.size() + n > max_desync_report_size)
      return Status::error("desync report " + path + ": larger than " +
                           std::to_string(max_desync_report_size >> 20) + " MiB, not read");
    bytes.insert(bytes.end(), buffer, buffer + n);
  }
  if (std::ferror(in.get())) return Status::error("desync report " + path + ": read failed");
  return parse_desync_report(bytes, path);
}

}  // namespace detsim::replay
