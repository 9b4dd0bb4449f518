// The solid properties of a hull (hull.hpp: solid_properties): volume, centroid and inertia by the
// divergence theorem, then the principal frame (inertia.cpp).
//
// Method: the tetrahedra from a reference point o to each fan triangle (a, b, c) of each face
// (faces are convex, counter-clockwise from outside) tile the solid with signed volumes
// det[a b c] / 6 (coordinates relative to o), whatever side of a face o lies on. Over one such
// tetrahedron, exactly:
//   volume        det / 6
//   first moment  det / 24 * s,                                  s = a + b + c
//   second moment det / 120 * (a a^T + b b^T + c c^T + s s^T)    (the covariance about o)
// (Tonon, "Explicit exact formulas for the 3-D tetrahedron inertia tensor", 2004; the same sums as
// Mirtich's face integrals, in matrix form). Summed over the faces, these give the solid's.
//
// Precision: o is the bounding box's centre, so no coordinate exceeds half the extent and the
// centroid is near o (no cancellation in "second moment - centroid centroid^T"). The coordinates
// are then scaled by a power of two so that the largest lies in [1, 2): a determinant is below
// (2 sqrt 3)^3 < 2^6, a factor of the second moment below 48 and their product below 2^11, far
// inside the range, and every term keeps 32 fraction bits whatever the hull's size (a 1 mm hull
// and a 1 km hull are computed alike); the results are scaled back by shifts (exact upwards). Each
// determinant is an exact sum rounded once; each tetrahedron's moments are det times an exactly
// summed factor, and all of them are summed exactly (ProductSum) and rounded once per entry. So
// the volume, centroid and tensor are within a few 2^-32 of the largest term, relative to the
// hull's size: about 1e-9 relative for a compact hull, and the Fixed resolution (2^-32 m^2) bounds
// the tensor of a hull of millimetres.
#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <string>

#include <detsim/fixed/decimal.hpp>
#include <detsim/fixed/exact_sum.hpp>
#include <detsim/fixed/math.hpp>

#include "../limits.hpp"
#include "hull.hpp"
#include "inertia.hpp"

