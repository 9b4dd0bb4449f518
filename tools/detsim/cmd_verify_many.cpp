// detsim verify in bulk: many replays (FILEs and/or a --manifest), on --jobs worker threads, one
// --shard of them, one result line each in the entries' order (docs/SCALE.md).
//
// Data flow: the entries (the FILEs, then the manifest's lines) are numbered from 0; this process
// keeps those whose number modulo --of is --shard. Workers take the kept entries in order from a
// shared counter and verify each on their own (a replay's verification shares nothing with
// another's: the scenario registry is only read, and the simulation's scratch is thread_local).
// The main thread prints results in the entries' order as they complete, so the output is the same
// whatever the number of workers; workers stay at most `window` entries ahead of the printer,
// which bounds the results held in memory whatever the manifest's length.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include <detsim/replay.hpp>
#include <detsim/sim/state_diff.hpp>

#include "commands.hpp"
#include "output.hpp"
#include "scenario_args.hpp"

namespace detsim::cli {

namespace {

constexpr std::string_view bulk_command = "verify";

/// The environment variables --shard auto reads, in this order: Kubernetes Indexed Jobs, Slurm
/// array jobs, AWS Batch array jobs.
constexpr const char* shard_variables[] = {"JOB_COMPLETION_INDEX", "SLURM_ARRAY_TASK_ID",
                                           "AWS_BATCH_JOB_ARRAY_INDEX"};

enum class BulkOutcome { ok, desync, invalid, incomplete };

const char* outcome_name(BulkOutcome o) {
  switch (o) {
    case BulkOutcome::ok:
      return "ok";
    case BulkOutcome::desync:
      return "desync";
    case BulkOutcome::invalid:
      return "invalid";
    case BulkOutcome::incomplete:
      return "incomplete";
  }
  return "invalid";
}

struct BulkEntry {
  std::uint64_t index = 0;  ///< among all entries, from 0
  std::string path;         ///< as opened: a manifest's relative paths joined to its directory
};

struct BulkResult {
  BulkOutcome outcome = BulkOutcome::invalid;
  std::uint64_t frames = 0;  ///< frames re-simulated and compared
  std::optional<std::uint64_t> first_bad_frame;
  double seconds = 0;
  double game_seconds = 0;  ///< frames × the replay's dt: the time the verified frames cover
  std::string scenario;     ///< "arena (seed 1, 2 players)", or empty when unreadable
  std::optional<std::uint64_t> final_hash;
  std::string message;  ///< why invalid, which parts desynced, what an incomplete replay lacks
};

BulkResult verify_one(const std::string& path) {
  const auto start = std::chrono::steady_clock::now();
  BulkResult r;
  const auto finish = [&] {
    r.seconds = seconds_since(start);
    return r;
  };
  auto reader = replay::ReplayReader::open(path);
  if (!reader) {
    r.message = reader.message();
    return finish();
  }
  r.scenario = describe(reader->fingerprint());
  auto verified = replay::verify(reader.value());
  if (!verified) {
    r.message = verified.message();
    return finish();
  }
  const replay::VerifyResult& v = verified.value();
  r.frames = v.frames;
  r.final_hash = v.final_hash;
  r.game_seconds = static_cast<double>(v.frames) * reader->fingerprint().dt.to_double();
  if (v.first_mismatch) {
    r.outcome = BulkOutcome::desync;
    r.first_bad_frame = v.first_mismatch;
    std::string parts;
    for (const std::string& p : differing_subsystems(v.expected, v.actual))
      parts += (parts.empty() ? "" : ", ") + p;
    r.message = v.note.empty() ? "differing parts: " + parts : v.note;
  } else if (!v.ok) {
    // The frames reproduce but the file disagrees with itself (its end marker's chain hash).
    r.message = v.note;
  } else if (!reader->complete()) {
    r.outcome = BulkOutcome::incomplete;
    r.message = v.note;
  } else {
    r.outcome = BulkOutcome::ok;
  }
  return finish();
}

/// --shard's index: a number, or read from the scheduler's environment.
Expected<std::uint64_t> shard_index(const std::string& spec, std::uint64_t count) {
  std::string text = spec;
  std::string source = "--shard " + spec;
  const auto from_env = [&](const char* var) -> std::optional<std::string> {
    const char* value = std::getenv(var);
    if (value == nullptr || *value == '\0') return std::nullopt;
    source = "--shard " + spec + " (" + var + "=" + value + ")";
    return std::string(value);
  };
  if (spec == "auto") {
    std::optional<std::string> found;
    for (const char* var : shard_variables)
      if ((found = from_env(var))) break;
    if (!found)
      return Status::error(
          "--shard auto: none of JOB_COMPLETION_INDEX, SLURM_ARRAY_TASK_ID, "
          "AWS_BATCH_JOB_ARRAY_INDEX is set (give the index, or env:NAME)");
    text = *found;
  } else if (spec.rfind("env:", 0) == 0) {
    const std::string var = spec.substr(4);
    auto found = from_env(var.c_str());
    if (!found) return Status::error("--shard " + spec + ": " + var + " is not set");
    text = *found;
  }
  const bool digits =
      !text.empty() && text.size() <= 18 &&
      std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; });
  if (!digits)
    return Status::error(source + ": the shard index must be a number from 0, auto or env:NAME");
  const std::uint64_t index = std::stoull(text);
  if (index >= count)
    return Status::error(source + " --of " + std::to_string(count) +
                         ": the index must be below the shard count (shards are 0 to " +
                         std::to_string(count - 1) + ")");
  return index;
}

