// libFuzzer target for the World's API: the input is a hostile WorldDef and a sequence of calls
// (create_body with any shape, size, mass, density, velocity, orientation and axis locks,
// destroy_body, set_type, set_transform, set_*_velocity, the forces and impulses, wake, step, save,
// restore, create_joint with any type, bodies, anchor, axis, limits, motor, lengths, spring and
// break thresholds, destroy_joint, set_joint_motor, the geometry registrations, and the particle
// groups: create_rope, create_cloth, create_soft_body with any values, apply_particle_force,
// destroy_particle_group; the queries raycast_particles, shape_cast, shape_contacts and
// contacts_of with any shape and pose; and the game's own state: set_game_state of any size,
// describe_game_state with good and bad fields, set_user_data; characters and vehicles with any
// definition and input).
//
// Properties checked beyond the sanitizers' (no crash, no undefined behaviour, no leak):
// - a refused call changes nothing: the world's saved bytes are those from before the call;
// - after every accepted call and every step, World::validate() holds (between steps, but for
//   the islands' sleep, which a call that wakes one body splits until the next step);
// - a saved state restores exactly (the restored world saves the same bytes), and a world
//   restored from it into a second World steps to the same bytes as the original (rule 5 of
//   docs/DETERMINISM.md).
// Work is bounded per input (at most 64 bodies, 64 joints, 16 steps, and a budget of solver passes)
// so that one input runs in milliseconds even under the sanitizers.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <detsim/sim/joint.hpp>
#include <detsim/sim/particles.hpp>
#include <detsim/sim/world.hpp>

namespace {

using detsim::BodyDef;
using detsim::BodyId;
using detsim::BodyType;
using detsim::Fixed;
using detsim::GeometryId;
using detsim::Quat;
using detsim::Shape;
using detsim::ShapeType;
using detsim::Vec3;
using detsim::World;
using detsim::WorldDef;

constexpr std::size_t kMaxBodies = 64;
constexpr std::size_t kMaxJoints = 64;
constexpr int kMaxSteps = 16;
constexpr int kMaxCalls = 256;
constexpr std::size_t kMaxGeometries = 16;
constexpr int kOps = 33;                    // the calls' opcodes, op % kOps
constexpr std::size_t kMaxParticles = 600;  // what the groups of one input may hold in all
// Sub-steps x iterations x (bodies + joints + 1), summed over the steps: what the steps of one
// input may cost in total.
constexpr std::uint64_t kStepBudget = 40000;

/// A finding: says which property broke, then aborts (libFuzzer saves the input).
[[noreturn]] void fail(const char* what) {
  std::fprintf(stderr, "world_api_fuzz: %s\n", what);
  std::abort();
}

/// Reads the input from the front; past its end every read is zero.
class Input {
 public:
  explicit Input(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}

  [[nodiscard]] bool empty() const { return pos_ >= bytes_.size(); }

  std::uint8_t byte() { return pos_ < bytes_.size() ? bytes_[pos_++] : std::uint8_t{0}; }

  std::uint64_t u64(int n = 8) {
    std::uint64_t v = 0;
    for (int i = 0; i < n; ++i)
      v |= std::uint64_t{byte()} << (8 * i);
    return v;
  }

  std::uint32_t u32() { return static_cast<std::uint32_t>(u64(4)); }

  /// A Fixed drawn from the values that break arithmetic most often: small integers, the range's
  /// ends, powers of two on both sides of one, the API's documented limits and their neighbours,
  /// and raw bits.
  Fixed fixed() {
    const std::uint8_t kind = byte();
    const auto signed_byte = [this] { return static_cast<std::int32_t>(byte()) - 128; };
    switch (kind % 8) {
      case 0:
        return Fixed::from_int(signed_byte());
      case 1:
        return Fixed::from_raw(static_cast<std::int64_t>(u64()));
      case 2: {
        static constexpr std::array<std::int64_t, 12> specials = {0,
                                                                  1,
                                                                  -1,
                                                                  2,
                                                                  3,
                                                                  std::int64_t{10000} << 32,
                                                                  (std::int64_t{10000} << 32) + 1,
                                                                  std::int64_t{1} << 62,
                                                                  (std::int64_t{1} << 62) - 1,
                                                                  INT64_MAX,
                                                                  INT64_MIN,
                                                                  INT64_MAX - 1};
        return Fixed::from_raw(specials[byte() % specials.size()]);
      }
      case 3: {
        const int shift = byte() % 63;  // 2^(shift - 32): 2^-32 .. 2^30
        const Fixed p = Fixed::from_raw(std::int64_t{1} << shift);
        return (kind & 0x80U) != 0 ? -p : p;
      }
      case 4:
        return Fixed::from_raw(static_cast<std::int32_t>(u32()));  // within +-0.5
      case 5:
        return Fixed::from_int(static_cast<std::int32_t>(u32()));
      case 6:  // a small positive size or mass with a fraction
        return Fixed::from_raw(static_cast<std::int64_t>(u64(3)) << 16);
      default:
        return Fixed::from_int(signed_byte()) + Fixed::from_raw(static_cast<std::int32_t>(u32()));
    }
  }

