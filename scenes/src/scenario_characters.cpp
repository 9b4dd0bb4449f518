// The characters scene: character controllers (World::create_character) walking, jumping, climbing
// stairs, keeping off a slope too steep to walk, riding a sliding and a turning platform and
// pushing crates in a walled yard, their inputs drawn from the world's RNG each second.
#include <cstdint>
#include <vector>

#include <detsim/fixed/math.hpp>
#include <detsim/fixed/quat.hpp>

#include "scenario_scenes.hpp"

namespace detsim::scenes_detail {

namespace {

using namespace characters;

BodyDef solid(Shape shape, Vec3 position, Quat orientation = {}) {
  BodyDef d;
  d.type = BodyType::static_body;
  d.shape = shape;
  d.position = position;
  d.orientation = orientation;
  return d;
}

const Vec3 kY{0_fx, 1_fx, 0_fx};
const Vec3 kZ{0_fx, 0_fx, 1_fx};

// A ramp of `angle` whose top face rises towards +x from (x0, 0, z) over `run` metres of x.
void add_ramp(World& w, Fixed x0, Fixed z, Fixed angle, Fixed run) {
  const SinCos sc = sincos(angle);
  const Fixed slope_length = run / sc.cos;
  const Fixed half_thick = 0.25_fx;
  // The top face's centre, then the box's centre a half thickness below it along the normal.
  const Vec3 top{x0 + run / 2_fx, run * sc.sin / sc.cos / 2_fx, z};
  const Vec3 normal{-sc.sin, sc.cos, 0_fx};
  add(w, solid(Shape::box({slope_length / 2_fx, half_thick, 1.5_fx}), top - normal * half_thick,
               from_axis_angle(kZ, angle)));
}

/// Where character k of `count` starts: the first eight at the yard's features, the rest on a
/// grid around the middle, 5 m up (they fall to whatever is below).
Vec3 start_of(std::uint32_t k) {
  const Vec3 features[8] = {
      {2_fx, 1.5_fx, stairs_z},             // at the foot of the stairs
      {-3_fx, 1.5_fx, ramp_z},              // at the foot of the walkable ramp
      {-3_fx, 1.5_fx, steep_z},             // at the foot of the steep one
      {slide_at.x, 2_fx, slide_at.z},       // on the sliding platform
      {spin_at.x + 1_fx, 2_fx, spin_at.z},  // on the turning platform, off its axis
      {1_fx, 1.5_fx, crates_z},             // behind the crates
      {0_fx, 1.5_fx, 0_fx},
      {-1.5_fx, 1.5_fx, 1.5_fx},
  };
  if (k < 8) return features[k];
  const std::int32_t i = static_cast<std::int32_t>(k - 8);
  return {Fixed::from_int(i % 10) * 1.2_fx - 5.4_fx, 5_fx,
          Fixed::from_int(i / 10) * 1.2_fx - 5.4_fx};
}

}  // namespace

void build_characters(World& w, const ScenarioParams& p) {
  // The yard: a floor and four walls.
  BodyDef floor = solid(Shape::plane(), {});
  (void)add(w, floor);
  const Fixed wall_half = 0.25_fx;
  for (const Vec3 at : {Vec3{yard + wall_half, 1_fx, 0_fx}, Vec3{-yard - wall_half, 1_fx, 0_fx}})
    (void)add(w, solid(Shape::box({wall_half, 1_fx, yard}), at));
  for (const Vec3 at : {Vec3{0_fx, 1_fx, yard + wall_half}, Vec3{0_fx, 1_fx, -yard - wall_half}})
    (void)add(w, solid(Shape::box({yard, 1_fx, wall_half}), at));
  // Stairs up towards +x from x = 3, and a landing at their top.
  for (std::int32_t i = 0; i < stair_count; ++i) {
    const Fixed height = stair_rise * Fixed::from_int(i + 1);
    const Fixed x = 3_fx + stair_run * Fixed::from_int(i) + stair_run / 2_fx;
    (void)add(w, solid(Shape::box({stair_run / 2_fx, height / 2_fx, 1.5_fx}),
                       {x, height / 2_fx, stairs_z}));
  }
  const Fixed top = stair_rise * Fixed::from_int(stair_count);
  const Fixed landing_x = 3_fx + stair_run * Fixed::from_int(stair_count) + 1_fx;
  (void)add(w, solid(Shape::box({1_fx, top / 2_fx, 1.5_fx}), {landing_x, top / 2_fx, stairs_z}));
  // A ramp it may walk and one it may not, both rising towards +x from x = -2.
  add_ramp(w, -2_fx, ramp_z, walkable_slope, 3_fx);
  add_ramp(w, -2_fx, steep_z, steep_slope, 2_fx);
  // Two kinematic platforms: one sliding back and forth along x (control_characters), one turning.
  BodyDef slide = solid(Shape::box({1.5_fx, platform_half_thickness, 1.5_fx}), slide_at);
  slide.type = BodyType::kinematic;
  slide.user_data = platform_tag;
  (void)add(w, slide);
  BodyDef spin = solid(Shape::box({2_fx, platform_half_thickness, 2_fx}), spin_at);
  spin.type = BodyType::kinematic;
  spin.angular_velocity = kY * spin_rate;
  (void)add(w, spin);
  // Crates to push.
  for (std::int32_t i = 0; i < 4; ++i) {
    BodyDef crate;
    crate.shape = Shape::box({crate_half, crate_half, crate_half});
    crate.position = {2.5_fx + Fixed::from_int(i) * 1.2_fx, crate_half, crates_z};
    crate.mass = crate_mass;
    crate.user_data = crate_tag;
    (void)add(w, crate);
  }
  const std::uint32_t count = p.count;
  for (std::uint32_t k = 0; k < count; ++k) {
    CharacterDef c;
    c.position = start_of(k);
    c.user_data = player_tag + k;
    (void)w.create_character(c).value();
  }
}

void control_characters(World& w, std::span<const PlayerInput>, const ScenarioParams&) {
  const std::uint64_t frame = w.frame();
  const bool forward = (frame / slide_period) % 2 == 0;
  for (const BodyId id : w.body_ids()) {
    if (w.body(id)->user_data == platform_tag)
      (void)w.set_linear_velocity(id, {forward ? slide_speed : -slide_speed, 0_fx, 0_fx});
  }
  // Each character chooses anew once a second, its own frame in the second: a direction and a
  // speed, and sometimes a jump when it stands. Drawn in statement order from the world's RNG.
  Rng& rng = w.rng();
  for (const CharacterId id : w.character_ids()) {
    if ((frame + 7 * id.value) % 60 != 0) continue;
    const CharacterState c = w.character(id).value();
    const Fixed angle = rng.uniform(Fixed::zero(), Fixed::two_pi());
    const Fixed speed = rng.uniform(0.5_fx, max_walk_speed);
    const bool jump = rng.uniform(Fixed::zero(), Fixed::one()) < 0.25_fx && c.grounded;
    const SinCos sc = sincos(angle);
    (void)w.set_character_input(
        id, {{sc.cos * speed, 0_fx, sc.sin * speed}, jump ? jump_speed : Fixed::zero()});
  }
}

}  // namespace detsim::scenes_detail
