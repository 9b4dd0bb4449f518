// golden/fields.txt: what the simulation computed, independent of how the state is encoded.
//
// For every golden scenario run (tools/detsim/golden_runs.hpp, shared with golden/scenarios.txt)
// and the mixed scene of golden/sim.txt, every body's position, orientation, linear and angular
// velocity at every frame, hashed in a layout of this test's own (below) that no state encoding
// version changes. golden/scenarios.txt hashes the canonical state
// bytes, which change whenever the encoding does; this file does not, so a refactor of the state
// format (or of any code around the physics) can prove that every simulated value stayed the same
// bit for bit. Regenerate only when the physics changes on purpose:
//   DETSIM_UPDATE_GOLDEN=1 <build>/tests/sim_field_identity_test
#include <xxhash.h>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

#include "support/golden.hpp"
#include "support/mixed_scene.hpp"
#include "tools/detsim/golden_runs.hpp"

namespace detsim {
namespace {

const char* const kGoldenPath = DETSIM_SOURCE_DIR "/golden/fields.txt";

// The layout hashed per frame: the frame number (u64), then per body in ascending ID order its ID
// (u32) and the raw Q32.32 values (i64) of position x y z, orientation w x y z, linear velocity
// x y z and angular velocity x y z, then per character in ascending ID order its ID (u32), its
// position x y z and velocity x y z (a world without characters adds nothing), all little-endian.
class FieldBytes {
 public:
  void u32(std::uint32_t v) { put(v, 4); }
  void u64(std::uint64_t v) { put(v, 8); }
  void fixed(Fixed v) { put(static_cast<std::uint64_t>(v.raw()), 8); }
  void vec3(Vec3 v) {
    fixed(v.x);
    fixed(v.y);
    fixed(v.z);
  }
  void clear() { bytes_.clear(); }
  [[nodiscard]] std::uint64_t hash() const { return XXH3_64bits(bytes_.data(), bytes_.size()); }

 private:
  void put(std::uint64_t v, int n) {
    for (int i = 0; i < n; ++i)
      bytes_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  std::vector<std::uint8_t> bytes_;
};

std::uint64_t field_hash(const World& world, FieldBytes& bytes) {
  bytes.clear();
  bytes.u64(world.frame());
  for (const BodyId id : world.body_ids()) {
    const BodyState b = *world.body(id);
    bytes.u32(id.value);
    bytes.vec3(b.position);
    bytes.fixed(b.orientation.w);
    bytes.fixed(b.orientation.x);
    bytes.fixed(b.orientation.y);
    bytes.fixed(b.orientation.z);
    bytes.vec3(b.linear_velocity);
    bytes.vec3(b.angular_velocity);
  }
  for (const CharacterId id : world.character_ids()) {
    const CharacterState c = *world.character(id);
    bytes.u32(id.value);
    bytes.vec3(c.position);
    bytes.vec3(c.velocity);
  }
  return bytes.hash();
}

// Per run: the field hash at frames 1, 10, 100, 1000 and the last, and the chain (XXH3-64 of every
// frame's field hash, 8 little-endian bytes each), which covers every frame.
std::map<std::string, std::uint64_t> run_all() {
  std::map<std::string, std::uint64_t> out;
  FieldBytes bytes;
  for (const golden::GoldenRun& run : golden::runs) {
    auto created = Scenario::create(run.scenario, run.params);
    EXPECT_TRUE(created.ok()) << created.message();
    if (!created.ok()) continue;
    Scenario scenario = std::move(created).value();
    const std::string key = std::string(run.scenario) + "_";
    FieldBytes chain;
    std::vector<PlayerInput> inputs(run.params.players);
    for (std::uint64_t frame = 1; frame <= run.frames; ++frame) {
      for (std::uint32_t p = 0; p < run.params.players; ++p)
        inputs[p] = scripted_input(run.params.seed, frame, p);
      scenario.step(inputs);
      const std::uint64_t h = field_hash(scenario.world(), bytes);
      chain.u64(h);
      if (frame == 1 || frame == 10 || frame == 100 || frame == 1000)
        out[key + "frame_" + std::to_string(10000 + frame).substr(1)] = h;
    }
    out[key + "last"] = field_hash(scenario.world(), bytes);
    out[key + "chain"] = chain.hash();
  }
  // The mixed scene of golden/sim.txt: every shape pair, kinematic pushing, forces and impulses.
  FieldBytes chain;
  test::run_mixed_scene([&](const World& w, int frame) {
    const std::uint64_t h = field_hash(w, bytes);
    chain.u64(h);
    if (frame == 1 || frame == 10 || frame == 100 || frame == 600)
      out["mixed_frame_" + std::to_string(10000 + frame).substr(1)] = h;
  });
  out["mixed_chain"] = chain.hash();
  return out;
}

TEST(SimFieldIdentity, EveryScenarioSimulatesTheRecordedValues) {
  test::check_golden(
      kGoldenPath,
      "# Every body's position, orientation and velocities at every frame of each golden scenario\n"
      "# run (tests/sim_field_identity_test.cpp has the layout), independent of the state "
      "encoding.\n# Regenerate only when the physics changes on purpose: DETSIM_UPDATE_GOLDEN=1 "
      "<build>/tests/sim_field_identity_test\n",
      run_all());
}

// The record is sensitive to every field it covers: a one-ulp change of one body's angular
// velocity at one frame changes that frame's hash.
TEST(SimFieldIdentity, AOneUlpChangeOfOneFieldChangesTheHash) {
  auto scenario = Scenario::create("pile_boxes", {.seed = 1, .players = 0, .count = 8}).value();
  for (int i = 0; i < 30; ++i)
    scenario.step();
  FieldBytes bytes;
  const std::uint64_t before = field_hash(scenario.world(), bytes);
  const BodyId last = scenario.world().body_ids().back();
  const Vec3 w = scenario.world().body(last)->angular_velocity;
  ASSERT_TRUE(
      scenario.world().set_angular_velocity(last, {w.x, w.y, w.z + Fixed::from_raw(1)}).ok());
  EXPECT_NE(field_hash(scenario.world(), bytes), before);
}

}  // namespace
}  // namespace detsim
