// The compound builder (geometry.hpp: build_compound): each child checked, and the solid of the
// parts: volume, centroid, and the inertia tensor per unit mass about the centroid, with its
// principal frame.
//
// Mass properties, for parts of one density that do not overlap (the solid is the sum of the
// parts; an overlap would count twice, so it is the caller's to avoid):
//   V = sum V_i,  w_i = V_i / V,  c = sum w_i c_i,
//   I = sum w_i (R_i I_i R_i^T + |d_i|^2 E - d_i d_i^T),  d_i = c_i - c,
// with I_i a part's tensor per unit mass about its own centroid in its own frame (a primitive's
// moments from its kind with mass 1, a hull's SolidProperties::inertia_per_mass), R_i its
// rotation and c_i its centroid in the compound's frame (the position, plus the turned hull
// centroid). Per unit mass, because the moments per unit volume (density 1) of a 10^4 m part would
// leave the Fixed range long before the per-mass ones (at most ~10^9 m^2 here).
//
// Precision (Fixed resolution 2^-32, sizes and positions <= 10^4 m): each weight is rounded once,
// |error| <= 2^-33; the sums of products (the centroid, each tensor entry) are exact and rounded
// once (ProductSum). So the centroid is within n 2^-33 max|c_i| + 2^-33 (about 2^-33 per metre of
// offset per part: 10^-10 m for metre-sized parts, 10^-4 m for 64 parts 10^4 m out), and each
// tensor entry within n 2^-33 max|J_i| + rotate_inertia's and shift_inertia's 0.5 ulp: relative to
// the moments, a few 2^-32 times the ratio of the largest part's moment about the centroid to the
// compound's. principal_frame then adds its ~2^-28 of the largest entry (inertia.hpp).
#include <algorithm>
#include <string>

#include <detsim/fixed/decimal.hpp>
#include <detsim/fixed/exact_sum.hpp>
#include <detsim/fixed/math.hpp>

#include "../shapes.hpp"
#include "../world_state.hpp"
#include "inertia.hpp"

