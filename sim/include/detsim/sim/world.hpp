// detsim::World: the deterministic rigid-body simulation.
//
// Single-threaded; everything iterates in ascending body ID order; only Fixed arithmetic. The same
// WorldDef, the same calls in the same order and the same inputs give the same bits on every
// machine. See docs/SIM.md for the step's stages and docs/DETERMINISM.md for the rules.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <detsim/core/rng.hpp>
#include <detsim/core/status.hpp>
#include <detsim/fixed/vec3.hpp>
#include <detsim/sim/body.hpp>
#include <detsim/sim/character.hpp>
#include <detsim/sim/game_state.hpp>
#include <detsim/sim/geometry.hpp>
#include <detsim/sim/joint.hpp>
#include <detsim/sim/mass.hpp>
#include <detsim/sim/particles.hpp>
#include <detsim/sim/shape_outline.hpp>
#include <detsim/sim/state_sections.hpp>
#include <detsim/sim/vehicle.hpp>
#include <detsim/sim/world_def.hpp>

namespace detsim {

namespace sim_detail {
struct WorldState;
struct WorldAccess;
}  // namespace sim_detail
struct Injection;

/// A body's complete state as the world holds it (a copy: it does not follow later changes).
struct BodyState {
  BodyId id{};
  BodyType type = BodyType::dynamic;
  Shape shape{};
  Vec3 position{};
  Quat orientation{};
  Vec3 linear_velocity{};   ///< of the centre of mass (the origin, for the primitives)
  Vec3 angular_velocity{};  ///< world space
  Fixed mass{};    ///< kg: what the body weighs while dynamic (kept while kinematic or static)
  Vec3 inertia{};  ///< principal moments, kg m^2, like mass (about inertia_axes)
  /// The centre of mass in the body frame (m): what the body rotates about. Zero for the
  /// primitives; world_center() gives it in world space. Set from the shape, like mass.
  Vec3 center_of_mass{};
  /// The principal axes of inertia in the body frame (MassProperties::inertia_axes).
  Quat inertia_axes{};
  Fixed friction{};
  Fixed restitution{};
  Fixed linear_damping{};
  Fixed angular_damping{};
  std::uint32_t layer = 1;
  std::uint32_t mask = 0xFFFFFFFFU;
  bool sensor = false;
  bool ccd = false;
  /// BodyDef::lock_translation and lock_rotation, one flag per world axis.
  bool lock_translation_x = false;
  bool lock_translation_y = false;
  bool lock_translation_z = false;
  bool lock_rotation_x = false;
  bool lock_rotation_y = false;
  bool lock_rotation_z = false;
  std::uint64_t user_data = 0;
  bool awake = true;
  Fixed sleep_time{};  ///< seconds the body has been slow enough to sleep
  Vec3 force{};        ///< accumulated for the next step, then cleared
  Vec3 torque{};

  /// The centre of mass in world space: position + orientation * center_of_mass. linear_velocity
  /// is this point's velocity.
  [[nodiscard]] Vec3 world_center() const noexcept;
  [[nodiscard]] constexpr AxisLocks translation_locks() const noexcept {
    return {lock_translation_x, lock_translation_y, lock_translation_z};
  }
  [[nodiscard]] constexpr AxisLocks rotation_locks() const noexcept {
    return {lock_rotation_x, lock_rotation_y, lock_rotation_z};
  }

  friend constexpr bool operator==(const BodyState&, const BodyState&) noexcept = default;
};

/// The hash of one section of a state (state_sections.hpp).
struct SectionHash {
  std::string name;
  std::uint64_t hash = 0;

  friend bool operator==(const SectionHash&, const SectionHash&) = default;
};

/// Hashes of a state: of all its bytes, and of each section (docs/STATE.md).
struct StateHashes {
  std::uint64_t total = 0;  ///< the frame's state hash: covers every section
  /// In the state's order. A World's: "globals" (frame, ID counter, definition), "rng",
  /// "geometry" (registered geometry by content hash), "bodies" (every body), "contacts" (the
  /// contact cache with its warm-start impulses), "joints", "particles", and when the world has
  /// had characters, "characters" (docs/STATE.md).
  std::vector<SectionHash> sections;

