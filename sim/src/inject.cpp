// Fault injection (inject.hpp). Parsing checks the field's name and the delta's form; applying
// changes a copy of the one thing touched (a body, the RNG state, a contact point, a joint, a
// particle group), checks it as restore() would, and only then writes it back, so a refused
// injection changes nothing.
#include <detsim/sim/inject.hpp>

#include <algorithm>
#include <charconv>
#include <optional>

#include <detsim/fixed/decimal.hpp>
#include <detsim/fixed/quat.hpp>

#include "body_fields.hpp"
#include "character_fields.hpp"
#include "joint_fields.hpp"
#include "shapes.hpp"
#include "state_io.hpp"
#include "vehicle_fields.hpp"
#include "world_state.hpp"

namespace detsim {
namespace {

/// A record's fields from its table (record_fields.hpp), with the delta each takes.
template <class T>
std::string record_fields_help(std::span<const sim_detail::RecordField<T>> fields) {
  using sim_detail::RecordFieldKind;
  std::string out;
  for (const sim_detail::RecordField<T>& f : fields) {
    std::string form = f.name;
    if (f.kind == RecordFieldKind::vec3) form += ".x|y|z";
    if (f.kind == RecordFieldKind::quat) form += ".w|x|y|z";
    if (f.kind == RecordFieldKind::flag) form += " (1 toggles)";
    if (f.kind == RecordFieldKind::u64 || f.kind == RecordFieldKind::u32) form += " (an integer)";
    out += (out.empty() ? "" : ", ") + form;
  }
  return out;
}

/// The field forms, for errors and --help: the body's motion fields from the field table, then
/// the forms that are not body fields. Built once.
const std::string& fields_help() {
  static const std::string help = [] {
    using sim_detail::FieldKind;
    std::string decimal, toggle, integer;
    const auto append = [](std::string& list, const std::string& form) {
      list += (list.empty() ? "" : ", ") + form;
    };
    for (const sim_detail::BodyField& f : sim_detail::body_fields()) {
      if (f.group != sim_detail::FieldGroup::motion) continue;
      const std::string name = f.name;
      switch (f.kind) {
        case FieldKind::vec3:
          append(decimal, name + ".x|y|z");
          break;
        case FieldKind::quat:
          append(decimal, name + ".w|x|y|z");
          break;
        case FieldKind::fixed:
          append(decimal, name);
          break;
        case FieldKind::flag:
          append(toggle, name);
          break;
        case FieldKind::u32:
        case FieldKind::u64:
          append(integer, name);
          break;
      }
    }
    return decimal + " (DELTA a decimal, added); " + toggle + " (DELTA 1 toggles); " + integer +
           " (DELTA an integer, added); present (DELTA -1 removes BODY, +1 adds a static copy of "
           "its shape 1000 m above); rng.state[0..3] (BODY 0, DELTA an integer, added mod 2^64); "
           "contact[OTHER].point[I].normal_impulse|tangent_impulse_1|tangent_impulse_2 (DELTA a "
           "decimal; contact[OTHER/S/T] for the contact of BODY's sub-shape S with OTHER's "
           "sub-shape T); joint[J].FIELD (BODY 0; FIELD a field of the joint as diff names it: " +
           record_fields_help(sim_detail::joint_fields()) +
           "); vehicle[V].FIELD and vehicle[V].wheel[K].FIELD (BODY 0; FIELD a field of the "
           "vehicle as diff names it: " +
           record_fields_help(sim_detail::vehicle_fields()) +
           "; of a wheel: " + record_fields_help(sim_detail::wheel_state_fields()) + ", " +
           record_fields_help(sim_detail::wheel_def_fields()) +
           "); character[C].FIELD (BODY 0; FIELD a field of the character as diff names it: " +
           record_fields_help(sim_detail::character_fields()) +
           "); particle_group[G].particle[I].position.x|y|z, "
           "particle_group[G].particle[I].velocity.x|y|z, particle_group[G].force.x|y|z, "
           "particle_group[G].sleep_time, particle_group[G].tether_impulse (BODY 0; DELTA a "
           "decimal, added), particle_group[G].awake (BODY 0; DELTA 1 toggles); game.NAME (BODY "
           "0; a field of the world's game state description, DELTA added at its width), "
           "game.byte[N] (BODY 0; DELTA an integer, added mod 256)";
  }();
  return help;
}

/// `number`: a decimal for a Fixed field, an integer for the others (a game state's field, whose
/// type only the world's description knows when the injection is applied).
enum class DeltaKind { fixed, toggle, integer, presence, number };

/// What a field name refers to, once parsed.
struct Target {
  DeltaKind kind = DeltaKind::fixed;
  enum class Part {
    body,
    rng,
    contact,
    joint,
    character,
    vehicle,
    particles,
    game
  } part = Part::body;
  /// vehicle: the table of `base`: the vehicle's own (0), a wheel's state (1) or definition (2)
  int table = 0;
  std::string base;             ///< "position", "sleep_time", "normal_impulse", ...
  int component = -1;           ///< x y z = 0 1 2, w = 3; the RNG word; -1: none
  std::uint32_t other = 0;      ///< contact: the other body
  std::uint32_t sub_body = 0;   ///< contact: BODY's sub-shape (compound part, surface triangle)
  std::uint32_t sub_other = 0;  ///< contact: OTHER's sub-shape
  std::size_t point = 0;        ///< contact: the point
  std::uint32_t joint = 0;      ///< joint, character: its ID
  std::uint32_t group = 0;      ///< particles: the group's ID
  std::optional<std::uint32_t> particle;  ///< particles: the particle (none: a group field)
};

/// A decimal without sign or leading zeros ("0" itself is fine).
std::optional<std::uint64_t> parse_u64(std::string_view text) {
  if (text.size() > 1 && text.front() == '0') return std::nullopt;
  std::uint64_t v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || ec != std::errc{} || end != text.data() + text.size()) return std::nullopt;
  return v;
}

std::optional<std::int64_t> parse_i64(std::string_view text) {
  if (text.size() > 1 && text.front() == '+' && text[1] != '-') text.remove_prefix(1);
  std::int64_t v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || ec != std::errc{} || end != text.data() + text.size()) return std::nullopt;
  return v;
}

