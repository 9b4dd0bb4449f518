// The "geometry" section of the state (docs/STATE.md): the world's registered geometry, named by
// type and content hash, never by its data. A snapshot of a pile on a 100k-triangle level is as
// small as the same pile on a plane; restoring it needs the world to have the same geometry under
// the same IDs, which a game has by registering its level before restoring (as it did before
// saving), and which a replay has by running its scenario's setup.
#include <string>

#include "geometry/geometry.hpp"
#include "state_io.hpp"

namespace detsim::sim_detail {

namespace {

// A record: the type byte and the 8-byte hash.
constexpr std::size_t kRecordBytes = 9;

std::string hex(std::uint64_t v) {
  static const char* digits = "0123456789abcdef";
  std::string out = "0x";
  for (int shift = 60; shift >= 0; shift -= 4)
    out += digits[(v >> shift) & 0xFU];
  return out;
}

}  // namespace

void write_geometry(const WorldState& s, ByteWriter& w) {
  w.var(s.geometries.size());
  for (const auto& g : s.geometries) {
    w.u8(static_cast<std::uint8_t>(g->type));
    w.u64(g->hash);
  }
}

// `s.geometries` holds the restoring world's geometry (World::restore puts it there): the state's
// list must be a prefix of it, entry for entry; geometry registered after the state was saved
// leaves the state with the rest of what came later, like bodies created since (World::restore
// sets it aside: WorldState::retained).
bool read_geometry(std::span<const std::uint8_t>, ByteReader& r, WorldState& s,
                   std::string& error) {
  const std::size_t count_at = r.offset();
  const std::uint64_t count = r.var("geometry count");
  if (!r.ok()) return false;
  if (count > r.remaining() / kRecordBytes) {
    error = "byte " + std::to_string(count_at) + ": geometry count " + std::to_string(count) +
            " exceeds what the data can hold";
    return false;
  }
  for (std::uint64_t i = 0; i < count; ++i) {
    const std::size_t at = r.offset();
    const std::uint8_t type = r.u8("geometry type");
    const std::uint64_t hash = r.u64("geometry hash");
    if (!r.ok()) return false;
    const std::string id = "geometry " + std::to_string(i + 1);
    if (type < static_cast<std::uint8_t>(GeometryType::convex_hull) ||
        type > static_cast<std::uint8_t>(GeometryType::compound)) {
      error = "byte " + std::to_string(at) + ": " + id + ": unknown geometry type " +
              std::to_string(type);
      return false;
    }
    const auto t = static_cast<GeometryType>(type);
    const std::string named =
        id + " (" + geometry_type_name(t) + ", content hash " + hex(hash) + ")";
    if (i >= s.geometries.size()) {
      error = "byte " + std::to_string(at) + ": the state needs " + named +
              ", which this world does not have (it has " + std::to_string(s.geometries.size()) +
              " geometries): register the same geometry, in the same order, before restoring";
      return false;
    }
    const Geometry& have = *s.geometries[static_cast<std::size_t>(i)];
    if (have.type != t || have.hash != hash) {
      error = "byte " + std::to_string(at) + ": the state needs " + named + ", but this world's " +
              id + " is a " + geometry_type_name(have.type) + " of content hash " + hex(have.hash) +
              ": register the same geometry, in the same order, before restoring";
      return false;
    }
  }
  s.geometries.resize(static_cast<std::size_t>(count));
  return true;
}

}  // namespace detsim::sim_detail
