// Particle groups from their definitions: checks, rest layouts, constraints (docs/PARTICLES.md).
#include "group.hpp"

#include <detsim/fixed/decimal.hpp>
#include <detsim/fixed/math.hpp>

#include <algorithm>
#include <array>

#include "../limits.hpp"
#include "../shapes.hpp"
#include "../world_state.hpp"
#include "fluid.hpp"

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

namespace {

// A soft body's lattice in its own frame: the particles (cell centres of a cubic grid over the
// shape's box, kept where the shape contains them) and the cubes of eight kept neighbours.
struct SoftLayout {
  std::vector<Vec3> local;
  std::vector<std::array<std::uint32_t, 8>> cubes;  ///< corners by bits (x 1, y 2, z 4)
  Fixed spacing;
  std::string error;
};

constexpr Fixed kMinSoftSpacing = Fixed::from_raw(Fixed::one_raw / 100);  // 1 cm

SoftLayout soft_layout(const WorldState& s, const SoftBodyDef& def) {
  SoftLayout out;
  const Geometry* g = s.geometry(def.shape);
  const ShapeKind& kind = shape_kind(def.shape.type);
  // The shape's bounding box in its frame: a box's, or a hull's corners' (its extent about the
  // origin would be wider where the hull is not centred on it).
  Vec3 lo = -def.shape.half_extents;
  Vec3 hi = def.shape.half_extents;
  if (g != nullptr) {
    lo = hi = g->hull().vertices.front();
    for (const Vec3& v : g->hull().vertices) {
      lo = {min(lo.x, v.x), min(lo.y, v.y), min(lo.z, v.z)};
      hi = {max(hi.x, v.x), max(hi.y, v.y), max(hi.z, v.z)};
    }
  }
  const Vec3 e = (hi - lo) * Fixed::half();
  const Vec3 centre = lo + e;
  const Fixed longest = max(e.x, max(e.y, e.z)) * 2;
  out.spacing = longest / count_fx(def.resolution);
  if (out.spacing < kMinSoftSpacing) {
    out.error = "resolution " + std::to_string(def.resolution) + " makes cells of " +
                num(out.spacing) + " m, below the smallest, " + num(kMinSoftSpacing) + " m";
    return out;
  }
  // Cells per axis: the side over the spacing, to nearest; particles at the cells' centres.
  const auto cells = [&](Fixed half) {
    return static_cast<std::uint32_t>((half * 2 / out.spacing).to_int());
  };
  const std::array<std::uint32_t, 3> n{cells(e.x), cells(e.y), cells(e.z)};
  if (n[0] < 2 || n[1] < 2 || n[2] < 2) {
    out.error = "resolution " + std::to_string(def.resolution) +
                " gives fewer than 2 particles along an axis of the shape";
    return out;
  }
  const auto at = [&](std::uint32_t i, std::uint32_t j, std::uint32_t k) {
    // The lattice centred in the box (its cells may not divide every side exactly).
    return centre +
           Vec3{out.spacing * (count_fx(i) + Fixed::half() - count_fx(n[0]) * Fixed::half()),
                out.spacing * (count_fx(j) + Fixed::half() - count_fx(n[1]) * Fixed::half()),
                out.spacing * (count_fx(k) + Fixed::half() - count_fx(n[2]) * Fixed::half())};
  };
  // Lattice points inside the shape, x fastest; their index among the kept ones.
  const std::size_t total = std::size_t{n[0]} * n[1] * n[2];
  std::vector<std::int64_t> index(total, -1);
  std::vector<bool> inside(total, false);
  for (std::uint32_t k = 0; k < n[2]; ++k)
    for (std::uint32_t j = 0; j < n[1]; ++j)
      for (std::uint32_t i = 0; i < n[0]; ++i)
        inside[(std::size_t{k} * n[1] + j) * n[0] + i] = kind.contains(def.shape, g, at(i, j, k));
  // Cubes whose eight corners are all inside; their corners are the particles, in lattice order.
  std::vector<std::array<std::size_t, 8>> cubes;
  for (std::uint32_t k = 0; k + 1 < n[2]; ++k)
    for (std::uint32_t j = 0; j + 1 < n[1]; ++j)
      for (std::uint32_t i = 0; i + 1 < n[0]; ++i) {
        std::array<std::size_t, 8> c{};
        bool all = true;
        for (std::uint32_t b = 0; b < 8; ++b) {
          c[b] = (std::size_t{k + ((b >> 2) & 1)} * n[1] + (j + ((b >> 1) & 1))) * n[0] +
                 (i + (b & 1));
          all = all && inside[c[b]];
        }
        if (all) cubes.push_back(c);
      }
  for (const auto& c : cubes)
    for (std::size_t v : c)
      index[v] = 0;
  for (std::uint32_t k = 0; k < n[2]; ++k)
    for (std::uint32_t j = 0; j < n[1]; ++j)
      for (std::uint32_t i = 0; i < n[0]; ++i) {
        std::int64_t& slot = index[(std::size_t{k} * n[1] + j) * n[0] + i];
        if (slot < 0) continue;
        slot = static_cast<std::int64_t>(out.local.size());
        out.local.push_back(at(i, j, k));
      }
  for (const auto& c : cubes) {
    std::array<std::uint32_t, 8> cube{};
    for (std::size_t b = 0; b < 8; ++b)
      cube[b] = static_cast<std::uint32_t>(index[c[b]]);
    out.cubes.push_back(cube);
  }
  if (out.cubes.empty())
    out.error = "the shape holds no whole cell at resolution " + std::to_string(def.resolution);
  return out;
}

Fixed triple(Vec3 x0, Vec3 x1, Vec3 x2, Vec3 x3) {
  return dot(x1 - x0, cross(x2 - x0, x3 - x0));
}

}  // namespace

