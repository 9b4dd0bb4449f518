// Compounds (World::create_compound, Shape::compound): parts placed in the body's frame whose
// centre of mass is off the origin. Mass properties against closed forms (boxes and spheres with
// the parallel-axis theorem, in doubles), refusals that name the child, content hashes that do not
// depend on geometry IDs, rays that hit the right part, and the free motion of a spinning
// dumbbell. Expected values are computed here, never read back from a run.
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

using Tensor = std::array<std::array<double, 3>, 3>;

constexpr double kPi = 3.14159265358979323846;

// The eight corners of the box of half extents h about `centre`.
std::vector<Vec3> box_corners(Vec3 h, Vec3 centre = {}) {
  std::vector<Vec3> out;
  for (const int i : {0, 1, 2, 3, 4, 5, 6, 7})
    out.push_back(centre + Vec3{(i & 1) != 0 ? h.x : -h.x, (i & 2) != 0 ? h.y : -h.y,
                                (i & 4) != 0 ? h.z : -h.z});
  return out;
}

GeometryId compound(World& w, const std::vector<CompoundChild>& children) {
  auto id = w.create_compound(children);
  EXPECT_TRUE(id.ok()) << id.message();
  return id.ok() ? *id : GeometryId{};
}

MassProperties mass_of(const World& w, GeometryId g, Fixed mass) {
  const auto m = w.mass_properties(Shape::compound(g), mass);
  EXPECT_TRUE(m.ok()) << m.message();
  return m.ok() ? *m : MassProperties{};
}

Tensor matrix(const Mat3& m) {
  Tensor out{};
  for (std::size_t r = 0; r < 3; ++r)
    out[r] = {m.rows[r].x.to_double(), m.rows[r].y.to_double(), m.rows[r].z.to_double()};
  return out;
}

// The body-frame tensor R diag(I) R^T (R = to_mat3(inertia_axes)), in doubles.
Tensor tensor_of(const MassProperties& m) {
  const Tensor r = matrix(to_mat3(m.inertia_axes));
  const double d[] = {m.inertia.x.to_double(), m.inertia.y.to_double(), m.inertia.z.to_double()};
  Tensor out{};
  for (std::size_t i = 0; i < 3; ++i) {
    for (std::size_t j = 0; j < 3; ++j) {
      for (std::size_t k = 0; k < 3; ++k)
        out[i][j] += r[i][k] * d[k] * r[j][k];
    }
  }
  return out;
}

// The largest |a_ij - b_ij| relative to the largest |b_ij|.
double relative_error(const Tensor& a, const Tensor& b) {
  double diff = 0;
  double scale = 0;
  for (std::size_t i = 0; i < 3; ++i) {
    for (std::size_t j = 0; j < 3; ++j) {
      diff = std::max(diff, std::abs(a[i][j] - b[i][j]));
      scale = std::max(scale, std::abs(b[i][j]));
    }
  }
  return diff / scale;
}

// A solid part in doubles: mass, centre, tensor about its centre (kg m^2, compound axes).
struct Part {
  double mass;
  std::array<double, 3> centre;
  Tensor inertia;
};

Part box_part(double density, std::array<double, 3> h, std::array<double, 3> centre) {
  const double m = density * 8 * h[0] * h[1] * h[2];
  Tensor t{};
  t[0][0] = m / 3 * (h[1] * h[1] + h[2] * h[2]);
  t[1][1] = m / 3 * (h[0] * h[0] + h[2] * h[2]);
  t[2][2] = m / 3 * (h[0] * h[0] + h[1] * h[1]);
  return {m, centre, t};
}

// The parts' total: mass, centre of mass, and the tensor about it (the parallel-axis theorem:
// I_i + m_i (|d|^2 E - d d^T) for d from the centre of mass to the part's centre).
Part combine(const std::vector<Part>& parts) {
  Part out{0, {0, 0, 0}, {}};
  for (const Part& p : parts) {
    out.mass += p.mass;
    for (std::size_t k = 0; k < 3; ++k)
      out.centre[k] += p.mass * p.centre[k];
  }
  for (std::size_t k = 0; k < 3; ++k)
    out.centre[k] /= out.mass;
  for (const Part& p : parts) {
    const double d[] = {p.centre[0] - out.centre[0], p.centre[1] - out.centre[1],
                        p.centre[2] - out.centre[2]};
    const double d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    for (std::size_t i = 0; i < 3; ++i) {
      for (std::size_t j = 0; j < 3; ++j)
        out.inertia[i][j] += p.inertia[i][j] + p.mass * ((i == j ? d2 : 0) - d[i] * d[j]);
    }
  }
  return out;
}

