// Fault injection (sim/inject.hpp): every field form parses and prints back, bad specs are refused
// naming the bad part, each applied injection changes exactly the named field (as diff_states sees
// it) by exactly DELTA, refused injections change nothing, and an injected world stays valid.
#include <gtest/gtest.h>

#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include <detsim/fixed/decimal.hpp>
#include <detsim/scenes/scenario.hpp>
#include <detsim/sim/inject.hpp>
#include <detsim/sim/state_diff.hpp>

namespace detsim {
namespace {

constexpr std::uint64_t kFrame = 60;

void step_scripted(Scenario& s) {
  std::vector<PlayerInput> inputs(s.params().players);
  for (std::uint32_t p = 0; p < inputs.size(); ++p)
    inputs[p] = scripted_input(s.params().seed, s.world().frame(), p);
  s.step(inputs);
}

Scenario new_arena() {
  return Scenario::create("arena", {.seed = 3, .players = 8}).value();
}

/// The arena after kFrame steps (players on the floor, crates resting: contacts with points).
const World& arena() {
  static const World world = [] {
    Scenario s = new_arena();
    while (s.world().frame() < kFrame)
      step_scripted(s);
    return s.world();
  }();
  return world;
}

/// A value as diff_states prints it: decimal, then the raw bits in hex.
std::string hex(std::uint64_t v) {
  char text[19];
  std::snprintf(text, sizeof text, "0x%016llx", static_cast<unsigned long long>(v));
  return text;
}
std::string shown(Fixed v) {
  return to_string(v) + " (" + hex(static_cast<std::uint64_t>(v.raw())) + ")";
}
std::string shown(std::uint64_t v) {
  return std::to_string(v) + " (" + hex(v) + ")";
}

std::string line(const FieldDiff& f) {
  return f.subsystem + " " + std::to_string(f.body) + " " + f.field + ": " + f.a + " -> " + f.b;
}

Fixed dec(const char* text) {
  return Fixed::parse(text).value;
}

Injection spec(const std::string& text) {
  auto parsed = parse_injection(text);
  EXPECT_TRUE(parsed.ok()) << text << ": " << parsed.message();
  return parsed.ok() ? parsed.value() : Injection{};
}

/// Applies `text` to `world` and returns the diff of the states before and after.
StateDiff inject(World& world, const std::string& text) {
  const std::vector<std::uint8_t> before = world.save();
  const Status s = apply_injection(world, spec(text));
  EXPECT_TRUE(s.ok()) << text << ": " << s.message();
  return diff_states(before, world.save()).value();
}

/// The diff lists exactly one field: this one. Returns it (or an empty FieldDiff).
FieldDiff only_field(const StateDiff& d, const std::string& subsystem, std::uint32_t body,
                     const std::string& field) {
  EXPECT_EQ(d.omitted, 0U);
  if (d.fields.size() != 1) {
    ADD_FAILURE() << d.fields.size() << " fields listed, expected only " << field;
    for (const FieldDiff& f : d.fields)
      ADD_FAILURE() << "listed: " << line(f);
    return {};
  }
  const FieldDiff& f = d.fields[0];
  EXPECT_EQ(f.subsystem, subsystem);
  EXPECT_EQ(f.body, body);
  EXPECT_EQ(f.field, field);
  return f;
}

/// A contact of the arena with cached points (the one with most, then the lowest pair).
ContactState touching_contact(const World& w) {
  ContactState best;
  for (const ContactState& c : w.contacts())
    if (c.point_count > best.point_count) best = c;
  EXPECT_GT(best.point_count, 0U) << "no contact with points at frame " << w.frame();
  return best;
}

std::string frame_prefix(const World& w, std::uint32_t body) {
  return std::to_string(w.frame()) + ":" + std::to_string(body) + ":";
}

// ---- Parsing ----

TEST(ParseInjection, EveryFieldFormRoundTrips) {
  std::vector<std::string> specs = {
      "12:3:sleep_time:0.5",
      "12:3:awake:1",
      "12:3:user_data:-5",
      "12:3:user_data:9223372036854775807",
      "12:3:present:-1",
      "12:3:present:+1",
      "12:3:present:1",
      "1:0:rng.state[0]:1",
      "1:0:rng.state[3]:-9223372036854775808",
      "18446744073709551615:4294967295:contact[17].point[0].normal_impulse:0.5",
      "7:17:contact[4294967295].point[3].tangent_impulse_1:-2",
      "7:17:contact[3].point[1].tangent_impulse_2:1e2",
      "7:17:contact[3/0/0].point[1].tangent_impulse_2:1e2",
      "7:17:contact[3/12/4294967295].point[0].normal_impulse:-0.5",
  };
  for (const char* base : {"position", "linear_velocity", "angular_velocity", "force", "torque"})
    for (const char* c : {"x:0.25", "y:-1.5", "z:1e-3"})
      specs.push_back(std::string("12:3:") + base + "." + c);
  for (const char* c : {"w:0.0000001", "x:-0.001", "y:0", "z:+0.5"})
    specs.push_back(std::string("12:3:orientation.") + c);
  for (const std::string& text : specs) {
    auto parsed = parse_injection(text);
    ASSERT_TRUE(parsed.ok()) << text << ": " << parsed.message();
    EXPECT_EQ(parsed->text(), text);
  }
  const Injection i =
      spec("18446744073709551615:4294967295:contact[17].point[0].normal_impulse:0.5");
  EXPECT_EQ(i.frame, 18446744073709551615ULL);
  EXPECT_EQ(i.body, 4294967295U);
  EXPECT_EQ(i.field, "contact[17].point[0].normal_impulse");
  EXPECT_EQ(i.delta, "0.5");
}

TEST(ParseInjection, ErrorsNameTheOffendingPart) {
  struct Case {
    const char* spec;
    const char* names;  // a substring the message must contain
  };
  const Case cases[] = {
      {"", "FRAME:BODY:FIELD:DELTA"},
      {"12", "FRAME:BODY:FIELD:DELTA"},
      {"12:3:position.y", "FRAME:BODY:FIELD:DELTA"},
      {"0:3:position.y:1", "FRAME \"0\""},
      {"x:3:position.y:1", "FRAME \"x\""},
      {"-1:3:position.y:1", "FRAME \"-1\""},
      {"18446744073709551616:3:position.y:1", "FRAME \"18446744073709551616\""},
      {"12:b:position.y:1", "BODY \"b\""},
      {"12::position.y:1", "BODY \"\""},
      {"12:4294967296:position.y:1", "BODY \"4294967296\""},
      {"12:0:position.y:1", "BODY must be a body ID"},
      {"12:0:contact[3].point[0].normal_impulse:1", "BODY must be a body ID"},
      {"12:3:rng.state[0]:1", "BODY must be 0"},
      {"12:3:position.q:1", "unknown field \"position.q\""},
      {"12:3:positionx:1", "unknown field \"positionx\""},
      {"12:3:position.xy:1", "unknown field \"position.xy\""},
      {"12:3:orientation.v:1", "unknown field \"orientation.v\""},
      {"12:3:mass:1", "unknown field \"mass\""},
      {"12:3::1", "unknown field \"\""},
      {"12:0:rng.state[4]:1", "unknown field \"rng.state[4]\""},
      {"12:0:rng.state[1]x:1", "unknown field \"rng.state[1]x\""},
      {"12:0:rng.state:1", "unknown field \"rng.state\""},
      {"12:3:contact[3].point[4].normal_impulse:1",
       "unknown field \"contact[3].point[4].normal_impulse\""},
      {"12:3:contact[x].point[0].normal_impulse:1", "unknown field \"contact[x]"},
      {"12:3:contact[4294967296].point[0].normal_impulse:1", "unknown field \"contact[42949"},
      {"12:3:contact[3].point[0].impulse:1", "unknown field \"contact[3].point[0].impulse\""},
      {"12:3:contact[3].normal_impulse:1", "unknown field \"contact[3].normal_impulse\""},
      {"12:3:contact[3/1].point[0].normal_impulse:1", "unknown field \"contact[3/1]"},
      {"12:3:contact[3/1/2/3].point[0].normal_impulse:1", "unknown field \"contact[3/1/2/3]"},
      {"12:3:contact[3/x/2].point[0].normal_impulse:1", "unknown field \"contact[3/x/2]"},
      {"12:3:contact[3//2].point[0].normal_impulse:1", "unknown field \"contact[3//2]"},
      {"12:3:contact[3/1/4294967296].point[0].normal_impulse:1", "unknown field \"contact[3/1/"},
      {"12:3:contact[0/1/2].point[0].normal_impulse:1", "unknown field \"contact[0/1/2]"},
      {"12:3:position.y:abc", "DELTA \"abc\""},
      {"12:3:position.y:", "DELTA \"\""},
      {"12:3:position.y:0.1:5", "DELTA \"0.1:5\""},
      {"12:3:sleep_time:1e", "DELTA \"1e\""},
      {"12:3:position.y:3000000000", "DELTA \"3000000000\""},
      {"12:3:contact[4].point[0].normal_impulse:x", "DELTA \"x\""},
      {"12:3:awake:2", "DELTA for awake"},
      {"12:3:awake:-1", "DELTA for awake"},
      {"12:3:present:0", "DELTA for present"},
      {"12:3:present:2", "DELTA for present"},
      {"12:3:user_data:1.5", "DELTA \"1.5\""},
      {"12:3:user_data:+-5", "DELTA \"+-5\""},
      {"12:3:user_data:18446744073709551615", "DELTA \"18446744073709551615\""},
      {"12:0:rng.state[1]:0.5", "DELTA \"0.5\""},
      {"12:0:rng.state[1]:", "DELTA \"\""},
  };
  for (const Case& c : cases) {
    auto parsed = parse_injection(c.spec);
    if (parsed.ok()) {
      ADD_FAILURE() << c.spec << " was accepted as " << parsed->text();
      continue;
    }
    const std::string& m = parsed.message();
    EXPECT_EQ(m.rfind("--inject \"" + std::string(c.spec) + "\": ", 0), 0U) << m;
    EXPECT_NE(m.find(c.names), std::string::npos) << c.spec << " -> " << m;
  }
  // An unknown field's message lists the fields there are.
  const std::string m = parse_injection("1:2:position.q:1").message();
  EXPECT_NE(m.find(injection_fields_help()), std::string::npos) << m;
}

TEST(ParseInjection, HelpNamesEveryFieldForm) {
  const std::string help(injection_fields_help());
  for (const char* name : {"position", "orientation", "linear_velocity", "angular_velocity",
                           "force", "torque", "sleep_time", "awake", "user_data", "present",
                           "rng.state", "normal_impulse", "tangent_impulse_1", "tangent_impulse_2"})
    EXPECT_NE(help.find(name), std::string::npos) << name;
}

// ---- Applying: the diff names exactly the injected field, changed by exactly DELTA ----

TEST(ApplyInjection, EachBodyDecimalFieldChangesByDelta) {
  struct Case {
    const char* field;
    const char* delta;
    Fixed (*get)(const BodyState&);
  };
  const Case cases[] = {
      {"position.y", "0.25", [](const BodyState& b) { return b.position.y; }},
      {"orientation.w", "0.0000001", [](const BodyState& b) { return b.orientation.w; }},
      {"orientation.z", "-0.0000001", [](const BodyState& b) { return b.orientation.z; }},
      {"linear_velocity.x", "-0.5", [](const BodyState& b) { return b.linear_velocity.x; }},
      {"angular_velocity.z", "0.125", [](const BodyState& b) { return b.angular_velocity.z; }},
      {"force.z", "7", [](const BodyState& b) { return b.force.z; }},
      {"torque.x", "-1e-3", [](const BodyState& b) { return b.torque.x; }},
      {"sleep_time", "0.5", [](const BodyState& b) { return b.sleep_time; }},
  };
  const BodyId crate = arena().body_ids().back();
  for (const Case& c : cases) {
    SCOPED_TRACE(c.field);
    World w = arena();
    const BodyState before = w.body(crate).value();
    const StateDiff d = inject(w, frame_prefix(w, crate.value) + c.field + ":" + c.delta);
    const Fixed expected = c.get(before) + dec(c.delta);
    EXPECT_EQ(shown(c.get(w.body(crate).value())), shown(expected));
    const FieldDiff f = only_field(d, "bodies", crate.value, c.field);
    EXPECT_EQ(f.a, shown(c.get(before)));
    EXPECT_EQ(f.b, shown(expected));
  }
}

TEST(ApplyInjection, AwakeTogglesAndTogglesBack) {
  World w = arena();
  const BodyId player = w.body_ids()[5];  // the floor and four walls come first
  ASSERT_EQ(w.body(player).value().type, BodyType::dynamic);
  const std::uint64_t original = w.hashes().total;
  const bool before = w.body(player).value().awake;
  const FieldDiff f = only_field(inject(w, frame_prefix(w, player.value) + "awake:1"), "bodies",
                                 player.value, "awake");
  EXPECT_EQ(f.a, before ? "true" : "false");
  EXPECT_EQ(f.b, before ? "false" : "true");
  EXPECT_EQ(w.body(player).value().awake, !before);
  ASSERT_TRUE(apply_injection(w, spec(frame_prefix(w, player.value) + "awake:1")).ok());
  EXPECT_EQ(w.hashes().total, original);
}

TEST(ApplyInjection, UserDataAndRngAddModulo2To64) {
  World w = arena();
  const BodyId player = w.body_ids()[5];
  const std::uint64_t data = w.body(player).value().user_data;
  FieldDiff f = only_field(inject(w, frame_prefix(w, player.value) + "user_data:-5"), "bodies",
                           player.value, "user_data");
  EXPECT_EQ(w.body(player).value().user_data, data - 5U);
  EXPECT_EQ(f.a, shown(data));
  EXPECT_EQ(f.b, shown(data - 5U));

  const Rng::State rng = w.rng().state();
  f = only_field(inject(w, frame_prefix(w, 0) + "rng.state[2]:-3"), "rng", 0, "state[2]");
  Rng::State expected = rng;
  expected[2] -= 3U;
  EXPECT_EQ(w.rng().state(), expected);
  EXPECT_EQ(f.a, shown(rng[2]));
  EXPECT_EQ(f.b, shown(expected[2]));
}

TEST(ApplyInjection, AContactPointIsNamedFromEitherBodyOfThePair) {
  const ContactState c = touching_contact(arena());
  const std::size_t point = c.point_count - 1U;
  const std::string field = "contact[" + std::to_string(c.b.value) + "].point[" +
                            std::to_string(point) + "].normal_impulse";
  const Fixed expected = c.points[point].normal_impulse + dec("0.75");

  World from_a = arena();
  const StateDiff da = inject(from_a, frame_prefix(from_a, c.a.value) + field + ":0.75");
  const FieldDiff f = only_field(da, "contacts", c.a.value, field);
  EXPECT_EQ(f.a, shown(c.points[point].normal_impulse));
  EXPECT_EQ(f.b, shown(expected));

  World from_b = arena();
  const StateDiff db =
      inject(from_b, frame_prefix(from_b, c.b.value) + "contact[" + std::to_string(c.a.value) +
                         "].point[" + std::to_string(point) + "].normal_impulse:0.75");
  const FieldDiff g = only_field(db, "contacts", c.a.value, field);
  EXPECT_EQ(g.b, f.b);
  EXPECT_EQ(from_a.hashes(), from_b.hashes());

  // Only that point of that pair changed, as contacts() shows it.
  std::vector<ContactState> after = from_b.contacts();
  std::vector<ContactState> want = arena().contacts();
  for (ContactState& x : want)
    if (x.a == c.a && x.b == c.b) x.points[point].normal_impulse = expected;
  EXPECT_EQ(after, want);
}

// With registered geometry a body pair has one contact per pair of sub-shapes (a compound's part,
// a mesh's triangle): diff names each as contact[OTHER/S/T], and that name, given to --inject from
// either body, changes exactly that contact.
TEST(ApplyInjection, AContactBetweenSubShapesIsNamedAsDiffPrintsIt) {
  Scenario level = Scenario::create("level", {.seed = 1, .count = 2}).value();
  const World geometry = level.world();
  // The first contact with points between sub-shapes of a pair that has several contacts.
  std::optional<ContactState> pick;
  while (!pick && level.world().frame() < 300) {
    level.step();
    const std::vector<ContactState> all = level.world().contacts();
    for (std::size_t i = 0; i + 1 < all.size() && !pick; ++i) {
      const ContactState& c = all[i];
      const bool shared = all[i + 1].a == c.a && all[i + 1].b == c.b;
      if (shared && c.point_count > 0 && (c.sub_a != 0 || c.sub_b != 0)) pick = c;
    }
  }
  ASSERT_TRUE(pick.has_value()) << "no pair with several sub-shape contacts by frame 300";
  const ContactState c = *pick;
  const std::string a = std::to_string(c.a.value), b = std::to_string(c.b.value);
  const std::string sa = std::to_string(c.sub_a), sb = std::to_string(c.sub_b);
  const std::string field = "contact[" + b + "/" + sa + "/" + sb + "].point[0].normal_impulse";
  const std::string frame = std::to_string(level.world().frame());

  World from_a = level.world();
  const std::vector<std::uint8_t> before = from_a.save();
  ASSERT_TRUE(apply_injection(from_a, spec(frame + ":" + a + ":" + field + ":0.5")).ok());
  const StateDiff da = diff_states(geometry, before, from_a.save()).value();
  const FieldDiff f = only_field(da, "contacts", c.a.value, field);
  EXPECT_EQ(f.a, shown(c.points[0].normal_impulse));
  EXPECT_EQ(f.b, shown(c.points[0].normal_impulse + dec("0.5")));

  // What diff printed is what --inject takes; from the other body, the sub-shapes swap.
  World from_b = level.world();
  const std::string mirrored = "contact[" + a + "/" + sb + "/" + sa + "].point[0].normal_impulse";
  ASSERT_TRUE(apply_injection(from_b, spec(frame + ":" + b + ":" + mirrored + ":0.5")).ok());
  EXPECT_EQ(from_a.hashes(), from_b.hashes());

  // Sub-shapes the pair has no contact between: refused, naming the contacts it has.
  World w = level.world();
  const Status refused = apply_injection(
      w, spec(frame + ":" + a + ":contact[" + b + "/99999/99999].point[0].normal_impulse:1"));
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.message().find("have no contact (sub-shapes 99999 and 99999)"),
            std::string::npos)
      << refused.message();
  EXPECT_NE(refused.message().find("contact[" + b + "/" + sa + "/" + sb + "]"), std::string::npos)
      << refused.message();
  EXPECT_EQ(w.hashes(), level.world().hashes());
}

TEST(ApplyInjection, PresentMinusOneRemovesTheBodyAndItsContacts) {
  const World& base = arena();
  // A dynamic body in contacts, preferably as the lower ID of one pair and the higher of another.
  BodyId gone;
  std::size_t best = 0;
  for (BodyId id : base.body_ids()) {
    std::size_t lower = 0;
    std::size_t higher = 0;
    for (const ContactState& c : base.contacts()) {
      lower += c.a == id ? 1U : 0U;
      higher += c.b == id ? 1U : 0U;
    }
    const std::size_t score = lower + higher + (lower > 0 && higher > 0 ? 100U : 0U);
    if (base.body(id).value().type == BodyType::dynamic && score > best) {
      best = score;
      gone = id;
    }
  }
  ASSERT_GT(best, 0U) << "no dynamic body in a contact";
  World w = base;
  const StateDiff d = inject(w, frame_prefix(w, gone.value) + "present:-1");

  std::vector<std::string> want;
  want.push_back(line({"globals", 0, "body count", shown(std::uint64_t{base.body_count()}),
                       shown(std::uint64_t{base.body_count() - 1})}));
  want.push_back(line({"bodies", gone.value, "present", "present", "absent"}));
  for (const ContactState& c : base.contacts())
    if (c.a == gone || c.b == gone)
      want.push_back(
          line({"contacts", c.a.value, "contact[" + std::to_string(c.b.value) + "].present",
                "present", "absent"}));
  std::vector<std::string> got;
  for (const FieldDiff& f : d.fields)
    got.push_back(line(f));
  EXPECT_EQ(got, want);
  EXPECT_FALSE(w.contains(gone));
  EXPECT_EQ(w.body_count(), base.body_count() - 1);
  for (const ContactState& c : w.contacts())
    EXPECT_TRUE(c.a != gone && c.b != gone);
}

TEST(ApplyInjection, PresentPlusOneAddsAStaticCopy1000MetresAbove) {
  const World& base = arena();
  const BodyId player = base.body_ids()[5];
  const BodyState of = base.body(player).value();
  World probe = base;  // the next ID is whatever create_body would hand out now
  const BodyId next = probe.create_body({.type = BodyType::static_body}).value();

  World w = base;
  const StateDiff d = inject(w, frame_prefix(w, player.value) + "present:+1");
  std::vector<std::string> got;
  for (const FieldDiff& f : d.fields)
    got.push_back(line(f));
  const std::vector<std::string> want = {
      line({"globals", 0, "body count", shown(std::uint64_t{base.body_count()}),
            shown(std::uint64_t{base.body_count() + 1})}),
      line({"bodies", next.value, "present", "absent", "present"}),
  };
  EXPECT_EQ(got, want);

  const BodyState copy = w.body(next).value();
  EXPECT_EQ(copy.type, BodyType::static_body);
  EXPECT_FALSE(copy.awake);
  EXPECT_EQ(copy.shape, of.shape);
  EXPECT_EQ(shown(copy.position.x), shown(of.position.x));
  EXPECT_EQ(shown(copy.position.y), shown(of.position.y + Fixed::from_int(1000)));
  EXPECT_EQ(shown(copy.position.z), shown(of.position.z));
  EXPECT_EQ(copy.linear_velocity, Vec3{});
  EXPECT_EQ(shown(copy.friction), shown(of.friction));
  EXPECT_EQ(shown(copy.restitution), shown(of.restitution));
  EXPECT_EQ(copy.layer, of.layer);
  EXPECT_EQ(copy.mask, of.mask);
  EXPECT_EQ(copy.user_data, 0U);          // game logic must not take it for the original (a player)
  EXPECT_EQ(w.body(player).value(), of);  // the original is untouched
}

// ---- Refused: a clear message and the world unchanged ----

void expect_refused(const World& base, const Injection& i, const std::string& names) {
  World w = base;
  const std::vector<std::uint8_t> before = w.save();
  const Status s = apply_injection(w, i);
  EXPECT_FALSE(s.ok()) << i.text();
  EXPECT_NE(s.message().find(names), std::string::npos) << i.text() << " -> " << s.message();
  EXPECT_EQ(w.hashes(), base.hashes()) << i.text();
  EXPECT_EQ(w.save(), before) << i.text();
}

TEST(ApplyInjection, RefusedInjectionsLeaveTheWorldUnchanged) {
  const World& base = arena();
  const std::string at = std::to_string(base.frame()) + ":";
  expect_refused(base, spec(at + "999:position.y:1"), "no body with ID 999");

  // A pair that is not in the cache: two static bodies (the floor and a wall) never pair.
  const std::vector<BodyId> ids = base.body_ids();
  const std::uint32_t a = ids[0].value;
  const std::uint32_t b = ids[1].value;
  ASSERT_EQ(base.body(ids[1]).value().type, BodyType::static_body);
  for (const ContactState& c : base.contacts())
    ASSERT_FALSE(c.a.value == a && c.b.value == b);
  expect_refused(base,
                 spec(at + std::to_string(b) + ":contact[" + std::to_string(a) +
                      "].point[0].normal_impulse:1"),
                 "have no contact");

  // A point index at the pair's point count.
  bool found = false;
  for (const ContactState& c : base.contacts()) {
    if (c.point_count >= 4) continue;
    found = true;
    expect_refused(base,
                   spec(at + std::to_string(c.a.value) + ":contact[" + std::to_string(c.b.value) +
                        "].point[" + std::to_string(c.point_count) + "].normal_impulse:1"),
                   std::to_string(c.point_count) + " cached points");
    break;
  }
  EXPECT_TRUE(found) << "every contact has 4 points";

  const BodyId crate = ids.back();
  expect_refused(base, spec(at + std::to_string(crate.value) + ":orientation.w:0.5"),
                 "unit quaternion");
  const Fixed sleep = base.body(crate).value().sleep_time;
  expect_refused(
      base,
      spec(at + std::to_string(crate.value) + ":sleep_time:" + to_string(-(sleep + dec("0.5")))),
      "sleep time must be >= 0");
  ASSERT_EQ(base.body(ids[0]).value().type, BodyType::static_body);  // the floor
  expect_refused(base, spec(at + std::to_string(a) + ":awake:1"), "a static body cannot be awake");

  // The all-zero RNG state.
  World lone;
  ASSERT_TRUE(lone.rng().set_state({1, 0, 0, 0}));
  expect_refused(lone, spec("1:0:rng.state[0]:-1"), "all-zero RNG state");
  // Not through the parser: a field apply_injection itself must refuse.
  expect_refused(base, Injection{kFrame, crate.value, "position.q", "1"}, "unknown field");
  expect_refused(base, Injection{kFrame, crate.value, "awake", "2"}, "awake");
}

// ---- An injected world stays valid; the injected frame is the first to differ ----

TEST(ApplyInjection, FirstDifferingFrameIsTheInjectedOneAndTheStateStaysValid) {
  constexpr std::uint64_t at = 40;
  Scenario clean = new_arena();
  Scenario faulty = new_arena();
  const std::uint32_t crate = clean.world().body_ids().back().value;
  const std::uint32_t player = clean.player_body(2).value;
  const std::uint32_t wall = clean.world().body_ids()[1].value;
  const std::vector<Injection> injections = {
      spec(std::to_string(at) + ":" + std::to_string(crate) + ":position.y:0.001"),
      spec(std::to_string(at) + ":" + std::to_string(crate - 1) + ":present:-1"),
      spec(std::to_string(at) + ":" + std::to_string(player) + ":present:+1"),
      spec(std::to_string(at) + ":0:rng.state[1]:12345"),
      spec(std::to_string(at + 5) + ":" + std::to_string(wall) + ":user_data:7"),
  };
  const std::uint64_t wall_data = clean.world().body(BodyId{wall}).value().user_data;
  for (std::uint64_t f = 1; f <= at + 30; ++f) {
    step_scripted(clean);
    step_scripted(faulty);
    ASSERT_EQ(faulty.world().frame(), f);
    const Status s = apply_injections(faulty.world(), injections);
    ASSERT_TRUE(s.ok()) << "frame " << f << ": " << s.message();
    if (f < at) {
      ASSERT_EQ(clean.world().hashes(), faulty.world().hashes()) << "frame " << f;
    } else if (f == at) {
      EXPECT_NE(clean.world().hashes().total, faulty.world().hashes().total);
      EXPECT_FALSE(faulty.world().contains(BodyId{crate - 1}));
    }
    EXPECT_EQ(faulty.world().body(BodyId{wall}).value().user_data,
              f < at + 5 ? wall_data : wall_data + 7U)
        << "frame " << f;
    // Every injected state saves and restores to itself.
    World restored;
    ASSERT_TRUE(restored.restore(faulty.world().save()).ok()) << "frame " << f;
    ASSERT_EQ(restored.hashes(), faulty.world().hashes()) << "frame " << f;
  }
  // And steps on exactly like the world it came from.
  Scenario resumed = faulty;
  ASSERT_TRUE(resumed.world().restore(faulty.world().save()).ok());
  for (int i = 0; i < 20; ++i) {
    step_scripted(faulty);
    step_scripted(resumed);
    ASSERT_EQ(faulty.world().hashes(), resumed.world().hashes())
        << "frame " << faulty.world().frame();
  }
}

// ---- World::contacts() ----

TEST(WorldContacts, AscendingBoundedAndRestoredExactly) {
  const World& w = arena();
  const std::vector<ContactState> contacts = w.contacts();
  ASSERT_FALSE(contacts.empty());
  for (std::size_t i = 0; i < contacts.size(); ++i) {
    const ContactState& c = contacts[i];
    EXPECT_LT(c.a.value, c.b.value);
    EXPECT_LE(c.point_count, 4U);
    EXPECT_EQ(c.touching, c.point_count > 0);
    EXPECT_TRUE(w.contains(c.a) && w.contains(c.b));
    if (i > 0) {
      const ContactState& p = contacts[i - 1];
      EXPECT_TRUE(p.a < c.a || (p.a == c.a && p.b < c.b)) << "contact " << i;
    }
    for (std::size_t k = c.point_count; k < 4; ++k)
      EXPECT_EQ(c.points[k], ContactPointState{}) << "unused point " << k << " of contact " << i;
  }
  World restored;
  ASSERT_TRUE(restored.restore(w.save()).ok());
  EXPECT_EQ(restored.contacts(), contacts);
  // An injected impulse survives save and restore, as contacts() shows it.
  World injected = w;
  const ContactState c = touching_contact(w);
  ASSERT_TRUE(
      apply_injection(injected, spec(frame_prefix(w, c.a.value) + "contact[" +
                                     std::to_string(c.b.value) + "].point[0].tangent_impulse_1:1"))
          .ok());
  ASSERT_TRUE(restored.restore(injected.save()).ok());
  EXPECT_EQ(restored.contacts(), injected.contacts());
  EXPECT_NE(restored.contacts(), contacts);
}

}  // namespace
}  // namespace detsim
