// Test support for the netplay tests: `detsim netplay` (or a game's tool) run as real processes
// on 127.0.0.1 — started in the background, on ports derived from the test's pid and retried
// when taken — and a UDP relay between two of them that can edit, drop or reorder their datagrams.
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include <detsim/net/udp.hpp>

#include "support/cli.hpp"
#include "support/replay_files.hpp"

extern char** environ;  // POSIX: the environment passed on to the spawned processes

namespace detsim::test {

/// The match key the netplay tests play with (64 hex digits).
inline constexpr const char* netplay_test_key =
    "8f2c0d41b6e97a3355c1e0f4a9d27b6803e5c19a7f4d2b60e1a8c3f5970b2d4e";

/// A detsim process started in the background, its stdout and stderr going to files.
class Process {
 public:
  Process(const std::vector<std::string>& args, const std::string& name,
          const std::string& binary = test::detsim_binary())
      : out_(name + ".out"), err_(name + ".err") {
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&actions, 1, out_.path().c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                     0644);
    posix_spawn_file_actions_addopen(&actions, 2, err_.path().c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                     0644);
    std::vector<std::string> all = {binary};
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& a : all)
      argv.push_back(a.data());
    argv.push_back(nullptr);
    if (posix_spawn(&pid_, binary.c_str(), &actions, nullptr, argv.data(), environ) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&actions);
  }
  ~Process() { kill(); }
  Process(const Process&) = delete;
  Process& operator=(const Process&) = delete;

  /// True once the process has exited (its exit code is then exit_code()).
  bool poll() {
    if (pid_ < 0) return true;
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) != pid_) return false;
    exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    pid_ = -1;
    return true;
  }
  /// Kills the process (this one, by its id) if it still runs.
  void kill() {
    if (pid_ < 0) return;
    ::kill(pid_, SIGKILL);
    int status = 0;
    waitpid(pid_, &status, 0);
    pid_ = -1;
  }
  /// Sends `sig` to the process (this one, by its id) if it still runs.
  void signal(int sig) {
    if (pid_ >= 0) ::kill(pid_, sig);
  }
  [[nodiscard]] int exit_code() const { return exit_code_; }
  [[nodiscard]] std::string out() const { return read_text(out_.path()); }
  [[nodiscard]] std::string err() const { return read_text(err_.path()); }

 private:
  TempFile out_;
  TempFile err_;
  pid_t pid_ = -1;
  int exit_code_ = -1;  ///< -1: killed, killed by a signal, or not started
};

