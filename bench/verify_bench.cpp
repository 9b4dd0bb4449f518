// verify_bench: what one core does for bulk replay verification (`detsim verify --manifest`,
// docs/SCALE.md "Throughput"): a recorded 2-player arena match of 3600 frames (a minute at 60 Hz)
// verified frame by frame, beside the same frames only simulated (the inputs decoded beforehand,
// no state hashed) and only read (the frames decoded, nothing simulated). The difference between
// the first two is the time verification spends outside the simulation: reading and decoding the
// file, encoding and hashing every frame's state, comparing.
//
// Counters: realtime_x (seconds of game verified per second), frames_per_second; run by hand:
//   build/bench/bench/verify_bench --benchmark_repetitions=3
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <unistd.h>

#include <detsim/replay.hpp>

namespace {

using namespace detsim;

constexpr std::uint32_t kFrames = 3600;

struct Recorded {
  std::vector<std::uint8_t> bytes;
  std::vector<std::vector<std::uint8_t>> inputs;  ///< each frame's, decoded from the file
  double dt = 1.0 / 60.0;
};

const Recorded& recorded() {
  static const Recorded r = [] {
    Recorded out;
    ScenarioParams params;
    params.players = 2;
    auto scenario = Scenario::create("arena", params);
    if (!scenario) std::abort();
    const std::string path = (std::filesystem::temp_directory_path() /
                              ("detsim_verify_bench_" + std::to_string(::getpid()) + ".replay"))
                                 .string();
    replay::RecordOptions options;
    options.frames = kFrames;
    if (!replay::record(scenario.value(), path, options)) std::abort();
    {
      std::ifstream in(path, std::ios::binary);
      out.bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    std::filesystem::remove(path);
    auto reader = replay::ReplayReader::from_bytes(out.bytes, "arena.replay");
    if (!reader) std::abort();
    out.dt = reader->fingerprint().dt.to_double();
    if (!reader->for_each_frame(1, reader->frame_count(), [&](const replay::FrameRecord& f) {
          out.inputs.push_back(f.inputs);
          return true;
        }))
      std::abort();
    return out;
  }();
  return r;
}

void count(benchmark::State& state, std::uint64_t frames_per_iteration) {
  const auto frames = static_cast<double>(state.iterations() * frames_per_iteration);
  state.counters["frames_per_second"] = benchmark::Counter(frames, benchmark::Counter::kIsRate);
  state.counters["realtime_x"] =
      benchmark::Counter(frames * recorded().dt, benchmark::Counter::kIsRate);
}

/// What `detsim verify` does per replay: open the bytes, re-simulate, hash and compare each frame.
void BM_VerifyReplay(benchmark::State& state) {
  const Recorded& r = recorded();
  for (auto _ : state) {
    auto reader = replay::ReplayReader::from_bytes(r.bytes, "arena.replay");
    auto result = replay::verify(reader.value());
    if (!result || !result->ok) state.SkipWithError("the replay did not verify");
    benchmark::DoNotOptimize(result->final_hash);
  }
  count(state, kFrames);
}
BENCHMARK(BM_VerifyReplay)->Unit(benchmark::kMillisecond);

/// The simulation alone: the same scenario and frames, the inputs already decoded, no hashing.
void BM_SimulateOnly(benchmark::State& state) {
  const Recorded& r = recorded();
  auto reader = replay::ReplayReader::from_bytes(r.bytes, "arena.replay");
  for (auto _ : state) {
    auto scenario = replay::scenario_of(reader.value());
    for (const std::vector<std::uint8_t>& inputs : r.inputs)
      scenario->step_encoded(inputs);
    benchmark::DoNotOptimize(scenario->world().body_count());
  }
  count(state, kFrames);
}
BENCHMARK(BM_SimulateOnly)->Unit(benchmark::kMillisecond);

/// Reading alone: every frame record decoded (inputs and recorded hashes), nothing simulated.
void BM_ReadFrames(benchmark::State& state) {
  const Recorded& r = recorded();
  for (auto _ : state) {
    auto reader = replay::ReplayReader::from_bytes(r.bytes, "arena.replay");
    std::uint64_t n = 0;
    if (!reader->for_each_frame(1, reader->frame_count(), [&](const replay::FrameRecord& f) {
          n += f.inputs.size();
          return true;
        }))
      state.SkipWithError("unreadable");
    benchmark::DoNotOptimize(n);
  }
  count(state, kFrames);
}
BENCHMARK(BM_ReadFrames)->Unit(benchmark::kMillisecond);

/// Encoding and hashing alone: one state saved and hashed as verify does each frame (the
/// arena's state at its last frame).
void BM_HashState(benchmark::State& state) {
  const Recorded& r = recorded();
  auto reader = replay::ReplayReader::from_bytes(r.bytes, "arena.replay");
  auto scenario = replay::scenario_of(reader.value());
  for (const std::vector<std::uint8_t>& inputs : r.inputs)
    scenario->step_encoded(inputs);
  std::vector<std::uint8_t> buffer;
  for (auto _ : state)
    benchmark::DoNotOptimize(scenario->world().save(buffer).total);
  count(state, 1);
}
BENCHMARK(BM_HashState)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
