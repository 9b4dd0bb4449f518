// detsim verify in bulk (several FILEs, --manifest, --jobs, --shard): shards that cover a manifest
// exactly, output that does not depend on the number of workers, bad replays reported as results
// while the others are still verified, the exit codes a scheduler's retry policy relies on, and
// usage errors that name what is wrong.
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "support/cli.hpp"
#include "support/replay_files.hpp"

namespace detsim {
namespace {

using test::detsim_cli;
using test::has;
using test::json_value;

/// A directory under the system's temporary directory, removed with everything in it.
class TempDir {
 public:
  explicit TempDir(const std::string& name) : file_(name) {
    std::filesystem::create_directories(file_.path());
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(file_.path(), ignored);
  }
  [[nodiscard]] std::string operator/(const std::string& name) const {
    return (std::filesystem::path(file_.path()) / name).string();
  }
  [[nodiscard]] const std::string& path() const { return file_.path(); }

 private:
  test::TempFile file_;
};

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    lines.push_back(line);
  return lines;
}

/// The line without its "seconds" field: what must not depend on the machine's speed.
std::string without_seconds(const std::string& line) {
  const std::size_t at = line.find("\"seconds\":");
  if (at == std::string::npos) return line;
  const std::size_t end = line.find_first_of(",}", at);
  return line.substr(0, at) + line.substr(end + 1);
}

/// Runs detsim with only the named scheduler variables set (none inherited from the caller).
test::CliResult detsim_with_env(const std::string& env, const std::string& args) {
  return test::run_program(
      "env -u JOB_COMPLETION_INDEX -u SLURM_ARRAY_TASK_ID -u AWS_BATCH_JOB_ARRAY_INDEX " + env +
          " " + test::detsim_binary(),
      args);
}

/// Seven short arena replays, a truncated and a corrupt copy, one recorded with a nudge (so that
/// re-simulating it disagrees from the nudged frame on), listed with a comment, a blank line and
/// a path that does not exist: eleven entries, relative to the list's directory.
class BulkVerify : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir("bulk");
    std::filesystem::create_directories(*dir_ / "replays");
    for (int seed = 1; seed <= 7; ++seed) {
      const test::CliResult run =
          detsim_cli("run --scenario arena --players 2 --frames 120 --seed " +
                     std::to_string(seed) + " --record " + replay(seed));
      ASSERT_EQ(run.exit_code, 0) << run.err;
    }
    auto bytes = test::read_bytes(replay(1));
    test::write_bytes(
        *dir_ / "replays/truncated.replay",
        std::vector<std::uint8_t>(
            bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(bytes.size() * 3 / 4)));
    bytes = test::read_bytes(replay(2));
    bytes[bytes.size() / 2] ^= 0x40;
    test::write_bytes(*dir_ / "replays/corrupt.replay", bytes);
    // Recorded with body 1's x nudged at frame 40: a faithful re-simulation differs there.
    const test::CliResult nudged = detsim_cli(
        "run --scenario arena --players 2 --frames 120 --seed 3 --inject 40:1:position.x:0.001 "
        "--record " +
        (*dir_ / "replays/nudged.replay"));
    ASSERT_EQ(nudged.exit_code, 0) << nudged.err;
    std::ofstream list(manifest());
    list << "# the bulk test's replays\n"
         << "replays/1.replay\n"
         << "replays/truncated.replay\n"
         << "\n"
         << "replays/2.replay\n"
         << "replays/corrupt.replay\n"
         << "replays/3.replay\n"
         << "replays/missing.replay\n"
         << "  replays/4.replay  \n"
         << "replays/nudged.replay\n"
         << replay(5) << "\n"  // an absolute path
         << "replays/6.replay\n"
         << "replays/7.replay\n";
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static std::string replay(int seed) {
    return *dir_ / ("replays/" + std::to_string(seed) + ".replay");
  }
  static std::string manifest() { return *dir_ / "list.txt"; }
  static constexpr std::size_t entries = 11;

