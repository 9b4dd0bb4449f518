// The world's geometry: registration (World::create_convex_hull, ...), content hashes, and the
// queries on it (geometry/geometry.hpp).
#include "geometry.hpp"

#include <detsim/core/hash.hpp>
#include <detsim/sim/world.hpp>

#include "../shapes.hpp"
#include "../world_state.hpp"

namespace detsim {

namespace sim_detail {

const char* geometry_type_name(GeometryType type) noexcept {
  switch (type) {
    case GeometryType::convex_hull:
      return "convex hull";
    case GeometryType::mesh:
      return "triangle mesh";
    case GeometryType::heightfield:
      return "heightfield";
    case GeometryType::compound:
      return "compound";
  }
  return "unknown geometry";
}

// The corners define the hull: build_hull of them gives it back, bit for bit (every corner of a
// hull is a corner of the hull of its corners, and the build depends on the set of points only).
void write_hull_content(const Hull& hull, ByteWriter& w) {
  w.var(hull.vertices.size());
  for (const Vec3 v : hull.vertices)
    w.var_vec3(v);
}

std::shared_ptr<const Geometry> make_hull_geometry(Hull hull) {
  auto g = std::make_shared<Geometry>();
  g->type = GeometryType::convex_hull;
  ByteWriter w;
  w.u8(static_cast<std::uint8_t>(g->type));
  write_hull_content(hull, w);
  g->hash = hash_bytes(w.bytes());
  g->data = std::move(hull);
  return g;
}

// The mesh's and heightfield's own canonical encodings (a version byte, then their defining data)
// are what their readers rebuild from, so the hash covers exactly what defines the geometry.
std::shared_ptr<const Geometry> make_mesh_geometry(Mesh mesh) {
  auto g = std::make_shared<Geometry>();
  g->type = GeometryType::mesh;
  ByteWriter w;
  w.u8(static_cast<std::uint8_t>(g->type));
  write(mesh, w);
  g->hash = hash_bytes(w.bytes());
  g->data = std::move(mesh);
  return g;
}

std::shared_ptr<const Geometry> make_heightfield_geometry(Heightfield hf) {
  auto g = std::make_shared<Geometry>();
  g->type = GeometryType::heightfield;
  ByteWriter w;
  w.u8(static_cast<std::uint8_t>(g->type));
  write(hf, w);
  g->hash = hash_bytes(w.bytes());
  g->data = std::move(hf);
  return g;
}

void write_compound_content(const Compound& compound, ByteWriter& w) {
  w.var(compound.parts.size());
  for (const CompoundPart& part : compound.parts) {
    const Shape& shape = part.child.shape;
    w.u8(static_cast<std::uint8_t>(shape.type));
    if (part.geometry != nullptr) {
      w.u64(part.geometry->hash);
    } else {
      shape_kind(shape.type).write(shape, w);
    }
    w.var_vec3(part.child.position);
    w.var_quat(part.child.orientation);
  }
}

std::shared_ptr<const Geometry> make_compound_geometry(Compound compound) {
  auto g = std::make_shared<Geometry>();
  g->type = GeometryType::compound;
  ByteWriter w;
  w.u8(static_cast<std::uint8_t>(g->type));
  write_compound_content(compound, w);
  g->hash = hash_bytes(w.bytes());
  g->data = std::move(compound);
  return g;
}

namespace {

// Geometry IDs are 32-bit like body IDs; a world that registered this many has bigger problems.
constexpr std::size_t kMaxGeometries = 0xFFFFFFFEU;

Expected<GeometryId> add(WorldState& s, std::shared_ptr<const Geometry> g) {
  if (s.geometries.size() >= kMaxGeometries)
    return Status::error("geometry IDs exhausted (2^32 - 2 registered)");
  // Registering again what a restore set aside (WorldState::retained) takes the same entry back;
  // anything else forgets the retained entries, which no state of this world's future names.
  if (!s.retained.empty() && s.retained.front()->type == g->type &&
      s.retained.front()->hash == g->hash) {
    g = s.retained.front();
    s.retained.erase(s.retained.begin());
  } else {
    s.retained.clear();
  }
  s.geometries.push_back(std::move(g));
  return GeometryId{static_cast<std::uint32_t>(s.geometries.size())};
}

}  // namespace

}  // namespace sim_detail

Vec3 BodyState::world_center() const noexcept {
  // rotate(q, 0) is exactly zero, so a primitive's centre is its position, bit for bit.
  return position + rotate(orientation, center_of_mass);
}

Expected<GeometryId> World::create_convex_hull(std::span<const Vec3> points) {
  auto hull = sim_detail::build_hull(points);
  if (!hull) return Status::error("invalid convex hull: " + hull.message());
  return sim_detail::add(*s_, sim_detail::make_hull_geometry(std::move(*hull)));
}

Expected<GeometryId> World::create_mesh(std::span<const Vec3> vertices,
                                        std::span<const std::uint32_t> indices) {
  auto mesh = sim_detail::build_mesh(vertices, indices);
  if (!mesh) return Status::error("invalid " + mesh.message());
  return sim_detail::add(*s_, sim_detail::make_mesh_geometry(std::move(*mesh)));
}

Expected<GeometryId> World::create_heightfield(const HeightfieldDef& def) {
  auto hf = sim_detail::build_heightfield(def);
  if (!hf) return Status::error("invalid " + hf.message());
  return sim_detail::add(*s_, sim_detail::make_heightfield_geometry(std::move(*hf)));
}

Expected<std::uint32_t> World::mesh_dropped_triangles(GeometryId id) const {
  const sim_detail::Geometry* g = sim_detail::find_geometry(s_->geometries, id);
  if (g == nullptr)
    return Status::error("no geometry with ID " + std::to_string(id.value) + " (" +
                         std::to_string(s_->geometries.size()) + " registered)");
  if (g->type != sim_detail::GeometryType::mesh)
    return Status::error("geometry " + std::to_string(id.value) + " is a " +
                         sim_detail::geometry_type_name(g->type) + ", not a triangle mesh");
  return g->mesh().dropped_triangles;
}

Expected<ShapeOutline> World::body_outline(BodyId id) const {
  const auto b = body(id);
  if (!b) return Status::error(b.message());
  ShapeOutline out;
  sim_detail::shape_kind(b->shape.type)
      .outline(b->shape, s_->geometry(b->shape), b->position, b->orientation, out);
  return out;
}

Expected<GeometryId> World::create_compound(std::span<const CompoundChild> children) {
  auto compound = sim_detail::build_compound(s_->geometries, children);
  if (!compound) return Status::error("invalid compound: " + compound.message());
  return sim_detail::add(*s_, sim_detail::make_compound_geometry(std::move(*compound)));
}

std::size_t World::geometry_count() const noexcept {
  return s_->geometries.size();
}

Expected<std::uint64_t> World::geometry_hash(GeometryId id) const {
  const sim_detail::Geometry* g = sim_detail::find_geometry(s_->geometries, id);
  if (g == nullptr)
    return Status::error("no geometry with ID " + std::to_string(id.value) + " (" +
                         std::to_string(s_->geometries.size()) + " registered)");
  return g->hash;
}

Expected<MassProperties> World::mass_properties(const Shape& shape, Fixed mass) const {
  if (auto e = sim_detail::check_shape(s_->geometries, shape, BodyType::dynamic); !e.empty())
    return Status::error("invalid shape: " + e);
  if (mass <= Fixed::zero()) return Status::error("mass must be > 0, got " + to_string(mass));
  return sim_detail::shape_kind(shape.type).mass_properties(shape, s_->geometry(shape), mass);
}

}  // namespace detsim
