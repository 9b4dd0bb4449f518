// The "particles" section of the canonical state (docs/STATE.md): the next particle group ID,
// then one record per group, in ascending ID order.
//
// A record is the ID step, the type, the definition (its type's fields, then the settings), the
// flags byte (bit 0: awake), the sleep time, the accumulated force, the tether's impulse, the
// attachments, the particle count (what the definition makes: a soft body's depends on its
// shape's lattice, so a reader need not build it to find the record's end), every particle's
// position and velocity, and the broken constraints. The
// constraints themselves are not written: build_group makes them again from the definition, the
// same on every machine. The reader checks every field as create_rope / create_cloth would, and
// the state's own parts (attachments, positions, velocities, broken indices) against the limits
// and the bodies already read.
#include <string>

#include <detsim/fixed/decimal.hpp>

#include "limits.hpp"
#include "state_io.hpp"

namespace detsim::sim_detail {

namespace {

constexpr std::uint8_t kAwake = 1;
// The smallest record (a rope of one segment has two particles of 48 bytes each): to bound the
// group count by the bytes that remain before allocating.
constexpr std::size_t kMinGroupBytes = 96;

void write_settings(const ParticleSettings& p, ByteWriter& w) {
  w.fixed(p.friction);
  w.fixed(p.damping);
  w.var(p.substeps);
  w.u32(p.layer);
  w.u32(p.mask);
}

ParticleSettings read_settings(ByteReader& r) {
  ParticleSettings p;
  p.friction = r.fixed("particle friction");
  p.damping = r.fixed("particle damping");
  p.substeps = r.var32("particle substeps");
  p.layer = r.u32("particle layer");
  p.mask = r.u32("particle mask");
  return p;
}

void write_def(const RopeDef& d, ByteWriter& w) {
  w.vec3(d.start);
  w.vec3(d.end);
  w.var(d.segments);
  w.fixed(d.length);
  w.fixed(d.mass);
  w.fixed(d.radius);
  w.fixed(d.compliance);
  w.fixed(d.bending_compliance);
  w.var(d.attach_start.value);
  w.var(d.attach_end.value);
  write_settings(d.settings, w);
}

RopeDef read_rope(ByteReader& r) {
  RopeDef d;
  d.start = r.vec3("rope start");
  d.end = r.vec3("rope end");
  d.segments = r.var32("rope segments");
  d.length = r.fixed("rope length");
  d.mass = r.fixed("rope mass");
  d.radius = r.fixed("rope radius");
  d.compliance = r.fixed("rope compliance");
  d.bending_compliance = r.fixed("rope bending compliance");
  d.attach_start = BodyId{r.var32("rope attach start")};
  d.attach_end = BodyId{r.var32("rope attach end")};
  d.settings = read_settings(r);
  return d;
}

void write_def(const ClothDef& d, ByteWriter& w) {
  w.vec3(d.origin);
  w.vec3(d.axis_u);
  w.vec3(d.axis_v);
  w.var(d.columns);
  w.var(d.rows);
  w.fixed(d.mass);
  w.fixed(d.thickness);
  w.fixed(d.stretch_compliance);
  w.fixed(d.bend_compliance);
  w.var(d.pinned.size());
  std::uint32_t previous = 0;
  for (std::size_t k = 0; k < d.pinned.size(); ++k) {
    w.var(k == 0 ? d.pinned[k] : d.pinned[k] - previous);
    previous = d.pinned[k];
  }
  w.var(d.attach_body.value);
  w.fixed(d.tear_strain);
  write_settings(d.settings, w);
}

bool read_cloth(ByteReader& r, ClothDef& d, std::string& error) {
  d.origin = r.vec3("cloth origin");
  d.axis_u = r.vec3("cloth axis u");
  d.axis_v = r.vec3("cloth axis v");
  d.columns = r.var32("cloth columns");
  d.rows = r.var32("cloth rows");
  d.mass = r.fixed("cloth mass");
  d.thickness = r.fixed("cloth thickness");
  d.stretch_compliance = r.fixed("cloth stretch compliance");
  d.bend_compliance = r.fixed("cloth bend compliance");
  const std::size_t count_at = r.offset();
  const std::uint32_t pins = r.var32("cloth pinned count");
  if (!r.ok()) return false;
  if (pins > max_particles_per_group || pins > r.remaining()) {
    error = "byte " + std::to_string(count_at) + ": cloth pinned count " + std::to_string(pins) +
            " exceeds what the data can hold";
    return false;
  }
  d.pinned.resize(pins);
  std::uint32_t previous = 0;
  for (std::uint32_t k = 0; k < pins && r.ok(); ++k) {
    const std::size_t at = r.offset();
    const std::uint32_t step = r.var32("cloth pinned index step");
    if (r.ok() && k > 0 && (step == 0 || step > 0xFFFFFFFFU - previous)) {
      error = "byte " + std::to_string(at) + ": pinned indices must ascend";
      return false;
    }
    d.pinned[k] = k == 0 ? step : previous + step;
    previous = d.pinned[k];
  }
  d.attach_body = BodyId{r.var32("cloth attach body")};
  d.tear_strain = r.fixed("cloth tear strain");
  d.settings = read_settings(r);
  return r.ok();
}

void write_def(const SoftBodyDef& d, ByteWriter& w) {
  w.u8(static_cast<std::uint8_t>(d.shape.type));
  if (d.shape.type == ShapeType::convex) {
    w.var(d.shape.geometry.value);
  } else {
    w.vec3(d.shape.half_extents);
  }
  w.vec3(d.position);
  w.quat(d.orientation);
  w.var(d.resolution);
  w.fixed(d.mass);
  w.fixed(d.edge_compliance);
  w.fixed(d.volume_compliance);
  write_settings(d.settings, w);
}

bool read_soft_body(ByteReader& r, SoftBodyDef& d) {
  const std::size_t type_at = r.offset();
  const std::uint8_t type = r.u8("soft body shape type");
  if (!r.ok()) return false;
  if (type == static_cast<std::uint8_t>(ShapeType::convex)) {
    d.shape = Shape::convex(GeometryId{r.var32("soft body hull")});
  } else if (type == static_cast<std::uint8_t>(ShapeType::box)) {
    d.shape = Shape::box(r.vec3("soft body half extents"));
  } else {
    r.fail_at(type_at, "soft body shape type", "a box or a convex hull");
    return false;
  }
  d.position = r.vec3("soft body position");
  d.orientation = r.quat("soft body orientation");
  d.resolution = r.var32("soft body resolution");
  d.mass = r.fixed("soft body mass");
  d.edge_compliance = r.fixed("soft body edge compliance");
  d.volume_compliance = r.fixed("soft body volume compliance");
  d.settings = read_settings(r);
  return r.ok();
}

void write_def(const FluidDef& d, ByteWriter& w) {
  w.vec3(d.min);
  w.vec3(d.max);
  w.fixed(d.spacing);
  w.fixed(d.rest_density);
  w.fixed(d.viscosity);
  w.fixed(d.particle_radius);
  write_settings(d.settings, w);
}

FluidDef read_fluid(ByteReader& r) {
  FluidDef d;
  d.min = r.vec3("fluid min");
  d.max = r.vec3("fluid max");
  d.spacing = r.fixed("fluid spacing");
  d.rest_density = r.fixed("fluid rest density");
  d.viscosity = r.fixed("fluid viscosity");
  d.particle_radius = r.fixed("fluid particle radius");
  d.settings = read_settings(r);
  return d;
}

}  // namespace

std::string check_particle_record(const WorldState& s, const ParticleGroup& g) {
  const std::uint32_t n = static_cast<std::uint32_t>(g.size());
  for (std::size_t k = 0; k < g.attachments.size(); ++k) {
    const Attachment& a = g.attachments[k];
    const std::string at = "attachment " + std::to_string(k) + ": ";
    if (a.particle >= n)
      return at + "particle " + std::to_string(a.particle) + " of " + std::to_string(n);
    if (k > 0 && a.particle <= g.attachments[k - 1].particle)
      return at + "particles must ascend without repeats";
    if (s.find(a.body) < 0) return at + "body " + std::to_string(a.body) + " does not exist";
    if (auto e = check_components("local point", a.local, max_position, "m"); !e.empty())
      return at + e;
  }
  for (std::uint32_t i = 0; i < n; ++i) {
    if (auto e = check_components("position", g.positions[i], max_position, "m"); !e.empty())
      return "particle " + std::to_string(i) + ": " + e;
    if (auto e = check_components("velocity", g.velocities[i], max_velocity, "m/s"); !e.empty())
      return "particle " + std::to_string(i) + ": " + e;
  }
  if (auto e = check_components("force", g.force, max_velocity, "N"); !e.empty()) return e;
  if (g.sleep_time < Fixed::zero())
    return "sleep time must be >= 0, got " + to_string(g.sleep_time);
  if (g.tether_impulse < Fixed::zero())
    return "tether impulse must be >= 0, got " + to_string(g.tether_impulse);
  return {};
}

void write_particle_group(const ParticleGroup& g, std::uint32_t previous_id, ByteWriter& w) {
  w.var(g.id.value - previous_id);
  w.u8(static_cast<std::uint8_t>(g.type));
  std::visit([&](const auto& def) { write_def(def, w); }, g.def);
  w.u8(g.awake ? kAwake : 0);
  w.fixed(g.sleep_time);
  w.vec3(g.force);
  w.fixed(g.tether_impulse);
  w.var(g.attachments.size());
  for (const Attachment& a : g.attachments) {
    w.var(a.particle);
    w.var(a.body);
    w.vec3(a.local);
  }
  w.var(g.size());
  for (std::size_t i = 0; i < g.size(); ++i) {
    w.vec3(g.positions[i]);
    w.vec3(g.velocities[i]);
  }
  w.var(g.broken.size());
  std::uint32_t last = 0;
  for (std::size_t k = 0; k < g.broken.size(); ++k) {
    w.var(k == 0 ? g.broken[k] : g.broken[k] - last);
    last = g.broken[k];
  }
}

void write_particles(const WorldState& s, ByteWriter& w) {
  w.u32(s.next_particle_group_id);
  w.var(s.particle_groups.size());
  std::uint32_t previous = 0;
  for (const ParticleGroup& g : s.particle_groups) {
    write_particle_group(g, previous, w);
    previous = g.id.value;
  }
}

bool read_particles(std::span<const std::uint8_t>, ByteReader& r, WorldState& s,
                    std::string& error) {
  const auto failed_at = [&](std::size_t at, const std::string& message) {
    error = "byte " + std::to_string(at) + ": " + message;
    return false;
  };
  const std::size_t next_at = r.offset();
  s.next_particle_group_id = r.u32("next particle group id");
  if (r.ok() && s.next_particle_group_id == 0)
    return failed_at(next_at, "next particle group ID must be >= 1");
  const std::size_t count_at = r.offset();
  const std::uint64_t count = r.var("particle group count");
  if (r.ok() && (count > max_particle_groups || count > r.remaining() / kMinGroupBytes))
    return failed_at(count_at, "particle group count " + std::to_string(count) +
                                   " exceeds what the data can hold (or max_particle_groups)");
  s.particle_groups.clear();
  s.particle_groups.reserve(static_cast<std::size_t>(count));
  std::uint32_t previous = 0;
  std::size_t total = 0;
  for (std::uint64_t k = 0; k < count && r.ok(); ++k) {
    const std::size_t at = r.offset();
    ParticleGroup g;
    const std::uint32_t step = r.var32("particle group ID step");
    if (r.ok() && (step == 0 || step > s.next_particle_group_id - 1 - previous))
      return failed_at(at, "particle group ID step " + std::to_string(step) + " after ID " +
                               std::to_string(previous) +
                               ": IDs must ascend and stay below the next particle group ID " +
                               std::to_string(s.next_particle_group_id));
    g.id = ParticleGroupId{previous + step};
    previous = g.id.value;
    const std::string name = "particle group " + std::to_string(g.id.value) + ": ";
    const std::size_t type_at = r.offset();
    const std::uint8_t type = r.u8("particle group type");
    if (r.ok() && type > static_cast<std::uint8_t>(ParticleGroupType::fluid))
      r.fail_at(type_at, "particle group type", "0-3 (rope, cloth, soft body, fluid)");
    if (!r.ok()) break;
    g.type = static_cast<ParticleGroupType>(type);
    const std::size_t def_at = r.offset();
    std::string check;
    std::uint32_t n = 0;
    if (g.type == ParticleGroupType::rope) {
      const RopeDef def = read_rope(r);
      if (!r.ok()) break;
      check = check_rope_def(s, def, false);
      n = particle_count(def);
      g.def = def;
    } else if (g.type == ParticleGroupType::fluid) {
      const FluidDef def = read_fluid(r);
      if (!r.ok()) break;
      check = check_fluid_def(def);
      n = particle_count(def);
      g.def = def;
    } else if (g.type == ParticleGroupType::soft_body) {
      SoftBodyDef def;
      if (!read_soft_body(r, def)) break;
      check = check_soft_body_def(s, def);
      n = check.empty() ? particle_count(s, def) : 0;
      g.def = def;
    } else {
      ClothDef def;
      if (!read_cloth(r, def, error)) {
        if (!error.empty()) return false;
        break;  // the reader failed: it names the byte
      }
      check = check_cloth_def(s, def, false);
      n = particle_count(def);
      g.def = std::move(def);
    }
    if (!check.empty()) return failed_at(def_at, name + check);
    total += n;
    if (total > max_particles_per_world)
      return failed_at(def_at, name + "the groups hold " + std::to_string(total) +
                                   " particles, above max_particles_per_world " +
                                   std::to_string(max_particles_per_world));
    const std::size_t flags_at = r.offset();
    const std::uint8_t flags = r.u8("particle group flags");
    if (r.ok() && (flags & ~kAwake) != 0)
      r.fail_at(flags_at, "particle group flags", "0 or 1 (bit 0: awake)");
    g.awake = (flags & kAwake) != 0;
    g.sleep_time = r.fixed("particle group sleep time");
    g.force = r.vec3("particle group force");
    g.tether_impulse = r.fixed("particle group tether impulse");
    const std::size_t attachments_at = r.offset();
    const std::uint64_t attachments = r.var("attachment count");
    if (r.ok() && attachments > n)
      return failed_at(attachments_at, name + "attachment count " + std::to_string(attachments) +
                                           " is above its particle count " + std::to_string(n));
    for (std::uint64_t a = 0; a < attachments && r.ok(); ++a) {
      Attachment att;
      att.particle = r.var32("attachment particle");
      att.body = r.var32("attachment body");
      att.local = r.vec3("attachment local point");
      g.attachments.push_back(att);
    }
    if (!r.ok()) break;
    const std::size_t particles_at = r.offset();
    const std::uint64_t particles = r.var("particle count");
    if (!r.ok()) break;
    if (particles != n)
      return failed_at(particles_at, name + "particle count " + std::to_string(particles) +
                                         ", but its definition makes " + std::to_string(n));
    if (std::size_t{n} * 48 > r.remaining())
      return failed_at(r.offset(),
                       name + std::to_string(n) + " particles exceed what the data can hold");
    g.positions.resize(n);
    g.velocities.resize(n);
    for (std::uint32_t i = 0; i < n; ++i) {
      g.positions[i] = r.vec3("particle position");
      g.velocities[i] = r.vec3("particle velocity");
    }
    const std::size_t broken_at = r.offset();
    const std::uint64_t broken = r.var("broken count");
    if (!r.ok()) break;
    if (broken > r.remaining())
      return failed_at(broken_at, name + "broken count " + std::to_string(broken) +
                                      " exceeds what the data can hold");
    std::uint32_t last = 0;
    for (std::uint64_t b = 0; b < broken && r.ok(); ++b) {
      const std::size_t step_at = r.offset();
      const std::uint32_t delta = r.var32("broken constraint step");
      if (r.ok() && b > 0 && (delta == 0 || delta > 0xFFFFFFFFU - last))
        return failed_at(step_at, name + "broken constraints must ascend");
      last = b == 0 ? delta : last + delta;
      g.broken.push_back(last);
    }
    if (!r.ok()) break;
    if (auto e = check_particle_record(s, g); !e.empty()) return failed_at(at, name + e);
    // The constraints, from the definition; the broken ones must be among them.
    build_group(s, g);
    if (!g.broken.empty() && g.broken.back() >= g.links.size())
      return failed_at(broken_at, name + "broken constraint " + std::to_string(g.broken.back()) +
                                      " of " + std::to_string(g.links.size()));
    s.particle_groups.push_back(std::move(g));
  }
  return r.ok();
}

}  // namespace detsim::sim_detail
