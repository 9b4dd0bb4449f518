// Continuous collision: the time-of-impact pass after the solver (docs/SIM.md, stage 6).
//
// Speculative contacts stop most fast bodies at the surface they approach, but they are made from
// the closest features at the start of the step, so a body that is fast compared with its own
// size can still pass something the start pose did not see (a thin wall beside its path, a box it
// spins into). This pass sweeps each such body from its pose at the start of the step to its pose
// now, and if the sweep meets another body, moves it back to the first touch. Its velocity is
// kept: the next step's speculative contact then stops it as usual. Swept bodies: those with the
// CCD flag, and any dynamic body whose travel in the step exceeds half its smallest dimension.
// They are swept in ascending ID order against every other solid body the layers allow, static
// ones and moving ones alike, whose swept box overlaps their own: the candidates come from one
// sort and sweep of all swept boxes (ccd_pairs.hpp), the very pairs an all-pairs test finds, so
// the cost follows what a sweep can reach, not the size of the world. A moving one is swept too,
// from its pose at the start of the step to its pose now (after the solver, possibly already
// moved back): the time of impact is the pair's, both at the same fraction of the step, so a
// bullet stops at a crate it hits however fast either moves, and never at a body that moves along
// with it. Ties are broken by ID: lower IDs are swept first, and a later body sweeps against
// where they ended.
//
// The sweep is conservative advancement: with d the distance at time t of the step and b a bound
// on how fast the distance can shrink per unit of t, no touch can happen before t + d / b. Every
// advance is such a safe step, so the pass never skips through a surface; it stops within the
// target gap, or gives up after a fixed number of iterations (a fixed bound: the same work and
// result on every machine) and keeps the last safe time.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <detsim/fixed/math.hpp>
#include <detsim/fixed/quat.hpp>

#include "ccd_pairs.hpp"
#include "shapes.hpp"
#include "world_state.hpp"

namespace detsim::sim_detail {

namespace {

constexpr int max_iterations = 24;

// An upper bound of the rotation angle (radians) between two unit quaternions, taken the shorter
// way. With c = |q1 - q0| (sign of q1 matched, so c <= sqrt 2), the angle is 4 asin(c / 2), and
// since asin(x) / x grows on [0, 1], 4 asin(c / 2) <= c * 4 asin(sqrt 2 / 2) / sqrt 2 = 2.2214 c.
Fixed angle_bound(Quat q0, Quat q1) {
  const Fixed d = q0.w * q1.w + q0.x * q1.x + q0.y * q1.y + q0.z * q1.z;
  if (d < Fixed::zero()) q1 = {-q1.w, -q1.x, -q1.y, -q1.z};
  const Vec3 dv{q1.x - q0.x, q1.y - q0.y, q1.z - q0.z};
  const Fixed chord2 = length_squared(dv) + (q1.w - q0.w) * (q1.w - q0.w);
  // 2.25 c, plus a few ulp for the rounding of c.
  const Fixed chord = sqrt(chord2);
  return min(chord * Fixed::from_raw(Fixed::one_raw * 9 / 4) + Fixed::from_raw(64), Fixed::pi());
}

// Normalised linear interpolation between unit quaternions along the shorter arc.
Quat nlerp(Quat q0, Quat q1, Fixed t) {
  const Fixed d = q0.w * q1.w + q0.x * q1.x + q0.y * q1.y + q0.z * q1.z;
  if (d < Fixed::zero()) q1 = {-q1.w, -q1.x, -q1.y, -q1.z};
  const Fixed u = Fixed::one() - t;
  return normalize(
      Quat{q0.w * u + q1.w * t, q0.x * u + q1.x * t, q0.y * u + q1.y * t, q0.z * u + q1.z * t});
}

struct Sweep {
  Vec3 p0, p1;
  Quat q0, q1;
  bool turns = false;

