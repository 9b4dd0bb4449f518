// The canonical state encoding (docs/STATE.md): the container of sections, the World's sections
// (globals, rng, bodies in state_bodies.cpp, contacts, joints in state_joints.cpp, characters in
// state_characters.cpp), save, restore
// and the hashes.
//
// A World's state is one list of sections, each with its name, version and length; the World's
// sections are described once, in kSections below, and save, restore and the hashes walk that
// list. Writer and reader of each section sit side by side so that a field added to one is seen
// missing from the other. The restore reads into a scratch WorldState and validates every field
// before the world is replaced, so bad bytes change nothing; it accepts only canonical bytes (the
// shortest vars, sets in first-use order, flags that match their values), so a state has exactly
// one encoding.
#include <algorithm>
#include <array>
#include <iterator>
#include <string_view>

#include <detsim/core/hash.hpp>

#include "collide.hpp"
#include "shapes.hpp"
#include "state_io.hpp"

namespace detsim {

namespace sim_detail {

namespace {

constexpr std::uint32_t kMagic = 0x4D495344;  // "DSIM" read as little-endian bytes
constexpr std::uint32_t kVersion = state_encoding_version;

// Smallest encoding of a contact, to bound the count by the bytes that remain before allocating.
constexpr std::size_t kMinContactBytes = 1 + 1 + 1;

// A contact's point byte: the count in bits 0-2, the reported flag, and whether the contact's
// sub-shapes follow (they do when either is not 0).
constexpr std::uint8_t kPointCountMask = 7;
constexpr std::uint8_t kReported = 8;
constexpr std::uint8_t kSubShapes = 16;

void write_def(const WorldDef& d, ByteWriter& w) {
  w.vec3(d.gravity);
  w.fixed(d.dt);
  w.u32(d.substeps);
  w.u32(d.iterations);
  w.u64(d.seed);
  w.fixed(d.max_linear_speed);
  w.fixed(d.max_angular_speed);
  w.fixed(d.contact_hertz);
  w.fixed(d.contact_damping_ratio);
  w.fixed(d.contact_push_max);
  w.fixed(d.restitution_threshold);
  w.fixed(d.linear_slop);
  w.fixed(d.speculative_distance);
  w.boolean(d.enable_sleep);
  w.fixed(d.sleep_linear_speed);
  w.fixed(d.sleep_angular_speed);
  w.fixed(d.time_to_sleep);
}

WorldDef read_def(ByteReader& r) {
  WorldDef d;
  d.gravity = r.vec3("gravity");
  d.dt = r.fixed("dt");
  d.substeps = r.u32("substeps");
  d.iterations = r.u32("iterations");
  d.seed = r.u64("seed");
  d.max_linear_speed = r.fixed("max linear speed");
  d.max_angular_speed = r.fixed("max angular speed");
  d.contact_hertz = r.fixed("contact hertz");
  d.contact_damping_ratio = r.fixed("contact damping ratio");
  d.contact_push_max = r.fixed("contact push max");
  d.restitution_threshold = r.fixed("restitution threshold");
  d.linear_slop = r.fixed("linear slop");
  d.speculative_distance = r.fixed("speculative distance");
  d.enable_sleep = r.boolean("enable sleep");
  d.sleep_linear_speed = r.fixed("sleep linear speed");
  d.sleep_angular_speed = r.fixed("sleep angular speed");
  d.time_to_sleep = r.fixed("time to sleep");
  return d;
}

// ---- Contacts ----

// A feature (collide_util.hpp and geometry/convex.hpp: index bits 0-7, kind in bits 8-9, index
// bits 8-13 in bits 10-15) is written as index * 4 + kind.
std::uint32_t pack_feature(std::uint32_t f) noexcept {
  const std::uint32_t index = (f & 0xFFU) | ((f >> 10) << 8);
  return (index << 2) | ((f >> 8) & 3U);
}
std::uint32_t unpack_feature(std::uint32_t v) noexcept {
  const std::uint32_t index = v >> 2;
  return (index & 0xFFU) | ((v & 3U) << 8) | ((index >> 8) << 10);
}
constexpr std::uint32_t kMaxPackedFeature = (0x3FFFU << 2) | 3U;

Contact read_contact(ByteReader& r, std::uint32_t previous_a) {
  Contact c;
  const std::size_t a_at = r.offset();
  const std::uint32_t a_step = r.var32("contact body a step");
  if (r.ok() && a_step > 0xFFFFFFFFU - previous_a)
    r.fail_at(a_at, "contact body a step", "an ID below 2^32");
  c.a = previous_a + a_step;
  const std::size_t b_at = r.offset();
  const std::uint32_t b_step = r.var32("contact body b - a");
  if (r.ok() && (b_step == 0 || b_step > 0xFFFFFFFFU - c.a))
    r.fail_at(b_at, "contact body b - a", "at least 1 (a < b) and an ID below 2^32");
  c.b = c.a + b_step;
  const std::size_t points_at = r.offset();
  const std::uint8_t points = r.u8("contact points");
  if ((points & ~(kPointCountMask | kReported | kSubShapes)) != 0 || (points & kPointCountMask) > 4)
    r.fail_at(points_at, "contact points",
              "a count of 0-4 in bits 0-2, bit 3 (reported) and bit 4 (sub-shapes follow)");
  c.point_count = points & kPointCountMask;
  c.touching = c.point_count > 0;
  c.reported = (points & kReported) != 0;
  if ((points & kSubShapes) != 0) {
    c.sub_a = r.var32("contact sub-shape a");
    const std::size_t sub_b_at = r.offset();
    c.sub_b = r.var32("contact sub-shape b");
    if (r.ok() && c.sub_a == 0 && c.sub_b == 0)
      r.fail_at(sub_b_at, "contact sub-shapes", "not both 0 when bit 4 says they follow");
  }
  for (std::size_t p = 0; p < c.point_count && r.ok(); ++p) {
    std::uint32_t feature = 0;
    for (int side = 0; side < 2; ++side) {
      const std::size_t at = r.offset();
      const std::uint32_t v = r.var32("contact feature");
      if (v > kMaxPackedFeature) r.fail_at(at, "contact feature", "index * 4 + kind, index < 2^14");
      feature |= unpack_feature(v) << (16 * side);
    }
    c.cached[p].feature = feature;
    c.cached[p].normal_impulse = r.var_fixed("contact normal impulse");
    c.cached[p].tangent_impulse_1 = r.var_fixed("contact tangent impulse");
    c.cached[p].tangent_impulse_2 = r.var_fixed("contact tangent impulse");
  }
  return c;
}

}  // namespace

void write_globals(const WorldState& s, ByteWriter& w) {
  w.u64(s.frame);
  w.u32(s.next_id);
  write_def(s.def, w);
}

void write_contact(const Contact& c, std::uint32_t previous_a, ByteWriter& w) {
  w.var(c.a - previous_a);
  w.var(c.b - c.a);
  const bool subs = c.sub_a != 0 || c.sub_b != 0;
  w.u8(static_cast<std::uint8_t>(c.point_count | (c.reported ? kReported : 0U) |
                                 (subs ? kSubShapes : 0U)));
  if (subs) {
    w.var(c.sub_a);
    w.var(c.sub_b);
  }
  for (std::size_t p = 0; p < c.point_count; ++p) {
    const std::uint32_t f = c.cached[p].feature;
    w.var(pack_feature(f & 0xFFFFU));
    w.var(pack_feature(f >> 16));
    w.var_fixed(c.cached[p].normal_impulse);
    w.var_fixed(c.cached[p].tangent_impulse_1);
    w.var_fixed(c.cached[p].tangent_impulse_2);
  }
}

namespace {

void write_rng(const Rng& rng, ByteWriter& w) {
  for (const std::uint64_t word : rng.state())
    w.u64(word);
}

void write_contacts(const WorldState& s, ByteWriter& w) {
  w.u32(static_cast<std::uint32_t>(s.contacts.size()));
  std::uint32_t previous_a = 0;
  for (const Contact& c : s.contacts) {
    write_contact(c, previous_a, w);
    previous_a = c.a;
  }
}

void write_rng_section(const WorldState& s, ByteWriter& w) {
  write_rng(s.rng, w);
}

bool read_globals(std::span<const std::uint8_t>, ByteReader& r, WorldState& s, std::string& error) {
  s.frame = r.u64("frame");
  const std::size_t next_id_at = r.offset();
  s.next_id = r.u32("next body id");
  if (r.ok() && s.next_id == 0) {
    error = "byte " + std::to_string(next_id_at) + ": next body ID must be >= 1";
    return false;
  }
  const std::size_t def_at = r.offset();
  s.def = read_def(r);
  if (!r.ok()) return false;
  if (auto e = check_world_def(s.def); !e.empty()) {
    error = "byte " + std::to_string(def_at) + ": world definition: " + e;
    return false;
  }
  return true;
}

bool read_rng(std::span<const std::uint8_t>, ByteReader& r, WorldState& s, std::string& error) {
  Rng::State rng{};
  const std::size_t rng_at = r.offset();
  for (std::uint64_t& word : rng)
    word = r.u64("rng state");
  if (r.ok() && !s.rng.set_state(rng)) {
    error = "byte " + std::to_string(rng_at) + ": rng state is all zero";
    return false;
  }
  return r.ok();
}

// A contact's sub-shapes name parts that its bodies' shapes have ("" when they do).
std::string check_sub_shapes(const WorldState& s, const Contact& c) {
  for (const auto& [id, sub] : {std::pair{c.a, c.sub_a}, std::pair{c.b, c.sub_b}}) {
    const BodyState& body = s.bodies[static_cast<std::size_t>(s.find(id))];
    const std::uint32_t count = sub_shape_count(body.shape, s.geometry(body.shape));
    if (sub >= count)
      return "sub-shape " + std::to_string(sub) + " of body " + std::to_string(id) + ", whose " +
             shape_kind(body.shape.type).name + " has " + std::to_string(count) +
             (count == 1 ? " (the whole shape: 0)" : "");
  }
  return {};
}

bool read_contacts(std::span<const std::uint8_t>, ByteReader& r, WorldState& s,
                   std::string& error) {
  const auto failed_at = [&](std::size_t at, const std::string& message) {
    error = "byte " + std::to_string(at) + ": " + message;
    return false;
  };
  const std::size_t contact_count_at = r.offset();
  const std::uint32_t contact_count = r.u32("contact count");
  if (r.ok() && contact_count > r.remaining() / kMinContactBytes)
    return failed_at(contact_count_at, "contact count " + std::to_string(contact_count) +
                                           " exceeds what the data can hold");
  s.contacts.clear();
  s.contacts.reserve(contact_count);
  std::uint32_t previous_a = 0;
  for (std::uint32_t i = 0; i < contact_count && r.ok(); ++i) {
    const std::size_t at = r.offset();
    Contact c = read_contact(r, previous_a);
    if (!r.ok()) break;
    const std::string where =
        "contact (" + std::to_string(c.a) + ", " + std::to_string(c.b) + "): ";
    if (s.find(c.a) < 0 || s.find(c.b) < 0)
      return failed_at(at, where + "names a body that does not exist");
    if (!s.contacts.empty() && !contact_before(s.contacts.back(), c))
      return failed_at(at, where + "contacts must be unique and ascending by (a, b, sub_a, sub_b)");
    const bool same_pair =
        !s.contacts.empty() && c.a == s.contacts.back().a && c.b == s.contacts.back().b;
    if (same_pair && c.reported != s.contacts.back().reported)
      return failed_at(at, where + "the contacts of one body pair must share its reported flag");
    if (auto e = check_sub_shapes(s, c); !e.empty()) return failed_at(at, where + e);
    if (c.reported && !c.touching)
      return failed_at(at, where + "reported as touching without contact points");
    s.contacts.push_back(c);
    previous_a = c.a;
  }
  return r.ok();
}

void write_game(const WorldState& s, ByteWriter& w) {
  w.raw(s.game);
}

bool read_game(std::span<const std::uint8_t>, ByteReader& r, WorldState& s, std::string& error) {
  // The payload is the game's bytes as they are: the section's whole length.
  const std::size_t at = r.offset();
  const std::size_t size = r.remaining();
  if (size == 0 || size > max_game_state_size) {
    error = "byte " + std::to_string(at) + ": " + std::to_string(size) + " bytes, expected 1 .. " +
            std::to_string(max_game_state_size);
    return false;
  }
  const std::span<const std::uint8_t> game = r.raw(size, "game state");
  s.game.assign(game.begin(), game.end());
  return r.ok();
}

bool has_game(const WorldState& s) {
  return !s.game.empty();
}

void clear_game(WorldState& s) {
  s.game.clear();
}

/// A section of a World's state: its name and version, and its writer and reader side by side.
/// A reader validates what it reads into the scratch state (sections before it already read) and
/// returns false with `error` set, or leaves the failure in the reader. An optional section is
/// written only when `present` says so; a state without it reads as `absent` leaves the scratch
/// state, so a world that never uses it saves what it always did.
struct WorldSection {
  const char* name;
  std::uint32_t version;
  void (*write)(const WorldState& s, ByteWriter& w);
  bool (*read)(std::span<const std::uint8_t> bytes, ByteReader& r, WorldState& s,
               std::string& error);
  bool (*present)(const WorldState& s) = nullptr;  ///< nullptr: always written
  void (*absent)(WorldState& s) = nullptr;         ///< an optional section not in the state
};

/// The World's sections, in the order a state lists them: a new kind of state (joints, particle
/// groups, controllers) is a row here, after the bodies it refers to. The game's own state
/// (World::set_game_state) comes last, present only when the game set one.
constexpr WorldSection kSections[] = {
    {"globals", 1, write_globals, read_globals},
    {"rng", 1, write_rng_section, read_rng},
    {"geometry", 1, write_geometry, read_geometry},
    {"bodies", 2, write_bodies, read_bodies},
    {"contacts", 2, write_contacts, read_contacts},
    {"joints", 1, write_joints, read_joints},
    {"particles", 1, write_particles, read_particles},
    {"vehicles", 1, write_vehicles, read_vehicles, has_vehicles, clear_vehicles},
    {"characters", 1, write_characters, read_characters, has_characters, clear_characters},
    {"game", 1, write_game, read_game, has_game, clear_game},
};
constexpr std::size_t kSectionCount = std::size(kSections);

// The container: "DSIM", the version, the section count, then each section's record.
constexpr std::size_t kMaxSectionName = max_section_name;

/// Where the sections of an encoded state start and end, for the hashes.
struct Encoded {
  ByteWriter w;
  std::size_t count = 0;                                ///< sections written
  std::array<std::size_t, kSectionCount> written{};     ///< each one's index in kSections
  std::array<std::size_t, kSectionCount + 1> starts{};  // then the end of the state
};

void encode(const WorldState& s, Encoded& e) {
  e.w.reserve(256 + s.bodies.size() * 96 + s.contacts.size() * 72 + s.joints.size() * 96 +
              s.game.size());
  e.count = 0;
  for (std::size_t i = 0; i < kSectionCount; ++i)
    if (kSections[i].present == nullptr || kSections[i].present(s)) e.written[e.count++] = i;
  e.w.u32(kMagic);
  e.w.u32(kVersion);
  e.w.var(e.count);
  for (std::size_t k = 0; k < e.count; ++k) {
    const WorldSection& section = kSections[e.written[k]];
    const std::string_view name = section.name;
    e.starts[k] = e.w.size();
    e.w.var(name.size());
    e.w.raw({reinterpret_cast<const std::uint8_t*>(name.data()), name.size()});
    e.w.var(section.version);
    const std::size_t length_at = e.w.size();
    e.w.u32(0);
    section.write(s, e.w);
    e.w.patch_u32(length_at, static_cast<std::uint32_t>(e.w.size() - length_at - 4));
  }
  e.starts[e.count] = e.w.size();
}

// Reads and validates a whole state; on failure returns false with `error` set.
bool read_state(std::span<const std::uint8_t> bytes, WorldState& s, std::string& error) {
  auto sections = read_state_sections(bytes);
  if (!sections) {
    error = "invalid state: " + sections.message();
    return false;
  }
  const auto failed_at = [&](std::size_t at, const std::string& message) {
    error = "invalid state: byte " + std::to_string(at) + ": " + message;
    return false;
  };
  // The World's sections, each once, in their order, at the version this build reads; an
  // optional one may be left out.
  std::string names;
  for (const WorldSection& ws : kSections)
    names += std::string(names.empty() ? "" : ", ") + (ws.present ? "optionally " : "") + ws.name;
  std::size_t next = 0;  // the next of the state's sections
  for (const WorldSection& section : kSections) {
    const bool here = next < sections->size() && (*sections)[next].name == section.name;
    if (!here) {
      if (section.absent != nullptr) {
        section.absent(s);
        continue;
      }
      if (next < sections->size())
        return failed_at((*sections)[next].offset,
                         "section \"" + std::string((*sections)[next].name) +
                             "\" where section \"" + section.name +
                             "\" was expected (a World's state is " + names + ")");
      return failed_at(bytes.size(), "section \"" + std::string(section.name) +
                                         "\" is missing (a World's state is " + names + ")");
    }
    const StateSection& found = (*sections)[next++];
    if (found.version != section.version)
      return failed_at(found.offset, "section \"" + std::string(found.name) + "\" version " +
                                         std::to_string(found.version) + ", this build reads " +
                                         std::to_string(section.version));
    const std::size_t end = found.payload_offset + found.payload.size();
    ByteReader r(bytes.first(end), found.payload_offset);
    std::string section_error;
    const bool read = section.read(bytes, r, s, section_error);
    const std::string where = "section \"" + std::string(found.name) + "\": ";
    if (!section_error.empty()) {
      error = "invalid state: " + where + section_error;
      return false;
    }
    if (!read || !r.ok()) {
      error = "invalid state: " + where + r.error();
      return false;
    }
    if (!r.at_end())
      return failed_at(r.offset(), where + std::to_string(r.remaining()) +
                                       " unexpected bytes after the section's fields");
  }
  if (next < sections->size())
    return failed_at((*sections)[next].offset,
                     "section \"" + std::string((*sections)[next].name) +
                         "\" where the state's end was expected (a World's state is " + names +
                         ")");
  return true;
}

}  // namespace

// ---- Delta coding (state_delta.cpp) ----

namespace {

/// A "contacts" payload read without its semantic checks.
bool read_contact_list(std::span<const std::uint8_t> bytes, const StateSection& section,
                       std::vector<Contact>& out, std::string& error) {
  ByteReader r(bytes.first(section.payload_offset + section.payload.size()),
               section.payload_offset);
  const std::uint32_t count = r.u32("contact count");
  if (r.ok() && count > r.remaining() / kMinContactBytes)
    r.fail_at(section.payload_offset, "contact count", "what the data can hold");
  if (r.ok()) out.reserve(count);
  std::uint32_t previous_a = 0;
  for (std::uint32_t i = 0; i < count && r.ok(); ++i) {
    out.push_back(read_contact(r, previous_a));
    previous_a = out.back().a;
  }
  if (r.ok() && !r.at_end())
    r.fail_at(r.offset(), "contacts", "the section's end after the last contact");
  if (!r.ok()) error = r.error();
  return r.ok();
}

}  // namespace

bool shift_contacts(std::span<const std::uint8_t> bytes, const StateSection& section,
                    std::span<const std::uint8_t> base_bytes, const StateSection& base, bool add,
                    ByteWriter& out, std::string& error) {
  std::vector<Contact> in;
  std::vector<Contact> from;
  if (!read_contact_list(bytes, section, in, error)) return false;
  if (!read_contact_list(base_bytes, base, from, error)) {
    error = "base: " + error;
    return false;
  }
  out.u32(static_cast<std::uint32_t>(in.size()));
  std::uint32_t previous_a = 0;
  for (Contact& c : in) {
    // The prediction: the base's impulses at the same feature of the same pair of sub-shapes.
    const auto it = std::lower_bound(from.begin(), from.end(), c, contact_before);
    if (it != from.end() && !contact_before(c, *it)) {
      for (std::size_t p = 0; p < c.point_count; ++p) {
        for (std::size_t q = 0; q < it->point_count; ++q) {
          const CachedPoint& by = it->cached[q];
          if (by.feature != c.cached[p].feature) continue;
          CachedPoint& point = c.cached[p];
          point.normal_impulse = shifted_value(point.normal_impulse, by.normal_impulse, add);
          point.tangent_impulse_1 =
              shifted_value(point.tangent_impulse_1, by.tangent_impulse_1, add);
          point.tangent_impulse_2 =
              shifted_value(point.tangent_impulse_2, by.tangent_impulse_2, add);
          break;
        }
      }
    }
    write_contact(c, previous_a, out);
    previous_a = c.a;
  }
  return true;
}

bool read_frame_and_step(std::span<const std::uint8_t> bytes, const StateSection& globals,
                         std::uint64_t& frame, Fixed& dt, std::string& error) {
  ByteReader r(bytes.first(globals.payload_offset + globals.payload.size()),
               globals.payload_offset);
  frame = r.u64("frame");
  (void)r.u32("next body id");
  dt = read_def(r).dt;
  if (!r.ok()) error = r.error();
  return r.ok();
}

}  // namespace sim_detail

bool valid_section_name(std::string_view name) noexcept {
  if (name.empty() || name.size() > sim_detail::kMaxSectionName) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '.';
  });
}

