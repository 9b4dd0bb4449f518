// Particle groups from their definitions: checks, rest layouts, constraints (docs/PARTICLES.md).
#include "group.hpp"

#include <detsim/fixed/decimal.hpp>
#include <detsim/fixed/math.hpp>

#include "../limits.hpp"
#include "../world_state.hpp"

namespace detsim::sim_detail {

namespace {

using namespace detsim::literals;

// Sizes a group may span: as the shapes (10^4 m), so that positions, rest lengths and their
// products with particle indices stay far inside the Q32.32 range.
constexpr Fixed kMaxExtent = Fixed::from_int(10000);
// The lightest particle: its inverse mass (2^20 per kg) and the impulses it takes stay exact.
constexpr Fixed kMinParticleMass = Fixed::from_raw(Fixed::one_raw >> 20);
constexpr Fixed kMaxMass = Fixed::from_int(1000000);
constexpr Fixed kMaxCompliance = Fixed::from_int(1000);
constexpr Fixed kMaxRadius = Fixed::from_int(10);
// The shortest link, 2^-7 m (7.8 mm): the solver works on squared lengths, whose resolution
// (2^-32 m^2) is then 2^-18 of the square, so that strains stay resolved to about 10^-6.
constexpr Fixed kMinLink = Fixed::from_raw(Fixed::one_raw >> 7);

std::string num(Fixed x) {
  return to_string(x);
}

std::string in_range(const char* what, Fixed x, Fixed lo, Fixed hi, const char* unit) {
  if (x < lo || x > hi)
    return std::string(what) + " must be within " + num(lo) + " .. " + num(hi) + " " + unit +
           ", got " + num(x);
  return {};
}

std::string check_settings(const ParticleSettings& p) {
  if (auto e = in_range("friction", p.friction, Fixed::zero(), Fixed::from_int(100), "");
      !e.empty())
    return e;
  if (auto e = in_range("damping", p.damping, Fixed::zero(), Fixed::from_int(1000), "1/s");
      !e.empty())
    return e;
  if (p.substeps < 1 || p.substeps > 16)
    return "substeps must be within 1 .. 16, got " + std::to_string(p.substeps);
  return {};
}

std::string check_attach(const WorldState& s, const char* what, BodyId body) {
  if (!body.is_null() && s.find(body.value) < 0)
    return std::string(what) + " is body " + std::to_string(body.value) + ", which does not exist";
  return {};
}

std::string check_mass(Fixed mass, std::uint32_t count) {
  if (auto e = in_range("mass", mass, kMinParticleMass, kMaxMass, "kg"); !e.empty()) return e;
  if (mass / Fixed::from_int(static_cast<std::int32_t>(count)) < kMinParticleMass)
    return "mass " + num(mass) + " kg over " + std::to_string(count) +
           " particles is below the lightest particle, " + num(kMinParticleMass) + " kg";
  return {};
}

Fixed count_fx(std::uint32_t n) {
  return Fixed::from_int(static_cast<std::int32_t>(n));
}

Fixed rope_length(const RopeDef& def) {
  return def.length == Fixed::zero() ? length(def.end - def.start) : def.length;
}

void add_link(ParticleGroup& g, std::uint32_t a, std::uint32_t b, Fixed compliance, LinkKind kind,
              const std::vector<Vec3>& rest) {
  g.links.push_back({a, b, length(rest[b] - rest[a]), compliance, kind});
}

}  // namespace

const ParticleSettings& ParticleGroup::settings() const noexcept {
  return std::visit([](const auto& d) -> const ParticleSettings& { return d.settings; }, def);
}

std::uint32_t particle_count(const RopeDef& def) noexcept {
  return def.segments + 1;
}

std::uint32_t particle_count(const ClothDef& def) noexcept {
  return def.columns * def.rows;
}

std::string check_rope_def(const WorldState& s, const RopeDef& def, bool bodies) {
  if (auto e = check_components("start", def.start, max_position, "m"); !e.empty()) return e;
  if (auto e = check_components("end", def.end, max_position, "m"); !e.empty()) return e;
  if (def.segments < 1 || def.segments >= max_particles_per_group)
    return "segments must be within 1 .. " + std::to_string(max_particles_per_group - 1) +
           ", got " + std::to_string(def.segments);
  const Vec3 span = def.end - def.start;
  if (beyond(span.x, kMaxExtent) || beyond(span.y, kMaxExtent) || beyond(span.z, kMaxExtent))
    return "end - start must be within +-" + num(kMaxExtent) + " m per component";
  const Fixed distance = length(span);
  if (distance == Fixed::zero() && def.length == Fixed::zero())
    return "length must be > 0 when start and end coincide";
  if (def.length != Fixed::zero() && def.length < distance)
    return "length must be >= |end - start| (" + num(distance) + " m), got " + num(def.length);
  if (auto e = in_range("length", def.length, Fixed::zero(), kMaxExtent, "m"); !e.empty()) return e;
  if (rope_length(def) / count_fx(def.segments) < kMinLink)
    return "length / segments must be at least " + num(kMinLink) + " m, got " +
           num(rope_length(def) / count_fx(def.segments));
  if (auto e = check_mass(def.mass, particle_count(def)); !e.empty()) return e;
  if (auto e = in_range("radius", def.radius, Fixed::from_raw(1), kMaxRadius, "m"); !e.empty())
    return e;
  if (auto e = in_range("compliance", def.compliance, Fixed::zero(), kMaxCompliance, "m/N");
      !e.empty())
    return e;
  if (auto e = in_range("bending_compliance", def.bending_compliance, Fixed::zero(), kMaxCompliance,
                        "m/N");
      !e.empty())
    return e;
  if (bodies) {
    if (auto e = check_attach(s, "attach_start", def.attach_start); !e.empty()) return e;
    if (auto e = check_attach(s, "attach_end", def.attach_end); !e.empty()) return e;
  }
  return check_settings(def.settings);
}

std::string check_cloth_def(const WorldState& s, const ClothDef& def, bool bodies) {
  if (auto e = check_components("origin", def.origin, max_position, "m"); !e.empty()) return e;
  if (auto e = check_components("axis_u", def.axis_u, kMaxExtent, "m"); !e.empty()) return e;
  if (auto e = check_components("axis_v", def.axis_v, kMaxExtent, "m"); !e.empty()) return e;
  if (def.columns < 2 || def.rows < 2)
    return "columns and rows must be >= 2, got " + std::to_string(def.columns) + " x " +
           std::to_string(def.rows);
  if (std::uint64_t{def.columns} * def.rows > max_particles_per_group)
    return "columns * rows must be at most " + std::to_string(max_particles_per_group) + ", got " +
           std::to_string(std::uint64_t{def.columns} * def.rows);
  if (length_squared(cross(def.axis_u, def.axis_v)) == Fixed::zero())
    return "axis_u and axis_v must span a sheet (not zero, not parallel)";
  constexpr Fixed kMinSpacing = kMinLink;
  if (length(def.axis_u) / count_fx(def.columns - 1) < kMinSpacing ||
      length(def.axis_v) / count_fx(def.rows - 1) < kMinSpacing)
    return "the particles must be at least " + num(kMinSpacing) +
           " m apart (|axis_u| / (columns - 1), |axis_v| / (rows - 1))";
  if (auto e = check_mass(def.mass, particle_count(def)); !e.empty()) return e;
  if (auto e = in_range("thickness", def.thickness, Fixed::from_raw(2), kMaxRadius, "m");
      !e.empty())
    return e;
  if (auto e = in_range("stretch_compliance", def.stretch_compliance, Fixed::zero(), kMaxCompliance,
                        "m/N");
      !e.empty())
    return e;
  if (auto e =
          in_range("bend_compliance", def.bend_compliance, Fixed::zero(), kMaxCompliance, "m/N");
      !e.empty())
    return e;
  if (auto e = in_range("tear_strain", def.tear_strain, Fixed::zero(), Fixed::from_int(1000), "");
      !e.empty())
    return e;
  const std::uint32_t n = particle_count(def);
  for (std::size_t k = 0; k < def.pinned.size(); ++k) {
    if (def.pinned[k] >= n)
      return "pinned[" + std::to_string(k) + "] is particle " + std::to_string(def.pinned[k]) +
             ", but the sheet has " + std::to_string(n);
    if (k > 0 && def.pinned[k] <= def.pinned[k - 1])
      return "pinned must be ascending without repeats (pinned[" + std::to_string(k) + "] is " +
             std::to_string(def.pinned[k]) + ")";
  }
  if (!def.attach_body.is_null() && def.pinned.empty())
    return "attach_body is set, but no particle is pinned to it";
  if (bodies) {
    if (auto e = check_attach(s, "attach_body", def.attach_body); !e.empty()) return e;
  }
  return check_settings(def.settings);
}

std::vector<Vec3> rest_positions(const RopeDef& def) {
  const std::uint32_t n = particle_count(def);
  std::vector<Vec3> out(n);
  const Vec3 span = def.end - def.start;
  const Fixed segments = count_fx(def.segments);
  for (std::uint32_t i = 0; i < n; ++i)
    out[i] = def.start + span * count_fx(i) / segments;
  out[n - 1] = def.end;
  return out;
}

std::vector<Vec3> rest_positions(const ClothDef& def) {
  std::vector<Vec3> out(particle_count(def));
  const Fixed cu = count_fx(def.columns - 1);
  const Fixed rv = count_fx(def.rows - 1);
  for (std::uint32_t r = 0; r < def.rows; ++r) {
    const Vec3 row = def.origin + def.axis_v * count_fx(r) / rv;
    for (std::uint32_t c = 0; c < def.columns; ++c)
      out[r * def.columns + c] = row + def.axis_u * count_fx(c) / cu;
  }
  return out;
}

namespace {

void build_rope(ParticleGroup& g, const RopeDef& def) {
  const std::uint32_t n = particle_count(def);
  const Fixed segment = rope_length(def) / count_fx(def.segments);
  const Fixed compliance = def.compliance / count_fx(def.segments);
  g.radius = def.radius;
  g.links.reserve(2 * static_cast<std::size_t>(n));
  for (std::uint32_t i = 0; i + 1 < n; ++i)
    g.links.push_back({i, i + 1, segment, compliance, LinkKind::rope});
  for (std::uint32_t i = 0; i + 2 < n; ++i)
    g.links.push_back({i, i + 2, segment * 2, def.bending_compliance, LinkKind::bend});
  // Long-range attachments to each attached end, for an inextensible rope: the rest path length
  // along the rope is the most a particle can be from that end.
  if (def.compliance != Fixed::zero()) return;
  for (std::uint32_t i = 0; i < n; ++i) {
    if (!def.attach_start.is_null() && i != 0) g.tethers.push_back({i, 0, segment * count_fx(i)});
    if (!def.attach_end.is_null() && i != n - 1)
      g.tethers.push_back({i, n - 1, segment * count_fx(n - 1 - i)});
  }
}

void build_cloth(ParticleGroup& g, const ClothDef& def) {
  const std::vector<Vec3> rest = rest_positions(def);
  const std::uint32_t cols = def.columns;
  const std::uint32_t rows = def.rows;
  g.radius = def.thickness * Fixed::half();
  const auto at = [cols](std::uint32_t r, std::uint32_t c) { return r * cols + c; };
  const Fixed stretch = def.stretch_compliance;
  g.links.reserve(6 * static_cast<std::size_t>(rows) * cols);
  for (std::uint32_t r = 0; r < rows; ++r) {
    for (std::uint32_t c = 0; c < cols; ++c) {
      if (c + 1 < cols) add_link(g, at(r, c), at(r, c + 1), stretch, LinkKind::stretch, rest);
      if (r + 1 < rows) add_link(g, at(r, c), at(r + 1, c), stretch, LinkKind::stretch, rest);
    }
  }
  for (std::uint32_t r = 0; r + 1 < rows; ++r) {
    for (std::uint32_t c = 0; c + 1 < cols; ++c) {
      add_link(g, at(r, c), at(r + 1, c + 1), stretch, LinkKind::shear, rest);
      add_link(g, at(r, c + 1), at(r + 1, c), stretch, LinkKind::shear, rest);
    }
  }
  for (std::uint32_t r = 0; r < rows; ++r) {
    for (std::uint32_t c = 0; c < cols; ++c) {
      if (c + 2 < cols)
        add_link(g, at(r, c), at(r, c + 2), def.bend_compliance, LinkKind::bend, rest);
      if (r + 2 < rows)
        add_link(g, at(r, c), at(r + 2, c), def.bend_compliance, LinkKind::bend, rest);
    }
  }
  const std::uint32_t n = particle_count(def);
  if (def.attach_body.is_null()) {
    g.pinned.assign(n, false);
    for (std::uint32_t p : def.pinned)
      g.pinned[p] = true;
  }
  // Long-range attachments of an unstretchable sheet: each free particle stays within its rest
  // distance (the sheet is flat at rest, so the straight line is the shortest path in it) of the
  // nearest pinned particle (ties: the lower index).
  if (stretch != Fixed::zero() || def.pinned.empty() || def.tear_strain != Fixed::zero()) return;
  std::vector<bool> is_pin(n, false);
  for (std::uint32_t p : def.pinned)
    is_pin[p] = true;
  for (std::uint32_t i = 0; i < n; ++i) {
    if (is_pin[i]) continue;
    std::uint32_t best = def.pinned.front();
    Fixed best_d2 = length_squared(rest[i] - rest[best]);
    for (std::uint32_t p : def.pinned) {
      const Fixed d2 = length_squared(rest[i] - rest[p]);
      if (d2 < best_d2) {
        best = p;
        best_d2 = d2;
      }
    }
    g.tethers.push_back({i, best, length(rest[i] - rest[best])});
  }
}

}  // namespace

void build_group(ParticleGroup& g) {
  g.links.clear();
  g.tethers.clear();
  g.pinned.clear();
  const std::uint32_t n = static_cast<std::uint32_t>(g.positions.size());
  std::visit(
      [&](const auto& def) {
        g.particle_mass = def.mass / count_fx(n);
        using Def = std::decay_t<decltype(def)>;
        if constexpr (std::is_same_v<Def, RopeDef>) {
          build_rope(g, def);
        } else {
          build_cloth(g, def);
        }
      },
      g.def);
  g.inverse_mass = Fixed::one() / g.particle_mass;
  g.link_broken.assign(g.links.size(), false);
  for (std::uint32_t k : g.broken) {
    if (k < g.link_broken.size()) g.link_broken[k] = true;  // restore refuses any other
  }
}

namespace {

// The body-frame point of world point p on body `id` at its present pose.
Attachment attach(const WorldState& s, std::uint32_t particle, BodyId id, Vec3 p) {
  const BodyState& b = s.bodies[static_cast<std::size_t>(s.find(id.value))];
  return {particle, id.value, rotate(conjugate(b.orientation), p - b.position)};
}

}  // namespace

ParticleGroup make_group(const WorldState& s, ParticleGroupId id, const RopeDef& def) {
  ParticleGroup g;
  g.id = id;
  g.type = ParticleGroupType::rope;
  g.def = def;
  g.positions = rest_positions(def);
  g.velocities.assign(g.positions.size(), Vec3{});
  const auto last = static_cast<std::uint32_t>(g.positions.size() - 1);
  if (!def.attach_start.is_null())
    g.attachments.push_back(attach(s, 0, def.attach_start, g.positions[0]));
  if (!def.attach_end.is_null())
    g.attachments.push_back(attach(s, last, def.attach_end, g.positions[last]));
  build_group(g);
  return g;
}

ParticleGroup make_group(const WorldState& s, ParticleGroupId id, const ClothDef& def) {
  ParticleGroup g;
  g.id = id;
  g.type = ParticleGroupType::cloth;
  g.def = def;
  g.positions = rest_positions(def);
  g.velocities.assign(g.positions.size(), Vec3{});
  if (!def.attach_body.is_null()) {
    for (std::uint32_t p : def.pinned)
      g.attachments.push_back(attach(s, p, def.attach_body, g.positions[p]));
  }
  build_group(g);
  return g;
}

ParticleGroupStats group_stats(const ParticleGroup& g) {
  ParticleGroupStats st;
  st.type = g.type;
  st.particle_count = static_cast<std::uint32_t>(g.size());
  st.constraint_count = static_cast<std::uint32_t>(g.links.size());
  st.broken_count = static_cast<std::uint32_t>(g.broken.size());
  st.awake = g.awake;
  Fixed v2_sum;
  Fixed max_v2;
  for (const Vec3& v : g.velocities) {
    const Fixed v2 = length_squared(v);
    v2_sum += v2;
    max_v2 = max(max_v2, v2);
  }
  st.kinetic_energy = v2_sum * g.particle_mass * Fixed::half();
  st.max_speed = sqrt(max_v2);
  for (std::size_t k = 0; k < g.links.size(); ++k) {
    const Link& l = g.links[k];
    if (g.link_broken[k] || l.kind == LinkKind::bend || l.kind == LinkKind::shear) continue;
    const Fixed d = length(g.positions[l.b] - g.positions[l.a]);
    st.max_strain = max(st.max_strain, d / l.rest - Fixed::one());
  }
  return st;
}

}  // namespace detsim::sim_detail
