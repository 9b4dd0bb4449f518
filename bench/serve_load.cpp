// serve_load: many game-server clients that do not simulate, for measuring how many `detsim serve`
// matches one machine holds (scripts/density.sh, docs/SCALE.md "Density").
//
// Each client speaks the server protocol (<detsim/net/server_protocol.hpp>) over its own UDP
// socket on loopback: it connects to a match with the fingerprint `detsim serve` uses, then
// sends the scripted bot's input every frame (scripted_input, as `detsim netplay --bot` does) a
// couple of frames ahead of the server, and acknowledges every update's units — without
// simulating, so that a machine's cores go to the servers under test, not to their clients. One
// thread, epoll, non-blocking sockets. It runs until every match has ended (the server's updates
// say its last frame) or --seconds pass, then prints one JSON line per match.
//
//   serve_load --port 7000 --matches 32 --players 8 [--host 127.0.0.1] [--seconds 120]
//
// Match m is the server at port + m. The program is a load generator, not a benchmark of its own:
// it reports what it saw (clients welcomed, updates, rejects) so the script can tell a refused or
// lost client from a slow server.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/epoll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <detsim/core/hash.hpp>
#include <detsim/core/version.hpp>
#include <detsim/net/server_protocol.hpp>
#include <detsim/scenes/scenario.hpp>

