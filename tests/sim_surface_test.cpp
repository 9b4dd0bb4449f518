// Triangle meshes and heightfields as static shapes of a World (World::create_mesh,
// World::create_heightfield, Shape::mesh, Shape::heightfield): registration and its refusals, the
// dropped-triangle count, content hashes, ray casts on posed bodies, overlap queries, save and
// restore, and the static-only rule. Expected hits come from the analytic plane of each flat or
// tilted surface (t from the plane equation) and from the geometry's own raycast in its frame,
// never from a recorded run.
//
// Not yet: collisions. The mesh narrowphase is another change; until it lands a mesh or
// heightfield pair has no manifold, so nothing here asserts a contact or an overlap hit that needs
// one — only what holds now and will still hold then.
#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

#include "sim/src/geometry/heightfield.hpp"
#include "sim/src/geometry/mesh.hpp"
#include "support/sim_helpers.hpp"

namespace detsim {
namespace {

using namespace detsim::literals;

using test::add;
using test::make_world;
using test::near;

// The square [-2, 2] x [-2, 2] in the local y = 0 plane, as two triangles facing +y.
const std::vector<Vec3> kSquare = {
    {-2_fx, 0_fx, -2_fx}, {2_fx, 0_fx, -2_fx}, {2_fx, 0_fx, 2_fx}, {-2_fx, 0_fx, 2_fx}};
const std::vector<std::uint32_t> kSquareIndices = {0, 2, 1, 0, 3, 2};

// A tilted heightfield: 5 rows (z = 0..4) by 6 columns (x = 0..5) of 1 m cells on the plane
// y = x / 4 - z / 2 + 1, i.e. -x / 4 + y + z / 2 = 1 (every sample exact in Fixed).
HeightfieldDef tilted_heightfield() {
  HeightfieldDef d;
  d.rows = 5;
  d.columns = 6;
  d.cell_size = 1_fx;
  for (std::uint32_t r = 0; r < d.rows; ++r) {
    for (std::uint32_t c = 0; c < d.columns; ++c)
      d.heights.push_back(Fixed::from_int(static_cast<std::int32_t>(c)) / 4_fx -
                          Fixed::from_int(static_cast<std::int32_t>(r)) / 2_fx + 1_fx);
  }
  return d;
}
// The plane of tilted_heightfield: dot(kTiltNormal, x) = 1 (kTiltNormal not unit).
const Vec3 kTiltNormal{-0.25_fx, 1_fx, 0.5_fx};

GeometryId mesh(World& w, const std::vector<Vec3>& v, const std::vector<std::uint32_t>& i) {
  auto id = w.create_mesh(v, i);
  EXPECT_TRUE(id.ok()) << id.message();
  return id.ok() ? *id : GeometryId{};
}

GeometryId heightfield(World& w, const HeightfieldDef& d) {
  auto id = w.create_heightfield(d);
  EXPECT_TRUE(id.ok()) << id.message();
  return id.ok() ? *id : GeometryId{};
}

// A pose that is neither axis-aligned nor at the origin.
const Vec3 kAt{3_fx, 1_fx, -2_fx};
Quat posed() {
  return from_axis_angle(normalize(Vec3{1_fx, 2_fx, -1_fx}), 0.7_fx);
}

// World <-> body frame for a body at kAt with orientation posed().
Vec3 to_local(Vec3 world) {
  return rotate(conjugate(posed()), world - kAt);
}
Vec3 to_world(Vec3 local) {
  return kAt + rotate(posed(), local);
}

constexpr Fixed kTolerance = Fixed::from_raw(Fixed::one_raw >> 20);  // ~1e-6 m

::testing::AssertionResult near(Vec3 a, Vec3 b, Fixed tolerance) {
  if (abs(a.x - b.x) <= tolerance && abs(a.y - b.y) <= tolerance && abs(a.z - b.z) <= tolerance)
    return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "(" << a.x.to_double() << ", " << a.y.to_double() << ", " << a.z.to_double() << ") vs ("
         << b.x.to_double() << ", " << b.y.to_double() << ", " << b.z.to_double() << ")";
}

TEST(Surface, BadMeshesAndHeightfieldsAreRefusedNamingTheProblemAndRegisterNothing) {
  World w = make_world();
  const auto refused_mesh = [&](const std::vector<Vec3>& v, const std::vector<std::uint32_t>& i,
                                const std::string& part) {
    const auto r = w.create_mesh(v, i);
    ASSERT_FALSE(r.ok()) << part;
    EXPECT_NE(r.message().find(part), std::string::npos) << r.message();
    EXPECT_EQ(w.geometry_count(), 0U);
  };
  refused_mesh(kSquare, {0, 2, 1, 0, 3, 12},
               "invalid mesh: triangle 1: index 2 is 12, but there are 4 vertices");
  refused_mesh(kSquare, {0, 2, 1, 0}, "invalid mesh: the index count must be a multiple of 3");
  refused_mesh({{0_fx, 0_fx, 0_fx}, {10001_fx, 0_fx, 0_fx}, {0_fx, 0_fx, 1_fx}}, {0, 1, 2},
               "invalid mesh: vertex 1 x is 10001, must be within +-10000");
  refused_mesh(kSquare, {0, 0, 1, 2, 2, 2}, "invalid mesh: no triangle left after dropping 2");
  refused_mesh({}, {}, "invalid mesh");

  const auto refused_heightfield = [&](const HeightfieldDef& d, const std::string& part) {
    const auto r = w.create_heightfield(d);
    ASSERT_FALSE(r.ok()) << part;
    EXPECT_NE(r.message().find(part), std::string::npos) << r.message();
    EXPECT_EQ(w.geometry_count(), 0U);
  };
  HeightfieldDef d = tilted_heightfield();
  d.rows = 1;
  refused_heightfield(d, "invalid heightfield: rows must be in 2..4096, got 1");
  d = tilted_heightfield();
  d.heights.pop_back();
  refused_heightfield(d,
                      "invalid heightfield: heights must hold rows * columns = 30 values, got 29");
  d = tilted_heightfield();
  d.cell_size = Fixed::zero();
  refused_heightfield(d, "invalid heightfield: cell_size must be >= 2^-10, got 0");
  d = tilted_heightfield();
  d.heights[7] = Fixed::max();
  refused_heightfield(d, "invalid heightfield: height at row 1, column 1 is");

  // A good one after all that gets ID 1.
  EXPECT_EQ(mesh(w, kSquare, kSquareIndices).value, 1U);
}

TEST(Surface, DegenerateTrianglesAreDroppedAndCountedExactly) {
  World w = make_world();
  // The square's two triangles, then three degenerate ones over the same vertices (repeated
  // indices) and one of zero area over a collinear vertex (4, on the edge from 0 to 1).
  std::vector<Vec3> v = kSquare;
  v.push_back({0_fx, 0_fx, -2_fx});
  const std::vector<std::uint32_t> i = {0, 2, 1, 0, 0, 1, 1, 2, 2, 3, 3, 3, 0, 3, 2, 0, 4, 1};
  const GeometryId g = mesh(w, v, i);
  ASSERT_TRUE(w.mesh_dropped_triangles(g).ok());
  EXPECT_EQ(*w.mesh_dropped_triangles(g), 4U);
  const GeometryId clean = mesh(w, kSquare, kSquareIndices);
  EXPECT_EQ(*w.mesh_dropped_triangles(clean), 0U);
  // Errors name the ID: unknown, or not a mesh.
  const GeometryId hf = heightfield(w, tilted_heightfield());
  const auto unknown = w.mesh_dropped_triangles(GeometryId{9});
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.message().find("no geometry with ID 9"), std::string::npos);
  const auto not_mesh = w.mesh_dropped_triangles(hf);
  ASSERT_FALSE(not_mesh.ok());
  EXPECT_NE(not_mesh.message().find("geometry 3 is a heightfield, not a triangle mesh"),
            std::string::npos)
      << not_mesh.message();
}

TEST(Surface, TheContentHashNamesTheDataNotTheWorld) {
  World a = make_world();
  World b = make_world();
  ASSERT_TRUE(
      b
          .create_convex_hull(std::vector<Vec3>{
              {0_fx, 0_fx, 0_fx}, {1_fx, 0_fx, 0_fx}, {0_fx, 1_fx, 0_fx}, {0_fx, 0_fx, 1_fx}})
          .ok());
  const GeometryId ma = mesh(a, kSquare, kSquareIndices);
  const GeometryId mb = mesh(b, kSquare, kSquareIndices);  // ID 2 there
  EXPECT_EQ(mb.value, 2U);
  EXPECT_EQ(*a.geometry_hash(ma), *b.geometry_hash(mb));
  // Degenerate triangles describe the input, not the mesh: the same hash.
  const GeometryId with_dropped = mesh(b, kSquare, {0, 2, 1, 1, 1, 2, 0, 3, 2});
  EXPECT_EQ(*b.geometry_hash(with_dropped), *a.geometry_hash(ma));
  // Other data: other hashes (a moved vertex, another triangle order, a flipped triangle).
  std::vector<Vec3> moved = kSquare;
  moved[2].y = 0.5_fx;
  EXPECT_NE(*b.geometry_hash(mesh(b, moved, kSquareIndices)), *a.geometry_hash(ma));
  EXPECT_NE(*b.geometry_hash(mesh(b, kSquare, {0, 3, 2, 0, 2, 1})), *a.geometry_hash(ma));
  EXPECT_NE(*b.geometry_hash(mesh(b, kSquare, {0, 1, 2, 0, 3, 2})), *a.geometry_hash(ma));

  const GeometryId ha = heightfield(a, tilted_heightfield());
  const GeometryId hb = heightfield(b, tilted_heightfield());
  EXPECT_EQ(*a.geometry_hash(ha), *b.geometry_hash(hb));
  HeightfieldDef other = tilted_heightfield();
  other.heights[3] += 0.125_fx;
  EXPECT_NE(*b.geometry_hash(heightfield(b, other)), *a.geometry_hash(ha));
  other = tilted_heightfield();
  other.cell_size = 2_fx;
  EXPECT_NE(*b.geometry_hash(heightfield(b, other)), *a.geometry_hash(ha));

  // The same triangles as a mesh and as a heightfield are different geometry (the type byte).
  HeightfieldDef flat;
  flat.rows = 2;
  flat.columns = 2;
  flat.cell_size = 1_fx;
  flat.heights.assign(4, Fixed::zero());
  const std::vector<Vec3> corners = {
      {0_fx, 0_fx, 0_fx}, {1_fx, 0_fx, 0_fx}, {0_fx, 0_fx, 1_fx}, {1_fx, 0_fx, 1_fx}};
  EXPECT_NE(*a.geometry_hash(heightfield(a, flat)),
            *a.geometry_hash(mesh(a, corners, {0, 2, 3, 0, 3, 1})));
}

// Rays at points of a posed mesh from above and from below: World::raycast_closest gives the
// analytic hit (the plane y = 0 of the body's frame, t = -o.y / d.y), the geometry's own raycast
// in the body's frame placed in the world, and the normal turned towards the ray's origin.
TEST(Surface, RaysOnAPosedMeshHitItsPlaneFromEitherSide) {
  World w = make_world();
  const GeometryId g = mesh(w, kSquare, kSquareIndices);
  const BodyId body = add(w, test::static_placed(Shape::mesh(g), kAt, posed()));
  auto own = sim_detail::build_mesh(kSquare, kSquareIndices);
  ASSERT_TRUE(own.ok());
  const std::array<Vec3, 4> targets = {Vec3{0.3_fx, 0_fx, 0.2_fx}, Vec3{-1.7_fx, 0_fx, 1.1_fx},
                                       Vec3{1.9_fx, 0_fx, -1.9_fx}, Vec3{-0.5_fx, 0_fx, -1.25_fx}};
  const std::array<Vec3, 2> offsets = {Vec3{0.4_fx, 3_fx, -0.3_fx}, Vec3{-0.2_fx, -2.5_fx, 0.6_fx}};
  for (const Vec3 target : targets) {
    for (const Vec3 offset : offsets) {
      const Vec3 origin = to_world(target + offset);
      const Vec3 translation = (to_world(target) - origin) * 2_fx;
      const auto hit = w.raycast_closest(origin, translation);
      ASSERT_TRUE(hit.has_value());
      EXPECT_EQ(hit->body, body);
      // Analytic: in the body frame the ray is o + d s, s in [0, 1]; the plane y = 0 at s = -o.y /
      // d.y.
      const Vec3 o = to_local(origin);
      const Vec3 d = rotate(conjugate(posed()), translation);
      const Fixed s = -o.y / d.y;
      EXPECT_TRUE(near(hit->fraction, s, kTolerance));
      EXPECT_TRUE(near(hit->fraction, 0.5_fx, kTolerance));
      EXPECT_TRUE(near(hit->point, to_world(target), kTolerance));
      const Vec3 up = rotate(posed(), Vec3::unit_y());
      EXPECT_TRUE(near(hit->normal, offset.y > Fixed::zero() ? up : -up, kTolerance));
      // The geometry's own answer, in its frame, placed.
      const Vec3 v = normalize(d);
      const auto local = sim_detail::raycast(*own, o, v, Fixed::max());
      ASSERT_TRUE(local.has_value());
      EXPECT_TRUE(near(hit->point, to_world(local->point), kTolerance));
      EXPECT_TRUE(near(hit->normal, rotate(posed(), local->normal), kTolerance));
      EXPECT_TRUE(near(hit->fraction, local->t / length(d), kTolerance));
    }
  }
  // Beside the square, and short of it: no hit.
  EXPECT_FALSE(
      w.raycast_closest(to_world({2.5_fx, 3_fx, 0_fx}), rotate(posed(), {0_fx, -6_fx, 0_fx}))
          .has_value());
  EXPECT_FALSE(w.raycast_closest(to_world({0_fx, 3_fx, 0_fx}), rotate(posed(), {0_fx, -2_fx, 0_fx}))
                   .has_value());
}

// The tilted heightfield, posed: hits on its plane -x/4 + y + z/2 = 1 (body frame), with
// t = (1 - n.o) / (n.d) from the plane equation.
TEST(Surface, RaysOnAPosedTiltedHeightfieldHitItsPlane) {
  World w = make_world();
  const GeometryId g = heightfield(w, tilted_heightfield());
  const BodyId body = add(w, test::static_placed(Shape::heightfield(g), kAt, posed()));
  auto own = sim_detail::build_heightfield(tilted_heightfield());
  ASSERT_TRUE(own.ok());
  const Vec3 unit_normal = normalize(kTiltNormal);
  const auto on_plane = [](Fixed x, Fixed z) { return Vec3{x, x / 4_fx - z / 2_fx + 1_fx, z}; };
  const std::array<Vec3, 4> targets = {on_plane(2.3_fx, 1.7_fx), on_plane(0.1_fx, 3.9_fx),
                                       on_plane(4.6_fx, 0.35_fx), on_plane(3.5_fx, 2.25_fx)};
  const std::array<Vec3, 3> offsets = {Vec3{0.4_fx, 3_fx, -0.3_fx}, Vec3{-0.2_fx, -2.5_fx, 0.6_fx},
                                       Vec3{1_fx, 1_fx, 1_fx}};
  for (const Vec3 target : targets) {
    for (const Vec3 offset : offsets) {
      const Vec3 origin = to_world(target + offset);
      const Vec3 translation = (to_world(target) - origin) * 2_fx;
      const auto hit = w.raycast_closest(origin, translation);
      ASSERT_TRUE(hit.has_value());
      EXPECT_EQ(hit->body, body);
      const Vec3 o = to_local(origin);
      const Vec3 d = rotate(conjugate(posed()), translation);
      const Fixed s = (1_fx - dot(kTiltNormal, o)) / dot(kTiltNormal, d);
      EXPECT_TRUE(near(hit->fraction, s, kTolerance));
      EXPECT_TRUE(near(hit->point, to_world(target), kTolerance));
      const bool above = dot(kTiltNormal, offset) > Fixed::zero();
      const Vec3 n = rotate(posed(), unit_normal);
      EXPECT_TRUE(near(hit->normal, above ? n : -n, kTolerance));
      const auto local = sim_detail::raycast(*own, o, normalize(d), Fixed::max());
      ASSERT_TRUE(local.has_value());
      EXPECT_TRUE(near(hit->point, to_world(local->point), kTolerance));
      EXPECT_TRUE(near(hit->normal, rotate(posed(), local->normal), kTolerance));
    }
  }
}

// raycast_all sees surfaces like any body: one hit per body, ascending by fraction.
TEST(Surface, RaycastAllOrdersSurfacesWithOtherBodies) {
  World w = make_world();
  const GeometryId m = mesh(w, kSquare, kSquareIndices);
  const GeometryId h = heightfield(w, tilted_heightfield());
  const BodyId low = add(w, test::static_placed(Shape::mesh(m), {0_fx, 0_fx, 0_fx}));
  // The heightfield above it, shifted so that x = z = 0 of the world is its sample (2, 2): there
  // its height is 2/4 - 2/2 + 1 = 0.5, so the surface is at y = 3.5 over the origin.
  const BodyId high = add(w, test::static_placed(Shape::heightfield(h), {-2_fx, 3_fx, -2_fx}));
  BodyDef ball;
  ball.shape = Shape::sphere(0.5_fx);
  ball.position = {0_fx, 10_fx, 0_fx};
  const BodyId top = add(w, ball);
  const auto hits = w.raycast_all({0_fx, 20_fx, 0_fx}, {0_fx, -40_fx, 0_fx});
  ASSERT_EQ(hits.size(), 3U);
  EXPECT_EQ(hits[0].body, top);
  EXPECT_EQ(hits[1].body, high);
  EXPECT_EQ(hits[2].body, low);
  EXPECT_TRUE(near(hits[1].point.y, 3.5_fx, kTolerance));
  EXPECT_TRUE(near(hits[2].point.y, 0_fx, kTolerance));
  EXPECT_TRUE(near(hits[2].fraction, 0.5_fx, kTolerance));
  // From below, the same surfaces in the other order, their normals facing down.
  const auto up = w.raycast_all({0_fx, -20_fx, 0_fx}, {0_fx, 40_fx, 0_fx});
  ASSERT_EQ(up.size(), 3U);
  EXPECT_EQ(up[0].body, low);
  EXPECT_EQ(up[1].body, high);
  EXPECT_TRUE(near(up[0].normal, -Vec3::unit_y(), kTolerance));
  EXPECT_EQ(w.raycast_closest({0_fx, -20_fx, 0_fx}, {0_fx, 40_fx, 0_fx})->body, low);
}

// A surface has no inside: a ray that starts on it hits it at fraction 0 (the geometry's raycast
// meets its plane at t = 0), its normal against the ray whichever way it goes; a point query (a
// zero translation) never hits it.
TEST(Surface, ARayStartingOnTheSurfaceHitsItAtZeroAndAPointNever) {
  World w = make_world();
  const GeometryId m = mesh(w, kSquare, kSquareIndices);
  const BodyId body = add(w, test::static_placed(Shape::mesh(m), {0_fx, 1_fx, 0_fx}));
  const Vec3 on{0.3_fx, 1_fx, 0.2_fx};
  const auto down = w.raycast_closest(on, {0_fx, -1_fx, 0_fx});
  ASSERT_TRUE(down.has_value());
  EXPECT_EQ(down->body, body);
  EXPECT_EQ(down->fraction, Fixed::zero());
  EXPECT_TRUE(near(down->normal, Vec3::unit_y(), kTolerance));
  const auto up = w.raycast_closest(on, {0_fx, 1_fx, 0_fx});
  ASSERT_TRUE(up.has_value());
  EXPECT_EQ(up->fraction, Fixed::zero());
  EXPECT_TRUE(near(up->normal, -Vec3::unit_y(), kTolerance));
  EXPECT_FALSE(w.raycast_closest(on, Vec3::zero()).has_value());
  EXPECT_FALSE(w.raycast_closest({0_fx, 0.5_fx, 0_fx}, Vec3::zero()).has_value());
  // Along the surface, in its plane: no crossing, no hit.
  EXPECT_FALSE(w.raycast_closest({-5_fx, 1_fx, 0.1_fx}, {10_fx, 0_fx, 0_fx}).has_value());
}

// Overlap queries with surfaces in the world. What holds now and after the mesh narrowphase:
// a sphere far from every surface overlaps none of them, a surface is never a query shape (a
// moving body cannot have one), and the other bodies are found as before. (A sphere that crosses
// the surface finds it only once the narrowphase has a mesh pair: not asserted here.)
TEST(Surface, OverlapQueriesSkipSurfacesFarAwayAndStillFindOtherBodies) {
  World w = make_world();
  const GeometryId m = mesh(w, kSquare, kSquareIndices);
  const GeometryId h = heightfield(w, tilted_heightfield());
  const BodyId ground = add(w, test::static_placed(Shape::mesh(m)));
  const BodyId hill = add(w, test::static_placed(Shape::heightfield(h), {10_fx, 0_fx, 0_fx}));
  BodyDef ball;
  ball.shape = Shape::sphere(0.5_fx);
  ball.position = {0_fx, 0.25_fx, 0_fx};
  const BodyId resting = add(w, ball);
  const Shape probe = Shape::sphere(0.5_fx);
  EXPECT_TRUE(w.overlap(probe, {0_fx, 5_fx, 0_fx}, {}).empty());
  EXPECT_TRUE(w.overlap(probe, {12_fx, -5_fx, 2_fx}, {}).empty());
  EXPECT_TRUE(w.overlap(probe, {30_fx, 0_fx, 0_fx}, {}).empty());
  // Crossing the square and touching the ball: the ball is found (and, later, the square).
  const auto near_ground = w.overlap(probe, {0.5_fx, 0_fx, 0_fx}, {});
  EXPECT_NE(std::find(near_ground.begin(), near_ground.end(), resting), near_ground.end());
  for (const BodyId id : near_ground)
    EXPECT_TRUE(id == resting || id == ground) << id.value;
  const auto near_hill = w.overlap(probe, {12_fx, 1.5_fx, 2_fx}, {});
  for (const BodyId id : near_hill)
    EXPECT_EQ(id, hill);
  // Surfaces are not query shapes.
  EXPECT_TRUE(w.overlap(Shape::mesh(m), {}, {}).empty());
  EXPECT_TRUE(w.overlap(Shape::heightfield(h), {}, {}).empty());
}

TEST(Surface, ASurfaceNeedsAStaticBodyAndStaysStatic) {
  World w = make_world();
  const GeometryId m = mesh(w, kSquare, kSquareIndices);
  const GeometryId h = heightfield(w, tilted_heightfield());
  for (const auto& [shape, name] : {std::pair{Shape::mesh(m), std::string("triangle mesh")},
                                    std::pair{Shape::heightfield(h), std::string("heightfield")}}) {
    for (const BodyType type : {BodyType::dynamic, BodyType::kinematic}) {
      BodyDef d = test::static_placed(shape);
      d.type = type;
      const auto r = w.create_body(d);
      ASSERT_FALSE(r.ok());
      EXPECT_NE(r.message().find("a " + name + " shape needs a static body"), std::string::npos)
          << r.message();
    }
    const std::size_t before = w.body_count();
    const BodyId id = add(w, test::static_placed(shape));
    EXPECT_EQ(w.body_count(), before + 1);
    const Status s = w.set_type(id, BodyType::dynamic);
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.message().find("is a " + name + ": it must stay static"), std::string::npos)
        << s.message();
    EXPECT_EQ(test::state(w, id).type, BodyType::static_body);
    EXPECT_FALSE(w.set_type(id, BodyType::kinematic).ok());
    // A shape of the wrong geometry type is refused, naming it.
    const auto wrong = w.create_body(test::static_placed(
        shape.type == ShapeType::mesh ? Shape::mesh(h) : Shape::heightfield(m)));
    ASSERT_FALSE(wrong.ok());
    EXPECT_NE(wrong.message().find("shape's geometry ID"), std::string::npos) << wrong.message();
  }
}