  static TempDir* dir_;
};
TempDir* BulkVerify::dir_ = nullptr;

TEST_F(BulkVerify, ReportsEveryEntryInOrderWithItsResultAndStillVerifiesAfterBadOnes) {
  const test::CliResult r = detsim_cli("verify --manifest " + manifest() + " --json --jobs 2");
  // A desync among them: exit 1 (it outranks the unreadable ones' 2).
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  const std::vector<std::string> lines = lines_of(r.out);
  ASSERT_EQ(lines.size(), entries + 1) << r.out;
  const std::vector<std::string> expected = {"ok", "incomplete", "ok", "invalid", "ok", "invalid",
                                             "ok", "desync",     "ok", "ok",      "ok"};
  for (std::size_t i = 0; i < entries; ++i) {
    SCOPED_TRACE(lines[i]);
    EXPECT_EQ(json_value(lines[i], "index"), std::to_string(i));
    EXPECT_EQ(json_value(lines[i], "result"), expected[i]);
  }
  // Relative paths are the list's directory's; the absolute one is kept.
  EXPECT_EQ(json_value(lines[0], "path"), *dir_ / "replays/1.replay");
  EXPECT_EQ(json_value(lines[8], "path"), replay(5));
  EXPECT_EQ(json_value(lines[6], "path"), *dir_ / "replays/4.replay") << "spaces trimmed";
  // The ok ones verified all their frames; the truncated one the frames it holds.
  EXPECT_EQ(json_value(lines[0], "frames"), "120");
  EXPECT_EQ(json_value(lines[0], "first_bad_frame"), "null");
  EXPECT_GT(std::stoull(json_value(lines[1], "frames")), 0U) << lines[1];
  EXPECT_LT(std::stoull(json_value(lines[1], "frames")), 120U) << lines[1];
  EXPECT_TRUE(has(json_value(lines[1], "message"), "no end marker")) << lines[1];
  // The corrupt chunk and the missing file are named.
  EXPECT_TRUE(has(json_value(lines[3], "message"), "corrupt")) << lines[3];
  EXPECT_TRUE(has(json_value(lines[5], "message"), "cannot open")) << lines[5];
  EXPECT_EQ(json_value(lines[5], "scenario"), "null");
  // The nudge was at frame 40: the recorded hashes differ from there on.
  EXPECT_EQ(json_value(lines[7], "first_bad_frame"), "40") << lines[7];
  EXPECT_TRUE(has(json_value(lines[7], "message"), "bodies")) << lines[7];
  // The summary counts them.
  const std::string& summary = lines.back();
  EXPECT_EQ(summary.rfind("{\"summary\":{", 0), 0U) << summary;
  EXPECT_EQ(json_value(summary, "replays"), "11");
  EXPECT_EQ(json_value(summary, "ok"), "7");
  EXPECT_EQ(json_value(summary, "desync"), "1");
  EXPECT_EQ(json_value(summary, "invalid"), "2");
  EXPECT_EQ(json_value(summary, "incomplete"), "1");
  std::uint64_t frames = 0;
  for (std::size_t i = 0; i < entries; ++i)
    frames += std::stoull(json_value(lines[i], "frames"));
  EXPECT_EQ(json_value(summary, "frames"), std::to_string(frames));
}