namespace {

namespace sp = detsim::net::server_protocol;
using Clock = std::chrono::steady_clock;

/// The game fingerprint `detsim serve` admits (tools/detsim/cmd_serve.cpp: the CLI's built-in
/// scenarios of this detsim version).
std::uint64_t serve_fingerprint() {
  const std::string text = "detsim serve " + std::string(detsim::version);
  return detsim::hash_bytes(std::span<const std::uint8_t>(
      reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
}

struct Options {
  std::string host = "127.0.0.1";
  int port = 7000;
  int matches = 1;
  int players = 8;
  double seconds = 120;
};

struct Bot {
  int fd = -1;
  int match = 0;
  sockaddr_in server{};
  std::uint64_t nonce = 0;
  std::uint64_t token = 0;
  std::uint16_t sequence = 0;
  bool welcomed = false;
  bool rejected = false;
  sp::Sizes sizes;
  std::uint32_t player = 0;
  std::uint64_t frame_us = 16'667;
  std::uint32_t frames = 0;     ///< the match's length (0: open-ended)
  std::uint32_t ack = 0;        ///< the match's units held (acknowledged) up to this frame
  std::uint32_t input_ack = 0;  ///< the server holds this bot's inputs before this frame
  std::uint32_t server_frame = 0;
  Clock::time_point server_frame_at{};
  bool heard_update = false;
  std::uint64_t updates = 0;
  std::uint64_t sent = 0;
  Clock::time_point next_send{};
  Clock::time_point next_connect{};
  [[nodiscard]] bool done() const {
    return rejected || (welcomed && frames != 0 && ack >= frames && heard_update);
  }
};

bool send_packet(Bot& bot, sp::Packet& packet, std::vector<std::uint8_t>& scratch) {
  packet.header.token = bot.token;
  packet.header.sequence = bot.sequence++;
  if (!sp::encode(packet, bot.sizes, scratch)) return false;
  const auto n = ::sendto(bot.fd, scratch.data(), scratch.size(), 0,
                          reinterpret_cast<const sockaddr*>(&bot.server), sizeof bot.server);
  if (n >= 0) ++bot.sent;
  return n >= 0;
}

void send_connect(Bot& bot, std::uint64_t game, std::vector<std::uint8_t>& scratch) {
  sp::Packet p;
  p.header.type = sp::PacketType::connect;
  p.connect.game = game;
  p.connect.nonce = bot.nonce;
  p.connect.seat = sp::any_seat;
  bot.token = 0;
  send_packet(bot, p, scratch);
}

/// The frame this bot's newest input is for: the server's frame as of its last update, moved on
/// by the time since, plus two (the lead `detsim netplay --server` keeps).
std::uint32_t client_frame(const Bot& bot, Clock::time_point now) {
  if (!bot.heard_update) return bot.input_ack + 2;
  const auto since =
      std::chrono::duration_cast<std::chrono::microseconds>(now - bot.server_frame_at);
  const auto ahead = static_cast<std::uint64_t>(std::max<std::int64_t>(0, since.count())) /
                     std::max<std::uint64_t>(1, bot.frame_us);
  return bot.server_frame + static_cast<std::uint32_t>(ahead) + 2;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    const char* value = argv[i + 1];
    if (key == "--host") {
      o.host = value;
    } else if (key == "--port") {
      o.port = std::atoi(value);
    } else if (key == "--matches") {
      o.matches = std::atoi(value);
    } else if (key == "--players") {
      o.players = std::atoi(value);
    } else if (key == "--seconds") {
      o.seconds = std::atof(value);
    } else {
      std::fprintf(stderr, "serve_load: unknown option %s\n", key.c_str());
      return 2;
    }
  }
  if (argc % 2 == 0 || o.matches < 1 || o.players < 1 || o.port < 1 || o.port + o.matches > 65535) {
    std::fprintf(stderr,
                 "usage: serve_load --port P --matches M --players N [--host H] [--seconds S]\n");
    return 2;
  }
  const std::uint64_t game = serve_fingerprint();
  const int epoll = ::epoll_create1(0);
  std::mt19937_64 random(std::random_device{}());
  std::vector<Bot> bots(static_cast<std::size_t>(o.matches * o.players));
  for (std::size_t i = 0; i < bots.size(); ++i) {
    Bot& b = bots[i];
    b.match = static_cast<int>(i) / o.players;
    b.fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK, 0);
    if (b.fd < 0) {
      std::perror("serve_load: socket");
      return 1;
    }
    b.server.sin_family = AF_INET;
    b.server.sin_port = htons(static_cast<std::uint16_t>(o.port + b.match));
    ::inet_pton(AF_INET, o.host.c_str(), &b.server.sin_addr);
    b.nonce = random();
    epoll_event e{};
    e.events = EPOLLIN;
    e.data.u64 = i;
    ::epoll_ctl(epoll, EPOLL_CTL_ADD, b.fd, &e);
  }
  std::vector<std::uint8_t> scratch;
  std::vector<std::uint8_t> buffer(65536);
  std::vector<std::uint8_t> input(detsim::PlayerInput::encoded_size);
  const auto start = Clock::now();
  const auto deadline =
      start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(o.seconds));
  std::vector<epoll_event> events(256);
  std::uint64_t malformed = 0;
  for (;;) {
    const auto now = Clock::now();
    if (now >= deadline) break;
    if (std::all_of(bots.begin(), bots.end(), [](const Bot& b) { return b.done(); })) break;
    // Out: connects until welcomed (every 250 ms), then inputs once a frame.
    for (Bot& b : bots) {
      if (b.done()) continue;
      if (!b.welcomed) {
        if (now >= b.next_connect) {
          send_connect(b, game, scratch);
          b.next_connect = now + std::chrono::milliseconds(250);
        }
        continue;
      }
      if (now < b.next_send) continue;
      b.next_send = now + std::chrono::microseconds(b.frame_us);
      const std::uint32_t newest = client_frame(b, now);
      sp::Packet p;
      p.header.type = sp::PacketType::input;
      p.input.ack = b.ack;
      p.input.snapshot_ack = 0;
      p.input.time_ms = static_cast<std::uint32_t>(
          std::chrono::duration_cast<std::chrono::milliseconds>(now - start).count());
      p.input.start = b.input_ack;
      const std::uint32_t end = b.frames != 0 ? std::min(newest + 1, b.frames) : newest + 1;
      const std::uint32_t count =
          std::min<std::uint32_t>(end > b.input_ack ? end - b.input_ack : 0,
                                  static_cast<std::uint32_t>(sp::max_frames_per_packet));
      p.input.count = static_cast<std::uint8_t>(count);
      p.input.inputs.resize(count * b.sizes.input_size);
      for (std::uint32_t k = 0; k < count; ++k) {
        const detsim::PlayerInput in = detsim::scripted_input(1, b.input_ack + k, b.player);
        detsim::encode_input(in, std::span<std::uint8_t, detsim::PlayerInput::encoded_size>(
                                     p.input.inputs.data() + k * b.sizes.input_size,
                                     detsim::PlayerInput::encoded_size));
      }
      send_packet(b, p, scratch);
    }
    // In: welcomes, rejects, updates (snapshot slices are not asked for under input authority).
    const int n = ::epoll_wait(epoll, events.data(), static_cast<int>(events.size()), 1);
    for (int k = 0; k < n; ++k) {
      Bot& b = bots[events[static_cast<std::size_t>(k)].data.u64];
      for (;;) {
        const auto got = ::recv(b.fd, buffer.data(), buffer.size(), 0);
        if (got <= 0) break;
        sp::Packet p;
        const std::span<const std::uint8_t> bytes(buffer.data(), static_cast<std::size_t>(got));
        if (sp::decode(bytes, b.sizes, p) != sp::DecodeError::none) {
          ++malformed;
          continue;
        }
        const auto at = Clock::now();
        switch (p.header.type) {
          case sp::PacketType::welcome:
            if (p.welcome.nonce != b.nonce || b.welcomed) break;
            b.welcomed = true;
            b.token = p.header.token;
            b.player = p.welcome.player;
            b.sizes = {p.welcome.players, p.welcome.input_size};
            b.frame_us = p.welcome.frame_us;
            b.frames = p.welcome.frames;
            b.ack = p.welcome.start_frame;
            b.input_ack = p.welcome.start_frame;
            break;
          case sp::PacketType::reject:
            if (p.reject.nonce == b.nonce) b.rejected = true;
            break;
          case sp::PacketType::update:
            if (!b.welcomed || p.header.token != b.token) break;
            ++b.updates;
            if (p.update.start <= b.ack)
              b.ack = std::max<std::uint32_t>(b.ack, p.update.start + p.update.count);
            b.input_ack = std::max(b.input_ack, p.update.input_ack);
            if (!b.heard_update || p.update.frame > b.server_frame) {
              b.server_frame = p.update.frame;
              b.server_frame_at = at;
            }
            b.heard_update = true;
            break;
          default:
            break;
        }
      }
    }
  }
  // Leave politely, so the servers free the seats at once.
  for (Bot& b : bots) {
    if (!b.welcomed) continue;
    sp::Packet p;
    p.header.type = sp::PacketType::leave;
    send_packet(b, p, scratch);
  }
  const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  for (int m = 0; m < o.matches; ++m) {
    int welcomed = 0;
    int rejected = 0;
    int finished = 0;
    std::uint64_t updates = 0;
    std::uint32_t ack = 0;
    for (const Bot& b : bots) {
      if (b.match != m) continue;
      welcomed += b.welcomed ? 1 : 0;
      rejected += b.rejected ? 1 : 0;
      finished += b.done() && !b.rejected ? 1 : 0;
      updates += b.updates;
      ack = std::max(ack, b.ack);
    }
    std::printf(
        "{\"match\":%d,\"port\":%d,\"clients\":%d,\"welcomed\":%d,\"rejected\":%d,\"finished\":%d,"
        "\"updates\":%llu,\"acknowledged_frame\":%u,\"seconds\":%.3f}\n",
        m, o.port + m, o.players, welcomed, rejected, finished,
        static_cast<unsigned long long>(updates), ack, elapsed);
  }
  if (malformed != 0)
    std::fprintf(stderr, "serve_load: %llu malformed datagrams\n",
                 static_cast<unsigned long long>(malformed));
  for (Bot& b : bots)
    ::close(b.fd);
  ::close(epoll);
  return 0;
}
