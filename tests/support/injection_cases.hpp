// The field classes of desync bisection's tests: for each, an injection chosen from the state it
// changes (a rule, so that the same state always gives the same choice), and the difference that
// bisection must name for it.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <detsim/sim/inject.hpp>
#include <detsim/sim/state_diff.hpp>
#include <detsim/sim/world.hpp>

namespace detsim::test {

enum class FieldClass {
  position,
  linear_velocity,
  angular_velocity,
  orientation,
  sleep_state,
  rng_state,
  contact_impulse,
  body_removed,
  body_added,
};

inline const char* class_name(FieldClass c) {
  switch (c) {
    case FieldClass::position:
      return "position";
    case FieldClass::linear_velocity:
      return "linear_velocity";
    case FieldClass::angular_velocity:
      return "angular_velocity";
    case FieldClass::orientation:
      return "orientation";
    case FieldClass::sleep_state:
      return "sleep_state";
    case FieldClass::rng_state:
      return "rng_state";
    case FieldClass::contact_impulse:
      return "contact_impulse";
    case FieldClass::body_removed:
      return "body_removed";
    case FieldClass::body_added:
      return "body_added";
  }
  return "?";
}

inline const std::vector<FieldClass>& all_field_classes() {
  static const std::vector<FieldClass> all = {
      FieldClass::position,        FieldClass::linear_velocity, FieldClass::angular_velocity,
      FieldClass::orientation,     FieldClass::sleep_state,     FieldClass::rng_state,
      FieldClass::contact_impulse, FieldClass::body_removed,    FieldClass::body_added};
  return all;
}

/// The injection of class `c` for `world` (at the frame it is to change), or nothing when this
/// state has no target for it (e.g. no contact with a cached point): the rule picks the highest-ID
/// dynamic body, or the first contact the solver leaves alone (no awake dynamic body), else the
/// first whose first point pushed, else the first with a point.
inline std::optional<Injection> choose_injection(FieldClass c, const World& world) {
  Injection i;
  i.frame = world.frame();
  std::uint32_t dynamic = 0;
  for (const BodyId id : world.body_ids())
    if (world.body(id).value().type == BodyType::dynamic) dynamic = id.value;
  if (dynamic == 0) return std::nullopt;
  i.body = dynamic;
  switch (c) {
    case FieldClass::position:
      i.field = "position.y";
      i.delta = "0.001";
      break;
    case FieldClass::linear_velocity:
      i.field = "linear_velocity.x";
      i.delta = "0.01";
      break;
    case FieldClass::angular_velocity:
      i.field = "angular_velocity.z";
      i.delta = "-0.05";
      break;
    case FieldClass::orientation:
      i.field = "orientation.w";  // |q|^2 moves by ~2e-7, within restore's 2^-20
      i.delta = "0.0000001";
      break;
    case FieldClass::sleep_state:
      i.field = "sleep_time";
      i.delta = "0.25";
      break;
    case FieldClass::rng_state:
      i.body = 0;
      i.field = "rng.state[1]";
      i.delta = "12345";
      break;
    case FieldClass::contact_impulse: {
      // A changed impulse must survive to the next hash check. The solver leaves the impulses of
      // a pair with no awake dynamic body as they are until the pair wakes, so such a pair is
      // preferred. A loaded pair's impulse is warm-started into the next step but can be absorbed
      // within a frame or two (the soft contact returns to the same bits), and a point that has
      // come apart has its impulse reset: those are the fallbacks, in that order.
      const auto moving = [&world](BodyId id) {
        const BodyState b = world.body(id).value();
        return b.type == BodyType::dynamic && b.awake;
      };
      std::optional<ContactState> resting;
      std::optional<ContactState> loaded;
      std::optional<ContactState> any;
      for (const ContactState& k : world.contacts()) {
        if (k.point_count == 0) continue;
        if (!any) any = k;
        if (!loaded && k.points[0].normal_impulse > Fixed::zero()) loaded = k;
        if (!moving(k.a) && !moving(k.b)) {
          resting = k;
          break;
        }
      }
      const std::optional<ContactState> target = resting ? resting : loaded ? loaded : any;
      if (!target) return std::nullopt;
      i.body = target->a.value;
      i.field = "contact[" + std::to_string(target->b.value) + "].point[0].normal_impulse";
      i.delta = "0.5";
      return i;
    }
    case FieldClass::body_removed:
      i.field = "present";
      i.delta = "-1";
      break;
    case FieldClass::body_added:
      i.field = "present";
      i.delta = "+1";
      break;
  }
  return i;
}

/// Checks that `diffs` (side A healthy, side B with `injection`) name exactly the injected field.
inline void expect_names_injection(const std::vector<FieldDiff>& diffs, FieldClass c,
                                   const Injection& injection) {
  SCOPED_TRACE(std::string("class ") + class_name(c) + ", injection " + injection.text());
  ASSERT_FALSE(diffs.empty());
  const FieldDiff& first = diffs.front();
  switch (c) {
    case FieldClass::rng_state:
      ASSERT_EQ(diffs.size(), 1U);
      EXPECT_EQ(first.subsystem, "rng");
      EXPECT_EQ(first.field, "state[1]");
      return;
    case FieldClass::contact_impulse:
      ASSERT_EQ(diffs.size(), 1U);
      EXPECT_EQ(first.subsystem, "contacts");
      EXPECT_EQ(first.body, injection.body);
      EXPECT_EQ(first.field, injection.field);
      return;
    case FieldClass::body_removed: {
      // The body, then its contacts (gone with it); the globals' body count.
      bool body = false;
      for (const FieldDiff& d : diffs) {
        if (d.subsystem == "bodies") {
          EXPECT_EQ(d.body, injection.body);
          EXPECT_EQ(d.field, "present");
          EXPECT_EQ(d.a, "present");
          EXPECT_EQ(d.b, "absent");
          body = true;
        } else if (d.subsystem == "contacts") {
          EXPECT_TRUE(d.field.ends_with(".present")) << d.field;
        } else {
          EXPECT_EQ(d.subsystem, "globals");
        }
      }
      EXPECT_TRUE(body);
      return;
    }
    case FieldClass::body_added: {
      bool body = false;
      for (const FieldDiff& d : diffs) {
        if (d.subsystem != "bodies") {
          EXPECT_EQ(d.subsystem, "globals") << d.field;
          continue;
        }
        EXPECT_GT(d.body, injection.body);  // the copy has the next ID
        EXPECT_EQ(d.field, "present");
        EXPECT_EQ(d.a, "absent");
        EXPECT_EQ(d.b, "present");
        body = true;
      }
      EXPECT_TRUE(body);
      return;
    }
    default:
      ASSERT_EQ(diffs.size(), 1U) << diffs[1].subsystem << " " << diffs[1].body << " "
                                  << diffs[1].field;
      EXPECT_EQ(first.subsystem, "bodies");
      EXPECT_EQ(first.body, injection.body);
      EXPECT_EQ(first.field, injection.field);
      EXPECT_NE(first.a, first.b);
      return;
  }
}

}  // namespace detsim::test
