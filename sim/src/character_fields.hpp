// A character's fields, listed once (the mechanism: record_fields.hpp). Internal to detsim::sim.
//
// The "characters" state section (state_characters.cpp), the field-level diff (state_diff.cpp)
// and fault injection (inject.cpp) walk this one table, so a field added to CharacterState (or
// CharacterDef) is added here and every tool sees it. What the table does not hold is the
// character's ID (written first in its record).
#pragma once

#include <span>

#include <detsim/sim/character.hpp>

#include "record_fields.hpp"

namespace detsim::sim_detail {

using CharacterField = RecordField<CharacterState>;

/// Every field: the definition's (CharacterDef's order), then CharacterState's own (its order).
[[nodiscard]] std::span<const CharacterField> character_fields() noexcept;

}  // namespace detsim::sim_detail
