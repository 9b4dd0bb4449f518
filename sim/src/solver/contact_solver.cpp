// Contacts, the first constraint kind: soft contacts of the sub-stepped solver ("soft step",
// Catto, Box2D v3, 2024) in 3D. solve.cpp runs the stages; this file is what each stage does to
// contacts.
//
// Contacts are not re-collided between sub-steps: each point keeps its anchors relative to the two
// bodies (in its rows), and its separation is updated from the bodies' motion since the start of
// the step (with a small-angle rotation), which is exact for translation and second-order small
// for rotation. Soft constraints act like a damped spring with a stiffness tied to the sub-step
// rate rather than an iteration count, so stacks neither jitter nor explode, and a restitution-1
// bounce loses almost nothing. Every constraint is solved in contact order (ascending ID pair),
// point order within a contact: the order is part of the result.
//
// Under abuse the spring alone gives way: a load of thousands of times a body's weight pressed
// it through the floor, and overlap pushed apart at contact_push_max per contact added up to tens
// of metres per second among hundreds of overlapping bodies. So the spring has a range, the
// speculative distance below the surface: a point may approach no faster than what stops it at
// the end of that range within the sub-step (hard_stop), and overlap beyond the range is not
// pushed by velocity at all but by push_out, on velocities that move the positions and are then
// dropped. Ordinary contacts never leave the range and behave as the plain soft step.
//
// Each point has three rows (the normal and two tangents, rows.hpp), each with its Jacobian per
// body, computed once per step because the anchors and the world inertia stay fixed for the step.
// The two friction rows of a point are pushed together. The sub-steps then need no cross product
// and no matrix.
#include "contact_solver.hpp"

#include <algorithm>

