// The `cubes` scenario's physical promises (Gaffer On Games' networked-physics demo): the small
// cubes start clear of each other and of every large cube, settle by the contact's slop and sag
// and fall asleep, and then nothing in the state changes while no one plays; a large cube driven
// by the stick rolls into the grid and pushes small cubes about, leaving those out of its reach
// asleep; the jump lifts it as high as a damped throw goes, and only from near the ground. Each
// expectation is derived from the scene's geometry (read from the World at frame 0) and the
// physics, never read back from a run.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

#include "support/sim_helpers.hpp"

namespace detsim {
namespace {

using namespace detsim::literals;

using test::state;

Scenario make(const ScenarioParams& p = {}) {
  auto s = Scenario::create("cubes", p);
  EXPECT_TRUE(s.ok()) << s.message();
  return std::move(s.value());
}

/// The scene's bodies at some frame: the players' large cubes (by player) and the small cubes (by
/// ID), told apart by Scenario::player_body.
struct Cubes {
  std::vector<BodyState> large;
  std::vector<BodyState> small;
};

Cubes cubes_of(const Scenario& s) {
  const World& w = s.world();
  Cubes out;
  std::vector<BodyId> players;
  for (std::uint32_t p = 0; p < s.params().players; ++p) {
    players.push_back(s.player_body(p));
    out.large.push_back(state(w, players.back()));
  }
  for (const BodyId id : w.body_ids()) {
    const BodyState b = state(w, id);
    if (b.type == BodyType::dynamic &&
        std::find(players.begin(), players.end(), id) == players.end())
      out.small.push_back(b);
  }
  return out;
}

/// The radius of the sphere around a cube: its half side times sqrt 3.
Fixed bounding_radius(const BodyState& b) {
  return length(b.shape.half_extents);
}

TEST(CubesScenario, TheDefaultIsOnePlayerAndNineHundredSmallCubesClearOfEachOther) {
  Scenario s = make();
  EXPECT_EQ(s.params().players, 1U);
  EXPECT_EQ(s.params().count, 900U);
  const Cubes c = cubes_of(s);
  ASSERT_EQ(c.small.size(), 900U);
  ASSERT_EQ(c.large.size(), 1U);
  EXPECT_EQ(s.world().body_count(), 902U);  // and the plane
  // A 30 x 30 grid: 30 distinct x and z, and no two cubes within a side of each other (their
  // faces parallel: a gap between any two).
  std::vector<Fixed> xs;
  for (const BodyState& b : c.small)
    xs.push_back(b.position.x);
  std::sort(xs.begin(), xs.end());
  EXPECT_EQ(std::unique(xs.begin(), xs.end()) - xs.begin(), 30);
  const BodyState& first = c.small.front();
  const Fixed side = 2_fx * first.shape.half_extents.x;
  for (std::size_t i = 0; i < c.small.size(); ++i) {
    for (std::size_t j = i + 1; j < c.small.size(); ++j) {
      const Vec3 d = c.small[i].position - c.small[j].position;
      ASSERT_GT(max(abs(d.x), abs(d.z)), side) << "small cubes " << i << " and " << j << " touch";
    }
  }
  // The large cube is several times the small ones' size and outweighs them.
  EXPECT_GE(c.large[0].shape.half_extents.x, 4_fx * first.shape.half_extents.x);
  EXPECT_GT(c.large[0].mass, 50_fx * first.mass);
}

TEST(CubesScenario, EachOfEightPlayersHasALargeCubeAroundTheGridClearOfEveryOther) {
  for (const std::uint32_t players : {1U, 2U, 3U, 8U}) {
    for (const std::uint32_t count : {1U, 27U, 900U}) {
      Scenario s = make({.seed = 1, .players = players, .count = count});
      const Cubes c = cubes_of(s);
      ASSERT_EQ(c.large.size(), players);
      ASSERT_EQ(c.small.size(), count);
      for (std::size_t i = 0; i < c.large.size(); ++i) {
        const BodyState& a = c.large[i];
        EXPECT_EQ(a.position.y, a.shape.half_extents.y) << "player " << i << " rests on the plane";
        for (std::size_t j = i + 1; j < c.large.size(); ++j) {
          EXPECT_GT(length(a.position - c.large[j].position), 2_fx * bounding_radius(a))
              << players << " players: " << i << " and " << j << " overlap";
        }
        for (const BodyState& b : c.small) {
          ASSERT_GT(length(a.position - b.position), bounding_radius(a) + bounding_radius(b))
              << "player " << i << " starts among the small cubes";
        }
      }
    }
  }
  EXPECT_FALSE(Scenario::create("cubes", {.seed = 1, .players = 9, .count = 0}).ok());
  EXPECT_FALSE(Scenario::create("cubes", {.seed = 1, .players = 0, .count = 10001}).ok());
}

TEST(CubesScenario, UntouchedCubesSettleBySlopAndSagAndSleepAndThenNothingChanges) {
  // Resting on the plane each cube sinks by the linear slop plus the soft contact's sag under its
  // weight, g / omega^2 with omega = 2 pi 60 Hz against a static body (as a sphere does,
  // tests/sim_physics_test.cpp); within one sag of that. Asleep after time_to_sleep (0.5 s) and
  // a little settling: by 2 s. Then the bodies' section of the state does not change at all.
  Scenario s = make();
  const World& w = s.world();
  const Cubes start = cubes_of(s);
  for (int f = 0; f < 120; ++f)
    s.step();
  const Fixed omega = Fixed::two_pi() * 60_fx;
  const Fixed sag = 9.81_fx / (omega * omega);
  const Fixed slop = w.def().linear_slop;
  const Cubes rested = cubes_of(s);
  for (std::size_t i = 0; i < rested.small.size(); ++i) {
    const BodyState& b = rested.small[i];
    const Fixed half = b.shape.half_extents.y;
    ASSERT_TRUE(test::near(b.position.y, half - slop - sag, sag)) << "small cube " << i;
    ASSERT_TRUE(test::near(b.position.x, start.small[i].position.x, slop)) << "small cube " << i;
    ASSERT_TRUE(test::near(b.position.z, start.small[i].position.z, slop)) << "small cube " << i;
    ASSERT_FALSE(b.awake) << "small cube " << i << " is awake after 2 s at rest";
  }
  EXPECT_FALSE(rested.large[0].awake) << "an idle large cube sleeps too";
  const std::uint64_t bodies = w.hashes().section("bodies");
  for (int f = 0; f < 60; ++f)
    s.step();
  EXPECT_EQ(w.hashes().section("bodies"), bodies) << "a sleeping scene changes nothing";
}

TEST(CubesScenario, TheStickRollsTheLargeCubeIntoTheGridWhereItPushesSmallCubesAbout) {
  // Player 0 starts at the middle of the grid's -z side. The full stick forwards (+z) for 6 s:
  // the large cube crosses the gap and pushes into the grid. Small cubes it hits move by more than
  // their own side; those whose centres are further from its path than it can reach (its widest
  // swing off the mid-line, its bounding radius, and four small sides more for a knocked cube to
  // knock the next) stay asleep and put.
  Scenario s = make();
  World& w = s.world();
  for (int f = 0; f < 60; ++f)
    s.step();  // all asleep first
  const Cubes before = cubes_of(s);
  const BodyState& large = before.large[0];
  Fixed grid_edge = 0_fx;  // the small cubes' most negative z
  for (const BodyState& b : before.small)
    grid_edge = min(grid_edge, b.position.z);
  ASSERT_LT(large.position.z, grid_edge);
  ASSERT_TRUE(test::near(large.position.x, 0_fx, w.def().linear_slop)) << "on the grid's mid-line";
  std::vector<PlayerInput> inputs(1);
  inputs[0].move_z = 127;
  Fixed widest = 0_fx;  // the large cube's furthest from x = 0 on the way
  for (int f = 0; f < 360; ++f) {
    s.step(inputs);
    widest = max(widest, abs(state(w, large.id).position.x));
  }
  const Cubes after = cubes_of(s);
  EXPECT_GT(after.large[0].position.z, grid_edge + 2_fx * bounding_radius(large))
      << "the large cube rolled into the grid";
  const BodyState& some_small = before.small.front();
  const Fixed side = 2_fx * some_small.shape.half_extents.x;
  const Fixed reach = widest + bounding_radius(large) + 4_fx * side;
  int moved = 0;
  int far_moved = 0;
  for (std::size_t i = 0; i < after.small.size(); ++i) {
    const Fixed travelled = length(after.small[i].position - before.small[i].position);
    if (travelled > side) ++moved;
    if (abs(before.small[i].position.x) > reach) {
      far_moved += travelled > w.def().linear_slop ? 1 : 0;
      EXPECT_FALSE(after.small[i].awake) << "small cube " << i << " far from the path woke";
    }
  }
  EXPECT_GE(moved, 10) << "the large cube pushed small cubes about";
  EXPECT_EQ(far_moved, 0);
  // Pushed, not thrown: no small cube is higher than one resting on a large cube on its corner.
  for (const BodyState& b : after.small)
    EXPECT_LT(b.position.y, 2_fx * bounding_radius(large) + bounding_radius(b));
  std::printf(
      "[ cubes ] after 6 s of full stick: the large cube at z %s (grid from %s), %d small "
      "cubes moved by more than a side, reach %s m\n",
      to_string(after.large[0].position.z).c_str(), to_string(grid_edge).c_str(), moved,
      to_string(reach).c_str());
}

TEST(CubesScenario, TheJumpLiftsTheLargeCubeAsADampedThrowAndOnlyFromTheGround) {
  // The jump is an impulse of 6 m/s times the mass, upwards. Under gravity and linear damping c
  // the rise of a throw at v is v / c - g / c^2 ln(1 + c v / g) (1.32 m at 6 m/s and c = 1/s);
  // the discrete steps agree with it within 3 %. At the top the jump button does nothing: the cube
  // is no longer near the ground.
  Scenario s = make();
  World& w = s.world();
  for (int f = 0; f < 60; ++f)
    s.step();
  const BodyId large = s.player_body(0);
  const BodyState rest = state(w, large);
  std::vector<PlayerInput> inputs(1);
  inputs[0].buttons = PlayerInput::jump;
  s.step(inputs);
  const Fixed v = state(w, large).linear_velocity.y;
  EXPECT_GT(v, 5_fx);
  Fixed highest = rest.position.y;
  int top = 0;
  inputs[0].buttons = 0;
  for (int f = 0; f < 60 && top == 0; ++f) {
    s.step(inputs);
    const BodyState b = state(w, large);
    if (b.position.y > highest) {
      highest = b.position.y;
    } else {
      top = f;
    }
  }
  ASSERT_GT(top, 0);
  const double c = rest.linear_damping.to_double();
  const double g = -w.def().gravity.y.to_double();
  const double v0 = 6.0;
  const double rise = v0 / c - g / (c * c) * std::log(1 + c * v0 / g);
  EXPECT_NEAR((highest - rest.position.y).to_double(), rise, 0.03 * rise);
  // At the top: pressing jump gives no second lift.
  inputs[0].buttons = PlayerInput::jump;
  const Fixed before = state(w, large).linear_velocity.y;
  s.step(inputs);
  EXPECT_LT(state(w, large).linear_velocity.y, before) << "no jump in the air";
}

}  // namespace
}  // namespace detsim
