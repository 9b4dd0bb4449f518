// replay::view_records: what a viewer is handed for one record and for two records of one match.
//
// - one replay: every frame once, in order, with this machine's hash equal to the one recorded;
//   the keyframes marked as the record's own states; every body introduced once, its outline in
//   its own frame (a player's sphere: one point at the origin, radius 0.5 m: the scenario's);
//   every pose equal to what World::body gives after seeking there;
// - a range starts at its first frame with that frame's recorded hash, wherever keyframes are;
// - two records, the second changed at frame F: outcome "diverged" at F; no body differs before
//   F; after the second record's first keyframe past F the changed body differs, and side B's
//   hash there is B's recorded one;
// - bad calls: no record, three records, a range past the end, a first frame after the last.
#include <gtest/gtest.h>

#include <map>
#include <set>
#include <string>
#include <vector>

#include <detsim/replay/scenario_replay.hpp>
#include <detsim/replay/view.hpp>
#include <detsim/sim/inject.hpp>

#include "support/replay_files.hpp"

namespace detsim {
namespace {

constexpr std::uint32_t kFrames = 700;

Scenario arena() {
  ScenarioParams params;
  params.players = 2;
  params.seed = 3;
  return Scenario::create("arena", params).value();
}

void record(const std::string& path, const std::optional<Injection>& injection = std::nullopt) {
  Scenario scenario = arena();
  replay::RecordOptions options;
  options.frames = kFrames;
  if (injection)
    options.after_step = [&](Scenario& s) {
      return apply_injections(s.world(), std::span(&*injection, 1));
    };
  auto recorded = replay::record(scenario, path, options);
  ASSERT_TRUE(recorded.ok()) << recorded.message();
}

/// Keeps every frame handed to it.
class Collect final : public replay::ViewSink {
 public:
  Status begin(const replay::ViewInfo& info) override {
    info_ = info;
    ++begins;
    return Status::success();
  }
  Status frame(const replay::ViewFrame& f) override {
    frames.push_back(f.frame);
    inputs.emplace_back(f.inputs.begin(), f.inputs.end());
    sides.push_back(f.sides);
    return Status::success();
  }
  [[nodiscard]] const replay::ViewInfo& info() const { return info_; }

  int begins = 0;
  std::vector<std::uint64_t> frames;
  std::vector<std::vector<std::uint8_t>> inputs;
  std::vector<std::vector<replay::ViewSide>> sides;

