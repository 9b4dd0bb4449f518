// Position-based fluids in fixed point (fluid.hpp; docs/PARTICLES.md, "Fluids").
//
// The neighbour grid is written here rather than taken from a library: its bucket order and the
// order of the pairs it yields are part of what makes every machine step the same bits.
#include "fluid.hpp"

#include <algorithm>
#include <array>
#include <bit>

#include <detsim/fixed/math.hpp>

#include "../solver/bodies.hpp"
#include "group.hpp"

namespace detsim::sim_detail {

namespace {

// The relaxation added to each density constraint's denominator, as a fraction of that
// denominator for a particle inside the fluid at rest: it keeps a particle with few neighbours
// (a drop, the surface) from taking a step its sparse gradient would make huge.
constexpr std::int32_t kRelaxationDivisor = 100;

std::uint32_t hash_cell(std::uint64_t x, std::uint64_t y, std::uint64_t z, std::uint32_t mask) {
  const std::uint64_t h = x * 73856093ULL ^ y * 19349663ULL ^ z * 83492791ULL;
  return static_cast<std::uint32_t>((h ^ (h >> 29)) & mask);
}

// W and its gradient at a for r = x_a - x_b, |r|^2 = d2 < H^2 (inv_h = 1 / H): W = u^3 and
// grad W = -3 u^2 r / (H |r|) with u = 1 - |r| / H. Two particles at the same point push apart
// along x (any direction will do; this one is the same everywhere).
struct KernelValue {
  Fixed weight;
  Vec3 gradient;
  Fixed slope;  ///< |gradient|
};

KernelValue kernel(Vec3 r, Fixed d2, Fixed inv_h, bool a_first) {
  const Fixed three_over_h = Fixed::from_int(3) * inv_h;
  if (d2 == Fixed::zero())
    return {Fixed::one(),
            {a_first ? -three_over_h : three_over_h, Fixed::zero(), Fixed::zero()},
            three_over_h};
  const Fixed inverse = rsqrt(d2);
  const Fixed u = Fixed::one() - d2 * inverse * inv_h;
  const Fixed u2 = u * u;
  const Fixed slope = three_over_h * u2;
  return {u2 * u, r * -(slope * inverse), slope};
}

// Each particle's density in kernel units: 1 + the sum of W over the pairs within reach (what the
// statistics report; the solver keeps its own sums per neighbour entry).
void density_pass(std::span<const Vec3> x, Fixed radius, FluidScratch& sc) {
  const Fixed radius2 = radius * radius;
  const Fixed inv_h = Fixed::one() / radius;
  sc.density.assign(x.size(), Fixed::one());
  for (std::size_t k = 0; k < sc.pair_a.size(); ++k) {
    const std::uint32_t a = sc.pair_a[k];
    const std::uint32_t b = sc.pair_b[k];
    const Vec3 r = x[a] - x[b];
    const Fixed d2 = length_squared(r);
    if (d2 >= radius2) continue;
    const Fixed w = kernel(r, d2, inv_h, true).weight;
    sc.density[a] += w;
    sc.density[b] += w;
  }
}

}  // namespace

const WallKernel& wall_kernel() {
  static const WallKernel table = [] {
    // Beyond a wall at distance t (spacings) lie lattice layers at t + k + 1/2, each a square
    // lattice: the sum of W(|offset| / 2) over those within two spacings, and its t-derivative
    // (W(q) = (1 - q)^3, dW/dq = -3 (1 - q)^2, dq/dt = (t + k + 1/2) / (2 |offset|)).
    WallKernel k;
    const std::int32_t steps = 2 * WallKernel::steps_per_spacing;
    for (std::int32_t m = 0; m <= steps; ++m) {
      const Fixed t = Fixed::from_int(m) / Fixed::from_int(WallKernel::steps_per_spacing);
      Fixed value;
      Fixed slope;
      for (std::int32_t layer = 0; layer < 2; ++layer) {
        const Fixed depth = t + Fixed::from_int(layer) + Fixed::half();
        for (std::int32_t i = -2; i <= 2; ++i) {
          for (std::int32_t j = -2; j <= 2; ++j) {
            const Fixed d2 = depth * depth + Fixed::from_int(i * i + j * j);
            if (d2 >= Fixed::from_int(4)) continue;
            const Fixed d = sqrt(d2);
            const Fixed u = Fixed::one() - d * Fixed::half();
            value += u * u * u;
            slope -= Fixed::from_int(3) * u * u * depth / (d * Fixed::from_int(2));
          }
        }
      }
      k.value.push_back(value);
      k.slope.push_back(slope);
    }
    return k;
  }();
  return table;
}

void build_fluid_kernel(ParticleGroup& g, Fixed spacing) {
  g.kernel_radius = spacing * Fixed::from_int(2);
  // The lattice within two spacings: offsets o with |o| < 2, q = |o| / 2.
  Fixed sum = Fixed::one();
  Fixed square;
  const Fixed three_over_radius = Fixed::from_int(3) / g.kernel_radius;
  for (int i = -2; i <= 2; ++i) {
    for (int j = -2; j <= 2; ++j) {
      for (int k = -2; k <= 2; ++k) {
        const int o2 = i * i + j * j + k * k;
        if (o2 == 0 || o2 >= 4) continue;
        const Fixed u = Fixed::one() - sqrt(Fixed::from_int(o2)) * Fixed::half();
        sum += u * u * u;
        const Fixed gradient = three_over_radius * u * u;
        square += gradient * gradient;
      }
    }
  }
  g.kernel_rest_sum = sum;
  // At rest the gradients at a particle cancel: its denominator is the sum of their squares.
  g.kernel_relaxation = square / Fixed::from_int(kRelaxationDivisor);
}

void find_fluid_pairs(std::span<const Vec3> x, Fixed reach, FluidScratch& sc) {
  const std::size_t n = x.size();
  sc.pair_a.clear();
  sc.pair_b.clear();
  if (n < 2) return;
  const std::uint32_t buckets = std::bit_ceil(static_cast<std::uint32_t>(2 * n));
  const std::uint32_t mask = buckets - 1;
  Vec3 lo = x[0];
  for (const Vec3& p : x)
    lo = {min(lo.x, p.x), min(lo.y, p.y), min(lo.z, p.z)};
  // Cell coordinates from the lowest corner: an integer division of the raw offsets (unsigned,
  // so that a fluid spread over the whole position range cannot overflow).
  const auto cell_raw = static_cast<std::uint64_t>(reach.raw());
  const auto cell_of = [&](Fixed p, Fixed low) {
    return (static_cast<std::uint64_t>(p.raw()) - static_cast<std::uint64_t>(low.raw())) / cell_raw;
  };
  std::vector<std::array<std::uint64_t, 3>> cells(n);
  sc.bucket_of.resize(n);
  sc.bucket_start.assign(std::size_t{buckets} + 1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    cells[i] = {cell_of(x[i].x, lo.x), cell_of(x[i].y, lo.y), cell_of(x[i].z, lo.z)};
    sc.bucket_of[i] = hash_cell(cells[i][0], cells[i][1], cells[i][2], mask);
    ++sc.bucket_start[sc.bucket_of[i] + 1];
  }
  for (std::uint32_t b = 0; b < buckets; ++b)
    sc.bucket_start[b + 1] += sc.bucket_start[b];
  sc.by_bucket.resize(n);
  {
    std::vector<std::uint32_t> fill(sc.bucket_start.begin(), sc.bucket_start.end() - 1);
    for (std::size_t i = 0; i < n; ++i)
      sc.by_bucket[fill[sc.bucket_of[i]]++] = static_cast<std::uint32_t>(i);
  }
  const Fixed reach2 = reach * reach;
  std::array<std::uint32_t, 27> near{};
  for (std::size_t i = 0; i < n; ++i) {
    std::size_t count = 0;
    for (std::uint64_t dx = 0; dx < 3; ++dx)
      for (std::uint64_t dy = 0; dy < 3; ++dy)
        for (std::uint64_t dz = 0; dz < 3; ++dz)
          near[count++] =
              hash_cell(cells[i][0] + dx - 1, cells[i][1] + dy - 1, cells[i][2] + dz - 1, mask);
    std::sort(near.begin(), near.end());
    const auto last = std::unique(near.begin(), near.end());
    const Vec3 p = x[i];
    std::uint32_t found = 0;
    for (auto it = near.begin(); it != last && found < kMaxFluidNeighbours; ++it) {
      const auto begin = sc.by_bucket.begin() + static_cast<std::ptrdiff_t>(sc.bucket_start[*it]);
      const auto end = sc.by_bucket.begin() + static_cast<std::ptrdiff_t>(sc.bucket_start[*it + 1]);
      for (auto j = std::upper_bound(begin, end, static_cast<std::uint32_t>(i)); j != end; ++j) {
        const Vec3 d = x[*j] - p;
        // A bucket holds other cells' particles too: far ones are dropped before squaring.
        if (abs(d.x) >= reach || abs(d.y) >= reach || abs(d.z) >= reach) continue;
        if (length_squared(d) >= reach2) continue;
        sc.pair_a.push_back(static_cast<std::uint32_t>(i));
        sc.pair_b.push_back(*j);
        if (++found == kMaxFluidNeighbours) break;
      }
    }
  }
}

void build_fluid_neighbours(std::size_t n, FluidScratch& sc) {
  sc.neighbour_start.assign(n + 1, 0);
  for (std::size_t k = 0; k < sc.pair_a.size(); ++k) {
    ++sc.neighbour_start[sc.pair_a[k] + 1];
    ++sc.neighbour_start[sc.pair_b[k] + 1];
  }
  for (std::size_t i = 0; i < n; ++i)
    sc.neighbour_start[i + 1] += sc.neighbour_start[i];
  sc.neighbours.resize(sc.neighbour_start[n]);
  sc.entry_weight.assign(sc.neighbour_start[n], Fixed::zero());
  std::vector<std::uint32_t> fill(sc.neighbour_start.begin(), sc.neighbour_start.end() - 1);
  for (std::size_t k = 0; k < sc.pair_a.size(); ++k) {
    sc.neighbours[fill[sc.pair_a[k]]++] = sc.pair_b[k];
    sc.neighbours[fill[sc.pair_b[k]]++] = sc.pair_a[k];
  }
}

void solve_fluid_density(ParticleGroup& g, FluidScratch& sc, std::span<Vec3> previous, Fixed h,
                         Fixed push_step) {
  const std::size_t n = g.size();
  const Fixed radius = g.kernel_radius;
  const Fixed radius2 = radius * radius;
  const Fixed inv_h = Fixed::one() / radius;
  const Fixed rest = g.kernel_rest_sum;
  const Fixed inv_spacing = Fixed::from_int(2) / radius;
  std::vector<Vec3>& grads = sc.gradient;
  std::vector<Vec3>& x = g.positions;
  const Fixed half_spacing = radius / Fixed::from_int(4);
  sc.delta.assign(x.begin(), x.end());  // where the pass starts
  // A particle whose centre is behind a wall (created inside a body, or pushed into it) is not
  // fluid: the contacts bring it out at the bodies' push-out speed, and until then it is no one's
  // neighbour (the wall already stands for the fluid beyond it: counted twice, a spawn inside a
  // body would blow the fluid apart).
  sc.buried.assign(n, false);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::uint32_t k = sc.wall_start[i]; k < sc.wall_start[i + 1]; ++k) {
      if (dot(x[i] - sc.walls[k].point, sc.walls[k].normal) < Fixed::zero()) sc.buried[i] = true;
    }
  }
  // Gauss-Seidel: each particle's constraint in ascending order, solved at once (every particle
  // it moves is seen moved by the next), as every other constraint of the particle solver.
  for (std::size_t i = 0; i < n; ++i) {
    if (sc.buried[i]) continue;
    const std::uint32_t first = sc.neighbour_start[i];
    const std::uint32_t count = sc.neighbour_start[i + 1] - first;
    grads.resize(std::max<std::size_t>(grads.size(), count));
    Fixed density = Fixed::one();
    Vec3 sum;
    Fixed square;
    Fixed longest;
    for (std::uint32_t e = 0; e < count; ++e) {
      const std::uint32_t b = sc.neighbours[first + e];
      const Vec3 r = x[i] - x[b];
      const Fixed d2 = length_squared(r);
      if (d2 >= radius2 || sc.buried[b]) {
        grads[e] = {};
        sc.entry_weight[first + e] = Fixed::zero();
        continue;
      }
      const KernelValue kv = kernel(r, d2, inv_h, b > i);
      sc.entry_weight[first + e] = kv.weight;
      density += kv.weight;
      grads[e] = kv.gradient;
      sum += kv.gradient;
      square += kv.slope * kv.slope;
      longest = max(longest, kv.slope);
    }
    // The walls: their density at the particle's distance, and its gradient along the normal.
    const WallKernel& table = wall_kernel();
    for (std::uint32_t k = sc.wall_start[i]; k < sc.wall_start[i + 1]; ++k) {
      FluidWall& wall = sc.walls[k];
      wall.gradient = {};
      const Fixed t = max(dot(x[i] - wall.point, wall.normal) * inv_spacing, Fixed::zero());
      const Fixed scaled = t * Fixed::from_int(WallKernel::steps_per_spacing);
      const std::int64_t m = scaled.raw() >> 32;
      if (m >= static_cast<std::int64_t>(table.value.size()) - 1) continue;
      const auto at = static_cast<std::size_t>(m);
      const Fixed f = scaled - Fixed::from_int(static_cast<std::int32_t>(m));
      density += table.value[at] + (table.value[at + 1] - table.value[at]) * f;
      const Fixed slope =
          (table.slope[at] + (table.slope[at + 1] - table.slope[at]) * f) * inv_spacing;
      const Vec3 gradient = wall.normal * slope;
      wall.gradient = gradient;
      sum += gradient;
      longest = max(longest, abs(slope));
    }
    if (density <= rest) continue;  // a free surface is not pulled together
    Fixed scale = -(density - rest) / (length_squared(sum) + square + g.kernel_relaxation);
    // No particle moves further than half a spacing for one constraint.
    const Fixed reach = max(length(sum), longest);
    if (-scale * reach > half_spacing) scale = -half_spacing / reach;
    x[i] += sum * scale;
    for (std::uint32_t k = sc.wall_start[i]; k < sc.wall_start[i + 1]; ++k)
      sc.walls[k].moved += sc.walls[k].gradient * scale;
    for (std::uint32_t e = 0; e < count; ++e) {
      if (sc.entry_weight[first + e] != Fixed::zero())
        x[sc.neighbours[first + e]] -= grads[e] * scale;
    }
  }
  // What the pass moved each particle by becomes velocity up to its own motion in the small step
  // plus push_step; the rest moves its start of step too, a correction of where it is: a
  // compression the particle's own motion made bounces as it should, one it already had (a fluid
  // created inside a body, or squeezed out of one) is undone without the fluid gaining the
  // energy of an explosion.
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 moved = x[i] - sc.delta[i];
    if (moved == Vec3{}) continue;
    const Fixed budget = length(g.velocities[i]) * h + push_step;
    previous[i] += moved - limit_speed(moved, budget);
  }
}