TEST(Surface, SaveAndRestoreNameTheMeshByItsHash) {
  World saved = make_world();
  const GeometryId m = mesh(saved, kSquare, kSquareIndices);
  const GeometryId h = heightfield(saved, tilted_heightfield());
  add(saved, test::static_placed(Shape::mesh(m), kAt, posed()));
  add(saved, test::static_placed(Shape::heightfield(h), {-10_fx, 0_fx, 0_fx}));
  BodyDef ball;
  ball.shape = Shape::sphere(0.5_fx);
  ball.position = {20_fx, 3_fx, 0_fx};
  add(saved, ball);
  for (int i = 0; i < 10; ++i)
    saved.step();
  const std::vector<std::uint8_t> bytes = saved.save();

  // The same geometry, in the same order: restored exactly, and it steps on identically.
  World same = make_world();
  mesh(same, kSquare, kSquareIndices);
  heightfield(same, tilted_heightfield());
  ASSERT_TRUE(same.restore(bytes).ok());
  EXPECT_EQ(same.save(), bytes);
  for (int i = 0; i < 20; ++i) {
    saved.step();
    same.step();
  }
  EXPECT_EQ(same.hashes(), saved.hashes());

  // Without the mesh: refused, naming it, and unchanged.
  World bare = make_world();
  const auto before = bare.save();
  const Status missing = bare.restore(bytes);
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.message().find("the state needs geometry 1 (triangle mesh, content hash 0x"),
            std::string::npos)
      << missing.message();
  EXPECT_EQ(bare.save(), before);
  // Another mesh under ID 1, or the two in the other order: refused.
  World other = make_world();
  std::vector<Vec3> moved = kSquare;
  moved[0].y = 1_fx;
  mesh(other, moved, kSquareIndices);
  heightfield(other, tilted_heightfield());
  EXPECT_FALSE(other.restore(bytes).ok());
  World swapped = make_world();
  heightfield(swapped, tilted_heightfield());
  mesh(swapped, kSquare, kSquareIndices);
  const Status wrong_type = swapped.restore(bytes);
  ASSERT_FALSE(wrong_type.ok());
  EXPECT_NE(wrong_type.message().find("this world's geometry 1 is a heightfield"),
            std::string::npos)
      << wrong_type.message();
}

