// detsim golden check / update: the scenario hashes and replays that every architecture must
// reproduce (golden/README.md).
//
// golden/scenarios.txt holds one line per golden run:
//   <scenario> seed=S players=P count=C frames=N 1=<hash> 10=<hash> 100=<hash> 1000=<hash>
//   last=<hash> chain=<hash>
// (frame hashes only for frames <= N; chain is the XXH3 of every frame's hash, as in replays).
// golden/replays/*.dsr are replays that must verify.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <detsim/replay.hpp>

#include "commands.hpp"
#include "golden_runs.hpp"
#include "output.hpp"
#include "scenario_args.hpp"

#ifndef DETSIM_GOLDEN_DIR
#define DETSIM_GOLDEN_DIR "golden"
#endif

namespace detsim::cli {

namespace {

namespace fs = std::filesystem;

using golden::GoldenRun;
constexpr const auto& kRuns = golden::runs;

/// The golden replays (recorded by `golden update`, verified by `golden check`).
struct GoldenReplay {
  const char* file;
  const char* scenario;
  ScenarioParams params;
  std::uint32_t frames;
  std::uint32_t keyframe_interval;
};

constexpr GoldenReplay kReplays[] = {
    {"arena.dsr", "arena", {.seed = 7, .players = 2, .count = 0}, 300, 100},
    {"spray.dsr", "spray", {.seed = 5, .players = 0, .count = 0}, 240, 120},
    {"pile_boxes.dsr", "pile_boxes", {.seed = 1, .players = 0, .count = 27}, 120, 60},
};

constexpr std::uint64_t kCheckFrames[] = {1, 10, 100, 1000};

/// The hashes a golden run records, as key -> hex.
using Entry = std::map<std::string, std::string>;

std::string run_key(const GoldenRun& r) {
  return std::string(r.scenario) + " seed=" + std::to_string(r.params.seed) +
         " players=" + std::to_string(r.params.players) +
         " count=" + std::to_string(r.params.count) + " frames=" + std::to_string(r.frames);
}

Expected<Entry> compute(const GoldenRun& run) {
  auto scenario = Scenario::create(run.scenario, run.params);
  if (!scenario) return scenario.status();
  replay::RecordOptions options;
  options.frames = static_cast<std::uint32_t>(run.frames);
  Entry entry;
  options.progress = [&](std::uint64_t done, std::uint64_t) {
    for (const std::uint64_t f : kCheckFrames) {
      if (done == f) entry[std::to_string(f)] = hex(scenario.value().world().hashes().total);
    }
    return true;
  };
  auto result = replay::record(scenario.value(), "", options);
  if (!result) return result.status();
  entry["last"] = hex(result->final_hash);
  entry["chain"] = hex(result->chain_hash);
  return entry;
}

std::string entry_text(const Entry& e) {
  std::string out;
  for (const std::uint64_t f : kCheckFrames) {
    const auto it = e.find(std::to_string(f));
    if (it != e.end()) out += " " + it->first + "=" + it->second;
  }
  return out + " last=" + e.at("last") + " chain=" + e.at("chain");
}

constexpr const char* kHeader =
    "# Golden scenario hashes: every architecture must reproduce them (golden/README.md).\n"
    "# Written by `detsim golden update`, on purpose only; checked by `detsim golden check`.\n"
    "# <scenario> <parameters> frames=N  <frame>=<state hash> ... last=<hash of frame N>\n"
    "#   chain=<XXH3-64 of every frame's hash, 8 little-endian bytes each>\n";

struct Mismatch {
  std::string run;
  std::string what;
  std::string expected;
  std::string actual;
};

int update(const fs::path& dir, bool json) {
  std::error_code ec;
  fs::create_directories(dir / "replays", ec);
  if (ec) return usage_error("golden update", "cannot create " + (dir / "replays").string());
  std::string text = kHeader;
  for (const GoldenRun& run : kRuns) {
    auto entry = compute(run);
    if (!entry) return usage_error("golden update", run_key(run) + ": " + entry.message());
    text += run_key(run) + entry_text(entry.value()) + "\n";
  }
  const fs::path file = dir / "scenarios.txt";
  std::ofstream out(file, std::ios::trunc);
  out << text;
  if (!out) return usage_error("golden update", "cannot write " + file.string());
  for (const GoldenReplay& g : kReplays) {
    auto scenario = Scenario::create(g.scenario, g.params);
    if (!scenario) return usage_error("golden update", scenario.message());
    replay::RecordOptions options;
    options.frames = g.frames;
    options.keyframe_interval = g.keyframe_interval;
    auto recorded = replay::record(scenario.value(), (dir / "replays" / g.file).string(), options);
    if (!recorded) return usage_error("golden update", recorded.message());
  }
  if (json) {
    Json()
        .boolean("ok", true)
        .str("dir", dir.string())
        .num("runs", std::size(kRuns))
        .num("replays", std::size(kReplays))
        .print();
  } else {
    std::printf("golden: wrote %s (%zu runs) and %zu replays in %s\n", file.string().c_str(),
                std::size(kRuns), std::size(kReplays), (dir / "replays").string().c_str());
  }
  return exit_ok;
}

/// Parses scenarios.txt into run key -> entry; errors name the line.
Expected<std::map<std::string, Entry>> parse(const fs::path& file) {
  std::ifstream in(file);
  if (!in)
    return Status::error("cannot read " + file.string() +
                         " (pass --dir, or create it with detsim golden update)");
  std::map<std::string, Entry> out;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line[0] == '#') continue;
    std::istringstream words(line);
    std::string word;
    std::string key;
    Entry entry;
    int n = 0;
    while (words >> word) {
      if (n++ < 5) {  // scenario seed= players= count= frames=
        key += (key.empty() ? "" : " ") + word;
        continue;
      }
      const auto eq = word.find('=');
      if (eq == std::string::npos || word.size() - eq - 1 != 16)
        return Status::error(file.string() + ":" + std::to_string(number) + ": '" + word +
                             "' is not <frame>=<16 hex digits>");
      entry[word.substr(0, eq)] = word.substr(eq + 1);
    }
    if (n < 7 || entry.count("last") == 0 || entry.count("chain") == 0)
      return Status::error(file.string() + ":" + std::to_string(number) +
                           ": expected a scenario, its parameters, frames=N, and last= and chain=");
    out[key] = entry;
  }
  return out;
}