/// The entries: the FILEs, then the manifest's paths.
Expected<std::vector<std::string>> entries_of(const VerifyArgs& args) {
  std::vector<std::string> paths = args.files;
  if (args.manifest.empty()) return paths;
  std::ifstream in(args.manifest);
  if (!in) return Status::error("--manifest " + args.manifest + ": cannot open it");
  const std::filesystem::path dir = std::filesystem::path(args.manifest).parent_path();
  std::string line;
  std::uint64_t number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();  // a list written on Windows
    const std::size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    const std::size_t last = line.find_last_not_of(" \t");
    const std::filesystem::path p(line.substr(first, last - first + 1));
    paths.push_back(p.is_absolute() || dir.empty() ? p.string() : (dir / p).string());
  }
  if (in.bad()) return Status::error("--manifest " + args.manifest + ": read error");
  return paths;
}

std::string json_line(const BulkEntry& e, const BulkResult& r) {
  Json j;
  j.num("index", e.index).str("path", e.path).str("result", outcome_name(r.outcome));
  j.num("frames", r.frames).frame("first_bad_frame", r.first_bad_frame).real("seconds", r.seconds);
  if (r.scenario.empty()) {
    j.null("scenario");
  } else {
    j.str("scenario", r.scenario);
  }
  if (r.final_hash) {
    j.hash("final_hash", *r.final_hash);
  } else {
    j.null("final_hash");
  }
  if (r.message.empty()) {
    j.null("message");
  } else {
    j.str("message", r.message);
  }
  return j.text();
}

std::string text_line(const BulkEntry& e, const BulkResult& r) {
  const std::string frames = std::to_string(r.frames) + " frames";
  const std::string of = r.scenario.empty() ? "" : " of " + r.scenario;
  char seconds[32];
  std::snprintf(seconds, sizeof seconds, "%.2f s", r.seconds);
  switch (r.outcome) {
    case BulkOutcome::ok:
      return e.path + ": ok: " + frames + of + ", final hash " + hex(*r.final_hash) + ", " +
             seconds;
    case BulkOutcome::incomplete:
      return e.path + ": incomplete: " + frames + of + " reproduce; " + r.message;
    case BulkOutcome::desync:
      return e.path + ": DESYNC at frame " + std::to_string(*r.first_bad_frame) + of + "; " +
             r.message;
    case BulkOutcome::invalid:
      return e.path + ": INVALID: " + r.message;
  }
  return e.path;
}

struct BulkTotals {
  std::uint64_t replays = 0;
  std::uint64_t counts[4] = {};
  std::uint64_t frames = 0;
  double replay_seconds = 0;  ///< the replays' own seconds, summed
  double game_seconds = 0;
  void add(const BulkResult& r) {
    ++replays;
    ++counts[static_cast<int>(r.outcome)];
    frames += r.frames;
    replay_seconds += r.seconds;
    game_seconds += r.game_seconds;
  }
  [[nodiscard]] std::uint64_t count(BulkOutcome o) const { return counts[static_cast<int>(o)]; }
};

/// Runs `verify_one` over `entries` on `jobs` threads, calling `print` in the entries' order.
template <class Print>
void verify_in_order(const std::vector<BulkEntry>& entries, std::uint32_t jobs, Print&& print) {
  const std::size_t window = 1024;  // results a worker may hold ahead of the printer
  std::mutex mutex;
  std::condition_variable changed;
  std::map<std::size_t, BulkResult> done;
  std::size_t next = 0;     // the next entry a worker takes
  std::size_t printed = 0;  // entries printed so far
  const auto work = [&] {
    std::unique_lock lock(mutex);
    for (;;) {
      changed.wait(lock, [&] { return next >= entries.size() || next < printed + window; });
      if (next >= entries.size()) return;
      const std::size_t i = next++;
      lock.unlock();
      BulkResult r = verify_one(entries[i].path);
      lock.lock();
      done.emplace(i, std::move(r));
      changed.notify_all();
    }
  };
  std::vector<std::thread> workers;
  for (std::uint32_t k = 0; k < jobs && k < entries.size(); ++k) {
    try {
      workers.emplace_back(work);
    } catch (const std::system_error&) {
      break;  // a platform without threads (or out of them): the ones started do the work
    }
  }
  if (workers.empty() && !entries.empty()) workers.emplace_back(work);  // rethrows: no way on
  std::unique_lock lock(mutex);
  while (printed < entries.size()) {
    changed.wait(lock, [&] { return done.count(printed) != 0; });
    auto node = done.extract(printed);
    lock.unlock();
    print(entries[printed], node.mapped());
    lock.lock();
    ++printed;
    changed.notify_all();
  }
  lock.unlock();
  for (std::thread& t : workers)
    t.join();
}

}  // namespace

