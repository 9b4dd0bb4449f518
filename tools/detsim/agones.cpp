// AgonesClient (agones.hpp): the Agones SDK's REST calls from one background thread, through
// cpp-httplib (Debian libcpp-httplib-dev). The REST API is Agones' "SDK REST API" page: each call
// is a POST or PUT of a small JSON body to the sidecar on the pod's loopback, answered 200 and {}.
//
// This is the CLI's only user of httplib.h, which is slow to compile: it stays its own
// translation unit (tools/CMakeLists.txt) and agones.hpp does not include it.
#include "agones.hpp"

#include <signal.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <utility>

#include <httplib.h>

#include "output.hpp"

namespace detsim::cli {

namespace {

std::string metadata_body(const std::string& key, const std::string& value) {
  return "{\"key\":" + Json::quote(key) + ",\"value\":" + Json::quote(value) + "}";
}

/// Blocks the asynchronous signals in the calling thread (and the threads it starts), so that
/// SIGTERM reaches the match loop's thread and a SIGPIPE from a sidecar that went away stays
/// pending in the client's thread instead of ending the process. Faults are left alone.
sigset_t block_async_signals() {
  sigset_t block;
  sigfillset(&block);
  for (const int fault : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGTRAP, SIGABRT})
    sigdelset(&block, fault);
  sigset_t old;
  pthread_sigmask(SIG_BLOCK, &block, &old);
  return old;
}

}  // namespace

Expected<std::uint16_t> agones_port_from_environment() {
  const char* text = std::getenv("AGONES_SDK_HTTP_PORT");
  if (text == nullptr || *text == '\0') return agones_default_port;
  const std::string value(text);
  char* end = nullptr;
  const unsigned long port = std::strtoul(value.c_str(), &end, 10);
  if (value.find_first_not_of("0123456789") != std::string::npos || *end != '\0' || port < 1 ||
      port > 65535)
    return Status::error("AGONES_SDK_HTTP_PORT must be a port number, 1 .. 65535, got '" + value +
                         "'");
  return static_cast<std::uint16_t>(port);
}

AgonesClient::AgonesClient(AgonesOptions options)
    : options_(std::move(options)),
      backoff_(options_.first_backoff),
      next_health_(Clock::now() + options_.health_period) {
  const sigset_t old = block_async_signals();
  thread_ = std::thread([this] { run(); });
  pthread_sigmask(SIG_SETMASK, &old, nullptr);
}

