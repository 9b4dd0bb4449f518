// Simulation benchmarks: the shared pile scenes beside Bullet 3 in the same run, and the costs a
// rollback session pays per frame (save, restore, hash, re-simulation) and what sleeping saves.
//
// Method (docs/BENCHMARKS.md repeats it for readers of the figures):
// - pile_boxes / pile_spheres: Scenario::create builds the scene (docs/SCENARIOS.md); the Bullet
//   peer (bullet_peer.cpp) builds the same lattice with the set-up of the project's Bullet anchor
//   (10 solver iterations, 60 Hz). One iteration is the whole run from the drop (600 steps by
//   default): building the scene is untimed, every step is timed. Each step's thread CPU time is
//   also read, so one run gives the mean over the first and the last `window` steps as well, and
//   each step's best time over the repetitions (a load-filtered cross-check of the whole run).
//   "<scene>/bullet_matched" runs the peer with friction sqrt(0.5) per body, so that Bullet's
//   product combine gives its contacts detsim's 0.5 (the anchor's 0.5 gives 0.25): the same
//   physical scene, as a cross-check of the anchor's comparison.
// - state/*: the box pile after `state_frame` steps (taken once, by running the scene): save,
//   restore (full validation included) and the state hash, each per call; "rollback8" restores
//   that snapshot and steps 8 frames, and splits each iteration into its restore and its steps
//   (one step = an eighth of the steps), keeping the best iteration of each.
// - sleep/step_sleeping: the box pile run on until every dynamic body sleeps (at most
//   `sleep_max_frames` frames; the counters say whether it got there), then one step per call.
// - Every figure is CPU time of the benchmark thread; the report also shows wall time.
// Bench code is not simulation code: double is used freely here.

#include <benchmark/benchmark.h>

#include <time.h>  // clock_gettime, CLOCK_THREAD_CPUTIME_ID (POSIX)

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <bench_config.hpp>
#include <detsim/detsim.hpp>

#if DETSIM_BENCH_HAVE_BULLET
#include "bullet_peer.hpp"
#endif

namespace {

// ---- Options: the scene's size and the windows, settable for quick runs ------------------------

struct Options {
  std::uint32_t count = 1000;             ///< bodies in a pile
  std::uint32_t steps = 600;              ///< steps of a whole run, from the drop
  std::uint32_t window = 100;             ///< steps in the "first" and "last" windows of a run
  std::uint32_t state_frame = 120;        ///< frame of the snapshot the state benchmarks use
  std::uint32_t sleep_max_frames = 1800;  ///< give up waiting for a sleeping pile here
};

Options options;

constexpr std::uint32_t kRollbackFrames = 8;
constexpr int kCheapRepetitions = 10;    // save, restore, hash, a sleeping step: milliseconds each
constexpr int kRollbackRepetitions = 5;  // a rollback: about a second each

/// Takes "--pile_<name>=<value>" arguments out of argv (Google Benchmark rejects unknown ones).
/// Returns false on a malformed one.
bool parse_options(int& argc, char** argv) {
  struct Flag {
    std::string_view name;
    std::uint32_t* value;
  };
  const Flag flags[] = {{"--pile_count=", &options.count},
                        {"--pile_steps=", &options.steps},
                        {"--pile_window=", &options.window},
                        {"--pile_state_frame=", &options.state_frame},
                        {"--pile_sleep_max_frames=", &options.sleep_max_frames}};
  int kept = 1;
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg(argv[i]);
    bool consumed = false;
    for (const Flag& flag : flags) {
      if (arg.substr(0, flag.name.size()) != flag.name) continue;
      const std::string text(arg.substr(flag.name.size()));
      char* end = nullptr;
      const unsigned long v = std::strtoul(text.c_str(), &end, 10);
      if (text.empty() || *end != '\0' || v == 0 || v > 1'000'000) {
        std::fprintf(stderr, "sim_bench: %s needs a whole number from 1 to 1000000\n", argv[i]);
        return false;
      }
      *flag.value = static_cast<std::uint32_t>(v);
      consumed = true;
    }
    if (!consumed) argv[kept++] = argv[i];
  }
  argc = kept;
  if (options.window > options.steps) options.window = options.steps;
  return true;
}

// ---- Helpers ------------------------------------------------------------------------------------

/// CPU time of the calling thread, seconds: what Google Benchmark's CPU time measures too.
double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

[[noreturn]] void fail(const std::string& what) {
  std::fprintf(stderr, "sim_bench: %s\n", what.c_str());
  std::exit(1);
}

