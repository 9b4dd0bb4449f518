// The World's spatial queries: ray casts against every shape (hit point, normal and fraction
// derived by hand), misses, degenerate rays, filters, ordering, very long rays, and overlap tests
// for every pair of shapes.
//
// Tolerance: kTol = 2^-20 m (~1e-6 m). A hit on metre-sized shapes goes through a few dozen
// roundings of quantities below ~10 m (rotation entries to ~10 ulp, a square root, a division), an
// error of well under 2^-24 m; any wrong formula errs by millimetres or more. Rays of 10^6 m have
// their own, derived tolerance (LongRaysDoNotOverflowAndStillHit).
#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

#include "support/sim_helpers.hpp"

namespace detsim {

inline void PrintTo(BodyId id, std::ostream* os) {
  *os << "BodyId " << id.value;
}

inline void PrintTo(const RayHit& h, std::ostream* os) {
  *os << "{body " << h.body.value << ", point ";
  PrintTo(h.point, os);
  *os << ", normal ";
  PrintTo(h.normal, os);
  *os << ", fraction ";
  PrintTo(h.fraction, os);
  *os << "}";
}

namespace {

using namespace detsim::literals;

using test::add;
using test::add_ground;
using test::make_world;
using test::near;
using test::near_vec;

constexpr Fixed kTol = Fixed::from_raw(Fixed::one_raw >> 20);
constexpr Fixed kQuarterPi = Fixed::from_raw(Fixed::pi().raw() / 4);  // pi's raw is a multiple of 4
const Fixed kHalfSqrt2 = Fixed::sqrt2() >> 1;
const Fixed kOut = Fixed::from_raw(1 << 16);  // 2^-16 m: "just outside"

/// A hit at `point` with `normal` (each component within `tolerance`) and `fraction`.
testing::AssertionResult hits(const std::optional<RayHit>& hit, Vec3 point, Vec3 normal,
                              Fixed fraction, Fixed tolerance = kTol,
                              Fixed fraction_tolerance = kTol) {
  if (!hit) return testing::AssertionFailure() << "no hit";
  for (const auto& r :
       {near_vec(hit->point, point, tolerance), near_vec(hit->normal, normal, tolerance),
        near(hit->fraction, fraction, fraction_tolerance)}) {
    if (!r)
      return testing::AssertionFailure() << testing::PrintToString(*hit) << ": " << r.message();
  }
  return testing::AssertionSuccess();
}

BodyDef at(Shape shape, Vec3 position, Quat orientation = {}) {
  BodyDef d;
  d.type = shape.type == ShapeType::plane ? BodyType::static_body : BodyType::kinematic;
  d.shape = shape;
  d.position = position;
  d.orientation = orientation;
  return d;
}

/// A world holding just `body`.
World only(const BodyDef& body) {
  World w = make_world();
  add(w, body);
  return w;
}

Quat about_z(Fixed angle) {
  return from_axis_angle(Vec3::unit_z(), angle);
}

// ---- Each shape -------------------------------------------------------------------------------

TEST(SimQuery, RayHitsSphere) {
  const World w = only(at(Shape::sphere(1_fx), {}));
  // From y = 5 down 10 m: the top, y = 1, is 4 m along.
  EXPECT_TRUE(hits(w.raycast_closest({0_fx, 5_fx, 0_fx}, {0_fx, -10_fx, 0_fx}), Vec3::unit_y(),
                   Vec3::unit_y(), 0.4_fx));
  // At height 0.6 the circle x^2 + y^2 = 1 is entered at x = -0.8; the normal is the radius.
  EXPECT_TRUE(hits(w.raycast_closest({-5_fx, 0.6_fx, 0_fx}, {10_fx, 0_fx, 0_fx}),
                   {-0.8_fx, 0.6_fx, 0_fx}, {-0.8_fx, 0.6_fx, 0_fx}, 0.42_fx));
  // Grazing at height 1: the tangent point; 2^-16 m higher, nothing.
  EXPECT_TRUE(hits(w.raycast_closest({-5_fx, 1_fx, 0_fx}, {10_fx, 0_fx, 0_fx}), Vec3::unit_y(),
                   Vec3::unit_y(), 0.5_fx));
  EXPECT_FALSE(w.raycast_closest({-5_fx, 1_fx + kOut, 0_fx}, {10_fx, 0_fx, 0_fx}));
  // Ending exactly on the surface is a hit at fraction 1; ending 1 cm short, pointing away or
  // passing beside, no hit.
  const Vec3 origin{0_fx, 5_fx, 0_fx};
  EXPECT_TRUE(
      hits(w.raycast_closest(origin, {0_fx, -4_fx, 0_fx}), Vec3::unit_y(), Vec3::unit_y(), 1_fx));
  EXPECT_FALSE(w.raycast_closest(origin, {0_fx, -3.99_fx, 0_fx}));
  EXPECT_FALSE(w.raycast_closest(origin, {0_fx, 10_fx, 0_fx}));
  EXPECT_FALSE(w.raycast_closest(origin, {10_fx, 0_fx, 0_fx}));
}

TEST(SimQuery, RayHitsEachFaceOfABox) {
  const Vec3 h{1_fx, 2_fx, 3_fx};
  const Vec3 centre{1_fx, -2_fx, 3_fx};
  const World w = only(at(Shape::box(h), centre));
  for (int axis = 0; axis < 3; ++axis) {
    for (const Fixed s : {1_fx, -1_fx}) {
      // The outward normal `dir`, and a point of that face off its centre: `offset` with its
      // component along `dir` replaced by the half extent.
      const Vec3 dir = (axis == 0   ? Vec3::unit_x()
                        : axis == 1 ? Vec3::unit_y()
                                    : Vec3::unit_z()) *
                       s;
      const Vec3 offset{0.25_fx, -0.25_fx, 0.5_fx};
      const Vec3 face_point = centre + offset + dir * (abs(dot(dir, h)) - dot(dir, offset));
      // From 6 m outside the face, 8 m toward the box: the face is 6 m along.
      EXPECT_TRUE(
          hits(w.raycast_closest(face_point + dir * 6_fx, dir * -8_fx), face_point, dir, 0.75_fx))
          << axis << " " << to_string(s);
    }
  }
}

TEST(SimQuery, RayHitsRotatedBoxAndBoxesAtTheirEdges) {
  // A unit cube turned 45 degrees about z: its local +y face has normal (-1, 1, 0) / sqrt 2 and
  // lies on -x + y = sqrt 2. The ray y = 0.5 along +x meets it at x = 0.5 - sqrt 2 (there the
  // local x, (x + y) / sqrt 2 = 1/sqrt 2 - 1, is inside the face), after crossing the local -x
  // face's plane, x + y = -sqrt 2, further back at x = -0.5 - sqrt 2 (outside that face).
  const World turned = only(at(Shape::box({1_fx, 1_fx, 1_fx}), {}, about_z(kQuarterPi)));
  EXPECT_TRUE(hits(turned.raycast_closest({-5_fx, 0.5_fx, 0_fx}, {10_fx, 0_fx, 0_fx}),
                   {0.5_fx - Fixed::sqrt2(), 0.5_fx, 0_fx}, {-kHalfSqrt2, kHalfSqrt2, 0_fx},
                   (5.5_fx - Fixed::sqrt2()) / 10_fx));

  const World w = only(at(Shape::box({1_fx, 1_fx, 1_fx}), {}));
  // Parallel to the top face and in its plane: the closed box is entered through the -x face;
  // 2^-16 m above, nothing.
  EXPECT_TRUE(hits(w.raycast_closest({-5_fx, 1_fx, 0_fx}, {10_fx, 0_fx, 0_fx}), {-1_fx, 1_fx, 0_fx},
                   -Vec3::unit_x(), 0.4_fx));
  EXPECT_FALSE(w.raycast_closest({-5_fx, 1_fx + kOut, 0_fx}, {10_fx, 0_fx, 0_fx}));
  // Along the diagonal (1, 1, 0) the -x and -y faces are entered at once, at the edge
  // (-1, -1, z): the tie goes to the lower axis, a fixed choice on every machine.
  const auto edge = w.raycast_closest({-5_fx, -5_fx, 0.5_fx}, {10_fx, 10_fx, 0_fx});
  EXPECT_TRUE(hits(edge, {-1_fx, -1_fx, 0.5_fx}, -Vec3::unit_x(), 0.4_fx));
}

TEST(SimQuery, RayHitsCapsuleSideAndCaps) {
  const World w = only(at(Shape::capsule(0.5_fx, 1_fx), {}));  // core y in [-1, 1], radius 0.5
  // The side x = -0.5 at a height within the core; the top of the top cap, y = 1.5, and the
  // bottom of the bottom one.
  EXPECT_TRUE(hits(w.raycast_closest({-5_fx, 0.3_fx, 0_fx}, {10_fx, 0_fx, 0_fx}),
                   {-0.5_fx, 0.3_fx, 0_fx}, -Vec3::unit_x(), 0.45_fx));
  EXPECT_TRUE(hits(w.raycast_closest({0_fx, 5_fx, 0_fx}, {0_fx, -10_fx, 0_fx}),
                   {0_fx, 1.5_fx, 0_fx}, Vec3::unit_y(), 0.35_fx));
  EXPECT_TRUE(hits(w.raycast_closest({0_fx, -5_fx, 0_fx}, {0_fx, 10_fx, 0_fx}),
                   {0_fx, -1.5_fx, 0_fx}, -Vec3::unit_y(), 0.35_fx));
  // The top cap off its axis, above x = 0.3: y = 1 + sqrt(0.25 - 0.09) = 1.4, normal
  // (0.3, 0.4, 0) / 0.5.
  EXPECT_TRUE(hits(w.raycast_closest({0.3_fx, 5_fx, 0_fx}, {0_fx, -10_fx, 0_fx}),
                   {0.3_fx, 1.4_fx, 0_fx}, {0.6_fx, 0.8_fx, 0_fx}, 0.36_fx));
  // Nearly along the axis from just outside the side: x falls by 0.002 over 1.8 m and reaches
  // the side, x = 0.5, half way, at y = 0.
  EXPECT_TRUE(hits(w.raycast_closest({0.501_fx, -0.9_fx, 0_fx}, {-0.002_fx, 1.8_fx, 0_fx}),
                   {0.5_fx, 0_fx, 0_fx}, Vec3::unit_x(), 0.5_fx));
  // Up the surface's straight line x = 0.5: first touched where the bottom ball meets it.
  EXPECT_TRUE(hits(w.raycast_closest({0.5_fx, -5_fx, 0_fx}, {0_fx, 10_fx, 0_fx}),
                   {0.5_fx, -1_fx, 0_fx}, Vec3::unit_x(), 0.4_fx));
  // Up the line x = 0.45, exactly and tilted by +-2^-24 rad: the bottom ball is entered at
  // y = -1 - sqrt(0.25 - 0.45^2). The tilt moves the ray under 4 m * 2^-24 = 2.4e-7 m sideways
  // there, and the surface's slope (0.45 / 0.22) makes that under 5e-7 m of height: 2 kTol,
  // and twice that again for the normal (the offset over the radius 0.5).
  const Fixed y = -1_fx - sqrt(0.25_fx - 0.45_fx * 0.45_fx);
  for (const Fixed tilt : {0_fx, Fixed::from_raw(1 << 8), -Fixed::from_raw(1 << 8)}) {
    const auto hit = w.raycast_closest({0.45_fx, -5_fx, 0_fx}, {tilt * 10, 10_fx, 0_fx});
    ASSERT_TRUE(hit.has_value());
    EXPECT_TRUE(near_vec(hit->point, {0.45_fx, y, 0_fx}, kTol * 2));
    EXPECT_TRUE(near_vec(hit->normal, {0.9_fx, (y + 1_fx) * 2, 0_fx}, kTol * 4));
  }
  // Beside the side and past the caps.
  EXPECT_FALSE(w.raycast_closest({-5_fx, 0_fx, 0.51_fx}, {10_fx, 0_fx, 0_fx}));
  EXPECT_FALSE(w.raycast_closest({-5_fx, 1.51_fx, 0_fx}, {10_fx, 0_fx, 0_fx}));
}

TEST(SimQuery, RayHitsRotatedAndDegenerateCapsules) {
  // Turned 90 degrees about z, the core lies along x from -1 to 1. Down onto its side at x = 0.7;
  // beyond the end x = 1, onto the end ball: y = sqrt(0.25 - 0.2^2), normal (0.2, y, 0) / 0.5.
  const World w = only(at(Shape::capsule(0.5_fx, 1_fx), {}, about_z(Fixed::half_pi())));
  EXPECT_TRUE(hits(w.raycast_closest({0.7_fx, 5_fx, 0_fx}, {0_fx, -10_fx, 0_fx}),
                   {0.7_fx, 0.5_fx, 0_fx}, Vec3::unit_y(), 0.45_fx));
  const Fixed y = sqrt(0.21_fx);
  EXPECT_TRUE(hits(w.raycast_closest({1.2_fx, 5_fx, 0_fx}, {0_fx, -10_fx, 0_fx}), {1.2_fx, y, 0_fx},
                   {0.4_fx, y * 2, 0_fx}, (5_fx - y) / 10_fx));
  // Half height 0 is a sphere: the circle of radius 0.5 at height 0.3 is entered at x = -0.4.
  const World ball = only(at(Shape::capsule(0.5_fx, 0_fx), {}));
  EXPECT_TRUE(hits(ball.raycast_closest({-5_fx, 0.3_fx, 0_fx}, {10_fx, 0_fx, 0_fx}),
                   {-0.4_fx, 0.3_fx, 0_fx}, {-0.8_fx, 0.6_fx, 0_fx}, 0.46_fx));
  EXPECT_TRUE(hits(ball.raycast_closest({0_fx, 5_fx, 0_fx}, {0_fx, -10_fx, 0_fx}),
                   {0_fx, 0.5_fx, 0_fx}, Vec3::unit_y(), 0.45_fx));
}

TEST(SimQuery, RayHitsPlanes) {
  World w = make_world();
  add_ground(w);
  EXPECT_TRUE(hits(w.raycast_closest({1_fx, 3_fx, 2_fx}, {0_fx, -6_fx, 0_fx}), {1_fx, 0_fx, 2_fx},
                   Vec3::unit_y(), 0.5_fx));
  // From height 2, falling 1 m per metre: y = 0 at x = 2, half way.
  EXPECT_TRUE(hits(w.raycast_closest({0_fx, 2_fx, 0_fx}, {4_fx, -4_fx, 0_fx}), {2_fx, 0_fx, 0_fx},
                   Vec3::unit_y(), 0.5_fx));
  // Up, parallel, or stopping short: nothing.
  EXPECT_FALSE(w.raycast_closest({0_fx, 1_fx, 0_fx}, {0_fx, 5_fx, 0_fx}));
  EXPECT_FALSE(w.raycast_closest({0_fx, 1_fx, 0_fx}, {1000_fx, 0_fx, 0_fx}));
  EXPECT_FALSE(w.raycast_closest({0_fx, 1_fx, 0_fx}, {0_fx, -0.99_fx, 0_fx}));
  // Turned 45 degrees about z, the plane is y = x with normal (-1, 1, 0) / sqrt 2; (3, 1, 0) is
  // below it, inside the half-space.
  World tilted = make_world();
  add_ground(tilted, about_z(kQuarterPi));
  EXPECT_TRUE(hits(tilted.raycast_closest({0_fx, 4_fx, 0_fx}, {0_fx, -8_fx, 0_fx}), {},
                   {-kHalfSqrt2, kHalfSqrt2, 0_fx}, 0.5_fx));
  const auto inside = tilted.raycast_closest({3_fx, 1_fx, 0_fx}, {0_fx, 8_fx, 0_fx});
  ASSERT_TRUE(inside.has_value());
  EXPECT_EQ(inside->fraction, 0_fx);
}

// ---- Degenerate rays --------------------------------------------------------------------------

struct ShapeCase {
  const char* name;
  BodyDef def;
  Vec3 inside;  ///< strictly
  Vec3 on_surface;
  Vec3 away;  ///< the outward unit normal at on_surface
};

std::vector<ShapeCase> shape_cases() {
  return {
      {"sphere",
       at(Shape::sphere(1_fx), {1_fx, 2_fx, 3_fx}),
       {1.5_fx, 2_fx, 3_fx},
       {1_fx, 3_fx, 3_fx},
       Vec3::unit_y()},
      // on_surface is a corner; `away` one of its faces' normals.
      {"box",
       at(Shape::box({1_fx, 2_fx, 3_fx}), {}),
       {0.9_fx, -1.9_fx, 2.9_fx},
       {1_fx, -2_fx, 3_fx},
       Vec3::unit_z()},
      {"capsule",
       at(Shape::capsule(0.5_fx, 1_fx), {}),
       {0_fx, 1.4_fx, 0_fx},
       {0_fx, -1.5_fx, 0_fx},
       -Vec3::unit_y()},
      {"plane", at(Shape::plane(), {}), {5_fx, -0.1_fx, 5_fx}, {5_fx, 0_fx, 5_fx}, Vec3::unit_y()},
  };
}

TEST(SimQuery, RayStartingInsideOrOnTheSurfaceHitsAtFractionZeroWithNoNormal) {
  for (const ShapeCase& c : shape_cases()) {
    World w = make_world();
    const BodyId id = add(w, c.def);
    for (const Vec3 origin : {c.inside, c.on_surface}) {
      for (const Vec3 translation : {Vec3{3_fx, 0_fx, 0_fx}, c.away * -3_fx, c.away * 3_fx}) {
        const auto hit = w.raycast_closest(origin, translation);
        ASSERT_TRUE(hit.has_value()) << c.name;
        EXPECT_EQ(*hit, (RayHit{id, origin, Vec3::zero(), 0_fx})) << c.name;
      }
    }
  }
}

TEST(SimQuery, RayFromJustOutsideHitsWhenTowardAndMissesWhenAway) {
  // The origins are 2^-16 m outside, well within each bounding sphere: the exact tests decide.
  for (const ShapeCase& c : shape_cases()) {
    const World w = only(c.def);
    const Vec3 outside = c.on_surface + c.away * kOut;
    EXPECT_FALSE(w.raycast_closest(outside, c.away * 3_fx)) << c.name;
    EXPECT_FALSE(w.raycast_closest(outside, c.away * 3_fx + Vec3{0.5_fx, 0_fx, 0_fx})) << c.name;
    const auto hit = w.raycast_closest(outside, c.away * -3_fx);
    EXPECT_TRUE(hits(hit, c.on_surface, c.away, kOut / 3_fx)) << c.name;
    EXPECT_TRUE(hit && hit->fraction > 0_fx) << c.name;
  }
}

TEST(SimQuery, ZeroLengthRayHitsExactlyTheShapesContainingItsOrigin) {
  for (const ShapeCase& c : shape_cases()) {
    World w = make_world();
    const BodyId id = add(w, c.def);
    for (const Vec3 origin : {c.inside, c.on_surface}) {
      EXPECT_EQ(w.raycast_all(origin, {}), (std::vector<RayHit>{{id, origin, Vec3::zero(), 0_fx}}))
          << c.name;
    }
    EXPECT_TRUE(w.raycast_all(c.on_surface + c.away * kOut, {}).empty()) << c.name;
  }
}

TEST(SimQuery, OneUlpRayReachesTheSurfaceOneUlpAway) {
  const World w = only(at(Shape::sphere(1_fx), {}));
  const Vec3 origin{0_fx, 1_fx + Fixed::epsilon(), 0_fx};
  EXPECT_EQ(w.raycast_closest(origin, {0_fx, -Fixed::epsilon(), 0_fx}),
            (RayHit{BodyId{1}, Vec3::unit_y(), Vec3::unit_y(), 1_fx}));
  EXPECT_FALSE(w.raycast_closest(origin, {0_fx, Fixed::epsilon(), 0_fx}));
}

/// Checks what must hold for any ray: fractions in [0, 1], sorted by (fraction, ID) with no body
/// twice, the closest first, unit normals against the ray (except from inside).
void expect_consistent(const World& w, Vec3 origin, Vec3 translation) {
  const auto all = w.raycast_all(origin, translation);
  const auto closest = w.raycast_closest(origin, translation);
  ASSERT_EQ(closest.has_value(), !all.empty());
  EXPECT_TRUE(all.empty() || closest == all.front());
  for (std::size_t n = 0; n < all.size(); ++n) {
    const RayHit& h = all[n];
    EXPECT_TRUE(h.fraction >= 0_fx && h.fraction <= 1_fx);
    if (n > 0) {
      const RayHit& g = all[n - 1];
      EXPECT_TRUE(g.fraction < h.fraction || (g.fraction == h.fraction && g.body < h.body));
    }
    // Normals are checked on rays of human scale: beyond, the direction's error (2^-32 per
    // metre) may tilt the normal of a grazing hit past perpendicular.
    if (h.fraction > 0_fx && length(translation) < 1000000_fx) {
      EXPECT_TRUE(near(length(h.normal), 1_fx, kTol));
      EXPECT_LE(dot(h.normal, translation), 0_fx);
    }
  }
}

TEST(SimQuery, ExtremeRaysGiveDefinedOrderedResults) {
  // Every combination of extreme origins and translations, up to the saturated Fixed range: no
  // undefined behaviour (UBSan runs this suite) and consistent results.
  World w = make_world();
  add_ground(w);
  add(w, at(Shape::sphere(1_fx), {}));
  add(w, at(Shape::box({1_fx, 2_fx, 3_fx}), {5_fx, 1_fx, 0_fx}, about_z(0.3_fx)));
  add(w, at(Shape::capsule(0.5_fx, 0_fx), {-5_fx, 1_fx, 0_fx}));
  // The largest shape. At a density its volume (10^13 m^3) would saturate and be refused
  // (docs/SIM.md, "What is refused"): a mass instead.
  BodyDef largest = at(Shape::capsule(10000_fx, 10000_fx), {0_fx, 0_fx, 100000_fx});
  largest.mass = 1_fx;
  add(w, largest);
  const std::vector<Fixed> values = {0_fx,        Fixed::epsilon(), -Fixed::epsilon(), -1_fx,
                                     3_fx,        1000000_fx,       -1000000_fx,       Fixed::max(),
                                     Fixed::min()};
  for (const Fixed a : values) {
    for (const Fixed b : values) {
      for (const Fixed c : {0_fx, 2_fx, -1000000_fx}) {
        expect_consistent(w, {a, c, b}, {b, a, c});
        (void)w.overlap(Shape::box({1_fx, 1_fx, 1_fx}), {a, c, b}, {});
      }
    }
  }
}

// ---- Filters and order ------------------------------------------------------------------------

TEST(SimQuery, FilterSelectsByLayerMaskAndSensor) {
  World w = make_world();
  // Four spheres along the ray, each with its own filtering.
  std::vector<BodyDef> defs(4, at(Shape::sphere(0.5_fx), {}));
  for (std::size_t i = 0; i < 4; ++i)
    defs[i].position.x = Fixed::from_int(2) * static_cast<std::int32_t>(i + 1);
  defs[0].layer = 1;
  defs[1].layer = 2;
  defs[2].layer = 4;
  defs[2].mask = 2;  // only seen by queries whose layer has bit 1
  defs[3].sensor = true;
  const BodyId a = add(w, defs[0]);
  const BodyId b = add(w, defs[1]);
  const BodyId c = add(w, defs[2]);
  const BodyId d = add(w, defs[3]);
  const auto ids = [&w](const QueryFilter& f) {
    std::vector<BodyId> out;
    for (const RayHit& h : w.raycast_all({}, {10_fx, 0_fx, 0_fx}, f))
      out.push_back(h.body);
    return out;
  };
  using Ids = std::vector<BodyId>;
  EXPECT_EQ(ids({}), (Ids{a, b, c}));
  EXPECT_EQ(ids({0xFFFFFFFFU, 0xFFFFFFFFU, true}), (Ids{a, b, c, d}));
  EXPECT_EQ(ids({0xFFFFFFFFU, 2U, false}), (Ids{b}));
  EXPECT_EQ(ids({0xFFFFFFFFU, 6U, false}), (Ids{b, c}));
  EXPECT_EQ(ids({1U, 0xFFFFFFFFU, false}), (Ids{a, b}));  // c's mask refuses
  EXPECT_EQ(ids({2U, 0xFFFFFFFFU, true}), (Ids{a, b, c, d}));
  EXPECT_TRUE(ids({0U, 0xFFFFFFFFU, true}).empty());
  // The closest hit follows the filter: with a excluded, b is first.
  const auto first = w.raycast_closest({}, {10_fx, 0_fx, 0_fx}, {0xFFFFFFFFU, 6U, false});
  EXPECT_TRUE(first && first->body == b);
  // So does overlap: a sphere covering all four.
  EXPECT_EQ(w.overlap(Shape::sphere(10_fx), {}, {}), (Ids{a, b, c}));
  EXPECT_EQ(w.overlap(Shape::sphere(10_fx), {}, {}, {1U, 0xFFFFFFFFU, true}), (Ids{a, b, d}));
}

TEST(SimQuery, RaycastAllSortsByFractionThenIdOneHitPerBody) {
  World w = make_world();
  // Created far to near: IDs and distances disagree.
  const BodyId far = add(w, at(Shape::sphere(1_fx), {30_fx, 0_fx, 0_fx}));
  const BodyId nearest = add(w, at(Shape::sphere(1_fx), {10_fx, 0_fx, 0_fx}));
  const BodyId mid = add(w, at(Shape::box({1_fx, 1_fx, 1_fx}), {20_fx, 0_fx, 0_fx}));
  // Mirror images across the ray's plane z = 0: the same entry fraction, bit for bit.
  const BodyId tie_hi = add(w, at(Shape::sphere(1_fx), {40_fx, 0_fx, 0.5_fx}));
  const BodyId tie_lo = add(w, at(Shape::sphere(1_fx), {40_fx, 0_fx, -0.5_fx}));
  const auto all = w.raycast_all({}, {50_fx, 0_fx, 0_fx});
  ASSERT_EQ(all.size(), 5U);
  EXPECT_EQ(all[0].body, nearest);
  EXPECT_EQ(all[1].body, mid);
  EXPECT_EQ(all[2].body, far);
  EXPECT_EQ(all[3].body, tie_hi);  // the lower ID of the tie
  EXPECT_EQ(all[4].body, tie_lo);
  EXPECT_EQ(all[3].fraction, all[4].fraction);
  // Each body's first entry: the near side.
  EXPECT_TRUE(hits(all[0], {9_fx, 0_fx, 0_fx}, -Vec3::unit_x(), 9_fx / 50_fx));
  EXPECT_TRUE(hits(all[1], {19_fx, 0_fx, 0_fx}, -Vec3::unit_x(), 19_fx / 50_fx));
  EXPECT_TRUE(hits(all[2], {29_fx, 0_fx, 0_fx}, -Vec3::unit_x(), 29_fx / 50_fx));
  EXPECT_EQ(w.raycast_closest({}, {50_fx, 0_fx, 0_fx}), all[0]);
  // From just before the tie: the closest of two equal hits is the lower ID.
  const auto tie = w.raycast_closest({35_fx, 0_fx, 0_fx}, {10_fx, 0_fx, 0_fx});
  EXPECT_TRUE(tie && tie->body == tie_hi);
}

TEST(SimQuery, ClosestIsAlwaysTheFirstOfAll) {
  World w = make_world();
  add_ground(w);
  // A lattice of every finite shape, rotated, some overlapping their neighbours.
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) {
      const Vec3 p{Fixed::from_int(2 * i - 3), 1.2_fx + Fixed::from_int(j) * 0.9_fx,
                   Fixed::from_int(i * j % 3 - 1)};
      const Quat q =
          normalize(Quat{1_fx, Fixed::from_int(i) * 0.3_fx, 0.2_fx, Fixed::from_int(j) * -0.25_fx});
      const int kind = (i + j) % 3;
      add(w, at(kind == 0   ? Shape::sphere(0.6_fx)
                : kind == 1 ? Shape::box({0.5_fx, 0.4_fx, 0.7_fx})
                            : Shape::capsule(0.35_fx, 0.5_fx),
                p, q));
    }
  }
  std::size_t hit_count = 0;
  for (int k = 0; k < 64; ++k) {
    // Rays from a ring around the lattice, through points spread in it.
    const SinCos sc = sincos(Fixed::from_int(k) * (Fixed::two_pi() / 64_fx));
    const Vec3 origin{sc.cos * 12_fx, Fixed::from_int(2 + k % 5), sc.sin * 12_fx};
    const Vec3 target{Fixed::from_int(k % 7 - 3), Fixed::from_int(k % 4), Fixed::from_int(k % 3)};
    expect_consistent(w, origin, (target - origin) * 2_fx);
    hit_count += w.raycast_all(origin, (target - origin) * 2_fx).size();
  }
  EXPECT_GT(hit_count, 64U);  // the scene is really hit, more than once per ray on average
}

