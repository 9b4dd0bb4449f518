// UdpTransport on POSIX sockets, and the numeric endpoint parser and printer.
//
// The socket calls stay in this file: the public header names no OS type, so a port to another
// socket API (Winsock) replaces this file only.
#include <detsim/net/udp.hpp>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstring>
#include <string>
#include <system_error>
#include <utility>

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/types.h>
#include <unistd.h>

namespace detsim::net {

// Helpers in a named namespace: in a unity build this file shares a translation unit with the
// other net/ sources, whose anonymous-namespace helpers would otherwise collide with these.
namespace udp_impl {
namespace {

constexpr std::string_view endpoint_example = "e.g. 127.0.0.1:7000 or [::1]:7000";

Status endpoint_error(std::string_view text, const std::string& problem) {
  return Status::error("endpoint \"" + std::string(text) + "\": " + problem);
}

std::string os_error_text(int err) {
  return std::generic_category().message(err);
}

bool would_block(int err) noexcept {
#if EAGAIN != EWOULDBLOCK
  if (err == EWOULDBLOCK) return true;
#endif
  return err == EAGAIN;
}

// Errors recvfrom reports for an earlier send (an ICMP message queued on the socket, or Windows-
// like stacks reporting a reset): the socket is fine and more datagrams may be waiting.
bool is_reported_send_failure(int err) noexcept {
  return err == ECONNREFUSED || err == ECONNRESET || err == EHOSTUNREACH || err == ENETUNREACH;
}

bool is_digit(char c) noexcept {
  return c >= '0' && c <= '9';
}

// A decimal number without sign, at most `max`. Returns false when `text` is empty, holds a
// non-digit, or exceeds `max` (checked digit by digit, so no overflow whatever the length).
bool parse_decimal(std::string_view text, std::uint32_t max, std::uint32_t& value) noexcept {
  if (text.empty()) return false;
  std::uint32_t v = 0;
  for (char c : text) {
    if (!is_digit(c)) return false;
    v = v * 10 + static_cast<std::uint32_t>(c - '0');
    if (v > max) return false;
  }
  value = v;
  return true;
}

Expected<std::uint16_t> parse_port(std::string_view text, std::string_view port) {
  if (port.empty()) {
    return endpoint_error(
        text, "missing port after ':'; expected ADDRESS:PORT, " + std::string(endpoint_example));
  }
  if (!std::all_of(port.begin(), port.end(), is_digit)) {
    return endpoint_error(text, "port \"" + std::string(port) + "\" is not a decimal number");
  }
  std::uint32_t value = 0;
  if (!parse_decimal(port, 65535, value)) {
    return endpoint_error(text, "port " + std::string(port) + " is out of range 0..65535");
  }
  return static_cast<std::uint16_t>(value);
}

// Four decimal octets "a.b.c.d", each 0..255, no leading zeros. Written here rather than calling
// inet_pton so the accepted forms are the same on every C library (some accept "1.2.3" or octal).
Expected<Endpoint> parse_ipv4(std::string_view text, std::string_view address) {
  const std::string problem_prefix = "bad IPv4 address \"" + std::string(address) + "\": ";
  Endpoint e;
  e.family = IpFamily::v4;
  std::size_t octet = 0;
  std::size_t start = 0;
  while (true) {
    const std::size_t dot = address.find('.', start);
    const std::string_view part =
        address.substr(start, dot == std::string_view::npos ? std::string_view::npos : dot - start);
    std::uint32_t value = 0;
    const bool digits = !part.empty() && std::all_of(part.begin(), part.end(), is_digit);
    if (octet == 4 || !digits) {
      return endpoint_error(text, problem_prefix +
                                      "expected four decimal octets a.b.c.d (numeric only: host "
                                      "names are not resolved)");
    }
    if (part.size() > 1 && part[0] == '0') {
      return endpoint_error(text, problem_prefix + "octet " + std::to_string(octet + 1) + " \"" +
                                      std::string(part) + "\" has a leading zero");
    }
    if (!parse_decimal(part, 255, value)) {
      return endpoint_error(text, problem_prefix + "octet " + std::to_string(octet + 1) + " is " +
                                      std::string(part) + ", must be 0..255");
    }
    e.address[octet++] = static_cast<std::uint8_t>(value);
    if (dot == std::string_view::npos) break;
    start = dot + 1;
  }
  if (octet != 4) {
    return endpoint_error(text, problem_prefix + "expected four decimal octets a.b.c.d");
  }
  return e;
}

Expected<Endpoint> parse_ipv6(std::string_view text, std::string_view address) {
  if (address.find('%') != std::string_view::npos) {
    return endpoint_error(text, "IPv6 zone IDs (\"%...\") are not supported");
  }
  const std::string copy(address);
  in6_addr parsed{};
  if (address.empty() || ::inet_pton(AF_INET6, copy.c_str(), &parsed) != 1) {
    return endpoint_error(text, "bad IPv6 address \"" + copy + "\"");
  }
  Endpoint e;
  e.family = IpFamily::v6;
  std::memcpy(e.address.data(), &parsed, e.address.size());
  return e;
}

std::string format_ipv4(const std::uint8_t* b) {
  return std::to_string(b[0]) + '.' + std::to_string(b[1]) + '.' + std::to_string(b[2]) + '.' +
         std::to_string(b[3]);
}

bool is_ipv4_mapped(const Endpoint& e) noexcept {
  if (e.family != IpFamily::v6) return false;
  for (std::size_t i = 0; i < 10; ++i) {
    if (e.address[i] != 0) return false;
  }
  return e.address[10] == 0xFF && e.address[11] == 0xFF;
}

bool is_unspecified(const Endpoint& e) noexcept {
  const std::size_t n = e.family == IpFamily::v4 ? 4 : 16;
  return std::all_of(e.address.begin(), e.address.begin() + static_cast<std::ptrdiff_t>(n),
                     [](std::uint8_t b) { return b == 0; });
}

// RFC 5952: groups in lower-case hex without leading zeros; the longest run of two or more zero
// groups (the first of equal runs) becomes "::"; IPv4-mapped addresses end in dotted decimal.
std::string format_ipv6(const Endpoint& e) {
  if (is_ipv4_mapped(e)) return "::ffff:" + format_ipv4(e.address.data() + 12);
  std::array<std::uint32_t, 8> groups{};
  for (std::size_t i = 0; i < 8; ++i) {
    groups[i] = (static_cast<std::uint32_t>(e.address[2 * i]) << 8) | e.address[2 * i + 1];
  }
  std::size_t best_start = 8;
  std::size_t best_length = 1;  // a run must be longer than this to be shortened
  for (std::size_t i = 0; i < 8;) {
    if (groups[i] != 0) {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j < 8 && groups[j] == 0)
      ++j;
    if (j - i > best_length) {
      best_start = i;
      best_length = j - i;
    }
    i = j;
  }
  static constexpr char hex[] = "0123456789abcdef";
  std::string out;
  for (std::size_t i = 0; i < 8; ++i) {
    if (i == best_start) {
      out += "::";
      i += best_length - 1;
      continue;
    }
    if (!out.empty() && out.back() != ':') out += ':';
    bool leading = true;
    for (int shift = 12; shift >= 0; shift -= 4) {
      const std::uint32_t digit = (groups[i] >> shift) & 0xFU;
      if (digit == 0 && leading && shift != 0) continue;
      leading = false;
      out += hex[digit];
    }
  }
  return out;
}

Endpoint normalized(Endpoint e) noexcept {
  if (e.family == IpFamily::v4) std::fill(e.address.begin() + 4, e.address.end(), 0);
  return e;
}

// Endpoint -> sockaddr. Ports and addresses are stored in network byte order, written byte by byte
// so no htons (a macro with casts on some C libraries) is needed.
socklen_t to_sockaddr(const Endpoint& e, sockaddr_storage& storage) noexcept {
  storage = sockaddr_storage{};
  const std::array<std::uint8_t, 2> port{static_cast<std::uint8_t>(e.port >> 8),
                                         static_cast<std::uint8_t>(e.port & 0xFFU)};
  if (e.family == IpFamily::v4) {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    std::memcpy(&a.sin_port, port.data(), 2);
    std::memcpy(&a.sin_addr, e.address.data(), 4);
    std::memcpy(&storage, &a, sizeof a);
    return sizeof a;
  }
  sockaddr_in6 a{};
  a.sin6_family = AF_INET6;
  std::memcpy(&a.sin6_port, port.data(), 2);
  std::memcpy(&a.sin6_addr, e.address.data(), 16);
  std::memcpy(&storage, &a, sizeof a);
  return sizeof a;
}

// sockaddr -> Endpoint; false for any other family or a short address.
bool from_sockaddr(const sockaddr_storage& storage, socklen_t length, Endpoint& out) noexcept {
  std::array<std::uint8_t, 2> port{};
  if (storage.ss_family == AF_INET && length >= static_cast<socklen_t>(sizeof(sockaddr_in))) {
    sockaddr_in a{};
    std::memcpy(&a, &storage, sizeof a);
    out = Endpoint{};
    out.family = IpFamily::v4;
    std::memcpy(out.address.data(), &a.sin_addr, 4);
    std::memcpy(port.data(), &a.sin_port, 2);
  } else if (storage.ss_family == AF_INET6 &&
             length >= static_cast<socklen_t>(sizeof(sockaddr_in6))) {
    sockaddr_in6 a{};
    std::memcpy(&a, &storage, sizeof a);
    out = Endpoint{};
    out.family = IpFamily::v6;
    std::memcpy(out.address.data(), &a.sin6_addr, 16);
    std::memcpy(port.data(), &a.sin6_port, 2);
  } else {
    return false;
  }
  out.port = static_cast<std::uint16_t>((port[0] << 8) | port[1]);
  return true;
}

std::string_view family_name(IpFamily f) noexcept {
  return f == IpFamily::v4 ? "IPv4" : "IPv6";
}

// Sets an int socket option; the error names the option.
Status set_int_option(int socket, int level, int option, int value, std::string_view what) {
  if (::setsockopt(socket, level, option, &value, sizeof value) != 0) {
    return Status::error(std::string(what) + ": " + os_error_text(errno));
  }
  return Status::success();
}

}  // namespace
}  // namespace udp_impl

// ---------------------------------------------------------------------------------------------
// Endpoint

std::string Endpoint::to_string() const {
  const std::string address_text = family == IpFamily::v4
                                       ? udp_impl::format_ipv4(address.data())
                                       : '[' + udp_impl::format_ipv6(*this) + ']';
  return address_text + ':' + std::to_string(port);
}

Expected<Endpoint> parse_endpoint(std::string_view text) {
  using udp_impl::endpoint_error;
  if (text.empty()) {
    return endpoint_error(
        text, "empty; expected ADDRESS:PORT, " + std::string(udp_impl::endpoint_example));
  }
  std::string_view address;
  std::string_view port;
  bool ipv6 = false;
  if (text.front() == '[') {
    const std::size_t bracket = text.find(']');
    if (bracket == std::string_view::npos) {
      return endpoint_error(text, "missing ']' after the IPv6 address");
    }
    address = text.substr(1, bracket - 1);
    const std::string_view rest = text.substr(bracket + 1);
    if (rest.empty()) {
      return endpoint_error(text, "missing port; expected [IPV6]:PORT, e.g. [::1]:7000");
    }
    if (rest.front() != ':') {
      return endpoint_error(text, "expected ':' and a port after ']'");
    }
    port = rest.substr(1);
    ipv6 = true;
  } else {
    const std::size_t colon = text.find(':');
    if (colon == std::string_view::npos) {
      return endpoint_error(
          text, "missing port; expected ADDRESS:PORT, " + std::string(udp_impl::endpoint_example));
    }
    if (text.find(':', colon + 1) != std::string_view::npos) {
      return endpoint_error(text, "an IPv6 address must be in brackets, e.g. [::1]:7000");
    }
    address = text.substr(0, colon);
    port = text.substr(colon + 1);
  }
  Expected<Endpoint> parsed =
      ipv6 ? udp_impl::parse_ipv6(text, address) : udp_impl::parse_ipv4(text, address);
  if (!parsed) return parsed;
  const Expected<std::uint16_t> port_value = udp_impl::parse_port(text, port);
  if (!port_value) return port_value.status();
  Endpoint e = parsed.value();
  e.port = port_value.value();
  return e;
}

// ---------------------------------------------------------------------------------------------
// UdpTransport: lifetime

UdpTransport::UdpTransport(int socket, const Endpoint& local, const UdpOptions& options) noexcept
    : socket_(socket), local_(local), options_(options) {}

UdpTransport::UdpTransport(UdpTransport&& other) noexcept
    : Transport(),
      socket_(std::exchange(other.socket_, -1)),
      local_(other.local_),
      options_(other.options_),
      peers_by_id_(std::move(other.peers_by_id_)),
      peers_by_endpoint_(std::move(other.peers_by_endpoint_)),
      buffer_(std::move(other.buffer_)),
      next_admitted_(other.next_admitted_),
      stats_(other.stats_),
      last_error_(std::move(other.last_error_)) {}

UdpTransport& UdpTransport::operator=(UdpTransport&& other) noexcept {
  if (this != &other) {
    close_socket();
    socket_ = std::exchange(other.socket_, -1);
    local_ = other.local_;
    options_ = other.options_;
    peers_by_id_ = std::move(other.peers_by_id_);
    peers_by_endpoint_ = std::move(other.peers_by_endpoint_);
    buffer_ = std::move(other.buffer_);
    next_admitted_ = other.next_admitted_;
    stats_ = other.stats_;
    last_error_ = std::move(other.last_error_);
  }
  return *this;
}

UdpTransport::~UdpTransport() {
  close_socket();
}

void UdpTransport::close_socket() noexcept {
  // No retry on EINTR: on Linux the descriptor is released even then, and a retry could close a
  // descriptor another thread has just been given.
  if (socket_ >= 0) ::close(socket_);
  socket_ = -1;
}

Expected<UdpTransport> UdpTransport::open(const Endpoint& bind, std::span<const UdpPeer> peers,
                                          const UdpOptions& options) {
  const Endpoint local = udp_impl::normalized(bind);
  const std::string where = local.to_string();
  if (options.max_datagrams_per_receive == 0) {
    return Status::error("open " + where + ": max_datagrams_per_receive must be >= 1");
  }
  if (options.socket_buffer_bytes > static_cast<std::uint32_t>(INT_MAX)) {
    return Status::error("open " + where + ": socket_buffer_bytes " +
                         std::to_string(options.socket_buffer_bytes) + " is above INT_MAX");
  }
  if (udp_impl::is_ipv4_mapped(local)) {
    return Status::error("open " + where +
                         ": an IPv4-mapped IPv6 address cannot be bound with IPV6_V6ONLY; bind "
                         "the IPv4 address instead");
  }
  const bool v4 = local.family == IpFamily::v4;
  const int fd = ::socket(v4 ? AF_INET : AF_INET6, SOCK_DGRAM, IPPROTO_UDP);
  if (fd < 0) return Status::error("socket for " + where + ": " + udp_impl::os_error_text(errno));
  UdpTransport t(fd, local, options);  // owns fd from here: every early return closes it

  // fcntl rather than SOCK_NONBLOCK | SOCK_CLOEXEC, which not every POSIX system has.
  const int flags = ::fcntl(fd, F_GETFL, 0);
  if (flags < 0 || ::fcntl(fd, F_SETFL, flags | O_NONBLOCK) != 0 ||
      ::fcntl(fd, F_SETFD, FD_CLOEXEC) != 0) {
    return Status::error("fcntl on the socket for " + where + ": " +
                         udp_impl::os_error_text(errno));
  }
  if (!v4) {
    // Explicit, because the default differs between systems (Linux: off, BSDs: on).
    const Status s = udp_impl::set_int_option(fd, IPPROTO_IPV6, IPV6_V6ONLY, 1,
                                              "IPV6_V6ONLY on the socket for " + where);
    if (!s) return s;
  }
  if (options.socket_buffer_bytes != 0) {
    const int bytes = static_cast<int>(options.socket_buffer_bytes);
    Status s = udp_impl::set_int_option(fd, SOL_SOCKET, SO_RCVBUF, bytes, "SO_RCVBUF for " + where);
    if (s) s = udp_impl::set_int_option(fd, SOL_SOCKET, SO_SNDBUF, bytes, "SO_SNDBUF for " + where);
    if (!s) return s;
  }

  sockaddr_storage address{};
  const socklen_t length = udp_impl::to_sockaddr(local, address);
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&address), length) != 0) {
    return Status::error("bind " + where + ": " + udp_impl::os_error_text(errno));
  }
  sockaddr_storage bound{};
  socklen_t bound_length = sizeof bound;
  if (::getsockname(fd, reinterpret_cast<sockaddr*>(&bound), &bound_length) != 0 ||
      !udp_impl::from_sockaddr(bound, bound_length, t.local_)) {
    return Status::error("getsockname after binding " + where + ": " +
                         udp_impl::os_error_text(errno));
  }

  for (const UdpPeer& peer : peers) {
    const Status s = t.add_peer(peer);
    if (!s) return Status::error("open " + where + ": " + s.message());
  }
  t.buffer_.resize(max_datagram + 1);
  return Expected<UdpTransport>(std::move(t));
}

