// to_string: the shortest decimal that Fixed::parse reads back as the same value.
//
// Fixed::parse maps a decimal c to x = I + F / 2^32 exactly when c lies in x's rounding interval
// (x - 2^-33, x + 2^-33) (the ends, odd multiples of 2^-33, have 33 decimal places and never meet
// a candidate of at most 10 places). Measured in units of 10^-10, that interval is
// ((2F - 1) 5^10 / 2^23, (2F + 1) 5^10 / 2^23) after the integer part; its ends are not integers
// ((2F +- 1) 5^10 is odd), so the 10-place candidates are the integers L..H with
// L = floor((2F - 1) 5^10 / 2^23) + 1 and H = floor((2F + 1) 5^10 / 2^23). The interval is
// 10^10 / 2^32 < 2.33 units wide, so for j >= 1 it holds at most one multiple of 10^j, and one
// exists iff floor(H / 10^j) != floor((L - 1) / 10^j). The largest such j gives the fewest places,
// 10 - j, and the one candidate. For F != 0, 2 <= L <= H < 10^10, so 1 <= 10 - j <= 10 and no carry
// reaches the integer part. At 10 places (j = 0) up to three integers qualify: the nearest,
// F 5^10 / 2^22 rounded with ties to even, is one of them (it is within 1/2 unit < 1.17 units).
// No result has a trailing zero: it would be a multiple of 10^(j+1) in the interval.
#include <detsim/fixed/decimal.hpp>

#include <cstddef>
#include <cstdint>
#include <string>

#include <detsim/fixed/wide.hpp>

namespace detsim {
namespace {

constexpr std::uint64_t fraction_mask = (std::uint64_t{1} << Fixed::fraction_bits) - 1;
constexpr int max_fraction_digits = 10;
constexpr std::uint64_t five_10 = 9765625;  // 5^10: (2F + 1) 5^10 < 2^33 * 2^23.3 fits 64 bits
static_assert(five_10 == detail::decimal::pow10[10] >> 10);

struct Shortest {
  std::uint64_t digits = 0;  ///< the fraction digits as an integer, < 10^places
  int places = 0;
};

Shortest shortest_fraction(std::uint64_t fraction) {
  if (fraction == 0) return {};
  const std::uint64_t low = (((2 * fraction - 1) * five_10) >> 23) + 1;  // L
  const std::uint64_t high = ((2 * fraction + 1) * five_10) >> 23;       // H
  std::uint64_t h = high;
  std::uint64_t l = low - 1;
  int places = max_fraction_digits;
  while (h / 10 != l / 10) {
    h /= 10;
    l /= 10;
    --places;
  }
  if (places == max_fraction_digits) {
    h = detail::round_shift_right(wide::U128{0, fraction * five_10},
                                  22U);  // F 10^10 / 2^32 = F 5^10 / 2^22
  }
  return {h, places};
}

}  // namespace

std::string to_string(Fixed x) {
  const std::uint64_t magnitude = detail::magnitude(x.raw());
  std::uint64_t integer = magnitude >> Fixed::fraction_bits;  // <= 2^31
  const Shortest fraction = shortest_fraction(magnitude & fraction_mask);

  // "-2147483647.9999999998" is the longest text: 22 characters.
  char buffer[24];
  char* end = buffer + sizeof buffer;
  char* p = end;
  if (fraction.places > 0) {
    std::uint64_t digits = fraction.digits;
    for (int i = 0; i < fraction.places; ++i) {
      *--p = static_cast<char>('0' + digits % 10);
      digits /= 10;
    }
    *--p = '.';
  }
  do {
    *--p = static_cast<char>('0' + integer % 10);
    integer /= 10;
  } while (integer != 0);
  if (x.raw() < 0) *--p = '-';
  return std::string(p, static_cast<std::size_t>(end - p));
}

}  // namespace detsim
