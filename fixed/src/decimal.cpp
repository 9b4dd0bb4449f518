// PLACEHOLDER: being written.
#include <detsim/fixed/decimal.hpp>