AgonesClient::~AgonesClient() {
  {
    const std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void AgonesClient::ready() {
  enqueue({"POST", "/ready", "{}"});
}

void AgonesClient::label(const std::string& key, const std::string& value) {
  enqueue({"PUT", "/metadata/label", metadata_body(key, value)});
}

void AgonesClient::annotation(const std::string& key, const std::string& value) {
  enqueue({"PUT", "/metadata/annotation", metadata_body(key, value)});
}

void AgonesClient::heartbeat() noexcept {
  heartbeats_.fetch_add(1, std::memory_order_relaxed);
}

void AgonesClient::advanced(std::uint64_t frame) noexcept {
  frame_.store(frame, std::memory_order_relaxed);
}

void AgonesClient::enqueue(Call call) {
  {
    const std::lock_guard lock(mutex_);
    if (closing_ || stop_) return;
    queue_.push_back(std::move(call));
  }
  wake_.notify_all();
}

bool AgonesClient::shutdown() {
  std::unique_lock lock(mutex_);
  if (!closing_ && !stop_) {
    queue_.push_back({"POST", "/shutdown", "{}"});
    closing_ = true;
    deadline_ = Clock::now() + options_.shutdown_wait;
    wake_.notify_all();
  }
  idle_.wait(lock, [this] { return finished_; });
  lock.unlock();
  if (thread_.joinable()) thread_.join();
  lock.lock();
  return stats_.shutdown;
}

AgonesStats AgonesClient::stats() const {
  const std::lock_guard lock(mutex_);
  return stats_;
}

void AgonesClient::run() {
  std::unique_lock lock(mutex_);
  while (!stop_) {
    const Clock::time_point now = Clock::now();
    if (closing_ && (queue_.empty() || now >= deadline_)) break;
    if (!queue_.empty()) {
      if (now >= retry_at_) {
        send_first(lock);
      } else {
        const bool was_closing = closing_;
        wake_.wait_until(lock, closing_ ? std::min(retry_at_, deadline_) : retry_at_,
                         [&] { return stop_ || closing_ != was_closing; });
      }
      continue;
    }
    // Health only with nothing queued: a ping never overtakes ready, and a sidecar that does not
    // answer is tried once per backoff, not twice.
    if (now >= next_health_) {
      maybe_ping(lock);
      continue;
    }
    wake_.wait_until(lock, next_health_, [this] { return stop_ || closing_ || !queue_.empty(); });
  }
  if (closing_ && !queue_.empty()) {
    const std::string first = queue_.front().method + " " + queue_.front().path;
    say("gave up after " + std::to_string(options_.shutdown_wait.count()) +
        " ms: " + std::to_string(queue_.size()) + " call" + (queue_.size() == 1 ? "" : "s") +
        " not delivered (the first " + first + "); the sidecar at " + options_.host + ":" +
        std::to_string(options_.port) + " does not answer");
  }
  stats_.calls_dropped += queue_.size();
  queue_.clear();
  finished_ = true;
  idle_.notify_all();
}

void AgonesClient::send_first(std::unique_lock<std::mutex>& lock) {
  const Call call = queue_.front();
  std::chrono::milliseconds limit = options_.call_timeout;
  if (closing_) {
    // Connect, write and read each get a third of what is left, so that shutdown() keeps its bound.
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline_ - Clock::now());
    limit = std::clamp(left / 3, std::chrono::milliseconds(1), limit);
  }
  lock.unlock();
  std::string error;
  const Outcome outcome = send(call, limit, error);
  lock.lock();
  count(outcome, call, error);
  if (outcome == Outcome::failed) {
    retry_at_ = Clock::now() + backoff_;
    backoff_ = std::min(backoff_ * 2, options_.max_backoff);
    return;
  }
  if (outcome == Outcome::delivered) {
    if (call.path == "/ready") stats_.ready = true;
    if (call.path == "/shutdown") stats_.shutdown = true;
  } else {
    ++stats_.calls_dropped;
  }
  queue_.pop_front();
  backoff_ = options_.first_backoff;
  retry_at_ = {};
}

void AgonesClient::maybe_ping(std::unique_lock<std::mutex>& lock) {
  next_health_ = Clock::now() + options_.health_period;
  const std::uint64_t heartbeats = heartbeats_.load(std::memory_order_relaxed);
  const std::uint64_t frame = frame_.load(std::memory_order_relaxed);
  if (heartbeats == pinged_heartbeats_ && frame == pinged_frame_) return;  // stalled: no ping
  pinged_heartbeats_ = heartbeats;
  pinged_frame_ = frame;
  const Call call{"POST", "/health", "{}"};
  lock.unlock();
  std::string error;
  const Outcome outcome = send(call, options_.call_timeout, error);
  lock.lock();
  count(outcome, call, error);
  if (outcome == Outcome::delivered) ++stats_.health_pings;
}

AgonesClient::Outcome AgonesClient::send(const Call& call, std::chrono::milliseconds limit,
                                         std::string& error) const {
  httplib::Client http(options_.host, options_.port);
  http.set_connection_timeout(limit);
  http.set_read_timeout(limit);
  http.set_write_timeout(limit);
  http.set_keep_alive(false);
  const httplib::Result result = call.method == "PUT"
                                     ? http.Put(call.path, call.body, "application/json")
                                     : http.Post(call.path, call.body, "application/json");
  if (!result) {
    error = "no answer (httplib: " + httplib::to_string(result.error()) + ")";
    return Outcome::failed;
  }
  if (result->status >= 200 && result->status < 300) return Outcome::delivered;
  error = "HTTP status " + std::to_string(result->status);
  // A 4xx is the sidecar's answer to this call (a bad key, say): sending it again changes nothing.
  return result->status >= 500 ? Outcome::failed : Outcome::refused;
}

void AgonesClient::count(Outcome outcome, const Call& call, const std::string& error) {
  const std::string name = call.method + " " + call.path;
  if (outcome == Outcome::delivered) {
    ++stats_.calls_sent;
    if (failure_streak_ > 0)
      say("the sidecar answers again (" + name + ") after " + std::to_string(failure_streak_) +
          " failed call" + (failure_streak_ == 1 ? "" : "s"));
    failure_streak_ = 0;
    return;
  }
  ++stats_.calls_failed;
  if (outcome == Outcome::refused) {
    say(name + " " + call.body + ": " + error + "; not sent again");
    return;
  }
  if (failure_streak_++ == 0)
    say(name + ": " + error + " (the sidecar at " + options_.host + ":" +
        std::to_string(options_.port) + "); trying again, the match goes on");
}

void AgonesClient::say(const std::string& line) const {
  if (options_.note) {
    options_.note(line);
  } else {
    std::fprintf(stderr, "agones: %s\n", line.c_str());
  }
}

}  // namespace detsim::cli