void expect_centre(const MassProperties& m, std::array<double, 3> want, double tolerance) {
  EXPECT_NEAR(m.center.x.to_double(), want[0], tolerance);
  EXPECT_NEAR(m.center.y.to_double(), want[1], tolerance);
  EXPECT_NEAR(m.center.z.to_double(), want[2], tolerance);
}

const Quat kNone = Quat::identity();

// The mass of a body of the compound at density 1: its volume (m^3).
double volume_of(World& w, GeometryId g) {
  BodyDef d;
  d.shape = Shape::compound(g);
  d.density = 1_fx;
  d.position = {0_fx, 0_fx, 100_fx};
  return state(w, add(w, d)).mass.to_double();
}

TEST(Compound, TwoBoxesSideBySideAreOneBoxOfTheirUnion) {
  World w = make_world();
  const Vec3 h{0.5_fx, 0.3_fx, 0.2_fx};
  const GeometryId g = compound(
      w, {{Shape::box(h), {1_fx, 2_fx, 0_fx}, kNone}, {Shape::box(h), {2_fx, 2_fx, 0_fx}, kNone}});
  EXPECT_EQ(g.value, 1U);
  const MassProperties m = mass_of(w, g, 6_fx);
  EXPECT_EQ(m.mass, 6_fx);
  expect_centre(m, {1.5, 2, 0}, 1e-8);
  // The union: half extents (1, 0.3, 0.2), mass 6: m/3 (b^2 + c^2).
  const double want[] = {2 * (0.09 + 0.04), 2 * (1 + 0.04), 2 * (1 + 0.09)};
  const double got[] = {m.inertia.x.to_double(), m.inertia.y.to_double(), m.inertia.z.to_double()};
  double worst = 0;
  for (std::size_t k = 0; k < 3; ++k)
    worst = std::max(worst, std::abs(got[k] - want[k]) / want[k]);
  EXPECT_LT(worst, 1e-6);
  // The box primitive of the union agrees, and the tensor is diagonal in the body's axes.
  const auto one = w.mass_properties(Shape::box({1_fx, 0.3_fx, 0.2_fx}), 6_fx);
  ASSERT_TRUE(one.ok());
  EXPECT_NEAR(m.inertia.y.to_double(), one->inertia.y.to_double(), 1e-6 * want[1]);
  EXPECT_EQ(m.inertia_axes, Quat::identity());
  EXPECT_NEAR(volume_of(w, g), 2 * 8 * 0.5 * 0.3 * 0.2, 1e-8);
  std::printf("two boxes as one: worst relative moment error %.3g\n", worst);
}

// Boxes off every axis: the tensor has products of inertia, and R diag(I) R^T must be the
// parallel-axis sum of the boxes' tensors.
TEST(Compound, BoxesOffAxisHaveTheParallelAxisTensor) {
  World w = make_world();
  const GeometryId g =
      compound(w, {{Shape::box({0.5_fx, 0.25_fx, 0.75_fx}), {1_fx, 2_fx, 0.5_fx}, kNone},
                   {Shape::box({0.2_fx, 0.6_fx, 0.3_fx}), {-0.7_fx, 0.3_fx, -1.1_fx}, kNone},
                   {Shape::box({0.4_fx, 0.4_fx, 0.1_fx}), {0.25_fx, -1.5_fx, 0.9_fx}, kNone}});
  const double mass = 10;
  const double v = 8 * (0.5 * 0.25 * 0.75 + 0.2 * 0.6 * 0.3 + 0.4 * 0.4 * 0.1);
  const Part want = combine({box_part(mass / v, {0.5, 0.25, 0.75}, {1, 2, 0.5}),
                             box_part(mass / v, {0.2, 0.6, 0.3}, {-0.7, 0.3, -1.1}),
                             box_part(mass / v, {0.4, 0.4, 0.1}, {0.25, -1.5, 0.9})});
  const MassProperties m = mass_of(w, g, 10_fx);
  expect_centre(m, want.centre, 1e-8);
  EXPECT_NE(m.inertia_axes, Quat::identity());
  const double e = relative_error(tensor_of(m), want.inertia);
  EXPECT_LT(e, 1e-6);
  EXPECT_GT(std::abs(want.inertia[0][1]), 0.1);  // the products of inertia are not small
  std::printf("off-axis boxes: tensor relative error %.3g\n", e);
}

