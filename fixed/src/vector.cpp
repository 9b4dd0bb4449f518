// PLACEHOLDER: being written.
#include <detsim/fixed/math.hpp>
