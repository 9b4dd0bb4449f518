// Refuse, never cap (docs/SIM.md, "What is refused"): a definition or call whose mass, moment of
// inertia or other derived quantity would saturate Q32.32 (or lose all precision) is refused with
// a message naming the quantity and the limit, and the world's bytes are unchanged. Each limit is
// derived here from its formula, with a case just inside it that is accepted.
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

#include "support/sim_helpers.hpp"

namespace detsim {
namespace {

using namespace detsim::literals;

using test::add;
using test::add_ground;
using test::make_world;
using test::state;

// The limits as docs/SIM.md states them.
const Fixed kMaxQuantity = Fixed::from_int(std::numeric_limits<std::int32_t>::max());  // 2^31 - 1
const Fixed kHalfRange = Fixed::from_int(1 << 30);  // positions, velocities, accelerations
const Fixed kUlp = Fixed::epsilon();

using Call = std::function<Status(World&)>;

Call create(const BodyDef& def) {
  return [def](World& w) { return w.create_body(def).status(); };
}

// The call is refused, its message names every word, and the world's bytes are unchanged.
void expect_refused(World& w, const Call& call, std::initializer_list<const char*> words) {
  const std::vector<std::uint8_t> before = w.save();
  const Status s = call(w);
  ASSERT_FALSE(s.ok()) << "accepted, expected a refusal naming " << *words.begin();
  for (const char* word : words)
    EXPECT_NE(s.message().find(word), std::string::npos) << "'" << word << "' in " << s.message();
  EXPECT_EQ(w.save(), before) << s.message();
}

void expect_accepted(World& w, const Call& call) {
  const Status s = call(w);
  EXPECT_TRUE(s.ok()) << s.message();
  EXPECT_TRUE(w.validate().ok());
}

// A world with a ground and a body in it, so that "unchanged" has something to compare.
World scene() {
  World w = make_world();
  add_ground(w);
  add(w, {.shape = Shape::box({0.5_fx, 0.5_fx, 0.5_fx}), .position = {0_fx, 2_fx, 0_fx}});
  return w;
}

Shape cube(Fixed half) {
  return Shape::box({half, half, half});
}

TEST(Refusal, AKilometreBoxOfWaterIsRefusedNotCapped) {
  World w = scene();
  // 8 * 500^3 = 10^9 m^3 (within the range), 10^12 kg (far above it).
  expect_refused(w, create({.shape = cube(500_fx)}),
                 {"mass", "1000000000000 kg", "density 1000", "volume 1000000000", "2147483647"});
  // Static too: the mass is kept for set_type(dynamic). Density 0 gives a body without one.
  expect_refused(w, create({.type = BodyType::static_body, .shape = cube(500_fx)}),
                 {"mass", "density 0"});
  expect_accepted(w, create({.type = BodyType::static_body, .shape = cube(500_fx), .density = {}}));
}

TEST(Refusal, MassFromDensityUpToTheLimit) {
  // A cube of half extent 1 has the volume 8 exactly; mass = density * 8 <= 2^31 - 1.
  const Fixed density = Fixed::from_raw(kMaxQuantity.raw() / 8);  // exact: the raw is a multiple
  ASSERT_EQ(density * 8_fx, kMaxQuantity);
  World w = scene();
  expect_accepted(w, create({.shape = cube(1_fx), .density = density}));
  EXPECT_EQ(state(w, BodyId{3}).mass, kMaxQuantity);
  expect_refused(w, create({.shape = cube(1_fx), .density = density + kUlp}), {"mass", "kg"});
}

TEST(Refusal, VolumeUpToTheLimit) {
  // 8 ((1000 * 1000) * h) <= 2^31 - 1, each product exact for h on the Q32.32 grid.
  const Fixed h = Fixed::from_raw(kMaxQuantity.raw() / 8000000);
  ASSERT_LE(8_fx * (1000_fx * 1000_fx * h), kMaxQuantity);
  ASSERT_GT(8_fx * (1000_fx * 1000_fx * (h + kUlp)), kMaxQuantity);
  // A density of one ulp keeps the mass (about 0.5 kg) and the inertia small.
  const auto box = [](Fixed z) {
    return BodyDef{.shape = Shape::box({1000_fx, 1000_fx, z}), .density = Fixed::epsilon()};
  };
  World w = scene();
  expect_accepted(w, create(box(h)));
  expect_refused(w, create(box(h + kUlp)), {"volume of the box", "2147483647 m^3"});
  // The largest boxes saturate outright: 8 * 10^12 m^3.
  expect_refused(w, create(box(10000_fx)), {"volume", "saturates"});
}

TEST(Refusal, MomentOfInertiaUpToTheLimit) {
  // A cube of half extent 2 and mass m: I = (m / 3) (4 + 4); (m / 3) * 8 is exact, so the largest
  // accepted m / 3 is (2^31 - 1) / 8, and m = 3 times that (exactly divisible again).
  const Fixed third = Fixed::from_raw(kMaxQuantity.raw() / 8);
  const Fixed mass = third * 3_fx;
  ASSERT_EQ(mass / 3_fx, third);
  ASSERT_EQ((mass + 3 * kUlp) / 3_fx, third + kUlp);
  World w = scene();
  expect_accepted(w, create({.shape = cube(2_fx), .mass = mass}));
  EXPECT_EQ(state(w, BodyId{3}).inertia.x, kMaxQuantity);
  expect_refused(w, create({.shape = cube(2_fx), .mass = mass + 3 * kUlp}),
                 {"moment of inertia about x", "kg m^2", "2147483647"});
  // A 10 km sphere of a tonne: 2/5 10^3 10^8 = 4 10^10 kg m^2 (its 2 m r^2 saturates first).
  expect_refused(w, create({.shape = Shape::sphere(10000_fx), .mass = 1000_fx}),
                 {"moment of inertia", "formula"});
  // A 20 km cube of 2^31 - 1 kg: (m / 3) (b^2 + c^2) saturates in its last product.
  expect_refused(w, create({.shape = cube(10000_fx), .mass = kMaxQuantity}),
                 {"moment of inertia about x", "at least 2147483648", "saturates"});
  // 2/5 m r^2 with m = 1.5e9 fits (6e8), but the formula's 2 m does not: refused, not wrong.
  expect_refused(w, create({.shape = Shape::sphere(1_fx), .mass = 1500000000_fx}),
                 {"moment of inertia", "formula"});
}

TEST(Refusal, MassAndInertiaWhoseInversesWouldSaturate) {
  World w = scene();
  // 1 / (2 ulp) = 2^31 saturates; 1 / (3 ulp) fits. A cube of half extent 2 has I = (m / 3) 8.
  expect_refused(w, create({.shape = cube(2_fx), .mass = 2 * kUlp}), {"mass", "below the limit"});
  expect_accepted(w, create({.shape = cube(2_fx), .mass = 3 * kUlp}));
  // A unit sphere: I = 2 m / 5, rounded: 7 ulp gives 3 ulp (accepted), 6 ulp gives 2 (refused).
  ASSERT_EQ(2_fx * (7 * kUlp) * 1_fx / 5_fx, 3 * kUlp);
  ASSERT_EQ(2_fx * (6 * kUlp) * 1_fx / 5_fx, 2 * kUlp);
  expect_accepted(w, create({.shape = Shape::sphere(1_fx), .mass = 7 * kUlp}));
  expect_refused(w, create({.shape = Shape::sphere(1_fx), .mass = 6 * kUlp}),
                 {"moment of inertia about x", "below the limit"});
}

TEST(Refusal, ABodyWithoutInertiaCannotBecomeDynamic) {
  // Found by fuzz/world_api_fuzz.cpp: a static millimetre sphere of water has a mass (4e-6 kg)
  // but moments of inertia that round to zero; set_type(dynamic) accepted it, and the world then
  // saved a state that restore() refuses ("a dynamic body needs ... moments of inertia").
  World w = scene();
  const BodyId grain = add(w, {.type = BodyType::static_body, .shape = Shape::sphere(0.001_fx)});
  ASSERT_GT(state(w, grain).mass, Fixed::zero());
  ASSERT_EQ(state(w, grain).inertia.x, Fixed::zero());
  expect_refused(w, [&](World& x) { return x.set_type(grain, BodyType::dynamic); },
                 {"cannot become dynamic", "moment of inertia"});
  World other;
  EXPECT_TRUE(other.restore(w.save()).ok());
}

TEST(Refusal, PositionsWithinHalfTheRange) {
  World w = scene();
  expect_accepted(w, create({.position = {kHalfRange, -kHalfRange, 0_fx}}));
  expect_refused(w, create({.position = {0_fx, 0_fx, kHalfRange + kUlp}}), {"position z"});
  const BodyId id{2};
  expect_accepted(w, [&](World& x) { return x.set_transform(id, {kHalfRange, 0_fx, 0_fx}, {}); });
  expect_refused(w,
                 [&](World& x) {
                   return x.set_transform(id, {-kHalfRange - kUlp, 0_fx, 0_fx}, {});
                 },
                 {"position x", "1073741824"});
}

TEST(Refusal, VelocitiesWithinHalfTheRangeAndRimSpeedWithinTheLimit) {
  World w = scene();
  const BodyId id{2};
  expect_accepted(w, [&](World& x) { return x.set_linear_velocity(id, {kHalfRange, 0_fx, 0_fx}); });
  expect_refused(w,
                 [&](World& x) {
                   return x.set_linear_velocity(id, {0_fx, kHalfRange + kUlp, 0_fx});
                 },
                 {"linear velocity y"});
  expect_refused(w, create({.linear_velocity = {-kHalfRange - kUlp, 0_fx, 0_fx}}),
                 {"linear velocity x"});
  // A sphere of radius 2: |w| * 2 <= 2^31 - 1, so |w| <= (2^31 - 1) / 2 (exact, and below 2^30).
  const Fixed w_max = kMaxQuantity / 2_fx;
  ASSERT_EQ(w_max * 2_fx, kMaxQuantity);
  expect_accepted(w,
                  create({.shape = Shape::sphere(2_fx), .angular_velocity = {w_max, 0_fx, 0_fx}}));
  expect_refused(
      w, create({.shape = Shape::sphere(2_fx), .angular_velocity = {0_fx, 0_fx, w_max + kUlp}}),
      {"rim speed", "m/s"});
  expect_refused(w,
                 [&](World& x) {
                   return x.set_angular_velocity(id, {0_fx, kHalfRange + kUlp, 0_fx});
                 },
                 {"angular velocity y"});
}

// A light cube: mass 1/8 kg (inverse exactly 8), half extent 1/2.
World light_scene() {
  World w = make_world();
  add_ground(w);
  add(w, {.shape = cube(0.5_fx), .position = {0_fx, 2_fx, 0_fx}, .mass = 0.125_fx});
  return w;
}

TEST(Refusal, ForcesWithinTheAccumulationAndAccelerationLimits) {
  const BodyId id{2};
  {
    // F / m = 8 F <= 2^30: F <= 2^27 exactly; added up over calls.
    World w = light_scene();
    const Fixed f = Fixed::from_int(1 << 27);
    expect_accepted(w, [&](World& x) { return x.apply_force(id, {0_fx, f >> 1, 0_fx}); });
    expect_accepted(w, [&](World& x) { return x.apply_force(id, {0_fx, f >> 1, 0_fx}); });
    expect_refused(w,
                   [&](World& x) {
                     return x.apply_force(id, {0_fx, kUlp, 0_fx});
                   },
                   {"linear acceleration y", "1073741824 m/s^2"});
  }
  {
    // A tonne: the acceleration stays small, the accumulated force itself reaches the limit.
    World w = scene();
    expect_accepted(w, [&](World& x) { return x.apply_force(id, {kMaxQuantity, 0_fx, 0_fx}); });
    expect_refused(w,
                   [&](World& x) {
                     return x.apply_force(id, {kUlp, 0_fx, 0_fx});
                   },
                   {"accumulated force x", "2147483647 N"});
    // |(L, L, 0)| = L sqrt(2): the torque's length is a limit too (its components in any frame).
    expect_refused(w,
                   [&](World& x) {
                     return x.apply_torque(id, {kMaxQuantity, kMaxQuantity, 0_fx});
                   },
                   {"|accumulated torque|"});
  }
  {
    // Angular: |T| / I <= 2^30 with I = (m / 3) (1/4 + 1/4), the cube's moment, and 1 / I rounded.
    World w = light_scene();
    const Fixed inertia = 0.125_fx / 3_fx * (0.25_fx + 0.25_fx);
    ASSERT_EQ(state(w, id).inertia.x, inertia);
    const Fixed inverse = 1_fx / inertia;
    Fixed t = kHalfRange / inverse;  // then the largest t with t * inverse <= 2^30, by ulps
    while (t * inverse > kHalfRange)
      t = t - kUlp;
    while ((t + kUlp) * inverse <= kHalfRange)
      t = t + kUlp;
    World w2 = w;
    expect_accepted(w, [&](World& x) { return x.apply_torque(id, {0_fx, 0_fx, t}); });
    expect_refused(w2,
                   [&](World& x) {
                     return x.apply_torque(id, {0_fx, 0_fx, t + kUlp});
                   },
                   {"angular acceleration", "rad/s^2"});
  }
  {
    // A force far from the centre: its moment r x f saturates.
    World w = scene();
    const Vec3 far{kHalfRange, 0_fx, 0_fx};
    expect_refused(w,
                   [&](World& x) {
                     return x.apply_force_at_point(id, {0_fx, 4_fx, 0_fx}, far);
                   },
                   {"moment about the centre z"});
    expect_refused(
        w,
        [&](World& x) {
          return x.apply_force_at_point(id, {0_fx, 1_fx, 0_fx}, {Fixed::min(), 0_fx, 0_fx});
        },
        {"lever arm (point - centre of mass) x"});
  }
}

TEST(Refusal, ImpulsesWithinTheVelocityLimit) {
  const BodyId id{2};
  World w = light_scene();
  World w2 = w;
  // v = J / m = 8 J <= 2^30: J <= 2^27.
  const Fixed j = Fixed::from_int(1 << 27);
  expect_refused(w,
                 [&](World& x) {
                   return x.apply_linear_impulse(id, {j + kUlp, 0_fx, 0_fx});
                 },
                 {"linear velocity x after the impulse", "1073741824 m/s"});
  expect_accepted(w, [&](World& x) { return x.apply_linear_impulse(id, {j, 0_fx, 0_fx}); });
  EXPECT_EQ(state(w, id).linear_velocity.x, kHalfRange);
  // Angular, at the identity orientation: w = J / I per axis <= 2^30.
  const Fixed inertia = state(w2, id).inertia.x;
  Fixed a = kHalfRange * inertia;
  while (a / inertia > kHalfRange)
    a = a - kUlp;
  while ((a + kUlp) / inertia <= kHalfRange)
    a = a + kUlp;
  World w3 = w2;
  expect_refused(w2,
                 [&](World& x) {
                   return x.apply_angular_impulse(id, {0_fx, a + kUlp, 0_fx});
                 },
                 {"angular velocity y after the impulse"});
  expect_accepted(w3, [&](World& x) { return x.apply_angular_impulse(id, {0_fx, a, 0_fx}); });
  // And at a point: the moment about the centre is checked as for forces.
  expect_refused(
      w2,
      [&](World& x) {
        return x.apply_impulse_at_point(id, {0_fx, 4_fx, 0_fx}, {kHalfRange, 0_fx, 0_fx});
      },
      {"moment about the centre z"});
}

TEST(Refusal, TheExtremeInputTestsAreWithinTheLimitsButOne) {
  // What tests/sim_extreme_test.cpp throws at the world is absurd but representable, and
  // accepted; the speed clamps of the step then apply. One exception: an angular impulse of 1e9
  // N m s per axis on a 0.2 m sphere (I = 0.54 kg m^2) would spin it at 1.9e9 rad/s per axis,
  // above the velocity limit (its length, 3.2e9 rad/s, saturates).
  World w = scene();
  add(w, {.shape = Shape::sphere(0.2_fx), .position = {0_fx, 3_fx, 0_fx}});
  expect_accepted(w, [](World& x) {
    return x.apply_linear_impulse(BodyId{3}, {1000000000_fx, -1000000000_fx, 7_fx});
  });
  expect_refused(
      w,
      [](World& x) {
        return x.apply_angular_impulse(BodyId{3}, {1000000000_fx, 1000000000_fx, 1000000000_fx});
      },
      {"angular velocity x after the impulse"});
  expect_accepted(w, [](World& x) {
    return x.apply_angular_impulse(BodyId{3}, {100000000_fx, 100000000_fx, 100000000_fx});
  });
  expect_accepted(w, [](World& x) {
    return x.apply_force(BodyId{2}, {1000000000_fx, 0_fx, 0_fx});
  });
  expect_accepted(w, [](World& x) {
    return x.set_transform(BodyId{3}, {1000000_fx, 1000000_fx, -1000000_fx}, {});
  });
  for (int i = 0; i < 10; ++i)
    w.step();
  EXPECT_TRUE(w.validate().ok());
}

}  // namespace
}  // namespace detsim
