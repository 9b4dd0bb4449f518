// The example game (examples/pushball): its rules, then every tool through its own binary,
// pushball-tool — record, verify, seek, sync test, desync report, diff and bisect naming the exact
// frame, body and field, its own score field included — and the stock detsim refusing its replays
// with a message that says why.
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

#include "pushball.hpp"
#include "support/cli.hpp"
#include "support/replay_files.hpp"

namespace detsim {
namespace {

using namespace detsim::literals;
using test::has;
using test::json_value;
using test::TempFile;

void ensure_registered() {
  static const bool done = [] {
    const Status s = register_scenario(pushball::definition());
    EXPECT_TRUE(s.ok()) << s.message();
    return true;
  }();
  (void)done;
}

Scenario make() {
  ensure_registered();
  return Scenario::create("pushball").value();
}

test::CliResult tool(const std::string& args) {
  return test::run_program(std::string(DETSIM_BINARY_DIR) + "/examples/pushball/pushball-tool",
                           args);
}

// ---- the rules ----

TEST(ExamplePushball, ABallOverTheGoalLineScoresOnceThenPlayRestartsFromTheStart) {
  Scenario s = make();
  World& w = s.world();
  const BodyId ball = pushball::find(w, pushball::ball_tag);
  ASSERT_TRUE(w.set_transform(ball, {9_fx, 0.5_fx, 0.5_fx}, {}).ok());
  ASSERT_TRUE(w.set_linear_velocity(ball, {6_fx, 0_fx, 0_fx}).ok());
  const std::vector<std::uint8_t> idle(2 * pushball::Input::size);  // nothing pressed
  int frames = 0;
  while (pushball::state_of(w).score[0] == 0 && frames < 60) {
    s.step_encoded(idle);
    ++frames;
  }
  // 1.5 m to the line at about 6 m/s: a quarter of a second, give or take the rolling friction.
  EXPECT_GE(frames, 12);
  EXPECT_LE(frames, 20);
  pushball::State st = pushball::state_of(w);
  EXPECT_EQ(st.score[0], 1U);
  EXPECT_EQ(st.score[1], 0U);
  EXPECT_EQ(st.last_scorer, 1U);
  EXPECT_EQ(st.kickoff, pushball::kickoff_frames);
  for (int f = 1; f < pushball::kickoff_frames; ++f)
    s.step_encoded(idle);
  EXPECT_EQ(pushball::state_of(w).score[0], 1U) << "counted once, though the ball stays in";
  EXPECT_EQ(pushball::state_of(w).kickoff, 1U);
  s.step_encoded(idle);
  EXPECT_EQ(pushball::state_of(w).kickoff, 0U);
  // Placed at the start before the step, then one step of gravity against the ground: at rest.
  EXPECT_EQ(w.body(ball)->position.x, 0_fx);
  EXPECT_EQ(w.body(ball)->position.z, 0_fx);
  EXPECT_EQ(w.body(ball)->linear_velocity.x, 0_fx);
}

TEST(ExamplePushball, TheEndWallBesideTheMouthStopsTheBallWithoutAGoal) {
  Scenario s = make();
  World& w = s.world();
  const BodyId ball = pushball::find(w, pushball::ball_tag);
  ASSERT_TRUE(w.set_transform(ball, {8_fx, 0.5_fx, 5_fx}, {}).ok());
  ASSERT_TRUE(w.set_linear_velocity(ball, {8_fx, 0_fx, 0_fx}).ok());
  const std::vector<std::uint8_t> idle(2 * pushball::Input::size);  // nothing pressed
  for (int f = 0; f < 120; ++f)
    s.step_encoded(idle);
  EXPECT_EQ(pushball::state_of(w).score[0], 0U);
  EXPECT_LT(w.body(ball)->position.x, 10_fx) << "the wall's face is at x = 10";
}

TEST(ExamplePushball, ADashIsAnImpulseOfEightNewtonSecondsThenWaitsOutItsCooldown) {
  Scenario s = make();
  World& w = s.world();
  const BodyId puck = pushball::find(w, pushball::player_tag + 0);
  pushball::Input dash;
  dash.buttons = pushball::Input::dash;
  const std::vector<std::uint8_t> inputs = pushball::encode_frame(dash, {});
  s.step_encoded(inputs);
  // J / m = 8 / 4 = 2 m/s along +x (no stick: towards the other goal), less at most one step of
  // sliding friction and damping.
  const Fixed v = w.body(puck)->linear_velocity.x;
  EXPECT_LE(v, 2_fx);
  EXPECT_GE(v, 1.8_fx);
  EXPECT_EQ(pushball::state_of(w).cooldown[0], pushball::dash_cooldown_frames);
  int dashes = 1;
  Fixed previous = v;
  for (int f = 0; f < 2 * pushball::dash_cooldown_frames; ++f) {
    s.step_encoded(inputs);
    const Fixed now = w.body(puck)->linear_velocity.x;
    if (now > previous + 1_fx) ++dashes;
    previous = now;
  }
  EXPECT_EQ(dashes, 2) << "one more dash once the cooldown ran out, not one per frame held";
}

// ---- the tools, through pushball-tool ----

TEST(ExamplePushball, ItsGoldenReplayVerifiesFrameByFrame) {
  // golden/games/pushball.dsr: what every leg of the determinism matrix reproduces too.
  const std::string golden = std::string(DETSIM_SOURCE_DIR) + "/golden/games/pushball.dsr";
  const test::CliResult verify = tool("verify " + golden + " --json");
  EXPECT_EQ(verify.exit_code, 0) << verify.out << verify.err;
  EXPECT_EQ(json_value(verify.out, "ok"), "true");
  EXPECT_EQ(json_value(verify.out, "frames"), "600");
  const test::CliResult info = tool("info " + golden + " --json");
  EXPECT_EQ(json_value(info.out, "input_size"), "5") << info.out;
}

TEST(ExamplePushball, ItsToolRecordsVerifiesAndSyncTestsItsRuns) {
  TempFile replay("pushball.dsr");
  const test::CliResult scenarios = tool("scenarios --json");
  EXPECT_EQ(scenarios.exit_code, 0) << scenarios.err;
  EXPECT_TRUE(has(scenarios.out, "\"name\":\"pushball\"")) << scenarios.out;
  const test::CliResult run =
      tool("run --scenario pushball --frames 900 --json --record " + replay.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const test::CliResult verify = tool("verify " + replay.path() + " --json");
  EXPECT_EQ(verify.exit_code, 0) << verify.err;
  EXPECT_EQ(json_value(verify.out, "ok"), "true");
  EXPECT_EQ(json_value(verify.out, "frames"), "900");
  EXPECT_EQ(json_value(verify.out, "final_hash"), json_value(run.out, "final_hash"));
  // Bulk verification knows the game too: its replay and its golden one, on two workers.
  const test::CliResult bulk =
      tool("verify " + replay.path() + " " + std::string(DETSIM_SOURCE_DIR) +
           "/golden/games/pushball.dsr --jobs 2");
  EXPECT_EQ(bulk.exit_code, 0) << bulk.out << bulk.err;
  EXPECT_TRUE(has(bulk.out, replay.path() + ": ok: 900 frames of pushball")) << bulk.out;
  EXPECT_TRUE(has(bulk.out, "2 replays: 2 ok, 0 desync, 0 invalid, 0 incomplete")) << bulk.out;
  const test::CliResult sync = tool("synctest --scenario pushball --frames 300 --json");
  EXPECT_EQ(sync.exit_code, 0) << sync.err;
  EXPECT_EQ(json_value(sync.out, "ok"), "true");

  // Seeking (the API, with the game registered in this process) lands on the straight run.
  ensure_registered();
  auto reader = replay::ReplayReader::open(replay.path());
  ASSERT_TRUE(reader.ok()) << reader.message();
  auto at = replay::seek(reader.value(), 450);
  ASSERT_TRUE(at.ok()) << at.message();
  Scenario straight = make();
  for (std::uint64_t f = 1; f <= 450; ++f)
    straight.step_encoded(
        pushball::encode_frame(pushball::scripted(1, f, 0), pushball::scripted(1, f, 1)));
  EXPECT_EQ(at->world().save(), straight.world().save());
  // The same through the tool: the state at 450, as recorded, written for diff.
  TempFile state("seek450.state");
  const test::CliResult seek =
      tool("seek " + replay.path() + " 450 --json --save-state " + state.path());
  EXPECT_EQ(seek.exit_code, 0) << seek.err;
  EXPECT_EQ(json_value(seek.out, "ok"), "true") << seek.out;
  EXPECT_EQ(test::read_bytes(state.path()), straight.world().save());
  const test::CliResult past = tool("seek " + replay.path() + " 901");
  EXPECT_EQ(past.exit_code, 2);
  EXPECT_TRUE(
      has(past.err, "pushball-tool seek: " + replay.path() + " has frames 0 .. 900, not 901"))
      << past.err;

  // The stock detsim does not know the game, and says where it is known.
  const test::CliResult stock = test::detsim_cli("verify " + replay.path());
  EXPECT_EQ(stock.exit_code, 2);
  EXPECT_TRUE(has(stock.err, "scenario \"pushball\" is not one of this program's scenarios"))
      << stock.err;
  EXPECT_TRUE(has(stock.err, "detsim::cli::run_cli")) << stock.err;
}

TEST(ExamplePushball, BisectNamesTheGamesOwnScoreFieldAndABodysField) {
  TempFile clean("clean.dsr");
  TempFile scored("scored.dsr");
  TempFile report("nudged.dsd");
  ASSERT_EQ(tool("run --scenario pushball --frames 900 --record " + clean.path()).exit_code, 0);
  ASSERT_EQ(tool("run --scenario pushball --frames 900 --record " + scored.path() +
                 " --inject 600:0:game.score.player1:1")
                .exit_code,
            0);
  const test::CliResult game = tool("bisect " + clean.path() + " " + scored.path() + " --json");
  EXPECT_EQ(game.exit_code, 1) << game.err;
  EXPECT_EQ(json_value(game.out, "first_divergent_frame"), "600") << game.out;
  EXPECT_EQ(json_value(game.out, "exact"), "true") << game.out;
  EXPECT_TRUE(has(game.out, R"("diffs":[{"subsystem":"game","body":0,"field":"score.player1",)"))
      << game.out;

  // A machine that nudges a puck's height while verifying the clean replay writes its side as a
  // desync report; bisected against the replay, it names the frame, the body and the field.
  const BodyId puck = pushball::find(make().world(), pushball::player_tag + 1);
  ASSERT_FALSE(puck.is_null());
  const test::CliResult v =
      tool("verify " + clean.path() + " --inject 700:" + std::to_string(puck.value) +
           ":position.y:0.001 --report " + report.path());
  EXPECT_EQ(v.exit_code, 1) << v.out << v.err;
  const test::CliResult body = tool("bisect " + clean.path() + " " + report.path() + " --json");
  EXPECT_EQ(body.exit_code, 1) << body.err;
  EXPECT_EQ(json_value(body.out, "first_divergent_frame"), "700") << body.out;
  EXPECT_TRUE(has(body.out, R"("diffs":[{"subsystem":"bodies","body":)" +
                                std::to_string(puck.value) + R"(,"field":"position.y",)"))
      << body.out;
}

TEST(ExamplePushball, DiffOfTwoSavedStatesNamesTheScoreField) {
  TempFile a("a.state");
  TempFile b("b.state");
  ASSERT_EQ(tool("run --scenario pushball --frames 300 --save-state " + a.path()).exit_code, 0);
  ASSERT_EQ(tool("run --scenario pushball --frames 300 --save-state " + b.path() +
                 " --inject 300:0:game.score.player2:2")
                .exit_code,
            0);
  const test::CliResult d =
      tool("diff " + a.path() + " " + b.path() + " --scenario pushball --json");
  EXPECT_EQ(d.exit_code, 1) << d.err;
  EXPECT_TRUE(has(d.out, R"("subsystem":"game","body":0,"field":"score.player2")")) << d.out;
}

}  // namespace
}  // namespace detsim