  /// The hash of the section called `name`, or 0 when there is none.
  [[nodiscard]] std::uint64_t section(std::string_view name) const noexcept;

  friend bool operator==(const StateHashes&, const StateHashes&) = default;
};

/// One point of a contact as the contact cache keeps it between steps: the feature pair that made
/// it (to match it with the next step's point) and the impulses the solver accumulated on it (to
/// warm start with).
struct ContactPointState {
  std::uint32_t feature = 0;
  Fixed normal_impulse{};  ///< N s
  Fixed tangent_impulse_1{};
  Fixed tangent_impulse_2{};

  friend constexpr bool operator==(const ContactPointState&,
                                   const ContactPointState&) noexcept = default;
};

/// A pair of bodies in the contact cache (their bounding boxes overlap), as saved and hashed.
struct ContactState {
  BodyId a{};  ///< the lower ID
  BodyId b{};
  /// The sub-shapes in touch: a compound's part or a surface's triangle (0 for a whole shape). A
  /// body pair has one contact per pair of sub-shapes, ascending (a, b, sub_a, sub_b).
  std::uint32_t sub_a = 0;
  std::uint32_t sub_b = 0;
  bool touching = false;  ///< had at least one point at the last narrowphase
  bool reported = false;  ///< in touch as contact events report it
  std::uint8_t point_count = 0;
  std::array<ContactPointState, 4> points{};  ///< the first point_count are used

  friend constexpr bool operator==(const ContactState&, const ContactState&) noexcept = default;
};

/// What a query considers: bodies with (layer & filter.mask) != 0 and (filter.layer & mask) != 0,
/// like a body with this layer and mask would. Sensors only when asked for.
struct QueryFilter {
  std::uint32_t layer = 0xFFFFFFFFU;
  std::uint32_t mask = 0xFFFFFFFFU;
  bool include_sensors = false;
  BodyId ignore{};  ///< a body to leave out (a character's or a vehicle's own), or none
};

/// Where a ray met a body.
struct RayHit {
  BodyId body{};
  Vec3 point{};      ///< world space
  Vec3 normal{};     ///< unit surface normal at `point`, against the ray (zero if it starts inside)
  Fixed fraction{};  ///< of the ray's translation, 0 .. 1

  friend constexpr bool operator==(const RayHit&, const RayHit&) noexcept = default;
};

/// Where a moving shape first met a body (World::shape_cast).
struct ShapeHit {
  BodyId body{};
  /// Of the cast's translation, 0 .. 1: the shape placed at position + fraction * translation is
  /// apart from the body by at most the world's linear_slop (and, unless it started so, never
  /// overlaps it).
  Fixed fraction{};
  Vec3 point{};   ///< world space, on the body's surface where the shape met it
  Vec3 normal{};  ///< unit, out of the body towards the shape (against the motion)

  friend constexpr bool operator==(const ShapeHit&, const ShapeHit&) noexcept = default;
};

/// A body in touch with a shape (World::shape_contacts, World::contacts_of): one per touching
/// sub-shape pair, so a body of parts or triangles (a compound, a mesh, a heightfield) may give
/// several, each with its own normal (a stair's tread and riser).
struct ShapeContact {
  BodyId body{};
  std::uint32_t sub_shape = 0;  ///< the body's part or triangle patch (0 for a whole shape)
  /// Unit, out of the body towards the shape: moving the shape by depth * normal separates them.
  Vec3 normal{};
  Fixed depth{};  ///< how far they overlap along the normal, >= 0 (0: the surfaces touch)
  std::uint8_t point_count = 0;  ///< 1 .. 4
  std::array<Vec3, 4> points{};  ///< world space, midway between the surfaces; first point_count

