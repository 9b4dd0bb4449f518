// The replay file format: what the writer writes reads back exactly; truncated, corrupted and
// hostile files are refused with errors naming the file, the byte and what was expected, or (a
// recording cut short) read up to their last complete chunk; a recording killed with SIGKILL reads
// back and verifies.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/replay.hpp>

#include "support/replay_files.hpp"
#include "support/scale.hpp"

namespace detsim::replay {
namespace {

using test::ChunkAt;
using test::chunks_of;
using test::make_chunk;
using test::read_bytes;
using test::TempFile;
using test::write_bytes;

Fingerprint sample_fingerprint() {
  Fingerprint f;
  f.detsim_version = "0.1.0";
  f.state_version = 1;
  f.state_sections = {"globals", "rng", "bodies", "contacts"};
  f.scenario = "arena";
  f.params = {.seed = 42, .players = 2, .count = 0};
  f.dt = Fixed::from_raw(71582788);
  f.substeps = 4;
  f.iterations = 1;
  f.players = 2;
  f.input_size = 3;
  f.keyframe_interval = 50;
  f.initial_hash = 0x0123456789ABCDEFULL;
  return f;
}

/// A frame's synthetic inputs and hashes, a pure function of the frame number.
FrameRecord sample_frame(std::uint64_t frame) {
  FrameRecord r;
  r.frame = frame;
  for (std::uint8_t i = 0; i < 6; ++i)
    r.inputs.push_back(static_cast<std::uint8_t>(frame * 7 + i));
  r.hashes.total = frame * 0x9E3779B97F4A7C15ULL;
  r.hashes.sections = {
      {"globals", frame + 1}, {"rng", frame + 2}, {"bodies", frame + 3}, {"contacts", frame + 4}};
  return r;
}

std::vector<std::uint8_t> sample_state(std::uint64_t frame) {
  return std::vector<std::uint8_t>(100 + frame % 7, static_cast<std::uint8_t>(frame));
}

/// Writes `frames` sample frames with a keyframe every 50 frames; `finish` writes the end marker.
void write_sample(const std::string& path, std::uint64_t frames, bool finish = true) {
  auto writer = ReplayWriter::create(path, sample_fingerprint());
  ASSERT_TRUE(writer) << writer.message();
  for (std::uint64_t f = 1; f <= frames; ++f) {
    const FrameRecord r = sample_frame(f);
    ASSERT_TRUE(writer.value().frame(r.inputs, r.hashes));
    if (f % 50 == 0) {
      ASSERT_TRUE(writer.value().keyframe(f, sample_state(f)));
    }
  }
  if (finish) {
    const Status s = writer.value().finish();
    ASSERT_TRUE(s) << s.message();
  }
}

std::vector<FrameRecord> all_frames(const ReplayReader& reader) {
  std::vector<FrameRecord> out;
  const Status s = reader.for_each_frame(1, reader.frame_count(), [&](const FrameRecord& r) {
    out.push_back(r);
    return true;
  });
  EXPECT_TRUE(s) << s.message();
  return out;
}

void expect_sample_frames(const ReplayReader& reader) {
  const auto frames = all_frames(reader);
  ASSERT_EQ(frames.size(), reader.frame_count());
  for (const FrameRecord& r : frames) {
    const FrameRecord want = sample_frame(r.frame);
    EXPECT_EQ(r.inputs, want.inputs) << "frame " << r.frame;
    EXPECT_EQ(r.hashes, want.hashes) << "frame " << r.frame;
  }
}

TEST(ReplayFile, WhatIsWrittenReadsBackExactly) {
  TempFile file("roundtrip.dsr");
  write_sample(file.path(), 173);
  auto reader = ReplayReader::open(file.path());
  ASSERT_TRUE(reader) << reader.message();
  const ReplayReader& r = reader.value();
  EXPECT_EQ(r.fingerprint(), sample_fingerprint());
  EXPECT_EQ(r.frame_count(), 173U);
  EXPECT_TRUE(r.complete());
  EXPECT_EQ(r.ignored_tail_bytes(), 0U);
  expect_sample_frames(r);
  ASSERT_EQ(r.keyframes().size(), 3U);
  for (std::size_t i = 0; i < 3; ++i) {
    const KeyframeInfo& k = r.keyframes()[i];
    EXPECT_EQ(k.frame, 50 * (i + 1));
    auto state = r.keyframe_state(k);
    ASSERT_TRUE(state) << state.message();
    EXPECT_EQ(state.value(), sample_state(k.frame));
  }
  HashChain chain;
  for (std::uint64_t f = 1; f <= 173; ++f)
    chain.add(sample_frame(f).hashes.total);
  ASSERT_TRUE(r.chain_hash().has_value());
  EXPECT_EQ(*r.chain_hash(), chain.value());
  // Random access and ranges.
  auto f61 = r.frame(61);
  ASSERT_TRUE(f61) << f61.message();
  EXPECT_EQ(f61->hashes, sample_frame(61).hashes);
  std::vector<std::uint64_t> seen;
  ASSERT_TRUE(r.for_each_frame(58, 63, [&](const FrameRecord& fr) {
    seen.push_back(fr.frame);
    return true;
  }));
  EXPECT_EQ(seen, (std::vector<std::uint64_t>{58, 59, 60, 61, 62, 63}));
  EXPECT_FALSE(r.frame(0));
  EXPECT_FALSE(r.frame(174));
}

TEST(ReplayFile, SessionFingerprintsDifferWhenAnythingPeersShareDiffers) {
  // Every field that makes two runs differ changes the handshake value, and so do the match
  // bytes a game adds; the keyframe interval, each machine's own choice, does not.
  const Fingerprint base = sample_fingerprint();
  const std::uint64_t reference = session_fingerprint(base);
  const std::vector<std::function<void(Fingerprint&)>> changes = {
      [](Fingerprint& f) { f.detsim_version = "0.1.1"; },
      [](Fingerprint& f) { f.fixed_fraction_bits = 16; },
      [](Fingerprint& f) { f.state_version += 1; },
      [](Fingerprint& f) { f.state_sections.pop_back(); },
      [](Fingerprint& f) { f.scenario = "arena2"; },
      [](Fingerprint& f) { f.params.seed += 1; },
      [](Fingerprint& f) { f.params.players += 1; },
      [](Fingerprint& f) { f.params.count += 1; },
      [](Fingerprint& f) { f.dt = Fixed::from_raw(f.dt.raw() + 1); },
      [](Fingerprint& f) { f.substeps += 1; },
      [](Fingerprint& f) { f.iterations += 1; },
      [](Fingerprint& f) { f.players += 1; },
      [](Fingerprint& f) { f.input_size += 1; },
      [](Fingerprint& f) { f.initial_hash ^= 1; },
  };
  for (std::size_t i = 0; i < changes.size(); ++i) {
    Fingerprint f = base;
    changes[i](f);
    EXPECT_NE(session_fingerprint(f), reference) << "change " << i;
  }
  Fingerprint other_interval = base;
  other_interval.keyframe_interval = 600;
  EXPECT_EQ(session_fingerprint(other_interval), reference);
  const std::uint8_t rollback_600[] = {0, 0x58, 0x02};
  const std::uint8_t lockstep_600[] = {1, 0x58, 0x02};
  EXPECT_NE(session_fingerprint(base, rollback_600), reference);
  EXPECT_NE(session_fingerprint(base, rollback_600), session_fingerprint(base, lockstep_600));
  EXPECT_EQ(session_fingerprint(base, rollback_600), session_fingerprint(base, rollback_600));
}

TEST(ReplayFile, ChainHashIsXxh3OfTheLittleEndianFrameHashes) {
  HashChain chain;
  std::vector<std::uint8_t> bytes;
  for (std::uint64_t h : {1ULL, 0xFFULL << 56, 0x0123456789ABCDEFULL}) {
    chain.add(h);
    for (int i = 0; i < 8; ++i)
      bytes.push_back(static_cast<std::uint8_t>(h >> (8 * i)));
  }
  EXPECT_EQ(chain.value(), XXH3_64bits(bytes.data(), bytes.size()));
}

TEST(ReplayFile, WriterRefusesMisuse) {
  TempFile file("misuse.dsr");
  auto writer = ReplayWriter::create(file.path(), sample_fingerprint());
  ASSERT_TRUE(writer);
  ReplayWriter& w = writer.value();
  const std::vector<std::uint8_t> short_inputs(5);
  const Status wrong_size = w.frame(short_inputs, {});
  EXPECT_FALSE(wrong_size);
  EXPECT_NE(wrong_size.message().find("expected 6 input bytes (2 players x 3), got 5"),
            std::string::npos)
      << wrong_size.message();
  const FrameRecord r = sample_frame(1);
  ASSERT_TRUE(w.frame(r.inputs, r.hashes));
  EXPECT_FALSE(w.keyframe(2, sample_state(2)));  // not the last frame appended
  ASSERT_TRUE(w.keyframe(1, sample_state(1)));
  EXPECT_FALSE(w.keyframe(1, sample_state(1)));  // twice
  ASSERT_TRUE(w.finish());
  EXPECT_FALSE(w.frame(r.inputs, r.hashes));
  EXPECT_FALSE(w.finish());

  Fingerprint bad = sample_fingerprint();
  bad.keyframe_interval = 0;
  EXPECT_FALSE(ReplayWriter::create(file.path(), bad));
  bad = sample_fingerprint();
  bad.players = 65;
  EXPECT_FALSE(ReplayWriter::create(file.path(), bad));
  const auto no_dir = ReplayWriter::create("/nonexistent-dir/x.dsr", sample_fingerprint());
  ASSERT_FALSE(no_dir);
  EXPECT_NE(no_dir.message().find("/nonexistent-dir/x.dsr: cannot create"), std::string::npos);
}

TEST(ReplayFile, AFileCutAtAnyByteReadsUpToItsLastCompleteChunk) {
  TempFile full("full.dsr");
  write_sample(full.path(), 130);
  const auto bytes = read_bytes(full.path());
  const auto chunks = chunks_of(bytes);
  ASSERT_GE(chunks.size(), 6U);  // HEAD, FRAM 1-50, KEYF 50, FRAM 51-100, KEYF 100, FRAM, END
  const std::string name = "cut.dsr";
  for (std::size_t n = 0; n < bytes.size(); ++n) {
    auto reader = ReplayReader::from_bytes(
        {bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(n)}, name);
    // The frames of the FRAM chunks that end at or before n.
    std::uint64_t frames = 0;
    std::size_t keyframes = 0;
    bool head = false;
    for (const ChunkAt& c : chunks) {
      if (c.end() > n) break;
      head = head || c.type == "HEAD";
      if (c.type == "FRAM") frames += test::get_u32(bytes, c.payload() + 8);
      if (c.type == "KEYF") ++keyframes;
    }
    if (!head) {
      ASSERT_FALSE(reader) << "cut at " << n;
      EXPECT_EQ(reader.message().rfind(name + ": ", 0), 0U) << reader.message();
      continue;
    }
    ASSERT_TRUE(reader) << "cut at " << n << ": " << reader.message();
    EXPECT_EQ(reader->frame_count(), frames) << "cut at " << n;
    EXPECT_EQ(reader->keyframes().size(), keyframes) << "cut at " << n;
    EXPECT_FALSE(reader->complete()) << "cut at " << n;
    const bool on_boundary =
        std::any_of(chunks.begin(), chunks.end(), [n](const ChunkAt& c) { return c.end() == n; });
    EXPECT_EQ(reader->ignored_tail_bytes() == 0, on_boundary) << "cut at " << n;
    expect_sample_frames(reader.value());
  }
}

TEST(ReplayFile, NoSingleBitFlipIsSilentlyAccepted) {
  TempFile file("flip.dsr");
  write_sample(file.path(), 70);
  const auto bytes = read_bytes(file.path());
  const std::string name = "flipped.dsr";
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    for (int bit = 0; bit < 8; ++bit) {
      auto b = bytes;
      b[i] = static_cast<std::uint8_t>(b[i] ^ (1U << bit));
      auto reader = ReplayReader::from_bytes(std::move(b), name);
      // Either refused, or (a length that now reaches past the end) read as a recording cut short
      // that says what it ignored and lost the end marker.
      if (reader) {
        EXPECT_GT(reader->ignored_tail_bytes(), 0U) << "byte " << i << " bit " << bit;
        EXPECT_FALSE(reader->complete()) << "byte " << i << " bit " << bit;
        EXPECT_FALSE(reader->tail_note().empty());
      } else {
        EXPECT_EQ(reader.message().rfind(name + ": ", 0), 0U) << reader.message();
      }
    }
  }
}

TEST(ReplayFile, ErrorsNameTheFileTheByteAndWhatWasExpected) {
  TempFile file("named.dsr");
  write_sample(file.path(), 10);
  const auto good = read_bytes(file.path());
  const auto chunks = chunks_of(good);
  const auto open_with = [&](std::vector<std::uint8_t> b) {
    write_bytes(file.path(), b);
    auto reader = ReplayReader::open(file.path());
    EXPECT_FALSE(reader);
    return reader.message();
  };
  auto b = good;
  b[0] = 'X';
  EXPECT_EQ(open_with(b), file.path() +
                              ": byte 0: expected the magic \"DSREPLAY\" (this is not a detsim "
                              "replay)");
  b = good;
  test::put_u32(b, 8, 1);
  EXPECT_EQ(open_with(b), file.path() + ": byte 8: format version 1, this build reads 2");
  // A flipped payload byte of the frames chunk: its checksum no longer matches.
  b = good;
  ASSERT_EQ(chunks[1].type, "FRAM");
  b[chunks[1].payload() + 20] = static_cast<std::uint8_t>(b[chunks[1].payload() + 20] ^ 1U);
  const std::string corrupt = open_with(b);
  EXPECT_NE(corrupt.find(": byte " + std::to_string(chunks[1].offset) + ": chunk FRAM of "),
            std::string::npos)
      << corrupt;
  EXPECT_NE(corrupt.find("(the chunk is corrupt)"), std::string::npos) << corrupt;
  // A well-sealed frames chunk that claims to start at frame 5.
  b = good;
  test::put_u64(b, chunks[1].payload(), 5);
  test::reseal(b, chunks[1]);
  EXPECT_EQ(open_with(b), file.path() + ": byte " + std::to_string(chunks[1].payload()) +
                              ": frames chunk starts at frame 5, expected frame 1");
  EXPECT_EQ(open_with({}), file.path() + ": 0 bytes, shorter than the 16-byte replay header");
  const auto empty = ReplayReader::from_bytes({}, "empty.dsr");
  ASSERT_FALSE(empty);
  EXPECT_EQ(empty.message(), "empty.dsr: 0 bytes, shorter than the 16-byte replay header");
  const auto missing = ReplayReader::open(file.path() + ".does-not-exist");
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.message().find("cannot open"), std::string::npos);
}

