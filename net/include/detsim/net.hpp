// The network layer: sessions (rollback, lockstep) and a game server with its clients, over a
// transport (UDP, simulated network).
#pragma once

#include <detsim/net/client.hpp>
#include <detsim/net/game.hpp>
#include <detsim/net/protection.hpp>
#include <detsim/net/protocol.hpp>
#include <detsim/net/server.hpp>
#include <detsim/net/server_protocol.hpp>
#include <detsim/net/session.hpp>
#include <detsim/net/sim_network.hpp>
#include <detsim/net/spectator.hpp>
#include <detsim/net/synctest.hpp>
#include <detsim/net/transport.hpp>
#if DETSIM_WITH_UDP  // a PUBLIC definition of detsim::net: 0 in a DETSIM_WITH_UDP=OFF build
#include <detsim/net/udp.hpp>
#endif