 private:
  replay::ViewInfo info_;
};

TEST(ReplayView, OneReplayEveryFrameItsHashesAndItsBodies) {
  test::TempFile file("view.dsr");
  record(file.path());
  auto reader = replay::ReplayReader::open(file.path());
  ASSERT_TRUE(reader.ok()) << reader.message();

  Collect sink;
  const std::vector<std::string> paths{file.path()};
  ASSERT_TRUE(replay::view_records(paths, {}, sink).ok());
  EXPECT_EQ(sink.begins, 1);
  EXPECT_EQ(sink.info().outcome, "single");
  EXPECT_TRUE(sink.info().player_inputs);
  ASSERT_EQ(sink.frames.size(), kFrames + 1);
  std::map<std::uint32_t, int> introduced;
  std::set<std::uint64_t> keyframes;
  for (const replay::KeyframeInfo& k : reader->keyframes())
    keyframes.insert(k.frame);
  for (std::uint64_t f = 0; f <= kFrames; ++f) {
    ASSERT_EQ(sink.frames[f], f);
    ASSERT_EQ(sink.sides[f].size(), 1U);
    const replay::ViewSide& side = sink.sides[f][0];
    const std::uint64_t recorded =
        f == 0 ? reader->fingerprint().initial_hash : reader->frame(f).value().hashes.total;
    ASSERT_TRUE(side.recorded_hash.has_value()) << "frame " << f;
    EXPECT_EQ(*side.recorded_hash, recorded) << "frame " << f;
    EXPECT_EQ(side.hash, recorded) << "frame " << f;
    EXPECT_EQ(side.stored, f > 0 && keyframes.count(f) != 0) << "frame " << f;
    if (f > 0) {
      EXPECT_EQ(sink.inputs[f], reader->frame(f).value().inputs) << "frame " << f;
    }
    for (const replay::ViewBody& b : side.new_bodies)
      ++introduced[b.id];
  }
  EXPECT_TRUE(sink.inputs[0].empty());

  // Every body once; a player's sphere drawn about its own origin with the scenario's radius.
  Scenario s = arena();
  for (const BodyId id : s.world().body_ids())
    EXPECT_EQ(introduced[id.value], 1) << "body " << id.value;
  const BodyId player = s.player_body(0);
  for (const replay::ViewBody& b : sink.sides[0][0].new_bodies) {
    if (b.id != player.value) continue;
    ASSERT_EQ(b.outline.points.size(), 1U);
    EXPECT_EQ(b.outline.points[0], Vec3{});
    EXPECT_EQ(b.outline.radius, Fixed::half());
    EXPECT_EQ(b.type, BodyType::dynamic);
  }

  // Poses: what the world holds at that frame.
  for (const std::uint64_t f : {std::uint64_t{1}, std::uint64_t{350}, std::uint64_t{kFrames}}) {
    auto at = replay::seek(reader.value(), f);
    ASSERT_TRUE(at.ok()) << at.message();
    for (const replay::ViewPose& p : sink.sides[f][0].bodies) {
      const BodyState b = at->world().body(BodyId{p.id}).value();
      EXPECT_EQ(p.position, b.position) << "frame " << f << " body " << p.id;
      EXPECT_EQ(p.orientation, b.orientation) << "frame " << f << " body " << p.id;
      EXPECT_FALSE(p.differs);
    }
    EXPECT_EQ(sink.sides[f][0].bodies.size(), at->world().body_ids().size());
  }
}

TEST(ReplayView, ARangeStartsAtItsFirstFrame) {
  test::TempFile file("range.dsr");
  record(file.path());
  auto reader = replay::ReplayReader::open(file.path());
  ASSERT_TRUE(reader.ok());
  Collect sink;
  replay::ViewOptions options;
  options.first = 333;
  options.last = 340;
  const std::vector<std::string> paths{file.path()};
  ASSERT_TRUE(replay::view_records(paths, options, sink).ok());
  ASSERT_EQ(sink.frames.size(), 8U);
  EXPECT_EQ(sink.frames.front(), 333U);
  EXPECT_EQ(sink.frames.back(), 340U);
  EXPECT_EQ(sink.sides[0][0].hash, reader->frame(333).value().hashes.total);
  // Every body is introduced at the first frame handed over.
  EXPECT_EQ(sink.sides[0][0].new_bodies.size(), sink.sides[0][0].bodies.size());
}

TEST(ReplayView, TwoRecordsMarkTheBodyThatDiverged) {
  constexpr std::uint64_t kChanged = 400;
  Scenario s = arena();
  const std::uint32_t body = s.player_body(1).value;
  auto injection = parse_injection(std::to_string(kChanged) + ":" + std::to_string(body) +
                                   ":linear_velocity.x:2");
  ASSERT_TRUE(injection.ok()) << injection.message();
  test::TempFile a("a.dsr");
  test::TempFile b("b.dsr");
  record(a.path());
  record(b.path(), injection.value());
  auto reader_b = replay::ReplayReader::open(b.path());
  ASSERT_TRUE(reader_b.ok());
  std::uint64_t keyframe_after = 0;
  for (const replay::KeyframeInfo& k : reader_b->keyframes())
    if (k.frame > kChanged && keyframe_after == 0) keyframe_after = k.frame;
  ASSERT_GT(keyframe_after, kChanged) << "the test needs a keyframe after the change";

  Collect sink;
  const std::vector<std::string> paths{a.path(), b.path()};
  ASSERT_TRUE(replay::view_records(paths, {}, sink).ok());
  EXPECT_EQ(sink.info().outcome, "diverged");
  EXPECT_EQ(sink.info().first_divergent_frame, kChanged);
  ASSERT_EQ(sink.frames.size(), kFrames + 1);
  for (std::uint64_t f = 0; f < kChanged; ++f)
    for (const replay::ViewSide& side : sink.sides[f])
      for (const replay::ViewPose& p : side.bodies)
        ASSERT_FALSE(p.differs) << "frame " << f << " body " << p.id;
  const auto differs = [&](std::uint64_t f, std::size_t side) {
    for (const replay::ViewPose& p : sink.sides[f][side].bodies)
      if (p.id == body) return p.differs;
    return false;
  };
  EXPECT_TRUE(differs(keyframe_after, 0));
  EXPECT_TRUE(differs(keyframe_after, 1));
  EXPECT_TRUE(differs(kFrames, 1));
  // Side B at its keyframe is its own state: its recorded hash.
  EXPECT_TRUE(sink.sides[keyframe_after][1].stored);
  EXPECT_EQ(sink.sides[keyframe_after][1].hash,
            reader_b->frame(keyframe_after).value().hashes.total);
  EXPECT_NE(sink.sides[keyframe_after][0].hash, sink.sides[keyframe_after][1].hash);
}

TEST(ReplayView, RefusesBadCallsBeforeAnyFrame) {
  test::TempFile file("bad.dsr");
  record(file.path());
  const auto refused = [&](const std::vector<std::string>& paths, replay::ViewOptions options,
                           const std::string& says) {
    Collect sink;
    const Status s = replay::view_records(paths, options, sink);
    EXPECT_FALSE(s.ok());
    EXPECT_NE(s.message().find(says), std::string::npos) << s.message();
    EXPECT_EQ(sink.begins, 0);
    EXPECT_TRUE(sink.frames.empty());
  };
  refused({}, {}, "one record");
  refused({file.path(), file.path(), file.path()}, {}, "got 3");
  refused({file.path() + ".missing"}, {}, ".missing");
  replay::ViewOptions past;
  past.last = kFrames + 1;
  refused({file.path()}, past, "past the end");
  replay::ViewOptions backwards;
  backwards.first = 20;
  backwards.last = 10;
  refused({file.path()}, backwards, "after the last");
}

}  // namespace
}  // namespace detsim
