// golden/sim.txt: the state hashes of a mixed scene every 60 frames. Every compiler, optimisation
// level and machine must reproduce them (this test runs in the gcc -O3 and the clang sanitizer
// builds alike). A change is a change of the simulation's results: regenerate only on purpose,
//   DETSIM_UPDATE_GOLDEN=1 <build>/tests/sim_golden_test
// and say in the commit why the results changed.
#include <map>
#include <string>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

#include "support/golden.hpp"

namespace detsim {
namespace {

using namespace detsim::literals;

const char* const kGoldenPath = DETSIM_SOURCE_DIR "/golden/sim.txt";

// Spheres, boxes and capsules rained from RNG-chosen places onto a ground plane, a kinematic paddle
// sweeping through them, a tilted static ramp, forces and impulses from the RNG every frame: most
// of the stepper's paths (every shape pair, sleep and wake, kinematic pushing, warm starting).
std::map<std::string, std::uint64_t> run_scene() {
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

  std::map<std::string, std::uint64_t> hashes;
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
    if (frame % 60 == 0)
      hashes["frame_" + std::to_string(1000 + frame).substr(1)] = w.hashes().total;
  }
  return hashes;
}

TEST(SimGolden, MixedSceneReproducesItsGoldenHashes) {
  test::check_golden(kGoldenPath,
                     "# World state hashes (XXH3-64 of the canonical state) of the mixed scene "
                     "in\n# tests/sim_golden_test.cpp every 60 frames. Every machine must "
                     "reproduce these.\n# Regenerate only on purpose: DETSIM_UPDATE_GOLDEN=1 "
                     "<build>/tests/sim_golden_test\n",
                     run_scene());
}

}  // namespace
}  // namespace detsim
