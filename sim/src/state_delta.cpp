// Delta coding of saved states (state_delta.hpp): the container is walked here; the bodies and
// contacts are shifted by their sections' own readers and writers (state_bodies.cpp,
// state_io.cpp), so that a field added to a record is delta-coded with it.
#include <detsim/sim/state_delta.hpp>

#include <algorithm>
#include <string>
#include <string_view>

#include <detsim/core/bytes.hpp>
#include <detsim/sim/state_sections.hpp>

#include "state_io.hpp"

namespace detsim {
namespace {

constexpr std::uint32_t kStateMagic = 0x4D495344;  // "DSIM"
constexpr std::uint32_t kDeltaMagic = 0x4C445344;  // "DSDL"
// The section versions whose payloads are shifted (others are copied).
constexpr std::uint32_t kBodiesVersion = 2;
constexpr std::uint32_t kContactsVersion = 2;

const StateSection* find(const std::vector<StateSection>& sections, std::string_view name) {
  for (const StateSection& s : sections)
    if (s.name == name) return &s;
  return nullptr;
}

/// `in` (a state when `add` is false, a delta when true) with its bodies and contacts shifted
/// against `base`, in the container of `out_magic`.
Expected<std::vector<std::uint8_t>> shift(std::span<const std::uint8_t> in, bool add,
                                          std::span<const std::uint8_t> base) {
  const char* what = add ? "delta" : "state";
  auto sections = sim_detail::read_sections(
      in, add ? kDeltaMagic : kStateMagic,
      add ? "\"DSDL\" (not a detsim state delta)" : "\"DSIM\" (not a detsim state)");
  if (!sections) return Status::error(std::string(what) + ": " + sections.message());
  auto base_sections = read_state_sections(base);
  if (!base_sections) return Status::error("base: " + base_sections.message());

  // How far the base's bodies are carried on: its step time times the frames between the two.
  Fixed ahead = Fixed::zero();
  const StateSection* globals = find(*sections, "globals");
  const StateSection* base_globals = find(*base_sections, "globals");
  if (globals != nullptr && base_globals != nullptr) {
    std::uint64_t frame = 0;
    std::uint64_t base_frame = 0;
    Fixed dt;
    Fixed base_dt;
    std::string error;
    if (!sim_detail::read_frame_and_step(in, *globals, frame, dt, error))
      return Status::error(std::string(what) + ": section \"globals\": " + error);
    if (!sim_detail::read_frame_and_step(base, *base_globals, base_frame, base_dt, error))
      return Status::error("base: section \"globals\": " + error);
    // Any difference carries on deterministically (Fixed saturates); a plausible one is small.
    const auto frames = static_cast<std::int64_t>(frame - base_frame);
    const std::int64_t bounded =
        frames < -(1 << 20) ? -(1 << 20) : std::min<std::int64_t>(frames, 1 << 20);
    ahead = base_dt * Fixed::from_int(static_cast<std::int32_t>(bounded));
  }

  ByteWriter w;
  w.reserve(in.size() + in.size() / 2);
  w.u32(add ? kStateMagic : kDeltaMagic);
  w.u32(state_encoding_version);
  w.var(sections->size());
  for (const StateSection& s : *sections) {
    w.var(s.name.size());
    w.raw({reinterpret_cast<const std::uint8_t*>(s.name.data()), s.name.size()});
    w.var(s.version);
    const std::size_t length_at = w.size();
    w.u32(0);
    const StateSection* from = find(*base_sections, s.name);
    std::string error;
    bool shifted = false;
    if (from != nullptr && from->version == s.version) {
      if (s.name == "bodies" && s.version == kBodiesVersion) {
        if (!sim_detail::shift_bodies(in, s, base, *from, ahead, add, w, error))
          return Status::error(std::string(what) + ": section \"bodies\": " + error);
        shifted = true;
      } else if (s.name == "contacts" && s.version == kContactsVersion) {
        if (!sim_detail::shift_contacts(in, s, base, *from, add, w, error))
          return Status::error(std::string(what) + ": section \"contacts\": " + error);
        shifted = true;
      }
    }
    if (!shifted) w.raw(s.payload);
    w.patch_u32(length_at, static_cast<std::uint32_t>(w.size() - length_at - 4));
  }
  return w.take();
}

}  // namespace

Expected<std::vector<std::uint8_t>> encode_state_delta(std::span<const std::uint8_t> state,
                                                       std::span<const std::uint8_t> base) {
  return shift(state, false, base);
}

Expected<std::vector<std::uint8_t>> decode_state_delta(std::span<const std::uint8_t> delta,
                                                       std::span<const std::uint8_t> base) {
  return shift(delta, true, base);
}

}  // namespace detsim
