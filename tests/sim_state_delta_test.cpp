// Delta coding of saved states (<detsim/sim/state_delta.hpp>, docs/STATE.md "Deltas"): a delta
// gives its state back bit for bit against the same base, for every scenario and for states far
// apart or in either order; what did not move codes as in the base's delta against itself; a body
// in free flight is predicted from its velocity; and bytes that are not a state or a delta are
// refused, naming what is wrong, without a crash or an unbounded result.
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

#include "support/scenario_counts.hpp"
#include "support/sim_helpers.hpp"

namespace detsim {
namespace {

using namespace detsim::literals;
using Bytes = std::vector<std::uint8_t>;

Bytes delta(const Bytes& state, const Bytes& base) {
  auto d = encode_state_delta(state, base);
  EXPECT_TRUE(d.ok()) << d.message();
  return d.ok() ? *d : Bytes{};
}

/// The payload of section `name` of a state or of a delta (a delta has the state's container
/// with "DSDL" for its magic, so it is read as a state's after putting "DSIM" there).
Bytes payload(Bytes bytes, std::string_view name) {
  const std::uint8_t magic[4] = {'D', 'S', 'I', 'M'};
  std::copy(magic, magic + 4, bytes.begin());
  auto sections = read_state_sections(bytes);
  EXPECT_TRUE(sections.ok()) << sections.message();
  if (!sections) return {};
  for (const StateSection& s : *sections)
    if (s.name == name) return Bytes(s.payload.begin(), s.payload.end());
  ADD_FAILURE() << "no section " << name;
  return {};
}

void expect_round_trip(const Bytes& state, const Bytes& base) {
  const Bytes d = delta(state, base);
  ASSERT_GE(d.size(), 4U);
  EXPECT_EQ(std::string(d.begin(), d.begin() + 4), "DSDL");
  auto back = decode_state_delta(d, base);
  ASSERT_TRUE(back.ok()) << back.message();
  EXPECT_TRUE(*back == state) << "the decoded state differs from the one coded";
}

TEST(StateDelta, EveryScenariosStatesComeBackAgainstNearFarAndLaterBases) {
  for (const ScenarioInfo& info : scenario_list()) {
    SCOPED_TRACE(std::string(info.name));
    const ScenarioParams params{
        .seed = 9,
        .players = info.default_players,
        .count = test::scenario_test_count(info, std::min(info.default_count, 27U))};
    auto created = Scenario::create(info.name, params);
    ASSERT_TRUE(created.ok()) << created.message();
    Scenario& s = *created;
    const std::uint32_t players = s.params().players;
    Bytes inputs(static_cast<std::size_t>(players) * info.input_size);
    std::vector<Bytes> states{s.world().save()};
    for (std::uint64_t f = 0; f < 60; ++f) {
      for (std::uint32_t p = 0; p < players; ++p)
        s.scripted(9, f, p, std::span(inputs).subspan(p * info.input_size, info.input_size));
      s.step_encoded(inputs);
      states.push_back(s.world().save());
    }
    expect_round_trip(states[60], states[59]);  // a snapshot's usual base
    expect_round_trip(states[60], states[53]);  // a round trip before
    expect_round_trip(states[60], states[0]);   // bodies that moved far
    expect_round_trip(states[0], states[60]);   // a base later than the state
    expect_round_trip(states[30], states[30]);  // the state itself
  }
}

TEST(StateDelta, BodiesAndContactsTheBaseLacksComeBackToo) {
  World w = test::make_world();
  test::add_ground(w);
  std::vector<BodyId> boxes;
  for (int i = 0; i < 4; ++i) {
    BodyDef def;
    def.type = BodyType::dynamic;
    def.shape = Shape::box({0.5_fx, 0.5_fx, 0.5_fx});
    def.position = {Fixed::from_int(i) * 2_fx, 0.6_fx, Fixed::zero()};
    boxes.push_back(test::add(w, def));
  }
  for (int i = 0; i < 20; ++i)
    w.step();
  const Bytes base = w.save();
  ASSERT_TRUE(w.destroy_body(boxes[1]).ok());
  BodyDef dropped;
  dropped.type = BodyType::dynamic;
  dropped.shape = Shape::sphere(0.4_fx);
  dropped.position = {1_fx, 3_fx, 1_fx};
  test::add(w, dropped);
  for (int i = 0; i < 30; ++i)
    w.step();
  ASSERT_FALSE(w.contacts().empty());
  expect_round_trip(w.save(), base);
  expect_round_trip(base, w.save());
}

TEST(StateDelta, WhatDidNotMoveCodesAsInTheBasesDeltaAgainstItself) {
  // A pile that falls asleep: ten frames later only the frame counter has changed.
  auto created = Scenario::create("pile_boxes", {.seed = 1, .players = 0, .count = 27});
  ASSERT_TRUE(created.ok()) << created.message();
  World& w = created->world();
  int steps = 0;
  const auto all_asleep = [&] {
    for (const BodyId id : w.body_ids())
      if (test::state(w, id).awake) return false;
    return true;
  };
  while (!all_asleep() && steps < 2000) {
    w.step();
    ++steps;
  }
  ASSERT_TRUE(all_asleep()) << "the pile did not fall asleep in " << steps << " steps";
  ASSERT_GT(steps, 30) << "the pile must have settled, not started asleep";
  const Bytes base = w.save();
  for (int i = 0; i < 10; ++i)
    w.step();
  const Bytes state = w.save();
  const Bytes d = delta(state, base);
  const Bytes itself = delta(base, base);
  ASSERT_FALSE(payload(state, "contacts").empty());
  EXPECT_EQ(payload(d, "bodies"), payload(itself, "bodies"));
  EXPECT_EQ(payload(d, "contacts"), payload(itself, "contacts"));
  EXPECT_NE(payload(d, "globals"), payload(itself, "globals"));  // the frame
}

TEST(StateDelta, ABodyInFreeFlightIsPredictedFromItsVelocities) {
  WorldDef def;
  def.gravity = {};
  World w = test::make_world(def);
  BodyDef ball;
  ball.type = BodyType::dynamic;
  ball.shape = Shape::box({0.3_fx, 0.2_fx, 0.1_fx});
  ball.linear_velocity = {1.25_fx, -0.5_fx, 3_fx};
  ball.angular_velocity = {0.3_fx, 0.2_fx, -0.1_fx};
  test::add(w, ball);
  for (int i = 0; i < 10; ++i)
    w.step();
  const Bytes base = w.save();
  for (int i = 0; i < 3; ++i)
    w.step();
  const Bytes state = w.save();
  // Unpredicted, the position alone moved by (0.0625, -0.025, 0.15) m: 4 to 5 bytes a component
  // more than zero takes. Predicted, each of the 13 motion numbers (position, orientation,
  // velocities, sleep time) is left with at most a byte more than zero: rounding.
  const std::size_t zero = payload(delta(base, base), "bodies").size();
  const std::size_t coded = payload(delta(state, base), "bodies").size();
  EXPECT_LE(coded, zero + 13) << "coded " << coded << " bytes, at rest " << zero;
  expect_round_trip(state, base);
}

TEST(StateDelta, BytesThatAreNotAStateOrADeltaAreRefusedByName) {
  World w = test::make_world();
  test::add_ground(w);
  BodyDef def;
  def.type = BodyType::dynamic;
  def.position = {Fixed::zero(), 2_fx, Fixed::zero()};
  test::add(w, def);
  const Bytes base = w.save();
  for (int i = 0; i < 40; ++i)
    w.step();
  const Bytes state = w.save();
  const Bytes d = delta(state, base);

  auto not_state = encode_state_delta(Bytes(state.begin() + 1, state.end()), base);
  ASSERT_FALSE(not_state.ok());
  EXPECT_NE(not_state.message().find("state: "), std::string::npos) << not_state.message();
  EXPECT_NE(not_state.message().find("DSIM"), std::string::npos) << not_state.message();
  auto not_base = encode_state_delta(state, Bytes{1, 2, 3});
  ASSERT_FALSE(not_base.ok());
  EXPECT_EQ(not_base.message().rfind("base: ", 0), 0U) << not_base.message();
  auto a_state = decode_state_delta(state, base);
  ASSERT_FALSE(a_state.ok());
  EXPECT_NE(a_state.message().find("DSDL"), std::string::npos) << a_state.message();
  for (std::size_t n = 0; n < d.size(); ++n) {
    auto cut = decode_state_delta(std::span(d).first(n), base);
    EXPECT_FALSE(cut.ok()) << "a delta cut to " << n << " bytes";
  }
  // Any byte altered: an error, or some bytes no larger than the bound (a delta against the
  // wrong base or altered on the way decodes to another state, which its hash tells apart).
  for (std::size_t i = 0; i < d.size(); ++i) {
    for (const unsigned flip : {0x01U, 0x80U, 0xFFU}) {
      Bytes bad = d;
      bad[i] = static_cast<std::uint8_t>(bad[i] ^ flip);
      auto out = decode_state_delta(bad, base);
      if (out.ok()) {
        EXPECT_LE(out->size(), 10 * bad.size() + base.size()) << "byte " << i;
      }
    }
  }
}

}  // namespace
}  // namespace detsim
