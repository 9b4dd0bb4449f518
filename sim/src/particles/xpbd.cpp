// XPBD for particle groups, inside the solver's sub-steps (xpbd.hpp; docs/PARTICLES.md).
//
// Every loop runs in ascending group, particle, link, tether and contact order, with Fixed
// arithmetic only. One pass per small step: there is no accumulated lambda to keep, so a group's
// whole state is its positions and velocities (Macklin et al. 2019, "small steps": one iteration
// of many sub-steps converges better than many iterations of one).
#include "xpbd.hpp"

#include <algorithm>

#include <detsim/fixed/math.hpp>

#include "../collide.hpp"

namespace detsim::sim_detail {

namespace {

bool filters_pass(const ParticleSettings& p, const BodyState& b) {
  return (p.layer & b.mask) != 0 && (b.layer & p.mask) != 0 && !b.sensor;
}

bool overlaps(Vec3 min_a, Vec3 max_a, const Derived& d) {
  if (d.infinite) return true;
  return min_a.x <= d.aabb_max.x && d.aabb_min.x <= max_a.x && min_a.y <= d.aabb_max.y &&
         d.aabb_min.y <= max_a.y && min_a.z <= d.aabb_max.z && d.aabb_min.z <= max_a.z;
}

// Whether the particles' pushes move body b (a dynamic body, awake): else it is a fixed or
// kinematic thing the particles follow and rest on.
bool takes_pushes(const BodyState& b) {
  return b.type == BodyType::dynamic && b.awake;
}

// How far a particle or body may travel in a step, beyond where it is: what the group's box and
// the contacts' margin cover.
Fixed travel(const WorldState& s, Fixed speed) {
  return (speed + length(s.def.gravity) * s.def.dt) * s.def.dt;
}

Fixed max_speed(const ParticleGroup& g) {
  Fixed v2;
  for (const Vec3& v : g.velocities)
    v2 = max(v2, length_squared(v));
  return sqrt(v2);
}

}  // namespace

void prepare_particles(WorldState& s) {
  for (ParticleGroup& g : s.particle_groups) {
    g.near_bodies.clear();
    Vec3 lo = g.positions.front();
    Vec3 hi = lo;
    for (const Vec3& p : g.positions) {
      lo = {min(lo.x, p.x), min(lo.y, p.y), min(lo.z, p.z)};
      hi = {max(hi.x, p.x), max(hi.y, p.y), max(hi.z, p.z)};
    }
    const Fixed reach =
        g.radius + s.def.speculative_distance + (g.awake ? travel(s, max_speed(g)) : Fixed::zero());
    const Vec3 r{reach, reach, reach};
    lo -= r;
    hi += r;
    const ParticleSettings& settings = g.settings();
    for (std::size_t i = 0; i < s.bodies.size(); ++i) {
      const BodyState& b = s.bodies[i];
      if (filters_pass(settings, b) && overlaps(lo, hi, s.derived[i]))
        g.near_bodies.push_back(static_cast<std::uint32_t>(i));
    }
    // A moving body near a sleeping group, or attached to it, wakes it.
    const auto moves = [&](const BodyState& b) {
      return b.type != BodyType::static_body && b.awake &&
             (b.type == BodyType::dynamic || b.linear_velocity != Vec3{} ||
              b.angular_velocity != Vec3{});
    };
    if (!g.awake) {
      bool wake = g.force != Vec3{};
      for (std::uint32_t i : g.near_bodies)
        wake = wake || moves(s.bodies[i]);
      for (const Attachment& a : g.attachments)
        wake = wake || moves(s.bodies[static_cast<std::size_t>(s.find(a.body))]);
      if (!wake) continue;
      g.awake = true;
      g.sleep_time = Fixed::zero();
    }
    // An awake group wakes the sleeping dynamic bodies near it and those it is attached to; the
    // wake stage then wakes their islands.
    const auto wake_body = [&](std::size_t i) {
      BodyState& b = s.bodies[i];
      if (b.type != BodyType::dynamic || b.awake) return;
      b.awake = true;
      b.sleep_time = Fixed::zero();
      prepare_body(s, i);
    };
    for (std::uint32_t i : g.near_bodies)
      wake_body(i);
    for (const Attachment& a : g.attachments)
      wake_body(static_cast<std::size_t>(s.find(a.body)));
  }
}

std::vector<bool> bodies_held_by_particles(const WorldState& s) {
  std::vector<bool> held(s.bodies.size(), false);
  for (const ParticleGroup& g : s.particle_groups) {
    if (!g.awake || g.sleep_time >= s.def.time_to_sleep) continue;
    for (std::uint32_t i : g.near_bodies)
      held[i] = true;
    for (const Attachment& a : g.attachments)
      held[static_cast<std::size_t>(s.find(a.body))] = true;
  }
  return held;
}

void update_particle_sleep(WorldState& s) {
  const Fixed limit2 = s.def.sleep_linear_speed * s.def.sleep_linear_speed;
  for (ParticleGroup& g : s.particle_groups) {
    g.force = {};
    if (!g.awake) continue;
    // At rest when the particles' mean square speed is below the bodies' sleep speed squared:
    // a few particles of a sheet folded over an edge keep a flutter of a few mm/s that a
    // per-particle test would never let sleep (docs/PARTICLES.md, "Not there yet").
    Fixed v2_sum;
    for (const Vec3& v : g.velocities)
      v2_sum += length_squared(v);
    const Fixed mean_v2 = v2_sum / Fixed::from_int(static_cast<std::int32_t>(g.size()));
    g.sleep_time =
        mean_v2 <= limit2 ? min(g.sleep_time + s.def.dt, Fixed::from_int(1000)) : Fixed::zero();
    if (!s.def.enable_sleep || g.sleep_time < s.def.time_to_sleep) continue;
    bool bodies_rest = true;
    for (std::uint32_t i : g.near_bodies)
      bodies_rest = bodies_rest && !takes_pushes(s.bodies[i]);
    for (const Attachment& a : g.attachments) {
      const BodyState& b = s.bodies[static_cast<std::size_t>(s.find(a.body))];
      bodies_rest = bodies_rest && b.awake == false;
      bodies_rest = bodies_rest && (b.type != BodyType::kinematic ||
                                    (b.linear_velocity == Vec3{} && b.angular_velocity == Vec3{}));
    }
    if (!bodies_rest) continue;
    g.awake = false;
    for (Vec3& v : g.velocities)
      v = {};
  }
}

ParticleStepper::ParticleStepper(WorldState& s, SolverBodies& bodies) : s_(s), bodies_(bodies) {}

void ParticleStepper::prepare() {
  scratch_.resize(s_.particle_groups.size());
  if (s_.particle_groups.empty()) return;
  pushes_.assign(s_.bodies.size(), Velocity{});
  for (std::size_t k = 0; k < s_.particle_groups.size(); ++k) {
    ParticleGroup& g = s_.particle_groups[k];
    if (g.awake) prepare_group(g, scratch_[k]);
  }
}

void ParticleStepper::prepare_group(ParticleGroup& g, GroupScratch& sc) {
  sc.contacts.clear();
  sc.attached_body.clear();
  for (const Attachment& a : g.attachments)
    sc.attached_body.push_back(static_cast<std::uint32_t>(s_.find(a.body)));
  // A tether holds while its anchor cannot be moved by the particles: pinned in space, or attached
  // to a body that is not dynamic.
  std::vector<bool> held(g.size(), false);
  for (std::uint32_t i = 0; i < g.size(); ++i)
    held[i] = is_pinned(g, i);
  for (std::size_t k = 0; k < g.attachments.size(); ++k)
    held[g.attachments[k].particle] = s_.bodies[sc.attached_body[k]].type != BodyType::dynamic;
  sc.tether_active.resize(g.tethers.size());
  for (std::size_t k = 0; k < g.tethers.size(); ++k)
    sc.tether_active[k] = held[g.tethers[k].anchor];
  // A rope attached to two bodies holds them through its tether row (solver/tether_solver.hpp):
  // that row is the rope's tension between them, so its links do not pull them as well.
  sc.tethered = false;
  if (g.type == ParticleGroupType::rope && g.attachments.size() == 2 &&
      sc.attached_body[0] != sc.attached_body[1]) {
    sc.tethered = takes_pushes(s_.bodies[sc.attached_body[0]]) ||
                  takes_pushes(s_.bodies[sc.attached_body[1]]);
  }
  sc.previous.resize(g.size());
  sc.target_from.resize(g.attachments.size());
  sc.targets.resize(g.attachments.size());
  // Which particles the group's constraints cannot move (pinned, or following a body), and each
  // link's 1 / (w_a + w_b + compliance / h^2): constant through the step (the small step's h is).
  sc.fixed.assign(g.size(), false);
  sc.attachment_of.assign(g.size(), -1);
  for (std::size_t k = 0; k < g.attachments.size(); ++k) {
    sc.fixed[g.attachments[k].particle] = true;
    sc.attachment_of[g.attachments[k].particle] = static_cast<std::int32_t>(k);
  }
  sc.free_count = 0;
  for (std::uint32_t i = 0; i < g.size(); ++i) {
    if (is_pinned(g, i)) sc.fixed[i] = true;
    sc.free_count += sc.fixed[i] ? 0 : 1;
  }
  sc.h = bodies_.h / Fixed::from_int(static_cast<std::int32_t>(g.settings().substeps));
  sc.inv_h = Fixed::one() / sc.h;
  const Fixed inv_h2 = sc.inv_h * sc.inv_h;
  sc.volume_compliance = Fixed::zero();
  if (const auto* soft = std::get_if<SoftBodyDef>(&g.def))
    sc.volume_compliance = soft->volume_compliance * inv_h2;
  sc.link_factor.resize(g.links.size());
  Fixed last_compliance = Fixed::min();
  Fixed scaled;
  for (std::size_t k = 0; k < g.links.size(); ++k) {
    const Link& l = g.links[k];
    if (l.compliance != last_compliance) {  // links come in runs of one compliance
      last_compliance = l.compliance;
      scaled = l.compliance * inv_h2;
    }
    const Fixed denominator = (sc.fixed[l.a] ? Fixed::zero() : g.inverse_mass) +
                              (sc.fixed[l.b] ? Fixed::zero() : g.inverse_mass) + scaled;
    sc.link_factor[k] = denominator == Fixed::zero() ? Fixed::zero() : Fixed::one() / denominator;
  }

  // Contact planes: each particle, as a ball of the group's radius, against each near body whose
  // box its own box meets, with a margin that covers the step's relative motion.
  const Shape ball = Shape::sphere(g.radius);
  const Fixed wall_reach = g.type == ParticleGroupType::fluid
                               ? max(g.kernel_radius - g.radius, Fixed::zero())
                               : Fixed::zero();
  const Fixed friction = g.settings().friction;
  std::vector<SubManifold> found;
  // What each near body contributes to every test, computed once.
  struct Near {
    std::uint32_t index;
    const Geometry* geometry;
    Fixed speed;
    Mat3 to_local;
    Fixed friction;
  };
  std::vector<Near> near;
  near.reserve(g.near_bodies.size());
  for (std::uint32_t bi : g.near_bodies) {
    const BodyState& b = s_.bodies[bi];
    const Derived& d = s_.derived[bi];
    near.push_back({bi, s_.geometry(b.shape), length(b.linear_velocity) + d.rim_speed,
                    transpose(d.pose.rotation), sqrt(friction * b.friction)});
  }
  // Ascending particle, then body, then sub-shape (collide_all's order): the order they are
  // solved in.
  for (std::uint32_t i = 0; i < g.size(); ++i) {
    const Vec3 p = g.positions[i];
    const Fixed own_speed = length(g.velocities[i]);
    for (const Near& n : near) {
      const BodyState& b = s_.bodies[n.index];
      const Derived& d = s_.derived[n.index];
      // A fluid's particles feel walls within its kernel's reach (fluid.hpp).
      const Fixed margin =
          s_.def.speculative_distance + travel(s_, own_speed + n.speed) + wall_reach;
      const Fixed reach = g.radius + margin;
      if (!overlaps(p - Vec3{reach, reach, reach}, p + Vec3{reach, reach, reach}, d)) continue;
      const Pose at{p, Mat3::identity()};
      collide_all(PosedShape{ball, nullptr, at}, PosedShape{b.shape, n.geometry, d.pose}, margin,
                  found);
      for (const SubManifold& m : found) {
        // The deepest point; the normal points from the particle into the body.
        std::uint8_t deepest = 0;
        for (std::uint8_t k = 1; k < m.manifold.count; ++k) {
          if (m.manifold.points[k].separation < m.manifold.points[deepest].separation) deepest = k;
        }
        const ContactPoint& cp = m.manifold.points[deepest];
        const Vec3 surface = cp.point + m.manifold.normal * (cp.separation * Fixed::half());
        ParticleContact c;
        c.particle = i;
        c.body = n.index;
        c.local_normal = n.to_local * -m.manifold.normal;
        c.local_point = n.to_local * (surface - b.position);
        c.friction = n.friction;
        sc.contacts.push_back(c);
      }
    }
  }
  // Bodies the particles push move by plain semi-implicit Euler, as bodies in contact do.
  for (const ParticleContact& c : sc.contacts)
    bodies_.in_contact[c.body] = true;
  for (std::uint32_t bi : sc.attached_body)
    bodies_.in_contact[bi] = true;
}

void ParticleStepper::substep() {
  for (std::size_t k = 0; k < s_.particle_groups.size(); ++k) {
    ParticleGroup& g = s_.particle_groups[k];
    if (g.awake) step_group(g, scratch_[k]);
  }
  apply_pushes();
}

void ParticleStepper::push_body(std::uint32_t i, Vec3 impulse, Vec3 point) {
  Velocity& p = pushes_[i];
  if (p.linear == Vec3{} && p.angular == Vec3{}) pushed_.push_back(i);
  p.linear += impulse;
  p.angular += cross(point - s_.derived[i].center, impulse);
}

void ParticleStepper::apply_pushes() {
  for (std::uint32_t i : pushed_) {
    const Derived& d = s_.derived[i];
    Velocity& v = bodies_.velocities[i];
    v.linear += without_locked(pushes_[i].linear, d.translation_locks) * d.inverse_mass;
    v.angular += d.inverse_inertia_world * pushes_[i].angular;
    pushes_[i] = {};
  }
  pushed_.clear();
}

void ParticleStepper::step_group(ParticleGroup& g, GroupScratch& sc) {
  const ParticleSettings& settings = g.settings();
  const std::uint32_t small_steps = settings.substeps;
  const Fixed h = sc.h;
  const Fixed inv_h = sc.inv_h;
  const Fixed w = g.inverse_mass;
  const Fixed drag = Fixed::one() / (Fixed::one() + h * settings.damping);
  const Fixed tear = [&] {
    if (const auto* cloth = std::get_if<ClothDef>(&g.def)) return cloth->tear_strain;
    return Fixed::zero();
  }();
  const std::vector<bool>& fixed_particle = sc.fixed;
  const Fixed push_step = s_.def.contact_push_max * h;

  // Where each attached particle's body puts it now (the bodies moved in this sub-step); the
  // small steps move it there in equal parts.
  for (std::size_t k = 0; k < g.attachments.size(); ++k) {
    const Attachment& a = g.attachments[k];
    const BodyState& b = s_.bodies[sc.attached_body[k]];
    sc.targets[k] = b.position + rotate(b.orientation, a.local);
    sc.target_from[k] = g.positions[a.particle];
  }
  // The group's force is spread over its free particles.
  const Vec3 kick =
      (s_.def.gravity + (sc.free_count > 0
                             ? g.force / (g.particle_mass * Fixed::from_int(sc.free_count))
                             : Vec3{})) *
      h;
  // What a link pushes on an attached particle goes to its body.
  const auto pull_attached = [&](std::uint32_t i, Vec3 impulse) {
    const std::int32_t k = sc.attachment_of[i];
    if (k < 0 || sc.tethered) return;
    const std::uint32_t bi = sc.attached_body[static_cast<std::size_t>(k)];
    if (takes_pushes(s_.bodies[bi])) push_body(bi, impulse, g.positions[i]);
  };

  // The contact planes at the bodies' present poses.
  for (ParticleContact& c : sc.contacts) {
    const BodyState& b = s_.bodies[c.body];
    c.normal = rotate(b.orientation, c.local_normal);
    c.point = b.position + rotate(b.orientation, c.local_point);
  }

  // A fluid's neighbours, once per sub-step, within the kernel's reach and a skin of a quarter
  // spacing that covers the particles' usual motion in its small steps.
  const auto* fluid = std::get_if<FluidDef>(&g.def);
  const Fixed fluid_skin = g.kernel_radius / Fixed::from_int(8);
  if (fluid != nullptr) {
    find_fluid_pairs(g.positions, g.kernel_radius + fluid_skin, sc.fluid);
    build_fluid_neighbours(g.size(), sc.fluid);
    // Its walls: the contact planes, particle by particle.
    FluidScratch& f = sc.fluid;
    f.wall_start.assign(g.size() + 1, 0);
    f.walls.clear();
    for (const ParticleContact& c : sc.contacts) {
      ++f.wall_start[c.particle + 1];
      f.walls.push_back({c.normal, c.point, c.body, Vec3{}, Vec3{}});
    }
    for (std::size_t i = 0; i < g.size(); ++i)
      f.wall_start[i + 1] += f.wall_start[i];
  }

  for (std::uint32_t step = 0; step < small_steps; ++step) {
    // Predict: free particles move by their velocity after gravity, forces and damping; attached
    // ones by their body's motion.
    for (std::uint32_t i = 0; i < g.size(); ++i) {
      sc.previous[i] = g.positions[i];
      if (fixed_particle[i]) continue;
      g.velocities[i] = limit_speed((g.velocities[i] + kick) * drag, s_.def.max_linear_speed);
      g.positions[i] += g.velocities[i] * h;
    }
    const Fixed part = Fixed::from_int(static_cast<std::int32_t>(step + 1)) /
                       Fixed::from_int(static_cast<std::int32_t>(small_steps));
    for (std::size_t k = 0; k < g.attachments.size(); ++k)
      g.positions[g.attachments[k].particle] =
          sc.target_from[k] + (sc.targets[k] - sc.target_from[k]) * part;

    // A fluid's density constraints: one Gauss-Seidel pass (fluid.hpp).
    if (fluid != nullptr) solve_fluid_density(g, sc.fluid, sc.previous, h, push_step);

    // Distance links: lambda = -C / (w_a + w_b + compliance / h^2), one pass, no accumulation.
    // With n = delta / |delta|, x_a -= w_a lambda n and x_b += w_b lambda n are the link's delta
    // times w * C / (|delta| * denominator): one reciprocal square root and no division per link.
    for (std::size_t k = 0; k < g.links.size(); ++k) {
      if (g.link_broken[k]) continue;
      const Link& l = g.links[k];
      const Vec3 delta = g.positions[l.b] - g.positions[l.a];
      const Fixed d2 = length_squared(delta);
      if (d2 == Fixed::zero()) continue;  // no direction to push in
      const Fixed inverse = rsqrt(d2);
      const Fixed c = d2 * inverse - l.rest;
      if (l.kind == LinkKind::rope && c <= Fixed::zero()) continue;  // a rope is never pushed
      if (tear > Fixed::zero() && c > l.rest * tear) {
        g.link_broken[k] = true;
        g.broken.insert(
            std::lower_bound(g.broken.begin(), g.broken.end(), static_cast<std::uint32_t>(k)),
            static_cast<std::uint32_t>(k));
        continue;
      }
      const Fixed scale = c * inverse * sc.link_factor[k];
      if (!fixed_particle[l.a])
        g.positions[l.a] += delta * (w * scale);
      else
        pull_attached(l.a, delta * (scale * inv_h));
      if (!fixed_particle[l.b])
        g.positions[l.b] -= delta * (w * scale);
      else
        pull_attached(l.b, -delta * (scale * inv_h));
    }

    // Volumes (Macklin et al. 2016's tetrahedral volume constraint): C = (x1 - x0) . g1 - C0
    // with g1 = (x2 - x0) x (x3 - x0) (six times the signed volume), gradients g0..g3,
    // lambda = -C / (sum w |g_i|^2 + compliance / h^2).
    for (const Tetrahedron& t : g.tetrahedra) {
      const auto& c = t.corners;
      const Vec3 x0 = g.positions[c[0]];
      const Vec3 e1 = g.positions[c[1]] - x0;
      const Vec3 e2 = g.positions[c[2]] - x0;
      const Vec3 e3 = g.positions[c[3]] - x0;
      const Vec3 g1 = cross(e2, e3);
      const Vec3 g2 = cross(e3, e1);
      const Vec3 g3 = cross(e1, e2);
      const Vec3 g0 = -(g1 + g2 + g3);
      const Fixed violation = dot(e1, g1) - t.rest_triple;
      if (violation == Fixed::zero()) continue;
      const Fixed denominator =
          w * (length_squared(g0) + length_squared(g1) + length_squared(g2) + length_squared(g3)) +
          sc.volume_compliance;
      if (denominator == Fixed::zero()) continue;
      const Fixed lambda = -violation / denominator;
      const Fixed move = w * lambda;
      g.positions[c[0]] += g0 * move;
      g.positions[c[1]] += g1 * move;
      g.positions[c[2]] += g2 * move;
      g.positions[c[3]] += g3 * move;
    }

    // Long-range tethers: only pull, only the free particle moves.
    for (std::size_t k = 0; k < g.tethers.size(); ++k) {
      if (!sc.tether_active[k]) continue;
      const Tether& t = g.tethers[k];
      if (fixed_particle[t.particle]) continue;
      const Vec3 delta = g.positions[t.particle] - g.positions[t.anchor];
      const Fixed d2 = length_squared(delta);
      if (d2 <= t.max * t.max) continue;
      const Fixed dist = sqrt(d2);
      g.positions[t.particle] -= delta * ((dist - t.max) / dist);
    }

    // Contacts: out of each body's surface, with Coulomb friction on the step's slide (Macklin et
    // al. 2014, section 6.1); what moved the particle pushes the body back.
    for (const ParticleContact& c : sc.contacts) {
      if (fixed_particle[c.particle]) continue;
      Vec3& x = g.positions[c.particle];
      Fixed depth = g.radius - dot(x - c.point, c.normal);
      if (depth <= Fixed::zero()) continue;
      // What the small step's own motion pushed in is undone at once; an overlap the particle
      // already had (created inside a body, or pushed in by its neighbours) comes out at most at
      // the bodies' contact_push_max, so that a body made inside another is not torn apart by
      // particles leaving through different faces.
      // The push-out moves the particle's start of step with it: it is a correction of where
      // the particle is, not a velocity (as the bodies' push-out velocities are dropped), or a
      // particle deep in a body would gain contact_push_max every small step it spends coming
      // out.
      const Fixed before_step = g.radius - dot(sc.previous[c.particle] - c.point, c.normal);
      Fixed position_only;
      if (before_step > Fixed::zero()) {
        const Fixed made = max(depth - before_step, Fixed::zero());
        depth = min(depth, made + push_step);
        position_only = depth - made;
        sc.previous[c.particle] += c.normal * position_only;
      }
      const Vec3 before = x;
      x += c.normal * depth;
      const BodyState& b = s_.bodies[c.body];
      const bool pushes = takes_pushes(b);
      Vec3 body_move;
      if (b.type != BodyType::static_body && b.awake) {
        const Velocity& v = bodies_.velocities[c.body];
        body_move = (v.linear + cross(v.angular, c.point - s_.derived[c.body].center)) * h;
      }
      const Vec3 slide = (x - sc.previous[c.particle]) - body_move;
      const Vec3 tangent = slide - c.normal * dot(slide, c.normal);
      const Fixed t = length(tangent);
      if (t > Fixed::zero()) {
        const Fixed limit = c.friction * depth;
        x -= t <= limit ? tangent : tangent * (limit / t);
      }
      // The body takes the particle's change of momentum (not its correction of position).
      if (pushes)
        push_body(c.body, (before + c.normal * position_only - x) * (g.particle_mass * inv_h),
                  c.point);
    }

    // Velocities from the positions.
    for (std::uint32_t i = 0; i < g.size(); ++i) {
      if (is_pinned(g, i)) continue;
      g.velocities[i] =
          limit_speed((g.positions[i] - sc.previous[i]) * inv_h, s_.def.max_linear_speed);
    }
    if (fluid != nullptr) apply_fluid_viscosity(g, sc.fluid, fluid->viscosity);
  }
  // The walls' share of the fluid's pressure pushes their bodies back, as the contacts do.
  if (fluid != nullptr) {
    const Fixed impulse = g.particle_mass * inv_h;
    for (std::uint32_t i = 0; i < g.size(); ++i) {
      for (std::uint32_t k = sc.fluid.wall_start[i]; k < sc.fluid.wall_start[i + 1]; ++k) {
        const FluidWall& wall = sc.fluid.walls[k];
        if (wall.moved != Vec3{} && takes_pushes(s_.bodies[wall.body]))
          push_body(wall.body, -wall.moved * impulse, g.positions[i] - wall.normal * g.radius);
      }
    }
  }
}

}  // namespace detsim::sim_detail
