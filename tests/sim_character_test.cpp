// Character controllers (World::create_character): a capsule that walks, climbs steps, keeps to
// the slopes it may walk, slides down those it may not, keeps to the ground walking down slopes,
// rides moving and turning platforms and pushes dynamic bodies with at most its weight.
//
// Expected values come from the geometry and the physics: a free fall is the semi-implicit Euler
// sum y0 - g dt^2 n (n + 1) / 2; a capsule standing on a plane of slope t has its centre
// r / cos t + half_height above the plane's height under it; a ledge is climbed when it is at
// most step_height high; a frictionless slide accelerates at g sin t along the slope; a rider
// keeps its place in the platform's frame; a pushed box on a frictionless floor accelerates at
// most at (character mass) g / (box mass), and friction mu m g above the character's weight holds
// it. The character is state: saved, restored, hashed, named by diff and taken by --inject.
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

#include "support/sim_helpers.hpp"
#include "support/state_codec.hpp"

namespace detsim {
namespace {

using namespace detsim::literals;

using test::add;
using test::add_ground;
using test::make_world;
using test::near;
using test::static_placed;

const Vec3 kZ{0_fx, 0_fx, 1_fx};

CharacterId add_character(World& w, const CharacterDef& def) {
  auto id = w.create_character(def);
  EXPECT_TRUE(id.ok()) << id.message();
  return id.ok() ? *id : CharacterId{};
}

CharacterState character(const World& w, CharacterId id) {
  auto c = w.character(id);
  EXPECT_TRUE(c.ok()) << c.message();
  return c.ok() ? *c : CharacterState{};
}

CharacterDef at(Vec3 position) {
  CharacterDef d;
  d.position = position;
  return d;
}

void walk(World& w, CharacterId id, Vec3 velocity) {
  ASSERT_TRUE(w.set_character_input(id, {velocity, 0_fx}).ok());
}

double to_d(Fixed x) {
  return x.to_double();
}

/// A test's own geometry from doubles (the library never reads a floating-point number).
Fixed fx(double v) {
  return Fixed::from_raw(static_cast<std::int64_t>(std::llround(v * 4294967296.0)));
}

constexpr double kPi = 3.14159265358979323846;

Fixed radians(double degrees) {
  return fx(degrees * kPi / 180);
}

// The centre height of the default capsule (r 0.4, half height 0.5) standing on ground of this
// height: the radius and the half height above it, plus the gap a cast leaves (slop/2 .. slop).
constexpr double kStand = 0.9;

// ---- Falling and standing ----

TEST(Character, FallsAsTheSemiImplicitEulerSumAndLandsOnTheGround) {
  World w = make_world();
  add_ground(w);
  const CharacterId c = add_character(w, at({0_fx, 3_fx, 0_fx}));
  const double g = 9.81;
  const double dt = 1.0 / 60;
  for (int n = 1; n <= 30; ++n) {
    w.step();
    const double expected = 3.0 - g * dt * dt * n * (n + 1) / 2;
    if (expected < kStand + 0.05) break;
    ASSERT_NEAR(to_d(character(w, c).position.y), expected, 1e-6) << "frame " << n;
    ASSERT_FALSE(character(w, c).grounded);
  }
  for (int n = 0; n < 60; ++n)
    w.step();
  const CharacterState s = character(w, c);
  EXPECT_TRUE(s.grounded);
  EXPECT_NEAR(to_d(s.position.y), kStand, 0.001);
  EXPECT_EQ(s.ground_normal, (Vec3{0_fx, 1_fx, 0_fx}));
  EXPECT_FALSE(s.ground_body.is_null());
  EXPECT_EQ(s.velocity, Vec3{}) << "at rest on the ground, it does not creep";
}

// ---- Steps ----

/// The x the character reaches walking at 1.5 m/s for 3 s towards a ledge of `height` whose
/// face is at x = 2, and whether it ends on top of it.
struct StepRun {
  double x = 0;
  double y = 0;
  bool grounded = false;
};

StepRun walk_at_ledge(double height) {
  World w = make_world();
  add_ground(w);
  const Fixed h = fx(height);
  add(w, static_placed(Shape::box({2_fx, h / 2_fx, 2_fx}), {4_fx, h / 2_fx, 0_fx}));
  const CharacterId c = add_character(w, at({0_fx, 1_fx, 0_fx}));
  walk(w, c, {1.5_fx, 0_fx, 0_fx});
  for (int i = 0; i < 180; ++i)
    w.step();
  const CharacterState s = character(w, c);
  return {to_d(s.position.x), to_d(s.position.y), s.grounded};
}

TEST(Character, ClimbsALedgeOfNineTenthsOfItsStepHeightAndStopsAtElevenTenths) {
  const double step = to_d(CharacterDef{}.step_height);
  const double r = to_d(CharacterDef{}.radius);
  const StepRun low = walk_at_ledge(0.9 * step);
  EXPECT_TRUE(low.grounded);
  EXPECT_GT(low.x, 2.0 + r) << "on top of the ledge, past its edge";
  EXPECT_NEAR(low.y, 0.9 * step + kStand, 0.002) << "standing on the ledge's top";
  const StepRun high = walk_at_ledge(1.1 * step);
  EXPECT_TRUE(high.grounded);
  // Held at the ledge's edge: the capsule's round bottom meets the edge at height h, its centre
  // sqrt(r^2 - (r - h)^2) before the face.
  const double h = 1.1 * step;
  EXPECT_NEAR(high.x, 2.0 - std::sqrt(r * r - (r - h) * (r - h)), 0.002);
  EXPECT_NEAR(high.y, kStand, 0.002) << "still on the floor";
}

// ---- Slopes ----

/// A world whose ground is a plane rising towards +x at `degrees`, and a character standing on
/// it above x = 0.
struct SlopeWorld {
  World w = make_world();
  CharacterId c;
  double angle = 0;

