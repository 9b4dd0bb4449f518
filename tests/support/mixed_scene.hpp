// The mixed scene of golden/sim.txt and golden/fields.txt: 600 frames that go through most of the
// stepper's paths. `each_frame(world, frame)` is called after every step (frames 1..600).
#pragma once

#include <functional>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

namespace detsim::test {

// Spheres, boxes and capsules rained from RNG-chosen places onto a ground plane, a kinematic paddle
// sweeping through them, a tilted static ramp, forces and impulses from the RNG every frame: most
// of the stepper's paths (every shape pair, sleep and wake, kinematic pushing, warm starting).
// Not a template: clang 14 leaves consteval literals (_fx) inside a function template's
// instantiation as undefined references.
inline void run_mixed_scene(const std::function<void(const World&, int)>& each_frame) {
  using namespace detsim::literals;
  WorldDef def;
  def.seed = 2026;
  auto created = World::create(def);
  EXPECT_TRUE(created.ok()) << created.message();
  World w = std::move(created.value());
  BodyDef ground;
  ground.type = BodyType::static_body;
  ground.shape = Shape::plane();
  (void)w.create_body(ground);
  BodyDef ramp;
  ramp.type = BodyType::static_body;
  ramp.shape = Shape::box({3_fx, 0.2_fx, 2_fx});
  ramp.position = {-4_fx, 1_fx, 0_fx};
  ramp.orientation = from_axis_angle(Vec3::unit_z(), -0.3_fx);
  (void)w.create_body(ramp);
  BodyDef paddle;
  paddle.type = BodyType::kinematic;
  paddle.shape = Shape::capsule(0.3_fx, 1.5_fx);
  paddle.position = {0_fx, 0.5_fx, -6_fx};
  paddle.orientation = from_axis_angle(Vec3::unit_x(), Fixed::half_pi());
  paddle.linear_velocity = {0_fx, 0_fx, 1_fx};
  const BodyId paddle_id = *w.create_body(paddle);

  for (int frame = 1; frame <= 600; ++frame) {
    if (frame <= 240 && frame % 8 == 0) {
      BodyDef d;
      const std::uint64_t kind = w.rng().below(3);
      // Each draw is its own statement or a braced-list element (evaluated left to right): the
      // order in which a function's arguments are evaluated is unspecified, and compilers differ.
      const Fixed size_1 = w.rng().uniform(0.2_fx, 0.5_fx);
      const Fixed size_2 = w.rng().uniform(0.1_fx, 0.5_fx);
      const Fixed size_3 = w.rng().uniform(0.2_fx, 0.5_fx);
      d.shape = kind == 0   ? Shape::sphere(size_1)
                : kind == 1 ? Shape::box({size_1, size_2, size_3})
                            : Shape::capsule(size_1 >> 1, size_2);
      d.position = {w.rng().uniform(-3_fx, 3_fx), w.rng().uniform(4_fx, 8_fx),
                    w.rng().uniform(-3_fx, 3_fx)};
      const Vec3 axis = w.rng().unit_vector();
      const Fixed angle = w.rng().uniform(0_fx, 3_fx);
      d.orientation = from_axis_angle(axis, angle);
      d.restitution = w.rng().uniform(0_fx, 0.5_fx);
      d.friction = w.rng().uniform(0.2_fx, 0.9_fx);
      (void)w.create_body(d);
    }
    if (frame == 300) (void)w.set_linear_velocity(paddle_id, {0_fx, 0_fx, -2_fx});
    const std::vector<BodyId> ids = w.body_ids();
    if (ids.size() > 3) {
      const BodyId target = ids[3 + w.rng().below(ids.size() - 3)];
      (void)w.apply_force_at_point(target, w.rng().unit_vector() * 20_fx,
                                   w.body(target)->position + Vec3{0_fx, 0.1_fx, 0_fx});
      if (frame % 97 == 0) (void)w.apply_linear_impulse(target, {0_fx, 3_fx, 0_fx});
    }
    w.step();
    each_frame(static_cast<const World&>(w), frame);
  }
}

}  // namespace detsim::test