detsim::Scenario make_pile(bool spheres) {
  auto scenario =
      detsim::Scenario::create(spheres ? "pile_spheres" : "pile_boxes", {.count = options.count});
  if (!scenario) fail(scenario.message());
  return std::move(scenario.value());
}

struct PileStats {
  std::uint32_t dynamic = 0;
  std::uint32_t awake = 0;
  double mean_height = 0.0;  ///< m, over the dynamic bodies
};

PileStats pile_stats(const detsim::World& world) {
  PileStats s;
  double height = 0.0;
  for (const detsim::BodyId id : world.body_ids()) {
    const auto body = world.body(id);
    if (!body || body->type != detsim::BodyType::dynamic) continue;
    ++s.dynamic;
    if (body->awake) ++s.awake;
    height += body->position.y.to_double();
  }
  if (s.dynamic != 0) s.mean_height = height / static_cast<double>(s.dynamic);
  return s;
}

void restore_or_fail(detsim::World& world, std::span<const std::uint8_t> bytes) {
  const detsim::Status status = world.restore(bytes);
  if (!status) fail("restore failed: " + status.message());
}

// ---- The two engines behind one shape, for the whole-run benchmark ------------------------------

class DetsimPile {
 public:
  DetsimPile(std::uint32_t, bool spheres) : scenario_(make_pile(spheres)) {}
  void step() { scenario_.step(); }
  [[nodiscard]] double mean_height() const { return pile_stats(scenario_.world()).mean_height; }
  [[nodiscard]] std::uint32_t awake_count() const { return pile_stats(scenario_.world()).awake; }

 private:
  detsim::Scenario scenario_;
};

/// The whole run from the drop: `options.steps` steps, each timed; building is untimed.
template <class Pile>
void whole_run(benchmark::State& state, bool spheres) {
  std::vector<double> step_seconds(options.steps);
  std::optional<Pile> pile;
  for (auto _ : state) {
    state.PauseTiming();
    pile.reset();
    pile.emplace(options.count, spheres);
    state.ResumeTiming();
    double before = thread_cpu_seconds();
    for (std::uint32_t i = 0; i < options.steps; ++i) {
      pile->step();
      const double after = thread_cpu_seconds();
      step_seconds[i] = after - before;
      before = after;
    }
  }
  const auto mean_ms = [&](std::size_t first, std::size_t n) {
    double sum = 0.0;
    for (std::size_t i = first; i < first + n; ++i)
      sum += step_seconds[i];
    return n == 0 ? 0.0 : 1e3 * sum / static_cast<double>(n);
  };
  const std::size_t steps = options.steps;
  const std::size_t window = options.window;
  // Each step's best time over the repetitions run so far. Both engines are deterministic, so
  // step i does the same work in every repetition, and its fastest time is the one least
  // disturbed by the machine's other load; their mean is a load-filtered ms/step for the run.
  static std::vector<double> best_step_seconds[2];
  std::vector<double>& best = best_step_seconds[spheres ? 1 : 0];
  if (best.size() != steps) best.assign(steps, 1e300);
  for (std::size_t i = 0; i < steps; ++i) {
    if (step_seconds[i] < best[i]) best[i] = step_seconds[i];
  }
  double best_sum = 0.0;
  for (const double t : best)
    best_sum += t;
  state.counters["ms_per_step_best_steps"] = 1e3 * best_sum / static_cast<double>(steps);
  state.counters["bodies"] = options.count;
  state.counters["steps_per_iteration"] = static_cast<double>(steps);
  state.counters["ms_per_step_all"] = mean_ms(0, steps);
  state.counters["ms_per_step_first"] = mean_ms(0, window);
  state.counters["ms_per_step_last"] = mean_ms(steps - window, window);
  state.counters["window"] = static_cast<double>(window);
  state.counters["mean_height"] = pile->mean_height();
  state.counters["awake_at_end"] = pile->awake_count();
}

// ---- Snapshots shared by the state and sleep benchmarks, taken once -----------------------------

struct Snapshot {
  std::vector<std::uint8_t> bytes;
  std::uint64_t frame = 0;
  PileStats stats;
};

/// The box pile after options.state_frame steps.
const Snapshot& snapshot_at_state_frame() {
  static const Snapshot snapshot = [] {
    detsim::Scenario pile = make_pile(false);
    for (std::uint32_t i = 0; i < options.state_frame; ++i)
      pile.step();
    return Snapshot{pile.world().save(), pile.world().frame(), pile_stats(pile.world())};
  }();
  return snapshot;
}

