// Shared by sim_collide_convex_test.cpp: the hand-built hulls, tolerant manifold comparisons,
// mirroring, random poses and a sampled cylinder-box distance.
#pragma once

#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "sim/src/geometry/convex.hpp"
#include "sim/src/geometry/convex_internal.hpp"
#include "support/collide_helpers.hpp"
#include "support/hull_by_hand.hpp"

namespace detsim::collide_test {

using sim_detail::collide_convex;
using sim_detail::ConvexView;
using sim_detail::Hull;

inline const Fixed kFine =
    Fixed::from_raw(Fixed::one_raw >> 20);  // 2^-20: "the same" across algorithms
inline const Fixed kPhi = 1.6180339887_fx;

inline std::uint16_t hull_vertex(unsigned i) {
  return sim_detail::convex::convex_feature(static_cast<unsigned>(nf::Kind::vertex), i);
}

inline unsigned index_of_vertex(const Hull& h, Vec3 p) {
  for (unsigned i = 0; i < h.vertices.size(); ++i)
    if (h.vertices[i] == p) return i;
  return 0xFFFF;
}

struct Shapes {
  const Hull cube = box_hull({0.5_fx, 0.5_fx, 0.5_fx});
  const Hull ground = box_hull({2_fx, 0.5_fx, 2_fx});
  const Hull wide = box_hull({0.6_fx, 0.5_fx, 0.6_fx});
  // Apex down at local y = -0.5, base triangle at y = +0.5.
  const Hull tetra = hull_by_hand({v3(0_fx, -0.5_fx, 0_fx), v3(0.5_fx, 0.5_fx, 0_fx),
                                   v3(-0.5_fx, 0.5_fx, 0.5_fx), v3(-0.5_fx, 0.5_fx, -0.5_fx)});
  // A unit wedge: bottom y = -0.5, back face z = -0.5, slope from the back's top to the front.
  const Hull wedge = hull_by_hand({v3(-0.5_fx, -0.5_fx, -0.5_fx), v3(0.5_fx, -0.5_fx, -0.5_fx),
                                   v3(-0.5_fx, -0.5_fx, 0.5_fx), v3(0.5_fx, -0.5_fx, 0.5_fx),
                                   v3(-0.5_fx, 0.5_fx, -0.5_fx), v3(0.5_fx, 0.5_fx, -0.5_fx)});
  // A 12-point rock: the icosahedron (0, +-1, +-phi) and its cyclic permutations, scaled by 0.3.
  const Hull rock = [] {
    std::vector<Vec3> p;
    for (const Fixed s : {-0.3_fx, 0.3_fx}) {
      for (const Fixed t : {-0.3_fx, 0.3_fx}) {
        const Fixed tp = t * kPhi;
        p.push_back(v3(0_fx, s, tp));
        p.push_back(v3(s, tp, 0_fx));
        p.push_back(v3(tp, 0_fx, s));
      }
    }
    return hull_by_hand(p);
  }();
};

inline const Shapes& shapes() {
  static const Shapes s;
  return s;
}

// Same normal, same separations and the same point set within 2^-20.
inline void expect_same_contacts(const Manifold& got, const Manifold& want) {
  ASSERT_EQ(got.count, want.count);
  if (want.count == 0) return;
  EXPECT_TRUE(near(got.normal, want.normal, kFine));
  for (std::size_t i = 0; i < want.count; ++i) {
    const ContactPoint* p = find_point(got, want.points[i].point, kFine);
    ASSERT_NE(p, nullptr) << "missing point " << i;
    EXPECT_TRUE(near(p->separation, want.points[i].separation, kFine));
  }
}

// collide_convex(b, a) mirrors collide_convex(a, b).
inline void expect_convex_mirrored(const ConvexView& a, const Pose& pa, const ConvexView& b,
                                   const Pose& pb) {
  const Manifold ab = collide_convex(a, pa, b, pb, kMargin);
  const Manifold ba = collide_convex(b, pb, a, pa, kMargin);
  expect_well_formed(ab, kMargin);
  ASSERT_GT(ab.count, 0U);
  ASSERT_EQ(ab.count, ba.count);
  EXPECT_TRUE(near(ba.normal, -ab.normal));
  for (std::size_t i = 0; i < ab.count; ++i) {
    const ContactPoint* q = find_feature(ba, nf::mirror_feature(ab.points[i].feature));
    ASSERT_NE(q, nullptr) << "feature " << std::hex << ab.points[i].feature << " not mirrored";
    EXPECT_TRUE(near(q->separation, ab.points[i].separation));
    EXPECT_TRUE(near(q->point, ab.points[i].point));
  }
}

inline Manifold mirrored(Manifold m) {
  m.normal = -m.normal;
  for (std::size_t i = 0; i < m.count; ++i)
    m.points[i].feature = nf::mirror_feature(m.points[i].feature);
  return m;
}

inline bool same_contacts(const Manifold& got, const Manifold& want) {
  if (got.count != want.count) return false;
  if (want.count > 0 && !near(got.normal, want.normal, kFine)) return false;
  for (std::size_t i = 0; i < want.count; ++i) {
    const ContactPoint* p = find_point(got, want.points[i].point, kFine);
    if (p == nullptr || !near(p->separation, want.points[i].separation, kFine)) return false;
  }
  return true;
}

/// The distance from a cylinder (radius r, half height h) to a box, sampled on the cylinder's
/// surface (1 degree, 50 steps along the side and across the caps): an upper bound within ~1e-3.
inline Fixed sampled_cylinder_box_distance(Fixed r, Fixed h, const Pose& pc, Vec3 half,
                                           const Pose& pbox) {
  Fixed best = Fixed::max();
  const auto sample = [&](Vec3 local) {
    const Vec3 q = nf::to_local(pbox.rotation, pc.position + pc.rotation * local - pbox.position);
    const nf::BoxPoint on_box = nf::closest_box_point(q, half);
    best = min(best, on_box.clamped > 0 ? length(on_box.point - q) : Fixed::zero());
  };
  for (int deg = 0; deg < 360; ++deg) {
    const SinCos sc = sincos(Fixed::two_pi() * Fixed::from_int(deg) / 360_fx);
    for (int k = 0; k <= 50; ++k) {
      sample(v3(sc.cos * r, h * Fixed::from_int(2 * k - 50) / 50_fx, sc.sin * r));
      const Fixed rk = r * Fixed::from_int(k) / 50_fx;
      sample(v3(sc.cos * rk, h, sc.sin * rk));
      sample(v3(sc.cos * rk, -h, sc.sin * rk));
    }
  }
  return best;
}

/// A fixed-seed 64-bit LCG (Knuth's MMIX constants) giving Fixed values in [-1, 1): the random
/// poses of the property tests, the same on every machine.
struct Lcg {
  std::uint64_t state;
  Fixed operator()() {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return Fixed::from_raw(static_cast<std::int64_t>(state >> 31) - (std::int64_t{1} << 32));
  }
};

/// The least separation of a manifold (Fixed::max() when it has no point).
inline Fixed deepest(const Manifold& m) {
  Fixed d = Fixed::max();
  for (std::size_t i = 0; i < m.count; ++i)
    d = min(d, m.points[i].separation);
  return d;
}

/// Two random poses: a at `origin`, b at an offset whose components lie in [-reach, reach), each
/// turned at random. Draws are made in braced lists, so in the same order on every compiler.
struct PosePair {
  Pose a;
  Pose b;
};
inline PosePair random_pair(Lcg& next, Vec3 origin, Fixed reach) {
  const Quat qa = normalize(Quat{next(), next(), next(), next()});
  const Quat qb = normalize(Quat{next(), next(), next(), next()});
  const Vec3 offset{next(), next(), next()};
  return {at(origin, qa), at(origin + offset * reach, qb)};
}
/// As random_pair, b at `distance` + `jitter` x [-1, 1) from a in a random direction.
inline PosePair random_pair_apart(Lcg& next, Vec3 origin, Fixed distance, Fixed jitter) {
  const Quat qa = normalize(Quat{next(), next(), next(), next()});
  const Quat qb = normalize(Quat{next(), next(), next(), next()});
  const Vec3 direction = normalize(Vec3{next(), next(), next()});
  const Fixed d = distance + next() * jitter;
  return {at(origin, qa), at(origin + direction * d, qb)};
}

/// The largest gap of the two cores' projections over a grid of directions (steps polar x
/// 2 steps azimuthal): minus their penetration when they overlap, as sampled (a lower bound).
inline Fixed largest_sampled_gap(const sim_detail::convex::Body& a,
                                 const sim_detail::convex::Body& b, int steps) {
  Fixed largest = Fixed::min();
  for (int u = 0; u <= steps; ++u) {
    const SinCos st = sincos(Fixed::pi() * Fixed::from_int(u) / Fixed::from_int(steps));
    for (int w = 0; w < 2 * steps; ++w) {
      const SinCos sp = sincos(Fixed::pi() * Fixed::from_int(w) / Fixed::from_int(steps));
      const Vec3 l{st.sin * sp.cos, st.cos, st.sin * sp.sin};
      largest = max(largest, dot(l, sim_detail::convex::support_at(b, -l).point -
                                        sim_detail::convex::support_at(a, l).point));
    }
  }
  return largest;
}

}  // namespace detsim::collide_test
