// The fixed-point layer: Fixed, its functions, and the vector types.
#pragma once

#include <detsim/fixed/decimal.hpp>
#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/mat3.hpp>
#include <detsim/fixed/math.hpp>
#include <detsim/fixed/quat.hpp>
#include <detsim/fixed/vec2.hpp>
#include <detsim/fixed/vec3.hpp>