// ---- Long rays --------------------------------------------------------------------------------

TEST(SimQuery, LongRaysDoNotOverflowAndStillHit) {
  // A translation of (1e6, 1e6, 0): its squared length, 2e12, is far outside the Fixed range.
  // The direction is known to ~2^-32 per component, so after 1e6 m the ray's position is known to
  // ~2^-12 m = 2.4e-4 m: 1e-3 m is four times that; fractions to 1e-3 m / |translation|.
  const Fixed tol = 0.001_fx;
  const Vec3 translation{1000000_fx, 1000000_fx, 0_fx};
  const Fixed len = 1000000_fx * Fixed::sqrt2();
  const Fixed fraction_tol = tol / len + Fixed::epsilon();
  // Shapes whose surface the diagonal meets 1 m before their centre, normal against the ray: a
  // sphere, a capsule lying along z (a circle in the ray's plane) and a box turned 45 degrees
  // about z (its -x face square to the ray). 0.7e6 sqrt 2 - 1 metres along 1e6 sqrt 2.
  const Vec3 back{-kHalfSqrt2, -kHalfSqrt2, 0_fx};
  for (const BodyDef& def :
       {at(Shape::sphere(1_fx), {}),
        at(Shape::capsule(1_fx, 3_fx), {}, from_axis_angle(Vec3::unit_x(), Fixed::half_pi())),
        at(Shape::box({1_fx, 2_fx, 2_fx}), {}, about_z(kQuarterPi))}) {
    const World w = only(def);
    EXPECT_TRUE(hits(w.raycast_closest({-700000_fx, -700000_fx, 0_fx}, translation), back, back,
                     0.7_fx - 1_fx / len, tol, fraction_tol))
        << static_cast<int>(def.shape.type);
  }
  // Far from the origin: a ball of radius 0.5 centred 0.49 m from the line is hit (entered
  // sqrt(0.5^2 - 0.49^2) before 0.6e6 sqrt 2), one 0.51 m from it is missed.
  World w = make_world();
  const Vec3 across{kHalfSqrt2, -kHalfSqrt2, 0_fx};  // unit, perpendicular to the ray
  const BodyId ball =
      add(w, at(Shape::sphere(0.5_fx), Vec3{600000_fx, 600000_fx, 0_fx} + across * 0.49_fx));
  add(w, at(Shape::sphere(0.5_fx), Vec3{500000_fx, 500000_fx, 0_fx} + across * 0.51_fx));
  const auto all = w.raycast_all({}, translation);
  ASSERT_EQ(all.size(), 1U);
  EXPECT_EQ(all[0].body, ball);
  const Fixed entry = 600000_fx * Fixed::sqrt2() - sqrt(0.25_fx - 0.49_fx * 0.49_fx);
  EXPECT_TRUE(near(all[0].fraction, entry / len, fraction_tol));
  // A plane met half way down a long slant; a long ray up that meets nothing.
  World g = make_world();
  add_ground(g);
  EXPECT_TRUE(
      hits(g.raycast_closest({-500000_fx, 500000_fx, 3_fx}, {1000000_fx, -1000000_fx, 0_fx}),
           {0_fx, 0_fx, 3_fx}, Vec3::unit_y(), 0.5_fx, tol, fraction_tol));
  EXPECT_FALSE(g.raycast_closest({0_fx, 1_fx, 0_fx}, {1000000_fx, 1000000_fx, -1000000_fx}));
}

