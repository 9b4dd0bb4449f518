// Character controllers (character.hpp; docs/SIM.md, "Characters"): the World's calls and the
// step's stage that moves them.
//
// Once per step, after the bodies have moved (and the step's applied forces are spent), each
// character in ascending ID order:
//   1. rides: if it stands on a body that moved, it follows that body's motion over the step
//      exactly (its pose at the step's start to its pose now, rotation included), as a slide;
//   2. gets out of what moved into it: up to four pushes out along the deepest contact;
//   3. takes its velocity: on walkable ground, the input's horizontal velocity along the ground;
//      in the air, the input's horizontal velocity and its own vertical one plus gravity's; on a
//      slope too steep to stand on, its own velocity plus gravity (it slides; the input does not
//      steer it); a jump replaces the vertical speed;
//   4. moves and slides with shape casts (World::shape_cast's rules: it stops short of each
//      surface, and a surface it rests on does not stop it moving along or away), up to four
//      surfaces a step:
//      - walking: a walkable surface it walks into low enough to step on (a slope, a low ledge's
//        rounded edge) turns the move along it, keeping its horizontal motion; anything else is a
//        wall, seen from the side (its normal made horizontal), which the move slides along
//        after trying to step up (cast up by step_height, forward, down: the step is taken when
//        the landing is walkable and no higher than step_height above its feet);
//      - falling or sliding: a walkable surface met going down is a landing, which ends the move;
//        anything else turns the move along it;
//   5. finds its ground: a cast down by twice the slop (by step_height more when it walked on
//      ground and did not jump: ground snapping down steps and slopes), which it moves down to
//      when the ground is walkable; `grounded`, the ground's normal and body follow;
//   6. pushes the dynamic bodies it walked or fell into (below), and keeps its velocity: how far
//      it moved in 3-5, over dt.
// Walkable is judged by the surface's own normal (a short ray at the contact, just outside the
// capsule's axis: a box's top face, not the rounded normal the capsule meets the box's edge
// with), so a capsule on a ledge's edge stands, and a ledge's edge does not look like a slope.
//
// A push is a force on the body for the next step, through its centre of mass (it never spins or
// tips what it pushes), along the contact: enough to bring the body to the character's speed
// along it in that step, and never more than mass * |gravity|: a character pushes with at most
// its weight, and friction holds what that cannot move.
//
// Every move along a surface is lifted off it by 2^-16 of its length, so that rounding never
// turns it into the surface (a cast would stop it there); the ground cast takes the lift back.
#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include <detsim/fixed/decimal.hpp>
#include <detsim/fixed/math.hpp>
#include <detsim/fixed/quat.hpp>

#include "limits.hpp"
#include "query_util.hpp"
#include "world_state.hpp"

namespace detsim {

namespace sim_detail {

std::ptrdiff_t WorldState::find_character(std::uint32_t id) const noexcept {
  const auto it =
      std::lower_bound(characters.begin(), characters.end(), id,
                       [](const CharacterState& c, std::uint32_t v) { return c.id.value < v; });
  if (it == characters.end() || it->id.value != id) return -1;
  return it - characters.begin();
}

namespace {

constexpr int kSurfaces = 4;  // the surfaces one move slides along, at most
constexpr int kPushOuts = 4;  // pushes out of overlaps per step, at most

std::string check_character_def(const CharacterDef& d) {
  const Fixed max_size = Fixed::from_int(100);
  if (d.radius < Fixed::from_raw(Fixed::one_raw >> 10) || d.radius > max_size)
    return "radius must be within 2^-10 .. 100 m, got " + to_string(d.radius);
  if (d.half_height < Fixed::zero() || d.half_height > max_size)
    return "half_height must be within 0 .. 100 m, got " + to_string(d.half_height);
  if (d.max_slope <= Fixed::zero() || d.max_slope >= Fixed::half_pi())
    return "max_slope must be within (0, pi/2) rad, got " + to_string(d.max_slope);
  const Fixed height = (d.radius + d.half_height) * Fixed::from_int(2);
  if (d.step_height < Fixed::zero() || d.step_height >= height)
    return "step_height must be >= 0 and below the character's height " + to_string(height) +
           " m, got " + to_string(d.step_height);
  if (d.mass <= Fixed::zero() || d.mass >= max_quantity)
    return "mass must be within (0, 2^31 - 1) kg, got " + to_string(d.mass);
  return check_position(d.position);
}

std::string check_input(const WorldState& s, const CharacterInput& in) {
  if (auto e = check_components("desired_velocity", in.desired_velocity, s.def.max_linear_speed,
                                "m/s (the world's max_linear_speed)");
      !e.empty())
    return e;
  if (in.jump < Fixed::zero() || in.jump > s.def.max_linear_speed)
    return "jump must be within 0 .. the world's max_linear_speed " +
           to_string(s.def.max_linear_speed) + " m/s, got " + to_string(in.jump);
  return {};
}

Vec3 horizontal(Vec3 v) noexcept {
  return {v.x, Fixed::zero(), v.z};
}

Fixed clamp_speed(Fixed v, Fixed limit) noexcept {
  return clamp(v, -limit, limit);
}

/// A dynamic body the move ran into, and along which unit direction it pushes it.
struct BodyPush {
  std::size_t body = 0;
  Vec3 direction;
};

/// One character's move against the world's bodies.
class CharacterMover {
 public:
  CharacterMover(const WorldState& s, const CharacterState& c)
      : s_(s),
        shape_(Shape::capsule(c.def.radius, c.def.half_height)),
        filter_{c.def.layer, c.def.mask, false, {}},
        cos_max_slope_(cos(c.def.max_slope)),
        slop_(s.def.linear_slop),
        foot_(c.def.radius + c.def.half_height),
        step_height_(c.def.step_height) {}