TEST_F(BulkVerify, OneJobAndTwoPrintTheSameResultsInTheSameOrder) {
  const test::CliResult one = detsim_cli("verify --manifest " + manifest() + " --json --jobs 1");
  const test::CliResult two = detsim_cli("verify --manifest " + manifest() + " --json --jobs 2");
  EXPECT_EQ(one.exit_code, two.exit_code);
  const std::vector<std::string> a = lines_of(one.out);
  const std::vector<std::string> b = lines_of(two.out);
  ASSERT_EQ(a.size(), entries + 1);
  ASSERT_EQ(b.size(), entries + 1);
  for (std::size_t i = 0; i < entries; ++i)
    EXPECT_EQ(without_seconds(a[i]), without_seconds(b[i]));
  // The text form too, line for line apart from the ok lines' seconds.
  const test::CliResult text1 = detsim_cli("verify --manifest " + manifest() + " --jobs 1");
  const test::CliResult text2 = detsim_cli("verify --manifest " + manifest() + " --jobs 2");
  const std::vector<std::string> t1 = lines_of(text1.out);
  const std::vector<std::string> t2 = lines_of(text2.out);
  ASSERT_EQ(t1.size(), entries + 1) << text1.out;
  ASSERT_EQ(t2.size(), entries + 1) << text2.out;
  for (std::size_t i = 0; i < entries; ++i) {
    const auto strip = [](const std::string& s) { return s.substr(0, s.rfind(", ")); };
    EXPECT_EQ(strip(t1[i]), strip(t2[i]));
  }
  EXPECT_TRUE(has(t1[7], "DESYNC at frame 40")) << t1[7];
  EXPECT_TRUE(has(t1.back(), "11 replays: 7 ok, 1 desync, 2 invalid, 1 incomplete")) << t1.back();
}

TEST_F(BulkVerify, ShardsCoverTheManifestExactlyWhateverTheIndexsSource) {
  const test::CliResult whole = detsim_cli("verify --manifest " + manifest() + " --json --jobs 1");
  const std::vector<std::string> all = lines_of(whole.out);
  ASSERT_EQ(all.size(), entries + 1);
  // The scheduler's variables, each read by --shard auto, and env:NAME.
  const std::vector<std::string> sources = {"JOB_COMPLETION_INDEX", "SLURM_ARRAY_TASK_ID",
                                            "AWS_BATCH_JOB_ARRAY_INDEX", "MY_INDEX"};
  for (const std::uint64_t n : {1U, 2U, 3U, 4U, 11U, 12U}) {
    const std::string& var = sources[n % sources.size()];
    const std::string spec = var == "MY_INDEX" ? "env:MY_INDEX" : "auto";
    std::map<std::uint64_t, std::string> seen;
    for (std::uint64_t i = 0; i < n; ++i) {
      SCOPED_TRACE("shard " + std::to_string(i) + " of " + std::to_string(n) + " from " + var);
      const test::CliResult r = detsim_with_env(
          var + "=" + std::to_string(i), "verify --manifest " + manifest() + " --json --jobs 1 " +
                                             "--shard " + spec + " --of " + std::to_string(n));
      EXPECT_TRUE(r.exit_code == 0 || r.exit_code == 1 || r.exit_code == 2) << r.err;
      const std::vector<std::string> lines = lines_of(r.out);
      ASSERT_FALSE(lines.empty());
      for (std::size_t k = 0; k + 1 < lines.size(); ++k) {
        const std::uint64_t index = std::stoull(json_value(lines[k], "index"));
        EXPECT_EQ(index % n, i) << lines[k];
        EXPECT_TRUE(seen.emplace(index, lines[k]).second) << "entry " << index << " twice";
      }
      EXPECT_EQ(json_value(lines.back(), "shard"), std::to_string(i));
      EXPECT_EQ(json_value(lines.back(), "entries"), std::to_string(entries));
    }
    ASSERT_EQ(seen.size(), entries) << "shards of " << n;
    for (const auto& [index, line] : seen)
      EXPECT_EQ(without_seconds(line), without_seconds(all[index]));
  }
  // An explicit index, and FILEs before the manifest's entries.
  const test::CliResult files =
      detsim_cli("verify " + replay(6) + " " + replay(7) + " --manifest " + manifest() +
                 " --json --shard 1 --of 2");
  const std::vector<std::string> lines = lines_of(files.out);
  ASSERT_EQ(lines.size(), 7U) << files.out;  // entries 1, 3, ..., 11 of 13
  EXPECT_EQ(json_value(lines[0], "path"), replay(7));
  EXPECT_EQ(json_value(lines[1], "path"), *dir_ / "replays/truncated.replay");
}

