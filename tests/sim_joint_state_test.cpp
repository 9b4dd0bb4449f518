// Joints in the canonical state (docs/STATE.md, section "joints"): the bytes are what the layout
// says (checked with the independent codec, support/state_codec.hpp), a restored world steps like
// the uninterrupted one for every joint type mid-motion, every bad field is refused naming it with
// the world unchanged, and the tools built on the state (hashes, diff, --inject) see joints.
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <detsim/sim/inject.hpp>
#include <detsim/sim/state_diff.hpp>

#include "support/state_helpers.hpp"

namespace detsim::state_test {
namespace {

constexpr JointType kTypes[] = {JointType::ball,  JointType::hinge,    JointType::slider,
                                JointType::fixed, JointType::distance, JointType::swing_twist};

const char* type_name(JointType t) {
  switch (t) {
    case JointType::ball:
      return "ball";
    case JointType::hinge:
      return "hinge";
    case JointType::slider:
      return "slider";
    case JointType::fixed:
      return "fixed";
    case JointType::distance:
      return "distance";
    case JointType::swing_twist:
      return "swing_twist";
  }
  return "?";
}

JointId join(World& w, const JointDef& def) {
  const Expected<JointId> id = w.create_joint(def);
  EXPECT_TRUE(id.ok()) << id.message();
  return id.ok() ? id.value() : JointId{};
}

/// A static post and, hanging from it, two boxes joined by `type` (post to first box, first box to
/// second), each with the options that type has (limits, motor, spring, break force), set moving
/// by seeded random velocities so that every impulse is in use. Boxes, not spheres, so that every
/// rotation matters. Also a box on the ground beside them, for contacts.
struct Scene {
  World world;
  std::vector<JointId> joints;
};

Scene joint_scene(JointType type, std::uint64_t seed) {
  WorldDef def;
  def.seed = seed;
  Scene s{make_world(def), {}};
  World& w = s.world;
  BodyDef ground;
  ground.type = BodyType::static_body;
  ground.shape = Shape::plane();
  add(w, ground);
  BodyDef post;
  post.type = BodyType::static_body;
  post.shape = Shape::box({0.1_fx, 0.1_fx, 0.1_fx});
  post.position = {0_fx, 6_fx, 0_fx};
  const BodyId top = add(w, post);
  Rng rng(seed);
  const auto random = [&](Fixed scale) {
    return Vec3{rng.uniform(-scale, scale), rng.uniform(-scale, scale), rng.uniform(-scale, scale)};
  };
  BodyId previous = top;
  Vec3 anchor = post.position;
  for (int k = 0; k < 2; ++k) {
    BodyDef box;
    box.shape = Shape::box({0.2_fx, 0.3_fx, 0.15_fx});
    box.mass = 2_fx;
    box.position = anchor - Vec3{0_fx, 1_fx, 0_fx};
    box.linear_velocity = random(2_fx);
    box.angular_velocity = random(3_fx);
    const BodyId id = add(w, box);
    JointDef j;
    j.type = type;
    j.body_a = previous;
    j.body_b = id;
    j.anchor = anchor;
    j.axis = normalize(Vec3{1_fx, 0_fx, 1_fx});
    j.user_data = k == 0 ? 0 : 0xABCDEF0123ULL;
    switch (type) {
      case JointType::hinge:
      case JointType::slider:
        j.limit_enabled = true;
        j.limit_lower = -0.5_fx;
        j.limit_upper = 0.375_fx;
        j.motor_enabled = k == 1;
        j.motor_speed = 1_fx;
        j.motor_max_force = 5_fx;
        break;
      case JointType::swing_twist:
        j.limit_enabled = true;
        j.swing_limit = 0.5_fx;
        j.limit_lower = -0.25_fx;
        j.limit_upper = 0.25_fx;
        break;
      case JointType::distance:
        if (k == 0) {
          j.min_length = 0.5_fx;
          j.max_length = 1.25_fx;
        } else {
          j.spring_frequency = 2_fx;
          j.spring_damping_ratio = 0.1_fx;
        }
        break;
      case JointType::fixed:
        j.break_force = 100000_fx;
        j.break_torque = 100000_fx;
        break;
      case JointType::ball:
        j.collide_connected = k == 1;
        break;
    }
    s.joints.push_back(join(w, j));
    previous = id;
    anchor = box.position - Vec3{0_fx, 0.3_fx, 0_fx};
  }
  BodyDef crate;
  crate.shape = Shape::box({0.5_fx, 0.5_fx, 0.5_fx});
  crate.position = {3_fx, 0.5_fx, 0_fx};
  add(w, crate);
  return s;
}

std::vector<StateHashes> run_hashes(World& w, int frames) {
  std::vector<StateHashes> out;
  for (int f = 0; f < frames; ++f) {
    w.step();
    out.push_back(w.hashes());
  }
  return out;
}

// ---- The bytes ----

TEST(JointState, TheBytesAreWhatTheLayoutSays) {
  for (const JointType type : kTypes) {
    Scene s = joint_scene(type, 7);
    run(s.world, 40);
    const Bytes bytes = s.world.save();
    const Decoded d = decode(bytes);
    ASSERT_TRUE(d.ok) << type_name(type) << ": " << d.error;
    ASSERT_EQ(d.joints.size(), 2U);
    // Four bodies and a crate: the next body ID is 6; two joints: the next joint ID is 3.
    const Decoded expected = expected_encoding(s.world, 6, 3);
    EXPECT_TRUE(encode(expected) == bytes) << type_name(type);
    EXPECT_EQ(encode(d), bytes);
    // The joints' impulses are in use (the scene moves), so the test compares real values.
    const JointState j = s.world.joint(s.joints[0]).value();
    EXPECT_TRUE(j.linear_impulse != Vec3{} || j.axial_impulse != Fixed::zero()) << type_name(type);
    EXPECT_EQ(d.joints[1].user_data, 0xABCDEF0123ULL);
    EXPECT_EQ(d.joints[1].flags & kJointHasUserData, kJointHasUserData);
  }
}

TEST(JointState, HashesSeeJointsAndTheirSectionAlone) {
  Scene with = joint_scene(JointType::ball, 3);
  Scene without = joint_scene(JointType::ball, 3);
  ASSERT_TRUE(without.world.destroy_joint(without.joints[1]).ok());
  // Destroying the joint woke nothing that was asleep (all awake): only the joints differ.
  const StateHashes a = with.world.hashes();
  const StateHashes b = without.world.hashes();
  EXPECT_NE(a.total, b.total);
  EXPECT_NE(a.section("joints"), b.section("joints"));
  EXPECT_EQ(a.section("bodies"), b.section("bodies"));
  EXPECT_EQ(a.section("contacts"), b.section("contacts"));
  EXPECT_EQ(differing_subsystems(a, b), std::vector<std::string>{"joints"});
}

// ---- Restore equals the uninterrupted run ----

TEST(JointState, RestoredMidMotionStepsLikeTheUninterruptedRunForEveryType) {
  for (const JointType type : kTypes) {
    for (const std::uint64_t seed : {1U, 2U}) {
      Scene s = joint_scene(type, seed);
      // A random frame in 20..199 (seeded), mid-motion.
      Rng pick(seed * 31 + static_cast<std::uint64_t>(type));
      const int at = 20 + static_cast<int>(pick.next_u64() % 180);
      run(s.world, static_cast<std::uint64_t>(at));
      const Bytes saved = s.world.save();
      const Vec3 saved_at = s.world.body(BodyId{4}).value().position;
      World restored;
      ASSERT_TRUE(restored.restore(saved).ok());
      EXPECT_TRUE(restored.save() == saved);
      for (const JointId id : s.joints)
        EXPECT_EQ(restored.joint(id).value(), s.world.joint(id).value());
      const std::vector<StateHashes> expected = run_hashes(s.world, 300);
      const std::vector<StateHashes> got = run_hashes(restored, 300);
      for (std::size_t f = 0; f < expected.size(); ++f) {
        ASSERT_EQ(got[f], expected[f]) << type_name(type) << " seed " << seed << ": saved at " << at
                                       << ", differs " << f + 1 << " frames later";
      }
      // The scene moved on after the save (the comparison was not of two resting worlds).
      EXPECT_NE(s.world.body(BodyId{4}).value().position, saved_at) << type_name(type);
    }
  }
}

TEST(JointState, AJointWhoseBodiesBothBecameStaticIsRestorable) {
  Scene s = joint_scene(JointType::hinge, 5);
  ASSERT_TRUE(s.world.set_type(BodyId{3}, BodyType::static_body).ok());
  const Bytes saved = s.world.save();
  World restored;
  const Status st = restored.restore(saved);
  ASSERT_TRUE(st.ok()) << st.message();
  EXPECT_TRUE(restored.save() == saved);
}

// ---- Refusals ----

struct BadJoint {
  const char* what;  // a part the message must contain
  void (*change)(Decoded& d);
};

TEST(JointState, RefusesEachBadFieldNamingItAndChangesNothing) {
  Scene s = joint_scene(JointType::hinge, 9);
  run(s.world, 10);
  const Bytes good = s.world.save();
  const Decoded d = decode(good);
  ASSERT_TRUE(d.ok) << d.error;
  const BadJoint cases[] = {
      {"next joint ID must be >= 1", [](Decoded& x) { x.next_joint_id = 0; }},
      {"joint ID step", [](Decoded& x) { x.joints[1].id_step = 0; }},
      {"stay below the next joint ID 2", [](Decoded& x) { x.next_joint_id = 2; }},
      {"joint type", [](Decoded& x) { x.joints[0].type = 6; }},
      {"body_a names no body", [](Decoded& x) { x.joints[0].body_a = 99; }},
      {"body_b must name a body", [](Decoded& x) { x.joints[0].body_b = 0; }},
      {"body_a and body_b must differ",
       [](Decoded& x) { x.joints[1].body_a = x.joints[1].body_b; }},
      {"joint flags", [](Decoded& x) { x.joints[0].flags |= 32; }},
      {"joint user data flagged present but zero",
       [](Decoded& x) {
         x.joints[1].user_data = 0;  // the flag stays set
       }},
      {"anchor x must be within", [](Decoded& x) { x.joints[0].anchor.x = Fixed::max(); }},
      {"axis must be a unit vector", [](Decoded& x) { x.joints[0].axis.y += 0.01_fx; }},
      {"limit_lower must be <= limit_upper", [](Decoded& x) { x.joints[0].numbers[0] = 1_fx; }},
      {"swing_limit must be >= 0", [](Decoded& x) { x.joints[0].numbers[2] = -1_fx; }},
      {"swing_limit must be <= pi", [](Decoded& x) { x.joints[0].numbers[2] = 4_fx; }},
      {"motor_max_force must be >= 0", [](Decoded& x) { x.joints[0].numbers[4] = -1_fx; }},
      {"min_length must be >= 0", [](Decoded& x) { x.joints[0].numbers[5] = -1_fx; }},
      {"min_length must be <= max_length", [](Decoded& x) { x.joints[0].numbers[5] = 2_fx; }},
      {"spring_frequency must be >= 0", [](Decoded& x) { x.joints[0].numbers[7] = -1_fx; }},
      {"spring_damping_ratio must be >= 0", [](Decoded& x) { x.joints[0].numbers[8] = -1_fx; }},
      {"break_force must be >= 0", [](Decoded& x) { x.joints[0].numbers[9] = -1_fx; }},
      {"break_torque must be >= 0", [](Decoded& x) { x.joints[0].numbers[10] = -1_fx; }},
      {"local_axis_a must be a unit vector", [](Decoded& x) { x.joints[0].local_axis_a = {}; }},
      {"local_axis_b must be a unit vector",
       [](Decoded& x) { x.joints[1].local_axis_b.z += 0.5_fx; }},
      {"relative_orientation: orientation must be a unit quaternion",
       [](Decoded& x) { x.joints[0].relative_orientation.w += 0.1_fx; }},
      {"length must be >= 0", [](Decoded& x) { x.joints[0].length = -1_fx; }},
  };
  for (const BadJoint& c : cases) {
    Decoded bad = d;
    c.change(bad);
    const Bytes bytes = encode(bad);
    ASSERT_FALSE(bytes == good) << c.what;
    const std::string message = expect_rejected(s.world, bytes);
    EXPECT_TRUE(contains(message, c.what)) << "expected '" << c.what << "' in: " << message;
    EXPECT_TRUE(contains(message, "section \"joints\"")) << message;
  }
}

TEST(JointState, AHugeJointCountIsRefusedBeforeAnythingIsAllocated) {
  Scene s = joint_scene(JointType::ball, 4);
  Bytes bytes = s.world.save();
  const Decoded d = decode(bytes);
  ASSERT_TRUE(d.ok) << d.error;
  put_u32(bytes, d.joint_count_at, 0xFFFFFFF0U);
  g_largest_allocation = 0;
  const std::string message = expect_rejected(s.world, bytes);
  EXPECT_TRUE(contains(message, "joint count")) << message;
  EXPECT_TRUE(contains(message, "exceeds what the data can hold")) << message;
  EXPECT_LT(g_largest_allocation.load(), std::size_t{1} << 20);
}

// ---- The tools: diff and --inject ----

TEST(JointState, DiffNamesTheJointAndTheField) {
  Scene s = joint_scene(JointType::slider, 2);
  run(s.world, 30);
  const Bytes a = s.world.save();
  const Expected<Injection> i = parse_injection("30:0:joint[2].linear_impulse.y:0.001");
  ASSERT_TRUE(i.ok()) << i.message();
  ASSERT_TRUE(apply_injection(s.world, i.value()).ok());
  const Bytes b = s.world.save();
  const Expected<StateDiff> diff = diff_states(a, b);
  ASSERT_TRUE(diff.ok()) << diff.message();
  ASSERT_EQ(diff->fields.size(), 1U);
  const FieldDiff& f = diff->fields[0];
  EXPECT_EQ(f.subsystem, "joints");
  EXPECT_EQ(f.body, 0U);
  EXPECT_EQ(f.field, "joint[2].linear_impulse.y");
  EXPECT_NE(f.a, f.b);

  // A joint on one side only.
  ASSERT_TRUE(s.world.destroy_joint(JointId{1}).ok());
  const Expected<StateDiff> gone = diff_states(b, s.world.save());
  ASSERT_TRUE(gone.ok()) << gone.message();
  bool named = false;
  for (const FieldDiff& g : gone->fields)
    named = named || (g.subsystem == "joints" && g.field == "joint[1].present" &&
                      g.a == "present" && g.b == "absent");
  EXPECT_TRUE(named);
}

TEST(JointState, InjectChangesOneJointFieldOrRefusesAndChangesNothing) {
  Scene s = joint_scene(JointType::hinge, 6);
  run(s.world, 5);
  const Bytes before = s.world.save();
  // Refused by the parser: a body with a joint field, unknown fields and components.
  for (const char* spec :
       {"5:3:joint[1].motor_speed:1", "5:0:joint[1].no_such_field:1", "5:0:joint[0].length:1",
        "5:0:joint[1].anchor.w:1", "5:0:joint[1].motor_speed.x:1", "5:0:joint[1].broken:2"}) {
    EXPECT_FALSE(parse_injection(spec).ok()) << spec;
  }
  // Refused when applied: no such joint; a result restore() would refuse.
  for (const char* spec :
       {"5:0:joint[7].motor_speed:1", "5:0:joint[1].axis.x:0.5", "5:0:joint[2].limit_lower:5"}) {
    const Expected<Injection> i = parse_injection(spec);
    ASSERT_TRUE(i.ok()) << spec << ": " << i.message();
    EXPECT_FALSE(apply_injection(s.world, i.value()).ok()) << spec;
    EXPECT_TRUE(s.world.save() == before) << spec;
  }
  // Accepted: the flag toggles, the number adds.
  const Expected<Injection> broken = parse_injection("5:0:joint[2].broken:1");
  ASSERT_TRUE(broken.ok()) << broken.message();
  ASSERT_TRUE(apply_injection(s.world, broken.value()).ok());
  EXPECT_TRUE(s.world.joint(JointId{2}).value().broken);
  const Expected<Injection> speed = parse_injection("5:0:joint[2].motor_speed:0.25");
  ASSERT_TRUE(speed.ok()) << speed.message();
  ASSERT_TRUE(apply_injection(s.world, speed.value()).ok());
  EXPECT_EQ(s.world.joint(JointId{2}).value().def.motor_speed, 1.25_fx);
  // The help names the joint fields.
  EXPECT_NE(injection_fields_help().find("joint[J]"), std::string_view::npos);
  EXPECT_NE(injection_fields_help().find("limit_impulse"), std::string_view::npos);
}

}  // namespace
}  // namespace detsim::state_test