  /// The first body the capsule at `p` meets moving by `d` (leaving out `ignore`).
  [[nodiscard]] std::optional<ShapeHit> cast(Vec3 p, Vec3 d, BodyId ignore = {}) const {
    QueryFilter f = filter_;
    f.ignore = ignore;
    return cast_shape(s_, shape_, p, Quat::identity(), d, f);
  }
  [[nodiscard]] bool walkable(Vec3 n) const noexcept { return n.y >= cos_max_slope_; }
  [[nodiscard]] Fixed slop() const noexcept { return slop_; }

  /// The surface's own normal where the capsule at `centre` met it (see the file comment).
  [[nodiscard]] Vec3 surface_normal(const ShapeHit& hit, Vec3 centre) const {
    const Vec3 out = horizontal(hit.point - centre);
    const Vec3 nudge = out == Vec3{} ? Vec3{} : normalize(out) * slop_;
    const Vec3 origin = hit.point + nudge + Vec3{Fixed::zero(), slop_, Fixed::zero()};
    const BodyState& b = s_.bodies[static_cast<std::size_t>(s_.find(hit.body.value))];
    const auto ray = ray_body(s_, b, origin, {Fixed::zero(), -(slop_ + slop_), Fixed::zero()});
    return ray && ray->normal != Vec3{} ? ray->normal : hit.normal;
  }
  /// How high above the feet of the capsule at `centre` the hit is.
  [[nodiscard]] Fixed rise(const ShapeHit& hit, Vec3 centre) const noexcept {
    return hit.point.y - (centre.y - foot_);
  }

  /// The body's motion over the step (its pose at the start to its pose now) applied to `p`, as
  /// a slide that ignores the body: what standing on it does.
  [[nodiscard]] Vec3 ride(BodyId ground, Vec3 p) const {
    const std::ptrdiff_t i = s_.find(ground.value);
    if (i < 0) return p;
    const BodyState& b = s_.bodies[static_cast<std::size_t>(i)];
    const Derived& d = s_.derived[static_cast<std::size_t>(i)];
    if (b.type == BodyType::static_body ||
        (b.position == d.start_position && b.orientation == d.start_orientation))
      return p;
    const Quat turn = b.orientation * conjugate(d.start_orientation);
    const Vec3 carried = b.position + rotate(turn, p - d.start_position);
    return slide(p, carried - p, false, nullptr, ground);
  }

  /// Out of the bodies it overlaps: up to kPushOuts moves along the deepest contact's normal.
  [[nodiscard]] Vec3 push_out(Vec3 p) const {
    for (int k = 0; k < kPushOuts; ++k) {
      const std::vector<ShapeContact> touching =
          contacts_with(s_, shape_, p, Quat::identity(), filter_);
      const ShapeContact* deepest = nullptr;
      for (const ShapeContact& c : touching)
        if (deepest == nullptr || c.depth > deepest->depth) deepest = &c;
      if (deepest == nullptr || deepest->depth <= slop_) break;
      p += deepest->normal * (deepest->depth + (slop_ >> 1));
    }
    return p;
  }

