// The C API (<detsim/detsim.h>) over the C++ World. Every entry point catches everything: a
// std::bad_alloc becomes DETSIM_OUT_OF_MEMORY, anything else DETSIM_INTERNAL_ERROR, and a refusal
// of the library (an Expected or Status error) DETSIM_INVALID_ARGUMENT; the message of the last
// failure is kept per thread for detsim_last_error.
#include <detsim/detsim.h>

#include <array>
#include <cstring>
#include <exception>
#include <memory>
#include <new>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <detsim/core/version.hpp>
#include <detsim/fixed/decimal.hpp>
#include <detsim/net/game.hpp>
#include <detsim/net/session.hpp>
#include <detsim/net/sim_network.hpp>
#include <detsim/net/transport.hpp>
#include <detsim/sim/world.hpp>
#if DETSIM_WITH_UDP
#include <detsim/net/udp.hpp>
#endif

struct detsim_world {
  detsim::World world;
};

struct detsim_network {
  detsim::net::SimNetwork network;
};

namespace detsim_c {

// The game's own network as a net::Transport: send() calls the game's function; what the game
// delivers waits in a bounded queue for the session's next receive().
class CallbackTransport final : public detsim::net::Transport {
 public:
  static constexpr std::size_t max_waiting = 4096;

  CallbackTransport(detsim_send_fn send_fn, void* context) : send_(send_fn), context_(context) {}
  void send(detsim::net::PeerId to, std::span<const std::uint8_t> bytes) override {
    send_(context_, to, bytes.data(), bytes.size());
  }
  void receive(std::vector<detsim::net::Datagram>& out) override {
    for (detsim::net::Datagram& d : waiting_)
      out.push_back(std::move(d));
    waiting_.clear();
  }
  /// False when the queue is full (the datagram is dropped).
  bool deliver(std::uint32_t from, std::span<const std::uint8_t> bytes) {
    if (waiting_.size() >= max_waiting) return false;
    waiting_.push_back({from, std::vector<std::uint8_t>(bytes.begin(), bytes.end())});
    return true;
  }

 private:
  detsim_send_fn send_;
  void* context_;
  std::vector<detsim::net::Datagram> waiting_;
};

}  // namespace detsim_c

struct detsim_transport {
  std::unique_ptr<detsim::net::Transport> transport;
  detsim_c::CallbackTransport* callbacks = nullptr;  ///< when made by detsim_transport_create
#if DETSIM_WITH_UDP
  detsim::net::UdpTransport* udp = nullptr;  ///< when made by detsim_udp_open
#endif
};

namespace detsim_c {

// The C callbacks as a net::Game. The session keeps the bytes save() writes; the game's own
// buffer is copied out and handed back to it at once.
class CallbackGame final : public detsim::net::Game {
 public:
  explicit CallbackGame(const detsim_game& game) : game_(game) {}

  std::uint64_t save(std::vector<std::uint8_t>& state) override {
    std::uint8_t* buffer = nullptr;
    std::size_t size = 0;
    const std::uint64_t hash = game_.save(game_.context, &buffer, &size);
    state.assign(buffer, buffer + (buffer == nullptr ? 0 : size));
    if (buffer != nullptr && game_.free_buffer != nullptr) game_.free_buffer(game_.context, buffer);
    return hash;
  }
  void load(std::span<const std::uint8_t> state) override {
    game_.load(game_.context, state.data(), state.size());
  }
  void advance(const detsim::net::FrameInputs& inputs, bool resimulating) override {
    status_.resize(inputs.status.size());
    for (std::size_t i = 0; i < inputs.status.size(); ++i)
      status_[i] = static_cast<std::uint8_t>(inputs.status[i]);
    game_.advance(game_.context, inputs.frame, inputs.bytes.data(),
                  static_cast<std::uint32_t>(inputs.players()),
                  static_cast<std::uint32_t>(inputs.input_size), status_.data(),
                  resimulating ? 1 : 0);
  }

 private:
  detsim_game game_;
  std::vector<std::uint8_t> status_;
};

}  // namespace detsim_c

