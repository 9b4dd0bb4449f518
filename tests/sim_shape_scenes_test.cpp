// The physical promises of the scenes of registered geometry: rocks (convex hulls onto a
// heightfield), level (every kind of body onto a triangle-mesh level) and furniture (compounds
// whose centre of mass is off their origin). Each expectation follows from a law (energy is never
// created; a solid cannot pass a surface) or from the scene's geometry at frame 0 (where a centre
// of mass stands against its support), never from a number read back from a run.
#include <cmath>
#include <cstdio>
#include <optional>
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

// Kinetic plus gravitational potential energy of every dynamic body, J (in double: a measurement,
// not part of the simulation). Rotational energy is 1/2 sum I_k w_k^2 in the principal frame.
double mechanical_energy(const World& w) {
  const double g = -d(w.def().gravity.y);
  double e = 0;
  for (const BodyId id : w.body_ids()) {
    const BodyState b = state(w, id);
    if (b.type != BodyType::dynamic) continue;
    const double m = d(b.mass);
    const Vec3 v = b.linear_velocity;
    e += 0.5 * m * (d(v.x) * d(v.x) + d(v.y) * d(v.y) + d(v.z) * d(v.z));
    const Vec3 wl = rotate(conjugate(b.orientation * b.inertia_axes), b.angular_velocity);
    e += 0.5 * (d(b.inertia.x) * d(wl.x) * d(wl.x) + d(b.inertia.y) * d(wl.y) * d(wl.y) +
                d(b.inertia.z) * d(wl.z) * d(wl.z));
    e += m * g * d(b.world_center().y);
  }
  return e;
}

// The height of `surface`'s top below (x, z), from a ray cast straight down from high above, or
// nothing where the ray misses it.
std::optional<Fixed> surface_below(const World& w, BodyId surface, Fixed x, Fixed z) {
  for (const RayHit& h : w.raycast_all({x, 100_fx, z}, {0_fx, -200_fx, 0_fx}))
    if (h.body == surface) return h.point.y;
  return std::nullopt;
}

BodyId first_static(const World& w) {
  for (const BodyId id : w.body_ids())
    if (state(w, id).type == BodyType::static_body) return id;
  return {};
}

struct Watch {
  double start_energy = 0;
  double worst_gain = 0;    // the most the energy ever rose above its value at frame 0, J
  Fixed worst_sink;         // the deepest a centre of mass went below the surface under it, m
  std::size_t checked = 0;  // centres of mass found above the surface (inside its extent)
};

// Steps `frames`, watching the energy every frame and every dynamic body's centre of mass against
// the surface under it every 10th.
Watch run_watching(Scenario& s, BodyId surface, std::size_t frames) {
  const World& w = s.world();
  Watch out;
  out.start_energy = mechanical_energy(w);
  for (std::size_t f = 0; f < frames; ++f) {
    s.step();
    out.worst_gain = std::max(out.worst_gain, mechanical_energy(w) - out.start_energy);
    if (f % 10 != 9) continue;
    for (const BodyId id : w.body_ids()) {
      const BodyState b = state(w, id);
      if (b.type != BodyType::dynamic) continue;
      const Vec3 c = b.world_center();
      const auto top = surface_below(w, surface, c.x, c.z);
      if (!top) continue;
      ++out.checked;
      out.worst_sink = max(out.worst_sink, *top - c.y);
    }
  }
  return out;
}

// The potential energy of the whole scene falling 1 cm: the yardstick of "no energy created".
double one_centimetre(const World& w) {
  double m = 0;
  for (const BodyId id : w.body_ids()) {
    const BodyState b = state(w, id);
    if (b.type == BodyType::dynamic) m += d(b.mass);
  }
  return m * -d(w.def().gravity.y) * 0.01;
}

// Runs `s` for 10 s (scaled) on its first static body, a surface of type `surface`: no dynamic
// body's centre of mass goes below the surface under it (a centre of mass is inside its body, so
// it cannot be below what the body rests on), and the energy never exceeds its start by more than
// the potential energy of the scene dropping 1 cm (a fall only loses energy: impacts and friction
// dissipate, nothing drives; the solver's position correction may lift a body a little).
void expect_lands_without_sinking_or_gaining_energy(Scenario s, ShapeType surface,
                                                    std::size_t at_least_checked) {
  const std::string name(s.info().name);
  const BodyId ground = first_static(s.world());
  ASSERT_EQ(state(s.world(), ground).shape.type, surface) << name;
  const double tolerance = one_centimetre(s.world());
  const Watch r = run_watching(s, ground, test::scaled(600));
  std::printf(
      "[ %s ] energy rose at most %.3f J (1 cm of the scene: %.3f J); deepest centre of mass "
      "below the surface %s m over %zu checks\n",
      name.c_str(), r.worst_gain, tolerance, to_string(r.worst_sink).c_str(), r.checked);
  EXPECT_LE(r.worst_gain, tolerance) << name;
  EXPECT_LE(r.worst_sink, 0_fx) << name << ": " << to_string(r.worst_sink);
  EXPECT_GT(r.checked, at_least_checked) << name;
}

