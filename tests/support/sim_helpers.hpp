// Helpers for the simulation tests: worlds and bodies made through the public API, failing the
// test (not crashing) when a definition is refused, and a Fixed comparison that prints decimals.
#pragma once

#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

#include "support/vector_print.hpp"

namespace detsim::test {

inline World make_world(const WorldDef& def = {}) {
  auto w = World::create(def);
  EXPECT_TRUE(w.ok()) << w.message();
  return w.ok() ? std::move(w.value()) : World();
}

inline BodyId add(World& w, const BodyDef& def) {
  auto id = w.create_body(def);
  EXPECT_TRUE(id.ok()) << id.message();
  return id.ok() ? *id : BodyId{};
}

/// A static ground plane through the origin with its normal along `orientation`'s +y.
inline BodyId add_ground(World& w, Quat orientation = {},
                         Fixed friction = Fixed::from_raw(Fixed::one_raw * 6 / 10)) {
  BodyDef g;
  g.type = BodyType::static_body;
  g.shape = Shape::plane();
  g.orientation = orientation;
  g.friction = friction;
  return add(w, g);
}

inline BodyState state(const World& w, BodyId id) {
  auto b = w.body(id);
  EXPECT_TRUE(b.ok()) << b.message();
  return b.ok() ? *b : BodyState{};
}

/// A dynamic body of `shape` placed at `position` turned by `orientation`, every other field
/// default.
inline BodyDef placed(Shape shape, Vec3 position, Quat orientation = {}) {
  BodyDef d;
  d.shape = shape;
  d.position = position;
  d.orientation = orientation;
  return d;
}

/// A static body of `shape` placed at `position` turned by `orientation`, every other field
/// default.
inline BodyDef static_placed(Shape shape, Vec3 position = {}, Quat orientation = {}) {
  BodyDef d = placed(shape, position, orientation);
  d.type = BodyType::static_body;
  return d;
}

/// The 12-point rock of the hull tests: points of Rng(9) on an ellipsoid of semi-axes 0.6, 0.4,
/// 0.5 m.
inline std::vector<Vec3> test_rock() {
  using namespace detsim::literals;
  Rng rng(9);
  std::vector<Vec3> rock;
  for (int i = 0; i < 12; ++i) {
    const Vec3 u = rng.unit_vector();
    rock.push_back({u.x * 0.6_fx, u.y * 0.4_fx, u.z * 0.5_fx});
  }
  return rock;
}

/// |actual - expected| <= tolerance, printing all three as decimals on failure.
inline testing::AssertionResult near(Fixed actual, Fixed expected, Fixed tolerance) {
  if (abs(actual - expected) <= tolerance) return testing::AssertionSuccess();
  return testing::AssertionFailure() << "actual " << to_string(actual) << ", expected "
                                     << to_string(expected) << " +- " << to_string(tolerance);
}

/// Each component of `actual` within `tolerance` of `expected`'s, printing both on failure.
inline testing::AssertionResult near_vec(Vec3 actual, Vec3 expected, Fixed tolerance) {
  if (near(actual.x, expected.x, tolerance) && near(actual.y, expected.y, tolerance) &&
      near(actual.z, expected.z, tolerance))
    return testing::AssertionSuccess();
  return testing::AssertionFailure()
         << testing::PrintToString(actual) << " is not within " << to_string(tolerance) << " of "
         << testing::PrintToString(expected);
}

}  // namespace detsim::test