  /// Moves the capsule from `p` by `d`, sliding along what it meets (the file comment, step 4).
  /// `walking`: on ground (walls are seen from the side, and it steps up); otherwise falling or
  /// sliding. Dynamic bodies met go to `pushes` (when given); `ignore` is not met.
  Vec3 slide(Vec3 p, Vec3 d, bool walking, std::vector<BodyPush>* pushes,
             BodyId ignore = {}) const {
    Vec3 planes[kSurfaces];
    int count = 0;
    bool tried_step = !walking || step_height_ == Fixed::zero();
    for (int k = 0; k < kSurfaces && d != Vec3{}; ++k) {
      const std::optional<ShapeHit> hit = cast(p, d, ignore);
      if (!hit) return p + d;
      p += d * hit->fraction;
      Vec3 rest = d - d * hit->fraction;
      const Vec3 n = hit->normal;
      note_push(*hit, pushes);
      Vec3 plane = n;
      if (walking) {
        if (walkable(n) && rise(*hit, p) <= step_height_ + slop_) {
          rest = along(rest, n);
        } else {
          if (!tried_step) {
            tried_step = true;
            if (auto up = step_up(p, horizontal(rest))) return *up;
          }
          const Vec3 side = horizontal(n);
          plane = side == Vec3{} ? n : normalize(side);
          rest = off(rest, plane);
        }
      } else {
        if (rest.y < Fixed::zero() && walkable(surface_normal(*hit, p))) return p;  // landed
        rest = off(rest, n);
      }
      // Between two surfaces (a corner, a crease): along their common line, or stop.
      for (int j = 0; j < count; ++j) {
        if (dot(rest, planes[j]) >= Fixed::zero()) continue;
        const Vec3 line = cross(plane, planes[j]);
        if (line == Vec3{} || count >= 2) return p;
        const Vec3 u = normalize(line);
        rest = u * dot(u, rest);
        break;
      }
      planes[count++] = plane;
      d = rest;
    }
    return p;
  }

  /// The ground below the capsule at `p`, within `reach`: the move down to it when walkable.
  struct Ground {
    bool found = false;
    bool walkable = false;
    Vec3 normal;
    BodyId body;
    Vec3 drop;
  };
  [[nodiscard]] Ground ground(Vec3 p, Fixed reach) const {
    Ground g;
    const Vec3 down{Fixed::zero(), -reach, Fixed::zero()};
    std::optional<ShapeHit> hit = cast(p, down);
    if (!hit) return g;
    // In a wedge (a floor at the foot of a wall or a steep slope) the steep surface may be met
    // first: the ground beyond it, when walkable, is what the character stands on.
    if (!walkable(surface_normal(*hit, p + down * hit->fraction))) {
      if (auto beyond = cast(p, down, hit->body);
          beyond && walkable(surface_normal(*beyond, p + down * beyond->fraction)))
        hit = beyond;
    }
    const Vec3 at = p + down * hit->fraction;
    g.found = true;
    g.normal = surface_normal(*hit, at);
    g.walkable = walkable(g.normal);
    g.body = hit->body;
    g.drop = down * hit->fraction;
    return g;
  }

  /// Pushes the bodies in `pushes` (the file comment): `velocity` is the character's. Each push
  /// is a force on the body for the next step, so that the solver weighs it against friction and
  /// contacts like any applied force.
  void push(WorldState& s, const std::vector<BodyPush>& pushes, Vec3 velocity, Fixed mass) const {
    const Fixed weight = min(mass * length(s.def.gravity), max_quantity >> 1);
    std::vector<std::size_t> pushed;
    for (const BodyPush& p : pushes) {
      if (std::find(pushed.begin(), pushed.end(), p.body) != pushed.end()) continue;
      BodyState& b = s.bodies[p.body];
      const Fixed closing = dot(velocity - b.linear_velocity, p.direction);
      if (closing <= Fixed::zero()) continue;
      // Enough to bring it to the character's speed in one step, at most the weight.
      const Fixed force = min(closing / s.def.dt * b.mass, weight);
      const Vec3 f = b.force + without_locked(p.direction * force, b.translation_locks());
      const Fixed most = max_quantity >> 1;
      b.force = {clamp(f.x, -most, most), clamp(f.y, -most, most), clamp(f.z, -most, most)};
      b.sleep_time = Fixed::zero();  // pushed, so not at rest
      pushed.push_back(p.body);
    }
    wake_islands(s, pushed);
  }

