// Bodies on triangle meshes and heightfields in the step, against the physics: a box slides over
// the shared edges of a flat mesh without bumping (internal edges take the face normal), a solid
// sphere rolls down a heightfield slope at (5/7) g sin(theta), a hull rests on a mesh without
// creeping, nothing tunnels through a one-triangle floor at 1000 m/s, and a snapshot does not grow
// with the mesh under the pile (geometry is named by content hash, not copied).
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

#include "support/scale.hpp"
#include "support/sim_helpers.hpp"

namespace detsim {
namespace {

using namespace detsim::literals;

using test::add;
using test::make_world;
using test::placed;
using test::state;

// A flat mesh at y = 0 of cells x cells square cells of `size` m from (-half, -half), each cell two
// triangles (counter-clockwise from above), alternating the diagonal so that edges meet at every
// angle a sliding box can cross.
GeometryId flat_mesh(World& w, int cells, Fixed size) {
  std::vector<Vec3> vertices;
  std::vector<std::uint32_t> indices;
  const Fixed half = Fixed::from_int(cells) * size / 2_fx;
  for (int i = 0; i <= cells; ++i)
    for (int k = 0; k <= cells; ++k)
      vertices.push_back(
          {Fixed::from_int(i) * size - half, 0_fx, Fixed::from_int(k) * size - half});
  const auto at = [cells](int i, int k) { return static_cast<std::uint32_t>(i * (cells + 1) + k); };
  for (int i = 0; i < cells; ++i) {
    for (int k = 0; k < cells; ++k) {
      // (i, k) -> (i, k + 1) -> (i + 1, k + 1) is counter-clockwise seen from +y.
      const std::uint32_t a = at(i, k), b = at(i, k + 1), c = at(i + 1, k + 1), d = at(i + 1, k);
      if ((i + k) % 2 == 0) {
        indices.insert(indices.end(), {a, b, c, a, c, d});
      } else {
        indices.insert(indices.end(), {a, b, d, b, c, d});
      }
    }
  }
  auto g = w.create_mesh(vertices, indices);
  EXPECT_TRUE(g.ok()) << g.message();
  return g.ok() ? *g : GeometryId{};
}

TEST(SurfacePhysics, BoxesSlideAcrossAFlatMeshOfTwoMetreTrianglesWithoutBumping) {
  // Four boxes (0.5 m, friction 0.2 with the mesh) launched at 5 m/s along x, along z and along
  // both diagonals (across the triangles' diagonals too), one turned 0.4 rad about y: while they
  // slide (about 2.5 s, 6 m over three cells) their vertical speed stays below 1 mm/s. An edge
  // contact with the edge's own normal would kick them up by centimetres per second.
  WorldDef def;
  def.enable_sleep = false;
  World w = make_world(def);
  BodyDef ground = test::static_placed(Shape::mesh(flat_mesh(w, 16, 2_fx)));
  ground.friction = 0.2_fx;
  add(w, ground);
  struct Launch {
    Vec3 velocity;
    Quat turn;
  };
  const Fixed diag = 5_fx / sqrt(2_fx);
  const std::vector<Launch> launches{{{5_fx, 0_fx, 0_fx}, {}},
                                     {{0_fx, 0_fx, 5_fx}, from_axis_angle(Vec3::unit_y(), 0.4_fx)},
                                     {{diag, 0_fx, diag}, {}},
                                     {{diag, 0_fx, -diag}, {}}};
  std::vector<BodyId> boxes;
  for (std::size_t i = 0; i < launches.size(); ++i) {
    // Start at rest on the mesh, each in its own lane, well inside the 32 m square.
    BodyDef d =
        placed(Shape::box({0.25_fx, 0.25_fx, 0.25_fx}),
               {Fixed::from_int(static_cast<int>(i) * 4 - 12), 0.25_fx, -8_fx}, launches[i].turn);
    d.friction = 0.2_fx;
    boxes.push_back(add(w, d));
  }
  for (int f = 0; f < 10; ++f)  // settle onto the mesh
    w.step();
  std::vector<Vec3> start;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    ASSERT_TRUE(w.set_linear_velocity(boxes[i], launches[i].velocity).ok());
    start.push_back(state(w, boxes[i]).position);
  }
  Fixed worst;
  int sliding_frames = 0;
  for (int f = 0; f < 180; ++f) {
    w.step();
    for (const BodyId id : boxes) {
      const BodyState b = state(w, id);
      if (length(b.linear_velocity) < 0.1_fx) continue;  // stopped: nothing left to bump
      ++sliding_frames;
      worst = max(worst, abs(b.linear_velocity.y));
    }
  }
  std::printf("boxes sliding over a mesh of 2 m triangles: worst |v_y| %s m/s over %d box-frames\n",
              to_string(worst).c_str(), sliding_frames);
  EXPECT_GT(sliding_frames, 4 * 100);
  EXPECT_LT(worst, 0.001_fx) << to_string(worst);
  // Kinetic friction alone stops each after v^2 / (2 mu g) = 25 / (2 * 0.2 * 9.81) = 6.37 m.
  const double stop = 25.0 / (2 * 0.2 * 9.81);
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const double travelled = length(state(w, boxes[i]).position - start[i]).to_double();
    EXPECT_NEAR(travelled, stop, 0.03 * stop) << "box " << i;
  }
}