// ---- Overlap ----------------------------------------------------------------------------------

/// Half the shape's extent along y when upright (the plane: its surface, 0 above its position).
Fixed top_of(const Shape& s) {
  switch (s.type) {
    case ShapeType::sphere:
      return s.radius;
    case ShapeType::box:
      return s.half_extents.y;
    case ShapeType::capsule:
      return s.half_height + s.radius;
    case ShapeType::cylinder:
      return s.half_height;
    case ShapeType::plane:
    default:  // the primitives of this test only
      break;
  }
  return 0_fx;
}

TEST(SimQuery, OverlapOfEveryShapePairTouchingCounts) {
  const std::vector<Shape> bodies = {Shape::sphere(1_fx), Shape::box({1_fx, 0.5_fx, 2_fx}),
                                     Shape::capsule(0.5_fx, 1_fx), Shape::plane()};
  const std::vector<Shape> queries = {Shape::sphere(0.5_fx), Shape::box({0.5_fx, 0.25_fx, 0.75_fx}),
                                      Shape::capsule(0.3_fx, 0.4_fx)};
  for (const Shape& b : bodies) {
    for (const Shape& q : queries) {
      World w = make_world();
      const BodyId id = add(w, at(b, {}));
      // The query stacked on the body: surfaces meet at height top_of(b), so the query's centre
      // touches at top_of(b) + top_of(q); offset it by -1 mm (overlapping), 0 (touching), +1 mm.
      const Fixed touch = top_of(b) + top_of(q);
      const auto found = [&](Fixed dy, Fixed dx) {
        return w.overlap(q, {dx, touch + dy, 0_fx}, {}) == std::vector<BodyId>{id};
      };
      const std::string label =
          std::to_string(static_cast<int>(b.type)) + "/" + std::to_string(static_cast<int>(q.type));
      EXPECT_TRUE(found(-0.001_fx, 0_fx)) << label;
      EXPECT_TRUE(found(0_fx, 0_fx)) << label;
      EXPECT_FALSE(found(0.001_fx, 0_fx)) << label;
      // 0.2 m sideways (no shared axis of symmetry): round tops fall away from the touching
      // point, so the query goes 5 cm deeper, which still overlaps every pair here (the closest
      // case, two balls, is sqrt(0.2^2 + (R - 0.05)^2) < R for R >= 0.45).
      EXPECT_TRUE(found(-0.05_fx, 0.2_fx)) << label;
      EXPECT_FALSE(found(0.001_fx, 0.2_fx)) << label;
      // Centres together (the finite shapes), and far away.
      EXPECT_TRUE(b.type == ShapeType::plane || found(-touch, 0_fx)) << label;
      EXPECT_FALSE(found(100_fx, 0_fx)) << label;
    }
  }
}

