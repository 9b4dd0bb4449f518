// The table of shape kinds (sim/src/shapes.hpp): one kind per ShapeType, and the contract every
// kind keeps. A new shape type gets these checks by adding its examples to `examples` below; the
// contract tests then hold it to the same geometry as the others (derived from what each function
// promises, never from a recorded run).
#include <array>
#include <cstdint>
#include <memory>
#include <set>
#include <span>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

#include "sim/src/shapes.hpp"

namespace detsim {
namespace {

using namespace detsim::literals;
using sim_detail::find_shape_kind;
using sim_detail::shape_kinds;
using sim_detail::ShapeKind;

// A shape and the geometry it refers to (none for a primitive).
struct Example {
  Shape shape;
  std::shared_ptr<const sim_detail::Geometry> geometry;
};

std::shared_ptr<const sim_detail::Geometry> hull_of(std::span<const Vec3> points) {
  auto hull = sim_detail::build_hull(points);
  EXPECT_TRUE(hull.ok()) << hull.message();
  if (!hull.ok()) return nullptr;
  return sim_detail::make_hull_geometry(std::move(*hull));
}

// Convex hulls about the origin (the contract's "centre", which for a hull is its centroid): a
// cube's corners, and a rock of 12 points from the RNG on an ellipsoid, in opposite pairs so that
// its centroid is the origin.
std::vector<Example> hull_examples() {
  std::vector<Vec3> cube;
  for (const int i : {0, 1, 2, 3, 4, 5, 6, 7})
    cube.push_back({(i & 1) != 0 ? 0.5_fx : -0.5_fx, (i & 2) != 0 ? 0.5_fx : -0.5_fx,
                    (i & 4) != 0 ? 0.5_fx : -0.5_fx});
  Rng rng(5);
  std::vector<Vec3> rock;
  for (int i = 0; i < 6; ++i) {
    const Vec3 u = rng.unit_vector();
    rock.push_back({u.x * 2_fx, u.y, u.z * 0.75_fx});
    rock.push_back(-rock.back());
  }
  std::vector<Example> out;
  for (const auto& points : {cube, rock}) {
    auto g = hull_of(points);
    if (g) out.push_back({Shape::convex(GeometryId{1}), g});
  }
  return out;
}

// Surfaces (static only, no inside): a closed cube's 12 triangles about the origin, and a tilted
// heightfield whose grid starts at the origin.
std::vector<Example> mesh_examples() {
  std::vector<Vec3> cube;
  for (const int i : {0, 1, 2, 3, 4, 5, 6, 7})
    cube.push_back({(i & 1) != 0 ? 0.5_fx : -0.5_fx, (i & 2) != 0 ? 0.5_fx : -0.5_fx,
                    (i & 4) != 0 ? 0.5_fx : -0.5_fx});
  std::vector<std::uint32_t> indices;
  for (const auto& q : std::vector<std::array<std::uint32_t, 4>>{
           {0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}})
    indices.insert(indices.end(), {q[0], q[1], q[2], q[0], q[2], q[3]});
  auto mesh = sim_detail::build_mesh(cube, indices);
  EXPECT_TRUE(mesh.ok()) << mesh.message();
  if (!mesh.ok()) return {};
  return {{Shape::mesh(GeometryId{1}), sim_detail::make_mesh_geometry(std::move(*mesh))}};
}

std::vector<Example> heightfield_examples() {
  HeightfieldDef d;
  d.rows = 4;
  d.columns = 5;
  d.cell_size = 0.5_fx;
  for (std::uint32_t i = 0; i < d.rows * d.columns; ++i)
    d.heights.push_back(Fixed::from_int(static_cast<std::int32_t>(i % 3)) / 4_fx -
                        Fixed::from_int(static_cast<std::int32_t>(i / d.columns)) / 8_fx);
  auto hf = sim_detail::build_heightfield(d);
  EXPECT_TRUE(hf.ok()) << hf.message();
  if (!hf.ok()) return {};
  return {
      {Shape::heightfield(GeometryId{1}), sim_detail::make_heightfield_geometry(std::move(*hf))}};
}

// A surface kind: bounded but static only — a mesh or a heightfield. It has no inside (contains
// is false everywhere), no volume and no mass, so the contracts of solids adapt for it below.
bool is_surface(const ShapeKind* kind) {
  return kind->bounded && kind->static_only;
}

// Triangle 0 of a surface's geometry (a point on the surface: its centroid).
Vec3 first_centroid(const sim_detail::Geometry* g) {
  const sim_detail::TriangleData t = g->type == sim_detail::GeometryType::mesh
                                         ? sim_detail::triangle(g->mesh(), 0)
                                         : sim_detail::triangle(g->heightfield(), 0);
  return (t.vertices[0] + t.vertices[1] + t.vertices[2]) / 3_fx;
}

// Compounds about the origin (the contract's "centre": their centroid, and the smallest dimension
// is the largest part's, so that part sits on the origin): a box between two spheres, and a turned
// cube hull between two capsules lying along x. Built as a world builds them, on a table of its
// own (the hull is its geometry 1).
std::vector<Example> compound_examples() {
  std::vector<Example> out;
  const auto make = [&out](const sim_detail::GeometryTable& table,
                           const std::vector<CompoundChild>& children) {
    auto c = sim_detail::build_compound(table, children);
    EXPECT_TRUE(c.ok()) << c.message();
    if (!c.ok()) return;
    out.push_back({Shape::compound(GeometryId{static_cast<std::uint32_t>(table.size() + 1)}),
                   sim_detail::make_compound_geometry(std::move(*c))});
  };
  const Quat none = Quat::identity();
  make({}, {{Shape::box({0.5_fx, 0.5_fx, 0.5_fx}), {}, none},
            {Shape::sphere(0.4_fx), {1.5_fx, 0_fx, 0_fx}, none},
            {Shape::sphere(0.4_fx), {-1.5_fx, 0_fx, 0_fx}, none}});
  const sim_detail::GeometryTable table{hull_examples()[0].geometry};
  const Quat lying = from_axis_angle(Vec3::unit_z(), Fixed::half_pi());
  make(table, {{Shape::convex(GeometryId{1}), {}, from_axis_angle(Vec3::unit_y(), 0.5_fx)},
               {Shape::capsule(0.3_fx, 0.4_fx), {0_fx, 1.2_fx, 0_fx}, lying},
               {Shape::capsule(0.3_fx, 0.4_fx), {0_fx, -1.2_fx, 0_fx}, lying}});
  return out;
}

// Shapes of each type that a body may have, from small and flat to long.
std::vector<Example> examples(ShapeType type) {
  const auto plain = [](std::initializer_list<Shape> shapes) {
    std::vector<Example> out;
    for (const Shape& s : shapes)
      out.push_back({s, nullptr});
    return out;
  };
  switch (type) {
    case ShapeType::sphere:
      return plain({Shape::sphere(0.5_fx), Shape::sphere(0.01_fx), Shape::sphere(7_fx)});
    case ShapeType::box:
      return plain({Shape::box({0.5_fx, 0.5_fx, 0.5_fx}), Shape::box({2_fx, 0.1_fx, 0.7_fx})});
    case ShapeType::capsule:
      return plain({Shape::capsule(0.3_fx, 1_fx), Shape::capsule(0.5_fx, 0_fx)});
    case ShapeType::plane:
      return plain({Shape::plane()});
    case ShapeType::cylinder:
      return plain({Shape::cylinder(0.5_fx, 1_fx), Shape::cylinder(2_fx, 0.05_fx),
                    Shape::cylinder(0.25_fx, 1.5_fx)});
    case ShapeType::convex:
      return hull_examples();
    case ShapeType::mesh:
      return mesh_examples();
    case ShapeType::heightfield:
      return heightfield_examples();
    case ShapeType::compound:
      return compound_examples();
  }
  ADD_FAILURE() << "no examples of shape type " << static_cast<unsigned>(type)
                << ": add them to examples() in this file";
  return {};
}

TEST(ShapeKinds, EveryShapeTypeHasExactlyOneKind) {
  std::set<std::string> names;
  unsigned previous = 0;
  for (const ShapeKind* kind : shape_kinds()) {
    const auto type = static_cast<unsigned>(kind->type);
    EXPECT_GT(type, previous) << "kinds must be listed ascending by type";
    previous = type;
    EXPECT_TRUE(names.insert(kind->name).second) << "two kinds are called " << kind->name;
    EXPECT_EQ(find_shape_kind(kind->type), kind);
  }
  // Every value that names no kind is refused everywhere a shape is taken.
  std::size_t found = 0;
  for (unsigned v = 0; v < 256; ++v) {
    if (find_shape_kind(static_cast<ShapeType>(v)) != nullptr) ++found;
  }
  EXPECT_EQ(found, shape_kinds().size());
  BodyDef def;
  def.shape.type = static_cast<ShapeType>(200);
  auto world = World::create({}).value();
  const auto refused = world.create_body(def);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.message().find("unknown shape type 200"), std::string::npos);
}

TEST(ShapeKinds, MassPropertiesHaveTheGivenMassAndPositiveMoments) {
  for (const ShapeKind* kind : shape_kinds()) {
    for (const Example& e : examples(kind->type)) {
      const Shape& s = e.shape;
      const sim_detail::Geometry* g = e.geometry.get();
      ASSERT_EQ(kind->check(s), "");
      if (!kind->bounded) {
        EXPECT_EQ(volume(s), Fixed::zero()) << kind->name;
        EXPECT_EQ(mass_properties(s, 3_fx), MassProperties{}) << kind->name;
        continue;
      }
      if (is_surface(kind)) {  // a surface has no mass: only static bodies have one
        EXPECT_EQ(kind->volume(s, g), Fixed::zero()) << kind->name;
        EXPECT_EQ(kind->mass_properties(s, g, 3_fx), MassProperties{}) << kind->name;
        EXPECT_FALSE(kind->checked_volume(s, g).over()) << kind->name;
        continue;
      }
      EXPECT_GT(kind->volume(s, g), Fixed::zero()) << kind->name;
      const MassProperties m = kind->mass_properties(s, g, 3_fx);
      // The primitives' free functions are the kinds' (geometry needs its world: zero there).
      if (g == nullptr) {
        EXPECT_EQ(volume(s), kind->volume(s, g)) << kind->name;
        EXPECT_EQ(mass_properties(s, 3_fx), m) << kind->name;
      } else {
        EXPECT_EQ(volume(s), Fixed::zero()) << kind->name;
      }
      EXPECT_EQ(m.mass, 3_fx) << kind->name;
      EXPECT_GT(m.inertia.x, Fixed::zero()) << kind->name;
      EXPECT_GT(m.inertia.y, Fixed::zero()) << kind->name;
      EXPECT_GT(m.inertia.z, Fixed::zero()) << kind->name;
      // No point of a solid is farther than the bounding radius R from the origin, so no moment
      // exceeds m R^2 (and each pair of moments obeys the triangle inequality of a real body).
      const Fixed r = kind->bounding_radius(s, g);
      const Fixed bound = 3_fx * r * r;
      EXPECT_LE(m.inertia.x, bound) << kind->name;
      EXPECT_LE(m.inertia.x, m.inertia.y + m.inertia.z + Fixed::from_raw(4)) << kind->name;
      EXPECT_LE(m.inertia.y, m.inertia.x + m.inertia.z + Fixed::from_raw(4)) << kind->name;
      EXPECT_LE(m.inertia.z, m.inertia.x + m.inertia.y + Fixed::from_raw(4)) << kind->name;
    }
  }
}

// Points in the cube of side 4R about the origin: those the shape contains lie within the
// bounding radius and the bounding box, and the smallest dimension's ball about the centre is
// inside the shape. A surface contains no point (it has no inside) and its smallest dimension is
// 0: its samples must all be outside, and there is no ball to check.
TEST(ShapeKinds, ContainedPointsLieWithinTheBoundsAndTheSmallestDimensionIsInside) {
  Rng rng(7);
  for (const ShapeKind* kind : shape_kinds()) {
    if (!kind->bounded) continue;
    for (const Example& e : examples(kind->type)) {
      const Shape& s = e.shape;
      const sim_detail::Geometry* g = e.geometry.get();
      const Fixed r = kind->bounding_radius(s, g);
      const Vec3 box = kind->aabb_extent(s, g, Mat3::identity());
      int inside = 0;
      for (int i = 0; i < 4000; ++i) {
        const Vec3 p{rng.uniform(-2_fx * r, 2_fx * r), rng.uniform(-2_fx * r, 2_fx * r),
                     rng.uniform(-2_fx * r, 2_fx * r)};
        if (!kind->contains(s, g, p)) continue;
        ASSERT_FALSE(is_surface(kind)) << kind->name << ": a surface has no inside";
        ++inside;
        ASSERT_LE(length(p), r + Fixed::from_raw(16)) << kind->name;
        ASSERT_LE(abs(p.x), box.x) << kind->name;
        ASSERT_LE(abs(p.y), box.y) << kind->name;
        ASSERT_LE(abs(p.z), box.z) << kind->name;
      }
      if (is_surface(kind)) {
        EXPECT_EQ(kind->smallest_dimension(s, g), Fixed::zero()) << kind->name;
        continue;
      }
      EXPECT_GT(inside, 0) << kind->name << ": no sample fell inside";
      const Fixed d = kind->smallest_dimension(s, g);
      for (const Vec3 axis : {Vec3::unit_x(), Vec3::unit_y(), Vec3::unit_z()}) {
        EXPECT_TRUE(kind->contains(s, g, axis * d)) << kind->name;
        EXPECT_TRUE(kind->contains(s, g, -axis * d)) << kind->name;
      }
    }
  }
}

// A ray aimed at the centre from outside the bounding ball hits the surface: the hit point is on
// the ray, within the bounding radius, and within 2^-16 m of the surface: a step on along the ray
// is inside the shape, a step back outside it. A ray aimed away from it misses.
//
// A surface has no inside to step into, and its centre need not lie on it (a heightfield's grid
// starts at the origin): its rays aim at a point on it (triangle 0's centroid) and must hit no
// farther than that point, on the ray, within the bounding radius, with a unit normal facing the
// ray's origin; rays aimed away miss.
TEST(ShapeKinds, RaysAtTheCentreHitTheSurfaceAndRaysAwayMiss) {
  Rng rng(11);
  const Fixed step_back = Fixed::from_raw(Fixed::one_raw >> 16);
  for (const ShapeKind* kind : shape_kinds()) {
    if (!kind->bounded) continue;
    for (const Example& e : examples(kind->type)) {
      const Shape& s = e.shape;
      const sim_detail::Geometry* g = e.geometry.get();
      const Fixed r = kind->bounding_radius(s, g);
      const Vec3 aim = is_surface(kind) ? first_centroid(g) : Vec3::zero();
      for (int i = 0; i < 200; ++i) {
        const Vec3 v = rng.unit_vector();
        const Vec3 p = aim - v * (r * 2_fx + 1_fx);
        const auto hit = kind->ray(s, g, p, v);
        if (is_surface(kind)) {
          ASSERT_TRUE(hit.has_value()) << kind->name;
          EXPECT_LE(hit->t, r * 2_fx + 1_fx + Fixed::from_raw(1 << 12)) << kind->name;
          EXPECT_LE(length(hit->point - (p + v * hit->t)), Fixed::from_raw(1 << 12)) << kind->name;
          EXPECT_LE(length(hit->point), r + Fixed::from_raw(1 << 12)) << kind->name;
          EXPECT_NEAR(length(hit->normal).to_double(), 1.0, 1e-6) << kind->name;
          EXPECT_LT(dot(hit->normal, v), Fixed::zero()) << kind->name;
          EXPECT_FALSE(kind->ray(s, g, p, -v).has_value()) << kind->name;
          continue;
        }
        ASSERT_TRUE(hit.has_value()) << kind->name;
        EXPECT_LE(length(hit->point - (p + v * hit->t)), Fixed::from_raw(1 << 12)) << kind->name;
        EXPECT_LE(length(hit->point), r + Fixed::from_raw(1 << 12)) << kind->name;
        EXPECT_TRUE(kind->contains(s, g, hit->point + v * step_back)) << kind->name;
        EXPECT_FALSE(kind->contains(s, g, hit->point - v * step_back)) << kind->name;
        EXPECT_NEAR(length(hit->normal).to_double(), 1.0, 1e-6) << kind->name;
        EXPECT_FALSE(kind->ray(s, g, p, -v).has_value()) << kind->name;
      }
    }
  }
}

TEST(ShapeKinds, TheBoundingBoxHoldsTheRotatedShape) {
  Rng rng(13);
  for (const ShapeKind* kind : shape_kinds()) {
    if (!kind->bounded) continue;
    for (const Example& e : examples(kind->type)) {
      const Shape& s = e.shape;
      const sim_detail::Geometry* g = e.geometry.get();
      for (int i = 0; i < 50; ++i) {
        const Quat q = from_axis_angle(rng.unit_vector(), rng.uniform(0_fx, 3_fx));
        const Mat3 rotation = to_mat3(q);
        const Vec3 box = kind->aabb_extent(s, g, rotation);
        // The outline's points grown by its radius are the extreme points of a convex shape (of
        // each part of a compound).
        ShapeOutline outline;
        kind->outline(s, g, Vec3{}, q, outline);
        std::vector<ShapeOutline> pieces = outline.parts;
        pieces.push_back(outline);
        for (const ShapeOutline& piece : pieces) {
          for (const Vec3 p : piece.points) {
            EXPECT_LE(abs(p.x) + piece.radius, box.x + Fixed::from_raw(64)) << kind->name;
            EXPECT_LE(abs(p.y) + piece.radius, box.y + Fixed::from_raw(64)) << kind->name;
            EXPECT_LE(abs(p.z) + piece.radius, box.z + Fixed::from_raw(64)) << kind->name;
          }
        }
        // A surface's triangles lie in the box too.
        EXPECT_EQ(outline.triangles.empty(), !is_surface(kind)) << kind->name;
        for (const auto& t : outline.triangles) {
          for (const Vec3 p : t) {
            EXPECT_LE(abs(p.x), box.x + Fixed::from_raw(64)) << kind->name;
            EXPECT_LE(abs(p.y), box.y + Fixed::from_raw(64)) << kind->name;
            EXPECT_LE(abs(p.z), box.z + Fixed::from_raw(64)) << kind->name;
          }
        }
      }
    }
  }
}

TEST(ShapeKinds, TheEncodingReadsBackTheSameShapeAndNothingMore) {
  for (const ShapeKind* kind : shape_kinds()) {
    for (const Example& e : examples(kind->type)) {
      const Shape& s = e.shape;
      ByteWriter w;
      kind->write(s, w);
      w.u8(0xAB);  // what follows the shape is not read
      ByteReader r(w.bytes());
      EXPECT_EQ(kind->read(r), s) << kind->name;
      ASSERT_TRUE(r.ok()) << r.error();
      EXPECT_EQ(r.remaining(), 1U) << kind->name;
    }
  }
}

// The cylinder's mass properties against its closed forms: V = pi r^2 H, I_axis = m r^2 / 2,
// I_across = m (3 r^2 + H^2) / 12 with the full height H = 2 h. (1e-6 relative needs moments
// well above the Fixed resolution, 2^-32: a 1 cm radius's m r^2 / 2 is only ~10^6 ulp.)
TEST(ShapeKinds, CylinderMassPropertiesAreTheClosedForms) {
  double worst = 0;
  for (const Example& example : examples(ShapeType::cylinder)) {
    const Shape& s = example.shape;
    const double r = s.radius.to_double();
    const double big_h = 2 * s.half_height.to_double();
    const double pi = 3.14159265358979323846;
    const double m = 3.5;
    const double want_volume = pi * r * r * big_h;
    const double want_axis = m * r * r / 2;
    const double want_across = m * (3 * r * r + big_h * big_h) / 12;
    const MassProperties p = mass_properties(s, 3.5_fx);
    const auto rel = [](Fixed got, double want) { return std::abs(got.to_double() - want) / want; };
    for (const double e : {rel(volume(s), want_volume), rel(p.inertia.y, want_axis),
                           rel(p.inertia.x, want_across), rel(p.inertia.z, want_across)}) {
      EXPECT_LT(e, 1e-6) << s.radius.to_double() << " " << s.half_height.to_double();
      worst = std::max(worst, e);
    }
  }
  std::printf("cylinder mass properties: worst relative error %.3g\n", worst);
}

TEST(ShapeKinds, CylinderChecksEncodingAndBounds) {
  const ShapeKind& kind = *find_shape_kind(ShapeType::cylinder);
  EXPECT_EQ(kind.check(Shape::cylinder(0_fx, 1_fx)), "cylinder radius must be > 0, got 0");
  EXPECT_EQ(kind.check(Shape::cylinder(1_fx, 0_fx)), "cylinder half height must be > 0, got 0");
  EXPECT_EQ(kind.check(Shape::cylinder(1_fx, 10001_fx)),
            "cylinder half height must be <= 10000, got 10001");
  EXPECT_EQ(kind.check(Shape::cylinder(10001_fx, 1_fx)),
            "cylinder radius must be <= 10000, got 10001");
  // The encoding: radius then half height, as var_fixed each (docs/STATE.md).
  ByteWriter w;
  kind.write(Shape::cylinder(0.5_fx, 2_fx), w);
  ByteWriter want;
  want.var_fixed(0.5_fx);
  want.var_fixed(2_fx);
  EXPECT_EQ(w.bytes(), want.bytes());
  // Exact bounds: upright, the box is (r, h, r); lying along x, (h, r, r); tilted 45 degrees
  // about z, h / sqrt 2 + r / sqrt 2 across x and y.
  const Shape s = Shape::cylinder(0.5_fx, 2_fx);
  EXPECT_EQ(kind.aabb_extent(s, nullptr, Mat3::identity()), (Vec3{0.5_fx, 2_fx, 0.5_fx}));
  EXPECT_NEAR(kind.bounding_radius(s, nullptr).to_double(), std::sqrt(4.25), 1e-9);
  EXPECT_EQ(kind.smallest_dimension(s, nullptr), 0.5_fx);
  const Mat3 tilt = to_mat3(from_axis_angle(Vec3::unit_z(), Fixed::pi() / 4_fx));
  const Vec3 e = kind.aabb_extent(s, nullptr, tilt);
  EXPECT_NEAR(e.x.to_double(), 2.5 / std::sqrt(2.0), 1e-8);
  EXPECT_NEAR(e.y.to_double(), 2.5 / std::sqrt(2.0), 1e-8);
  EXPECT_NEAR(e.z.to_double(), 0.5, 1e-8);
  // Rays onto an end and onto the side.
  const auto top = kind.ray(s, nullptr, {0.1_fx, 5_fx, 0.2_fx}, {0_fx, -1_fx, 0_fx});
  ASSERT_TRUE(top.has_value());
  EXPECT_EQ(top->t, 3_fx);
  EXPECT_EQ(top->normal, Vec3::unit_y());
  const auto side = kind.ray(s, nullptr, {-3_fx, 1.5_fx, 0_fx}, {1_fx, 0_fx, 0_fx});
  ASSERT_TRUE(side.has_value());
  EXPECT_EQ(side->t, 2.5_fx);
  EXPECT_EQ(side->normal, -Vec3::unit_x());
  EXPECT_FALSE(
      kind.ray(s, nullptr, {-3_fx, 2.5_fx, 0_fx}, {1_fx, 0_fx, 0_fx}).has_value());  // above it
  EXPECT_FALSE(
      kind.ray(s, nullptr, {0.6_fx, 5_fx, 0_fx}, {0_fx, -1_fx, 0_fx}).has_value());  // beside it
}

// The outlines a viewer draws, from each shape's definition.
TEST(ShapeOutline, EachShapeIsDrawnFromItsDefinition) {
  const Vec3 at{10_fx, 2_fx, -3_fx};
  const Quat q = from_axis_angle(Vec3::unit_z(), Fixed::half_pi());  // local +y -> world -x

  const ShapeOutline sphere = shape_outline(Shape::sphere(0.5_fx), at, q);
  EXPECT_FALSE(sphere.half_space);
  ASSERT_EQ(sphere.points.size(), 1U);
  EXPECT_EQ(sphere.points[0], at);
  EXPECT_EQ(sphere.radius, 0.5_fx);

  const ShapeOutline capsule = shape_outline(Shape::capsule(0.25_fx, 1_fx), at, q);
  ASSERT_EQ(capsule.points.size(), 2U);
  EXPECT_EQ(capsule.radius, 0.25_fx);
  // The core runs along the rotated local y axis: from x + 1 to x - 1.
  EXPECT_NEAR(capsule.points[0].x.to_double(), 11.0, 1e-8);
  EXPECT_NEAR(capsule.points[1].x.to_double(), 9.0, 1e-8);
  EXPECT_NEAR(capsule.points[0].y.to_double(), 2.0, 1e-8);

  const Vec3 h{1_fx, 0.5_fx, 0.25_fx};
  const ShapeOutline box = shape_outline(Shape::box(h), at, q);
  ASSERT_EQ(box.points.size(), 8U);
  EXPECT_EQ(box.radius, Fixed::zero());
  for (const Vec3 p : box.points)  // every corner is |h| from the centre
    EXPECT_NEAR(distance(p, at).to_double(), length(h).to_double(), 1e-8);

  const ShapeOutline plane = shape_outline(Shape::plane(), at, q);
  EXPECT_TRUE(plane.half_space);
  ASSERT_EQ(plane.points.size(), 1U);
  EXPECT_NEAR(plane.normal.x.to_double(), -1.0, 1e-8);

  Shape unknown;
  unknown.type = static_cast<ShapeType>(99);
  EXPECT_TRUE(shape_outline(unknown, at, q).points.empty());
}

// A compound is drawn as its parts, each its own outline at the part's world pose; its bounds
// hold every part.
TEST(ShapeKinds, ACompoundsOutlineIsItsPartsAtTheirPoses) {
  const ShapeKind& kind = *find_shape_kind(ShapeType::compound);
  const std::vector<Example> e = compound_examples();
  ASSERT_EQ(e.size(), 2U);
  const sim_detail::Geometry* g = e[0].geometry.get();
  const Vec3 at{1_fx, 2_fx, 3_fx};
  const Quat q = from_axis_angle(Vec3::unit_z(), Fixed::half_pi());  // local x -> world y
  ShapeOutline out;
  kind.outline(e[0].shape, g, at, q, out);
  EXPECT_TRUE(out.points.empty());
  ASSERT_EQ(out.parts.size(), 3U);
  EXPECT_EQ(out.parts[0].points.size(), 8U);  // the box's corners
  ASSERT_EQ(out.parts[1].points.size(), 1U);  // a sphere: its centre, grown by its radius
  EXPECT_EQ(out.parts[1].radius, 0.4_fx);
  EXPECT_NEAR(out.parts[1].points[0].x.to_double(), 1, 1e-8);
  EXPECT_NEAR(out.parts[1].points[0].y.to_double(), 3.5, 1e-8);
  EXPECT_NEAR(out.parts[2].points[0].y.to_double(), 0.5, 1e-8);
  // Bounds: the spheres reach 1.9 along local x, the box 0.5 across; radius 1.9.
  const Vec3 box = kind.aabb_extent(e[0].shape, g, Mat3::identity());
  EXPECT_EQ(box, (Vec3{1.9_fx, 0.5_fx, 0.5_fx}));
  EXPECT_EQ(kind.bounding_radius(e[0].shape, g), 1.9_fx);
  EXPECT_EQ(kind.smallest_dimension(e[0].shape, g), 0.5_fx);
}

}  // namespace
}  // namespace detsim
