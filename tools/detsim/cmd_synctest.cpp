// detsim synctest: GGPO's sync test on a scenario, run by net::SyncTestSession. Every frame f >= K,
// the state of frame f - K is loaded and the K frames re-simulated with the same inputs, and each
// frame's hash compared with the first pass; the run then goes on from the re-simulated state. Any
// state that save() misses, or any hidden dependence on history, shows up as a mismatch at a named
// frame, and both states are kept for a diff.
#include <chrono>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include <detsim/net/synctest.hpp>
#include <detsim/scenario_net/scenario_game.hpp>
#include <detsim/sim/state_diff.hpp>

#include "commands.hpp"
#include "output.hpp"
#include "scenario_args.hpp"

namespace detsim::cli {

namespace {

struct SyncResult {
  std::uint64_t frames = 0;
  std::uint64_t resimulated = 0;
  std::optional<net::SyncTestMismatch> mismatch;
  std::uint64_t final_hash = 0;
  std::string error;
};

SyncResult run_synctest(Scenario& s, std::uint64_t frames, std::uint32_t distance,
                        Progress& progress) {
  SyncResult r;
  net::ScenarioGame game(s);
  const std::uint32_t players = std::max<std::uint32_t>(s.params().players, 1);
  auto created =
      net::SyncTestSession::create(net::SyncTestConfig{players, game.input_size(), distance}, game);
  if (!created) {
    r.error = created.message();
    return r;
  }
  net::SyncTestSession session = std::move(created).value();
  const std::size_t size = game.input_size();
  std::vector<std::uint8_t> inputs(std::size_t{players} * size);
  for (std::uint64_t f = 1; f <= frames; ++f) {
    // The step to state f takes the scripted inputs of frame f (as `detsim run` does).
    for (std::uint32_t p = 0; p < players; ++p)
      s.scripted(s.params().seed, f, p, std::span<std::uint8_t>(inputs).subspan(p * size, size));
    auto ok = session.advance_frame(inputs);
    if (!ok) {
      r.error = ok.message();
      return r;
    }
    r.frames = f;
    r.resimulated = session.resimulated_frames();
    if (!ok.value()) {
      r.mismatch = *session.mismatch();
      return r;
    }
    r.final_hash = session.current_hash();
    progress.update(f, frames);
  }
  return r;
}

/// Which parts of the state differ between the two states of a mismatch (their part hashes).
// `geometry`: the scenario's world, which holds the geometry the states name.
std::string differing_parts(const World& geometry, const net::SyncTestMismatch& m) {
  auto diff = diff_states(geometry, m.expected_state, m.actual_state, 0);  // hashes, no fields
  if (!diff) return "unknown";
  std::string parts;
  for (const std::string& part : differing_subsystems(diff.value().a, diff.value().b))
    parts += (parts.empty() ? "" : ", ") + part;
  return parts.empty() ? "none" : parts;
}

}  // namespace

int synctest_command(const SynctestArgs& args) {
  if (args.check_distance == 0 || args.check_distance > 600)
    return usage_error("synctest", "--check-distance must be 1 to 600 frames, got " +
                                       std::to_string(args.check_distance));
  auto chosen = choose_scenario(args.scene);
  if (!chosen) return usage_error("synctest", chosen.message());
  Scenario& scenario = chosen.value().scenario;
  Progress progress("synctest " + args.scene.scenario);
  const auto start = std::chrono::steady_clock::now();
  const SyncResult r = run_synctest(scenario, chosen.value().frames, args.check_distance, progress);
  const double seconds = seconds_since(start);
  progress.done();
  if (!r.error.empty()) return usage_error("synctest", r.error);
  const bool ok = !r.mismatch.has_value();
  std::string dumped;
  if (!ok && !args.dump.empty()) {
    const std::string expected = args.dump + ".expected";
    const std::string actual = args.dump + ".actual";
    if (!write_file(expected, r.mismatch->expected_state) ||
        !write_file(actual, r.mismatch->actual_state))
      return usage_error("synctest", "cannot write the states to " + expected + " and " + actual);
    dumped = expected + " and " + actual;
  }
  const std::optional<std::uint64_t> first_mismatch =
      ok ? std::nullopt : std::optional<std::uint64_t>(r.mismatch->frame);
  if (args.json) {
    Json j;
    j.boolean("ok", ok)
        .str("scenario", scenario.info().name)
        .num("frames", r.frames)
        .num("check_distance", args.check_distance)
        .num("resimulated_frames", r.resimulated)
        .frame("first_mismatch", first_mismatch);
    if (ok) {
      j.hash("final_hash", r.final_hash);
    } else {
      j.hash("expected_hash", r.mismatch->expected_hash)
          .hash("actual_hash", r.mismatch->actual_hash)
          .str("differing_parts", differing_parts(scenario.world(), *r.mismatch));
      if (!dumped.empty()) j.str("dumped", dumped);
    }
    j.real("seconds", seconds).print();
    return ok ? exit_ok : exit_check_failed;
  }
  if (ok) {
    std::printf(
        "%s: ok: %llu frames, each re-simulated from %u frames back (%llu re-simulated frames) "
        "with identical hashes; final hash %s\n",
        describe(scenario).c_str(), static_cast<unsigned long long>(r.frames), args.check_distance,
        static_cast<unsigned long long>(r.resimulated), hex(r.final_hash).c_str());
    return exit_ok;
  }
  std::printf("%s: MISMATCH at frame %llu (rolling back from frame %llu to frame %llu)\n",
              describe(scenario).c_str(), static_cast<unsigned long long>(r.mismatch->frame),
              static_cast<unsigned long long>(r.frames),
              static_cast<unsigned long long>(r.frames - args.check_distance));
  std::printf("  first pass %s, re-simulation %s; differing: %s\n",
              hex(r.mismatch->expected_hash).c_str(), hex(r.mismatch->actual_hash).c_str(),
              differing_parts(scenario.world(), *r.mismatch).c_str());
  if (!dumped.empty()) std::printf("  states written to %s\n", dumped.c_str());
  return exit_check_failed;
}

}  // namespace detsim::cli