/// "a[N]" -> N when `text` starts with `prefix` + "[", ends the index with "]"; `rest` gets what
/// follows.
std::optional<std::uint64_t> indexed(std::string_view text, std::string_view prefix,
                                     std::string_view& rest) {
  if (text.substr(0, prefix.size() + 1) != std::string(prefix) + "[") return std::nullopt;
  text.remove_prefix(prefix.size() + 1);
  const std::size_t close = text.find(']');
  if (close == std::string_view::npos) return std::nullopt;
  auto n = parse_u64(text.substr(0, close));
  rest = text.substr(close + 1);
  return n;
}

Expected<Target> parse_field(std::string_view field) {
  Target t;
  const auto unknown = [&] {
    return Status::error("unknown field \"" + std::string(field) + "\"; fields: " + fields_help());
  };
  if (field.starts_with("rng.")) {
    std::string_view rest;
    auto word = indexed(field.substr(4), "state", rest);
    if (!word || !rest.empty() || *word > 3) return unknown();
    t.part = Target::Part::rng;
    t.kind = DeltaKind::integer;
    t.component = static_cast<int>(*word);
    return t;
  }
  if (field.starts_with("contact[")) {
    // contact[OTHER] or contact[OTHER/SUB_BODY/SUB_OTHER] (what diff prints for sub-shapes).
    const std::size_t close = field.find(']');
    if (close == std::string_view::npos) return unknown();
    std::string_view inside = field.substr(8, close - 8);
    const std::string_view rest = field.substr(close + 1);
    std::optional<std::uint64_t> subs[2] = {0, 0};
    if (const std::size_t slash = inside.find('/'); slash != std::string_view::npos) {
      const std::string_view pair = inside.substr(slash + 1);
      const std::size_t second = pair.find('/');
      if (second == std::string_view::npos) return unknown();
      subs[0] = parse_u64(pair.substr(0, second));
      subs[1] = parse_u64(pair.substr(second + 1));
      inside = inside.substr(0, slash);
    }
    const auto other = parse_u64(inside);
    if (!other || *other == 0 || *other > 0xFFFFFFFFU || !rest.starts_with(".")) return unknown();
    for (const auto& sub : subs)
      if (!sub || *sub > 0xFFFFFFFFU) return unknown();
    t.sub_body = static_cast<std::uint32_t>(*subs[0]);
    t.sub_other = static_cast<std::uint32_t>(*subs[1]);
    std::string_view name;
    auto point = indexed(rest.substr(1), "point", name);
    if (!point || *point > 3 || !name.starts_with(".")) return unknown();
    name.remove_prefix(1);
    if (name != "normal_impulse" && name != "tangent_impulse_1" && name != "tangent_impulse_2")
      return unknown();
    t.part = Target::Part::contact;
    t.other = static_cast<std::uint32_t>(*other);
    t.point = static_cast<std::size_t>(*point);
    t.base = std::string(name);
    return t;
  }
  // joint[J].FIELD, character[C].FIELD, vehicle[V].FIELD: a field of the record's table
  // (record_fields.hpp), `text` being PREFIX[ID].FIELD.
  const auto record = [&]<class T>(std::string_view prefix, Target::Part part,
                                   std::span<const sim_detail::RecordField<T>> fields,
                                   std::string_view text) -> Expected<Target> {
    std::string_view rest;
    auto id = indexed(text, prefix, rest);
    if (!id || *id == 0 || *id > 0xFFFFFFFFU || !rest.starts_with(".")) return unknown();
    int component = -1;
    const sim_detail::RecordField<T>* f =
        sim_detail::parse_record_field(fields, rest.substr(1), component);
    if (f == nullptr) return unknown();
    using sim_detail::RecordFieldKind;
    t.part = part;
    t.joint = static_cast<std::uint32_t>(*id);
    t.base = f->name;
    t.component = component;
    t.kind = f->kind == RecordFieldKind::flag ? DeltaKind::toggle
             : f->kind == RecordFieldKind::u64 || f->kind == RecordFieldKind::u32
                 ? DeltaKind::integer
                 : DeltaKind::fixed;
    return t;
  };
  if (field.starts_with("joint["))
    return record("joint", Target::Part::joint, sim_detail::joint_fields(), field);
  if (field.starts_with("character["))
    return record("character", Target::Part::character, sim_detail::character_fields(), field);
  if (field.starts_with("vehicle[")) {
    // vehicle[V].FIELD, or vehicle[V].wheel[K].FIELD of the wheel's state or definition.
    std::string_view rest;
    auto id = indexed(field, "vehicle", rest);
    if (!id || *id == 0 || *id > 0xFFFFFFFFU || !rest.starts_with(".")) return unknown();
    rest.remove_prefix(1);
    if (rest.starts_with("wheel[")) {
      std::string_view name;
      auto wheel = indexed(rest, "wheel", name);
      if (!wheel || *wheel > 0xFFFFU || !name.starts_with(".")) return unknown();
      const std::string prefix =
          "vehicle[" + std::to_string(*id) + "].wheel[" + std::to_string(*wheel) + "]";
      const std::string inner = "wheel_state[1]" + std::string(name);
      auto t_state =
          record("wheel_state", Target::Part::vehicle, sim_detail::wheel_state_fields(), inner);
      if (t_state.ok()) {
        t.table = 1;
      } else if (auto t_def = record("wheel_state", Target::Part::vehicle,
                                     sim_detail::wheel_def_fields(), inner);
                 t_def.ok()) {
        t.table = 2;
      } else {
        return unknown();
      }
      t.joint = static_cast<std::uint32_t>(*id);
      t.particle = static_cast<std::uint32_t>(*wheel);
      return t;
    }
    auto out = record("vehicle", Target::Part::vehicle, sim_detail::vehicle_fields(), field);
    if (out.ok()) t.table = 0;
    return out;
  }
  if (field.starts_with("particle_group[")) {
    // particle_group[G].particle[I].position|velocity.C, or a group field: force.C, sleep_time,
    // tether_impulse, awake.
    std::string_view rest;
    auto group = indexed(field, "particle_group", rest);
    if (!group || *group == 0 || *group > 0xFFFFFFFFU || !rest.starts_with(".")) return unknown();
    rest.remove_prefix(1);
    t.part = Target::Part::particles;
    t.group = static_cast<std::uint32_t>(*group);
    if (rest.starts_with("particle[")) {
      std::string_view name;
      auto particle = indexed(rest, "particle", name);
      if (!particle || *particle > 0xFFFFFFFFU || !name.starts_with(".")) return unknown();
      name.remove_prefix(1);
      t.particle = static_cast<std::uint32_t>(*particle);
      rest = name;
    }
    std::string_view base = rest;
    int component = -1;
    if (const std::size_t dot = rest.rfind('.');
        dot != std::string_view::npos && dot + 2 == rest.size()) {
      const char c = rest.back();
      base = rest.substr(0, dot);
      component = c >= 'x' && c <= 'z' ? c - 'x' : -2;
    }
    const bool vector = t.particle ? base == "position" || base == "velocity" : base == "force";
    const bool scalar = !t.particle && (base == "sleep_time" || base == "tether_impulse");
    const bool flag = !t.particle && base == "awake";
    if (vector ? component < 0 : component != -1 || !(scalar || flag)) return unknown();
    t.base = std::string(base);
    t.component = component;
    t.kind = flag ? DeltaKind::toggle : DeltaKind::fixed;
    return t;
  }
  if (field.starts_with("game.")) {
    // game.byte[N] or game.NAME, a field of the world's description (World::describe_game_state).
    const std::string_view name = field.substr(5);
    t.part = Target::Part::game;
    std::string_view rest;
    if (auto byte = indexed(name, "byte", rest); byte && rest.empty()) {
      if (*byte >= max_game_state_size) return unknown();
      t.point = static_cast<std::size_t>(*byte);
      t.kind = DeltaKind::integer;
      return t;
    }
    if (name.empty()) return unknown();
    t.base = std::string(name);
    t.kind = DeltaKind::number;
    return t;
  }
  if (field == "present") {
    t.base = "present";
    t.kind = DeltaKind::presence;
    return t;
  }
  // A motion field of the body table (body_fields.hpp), whole or one component of it.
  std::string_view base = field;
  int component = -1;
  const std::size_t dot = field.rfind('.');
  if (dot != std::string_view::npos && dot + 2 == field.size()) {
    const char c = field.back();
    base = field.substr(0, dot);
    component = c == 'w' ? 3 : c >= 'x' && c <= 'z' ? c - 'x' : -2;
  }
  const sim_detail::BodyField* f = sim_detail::find_body_field(base);
  if (f == nullptr || f->group != sim_detail::FieldGroup::motion) return unknown();
  using sim_detail::FieldKind;
  const bool whole = f->kind != FieldKind::vec3 && f->kind != FieldKind::quat;
  if (whole ? component != -1 : component < 0 || (f->kind == FieldKind::vec3 && component == 3))
    return unknown();
  t.base = f->name;
  t.component = component;
  t.kind = f->kind == FieldKind::flag                               ? DeltaKind::toggle
           : f->kind == FieldKind::u64 || f->kind == FieldKind::u32 ? DeltaKind::integer
                                                                    : DeltaKind::fixed;
  return t;
}

