// World's particle calls (world.hpp, "Particles"; docs/PARTICLES.md).
#include <algorithm>

#include <detsim/fixed/decimal.hpp>

#include "../limits.hpp"
#include "../world_state.hpp"
#include "group.hpp"

namespace detsim {

namespace sim_detail {

std::ptrdiff_t WorldState::find_group(std::uint32_t id) const noexcept {
  const auto it =
      std::lower_bound(particle_groups.begin(), particle_groups.end(), id,
                       [](const ParticleGroup& g, std::uint32_t v) { return g.id.value < v; });
  if (it == particle_groups.end() || it->id.value != id) return -1;
  return it - particle_groups.begin();
}

std::size_t WorldState::particle_total() const noexcept {
  std::size_t n = 0;
  for (const ParticleGroup& g : particle_groups)
    n += g.size();
  return n;
}

}  // namespace sim_detail

namespace {

Status unknown_group(ParticleGroupId id) {
  return Status::error("no particle group with ID " + std::to_string(id.value));
}

// Wakes the dynamic bodies a group is attached to.
void wake_attached(sim_detail::WorldState& s, const sim_detail::ParticleGroup& g) {
  for (const sim_detail::Attachment& a : g.attachments) {
    BodyState& b = s.bodies[static_cast<std::size_t>(s.find(a.body))];
    if (b.type != BodyType::dynamic) continue;
    b.awake = true;
    b.sleep_time = Fixed::zero();
  }
}

std::size_t count_of(const sim_detail::WorldState&, const RopeDef& def) {
  return sim_detail::particle_count(def);
}
std::size_t count_of(const sim_detail::WorldState&, const ClothDef& def) {
  return sim_detail::particle_count(def);
}
std::size_t count_of(const sim_detail::WorldState& s, const SoftBodyDef& def) {
  return sim_detail::particle_count(s, def);
}
std::size_t count_of(const sim_detail::WorldState&, const FluidDef& def) {
  return sim_detail::particle_count(def);
}

template <class Def>
Expected<ParticleGroupId> create_group(sim_detail::WorldState& s, const Def& def, std::string check,
                                       const char* what) {
  if (!check.empty())
    return Status::error(std::string("invalid ") + what + " definition: " + check);
  if (s.particle_groups.size() >= max_particle_groups)
    return Status::error("invalid " + std::string(what) + " definition: the world has " +
                         std::to_string(max_particle_groups) + " particle groups, the most it may");
  const std::size_t n = count_of(s, def);
  if (s.particle_total() + n > max_particles_per_world)
    return Status::error("invalid " + std::string(what) + " definition: " + std::to_string(n) +
                         " more particles would make " + std::to_string(s.particle_total() + n) +
                         ", above max_particles_per_world " +
                         std::to_string(max_particles_per_world));
  if (s.next_particle_group_id == 0xFFFFFFFFU)
    return Status::error("particle group IDs exhausted (2^32 - 1 created)");
  const ParticleGroupId id{s.next_particle_group_id};
  s.particle_groups.push_back(sim_detail::make_group(s, id, def));  // IDs only grow
  ++s.next_particle_group_id;
  wake_attached(s, s.particle_groups.back());
  return id;
}

}  // namespace

Expected<ParticleGroupId> World::create_rope(const RopeDef& def) {
  return create_group(*s_, def, sim_detail::check_rope_def(*s_, def), "rope");
}

Expected<ParticleGroupId> World::create_cloth(const ClothDef& def) {
  return create_group(*s_, def, sim_detail::check_cloth_def(*s_, def), "cloth");
}

Expected<ParticleGroupId> World::create_soft_body(const SoftBodyDef& def) {
  return create_group(*s_, def, sim_detail::check_soft_body_def(*s_, def), "soft body");
}

Expected<ParticleGroupId> World::create_fluid(const FluidDef& def) {
  return create_group(*s_, def, sim_detail::check_fluid_def(def), "fluid");
}

Status World::destroy_particle_group(ParticleGroupId id) {
  const std::ptrdiff_t k = s_->find_group(id.value);
  if (k < 0) return unknown_group(id);
  wake_attached(*s_, s_->particle_groups[static_cast<std::size_t>(k)]);
  s_->particle_groups.erase(s_->particle_groups.begin() + k);
  return Status::success();
}

std::vector<ParticleGroupId> World::particle_group_ids() const {
  std::vector<ParticleGroupId> ids;
  ids.reserve(s_->particle_groups.size());
  for (const sim_detail::ParticleGroup& g : s_->particle_groups)
    ids.push_back(g.id);
  return ids;
}

Expected<std::vector<Vec3>> World::particle_positions(ParticleGroupId id) const {
  const std::ptrdiff_t k = s_->find_group(id.value);
  if (k < 0) return unknown_group(id);
  return s_->particle_groups[static_cast<std::size_t>(k)].positions;
}

Expected<std::vector<Vec3>> World::particle_velocities(ParticleGroupId id) const {
  const std::ptrdiff_t k = s_->find_group(id.value);
  if (k < 0) return unknown_group(id);
  return s_->particle_groups[static_cast<std::size_t>(k)].velocities;
}

namespace {

template <class Def>
Expected<Def> def_of(const sim_detail::WorldState& s, ParticleGroupId id, const char* what) {
  const std::ptrdiff_t k = s.find_group(id.value);
  if (k < 0) return unknown_group(id);
  const auto* def = std::get_if<Def>(&s.particle_groups[static_cast<std::size_t>(k)].def);
  if (def == nullptr)
    return Status::error("particle group " + std::to_string(id.value) + " is not a " + what);
  return *def;
}

}  // namespace

Expected<RopeDef> World::rope_def(ParticleGroupId id) const {
  return def_of<RopeDef>(*s_, id, "rope");
}

Expected<ClothDef> World::cloth_def(ParticleGroupId id) const {
  return def_of<ClothDef>(*s_, id, "sheet of cloth");
}

Expected<SoftBodyDef> World::soft_body_def(ParticleGroupId id) const {
  return def_of<SoftBodyDef>(*s_, id, "soft body");
}

Expected<FluidDef> World::fluid_def(ParticleGroupId id) const {
  return def_of<FluidDef>(*s_, id, "fluid");
}

Expected<ParticleGroupStats> World::particle_group_stats(ParticleGroupId id) const {
  const std::ptrdiff_t k = s_->find_group(id.value);
  if (k < 0) return unknown_group(id);
  return sim_detail::group_stats(s_->particle_groups[static_cast<std::size_t>(k)]);
}

Status World::apply_particle_force(ParticleGroupId id, Vec3 force) {
  const std::ptrdiff_t k = s_->find_group(id.value);
  if (k < 0) return unknown_group(id);
  sim_detail::ParticleGroup& g = s_->particle_groups[static_cast<std::size_t>(k)];
  const Vec3 sum = g.force + force;
  if (auto e = sim_detail::check_components("force", force, sim_detail::max_velocity, "N");
      !e.empty())
    return Status::error(e);
  if (auto e =
          sim_detail::check_components("accumulated force", sum, sim_detail::max_velocity, "N");
      !e.empty())
    return Status::error(e);
  g.force = sum;
  g.awake = true;
  g.sleep_time = Fixed::zero();
  return Status::success();
}

namespace sim_detail {

void detach_particles_of(WorldState& s, BodyId id) {
  for (ParticleGroup& g : s.particle_groups) {
    const std::size_t before = g.attachments.size();
    std::erase_if(g.attachments, [id](const Attachment& a) { return a.body == id.value; });
    if (g.attachments.size() == before) continue;
    g.awake = true;
    g.sleep_time = Fixed::zero();
    g.tether_impulse = Fixed::zero();
  }
}

}  // namespace sim_detail

}  // namespace detsim