// Two unequal spheres, no bar: the centre at the volume-weighted mean of the centres; about the
// line through them sum m_i 2/5 r_i^2, across it each adds m_i d_i^2.
TEST(Compound, AnUnequalDumbbellHasTheWeightedCentreAndMoments) {
  World w = make_world();
  const GeometryId g = compound(w, {{Shape::sphere(0.6_fx), {-1.2_fx, 0.3_fx, 0_fx}, kNone},
                                    {Shape::sphere(0.3_fx), {1_fx, 0.3_fx, 0_fx}, kNone}});
  const double v1 = 0.216;
  const double v2 = 0.027;
  const double m1 = 3 * v1 / (v1 + v2);
  const double m2 = 3 * v2 / (v1 + v2);
  const double cx = (v1 * -1.2 + v2 * 1.0) / (v1 + v2);
  const double d1 = -1.2 - cx;
  const double d2 = 1.0 - cx;
  const double along = m1 * 0.4 * 0.36 + m2 * 0.4 * 0.09;
  const double across = along + m1 * d1 * d1 + m2 * d2 * d2;
  const MassProperties m = mass_of(w, g, 3_fx);
  expect_centre(m, {cx, 0.3, 0}, 1e-8);
  Tensor want{};
  want[0][0] = along;
  want[1][1] = across;
  want[2][2] = across;
  const double e = relative_error(tensor_of(m), want);
  EXPECT_LT(e, 1e-6);
  EXPECT_NEAR(volume_of(w, g), 4.0 / 3.0 * kPi * (v1 + v2), 1e-6);
  std::printf("dumbbell: tensor relative error %.3g\n", e);
}

// A box turned 90 degrees about z is the box with its x and y extents swapped.
TEST(Compound, APartTurnedAQuarterIsTheBoxWithSwappedExtents) {
  World w = make_world();
  const Quat quarter = from_axis_angle(Vec3::unit_z(), Fixed::half_pi());
  const Vec3 at{0.3_fx, -0.4_fx, 1.2_fx};
  const CompoundChild other{Shape::sphere(0.25_fx), {-1_fx, 0.5_fx, 0_fx}, kNone};
  const GeometryId turned =
      compound(w, {{Shape::box({0.5_fx, 0.2_fx, 0.1_fx}), at, quarter}, other});
  const GeometryId swapped =
      compound(w, {{Shape::box({0.2_fx, 0.5_fx, 0.1_fx}), at, kNone}, other});
  const MassProperties a = mass_of(w, turned, 2_fx);
  const MassProperties b = mass_of(w, swapped, 2_fx);
  expect_centre(a, {b.center.x.to_double(), b.center.y.to_double(), b.center.z.to_double()}, 1e-8);
  const double e = relative_error(tensor_of(a), tensor_of(b));
  EXPECT_LT(e, 1e-6);
  std::printf("quarter turn: tensor relative error %.3g\n", e);
}

// A hull of a box's corners (off its own origin) as a part equals the box primitive placed at
// the hull's centroid: position + R * offset, turned by R.
TEST(Compound, AHullPartIsTheEquivalentBoxPart) {
  World w = make_world();
  const Vec3 h{0.4_fx, 0.25_fx, 0.6_fx};
  const Vec3 offset{0.5_fx, 0_fx, -0.25_fx};
  auto hull = w.create_convex_hull(box_corners(h, offset));
  ASSERT_TRUE(hull.ok()) << hull.message();
  const Quat turn = from_axis_angle(normalize(Vec3{1_fx, 1_fx, 0_fx}), 0.6_fx);
  const Vec3 at{1_fx, 0.5_fx, -0.5_fx};
  const CompoundChild other{Shape::capsule(0.2_fx, 0.5_fx), {-2_fx, 0_fx, 0_fx}, kNone};
  const GeometryId with_hull = compound(w, {{Shape::convex(*hull), at, turn}, other});
  const GeometryId with_box =
      compound(w, {{Shape::box(h), at + rotate(turn, offset), turn}, other});
  const MassProperties a = mass_of(w, with_hull, 5_fx);
  const MassProperties b = mass_of(w, with_box, 5_fx);
  expect_centre(a, {b.center.x.to_double(), b.center.y.to_double(), b.center.z.to_double()}, 1e-8);
  const double e = relative_error(tensor_of(a), tensor_of(b));
  EXPECT_LT(e, 1e-6);
  std::printf("hull part as box part: tensor relative error %.3g\n", e);
}