/// The box pile once every dynamic body sleeps, or at options.sleep_max_frames if it never does.
const Snapshot& snapshot_settled() {
  static const Snapshot snapshot = [] {
    detsim::Scenario pile = make_pile(false);
    restore_or_fail(pile.world(), snapshot_at_state_frame().bytes);
    PileStats stats = pile_stats(pile.world());
    while (stats.awake != 0 && pile.world().frame() < options.sleep_max_frames) {
      pile.step();
      stats = pile_stats(pile.world());
    }
    return Snapshot{pile.world().save(), pile.world().frame(), stats};
  }();
  return snapshot;
}

detsim::World world_from(const Snapshot& snapshot) {
  detsim::World world;
  restore_or_fail(world, snapshot.bytes);
  return world;
}

void snapshot_counters(benchmark::State& state, const Snapshot& snapshot) {
  state.counters["frame"] = static_cast<double>(snapshot.frame);
  state.counters["bodies"] = snapshot.stats.dynamic;
  state.counters["awake"] = snapshot.stats.awake;
  state.counters["snapshot_bytes"] = static_cast<double>(snapshot.bytes.size());
  // Every byte of the snapshot (globals, the static ground, the contact cache) over the dynamic
  // bodies: the figure a rollback buffer pays per body.
  state.counters["bytes_per_body"] = snapshot.stats.dynamic == 0
                                         ? 0.0
                                         : static_cast<double>(snapshot.bytes.size()) /
                                               static_cast<double>(snapshot.stats.dynamic);
}

// ---- State benchmarks ---------------------------------------------------------------------------

void state_save(benchmark::State& state) {
  const Snapshot& snapshot = snapshot_at_state_frame();
  const detsim::World world = world_from(snapshot);
  for (auto _ : state) {
    std::vector<std::uint8_t> bytes = world.save();
    benchmark::DoNotOptimize(bytes.data());
    benchmark::ClobberMemory();
  }
  snapshot_counters(state, snapshot);
}

void state_restore(benchmark::State& state) {
  const Snapshot& snapshot = snapshot_at_state_frame();
  detsim::World world = world_from(snapshot);
  for (auto _ : state) {
    const detsim::Status status = world.restore(snapshot.bytes);
    benchmark::DoNotOptimize(status);
    benchmark::ClobberMemory();
  }
  snapshot_counters(state, snapshot);
}

void state_hash(benchmark::State& state) {
  const Snapshot& snapshot = snapshot_at_state_frame();
  const detsim::World world = world_from(snapshot);
  for (auto _ : state) {
    const detsim::StateHashes hashes = world.hashes();
    benchmark::DoNotOptimize(hashes);
  }
  snapshot_counters(state, snapshot);
}

/// An 8-frame rollback: restore the snapshot, then kRollbackFrames steps, all timed. The thread's
/// CPU clock also splits each iteration into its restore and its steps, so the rollback's ratio to
/// one step comes from figures taken moments apart (on a shared machine, two benchmarks run at
/// different moments can differ by more than the restore costs). The counters keep the best
/// iteration of each kind: on this machine single steps sometimes take tens of times their usual
/// CPU time (the virtual CPU is descheduled), which the iteration mean would include.
void state_rollback(benchmark::State& state) {
  const Snapshot& snapshot = snapshot_at_state_frame();
  detsim::World world = world_from(snapshot);
  double best_restore = 0.0;
  double best_steps = 0.0;
  double best_total = 0.0;
  double best_ratio = 0.0;
  bool first = true;
  for (auto _ : state) {
    const double t0 = thread_cpu_seconds();
    restore_or_fail(world, snapshot.bytes);
    const double t1 = thread_cpu_seconds();
    for (std::uint32_t i = 0; i < kRollbackFrames; ++i)
      world.step();
    const double t2 = thread_cpu_seconds();
    const double restore = t1 - t0;
    const double steps = t2 - t1;
    const double ratio = steps > 0.0 ? (restore + steps) / (steps / kRollbackFrames) : 0.0;
    if (first || restore < best_restore) best_restore = restore;
    if (first || steps < best_steps) best_steps = steps;
    if (first || restore + steps < best_total) best_total = restore + steps;
    if (first || ratio < best_ratio) best_ratio = ratio;
    first = false;
  }
  snapshot_counters(state, snapshot);
  state.counters["steps_per_iteration"] = kRollbackFrames;
  state.counters["restore_ms"] = 1e3 * best_restore;
  state.counters["rollback_ms"] = 1e3 * best_total;
  state.counters["step_ms"] = 1e3 * best_steps / kRollbackFrames;
  state.counters["rollback_ratio"] = best_ratio;
}