int verify_many_command(const VerifyArgs& args) {
  if (!args.report.empty() || args.at != 0 || !args.injections.empty())
    return usage_error(
        bulk_command,
        "--report, --at and --inject work on one replay; bulk verification (" +
            std::string(args.files.size() > 1 ? "several FILEs" : "--manifest, --jobs or --shard") +
            ") takes none of them");
  if (args.files.empty() && args.manifest.empty())
    return usage_error(bulk_command, "nothing to verify: give replay FILEs or --manifest LIST");
  if (args.shard.empty() != (args.shard_count == 0))
    return usage_error(bulk_command, args.shard.empty() ? "--of needs --shard I"
                                                        : "--shard needs --of N (the shard count)");
  std::uint64_t shard = 0;
  const std::uint64_t shards = args.shard_count == 0 ? 1 : args.shard_count;
  if (!args.shard.empty()) {
    auto index = shard_index(args.shard, shards);
    if (!index) return usage_error(bulk_command, index.message());
    shard = index.value();
  }
  auto paths = entries_of(args);
  if (!paths) return usage_error(bulk_command, paths.message());
  std::vector<BulkEntry> entries;
  for (std::uint64_t i = shard; i < paths->size(); i += shards)
    entries.push_back({i, (*paths)[static_cast<std::size_t>(i)]});
  const std::uint32_t jobs =
      args.jobs != 0 ? args.jobs : std::max(1U, std::thread::hardware_concurrency());

  BulkTotals totals;
  Progress progress("verify");
  const auto start = std::chrono::steady_clock::now();
  verify_in_order(entries, jobs, [&](const BulkEntry& e, const BulkResult& r) {
    totals.add(r);
    progress.done();  // a result line replaces the bar, which comes back after a second
    if (args.json) {
      std::printf("%s\n", json_line(e, r).c_str());
    } else {
      std::printf("%s\n", text_line(e, r).c_str());
    }
    std::fflush(stdout);
    progress.update(totals.replays, entries.size());
  });
  progress.done();
  const double seconds = seconds_since(start);
  const double realtime = seconds > 0 ? totals.game_seconds / seconds : 0.0;
  if (args.json) {
    Json summary;
    summary.num("replays", totals.replays)
        .num("ok", totals.count(BulkOutcome::ok))
        .num("desync", totals.count(BulkOutcome::desync))
        .num("invalid", totals.count(BulkOutcome::invalid))
        .num("incomplete", totals.count(BulkOutcome::incomplete))
        .num("frames", totals.frames)
        .real("seconds", seconds)
        .real("replay_seconds", totals.replay_seconds)
        .real("game_seconds", totals.game_seconds)
        .real("realtime_factor", realtime)
        .num("jobs", jobs)
        .num("shard", shard)
        .num("shards", shards)
        .num("entries", paths->size());
    Json().raw("summary", summary.text()).print();
  } else {
    std::printf(
        "%llu replays%s: %llu ok, %llu desync, %llu invalid, %llu incomplete; %llu frames in "
        "%.2f s on %u jobs (%.0fx real time)\n",
        static_cast<unsigned long long>(totals.replays),
        shards > 1 ? (" (shard " + std::to_string(shard) + " of " + std::to_string(shards) +
                      ", entries " + std::to_string(paths->size()) + ")")
                         .c_str()
                   : "",
        static_cast<unsigned long long>(totals.count(BulkOutcome::ok)),
        static_cast<unsigned long long>(totals.count(BulkOutcome::desync)),
        static_cast<unsigned long long>(totals.count(BulkOutcome::invalid)),
        static_cast<unsigned long long>(totals.count(BulkOutcome::incomplete)),
        static_cast<unsigned long long>(totals.frames), seconds, jobs, realtime);
  }
  std::fflush(stdout);
  if (totals.count(BulkOutcome::desync) != 0) return exit_check_failed;
  if (totals.count(BulkOutcome::invalid) != 0) return exit_usage;
  return exit_ok;
}

}  // namespace detsim::cli