void apply_fluid_viscosity(ParticleGroup& g, FluidScratch& sc, Fixed viscosity) {
  if (viscosity == Fixed::zero()) return;
  // Each pair once (from its lower particle), with the weight the last density pass found.
  const Fixed factor = viscosity / g.kernel_rest_sum;
  sc.delta.assign(g.size(), Vec3{});
  for (std::uint32_t a = 0; a < g.size(); ++a) {
    for (std::uint32_t e = sc.neighbour_start[a]; e < sc.neighbour_start[a + 1]; ++e) {
      const std::uint32_t b = sc.neighbours[e];
      const Fixed w = sc.entry_weight[e];
      if (b < a || w == Fixed::zero()) continue;
      const Vec3 dv = (g.velocities[b] - g.velocities[a]) * (w * factor);
      sc.delta[a] += dv;
      sc.delta[b] -= dv;
    }
  }
  for (std::size_t i = 0; i < g.size(); ++i)
    g.velocities[i] += sc.delta[i];
}

std::vector<Fixed> fluid_densities(const ParticleGroup& g) {
  FluidScratch sc;
  find_fluid_pairs(g.positions, g.kernel_radius, sc);
  density_pass(g.positions, g.kernel_radius, sc);
  std::vector<Fixed> out(g.size());
  for (std::size_t i = 0; i < g.size(); ++i)
    out[i] = sc.density[i] / g.kernel_rest_sum;
  return out;
}

}  // namespace detsim::sim_detail
