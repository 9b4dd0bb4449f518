// Continuous collision's candidate pairs (ccd_pairs.hpp).
//
// Determinism: the axis is chosen by fixed-point arithmetic on the boxes alone; the sort order
// (min on that axis, then index) is total, so every correct sort gives the same sequence; the
// pairs are sorted before they are returned. Nothing depends on addresses.
#include "ccd_pairs.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include <detsim/fixed/math.hpp>

namespace detsim::sim_detail {

namespace {

bool starts_before(const SweptBox& a, const SweptBox& b) {
  return a.min.x != b.min.x ? a.min.x < b.min.x : a.index < b.index;
}

bool swept_boxes_overlap_yz(const SweptBox& a, const SweptBox& b) {
  return a.min.y <= b.max.y && b.min.y <= a.max.y && a.min.z <= b.max.z && b.min.z <= a.max.z;
}

// The axis along which the box centres spread the most (0 x, 1 y, 2 z; ties to the lower), by
// their mean absolute deviation: sorting along it leaves the fewest boxes overlapping on it. A row
// of ragdolls along z, all at about the same x, would otherwise have every body overlap every
// other on x. Only the cost depends on the axis, never the pairs.
int widest_axis(const std::vector<SweptBox>& boxes) {
  if (boxes.empty()) return 0;
  const Fixed n =
      Fixed::from_int(static_cast<std::int32_t>(std::min<std::size_t>(boxes.size(), 1U << 30)));
  const auto centre = [](const SweptBox& b) {
    return Vec3{(b.min.x + b.max.x) >> 1, (b.min.y + b.max.y) >> 1, (b.min.z + b.max.z) >> 1};
  };
  Vec3 mean;
  for (const SweptBox& b : boxes)
    mean += centre(b) / n;
  Vec3 spread;
  for (const SweptBox& b : boxes) {
    const Vec3 d = centre(b) - mean;
    spread += Vec3{abs(d.x), abs(d.y), abs(d.z)} / n;
  }
  if (spread.z > spread.x && spread.z > spread.y) return 2;
  return spread.y > spread.x ? 1 : 0;
}

// The box with its coordinates on `axis` and on x swapped: the sweep then runs along x.
void swap_axis(SweptBox& b, int axis) {
  if (axis == 1) {
    std::swap(b.min.x, b.min.y);
    std::swap(b.max.x, b.max.y);
  } else if (axis == 2) {
    std::swap(b.min.x, b.min.z);
    std::swap(b.max.x, b.max.z);
  }
}

std::uint64_t pack(std::uint32_t swept, std::uint32_t other) {
  return (std::uint64_t{swept} << 32) | other;
}

}  // namespace

std::vector<std::uint64_t> swept_box_pairs(std::vector<SweptBox> boxes) {
  std::vector<std::uint64_t> pairs;
  if (std::none_of(boxes.begin(), boxes.end(), [](const SweptBox& b) { return b.swept; }))
    return pairs;
  // Overlap is the same test on every axis, so sweeping along the widest one by swapping it with
  // x in every box finds the same pairs.
  const int axis = widest_axis(boxes);
  for (SweptBox& b : boxes)
    swap_axis(b, axis);
  std::sort(boxes.begin(), boxes.end(), starts_before);
  std::vector<std::size_t> swept;  // positions of the swept boxes in sweep order, ascending
  for (std::size_t p = 0; p < boxes.size(); ++p) {
    if (boxes[p].swept) swept.push_back(p);
  }
  std::size_t next_swept = 0;  // the first swept box after position p
  for (std::size_t p = 0; p < boxes.size(); ++p) {
    const SweptBox& box = boxes[p];
    while (next_swept < swept.size() && swept[next_swept] <= p)
      ++next_swept;
    // The swept boxes that start within this box's x range, after it.
    for (std::size_t k = next_swept; k < swept.size(); ++k) {
      const SweptBox& later = boxes[swept[k]];
      if (later.min.x > box.max.x) break;
      if (swept_boxes_overlap_yz(box, later)) pairs.push_back(pack(later.index, box.index));
    }
    if (!box.swept) continue;
    // Every box that starts within this swept box's x range, after it.
    for (std::size_t q = p + 1; q < boxes.size(); ++q) {
      const SweptBox& later = boxes[q];
      if (later.min.x > box.max.x) break;
      if (swept_boxes_overlap_yz(box, later)) pairs.push_back(pack(box.index, later.index));
    }
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace detsim::sim_detail
