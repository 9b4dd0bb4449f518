// The convex hull builder (hull.hpp): quickhull with exact orientation predicates, then coplanar
// faces merged and every vertex that is not a corner dropped.
//
// Why our own code rather than a library's (qhull, Bullet's btConvexHullComputer, Jolt's
// ConvexHullBuilder): they decide in floating point, so which points survive, how faces merge and
// in what order vertices come out can differ between compilers and targets, and each of those
// reaches the simulation (a hull's vertices and faces are what contacts are made of). Here every
// decision is made on the Fixed values themselves, by integer arithmetic: an exact sign where the
// topology depends on it, and Fixed distances compared with a documented tolerance where only
// "close enough" is asked. The input is sorted by (x, y, z) raw value and duplicates are dropped
// first, and every later choice breaks ties by that order, so any permutation of the same points
// gives the same hull, bit for bit, on every platform (rule 4 of docs/DETERMINISM.md).
//
// The algorithm (Barber, Dobkin and Huhdanpaa, "The Quickhull Algorithm for Convex Hulls", 1996):
// 1. An initial tetrahedron of extreme points; each other point goes to the first face it is more
//    than `tolerance` above (the face's outside set), or is inside and dropped.
// 2. Repeatedly, the lowest-numbered face with an outside set adds its farthest point (the eye):
//    the faces the eye sees — decided exactly — are removed and the horizon around them is joined
//    to the eye by new triangles; the removed faces' points move to the new faces (or to any face
//    they are above, or are dropped as inside).
// 3. Triangles within `tolerance` of one plane are merged into one polygon (the boundary of the
//    group), and vertices left on fewer than three faces — in the middle of an edge or of a face —
//    are dropped: what remains are true corners.
//
// Exactness: coordinates are at most 10^4 m (raw < 2^45.3), so a difference of two is below
// 2^46.3, a face's exact normal (b - a) x (c - a) has components below 2^93.6 (128 bits) and the
// orientation dot(normal, p - a) is below 2^141.2 (the 256-bit ExactSum<4>). Visibility is that
// exact sign, so the hull of the points processed is exactly convex after every step and the
// horizon is always one simple loop.
//
// Bounded work: at most max_hull_points points; each iteration makes one point a vertex for good,
// so there are at most that many iterations; the face array is reused through a free list and
// never holds more than 2 V + its free slots; the build stops as soon as the hull in progress has
// more than 2 * max_hull_vertices vertices.
#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <detsim/fixed/decimal.hpp>
#include <detsim/fixed/exact_sum.hpp>
#include <detsim/fixed/math.hpp>

#include "../limits.hpp"
#include "hull.hpp"

