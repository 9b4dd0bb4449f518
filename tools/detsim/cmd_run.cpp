// detsim scenarios and detsim run: list the scenarios; run one headless, optionally recording it.
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include <detsim/core/hash.hpp>
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

Expected<std::vector<Injection>> parse_injections(const std::vector<std::string>& specs) {
  std::vector<Injection> out;
  for (const std::string& spec : specs) {
    auto parsed = parse_injection(spec);
    if (!parsed) return parsed.status();
    out.push_back(std::move(parsed).value());
  }
  return out;
}

std::string describe(const Scenario& scenario) {
  const ScenarioParams& p = scenario.params();
  std::string out = std::string(scenario.info().name) + " (seed " + std::to_string(p.seed);
  if (scenario.info().max_players != 0) out += ", " + std::to_string(p.players) + " players";
  if (scenario.info().default_count != 0)
    out += ", " + std::to_string(p.count) + " " + std::string(scenario.info().count_unit);
  return out + ")";
}

// ---- The session fingerprint (netplay, demo) -------------------------------------------------

namespace {

void put_u64(std::vector<std::uint8_t>& out, std::uint64_t v) {
  for (int i = 0; i < 8; ++i)
    out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}

void put_text(std::vector<std::uint8_t>& out, std::string_view text) {
  put_u64(out, text.size());
  out.insert(out.end(), text.begin(), text.end());
}

}  // namespace

std::uint64_t session_fingerprint(const Scenario& scenario, net::SessionMode mode,
                                  std::uint64_t frames) {
  std::vector<std::uint8_t> match;
  put_text(match, "detsim netplay 2");
  put_u64(match, static_cast<std::uint64_t>(mode));
  put_u64(match, frames);
  return replay::session_fingerprint(replay::fingerprint_of(scenario), match);
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
  auto injections = parse_injections(args.injections);
  if (!injections) return usage_error("run", injections.message());
  for (const Injection& i : injections.value())
    if (i.frame > frames)
      return usage_error("run", "--inject " + i.text() + ": frame " + std::to_string(i.frame) +
                                    " is beyond the run's " + std::to_string(frames) + " frames");
  Progress progress("run " + args.scene.scenario);
  replay::RecordOptions options;
  options.frames = static_cast<std::uint32_t>(frames);
  options.keyframe_interval = args.keyframe_interval;
  options.progress = [&progress](std::uint64_t done, std::uint64_t total) {
    progress.update(done, total);
    return true;
  };
  if (!injections->empty()) {
    options.after_step = [&injections](Scenario& s) {
      return apply_injections(s.world(), injections.value());
    };
  }
  const auto start = std::chrono::steady_clock::now();
  auto result = replay::record(scenario, args.record, options);
  const double seconds = seconds_since(start);
  progress.done();
  if (!result) return usage_error("run", result.message());
  if (!args.save_state.empty() && !write_file(args.save_state, scenario.world().save()))
    return usage_error("run", "cannot write the state to " + args.save_state);
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
  if (!args.save_state.empty()) std::printf("state written to %s\n", args.save_state.c_str());
  return exit_ok;
}

}  // namespace detsim::cli
