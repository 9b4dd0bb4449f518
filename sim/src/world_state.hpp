// The World's state, internal to detsim::sim.
//
// Saved state (everything that affects the future, docs/DETERMINISM.md rule 5): the definition,
// the frame counter, the ID counters, the RNG, the bodies (sorted by ID), the contact cache
// (sorted by ID pair) with its warm-start impulses and the joints (sorted by ID) with theirs.
// Derived data (poses, world-space inverse inertia, bounding boxes, solver scratch) is rebuilt from
// it at the start of every step, so a restored world steps exactly like the one that was saved.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <detsim/core/bytes.hpp>
#include <detsim/fixed/mat3.hpp>
#include <detsim/sim/mass.hpp>
#include <detsim/sim/world.hpp>

#include "collide.hpp"
#include "geometry/geometry.hpp"
#include "particles/group.hpp"

namespace detsim::sim_detail {

/// What a contact point keeps from one step to the next: the feature pair it was made by (to match
/// it with the next step's point) and the accumulated impulses (to warm start with).
struct CachedPoint {
  std::uint32_t feature = 0;
  Fixed normal_impulse;
  Fixed tangent_impulse_1;
  Fixed tangent_impulse_2;

  friend constexpr bool operator==(const CachedPoint&, const CachedPoint&) noexcept = default;
};

/// A pair of bodies whose bounding boxes overlap, a < b, and of their sub-shapes: `sub_a` and
/// `sub_b` name a compound's part or a surface's triangle (0 for a shape that has none), so that a
/// body pair may hold several contacts, each with its own normal (a box on a stair's tread and
/// riser, a chair's four legs). A pair of two whole shapes has exactly one, of sub-shapes (0, 0).
/// Contacts are ordered by (a, b, sub_a, sub_b); the contacts of one body pair are its *group*,
/// and share the pair's `reported` flag. `manifold` is the current geometry
/// (recomputed every step while either body is awake; not saved — a sleeping pair's manifold is
/// recomputed on waking before it is used); `cached` is saved.
struct Contact {
  std::uint32_t a = 0;
  std::uint32_t b = 0;
  std::uint32_t sub_a = 0;
  std::uint32_t sub_b = 0;
  std::uint8_t point_count = 0;  ///< points in `cached` (and in `manifold` after collide)
  bool touching = false;         ///< had at least one point at the last collide
  /// In touch as contact events report it (docs/SIM.md): some point within the speculative
  /// distance, or for a sensor pair, overlapping. A change of it is an event.
  bool reported = false;
  // Step scratch, not saved: the narrowphase ran on the pair this step; the solver pushed on it.
  bool collided = false;
  bool pushed = false;
  /// Step scratch, not saved: where a and b are in WorldState::bodies. Set by the broadphase for
  /// the stages after it, so that they need not search for the IDs; stale between steps (bodies
  /// are created and destroyed), so nothing outside the step reads them.
  std::uint32_t index_a = 0;
  std::uint32_t index_b = 0;
  std::array<CachedPoint, 4> cached{};
  Manifold manifold;
};

/// Whether contact x comes before contact y: ascending (a, b, sub_a, sub_b).
[[nodiscard]] constexpr bool contact_before(const Contact& x, const Contact& y) noexcept {
  if (x.a != y.a) return x.a < y.a;
  if (x.b != y.b) return x.b < y.b;
  if (x.sub_a != y.sub_a) return x.sub_a < y.sub_a;
  return x.sub_b < y.sub_b;
}

/// Per-body data rebuilt at the start of each step (parallel to WorldState::bodies).
struct Derived {
  Pose pose;
  /// The centre of mass in world space (BodyState::world_center): what the solver's lever arms
  /// start from. The sub-steps move it, and the body's position follows from it; for a body whose
  /// centre is its origin (every primitive) it is the position, bit for bit.
  Vec3 center;
  Fixed inverse_mass;
  /// R I^-1 R^T; zero unless dynamic. A locked rotation axis k zeroes row and column k (P I^-1 P
  /// with P the projection on the free axes), so no impulse turns the body about it.
  Mat3 inverse_inertia_world;
  /// BodyState's lock_translation_* of a dynamic body (none otherwise): its rows' linear
  /// responses and shares of effective mass leave the locked world axes out (solver/rows.hpp).
  AxisLocks translation_locks;
  AxisLocks rotation_locks;
  Vec3 aabb_min;
  Vec3 aabb_max;
  bool infinite = false;  ///< a plane: bounded by nothing
  Vec3 start_position;    ///< the pose at the start of the step (for the continuous pass)
  Quat start_orientation;
  /// |angular velocity| * bounding radius: how fast the body's rim moves (for contact margins).
  Fixed rim_speed;
  // Solver scratch for the current step.
  Vec3 delta_position;  ///< since the start of the step
  Vec3 delta_angle;     ///< small-angle sum of angular velocity * h since the start of the step
  Vec3 pushed_out;      ///< how far overlap recovery moved the body this step (part of delta)
};

struct WorldState {
  WorldDef def;
  /// Registered geometry (part of the definition; the "geometry" section lists it by hash).
  GeometryTable geometries;
  /// Geometry this world registered after the state it last restored was saved: not part of the
  /// state (not saved, not hashed), kept so that a later state that names it restores (rollback
  /// restores an earlier frame, then a later one), and reused, not rebuilt, when the same geometry
  /// is registered again in the same place. Registering other geometry drops it.
  GeometryTable retained;
  std::uint64_t frame = 0;
  std::uint32_t next_id = 1;
  Rng rng;
  std::vector<BodyState> bodies;   ///< ascending ID
  std::vector<Contact> contacts;   ///< ascending (a, b)
  std::vector<JointState> joints;  ///< ascending ID
  std::uint32_t next_joint_id = 1;
  std::vector<ParticleGroup> particle_groups;  ///< ascending ID
  std::uint32_t next_particle_group_id = 1;
  std::vector<VehicleState> vehicles;  ///< ascending ID
  std::uint32_t next_vehicle_id = 1;
  std::vector<CharacterState> characters;  ///< ascending ID
  std::uint32_t next_character_id = 1;
  /// The game's own state (World::set_game_state): the "game" section when not empty.
  std::vector<std::uint8_t> game;
  /// Its fields' names for diff (World::describe_game_state): a description, not saved.
  std::vector<GameField> game_fields;
  std::vector<Derived> derived;  ///< rebuilt each step
  /// Step scratch, not saved: where each joint's body_a and body_b are in `bodies` (parallel to
  /// `joints`), set by prepare_bodies for the stages after it so that they need not search for
  /// the IDs every stage and sub-step (the contacts' index_a and index_b, for joints). Stale
  /// between steps (bodies and joints are created and destroyed): nothing outside the step reads
  /// it.
  std::vector<std::array<std::uint32_t, 2>> joint_bodies;
  /// The broadphase's sweep order at the last step (body indices): where the next step's sort
  /// starts. Not saved: the order sorted to is total, so stale or empty content changes nothing
  /// but the time the sort takes.
  std::vector<std::uint32_t> sweep_order;
  /// What the broadphase read of each body at the last step, and the pairs it found then (body
  /// indices, before the joints' and the budget's filters): the next step sweeps only the bodies
  /// whose entry changed and keeps the pairs of the others (broadphase.cpp). Not saved: the pairs
  /// are a function of these entries, so an empty cache (after restore) finds the same ones.
  struct BroadphaseEntry {
    Vec3 min;  ///< the box; a plane's point
    Vec3 max;  ///< the box; a plane's normal
    std::uint32_t id = 0;
    std::uint32_t layer = 0;
    std::uint32_t mask = 0;
    BodyType type = BodyType::static_body;
    bool sensor = false;
    bool infinite = false;
    friend bool operator==(const BroadphaseEntry&, const BroadphaseEntry&) = default;
  };
  std::vector<BroadphaseEntry> broadphase_entries;
  /// Of each body at rest (asleep or static), what its derived data was computed from at the
  /// last step: while they are the same, prepare_bodies keeps the derived data (step.cpp), so
  /// that a sleeping body costs no rotation matrix or box. Not saved, like `derived`.
  struct PreparedFrom {
    Vec3 position;
    Quat orientation;
    Vec3 angular_velocity;
    Vec3 center_of_mass;
    Shape shape;
    std::uint32_t id = 0;  ///< 0: nothing kept
    BodyType type = BodyType::static_body;
    friend bool operator==(const PreparedFrom&, const PreparedFrom&) = default;
  };
  std::vector<PreparedFrom> prepared_from;
  std::vector<std::uint64_t> broadphase_pairs;
  /// Output of the last step (and of destroy_body since); not saved, cleared by restore.
  std::vector<ContactEvent> events;
  /// The same for joints: breaks in the last step, then joints destroy_body removed since.
  std::vector<JointEvent> joint_events;

