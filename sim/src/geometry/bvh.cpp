// The deterministic BVH build and the ray-box test (bvh.hpp).
//
// The build presorts the items once per axis by (centroid, index) — a total order, so std::sort
// has no ties to leave open — and keeps the three orders in step as it splits: the items of the
// left half, marked, go first in a stable partition of the two other axes' lists. Each level is
// then linear, and the whole build O(n log n), with no floating point and no choice left to the
// standard library.
#include "bvh.hpp"

#include <algorithm>
#include <utility>

#include <detsim/core/assert.hpp>
#include <detsim/fixed/math.hpp>

namespace detsim::sim_detail {

namespace {

Fixed axis_of(Vec3 v, int axis) noexcept {
  return axis == 0 ? v.x : (axis == 1 ? v.y : v.z);
}

class Builder {
 public:
  explicit Builder(std::span<const Bounds> bounds) : bounds_(bounds) {
    const auto n = static_cast<std::uint32_t>(bounds.size());
    centroids_.resize(n);
    for (std::uint32_t i = 0; i < n; ++i)
      centroids_[i] = bounds[i].min + bounds[i].max;  // twice the centroid, exact in range
    for (int axis = 0; axis < 3; ++axis) {
      auto& order = order_[static_cast<std::size_t>(axis)];
      order.resize(n);
      for (std::uint32_t i = 0; i < n; ++i)
        order[i] = i;
      std::sort(order.begin(), order.end(), [this, axis](std::uint32_t a, std::uint32_t b) {
        const Fixed ca = axis_of(centroids_[a], axis);
        const Fixed cb = axis_of(centroids_[b], axis);
        return ca != cb ? ca < cb : a < b;
      });
    }
    left_.assign(n, 0);
    scratch_.resize(n);
    bvh_.nodes.reserve(n == 0 ? 0 : 2 * ((n + bvh_leaf_size - 1) / bvh_leaf_size));
    bvh_.items.reserve(n);
  }

  Bvh build() && {
    if (!bounds_.empty()) node(0, static_cast<std::uint32_t>(bounds_.size()), 0);
    return std::move(bvh_);
  }

 private:
  /// Builds the subtree of order_[*][lo, hi) and returns its node's index.
  std::uint32_t node(std::uint32_t lo, std::uint32_t hi, std::uint32_t depth) {
    DETSIM_ASSERT(depth <= bvh_max_depth);
    bvh_.depth = std::max(bvh_.depth, depth);
    const auto index = static_cast<std::uint32_t>(bvh_.nodes.size());
    bvh_.nodes.push_back({range_bounds(lo, hi), 0, 0});
    if (hi - lo <= bvh_leaf_size) {
      const auto first = static_cast<std::uint32_t>(bvh_.items.size());
      bvh_.items.insert(bvh_.items.end(), order_[0].begin() + lo, order_[0].begin() + hi);
      std::sort(bvh_.items.begin() + first, bvh_.items.end());  // distinct indices: no ties
      bvh_.nodes[index].first = first;
      bvh_.nodes[index].count = hi - lo;
      return index;
    }
    const int axis = split_axis(lo, hi);
    const std::uint32_t mid = lo + (hi - lo) / 2;
    partition(axis, lo, mid, hi);
    node(lo, mid, depth + 1);  // the left child is index + 1
    const std::uint32_t right = node(mid, hi, depth + 1);
    bvh_.nodes[index].first = right;
    return index;
  }

  Bounds range_bounds(std::uint32_t lo, std::uint32_t hi) const noexcept {
    Bounds b = bounds_[order_[0][lo]];
    for (std::uint32_t i = lo + 1; i < hi; ++i) {
      const Bounds& x = bounds_[order_[0][i]];
      b.min = {min(b.min.x, x.min.x), min(b.min.y, x.min.y), min(b.min.z, x.min.z)};
      b.max = {max(b.max.x, x.max.x), max(b.max.y, x.max.y), max(b.max.z, x.max.z)};
    }
    return b;
  }

  /// The axis along which the centroids spread most (ties to the lower axis); each order_ list is
  /// sorted, so the spread is its last entry's centroid minus its first's.
  int split_axis(std::uint32_t lo, std::uint32_t hi) const noexcept {
    int best = 0;
    Fixed best_extent = Fixed::min();
    for (int axis = 0; axis < 3; ++axis) {
      const auto& order = order_[static_cast<std::size_t>(axis)];
      const Fixed extent =
          axis_of(centroids_[order[hi - 1]], axis) - axis_of(centroids_[order[lo]], axis);
      if (extent > best_extent) {
        best = axis;
        best_extent = extent;
      }
    }
    return best;
  }

  /// Makes order_[a][lo, mid) the same items for every axis a: those of the split axis' lower
  /// half, each list keeping its own sorted order (a stable partition).
  void partition(int axis, std::uint32_t lo, std::uint32_t mid, std::uint32_t hi) {
    const auto& split = order_[static_cast<std::size_t>(axis)];
    for (std::uint32_t i = lo; i < hi; ++i)
      left_[split[i]] = i < mid ? 1 : 0;
    for (int other = 0; other < 3; ++other) {
      if (other == axis) continue;
      auto& order = order_[static_cast<std::size_t>(other)];
      std::uint32_t l = lo;
      std::uint32_t r = mid;
      for (std::uint32_t i = lo; i < hi; ++i) {
        const std::uint32_t item = order[i];
        scratch_[left_[item] != 0 ? l++ : r++] = item;
      }
      std::copy(scratch_.begin() + lo, scratch_.begin() + hi, order.begin() + lo);
    }
  }

  std::span<const Bounds> bounds_;
  std::vector<Vec3> centroids_;
  std::array<std::vector<std::uint32_t>, 3> order_;
  std::vector<std::uint8_t> left_;
  std::vector<std::uint32_t> scratch_;
  Bvh bvh_;
};

}  // namespace

Bvh build_bvh(std::span<const Bounds> bounds) {
  return Builder(bounds).build();
}

RayBox::RayBox(Vec3 p, Vec3 v) noexcept : origin_plus_{}, origin_minus_{}, inverse_{}, parallel_{} {
  // Below 2^-31 the ray moves less than 2^16 * 2^-31 = 2^-15 m along the axis over the longest
  // distance that can reach geometry (< 2^16 m with p and the geometry in range): well inside the
  // margin, so such an axis is treated as parallel (and its reciprocal, which would saturate, is
  // not used).
  const Fixed tiny = Fixed::from_raw(2);
  for (int i = 0; i < 3; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const Fixed vi = axis_of(v, i);
    origin_plus_[k] = axis_of(p, i) + box_margin;
    origin_minus_[k] = axis_of(p, i) - box_margin;
    parallel_[k] = abs(vi) <= tiny;
    inverse_[k] = parallel_[k] ? Fixed::zero() : Fixed::one() / vi;
  }
}

}  // namespace detsim::sim_detail
