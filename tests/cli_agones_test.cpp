// `detsim serve --agones` against a fake Agones SDK sidecar (support/fake_agones_sidecar.hpp,
// written from the Agones SDK REST docs), which records every call and when it came.
//
// AgonesClient (tools/detsim/agones.hpp) alone, with the test as the match loop: the whole
// timeline ready -> health... -> annotations -> shutdown; a sidecar that starts 3 s late; one that
// dies mid-match; a stalled simulation that sends no health. Then the real binary: a short match
// with two clients, and SIGTERM mid-match.
//
// Times are asserted with generous bounds only (order and presence first): the machine may be
// loaded.
#include <signal.h>

#include <chrono>
#include <cstdlib>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include <detsim/net/udp.hpp>

#include "support/cli.hpp"
#include "support/fake_agones_sidecar.hpp"
#include "support/netplay_processes.hpp"
#include "tools/detsim/agones.hpp"

namespace detsim {
namespace {

using Clock = std::chrono::steady_clock;
using cli::AgonesClient;
using cli::AgonesOptions;
using test::FakeAgonesSidecar;
using test::has;
using test::SidecarCall;

double seconds_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

/// The client's notes, collected from its thread.
struct Notes {
  std::mutex mutex;
  std::vector<std::string> lines;
  [[nodiscard]] bool any(const std::string& part) {
    const std::lock_guard lock(mutex);
    for (const std::string& l : lines)
      if (has(l, part)) return true;
    return false;
  }
  [[nodiscard]] std::string all() {
    const std::lock_guard lock(mutex);
    std::string text;
    for (const std::string& l : lines)
      text += l + "\n";
    return text;
  }
};

AgonesOptions options_for(std::uint16_t port, Notes& notes) {
  AgonesOptions o;
  o.port = port;
  o.note = [&notes](const std::string& line) {
    const std::lock_guard lock(notes.mutex);
    notes.lines.push_back(line);
  };
  return o;
}

/// The match loop of a server at 60 fps for `seconds`: advanced() after each frame from `frame`
/// on (or heartbeat() each time round when `waiting`); returns the next frame.
std::uint64_t play(AgonesClient& client, double seconds, std::uint64_t frame,
                   bool waiting = false) {
  const auto end = Clock::now() + std::chrono::duration<double>(seconds);
  while (Clock::now() < end) {
    if (waiting) {
      client.heartbeat();
    } else {
      client.advanced(frame++);
    }
    std::this_thread::sleep_for(std::chrono::microseconds(16'667));
  }
  return frame;
}

std::vector<SidecarCall> named(const std::vector<SidecarCall>& calls, const std::string& name) {
  std::vector<SidecarCall> out;
  for (const SidecarCall& c : calls)
    if (c.name() == name) out.push_back(c);
  return out;
}

/// The value of the annotation `key` among the calls, or "<none>".
std::string annotation(const std::vector<SidecarCall>& calls, const std::string& key) {
  const std::string prefix = R"({"key":")" + key + R"(","value":")";
  for (const SidecarCall& c : named(calls, "PUT /metadata/annotation"))
    if (c.body.rfind(prefix, 0) == 0)
      return c.body.substr(prefix.size(), c.body.size() - prefix.size() - 2);
  return "<none>";
}

TEST(Agones, TheTimelineIsReadyThenHealthThenAnnotationsThenShutdown) {
  FakeAgonesSidecar sidecar;
  ASSERT_TRUE(sidecar.start());
  Notes notes;
  const auto origin = Clock::now();
  {
    AgonesClient client(options_for(sidecar.port(), notes));
    client.ready();
    client.label("detsim.scenario", "arena");
    play(client, 4.5, 1);
    client.annotation("detsim.final-hash", "0123456789abcdef");
    client.annotation("detsim.frames", "270");
    EXPECT_TRUE(client.shutdown());
    const cli::AgonesStats stats = client.stats();
    EXPECT_TRUE(stats.ready);
    EXPECT_TRUE(stats.shutdown);
    EXPECT_EQ(stats.calls_failed, 0U) << notes.all();
    EXPECT_EQ(stats.calls_dropped, 0U);
    EXPECT_EQ(stats.calls_sent, stats.health_pings + 5);
  }
  const std::vector<SidecarCall> calls = sidecar.calls();
  const std::string at = test::timeline(calls, origin);
  ASSERT_GE(calls.size(), 6U) << at;
  EXPECT_EQ(calls[0].name(), "POST /ready") << at;
  EXPECT_EQ(calls[0].body, "{}");
  EXPECT_EQ(calls[1].name(), "PUT /metadata/label") << at;
  EXPECT_EQ(calls[1].body, R"({"key":"detsim.scenario","value":"arena"})");
  // Pings every 2 s while the match advanced: about two in 4.5 s, never closer than a period's
  // worth of scheduling allows.
  const std::size_t n = calls.size();
  const std::vector<SidecarCall> health = named(calls, "POST /health");
  EXPECT_GE(health.size(), 1U) << at;
  EXPECT_LE(health.size(), 3U) << at;
  for (std::size_t i = 2; i < n - 3; ++i)
    EXPECT_EQ(calls[i].name(), "POST /health") << at;
  for (std::size_t i = 1; i < health.size(); ++i)
    EXPECT_GE(seconds_between(health[i - 1].at, health[i].at), 1.0) << at;
  EXPECT_EQ(calls[n - 3].body, R"({"key":"detsim.final-hash","value":"0123456789abcdef"})") << at;
  EXPECT_EQ(calls[n - 2].body, R"({"key":"detsim.frames","value":"270"})") << at;
  EXPECT_EQ(calls[n - 1].name(), "POST /shutdown") << at;
}

TEST(Agones, ASidecarThatStartsThreeSecondsLateStillGetsReadyAndTheMatchGoesOn) {
  const std::uint16_t port = FakeAgonesSidecar::free_port();
  ASSERT_NE(port, 0);
  FakeAgonesSidecar sidecar;
  Notes notes;
  const auto origin = Clock::now();
  AgonesClient client(options_for(port, notes));
  client.ready();
  std::uint64_t frame = play(client, 3.0, 1);
  const auto sidecar_up = Clock::now();
  ASSERT_TRUE(sidecar.start(port)) << "port " << port << " was taken meanwhile";
  frame = play(client, 3.0, frame);
  EXPECT_GE(frame, 300U);  // the loop went on at its pace, sidecar or not (about 360 frames)
  client.annotation("detsim.frames", std::to_string(frame - 1));
  EXPECT_TRUE(client.shutdown()) << notes.all();

  const std::vector<SidecarCall> calls = sidecar.calls();
  const std::string at = test::timeline(calls, origin);
  ASSERT_GE(calls.size(), 3U) << at;
  EXPECT_EQ(calls.front().name(), "POST /ready") << at;
  // Retried with backoff up to 2 s: ready comes within about 2 s of the sidecar (4 s allowed).
  EXPECT_LE(seconds_between(sidecar_up, calls.front().at), 4.0) << at;
  EXPECT_EQ(calls.back().name(), "POST /shutdown") << at;
  EXPECT_EQ(annotation(calls, "detsim.frames"), std::to_string(frame - 1)) << at;
  const cli::AgonesStats stats = client.stats();
  EXPECT_TRUE(stats.ready);
  // Backoff: a handful of refused connections in 3 s (100, 200, 400, 800 ms, ...), not hundreds.
  EXPECT_GE(stats.calls_failed, 2U);
  EXPECT_LE(stats.calls_failed, 12U);
  EXPECT_TRUE(notes.any("trying again, the match goes on")) << notes.all();
  EXPECT_TRUE(notes.any("the sidecar answers again (POST /ready)")) << notes.all();
}

TEST(Agones, ASidecarThatDiesMidMatchNeitherStopsTheMatchNorHoldsTheShutdownPastItsBound) {
  FakeAgonesSidecar sidecar;
  ASSERT_TRUE(sidecar.start());
  Notes notes;
  const auto origin = Clock::now();
  AgonesOptions options = options_for(sidecar.port(), notes);
  options.shutdown_wait = std::chrono::milliseconds(2000);
  AgonesClient client(options);
  client.ready();
  std::uint64_t frame = play(client, 2.5, 1);
  sidecar.stop();
  const auto died = Clock::now();
  frame = play(client, 2.5, frame);
  EXPECT_GE(frame, 250U);  // about 300: the loop never waited for the sidecar
  client.annotation("detsim.final-hash", "00000000deadbeef");
  const auto asked = Clock::now();
  EXPECT_FALSE(client.shutdown());
  // The bound is 2 s here (5 s by default), the calls' timeouts included; 1.5 s for the machine.
  EXPECT_LE(seconds_between(asked, Clock::now()), 3.5);

  const std::vector<SidecarCall> calls = sidecar.calls();
  const std::string at = test::timeline(calls, origin);
  ASSERT_FALSE(calls.empty());
  EXPECT_EQ(calls.front().name(), "POST /ready") << at;
  for (const SidecarCall& c : calls)
    EXPECT_LE(c.at, died) << at;
  const cli::AgonesStats stats = client.stats();
  EXPECT_TRUE(stats.ready);
  EXPECT_FALSE(stats.shutdown);
  EXPECT_GE(stats.calls_failed, 1U);
  EXPECT_EQ(stats.calls_dropped, 2U);  // the annotation and the shutdown
  EXPECT_TRUE(notes.any("gave up after 2000 ms: 2 calls not delivered")) << notes.all();
}

TEST(Agones, AStalledSimulationSendsNoHealthUntilItAdvancesAgain) {
  FakeAgonesSidecar sidecar;
  ASSERT_TRUE(sidecar.start());
  Notes notes;
  const auto origin = Clock::now();
  AgonesClient client(options_for(sidecar.port(), notes));
  client.ready();
  play(client, 2.5, 0, /*waiting=*/true);  // waiting for players: the loop's heartbeat
  std::uint64_t frame = play(client, 1.0, 1);
  const auto stalled = Clock::now();
  std::this_thread::sleep_for(std::chrono::milliseconds(5000));  // no heartbeat, no frame
  const auto resumed = Clock::now();
  frame = play(client, 3.0, frame);
  EXPECT_TRUE(client.shutdown());

  const std::vector<SidecarCall> calls = sidecar.calls();
  const std::string at = test::timeline(calls, origin);
  std::size_t before = 0;
  std::size_t during = 0;
  std::size_t after = 0;
  for (const SidecarCall& c : named(calls, "POST /health")) {
    if (c.at < stalled) {
      ++before;
    } else if (c.at < resumed) {
      ++during;
    } else {
      ++after;
    }
  }
  EXPECT_GE(before, 1U) << at;  // the heartbeat while waiting counts as progress
  // At most the one ping for the frames just before the stall; pinging on a timer alone would
  // send two or three in 5 s.
  EXPECT_LE(during, 1U) << at;
  EXPECT_GE(after, 1U) << at;
}

TEST(Agones, ThePortComesFromAgonesSdkHttpPort) {
  ::unsetenv("AGONES_SDK_HTTP_PORT");
  EXPECT_EQ(cli::agones_port_from_environment().value(), 9358);
  ::setenv("AGONES_SDK_HTTP_PORT", "7001", 1);
  EXPECT_EQ(cli::agones_port_from_environment().value(), 7001);
  for (const char* bad : {"0", "65536", "x", "80a", "-1"}) {
    ::setenv("AGONES_SDK_HTTP_PORT", bad, 1);
    const auto port = cli::agones_port_from_environment();
    EXPECT_FALSE(port.ok()) << bad;
    EXPECT_TRUE(has(port.message(), "AGONES_SDK_HTTP_PORT")) << port.message();
  }
  ::unsetenv("AGONES_SDK_HTTP_PORT");
}

// ---- the real binary -------------------------------------------------------------------------

/// The sidecar's port in the environment the spawned processes inherit.
void point_children_at(const FakeAgonesSidecar& sidecar) {
  ::setenv("AGONES_SDK_HTTP_PORT", std::to_string(sidecar.port()).c_str(), 1);
}

std::vector<std::string> client_args(std::uint16_t server, std::uint16_t me, int bot) {
  return {"netplay",          "--server", test::endpoint(server), "--bind",
          test::endpoint(me), "--bot",    std::to_string(bot)};
}

TEST(AgonesServe, AMatchSendsReadyAfterTheBindHealthTheFinalHashAndShutdownLast) {
  FakeAgonesSidecar sidecar;
  ASSERT_TRUE(sidecar.start());
  point_children_at(sidecar);
  test::TempFile replay("agones_serve.dsr");
  for (int attempt = 0; attempt < 6; ++attempt) {
    const std::uint16_t base = test::port_for(attempt + 140);
    // Ready must come after the server's socket is bound: then this bind of its port fails.
    std::mutex mutex;
    int bound_at_ready = -1;
    sidecar.clear();
    sidecar.on_call([&](const SidecarCall& c) {
      if (c.path != "/ready") return;
      const auto taken =
          net::UdpTransport::open(net::parse_endpoint(test::endpoint(base)).value(), {});
      const std::lock_guard lock(mutex);
      bound_at_ready = taken ? 0 : 1;
    });
    const auto origin = Clock::now();
    test::Process server({"serve", "--agones", "--bind", test::endpoint(base), "--players", "2",
                          "--frames", "240", "--record", replay.path(), "--json"},
                         "agones_server");
    test::Process c0(client_args(base, static_cast<std::uint16_t>(base + 1), 1), "agones_c0");
    test::Process c1(client_args(base, static_cast<std::uint16_t>(base + 2), 2), "agones_c1");
    const bool finished = test::wait_for_both(server, c0, std::chrono::seconds(60)) &&
                          test::wait_for_both(server, c1, std::chrono::seconds(10));
    sidecar.on_call({});
    if (test::bind_failed(server) || test::bind_failed(c0) || test::bind_failed(c1)) continue;
    ASSERT_TRUE(finished) << server.err() << c0.err() << c1.err();
    ASSERT_EQ(server.exit_code(), 0) << server.out() << server.err();
    const std::string hash = test::json_value(server.out(), "final_hash");
    ASSERT_EQ(hash.size(), 16U) << server.out();
    EXPECT_EQ(test::json_value(server.out(), "frames"), "240");
    EXPECT_TRUE(has(server.out(), R"("agones":{"ready":true,)")) << server.out();
    EXPECT_TRUE(has(server.out(), R"("shutdown":true,)")) << server.out();

    const std::vector<SidecarCall> calls = sidecar.calls();
    const std::string at = test::timeline(calls, origin);
    ASSERT_GE(calls.size(), 6U) << at << server.err();
    EXPECT_EQ(calls.front().name(), "POST /ready") << at;
    {
      const std::lock_guard lock(mutex);
      EXPECT_EQ(bound_at_ready, 1) << "ready came before the server's socket was bound";
    }
    EXPECT_GE(named(calls, "POST /health").size(), 1U) << at;
    EXPECT_EQ(annotation(calls, "detsim.final-hash"), hash) << at;
    EXPECT_EQ(annotation(calls, "detsim.frames"), "240") << at;
    EXPECT_EQ(annotation(calls, "detsim.outcome"), "ended") << at;
    EXPECT_EQ(calls.back().name(), "POST /shutdown") << at;
    EXPECT_EQ(named(calls, "POST /shutdown").size(), 1U) << at;
    ::unsetenv("AGONES_SDK_HTTP_PORT");
    return;
  }
  FAIL() << "no free ports after 6 attempts";
}

TEST(AgonesServe, SigtermMidMatchClosesTheReplayAndShutsDown) {
  FakeAgonesSidecar sidecar;
  ASSERT_TRUE(sidecar.start());
  point_children_at(sidecar);
  test::TempFile replay("agones_sigterm.dsr");
  for (int attempt = 0; attempt < 6; ++attempt) {
    const std::uint16_t base = test::port_for(attempt + 160);
    sidecar.clear();
    const auto origin = Clock::now();
    test::Process server({"serve", "--agones", "--bind", test::endpoint(base), "--players", "2",
                          "--frames", "3600", "--record", replay.path()},
                         "sigterm_server");
    test::Process c0(client_args(base, static_cast<std::uint16_t>(base + 1), 1), "sigterm_c0");
    test::Process c1(client_args(base, static_cast<std::uint16_t>(base + 2), 2), "sigterm_c1");
    // Once the match runs (a second in), SIGTERM.
    const auto limit = Clock::now() + std::chrono::seconds(30);
    while (!has(server.out(), "the match starts") && !server.poll() && Clock::now() < limit)
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    if (test::bind_failed(server)) continue;
    ASSERT_TRUE(has(server.out(), "the match starts")) << server.out() << server.err();
    std::this_thread::sleep_for(std::chrono::milliseconds(1000));
    server.signal(SIGTERM);
    const auto exit_limit = Clock::now() + std::chrono::seconds(20);
    while (!server.poll() && Clock::now() < exit_limit)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    ASSERT_TRUE(server.poll()) << "the server did not exit after SIGTERM";
    // Exit status 0: stopping on request is the end the orchestrator asked for.
    EXPECT_EQ(server.exit_code(), 0) << server.out() << server.err();
    const std::string out = server.out();
    const std::size_t at_stop = out.find("stopped      by SIGTERM at frame ");
    ASSERT_NE(at_stop, std::string::npos) << out;
    const std::string frames = out.substr(at_stop + 33, out.find(' ', at_stop + 33) - at_stop - 33);
    EXPECT_NE(frames, "0");
    EXPECT_LT(std::stoull(frames), 3600U);
    // The replay is complete up to the frame the match reached, and reproduces.
    const test::CliResult verify = test::detsim_cli("verify " + replay.path());
    EXPECT_EQ(verify.exit_code, 0) << verify.out << verify.err;
    EXPECT_TRUE(has(verify.out, test::final_hash_of(out))) << verify.out << out;

    const std::vector<SidecarCall> calls = sidecar.calls();
    const std::string at = test::timeline(calls, origin);
    ASSERT_FALSE(calls.empty()) << server.err();
    EXPECT_EQ(calls.front().name(), "POST /ready") << at;
    EXPECT_EQ(annotation(calls, "detsim.outcome"), "stopped") << at;
    EXPECT_EQ(annotation(calls, "detsim.frames"), frames) << at;
    EXPECT_EQ(annotation(calls, "detsim.final-hash"), test::final_hash_of(out)) << at;
    EXPECT_EQ(calls.back().name(), "POST /shutdown") << at;
    ::unsetenv("AGONES_SDK_HTTP_PORT");
    return;
  }
  FAIL() << "no free ports after 6 attempts";
}

TEST(AgonesServe, HelpNamesTheFlagAndItsVariable) {
  const test::CliResult r = test::detsim_cli("serve --help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* part : {"--agones", "AGONES_SDK_HTTP_PORT", "SIGTERM", "detsim.final-hash"})
    EXPECT_TRUE(has(r.out, part)) << part;
  ::setenv("AGONES_SDK_HTTP_PORT", "nonsense", 1);
  const test::CliResult bad = test::detsim_cli("serve --agones --bind 127.0.0.1:0");
  ::unsetenv("AGONES_SDK_HTTP_PORT");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_TRUE(has(bad.err, "AGONES_SDK_HTTP_PORT")) << bad.err;
}

}  // namespace
}  // namespace detsim
