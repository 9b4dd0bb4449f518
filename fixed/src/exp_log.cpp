// PLACEHOLDER: being written.
#include <detsim/fixed/math.hpp>
namespace detsim {
Fixed exp(Fixed) noexcept { return Fixed{}; }
Fixed exp2(Fixed) noexcept { return Fixed{}; }
Fixed log(Fixed) noexcept { return Fixed{}; }
Fixed log2(Fixed) noexcept { return Fixed{}; }
Fixed pow(Fixed, Fixed) noexcept { return Fixed{}; }
}  // namespace detsim