struct detsim_session {
  std::unique_ptr<detsim_c::CallbackGame> game;
  std::unique_ptr<detsim::net::Session> session;
  /// The last kept_hashes confirmed frames' hashes, by frame % kept_hashes.
  static constexpr std::size_t kept_hashes = 1024;
  std::array<std::uint64_t, kept_hashes> frames{};
  std::array<std::uint64_t, kept_hashes> hashes{};
  std::array<bool, kept_hashes> kept{};  ///< the slot holds a frame
};

namespace {

using detsim::Fixed;

thread_local std::string last_error;

detsim_result fail(detsim_result result, std::string message) {
  last_error = std::move(message);
  return result;
}

detsim_result ok() {
  last_error.clear();
  return DETSIM_OK;
}

detsim_result refused(const detsim::Status& status) {
  return status.ok() ? ok() : fail(DETSIM_INVALID_ARGUMENT, status.message());
}

// Runs `body`, turning every exception into a result.
template <class F>
detsim_result guarded(const char* what, F&& body) noexcept {
  try {
    return body();
  } catch (const std::bad_alloc&) {
    return fail(DETSIM_OUT_OF_MEMORY, std::string(what) + ": out of memory");
  } catch (const std::exception& e) {
    return fail(DETSIM_INTERNAL_ERROR, std::string(what) + ": " + e.what());
  } catch (...) {
    return fail(DETSIM_INTERNAL_ERROR, std::string(what) + ": an unknown exception");
  }
}

detsim_result null_argument(const char* what, const char* name) {
  return fail(DETSIM_INVALID_ARGUMENT, std::string(what) + ": " + name + " is NULL");
}

Fixed fx(detsim_fixed raw) {
  return Fixed::from_raw(raw);
}
detsim::Vec3 vec(detsim_vec3 v) {
  return {fx(v.x), fx(v.y), fx(v.z)};
}
detsim_vec3 vec(detsim::Vec3 v) {
  return {v.x.raw(), v.y.raw(), v.z.raw()};
}
detsim::Quat quat(detsim_quat q) {
  return {fx(q.w), fx(q.x), fx(q.y), fx(q.z)};
}
detsim_quat quat(detsim::Quat q) {
  return {q.w.raw(), q.x.raw(), q.y.raw(), q.z.raw()};
}

// The C shape as a Shape, or an error naming what is wrong (the world checks the sizes).
bool to_shape(const detsim_shape& in, detsim::Shape& out, std::string& error) {
  switch (in.type) {
    case DETSIM_SHAPE_SPHERE:
      out = detsim::Shape::sphere(fx(in.radius));
      return true;
    case DETSIM_SHAPE_BOX:
      out = detsim::Shape::box(vec(in.half_extents));
      return true;
    case DETSIM_SHAPE_CAPSULE:
      out = detsim::Shape::capsule(fx(in.radius), fx(in.half_height));
      return true;
    case DETSIM_SHAPE_PLANE:
      out = detsim::Shape::plane();
      return true;
    case DETSIM_SHAPE_CYLINDER:
      out = detsim::Shape::cylinder(fx(in.radius), fx(in.half_height));
      return true;
    default:
      error = "shape type " + std::to_string(in.type) + " is not one of 1 (sphere), 2 (box), " +
              "3 (capsule), 4 (plane), 5 (cylinder)";
      return false;
  }
}

detsim_hit to_hit(detsim::BodyId body, detsim::Vec3 point, detsim::Vec3 normal, Fixed fraction) {
  return {body.value, vec(point), vec(normal), fraction.raw()};
}

}  // namespace