  /// The geometry a shape of this world refers to (nullptr for the primitives).
  [[nodiscard]] const Geometry* geometry(const Shape& shape) const noexcept {
    return shape_geometry(geometries, shape);
  }
  /// Index of body `id` in `bodies`, or -1.
  [[nodiscard]] std::ptrdiff_t find(std::uint32_t id) const noexcept;
  /// Index of joint `id` in `joints`, or -1.
  [[nodiscard]] std::ptrdiff_t find_joint(std::uint32_t id) const noexcept;
  /// Index of particle group `id` in `particle_groups`, or -1.
  [[nodiscard]] std::ptrdiff_t find_group(std::uint32_t id) const noexcept;
  /// Index of vehicle `id` in `vehicles`, or -1.
  [[nodiscard]] std::ptrdiff_t find_vehicle(std::uint32_t id) const noexcept;
  /// Index of character `id` in `characters`, or -1.
  [[nodiscard]] std::ptrdiff_t find_character(std::uint32_t id) const noexcept;
  /// Particles in every group.
  [[nodiscard]] std::size_t particle_total() const noexcept;
};

/// A World's state, for the library's own code outside World's members that reads what the
/// public API does not show (state_diff.cpp: a particle group's sleep time, force, tether impulse
/// and broken constraints).
struct WorldAccess {
  [[nodiscard]] static const WorldState& of(const World& w) noexcept { return *w.s_; }
};

/// v without its components along the locked axes.
[[nodiscard]] inline Vec3 without_locked(Vec3 v, AxisLocks locks) noexcept {
  return {locks.x ? Fixed::zero() : v.x, locks.y ? Fixed::zero() : v.y,
          locks.z ? Fixed::zero() : v.z};
}

/// Definition checks shared by World::create, create_body and restore. Empty string: valid.
[[nodiscard]] std::string check_world_def(const WorldDef& def);
[[nodiscard]] std::string check_shape(const GeometryTable& geometries, const Shape& shape,
                                      BodyType type);
[[nodiscard]] std::string check_orientation(Quat q);
/// "<what> must be a unit vector ..." unless | |v|^2 - 1 | <= 2^-20 (the orientations' tolerance).
[[nodiscard]] std::string check_unit_vector(const char* what, Vec3 v);
[[nodiscard]] std::string check_body_def(const WorldState& s, const BodyDef& def);
/// A joint definition against the world's bodies (validate.cpp): "" when valid.
[[nodiscard]] std::string check_joint_def(const WorldState& s, const JointDef& def);
/// check_joint_def without "at most one body static": what a saved joint must satisfy (set_type
/// may make both of a joint's bodies static after its creation; the solver skips such a joint).
[[nodiscard]] std::string check_joint_fields(const WorldState& s, const JointDef& def);
/// A motor's speed and max_force (create_joint and set_joint_motor): "" when valid.
[[nodiscard]] std::string check_joint_motor(Fixed speed, Fixed max_force);
/// The limits of limits.hpp for calls: "" when within them, else the refusal's message.
/// Each component of v within +-limit ("<what> x must be within +-limit unit, got v").
[[nodiscard]] std::string check_components(const char* what, Vec3 v, Fixed limit, const char* unit);
[[nodiscard]] std::string check_position(Vec3 p);
/// Components within max_velocity, and the rim speed |w| * bounding radius within max_quantity.
[[nodiscard]] std::string check_angular_velocity(const Shape& shape, const Geometry* g, Vec3 w,
                                                 const char* what);
/// What a dynamic body's mass and moments need beyond being positive: inverses that fit.
[[nodiscard]] std::string check_dynamic_mass(const MassProperties& m);

/// Mass and inertia of a body of this definition (what it has whenever it is dynamic).
[[nodiscard]] MassProperties body_mass(const WorldState& s, const BodyDef& def) noexcept;
/// 1 / x for x > 0, else 0.
[[nodiscard]] Fixed inverse_or_zero(Fixed x) noexcept;

// The step's stages (step.cpp orchestrates them, in this order).
void prepare_bodies(WorldState& s);        // poses, inverse masses, world inertia, bounding boxes
void update_contacts(WorldState& s);       // broadphase: contact list = overlapping pairs, by ID
void collide_contacts(WorldState& s);      // narrowphase: manifolds, warm start matched by feature
void wake_touched_islands(WorldState& s);  // sleeping bodies touched by awake ones wake
void solve(WorldState& s);                 // the sub-stepped solver's stages (solver/solve.cpp)
void continuous(WorldState& s);            // fast and CCD bodies moved back to their first touch
void update_sleep(WorldState& s);          // sleep timers; islands at rest fall asleep
void report_contacts(WorldState& s);       // contact and sensor events, in pair order

/// The world's invariants (invariants.cpp): "" when every one holds, else what is broken.
[[nodiscard]] std::string validate_world(const WorldState& s);
/// validate_world after a step, in builds with DETSIM_CHECKS (nothing in the others).
void check_after_step(const WorldState& s);

/// prepare_bodies for body i alone (derived already sized): when a body wakes in mid-step.
void prepare_body(WorldState& s, std::size_t i);

/// The pairs of bodies that a joint keeps from colliding (unbroken, collide_connected false), as
/// (lower index << 32 | higher index) into `bodies`, ascending (joints.cpp). Empty without joints.
/// Within a step only (it reads joint_bodies).
[[nodiscard]] std::vector<std::uint64_t> joined_pairs(const WorldState& s);
/// Whether (i, j), in either order, is in a list from joined_pairs.
[[nodiscard]] bool is_joined_pair(const std::vector<std::uint64_t>& pairs, std::size_t i,
                                  std::size_t j) noexcept;

/// Removes the joints of body `id`, waking the other body of each and reporting each (a
/// JointEvent::Kind::destroyed, ascending by joint ID) (joints.cpp).
void destroy_joints_of(WorldState& s, BodyId id);

/// The force and torque joint `j` applied to its body b in the last step it was solved, from its
/// accumulated impulses and its bodies' present poses (joint_prepare.cpp; zero when broken).
[[nodiscard]] JointReaction joint_reaction_of(const WorldState& s, const JointState& j);

/// Detaches every particle attached to body `id` (the particle goes free; its group wakes)
/// (particles/api.cpp).
void detach_particles_of(WorldState& s, BodyId id);

/// Wakes the islands of the bodies at these indices (a character pushed them after the solver):
/// every dynamic body of each, so that islands stay asleep or awake as a whole (contacts.cpp).
void wake_islands(WorldState& s, const std::vector<std::size_t>& bodies);

/// Moves every character (character.cpp): after the bodies, against their new poses.
void move_characters(WorldState& s);
/// Removes the vehicles whose chassis is body `id` (being destroyed) and forgets it as a wheel's
/// ground (vehicles.cpp).
void forget_vehicles_of(WorldState& s, BodyId id);
/// Characters standing on body `id` (being destroyed) stand on nothing until their next step.
void forget_ground(WorldState& s, BodyId id);
/// What a saved character must satisfy (character.cpp): "" when it does.
[[nodiscard]] std::string check_character_record(const WorldState& s, const CharacterState& c);

/// Appends the end event of a contact that is reported as touching (a pair that stops existing).
void report_end(WorldState& s, const Contact& c);

/// Canonical bytes (state_io.cpp). write_body writes a body on its own: its property set, then its
/// record as if it were the only body (what body_hash hashes).
void write_globals(const WorldState& s, ByteWriter& w);
void write_body(const BodyState& b, ByteWriter& w);
void write_contact(const Contact& c, std::uint32_t previous_a, ByteWriter& w);

}  // namespace detsim::sim_detail
