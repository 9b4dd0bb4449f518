// A bounding volume hierarchy over the triangles of static geometry (mesh.hpp), and the ray-box
// test that every hierarchical query of triangles (the BVH, the heightfield's height pyramid)
// uses. Internal to detsim::sim.
//
// Why our own code rather than a library's BVH: determinism demands that the tree be a function of
// the data only. Library builders (Bullet's quantized BVH, Embree, Jolt's) split with floating
// point SAH costs, sort with unstable sorts or build in parallel, so the same triangles give
// different trees on different compilers, flags or thread counts — and although a tree's shape
// should not change a query's answer, the content hash, the order of overlap results, the
// traversal's cost and any tie left open would. This one splits by the surface area heuristic,
// swept exactly over the items sorted by centroid along each axis (ties by triangle index), with
// costs in exact integers and a median split below a fixed depth; so the same triangles give the
// same nodes, bit for bit, everywhere.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/math.hpp>
#include <detsim/fixed/vec3.hpp>

#include "triangle.hpp"

namespace detsim::sim_detail {

/// The most items in one leaf.
inline constexpr std::uint32_t bvh_leaf_size = 4;
/// The levels split by the surface area heuristic; deeper ones split at the median.
inline constexpr std::uint32_t bvh_sah_levels = 20;
/// The deepest a tree may be: 20 levels of SAH splits, then median splits, which take any 2^20
/// items to leaves within 18 more; the traversal's fixed stack is sized from this.
inline constexpr std::uint32_t bvh_max_depth = 40;

/// One node: its bounds (exact componentwise min and max of its items' bounds), and either two
/// children (count == 0: the left child is the next node, the right child is node `first`) or a
/// leaf's items (count in 1..bvh_leaf_size: Bvh::items[first, first + count)).
struct BvhNode {
  Bounds bounds;
  std::uint32_t first = 0;
  std::uint32_t count = 0;
  friend bool operator==(const BvhNode&, const BvhNode&) = default;
};

/// A flat tree in depth-first order (node 0 is the root); empty for no items.
struct Bvh {
  std::vector<BvhNode> nodes;
  std::vector<std::uint32_t> items;  ///< the leaves' items: indices into the bounds given to build
  std::uint32_t depth = 0;           ///< levels below the root
  friend bool operator==(const Bvh&, const Bvh&) = default;
};

/// The tree over items 0..n-1 with the given bounds (n = bounds.size() <= 2^20, coordinates
/// within +-10^4 m). At each node of more than bvh_leaf_size items, the items are ordered by their
/// centroid (min + max, exact) along each axis, ties by index; the first `sah_levels` (<=
/// bvh_sah_levels) levels split where the surface area heuristic is least (ties to the lower axis,
/// then the earlier split), deeper ones at the middle of the axis along which the centroids spread
/// most.
[[nodiscard]] Bvh build_bvh(std::span<const Bounds> bounds,
                            std::uint32_t sah_levels = bvh_sah_levels);

/// A ray p + v t prepared for box tests: the reciprocal of each component of v. Boxes are tested
/// grown by box_margin, so that no rounding of the triangle tests (a few ulps of the geometry's
/// size, plus t * 2^-32) can put a hit outside the box of its triangle.
class RayBox {
 public:
  static constexpr Fixed box_margin = Fixed::from_raw(Fixed::one_raw >> 12);  // ~0.24 mm

  RayBox(Vec3 p, Vec3 v) noexcept;

