// Joints (work in progress, docs/JOINTS-WIP.md): the API's promises (refusals name the field and
// change nothing, IDs ascend, a destroyed body takes its joints along) and the physics of the
// solved joint types, with expectations derived from formulas (stated beside each), never from a
// previous run's output.
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

#include "support/sim_helpers.hpp"

namespace detsim {
namespace {

using namespace detsim::literals;

using test::add;
using test::make_world;
using test::near;
using test::state;

BodyDef ball_at(Vec3 p, Fixed radius = 0.1_fx, Fixed mass = 1_fx) {
  BodyDef d;
  d.shape = Shape::sphere(radius);
  d.position = p;
  d.mass = mass;
  return d;
}

BodyDef anchor_at(Vec3 p) {
  BodyDef d = ball_at(p);
  d.type = BodyType::static_body;
  return d;
}

JointId join(World& w, const JointDef& def) {
  auto id = w.create_joint(def);
  EXPECT_TRUE(id.ok()) << id.message();
  return id.ok() ? *id : JointId{};
}

// ---- The API ----

struct Refusal {
  const char* field;  // what the message must name
  JointDef def;
};

TEST(SimJoint, RefusesInvalidDefinitionsNamingTheFieldAndChangesNothing) {
  World w = make_world();
  const BodyId ground = add(w, anchor_at({0_fx, 5_fx, 0_fx}));
  const BodyId other_static = add(w, anchor_at({3_fx, 5_fx, 0_fx}));
  const BodyId ball = add(w, ball_at({0_fx, 3_fx, 0_fx}));
  JointDef good;
  good.body_a = ground;
  good.body_b = ball;
  good.anchor = {0_fx, 5_fx, 0_fx};
  const JointId first = join(w, good);
  const std::vector<std::uint8_t> before = w.save();

  std::vector<Refusal> cases;
  const auto with = [&](const char* field, auto change) {
    JointDef d = good;
    change(d);
    cases.push_back({field, d});
  };
  with("body_a", [](JointDef& d) { d.body_a = BodyId{}; });
  with("body_a", [](JointDef& d) { d.body_a = BodyId{99}; });
  with("body_b", [](JointDef& d) { d.body_b = BodyId{42}; });
  with("body_a and body_b", [&](JointDef& d) { d.body_a = ball; });
  with("both static", [&](JointDef& d) { d.body_b = other_static; });
  with("axis", [](JointDef& d) { d.axis = {}; });
  with("axis", [](JointDef& d) { d.axis = {1_fx, 1_fx, 0_fx}; });
  with("limit_lower", [](JointDef& d) {
    d.limit_lower = 1_fx;
    d.limit_upper = -1_fx;
  });
  with("swing_limit", [](JointDef& d) { d.swing_limit = -0.5_fx; });
  with("motor_max_force", [](JointDef& d) { d.motor_max_force = -1_fx; });
  with("min_length", [](JointDef& d) { d.min_length = -1_fx; });
  with("max_length", [](JointDef& d) { d.max_length = -1_fx; });
  with("min_length", [](JointDef& d) {
    d.min_length = 2_fx;
    d.max_length = 1_fx;
  });
  with("spring_frequency", [](JointDef& d) { d.spring_frequency = -1_fx; });
  with("spring_damping_ratio", [](JointDef& d) { d.spring_damping_ratio = -1_fx; });
  with("break_force", [](JointDef& d) { d.break_force = -1_fx; });
  with("break_torque", [](JointDef& d) { d.break_torque = -1_fx; });
  with("anchor", [](JointDef& d) { d.anchor = {0_fx, Fixed::max(), 0_fx}; });

  for (const Refusal& r : cases) {
    auto id = w.create_joint(r.def);
    ASSERT_FALSE(id.ok()) << "expected a refusal naming " << r.field;
    EXPECT_NE(id.message().find(r.field), std::string::npos)
        << "the message must name " << r.field << ": " << id.message();
    EXPECT_EQ(w.save(), before) << r.field;
    EXPECT_EQ(w.joint_ids(), std::vector<JointId>{first}) << r.field;
  }
}

TEST(SimJoint, IdsAscendInCreationOrderAndAreNeverReused) {
  World w = make_world();
  const BodyId ground = add(w, anchor_at({0_fx, 5_fx, 0_fx}));
  std::vector<BodyId> balls;
  for (std::int32_t i = 0; i < 3; ++i)
    balls.push_back(add(w, ball_at({Fixed::from_int(i), 3_fx, 0_fx})));
  JointDef d;
  d.body_a = ground;
  d.anchor = {0_fx, 5_fx, 0_fx};
  std::vector<JointId> ids;
  for (const BodyId b : balls) {
    d.body_b = b;
    ids.push_back(join(w, d));
  }
  EXPECT_EQ(ids, (std::vector<JointId>{{1}, {2}, {3}}));
  EXPECT_EQ(w.joint_ids(), ids);
  EXPECT_TRUE(w.destroy_joint(ids[1]).ok());
  EXPECT_FALSE(w.destroy_joint(ids[1]).ok());
  EXPECT_FALSE(w.joint(ids[1]).ok());
  d.body_b = balls[1];
  EXPECT_EQ(join(w, d), JointId{4});  // never reused
  EXPECT_EQ(w.joint_ids(), (std::vector<JointId>{{1}, {3}, {4}}));
  // The state keeps the definition and the anchor in each body's frame.
  const JointState j = *w.joint(JointId{4});
  EXPECT_EQ(j.def.body_b, balls[1]);
  EXPECT_EQ(j.local_anchor_a, Vec3{});
  EXPECT_EQ(j.local_anchor_b, (Vec3{-1_fx, 2_fx, 0_fx}));
  EXPECT_FALSE(j.broken);
}

TEST(SimJoint, DestroyingABodyRemovesItsJoints) {
  World w = make_world();
  const BodyId ground = add(w, anchor_at({0_fx, 5_fx, 0_fx}));
  const BodyId a = add(w, ball_at({0_fx, 4_fx, 0_fx}));
  const BodyId b = add(w, ball_at({0_fx, 3_fx, 0_fx}));
  JointDef d;
  d.body_a = ground;
  d.body_b = a;
  d.anchor = {0_fx, 5_fx, 0_fx};
  const JointId top = join(w, d);
  d.body_a = a;
  d.body_b = b;
  d.anchor = {0_fx, 3.5_fx, 0_fx};
  const JointId middle = join(w, d);
  d.body_a = ground;
  d.anchor = {0_fx, 5_fx, 0_fx};
  const JointId side = join(w, d);
  EXPECT_TRUE(w.destroy_body(a).ok());
  EXPECT_EQ(w.joint_ids(), std::vector<JointId>{side});
  EXPECT_FALSE(w.joint(top).ok());
  EXPECT_FALSE(w.joint(middle).ok());
}

}  // namespace
}  // namespace detsim