  explicit SlopeWorld(double degrees) : angle(degrees * kPi / 180) {
    add_ground(w, from_axis_angle(kZ, radians(degrees)));
    const double r = to_d(CharacterDef{}.radius);
    const double hh = to_d(CharacterDef{}.half_height);
    c = add_character(w, at({0_fx, fx(r / std::cos(angle) + hh + 0.001), 0_fx}));
  }
  /// The centre height of a capsule standing on the slope at x.
  [[nodiscard]] double standing_y(double x) const {
    const double r = to_d(CharacterDef{}.radius);
    const double hh = to_d(CharacterDef{}.half_height);
    return x * std::tan(angle) + r / std::cos(angle) + hh;
  }
};

TEST(Character, WalksUpASlopeFiveDegreesBelowItsMaxSlope) {
  const double max_slope = to_d(CharacterDef{}.max_slope) * 180 / kPi;
  SlopeWorld s(max_slope - 5);
  for (int i = 0; i < 10; ++i)
    s.w.step();
  ASSERT_TRUE(character(s.w, s.c).grounded);
  const double x0 = to_d(character(s.w, s.c).position.x);
  walk(s.w, s.c, {2_fx, 0_fx, 0_fx});
  for (int i = 0; i < 120; ++i) {
    s.w.step();
    ASSERT_TRUE(character(s.w, s.c).grounded) << "frame " << i;
  }
  const CharacterState end = character(s.w, s.c);
  const double x = to_d(end.position.x);
  EXPECT_NEAR(x - x0, 2.0 * 2.0, 0.02) << "its horizontal speed is its input's";
  EXPECT_NEAR(to_d(end.position.y), s.standing_y(x), 0.002) << "on the slope, up it";
}

TEST(Character, SlidesDownASlopeFiveDegreesAboveItsMaxSlopeAtGSinTheta) {
  const double max_slope = to_d(CharacterDef{}.max_slope) * 180 / kPi;
  SlopeWorld s(max_slope + 5);
  walk(s.w, s.c, {2_fx, 0_fx, 0_fx});  // trying to walk up: it does not steer while sliding
  for (int i = 0; i < 10; ++i)
    s.w.step();
  const CharacterState a = character(s.w, s.c);
  ASSERT_TRUE(a.sliding());
  ASSERT_FALSE(a.grounded);
  for (int i = 0; i < 30; ++i)
    s.w.step();
  const CharacterState b = character(s.w, s.c);
  EXPECT_TRUE(b.sliding());
  EXPECT_LT(to_d(b.position.x), to_d(a.position.x)) << "down the slope, not up";
  EXPECT_NEAR(to_d(b.position.y), s.standing_y(to_d(b.position.x)), 0.002) << "on the slope";
  // Along the slope its speed grows by g sin(theta) per second (a frictionless slide).
  const double gain = (to_d(length(b.velocity)) - to_d(length(a.velocity))) / 0.5;
  EXPECT_NEAR(gain, 9.81 * std::sin(s.angle), 0.02 * 9.81 * std::sin(s.angle));
}

TEST(Character, AtTheFootOfASteepSlopeItStandsOnTheFloorAndWalksAway) {
  // A wedge: the floor, and a 60-degree slope rising from x = 0. A character pushed against the
  // slope's foot touches both; it stands on the floor (walkable) and walks away when told to.
  World w = make_world();
  add_ground(w);
  // A box turned -30 degrees about z: its -x face, of normal (-cos 30, sin 30), is the slope; the
  // box's centre 1 / cos 30 beyond x = 0 puts the face's foot there.
  add(w, static_placed(Shape::box({1_fx, 4_fx, 2_fx}), {fx(1 / std::cos(kPi / 6)), 0_fx, 0_fx},
                       from_axis_angle(kZ, radians(-30))));
  const CharacterId c = add_character(w, at({-1_fx, 1_fx, 0_fx}));
  walk(w, c, {2_fx, 0_fx, 0_fx});  // into the slope's foot
  for (int i = 0; i < 60; ++i)
    w.step();
  const CharacterState pressed = character(w, c);
  EXPECT_TRUE(pressed.grounded);
  EXPECT_FALSE(pressed.sliding());
  EXPECT_NEAR(to_d(pressed.position.y), kStand, 0.002) << "on the floor, not up the slope";
  walk(w, c, {-2_fx, 0_fx, 0_fx});
  for (int i = 0; i < 30; ++i)
    w.step();
  EXPECT_NEAR(to_d(character(w, c).position.x), to_d(pressed.position.x) - 1.0, 0.02)
      << "it walks away at its input's speed";
}

TEST(Character, StaysGroundedWalkingDownThirtyDegreesAtFiveMetresASecond) {
  World w = make_world();
  // A floor whose top is y = 0 for x < 0, then a 30-degree slope down towards +x from its edge.
  add(w, static_placed(Shape::box({5_fx, 0.5_fx, 5_fx}), {-5_fx, -0.5_fx, 0_fx}));
  const double t = 30 * kPi / 180;
  const double length_along = 10;
  const Vec3 top_centre{fx(length_along * std::cos(t)), fx(-length_along * std::sin(t)), 0_fx};
  const Vec3 normal{fx(std::sin(t)), fx(std::cos(t)), 0_fx};
  add(w, static_placed(Shape::box({fx(length_along), 0.5_fx, 5_fx}), top_centre - normal * 0.5_fx,
                       from_axis_angle(kZ, radians(-30))));
  const CharacterId c = add_character(w, at({-2_fx, 1_fx, 0_fx}));
  for (int i = 0; i < 30; ++i)
    w.step();
  ASSERT_TRUE(character(w, c).grounded);
  walk(w, c, {5_fx, 0_fx, 0_fx});
  for (int i = 0; i < 90; ++i) {  // 1.5 s: 7.5 m, from x = -2 to 5.5, down the slope from x = 0
    w.step();
    ASSERT_TRUE(character(w, c).grounded)
        << "frame " << i << " at x " << to_d(character(w, c).position.x);
  }
  const CharacterState end = character(w, c);
  const double x = to_d(end.position.x);
  EXPECT_NEAR(x, 5.5, 0.05);
  const double r = to_d(CharacterDef{}.radius);
  const double hh = to_d(CharacterDef{}.half_height);
  EXPECT_NEAR(to_d(end.position.y), -x * std::tan(t) + r / std::cos(t) + hh, 0.002);
}

// ---- Platforms ----

TEST(Character, RidesAPlatformMovingAtThreeMetresASecondAndTurningAtOneRadianASecond) {
  World w = make_world();
  BodyDef p;
  p.type = BodyType::kinematic;
  p.shape = Shape::box({3_fx, 0.25_fx, 3_fx});
  p.linear_velocity = {3_fx, 0_fx, 0_fx};
  p.angular_velocity = {0_fx, 1_fx, 0_fx};
  const BodyId platform = add(w, p);
  const CharacterId c = add_character(w, at({1_fx, 0.25_fx + 0.9_fx + 0.001_fx, 0.5_fx}));
  for (int i = 0; i < 5; ++i)
    w.step();
  ASSERT_TRUE(character(w, c).grounded);
  const auto local = [&] {
    const BodyState b = test::state(w, platform);
    return rotate(conjugate(b.orientation), character(w, c).position - b.position);
  };
  const Vec3 start = local();
  for (int i = 0; i < 180; ++i) {
    w.step();
    const CharacterState s = character(w, c);
    ASSERT_TRUE(s.grounded) << "frame " << i;
    ASSERT_EQ(s.ground_body, platform) << "frame " << i;
  }
  EXPECT_TRUE(test::near_vec(local(), start, 0.002_fx))
      << "after 9 m and 3 rad, where it stood on the platform";
  EXPECT_GT(to_d(character(w, c).position.x), 8.0);
}

// ---- Pushing ----

struct PushRun {
  World w = make_world();
  BodyId box;
  CharacterId c;