/// Well-sealed but hostile chunks: each is refused with the field named, and nothing is allocated
/// from a size that the file does not back.
TEST(ReplayFile, HostileChunksAreRefused) {
  TempFile file("hostile.dsr");
  write_sample(file.path(), 10);
  const auto good = read_bytes(file.path());
  const auto chunks = chunks_of(good);
  ASSERT_EQ(chunks[0].type, "HEAD");
  const std::vector<std::uint8_t> header(good.begin(), good.begin() + 16);
  const std::vector<std::uint8_t> head(good.begin() + 16,
                                       good.begin() + static_cast<std::ptrdiff_t>(chunks[0].end()));
  const std::vector<std::uint8_t> head_payload(
      good.begin() + static_cast<std::ptrdiff_t>(chunks[0].payload()),
      good.begin() + static_cast<std::ptrdiff_t>(chunks[0].payload() + chunks[0].length));
  const auto file_of = [&](std::initializer_list<std::vector<std::uint8_t>> parts) {
    std::vector<std::uint8_t> b = header;
    for (const auto& p : parts)
      b.insert(b.end(), p.begin(), p.end());
    return b;
  };
  const auto error_of = [&](const std::vector<std::uint8_t>& b) {
    write_bytes(file.path(), b);
    auto reader = ReplayReader::open(file.path());
    EXPECT_FALSE(reader);
    return reader.message();
  };
  const auto contains = [](const std::string& s, const std::string& part) {
    return s.find(part) != std::string::npos;
  };

  // A chunk that declares 4 GiB - 1 bytes: refused by the limit before anything is read.
  std::vector<std::uint8_t> huge(16, 0);
  test::put_u32(huge, 0, test::get_u32(good, chunks[1].offset));
  test::put_u32(huge, 4, 0xFFFFFFFFU);
  EXPECT_TRUE(contains(error_of(file_of({head, huge})), "more than the limit")) << "huge";

  // A frames chunk whose count promises 4 billion frames in 12 bytes.
  std::vector<std::uint8_t> frames(12, 0);
  test::put_u64(frames, 0, 1);
  test::put_u32(frames, 8, 0xFFFFFFFFU);
  EXPECT_TRUE(contains(error_of(file_of({head, make_chunk("FRAM", frames)})),
                       "4294967295 frames of 46 bytes need a payload of"));
  // ... and one with no frames at all.
  test::put_u32(frames, 8, 0);
  EXPECT_TRUE(contains(error_of(file_of({head, make_chunk("FRAM", frames)})), "(and no frames)"));

  // Frames before the fingerprint; two fingerprints; a keyframe of a frame never recorded.
  EXPECT_TRUE(contains(error_of(file_of({make_chunk("FRAM", frames)})),
                       "expected the fingerprint chunk HEAD first"));
  EXPECT_TRUE(contains(error_of(file_of({head, head})), "a second fingerprint chunk HEAD"));
  std::vector<std::uint8_t> keyframe(8, 0);
  test::put_u64(keyframe, 0, 9);
  EXPECT_TRUE(contains(error_of(file_of({head, make_chunk("KEYF", keyframe)})),
                       "keyframe of frame 9, expected the last frame recorded before it, 0"));
  // An end marker that counts frames the file does not hold, and chunks after the end.
  std::vector<std::uint8_t> end(16, 0);
  test::put_u64(end, 0, 3);
  EXPECT_TRUE(contains(error_of(file_of({head, make_chunk("END ", end)})),
                       "end marker counts 3 frames, the file holds 0"));
  test::put_u64(end, 0, 0);
  EXPECT_TRUE(contains(error_of(file_of({head, make_chunk("END ", end), head})),
                       "chunk HEAD after the end marker"));

  // Fingerprints with out-of-range fields, each named.
  const auto head_with = [&](std::size_t field_from_end, std::uint32_t value) {
    auto p = head_payload;
    test::put_u32(p, p.size() - field_from_end, value);
    return make_chunk("HEAD", p);
  };
  // From the end: initial hash (8), keyframe interval (4), input size (4), player count (4).
  EXPECT_TRUE(contains(error_of(file_of({head_with(12, 0)})),
                       "fingerprint: keyframe interval: expected at least 1"));
  EXPECT_TRUE(contains(error_of(file_of({head_with(16, 5000)})),
                       "fingerprint: input size: expected at most 1024 bytes"));
  EXPECT_TRUE(contains(error_of(file_of({head_with(20, 1000)})),
                       "fingerprint: player count: expected at most 64"));
  auto long_head = head_payload;
  long_head.push_back(0);
  EXPECT_TRUE(contains(error_of(file_of({make_chunk("HEAD", long_head)})),
                       "no bytes after the initial state hash"));
  auto bad_name = head_payload;
  bad_name[1] = 0x07;  // inside the version string: not printable
  EXPECT_TRUE(contains(error_of(file_of({make_chunk("HEAD", bad_name)})), "printable ASCII"));
  EXPECT_TRUE(contains(error_of(file_of({})), "no fingerprint chunk"));
}

