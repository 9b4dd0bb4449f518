// Field-level state comparison (sim/state_diff.hpp): equal states, one nudged field, a body on one
// side only, the RNG, the frame, and states that do not restore.
#include <gtest/gtest.h>

#include <detsim/sim/state_diff.hpp>

namespace detsim {
namespace {

Scenario arena_at(std::uint64_t frames) {
  ScenarioParams params;
  params.players = 2;
  Scenario s = Scenario::create("arena", params).value();
  for (std::uint64_t f = 0; f < frames; ++f)
    s.step();
  return s;
}

TEST(StateDiff, EqualStatesHaveNoDifferences) {
  Scenario s = arena_at(40);
  const std::vector<std::uint8_t> bytes = s.world().save();
  const StateDiff d = diff_states(bytes, bytes).value();
  EXPECT_TRUE(d.equal());
  EXPECT_TRUE(d.fields.empty());
  EXPECT_EQ(d.frame_a, 40U);
}

TEST(StateDiff, OneRawUnitOfOneFieldIsNamedWithBothValues) {
  Scenario s = arena_at(40);
  const std::vector<std::uint8_t> a = s.world().save();
  const BodyId id = s.player_body(1);
  BodyState body = s.world().body(id).value();
  const Fixed before = body.linear_velocity.y;
  ASSERT_TRUE(s.world()
                  .set_linear_velocity(id, {body.linear_velocity.x, before + Fixed::from_raw(1),
                                            body.linear_velocity.z})
                  .ok());
  const StateDiff d = diff_states(a, s.world().save()).value();
  ASSERT_FALSE(d.equal());
  // The field that changed comes first (declaration order); setting a velocity also wakes the
  // body, so its sleep state may be listed after it, and nothing else.
  ASSERT_FALSE(d.fields.empty());
  const FieldDiff& f = d.fields[0];
  EXPECT_EQ(f.subsystem, "bodies");
  EXPECT_EQ(f.body, id.value);
  EXPECT_EQ(f.field, "linear_velocity.y");
  char raw[19];
  std::snprintf(raw, sizeof raw, "0x%016llx", static_cast<unsigned long long>(before.raw()));
  EXPECT_EQ(f.a, to_string(before) + " (" + raw + ")");
  EXPECT_NE(f.a, f.b);
  for (std::size_t i = 1; i < d.fields.size(); ++i) {
    EXPECT_EQ(d.fields[i].body, id.value);
    EXPECT_TRUE(d.fields[i].field == "awake" || d.fields[i].field == "sleep_time")
        << d.fields[i].field;
  }
}

TEST(StateDiff, ABodyOnOneSideOnlyAndTheFrameAndRngAreNamed) {
  Scenario s = arena_at(20);
  const std::vector<std::uint8_t> a = s.world().save();
  const BodyId gone = s.world().body_ids().back();
  ASSERT_TRUE(s.world().destroy_body(gone).ok());
  (void)s.world().rng().next_u64();
  const StateDiff d = diff_states(a, s.world().save()).value();
  bool present = false;
  bool rng = false;
  for (const FieldDiff& f : d.fields) {
    if (f.field == "present" && f.body == gone.value) {
      present = true;
      EXPECT_EQ(f.a, "present");
      EXPECT_EQ(f.b, "absent");
    }
    if (f.subsystem == "rng") rng = true;
  }
  EXPECT_TRUE(present);
  EXPECT_TRUE(rng);
  // A later frame: the frame is a global that differs.
  Scenario later = arena_at(21);
  const StateDiff frames = diff_states(arena_at(20).world().save(), later.world().save()).value();
  ASSERT_FALSE(frames.fields.empty());
  EXPECT_EQ(frames.fields[0].subsystem, "globals");
  EXPECT_EQ(frames.fields[0].field, "frame");
  EXPECT_EQ(frames.frame_b, 21U);
}

TEST(StateDiff, MaxFieldsBoundsTheListAndCountsTheRest) {
  const StateDiff d =
      diff_states(arena_at(10).world().save(), arena_at(60).world().save(), 3).value();
  EXPECT_EQ(d.fields.size(), 3U);
  EXPECT_GT(d.omitted, 0U);
}

TEST(StateDiff, AStateThatDoesNotRestoreIsAnErrorNamingTheSide) {
  const std::vector<std::uint8_t> good = arena_at(5).world().save();
  const std::vector<std::uint8_t> bad(good.begin(), good.begin() + 20);
  auto r = diff_states(good, bad);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.message().rfind("state B: ", 0), 0U) << r.message();
  r = diff_states(bad, good);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.message().rfind("state A: ", 0), 0U) << r.message();
}

}  // namespace
}  // namespace detsim
