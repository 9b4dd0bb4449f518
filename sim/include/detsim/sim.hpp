// The simulation layer: World, bodies, shapes and the canonical state.
#pragma once

#include <detsim/core.hpp>  // Status, Rng and the byte codec, which sim's API speaks

#include <detsim/sim/body.hpp>
#include <detsim/sim/character.hpp>
#include <detsim/sim/driver.hpp>
#include <detsim/sim/inject.hpp>
#include <detsim/sim/joint.hpp>
#include <detsim/sim/mass.hpp>
#include <detsim/sim/shape.hpp>
#include <detsim/sim/shape_outline.hpp>
#include <detsim/sim/state_delta.hpp>
#include <detsim/sim/state_diff.hpp>
#include <detsim/sim/state_sections.hpp>
#include <detsim/sim/vehicle.hpp>
#include <detsim/sim/world.hpp>
#include <detsim/sim/world_def.hpp>