// Each refusal names the child and what is wrong, and registers nothing.
TEST(Compound, BadChildrenAreRefusedByIndex) {
  World w = make_world();
  auto small = w.create_convex_hull(box_corners({1_fx, 1_fx, 1_fx}, {9999_fx, 9999_fx, 9999_fx}));
  auto big =
      w.create_convex_hull(box_corners({500_fx, 500_fx, 500_fx}, {-9500_fx, -9500_fx, -9500_fx}));
  ASSERT_TRUE(small.ok() && big.ok());
  const GeometryId inner = compound(w, {{Shape::sphere(1_fx), {}, kNone}});
  const std::size_t registered = w.geometry_count();
  const CompoundChild ok{Shape::sphere(0.5_fx), {}, kNone};
  const Vec3 far{10000_fx, 10000_fx, 10000_fx};
  const auto refused = [&](const std::vector<CompoundChild>& children, const std::string& want) {
    const auto r = w.create_compound(children);
    ASSERT_FALSE(r.ok()) << want;
    EXPECT_NE(r.message().find(want), std::string::npos) << r.message();
    EXPECT_EQ(r.message().rfind("invalid compound: ", 0), 0U) << r.message();
    EXPECT_EQ(w.geometry_count(), registered);
  };
  refused({}, "a compound needs at least one child");
  refused(std::vector<CompoundChild>(65, ok), "at most 64 children, got 65");
  refused({ok, {Shape::plane(), {}, kNone}}, "child 1: a plane shape needs a static body");
  refused({{Shape::compound(inner), {}, kNone}}, "child 0: a compound cannot be a part");
  refused({ok, ok, {Shape::convex(GeometryId{9}), {}, kNone}},
          "child 2: a convex hull shape's geometry ID 9 is not registered");
  refused({{Shape::convex(inner), {}, kNone}}, "child 0: a convex hull shape's geometry ID");
  refused({ok, {Shape::sphere(0_fx), {}, kNone}}, "child 1: sphere radius must be > 0");
  refused({ok, {Shape::sphere(1_fx), {}, Quat{1_fx, 1_fx, 0_fx, 0_fx}}},
          "child 1: orientation must be a unit quaternion");
  refused({{Shape::sphere(1_fx), {0_fx, 10000.5_fx, 0_fx}, kNone}},
          "child 0: position y must be within +-10000 m, got 10000.5");
  refused({{Shape::box({1300_fx, 1300_fx, 1300_fx}), {}, kNone}},
          "child 0: volume of the box would be");
  refused({{Shape::box({600_fx, 600_fx, 600_fx}), {-1000_fx, 0_fx, 0_fx}, kNone},
           {Shape::box({600_fx, 600_fx, 600_fx}), {1000_fx, 0_fx, 0_fx}, kNone}},
          "the compound's volume (children 0..1) would be");
  // The big hull's centroid at -2 * 9500 per axis, the small one's at 2 * 9999: ~4e4 m apart on
  // each axis, so the small part's moment per unit mass about the centre is ~3e9 m^2.
  refused({{Shape::convex(*big), -far, kNone}, {Shape::convex(*small), far, kNone}},
          "child 1: its moment of inertia per unit mass about the compound's centroid");
  // At the limits, one part less far: accepted.
  EXPECT_TRUE(w.create_compound(std::vector<CompoundChild>(64, ok)).ok());
}