  friend constexpr bool operator==(const ShapeContact&, const ShapeContact&) noexcept = default;
};

/// Where a ray met a particle (World::raycast_particles).
struct ParticleRayHit {
  ParticleGroupId group{};
  std::uint32_t particle = 0;
  Vec3 point{};   ///< world space
  Vec3 normal{};  ///< unit, against the ray (zero if it starts inside the particle's ball)
  Fixed fraction{};

  friend constexpr bool operator==(const ParticleRayHit&, const ParticleRayHit&) noexcept = default;
};

/// A change of touch between two bodies during a step. For a pair of solid bodies, "touching" means
/// that their surfaces are within the world's speculative distance (the contact exists for the
/// solver); for a pair with a sensor, that the shapes overlap.
struct ContactEvent {
  enum class Kind : std::uint8_t { begin = 0, end = 1 };
  Kind kind = Kind::begin;
  BodyId a{};  ///< the lower ID
  BodyId b{};
  bool sensor = false;  ///< a or b is a sensor: an overlap event, no contact response

  friend constexpr bool operator==(const ContactEvent&, const ContactEvent&) noexcept = default;
};

class World {
 public:
  /// A world with the default WorldDef.
  World();
  /// A world from `def`, or an error naming the first invalid field.
  static Expected<World> create(const WorldDef& def);

  World(const World& other);
  World& operator=(const World& other);
  World(World&&) noexcept;
  World& operator=(World&&) noexcept;
  ~World();

  [[nodiscard]] const WorldDef& def() const noexcept;
  /// Steps taken since creation (restored by restore()).
  [[nodiscard]] std::uint64_t frame() const noexcept;

  // ---- Geometry: immutable, registered once, referred to by ID (docs/SIM.md, "Shapes") ----

  /// Registers the convex hull of `points` (body frame, metres): duplicate, coplanar and interior
  /// points are fine, and their order does not matter. Refused, with a message naming what is
  /// wrong: more than 4096 points, a component beyond +-10^4 m, fewer than 4 points that are not
  /// coplanar (a flat or degenerate cloud), or a hull of more than 256 corners.
  Expected<GeometryId> create_convex_hull(std::span<const Vec3> points);
  /// Registers a triangle mesh (body frame, metres) for static bodies (Shape::mesh): `indices`
  /// read as triples into `vertices`, each counter-clockwise seen from the side its normal points
  /// to (a mesh is two-sided: rays hit either side). Degenerate triangles (repeated indices, zero
  /// area, or too small for a reliable normal: every component of twice the area vector below
  /// 2^-24 m^2) are dropped and counted (mesh_dropped_triangles); the others keep
  /// their input order, which is the order of triangle indices. Refused, with a message naming what
  /// is wrong and registering nothing: an index count not divisible by 3; more than 2^20 triangles
  /// or vertices; a vertex component beyond +-10^4 m; an index out of range ("invalid mesh:
  /// triangle 7: index 3 is 12, but there are 10 vertices"); no triangle left.
  Expected<GeometryId> create_mesh(std::span<const Vec3> vertices,
                                   std::span<const std::uint32_t> indices);
  /// Registers a heightfield (HeightfieldDef: a grid of heights in the local x-z plane) for static
  /// bodies (Shape::heightfield). Refused, with a message naming the field and registering
  /// nothing: rows or columns outside 2..4096, a heights count other than rows * columns, a cell
  /// size below 2^-10 m or a grid wider than 10^4 m, a height beyond +-10^4 m.
  Expected<GeometryId> create_heightfield(const HeightfieldDef& def);
  /// How many of the triangles given to create_mesh were dropped as degenerate. Not part of the
  /// content hash: two inputs that differ only by degenerate triangles are the same mesh. An error
  /// for an unknown ID or a geometry that is not a triangle mesh.
  [[nodiscard]] Expected<std::uint32_t> mesh_dropped_triangles(GeometryId id) const;
  /// Registers a compound of `children` (1 to 64): spheres, boxes, capsules, cylinders and convex
  /// hulls of this world, each placed by its position (metres) and unit orientation in the
  /// compound's frame (Shape::compound). The parts must not overlap: mass properties treat the
  /// compound as their sum, one density throughout, so the centre of mass is wherever the parts
  /// put it. Refused, with a message naming the child and what is wrong: no children, more than
  /// 64, a shape that is not one of those (a plane, a mesh, a heightfield, a compound, or an
  /// invalid size or geometry ID), a non-unit orientation, a position component beyond +-10^4 m,
  /// or a volume or moment of inertia per unit mass above the limits (2^31 - 1).
  Expected<GeometryId> create_compound(std::span<const CompoundChild> children);
  /// Registered geometries, 0 .. n-1 being IDs 1 .. n (geometry is never removed).
  [[nodiscard]] std::size_t geometry_count() const noexcept;
  /// The content hash of a geometry (XXH3-64 of its canonical encoding, docs/STATE.md): equal
  /// for equal geometry in any world, on any machine. An error for an unknown ID.
  [[nodiscard]] Expected<std::uint64_t> geometry_hash(GeometryId id) const;
  /// The mass properties that a dynamic body of `shape` and the given mass would have (mass > 0;
  /// the same as detsim::mass_properties for a primitive); an error for an invalid shape.
  [[nodiscard]] Expected<MassProperties> mass_properties(const Shape& shape, Fixed mass) const;