  Vec3 vec3() {
    const std::uint8_t how = byte();
    if (how % 4 == 0) return {};
    if (how % 4 == 1) return {fixed(), {}, {}};
    return {fixed(), fixed(), fixed()};
  }

  Quat quat() {
    const std::uint8_t how = byte();
    switch (how % 4) {
      case 0:
        return {};
      case 1: {
        const Vec3 axis = vec3();
        return detsim::from_axis_angle(detsim::normalize_or(axis, Vec3::unit_x()), fixed());
      }
      case 2:
        return detsim::normalize(Quat{fixed(), fixed(), fixed(), fixed()});
      default:
        return Quat{fixed(), fixed(), fixed(), fixed()};  // most often not a unit quaternion
    }
  }

  BodyType body_type() { return static_cast<BodyType>(byte() % 4); }  // 3 names no type

 private:
  std::span<const std::uint8_t> bytes_;
  std::size_t pos_ = 0;
};

WorldDef world_def(Input& in) {
  WorldDef def;
  const std::uint8_t fields = in.byte();
  if ((fields & 1U) != 0) def.gravity = in.vec3();
  if ((fields & 2U) != 0) def.dt = in.fixed();
  if ((fields & 4U) != 0) {
    def.substeps = in.byte() % 66U;  // 0 and 65 are refused
    def.iterations = in.byte() % 66U;
  }
  if ((fields & 8U) != 0) {
    def.max_linear_speed = in.fixed();
    def.max_angular_speed = in.fixed();
  }
  if ((fields & 16U) != 0) {
    def.contact_hertz = in.fixed();
    def.contact_damping_ratio = in.fixed();
    def.contact_push_max = in.fixed();
    def.restitution_threshold = in.fixed();
  }
  if ((fields & 32U) != 0) {
    def.linear_slop = in.fixed();
    def.speculative_distance = in.fixed();
  }
  if ((fields & 64U) != 0) {
    def.enable_sleep = (in.byte() & 1U) != 0;
    def.sleep_linear_speed = in.fixed();
    def.sleep_angular_speed = in.fixed();
    def.time_to_sleep = in.fixed();
  }
  if ((fields & 128U) != 0) def.seed = in.u64();
  return def;
}

Shape shape(Input& in) {
  const auto type = static_cast<ShapeType>(in.byte() % 11);  // 0 and 10 name no type
  Shape s;
  s.type = type;
  const std::uint8_t fields = in.byte();
  // Mostly the fields the type uses; sometimes every field, which the checks must refuse.
  const bool all = (fields & 0x80U) != 0;
  const bool round = type == ShapeType::capsule || type == ShapeType::cylinder;
  if (all || type == ShapeType::sphere || round) s.radius = in.fixed();
  if (all || round) s.half_height = in.fixed();
  if (all || type == ShapeType::box) {
    const Fixed h = in.fixed();
    s.half_extents = (fields & 1U) != 0 ? Vec3{h, h, h} : Vec3{h, in.fixed(), in.fixed()};
  }
  // A geometry ID: mostly one the world may hold (of the type or another: refused), sometimes on
  // a primitive (refused) or unknown.
  const bool registered = type == ShapeType::convex || type == ShapeType::mesh ||
                          type == ShapeType::heightfield || type == ShapeType::compound;
  if (all || registered)
    s.geometry = GeometryId{static_cast<std::uint32_t>(in.byte() % (kMaxGeometries + 2))};
  return s;
}

// ---- Registered geometry: hostile point sets, meshes, heightfields and compounds ----

detsim::Status create_hull(Input& in, World& world) {
  std::vector<Vec3> points(in.byte() % 24U);
  for (Vec3& p : points)
    p = in.vec3();
  auto id = world.create_convex_hull(points);
  return id ? detsim::Status::success() : id.status();
}

detsim::Status create_mesh(Input& in, World& world) {
  std::vector<Vec3> vertices(in.byte() % 16U);
  for (Vec3& v : vertices)
    v = in.vec3();
  std::vector<std::uint32_t> indices(in.byte() % 40U);
  for (std::uint32_t& i : indices)
    i = (in.byte() & 0x80U) != 0 ? in.u32() : in.byte() % 17U;  // mostly in range, or any
  auto id = world.create_mesh(vertices, indices);
  return id ? detsim::Status::success() : id.status();
}

detsim::Status create_heightfield(Input& in, World& world) {
  detsim::HeightfieldDef def;
  def.rows = in.byte() % 10U;
  def.columns = in.byte() % 10U;
  def.cell_size = in.fixed();
  // Mostly rows x columns heights, sometimes a count that does not match (refused).
  std::size_t n = std::size_t{def.rows} * def.columns;
  if ((in.byte() & 0x80U) != 0) n = in.byte() % 100U;
  def.heights.resize(n);
  for (Fixed& h : def.heights)
    h = (in.byte() & 1U) != 0 ? in.fixed()
                              : Fixed::from_int(static_cast<std::int32_t>(in.byte() % 8));
  auto id = world.create_heightfield(def);
  return id ? detsim::Status::success() : id.status();
}

detsim::Status create_compound(Input& in, World& world) {
  std::vector<detsim::CompoundChild> children(in.byte() % 6U);
  for (detsim::CompoundChild& c : children) {
    c.shape = shape(in);
    c.position = in.vec3();
    c.orientation = in.quat();
  }
  auto id = world.create_compound(children);
  return id ? detsim::Status::success() : id.status();
}

BodyDef body_def(Input& in) {
  BodyDef def;
  def.type = in.body_type();
  def.shape = shape(in);
  const std::uint8_t fields = in.byte();
  if ((fields & 1U) != 0) def.position = in.vec3();
  if ((fields & 2U) != 0) def.orientation = in.quat();
  if ((fields & 4U) != 0) {
    def.linear_velocity = in.vec3();
    def.angular_velocity = in.vec3();
  }
  if ((fields & 8U) != 0) def.mass = in.fixed();
  if ((fields & 16U) != 0) def.density = in.fixed();
  if ((fields & 32U) != 0) {
    def.friction = in.fixed();
    def.restitution = in.fixed();
  }
  if ((fields & 64U) != 0) {
    def.linear_damping = in.fixed();
    def.angular_damping = in.fixed();
  }
  if ((fields & 128U) != 0) {
    def.layer = in.u32();
    def.mask = in.u32();
    const std::uint8_t flags = in.byte();
    def.sensor = (flags & 1U) != 0;
    def.ccd = (flags & 2U) != 0;
    def.lock_translation = {(flags & 4U) != 0, (flags & 8U) != 0, (flags & 16U) != 0};
    def.lock_rotation = {(flags & 32U) != 0, (flags & 64U) != 0, (flags & 128U) != 0};
    def.user_data = in.u64();
  }
  return def;
}

/// An existing body most of the time (by index), else any ID (usually unknown).
BodyId body_id(Input& in, const World& world) {
  const std::uint8_t pick = in.byte();
  const std::vector<BodyId> ids = world.body_ids();
  if ((pick & 0x80U) == 0 && !ids.empty()) return ids[pick % ids.size()];
  return BodyId{pick % 0x80U};
}

/// A character's definition: the defaults, each field replaced by a hostile value when a bit says.
detsim::CharacterDef character_def(Input& in) {
  detsim::CharacterDef d;
  const std::uint8_t fields = in.byte();
  d.position = in.vec3();
  if ((fields & 1U) != 0) d.radius = in.fixed();
  if ((fields & 2U) != 0) d.half_height = in.fixed();
  if ((fields & 4U) != 0) d.max_slope = in.fixed();
  if ((fields & 8U) != 0) d.step_height = in.fixed();
  if ((fields & 16U) != 0) d.mass = in.fixed();
  if ((fields & 32U) != 0) d.mask = in.u32();
  return d;
}

/// A vehicle's definition on a body of the world: 0 to 5 wheels, each default or hostile, and
/// hostile engine, gears, axles and tire when a bit says.
detsim::VehicleDef vehicle_def(Input& in, const World& world) {
  detsim::VehicleDef d;
  d.chassis = body_id(in, world);
  const std::uint8_t fields = in.byte();
  const std::size_t wheels = in.byte() % 6U;
  for (std::size_t i = 0; i < wheels; ++i) {
    detsim::WheelDef w;
    w.attachment = in.vec3();
    const std::uint8_t wf = in.byte();
    if ((wf & 1U) != 0) w.radius = in.fixed();
    if ((wf & 2U) != 0) w.suspension_rest_length = in.fixed();
    if ((wf & 4U) != 0) w.suspension_stiffness = in.fixed();
    if ((wf & 8U) != 0) w.suspension_damping = in.fixed();
    if ((wf & 16U) != 0) w.max_steer_angle = in.fixed();
    if ((wf & 32U) != 0) w.inertia = in.fixed();
    w.driven = (wf & 64U) != 0;
    w.handbrake = (wf & 128U) != 0;
    d.wheels.push_back(w);
  }
  if ((fields & 1U) != 0) {
    d.engine.torque_curve.resize(in.byte() % 4U);
    for (detsim::TorquePoint& p : d.engine.torque_curve)
      p = {in.fixed(), in.fixed()};
    d.engine.max_rpm = in.fixed();
    d.engine.inertia = in.fixed();
  }
  if ((fields & 2U) != 0) {
    d.gear_ratios.resize(in.byte() % 4U);
    for (Fixed& g : d.gear_ratios)
      g = in.fixed();
    d.final_drive = in.fixed();
  }
  if ((fields & 4U) != 0) {
    d.axles.resize(in.byte() % 3U);
    for (detsim::AxleDef& a : d.axles)
      a = {in.byte() % 6U, in.byte() % 6U, in.fixed()};
  }
  if ((fields & 8U) != 0) d.tire.lateral = {in.fixed(), in.fixed(), in.fixed(), in.fixed()};
  d.automatic = (fields & 16U) == 0;
  return d;
}

detsim::JointDef joint_def(Input& in, const World& world) {
  detsim::JointDef def;
  def.type = static_cast<detsim::JointType>(in.byte() % 7);  // 6 names no type
  def.body_a = body_id(in, world);
  def.body_b = body_id(in, world);
  const std::uint8_t fields = in.byte();
  // Mostly the anchor at one body's centre or between the two, sometimes anywhere.
  const auto centre = [&](BodyId id) {
    auto b = world.body(id);
    return b ? b.value().position : Vec3{};
  };
  def.anchor = (fields & 1U) != 0 ? in.vec3()
                                  : (centre(def.body_a) + centre(def.body_b)) / Fixed::from_int(2);
  if ((fields & 2U) != 0) {
    const Vec3 axis = in.vec3();
    def.axis = (fields & 4U) != 0 ? axis : detsim::normalize_or(axis, Vec3::unit_y());
  }
  if ((fields & 8U) != 0) {
    def.limit_enabled = (in.byte() & 1U) != 0;
    def.limit_lower = in.fixed();
    def.limit_upper = in.fixed();
    def.swing_limit = in.fixed();
  }
  if ((fields & 16U) != 0) {
    def.motor_enabled = (in.byte() & 1U) != 0;
    def.motor_speed = in.fixed();
    def.motor_max_force = in.fixed();
  }
  if ((fields & 32U) != 0) {
    def.min_length = in.fixed();
    def.max_length = in.fixed();
    def.spring_frequency = in.fixed();
    def.spring_damping_ratio = in.fixed();
  }
  if ((fields & 64U) != 0) {
    def.break_force = in.fixed();
    def.break_torque = in.fixed();
  }
  if ((fields & 128U) != 0) {
    def.collide_connected = (in.byte() & 1U) != 0;
    def.user_data = in.u64();
  }
  return def;
}

/// An existing joint most of the time (by index), else any ID (usually unknown).
// ---- Particle groups: any values, but sizes kept small (a count byte, with the refused 0 and 1
// among them) so that one input stays fast.

std::size_t particles_in(const World& world) {
  std::size_t n = 0;
  for (const detsim::ParticleGroupId id : world.particle_group_ids())
    n += world.particle_group_stats(id).value().particle_count;
  return n;
}

detsim::ParticleSettings particle_settings(Input& in) {
  detsim::ParticleSettings p;
  p.friction = in.fixed();
  p.damping = in.fixed();
  p.substeps = in.byte() % 18;  // 0 and 17 are refused
  p.layer = in.u32();
  p.mask = in.u32();
  return p;
}

detsim::Status create_particles(Input& in, World& world, int kind) {
  const std::size_t room = kMaxParticles - std::min(kMaxParticles, particles_in(world));
  if (kind == 0) {
    detsim::RopeDef r;
    r.start = in.vec3();
    r.end = in.vec3();
    r.segments = in.byte() % 40;
    r.length = in.fixed();
    r.mass = in.fixed();
    r.radius = in.fixed();
    r.compliance = in.fixed();
    r.bending_compliance = in.fixed();
    r.attach_start = body_id(in, world);
    r.attach_end = body_id(in, world);
    r.settings = particle_settings(in);
    if (r.segments + 1U > room) return detsim::Status::success();
    auto id = world.create_rope(r);
    return id ? detsim::Status::success() : id.status();
  }
  if (kind == 1) {
    detsim::ClothDef c;
    c.origin = in.vec3();
    c.axis_u = in.vec3();
    c.axis_v = in.vec3();
    c.columns = in.byte() % 12;
    c.rows = in.byte() % 12;
    c.mass = in.fixed();
    c.thickness = in.fixed();
    c.stretch_compliance = in.fixed();
    c.bend_compliance = in.fixed();
    for (std::uint8_t k = in.byte() % 4; k > 0; --k)
      c.pinned.push_back(in.byte());
    if (in.byte() % 2 == 0) c.attach_body = body_id(in, world);
    c.tear_strain = in.fixed();
    c.settings = particle_settings(in);
    if (std::size_t{c.columns} * c.rows > room) return detsim::Status::success();
    auto id = world.create_cloth(c);
    return id ? detsim::Status::success() : id.status();
  }
  if (kind == 3) {
    // A fluid of any values; its particle count (the block over the spacing, cubed at most)
    // must fit the input's budget before it is made.
    detsim::FluidDef f;
    f.min = in.vec3();
    f.max = f.min + in.vec3();
    f.spacing = in.fixed();
    f.rest_density = in.fixed();
    f.viscosity = in.fixed();
    f.particle_radius = in.fixed();
    f.settings = particle_settings(in);
    if (f.spacing <= Fixed::zero()) return world.create_fluid(f).status();
    std::size_t count = 1;
    for (const Fixed extent : {f.max.x - f.min.x, f.max.y - f.min.y, f.max.z - f.min.z}) {
      if (extent <= Fixed::zero()) return world.create_fluid(f).status();
      const std::uint64_t n =
          static_cast<std::uint64_t>(extent.raw()) / static_cast<std::uint64_t>(f.spacing.raw());
      if (n > room) return detsim::Status::success();
      count *= static_cast<std::size_t>(n) + 1;
      if (count > room) return detsim::Status::success();
    }
    auto id = world.create_fluid(f);
    return id ? detsim::Status::success() : id.status();
  }
  detsim::SoftBodyDef b;
  b.shape = shape(in);
  b.position = in.vec3();
  b.orientation = in.quat();
  b.resolution = in.byte() % 10;
  b.mass = in.fixed();
  b.edge_compliance = in.fixed();
  b.volume_compliance = in.fixed();
  b.settings = particle_settings(in);
  if (std::size_t{b.resolution} * b.resolution * b.resolution > room)
    return detsim::Status::success();
  auto id = world.create_soft_body(b);
  return id ? detsim::Status::success() : id.status();
}

detsim::ParticleGroupId group_id(Input& in, const World& world) {
  const std::vector<detsim::ParticleGroupId> ids = world.particle_group_ids();
  const std::uint8_t pick = in.byte();
  if (ids.empty() || pick == 255) return detsim::ParticleGroupId{pick};  // unknown IDs too
  return ids[pick % ids.size()];
}

detsim::JointId joint_id(Input& in, const World& world) {
  const std::uint8_t pick = in.byte();
  const std::vector<detsim::JointId> ids = world.joint_ids();
  if ((pick & 0x80U) == 0 && !ids.empty()) return ids[pick % ids.size()];
  return detsim::JointId{pick % 0x80U};
}

/// With DETSIM_FUZZ_TRACE set, each call's opcode, result and the bodies after it go to stderr:
/// a finding's input read as the calls it makes.
void trace(int op, const detsim::Status& status, const World& world) {
  static const bool on = std::getenv("DETSIM_FUZZ_TRACE") != nullptr;
  if (!on) return;
  std::fprintf(stderr, "op %d: %s\n", op, status.ok() ? "ok" : status.message().c_str());
  const auto num = [](Fixed x) { return x.to_double(); };  // display only
  for (const detsim::ParticleGroupId id : world.particle_group_ids()) {
    const std::size_t n = world.particle_positions(id)->size();
    const char* type = world.rope_def(id).ok()        ? "rope"
                       : world.cloth_def(id).ok()     ? "cloth"
                       : world.soft_body_def(id).ok() ? "soft body"
                                                      : "fluid";
    std::fprintf(stderr, "  particle group %u: %s of %zu particles\n", id.value, type, n);
  }
  for (const BodyId id : world.body_ids()) {
    const detsim::BodyState b = world.body(id).value();
    std::fprintf(stderr,
                 "  body %u type %d shape %d awake %d mass %g inertia (%g %g %g) p (%g %g %g) "
                 "v (%g %g %g) w (%g %g %g) f (%g %g %g) t (%g %g %g)\n",
                 id.value, static_cast<int>(b.type), static_cast<int>(b.shape.type),
                 static_cast<int>(b.awake), num(b.mass), num(b.inertia.x), num(b.inertia.y),
                 num(b.inertia.z), num(b.position.x), num(b.position.y), num(b.position.z),
                 num(b.linear_velocity.x), num(b.linear_velocity.y), num(b.linear_velocity.z),
                 num(b.angular_velocity.x), num(b.angular_velocity.y), num(b.angular_velocity.z),
                 num(b.force.x), num(b.force.y), num(b.force.z), num(b.torque.x), num(b.torque.y),
                 num(b.torque.z));
  }
}

/// World::validate() holds. Between steps, one of its invariants may not yet: a call wakes only
/// its body, and the next step wakes the rest of the island (World::validate's "after a step").
void check_valid(const World& world, bool after_step) {
  const detsim::Status s = world.validate();
  if (s.ok()) return;
  if (!after_step && s.message().find("an island is split") != std::string::npos) return;
  std::fprintf(stderr, "world_api_fuzz: %s\n", s.message().c_str());
  fail("World::validate() failed");
}

/// save -> restore into a second World -> both step once -> the same bytes. The second World is
/// a fresh one when there is no geometry, else a copy (geometry is the world's definition: a
/// state restores only into a world that holds it).
void check_restore_steps_alike(World& world) {
  const std::vector<std::uint8_t> bytes = world.save();
  World copy;
  if (world.geometry_count() > 0) copy = world;
  if (!copy.restore(bytes)) fail("a saved state was refused by another World");
  if (copy.save() != bytes) fail("a restored state saves other bytes");
  world.step();
  copy.step();
  check_valid(world, true);
  if (copy.save() != world.save()) fail("a restored world steps differently from the original");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Input in({data, size});
  std::optional<World> created;
  if ((in.byte() & 1U) != 0) {
    auto w = World::create(world_def(in));
    if (!w) return 0;  // a refused definition makes no world: nothing more to check
    created.emplace(std::move(w.value()));
  } else {
    created.emplace();
  }
  World& world = *created;
  check_valid(world, true);
  const WorldDef& def = world.def();
  const std::uint64_t step_cost = std::uint64_t{def.substeps} * def.iterations;
  std::uint64_t spent = 0;
  int steps = 0;
  std::vector<std::vector<std::uint8_t>> slots(2);

  for (int call = 0; call < kMaxCalls && !in.empty(); ++call) {
    const std::vector<std::uint8_t> before = world.save();
    detsim::Status status = detsim::Status::success();
    const std::uint8_t op = in.byte();
    switch (op % kOps) {
      case 0: {
        const BodyDef body = body_def(in);
        if (world.body_count() >= kMaxBodies) break;
        auto id = world.create_body(body);
        if (!id) status = id.status();
        break;
      }
      case 1:
        status = world.destroy_body(body_id(in, world));
        break;
      case 2: {
        const BodyId id = body_id(in, world);
        status = world.set_type(id, in.body_type());
        break;
      }
      case 3: {
        const BodyId id = body_id(in, world);
        const Vec3 p = in.vec3();
        status = world.set_transform(id, p, in.quat());
        break;
      }
      case 4: {
        const BodyId id = body_id(in, world);
        status = world.set_linear_velocity(id, in.vec3());
        break;
      }
      case 5: {
        const BodyId id = body_id(in, world);
        status = world.set_angular_velocity(id, in.vec3());
        break;
      }
      case 6: {
        const BodyId id = body_id(in, world);
        status = world.apply_force(id, in.vec3());
        break;
      }
      case 7: {
        const BodyId id = body_id(in, world);
        status = world.apply_torque(id, in.vec3());
        break;
      }
      case 8: {
        const BodyId id = body_id(in, world);
        const Vec3 f = in.vec3();
        status = world.apply_force_at_point(id, f, in.vec3());
        break;
      }
      case 9: {
        const BodyId id = body_id(in, world);
        status = world.apply_linear_impulse(id, in.vec3());
        break;
      }
      case 10: {
        const BodyId id = body_id(in, world);
        const Vec3 j = in.vec3();
        status = world.apply_impulse_at_point(id, j, in.vec3());
        break;
      }
      case 11: {
        const BodyId id = body_id(in, world);
        status = world.apply_angular_impulse(id, in.vec3());
        break;
      }
      case 12:
        status = world.wake(body_id(in, world));
        break;
      case 13:
      case 14: {
        const std::uint64_t cost =
            step_cost * (world.body_count() + world.joint_ids().size() + particles_in(world) + 1);
        if (steps >= kMaxSteps || spent + cost > kStepBudget) break;
        ++steps;
        spent += cost;
        if (op % kOps == 14) {
          check_restore_steps_alike(world);
        } else {
          world.step();
        }
        check_valid(world, true);
        trace(op % kOps, status, world);
        continue;  // a step changes the world: nothing to compare with `before`
      }
      case 15:
        slots[in.byte() % 2] = before;
        break;
      case 17: {
        const detsim::JointDef joint = joint_def(in, world);
        if (world.joint_ids().size() >= kMaxJoints) break;
        auto id = world.create_joint(joint);
        if (!id) status = id.status();
        break;
      }
      case 18:
        status = world.destroy_joint(joint_id(in, world));
        break;
      case 19: {
        const detsim::JointId id = joint_id(in, world);
        const Fixed speed = in.fixed();
        status = world.set_joint_motor(id, speed, in.fixed());
        break;
      }
      case 20:
      case 21:
      case 22:
      case 23: {
        if (world.geometry_count() >= kMaxGeometries) break;
        const int kind = op % kOps;
        status = kind == 20   ? create_hull(in, world)
                 : kind == 21 ? create_mesh(in, world)
                 : kind == 22 ? create_heightfield(in, world)
                              : create_compound(in, world);
        break;
      }
      case 24:
        status = create_particles(in, world, in.byte() % 4);
        break;
      case 25: {
        const detsim::ParticleGroupId id = group_id(in, world);
        status = world.apply_particle_force(id, in.vec3());
        break;
      }
      case 26:
        status = world.destroy_particle_group(group_id(in, world));
        break;
      case 27: {  // the queries, with any shape and pose: they answer and change nothing
        const std::uint8_t which = in.byte() % 4U;
        const Vec3 origin = in.vec3();
        if (which == 0) {
          (void)world.raycast_particles(origin, in.vec3());
          break;
        }
        const Shape query = shape(in);
        const detsim::Quat q = in.quat();
        detsim::QueryFilter filter;
        filter.ignore = body_id(in, world);
        if (which == 1) {
          const Vec3 translation = in.vec3();
          if (const auto hit = world.shape_cast(query, origin, q, translation, filter)) {
            if (hit->fraction < Fixed::zero() || hit->fraction > Fixed::one())
              fail("a shape cast's fraction is outside [0, 1]");
          }
        } else if (which == 2) {
          for (const detsim::ShapeContact& c : world.shape_contacts(query, origin, q, filter)) {
            if (c.point_count == 0 || c.point_count > 4 || c.depth < Fixed::zero())
              fail("a shape contact without points or with a negative depth");
          }
        } else {
          (void)world.contacts_of(filter.ignore);
        }
        if (world.save() != before) fail("a query changed the world");
        break;
      }
      case 28: {  // the game's own state: mostly small, sometimes empty or over the limit
        const std::uint8_t pick = in.byte();
        const std::size_t size = pick == 0xFF   ? detsim::max_game_state_size + 1
                                 : pick == 0xFE ? 0
                                                : pick % 48U;
        std::vector<std::uint8_t> bytes(size);
        for (std::size_t i = 0; i < size && i < 48; ++i)
          bytes[i] = in.byte();
        status = world.set_game_state(bytes);
        break;
      }
      case 29: {  // its description: names, offsets and types good and bad
        std::vector<detsim::GameField> fields(in.byte() % 5U);
        for (detsim::GameField& f : fields) {
          static constexpr const char* names[] = {"score", "score", "a.b[1]", "", "bad name"};
          f.name = names[in.byte() % 5U];
          f.offset = (in.byte() & 0x80U) != 0 ? in.u32() : in.byte() % 40U;
          f.type = static_cast<detsim::GameFieldType>(in.byte() % 10U);  // 9: no type
        }
        status = world.describe_game_state(fields);
        break;
      }
      case 30: {
        const BodyId id = body_id(in, world);
        status = world.set_user_data(id, in.u32());
        break;
      }
      case 31: {  // characters: a hostile definition, or any input to one (or to no one)
        const std::vector<detsim::CharacterId> ids = world.character_ids();
        if ((in.byte() & 1U) != 0) {
          const detsim::CharacterDef c = character_def(in);
          if (ids.size() >= 8) break;
          auto id = world.create_character(c);
          if (!id) status = id.status();
        } else {
          const std::uint8_t pick = in.byte();
          const detsim::CharacterId id = ids.empty() || (pick & 0x80U) != 0
                                             ? detsim::CharacterId{pick % 0x80U}
                                             : ids[pick % ids.size()];
          const Vec3 v = in.vec3();
          status = world.set_character_input(id, {v, in.fixed()});
        }
        break;
      }
      case 32: {  // vehicles: a hostile definition, or any input to one (or to no one)
        const std::vector<detsim::VehicleId> ids = world.vehicle_ids();
        if ((in.byte() & 1U) != 0) {
          const detsim::VehicleDef v = vehicle_def(in, world);
          if (ids.size() >= 8) break;
          auto id = world.create_vehicle(v);
          if (!id) status = id.status();
        } else {
          const std::uint8_t pick = in.byte();
          const detsim::VehicleId id = ids.empty() || (pick & 0x80U) != 0
                                           ? detsim::VehicleId{pick % 0x80U}
                                           : ids[pick % ids.size()];
          const Fixed throttle = in.fixed();
          const Fixed brake = in.fixed();
          const Fixed steering = in.fixed();
          status = world.set_vehicle_input(id, {throttle, brake, steering, (in.byte() & 1U) != 0});
        }
        break;
      }
      default: {
        const std::vector<std::uint8_t>& slot = slots[in.byte() % 2];
        if (slot.empty()) break;
        if (!world.restore(slot)) fail("bytes this world saved were refused");
        if (world.save() != slot) fail("a restored slot saves other bytes");
        check_valid(world, false);
        continue;
      }
    }
    trace(op % kOps, status, world);
    if (!status.ok()) {
      if (world.save() != before) fail("a refused call changed the world");
    } else {
      check_valid(world, false);
    }
  }
  return 0;
}
