// The fixed-point layer: Fixed, its functions, and the vector types.
#pragma once

#include <detsim/fixed/decimal.hpp>
#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/math.hpp>
