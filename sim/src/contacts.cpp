// Narrowphase driving, warm-start matching, islands and sleep.
//
// Islands are not stored: they are recomputed when needed with a union-find over the touching
// contacts and the unbroken joints between dynamic bodies, rooted at the lowest body index (so at
// the lowest ID), which makes them a pure function of the saved state.
#include <algorithm>
#include <numeric>
#include <vector>

#include <detsim/fixed/math.hpp>

#include "particles/xpbd.hpp"
#include "world_state.hpp"

namespace detsim::sim_detail {

namespace {

std::size_t index_of(const WorldState& s, std::uint32_t id) {
  return static_cast<std::size_t>(s.find(id));
}

bool moving(const BodyState& b) {
  if (b.type == BodyType::static_body || !b.awake) return false;
  if (b.type == BodyType::dynamic) return true;
  return b.linear_velocity != Vec3{} || b.angular_velocity != Vec3{};  // a kinematic body
}

// How far apart two bodies may be and still touch within this step: the speculative distance
// plus the distance their relative motion can close in dt (linear, and the rim speed of each
// body's rotation). Speculative contacts over this margin let the solver stop a fast body exactly
// at the surface instead of resolving a deep overlap a step later, which keeps bounces elastic and
// thin walls solid; the margin is capped so that a runaway speed cannot make every pair collide.
Fixed contact_margin(const WorldState& s, std::size_t ia, std::size_t ib) {
  const Fixed closing = length(s.bodies[ia].linear_velocity - s.bodies[ib].linear_velocity) +
                        s.derived[ia].rim_speed + s.derived[ib].rim_speed;
  const Fixed cap = Fixed::from_int(20);
  return s.def.speculative_distance + min(closing * s.def.dt, cap);
}

// Sets the manifold of `c` and carries the impulses of points whose features persist.
void take_manifold(Contact& c, const Manifold& m) {
  c.manifold = m;
  std::array<CachedPoint, 4> next{};
  for (std::size_t k = 0; k < c.manifold.count; ++k) {
    next[k].feature = c.manifold.points[k].feature;
    for (std::size_t j = 0; j < c.point_count; ++j) {
      if (c.cached[j].feature == next[k].feature) {
        next[k] = c.cached[j];
        break;
      }
    }
  }
  c.cached = next;
  c.point_count = c.manifold.count;
  c.touching = c.point_count > 0;
  c.collided = true;
  c.pushed = false;  // set by the solver if a point pushes
}

PosedShape posed(const WorldState& s, std::size_t i) {
  return {s.bodies[i].shape, s.geometry(s.bodies[i].shape), s.derived[i].pose};
}

// Recomputes the manifold of `c`, a pair of two whole shapes.
void collide_one(WorldState& s, Contact& c, std::size_t ia, std::size_t ib) {
  take_manifold(c, collide(posed(s, ia), posed(s, ib), contact_margin(s, ia, ib)));
}

// Whether the group of the contact at `i` (its body pair) has sub-shapes on either side.
bool group_has_sub_shapes(const WorldState& s, const Contact& c) {
  return has_sub_shapes(posed(s, c.index_a)) || has_sub_shapes(posed(s, c.index_b));
}

// Recomputes the group [first, last) of s.contacts, a body pair with sub-shapes, into `out`: one
// contact per sub-manifold with points, ascending by sub-shapes, each carrying the impulses of
// the group's contact of the same sub-shapes (matched by feature, as for whole shapes); with no
// points anywhere, one empty contact of sub-shapes (0, 0), which keeps the pair until its boxes
// part. Every contact of the group keeps the pair's reported flag.
void collide_group(WorldState& s, std::size_t first, std::size_t last, std::vector<Contact>& out,
                   std::vector<SubManifold>& scratch) {
  const Contact& head = s.contacts[first];
  const std::size_t ia = head.index_a;
  const std::size_t ib = head.index_b;
  collide_all(posed(s, ia), posed(s, ib), contact_margin(s, ia, ib), scratch);
  std::size_t old = first;
  const auto fresh = [&head] {
    Contact c;
    c.a = head.a;
    c.b = head.b;
    c.index_a = head.index_a;
    c.index_b = head.index_b;
    c.reported = head.reported;
    return c;
  };
  // Against a surface, a part's patch of one face moves from triangle to triangle (its key, the
  // lowest triangle, changes): a manifold whose key is new takes the impulses of the old contact of
  // the same part with the same normal, where there is one.
  const bool surface = has_triangles(posed(s, ia)) || has_triangles(posed(s, ib));
  const auto same_face = [&](const SubManifold& m) {
    for (std::size_t j = first; j < last; ++j) {
      const Contact& o = s.contacts[j];
      if (o.sub_a == m.sub_a && o.point_count > 0 &&
          dot(o.manifold.normal, m.manifold.normal) >= surface_patch_cos)
        return j;
    }
    return last;
  };
  for (const SubManifold& m : scratch) {
    while (old < last && (s.contacts[old].sub_a < m.sub_a ||
                          (s.contacts[old].sub_a == m.sub_a && s.contacts[old].sub_b < m.sub_b)))
      ++old;
    std::size_t match =
        old < last && s.contacts[old].sub_a == m.sub_a && s.contacts[old].sub_b == m.sub_b ? old
                                                                                           : last;
    if (match == last && surface) match = same_face(m);
    Contact c = match < last ? s.contacts[match] : fresh();
    c.sub_a = m.sub_a;
    c.sub_b = m.sub_b;
    take_manifold(c, m.manifold);
    out.push_back(c);
  }
  if (scratch.empty()) {
    Contact c = fresh();
    take_manifold(c, Manifold{});
    out.push_back(c);
  }
}

// The narrowphase over the contact list: every pair in which something moves (`only_new`: only
// the pairs not yet collided this step). Pairs of two whole shapes are updated in place; when a
// pair has sub-shapes, the list is rebuilt, as its contacts come and go with its parts' touches.
void narrowphase(WorldState& s, bool only_new) {
  const auto wanted = [&](const Contact& c) {
    if (only_new) return !c.collided;
    return moving(s.bodies[c.index_a]) || moving(s.bodies[c.index_b]);
  };
  bool parts = false;
  for (const Contact& c : s.contacts)
    parts = parts || (wanted(c) && group_has_sub_shapes(s, c));
  if (!parts) {
    for (Contact& c : s.contacts) {
      if (wanted(c)) collide_one(s, c, c.index_a, c.index_b);
    }
    return;
  }
  std::vector<Contact> next;
  next.reserve(s.contacts.size() + 8);
  std::vector<SubManifold> scratch;
  for (std::size_t first = 0; first < s.contacts.size();) {
    std::size_t last = first + 1;
    while (last < s.contacts.size() && s.contacts[last].a == s.contacts[first].a &&
           s.contacts[last].b == s.contacts[first].b)
      ++last;
    const Contact& head = s.contacts[first];
    if (!wanted(head)) {
      next.insert(next.end(), s.contacts.begin() + static_cast<std::ptrdiff_t>(first),
                  s.contacts.begin() + static_cast<std::ptrdiff_t>(last));
    } else if (group_has_sub_shapes(s, head)) {
      collide_group(s, first, last, next, scratch);
    } else {
      next.push_back(head);
      collide_one(s, next.back(), head.index_a, head.index_b);
    }
    first = last;
  }
  s.contacts = std::move(next);
}

struct UnionFind {
  std::vector<std::uint32_t> parent;
  explicit UnionFind(std::size_t n) : parent(n) {
    std::iota(parent.begin(), parent.end(), std::uint32_t{0});
  }
  std::uint32_t root(std::uint32_t i) {
    while (parent[i] != i) {
      parent[i] = parent[parent[i]];  // path halving
      i = parent[i];
    }
    return i;
  }
  void join(std::uint32_t i, std::uint32_t j) {
    const std::uint32_t ri = root(i);
    const std::uint32_t rj = root(j);
    if (ri < rj) parent[rj] = ri;  // the lower index becomes the root: order-independent result
    if (rj < ri) parent[ri] = rj;
  }
};

// Islands of dynamic bodies joined by touching, non-sensor contacts.
UnionFind islands(const WorldState& s) {
  UnionFind uf(s.bodies.size());
  for (const Contact& c : s.contacts) {
    if (!c.touching) continue;
    const std::size_t ia = c.index_a;
    const std::size_t ib = c.index_b;
    const BodyState& a = s.bodies[ia];
    const BodyState& b = s.bodies[ib];
    if (a.type == BodyType::dynamic && b.type == BodyType::dynamic && !a.sensor && !b.sensor)
      uf.join(static_cast<std::uint32_t>(ia), static_cast<std::uint32_t>(ib));
  }
  // So are two bodies that a rope holds together (its tether).
  for (const ParticleGroup& g : s.particle_groups) {
    if (g.type != ParticleGroupType::rope || g.attachments.size() != 2) continue;
    const auto ia = static_cast<std::size_t>(s.find(g.attachments[0].body));
    const auto ib = static_cast<std::size_t>(s.find(g.attachments[1].body));
    if (s.bodies[ia].type == BodyType::dynamic && s.bodies[ib].type == BodyType::dynamic)
      uf.join(static_cast<std::uint32_t>(ia), static_cast<std::uint32_t>(ib));
  }
  // Joined bodies are one island: they sleep and wake together.
  for (std::size_t ji = 0; ji < s.joints.size(); ++ji) {
    if (s.joints[ji].broken) continue;
    const std::size_t ia = s.joint_bodies[ji][0];
    const std::size_t ib = s.joint_bodies[ji][1];
    if (s.bodies[ia].type == BodyType::dynamic && s.bodies[ib].type == BodyType::dynamic)
      uf.join(static_cast<std::uint32_t>(ia), static_cast<std::uint32_t>(ib));
  }
  return uf;
}

// `f(ia, ib)` for the body indices of every unbroken joint, in joint order.
template <class F>
void each_joint(const WorldState& s, F&& f) {
  for (std::size_t ji = 0; ji < s.joints.size(); ++ji) {
    if (!s.joints[ji].broken)
      f(std::size_t{s.joint_bodies[ji][0]}, std::size_t{s.joint_bodies[ji][1]});
  }
}

}  // namespace

// A pair where nothing moves keeps its manifold and impulses as they were.
void collide_contacts(WorldState& s) {
  narrowphase(s, false);
}

void wake_touched_islands(WorldState& s) {
  // Only a moving body wakes anything: a scene at rest builds no islands.
  if (std::none_of(s.bodies.begin(), s.bodies.end(), moving)) return;
  UnionFind uf = islands(s);
  std::vector<bool> wake(s.bodies.size(), false);
  for (std::size_t i = 0; i < s.bodies.size(); ++i) {
    if (moving(s.bodies[i])) wake[uf.root(static_cast<std::uint32_t>(i))] = true;
  }
  // A moving kinematic body is in no island but wakes what it touches.
  for (const Contact& c : s.contacts) {
    if (!c.touching) continue;
    const std::size_t ia = c.index_a;
    const std::size_t ib = c.index_b;
    if (moving(s.bodies[ia]) && s.bodies[ib].type == BodyType::dynamic)
      wake[uf.root(static_cast<std::uint32_t>(ib))] = true;
    if (moving(s.bodies[ib]) && s.bodies[ia].type == BodyType::dynamic)
      wake[uf.root(static_cast<std::uint32_t>(ia))] = true;
  }
  // So does one joined to a dynamic body.
  each_joint(s, [&](std::size_t ia, std::size_t ib) {
    if (moving(s.bodies[ia]) && s.bodies[ib].type == BodyType::dynamic)
      wake[uf.root(static_cast<std::uint32_t>(ib))] = true;
    if (moving(s.bodies[ib]) && s.bodies[ia].type == BodyType::dynamic)
      wake[uf.root(static_cast<std::uint32_t>(ia))] = true;
  });
  bool woke_any = false;
  for (std::size_t i = 0; i < s.bodies.size(); ++i) {
    BodyState& b = s.bodies[i];
    if (b.type == BodyType::dynamic && !b.awake && wake[uf.root(static_cast<std::uint32_t>(i))]) {
      b.awake = true;
      b.sleep_time = Fixed::zero();
      prepare_body(s, i);  // the derived data the solver will use for it (no other body changed)
      woke_any = true;
    }
  }
  if (!woke_any) return;
  // The pairs of bodies that just woke were skipped by collide_contacts: collide them now, with
  // every other pair it skipped. The pairs it collided would come out the same again (same poses
  // and speeds, and matching the cache by feature twice is matching it once).
  narrowphase(s, true);
}

void wake_islands(WorldState& s, const std::vector<std::size_t>& bodies) {
  bool asleep = false;
  for (const std::size_t i : bodies)
    asleep = asleep || (s.bodies[i].type == BodyType::dynamic && !s.bodies[i].awake);
  if (!asleep) return;  // the common case: no island to find
  UnionFind uf = islands(s);
  std::vector<bool> wake(s.bodies.size(), false);
  for (const std::size_t i : bodies)
    wake[uf.root(static_cast<std::uint32_t>(i))] = true;
  for (std::size_t i = 0; i < s.bodies.size(); ++i) {
    BodyState& b = s.bodies[i];
    if (b.type == BodyType::dynamic && wake[uf.root(static_cast<std::uint32_t>(i))]) {
      b.awake = true;
      b.sleep_time = Fixed::zero();
    }
  }
}

void report_end(WorldState& s, const Contact& c) {
  if (!c.reported) return;
  const BodyState& a = s.bodies[index_of(s, c.a)];
  const BodyState& b = s.bodies[index_of(s, c.b)];
  s.events.push_back({ContactEvent::Kind::end, BodyId{c.a}, BodyId{c.b}, a.sensor || b.sensor});
}

void report_contacts(WorldState& s) {
  // One event per body pair: its group of contacts (one per pair of sub-shapes) is in touch when
  // any of them is, and all of them carry the pair's flag.
  for (std::size_t first = 0; first < s.contacts.size();) {
    std::size_t last = first + 1;
    while (last < s.contacts.size() && s.contacts[last].a == s.contacts[first].a &&
           s.contacts[last].b == s.contacts[first].b)
      ++last;
    const std::size_t group_first = first;
    first = last;
    Contact& head = s.contacts[group_first];
    if (!head.collided) continue;  // neither body moved: the pair is as it was
    const BodyState& a = s.bodies[head.index_a];
    const BodyState& b = s.bodies[head.index_b];
    // A solid pair is in touch when a point began the step within the speculative distance, or
    // when the solver pushed on it (a fast body that met the surface and bounced within the step
    // never shows a small gap at a step's boundary). The contact margin also holds points that a
    // body would reach only in later steps: those alone are not a touch. A sensor pair is in touch
    // while the shapes overlap.
    const bool sensor = a.sensor || b.sensor;
    const Fixed reach = sensor ? Fixed::zero() : s.def.speculative_distance;
    bool touch = false;
    for (std::size_t i = group_first; i < last; ++i) {
      Contact& c = s.contacts[i];
      c.collided = false;
      touch = touch || (!sensor && c.pushed);
      for (std::size_t k = 0; k < c.manifold.count; ++k)
        touch = touch || c.manifold.points[k].separation <= reach;
    }
    if (touch == head.reported) continue;
    for (std::size_t i = group_first; i < last; ++i)
      s.contacts[i].reported = touch;
    s.events.push_back({touch ? ContactEvent::Kind::begin : ContactEvent::Kind::end, BodyId{head.a},
                        BodyId{head.b}, sensor});
  }
  // Ends of vanished pairs were found first, by the broadphase; the order reported is by pair. A
  // pair changes at most once per step, so the order is total.
  std::sort(s.events.begin(), s.events.end(), [](const ContactEvent& x, const ContactEvent& y) {
    if (x.a != y.a) return x.a < y.a;
    if (x.b != y.b) return x.b < y.b;
    return x.kind < y.kind;
  });
}

void update_sleep(WorldState& s) {
  const Fixed lin2 = s.def.sleep_linear_speed * s.def.sleep_linear_speed;
  const Fixed ang2 = s.def.sleep_angular_speed * s.def.sleep_angular_speed;
  // A body that overlap recovery is still moving apart is not at rest, whatever its velocity.
  const Fixed pushed_limit = s.def.sleep_linear_speed * s.def.dt;
  const Fixed pushed2 = pushed_limit * pushed_limit;
  for (std::size_t i = 0; i < s.bodies.size(); ++i) {
    BodyState& b = s.bodies[i];
    if (b.type != BodyType::dynamic || !b.awake) continue;
    const bool slow = length_squared(b.linear_velocity) <= lin2 &&
                      length_squared(b.angular_velocity) <= ang2 &&
                      length_squared(s.derived[i].pushed_out) <= pushed2;
    b.sleep_time = slow ? min(b.sleep_time + s.def.dt, Fixed::from_int(1000)) : Fixed::zero();
  }
  if (!s.def.enable_sleep) return;
  // Only an awake dynamic body falls asleep: a scene at rest builds no islands.
  if (std::none_of(s.bodies.begin(), s.bodies.end(),
                   [](const BodyState& b) { return b.type == BodyType::dynamic && b.awake; }))
    return;
  UnionFind uf = islands(s);
  // An island sleeps when every body in it has been slow long enough and nothing moving that is
  // outside the island (a kinematic body) touches it.
  std::vector<bool> keep_awake(s.bodies.size(), false);
  const std::vector<bool> held = bodies_held_by_particles(s);
  for (std::size_t i = 0; i < s.bodies.size(); ++i) {
    const BodyState& b = s.bodies[i];
    if (b.type == BodyType::dynamic && b.awake && (b.sleep_time < s.def.time_to_sleep || held[i]))
      keep_awake[uf.root(static_cast<std::uint32_t>(i))] = true;
  }
  for (const Contact& c : s.contacts) {
    if (!c.touching) continue;
    const std::size_t ia = c.index_a;
    const std::size_t ib = c.index_b;
    if (s.bodies[ia].type == BodyType::kinematic && moving(s.bodies[ia]))
      keep_awake[uf.root(static_cast<std::uint32_t>(ib))] = true;
    if (s.bodies[ib].type == BodyType::kinematic && moving(s.bodies[ib]))
      keep_awake[uf.root(static_cast<std::uint32_t>(ia))] = true;
  }
  each_joint(s, [&](std::size_t ia, std::size_t ib) {
    if (s.bodies[ia].type == BodyType::kinematic && moving(s.bodies[ia]))
      keep_awake[uf.root(static_cast<std::uint32_t>(ib))] = true;
    if (s.bodies[ib].type == BodyType::kinematic && moving(s.bodies[ib]))
      keep_awake[uf.root(static_cast<std::uint32_t>(ia))] = true;
  });
  for (std::size_t i = 0; i < s.bodies.size(); ++i) {
    BodyState& b = s.bodies[i];
    if (b.type != BodyType::dynamic || !b.awake) continue;
    if (keep_awake[uf.root(static_cast<std::uint32_t>(i))]) continue;
    b.awake = false;
    b.linear_velocity = {};
    b.angular_velocity = {};
  }
}

}  // namespace detsim::sim_detail