  PushRun(Fixed box_mass, Fixed friction) {
    add_ground(w, {}, friction);
    BodyDef b = test::placed(Shape::box({0.5_fx, 0.5_fx, 0.5_fx}), {1.5_fx, 0.5_fx, 0_fx});
    b.mass = box_mass;
    b.friction = friction;
    box = add(w, b);
    c = add_character(w, at({0.598_fx, 1_fx, 0_fx}));
    for (int i = 0; i < 30; ++i)
      w.step();  // both settle
    walk(w, c, {2_fx, 0_fx, 0_fx});
  }
};

TEST(Character, PushesAFrictionlessBoxWithAtMostItsWeight) {
  const Fixed mass = CharacterDef{}.mass;
  PushRun run(mass * 4_fx, 0_fx);
  const double x0 = to_d(test::state(run.w, run.box).position.x);
  for (int i = 0; i < 30; ++i)
    run.w.step();
  // The character closes the 2 mm gap in its first step and pushes in every step after it, each
  // push M g dt: after n pushes the box moves at n M g dt / m (below the character's 2 m/s).
  const double v = to_d(test::state(run.w, run.box).linear_velocity.x);
  const double per_push = 9.81 / 60 / 4;
  EXPECT_GE(v, 28 * per_push);
  EXPECT_LE(v, 30 * per_push + 1e-6) << "never more than its weight";
  EXPECT_GT(to_d(test::state(run.w, run.box).position.x), x0 + 0.1);
}

TEST(Character, CannotMoveABoxWhoseFrictionExceedsItsWeight) {
  const Fixed mass = CharacterDef{}.mass;
  // Friction 0.6 on a box of 4 M: mu m g = 2.4 M g, above the character's M g.
  PushRun run(mass * 4_fx, 0.6_fx);
  const double x0 = to_d(test::state(run.w, run.box).position.x);
  for (int i = 0; i < 120; ++i)
    run.w.step();
  EXPECT_NEAR(to_d(test::state(run.w, run.box).position.x), x0, 0.002);
  const CharacterState s = character(run.w, run.c);
  EXPECT_LT(to_d(s.position.x), 1.0 - 0.39) << "held by the box";
  // A box light enough (mu m g = 0.3 M g) goes: its acceleration is (M - mu m) g / m.
  PushRun light(mass / 2_fx, 0.6_fx);
  const double lx0 = to_d(test::state(light.w, light.box).position.x);
  for (int i = 0; i < 60; ++i)
    light.w.step();
  EXPECT_GT(to_d(test::state(light.w, light.box).position.x), lx0 + 0.5);
}

// ---- State ----

/// A scene with everything a character meets: a ledge, a slope, a platform, a box, and three
/// characters with scripted inputs.
struct Scene {
  World w = make_world();
  std::vector<CharacterId> cs;

