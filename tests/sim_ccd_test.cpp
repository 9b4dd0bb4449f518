// Continuous collision's candidates: the sort and sweep of swept boxes (sim/src/ccd_pairs.hpp)
// finds exactly the pairs that testing every swept box against every box finds, in the same
// order; and in a world, a bullet whose sweep crosses the boxes of many bodies still stops at the
// far one in its path, from either side and whichever body has the lower ID, and a bullet stops
// at a body whose box starts before its own in the sort. And the sweep of a pair: two bodies that
// move together are never stopped by each other (a body moved back to its first touch taking the
// bodies jointed to it along is tested by the ragdolls scenario, sim_scenario_physics_test.cpp).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

#include "sim/src/ccd_pairs.hpp"
#include "support/sim_helpers.hpp"

namespace detsim {
namespace {

using namespace detsim::literals;

using sim_detail::swept_box_pairs;
using sim_detail::SweptBox;
using test::add;
using test::make_world;
using test::state;

// What the all-pairs loop tested: every swept box against every other box, in index order.
std::vector<std::uint64_t> all_pairs(const std::vector<SweptBox>& boxes) {
  std::vector<SweptBox> by_index = boxes;
  std::sort(by_index.begin(), by_index.end(),
            [](const SweptBox& a, const SweptBox& b) { return a.index < b.index; });
  std::vector<std::uint64_t> pairs;
  for (const SweptBox& a : by_index) {
    if (!a.swept) continue;
    for (const SweptBox& b : by_index) {
      if (a.index == b.index) continue;
      if (a.min.x <= b.max.x && b.min.x <= a.max.x && a.min.y <= b.max.y && b.min.y <= a.max.y &&
          a.min.z <= b.max.z && b.min.z <= a.max.z)
        pairs.push_back((std::uint64_t{a.index} << 32) | b.index);
    }
  }
  return pairs;
}

// Boxes on a coarse grid (so that many share a min x, a max x or a face), a few of them large
// (as a long static floor box is), some swept, with gaps in the indices, in a shuffled order;
// spread ten times wider along `long_axis` (0 x, 1 y, 2 z: the axis the sweep then runs along).
std::vector<SweptBox> random_boxes(Rng& rng, int count, int swept_percent, int long_axis) {
  std::vector<SweptBox> boxes;
  for (int k = 0; k < count; ++k) {
    const auto coordinate = [&rng](bool wide) {
      const int limit = wide ? 200 : 20;
      return Fixed::from_int(static_cast<int>(rng.range(-limit, limit)));
    };
    const auto corner = [&] {
      const Fixed x = coordinate(long_axis == 0);
      const Fixed y = coordinate(long_axis == 1);
      return Vec3{x, y, coordinate(long_axis == 2)};
    };
    const Fixed size_limit = rng.below(20) == 0 ? 40_fx : 4_fx;
    // Whole sizes often, so that boxes touch (max of one = min of another) on every axis.
    const auto size = [&rng, size_limit] {
      return rng.below(2) == 0 ? Fixed::from_int(static_cast<int>(rng.range(0, 4)))
                               : rng.uniform(Fixed::zero(), size_limit);
    };
    SweptBox b;
    b.min = corner();
    b.max = b.min + Vec3{size(), size(), size()};
    if (rng.below(4) == 0) b.max.x = b.min.x;  // flat on x: touching counts
    b.index = static_cast<std::uint32_t>(3 * k + static_cast<int>(rng.below(3)));
    b.swept = static_cast<int>(rng.below(100)) < swept_percent;
    boxes.push_back(b);
  }
  for (std::size_t k = boxes.size(); k > 1; --k)
    std::swap(boxes[k - 1], boxes[rng.below(k)]);
  return boxes;
}

TEST(SweptBoxPairs, AreThePairsOfTheAllPairsTestInItsOrder) {
  Rng rng(11);
  for (const int swept_percent : {0, 3, 30, 100}) {
    for (const int count : {0, 1, 2, 17, 300}) {
      for (int trial = 0; trial < 6; ++trial) {
        const std::vector<SweptBox> boxes = random_boxes(rng, count, swept_percent, trial % 3);
        ASSERT_EQ(swept_box_pairs(boxes), all_pairs(boxes))
            << count << " boxes, " << swept_percent << " % swept, trial " << trial;
      }
    }
  }
}

TEST(SweptBoxPairs, DoNotDependOnTheOrderGiven) {
  Rng rng(12);
  std::vector<SweptBox> boxes = random_boxes(rng, 200, 20, 2);
  const std::vector<std::uint64_t> first = swept_box_pairs(boxes);
  ASSERT_FALSE(first.empty());
  std::reverse(boxes.begin(), boxes.end());
  EXPECT_EQ(swept_box_pairs(boxes), first);
}

// A CCD bullet flies through a field of boxes (static and dynamic, close beside its path)
// towards a crate far beyond them. It must stop at the crate: never end a step on its far side.
struct FarCrate {
  int direction;     // +1: the bullet flies towards +x; -1: towards -x
  bool crate_first;  // the crate has the lower ID
};

class BulletThroughAField : public testing::TestWithParam<FarCrate> {};

TEST_P(BulletThroughAField, StopsAtTheFarCrate) {
  const FarCrate p = GetParam();
  WorldDef def;
  def.gravity = {};
  World w = make_world(def);
  const Fixed dir = Fixed::from_int(p.direction);
  const Fixed half = 0.25_fx;
  const auto crate_def = [&] {
    BodyDef c;
    c.shape = Shape::box({half, half, half});
    c.position = {dir * 72_fx, {}, {}};
    return c;
  };
  BodyId crate;
  if (p.crate_first) crate = add(w, crate_def());
  // The field: boxes every 2 m from x = 2 to 50 on the bullet's side, four around the path at
  // each x, alternately static and dynamic (at rest without gravity). Their faces are 0.1 m from
  // the bullet's path, so their swept boxes overlap the bullet's on every axis and each is swept
  // against in full, but none is touched.
  for (int k = 1; k <= 25; ++k) {
    for (const Vec3 offset : {Vec3{0.45_fx, {}, {}}, Vec3{-0.45_fx, {}, {}}, Vec3{{}, 0.45_fx, {}},
                              Vec3{{}, -0.45_fx, {}}}) {
      BodyDef b;
      b.type = (k % 2 == 0) ? BodyType::static_body : BodyType::dynamic;
      b.shape = Shape::box({half, half, half});
      b.position = {dir * Fixed::from_int(2 * k), offset.x, offset.y};
      add(w, b);
    }
  }
  BodyDef b;
  b.shape = Shape::sphere(0.1_fx);
  // 25 m a step: the step that reaches the crate starts 21.6 m before it, beyond the 20 m cap of
  // the speculative contact margin, so only continuous collision can stop the bullet there.
  b.linear_velocity = {dir * 1500_fx, {}, {}};
  b.ccd = true;
  const BodyId bullet = add(w, b);
  if (!p.crate_first) crate = add(w, crate_def());
  bool hit = false;
  for (int f = 0; f < 10; ++f) {
    w.step();
    const Fixed xb = state(w, bullet).position.x;
    const Fixed xc = state(w, crate).position.x;
    // The bullet's centre stays on its side of the crate: the gap of the two centres, along the
    // flight, is at least the crate's half size and a little less than the bullet's radius.
    EXPECT_GT(dir * (xc - xb), half)
        << "frame " << f << ": bullet at " << to_string(xb) << ", crate at " << to_string(xc);
    hit = hit || state(w, crate).linear_velocity.x != Fixed::zero();
  }
  EXPECT_TRUE(hit) << "the crate never moved: the bullet did not reach it";
}

INSTANTIATE_TEST_SUITE_P(Directions, BulletThroughAField,
                         testing::Values(FarCrate{1, false}, FarCrate{1, true}, FarCrate{-1, false},
                                         FarCrate{-1, true}));

// A bullet dropped onto a long static slab (a box, not a plane): the slab's swept box starts far
// before the bullet's along x, so the pair is found from the slab's side of the sort. The bullet
// starts 23.8 m above the slab (beyond the speculative margin's 20 m cap) and passes it in the
// first step unless continuous collision stops it.
TEST(BulletOntoALongSlab, StaysAboveIt) {
  World w = make_world();
  BodyDef slab;
  slab.type = BodyType::static_body;
  slab.shape = Shape::box({50_fx, 0.1_fx, 50_fx});
  slab.mass = 1_fx;
  add(w, slab);
  BodyDef b;
  b.shape = Shape::sphere(0.1_fx);
  b.position = {3_fx, 24_fx, -2_fx};
  b.linear_velocity = {{}, -1500_fx, {}};
  b.ccd = true;
  const BodyId bullet = add(w, b);
  for (int f = 0; f < 10; ++f) {
    w.step();
    EXPECT_GT(state(w, bullet).position.y, 0.1_fx) << "frame " << f << ": through the slab";
  }
}

// Two fast bodies falling side by side, 1 cm apart (within each other's contact range, so a
// contact pair): their relative motion is zero, so neither may stop the other. The pair's bound
// once summed their travels, every sweep ran out of iterations short of the end, and the box fell
// 0.17 m behind the capsule in a second. They must fall exactly together.
TEST(PairSweep, BodiesMovingTogetherAreNotStoppedByEachOther) {
  World pair = make_world();
  BodyDef box;
  box.shape = Shape::box({0.1_fx, 0.2_fx, 0.18_fx});
  box.mass = 20_fx;
  box.position = {0_fx, 30_fx, 0_fx};
  BodyDef capsule;
  capsule.shape = Shape::capsule(0.04_fx, 0.1_fx);
  capsule.mass = 1.5_fx;
  capsule.position = {0_fx, 30_fx, 0.23_fx};  // 1 cm from the box's face
  const BodyId a = add(pair, box);
  const BodyId b = add(pair, capsule);
  for (int f = 0; f < 90; ++f)  // to 14.7 m/s: far beyond both bodies' "fast" speeds
    pair.step();
  EXPECT_FALSE(pair.contacts().empty());
  EXPECT_LT(state(pair, a).position.y, 30_fx - 10_fx);  // it fell (0.5 g t^2 = 11 m)
  EXPECT_EQ(state(pair, b).position - state(pair, a).position, capsule.position - box.position);
  EXPECT_EQ(state(pair, b).linear_velocity, state(pair, a).linear_velocity);
}

}  // namespace
}  // namespace detsim