namespace detsim::sim_detail {

namespace hull_build_detail {

constexpr std::uint32_t none = 0xFFFFFFFFU;

/// A sign and a 128-bit magnitude: one component of an exact face normal.
struct Wide {
  bool negative = false;
  wide::U128 magnitude;
};

using ExactNormal = std::array<Wide, 3>;

std::int64_t diff(Fixed a, Fixed b) noexcept {
  return a.raw() - b.raw();  // |a|, |b| <= 10^4 m: no overflow
}

/// (b - a) x (c - a), exactly.
ExactNormal exact_normal(Vec3 a, Vec3 b, Vec3 c) noexcept {
  const std::array<std::int64_t, 3> u{diff(b.x, a.x), diff(b.y, a.y), diff(b.z, a.z)};
  const std::array<std::int64_t, 3> v{diff(c.x, a.x), diff(c.y, a.y), diff(c.z, a.z)};
  ExactNormal n;
  for (std::size_t i = 0; i < 3; ++i) {
    const std::size_t j = (i + 1) % 3;
    const std::size_t k = (i + 2) % 3;
    detail::ProductSum s;
    s.add_product(u[j], v[k]);
    s.sub_product(u[k], v[j]);
    n[i] = {s.negative(), s.magnitude_128()};
  }
  return n;
}

/// The sign of dot(n, p - a): +1 above the plane, 0 on it, -1 below. Exact.
int side(const ExactNormal& n, Vec3 a, Vec3 p) noexcept {
  detail::ExactSum<4> s;
  s.add_product(n[0].negative, n[0].magnitude, diff(p.x, a.x));
  s.add_product(n[1].negative, n[1].magnitude, diff(p.y, a.y));
  s.add_product(n[2].negative, n[2].magnitude, diff(p.z, a.z));
  if (s.is_zero()) return 0;
  return s.negative() ? -1 : 1;
}

/// The unit vector along an exact vector: the components are shifted (by the same amount) to 40
/// significant bits, which keeps the direction to a relative 2^-39, then normalised. The zero
/// vector gives zero.
Vec3 unit_of(const ExactNormal& n) noexcept {
  int top = 0;
  for (const Wide& c : n) {
    const int bits = c.magnitude.hi != 0 ? 128 - std::countl_zero(c.magnitude.hi)
                                         : 64 - std::countl_zero(c.magnitude.lo);
    top = std::max(top, bits);
  }
  if (top == 0) return {};
  std::array<Fixed, 3> r{};
  for (std::size_t i = 0; i < 3; ++i) {
    const wide::U128 m = top > 40 ? wide::shr(n[i].magnitude, static_cast<unsigned>(top - 40))
                                  : wide::shl(n[i].magnitude, static_cast<unsigned>(40 - top));
    const auto v = static_cast<std::int64_t>(m.lo);
    r[i] = Fixed::from_raw(n[i].negative ? -v : v);
  }
  return normalize(Vec3{r[0], r[1], r[2]});
}

struct Face {
  std::array<std::uint16_t, 3> v{};                    ///< counter-clockwise from outside
  std::array<std::uint32_t, 3> adj{none, none, none};  ///< across edge v[i] -> v[i + 1]
  ExactNormal normal;
  Vec3 unit;
  std::vector<std::uint16_t> outside;
  std::uint16_t furthest = 0;
  Fixed furthest_distance;
  std::uint32_t stamp = 0;
  bool alive = false;
};

struct HorizonEdge {
  std::uint16_t from;
  std::uint16_t to;
  std::uint32_t beyond;
};

Status refuse(std::string message) {
  return Status::error("convex hull: " + std::move(message));
}

class HullBuilder {
 public:
  HullBuilder(std::vector<Vec3> points, Fixed tolerance)
      : p_(std::move(points)), tolerance_(tolerance), slot_(p_.size(), -1) {}

  Status build();
  const std::vector<Vec3>& points() const { return p_; }
  std::vector<std::vector<std::uint16_t>>& loops() { return loops_; }

 private:
  /// Signed distance of p above face f's plane (Fixed; error about 2^-31 of the hull's extent).
  Fixed distance(const Face& f, Vec3 p) const noexcept { return dot(f.unit, p - p_[f.v[0]]); }
  std::uint32_t new_face(std::uint16_t a, std::uint16_t b, std::uint16_t c);
  void link(std::uint32_t f, std::uint16_t from, std::uint16_t to, std::uint32_t g);
  bool assign(std::uint16_t point, const std::vector<std::uint32_t>& candidates);
  Status initial_simplex();
  Status add_eye(std::uint32_t face);
  Status merge();
  bool boundary_loop(const std::vector<std::uint32_t>& group, const std::vector<std::int32_t>& id,
                     std::int32_t g, std::vector<std::uint16_t>& loop);
  std::size_t alive_faces() const noexcept { return faces_.size() - free_.size(); }

