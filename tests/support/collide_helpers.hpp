// Shared helpers of the narrowphase tests (sim_collide_test.cpp, sim_collide_box_test.cpp):
// poses, tolerant comparisons that print both values, manifold invariants, and feature IDs.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include <detsim/fixed/math.hpp>
#include <detsim/fixed/quat.hpp>

#include "sim/src/collide.hpp"
#include "sim/src/collide_util.hpp"
#include "support/vector_print.hpp"

namespace detsim::collide_test {

using namespace detsim::literals;
using sim_detail::collide;
using sim_detail::ContactPoint;
using sim_detail::Manifold;
using sim_detail::Pose;
namespace nf = sim_detail::narrow;

inline constexpr Fixed kTol = 1e-6_fx;  // metres; also used for unit-vector components
inline constexpr Fixed kMargin = 0.1_fx;

inline Vec3 v3(Fixed x, Fixed y, Fixed z) {
  return {x, y, z};
}
inline Pose at(Vec3 p) {
  return {p, Mat3::identity()};
}
inline Pose at(Vec3 p, Quat q) {
  return {p, to_mat3(q)};
}
inline Quat about(Vec3 axis, Fixed angle) {
  return from_axis_angle(axis, angle);
}
inline const Fixed quarter_turn = Fixed::half_pi();
inline const Fixed eighth_turn = Fixed::pi() >> 2;
inline const Fixed half_sqrt2 = Fixed::sqrt2() >> 1;

inline ::testing::AssertionResult near(Fixed actual, Fixed expected, Fixed tol = kTol) {
  if (abs(actual - expected) <= tol) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "actual " << to_string(actual) << ", expected " << to_string(expected) << " (tolerance "
         << to_string(tol) << ")";
}

inline ::testing::AssertionResult near(Vec3 actual, Vec3 expected, Fixed tol = kTol) {
  const Vec3 d = actual - expected;
  if (abs(d.x) <= tol && abs(d.y) <= tol && abs(d.z) <= tol) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "actual (" << to_string(actual.x) << ", " << to_string(actual.y) << ", "
         << to_string(actual.z) << "), expected (" << to_string(expected.x) << ", "
         << to_string(expected.y) << ", " << to_string(expected.z) << ")";
}

inline const ContactPoint* find_feature(const Manifold& m, std::uint32_t feature) {
  for (std::size_t i = 0; i < m.count; ++i)
    if (m.points[i].feature == feature) return &m.points[i];
  return nullptr;
}

inline const ContactPoint* find_point(const Manifold& m, Vec3 p, Fixed tol = kTol) {
  for (std::size_t i = 0; i < m.count; ++i)
    if (near(m.points[i].point, p, tol)) return &m.points[i];
  return nullptr;
}

inline std::vector<std::uint32_t> features(const Manifold& m) {
  std::vector<std::uint32_t> f;
  for (std::size_t i = 0; i < m.count; ++i)
    f.push_back(m.points[i].feature);
  std::sort(f.begin(), f.end());
  return f;
}

inline bool identical(const Manifold& x, const Manifold& y) {
  if (x.normal != y.normal || x.count != y.count) return false;
  for (std::size_t i = 0; i < x.count; ++i) {
    if (x.points[i].point != y.points[i].point ||
        x.points[i].separation != y.points[i].separation ||
        x.points[i].feature != y.points[i].feature)
      return false;
  }
  return true;
}

// Invariants of every manifold: at most four points, a unit normal, separations within the
// margin, distinct feature IDs (the solver matches points by ID).
inline void expect_well_formed(const Manifold& m, Fixed margin) {
  ASSERT_LE(m.count, 4U);
  if (m.count == 0) return;
  EXPECT_TRUE(near(length(m.normal), Fixed::one(), 1e-8_fx)) << "normal not unit";
  std::vector<std::uint32_t> f = features(m);
  EXPECT_EQ(std::unique(f.begin(), f.end()), f.end()) << "duplicate feature IDs";
  for (std::size_t i = 0; i < m.count; ++i)
    EXPECT_LE(m.points[i].separation, margin);
}

// collide(b, a) must be collide(a, b) seen from the other side: the normal negated, the same
// points and separations, each feature ID with its halves swapped (low half = first argument).
inline void expect_mirrored(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb,
                            Fixed margin = kMargin, Fixed tol = kTol) {
  const Manifold ab = collide(a, pa, b, pb, margin);
  const Manifold ba = collide(b, pb, a, pa, margin);
  ASSERT_EQ(ab.count, ba.count);
  ASSERT_GT(ab.count, 0U) << "a mirror test needs a contact";
  EXPECT_TRUE(near(ba.normal, -ab.normal, tol));
  for (std::size_t i = 0; i < ab.count; ++i) {
    const ContactPoint* q = find_feature(ba, nf::mirror_feature(ab.points[i].feature));
    ASSERT_NE(q, nullptr) << "feature " << std::hex << ab.points[i].feature << " not mirrored";
    EXPECT_TRUE(near(q->separation, ab.points[i].separation, tol));
    EXPECT_TRUE(near(q->point, ab.points[i].point, tol));
  }
}

// Moving b by `delta` (1e-4 m or so) without changing which features touch must keep every
// feature ID, so that the solver can warm start the same points next step.
inline void expect_features_stable(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb,
                                   Vec3 delta, Fixed margin = kMargin) {
  const Manifold m = collide(a, pa, b, pb, margin);
  const Manifold moved = collide(a, pa, b, Pose{pb.position + delta, pb.rotation}, margin);
  ASSERT_GT(m.count, 0U);
  EXPECT_EQ(features(moved), features(m));
}

// ---- Shapes and features used throughout --------------------------------------------------------

inline const std::uint16_t kWhole = nf::whole_shape;
inline const std::uint16_t kPlane = nf::plane_face;
inline const std::uint16_t kCore = nf::capsule_core;
inline const std::uint16_t kBottom = nf::capsule_end(false);  // the core's local -y end
inline const std::uint16_t kTop = nf::capsule_end(true);
inline std::uint32_t pair(std::uint16_t a, std::uint16_t b) {
  return nf::pair_feature(a, b);
}
inline std::uint16_t vertex(bool x, bool y, bool z) {
  return nf::box_vertex({x, y, z});
}
inline std::uint16_t edge(int axis, bool x, bool y, bool z) {
  return nf::box_edge(axis, {x, y, z});
}

}  // namespace detsim::collide_test
