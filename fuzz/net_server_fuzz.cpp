// libFuzzer target for the game server (clang: `scripts/fuzz.sh SECONDS server` builds and runs
// it): the server protocol's decoder, and a live server that a hostile node sprays with whatever
// the fuzzer makes.
//
// The first input byte picks the mode:
// - bit 1 clear: the rest is a datagram; bit 0 set recomputes its checksum first (so mutations
//   reach the fields). It is decoded with several match sizes (and none, as a client not yet
//   welcomed reads); whenever it decodes, the packet must re-encode, that encoding decode to the
//   same packet, and encode again to the same bytes.
// - bit 1 set: the rest is a sequence of datagrams (a length byte, then the bytes; bit 0 set
//   recomputes each one's checksum) that a third node of a simulated network sends to a server
//   while an honest client plays 40 frames of a one-seat match with it, one datagram every 2 ms
//   from 100 ms on (once the client holds the seat: before that, a connect for the right game
//   would simply be first).
//   The server's frames must hash exactly as they do without the stranger (its datagrams are
//   counted and dropped; its connects find the one seat taken), and the honest client must end on
//   the server's state.
// A violation traps; the sanitizers and libFuzzer's limits catch the rest.
#include <xxhash.h>

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <detsim/net/client.hpp>
#include <detsim/net/server.hpp>
#include <detsim/net/server_protocol.hpp>
#include <detsim/net/sim_network.hpp>

