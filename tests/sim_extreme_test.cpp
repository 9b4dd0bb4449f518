// Extreme input: absurd speeds and forces, bodies spawned inside each other, tiny boxes, huge mass
// ratios. The promise: no crash and no undefined behaviour (this suite runs under ASan and UBSan),
// the same bits twice, speeds within the world's clamps, and no explosion (bounds stated per
// scene, each far above what the scene needs and far below what a blow-up produces).
#include <cstdint>
#include <functional>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

#include "support/sim_helpers.hpp"

namespace detsim {
namespace {

using namespace detsim::literals;

using test::add;
using test::add_ground;
using test::make_world;
using test::state;

struct Extremes {
  Fixed max_speed;
  Fixed max_angular_speed;
  Fixed max_distance;  // of any body from the origin
};

// Runs `build` + `frames` steps (with `each_frame` before each step) twice; checks that every
// frame's hash agrees, that speeds stay within the clamps, and returns the extremes seen.
Extremes run_twice(const std::function<void(World&)>& build, int frames,
                   const std::function<void(World&)>& each_frame = {}) {
  World a = make_world();
  World b = make_world();
  build(a);
  build(b);
  Extremes seen;
  for (int f = 0; f < frames; ++f) {
    if (each_frame) {
      each_frame(a);
      each_frame(b);
    }
    a.step();
    b.step();
    EXPECT_EQ(a.hashes().total, b.hashes().total) << "frame " << f;
    for (const BodyId id : a.body_ids()) {
      const BodyState s = state(a, id);
      const Fixed v = length(s.linear_velocity);
      const Fixed w = length(s.angular_velocity);
      EXPECT_LE(v, a.def().max_linear_speed + 0.001_fx) << "body " << id.value;
      EXPECT_LE(w, a.def().max_angular_speed + 0.001_fx) << "body " << id.value;
      seen.max_speed = max(seen.max_speed, v);
      seen.max_angular_speed = max(seen.max_angular_speed, w);
      seen.max_distance = max(seen.max_distance, length(s.position));
    }
  }
  return seen;
}

TEST(ExtremeInput, AMillionMetresPerSecondIsClampedAndStopsAtTheGround) {
  const auto build = [](World& w) {
    add_ground(w);
    add(w, {.shape = Shape::box({0.5_fx, 0.5_fx, 0.5_fx}),
            .position = {0_fx, 10_fx, 0_fx},
            .linear_velocity = {0_fx, -1000000_fx, 0_fx}});
    add(w, {.shape = Shape::sphere(0.5_fx),
            .position = {5_fx, 10_fx, 0_fx},
            .linear_velocity = {1000000_fx, 1000000_fx, -1000000_fx},
            .angular_velocity = {100000_fx, 0_fx, 0_fx}});
  };
  run_twice(build, 120);
  World w = make_world();
  build(w);
  for (int f = 0; f < 120; ++f)
    w.step();
  // The box went down at the clamp: the ground stopped it (no tunnelling at 25 m per step).
  EXPECT_GT(state(w, BodyId{2}).position.y, 0_fx);
}

TEST(ExtremeInput, AGigaNewtonEveryFrameIsClamped) {
  // The same giga-newton pushes on a box pressed into the ground and on one starting 100 m up. How
  // fast the grounded box goes depends on how its contact and friction play out (chaotic at these
  // forces); the other reaches the clamps in its first step, before it lands, so the clamps are
  // known to be exercised.
  const auto build = [](World& w) {
    add_ground(w);
    add(w, {.shape = Shape::box({0.5_fx, 0.5_fx, 0.5_fx}), .position = {0_fx, 0.5_fx, 0_fx}});
    add(w, {.shape = Shape::box({0.5_fx, 0.5_fx, 0.5_fx}), .position = {0_fx, 100_fx, 0_fx}});
  };
  const auto push = [](World& w) {
    for (const BodyId id : {BodyId{2}, BodyId{3}}) {
      (void)w.apply_force(id, {1000000000_fx, 0_fx, 0_fx});
      (void)w.apply_torque(id, {0_fx, 1000000000_fx, 0_fx});
      const Vec3 corner = state(w, id).position + Vec3{0.5_fx, 0.5_fx, 0_fx};
      (void)w.apply_force_at_point(id, {0_fx, -1000000000_fx, 0_fx}, corner);
    }
  };
  const Extremes e = run_twice(build, 60, push);
  EXPECT_GE(e.max_speed, 1500_fx - 0.001_fx) << "the free box should reach the clamp";
  EXPECT_GE(e.max_angular_speed, 200_fx - 0.001_fx) << "and spin at the angular clamp";
}

TEST(ExtremeInput, FiftyBodiesSpawnedInsideEachOtherSeparateWithoutExploding) {
  const auto build = [](World& w) {
    add_ground(w);
    for (int i = 0; i < 50; ++i) {
      const Shape shape = i % 3 == 0   ? Shape::sphere(0.5_fx)
                          : i % 3 == 1 ? Shape::box({0.5_fx, 0.5_fx, 0.5_fx})
                                       : Shape::capsule(0.3_fx, 0.5_fx);
      add(w, {.shape = shape, .position = {0_fx, 1_fx, 0_fx}});  // all at the same place
    }
  };
  const Extremes e = run_twice(build, 300);
  // Overlap is pushed apart at most contact_push_max (3 m/s) per contact; pile-ups of 50 bodies
  // add up a few of those. An explosion reaches the clamp (1500 m/s) within a step.
  EXPECT_LT(e.max_speed, 30_fx);
  EXPECT_LT(e.max_distance, 50_fx);
}

TEST(ExtremeInput, TenthOfAMillimetreBoxesRestOnTheGround) {
  const auto build = [](World& w) {
    add_ground(w);
    for (int i = 0; i < 10; ++i) {
      add(w, {.shape = Shape::box({0.00005_fx, 0.00005_fx, 0.00005_fx}),
              .position = {Fixed::from_int(i) * 0.001_fx, 0.01_fx, 0_fx},
              .mass = 1_fx});
    }
  };
  const Extremes e = run_twice(build, 240);
  EXPECT_LT(e.max_speed, 2_fx);  // a 1 cm drop lands at 0.44 m/s
  World w = make_world();
  build(w);
  for (int f = 0; f < 240; ++f)
    w.step();
  // Resting: sunk into the ground by the allowed overlap plus the soft contact's sag under the
  // box's weight, g / omega^2 with omega = 2 pi 60 Hz against a static body (0.07 mm), not through
  // it. The bound allows twice the sag.
  const Fixed omega = Fixed::two_pi() * 60_fx;
  const Fixed sag = 9.81_fx / (omega * omega);
  const Fixed half = 0.00005_fx;
  for (const BodyId id : w.body_ids()) {
    const BodyState b = state(w, id);
    if (b.type != BodyType::dynamic) continue;
    EXPECT_GT(b.position.y - half, -(w.def().linear_slop + sag * 2_fx)) << "body " << id.value;
    EXPECT_LT(b.position.y, 0.001_fx) << "body " << id.value;
  }
}

TEST(ExtremeInput, TooSmallToHaveInertiaIsARefusalNotACrash) {
  World w = make_world();
  // 0.1 mm at water density: 1e-12 kg, which rounds to zero in Q32.32.
  auto tiny = w.create_body({.shape = Shape::box({0.00005_fx, 0.00005_fx, 0.00005_fx})});
  EXPECT_FALSE(tiny.ok());
  EXPECT_NE(tiny.message().find("mass"), std::string::npos) << tiny.message();
  EXPECT_EQ(w.body_count(), 0U);
}

TEST(ExtremeInput, TenTonnesOnAGramDoesNotExplode) {
  const auto build = [](World& w) {
    add_ground(w);
    add(w, {.shape = Shape::box({0.5_fx, 0.5_fx, 0.5_fx}),
            .position = {0_fx, 0.5_fx, 0_fx},
            .mass = 0.001_fx});
    add(w, {.shape = Shape::box({0.5_fx, 0.5_fx, 0.5_fx}),
            .position = {0_fx, 1.5_fx, 0_fx},
            .mass = 10000_fx});
    // And a gram sphere under a ten-tonne sphere, off to the side.
    add(w, {.shape = Shape::sphere(0.5_fx), .position = {5_fx, 0.5_fx, 0_fx}, .mass = 0.001_fx});
    add(w, {.shape = Shape::sphere(0.5_fx), .position = {5_fx, 1.5_fx, 0_fx}, .mass = 10000_fx});
  };
  const Extremes e = run_twice(build, 600);
  // The gram may be squeezed out sideways; the soft contact limits the push-out speed to a few
  // m/s, a blow-up would reach the clamp.
  EXPECT_LT(e.max_speed, 30_fx);
  EXPECT_LT(e.max_distance, 60_fx);
}

TEST(ExtremeInput, HugeImpulsesAndTeleportsFarAwayStayDefined) {
  const auto build = [](World& w) {
    add_ground(w);
    add(w, {.shape = Shape::capsule(0.2_fx, 0.5_fx), .position = {0_fx, 1_fx, 0_fx}});
    add(w, {.shape = Shape::sphere(0.2_fx), .position = {0_fx, 3_fx, 0_fx}});
  };
  int frame = 0;
  const auto chaos = [&frame](World& w) {
    // Alternating frames of world: the first call of a frame is world a, the second world b.
    const int f = frame++ / 2;
    if (f % 20 == 0) (void)w.apply_linear_impulse(BodyId{2}, {1000000000_fx, -1000000000_fx, 7_fx});
    if (f % 20 == 10)
      (void)w.apply_angular_impulse(BodyId{3}, {1000000000_fx, 1000000000_fx, 1000000000_fx});
    if (f == 100) (void)w.set_transform(BodyId{3}, {1000000_fx, 1000000_fx, -1000000_fx}, {});
  };
  run_twice(build, 200, chaos);
}

}  // namespace
}  // namespace detsim
