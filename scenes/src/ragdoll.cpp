// The ragdoll's tables and its builder (ragdoll.hpp). Proportions: a 1.7 m, 69 kg figure whose
// limbs are capsules, chest and pelvis boxes, head a sphere; each joint sits where the two parts
// meet, so that the figure starts with every anchor gap zero.
#include <detsim/scenes/ragdoll.hpp>

namespace detsim {

namespace {

using namespace detsim::literals;

enum Part : std::uint8_t {
  pelvis,
  chest,
  head,
  upper_arm_left,
  lower_arm_left,
  upper_arm_right,
  lower_arm_right,
  thigh_left,
  shin_left,
  thigh_right,
  shin_right,
};

// Heights (m above the soles): pelvis 0.9 .. 1.1, chest 1.1 .. 1.5, head centre 1.62; shoulder
// 1.45, elbow 1.15; hip 0.9, knee 0.46. Arms hang at z = +-0.23 (against the chest's sides), legs
// at z = +-0.1.
constexpr std::array<RagdollPart, ragdoll_part_count> parts{{
    {"pelvis", Shape::box({0.1_fx, 0.1_fx, 0.15_fx}), {0_fx, 1_fx, 0_fx}, 12_fx},
    {"chest", Shape::box({0.1_fx, 0.2_fx, 0.18_fx}), {0_fx, 1.3_fx, 0_fx}, 20_fx},
    {"head", Shape::sphere(0.1_fx), {0_fx, 1.62_fx, 0_fx}, 5_fx},
    {"upper_arm_left", Shape::capsule(0.05_fx, 0.1_fx), {0_fx, 1.3_fx, 0.23_fx}, 2.5_fx},
    {"lower_arm_left", Shape::capsule(0.04_fx, 0.1_fx), {0_fx, 1.01_fx, 0.23_fx}, 1.5_fx},
    {"upper_arm_right", Shape::capsule(0.05_fx, 0.1_fx), {0_fx, 1.3_fx, -0.23_fx}, 2.5_fx},
    {"lower_arm_right", Shape::capsule(0.04_fx, 0.1_fx), {0_fx, 1.01_fx, -0.23_fx}, 1.5_fx},
    {"thigh_left", Shape::capsule(0.07_fx, 0.15_fx), {0_fx, 0.68_fx, 0.1_fx}, 8_fx},
    {"shin_left", Shape::capsule(0.06_fx, 0.16_fx), {0_fx, 0.24_fx, 0.1_fx}, 4_fx},
    {"thigh_right", Shape::capsule(0.07_fx, 0.15_fx), {0_fx, 0.68_fx, -0.1_fx}, 8_fx},
    {"shin_right", Shape::capsule(0.06_fx, 0.16_fx), {0_fx, 0.24_fx, -0.1_fx}, 4_fx},
}};

constexpr Vec3 up{0_fx, 1_fx, 0_fx};
constexpr Vec3 down{0_fx, -1_fx, 0_fx};
constexpr Vec3 side{0_fx, 0_fx, 1_fx};  // the hinges' axis: elbows and knees bend in the x-y plane

// Swing-twist twist axes point from the parent into the child (up the spine, down the limbs).
// Hinge angles are body b's turn about +z relative to a: a forearm folds forwards (+x, positive),
// a shin backwards (negative).
constexpr std::array<RagdollJoint, ragdoll_joint_count> joints{{
    {"spine",
     JointType::swing_twist,
     pelvis,
     chest,
     {0_fx, 1.1_fx, 0_fx},
     up,
     0.4_fx,
     -0.3_fx,
     0.3_fx},
    {"neck", JointType::ball, chest, head, {0_fx, 1.5_fx, 0_fx}, up, 0_fx, 0_fx, 0_fx},
    {"shoulder_left",
     JointType::swing_twist,
     chest,
     upper_arm_left,
     {0_fx, 1.45_fx, 0.23_fx},
     down,
     1.3_fx,
     -0.6_fx,
     0.6_fx},
    {"elbow_left",
     JointType::hinge,
     upper_arm_left,
     lower_arm_left,
     {0_fx, 1.15_fx, 0.23_fx},
     side,
     0_fx,
     0_fx,
     2.4_fx},
    {"shoulder_right",
     JointType::swing_twist,
     chest,
     upper_arm_right,
     {0_fx, 1.45_fx, -0.23_fx},
     down,
     1.3_fx,
     -0.6_fx,
     0.6_fx},
    {"elbow_right",
     JointType::hinge,
     upper_arm_right,
     lower_arm_right,
     {0_fx, 1.15_fx, -0.23_fx},
     side,
     0_fx,
     0_fx,
     2.4_fx},
    {"hip_left",
     JointType::swing_twist,
     pelvis,
     thigh_left,
     {0_fx, 0.9_fx, 0.1_fx},
     down,
     1_fx,
     -0.3_fx,
     0.3_fx},
    {"knee_left",
     JointType::hinge,
     thigh_left,
     shin_left,
     {0_fx, 0.46_fx, 0.1_fx},
     side,
     0_fx,
     -2.4_fx,
     0_fx},
    {"hip_right",
     JointType::swing_twist,
     pelvis,
     thigh_right,
     {0_fx, 0.9_fx, -0.1_fx},
     down,
     1_fx,
     -0.3_fx,
     0.3_fx},
    {"knee_right",
     JointType::hinge,
     thigh_right,
     shin_right,
     {0_fx, 0.46_fx, -0.1_fx},
     side,
     0_fx,
     -2.4_fx,
     0_fx},
}};

}  // namespace

std::span<const RagdollPart, ragdoll_part_count> ragdoll_parts() noexcept {
  return parts;
}

std::span<const RagdollJoint, ragdoll_joint_count> ragdoll_joints() noexcept {
  return joints;
}

Expected<Ragdoll> add_ragdoll(World& world, const RagdollPlacement& placement) {
  const Quat q = placement.orientation;
  const auto place = [&](Vec3 local) { return placement.position + rotate(q, local); };
  Ragdoll made;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const Vec3 at = place(parts[i].position);
    BodyDef d;
    d.shape = parts[i].shape;
    d.position = at;
    d.orientation = q;
    d.mass = parts[i].mass;
    d.friction = placement.friction;
    d.angular_damping = placement.angular_damping;
    // The whole figure turns about `position`: each part's centre moves at v + w x r.
    d.linear_velocity =
        placement.linear_velocity + cross(placement.angular_velocity, at - placement.position);
    d.angular_velocity = placement.angular_velocity;
    d.user_data = placement.user_data;
    auto id = world.create_body(d);
    if (!id) return id.status();
    made.bodies[i] = *id;
  }
  for (std::size_t i = 0; i < joints.size(); ++i) {
    const RagdollJoint& j = joints[i];
    JointDef d;
    d.type = j.type;
    d.body_a = made.bodies[j.parent];
    d.body_b = made.bodies[j.child];
    d.anchor = place(j.anchor);
    d.axis = rotate(q, j.axis);
    d.limit_enabled = j.type != JointType::ball;
    d.swing_limit = j.swing_limit;
    d.limit_lower = j.limit_lower;
    d.limit_upper = j.limit_upper;
    auto id = world.create_joint(d);
    if (!id) return id.status();
    made.joints[i] = *id;
  }
  return made;
}

}  // namespace detsim
