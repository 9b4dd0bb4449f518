// The world of registered geometry shared by the state fuzzer and its seed maker: a state restores
// only into a world that holds the geometry it names (docs/STATE.md, "geometry"), so the fuzzer's
// target world and the seeds' world register the same hull, mesh, heightfield and compound, in the
// same order. With bodies (`with_bodies`) it is a seed's scene: one body of each kind on them.
#pragma once

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include <detsim/sim/world.hpp>

namespace fuzz_support {

inline detsim::World geometry_world(bool with_bodies) {
  using detsim::Fixed;
  using detsim::Vec3;
  const Fixed h = Fixed::half();
  const Fixed one = Fixed::one();
  auto created = detsim::World::create({});
  if (!created) return detsim::World();
  detsim::World w = std::move(created.value());
  std::vector<Vec3> corners;
  for (int i = 0; i < 8; ++i)
    corners.push_back({(i & 1) != 0 ? h : -h, (i & 2) != 0 ? h : -h, (i & 4) != 0 ? h : -h});
  const auto hull = w.create_convex_hull(corners);
  const Fixed ten = Fixed::from_int(10);
  const std::vector<Vec3> vertices{
      {-ten, {}, -ten}, {-ten, {}, ten}, {ten, {}, ten}, {ten, {}, -ten}};
  const std::vector<std::uint32_t> indices{0, 1, 2, 0, 2, 3};
  const auto mesh = w.create_mesh(vertices, indices);
  detsim::HeightfieldDef field;
  field.rows = 3;
  field.columns = 3;
  field.cell_size = Fixed::from_int(4);
  field.heights = {Fixed{}, h, Fixed{}, h, one, h, Fixed{}, h, Fixed{}};
  const auto heights = w.create_heightfield(field);
  if (!hull || !mesh || !heights) return detsim::World();
  const std::array<detsim::CompoundChild, 2> parts{{
      {detsim::Shape::box({h, h / Fixed::from_int(4), h}), {Fixed{}, h, Fixed{}}, {}},
      {detsim::Shape::convex(hull.value()), {h, one, Fixed{}}, {}},
  }};
  const auto compound = w.create_compound(parts);
  if (!compound) return detsim::World();
  if (!with_bodies) return w;
  (void)w.create_body(
      {.type = detsim::BodyType::static_body, .shape = detsim::Shape::mesh(mesh.value())});
  (void)w.create_body({.type = detsim::BodyType::static_body,
                       .shape = detsim::Shape::heightfield(heights.value()),
                       .position = {Fixed::from_int(20), Fixed{}, Fixed{}}});
  (void)w.create_body(
      {.shape = detsim::Shape::convex(hull.value()), .position = {Fixed{}, one, Fixed{}}});
  (void)w.create_body({.shape = detsim::Shape::compound(compound.value()),
                       .position = {Fixed::from_int(3), one, Fixed{}}});
  (void)w.create_body({.shape = detsim::Shape::cylinder(h, h),
                       .position = {Fixed::from_int(24), Fixed::from_int(3), Fixed::from_int(4)}});
  return w;
}

}  // namespace fuzz_support
