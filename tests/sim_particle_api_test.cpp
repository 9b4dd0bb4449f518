// Particles' API (docs/PARTICLES.md): refusals name the field and change nothing, IDs ascend and
// are never reused, the limits hold, a destroyed body lets its particles go, statistics are what
// the particles say.
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

#include "support/sim_helpers.hpp"

namespace detsim {
namespace {

using namespace detsim::literals;

using test::add;
using test::make_world;

RopeDef a_rope() {
  RopeDef r;
  r.start = {0_fx, 2_fx, 0_fx};
  r.end = {1_fx, 2_fx, 0_fx};
  r.segments = 8;
  return r;
}

ClothDef a_cloth() {
  ClothDef c;
  c.origin = {0_fx, 2_fx, 0_fx};
  c.columns = 4;
  c.rows = 3;
  return c;
}

// A refused definition names `field` and leaves the state's hash as it was.
template <class Def, class Create>
void expect_refused(const Def& def, Create create, const std::string& field) {
  World w = make_world();
  const std::uint64_t before = w.hashes().total;
  auto id = create(w, def);
  ASSERT_FALSE(id.ok()) << "accepted, expected a refusal naming " << field;
  EXPECT_NE(id.message().find(field), std::string::npos) << id.message();
  EXPECT_EQ(w.hashes().total, before);
  EXPECT_TRUE(w.particle_group_ids().empty());
}

auto make_rope = [](World& w, const RopeDef& d) { return w.create_rope(d); };
auto make_cloth = [](World& w, const ClothDef& d) { return w.create_cloth(d); };

TEST(ParticleApi, RopeRefusalsNameTheField) {
  RopeDef d = a_rope();
  d.segments = 0;
  expect_refused(d, make_rope, "segments");
  d = a_rope();
  d.length = 0.5_fx;  // shorter than the 1 m span
  expect_refused(d, make_rope, "length");
  d = a_rope();
  d.mass = 0_fx;
  expect_refused(d, make_rope, "mass");
  d = a_rope();
  d.radius = -1_fx;
  expect_refused(d, make_rope, "radius");
  d = a_rope();
  d.compliance = -1_fx;
  expect_refused(d, make_rope, "compliance");
  d = a_rope();
  d.bending_compliance = -1_fx;
  expect_refused(d, make_rope, "bending_compliance");
  d = a_rope();
  d.attach_start = BodyId{7};
  expect_refused(d, make_rope, "attach_start");
  d = a_rope();
  d.attach_end = BodyId{3};
  expect_refused(d, make_rope, "attach_end");
  d = a_rope();
  d.settings.substeps = 0;
  expect_refused(d, make_rope, "substeps");
  d = a_rope();
  d.settings.friction = -1_fx;
  expect_refused(d, make_rope, "friction");
  d = a_rope();
  d.segments = max_particles_per_group;  // one particle too many
  expect_refused(d, make_rope, "segments");
  d = a_rope();
  d.end = d.start;  // no span and no length
  expect_refused(d, make_rope, "length");
  d = a_rope();
  d.segments = 1000;  // 1 mm links
  expect_refused(d, make_rope, "length / segments");
}

TEST(ParticleApi, ClothRefusalsNameTheField) {
  ClothDef d = a_cloth();
  d.columns = 1;
  expect_refused(d, make_cloth, "columns");
  d = a_cloth();
  d.axis_v = d.axis_u;
  expect_refused(d, make_cloth, "axis_u and axis_v");
  d = a_cloth();
  d.thickness = 0_fx;
  expect_refused(d, make_cloth, "thickness");
  d = a_cloth();
  d.pinned = {12};
  expect_refused(d, make_cloth, "pinned[0]");
  d = a_cloth();
  d.pinned = {3, 1};
  expect_refused(d, make_cloth, "ascending");
  d = a_cloth();
  d.attach_body = BodyId{1};
  d.pinned = {0};
  expect_refused(d, make_cloth, "attach_body");
  d = a_cloth();
  d.tear_strain = -1_fx;
  expect_refused(d, make_cloth, "tear_strain");
  d = a_cloth();
  d.stretch_compliance = -1_fx;
  expect_refused(d, make_cloth, "stretch_compliance");
  d = a_cloth();
  d.columns = 300;
  d.rows = 300;
  expect_refused(d, make_cloth, "columns * rows");
}

auto make_soft = [](World& w, const SoftBodyDef& d) { return w.create_soft_body(d); };

TEST(ParticleApi, SoftBodyRefusalsNameTheField) {
  SoftBodyDef d;
  d.shape = Shape::sphere(1_fx);
  expect_refused(d, make_soft, "shape");
  d = SoftBodyDef{};
  d.resolution = 0;
  expect_refused(d, make_soft, "resolution");
  d = SoftBodyDef{};
  d.resolution = 41;
  expect_refused(d, make_soft, "resolution");
  d = SoftBodyDef{};
  d.resolution = 1;  // one cell along the longest side: one particle per axis
  expect_refused(d, make_soft, "fewer than 2 particles");
  d = SoftBodyDef{};
  d.shape = Shape::box({0.02_fx, 0.02_fx, 0.02_fx});
  d.resolution = 8;  // 5 mm cells
  expect_refused(d, make_soft, "below the smallest");
  d = SoftBodyDef{};
  d.volume_compliance = -1_fx;
  expect_refused(d, make_soft, "volume_compliance");
  d = SoftBodyDef{};
  d.edge_compliance = -1_fx;
  expect_refused(d, make_soft, "edge_compliance");
  d = SoftBodyDef{};
  d.orientation = Quat{2_fx, 0_fx, 0_fx, 0_fx};
  expect_refused(d, make_soft, "orientation");
  d = SoftBodyDef{};
  d.shape = Shape::convex(GeometryId{5});
  expect_refused(d, make_soft, "shape");
}

// A soft body fills its shape: a box with a lattice of resolution cells along its longest side,
// a hull with the cells whose corners are inside it (fewer than its box's).
TEST(ParticleApi, SoftBodiesFillTheirShape) {
  World w = make_world();
  SoftBodyDef box;
  box.shape = Shape::box({0.5_fx, 0.25_fx, 0.25_fx});
  box.resolution = 4;  // cells of 0.25 m: 4 x 2 x 2 particles
  const ParticleGroupId a = w.create_soft_body(box).value();
  const ParticleGroupStats sa = w.particle_group_stats(a).value();
  EXPECT_EQ(sa.particle_count, 16U);
  EXPECT_EQ(sa.type, ParticleGroupType::soft_body);
  // 3 x 1 x 1 cubes of 0.25 m between the particles' centres.
  EXPECT_EQ(sa.rest_volume, 3_fx * 0.25_fx * 0.25_fx * 0.25_fx);
  std::vector<Vec3> corners;
  for (const Fixed x : {-0.5_fx, 0.5_fx})
    for (const Fixed y : {-0.5_fx, 0.5_fx})
      for (const Fixed z : {-0.5_fx, 0.5_fx})
        corners.push_back({x, y, z});
  corners.push_back({0_fx, 0.9_fx, 0_fx});  // a roof: the hull is not its box
  SoftBodyDef hull;
  hull.shape = Shape::convex(w.create_convex_hull(corners).value());
  hull.resolution = 8;
  const ParticleGroupStats sh = w.particle_group_stats(w.create_soft_body(hull).value()).value();
  // Its box is 1 x 1.4 x 1 m: cells of 1.4 / 8 = 0.175 m, a 6 x 8 x 6 lattice centred in it. The
  // six lowest layers (centres up to 0.4625 m) are inside the cube part: 216 particles; the top
  // two only where the roof holds them.
  EXPECT_GE(sh.particle_count, 216U);
  EXPECT_LT(sh.particle_count, 288U);
}

// A ray down onto a rope lying along x meets the particle under it, on its ball's top; the
// bodies' raycasts do not see particles, and a filter that leaves the group's layer out misses.
TEST(ParticleApi, RaysMeetParticlesAsBalls) {
  WorldDef def;
  def.gravity = {};
  World w = make_world(def);
  RopeDef r = a_rope();  // particles every 1/8 m along x at y = 2, radius 0.05
  const ParticleGroupId id = w.create_rope(r).value();
  const auto hit = w.raycast_particles({0.25_fx, 3_fx, 0_fx}, {0_fx, -2_fx, 0_fx});
  ASSERT_TRUE(hit.has_value());
  EXPECT_EQ(hit->group, id);
  EXPECT_EQ(hit->particle, 2U);
  EXPECT_NEAR(hit->point.y.to_double(), 2.05, 1e-6);
  EXPECT_NEAR(hit->fraction.to_double(), 0.475, 1e-6);  // (3 - 2.05) / 2
  EXPECT_NEAR(hit->normal.y.to_double(), 1.0, 1e-6);
  EXPECT_FALSE(w.raycast_closest({0.25_fx, 3_fx, 0_fx}, {0_fx, -2_fx, 0_fx}).has_value());
  QueryFilter other;
  other.layer = 2;
  other.mask = 2;
  EXPECT_FALSE(w.raycast_particles({0.25_fx, 3_fx, 0_fx}, {0_fx, -2_fx, 0_fx}, other));
  EXPECT_FALSE(w.raycast_particles({5_fx, 3_fx, 0_fx}, {0_fx, -2_fx, 0_fx}));
}

TEST(ParticleApi, TheWorldsParticleLimitHolds) {
  World w = make_world();
  ClothDef d = a_cloth();
  d.axis_u = {100_fx, 0_fx, 0_fx};
  d.axis_v = {0_fx, 0_fx, 100_fx};
  d.columns = 256;
  d.rows = 256;  // 65536: the most one group may hold
  for (std::uint32_t k = 0; k < max_particles_per_world / 65536; ++k)
    ASSERT_TRUE(w.create_cloth(d).ok());
  const std::uint64_t before = w.hashes().total;
  auto more = w.create_rope(a_rope());
  ASSERT_FALSE(more.ok());
  EXPECT_NE(more.message().find("max_particles_per_world"), std::string::npos) << more.message();
  EXPECT_EQ(w.hashes().total, before);
}

TEST(ParticleApi, IdsAscendAndAreNeverReused) {
  World w = make_world();
  const ParticleGroupId a = w.create_rope(a_rope()).value();
  const ParticleGroupId b = w.create_cloth(a_cloth()).value();
  EXPECT_EQ(a.value, 1U);
  EXPECT_EQ(b.value, 2U);
  ASSERT_TRUE(w.destroy_particle_group(a).ok());
  EXPECT_FALSE(w.destroy_particle_group(a).ok());
  const ParticleGroupId c = w.create_rope(a_rope()).value();
  EXPECT_EQ(c.value, 3U);
  EXPECT_EQ(w.particle_group_ids(), (std::vector<ParticleGroupId>{b, c}));
  EXPECT_FALSE(w.particle_positions(a).ok());
  EXPECT_FALSE(w.particle_velocities(a).ok());
  EXPECT_FALSE(w.particle_group_stats(a).ok());
  EXPECT_FALSE(w.apply_particle_force(a, {1_fx, 0_fx, 0_fx}).ok());
}

// The rest layout is the definition's: a rope's particles evenly on its line, a sheet's on its
// grid (index = row * columns + column).
TEST(ParticleApi, ParticlesStartWhereTheDefinitionLaysThemOut) {
  World w = make_world();
  const ParticleGroupId rope = w.create_rope(a_rope()).value();
  const std::vector<Vec3> p = w.particle_positions(rope).value();
  ASSERT_EQ(p.size(), 9U);
  for (std::size_t i = 0; i < p.size(); ++i)
    EXPECT_EQ(p[i], (Vec3{Fixed::from_int(static_cast<std::int32_t>(i)) / 8_fx, 2_fx, 0_fx}));
  ClothDef c = a_cloth();
  c.axis_u = {3_fx, 0_fx, 0_fx};
  c.axis_v = {0_fx, 0_fx, 2_fx};
  const ParticleGroupId cloth = w.create_cloth(c).value();
  const std::vector<Vec3> q = w.particle_positions(cloth).value();
  ASSERT_EQ(q.size(), 12U);
  EXPECT_EQ(q[1 * 4 + 2], (Vec3{2_fx, 2_fx, 1_fx}));
  const ParticleGroupStats st = w.particle_group_stats(cloth).value();
  EXPECT_EQ(st.particle_count, 12U);
  // Edges 3 * 3 + 2 * 4, diagonals 2 * 3 * 2, bending 3 * 2 + 1 * 4.
  EXPECT_EQ(st.constraint_count, 17U + 12U + 10U);
  EXPECT_EQ(st.kinetic_energy, 0_fx);
}

// A pinned particle stays where it was created; the others fall.
TEST(ParticleApi, PinnedParticlesStayPut) {
  World w = make_world();
  ClothDef c = a_cloth();
  c.pinned = {0, 3};
  const ParticleGroupId id = w.create_cloth(c).value();
  const std::vector<Vec3> start = w.particle_positions(id).value();
  for (int i = 0; i < 30; ++i)
    w.step();
  const std::vector<Vec3> now = w.particle_positions(id).value();
  EXPECT_EQ(now[0], start[0]);
  EXPECT_EQ(now[3], start[3]);
  EXPECT_LT(now[11].y, start[11].y);
}

// Destroying a body that a rope hangs from lets the rope fall: its end is free.
TEST(ParticleApi, DestroyingTheBodyFreesTheAttachedEnd) {
  World w = make_world();
  BodyDef post;
  post.type = BodyType::static_body;
  post.shape = Shape::sphere(0.05_fx);
  post.position = {0_fx, 2_fx, 0_fx};
  const BodyId p = add(w, post);
  RopeDef r = a_rope();
  r.attach_start = p;
  const ParticleGroupId id = w.create_rope(r).value();
  for (int i = 0; i < 10; ++i)
    w.step();
  EXPECT_EQ(w.particle_positions(id).value()[0], r.start);
  ASSERT_TRUE(w.destroy_body(p).ok());
  for (int i = 0; i < 10; ++i)
    w.step();
  EXPECT_LT(w.particle_positions(id).value()[0].y, r.start.y);
}

// A force on a group accelerates it: F / m over a step in free fall without gravity.
TEST(ParticleApi, AForceMovesTheGroupByItsMass) {
  WorldDef def;
  def.gravity = {};
  World w = make_world(def);
  RopeDef r = a_rope();
  r.mass = 2_fx;
  const ParticleGroupId id = w.create_rope(r).value();
  ASSERT_TRUE(w.apply_particle_force(id, {0_fx, 4_fx, 0_fx}).ok());
  EXPECT_FALSE(w.apply_particle_force(id, {0_fx, Fixed::from_int(1 << 30), 0_fx}).ok());
  w.step();
  // 4 N on 2 kg for 1/60 s: 1/30 m/s on every particle (the links pull evenly, so stay slack),
  // within the rounding of velocities recovered from positions, (x - x_prev) / h: 2^-32 m over
  // h = 1/960 s is 2.2e-7 m/s per small step, 16 of them.
  const std::vector<Vec3> velocities = w.particle_velocities(id).value();
  for (const Vec3& v : velocities)
    EXPECT_NEAR(v.y.to_double(), 2.0 / 60.0, 16 * 2.3e-7);
}

}  // namespace
}  // namespace detsim
