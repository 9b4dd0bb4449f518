// The replay layer: replay files, and recording, verifying and seeking scenario replays.
#pragma once

#include <detsim/replay/bisect.hpp>
#include <detsim/replay/desync_report.hpp>
#include <detsim/replay/replay.hpp>
#include <detsim/replay/scenario_replay.hpp>
#include <detsim/replay/view.hpp>
