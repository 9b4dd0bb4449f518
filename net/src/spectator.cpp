// The spectator side of a match (spectator.hpp): a handshake with the host, then confirmed frames
// in order. Each received unit is a whole frame: a byte whose bit p says player p was
// disconnected, then every player's input.
#include <detsim/net/spectator.hpp>

#include <deque>
#include <string>

#include <detsim/net/protocol.hpp>

#include "channel.hpp"
#include "secure_random.hpp"

namespace detsim::net {

struct SpectatorSession::Impl {
  SpectatorConfig config;
  Game* game = nullptr;
  Transport* transport = nullptr;
  std::size_t unit = 0;  ///< bytes per received frame
  // The handshake (docs/NET.md, "Handshake"): the host's session id comes only from its reply to
  // our challenge, and never changes after.
  std::uint64_t session_id = 0;
  std::uint64_t challenge = 0;
  bool answered = false;
  std::uint64_t host_session = 0;
  bool host_knows_us = false;  ///< the host's session sent frames or pings: it has our id
  bool running = false;
  bool disconnected = false;
  std::uint64_t now_us = 0;
  std::uint64_t last_receive_us = 0;
  std::uint64_t last_send_us = 0;
  std::uint64_t last_hello_us = 0;
  bool hello_sent = false;
  bool needs_ack = false;
  std::uint16_t sequence = 0;
  std::optional<detail::Protection> protection;  ///< with a match key
  detail::Channel channel;                       ///< to the host
  std::vector<std::uint8_t> body;

  std::uint64_t current = 0;             ///< next frame to simulate
  std::deque<std::uint8_t> received;     ///< frames current .. current + buffered - 1
  std::vector<std::uint8_t> last_frame;  ///< the frame before `received` (delta reference)
  std::vector<std::uint8_t> frame_inputs;
  std::vector<InputStatus> frame_status;
  std::vector<std::uint8_t> state;
  std::vector<std::uint8_t> scratch;
  std::vector<std::uint8_t> out;
  std::vector<Datagram> inbox;
  protocol::Packet packet;
  std::function<void(const ConfirmedFrame&)> listener;
  std::vector<Event> events;
  SpectatorStats stats;

  [[nodiscard]] std::uint64_t buffered() const noexcept { return received.size() / unit; }
  [[nodiscard]] std::uint64_t next_needed() const noexcept { return current + buffered(); }

  void send(protocol::Packet& p) {
    p.header.session = session_id;
    p.header.sequence = sequence++;
    const bool encoded = protection ? protection->seal(channel, p, config.input_size, out)
                                    : protocol::encode(p, config.input_size, out);
    if (!encoded) return;
    transport->send(config.host, out);
    last_send_us = now_us;
  }

  void handle(const protocol::Packet& p) {
    using protocol::PacketType;
    switch (p.header.type) {
      case PacketType::hello: {
        const protocol::Hello& h = p.hello;
        // Answered (unless the host has shown it knows our id), never believed: a hello changes
        // nothing here, nor is it a sign of life.
        if (h.fingerprint != config.fingerprint || h.players != config.players ||
            h.input_size != config.input_size || h.player >= config.players || host_knows_us) {
          ++stats.dropped;
          return;
        }
        protocol::Packet reply;
        reply.header.type = PacketType::hello_reply;
        reply.hello_reply.challenge = h.challenge;
        send(reply);
        return;
      }
      case PacketType::hello_reply:
        if (p.hello_reply.challenge != challenge ||
            (answered && p.header.session != host_session)) {
          ++stats.dropped;
          return;
        }
        if (answered) return;  // a duplicate
        answered = true;
        host_session = p.header.session;
        if (protection) protection->bind(channel, host_session);
        break;
      case PacketType::ping: {
        if (!running || p.header.session != host_session) {
          ++stats.dropped;
          return;
        }
        host_knows_us = true;
        protocol::Packet pong;
        pong.header.type = PacketType::pong;
        pong.ping.time_us = p.ping.time_us;
        send(pong);
        break;
      }
      case PacketType::pong:
        return;
      case PacketType::state_request:  // between players only
      case PacketType::state_chunk:
        ++stats.dropped;
        return;
      case PacketType::input:
        if (!running || p.header.session != host_session) {
          ++stats.dropped;
          return;
        }
        host_knows_us = true;
        receive_frames(p.input);
        break;
    }
    ++stats.packets_received;
    last_receive_us = now_us;
    if (!running && answered) {
      running = true;
      events.push_back(Event{EventType::synchronized, 0, current, 0, 0, {}});
      events.push_back(Event{EventType::running, 0, current, 0, 0, {}});
    }
  }

