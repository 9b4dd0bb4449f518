// Broadphase: sort and sweep along x, then the contact list is merged with the new pair list.
//
// Determinism: the sweep order is a total order (min x, then ID), so any correct sort gives the
// same sequence; pairs are emitted as (lower ID, higher ID) and sorted the same way; the merge with
// the previous step's contacts walks both sorted lists once. Nothing depends on addresses.
#include <algorithm>
#include <cstdint>
#include <vector>

#include <detsim/fixed/math.hpp>

#include "world_state.hpp"

namespace detsim::sim_detail {

namespace {

struct SweepItem {
  Fixed min_x;
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

bool overlap_yz(const Derived& a, const Derived& b) {
  return a.aabb_min.y <= b.aabb_max.y && b.aabb_min.y <= a.aabb_max.y &&
         a.aabb_min.z <= b.aabb_max.z && b.aabb_min.z <= a.aabb_max.z;
}

// Whether the box [lo, hi] reaches the half-space below the plane through `p` with unit normal n.
bool below_plane(const Derived& box, Vec3 p, Vec3 n) {
  const auto halve = [](Vec3 v) { return Vec3{v.x >> 1, v.y >> 1, v.z >> 1}; };
  const Vec3 c = halve(box.aabb_min + box.aabb_max);
  const Vec3 e = halve(box.aabb_max - box.aabb_min);
  const Fixed radius = abs(n.x) * e.x + abs(n.y) * e.y + abs(n.z) * e.z;
  return dot(c - p, n) <= radius;
}

}  // namespace

void update_contacts(WorldState& s) {
  const std::size_t n = s.bodies.size();
  std::vector<SweepItem> items;
  items.reserve(n);
  std::vector<std::uint32_t> planes;
  for (std::size_t i = 0; i < n; ++i) {
    if (s.derived[i].infinite) {
      planes.push_back(static_cast<std::uint32_t>(i));
    } else {
      items.push_back({s.derived[i].aabb_min.x, static_cast<std::uint32_t>(i)});
    }
  }
  std::sort(items.begin(), items.end(), [](const SweepItem& a, const SweepItem& b) {
    return a.min_x != b.min_x ? a.min_x < b.min_x : a.index < b.index;
  });

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
  std::vector<std::uint32_t> active;
  for (const SweepItem& item : items) {
    const Derived& d = s.derived[item.index];
    std::erase_if(active, [&](std::uint32_t j) { return s.derived[j].aabb_max.x < item.min_x; });
    for (const std::uint32_t j : active) {
      if (overlap_yz(d, s.derived[j])) add_pair(item.index, j);
    }
    active.push_back(item.index);
  }
  for (const std::uint32_t p : planes) {
    const Vec3 normal = s.derived[p].pose.rotation.column(1);
    for (const SweepItem& item : items) {
      if (below_plane(s.derived[item.index], s.bodies[p].position, normal)) add_pair(p, item.index);
    }
  }
  std::sort(pairs.begin(), pairs.end());

  // Merge: keep the contacts whose pair persists (with their cached impulses), add new ones.
  std::vector<Contact> merged;
  merged.reserve(pairs.size());
  std::size_t old = 0;
  for (const std::uint64_t pair : pairs) {
    const std::uint32_t a = s.bodies[static_cast<std::size_t>(pair >> 32)].id.value;
    const std::uint32_t b = s.bodies[static_cast<std::size_t>(pair & 0xFFFFFFFFU)].id.value;
    while (old < s.contacts.size() &&
           (s.contacts[old].a < a || (s.contacts[old].a == a && s.contacts[old].b < b)))
      report_end(s, s.contacts[old++]);  // a pair whose boxes parted
    if (old < s.contacts.size() && s.contacts[old].a == a && s.contacts[old].b == b) {
      merged.push_back(s.contacts[old++]);
    } else {
      Contact c;
      c.a = a;
      c.b = b;
      merged.push_back(c);
    }
  }
  for (; old < s.contacts.size(); ++old)
    report_end(s, s.contacts[old]);
  s.contacts = std::move(merged);
}

}  // namespace detsim::sim_detail
