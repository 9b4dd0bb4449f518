// The game-server wire protocol: encoding and the validating decoder (layout in
// server_protocol.hpp). Like the session protocol, written by hand: every field is range-checked
// before either side sees it, and nothing is allocated beyond a packet's own bounded vectors.
#include <detsim/net/server_protocol.hpp>

#include <algorithm>

#include "wire.hpp"

namespace detsim::net::server_protocol {
namespace {

using wire::checksum;
using wire::put;
using wire::put_frame;
using wire::put_varint;
using wire::Reader;

bool known_type(std::uint8_t type) noexcept {
  return type >= static_cast<std::uint8_t>(PacketType::connect) &&
         type <= static_cast<std::uint8_t>(PacketType::leave);
}

bool sizes_ok(const Sizes& s) noexcept {
  return s.players >= 1 && s.players <= max_players && s.input_size >= 1 &&
         s.input_size <= protocol::max_input_size &&
         unit_size(s.players, s.input_size) <= max_unit_size;
}

/// A frame-sized varint (at most u32), or `bad`.
std::uint32_t get_u32_varint(Reader& in, bool& bad) {
  const std::uint64_t v = in.varint(bad);
  if (v > 0xFFFF'FFFFU) bad = true;
  return static_cast<std::uint32_t>(v);
}

bool body_ok(const Packet& p, const Sizes& sizes) {
  switch (p.header.type) {
    case PacketType::welcome:
      return p.welcome.description.size() <= max_description &&
             static_cast<std::uint8_t>(p.welcome.authority) <= 1;
    case PacketType::input:
      return sizes_ok(sizes) &&
             p.input.inputs.size() == std::size_t{p.input.count} * sizes.input_size;
    case PacketType::update:
      return sizes_ok(sizes) &&
             p.update.units.size() ==
                 std::size_t{p.update.count} * unit_size(sizes.players, sizes.input_size);
    case PacketType::snapshot: {
      const SnapshotChunk& c = p.snapshot;
      return c.total > 0 && c.total <= max_snapshot_size && !c.data.empty() &&
             c.data.size() <= max_snapshot_chunk &&
             std::size_t{c.offset} + c.data.size() <= c.total;
    }
    default:
      return true;
  }
}

void put_body(const Packet& p, const Sizes& sizes, std::vector<std::uint8_t>& out) {
  switch (p.header.type) {
    case PacketType::connect:
      put(out, p.connect.game, 8);
      put(out, p.connect.nonce, 8);
      out.push_back(p.connect.seat);
      break;
    case PacketType::welcome: {
      const Welcome& w = p.welcome;
      put(out, w.nonce, 8);
      out.push_back(w.player);
      out.push_back(w.players);
      out.push_back(w.input_size);
      out.push_back(static_cast<std::uint8_t>(w.authority));
      put(out, w.frame_us, 4);
      put(out, w.frames, 4);
      put(out, w.start_frame, 4);
      put(out, w.initial_hash, 8);
      put_varint(out, w.description.size());
      out.insert(out.end(), w.description.begin(), w.description.end());
      break;
    }
    case PacketType::reject:
      put(out, p.reject.nonce, 8);
      out.push_back(static_cast<std::uint8_t>(p.reject.reason));
      break;
    case PacketType::input: {
      const ClientInput& c = p.input;
      put_varint(out, c.ack);
      put_frame(out, c.snapshot_ack, c.ack);
      put(out, c.time_ms, 4);
      put_frame(out, c.start, c.ack);
      out.push_back(c.count);
      std::vector<std::uint8_t> chained = c.inputs;
      const std::vector<std::uint8_t> zero(sizes.input_size, 0);
      chain(zero, chained);
      wire::run_length_encode(chained, out);
      break;
    }
    case PacketType::update: {
      const Update& u = p.update;
      put_varint(out, u.frame);
      put_frame(out, u.input_ack, u.frame);
      out.push_back(static_cast<std::uint8_t>(u.lead));
      put(out, u.echo_ms, 4);
      put_frame(out, u.start, u.frame);
      out.push_back(u.count);
      wire::run_length_encode(u.units, out);
      if (u.count > 0) put(out, u.hash, 8);
      break;
    }
    case PacketType::snapshot: {
      const SnapshotChunk& c = p.snapshot;
      put_varint(out, c.frame);
      put_frame(out, c.base, c.frame);
      put(out, c.hash, 8);
      wire::put_slice(out, c.total, c.offset, c.data);
      break;
    }
    case PacketType::leave:
      break;
  }
}

DecodeError get_body(Reader& in, PacketType type, const Sizes& sizes, Packet& out) {
  bool bad = false;
  switch (type) {
    case PacketType::connect:
      out.connect.game = in.u64();
      out.connect.nonce = in.u64();
      out.connect.seat = in.u8();
      break;
    case PacketType::welcome: {
      Welcome& w = out.welcome;
      w.nonce = in.u64();
      w.player = in.u8();
      w.players = in.u8();
      w.input_size = in.u8();
      const std::uint8_t authority = in.u8();
      w.frame_us = in.u32();
      w.frames = in.u32();
      w.start_frame = in.u32();
      w.initial_hash = in.u64();
      const std::uint64_t length = in.varint(bad);
      if (!in.ok()) return DecodeError::bad_length;
      if (bad || authority > 1 || length > max_description || length > in.remaining() ||
          w.players == 0 || w.player >= w.players || !sizes_ok({w.players, w.input_size}))
        return DecodeError::bad_field;
      w.authority = static_cast<Authority>(authority);
      w.description.resize(static_cast<std::size_t>(length));
      for (std::uint8_t& b : w.description)
        b = in.u8();
      break;
    }
    case PacketType::reject: {
      out.reject.nonce = in.u64();
      const std::uint8_t reason = in.u8();
      if (!in.ok()) return DecodeError::bad_length;
      if (reason < 1 || reason > 3) return DecodeError::bad_field;
      out.reject.reason = static_cast<RejectReason>(reason);
      break;
    }
    case PacketType::input: {
      if (!sizes_ok(sizes)) return DecodeError::bad_field;
      ClientInput& c = out.input;
      c.ack = get_u32_varint(in, bad);
      c.snapshot_ack = in.frame(c.ack, bad);
      c.time_ms = in.u32();
      c.start = in.frame(c.ack, bad);
      c.count = in.u8();
      if (!in.ok()) return DecodeError::bad_length;
      if (bad) return DecodeError::bad_field;
      // count <= 255 and input_size <= 64 bound the allocation to 16 KiB whatever the bytes say.
      if (!wire::run_length_decode(in, std::size_t{c.count} * sizes.input_size, c.inputs))
        return in.ok() ? DecodeError::bad_field : DecodeError::bad_length;
      const std::vector<std::uint8_t> zero(sizes.input_size, 0);
      unchain(zero, c.inputs);
      break;
    }
    case PacketType::update: {
      if (!sizes_ok(sizes)) return DecodeError::bad_field;
      Update& u = out.update;
      u.frame = get_u32_varint(in, bad);
      u.input_ack = in.frame(u.frame, bad);
      u.lead = static_cast<std::int8_t>(in.u8());
      u.echo_ms = in.u32();
      u.start = in.frame(u.frame, bad);
      u.count = in.u8();
      if (!in.ok()) return DecodeError::bad_length;
      if (bad) return DecodeError::bad_field;
      // count <= 255 and a unit <= 1024 bytes bound the allocation to 255 KiB.
      const std::size_t unit = unit_size(sizes.players, sizes.input_size);
      if (!wire::run_length_decode(in, std::size_t{u.count} * unit, u.units))
        return in.ok() ? DecodeError::bad_field : DecodeError::bad_length;
      u.hash = u.count > 0 ? in.u64() : 0;
      break;
    }
    case PacketType::snapshot: {
      SnapshotChunk& c = out.snapshot;
      c.frame = get_u32_varint(in, bad);
      c.base = in.frame(c.frame, bad);
      c.hash = in.u64();
      if (!in.ok()) return DecodeError::bad_length;
      if (bad) return DecodeError::bad_field;
      const DecodeError e =
          wire::read_slice(in, max_snapshot_size, max_snapshot_chunk, c.total, c.offset, c.data);
      if (e != DecodeError::none) return e;
      break;
    }
    case PacketType::leave:
      break;
  }
  if (!in.ok() || !in.at_end()) return DecodeError::bad_length;
  return DecodeError::none;
}

}  // namespace

bool encode(const Packet& packet, const Sizes& sizes, std::vector<std::uint8_t>& out) {
  out.clear();
  if (!known_type(static_cast<std::uint8_t>(packet.header.type)) || !body_ok(packet, sizes))
    return false;
  out.push_back(magic0);
  out.push_back(magic1);
  out.push_back(version);
  out.push_back(static_cast<std::uint8_t>(packet.header.type));
  put(out, packet.header.token, 8);
  put(out, packet.header.sequence, 2);
  put_body(packet, sizes, out);
  if (out.size() + trailer_size > max_datagram) {
    out.clear();
    return false;
  }
  put(out, checksum(out), 4);
  return true;
}

DecodeError decode(std::span<const std::uint8_t> bytes, const Sizes& sizes, Packet& out) {
  static_assert(header_size == 14 && trailer_size == 4);  // wire::check_plain's framing
  const wire::PlainFraming framing{magic0, magic1, version,
                                   static_cast<std::uint8_t>(PacketType::connect),
                                   static_cast<std::uint8_t>(PacketType::leave)};
  if (const DecodeError e = wire::check_plain(bytes, framing); e != DecodeError::none) return e;
  const std::span<const std::uint8_t> signed_part = bytes.first(bytes.size() - trailer_size);
  Reader in(signed_part);
  in.get(4);  // magic, version, type: checked above
  out.header.type = static_cast<PacketType>(bytes[3]);
  out.header.token = in.u64();
  out.header.sequence = in.u16();
  return get_body(in, out.header.type, sizes, out);
}

void chain(std::span<const std::uint8_t> reference, std::span<std::uint8_t> units) noexcept {
  const std::size_t size = reference.size();
  if (size == 0) return;
  // Backwards, so that each unit is XORed with the one before it as it was.
  for (std::size_t i = units.size(); i-- > 0;) {
    const std::uint8_t previous = i < size ? reference[i] : units[i - size];
    units[i] = static_cast<std::uint8_t>(units[i] ^ previous);
  }
}

void unchain(std::span<const std::uint8_t> reference, std::span<std::uint8_t> units) noexcept {
  const std::size_t size = reference.size();
  if (size == 0) return;
  for (std::size_t i = 0; i < units.size(); ++i) {
    const std::uint8_t previous = i < size ? reference[i] : units[i - size];
    units[i] = static_cast<std::uint8_t>(units[i] ^ previous);
  }
}

}  // namespace detsim::net::server_protocol