namespace {

namespace net = detsim::net;
namespace sp = detsim::net::server_protocol;

void reseal(std::vector<std::uint8_t>& b) {
  if (b.size() < 4) return;
  const std::size_t n = b.size() - 4;
  const auto sum = static_cast<std::uint32_t>(XXH3_64bits(b.data(), n));
  for (std::size_t i = 0; i < 4; ++i)
    b[n + i] = static_cast<std::uint8_t>(sum >> (8 * i));
}

bool same(const sp::Packet& a, const sp::Packet& b) {
  if (a.header.type != b.header.type || a.header.token != b.header.token ||
      a.header.sequence != b.header.sequence)
    return false;
  switch (a.header.type) {
    case sp::PacketType::connect:
      return a.connect.game == b.connect.game && a.connect.nonce == b.connect.nonce &&
             a.connect.seat == b.connect.seat;
    case sp::PacketType::welcome:
      return a.welcome.nonce == b.welcome.nonce && a.welcome.player == b.welcome.player &&
             a.welcome.players == b.welcome.players &&
             a.welcome.input_size == b.welcome.input_size &&
             a.welcome.authority == b.welcome.authority &&
             a.welcome.frame_us == b.welcome.frame_us && a.welcome.frames == b.welcome.frames &&
             a.welcome.start_frame == b.welcome.start_frame &&
             a.welcome.initial_hash == b.welcome.initial_hash &&
             a.welcome.description == b.welcome.description;
    case sp::PacketType::reject:
      return a.reject.nonce == b.reject.nonce && a.reject.reason == b.reject.reason;
    case sp::PacketType::input:
      return a.input.ack == b.input.ack && a.input.snapshot_ack == b.input.snapshot_ack &&
             a.input.time_ms == b.input.time_ms && a.input.start == b.input.start &&
             a.input.count == b.input.count && a.input.inputs == b.input.inputs;
    case sp::PacketType::update:
      return a.update.frame == b.update.frame && a.update.input_ack == b.update.input_ack &&
             a.update.lead == b.update.lead && a.update.echo_ms == b.update.echo_ms &&
             a.update.start == b.update.start && a.update.count == b.update.count &&
             a.update.units == b.update.units && a.update.hash == b.update.hash;
    case sp::PacketType::snapshot:
      return a.snapshot.frame == b.snapshot.frame && a.snapshot.base == b.snapshot.base &&
             a.snapshot.hash == b.snapshot.hash && a.snapshot.total == b.snapshot.total &&
             a.snapshot.offset == b.snapshot.offset && a.snapshot.data == b.snapshot.data;
    case sp::PacketType::leave:
      return true;
  }
  return false;
}

void check(const std::vector<std::uint8_t>& bytes, const sp::Sizes& sizes) {
  sp::Packet packet;
  if (sp::decode(bytes, sizes, packet) != sp::DecodeError::none) return;
  std::vector<std::uint8_t> again;
  if (!sp::encode(packet, sizes, again)) __builtin_trap();
  sp::Packet back;
  if (sp::decode(again, sizes, back) != sp::DecodeError::none) __builtin_trap();
  if (!same(packet, back)) __builtin_trap();
  std::vector<std::uint8_t> third;
  if (!sp::encode(back, sizes, third) || third != again) __builtin_trap();
}

/// A game whose state is an accumulator of every input byte and presence, frame by frame.
class Tally final : public net::Game {
 public:
  std::uint64_t save(std::vector<std::uint8_t>& state) override {
    state.assign(16, 0);
    for (int i = 0; i < 8; ++i) {
      state[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(frame_ >> (8 * i));
      state[static_cast<std::size_t>(8 + i)] = static_cast<std::uint8_t>(acc_ >> (8 * i));
    }
    return XXH3_64bits(state.data(), state.size());
  }
  void load(std::span<const std::uint8_t> state) override {
    frame_ = acc_ = 0;
    for (int i = 0; i < 8 && state.size() == 16; ++i) {
      frame_ |= std::uint64_t{state[static_cast<std::size_t>(i)]} << (8 * i);
      acc_ |= std::uint64_t{state[static_cast<std::size_t>(8 + i)]} << (8 * i);
    }
  }
  void advance(const net::FrameInputs& inputs, bool) override {
    for (const std::uint8_t b : inputs.bytes)
      acc_ = acc_ * 0x100000001B3ULL + b;
    for (const net::InputStatus s : inputs.status)
      acc_ = acc_ * 31 + static_cast<std::uint64_t>(s);
    ++frame_;
  }

 private:
  std::uint64_t frame_ = 0;
  std::uint64_t acc_ = 0;
};

constexpr std::uint32_t match_frames = 40;

/// The server's frame hashes of the one-seat match, with `stranger` datagrams sent to the server
/// from node 2 (one every 2 ms from the start); traps if the honest client does not end on them.
std::vector<std::uint64_t> play(const std::vector<std::vector<std::uint8_t>>& stranger) {
  auto network = net::SimNetwork::create(3, 1).value();
  Tally server_game;
  net::ServerConfig config;
  config.players = 1;
  config.input_size = 3;
  config.game = 0xF022;
  config.frames = match_frames;
  config.start_clients = 1;
  net::Server server = net::Server::create(config, server_game, network.endpoint(0)).value();
  std::vector<std::uint64_t> hashes;
  server.set_confirmed_listener(
      [&hashes](const net::ConfirmedFrame& f) { hashes.push_back(f.hash); });
  Tally client_game;
  net::ClientConfig cc;
  cc.game = 0xF022;
  net::Client client = net::Client::create(cc, network.endpoint(1)).value();
  std::uint64_t next = 0;
  std::size_t sent = 0;
  for (std::uint64_t ms = 0; ms < 5000; ++ms) {
    const std::uint64_t now = ms * 1000;
    network.advance_to(now);
    if (ms >= 100 && ms % 2 == 0 && sent < stranger.size())
      network.endpoint(2).send(0, stranger[sent++]);
    std::vector<net::Datagram> ignored;
    network.endpoint(2).receive(ignored);  // whatever the server answers the stranger
    server.poll(now);
    server.advance(now);
    server.poll(now);
    client.poll(now);
    if (client.welcome() != nullptr && !client.started() && !client.start(client_game))
      __builtin_trap();
    if (client.running() && now >= next) {
      next = now + client.welcome()->frame_us;
      const std::uint8_t input[3] = {static_cast<std::uint8_t>(client.current_frame() / 4), 1, 2};
      (void)client.advance_frame(input);
    }
    if (server.settled() && client.ended() && sent == stranger.size()) break;
  }
  if (!client.ended() || client.stats().desyncs != 0 || hashes.size() != match_frames)
    __builtin_trap();
  std::vector<std::uint8_t> state;
  if (client_game.save(state) != server.current_hash()) __builtin_trap();
  return hashes;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const bool resign = (data[0] & 1U) != 0;
  if ((data[0] & 2U) == 0) {
    std::vector<std::uint8_t> bytes(data + 1, data + size);
    if (resign) reseal(bytes);
    for (const sp::Sizes sizes :
         {sp::Sizes{}, sp::Sizes{1, 1}, sp::Sizes{3, 4}, sp::Sizes{2, 64}, sp::Sizes{128, 7}})
      check(bytes, sizes);
    return 0;
  }
  std::vector<std::vector<std::uint8_t>> stranger;
  for (std::size_t at = 1; at < size && stranger.size() < 64;) {
    const std::size_t n = data[at];
    const std::size_t take = std::min(n, size - at - 1);
    std::vector<std::uint8_t> d(data + at + 1, data + at + 1 + take);
    if (resign) reseal(d);
    stranger.push_back(std::move(d));
    at += 1 + take;
  }
  // The match without the stranger, once: the server's frames must be exactly these.
  static const std::vector<std::uint64_t> reference = play({});
  if (play(stranger) != reference) __builtin_trap();
  return 0;
}