Status check_delta(const Target& t, std::string_view delta) {
  switch (t.kind) {
    case DeltaKind::fixed: {
      const ParseResult r = Fixed::parse(delta);
      if (!r) return Status::error("DELTA \"" + std::string(delta) + "\": " + describe(r.error));
      return Status::success();
    }
    case DeltaKind::toggle:
      if (delta != "1")
        return Status::error("DELTA for " + t.base + " must be 1 (toggle the flag)");
      return Status::success();
    case DeltaKind::integer:
      if (!parse_i64(delta))
        return Status::error("DELTA \"" + std::string(delta) + "\" is not a 64-bit integer");
      return Status::success();
    case DeltaKind::presence:
      if (delta != "-1" && delta != "+1" && delta != "1")
        return Status::error("DELTA for present must be -1 (remove the body) or +1 (add a copy)");
      return Status::success();
    case DeltaKind::number:
      if (!parse_i64(delta) && !Fixed::parse(delta))
        return Status::error("DELTA \"" + std::string(delta) + "\" is not a number");
      return Status::success();
  }
  return Status::success();
}

/// Adds `delta` to a byte or a described field of the game state (wrapping at the field's width;
/// a Fixed field saturating like Fixed's addition).
Status change_game_state(sim_detail::WorldState& s, const Target& t, std::string_view delta) {
  std::vector<std::uint8_t>& game = s.game;
  if (t.base.empty()) {  // game.byte[N]
    if (t.point >= game.size())
      return Status::error("the game state has " + std::to_string(game.size()) +
                           " bytes, no byte " + std::to_string(t.point));
    game[t.point] =
        static_cast<std::uint8_t>(game[t.point] + static_cast<std::uint64_t>(*parse_i64(delta)));
    return Status::success();
  }
  const auto f = std::find_if(s.game_fields.begin(), s.game_fields.end(),
                              [&t](const GameField& g) { return g.name == t.base; });
  if (f == s.game_fields.end())
    return Status::error("the world's game state description has no field \"" + t.base + "\"");
  const std::size_t size = game_field_size(f->type);
  if (std::size_t{f->offset} + size > game.size())
    return Status::error("field \"" + t.base + "\" ends past the game state (" +
                         std::to_string(game.size()) + " bytes)");
  std::uint64_t raw = 0;
  for (std::size_t k = 0; k < size; ++k)
    raw |= std::uint64_t{game[f->offset + k]} << (8 * k);
  if (f->type == GameFieldType::fixed) {
    const ParseResult d = Fixed::parse(delta);
    if (!d) return Status::error("DELTA \"" + std::string(delta) + "\": " + describe(d.error));
    raw = static_cast<std::uint64_t>(
        (Fixed::from_raw(static_cast<std::int64_t>(raw)) + d.value).raw());
  } else {
    const auto d = parse_i64(delta);
    if (!d)
      return Status::error("DELTA \"" + std::string(delta) +
                           "\" for an integer field must be an integer");
    raw += static_cast<std::uint64_t>(*d);
  }
  for (std::size_t k = 0; k < size; ++k)
    game[f->offset + k] = static_cast<std::uint8_t>(raw >> (8 * k));
  return Status::success();
}

