// FixedStepDriver: the same states whatever the host's frame rate and jitter, exact step counts
// over long runs, alpha, the frame clamp and the step cap, the before_step and after_step
// callbacks, interpolation (also of a world a session steps), and configuration errors.
//
// Expected step counts and alphas come from the definition, not from the driver's tick unit: after
// T ns of accepted time there have been floor(T / (dt.raw() * 10^9 / 2^32 ns)) steps, computed
// here in the host's 128-bit integers.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <functional>
#include <limits>
#include <ostream>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

#include "support/sim_helpers.hpp"

namespace detsim {

// Found by argument-dependent lookup, so it lives in detsim itself.
void PrintTo(const Transform& t, std::ostream* os) {
  *os << "{position ";
  PrintTo(t.position, os);
  *os << ", orientation ";
  PrintTo(t.orientation, os);
  *os << "}";
}

namespace {

using namespace detsim::literals;

using test::add;
using test::add_ground;
using test::make_world;
using test::near;
using test::u128;

constexpr std::uint64_t ns_per_second = 1'000'000'000;

/// One step of dt in units of 2^-32 ns: dt.raw() 2^-32 s = dt.raw() 10^9 2^-32 ns.
u128 step_length(Fixed dt) {
  return static_cast<u128>(ns_per_second) * static_cast<std::uint64_t>(dt.raw());
}

/// Whole steps of dt in `total_ns` (both are far below 2^64 / 2^32 here, so nothing overflows).
std::uint64_t steps_in(std::uint64_t total_ns, Fixed dt) {
  return static_cast<std::uint64_t>((static_cast<u128>(total_ns) << 32) / step_length(dt));
}

/// The fraction of a step left after `total_ns`, rounded down to a Fixed.
Fixed alpha_after(std::uint64_t total_ns, Fixed dt) {
  const u128 rest = (static_cast<u128>(total_ns) << 32) % step_length(dt);
  return Fixed::from_raw(static_cast<std::int64_t>((rest << 32) / step_length(dt)));
}

/// The time left after `total_ns`, in seconds rounded down to a Fixed.
Fixed accumulated_after(std::uint64_t total_ns, Fixed dt) {
  const u128 rest = (static_cast<u128>(total_ns) << 32) % step_length(dt);  // ns * 2^32
  return Fixed::from_raw(static_cast<std::int64_t>(rest / ns_per_second));
}

FixedStepDriver make_driver(const DriverConfig& config = {}) {
  auto d = FixedStepDriver::create(config);
  EXPECT_TRUE(d.ok()) << d.message();
  return d.ok() ? d.value() : FixedStepDriver();
}

WorldDef def_with_dt(Fixed dt) {
  WorldDef def;
  def.dt = dt;
  return def;
}

// 1/64 s is exactly 15'625'000 ns: steps and half steps land on whole nanoseconds.
constexpr Fixed dt_64 = Fixed::from_raw(Fixed::one_raw / 64);
constexpr std::int64_t step_64_ns = 15'625'000;

// ---- The same states whatever the host -------------------------------------------------------

struct Scene {
  World world;
  std::vector<BodyId> bodies;
};

Scene make_scene() {
  WorldDef def;
  def.seed = 2024;
  Scene s{make_world(def), {}};
  add_ground(s.world);
  const auto box = [](Fixed x, Fixed y, Fixed z) {
    BodyDef d;
    d.shape = Shape::box({0.5_fx, 0.25_fx, 0.4_fx});
    d.position = {x, y, z};
    d.orientation = from_axis_angle({1_fx, 2_fx, 0.5_fx}, 0.7_fx);
    return d;
  };
  const auto sphere = [](Fixed x, Fixed y, Fixed z) {
    BodyDef d;
    d.shape = Shape::sphere(0.5_fx);
    d.position = {x, y, z};
    d.restitution = 0.5_fx;
    return d;
  };
  s.bodies = {add(s.world, box(0_fx, 1_fx, 0_fx)), add(s.world, sphere(0.3_fx, 3_fx, 0.1_fx)),
              add(s.world, box(-0.2_fx, 5_fx, 0.2_fx)), add(s.world, sphere(2_fx, 0.5_fx, 0_fx))};
  return s;
}

/// The game's input for the frame about to be stepped: depends only on the world (its frame and
/// its RNG), as a lockstep game's inputs would.
void apply_inputs(World& w, const std::vector<BodyId>& bodies) {
  if (w.frame() % 17 == 5) {
    const BodyId target = bodies[w.rng().next_u64() % bodies.size()];
    EXPECT_TRUE(w.apply_linear_impulse(target, {1_fx, 4_fx, -0.5_fx}).ok());
  }
  if (w.frame() % 3 == 0) {
    EXPECT_TRUE(w.apply_torque(bodies[0], {0_fx, 3_fx, 0_fx}).ok());
  }
}

/// Index of the first differing element (or of the first missing one), or -1 if equal.
long first_difference(const std::vector<std::uint64_t>& a, const std::vector<std::uint64_t>& b) {
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i)
    if (a[i] != b[i]) return static_cast<long>(i);
  return a.size() == b.size() ? -1 : static_cast<long>(std::min(a.size(), b.size()));
}

TEST(SimDriver, HostFrameRatesAndJitterGiveTheStatesOfSteppingDirectly) {
  const std::uint64_t span_ns = 5 * ns_per_second;
  const Fixed dt = WorldDef{}.dt;
  const std::uint64_t steps = steps_in(span_ns, dt);
  ASSERT_GT(steps, 290U);

  // The reference: the state hash of every frame 0..steps, inputs applied by hand.
  std::vector<std::uint64_t> reference;
  {
    Scene s = make_scene();
    for (std::uint64_t i = 0; i < steps; ++i) {
      apply_inputs(s.world, s.bodies);
      reference.push_back(s.world.hashes().total);
      s.world.step();
    }
    reference.push_back(s.world.hashes().total);
  }

  struct Host {
    std::int64_t hz;
    std::uint64_t seed;
  };
  for (const Host host : {Host{30, 1}, Host{60, 2}, Host{144, 3}}) {
    SCOPED_TRACE(std::to_string(host.hz) + " Hz");
    Scene s = make_scene();
    FixedStepDriver driver = make_driver();
    std::mt19937_64 rng(host.seed);
    const std::int64_t period = static_cast<std::int64_t>(ns_per_second) / host.hz;
    const std::int64_t jitter = period / 4;  // +-25% of the frame
    std::vector<std::uint64_t> hashes;
    std::uint64_t total = 0;
    std::uint64_t taken = 0;
    int idle_frames = 0;
    int multi_step_frames = 0;
    while (total < span_ns) {
      const auto offset =
          static_cast<std::int64_t>(rng() % static_cast<std::uint64_t>(2 * jitter + 1));
      std::int64_t elapsed = period - jitter + offset;
      // The last frame ends exactly at the span, so every host ends at the same step.
      elapsed = std::min<std::int64_t>(elapsed, static_cast<std::int64_t>(span_ns - total));
      const std::uint32_t n = driver.advance(s.world, elapsed, [&](World& w) {
        apply_inputs(w, s.bodies);
        hashes.push_back(w.hashes().total);
      });
      total += static_cast<std::uint64_t>(elapsed);
      taken += n;
      idle_frames += n == 0 ? 1 : 0;
      multi_step_frames += n >= 2 ? 1 : 0;
      ASSERT_EQ(taken, steps_in(total, dt)) << "after " << total << " ns";
      ASSERT_EQ(driver.alpha(), alpha_after(total, dt)) << "after " << total << " ns";
      ASSERT_GE(driver.alpha(), Fixed::zero());
      ASSERT_LT(driver.alpha(), Fixed::one());
    }
    hashes.push_back(s.world.hashes().total);
    EXPECT_EQ(taken, steps);
    EXPECT_EQ(driver.total_steps(), steps);
    EXPECT_EQ(s.world.frame(), steps);
    EXPECT_EQ(first_difference(hashes, reference), -1)
        << "sizes " << hashes.size() << " and " << reference.size();
    // The hosts really did exercise both sides of the accumulator.
    if (host.hz > 60) {
      EXPECT_GT(idle_frames, 0);
    }
    if (host.hz < 60) {
      EXPECT_GT(multi_step_frames, 0);
    }
  }
}

// ---- Exact time --------------------------------------------------------------------------------

TEST(SimDriver, AnHourOfSixtyHertzFramesGivesExactlyFloorOfTotalOverDt) {
  World world = make_world();
  const Fixed dt = world.def().dt;
  FixedStepDriver driver = make_driver();
  const std::int64_t frame_ns = 16'666'667;  // what a 60 Hz host measures, rounded up
  const std::uint64_t frames = 60 * 60 * 60;
  std::uint64_t total = 0;
  for (std::uint64_t f = 0; f < frames; ++f) {
    (void)driver.advance(world, frame_ns);
    total += frame_ns;
    ASSERT_EQ(driver.total_steps(), steps_in(total, dt)) << "frame " << f;
  }
  EXPECT_EQ(total, frames * static_cast<std::uint64_t>(frame_ns));
  EXPECT_EQ(world.frame(), steps_in(total, dt));
  EXPECT_EQ(driver.accepted_ns(), static_cast<std::int64_t>(total));
  EXPECT_EQ(driver.dropped_ns(), 0);
  EXPECT_EQ(driver.alpha(), alpha_after(total, dt));
  EXPECT_EQ(driver.accumulated(), accumulated_after(total, dt));
}

TEST(SimDriver, RandomFrameTimesNeverDriftFromTheExactCount) {
  // dt values whose step is not a whole number of nanoseconds (1/60 s, an odd raw value) and one
  // that is (1/64 s).
  for (const Fixed dt : {WorldDef{}.dt, Fixed::from_raw(12'345'679), dt_64}) {
    SCOPED_TRACE(to_string(dt));
    World world = make_world(def_with_dt(dt));
    FixedStepDriver driver = make_driver();
    std::mt19937_64 rng(static_cast<std::uint64_t>(dt.raw()));
    std::uint64_t total = 0;
    for (int f = 0; f < 40'000; ++f) {
      // 0 .. 40 ms, with a few exact zeros and single nanoseconds.
      const std::uint64_t r = rng();
      const auto elapsed = static_cast<std::int64_t>(r % 8 == 0 ? (r >> 3) % 2 : r % 40'000'001);
      (void)driver.advance(world, elapsed);
      total += static_cast<std::uint64_t>(elapsed);
      ASSERT_EQ(driver.total_steps(), steps_in(total, dt)) << "frame " << f;
      ASSERT_EQ(driver.alpha(), alpha_after(total, dt)) << "frame " << f;
      ASSERT_EQ(driver.accumulated(), accumulated_after(total, dt)) << "frame " << f;
    }
    EXPECT_EQ(world.frame(), driver.total_steps());
  }
}

TEST(SimDriver, AlphaIsTheExactFractionOfAStep) {
  World world = make_world(def_with_dt(dt_64));
  FixedStepDriver driver = make_driver();
  EXPECT_EQ(driver.alpha(), Fixed::zero());
  EXPECT_EQ(driver.advance(world, step_64_ns / 2), 0U);
  EXPECT_EQ(driver.alpha(), Fixed::half());
  EXPECT_EQ(driver.accumulated(), Fixed::from_raw(Fixed::one_raw / 128));
  EXPECT_EQ(driver.advance(world, step_64_ns / 2), 1U);
  EXPECT_EQ(driver.alpha(), Fixed::zero());
  EXPECT_EQ(driver.advance(world, step_64_ns / 4), 0U);
  EXPECT_EQ(driver.alpha(), Fixed::from_raw(Fixed::one_raw / 4));
  // One nanosecond short of a step: just below 1, rounded down.
  EXPECT_EQ(driver.advance(world, step_64_ns * 3 / 4 - 1), 0U);
  const auto expected = static_cast<std::int64_t>((static_cast<u128>(step_64_ns - 1) << 32) /
                                                  static_cast<std::uint64_t>(step_64_ns));
  EXPECT_EQ(driver.alpha(), Fixed::from_raw(expected));
  EXPECT_LT(driver.alpha(), Fixed::one());
  EXPECT_EQ(driver.advance(world, 1), 1U);
  EXPECT_EQ(driver.alpha(), Fixed::zero());
}

TEST(SimDriver, ChronoDurationsAreNanoseconds) {
  World a = make_world();
  World b = make_world();
  FixedStepDriver da = make_driver();
  FixedStepDriver db = make_driver();
  EXPECT_EQ(da.advance(a, std::chrono::milliseconds(50)), db.advance(b, 50'000'000));
  EXPECT_EQ(da.advance(a, std::chrono::microseconds(7'500)), db.advance(b, 7'500'000));
  EXPECT_EQ(da.alpha(), db.alpha());
  EXPECT_EQ(da.accepted_ns(), 57'500'000);
  EXPECT_EQ(a.hashes(), b.hashes());
}

// ---- Guards ------------------------------------------------------------------------------------

TEST(SimDriver, AHitchIsClampedToMaxFrameAndTheRestReportedDropped) {
  World world = make_world();
  const Fixed dt = world.def().dt;
  FixedStepDriver driver = make_driver();
  const std::int64_t max_frame = driver.config().max_frame_ns;
  const std::int64_t hitch = 10 * static_cast<std::int64_t>(ns_per_second);
  int calls = 0;
  const std::uint32_t n = driver.advance(world, hitch, [&](World&) { ++calls; });
  EXPECT_EQ(n, steps_in(static_cast<std::uint64_t>(max_frame), dt));
  EXPECT_EQ(calls, static_cast<int>(n));
  EXPECT_GT(n, 0U);
  EXPECT_EQ(driver.accepted_ns(), max_frame);
  EXPECT_EQ(driver.dropped_ns(), hitch - max_frame);
  EXPECT_EQ(driver.alpha(), alpha_after(static_cast<std::uint64_t>(max_frame), dt));

  // A normal frame afterwards carries on from the clamped time, not the hitch.
  (void)driver.advance(world, 16'000'000);
  EXPECT_EQ(driver.total_steps(), steps_in(static_cast<std::uint64_t>(max_frame) + 16'000'000, dt));
  EXPECT_EQ(driver.dropped_ns(), hitch - max_frame);

  // A custom clamp, and counters that saturate instead of overflowing.
  auto custom = make_driver(DriverConfig{100'000'000, 1000});
  World other = make_world();
  EXPECT_EQ(custom.advance(other, std::numeric_limits<std::int64_t>::max()),
            steps_in(100'000'000, dt));
  EXPECT_EQ(custom.dropped_ns(), std::numeric_limits<std::int64_t>::max() - 100'000'000);
  (void)custom.advance(other, std::numeric_limits<std::int64_t>::max());
  EXPECT_EQ(custom.dropped_ns(), std::numeric_limits<std::int64_t>::max());
  EXPECT_EQ(custom.accepted_ns(), 200'000'000);
  EXPECT_EQ(custom.total_steps(), steps_in(200'000'000, dt));
}

TEST(SimDriver, TheStepCapDropsWholeStepsAndKeepsTheFraction) {
  World world = make_world(def_with_dt(dt_64));
  FixedStepDriver driver = make_driver(DriverConfig{1'000'000'000, 3});
  const std::int64_t fraction_ns = 1'000'000;
  EXPECT_EQ(driver.advance(world, 10 * step_64_ns + fraction_ns), 3U);
  EXPECT_EQ(driver.skipped_steps(), 7U);
  EXPECT_EQ(driver.alpha(), alpha_after(fraction_ns, dt_64));
  EXPECT_GT(driver.alpha(), Fixed::zero());
  EXPECT_EQ(world.frame(), 3U);
  // The accumulator does not grow: the next frame of one step's time takes one step.
  EXPECT_EQ(driver.advance(world, step_64_ns), 1U);
  EXPECT_EQ(driver.skipped_steps(), 7U);
}

TEST(SimDriver, TheLargestClampWithTheSmallestDtDoesNotOverflow) {
  const Fixed dt = Fixed::epsilon();  // 2^-32 s: the most steps per nanosecond a world allows
  World world = make_world(def_with_dt(dt));
  const std::int64_t max_frame = 1'000'000'000'000;
  FixedStepDriver driver = make_driver(DriverConfig{max_frame, 5});
  const auto whole = static_cast<std::uint64_t>(max_frame);
  EXPECT_EQ(driver.advance(world, std::numeric_limits<std::int64_t>::max()), 5U);
  EXPECT_EQ(driver.skipped_steps(), steps_in(whole, dt) - 5);
  EXPECT_EQ(driver.alpha(), alpha_after(whole, dt));
  EXPECT_EQ(driver.advance(world, std::numeric_limits<std::int64_t>::max()), 5U);
  EXPECT_EQ(driver.skipped_steps() + driver.total_steps(), steps_in(2 * whole, dt));
  EXPECT_EQ(driver.alpha(), alpha_after(2 * whole, dt));
}

TEST(SimDriver, ZeroAndNegativeElapsedTimeChangeNothing) {
  World world = make_world();
  add_ground(world);
  BodyDef ball;
  ball.position = {0_fx, 2_fx, 0_fx};
  (void)add(world, ball);
  FixedStepDriver driver = make_driver();
  ASSERT_EQ(driver.advance(world, 40'000'000), 2U);
  const StateHashes before = world.hashes();
  const Fixed alpha = driver.alpha();
  ASSERT_GT(alpha, Fixed::zero());
  for (const std::int64_t elapsed : {std::int64_t{0}, std::int64_t{-1}, std::int64_t{-16'666'667},
                                     std::numeric_limits<std::int64_t>::min()}) {
    SCOPED_TRACE(elapsed);
    int calls = 0;
    EXPECT_EQ(driver.advance(world, elapsed, [&](World&) { ++calls; }), 0U);
    EXPECT_EQ(calls, 0);
    EXPECT_EQ(world.hashes(), before);
    EXPECT_EQ(driver.alpha(), alpha);
    EXPECT_EQ(driver.accepted_ns(), 40'000'000);
    EXPECT_EQ(driver.dropped_ns(), 0);
    EXPECT_EQ(driver.total_steps(), 2U);
  }
}

TEST(SimDriver, InvalidConfigurationsAreRefusedWithTheFieldNamed) {
  struct Case {
    DriverConfig config;
    std::string field;
    std::string value;
  };
  const std::vector<Case> cases = {
      {{0, 128}, "max_frame_ns", "got 0"},
      {{-5, 128}, "max_frame_ns", "got -5"},
      {{1'000'000'000'001, 128}, "max_frame_ns", "got 1000000000001"},
      {{std::numeric_limits<std::int64_t>::min(), 128}, "max_frame_ns", "got -"},
      {{250'000'000, 0}, "max_steps_per_advance", "got 0"},
  };
  for (const Case& c : cases) {
    const auto d = FixedStepDriver::create(c.config);
    ASSERT_FALSE(d.ok()) << c.field;
    EXPECT_NE(d.message().find(c.field), std::string::npos) << d.message();
    EXPECT_NE(d.message().find(c.value), std::string::npos) << d.message();
  }
  // The edges of the valid ranges.
  for (const DriverConfig config :
       {DriverConfig{1, 1}, DriverConfig{1'000'000'000'000, 1},
        DriverConfig{1, std::numeric_limits<std::uint32_t>::max()}, DriverConfig{}}) {
    const auto d = FixedStepDriver::create(config);
    ASSERT_TRUE(d.ok()) << d.message();
    EXPECT_EQ(d->config(), config);
  }
  EXPECT_EQ(FixedStepDriver().config(), DriverConfig{});
}

// ---- The before_step callback ------------------------------------------------------------------

void count_call(World& w) {
  static_cast<void>(w.rng().next_u64());
}

TEST(SimDriver, BeforeStepRunsOncePerStepAtTheFrameAboutToBeStepped) {
  World world = make_world();
  const Fixed dt = world.def().dt;
  FixedStepDriver driver = make_driver();
  std::vector<std::uint64_t> frames;
  std::uint64_t returned = 0;
  std::uint64_t total = 0;
  for (const std::int64_t elapsed :
       {5'000'000, 40'000'000, 0, 16'666'666, 16'666'667, 100'000'000, 3'000'000, 33'333'333}) {
    returned += driver.advance(world, elapsed, [&](World& w) { frames.push_back(w.frame()); });
    total += static_cast<std::uint64_t>(elapsed);
  }
  ASSERT_EQ(frames.size(), steps_in(total, dt));
  EXPECT_EQ(returned, frames.size());
  for (std::size_t i = 0; i < frames.size(); ++i)
    EXPECT_EQ(frames[i], i);
  EXPECT_EQ(world.frame(), frames.size());

  // Any callable: a plain function, a function pointer, a const functor, a std::function. Each
  // draws from the RNG once per step, which the RNG's state then shows.
  World reference = make_world();
  Rng expected = reference.rng();
  const auto draws_once = [](World& w) { count_call(w); };
  const std::function<void(World&)> wrapped = count_call;
  std::uint64_t steps = driver.advance(world, 50'000'000, count_call);
  steps += driver.advance(world, 50'000'000, &count_call);
  steps += driver.advance(world, 50'000'000, draws_once);
  steps += driver.advance(world, 50'000'000, wrapped);
  ASSERT_GT(steps, 4U);
  for (std::uint64_t i = 0; i < steps; ++i)
    (void)expected.next_u64();
  EXPECT_EQ(world.rng().state(), expected.state());
}

TEST(SimDriver, AfterStepRunsOncePerStepAtTheFrameJustStepped) {
  // before_step sees frame f, the step makes f + 1, after_step sees f + 1 — in that order, once
  // per step, any callable.
  World world = make_world();
  FixedStepDriver driver = make_driver();
  std::vector<std::int64_t> log;  // +frame for before_step, -frame for after_step
  std::uint64_t steps = 0;
  for (const std::int64_t elapsed : {40'000'000, 0, 16'666'667, 100'000'000}) {
    steps += driver.advance(
        world, elapsed, [&](World& w) { log.push_back(static_cast<std::int64_t>(w.frame())); },
        [&](World& w) { log.push_back(-static_cast<std::int64_t>(w.frame())); });
  }
  ASSERT_GT(steps, 4U);
  ASSERT_EQ(log.size(), 2 * steps);
  for (std::size_t i = 0; i < steps; ++i) {
    EXPECT_EQ(log[2 * i], static_cast<std::int64_t>(i));
    EXPECT_EQ(log[2 * i + 1], -static_cast<std::int64_t>(i + 1));
  }
  const std::uint64_t before = world.frame();
  const std::uint64_t more =
      driver.advance(world, 50'000'000, FixedStepDriver::NoInput{}, count_call);
  EXPECT_EQ(world.frame(), before + more);
}

TEST(SimDriver, AnExceptionFromBeforeStepLeavesTheStepUntaken) {
  World world = make_world(def_with_dt(dt_64));
  FixedStepDriver driver = make_driver();
  int calls = 0;
  EXPECT_THROW(driver.advance(world, 3 * step_64_ns,
                              [&](World&) {
                                if (++calls == 2) throw std::runtime_error("game error");
                              }),
               std::runtime_error);
  EXPECT_EQ(world.frame(), 1U);
  EXPECT_EQ(driver.total_steps(), 1U);
  EXPECT_LT(driver.alpha(), Fixed::one());
  // The two steps' worth still pending are taken next time, and the count stays exact.
  EXPECT_EQ(driver.advance(world, 0), 2U);
  EXPECT_EQ(world.frame(), 3U);
  EXPECT_EQ(driver.alpha(), Fixed::zero());
}

// ---- Interpolation -----------------------------------------------------------------------------

struct Spinner {
  World world;
  BodyId id;
};

// A sphere in free flight (no gravity), moving and spinning, stepped at 1/64 s.
Spinner make_spinner() {
  WorldDef def = def_with_dt(dt_64);
  def.gravity = {};
  Spinner s{make_world(def), {}};
  BodyDef d;
  d.position = {1_fx, 2_fx, 3_fx};
  d.linear_velocity = {2_fx, -1_fx, 0.5_fx};
  d.angular_velocity = {0.5_fx, 3_fx, -1_fx};
  s.id = add(s.world, d);
  return s;
}

Transform pose(const World& w, BodyId id) {
  const BodyState b = test::state(w, id);
  return {b.position, b.orientation};
}

TEST(SimDriver, TakeDueStepsCountsLikeAdvanceAndInterpolatesWhatSomethingElseStepped) {
  // Two hosts with the same frame times: one lets the driver step its world, the other takes
  // the due count and steps the world itself (as a session does), capturing the poses before
  // the last step. Same counts, same counters, same alpha, the same interpolated poses.
  Spinner driven = make_spinner();
  Spinner stepped = make_spinner();
  FixedStepDriver a = make_driver();
  FixedStepDriver b = make_driver();
  std::mt19937_64 random(17);
  for (int frame = 0; frame < 200; ++frame) {
    SCOPED_TRACE(frame);
    const auto elapsed = static_cast<std::int64_t>(random() % 40'000'000);
    const std::uint32_t n = a.advance(driven.world, elapsed);
    const std::uint32_t due = b.take_due_steps(stepped.world, elapsed);
    ASSERT_EQ(due, n);
    for (std::uint32_t i = 0; i < due; ++i) {
      if (i + 1 == due) b.capture_poses(stepped.world);
      stepped.world.step();
    }
    ASSERT_EQ(stepped.world.frame(), driven.world.frame());
    EXPECT_EQ(b.alpha(), a.alpha());
    EXPECT_EQ(b.total_steps(), a.total_steps());
    EXPECT_EQ(b.interpolated(stepped.world, stepped.id), a.interpolated(driven.world, driven.id));
  }
  // A host that did not step after capturing (a session at its prediction limit) is drawn where
  // its world is: no blend towards a frame that never came.
  ASSERT_EQ(b.take_due_steps(stepped.world, step_64_ns * 3 / 2), 1U);
  b.capture_poses(stepped.world);
  EXPECT_EQ(b.interpolated(stepped.world, stepped.id), pose(stepped.world, stepped.id));
  EXPECT_EQ(b.take_due_steps(stepped.world, -5), 0U) << "time going backwards adds nothing";
}

TEST(SimDriver, InterpolationStartsAtThePreviousPoseAndApproachesTheCurrentOne) {
  Spinner s = make_spinner();
  FixedStepDriver driver = make_driver();
  Transform seen{};
  ASSERT_EQ(driver.advance(s.world, 2 * step_64_ns, [&](World& w) { seen = pose(w, s.id); }), 2U);
  const Transform previous = seen;
  const Transform current = pose(s.world, s.id);
  ASSERT_NE(previous.position, current.position);
  ASSERT_NE(previous.orientation, current.orientation);
  ASSERT_EQ(driver.alpha(), Fixed::zero());
  EXPECT_EQ(driver.interpolated(s.world, s.id), previous);

  // Tenths of a step: the pose moves along the segment, closer to the current one each time.
  Fixed last_distance = distance(previous.position, current.position);
  Fixed last_alignment = abs(dot(previous.orientation, current.orientation));
  for (int tenth = 1; tenth < 10; ++tenth) {
    SCOPED_TRACE(tenth);
    ASSERT_EQ(driver.advance(s.world, step_64_ns / 10), 0U);
    const Fixed t = driver.alpha();
    const auto p = driver.interpolated(s.world, s.id);
    ASSERT_TRUE(p.has_value());
    const Vec3 along = previous.position + (current.position - previous.position) * t;
    EXPECT_TRUE(near(p->position.x, along.x, Fixed::epsilon()));
    EXPECT_TRUE(near(p->position.y, along.y, Fixed::epsilon()));
    EXPECT_TRUE(near(p->position.z, along.z, Fixed::epsilon()));
    const Fixed d = distance(p->position, current.position);
    EXPECT_LT(d, last_distance);
    last_distance = d;
    // A unit quaternion turning monotonically towards the current orientation.
    EXPECT_TRUE(near(length_squared(p->orientation), Fixed::one(), Fixed::from_raw(8)));
    const Fixed alignment = abs(dot(p->orientation, current.orientation));
    EXPECT_GT(alignment, last_alignment);
    last_alignment = alignment;
  }
  // At 0.9 of a step, a tenth of the way from the current pose (plus rounding).
  EXPECT_LE(last_distance, distance(previous.position, current.position) / Fixed::from_int(10) +
                               4 * Fixed::epsilon());

  // The tenth tenth completes the step: the new previous pose is the old current one, so the
  // rendered pose continues without a jump.
  ASSERT_EQ(driver.advance(s.world, step_64_ns / 10), 1U);
  EXPECT_EQ(driver.alpha(), Fixed::zero());
  EXPECT_EQ(driver.interpolated(s.world, s.id), current);
}

TEST(SimDriver, AtAlphaZeroThePreviousPoseComesBackBitForBit) {
  // The world holds normalize(input). For about 1% of near-unit inputs, normalising that once more
  // still moves a bit, so an interpolation that renormalised at alpha 0 would not return the pose
  // the world held. Find such an input.
  std::mt19937_64 rng(11);
  const auto component = [&rng] {
    return Fixed::from_raw(static_cast<std::int64_t>(rng() % (std::uint64_t{1} << 33)) -
                           Fixed::one_raw);
  };
  Quat input{};
  for (int i = 0; i < 100'000; ++i) {
    Quat candidate = normalize(Quat{component(), component(), component(), component()});
    candidate.w += Fixed::from_raw(static_cast<std::int64_t>(rng() % 4096));  // within 2^-20
    const Quat held = normalize(candidate);
    if (normalize(held) != held) {
      input = candidate;
      break;
    }
  }
  const Quat held = normalize(input);
  ASSERT_NE(normalize(held), held) << "no such quaternion found";

  Spinner s = make_spinner();
  FixedStepDriver driver = make_driver();
  const Vec3 where{5_fx, 6_fx, 7_fx};
  ASSERT_EQ(
      driver.advance(s.world, step_64_ns,
                     [&](World& w) { EXPECT_TRUE(w.set_transform(s.id, where, input).ok()); }),
      1U);
  ASSERT_EQ(driver.alpha(), Fixed::zero());
  ASSERT_NE(pose(s.world, s.id).orientation, held);  // it spun during the step
  EXPECT_EQ(driver.interpolated(s.world, s.id), (Transform{where, held}));
}

TEST(SimDriver, InterpolationTakesTheShorterArc) {
  Spinner s = make_spinner();
  FixedStepDriver driver = make_driver();
  Transform seen{};
  ASSERT_EQ(driver.advance(s.world, step_64_ns * 3 / 2, [&](World& w) { seen = pose(w, s.id); }),
            1U);
  ASSERT_EQ(driver.alpha(), Fixed::half());
  const Quat previous = seen.orientation;
  const Transform current = pose(s.world, s.id);
  // -q is the same rotation as q, on the other side of the quaternion sphere.
  const Quat flipped{-current.orientation.w, -current.orientation.x, -current.orientation.y,
                     -current.orientation.z};
  ASSERT_TRUE(s.world.set_transform(s.id, current.position, flipped).ok());
  ASSERT_LT(dot(previous, flipped), Fixed::zero());
  const auto p = driver.interpolated(s.world, s.id);
  ASSERT_TRUE(p.has_value());
  // Halfway along a small rotation, so close to both ends (as rotations: up to sign). A blend that
  // took the long way would pass near the zero quaternion and come out far from both.
  const Fixed close = Fixed::one() - Fixed::from_raw(Fixed::one_raw / 1000);
  ASSERT_GT(abs(dot(previous, flipped)), close);
  EXPECT_GT(abs(dot(p->orientation, previous)), close);
  EXPECT_GT(abs(dot(p->orientation, flipped)), close);
  EXPECT_TRUE(near(length_squared(p->orientation), Fixed::one(), Fixed::from_raw(8)));
}

TEST(SimDriver, NewUnknownAndForeignSteppedBodiesGetTheirCurrentPose) {
  Spinner s = make_spinner();
  FixedStepDriver driver = make_driver();
  ASSERT_EQ(driver.advance(s.world, step_64_ns * 3 / 2), 1U);
  ASSERT_NE(driver.interpolated(s.world, s.id), pose(s.world, s.id));

  // Created after the last step: nothing to interpolate from.
  BodyDef d;
  d.position = {-4_fx, 1_fx, 0_fx};
  d.linear_velocity = {1_fx, 0_fx, 0_fx};
  const BodyId late = add(s.world, d);
  EXPECT_EQ(driver.interpolated(s.world, late), pose(s.world, late));
  // Unknown and destroyed IDs.
  EXPECT_FALSE(driver.interpolated(s.world, BodyId{}).has_value());
  EXPECT_FALSE(driver.interpolated(s.world, BodyId{999}).has_value());
  ASSERT_TRUE(s.world.destroy_body(late).ok());
  EXPECT_FALSE(driver.interpolated(s.world, late).has_value());

  // A step the driver did not take: its previous poses belong to another frame.
  s.world.step();
  EXPECT_EQ(driver.interpolated(s.world, s.id), pose(s.world, s.id));

  // A body created in before_step has a previous pose (the one it was created with).
  BodyId created{};
  ASSERT_EQ(driver.advance(s.world, step_64_ns, [&](World& w) { created = add(w, d); }), 1U);
  ASSERT_EQ(driver.alpha(), Fixed::half());
  const Vec3 halfway = d.position + (test::state(s.world, created).position - d.position) / 2_fx;
  const auto p = driver.interpolated(s.world, created);
  ASSERT_TRUE(p.has_value());
  EXPECT_TRUE(near(p->position.x, halfway.x, Fixed::epsilon()));
  EXPECT_NE(p->position, test::state(s.world, created).position);

  // reset() forgets everything but the configuration.
  driver.reset();
  EXPECT_EQ(driver.alpha(), Fixed::zero());
  EXPECT_EQ(driver.accumulated(), Fixed::zero());
  EXPECT_EQ(driver.total_steps(), 0U);
  EXPECT_EQ(driver.accepted_ns(), 0);
  EXPECT_EQ(driver.interpolated(s.world, s.id), pose(s.world, s.id));
}

}  // namespace
}  // namespace detsim
