// The World's API: creation, validation of definitions (clear errors, world unchanged), IDs and
// their order, adding and removing bodies mid-run, type switches, inputs, filtering and sleep.
#include <string>
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

BodyDef box_at(Fixed x, Fixed y, Fixed z) {
  BodyDef d;
  d.shape = Shape::box({0.5_fx, 0.5_fx, 0.5_fx});
  d.position = {x, y, z};
  return d;
}

bool contains_text(const std::string& haystack, const std::string& needle) {
  return haystack.find(needle) != std::string::npos;
}

TEST(SimWorld, InvalidWorldDefinitionsAreRefusedWithTheFieldNamed) {
  struct Case {
    WorldDef def;
    const char* field;
  };
  std::vector<Case> cases;
  WorldDef d;
  d.dt = 0_fx;
  cases.push_back({d, "dt"});
  d = {};
  d.substeps = 0;
  cases.push_back({d, "substeps"});
  d = {};
  d.iterations = 65;
  cases.push_back({d, "iterations"});
  d = {};
  d.max_linear_speed = -1_fx;
  cases.push_back({d, "max linear speed"});
  d = {};
  d.contact_hertz = 0_fx;
  cases.push_back({d, "contact hertz"});
  d = {};
  d.linear_slop = -0.1_fx;
  cases.push_back({d, "linear slop"});
  d = {};
  d.gravity = {0_fx, -1000000_fx, 0_fx};
  cases.push_back({d, "gravity"});
  for (const Case& c : cases) {
    const auto w = World::create(c.def);
    ASSERT_FALSE(w.ok()) << c.field;
    EXPECT_TRUE(contains_text(w.message(), c.field)) << w.message();
  }
  EXPECT_TRUE(World::create(WorldDef{}).ok());
}

TEST(SimWorld, InvalidBodyDefinitionsAreRefusedAndChangeNothing) {
  World w = make_world();
  add_ground(w);
  add(w, box_at(0_fx, 1_fx, 0_fx));
  const std::vector<std::uint8_t> before = w.save();
  struct Case {
    BodyDef def;
    const char* expect;
  };
  std::vector<Case> cases;
  BodyDef d;
  d.shape = Shape::sphere(0_fx);
  cases.push_back({d, "sphere radius must be > 0"});
  d = {};
  d.shape = Shape::box({1_fx, -1_fx, 1_fx});
  cases.push_back({d, "box half extent y"});
  d = {};
  d.shape = Shape::capsule(0.5_fx, -1_fx);
  cases.push_back({d, "capsule half height"});
  d = {};
  d.shape = Shape::plane();
  cases.push_back({d, "plane shape needs a static body"});
  d = {};
  d.orientation = Quat{1_fx, 1_fx, 0_fx, 0_fx};
  cases.push_back({d, "unit quaternion"});
  d = {};
  d.mass = -1_fx;
  cases.push_back({d, "mass must be >= 0"});
  d = {};
  d.density = 0_fx;
  cases.push_back({d, "positive mass"});
  d = {};
  d.restitution = 1.5_fx;
  cases.push_back({d, "restitution must be <= 1"});
  d = {};
  d.friction = -0.5_fx;
  cases.push_back({d, "friction"});
  d = {};
  d.shape = Shape::box({0.0001_fx, 0.0001_fx, 0.0001_fx});
  d.mass = 0.000001_fx;
  cases.push_back({d, "inertia"});
  d = {};
  d.type = static_cast<BodyType>(7);
  cases.push_back({d, "unknown body type"});
  d = {};
  // 9 is the compound now, and 7 and 8 are taken by meshes and heightfields: a value far above.
  d.shape.type = static_cast<ShapeType>(200);
  cases.push_back({d, "unknown shape type"});
  for (const Case& c : cases) {
    const auto id = w.create_body(c.def);
    ASSERT_FALSE(id.ok()) << c.expect;
    EXPECT_TRUE(contains_text(id.message(), c.expect)) << id.message();
  }
  EXPECT_EQ(w.save(), before) << "a refused body must leave the world untouched";
  // The next valid body still gets the next ID: refusals consume none.
  EXPECT_EQ(add(w, box_at(3_fx, 1_fx, 0_fx)).value, 3U);
}

