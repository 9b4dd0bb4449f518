// The narrowphase of shapes with sub-shapes (collide.hpp, collide_all): a compound's parts and a
// surface's triangles each make their own manifold, so that a body pair can touch with several
// normals at once (a box on a stair's tread and riser). Whole shapes go through collide().
#include "collide.hpp"
#include "geometry/geometry.hpp"

namespace detsim::sim_detail {

std::uint32_t sub_shape_count(const Shape&, const Geometry* g) noexcept {
  if (g == nullptr) return 1;
  switch (g->type) {
    case GeometryType::convex_hull:
      return 1;
    case GeometryType::mesh:
      return triangle_count(g->mesh());
    case GeometryType::heightfield:
      return triangle_count(g->heightfield());
    case GeometryType::compound:
      return static_cast<std::uint32_t>(g->compound().parts.size());
  }
  return 1;
}

bool has_sub_shapes(const PosedShape& s) noexcept {
  return s.geometry != nullptr && s.geometry->type != GeometryType::convex_hull;
}

void collide_all(const PosedShape& a, const PosedShape& b, Fixed margin,
                 std::vector<SubManifold>& out) {
  out.clear();
  // Compounds and surfaces collide part by part once their narrowphase lands; until then they
  // make no manifold (the pair stays in the broadphase without contact points).
  if (has_sub_shapes(a) || has_sub_shapes(b)) return;
  const Manifold m = collide(a, b, margin);
  if (m.count > 0) out.push_back({0, 0, m});
}

}  // namespace detsim::sim_detail