TEST(SimQuery, OverlapWithARotatedQueryAndIdsAscending) {
  World w = make_world();
  const BodyId g = add_ground(w);
  // A 2 x 0.2 x 0.2 box turned 45 degrees about z reaches (1 + 0.1) / sqrt 2 below its centre.
  const Shape bar = Shape::box({1_fx, 0.1_fx, 0.1_fx});
  const Fixed reach = 1.1_fx * kHalfSqrt2;
  const Quat q = about_z(kQuarterPi);
  EXPECT_EQ(w.overlap(bar, {0_fx, reach - 0.001_fx, 0_fx}, q), std::vector<BodyId>{g});
  EXPECT_TRUE(w.overlap(bar, {0_fx, reach + 0.001_fx, 0_fx}, q).empty());
  // Spheres on a circle of radius 2 around (0, 10, 0), created in an order unrelated to place.
  std::vector<BodyId> ring;
  for (const int k : {3, 0, 5, 1, 4, 2}) {
    const SinCos sc = sincos(Fixed::from_int(k));
    ring.push_back(add(w, at(Shape::sphere(0.5_fx), {sc.cos * 2_fx, 10_fx + sc.sin * 2_fx, 0_fx})));
  }
  add(w, at(Shape::sphere(0.5_fx), {0_fx, 10_fx, 5_fx}));  // out of reach
  EXPECT_EQ(w.overlap(Shape::sphere(1.6_fx), {0_fx, 10_fx, 0_fx}, {}), ring);
  EXPECT_EQ(w.overlap(Shape::capsule(1.6_fx, 0.1_fx), {0_fx, 10_fx, 0_fx}, {}), ring);
}

