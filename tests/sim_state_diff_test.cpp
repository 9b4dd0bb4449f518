// Field-level state comparison (sim/state_diff.hpp): equal states, one nudged field, a body on one
// side only, the RNG, the frame, states that do not restore, states of a scene with registered
// geometry (diffed against the world that holds it) and states whose geometry differs.
#include <gtest/gtest.h>

#include <string>

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

Scenario scene_at(const char* name, std::uint64_t frames, std::uint64_t seed = 1) {
  ScenarioParams params;
  params.seed = seed;
  params.count = 40;
  Scenario s = Scenario::create(name, params).value();
  for (std::uint64_t f = 0; f < frames; ++f)
    s.step();
  return s;
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// A state names its geometry by hash: restoring it needs a world holding that geometry. Against
// the scenario's world the diff names the field; against an empty one the error says what to do.
TEST(StateDiff, StatesOfAGeometrySceneAreDiffedAgainstTheWorldThatHoldsTheirGeometry) {
  Scenario s = scene_at("rocks", 30);
  const std::vector<std::uint8_t> a = s.world().save();
  const BodyId rock = s.world().body_ids().back();
  ASSERT_EQ(s.world().body(rock).value().shape.type, ShapeType::convex);
  BodyState body = s.world().body(rock).value();
  ASSERT_TRUE(
      s.world()
          .set_transform(rock, body.position + Vec3{{}, Fixed::from_raw(1), {}}, body.orientation)
          .ok());
  const std::vector<std::uint8_t> b = s.world().save();

  const World geometry = Scenario::create("rocks", {.seed = 1, .count = 40}).value().world();
  const StateDiff d = diff_states(geometry, a, b).value();
  ASSERT_FALSE(d.fields.empty());
  EXPECT_EQ(d.fields[0].subsystem, "bodies");
  EXPECT_EQ(d.fields[0].body, rock.value);
  EXPECT_EQ(d.fields[0].field, "position.y");
  EXPECT_TRUE(d.note.empty()) << d.note;
  EXPECT_EQ(d.frame_a, 30U);
  // The world given keeps its own state: only copies of it are restored into.
  EXPECT_EQ(geometry.frame(), 0U);
  EXPECT_TRUE(diff_states(geometry, a, a).value().equal());

  auto without = diff_states(a, b);
  ASSERT_FALSE(without.ok());
  EXPECT_EQ(without.message().rfind("state A: ", 0), 0U) << without.message();
  EXPECT_TRUE(contains(without.message(), "heightfield")) << without.message();
  EXPECT_TRUE(contains(without.message(), "a world that holds their geometry"))
      << without.message();
}

// Other geometry on the two sides: each differing entry is named with its type and content hash;
// the side that the world cannot restore is not compared further, and the note says so.
TEST(StateDiff, DifferentGeometryIsNamedByEntryTypeAndContentHash) {
  const World rocks = scene_at("rocks", 0).world();
  const std::vector<std::uint8_t> a = scene_at("rocks", 5).world().save();
  const std::vector<std::uint8_t> b = scene_at("rocks", 5, 2).world().save();  // other rocks
  const StateDiff d = diff_states(rocks, a, b, 5).value();
  ASSERT_FALSE(d.equal());
  ASSERT_FALSE(d.fields.empty());
  const FieldDiff& f = d.fields[0];
  EXPECT_EQ(f.subsystem, "geometry");
  EXPECT_EQ(f.body, 0U);
  EXPECT_EQ(f.field, "geometry[2]");  // 1 is the heightfield, the same for every seed
  char hash[19];
  std::snprintf(hash, sizeof hash, "0x%016llx",
                static_cast<unsigned long long>(rocks.geometry_hash(GeometryId{2}).value()));
  EXPECT_EQ(f.a, std::string("convex hull, content hash ") + hash);
  EXPECT_TRUE(f.b.starts_with("convex hull, content hash 0x")) << f.b;
  EXPECT_NE(f.a, f.b);
  EXPECT_TRUE(contains(d.note, "state B")) << d.note;
  EXPECT_EQ(d.frame_b, 5U);

  // Geometry registered after A was saved: both restore (a state's geometry is a prefix of the
  // world's), and the entry A lacks is listed as absent there, before the bodies.
  World w = scene_at("rocks", 0).world();
  const std::vector<std::uint8_t> before = w.save();
  const Vec3 corners[] = {{}, Vec3::unit_x(), Vec3::unit_y(), Vec3::unit_z()};
  const GeometryId added = w.create_convex_hull(corners).value();
  const StateDiff grown = diff_states(w, before, w.save()).value();
  ASSERT_EQ(grown.fields.size(), 1U);
  EXPECT_EQ(grown.fields[0].field, "geometry[" + std::to_string(added.value) + "]");
  EXPECT_EQ(grown.fields[0].a, "absent");
  EXPECT_TRUE(grown.fields[0].b.starts_with("convex hull, content hash")) << grown.fields[0].b;
  EXPECT_TRUE(grown.note.empty()) << grown.note;
}

}  // namespace
}  // namespace detsim