 private:
  /// `v` turned along a walkable surface, keeping its horizontal part, lifted off it.
  [[nodiscard]] static Vec3 along(Vec3 v, Vec3 n) noexcept {
    const Vec3 h = horizontal(v);
    if (h == Vec3{}) return off(v, n);
    const Vec3 on{h.x, -(n.x * h.x + n.z * h.z) / n.y, h.z};
    return on + n * (length(on) >> 16);
  }
  /// `v` without its part into the surface of normal n, lifted off it.
  [[nodiscard]] static Vec3 off(Vec3 v, Vec3 n) noexcept {
    const Fixed into = dot(v, n);
    if (into >= Fixed::zero()) return v;
    const Vec3 on = v - n * into;
    return on + n * (length(on) >> 16);
  }

  void note_push(const ShapeHit& hit, std::vector<BodyPush>* pushes) const {
    if (pushes == nullptr) return;
    const std::ptrdiff_t i = s_.find(hit.body.value);
    if (s_.bodies[static_cast<std::size_t>(i)].type != BodyType::dynamic) return;
    pushes->push_back({static_cast<std::size_t>(i), -hit.normal});
  }

  /// Up by step_height, forward by `h`, down: the landing when it is a step (the file comment).
  [[nodiscard]] std::optional<Vec3> step_up(Vec3 p, Vec3 h) const {
    if (h == Vec3{}) return std::nullopt;
    const Vec3 up_move{Fixed::zero(), step_height_, Fixed::zero()};
    const std::optional<ShapeHit> up = cast(p, up_move);
    const Fixed lift = up ? step_height_ * up->fraction : step_height_;
    if (lift <= slop_) return std::nullopt;
    const Vec3 raised = p + Vec3{Fixed::zero(), lift, Fixed::zero()};
    const std::optional<ShapeHit> ahead = cast(raised, h);
    if (ahead && ahead->fraction == Fixed::zero()) return std::nullopt;
    const Vec3 over = raised + (ahead ? h * ahead->fraction : h);
    const Vec3 down_move{Fixed::zero(), -(lift + slop_ + slop_), Fixed::zero()};
    const std::optional<ShapeHit> down = cast(over, down_move);
    if (!down) return std::nullopt;
    const Vec3 landing = over + down_move * down->fraction;
    if (landing.y <= p.y + (slop_ >> 1)) return std::nullopt;
    if (rise(*down, p) > step_height_ + slop_) return std::nullopt;
    if (!walkable(surface_normal(*down, landing))) return std::nullopt;
    return landing;
  }

