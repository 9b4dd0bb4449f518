// World: construction, bodies and game inputs. The step is in step.cpp, the state's bytes in
// state_io.cpp.
#include <algorithm>
#include <cstdint>
#include <string>
#include <utility>

#include <detsim/fixed/decimal.hpp>
#include <detsim/fixed/math.hpp>

#include "limits.hpp"
#include "shapes.hpp"
#include "world_state.hpp"

namespace detsim {

using sim_detail::Checked;
using sim_detail::WorldState;

namespace sim_detail {

std::ptrdiff_t WorldState::find(std::uint32_t id) const noexcept {
  const auto it =
      std::lower_bound(bodies.begin(), bodies.end(), id,
                       [](const BodyState& b, std::uint32_t v) { return b.id.value < v; });
  if (it == bodies.end() || it->id.value != id) return -1;
  return it - bodies.begin();
}

}  // namespace sim_detail

WorldDef scale_lengths(WorldDef def, Fixed unit) noexcept {
  def.linear_slop = def.linear_slop * unit;
  def.speculative_distance = def.speculative_distance * unit;
  def.contact_push_max = def.contact_push_max * unit;
  def.sleep_linear_speed = def.sleep_linear_speed * unit;
  if (unit <= Fixed::zero()) return def;  // refused by World::create (the push max is not > 0)
  def.contact_hertz = def.contact_hertz / sqrt(unit);
  // The solver holds the spring to a quarter of the sub-step rate: substeps >= 4 hertz dt.
  const Fixed needed = Fixed::from_int(4) * def.contact_hertz * def.dt;
  const std::int64_t whole = (needed.raw() + Fixed::one_raw - 1) / Fixed::one_raw;
  def.substeps = static_cast<std::uint32_t>(
      std::clamp<std::int64_t>(whole, static_cast<std::int64_t>(def.substeps), 64));
  return def;
}

namespace {

Status unknown(BodyId id) {
  return Status::error("no body with ID " + std::to_string(id.value));
}

}  // namespace

World::World() : s_(std::make_unique<WorldState>()) {
  s_->rng = Rng(s_->def.seed);
}

World::World(std::unique_ptr<WorldState> state) noexcept : s_(std::move(state)) {}

Expected<World> World::create(const WorldDef& def) {
  if (auto e = sim_detail::check_world_def(def); !e.empty())
    return Status::error("invalid world definition: " + e);
  auto s = std::make_unique<WorldState>();
  s->def = def;
  s->rng = Rng(def.seed);
  return World(std::move(s));
}

World::World(const World& other) : s_(std::make_unique<WorldState>(*other.s_)) {}
World& World::operator=(const World& other) {
  if (this != &other) s_ = std::make_unique<WorldState>(*other.s_);
  return *this;
}
World::World(World&&) noexcept = default;
World& World::operator=(World&&) noexcept = default;
World::~World() = default;

const WorldDef& World::def() const noexcept {
  return s_->def;
}
std::uint64_t World::frame() const noexcept {
  return s_->frame;
}
Rng& World::rng() noexcept {
  return s_->rng;
}
const Rng& World::rng() const noexcept {
  return s_->rng;
}

Expected<BodyId> World::create_body(const BodyDef& def) {
  if (s_->next_id == 0xFFFFFFFFU) return Status::error("body IDs exhausted (2^32 - 1 created)");
  if (auto e = sim_detail::check_body_def(*s_, def); !e.empty())
    return Status::error("invalid body definition: " + e);
  const MassProperties m = sim_detail::body_mass(*s_, def);
  BodyState b;
  b.id = BodyId{s_->next_id};
  b.type = def.type;
  b.shape = def.shape;
  b.position = def.position;
  b.orientation = normalize(def.orientation);
  if (def.type != BodyType::static_body) {
    b.linear_velocity = def.linear_velocity;
    b.angular_velocity = def.angular_velocity;
  }
  b.mass = m.mass;
  b.inertia = m.inertia;
  b.center_of_mass = m.center;
  b.inertia_axes = m.inertia_axes;
  b.friction = def.friction;
  b.restitution = def.restitution;
  b.linear_damping = def.linear_damping;
  b.angular_damping = def.angular_damping;
  b.layer = def.layer;
  b.mask = def.mask;
  b.sensor = def.sensor;
  b.ccd = def.ccd;
  b.lock_translation_x = def.lock_translation.x;
  b.lock_translation_y = def.lock_translation.y;
  b.lock_translation_z = def.lock_translation.z;
  b.lock_rotation_x = def.lock_rotation.x;
  b.lock_rotation_y = def.lock_rotation.y;
  b.lock_rotation_z = def.lock_rotation.z;
  b.user_data = def.user_data;
  b.awake = def.type != BodyType::static_body;
  s_->bodies.push_back(b);  // IDs only grow: appending keeps the order
  ++s_->next_id;
  return b.id;
}

Status World::destroy_body(BodyId id) {
  const std::ptrdiff_t i = s_->find(id.value);
  if (i < 0) return unknown(id);
  // Whatever rested on the body must notice that it is gone.
  for (const sim_detail::Contact& c : s_->contacts) {
    if (c.touching && (c.a == id.value || c.b == id.value)) {
      const std::ptrdiff_t other = s_->find(c.a == id.value ? c.b : c.a);
      BodyState& o = s_->bodies[static_cast<std::size_t>(other)];
      if (o.type != BodyType::static_body) {
        o.awake = true;
        o.sleep_time = Fixed::zero();
      }
    }
  }
  // One end event per body pair (its first contact: a pair's contacts share the reported flag).
  for (std::size_t k = 0; k < s_->contacts.size(); ++k) {
    const sim_detail::Contact& c = s_->contacts[k];
    const bool first_of_pair =
        k == 0 || s_->contacts[k - 1].a != c.a || s_->contacts[k - 1].b != c.b;
    if (first_of_pair && (c.a == id.value || c.b == id.value)) sim_detail::report_end(*s_, c);
  }
  std::erase_if(s_->contacts,
                [id](const sim_detail::Contact& c) { return c.a == id.value || c.b == id.value; });
  sim_detail::destroy_joints_of(*s_, id);
  sim_detail::detach_particles_of(*s_, id);
  sim_detail::forget_ground(*s_, id);
  sim_detail::forget_vehicles_of(*s_, id);
  s_->bodies.erase(s_->bodies.begin() + i);
  return Status::success();
}

std::span<const ContactEvent> World::contact_events() const noexcept {
  return s_->events;
}

bool World::contains(BodyId id) const noexcept {
  return s_->find(id.value) >= 0;
}
std::size_t World::body_count() const noexcept {
  return s_->bodies.size();
}
std::vector<BodyId> World::body_ids() const {
  std::vector<BodyId> ids;
  ids.reserve(s_->bodies.size());
  for (const BodyState& b : s_->bodies)
    ids.push_back(b.id);
  return ids;
}

Expected<BodyState> World::body(BodyId id) const {
  const std::ptrdiff_t i = s_->find(id.value);
  if (i < 0) return unknown(id);
  return s_->bodies[static_cast<std::size_t>(i)];
}

std::vector<ContactState> World::contacts() const {
  std::vector<ContactState> out;
  out.reserve(s_->contacts.size());
  for (const sim_detail::Contact& c : s_->contacts) {
    ContactState v;
    v.a = BodyId{c.a};
    v.b = BodyId{c.b};
    v.sub_a = c.sub_a;
    v.sub_b = c.sub_b;
    v.touching = c.touching;
    v.reported = c.reported;
    v.point_count = c.point_count;
    for (std::size_t p = 0; p < c.point_count; ++p)
      v.points[p] = ContactPointState{c.cached[p].feature, c.cached[p].normal_impulse,
                                      c.cached[p].tangent_impulse_1, c.cached[p].tangent_impulse_2};
    out.push_back(v);
  }
  return out;
}

namespace {

// Runs `f` on the body, which is woken first when `wake` is set and the body can move.
template <class F>
Status with_body(WorldState& s, BodyId id, bool wake, F&& f) {
  const std::ptrdiff_t i = s.find(id.value);
  if (i < 0) return unknown(id);
  BodyState& b = s.bodies[static_cast<std::size_t>(i)];
  if (Status st = f(b); !st.ok()) return st;
  if (wake && b.type != BodyType::static_body) {
    b.awake = true;
    b.sleep_time = Fixed::zero();
  }
  return Status::success();
}

Status ok() {
  return Status::success();
}

Status refuse(std::string message) {
  return Status::error(std::move(message));
}

std::string str(Fixed x) {
  return to_string(x);
}

constexpr const char* kAxes[] = {"x", "y", "z"};

Fixed component(Vec3 v, int i) {
  return i == 0 ? v.x : (i == 1 ? v.y : v.z);
}

// r x f for a point given in world space, or a refusal when the lever arm or the moment leaves
// the limits (limits.hpp).
std::string moment(const BodyState& b, Vec3 point, Vec3 f, Vec3& out) {
  const Vec3 center = b.world_center();
  const Vec3 r = point - center;
  out = cross(r, f);
  for (int i = 0; i < 3; ++i) {
    const Checked arm = Checked(component(point, i)) - component(center, i);
    if (arm.over())
      return sim_detail::above_limit(std::string("lever arm (point - centre of mass) ") + kAxes[i],
                                     arm, sim_detail::max_quantity, "m");
  }
  for (int i = 0; i < 3; ++i) {
    if (const Checked m = component(out, i); m.over())
      return sim_detail::above_limit(std::string("moment about the centre ") + kAxes[i], m,
                                     sim_detail::max_quantity, "N m");
  }
  return {};
}

// The body's force and torque with `force` and `torque` added, or a refusal: each accumulated
// component within max_quantity, the torque's length too (its components in any frame), and the
// accelerations they give a body that is or may become dynamic within max_acceleration (the
// solver computes (g + F / m) h and (R I^-1 R^T T) h).
std::string accumulate(const BodyState& b, Vec3 force, Vec3 torque, Vec3& f_out, Vec3& t_out) {
  using sim_detail::max_acceleration;
  using sim_detail::max_quantity;
  using sim_detail::min_mass;
  f_out = b.force + force;
  t_out = b.torque + torque;
  for (int i = 0; i < 3; ++i) {
    if (const Checked f = Checked(component(b.force, i)) + component(force, i); f.over())
      return sim_detail::above_limit(std::string("accumulated force ") + kAxes[i], f, max_quantity,
                                     "N");
    if (const Checked t = Checked(component(b.torque, i)) + component(torque, i); t.over())
      return sim_detail::above_limit(std::string("accumulated torque ") + kAxes[i], t, max_quantity,
                                     "N m");
  }
  if (b.mass >= min_mass) {
    const Fixed inverse_mass = sim_detail::inverse_or_zero(b.mass);
    for (int i = 0; i < 3; ++i) {
      const Checked a = Checked(component(f_out, i)) * inverse_mass;
      if (a.over() || sim_detail::beyond(a.value(), max_acceleration))
        return sim_detail::above_limit(std::string("linear acceleration ") + kAxes[i] +
                                           " (accumulated force / mass " + str(b.mass) + " kg)",
                                       a, max_acceleration, "m/s^2");
    }
  }
  const Checked length_t = length(t_out);
  if (length_t.over())
    return sim_detail::above_limit("|accumulated torque|", length_t, max_quantity, "N m");
  const Fixed smallest = min(b.inertia.x, min(b.inertia.y, b.inertia.z));
  if (smallest >= min_mass) {
    const Checked a = length_t * sim_detail::inverse_or_zero(smallest);
    if (a.over() || sim_detail::beyond(a.value(), max_acceleration))
      return sim_detail::above_limit(
          "angular acceleration (|accumulated torque| / smallest "
          "moment of inertia " +
              str(smallest) + " kg m^2)",
          a, max_acceleration, "rad/s^2");
  }
  return {};
}

// The velocities of a dynamic body after an impulse through its centre and an angular impulse,
// with the world-space inverse inertia of its current orientation; or a refusal when a step of
// that leaves the limits (the new velocities within max_velocity, the rim speed within
// max_quantity). Other bodies keep their velocities.
std::string impulse(const sim_detail::WorldState& s, const BodyState& b, Vec3 linear, Vec3 angular,
                    Vec3& v_out, Vec3& w_out) {
  using sim_detail::max_quantity;
  using sim_detail::max_velocity;
  v_out = b.linear_velocity;
  w_out = b.angular_velocity;
  if (b.type != BodyType::dynamic) return {};
  const Vec3 dv = linear / b.mass;
  v_out = b.linear_velocity + dv;
  // The principal frame: the body's, turned by its inertia axes (the identity for primitives).
  const Mat3 r = to_mat3(b.orientation * b.inertia_axes);
  const Vec3 local = transpose(r) * angular;
  const Vec3 local_dw{local.x / b.inertia.x, local.y / b.inertia.y, local.z / b.inertia.z};
  const Vec3 dw = r * local_dw;
  w_out = b.angular_velocity + dw;
  const Fixed inertia[] = {b.inertia.x, b.inertia.y, b.inertia.z};
  for (int i = 0; i < 3; ++i) {
    const Checked change = Checked(component(linear, i)) / b.mass;
    const Checked v = Checked(component(b.linear_velocity, i)) + change;
    if (v.over() || sim_detail::beyond(v.value(), max_velocity))
      return sim_detail::above_limit(std::string("linear velocity ") + kAxes[i] +
                                         " after the impulse (mass " + str(b.mass) + " kg)",
                                     v, max_velocity, "m/s");
  }
  for (int i = 0; i < 3; ++i) {
    const Checked body_frame = Checked(component(local, i)) / inertia[i];
    const Checked w = Checked(component(b.angular_velocity, i)) + component(dw, i);
    if (body_frame.over() || Checked(component(dw, i)).over() || w.over() ||
        sim_detail::beyond(w.value(), max_velocity))
      return sim_detail::above_limit(std::string("angular velocity ") + kAxes[i] +
                                         " after the impulse (moment of inertia " +
                                         str(inertia[i]) + " kg m^2 about body " + kAxes[i] + ")",
                                     body_frame.over() ? body_frame : w, max_velocity, "rad/s");
  }
  return sim_detail::check_angular_velocity(b.shape, s.geometry(b.shape), w_out,
                                            "angular velocity after the impulse");
}

}  // namespace

Status World::set_type(BodyId id, BodyType type) {
  return with_body(*s_, id, true, [&](BodyState& b) {
    if (type != BodyType::static_body && type != BodyType::kinematic && type != BodyType::dynamic)
      return Status::error("unknown body type " + std::to_string(static_cast<unsigned>(type)));
    const sim_detail::ShapeKind& shape = sim_detail::shape_kind(b.shape.type);
    if (shape.static_only && type != BodyType::static_body)
      return Status::error("body " + std::to_string(id.value) + " is a " + shape.name +
                           ": it must stay static");
    if (type == BodyType::dynamic && b.mass <= Fixed::zero())
      return Status::error("body " + std::to_string(id.value) +
                           " has no mass (it was created with zero mass and density)");
    if (type == BodyType::dynamic) {
      if (auto e =
              sim_detail::check_dynamic_mass({b.mass, b.inertia, b.center_of_mass, b.inertia_axes});
          !e.empty())
        return refuse("body " + std::to_string(id.value) + " cannot become dynamic: " + e);
    }
    if (type == BodyType::static_body) {
      b.linear_velocity = {};
      b.angular_velocity = {};
      b.awake = false;
    }
    b.type = type;
    return ok();
  });
}

Status World::set_transform(BodyId id, Vec3 position, Quat orientation) {
  if (auto e = sim_detail::check_orientation(orientation); !e.empty()) return Status::error(e);
  if (auto e = sim_detail::check_position(position); !e.empty()) return Status::error(e);
  return with_body(*s_, id, true, [&](BodyState& b) {
    b.position = position;
    b.orientation = normalize(orientation);
    return ok();
  });
}

Status World::set_linear_velocity(BodyId id, Vec3 velocity) {
  return with_body(*s_, id, true, [&](BodyState& b) {
    if (b.type == BodyType::static_body) return Status::error("a static body cannot move");
    if (auto e = sim_detail::check_components("linear velocity", velocity, sim_detail::max_velocity,
                                              "m/s");
        !e.empty())
      return refuse(e);
    b.linear_velocity = velocity;
    return ok();
  });
}

Status World::set_angular_velocity(BodyId id, Vec3 velocity) {
  return with_body(*s_, id, true, [&](BodyState& b) {
    if (b.type == BodyType::static_body) return Status::error("a static body cannot move");
    if (auto e = sim_detail::check_angular_velocity(b.shape, s_->geometry(b.shape), velocity,
                                                    "angular velocity");
        !e.empty())
      return refuse(e);
    b.angular_velocity = velocity;
    return ok();
  });
}

Status World::set_user_data(BodyId id, std::uint64_t user_data) {
  return with_body(*s_, id, false, [&](BodyState& b) {
    b.user_data = user_data;
    return ok();
  });
}

Status World::set_game_state(std::span<const std::uint8_t> bytes) {
  if (bytes.empty())
    return Status::error("game state: expected 1 .. " + std::to_string(max_game_state_size) +
                         " bytes, got none");
  if (bytes.size() > max_game_state_size)
    return Status::error("game state: " + std::to_string(bytes.size()) + " bytes, at most " +
                         std::to_string(max_game_state_size));
  s_->game.assign(bytes.begin(), bytes.end());
  return Status::success();
}

std::span<const std::uint8_t> World::game_state() const noexcept {
  return s_->game;
}

Status World::describe_game_state(std::span<const GameField> fields) {
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const GameField& f = fields[i];
    const std::string which = "game state field " + std::to_string(i) + " \"" + f.name + "\": ";
    const bool good_name = !f.name.empty() && f.name.size() <= 64 &&
                           std::all_of(f.name.begin(), f.name.end(), [](char c) {
                             return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
                                    (c >= '0' && c <= '9') || c == '_' || c == '.' || c == '[' ||
                                    c == ']';
                           });
    if (!good_name)
      return Status::error(which + "a name is 1..64 characters of A-Z a-z 0-9 _ . [ ]");
    if (f.type > GameFieldType::fixed)
      return Status::error(which + "unknown type " + std::to_string(static_cast<unsigned>(f.type)));
    if (std::uint64_t{f.offset} + game_field_size(f.type) > max_game_state_size)
      return Status::error(which + "ends past the largest game state (" +
                           std::to_string(max_game_state_size) + " bytes)");
    for (std::size_t k = 0; k < i; ++k)
      if (fields[k].name == f.name) return Status::error(which + "named twice");
  }
  s_->game_fields.assign(fields.begin(), fields.end());
  return Status::success();
}

