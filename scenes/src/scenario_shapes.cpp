// The scenes of registered geometry: rocks (convex hulls on a heightfield), level (every kind of
// body on a triangle-mesh landscape with a ramp and stairs) and furniture (compounds whose centre
// of mass is off their origin, toppling).
#include <array>
#include <cstdint>
#include <vector>

#include <detsim/fixed/math.hpp>
#include <detsim/fixed/quat.hpp>

#include "scenario_scenes.hpp"

namespace detsim::scenes_detail {

namespace {

// Registered geometry is part of a scenario's definition: a refusal is a bug here.
GeometryId hull(World& w, const std::vector<Vec3>& points) {
  return w.create_convex_hull(points).value();
}

BodyDef dynamic(Shape shape, Vec3 position, Quat orientation = {}) {
  BodyDef d;
  d.shape = shape;
  d.position = position;
  d.orientation = orientation;
  return d;
}

BodyDef fixed_body(Shape shape, Vec3 position) {
  BodyDef d;
  d.type = BodyType::static_body;
  d.shape = shape;
  d.position = position;
  return d;
}

// A rock: 12 points from the RNG on an ellipsoid of semi-axes in [0.25, 0.6] m.
std::vector<Vec3> rock_points(Rng& rng) {
  const Vec3 axes{rng.uniform(0.25_fx, 0.6_fx), rng.uniform(0.25_fx, 0.6_fx),
                  rng.uniform(0.25_fx, 0.6_fx)};
  std::vector<Vec3> points;
  for (int i = 0; i < 12; ++i) {
    const Vec3 u = rng.unit_vector();
    points.push_back({u.x * axes.x, u.y * axes.y, u.z * axes.z});
  }
  return points;
}

// ---- rocks ----

constexpr std::uint32_t kTerrainSide = 48;    // samples per side
constexpr Fixed kTerrainCell = Fixed::one();  // m

// Rolling hills: 1.5 sin(x / 5) cos(z / 7) + 0.5 sin((x + z) / 3) m, in Fixed (sin and cos are
// the library's, correctly rounded within an ulp on every machine).
HeightfieldDef hills() {
  HeightfieldDef def;
  def.rows = kTerrainSide;
  def.columns = kTerrainSide;
  def.cell_size = kTerrainCell;
  for (std::uint32_t r = 0; r < kTerrainSide; ++r) {
    for (std::uint32_t c = 0; c < kTerrainSide; ++c) {
      const Fixed x = Fixed::from_int(static_cast<std::int32_t>(c));
      const Fixed z = Fixed::from_int(static_cast<std::int32_t>(r));
      def.heights.push_back(1.5_fx * sin(x / 5_fx) * cos(z / 7_fx) + 0.5_fx * sin((x + z) / 3_fx));
    }
  }
  return def;
}

}  // namespace

void build_rocks(World& w, const ScenarioParams& p) {
  const GeometryId terrain = w.create_heightfield(hills()).value();
  // The grid's corner at (-23.5, 0, -23.5): the terrain is centred on the origin.
  const Fixed half = Fixed::from_int(static_cast<std::int32_t>(kTerrainSide - 1)) / 2_fx;
  add(w, fixed_body(Shape::heightfield(terrain), {-half, 0_fx, -half}));
  // Rocks in layers of 15 x 15 above the middle of the terrain, 1.4 m apart, from 4 m up.
  const std::uint32_t n = p.count;
  for (std::uint32_t i = 0; i < n; ++i) {
    const auto column = static_cast<std::int32_t>(i % 15);
    const auto row = static_cast<std::int32_t>((i / 15) % 15);
    const auto layer = static_cast<std::int32_t>(i / 225);
    const GeometryId g = hull(w, rock_points(w.rng()));
    const Vec3 at{Fixed::from_int(column - 7) * 1.4_fx, 4_fx + Fixed::from_int(layer) * 1.4_fx,
                  Fixed::from_int(row - 7) * 1.4_fx};
    // One draw per statement: the order of a call's arguments is the compiler's choice.
    const Fixed angle = w.rng().uniform(0_fx, Fixed::pi());
    const Vec3 axis = w.rng().unit_vector();
    const Quat turn = from_axis_angle(axis, angle);
    add(w, dynamic(Shape::convex(g), at, turn));
  }
}

// ---- level ----

namespace {

// The level's mesh: a 32 x 32 m ground of 2 m cells at y = 0 with a gentle bump, a ramp rising
// 2 m over 8 m along +x, and a flight of five stairs (0.3 m rise, 0.6 m run) along -x.
struct MeshBuilder {
  std::vector<Vec3> vertices;
  std::vector<std::uint32_t> indices;

