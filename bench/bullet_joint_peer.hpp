// The Bullet 3 peer of the joint scenes (joint_bench.cpp; docs/BENCHMARKS.md, "Joints"), behind an
// interface that names no Bullet type: only bullet_joint_peer.cpp includes Bullet's headers.
#pragma once

#include <cstdint>
#include <memory>

#include "joint_scene.hpp"

namespace detsim_bench {

/// A JointScene in a btDiscreteDynamicsWorld with the sequential impulse solver: ball joints as
/// btPoint2PointConstraint, hinges as btHingeConstraint (limit, motor), swing-twists as
/// btConeTwistConstraint (the twist range made symmetric: Bullet has one span), fixed joints as
/// btFixedConstraint; collisions between joined bodies disabled (detsim's collide_connected =
/// false). Each body's friction is the square root of detsim's, so that Bullet's product of two
/// frictions gives detsim's geometric mean; damping is converted to Bullet's (1 - d)^dt form.
class BulletJointScene {
 public:
  /// `substeps` fixed sub-steps of dt / substeps per step, `iterations` solver iterations each.
  BulletJointScene(const JointScene& scene, int substeps, int iterations);
  ~BulletJointScene();
  BulletJointScene(const BulletJointScene&) = delete;
  BulletJointScene& operator=(const BulletJointScene&) = delete;

  /// One step of the scene's dt.
  void step();
  /// The anchors' separation now: each joint's anchor as body a carries it against body b's.
  [[nodiscard]] Stretch stretch() const;
  /// Dynamic bodies not deactivated.
  [[nodiscard]] std::uint32_t awake_count() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace detsim_bench