  // ---- Bodies ----

  /// Creates a body; its ID is the next in sequence. An invalid definition (non-positive size or
  /// mass, an orientation that is not a unit quaternion, a non-static plane, a mass, moment of
  /// inertia or other derived quantity that would saturate: docs/SIM.md, "What is refused") is
  /// refused with a message naming the field or quantity, and the world is unchanged.
  Expected<BodyId> create_body(const BodyDef& def);
  /// Removes a body, its contacts and its joints; wakes the bodies it touched or was joined to.
  /// Unknown IDs are an error.
  Status destroy_body(BodyId id);
  [[nodiscard]] bool contains(BodyId id) const noexcept;
  [[nodiscard]] std::size_t body_count() const noexcept;
  /// Every body's ID, ascending.
  [[nodiscard]] std::vector<BodyId> body_ids() const;
  /// A copy of a body's state, or an error for an unknown ID.
  [[nodiscard]] Expected<BodyState> body(BodyId id) const;
  /// What a viewer draws for a body (detsim/sim/shape_outline.hpp) at its current pose: the same
  /// as shape_outline for a primitive, and also for the shapes whose geometry is registered with
  /// the world (convex hulls, meshes, heightfields). An error for an unknown ID.
  [[nodiscard]] Expected<ShapeOutline> body_outline(BodyId id) const;

  /// Switches between kinematic and dynamic (either way, keeping the velocity) or to/from static
  /// (velocity zeroed). A dynamic body gets its mass back from its shape and definition.
  Status set_type(BodyId id, BodyType type);
  /// Teleports a body (orientation must be a unit quaternion). Wakes it.
  Status set_transform(BodyId id, Vec3 position, Quat orientation);
  Status set_linear_velocity(BodyId id, Vec3 velocity);
  Status set_angular_velocity(BodyId id, Vec3 velocity);
  /// Changes a body's user data (BodyDef::user_data: the game's own tag, saved and hashed with
  /// the body, so a game may keep an entity index or a team in it). Does not wake the body.
  Status set_user_data(BodyId id, std::uint64_t user_data);

  // ---- Joints (<detsim/sim/joint.hpp>; docs/SIM.md, "Joints") ----

