// Desync report files (replay/desync_report.hpp): a faithful round trip, and every damaged or
// hostile file refused with the byte offset and what was expected, without large allocations.
#include <gtest/gtest.h>

#include <xxhash.h>

#include <cstdio>
#include <fstream>
#include <iterator>

#include <detsim/replay/desync_report.hpp>
#include <detsim/replay/scenario_replay.hpp>

namespace detsim {
namespace {

std::string temp_path(const char* name) {
  std::string path = DETSIM_BINARY_DIR;
  path.append("/tests/desync_report_").append(name).append(".dsd");
  return path;
}

std::vector<std::uint8_t> file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// A small but real report: the `stack` scenario's states at frames 30 and 60.
replay::DesyncReport sample_report() {
  Scenario scenario = Scenario::create("stack").value();
  replay::DesyncReport r;
  r.fingerprint = replay::fingerprint_of(scenario);
  r.reporter = 1;
  r.other = 0;
  r.agreed_frame = 30;
  r.divergent_frame = 60;
  const std::size_t unit = 1 + std::size_t{r.fingerprint.players} * r.fingerprint.input_size;
  r.origin = replay::ReportOrigin::session;
  for (std::uint64_t f = 0; f < 60; ++f) {
    if (f == 30) r.agreed_state = scenario.world().save();
    if (f > 30) r.intermediate_states.push_back({f, scenario.world().save()});
    for (std::size_t i = 0; i < unit; ++i)
      r.confirmed_frames.push_back(static_cast<std::uint8_t>(f + i));
    scenario.step();
  }
  r.divergent_state = scenario.world().save();
  r.local_hash = scenario.world().hashes().total;
  r.remote_hash = r.local_hash ^ 1;
  r.agreed_bodies = replay::body_hashes(r.agreed_state).value();
  r.divergent_bodies = replay::body_hashes(r.divergent_state).value();
  return r;
}

TEST(DesyncReport, RoundTripsEveryField) {
  const replay::DesyncReport report = sample_report();
  ASSERT_EQ(report.agreed_bodies.size(), 11U);  // ten boxes and the ground plane
  ASSERT_TRUE(replay::write_desync_report(temp_path("round"), report).ok());
  auto back = replay::read_desync_report(temp_path("round"));
  ASSERT_TRUE(back.ok()) << back.message();
  EXPECT_EQ(back.value(), report);
  std::remove(temp_path("round").c_str());
}

TEST(DesyncReport, BodyHashesAreTheWorldsOwn) {
  Scenario scenario = Scenario::create("stack").value();
  for (int i = 0; i < 10; ++i)
    scenario.step();
  const auto hashes = replay::body_hashes(scenario.world().save()).value();
  const std::vector<BodyId> ids = scenario.world().body_ids();
  ASSERT_EQ(hashes.size(), ids.size());
  for (std::size_t i = 0; i < ids.size(); ++i) {
    EXPECT_EQ(hashes[i].id, ids[i].value);
    EXPECT_EQ(hashes[i].hash, scenario.world().body_hash(ids[i]).value());
  }
  const std::vector<std::uint8_t> junk(40, 7);
  auto bad = replay::body_hashes(junk);
  ASSERT_FALSE(bad.ok());
}

TEST(DesyncReport, EveryTruncationIsRefusedWithAnOffset) {
  ASSERT_TRUE(replay::write_desync_report(temp_path("trunc"), sample_report()).ok());
  const std::vector<std::uint8_t> bytes = file_bytes(temp_path("trunc"));
  std::remove(temp_path("trunc").c_str());
  for (std::size_t n = 0; n < bytes.size(); ++n) {
    auto r = replay::parse_desync_report(std::span(bytes.data(), n), "t.dsd");
    ASSERT_FALSE(r.ok()) << n;
    ASSERT_NE(r.message().find("desync report t.dsd: byte "), std::string::npos) << r.message();
  }
}

TEST(DesyncReport, CorruptionIsCaughtByTheChecksum) {
  ASSERT_TRUE(replay::write_desync_report(temp_path("flip"), sample_report()).ok());
  const std::vector<std::uint8_t> bytes = file_bytes(temp_path("flip"));
  std::remove(temp_path("flip").c_str());
  for (std::size_t at = 20; at < bytes.size(); at += 7) {
    std::vector<std::uint8_t> bad = bytes;
    bad[at] ^= 0x10;
    auto r = replay::parse_desync_report(bad, "f.dsd");
    ASSERT_FALSE(r.ok()) << at;
    EXPECT_NE(r.message().find("checksum"), std::string::npos) << r.message();
  }
  std::vector<std::uint8_t> magic = bytes;
  magic[0] = 'X';
  EXPECT_NE(replay::parse_desync_report(magic, "m").message().find("magic"), std::string::npos);
  std::vector<std::uint8_t> version = bytes;
  version[8] = 3;
  EXPECT_NE(replay::parse_desync_report(version, "v").message().find("version 3"),
            std::string::npos);
}

/// A file whose checksum is right but whose fields lie: built from a payload by hand.
std::vector<std::uint8_t> with_valid_checksum(const std::vector<std::uint8_t>& payload,
                                              std::uint8_t version = 2) {
  std::vector<std::uint8_t> file = {'D', 'S', 'D', 'E', 'S', 'Y', 'N', 'C', version, 0, 0, 0};
  for (int i = 0; i < 8; ++i)
    file.push_back(static_cast<std::uint8_t>(payload.size() >> (8 * i)));
  file.insert(file.end(), payload.begin(), payload.end());
  const std::uint64_t sum = XXH3_64bits(payload.data(), payload.size());
  for (int i = 0; i < 8; ++i)
    file.push_back(static_cast<std::uint8_t>(sum >> (8 * i)));
  return file;
}

TEST(DesyncReport, HostileLengthsAreRefusedBeforeAllocating) {
  // A fingerprint length of 2^62: must be refused from the bytes that remain, not allocated.
  std::vector<std::uint8_t> payload(8, 0);
  payload[7] = 0x40;
  payload.resize(64, 0);
  auto r = replay::parse_desync_report(with_valid_checksum(payload), "h.dsd");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.message().find("byte 20: fingerprint: expected a length within the file"),
            std::string::npos)
      << r.message();
  // A valid report whose body count is then inflated.
  ASSERT_TRUE(replay::write_desync_report(temp_path("count"), sample_report()).ok());
  std::vector<std::uint8_t> bytes = file_bytes(temp_path("count"));
  std::remove(temp_path("count").c_str());
  std::vector<std::uint8_t> body(bytes.begin() + 20, bytes.end() - 8);
  // From the end: the intermediate states (29 of them, each a frame and a length-prefixed state),
  // their count, the origin, the divergent bodies.
  const replay::DesyncReport sample = sample_report();
  std::size_t tail = 8 + 1;
  for (const replay::FrameState& f : sample.intermediate_states)
    tail += 16 + f.state.size();
  const std::size_t count_at = body.size() - tail - (8 + 11 * 12);  // the divergent bodies' count
  std::vector<std::uint8_t> inflated = body;
  inflated[count_at + 7] = 0x7F;
  r = replay::parse_desync_report(with_valid_checksum(inflated), "c.dsd");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.message().find("divergent body hashes: expected a body count within the file"),
            std::string::npos)
      << r.message();
  // An intermediate state count that is neither 0 nor the frames in between.
  std::vector<std::uint8_t> miscounted = body;
  miscounted[body.size() - tail + 1] = 28;
  r = replay::parse_desync_report(with_valid_checksum(miscounted), "i.dsd");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.message().find("intermediate state count: expected 0 or one per frame"),
            std::string::npos)
      << r.message();
  // An origin that is not one.
  std::vector<std::uint8_t> origin = body;
  origin[body.size() - tail] = 7;
  r = replay::parse_desync_report(with_valid_checksum(origin), "o.dsd");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.message().find("origin: expected 0 (a session) or 1 (verify)"), std::string::npos)
      << r.message();
}

