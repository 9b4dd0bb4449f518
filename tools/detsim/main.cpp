// The detsim command: the command line (CLI11, only in this file) and the help texts; each
// subcommand's work is in its cmd_*.cpp. Exit status: 0 success, 1 a check failed, 2 bad usage or
// bad input.
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <detsim/cli.hpp>
#include <detsim/detsim.hpp>

#include "cli_app.hpp"

#include "commands.hpp"
#include "output.hpp"
#include "scenario_args.hpp"

namespace {

const std::string version_text = "detsim " + std::string(detsim::version);

// ---- Scenario, replay and golden commands -------------------------------------------------------

constexpr const char* exit_footer =
    "\nExit status: 0 success; 1 a check failed (hash mismatch, desync); 2 bad usage or bad input\n"
    "(the message on stderr names what is wrong). --json prints exactly one JSON object on stdout.";

void add_inject_option(CLI::App* cmd, std::vector<std::string>& specs) {
  cmd->add_option("--inject", specs,
                  "Debug aid: change one field of this machine's state at one frame (repeatable; "
                  "see below)")
      ->type_name("FRAME:BODY:FIELD:DELTA");
}

const std::string inject_footer = std::string(R"(
--inject FRAME:BODY:FIELD:DELTA changes the state of frame FRAME (after its step, before its hash)
on this machine only, as non-determinism would: e.g. 500:17:position.y:0.001. FIELD is one of: )") +
                                  std::string(detsim::injection_fields_help()) +
                                  ". A contact field is named as detsim diff prints it: "
                                  "contact[OTHER] between whole shapes, contact[OTHER/S/T] "
                                  "between sub-shape S of BODY (a compound's part, a mesh's "
                                  "triangle) and sub-shape T of OTHER, e.g. "
                                  "120:4:contact[9/0/17].point[0].normal_impulse:0.5.\n";

void add_scenario_options(CLI::App* cmd, detsim::cli::ScenarioArgs& a) {
  cmd->add_option("--scenario", a.scenario, "Scenario name (detsim scenarios lists them)")
      ->required()
      ->type_name("NAME");
  cmd->add_option("--frames", a.frames, "Frames to simulate (default: the scenario's own)")
      ->type_name("N")
      ->check(CLI::Range(std::uint64_t{1}, detsim::cli::max_frames));
  cmd->add_option("--seed", a.seed,
                  "Seed of the world's RNG and of the scripted players (default 1)")
      ->type_name("S");
  cmd->add_option("--players", a.players,
                  "Players, for scenarios that have them (default: the scenario's own)")
      ->type_name("P");
  cmd->add_option("--count", a.count,
                  "Size of the scene: bodies for the piles (default 1000), rows for the pyramid "
                  "(default 20), links (chain), planks (bridge), ragdolls; `detsim scenarios` "
                  "lists each range")
      ->type_name("N");
}

[[maybe_unused]] constexpr const char* netplay_footer = R"(
Every player runs this command with the same --players, --seed and --mode and its own --me, --bind
and one --peer for each other player, e.g. for two players on one machine:
  detsim netplay --players 2 --me 0 --bind 127.0.0.1:7000 --peer 1=127.0.0.1:7001 --bot 1
  detsim netplay --players 2 --me 1 --bind 127.0.0.1:7001 --peer 0=127.0.0.1:7000 --bot 2
Peers whose settings differ (players, seed, mode, frames, detsim version) refuse each other.

Packet protection: with --key (or --key-file) every packet is encrypted and authenticated
(ChaCha20-Poly1305 under per-direction keys derived from the match key; a replay window drops
duplicates and old packets). Whoever lacks the key can drop packets, and nothing more: no reading,
forging, rewriting or replaying. Peers with different keys (or one without) never connect, and
say so. Without a key packets are NOT protected: anyone on the path can read every input and
rewrite it, and a relay that also rewrites the hash checks can split the match unnoticed. Play
without a key only on a network you trust (a LAN, tests).
After the last frame the command keeps answering until every frame is confirmed and every peer
has reached the end. With --record every peer writes the same replay, byte for byte; detsim
verify checks it. The bot plays by frame number, so the final hash depends only on the
arguments, never on the network's timing.

A spectator watches through one player, which lists it with --spectator; it simulates the
confirmed frames only (no prediction, no rollback), catches up when behind, and records the same
replay as the players. Player 0 above could serve one at 127.0.0.1:7002 with
--spectator 127.0.0.1:7002, and the spectator would run
  detsim netplay --spectate --players 2 --bind 127.0.0.1:7002 --peer 0=127.0.0.1:7000
A player waits for its connected spectators to have every frame before it exits (up to
--timeout; a spectator that lags is only warned about).

If a player's process stops, it can be started again with the same arguments plus --rejoin: a
peer sends the match's state (compressed) and the inputs since, and the match goes on; the frames
the restart missed take no input from the rejoining player. All end with the same hash. A player
may also start alone with --open-seat; the others join whenever they start, with --join.

Exit status: 0 the match completed; 1 a desync (the frame, both hashes and the player are
printed; --desync-report writes this machine's side for bisection) or an unverified frame (a
peer's hash check that never arrived: "UNVERIFIED" on stderr, "unverified" in --json); 2 bad
usage, a port in use, a handshake timeout, or a peer that disconnected and left this machine
without a majority (the message on stderr names it and why: silent, or no progress); a player
that leaves while a majority plays on (three or more players, or --partition play-on) is reported
on stderr and the match goes on, which it may rejoin. --json prints exactly one JSON object on
stdout.)";

#if !DETSIM_WITH_UDP
// Without UDP the command stays, takes any arguments and says why it cannot run, so that a script
// gets that message and exit status 2 rather than "unknown subcommand" or a missing option.
void add_netplay(CLI::App& app, int& exit_code) {
  auto* c =
      app.add_subcommand("netplay", "Not in this build: built without UDP (DETSIM_WITH_UDP=OFF)");
  c->allow_extras();
  c->callback(
      [&exit_code] { exit_code = detsim::cli::netplay_command(detsim::cli::NetplayArgs{}); });
}
#else
void add_netplay(CLI::App& app, int& exit_code) {
  static detsim::cli::NetplayArgs netplay;
  auto* c = app.add_subcommand(
      "netplay", "Play one player of a match (the arena, or --scenario) against peers over UDP");
  c->add_option("--scenario", netplay.scenario,
                "The scenario to play, one that takes players (default arena; same on all peers)")
      ->type_name("NAME");
  c->add_option("--players", netplay.players,
                "Players in the match, 2 .. 8 (and at most the scenario's; default 2)")
      ->type_name("N");
  auto* me = c->add_option("--me", netplay.me,
                           "This machine's player index, 0 .. N-1 (default 0; not with --spectate)")
                 ->type_name("I");
  c->add_option("--bind", netplay.bind,
                "Local UDP address and port to listen on, numeric: 127.0.0.1:7000, "
                "0.0.0.0:7000 or [::1]:7000")
      ->required()
      ->type_name("IP:PORT");
  c->add_option("--peer", netplay.peers,
                "Player J's address (repeat for every player but --me): 1=192.0.2.7:7000; with "
                "--spectate exactly one: the player that serves this spectator")
      ->type_name("J=IP:PORT");
  c->add_option(
       "--spectator", netplay.spectators,
       "Serve a spectator at this address (repeatable, at most 16): it receives every "
       "confirmed frame from this player (the spectator runs --spectate --peer I=<this --bind>)")
      ->type_name("IP:PORT");
  c->add_flag("--spectate", netplay.spectate,
              "Watch the match instead of playing: no --me, one --peer naming the player that "
              "lists this machine with --spectator, and the players' --players, --seed, --mode "
              "and --frames");
  c->add_option("--seed", netplay.seed, "Seed of the scenario (default 1; same on all peers)")
      ->type_name("S");
  c->add_option("--mode", netplay.mode,
                "rollback (predict remote inputs, correct by re-simulating) or lockstep (wait "
                "for every input); default rollback, same on all peers")
      ->type_name("MODE");
  c->add_option("--input-delay", netplay.input_delay,
                "Frames between a local input and the frame it applies to, 0 .. 16 (default 2)")
      ->type_name("D")
      ->check(CLI::Range(0U, 16U));
  c->add_option("--frames", netplay.frames, "Frames to play (default 3600: one minute at 60 fps)")
      ->type_name("F");
  auto* bot = c->add_option("--bot", netplay.bot_seed,
                            "Drive this player with the scripted bot seeded with SEED (default: "
                            "no input, the player stands still)")
                  ->type_name("SEED");
  c->add_option("--fps", netplay.fps,
                "Frames per second, 1 .. 1000; 0 runs as fast as the peers allow (default 60)")
      ->type_name("N")
      ->check(CLI::Range(0U, 1000U));
  c->add_option("--timeout", netplay.timeout_seconds,
                "Seconds to wait for the handshake with every peer, and for the peers after the "
                "last frame (default 10)")
      ->type_name("SECONDS");
  c->add_option("--record", netplay.record,
                "Record the confirmed frames to a replay file (the same bytes on every peer and "
                "spectator; with --rejoin, the frames before the return are re-simulated from "
                "the snapshot's log, which must give the snapshot's state)")
      ->type_name("FILE");
  auto* key = c->add_option("--key", netplay.key,
                            "The match key, 64 hex digits (e.g. from `head -c 32 /dev/urandom | "
                            "xxd -p -c 64`), the same on every peer and spectator: every packet "
                            "is encrypted and authenticated, replays are dropped. Visible to "
                            "other users in the process list: prefer --key-file. Without a key "
                            "packets are NOT protected (see below)")
                  ->type_name("HEX");
  c->add_option("--key-file", netplay.key_file,
                "Read the match key from FILE: 64 hex digits (whitespace around them ignored) or "
                "exactly 32 raw bytes")
      ->type_name("FILE")
      ->excludes(key);
  c->add_option("--partition", netplay.partition,
                "When this player is left without a majority (two players: the other one is "
                "gone): end (the match ends on every side at the frames all of them hold; "
                "exit 2), pause (wait for the player to come back or --rejoin, however long) "
                "or play-on (go on alone: the match splits); default end")
      ->type_name("POLICY");
  c->add_flag("--rejoin,--join", netplay.rejoin,
              "Take this player's seat in a match under way: again, after this machine's "
              "process stopped, or for the first time when the other player runs --open-seat. "
              "A peer sends the match's state and this one re-simulates to the present (two "
              "players: a seat still held — within 5 s of the stop, or --partition pause — "
              "continues where the peer's copy of this player's inputs ends; an open seat, or "
              "one given up under --partition play-on, is taken from the present. Three or more: "
              "always from the present, after the peers agree where the old process stopped)");
  c->add_flag("--open-seat", netplay.open_seat,
              "Start without the other players: their seats are open (their inputs zero) until "
              "each joins with --join, which it may do at any time; a match nobody joins ends "
              "normally");
  add_inject_option(c, netplay.injections);
  c->add_option("--desync-report", netplay.desync_report,
                "On a desync, write this machine's side to FILE: the inputs up to the divergent "
                "frame, the states at the last agreed and the divergent frame, per-body hashes "
                "(default: none written)")
      ->type_name("FILE");
  c->add_flag("--json", netplay.json,
              "Print one JSON object: frames, final_hash (16 hex digits), rollbacks, "
              "resimulated_frames, desyncs, peers, spectator, ...");
  c->add_option("--server", netplay.server,
                "Play against a game server (detsim serve) at IP:PORT instead of peers: it names "
                "the scenario, seed, players and frames; --me asks for a seat")
      ->type_name("IP:PORT");
  c->footer(std::string(netplay_footer) + inject_footer);
  c->callback([&exit_code, bot, me] {
    netplay.bot = bot->count() > 0;
    netplay.me_given = me->count() > 0;
    netplay.seat_given = netplay.me_given;
    exit_code = detsim::cli::netplay_command(netplay);
  });
}
#endif

[[maybe_unused]] constexpr const char* serve_footer = R"(
The server owns the match: clients (detsim netplay --server IP:PORT --bind IP:PORT) connect,
take a seat, and learn the scenario, seed, players and frames from it. It simulates on its own
clock and never waits for a client: an input that arrives late goes to the next frame not yet
simulated, a missing one repeats the player's last. Each client predicts and reconciles exactly:
a right prediction costs nothing, a wrong one is re-simulated (--authority inputs: the server
sends every player's inputs and a hash of its state) or replaced by the server's state
(--authority state: delta-coded, zstd-compressed snapshots, checked against their hash). A client
may join at any time, or come back after its process was killed: it gets a snapshot of now, and
nobody waits. With --record the server writes an ordinary replay (detsim verify checks it).
Packets are not encrypted: the server takes a client's inputs only from the address and token it
admitted, for that client's seat, within a window of frames; anything else is counted and
dropped. docs/SERVER.md explains when to pick a server over rollback or lockstep.

SIGTERM ends the match at the frame it has reached: the replay of --record is closed (complete up
to that frame: detsim verify checks it), the report says "stopped by SIGTERM at frame N" (--json:
"stopped":"SIGTERM"), and the exit status is 0.

--agones (a game server under Agones, docs/SCALE.md): the server talks to the Agones SDK
sidecar over HTTP at 127.0.0.1:$AGONES_SDK_HTTP_PORT (default 9358). It sends ready once its
socket is bound; health every 2 s while the server makes progress (its loop waits for players or
acknowledgements, or the match simulates new frames: a stalled match sends none and Agones marks
it Unhealthy); when the match ends (or stops), the annotations detsim.final-hash,
detsim.frames and detsim.outcome (ended, stopped, no-match); then shutdown. A call the sidecar
does not take is retried with backoff (100 ms doubling to 2 s) from a thread of its own: the
match never waits for the sidecar, and a sidecar that is not up yet or goes away costs failed
calls, noted on stderr, never a frame. At the end the server waits at most 5 s for the
annotations and shutdown to be delivered. The report gains agones (--json: an "agones" object).

Exit status: 0 the match ran to its end, or SIGTERM stopped it; 2 bad usage, a port in use, or no
match (fewer than --wait-for clients within --timeout). --json prints exactly one JSON object on
stdout: frames, final_hash, clients (player, bytes_sent, bytes_received, inputs_late,
packets_rejected, ...), bytes_sent_per_client_per_second.)";

#if DETSIM_WITH_UDP
void add_serve(CLI::App& app, int& exit_code) {
  static detsim::cli::ServeArgs serve;
  auto* c = app.add_subcommand(
      "serve",
      "Run a server-authoritative match of a scenario over UDP for detsim netplay "
      "--server clients");
  c->add_option("--bind", serve.bind,
                "Local UDP address and port to serve on, numeric: 0.0.0.0:7000, 127.0.0.1:7000 "
                "or [::1]:7000")
      ->required()
      ->type_name("IP:PORT");
  c->add_option("--players", serve.players, "Seats in the match, 1 .. 128 (default 2)")
      ->type_name("N");
  c->add_option("--frames", serve.frames, "Frames to play (default 3600: one minute at 60 fps)")
      ->type_name("F");
  c->add_option("--scenario", serve.scenario,
                "The scenario, one that takes players (default arena)")
      ->type_name("NAME");
  c->add_option("--count", serve.count, "The scenario's size (default: its own)")->type_name("N");
  c->add_option("--seed", serve.seed, "Seed of the scenario (default 1)")->type_name("S");
  c->add_option("--authority", serve.authority,
                "inputs (clients get every player's inputs and a hash: bandwidth independent of "
                "the scene) or state (clients get the server's state, delta-coded); default "
                "inputs")
      ->type_name("KIND");
  c->add_option("--snapshot-rate", serve.snapshot_rate,
                "The server's word to each client per second: updates (inputs), or snapshots "
                "(state); default 20")
      ->type_name("HZ");
  c->add_option("--fps", serve.fps, "Frames per second, 1 .. 1000 (default 60)")->type_name("N");
  auto* wait = c->add_option("--wait-for", serve.wait_for,
                             "Clients that must be in before frame 0 (default: every seat); the "
                             "rest join the match under way")
                   ->type_name("N");
  c->add_option("--timeout", serve.timeout_seconds,
                "Seconds to wait for --wait-for clients, and for the clients' last "
                "acknowledgements after the last frame (default 30)")
      ->type_name("SECONDS");
  c->add_option("--record", serve.record,
                "Record the match (every frame the server simulates) to a replay file")
      ->type_name("FILE");
  c->add_flag("--json", serve.json,
              "Print one JSON object: frames, final_hash, clients, "
              "bytes_sent_per_client_per_second, ...");
  c->add_flag("--agones", serve.agones,
              "Run under Agones: ready, health and shutdown to the SDK sidecar at "
              "127.0.0.1:$AGONES_SDK_HTTP_PORT (default 9358), the final hash and frames as "
              "annotations (below)");
  c->footer(serve_footer);
  c->callback([&exit_code, wait] {
    if (wait->count() == 0) serve.wait_for = serve.players;
    exit_code = detsim::cli::serve_command(serve);
  });
}
#else
void add_serve(CLI::App& app, int& exit_code) {
  auto* c =
      app.add_subcommand("serve", "Not in this build: built without UDP (DETSIM_WITH_UDP=OFF)");
  c->allow_extras();
  c->callback([&exit_code] { exit_code = detsim::cli::serve_command(detsim::cli::ServeArgs{}); });
}
#endif

void add_scenario_commands(CLI::App& app, int& exit_code) {
  namespace cli = detsim::cli;
  static cli::ScenariosArgs scenarios;
  static cli::RunArgs run;
  static cli::VerifyArgs verify;
  static cli::InfoArgs info;
  static cli::DiffArgs diff;
  static cli::BisectArgs bisect;
  static cli::ViewArgs view;
  static cli::SynctestArgs synctest;
  static cli::GoldenArgs golden_check;
  static cli::GoldenArgs golden_update;
  static cli::DemoArgs demo;

  auto* c = app.add_subcommand("scenarios", "List the scenarios and their parameters");
  c->add_flag("--json", scenarios.json, "Print one JSON object");
  c->footer(exit_footer);
  c->callback([&exit_code] { exit_code = cli::scenarios_command(scenarios); });

  c = app.add_subcommand("run", "Run a scenario headless; print its frame count and final hash");
  add_scenario_options(c, run.scene);
  c->add_option("--record", run.record, "Record the run to a replay file (replay/FORMAT.md)")
      ->type_name("FILE");
  c->add_option("--save-state", run.save_state,
                "Write the last frame's state (World::save bytes) to FILE, for detsim diff")
      ->type_name("FILE");
  c->add_option("--keyframe-interval", run.keyframe_interval,
                "Frames between the replay's keyframes, for seeking (default 300)")
      ->type_name("K")
      ->check(CLI::Range(1U, 1'000'000U));
  add_inject_option(c, run.injections);
  c->add_flag("--json", run.json,
              "Print one JSON object: scenario, frames, final_hash (16 hex digits), ...");
  c->footer(std::string(R"(
Players are driven by a deterministic script (a function of the seed, the frame and the player), so
the same arguments give the same final hash on every machine.
)") + inject_footer +
            exit_footer);
  c->callback([&exit_code] { exit_code = cli::run_command(run); });

  c = app.add_subcommand(
      "verify", "Re-simulate a replay and compare every frame's hash with the recorded one");
  c->add_option("FILE", verify.files,
                "Replay file(s); more than one, or any of --manifest, --jobs, --shard, verifies "
                "in bulk (below)");
  c->add_option("--manifest", verify.manifest,
                "Verify the replays listed in LIST, one path a line (relative paths are relative "
                "to LIST's directory; blank lines and lines starting with # are skipped)")
      ->type_name("LIST");
  c->add_option("--jobs", verify.jobs,
                "Worker threads (default: the machine's cores); the output's order is the "
                "entries' order whatever N")
      ->type_name("N")
      ->check(CLI::Range(1U, 1024U));
  c->add_option("--shard", verify.shard,
                "Verify only the entries whose index (from 0: the FILEs, then the manifest's "
                "lines) modulo --of is I; I is a number, auto (the first set of "
                "JOB_COMPLETION_INDEX, SLURM_ARRAY_TASK_ID, AWS_BATCH_JOB_ARRAY_INDEX) or "
                "env:NAME")
      ->type_name("I|auto|env:NAME");
  c->add_option("--of", verify.shard_count, "With --shard: the number of shards")
      ->type_name("N")
      ->check(CLI::Range(std::uint64_t{1}, std::uint64_t{1'000'000}));
  c->add_option("--report", verify.report,
                "On a mismatch, write this machine's side as a desync report to FILE: its states "
                "at the first mismatching frame and the one before, the inputs so far (for "
                "detsim bisect)")
      ->type_name("FILE");
  c->add_option("--at", verify.at,
                "With --report: write this machine's state at FRAME instead, whether or not "
                "verification passes (the command bisect asks the other machine to run)")
      ->type_name("FRAME")
      ->check(CLI::Range(std::uint64_t{1}, detsim::cli::max_frames));
  add_inject_option(c, verify.injections);
  c->add_flag("--json", verify.json,
              "Print one JSON object: ok, frames, first_mismatch (null or a frame), report, ...; "
              "in bulk, one object a replay and a summary (below)");
  c->footer(std::string(R"(
Prints the first frame whose hash differs, both hashes, which parts of the state differ (globals,
rng, bodies, contacts) and the last frame both agreed on; also the speed in frames/s. A replay
without its end marker (a recording that stopped early) verifies up to its last complete chunk.

Bulk verification (several FILEs, --manifest, --jobs or --shard): one line a replay, in the
entries' order, each with its result: ok, desync (a frame's hash differs: first_bad_frame),
invalid (unreadable, corrupt, or recorded by a build this one cannot reproduce) or incomplete (no
end marker: the frames it holds reproduce). A bad replay is a result, not a stop. Then a summary.
With --json each line is a JSON object: index, path, result, frames, first_bad_frame (a frame or
null), seconds, scenario, final_hash, message; the last is {"summary": {replays, ok, desync,
invalid, incomplete, frames, seconds, ...}}. The shards of --shard I --of N together are exactly
the entries, each once; results are deterministic, so a scheduler should not retry exit status 1
or 2 (docs/SCALE.md).
)") + inject_footer +
            "\nExit status: 0 every replay reproduced (incomplete ones included); 1 a hash "
            "mismatch (any replay desynced); 2 bad usage, or (with no desync) any replay "
            "unreadable or invalid (the message names what is wrong). --json prints one JSON "
            "object on stdout (in bulk: one a line).");
  c->callback([&exit_code] { exit_code = cli::verify_command(verify); });