  void receive_frames(const protocol::InputBody& b) {
    needs_ack = true;
    const std::uint64_t start = b.start_frame;
    const std::uint64_t end = start + b.count;
    if (b.count == 0 || end <= next_needed()) return;  // a keepalive or old frames
    if (start > next_needed() || end - current > max_buffered_frames) {
      ++stats.dropped;
      return;
    }
    // The reference is the frame before `start`: the last buffered one, or the last simulated.
    const std::uint64_t offset = start - current;  // may be "negative" when start < current
    scratch.assign(b.deltas.begin(), b.deltas.end());
    std::vector<std::uint8_t> reference(unit, 0);
    if (start > current) {
      const auto at = received.begin() + static_cast<std::ptrdiff_t>((offset - 1) * unit);
      reference.assign(at, at + static_cast<std::ptrdiff_t>(unit));
    } else if (start == current) {
      reference = last_frame;
    } else {
      ++stats.dropped;  // starts before what we simulated: the reference is gone
      return;
    }
    protocol::delta_decode(reference, scratch);
    const std::uint64_t skip = next_needed() - start;
    received.insert(received.end(), scratch.begin() + static_cast<std::ptrdiff_t>(skip * unit),
                    scratch.end());
  }

  void simulate_one() {
    const auto first = received.begin();
    const std::uint8_t gone = *first;
    for (std::uint32_t p = 0; p < config.players; ++p)
      frame_status[p] = (gone >> p) & 1U ? InputStatus::disconnected : InputStatus::confirmed;
    std::copy(first + 1, first + static_cast<std::ptrdiff_t>(unit), frame_inputs.begin());
    last_frame.assign(first, first + static_cast<std::ptrdiff_t>(unit));
    received.erase(first, first + static_cast<std::ptrdiff_t>(unit));
    game->advance(FrameInputs{current, config.input_size, frame_inputs, frame_status}, false);
    const std::uint64_t hash = listener ? game->save(state) : 0;
    if (listener) listener(ConfirmedFrame{current, frame_inputs, frame_status, hash});
    ++current;
    ++stats.frames;
  }
};

Expected<SpectatorSession> SpectatorSession::create(const SpectatorConfig& c, Game& game,
                                                    Transport& transport) {
  const auto bad = [](const std::string& what) {
    return Status::error("spectator config: " + what);
  };
  if (c.players < 1 || c.players > 8)
    return bad("players must be 1 .. 8, got " + std::to_string(c.players));
  if (c.input_size < 1 || c.input_size > protocol::max_input_size)
    return bad("input_size must be 1 .. 64 bytes, got " + std::to_string(c.input_size));
  if (c.catch_up_frames < 1 || c.catch_up_frames > 1000)
    return bad("catch_up_frames must be 1 .. 1000, got " + std::to_string(c.catch_up_frames));
  if (c.hello_interval_us == 0 || c.keepalive_us == 0 || c.disconnect_timeout_us == 0)
    return bad("hello_interval_us, keepalive_us and disconnect_timeout_us must be > 0");
  auto impl = std::make_unique<Impl>();
  impl->config = c;
  impl->game = &game;
  impl->transport = &transport;
  impl->unit = 1 + std::size_t{c.players} * c.input_size;
  if (Status s = detail::check_match_key(c.match_key, "spectator config: match_key"); !s) return s;
  if (Status s = detail::secure_random_ready(); !s) return s;
  impl->session_id = detail::secure_random_u64();
  if (c.match_key) impl->protection.emplace(*c.match_key, impl->session_id);
  impl->challenge = detail::secure_random_u64();
  impl->last_frame.assign(impl->unit, 0);
  impl->frame_inputs.assign(std::size_t{c.players} * c.input_size, 0);
  impl->frame_status.assign(c.players, InputStatus::confirmed);
  return SpectatorSession(std::move(impl));
}

SpectatorSession::SpectatorSession(std::unique_ptr<Impl> impl) noexcept : impl_(std::move(impl)) {}
SpectatorSession::SpectatorSession(SpectatorSession&&) noexcept = default;
SpectatorSession& SpectatorSession::operator=(SpectatorSession&&) noexcept = default;
SpectatorSession::~SpectatorSession() = default;

void SpectatorSession::poll(std::uint64_t now_us) {
  Impl& s = *impl_;
  s.now_us = std::max(s.now_us, now_us);
  if (s.disconnected) return;
  s.inbox.clear();
  s.transport->receive(s.inbox);
  for (const Datagram& d : s.inbox) {
    if (d.from != s.config.host) {
      ++s.stats.dropped;
      continue;
    }
    // The host's frames carry whole-frame units; everything else its players' input size.
    const bool frames =
        d.bytes.size() > 3 && d.bytes[3] == static_cast<std::uint8_t>(protocol::PacketType::input);
    const std::size_t size = frames ? s.unit : s.config.input_size;
    if (s.protection) {
      // Header, replay window, tag, then the body (channel.hpp), as a player's session does.
      protocol::DecodeError error = protocol::DecodeError::none;
      const detail::Opened opened =
          s.protection->open(s.channel, d.bytes, s.packet.header, error, s.body);
      if (opened == detail::Opened::replayed) ++s.stats.dropped_replayed;
      if (opened == detail::Opened::unauthenticated ||
          (opened == detail::Opened::malformed && !detail::looks_sealed(d.bytes)))
        ++s.stats.dropped_unauthenticated;
      if (opened != detail::Opened::ok ||
          protocol::decode_body(s.packet.header.type, s.body, size, s.packet) !=
              protocol::DecodeError::none) {
        ++s.stats.dropped;
        continue;
      }
    } else if (protocol::decode(d.bytes, size, s.packet) != protocol::DecodeError::none) {
      ++s.stats.dropped;
      continue;
    }
    s.stats.bytes_received += d.bytes.size();
    s.handle(s.packet);
  }
  if (s.running && s.now_us - s.last_receive_us >= s.config.disconnect_timeout_us) {
    s.disconnected = true;
    s.events.push_back(Event{EventType::disconnected, 0, s.current, 0, 0, {}});
    return;
  }
  if (!s.answered && (!s.hello_sent || s.now_us - s.last_hello_us >= s.config.hello_interval_us)) {
    protocol::Packet hello;
    hello.header.type = protocol::PacketType::hello;
    hello.hello = protocol::Hello{s.config.fingerprint, static_cast<std::uint8_t>(s.config.players),
                                  protocol::spectator_player,
                                  static_cast<std::uint8_t>(s.config.input_size), s.challenge};
    s.send(hello);
    s.hello_sent = true;
    s.last_hello_us = s.now_us;
  }
  if (s.running && (s.needs_ack || s.now_us - s.last_send_us >= s.config.keepalive_us)) {
    protocol::Packet ack;
    ack.header.type = protocol::PacketType::input;
    ack.input = protocol::InputBody{};
    ack.input.ack_frame = static_cast<std::uint32_t>(s.next_needed());
    ack.input.current_frame = static_cast<std::uint32_t>(s.current);
    s.send(ack);
    s.needs_ack = false;
  }
}

std::uint32_t SpectatorSession::advance() {
  Impl& s = *impl_;
  const std::uint64_t waiting = s.buffered();
  if (waiting == 0) return 0;
  const std::uint64_t n = waiting > s.config.catch_up_threshold
                              ? std::min<std::uint64_t>(waiting, s.config.catch_up_frames)
                              : 1;
  for (std::uint64_t i = 0; i < n; ++i)
    s.simulate_one();
  if (n > 1) ++s.stats.catch_up_calls;
  return static_cast<std::uint32_t>(n);
}

void SpectatorSession::set_confirmed_listener(std::function<void(const ConfirmedFrame&)> listener) {
  impl_->listener = std::move(listener);
}

std::vector<Event> SpectatorSession::take_events() {
  std::vector<Event> out;
  out.swap(impl_->events);
  return out;
}

bool SpectatorSession::running() const noexcept {
  return impl_->running;
}
std::uint64_t SpectatorSession::current_frame() const noexcept {
  return impl_->current;
}
std::uint64_t SpectatorSession::frames_behind() const noexcept {
  return impl_->buffered();
}
const SpectatorStats& SpectatorSession::stats() const noexcept {
  return impl_->stats;
}

}  // namespace detsim::net