Fixed& field_ref(Vec3& v, int c) {
  return c == 0 ? v.x : c == 1 ? v.y : v.z;
}
Fixed& field_ref(Quat& q, int c) {
  return c == 0 ? q.x : c == 1 ? q.y : c == 2 ? q.z : q.w;
}

// Changes a copy of the body's field, then checks it as restore() would.
Status change_body(BodyState& b, const Target& t, std::string_view delta) {
  const sim_detail::BodyField& f = *sim_detail::find_body_field(t.base);
  switch (f.kind) {
    case sim_detail::FieldKind::fixed:
      b.*f.fixed += Fixed::parse(delta).value;
      break;
    case sim_detail::FieldKind::vec3:
      field_ref(b.*f.vec3, t.component) += Fixed::parse(delta).value;
      break;
    case sim_detail::FieldKind::quat:
      field_ref(b.*f.quat, t.component) += Fixed::parse(delta).value;
      break;
    case sim_detail::FieldKind::u32:
      b.*f.u32 += static_cast<std::uint32_t>(*parse_i64(delta));  // modulo 2^32
      break;
    case sim_detail::FieldKind::u64:
      b.*f.u64 += static_cast<std::uint64_t>(*parse_i64(delta));  // modulo 2^64
      break;
    case sim_detail::FieldKind::flag:
      b.*f.flag = !(b.*f.flag);
      break;
  }
  if (auto e = sim_detail::check_body_record(b); !e.empty())
    return Status::error("body " + std::to_string(b.id.value) +
                         ": the change would leave an invalid state: " + e);
  return Status::success();
}

