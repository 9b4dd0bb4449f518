// detsim serve and detsim netplay --server between real processes over UDP on 127.0.0.1: a server
// and four bot clients behind lossy relays (loss, delay, duplication), one joining 5 s late and
// one killed and restarted mid-match, all ending on the server's final hash, the server's replay
// verifying; state authority through loss; a stranger spraying forged datagrams; bad usage. The
// same with every field checked, in virtual time: net_server_test.cpp.
#include <chrono>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include <detsim/net/server_protocol.hpp>
#include <detsim/net/udp.hpp>

#include "support/cli.hpp"
#include "support/netplay_processes.hpp"
#include "support/replay_files.hpp"

namespace detsim {
namespace {

using test::bind_failed;
using test::endpoint;
using test::has;
using test::port_for;
using test::Process;
using test::TempFile;

/// The value of "key":"..." (a string) or "key":N in a one-line JSON object, or "".
std::string json_field(const std::string& json, const std::string& key) {
  const std::string quoted = "\"" + key + "\":";
  const std::size_t at = json.find(quoted);
  if (at == std::string::npos) return "";
  std::size_t from = at + quoted.size();
  if (json[from] == '"') {
    const std::size_t end = json.find('"', from + 1);
    return json.substr(from + 1, end - from - 1);
  }
  std::size_t end = from;
  while (end < json.size() && json[end] != ',' && json[end] != '}')
    ++end;
  return json.substr(from, end - from);
}

/// A bad link between one client process and the server: the client talks to the relay's first
/// port as if it were the server, the server sees the relay's second port as the client. Each
/// datagram, either way, is lost with `loss`, sent twice with `duplicate`, and delayed
/// delay_ms +- jitter_ms (so some arrive out of order).
class LossyRelay {
 public:
  struct Conditions {
    double loss = 0.1;
    double duplicate = 0.05;
    int delay_ms = 30;
    int jitter_ms = 10;
  };
  static std::optional<LossyRelay> open(std::uint16_t client_port, std::uint16_t relay_port,
                                        std::uint16_t server_port, Conditions c,
                                        std::uint32_t seed) {
    const auto at = [](std::uint16_t port) { return net::parse_endpoint(endpoint(port)).value(); };
    const net::UdpPeer client[] = {{0, at(client_port)}};
    const net::UdpPeer server[] = {{1, at(server_port)}};
    auto to_client = net::UdpTransport::open(at(relay_port), client);
    auto to_server =
        net::UdpTransport::open(at(static_cast<std::uint16_t>(relay_port + 1)), server);
    if (!to_client || !to_server) return std::nullopt;
    return LossyRelay(std::move(to_client.value()), std::move(to_server.value()), c, seed);
  }
  void pump() {
    const auto now = std::chrono::steady_clock::now();
    take(client_side_, 1, now);
    take(server_side_, 0, now);
    for (auto it = queue_.begin(); it != queue_.end();) {
      if (it->due > now) {
        ++it;
        continue;
      }
      (it->to == 1 ? server_side_ : client_side_).send(it->to, it->bytes);
      it = queue_.erase(it);
    }
  }