extern "C" {

const char* detsim_last_error(void) {
  return last_error.c_str();
}

const char* detsim_version(void) {
  static const std::string version(detsim::version);
  return version.c_str();
}

detsim_fixed detsim_fixed_from_int(int32_t value) {
  return Fixed::from_int(value).raw();
}

detsim_result detsim_fixed_parse(const char* text, detsim_fixed* out) {
  return guarded("detsim_fixed_parse", [&] {
    if (text == nullptr) return null_argument("detsim_fixed_parse", "text");
    if (out == nullptr) return null_argument("detsim_fixed_parse", "out");
    const detsim::ParseResult r = Fixed::parse(text);
    if (!r.ok()) {
      return fail(DETSIM_INVALID_ARGUMENT, std::string("detsim_fixed_parse: \"") + text +
                                               "\": " + detsim::describe(r.error) +
                                               " at character " + std::to_string(r.position));
    }
    *out = r.value.raw();
    return ok();
  });
}

double detsim_fixed_to_double(detsim_fixed value) {
  return fx(value).to_double();
}

void detsim_world_def_init(detsim_world_def* def) {
  if (def == nullptr) return;
  const detsim::WorldDef d;
  def->gravity = vec(d.gravity);
  def->dt = d.dt.raw();
  def->substeps = d.substeps;
  def->iterations = d.iterations;
  def->seed = d.seed;
}

detsim_result detsim_world_create(const detsim_world_def* def, detsim_world** out) {
  return guarded("detsim_world_create", [&] {
    if (out == nullptr) return null_argument("detsim_world_create", "out");
    detsim::WorldDef d;
    if (def != nullptr) {
      d.gravity = vec(def->gravity);
      d.dt = fx(def->dt);
      d.substeps = def->substeps;
      d.iterations = def->iterations;
      d.seed = def->seed;
    }
    auto world = detsim::World::create(d);
    if (!world.ok()) return fail(DETSIM_INVALID_ARGUMENT, world.message());
    *out = new detsim_world{std::move(world.value())};
    return ok();
  });
}

void detsim_world_destroy(detsim_world* world) {
  delete world;
}

detsim_result detsim_world_step(detsim_world* world) {
  return guarded("detsim_world_step", [&] {
    if (world == nullptr) return null_argument("detsim_world_step", "world");
    world->world.step();
    return ok();
  });
}

uint64_t detsim_world_frame(const detsim_world* world) {
  return world == nullptr ? 0 : world->world.frame();
}

detsim_result detsim_world_save(const detsim_world* world, uint8_t* buffer, size_t capacity,
                                size_t* size) {
  return guarded("detsim_world_save", [&] {
    if (world == nullptr) return null_argument("detsim_world_save", "world");
    if (size == nullptr) return null_argument("detsim_world_save", "size");
    const std::vector<std::uint8_t> bytes = world->world.save();
    *size = bytes.size();
    if (buffer == nullptr && capacity == 0) return ok();  // a size query
    if (buffer == nullptr || capacity < bytes.size()) {
      return fail(DETSIM_BUFFER_TOO_SMALL, "detsim_world_save: the state takes " +
                                               std::to_string(bytes.size()) +
                                               " bytes, the buffer " + std::to_string(capacity));
    }
    std::memcpy(buffer, bytes.data(), bytes.size());
    return ok();
  });
}

detsim_result detsim_world_restore(detsim_world* world, const uint8_t* bytes, size_t size) {
  return guarded("detsim_world_restore", [&] {
    if (world == nullptr) return null_argument("detsim_world_restore", "world");
    if (bytes == nullptr && size > 0) return null_argument("detsim_world_restore", "bytes");
    return refused(world->world.restore({bytes, size}));
  });
}

detsim_result detsim_world_hash(const detsim_world* world, uint64_t* out) {
  return guarded("detsim_world_hash", [&] {
    if (world == nullptr) return null_argument("detsim_world_hash", "world");
    if (out == nullptr) return null_argument("detsim_world_hash", "out");
    *out = world->world.hashes().total;
    return ok();
  });
}

void detsim_body_def_init(detsim_body_def* def) {
  if (def == nullptr) return;
  const detsim::BodyDef d;
  std::memset(def, 0, sizeof *def);
  def->type = static_cast<std::uint32_t>(d.type);
  def->shape.type = DETSIM_SHAPE_SPHERE;
  def->shape.radius = d.shape.radius.raw();
  def->position = vec(d.position);
  def->orientation = quat(d.orientation);
  def->linear_velocity = vec(d.linear_velocity);
  def->angular_velocity = vec(d.angular_velocity);
  def->mass = d.mass.raw();
  def->density = d.density.raw();
  def->friction = d.friction.raw();
  def->restitution = d.restitution.raw();
  def->layer = d.layer;
  def->mask = d.mask;
  def->user_data = d.user_data;
}

detsim_result detsim_body_create(detsim_world* world, const detsim_body_def* def, uint32_t* id) {
  return guarded("detsim_body_create", [&] {
    if (world == nullptr) return null_argument("detsim_body_create", "world");
    if (def == nullptr) return null_argument("detsim_body_create", "def");
    if (id == nullptr) return null_argument("detsim_body_create", "id");
    if (def->type > DETSIM_BODY_DYNAMIC) {
      return fail(DETSIM_INVALID_ARGUMENT, "body definition: type " + std::to_string(def->type) +
                                               " is not 0 (static), 1 (kinematic) or 2 (dynamic)");
    }
    detsim::BodyDef d;
    std::string error;
    if (!to_shape(def->shape, d.shape, error))
      return fail(DETSIM_INVALID_ARGUMENT, "body definition: " + error);
    d.type = static_cast<detsim::BodyType>(def->type);
    d.position = vec(def->position);
    d.orientation = quat(def->orientation);
    d.linear_velocity = vec(def->linear_velocity);
    d.angular_velocity = vec(def->angular_velocity);
    d.mass = fx(def->mass);
    d.density = fx(def->density);
    d.friction = fx(def->friction);
    d.restitution = fx(def->restitution);
    d.layer = def->layer;
    d.mask = def->mask;
    d.user_data = def->user_data;
    auto created = world->world.create_body(d);
    if (!created.ok()) return fail(DETSIM_INVALID_ARGUMENT, created.message());
    *id = created->value;
    return ok();
  });
}

detsim_result detsim_body_destroy(detsim_world* world, uint32_t id) {
  return guarded("detsim_body_destroy", [&] {
    if (world == nullptr) return null_argument("detsim_body_destroy", "world");
    return refused(world->world.destroy_body(detsim::BodyId{id}));
  });
}

detsim_result detsim_body_get(const detsim_world* world, uint32_t id, detsim_body_state* out) {
  return guarded("detsim_body_get", [&] {
    if (world == nullptr) return null_argument("detsim_body_get", "world");
    if (out == nullptr) return null_argument("detsim_body_get", "out");
    const auto b = world->world.body(detsim::BodyId{id});
    if (!b.ok()) return fail(DETSIM_INVALID_ARGUMENT, b.message());
    out->id = b->id.value;
    out->type = static_cast<std::uint32_t>(b->type);
    out->position = vec(b->position);
    out->orientation = quat(b->orientation);
    out->linear_velocity = vec(b->linear_velocity);
    out->angular_velocity = vec(b->angular_velocity);
    out->mass = b->mass.raw();
    out->awake = b->awake ? 1 : 0;
    out->user_data = b->user_data;
    return ok();
  });
}

detsim_result detsim_body_apply_force(detsim_world* world, uint32_t id, detsim_vec3 force) {
  return guarded("detsim_body_apply_force", [&] {
    if (world == nullptr) return null_argument("detsim_body_apply_force", "world");
    return refused(world->world.apply_force(detsim::BodyId{id}, vec(force)));
  });
}

detsim_result detsim_body_apply_impulse(detsim_world* world, uint32_t id, detsim_vec3 impulse) {
  return guarded("detsim_body_apply_impulse", [&] {
    if (world == nullptr) return null_argument("detsim_body_apply_impulse", "world");
    return refused(world->world.apply_linear_impulse(detsim::BodyId{id}, vec(impulse)));
  });
}

detsim_result detsim_body_set_linear_velocity(detsim_world* world, uint32_t id,
                                              detsim_vec3 velocity) {
  return guarded("detsim_body_set_linear_velocity", [&] {
    if (world == nullptr) return null_argument("detsim_body_set_linear_velocity", "world");
    return refused(world->world.set_linear_velocity(detsim::BodyId{id}, vec(velocity)));
  });
}

detsim_result detsim_world_raycast(const detsim_world* world, detsim_vec3 origin,
                                   detsim_vec3 translation, detsim_hit* hit, int* found) {
  return guarded("detsim_world_raycast", [&] {
    if (world == nullptr) return null_argument("detsim_world_raycast", "world");
    if (hit == nullptr) return null_argument("detsim_world_raycast", "hit");
    if (found == nullptr) return null_argument("detsim_world_raycast", "found");
    const auto h = world->world.raycast_closest(vec(origin), vec(translation));
    *found = h ? 1 : 0;
    if (h) *hit = to_hit(h->body, h->point, h->normal, h->fraction);
    return ok();
  });
}

detsim_result detsim_world_shape_cast(const detsim_world* world, const detsim_shape* shape,
                                      detsim_vec3 position, detsim_quat orientation,
                                      detsim_vec3 translation, detsim_hit* hit, int* found) {
  return guarded("detsim_world_shape_cast", [&] {
    if (world == nullptr) return null_argument("detsim_world_shape_cast", "world");
    if (shape == nullptr) return null_argument("detsim_world_shape_cast", "shape");
    if (hit == nullptr) return null_argument("detsim_world_shape_cast", "hit");
    if (found == nullptr) return null_argument("detsim_world_shape_cast", "found");
    detsim::Shape s;
    std::string error;
    if (!to_shape(*shape, s, error)) return fail(DETSIM_INVALID_ARGUMENT, error);
    const auto h = world->world.shape_cast(s, vec(position), quat(orientation), vec(translation));
    *found = h ? 1 : 0;
    if (h) *hit = to_hit(h->body, h->point, h->normal, h->fraction);
    return ok();
  });
}

void detsim_session_config_init(detsim_session_config* config) {
  if (config == nullptr) return;
  const detsim::net::SessionConfig c;
  config->mode = static_cast<std::uint32_t>(c.mode);
  config->players = c.players;
  config->local_player = c.local_player;
  config->input_size = c.input_size;
  config->input_delay = c.input_delay;
  config->max_prediction = c.max_prediction;
  config->fingerprint = c.fingerprint;
}

detsim_result detsim_network_create(uint32_t nodes, uint64_t seed, const detsim_link* links,
                                    detsim_network** out) {
  return guarded("detsim_network_create", [&] {
    if (out == nullptr) return null_argument("detsim_network_create", "out");
    detsim::net::LinkConditions all;
    if (links != nullptr) {
      all.latency_us = links->latency_us;
      all.jitter_us = links->jitter_us;
      all.loss_ppm = links->loss_ppm;
      all.duplicate_ppm = links->duplicate_ppm;
      all.reorder_ppm = links->reorder_ppm;
    }
    auto network = detsim::net::SimNetwork::create(nodes, seed, all);
    if (!network.ok()) return fail(DETSIM_INVALID_ARGUMENT, network.message());
    *out = new detsim_network{std::move(network.value())};
    return ok();
  });
}

void detsim_network_destroy(detsim_network* network) {
  delete network;
}

detsim_result detsim_network_advance_to(detsim_network* network, uint64_t now_us) {
  return guarded("detsim_network_advance_to", [&] {
    if (network == nullptr) return null_argument("detsim_network_advance_to", "network");
    network->network.advance_to(now_us);
    return ok();
  });
}

namespace {

/// A session over `transport`, player p at peer p; `nodes` (a simulated network's size) bounds the
/// players when given. `name` names the entry point in messages.
detsim_result create_session(const char* name, const detsim_session_config* config,
                             const detsim_game* game, detsim::net::Transport* transport,
                             std::optional<std::uint32_t> nodes, detsim_session** out) {
  if (config == nullptr) return null_argument(name, "config");
  if (game == nullptr) return null_argument(name, "game");
  if (out == nullptr) return null_argument(name, "out");
  if (game->save == nullptr || game->load == nullptr || game->advance == nullptr)
    return fail(DETSIM_INVALID_ARGUMENT,
                std::string(name) + ": the game's save, load and advance must all be set");
  if (config->mode > DETSIM_MODE_LOCKSTEP) {
    return fail(DETSIM_INVALID_ARGUMENT, "session config: mode " + std::to_string(config->mode) +
                                             " is not 0 (rollback) or 1 (lockstep)");
  }
  if (nodes && (config->players > *nodes || config->local_player >= *nodes)) {
    return fail(DETSIM_INVALID_ARGUMENT, "session config: " + std::to_string(config->players) +
                                             " players need as many network nodes, the network "
                                             "has " +
                                             std::to_string(*nodes));
  }
  detsim::net::SessionConfig c;
  c.mode = static_cast<detsim::net::SessionMode>(config->mode);
  c.players = config->players;
  c.local_player = config->local_player;
  c.input_size = config->input_size;
  c.input_delay = config->input_delay;
  c.max_prediction = config->max_prediction;
  c.fingerprint = config->fingerprint;
  for (std::uint32_t p = 0; p < config->players; ++p) {
    if (p != config->local_player) c.remotes.push_back({p, p});
  }
  auto wrapper = std::make_unique<detsim_session>();
  wrapper->game = std::make_unique<detsim_c::CallbackGame>(*game);
  auto session = detsim::net::Session::create(c, *wrapper->game, *transport);
  if (!session.ok()) return fail(DETSIM_INVALID_ARGUMENT, session.message());
  wrapper->session = std::make_unique<detsim::net::Session>(std::move(session.value()));
  detsim_session* self = wrapper.get();
  self->session->set_confirmed_listener([self](const detsim::net::ConfirmedFrame& f) {
    const std::size_t slot = f.frame % detsim_session::kept_hashes;
    self->frames[slot] = f.frame;
    self->hashes[slot] = f.hash;
    self->kept[slot] = true;
  });
  *out = wrapper.release();
  return ok();
}

}  // namespace

detsim_result detsim_session_create(const detsim_session_config* config, const detsim_game* game,
                                    detsim_network* network, detsim_session** out) {
  return guarded("detsim_session_create", [&] {
    if (network == nullptr) return null_argument("detsim_session_create", "network");
    const std::uint32_t nodes = network->network.nodes();
    if (config != nullptr && config->local_player >= nodes)
      return fail(DETSIM_INVALID_ARGUMENT,
                  "session config: local player " + std::to_string(config->local_player) +
                      " is not a node of the network, which has " + std::to_string(nodes));
    return create_session(
        "detsim_session_create", config, game,
        config == nullptr ? nullptr : &network->network.endpoint(config->local_player), nodes, out);
  });
}

detsim_result detsim_session_create_on(const detsim_session_config* config, const detsim_game* game,
                                       detsim_transport* transport, detsim_session** out) {
  return guarded("detsim_session_create_on", [&] {
    if (transport == nullptr) return null_argument("detsim_session_create_on", "transport");
    return create_session("detsim_session_create_on", config, game, transport->transport.get(),
                          std::nullopt, out);
  });
}

detsim_result detsim_udp_open(const char* bind, detsim_transport** out) {
  return guarded("detsim_udp_open", [&] {
    if (bind == nullptr) return null_argument("detsim_udp_open", "bind");
    if (out == nullptr) return null_argument("detsim_udp_open", "out");
#if DETSIM_WITH_UDP
    auto endpoint = detsim::net::parse_endpoint(bind);
    if (!endpoint.ok()) return fail(DETSIM_INVALID_ARGUMENT, "bind: " + endpoint.message());
    auto udp = detsim::net::UdpTransport::open(endpoint.value(), {});
    if (!udp.ok()) return fail(DETSIM_INVALID_ARGUMENT, udp.message());
    auto t = std::make_unique<detsim_transport>();
    auto owned = std::make_unique<detsim::net::UdpTransport>(std::move(udp.value()));
    t->udp = owned.get();
    t->transport = std::move(owned);
    *out = t.release();
    return ok();
#else
    return fail(DETSIM_INVALID_ARGUMENT,
                "detsim_udp_open: this build has no sockets (DETSIM_WITH_UDP=OFF); bring the "
                "network with detsim_transport_create");
#endif
  });
}

detsim_result detsim_udp_add_peer(detsim_transport* transport, uint32_t player,
                                  const char* address) {
  return guarded("detsim_udp_add_peer", [&] {
    if (transport == nullptr) return null_argument("detsim_udp_add_peer", "transport");
    if (address == nullptr) return null_argument("detsim_udp_add_peer", "address");
#if DETSIM_WITH_UDP
    if (transport->udp == nullptr)
      return fail(DETSIM_INVALID_ARGUMENT,
                  "detsim_udp_add_peer: the transport is not a UDP one (detsim_udp_open)");
    auto endpoint = detsim::net::parse_endpoint(address);
    if (!endpoint.ok())
      return fail(DETSIM_INVALID_ARGUMENT,
                  "player " + std::to_string(player) + "'s address: " + endpoint.message());
    if (detsim::Status s = transport->udp->add_peer({player, endpoint.value()}); !s)
      return fail(DETSIM_INVALID_ARGUMENT, s.message());
    return ok();
#else
    (void)player;
    return fail(DETSIM_INVALID_ARGUMENT, "detsim_udp_add_peer: this build has no sockets");
#endif
  });
}

detsim_result detsim_udp_local_port(const detsim_transport* transport, uint16_t* port) {
  return guarded("detsim_udp_local_port", [&] {
    if (transport == nullptr) return null_argument("detsim_udp_local_port", "transport");
    if (port == nullptr) return null_argument("detsim_udp_local_port", "port");
#if DETSIM_WITH_UDP
    if (transport->udp == nullptr)
      return fail(DETSIM_INVALID_ARGUMENT,
                  "detsim_udp_local_port: the transport is not a UDP one (detsim_udp_open)");
    *port = transport->udp->local_endpoint().port;
    return ok();
#else
    return fail(DETSIM_INVALID_ARGUMENT, "detsim_udp_local_port: this build has no sockets");
#endif
  });
}

detsim_result detsim_transport_create(detsim_send_fn send, void* context, detsim_transport** out) {
  return guarded("detsim_transport_create", [&] {
    if (send == nullptr) return null_argument("detsim_transport_create", "send");
    if (out == nullptr) return null_argument("detsim_transport_create", "out");
    auto t = std::make_unique<detsim_transport>();
    auto owned = std::make_unique<detsim_c::CallbackTransport>(send, context);
    t->callbacks = owned.get();
    t->transport = std::move(owned);
    *out = t.release();
    return ok();
  });
}

detsim_result detsim_transport_deliver(detsim_transport* transport, uint32_t from,
                                       const uint8_t* bytes, size_t size) {
  return guarded("detsim_transport_deliver", [&] {
    if (transport == nullptr) return null_argument("detsim_transport_deliver", "transport");
    if (bytes == nullptr && size != 0) return null_argument("detsim_transport_deliver", "bytes");
    if (transport->callbacks == nullptr)
      return fail(DETSIM_INVALID_ARGUMENT,
                  "detsim_transport_deliver: the transport was not made by "
                  "detsim_transport_create (a UDP transport reads its own socket)");
    if (size > detsim::net::max_datagram)
      return fail(DETSIM_INVALID_ARGUMENT, "detsim_transport_deliver: " + std::to_string(size) +
                                               " bytes is more than a datagram holds (" +
                                               std::to_string(detsim::net::max_datagram) + ")");
    transport->callbacks->deliver(from, std::span<const std::uint8_t>(bytes, size));
    return ok();
  });
}

void detsim_transport_destroy(detsim_transport* transport) {
  delete transport;
}

void detsim_session_destroy(detsim_session* session) {
  delete session;
}

detsim_result detsim_session_poll(detsim_session* session, uint64_t now_us) {
  return guarded("detsim_session_poll", [&] {
    if (session == nullptr) return null_argument("detsim_session_poll", "session");
    session->session->poll(now_us);
    return ok();
  });
}

detsim_result detsim_session_advance_frame(detsim_session* session, const uint8_t* input,
                                           size_t size, uint32_t* what) {
  return guarded("detsim_session_advance_frame", [&] {
    if (session == nullptr) return null_argument("detsim_session_advance_frame", "session");
    if (input == nullptr && size > 0) return null_argument("detsim_session_advance_frame", "input");
    if (what == nullptr) return null_argument("detsim_session_advance_frame", "what");
    const auto advanced = session->session->advance_frame({input, size});
    if (!advanced.ok()) return fail(DETSIM_INVALID_ARGUMENT, advanced.message());
    *what = static_cast<std::uint32_t>(*advanced);
    return ok();
  });
}

uint64_t detsim_session_current_frame(const detsim_session* session) {
  return session == nullptr ? 0 : session->session->current_frame();
}

uint64_t detsim_session_confirmed_frame(const detsim_session* session) {
  return session == nullptr ? 0 : session->session->confirmed_frame();
}

detsim_result detsim_session_confirmed_hash(const detsim_session* session, uint64_t frame,
                                            uint64_t* hash) {
  return guarded("detsim_session_confirmed_hash", [&] {
    if (session == nullptr) return null_argument("detsim_session_confirmed_hash", "session");
    if (hash == nullptr) return null_argument("detsim_session_confirmed_hash", "hash");
    const std::size_t slot = frame % detsim_session::kept_hashes;
    if (!session->kept[slot] || session->frames[slot] != frame) {
      return fail(DETSIM_INVALID_ARGUMENT, "detsim_session_confirmed_hash: frame " +
                                               std::to_string(frame) +
                                               " is not among the last 1024 confirmed frames");
    }
    *hash = session->hashes[slot];
    return ok();
  });
}

}  // extern "C"