  std::vector<Vec3> p_;
  Fixed tolerance_;
  std::vector<Face> faces_;
  std::vector<std::uint32_t> free_;
  std::vector<std::int32_t> slot_;  ///< per point, scratch for loop chaining (-1 between uses)
  std::uint32_t stamp_ = 0;
  std::vector<std::vector<std::uint16_t>> loops_;
};

std::uint32_t HullBuilder::new_face(std::uint16_t a, std::uint16_t b, std::uint16_t c) {
  std::uint32_t f = 0;
  if (free_.empty()) {
    f = static_cast<std::uint32_t>(faces_.size());
    faces_.emplace_back();
  } else {
    f = free_.back();
    free_.pop_back();
  }
  Face& face = faces_[f];
  face = Face{};
  face.v = {a, b, c};
  face.normal = exact_normal(p_[a], p_[b], p_[c]);
  face.unit = unit_of(face.normal);
  face.alive = true;
  return f;
}

/// Sets the neighbour of f across its edge from -> to to g.
void HullBuilder::link(std::uint32_t f, std::uint16_t from, std::uint16_t to, std::uint32_t g) {
  Face& face = faces_[f];
  for (std::size_t i = 0; i < 3; ++i) {
    if (face.v[i] == from && face.v[(i + 1) % 3] == to) face.adj[i] = g;
  }
}

/// Puts the point in the outside set of the first candidate face it is more than the tolerance
/// above; a point above none is inside (within the tolerance) and dropped. Ties for the farthest
/// point go to the lowest index. Whether it was placed.
bool HullBuilder::assign(std::uint16_t point, const std::vector<std::uint32_t>& candidates) {
  for (const std::uint32_t f : candidates) {
    Face& face = faces_[f];
    if (!face.alive) continue;
    const Fixed d = distance(face, p_[point]);
    if (d <= tolerance_) continue;
    if (face.outside.empty() || d > face.furthest_distance ||
        (d == face.furthest_distance && point < face.furthest)) {
      face.furthest = point;
      face.furthest_distance = d;
    }
    face.outside.push_back(point);
    return true;
  }
  return false;
}

Status HullBuilder::initial_simplex() {
  const auto n = static_cast<std::uint16_t>(p_.size());
  // p0 is the lowest point in (x, y, z) order (a vertex of any hull); p1 the farthest from it;
  // p2 the farthest from the line p0 p1; p3 the farthest from the plane p0 p1 p2. Ties: lowest.
  const std::uint16_t i0 = 0;
  std::uint16_t i1 = 0;
  Fixed best;
  for (std::uint16_t i = 1; i < n; ++i) {
    const Fixed d = detsim::distance(p_[i], p_[i0]);
    if (d > best) {
      best = d;
      i1 = i;
    }
  }
  const Vec3 axis = normalize(p_[i1] - p_[i0]);
  std::uint16_t i2 = 0;
  best = Fixed::zero();
  for (std::uint16_t i = 1; i < n; ++i) {
    const Fixed d = length(cross(p_[i] - p_[i0], axis));
    if (d > best) {
      best = d;
      i2 = i;
    }
  }
  if (best < hull_min_thickness)
    return refuse("the points lie on a line (all within " + to_string(best) +
                  " m of it); a hull needs 4 points that are not coplanar, at least "
                  "0.0009765625 m off a plane");
  const ExactNormal base = exact_normal(p_[i0], p_[i1], p_[i2]);
  const Vec3 up = unit_of(base);
  std::uint16_t i3 = 0;
  best = Fixed::zero();
  for (std::uint16_t i = 1; i < n; ++i) {
    const Fixed d = abs(dot(up, p_[i] - p_[i0]));
    if (d > best) {
      best = d;
      i3 = i;
    }
  }
  if (best < hull_min_thickness)
    return refuse("the points are flat (all within " + to_string(best) +
                  " m of one plane); a hull needs 4 points that are not coplanar, at least "
                  "0.0009765625 m off a plane");

  const std::array<std::uint16_t, 4> t{i0, i1, i2, i3};
  std::array<std::uint32_t, 4> made{};
  for (std::size_t k = 0; k < 4; ++k) {
    // The face opposite t[k], wound so that t[k] is below it.
    std::array<std::uint16_t, 3> v{};
    std::size_t m = 0;
    for (std::size_t j = 0; j < 4; ++j) {
      if (j != k) v[m++] = t[j];
    }
    if (side(exact_normal(p_[v[0]], p_[v[1]], p_[v[2]]), p_[v[0]], p_[t[k]]) > 0)
      std::swap(v[1], v[2]);
    made[k] = new_face(v[0], v[1], v[2]);
  }
  for (const std::uint32_t f : made) {
    for (std::size_t i = 0; i < 3; ++i) {
      const std::uint16_t from = faces_[f].v[i];
      const std::uint16_t to = faces_[f].v[(i + 1) % 3];
      for (const std::uint32_t g : made) {
        if (g != f) link(g, to, from, f);
      }
    }
  }
  const std::vector<std::uint32_t> all(made.begin(), made.end());
  for (std::uint16_t i = 0; i < n; ++i) {
    if (i != i0 && i != i1 && i != i2 && i != i3) static_cast<void>(assign(i, all));
  }
  return Status::success();
}

Status HullBuilder::add_eye(std::uint32_t start) {
  const std::uint16_t eye = faces_[start].furthest;
  const Vec3 e = p_[eye];
  // The faces the eye sees (exactly above their planes): a connected region around `start`.
  ++stamp_;
  std::vector<std::uint32_t> visible{start};
  faces_[start].stamp = stamp_;
  for (std::size_t k = 0; k < visible.size(); ++k) {
    for (const std::uint32_t g : faces_[visible[k]].adj) {
      Face& face = faces_[g];
      if (face.stamp == stamp_) continue;
      if (side(face.normal, p_[face.v[0]], e) > 0) {
        face.stamp = stamp_;
        visible.push_back(g);
      }
    }
  }
  // The horizon: edges of visible faces whose neighbour is not visible, chained into one loop.
  std::vector<HorizonEdge> edges;
  for (const std::uint32_t f : visible) {
    for (std::size_t i = 0; i < 3; ++i) {
      const std::uint32_t g = faces_[f].adj[i];
      if (faces_[g].stamp != stamp_) edges.push_back({faces_[f].v[i], faces_[f].v[(i + 1) % 3], g});
    }
  }
  bool simple = true;
  for (std::size_t k = 0; k < edges.size(); ++k) {
    if (slot_[edges[k].from] >= 0) simple = false;
    slot_[edges[k].from] = static_cast<std::int32_t>(k);
  }
  std::vector<HorizonEdge> loop;
  if (simple) {
    std::size_t k = 0;
    do {
      loop.push_back(edges[k]);
      const std::int32_t next = slot_[edges[k].to];
      if (next < 0) break;
      k = static_cast<std::size_t>(next);
    } while (k != 0 && loop.size() <= edges.size());
  }
  for (const HorizonEdge& h : edges)
    slot_[h.from] = -1;
  if (!simple || loop.size() != edges.size())
    return refuse("internal error: the horizon is not one loop");

  // New faces from each horizon edge to the eye, linked to the faces beyond and to each other.
  std::vector<std::uint32_t> made;
  made.reserve(loop.size());
  for (const HorizonEdge& h : loop)
    made.push_back(new_face(h.from, h.to, eye));
  for (std::size_t k = 0; k < loop.size(); ++k) {
    Face& face = faces_[made[k]];
    face.adj[0] = loop[k].beyond;
    face.adj[1] = made[(k + 1) % made.size()];
    face.adj[2] = made[(k + made.size() - 1) % made.size()];
    link(loop[k].beyond, loop[k].to, loop[k].from, made[k]);
  }
  // The visible faces go; their points move to the new faces, or to any face they are above.
  std::vector<std::uint16_t> orphans;
  for (const std::uint32_t f : visible) {
    Face& face = faces_[f];
    for (const std::uint16_t q : face.outside) {
      if (q != eye) orphans.push_back(q);
    }
    std::vector<std::uint16_t>().swap(face.outside);
    face.alive = false;
  }
  // Freed in reverse, so that later faces reuse the slots in the order the faces were found.
  for (auto it = visible.rbegin(); it != visible.rend(); ++it)
    free_.push_back(*it);
  std::vector<std::uint32_t> all;
  for (const std::uint16_t q : orphans) {
    if (assign(q, made)) continue;
    // Not above a new face, but it may still be above an old one (then it is not inside).
    if (all.empty()) {
      for (std::uint32_t f = 0; f < faces_.size(); ++f) {
        if (faces_[f].alive) all.push_back(f);
      }
    }
    static_cast<void>(assign(q, all));
  }
  return Status::success();
}

/// The boundary of a group of triangles, counter-clockwise from outside; false unless it is one
/// simple loop (the group is a disc).
bool HullBuilder::boundary_loop(const std::vector<std::uint32_t>& group,
                                const std::vector<std::int32_t>& id, std::int32_t g,
                                std::vector<std::uint16_t>& loop) {
  std::vector<std::array<std::uint16_t, 2>> edges;
  for (const std::uint32_t f : group) {
    for (std::size_t i = 0; i < 3; ++i) {
      if (id[faces_[f].adj[i]] != g) edges.push_back({faces_[f].v[i], faces_[f].v[(i + 1) % 3]});
    }
  }
  bool simple = true;
  for (std::size_t k = 0; k < edges.size(); ++k) {
    if (slot_[edges[k][0]] >= 0) simple = false;
    slot_[edges[k][0]] = static_cast<std::int32_t>(k);
  }
  loop.clear();
  if (simple && !edges.empty()) {
    std::size_t k = 0;
    do {
      loop.push_back(edges[k][0]);
      const std::int32_t next = slot_[edges[k][1]];
      if (next < 0) break;
      k = static_cast<std::size_t>(next);
    } while (k != 0 && loop.size() <= edges.size());
  }
  for (const auto& e : edges)
    slot_[e[0]] = -1;
  return simple && loop.size() == edges.size() && loop.size() >= 3;
}

Status HullBuilder::merge() {
  // Groups of triangles within the tolerance of the plane of the group's first (lowest-numbered)
  // triangle, grown across edges. That plane supports the hull exactly (every vertex is on or
  // below it), so a group lies in a slab of the tolerance's width below it.
  std::vector<std::int32_t> id(faces_.size(), -1);
  std::vector<std::vector<std::uint32_t>> groups;
  for (std::uint32_t s = 0; s < faces_.size(); ++s) {
    if (!faces_[s].alive || id[s] >= 0) continue;
    const auto g = static_cast<std::int32_t>(groups.size());
    groups.push_back({s});
    id[s] = g;
    const Face& seed = faces_[s];
    std::vector<std::uint32_t>& group = groups.back();
    for (std::size_t k = 0; k < group.size(); ++k) {
      for (const std::uint32_t t : faces_[group[k]].adj) {
        if (id[t] >= 0) continue;
        bool flat = true;
        for (const std::uint16_t v : faces_[t].v)
          flat = flat && abs(distance(seed, p_[v])) <= tolerance_;
        if (flat) {
          id[t] = g;
          group.push_back(t);
        }
      }
    }
  }
  // Each group's boundary is its polygon. A group that is not a disc (a pathological ring of
  // nearly coplanar triangles) is left as its triangles rather than merged.
  std::vector<std::uint16_t> loop;
  const std::size_t group_count = groups.size();
  for (std::size_t gi = 0; gi < group_count; ++gi) {
    const auto g = static_cast<std::int32_t>(gi);
    if (boundary_loop(groups[gi], id, g, loop)) {
      loops_.push_back(loop);
      continue;
    }
    for (const std::uint32_t f : groups[gi]) {
      id[f] = static_cast<std::int32_t>(groups.size());
      groups.push_back({f});
    }
  }
  for (std::size_t gi = group_count; gi < groups.size(); ++gi) {
    const Face& f = faces_[groups[gi][0]];
    loops_.push_back({f.v[0], f.v[1], f.v[2]});
  }
  // A vertex on fewer than three faces is in the middle of an edge (two) or of a face (one, and
  // then on no boundary already): not a corner. Drop it from every loop.
  std::vector<std::uint8_t> degree(p_.size(), 0);
  for (const auto& l : loops_) {
    for (const std::uint16_t v : l)
      degree[v] = static_cast<std::uint8_t>(std::min(degree[v] + 1, 3));
  }
  for (auto& l : loops_) {
    std::erase_if(l, [&degree](std::uint16_t v) { return degree[v] < 3; });
    if (l.size() < 3) return refuse("internal error: a face lost its corners");
  }
  return Status::success();
}

Status HullBuilder::build() {
  if (Status s = initial_simplex(); !s) return s;
  const std::size_t cap = 2 * max_hull_vertices;
  for (std::size_t iteration = 0; iteration <= p_.size(); ++iteration) {
    std::uint32_t next = none;
    for (std::uint32_t f = 0; f < faces_.size(); ++f) {
      if (faces_[f].alive && !faces_[f].outside.empty()) {
        next = f;
        break;
      }
    }
    if (next == none) return merge();
    if (Status s = add_eye(next); !s) return s;
    // A closed triangulated surface has V = F / 2 + 2.
    if (alive_faces() / 2 + 2 > cap)
      return refuse("the hull has more than " + std::to_string(max_hull_vertices) +
                    " corners (at least " + std::to_string(alive_faces() / 2 + 2) +
                    " while building); simplify the points first");
  }
  return refuse("internal error: quickhull did not finish");
}

/// Fills the hull's faces, edges, bounds and solid properties from its face loops (vertex indices,
/// counter-clockwise from outside), and checks that they make a closed convex surface.
Status finish_hull(Hull& hull, const std::vector<std::vector<std::uint16_t>>& loops) {
  const std::vector<Vec3>& v = hull.vertices;
  for (const auto& loop : loops) {
    HullFace face;
    face.first = static_cast<std::uint16_t>(hull.face_vertices.size());
    face.count = static_cast<std::uint16_t>(loop.size());
    hull.face_vertices.insert(hull.face_vertices.end(), loop.begin(), loop.end());
    // The normal is the direction of the polygon's exact area vector: the sum of its fan
    // triangles' cross products (each below 2^93.6, at most 254 of them: 128 bits hold it).
    std::array<detail::ProductSum, 3> area;
    const Vec3 o = v[loop[0]];
    for (std::size_t k = 1; k + 1 < loop.size(); ++k) {
      const ExactNormal n = exact_normal(o, v[loop[k]], v[loop[k + 1]]);
      for (std::size_t i = 0; i < 3; ++i)
        area[i].add(n[i].negative, n[i].magnitude);
    }
    ExactNormal sum;
    for (std::size_t i = 0; i < 3; ++i)
      sum[i] = {area[i].negative(), area[i].magnitude_128()};
    face.normal = unit_of(sum);
    // The offset is the hull's support along the normal, so that every vertex is on or below
    // the plane: the plane of a merged face is as far out as its farthest vertex.
    face.offset = dot(face.normal, v[0]);
    for (const Vec3 p : v)
      face.offset = max(face.offset, dot(face.normal, p));
    hull.faces.push_back(face);
  }
  // Edges from the loops' directed edges: a -> b in face_0's loop, b -> a in face_1's.
  struct Directed {
    std::uint16_t from;
    std::uint16_t to;
    std::uint16_t face;
  };
  std::vector<Directed> directed;
  for (std::size_t f = 0; f < loops.size(); ++f) {
    const auto& loop = loops[f];
    for (std::size_t k = 0; k < loop.size(); ++k) {
      directed.push_back({loop[k], loop[(k + 1) % loop.size()], static_cast<std::uint16_t>(f)});
    }
  }
  const auto before = [](const Directed& a, const Directed& b) {
    return std::pair(a.from, a.to) < std::pair(b.from, b.to);
  };
  std::sort(directed.begin(), directed.end(), before);  // keys are unique on a closed surface
  for (const Directed& d : directed) {
    const Directed reverse{d.to, d.from, 0};
    const auto it = std::lower_bound(directed.begin(), directed.end(), reverse, before);
    if (it == directed.end() || it->from != d.to || it->to != d.from)
      return refuse("internal error: an edge has one face");
    if (d.from < d.to) hull.edges.push_back({d.from, d.to, d.face, it->face, Vec3{}});
  }
  if (v.size() + hull.faces.size() != hull.edges.size() + 2)
    return refuse("internal error: the faces do not close (V - E + F != 2)");

  hull.aabb_min = v[0];
  hull.aabb_max = v[0];
  for (const Vec3 p : v) {
    hull.aabb_min = {min(hull.aabb_min.x, p.x), min(hull.aabb_min.y, p.y),
                     min(hull.aabb_min.z, p.z)};
    hull.aabb_max = {max(hull.aabb_max.x, p.x), max(hull.aabb_max.y, p.y),
                     max(hull.aabb_max.z, p.z)};
    hull.bounding_radius = max(hull.bounding_radius, length(p));
  }
  Expected<SolidProperties> solid = solid_properties(hull);
  if (!solid) return solid.status();
  hull.solid = *solid;
  hull.inner_radius = Fixed::max();
  for (const HullFace& face : hull.faces)
    hull.inner_radius = min(hull.inner_radius, face.offset - dot(face.normal, hull.solid.centroid));
  return Status::success();
}

}  // namespace hull_build_detail

Expected<Hull> build_hull(std::span<const Vec3> points) {
  using namespace hull_build_detail;
  if (points.size() > max_hull_points)
    return refuse("too many points: " + std::to_string(points.size()) + ", at most " +
                  std::to_string(max_hull_points));
  const Fixed limit = Fixed::from_int(10000);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3 p = points[i];
    const std::array<Fixed, 3> c{p.x, p.y, p.z};
    for (std::size_t k = 0; k < 3; ++k) {
      if (beyond(c[k], limit))
        return refuse("point " + std::to_string(i) + " has " + "xyz"[k] + " = " + to_string(c[k]) +
                      ", outside +-10000 m");
    }
  }
  // Sorted by (x, y, z) raw value, duplicates dropped: the hull is then a function of the set of
  // points. The keys are the values themselves, so equal keys are equal points and the order is
  // total: std::sort cannot leave an implementation-dependent order here.
  std::vector<Vec3> sorted(points.begin(), points.end());
  const auto key = [](Vec3 v) { return std::array{v.x.raw(), v.y.raw(), v.z.raw()}; };
  std::sort(sorted.begin(), sorted.end(), [&key](Vec3 a, Vec3 b) { return key(a) < key(b); });
  sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
  if (sorted.size() < 4)
    return refuse("fewer than 4 distinct points (" + std::to_string(sorted.size()) +
                  "); a hull needs 4 points that are not coplanar");

