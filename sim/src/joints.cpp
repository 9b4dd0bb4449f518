// World: joints — creation, destruction and queries (docs/SIM.md, "Joints"). The solver's joint
// kind is solver/joint_solver.cpp.
#include <algorithm>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <detsim/fixed/math.hpp>

#include "world_state.hpp"

namespace detsim {

using sim_detail::WorldState;

namespace sim_detail {

std::ptrdiff_t WorldState::find_joint(std::uint32_t id) const noexcept {
  const auto it =
      std::lower_bound(joints.begin(), joints.end(), id,
                       [](const JointState& j, std::uint32_t v) { return j.id.value < v; });
  if (it == joints.end() || it->id.value != id) return -1;
  return it - joints.begin();
}

namespace {

void wake_body(WorldState& s, BodyId id) {
  const std::ptrdiff_t i = s.find(id.value);
  if (i < 0) return;
  BodyState& b = s.bodies[static_cast<std::size_t>(i)];
  if (b.type == BodyType::static_body) return;
  b.awake = true;
  b.sleep_time = Fixed::zero();
}

}  // namespace

std::vector<std::uint64_t> joined_pairs(const WorldState& s) {
  std::vector<std::uint64_t> pairs;
  for (std::size_t ji = 0; ji < s.joints.size(); ++ji) {
    const JointState& j = s.joints[ji];
    if (j.broken || j.def.collide_connected) continue;
    const std::uint64_t ia = s.joint_bodies[ji][0];
    const std::uint64_t ib = s.joint_bodies[ji][1];
    pairs.push_back((std::min(ia, ib) << 32) | std::max(ia, ib));
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

bool is_joined_pair(const std::vector<std::uint64_t>& pairs, std::size_t i,
                    std::size_t j) noexcept {
  if (pairs.empty()) return false;
  const std::uint64_t lo = std::min(i, j);
  const std::uint64_t hi = std::max(i, j);
  return std::binary_search(pairs.begin(), pairs.end(), (lo << 32) | hi);
}

void destroy_joints_of(WorldState& s, BodyId id) {
  for (const JointState& j : s.joints) {
    if (j.def.body_a != id && j.def.body_b != id) continue;
    wake_body(s, j.def.body_a == id ? j.def.body_b : j.def.body_a);
    // Reported with the load it carried, while both bodies still exist.
    s.joint_events.push_back({JointEvent::Kind::destroyed, j.id, j.def.body_a, j.def.body_b,
                              j.def.user_data, joint_reaction_of(s, j)});
  }
  std::erase_if(s.joints,
                [id](const JointState& j) { return j.def.body_a == id || j.def.body_b == id; });
}

}  // namespace sim_detail

namespace {

Status unknown_joint(JointId id) {
  return Status::error("no joint with ID " + std::to_string(id.value));
}

// `v` (world space) in the frame of body `b`.
Vec3 to_local(const BodyState& b, Vec3 v) {
  return rotate(conjugate(b.orientation), v);
}

}  // namespace

Expected<JointId> World::create_joint(const JointDef& def) {
  if (s_->next_joint_id == 0xFFFFFFFFU)
    return Status::error("joint IDs exhausted (2^32 - 1 created)");
  if (auto e = sim_detail::check_joint_def(*s_, def); !e.empty())
    return Status::error("invalid joint definition: " + e);
  const BodyState& a = s_->bodies[static_cast<std::size_t>(s_->find(def.body_a.value))];
  const BodyState& b = s_->bodies[static_cast<std::size_t>(s_->find(def.body_b.value))];
  JointState j;
  j.id = JointId{s_->next_joint_id};
  j.def = def;
  j.def.axis = normalize(def.axis);
  j.local_anchor_a = to_local(a, def.anchor - a.position);
  if (def.type == JointType::distance) {
    // The rope's or rod's other end is body_b's centre.
    j.local_anchor_b = Vec3{};
    j.length = length(b.position - def.anchor);
  } else {
    j.local_anchor_b = to_local(b, def.anchor - b.position);
  }
  j.relative_orientation = normalize(conjugate(a.orientation) * b.orientation);
  j.local_axis_a = to_local(a, j.def.axis);
  j.local_axis_b = to_local(b, j.def.axis);
  s_->joints.push_back(j);  // IDs only grow: appending keeps the order
  ++s_->next_joint_id;
  // Joined bodies are one island: they sleep and wake together.
  sim_detail::wake_body(*s_, def.body_a);
  sim_detail::wake_body(*s_, def.body_b);
  return j.id;
}

Status World::destroy_joint(JointId id) {
  const std::ptrdiff_t i = s_->find_joint(id.value);
  if (i < 0) return unknown_joint(id);
  const JointState& j = s_->joints[static_cast<std::size_t>(i)];
  sim_detail::wake_body(*s_, j.def.body_a);
  sim_detail::wake_body(*s_, j.def.body_b);
  s_->joints.erase(s_->joints.begin() + i);
  return Status::success();
}

Expected<JointState> World::joint(JointId id) const {
  const std::ptrdiff_t i = s_->find_joint(id.value);
  if (i < 0) return unknown_joint(id);
  return s_->joints[static_cast<std::size_t>(i)];
}

Status World::set_joint_motor(JointId id, Fixed speed, Fixed max_force) {
  const std::ptrdiff_t i = s_->find_joint(id.value);
  if (i < 0) return unknown_joint(id);
  JointState& j = s_->joints[static_cast<std::size_t>(i)];
  if (j.def.type != JointType::hinge && j.def.type != JointType::slider)
    return Status::error("joint " + std::to_string(id.value) +
                         " has no motor: only hinge and slider joints have one");
  if (auto e = sim_detail::check_joint_motor(speed, max_force); !e.empty())
    return Status::error("joint " + std::to_string(id.value) + ": " + e);
  j.def.motor_speed = speed;
  j.def.motor_max_force = max_force;
  // A motor of no force does nothing: max_force 0 is how a game switches it off. (Its
  // accumulated impulse is clamped to the new force by the next step's warm start.)
  j.def.motor_enabled = max_force > Fixed::zero();
  sim_detail::wake_body(*s_, j.def.body_a);
  sim_detail::wake_body(*s_, j.def.body_b);
  return Status::success();
}

Expected<JointReaction> World::joint_reaction(JointId id) const {
  const std::ptrdiff_t i = s_->find_joint(id.value);
  if (i < 0) return unknown_joint(id);
  return sim_detail::joint_reaction_of(*s_, s_->joints[static_cast<std::size_t>(i)]);
}

std::span<const JointEvent> World::joint_events() const noexcept {
  return s_->joint_events;
}

std::vector<JointId> World::joint_ids() const {
  std::vector<JointId> ids;
  ids.reserve(s_->joints.size());
  for (const JointState& j : s_->joints)
    ids.push_back(j.id);
  return ids;
}

}  // namespace detsim
