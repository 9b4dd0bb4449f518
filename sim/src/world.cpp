// World: construction, bodies and game inputs. The step is in step.cpp, the state's bytes in
// state_io.cpp.
#include <algorithm>
#include <cstdint>
#include <string>
#include <utility>

#include <detsim/fixed/math.hpp>

#include "shapes.hpp"
#include "world_state.hpp"

namespace detsim {

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
  if (auto e = sim_detail::check_body_def(def); !e.empty())
    return Status::error("invalid body definition: " + e);
  const MassProperties m = sim_detail::body_mass(def);
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
  b.friction = def.friction;
  b.restitution = def.restitution;
  b.linear_damping = def.linear_damping;
  b.angular_damping = def.angular_damping;
  b.layer = def.layer;
  b.mask = def.mask;
  b.sensor = def.sensor;
  b.ccd = def.ccd;
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
  for (const sim_detail::Contact& c : s_->contacts) {
    if (c.a == id.value || c.b == id.value) sim_detail::report_end(*s_, c);
  }
  std::erase_if(s_->contacts,
                [id](const sim_detail::Contact& c) { return c.a == id.value || c.b == id.value; });
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

// r x f for a point given in world space.
Vec3 moment(const BodyState& b, Vec3 point, Vec3 f) {
  return cross(point - b.position, f);
}

// Immediate velocity change of a dynamic body from an impulse through its centre and an angular
// impulse, with the world-space inverse inertia of its current orientation.
void apply_impulse(BodyState& b, Vec3 linear, Vec3 angular) {
  if (b.type != BodyType::dynamic) return;
  b.linear_velocity += linear / b.mass;
  const Mat3 r = to_mat3(b.orientation);
  const Vec3 local = transpose(r) * angular;
  const Vec3 local_dw{local.x / b.inertia.x, local.y / b.inertia.y, local.z / b.inertia.z};
  b.angular_velocity += r * local_dw;
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
  return with_body(*s_, id, true, [&](BodyState& b) {
    b.position = position;
    b.orientation = normalize(orientation);
    return ok();
  });
}

Status World::set_linear_velocity(BodyId id, Vec3 velocity) {
  return with_body(*s_, id, true, [&](BodyState& b) {
    if (b.type == BodyType::static_body) return Status::error("a static body cannot move");
    b.linear_velocity = velocity;
    return ok();
  });
}

Status World::set_angular_velocity(BodyId id, Vec3 velocity) {
  return with_body(*s_, id, true, [&](BodyState& b) {
    if (b.type == BodyType::static_body) return Status::error("a static body cannot move");
    b.angular_velocity = velocity;
    return ok();
  });
}

Status World::apply_force(BodyId id, Vec3 force) {
  return with_body(*s_, id, true, [&](BodyState& b) {
    b.force += force;
    return ok();
  });
}

Status World::apply_torque(BodyId id, Vec3 torque) {
  return with_body(*s_, id, true, [&](BodyState& b) {
    b.torque += torque;
    return ok();
  });
}

Status World::apply_force_at_point(BodyId id, Vec3 force, Vec3 point) {
  return with_body(*s_, id, true, [&](BodyState& b) {
    b.force += force;
    b.torque += moment(b, point, force);
    return ok();
  });
}

Status World::apply_linear_impulse(BodyId id, Vec3 impulse) {
  return with_body(*s_, id, true, [&](BodyState& b) {
    apply_impulse(b, impulse, {});
    return ok();
  });
}

Status World::apply_impulse_at_point(BodyId id, Vec3 impulse, Vec3 point) {
  return with_body(*s_, id, true, [&](BodyState& b) {
    apply_impulse(b, impulse, moment(b, point, impulse));
    return ok();
  });
}

Status World::apply_angular_impulse(BodyId id, Vec3 impulse) {
  return with_body(*s_, id, true, [&](BodyState& b) {
    apply_impulse(b, {}, impulse);
    return ok();
  });
}

Status World::wake(BodyId id) {
  return with_body(*s_, id, true, [](BodyState&) { return ok(); });
}

}  // namespace detsim
