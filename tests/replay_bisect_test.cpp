// Desync bisection, replay path (replay/bisect.hpp), for every field class at a seeded random frame
// of a 10,000-frame 8-player arena match (1,000 frames in the sanitizer build):
// - the faulty machine records the match with one field of one body changed at frame F;
// - the healthy machine verifies that replay, which flags frame F, and writes its side (--report);
// - the faulty machine verifies with the same injection and writes its side of frame F (--at F);
// - bisect of the two reports names exactly frame F and the injected body and field;
// - bisect of the faulty replay and the healthy report names frame F exactly and tells which
//   verify command gives the faulty side's exact state.
#include <random>

#include <gtest/gtest.h>

#include <detsim/replay/bisect.hpp>
#include <detsim/replay/desync_report.hpp>
#include <detsim/replay/scenario_replay.hpp>
#include <detsim/sim/inject.hpp>

#include "support/injection_cases.hpp"
#include "support/replay_files.hpp"
#include "support/scale.hpp"

namespace detsim {
namespace {

using test::FieldClass;

constexpr std::uint32_t kPlayers = 8;

std::uint64_t match_frames() {
  return test::scaled(10'000);
}

/// A seeded "random" frame for a class, 2 .. frames - 1.
std::uint64_t random_frame(FieldClass c) {
  std::mt19937_64 rng(0xB15EC7 + static_cast<std::uint64_t>(c));
  return 2 + rng() % (match_frames() - 2);
}

Scenario arena() {
  ScenarioParams params;
  params.players = kPlayers;
  params.seed = 5;
  return Scenario::create("arena", params).value();
}

class ReplayBisect : public ::testing::TestWithParam<FieldClass> {};

TEST_P(ReplayBisect, NamesTheInjectedFrameBodyAndField) {
  const FieldClass field_class = GetParam();
  std::uint64_t frame = random_frame(field_class);
  SCOPED_TRACE(std::string("class ") + test::class_name(field_class) + ", frame " +
               std::to_string(frame));

  // The faulty machine: the injection is chosen from the state at `frame` (the first frame at or
  // after it that has a target) and applied there.
  std::optional<Injection> injection;
  test::TempFile faulty_replay("faulty.dsr");
  {
    Scenario scenario = arena();
    replay::RecordOptions options;
    options.frames = static_cast<std::uint32_t>(match_frames());
    options.after_step = [&](Scenario& s) -> Status {
      if (!injection && s.world().frame() >= frame) {
        injection = test::choose_injection(field_class, s.world());
        if (!injection) return Status::success();
        frame = s.world().frame();
      }
      return injection ? apply_injections(s.world(), std::span(&*injection, 1)) : Status::success();
    };
    auto recorded = replay::record(scenario, faulty_replay.path(), options);
    ASSERT_TRUE(recorded.ok()) << recorded.message();
  }
  ASSERT_TRUE(injection.has_value());
  ASSERT_EQ(injection->frame, frame);
  auto reader = replay::ReplayReader::open(faulty_replay.path());
  ASSERT_TRUE(reader.ok()) << reader.message();

  // The healthy machine verifies the faulty recording: frame F is the first mismatch.
  test::TempFile healthy_report("healthy.dsd");
  {
    replay::VerifyOptions options;
    options.report = true;
    auto v = replay::verify(reader.value(), options);
    ASSERT_TRUE(v.ok()) << v.message();
    EXPECT_FALSE(v->ok);
    ASSERT_TRUE(v->first_mismatch.has_value());
    EXPECT_EQ(*v->first_mismatch, frame);
    ASSERT_TRUE(v->report.has_value());
    EXPECT_EQ(v->report->divergent_frame, frame);
    EXPECT_EQ(v->report->origin, replay::ReportOrigin::verify);
    ASSERT_TRUE(replay::write_desync_report(healthy_report.path(), *v->report).ok());
  }
  // The faulty machine reproduces its own recording up to F and writes its side of frame F.
  test::TempFile faulty_report("faulty.dsd");
  {
    replay::VerifyOptions options;
    options.after_step = [&](Scenario& s) {
      return apply_injections(s.world(), std::span(&*injection, 1));
    };
    options.report_at = frame;
    options.progress = [&](std::uint64_t done, std::uint64_t) { return done < frame; };
    auto v = replay::verify(reader.value(), options);
    ASSERT_TRUE(v.ok()) << v.message();
    EXPECT_FALSE(v->first_mismatch.has_value()) << "the faulty machine reproduces its replay";
    ASSERT_TRUE(v->report.has_value());
    EXPECT_EQ(v->report->local_hash, v->report->remote_hash);
    ASSERT_TRUE(replay::write_desync_report(faulty_report.path(), *v->report).ok());
  }

  // The two reports: exactly frame F, and exactly the injected field.
  auto r = replay::bisect(healthy_report.path(), faulty_report.path());
  ASSERT_TRUE(r.ok()) << r.message();
  EXPECT_EQ(r->outcome, replay::BisectOutcome::diverged);
  ASSERT_TRUE(r->first_divergent_frame.has_value());
  EXPECT_EQ(*r->first_divergent_frame, frame);
  EXPECT_EQ(r->last_agreed_frame, frame - 1);
  EXPECT_TRUE(r->exact);
  ASSERT_EQ(r->diff_frame, frame);
  EXPECT_EQ(r->diff_source_a, "desync report");
  EXPECT_EQ(r->diff_source_b, "desync report");
  EXPECT_TRUE(r->advice.empty()) << r->advice;
  test::expect_names_injection(r->diffs, field_class, *injection);
  ASSERT_EQ(r->inputs_between.size(), 1U);
  EXPECT_EQ(r->inputs_between[0].frame, frame);
  EXPECT_EQ(r->inputs_between[0].inputs.size(), kPlayers * 3U);

  // The faulty replay against the healthy report: the exact frame from the hash streams; this
  // machine agrees with the healthy side; the faulty side's state at F is unknown, so the diff is
  // at a later keyframe and the advice is the verify command that gives the exact frame.
  auto mixed = replay::bisect(faulty_replay.path(), healthy_report.path());
  ASSERT_TRUE(mixed.ok()) << mixed.message();
  EXPECT_EQ(mixed->first_divergent_frame, frame);
  EXPECT_TRUE(mixed->exact);
  EXPECT_EQ(mixed->local_agrees_with, "B");
  EXPECT_FALSE(mixed->subsystems.empty());
  if (mixed->diff_frame) {
    EXPECT_GT(*mixed->diff_frame, frame);
    EXPECT_EQ(*mixed->diff_frame % replay::default_keyframe_interval, 0U);
    EXPECT_EQ(mixed->diff_source_a, "keyframe");
    EXPECT_EQ(mixed->diff_source_b, "re-simulated here");
  }
  EXPECT_NE(mixed->advice.find("detsim verify " + faulty_replay.path() + " --report"),
            std::string::npos)
      << mixed->advice;
  EXPECT_NE(mixed->advice.find("--at " + std::to_string(frame)), std::string::npos)
      << mixed->advice;
}

INSTANTIATE_TEST_SUITE_P(EveryFieldClass, ReplayBisect,
                         ::testing::ValuesIn(test::all_field_classes()),
                         [](const ::testing::TestParamInfo<FieldClass>& param) {
                           return std::string(test::class_name(param.param));
                         });

}  // namespace
}  // namespace detsim
