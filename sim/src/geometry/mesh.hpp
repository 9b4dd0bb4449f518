// A static triangle mesh's geometry: what World::create_mesh registers (once, content-hashed),
// and what static bodies' raycasts, overlaps and the mesh narrowphase read. Internal to
// detsim::sim.
//
// Immutable once built. Everything is in the shape's local frame, in Fixed arithmetic, and a
// function of the input's values and order only: the same vertices and indices give the same
// mesh, bit for bit, on every platform (the BVH's build included, see bvh.hpp).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include <detsim/core/bytes.hpp>
#include <detsim/core/status.hpp>
#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/vec3.hpp>

#include "bvh.hpp"
#include "triangle.hpp"

namespace detsim::sim_detail {

/// The most triangles (index triples) and vertices build_mesh accepts; larger input is refused
/// before anything proportional to it is allocated. 2^20 triangles take ~100 MB with their BVH.
inline constexpr std::size_t max_mesh_triangles = std::size_t{1} << 20;
inline constexpr std::size_t max_mesh_vertices = std::size_t{1} << 20;

/// No neighbour across an edge.
inline constexpr std::uint32_t no_neighbour = 0xFFFFFFFFU;

/// One edge of a triangle (edge k runs from its vertex k to vertex (k + 1) % 3): the triangle on
/// the other side and the kind of the fold between them. An edge has a neighbour when exactly two
/// kept triangles share it (by vertex position, so duplicated vertices still join) and run along
/// it in opposite directions (consistent winding); otherwise it is a boundary.
struct MeshEdge {
  std::uint32_t neighbour = no_neighbour;
  EdgeKind kind = EdgeKind::boundary;
  friend bool operator==(const MeshEdge&, const MeshEdge&) = default;
};

struct Mesh {
  std::vector<Vec3> vertices;  ///< as given (unused ones included)
  /// The kept triangles, in input order: indices into vertices, counter-clockwise seen from the
  /// side the normal points to. Triangle i of every query is triangles[i].
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::vector<Vec3> normals;                   ///< unit, per triangle (triangle_normal)
  std::vector<std::array<MeshEdge, 3>> edges;  ///< per triangle
  Bvh bvh;                                     ///< over the triangles' bounds
  Bounds bounds;                               ///< of the kept triangles
  /// Input triangles dropped as degenerate (triangle_normal's test: repeated indices, zero area,
  /// or twice the area's largest component below 2^-24 m^2). Not part of the encoding.
  std::uint32_t dropped_triangles = 0;
};

/// Builds a mesh from `indices`, read as triples into `vertices`. Refuses, with a message naming
/// what is wrong: an index count not divisible by 3; more than max_mesh_triangles triangles or
/// max_mesh_vertices vertices; a vertex component outside +-10^4 m (which includes the saturated
/// Fixed::max() and min()); an index out of range ("triangle 7: index 3 is 12, but there are 10
/// vertices"); no triangle left after dropping the degenerate ones.
[[nodiscard]] Expected<Mesh> build_mesh(std::span<const Vec3> vertices,
                                        std::span<const std::uint32_t> indices);

/// The geometry's equality: vertices, triangles and everything derived from them (not
/// dropped_triangles, which describes the input).
[[nodiscard]] bool same_geometry(const Mesh& a, const Mesh& b) noexcept;

[[nodiscard]] inline std::uint32_t triangle_count(const Mesh& mesh) noexcept {
  return static_cast<std::uint32_t>(mesh.triangles.size());
}
/// Triangle `index` (< triangle_count) with its normal and edges.
[[nodiscard]] TriangleData triangle(const Mesh& mesh, std::uint32_t index) noexcept;

/// The closest hit of the ray p + v t, 0 <= t <= max_t (v a unit vector, p within +-2 * 10^4 m):
/// the lowest t, ties to the lowest triangle index. Two-sided: a triangle is hit from either side,
/// and the hit's normal is the face normal turned towards p.
[[nodiscard]] std::optional<TriangleHit> raycast(const Mesh& mesh, Vec3 p, Vec3 v,
                                                 Fixed max_t) noexcept;

/// The triangles whose bounds overlap the closed box [lo, hi] (touching counts), ascending, in
/// `out` (cleared first).
void overlap(const Mesh& mesh, Vec3 lo, Vec3 hi, std::vector<std::uint32_t>& out);

/// The canonical encoding: a version byte (1), the vertex count and the vertices (var_vec3), the
/// triangle count and the kept triangles' indices (var32). read_mesh rebuilds through build_mesh,
/// so the derived data (normals, edges, BVH) is never trusted from bytes.
void write(const Mesh& mesh, ByteWriter& w);
/// Reads what write wrote; refuses bad bytes with a message (the reader's error, or build_mesh's),
/// checking every count against the bytes left before allocating.
[[nodiscard]] Expected<Mesh> read_mesh(ByteReader& r);

}  // namespace detsim::sim_detail