// ---------------------------------------------------------------------------------------------
// UdpTransport: peers

const UdpPeer* UdpTransport::find_peer(PeerId id) const noexcept {
  const auto it = std::lower_bound(peers_by_id_.begin(), peers_by_id_.end(), id,
                                   [](const UdpPeer& p, PeerId key) { return p.id < key; });
  return it != peers_by_id_.end() && it->id == id ? &*it : nullptr;
}

const UdpPeer* UdpTransport::find_peer(const Endpoint& endpoint) const noexcept {
  const auto it =
      std::lower_bound(peers_by_endpoint_.begin(), peers_by_endpoint_.end(), endpoint,
                       [](const UdpPeer& p, const Endpoint& key) { return p.endpoint < key; });
  return it != peers_by_endpoint_.end() && it->endpoint == endpoint ? &*it : nullptr;
}

Status UdpTransport::add_peer(const UdpPeer& given) {
  const UdpPeer peer{given.id, udp_impl::normalized(given.endpoint)};
  const std::string name =
      "peer " + std::to_string(peer.id) + " (" + peer.endpoint.to_string() + ")";
  if (peer.endpoint.family != local_.family) {
    return Status::error(name + ": is " + std::string(udp_impl::family_name(peer.endpoint.family)) +
                         " but the transport is bound to " +
                         std::string(udp_impl::family_name(local_.family)) + " address " +
                         local_.to_string() + "; one transport talks to one address family");
  }
  if (peer.endpoint.port == 0) return Status::error(name + ": port 0 cannot be sent to");
  if (udp_impl::is_unspecified(peer.endpoint)) {
    return Status::error(name + ": the unspecified address cannot be sent to");
  }
  if (udp_impl::is_ipv4_mapped(peer.endpoint)) {
    return Status::error(name +
                         ": an IPv4-mapped address is unreachable from an IPv6-only socket; open "
                         "an IPv4 transport for IPv4 peers");
  }
  if (const UdpPeer* other = find_peer(peer.id)) {
    return Status::error(name + ": PeerId " + std::to_string(peer.id) + " is already " +
                         other->endpoint.to_string());
  }
  if (const UdpPeer* other = find_peer(peer.endpoint)) {
    return Status::error(name + ": endpoint already belongs to peer " + std::to_string(other->id));
  }
  // Reserve both before taking positions (reserving invalidates iterators), so that the second
  // insert cannot fail after the first succeeded.
  peers_by_id_.reserve(peers_by_id_.size() + 1);
  peers_by_endpoint_.reserve(peers_by_endpoint_.size() + 1);
  const auto by_id = std::lower_bound(peers_by_id_.begin(), peers_by_id_.end(), peer.id,
                                      [](const UdpPeer& p, PeerId key) { return p.id < key; });
  const auto by_endpoint =
      std::lower_bound(peers_by_endpoint_.begin(), peers_by_endpoint_.end(), peer.endpoint,
                       [](const UdpPeer& p, const Endpoint& key) { return p.endpoint < key; });
  peers_by_id_.insert(by_id, peer);
  peers_by_endpoint_.insert(by_endpoint, peer);
  return Status::success();
}

