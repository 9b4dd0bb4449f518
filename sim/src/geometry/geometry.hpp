// The world's table of registered geometry. Internal to detsim::sim.
//
// Geometry (convex hulls, triangle meshes, heightfields, compounds) is immutable once built:
// a World copy shares it (shared_ptr to const), which keeps the copies a rollback session makes
// cheap. It is part of the world's definition, not of its per-frame state: the "geometry" state
// section lists each geometry's ID, type and content hash (not its data), so a snapshot stays
// small however large a level's mesh is, and restore refuses a state naming geometry that the
// world does not have (state_geometry.cpp).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <variant>
#include <vector>

#include <detsim/core/bytes.hpp>
#include <detsim/core/status.hpp>
#include <detsim/sim/geometry.hpp>
#include <detsim/sim/shape.hpp>

#include "compound.hpp"
#include "heightfield.hpp"
#include "hull.hpp"
#include "mesh.hpp"

namespace detsim::sim_detail {

/// The kinds of geometry. The numeric values are part of the canonical encoding: never renumber.
enum class GeometryType : std::uint8_t { convex_hull = 1, mesh = 2, heightfield = 3, compound = 4 };

/// "convex hull": in messages.
[[nodiscard]] const char* geometry_type_name(GeometryType type) noexcept;

/// One registered geometry: its type, its content hash (XXH3-64 of its canonical encoding) and
/// its data (the member of its type).
struct Geometry {
  GeometryType type = GeometryType::convex_hull;
  std::uint64_t hash = 0;
  std::variant<Hull, Mesh, Heightfield, Compound> data;

  [[nodiscard]] const Hull& hull() const { return std::get<Hull>(data); }
  [[nodiscard]] const Mesh& mesh() const { return std::get<Mesh>(data); }
  [[nodiscard]] const Heightfield& heightfield() const { return std::get<Heightfield>(data); }
  [[nodiscard]] const Compound& compound() const { return std::get<Compound>(data); }
};

/// Registered geometry in ID order: entry i has ID i + 1.
using GeometryTable = std::vector<std::shared_ptr<const Geometry>>;

/// The geometry of `id`, or nullptr when the table has no such ID.
[[nodiscard]] inline const Geometry* find_geometry(const GeometryTable& table,
                                                   GeometryId id) noexcept {
  if (id.value == 0 || id.value > table.size()) return nullptr;
  return table[id.value - 1].get();
}

/// The geometry a shape refers to: nullptr for the primitives (and for an ID the table lacks,
/// which a checked shape never has).
[[nodiscard]] inline const Geometry* shape_geometry(const GeometryTable& table,
                                                    const Shape& shape) noexcept {
  return shape.geometry.is_null() ? nullptr : find_geometry(table, shape.geometry);
}

/// The canonical encoding of a hull's content (its corners, in order), which its hash covers and
/// from which build_hull rebuilds the same hull.
void write_hull_content(const Hull& hull, ByteWriter& w);

/// A geometry of hull `hull`, its hash computed.
[[nodiscard]] std::shared_ptr<const Geometry> make_hull_geometry(Hull hull);
/// A geometry of mesh `mesh`, its hash computed: XXH3-64 of the type byte (2) and the mesh's
/// canonical encoding (mesh.hpp's write).
[[nodiscard]] std::shared_ptr<const Geometry> make_mesh_geometry(Mesh mesh);
/// A geometry of heightfield `hf`, its hash computed: XXH3-64 of the type byte (3) and the
/// heightfield's canonical encoding (heightfield.hpp's write).
[[nodiscard]] std::shared_ptr<const Geometry> make_heightfield_geometry(Heightfield hf);

/// The compound of `children` (compound.cpp): each child's shape checked against `table` (a
/// primitive a dynamic body may have, or a convex hull of the table), its pose checked, and the
/// solid of the parts computed. Refuses, with a message naming the child and what is wrong: no
/// children, more than max_compound_parts, a shape that is not a valid primitive or convex hull of
/// the table, a non-unit orientation, a position component beyond +-10^4 m, or a volume or moment
/// of inertia (per unit mass) beyond the limits of limits.hpp.
[[nodiscard]] Expected<Compound> build_compound(const GeometryTable& table,
                                                std::span<const CompoundChild> children);

/// The canonical encoding of a compound's content, which its hash covers: the part count, then
/// per part its shape type, its fields (a primitive: its kind's encoding; a convex hull: the
/// hull's content hash, never its ID, so that equal compounds hash equal in any world), its
/// position and its orientation as given.
void write_compound_content(const Compound& compound, ByteWriter& w);

/// A geometry of compound `compound`, its hash computed.
[[nodiscard]] std::shared_ptr<const Geometry> make_compound_geometry(Compound compound);

}  // namespace detsim::sim_detail
