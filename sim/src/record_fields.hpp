// A record's fields, listed once: the mechanism behind the tables of joints (joint_fields.hpp)
// and characters (character_fields.hpp). Internal to detsim::sim.
//
// A kind of state that is a list of records (a joint, a character) describes its fields in one
// table of RecordField<T>; its state section's writer and reader, the field-level diff
// (state_diff.cpp) and fault injection (inject.cpp) walk that table, so a field added to the
// state is added to the table and every tool sees it: its bytes, its name in a diff, its --inject
// form. What a table does not hold is what identifies a record (its ID, its type, its bodies),
// which its section writes first.
//
// The bytes of a record's fields: a flags byte (the flag fields' bits in table order, then one
// presence bit per optional field), the values of the fields that are not optional in table
// order, then the optional values that are present. Only canonical bytes are read: no other bit
// set, and a present optional value is not zero.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <detsim/core/bytes.hpp>
#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/quat.hpp>
#include <detsim/fixed/vec3.hpp>

namespace detsim::sim_detail {

enum class RecordFieldKind : std::uint8_t { fixed, vec3, quat, u32, u64, flag };

template <class T>
struct RecordField {
  const char* name;  ///< as diff prints it and --inject takes it: "linear_impulse"
  const char* what;  ///< as a reader's error names it: "joint linear impulse"
  RecordFieldKind kind;
  /// Encoded only when not zero, its presence a bit of the flags byte (a u64: user data).
  bool optional = false;
  // The member, by kind (one is set): a function, so that a table reaches into nested members.
  Fixed& (*fixed)(T&) = nullptr;
  Vec3& (*vec3)(T&) = nullptr;
  Quat& (*quat)(T&) = nullptr;
  std::uint32_t& (*u32)(T&) = nullptr;
  std::uint64_t& (*u64)(T&) = nullptr;
  bool& (*flag)(T&) = nullptr;
};

// One constructor per kind.
template <class T>
constexpr RecordField<T> fixed_field(const char* name, const char* what, Fixed& (*ref)(T&)) {
  RecordField<T> f{name, what, RecordFieldKind::fixed};
  f.fixed = ref;
  return f;
}
template <class T>
constexpr RecordField<T> vec3_field(const char* name, const char* what, Vec3& (*ref)(T&)) {
  RecordField<T> f{name, what, RecordFieldKind::vec3};
  f.vec3 = ref;
  return f;
}
template <class T>
constexpr RecordField<T> quat_field(const char* name, const char* what, Quat& (*ref)(T&)) {
  RecordField<T> f{name, what, RecordFieldKind::quat};
  f.quat = ref;
  return f;
}
template <class T>
constexpr RecordField<T> u32_field(const char* name, const char* what, std::uint32_t& (*ref)(T&)) {
  RecordField<T> f{name, what, RecordFieldKind::u32};
  f.u32 = ref;
  return f;
}
template <class T>
constexpr RecordField<T> flag_field(const char* name, const char* what, bool& (*ref)(T&)) {
  RecordField<T> f{name, what, RecordFieldKind::flag};
  f.flag = ref;
  return f;
}
/// An optional 64-bit field: written only when not zero.
template <class T>
constexpr RecordField<T> u64_field(const char* name, const char* what, std::uint64_t& (*ref)(T&)) {
  RecordField<T> f{name, what, RecordFieldKind::u64, true};
  f.u64 = ref;
  return f;
}

/// The bits a table's flags byte uses: its flag fields, then its optional fields.
template <class T>
constexpr unsigned record_flag_count(std::span<const RecordField<T>> fields) {
  unsigned n = 0;
  for (const RecordField<T>& f : fields)
    n += f.kind == RecordFieldKind::flag || f.optional ? 1U : 0U;
  return n;
}

/// The field called `name`, or nullptr.
template <class T>
const RecordField<T>* find_record_field(std::span<const RecordField<T>> fields,
                                        std::string_view name) noexcept {
  for (const RecordField<T>& f : fields) {
    if (name == f.name) return &f;
  }
  return nullptr;
}

/// What a reader expects of the flags byte, for its error: "only bits 0 (limit_enabled), ...".
/// Kept for the program's life (ByteReader keeps the pointer): one table per record type.
template <class T>
const std::string& record_flags_expected(std::span<const RecordField<T>> fields) {
  static const std::string text = [&] {
    std::string s = "only bits ";
    unsigned bit = 0;
    for (int pass = 0; pass < 2; ++pass) {
      for (const RecordField<T>& f : fields) {
        const bool listed = pass == 0 ? f.kind == RecordFieldKind::flag : f.optional;
        if (!listed) continue;
        s += (bit > 0 ? ", " : "") + std::to_string(bit) + " (" + f.name +
             (pass == 1 ? " follows" : "") + ")";
        ++bit;
      }
    }
    return s;
  }();
  return text;
}

namespace record_detail {

template <class T>
void write_value(const RecordField<T>& f, T& x, ByteWriter& w) {
  switch (f.kind) {
    case RecordFieldKind::fixed:
      w.var_fixed(f.fixed(x));
      break;
    case RecordFieldKind::vec3:
      w.var_vec3(f.vec3(x));
      break;
    case RecordFieldKind::quat:
      w.var_quat(f.quat(x));
      break;
    case RecordFieldKind::u32:
      w.var(f.u32(x));
      break;
    case RecordFieldKind::u64:
      w.var(f.u64(x));
      break;
    case RecordFieldKind::flag:
      break;  // a bit of the flags byte
  }
}

template <class T>
void read_value(const RecordField<T>& f, T& x, ByteReader& r) {
  switch (f.kind) {
    case RecordFieldKind::fixed:
      f.fixed(x) = r.var_fixed(f.what);
      break;
    case RecordFieldKind::vec3:
      f.vec3(x) = r.var_vec3(f.what);
      break;
    case RecordFieldKind::quat:
      f.quat(x) = r.var_quat(f.what);
      break;
    case RecordFieldKind::u32:
      f.u32(x) = r.var32(f.what);
      break;
    case RecordFieldKind::u64:
      f.u64(x) = r.var(f.what);
      break;
    case RecordFieldKind::flag:
      break;
  }
}

}  // namespace record_detail

/// Writes the flags byte and the values of `record` (see the file comment).
template <class T>
void write_record_fields(std::span<const RecordField<T>> fields, const T& record, ByteWriter& w) {
  auto& x = const_cast<T&>(record);  // the accessors take a mutable record; nothing is written
  unsigned bits = 0;
  unsigned bit = 0;
  for (const RecordField<T>& f : fields) {
    if (f.kind == RecordFieldKind::flag) bits |= (f.flag(x) ? 1U : 0U) << bit++;
  }
  for (const RecordField<T>& f : fields) {
    if (f.optional) bits |= (f.u64(x) != 0 ? 1U : 0U) << bit++;
  }
  w.u8(static_cast<std::uint8_t>(bits));
  for (const RecordField<T>& f : fields) {
    if (!f.optional) record_detail::write_value(f, x, w);
  }
  for (const RecordField<T>& f : fields) {
    if (f.optional && f.u64(x) != 0) record_detail::write_value(f, x, w);
  }
}

/// Reads what write_record_fields wrote into `record`. A bad flags byte is left as the reader's
/// failure; a present optional value that is zero sets `error` ("byte N: ..."). False on either.
/// `flags_what` names the flags byte ("joint flags").
template <class T>
bool read_record_fields(std::span<const RecordField<T>> fields, const char* flags_what, T& record,
                        ByteReader& r, std::string& error) {
  const std::size_t flags_at = r.offset();
  const std::uint8_t flags = r.u8(flags_what);
  if (r.ok() && (flags >> record_flag_count(fields)) != 0) {
    r.fail_at(flags_at, flags_what, record_flags_expected(fields).c_str());
  }
  if (!r.ok()) return false;
  unsigned bit = 0;
  for (const RecordField<T>& f : fields) {
    if (f.kind == RecordFieldKind::flag) f.flag(record) = ((flags >> bit++) & 1U) != 0;
  }
  for (const RecordField<T>& f : fields) {
    if (!f.optional) record_detail::read_value(f, record, r);
  }
  for (const RecordField<T>& f : fields) {
    if (!f.optional || ((flags >> bit++) & 1U) == 0) continue;
    const std::size_t value_at = r.offset();
    record_detail::read_value(f, record, r);
    if (r.ok() && f.u64(record) == 0) {
      error = "byte " + std::to_string(value_at) + ": " + f.what + " flagged present but zero";
      return false;
    }
  }
  return r.ok();
}

/// The list of a section of records (joints, characters): the next ID `u32`, the count `u32`,
/// then each record as its ID step `var` (its ID minus the previous one's, the first's previous 0)
/// and what `write_one(record, w)` writes.
template <class T, class WriteOne>
void write_id_records(std::uint32_t next_id, const std::vector<T>& records, ByteWriter& w,
                      WriteOne&& write_one) {
  w.u32(next_id);
  w.u32(static_cast<std::uint32_t>(records.size()));
  std::uint32_t previous = 0;
  for (const T& x : records) {
    w.var(x.id.value - previous);
    previous = x.id.value;
    write_one(x, w);
  }
}

/// Reads what write_id_records wrote into `records`: the next ID (at least `min_next_id`), the
/// count (bounded by the bytes left at `min_bytes` a record), IDs ascending and below the next
/// ID; `read_one(record, at)` reads and checks the rest of a record that starts at byte `at`,
/// returning false with `error` set or the reader failed. `noun` names the records ("joint").
template <class T, class ReadOne>
bool read_id_records(ByteReader& r, const std::string& noun, std::uint32_t min_next_id,
                     std::size_t min_bytes, std::uint32_t& next_id, std::vector<T>& records,
                     std::string& error, ReadOne&& read_one) {
  const auto failed_at = [&](std::size_t at, const std::string& message) {
    error = "byte " + std::to_string(at) + ": " + message;
    return false;
  };
  const std::size_t next_at = r.offset();
  next_id = r.u32("next ID");
  if (r.ok() && next_id < min_next_id)
    return failed_at(next_at, "next " + noun + " ID must be >= " + std::to_string(min_next_id) +
                                  (min_next_id > 1 ? " (a world that never had one has no such "
                                                     "section)"
                                                   : ""));
  const std::size_t count_at = r.offset();
  const std::uint32_t count = r.u32("count");
  if (r.ok() && count > r.remaining() / min_bytes)
    return failed_at(count_at,
                     noun + " count " + std::to_string(count) + " exceeds what the data can hold");
  records.clear();
  records.reserve(count);
  std::uint32_t previous = 0;
  for (std::uint32_t i = 0; i < count && r.ok(); ++i) {
    const std::size_t at = r.offset();
    T x;
    const std::uint32_t step = r.var32("ID step");
    if (r.ok() && (step == 0 || step > next_id - 1 - previous))
      return failed_at(at, noun + " ID step " + std::to_string(step) + " after ID " +
                               std::to_string(previous) + ": IDs must ascend and stay below the " +
                               "next " + noun + " ID " + std::to_string(next_id));
    x.id = decltype(x.id){previous + step};
    previous = x.id.value;
    if (!r.ok() || !read_one(x, at)) return false;
    records.push_back(x);
  }
  return r.ok();
}

/// A field's name as --inject takes it: "NAME" or "NAME.c" (c one of x, y, z and, for a
/// quaternion, w). The field, with `component` set (-1: the whole value; 0 .. 2: x .. z; 3: w),
/// or nullptr for a name the table does not have.
template <class T>
const RecordField<T>* parse_record_field(std::span<const RecordField<T>> fields,
                                         std::string_view text, int& component) noexcept {
  std::string_view base = text;
  component = -1;
  const std::size_t dot = text.rfind('.');
  if (dot != std::string_view::npos && dot + 2 == text.size()) {
    const char c = text.back();
    base = text.substr(0, dot);
    component = c == 'w' ? 3 : c >= 'x' && c <= 'z' ? c - 'x' : -2;
  }
  const RecordField<T>* f = find_record_field(fields, base);
  if (f == nullptr) return nullptr;
  const bool whole = f->kind != RecordFieldKind::vec3 && f->kind != RecordFieldKind::quat;
  if (whole ? component != -1
            : component < 0 || (f->kind == RecordFieldKind::vec3 && component == 3))
    return nullptr;
  return f;
}

}  // namespace detsim::sim_detail
