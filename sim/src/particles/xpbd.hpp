// The particle stage of the solver: every awake particle group stepped by XPBD in small steps
// inside each solver sub-step, coupled with the bodies (docs/PARTICLES.md). Internal to
// detsim::sim.
//
// Per step (prepare): each group's contact planes against the bodies near it, found once with a
// margin that covers the step's motion (Macklin et al., "Unified Particle Physics", 2014: contacts
// found per frame, solved per iteration), in each body's frame so that they move with it.
// Per solver sub-step (substep, after the bodies moved): `substeps` small steps of h / substeps,
// each one pass of predict -> attachments -> distance links -> long-range tethers -> contacts
// (with friction) -> velocities from positions (Macklin et al., "Small Steps in Physics
// Simulation", 2019). Bodies are held where the sub-step put them; what the particles' constraints
// push on a dynamic body (an attached particle's links, a particle's contact) is summed as impulses
// and given to the body's velocity at the end of the sub-step: the particles pull and push the
// bodies (two-way), momentum balanced.
#pragma once

#include <cstdint>
#include <vector>

#include "../solver/bodies.hpp"
#include "../world_state.hpp"
#include "fluid.hpp"

namespace detsim::sim_detail {

/// A particle's contact with a body, found once per step: a plane in the body's frame.
struct ParticleContact {
  std::uint32_t particle = 0;
  std::uint32_t body = 0;  ///< index into WorldState::bodies
  Vec3 local_normal;       ///< out of the body, body frame
  Vec3 local_point;        ///< on the body's surface, body frame (from its origin)
  Fixed friction;
  // Per sub-step: the plane in world space at the body's present pose.
  Vec3 normal;
  Vec3 point;
};

class ParticleStepper {
 public:
  ParticleStepper(WorldState& s, SolverBodies& bodies);

  /// Once per step, before the first sub-step: contact planes of every awake group.
  void prepare();
  /// Once per solver sub-step, after the bodies' positions moved.
  void substep();

 private:
  struct GroupScratch {
    std::vector<ParticleContact> contacts;     ///< ascending particle, then body
    std::vector<std::uint32_t> attached_body;  ///< per attachment: body index
    std::vector<bool> tether_active;           ///< per tether: its anchor is held in place
    std::vector<Vec3> previous;                ///< positions before the small step
    std::vector<Vec3> target_from;             ///< attachments: where the sub-step starts
    std::vector<Vec3> targets;                 ///< attachments: where the sub-step ends
    std::vector<bool> fixed;                   ///< per particle: pinned or attached
    std::vector<std::int32_t> attachment_of;   ///< per particle: its attachment, or -1
    bool tethered = false;                     ///< a rope whose tether row holds its two bodies
    std::int32_t free_count = 0;               ///< particles neither pinned nor attached
    Fixed h;                                   ///< the small step
    Fixed inv_h;
    std::vector<Fixed> link_factor;  ///< per link: 1 / (w_a + w_b + compliance / h^2)
    Fixed volume_compliance;         ///< a soft body's volume compliance / h^2
    FluidScratch fluid;              ///< a fluid's neighbours and kernel sums
  };

  void prepare_group(ParticleGroup& g, GroupScratch& scratch);
  void step_group(ParticleGroup& g, GroupScratch& scratch);
  /// An impulse (N s) on body i at world point p, given to its velocity at the end of the
  /// sub-step.
  void push_body(std::uint32_t i, Vec3 impulse, Vec3 point);
  void apply_pushes();

  WorldState& s_;
  SolverBodies& bodies_;
  std::vector<GroupScratch> scratch_;  ///< parallel to WorldState::particle_groups
  std::vector<Velocity> pushes_;       ///< per body: impulse and angular impulse this sub-step
  std::vector<std::uint32_t> pushed_;  ///< bodies with a push, in first-push order
};

/// Before the wake stage: each group's bounding box and the bodies near it; a sleeping group
/// that a moving body comes near wakes, and an awake group wakes the sleeping bodies near it or
/// attached to it (their islands wake with them).
void prepare_particles(WorldState& s);
/// After the bodies' sleep stage: groups at rest long enough, with every body near them asleep,
/// fall asleep; forces applied to the groups are consumed.
void update_particle_sleep(WorldState& s);
/// Whether body i must stay awake for the particles: an awake group that is not yet at rest is
/// near it or attached to it.
[[nodiscard]] std::vector<bool> bodies_held_by_particles(const WorldState& s);

}  // namespace detsim::sim_detail
