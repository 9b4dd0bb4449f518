// The static triangle mesh (mesh.hpp): validation, degenerate triangles, adjacency, the BVH,
// queries and the canonical encoding.
#include "mesh.hpp"

#include <algorithm>
#include <string>
#include <tuple>
#include <utility>

#include <detsim/fixed/decimal.hpp>
#include <detsim/fixed/math.hpp>

namespace detsim::sim_detail {

namespace {

Status refuse_mesh(const std::string& what) {
  return Status::error("mesh: " + what);
}

/// "" when every component is within +-10^4 m, else the first offending one.
std::string check_vertices(std::span<const Vec3> vertices) {
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    const Vec3 v = vertices[i];
    const std::array<Fixed, 3> c = {v.x, v.y, v.z};
    for (std::size_t k = 0; k < 3; ++k) {
      if (abs(c[k]) > max_geometry_coordinate) {
        return "vertex " + std::to_string(i) + " " + "xyz"[k] + " is " + to_string(c[k]) +
               ", must be within +-10000";
      }
    }
  }
  return "";
}

/// For each vertex, the lowest index of a vertex at the same position: edges are matched by
/// position, so a mesh whose vertices were duplicated (per-face vertices, say) still has its
/// neighbours. The sort's order is total (index breaks ties of position).
std::vector<std::uint32_t> weld(std::span<const Vec3> vertices) {
  const auto n = static_cast<std::uint32_t>(vertices.size());
  std::vector<std::uint32_t> order(n);
  for (std::uint32_t i = 0; i < n; ++i)
    order[i] = i;
  const auto key = [&vertices](std::uint32_t i) {
    const Vec3 v = vertices[i];
    return std::array<std::int64_t, 4>{v.x.raw(), v.y.raw(), v.z.raw(), std::int64_t{i}};
  };
  std::sort(order.begin(), order.end(),
            [&key](std::uint32_t a, std::uint32_t b) { return key(a) < key(b); });
  std::vector<std::uint32_t> canonical(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    const bool same = i > 0 && vertices[order[i]] == vertices[order[i - 1]];
    canonical[order[i]] = same ? canonical[order[i - 1]] : order[i];
  }
  return canonical;
}

/// One triangle's edge, keyed by its endpoints' welded vertices (lower first).
struct EdgeRecord {
  std::uint32_t lo;
  std::uint32_t hi;
  std::uint32_t triangle;
  std::uint32_t k;
  bool forward;  ///< runs lo -> hi
};

void link_edges(Mesh& mesh) {
  const std::vector<std::uint32_t> canonical = weld(mesh.vertices);
  std::vector<EdgeRecord> records;
  records.reserve(mesh.triangles.size() * 3);
  for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
    for (std::uint32_t k = 0; k < 3; ++k) {
      // Distinct: a kept triangle has no two vertices at one position (its area would be zero).
      const std::uint32_t a = canonical[mesh.triangles[t][k]];
      const std::uint32_t b = canonical[mesh.triangles[t][(k + 1) % 3]];
      records.push_back({std::min(a, b), std::max(a, b), t, k, a < b});
    }
  }
  std::sort(records.begin(), records.end(), [](const EdgeRecord& x, const EdgeRecord& y) {
    return std::tie(x.lo, x.hi, x.triangle, x.k) < std::tie(y.lo, y.hi, y.triangle, y.k);
  });
  mesh.edges.assign(mesh.triangles.size(), {});
  for (std::size_t i = 0; i < records.size();) {
    std::size_t end = i + 1;
    while (end < records.size() && records[end].lo == records[i].lo &&
           records[end].hi == records[i].hi)
      ++end;
    if (end - i == 2 && records[i].forward != records[i + 1].forward) {
      for (const auto& [self, other] :
           {std::pair{records[i], records[i + 1]}, std::pair{records[i + 1], records[i]}}) {
        const Vec3 on_edge = mesh.vertices[mesh.triangles[self.triangle][self.k]];
        const Vec3 far = mesh.vertices[mesh.triangles[other.triangle][(other.k + 2) % 3]];
        mesh.edges[self.triangle][self.k] = {
            other.triangle,
            classify_edge(mesh.normals[self.triangle], on_edge, mesh.normals[other.triangle], far)};
      }
    }
    i = end;
  }
}

Bounds bounds_of(const Mesh& mesh, std::uint32_t t) noexcept {
  const auto& tri = mesh.triangles[t];
  return triangle_bounds(mesh.vertices[tri[0]], mesh.vertices[tri[1]], mesh.vertices[tri[2]]);
}

}  // namespace