std::uint64_t section_hash(const StateSection& section) noexcept {
  return hash_bytes(section.record);
}

Expected<std::vector<StateSection>> read_state_sections(std::span<const std::uint8_t> bytes) {
  return sim_detail::read_sections(bytes, sim_detail::kMagic, "\"DSIM\" (not a detsim state)");
}

Expected<std::vector<StateSection>> sim_detail::read_sections(std::span<const std::uint8_t> bytes,
                                                              std::uint32_t magic,
                                                              const char* expected) {
  ByteReader r(bytes);
  if (r.u32("magic") != magic) r.fail_at(0, "magic", expected);
  const std::uint32_t version = r.u32("version");
  if (r.ok() && version != sim_detail::kVersion) {
    return Status::error("byte 4: state encoding version " + std::to_string(version) +
                         ", this build reads " + std::to_string(sim_detail::kVersion));
  }
  const std::size_t count_at = r.offset();
  const std::uint64_t count = r.var("section count");
  // The smallest section record: a one-byte name, its length, a version and a length.
  if (r.ok() && count > r.remaining() / 7)
    return Status::error("byte " + std::to_string(count_at) + ": section count " +
                         std::to_string(count) + " exceeds what the data can hold");
  std::vector<StateSection> out;
  out.reserve(static_cast<std::size_t>(count));
  for (std::uint64_t i = 0; i < count && r.ok(); ++i) {
    StateSection section;
    section.offset = r.offset();
    const std::uint64_t name_size = r.var("section name length");
    if (r.ok() && (name_size == 0 || name_size > sim_detail::kMaxSectionName))
      r.fail_at(section.offset, "section name length", "1..32");
    if (r.ok() && name_size > r.remaining())
      r.fail("section name", "more bytes (the data ends here)");
    if (!r.ok()) break;
    const std::size_t name_at = r.offset();
    section.name = std::string_view(reinterpret_cast<const char*>(bytes.data() + name_at),
                                    static_cast<std::size_t>(name_size));
    for (std::size_t k = 0; k < name_size; ++k)
      (void)r.u8("section name");
    if (!valid_section_name(section.name))
      r.fail_at(name_at, "section name", "only a-z, 0-9, '_' and '.'");
    section.version = r.var32("section version");
    const std::size_t length_at = r.offset();
    const std::uint32_t length = r.u32("section length");
    if (r.ok() && length > r.remaining())
      r.fail_at(length_at, "section length", "at most the bytes that follow it");
    if (!r.ok()) break;
    for (const StateSection& earlier : out) {
      if (earlier.name == section.name)
        return Status::error("byte " + std::to_string(section.offset) + ": section \"" +
                             std::string(section.name) + "\" appears twice");
    }
    section.payload_offset = r.offset();
    section.payload = bytes.subspan(section.payload_offset, length);
    section.record =
        bytes.subspan(section.offset, section.payload_offset + length - section.offset);
    for (std::uint32_t k = 0; k < length; ++k)
      (void)r.u8("section payload");
    out.push_back(section);
  }
  if (!r.ok()) return Status::error(r.error());
  if (!r.at_end())
    return Status::error("byte " + std::to_string(r.offset()) + ": " +
                         std::to_string(r.remaining()) +
                         " unexpected bytes after the last section");
  return out;
}

