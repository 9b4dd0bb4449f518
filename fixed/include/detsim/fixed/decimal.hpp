// Exact decimal text <-> Fixed conversions. (Being written: parse, to_string, the _fx literal.)
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include <detsim/fixed/fixed.hpp>

namespace detsim {

/// Why Fixed::parse rejected its input.
enum class ParseError : std::uint8_t {
  none = 0,
  empty,              ///< no characters, or only a sign
  invalid_character,  ///< something other than digits, one '.', a leading sign, an exponent
  out_of_range,       ///< the rounded value does not fit in [Fixed::min(), Fixed::max()]
};

/// Result of Fixed::parse: a value, or the reason there is none.
struct ParseResult {
  Fixed value{};
  ParseError error = ParseError::none;
  [[nodiscard]] constexpr bool ok() const noexcept { return error == ParseError::none; }
  constexpr explicit operator bool() const noexcept { return ok(); }
};

constexpr ParseResult Fixed::parse(std::string_view) noexcept { return {Fixed{}, ParseError::empty}; }

}  // namespace detsim
