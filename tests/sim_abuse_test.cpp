// Physics under abuse: huge forces, bullets, heavy bodies on light ones, bodies pressed into the
// ground, hundreds of bodies spawned at one point, face-on impacts at the speed limit, and scenes
// a thousand times smaller than a metre. Each case asserts physics (a bound from the world's
// limits, a conservation law, a symmetry, which side of a surface a body is on), never a number
// read back from a run, and each runs twice, the second time through a save and restore half way,
// which must give the same bits frame for frame.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

#include "support/sim_helpers.hpp"

namespace detsim {
namespace {

using namespace detsim::literals;

using test::add;
using test::add_ground;
using test::make_world;
using test::state;

using Frame = std::function<void(World&, int)>;

// Builds a world with `build`, then runs `frames` steps, calling `before` ahead of each step and
// `check` after it. A second copy runs beside it and is saved and restored into a fresh world at
// half time: from then on its hashes must equal the first copy's, frame for frame.
void run(const WorldDef& def, const std::function<void(World&)>& build, int frames,
         const Frame& before, const Frame& check) {
  World a = make_world(def);
  World b = make_world(def);
  build(a);
  build(b);
  for (int f = 0; f < frames; ++f) {
    if (f == frames / 2) {
      std::vector<std::uint8_t> bytes;
      b.save(bytes);
      World c = make_world(def);
      ASSERT_TRUE(c.restore(bytes).ok());
      b = std::move(c);
    }
    if (before) {
      before(a, f);
      before(b, f);
    }
    a.step();
    b.step();
    ASSERT_EQ(a.hashes(), b.hashes()) << "frame " << f;
    if (check) check(a, f);
    if (testing::Test::HasFatalFailure()) return;
  }
}

WorldDef no_gravity() {
  WorldDef def;
  def.gravity = {};
  return def;
}

BodyDef box(Vec3 position, Fixed half, Fixed mass) {
  BodyDef d;
  d.shape = Shape::box({half, half, half});
  d.position = position;
  d.mass = mass;
  return d;
}

// Kinetic energy, translational and rotational (world-space inertia from the body's state is not
// public: the rotational part uses the body-frame inertia of a cube, |w|^2 I for I = m s^2 / 6 with
// s the edge, the same on every axis, so orientation does not matter).
double kinetic_energy(const World& w, BodyId id, double edge) {
  const BodyState s = state(w, id);
  const double m = s.mass.to_double();
  const double v2 = length_squared(s.linear_velocity).to_double();
  const double w2 = length_squared(s.angular_velocity).to_double();
  return 0.5 * m * v2 + 0.5 * (m * edge * edge / 6.0) * w2;
}

// --- A free body moves the way its impulse points, never faster than the speed limit ---------

class LargeForce : public testing::TestWithParam<std::int32_t> {};

TEST_P(LargeForce, MovesAFreeBodyForwardAndNoFasterThanTheLimit) {
  const Fixed force = Fixed::from_int(GetParam());
  const WorldDef def = no_gravity();
  BodyId id;
  Fixed last_x;
  const Fixed step_limit = def.max_linear_speed * def.dt;
  run(
      def, [&](World& w) { id = add(w, box({}, 0.25_fx, 1_fx)); }, 6,
      [&](World& w, int) {
        ASSERT_TRUE(w.apply_force(id, {force, {}, {}}).ok());
      },
      [&](World& w, int f) {
        const BodyState s = state(w, id);
        const Fixed dx = s.position.x - last_x;
        last_x = s.position.x;
        EXPECT_GT(dx, Fixed::zero()) << "frame " << f << ": the body moved against the force";
        EXPECT_LE(dx, step_limit) << "frame " << f << ": faster than the speed limit";
        EXPECT_EQ(s.position.y, Fixed::zero());
        EXPECT_EQ(s.position.z, Fixed::zero());
        EXPECT_LE(length(s.linear_velocity), def.max_linear_speed);
      });
}

INSTANTIATE_TEST_SUITE_P(Newtons, LargeForce,
                         testing::Values(1000, 100000, 1000000, 100000000, 1000000000));

// --- The speed limits hold at any limit the definition allows, down to one ulp ---------------

// A velocity a few ulp long clamped to a limit of an ulp: the factor's ulp steps no longer move
// the rounded result, and the clamp once took ~2^31 of them (the API fuzzer's timeout). It must
// end, and end within the limit.
TEST(SpeedLimit, HoldsAtALimitOfOneUlp) {
  WorldDef def = no_gravity();
  def.max_linear_speed = Fixed::from_raw(1);
  def.max_angular_speed = Fixed::from_raw(1);
  World w = make_world(def);
  BodyDef d = box({}, 0.25_fx, 1_fx);
  d.linear_velocity = {Fixed::from_raw(3), Fixed::from_raw(2), Fixed::from_raw(-2)};
  d.angular_velocity = {Fixed::from_raw(2), Fixed::from_raw(-2), Fixed::from_raw(2)};
  const BodyId id = add(w, d);
  for (int f = 0; f < 3; ++f) {
    ASSERT_TRUE(w.apply_force(id, {1_fx, 1_fx, 1_fx}).ok());
    w.step();
    const BodyState s = state(w, id);
    EXPECT_FALSE(length_exceeds(s.linear_velocity, def.max_linear_speed)) << "frame " << f;
    EXPECT_FALSE(length_exceeds(s.angular_velocity, def.max_angular_speed)) << "frame " << f;
  }
}

// --- A bullet flagged CCD stops at the body it hits -----------------------------------------

struct Bullet {
  int speed;  // m/s
  int gap;    // m between the facing surfaces at the start
};

class BulletHitsCrate : public testing::TestWithParam<Bullet> {};

TEST_P(BulletHitsCrate, NeverEndsOnTheFarSide) {
  const Bullet p = GetParam();
  const WorldDef def = no_gravity();
  BodyId bullet;
  BodyId crate;
  const Fixed half = 0.25_fx;
  run(
      def,
      [&](World& w) {
        BodyDef b = box({}, half, 1_fx);
        b.linear_velocity = {Fixed::from_int(p.speed), {}, {}};
        b.ccd = true;
        bullet = add(w, b);
        crate = add(w, box({Fixed::from_int(p.gap) + 2_fx * half, {}, {}}, half, 1_fx));
      },
      60, {},
      [&](World& w, int f) {
        const Fixed xb = state(w, bullet).position.x;
        const Fixed xc = state(w, crate).position.x;
        // Centres at least a little less than one edge apart: the boxes may overlap by the
        // contact tolerances, never pass.
        EXPECT_GT(xc - xb, half) << "frame " << f << ": bullet at " << to_string(xb)
                                 << ", crate at " << to_string(xc);
      });
}

INSTANTIATE_TEST_SUITE_P(Speeds, BulletHitsCrate,
                         testing::Values(Bullet{200, 20}, Bullet{400, 2}, Bullet{1000, 5},
                                         Bullet{1500, 1}, Bullet{1500, 30}));

// --- A body pressed into the ground stays on the surface side ---------------------------------

class PressedIntoGround : public testing::TestWithParam<std::int32_t> {};

TEST_P(PressedIntoGround, KeepsItsCentreAboveTheSurface) {
  const Fixed weights = Fixed::from_int(GetParam());
  const WorldDef def;
  BodyId id;
  const Fixed half = 0.25_fx;
  const Fixed force = weights * def.gravity.y;  // down, `weights` times the body's weight (1 kg)
  run(
      def,
      [&](World& w) {
        add_ground(w);
        id = add(w, box({{}, half, {}}, half, 1_fx));
      },
      120,
      [&](World& w, int) {
        ASSERT_TRUE(w.apply_force(id, {{}, force, {}}).ok());
      },
      [&](World& w, int f) {
        const BodyState s = state(w, id);
        EXPECT_GT(s.position.y, Fixed::zero()) << "frame " << f << ": centre below the ground";
      });
}

INSTANTIATE_TEST_SUITE_P(TimesItsWeight, PressedIntoGround,
                         testing::Values(1, 10, 100, 1000, 10000));

// --- A heavy box on a light one stands ---------------------------------------------------------

class HeavyOnLight : public testing::TestWithParam<std::int32_t> {};

TEST_P(HeavyOnLight, Stands) {
  const Fixed ratio = Fixed::from_int(GetParam());
  const WorldDef def;
  const Fixed half = 0.5_fx;
  BodyId light;
  BodyId heavy;
  run(
      def,
      [&](World& w) {
        add_ground(w);
        light = add(w, box({{}, half, {}}, half, 1_fx));
        heavy = add(w, box({{}, 3_fx * half, {}}, half, ratio));
      },
      300, {},
      [&](World& w, int f) {
        const BodyState l = state(w, light);
        const BodyState h = state(w, heavy);
        // Standing: each box rests on what is under it, overlapping by no more than a tenth of
        // an edge (the contact tolerances are millimetres), and nothing slides off.
        const Fixed tolerance = 0.1_fx;
        EXPECT_GT(l.position.y, half - tolerance) << "frame " << f << ": light box in the ground";
        EXPECT_GT(h.position.y - l.position.y, 2_fx * half - tolerance)
            << "frame " << f << ": heavy box sinks into the light one";
        EXPECT_LT(abs(h.position.x - l.position.x), tolerance) << "frame " << f;
        EXPECT_LT(abs(h.position.z - l.position.z), tolerance) << "frame " << f;
      });
}

INSTANTIATE_TEST_SUITE_P(MassRatio, HeavyOnLight, testing::Values(10, 100, 1000, 10000, 10000000));

// --- Bodies spawned inside each other separate calmly -----------------------------------------

TEST(CoincidentSpawn, NeverGainsMoreEnergyThanThePushOutCapAllows) {
  const WorldDef def = no_gravity();
  const int count = 500;
  const double edge = 0.5;
  std::vector<BodyId> ids;
  // Every body moving at the push-out cap: the most the separation may give.
  const double push = def.contact_push_max.to_double();
  const double cap = count * 0.5 * 1.0 * push * push;
  double most = 0;
  run(
      def,
      [&](World& w) {
        ids.clear();
        for (int i = 0; i < count; ++i)
          ids.push_back(add(w, box({}, 0.25_fx, 1_fx)));
      },
      6, {},
      [&](World& w, int f) {
        double energy = 0;
        for (const BodyId id : ids)
          energy += kinetic_energy(w, id, edge);
        most = std::max(most, energy);
        EXPECT_LE(energy, cap) << "frame " << f;
        // The cost is bounded: each body in at most pair_budget pairs, not every body with
        // every other (124 750 pairs).
        EXPECT_LE(w.contacts().size(), std::size_t{count} * pair_budget / 2) << "frame " << f;
      });
  RecordProperty("most_energy_j", std::to_string(most));
}

// A large body carrying more small ones than the pair budget: the budget counts only bodies of
// comparable size, so none of the 100 crates on a dynamic 20 m deck falls through it.
TEST(PairBudget, ALargeBodyCarriesMoreSmallOnesThanTheBudget) {
  const WorldDef def;
  const Fixed half = 0.25_fx;
  std::vector<BodyId> crates;
  BodyId deck;
  run(
      def,
      [&](World& w) {
        crates.clear();
        add_ground(w);
        BodyDef d;
        d.shape = Shape::box({10_fx, 0.5_fx, 10_fx});
        d.position = {{}, 0.5_fx, {}};
        d.density = 100_fx;
        deck = add(w, d);
        for (int x = 0; x < 10; ++x) {
          for (int z = 0; z < 10; ++z) {
            const Vec3 p{Fixed::from_int(2 * x - 9), 1_fx + half, Fixed::from_int(2 * z - 9)};
            crates.push_back(add(w, box(p, half, 1_fx)));
          }
        }
      },
      60, {},
      [&](World& w, int f) {
        const Fixed top = state(w, deck).position.y + 0.5_fx;
        for (const BodyId id : crates) {
          EXPECT_GT(state(w, id).position.y, top) << "frame " << f << ": crate " << id.value;
        }
      });
}

// --- A scene of millimetres or of kilometres behaves like a scene of metres ------------------

struct StackOf {
  Fixed edge;   // m
  Fixed mass;   // kg, each box
  bool scaled;  // in a world made for the edge (scale_lengths), else the metre defaults
};

class Stack : public testing::TestWithParam<StackOf> {};

// Five boxes stacked on the ground stand: no box more than a tenth of an edge from where it was
// put, sideways or down, as a stack of metre boxes does.
// - 1 mm to 1 m, 10 g each, in a world made for their size (scale_lengths). With the metre
//   defaults the 1 cm and 1 mm stacks fall over: the contact spring sags by more than a box.
// - 10 m to 1 km, a tonne each. Their contact tolerances are already small beside them, so the
//   metre defaults do (and a world made for 10 m). What limits such scenes is the mass range: a
//   1 km cube's moments of inertia, m s^2 / 6, pass 2^31 kg m^2 above about 12.9 t (a real one
//   is written in kilometres and tonnes).
TEST_P(Stack, Stands) {
  const StackOf p = GetParam();
  const WorldDef def = p.scaled ? scale_lengths(WorldDef{}, p.edge) : WorldDef{};
  const Fixed half = p.edge / 2_fx;
  std::vector<BodyId> ids;
  run(
      def,
      [&](World& w) {
        ids.clear();
        add_ground(w);
        for (int i = 0; i < 5; ++i)
          ids.push_back(add(w, box({{}, half + p.edge * Fixed::from_int(i), {}}, half, p.mass)));
      },
      300, {},
      [&](World& w, int f) {
        for (std::size_t i = 0; i < ids.size(); ++i) {
          const BodyState s = state(w, ids[i]);
          const Fixed put = half + p.edge * Fixed::from_int(static_cast<std::int32_t>(i));
          EXPECT_LT(abs(s.position.y - put), p.edge / 10_fx) << "frame " << f << ", box " << i;
          EXPECT_LT(abs(s.position.x), p.edge / 10_fx) << "frame " << f << ", box " << i;
          EXPECT_LT(abs(s.position.z), p.edge / 10_fx) << "frame " << f << ", box " << i;
        }
      });
}

INSTANTIATE_TEST_SUITE_P(
    Sizes, Stack,
    testing::Values(StackOf{1_fx / 1000_fx, 0.01_fx, true}, StackOf{1_fx / 100_fx, 0.01_fx, true},
                    StackOf{1_fx / 10_fx, 0.01_fx, true}, StackOf{1_fx, 0.01_fx, true},
                    StackOf{10_fx, 1000_fx, true}, StackOf{100_fx, 1000_fx, false},
                    StackOf{1000_fx, 1000_fx, false}));

// --- A face-on impact stays symmetric -----------------------------------------------------------

class FaceOnImpact : public testing::TestWithParam<int> {};

TEST_P(FaceOnImpact, LeavesNoSidewaysSpeedOrSpin) {
  const Fixed speed = Fixed::from_int(GetParam());
  const WorldDef def = no_gravity();
  BodyId id;
  run(
      def,
      [&](World& w) {
        BodyDef wall;
        wall.type = BodyType::static_body;
        wall.shape = Shape::box({1_fx, 10_fx, 10_fx});
        wall.position = {Fixed::from_int(60), {}, {}};
        add(w, wall);
        BodyDef b = box({}, 0.5_fx, 1_fx);
        b.linear_velocity = {speed, {}, {}};
        b.ccd = true;
        id = add(w, b);
      },
      90, {},
      [&](World& w, int f) {
        const BodyState s = state(w, id);
        const Vec3 v = s.linear_velocity;
        const Fixed lateral = sqrt(v.y * v.y + v.z * v.z);
        EXPECT_LT(lateral, speed / 100_fx) << "frame " << f;
        // Spin of 1 % of the impact speed at the box's corner (half-diagonal 0.87 m) at most.
        EXPECT_LT(length(s.angular_velocity), speed / 87_fx) << "frame " << f;
        EXPECT_LT(s.position.x, 59_fx) << "frame " << f << ": through the wall";
      });
}

INSTANTIATE_TEST_SUITE_P(Speeds, FaceOnImpact, testing::Values(10, 100, 1500));

}  // namespace
}  // namespace detsim