TEST(DesyncReport, ConfirmedFramesMustCoverEveryStepBeforeTheDivergentFrame) {
  // What bounds the divergent frame (and what a reader allocates for it) by the file's size.
  replay::DesyncReport short_log = sample_report();
  const std::size_t unit = 1 + std::size_t{short_log.fingerprint.players} * 3;
  std::vector<std::uint8_t>& log = short_log.confirmed_frames;
  log.erase(log.end() - static_cast<std::ptrdiff_t>(unit), log.end());  // the last frame
  ASSERT_TRUE(replay::write_desync_report(temp_path("short"), short_log).ok());
  auto r = replay::read_desync_report(temp_path("short"));
  std::remove(temp_path("short").c_str());
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.message().find("confirmed frames: expected one frame per step before the divergent"),
            std::string::npos)
      << r.message();
}

TEST(DesyncReport, VersionOneReportsAreStillRead) {
  // Version 1 ends after the divergent bodies: no origin, no intermediate states.
  ASSERT_TRUE(replay::write_desync_report(temp_path("v1"), sample_report()).ok());
  std::vector<std::uint8_t> bytes = file_bytes(temp_path("v1"));
  std::remove(temp_path("v1").c_str());
  const replay::DesyncReport sample = sample_report();
  std::size_t tail = 8 + 1;
  for (const replay::FrameState& f : sample.intermediate_states)
    tail += 16 + f.state.size();
  std::vector<std::uint8_t> body(bytes.begin() + 20, bytes.end() - 8 - static_cast<long>(tail));
  auto r = replay::parse_desync_report(with_valid_checksum(body, 1), "v1.dsd");
  ASSERT_TRUE(r.ok()) << r.message();
  replay::DesyncReport expected = sample;
  expected.intermediate_states.clear();
  EXPECT_EQ(r.value(), expected);
  // The same bytes labelled version 2 lack the version 2 fields.
  EXPECT_FALSE(replay::parse_desync_report(with_valid_checksum(body, 2), "v2.dsd").ok());
}

TEST(DesyncReport, AMissingFileIsNamed) {
  auto r = replay::read_desync_report("/nonexistent/x.dsd");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.message().find("/nonexistent/x.dsd"), std::string::npos);
}

}  // namespace
}  // namespace detsim