int check(const fs::path& dir, bool json) {
  auto golden = parse(dir / "scenarios.txt");
  if (!golden) return usage_error("golden check", golden.message());
  std::vector<Mismatch> mismatches;
  std::size_t runs = 0;
  for (const GoldenRun& run : kRuns) {
    const std::string key = run_key(run);
    const auto it = golden.value().find(key);
    if (it == golden.value().end()) {
      mismatches.push_back({key, "no golden entry (run detsim golden update)", "", ""});
      continue;
    }
    auto actual = compute(run);
    if (!actual) return usage_error("golden check", key + ": " + actual.message());
    ++runs;
    for (const auto& [what, expected] : it->second) {
      const auto got = actual.value().find(what);
      const std::string value = got == actual.value().end() ? "(not computed)" : got->second;
      if (value != expected)
        mismatches.push_back({key,
                              what == "chain"  ? "chain"
                              : what == "last" ? "last frame"
                                               : "frame " + what,
                              expected, value});
    }
  }
  std::size_t replays = 0;
  for (const GoldenReplay& g : kReplays) {
    const std::string path = (dir / "replays" / g.file).string();
    auto reader = replay::ReplayReader::open(path);
    if (!reader) return usage_error("golden check", reader.message());
    auto v = replay::verify(reader.value());
    if (!v) return usage_error("golden check", v.message());
    ++replays;
    if (!v->ok) {
      mismatches.push_back(
          {path, v->first_mismatch ? "frame " + std::to_string(*v->first_mismatch) : v->note,
           hex(v->expected.total), hex(v->actual.total)});
    }
  }
  const bool ok = mismatches.empty();
  if (json) {
    std::vector<std::string> items;
    for (const Mismatch& m : mismatches) {
      items.push_back(Json()
                          .str("run", m.run)
                          .str("what", m.what)
                          .str("expected", m.expected)
                          .str("actual", m.actual)
                          .text());
    }
    Json()
        .boolean("ok", ok)
        .str("dir", dir.string())
        .num("runs", runs)
        .num("replays", replays)
        .raw("mismatches", Json::array(items))
        .print();
  } else {
    for (const Mismatch& m : mismatches) {
      std::printf("golden MISMATCH: %s: %s: expected %s, got %s\n", m.run.c_str(), m.what.c_str(),
                  m.expected.empty() ? "-" : m.expected.c_str(),
                  m.actual.empty() ? "-" : m.actual.c_str());
    }
    std::printf("golden: %s: %zu runs and %zu replays checked, %zu mismatches\n",
                ok ? "ok" : "FAILED", runs, replays, mismatches.size());
  }
  return ok ? exit_ok : exit_check_failed;
}

}  // namespace

int golden_command(const GoldenArgs& args) {
  const fs::path dir = args.dir.empty() ? fs::path(DETSIM_GOLDEN_DIR) : fs::path(args.dir);
  return args.update ? update(dir, args.json) : check(dir, args.json);
}

}  // namespace detsim::cli
