// The detsim command as a user meets it: exit codes (0 ok, 1 a check failed, 2 bad usage or
// input), exactly one JSON object with --json, errors on stderr naming what is wrong, no progress
// output when stderr is not a terminal, and the golden check against the checked-in golden/.
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/replay.hpp>

#include "support/cli.hpp"
#include "support/replay_files.hpp"

namespace detsim {
namespace {

using test::detsim_cli;
using test::expect_one_json_object;
using test::has;
using test::json_value;
using test::read_bytes;
using test::read_text;
using test::TempFile;
using test::write_bytes;
using Result = test::CliResult;

std::string hex16(std::uint64_t v) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(v));
  return text;
}

/// The final hash of `scenario` after `frames` frames with scripted players, from the library.
std::uint64_t library_final_hash(const std::string& name, const ScenarioParams& params,
                                 std::uint32_t frames) {
  auto s = Scenario::create(name, params);
  EXPECT_TRUE(s) << s.message();
  replay::RecordOptions options;
  options.frames = frames;
  auto r = replay::record(s.value(), "", options);
  EXPECT_TRUE(r) << r.message();
  return r->final_hash;
}

TEST(Cli, HelpListsEverySubcommandAndEachHasItsOwnHelp) {
  const Result top = detsim_cli("--help");
  EXPECT_EQ(top.exit_code, 0);
  for (const char* sub :
       {"scenarios", "run", "verify", "info", "diff", "synctest", "golden", "demo"}) {
    EXPECT_TRUE(has(top.out, std::string("  ") + sub)) << sub;
    const Result help = detsim_cli(std::string(sub) + " --help");
    EXPECT_EQ(help.exit_code, 0) << sub;
    EXPECT_TRUE(has(help.out, "Usage:")) << sub;
  }
  for (const char* sub : {"run", "verify", "synctest", "golden check"}) {
    EXPECT_TRUE(has(detsim_cli(std::string(sub) + " --help").out, "Exit status: 0")) << sub;
  }
  EXPECT_EQ(detsim_cli("--version").out, "detsim " + std::string(version) + "\n");
  EXPECT_EQ(version, DETSIM_PROJECT_VERSION);  // <detsim/core/version.hpp> follows CMakeLists.txt
}

TEST(Cli, RunPrintsTheFrameCountAndTheLibrarysFinalHash) {
  const std::string expected = hex16(library_final_hash("arena", {.seed = 5, .players = 3}, 40));
  const Result json = detsim_cli("run --scenario arena --seed 5 --players 3 --frames 40 --json");
  EXPECT_EQ(json.exit_code, 0) << json.err;
  expect_one_json_object(json.out);
  EXPECT_EQ(json_value(json.out, "scenario"), "arena");
  EXPECT_EQ(json_value(json.out, "frames"), "40");
  EXPECT_EQ(json_value(json.out, "final_hash"), expected);
  EXPECT_EQ(json.err, "");  // no progress bar when stderr is not a terminal
  const Result text = detsim_cli("run --scenario arena --seed 5 --players 3 --frames 40");
  EXPECT_EQ(text.exit_code, 0);
  EXPECT_TRUE(has(text.out, "40 frames, final hash " + expected)) << text.out;
}

