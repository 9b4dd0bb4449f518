// Geometry registered with a world (convex hulls): IDs, content hashes, the "geometry" state
// section by hash (restore refuses a state whose geometry the world lacks), snapshots that do not
// grow with the geometry, shapes that name it, and bodies whose centre of mass is off their
// origin. Expected values come from closed forms (a box's moments, the free motion of a rigid
// body: its centre moves in a straight line, its angular momentum is constant), never from a run.
#include <array>
#include <cmath>
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
using test::state;

// The eight corners of the box of half extents h about `centre`.
std::vector<Vec3> box_corners(Vec3 h, Vec3 centre = {}) {
  std::vector<Vec3> out;
  for (const int i : {0, 1, 2, 3, 4, 5, 6, 7})
    out.push_back(centre + Vec3{(i & 1) != 0 ? h.x : -h.x, (i & 2) != 0 ? h.y : -h.y,
                                (i & 4) != 0 ? h.z : -h.z});
  return out;
}

GeometryId hull(World& w, const std::vector<Vec3>& points) {
  auto id = w.create_convex_hull(points);
  EXPECT_TRUE(id.ok()) << id.message();
  return id.ok() ? *id : GeometryId{};
}

BodyDef hull_body(GeometryId g, Vec3 position) {
  BodyDef d;
  d.shape = Shape::convex(g);
  d.position = position;
  return d;
}

TEST(Geometry, AHullIsNamedByItsContentWhateverItsPoints) {
  World a = make_world();
  World b = make_world();
  const std::vector<Vec3> cube = box_corners({0.5_fx, 0.5_fx, 0.5_fx});
  const GeometryId ga = hull(a, cube);
  EXPECT_EQ(ga.value, 1U);
  EXPECT_EQ(a.geometry_count(), 1U);
  // The same corners in another order, with an interior point, a duplicate and a face centre.
  std::vector<Vec3> other(cube.rbegin(), cube.rend());
  other.push_back({});
  other.push_back(cube[3]);
  other.push_back({0.5_fx, 0_fx, 0_fx});
  const GeometryId gb = hull(b, other);
  ASSERT_TRUE(a.geometry_hash(ga).ok());
  EXPECT_EQ(*a.geometry_hash(ga), *b.geometry_hash(gb));
  // A different box is different content.
  const GeometryId gc = hull(b, box_corners({0.5_fx, 0.5_fx, 0.25_fx}));
  EXPECT_EQ(gc.value, 2U);
  EXPECT_NE(*b.geometry_hash(gc), *b.geometry_hash(gb));
  const auto unknown = b.geometry_hash(GeometryId{3});
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.message().find("no geometry with ID 3"), std::string::npos)
      << unknown.message();
}

TEST(Geometry, BadHullsAreRefusedAndRegisterNothing) {
  World w = make_world();
  const std::vector<Vec3> three = {{}, {1_fx, 0_fx, 0_fx}, {0_fx, 1_fx, 0_fx}};
  const auto refused = w.create_convex_hull(three);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.message().find("invalid convex hull"), std::string::npos) << refused.message();
  EXPECT_EQ(w.geometry_count(), 0U);
  const std::vector<Vec3> none;
  EXPECT_FALSE(w.create_convex_hull(none).ok());
  EXPECT_EQ(w.geometry_count(), 0U);
}

