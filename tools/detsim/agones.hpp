// AgonesClient: a game server's side of the Agones SDK, over the sidecar's REST API (`detsim serve
// --agones`; docs/SCALE.md, "Agones").
//
// The sidecar runs in the game server's pod and answers HTTP on 127.0.0.1:$AGONES_SDK_HTTP_PORT
// (default 9358): POST /ready, POST /health, PUT /metadata/label and /metadata/annotation
// ({"key":K,"value":V}), POST /shutdown; every body is JSON, every answer 200 and {}.
//
// One background thread owns every HTTP call, so that the match loop never waits for the sidecar:
// the loop only queues calls and bumps counters.
// - Queued calls (ready, label, annotation, shutdown) go in order. A call the sidecar cannot take
//   (no connection, a timeout, a 5xx) is retried with exponential backoff (100 ms doubling to
//   2 s), and the calls behind it wait: a sidecar that starts late still gets ready first, and one
//   that dies mid-match costs failed calls, never a frame. A 4xx answer is final: the call is
//   counted failed and dropped.
// - Health: every 2 s, once the queue is empty, a ping goes only if the server made progress since
//   the last one: heartbeat() (its loop ran with nothing to simulate: before the match, after the
//   last frame) or advanced(frame) with a new frame. A match whose simulation stalls sends none,
//   so Agones marks it Unhealthy after its failureThreshold missed periods.
// - shutdown() queues the shutdown call and waits until everything queued was delivered, or until
//   shutdown_wait (5 s) passed: the calls' own timeouts are cut to fit, so that is the whole wait.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

#include <detsim/core/status.hpp>

namespace detsim::cli {

/// The sidecar's HTTP port when AGONES_SDK_HTTP_PORT is not set (Agones' default).
inline constexpr std::uint16_t agones_default_port = 9358;

struct AgonesOptions {
  /// Where the sidecar listens: the pod's loopback (the sidecar binds localhost's IPv4 address).
  std::string host = "127.0.0.1";
  std::uint16_t port = agones_default_port;
  /// A health ping at most this often, and only after progress (see heartbeat(), advanced()).
  std::chrono::milliseconds health_period{2000};
  /// The first retry of a failed call after this, doubling up to max_backoff.
  std::chrono::milliseconds first_backoff{100};
  std::chrono::milliseconds max_backoff{2000};
  /// Each of a call's connect, write and read timeouts.
  std::chrono::milliseconds call_timeout{1000};
  /// shutdown() waits at most this long for the queued calls and the shutdown call itself.
  std::chrono::milliseconds shutdown_wait{5000};
  /// Where notes go (the sidecar stopped answering, answers again, gave up): one line each, from
  /// the client's thread. Empty: stderr, as "agones: ...".
  std::function<void(const std::string&)> note;
};

/// The port of AGONES_SDK_HTTP_PORT (1 .. 65535), or agones_default_port when it is unset or
/// empty; an error naming the variable when it is anything else.
Expected<std::uint16_t> agones_port_from_environment();

/// What the client did so far.
struct AgonesStats {
  std::uint64_t calls_sent = 0;     ///< calls the sidecar answered with 2xx, health pings included
  std::uint64_t calls_failed = 0;   ///< attempts that failed (no answer, or an error status)
  std::uint64_t health_pings = 0;   ///< health pings the sidecar answered
  std::uint64_t calls_dropped = 0;  ///< queued calls never delivered (refused, or given up on)
  bool ready = false;               ///< the sidecar answered ready
  bool shutdown = false;            ///< the sidecar answered shutdown
};

class AgonesClient {
 public:
  /// Starts the client's thread; nothing is sent until a call is queued or progress is made.
  explicit AgonesClient(AgonesOptions options);
  /// Stops the thread without waiting for what is queued (use shutdown() to deliver it first); an
  /// HTTP call under way is waited for (at most its timeouts).
  ~AgonesClient();
  AgonesClient(const AgonesClient&) = delete;
  AgonesClient& operator=(const AgonesClient&) = delete;

  /// Queues POST /ready: the game server can take players.
  void ready();
  /// Queues PUT /metadata/label and /metadata/annotation. `key` must be a valid Kubernetes key
  /// name (Agones stores it as "agones.dev/sdk-" + key); a label's value at most 63 characters
  /// of [A-Za-z0-9._-]. The sidecar refuses others (4xx: the call is dropped, with a note).
  void label(const std::string& key, const std::string& value);
  void annotation(const std::string& key, const std::string& value);

  /// The server's loop ran and is healthy with nothing to simulate (waiting for players, waiting
  /// for the last acknowledgements): the next health ping may go. Lock-free; call it every loop.
  void heartbeat() noexcept;
  /// The match has simulated up to `frame`: the next health ping may go if the frame changed
  /// since the last ping. Lock-free; call it every loop while the match runs.
  void advanced(std::uint64_t frame) noexcept;

  /// Queues POST /shutdown after everything queued, waits until all is delivered or
  /// shutdown_wait passed, and stops the thread; true when the sidecar answered shutdown. A note
  /// says what was given up on. Later calls return the same answer and queue nothing.
  bool shutdown();

  [[nodiscard]] AgonesStats stats() const;

 private:
  struct Call {
    std::string method;  ///< "POST" or "PUT"
    std::string path;
    std::string body;
  };
  using Clock = std::chrono::steady_clock;
  /// How a call ended: delivered (2xx), refused (4xx: final), or failed (try again later).
  enum class Outcome { delivered, refused, failed };

  void enqueue(Call call);
  void run();
  /// Sends the queue's first call once (the lock is held on entry and exit, released while the
  /// call is under way) and retires it or schedules its retry.
  void send_first(std::unique_lock<std::mutex>& lock);
  /// Sends a health ping when one is due and the server made progress since the last one.
  void maybe_ping(std::unique_lock<std::mutex>& lock);
  /// One HTTP call with every timeout at most `limit`; `error` says why it was not delivered.
  Outcome send(const Call& call, std::chrono::milliseconds limit, std::string& error) const;
  /// Counts an attempt and notes the first failure of a streak and the recovery after one.
  void count(Outcome outcome, const Call& call, const std::string& error);
  void say(const std::string& line) const;

  const AgonesOptions options_;
  std::atomic<std::uint64_t> heartbeats_{0};
  std::atomic<std::uint64_t> frame_{0};

  mutable std::mutex mutex_;
  std::condition_variable wake_;  ///< the thread: a call was queued, or stop
  std::condition_variable idle_;  ///< shutdown(): the thread has finished
  std::deque<Call> queue_;
  AgonesStats stats_;
  std::uint64_t failure_streak_ = 0;
  std::chrono::milliseconds backoff_;
  Clock::time_point retry_at_{};
  Clock::time_point next_health_;
  std::uint64_t pinged_heartbeats_ = 0;
  std::uint64_t pinged_frame_ = 0;
  bool closing_ = false;  ///< shutdown() was called: deliver what is queued by deadline_, then end
  Clock::time_point deadline_{};
  bool stop_ = false;      ///< end now (the destructor)
  bool finished_ = false;  ///< the thread has left its loop
  std::thread thread_;
};

}  // namespace detsim::cli
