// detsim scenarios, detsim run, and the main job (detsim demo): run a scenario, record, verify.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <system_error>

#include <detsim/replay.hpp>

#include "commands.hpp"
#include "output.hpp"
#include "scenario_args.hpp"

namespace detsim::cli {

// ---- Scenario arguments -------------------------------------------------------------------------

std::string scenario_names() {
  std::string out;
  for (const ScenarioInfo& info : scenario_list()) {
    if (!out.empty()) out += ", ";
    out += info.name;
  }
  return out;
}

Expected<ChosenScenario> choose_scenario(const ScenarioArgs& args) {
  const ScenarioInfo* info = find_scenario(args.scenario);
  if (info == nullptr)
    return Status::error("unknown scenario '" + args.scenario + "'; known: " + scenario_names() +
                         " (detsim scenarios describes them)");
  if (args.frames > max_frames)
    return Status::error("--frames " + std::to_string(args.frames) + " is more than the limit of " +
                         std::to_string(max_frames));
  auto scenario = Scenario::create(args.scenario, {args.seed, args.players, args.count});
  if (!scenario) return scenario.status();
  const std::uint64_t frames = args.frames != 0 ? args.frames : info->default_frames;
  return ChosenScenario{std::move(scenario.value()), frames};
}

std::string describe(const Scenario& scenario) {
  const ScenarioParams& p = scenario.params();
  std::string out = std::string(scenario.info().name) + " (seed " + std::to_string(p.seed);
  if (scenario.info().max_players != 0) out += ", " + std::to_string(p.players) + " players";
  if (scenario.info().default_count != 0)
    out += ", " + std::to_string(p.count) + " " + std::string(scenario.info().count_unit);
  return out + ")";
}

// ---- detsim scenarios ---------------------------------------------------------------------------

int scenarios_command(const ScenariosArgs& args) {
  if (args.json) {
    std::vector<std::string> items;
    for (const ScenarioInfo& s : scenario_list()) {
      Json j;
      j.str("name", s.name).str("summary", s.summary).num("default_frames", s.default_frames);
      if (s.max_players != 0) {
        j.num("min_players", s.min_players)
            .num("max_players", s.max_players)
            .num("default_players", s.default_players);
      }
      if (s.default_count != 0)
        j.num("default_count", s.default_count)
            .num("max_count", s.max_count)
            .str("count_unit", s.count_unit);
      j.boolean("uses_seed", s.uses_seed);
      items.push_back(j.text());
    }
    Json().raw("scenarios", Json::array(items)).print();
    return exit_ok;
  }
  for (const ScenarioInfo& s : scenario_list()) {
    std::printf("%-13s %.*s\n", std::string(s.name).c_str(), static_cast<int>(s.summary.size()),
                s.summary.data());
    std::string params = "default frames " + std::to_string(s.default_frames);
    if (s.max_players != 0)
      params += "; --players " + std::to_string(s.min_players) + ".." +
                std::to_string(s.max_players) + " (default " + std::to_string(s.default_players) +
                ")";
    if (s.default_count != 0)
      params += "; --count 1.." + std::to_string(s.max_count) + " " + std::string(s.count_unit) +
                " (default " + std::to_string(s.default_count) + ")";
    params += s.uses_seed ? "; --seed changes the run" : "; --seed only seeds the unused RNG";
    std::printf("%-13s %s\n", "", params.c_str());
  }
  return exit_ok;
}

// ---- detsim run ---------------------------------------------------------------------------------

int run_command(const RunArgs& args) {
  auto chosen = choose_scenario(args.scene);
  if (!chosen) return usage_error("run", chosen.message());
  Scenario& scenario = chosen.value().scenario;
  const std::uint64_t frames = chosen.value().frames;
  Progress progress("run " + args.scene.scenario);
  replay::RecordOptions options;
  options.frames = static_cast<std::uint32_t>(frames);
  options.keyframe_interval = args.keyframe_interval;
  options.progress = [&progress](std::uint64_t done, std::uint64_t total) {
    progress.update(done, total);
    return true;
  };
  const auto start = std::chrono::steady_clock::now();
  auto result = replay::record(scenario, args.record, options);
  const double seconds = seconds_since(start);
  progress.done();
  if (!result) return usage_error("run", result.message());
  if (args.json) {
    Json j;
    j.str("scenario", scenario.info().name)
        .num("frames", result->frames)
        .hash("final_hash", result->final_hash)
        .hash("chain_hash", result->chain_hash)
        .num("seed", scenario.params().seed)
        .num("players", scenario.params().players)
        .num("count", scenario.params().count);
    if (args.record.empty()) {
      j.null("record");
    } else {
      j.str("record", args.record);
    }
    j.real("seconds", seconds).print();
    return exit_ok;
  }
  std::printf("%s: %llu frames, final hash %s\n", describe(scenario).c_str(),
              static_cast<unsigned long long>(result->frames), hex(result->final_hash).c_str());
  if (!args.record.empty()) std::printf("recorded %s\n", args.record.c_str());
  return exit_ok;
}

// ---- detsim demo (the main job) -----------------------------------------------------------------

int demo_command(const DemoArgs& args) {
  auto chosen = choose_scenario(args.scene);
  if (!chosen) return usage_error("demo", chosen.message());
  Scenario& scenario = chosen.value().scenario;
  std::string path = args.record;
  if (path.empty()) {
    std::error_code ec;
    path = (std::filesystem::temp_directory_path(ec) / "detsim-demo.dsr").string();
  }
  replay::RecordOptions options;
  options.frames = static_cast<std::uint32_t>(chosen.value().frames);
  Progress run_progress("run");
  options.progress = [&run_progress](std::uint64_t done, std::uint64_t total) {
    run_progress.update(done, total);
    return true;
  };
  auto start = std::chrono::steady_clock::now();
  auto recorded = replay::record(scenario, path, options);
  const double run_seconds = seconds_since(start);
  run_progress.done();
  if (!recorded) return usage_error("demo", recorded.message());

  auto reader = replay::ReplayReader::open(path);
  if (!reader) return usage_error("demo", reader.message());
  Progress verify_progress("verify");
  start = std::chrono::steady_clock::now();
  auto verified = replay::verify(reader.value(), [&](std::uint64_t done, std::uint64_t total) {
    verify_progress.update(done, total);
    return true;
  });
  const double verify_seconds = seconds_since(start);
  verify_progress.done();
  if (!verified) return usage_error("demo", verified.message());
  const bool ok = verified->ok;
  const double fps =
      verify_seconds > 0 ? static_cast<double>(verified->frames) / verify_seconds : 0;
  const double realtime = fps * scenario.world().def().dt.to_double();
  if (args.json) {
    Json()
        .str("scenario", scenario.info().name)
        .num("frames", recorded->frames)
        .hash("final_hash", recorded->final_hash)
        .str("replay", path)
        .num("replay_bytes", reader->file_size())
        .boolean("verified", ok)
        .frame("first_mismatch", verified->first_mismatch)
        .real("run_seconds", run_seconds)
        .real("verify_seconds", verify_seconds)
        .real("verify_frames_per_second", fps)
        .print();
    return ok ? exit_ok : exit_check_failed;
  }
  std::printf("scenario     %s\n", describe(scenario).c_str());
  std::printf("frames       %llu (%.2f s of simulated time)\n",
              static_cast<unsigned long long>(recorded->frames),
              static_cast<double>(recorded->frames) * scenario.world().def().dt.to_double());
  std::printf("final hash   %s\n", hex(recorded->final_hash).c_str());
  std::printf("replay       %s (%llu bytes, %zu keyframes)\n", path.c_str(),
              static_cast<unsigned long long>(reader->file_size()), reader->keyframes().size());
  if (ok) {
    std::printf("verify       ok: every frame's hash reproduced\n");
  } else {
    std::printf("verify       MISMATCH at frame %llu\n",
                static_cast<unsigned long long>(verified->first_mismatch.value_or(0)));
  }
  std::printf("time         run %.2f s, verify %.2f s (%.0f frames/s, %.0fx real time)\n",
              run_seconds, verify_seconds, fps, realtime);
  return ok ? exit_ok : exit_check_failed;
}

}  // namespace detsim::cli