TEST(Geometry, ShapesMustNameGeometryOfTheirWorldAndType) {
  World w = make_world();
  const auto expect_refused = [&](const BodyDef& d, const char* part) {
    const std::size_t before = w.body_count();
    const auto r = w.create_body(d);
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.message().find(part), std::string::npos) << r.message();
    EXPECT_EQ(w.body_count(), before);
  };
  expect_refused(hull_body(GeometryId{1}, {}), "geometry ID 1 is not registered");
  const GeometryId g = hull(w, box_corners({0.5_fx, 0.5_fx, 0.5_fx}));
  expect_refused(hull_body(GeometryId{}, {}), "geometry ID 0 is not registered");
  BodyDef sphere;
  sphere.shape = Shape::sphere(1_fx);
  sphere.shape.geometry = g;
  expect_refused(sphere, "a sphere shape has no geometry");
  EXPECT_TRUE(w.create_body(hull_body(g, {})).ok());
  // Queries take the same shapes: an unknown geometry overlaps nothing.
  EXPECT_TRUE(w.overlap(Shape::convex(GeometryId{9}), {}, {}).empty());
  EXPECT_EQ(w.overlap(Shape::convex(g), {0.25_fx, 0_fx, 0_fx}, {}).size(), 1U);
}

TEST(Geometry, RestoreNeedsTheSameGeometryUnderTheSameIds) {
  World saved = make_world();
  const std::vector<Vec3> cube = box_corners({0.5_fx, 0.5_fx, 0.5_fx});
  const GeometryId g = hull(saved, cube);
  add(saved, hull_body(g, {0_fx, 3_fx, 0_fx}));
  for (int i = 0; i < 10; ++i)
    saved.step();
  const std::vector<std::uint8_t> bytes = saved.save();

  // A world without the hull: refused, naming the geometry and its hash, and unchanged.
  World bare = make_world();
  const auto before = bare.save();
  const Status missing = bare.restore(bytes);
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.message().find("the state needs geometry 1 (convex hull, content hash 0x"),
            std::string::npos)
      << missing.message();
  EXPECT_NE(missing.message().find("register the same geometry"), std::string::npos);
  EXPECT_EQ(bare.save(), before);

  // Different geometry under ID 1: refused, naming both hashes.
  World different = make_world();
  hull(different, box_corners({0.5_fx, 0.5_fx, 0.25_fx}));
  const Status mismatch = different.restore(bytes);
  ASSERT_FALSE(mismatch.ok());
  EXPECT_NE(mismatch.message().find("this world's geometry 1 is a convex hull of content hash"),
            std::string::npos)
      << mismatch.message();

  // The same hull (its points in another order): restored exactly, and steps on identically.
  World same = make_world();
  std::vector<Vec3> reversed(cube.rbegin(), cube.rend());
  hull(same, reversed);
  ASSERT_TRUE(same.restore(bytes).ok());
  EXPECT_EQ(same.save(), bytes);
  // Geometry registered after the state was saved is dropped, like bodies created since.
  World more = make_world();
  hull(more, cube);
  hull(more, box_corners({1_fx, 1_fx, 1_fx}));
  ASSERT_TRUE(more.restore(bytes).ok());
  EXPECT_EQ(more.geometry_count(), 1U);
  EXPECT_EQ(more.save(), bytes);
  for (int i = 0; i < 30; ++i) {
    saved.step();
    same.step();
    more.step();
  }
  EXPECT_EQ(same.hashes(), saved.hashes());
  EXPECT_EQ(more.hashes(), saved.hashes());
}

// A snapshot names geometry by hash: a hull of 200 points costs what a cube's does.
TEST(Geometry, TheSnapshotDoesNotGrowWithTheGeometry) {
  const auto state_size = [](const std::vector<Vec3>& points) {
    World w = make_world();
    const GeometryId g = hull(w, points);
    for (int i = 0; i < 20; ++i)
      add(w, hull_body(g, {Fixed::from_int(3 * i), 2_fx, 0_fx}));
    return w.save().size();
  };
  Rng rng(3);
  std::vector<Vec3> ball;
  for (int i = 0; i < 200; ++i)
    ball.push_back(rng.unit_vector());
  const std::size_t cube = state_size(box_corners({0.5_fx, 0.5_fx, 0.5_fx}));
  const std::size_t many = state_size(ball);
  // The bodies' property set holds the centre of mass and principal axes, whose bytes depend on
  // their values; the geometry itself adds nothing.
  EXPECT_LE(many, cube + 64);
}