// Changes a copy of a record's field (a joint's, a character's); the caller checks it as
// restore() would before writing it back.
template <class T>
void change_record(std::span<const sim_detail::RecordField<T>> fields, T& x, const Target& t,
                   std::string_view delta) {
  const sim_detail::RecordField<T>& f = *sim_detail::find_record_field(fields, t.base);
  switch (f.kind) {
    case sim_detail::RecordFieldKind::fixed:
      f.fixed(x) += Fixed::parse(delta).value;
      break;
    case sim_detail::RecordFieldKind::vec3:
      field_ref(f.vec3(x), t.component) += Fixed::parse(delta).value;
      break;
    case sim_detail::RecordFieldKind::quat:
      field_ref(f.quat(x), t.component) += Fixed::parse(delta).value;
      break;
    case sim_detail::RecordFieldKind::u32:
      f.u32(x) += static_cast<std::uint32_t>(*parse_i64(delta));  // modulo 2^32
      break;
    case sim_detail::RecordFieldKind::u64:
      f.u64(x) += static_cast<std::uint64_t>(*parse_i64(delta));  // modulo 2^64
      break;
    case sim_detail::RecordFieldKind::flag:
      f.flag(x) = !f.flag(x);
      break;
  }
}

// Changes one field of a particle group (a particle's or the group's own), checks the group as
// restore() would, and only then writes the change: a copy of the one vector or value touched, so
// a refused change leaves the group as it was.
Status change_group(const sim_detail::WorldState& s, sim_detail::ParticleGroup& g, const Target& t,
                    std::string_view delta) {
  const Fixed d = t.kind == DeltaKind::fixed ? Fixed::parse(delta).value : Fixed::zero();
  // The one value touched, by reference, and its old value to put back if refused.
  const auto attempt = [&](auto& value, auto changed) -> Status {
    const auto old = value;
    value = changed;
    if (auto e = sim_detail::check_particle_record(s, g); !e.empty()) {
      value = old;
      return Status::error("particle group " + std::to_string(g.id.value) +
                           ": the change would leave an invalid state: " + e);
    }
    return Status::success();
  };
  if (t.particle) {
    Vec3& v = t.base == "position" ? g.positions[*t.particle] : g.velocities[*t.particle];
    Vec3 changed = v;
    field_ref(changed, t.component) += d;
    return attempt(v, changed);
  }
  if (t.base == "force") {
    Vec3 changed = g.force;
    field_ref(changed, t.component) += d;
    return attempt(g.force, changed);
  }
  if (t.base == "sleep_time") return attempt(g.sleep_time, g.sleep_time + d);
  if (t.base == "tether_impulse") return attempt(g.tether_impulse, g.tether_impulse + d);
  return attempt(g.awake, !g.awake);  // awake
}

