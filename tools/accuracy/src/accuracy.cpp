// PLACEHOLDER: being written.
#include <detsim/fixed.hpp>
