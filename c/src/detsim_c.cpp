// The C API (<detsim/detsim.h>) over the C++ World. Every entry point catches everything: a
// std::bad_alloc becomes DETSIM_OUT_OF_MEMORY, anything else DETSIM_INTERNAL_ERROR, and a refusal
// of the library (an Expected or Status error) DETSIM_INVALID_ARGUMENT; the message of the last
// failure is kept per thread for detsim_last_error.
#include <detsim/detsim.h>

#include <cstring>
#include <exception>
#include <new>
#include <string>
#include <vector>

#include <detsim/core/version.hpp>
#include <detsim/fixed/decimal.hpp>
#include <detsim/sim/world.hpp>

struct detsim_world {
  detsim::World world;
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

}  // extern "C"
