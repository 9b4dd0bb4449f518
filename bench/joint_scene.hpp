// A scene of bodies and joints in plain doubles: what joint_bench reads out of a detsim World at
// frame 0 and hands to the Bullet peer (bullet_joint_peer.cpp), so that both engines start from
// the same bodies, masses, shapes and joints. Benchmark code: double is used freely here.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace detsim_bench {

struct SceneBody {
  enum class Kind : std::uint8_t { sphere, box, capsule, plane };
  Kind kind = Kind::sphere;
  bool dynamic = true;                            ///< else static
  double radius = 0.0;                            ///< sphere, capsule
  double half_height = 0.0;                       ///< capsule: its core segment along local y
  std::array<double, 3> half_extents{};           ///< box
  std::array<double, 3> position{};               ///< m
  std::array<double, 4> orientation{1, 0, 0, 0};  ///< unit quaternion w, x, y, z
  std::array<double, 3> linear_velocity{};        ///< m/s
  std::array<double, 3> angular_velocity{};       ///< rad/s
  double mass = 0.0;                              ///< kg
  double friction = 0.5;        ///< detsim's per-body coefficient (geometric mean)
  double linear_damping = 0.0;  ///< detsim's, 1/s: v *= 1 / (1 + dt c) per step
  double angular_damping = 0.0;
};

struct SceneJoint {
  enum class Kind : std::uint8_t { ball, hinge, fixed, swing_twist };
  Kind kind = Kind::ball;
  std::uint32_t body_a = 0;  ///< indices into JointScene::bodies
  std::uint32_t body_b = 0;
  std::array<double, 3> anchor{};  ///< world space, at frame 0
  std::array<double, 3> axis{};    ///< world space unit vector, at frame 0
  bool limit_enabled = false;
  double limit_lower = 0.0;  ///< hinge angle, swing_twist twist (rad)
  double limit_upper = 0.0;
  double swing_limit = 0.0;  ///< swing_twist cone half-angle (rad)
  bool motor_enabled = false;
  double motor_speed = 0.0;
  double motor_max_force = 0.0;
};

struct JointScene {
  std::vector<SceneBody> bodies;
  std::vector<SceneJoint> joints;
  double dt = 1.0 / 60.0;
  double gravity_y = -9.81;
};

/// The anchors' separation over a scene's joints: the largest and the mean, m.
struct Stretch {
  double worst = 0.0;
  double mean = 0.0;
};

}  // namespace detsim_bench