  /// Creates a joint; its ID is the next in joint sequence. An invalid definition (unknown or
  /// identical bodies, two static bodies, an axis that is not a unit vector, lower > upper,
  /// negative lengths, forces or frequencies) is refused with a message naming the field, and the
  /// world is unchanged. Wakes both bodies.
  Expected<JointId> create_joint(const JointDef& def);
  /// Removes a joint; wakes its bodies. Unknown IDs are an error.
  Status destroy_joint(JointId id);
  /// A copy of a joint's definition and run-time state, or an error for an unknown ID.
  [[nodiscard]] Expected<JointState> joint(JointId id) const;
  /// Every joint's ID, ascending.
  [[nodiscard]] std::vector<JointId> joint_ids() const;
  /// Sets a hinge's or slider's motor: it drives the joint's speed (rad/s about the hinge's axis,
  /// m/s along the slider's) towards `speed` with at most `max_force` (N m, N). The motor is
  /// enabled exactly when max_force > 0 (a motor of no force does nothing: 0 switches it off).
  /// Wakes both bodies. Refused, changing nothing: an unknown ID, a joint type without a motor,
  /// a speed beyond +-2^30 or a max_force below 0 or above 2^31 - 1 (a saturated value).
  Status set_joint_motor(JointId id, Fixed speed, Fixed max_force);
  /// The force and torque the joint applied to body_b in the last step it was solved (the
  /// convention: JointReaction), or an error for an unknown ID.
  [[nodiscard]] Expected<JointReaction> joint_reaction(JointId id) const;
  /// The joint events of the last step (joints that broke), ascending by joint ID, then the
  /// events of the joints that destroy_body calls since have removed, in call order (each call's
  /// ascending). destroy_joint reports nothing: the game asked for it. The next step() starts a
  /// new list; restore() clears it (output, not state, like contact_events()).
  [[nodiscard]] std::span<const JointEvent> joint_events() const noexcept;

  // ---- Particles: ropes, cloth, soft bodies and fluids (docs/PARTICLES.md) ----

  /// Creates a rope (RopeDef); its ID is the next in particle-group sequence. Refused, with a
  /// message naming the field and changing nothing: a value outside its documented range, an
  /// attach body that does not exist, or more particles than max_particles_per_group or (with the
  /// world's other groups) max_particles_per_world, or more than max_particle_groups groups.
  /// Wakes the bodies it is attached to.
  Expected<ParticleGroupId> create_rope(const RopeDef& def);
  /// Creates a sheet of cloth (ClothDef), refused like create_rope (and for a pinned index out of
  /// range or not ascending, or an attach_body with nothing pinned).
  Expected<ParticleGroupId> create_cloth(const ClothDef& def);
  /// Creates a soft body (SoftBodyDef), refused like create_rope (and for a shape that is not a
  /// box or a convex hull of this world, a resolution outside 1..40, cells below 1 cm, or a
  /// shape that holds fewer than two particles along an axis).
  Expected<ParticleGroupId> create_soft_body(const SoftBodyDef& def);
  /// Creates a fluid (FluidDef), refused like create_rope (and for max not above min + spacing
  /// on every axis, a block with room for one particle only, or a particle_radius above the
  /// spacing).
  Expected<ParticleGroupId> create_fluid(const FluidDef& def);
  /// Removes a group; wakes the bodies it was attached to. Unknown IDs are an error.
  Status destroy_particle_group(ParticleGroupId id);
  /// Every group's ID, ascending.
  [[nodiscard]] std::vector<ParticleGroupId> particle_group_ids() const;
  /// A group's particle positions (m) and velocities (m/s), by particle index, or an error for an
  /// unknown ID.
  [[nodiscard]] Expected<std::vector<Vec3>> particle_positions(ParticleGroupId id) const;
  [[nodiscard]] Expected<std::vector<Vec3>> particle_velocities(ParticleGroupId id) const;
  /// The definition a group was created from (attach bodies as given then, even if
  /// destroyed since), or an error for an unknown ID or a group of the other type.
  [[nodiscard]] Expected<RopeDef> rope_def(ParticleGroupId id) const;
  [[nodiscard]] Expected<ClothDef> cloth_def(ParticleGroupId id) const;
  [[nodiscard]] Expected<SoftBodyDef> soft_body_def(ParticleGroupId id) const;
  [[nodiscard]] Expected<FluidDef> fluid_def(ParticleGroupId id) const;
  /// A group's statistics (energy, strain, speed), or an error for an unknown ID.
  [[nodiscard]] Expected<ParticleGroupStats> particle_group_stats(ParticleGroupId id) const;
  /// A force (N, world frame) spread evenly over a group's free particles for the next step (wind,
  /// a push): accumulated like apply_force, cleared by the step. Wakes the group. Refused beyond
  /// +-2^30 N per component (summed), changing nothing.
  Status apply_particle_force(ParticleGroupId id, Vec3 force);

