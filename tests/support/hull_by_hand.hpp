// Test-only hulls made by hand (the hull builder is another engineer's work): a brute-force
// construction from a handful of points — every plane through three points with all points on one
// side is a face, coplanar points merge into one polygon ordered counter-clockwise seen from
// outside, edges come from the face loops. Fine for the ~12 points of a test, O(n^4).
#pragma once

#include <algorithm>
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

#include <detsim/fixed/math.hpp>
#include <detsim/fixed/vec3.hpp>

#include "sim/src/geometry/hull.hpp"

namespace detsim::collide_test {

inline bool raw_less(Vec3 p, Vec3 q) {
  if (p.x != q.x) return p.x < q.x;
  if (p.y != q.y) return p.y < q.y;
  return p.z < q.z;
}

inline sim_detail::Hull hull_by_hand(std::vector<Vec3> points) {
  using sim_detail::Hull;
  using sim_detail::HullEdge;
  using sim_detail::HullFace;
  const Fixed tol = Fixed::from_raw(Fixed::one_raw >> 20);
  std::sort(points.begin(), points.end(), raw_less);
  points.erase(std::unique(points.begin(), points.end()), points.end());
  Hull h;
  h.vertices = points;
  const std::size_t n = points.size();
  std::vector<std::pair<Vec3, Fixed>> planes;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      for (std::size_t k = j + 1; k < n; ++k) {
        const Vec3 c = cross(points[j] - points[i], points[k] - points[i]);
        if (length_squared(c) < tol) continue;
        Vec3 normal = normalize(c);
        bool above = false;
        bool below = false;
        for (const Vec3& p : points) {
          const Fixed s = dot(normal, p - points[i]);
          above = above || s > tol;
          below = below || s < -tol;
        }
        if (above && below) continue;
        if (above) normal = -normal;
        const Fixed offset = dot(normal, points[i]);
        const bool known = std::any_of(planes.begin(), planes.end(), [&](const auto& pl) {
          return length_squared(pl.first - normal) < tol && abs(pl.second - offset) < tol;
        });
        if (!known) planes.emplace_back(normal, offset);
      }
    }
  }
  for (const auto& [normal, offset] : planes) {
    std::vector<std::uint16_t> on;
    Vec3 centre;
    for (std::size_t i = 0; i < n; ++i) {
      if (abs(dot(normal, points[i]) - offset) <= tol) {
        on.push_back(static_cast<std::uint16_t>(i));
        centre += points[i];
      }
    }
    centre = centre / Fixed::from_int(static_cast<std::int32_t>(on.size()));
    const Vec3 u = normalize(points[on[0]] - centre);
    const Vec3 v = cross(normal, u);
    const auto angle = [&](std::uint16_t i) {
      const Vec3 d = points[i] - centre;
      return atan2(dot(d, v), dot(d, u));
    };
    std::sort(on.begin(), on.end(),
              [&](std::uint16_t x, std::uint16_t y) { return angle(x) < angle(y); });
    HullFace f{normal, offset, static_cast<std::uint16_t>(h.face_vertices.size()),
               static_cast<std::uint16_t>(on.size())};
    h.faces.push_back(f);
    h.face_vertices.insert(h.face_vertices.end(), on.begin(), on.end());
  }
  std::map<std::pair<std::uint16_t, std::uint16_t>, HullEdge> edges;
  for (std::size_t fi = 0; fi < h.faces.size(); ++fi) {
    const HullFace& f = h.faces[fi];
    for (std::size_t i = 0; i < f.count; ++i) {
      std::uint16_t a = h.face_vertices[f.first + i];
      std::uint16_t b = h.face_vertices[f.first + (i + 1) % f.count];
      if (b < a) std::swap(a, b);
      auto [it, fresh] =
          edges.try_emplace({a, b}, HullEdge{a, b, 0, 0, normalize(h.vertices[b] - h.vertices[a])});
      (fresh ? it->second.face_0 : it->second.face_1) = static_cast<std::uint16_t>(fi);
    }
  }
  for (const auto& [key, e] : edges)
    h.edges.push_back(e);
  h.aabb_min = h.aabb_max = points[0];
  for (const Vec3& p : points) {
    h.aabb_min = {min(h.aabb_min.x, p.x), min(h.aabb_min.y, p.y), min(h.aabb_min.z, p.z)};
    h.aabb_max = {max(h.aabb_max.x, p.x), max(h.aabb_max.y, p.y), max(h.aabb_max.z, p.z)};
    h.bounding_radius = max(h.bounding_radius, length(p));
  }
  return h;
}

inline sim_detail::Hull box_hull(Vec3 half) {
  std::vector<Vec3> p;
  for (unsigned bits = 0; bits < 8; ++bits) {
    p.push_back({(bits & 1U) != 0 ? half.x : -half.x, (bits & 2U) != 0 ? half.y : -half.y,
                 (bits & 4U) != 0 ? half.z : -half.z});
  }
  return hull_by_hand(p);
}

}  // namespace detsim::collide_test