TEST(SimWorld, IdsAreSequentialNeverReusedAndListedAscending) {
  World w = make_world();
  const BodyId a = add(w, box_at(0_fx, 1_fx, 0_fx));
  const BodyId b = add(w, box_at(2_fx, 1_fx, 0_fx));
  const BodyId c = add(w, box_at(4_fx, 1_fx, 0_fx));
  EXPECT_EQ(a.value, 1U);
  EXPECT_EQ(b.value, 2U);
  EXPECT_EQ(c.value, 3U);
  ASSERT_TRUE(w.destroy_body(b).ok());
  EXPECT_FALSE(w.contains(b));
  const BodyId d = add(w, box_at(6_fx, 1_fx, 0_fx));
  EXPECT_EQ(d.value, 4U) << "IDs are never reused";
  EXPECT_EQ(w.body_ids(), (std::vector<BodyId>{a, c, d}));
  EXPECT_FALSE(w.destroy_body(b).ok());
  EXPECT_TRUE(contains_text(w.destroy_body(BodyId{99}).message(), "99"));
  EXPECT_FALSE(w.body(BodyId{}).ok());
  EXPECT_FALSE(w.apply_force(BodyId{42}, {1_fx, 0_fx, 0_fx}).ok());
}

TEST(SimWorld, BodiesCanBeAddedAndRemovedMidRunDeterministically) {
  const auto run = [] {
    World w = make_world();
    add_ground(w);
    std::vector<std::uint64_t> hashes;
    for (int frame = 0; frame < 240; ++frame) {
      if (frame % 20 == 0) add(w, box_at(Fixed::from_int(frame % 3), 3_fx, 0_fx));
      if (frame % 50 == 49) {
        EXPECT_TRUE(w.destroy_body(w.body_ids()[1]).ok());
      }
      w.step();
      hashes.push_back(w.hashes().total);
    }
    return hashes;
  };
  EXPECT_EQ(run(), run());
}

TEST(SimWorld, SwitchingKinematicAndDynamicKeepsTheVelocity) {
  WorldDef def;
  def.gravity = {};
  World w = make_world(def);
  BodyDef d = box_at(0_fx, 0_fx, 0_fx);
  d.type = BodyType::kinematic;
  d.linear_velocity = {1_fx, 2_fx, 0_fx};
  d.angular_velocity = {0_fx, 0.5_fx, 0_fx};
  const BodyId id = add(w, d);
  EXPECT_GT(w.body(id)->mass, 0_fx) << "a kinematic body keeps the mass it would have when dynamic";
  w.step();
  ASSERT_TRUE(w.set_type(id, BodyType::dynamic).ok());
  EXPECT_EQ(w.body(id)->linear_velocity, d.linear_velocity);
  EXPECT_EQ(w.body(id)->angular_velocity, d.angular_velocity);
  w.step();
  ASSERT_TRUE(w.set_type(id, BodyType::kinematic).ok());
  EXPECT_EQ(w.body(id)->linear_velocity, d.linear_velocity) << "no gravity, no contact: unchanged";
  const Vec3 before = w.body(id)->position;
  w.step();
  // A kinematic body moves by its velocity: dt * v, rounded per sub-step.
  const Vec3 moved = w.body(id)->position - before;
  EXPECT_LE(abs(moved.x - w.def().dt), Fixed::from_raw(8));
  EXPECT_LE(abs(moved.y - 2_fx * w.def().dt), Fixed::from_raw(8));
  ASSERT_TRUE(w.set_type(id, BodyType::static_body).ok());
  EXPECT_EQ(w.body(id)->linear_velocity, Vec3{});
  BodyDef plane;
  plane.type = BodyType::static_body;
  plane.shape = Shape::plane();
  const BodyId p = add(w, plane);
  EXPECT_FALSE(w.set_type(p, BodyType::dynamic).ok()) << "a plane must stay static";
}

TEST(SimWorld, ImpulsesChangeVelocityByImpulseOverMass) {
  WorldDef def;
  def.gravity = {};
  World w = make_world(def);
  BodyDef d = box_at(0_fx, 0_fx, 0_fx);
  d.mass = 4_fx;
  const BodyId id = add(w, d);
  ASSERT_TRUE(w.apply_linear_impulse(id, {8_fx, 0_fx, -2_fx}).ok());
  EXPECT_EQ(w.body(id)->linear_velocity, (Vec3{2_fx, 0_fx, -0.5_fx}));
  // An impulse at a point above the centre also spins the body: dw = I^-1 (r x J). A 1 m cube of
  // 4 kg has I = m (1^2 + 1^2) / 12 = 2/3 on every axis; r = (0, 0.5, 0), J = (1, 0, 0):
  // r x J = (0, 0, -0.5), so dw_z = -0.75 rad/s.
  ASSERT_TRUE(w.apply_impulse_at_point(id, {1_fx, 0_fx, 0_fx}, {0_fx, 0.5_fx, 0_fx}).ok());
  EXPECT_LE(abs(w.body(id)->angular_velocity.z + 0.75_fx), Fixed::from_raw(16));
  EXPECT_EQ(w.body(id)->linear_velocity.x, 2.25_fx);
}

