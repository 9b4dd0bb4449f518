// Joined structures of issue 17: a 40-plank bridge hanging between two banks and a 20-body ragdoll
// dropped on the ground must be stable — no energy gained, still at rest (no jitter), joints held
// together. Energy is measured in double (a test's measurement, not simulation arithmetic):
// kinetic (1/2 m v^2 + 1/2 w . I w) plus potential (m g y).
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

#include "support/joint_helpers.hpp"

namespace detsim {
namespace {

using namespace detsim::literals;
using test::add;
using test::anchor_gap;
using test::join;
using test::make_world;

double to_double(Fixed x) {
  return static_cast<double>(x.raw()) / 4294967296.0;
}

/// Kinetic plus potential energy of every dynamic body, J (potential from y = 0).
double energy(const World& w) {
  const double g = -to_double(w.def().gravity.y);
  double e = 0;
  for (const BodyId id : w.body_ids()) {
    const BodyState b = w.body(id).value();
    if (b.type != BodyType::dynamic) continue;
    const double m = to_double(b.mass);
    const Vec3 v = b.linear_velocity;
    e += 0.5 * m *
         (to_double(v.x) * to_double(v.x) + to_double(v.y) * to_double(v.y) +
          to_double(v.z) * to_double(v.z));
    const Vec3 wb = rotate(conjugate(b.orientation), b.angular_velocity);  // body frame
    e += 0.5 * (to_double(b.inertia.x) * to_double(wb.x) * to_double(wb.x) +
                to_double(b.inertia.y) * to_double(wb.y) * to_double(wb.y) +
                to_double(b.inertia.z) * to_double(wb.z) * to_double(wb.z));
    e += m * g * to_double(b.position.y);
  }
  return e;
}

double total_mass(const World& w) {
  double m = 0;
  for (const BodyId id : w.body_ids()) {
    const BodyState b = w.body(id).value();
    if (b.type == BodyType::dynamic) m += to_double(b.mass);
  }
  return m;
}

Fixed fastest(const World& w) {
  Fixed top;
  for (const BodyId id : w.body_ids()) {
    const BodyState b = w.body(id).value();
    if (b.type != BodyType::dynamic || !b.awake) continue;
    top = max(top, length(b.linear_velocity));
  }
  return top;
}

Fixed worst_gap(const World& w) {
  Fixed worst;
  for (const JointId id : w.joint_ids())
    worst = max(worst, anchor_gap(w, id));
  return worst;
}

/// Runs `seconds` at 60 Hz and checks, every frame, that the energy never rose above the start's
/// by more than lifting the whole mass 1 cm; returns the largest rise seen (J).
double run_without_energy_gain(World& w, int seconds, const char* what) {
  const double start = energy(w);
  const double allowed = total_mass(w) * -to_double(w.def().gravity.y) * 0.01;
  double worst = -1e300;
  for (int f = 0; f < seconds * 60; ++f) {
    w.step();
    const double rise = energy(w) - start;
    worst = std::max(worst, rise);
    if (rise > allowed) {
      ADD_FAILURE() << what << ": energy rose " << rise << " J above the start's at frame "
                    << w.frame() << " (allowed " << allowed << " J)";
      break;
    }
  }
  return worst;
}

// ---- A 40-plank bridge ----

TEST(SimJointStructures, FortyPlankBridgeSettlesWithoutGainingEnergyAndRestsStill) {
  // 40 planks of 0.5 m and 5 kg, hinged end to end about z, laid in a shallow V (0.2 rad down,
  // then up) between two static banks; released, the chain of planks swings into its hanging
  // shape and must come to rest: no energy gained, still at the end, every hinge held.
  World w = make_world();
  constexpr int planks = 40;
  const Fixed slack = 0.2_fx;
  const Fixed plank = 0.5_fx;
  std::vector<Vec3> hinge(planks + 1);
  hinge[0] = {0_fx, 10_fx, 0_fx};
  for (int i = 0; i < planks; ++i) {
    const Fixed dy = i < planks / 2 ? -sin(slack) : sin(slack);
    hinge[static_cast<std::size_t>(i + 1)] =
        hinge[static_cast<std::size_t>(i)] + Vec3{cos(slack), dy, 0_fx} * plank;
  }
  BodyDef bank;
  bank.type = BodyType::static_body;
  bank.shape = Shape::box({0.5_fx, 0.5_fx, 1_fx});
  bank.position = hinge[0] - Vec3{0.5_fx, 0.5_fx, 0_fx};
  BodyId previous = add(w, bank);
  bank.position = hinge[planks] + Vec3{0.5_fx, -0.5_fx, 0_fx};
  const BodyId right = add(w, bank);
  for (int i = 0; i < planks; ++i) {
    const Vec3 a = hinge[static_cast<std::size_t>(i)];
    const Vec3 b = hinge[static_cast<std::size_t>(i + 1)];
    BodyDef d;
    d.shape = Shape::box({plank / 2_fx, 0.05_fx, 1_fx});
    d.position = (a + b) / 2_fx;
    d.orientation = from_axis_angle({0_fx, 0_fx, 1_fx}, i < planks / 2 ? -slack : slack);
    d.mass = 5_fx;
    d.linear_damping = 0.5_fx;  // a real bridge's losses (an undamped one swings for ever)
    d.angular_damping = 0.5_fx;
    const BodyId id = add(w, d);
    JointDef j;
    j.type = JointType::hinge;
    j.body_a = previous;
    j.body_b = id;
    j.anchor = a;
    j.axis = {0_fx, 0_fx, 1_fx};
    join(w, j);
    previous = id;
  }
  JointDef last;
  last.type = JointType::hinge;
  last.body_a = previous;
  last.body_b = right;
  last.anchor = hinge[planks];
  last.axis = {0_fx, 0_fx, 1_fx};
  join(w, last);

  const double rise = run_without_energy_gain(w, 20, "bridge");
  const Fixed gap = worst_gap(w);
  std::printf("[ bridge ] 20 s: energy rise at most %.4f J, fastest plank %s m/s, worst gap %s m\n",
              rise, to_string(fastest(w)).c_str(), to_string(gap).c_str());
  // At rest: no plank moving faster than the chain test's 0.05 m/s (asleep counts as still).
  EXPECT_LT(fastest(w), 0.05_fx);
  // Held together: the hinges' give under the bridge's tension (docs/SIM.md, "Joints": a
  // soft joint at rest stretches by F / (m_eff (2 pi 60 Hz)^2)). The end tension of a hanging
  // chain of weight W whose ends leave at angle theta is at most W / (2 sin theta): for 200 kg
  // and the planks' 0.2 rad, 4.93 kN, along the planks. Along a plank's axis its end's arm is
  // zero, so the effective mass of a hinge between two 5 kg planks in that direction is 2.5 kg,
  // and the give is at most 4930 / (2.5 (2 pi 60)^2) = 13.9 mm.
  EXPECT_LT(gap, 0.0139_fx) << to_string(gap);
}

// ---- A 20-body ragdoll ----

struct Part {
  const char* name;
  Shape shape;
  Vec3 at;
  Fixed mass;
};

TEST(SimJointStructures, TwentyBodyRagdollFallsWithoutGainingEnergyAndLiesStill) {
  // A figure of 20 bodies — pelvis, two spine segments, chest, neck, head, collarbones, upper arms,
  // forearms, hands, thighs, shins, feet — joined by swing-twists (spine, neck, shoulders, hips),
  // hinges with limits (elbows, knees, ankles), balls (wrists) and fixed joints (collarbones),
  // dropped face down from 1 m onto the ground with a spin.
  World w = make_world();
  BodyDef ground;
  ground.type = BodyType::static_body;
  ground.shape = Shape::plane();
  add(w, ground);
  const Fixed up = 1_fx;  // the whole figure 1 m above its standing height
  const std::vector<Part> parts = {
      {"pelvis", Shape::box({0.1_fx, 0.08_fx, 0.15_fx}), {0_fx, 1_fx, 0_fx}, 10_fx},
      {"spine1", Shape::box({0.09_fx, 0.06_fx, 0.14_fx}), {0_fx, 1.14_fx, 0_fx}, 5_fx},
      {"spine2", Shape::box({0.1_fx, 0.12_fx, 0.16_fx}), {0_fx, 1.32_fx, 0_fx}, 11_fx},
      {"chest", Shape::box({0.1_fx, 0.07_fx, 0.17_fx}), {0_fx, 1.51_fx, 0_fx}, 8_fx},
      {"neck", Shape::capsule(0.04_fx, 0.03_fx), {0_fx, 1.65_fx, 0_fx}, 1_fx},
      {"head", Shape::sphere(0.1_fx), {0_fx, 1.82_fx, 0_fx}, 5_fx},
      {"collar_l", Shape::box({0.03_fx, 0.03_fx, 0.06_fx}), {0_fx, 1.55_fx, 0.21_fx}, 0.5_fx},
      {"collar_r", Shape::box({0.03_fx, 0.03_fx, 0.06_fx}), {0_fx, 1.55_fx, -0.21_fx}, 0.5_fx},
      {"upper_arm_l", Shape::capsule(0.045_fx, 0.1_fx), {0_fx, 1.4_fx, 0.31_fx}, 2_fx},
      {"upper_arm_r", Shape::capsule(0.045_fx, 0.1_fx), {0_fx, 1.4_fx, -0.31_fx}, 2_fx},
      {"forearm_l", Shape::capsule(0.04_fx, 0.09_fx), {0_fx, 1.12_fx, 0.31_fx}, 1.5_fx},
      {"forearm_r", Shape::capsule(0.04_fx, 0.09_fx), {0_fx, 1.12_fx, -0.31_fx}, 1.5_fx},
      {"hand_l", Shape::box({0.03_fx, 0.06_fx, 0.02_fx}), {0_fx, 0.91_fx, 0.31_fx}, 0.5_fx},
      {"hand_r", Shape::box({0.03_fx, 0.06_fx, 0.02_fx}), {0_fx, 0.91_fx, -0.31_fx}, 0.5_fx},
      {"thigh_l", Shape::capsule(0.07_fx, 0.15_fx), {0_fx, 0.7_fx, 0.09_fx}, 8_fx},
      {"thigh_r", Shape::capsule(0.07_fx, 0.15_fx), {0_fx, 0.7_fx, -0.09_fx}, 8_fx},
      {"shin_l", Shape::capsule(0.055_fx, 0.15_fx), {0_fx, 0.3_fx, 0.09_fx}, 4_fx},
      {"shin_r", Shape::capsule(0.055_fx, 0.15_fx), {0_fx, 0.3_fx, -0.09_fx}, 4_fx},
      {"foot_l", Shape::box({0.1_fx, 0.03_fx, 0.045_fx}), {0.05_fx, 0.05_fx, 0.09_fx}, 1_fx},
      {"foot_r", Shape::box({0.1_fx, 0.03_fx, 0.045_fx}), {0.05_fx, 0.05_fx, -0.09_fx}, 1_fx},
  };
  const std::vector<Part>& all = parts;
  ASSERT_EQ(all.size(), 20U);
  // Face down: the standing figure turned about z by -90 degrees about the pelvis, then raised.
  const Quat face_down = from_axis_angle({0_fx, 0_fx, 1_fx}, -Fixed::half_pi());
  const Vec3 pivot{0_fx, 1_fx, 0_fx};
  const auto place = [&](Vec3 p) {
    return pivot + rotate(face_down, p - pivot) + Vec3{0_fx, up - 0.6_fx, 0_fx};
  };
  std::vector<BodyId> id;
  for (const Part& p : all) {
    BodyDef d;
    d.shape = p.shape;
    d.position = place(p.at);
    d.orientation = face_down;
    d.mass = p.mass;
    d.angular_velocity = {0_fx, 1_fx, 0_fx};
    d.angular_damping = 0.5_fx;
    d.friction = 0.8_fx;
    id.push_back(add(w, d));
  }
  const auto body = [&](const char* name) {
    for (std::size_t i = 0; i < all.size(); ++i)
      if (std::string(all[i].name) == name) return id[i];
    ADD_FAILURE() << "no part " << name;
    return BodyId{};
  };
  const auto joint = [&](JointType type, const char* a, const char* b, Vec3 at, Vec3 axis,
                         Fixed lower, Fixed upper, Fixed swing) {
    JointDef j;
    j.type = type;
    j.body_a = body(a);
    j.body_b = body(b);
    j.anchor = place(at);
    j.axis = rotate(face_down, axis);
    j.limit_enabled = type == JointType::hinge || type == JointType::swing_twist;
    j.limit_lower = lower;
    j.limit_upper = upper;
    j.swing_limit = swing;
    join(w, j);
  };
  const Vec3 y{0_fx, 1_fx, 0_fx};
  const Vec3 z{0_fx, 0_fx, 1_fx};
  const Fixed q = 0.3_fx;
  joint(JointType::swing_twist, "pelvis", "spine1", {0_fx, 1.08_fx, 0_fx}, y, -q, q, q);
  joint(JointType::swing_twist, "spine1", "spine2", {0_fx, 1.2_fx, 0_fx}, y, -q, q, q);
  joint(JointType::swing_twist, "spine2", "chest", {0_fx, 1.44_fx, 0_fx}, y, -q, q, q);
  joint(JointType::swing_twist, "chest", "neck", {0_fx, 1.58_fx, 0_fx}, y, -q, q, 0.5_fx);
  joint(JointType::swing_twist, "neck", "head", {0_fx, 1.72_fx, 0_fx}, y, -0.6_fx, 0.6_fx, 0.5_fx);
  joint(JointType::fixed, "chest", "collar_l", {0_fx, 1.55_fx, 0.15_fx}, y, 0_fx, 0_fx, 0_fx);
  joint(JointType::fixed, "chest", "collar_r", {0_fx, 1.55_fx, -0.15_fx}, y, 0_fx, 0_fx, 0_fx);
  joint(JointType::swing_twist, "collar_l", "upper_arm_l", {0_fx, 1.55_fx, 0.31_fx}, y, -0.5_fx,
        0.5_fx, 1.2_fx);
  joint(JointType::swing_twist, "collar_r", "upper_arm_r", {0_fx, 1.55_fx, -0.31_fx}, y, -0.5_fx,
        0.5_fx, 1.2_fx);
  joint(JointType::hinge, "upper_arm_l", "forearm_l", {0_fx, 1.25_fx, 0.31_fx}, z, -2_fx, 0_fx,
        0_fx);
  joint(JointType::hinge, "upper_arm_r", "forearm_r", {0_fx, 1.25_fx, -0.31_fx}, z, -2_fx, 0_fx,
        0_fx);
  joint(JointType::ball, "forearm_l", "hand_l", {0_fx, 0.98_fx, 0.31_fx}, y, 0_fx, 0_fx, 0_fx);
  joint(JointType::ball, "forearm_r", "hand_r", {0_fx, 0.98_fx, -0.31_fx}, y, 0_fx, 0_fx, 0_fx);
  joint(JointType::swing_twist, "pelvis", "thigh_l", {0_fx, 0.92_fx, 0.09_fx}, y, -0.3_fx, 0.3_fx,
        1_fx);
  joint(JointType::swing_twist, "pelvis", "thigh_r", {0_fx, 0.92_fx, -0.09_fx}, y, -0.3_fx, 0.3_fx,
        1_fx);
  joint(JointType::hinge, "thigh_l", "shin_l", {0_fx, 0.5_fx, 0.09_fx}, z, 0_fx, 2_fx, 0_fx);
  joint(JointType::hinge, "thigh_r", "shin_r", {0_fx, 0.5_fx, -0.09_fx}, z, 0_fx, 2_fx, 0_fx);
  joint(JointType::hinge, "shin_l", "foot_l", {0_fx, 0.09_fx, 0.09_fx}, z, -0.5_fx, 0.5_fx, 0_fx);
  joint(JointType::hinge, "shin_r", "foot_r", {0_fx, 0.09_fx, -0.09_fx}, z, -0.5_fx, 0.5_fx, 0_fx);
  ASSERT_EQ(w.joint_ids().size(), 19U);  // a tree of 20 bodies

  const double rise = run_without_energy_gain(w, 10, "ragdoll");
  const Fixed gap = worst_gap(w);
  std::printf("[ ragdoll ] 10 s: energy rise at most %.4f J, fastest part %s m/s, worst gap %s m\n",
              rise, to_string(fastest(w)).c_str(), to_string(gap).c_str());
  EXPECT_LT(fastest(w), 0.05_fx);
  // Held together within issue 17's tolerance for a chain, 5 mm: lying on the ground, a joint
  // carries at most a few kilograms' weight.
  EXPECT_LT(gap, 0.005_fx) << to_string(gap);
}

}  // namespace
}  // namespace detsim
