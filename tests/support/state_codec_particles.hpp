// The "particles" section of the independent state codec (support/state_codec.hpp includes it),
// written from docs/STATE.md ("particles", version 1), not from state_particles.cpp.
//
// In brief: u32 next particle group ID (>= 1) | var group count | each group, ascending by ID:
// ID step var, type u8 (0 rope, 1 cloth, 2 soft body, 3 fluid), the definition:
//   rope:  start, end (fvec3), segments var, length, mass, radius, compliance, bending compliance
//          (fixed), attach start var, attach end var;
//   cloth: origin, axis u, axis v (fvec3), columns var, rows var, mass, thickness, stretch
//          compliance, bend compliance (fixed), pinned count var, pinned indices (first var, then
//          ascending steps var >= 1), attach body var, tear strain (fixed);
//   soft body: shape type u8 (2 box: half extents fvec3; 6 convex hull: geometry ID var),
//          position fvec3, orientation (w, x, y, z fixed), resolution var, mass, edge compliance,
//          volume compliance (fixed);
//   fluid: min, max (fvec3), spacing, rest density, viscosity, particle radius (fixed);
// then the settings: friction, damping (fixed), substeps var, layer u32, mask u32; flags u8 (bit 0
// awake), sleep time fixed, force fvec3, tether impulse fixed, attachment count var, each
// attachment: particle var, body var, local point fvec3; particle count var; per particle:
// position fvec3, velocity fvec3; broken count var, broken constraint
// indices (first var, then ascending steps var >= 1).
// `fixed` is the full-width i64 raw value and `fvec3` three of them: nothing in this section is a
// vfixed.
//
// The reader and writer are templates over support/state_codec.hpp's StateReader and StateWriter
// (defined after this header is included): decode_particles() is strict about what the layout
// says (ID steps, the type, the flag bits, index steps, counts against the bytes that remain) and
// leaves the simulation's own checks (ranges, bodies, limits) to World::restore.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/vec3.hpp>

namespace detsim::state_test {

// A particle group's flags.
inline constexpr std::uint8_t kGroupAwake = 1;
// Particle group types.
inline constexpr std::uint8_t kRope = 0;
inline constexpr std::uint8_t kCloth = 1;
inline constexpr std::uint8_t kSoftBody = 2;
inline constexpr std::uint8_t kFluid = 3;
/// The bytes of one particle (position and velocity, fvec3 each).
inline constexpr std::size_t kParticleBytes = 48;

struct DecodedParticleSettings {
  Fixed friction{};
  Fixed damping{};
  std::uint64_t substeps = 0;
  std::uint32_t layer = 0;
  std::uint32_t mask = 0;
};

struct DecodedRope {
  Vec3 start{};
  Vec3 end{};
  std::uint64_t segments = 0;
  Fixed length{};
  Fixed mass{};
  Fixed radius{};
  Fixed compliance{};
  Fixed bending_compliance{};
  std::uint64_t attach_start = 0;  // a body ID, 0 for none
  std::uint64_t attach_end = 0;
};

struct DecodedCloth {
  Vec3 origin{};
  Vec3 axis_u{};
  Vec3 axis_v{};
  std::uint64_t columns = 0;
  std::uint64_t rows = 0;
  Fixed mass{};
  Fixed thickness{};
  Fixed stretch_compliance{};
  Fixed bend_compliance{};
  /// The indices, not the steps: encode() writes each step modulo 2^32, so a list that does not
  /// ascend becomes a step restore refuses.
  std::vector<std::uint32_t> pinned;
  std::uint64_t attach_body = 0;
  Fixed tear_strain{};
};

struct DecodedSoftBody {
  std::uint8_t shape_type = 2;  // ShapeType: 2 box (half extents), 6 convex (a geometry ID)
  Vec3 half_extents{};
  std::uint64_t hull = 0;
  Vec3 position{};
  Fixed orientation_w{};
  Vec3 orientation_xyz{};
  std::uint64_t resolution = 0;
  Fixed mass{};
  Fixed edge_compliance{};
  Fixed volume_compliance{};
};

struct DecodedFluid {
  Vec3 min{};
  Vec3 max{};
  Fixed spacing{};
  Fixed rest_density{};
  Fixed viscosity{};
  Fixed particle_radius{};
};

struct DecodedAttachment {
  std::uint64_t particle = 0;
  std::uint64_t body = 0;
  Vec3 local{};
};

struct DecodedParticleGroup {
  std::uint64_t id_step = 0;  // the ID minus the previous group's
  std::uint8_t type = kRope;  // any byte; encode() writes the rope's fields for any other
  DecodedRope rope;           // when type is kRope
  DecodedCloth cloth;         // when type is kCloth
  DecodedSoftBody soft_body;  // when type is kSoftBody
  DecodedFluid fluid;         // when type is kFluid
  DecodedParticleSettings settings;
  std::uint8_t flags = 0;  // kGroupAwake
  Fixed sleep_time{};
  Vec3 force{};
  Fixed tether_impulse{};
  std::vector<DecodedAttachment> attachments;
  // Parallel, by particle index; encode() writes positions.size() particles, whatever the
  // definition says.
  std::vector<Vec3> positions;
  std::vector<Vec3> velocities;
  /// The indices, written as steps modulo 2^32 like the cloth's pinned list.
  std::vector<std::uint32_t> broken;
  // Filled by decode(), ignored by encode():
  std::uint32_t id = 0;
  std::size_t at = 0;  // the record, = its ID step
  std::size_t type_at = 0;
  std::size_t def_at = 0;
  std::size_t pinned_at = 0;  // a cloth's pinned count
  std::size_t flags_at = 0;
  std::size_t attachments_at = 0;  // the attachment count
  std::size_t particle_count_at = 0;
  std::size_t particles_at = 0;  // particle 0's position
  std::size_t broken_at = 0;     // the broken count
  std::size_t end = 0;