  [[nodiscard]] Pose at(Fixed t) const {
    const Vec3 p = p0 + (p1 - p0) * t;
    return {p, to_mat3(turns ? nlerp(q0, q1, t) : q1)};
  }
};

// The signed distance between two posed shapes, as the narrowphase measures it (a lower bound of
// the true distance when apart), or `beyond` when they are farther apart than that.
// Over every pair of sub-shapes (a compound's parts, a surface's triangles).
Fixed distance(const WorldState& s, const Shape& a, const Pose& pa, const Shape& b, const Pose& pb,
               Fixed beyond, std::vector<SubManifold>& scratch) {
  collide_all({a, s.geometry(a), pa}, {b, s.geometry(b), pb}, beyond, scratch);
  Fixed d = beyond;
  for (const SubManifold& sub : scratch) {
    for (std::size_t k = 0; k < sub.manifold.count; ++k)
      d = min(d, sub.manifold.points[k].separation);
  }
  return d;
}

bool swept_boxes_overlap(const SweptBox& a, const SweptBox& b) {
  return a.min.x <= b.max.x && b.min.x <= a.max.x && a.min.y <= b.max.y && b.min.y <= a.max.y &&
         a.min.z <= b.max.z && b.min.z <= a.max.z;
}

// The box body i covers from its pose at the start of the step to its pose now, for a body of
// bounding radius r.
SweptBox swept_box(const WorldState& s, std::size_t i, Fixed r) {
  const Vec3 p0 = s.derived[i].start_position;
  const Vec3 p1 = s.bodies[i].position;
  const Vec3 rr{r, r, r};
  const Vec3 lo{min(p0.x, p1.x), min(p0.y, p1.y), min(p0.z, p1.z)};
  const Vec3 hi{max(p0.x, p1.x), max(p0.y, p1.y), max(p0.z, p1.z)};
  return {lo - rr, hi + rr, static_cast<std::uint32_t>(i), false};
}

// A body this pass sweeps: its motion in the step and a bound of how fast the distance to
// anything can shrink per unit of t.
struct Mover {
  std::size_t index = 0;
  Sweep sweep;
  Vec3 travel;  ///< p1 - p0
  Fixed rim;    ///< how fast the turn can move the body's surface, per unit of t
};

// The bodies to sweep, ascending by index. Whether a body is swept depends on its own motion
// alone, which nothing in this pass changes before its turn, so they can be chosen up front.
std::vector<Mover> movers(const WorldState& s) {
  std::vector<Mover> out;
  for (std::size_t i = 0; i < s.bodies.size(); ++i) {
    const BodyState& body = s.bodies[i];
    if (body.type != BodyType::dynamic || !body.awake || body.sensor) continue;
    const Derived& d = s.derived[i];
    const Vec3 travel = body.position - d.start_position;
    const Fixed distance_moved = length(travel);
    const Geometry* g = s.geometry(body.shape);
    const bool fast =
        distance_moved >
        shape_kind(body.shape.type).smallest_dimension(body.shape, g) / Fixed::from_int(2);
    if (!body.ccd && !fast) continue;
    const Sweep sweep{d.start_position, body.position, d.start_orientation, body.orientation,
                      body.orientation != d.start_orientation};
    // The travel plus the rim speed. Normalised lerp turns at a varying rate, at most twice its
    // mean for any angle up to pi, so the rim term is doubled.
    const Fixed rim = sweep.turns ? angle_bound(sweep.q0, sweep.q1) *
                                        bounding_radius(body.shape, g) * Fixed::from_int(2)
                                  : Fixed::zero();
    if (distance_moved + rim == Fixed::zero()) continue;
    out.push_back({i, sweep, travel, rim});
  }
  return out;
}

// The joint islands of the dynamic bodies. Unbroken joints between two dynamic bodies join;
// static and kinematic bodies do not carry an island's motion back, so they cut it. Both lists
// are empty without joints.
struct JointIslands {
  /// Per body index: the island's lowest body index (the body's own when it is joined to none).
  std::vector<std::uint32_t> root;
  /// Per body index: the next body of its island, in a cycle through the island (ascending by
  /// index from the lowest, the highest back to the lowest); itself when it is joined to none.
  std::vector<std::uint32_t> next;
};

JointIslands joint_islands(const WorldState& s) {
  if (s.joints.empty()) return {};
  const std::size_t n = s.bodies.size();
  std::vector<std::uint32_t> root(n);
  for (std::size_t k = 0; k < n; ++k)
    root[k] = static_cast<std::uint32_t>(k);
  const auto find = [&](std::uint32_t k) {
    while (root[k] != k)
      k = root[k] = root[root[k]];
    return k;
  };
  for (std::size_t ji = 0; ji < s.joints.size(); ++ji) {
    if (s.joints[ji].broken) continue;
    const std::uint32_t a = s.joint_bodies[ji][0];
    const std::uint32_t b = s.joint_bodies[ji][1];
    if (s.bodies[a].type != BodyType::dynamic || s.bodies[b].type != BodyType::dynamic) continue;
    const std::uint32_t ra = find(a);
    const std::uint32_t rb = find(b);
    root[std::max(ra, rb)] = std::min(ra, rb);  // the lowest index is the root: order-free
  }
  // Link each island's members in ascending index order into a cycle.
  std::vector<std::uint32_t> next(n);
  std::vector<std::uint32_t> last(n, UINT32_MAX);  // per root: the member seen last
  for (std::size_t k = 0; k < n; ++k) {
    const std::uint32_t r = find(static_cast<std::uint32_t>(k));
    root[k] = r;
    next[k] = r;  // the highest member's next stays its root
    if (last[r] != UINT32_MAX) next[last[r]] = static_cast<std::uint32_t>(k);
    last[r] = static_cast<std::uint32_t>(k);
  }
  return {std::move(root), std::move(next)};
}

}  // namespace

void continuous(WorldState& s) {
  const std::vector<Mover> swept = movers(s);
  if (swept.empty()) return;
  const std::size_t n = s.bodies.size();
  // Each body's bounding radius, or -1 when unbounded (a plane): looked up once per body, not
  // once per pair. The swept boxes of the solid bounded bodies give the candidates; the planes
  // reach everything and are candidates of every sweep.
  std::vector<Fixed> reach(n);
  std::vector<SweptBox> boxes;
  std::vector<std::uint32_t> planes;  // ascending
  boxes.reserve(n);
  for (std::size_t k = 0, m = 0; k < n; ++k) {
    const ShapeKind& kind = shape_kind(s.bodies[k].shape.type);
    reach[k] = kind.bounded ? kind.bounding_radius(s.bodies[k].shape, s.geometry(s.bodies[k].shape))
                            : -Fixed::one();
    if (s.bodies[k].sensor) continue;
    if (!kind.bounded) {
      planes.push_back(static_cast<std::uint32_t>(k));
      continue;
    }
    boxes.push_back(swept_box(s, k, reach[k]));
    while (m < swept.size() && swept[m].index < k)
      ++m;
    boxes.back().swept = m < swept.size() && swept[m].index == k;
  }
  // The candidates are found once, from the boxes at the start of the pass. A hit moves a body
  // back to p0 + (p1 - p0) t with 0 <= t < 1, which (rounded to nearest, so |(p1 - p0) t| <=
  // |p1 - p0| on each axis) lies between p0 and p1: a later sweep sees a box within the one it
  // had here, so no pair it would test is missing. Each candidate is still tested against the
  // boxes as they are at its turn, as the all-pairs loop did.
  const std::vector<std::uint64_t> pairs = swept_box_pairs(std::move(boxes));
  const std::vector<std::uint64_t> joined = joined_pairs(s);  // these never collide
  const Fixed target = s.def.linear_slop;                     // stop this close to the surface
  // A body moved back to its first touch takes the bodies jointed to it along, each to the same
  // fraction of its own motion in the step, so that no joint is torn open by the pass (a ragdoll
  // whose forearm meets a step stops where the forearm touched, as a whole).
  // Two bodies of one joint island are not swept against each other: the joints hold them
  // together, so neither can pass the other within a step, and a touch between them (a hand on
  // its own chest) is the contact solver's. Swept, such a touch would stop the whole island at
  // the start of every step while its velocity grew.
  const JointIslands islands = joint_islands(s);
  const std::vector<std::uint32_t>& island_next = islands.next;
  std::vector<Mover> movers_now = swept;  // sweeps shortened as islands are moved back
  std::vector<std::uint32_t> mover_of;    // body index -> position in movers_now, or -1
  if (!island_next.empty()) {
    mover_of.assign(n, UINT32_MAX);
    for (std::size_t m = 0; m < movers_now.size(); ++m)
      mover_of[movers_now[m].index] = static_cast<std::uint32_t>(m);
  }
  std::vector<std::uint32_t> near;   // the current sweep's candidates, ascending
  std::vector<SubManifold> scratch;  // the narrowphase's output, reused
  std::size_t next_pair = 0;
  for (const Mover& mover : movers_now) {
    const std::size_t i = mover.index;
    BodyState& body = s.bodies[i];
    const Sweep& sweep = mover.sweep;
    // This sweep's candidates: its pairs (ascending by other index) merged with the planes.
    const std::size_t first_pair = next_pair;
    while (next_pair < pairs.size() && (pairs[next_pair] >> 32) == i)
      ++next_pair;
    near.clear();
    std::size_t plane = 0;
    for (std::size_t k = first_pair; k < next_pair; ++k) {
      const auto j = static_cast<std::uint32_t>(pairs[k] & 0xFFFFFFFFU);
      for (; plane < planes.size() && planes[plane] < j; ++plane)
        near.push_back(planes[plane]);
      near.push_back(j);
    }
    near.insert(near.end(), planes.begin() + static_cast<std::ptrdiff_t>(plane), planes.end());
    const Fixed r = reach[i];
    const SweptBox box = swept_box(s, i, r);

    Fixed first_hit = Fixed::one();  // the earliest touch, as a fraction of the step
    for (const std::uint32_t candidate : near) {
      const std::size_t j = candidate;
      const BodyState& other = s.bodies[j];
      if ((body.layer & other.mask) == 0 || (other.layer & body.mask) == 0) continue;
      const Fixed o = reach[j];
      const bool other_bounded = o >= Fixed::zero();
      // The box the other body covers now (an earlier sweep may have moved it back).
      if (other_bounded && !swept_boxes_overlap(box, swept_box(s, j, o))) continue;
      if (is_joined_pair(joined, i, j)) continue;
      if (!island_next.empty() && islands.root[i] == islands.root[j]) continue;
      // The other body moves too, from its pose at the start of the step to its pose now: the
      // sweep is of the pair, both at the same time t, so a body that moves along with this one
      // is never hit, and one that this body passed during the step always is.
      const Derived& od = s.derived[j];
      const Sweep other_sweep{od.start_position, other.position, od.start_orientation,
                              other.orientation, other.orientation != od.start_orientation};
      // How fast the pair's distance can shrink per unit of t: their relative travel (both move
      // linearly in t, so the difference of their positions does too) plus both rims. Two bodies
      // that move together (the parts of a falling ragdoll, a pile carried on a platform) have
      // no relative travel: without a turn they cannot meet in this step, and summing their
      // travels instead made every such sweep run out of iterations and stop the body short.
      Fixed pair_bound = length(mover.travel - (other_sweep.p1 - other_sweep.p0)) + mover.rim;
      if (other_bounded && other_sweep.turns)
        pair_bound += angle_bound(other_sweep.q0, other_sweep.q1) * o * Fixed::from_int(2);
      if (pair_bound == Fixed::zero()) continue;
      const Fixed pair_beyond = pair_bound + target + r;
      // Already touching at the start: the contact solver has it; a sweep would only stick.
      if (distance(s, body.shape, sweep.at(Fixed::zero()), other.shape,
                   other_sweep.at(Fixed::zero()), pair_beyond, scratch) <= target)
        continue;
      Fixed t = Fixed::zero();
      bool stop = true;  // a touch, or out of iterations: t is then the last safe time
      for (int k = 0; k < max_iterations; ++k) {
        const Fixed gap = distance(s, body.shape, sweep.at(t), other.shape, other_sweep.at(t),
                                   pair_beyond, scratch);
        if (gap <= target) break;
        // A safe advance that aims for half the target gap, so the loop ends near the surface.
        t += (gap - target / Fixed::from_int(2)) / pair_bound;
        if (t >= first_hit) {
          stop = false;  // no touch before what is already known
          break;
        }
      }
      if (stop && t < first_hit) first_hit = t;
    }
    if (first_hit < Fixed::one()) {
      const Pose p = sweep.at(first_hit);
      body.position = p.position;
      if (sweep.turns) body.orientation = nlerp(sweep.q0, sweep.q1, first_hit);
      if (island_next.empty()) continue;
      for (std::uint32_t k = island_next[i]; k != i; k = island_next[k]) {
        BodyState& joined_body = s.bodies[k];
        const Derived& kd = s.derived[k];
        const Sweep along{kd.start_position, joined_body.position, kd.start_orientation,
                          joined_body.orientation, joined_body.orientation != kd.start_orientation};
        joined_body.position = along.at(first_hit).position;
        if (along.turns) joined_body.orientation = nlerp(along.q0, along.q1, first_hit);
        // A body still to be swept sweeps from its start to where it is now.
        if (mover_of[k] != UINT32_MAX) {
          Mover& later = movers_now[mover_of[k]];
          later.sweep.p1 = joined_body.position;
          later.sweep.q1 = joined_body.orientation;
          later.travel = joined_body.position - kd.start_position;
        }
      }
    }
  }
}

}  // namespace detsim::sim_detail
