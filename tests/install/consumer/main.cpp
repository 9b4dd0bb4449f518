// A game's first use of detsim, built against the installed package.
#include <cstdio>

#include <detsim/detsim.hpp>

int main() {
  using detsim::Fixed;
  const Fixed a = Fixed::from_raw(Fixed::one_raw + Fixed::one_raw / 2);  // 1.5
  const Fixed b = Fixed::from_int(9) / Fixed::from_int(4);               // 2.25
  const Fixed p = a * b;
  std::printf("1.5 * 2.25 = %.3f (sqrt(4) = %.1f)\n", p.to_double(),
              detsim::sqrt(Fixed::from_int(4)).to_double());
  return p == Fixed::from_raw(Fixed::one_raw * 27 / 8) ? 0 : 1;
}