TEST(SimQuery, InvalidQueryShapeOrOrientationOverlapsNothing) {
  World w = make_world();
  add_ground(w);
  add(w, at(Shape::sphere(1_fx), {}));
  ASSERT_EQ(w.overlap(Shape::sphere(1_fx), {}, {}).size(), 2U);
  EXPECT_TRUE(w.overlap(Shape::plane(), {}, {}).empty());
  EXPECT_TRUE(w.overlap(Shape::sphere(0_fx), {}, {}).empty());
  EXPECT_TRUE(w.overlap(Shape::box({1_fx, -1_fx, 1_fx}), {}, {}).empty());
  EXPECT_TRUE(w.overlap(Shape::capsule(1_fx, -0.5_fx), {}, {}).empty());
  EXPECT_TRUE(w.overlap(Shape::sphere(20000_fx), {}, {}).empty());  // beyond the size limit
  EXPECT_TRUE(w.overlap(Shape::sphere(1_fx), {}, Quat{2_fx, 0_fx, 0_fx, 0_fx}).empty());
  EXPECT_TRUE(w.overlap(Shape::sphere(1_fx), {}, Quat{0_fx, 0_fx, 0_fx, 0_fx}).empty());
}

// ---- The queries and the state ----------------------------------------------------------------

TEST(SimQuery, QueriesChangeNothing) {
  World w = make_world();
  add_ground(w);
  add(w, at(Shape::box({0.5_fx, 0.5_fx, 0.5_fx}), {0_fx, 0.5_fx, 0_fx}));
  BodyDef ball;
  ball.shape = Shape::sphere(0.5_fx);
  ball.position = {0_fx, 3_fx, 0_fx};
  add(w, ball);
  for (int i = 0; i < 10; ++i)
    w.step();
  const StateHashes before = w.hashes();
  const std::vector<std::uint8_t> bytes = w.save();
  (void)w.raycast_closest({0_fx, 10_fx, 0_fx}, {0_fx, -20_fx, 0_fx});
  (void)w.raycast_all({0_fx, 10_fx, 0_fx}, {0_fx, -20_fx, 0_fx}, {0xFFFFFFFFU, 0xFFFFFFFFU, true});
  (void)w.overlap(Shape::sphere(5_fx), {}, {});
  EXPECT_EQ(w.hashes(), before);
  EXPECT_EQ(w.save(), bytes);
  // And the next step is the one it would have been.
  World twin = w;
  ASSERT_TRUE(twin.restore(bytes).ok());
  w.step();
  twin.step();
  EXPECT_EQ(w.hashes(), twin.hashes());
}