// The content hash names what the compound is, in any world: a hull part by the hull's content,
// not its ID. Moving a child changes it.
TEST(Compound, TheContentHashIsTheSameInEveryWorld) {
  World a = make_world();
  World b = make_world();
  const std::vector<Vec3> cube = box_corners({0.5_fx, 0.5_fx, 0.5_fx});
  const GeometryId ha = *a.create_convex_hull(cube);
  ASSERT_TRUE(b.create_convex_hull(box_corners({1_fx, 2_fx, 3_fx})).ok());
  const GeometryId hb = *b.create_convex_hull(cube);
  EXPECT_NE(ha, hb);
  const Quat turn = from_axis_angle(Vec3::unit_x(), 0.3_fx);
  const auto children = [&](GeometryId hull, Fixed x) {
    return std::vector<CompoundChild>{{Shape::capsule(0.25_fx, 0.5_fx), {x, 0_fx, 0_fx}, turn},
                                      {Shape::convex(hull), {0_fx, 2_fx, 0_fx}, kNone}};
  };
  const GeometryId ga = compound(a, children(ha, 1_fx));
  const GeometryId gb = compound(b, children(hb, 1_fx));
  EXPECT_NE(ga, gb);
  EXPECT_EQ(*a.geometry_hash(ga), *b.geometry_hash(gb));
  const GeometryId moved = compound(b, children(hb, 1.25_fx));
  EXPECT_NE(*b.geometry_hash(moved), *b.geometry_hash(gb));
  const GeometryId again = compound(b, children(hb, 1_fx));
  EXPECT_EQ(*b.geometry_hash(again), *b.geometry_hash(gb));
  EXPECT_NE(*a.geometry_hash(ga), *a.geometry_hash(ha));
  // A world with the compound body saves and restores (the geometry section names type 4).
  BodyDef d;
  d.shape = Shape::compound(ga);
  const BodyId id = add(a, d);
  const auto bytes = a.save();
  a.step();
  ASSERT_TRUE(a.restore(bytes).ok());
  EXPECT_EQ(a.save(), bytes);
  EXPECT_EQ(state(a, id).shape, Shape::compound(ga));
  // A world whose geometry 3 is a different compound refuses the state.
  World c = make_world();
  ASSERT_TRUE(c.create_convex_hull(cube).ok());
  compound(c, children(GeometryId{1}, 1.25_fx));
  const Status refused = c.restore(bytes);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.message().find("compound"), std::string::npos) << refused.message();
}

// Rays against a posed compound body hit the first part on their way, at the analytic distance.
TEST(Compound, RaysHitTheRightPart) {
  World w = make_world();
  const Quat quarter = from_axis_angle(Vec3::unit_z(), Fixed::half_pi());
  // A box of half extents (0.5, 0.2, 0.2) turned a quarter about z at local (2, 0, 0): it spans
  // x in [1.8, 2.2]; a sphere of radius 0.5 at local (-2, 0, 0).
  const GeometryId g =
      compound(w, {{Shape::sphere(0.5_fx), {-2_fx, 0_fx, 0_fx}, kNone},
                   {Shape::box({0.5_fx, 0.2_fx, 0.2_fx}), {2_fx, 0_fx, 0_fx}, quarter}});
  BodyDef d;
  d.shape = Shape::compound(g);
  d.position = {10_fx, 1_fx, 0_fx};
  d.orientation = from_axis_angle(Vec3::unit_y(), Fixed::half_pi());  // local x -> world -z
  d.type = BodyType::static_body;
  const BodyId id = add(w, d);
  // Along +z from z = -10: the box part is at world z = -2 (local x = +2), its near face at
  // z = -2.2; the sphere is at z = +2.
  const auto hit = w.raycast_closest({10_fx, 1_fx, -10_fx}, {0_fx, 0_fx, 20_fx});
  ASSERT_TRUE(hit.has_value());
  EXPECT_EQ(hit->body, id);
  EXPECT_NEAR(hit->point.z.to_double(), -2.2, 1e-6);
  EXPECT_NEAR(hit->fraction.to_double(), 7.8 / 20, 1e-6);
  EXPECT_NEAR(hit->normal.z.to_double(), -1, 1e-6);
  // Along -z from z = +10: the sphere first, at z = 2.5.
  const auto back = w.raycast_closest({10_fx, 1_fx, 10_fx}, {0_fx, 0_fx, -20_fx});
  ASSERT_TRUE(back.has_value());
  EXPECT_NEAR(back->point.z.to_double(), 2.5, 1e-6);
  EXPECT_NEAR(back->fraction.to_double(), 7.5 / 20, 1e-6);
  // Between the parts: nothing; the sphere off its centre line: at the analytic chord.
  EXPECT_FALSE(w.raycast_closest({12_fx, 1_fx, 0_fx}, {-4_fx, 0_fx, 0_fx}).has_value());
  const auto chord = w.raycast_closest({13_fx, 1.3_fx, 2_fx}, {-6_fx, 0_fx, 0_fx});
  ASSERT_TRUE(chord.has_value());
  EXPECT_NEAR(chord->point.x.to_double(), 10 + std::sqrt(0.25 - 0.09), 1e-6);
}

