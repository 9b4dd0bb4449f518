// World state: save(), restore(), hashes() and body_hash() (docs/DETERMINISM.md rules 5, 6 and 7).
//
// - A restored world is the saved world: the same bytes, the same hashes, and the same hash on
//   every later frame as a run that never saved.
// - The bytes are canonical: the v2 layout is decoded here by an independent codec
//   (support/state_codec.hpp) and compared field by field with what the public API reports, and
//   the bytes the accessors imply are encoded and compared with save(); the hashes are recomputed
//   with xxHash itself.
// - Bad bytes are refused (sim_state_restore_test.cpp); what version 2 adds to the layout (vars,
//   property sets, flags, steps) is tested in sim_state_v2_codec_test.cpp.
//
// Worlds are built through the public API only.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "support/state_helpers.hpp"

namespace detsim {
namespace {

using namespace detsim::literals;
using namespace detsim::state_test;

// ======================================================================================
// The format
// ======================================================================================

TEST(StateFormat, DefaultWorldStartsWithMagicAndVersion) {
  const World w;
  const Bytes bytes = w.save();
  ASSERT_GE(bytes.size(), 8U);
  EXPECT_EQ(bytes[0], 'D');
  EXPECT_EQ(bytes[1], 'S');
  EXPECT_EQ(bytes[2], 'I');
  EXPECT_EQ(bytes[3], 'M');
  EXPECT_EQ((Bytes(bytes.begin() + 4, bytes.begin() + 8)), (Bytes{6, 0, 0, 0}));
  EXPECT_EQ(state_encoding_version, 6U);
  // Then the section count (var 7) and the first section's record: its name's length (7),
  // "globals", its version (var 1) and its payload's length: frame 8 + next ID 4 + definition 137
  // = 149 = 0x95 (u32); then frame 0 (u64) and the next body ID, 1 (u32).
  EXPECT_EQ((Bytes(bytes.begin() + 8, bytes.begin() + 22)),
            (Bytes{7, 7, 'g', 'l', 'o', 'b', 'a', 'l', 's', 1, 0x95, 0, 0, 0}));
  EXPECT_EQ((Bytes(bytes.begin() + 22, bytes.begin() + 34)),
            (Bytes{0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0}));
  // magic 4 + version 4 + count 1, each section's name length, name, version and payload length
  // (1 + 7 + 1 + 4, 1 + 3 + 1 + 4, 1 + 8 + 1 + 4, 1 + 6 + 1 + 4, 1 + 8 + 1 + 4, 1 + 6 + 1 + 4,
  // 1 + 9 + 1 + 4), and the payloads: globals 149, RNG 32, geometry an empty var count 1, bodies
  // two empty counts 8, contacts one empty count 4, joints the next joint ID 1 and an empty count,
  // 8, particles the next particle group ID 1 (u32) and an empty var count, 5.
  EXPECT_EQ(bytes.size(), 9U + 13 + 9 + 14 + 12 + 14 + 12 + 15 + (8 + 4 + kDefinitionBytes) + 32 +
                              1 + 8 + 4 + 8 + 5);
  EXPECT_EQ(bytes.size(), 305U);
  EXPECT_EQ((Bytes(bytes.end() - 28, bytes.end() - 5)),
            (Bytes{1,   0,   0,   0,   0,   0,   0, 0, 9, 'p', 'a', 'r',
                   't', 'i', 'c', 'l', 'e', 's', 1, 5, 0, 0,   0}));
  EXPECT_EQ((Bytes(bytes.end() - 5, bytes.end())), (Bytes{1, 0, 0, 0, 0}));

  const Decoded d = decode(bytes);
  ASSERT_TRUE(d.ok) << d.error;
  EXPECT_EQ(d.def, WorldDef{});
  EXPECT_EQ(d.rng, Rng(0).state());
  EXPECT_EQ(d.globals_at, 22U);
  EXPECT_EQ(d.rng_at, d.globals_at + 12 + kDefinitionBytes + 9);  // after rng's section header
  EXPECT_EQ(d.geometry_count_at, d.rng_at + 32 + 14);
  EXPECT_EQ(d.property_count_at, d.geometry_count_at + 1 + 12);
  EXPECT_EQ(d.contact_count_at, d.body_count_at + 4 + 14);
  EXPECT_EQ(d.next_joint_id_at, d.contact_count_at + 4 + 12);
  EXPECT_EQ(d.next_joint_id, 1U);
  EXPECT_EQ(d.particles.next_group_id_at, d.next_joint_id_at + 8 + 15);
  EXPECT_EQ(d.particles.next_group_id, 1U);
  EXPECT_EQ(d.particles.group_count_at, bytes.size() - 1);
  EXPECT_TRUE(d.sets.empty() && d.bodies.empty() && d.contacts.empty() && d.joints.empty() &&
              d.particles.groups.empty());
  EXPECT_EQ(encode(d), bytes);
}

TEST(StateFormat, DecodesToExactlyWhatTheWorldReports) {
  const World w = settled();
  const Bytes bytes = w.save();
  const Decoded d = decode(bytes);
  ASSERT_TRUE(d.ok) << d.error;
  EXPECT_EQ(d.frame, 300U);
  EXPECT_EQ(d.frame, w.frame());
  EXPECT_EQ(d.def, w.def());
  EXPECT_EQ(d.rng, w.rng().state());
  EXPECT_EQ(d.next_id, w.body_ids().back().value + 1);

  const std::vector<BodyId> ids = w.body_ids();
  ASSERT_EQ(d.bodies.size(), ids.size());
  for (std::size_t i = 0; i < ids.size(); ++i) {
    const Expected<BodyState> b = w.body(ids[i]);
    ASSERT_TRUE(b.ok());
    EXPECT_EQ(d.bodies[i].id, ids[i]);
    EXPECT_TRUE(body_state(d, i) == b.value()) << "body " << ids[i].value << " decodes differently";
  }
  // Bodies that differ only in their motion share a set: of the three stacked boxes only the top
  // one has CCD, so the playground's 11 bodies use 10 sets.
  ASSERT_EQ(d.bodies.size(), 11U);
  EXPECT_EQ(d.sets.size(), 10U);
  EXPECT_EQ(d.bodies[4].set, d.bodies[5].set);
  EXPECT_NE(d.bodies[5].set, d.bodies[6].set);

  // The contacts, as contacts() reports them (touching is "has points").
  const std::vector<ContactState> cache = w.contacts();
  ASSERT_EQ(d.contacts.size(), cache.size());
  for (std::size_t i = 0; i < cache.size(); ++i) {
    SCOPED_TRACE(testing::Message() << "contact " << cache[i].a.value << "-" << cache[i].b.value);
    const ContactState c = contact_state(d.contacts[i]);
    EXPECT_EQ(c.a, cache[i].a);
    EXPECT_EQ(c.b, cache[i].b);
    EXPECT_EQ(c.touching, cache[i].touching);
    EXPECT_EQ(c.reported, cache[i].reported);
    ASSERT_EQ(c.point_count, cache[i].point_count);
    for (std::size_t p = 0; p < c.point_count; ++p)
      EXPECT_EQ(c.points[p], cache[i].points[p]) << "point " << p;
  }
  // The scene must exercise what the state carries: contacts (touching, with points), sleeping
  // bodies, a kinematic body in motion, and user data.
  ASSERT_FALSE(d.contacts.empty());
  std::size_t touching = 0;
  std::size_t reported = 0;
  for (const DecodedContact& c : d.contacts) {
    touching += c.point_count() > 0 ? 1U : 0U;
    reported += c.reported() ? 1U : 0U;
  }
  EXPECT_GE(touching, 5U);
  EXPECT_GE(reported, 5U);
  std::size_t asleep = 0;
  std::size_t moving_kinematic = 0;
  for (std::size_t i = 0; i < d.bodies.size(); ++i) {
    const BodyState b = body_state(d, i);
    asleep += b.type == BodyType::dynamic && !b.awake ? 1U : 0U;
    moving_kinematic += b.type == BodyType::kinematic && b.linear_velocity != Vec3{} ? 1U : 0U;
  }
  EXPECT_GE(asleep, 3U) << "the scene should have sleeping bodies by frame 300";
  EXPECT_EQ(moving_kinematic, 1U);
  EXPECT_EQ(d.bodies[2].user_data, 0xDEADBEEFCAFEF00DU);
  EXPECT_EQ(d.bodies[2].flags & kHasUserData, kHasUserData);
}

TEST(StateFormat, SavesExactlyWhatTheAccessorsImply) {
  // The encoding built from body(), contacts(), rng(), def() and frame() by the test codec (sets
  // deduplicated in first-use order, flags from the values, steps from the IDs) is save()'s.
  std::vector<World> worlds;
  worlds.emplace_back();
  worlds.push_back(playground(1));
  worlds.push_back(played_once(2, 60));
  worlds.push_back(settled());
  World destroyed = settled();
  ASSERT_TRUE(destroyed.destroy_body(BodyId{2}).ok());  // the first user of the second set
  worlds.push_back(destroyed);
  World pushed = settled();
  ASSERT_TRUE(pushed.apply_force(BodyId{3}, {1_fx, -2_fx, 0_fx}).ok());
  ASSERT_TRUE(pushed.apply_torque(BodyId{4}, {0_fx, 0_fx, -0.5_fx}).ok());
  worlds.push_back(pushed);
  for (std::size_t i = 0; i < worlds.size(); ++i) {
    SCOPED_TRACE(testing::Message() << "world " << i);
    const Bytes bytes = worlds[i].save();
    const Decoded d = decode(bytes);
    ASSERT_TRUE(d.ok) << d.error;
    const Bytes expected = encode(expected_encoding(worlds[i], d.next_id));
    EXPECT_TRUE(expected == bytes) << "save() differs from the encoding its accessors imply ("
                                   << bytes.size() << " bytes, expected " << expected.size() << ")";
  }
}

TEST(StateFormat, HashesAreXxh3OfTheCanonicalSections) {
  World w = settled();
  // Unconsumed inputs are state too: leave some force on a body.
  ASSERT_TRUE(w.apply_force(BodyId{2}, {1_fx, 2_fx, 3_fx}).ok());
  const Bytes bytes = w.save();
  const Decoded d = decode(bytes);
  ASSERT_TRUE(d.ok) << d.error;
  const std::span<const std::uint8_t> all(bytes);
  const StateHashes h = w.hashes();
  EXPECT_EQ(h.total, xxh3(all));
  // Each section's hash covers its whole record, from its name's length to the end of its
  // payload: the sections follow one another, and the last ends with the state.
  ASSERT_EQ(h.sections.size(), kSectionCount);
  for (std::size_t i = 0; i < kSectionCount; ++i) {
    EXPECT_EQ(h.sections[i].name, kSectionNames[i]);
    const std::size_t end = i + 1 < kSectionCount ? d.section_at[i + 1] : bytes.size();
    EXPECT_EQ(h.sections[i].hash, xxh3(all.subspan(d.section_at[i], end - d.section_at[i])))
        << kSectionNames[i];
  }
  EXPECT_EQ(d.section_at[0], 9U);
  EXPECT_EQ(d.bodies.back().end, d.section_at[kContacts]);
  EXPECT_EQ(
      h.section("bodies"),
      xxh3(all.subspan(d.section_at[kBodies], d.section_at[kContacts] - d.section_at[kBodies])));
  EXPECT_EQ(h.section("no such section"), 0U);
  // body_hash: the body's set, then its record as if it were the only body.
  for (std::size_t i = 0; i < d.bodies.size(); ++i) {
    const Expected<std::uint64_t> bh = w.body_hash(d.bodies[i].id);
    ASSERT_TRUE(bh.ok());
    EXPECT_EQ(bh.value(), expected_body_hash(d, i)) << "body " << d.bodies[i].id.value;
  }
  // For the first body, "as if alone" is what is written: its set and record are in the bytes.
  ASSERT_EQ(d.bodies[0].set, 0U);
  Bytes first(all.begin() + static_cast<std::ptrdiff_t>(d.sets[0].at),
              all.begin() + static_cast<std::ptrdiff_t>(d.sets[0].end));
  first.insert(first.end(), all.begin() + static_cast<std::ptrdiff_t>(d.bodies[0].at),
               all.begin() + static_cast<std::ptrdiff_t>(d.bodies[0].end));
  EXPECT_EQ(w.body_hash(d.bodies[0].id).value(), xxh3(first));
}

// ======================================================================================
// Save and restore
// ======================================================================================

void expect_same_world(const World& a, const World& b) {
  EXPECT_EQ(a.save(), b.save());
  EXPECT_EQ(a.hashes(), b.hashes());
  EXPECT_EQ(a.def(), b.def());
  EXPECT_EQ(a.frame(), b.frame());
  EXPECT_EQ(a.rng(), b.rng());
  ASSERT_EQ(a.body_ids(), b.body_ids());
  for (const BodyId id : a.body_ids()) {
    EXPECT_TRUE(a.body(id).value() == b.body(id).value()) << "body " << id.value;
    EXPECT_EQ(a.body_hash(id).value(), b.body_hash(id).value()) << "body " << id.value;
  }
}

TEST(SaveRestore, RoundTripIsExact) {
  std::vector<World> worlds;
  worlds.emplace_back();                 // default, empty
  worlds.push_back(playground(1));       // fresh, never stepped
  worlds.push_back(played_once(2, 60));  // in flight, forces pending
  worlds.push_back(settled());           // settled: contacts and sleep
  World destroyed = settled();           // with a gap in the IDs
  ASSERT_TRUE(destroyed.destroy_body(BodyId{6}).ok());
  worlds.push_back(destroyed);
  for (std::size_t i = 0; i < worlds.size(); ++i) {
    SCOPED_TRACE(testing::Message() << "world " << i);
    const Bytes bytes = worlds[i].save();
    World fresh;
    const Status st = fresh.restore(bytes);
    ASSERT_TRUE(st.ok()) << st.message();
    expect_same_world(fresh, worlds[i]);
    // Restoring over a world that already has a (different) state replaces all of it.
    World busy = played_once(22, 120);
    ASSERT_TRUE(busy.restore(bytes).ok());
    expect_same_world(busy, worlds[i]);
  }
}

// Steps `w` (driven) to frame `to`, recording hashes() after every step.
std::vector<StateHashes> hashes_until(World& w, std::uint64_t to) {
  std::vector<StateHashes> out;
  while (w.frame() < to) {
    drive(w, w.frame());
    w.step();
    out.push_back(w.hashes());
  }
  return out;
}

TEST(SaveRestore, RestoredWorldStepsLikeOneThatNeverSaved) {
  // One uninterrupted, driven run to frame n, saving at several frames k on the way: before any
  // contact, while the bodies first land, while forces are pending, and while the stack sleeps
  // just before an impulse wakes it (in this scene the stack is asleep at frames 130-145 and
  // 345-365; the drive's impulses come at frames 142, ..., 367). A world restored from each save
  // must then reproduce every later frame's hashes.
  constexpr std::uint64_t n = 400;
  const std::vector<std::uint64_t> save_at{0, 25, 97, 135, 231, 355};
  World original = playground(5);
  std::vector<Bytes> saved;
  std::vector<StateHashes> reference;  // reference[f - 1]: the hashes after frame f
  while (original.frame() < n) {
    if (std::find(save_at.begin(), save_at.end(), original.frame()) != save_at.end())
      saved.push_back(original.save());
    drive(original, original.frame());
    original.step();
    reference.push_back(original.hashes());
  }
  ASSERT_EQ(saved.size(), save_at.size());
  const Bytes at_n = original.save();

  for (std::size_t i = 0; i < save_at.size(); ++i) {
    const std::uint64_t k = save_at[i];
    SCOPED_TRACE(testing::Message() << "saved at frame " << k);
    World restored;
    ASSERT_TRUE(restored.restore(saved[i]).ok());
    ASSERT_EQ(restored.frame(), k);
    const std::vector<StateHashes> replay = hashes_until(restored, n);
    ASSERT_EQ(replay.size(), n - k);
    for (std::size_t f = 0; f < replay.size(); ++f)
      ASSERT_EQ(replay[f], reference[k + f]) << "first divergence at frame " << k + f + 1;
    EXPECT_EQ(restored.save(), at_n);
  }

  // Rewind the original itself (save at k, step to n, restore, step to n again).
  const std::uint64_t k = save_at[3];
  ASSERT_TRUE(original.restore(saved[3]).ok());
  ASSERT_EQ(original.frame(), k);
  const std::vector<StateHashes> again = hashes_until(original, n);
  for (std::size_t f = 0; f < again.size(); ++f)
    ASSERT_EQ(again[f], reference[k + f]) << "rewound: first divergence at frame " << k + f + 1;
  EXPECT_EQ(original.save(), at_n);
}

TEST(SaveRestore, CopiesAndMovesCarryTheWholeState) {
  const World source = settled();
  World copy = source;
  World assigned;
  assigned = source;
  World moved_from = source;
  const World moved = std::move(moved_from);
  expect_same_world(copy, source);
  expect_same_world(assigned, source);
  expect_same_world(moved, source);
  // And they step alike.
  World a = source;
  run(a, 50);
  run(copy, 50);
  EXPECT_EQ(a.hashes(), copy.hashes());
}

// ======================================================================================
// Hashes
// ======================================================================================

struct HashSnapshot {
  StateHashes world;
  std::vector<std::uint64_t> bodies;
};

HashSnapshot snapshot(const World& w) {
  HashSnapshot s{w.hashes(), {}};
  for (const BodyId id : w.body_ids())
    s.bodies.push_back(w.body_hash(id).value());
  return s;
}

// After a change to body `touched` only: the total and body hashes changed, and only its body_hash.
void expect_only_body_changed(const World& w, const HashSnapshot& before, BodyId touched) {
  const HashSnapshot after = snapshot(w);
  EXPECT_NE(after.world.total, before.world.total);
  EXPECT_NE(after.world.section("bodies"), before.world.section("bodies"));
  EXPECT_EQ(after.world.section("globals"), before.world.section("globals"));
  EXPECT_EQ(after.world.section("rng"), before.world.section("rng"));
  EXPECT_EQ(after.world.section("contacts"), before.world.section("contacts"));
  const std::vector<BodyId> ids = w.body_ids();
  ASSERT_EQ(after.bodies.size(), before.bodies.size());
  for (std::size_t i = 0; i < ids.size(); ++i) {
    if (ids[i] == touched) {
      EXPECT_NE(after.bodies[i], before.bodies[i]) << "body " << ids[i].value;
    } else {
      EXPECT_EQ(after.bodies[i], before.bodies[i]) << "body " << ids[i].value;
    }
  }
}

TEST(StateHashes, OneBodyFieldChangesItsHashesOnly) {
  const World base = settled();
  const std::vector<BodyId> ids = base.body_ids();
  // For each dynamic or kinematic body (asleep or awake), several single-field changes.
  for (const BodyId id : ids) {
    const BodyState b = base.body(id).value();
    if (b.type == BodyType::static_body) continue;
    SCOPED_TRACE(testing::Message() << "body " << id.value);
    const HashSnapshot before = snapshot(base);
    {
      World w = base;
      Vec3 v = b.linear_velocity;
      v.y += Fixed::epsilon();  // one ulp
      ASSERT_TRUE(w.set_linear_velocity(id, v).ok());
      expect_only_body_changed(w, before, id);
    }
    {
      World w = base;
      ASSERT_TRUE(w.set_angular_velocity(id, b.angular_velocity + Vec3{0_fx, 0_fx, 1_fx}).ok());
      expect_only_body_changed(w, before, id);
    }
    {
      World w = base;
      ASSERT_TRUE(
          w.set_transform(id, b.position + Vec3{Fixed::epsilon(), 0_fx, 0_fx}, b.orientation).ok());
      expect_only_body_changed(w, before, id);
    }
    {
      World w = base;
      ASSERT_TRUE(w.apply_torque(id, {0_fx, 0_fx, 1_fx}).ok());
      expect_only_body_changed(w, before, id);
    }
  }
}

TEST(StateHashes, EachPartHasItsOwnHash) {
  const World base = settled();
  const HashSnapshot before = snapshot(base);
  {
    // The RNG: one draw changes the rng hash and the total only.
    World w = base;
    (void)w.rng().next_u64();
    const StateHashes h = w.hashes();
    EXPECT_NE(h.total, before.world.total);
    EXPECT_NE(h.section("rng"), before.world.section("rng"));
    EXPECT_EQ(h.section("globals"), before.world.section("globals"));
    EXPECT_EQ(h.section("bodies"), before.world.section("bodies"));
    EXPECT_EQ(h.section("contacts"), before.world.section("contacts"));
  }
  {
    // The globals: creating and destroying a body leaves every body and contact as it was but
    // advances the ID counter.
    World w = base;
    const BodyId extra = add(w, {.position = {100_fx, 100_fx, 100_fx}});
    ASSERT_TRUE(w.destroy_body(extra).ok());
    const HashSnapshot after = snapshot(w);
    EXPECT_NE(after.world.total, before.world.total);
    EXPECT_NE(after.world.section("globals"), before.world.section("globals"));
    EXPECT_EQ(after.world.section("rng"), before.world.section("rng"));
    EXPECT_EQ(after.world.section("bodies"), before.world.section("bodies"));
    EXPECT_EQ(after.world.section("contacts"), before.world.section("contacts"));
    EXPECT_EQ(after.bodies, before.bodies);
  }
  {
    // The contacts: one warm-start impulse changed (through the bytes; no API edits contacts).
    Decoded d = decode(base.save());
    ASSERT_TRUE(d.ok) << d.error;
    const auto touching = std::find_if(d.contacts.begin(), d.contacts.end(),
                                       [](const DecodedContact& c) { return c.point_count() > 0; });
    ASSERT_NE(touching, d.contacts.end());
    touching->points[0].normal_impulse += Fixed::epsilon();
    World w;
    const Status st = w.restore(encode(d));
    ASSERT_TRUE(st.ok()) << st.message();
    const HashSnapshot after = snapshot(w);
    EXPECT_NE(after.world.total, before.world.total);
    EXPECT_NE(after.world.section("contacts"), before.world.section("contacts"));
    EXPECT_EQ(after.world.section("globals"), before.world.section("globals"));
    EXPECT_EQ(after.world.section("rng"), before.world.section("rng"));
    EXPECT_EQ(after.world.section("bodies"), before.world.section("bodies"));
    EXPECT_EQ(after.bodies, before.bodies);
  }
  {
    // A step changes the frame number at least.
    World w = base;
    w.step();
    EXPECT_NE(w.hashes().section("globals"), before.world.section("globals"));
    EXPECT_NE(w.hashes().total, before.world.total);
  }
}

TEST(StateHashes, BodyHashDoesNotDependOnTheOtherBodies) {
  // Boxes 2, 3 and 4 share a set. Making box 2 kinematic gives it a set of its own, listed first,
  // which moves the others' set index from 0 to 1 in the bytes; destroying the plane moves every
  // body's ID step. Neither may change the other bodies' hashes.
  World w = make_world(WorldDef{});
  const BodyId plane = add(w, {.type = BodyType::static_body, .shape = Shape::plane()});
  std::vector<BodyId> boxes;
  for (int i = 0; i < 3; ++i) {
    boxes.push_back(add(w, {.shape = Shape::box({0.5_fx, 0.5_fx, 0.5_fx}),
                            .position = {Fixed::from_int(3 * i), 2_fx, 0_fx}}));
  }
  const auto hash = [&](BodyId id) { return w.body_hash(id).value(); };
  const std::uint64_t box3 = hash(boxes[1]);
  const std::uint64_t box4 = hash(boxes[2]);
  Decoded d = decode(w.save());
  ASSERT_TRUE(d.ok) << d.error;
  ASSERT_EQ(d.sets.size(), 2U);
  EXPECT_EQ(d.bodies[3].set, 1U);

  ASSERT_TRUE(w.set_type(boxes[0], BodyType::kinematic).ok());
  d = decode(w.save());
  ASSERT_TRUE(d.ok) << d.error;
  ASSERT_EQ(d.sets.size(), 3U);
  EXPECT_EQ(d.sets[1].type, BodyType::kinematic);
  EXPECT_EQ(d.bodies[3].set, 2U);
  EXPECT_EQ(hash(boxes[1]), box3);
  EXPECT_EQ(hash(boxes[2]), box4);

  ASSERT_TRUE(w.destroy_body(plane).ok());
  d = decode(w.save());
  ASSERT_TRUE(d.ok) << d.error;
  EXPECT_EQ(d.bodies[0].id_step, 2U);
  EXPECT_EQ(d.bodies[0].set, 0U);
  EXPECT_EQ(hash(boxes[1]), box3);
  EXPECT_EQ(hash(boxes[2]), box4);
  for (std::size_t i = 0; i < d.bodies.size(); ++i)
    EXPECT_EQ(hash(d.bodies[i].id), expected_body_hash(d, i)) << "body " << d.bodies[i].id.value;
}

TEST(StateHashes, BodyHashOfAnUnknownIdIsAnError) {
  World w = playground(3);
  EXPECT_FALSE(w.body_hash(BodyId{}).ok());
  EXPECT_FALSE(w.body_hash(BodyId{999}).ok());
  EXPECT_FALSE(w.body_hash(BodyId{0xFFFFFFFFU}).ok());
  EXPECT_FALSE(w.body_hash(BodyId{999}).message().empty());
  const BodyId gone = w.body_ids()[2];
  ASSERT_TRUE(w.body_hash(gone).ok());
  ASSERT_TRUE(w.destroy_body(gone).ok());
  EXPECT_FALSE(w.body_hash(gone).ok());
  EXPECT_FALSE(World().body_hash(BodyId{1}).ok());
}

TEST(StateHashes, IdenticalWorldsHashIdenticallyAndDifferentSeedsDiffer) {
  // Two independent runs (not the cache).
  const World a = played(40, 90);
  const World b = played(40, 90);
  EXPECT_EQ(a.hashes(), b.hashes());
  const World c = played(41, 90);
  EXPECT_NE(a.hashes().total, c.hashes().total);
  EXPECT_NE(a.hashes().section("rng"), c.hashes().section("rng"));
}

// ======================================================================================
// Canonical bytes
// ======================================================================================

TEST(CanonicalBytes, TheSameStateBuiltTwoWaysSavesTheSameBytes) {
  const Vec3 position{1.25_fx, 3_fx, -2_fx};
  const Quat orientation = about({0_fx, 1_fx, 1_fx}, 0.7_fx);
  const Vec3 velocity{-1_fx, 0.5_fx, 2_fx};
  const Vec3 spin{0_fx, 3_fx, 0.125_fx};

  // In one go: everything in the definitions.
  World direct = make_world(WorldDef{.seed = 77});
  add(direct, {.type = BodyType::static_body, .shape = Shape::plane()});
  add(direct, {.shape = Shape::box({0.5_fx, 0.5_fx, 0.25_fx}),
               .position = position,
               .orientation = orientation,
               .linear_velocity = velocity,
               .angular_velocity = spin});
  add(direct, {.type = BodyType::kinematic,
               .shape = Shape::capsule(0.5_fx, 1_fx),
               .position = {5_fx, 5_fx, 5_fx}});

  // Step by step: defaults first, then the setters.
  World stepwise = make_world(WorldDef{.seed = 77});
  add(stepwise, {.type = BodyType::static_body, .shape = Shape::plane()});
  const BodyId box = add(stepwise, {.shape = Shape::box({0.5_fx, 0.5_fx, 0.25_fx})});
  const BodyId capsule = add(stepwise, {.shape = Shape::capsule(0.5_fx, 1_fx)});
  ASSERT_TRUE(stepwise.set_transform(box, position, orientation).ok());
  ASSERT_TRUE(stepwise.set_linear_velocity(box, velocity).ok());
  ASSERT_TRUE(stepwise.set_angular_velocity(box, spin).ok());
  ASSERT_TRUE(stepwise.set_transform(capsule, {5_fx, 5_fx, 5_fx}, Quat{}).ok());
  ASSERT_TRUE(stepwise.set_type(capsule, BodyType::kinematic).ok());

  // Restored from another world's bytes (a world with a different definition and seed).
  World restored = played_once(2, 60);
  ASSERT_TRUE(restored.restore(direct.save()).ok());

  EXPECT_EQ(stepwise.save(), direct.save());
  EXPECT_EQ(restored.save(), direct.save());
  EXPECT_EQ(stepwise.hashes(), direct.hashes());

  // And they stay identical when stepped.
  for (int f = 0; f < 90; ++f) {
    direct.step();
    stepwise.step();
    restored.step();
    ASSERT_EQ(stepwise.hashes(), direct.hashes()) << "frame " << f + 1;
    ASSERT_EQ(restored.hashes(), direct.hashes()) << "frame " << f + 1;
  }
  EXPECT_EQ(stepwise.save(), direct.save());
}

TEST(CanonicalBytes, TheIdCounterIsPartOfTheState) {
  // Equal bodies, but one world has issued an extra ID: their futures differ (the next body gets a
  // different ID), so their bytes must too.
  World a = playground(9);
  World b = playground(9);
  const BodyId extra = add(b, {.position = {50_fx, 50_fx, 50_fx}});
  ASSERT_TRUE(b.destroy_body(extra).ok());
  EXPECT_NE(a.save(), b.save());
  EXPECT_EQ(a.hashes().section("bodies"), b.hashes().section("bodies"));
  EXPECT_EQ(add(a, {}).value + 1, add(b, {}).value);
}

TEST(CanonicalBytes, SaveIsAPureFunctionOfTheState) {
  const World w = settled();
  const Bytes first = w.save();
  EXPECT_EQ(w.save(), first);
  const StateHashes h = w.hashes();
  EXPECT_EQ(w.save(), first);  // hashing does not disturb anything
  EXPECT_EQ(w.hashes(), h);
  World again;
  ASSERT_TRUE(again.restore(first).ok());
  ASSERT_TRUE(again.restore(again.save()).ok());
  EXPECT_EQ(again.save(), first);
}

}  // namespace
}  // namespace detsim