Status add_copy(World& world, const BodyState& of) {
  if (!sim_detail::shape_kind(of.shape.type).bounded)
    return Status::error("body " + std::to_string(of.id.value) + " is a " +
                         sim_detail::shape_kind(of.shape.type).name +
                         ": a copy above it would still touch everything");
  BodyDef def;
  def.type = BodyType::static_body;
  def.shape = of.shape;
  def.position = of.position;
  def.position.y += Fixed::from_int(1000);
  def.orientation = of.orientation;
  def.friction = of.friction;
  def.restitution = of.restitution;
  def.layer = of.layer;
  def.mask = of.mask;
  def.sensor = of.sensor;  // user_data stays 0: game logic must not take it for the original
  auto id = world.create_body(def);
  if (!id)
    return Status::error("adding a copy of body " + std::to_string(of.id.value) + ": " +
                         id.message());
  return Status::success();
}

}  // namespace

std::string Injection::text() const {
  return std::to_string(frame) + ":" + std::to_string(body) + ":" + field + ":" + delta;
}

Status apply_injections(World& world, std::span<const Injection> injections) {
  for (const Injection& i : injections) {
    if (i.frame != world.frame()) continue;
    if (Status s = apply_injection(world, i); !s) return s;
  }
  return Status::success();
}

std::string_view injection_fields_help() noexcept {
  return fields_help();
}

Expected<Injection> parse_injection(std::string_view spec) {
  const std::string where = "--inject \"" + std::string(spec) + "\": ";
  std::string_view parts[4];
  std::string_view rest = spec;
  for (int i = 0; i < 3; ++i) {
    const std::size_t colon = rest.find(':');
    if (colon == std::string_view::npos)
      return Status::error(where + "expected FRAME:BODY:FIELD:DELTA (four parts separated by ':')");
    parts[i] = rest.substr(0, colon);
    rest.remove_prefix(colon + 1);
  }
  parts[3] = rest;
  Injection out;
  auto frame = parse_u64(parts[0]);
  if (!frame || *frame == 0)
    return Status::error(where + "FRAME \"" + std::string(parts[0]) +
                         "\" must be a frame number >= 1 (the state after that step)");
  auto body = parse_u64(parts[1]);
  if (!body || *body > 0xFFFFFFFFU)
    return Status::error(where + "BODY \"" + std::string(parts[1]) + "\" must be a body ID");
  auto target = parse_field(parts[2]);
  if (!target) return Status::error(where + target.message());
  if (target->part == Target::Part::rng && *body != 0)
    return Status::error(where + "BODY must be 0 for an RNG field");
  if (target->part == Target::Part::joint && *body != 0)
    return Status::error(where + "BODY must be 0 for a joint field (the joint is named in it)");
  if (target->part == Target::Part::vehicle && *body != 0)
    return Status::error(where + "BODY must be 0 for a vehicle field (the vehicle is named in it)");
  if (target->part == Target::Part::character && *body != 0)
    return Status::error(where +
                         "BODY must be 0 for a character field (the character is named in it)");
  if (target->part == Target::Part::game && *body != 0)
    return Status::error(where + "BODY must be 0 for a field of the game state");
  if (target->part == Target::Part::particles && *body != 0)
    return Status::error(where +
                         "BODY must be 0 for a particle group field (the group is named in it)");
  if ((target->part == Target::Part::body || target->part == Target::Part::contact) && *body == 0)
    return Status::error(where + "BODY must be a body ID (IDs start at 1)");
  if (target->part == Target::Part::contact && target->other == *body)
    return Status::error(where + "a contact is between BODY and another body, not itself");
  if (Status s = check_delta(target.value(), parts[3]); !s)
    return Status::error(where + s.message());
  out.frame = *frame;
  out.body = static_cast<std::uint32_t>(*body);
  out.field = std::string(parts[2]);
  out.delta = std::string(parts[3]);
  return out;
}