  // The tolerance: 2^-20 m (about a micrometre) plus 2^-26 of the cloud's extent. Distances to a
  // face plane are computed with a unit normal good to about 2^-32 relative, so their error is
  // about 2^-31 of the extent: the tolerance is 32 times that at any size.
  Vec3 lo = sorted[0];
  Vec3 hi = sorted[0];
  for (const Vec3 p : sorted) {
    lo = {min(lo.x, p.x), min(lo.y, p.y), min(lo.z, p.z)};
    hi = {max(hi.x, p.x), max(hi.y, p.y), max(hi.z, p.z)};
  }
  const Fixed extent = max(hi.x - lo.x, max(hi.y - lo.y, hi.z - lo.z));
  const Fixed tolerance = hull_tolerance(extent);

  HullBuilder builder(std::move(sorted), tolerance);
  if (Status s = builder.build(); !s) return s;
  const std::vector<Vec3>& p = builder.points();
  auto& loops = builder.loops();

  // The corners, in the sorted order of the input (so ascending by (x, y, z)), renumbered.
  std::vector<std::int32_t> index(p.size(), -1);
  for (const auto& l : loops) {
    for (const std::uint16_t v : l)
      index[v] = 0;
  }
  Hull hull;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (index[i] < 0) continue;
    index[i] = static_cast<std::int32_t>(hull.vertices.size());
    hull.vertices.push_back(p[i]);
  }
  if (hull.vertices.size() > max_hull_vertices)
    return refuse("the hull has " + std::to_string(hull.vertices.size()) + " corners, more than " +
                  std::to_string(max_hull_vertices) + "; simplify the points first");
  // Each loop renumbered and started at its lowest vertex; faces in the order of their first two
  // vertices (unique: a directed edge belongs to one face).
  for (auto& l : loops) {
    for (std::uint16_t& v : l)
      v = static_cast<std::uint16_t>(index[v]);
    std::rotate(l.begin(), std::min_element(l.begin(), l.end()), l.end());
  }
  std::sort(loops.begin(), loops.end(), [](const auto& a, const auto& b) {
    return std::pair(a[0], a[1]) < std::pair(b[0], b[1]);
  });
  if (Status s = finish_hull(hull, loops); !s) return s;
  // Each edge's unit direction, once: the separating-axis test reads every edge of both hulls of
  // every pair, every step.
  for (HullEdge& e : hull.edges)
    e.direction = normalize(hull.vertices[e.b] - hull.vertices[e.a]);
  make_coarse(hull);
  return hull;
}

