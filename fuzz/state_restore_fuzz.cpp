// libFuzzer target for World::restore, the reader of the canonical state encoding (docs/STATE.md):
// every keyframe, desync report and spectator snapshot from another machine passes through it.
//
// Properties checked beyond the sanitizers' (no crash, no undefined behaviour, no leak) and
// libFuzzer's (no unbounded allocation, no hang):
// - a refused restore leaves the world exactly as it was (its bytes are unchanged);
// - an accepted restore is canonical: the restored world saves exactly the input bytes;
// - an accepted state can be stepped (a few frames, small states only, to keep runs fast).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <vector>

#include <detsim/sim/world.hpp>

#include "geometry_world.hpp"

namespace {

// A world holding the seeds' geometry (geometry_world.hpp), so that states naming it restore;
// states naming other geometry (the scenarios') exercise the refusal.
detsim::World& target() {
  static detsim::World world = [] {
    detsim::World w = fuzz_support::geometry_world(false);
    if (w.geometry_count() == 0) std::abort();
    (void)w.create_body({.type = detsim::BodyType::static_body, .shape = detsim::Shape::plane()});
    return w;
  }();
  return world;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  detsim::World& world = target();
  static const std::vector<std::uint8_t> original = world.save();
  const std::span<const std::uint8_t> bytes(data, size);
  if (!world.restore(bytes)) {
    if (world.save() != original) std::abort();  // a refused restore changed the world
    return 0;
  }
  const std::vector<std::uint8_t> again = world.save();
  if (again.size() != size || !std::equal(again.begin(), again.end(), data))
    std::abort();  // accepted bytes that are not the canonical encoding of what was read
  if (world.body_count() <= 64) {
    for (int i = 0; i < 3; ++i)
      world.step();
  }
  if (!world.restore(original)) std::abort();
  return 0;
}