  // ---- Characters: capsules that walk, climb, slide and ride (<detsim/sim/character.hpp>) ----

  /// Creates a character (docs/SIM.md, "Characters"); its ID is the next in character sequence.
  /// Refused, with a message naming the field and changing nothing: a radius outside 2^-10 ..
  /// 100 m, a half_height outside 0 .. 100 m, a max_slope outside (0, pi/2), a step_height below
  /// 0 or not below the character's height, a mass outside (0, 2^31 - 1) kg, a position beyond
  /// +-2^30 m. It may start overlapping bodies: its first step moves it out.
  Expected<CharacterId> create_character(const CharacterDef& def);
  /// Removes a character. Unknown IDs are an error.
  Status destroy_character(CharacterId id);
  /// Sets what the next step applies (CharacterInput). Refused, changing nothing: an unknown ID,
  /// a desired_velocity component or a jump beyond the world's max_linear_speed, a negative jump.
  Status set_character_input(CharacterId id, const CharacterInput& input);
  /// A copy of a character's state, or an error for an unknown ID.
  [[nodiscard]] Expected<CharacterState> character(CharacterId id) const;
  /// Every character's ID, ascending.
  [[nodiscard]] std::vector<CharacterId> character_ids() const;

  // ---- Vehicles: a chassis on wheels, engine, gearbox and tires (<detsim/sim/vehicle.hpp>) ----

  /// Makes the dynamic body def.chassis a vehicle (docs/SIM.md, "Vehicles"); its ID is the next
  /// in vehicle sequence. Refused, with a message naming the field and changing nothing: a chassis
  /// that does not exist, is not dynamic or is already a vehicle's; a count of wheels (1 .. 16),
  /// torque curve points (1 .. 16, ascending rpm), gears (1 .. 8) or axles (0 .. 8) out of range;
  /// a value out of its documented range. Wakes the chassis.
  Expected<VehicleId> create_vehicle(const VehicleDef& def);
  /// Removes a vehicle (its chassis stays, a plain body). Unknown IDs are an error.
  Status destroy_vehicle(VehicleId id);
  /// Sets what the next steps apply (VehicleInput: kept until changed); a change wakes the
  /// chassis. Refused, changing nothing: an unknown ID, a throttle or brake outside 0 .. 1, a
  /// steering outside -1 .. 1.
  Status set_vehicle_input(VehicleId id, const VehicleInput& input);
  /// A copy of a vehicle's state, or an error for an unknown ID.
  [[nodiscard]] Expected<VehicleState> vehicle(VehicleId id) const;
  /// Every vehicle's ID, ascending.
  [[nodiscard]] std::vector<VehicleId> vehicle_ids() const;

  // ---- Game inputs: accumulated until the next step. Each wakes the body. ----
  // A call whose sums, accelerations or resulting velocities would leave the limits of docs/SIM.md
  // ("What is refused") is refused, naming the quantity, and changes nothing.

  Status apply_force(BodyId id, Vec3 force);                       ///< N, at the centre
  Status apply_torque(BodyId id, Vec3 torque);                     ///< N m, world space
  Status apply_force_at_point(BodyId id, Vec3 force, Vec3 point);  ///< point in world space
  Status apply_linear_impulse(BodyId id, Vec3 impulse);            ///< N s, immediate
  Status apply_impulse_at_point(BodyId id, Vec3 impulse, Vec3 point);
  Status apply_angular_impulse(BodyId id, Vec3 impulse);  ///< N m s, immediate
  Status wake(BodyId id);

