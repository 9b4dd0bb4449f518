// detsim bisect, detsim verify --report/--at and --inject from the command line: the replay path of
// a desync end to end (the faulty machine records with --inject, the healthy one verifies and
// reports, the faulty one reports the flagged frame, bisect names the frame, body and field) for
// every field class, the other outcomes (identical, different runs, different inputs), the HTML
// report, and bad usage.
#include <optional>
#include <random>

#include <gtest/gtest.h>

#include <detsim/replay/bisect.hpp>
#include <detsim/replay/scenario_replay.hpp>
#include <detsim/scenes/scenario.hpp>
#include <detsim/sim/inject.hpp>

#include "support/cli.hpp"
#include "support/injection_cases.hpp"
#include "support/replay_files.hpp"
#include "support/scale.hpp"

namespace detsim {
namespace {

using test::detsim_cli;
using test::expect_one_json_object;
using test::has;
using test::json_value;
using test::read_text;
using test::TempFile;

constexpr const char* kInject = "1234:17:linear_velocity.x:0.01";

std::string record(const TempFile& file, const std::string& extra = "") {
  return "run --scenario arena --players 8 --frames 2000 --record " + file.path() + " " + extra;
}

TEST(CliBisect, ReplayPathNamesTheInjectedFrameBodyAndField) {
  TempFile faulty("faulty.dsr");
  TempFile healthy_report("healthy.dsd");
  TempFile faulty_report("faulty.dsd");
  TempFile html("bisect.html");
  auto r = detsim_cli(record(faulty, std::string("--inject ") + kInject));
  ASSERT_EQ(r.exit_code, 0) << r.err;

  // The healthy machine: the first mismatch is frame 1234, and its side is written.
  r = detsim_cli("verify " + faulty.path() + " --report " + healthy_report.path() + " --json");
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_EQ(json_value(r.out, "first_mismatch"), "1234") << r.out;
  EXPECT_EQ(json_value(r.out, "report"), healthy_report.path()) << r.out;
  EXPECT_EQ(json_value(r.out, "report_frame"), "1234") << r.out;
  // The faulty machine reproduces its replay and writes its side of frame 1234.
  r = detsim_cli("verify " + faulty.path() + " --inject " + kInject + " --report " +
                 faulty_report.path() + " --at 1234");
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_TRUE(has(r.out, "ok: 2000 frames")) << r.out;
  EXPECT_TRUE(has(r.out, "state at frame 1234 written to " + faulty_report.path())) << r.out;

  r = detsim_cli("bisect " + healthy_report.path() + " " + faulty_report.path() +
                 " --json --html " + html.path());
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  expect_one_json_object(r.out);
  EXPECT_EQ(json_value(r.out, "outcome"), "diverged");
  EXPECT_EQ(json_value(r.out, "first_divergent_frame"), "1234");
  EXPECT_EQ(json_value(r.out, "last_agreed_frame"), "1233");
  EXPECT_EQ(json_value(r.out, "diff_frame"), "1234");
  EXPECT_TRUE(
      has(r.out, R"("diffs":[{"subsystem":"bodies","body":17,"field":"linear_velocity.x",)"))
      << r.out;
  EXPECT_TRUE(has(r.out, R"(}],"diffs_omitted":0)")) << "exactly one difference: " << r.out;
  const std::string page = read_text(html.path());
  EXPECT_TRUE(page.starts_with("<!DOCTYPE html>"));
  EXPECT_TRUE(has(page, "linear_velocity.x"));
  EXPECT_FALSE(has(page, "http://") || has(page, "https://")) << "self-contained";

  // Text output, and the faulty replay against the healthy report.
  r = detsim_cli("bisect " + faulty.path() + " " + healthy_report.path());
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_TRUE(has(r.out, "DIVERGED at frame 1234 (last agreed frame 1233)")) << r.out;
  EXPECT_TRUE(has(r.out, "this machine's re-simulation agrees with: B")) << r.out;
  EXPECT_TRUE(has(r.out, "detsim verify " + faulty.path() + " --report")) << r.out;
  EXPECT_TRUE(has(r.out, "--at 1234")) << r.out;
}

/// A joint's field (a warm-start impulse of the chain scenario's fifth joint) through the
/// commands: bisection names the joint and the field like a body's, in the "joints" subsystem.
TEST(CliBisect, AJointsFieldIsNamedLikeABodysField) {
  TempFile faulty("faulty.dsr");
  TempFile healthy_report("healthy.dsd");
  TempFile faulty_report("faulty.dsd");
  const std::string inject = "150:0:joint[5].linear_impulse.x:0.01";
  auto r = detsim_cli("run --scenario chain --frames 300 --record " + faulty.path() + " --inject " +
                      inject);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = detsim_cli("verify " + faulty.path() + " --report " + healthy_report.path() + " --json");
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_EQ(json_value(r.out, "first_mismatch"), "150") << r.out;
  r = detsim_cli("verify " + faulty.path() + " --inject " + inject + " --report " +
                 faulty_report.path() + " --at 150");
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  r = detsim_cli("bisect " + healthy_report.path() + " " + faulty_report.path() + " --json");
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_EQ(json_value(r.out, "first_divergent_frame"), "150") << r.out;
  EXPECT_TRUE(has(r.out, R"("subsystems":["joints"])")) << r.out;
  EXPECT_TRUE(
      has(r.out, R"("diffs":[{"subsystem":"joints","body":0,"field":"joint[5].linear_impulse.x",)"))
      << r.out;
  EXPECT_TRUE(has(r.out, R"(}],"diffs_omitted":0)")) << "exactly one difference: " << r.out;
  r = detsim_cli("bisect " + healthy_report.path() + " " + faulty_report.path());
  EXPECT_TRUE(has(r.out, "joint[5].linear_impulse.x")) << r.out;

  // A joint that does not exist is refused before the run starts.
  r = detsim_cli("run --scenario chain --frames 100 --inject 50:0:joint[999].motor_speed:1");
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_TRUE(has(r.err, "no joint with ID 999")) << r.err;
}

/// A character's field (the characters scenario) through the commands: bisection names the
/// character and the field in the "characters" subsystem; a change the next step overwrites (the
/// velocity of a character that stands) is found, and said to have healed by the next keyframe.
TEST(CliBisect, ACharactersFieldIsNamedAndAHealedDivergenceIsSaid) {
  TempFile faulty("faulty.dsr");
  TempFile healthy_report("healthy.dsd");
  TempFile faulty_report("faulty.dsd");
  const std::string inject = "150:0:character[3].position.x:0.01";
  auto r = detsim_cli("run --scenario characters --frames 300 --record " + faulty.path() +
                      " --inject " + inject);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = detsim_cli("verify " + faulty.path() + " --report " + healthy_report.path() + " --json");
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_EQ(json_value(r.out, "first_mismatch"), "150") << r.out;
  r = detsim_cli("verify " + faulty.path() + " --inject " + inject + " --report " +
                 faulty_report.path() + " --at 150");
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  r = detsim_cli("bisect " + healthy_report.path() + " " + faulty_report.path() + " --json");
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_TRUE(has(r.out, R"("subsystems":["characters"])")) << r.out;
  EXPECT_TRUE(has(r.out, R"("field":"character[3].position.x",)")) << r.out;
  EXPECT_TRUE(has(r.out, R"(}],"diffs_omitted":0)")) << "exactly one difference: " << r.out;

  // A standing character's velocity is recomputed from its input by the next step.
  TempFile healthy("healthy.dsr");
  TempFile healing("healing.dsr");
  r = detsim_cli("run --scenario characters --frames 400 --keyframe-interval 100 --record " +
                 healthy.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = detsim_cli("run --scenario characters --frames 400 --keyframe-interval 100 --record " +
                 healing.path() + " --inject 250:0:character[2].velocity.y:0.5");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = detsim_cli("bisect " + healthy.path() + " " + healing.path() + " --json");
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_EQ(json_value(r.out, "first_divergent_frame"), "250") << r.out;
  EXPECT_EQ(json_value(r.out, "healed_frame"), "300") << r.out;
  EXPECT_EQ(json_value(r.out, "diff_frame"), "null") << r.out;
}

/// A particle's field (a cloth particle's height in the drape scenario) through the commands:
/// bisection names the group, the particle and the field, in the "particles" subsystem.
TEST(CliBisect, AParticlesFieldIsNamedLikeABodysField) {
  if (find_scenario("drape") == nullptr) GTEST_SKIP() << "this build has no drape scenario";
  TempFile faulty("faulty.dsr");
  TempFile healthy_report("healthy.dsd");
  TempFile faulty_report("faulty.dsd");
  const std::string inject = "100:0:particle_group[1].particle[30].position.y:0.01";
  auto r = detsim_cli("run --scenario drape --frames 200 --record " + faulty.path() + " --inject " +
                      inject);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = detsim_cli("verify " + faulty.path() + " --report " + healthy_report.path() + " --json");
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_EQ(json_value(r.out, "first_mismatch"), "100") << r.out;
  r = detsim_cli("verify " + faulty.path() + " --inject " + inject + " --report " +
                 faulty_report.path() + " --at 100");
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  r = detsim_cli("bisect " + healthy_report.path() + " " + faulty_report.path() + " --json");
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_EQ(json_value(r.out, "first_divergent_frame"), "100") << r.out;
  EXPECT_TRUE(has(r.out, R"("subsystems":["particles"])")) << r.out;
  EXPECT_TRUE(has(
      r.out,
      R"("diffs":[{"subsystem":"particles","body":0,"field":"particle_group[1].particle[30].position.y",)"))
      << r.out;
  EXPECT_TRUE(has(r.out, R"(}],"diffs_omitted":0)")) << "exactly one difference: " << r.out;

  // A group or particle that does not exist is refused when the run reaches it.
  r = detsim_cli("run --scenario drape --frames 20 --inject 10:0:particle_group[9].awake:1");
  EXPECT_NE(r.exit_code, 0) << r.out << r.err;
  EXPECT_TRUE(has(r.err, "no particle group with ID 9")) << r.err;
  const std::string beyond = "10:0:particle_group[1].particle[100000].position.x:1";
  r = detsim_cli("run --scenario drape --frames 20 --inject " + beyond);
  EXPECT_NE(r.exit_code, 0) << r.out << r.err;
  EXPECT_TRUE(has(r.err, "not particle 100000")) << r.err;
}

/// A scene of registered geometry (level: a triangle mesh, convex rocks, compound tables) end to
/// end: a contact between sub-shapes is injected under the name diff gives it
/// (contact[OTHER/S/T]); bisect restores both reports against the scenario's geometry, names that
/// contact exactly, and its HTML draws the mesh, the hulls and the compounds.
TEST(CliBisect, AGeometrySceneIsBisectedToTheSubShapeContact) {
  Scenario level = Scenario::create("level", {.seed = 1, .count = 2}).value();
  std::optional<ContactState> pick;
  while (!pick && level.world().frame() < 200) {
    level.step();
    for (const ContactState& c : level.world().contacts())
      if (!pick && c.point_count > 0 && c.sub_a != 0) pick = c;
  }
  ASSERT_TRUE(pick.has_value()) << "no contact with a sub-shape by frame 200";
  const std::string frame = std::to_string(level.world().frame());
  const std::string field = "contact[" + std::to_string(pick->b.value) + "/" +
                            std::to_string(pick->sub_a) + "/" + std::to_string(pick->sub_b) +
                            "].point[0].normal_impulse";
  const std::string inject = frame + ":" + std::to_string(pick->a.value) + ":" + field + ":0.25";
  SCOPED_TRACE("--inject " + inject);

  TempFile faulty("faulty.dsr");
  TempFile healthy_report("healthy.dsd");
  TempFile faulty_report("faulty.dsd");
  TempFile html("bisect.html");
  auto r = detsim_cli("run --scenario level --count 2 --frames 250 --record " + faulty.path() +
                      " --inject " + inject);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = detsim_cli("verify " + faulty.path() + " --report " + healthy_report.path() + " --json");
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_EQ(json_value(r.out, "first_mismatch"), frame) << r.out;
  r = detsim_cli("verify " + faulty.path() + " --inject " + inject + " --report " +
                 faulty_report.path() + " --at " + frame);
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  r = detsim_cli("bisect " + healthy_report.path() + " " + faulty_report.path() +
                 " --json --html " + html.path());
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_EQ(json_value(r.out, "first_divergent_frame"), frame) << r.out;
  EXPECT_TRUE(has(r.out, R"("diffs":[{"subsystem":"contacts","body":)" +
                             std::to_string(pick->a.value) + R"(,"field":")" + field + "\""))
      << r.out;
  EXPECT_TRUE(has(r.out, R"(}],"diffs_omitted":0)")) << "exactly one difference: " << r.out;
  // The faulty replay against the healthy report: this machine re-simulates the scenario, with
  // its geometry, and agrees with the report.
  r = detsim_cli("bisect " + faulty.path() + " " + healthy_report.path());
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_TRUE(has(r.out, "DIVERGED at frame " + frame)) << r.out;
  EXPECT_TRUE(has(r.out, "this machine's re-simulation agrees with: B")) << r.out;

  // Every body is drawn: the mesh as its triangles, rocks as polygons, tables as their parts.
  const std::string page = read_text(html.path());
  for (const BodyId id : level.world().body_ids()) {
    const ShapeType type = level.world().body(id).value().shape.type;
    const std::string title = "<title>body " + std::to_string(id.value) + " (";
    const std::size_t at = page.find(title);
    ASSERT_NE(at, std::string::npos) << "body " << id.value << " not drawn";
    const std::string tag = page.substr(page.rfind('<', at - 1), 9);
    if (type == ShapeType::mesh) {
      EXPECT_EQ(tag, "<path cla") << id.value;
    }
    if (type == ShapeType::convex) {
      EXPECT_EQ(tag, "<polygon ") << id.value;
    }
    if (type == ShapeType::compound) {
      std::size_t parts = 0;
      for (std::size_t p = at; p != std::string::npos; p = page.find(title, p + 1))
        ++parts;
      EXPECT_GT(parts, 2U) << "a compound's parts, in both panels: body " << id.value;
    }
  }
}

/// Every field class through the commands themselves, at a seeded random frame of a 10,000-frame
/// 8-player arena match (1,000 in the sanitizer build): the injection is chosen from the state at
/// that frame (simulated here), then the faulty machine records with --inject, the healthy one
/// verifies with --report, the faulty one verifies with --inject --report --at F, and bisect of
/// the two reports names exactly frame F and the injected body and field.
class CliBisectClasses : public ::testing::TestWithParam<test::FieldClass> {};

TEST_P(CliBisectClasses, ReplayPathNamesTheInjectedField) {
  const test::FieldClass field_class = GetParam();
  const std::uint64_t frames = test::scaled(10'000);
  std::mt19937_64 rng(0xC11B15 + static_cast<std::uint64_t>(field_class));
  std::uint64_t frame = 2 + rng() % (frames - 2);
  // The state at `frame` as `detsim run` computes it (scripted players, seed 1).
  ScenarioParams params;
  params.players = 8;
  Scenario scenario = Scenario::create("arena", params).value();
  std::vector<PlayerInput> inputs(8);
  std::optional<Injection> injection;
  for (std::uint64_t f = 1; f <= frames && !injection; ++f) {
    for (std::uint32_t p = 0; p < 8; ++p)
      inputs[p] = scripted_input(1, f, p);
    scenario.step(inputs);
    if (f >= frame) injection = test::choose_injection(field_class, scenario.world());
  }
  ASSERT_TRUE(injection.has_value());
  frame = injection->frame;
  const std::string spec = injection->text();
  SCOPED_TRACE(std::string(test::class_name(field_class)) + ": --inject " + spec);

  TempFile faulty("faulty.dsr");
  TempFile healthy_report("healthy.dsd");
  TempFile faulty_report("faulty.dsd");
  const std::string run = "run --scenario arena --players 8 --frames " + std::to_string(frames) +
                          " --record " + faulty.path() + " --inject " + spec;
  auto r = detsim_cli(run);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = detsim_cli("verify " + faulty.path() + " --report " + healthy_report.path() + " --json");
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_EQ(json_value(r.out, "first_mismatch"), std::to_string(frame)) << r.out;
  r = detsim_cli("verify " + faulty.path() + " --inject " + spec + " --report " +
                 faulty_report.path() + " --at " + std::to_string(frame) + " --json");
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_EQ(json_value(r.out, "report_frame"), std::to_string(frame)) << r.out;

  // Bisect's diffs, read back from its JSON through the library's own result for the same files
  // (the CLI prints what bisect() returns; the JSON's first diff is checked against it too).
  r = detsim_cli("bisect " + healthy_report.path() + " " + faulty_report.path() + " --json");
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_EQ(json_value(r.out, "first_divergent_frame"), std::to_string(frame)) << r.out;
  EXPECT_EQ(json_value(r.out, "last_agreed_frame"), std::to_string(frame - 1)) << r.out;
  EXPECT_EQ(json_value(r.out, "diff_frame"), std::to_string(frame)) << r.out;
  auto b = replay::bisect(healthy_report.path(), faulty_report.path());
  ASSERT_TRUE(b.ok()) << b.message();
  test::expect_names_injection(b->diffs, field_class, *injection);
  ASSERT_FALSE(b->diffs.empty());
  const FieldDiff& first = b->diffs.front();
  EXPECT_TRUE(has(r.out, "\"diffs\":[{\"subsystem\":\"" + first.subsystem + "\",\"body\":" +
                             std::to_string(first.body) + ",\"field\":\"" + first.field + "\""))
      << r.out;
}

INSTANTIATE_TEST_SUITE_P(EveryFieldClass, CliBisectClasses,
                         ::testing::ValuesIn(test::all_field_classes()),
                         [](const ::testing::TestParamInfo<test::FieldClass>& param) {
                           return std::string(test::class_name(param.param));
                         });

TEST(CliBisect, IdenticalRecordsDifferentRunsAndDifferentInputs) {
  TempFile a("a.dsr");
  TempFile b("b.dsr");
  ASSERT_EQ(detsim_cli(record(a)).exit_code, 0);
  ASSERT_EQ(detsim_cli(record(b)).exit_code, 0);
  auto r = detsim_cli("bisect " + a.path() + " " + b.path() + " --json");
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_EQ(json_value(r.out, "outcome"), "identical") << r.out;
  EXPECT_EQ(json_value(r.out, "first_divergent_frame"), "null") << r.out;

  TempFile other_seed("seed.dsr");
  ASSERT_EQ(detsim_cli(record(other_seed, "--seed 2")).exit_code, 0);
  r = detsim_cli("bisect " + a.path() + " " + other_seed.path());
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_TRUE(has(r.out, "DIFFERENT RUNS")) << r.out;
  EXPECT_TRUE(has(r.out, "seed: 1 vs 2")) << r.out;

  // The same match with player 3 pressing something else at frame 700: not a desync.
  TempFile other_inputs("inputs.dsr");
  {
    ScenarioParams params;
    params.players = 8;
    Scenario scenario = Scenario::create("arena", params).value();
    replay::RecordOptions options;
    options.frames = 2000;
    options.inputs = [](std::uint64_t frame, std::span<PlayerInput> out) {
      for (std::uint32_t p = 0; p < out.size(); ++p)
        out[p] = scripted_input(1, frame, p);
      if (frame == 700) out[3].move_x = static_cast<std::int8_t>(out[3].move_x ^ 5);
    };
    ASSERT_TRUE(replay::record(scenario, other_inputs.path(), options).ok());
  }
  r = detsim_cli("bisect " + a.path() + " " + other_inputs.path() + " --json");
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_EQ(json_value(r.out, "outcome"), "inputs_differ") << r.out;
  EXPECT_EQ(json_value(r.out, "input_frame"), "700") << r.out;
  EXPECT_EQ(json_value(r.out, "input_player"), "3") << r.out;
}

TEST(CliBisect, BadUsageExitsWithTwoAndNamesTheProblem) {
  TempFile a("a.dsr");
  ASSERT_EQ(detsim_cli(record(a)).exit_code, 0);
  TempFile junk("junk.bin");
  test::write_bytes(junk.path(), std::vector<std::uint8_t>(100, 7));
  const struct {
    std::string args;
    std::string message;
  } cases[] = {
      {"bisect " + a.path() + " /nonexistent/x.dsr", "/nonexistent/x.dsr"},
      {"bisect " + a.path() + " " + junk.path(), "side B"},
      {"bisect " + a.path(), "B is required"},
      {"verify " + a.path() + " --at 5", "--at needs --report"},
      {"verify " + a.path() + " --report /tmp/x.dsd --at 2001", "holds frames 1 to 2000"},
      {"verify " + a.path() + " --inject 5:17:position.q:1", "unknown field \"position.q\""},
      {"verify " + a.path() + " --inject 5:17:position.x", "FRAME:BODY:FIELD:DELTA"},
      {"run --scenario arena --frames 100 --inject 500:3:position.x:1", "beyond the run"},
      {"verify " + a.path() + " --inject 2001:3:position.x:1", "beyond the replay's 2000 frames"},
      {"run --scenario arena --frames 100 --inject 50:999:position.x:1", "no body with ID 999"},
  };
  for (const auto& c : cases) {
    const auto r = detsim_cli(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args << "\n" << r.out << r.err;
    EXPECT_TRUE(has(r.err, c.message)) << c.args << "\n" << r.err;
  }
}

TEST(CliBisect, HelpDescribesTheOptions) {
  const auto r = detsim_cli("bisect --help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* word : {"--html", "--json", "--max", "desync report", "Exit status"})
    EXPECT_TRUE(has(r.out, word)) << word << "\n" << r.out;
  const auto verify = detsim_cli("verify --help");
  for (const char* word : {"--report", "--at", "--inject", "FRAME:BODY:FIELD:DELTA"})
    EXPECT_TRUE(has(verify.out, word)) << word << "\n" << verify.out;
}

}  // namespace
}  // namespace detsim