  const WorldState& s_;
  Shape shape_;
  QueryFilter filter_;
  Fixed cos_max_slope_;
  Fixed slop_;
  Fixed foot_;  ///< from the capsule's centre down to its lowest point
  Fixed step_height_;
};

void move_character(WorldState& s, CharacterState& c) {
  CharacterMover m(s, c);
  const Fixed dt = s.def.dt;
  const Fixed limit = s.def.max_linear_speed;
  Vec3 p = c.position;
  if (c.grounded) p = m.ride(c.ground_body, p);  // 1
  p = m.push_out(p);                             // 2
  const Vec3 start = p;
  // 3. The velocity of the move.
  const Vec3 walk = horizontal(c.input.desired_velocity);
  const bool jumped = c.input.jump > Fixed::zero();
  const bool walking = c.grounded && !jumped;
  Vec3 v;
  if (jumped) {
    v = walk + Vec3{Fixed::zero(), c.input.jump, Fixed::zero()};
  } else if (walking) {
    v = walk;
  } else if (c.sliding()) {
    v = c.velocity + s.def.gravity * dt;
  } else {
    v = {walk.x, c.velocity.y + s.def.gravity.y * dt, walk.z};
  }
  v = {clamp_speed(v.x, limit), clamp_speed(v.y, limit), clamp_speed(v.z, limit)};
  // 4. The move: on the ground, along it.
  Vec3 d = v * dt;
  if (walking && c.ground_normal.y > Fixed::zero()) {
    const Vec3 n = c.ground_normal;
    d = {d.x, -(n.x * d.x + n.z * d.z) / n.y, d.z};
    d += n * (length(d) >> 16);
  }
  std::vector<BodyPush> pushes;
  p = m.slide(p, d, walking, &pushes);
  // 5. The ground: snapped down to while walking, touched otherwise.
  const Fixed touch = m.slop() + m.slop();
  const auto g = m.ground(p, walking ? c.def.step_height + touch : touch);
  const bool near = g.found && length(g.drop) <= touch;
  c.grounded = g.found && g.walkable;
  if (c.grounded) p += g.drop;
  const bool on_steep = g.found && !g.walkable && near;
  c.ground_normal = c.grounded || on_steep ? g.normal : Vec3{};
  c.ground_body = c.grounded || on_steep ? g.body : BodyId{};
  // 6. Pushes and the velocity.
  c.velocity = (p - start) / dt;
  c.velocity = {clamp_speed(c.velocity.x, limit), clamp_speed(c.velocity.y, limit),
                clamp_speed(c.velocity.z, limit)};
  c.position = p;
  c.input.jump = Fixed::zero();
  m.push(s, pushes, v, c.def.mass);
}

}  // namespace

void move_characters(WorldState& s) {
  for (CharacterState& c : s.characters)
    move_character(s, c);
}

std::string check_character_record(const WorldState& s, const CharacterState& c) {
  if (auto e = check_character_def(c.def); !e.empty()) return e;
  if (auto e = check_position(c.position); !e.empty()) return e;
  if (auto e = check_components("velocity", c.velocity, s.def.max_linear_speed, "m/s"); !e.empty())
    return e;
  if (auto e = check_input(s, c.input); !e.empty()) return e;
  if (c.ground_body.is_null()) {
    if (c.grounded) return "grounded without a ground body";
    if (c.ground_normal != Vec3{}) return "a ground normal without a ground body";
    return {};
  }
  if (s.find(c.ground_body.value) < 0)
    return "ground body " + std::to_string(c.ground_body.value) + " does not exist";
  return check_unit_vector("ground_normal", c.ground_normal);
}

void forget_ground(WorldState& s, BodyId body) {
  for (CharacterState& c : s.characters) {
    if (c.ground_body != body) continue;
    c.ground_body = {};
    c.ground_normal = {};
    c.grounded = false;
  }
}

}  // namespace sim_detail

namespace {

Status unknown_character(CharacterId id) {
  return Status::error("no character with ID " + std::to_string(id.value));
}

}  // namespace

Expected<CharacterId> World::create_character(const CharacterDef& def) {
  if (auto e = sim_detail::check_character_def(def); !e.empty())
    return Status::error("invalid character definition: " + e);
  if (s_->next_character_id == 0xFFFFFFFFU) return Status::error("character IDs are used up");
  CharacterState c;
  c.id = CharacterId{s_->next_character_id++};
  c.def = def;
  c.position = def.position;
  s_->characters.push_back(c);  // IDs only grow: appending keeps the order
  return c.id;
}

Status World::destroy_character(CharacterId id) {
  const std::ptrdiff_t i = s_->find_character(id.value);
  if (i < 0) return unknown_character(id);
  s_->characters.erase(s_->characters.begin() + i);
  return Status::success();
}

Status World::set_character_input(CharacterId id, const CharacterInput& input) {
  const std::ptrdiff_t i = s_->find_character(id.value);
  if (i < 0) return unknown_character(id);
  if (auto e = sim_detail::check_input(*s_, input); !e.empty())
    return Status::error("character " + std::to_string(id.value) + ": " + e);
  s_->characters[static_cast<std::size_t>(i)].input = input;
  return Status::success();
}

Expected<CharacterState> World::character(CharacterId id) const {
  const std::ptrdiff_t i = s_->find_character(id.value);
  if (i < 0) return unknown_character(id);
  return s_->characters[static_cast<std::size_t>(i)];
}

std::vector<CharacterId> World::character_ids() const {
  std::vector<CharacterId> ids;
  ids.reserve(s_->characters.size());
  for (const CharacterState& c : s_->characters)
    ids.push_back(c.id);
  return ids;
}

}  // namespace detsim