// Rollback over a registration: a rock registered at frame 5 leaves the state when frame 2 is
// restored, but the world sets it aside, so frame 8 restores after it (and hashes as it did);
// re-simulating registers the same rock again under the same ID; registering another rock there
// instead forgets the set-aside one, and frame 8 is then refused, naming what it needs.
TEST(Geometry, RestoringAnEarlierFrameThenALaterOneKeepsGeometryRegisteredBetween) {
  const std::vector<Vec3> cube = box_corners({0.5_fx, 0.5_fx, 0.5_fx});
  const std::vector<Vec3> slab = box_corners({1_fx, 0.25_fx, 1_fx});
  World w = make_world();
  add(w, hull_body(hull(w, cube), {0_fx, 2_fx, 0_fx}));
  const auto play = [&](World& world, std::uint64_t to) {
    while (world.frame() < to) {
      if (world.frame() == 5) add(world, hull_body(hull(world, slab), {3_fx, 2_fx, 0_fx}));
      world.step();
    }
  };
  play(w, 2);
  const std::vector<std::uint8_t> frame2 = w.save();
  play(w, 8);
  const std::vector<std::uint8_t> frame8 = w.save();
  ASSERT_EQ(w.geometry_count(), 2U);

  ASSERT_TRUE(w.restore(frame2).ok());
  EXPECT_EQ(w.geometry_count(), 1U);
  EXPECT_EQ(w.save(), frame2);
  ASSERT_TRUE(w.restore(frame8).ok()) << "the slab registered at frame 5 was forgotten";
  EXPECT_EQ(w.geometry_count(), 2U);
  EXPECT_EQ(w.save(), frame8);

  // Re-simulating from frame 2 registers the slab again: the same ID, the same frame 8.
  ASSERT_TRUE(w.restore(frame2).ok());
  play(w, 8);
  EXPECT_EQ(w.save(), frame8);

  // Another rock in the slab's place: the slab is forgotten; frame 8 needs it and says so.
  ASSERT_TRUE(w.restore(frame2).ok());
  const GeometryId other = hull(w, box_corners({0.3_fx, 0.3_fx, 0.3_fx}));
  EXPECT_EQ(other.value, 2U);
  const std::vector<std::uint8_t> before = w.save();
  const Status refused = w.restore(frame8);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.message().find("geometry 2 (convex hull"), std::string::npos)
      << refused.message();
  EXPECT_EQ(w.save(), before);
}

TEST(Geometry, ACopyOfAWorldSharesItsGeometryAndStepsTheSame) {
  World w = make_world();
  const GeometryId g = hull(w, box_corners({0.5_fx, 0.25_fx, 0.5_fx}, {0.1_fx, 0_fx, 0_fx}));
  add(w, hull_body(g, {0_fx, 2_fx, 0_fx}));
  World copy = w;
  EXPECT_EQ(copy.geometry_count(), 1U);
  EXPECT_EQ(*copy.geometry_hash(g), *w.geometry_hash(g));
  for (int i = 0; i < 20; ++i) {
    w.step();
    copy.step();
  }
  EXPECT_EQ(copy.save(), w.save());
}