std::uint64_t StateHashes::section(std::string_view name) const noexcept {
  for (const SectionHash& h : sections) {
    if (h.name == name) return h.hash;
  }
  return 0;
}

std::vector<std::uint8_t> World::save() const {
  sim_detail::Encoded e;
  sim_detail::encode(*s_, e);
  return e.w.take();
}

Status World::restore(std::span<const std::uint8_t> bytes) {
  auto scratch = std::make_unique<sim_detail::WorldState>();
  // The geometry is the world's definition, not the state's: the state names it by hash, and
  // read_geometry checks it against this world's, including what an earlier restore set aside
  // (so restoring frame 90 and then frame 100 works when frame 100's geometry came later).
  // Whatever the state does not name is set aside again, not forgotten.
  scratch->geometries = s_->geometries;
  scratch->geometries.insert(scratch->geometries.end(), s_->retained.begin(), s_->retained.end());
  scratch->game_fields = s_->game_fields;  // a description, like the geometry: not the state's
  const sim_detail::GeometryTable known = scratch->geometries;
  std::string error;
  if (!sim_detail::read_state(bytes, *scratch, error)) return Status::error(error);
  scratch->retained.assign(known.begin() + static_cast<std::ptrdiff_t>(scratch->geometries.size()),
                           known.end());
  s_ = std::move(scratch);
  return Status::success();
}