std::size_t UdpTransport::admitted_peers() const noexcept {
  const auto first = std::lower_bound(peers_by_id_.begin(), peers_by_id_.end(), first_admitted_peer,
                                      [](const UdpPeer& p, PeerId key) { return p.id < key; });
  return static_cast<std::size_t>(peers_by_id_.end() - first);
}

bool UdpTransport::remove_peer(PeerId id) {
  const UdpPeer* peer = find_peer(id);
  if (peer == nullptr) return false;
  const Endpoint endpoint = peer->endpoint;
  std::erase_if(peers_by_id_, [id](const UdpPeer& p) { return p.id == id; });
  std::erase_if(peers_by_endpoint_, [&](const UdpPeer& p) { return p.endpoint == endpoint; });
  return true;
}

// ---------------------------------------------------------------------------------------------
// UdpTransport: datagrams

void UdpTransport::send(PeerId to, std::span<const std::uint8_t> bytes) {
  if (!is_open()) {
    ++stats_.send_errors;
    last_error_ = "send to peer " + std::to_string(to) + ": the transport is closed (moved from)";
    return;
  }
  const UdpPeer* peer = find_peer(to);
  if (peer == nullptr) {
    ++stats_.dropped_unknown_peer;
    return;
  }
  if (bytes.size() > max_datagram) {
    ++stats_.dropped_oversize_send;
    return;
  }
  sockaddr_storage address{};
  const socklen_t length = udp_impl::to_sockaddr(peer->endpoint, address);
  int flags = 0;
#ifdef MSG_NOSIGNAL
  flags |= MSG_NOSIGNAL;
#endif
#ifdef MSG_DONTWAIT
  flags |= MSG_DONTWAIT;  // the socket is O_NONBLOCK already; this guards against a changed fd
#endif
  ssize_t n = -1;
  int err = 0;
  for (int attempt = 0; attempt < 3; ++attempt) {  // a signal may interrupt; do not spin on it
    n = ::sendto(socket_, bytes.data(), bytes.size(), flags,
                 reinterpret_cast<const sockaddr*>(&address), length);
    err = n < 0 ? errno : 0;
    if (err != EINTR) break;
  }
  if (n < 0 || static_cast<std::size_t>(n) != bytes.size()) {
    ++stats_.send_errors;
    last_error_ = "sendto " + peer->endpoint.to_string() + ": " +
                  (n < 0 ? udp_impl::os_error_text(err) : std::string("short write"));
    return;
  }
  ++stats_.sent;
  stats_.sent_bytes += bytes.size();
}