// ---- Sleeping -----------------------------------------------------------------------------------

void sleep_step(benchmark::State& state) {
  const Snapshot& snapshot = snapshot_settled();
  detsim::World world = world_from(snapshot);
  for (auto _ : state)
    world.step();
  snapshot_counters(state, snapshot);
  state.counters["steps_per_iteration"] = 1;
  state.counters["all_asleep"] = snapshot.stats.awake == 0 ? 1 : 0;
  state.counters["awake_after"] = pile_stats(world).awake;
  state.counters["sleep_max_frames"] = options.sleep_max_frames;
}

// ---- Registration -------------------------------------------------------------------------------

void register_benchmarks() {
  for (const bool spheres : {false, true}) {
    const std::string scene = spheres ? "pile_spheres" : "pile_boxes";
    benchmark::RegisterBenchmark(
        (scene + "/detsim").c_str(),
        [spheres](benchmark::State& s) { whole_run<DetsimPile>(s, spheres); })
        ->Iterations(1)
        ->Unit(benchmark::kMillisecond);
#if DETSIM_BENCH_HAVE_BULLET
    benchmark::RegisterBenchmark(
        (scene + "/bullet").c_str(),
        [spheres](benchmark::State& s) { whole_run<detsim_bench::BulletPile>(s, spheres); })
        ->Iterations(1)
        ->Unit(benchmark::kMillisecond);
    // The cross-check on the same physical scene: Bullet's contacts get detsim's friction.
    benchmark::RegisterBenchmark(
        (scene + "/bullet_matched").c_str(),
        [spheres](benchmark::State& s) { whole_run<detsim_bench::BulletPileMatched>(s, spheres); })
        ->Iterations(1)
        ->Unit(benchmark::kMillisecond);
#endif
  }
  // The cheap benchmarks get more, shorter repetitions than the whole runs: their minimum then
  // comes from a quiet moment of the shared machine more often.
  const auto cheap = [](benchmark::internal::Benchmark* b) {
    b->Repetitions(kCheapRepetitions)->MinTime(0.1)->Unit(benchmark::kMicrosecond);
  };
  cheap(benchmark::RegisterBenchmark("state/save", state_save));
  cheap(benchmark::RegisterBenchmark("state/restore", state_restore));
  cheap(benchmark::RegisterBenchmark("state/hash", state_hash));
  cheap(benchmark::RegisterBenchmark("sleep/step_sleeping", sleep_step));
  benchmark::RegisterBenchmark("state/rollback8", state_rollback)
      ->Repetitions(kRollbackRepetitions)
      ->Unit(benchmark::kMillisecond);
}

}  // namespace

int main(int argc, char** argv) {
  if (!parse_options(argc, argv)) return 2;
  register_benchmarks();
  const detsim::WorldDef def;
  benchmark::AddCustomContext("detsim_compiler", DETSIM_BENCH_COMPILER);
  benchmark::AddCustomContext("detsim_cxx_flags", DETSIM_BENCH_CXX_FLAGS);
  benchmark::AddCustomContext("detsim_build_type", DETSIM_BENCH_BUILD_TYPE);
  benchmark::AddCustomContext("detsim_substeps", std::to_string(def.substeps));
  benchmark::AddCustomContext("detsim_iterations", std::to_string(def.iterations));
  benchmark::AddCustomContext("pile_count", std::to_string(options.count));
  benchmark::AddCustomContext("pile_steps", std::to_string(options.steps));
  benchmark::AddCustomContext("pile_window", std::to_string(options.window));
  benchmark::AddCustomContext("pile_state_frame", std::to_string(options.state_frame));
  benchmark::AddCustomContext("pile_sleep_max_frames", std::to_string(options.sleep_max_frames));
  benchmark::AddCustomContext("rollback_frames", std::to_string(kRollbackFrames));
#if DETSIM_BENCH_HAVE_BULLET
  benchmark::AddCustomContext("bullet_version",
                              std::to_string(detsim_bench::BulletPile::version()));
#else
  benchmark::AddCustomContext("bullet_version", "none (not found at configure time)");
#endif
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