  // ---- Stepping ----

  /// Advances the world by def().dt.
  void step();

  /// The world's random number generator: the only randomness the simulation (and a game built
  /// on it) should draw. Part of the saved and hashed state.
  [[nodiscard]] Rng& rng() noexcept;
  [[nodiscard]] const Rng& rng() const noexcept;

  /// The contact and sensor events of the last step, ascending by (a, b), then the end events of
  /// the pairs that destroy_body calls since have removed, in call order. A pair changes at most
  /// once per step. The next step() starts a new list; restore() clears it (the events are output,
  /// not state: whether each pair is in touch is state, so a restored world reports exactly what
  /// the original did).
  [[nodiscard]] std::span<const ContactEvent> contact_events() const noexcept;

  // ---- Queries: on the current state, touch nothing, allocate only their result ----

  /// The first body a ray from `origin` along `translation` meets (the lowest fraction; ties go to
  /// the lower ID), or nothing. A ray that starts inside a shape hits it at fraction 0. Shapes are
  /// closed: an origin on a surface is inside. A zero translation is a point: it hits exactly the
  /// shapes that contain it. Long rays do not overflow (up to 10^9 m per component); the hit is
  /// placed within about 2^-32 of the ray's length (~2.4e-4 m for 10^6 m), the resolution of
  /// `fraction` itself.
  [[nodiscard]] std::optional<RayHit> raycast_closest(Vec3 origin, Vec3 translation,
                                                      const QueryFilter& filter = {}) const;
  /// Every body the ray meets, one hit per body (its first), by ascending fraction then ID.
  [[nodiscard]] std::vector<RayHit> raycast_all(Vec3 origin, Vec3 translation,
                                                const QueryFilter& filter = {}) const;
  /// The first particle the ray meets (each a ball of its group's radius; the lowest fraction,
  /// ties to the lower group ID, then the lower index), or nothing: the bodies' raycasts do not
  /// see particles, this one sees only them. Groups are filtered by their settings' layer and
  /// mask like bodies. The same precision and containment rules as raycast_closest.
  [[nodiscard]] std::optional<ParticleRayHit> raycast_particles(
      Vec3 origin, Vec3 translation, const QueryFilter& filter = {}) const;
  /// The IDs, ascending, of the bodies whose shapes overlap `shape` placed at `position` with
  /// `orientation` (a unit quaternion; touching surfaces count as overlapping). A shape that a
  /// dynamic body could not have (a plane, a non-positive size, ...) or an orientation that
  /// create_body would refuse overlaps nothing: the result is empty.
  [[nodiscard]] std::vector<BodyId> overlap(const Shape& shape, Vec3 position, Quat orientation,
                                            const QueryFilter& filter = {}) const;

  /// The first body that `shape`, placed at `position` with `orientation`, meets when moved along
  /// `translation` without turning (the lowest fraction; ties go to the lower ID), or nothing.
  /// What a character or a wheel asks before it moves. Bodies the shape already touches or
  /// overlaps at the start are hit at fraction 0 only where the motion goes deeper into them; a
  /// shape resting on a floor and cast along it meets the walls ahead, not the floor it slides on.
  /// The cast shape is a sphere, box, capsule, cylinder or convex hull (a compound is not cast),
  /// valid by overlap()'s rules; anything else, or a zero translation, meets nothing. It meets
  /// every shape. Against convex bodies it never passes one (docs/SIM.md, "Queries").
  [[nodiscard]] std::optional<ShapeHit> shape_cast(const Shape& shape, Vec3 position,
                                                   Quat orientation, Vec3 translation,
                                                   const QueryFilter& filter = {}) const;
  /// Every body in touch with `shape` placed at `position` with `orientation` (surfaces touching
  /// or overlapping), with the normal, depth and points of each touch, ascending by (body,
  /// sub_shape). The same shape and orientation rules as overlap(): anything else touches nothing.
  [[nodiscard]] std::vector<ShapeContact> shape_contacts(const Shape& shape, Vec3 position,
                                                         Quat orientation,
                                                         const QueryFilter& filter = {}) const;
  /// What touches body `id` now: shape_contacts of its shape at its pose, against the bodies its
  /// layer and mask collide with (sensors and itself left out). The normals point out of each
  /// other body towards this one. An error for an unknown ID.
  [[nodiscard]] Expected<std::vector<ShapeContact>> contacts_of(BodyId id) const;

