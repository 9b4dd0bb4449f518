// A game's own scenario (register_scenario): created by name like the built-ins, listed, refused
// with the problem named, and recorded, verified and seeked through replay/ with its game state.
#include <array>
#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

#include "support/replay_files.hpp"

namespace detsim {
namespace {

using namespace detsim::literals;

/// "tally": a ball on a plane, and per player the number of frames its jump button was down,
/// kept in the World's game state (u32 each, little-endian) and pushed into the ball as a kick.
void build_tally(World& w, const ScenarioParams& p) {
  BodyDef ground;
  ground.type = BodyType::static_body;
  ground.shape = Shape::plane();
  (void)w.create_body(ground);
  BodyDef ball;
  ball.shape = Shape::sphere(0.5_fx);
  ball.position = {0_fx, 0.5_fx, 0_fx};
  (void)w.create_body(ball);
  (void)w.set_game_state(std::vector<std::uint8_t>(4 * p.players, 0));
  std::vector<GameField> fields;
  for (std::uint32_t i = 0; i < p.players; ++i)
    fields.push_back({"presses.player" + std::to_string(i + 1), 4 * i, GameFieldType::u32});
  (void)w.describe_game_state(fields);
}

void control_tally(World& w, std::span<const PlayerInput> inputs, const ScenarioParams&) {
  std::vector<std::uint8_t> state(w.game_state().begin(), w.game_state().end());
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    if ((inputs[i].buttons & PlayerInput::jump) == 0) continue;
    std::uint32_t count = 0;
    for (int k = 0; k < 4; ++k)
      count |= std::uint32_t{state[4 * i + static_cast<std::size_t>(k)]} << (8 * k);
    ++count;
    for (int k = 0; k < 4; ++k)
      state[4 * i + static_cast<std::size_t>(k)] = static_cast<std::uint8_t>(count >> (8 * k));
    (void)w.apply_linear_impulse(BodyId{2},
                                 {Fixed::from_int(inputs[i].move_x) / 64_fx, 0_fx, 0_fx});
  }
  (void)w.set_game_state(state);
}

ScenarioDefinition tally() {
  ScenarioDefinition d;
  d.name = "tally";
  d.summary = "a ball kicked by players, who score a point per frame of jump";
  d.default_frames = 300;
  d.min_players = 1;
  d.max_players = 4;
  d.default_players = 2;
  d.uses_seed = true;
  d.build = build_tally;
  d.control = control_tally;
  return d;
}

/// Registers `definition` unless a scenario of its name is known (the registry never forgets,
/// and tests of one process share it).
void ensure_registered(const ScenarioDefinition& definition) {
  if (find_scenario(definition.name) != nullptr) return;
  const Status s = register_scenario(definition);
  EXPECT_TRUE(s.ok()) << s.message();
}

void ensure_tally() {
  ensure_registered(tally());
}

std::uint32_t presses(const World& w, std::uint32_t player) {
  std::uint32_t n = 0;
  for (int k = 0; k < 4; ++k)
    n |= std::uint32_t{w.game_state()[4 * player + static_cast<std::size_t>(k)]} << (8 * k);
  return n;
}

TEST(ScenarioRegister, ARegisteredGameIsCreatedListedAndStepsLikeABuiltIn) {
  ensure_tally();
  const ScenarioInfo* info = find_scenario("tally");
  ASSERT_NE(info, nullptr);
  EXPECT_EQ(info->summary, tally().summary);
  EXPECT_EQ(info->default_players, 2U);
  const std::vector<ScenarioInfo> all = scenario_list();
  for (std::size_t i = 1; i < all.size(); ++i)
    EXPECT_LT(all[i - 1].name, all[i].name) << "sorted by name";
  EXPECT_TRUE(
      std::any_of(all.begin(), all.end(), [](const ScenarioInfo& s) { return s.name == "tally"; }));

  auto made = Scenario::create("tally", {.seed = 9});
  ASSERT_TRUE(made.ok()) << made.message();
  Scenario& s = made.value();
  EXPECT_EQ(s.params().players, 2U);
  EXPECT_EQ(s.info().name, "tally");
  std::vector<PlayerInput> inputs(2);
  inputs[1].buttons = PlayerInput::jump;
  inputs[1].move_x = 64;
  for (int f = 0; f < 10; ++f)
    s.step(inputs);
  EXPECT_EQ(presses(s.world(), 0), 0U);
  EXPECT_EQ(presses(s.world(), 1), 10U);
  EXPECT_GT(s.world().body(BodyId{2})->linear_velocity.x, 0_fx) << "the kicks moved the ball";
  EXPECT_EQ(s.world().hashes().sections.back().name, "game");

  auto other = Scenario::create("tally", {.players = 5});
  EXPECT_FALSE(other.ok());
  EXPECT_NE(other.message().find("takes 1 to 4 players, got 5"), std::string::npos)
      << other.message();
}

TEST(ScenarioRegister, ARegisteredGameRecordsVerifiesAndSeeks) {
  ensure_tally();
  test::TempFile file("tally.dsr");
  auto scenario = Scenario::create("tally", {.seed = 3});
  ASSERT_TRUE(scenario.ok());
  replay::RecordOptions options;
  options.frames = 200;
  options.keyframe_interval = 50;
  auto recorded = replay::record(scenario.value(), file.path(), options);
  ASSERT_TRUE(recorded.ok()) << recorded.message();
  auto reader = replay::ReplayReader::open(file.path());
  ASSERT_TRUE(reader.ok()) << reader.message();
  EXPECT_EQ(reader->fingerprint().scenario, "tally");
  EXPECT_EQ(reader->fingerprint().state_sections.back(), "game");
  auto verified = replay::verify(reader.value());
  ASSERT_TRUE(verified.ok()) << verified.message();
  EXPECT_TRUE(verified->ok);
  EXPECT_EQ(verified->frames, 200U);
  EXPECT_EQ(verified->final_hash, recorded->final_hash);
  auto at = replay::seek(reader.value(), 137);
  ASSERT_TRUE(at.ok()) << at.message();
  auto straight = Scenario::create("tally", {.seed = 3});
  ASSERT_TRUE(straight.ok());
  std::vector<PlayerInput> inputs(2);
  for (std::uint64_t f = 1; f <= 137; ++f) {  // record's frame f is stepped with its inputs
    for (std::uint32_t p = 0; p < 2; ++p)
      inputs[p] = scripted_input(3, f, p);
    straight->step(inputs);
  }
  EXPECT_EQ(at->world().save(), straight->world().save());
}

TEST(ScenarioRegister, AGameStateSetAfterFrameZeroIsARecordingErrorThatSaysWhy) {
  // A replay lists the sections of frame 0; a game section that appears later cannot be recorded.
  static const bool registered = [] {
    ScenarioDefinition late = tally();
    late.name = "tally_late";
    late.build = [](World& w, const ScenarioParams&) {
      BodyDef ground;
      ground.type = BodyType::static_body;
      ground.shape = Shape::plane();
      (void)w.create_body(ground);
    };
    late.control = [](World& w, std::span<const PlayerInput>, const ScenarioParams&) {
      (void)w.set_game_state(std::vector<std::uint8_t>{1});
    };
    return register_scenario(late).ok();
  }();
  ASSERT_TRUE(registered);
  test::TempFile file("late.dsr");
  auto scenario = Scenario::create("tally_late");
  ASSERT_TRUE(scenario.ok());
  replay::RecordOptions options;
  options.frames = 10;
  auto recorded = replay::record(scenario.value(), file.path(), options);
  ASSERT_FALSE(recorded.ok());
  EXPECT_NE(recorded.message().find("frame 1: the state's sections"), std::string::npos)
      << recorded.message();
  EXPECT_NE(recorded.message().find("must be set before the first frame"), std::string::npos)
      << recorded.message();
}

/// "dial": a game with its own input — 2 bytes per player, a signed 16-bit push along x, little-
/// endian — that adds each player's pushes up in its game state and kicks the ball with them.
void control_dial(World& w, std::span<const std::uint8_t> inputs, const ScenarioParams& p) {
  std::vector<std::uint8_t> state(w.game_state().begin(), w.game_state().end());
  for (std::uint32_t i = 0; i < p.players; ++i) {
    const auto push = static_cast<std::int16_t>(
        static_cast<std::uint16_t>(inputs[2 * i] | (std::uint16_t{inputs[2 * i + 1]} << 8)));
    std::uint32_t total = 0;
    for (int k = 0; k < 4; ++k)
      total |= std::uint32_t{state[4 * i + static_cast<std::size_t>(k)]} << (8 * k);
    total += static_cast<std::uint32_t>(push);  // modulo 2^32: a running sum with wrap-around
    for (int k = 0; k < 4; ++k)
      state[4 * i + static_cast<std::size_t>(k)] = static_cast<std::uint8_t>(total >> (8 * k));
    (void)w.apply_force(BodyId{2}, {Fixed::from_int(push) / 4096_fx, 0_fx, 0_fx});
  }
  (void)w.set_game_state(state);
}

ScenarioDefinition dial() {
  ScenarioDefinition d = tally();
  d.name = "dial";
  d.summary = "a ball pushed by each player's 16-bit dial";
  d.control = nullptr;
  d.input_size = 2;
  d.control_bytes = control_dial;
  return d;
}

void ensure_dial() {
  ensure_registered(dial());
}

std::int32_t dial_total(const World& w, std::uint32_t player) {
  std::uint32_t n = 0;
  for (int k = 0; k < 4; ++k)
    n |= std::uint32_t{w.game_state()[4 * player + static_cast<std::size_t>(k)]} << (8 * k);
  return static_cast<std::int32_t>(n);
}

TEST(ScenarioRegister, AGameWithItsOwnInputGetsItsBytesAsTheyAre) {
  ensure_dial();
  const ScenarioInfo* info = find_scenario("dial");
  ASSERT_NE(info, nullptr);
  EXPECT_EQ(info->input_size, 2U);
  auto s = Scenario::create("dial", {.players = 3});
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_FALSE(s->takes_player_input());
  // -2, 300 and (missing bytes) 0, then 1000, -1 and 7: the totals are the sums.
  s->step_encoded(std::vector<std::uint8_t>{0xFE, 0xFF, 0x2C, 0x01});
  s->step_encoded(std::vector<std::uint8_t>{0xE8, 0x03, 0xFF, 0xFF, 0x07, 0x00, 0x99});
  EXPECT_EQ(dial_total(s->world(), 0), -2 + 1000);
  EXPECT_EQ(dial_total(s->world(), 1), 300 - 1);
  EXPECT_EQ(dial_total(s->world(), 2), 7);
  // PlayerInputs mean nothing to it: step() gives every player the zero input.
  const std::vector<PlayerInput> stick(3, PlayerInput{PlayerInput::dash, 100, 100});
  s->step(stick);
  EXPECT_EQ(dial_total(s->world(), 0), 998);
  // Without a script of its own, its stand-in's bytes are a pure function of (seed, frame, player)
  // that changes with each of them.
  std::array<std::uint8_t, 2> a{};
  std::array<std::uint8_t, 2> again{};
  s->scripted(5, 30, 1, a);
  s->scripted(5, 30, 1, again);
  EXPECT_EQ(a, again);
  std::set<std::array<std::uint8_t, 2>> seen;
  for (std::uint64_t f = 0; f < 300; f += 15)
    for (std::uint32_t p = 0; p < 3; ++p) {
      s->scripted(5, f, p, a);
      seen.insert(a);
    }
  EXPECT_GT(seen.size(), 50U) << "60 decisions, nearly all different";
}

TEST(ScenarioRegister, AGameWithItsOwnInputRecordsVerifiesSeeksAndSyncTests) {
  ensure_dial();
  test::TempFile file("dial.dsr");
  auto scenario = Scenario::create("dial", {.seed = 4});
  ASSERT_TRUE(scenario.ok());
  replay::RecordOptions options;
  options.frames = 150;
  options.keyframe_interval = 40;
  options.input_bytes = [](std::uint64_t frame, std::span<std::uint8_t> out) {
    ASSERT_EQ(out.size(), 4U);  // two players of 2 bytes
    for (std::size_t i = 0; i < out.size(); ++i)
      out[i] = static_cast<std::uint8_t>(frame * 7 + i * 61);
  };
  auto recorded = replay::record(scenario.value(), file.path(), options);
  ASSERT_TRUE(recorded.ok()) << recorded.message();
  auto reader = replay::ReplayReader::open(file.path());
  ASSERT_TRUE(reader.ok()) << reader.message();
  EXPECT_EQ(reader->fingerprint().input_size, 2U);
  auto verified = replay::verify(reader.value());
  ASSERT_TRUE(verified.ok()) << verified.message();
  EXPECT_TRUE(verified->ok) << verified->note;
  EXPECT_EQ(verified->final_hash, recorded->final_hash);
  auto at = replay::seek(reader.value(), 99);
  ASSERT_TRUE(at.ok()) << at.message();
  auto straight = Scenario::create("dial", {.seed = 4});
  std::vector<std::uint8_t> bytes(4);
  for (std::uint64_t f = 1; f <= 99; ++f) {
    options.input_bytes(f, bytes);
    straight->step_encoded(bytes);
  }
  EXPECT_EQ(at->world().save(), straight->world().save());
  // The running sums in the game state are the inputs' (a formula, not a read-back).
  std::int32_t expected = 0;
  for (std::uint64_t f = 1; f <= 99; ++f)
    expected += static_cast<std::int16_t>(static_cast<std::uint16_t>(
        static_cast<std::uint8_t>(f * 7) | (static_cast<std::uint8_t>(f * 7 + 61) << 8)));
  EXPECT_EQ(dial_total(at->world(), 0), expected);

  // PlayerInputs are refused by name for such a game; the sync test takes its bytes.
  auto other = Scenario::create("dial", {.seed = 4});
  replay::RecordOptions wrong;
  wrong.inputs = [](std::uint64_t, std::span<PlayerInput>) {};
  auto refused = replay::record(other.value(), "", wrong);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.message().find("takes its own input of 2 bytes"), std::string::npos)
      << refused.message();
  auto sync_scenario = Scenario::create("dial", {.seed = 4});
  net::ScenarioGame game(sync_scenario.value());
  EXPECT_EQ(game.input_size(), 2U);
  auto sync = net::SyncTestSession::create({2, game.input_size(), 6}, game);
  ASSERT_TRUE(sync.ok()) << sync.message();
  for (std::uint64_t f = 1; f <= 120; ++f) {
    options.input_bytes(f, bytes);
    auto ok = sync->advance_frame(bytes);
    ASSERT_TRUE(ok.ok()) << ok.message();
    ASSERT_TRUE(ok.value()) << "frame " << f;
  }
}

