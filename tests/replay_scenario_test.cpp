// Scenario replays: record -> verify for every scenario, verification names the first frame that
// differs, seeking restores a keyframe and re-simulates at most one interval, and fingerprints this
// build cannot reproduce are refused with the field named.
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/replay.hpp>

#include "support/replay_files.hpp"
#include "support/scenario_counts.hpp"

namespace detsim::replay {
namespace {

using test::chunks_of;
using test::read_bytes;
using test::TempFile;
using test::write_bytes;

Scenario make(const std::string& name, const ScenarioParams& params = {}) {
  auto s = Scenario::create(name, params);
  EXPECT_TRUE(s) << s.message();
  return std::move(s.value());
}

/// The hashes of an uninterrupted run with scripted inputs, frame 0 first.
std::vector<StateHashes> reference_run(const std::string& name, const ScenarioParams& params,
                                       std::uint64_t frames) {
  Scenario s = make(name, params);
  std::vector<StateHashes> out{s.world().hashes()};
  std::vector<PlayerInput> inputs(s.params().players);
  for (std::uint64_t f = 1; f <= frames; ++f) {
    for (std::uint32_t p = 0; p < inputs.size(); ++p)
      inputs[p] = scripted_input(s.params().seed, f, p);
    s.step(inputs);
    out.push_back(s.world().hashes());
  }
  return out;
}

TEST(ScenarioReplay, EveryScenarioRecordsAndVerifies) {
  for (const ScenarioInfo& info : scenario_list()) {
    SCOPED_TRACE(std::string(info.name));
    const ScenarioParams params{
        .seed = 9,
        .players = 0,
        .count = test::scenario_test_count(info, std::min(info.default_count, 27U))};
    Scenario scenario = make(std::string(info.name), params);
    const std::uint32_t frames = std::min<std::uint32_t>(info.default_frames, 90);
    TempFile file(std::string(info.name) + ".dsr");
    RecordOptions options;
    options.frames = frames;
    options.keyframe_interval = 40;
    auto recorded = record(scenario, file.path(), options);
    ASSERT_TRUE(recorded) << recorded.message();
    EXPECT_EQ(recorded->frames, frames);
    EXPECT_EQ(recorded->final_hash, scenario.world().hashes().total);

    auto reader = ReplayReader::open(file.path());
    ASSERT_TRUE(reader) << reader.message();
    EXPECT_EQ(reader->fingerprint(), fingerprint_of(make(std::string(info.name), params), 40));
    EXPECT_EQ(reader->frame_count(), frames);
    EXPECT_EQ(reader->keyframes().size(), frames / 40);
    ASSERT_TRUE(reader->chain_hash().has_value());
    EXPECT_EQ(*reader->chain_hash(), recorded->chain_hash);
    auto verified = verify(reader.value());
    ASSERT_TRUE(verified) << verified.message();
    EXPECT_TRUE(verified->ok) << verified->note;
    EXPECT_EQ(verified->frames, frames);
    EXPECT_FALSE(verified->first_mismatch.has_value());
    EXPECT_EQ(verified->final_hash, recorded->final_hash);
    EXPECT_TRUE(verified->note.empty()) << verified->note;

    // The recorded hashes are those of an uninterrupted run with the same inputs.
    const auto reference = reference_run(std::string(info.name), params, frames);
    EXPECT_EQ(reader->fingerprint().initial_hash, reference[0].total);
    ASSERT_TRUE(reader->for_each_frame(1, frames, [&](const FrameRecord& r) {
      EXPECT_EQ(r.hashes, reference[r.frame]) << "frame " << r.frame;
      return true;
    }));
  }
}

/// Rewrites frame `frame`'s record in the file with `edit`, resealing its chunk.
template <class Edit>
void edit_frame(const std::string& path, std::uint64_t frame, std::size_t record_size, Edit edit) {
  auto b = read_bytes(path);
  for (const auto& c : chunks_of(b)) {
    if (c.type != "FRAM") continue;
    const std::uint64_t first = test::get_u64(b, c.payload());
    const std::uint32_t count = test::get_u32(b, c.payload() + 8);
    if (frame < first || frame >= first + count) continue;
    edit(b, c.payload() + 12 + (frame - first) * record_size);
    test::reseal(b, c);
    write_bytes(path, b);
    return;
  }
  FAIL() << "no frame " << frame;
}

TEST(ScenarioReplay, VerifyNamesTheFirstFrameThatDiffers) {
  TempFile file("arena.dsr");
  Scenario scenario = make("arena", {.seed = 4, .players = 3});
  RecordOptions options;
  options.frames = 150;
  options.keyframe_interval = 50;
  ASSERT_TRUE(record(scenario, file.path(), options));
  const std::size_t record_size = 3 * 3 + 8 * (1 + 7);  // inputs, total and seven section hashes
  const auto original = read_bytes(file.path());

  // A recorded hash changed at frame 77 (the machine that recorded disagreed there).
  edit_frame(file.path(), 77, record_size, [&](std::vector<std::uint8_t>& b, std::size_t at) {
    b[at + 9] = static_cast<std::uint8_t>(b[at + 9] ^ 0x10U);  // first byte of the total hash
  });
  const auto verify_file = [&file] {
    auto reader = ReplayReader::open(file.path());
    EXPECT_TRUE(reader) << reader.message();
    auto v = verify(reader.value());
    EXPECT_TRUE(v) << v.message();
    EXPECT_FALSE(v->ok);
    EXPECT_TRUE(v->first_mismatch.has_value());
    return v.value();
  };
  VerifyResult v = verify_file();
  EXPECT_EQ(v.first_mismatch.value_or(0), 77U);
  EXPECT_EQ(v.frames, 77U);
  EXPECT_NE(v.expected.total, v.actual.total);
  EXPECT_EQ(v.expected.section("bodies"), v.actual.section("bodies"));  // only the total was edited

  // An input changed at frame 101: player 0 pushes the stick the other way from there.
  write_bytes(file.path(), original);
  edit_frame(file.path(), 101, record_size, [&](std::vector<std::uint8_t>& b, std::size_t at) {
    b[at + 1] = static_cast<std::uint8_t>(b[at + 1] == 127 ? 0x81 : 127);  // move_x
  });
  v = verify_file();
  EXPECT_EQ(v.first_mismatch.value_or(0), 101U);
  EXPECT_NE(v.expected.section("bodies"), v.actual.section("bodies"));
}

TEST(ScenarioReplay, SeekRestoresAKeyframeAndResimulatesAtMostOneInterval) {
  TempFile file("seek.dsr");
  const ScenarioParams params{.seed = 8, .players = 2};
  Scenario scenario = make("arena", params);
  RecordOptions options;
  options.frames = 130;
  options.keyframe_interval = 30;
  ASSERT_TRUE(record(scenario, file.path(), options));
  auto reader = ReplayReader::open(file.path());
  ASSERT_TRUE(reader) << reader.message();
  const auto reference = reference_run("arena", params, 130);
  for (std::uint64_t f : {0U, 1U, 29U, 30U, 31U, 59U, 60U, 89U, 120U, 129U, 130U}) {
    std::uint64_t resimulated = 0;
    auto at = seek(reader.value(), f, &resimulated);
    ASSERT_TRUE(at) << "frame " << f << ": " << at.message();
    EXPECT_EQ(at->world().frame(), f);
    EXPECT_EQ(at->world().hashes(), reference[f]) << "frame " << f;
    EXPECT_EQ(resimulated, f % 30) << "frame " << f;
  }
  const auto beyond = seek(reader.value(), 131);
  ASSERT_FALSE(beyond);
  EXPECT_NE(beyond.message().find("holds frames 0 to 130"), std::string::npos) << beyond.message();
}

TEST(ScenarioReplay, AKeyframeThatDisagreesWithItsHashIsReported) {
  TempFile file("keyframe.dsr");
  Scenario scenario = make("stack");
  RecordOptions options;
  options.frames = 40;
  options.keyframe_interval = 20;
  ASSERT_TRUE(record(scenario, file.path(), options));
  auto b = read_bytes(file.path());
  for (const auto& c : chunks_of(b)) {
    if (c.type != "KEYF") continue;
    b[c.end() - 20] = static_cast<std::uint8_t>(b[c.end() - 20] ^ 1U);  // inside the state
    test::reseal(b, c);
    break;
  }
  write_bytes(file.path(), b);
  auto reader = ReplayReader::open(file.path());
  ASSERT_TRUE(reader) << reader.message();
  auto v = verify(reader.value());
  ASSERT_FALSE(v);
  EXPECT_NE(v.message().find("the keyframe of frame 20 does not hash to its frame's recorded hash"),
            std::string::npos)
      << v.message();
}

/// A fingerprint written by hand: each field this build cannot reproduce is named.
TEST(ScenarioReplay, FingerprintsThisBuildCannotReproduceAreRefused) {
  const Fingerprint good = fingerprint_of(make("bounce"));
  const auto error_for = [&](const Fingerprint& f) {
    TempFile file("fp.dsr");
    {
      auto w = ReplayWriter::create(file.path(), f);
      EXPECT_TRUE(w) << w.message();
      if (w) {
        EXPECT_TRUE(w.value().finish());
      }
    }
    auto reader = ReplayReader::open(file.path());
    EXPECT_TRUE(reader) << reader.message();
    if (!reader) return std::string();
    auto v = verify(reader.value());
    EXPECT_FALSE(v);
    return v.message();
  };
  Fingerprint f = good;
  f.scenario = "nope";
  EXPECT_NE(error_for(f).find("scenario \"nope\" is not one of this program's scenarios"),
            std::string::npos);
  f = good;
  f.fixed_fraction_bits = 16;
  EXPECT_NE(error_for(f).find("recorded with Q48.16 numbers"), std::string::npos);
  f = good;
  f.state_version = state_encoding_version - 1;
  EXPECT_NE(error_for(f).find("recorded with state encoding " +
                              std::to_string(state_encoding_version - 1) +
                              " (its hashes and keyframes are of it), this build writes and reads "
                              "encoding " +
                              std::to_string(state_encoding_version)),
            std::string::npos)
      << error_for(f);
  f = good;
  f.input_size = 4;
  EXPECT_NE(error_for(f).find("inputs of 4 bytes"), std::string::npos);
  f = good;
  f.substeps = 8;
  EXPECT_NE(error_for(f).find("8 substeps x"), std::string::npos);
  f = good;
  f.dt = Fixed::from_int(1);
  EXPECT_NE(error_for(f).find("dt 1 (raw 4294967296)"), std::string::npos);

  // A different initial state is a mismatch at frame 0, not an error.
  f = good;
  f.initial_hash ^= 1;
  TempFile file("initial.dsr");
  {
    auto w = ReplayWriter::create(file.path(), f);
    ASSERT_TRUE(w);
    ASSERT_TRUE(w.value().finish());
  }
  auto reader = ReplayReader::open(file.path());
  ASSERT_TRUE(reader);
  auto v = verify(reader.value());
  ASSERT_TRUE(v) << v.message();
  EXPECT_FALSE(v->ok);
  ASSERT_TRUE(v->first_mismatch.has_value());
  EXPECT_EQ(*v->first_mismatch, 0U);
}

TEST(ScenarioReplay, RecordingOnlyRunsWithoutAPathAndRefusesAStartedScenario) {
  Scenario scenario = make("slope");
  RecordOptions options;
  options.frames = 30;
  auto run = record(scenario, "", options);
  ASSERT_TRUE(run) << run.message();
  EXPECT_EQ(scenario.world().frame(), 30U);
  EXPECT_EQ(run->final_hash, reference_run("slope", {}, 30).back().total);
  const auto again = record(scenario, "", options);
  ASSERT_FALSE(again);
  EXPECT_NE(again.message().find("at frame 30, expected frame 0"), std::string::npos);
}

}  // namespace
}  // namespace detsim::replay