  [[nodiscard]] bool is_cloth() const { return type == kCloth; }
  /// Where particle i's position starts (its velocity is 24 bytes further).
  [[nodiscard]] std::size_t position_at(std::size_t i) const {
    return particles_at + i * kParticleBytes;
  }
};

/// The particles section as decode() found it.
struct DecodedParticles {
  std::uint32_t next_group_id = 1;
  std::vector<DecodedParticleGroup> groups;
  std::size_t next_group_id_at = 0;
  std::size_t group_count_at = 0;
};

// ---- Reading ----

template <class Reader>
Vec3 read_fvec3(Reader& r, const char* what) {
  const Fixed x = r.fixed(what);
  const Fixed y = r.fixed(what);
  return {x, y, r.fixed(what)};
}

/// An ascending list of 32-bit indices: `count` then the first index and the steps (>= 1).
template <class Reader>
std::vector<std::uint32_t> read_ascending(Reader& r, const char* count_what, const char* what) {
  std::vector<std::uint32_t> out;
  const std::size_t count_at = r.at();
  const std::uint64_t count = r.var(count_what, 64);
  // Each index takes at least a byte.
  if (r.ok() && count > r.remaining()) {
    r.fail(count_at, std::string(count_what) + ": beyond what the data can hold");
    return out;
  }
  std::uint64_t index = 0;
  for (std::uint64_t k = 0; k < count && r.ok(); ++k) {
    const std::size_t at = r.at();
    const std::uint64_t step = r.var(what, 32);
    if (r.ok() && k > 0 && step == 0) r.fail(at, std::string(what) + ": a step of zero");
    index = k == 0 ? step : index + step;
    if (r.ok() && index > 0xFFFFFFFFU) r.fail(at, std::string(what) + ": beyond 32 bits");
    out.push_back(static_cast<std::uint32_t>(index));
  }
  return out;
}

template <class Reader>
DecodedParticleSettings read_particle_settings(Reader& r) {
  DecodedParticleSettings p;
  p.friction = r.fixed("particle friction");
  p.damping = r.fixed("particle damping");
  p.substeps = r.var("particle substeps", 32);
  p.layer = r.u32("particle layer");
  p.mask = r.u32("particle mask");
  return p;
}

template <class Reader>
void read_particle_group(Reader& r, DecodedParticles& d, std::uint64_t& previous_id) {
  DecodedParticleGroup g;
  g.at = r.at();
  g.id_step = r.var("particle group ID step", 32);
  if (r.ok() && g.id_step == 0) r.fail(g.at, "particle group ID step: zero");
  const std::uint64_t id = previous_id + g.id_step;
  if (r.ok() && id >= d.next_group_id)
    r.fail(g.at, "particle group ID: not below the next particle group ID");
  previous_id = id;
  g.id = static_cast<std::uint32_t>(id);
  g.type_at = r.at();
  g.type = r.u8("particle group type");
  if (r.ok() && g.type > kFluid) r.fail(g.type_at, "particle group type: not 0, 1, 2 or 3");
  g.def_at = r.at();
  if (g.type == kFluid) {
    DecodedFluid& f = g.fluid;
    f.min = read_fvec3(r, "fluid min");
    f.max = read_fvec3(r, "fluid max");
    f.spacing = r.fixed("fluid spacing");
    f.rest_density = r.fixed("fluid rest density");
    f.viscosity = r.fixed("fluid viscosity");
    f.particle_radius = r.fixed("fluid particle radius");
  } else if (g.type == kSoftBody) {
    DecodedSoftBody& soft = g.soft_body;
    const std::size_t shape_at = r.at();
    soft.shape_type = r.u8("soft body shape type");
    if (soft.shape_type == 6) {
      soft.hull = r.var("soft body hull", 32);
    } else if (soft.shape_type == 2) {
      soft.half_extents = read_fvec3(r, "soft body half extents");
    } else if (r.ok()) {
      r.fail(shape_at, "soft body shape type: not a box (2) or a convex hull (6)");
    }
    soft.position = read_fvec3(r, "soft body position");
    soft.orientation_w = r.fixed("soft body orientation");
    soft.orientation_xyz = read_fvec3(r, "soft body orientation");
    soft.resolution = r.var("soft body resolution", 32);
    soft.mass = r.fixed("soft body mass");
    soft.edge_compliance = r.fixed("soft body edge compliance");
    soft.volume_compliance = r.fixed("soft body volume compliance");
  } else if (g.type == kRope) {
    DecodedRope& rope = g.rope;
    rope.start = read_fvec3(r, "rope start");
    rope.end = read_fvec3(r, "rope end");
    rope.segments = r.var("rope segments", 32);
    rope.length = r.fixed("rope length");
    rope.mass = r.fixed("rope mass");
    rope.radius = r.fixed("rope radius");
    rope.compliance = r.fixed("rope compliance");
    rope.bending_compliance = r.fixed("rope bending compliance");
    rope.attach_start = r.var("rope attach start", 32);
    rope.attach_end = r.var("rope attach end", 32);
  } else {
    DecodedCloth& cloth = g.cloth;
    cloth.origin = read_fvec3(r, "cloth origin");
    cloth.axis_u = read_fvec3(r, "cloth axis u");
    cloth.axis_v = read_fvec3(r, "cloth axis v");
    cloth.columns = r.var("cloth columns", 32);
    cloth.rows = r.var("cloth rows", 32);
    cloth.mass = r.fixed("cloth mass");
    cloth.thickness = r.fixed("cloth thickness");
    cloth.stretch_compliance = r.fixed("cloth stretch compliance");
    cloth.bend_compliance = r.fixed("cloth bend compliance");
    g.pinned_at = r.at();
    cloth.pinned = read_ascending(r, "cloth pinned count", "cloth pinned index");
    cloth.attach_body = r.var("cloth attach body", 32);
    cloth.tear_strain = r.fixed("cloth tear strain");
  }
  g.settings = read_particle_settings(r);
  g.flags_at = r.at();
  g.flags = r.u8("particle group flags");
  if (r.ok() && (g.flags & ~kGroupAwake) != 0)
    r.fail(g.flags_at, "particle group flags: an unknown bit");
  g.sleep_time = r.fixed("particle group sleep time");
  g.force = read_fvec3(r, "particle group force");
  g.tether_impulse = r.fixed("particle group tether impulse");
  g.attachments_at = r.at();
  const std::uint64_t attachments = r.var("attachment count", 64);
  // An attachment takes at least 26 bytes.
  if (r.ok() && attachments > r.remaining() / 26)
    r.fail(g.attachments_at, "attachment count: beyond what the data can hold");
  for (std::uint64_t k = 0; k < attachments && r.ok(); ++k) {
    DecodedAttachment a;
    a.particle = r.var("attachment particle", 32);
    a.body = r.var("attachment body", 32);
    a.local = read_fvec3(r, "attachment local point");
    g.attachments.push_back(a);
  }
  g.particle_count_at = r.at();
  const std::uint64_t particles = r.var("particle count", 64);
  g.particles_at = r.at();
  if (r.ok() && particles > r.remaining() / kParticleBytes)
    r.fail(g.particles_at, "particles: beyond what the data can hold");
  for (std::uint64_t i = 0; i < particles && r.ok(); ++i) {
    g.positions.push_back(read_fvec3(r, "particle position"));
    g.velocities.push_back(read_fvec3(r, "particle velocity"));
  }
  g.broken_at = r.at();
  g.broken = read_ascending(r, "broken count", "broken constraint index");
  g.end = r.at();
  d.groups.push_back(std::move(g));
}

/// The section's payload (the reader at its first byte).
template <class Reader>
void read_particles_section(Reader& r, DecodedParticles& d) {
  d.next_group_id_at = r.at();
  d.next_group_id = r.u32("next particle group ID");
  if (r.ok() && d.next_group_id == 0) r.fail(d.next_group_id_at, "next particle group ID: zero");
  d.group_count_at = r.at();
  const std::uint64_t count = r.var("particle group count", 64);
  // A group takes well over 48 bytes (at least two particles).
  if (r.ok() && count > r.remaining() / (2 * kParticleBytes))
    r.fail(d.group_count_at, "particle group count: beyond what the data can hold");
  std::uint64_t previous_id = 0;
  for (std::uint64_t k = 0; k < count && r.ok(); ++k)
    read_particle_group(r, d, previous_id);
}

// ---- Writing ----

template <class Writer>
void write_fvec3(Writer& w, Vec3 v) {
  w.fixed(v.x);
  w.fixed(v.y);
  w.fixed(v.z);
}

/// `list` as a count and steps, each step modulo 2^32 (a list that does not ascend is written as
/// such, for tests of refusals).
template <class Writer>
void write_ascending(Writer& w, const std::vector<std::uint32_t>& list) {
  w.var(list.size());
  for (std::size_t k = 0; k < list.size(); ++k)
    w.var(k == 0 ? list[k] : static_cast<std::uint32_t>(list[k] - list[k - 1]));
}

template <class Writer>
void write_particle_group(Writer& w, const DecodedParticleGroup& g) {
  w.var(g.id_step);
  w.u8(g.type);
  if (g.type == kFluid) {
    const DecodedFluid& f = g.fluid;
    write_fvec3(w, f.min);
    write_fvec3(w, f.max);
    for (const Fixed x : {f.spacing, f.rest_density, f.viscosity, f.particle_radius})
      w.fixed(x);
  } else if (g.type == kSoftBody) {
    const DecodedSoftBody& soft = g.soft_body;
    w.u8(soft.shape_type);
    if (soft.shape_type == 6)
      w.var(soft.hull);
    else
      write_fvec3(w, soft.half_extents);
    write_fvec3(w, soft.position);
    w.fixed(soft.orientation_w);
    write_fvec3(w, soft.orientation_xyz);
    w.var(soft.resolution);
    for (const Fixed f : {soft.mass, soft.edge_compliance, soft.volume_compliance})
      w.fixed(f);
  } else if (g.type != kCloth) {
    const DecodedRope& rope = g.rope;
    write_fvec3(w, rope.start);
    write_fvec3(w, rope.end);
    w.var(rope.segments);
    for (const Fixed f :
         {rope.length, rope.mass, rope.radius, rope.compliance, rope.bending_compliance})
      w.fixed(f);
    w.var(rope.attach_start);
    w.var(rope.attach_end);
  } else {
    const DecodedCloth& cloth = g.cloth;
    write_fvec3(w, cloth.origin);
    write_fvec3(w, cloth.axis_u);
    write_fvec3(w, cloth.axis_v);
    w.var(cloth.columns);
    w.var(cloth.rows);
    for (const Fixed f :
         {cloth.mass, cloth.thickness, cloth.stretch_compliance, cloth.bend_compliance})
      w.fixed(f);
    write_ascending(w, cloth.pinned);
    w.var(cloth.attach_body);
    w.fixed(cloth.tear_strain);
  }
  w.fixed(g.settings.friction);
  w.fixed(g.settings.damping);
  w.var(g.settings.substeps);
  w.u32(g.settings.layer);
  w.u32(g.settings.mask);
  w.u8(g.flags);
  w.fixed(g.sleep_time);
  write_fvec3(w, g.force);
  w.fixed(g.tether_impulse);
  w.var(g.attachments.size());
  for (const DecodedAttachment& a : g.attachments) {
    w.var(a.particle);
    w.var(a.body);
    write_fvec3(w, a.local);
  }
  w.var(g.positions.size());
  for (std::size_t i = 0; i < g.positions.size(); ++i) {
    write_fvec3(w, g.positions[i]);
    write_fvec3(w, i < g.velocities.size() ? g.velocities[i] : Vec3{});
  }
  write_ascending(w, g.broken);
}

/// The section's payload.
template <class Writer>
void write_particles_section(Writer& w, const DecodedParticles& d) {
  w.u32(d.next_group_id);
  w.var(d.groups.size());
  for (const DecodedParticleGroup& g : d.groups)
    write_particle_group(w, g);
}

}  // namespace detsim::state_test
