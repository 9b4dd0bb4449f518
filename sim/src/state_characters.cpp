// The "characters" section of the canonical state (docs/STATE.md): the next character ID, then one
// record per character, in ascending ID order: its ID step, then its fields from the table
// (character_fields.hpp, encoded by record_fields.hpp). An optional section: written only by a
// world that has had a character (next ID above 1), so every other world's state is what it was.
#include <string>

#include "character_fields.hpp"
#include "state_io.hpp"

namespace detsim::sim_detail {

namespace {

#define DETSIM_CHARACTER_REF(type, member) [](CharacterState& c) -> type& { return c.member; }

constexpr CharacterField kCharacterFields[] = {
    vec3_field<CharacterState>("def.position", "character definition position",
                               DETSIM_CHARACTER_REF(Vec3, def.position)),
    fixed_field<CharacterState>("radius", "character radius",
                                DETSIM_CHARACTER_REF(Fixed, def.radius)),
    fixed_field<CharacterState>("half_height", "character half height",
                                DETSIM_CHARACTER_REF(Fixed, def.half_height)),
    fixed_field<CharacterState>("max_slope", "character max slope",
                                DETSIM_CHARACTER_REF(Fixed, def.max_slope)),
    fixed_field<CharacterState>("step_height", "character step height",
                                DETSIM_CHARACTER_REF(Fixed, def.step_height)),
    fixed_field<CharacterState>("mass", "character mass", DETSIM_CHARACTER_REF(Fixed, def.mass)),
    u32_field<CharacterState>("layer", "character layer",
                              DETSIM_CHARACTER_REF(std::uint32_t, def.layer)),
    u32_field<CharacterState>("mask", "character mask",
                              DETSIM_CHARACTER_REF(std::uint32_t, def.mask)),
    u64_field<CharacterState>("user_data", "character user data",
                              DETSIM_CHARACTER_REF(std::uint64_t, def.user_data)),
    vec3_field<CharacterState>("position", "character position",
                               DETSIM_CHARACTER_REF(Vec3, position)),
    vec3_field<CharacterState>("velocity", "character velocity",
                               DETSIM_CHARACTER_REF(Vec3, velocity)),
    flag_field<CharacterState>("grounded", "character grounded",
                               DETSIM_CHARACTER_REF(bool, grounded)),
    vec3_field<CharacterState>("ground_normal", "character ground normal",
                               DETSIM_CHARACTER_REF(Vec3, ground_normal)),
    u32_field<CharacterState>("ground_body", "character ground body",
                              DETSIM_CHARACTER_REF(std::uint32_t, ground_body.value)),
    vec3_field<CharacterState>("desired_velocity", "character desired velocity",
                               DETSIM_CHARACTER_REF(Vec3, input.desired_velocity)),
    fixed_field<CharacterState>("jump", "character jump", DETSIM_CHARACTER_REF(Fixed, input.jump)),
};

#undef DETSIM_CHARACTER_REF

static_assert(record_flag_count<CharacterState>(kCharacterFields) <= 8, "one flags byte");

// The smallest record: ID step, flags, then one byte per value component (six vectors, eight
// numbers and IDs).
constexpr std::size_t kMinCharacterBytes = 1 + 1 + 3 * 6 + 8;

}  // namespace

std::span<const CharacterField> character_fields() noexcept {
  return kCharacterFields;
}

bool has_characters(const WorldState& s) {
  return s.next_character_id != 1;
}

void clear_characters(WorldState& s) {
  s.characters.clear();
  s.next_character_id = 1;
}

void write_characters(const WorldState& s, ByteWriter& w) {
  write_id_records(s.next_character_id, s.characters, w,
                   [](const CharacterState& c, ByteWriter& out) {
                     write_record_fields<CharacterState>(kCharacterFields, c, out);
                   });
}

bool read_characters(std::span<const std::uint8_t>, ByteReader& r, WorldState& s,
                     std::string& error) {
  return read_id_records(
      r, "character", 2, kMinCharacterBytes, s.next_character_id, s.characters, error,
      [&](CharacterState& c, std::size_t at) {
        if (!read_record_fields<CharacterState>(kCharacterFields, "character flags", c, r, error))
          return false;
        if (auto e = check_character_record(s, c); !e.empty()) {
          error =
              "byte " + std::to_string(at) + ": character " + std::to_string(c.id.value) + ": " + e;
          return false;
        }
        return true;
      });
}

}  // namespace detsim::sim_detail