std::span<const GameField> World::game_state_fields() const noexcept {
  return s_->game_fields;
}

Status World::apply_force(BodyId id, Vec3 force) {
  return with_body(*s_, id, true, [&](BodyState& b) {
    Vec3 f;
    Vec3 t;
    if (auto e = accumulate(b, force, {}, f, t); !e.empty()) return refuse(e);
    b.force = f;
    return ok();
  });
}

Status World::apply_torque(BodyId id, Vec3 torque) {
  return with_body(*s_, id, true, [&](BodyState& b) {
    Vec3 f;
    Vec3 t;
    if (auto e = accumulate(b, {}, torque, f, t); !e.empty()) return refuse(e);
    b.torque = t;
    return ok();
  });
}

Status World::apply_force_at_point(BodyId id, Vec3 force, Vec3 point) {
  return with_body(*s_, id, true, [&](BodyState& b) {
    Vec3 m;
    if (auto e = moment(b, point, force, m); !e.empty()) return refuse(e);
    Vec3 f;
    Vec3 t;
    if (auto e = accumulate(b, force, m, f, t); !e.empty()) return refuse(e);
    b.force = f;
    b.torque = t;
    return ok();
  });
}

Status World::apply_linear_impulse(BodyId id, Vec3 linear) {
  return with_body(*s_, id, true, [&](BodyState& b) {
    Vec3 v;
    Vec3 w;
    if (auto e = impulse(*s_, b, linear, {}, v, w); !e.empty()) return refuse(e);
    b.linear_velocity = v;
    b.angular_velocity = w;
    return ok();
  });
}

Status World::apply_impulse_at_point(BodyId id, Vec3 linear, Vec3 point) {
  return with_body(*s_, id, true, [&](BodyState& b) {
    Vec3 m;
    if (auto e = moment(b, point, linear, m); !e.empty()) return refuse(e);
    Vec3 v;
    Vec3 w;
    if (auto e = impulse(*s_, b, linear, m, v, w); !e.empty()) return refuse(e);
    b.linear_velocity = v;
    b.angular_velocity = w;
    return ok();
  });
}

Status World::apply_angular_impulse(BodyId id, Vec3 angular) {
  return with_body(*s_, id, true, [&](BodyState& b) {
    Vec3 v;
    Vec3 w;
    if (auto e = impulse(*s_, b, {}, angular, v, w); !e.empty()) return refuse(e);
    b.linear_velocity = v;
    b.angular_velocity = w;
    return ok();
  });
}

Status World::wake(BodyId id) {
  return with_body(*s_, id, true, [](BodyState&) { return ok(); });
}

}  // namespace detsim