// The outline a viewer draws: the triangles placed in the world, capped at max_outline_triangles.
TEST(Surface, TheOutlineHoldsTheTrianglesPlaced) {
  World w = make_world();
  const GeometryId m = mesh(w, kSquare, kSquareIndices);
  const BodyId body = add(w, test::static_placed(Shape::mesh(m), kAt, posed()));
  const auto out = w.body_outline(body);
  ASSERT_TRUE(out.ok()) << out.message();
  EXPECT_EQ(out->surface_triangles, 2U);
  ASSERT_EQ(out->triangles.size(), 2U);
  EXPECT_TRUE(near(out->triangles[0][0], to_world(kSquare[0]), kTolerance));
  EXPECT_TRUE(near(out->triangles[0][1], to_world(kSquare[2]), kTolerance));
  EXPECT_TRUE(near(out->triangles[1][1], to_world(kSquare[3]), kTolerance));
  EXPECT_EQ(out->points.size(), 8U);  // the bounds' corners

  HeightfieldDef big;
  big.rows = 102;
  big.columns = 102;
  big.cell_size = 0.5_fx;
  big.heights.assign(102 * 102, Fixed::zero());
  const BodyId ground = add(w, test::static_placed(Shape::heightfield(heightfield(w, big))));
  const auto capped = w.body_outline(ground);
  ASSERT_TRUE(capped.ok());
  EXPECT_EQ(capped->surface_triangles, 2U * 101U * 101U);
  EXPECT_EQ(capped->triangles.size(), max_outline_triangles);
  EXPECT_FALSE(w.body_outline(BodyId{99}).ok());
}

}  // namespace
}  // namespace detsim
