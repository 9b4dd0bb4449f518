// A proven lower bound of the distance between two convex shapes (gap.hpp).
#include "gap.hpp"

#include "geometry/convex_internal.hpp"
#include "geometry/geometry.hpp"

namespace detsim::sim_detail {

std::optional<ConvexView> convex_view(const Shape& shape, const Geometry* g) {
  switch (shape.type) {
    case ShapeType::sphere:
    case ShapeType::box:
    case ShapeType::capsule:
    case ShapeType::cylinder:
      return ConvexView::of(shape);
    case ShapeType::convex:
      return ConvexView::of_hull(g->hull());
    default:
      return std::nullopt;
  }
}

Gap convex_gap(const PosedShape& a, const ConvexView& va, const PosedShape& b,
               const ConvexView& vb) {
  using namespace convex;
  const Vec3 origin = a.pose.position;
  const Body ba = make_body(va, a.pose, origin);
  const Body bb = make_body(vb, b.pose, origin);
  const Closest c = gjk_closest(ba, bb);
  if (c.overlap || c.on_b == c.on_a) {
    const Manifold m = collide(a, b, Fixed::zero());
    if (m.count == 0) return {Fixed::zero(), Vec3::zero(), origin};
    std::uint8_t deepest = 0;
    for (std::uint8_t k = 1; k < m.count; ++k) {
      if (m.points[k].separation < m.points[deepest].separation) deepest = k;
    }
    const ContactPoint& p = m.points[deepest];
    // The point lies midway between the surfaces; b's surface is half the separation on.
    return {p.separation, m.normal, p.point + m.normal * (p.separation >> 1)};
  }
  const Vec3 n = normalize(c.on_b - c.on_a);
  const Fixed gap =
      dot(n, support_at(bb, -n).point - support_at(ba, n).point) - ba.radius - bb.radius;
  return {gap, n, origin + c.on_b - n * bb.radius};
}

}  // namespace detsim::sim_detail
