// The simulation layer: World, bodies, shapes, the RNG and the canonical state.
#pragma once

#include <detsim/sim/body.hpp>
#include <detsim/sim/bytes.hpp>
#include <detsim/sim/driver.hpp>
#include <detsim/sim/inject.hpp>
#include <detsim/sim/mass.hpp>
#include <detsim/sim/rng.hpp>
#include <detsim/sim/scenario.hpp>
#include <detsim/sim/shape.hpp>
#include <detsim/sim/shape_outline.hpp>
#include <detsim/sim/state_diff.hpp>
#include <detsim/sim/status.hpp>
#include <detsim/sim/world.hpp>
#include <detsim/sim/world_def.hpp>
