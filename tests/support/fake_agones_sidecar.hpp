// A stand-in for the Agones SDK sidecar, for tests: its REST API as the Agones docs describe it
// ("SDK REST API": POST /ready, /health, /shutdown; PUT /metadata/label, /metadata/annotation
// with {"key":K,"value":V}; GET /gameserver), served by cpp-httplib on 127.0.0.1 from a thread of
// its own. Every call is answered 200 and {} (GET /gameserver: a minimal GameServer in state
// Ready), and recorded with the time it came. httplib.h stays in fake_agones_sidecar.cpp.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace detsim::test {

struct SidecarCall {
  std::string method;  ///< "POST", "PUT", "GET"
  std::string path;    ///< "/ready", "/metadata/annotation", ...
  std::string body;
  std::chrono::steady_clock::time_point at;
  /// "POST /ready", for messages and comparisons.
  [[nodiscard]] std::string name() const { return method + " " + path; }
};

class FakeAgonesSidecar {
 public:
  FakeAgonesSidecar();
  ~FakeAgonesSidecar();
  FakeAgonesSidecar(const FakeAgonesSidecar&) = delete;
  FakeAgonesSidecar& operator=(const FakeAgonesSidecar&) = delete;

  /// Listens on 127.0.0.1:port (0: a free port); false when it cannot bind. Once this returns,
  /// connections are accepted.
  bool start(std::uint16_t port = 0);
  /// Stops listening and answering, as a sidecar that died; start() may follow.
  void stop();
  /// The port it listens on (or last listened on).
  [[nodiscard]] std::uint16_t port() const;
  /// Every call so far, in the order they came.
  [[nodiscard]] std::vector<SidecarCall> calls() const;
  void clear();
  /// Called from the server's threads as each call arrives, before it is answered.
  void on_call(std::function<void(const SidecarCall&)> hook);

  /// A TCP port of 127.0.0.1 that was free a moment ago (for a sidecar that starts late).
  static std::uint16_t free_port();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The calls' names, one a line, with their times relative to `origin` (for failure messages).
std::string timeline(const std::vector<SidecarCall>& calls,
                     std::chrono::steady_clock::time_point origin);

}  // namespace detsim::test