TEST_F(BulkVerify, ExitStatusIsZeroOnlyWhenEveryReplayReproduces) {
  // All good, an incomplete one among them: 0.
  const std::string good = replay(1) + " " + replay(2) + " " + (*dir_ / "replays/truncated.replay");
  const test::CliResult ok = detsim_cli("verify " + good);
  EXPECT_EQ(ok.exit_code, 0) << ok.out << ok.err;
  EXPECT_TRUE(has(ok.out, "3 replays: 2 ok, 0 desync, 0 invalid, 1 incomplete")) << ok.out;
  // An unreadable one: 2, the others still verified.
  const test::CliResult bad =
      detsim_cli("verify " + good + " " + (*dir_ / "replays/corrupt.replay"));
  EXPECT_EQ(bad.exit_code, 2) << bad.out;
  EXPECT_TRUE(has(bad.out, "4 replays: 2 ok, 0 desync, 1 invalid, 1 incomplete")) << bad.out;
  // A desync: 1.
  const test::CliResult desync =
      detsim_cli("verify " + replay(3) + " " + (*dir_ / "replays/nudged.replay"));
  EXPECT_EQ(desync.exit_code, 1) << desync.out;
  // One file and no bulk option keeps the one-replay report.
  const test::CliResult single = detsim_cli("verify " + replay(4));
  EXPECT_EQ(single.exit_code, 0);
  EXPECT_TRUE(has(single.out, "reproduce every recorded hash")) << single.out;
  // ... and --jobs makes even one file a bulk run.
  const test::CliResult bulk_one = detsim_cli("verify " + replay(4) + " --jobs 1 --json");
  EXPECT_EQ(lines_of(bulk_one.out).size(), 2U) << bulk_one.out;
  EXPECT_EQ(json_value(bulk_one.out, "result"), "ok");
}

TEST_F(BulkVerify, BadUsageIsRefusedWithAMessageAndVerifiesNothing) {
  const struct {
    std::string args;
    std::string message;
  } cases[] = {
      {"verify", "nothing to verify"},
      {"verify --manifest " + manifest() + " --shard 0", "--shard needs --of N"},
      {"verify --manifest " + manifest() + " --of 2", "--of needs --shard I"},
      {"verify --manifest " + manifest() + " --shard 2 --of 2", "must be below the shard count"},
      {"verify --manifest " + manifest() + " --shard x --of 2", "must be a number"},
      {"verify --manifest " + manifest() + " --shard -1 --of 2", "must be a number"},
      {"verify --manifest " + manifest() + " --shard auto --of 2", "none of JOB_COMPLETION_INDEX"},
      {"verify --manifest " + manifest() + " --shard env:NO_SUCH_VARIABLE --of 2",
       "NO_SUCH_VARIABLE is not set"},
      {"verify --manifest " + (*dir_ / "no-such-list.txt"), "cannot open it"},
      {"verify " + replay(1) + " " + replay(2) + " --report x.dsd", "work on one replay"},
      {"verify --manifest " + manifest() + " --inject 5:1:position.x:1", "work on one replay"},
      {"verify --manifest " + manifest() + " --jobs 0", "--jobs"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.args);
    const test::CliResult r = detsim_with_env("", c.args);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_TRUE(r.out.empty()) << r.out;
    EXPECT_TRUE(has(r.err, c.message)) << r.err;
  }
  // With a shard index from the environment that is out of range, the variable is named.
  const test::CliResult r = detsim_with_env(
      "SLURM_ARRAY_TASK_ID=7", "verify --manifest " + manifest() + " --shard auto --of 4");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(has(r.err, "SLURM_ARRAY_TASK_ID=7")) << r.err;
}

}  // namespace
}  // namespace detsim
