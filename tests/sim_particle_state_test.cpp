// Particle groups in the canonical state (docs/STATE.md, section "particles"): the bytes are what
// the layout says (checked with the independent codec, support/state_codec_particles.hpp), a
// restored world steps like the uninterrupted one, the section has its own hash, every bad field
// is refused naming its byte with the world unchanged, and the tools built on the state (diff,
// --inject, bisect) name a particle's field.
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <detsim/replay/bisect.hpp>
#include <detsim/replay/desync_report.hpp>
#include <detsim/sim/inject.hpp>
#include <detsim/sim/state_diff.hpp>

#include "support/replay_files.hpp"
#include "support/state_helpers.hpp"

namespace detsim::state_test {
namespace {

constexpr ParticleGroupId kRopeId{1};
constexpr ParticleGroupId kClothId{2};
// The rope's particles (segments + 1) and the cloth's (columns x rows).
constexpr std::uint32_t kRopeSegments = 12;
constexpr std::uint32_t kClothSide = 8;

/// A ground plane; a static post (body 2) with a rope hanging from it to a dynamic ball (body 3),
/// held out to the side so that it swings; a static box (body 4) with a cloth pinned at two
/// corners of one edge above it, which falls and drapes over the box.
World particle_scene() {
  World w = make_world(WorldDef{});
  BodyDef ground;
  ground.type = BodyType::static_body;
  ground.shape = Shape::plane();
  add(w, ground);
  BodyDef post;
  post.type = BodyType::static_body;
  post.shape = Shape::box({0.1_fx, 0.1_fx, 0.1_fx});
  post.position = {0_fx, 6_fx, 0_fx};
  const BodyId post_id = add(w, post);
  BodyDef ball;
  ball.shape = Shape::sphere(0.25_fx);
  ball.mass = 2_fx;
  ball.position = {2_fx, 5.5_fx, 0_fx};
  const BodyId ball_id = add(w, ball);
  BodyDef box;
  box.type = BodyType::static_body;
  box.shape = Shape::box({0.5_fx, 0.5_fx, 0.5_fx});
  box.position = {5_fx, 1_fx, 0_fx};
  add(w, box);

  RopeDef rope;
  rope.start = {0_fx, 5.9_fx, 0_fx};
  rope.end = ball.position;
  rope.segments = kRopeSegments;
  rope.length = 2.25_fx;
  rope.mass = 0.5_fx;
  rope.attach_start = post_id;
  rope.attach_end = ball_id;
  rope.settings.mask = 0;  // hangs free of the post and the ball it is attached to
  const Expected<ParticleGroupId> r = w.create_rope(rope);
  EXPECT_TRUE(r.ok()) << r.message();

  ClothDef cloth;
  cloth.origin = {4.2_fx, 2_fx, -0.8_fx};
  cloth.axis_u = {1.6_fx, 0_fx, 0_fx};
  cloth.axis_v = {0_fx, 0_fx, 1.6_fx};
  cloth.columns = kClothSide;
  cloth.rows = kClothSide;
  cloth.mass = 0.5_fx;
  cloth.pinned = {0, kClothSide - 1};
  cloth.settings.friction = 0.25_fx;
  const Expected<ParticleGroupId> c = w.create_cloth(cloth);
  EXPECT_TRUE(c.ok()) << c.message();
  EXPECT_EQ(r.ok() ? r.value() : ParticleGroupId{}, kRopeId);
  EXPECT_EQ(c.ok() ? c.value() : ParticleGroupId{}, kClothId);
  // A soft cube falling beside them (a box: a fresh world restores it without registering
  // geometry first).
  SoftBodyDef soft;
  soft.shape = Shape::box({0.2_fx, 0.2_fx, 0.2_fx});
  soft.position = {-3_fx, 1.5_fx, 0_fx};
  soft.resolution = 4;
  soft.edge_compliance = 0.001_fx;
  EXPECT_TRUE(w.create_soft_body(soft).ok());
  return w;
}

/// The scene stepped 60 frames, with a wind on the cloth for the next step (saved, not yet used).
World stepped_scene() {
  World w = particle_scene();
  run(w, 60);
  EXPECT_TRUE(w.apply_particle_force(kClothId, {0.5_fx, 0_fx, 0.25_fx}).ok());
  return w;
}

std::vector<StateHashes> run_hashes(World& w, int frames) {
  std::vector<StateHashes> out;
  for (int f = 0; f < frames; ++f) {
    w.step();
    out.push_back(w.hashes());
  }
  return out;
}

std::vector<Vec3> positions(const World& w, ParticleGroupId id) {
  const Expected<std::vector<Vec3>> p = w.particle_positions(id);
  EXPECT_TRUE(p.ok()) << p.message();
  return p.ok() ? p.value() : std::vector<Vec3>{};
}

Injection injection(const std::string& spec) {
  const Expected<Injection> i = parse_injection(spec);
  EXPECT_TRUE(i.ok()) << spec << ": " << i.message();
  return i.ok() ? i.value() : Injection{};
}

// ---- The bytes ----

TEST(ParticleState, TheBytesAreWhatTheLayoutSays) {
  const World w = stepped_scene();
  const Bytes bytes = w.save();
  const Decoded d = decode(bytes);
  ASSERT_TRUE(d.ok) << d.error;
  EXPECT_EQ(encode(d), bytes);
  EXPECT_EQ(d.particles.next_group_id, 4U);
  ASSERT_EQ(d.particles.groups.size(), 3U);
  const DecodedParticleGroup& rope = d.particles.groups[0];
  const DecodedParticleGroup& cloth = d.particles.groups[1];
  const DecodedParticleGroup& soft = d.particles.groups[2];
  EXPECT_EQ(soft.type, kSoftBody);
  EXPECT_EQ(soft.soft_body.shape_type, static_cast<std::uint8_t>(ShapeType::box));
  EXPECT_EQ(soft.soft_body.half_extents, (Vec3{0.2_fx, 0.2_fx, 0.2_fx}));
  EXPECT_EQ(soft.soft_body.resolution, 4U);
  EXPECT_EQ(soft.positions.size(), 64U);  // a 4 x 4 x 4 lattice
  EXPECT_EQ(soft.particle_count_at + 1, soft.particles_at);
  EXPECT_EQ(rope.id, kRopeId.value);
  EXPECT_EQ(rope.type, kRope);
  EXPECT_EQ(rope.rope.segments, kRopeSegments);
  EXPECT_EQ(rope.rope.attach_start, 2U);
  EXPECT_EQ(rope.rope.attach_end, 3U);
  EXPECT_EQ(rope.rope.length, 2.25_fx);
  EXPECT_EQ(rope.settings.mask, 0U);
  // Both ends attached: the first and the last particle, to the post and the ball.
  ASSERT_EQ(rope.attachments.size(), 2U);
  EXPECT_EQ(rope.attachments[0].particle, 0U);
  EXPECT_EQ(rope.attachments[0].body, 2U);
  EXPECT_EQ(rope.attachments[1].particle, kRopeSegments);
  EXPECT_EQ(rope.attachments[1].body, 3U);
  EXPECT_EQ(cloth.id, kClothId.value);
  EXPECT_EQ(cloth.type, kCloth);
  EXPECT_EQ(cloth.cloth.columns, kClothSide);
  EXPECT_EQ(cloth.cloth.pinned, (std::vector<std::uint32_t>{0, kClothSide - 1}));
  EXPECT_EQ(cloth.cloth.attach_body, 0U);
  EXPECT_EQ(cloth.settings.friction, 0.25_fx);
  EXPECT_TRUE(cloth.attachments.empty());
  EXPECT_EQ(cloth.force, (Vec3{0.5_fx, 0_fx, 0.25_fx}));
  EXPECT_EQ(cloth.flags, kGroupAwake);
  EXPECT_TRUE(cloth.broken.empty());
  // The particles, at full width, are the ones the world reports.
  for (const DecodedParticleGroup* g : {&rope, &cloth, &soft}) {
    const ParticleGroupId id{g->id};
    EXPECT_EQ(g->positions, positions(w, id));
    EXPECT_EQ(g->velocities, w.particle_velocities(id).value());
    for (std::size_t i = 0; i < g->positions.size(); ++i)
      EXPECT_EQ(g->position_at(i), g->particles_at + 48 * i);
    EXPECT_EQ(g->broken_at, g->particles_at + 48 * g->positions.size());
  }
  EXPECT_EQ(rope.positions.size(), kRopeSegments + 1);
  EXPECT_EQ(cloth.positions.size(), kClothSide * kClothSide);
  // The ball hangs from the post by the rope: its tether carries the ball's weight.
  EXPECT_GT(rope.tether_impulse, Fixed::zero());
}

// ---- Restore equals the uninterrupted run ----

TEST(ParticleState, RestoredStepsLikeTheUninterruptedRun) {
  World w = stepped_scene();
  const Bytes saved = w.save();
  const std::vector<Vec3> cloth_at_save = positions(w, kClothId);
  const Vec3 ball_at_save = w.body(BodyId{3}).value().position;
  const std::vector<StateHashes> expected = run_hashes(w, 60);
  // The scene moved on after the save (the comparison is not of two resting worlds).
  EXPECT_NE(positions(w, kClothId), cloth_at_save);
  EXPECT_NE(w.body(BodyId{3}).value().position, ball_at_save);
  const Bytes end = w.save();

  // Into a fresh world.
  World fresh;
  const Status st = fresh.restore(saved);
  ASSERT_TRUE(st.ok()) << st.message();
  EXPECT_TRUE(fresh.save() == saved);
  const std::vector<StateHashes> got = run_hashes(fresh, 60);
  for (std::size_t f = 0; f < expected.size(); ++f)
    ASSERT_EQ(got[f], expected[f]) << "fresh world: differs " << f + 1 << " frames after restore";
  EXPECT_TRUE(fresh.save() == end);

  // Into the same world, back from 60 frames later.
  ASSERT_TRUE(w.restore(saved).ok());
  EXPECT_TRUE(w.save() == saved);
  const std::vector<StateHashes> again = run_hashes(w, 60);
  for (std::size_t f = 0; f < expected.size(); ++f)
    ASSERT_EQ(again[f], expected[f]) << "same world: differs " << f + 1 << " frames after restore";
}

// ---- Hashes ----

// A group's own hash changes when (and only when) that group changes.
TEST(ParticleState, EachGroupHasItsOwnHash) {
  World w = stepped_scene();
  const std::uint64_t rope = w.particle_group_hash(kRopeId).value();
  const std::uint64_t cloth = w.particle_group_hash(kClothId).value();
  EXPECT_NE(rope, cloth);
  EXPECT_FALSE(w.particle_group_hash(ParticleGroupId{99}).ok());
  ASSERT_TRUE(w.apply_particle_force(kRopeId, {1_fx, 0_fx, 0_fx}).ok());
  EXPECT_NE(w.particle_group_hash(kRopeId).value(), rope);
  EXPECT_EQ(w.particle_group_hash(kClothId).value(), cloth);
}

TEST(ParticleState, TheParticlesSectionHasItsOwnHash) {
  const World w = stepped_scene();
  const Bytes bytes = w.save();
  const StateHashes before = w.hashes();
  ASSERT_NE(before.section("particles"), 0U);
  // One coordinate of one cloth particle, one 2^-10 m higher.
  Decoded d = decode(bytes);
  ASSERT_TRUE(d.ok) << d.error;
  d.particles.groups[1].positions[kClothSide + 3].y += Fixed::from_raw(Fixed::one_raw >> 10);
  World changed;
  const Status st = changed.restore(encode(d));
  ASSERT_TRUE(st.ok()) << st.message();
  const StateHashes after = changed.hashes();
  EXPECT_NE(after.total, before.total);
  EXPECT_NE(after.section("particles"), before.section("particles"));
  for (const char* other : {"globals", "rng", "geometry", "bodies", "contacts", "joints"})
    EXPECT_EQ(after.section(other), before.section(other)) << other;
  EXPECT_EQ(differing_subsystems(before, after), std::vector<std::string>{"particles"});
}

// ---- Refusals ----

struct BadGroup {
  const char* what;  // a part the message must contain
  void (*change)(Decoded& d);
  std::size_t (*byte)(const Decoded& d);  // the byte the message must name
};

TEST(ParticleState, RefusesEachBadFieldNamingItAndChangesNothing) {
  World w = stepped_scene();
  const Bytes good = w.save();
  const Decoded d = decode(good);
  ASSERT_TRUE(d.ok) << d.error;
  const BadGroup cases[] = {
      {"particle group type", [](Decoded& x) { x.particles.groups[0].type = 4; },
       [](const Decoded& x) { return x.particles.groups[0].type_at; }},
      {"particle group ID step 0", [](Decoded& x) { x.particles.groups[1].id_step = 0; },
       [](const Decoded& x) { return x.particles.groups[1].at; }},
      {"stay below the next particle group ID 2", [](Decoded& x) { x.particles.next_group_id = 2; },
       [](const Decoded& x) { return x.particles.groups[1].at; }},
      {"next particle group ID must be >= 1", [](Decoded& x) { x.particles.next_group_id = 0; },
       [](const Decoded& x) { return x.particles.next_group_id_at; }},
      {"attachment 1: particle 99 of 13",
       [](Decoded& x) { x.particles.groups[0].attachments[1].particle = 99; },
       [](const Decoded& x) { return x.particles.groups[0].at; }},
      {"attachment 0: body 77 does not exist",
       [](Decoded& x) { x.particles.groups[0].attachments[0].body = 77; },
       [](const Decoded& x) { return x.particles.groups[0].at; }},
      {"broken constraint 100000 of",
       [](Decoded& x) {
         x.particles.groups[1].broken = {3, 100000};
       },
       [](const Decoded& x) { return x.particles.groups[1].broken_at; }},
      {"broken constraints must ascend",
       [](Decoded& x) {
         x.particles.groups[1].broken = {5, 5};
       },
       [](const Decoded& x) { return x.particles.groups[1].broken_at + 2; }},
      {"pinned indices must ascend",
       [](Decoded& x) {
         x.particles.groups[1].cloth.pinned = {kClothSide - 1, 0};
       },
       // The count, the first index, then the step that goes back.
       [](const Decoded& x) { return x.particles.groups[1].pinned_at + 2; }},
      {"particle 3: velocity x must be within",
       [](Decoded& x) {
         x.particles.groups[1].velocities[3].x = Fixed::from_int(1 << 30) + Fixed::from_raw(1);
       },
       [](const Decoded& x) { return x.particles.groups[1].at; }},
      {"particle 5: position y must be within",
       [](Decoded& x) { x.particles.groups[0].positions[5].y = Fixed::min(); },
       [](const Decoded& x) { return x.particles.groups[0].at; }},
      {"particle group flags", [](Decoded& x) { x.particles.groups[1].flags = 2; },
       [](const Decoded& x) { return x.particles.groups[1].flags_at; }},
      {"sleep time must be >= 0", [](Decoded& x) { x.particles.groups[0].sleep_time = -1_fx; },
       [](const Decoded& x) { return x.particles.groups[0].at; }},
      {"attachment count 14 is above its particle count 13",
       [](Decoded& x) {
         auto& a = x.particles.groups[0].attachments;
         a.resize(14, a[0]);
       },
       [](const Decoded& x) { return x.particles.groups[0].attachments_at; }},
  };
  for (const BadGroup& c : cases) {
    Decoded bad = d;
    c.change(bad);
    const Bytes bytes = encode(bad);
    ASSERT_FALSE(bytes == good) << c.what;
    const std::string message = expect_rejected(w, bytes);
    EXPECT_TRUE(contains(message, c.what)) << "expected '" << c.what << "' in: " << message;
    EXPECT_TRUE(contains(message, "section \"particles\"")) << message;
    EXPECT_TRUE(names_one_of(message, {c.byte(d)}))
        << c.what << ": expected byte " << c.byte(d) << " in: " << message;
  }
}

// Every single-bit change of the section's payload (one bit of each byte, cycling through the
// eight): refused with the world unchanged, or accepted and then saved back as exactly those bytes
// (the encoding is canonical).
TEST(ParticleState, EveryBitFlipIsRefusedOrCanonical) {
  World w = stepped_scene();
  const Bytes original = w.save();
  const StateHashes hashes = w.hashes();
  const Decoded d = decode(original);
  ASSERT_TRUE(d.ok) << d.error;
  std::size_t accepted = 0;
  std::size_t refused = 0;
  for (std::size_t at = d.payload_at[kParticles]; at < original.size(); ++at) {
    Bytes bytes = original;
    bytes[at] = static_cast<std::uint8_t>(bytes[at] ^ (1U << (at % 8)));
    (restore_outcome_is_sound(w, bytes, original, hashes,
                              "bit " + std::to_string(at % 8) + " of byte " + std::to_string(at))
         ? accepted
         : refused)++;
  }
  // Most bytes are particles' numbers, which any value within the limits leaves valid; the
  // structure's bytes are refused.
  EXPECT_GT(accepted, 0U);
  EXPECT_GT(refused, 0U);
  EXPECT_TRUE(w.save() == original);
}

// ---- A fluid ----

/// A ground plane, a static box, and a 4 x 6 x 4 block of water (group 1) falling beside it.
World fluid_scene() {
  World w = make_world(WorldDef{});
  BodyDef ground;
  ground.type = BodyType::static_body;
  ground.shape = Shape::plane();
  add(w, ground);
  BodyDef box;
  box.type = BodyType::static_body;
  box.shape = Shape::box({0.2_fx, 0.2_fx, 0.2_fx});
  box.position = {0.4_fx, 0.2_fx, 0.1_fx};
  add(w, box);
  FluidDef water;
  water.min = {0_fx, 0.3_fx, 0_fx};
  water.max = {0.2_fx, 0.6_fx, 0.2_fx};
  water.spacing = 0.05_fx;
  water.particle_radius = 0.025_fx;
  water.viscosity = 0.02_fx;
  water.settings.substeps = 2;
  EXPECT_TRUE(w.create_fluid(water).ok());
  return w;
}

// A fluid's record is its definition (docs/STATE.md) and its particles; a restored world steps on
// exactly like the uninterrupted one while the water splashes.
TEST(ParticleState, AFluidIsSavedAndRestoredExactly) {
  World w = fluid_scene();
  (void)run_hashes(w, 20);
  const Bytes saved = w.save();
  const Decoded d = decode(saved);
  ASSERT_TRUE(d.ok) << d.error;
  EXPECT_EQ(encode(d), saved);
  ASSERT_EQ(d.particles.groups.size(), 1U);
  const DecodedParticleGroup& g = d.particles.groups[0];
  const FluidDef def = w.fluid_def(ParticleGroupId{1}).value();
  EXPECT_EQ(g.type, kFluid);
  EXPECT_EQ(g.fluid.min, def.min);
  EXPECT_EQ(g.fluid.max, def.max);
  EXPECT_EQ(g.fluid.spacing, def.spacing);
  EXPECT_EQ(g.fluid.rest_density, def.rest_density);
  EXPECT_EQ(g.fluid.viscosity, def.viscosity);
  EXPECT_EQ(g.fluid.particle_radius, def.particle_radius);
  EXPECT_EQ(g.settings.substeps, 2U);
  EXPECT_EQ(g.positions.size(), 4U * 6U * 4U);
  EXPECT_EQ(g.positions, positions(w, ParticleGroupId{1}));
  const std::vector<StateHashes> expected = run_hashes(w, 40);
  World fresh;
  ASSERT_TRUE(fresh.restore(saved).ok());
  const std::vector<StateHashes> got = run_hashes(fresh, 40);
  for (std::size_t f = 0; f < expected.size(); ++f)
    ASSERT_EQ(got[f], expected[f]) << "differs " << f + 1 << " frames after restore";
  EXPECT_NE(expected.front().total, expected.back().total);
}

TEST(ParticleState, AFluidsBadFieldsAreRefusedNamingThem) {
  World w = fluid_scene();
  (void)run_hashes(w, 5);
  const Bytes good = w.save();
  const Decoded d = decode(good);
  ASSERT_TRUE(d.ok) << d.error;
  const BadGroup cases[] = {
      {"spacing must be within", [](Decoded& x) { x.particles.groups[0].fluid.spacing = 0_fx; },
       [](const Decoded& x) { return x.particles.groups[0].def_at; }},
      {"particle_radius must be within",
       [](Decoded& x) { x.particles.groups[0].fluid.particle_radius = 1_fx; },
       [](const Decoded& x) { return x.particles.groups[0].def_at; }},
      {"rest_density must be within",
       [](Decoded& x) { x.particles.groups[0].fluid.rest_density = -1_fx; },
       [](const Decoded& x) { return x.particles.groups[0].def_at; }},
      // One more column of particles than the record holds.
      {"particle count 96, but its definition makes 120",
       [](Decoded& x) { x.particles.groups[0].fluid.max.x = 0.25_fx; },
       [](const Decoded& x) { return x.particles.groups[0].particle_count_at; }},
  };
  for (const BadGroup& c : cases) {
    Decoded bad = d;
    c.change(bad);
    const std::string message = expect_rejected(w, encode(bad));
    EXPECT_TRUE(contains(message, c.what)) << "expected '" << c.what << "' in: " << message;
    EXPECT_TRUE(names_one_of(message, {c.byte(d)}))
        << c.what << ": expected byte " << c.byte(d) << " in: " << message;
  }
}

TEST(ParticleState, AHugeGroupCountIsRefusedBeforeAnythingIsAllocated) {
  World w = stepped_scene();
  Bytes bytes = w.save();
  const Decoded d = decode(bytes);
  ASSERT_TRUE(d.ok) << d.error;
  const std::size_t at = d.particles.group_count_at;
  const Bytes huge = leb128(std::uint64_t{1} << 40);
  const std::ptrdiff_t delta = static_cast<std::ptrdiff_t>(huge.size()) -
                               static_cast<std::ptrdiff_t>(var_length_at(bytes, at));
  replace_var(bytes, at, huge);
  adjust_section_length(bytes, d, at, delta);
  g_largest_allocation = 0;
  const std::string message = expect_rejected(w, bytes);
  EXPECT_TRUE(contains(message, "particle group count")) << message;
  EXPECT_TRUE(contains(message, "exceeds what the data can hold")) << message;
  EXPECT_TRUE(names_one_of(message, {at})) << message;
  EXPECT_LT(g_largest_allocation.load(), std::size_t{1} << 20);
  // Within max_particle_groups, but more than the bytes can hold, too.
  Bytes many = w.save();
  const Bytes count = leb128(max_particle_groups);
  replace_var(many, at, count);
  adjust_section_length(many, d, at, static_cast<std::ptrdiff_t>(count.size()) - 1);
  EXPECT_TRUE(contains(expect_rejected(w, many), "particle group count 4096"));
}

// ---- The tools: diff, --inject, bisect ----

TEST(ParticleState, DiffNamesTheGroupTheParticleAndTheField) {
  World w = stepped_scene();
  const Bytes a = w.save();
  ASSERT_TRUE(
      apply_injection(w, injection("60:0:particle_group[2].particle[17].position.y:0.001")).ok());
  const Bytes b = w.save();
  const Expected<StateDiff> diff = diff_states(a, b);
  ASSERT_TRUE(diff.ok()) << diff.message();
  ASSERT_EQ(diff->fields.size(), 1U);
  const FieldDiff& f = diff->fields[0];
  EXPECT_EQ(f.subsystem, "particles");
  EXPECT_EQ(f.body, 0U);
  EXPECT_EQ(f.field, "particle_group[2].particle[17].position.y");
  EXPECT_NE(f.a, f.b);

  // The group's own fields, and a constraint broken on one side only.
  Decoded d = decode(b);
  ASSERT_TRUE(d.ok) << d.error;
  d.particles.groups[0].tether_impulse += 1_fx;
  d.particles.groups[1].sleep_time = 0.5_fx;
  d.particles.groups[1].force.z = 3_fx;
  d.particles.groups[1].broken = {4};
  const Expected<StateDiff> groups = diff_states(b, encode(d));
  ASSERT_TRUE(groups.ok()) << groups.message();
  std::vector<std::string> names;
  for (const FieldDiff& g : groups->fields) {
    EXPECT_EQ(g.subsystem, "particles");
    names.push_back(g.field);
  }
  EXPECT_EQ(names, (std::vector<std::string>{
                       "particle_group[1].tether_impulse", "particle_group[2].sleep_time",
                       "particle_group[2].force.z", "particle_group[2].broken_count",
                       "particle_group[2].constraint[4].broken"}));
  EXPECT_EQ(groups->fields.back().a, "false");
  EXPECT_EQ(groups->fields.back().b, "true");

  // A group on one side only.
  ASSERT_TRUE(w.destroy_particle_group(kRopeId).ok());
  const Expected<StateDiff> gone = diff_states(b, w.save());
  ASSERT_TRUE(gone.ok()) << gone.message();
  bool named = false;
  for (const FieldDiff& g : gone->fields)
    named = named || (g.subsystem == "particles" && g.field == "particle_group[1].present" &&
                      g.a == "present" && g.b == "absent");
  EXPECT_TRUE(named);
}

TEST(ParticleState, InjectChangesOneParticleFieldOrRefusesAndChangesNothing) {
  World w = stepped_scene();
  const Bytes before = w.save();
  // Refused by the parser: a body with a group field, unknown groups, particles, fields and
  // components.
  for (const char* spec : {
           "60:3:particle_group[1].particle[0].position.x:1",
           "60:0:particle_group[0].particle[0].position.x:1",
           "60:0:particle_group[1].particle[0].position:1",
           "60:0:particle_group[1].particle[0].position.w:1",
           "60:0:particle_group[1].particle[0].mass:1",
           "60:0:particle_group[1].particle[0].sleep_time:1",
           "60:0:particle_group[1].particle[x].position.x:1",
           "60:0:particle_group[1].position.x:1",
           "60:0:particle_group[1].force:1",
           "60:0:particle_group[1].sleep_time.x:1",
           "60:0:particle_group[1].awake:2",
           "60:0:particle_group[1].particle[0].velocity.y:fast",
       }) {
    EXPECT_FALSE(parse_injection(spec).ok()) << spec;
  }
  // Refused when applied, naming why: no such group or particle; a result restore() would refuse.
  const std::pair<const char*, const char*> refused[] = {
      {"60:0:particle_group[9].particle[0].position.x:1", "no particle group with ID 9"},
      {"60:0:particle_group[1].particle[13].position.x:1",
       "particle group 1 has 13 particles (0 .. 12), not particle 13"},
      {"60:0:particle_group[2].particle[0].velocity.x:2000000000", "velocity x must be within"},
      {"60:0:particle_group[2].sleep_time:-1000", "sleep time must be >= 0"},
      {"60:0:particle_group[1].tether_impulse:-1000000", "tether impulse must be >= 0"},
  };
  for (const auto& [spec, why] : refused) {
    const Status st = apply_injection(w, injection(spec));
    EXPECT_FALSE(st.ok()) << spec;
    EXPECT_TRUE(contains(st.message(), why)) << "expected '" << why << "' in: " << st.message();
    EXPECT_TRUE(w.save() == before) << spec;
  }
  // Accepted: the number adds, the flag toggles.
  const Vec3 p = positions(w, kClothId)[10];
  ASSERT_TRUE(
      apply_injection(w, injection("60:0:particle_group[2].particle[10].position.z:0.25")).ok());
  EXPECT_EQ(positions(w, kClothId)[10], (Vec3{p.x, p.y, p.z + 0.25_fx}));
  ASSERT_TRUE(apply_injection(w, injection("60:0:particle_group[1].awake:1")).ok());
  EXPECT_FALSE(w.particle_group_stats(kRopeId).value().awake);
  // The help names the forms.
  EXPECT_NE(injection_fields_help().find("particle_group[G].particle[I].position.x|y|z"),
            std::string_view::npos);
}

// What diff prints, --inject takes: a change found by diff, injected under that name into the
// state it was found against, gives the other state, bit for bit.
TEST(ParticleState, InjectTakesTheNamesDiffPrints) {
  const World start = stepped_scene();
  const Bytes a = start.save();
  const char* specs[] = {
      "60:0:particle_group[1].particle[4].velocity.x:-0.125",
      "60:0:particle_group[2].particle[63].position.y:0.5",
      "60:0:particle_group[2].force.y:2",
      "60:0:particle_group[1].sleep_time:0.25",
      "60:0:particle_group[2].awake:1",
  };
  for (const char* spec : specs) {
    World changed = start;
    ASSERT_TRUE(apply_injection(changed, injection(spec)).ok()) << spec;
    const Bytes b = changed.save();
    const Expected<StateDiff> diff = diff_states(a, b);
    ASSERT_TRUE(diff.ok()) << diff.message();
    ASSERT_EQ(diff->fields.size(), 1U) << spec;
    const std::string field = diff->fields[0].field;
    EXPECT_TRUE(contains(spec, ":" + field + ":")) << spec << " diffs as " << field;
    // The same change under diff's name, applied to a restored copy of A.
    World again;
    ASSERT_TRUE(again.restore(a).ok());
    const std::string delta = std::string(spec).substr(std::string(spec).rfind(':') + 1);
    ASSERT_TRUE(apply_injection(again, injection("60:0:" + field + ":" + delta)).ok());
    EXPECT_TRUE(again.save() == b) << spec;
    // And the changed state restores and saves as itself.
    World restored;
    ASSERT_TRUE(restored.restore(b).ok()) << spec;
    EXPECT_TRUE(restored.save() == b) << spec;
  }
}

/// One side of a desync as a report: the states at frames F - 1 and F of a run of the particle
/// scene (no scenario of this build: bisect compares the stored states, not a re-simulation).
replay::DesyncReport report_of(const World& frame_zero, const Bytes& agreed, const Bytes& divergent,
                               std::uint64_t frame, std::uint64_t local, std::uint64_t remote) {
  replay::DesyncReport r;
  replay::Fingerprint& fp = r.fingerprint;
  fp.detsim_version = "test";
  fp.state_version = state_encoding_version;
  for (const SectionHash& s : frame_zero.hashes().sections)
    fp.state_sections.push_back(s.name);
  fp.scenario = "particle_state_test";
  fp.dt = frame_zero.def().dt;
  fp.substeps = frame_zero.def().substeps;
  fp.iterations = frame_zero.def().iterations;
  fp.players = 1;
  fp.input_size = 1;
  fp.initial_hash = frame_zero.hashes().total;
  r.origin = replay::ReportOrigin::verify;
  r.agreed_frame = frame - 1;
  r.divergent_frame = frame;
  r.local_hash = local;
  r.remote_hash = remote;
  r.confirmed_frames.assign(static_cast<std::size_t>(frame) * 2, 0);
  r.agreed_state = agreed;
  r.divergent_state = divergent;
  r.agreed_bodies = replay::body_hashes(agreed).value();
  r.divergent_bodies = replay::body_hashes(divergent).value();
  return r;
}

TEST(ParticleState, BisectNamesAnInjectedParticlesField) {
  const World frame_zero = particle_scene();
  World healthy = particle_scene();
  run(healthy, 59);
  const Bytes agreed = healthy.save();
  World faulty = healthy;
  healthy.step();
  faulty.step();
  ASSERT_TRUE(
      apply_injection(faulty, injection("60:0:particle_group[2].particle[20].position.x:0.01"))
          .ok());
  const Bytes good = healthy.save();
  const Bytes bad = faulty.save();
  const std::uint64_t good_hash = healthy.hashes().total;
  const std::uint64_t bad_hash = faulty.hashes().total;
  ASSERT_NE(good_hash, bad_hash);

  test::TempFile healthy_report("healthy.dsd");
  test::TempFile faulty_report("faulty.dsd");
  ASSERT_TRUE(replay::write_desync_report(healthy_report.path(), report_of(frame_zero, agreed, good,
                                                                           60, good_hash, bad_hash))
                  .ok());
  ASSERT_TRUE(replay::write_desync_report(
                  faulty_report.path(), report_of(frame_zero, agreed, bad, 60, bad_hash, good_hash))
                  .ok());
  const Expected<replay::BisectResult> r =
      replay::bisect(healthy_report.path(), faulty_report.path());
  ASSERT_TRUE(r.ok()) << r.message();
  EXPECT_EQ(r->outcome, replay::BisectOutcome::diverged);
  EXPECT_EQ(r->first_divergent_frame, 60U);
  EXPECT_EQ(r->last_agreed_frame, 59U);
  EXPECT_TRUE(r->exact);
  EXPECT_EQ(r->subsystems, std::vector<std::string>{"particles"});
  ASSERT_EQ(r->diff_frame, 60U);
  ASSERT_EQ(r->diffs.size(), 1U);
  EXPECT_EQ(r->diffs[0].subsystem, "particles");
  EXPECT_EQ(r->diffs[0].body, 0U);
  EXPECT_EQ(r->diffs[0].field, "particle_group[2].particle[20].position.x");
  EXPECT_EQ(r->diffs_omitted, 0U);
  // The report's scene draws every particle (under 1000 a group) as a ball of its radius, after
  // the bodies, titled "particle" on the page.
  std::size_t drawn = 0;
  for (const replay::ScenePose& p : r->scene_a)
    drawn += p.id == 0 && p.shape.type == ShapeType::sphere ? 1U : 0U;
  std::size_t particles = 0;
  const World scene = particle_scene();
  for (const ParticleGroupId id : scene.particle_group_ids())
    particles += scene.particle_group_stats(id).value().particle_count;
  EXPECT_EQ(drawn, particles);
  EXPECT_NE(replay::bisect_html(*r).find("<title>particle ("), std::string::npos);
}

}  // namespace
}  // namespace detsim::state_test
