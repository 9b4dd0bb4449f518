// PLACEHOLDER: being written.
#include <detsim/fixed/math.hpp>
namespace detsim {
Fixed asin(Fixed) noexcept { return Fixed{}; }
Fixed acos(Fixed) noexcept { return Fixed{}; }
Fixed atan(Fixed) noexcept { return Fixed{}; }
Fixed atan2(Fixed, Fixed) noexcept { return Fixed{}; }
}  // namespace detsim