TEST(SimQuery, QueriesSeeTheCurrentPosesNotTheLastStep) {
  WorldDef def;
  def.gravity = {};
  World w = make_world(def);
  const BodyId id = add(w, BodyDef{});  // a dynamic ball of radius 0.5 at the origin
  w.step();
  const std::vector<std::uint8_t> at_origin = w.save();
  const auto first_hit = [&w](Vec3 origin) {
    const auto hit = w.raycast_closest(origin, {0_fx, -10_fx, 0_fx});
    return hit ? hit->body : BodyId{};
  };
  // Teleported without a step: the queries must follow.
  ASSERT_TRUE(w.set_transform(id, {10_fx, 0_fx, 0_fx}, {}).ok());
  EXPECT_EQ(first_hit({0_fx, 5_fx, 0_fx}), BodyId{});
  EXPECT_EQ(first_hit({10_fx, 5_fx, 0_fx}), id);
  EXPECT_TRUE(w.overlap(Shape::sphere(0.4_fx), {}, {}).empty());
  EXPECT_EQ(w.overlap(Shape::sphere(0.4_fx), {10_fx, 0_fx, 0_fx}, {}), std::vector<BodyId>{id});
  // A body created since the last step is seen too.
  const BodyId fresh = add(w, at(Shape::box({1_fx, 1_fx, 1_fx}), {-10_fx, 0_fx, 0_fx}));
  EXPECT_EQ(first_hit({-10_fx, 5_fx, 0_fx}), fresh);
  // Restored: back at the origin, and the new box is gone.
  ASSERT_TRUE(w.restore(at_origin).ok());
  EXPECT_EQ(first_hit({0_fx, 5_fx, 0_fx}), id);
  EXPECT_EQ(first_hit({-10_fx, 5_fx, 0_fx}), BodyId{});
}

}  // namespace
}  // namespace detsim