  static cli::SeekArgs seek;
  c = app.add_subcommand("seek",
                         "A replay's state at one frame: from the nearest keyframe, re-simulated");
  c->add_option("FILE", seek.file, "Replay file")->required();
  c->add_option("FRAME", seek.frame, "The frame, 0 .. the replay's last")->required();
  c->add_option("--save-state", seek.save_state,
                "Write the state at FRAME (World::save bytes) to FILE, for detsim diff")
      ->type_name("FILE");
  c->add_flag("--json", seek.json,
              "Print one JSON object: ok, frame, hash, recorded_hash, resimulated_frames, state");
  c->footer(std::string(R"(
Restores the keyframe at or before FRAME and re-simulates the recorded inputs up to it (at most one
keyframe interval), then compares the state's hash with the one recorded for FRAME: exit 1 when
they differ (this machine does not reproduce the recording there).
)") + exit_footer);
  c->callback([&exit_code] { exit_code = cli::seek_command(seek); });

  c = app.add_subcommand("info", "Describe a replay: fingerprint, frames, keyframes");
  c->add_option("FILE", info.file, "Replay file")->required();
  c->add_flag("--json", info.json, "Print one JSON object");
  c->footer(exit_footer);
  c->callback([&exit_code] { exit_code = cli::info_command(info); });

  c = app.add_subcommand("bisect",
                         "Find where two records of one match diverged: frame, subsystem, body, "
                         "field");
  c->add_option("A", bisect.a, "A replay or desync report")->required();
  c->add_option("B", bisect.b, "A replay or desync report of the same match")->required();
  c->add_option("--html", bisect.html,
                "Also write a self-contained HTML page: agreement timeline, diff table, top-down "
                "plot of both sides' scenes")
      ->type_name("REPORT");
  c->add_option("--max", bisect.max_fields, "List at most N field differences (default 100)")
      ->type_name("N")
      ->check(CLI::Range(std::size_t{1}, std::size_t{1000000}));
  c->add_flag("--json", bisect.json,
              "Print one JSON object: outcome, first_divergent_frame, last_agreed_frame, diffs "
              "(subsystem, body, field, a, b), ...");
  c->footer(std::string(R"(
A and B are records of the same match from two machines: replays (detsim run --record, netplay
--record) and/or desync reports (netplay --desync-report, verify --report). First the fingerprints
are compared (different runs are reported as such), then the inputs (differing inputs are not a
desync), then the state hashes frame by frame: the first frame that differs, the subsystems that
differ there, and every differing field with both values in decimal and raw hex. Where a side has a
hash but no state at that frame, this machine re-simulates from the last state both agree on and
says which side it agrees with; if neither side's state at the exact frame can be known, the diff
is taken at the first later frame where both are, and the verify command that would give the exact
frame is printed. Exit 0 when the records agree.)") +
            exit_footer);
  c->callback([&exit_code] { exit_code = cli::bisect_command(bisect); });

  c = app.add_subcommand("view", "Write a 3D replay viewer: one HTML page that plays a match");
  c->add_option("RECORD", view.record, "A replay or desync report")->required();
  c->add_option("OTHER", view.other,
                "Optional: a second record of the same match (another machine's), overlaid");
  c->add_option("-o,--out", view.out, "The page to write (default: RECORD with .html)")
      ->type_name("PAGE");
  c->add_option("--from", view.from, "The first frame shown (default 0)")->type_name("FRAME");
  c->add_option("--to", view.to, "The last frame shown (default: the end)")->type_name("FRAME");
  c->add_option("--three", view.three,
                "Where three.js is (Debian libjs-three; default /usr/share/javascript/three)")
      ->type_name("DIR");
  c->add_flag("--json", view.json, "Print one JSON object: page, bytes, frames, bodies, ...");
  c->footer(std::string(R"(
The page is one self-contained file (three.js and the match inlined; it opens offline in any
browser with WebGL): bodies drawn by shape, play/pause, a frame slider, speed, the frame's state
hash and every player's input. The records are re-simulated here, each with its own inputs, and
each is shown with its own stored states where it has them (keyframes, a desync report's states).
Two records of one match are drawn overlaid: from the first frame where they diverge, the bodies
that differ are drawn red and side B's bodies as an orange ghost. Keys: space plays or pauses,
left and right step a frame (with shift: a second), home and end jump. A page URL ending in
#frame=N opens at frame N. docs/VIEWER.md describes the page and its data.)") +
            exit_footer);
  c->callback([&exit_code] { exit_code = cli::view_command(view); });

  c = app.add_subcommand("diff", "Compare two saved states field by field");
  c->add_option("STATE_A", diff.a, "A saved World state (e.g. from synctest --dump)")->required();
  c->add_option("STATE_B", diff.b, "The state to compare it with")->required();
  c->add_option("--max", diff.max_fields, "List at most N differences (default 100)")
      ->type_name("N")
      ->check(CLI::Range(std::size_t{1}, std::size_t{1000000}));
  c->add_option("--scenario", diff.scene.scenario,
                "The scenario whose geometry the states name (hulls, meshes, heightfields, "
                "compounds): needed for states of such a scenario")
      ->type_name("NAME");
  c->add_option("--seed", diff.scene.seed, "With --scenario: its seed (default 1)")->type_name("S");
  c->add_option("--players", diff.scene.players, "With --scenario: its players")->type_name("P");
  c->add_option("--count", diff.scene.count, "With --scenario: its size")->type_name("N");
  c->add_flag("--json", diff.json,
              "Print one JSON object: equal, frame_a, frame_b, hash_a, hash_b, differences "
              "(subsystem, body, field, a, b), omitted, and note when only part was compared");
  c->footer(std::string(R"(
Each difference names the subsystem (globals, geometry, rng, bodies, contacts, joints), the body ID
and the field (position.y, orientation.w, angular_velocity.x, sleep_time, ...) with both values in
decimal and raw hex; a body present in one state only is listed as such. A contact between
sub-shapes (a compound's part, a mesh's triangle) is named contact[OTHER/S/T], as --inject takes it.
A state names its geometry by type and content hash, so states of a scenario with geometry are
restored against that scenario's world: give --scenario (and the --seed, --players, --count it ran
with), e.g. detsim run --scenario rocks --frames 100 --save-state a.state, then
detsim diff a.state b.state --scenario rocks. Geometry that differs between the states is listed
as geometry[N] with its type and content hash on each side. Exit 0 when the states are equal.)") +
            exit_footer);
  c->callback([&exit_code] { exit_code = cli::diff_command(diff); });

  c = app.add_subcommand("synctest",
                         "Every frame, roll back K frames, re-simulate and compare the hashes");
  add_scenario_options(c, synctest.scene);
  c->add_option("--check-distance", synctest.check_distance,
                "Frames to roll back every frame (default 8, at most 600)")
      ->type_name("K");
  c->add_option("--dump", synctest.dump,
                "On a mismatch, write both states of the frame (World::save bytes) to "
                "PREFIX.expected and PREFIX.actual")
      ->type_name("PREFIX");
  c->add_flag("--json", synctest.json,
              "Print one JSON object: ok, frames, first_mismatch (null or a frame), ...");
  c->footer(std::string(R"(
GGPO's sync test: state that save() misses, or a dependence on history, shows up as a hash that a
re-simulation does not reproduce. It names the first such frame.)") +
            exit_footer);
  c->callback([&exit_code] { exit_code = cli::synctest_command(synctest); });

  auto* golden = app.add_subcommand("golden", "Check or rewrite the golden hashes and replays");
  golden->require_subcommand(1);
  golden->footer(R"(
golden/scenarios.txt holds, for every scenario, the state hash at frames 1, 10, 100, 1000 and the
last frame, and the hash of the chain of all frame hashes; golden/replays/ holds replays that must
verify. Every architecture must reproduce them (golden/README.md).)");
  c = golden->add_subcommand("check", "Recompute every golden run and verify the golden replays");
  c->add_option("--dir", golden_check.dir, "Golden directory (default: the source tree's golden/)")
      ->type_name("DIR");
  c->add_flag("--json", golden_check.json, "Print one JSON object: ok, runs, replays, mismatches");
  c->footer(
      std::string("\nA mismatch prints the run, the frame, and the expected and actual hash.") +
      exit_footer);
  c->callback([&exit_code] { exit_code = cli::golden_command(golden_check); });
  c = golden->add_subcommand("update",
                             "Rewrite the golden hashes and replays (on purpose only: say why in "
                             "the commit)");
  c->add_option("--dir", golden_update.dir, "Golden directory (default: the source tree's golden/)")
      ->type_name("DIR");
  c->add_flag("--json", golden_update.json, "Print one JSON object");
  c->footer(exit_footer);
  c->callback([&exit_code] {
    golden_update.update = true;
    exit_code = cli::golden_command(golden_update);
  });

  c = app.add_subcommand("demo",
                         "The main job: a 4-player arena match of bots over a simulated bad "
                         "network, recorded, verified, summarised");
  c->add_option("--scenario", demo.scenario,
                "The match's scenario: any that takes 4 players (default arena; soccar is car "
                "soccer)")
      ->type_name("NAME");
  c->add_option("--frames", demo.frames, "Frames to play (default 1200: 20 s at 60 Hz)")
      ->type_name("N")
      ->check(CLI::Range(std::uint64_t{1}, detsim::cli::max_frames));
  c->add_option("--seed", demo.seed,
                "Seed of the scenario, the bots and the simulated network (default 1)")
      ->type_name("S");
  c->add_option("--record", demo.record,
                "Keep player 0's replay in FILE (default: a temporary file, removed afterwards)")
      ->type_name("FILE");
  c->add_flag("--json", demo.json,
              "Print one JSON object: frames, final_hash, rollbacks, peers_agree, verified, ...");
  c->footer(std::string(R"(
Four players, each with its own game and rollback session, play the scenario over one
simulated network: 50 ms latency each way (100 ms round trip), 20 ms jitter, 5% loss, 1%
duplication, 1% reordering. Time is virtual (nothing sleeps), so the run takes a few seconds and
gives the same result every time. Player 0's confirmed frames are recorded to a replay, which is
then re-simulated and checked frame by frame (detsim verify). Exit status 1 if the peers'
confirmed hashes ever disagree or the replay does not verify.
)") + exit_footer);
  c->callback([&exit_code] { exit_code = cli::demo_command(demo); });

  add_netplay(app, exit_code);
  add_serve(app, exit_code);
}

}  // namespace

namespace detsim::cli {

namespace detail {

int run(int argc, char** argv, std::string_view program, const ExtraCommands& extra) {
  const std::string name(program);
  set_program_name(name);
  CLI::App app{name == "detsim"
                   ? std::string("detsim: deterministic fixed-point simulation core")
                   : name + ": run, record, verify, sync-test, diff and bisect this game's runs " +
                         "(detsim " + std::string(detsim::version) + ")"};
  app.name(name);
  app.set_version_flag("--version", version_text);
  app.require_subcommand(0, 1);
  int exit_code = 0;

  auto* version = app.add_subcommand("version", "Print the detsim version");
  version->callback([] { std::puts(version_text.c_str()); });
  add_scenario_commands(app, exit_code);
  if (extra) extra(app, exit_code);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : exit_usage;
  }
  if (app.get_subcommands().empty()) {
    std::fputs(app.help().c_str(), stderr);
    return exit_usage;
  }
  return exit_code;
}

}  // namespace detail

int run_cli(int argc, char** argv, std::string_view program) {
  return detail::run(argc, argv, program, {});
}

}  // namespace detsim::cli
