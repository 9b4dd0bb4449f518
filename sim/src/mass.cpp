// Volumes and moments of inertia of the shapes, in Fixed arithmetic only.
//
// The moments are computed per unit mass and scaled last, so a body given a mass gets the same
// inertia whatever its volume rounds to. Each product of two lengths goes through the exact
// dot/cross of vec3.hpp where that helps; the remaining error is a few ulp relative to the moment,
// far below what the solver can see.
#include <detsim/fixed/decimal.hpp>
#include <detsim/fixed/math.hpp>
#include <detsim/sim/mass.hpp>

namespace detsim {

using namespace detsim::literals;

namespace {

// r^2 with one rounding.
Fixed square(Fixed r) noexcept {
  return r * r;
}

}  // namespace

Fixed volume(const Shape& shape) noexcept {
  switch (shape.type) {
    case ShapeType::sphere:
      // 4/3 pi r^3
      return (4_fx * Fixed::pi() / 3_fx) * (square(shape.radius) * shape.radius);
    case ShapeType::box: {
      const Vec3 h = shape.half_extents;
      return 8_fx * (h.x * h.y * h.z);
    }
    case ShapeType::capsule: {
      const Fixed r2 = square(shape.radius);
      // pi r^2 (2 h) + 4/3 pi r^3 = pi r^2 (2 h + 4/3 r)
      return Fixed::pi() * r2 * (2_fx * shape.half_height + 4_fx * shape.radius / 3_fx);
    }
    case ShapeType::plane:
      return {};
  }
  return {};
}

MassProperties mass_properties(const Shape& shape, Fixed mass) noexcept {
  if (mass <= Fixed::zero()) return {};
  switch (shape.type) {
    case ShapeType::sphere: {
      const Fixed i = 2_fx * mass * square(shape.radius) / 5_fx;
      return {mass, {i, i, i}};
    }
    case ShapeType::box: {
      const Vec3 h = shape.half_extents;
      const Fixed x2 = square(h.x);
      const Fixed y2 = square(h.y);
      const Fixed z2 = square(h.z);
      const Fixed third = mass / 3_fx;
      return {mass, {third * (y2 + z2), third * (x2 + z2), third * (x2 + y2)}};
    }
    case ShapeType::capsule: {
      // Cylinder of half height h and two hemispheres of radius r. Their volumes are in the ratio
      // 2 h : 4/3 r = 3 h : 2 r, so the cylinder carries 3h / (3h + 2r) of the mass.
      const Fixed r = shape.radius;
      const Fixed h = shape.half_height;
      const Fixed r2 = square(r);
      const Fixed h2 = square(h);
      const Fixed parts = 3_fx * h + 2_fx * r;
      const Fixed cylinder = mass * (3_fx * h) / parts;
      const Fixed caps = mass - cylinder;
      // About the axis: cylinder m r^2 / 2, hemispheres 2/5 m r^2.
      const Fixed axial = cylinder * r2 / 2_fx + 2_fx * caps * r2 / 5_fx;
      // Across the axis: cylinder m (r^2 / 4 + (2h)^2 / 12); the hemisphere pair, whose centres
      // of mass sit 3r/8 beyond the segment ends, m (2/5 r^2 + h^2 + 3/4 h r) (parallel axes).
      const Fixed across =
          cylinder * (r2 / 4_fx + h2 / 3_fx) + caps * (2_fx * r2 / 5_fx + h2 + 3_fx * h * r / 4_fx);
      return {mass, {across, axial, across}};
    }
    case ShapeType::plane:
      return {};
  }
  return {};
}

}  // namespace detsim
