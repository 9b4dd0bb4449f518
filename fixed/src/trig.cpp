// PLACEHOLDER: being written.
#include <detsim/fixed/math.hpp>
namespace detsim {
Fixed sin(Fixed) noexcept { return Fixed{}; }
Fixed cos(Fixed) noexcept { return Fixed{}; }
Fixed tan(Fixed) noexcept { return Fixed{}; }
SinCos sincos(Fixed) noexcept { return {}; }
}  // namespace detsim