TEST(ReplayFile, UnknownChunkTypesAreSkipped) {
  TempFile file("unknown.dsr");
  write_sample(file.path(), 130);
  auto b = read_bytes(file.path());
  const auto chunks = chunks_of(b);
  // A later format's chunk after the fingerprint, between frames and after the end marker.
  const auto extra = make_chunk("XTRA", std::vector<std::uint8_t>(33, 0xAB));
  for (std::size_t at : {chunks.back().end(), chunks[2].end(), chunks[0].end()})
    b.insert(b.begin() + static_cast<std::ptrdiff_t>(at), extra.begin(), extra.end());
  write_bytes(file.path(), b);
  auto reader = ReplayReader::open(file.path());
  ASSERT_TRUE(reader) << reader.message();
  EXPECT_EQ(reader->frame_count(), 130U);
  EXPECT_TRUE(reader->complete());
  expect_sample_frames(reader.value());
}

TEST(ReplayFile, RandomBytesNeverCrash) {
  std::mt19937_64 rng(5);
  TempFile base("base.dsr");
  write_sample(base.path(), 20);
  const auto good = read_bytes(base.path());
  const std::size_t rounds = test::scaled(3000);
  for (std::size_t i = 0; i < rounds; ++i) {
    std::vector<std::uint8_t> b;
    if (i % 2 == 0) {  // pure noise, sometimes with a valid header
      b.resize(rng() % 300);
      for (auto& v : b)
        v = static_cast<std::uint8_t>(rng());
      if (i % 4 == 0 && b.size() >= 16) std::copy(good.begin(), good.begin() + 16, b.begin());
    } else {  // a good file with a few random bytes changed
      b = good;
      for (int k = 0; k < 1 + static_cast<int>(rng() % 4); ++k)
        b[rng() % b.size()] = static_cast<std::uint8_t>(rng());
    }
    auto reader = ReplayReader::from_bytes(std::move(b), "random.dsr");
    if (reader) {
      EXPECT_LE(reader->frame_count(), 20U);
      (void)all_frames(reader.value());
    } else {
      EXPECT_FALSE(reader.message().empty());
    }
  }
}