TEST(ScenarioRegister, BadDefinitionsAreRefusedNamingTheProblem) {
  ensure_tally();
  const auto refused = [](ScenarioDefinition d, const std::string& expected) {
    const Status s = register_scenario(d);
    EXPECT_FALSE(s.ok()) << d.name;
    EXPECT_NE(s.message().find(expected), std::string::npos) << s.message();
  };
  ScenarioDefinition d = tally();
  d.name = "Tally";
  refused(d, "a name is 1..32 characters of a-z, 0-9 and _");
  d.name = "";
  refused(d, "a name is 1..32 characters");
  d = tally();
  refused(d, "a scenario of that name exists");
  d.name = "arena";
  refused(d, "a scenario of that name exists");
  d = tally();
  d.name = "tally2";
  d.build = nullptr;
  refused(d, "build is empty");
  d = tally();
  d.name = "tally2";
  d.max_players = 65;
  refused(d, "at most 64 players");
  d = tally();
  d.name = "tally2";
  d.default_players = 5;
  refused(d, "min_players <= default_players <= max_players, got 1, 5, 4");
  d = tally();
  d.name = "tally2";
  d.control = nullptr;
  refused(d, "needs control");
  d = tally();
  d.name = "tally2";
  d.default_count = 3;
  refused(d, "default_count 3 exceeds max_count 0");
  d = tally();
  d.name = "tally2";
  d.world.dt = 0_fx;
  refused(d, "world: ");
  d = tally();
  d.name = "tally2";
  d.default_frames = 0;
  refused(d, "default_frames must be >= 1");
  d = tally();
  d.name = "tally2";
  d.input_size = 65;
  refused(d, "input_size is at most 64 bytes, got 65");
  d.input_size = 2;
  refused(d, "takes control_bytes, not control");
  d.control = nullptr;
  refused(d, "needs control_bytes");
  d = tally();
  d.name = "tally2";
  d.control_bytes = control_dial;
  refused(d, "control_bytes and script are for a game's own input: set input_size");
  EXPECT_EQ(find_scenario("tally2"), nullptr) << "nothing was registered";
}

}  // namespace
}  // namespace detsim
