// A game's own state in the World (World::set_game_state): the "game" section of the state — saved,
// restored, hashed as its own part, refused when malformed, absent from worlds that never set it —
// and diff naming its described fields.
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

#include "support/sim_helpers.hpp"

namespace detsim {
namespace {

using namespace detsim::literals;

using test::add;
using test::add_ground;
using test::make_world;

using Bytes = std::vector<std::uint8_t>;

/// A two-player game's state as a game would encode it: scores (u32 each), a cooldown (i16), the
/// ball's spin bonus (Fixed), a round (u8), little-endian.
struct Scores {
  std::uint32_t player1 = 0;
  std::uint32_t player2 = 0;
  std::int16_t cooldown = 0;
  Fixed bonus{};
  std::uint8_t round = 1;

  Bytes encode() const {
    Bytes out;
    const auto put = [&out](std::uint64_t v, std::size_t n) {
      for (std::size_t i = 0; i < n; ++i)
        out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
    };
    put(player1, 4);
    put(player2, 4);
    put(static_cast<std::uint16_t>(cooldown), 2);
    put(static_cast<std::uint64_t>(bonus.raw()), 8);
    put(round, 1);
    return out;
  }
};

const std::vector<GameField> scores_fields = {
    {"score.player1", 0, GameFieldType::u32},
    {"score.player2", 4, GameFieldType::u32},
    {"cooldown", 8, GameFieldType::i16},
    {"bonus", 10, GameFieldType::fixed},
    // byte 18, the round, left undescribed
};

World scene() {
  World w = make_world();
  add_ground(w);
  BodyDef ball;
  ball.shape = Shape::sphere(0.5_fx);
  ball.position = {0_fx, 3_fx, 0_fx};
  add(w, ball);
  return w;
}

std::vector<std::string> section_names(const StateHashes& h) {
  std::vector<std::string> names;
  for (const SectionHash& s : h.sections)
    names.push_back(s.name);
  return names;
}

TEST(SimGameState, AWorldThatNeverSetsOneHasNoGameSection) {
  World w = scene();
  EXPECT_TRUE(w.game_state().empty());
  const std::vector<std::string> names = section_names(w.hashes());
  EXPECT_EQ(names, (std::vector<std::string>{"globals", "rng", "geometry", "bodies", "contacts",
                                             "joints", "particles"}));
}

TEST(SimGameState, TheGameSectionIsSavedRestoredAndHashedAsItsOwnPart) {
  World w = scene();
  Scores scores;
  scores.player1 = 3;
  const Bytes bytes = scores.encode();
  ASSERT_TRUE(w.set_game_state(bytes).ok());
  EXPECT_EQ(Bytes(w.game_state().begin(), w.game_state().end()), bytes);
  const StateHashes h = w.hashes();
  ASSERT_EQ(section_names(h).back(), "game");
  const Bytes saved = w.save();
  // The section's hash is XXH3-64 of its record: name length, name, version, u32 length, payload
  // (docs/STATE.md), the last record of the state.
  Bytes record = {4, 'g', 'a', 'm', 'e', 1};
  for (int i = 0; i < 4; ++i)
    record.push_back(static_cast<std::uint8_t>(bytes.size() >> (8 * i)));
  record.insert(record.end(), bytes.begin(), bytes.end());
  ASSERT_GE(saved.size(), record.size());
  EXPECT_TRUE(std::equal(record.begin(), record.end(), saved.end() - std::ssize(record)));
  EXPECT_EQ(h.section("game"), hash_bytes(record));
  EXPECT_EQ(h.total, hash_bytes(saved));

  // Only the game part changes when only the game state does.
  scores.player1 = 4;
  ASSERT_TRUE(w.set_game_state(scores.encode()).ok());
  const StateHashes changed = w.hashes();
  for (const SectionHash& s : changed.sections)
    EXPECT_EQ(s.hash == h.section(s.name), s.name != "game") << s.name;

  // Restore brings it back, into this world or another; stepping leaves it alone.
  ASSERT_TRUE(w.restore(saved).ok());
  EXPECT_EQ(Bytes(w.game_state().begin(), w.game_state().end()), bytes);
  World other = scene();
  ASSERT_TRUE(other.restore(saved).ok());
  EXPECT_EQ(other.save(), saved);
  other.step();
  EXPECT_EQ(Bytes(other.game_state().begin(), other.game_state().end()), bytes);

  // A state without a game section clears it.
  const Bytes plain = scene().save();
  ASSERT_TRUE(w.restore(plain).ok());
  EXPECT_TRUE(w.game_state().empty());
  EXPECT_EQ(w.save(), plain);
}

TEST(SimGameState, RefusalsNameTheProblemAndChangeNothing) {
  World w = scene();
  ASSERT_TRUE(w.set_game_state(Scores{}.encode()).ok());
  const Bytes before = w.save();
  const Status empty = w.set_game_state({});
  EXPECT_FALSE(empty.ok());
  EXPECT_NE(empty.message().find("got none"), std::string::npos) << empty.message();
  const Bytes huge(max_game_state_size + 1, 0xAB);
  const Status too_big = w.set_game_state(huge);
  EXPECT_FALSE(too_big.ok());
  EXPECT_NE(too_big.message().find(std::to_string(max_game_state_size + 1)), std::string::npos)
      << too_big.message();
  EXPECT_EQ(w.save(), before);
  const Bytes largest(max_game_state_size, 0xCD);
  EXPECT_TRUE(w.set_game_state(largest).ok());

  // Malformed game sections in a state: another version, an empty payload, a section after it.
  ASSERT_TRUE(w.set_game_state(Bytes{7}).ok());
  const Bytes one = w.save();  // ends with 4 "game" 1 | 01 00 00 00 | 07
  const std::size_t version_at = one.size() - 6;
  ASSERT_EQ(one[version_at], 1);
  Bytes other_version = one;
  other_version[version_at] = 2;
  Bytes no_payload = one;
  no_payload.pop_back();
  no_payload[no_payload.size() - 4] = 0;
  World fresh = scene();
  const Bytes untouched = fresh.save();
  const Status v = fresh.restore(other_version);
  EXPECT_FALSE(v.ok());
  EXPECT_NE(v.message().find("section \"game\" version 2, this build reads 1"), std::string::npos)
      << v.message();
  const Status e = fresh.restore(no_payload);
  EXPECT_FALSE(e.ok());
  EXPECT_NE(e.message().find("0 bytes, expected 1"), std::string::npos) << e.message();
  EXPECT_EQ(fresh.save(), untouched);
}

TEST(SimGameState, DiffNamesDescribedFieldsAndTheBytesNoFieldCovers) {
  World w = scene();
  ASSERT_TRUE(w.describe_game_state(scores_fields).ok());
  Scores sa;
  sa.player1 = 2;
  sa.cooldown = -5;
  sa.bonus = 0.5_fx;
  ASSERT_TRUE(w.set_game_state(sa.encode()).ok());
  const Bytes a = w.save();
  Scores sb = sa;
  sb.player1 = 3;
  sb.cooldown = -6;
  sb.round = 2;
  ASSERT_TRUE(w.set_game_state(sb.encode()).ok());
  const Bytes b = w.save();

  World described = scene();
  ASSERT_TRUE(described.describe_game_state(scores_fields).ok());
  auto d = diff_states(described, a, b);
  ASSERT_TRUE(d.ok()) << d.message();
  ASSERT_EQ(d->fields.size(), 3U);
  EXPECT_EQ(d->fields[0].subsystem, "game");
  EXPECT_EQ(d->fields[0].field, "score.player1");
  EXPECT_EQ(d->fields[0].a, "2 (0x0000000000000002)");
  EXPECT_EQ(d->fields[0].b, "3 (0x0000000000000003)");
  EXPECT_EQ(d->fields[1].field, "cooldown");
  EXPECT_EQ(d->fields[1].a, "-5 (0x000000000000fffb)");
  EXPECT_EQ(d->fields[1].b, "-6 (0x000000000000fffa)");
  EXPECT_EQ(d->fields[2].field, "bytes[18..18]");
  EXPECT_EQ(d->fields[2].a, "01");
  EXPECT_EQ(d->fields[2].b, "02");

  // The description survives restore (it is the world's, not the state's) and copies.
  ASSERT_TRUE(described.restore(b).ok());
  World copy(described);
  EXPECT_EQ(
      std::vector<GameField>(copy.game_state_fields().begin(), copy.game_state_fields().end()),
      scores_fields);

  // Undescribed: byte ranges; a longer state: its size, and a field present on one side only.
  auto raw = diff_states(scene(), a, b);
  ASSERT_TRUE(raw.ok()) << raw.message();
  ASSERT_EQ(raw->fields.size(), 3U);
  EXPECT_EQ(raw->fields[0].field, "bytes[0..0]");
  EXPECT_EQ(raw->fields[1].field, "bytes[8..8]");
  EXPECT_EQ(raw->fields[2].field, "bytes[18..18]");
  const Bytes four = {1, 0, 0, 0};
  ASSERT_TRUE(w.set_game_state(four).ok());
  auto shorter = diff_states(described, a, w.save());
  ASSERT_TRUE(shorter.ok()) << shorter.message();
  ASSERT_GE(shorter->fields.size(), 3U);
  EXPECT_EQ(shorter->fields[0].field, "size");
  EXPECT_EQ(shorter->fields[1].field, "score.player1");
  EXPECT_EQ(shorter->fields[2].field, "score.player2");
  EXPECT_EQ(shorter->fields[2].b, "absent");
}

TEST(SimGameState, InjectionChangesOneFieldAndDiffNamesIt) {
  World w = scene();
  ASSERT_TRUE(w.describe_game_state(scores_fields).ok());
  Scores scores;
  scores.player2 = 0xFFFFFFFFU;
  scores.bonus = 1.5_fx;
  ASSERT_TRUE(w.set_game_state(scores.encode()).ok());
  w.step();
  const Bytes before = w.save();
  const auto inject = [&w](const std::string& spec) {
    auto parsed = parse_injection(spec);
    if (!parsed) return Status::error(parsed.message());
    return apply_injection(w, parsed.value());
  };
  // Each described field, by name, at its width (a u32 wraps), and one byte.
  const struct {
    const char* spec;
    const char* field;
    const char* b;
  } cases[] = {
      {"1:0:game.score.player1:3", "score.player1", "3 (0x0000000000000003)"},
      {"1:0:game.score.player2:1", "score.player2", "0 (0x0000000000000000)"},
      {"1:0:game.cooldown:-2", "cooldown", "-2 (0x000000000000fffe)"},
      {"1:0:game.bonus:0.25", "bonus", "1.75 (0x00000001c0000000)"},
      {"1:0:game.byte[18]:255", "bytes[18..18]", "00"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.spec);
    ASSERT_TRUE(w.restore(before).ok());
    ASSERT_TRUE(inject(c.spec).ok());
    auto d = diff_states(w, before, w.save());
    ASSERT_TRUE(d.ok()) << d.message();
    ASSERT_EQ(d->fields.size(), 1U);
    EXPECT_EQ(d->fields[0].subsystem, "game");
    EXPECT_EQ(d->fields[0].field, c.field);
    EXPECT_EQ(d->fields[0].b, c.b);
  }
  // Refused, naming why, the world unchanged.
  ASSERT_TRUE(w.restore(before).ok());
  const struct {
    const char* spec;
    const char* message;
  } refused[] = {
      {"1:2:game.score.player1:1", "BODY must be 0 for a field of the game state"},
      {"1:0:game.byte[1]:0.5", "is not a 64-bit integer"},
      {"1:0:game.lives:1", "has no field \"lives\""},
      {"1:0:game.byte[19]:1", "the game state has 19 bytes, no byte 19"},
      {"1:0:game.score.player1:0.5", "for an integer field must be an integer"},
      {"1:0:game.:1", "unknown field"},
  };
  for (const auto& r : refused) {
    SCOPED_TRACE(r.spec);
    const Status st = inject(r.spec);
    EXPECT_FALSE(st.ok());
    EXPECT_NE(st.message().find(r.message), std::string::npos) << st.message();
    EXPECT_EQ(w.save(), before);
  }
}

TEST(SimGameState, BadDescriptionsAreRefusedNamingTheField) {
  World w = scene();
  ASSERT_TRUE(w.describe_game_state(scores_fields).ok());
  const auto refused = [&w](std::vector<GameField> fields, const std::string& expected) {
    const Status s = w.describe_game_state(fields);
    EXPECT_FALSE(s.ok());
    EXPECT_NE(s.message().find(expected), std::string::npos) << s.message();
  };
  refused({{"", 0, GameFieldType::u8}}, "a name is 1..64 characters");
  refused({{"score player", 0, GameFieldType::u8}}, "a name is 1..64 characters");
  refused({{std::string(65, 'a'), 0, GameFieldType::u8}}, "a name is 1..64 characters");
  refused({{"a", 0, GameFieldType::u8}, {"a", 1, GameFieldType::u8}}, "field 1 \"a\": named twice");
  refused({{"far", static_cast<std::uint32_t>(max_game_state_size - 7), GameFieldType::u64}},
          "ends past the largest game state");
  refused({{"odd", 0, static_cast<GameFieldType>(42)}}, "unknown type 42");
  EXPECT_EQ(w.game_state_fields().size(), scores_fields.size()) << "refusals change nothing";
  EXPECT_TRUE(w.describe_game_state({}).ok());
  EXPECT_TRUE(w.game_state_fields().empty());
}

}  // namespace
}  // namespace detsim
