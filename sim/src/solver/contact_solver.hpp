// Contacts as a constraint kind: the sub-stepped soft contact solver (contact_solver.cpp).
// Internal to detsim::sim.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "../world_state.hpp"
#include "bodies.hpp"
#include "constraint_kind.hpp"
#include "rows.hpp"

namespace detsim::sim_detail {

/// A contact point's rows (the normal and two tangents, at the point's anchors), its separation
/// and its accumulated impulses.
struct SolverPoint {
  Fixed base_separation;
  Fixed separation;  ///< at the bodies' present motion (refresh_separations)
  Row normal;
  Row tangent_1;
  Row tangent_2;
  Fixed normal_impulse;
  Fixed tangent_impulse_1;
  Fixed tangent_impulse_2;
  Fixed push_impulse;  ///< accumulated on the push-out velocities, this sub-step
};

/// The normal row at the centroid of a contact's points: the manifold's first push
/// (solve_centre), and restitution, which acts once per contact along it.
struct Centroid {
  Row normal;
  Fixed relative_velocity;  ///< normal approach speed before the first push
};

/// One contact's constraint for the step: the directions its points share, and the points.
struct ContactConstraint {
  std::size_t contact;  ///< index in WorldState::contacts
  BodyPair bodies;
  Direction normal;
  Direction tangent_1;
  Direction tangent_2;
  Fixed friction;
  Fixed restitution;
  std::uint8_t count;
  bool pushed;          ///< some point has pushed in this step
  bool bounced;         ///< restitution applied this step
  bool loaded;          ///< some point carried a normal impulse from the last step (warm start)
  bool centroid_ready;  ///< centroid.normal is made
  std::array<SolverPoint, 4> points;
  Centroid centroid;  ///< its row when centroid_ready; restitution's approach speed
};

/// The contacts of the step, in contact order (ascending ID pair), point order within a contact.
// The kind owns its constraints (`constraints_`, one struct per contact, built in prepare) and
// every stage is a loop over them. Wide rows will change only that: prepare also packs the
// constraints of each colour into batches of 4 or 8 side by side (structure of arrays, one lane
// per contact, gathering the bodies' velocities by index), and solve and relax loop over the
// batches. Solving by colour is a new order, so new results: the scalar loop must then follow the
// same colour order for the two paths to give the same bits.
class ContactSolver final : public ConstraintKind {
 public:
  ContactSolver(WorldState& s, SolverBodies& bodies);

  void prepare() override;
  void warm_start() override;
  void solve() override;
  void hold() override;
  void push_out() override;
  void positions_moved() override;
  void relax() override;
  void restitution() override;
  void store_impulses() override;

 private:
  void prepare_constraint(std::size_t contact_index);
  void prepare_levels();
  void solve_contacts(bool first_pass);
  [[nodiscard]] Fixed hard_stop(Fixed separation) const;
  /// The contact spring of `k`: stiffer against a body that no impulse moves.
  [[nodiscard]] const Softness& softness(const ContactConstraint& k) const;
  void solve_centre(ContactConstraint& k);
  void solve_normal(ContactConstraint& k, const Softness& soft, bool use_bias);
  void solve_friction(ContactConstraint& k);
  [[nodiscard]] Fixed current_separation(const ContactConstraint& k, const SolverPoint& p) const;

  WorldState& s_;
  SolverBodies& bodies_;
  Softness soft_;
  Softness static_soft_;
  std::vector<ContactConstraint> constraints_;
  /// The constraints between bodies of different levels (levels_), lower level first, then in
  /// contact order: the order of hold().
  std::vector<std::uint32_t> hold_order_;
  /// Each body's level: 0 for a body no impulse moves (static, kinematic, asleep), then the
  /// number of contacts to the nearest such body; kNoLevel when there is none.
  std::vector<std::uint32_t> levels_;
};

}  // namespace detsim::sim_detail