Expected<Mesh> build_mesh(std::span<const Vec3> vertices, std::span<const std::uint32_t> indices) {
  // Everything that bounds the work is checked before any allocation.
  if (indices.size() % 3 != 0) {
    return refuse_mesh("the index count must be a multiple of 3, got " +
                       std::to_string(indices.size()));
  }
  if (indices.size() / 3 > max_mesh_triangles) {
    return refuse_mesh(std::to_string(indices.size() / 3) + " triangles, at most " +
                       std::to_string(max_mesh_triangles));
  }
  if (vertices.size() > max_mesh_vertices) {
    return refuse_mesh(std::to_string(vertices.size()) + " vertices, at most " +
                       std::to_string(max_mesh_vertices));
  }
  if (const std::string bad = check_vertices(vertices); !bad.empty()) return refuse_mesh(bad);
  for (std::size_t i = 0; i < indices.size(); ++i) {
    if (indices[i] >= vertices.size()) {
      return refuse_mesh("triangle " + std::to_string(i / 3) + ": index " + std::to_string(i % 3) +
                         " is " + std::to_string(indices[i]) + ", but there are " +
                         std::to_string(vertices.size()) + " vertices");
    }
  }

  Mesh mesh;
  mesh.vertices.assign(vertices.begin(), vertices.end());
  mesh.triangles.reserve(indices.size() / 3);
  mesh.normals.reserve(indices.size() / 3);
  for (std::size_t i = 0; i < indices.size(); i += 3) {
    const std::array<std::uint32_t, 3> tri = {indices[i], indices[i + 1], indices[i + 2]};
    const auto normal = triangle_normal(vertices[tri[0]], vertices[tri[1]], vertices[tri[2]]);
    if (!normal) {  // repeated indices included: their cross product is exactly zero
      ++mesh.dropped_triangles;
      continue;
    }
    mesh.triangles.push_back(tri);
    mesh.normals.push_back(*normal);
  }
  if (mesh.triangles.empty()) {
    return refuse_mesh("no triangle left after dropping " + std::to_string(mesh.dropped_triangles) +
                       " degenerate ones");
  }

  std::vector<Bounds> bounds(mesh.triangles.size());
  for (std::uint32_t t = 0; t < bounds.size(); ++t)
    bounds[t] = bounds_of(mesh, t);
  mesh.bvh = build_bvh(bounds);
  mesh.bounds = mesh.bvh.nodes[0].bounds;
  link_edges(mesh);
  return mesh;
}

bool same_geometry(const Mesh& a, const Mesh& b) noexcept {
  return a.vertices == b.vertices && a.triangles == b.triangles && a.normals == b.normals &&
         a.edges == b.edges && a.bvh == b.bvh && a.bounds == b.bounds;
}

TriangleData triangle(const Mesh& mesh, std::uint32_t index) noexcept {
  const auto& tri = mesh.triangles[index];
  TriangleData data;
  for (std::size_t k = 0; k < 3; ++k) {
    data.vertices[k] = mesh.vertices[tri[k]];
    const MeshEdge e = mesh.edges[index][k];
    data.edges[k] = {e.kind,
                     e.neighbour == no_neighbour ? Vec3::zero() : mesh.normals[e.neighbour]};
  }
  data.normal = mesh.normals[index];
  return data;
}

std::optional<TriangleHit> raycast(const Mesh& mesh, Vec3 p, Vec3 v, Fixed max_t) noexcept {
  const RayBox ray(p, v);
  Fixed limit = max_t;
  std::optional<TriangleHit> best;
  bvh_raycast(mesh.bvh, ray, limit, [&](std::uint32_t t) {
    const auto& tri = mesh.triangles[t];
    const auto hit = ray_triangle(p, v, mesh.vertices[tri[0]], mesh.vertices[tri[1]],
                                  mesh.vertices[tri[2]], mesh.normals[t], t, limit);
    if (hit && (!best || closer(*hit, *best))) {
      best = hit;
      limit = hit->t;
    }
  });
  return best;
}

void overlap(const Mesh& mesh, Vec3 lo, Vec3 hi, std::vector<std::uint32_t>& out) {
  out.clear();
  bvh_overlap(mesh.bvh, lo, hi, [&](std::uint32_t t) {
    if (overlaps(bounds_of(mesh, t), lo, hi)) out.push_back(t);
  });
  std::sort(out.begin(), out.end());  // distinct indices: no ties
}

void write(const Mesh& mesh, ByteWriter& w) {
  w.u8(1);
  w.var(mesh.vertices.size());
  for (const Vec3& v : mesh.vertices)
    w.var_vec3(v);
  w.var(mesh.triangles.size());
  for (const auto& tri : mesh.triangles) {
    for (const std::uint32_t i : tri)
      w.var(i);
  }
}

Expected<Mesh> read_mesh(ByteReader& r) {
  const std::size_t start = r.offset();
  if (r.u8("mesh version") != 1 && r.ok()) r.fail_at(start, "mesh version", "version 1");
  // A vertex takes at least 3 bytes and a triangle at least 3: counts beyond what the bytes left
  // can hold are refused before the vectors are sized.
  const std::uint32_t vertex_count = r.var32("mesh vertex count");
  if (vertex_count > max_mesh_vertices) r.fail("mesh vertex count", "at most 2^20 vertices");
  if (vertex_count > r.remaining() / 3) r.fail("mesh vertex count", "a count the data can hold");
  std::vector<Vec3> vertices;
  if (r.ok()) vertices.resize(vertex_count);
  for (Vec3& v : vertices)
    v = r.var_vec3("mesh vertex");
  const std::uint32_t triangle_count = r.var32("mesh triangle count");
  if (triangle_count > max_mesh_triangles) r.fail("mesh triangle count", "at most 2^20 triangles");
  if (triangle_count > r.remaining() / 3) {
    r.fail("mesh triangle count", "a count the data can hold");
  }
  std::vector<std::uint32_t> indices;
  if (r.ok()) indices.resize(std::size_t{triangle_count} * 3);
  for (std::uint32_t& i : indices)
    i = r.var32("mesh index");
  if (!r.ok()) return refuse_mesh(r.error());
  auto mesh = build_mesh(vertices, indices);
  if (mesh && mesh->dropped_triangles != 0) {
    // write() keeps only the kept triangles: bytes with degenerate ones are not canonical.
    return refuse_mesh("the encoding holds " + std::to_string(mesh->dropped_triangles) +
                       " degenerate triangles");
  }
  return mesh;
}

}  // namespace detsim::sim_detail