  std::uint32_t vertex(Vec3 v) {
    vertices.push_back(v);
    return static_cast<std::uint32_t>(vertices.size() - 1);
  }
  // Two triangles, counter-clockwise seen from where the normal points (a, b, c, d in order).
  void quad(Vec3 a, Vec3 b, Vec3 c, Vec3 d) {
    const std::uint32_t ia = vertex(a);
    const std::uint32_t ib = vertex(b);
    const std::uint32_t ic = vertex(c);
    const std::uint32_t id = vertex(d);
    indices.insert(indices.end(), {ia, ib, ic, ia, ic, id});
  }
};

Fixed ground_height(std::int32_t i, std::int32_t k) {
  // A bump of 0.5 m around (6, 6), sampled at the grid points.
  const std::int32_t di = i - 3;
  const std::int32_t dk = k - 3;
  const std::int32_t r2 = di * di + dk * dk;
  return r2 >= 4 ? 0_fx : Fixed::from_int(4 - r2) / 8_fx;
}

MeshBuilder level_mesh() {
  MeshBuilder m;
  // Ground: cells of 2 m from -16 to 16 in x and z; the area of the ramp and stairs (x in [2, 10]
  // and [-10, -2], z in [-2, 2]) is ground too (they stand on it).
  for (std::int32_t i = 0; i < 16; ++i) {
    for (std::int32_t k = 0; k < 16; ++k) {
      const auto at = [&](std::int32_t di, std::int32_t dk) {
        return Vec3{Fixed::from_int(2 * (i + di) - 16), ground_height(i + di, k + dk),
                    Fixed::from_int(2 * (k + dk) - 16)};
      };
      // Counter-clockwise seen from above (+y): (x, z), (x, z + 1), (x + 1, z + 1), (x + 1, z).
      m.quad(at(0, 0), at(0, 1), at(1, 1), at(1, 0));
    }
  }
  // The ramp: from (2, 0) up to (10, 2), 4 m wide.
  m.quad({2_fx, 0_fx, -2_fx}, {2_fx, 0_fx, 2_fx}, {10_fx, 2_fx, 2_fx}, {10_fx, 2_fx, -2_fx});
  // The stairs: step s has its riser at x = -2 - 0.6 s, facing +x, and its tread 0.3 (s + 1) up.
  for (std::int32_t s = 0; s < 5; ++s) {
    const Fixed x0 = -2_fx - 0.6_fx * Fixed::from_int(s);
    const Fixed x1 = x0 - 0.6_fx;
    const Fixed y0 = 0.3_fx * Fixed::from_int(s);
    const Fixed y1 = y0 + 0.3_fx;
    // Riser, facing +x: counter-clockwise seen from +x.
    m.quad({x0, y0, -2_fx}, {x0, y1, -2_fx}, {x0, y1, 2_fx}, {x0, y0, 2_fx});
    // Tread, facing +y.
    m.quad({x0, y1, -2_fx}, {x1, y1, -2_fx}, {x1, y1, 2_fx}, {x0, y1, 2_fx});
  }
  return m;
}

}  // namespace

void build_level(World& w, const ScenarioParams& p) {
  const MeshBuilder m = level_mesh();
  const GeometryId level = w.create_mesh(m.vertices, m.indices).value();
  add(w, fixed_body(Shape::mesh(level), {}));
  const GeometryId rock = hull(w, rock_points(w.rng()));
  // A table: a top and four legs; its centre of mass is above its origin (the legs' feet).
  const std::array<CompoundChild, 5> table_parts{{
      {Shape::box({0.6_fx, 0.05_fx, 0.4_fx}), {0_fx, 0.75_fx, 0_fx}, {}},
      {Shape::box({0.04_fx, 0.35_fx, 0.04_fx}), {-0.5_fx, 0.35_fx, -0.3_fx}, {}},
      {Shape::box({0.04_fx, 0.35_fx, 0.04_fx}), {0.5_fx, 0.35_fx, -0.3_fx}, {}},
      {Shape::box({0.04_fx, 0.35_fx, 0.04_fx}), {-0.5_fx, 0.35_fx, 0.3_fx}, {}},
      {Shape::box({0.04_fx, 0.35_fx, 0.04_fx}), {0.5_fx, 0.35_fx, 0.3_fx}, {}},
  }};
  const GeometryId table = w.create_compound(table_parts).value();
  // Bodies of each kind in rows across the ramp, the stairs and the ground: `count` of each.
  const std::uint32_t n = p.count;
  for (std::uint32_t i = 0; i < n; ++i) {
    const Fixed z = Fixed::from_int(static_cast<std::int32_t>(i % 4)) * 1.5_fx - 2.25_fx;
    const Fixed lane = Fixed::from_int(static_cast<std::int32_t>(i / 4)) * 3_fx;
    const Quat tip = from_axis_angle(Vec3::unit_z(), 0.2_fx);
    add(w, dynamic(Shape::box({0.3_fx, 0.3_fx, 0.3_fx}), {8_fx - lane, 4_fx, z}, tip));
    add(w, dynamic(Shape::convex(rock), {6_fx - lane, 5_fx, z}));
    add(w, dynamic(Shape::capsule(0.2_fx, 0.4_fx), {4_fx - lane, 6_fx, z},
                   from_axis_angle(Vec3::unit_x(), Fixed::half_pi())));
    add(w, dynamic(Shape::compound(table), {-4_fx - lane, 3_fx, z + 5_fx}, tip));
  }
}

// ---- furniture ----

void build_furniture(World& w, const ScenarioParams& p) {
  BodyDef ground;
  ground.type = BodyType::static_body;
  ground.shape = Shape::plane();
  add(w, ground);
  // A chair: seat, four legs and a back; the back puts its centre of mass behind and above the
  // middle of the seat.
  const std::array<CompoundChild, 6> chair_parts{{
      {Shape::box({0.22_fx, 0.03_fx, 0.22_fx}), {0_fx, 0.45_fx, 0_fx}, {}},
      {Shape::box({0.025_fx, 0.21_fx, 0.025_fx}), {-0.19_fx, 0.21_fx, -0.19_fx}, {}},
      {Shape::box({0.025_fx, 0.21_fx, 0.025_fx}), {0.19_fx, 0.21_fx, -0.19_fx}, {}},
      {Shape::box({0.025_fx, 0.21_fx, 0.025_fx}), {-0.19_fx, 0.21_fx, 0.19_fx}, {}},
      {Shape::box({0.025_fx, 0.21_fx, 0.025_fx}), {0.19_fx, 0.21_fx, 0.19_fx}, {}},
      {Shape::box({0.22_fx, 0.3_fx, 0.03_fx}), {0_fx, 0.78_fx, -0.2_fx}, {}},
  }};
  const GeometryId chair = w.create_compound(chair_parts).value();
  // A hammer: a long handle and a heavy head at its top (steel-like parts are dense: the head's
  // volume dominates the mass, so the centre of mass sits near the head).
  const std::array<CompoundChild, 2> hammer_parts{{
      {Shape::capsule(0.02_fx, 0.15_fx), {0_fx, 0.17_fx, 0_fx}, {}},
      {Shape::box({0.07_fx, 0.03_fx, 0.03_fx}), {0.02_fx, 0.37_fx, 0_fx}, {}},
  }};
  const GeometryId hammer = w.create_compound(hammer_parts).value();
  // Each set: a chair tipped back 25 degrees onto two legs (it topples backwards, its centre of
  // mass behind the legs it stands on), a hammer standing on its handle's end leaning 5 degrees
  // towards its head (it falls head first), and a chair dropped upright (it stands).
  const std::uint32_t n = p.count;
  for (std::uint32_t i = 0; i < n; ++i) {
    const Fixed x = Fixed::from_int(static_cast<std::int32_t>(i)) * 2_fx;
    const Quat back = from_axis_angle(Vec3::unit_x(), -0.436_fx);
    add(w, dynamic(Shape::compound(chair), {x, 0.25_fx, 0_fx}, back));
    const Quat lean = from_axis_angle(Vec3::unit_z(), -0.087_fx);
    add(w, dynamic(Shape::compound(hammer), {x, 0.03_fx, 2_fx}, lean));
    add(w, dynamic(Shape::compound(chair), {x, 0.2_fx, 4_fx}));
  }
}

}  // namespace detsim::scenes_detail
