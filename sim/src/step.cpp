// World::step: a short orchestrator of named stages (docs/SIM.md describes each).
#include <detsim/fixed/math.hpp>

#include "particles/xpbd.hpp"
#include "shapes.hpp"
#include "world_state.hpp"

namespace detsim {

void World::step() {
  sim_detail::WorldState& s = *s_;
  s.events.clear();
  s.joint_events.clear();
  sim_detail::prepare_bodies(s);         // 1. derived data: poses, inverse mass and inertia, AABBs
  sim_detail::prepare_particles(s);      //    particle groups' boxes; awake groups wake bodies
  sim_detail::update_contacts(s);        // 2. broadphase: overlapping pairs, ascending by ID pair
  sim_detail::collide_contacts(s);       // 3. narrowphase: manifolds, warm-start impulses matched
  sim_detail::wake_touched_islands(s);   // 4. islands touched by moving bodies wake up
  sim_detail::solve(s);                  // 5. inputs, velocities, contacts, positions (sub-stepped)
  sim_detail::continuous(s);             // 6. fast and CCD bodies stop at their first touch
  sim_detail::update_sleep(s);           // 7. islands at rest fall asleep
  sim_detail::update_particle_sleep(s);  //    then particle groups at rest, among sleeping bodies
  sim_detail::report_contacts(s);        // 8. contact and sensor events, by pair
  for (BodyState& b : s.bodies) {        // 9. game inputs are consumed by the step
    b.force = {};
    b.torque = {};
  }
  sim_detail::move_characters(s);  //    characters walk, slide and ride on the new poses (their
                                   //    pushes are forces for the next step)
  ++s.frame;
  sim_detail::check_after_step(s);  // 10. invariants, in builds with DETSIM_CHECKS
}

namespace sim_detail {

void prepare_bodies(WorldState& s) {
  s.derived.resize(s.bodies.size());
  s.prepared_from.resize(s.bodies.size());
  for (std::size_t i = 0; i < s.bodies.size(); ++i) {
    // A body at rest whose derived data came from what it holds now keeps it (the solver moves
    // only awake bodies); everything else is prepared again.
    const BodyState& b = s.bodies[i];
    WorldState::PreparedFrom from;
    if (!b.awake) {
      from = {b.position, b.orientation, b.angular_velocity, b.center_of_mass, b.shape,
              b.id.value, b.type};
      if (s.prepared_from[i] == from) {
        Derived& d = s.derived[i];
        d.delta_position = {};
        d.delta_angle = {};
        d.pushed_out = {};
        continue;
      }
    }
    prepare_body(s, i);
    s.prepared_from[i] = from;  // id 0 for an awake body: nothing kept
  }
  s.joint_bodies.resize(s.joints.size());
  for (std::size_t j = 0; j < s.joints.size(); ++j) {
    const JointDef& def = s.joints[j].def;
    s.joint_bodies[j] = {static_cast<std::uint32_t>(s.find(def.body_a.value)),
                         static_cast<std::uint32_t>(s.find(def.body_b.value))};
  }
}

void prepare_body(WorldState& s, std::size_t i) {
  // Whoever prepares a body (a wake, a teleport) replaces what prepare_bodies kept.
  if (i < s.prepared_from.size()) s.prepared_from[i].id = 0;
  const Vec3 margin{s.def.speculative_distance, s.def.speculative_distance,
                    s.def.speculative_distance};
  const BodyState& b = s.bodies[i];
  Derived& d = s.derived[i];
  d.pose = {b.position, to_mat3(b.orientation)};
  // A zero centre of mass (every primitive) leaves the position as it is: the same bits as
  // world_center(), without its rotation.
  d.center = b.center_of_mass == Vec3{} ? b.position : b.world_center();
  const bool moving = b.type == BodyType::dynamic && b.awake;
  d.inverse_mass = moving ? inverse_or_zero(b.mass) : Fixed::zero();
  if (moving) {
    // R I^-1 R^T in the principal frame, turned by the body's orientation. Principal axes that
    // are the body's (the identity) turn nothing: the body's rotation, bit for bit.
    const Mat3 principal = b.inertia_axes == Quat::identity()
                               ? d.pose.rotation
                               : to_mat3(b.orientation * b.inertia_axes);
    d.inverse_inertia_world = rotate_inertia(
        principal, Mat3::diagonal(inverse_or_zero(b.inertia.x), inverse_or_zero(b.inertia.y),
                                  inverse_or_zero(b.inertia.z)));
    d.translation_locks = b.translation_locks();
    d.rotation_locks = b.rotation_locks();
    if (d.rotation_locks.any()) {
      // P I^-1 P: the locked rows and columns zeroed.
      Mat3& m = d.inverse_inertia_world;
      for (std::size_t r = 0; r < 3; ++r)
        m.rows[r] = without_locked(m.rows[r], d.rotation_locks);
      const AxisLocks& l = d.rotation_locks;
      if (l.x) m.rows[0] = Vec3::zero();
      if (l.y) m.rows[1] = Vec3::zero();
      if (l.z) m.rows[2] = Vec3::zero();
    }
  } else {
    d.inverse_inertia_world = Mat3::zero();
    d.translation_locks = {};
    d.rotation_locks = {};
  }
  const ShapeKind& shape = shape_kind(b.shape.type);
  const Geometry* g = s.geometry(b.shape);
  d.infinite = !shape.bounded;
  // length(0) * r is exactly 0: most bodies at rest skip the two square roots.
  d.rim_speed = b.angular_velocity == Vec3{}
                    ? Fixed::zero()
                    : length(b.angular_velocity) * shape.bounding_radius(b.shape, g);
  const Vec3 e = shape.aabb_extent(b.shape, g, d.pose.rotation) + margin;
  d.aabb_min = b.position - e;
  d.aabb_max = b.position + e;
  // A moving body's box also covers where its velocity takes it this step, so that speculative
  // contacts exist before fast bodies meet.
  if (b.type != BodyType::static_body && b.awake) {
    const Vec3 travel = b.linear_velocity * s.def.dt;
    d.aabb_min += Vec3{min(travel.x, Fixed::zero()), min(travel.y, Fixed::zero()),
                       min(travel.z, Fixed::zero())};
    d.aabb_max += Vec3{max(travel.x, Fixed::zero()), max(travel.y, Fixed::zero()),
                       max(travel.z, Fixed::zero())};
  }
  d.start_position = b.position;
  d.start_orientation = b.orientation;
  d.delta_position = {};
  d.delta_angle = {};
  d.pushed_out = {};
}

}  // namespace sim_detail
}  // namespace detsim
