// detsim synctest: GGPO's sync test on a scenario. Every frame f >= K, restore the state saved at
// frame f - K, re-simulate the K frames with the same inputs, and compare each frame's hashes with
// those of the first pass; the run then goes on from the re-simulated state. Any state that save()
// misses, or any hidden dependence on history, shows up as a mismatch at a named frame.
#include <chrono>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "output.hpp"
#include "scenario_args.hpp"

namespace detsim::cli {

namespace {

struct SyncResult {
  std::uint64_t frames = 0;
  std::uint64_t resimulated = 0;
  std::optional<std::uint64_t> first_mismatch;
  StateHashes expected;  ///< first pass, at first_mismatch
  StateHashes actual;    ///< re-simulation, at first_mismatch
  std::uint64_t final_hash = 0;
  std::string error;
};

void inputs_at(const Scenario& s, std::uint64_t frame, std::vector<PlayerInput>& out) {
  out.resize(s.params().players);
  for (std::uint32_t p = 0; p < out.size(); ++p)
    out[p] = scripted_input(s.params().seed, frame, p);
}

SyncResult run_synctest(Scenario& s, std::uint64_t frames, std::uint32_t distance,
                        Progress& progress) {
  SyncResult r;
  // Saved states of the last distance + 1 frames, and every frame's first-pass hashes.
  std::vector<std::vector<std::uint8_t>> saved(distance + 1);
  std::vector<StateHashes> first_pass(distance + 1);
  std::vector<PlayerInput> inputs;
  // The ring slot of frame f (distance + 1 slots; the remainder fits size_t on every target).
  const auto slot_of = [&](std::uint64_t f) {
    return static_cast<std::size_t>(f % (std::uint64_t{distance} + 1));
  };
  saved[0] = s.world().save();
  first_pass[0] = s.world().hashes();
  for (std::uint64_t f = 1; f <= frames; ++f) {
    inputs_at(s, f, inputs);
    s.step(inputs);
    const std::size_t slot = slot_of(f);
    first_pass[slot] = s.world().hashes();
    if (f >= distance && distance > 0) {
      const Status restored = s.world().restore(saved[slot_of(f - distance)]);
      if (!restored) {
        r.error = "frame " + std::to_string(f) + ": restoring frame " +
                  std::to_string(f - distance) + " failed: " + restored.message();
        return r;
      }
      for (std::uint64_t g = f - distance + 1; g <= f; ++g) {
        inputs_at(s, g, inputs);
        s.step(inputs);
        ++r.resimulated;
        const StateHashes again = s.world().hashes();
        const StateHashes& want = first_pass[slot_of(g)];
        if (again != want) {
          r.frames = f;
          r.first_mismatch = g;
          r.expected = want;
          r.actual = again;
          return r;
        }
      }
    }
    saved[slot] = s.world().save();
    r.frames = f;
    r.final_hash = first_pass[slot].total;
    progress.update(f, frames);
  }
  return r;
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
  const bool ok = !r.first_mismatch.has_value();
  if (args.json) {
    Json j;
    j.boolean("ok", ok)
        .str("scenario", scenario.info().name)
        .num("frames", r.frames)
        .num("check_distance", args.check_distance)
        .num("resimulated_frames", r.resimulated)
        .frame("first_mismatch", r.first_mismatch);
    if (ok) {
      j.hash("final_hash", r.final_hash);
    } else {
      j.hash("expected_hash", r.expected.total).hash("actual_hash", r.actual.total);
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
              describe(scenario).c_str(), static_cast<unsigned long long>(*r.first_mismatch),
              static_cast<unsigned long long>(r.frames),
              static_cast<unsigned long long>(r.frames - args.check_distance));
  std::printf("  first pass %s, re-simulation %s\n", hex(r.expected.total).c_str(),
              hex(r.actual.total).c_str());
  return exit_check_failed;
}

}  // namespace detsim::cli