/// A child process records `arena` and is killed with SIGKILL at a moment the parent picks; what
/// it left reads back up to its last complete chunk, and those frames verify.
TEST(ReplayFile, ARecordingKilledWithSigkillReadsBackAndVerifies) {
  std::mt19937_64 rng(11);
  for (int round = 0; round < 3; ++round) {
    TempFile file("killed.dsr");
    int ready[2];
    ASSERT_EQ(pipe(ready), 0);
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      close(ready[0]);
      auto scenario = Scenario::create("arena", {.seed = 3, .players = 4});
      if (!scenario) _exit(3);
      RecordOptions options;
      options.frames = 1'000'000;  // runs until killed
      options.keyframe_interval = 100;
      options.progress = [&](std::uint64_t done, std::uint64_t) {
        if (done == 130) {
          const char byte = 1;
          if (write(ready[1], &byte, 1) != 1) _exit(4);
        }
        return true;
      };
      (void)record(scenario.value(), file.path(), options);
      _exit(0);
    }
    close(ready[1]);
    char byte = 0;
    ASSERT_EQ(read(ready[0], &byte, 1), 1);
    close(ready[0]);
    usleep(static_cast<useconds_t>(rng() % 400'000));
    ASSERT_EQ(kill(child, SIGKILL), 0);
    int status = 0;
    ASSERT_EQ(waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFSIGNALED(status));
    ASSERT_EQ(WTERMSIG(status), SIGKILL);

    auto reader = ReplayReader::open(file.path());
    ASSERT_TRUE(reader) << reader.message();
    EXPECT_FALSE(reader->complete());
    // Frames 1-60 and 61-100 (flushed before the keyframe of frame 100) were written before the
    // child reported frame 130; chunks then end at frames 160, 200, 260, 300, ...
    EXPECT_GE(reader->frame_count(), 100U);
    EXPECT_TRUE(reader->frame_count() % 100 == 0 || reader->frame_count() % 100 == 60)
        << reader->frame_count();
    EXPECT_GE(reader->keyframes().size(), 1U);
    auto verified = verify(reader.value());
    ASSERT_TRUE(verified) << verified.message();
    EXPECT_TRUE(verified->ok) << verified->note;
    EXPECT_EQ(verified->frames, reader->frame_count());
    EXPECT_NE(verified->note.find("no end marker"), std::string::npos);
  }
}

}  // namespace
}  // namespace detsim::replay