StateHashes World::hashes() const {
  std::vector<std::uint8_t> bytes;
  return save(bytes);
}

StateHashes World::save(std::vector<std::uint8_t>& out) const {
  // One encoding: the total is the hash of save()'s bytes, each section's the hash of its record.
  // The bytes go into `out`'s own buffer, so a caller saving every frame allocates nothing but
  // the list of hashes.
  sim_detail::Encoded e{ByteWriter(std::move(out))};
  sim_detail::encode(*s_, e);
  const std::uint8_t* bytes = e.w.bytes().data();
  StateHashes h;
  h.sections.reserve(e.count);
  for (std::size_t k = 0; k < e.count; ++k) {
    const std::size_t from = e.starts[k];
    h.sections.push_back({sim_detail::kSections[e.written[k]].name,
                          hash_bytes({bytes + from, e.starts[k + 1] - from})});
  }
  h.total = hash_bytes({bytes, e.w.size()});
  out = e.w.take();
  return h;
}

Expected<std::uint64_t> World::body_hash(BodyId id) const {
  const std::ptrdiff_t i = s_->find(id.value);
  if (i < 0) return Status::error("no body with ID " + std::to_string(id.value));
  ByteWriter w;
  sim_detail::write_body(s_->bodies[static_cast<std::size_t>(i)], w);
  return hash_bytes(w.bytes());
}

Expected<std::uint64_t> World::particle_group_hash(ParticleGroupId id) const {
  const std::ptrdiff_t k = s_->find_group(id.value);
  if (k < 0) return Status::error("no particle group with ID " + std::to_string(id.value));
  ByteWriter w;
  sim_detail::write_particle_group(s_->particle_groups[static_cast<std::size_t>(k)], 0, w);
  return hash_bytes(w.bytes());
}

}  // namespace detsim