 private:
  struct Held {
    std::chrono::steady_clock::time_point due;
    net::PeerId to;
    std::vector<std::uint8_t> bytes;
  };
  LossyRelay(net::UdpTransport client_side, net::UdpTransport server_side, Conditions c,
             std::uint32_t seed)
      : client_side_(std::move(client_side)),
        server_side_(std::move(server_side)),
        conditions_(c),
        random_(seed) {}
  void take(net::UdpTransport& from, net::PeerId to, std::chrono::steady_clock::time_point now) {
    inbox_.clear();
    from.receive(inbox_);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::uniform_int_distribution<int> jitter(-conditions_.jitter_ms, conditions_.jitter_ms);
    for (const net::Datagram& d : inbox_) {
      if (u(random_) < conditions_.loss) continue;
      const int copies = u(random_) < conditions_.duplicate ? 2 : 1;
      for (int k = 0; k < copies; ++k)
        queue_.push_back(
            {now + std::chrono::milliseconds(conditions_.delay_ms + jitter(random_)), to, d.bytes});
    }
  }
  net::UdpTransport client_side_;
  net::UdpTransport server_side_;
  Conditions conditions_;
  std::mt19937 random_;
  std::vector<net::Datagram> inbox_;
  std::vector<Held> queue_;
};

/// Ports: the server at base, client i at base + 10 + i, its relay at base + 20 + 2i (and + 1).
struct Ports {
  std::uint16_t base;
  std::uint16_t server() const { return base; }
  std::uint16_t client(int i) const { return static_cast<std::uint16_t>(base + 10 + i); }
  std::uint16_t relay(int i) const { return static_cast<std::uint16_t>(base + 20 + 2 * i); }
};

std::vector<std::string> client_args(const Ports& p, int i, int bot) {
  return {"netplay",
          "--server",
          endpoint(p.relay(i)),
          "--bind",
          endpoint(p.client(i)),
          "--bot",
          std::to_string(bot),
          "--json",
          "--timeout",
          "30"};
}

/// Pumps every relay and polls every process until all have exited or `limit` passed; true if
/// they all exited. `at(seconds)` runs once per pump (kills and late starts).
bool run_all(std::vector<LossyRelay>& relays, const std::vector<Process*>& processes,
             std::chrono::seconds limit, const std::function<void(double)>& at = {}) {
  const auto start = std::chrono::steady_clock::now();
  for (;;) {
    for (LossyRelay& r : relays)
      r.pump();
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (at) at(seconds);
    bool done = true;
    for (Process* p : processes)
      done = p->poll() && done;
    if (done) return true;
    if (std::chrono::steady_clock::now() - start > limit) return false;
    std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
}

TEST(CliServe, FourClientsOverBadLinksWithALateJoinerAndARestartEndOnTheServersHash) {
  TempFile replay("serve.dsr");
  for (int attempt = 0; attempt < 6; ++attempt) {
    const Ports ports{port_for(attempt + 60)};
    std::vector<LossyRelay> relays;
    for (int i = 0; i < 4; ++i) {
      auto r = LossyRelay::open(ports.client(i), ports.relay(i), ports.server(), {},
                                static_cast<std::uint32_t>(i + 1));
      if (!r) break;
      relays.push_back(std::move(*r));
    }
    if (relays.size() != 4) continue;
    Process server({"serve", "--bind", endpoint(ports.server()), "--players", "4", "--frames",
                    "900", "--wait-for", "3", "--record", replay.path(), "--json"},
                   "serve_server");
    auto c0 = std::make_unique<Process>(client_args(ports, 0, 11), "serve_c0");
    auto c1 = std::make_unique<Process>(client_args(ports, 1, 12), "serve_c1");
    auto c2 = std::make_unique<Process>(client_args(ports, 2, 13), "serve_c2");
    std::unique_ptr<Process> c1_again;
    std::unique_ptr<Process> c3;
    std::vector<Process*> all = {&server, c0.get(), c1.get(), c2.get()};
    // Client 1 is killed at 4 s and started again at 5 s; client 3 starts at 5 s.
    bool killed = false;
    const bool finished = run_all(relays, all, std::chrono::seconds(90), [&](double s) {
      if (!killed && s >= 4.0) {
        c1->kill();
        killed = true;
      }
      if (!c3 && s >= 5.0) {
        c1_again = std::make_unique<Process>(client_args(ports, 1, 12), "serve_c1b");
        c3 = std::make_unique<Process>(client_args(ports, 3, 14), "serve_c3");
        all.push_back(c1_again.get());
        all.push_back(c3.get());
      }
    });
    if (bind_failed(server)) continue;
    ASSERT_TRUE(finished) << server.err() << c0->err() << c2->err();
    ASSERT_EQ(server.exit_code(), 0) << server.out() << server.err();
    const std::string hash = json_field(server.out(), "final_hash");
    ASSERT_EQ(hash.size(), 16U) << server.out();
    EXPECT_EQ(json_field(server.out(), "frames"), "900");
    // How late it simulated its frames (a bucket's upper edge: 100 us at least), and its CPU.
    const std::string p99 = json_field(server.out(), "p99");
    ASSERT_FALSE(p99.empty()) << server.out();
    EXPECT_GE(std::stoull(p99), 100U);
    EXPECT_LE(std::stoull(p99), std::stoull(json_field(server.out(), "max")) + 100);
    EXPECT_GT(std::stod(json_field(server.out(), "cpu_seconds")), 0.0) << server.out();
    for (Process* c : {c0.get(), c2.get(), c1_again.get(), c3.get()}) {
      ASSERT_EQ(c->exit_code(), 0) << c->out() << c->err();
      EXPECT_EQ(json_field(c->out(), "final_hash"), hash) << c->out();
      EXPECT_EQ(json_field(c->out(), "desyncs"), "0") << c->out();
      EXPECT_EQ(json_field(c->out(), "frames"), "900") << c->out();
    }
    // The late one and the restarted one started from a snapshot of the match under way.
    EXPECT_NE(json_field(c3->out(), "snapshots_received"), "0") << c3->out();
    EXPECT_NE(json_field(c1_again->out(), "snapshots_received"), "0") << c1_again->out();
    const test::CliResult verify = test::detsim_cli("verify " + replay.path());
    EXPECT_EQ(verify.exit_code, 0) << verify.out << verify.err;
    EXPECT_TRUE(has(verify.out, hash)) << verify.out;
    return;
  }
  FAIL() << "no free ports after 6 attempts";
}

TEST(CliServe, StateAuthorityThroughLossEndsOnTheServersHash) {
  for (int attempt = 0; attempt < 6; ++attempt) {
    const Ports ports{port_for(attempt + 80)};
    std::vector<LossyRelay> relays;
    for (int i = 0; i < 2; ++i) {
      auto r = LossyRelay::open(ports.client(i), ports.relay(i), ports.server(),
                                {0.05, 0.02, 20, 5}, static_cast<std::uint32_t>(i + 7));
      if (!r) break;
      relays.push_back(std::move(*r));
    }
    if (relays.size() != 2) continue;
    Process server({"serve", "--bind", endpoint(ports.server()), "--players", "2", "--frames",
                    "300", "--authority", "state", "--snapshot-rate", "30", "--json"},
                   "state_server");
    Process c0(client_args(ports, 0, 3), "state_c0");
    Process c1(client_args(ports, 1, 4), "state_c1");
    const bool finished = run_all(relays, {&server, &c0, &c1}, std::chrono::seconds(60));
    if (bind_failed(server)) continue;
    ASSERT_TRUE(finished) << server.err() << c0.err() << c1.err();
    ASSERT_EQ(server.exit_code(), 0) << server.out() << server.err();
    const std::string hash = json_field(server.out(), "final_hash");
    for (Process* c : {&c0, &c1}) {
      ASSERT_EQ(c->exit_code(), 0) << c->out() << c->err();
      EXPECT_EQ(json_field(c->out(), "final_hash"), hash) << c->out();
      EXPECT_EQ(json_field(c->out(), "desyncs"), "0") << c->out();
      EXPECT_NE(json_field(c->out(), "snapshots_received"), "0") << c->out();
    }
    return;
  }
  FAIL() << "no free ports after 6 attempts";
}

TEST(CliServe, AStrangerSprayingForgedDatagramsChangesNoClientsOutcome) {
  for (int attempt = 0; attempt < 6; ++attempt) {
    const Ports ports{port_for(attempt + 100)};
    std::vector<LossyRelay> relays;
    for (int i = 0; i < 2; ++i) {
      auto r = LossyRelay::open(ports.client(i), ports.relay(i), ports.server(), {0, 0, 5, 0},
                                static_cast<std::uint32_t>(i + 1));
      if (!r) break;
      relays.push_back(std::move(*r));
    }
    if (relays.size() != 2) continue;
    const net::UdpPeer server_peer[] = {{0, net::parse_endpoint(endpoint(ports.server())).value()}};
    auto stranger = net::UdpTransport::open(
        net::parse_endpoint(endpoint(static_cast<std::uint16_t>(ports.base + 40))).value(),
        server_peer);
    if (!stranger) continue;
    Process server({"serve", "--bind", endpoint(ports.server()), "--players", "2", "--frames",
                    "300", "--json"},
                   "forge_server");
    Process c0(client_args(ports, 0, 3), "forge_c0");
    Process c1(client_args(ports, 1, 4), "forge_c1");
    std::uint64_t n = 0;
    const bool finished =
        run_all(relays, {&server, &c0, &c1}, std::chrono::seconds(60), [&](double) {
          // Inputs under guessed tokens, a connect for another game, and garbage.
          namespace sp = net::server_protocol;
          sp::Packet p;
          p.header.type = sp::PacketType::input;
          p.header.token = 0x1234'5678'9ABC'DEF0ULL + n;
          p.input.start = static_cast<std::uint32_t>(n);
          p.input.count = 1;
          p.input.inputs = {1, 2, 3};
          std::vector<std::uint8_t> out;
          if (sp::encode(p, {2, 3}, out)) stranger->send(0, out);
          p.header.type = sp::PacketType::connect;
          p.header.token = 0;
          p.connect = {0xBAD, n, sp::any_seat};
          if (sp::encode(p, {2, 3}, out)) stranger->send(0, out);
          stranger->send(0, std::vector<std::uint8_t>(64, static_cast<std::uint8_t>(n)));
          ++n;
        });
    if (bind_failed(server)) continue;
    ASSERT_TRUE(finished) << server.err() << c0.err() << c1.err();
    ASSERT_EQ(server.exit_code(), 0) << server.out() << server.err();
    const std::string hash = json_field(server.out(), "final_hash");
    for (Process* c : {&c0, &c1}) {
      ASSERT_EQ(c->exit_code(), 0) << c->out() << c->err();
      EXPECT_EQ(json_field(c->out(), "final_hash"), hash) << c->out();
    }
    // Counted, never taken: the honest clients' packets were all accepted.
    EXPECT_NE(json_field(server.out(), "dropped_unknown"), "0") << server.out();
    EXPECT_NE(json_field(server.out(), "dropped_malformed"), "0") << server.out();
    EXPECT_TRUE(has(server.out(), "\"packets_rejected\":0")) << server.out();
    EXPECT_FALSE(has(server.out(), "\"packets_rejected\":1")) << server.out();
    EXPECT_GT(n, 100U);
    return;
  }
  FAIL() << "no free ports after 6 attempts";
}

TEST(CliServe, AnInjectedClientDesyncsAndBisectAgainstTheServersReplayNamesTheField) {
  // Client 1's machine changes body 7's position at frame 300: it reports a desync against the
  // server's hashes and writes its side; bisect of the server's replay and that report names
  // exactly that change. The server and the honest client are unaffected.
  TempFile replay("desync_server.dsr");
  TempFile report("desync_client.dsd");
  for (int attempt = 0; attempt < 6; ++attempt) {
    const Ports ports{port_for(attempt + 120)};
    Process server({"serve", "--bind", endpoint(ports.server()), "--players", "2", "--frames",
                    "600", "--fps", "240", "--record", replay.path(), "--json"},
                   "desync_server");
    Process honest({"netplay", "--server", endpoint(ports.server()), "--bind",
                    endpoint(ports.client(0)), "--bot", "3", "--json"},
                   "desync_honest");
    Process faulty({"netplay", "--server", endpoint(ports.server()), "--bind",
                    endpoint(ports.client(1)), "--bot", "4", "--json", "--inject",
                    "300:7:position.y:0.001", "--desync-report", report.path()},
                   "desync_faulty");
    std::vector<LossyRelay> none;
    const bool finished = run_all(none, {&server, &honest, &faulty}, std::chrono::seconds(60));
    if (bind_failed(server)) continue;
    ASSERT_TRUE(finished) << server.err() << honest.err() << faulty.err();
    EXPECT_EQ(server.exit_code(), 0) << server.err();
    EXPECT_EQ(honest.exit_code(), 0) << honest.out() << honest.err();
    EXPECT_EQ(json_field(honest.out(), "desyncs"), "0");
    EXPECT_EQ(faulty.exit_code(), 1) << faulty.out() << faulty.err();
    EXPECT_NE(json_field(faulty.out(), "desyncs"), "0") << faulty.out();
    EXPECT_EQ(json_field(faulty.out(), "desync_report"), report.path()) << faulty.out();
    EXPECT_TRUE(has(faulty.err(), "DESYNC with the server")) << faulty.err();
    const test::CliResult r =
        test::detsim_cli("bisect " + replay.path() + " " + report.path() + " --json");
    EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
    EXPECT_EQ(json_field(r.out, "outcome"), "diverged") << r.out;
    EXPECT_EQ(json_field(r.out, "first_divergent_frame"), "300") << r.out;
    EXPECT_TRUE(has(r.out, R"("diffs":[{"subsystem":"bodies","body":7,"field":"position.y",)"))
        << r.out;
    const test::CliResult verify = test::detsim_cli("verify " + replay.path());
    EXPECT_EQ(verify.exit_code, 0) << verify.out << verify.err;
    return;
  }
  FAIL() << "no free ports after 6 attempts";
}

TEST(CliServe, BadUsageExitsWithTwoAndNamesTheProblem) {
  const auto fails = [](const std::string& args, const std::string& needle) {
    const test::CliResult r = test::detsim_cli(args);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.out << r.err;
    EXPECT_TRUE(has(r.err, needle)) << args << "\n" << r.err;
  };
  fails("serve", "--bind");
  fails("serve --bind 127.0.0.1:0 --authority bogus", "--authority");
  fails("serve --bind 127.0.0.1:0 --players 0", "--players");
  fails("serve --bind 127.0.0.1:0 --players 2 --wait-for 3", "--wait-for");
  fails("serve --bind 127.0.0.1:0 --snapshot-rate 0", "--snapshot-rate");
  fails("serve --bind 127.0.0.1:0 --scenario bounce", "takes no players");
  fails("serve --bind 127.0.0.1:0 --scenario nosuch", "nosuch");
  fails("serve --bind nonsense", "--bind");
  fails("serve --bind 127.0.0.1:0 --timeout 0.2", "no match");
  fails("netplay --server 127.0.0.1:9 --bind 127.0.0.1:0 --peer 1=127.0.0.1:9", "--server");
  fails("netplay --server 127.0.0.1:9 --bind 127.0.0.1:0 --record x.dsr", "the server records");
  fails("netplay --server 127.0.0.1:9 --bind 127.0.0.1:0 --timeout 0.3", "no answer");
}

TEST(CliServe, HelpDescribesEveryOption) {
  const test::CliResult r = test::detsim_cli("serve --help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* option :
       {"--bind", "--players", "--frames", "--scenario", "--seed", "--authority", "--snapshot-rate",
        "--fps", "--wait-for", "--timeout", "--record", "--json", "Exit status"})
    EXPECT_TRUE(has(r.out, option)) << option;
  const test::CliResult n = test::detsim_cli("netplay --help");
  EXPECT_TRUE(has(n.out, "--server")) << n.out;
}

}  // namespace
}  // namespace detsim