namespace detsim::sim_detail {

// Named, not anonymous: unity builds put many files of sim/src in one translation unit.
namespace compound_build {

/// The tensor per unit mass of a part about its own centroid, in its own frame.
Mat3 part_tensor(const ShapeKind& kind, const CompoundPart& part) noexcept {
  const Geometry* g = part_geometry(part);
  if (g != nullptr) return g->hull().solid.inertia_per_mass;
  const Vec3 m = kind.mass_properties(part.child.shape, nullptr, Fixed::one()).inertia;
  return Mat3{{Vec3{m.x, Fixed::zero(), Fixed::zero()}, Vec3{Fixed::zero(), m.y, Fixed::zero()},
               Vec3{Fixed::zero(), Fixed::zero(), m.z}}};
}

Fixed& entry(Mat3& m, std::size_t i, std::size_t j) noexcept {
  Vec3& row = m.rows[i];
  return j == 0 ? row.x : (j == 1 ? row.y : row.z);
}

bool tensor_beyond(const Mat3& m) noexcept {
  for (const Vec3& row : m.rows) {
    if (beyond(row.x, max_quantity) || beyond(row.y, max_quantity) || beyond(row.z, max_quantity))
      return true;
  }
  return false;
}

/// One child's checks and its part (volume and centroid filled); "" when valid.
std::string make_part(const GeometryTable& table, const CompoundChild& child, CompoundPart& part) {
  if (auto e = check_shape(table, child.shape, BodyType::dynamic); !e.empty()) return e;
  const ShapeKind& kind = shape_kind(child.shape.type);
  if (!kind.bounded || (kind.geometry && *kind.geometry != GeometryType::convex_hull))
    return std::string("a ") + kind.name +
           " cannot be a part of a compound (spheres, boxes, capsules, cylinders and convex hulls "
           "can)";
  if (auto e = check_orientation(child.orientation); !e.empty()) return e;
  const char* axes[] = {"x", "y", "z"};
  for (std::size_t i = 0; i < 3; ++i) {
    const Fixed p = i == 0 ? child.position.x : (i == 1 ? child.position.y : child.position.z);
    if (beyond(p, max_shape_size))
      return std::string("position ") + axes[i] + " must be within +-10000 m, got " + to_string(p);
  }
  part.child = child;
  if (kind.geometry) part.geometry = table[child.shape.geometry.value - 1];
  const Geometry* g = part_geometry(part);
  const Checked volume = kind.checked_volume(child.shape, g);
  if (volume.over())
    return above_limit(std::string("volume of the ") + kind.name, volume, max_quantity, "m^3");
  part.volume = volume.value();
  part.orientation = normalize(child.orientation);
  part.rotation = to_mat3(part.orientation);
  part.centroid = child.position;
  if (g != nullptr) part.centroid = child.position + part.rotation * g->hull().solid.centroid;
  return {};
}

}  // namespace compound_build

Expected<Compound> build_compound(const GeometryTable& table,
                                  std::span<const CompoundChild> children) {
  using namespace compound_build;
  if (children.empty()) return Status::error("a compound needs at least one child, got none");
  if (children.size() > max_compound_parts)
    return Status::error("a compound has at most " + std::to_string(max_compound_parts) +
                         " children, got " + std::to_string(children.size()));
  Compound c;
  c.parts.resize(children.size());
  Checked total = Fixed::zero();
  for (std::size_t i = 0; i < children.size(); ++i) {
    if (auto e = make_part(table, children[i], c.parts[i]); !e.empty())
      return Status::error("child " + std::to_string(i) + ": " + e);
    total = total + c.parts[i].volume;
    if (total.over())
      return Status::error(
          above_limit("the compound's volume (children 0.." + std::to_string(i) + ")", total,
                      max_quantity, "m^3"));
  }
  const Fixed volume = total.value();
  if (volume <= Fixed::zero())
    return Status::error("the compound's volume is 0 m^3 (its children are too small)");

  // The weights and the centroid: exact sums of products, rounded once.
  std::vector<Fixed> weight(c.parts.size());
  std::array<detail::ProductSum, 3> first;
  for (std::size_t i = 0; i < c.parts.size(); ++i) {
    weight[i] = c.parts[i].volume / volume;
    const Vec3 ci = c.parts[i].centroid;
    first[0].add_product(weight[i].raw(), ci.x.raw());
    first[1].add_product(weight[i].raw(), ci.y.raw());
    first[2].add_product(weight[i].raw(), ci.z.raw());
  }
  const Vec3 centroid{first[0].to_fixed(), first[1].to_fixed(), first[2].to_fixed()};

  // The tensor about the centroid: each part's turned, shifted (parallel axes) and weighted.
  std::array<std::array<detail::ProductSum, 3>, 3> tensor;
  for (std::size_t i = 0; i < c.parts.size(); ++i) {
    const CompoundPart& part = c.parts[i];
    const ShapeKind& kind = shape_kind(part.child.shape.type);
    Mat3 j = shift_inertia(rotate_inertia(part.rotation, part_tensor(kind, part)),
                           part.centroid - centroid);
    if (tensor_beyond(j))
      return Status::error("child " + std::to_string(i) +
                           ": its moment of inertia per unit mass about the compound's centroid "
                           "would be above the limit " +
                           to_string(max_quantity) + " m^2 (the children are too far apart)");
    for (std::size_t r = 0; r < 3; ++r) {
      for (std::size_t k = r; k < 3; ++k)
        tensor[r][k].add_product(weight[i].raw(), entry(j, r, k).raw());
    }
  }
  Mat3 inertia;
  for (std::size_t r = 0; r < 3; ++r) {
    for (std::size_t k = r; k < 3; ++k)
      entry(inertia, r, k) = entry(inertia, k, r) = tensor[r][k].to_fixed();
  }
  // A weighted mean of tensors within the limit is within it too (the weights sum to 1 up to
  // n 2^-33); checked anyway, as the simulation relies on it.
  if (tensor_beyond(inertia))
    return Status::error(
        "the compound's moment of inertia per unit mass would be above the limit " +
        to_string(max_quantity) + " m^2");
  c.solid.volume = volume;
  c.solid.centroid = centroid;
  c.solid.inertia_per_mass = inertia;
  const PrincipalFrame frame = principal_frame(inertia);
  c.solid.principal = frame.moments;
  c.solid.principal_axes = frame.axes;

  // Bounds: each part's box about its position (its kind's, turned by its rotation); the radius
  // about the origin is the largest |position| + part radius, grown by |centroid| so that it also
  // bounds every point's distance from the centre of mass (the triangle inequality).
  Fixed origin_radius = Fixed::zero();
  std::size_t largest = 0;
  for (std::size_t i = 0; i < c.parts.size(); ++i) {
    const CompoundPart& part = c.parts[i];
    const ShapeKind& kind = shape_kind(part.child.shape.type);
    const Geometry* g = part_geometry(part);
    const Vec3 e = kind.aabb_extent(part.child.shape, g, part.rotation);
    const Vec3 lo = part.child.position - e;
    const Vec3 hi = part.child.position + e;
    if (i == 0) {
      c.aabb_min = lo;
      c.aabb_max = hi;
    } else {
      c.aabb_min = {min(c.aabb_min.x, lo.x), min(c.aabb_min.y, lo.y), min(c.aabb_min.z, lo.z)};
      c.aabb_max = {max(c.aabb_max.x, hi.x), max(c.aabb_max.y, hi.y), max(c.aabb_max.z, hi.z)};
    }
    origin_radius =
        max(origin_radius, length(part.child.position) + kind.bounding_radius(part.child.shape, g));
    if (part.volume > c.parts[largest].volume) largest = i;  // ties: the lower index
  }
  c.bounding_radius = origin_radius + length(centroid);
  const CompoundPart& big = c.parts[largest];
  c.inner_radius =
      shape_kind(big.child.shape.type).smallest_dimension(big.child.shape, part_geometry(big));
  return c;
}

}  // namespace detsim::sim_detail