std::uint32_t particle_count(const WorldState& s, const SoftBodyDef& def) {
  return static_cast<std::uint32_t>(soft_layout(s, def).local.size());
}

std::string check_soft_body_def(const WorldState& s, const SoftBodyDef& def) {
  if (def.shape.type != ShapeType::box && def.shape.type != ShapeType::convex)
    return "shape must be a box or a convex hull";
  if (auto e = check_shape(s.geometries, def.shape, BodyType::dynamic); !e.empty())
    return "shape: " + e;
  if (auto e = check_components("position", def.position, max_position, "m"); !e.empty()) return e;
  if (auto e = check_orientation(def.orientation); !e.empty()) return e;
  if (def.resolution < 1 || def.resolution > 40)
    return "resolution must be within 1 .. 40, got " + std::to_string(def.resolution);
  const SoftLayout layout = soft_layout(s, def);
  if (!layout.error.empty()) return layout.error;
  if (auto e = check_mass(def.mass, static_cast<std::uint32_t>(layout.local.size())); !e.empty())
    return e;
  if (auto e =
          in_range("edge_compliance", def.edge_compliance, Fixed::zero(), kMaxCompliance, "m/N");
      !e.empty())
    return e;
  if (auto e = in_range("volume_compliance", def.volume_compliance, Fixed::zero(), kMaxCompliance,
                        "m^3/(N m)");
      !e.empty())
    return e;
  return check_settings(def.settings);
}

std::vector<Vec3> rest_positions(const WorldState& s, const SoftBodyDef& def) {
  std::vector<Vec3> out = soft_layout(s, def).local;
  for (Vec3& p : out)
    p = def.position + rotate(def.orientation, p);
  return out;
}

namespace {

// A fluid's particles along one axis: as many centres min + spacing * (i + 1/2) as fit whole in
// [min, max], allowing 1/1024 of a spacing (so that max = min + 20 * spacing makes 20 when the
// spacing, 0.05 say, has no exact binary value); 0 when none does.
std::uint64_t fluid_axis(Fixed lo, Fixed hi, Fixed spacing) {
  if (hi <= lo) return 0;
  const auto s = static_cast<std::uint64_t>(spacing.raw());
  return (static_cast<std::uint64_t>((hi - lo).raw()) + s / 1024) / s;
}

std::array<std::uint64_t, 3> fluid_counts(const FluidDef& def) {
  return {fluid_axis(def.min.x, def.max.x, def.spacing),
          fluid_axis(def.min.y, def.max.y, def.spacing),
          fluid_axis(def.min.z, def.max.z, def.spacing)};
}

// The densest and lightest fluids: water is 1000 kg/m^3, mercury 13 534, air 1.2.
constexpr Fixed kMinDensity = Fixed::one();
constexpr Fixed kMaxDensity = Fixed::from_int(100000);
constexpr Fixed kMaxSpacing = Fixed::from_int(10);

}  // namespace

std::uint32_t particle_count(const FluidDef& def) noexcept {
  if (def.spacing <= Fixed::zero()) return 0;
  const auto c = fluid_counts(def);
  const std::uint64_t limit = max_particles_per_group;
  if (c[0] > limit || c[1] > limit || c[2] > limit || c[0] * c[1] > limit ||
      c[0] * c[1] * c[2] > limit)
    return 0;
  return static_cast<std::uint32_t>(c[0] * c[1] * c[2]);
}