TEST(SurfacePhysics, ASolidSphereRollsDownAHeightfieldSlopeAtFiveSeventhsGSinTheta) {
  // A heightfield sampled from the plane y = -0.3 x (tan(theta) = 0.3) in 1 m cells; a solid
  // sphere (I = (2/5) m r^2) rolling without slipping (friction 0.8 >= (2/7) tan(theta)) down it
  // accelerates at a = (5/7) g sin(theta). Its travel over 1.5 s from the velocity it has after
  // settling must match v0 t + a t^2 / 2 within 2 %.
  WorldDef def;
  def.enable_sleep = false;
  World w = make_world(def);
  HeightfieldDef hf;
  hf.rows = 12;
  hf.columns = 40;
  hf.cell_size = 1_fx;
  for (std::uint32_t r = 0; r < hf.rows; ++r)
    for (std::uint32_t c = 0; c < hf.columns; ++c)
      hf.heights.push_back(Fixed::from_int(-3 * static_cast<int>(c)) / 10_fx);
  auto g = w.create_heightfield(hf);
  ASSERT_TRUE(g.ok()) << g.message();
  BodyDef ground = test::static_placed(Shape::heightfield(*g));
  ground.friction = 0.8_fx;
  add(w, ground);
  // On the slope at x = 3, z = 6 (the middle row): the centre r along the normal from the surface.
  const double tan_theta = 0.3;
  const double cos_theta = 1 / std::sqrt(1 + tan_theta * tan_theta);
  const double sin_theta = tan_theta * cos_theta;
  const Vec3 normal = normalize(Vec3{0.3_fx, 1_fx, 0_fx});
  BodyDef d = placed(Shape::sphere(0.5_fx), Vec3{3_fx, -0.9_fx, 6_fx} + normal * 0.5_fx);
  d.friction = 0.8_fx;
  const BodyId ball = add(w, d);
  for (int f = 0; f < 6; ++f)
    w.step();
  const BodyState s0 = state(w, ball);
  const double v0 = length(s0.linear_velocity).to_double();
  const int frames = 90;
  for (int f = 0; f < frames; ++f)
    w.step();
  const BodyState s1 = state(w, ball);
  const double t = frames / 60.0;
  const double a = 5.0 / 7.0 * 9.81 * sin_theta;
  const double expected = v0 * t + a * t * t / 2;
  const double travelled = length(s1.position - s0.position).to_double();
  std::printf(
      "sphere down a heightfield: travelled %.4f m, (5/7) g sin(theta) predicts %.4f m "
      "(%.2f %%)\n",
      travelled, expected, 100 * (travelled - expected) / expected);
  EXPECT_NEAR(travelled, expected, 0.02 * expected);
  // Rolling, not sliding: the surface speed equals the centre's speed; and it stays on the row.
  const double spin = length(s1.angular_velocity).to_double() * 0.5;
  EXPECT_NEAR(spin, length(s1.linear_velocity).to_double(), 0.02 * spin);
  EXPECT_LT(abs(s1.position.z - 6_fx), 0.001_fx);
}

TEST(SurfacePhysics, AHullRestsOnAMeshAcrossItsEdgesWithoutCreeping) {
  // A 12-point rock dropped onto a flat mesh where four cells meet (its contacts span several
  // triangles and their shared edges and vertex): once settled it stays within 0.5 mm for 5 s and
  // falls asleep, as on a plane.
  World w = make_world();
  add(w, test::static_placed(Shape::mesh(flat_mesh(w, 4, 2_fx))));
  auto g = w.create_convex_hull(test::test_rock());
  ASSERT_TRUE(g.ok()) << g.message();
  const BodyId id = add(w, placed(Shape::convex(*g), {0_fx, 1_fx, 0_fx}));
  for (int i = 0; i < 180; ++i)
    w.step();
  const BodyState settled = state(w, id);
  for (int i = 0; i < 300; ++i)
    w.step();
  const BodyState end = state(w, id);
  EXPECT_LT(length(end.position - settled.position), 0.0005_fx)
      << to_string(length(end.position - settled.position));
  EXPECT_GT(end.position.y, 0_fx);
  EXPECT_FALSE(end.awake);
}

