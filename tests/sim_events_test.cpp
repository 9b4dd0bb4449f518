// Contact and sensor events: when a pair begins and ends touching, in which order the events come,
// and that they are as deterministic as the state (a restored world reports what the original did).
#include <algorithm>
#include <cstdint>
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
using test::state;

using Events = std::vector<ContactEvent>;

Events events(const World& w) {
  return {w.contact_events().begin(), w.contact_events().end()};
}

ContactEvent begin(BodyId a, BodyId b, bool sensor = false) {
  return {ContactEvent::Kind::begin, a, b, sensor};
}
ContactEvent end(BodyId a, BodyId b, bool sensor = false) {
  return {ContactEvent::Kind::end, a, b, sensor};
}

TEST(ContactEvents, DroppedSphereBeginsOnceWhenItTouches) {
  // A solid pair is in touch once its gap at the start of a step is within the speculative
  // distance, or when the contact pushes during the step (a fast sphere is stopped at the surface
  // by a speculative contact from farther away): the begin event comes in exactly the first such
  // step, and none follows while the sphere rests.
  World w = make_world();
  const BodyId ground = add_ground(w);
  const BodyId ball = add(w, {.shape = Shape::sphere(0.5_fx), .position = {0_fx, 3_fx, 0_fx}});
  const Fixed reach = w.def().speculative_distance;
  int begins = 0;
  for (int frame = 0; frame < 240; ++frame) {
    const Fixed gap = state(w, ball).position.y - 0.5_fx;  // before the step
    const Fixed free_fall_vy = state(w, ball).linear_velocity.y + w.def().gravity.y * w.def().dt;
    w.step();
    const bool pushed = state(w, ball).linear_velocity.y > free_fall_vy + 0.000001_fx;
    const Events e = events(w);
    if (begins == 0 && gap > reach && !pushed) {
      EXPECT_TRUE(e.empty()) << "frame " << frame << ": gap " << to_string(gap);
    } else if (begins == 0) {
      ASSERT_EQ(e, Events{begin(ground, ball)}) << "frame " << frame;
      ++begins;
    } else {
      EXPECT_TRUE(e.empty()) << "frame " << frame << ": the resting sphere reported a change";
    }
  }
  EXPECT_EQ(begins, 1);
  EXPECT_FALSE(state(w, ball).awake) << "the scene should end at rest";
}

TEST(ContactEvents, BouncingBallAlternatesBeginAndEnd) {
  World w = make_world();
  const BodyId ground = add_ground(w);
  const BodyId ball = add(
      w, {.shape = Shape::sphere(0.25_fx), .position = {0_fx, 2_fx, 0_fx}, .restitution = 1_fx});
  Events all;
  for (int frame = 0; frame < 300; ++frame) {
    w.step();
    for (const ContactEvent& e : w.contact_events()) {
      EXPECT_EQ(e.a, ground);
      EXPECT_EQ(e.b, ball);
      EXPECT_FALSE(e.sensor);
      all.push_back(e);
    }
  }
  // An elastic ball dropped from 1.75 m above the ground lands every 2 sqrt(2 h / g) = 1.19 s: in
  // 5 s, at least 4 landings, each a begin followed by an end.
  ASSERT_GE(all.size(), 8U);
  for (std::size_t i = 0; i < all.size(); ++i) {
    EXPECT_EQ(all[i].kind, i % 2 == 0 ? ContactEvent::Kind::begin : ContactEvent::Kind::end)
        << "event " << i;
  }
}

TEST(SensorEvents, ReportOverlapAndLeaveTheMotionUntouched) {
  // A static sensor slab the sphere falls through: begin on entering, end on leaving, flagged as
  // sensor events — and the sphere's motion is exactly that of a world without the sensor.
  const BodyDef ball_def{.shape = Shape::sphere(0.25_fx), .position = {0_fx, 10_fx, 0_fx}};
  World plain = make_world();
  add(plain, {.type = BodyType::static_body,
              .shape = Shape::sphere(0.1_fx),
              .position = {50_fx, 0_fx, 0_fx}});  // keeps the body IDs equal in both worlds
  const BodyId plain_ball = add(plain, ball_def);

  World w = make_world();
  const BodyId sensor = add(w, {.type = BodyType::static_body,
                                .shape = Shape::box({2_fx, 1_fx, 2_fx}),
                                .position = {0_fx, 5_fx, 0_fx},
                                .sensor = true});
  const BodyId ball = add(w, ball_def);
  ASSERT_EQ(ball, plain_ball);

  int entered = -1;
  int left = -1;
  for (int frame = 0; frame < 120; ++frame) {
    const Fixed y = state(w, ball).position.y;  // before the step
    // Overlap with the slab (y in 4 .. 6) for a sphere of radius 0.25: centre in 3.75 .. 6.25.
    const bool inside = y < 6.25_fx && y > 3.75_fx;
    w.step();
    plain.step();
    ASSERT_EQ(state(w, ball).position, state(plain, plain_ball).position) << "frame " << frame;
    ASSERT_EQ(state(w, ball).linear_velocity, state(plain, plain_ball).linear_velocity);
    const Events e = events(w);
    if (inside && entered < 0) {
      ASSERT_EQ(e, Events{begin(sensor, ball, true)}) << "frame " << frame;
      entered = frame;
    } else if (!inside && entered >= 0 && left < 0) {
      ASSERT_EQ(e, Events{end(sensor, ball, true)}) << "frame " << frame;
      left = frame;
    } else {
      EXPECT_TRUE(e.empty()) << "frame " << frame;
    }
  }
  EXPECT_GE(entered, 0);
  EXPECT_GT(left, entered);
}