TEST(SimWorld, UserDataIsSetSavedAndHashedWithoutWakingTheBody) {
  World w = make_world();
  add_ground(w);
  BodyDef d = box_at(0_fx, 0.5_fx, 0_fx);
  d.user_data = 7;
  const BodyId box = add(w, d);
  for (int i = 0; i < 120; ++i)
    w.step();
  ASSERT_FALSE(w.body(box)->awake);
  const std::uint64_t before = w.hashes().total;
  const std::vector<std::uint8_t> saved = w.save();
  ASSERT_TRUE(w.set_user_data(box, 0xFEED'0000'0000'0042ULL).ok());
  EXPECT_EQ(w.body(box)->user_data, 0xFEED'0000'0000'0042ULL);
  EXPECT_FALSE(w.body(box)->awake) << "a tag is not a push";
  EXPECT_NE(w.hashes().total, before) << "the game's tag is part of the state peers compare";
  const std::vector<std::uint8_t> tagged = w.save();
  ASSERT_TRUE(w.restore(saved).ok());
  EXPECT_EQ(w.body(box)->user_data, 7U);
  ASSERT_TRUE(w.restore(tagged).ok());
  EXPECT_EQ(w.body(box)->user_data, 0xFEED'0000'0000'0042ULL);
  const Status unknown = w.set_user_data(BodyId{999}, 1);
  EXPECT_FALSE(unknown.ok());
  EXPECT_TRUE(contains_text(unknown.message(), "999")) << unknown.message();
  EXPECT_EQ(w.save(), tagged) << "a refusal changes nothing";
}

TEST(SimWorld, LayersAndMasksFilterCollisions) {
  World w = make_world();
  BodyDef ground;
  ground.type = BodyType::static_body;
  ground.shape = Shape::plane();
  ground.layer = 0b01;
  add(w, ground);
  BodyDef ghost = box_at(0_fx, 2_fx, 0_fx);
  ghost.mask = 0b10;  // does not collide with layer 1
  const BodyId through = add(w, ghost);
  const BodyId stops = add(w, box_at(3_fx, 2_fx, 0_fx));
  for (int i = 0; i < 120; ++i)
    w.step();
  EXPECT_LT(w.body(through)->position.y, -5_fx) << "filtered out: falls through the ground";
  EXPECT_GT(w.body(stops)->position.y, 0.4_fx) << "not filtered: rests on the ground";
}

TEST(SimSleep, RestingBodiesSleepAndAnImpulseWakesThem) {
  World w = make_world();
  add_ground(w);
  const BodyId box = add(w, box_at(0_fx, 0.5_fx, 0_fx));
  for (int i = 0; i < 120; ++i)
    w.step();
  ASSERT_FALSE(w.body(box)->awake);
  const std::uint64_t asleep = w.hashes().total;
  const Vec3 position = w.body(box)->position;
  w.step();
  EXPECT_EQ(w.body(box)->position, position) << "a sleeping body does not move";
  EXPECT_NE(w.hashes().total, asleep) << "the frame counter still advances";
  ASSERT_TRUE(w.apply_linear_impulse(box, {0_fx, 5000_fx, 0_fx}).ok());
  EXPECT_TRUE(w.body(box)->awake);
  w.step();
  EXPECT_GT(w.body(box)->position.y, 0.5_fx);
}

TEST(SimSleep, RemovingTheSupportWakesWhatRestedOnIt) {
  World w = make_world();
  add_ground(w);
  const BodyId bottom = add(w, box_at(0_fx, 0.5_fx, 0_fx));
  const BodyId top = add(w, box_at(0_fx, 1.5_fx, 0_fx));
  for (int i = 0; i < 180; ++i)
    w.step();
  ASSERT_FALSE(w.body(top)->awake);
  const Fixed rested = w.body(top)->position.y;
  ASSERT_TRUE(w.destroy_body(bottom).ok());
  EXPECT_TRUE(w.body(top)->awake);
  for (int i = 0; i < 60; ++i)
    w.step();
  EXPECT_LT(w.body(top)->position.y, rested - 0.5_fx) << "it fell onto the ground";
}

TEST(SimSleep, AFallingBodyWakesASleepingPile) {
  World w = make_world();
  add_ground(w);
  const BodyId resting = add(w, box_at(0_fx, 0.5_fx, 0_fx));
  for (int i = 0; i < 120; ++i)
    w.step();
  ASSERT_FALSE(w.body(resting)->awake);
  add(w, box_at(0.3_fx, 4_fx, 0_fx));
  bool woke = false;
  for (int i = 0; i < 90 && !woke; ++i) {
    w.step();
    woke = w.body(resting)->awake;
  }
  EXPECT_TRUE(woke) << "the impact must wake the body it lands on";
}

}  // namespace
}  // namespace detsim
