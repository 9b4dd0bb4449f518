// The core layer: errors as values, the RNG, canonical bytes, the hash and the version.
#pragma once

#include <detsim/core/bytes.hpp>
#include <detsim/core/hash.hpp>
#include <detsim/core/rng.hpp>
#include <detsim/core/status.hpp>
#include <detsim/core/version.hpp>
