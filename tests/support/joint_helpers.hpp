// Helpers for the joint tests: bodies and joints made through the public API (failing the test,
// not crashing, when a definition is refused) and what the tests measure of a joint.
#pragma once

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

#include "support/sim_helpers.hpp"

namespace detsim::test {

/// A dynamic sphere of `radius` and `mass` at p.
inline BodyDef sphere_at(Vec3 p, Fixed radius, Fixed mass) {
  BodyDef d;
  d.shape = Shape::sphere(radius);
  d.position = p;
  d.mass = mass;
  return d;
}

/// A static sphere of 0.1 m at p: something to hang joints from.
inline BodyDef post_at(Vec3 p) {
  BodyDef d = sphere_at(p, Fixed::one() / Fixed::from_int(10), Fixed::one());
  d.type = BodyType::static_body;
  return d;
}

inline JointId join(World& w, const JointDef& def) {
  auto id = w.create_joint(def);
  EXPECT_TRUE(id.ok()) << id.message();
  return id.ok() ? *id : JointId{};
}

/// The anchors' distance, world space: where the joint's anchor is on body a, and on body b.
inline Fixed anchor_gap(const World& w, JointId id) {
  const JointState j = *w.joint(id);
  const BodyState a = state(w, j.def.body_a);
  const BodyState b = state(w, j.def.body_b);
  const Vec3 pa = a.position + rotate(a.orientation, j.local_anchor_a);
  const Vec3 pb = b.position + rotate(b.orientation, j.local_anchor_b);
  return length(pb - pa);
}

}  // namespace detsim::test
