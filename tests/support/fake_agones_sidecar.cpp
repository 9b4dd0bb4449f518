// FakeAgonesSidecar (fake_agones_sidecar.hpp): cpp-httplib's server, one per start().
#include "support/fake_agones_sidecar.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdio>
#include <mutex>
#include <thread>
#include <utility>

#include <httplib.h>

namespace detsim::test {

struct FakeAgonesSidecar::Impl {
  mutable std::mutex mutex;
  std::vector<SidecarCall> calls;
  std::function<void(const SidecarCall&)> hook;
  std::unique_ptr<httplib::Server> server;
  std::thread thread;
  std::uint16_t port = 0;

  void record(const httplib::Request& request) {
    SidecarCall call{request.method, request.path, request.body, std::chrono::steady_clock::now()};
    std::function<void(const SidecarCall&)> h;
    {
      const std::lock_guard lock(mutex);
      calls.push_back(call);
      h = hook;
    }
    if (h) h(call);
  }
};

FakeAgonesSidecar::FakeAgonesSidecar() : impl_(std::make_unique<Impl>()) {}

FakeAgonesSidecar::~FakeAgonesSidecar() {
  stop();
}

bool FakeAgonesSidecar::start(std::uint16_t port) {
  stop();
  // A client that hangs up before its answer is written must not end the test with SIGPIPE.
  std::signal(SIGPIPE, SIG_IGN);
  auto server = std::make_unique<httplib::Server>();
  Impl* impl = impl_.get();
  const auto answer = [impl](const httplib::Request& request, httplib::Response& response) {
    impl->record(request);
    response.set_content("{}", "application/json");
  };
  for (const char* path : {"/ready", "/health", "/shutdown", "/allocate"})
    server->Post(path, answer);
  for (const char* path : {"/metadata/label", "/metadata/annotation"})
    server->Put(path, answer);
  server->Get("/gameserver", [impl](const httplib::Request& request, httplib::Response& response) {
    impl->record(request);
    response.set_content(
        R"({"object_meta":{"name":"fake","namespace":"default"},"status":{"state":"Ready","address":"127.0.0.1","ports":[]}})",
        "application/json");
  });
  if (port == 0) {
    const int bound = server->bind_to_any_port("127.0.0.1");
    if (bound <= 0) return false;
    port = static_cast<std::uint16_t>(bound);
  } else if (!server->bind_to_port("127.0.0.1", port)) {
    return false;
  }
  impl_->port = port;
  impl_->server = std::move(server);
  impl_->thread = std::thread([impl] { impl->server->listen_after_bind(); });
  return true;
}

void FakeAgonesSidecar::stop() {
  if (!impl_->server) return;
  // stop() before the thread is in its accept loop is lost: wait until it runs.
  while (!impl_->server->is_running())
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  impl_->server->stop();
  impl_->thread.join();
  impl_->server.reset();
}

std::uint16_t FakeAgonesSidecar::port() const {
  return impl_->port;
}

std::vector<SidecarCall> FakeAgonesSidecar::calls() const {
  const std::lock_guard lock(impl_->mutex);
  return impl_->calls;
}

void FakeAgonesSidecar::clear() {
  const std::lock_guard lock(impl_->mutex);
  impl_->calls.clear();
}

void FakeAgonesSidecar::on_call(std::function<void(const SidecarCall&)> hook) {
  const std::lock_guard lock(impl_->mutex);
  impl_->hook = std::move(hook);
}

std::uint16_t FakeAgonesSidecar::free_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return 0;
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  address.sin_port = 0;
  socklen_t length = sizeof address;
  std::uint16_t port = 0;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) == 0 &&
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length) == 0)
    port = ntohs(address.sin_port);
  ::close(fd);
  return port;
}

std::string timeline(const std::vector<SidecarCall>& calls,
                     std::chrono::steady_clock::time_point origin) {
  std::string text;
  for (const SidecarCall& c : calls) {
    char at[32];
    std::snprintf(at, sizeof at, "%7.3f s  ", std::chrono::duration<double>(c.at - origin).count());
    text += at + c.name() + " " + c.body + "\n";
  }
  return text;
}

}  // namespace detsim::test
