// Helpers for the simulation tests: worlds and bodies made through the public API, failing the
// test (not crashing) when a definition is refused, and a Fixed comparison that prints decimals.
#pragma once

#include <utility>

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

/// |actual - expected| <= tolerance, printing all three as decimals on failure.
inline testing::AssertionResult near(Fixed actual, Fixed expected, Fixed tolerance) {
  if (abs(actual - expected) <= tolerance) return testing::AssertionSuccess();
  return testing::AssertionFailure() << "actual " << to_string(actual) << ", expected "
                                     << to_string(expected) << " +- " << to_string(tolerance);
}

}  // namespace detsim::test