TEST(Cli, RecordVerifyInfoAndATamperedReplay) {
  TempFile file("cli.dsr");
  const Result run =
      detsim_cli("run --scenario spray --frames 90 --keyframe-interval 30 --record " + file.path() +
                 " --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const Result verify = detsim_cli("verify " + file.path() + " --json");
  EXPECT_EQ(verify.exit_code, 0) << verify.err;
  expect_one_json_object(verify.out);
  EXPECT_EQ(json_value(verify.out, "ok"), "true");
  EXPECT_EQ(json_value(verify.out, "frames"), "90");
  EXPECT_EQ(json_value(verify.out, "first_mismatch"), "null");
  EXPECT_EQ(json_value(verify.out, "final_hash"), json_value(run.out, "final_hash"));
  const Result info = detsim_cli("info " + file.path() + " --json");
  EXPECT_EQ(info.exit_code, 0);
  expect_one_json_object(info.out);
  EXPECT_EQ(json_value(info.out, "frames"), "90");
  EXPECT_TRUE(has(info.out, "\"keyframes\":[{\"frame\":30,")) << info.out;
  EXPECT_TRUE(has(detsim_cli("info " + file.path()).out, "keyframes         3 every 30 frames"));

  // The hash of frame 47 changed: verification fails there, exit code 1.
  auto b = read_bytes(file.path());
  for (const auto& c : test::chunks_of(b)) {
    if (c.type != "FRAM" || test::get_u64(b, c.payload()) > 47) continue;
    const std::uint64_t first = test::get_u64(b, c.payload());
    if (first + test::get_u32(b, c.payload() + 8) <= 47) continue;
    const std::size_t at = c.payload() + 12 + (47 - first) * 64;  // no players, total + 7 sections
    b[at] = static_cast<std::uint8_t>(b[at] ^ 1U);
    test::reseal(b, c);
  }
  write_bytes(file.path(), b);
  const Result bad = detsim_cli("verify " + file.path() + " --json");
  EXPECT_EQ(bad.exit_code, 1);
  expect_one_json_object(bad.out);
  EXPECT_EQ(json_value(bad.out, "ok"), "false");
  EXPECT_EQ(json_value(bad.out, "first_mismatch"), "47");
  const Result text = detsim_cli("verify " + file.path());
  EXPECT_EQ(text.exit_code, 1);
  EXPECT_TRUE(has(text.out, "MISMATCH at frame 47")) << text.out;
  EXPECT_TRUE(has(text.out, "last agreed frame: 46")) << text.out;
}

TEST(Cli, BadUsageAndBadInputExitWithTwoAndSayWhatIsWrong) {
  TempFile junk("junk.dsr");
  write_bytes(junk.path(), std::vector<std::uint8_t>(100, 0x41));
  struct Case {
    std::string args;
    std::string message;  ///< on stderr
  };
  const std::vector<Case> cases = {
      {"run", "--scenario is required"},
      {"run --scenario nope", "unknown scenario 'nope'; known: arena,"},
      {"run --scenario arena --players 65", "takes 2 to 64 players, got 65"},
      {"run --scenario arena --frames 0", "--frames"},
      {"run --scenario arena --frames abc", "--frames"},
      {"run --scenario stack --frames 1 --record /nonexistent-dir/x.dsr",
       "/nonexistent-dir/x.dsr: cannot create"},
      {"synctest --scenario stack --check-distance 0", "--check-distance must be 1 to 600"},
      {"verify", "nothing to verify: give replay FILEs or --manifest LIST"},
      {"verify " + junk.path(), junk.path() + ": byte 0: expected the magic"},
      {"verify /nonexistent-file.dsr", "/nonexistent-file.dsr: cannot open"},
      {"info " + junk.path(), "this is not a detsim replay"},
      {"golden check --dir /nonexistent-dir", "cannot read /nonexistent-dir/scenarios.txt"},
      {"frobnicate", "frobnicate"},
      {"run --scenario arena --bogus-flag", "--bogus-flag"},
  };
  for (const Case& c : cases) {
    const Result r = detsim_cli(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args << "\n" << r.err;
    EXPECT_TRUE(has(r.err, c.message)) << c.args << "\nstderr: " << r.err;
    EXPECT_EQ(r.out, "") << c.args;
  }
}

TEST(Cli, DiffNamesTheFieldThatDiffersAndExitsOneOrZero) {
  ScenarioParams params;
  params.players = 2;
  Scenario s = Scenario::create("arena", params).value();
  for (int f = 0; f < 30; ++f)
    s.step();
  TempFile a("a.state");
  TempFile b("b.state");
  write_bytes(a.path(), s.world().save());
  const BodyId id = s.player_body(0);
  const Vec3 v = s.world().body(id).value().angular_velocity;
  ASSERT_TRUE(s.world().set_angular_velocity(id, {v.x + Fixed::from_raw(5), v.y, v.z}).ok());
  write_bytes(b.path(), s.world().save());

  const Result same = detsim_cli("diff " + a.path() + " " + a.path());
  EXPECT_EQ(same.exit_code, 0) << same.err;
  EXPECT_TRUE(has(same.out, "equal: frame 30")) << same.out;

  const Result text = detsim_cli("diff " + a.path() + " " + b.path());
  EXPECT_EQ(text.exit_code, 1) << text.err;
  EXPECT_TRUE(has(text.out, "body " + std::to_string(id.value))) << text.out;
  EXPECT_TRUE(has(text.out, "angular_velocity.x")) << text.out;

  const Result json = detsim_cli("diff " + a.path() + " " + b.path() + " --json");
  EXPECT_EQ(json.exit_code, 1);
  expect_one_json_object(json.out);
  EXPECT_EQ(json_value(json.out, "equal"), "false");
  EXPECT_TRUE(has(json.out, "\"field\":\"angular_velocity.x\"")) << json.out;

  const Result broken = detsim_cli("diff " + a.path() + " /nonexistent/state");
  EXPECT_EQ(broken.exit_code, 2);
  EXPECT_TRUE(has(broken.err, "/nonexistent/state: cannot open the file")) << broken.err;
  TempFile junk("junk.state");
  write_bytes(junk.path(), std::vector<std::uint8_t>(64, 0x41));
  const Result bad = detsim_cli("diff " + junk.path() + " " + a.path());
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_TRUE(has(bad.err, junk.path() + ": ")) << bad.err;
  EXPECT_EQ(bad.out, "");
}

// States of a scene with registered geometry, written by `run --save-state`: diffed against the
// scenario's world (--scenario), the field is named; without it, the error says what is missing;
// states of different geometry name the differing entry by type and content hash.
TEST(Cli, DiffOfAGeometrySceneNeedsItsScenarioAndNamesDifferingGeometry) {
  TempFile a("rocks_a.state");
  TempFile b("rocks_b.state");
  TempFile other("rocks_seed2.state");
  const std::string run = "run --scenario rocks --count 30 --frames 40 --save-state ";
  Result r = detsim_cli(run + a.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(has(r.out, "state written to " + a.path())) << r.out;
  r = detsim_cli(run + b.path() + " --inject 40:7:angular_velocity.z:0.5");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = detsim_cli(run + other.path() + " --seed 2");
  ASSERT_EQ(r.exit_code, 0) << r.err;

  r = detsim_cli("diff " + a.path() + " " + b.path() + " --scenario rocks --count 30 --json");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  expect_one_json_object(r.out);
  EXPECT_TRUE(has(r.out, R"("differences":[{"subsystem":"bodies","body":7,)"
                         R"("field":"angular_velocity.z",)"))
      << r.out;
  r = detsim_cli("diff " + a.path() + " " + a.path() + " --scenario rocks --count 30");
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_TRUE(has(r.out, "equal: frame 40")) << r.out;

  r = detsim_cli("diff " + a.path() + " " + b.path());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(has(r.err, a.path() + ": ")) << r.err;
  EXPECT_TRUE(has(r.err, "the state needs geometry 1 (heightfield, content hash 0x")) << r.err;
  EXPECT_TRUE(has(r.err, "--scenario")) << r.err;

  r = detsim_cli("diff " + a.path() + " " + other.path() + " --scenario rocks --count 30");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_TRUE(has(r.out, "geometry     geometry[2]            A convex hull, content hash 0x"))
      << r.out;
  EXPECT_TRUE(has(r.out, "note: state B names geometry that the world given does not hold"))
      << r.out;

  r = detsim_cli("diff " + a.path() + " " + b.path() + " --scenario nowhere");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(has(r.err, "unknown scenario 'nowhere'")) << r.err;
}

TEST(Cli, HelpNamesTheSubShapeContactSyntaxAndDiffsScenario) {
  const Result run = detsim_cli("run --help");
  EXPECT_TRUE(has(run.out, "contact[OTHER/S/T]")) << run.out;
  EXPECT_TRUE(has(run.out, "--save-state")) << run.out;
  const Result diff = detsim_cli("diff --help");
  EXPECT_TRUE(has(diff.out, "--scenario")) << diff.out;
  EXPECT_TRUE(has(diff.out, "geometry[N]")) << diff.out;
}

TEST(Cli, SynctestPassesOnEveryKindOfScene) {
  for (const char* scene :
       {"arena --players 3", "spray", "dominoes", "flag", "jelly --count 2",
        "rope_bridge --count 3", "drape --count 8", "wrecking_rope", "dam_break --count 3"}) {
    const Result r = detsim_cli(std::string("synctest --scenario ") + scene +
                                " --frames 40 --check-distance 7 --json");
    EXPECT_EQ(r.exit_code, 0) << scene << r.err;
    expect_one_json_object(r.out);
    EXPECT_EQ(json_value(r.out, "ok"), "true") << r.out;
    EXPECT_EQ(json_value(r.out, "first_mismatch"), "null");
    EXPECT_EQ(json_value(r.out, "resimulated_frames"), std::to_string((40 - 7 + 1) * 7));
  }
}

TEST(Cli, ScenariosListsTheRegistry) {
  const Result json = detsim_cli("scenarios --json");
  EXPECT_EQ(json.exit_code, 0);
  expect_one_json_object(json.out);
  const Result text = detsim_cli("scenarios");
  for (const ScenarioInfo& info : scenario_list()) {
    EXPECT_TRUE(has(json.out, "{\"name\":\"" + std::string(info.name) + "\"")) << info.name;
    EXPECT_TRUE(has(text.out, std::string(info.name) + " ")) << info.name;
  }
}

/// The checked-in golden hashes and replays reproduce on this machine; a changed golden hash is
/// reported with the run, the frame and both hashes, exit code 1.
TEST(Cli, GoldenCheckPassesAndNamesAMismatch) {
  const std::string golden = std::string(DETSIM_SOURCE_DIR) + "/golden";
  const Result ok = detsim_cli("golden check --dir " + golden + " --json");
  EXPECT_EQ(ok.exit_code, 0) << ok.out << ok.err;
  EXPECT_EQ(json_value(ok.out, "ok"), "true");
  EXPECT_EQ(json_value(ok.out, "mismatches"), "[]");

  namespace fs = std::filesystem;
  const fs::path copy = fs::temp_directory_path() / ("detsim_golden_" + std::to_string(getpid()));
  fs::remove_all(copy);
  fs::copy(golden, copy, fs::copy_options::recursive);
  std::string text = read_text((copy / "scenarios.txt").string());
  const auto line = text.find("\nbounce ");
  ASSERT_NE(line, std::string::npos);
  const auto at = text.find(" 100=", line) + 5;
  const std::string recorded = text.substr(at, 16);
  text[at] = text[at] == '0' ? '1' : '0';
  const std::string changed = text.substr(at, 16);
  write_bytes((copy / "scenarios.txt").string(), {text.begin(), text.end()});
  const Result bad = detsim_cli("golden check --dir " + copy.string());
  fs::remove_all(copy);
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_TRUE(has(bad.out,
                  "golden MISMATCH: bounce seed=1 players=0 count=0 frames=1000: frame "
                  "100: expected " +
                      changed + ", got " + recorded))
      << bad.out;
}

}  // namespace
}  // namespace detsim
