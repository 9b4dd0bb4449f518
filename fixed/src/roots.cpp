// PLACEHOLDER: being written.
#include <detsim/fixed/math.hpp>
namespace detsim {
Fixed sqrt(Fixed) noexcept { return Fixed{}; }
Fixed rsqrt(Fixed) noexcept { return Fixed{}; }
Fixed hypot(Fixed, Fixed) noexcept { return Fixed{}; }
}  // namespace detsim