// A box's hull translated off the origin: its centre of mass is the translation and its moments
// the box's, m/3 (b^2 + c^2) with half extents.
TEST(Geometry, AnOffsetHullsMassPropertiesAreTheBoxsAboutItsCentre) {
  World w = make_world();
  const Vec3 h{0.5_fx, 0.25_fx, 1_fx};
  const Vec3 offset{0.3_fx, -0.2_fx, 0.1_fx};
  const GeometryId g = hull(w, box_corners(h, offset));
  const auto m = w.mass_properties(Shape::convex(g), 6_fx);
  ASSERT_TRUE(m.ok()) << m.message();
  const double b2[] = {0.25, 0.0625, 1.0};  // half extents squared
  const double expected[] = {2 * (b2[1] + b2[2]), 2 * (b2[0] + b2[2]), 2 * (b2[0] + b2[1])};
  EXPECT_NEAR(m->inertia.x.to_double(), expected[0], 1e-6 * expected[0]);
  EXPECT_NEAR(m->inertia.y.to_double(), expected[1], 1e-6 * expected[1]);
  EXPECT_NEAR(m->inertia.z.to_double(), expected[2], 1e-6 * expected[2]);
  EXPECT_NEAR(m->center.x.to_double(), 0.3, 1e-8);
  EXPECT_NEAR(m->center.y.to_double(), -0.2, 1e-8);
  EXPECT_NEAR(m->center.z.to_double(), 0.1, 1e-8);
  EXPECT_EQ(m->inertia_axes, Quat::identity());  // a box's tensor is diagonal in its axes

  // A body made of it has those properties, and its centre in world space.
  BodyDef d = hull_body(g, {1_fx, 2_fx, 3_fx});
  d.mass = 6_fx;
  d.orientation = from_axis_angle(Vec3::unit_y(), Fixed::half_pi());  // local x -> world -z
  const BodyState b = state(w, add(w, d));
  EXPECT_EQ(b.center_of_mass, m->center);
  EXPECT_EQ(b.inertia, m->inertia);
  const Vec3 c = b.world_center();
  EXPECT_NEAR(c.x.to_double(), 1.0 + 0.1, 1e-8);
  EXPECT_NEAR(c.y.to_double(), 2.0 - 0.2, 1e-8);
  EXPECT_NEAR(c.z.to_double(), 3.0 - 0.3, 1e-8);
  // Invalid shapes and masses are refused.
  EXPECT_FALSE(w.mass_properties(Shape::convex(GeometryId{7}), 1_fx).ok());
  EXPECT_FALSE(w.mass_properties(Shape::convex(g), 0_fx).ok());
  // The primitives' are the free function's.
  const auto sphere = w.mass_properties(Shape::sphere(1_fx), 2_fx);
  ASSERT_TRUE(sphere.ok());
  EXPECT_EQ(*sphere, mass_properties(Shape::sphere(1_fx), 2_fx));
}

// The angular momentum of a body about its centre, world space, in doubles: R I R^T w with R the
// rotation of orientation * inertia axes.
std::array<double, 3> angular_momentum(const BodyState& b) {
  const Mat3 r = to_mat3(b.orientation * b.inertia_axes);
  double m[3][3];
  for (std::size_t row = 0; row < 3; ++row) {
    m[row][0] = r.rows[row].x.to_double();
    m[row][1] = r.rows[row].y.to_double();
    m[row][2] = r.rows[row].z.to_double();
  }
  const double i[] = {b.inertia.x.to_double(), b.inertia.y.to_double(), b.inertia.z.to_double()};
  const double w[] = {b.angular_velocity.x.to_double(), b.angular_velocity.y.to_double(),
                      b.angular_velocity.z.to_double()};
  double local[3];  // I R^T w
  for (std::size_t k = 0; k < 3; ++k)
    local[k] = i[k] * (m[0][k] * w[0] + m[1][k] * w[1] + m[2][k] * w[2]);
  std::array<double, 3> out{};
  for (std::size_t row = 0; row < 3; ++row)
    out[row] = m[row][0] * local[0] + m[row][1] * local[1] + m[row][2] * local[2];
  return out;
}

