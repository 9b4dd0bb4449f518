// Netplay matches that survive, between real processes over UDP on 127.0.0.1: a player killed
// and started again with --rejoin (of two, and of three), a late player joining an --open-seat,
// and an 8-second outage
// under --partition pause. Each ends with the same final hash on both processes. The same on the
// simulated network, with every field checked: net_rejoin_test.cpp.
#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include <detsim/net/protection.hpp>

#include "support/cli.hpp"
#include "support/netplay_processes.hpp"
#include "support/replay_files.hpp"

namespace detsim {
namespace {

using test::bind_failed;
using test::endpoint;
using test::final_hash_of;
using test::has;
using test::port_for;
using test::Process;
using test::read_bytes;
using test::Relay;
using test::RelayedPair;
using test::run_through_relay;
using test::TempFile;
using test::wait_for_both;
const char* const test_key = test::netplay_test_key;

TEST(CliNetplay, AKilledPlayerRestartedWithRejoinFinishesTheMatchWithTheSameHash) {
  // Player 1's process is killed 4 s into a sealed match and started again a second later with
  // --rejoin: it takes its seat from player 0's snapshot, and both finish on one final hash.
  // Both record: the rejoined process re-simulates the frames before its return from the
  // snapshot's log, so the two replays are the same bytes.
  if (!net::protection::available()) GTEST_SKIP() << "built without libsodium: no --key";
  TempFile replay_a("rejoin_a.dsr");
  TempFile replay_b("rejoin_b.dsr");
  for (int attempt = 0; attempt < 6; ++attempt) {
    const std::uint16_t port_a = port_for(attempt + 40);
    const auto port_b = static_cast<std::uint16_t>(port_a + 1);
    const std::vector<std::string> common = {"netplay", "--players", "2",     "--frames",
                                             "900",     "--key",     test_key};
    std::vector<std::string> a = common;
    std::vector<std::string> b = common;
    for (const std::string& arg :
         {std::string("--me"), std::string("0"), std::string("--bot"), std::string("21"),
          std::string("--bind"), endpoint(port_a), std::string("--peer"), "1=" + endpoint(port_b),
          std::string("--record"), replay_a.path()})
      a.push_back(arg);
    for (const std::string& arg :
         {std::string("--me"), std::string("1"), std::string("--bot"), std::string("22"),
          std::string("--bind"), endpoint(port_b), std::string("--peer"), "0=" + endpoint(port_a)})
      b.push_back(arg);
    Process stayer(a, "rejoin_a");
    auto first = std::make_unique<Process>(b, "rejoin_b1");
    std::this_thread::sleep_for(std::chrono::seconds(4));
    if (stayer.poll() || first->poll()) {
      if (bind_failed(stayer) || bind_failed(*first)) continue;  // a port in use: other ports
      FAIL() << "a process ended early: " << stayer.err() << first->err();
    }
    first->kill();
    std::this_thread::sleep_for(std::chrono::seconds(1));
    std::vector<std::string> again = b;
    again.insert(again.end(), {"--rejoin", "--record", replay_b.path()});
    Process rejoiner(again, "rejoin_b2");
    ASSERT_TRUE(wait_for_both(stayer, rejoiner, std::chrono::seconds(90)))
        << stayer.err() << rejoiner.err();
    ASSERT_EQ(stayer.exit_code(), 0) << stayer.out() << stayer.err();
    ASSERT_EQ(rejoiner.exit_code(), 0) << rejoiner.out() << rejoiner.err();
    EXPECT_TRUE(has(stayer.err(), "rejoined at frame")) << stayer.err();
    EXPECT_TRUE(has(rejoiner.out(), "rejoined the match at frame")) << rejoiner.out();
    EXPECT_TRUE(has(rejoiner.out(), "frames       900,")) << rejoiner.out();
    EXPECT_TRUE(has(rejoiner.out(), "desyncs      0")) << rejoiner.out();
    EXPECT_FALSE(has(stayer.err() + rejoiner.err(), "UNVERIFIED"));
    const std::string hash = final_hash_of(stayer.out());
    EXPECT_EQ(hash.size(), 16U) << stayer.out();
    EXPECT_EQ(final_hash_of(rejoiner.out()), hash) << stayer.out() << rejoiner.out();
    const std::vector<std::uint8_t> recorded = read_bytes(replay_a.path());
    EXPECT_FALSE(recorded.empty());
    EXPECT_TRUE(recorded == read_bytes(replay_b.path())) << "the two players' replays differ";
    const test::CliResult verify = test::detsim_cli("verify " + replay_b.path());
    EXPECT_EQ(verify.exit_code, 0) << verify.out << verify.err;
    return;
  }
  FAIL() << "no free ports after 6 attempts";
}

TEST(CliNetplay, AKilledPlayerOfThreeRestartedWithRejoinFinishesWithEveryoneOnOneHash) {
  // Three processes, sealed; player 2's is killed 4 s in and started again with --rejoin, 1 s
  // later (its seat still held: the new process's arrival disconnects the old one) or 7 s later
  // (past the 5 s timeout: players 0 and 1 play on without it). Players 0 and 1 agree on the
  // frame the old process is gone from, one of them serves the snapshot and both take player 2
  // back at the same frame: all three end on one final hash, with every hash check compared.
  if (!net::protection::available()) GTEST_SKIP() << "built without libsodium: no --key";
  for (const int down_seconds : {1, 7}) {
    SCOPED_TRACE("down " + std::to_string(down_seconds) + " s");
    bool played = false;
    for (int attempt = 0; attempt < 6 && !played; ++attempt) {
      const std::uint16_t base = port_for(attempt + 60);
      std::vector<std::vector<std::string>> args(3);
      for (std::uint32_t p = 0; p < 3; ++p) {
        args[p] = {"netplay",
                   "--players",
                   "3",
                   "--frames",
                   "900",
                   "--key",
                   test_key,
                   "--me",
                   std::to_string(p),
                   "--bot",
                   std::to_string(31 + p),
                   "--bind",
                   endpoint(static_cast<std::uint16_t>(base + p))};
        for (std::uint32_t q = 0; q < 3; ++q)
          if (q != p)
            args[p].insert(args[p].end(),
                           {"--peer", std::to_string(q) + "=" +
                                          endpoint(static_cast<std::uint16_t>(base + q))});
      }
      Process zero(args[0], "rejoin3_a");
      Process one(args[1], "rejoin3_b");
      auto first = std::make_unique<Process>(args[2], "rejoin3_c1");
      std::this_thread::sleep_for(std::chrono::seconds(4));
      if (zero.poll() || one.poll() || first->poll()) {
        if (bind_failed(zero) || bind_failed(one) || bind_failed(*first)) continue;  // other ports
        FAIL() << "a process ended early: " << zero.err() << one.err() << first->err();
      }
      first->kill();
      std::this_thread::sleep_for(std::chrono::seconds(down_seconds));
      std::vector<std::string> again = args[2];
      again.push_back("--rejoin");
      Process rejoiner(again, "rejoin3_c2");
      ASSERT_TRUE(wait_for_both(zero, rejoiner, std::chrono::seconds(90)))
          << zero.err() << rejoiner.err();
      ASSERT_TRUE(wait_for_both(one, rejoiner, std::chrono::seconds(30))) << one.err();
      for (const Process* p : {&zero, &one, &rejoiner}) {
        ASSERT_EQ(p->exit_code(), 0) << p->out() << p->err();
        EXPECT_TRUE(has(p->out(), "desyncs      0")) << p->out();
        EXPECT_FALSE(has(p->err(), "UNVERIFIED")) << p->err();
      }
      EXPECT_TRUE(has(zero.err(), "rejoined at frame")) << zero.err();
      EXPECT_TRUE(has(one.err(), "rejoined at frame")) << one.err();
      EXPECT_TRUE(has(rejoiner.out(), "rejoined the match at frame")) << rejoiner.out();
      EXPECT_TRUE(has(rejoiner.out(), "frames       900,")) << rejoiner.out();
      const std::string hash = final_hash_of(zero.out());
      EXPECT_EQ(hash.size(), 16U) << zero.out();
      EXPECT_EQ(final_hash_of(one.out()), hash) << one.out();
      EXPECT_EQ(final_hash_of(rejoiner.out()), hash) << zero.out() << rejoiner.out();
      for (const Process* p : {&zero, &one}) {
        EXPECT_TRUE(has(p->err(), down_seconds == 1
                                      ? "restarted: its old process is gone from frame"
                                      : "the match goes on without it"))
            << p->err();
      }
      played = true;
    }
    EXPECT_TRUE(played) << "no free ports after 6 attempts";
  }
}

TEST(CliNetplay, APlayerJoinsAnOpenSeatLateAndBothFinishWithTheSameHash) {
  // Player 0 starts alone with --open-seat; player 1 starts 3 s later with --join and plays from
  // the present on. Both finish the 600 frames on one hash.
  for (int attempt = 0; attempt < 6; ++attempt) {
    const std::uint16_t port_a = port_for(attempt + 50);
    const auto port_b = static_cast<std::uint16_t>(port_a + 1);
    Process host({"netplay", "--players", "2", "--frames", "600", "--me", "0", "--bot", "31",
                  "--open-seat", "--bind", endpoint(port_a), "--peer", "1=" + endpoint(port_b)},
                 "open_a");
    std::this_thread::sleep_for(std::chrono::seconds(3));
    if (host.poll()) {
      if (bind_failed(host)) continue;
      FAIL() << "the host ended early: " << host.out() << host.err();
    }
    Process joiner({"netplay", "--players", "2", "--frames", "600", "--me", "1", "--bot", "32",
                    "--join", "--bind", endpoint(port_b), "--peer", "0=" + endpoint(port_a)},
                   "open_b");
    const bool both = wait_for_both(host, joiner, std::chrono::seconds(60));
    if (bind_failed(joiner)) continue;
    ASSERT_TRUE(both) << host.err() << joiner.err();
    EXPECT_EQ(host.exit_code(), 0) << host.out() << host.err();
    EXPECT_EQ(joiner.exit_code(), 0) << joiner.out() << joiner.err();
    EXPECT_TRUE(has(host.out(), "seat is open")) << host.out();
    EXPECT_TRUE(has(host.err(), "rejoined at frame")) << host.err();
    EXPECT_TRUE(has(joiner.out(), "rejoined the match at frame")) << joiner.out();
    EXPECT_FALSE(has(host.err() + joiner.err(), "UNVERIFIED"));
    const std::string hash = final_hash_of(host.out());
    EXPECT_EQ(hash.size(), 16U) << host.out();
    EXPECT_EQ(final_hash_of(joiner.out()), hash) << host.out() << joiner.out();
    return;
  }
  FAIL() << "no free ports after 6 attempts";
}

TEST(CliNetplay, AnEightSecondOutageUnderPauseEndsWithTheSameHashOnBothSides) {
  // The outage over UDP: a relay drops everything both ways for 8 s, 3 s into the match.
  // With --partition pause neither side gives the other up; both wait, go on and agree.
  std::optional<std::chrono::steady_clock::time_point> start;
  std::uint64_t dropped = 0;
  const Relay::Edit outage = [&](int, std::uint64_t, const Relay::Bytes& in,
                                 std::vector<Relay::Bytes>& out) {
    const auto now = std::chrono::steady_clock::now();
    if (!start) start = now;
    const auto since = now - *start;
    if (since >= std::chrono::seconds(3) && since < std::chrono::seconds(11)) {
      ++dropped;
      return;
    }
    out.push_back(in);
  };
  const RelayedPair pair = run_through_relay(
      {"--frames", "600", "--bot", "5", "--partition", "pause"}, outage, "outage");
  ASSERT_TRUE(pair.a && pair.b);
  ASSERT_TRUE(pair.finished) << pair.a->err() << pair.b->err();
  EXPECT_GT(dropped, 100U);
  for (const Process* p : {pair.a.get(), pair.b.get()}) {
    EXPECT_EQ(p->exit_code(), 0) << p->out() << p->err();
    EXPECT_TRUE(has(p->err(), "paused at frame")) << p->err();
    EXPECT_TRUE(has(p->err(), "is back")) << p->err();
    EXPECT_FALSE(has(p->err(), "disconnected")) << p->err();
    EXPECT_TRUE(has(p->out(), "frames       600,")) << p->out();
  }
  const std::string hash = final_hash_of(pair.a->out());
  EXPECT_EQ(hash.size(), 16U) << pair.a->out();
  EXPECT_EQ(final_hash_of(pair.b->out()), hash);
}

}  // namespace
}  // namespace detsim
