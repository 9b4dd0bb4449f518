// The session wire protocol: encoding and the validating decoder (layout in protocol.hpp).
//
// Written by hand rather than with a serialisation library: the bytes on the wire are part of the
// determinism contract (a peer on another CPU must read exactly what was meant) and every field
// must be range-checked before use, so the decoder is a plain little-endian reader with an error
// code per failure and no allocation beyond the packet's own bounded vectors.
#include <detsim/net/protocol.hpp>

#include <algorithm>

#include "wire.hpp"

namespace detsim::net::protocol {
namespace {

using wire::checksum;
using wire::put;
using wire::put_frame;
using wire::put_varint;
using wire::Reader;
using wire::run_length_decode;
using wire::run_length_encode;

bool body_ok(const Packet& p, std::size_t input_size) {
  if (p.header.type == PacketType::state_chunk) {
    const StateChunk& c = p.state_chunk;
    return c.total > 0 && c.total <= max_state_transfer && !c.data.empty() &&
           c.data.size() <= max_state_chunk && std::size_t{c.offset} + c.data.size() <= c.total;
  }
  if (p.header.type == PacketType::state_request)
    return p.state_request.offset <= max_state_transfer;
  if (p.header.type != PacketType::input) return true;
  const InputBody& b = p.input;
  return b.deltas.size() == std::size_t{b.count} * input_size &&
         b.checks.size() <= max_checks_per_packet && b.gone.size() <= max_gone_reports &&
         b.back.size() <= max_gone_reports &&
         std::all_of(b.gone.begin(), b.gone.end(),
                     [](const GoneReport& g) { return g.player < max_gone_reports; }) &&
         std::all_of(b.back.begin(), b.back.end(),
                     [](const BackReport& r) { return r.player < max_gone_reports; });
}

}  // namespace

std::string_view to_string(DecodeError error) noexcept {
  switch (error) {
    case DecodeError::none:
      return "none";
    case DecodeError::too_short:
      return "too_short";
    case DecodeError::too_long:
      return "too_long";
    case DecodeError::bad_magic:
      return "bad_magic";
    case DecodeError::bad_version:
      return "bad_version";
    case DecodeError::bad_type:
      return "bad_type";
    case DecodeError::bad_checksum:
      return "bad_checksum";
    case DecodeError::bad_length:
      return "bad_length";
    case DecodeError::bad_field:
      return "bad_field";
  }
  return "unknown";
}

namespace {

// The body of `packet` (its header.type's fields), appended to `out`.
void put_body(const Packet& packet, std::vector<std::uint8_t>& out) {
  switch (packet.header.type) {
    case PacketType::hello:
      put(out, packet.hello.fingerprint, 8);
      out.push_back(packet.hello.players);
      out.push_back(packet.hello.player);
      out.push_back(packet.hello.input_size);
      put(out, packet.hello.challenge, 8);
      break;
    case PacketType::hello_reply:
      put(out, packet.hello_reply.challenge, 8);
      break;
    case PacketType::input: {
      const InputBody& b = packet.input;
      put_varint(out, b.ack_frame);
      put_frame(out, b.check_ack, b.ack_frame);
      put_frame(out, b.current_frame, b.ack_frame);
      out.push_back(static_cast<std::uint8_t>(b.advantage));
      put_frame(out, b.start_frame, b.ack_frame);
      out.push_back(b.count);
      put_frame(out, b.held_frame, b.ack_frame);
      out.push_back(static_cast<std::uint8_t>(b.gone.size() | b.back.size() << 4));
      for (const GoneReport& g : b.gone) {
        out.push_back(g.player);
        put_frame(out, g.frame, b.ack_frame);
      }
      for (const BackReport& r : b.back) {
        out.push_back(r.player);
        put_frame(out, r.from, b.ack_frame);
        put_frame(out, r.until, b.ack_frame);
      }
      run_length_encode(b.deltas, out);
      out.push_back(static_cast<std::uint8_t>(b.checks.size()));
      for (const HashCheck& c : b.checks) {
        put_frame(out, c.frame, b.ack_frame);
        put(out, c.hash, 8);
      }
      break;
    }
    case PacketType::ping:
    case PacketType::pong:
      put(out, packet.ping.time_us, 8);
      break;
    case PacketType::state_request:
      put_varint(out, packet.state_request.offset);
      break;
    case PacketType::state_chunk:
      wire::put_slice(out, packet.state_chunk.total, packet.state_chunk.offset,
                      packet.state_chunk.data);
      break;
  }
}

bool known_type(std::uint8_t type) noexcept {
  return type >= static_cast<std::uint8_t>(PacketType::hello) &&
         type <= static_cast<std::uint8_t>(PacketType::state_chunk);
}

bool handshake(PacketType type) noexcept {
  return type == PacketType::hello || type == PacketType::hello_reply;
}

// The body's fields, from a reader positioned at its start; the reader must end exactly there.
DecodeError get_body(Reader& in, PacketType type, std::size_t input_size, Packet& out) {
  switch (type) {
    case PacketType::hello:
      out.hello.fingerprint = in.u64();
      out.hello.players = in.u8();
      out.hello.player = in.u8();
      out.hello.input_size = in.u8();
      out.hello.challenge = in.u64();
      break;
    case PacketType::hello_reply:
      out.hello_reply.challenge = in.u64();
      break;
    case PacketType::input: {
      InputBody& b = out.input;
      bool bad = false;
      const std::uint64_t ack = in.varint(bad);
      if (ack > 0xFFFF'FFFFU) bad = true;
      b.ack_frame = static_cast<std::uint32_t>(ack);
      b.check_ack = in.frame(b.ack_frame, bad);
      b.current_frame = in.frame(b.ack_frame, bad);
      b.advantage = static_cast<std::int8_t>(in.u8());
      b.start_frame = in.frame(b.ack_frame, bad);
      b.count = in.u8();
      b.held_frame = in.frame(b.ack_frame, bad);
      const std::uint8_t lists = in.u8();
      const std::size_t gone = lists & 0x0FU;
      const std::size_t back = lists >> 4U;
      if (!in.ok()) return DecodeError::bad_length;
      if (bad || gone > max_gone_reports || back > max_gone_reports) return DecodeError::bad_field;
      b.gone.resize(gone);
      for (GoneReport& g : b.gone) {
        g.player = in.u8();
        g.frame = in.frame(b.ack_frame, bad);
        if (g.player >= max_gone_reports) bad = true;
      }
      // Appended one by one: gcc 12 at -O3 takes a resize() of this vector for an overflow
      // (-Wstringop-overflow, a false positive that -Werror turns into a failed build).
      b.back.clear();
      for (std::size_t k = 0; k < back; ++k) {
        BackReport r;
        r.player = in.u8();
        r.from = in.frame(b.ack_frame, bad);
        r.until = in.frame(b.ack_frame, bad);
        if (r.player >= max_gone_reports) bad = true;
        b.back.push_back(r);
      }
      if (!in.ok()) return DecodeError::bad_length;
      if (bad) return DecodeError::bad_field;
      // count <= 255 and input_size <= 513 bound the allocation to 128 KiB whatever the bytes say.
      if (!run_length_decode(in, std::size_t{b.count} * input_size, b.deltas))
        return in.ok() ? DecodeError::bad_field : DecodeError::bad_length;
      const std::uint8_t checks = in.u8();
      if (!in.ok()) return DecodeError::bad_length;
      if (checks > max_checks_per_packet) return DecodeError::bad_field;
      b.checks.resize(checks);
      for (HashCheck& c : b.checks) {
        c.frame = in.frame(b.ack_frame, bad);
        c.hash = in.u64();
      }
      if (!in.ok()) return DecodeError::bad_length;
      if (bad) return DecodeError::bad_field;
      break;
    }
    case PacketType::ping:
    case PacketType::pong:
      out.ping.time_us = in.u64();
      break;
    case PacketType::state_request: {
      bool bad = false;
      const std::uint64_t offset = in.varint(bad);
      if (!in.ok()) return DecodeError::bad_length;
      if (bad || offset > max_state_transfer) return DecodeError::bad_field;
      out.state_request.offset = static_cast<std::uint32_t>(offset);
      break;
    }
    case PacketType::state_chunk: {
      StateChunk& c = out.state_chunk;
      const DecodeError e =
          wire::read_slice(in, max_state_transfer, max_state_chunk, c.total, c.offset, c.data);
      if (e != DecodeError::none) return e;
      break;
    }
  }
  if (!in.ok() || !in.at_end()) return DecodeError::bad_length;
  return DecodeError::none;
}

}  // namespace

bool encode(const Packet& packet, std::size_t input_size, std::vector<std::uint8_t>& out) {
  out.clear();
  if (input_size == 0 || input_size > max_unit_size || !body_ok(packet, input_size) ||
      !known_type(static_cast<std::uint8_t>(packet.header.type)))
    return false;
  out.push_back(magic0);
  out.push_back(magic1);
  out.push_back(version);
  out.push_back(static_cast<std::uint8_t>(packet.header.type));
  put(out, packet.header.session, 8);
  put(out, packet.header.sequence, 2);
  put_body(packet, out);
  if (out.size() + trailer_size > max_datagram) {
    out.clear();
    return false;
  }
  put(out, checksum(out), 4);
  return true;
}

DecodeError decode(std::span<const std::uint8_t> bytes, std::size_t input_size, Packet& out) {
  static_assert(header_size == 14 && trailer_size == 4);  // wire::check_plain's framing
  const wire::PlainFraming framing{magic0, magic1, version,
                                   static_cast<std::uint8_t>(PacketType::hello),
                                   static_cast<std::uint8_t>(PacketType::state_chunk)};
  if (const DecodeError e = wire::check_plain(bytes, framing); e != DecodeError::none) return e;
  if (input_size == 0 || input_size > max_unit_size) return DecodeError::bad_field;
  const std::span<const std::uint8_t> signed_part = bytes.first(bytes.size() - trailer_size);

  Reader in(signed_part);
  in.get(4);  // magic, version, type: checked above
  out.header.type = static_cast<PacketType>(bytes[3]);
  out.header.session = in.u64();
  out.header.sequence = in.u16();
  return get_body(in, out.header.type, input_size, out);
}

std::size_t sealed_header_size(PacketType type) noexcept {
  return handshake(type) ? sealed_handshake_header_size : sealed_data_header_size;
}

bool encode_sealed_plaintext(const Packet& packet, std::uint32_t sequence, std::size_t input_size,
                             std::vector<std::uint8_t>& out) {
  out.clear();
  if (input_size == 0 || input_size > max_unit_size || !body_ok(packet, input_size) ||
      !known_type(static_cast<std::uint8_t>(packet.header.type)))
    return false;
  out.push_back(magic0);
  out.push_back(sealed_magic1);
  out.push_back(version);
  out.push_back(static_cast<std::uint8_t>(packet.header.type));
  put(out, sequence, 4);
  if (handshake(packet.header.type)) put(out, packet.header.session, 8);
  put_body(packet, out);
  if (out.size() + sealed_tag_size > max_datagram) {
    out.clear();
    return false;
  }
  return true;
}

DecodeError decode_sealed_header(std::span<const std::uint8_t> bytes, SealedHeader& out) {
  if (bytes.size() > max_datagram) return DecodeError::too_long;
  if (bytes.size() < sealed_data_header_size + sealed_tag_size) return DecodeError::too_short;
  if (bytes[0] != magic0 || bytes[1] != sealed_magic1) return DecodeError::bad_magic;
  if (bytes[2] != version) return DecodeError::bad_version;
  if (!known_type(bytes[3])) return DecodeError::bad_type;
  out.type = static_cast<PacketType>(bytes[3]);
  out.size = sealed_header_size(out.type);
  if (bytes.size() < out.size + sealed_tag_size) return DecodeError::too_short;
  Reader in(bytes.first(out.size));
  in.get(4);
  out.sequence = in.u32();
  out.session = handshake(out.type) ? in.u64() : 0;
  return DecodeError::none;
}

DecodeError decode_body(PacketType type, std::span<const std::uint8_t> body, std::size_t input_size,
                        Packet& out) {
  if (!known_type(static_cast<std::uint8_t>(type))) return DecodeError::bad_type;
  if (input_size == 0 || input_size > max_unit_size) return DecodeError::bad_field;
  out.header.type = type;
  Reader in(body);
  return get_body(in, type, input_size, out);
}

void delta_encode(std::span<const std::uint8_t> reference, std::span<const std::uint8_t> inputs,
                  std::vector<std::uint8_t>& deltas) {
  const std::size_t size = reference.size();
  deltas.resize(inputs.size());
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    const std::uint8_t previous = i < size ? reference[i] : inputs[i - size];
    deltas[i] = static_cast<std::uint8_t>(inputs[i] ^ previous);
  }
}

void delta_decode(std::span<const std::uint8_t> reference, std::span<std::uint8_t> deltas) {
  const std::size_t size = reference.size();
  for (std::size_t i = 0; i < deltas.size(); ++i) {
    const std::uint8_t previous = i < size ? reference[i] : deltas[i - size];
    deltas[i] = static_cast<std::uint8_t>(deltas[i] ^ previous);
  }
}

}  // namespace detsim::net::protocol
