// Continuous collision's candidate pairs: which bodies a sweep can reach (ccd.cpp uses it).
#pragma once

#include <cstdint>
#include <vector>

#include <detsim/fixed/vec3.hpp>

namespace detsim::sim_detail {

/// The box a body covers during the step: its bounding ball swept from its pose at the start of
/// the step to its pose now. min <= max on every axis.
struct SweptBox {
  Vec3 min;
  Vec3 max;
  std::uint32_t index = 0;  ///< into WorldState::bodies; distinct between the boxes given
  bool swept = false;       ///< a body that continuous collision sweeps this step
};

/// Every ordered pair (a, b) of distinct boxes, a swept and b any, whose boxes overlap (closed:
/// touching counts), as (a.index << 32 | b.index), ascending: exactly the pairs, and in the order,
/// that testing every swept box against every box in index order would give.
///
/// Sort and sweep along one axis, the one along which the boxes' centres spread the most (the
/// pairs are the same along any axis; only the cost differs): the boxes in the order (min on that
/// axis, index), a total order, so the result does not depend on the order given. Two boxes
/// overlap on the axis iff the one later in that order starts within the earlier one's range, so
/// each pair is found from its earlier box by scanning forward while boxes start within its range:
/// all boxes after a swept one, and the swept boxes after any one. The cost is O(n log n) for the
/// sort plus the pairs that overlap on the axis with a swept box; nothing is spent on pairs of
/// boxes neither of which is swept.
[[nodiscard]] std::vector<std::uint64_t> swept_box_pairs(std::vector<SweptBox> boxes);

}  // namespace detsim::sim_detail