TEST(SurfacePhysics, NothingTunnelsThroughAOneTriangleFloorAt1000MetresPerSecond) {
  // A floor of one triangle (a mesh) or of two (a 2 x 2 heightfield), zero thickness; a sphere of
  // 0.1 m and a hull of 0.2 m shot at it from 10 m at 1000 m/s (16.7 m per step), straight down and
  // slanted, with and without the CCD flag (a body that moves more than its size in a step is
  // swept either way): after a second, each is above the floor.
  for (const bool heightfield : {false, true}) {
    for (const bool ccd : {false, true}) {
      WorldDef def;
      def.gravity = {};
      World w = make_world(def);
      GeometryId floor;
      if (heightfield) {
        HeightfieldDef hf;
        hf.rows = 2;
        hf.columns = 2;
        hf.cell_size = 100_fx;
        hf.heights = {0_fx, 0_fx, 0_fx, 0_fx};
        floor = w.create_heightfield(hf).value();
        add(w, test::static_placed(Shape::heightfield(floor), {-50_fx, 0_fx, -50_fx}));
      } else {
        const std::vector<Vec3> v{
            {-100_fx, 0_fx, -100_fx}, {0_fx, 0_fx, 100_fx}, {100_fx, 0_fx, -100_fx}};
        const std::vector<std::uint32_t> tri{0, 1, 2};
        floor = w.create_mesh(v, tri).value();
        add(w, test::static_placed(Shape::mesh(floor)));
      }
      const std::vector<Vec3> corners{{-0.1_fx, -0.1_fx, -0.1_fx},
                                      {0.1_fx, -0.1_fx, -0.1_fx},
                                      {0_fx, -0.1_fx, 0.1_fx},
                                      {0_fx, 0.1_fx, 0_fx},
                                      {0.05_fx, 0.05_fx, 0.05_fx}};
      const GeometryId hull = w.create_convex_hull(corners).value();
      std::vector<BodyId> shots;
      int lane = 0;
      for (const Shape& shape : {Shape::sphere(0.1_fx), Shape::convex(hull)}) {
        for (const Vec3 v : {Vec3{0_fx, -1000_fx, 0_fx}, Vec3{300_fx, -950_fx, -200_fx}}) {
          BodyDef d = placed(shape, {Fixed::from_int(lane * 3 - 6), 10_fx, 0_fx},
                             from_axis_angle(Vec3::unit_x(), 0.3_fx));
          d.linear_velocity = v;
          d.ccd = ccd;
          d.restitution = 0_fx;
          shots.push_back(add(w, d));
          ++lane;
        }
      }
      for (int f = 0; f < 60; ++f)
        w.step();
      for (const BodyId id : shots) {
        const BodyState b = state(w, id);
        EXPECT_GT(b.world_center().y, 0_fx)
            << (heightfield ? "heightfield" : "mesh") << (ccd ? ", ccd" : "") << ": body "
            << id.value << " at y " << to_string(b.world_center().y);
      }
    }
  }
}

TEST(SurfacePhysics, ASnapshotDoesNotGrowWithTheMeshUnderThePile) {
  // 1000 boxes (10 x 10 x 10, 1 m, 1.1 m apart) settling for half a second on a plane and on a
  // flat mesh of 100 352 triangles (224 x 224 cells of 0.25 m): the mesh is named by its content
  // hash, so the two snapshots differ only by the bottom layer's contacts (a box on a mesh touches
  // several triangles): within 5 %.
  const auto snapshot_bytes = [](bool on_mesh) {
    World w = make_world();
    if (on_mesh) {
      add(w, test::static_placed(Shape::mesh(flat_mesh(w, 224, 0.25_fx))));
    } else {
      test::add_ground(w);
    }
    for (int i = 0; i < 10; ++i)
      for (int j = 0; j < 10; ++j)
        for (int k = 0; k < 10; ++k)
          add(w, placed(Shape::box({0.5_fx, 0.5_fx, 0.5_fx}),
                        {Fixed::from_int(i - 5) * 1.1_fx, 0.5_fx + Fixed::from_int(j) * 1.1_fx,
                         Fixed::from_int(k - 5) * 1.1_fx}));
    for (int f = 0; f < 30; ++f)
      w.step();
    return w.save().size();
  };
  const std::size_t plane = snapshot_bytes(false);
  const std::size_t mesh = snapshot_bytes(true);
  std::printf(
      "snapshot of 1000 boxes: %zu bytes on a plane, %zu on a 100k-triangle mesh (%+.2f "
      "%%)\n",
      plane, mesh,
      100.0 * (static_cast<double>(mesh) - static_cast<double>(plane)) /
          static_cast<double>(plane));
  EXPECT_LE(static_cast<double>(mesh), 1.05 * static_cast<double>(plane));
  EXPECT_GE(static_cast<double>(mesh), 0.95 * static_cast<double>(plane));
}

}  // namespace
}  // namespace detsim