namespace detsim::sim_detail {

namespace hull_mass_detail {

std::uint64_t magnitude(Fixed x) noexcept {
  const auto r = static_cast<std::uint64_t>(x.raw());
  return x.raw() < 0 ? 0U - r : r;
}

Fixed component(Vec3 v, std::size_t i) noexcept {
  return i == 0 ? v.x : (i == 1 ? v.y : v.z);
}

}  // namespace hull_mass_detail

Expected<SolidProperties> solid_properties(const Hull& hull) {
  using namespace hull_mass_detail;
  const Vec3 o = hull.aabb_min + Vec3{(hull.aabb_max.x - hull.aabb_min.x) >> 1,
                                      (hull.aabb_max.y - hull.aabb_min.y) >> 1,
                                      (hull.aabb_max.z - hull.aabb_min.z) >> 1};
  std::uint64_t largest = 0;
  for (const Vec3 p : hull.vertices) {
    const Vec3 q = p - o;
    largest = std::max({largest, magnitude(q.x), magnitude(q.y), magnitude(q.z)});
  }
  if (largest == 0) return Status::error("convex hull: the solid has no extent");
  // Scaled coordinates are (p - o) * 2^shift, in [1, 2) at the largest.
  const int shift = Fixed::fraction_bits + 1 - (64 - std::countl_zero(largest));
  std::vector<Vec3> s;
  s.reserve(hull.vertices.size());
  for (const Vec3 p : hull.vertices) {
    const Vec3 q = p - o;
    s.push_back({q.x << shift, q.y << shift, q.z << shift});
  }

  detail::ProductSum six_volume;
  std::array<detail::ProductSum, 3> first;   // sum of det * s_i          (24 first moment)
  std::array<detail::ProductSum, 6> second;  // sum of det * X_ij        (120 second moment)
  constexpr std::array<std::array<std::size_t, 2>, 6> kMomentPairs{
      {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}}};
  for (const HullFace& face : hull.faces) {
    const std::uint16_t* loop = hull.face_vertices.data() + face.first;
    const Vec3 a = s[loop[0]];
    for (std::uint16_t k = 1; k + 1 < face.count; ++k) {
      const Vec3 b = s[loop[k]];
      const Vec3 c = s[loop[k + 1]];
      const Fixed det = determinant(Mat3{{a, b, c}});
      const Vec3 sum = a + b + c;
      six_volume.add_product(det.raw(), Fixed::one().raw());
      for (std::size_t i = 0; i < 3; ++i)
        first[i].add_product(det.raw(), component(sum, i).raw());
      for (std::size_t e = 0; e < kMomentPairs.size(); ++e) {
        const std::size_t i = kMomentPairs[e][0];
        const std::size_t j = kMomentPairs[e][1];
        detail::ProductSum x;
        for (const Vec3 v : {a, b, c, sum})
          x.add_product(component(v, i).raw(), component(v, j).raw());
        second[e].add_product(det.raw(), x.to_fixed().raw());
      }
    }
  }
  const Fixed v6 = six_volume.to_fixed();
  if (v6 <= Fixed::zero()) return Status::error("convex hull: the solid has no volume");
  // Per unit volume: centroid = first / (4 * 6V), covariance about o = second / (20 * 6V).
  const Fixed four_v6 = v6 * Fixed::from_int(4);
  const Fixed twenty_v6 = v6 * Fixed::from_int(20);
  const Vec3 centroid{first[0].to_fixed() / four_v6, first[1].to_fixed() / four_v6,
                      first[2].to_fixed() / four_v6};
  std::array<Fixed, 6> cov{};  // about the centroid: E[x_i x_j] - c_i c_j
  for (std::size_t e = 0; e < kMomentPairs.size(); ++e) {
    const Fixed ci = component(centroid, kMomentPairs[e][0]);
    const Fixed cj = component(centroid, kMomentPairs[e][1]);
    cov[e] = second[e].to_fixed() / twenty_v6 - ci * cj;
  }
  // Inertia per unit mass: trace(cov) E - cov.
  const Fixed xx = cov[1] + cov[2];
  const Fixed yy = cov[0] + cov[2];
  const Fixed zz = cov[0] + cov[1];

  // Back to metres: lengths by 2^-shift, areas by 2^-2shift, volumes by 2^-3shift.
  const Fixed volume_scaled = v6 / Fixed::from_int(6);
  const int up = -3 * shift;
  if (up > 0 && (up >= 63 || volume_scaled.raw() > (max_quantity.raw() >> up)))
    return Status::error(
        "convex hull: the volume would be above the limit 2147483647 m^3 (the points span " +
        to_string(max(hull.aabb_max.x - hull.aabb_min.x,
                      max(hull.aabb_max.y - hull.aabb_min.y, hull.aabb_max.z - hull.aabb_min.z))) +
        " m)");
  SolidProperties out;
  out.volume = volume_scaled >> (3 * shift);
  out.centroid = o + Vec3{centroid.x >> shift, centroid.y >> shift, centroid.z >> shift};
  const int area_shift = 2 * shift;
  const auto metres2 = [area_shift](Fixed x) { return x >> area_shift; };
  out.inertia_per_mass = Mat3{{Vec3{metres2(xx), metres2(-cov[3]), metres2(-cov[4])},
                               Vec3{metres2(-cov[3]), metres2(yy), metres2(-cov[5])},
                               Vec3{metres2(-cov[4]), metres2(-cov[5]), metres2(zz)}}};
  for (const Vec3& row : out.inertia_per_mass.rows) {
    if (beyond(row.x, max_quantity) || beyond(row.y, max_quantity) || beyond(row.z, max_quantity))
      return Status::error(
          "convex hull: a moment of inertia per unit mass would be above the "
          "limit 2147483647 m^2");
  }
  const PrincipalFrame frame = principal_frame(out.inertia_per_mass);
  out.principal = frame.moments;
  out.principal_axes = frame.axes;
  return out;
}

}  // namespace detsim::sim_detail