  Scene() {
    add_ground(w);
    add(w, static_placed(Shape::box({1_fx, 0.12_fx, 2_fx}), {4_fx, 0.12_fx, 0_fx}));
    add(w, static_placed(Shape::box({2_fx, 0.2_fx, 2_fx}), {-4_fx, 0.5_fx, 0_fx},
                         from_axis_angle(kZ, radians(20))));
    BodyDef p;
    p.type = BodyType::kinematic;
    p.shape = Shape::box({1.5_fx, 0.2_fx, 1.5_fx});
    p.position = {0_fx, 0.2_fx, 5_fx};
    p.linear_velocity = {1_fx, 0_fx, 0_fx};
    p.angular_velocity = {0_fx, 0.5_fx, 0_fx};
    add(w, p);
    add(w, test::placed(Shape::box({0.4_fx, 0.4_fx, 0.4_fx}), {2_fx, 0.4_fx, -3_fx}));
    for (const Vec3 at_ :
         {Vec3{0_fx, 1_fx, 0_fx}, Vec3{0_fx, 1.5_fx, 5_fx}, Vec3{0_fx, 1_fx, -3_fx}})
      cs.push_back(add_character(w, at(at_)));
  }
  void frame(int f) {
    for (std::size_t k = 0; k < cs.size(); ++k) {
      const int phase = (f / 20 + static_cast<int>(k)) % 4;
      const Fixed speeds[] = {2_fx, -1_fx, 0_fx, 1.5_fx};
      CharacterInput in{{speeds[phase], 0_fx, speeds[(phase + 1) % 4]}, 0_fx};
      if (f % 45 == static_cast<int>(k) * 7) in.jump = 4_fx;
      ASSERT_TRUE(w.set_character_input(cs[k], in).ok());
    }
    w.step();
  }
};

TEST(Character, RestoredMidManoeuvreItStepsLikeTheUninterruptedRun) {
  Scene a;
  for (int f = 0; f < 70; ++f)
    a.frame(f);
  const std::vector<std::uint8_t> saved = a.w.save();
  std::vector<StateHashes> expected;
  for (int f = 70; f < 170; ++f) {
    a.frame(f);
    expected.push_back(a.w.hashes());
  }
  Scene b;
  ASSERT_TRUE(b.w.restore(saved).ok());
  for (int f = 70; f < 170; ++f) {
    b.frame(f);
    ASSERT_EQ(b.w.hashes(), expected[static_cast<std::size_t>(f - 70)]) << "frame " << f;
  }
  for (const CharacterId c : a.cs)
    EXPECT_EQ(character(a.w, c), character(b.w, c));
}

TEST(Character, TheCharactersSectionIsWrittenOnlyByAWorldThatHasHadOne) {
  World w = make_world();
  add_ground(w);
  EXPECT_EQ(w.hashes().section("characters"), 0U);
  const CharacterId c = add_character(w, at({0_fx, 1_fx, 0_fx}));
  EXPECT_NE(w.hashes().section("characters"), 0U);
  ASSERT_TRUE(w.destroy_character(c).ok());
  EXPECT_NE(w.hashes().section("characters"), 0U) << "the next ID is state";
  // A state without the section restores to a world without characters.
  World plain = make_world();
  add_ground(plain);
  ASSERT_TRUE(w.restore(plain.save()).ok());
  EXPECT_TRUE(w.character_ids().empty());
  EXPECT_EQ(w.save(), plain.save());
}

TEST(Character, DiffNamesTheFieldAndInjectChangesIt) {
  Scene s;
  for (int f = 0; f < 30; ++f)
    s.frame(f);
  const std::vector<std::uint8_t> before = s.w.save();
  auto injection = parse_injection("30:0:character[2].position.y:0.25");
  ASSERT_TRUE(injection.ok()) << injection.message();
  ASSERT_TRUE(apply_injection(s.w, *injection).ok());
  const StateDiff d = diff_states(s.w, before, s.w.save()).value();
  ASSERT_EQ(d.fields.size(), 1U);
  EXPECT_EQ(d.fields[0].subsystem, "characters");
  EXPECT_EQ(d.fields[0].field, "character[2].position.y");
  // What restore would refuse is refused, and changes nothing.
  const std::vector<std::uint8_t> now = s.w.save();
  EXPECT_FALSE(
      apply_injection(s.w, *parse_injection("30:0:character[1].ground_normal.x:0.5")).ok());
  EXPECT_FALSE(apply_injection(s.w, *parse_injection("30:0:character[9].position.x:1")).ok());
  EXPECT_FALSE(parse_injection("30:3:character[1].position.x:1").ok()) << "BODY must be 0";
  EXPECT_FALSE(parse_injection("30:0:character[1].elbow:1").ok());
  EXPECT_EQ(s.w.save(), now);
}

/// The "characters" section of a state with one character, decoded as docs/STATE.md describes it
/// (offsets are into the whole state).
struct DecodedCharacters {
  std::size_t payload_at = 0;
  std::uint32_t next_id = 0;
  std::uint32_t count = 0;
  std::size_t step_at = 0;
  std::size_t flags_at = 0;
  std::uint8_t flags = 0;
  CharacterState c;
  std::size_t end = 0;
};

DecodedCharacters decode_characters(const std::vector<std::uint8_t>& bytes) {
  DecodedCharacters d;
  const auto sections = read_state_sections(bytes);
  EXPECT_TRUE(sections.ok()) << sections.message();
  if (!sections.ok()) return d;
  for (const StateSection& section : *sections) {
    if (section.name != "characters") continue;
    d.payload_at = section.payload_offset;
    state_test::StateReader r(section.payload);
    d.next_id = r.u32("next character ID");
    d.count = r.u32("character count");
    d.step_at = d.payload_at + r.at();
    d.c.id = CharacterId{static_cast<std::uint32_t>(r.var("ID step", 32))};
    d.flags_at = d.payload_at + r.at();
    d.flags = r.u8("flags");
    const auto vec = [&] {
      const Fixed x = r.vfixed("x");
      const Fixed y = r.vfixed("y");
      return Vec3{x, y, r.vfixed("z")};
    };
    CharacterState& c = d.c;
    c.def.position = vec();
    c.def.radius = r.vfixed("radius");
    c.def.half_height = r.vfixed("half height");
    c.def.max_slope = r.vfixed("max slope");
    c.def.step_height = r.vfixed("step height");
    c.def.mass = r.vfixed("mass");
    c.def.layer = static_cast<std::uint32_t>(r.var("layer", 32));
    c.def.mask = static_cast<std::uint32_t>(r.var("mask", 32));
    c.position = vec();
    c.velocity = vec();
    c.grounded = (d.flags & 1U) != 0;
    c.ground_normal = vec();
    c.ground_body = BodyId{static_cast<std::uint32_t>(r.var("ground body", 32))};
    c.input.desired_velocity = vec();
    c.input.jump = r.vfixed("jump");
    if ((d.flags & 2U) != 0) c.def.user_data = r.var("user data", 64);
    EXPECT_TRUE(r.ok()) << r.error();
    d.end = d.payload_at + r.at();
    EXPECT_EQ(d.end, d.payload_at + section.payload.size()) << "the section ends there";
  }
  return d;
}

TEST(Character, TheSectionIsAsDocumentedAndRestoreRefusesEachBadField) {
  World w = make_world();
  add_ground(w);
  CharacterDef def = at({0_fx, 1_fx, 0_fx});
  def.user_data = 77;
  const CharacterId id = add_character(w, def);
  walk(w, id, {1_fx, 0_fx, -0.5_fx});
  for (int i = 0; i < 40; ++i)
    w.step();
  const std::vector<std::uint8_t> good = w.save();
  const DecodedCharacters d = decode_characters(good);
  EXPECT_EQ(d.next_id, 2U);
  EXPECT_EQ(d.count, 1U);
  EXPECT_EQ(d.c, character(w, id)) << "the bytes hold exactly the character's state";

  const auto refused = [&](std::vector<std::uint8_t> bad, const std::string& what) {
    World copy = w;
    const Status st = copy.restore(bad);
    ASSERT_FALSE(st.ok()) << what;
    EXPECT_NE(st.message().find(what), std::string::npos) << st.message();
    EXPECT_EQ(copy.save(), good) << "a refused state changes nothing";
  };
  std::vector<std::uint8_t> bad = good;
  bad[d.payload_at] = 1;  // next character ID 1: a world without characters has no section
  refused(bad, "next character ID");
  bad = good;
  bad[d.payload_at + 4] = 9;  // nine characters in the bytes of one
  refused(bad, "character count");
  bad = good;
  bad[d.step_at] = 0;  // ID 0
  refused(bad, "character ID step");
  bad = good;
  bad[d.flags_at] |= 0x80;
  refused(bad, "character flags");
  bad = good;
  bad[d.flags_at] &= static_cast<std::uint8_t>(~2U);  // user data not flagged: a byte left over
  refused(bad, "unexpected bytes");
  // Standing on nothing: the character's ground body is its record's last var but for the input
  // and user data; rebuilt from the decoded state with ground body 0.
  CharacterState in_air = d.c;
  in_air.ground_body = {};
  in_air.ground_normal = {};
  ASSERT_TRUE(in_air.grounded);
  {
    ByteWriter rec;
    rec.var(1);
    rec.u8(d.flags);
    rec.var_vec3(in_air.def.position);
    for (const Fixed f : {in_air.def.radius, in_air.def.half_height, in_air.def.max_slope,
                          in_air.def.step_height, in_air.def.mass})
      rec.var_fixed(f);
    rec.var(in_air.def.layer);
    rec.var(in_air.def.mask);
    rec.var_vec3(in_air.position);
    rec.var_vec3(in_air.velocity);
    rec.var_vec3(in_air.ground_normal);
    rec.var(in_air.ground_body.value);
    rec.var_vec3(in_air.input.desired_velocity);
    rec.var_fixed(in_air.input.jump);
    rec.var(in_air.def.user_data);
    std::vector<std::uint8_t> spliced(good.begin(),
                                      good.begin() + static_cast<std::ptrdiff_t>(d.step_at));
    spliced.insert(spliced.end(), rec.bytes().begin(), rec.bytes().end());
    spliced.insert(spliced.end(), good.begin() + static_cast<std::ptrdiff_t>(d.end), good.end());
    // The section's payload length (the u32 before the payload) follows the record's new size.
    const std::uint32_t length = static_cast<std::uint32_t>(d.end - d.payload_at) -
                                 static_cast<std::uint32_t>(d.end - d.step_at) +
                                 static_cast<std::uint32_t>(rec.bytes().size());
    for (std::size_t k = 0; k < 4; ++k)
      spliced[d.payload_at - 4 + k] = static_cast<std::uint8_t>(length >> (8 * k));
    refused(spliced, "grounded without a ground body");
  }
}

TEST(Character, BadDefinitionsAndInputsAreRefusedNamingTheField) {
  World w = make_world();
  const std::vector<std::uint8_t> empty = w.save();
  const auto refused = [&](CharacterDef d, const char* field) {
    auto id = w.create_character(d);
    ASSERT_FALSE(id.ok()) << field;
    EXPECT_NE(id.message().find(field), std::string::npos) << id.message();
  };
  CharacterDef d;
  d.radius = 0_fx;
  refused(d, "radius");
  d = {};
  d.half_height = -1_fx;
  refused(d, "half_height");
  d = {};
  d.max_slope = Fixed::half_pi();
  refused(d, "max_slope");
  d = {};
  d.step_height = 2_fx;
  refused(d, "step_height");
  d = {};
  d.mass = 0_fx;
  refused(d, "mass");
  d = {};
  d.position = {Fixed::from_int(1 << 30) + 1_fx, 0_fx, 0_fx};
  refused(d, "position");
  EXPECT_EQ(w.save(), empty) << "a refused character changes nothing";
  const CharacterId c = add_character(w, {});
  EXPECT_EQ(c.value, 1U) << "refusals use up no ID";
  EXPECT_FALSE(w.set_character_input(c, {{}, -1_fx}).ok());
  EXPECT_FALSE(w.set_character_input(c, {{Fixed::from_int(1 << 20), 0_fx, 0_fx}, 0_fx}).ok());
  EXPECT_FALSE(w.set_character_input(CharacterId{7}, {}).ok());
  EXPECT_FALSE(w.character(CharacterId{7}).ok());
  EXPECT_FALSE(w.destroy_character(CharacterId{7}).ok());
  EXPECT_EQ(character(w, c).input, CharacterInput{});
}

TEST(Character, AJumpIsAppliedOnceAndRisesAsTheEulerSum) {
  World w = make_world();
  add_ground(w);
  const CharacterId c = add_character(w, at({0_fx, 1_fx, 0_fx}));
  for (int i = 0; i < 30; ++i)
    w.step();
  const double y0 = to_d(character(w, c).position.y);
  ASSERT_TRUE(w.set_character_input(c, {{}, 5_fx}).ok());
  w.step();
  EXPECT_EQ(character(w, c).input.jump, 0_fx) << "the step clears it";
  EXPECT_FALSE(character(w, c).grounded);
  // Up at 5 m/s for one step, then gravity: after n steps, 5 n dt - g dt^2 n (n - 1) / 2.
  for (int n = 2; n <= 20; ++n) {
    w.step();
    const double dt = 1.0 / 60;
    EXPECT_NEAR(to_d(character(w, c).position.y) - y0,
                5 * n * dt - 9.81 * dt * dt * n * (n - 1) / 2, 1e-6)
        << "step " << n;
  }
}

}  // namespace
}  // namespace detsim
