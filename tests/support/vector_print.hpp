// GoogleTest printers for the vector types: every component as decimal and raw hex (print.hpp),
// and the exact 128-bit helpers the vector tests use to derive expected values.
#pragma once

#include <cstdint>
#include <ostream>

#include <detsim/fixed/mat3.hpp>
#include <detsim/fixed/quat.hpp>
#include <detsim/fixed/vec2.hpp>
#include <detsim/fixed/vec3.hpp>

#include "support/print.hpp"

namespace detsim {

inline void PrintTo(Vec2 v, std::ostream* os) {
  *os << "(";
  PrintTo(v.x, os);
  *os << ", ";
  PrintTo(v.y, os);
  *os << ")";
}

inline void PrintTo(Vec3 v, std::ostream* os) {
  *os << "(";
  PrintTo(v.x, os);
  *os << ", ";
  PrintTo(v.y, os);
  *os << ", ";
  PrintTo(v.z, os);
  *os << ")";
}

inline void PrintTo(Quat q, std::ostream* os) {
  *os << "(w ";
  PrintTo(q.w, os);
  *os << ", x ";
  PrintTo(q.x, os);
  *os << ", y ";
  PrintTo(q.y, os);
  *os << ", z ";
  PrintTo(q.z, os);
  *os << ")";
}

inline void PrintTo(const Mat3& m, std::ostream* os) {
  *os << "[";
  PrintTo(m.rows[0], os);
  *os << ",\n ";
  PrintTo(m.rows[1], os);
  *os << ",\n ";
  PrintTo(m.rows[2], os);
  *os << "]";
}

namespace test {

// The tests' exact reference arithmetic: the host compiler's 128-bit integers (the library itself
// uses wide::U128 so that it also runs where these do not exist). Every use keeps its values in
// range and says why.
__extension__ using i128 = __int128;
__extension__ using u128 = unsigned __int128;

inline i128 product(Fixed a, Fixed b) {
  return static_cast<i128>(a.raw()) * b.raw();
}

inline std::uint64_t abs64(i128 v) {
  return static_cast<std::uint64_t>(v < 0 ? -v : v);
}

// True when r is the exact value `exact / 2^shift` rounded to nearest with ties to even and
// saturated to the int64 range. Requires |exact| < 2^126 and |r| 2^shift < 2^127 so that nothing
// below overflows.
inline bool is_rounded(std::int64_t r, i128 exact, int shift) {
  const i128 scaled = static_cast<i128>(r) * (i128{1} << shift);
  const i128 half = i128{1} << (shift - 1);
  const i128 diff = exact - scaled;
  if (r == INT64_MAX && diff > -half) return true;  // saturated (max - 1/2 is a tie: max - 1)
  if (r == INT64_MIN && diff <= half) return true;
  if (diff > half || diff < -half) return false;
  if (diff == half || diff == -half) return (r & 1) == 0;
  return true;
}

// With probability 1/2, r with its low 14..24 bits cleared. Products of such values often end in
// exactly half an ulp (or, for products of three, half of the 2^64 rounding unit), so the random
// tests see many ties and check that they go to even; uniform raws almost never produce one.
template <class Rng>
std::int64_t maybe_coarse(std::int64_t r, Rng& rng) {
  const std::uint64_t choice = rng();
  if ((choice & 1) != 0) return r;
  const unsigned k = 14 + static_cast<unsigned>((choice >> 1) % 11);
  return static_cast<std::int64_t>(static_cast<std::uint64_t>(r) & ~((std::uint64_t{1} << k) - 1));
}

}  // namespace test
}  // namespace detsim
