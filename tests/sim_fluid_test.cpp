// Fluids (docs/PARTICLES.md, "Fluids") against the physics: water at rest in a tank keeps its
// volume (its density) and a flat surface, a released column's front follows Martin and Moyce's
// experiment, a box floats at the depth Archimedes gives and a denser one sinks; and the API's
// refusals and layout. Every expectation is derived from a formula or an experiment stated beside
// it, never read back from a run.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <iostream>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

#include "support/sim_helpers.hpp"

namespace detsim {
namespace {

using namespace detsim::literals;

using test::add;
using test::make_world;

double d(Fixed x) {
  return x.to_double();
}

constexpr Fixed kSpacing = 0.05_fx;
constexpr double kS = 0.05;

/// A tank of static boxes: a floor at y = 0 and four walls, its inside [0, length] x [0, 2 m] x
/// [0, depth].
void tank(World& w, Fixed length, Fixed depth) {
  const Fixed t = 0.1_fx;
  const auto wall = [&](Vec3 half, Vec3 at) {
    add(w, {.type = BodyType::static_body, .shape = Shape::box(half), .position = at});
  };
  wall({length / 2_fx + t * 2_fx, t, depth / 2_fx + t * 2_fx}, {length / 2_fx, -t, depth / 2_fx});
  wall({t, 1_fx, depth / 2_fx + t * 2_fx}, {-t, 1_fx, depth / 2_fx});
  wall({t, 1_fx, depth / 2_fx + t * 2_fx}, {length + t, 1_fx, depth / 2_fx});
  wall({length / 2_fx, 1_fx, t}, {length / 2_fx, 1_fx, -t});
  wall({length / 2_fx, 1_fx, t}, {length / 2_fx, 1_fx, depth + t});
}

/// Water (1000 kg/m^3) filling [0, size.x] x [0, size.y] x [0, size.z] at kSpacing.
FluidDef water(Vec3 size) {
  FluidDef f;
  f.min = {};
  f.max = size;
  f.spacing = kSpacing;
  f.particle_radius = kSpacing / 2_fx;
  f.settings.substeps = 2;
  return f;
}

std::vector<Vec3> positions(const World& w, ParticleGroupId id) {
  auto p = w.particle_positions(id);
  EXPECT_TRUE(p.ok()) << p.message();
  return p.ok() ? *p : std::vector<Vec3>{};
}

/// The free surface's height above (x, z): the highest particle centre within one spacing
/// horizontally, plus the particle radius.
double surface_at(const std::vector<Vec3>& p, double x, double z) {
  double top = -1;
  for (const Vec3& q : p) {
    const double dx = d(q.x) - x;
    const double dz = d(q.z) - z;
    if (dx * dx + dz * dz < kS * kS) top = std::max(top, d(q.y));
  }
  return top + kS / 2;
}

// Water at rest in a tank. It is incompressible: N particles of spacing s fill N s^3 of the tank,
// so over a floor of area A its surface stands at N s^3 / A; a surface within 2 % of that height
// is a mean density within 2 % of the rest density. The most compressed particle (its kernel
// density from its neighbours, ParticleGroupStats) is within 2 % too; the surface is flat within
// one particle radius, and no particle is outside the tank.
TEST(Fluid, AtRestKeepsItsDensityAndAFlatSurfaceInsideTheTank) {
  World w = make_world();
  const Fixed side = kSpacing * 8_fx;
  tank(w, side, side);
  auto id = w.create_fluid(water({side, kSpacing * 12_fx, side}));
  ASSERT_TRUE(id.ok()) << id.message();
  for (int f = 0; f < 180; ++f)
    w.step();
  const std::vector<Vec3> p = positions(w, *id);
  ASSERT_EQ(p.size(), 8U * 12U * 8U);
  const double l = d(side);
  const double expected = static_cast<double>(p.size()) * kS * kS * kS / (l * l);
  std::vector<double> heights;
  for (int i = 1; i <= 4; ++i)
    for (int k = 1; k <= 4; ++k)
      heights.push_back(surface_at(p, l * i / 5, l * k / 5));
  double mean = 0;
  for (double h : heights)
    mean += h / static_cast<double>(heights.size());
  EXPECT_NEAR(mean, expected, 0.02 * expected) << "mean density off by " << expected / mean - 1;
  std::cout << "measured: surface " << mean << " m for " << expected << " m (density "
            << expected / mean - 1 << " off)\n";
  const auto [lowest, highest] = std::minmax_element(heights.begin(), heights.end());
  EXPECT_LE(*highest - *lowest, kS / 2) << "surface between " << *lowest << " and " << *highest;
  const ParticleGroupStats st = w.particle_group_stats(*id).value();
  std::cout << "measured: surface spread " << *highest - *lowest << " m, most compressed "
            << d(st.max_density_error) << "\n";
  EXPECT_EQ(st.type, ParticleGroupType::fluid);
  EXPECT_LT(d(st.max_density_error), 0.02);
  for (const Vec3& q : p) {
    ASSERT_GE(d(q.x), 0.0);
    ASSERT_LE(d(q.x), l);
    ASSERT_GE(d(q.z), 0.0);
    ASSERT_LE(d(q.z), l);
    ASSERT_GE(d(q.y), 0.0);
  }
}

// Martin and Moyce (1952), "An experimental study of the collapse of liquid columns on a rigid
// horizontal plane", figure 3, n^2 = 2 (a column a wide and 2a high), a = 2.25 in: the surge
// front z against time, as Z = z / a at T = t sqrt(2 g / a). The same column here, a = 10
// spacings (0.5 m), as deep as it is wide: its front (the 99.5th percentile of the particles' x,
// plus a radius, so that a few drops thrown ahead do not count) is within 10 % of the measured
// curve at every measured point of the first 0.5 s.
TEST(Fluid, DamBreakFrontFollowsMartinAndMoyce) {
  World w = make_world();
  const double a = 10 * kS;
  const Fixed a_fx = kSpacing * 10_fx;
  tank(w, a_fx * 6_fx, a_fx);
  auto id = w.create_fluid(water({a_fx, a_fx * 2_fx, a_fx}));
  ASSERT_TRUE(id.ok()) << id.message();
  struct Point {
    double t;
    double z;
  };
  constexpr std::array<Point, 4> kMeasured{
      {{0.832, 1.217}, {1.219, 1.474}, {1.997, 2.292}, {2.547, 2.995}}};
  const double g = 9.81;
  const double dt = 1.0 / 60.0;
  std::vector<double> front{1.0};  // Z at frame 0: the column's face
  for (int f = 1; f <= 30; ++f) {
    w.step();
    std::vector<double> x;
    for (const Vec3& q : positions(w, *id))
      x.push_back(d(q.x));
    std::sort(x.begin(), x.end());
    front.push_back((x[x.size() - 1 - x.size() / 200] + kS / 2) / a);
  }
  for (const Point& m : kMeasured) {
    const double t = m.t / std::sqrt(2 * g / a);  // seconds
    ASSERT_LE(t, 30 * dt);
    const double frame = t / dt;
    const auto k = static_cast<std::size_t>(frame);
    const double z = front[k] + (front[k + 1] - front[k]) * (frame - static_cast<double>(k));
    EXPECT_NEAR(z, m.z, 0.1 * m.z) << "at T = " << m.t << " (t = " << t << " s)";
    std::cout << "measured: T " << m.t << " Z " << z << " (experiment " << m.z << ", "
              << 100 * (z / m.z - 1) << " %)\n";
  }
}

// Archimedes: a box of density rho_b < rho floats with the water it displaces weighing what it
// weighs: submerged depth m / (rho side^2); the water's surface over the tank's floor area A
// stands at (N s^3 + m / rho) / A. Its centre rests within one particle radius of where that puts
// it (the resolution of the free surface itself: the flatness asked of water at rest). A box
// denser than water sinks: its top ends below the surface.
TEST(Fluid, ABoxFloatsAtTheDepthArchimedesGivesAndADenserOneSinks) {
  const Fixed side = kSpacing * 8_fx;
  const double box = 0.2;
  for (const double density : {500.0, 2000.0}) {
    World w = make_world();
    tank(w, side, side);
    auto id = w.create_fluid(water({side, kSpacing * 8_fx, side}));
    ASSERT_TRUE(id.ok()) << id.message();
    const double mass = density * box * box * box;
    const BodyId b = add(w, {.shape = Shape::box({0.1_fx, 0.1_fx, 0.1_fx}),
                             .position = {side / 2_fx, 0.6_fx, side / 2_fx},
                             .mass = Fixed::from_raw(std::llround(mass * 4294967296.0))});
    for (int f = 0; f < 150; ++f)
      w.step();
    const double y = d(w.body(b).value().position.y);
    const double l = d(side);
    const double n = static_cast<double>(positions(w, *id).size());
    if (density < 1000) {
      const double surface = (n * kS * kS * kS + mass / 1000) / (l * l);
      const double expected = surface - mass / (1000 * box * box) + box / 2;
      EXPECT_NEAR(y, expected, kS / 2) << "density " << density;
      std::cout << "measured: box of " << density << " kg/m^3 floats at " << y << " m, " << expected
                << " m expected\n";
    } else {
      // Wholly under: it displaces its whole volume.
      const double surface = (n * kS * kS * kS + box * box * box) / (l * l);
      EXPECT_LT(y + box / 2, surface) << "density " << density << ": it should sink";
      std::cout << "measured: box of " << density << " kg/m^3: top at " << y + box / 2
                << " m, surface at " << surface << " m\n";
    }
  }
}

// ---- API ----

auto make_fluid = [](World& w, const FluidDef& def) { return w.create_fluid(def); };

void expect_refused(const FluidDef& def, const std::string& field) {
  World w = make_world();
  const std::uint64_t before = w.hashes().total;
  auto id = make_fluid(w, def);
  ASSERT_FALSE(id.ok()) << "accepted, expected a refusal naming " << field;
  EXPECT_NE(id.message().find(field), std::string::npos) << id.message();
  EXPECT_NE(id.message().find("invalid fluid definition"), std::string::npos) << id.message();
  EXPECT_EQ(w.hashes().total, before);
  EXPECT_TRUE(w.particle_group_ids().empty());
}

TEST(FluidApi, RefusalsNameTheField) {
  FluidDef f;
  f.spacing = 0_fx;
  expect_refused(f, "spacing");
  f = FluidDef{};
  f.spacing = 0.005_fx;  // below 2^-7 m
  expect_refused(f, "spacing");
  f = FluidDef{};
  f.max = {1_fx, 0.05_fx, 1_fx};  // less than a spacing high
  expect_refused(f, "max.y - min.y");
  f = FluidDef{};
  f.max = f.min;
  expect_refused(f, "max.x - min.x");
  f = FluidDef{};
  f.max = f.min + Vec3{f.spacing, f.spacing, f.spacing};  // room for one particle only
  expect_refused(f, "1 x 1 x 1 particles");
  f = FluidDef{};
  f.spacing = 0.01_fx;  // 100^3 particles
  expect_refused(f, "max_particles_per_group");
  f = FluidDef{};
  f.rest_density = 0_fx;
  expect_refused(f, "rest_density");
  f = FluidDef{};
  f.viscosity = 2_fx;
  expect_refused(f, "viscosity");
  f = FluidDef{};
  f.viscosity = -0.1_fx;
  expect_refused(f, "viscosity");
  f = FluidDef{};
  f.particle_radius = 0_fx;
  expect_refused(f, "particle_radius");
  f = FluidDef{};
  f.particle_radius = 0.2_fx;  // above the spacing
  expect_refused(f, "particle_radius");
  f = FluidDef{};
  f.settings.substeps = 0;
  expect_refused(f, "substeps");
  f = FluidDef{};
  f.min = {Fixed::min(), 0_fx, 0_fx};
  expect_refused(f, "min");
}

// The block holds as many particles as fit whole at the spacing (a spacing with no exact binary
// value, 0.05, still makes 20 along 20 spacings), layer by layer from the bottom (index =
// (y * nz + z) * nx + x), each at min + spacing * (i + 1/2); each weighs rest_density * s^3.
TEST(FluidApi, ParticlesFillTheBlockAtTheSpacing) {
  World w = make_world();
  FluidDef f;
  f.min = {1_fx, 2_fx, 3_fx};
  f.max = f.min + Vec3{kSpacing * 4_fx, kSpacing * 3_fx, kSpacing * 20_fx};
  f.spacing = kSpacing;
  f.particle_radius = kSpacing / 2_fx;
  auto id = w.create_fluid(f);
  ASSERT_TRUE(id.ok()) << id.message();
  const std::vector<Vec3> p = positions(w, *id);
  ASSERT_EQ(p.size(), 4U * 3U * 20U);
  const auto at = [&](std::uint32_t x, std::uint32_t y, std::uint32_t z) {
    return p[(y * 20 + z) * 4 + x];
  };
  const Vec3 half{kSpacing / 2_fx, kSpacing / 2_fx, kSpacing / 2_fx};
  EXPECT_EQ(at(0, 0, 0), f.min + half);
  const Vec3 last = f.min + half + Vec3{kSpacing * 3_fx, kSpacing * 2_fx, kSpacing * 19_fx};
  EXPECT_EQ(at(3, 2, 19), last);
  EXPECT_EQ(w.fluid_def(*id).value(), f);
  EXPECT_FALSE(w.rope_def(*id).ok());
  const ParticleGroupStats st = w.particle_group_stats(*id).value();
  EXPECT_EQ(st.radius, f.particle_radius);
  // At rest as laid out: no particle is compressed (beyond the rounding of its neighbours'
  // distances).
  EXPECT_LT(d(st.max_density_error), 1e-6);
  // A push of F for one step gives the block (mass N rho s^3) dv = F dt / m.
  ASSERT_TRUE(w.apply_particle_force(*id, {600_fx, 0_fx, 0_fx}).ok());
  WorldDef def;
  const double m = 240 * 1000 * kS * kS * kS;
  w.step();
  double vx = 0;
  const std::vector<Vec3> v = w.particle_velocities(*id).value();
  for (const Vec3& q : v)
    vx += d(q.x) / 240;
  EXPECT_NEAR(vx, 600 * d(def.dt) / m, 0.02 * 600 * d(def.dt) / m);
}

}  // namespace
}  // namespace detsim