/// Ports for this test process: even numbers in 20000 .. 59998 derived from the pid, so that
/// concurrent test runs rarely collide; attempt k moves on to other ports.
inline std::uint16_t port_for(int attempt) {
  const auto pid = static_cast<std::uint32_t>(getpid());
  const std::uint32_t slot =
      (pid * 2'654'435'761U + static_cast<std::uint32_t>(attempt) * 7919U) % 20'000U;
  return static_cast<std::uint16_t>(20'000U + slot * 2U);
}

inline std::string endpoint(std::uint16_t port) {
  return "127.0.0.1:" + std::to_string(port);
}

inline bool bind_failed(const Process& p) {
  return p.exit_code() == 2 && has(p.err(), "bind 127.0.0.1:");
}

/// Netplay processes started together: `commands(base)` gives each one's arguments for ports
/// base, base + 1, ... Retries on other ports when a bind fails; kills all after `limit`.
struct Group {
  std::vector<std::unique_ptr<Process>> processes;
  bool timed_out = false;
};

using Commands = std::function<std::vector<std::vector<std::string>>(std::uint16_t base)>;

inline Group run_group(const Commands& commands, std::chrono::seconds limit,
                       const std::string& binary = test::detsim_binary()) {
  Group group;
  for (int attempt = 0; attempt < 6; ++attempt) {
    const std::vector<std::vector<std::string>> args = commands(port_for(attempt));
    group.processes.clear();
    group.timed_out = false;
    for (std::size_t i = 0; i < args.size(); ++i)
      group.processes.push_back(
          std::make_unique<Process>(args[i], "netplay_" + std::to_string(i), binary));
    const auto deadline = std::chrono::steady_clock::now() + limit;
    bool retry = false;
    for (;;) {
      bool all_done = true;
      for (const auto& p : group.processes) {
        const bool done = p->poll();
        all_done = all_done && done;
        if (done && bind_failed(*p)) retry = true;  // a port in use: try other ports
      }
      if (retry || all_done) break;
      if (std::chrono::steady_clock::now() > deadline) {
        group.timed_out = true;
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    for (const auto& p : group.processes)
      p->kill();
    if (!retry) return group;
  }
  return group;
}

/// Two netplay processes, players 0 and 1, each with its own extra arguments, on fresh ports.
struct Pair {
  std::unique_ptr<Process> a;
  std::unique_ptr<Process> b;
  bool timed_out = false;
};

inline Pair run_pair(const std::vector<std::string>& extra_a,
                     const std::vector<std::string>& extra_b, std::chrono::seconds limit,
                     const std::string& binary = test::detsim_binary()) {
  const auto commands = [&](std::uint16_t port_a) {
    const auto port_b = static_cast<std::uint16_t>(port_a + 1);
    std::vector<std::string> args_a = {"netplay",        "--players", "2",
                                       "--me",           "0",         "--bind",
                                       endpoint(port_a), "--peer",    "1=" + endpoint(port_b)};
    std::vector<std::string> args_b = {"netplay",        "--players", "2",
                                       "--me",           "1",         "--bind",
                                       endpoint(port_b), "--peer",    "0=" + endpoint(port_a)};
    args_a.insert(args_a.end(), extra_a.begin(), extra_a.end());
    args_b.insert(args_b.end(), extra_b.begin(), extra_b.end());
    return std::vector<std::vector<std::string>>{args_a, args_b};
  };
  Group group = run_group(commands, limit, binary);
  return Pair{std::move(group.processes[0]), std::move(group.processes[1]), group.timed_out};
}

/// A relay between two netplay processes: player 0 talks to it as if it were player 1 and player
/// 1 as if it were player 0. Each datagram goes through `edit(direction, n, bytes, out)`
/// (direction 0: from A to B; n counts that direction's datagrams), which appends what to forward
/// to `out`: nothing (drop), the bytes changed, copies, or datagrams held back from before.
class Relay {
 public:
  using Bytes = std::vector<std::uint8_t>;
  using Edit =
      std::function<void(int direction, std::uint64_t n, const Bytes& in, std::vector<Bytes>& out)>;
  static std::optional<Relay> open(std::uint16_t port_a, std::uint16_t port_b,
                                   std::uint16_t relay_port, Edit edit) {
    const auto at = [](std::uint16_t port) { return net::parse_endpoint(endpoint(port)).value(); };
    const net::UdpPeer a[] = {{0, at(port_a)}};
    const net::UdpPeer b[] = {{1, at(port_b)}};
    auto to_b = net::UdpTransport::open(at(relay_port), a);  // receives from A, sends to A
    auto to_a = net::UdpTransport::open(at(static_cast<std::uint16_t>(relay_port + 1)), b);
    if (!to_b || !to_a) return std::nullopt;
    return Relay(std::move(to_b.value()), std::move(to_a.value()), std::move(edit));
  }
  /// Forwards what arrived since the last call.
  void pump() {
    forward(from_a_, from_b_, 1, 0);
    forward(from_b_, from_a_, 0, 1);
  }

 private:
  Relay(net::UdpTransport a, net::UdpTransport b, Edit edit)
      : from_a_(std::move(a)), from_b_(std::move(b)), edit_(std::move(edit)) {}
  void forward(net::UdpTransport& in, net::UdpTransport& out, net::PeerId to, int direction) {
    inbox_.clear();
    in.receive(inbox_);
    for (const net::Datagram& d : inbox_) {
      outbox_.clear();
      edit_(direction, count_[direction]++, d.bytes, outbox_);
      for (const Bytes& bytes : outbox_)
        out.send(to, bytes);
    }
  }
  net::UdpTransport from_a_;
  net::UdpTransport from_b_;
  Edit edit_;
  std::uint64_t count_[2] = {0, 0};
  std::vector<net::Datagram> inbox_;
  std::vector<Bytes> outbox_;
};

/// Two netplay processes, players 0 and 1, talking through a relay that `edit`s their datagrams
/// (`common` are both processes' further arguments), run until both exit or 60 s passed.
struct RelayedPair {
  std::unique_ptr<Process> a;
  std::unique_ptr<Process> b;
  bool finished = false;
};

inline RelayedPair run_through_relay(const std::vector<std::string>& common,
                                     const Relay::Edit& edit, const std::string& name) {
  for (int attempt = 0; attempt < 6; ++attempt) {
    const std::uint16_t base = port_for(attempt + 20);
    auto relay = Relay::open(base, static_cast<std::uint16_t>(base + 1),
                             static_cast<std::uint16_t>(base + 2), edit);
    if (!relay) continue;
    std::vector<std::string> a = {
        "netplay",      "--players", "2",
        "--me",         "0",         "--bind",
        endpoint(base), "--peer",    "1=" + endpoint(static_cast<std::uint16_t>(base + 2))};
    std::vector<std::string> b = {"netplay",
                                  "--players",
                                  "2",
                                  "--me",
                                  "1",
                                  "--bind",
                                  endpoint(static_cast<std::uint16_t>(base + 1)),
                                  "--peer",
                                  "0=" + endpoint(static_cast<std::uint16_t>(base + 3))};
    a.insert(a.end(), common.begin(), common.end());
    b.insert(b.end(), common.begin(), common.end());
    RelayedPair pair{std::make_unique<Process>(a, name + "_a"),
                     std::make_unique<Process>(b, name + "_b"), false};
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    bool done_a = false;
    bool done_b = false;
    while (!(done_a && done_b) && std::chrono::steady_clock::now() < deadline) {
      relay->pump();
      done_a = done_a || pair.a->poll();
      done_b = done_b || pair.b->poll();
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    if (bind_failed(*pair.a) || bind_failed(*pair.b)) continue;
    pair.finished = done_a && done_b;
    return pair;
  }
  ADD_FAILURE() << "no free ports after 6 attempts";
  return {};
}

/// The 16 hex digits after "final hash " in netplay's text report, or "" without one.
inline std::string final_hash_of(const std::string& out) {
  const std::size_t at = out.find("final hash ");
  return at == std::string::npos ? "" : out.substr(at + 11, 16);
}

/// Polls `a` and `b` until both exited or `limit` passed; true when both exited.
inline bool wait_for_both(Process& a, Process& b, std::chrono::seconds limit) {
  const auto deadline = std::chrono::steady_clock::now() + limit;
  bool done_a = false;
  bool done_b = false;
  while (!(done_a && done_b) && std::chrono::steady_clock::now() < deadline) {
    done_a = done_a || a.poll();
    done_b = done_b || b.poll();
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return done_a && done_b;
}

}  // namespace detsim::test