  // ---- The game's own state (<detsim/sim/game_state.hpp>) ----

  /// Stores the game's own state beside the bodies: 1 .. max_game_state_size bytes in the game's
  /// canonical encoding (fixed byte order, no padding, no pointers, no floating point). It is the
  /// state's "game" section: saved, restored, hashed (its own part hash), compared by diff and
  /// bisect, carried by keyframes and desync reports, so every tool sees it. Set it before the
  /// first step and keep it for the run (a replay lists the sections of frame 0). A world that
  /// never sets it has no such section: its states and hashes are what they were. Refused
  /// (nothing changes): empty, or more than max_game_state_size bytes.
  Status set_game_state(std::span<const std::uint8_t> bytes);
  /// The game state (empty if never set).
  [[nodiscard]] std::span<const std::uint8_t> game_state() const noexcept;
  /// Names fields of the game state for diff and bisect ("score.player1" instead of a byte
  /// range). A description, not state: not saved or hashed, kept by restore() and by copies of
  /// the world (the world a diff restores states into must carry it: the game's own world at
  /// frame 0). Replaces any earlier description. Refused (nothing changes), naming the field: a
  /// bad or repeated name, or a field that ends past max_game_state_size.
  Status describe_game_state(std::span<const GameField> fields);
  /// The description (empty if none).
  [[nodiscard]] std::span<const GameField> game_state_fields() const noexcept;

  // ---- State ----

  /// The complete state in the canonical encoding (docs/STATE.md): versioned, little-endian,
  /// identical on every host.
  [[nodiscard]] std::vector<std::uint8_t> save() const;
  /// Replaces the whole state with `bytes`. Everything is validated first; on any error the world
  /// is untouched and the message names the byte offset and the field.
  Status restore(std::span<const std::uint8_t> bytes);
  /// The hashes of the current state (the per-frame state hash is `hashes().total`).
  [[nodiscard]] StateHashes hashes() const;
  /// save() and hashes() from one encoding: the bytes go to `bytes` (replacing its contents).
  StateHashes save(std::vector<std::uint8_t>& bytes) const;
  /// XXH3-64 of one particle group's record in the "particles" section (as if it were the only
  /// group: its ID step counted from 0), or an error for an unknown ID: what a peer compares to
  /// find which rope or sheet diverged.
  [[nodiscard]] Expected<std::uint64_t> particle_group_hash(ParticleGroupId id) const;
  /// XXH3-64 of one body's canonical bytes, or an error for an unknown ID.
  [[nodiscard]] Expected<std::uint64_t> body_hash(BodyId id) const;
  /// Checks the world's invariants (docs/ARCHITECTURE.md): body IDs ascending and below the next
  /// ID, valid shapes, unit orientations, static bodies asleep, the contact cache ascending and
  /// consistent, joints, characters and vehicles ascending and naming bodies that exist, and
  /// (after a step) islands asleep or awake as a whole. Changes
  /// nothing; an error names what is broken. Builds with DETSIM_CHECKS run it after every step.
  [[nodiscard]] Status validate() const;
  /// The contact cache (part of the saved state), ascending (a, b).
  [[nodiscard]] std::vector<ContactState> contacts() const;

 private:
  friend Status apply_injection(World& world, const Injection& injection);
  friend struct sim_detail::WorldAccess;  // the library's own tools (state_diff.cpp)
  explicit World(std::unique_ptr<sim_detail::WorldState> state) noexcept;
  std::unique_ptr<sim_detail::WorldState> s_;
};

}  // namespace detsim