// Three balls resting on the ground and one resting on a box, with events in every step.
World busy_scene() {
  World w = make_world();
  add_ground(w);
  for (int i = 0; i < 6; ++i) {
    add(w, {.shape = i % 2 == 0 ? Shape::sphere(0.3_fx) : Shape::box({0.3_fx, 0.3_fx, 0.3_fx}),
            .position = {Fixed::from_int(i) * 0.5_fx, Fixed::from_int(1 + i), 0_fx},
            .restitution = 0.5_fx});
  }
  return w;
}

TEST(ContactEvents, ComeInPairOrderAndAreReproducedAfterRestore) {
  World w = busy_scene();
  std::vector<std::uint8_t> saved;
  std::vector<Events> original;
  int nonempty = 0;
  for (int frame = 0; frame < 200; ++frame) {
    if (frame == 40) saved = w.save();
    w.step();
    const Events e = events(w);
    nonempty += e.empty() ? 0 : 1;
    for (std::size_t i = 1; i < e.size(); ++i) {
      const bool ordered = e[i - 1].a < e[i].a || (e[i - 1].a == e[i].a && e[i - 1].b < e[i].b);
      EXPECT_TRUE(ordered) << "frame " << frame << ": events out of pair order";
    }
    if (frame >= 40) original.push_back(e);
  }
  EXPECT_GE(nonempty, 5) << "the scene should produce events in several steps";

  World restored = make_world();
  ASSERT_TRUE(restored.restore(saved).ok());
  EXPECT_TRUE(restored.contact_events().empty()) << "restore must clear the event list";
  for (std::size_t k = 0; k < original.size(); ++k) {
    restored.step();
    ASSERT_EQ(events(restored), original[k]) << "step " << k << " after the restore";
  }
}

TEST(ContactEvents, DestroyingABodyEndsItsTouchingPairs) {
  World w = make_world();
  const BodyId ground = add_ground(w);
  const BodyId box =
      add(w, {.shape = Shape::box({1_fx, 0.5_fx, 1_fx}), .position = {0_fx, 0.5_fx, 0_fx}});
  const BodyId top = add(w, {.shape = Shape::sphere(0.25_fx), .position = {0_fx, 1.25_fx, 0_fx}});
  const BodyId far = add(w, {.shape = Shape::sphere(0.25_fx), .position = {20_fx, 0.25_fx, 0_fx}});
  for (int i = 0; i < 30; ++i)
    w.step();
  ASSERT_TRUE(w.destroy_body(box).ok());
  // The box touched the ground (lower ID) and the top sphere: both pairs end, in pair order.
  EXPECT_EQ(events(w), (Events{end(ground, box), end(box, top)}));
  // The next step starts a new list; the sphere that fell keeps touching nothing new until it
  // lands, and the far sphere still rests.
  w.step();
  for (const ContactEvent& e : w.contact_events()) {
    EXPECT_NE(e.a, box);
    EXPECT_NE(e.b, box);
    EXPECT_NE(e.b, far);
  }
}

TEST(ContactEvents, TeleportingAwayEndsThePairWhenItsBoxesPart) {
  World w = make_world();
  const BodyId ground = add(w, {.type = BodyType::static_body,
                                .shape = Shape::box({5_fx, 0.5_fx, 5_fx}),
                                .position = {0_fx, -0.5_fx, 0_fx}});
  const BodyId ball = add(w, {.shape = Shape::sphere(0.5_fx), .position = {0_fx, 0.5_fx, 0_fx}});
  w.step();
  ASSERT_EQ(events(w), Events{begin(ground, ball)});
  ASSERT_TRUE(w.set_transform(ball, {100_fx, 100_fx, 0_fx}, Quat{}).ok());
  w.step();  // the broadphase drops the pair: its end is reported
  EXPECT_EQ(events(w), Events{end(ground, ball)});
  w.step();
  EXPECT_TRUE(events(w).empty());
}

TEST(ContactEvents, AreTheSameInTwoIdenticalRuns) {
  World a = busy_scene();
  World b = busy_scene();
  for (int frame = 0; frame < 150; ++frame) {
    a.step();
    b.step();
    ASSERT_EQ(events(a), events(b)) << "frame " << frame;
  }
}

}  // namespace
}  // namespace detsim
