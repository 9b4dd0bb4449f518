// The particle scenes' physical promises (docs/SCENARIOS.md): the wrecking rope holds its ball at
// its length and knocks the boxes over, the drape rests on the sphere, the box and the ground
// without passing through them, the flag streams out in the wind and stays on its pole, and the
// rope bridge sags no more than its ropes allow, the dam break's water stays in its tank and out
// of the obstacle. Each expectation comes from the scene's geometry
// as the World reports it at frame 0 and the physics, never from a run.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

#include "support/scale.hpp"
#include "support/sim_helpers.hpp"

namespace detsim {
namespace {

using namespace detsim::literals;

using test::state;

Scenario make(std::string_view name, const ScenarioParams& p = {}) {
  auto s = Scenario::create(name, p);
  EXPECT_TRUE(s.ok()) << s.message();
  return std::move(s.value());
}

double d(Fixed x) {
  return x.to_double();
}

std::vector<BodyState> bodies_of(const World& w, BodyType type) {
  std::vector<BodyState> out;
  for (const BodyId id : w.body_ids()) {
    const BodyState b = state(w, id);
    if (b.type == type) out.push_back(b);
  }
  return out;
}

std::vector<Vec3> all_particles(const World& w) {
  std::vector<Vec3> out;
  for (const ParticleGroupId id : w.particle_group_ids()) {
    const std::vector<Vec3> p = w.particle_positions(id).value();
    out.insert(out.end(), p.begin(), p.end());
  }
  return out;
}

// The ball hangs on an inextensible rope from a pivot: it is never farther from the pivot than
// the rope's length plus its own radius (1 % for the solver), and its swing scatters the boxes
// standing in its path.
TEST(WreckingRopeScenario, HoldsTheBallAtItsLengthAndKnocksTheBoxesOver) {
  Scenario s = make("wrecking_rope");
  const World& w = s.world();
  const ParticleGroupId rope = w.particle_group_ids().at(0);
  const RopeDef def = w.rope_def(rope).value();
  const double length = d(::detsim::length(def.end - def.start));
  const BodyState ball = state(w, def.attach_end);
  const double reach = length + d(ball.shape.radius);
  const Vec3 pivot = def.start;
  std::vector<BodyState> boxes;
  for (const BodyState& b : bodies_of(w, BodyType::dynamic))
    if (b.id != ball.id) boxes.push_back(b);
  double farthest = 0;
  const std::size_t frames = 300;  // the swing reaches the boxes after ~1.3 s: never scaled down
  for (std::size_t f = 0; f < frames; ++f) {
    s.step();
    farthest = std::max(farthest, d(::detsim::length(state(w, ball.id).position - pivot)));
  }
  EXPECT_LT(farthest, reach * 1.01);
  EXPECT_GT(farthest, reach * 0.99);
  std::size_t moved = 0;
  for (const BodyState& b : boxes)
    moved += d(::detsim::length(state(w, b.id).position - b.position)) > 1.0 ? 1U : 0U;
  EXPECT_GE(moved, boxes.size() / 2);
}

// A sheet dropped over a sphere and a box on the ground comes to rest on them: no particle inside
// the sphere, the box or the ground by more than 5 mm past its own radius, and the sheet lies on
// the sphere's top.
TEST(DrapeScenario, RestsOnTheSphereTheBoxAndTheGroundWithoutPassingThrough) {
  Scenario s = make("drape", {.count = 12});
  const World& w = s.world();
  const ParticleGroupId cloth = w.particle_group_ids().at(0);
  const double radius = d(w.cloth_def(cloth).value().thickness) / 2;
  BodyState sphere;
  BodyState box;
  for (const BodyState& b : bodies_of(w, BodyType::static_body)) {
    if (b.shape.type == ShapeType::sphere) sphere = b;
    if (b.shape.type == ShapeType::box) box = b;
  }
  const double slack = 0.005;
  const std::size_t frames = 300;  // it lands and settles in ~3 s: never scaled down
  for (std::size_t f = 0; f < frames; ++f) {
    s.step();
    for (const Vec3& p : all_particles(w)) {
      EXPECT_GE(d(p.y), radius - slack);
      EXPECT_GE(d(::detsim::length(p - sphere.position)), d(sphere.shape.radius) + radius - slack);
      // Inside the box when within its half extents plus the radius on every axis.
      const Vec3 q = p - box.position;
      const double depth = std::min({d(box.shape.half_extents.x) + radius - std::abs(d(q.x)),
                                     d(box.shape.half_extents.y) + radius - std::abs(d(q.y)),
                                     d(box.shape.half_extents.z) + radius - std::abs(d(q.z))});
      EXPECT_LT(depth, slack) << "frame " << f;
      if (::testing::Test::HasFailure()) return;
    }
  }
  // The sheet covers the sphere: its highest particle is on the sphere's top.
  double top = -1;
  for (const Vec3& p : all_particles(w))
    top = std::max(top, d(p.y));
  const double sphere_top = d(sphere.position.y + sphere.shape.radius) + radius;
  EXPECT_GT(top, sphere_top - slack);
  EXPECT_LT(top, sphere_top + 0.1);
}

// The flag's pinned edge stays on the pole, and a wind of about its own weight (2 to 8 N on
// 0.5 kg, 4.9 N) holds it out: over the last second its far edge is more than half its width
// out from the pole (hanging in still air, it would be under the pole).
TEST(FlagScenario, StreamsOutInTheWindAndStaysOnItsPole) {
  Scenario s = make("flag");
  const World& w = s.world();
  const ParticleGroupId flag = w.particle_group_ids().at(0);
  const ClothDef def = w.cloth_def(flag).value();
  const std::vector<Vec3> start = w.particle_positions(flag).value();
  const std::size_t frames = test::scaled(300);
  double far_x = 0;
  std::size_t samples = 0;
  for (std::size_t f = 0; f < frames; ++f) {
    s.step();
    if (f + 60 < frames) continue;
    const std::vector<Vec3> p = w.particle_positions(flag).value();
    for (std::uint32_t r = 0; r < def.rows; ++r) {
      far_x += d(p[r * def.columns + def.columns - 1].x);
      ++samples;
    }
  }
  const std::vector<Vec3> end = w.particle_positions(flag).value();
  for (const std::uint32_t i : def.pinned)
    EXPECT_EQ(end[i], start[i]) << "pinned particle " << i;
  EXPECT_GT(far_x / double(samples), d(def.origin.x) + d(def.axis_u.x) / 2);
}

// Planks hung on ropes between two posts: the deck can sag no lower than a chain of the same
// length pulled into a V, sqrt((L / 2)^2 - (S / 2)^2) below the posts, L the ropes' and planks'
// total length and S the span; the crates end up on the deck, above the ground.
TEST(RopeBridgeScenario, SagsNoMoreThanItsRopesAllowAndCarriesTheCrates) {
  Scenario s = make("rope_bridge", {.count = 6});
  const World& w = s.world();
  double total = 0;
  double left = 1e9;
  double right = -1e9;
  double deck = 0;
  for (const ParticleGroupId id : w.particle_group_ids()) {
    const RopeDef r = w.rope_def(id).value();
    if (r.start.z > 0_fx) continue;  // one side's ropes
    total += d(r.length);
    left = std::min(left, d(r.start.x));
    right = std::max(right, d(r.end.x));
    deck = d(r.start.y);
  }
  std::vector<BodyState> planks;
  std::vector<BodyState> crates;
  for (const BodyState& b : bodies_of(w, BodyType::dynamic))
    (b.shape.half_extents.y < 0.1_fx ? planks : crates).push_back(b);  // planks are thin
  for (const BodyState& p : planks)
    total += 2 * d(p.shape.half_extents.x);
  const double span = right - left;
  const double lowest = deck - std::sqrt(total * total / 4 - span * span / 4);
  const std::size_t frames = test::scaled(300);
  for (std::size_t f = 0; f < frames; ++f) {
    s.step();
    for (const BodyState& p : planks)
      EXPECT_GT(d(state(w, p.id).position.y), lowest - 0.02) << "frame " << f;
  }
  for (const BodyState& c : crates)
    EXPECT_GT(d(state(w, c.id).position.y), 1.0) << "crate " << c.id.value << " fell through";
}

// Soft cubes dropped on stairs keep their volume (3 %, at volume compliance 0) and never pass
// into a step: every particle over a step stays above its top by its radius (5 mm allowed).
TEST(JellyScenario, CubesKeepTheirVolumeAndStayOnTheSteps) {
  Scenario s = make("jelly", {.count = 3});
  const World& w = s.world();
  std::vector<BodyState> stairs;
  for (const BodyState& b : bodies_of(w, BodyType::static_body))
    if (b.shape.type == ShapeType::box) stairs.push_back(b);
  ASSERT_FALSE(stairs.empty());
  const std::size_t frames = test::scaled(300);
  for (std::size_t f = 0; f < frames; ++f) {
    s.step();
    for (const ParticleGroupId id : w.particle_group_ids()) {
      const ParticleGroupStats st = w.particle_group_stats(id).value();
      EXPECT_NEAR(d(st.volume), d(st.rest_volume), 0.03 * d(st.rest_volume)) << "frame " << f;
      const double radius = d(w.soft_body_def(id).value().shape.half_extents.x) /
                            w.soft_body_def(id).value().resolution;
      const std::vector<Vec3> particles = w.particle_positions(id).value();
      for (const Vec3& p : particles) {
        for (const BodyState& step : stairs) {
          const Vec3 q = p - step.position;
          const Vec3 e = step.shape.half_extents;
          if (abs(q.x) > e.x || abs(q.z) > e.z) continue;  // not over this step
          EXPECT_GT(d(p.y), d(step.position.y + e.y) + radius - 0.005)
              << "frame " << f << " x " << d(q.x) << " of " << d(e.x) << " z " << d(q.z);
        }
      }
      if (::testing::Test::HasFailure()) return;
    }
  }
}

// The dam break (block 4 particles across: a = 0.2 m): the water runs round the obstacle and on
// past it, never leaves the tank or enters the obstacle (no particle centre deeper into a wall
// than its radius), and comes to rest: after 5 s its kinetic energy is below 1 % of the potential
// energy the column's fall released (its centre of mass drops from a to about a thin layer's).
TEST(DamBreakScenario, WaterRunsTheTankAroundTheObstacleAndComesToRest) {
  Scenario s = make("dam_break", {.count = 4});
  const World& w = s.world();
  const ParticleGroupId id = w.particle_group_ids().front();
  const double a = 4 * 0.05;
  const double length = 6 * a;
  const double depth = 2 * a;
  const double r = d(w.fluid_def(id).value().particle_radius);
  // The obstacle: the one static box that is not a wall (its half height is below the walls').
  BodyState obstacle;
  for (const BodyState& b : bodies_of(w, BodyType::static_body)) {
    if (b.shape.half_extents.y < 0.3_fx) obstacle = b;
  }
  ASSERT_EQ(obstacle.shape.type, ShapeType::box);
  const Vec3 lo = obstacle.position - obstacle.shape.half_extents;
  const Vec3 hi = obstacle.position + obstacle.shape.half_extents;
  double mass = 0;
  {
    const ParticleGroupStats st = w.particle_group_stats(id).value();
    mass = st.particle_count * 1000 * 0.05 * 0.05 * 0.05;
  }
  double furthest = 0;
  for (int f = 0; f < 300; ++f) {
    s.step();
    const std::vector<Vec3> p = w.particle_positions(id).value();
    for (const Vec3& q : p) {
      const double x = d(q.x);
      const double y = d(q.y);
      const double z = d(q.z);
      furthest = std::max(furthest, x);
      ASSERT_TRUE(x >= 0 && x <= length && z >= 0 && z <= depth && y >= 0)
          << "frame " << f + 1 << ": a particle left the tank at " << x << ", " << y << ", " << z;
      const bool inside = x > d(lo.x) + r && x < d(hi.x) - r && y < d(hi.y) - r &&
                          z > d(lo.z) + r && z < d(hi.z) - r;
      ASSERT_FALSE(inside) << "frame " << f + 1 << ": a particle is inside the obstacle";
    }
  }
  EXPECT_GT(furthest, d(hi.x) + 2 * r) << "the water never got past the obstacle";
  const ParticleGroupStats st = w.particle_group_stats(id).value();
  EXPECT_LT(d(st.kinetic_energy), 0.01 * mass * 9.81 * a) << "still sloshing after 5 s";
}

}  // namespace
}  // namespace detsim