namespace detsim::sim_detail {

namespace {

// A unit vector perpendicular to the unit vector n, chosen by n's components only.
Vec3 perpendicular(Vec3 n) {
  const Fixed threshold = Fixed::from_raw(2479700525);  // 0.57735 ~ 1/sqrt(3)
  if (abs(n.x) >= threshold) return normalize(Vec3{n.y, -n.x, Fixed::zero()});
  return normalize(Vec3{Fixed::zero(), n.z, -n.y});
}

}  // namespace

namespace {

// The normal row at the centroid of a constraint's points. A row is linear in its anchor (d x r),
// and so is its response (I^-1 (d x r)): the centroid's are the means of the points' rows, which
// costs additions instead of the cross products and matrix products of make_row. The effective
// mass follows from them as in make_row.
[[gnu::noinline]] Row centroid_row(const ContactConstraint& k, const Derived& a, const Derived& b) {
  if (k.count == 1) return k.points[0].normal;
  // 1 / count: exact for 2 and 4, rounded once for 3.
  const Fixed share = Fixed::one() / Fixed::from_int(k.count);
  Row r;
  for (std::size_t p = 0; p < k.count; ++p) {
    const Row& pr = k.points[p].normal;
    r.angular_a += pr.angular_a;
    r.angular_b += pr.angular_b;
    r.response_a += pr.response_a;
    r.response_b += pr.response_b;
  }
  r.angular_a = r.angular_a * share;
  r.angular_b = r.angular_b * share;
  r.response_a = r.response_a * share;
  r.response_b = r.response_b * share;
  const Fixed angular =
      DotSum{}.add(r.response_a, r.angular_a).add(r.response_b, r.angular_b).result();
  const Vec3 n = k.normal.linear_b;
  r.mass = inverse_or_zero(linear_share(a, n) + linear_share(b, n) + angular);
  return r;
}

}  // namespace

ContactSolver::ContactSolver(WorldState& s, SolverBodies& bodies) : s_(s), bodies_(bodies) {
  // The contact spring may not be stiffer than a quarter of the sub-step rate (Box2D's bound),
  // or the implicit discretisation stops damping it.
  const Fixed hertz = min(s.def.contact_hertz, bodies.inv_h >> 2);
  soft_ = make_soft(hertz, s.def.contact_damping_ratio, bodies.h);
  static_soft_ =
      make_soft(min(hertz << 1, bodies.inv_h >> 2), s.def.contact_damping_ratio, bodies.h);
}

// Every separation starts at its base (no motion yet).
void ContactSolver::prepare() {
  constraints_.clear();
  // At most one constraint per contact: reserved at once, the constraints are never moved while
  // the list grows (each is about 1.5 KB).
  constraints_.reserve(s_.contacts.size());
  for (std::size_t ci = 0; ci < s_.contacts.size(); ++ci) {
    const Contact& c = s_.contacts[ci];
    if (c.point_count == 0) continue;
    const BodyState& a = s_.bodies[c.index_a];
    const BodyState& b = s_.bodies[c.index_b];
    if (a.sensor || b.sensor) continue;
    const bool dynamic_a = a.type == BodyType::dynamic && a.awake;
    const bool dynamic_b = b.type == BodyType::dynamic && b.awake;
    if (!dynamic_a && !dynamic_b) continue;
    prepare_constraint(ci);
  }
  prepare_levels();
}

void ContactSolver::prepare_constraint(std::size_t ci) {
  const Contact& c = s_.contacts[ci];
  const std::size_t ia = c.index_a;
  const std::size_t ib = c.index_b;
  const BodyState& a = s_.bodies[ia];
  const BodyState& b = s_.bodies[ib];
  const Derived& da = s_.derived[ia];
  const Derived& db = s_.derived[ib];
  // Built in place: a constraint is about 1.5 KB, and a copy per contact per step is waste.
  ContactConstraint& k = constraints_.emplace_back();
  k.contact = ci;
  k.bodies = bodies_.pair(ia, ib);
  const Vec3 normal = c.manifold.normal;
  const Vec3 tangent_1 = perpendicular(normal);
  const Vec3 tangent_2 = cross(normal, tangent_1);
  k.normal = make_direction(da, db, normal);
  k.tangent_1 = make_direction(da, db, tangent_1);
  k.tangent_2 = make_direction(da, db, tangent_2);
  k.friction = sqrt(a.friction * b.friction);
  k.restitution = max(a.restitution, b.restitution);
  k.count = c.point_count;
  k.pushed = false;
  k.bounced = false;
  k.loaded = false;
  for (std::size_t p = 0; p < c.point_count; ++p) {
    const ContactPoint& mp = c.manifold.points[p];
    SolverPoint& sp = k.points[p];
    // The contact point relative to each body's centre of mass at the start of the step.
    const Vec3 anchor_a = mp.point - da.center;
    const Vec3 anchor_b = mp.point - db.center;
    sp.base_separation = mp.separation;
    sp.separation = mp.separation;
    sp.normal = make_row(da, db, anchor_a, anchor_b, normal);
    sp.tangent_1 = make_row(da, db, anchor_a, anchor_b, tangent_1);
    sp.tangent_2 = make_row(da, db, anchor_a, anchor_b, tangent_2);
    sp.normal_impulse = c.cached[p].normal_impulse;
    k.loaded = k.loaded || sp.normal_impulse > Fixed::zero();
    sp.tangent_impulse_1 = c.cached[p].tangent_impulse_1;
    sp.tangent_impulse_2 = c.cached[p].tangent_impulse_2;
  }
  k.centroid = {};
  // The centroid's row: restitution's, and the whole manifold's first push (solve_centre, which
  // makes it when it first needs it: most resting manifolds never do).
  k.centroid_ready = k.restitution != Fixed::zero();
  if (k.centroid_ready) k.centroid.normal = centroid_row(k, da, db);
  if (k.restitution != Fixed::zero())
    k.centroid.relative_velocity =
        row_speed(bodies_.velocities, k.bodies, k.normal, k.centroid.normal);
  bodies_.in_contact[ia] = true;
  bodies_.in_contact[ib] = true;
}

void ContactSolver::warm_start() {
  for (ContactConstraint& k : constraints_) {
    for (std::size_t p = 0; p < k.count; ++p) {
      SolverPoint& sp = k.points[p];
      sp.push_impulse = Fixed::zero();
      // A point whose surfaces have come apart (a bounce, a body lifted off) carries no load:
      // re-applying its old impulse would push the bodies apart a second time and feed energy
      // into whatever else they touch before this point's own solve takes it back.
      if (sp.separation > Fixed::zero()) {
        sp.normal_impulse = Fixed::zero();
        sp.tangent_impulse_1 = Fixed::zero();
        sp.tangent_impulse_2 = Fixed::zero();
        continue;
      }
      apply_impulse(bodies_.velocities, k.bodies, k.normal, sp.normal, sp.normal_impulse);
      apply_impulses(bodies_.velocities, k.bodies, k.tangent_1, sp.tangent_1, sp.tangent_impulse_1,
                     k.tangent_2, sp.tangent_2, sp.tangent_impulse_2);
    }
  }
}

// The normal rows of a contact's points, in point order. `inline`, like the row helpers: it runs
// per contact per pass, and the hint keeps it inside solve_contacts' loop, where it was written
// before the contact kind had a file of its own.
inline void ContactSolver::solve_normal(ContactConstraint& k, const Softness& soft, bool use_bias) {
  const Fixed depth = s_.def.speculative_distance;
  for (std::size_t p = 0; p < k.count; ++p) {
    SolverPoint& sp = k.points[p];
    const Fixed separation = sp.separation;
    Fixed bias;
    bool soft_push = false;  // soft: mass and impulse scaled; else scales 1 and 0
    if (separation > Fixed::zero()) {
      bias = separation * bodies_.inv_h;  // speculative: close the gap within this sub-step
    } else if (use_bias && separation >= -depth) {
      // Overlap within the soft range: a damped spring pushes it apart (and gives a little under
      // load). Deeper, the point is rigid (bias zero): the bodies may not approach at all, and
      // push_out moves the excess apart without velocity.
      bias = max(soft.bias_rate * min(separation + s_.def.linear_slop, Fixed::zero()),
                 -s_.def.contact_push_max);
      soft_push = true;
    }
    const Fixed vn = row_speed(bodies_.velocities, k.bodies, k.normal, sp.normal);
    // Scales 1 and 0 need no arithmetic: x * 1 = x and x - 0 * y = x, bit for bit.
    Fixed impulse = soft_push ? -sp.normal.mass * soft.mass_scale * (vn + bias) -
                                    soft.impulse_scale * sp.normal_impulse
                              : -sp.normal.mass * (vn + bias);
    // The spring has a hard stop at the end of its range: at least the impulse that stops the
    // point there within this sub-step, whatever presses the bodies together.
    if (soft_push)
      impulse = max(impulse, -sp.normal.mass * (vn + hard_stop(separation) * bodies_.inv_h));
    const Fixed accumulated = max(sp.normal_impulse + impulse, Fixed::zero());
    impulse = accumulated - sp.normal_impulse;
    sp.normal_impulse = accumulated;
    if (impulse > Fixed::zero()) k.pushed = true;
    apply_impulse(bodies_.velocities, k.bodies, k.normal, sp.normal, impulse);
  }
}

inline const Softness& ContactSolver::softness(const ContactConstraint& k) const {
  const bool against_static = s_.derived[k.bodies.a].inverse_mass == Fixed::zero() ||
                              s_.derived[k.bodies.b].inverse_mass == Fixed::zero();
  return against_static ? static_soft_ : soft_;
}

// How far a point at `separation` may still close within a sub-step: to the surface when apart
// (a speculative contact), to the end of the soft range (the speculative distance) when
// overlapping within it, not at all beyond.
inline Fixed ContactSolver::hard_stop(Fixed separation) const {
  if (separation > Fixed::zero()) return separation;
  return max(separation + s_.def.speculative_distance, Fixed::zero());
}

// The manifold as one: before its points, an impulse at the centroid of its points stops the
// centroid's approach (up to the smallest gap, which a speculative contact may close), booked in
// equal shares to the points, whose own rows then correct the rest. Solved one after another
// alone, the first point of a face takes the whole load and turns the body, which the next
// points must undo: with the few passes of a sub-step, a box pressed onto a floor by a huge force
// kept turning into it, and a box hitting a wall face-on left spinning. The shares are the
// points' accumulated impulses, so the solution is the same problem's, reached from a better
// start. Only a push is applied here: taking load off is left to each point's own row.
inline void ContactSolver::solve_centre(ContactConstraint& k) {
  if (k.count < 2) return;
  // A manifold that carried load in the last step and whose points all overlap within the soft
  // range is resting: its springs share the load point by point, its warm start already holds
  // it, and the centroid would only cost time. A new one (a body arriving) is not.
  const Fixed depth = -s_.def.speculative_distance;
  Fixed gap = k.points[0].separation;
  bool resting = true;
  for (std::size_t p = 0; p < k.count; ++p) {
    const Fixed separation = k.points[p].separation;
    gap = min(gap, separation);
    resting = resting && separation <= Fixed::zero() && separation >= depth;
  }
  if (resting && k.loaded) return;
  if (!k.centroid_ready) {
    k.centroid.normal = centroid_row(k, s_.derived[k.bodies.a], s_.derived[k.bodies.b]);
    k.centroid_ready = true;
  }
  const Fixed bias = hard_stop(gap) * bodies_.inv_h;
  const Fixed vn = row_speed(bodies_.velocities, k.bodies, k.normal, k.centroid.normal);
  // Only an approach that would cross the whole soft range within the sub-step: slower ones
  // (bodies landing on a pile) are the springs' to take, point by point, as they always were.
  if (vn + s_.def.speculative_distance * bodies_.inv_h >= Fixed::zero()) return;
  const Fixed impulse = -k.centroid.normal.mass * (vn + bias);
  if (impulse <= Fixed::zero()) return;
  const Fixed share = impulse / Fixed::from_int(k.count);
  for (std::size_t p = 0; p < k.count; ++p)
    k.points[p].normal_impulse += share;
  k.pushed = true;
  apply_impulse(bodies_.velocities, k.bodies, k.normal, k.centroid.normal,
                share * Fixed::from_int(k.count));
}

// Coulomb friction, each point limited to the disc of radius friction * normal impulse.
inline void ContactSolver::solve_friction(ContactConstraint& k) {
  for (std::size_t p = 0; p < k.count; ++p) {
    SolverPoint& sp = k.points[p];
    const Fixed limit = k.friction * sp.normal_impulse;
    // With a zero limit the clamp below gives zero whatever t1 and t2 are (0 / |t| = 0, and
    // |t| = 0 only for t = 0): a point with no friction impulse keeps none.
    if (limit == Fixed::zero() && sp.tangent_impulse_1 == Fixed::zero() &&
        sp.tangent_impulse_2 == Fixed::zero())
      continue;
    const Fixed t1 =
        sp.tangent_impulse_1 -
        sp.tangent_1.mass * row_speed(bodies_.velocities, k.bodies, k.tangent_1, sp.tangent_1);
    const Fixed t2 =
        sp.tangent_impulse_2 -
        sp.tangent_2.mass * row_speed(bodies_.velocities, k.bodies, k.tangent_2, sp.tangent_2);
    Fixed n1 = t1;
    Fixed n2 = t2;
    if (hypot_exceeds(t1, t2, limit)) {  // hypot(t1, t2) > limit, most often false: no root
      const Fixed scale = limit / hypot(t1, t2);
      n1 = t1 * scale;
      n2 = t2 * scale;
    }
    const Fixed impulse_1 = n1 - sp.tangent_impulse_1;
    const Fixed impulse_2 = n2 - sp.tangent_impulse_2;
    sp.tangent_impulse_1 = n1;
    sp.tangent_impulse_2 = n2;
    apply_impulses(bodies_.velocities, k.bodies, k.tangent_1, sp.tangent_1, impulse_1, k.tangent_2,
                   sp.tangent_2, impulse_2);
  }
}

void ContactSolver::solve() {
  solve_contacts(true);
}

// Overlap recovery beyond the soft range (split impulses, as in Bullet's split impulse and Jolt's
// position iterations): each point overlapping by more than the range (the speculative distance)
// asks its bodies' push-out velocities to separate at the spring's rate times the excess
// (contact_hertz and the damping ratio, stiffer against static bodies), up to contact_push_max.
// The push-out velocities move the positions in integrate_positions and are then dropped:
// recovery never adds kinetic energy, however many overlaps a body has. Within the range the
// soft spring's own bias pushes, as before.
void ContactSolver::push_out() {
  const Fixed depth = s_.def.speculative_distance;
  const Fixed push_max = s_.def.contact_push_max;
  for (ContactConstraint& k : constraints_) {
    const Fixed rate = softness(k).bias_rate;
    for (std::size_t p = 0; p < k.count; ++p) {
      SolverPoint& sp = k.points[p];
      const Fixed overlap = -(sp.separation + depth);  // beyond the soft range
      if (overlap <= Fixed::zero() && sp.push_impulse == Fixed::zero()) continue;
      const Fixed target = min(rate * max(overlap, Fixed::zero()), push_max);
      const Fixed vn = row_speed(bodies_.push, k.bodies, k.normal, sp.normal);
      const Fixed impulse = sp.normal.mass * (target - vn);
      const Fixed accumulated = max(sp.push_impulse + impulse, Fixed::zero());
      apply_impulse(bodies_.push, k.bodies, k.normal, sp.normal, accumulated - sp.push_impulse);
      sp.push_impulse = accumulated;
    }
  }
}

void ContactSolver::relax() {
  solve_contacts(false);
}

void ContactSolver::solve_contacts(bool first_pass) {
  for (ContactConstraint& k : constraints_) {
    // Until the contact first pushes, its approach speed (at the centroid, before any point is
    // solved) is what restitution must reverse.
    if (first_pass && !k.pushed && k.restitution != Fixed::zero())
      k.centroid.relative_velocity =
          row_speed(bodies_.velocities, k.bodies, k.normal, k.centroid.normal);
    solve_centre(k);
    solve_normal(k, softness(k), first_pass);
    solve_friction(k);
  }
}

// Where the surfaces of a point are now, from the manifold and the motion since the step began:
// the separation grows at the normal row's speed, so it has grown by the row's Jacobian times
// the bodies' displacements (delta position, small-angle delta rotation), one exact sum rounded
// once. A still body has not moved (integrate_positions never moves it) and adds exact zeros.
inline Fixed ContactSolver::current_separation(const ContactConstraint& k,
                                               const SolverPoint& sp) const {
  DotSum moved;
  if (!k.bodies.still_a) {
    const Derived& da = s_.derived[k.bodies.a];
    moved.add(k.normal.linear_a, da.delta_position).add(sp.normal.angular_a, da.delta_angle);
  }
  if (!k.bodies.still_b) {
    const Derived& db = s_.derived[k.bodies.b];
    moved.add(k.normal.linear_b, db.delta_position).add(sp.normal.angular_b, db.delta_angle);
  }
  return sp.base_separation + moved.result();
}

// The separations depend only on the bodies' motion since the start of the step, which only
// integrate_positions changes: computed once after it (and set to their base in prepare), they
// serve the warm start, the solve and the relaxation that follow.
void ContactSolver::positions_moved() {
  for (ContactConstraint& k : constraints_) {
    for (std::size_t p = 0; p < k.count; ++p)
      k.points[p].separation = current_separation(k, k.points[p]);
  }
}

// Restitution acts once per contact, at the centroid of its points, reversing the centroid's
// approach speed: one Newton impulse at one point conserves energy for e = 1, whereas
// per-point impulses applied one after another over-shoot on a rotating body and can add energy.
void ContactSolver::restitution() {
  const Fixed threshold = s_.def.restitution_threshold;
  for (ContactConstraint& k : constraints_) {
    if (k.restitution == Fixed::zero() || k.bounced || !k.pushed) continue;
    const Centroid& c = k.centroid;
    if (c.relative_velocity > -threshold) continue;
    k.bounced = true;
    const Fixed vn = row_speed(bodies_.velocities, k.bodies, k.normal, c.normal);
    const Fixed impulse = -c.normal.mass * (vn + k.restitution * c.relative_velocity);
    if (impulse > Fixed::zero())
      apply_impulse(bodies_.velocities, k.bodies, k.normal, c.normal, impulse);
  }
}

void ContactSolver::store_impulses() {
  for (const ContactConstraint& k : constraints_) {
    Contact& c = s_.contacts[k.contact];
    c.pushed = k.pushed;
    for (std::size_t p = 0; p < k.count; ++p) {
      c.cached[p].normal_impulse = k.points[p].normal_impulse;
      c.cached[p].tangent_impulse_1 = k.points[p].tangent_impulse_1;
      c.cached[p].tangent_impulse_2 = k.points[p].tangent_impulse_2;
    }
  }
}

}  // namespace detsim::sim_detail