  /// The t at which the ray enters `b` (grown by the margin), when it meets it for some t in
  /// [0, max_t]; 0 when p is inside. An underestimate of the true entry, never more. Inline: the
  /// traversals call it twice per node, and it is most of their time.
  [[nodiscard]] std::optional<Fixed> entry(const Bounds& b, Fixed max_t) const noexcept {
    Fixed enter = Fixed::zero();
    Fixed exit = max_t;
    const std::array<Fixed, 3> lo = {b.min.x, b.min.y, b.min.z};
    const std::array<Fixed, 3> hi = {b.max.x, b.max.y, b.max.z};
    for (std::size_t i = 0; i < 3; ++i) {
      // (b.min - margin) - p == b.min - (p + margin), and the same for the upper side.
      const Fixed below = lo[i] - origin_plus_[i];
      const Fixed above = hi[i] - origin_minus_[i];
      if (parallel_[i]) {
        if (below > Fixed::zero() || above < Fixed::zero()) return std::nullopt;
        continue;
      }
      // The reciprocal's relative error (2^-32) and the product's rounding move these by far
      // less than the margin's box_margin / |v_i| >= box_margin in t; saturated products act as
      // infinities of the right sign.
      const Fixed t_below = below * inverse_[i];
      const Fixed t_above = above * inverse_[i];
      const bool backwards = inverse_[i] < Fixed::zero();
      enter = max(enter, backwards ? t_above : t_below);
      exit = min(exit, backwards ? t_below : t_above);
    }
    if (enter > exit) return std::nullopt;
    return enter;
  }

 private:
  std::array<Fixed, 3> origin_plus_;   ///< p + box_margin
  std::array<Fixed, 3> origin_minus_;  ///< p - box_margin
  std::array<Fixed, 3> inverse_;       ///< 1 / v_i, or 0 where parallel
  std::array<bool, 3> parallel_;       ///< |v_i| <= 2^-31: the ray moves < box_margin along i
};

/// Calls test(item) for every item of a leaf the ray p + v t, t in [0, limit], reaches; `limit`
/// may shrink during the traversal (test lowers it to its best hit's t), which prunes every node
/// entered beyond it. Nodes at exactly `limit` are still visited, so a tie at the same t can be
/// resolved by index in `test`. The nearer child is visited first.
template <class Test>
void bvh_raycast(const Bvh& bvh, const RayBox& ray, const Fixed& limit, Test&& test) {
  if (bvh.nodes.empty()) return;
  std::array<std::uint32_t, 2 * bvh_max_depth + 2> stack;
  std::size_t size = 0;
  if (!ray.entry(bvh.nodes[0].bounds, limit)) return;
  stack[size++] = 0;
  while (size > 0) {
    const std::uint32_t index = stack[--size];
    const BvhNode& node = bvh.nodes[index];
    if (node.count > 0) {
      for (std::uint32_t i = node.first; i < node.first + node.count; ++i)
        test(bvh.items[i]);
      continue;
    }
    const std::uint32_t left = index + 1;
    const std::uint32_t right = node.first;
    const auto enter_left = ray.entry(bvh.nodes[left].bounds, limit);
    const auto enter_right = ray.entry(bvh.nodes[right].bounds, limit);
    if (enter_left && enter_right) {
      const bool left_first = *enter_left <= *enter_right;
      stack[size++] = left_first ? right : left;  // the far one waits
      stack[size++] = left_first ? left : right;
    } else if (enter_left) {
      stack[size++] = left;
    } else if (enter_right) {
      stack[size++] = right;
    }
  }
}

/// Calls visit(item) for every item in a leaf whose node bounds overlap the closed box [lo, hi];
/// the caller tests each item's own bounds.
template <class Visit>
void bvh_overlap(const Bvh& bvh, Vec3 lo, Vec3 hi, Visit&& visit) {
  if (bvh.nodes.empty()) return;
  std::array<std::uint32_t, 2 * bvh_max_depth + 2> stack;
  std::size_t size = 0;
  stack[size++] = 0;
  while (size > 0) {
    const std::uint32_t index = stack[--size];
    const BvhNode& node = bvh.nodes[index];
    if (!overlaps(node.bounds, lo, hi)) continue;
    if (node.count > 0) {
      for (std::uint32_t i = node.first; i < node.first + node.count; ++i)
        visit(bvh.items[i]);
      continue;
    }
    stack[size++] = node.first;
    stack[size++] = index + 1;
  }
}

}  // namespace detsim::sim_detail