// The angular momentum of a body about its centre, world space, in doubles: R diag(I) R^T w with
// R the rotation of orientation * inertia axes.
std::array<double, 3> angular_momentum(const BodyState& b) {
  const Tensor m = matrix(to_mat3(b.orientation * b.inertia_axes));
  const double i[] = {b.inertia.x.to_double(), b.inertia.y.to_double(), b.inertia.z.to_double()};
  const double w[] = {b.angular_velocity.x.to_double(), b.angular_velocity.y.to_double(),
                      b.angular_velocity.z.to_double()};
  double local[3];  // diag(I) R^T w
  for (std::size_t k = 0; k < 3; ++k)
    local[k] = i[k] * (m[0][k] * w[0] + m[1][k] * w[1] + m[2][k] * w[2]);
  std::array<double, 3> out{};
  for (std::size_t row = 0; row < 3; ++row)
    out[row] = m[row][0] * local[0] + m[row][1] * local[1] + m[row][2] * local[2];
  return out;
}

// A dumbbell thrown spinning in zero gravity: its centre of mass moves in a straight line at
// constant speed, and its angular momentum about the centre stays what it was. The step
// integrates no gyroscopic torque (docs/SIM.md), so it is spun about a principal axis, which needs
// none; about another axis it would keep its angular velocity instead of precessing.
TEST(Compound, ASpinningDumbbellKeepsItsMomentum) {
  WorldDef def;
  def.gravity = {};
  def.enable_sleep = false;
  World w = make_world(def);
  const GeometryId g = compound(w, {{Shape::sphere(0.5_fx), {-1_fx, 0.2_fx, 0_fx}, kNone},
                                    {Shape::sphere(0.3_fx), {1.2_fx, 0.2_fx, 0_fx}, kNone},
                                    {Shape::cylinder(0.05_fx, 0.7_fx),
                                     {0.2_fx, 0.2_fx, 0_fx},
                                     from_axis_angle(Vec3::unit_z(), Fixed::half_pi())}});
  BodyDef d;
  d.shape = Shape::compound(g);
  d.position = {0_fx, 10_fx, 0_fx};
  d.orientation = from_axis_angle(normalize(Vec3{1_fx, 2_fx, 3_fx}), 0.7_fx);
  d.linear_velocity = {1_fx, 0.5_fx, -0.25_fx};
  const BodyId probe = add(w, d);
  // Spin about the body's principal axis of the largest moment (across the bar).
  const BodyState s0 = state(w, probe);
  ASSERT_TRUE(w.destroy_body(probe).ok());
  const Vec3 i = s0.inertia;
  const Vec3 axis =
      i.x >= i.y && i.x >= i.z ? Vec3::unit_x() : (i.y >= i.z ? Vec3::unit_y() : Vec3::unit_z());
  d.angular_velocity = rotate(d.orientation * s0.inertia_axes, axis * 3_fx);
  const BodyId id = add(w, d);
  const BodyState start = state(w, id);
  EXPECT_NE(start.center_of_mass, Vec3{});
  const Vec3 c0 = start.world_center();
  const Vec3 v0 = start.linear_velocity;
  const auto l0 = angular_momentum(start);
  const double l0_length = std::sqrt(l0[0] * l0[0] + l0[1] * l0[1] + l0[2] * l0[2]);
  double worst_centre = 0;
  double worst_momentum = 0;
  for (int frame = 1; frame <= 240; ++frame) {
    w.step();
    const BodyState b = state(w, id);
    const double t = frame / 60.0;
    const Vec3 c = b.world_center();
    const double dc[] = {c.x.to_double() - (c0.x.to_double() + v0.x.to_double() * t),
                         c.y.to_double() - (c0.y.to_double() + v0.y.to_double() * t),
                         c.z.to_double() - (c0.z.to_double() + v0.z.to_double() * t)};
    worst_centre = std::max(worst_centre, std::sqrt(dc[0] * dc[0] + dc[1] * dc[1] + dc[2] * dc[2]));
    ASSERT_LT(worst_centre, 1e-6) << frame;
    EXPECT_EQ(b.linear_velocity, v0);
    const auto l = angular_momentum(b);
    const double dl = std::sqrt((l[0] - l0[0]) * (l[0] - l0[0]) + (l[1] - l0[1]) * (l[1] - l0[1]) +
                                (l[2] - l0[2]) * (l[2] - l0[2]));
    worst_momentum = std::max(worst_momentum, dl / l0_length);
    ASSERT_LE(dl, 0.005 * l0_length) << "frame " << frame;
  }
  EXPECT_NE(state(w, id).orientation, start.orientation);
  std::printf("spinning dumbbell over 4 s: centre off the line by %.3g m, momentum by %.3g\n",
              worst_centre, worst_momentum);
}