void UdpTransport::receive(std::vector<Datagram>& out) {
  if (!is_open()) return;
  for (std::size_t read = 0; read < options_.max_datagrams_per_receive; ++read) {
    sockaddr_storage from{};
    socklen_t from_length = sizeof from;
    // The buffer is one byte longer than max_datagram: recvfrom truncates a longer datagram to
    // the buffer's size, so a full buffer means "too long" on every system.
    const ssize_t n = ::recvfrom(socket_, buffer_.data(), buffer_.size(), 0,
                                 reinterpret_cast<sockaddr*>(&from), &from_length);
    if (n < 0) {
      const int err = errno;
      if (err == EINTR) continue;
      if (udp_impl::would_block(err)) return;
      ++stats_.receive_errors;
      last_error_ = "recvfrom on " + local_.to_string() + ": " + udp_impl::os_error_text(err);
      if (udp_impl::is_reported_send_failure(err)) continue;
      return;  // anything else may repeat on every call: stop here, try again next call
    }
    Endpoint sender;
    const bool parsed = udp_impl::from_sockaddr(from, from_length, sender);
    const UdpPeer* peer = parsed ? find_peer(sender) : nullptr;
    if (peer == nullptr && parsed && admitted_peers() < options_.admit_unknown_senders &&
        next_admitted_ != 0 && add_peer({next_admitted_, sender}).ok()) {
      ++next_admitted_;  // 0 after the last id: no more admissions, ever
      ++stats_.admitted_senders;
      peer = find_peer(sender);
    }
    if (peer == nullptr) {
      ++stats_.dropped_unknown_sender;
      continue;
    }
    const auto size = static_cast<std::size_t>(n);
    if (size > max_datagram) {
      ++stats_.dropped_oversize;
      continue;
    }
    Datagram d;
    d.from = peer->id;
    d.bytes.assign(buffer_.begin(), buffer_.begin() + n);
    out.push_back(std::move(d));
    ++stats_.received;
    stats_.received_bytes += size;
  }
}

}  // namespace detsim::net
