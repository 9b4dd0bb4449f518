// The static heightfield (heightfield.hpp): checks, the height pyramid, triangles, queries and the
// canonical encoding.
#include "heightfield.hpp"

#include <algorithm>
#include <string>
#include <utility>

#include <detsim/fixed/decimal.hpp>
#include <detsim/fixed/math.hpp>

#include "bvh.hpp"

namespace detsim::sim_detail {

namespace {

constexpr std::uint32_t leaf_block_cells = 4;

Status refuse_heightfield(const std::string& what) {
  return Status::error("heightfield: " + what);
}

/// column * cell_size: exact (an integer times a raw value below the Fixed range).
Fixed grid(std::uint32_t i, Fixed cell) noexcept {
  return Fixed::from_int(static_cast<std::int32_t>(i)) * cell;
}

Fixed height(const HeightfieldDef& d, std::uint32_t row, std::uint32_t column) noexcept {
  return d.heights[std::size_t{row} * d.columns + column];
}

Vec3 sample(const HeightfieldDef& d, std::uint32_t row, std::uint32_t column) noexcept {
  return {grid(column, d.cell_size), height(d, row, column), grid(row, d.cell_size)};
}

std::uint32_t cell_columns(const HeightfieldDef& d) noexcept {
  return d.columns - 1;
}
std::uint32_t cell_rows(const HeightfieldDef& d) noexcept {
  return d.rows - 1;
}

/// The cells of block (i, j) at a level whose blocks have `size` cells per side: rows [r0, r1)
/// and columns [c0, c1).
struct CellRange {
  std::uint32_t r0, r1, c0, c1;
};
CellRange cells_of(const HeightfieldDef& d, std::uint32_t size, std::uint32_t i,
                   std::uint32_t j) noexcept {
  return {i * size, std::min((i + 1) * size, cell_rows(d)), j * size,
          std::min((j + 1) * size, cell_columns(d))};
}

std::vector<HeightLevel> build_pyramid(const HeightfieldDef& d) {
  std::vector<HeightLevel> levels;
  HeightLevel base;
  base.block_rows = (cell_rows(d) + leaf_block_cells - 1) / leaf_block_cells;
  base.block_columns = (cell_columns(d) + leaf_block_cells - 1) / leaf_block_cells;
  for (std::uint32_t i = 0; i < base.block_rows; ++i) {
    for (std::uint32_t j = 0; j < base.block_columns; ++j) {
      const CellRange c = cells_of(d, leaf_block_cells, i, j);
      Fixed lo = height(d, c.r0, c.c0);
      Fixed hi = lo;
      for (std::uint32_t r = c.r0; r <= c.r1; ++r) {  // samples: one more than cells per side
        for (std::uint32_t k = c.c0; k <= c.c1; ++k) {
          lo = min(lo, height(d, r, k));
          hi = max(hi, height(d, r, k));
        }
      }
      base.low.push_back(lo);
      base.high.push_back(hi);
    }
  }
  levels.push_back(std::move(base));
  while (levels.back().block_rows > 1 || levels.back().block_columns > 1) {
    const HeightLevel& below = levels.back();
    HeightLevel up;
    up.block_rows = (below.block_rows + 1) / 2;
    up.block_columns = (below.block_columns + 1) / 2;
    for (std::uint32_t i = 0; i < up.block_rows; ++i) {
      for (std::uint32_t j = 0; j < up.block_columns; ++j) {
        Fixed lo = Fixed::max();
        Fixed hi = Fixed::min();
        for (std::uint32_t ci = 2 * i; ci < std::min(2 * i + 2, below.block_rows); ++ci) {
          for (std::uint32_t cj = 2 * j; cj < std::min(2 * j + 2, below.block_columns); ++cj) {
            lo = min(lo, below.low[ci * below.block_columns + cj]);
            hi = max(hi, below.high[ci * below.block_columns + cj]);
          }
        }
        up.low.push_back(lo);
        up.high.push_back(hi);
      }
    }
    levels.push_back(std::move(up));
  }
  return levels;
}

/// Triangle `index`'s cell and half.
struct TriangleAt {
  std::uint32_t row, column, k;
};
TriangleAt locate(const HeightfieldDef& d, std::uint32_t index) noexcept {
  const std::uint32_t cell = index / 2;
  return {cell / cell_columns(d), cell % cell_columns(d), index % 2};
}
std::uint32_t index_of(const HeightfieldDef& d, std::uint32_t row, std::uint32_t column,
                       std::uint32_t k) noexcept {
  return 2 * (row * cell_columns(d) + column) + k;
}

std::array<Vec3, 3> vertices_at(const HeightfieldDef& d, std::uint32_t r, std::uint32_t c,
                                std::uint32_t k) noexcept {
  if (k == 0) return {sample(d, r, c), sample(d, r + 1, c), sample(d, r + 1, c + 1)};
  return {sample(d, r, c), sample(d, r + 1, c + 1), sample(d, r, c + 1)};
}

Vec3 normal_of(const std::array<Vec3, 3>& v) noexcept {
  // Never degenerate: the exact cross product's y component is cell_size^2 >= 2^-20 m^2.
  return triangle_normal(v[0], v[1], v[2]).value_or(Vec3::unit_y());
}

/// The triangle across edge `edge` of (r, c, k) and its own number for that edge, if any (see
/// heightfield.hpp's vertex order: k = 0's edges are the cell's left side, its bottom side and the
/// diagonal; k = 1's the diagonal, its right side and its top side).
struct Across {
  std::uint32_t row, column, k, edge;
};
std::optional<Across> across(const HeightfieldDef& d, TriangleAt t, std::uint32_t edge) noexcept {
  const std::uint32_t r = t.row;
  const std::uint32_t c = t.column;
  if (t.k == 0) {
    if (edge == 0) return c > 0 ? std::optional<Across>({r, c - 1, 1, 1}) : std::nullopt;
    if (edge == 1) {
      return r + 1 < cell_rows(d) ? std::optional<Across>({r + 1, c, 1, 2}) : std::nullopt;
    }
    return Across{r, c, 1, 0};
  }
  if (edge == 0) return Across{r, c, 0, 2};
  if (edge == 1) {
    return c + 1 < cell_columns(d) ? std::optional<Across>({r, c + 1, 0, 0}) : std::nullopt;
  }
  return r > 0 ? std::optional<Across>({r - 1, c, 0, 1}) : std::nullopt;
}

Bounds cell_bounds(const HeightfieldDef& d, CellRange c, Fixed low, Fixed high) noexcept {
  return {{grid(c.c0, d.cell_size), low, grid(c.r0, d.cell_size)},
          {grid(c.c1, d.cell_size), high, grid(c.r1, d.cell_size)}};
}

/// The first cell index i in [0, count) with (i + 1) * cell >= lo, and the last with
/// i * cell <= hi: the cells whose closed extent [i cell, (i + 1) cell] meets [lo, hi]. The
/// quotient only estimates; the exact products decide.
struct IndexRange {
  std::int64_t first, last;
};
IndexRange cells_under(Fixed lo, Fixed hi, Fixed cell, std::uint32_t count) noexcept {
  const auto at = [cell](std::int64_t i) { return grid(static_cast<std::uint32_t>(i), cell); };
  const auto estimate = [cell, count](Fixed x) {
    const Fixed q = clamp(floor(x / cell), Fixed::from_int(-1),
                          Fixed::from_int(static_cast<std::int32_t>(count)));
    return static_cast<std::int64_t>(q.to_int());
  };
  const std::int64_t n = count;
  std::int64_t first = std::max<std::int64_t>(estimate(lo) - 1, 0);
  while (first < n && at(first + 1) < lo)
    ++first;
  while (first > 0 && at(first) >= lo)
    --first;
  std::int64_t last = std::min<std::int64_t>(estimate(hi) + 1, n - 1);
  while (last >= 0 && at(last) > hi)
    --last;
  while (last + 1 < n && at(last + 1) <= hi)
    ++last;
  return {first, last};
}

}  // namespace

Expected<Heightfield> build_heightfield(HeightfieldDef def) {
  for (const auto& [name, n] : {std::pair{"rows", def.rows}, std::pair{"columns", def.columns}}) {
    if (n < 2 || n > max_heightfield_side) {
      return refuse_heightfield(std::string(name) + " must be in 2..4096, got " +
                                std::to_string(n));
    }
  }
  if (def.heights.size() != std::size_t{def.rows} * def.columns) {
    return refuse_heightfield("heights must hold rows * columns = " +
                              std::to_string(std::size_t{def.rows} * def.columns) +
                              " values, got " + std::to_string(def.heights.size()));
  }
  if (def.cell_size < min_heightfield_cell) {
    return refuse_heightfield("cell_size must be >= 2^-10, got " + to_string(def.cell_size));
  }
  const std::uint32_t side = std::max(def.rows, def.columns) - 1;
  if (def.cell_size > max_geometry_coordinate ||
      grid(side, def.cell_size) > max_geometry_coordinate) {
    return refuse_heightfield(
        "(max(rows, columns) - 1) * cell_size must be <= 10000, got cell_size " +
        to_string(def.cell_size) + " over " + std::to_string(side) + " cells");
  }
  for (std::size_t i = 0; i < def.heights.size(); ++i) {
    if (abs(def.heights[i]) > max_geometry_coordinate) {
      return refuse_heightfield("height at row " + std::to_string(i / def.columns) + ", column " +
                                std::to_string(i % def.columns) + " is " +
                                to_string(def.heights[i]) + ", must be within +-10000");
    }
  }
  Heightfield hf;
  hf.def = std::move(def);
  hf.levels = build_pyramid(hf.def);
  const HeightLevel& top = hf.levels.back();
  hf.bounds =
      cell_bounds(hf.def, {0, cell_rows(hf.def), 0, cell_columns(hf.def)}, top.low[0], top.high[0]);
  return hf;
}

std::array<Vec3, 3> triangle_vertices(const Heightfield& hf, std::uint32_t index) noexcept {
  const TriangleAt t = locate(hf.def, index);
  return vertices_at(hf.def, t.row, t.column, t.k);
}

TriangleData triangle(const Heightfield& hf, std::uint32_t index) noexcept {
  const TriangleAt t = locate(hf.def, index);
  TriangleData data;
  data.vertices = vertices_at(hf.def, t.row, t.column, t.k);
  data.normal = normal_of(data.vertices);
  for (std::uint32_t e = 0; e < 3; ++e) {
    const auto other = across(hf.def, t, e);
    if (!other) continue;
    const auto v = vertices_at(hf.def, other->row, other->column, other->k);
    const Vec3 n = normal_of(v);
    data.edges[e] = {classify_edge(data.normal, data.vertices[e], n, v[(other->edge + 2) % 3]), n};
  }
  return data;
}

std::optional<TriangleHit> raycast(const Heightfield& hf, Vec3 p, Vec3 v, Fixed max_t) noexcept {
  const HeightfieldDef& d = hf.def;
  const RayBox ray(p, v);
  Fixed limit = max_t;
  std::optional<TriangleHit> best;

  const auto test_cell = [&](std::uint32_t r, std::uint32_t c) {
    const Fixed h00 = height(d, r, c);
    const Fixed h01 = height(d, r, c + 1);
    const Fixed h10 = height(d, r + 1, c);
    const Fixed h11 = height(d, r + 1, c + 1);
    const Bounds box = cell_bounds(d, {r, r + 1, c, c + 1}, min(min(h00, h01), min(h10, h11)),
                                   max(max(h00, h01), max(h10, h11)));
    if (!ray.entry(box, limit)) return;
    for (std::uint32_t k = 0; k < 2; ++k) {
      const auto tri = vertices_at(d, r, c, k);
      if (!ray_crosses_triangle(p, v, tri[0], tri[1], tri[2])) continue;
      const auto hit = ray_hit_plane(p, v, tri[0], normal_of(tri), index_of(d, r, c, k), limit);
      if (hit && (!best || closer(*hit, *best))) {
        best = hit;
        limit = hit->t;
      }
    }
  };

  // Depth first through the pyramid, the nearer of a block's children first; a block entered
  // beyond the best hit so far is pruned (at exactly its t it is still visited, for ties).
  struct Block {
    std::uint32_t level, i, j;
  };
  const auto bounds_of = [&](const Block& b) {
    const HeightLevel& l = hf.levels[b.level];
    const std::size_t at = std::size_t{b.i} * l.block_columns + b.j;
    return cell_bounds(d, cells_of(d, leaf_block_cells << b.level, b.i, b.j), l.low[at],
                       l.high[at]);
  };
  std::array<Block, 4 * 16> stack;  // <= 3 per level below the top, 12 levels at most
  std::size_t size = 0;
  const Block root{static_cast<std::uint32_t>(hf.levels.size() - 1), 0, 0};
  if (ray.entry(bounds_of(root), limit)) stack[size++] = root;
  while (size > 0) {
    const Block b = stack[--size];
    if (b.level == 0) {
      const CellRange c = cells_of(d, leaf_block_cells, b.i, b.j);
      for (std::uint32_t r = c.r0; r < c.r1; ++r) {
        for (std::uint32_t k = c.c0; k < c.c1; ++k)
          test_cell(r, k);
      }
      continue;
    }
    const HeightLevel& below = hf.levels[b.level - 1];
    std::array<std::pair<Fixed, Block>, 4> children;
    std::size_t n = 0;
    for (std::uint32_t ci = 2 * b.i; ci < std::min(2 * b.i + 2, below.block_rows); ++ci) {
      for (std::uint32_t cj = 2 * b.j; cj < std::min(2 * b.j + 2, below.block_columns); ++cj) {
        const Block child{b.level - 1, ci, cj};
        if (const auto t = ray.entry(bounds_of(child), limit)) children[n++] = {*t, child};
      }
    }
    // Farthest pushed first (insertion sort of at most four by entry, ties by position).
    for (std::size_t x = 1; x < n; ++x) {
      for (std::size_t y = x; y > 0 && children[y - 1].first < children[y].first; --y)
        std::swap(children[y - 1], children[y]);
    }
    for (std::size_t x = 0; x < n; ++x)
      stack[size++] = children[x].second;
  }
  return best;
}

void overlap(const Heightfield& hf, Vec3 lo, Vec3 hi, std::vector<std::uint32_t>& out) {
  out.clear();
  const HeightfieldDef& d = hf.def;
  if (lo.x > hi.x || lo.y > hi.y || lo.z > hi.z) return;
  const IndexRange rows = cells_under(lo.z, hi.z, d.cell_size, cell_rows(d));
  const IndexRange columns = cells_under(lo.x, hi.x, d.cell_size, cell_columns(d));
  for (std::int64_t r = rows.first; r <= rows.last; ++r) {
    for (std::int64_t c = columns.first; c <= columns.last; ++c) {
      for (std::uint32_t k = 0; k < 2; ++k) {
        const auto v =
            vertices_at(d, static_cast<std::uint32_t>(r), static_cast<std::uint32_t>(c), k);
        const Fixed y_lo = min(v[0].y, min(v[1].y, v[2].y));
        const Fixed y_hi = max(v[0].y, max(v[1].y, v[2].y));
        if (y_lo <= hi.y && y_hi >= lo.y) {
          out.push_back(
              index_of(d, static_cast<std::uint32_t>(r), static_cast<std::uint32_t>(c), k));
        }
      }
    }
  }
}

void write(const Heightfield& hf, ByteWriter& w) {
  w.u8(1);
  w.var(hf.def.rows);
  w.var(hf.def.columns);
  w.var_fixed(hf.def.cell_size);
  for (const Fixed h : hf.def.heights)
    w.var_fixed(h);
}

Expected<Heightfield> read_heightfield(ByteReader& r) {
  const std::size_t start = r.offset();
  if (r.u8("heightfield version") != 1 && r.ok())
    r.fail_at(start, "heightfield version", "version 1");
  HeightfieldDef def;
  def.rows = r.var32("heightfield rows");
  def.columns = r.var32("heightfield columns");
  if (r.ok() && (def.rows < 2 || def.rows > max_heightfield_side || def.columns < 2 ||
                 def.columns > max_heightfield_side)) {
    r.fail("heightfield size", "2..4096 rows and columns");
  }
  def.cell_size = r.var_fixed("heightfield cell_size");
  // Each height takes at least one byte: a count beyond the bytes left is refused before sizing.
  const std::size_t count = std::size_t{def.rows} * def.columns;
  if (r.ok() && count > r.remaining()) r.fail("heightfield heights", "a count the data can hold");
  if (r.ok()) def.heights.resize(count);
  for (Fixed& h : def.heights)
    h = r.var_fixed("heightfield height");
  if (!r.ok()) return refuse_heightfield(r.error());
  return build_heightfield(std::move(def));
}

}  // namespace detsim::sim_detail
