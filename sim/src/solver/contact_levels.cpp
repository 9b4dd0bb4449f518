// Shock propagation for contacts (solver/contact_solver.hpp): each body's level, its distance in
// contacts from the bodies no impulse moves, and hold(), which enforces the ends of the contacts'
// soft ranges from the ground up. Its own file: it is a stage apart from the row passes, and
// beside them in one translation unit it changed how GCC inlined the rows' helpers (0.7 % more
// instructions per step on the 1000-box pile, callgrind).
#include <algorithm>
#include <cstdint>
#include <vector>

#include "contact_solver.hpp"

namespace detsim::sim_detail {

namespace {
constexpr std::uint32_t kNoLevel = 0xFFFFFFFFU;
}  // namespace

// Levels by breadth-first search from the bodies no impulse moves, over the step's contact
// constraints, in index order (bodies, then constraints): the same levels on every machine.
void ContactSolver::prepare_levels() {
  hold_order_.clear();
  const std::size_t n = s_.bodies.size();
  levels_.assign(n, kNoLevel);
  // Adjacency in constraint order: for each body, the constraints it is in.
  std::vector<std::uint32_t> start(n + 1, 0);
  for (const ContactConstraint& k : constraints_) {
    ++start[k.bodies.a + 1];
    ++start[k.bodies.b + 1];
  }
  for (std::size_t i = 0; i < n; ++i)
    start[i + 1] += start[i];
  std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
  std::vector<std::uint32_t> adjacent(start[n]);
  for (std::size_t c = 0; c < constraints_.size(); ++c) {
    adjacent[fill[constraints_[c].bodies.a]++] = static_cast<std::uint32_t>(c);
    adjacent[fill[constraints_[c].bodies.b]++] = static_cast<std::uint32_t>(c);
  }
  std::vector<std::uint32_t> queue;
  for (std::size_t i = 0; i < n; ++i) {
    if (start[i] != start[i + 1] && !bodies_.takes_impulse(i)) {
      levels_[i] = 0;
      queue.push_back(static_cast<std::uint32_t>(i));
    }
  }
  for (std::size_t q = 0; q < queue.size(); ++q) {
    const std::uint32_t i = queue[q];
    for (std::uint32_t e = start[i]; e < start[i + 1]; ++e) {
      const ContactConstraint& k = constraints_[adjacent[e]];
      const std::size_t other = k.bodies.a == i ? k.bodies.b : k.bodies.a;
      if (levels_[other] != kNoLevel) continue;
      levels_[other] = levels_[i] + 1;
      queue.push_back(static_cast<std::uint32_t>(other));
    }
  }
  // hold()'s order: by the lower level of the two bodies (a stable counting sort), contact order
  // within a level. Held: pairs whose upper body is heavier than the lower one, where the passes
  // build the impulse up slowly (by the lower body's share per pass), and pairs on a still body,
  // where the other contacts' passes may press the upper body after its own. Pairs of bodies as
  // heavy as each other are stopped within their own passes (a stack of equal boxes).
  const auto held = [&](const ContactConstraint& k) {
    const std::uint32_t la = levels_[k.bodies.a];
    const std::uint32_t lb = levels_[k.bodies.b];
    if (la == lb || la == kNoLevel || lb == kNoLevel) return false;
    if (la == 0 || lb == 0) return true;
    const Fixed ma = s_.bodies[k.bodies.a].mass;
    const Fixed mb = s_.bodies[k.bodies.b].mass;
    return la > lb ? ma > mb : mb > ma;
  };
  std::uint32_t top = 0;
  for (const ContactConstraint& k : constraints_) {
    if (held(k)) top = std::max(top, std::min(levels_[k.bodies.a], levels_[k.bodies.b]));
  }
  std::vector<std::uint32_t> count(top + 2, 0);
  for (const ContactConstraint& k : constraints_) {
    if (held(k)) ++count[std::min(levels_[k.bodies.a], levels_[k.bodies.b]) + 1];
  }
  for (std::size_t l = 0; l + 1 < count.size(); ++l)
    count[l + 1] += count[l];
  hold_order_.resize(count.back());
  for (std::size_t c = 0; c < constraints_.size(); ++c) {
    const ContactConstraint& k = constraints_[c];
    if (held(k))
      hold_order_[count[std::min(levels_[k.bodies.a], levels_[k.bodies.b])]++] =
          static_cast<std::uint32_t>(c);
  }
}

// Shock propagation (Guendelman, Bridson and Fedkiw 2003), for the ends of the contacts' soft
// ranges only: from the ground up, a point closing faster than what stops it at the end of its
// range within the sub-step is stopped there by an
// impulse on the upper body alone, the lower one held still: a heavy body on a light one needs
// about M / m ordinary passes to build its impulse up, and in that time drove the light one deep
// into the ground. The impulse only takes away approach speed (it is not added to the point's
// accumulated impulse, which booked as a load in the warm start threw the pair into the air).
// Points within their allowance are left alone: resting contacts of ordinary scenes are not
// touched.
void ContactSolver::hold() {
  const Fixed depth = s_.def.speculative_distance;
  for (const std::uint32_t c : hold_order_) {
    ContactConstraint& k = constraints_[c];
    const bool a_upper = levels_[k.bodies.a] > levels_[k.bodies.b];
    for (std::size_t p = 0; p < k.count; ++p) {
      SolverPoint& sp = k.points[p];
      const Fixed vn = row_speed(bodies_.velocities, k.bodies, k.normal, sp.normal);
      // The end of the range, also for a point still apart: a speculative contact's own stop at
      // the surface is the solve passes' business, as in every other scene.
      const Fixed allowed = max(sp.separation + depth, Fixed::zero()) * bodies_.inv_h;
      if (vn + allowed >= Fixed::zero()) continue;
      // The upper body's effective mass alone.
      const std::size_t upper = a_upper ? k.bodies.a : k.bodies.b;
      const Fixed angular = a_upper ? dot(sp.normal.response_a, sp.normal.angular_a)
                                    : dot(sp.normal.response_b, sp.normal.angular_b);
      const Fixed mass =
          inverse_or_zero(linear_share(s_.derived[upper], k.normal.linear_b) + angular);
      const Fixed impulse = -mass * (vn + allowed);
      k.pushed = true;
      BodyPair one_side = k.bodies;
      (a_upper ? one_side.takes_impulse_b : one_side.takes_impulse_a) = false;
      apply_impulse(bodies_.velocities, one_side, k.normal, sp.normal, impulse);
    }
  }
}

}  // namespace detsim::sim_detail