namespace {

// Whether vertex a is strictly farther along `direction` than vertex b, exactly:
// dot(direction, a - b) summed in 192 bits, so neither the length of the direction nor rounding
// can change the answer.
bool farther(Vec3 direction, Vec3 a, Vec3 b) noexcept {
  detail::ExactSum<3> s;
  s.add_product(direction.x.raw(), a.x.raw() - b.x.raw());
  s.add_product(direction.y.raw(), a.y.raw() - b.y.raw());
  s.add_product(direction.z.raw(), a.z.raw() - b.z.raw());
  return !s.negative() && !s.is_zero();
}

// The exact scan over `count` vertices (or those `keep` marks): ties keep the lower index.
std::uint16_t exact_support(const Hull& hull, Vec3 direction, const bool* keep) noexcept {
  std::size_t best = hull.vertices.size();
  for (std::size_t i = 0; i < hull.vertices.size(); ++i) {
    if (keep != nullptr && !keep[i]) continue;
    if (best == hull.vertices.size() || farther(direction, hull.vertices[i], hull.vertices[best]))
      best = i;
  }
  return static_cast<std::uint16_t>(best);
}

}  // namespace

namespace {

std::array<std::int64_t, 3> coarse_of(Vec3 v) noexcept {
  return {v.x.raw() >> 20, v.y.raw() >> 20, v.z.raw() >> 20};
}

std::int64_t magnitude_of(const std::array<std::int64_t, 3>& c) noexcept {
  const auto m = [](std::int64_t x) { return x < 0 ? -x : x; };
  return std::max({m(c[0]), m(c[1]), m(c[2])});
}

}  // namespace

