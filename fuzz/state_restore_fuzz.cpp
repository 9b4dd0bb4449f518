// libFuzzer target for World::restore, the reader of the canonical state encoding (docs/STATE.md):
// every keyframe, desync report and spectator snapshot from another machine passes through it.
//
// Properties checked beyond the sanitizers' (no crash, no undefined behaviour, no leak) and
// libFuzzer's (no unbounded allocation, no hang):
// - a refused restore leaves the world exactly as it was (its bytes are unchanged);
// - an accepted restore is canonical: the restored world saves exactly the input bytes;
// - an accepted state can be stepped (a few frames, small states only, to keep runs fast);
// - delta coding (state_delta.hpp): an accepted state coded against the world's own state, and
//   that one against it, decodes back to itself, byte for byte; and the input read as a delta
//   (its magic made "DSDL") decodes to an error or to bytes within the documented bound.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <utility>
#include <vector>

#include <detsim/sim/state_delta.hpp>
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
  if (size >= 4) {
    std::vector<std::uint8_t> as_delta(bytes.begin(), bytes.end());
    const std::uint8_t magic[4] = {'D', 'S', 'D', 'L'};
    std::copy(magic, magic + 4, as_delta.begin());
    const auto decoded = detsim::decode_state_delta(as_delta, original);
    if (decoded && decoded->size() > 10 * size + original.size()) std::abort();  // beyond the bound
  }
  if (!world.restore(bytes)) {
    if (world.save() != original) std::abort();  // a refused restore changed the world
    return 0;
  }
  const std::vector<std::uint8_t> again = world.save();
  if (again.size() != size || !std::equal(again.begin(), again.end(), data))
    std::abort();  // accepted bytes that are not the canonical encoding of what was read
  for (const auto& [state, base] :
       {std::pair{bytes, std::span(original)}, std::pair{std::span(original), bytes}}) {
    const auto delta = detsim::encode_state_delta(state, base);
    if (!delta) std::abort();  // two valid states always code
    const auto back = detsim::decode_state_delta(*delta, base);
    if (!back || !std::equal(back->begin(), back->end(), state.begin(), state.end()))
      std::abort();  // a delta that does not give its state back
  }
  if (world.body_count() <= 64) {
    for (int i = 0; i < 3; ++i)
      world.step();
  }
  if (!world.restore(original)) std::abort();
  return 0;
}