// An off-centre hull in zero gravity, spinning about a principal axis that is none of the body's:
// its centre of mass moves in a straight line at constant speed and its angular momentum about the
// centre stays what it was (torque-free motion). The step integrates no gyroscopic torque
// (docs/SIM.md): a spin about a principal axis needs none; one about another axis would keep its
// angular velocity instead of precessing.
TEST(Geometry, AnOffCentreBodyTumblesAboutItsCentreOfMass) {
  WorldDef def;
  def.gravity = {};
  def.enable_sleep = false;
  World w = make_world(def);
  // An unequal box, off the origin along x and y, and turned so its axes are not the body's.
  const Quat turn = from_axis_angle(normalize(Vec3{1_fx, 2_fx, 3_fx}), 0.7_fx);
  std::vector<Vec3> points;
  for (const Vec3 p : box_corners({0.6_fx, 0.2_fx, 0.35_fx}))
    points.push_back(rotate(turn, p) + Vec3{0.8_fx, 0.3_fx, 0_fx});
  const GeometryId g = hull(w, points);
  BodyDef d = hull_body(g, {0_fx, 10_fx, 0_fx});
  d.linear_velocity = {1_fx, 0.5_fx, -0.25_fx};
  d.angular_velocity = rotate(turn, Vec3{0_fx, 0_fx, 3_fx});  // the box's z axis
  const BodyId id = add(w, d);
  const BodyState start = state(w, id);
  EXPECT_NE(start.inertia_axes, Quat::identity());
  const Vec3 c0 = start.world_center();
  const Vec3 v0 = start.linear_velocity;
  const auto l0 = angular_momentum(start);
  const double l0_length = std::sqrt(l0[0] * l0[0] + l0[1] * l0[1] + l0[2] * l0[2]);
  for (int frame = 1; frame <= 240; ++frame) {
    w.step();
    const BodyState b = state(w, id);
    // The centre: c0 + v0 t (to a micrometre: rounding of the origin derived from it each step).
    const double t = frame / 60.0;
    const Vec3 c = b.world_center();
    ASSERT_NEAR(c.x.to_double(), c0.x.to_double() + v0.x.to_double() * t, 1e-6) << frame;
    ASSERT_NEAR(c.y.to_double(), c0.y.to_double() + v0.y.to_double() * t, 1e-6) << frame;
    ASSERT_NEAR(c.z.to_double(), c0.z.to_double() + v0.z.to_double() * t, 1e-6) << frame;
    EXPECT_EQ(b.linear_velocity, v0);
    const auto l = angular_momentum(b);
    const double dl = std::sqrt((l[0] - l0[0]) * (l[0] - l0[0]) + (l[1] - l0[1]) * (l[1] - l0[1]) +
                                (l[2] - l0[2]) * (l[2] - l0[2]));
    ASSERT_LE(dl, 0.005 * l0_length) << "frame " << frame;
  }
  // It did tumble: the origin went round the centre rather than along with it.
  const BodyState end = state(w, id);
  EXPECT_NE(end.orientation, start.orientation);
}

// An impulse through the centre of mass turns nothing; one through the origin of an off-centre
// body does (the lever arm is from the centre).
TEST(Geometry, ImpulsesActAboutTheCentreOfMass) {
  WorldDef def;
  def.gravity = {};
  World w = make_world(def);
  const GeometryId g = hull(w, box_corners({0.5_fx, 0.5_fx, 0.5_fx}, {1_fx, 0_fx, 0_fx}));
  const BodyId through_centre = add(w, hull_body(g, {0_fx, 0_fx, 0_fx}));
  const BodyId through_origin = add(w, hull_body(g, {0_fx, 0_fx, 10_fx}));
  const Vec3 up{0_fx, 1_fx, 0_fx};
  ASSERT_TRUE(
      w.apply_impulse_at_point(through_centre, up, state(w, through_centre).world_center()).ok());
  ASSERT_TRUE(w.apply_impulse_at_point(through_origin, up, state(w, through_origin).position).ok());
  EXPECT_EQ(state(w, through_centre).angular_velocity, Vec3{});
  // Arm from the centre to the origin: (-1, 0, 0); (-1, 0, 0) x (0, 1, 0) = (0, 0, -1): about -z.
  const Vec3 spin = state(w, through_origin).angular_velocity;
  EXPECT_LT(spin.z, 0_fx);
  EXPECT_EQ(spin.x, 0_fx);
  EXPECT_EQ(spin.y, 0_fx);
}

}  // namespace
}  // namespace detsim