Status apply_injection(World& world, const Injection& injection) {
  const std::string where = "inject " + injection.text() + ": ";
  auto parsed = parse_field(injection.field);
  if (!parsed) return Status::error(where + parsed.message());
  const Target& t = parsed.value();
  if (Status st = check_delta(t, injection.delta); !st) return Status::error(where + st.message());
  sim_detail::WorldState& s = *world.s_;

  if (t.part == Target::Part::rng) {
    Rng::State state = s.rng.state();
    state[static_cast<std::size_t>(t.component)] +=
        static_cast<std::uint64_t>(*parse_i64(injection.delta));
    if (!s.rng.set_state(state))
      return Status::error(where + "the change would leave the all-zero RNG state");
    return Status::success();
  }

  if (t.part == Target::Part::game) {
    if (Status st = change_game_state(s, t, injection.delta); !st)
      return Status::error(where + st.message());
    return Status::success();
  }

  if (t.part == Target::Part::joint) {
    const std::ptrdiff_t j = s.find_joint(t.joint);
    if (j < 0) return Status::error(where + "no joint with ID " + std::to_string(t.joint));
    JointState changed = s.joints[static_cast<std::size_t>(j)];
    change_record(sim_detail::joint_fields(), changed, t, injection.delta);
    if (auto e = sim_detail::check_joint_record(s, changed); !e.empty())
      return Status::error(where + "joint " + std::to_string(t.joint) +
                           ": the change would leave an invalid state: " + e);
    s.joints[static_cast<std::size_t>(j)] = changed;
    return Status::success();
  }

  if (t.part == Target::Part::vehicle) {
    const std::ptrdiff_t k = s.find_vehicle(t.joint);
    if (k < 0) return Status::error(where + "no vehicle with ID " + std::to_string(t.joint));
    VehicleState changed = s.vehicles[static_cast<std::size_t>(k)];
    if (t.table != 0 && *t.particle >= changed.wheels.size())
      return Status::error(where + "vehicle " + std::to_string(t.joint) + " has " +
                           std::to_string(changed.wheels.size()) + " wheels, not wheel " +
                           std::to_string(*t.particle));
    if (t.table == 0) change_record(sim_detail::vehicle_fields(), changed, t, injection.delta);
    if (t.table == 1)
      change_record(sim_detail::wheel_state_fields(), changed.wheels[*t.particle], t,
                    injection.delta);
    if (t.table == 2)
      change_record(sim_detail::wheel_def_fields(), changed.def.wheels[*t.particle], t,
                    injection.delta);
    if (auto e = sim_detail::check_vehicle_record(s, changed); !e.empty())
      return Status::error(where + "vehicle " + std::to_string(t.joint) +
                           ": the change would leave an invalid state: " + e);
    s.vehicles[static_cast<std::size_t>(k)] = changed;
    return Status::success();
  }

  if (t.part == Target::Part::character) {
    const std::ptrdiff_t k = s.find_character(t.joint);
    if (k < 0) return Status::error(where + "no character with ID " + std::to_string(t.joint));
    CharacterState changed = s.characters[static_cast<std::size_t>(k)];
    change_record(sim_detail::character_fields(), changed, t, injection.delta);
    if (auto e = sim_detail::check_character_record(s, changed); !e.empty())
      return Status::error(where + "character " + std::to_string(t.joint) +
                           ": the change would leave an invalid state: " + e);
    s.characters[static_cast<std::size_t>(k)] = changed;
    return Status::success();
  }

  if (t.part == Target::Part::particles) {
    const std::ptrdiff_t k = s.find_group(t.group);
    if (k < 0) return Status::error(where + "no particle group with ID " + std::to_string(t.group));
    sim_detail::ParticleGroup& group = s.particle_groups[static_cast<std::size_t>(k)];
    if (t.particle && *t.particle >= group.size())
      return Status::error(where + "particle group " + std::to_string(t.group) + " has " +
                           std::to_string(group.size()) + " particles (0 .. " +
                           std::to_string(group.size() - 1) + "), not particle " +
                           std::to_string(*t.particle));
    if (Status st = change_group(s, group, t, injection.delta); !st)
      return Status::error(where + st.message());
    return Status::success();
  }

  const std::ptrdiff_t index = s.find(injection.body);
  if (index < 0) return Status::error(where + "no body with ID " + std::to_string(injection.body));
  BodyState& body = s.bodies[static_cast<std::size_t>(index)];

  if (t.part == Target::Part::contact) {
    // The pair is stored lower ID first: BODY's sub-shape is sub_a when BODY is the lower.
    const bool body_first = injection.body < t.other;
    const std::uint32_t a = body_first ? injection.body : t.other;
    const std::uint32_t b = body_first ? t.other : injection.body;
    const std::uint32_t sub_a = body_first ? t.sub_body : t.sub_other;
    const std::uint32_t sub_b = body_first ? t.sub_other : t.sub_body;
    auto it = std::find_if(s.contacts.begin(), s.contacts.end(), [&](const sim_detail::Contact& c) {
      return c.a == a && c.b == b && c.sub_a == sub_a && c.sub_b == sub_b;
    });
    const std::string subs = sub_a == 0 && sub_b == 0 ? ""
                                                      : " (sub-shapes " + std::to_string(sub_a) +
                                                            " and " + std::to_string(sub_b) + ")";
    if (it == s.contacts.end()) {
      // Name the sub-shape pairs the bodies do have, so the fix is one look away.
      std::string have;
      for (const sim_detail::Contact& c : s.contacts) {
        if (c.a != a || c.b != b) continue;
        have += (have.empty() ? "" : ", ") + std::string("contact[") +
                std::to_string(body_first ? b : a) + "/" +
                std::to_string(body_first ? c.sub_a : c.sub_b) + "/" +
                std::to_string(body_first ? c.sub_b : c.sub_a) + "]";
      }
      return Status::error(where + "bodies " + std::to_string(a) + " and " + std::to_string(b) +
                           " have no contact" + subs +
                           (have.empty() ? "" : "; their contacts: " + have));
    }
    if (t.point >= it->point_count)
      return Status::error(where + "the contact of " + std::to_string(a) + " and " +
                           std::to_string(b) + subs + " has " + std::to_string(it->point_count) +
                           " cached points");
    sim_detail::CachedPoint& p = it->cached[t.point];
    const Fixed d = Fixed::parse(injection.delta).value;
    if (t.base == "normal_impulse") p.normal_impulse += d;
    if (t.base == "tangent_impulse_1") p.tangent_impulse_1 += d;
    if (t.base == "tangent_impulse_2") p.tangent_impulse_2 += d;
    return Status::success();
  }

  if (t.kind == DeltaKind::presence) {
    if (injection.delta != "-1") {
      if (Status st = add_copy(world, body); !st) return Status::error(where + st.message());
      return Status::success();
    }
    // Removed as a fault, not as a game action: nothing else notices (no wake, no events).
    const std::uint32_t id = injection.body;
    std::erase_if(s.contacts,
                  [id](const sim_detail::Contact& c) { return c.a == id || c.b == id; });
    s.bodies.erase(s.bodies.begin() + index);
    // No character may stand on a body that is gone, no vehicle drive one: a chassis takes its
    // vehicle with it.
    sim_detail::forget_ground(s, BodyId{id});
    sim_detail::forget_vehicles_of(s, BodyId{id});
    return Status::success();
  }

  BodyState changed = body;
  if (Status st = change_body(changed, t, injection.delta); !st)
    return Status::error(where + st.message());
  body = changed;
  return Status::success();
}

}  // namespace detsim
