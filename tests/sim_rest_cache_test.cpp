// What a step keeps between steps for bodies at rest — their derived data
// (WorldState::prepared_from), the broadphase's entries and pairs, the solver's lists of awake
// bodies — changes no bit: a world stepped through a sleeping pile and every call that disturbs
// one body saves, after each step, the same bytes as a world restored from its state just before
// that step, whose caches start empty and are filled by a full pass.
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

namespace detsim {
namespace {

using namespace detsim::literals;
using Bytes = std::vector<std::uint8_t>;

Scenario pile() {
  auto s = Scenario::create("pile_boxes", {.seed = 1, .players = 0, .count = 64});
  EXPECT_TRUE(s.ok()) << s.message();
  return std::move(s.value());
}

bool all_asleep(const World& w) {
  for (const BodyId id : w.body_ids())
    if (w.body(id)->awake) return false;
  return true;
}

TEST(RestCache, AStepWithKeptWorkEqualsAStepFromARestoredState) {
  Scenario a = pile();
  World& w = a.world();
  int settle = 0;
  while (!all_asleep(w) && settle < 3000) {
    w.step();
    ++settle;
  }
  ASSERT_TRUE(all_asleep(w));
  std::vector<BodyId> ids;
  for (const BodyId id : w.body_ids())
    if (w.body(id)->type == BodyType::dynamic) ids.push_back(id);
  ASSERT_GE(ids.size(), 64U);
  Scenario fresh = pile();
  for (int f = 0; f < 160; ++f) {
    SCOPED_TRACE("step " + std::to_string(f));
    const BodyId some = ids[static_cast<std::size_t>(f) % ids.size()];
    switch (f) {
      case 10: {  // a sleeping body teleported a little: it stays asleep, its box moves
        const BodyState b = *w.body(ids[5]);
        ASSERT_TRUE(
            w.set_transform(ids[5], b.position + Vec3{0.01_fx, 0.3_fx, 0_fx}, b.orientation).ok());
        break;
      }
      case 30:
        ASSERT_TRUE(w.set_type(ids[7], BodyType::static_body).ok());
        break;
      case 45:
        ASSERT_TRUE(w.apply_linear_impulse(some, {0.5_fx, 2_fx, 0_fx}).ok());
        break;
      case 60:
        ASSERT_TRUE(w.destroy_body(ids[20]).ok());
        break;
      case 75: {
        BodyDef def;
        def.type = BodyType::dynamic;
        def.shape = Shape::box({0.25_fx, 0.25_fx, 0.25_fx});
        def.position = w.body(ids[30])->position + Vec3{0_fx, 3_fx, 0_fx};
        ASSERT_TRUE(w.create_body(def).ok());
        break;
      }
      case 100:
        ASSERT_TRUE(w.set_type(ids[7], BodyType::dynamic).ok());
        break;
      case 120:
        ASSERT_TRUE(w.wake(ids[40]).ok());
        break;
      default:
        break;
    }
    const Bytes before = w.save();
    World& cold = fresh.world();
    ASSERT_TRUE(cold.restore(before).ok());
    w.step();
    cold.step();
    ASSERT_EQ(w.save(), cold.save());
  }
}

}  // namespace
}  // namespace detsim