TEST(Compound, RestsOnAPlaneOnItsLowestParts) {
  // A stool of a seat and four legs of different kinds (box, capsule, cylinder, hull, each
  // reaching y = 0 in the body's frame) dropped from 0.5 m onto a plane, and onto a plane turned
  // 0.3 rad: every part meets a plane (a plane is unbounded: no bounding ball can cull it), and
  // the stool comes to rest on its four feet at the plane's height (within the contact slop, 1 cm)
  // and upright. On the slope its centre of mass (0.35 m up) leans 0.35 tan 0.3 = 0.11 m downhill,
  // inside the feet's 0.2 m: it stands.
  for (const Fixed tilt : {0_fx, 0.3_fx}) {
    World w = make_world();
    const Quat ground_turn = from_axis_angle(Vec3::unit_z(), tilt);
    BodyDef ground;
    ground.type = BodyType::static_body;
    ground.shape = Shape::plane();
    ground.orientation = ground_turn;
    ground.friction = 1_fx;  // tan 0.3 < 1: the stool does not slide on the turned plane
    add(w, ground);
    const auto hull = w.create_convex_hull(box_corners({0.03_fx, 0.25_fx, 0.03_fx}));
    ASSERT_TRUE(hull.ok()) << hull.message();
    const GeometryId g =
        compound(w, {{Shape::box({0.3_fx, 0.03_fx, 0.3_fx}), {0_fx, 0.53_fx, 0_fx}, kNone},
                     {Shape::box({0.03_fx, 0.25_fx, 0.03_fx}), {-0.2_fx, 0.25_fx, -0.2_fx}, kNone},
                     {Shape::capsule(0.03_fx, 0.22_fx), {0.2_fx, 0.25_fx, -0.2_fx}, kNone},
                     {Shape::cylinder(0.03_fx, 0.25_fx), {-0.2_fx, 0.25_fx, 0.2_fx}, kNone},
                     {Shape::convex(*hull), {0.2_fx, 0.25_fx, 0.2_fx}, kNone}});
    BodyDef d;
    d.shape = Shape::compound(g);
    d.orientation = ground_turn;
    d.position = rotate(ground_turn, Vec3{0_fx, 0.5_fx, 0_fx});
    const BodyId id = add(w, d);
    for (int f = 0; f < 180; ++f)
      w.step();
    const BodyState b = state(w, id);
    // The feet are the body's frame's y = 0: the origin's height above the turned plane.
    const Vec3 up = rotate(ground_turn, Vec3::unit_y());
    const Fixed height = dot(b.position, up);
    EXPECT_GT(height, -0.01_fx) << "tilt " << to_string(tilt) << ": " << to_string(height);
    EXPECT_LT(height, 0.01_fx) << "tilt " << to_string(tilt) << ": " << to_string(height);
    EXPECT_GT(dot(rotate(b.orientation, Vec3::unit_y()), up), 0.999_fx) << to_string(tilt);
    EXPECT_LT(length(b.linear_velocity), 0.01_fx) << to_string(tilt);
  }
}

}  // namespace
}  // namespace detsim
