// The detsim subcommands, each a function of its parsed arguments returning the exit code. main.cpp
// parses the command line (CLI11, in that one file); these files do the work.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace detsim::cli {

/// Scenario selection shared by run and synctest; 0 means "the scenario's default".
struct ScenarioArgs {
  std::string scenario;
  std::uint64_t frames = 0;
  std::uint64_t seed = 1;
  std::uint32_t players = 0;
  std::uint32_t count = 0;
};

struct ScenariosArgs {
  bool json = false;
};
int scenarios_command(const ScenariosArgs& args);

struct RunArgs {
  ScenarioArgs scene;
  std::vector<std::string> injections;  ///< --inject FRAME:BODY:FIELD:DELTA, each
  std::string record;                   ///< replay file to write, or empty
  std::string save_state;               ///< the last frame's state (World::save) to write, or empty
  std::uint32_t keyframe_interval = 300;
  bool json = false;
};
int run_command(const RunArgs& args);

struct VerifyArgs {
  std::vector<std::string> files;       ///< replay files named on the command line
  std::vector<std::string> injections;  ///< --inject FRAME:BODY:FIELD:DELTA, each
  std::string report;                   ///< desync report to write, or empty
  std::uint64_t at = 0;                 ///< --at FRAME: report this frame; 0: the first mismatch
  bool json = false;
  // Bulk verification (cmd_verify_many.cpp): any of these, or more than one file.
  std::string manifest;           ///< --manifest LIST: a file of replay paths, one a line
  std::uint32_t jobs = 0;         ///< --jobs N: worker threads; 0: the machine's cores
  std::string shard;              ///< --shard I | auto | env:NAME, or empty
  std::uint64_t shard_count = 0;  ///< --of N
  [[nodiscard]] bool bulk() const {
    return files.size() != 1 || !manifest.empty() || jobs != 0 || !shard.empty() ||
           shard_count != 0;
  }
};
int verify_command(const VerifyArgs& args);
int verify_many_command(const VerifyArgs& args);

struct BisectArgs {
  std::string a;  ///< a replay or a desync report
  std::string b;
  std::string html;  ///< write the HTML report here, or empty
  std::size_t max_fields = 100;
  bool json = false;
};
int bisect_command(const BisectArgs& args);

struct ViewArgs {
  std::string record;               ///< a replay or a desync report
  std::string other;                ///< optional: a second record of the same match, overlaid
  std::string out;                  ///< the page; empty: the first file with .html
  std::uint64_t from = 0;           ///< the first frame shown
  std::optional<std::uint64_t> to;  ///< the last (default: the records' end)
  std::string three = "/usr/share/javascript/three";  ///< Debian libjs-three's directory
  bool json = false;
};
int view_command(const ViewArgs& args);

struct DiffArgs {
  std::string a;  ///< a saved state (World::save() bytes)
  std::string b;
  /// The scenario whose world holds the states' geometry (--scenario, --seed, --players,
  /// --count); empty: a world without geometry.
  ScenarioArgs scene;
  std::size_t max_fields = 100;
  bool json = false;
};
int diff_command(const DiffArgs& args);

struct InfoArgs {
  std::string file;
  bool json = false;
};
int info_command(const InfoArgs& args);

struct SeekArgs {
  std::string file;
  std::uint64_t frame = 0;
  std::string save_state;  ///< the state at the frame (World::save bytes) to write, or empty
  bool json = false;
};
int seek_command(const SeekArgs& args);

struct SynctestArgs {
  ScenarioArgs scene;
  std::uint32_t check_distance = 8;
  std::string dump;  ///< on a mismatch, write both states to DUMP.expected / DUMP.actual
  bool json = false;
};
int synctest_command(const SynctestArgs& args);

struct GoldenArgs {
  std::string dir;  ///< the golden directory (default: the source tree's golden/)
  bool update = false;
  bool json = false;
};
int golden_command(const GoldenArgs& args);

/// The main job of scripts/run.sh: a 4-player arena match of bots over a simulated bad network
/// (rollback sessions in virtual time), player 0 recorded, the replay verified, a summary.
struct DemoArgs {
  std::string scenario = "arena";  ///< any scenario that takes 4 players
  std::uint64_t frames = 1200;
  std::uint64_t seed = 1;
  std::string record;  ///< empty: a temporary file, removed afterwards
  bool json = false;
};
int demo_command(const DemoArgs& args);

/// One player of an arena match over UDP against the listed peers, or (spectate) a spectator of
/// one of them.
struct NetplayArgs {
  std::string scenario = "arena";  ///< any scenario with players (2 or more)
  std::uint32_t players = 2;
  std::uint32_t me = 0;
  bool me_given = false;           ///< --me was on the command line (refused with spectate)
  std::string bind;                ///< IP:PORT
  std::vector<std::string> peers;  ///< "J=IP:PORT": every player but `me` once; spectate: the host
  std::vector<std::string> spectators;  ///< IP:PORT of each spectator this player serves
  bool spectate = false;                ///< watch the match instead of playing in it
  std::string mode = "rollback";        ///< or "lockstep"
  std::uint32_t input_delay = 2;
  std::uint64_t frames = 3600;
  std::uint64_t seed = 1;  ///< the scenario's seed
  bool bot = false;        ///< drive this player with scripted_input(bot_seed, ...)
  std::uint64_t bot_seed = 0;
  std::uint32_t fps = 60;  ///< 0: as fast as possible
  double timeout_seconds = 10;
  std::string record;                   ///< replay file, or empty
  std::string desync_report;            ///< on a desync, write this machine's side here; or empty
  std::vector<std::string> injections;  ///< --inject FRAME:BODY:FIELD:DELTA, each
  bool json = false;
  std::string key;       ///< --key: the match key, 64 hex digits; or empty
  std::string key_file;  ///< --key-file: a file holding it (64 hex digits, or 32 raw bytes)
  std::string partition = "end";  ///< --partition: end, pause or play-on
  bool rejoin = false;            ///< --rejoin/--join: take this player's seat (again)
  bool open_seat = false;         ///< --open-seat: start without the other player
  /// --server IP:PORT: play against a game server (detsim serve) instead of peers; --me, when
  /// given, is the seat to ask for.
  std::string server;
  bool seat_given = false;
};
int netplay_command(const NetplayArgs& args);
/// `detsim netplay --server`: one client of a server (cmd_serve.cpp).
int server_client_command(const NetplayArgs& args);

/// `detsim serve`: a server-authoritative match over UDP (net::Server; docs/SERVER.md).
struct ServeArgs {
  std::string bind;  ///< IP:PORT
  std::string scenario = "arena";
  std::uint32_t players = 2;  ///< seats
  std::uint32_t count = 0;    ///< the scenario's size (0: its default)
  std::uint64_t frames = 3600;
  std::uint64_t seed = 1;
  std::string authority = "inputs";  ///< or "state"
  double snapshot_rate = 20;         ///< the server's word per second: updates, or snapshots
  std::uint32_t fps = 60;
  std::uint32_t wait_for = 0;  ///< clients before the match starts (main.cpp: default players)
  double timeout_seconds = 30;
  std::string record;
  bool json = false;
  /// Talk to the Agones SDK sidecar at 127.0.0.1:$AGONES_SDK_HTTP_PORT (agones.hpp).
  bool agones = false;
};
int serve_command(const ServeArgs& args);

}  // namespace detsim::cli