void make_coarse(Hull& hull) {
  hull.coarse.clear();
  hull.coarse_widest = 0;
  for (const Vec3 v : hull.vertices) {
    hull.coarse.push_back(coarse_of(v));
    hull.coarse_widest = std::max(hull.coarse_widest, magnitude_of(hull.coarse.back()));
  }
}

std::uint16_t hull_support(const Hull& hull, Vec3 direction) noexcept {
  // The answer is the exact scan's (exact_support: the lowest index of the exactly farthest
  // vertices), found faster: a 64-bit estimate of every vertex's dot product, with a bound on its
  // error, keeps only the vertices that could be farthest, and the exact scan runs over those (in
  // index order, so ties still keep the lower index). The estimate: the direction cut to 15
  // significant bits (d' = d >> s), each vertex coordinate to raw >> 20 (v', Hull::coarse;
  // |v'| < 2^43 for any Fixed), so |sum d' v'| < 3 * 2^58: no overflow. Its error against
  // sum (d / 2^s)(v / 2^20) is below sum over c of (max |v'| + 1) + (|d'_c| + 1) per vertex; two
  // estimates within twice that of the best may be in either order, and are both kept.
  constexpr std::size_t kMaxEstimated = 64;
  const std::size_t n = hull.vertices.size();
  if (n <= 1 || n > kMaxEstimated) return exact_support(hull, direction, nullptr);
  const bool built = hull.coarse.size() == n;
  const std::array<std::int64_t, 3> d{direction.x.raw(), direction.y.raw(), direction.z.raw()};
  std::uint64_t largest = 0;
  for (const std::int64_t c : d)
    largest = std::max(largest,
                       c < 0 ? 0U - static_cast<std::uint64_t>(c) : static_cast<std::uint64_t>(c));
  const int s = std::max(0, static_cast<int>(std::bit_width(largest)) - 15);
  std::array<std::int64_t, 3> dc{};
  std::int64_t error = 0;
  for (std::size_t c = 0; c < 3; ++c) {
    dc[c] = d[c] >> s;  // arithmetic: floor
    error += (dc[c] < 0 ? -dc[c] : dc[c]) + 1;
  }
  std::array<std::int64_t, kMaxEstimated> estimate;  // entries [0, n) written below (no memset)
  std::int64_t widest = built ? hull.coarse_widest : 0;
  std::int64_t top = INT64_MIN;
  for (std::size_t i = 0; i < n; ++i) {
    const std::array<std::int64_t, 3> v = built ? hull.coarse[i] : coarse_of(hull.vertices[i]);
    if (!built) widest = std::max(widest, magnitude_of(v));
    estimate[i] = dc[0] * v[0] + dc[1] * v[1] + dc[2] * v[2];
    top = std::max(top, estimate[i]);
  }
  error += 3 * (widest + 1);
  std::array<bool, kMaxEstimated> keep;  // entries [0, n) written below
  std::size_t kept = 0;
  std::size_t only = 0;
  for (std::size_t i = 0; i < n; ++i) {
    keep[i] = estimate[i] >= top - 2 * error;
    if (keep[i]) {
      ++kept;
      only = i;
    }
  }
  if (kept == 1) return static_cast<std::uint16_t>(only);
  return exact_support(hull, direction, keep.data());
}

}  // namespace detsim::sim_detail
