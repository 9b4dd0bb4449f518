// The World's invariants (World::validate, and after every step in builds with DETSIM_CHECKS).
//
// What restore() checks of bytes, checked here of the live state, plus what a step restores from
// any state that restore() accepts: the contact cache's order and consistency, and islands that
// sleep as a whole. (A sleeping or static body with a velocity is accepted by restore, and
// fault injection makes one on purpose, so it is not an invariant.) Each check reads; none
// changes the world. A failure names the body or pair and what is wrong.
#include <string>
#include <tuple>

#include <detsim/core/assert.hpp>

#include "world_state.hpp"

namespace detsim {

namespace sim_detail {

std::string validate_world(const WorldState& s) {
  const auto body = [](std::uint32_t id) { return "body " + std::to_string(id) + ": "; };
  if (s.next_id == 0) return "the next body ID is 0";
  for (std::size_t i = 0; i < s.bodies.size(); ++i) {
    const BodyState& b = s.bodies[i];
    if (b.id.value == 0 || b.id.value >= s.next_id)
      return body(b.id.value) + "ID outside 1.." + std::to_string(s.next_id - 1);
    if (i > 0 && s.bodies[i - 1].id >= b.id) return body(b.id.value) + "IDs are not ascending";
    if (auto e = check_shape(s.geometries, b.shape, b.type); !e.empty())
      return body(b.id.value) + e;
    if (auto e = check_orientation(b.orientation); !e.empty()) return body(b.id.value) + e;
    if (b.sleep_time < Fixed::zero()) return body(b.id.value) + "negative sleep time";
    if (b.type == BodyType::static_body && b.awake) return body(b.id.value) + "static and awake";
  }
  for (std::size_t k = 0; k < s.contacts.size(); ++k) {
    const Contact& c = s.contacts[k];
    const std::string pair = "contact (" + std::to_string(c.a) + ", " + std::to_string(c.b) + "): ";
    if (c.a >= c.b) return pair + "a is not below b";
    if (k > 0) {
      const Contact& p = s.contacts[k - 1];
      const auto key = [](const Contact& x) { return std::tuple(x.a, x.b, x.sub_a, x.sub_b); };
      if (key(p) >= key(c))
        return pair + "the cache is not in strictly ascending (a, b, sub_a, sub_b) order";
    }
    if (s.find(c.a) < 0 || s.find(c.b) < 0) return pair + "names a body that does not exist";
    if (c.point_count > 4) return pair + "more than 4 points";
    if (c.touching != (c.point_count > 0)) return pair + "touching disagrees with its points";
    if (c.reported && !c.touching) return pair + "reported without points";
  }
  for (std::size_t k = 0; k < s.characters.size(); ++k) {
    const CharacterState& c = s.characters[k];
    const std::string character = "character " + std::to_string(c.id.value) + ": ";
    if (c.id.value == 0 || c.id.value >= s.next_character_id)
      return character + "ID outside 1.." + std::to_string(s.next_character_id - 1);
    if (k > 0 && s.characters[k - 1].id >= c.id) return character + "IDs are not ascending";
    if (!c.ground_body.is_null() && s.find(c.ground_body.value) < 0)
      return character + "stands on a body that does not exist";
  }
  for (std::size_t k = 0; k < s.vehicles.size(); ++k) {
    const VehicleState& v = s.vehicles[k];
    const std::string vehicle = "vehicle " + std::to_string(v.id.value) + ": ";
    if (v.id.value == 0 || v.id.value >= s.next_vehicle_id)
      return vehicle + "ID outside 1.." + std::to_string(s.next_vehicle_id - 1);
    if (k > 0 && s.vehicles[k - 1].id >= v.id) return vehicle + "IDs are not ascending";
    if (s.find(v.def.chassis.value) < 0) return vehicle + "its chassis does not exist";
    if (v.wheels.size() != v.def.wheels.size()) return vehicle + "wheel states and wheels differ";
    for (const WheelState& w : v.wheels)
      if (!w.contact_body.is_null() && s.find(w.contact_body.value) < 0)
        return vehicle + "a wheel touches a body that does not exist";
  }
  for (std::size_t k = 0; k < s.joints.size(); ++k) {
    const JointState& j = s.joints[k];
    const std::string joint = "joint " + std::to_string(j.id.value) + ": ";
    if (j.id.value == 0 || j.id.value >= s.next_joint_id)
      return joint + "ID outside 1.." + std::to_string(s.next_joint_id - 1);
    if (k > 0 && s.joints[k - 1].id >= j.id) return joint + "IDs are not ascending";
    if (s.find(j.def.body_a.value) < 0 || s.find(j.def.body_b.value) < 0)
      return joint + "names a body that does not exist";
  }
  std::size_t particles = 0;
  for (std::size_t k = 0; k < s.particle_groups.size(); ++k) {
    const ParticleGroup& g = s.particle_groups[k];
    const std::string group = "particle group " + std::to_string(g.id.value) + ": ";
    if (g.id.value == 0 || g.id.value >= s.next_particle_group_id)
      return group + "ID outside 1.." + std::to_string(s.next_particle_group_id - 1);
    if (k > 0 && s.particle_groups[k - 1].id >= g.id) return group + "IDs are not ascending";
    if (g.velocities.size() != g.size() || g.size() < 2 || g.size() > max_particles_per_group)
      return group + "particle arrays of " + std::to_string(g.size()) + " and " +
             std::to_string(g.velocities.size());
    particles += g.size();
    for (std::size_t a = 0; a < g.attachments.size(); ++a) {
      if (g.attachments[a].particle >= g.size() || s.find(g.attachments[a].body) < 0 ||
          (a > 0 && g.attachments[a - 1].particle >= g.attachments[a].particle))
        return group + "attachment " + std::to_string(a) + " is not a particle on a body";
    }
    for (std::size_t b = 0; b < g.broken.size(); ++b) {
      if (g.broken[b] >= g.links.size() || !g.link_broken[g.broken[b]] ||
          (b > 0 && g.broken[b - 1] >= g.broken[b]))
        return group + "the broken constraints disagree with the links";
    }
  }
  if (particles > max_particles_per_world)
    return std::to_string(particles) + " particles, above max_particles_per_world";
  // Islands sleep and wake as a whole: no touching pair of dynamic bodies is half asleep.
  if (s.def.enable_sleep) {
    for (const Contact& c : s.contacts) {
      if (!c.touching) continue;
      const BodyState& a = s.bodies[static_cast<std::size_t>(s.find(c.a))];
      const BodyState& b = s.bodies[static_cast<std::size_t>(s.find(c.b))];
      if (a.type == BodyType::dynamic && b.type == BodyType::dynamic && !a.sensor && !b.sensor &&
          a.awake != b.awake)
        return "contact (" + std::to_string(c.a) + ", " + std::to_string(c.b) +
               "): one body of a touching pair sleeps, the other is awake (an island is split)";
    }
    for (const JointState& j : s.joints) {
      if (j.broken) continue;
      const BodyState& a = s.bodies[static_cast<std::size_t>(s.find(j.def.body_a.value))];
      const BodyState& b = s.bodies[static_cast<std::size_t>(s.find(j.def.body_b.value))];
      if (a.type == BodyType::dynamic && b.type == BodyType::dynamic && a.awake != b.awake)
        return "joint " + std::to_string(j.id.value) +
               ": one body sleeps, the other is awake (an island is split)";
    }
  }
  return {};
}

void check_after_step(const WorldState& s) {
  if constexpr (checks_enabled) {
    if (const std::string e = validate_world(s); !e.empty())
      invariant_failed(("after step " + std::to_string(s.frame) + ": " + e).c_str(), __FILE__,
                       __LINE__);
  }
}

}  // namespace sim_detail

Status World::validate() const {
  if (std::string e = sim_detail::validate_world(*s_); !e.empty()) return Status::error(e);
  return Status::success();
}

}  // namespace detsim
