// Character controllers (issue 20, "Performance"): time per step of the `characters` scene with 8
// and with 100 characters, and the cost of one character's move (the difference over the 92 more
// characters). There is no peer character controller in the process: Bullet's
// btKinematicCharacterController is float and moves one character against Bullet's own world,
// a different scene; the figures are reported as they are.
//
// Method: the scene is built untimed and run 60 steps untimed (the characters land and start
// walking); each step after that is timed with the thread's CPU clock (manual time). The scene's
// inputs are the scenario's own (drawn from the world's RNG each second), so both sizes run the
// same yard. Counters: ms_per_step, us_per_character (the step's time over its characters, an
// upper bound of one move that includes the yard's own bodies), characters.
// Bench code is not simulation code: double is used freely here.
#include <benchmark/benchmark.h>

#include <time.h>  // clock_gettime, CLOCK_THREAD_CPUTIME_ID (POSIX)

#include <cstdint>

#include <detsim/detsim.hpp>

namespace {

double thread_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + double(t.tv_nsec) * 1e-9;
}

void BM_CharactersYard(benchmark::State& state) {
  const auto count = static_cast<std::uint32_t>(state.range(0));
  detsim::Scenario scene = detsim::Scenario::create("characters", {1, 0, count}).value();
  for (int i = 0; i < 60; ++i)
    scene.step();
  double total = 0;
  int steps = 0;
  for (auto _ : state) {
    const double t0 = thread_seconds();
    scene.step();
    const double t1 = thread_seconds();
    state.SetIterationTime(t1 - t0);
    total += t1 - t0;
    ++steps;
  }
  state.counters["ms_per_step"] = 1e3 * total / steps;
  state.counters["us_per_character"] = 1e6 * total / steps / count;
  state.counters["characters"] = count;
}
BENCHMARK(BM_CharactersYard)
    ->Arg(8)
    ->Arg(100)
    ->Iterations(600)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
