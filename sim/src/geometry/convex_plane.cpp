// convex_plane: a convex shape against the static half-space below a plane (shape_plane.cpp).
//
// Heights above the plane are the centre's height plus each local point's dot with the plane's
// normal in the shape's frame (one rotation of the normal, exact dots), so the vertices of a face
// lying level with the plane get bitwise equal separations, as in box_plane.
#include <array>
#include <cstdint>
#include <span>

#include <detsim/fixed/math.hpp>
#include <detsim/fixed/vec3.hpp>

#include "../collide_util.hpp"
#include "convex_internal.hpp"

namespace detsim::sim_detail {

namespace convex::plane_detail {

using namespace narrow;

/// The most candidate points: every vertex of the largest hull.
constexpr std::size_t kMaxPoints = max_hull_vertices;

struct PlaneCandidates {
  std::array<Candidate, kMaxPoints> c{};
  std::size_t n = 0;
};

struct PlaneFrame {
  Vec3 up;        ///< world
  Vec3 up_local;  ///< in the shape's frame
  Fixed centre_height;
  Fixed radius;
  Mat3 rotation;
};

/// The candidate of local core point p (relative to the shape's position).
void add_local(const PlaneFrame& f, Vec3 p, std::uint16_t feature, Fixed margin,
               PlaneCandidates& out) noexcept {
  const Fixed height = f.centre_height + dot(p, f.up_local);
  const Fixed separation = height - f.radius;
  if (separation > margin || out.n >= out.c.size()) return;
  const Vec3 core = f.rotation * p;
  const Vec3 point = midpoint(core - f.up * f.radius, core - f.up * height);
  out.c[out.n++] = {point, separation, pair_feature(feature, plane_face)};
}

void cylinder_points(const ConvexView& v, const PlaneFrame& f, Fixed margin,
                     PlaneCandidates& out) noexcept {
  const Vec3 down = -f.up_local;
  const Face face = supporting_face(v, down);
  for (unsigned i = 0; i < face.count; ++i)
    add_local(f, face.points[i], face.vertex[i], margin, out);
  // A tilted cap: its true lowest rim point lies between two polygon points.
  const Fixed tilt2 = down.x * down.x + down.z * down.z;
  if (face.count > 2 && tilt2 >= flat_sin2) {
    const SupportPoint s = core_support(v, down);
    add_local(f, s.point, s.feature, margin, out);
  }
}

void vertex_points(const ConvexView& v, const PlaneFrame& f, Fixed margin,
                   PlaneCandidates& out) noexcept {
  switch (v.kind) {
    case ConvexKind::sphere:
      add_local(f, Vec3{}, whole_shape, margin, out);
      return;
    case ConvexKind::capsule:
      for (const bool top : {false, true}) {
        if (top && v.half_height == Fixed::zero()) break;
        const Vec3 end{Fixed::zero(), signed_value(top, v.half_height), Fixed::zero()};
        add_local(f, end, capsule_end(top), margin, out);
      }
      return;
    case ConvexKind::box:
      for (unsigned bits = 0; bits < 8; ++bits) {
        const Signs s{(bits & 1U) != 0, (bits & 2U) != 0, (bits & 4U) != 0};
        const Vec3 h = v.half_extents;
        add_local(f, {signed_value(s[0], h.x), signed_value(s[1], h.y), signed_value(s[2], h.z)},
                  box_vertex(s), margin, out);
      }
      return;
    case ConvexKind::cylinder:
      cylinder_points(v, f, margin, out);
      return;
    case ConvexKind::hull:
      for (std::size_t i = 0; i < v.hull->vertices.size(); ++i) {
        add_local(f, v.hull->vertices[i],
                  convex_feature(static_cast<unsigned>(Kind::vertex), static_cast<unsigned>(i)),
                  margin, out);
      }
      return;
  }
}

}  // namespace convex::plane_detail

Manifold convex_plane(const ConvexView& a, const Pose& pa, const Pose& pb, Fixed margin) noexcept {
  using namespace convex;
  using namespace convex::plane_detail;
  PlaneFrame f;
  f.up = narrow::unit_or(pb.rotation.column(1), Vec3::unit_y());
  f.up_local = narrow::to_local(pa.rotation, f.up);
  f.centre_height = dot(pa.position - pb.position, f.up);
  f.radius = core_radius(a);
  f.rotation = pa.rotation;
  if (f.centre_height - bounding_radius(a) > margin) return {};
  PlaneCandidates found;
  vertex_points(a, f, margin, found);
  Manifold m;
  m.normal = -f.up;
  reduce_into(std::span<const convex::Candidate>(found.c.data(), found.n), m.normal, pa.position,
              m);
  return m;
}

}  // namespace detsim::sim_detail