std::string check_fluid_def(const FluidDef& def) {
  if (auto e = check_components("min", def.min, max_position, "m"); !e.empty()) return e;
  if (auto e = check_components("max", def.max, max_position, "m"); !e.empty()) return e;
  if (auto e = in_range("spacing", def.spacing, kMinLink, kMaxSpacing, "m"); !e.empty()) return e;
  const Vec3 span = def.max - def.min;
  if (beyond(span.x, kMaxExtent) || beyond(span.y, kMaxExtent) || beyond(span.z, kMaxExtent))
    return "max - min must be within +-" + num(kMaxExtent) + " m per component";
  const auto c = fluid_counts(def);
  static constexpr std::array<const char*, 3> kAxis{"x", "y", "z"};
  for (std::size_t k = 0; k < 3; ++k) {
    if (c[k] == 0)
      return std::string("max.") + kAxis[k] + " - min." + kAxis[k] +
             " must be at least the spacing (" + num(def.spacing) + " m): no particle fits";
  }
  if (particle_count(def) == 0)
    return std::to_string(c[0]) + " x " + std::to_string(c[1]) + " x " + std::to_string(c[2]) +
           " particles: above max_particles_per_group " + std::to_string(max_particles_per_group);
  // Every group has at least two particles (a rope of one segment); a fluid of one is a ball.
  if (c[0] * c[1] * c[2] < 2)
    return "1 x 1 x 1 particles: a fluid needs at least 2 (max - min at least twice the spacing "
           "along an axis)";
  if (auto e = in_range("rest_density", def.rest_density, kMinDensity, kMaxDensity, "kg/m^3");
      !e.empty())
    return e;
  const Fixed mass = def.rest_density * def.spacing * def.spacing * def.spacing;
  if (mass < kMinParticleMass || mass > kMaxMass)
    return "rest_density * spacing^3 (each particle's mass) must be within " +
           num(kMinParticleMass) + " .. " + num(kMaxMass) + " kg, got " + num(mass);
  if (auto e = in_range("viscosity", def.viscosity, Fixed::zero(), Fixed::one(), ""); !e.empty())
    return e;
  if (def.particle_radius <= Fixed::zero() || def.particle_radius > def.spacing)
    return "particle_radius must be within 0 (excluded) .. the spacing " + num(def.spacing) +
           " m, got " + num(def.particle_radius);
  return check_settings(def.settings);
}

