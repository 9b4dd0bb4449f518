// The scenes with particles: rope_bridge (planks hung on ropes between two posts), flag (cloth on
// a pole in RNG gusts of wind), drape (cloth falling over a sphere and a box), jelly (soft cubes
// down stairs), dam_break (a block of water released in a tank with an obstacle) and
// wrecking_rope (a heavy ball on a rope swinging into boxes).
#include <algorithm>
#include <cstdint>
#include <vector>

#include <detsim/fixed/math.hpp>
#include <detsim/fixed/quat.hpp>

#include "scenario_scenes.hpp"

namespace detsim::scenes_detail {

namespace {

// Particle groups are part of a scenario's definition: a refusal is a bug here.
ParticleGroupId rope(World& w, const RopeDef& def) {
  return w.create_rope(def).value();
}

void ground(World& w) {
  add(w, {.type = BodyType::static_body, .shape = Shape::plane(), .friction = 0.6_fx});
}

BodyId fixed_box(World& w, Vec3 half, Vec3 at) {
  return add(w, {.type = BodyType::static_body, .shape = Shape::box(half), .position = at});
}

Fixed fx(std::uint32_t n) {
  return Fixed::from_int(static_cast<std::int32_t>(n));
}

}  // namespace

// ---- rope_bridge ----

void build_rope_bridge(World& w, const ScenarioParams& p) {
  using namespace rope_bridge;
  ground(w);
  // Two posts; N planks across the gap between them, each hung from its neighbours (or a post)
  // by two short ropes, one at each side: the ropes run from post to post through the planks.
  const Fixed span = (plank_width + gap) * fx(p.count) + gap;
  const Fixed left = -span / 2_fx;
  const BodyId left_post =
      fixed_box(w, {0.2_fx, height / 2_fx, 1_fx}, {left - 0.2_fx, height / 2_fx, 0_fx});
  const BodyId right_post =
      fixed_box(w, {0.2_fx, height / 2_fx, 1_fx}, {-left + 0.2_fx, height / 2_fx, 0_fx});
  BodyId previous = left_post;
  Fixed previous_edge = left;
  for (std::uint32_t i = 0; i <= p.count; ++i) {
    BodyId next = right_post;
    Fixed next_edge = -left;
    if (i < p.count) {
      const Fixed x = previous_edge + gap + plank_width / 2_fx;
      next = add(w, {.shape = Shape::box({plank_width / 2_fx, 0.03_fx, 0.8_fx}),
                     .position = {x, height, 0_fx},
                     .mass = plank_mass,
                     .friction = 0.6_fx,
                     .linear_damping = plank_damping,
                     .angular_damping = plank_damping});
      next_edge = x - plank_width / 2_fx;
    }
    for (const Fixed z : {-side_z, side_z}) {
      rope(w, {.start = {previous_edge, height, z},
               .end = {next_edge, height, z},
               .segments = 4,
               .length = gap * slack,
               .mass = 0.05_fx,
               .radius = 0.02_fx,
               .attach_start = previous,
               .attach_end = next,
               .settings = {.damping = 0.5_fx, .mask = 0}});
    }
    previous = next;
    previous_edge = next_edge + plank_width;
  }
  // Three crates dropped onto the deck.
  for (std::int32_t k = -1; k <= 1; ++k) {
    add(w, {.shape = Shape::box({0.2_fx, 0.2_fx, 0.2_fx}),
            .position = {Fixed::from_int(k) * span / 4_fx, height + 1_fx, 0_fx},
            .mass = crate_mass,
            .user_data = crate_tag});
  }
}

// ---- flag ----

void build_flag(World& w, const ScenarioParams&) {
  using namespace flag;
  ground(w);
  add(w, {.type = BodyType::static_body,
          .shape = Shape::capsule(0.05_fx, pole_height / 2_fx),
          .position = {0_fx, pole_height / 2_fx, 0_fx}});
  // The sheet hangs from the pole's top along +x, its left column pinned to the pole.
  ClothDef cloth;
  cloth.origin = {0.06_fx, pole_height - height, 0_fx};
  cloth.axis_u = {width, 0_fx, 0_fx};
  cloth.axis_v = {0_fx, height, 0_fx};
  cloth.columns = columns;
  cloth.rows = rows;
  cloth.mass = 0.5_fx;
  cloth.thickness = 0.02_fx;
  cloth.settings.damping = 0.2_fx;
  for (std::uint32_t r = 0; r < rows; ++r)
    cloth.pinned.push_back(r * columns);
  (void)w.create_cloth(cloth).value();
}

void control_flag(World& w, std::span<const PlayerInput>, const ScenarioParams&) {
  // Wind along +x with gusts: the RNG draws each frame's strength and sideways part, so that the
  // sheet lifts and flutters (a force on the whole sheet, spread over its particles).
  Rng& rng = w.rng();
  const Fixed strength = rng.uniform(flag::wind_min, flag::wind_max);
  const Fixed side = rng.uniform(-flag::wind_side, flag::wind_side);
  for (const ParticleGroupId id : w.particle_group_ids())
    (void)w.apply_particle_force(id, {strength, 0_fx, side});
}

// ---- drape ----

void build_drape(World& w, const ScenarioParams& p) {
  using namespace drape;
  ground(w);
  add(w, {.type = BodyType::static_body,
          .shape = Shape::sphere(sphere_radius),
          .position = sphere_at});
  fixed_box(w, box_half, box_at);
  ClothDef cloth;
  cloth.origin = {-size / 2_fx, drop_height, -size / 2_fx};
  cloth.axis_u = {size, 0_fx, 0_fx};
  cloth.axis_v = {0_fx, 0_fx, size};
  // A sheet needs two particles a side: a count of 1 makes the smallest sheet.
  cloth.columns = std::max<std::uint32_t>(p.count, 2);
  cloth.rows = cloth.columns;
  cloth.mass = 1_fx;
  cloth.thickness = 0.04_fx;
  cloth.settings.friction = 0.6_fx;
  cloth.settings.damping = 1_fx;
  (void)w.create_cloth(cloth).value();
}

// ---- jelly ----

void build_jelly(World& w, const ScenarioParams& p) {
  using namespace jelly;
  ground(w);
  // A flight of stairs down towards +x, its top step at x = 0.
  for (std::int32_t k = 0; k < steps; ++k) {
    const Fixed top = rise * Fixed::from_int(steps - k);
    fixed_box(w, {run / 2_fx, top / 2_fx, width / 2_fx},
              {run * Fixed::from_int(k) + run / 2_fx, top / 2_fx, 0_fx});
  }
  // The cubes drop in a row across the top step, each a little further down the stairs and
  // turned a little more than the last, and slide and tumble down.
  const Fixed top = rise * Fixed::from_int(steps);
  for (std::uint32_t i = 0; i < p.count; ++i) {
    const Fixed f = fx(i);
    SoftBodyDef cube;
    cube.shape = Shape::box({half, half, half});
    cube.position = {run / 2_fx + f * 0.05_fx, top + 0.6_fx + f * 0.1_fx,
                     (f - fx(p.count - 1) / 2_fx) * (half * 2_fx + 0.1_fx)};
    cube.orientation = from_axis_angle({0_fx, 0_fx, 1_fx}, 0.3_fx + f * 0.1_fx);
    cube.resolution = resolution;
    cube.mass = mass;
    cube.edge_compliance = edge_compliance;
    cube.settings.damping = 1_fx;
    cube.settings.friction = 0.3_fx;
    (void)w.create_soft_body(cube).value();
  }
}

// ---- dam_break ----

void build_dam_break(World& w, const ScenarioParams& p) {
  using namespace dam_break;
  // Martin and Moyce's column (1952): a block of water a wide and 2a high (here as deep as it is
  // high) at one end of a tank, released at once. a = count spacings.
  const Fixed a = spacing * fx(p.count);
  const Fixed length = a * Fixed::from_int(tank_length);
  const Fixed depth = a * 2_fx;
  const Fixed height = a * 2_fx;
  // The tank: a floor and four walls (static boxes), inside [0, length] x [0, ...) x [0, depth].
  fixed_box(w, {length / 2_fx + wall * 2_fx, wall, depth / 2_fx + wall * 2_fx},
            {length / 2_fx, -wall, depth / 2_fx});
  for (const Fixed x : {-wall, length + wall})
    fixed_box(w, {wall, height, depth / 2_fx + wall * 2_fx}, {x, height, depth / 2_fx});
  for (const Fixed z : {-wall, depth + wall})
    fixed_box(w, {length / 2_fx, height, wall}, {length / 2_fx, height, z});
  // The obstacle, in the middle of the tank's width, a block width beyond the dam.
  fixed_box(w, obstacle_half, {a * 2_fx + obstacle_half.x, obstacle_half.y, depth / 2_fx});
  FluidDef water;
  water.min = {};
  water.max = {a, height, depth};
  water.spacing = spacing;
  water.particle_radius = spacing / 2_fx;
  water.rest_density = 1000_fx;
  water.viscosity = 0.01_fx;
  water.settings.substeps = 2;
  (void)w.create_fluid(water).value();
}

// ---- wrecking_rope ----

void build_wrecking_rope(World& w, const ScenarioParams&) {
  using namespace wrecking_rope;
  ground(w);
  const BodyId beam = fixed_box(w, {0.2_fx, 0.2_fx, 0.2_fx}, pivot + Vec3{0_fx, 0.2_fx, 0_fx});
  // The ball starts level with the pivot, the rope straight and taut along -x.
  const Vec3 start = pivot + Vec3{-length, 0_fx, 0_fx};
  const BodyId ball = add(w, {.shape = Shape::sphere(ball_radius),
                              .position = start + Vec3{-ball_radius, 0_fx, 0_fx},
                              .mass = ball_mass,
                              .user_data = ball_tag});
  rope(w, {.start = pivot,
           .end = start,
           .segments = segments,
           .mass = 2_fx,
           .radius = 0.03_fx,
           .attach_start = beam,
           .attach_end = ball,
           .settings = {.damping = 0.1_fx}});
  // A stack of boxes where the ball passes its lowest point.
  for (std::int32_t level = 0; level < 5; ++level) {
    for (std::int32_t k = -1; k <= 1; ++k) {
      add(w, {.shape = Shape::box({0.25_fx, 0.25_fx, 0.25_fx}),
              .position = {pivot.x + 1_fx, 0.25_fx + Fixed::from_int(level) * 0.5_fx,
                           Fixed::from_int(k) * 0.55_fx},
              .mass = 5_fx,
              .user_data = crate_tag});
    }
  }
}

}  // namespace detsim::scenes_detail
