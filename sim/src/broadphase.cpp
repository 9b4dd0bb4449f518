// Broadphase: sort and sweep along x, then the contact list is merged with the new pair list.
// While most of a scene is at rest, only the bodies whose box (or anything else the broadphase
// reads) changed since the last step are tested, against every body, and the other pairs are the
// last step's (WorldState::broadphase_pairs): the same pairs, found in time proportional to what
// moved.
//
// Determinism: the sweep order is a total order (min x, then ID), so any correct sort gives the
// same sequence; pairs are emitted as (lower ID, higher ID) and sorted the same way; the merge with
// the previous step's contacts walks both sorted lists once. Nothing depends on addresses.
#include <algorithm>
#include <cstdint>
#include <vector>

#include <detsim/fixed/math.hpp>

#include "shapes.hpp"
#include "world_state.hpp"

namespace detsim::sim_detail {

namespace {

// A body's bounding box, copied out of Derived so that the sweep's inner loop reads a compact
// array instead of the whole derived record of every active body.
struct SweepItem {
  Vec3 min;
  Vec3 max;
  std::uint32_t index;  // into bodies; bodies are ID-sorted, so index order is ID order
};

bool layers_match(const BodyState& a, const BodyState& b) {
  return (a.layer & b.mask) != 0 && (b.layer & a.mask) != 0;
}

// Whether a pair can ever produce a contact response or event. Two bodies that cannot move never
// interact; everything else is kept, sleeping bodies included (their cached impulses must survive).
bool may_interact(const BodyState& a, const BodyState& b) {
  if (a.type != BodyType::dynamic && b.type != BodyType::dynamic && !a.sensor && !b.sensor)
    return false;
  return layers_match(a, b);
}

bool overlap_yz(const SweepItem& a, const SweepItem& b) {
  return a.min.y <= b.max.y && b.min.y <= a.max.y && a.min.z <= b.max.z && b.min.z <= a.max.z;
}

// Whether the box [lo, hi] reaches the half-space below the plane through `p` with unit normal n.
bool below_plane(const SweepItem& box, Vec3 p, Vec3 n) {
  const auto halve = [](Vec3 v) { return Vec3{v.x >> 1, v.y >> 1, v.z >> 1}; };
  const Vec3 c = halve(box.min + box.max);
  const Vec3 e = halve(box.max - box.min);
  const Fixed radius = abs(n.x) * e.x + abs(n.y) * e.y + abs(n.z) * e.z;
  return dot(c - p, n) <= radius;
}

// Sweep order: min x, then index (a total order, so every correct sort gives the same sequence).
bool sweeps_before(const SweepItem& a, const SweepItem& b) {
  return a.min.x != b.min.x ? a.min.x < b.min.x : a.index < b.index;
}

// Insertion sort that gives up (leaving a permutation of the input) after `budget` moves: linear
// on the nearly sorted input a moving scene gives from one step to the next.
bool insertion_sort(std::vector<SweepItem>& v, std::size_t budget) {
  for (std::size_t i = 1; i < v.size(); ++i) {
    const SweepItem x = v[i];
    std::size_t j = i;
    for (; j > 0 && sweeps_before(x, v[j - 1]); --j) {
      if (budget-- == 0) {
        v[j] = x;
        return false;
      }
      v[j] = v[j - 1];
    }
    v[j] = x;
  }
  return true;
}

// The bounded bodies' boxes in sweep order; the planes' indices go to `planes`. The sort starts
// from the last step's order (WorldState::sweep_order) when that is still a permutation of the
// bounded bodies.
std::vector<SweepItem> sorted_sweep_items(WorldState& s, std::vector<std::uint32_t>& planes) {
  const std::size_t n = s.bodies.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (s.derived[i].infinite) planes.push_back(static_cast<std::uint32_t>(i));
  }
  const auto item = [&s](std::uint32_t i) {
    return SweepItem{s.derived[i].aabb_min, s.derived[i].aabb_max, i};
  };
  std::vector<SweepItem> items;
  items.reserve(n - planes.size());
  bool hinted = s.sweep_order.size() == n - planes.size();
  std::vector<bool> seen(hinted ? n : 0, false);
  for (std::size_t k = 0; hinted && k < s.sweep_order.size(); ++k) {
    const std::uint32_t i = s.sweep_order[k];
    hinted = i < n && !s.derived[i].infinite && !seen[i];
    if (hinted) seen[i] = true;
  }
  if (hinted) {
    for (const std::uint32_t i : s.sweep_order)
      items.push_back(item(i));
  } else {
    for (std::size_t i = 0; i < n; ++i) {
      if (!s.derived[i].infinite) items.push_back(item(static_cast<std::uint32_t>(i)));
    }
  }
  if (!hinted || !insertion_sort(items, 4 * items.size()))
    std::sort(items.begin(), items.end(), sweeps_before);
  s.sweep_order.clear();
  for (const SweepItem& it : items)
    s.sweep_order.push_back(it.index);
  return items;
}

// The new contact list: the contacts whose pair persists (with their cached impulses) and new ones
// for the new pairs; the pairs that ended report their end.
// The body pairs are the groups of the contact list (a body pair holds one contact per pair of
// sub-shapes in touch, world_state.hpp): a pair that stays keeps all of its contacts, a new pair
// gets one contact of sub-shapes (0, 0), and a pair whose boxes parted loses them all (one end
// event for the group).
void merge_contacts(WorldState& s, const std::vector<std::uint64_t>& pairs) {
  const auto index_a = [](std::uint64_t pair) { return static_cast<std::uint32_t>(pair >> 32); };
  const auto index_b = [](std::uint64_t pair) {
    return static_cast<std::uint32_t>(pair & 0xFFFFFFFFU);
  };
  const auto same_pair = [](const Contact& x, const Contact& y) {
    return x.a == y.a && x.b == y.b;
  };
  // At rest the pairs are the last step's: only the indices need refreshing.
  bool same = true;
  std::size_t k = 0;
  for (std::size_t c = 0; same && c < s.contacts.size(); ++c) {
    if (c > 0 && same_pair(s.contacts[c], s.contacts[c - 1])) continue;
    same = k < pairs.size() && s.contacts[c].a == s.bodies[index_a(pairs[k])].id.value &&
           s.contacts[c].b == s.bodies[index_b(pairs[k])].id.value;
    ++k;
  }
  if (same && k == pairs.size()) {
    k = 0;
    for (std::size_t c = 0; c < s.contacts.size(); ++c) {
      if (c > 0 && !same_pair(s.contacts[c], s.contacts[c - 1])) ++k;
      s.contacts[c].index_a = index_a(pairs[k]);
      s.contacts[c].index_b = index_b(pairs[k]);
    }
    return;
  }
  std::vector<Contact> merged;
  merged.reserve(pairs.size());
  std::size_t old = 0;
  const auto end_group = [&] {  // the group at `old` parted: its end event once, then skip it
    report_end(s, s.contacts[old]);
    const Contact& first = s.contacts[old];
    while (old < s.contacts.size() && same_pair(s.contacts[old], first))
      ++old;
  };
  for (const std::uint64_t pair : pairs) {
    const std::uint32_t a = s.bodies[index_a(pair)].id.value;
    const std::uint32_t b = s.bodies[index_b(pair)].id.value;
    while (old < s.contacts.size() &&
           (s.contacts[old].a < a || (s.contacts[old].a == a && s.contacts[old].b < b)))
      end_group();  // a pair whose boxes parted
    if (old < s.contacts.size() && s.contacts[old].a == a && s.contacts[old].b == b) {
      while (old < s.contacts.size() && s.contacts[old].a == a && s.contacts[old].b == b) {
        merged.push_back(s.contacts[old++]);
        merged.back().index_a = index_a(pair);
        merged.back().index_b = index_b(pair);
      }
    } else {
      Contact c;
      c.a = a;
      c.b = b;
      c.index_a = index_a(pair);
      c.index_b = index_b(pair);
      merged.push_back(c);
    }
  }
  while (old < s.contacts.size())
    end_group();
  s.contacts = std::move(merged);
}

// The pair budget (pair_budget, world_def.hpp): bodies spawned into one another (a level loaded
// with overlapping props, a burst of spawns at one point) make a pair of every two of them,
// n^2 / 2 in all, and each pair a manifold and a constraint: 500 boxes at one point took about a
// second per step. So a dynamic body takes part in at most pair_budget pairs with other dynamic
// bodies of comparable size (a bounding radius at least half its own), in ascending pair order;
// further pairs wait for a later step, by which time push-out has moved the first ones apart. No
// ordinary scene comes near it (a box in a dense heap has at most 26 neighbours whose boxes
// overlap its own), and a large body carrying many small ones (a deck with crates) does not
// count them.
void keep_within_budget(const WorldState& s, std::vector<std::uint64_t>& pairs) {
  // Most steps: no body has that many pairs at all, and nothing is left out.
  std::vector<std::uint32_t> used(s.bodies.size(), 0);
  bool over = false;
  for (const std::uint64_t pair : pairs) {
    const auto i = static_cast<std::uint32_t>(pair >> 32);
    const auto j = static_cast<std::uint32_t>(pair & 0xFFFFFFFFU);
    if (s.bodies[i].type != BodyType::dynamic || s.bodies[j].type != BodyType::dynamic) continue;
    over = over || ++used[i] > pair_budget || ++used[j] > pair_budget;
  }
  if (!over) return;
  used.clear();
  std::vector<Fixed> radius;
  std::size_t kept = 0;
  for (const std::uint64_t pair : pairs) {
    const auto i = static_cast<std::uint32_t>(pair >> 32);
    const auto j = static_cast<std::uint32_t>(pair & 0xFFFFFFFFU);
    if (s.bodies[i].type == BodyType::dynamic && s.bodies[j].type == BodyType::dynamic) {
      if (used.empty()) {
        used.assign(s.bodies.size(), 0);
        radius.resize(s.bodies.size());
        for (std::size_t b = 0; b < s.bodies.size(); ++b)
          radius[b] = bounding_radius(s.bodies[b].shape, s.geometry(s.bodies[b].shape));
      }
      // Each counts the other if the other is at least half its size.
      const bool i_counts = (radius[j] << 1) >= radius[i];
      const bool j_counts = (radius[i] << 1) >= radius[j];
      if ((i_counts && used[i] == pair_budget) || (j_counts && used[j] == pair_budget)) continue;
      used[i] += i_counts ? 1 : 0;
      used[j] += j_counts ? 1 : 0;
    }
    pairs[kept++] = pair;
  }
  pairs.resize(kept);
}

// Every overlapping pair of bodies that may interact, by a sort and sweep along x.
std::vector<std::uint64_t> sweep_pairs(WorldState& s) {
  std::vector<std::uint32_t> planes;
  const std::vector<SweepItem> items = sorted_sweep_items(s, planes);

  // Pairs as (lower index, higher index) packed into 64 bits: sorting them sorts by ID pair.
  std::vector<std::uint64_t> pairs;
  const auto add_pair = [&](std::uint32_t i, std::uint32_t j) {
    const BodyState& a = s.bodies[i];
    const BodyState& b = s.bodies[j];
    if (!may_interact(a, b)) return;
    const std::uint32_t lo = std::min(i, j);
    const std::uint32_t hi = std::max(i, j);
    pairs.push_back((std::uint64_t{lo} << 32) | hi);
  };
  std::vector<SweepItem> active;
  for (const SweepItem& item : items) {
    std::erase_if(active, [&](const SweepItem& other) { return other.max.x < item.min.x; });
    for (const SweepItem& other : active) {
      if (overlap_yz(item, other)) add_pair(item.index, other.index);
    }
    active.push_back(item);
  }
  for (const std::uint32_t p : planes) {
    const Vec3 normal = s.derived[p].pose.rotation.column(1);
    for (const SweepItem& item : items) {
      if (below_plane(item, s.bodies[p].position, normal)) add_pair(p, item.index);
    }
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

// What the broadphase reads of body i.
WorldState::BroadphaseEntry broadphase_entry(const WorldState& s, std::size_t i) {
  const BodyState& b = s.bodies[i];
  const Derived& d = s.derived[i];
  WorldState::BroadphaseEntry e;
  e.infinite = d.infinite;
  e.min = d.infinite ? b.position : d.aabb_min;
  e.max = d.infinite ? d.pose.rotation.column(1) : d.aabb_max;
  e.id = b.id.value;
  e.layer = b.layer;
  e.mask = b.mask;
  e.type = b.type;
  e.sensor = b.sensor;
  return e;
}

// The pairs sweep_pairs would find, from the last step's: a pair of two bodies whose entries are
// unchanged is kept as it was (it overlapped then, so it does now), and every body whose entry
// changed is tested against every other body as the sweep tests them (boxes overlapping on every
// axis, ends included; a plane against a box below it). The same set, in the same order.
std::vector<std::uint64_t> update_pairs(const WorldState& s, const std::vector<bool>& changed,
                                        const std::vector<std::uint32_t>& moved) {
  std::vector<std::uint64_t> pairs;
  pairs.reserve(s.broadphase_pairs.size() + moved.size() * 8);
  for (const std::uint64_t pair : s.broadphase_pairs) {
    const auto a = static_cast<std::uint32_t>(pair >> 32);
    const auto b = static_cast<std::uint32_t>(pair & 0xFFFFFFFFU);
    if (!changed[a] && !changed[b]) pairs.push_back(pair);
  }
  const auto item = [&s](std::size_t i) {
    return SweepItem{s.derived[i].aabb_min, s.derived[i].aabb_max, static_cast<std::uint32_t>(i)};
  };
  for (const std::uint32_t i : moved) {
    for (std::uint32_t j = 0; j < s.bodies.size(); ++j) {
      if (j == i || (changed[j] && j < i)) continue;  // a pair of two changed ones: once
      const Derived& di = s.derived[i];
      const Derived& dj = s.derived[j];
      if (di.infinite && dj.infinite) continue;
      bool touch = false;
      if (di.infinite || dj.infinite) {
        const std::uint32_t plane = di.infinite ? i : j;
        touch = below_plane(item(di.infinite ? j : i), s.bodies[plane].position,
                            s.derived[plane].pose.rotation.column(1));
      } else {
        const SweepItem a = item(i);
        const SweepItem b = item(j);
        touch = a.min.x <= b.max.x && b.min.x <= a.max.x && overlap_yz(a, b);
      }
      if (!touch || !may_interact(s.bodies[i], s.bodies[j])) continue;
      pairs.push_back((std::uint64_t{std::min(i, j)} << 32) | std::max(i, j));
    }
  }
  // The kept pairs are in order already (a subset of a sorted list); only added ones need a sort.
  if (!moved.empty()) std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace

void update_contacts(WorldState& s) {
  // The bodies whose broadphase entry changed since the last step (all of them after a restore,
  // or when bodies came or went): few, while most of a scene sleeps.
  const std::size_t n = s.bodies.size();
  const bool cached = s.broadphase_entries.size() == n;
  std::vector<bool> changed(n, !cached);
  std::vector<std::uint32_t> moved;
  if (!cached) {
    s.broadphase_entries.clear();
    s.broadphase_entries.reserve(n);
  }
  for (std::size_t i = 0; i < n; ++i) {
    const WorldState::BroadphaseEntry e = broadphase_entry(s, i);
    if (cached && s.broadphase_entries[i] == e) continue;
    changed[i] = true;
    moved.push_back(static_cast<std::uint32_t>(i));
    if (cached) {
      s.broadphase_entries[i] = e;
    } else {
      s.broadphase_entries.push_back(e);
    }
  }
  // Testing m changed bodies against all n costs m n; the sweep about n times its active list.
  std::vector<std::uint64_t> pairs =
      cached && moved.size() * 16 <= n ? update_pairs(s, changed, moved) : sweep_pairs(s);
  s.broadphase_pairs = pairs;
  // Bodies joined without collide_connected never collide (nor use up each other's budget).
  if (!s.joints.empty()) {
    const std::vector<std::uint64_t> joined = joined_pairs(s);
    if (!joined.empty()) {
      std::erase_if(pairs, [&](std::uint64_t pair) {
        return std::binary_search(joined.begin(), joined.end(), pair);
      });
    }
  }
  keep_within_budget(s, pairs);
  merge_contacts(s, pairs);
}

}  // namespace detsim::sim_detail