std::vector<Vec3> rest_positions(const FluidDef& def) {
  const auto c = fluid_counts(def);
  std::vector<Vec3> out;
  out.reserve(particle_count(def));
  const Fixed s = def.spacing;
  const auto at = [&](Fixed lo, std::uint64_t i) {
    return lo + s * Fixed::from_int(static_cast<std::int32_t>(i)) + s * Fixed::half();
  };
  // Index = (y * nz + z) * nx + x: layer by layer from the bottom.
  for (std::uint64_t y = 0; y < c[1]; ++y)
    for (std::uint64_t z = 0; z < c[2]; ++z)
      for (std::uint64_t x = 0; x < c[0]; ++x)
        out.push_back({at(def.min.x, x), at(def.min.y, y), at(def.min.z, z)});
  return out;
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

namespace {

// A soft body's links (every tetrahedron's edges, once each, ascending) and tetrahedra.
void build_soft_body(const WorldState& s, ParticleGroup& g, const SoftBodyDef& def) {
  const SoftLayout layout = soft_layout(s, def);
  g.radius = layout.spacing * Fixed::half();
  // Freudenthal's six tetrahedra of a cube: from corner 0 to corner 7 through one axis, then two.
  constexpr std::array<std::array<std::uint32_t, 2>, 6> kPaths{
      {{1, 3}, {1, 5}, {2, 3}, {2, 6}, {4, 5}, {4, 6}}};
  std::vector<std::array<std::uint32_t, 2>> edges;
  for (const auto& cube : layout.cubes) {
    for (const auto& path : kPaths) {
      Tetrahedron t;
      t.corners = {cube[0], cube[path[0]], cube[path[1]], cube[7]};
      t.rest_triple = triple(layout.local[t.corners[0]], layout.local[t.corners[1]],
                             layout.local[t.corners[2]], layout.local[t.corners[3]]);
      g.tetrahedra.push_back(t);
      for (std::size_t a = 0; a < 4; ++a)
        for (std::size_t b = a + 1; b < 4; ++b)
          edges.push_back(
              {std::min(t.corners[a], t.corners[b]), std::max(t.corners[a], t.corners[b])});
    }
  }
  std::sort(edges.begin(), edges.end());  // a total order on (a, b): no ties between equals
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  for (const auto& e : edges)
    add_link(g, e[0], e[1], def.edge_compliance, LinkKind::stretch, layout.local);
}

}  // namespace

void build_group(const WorldState& s, ParticleGroup& g) {
  g.links.clear();
  g.tethers.clear();
  g.pinned.clear();
  g.tetrahedra.clear();
  const std::uint32_t n = static_cast<std::uint32_t>(g.positions.size());
  std::visit(
      [&](const auto& def) {
        using Def = std::decay_t<decltype(def)>;
        if constexpr (std::is_same_v<Def, FluidDef>) {
          g.particle_mass = def.rest_density * def.spacing * def.spacing * def.spacing;
          g.radius = def.particle_radius;
          build_fluid_kernel(g, def.spacing);
        } else {
          g.particle_mass = def.mass / count_fx(n);
          if constexpr (std::is_same_v<Def, RopeDef>) {
            build_rope(g, def);
          } else if constexpr (std::is_same_v<Def, ClothDef>) {
            build_cloth(g, def);
          } else {
            build_soft_body(s, g, def);
          }
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

namespace {

// A group of `def` at rest at `positions`; the caller adds its attachments, then builds it.
template <class Def>
ParticleGroup new_group(ParticleGroupId id, ParticleGroupType type, const Def& def,
                        std::vector<Vec3> positions) {
  ParticleGroup g;
  g.id = id;
  g.type = type;
  g.def = def;
  g.positions = std::move(positions);
  g.velocities.assign(g.positions.size(), Vec3{});
  return g;
}

}  // namespace

ParticleGroup make_group(const WorldState& s, ParticleGroupId id, const RopeDef& def) {
  ParticleGroup g = new_group(id, ParticleGroupType::rope, def, rest_positions(def));
  const auto last = static_cast<std::uint32_t>(g.positions.size() - 1);
  if (!def.attach_start.is_null())
    g.attachments.push_back(attach(s, 0, def.attach_start, g.positions[0]));
  if (!def.attach_end.is_null())
    g.attachments.push_back(attach(s, last, def.attach_end, g.positions[last]));
  build_group(s, g);
  return g;
}

ParticleGroup make_group(const WorldState& s, ParticleGroupId id, const ClothDef& def) {
  ParticleGroup g = new_group(id, ParticleGroupType::cloth, def, rest_positions(def));
  if (!def.attach_body.is_null()) {
    for (std::uint32_t p : def.pinned)
      g.attachments.push_back(attach(s, p, def.attach_body, g.positions[p]));
  }
  build_group(s, g);
  return g;
}

ParticleGroup make_group(const WorldState& s, ParticleGroupId id, const SoftBodyDef& def) {
  ParticleGroup g = new_group(id, ParticleGroupType::soft_body, def, rest_positions(s, def));
  build_group(s, g);
  return g;
}

ParticleGroup make_group(const WorldState& s, ParticleGroupId id, const FluidDef& def) {
  ParticleGroup g = new_group(id, ParticleGroupType::fluid, def, rest_positions(def));
  build_group(s, g);
  return g;
}

ParticleGroupStats group_stats(const ParticleGroup& g) {
  ParticleGroupStats st;
  st.type = g.type;
  st.particle_count = static_cast<std::uint32_t>(g.size());
  st.constraint_count = static_cast<std::uint32_t>(g.links.size());
  st.broken_count = static_cast<std::uint32_t>(g.broken.size());
  st.radius = g.radius;
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
  for (const Tetrahedron& t : g.tetrahedra) {
    const auto& c = t.corners;
    // Six times the tetrahedron's volume, signed by its corners' order.
    st.volume +=
        abs(triple(g.positions[c[0]], g.positions[c[1]], g.positions[c[2]], g.positions[c[3]]));
    st.rest_volume += abs(t.rest_triple);
  }
  st.volume = st.volume / Fixed::from_int(6);
  st.rest_volume = st.rest_volume / Fixed::from_int(6);
  if (g.type == ParticleGroupType::fluid) {
    for (Fixed density : fluid_densities(g))
      st.max_density_error = max(st.max_density_error, density - Fixed::one());
  }
  for (std::size_t k = 0; k < g.links.size(); ++k) {
    const Link& l = g.links[k];
    if (g.link_broken[k] || l.kind == LinkKind::bend || l.kind == LinkKind::shear) continue;
    const Fixed d = length(g.positions[l.b] - g.positions[l.a]);
    st.max_strain = max(st.max_strain, d / l.rest - Fixed::one());
  }
  return st;
}

}  // namespace detsim::sim_detail
