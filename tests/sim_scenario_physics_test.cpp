// The scenarios' physical promises: the stack and the pyramid stand and sleep, the bullet never
// passes the wall (with and without the CCD flag, at any phase of the step), the slope sorts boxes
// by friction, the dominoes all fall, and the game logic of spray and arena does what it says.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

#include "support/scale.hpp"
#include "support/sim_helpers.hpp"

namespace detsim {
namespace {

using namespace detsim::literals;

using test::add;
using test::make_world;
using test::state;

Scenario make(std::string_view name, const ScenarioParams& p = {}) {
  auto s = Scenario::create(name, p);
  EXPECT_TRUE(s.ok()) << s.message();
  return std::move(s.value());
}

std::vector<BodyState> dynamic_bodies(const World& w) {
  std::vector<BodyState> out;
  for (const BodyId id : w.body_ids()) {
    const BodyState b = state(w, id);
    if (b.type == BodyType::dynamic) out.push_back(b);
  }
  return out;
}

// Stands for 20 s: after a settling second, no box moves by 1 cm in any direction, and by the
// end every box sleeps. The sanitizer build runs a tenth of the time and checks the drift only.
void expect_stands_and_sleeps(std::string_view name) {
  Scenario s = make(name);
  const std::size_t frames = test::scaled(1200);
  for (int f = 0; f < 60; ++f)
    s.step();
  const std::vector<BodyState> settled = dynamic_bodies(s.world());
  for (std::size_t f = 60; f < frames; ++f)
    s.step();
  const std::vector<BodyState> end = dynamic_bodies(s.world());
  ASSERT_EQ(end.size(), settled.size());
  Fixed worst;
  for (std::size_t i = 0; i < end.size(); ++i) {
    const Vec3 d = end[i].position - settled[i].position;
    worst = max(worst, max(abs(d.x), max(abs(d.y), abs(d.z))));
    EXPECT_LT(length(d), 0.01_fx) << name << ": body " << end[i].id.value << " drifted";
    // Boxes of a stack or pyramid stay axis-aligned: |w| of the orientation stays ~1.
    EXPECT_GT(abs(end[i].orientation.w), 0.9999_fx) << name << ": body " << end[i].id.value;
  }
  if (frames == 1200) {
    for (const BodyState& b : end)
      EXPECT_FALSE(b.awake) << name << ": body " << b.id.value;
  }
  std::printf("%s: worst drift over %zu frames after settling %s m\n", std::string(name).c_str(),
              frames - 60, to_string(worst).c_str());
}

TEST(StackScenario, StandsTwentySecondsWithoutDriftAndSleeps) {
  expect_stands_and_sleeps("stack");
}

TEST(PyramidScenario, StandsTwentySecondsWithoutDriftAndSleeps) {
  expect_stands_and_sleeps("pyramid");
}

// ---- The bullet and the wall ----

// The wall's near face is at x = 9.9 and the bullet's radius 0.05: its centre must never pass
// 9.85 (plus the allowed overlap), in any frame.
void expect_bullet_stopped(World& w, BodyId bullet, Fixed face, Fixed radius, int frames,
                           const char* what) {
  Fixed furthest = state(w, bullet).position.x;
  for (int f = 0; f < frames; ++f) {
    w.step();
    furthest = max(furthest, state(w, bullet).position.x);
  }
  EXPECT_LE(furthest, face - radius + w.def().linear_slop)
      << what << ": the bullet reached x = " << to_string(furthest);
}

TEST(BulletWallScenario, TheBulletNeverPassesTheWall) {
  Scenario s = make("bullet_wall");
  const BodyId bullet{3};
  ASSERT_EQ(state(s.world(), bullet).shape.radius, 0.05_fx);
  expect_bullet_stopped(s.world(), bullet, 9.9_fx, 0.05_fx, 120, "bullet_wall");
}

TEST(ContinuousCollision, NoPhaseOfTheStepLetsABulletThrough) {
  // The same bullet at 1000 m/s (16.7 m per step) against a 0.2 m wall, starting at 40 offsets
  // spread over one step's travel, with and without the CCD flag, and at 1500 m/s (the clamp).
  for (const bool ccd : {true, false}) {
    for (const Fixed speed : {1000_fx, 1500_fx}) {
      for (int k = 0; k < 40; ++k) {
        World w = make_world();
        add(w, {.type = BodyType::static_body,
                .shape = Shape::box({0.1_fx, 1_fx, 1_fx}),
                .position = {30_fx, 1_fx, 0_fx}});
        const Fixed start = Fixed::from_int(k) * 0.42_fx;
        const BodyId bullet = add(w, {.shape = Shape::sphere(0.05_fx),
                                      .position = {start, 1_fx, 0_fx},
                                      .linear_velocity = {speed, 0_fx, 0_fx},
                                      .ccd = ccd});
        expect_bullet_stopped(w, bullet, 29.9_fx, 0.05_fx, 10, ccd ? "ccd" : "fast, no ccd flag");
      }
    }
  }
}

TEST(ContinuousCollision, AFastBodyDoesNotPassAThinDynamicBodyOrABoxCorner) {
  // A dynamic 0.1 m plank in free space, a CCD sphere at 800 m/s: the sphere must hit it (the
  // plank is then moving +x), never appear beyond it while the plank is still behind.
  WorldDef def;
  def.gravity = {};
  World w = make_world(def);
  const BodyId plank =
      add(w, {.shape = Shape::box({0.05_fx, 1_fx, 1_fx}), .position = {20_fx, 0_fx, 0_fx}});
  const BodyId ball = add(
      w, {.shape = Shape::sphere(0.1_fx), .linear_velocity = {800_fx, 0_fx, 0_fx}, .ccd = true});
  for (int f = 0; f < 5; ++f) {
    w.step();
    EXPECT_LE(state(w, ball).position.x, state(w, plank).position.x) << "frame " << f;
  }
  EXPECT_GT(state(w, plank).linear_velocity.x, 1_fx) << "the plank should have been hit";

  // A fast spinning box past a thin static wall edge-on: it must not end up inside or beyond.
  World spin = make_world(def);
  add(spin, {.type = BodyType::static_body,
             .shape = Shape::box({0.02_fx, 2_fx, 2_fx}),
             .position = {3_fx, 0_fx, 0_fx}});
  const BodyId box = add(spin, {.shape = Shape::box({0.5_fx, 0.1_fx, 0.1_fx}),
                                .linear_velocity = {300_fx, 0_fx, 0_fx},
                                .angular_velocity = {0_fx, 0_fx, 150_fx}});
  for (int f = 0; f < 5; ++f) {
    spin.step();
    EXPECT_LT(state(spin, box).position.x, 3_fx) << "frame " << f;
  }
}

// ---- Slope, dominoes, bounce ----

TEST(SlopeScenario, BoxesSlideExactlyWhenTanThirtyExceedsTheirFriction) {
  Scenario s = make("slope");
  const std::vector<BodyState> start = dynamic_bodies(s.world());
  ASSERT_EQ(start.size(), 5U);
  for (int f = 0; f < 240; ++f)
    s.step();
  const std::vector<BodyState> end = dynamic_bodies(s.world());
  const Fixed tan30 = tan(Fixed::pi() / 6_fx);
  for (std::size_t i = 0; i < start.size(); ++i) {
    // The pair's friction is sqrt(box mu * slab mu) with slab mu = 1.
    const Fixed mu = sqrt(start[i].friction);
    const Fixed moved = length(end[i].position - start[i].position);
    if (mu < tan30) {
      EXPECT_GT(moved, 1_fx) << "mu " << to_string(mu) << " should slide";
    } else {
      EXPECT_LT(moved, 0.02_fx) << "mu " << to_string(mu) << " should hold";
    }
  }
}

TEST(DominoesScenario, EveryDominoFalls) {
  Scenario s = make("dominoes");
  for (int f = 0; f < 600; ++f)
    s.step();
  const std::vector<BodyState> end = dynamic_bodies(s.world());
  ASSERT_EQ(end.size(), 30U);
  for (const BodyState& b : end) {
    // Fallen: the domino's long axis (local y) is tilted more than 30 degrees from vertical.
    const Vec3 up = rotate(b.orientation, Vec3{0_fx, 1_fx, 0_fx});
    EXPECT_LT(up.y, cos(Fixed::pi() / 6_fx)) << "domino " << b.id.value << " still stands";
  }
}

TEST(BounceScenario, ReboundHeightGrowsWithRestitution) {
  Scenario s = make("bounce");
  std::vector<Fixed> highest_after_first_landing(5);
  std::vector<bool> landed(5, false);
  for (int f = 0; f < 300; ++f) {
    s.step();
    const std::vector<BodyState> b = dynamic_bodies(s.world());
    for (std::size_t i = 0; i < 5; ++i) {
      if (b[i].position.y < 0.3_fx) landed[i] = true;
      if (landed[i])
        highest_after_first_landing[i] = max(highest_after_first_landing[i], b[i].position.y);
    }
  }
  // Drop height above the ground h = 4.75 m; a rebound reaches about e^2 h above it.
  EXPECT_LT(highest_after_first_landing[0], 0.26_fx);  // e = 0: stays down
  for (std::size_t i = 1; i < 5; ++i) {
    EXPECT_GT(highest_after_first_landing[i], highest_after_first_landing[i - 1]);
    const Fixed e = Fixed::from_int(static_cast<std::int32_t>(i)) / 4_fx;
    const Fixed expected = 0.25_fx + e * e * 4.75_fx;
    EXPECT_GT(highest_after_first_landing[i], expected * 0.95_fx) << "e = " << to_string(e);
    EXPECT_LT(highest_after_first_landing[i], expected * 1.02_fx + 0.01_fx)
        << "e = " << to_string(e);
  }
}

// ---- Game logic ----

TEST(SprayScenario, SpawnsFromTheRngKeepsItsPopulationBoundedAndMovesItsMovers) {
  Scenario s = make("spray", {.seed = 3});
  const std::size_t statics = s.world().body_count();
  std::size_t most = 0;
  for (int f = 0; f < 1000; ++f) {
    s.step();
    most = std::max(most, s.world().body_count() - statics);
  }
  EXPECT_EQ(most, 120U) << "one spawn every 6 frames reaches the cap of 120 by frame 720";
  // The platform (body 7, kinematic) went back and forth: +2 m/s in frames [0, 180), -2 m/s in
  // [180, 360), and so on. Over frames 0 .. 999 the signs sum to 180 (five periods: + - + - +)
  // minus 100 (frames 900 .. 999), so x = -6 + 2 dt 80.
  const BodyState platform = state(s.world(), BodyId{7});
  ASSERT_EQ(platform.type, BodyType::kinematic);
  const Fixed expected = -6_fx + 2_fx * s.world().def().dt * Fixed::from_int(80);
  EXPECT_LT(abs(platform.position.x - expected), 0.001_fx) << to_string(platform.position.x);
}

TEST(ArenaScenario, PlayersFollowTheirSticks) {
  Scenario s = make("arena", {.players = 4});
  const BodyId p0 = s.player_body(0);
  const BodyId p1 = s.player_body(1);
  const Vec3 start0 = state(s.world(), p0).position;
  const Vec3 start1 = state(s.world(), p1).position;
  // Player 0 starts at (8, 0, 0) and pushes towards -x; player 1 at (-8, 0, 0) pushes towards +z.
  const std::vector<PlayerInput> inputs{{0, -127, 0}, {0, 0, 127}, {}, {}};
  for (int f = 0; f < 60; ++f)
    s.step(inputs);
  const Vec3 d0 = state(s.world(), p0).position - start0;
  const Vec3 d1 = state(s.world(), p1).position - start1;
  EXPECT_LT(d0.x, -1_fx);
  EXPECT_LT(abs(d0.z), 0.1_fx);
  EXPECT_GT(d1.z, 1_fx);
  EXPECT_LT(abs(d1.x), 0.1_fx);
}

TEST(ArenaScenario, JumpWorksFromTheFloorOnly) {
  Scenario s = make("arena");
  const BodyId p0 = s.player_body(0);
  for (int f = 0; f < 30; ++f)
    s.step();  // settle on the floor
  const std::vector<PlayerInput> jump{{PlayerInput::jump, 0, 0}};
  s.step(jump);
  // 400 N s on 80 kg: +5 m/s, less a step of gravity.
  EXPECT_GT(state(s.world(), p0).linear_velocity.y, 4.5_fx);
  s.step(jump);  // in the air: nothing more
  EXPECT_LT(state(s.world(), p0).linear_velocity.y, 5_fx);
}

TEST(ArenaScenario, RngEventsKickAndSpawnCrates) {
  Scenario s = make("arena", {.seed = 11});
  const std::size_t before = s.world().body_count();
  const auto rng_before = s.world().rng().state();
  for (int f = 0; f < 301; ++f)
    s.step();
  EXPECT_NE(s.world().rng().state(), rng_before);
  EXPECT_EQ(s.world().body_count(), before + 1) << "one crate spawns at frame 300";
}

}  // namespace
}  // namespace detsim