TEST(RocksScenario, HullsLandOnTheHeightfieldWithoutSinkingOrGainingEnergy) {
  // 60 rocks: four layers of 15 falling onto rolling hills and onto each other.
  expect_lands_without_sinking_or_gaining_energy(make("rocks", {.seed = 1, .count = 60}),
                                                 ShapeType::heightfield, 60);
}

TEST(LevelScenario, EveryKindOfBodyStaysOnTheMeshWithoutGainingEnergy) {
  // Boxes, rocks, capsules and compound tables dropped onto the ramp, the stairs and the ground of
  // a triangle mesh.
  expect_lands_without_sinking_or_gaining_energy(make("level", {.seed = 1, .count = 8}),
                                                 ShapeType::mesh, 32);
}

// How far a body's local +y axis is tilted from the world's up, radians.
double tilt(const BodyState& b) {
  const Vec3 up = rotate(b.orientation, Vec3::unit_y());
  return std::acos(std::clamp(d(up.y), -1.0, 1.0));
}

TEST(FurnitureScenario, CompoundsFallWhereTheirCentreOfMassSaysAndTheUprightChairStands) {
  // Each set: a chair tipped back 25 degrees onto its back legs, a hammer standing on its handle
  // leaning 5 degrees towards its head, a chair standing upright. Where each goes is read from its
  // centre of mass at frame 0 against the edge it stands on: beyond the edge, it topples over
  // that edge; over its feet, it stands.
  Scenario s = make("furniture", {.seed = 1, .count = 2});
  const World& w = s.world();
  std::vector<BodyState> start;
  for (const BodyId id : w.body_ids())
    if (state(w, id).type == BodyType::dynamic) start.push_back(state(w, id));
  ASSERT_EQ(start.size(), 6U);
  // Each tipped chair's rearmost foot: the rearmost corner within 1 cm of its lowest (frame 0).
  std::vector<Fixed> rearmost_foot;
  for (const BodyState& b0 : start) {
    const ShapeOutline o = w.body_outline(b0.id).value();
    Fixed lowest = b0.position.y + 10_fx;
    for (const ShapeOutline& part : o.parts)
      for (const Vec3& p : part.points)
        lowest = min(lowest, p.y);
    Fixed rear = b0.position.z + 10_fx;
    for (const ShapeOutline& part : o.parts)
      for (const Vec3& p : part.points)
        if (p.y < lowest + 0.01_fx) rear = min(rear, p.z);
    rearmost_foot.push_back(rear);
  }
  for (int f = 0; f < 300; ++f)  // six bodies: the full 5 s even in the sanitizer build
    s.step();
  for (std::size_t i = 0; i < start.size(); ++i) {
    const BodyState& b0 = start[i];
    const BodyState b = state(w, b0.id);
    const Vec3 c0 = b0.world_center();
    // The offset centre of mass: every compound's is off its origin, in its local frame.
    EXPECT_NE(b0.center_of_mass, Vec3{}) << "body " << b0.id.value;
    switch (i % 3) {
      case 0:  // the tipped chair: its centre of mass is behind (-z of) its rearmost foot
        EXPECT_LT(c0.z, rearmost_foot[i]) << "the scene's chair " << b0.id.value << " balances";
        EXPECT_GT(tilt(b), 1.2) << "chair " << b0.id.value << " did not fall on its back";
        EXPECT_LT(b.world_center().z, c0.z) << "chair " << b0.id.value << " fell forwards";
        break;
      case 1:  // the hammer: leaning towards +x (its head's side), it falls that way
        EXPECT_GT(tilt(b), 1.2) << "hammer " << b0.id.value << " still stands";
        EXPECT_GT(b.world_center().x, c0.x + 0.1_fx) << "hammer " << b0.id.value;
        break;
      default:  // the upright chair: its centre of mass is over its four feet; it stands
        EXPECT_LT(tilt(b), 0.02) << "chair " << b0.id.value;
        EXPECT_LT(abs(b.world_center().x - c0.x) + abs(b.world_center().z - c0.z), 0.01_fx)
            << "chair " << b0.id.value << " wandered";
        break;
    }
  }
}

}  // namespace
}  // namespace detsim
