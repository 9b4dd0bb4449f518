// The contact solver: sub-stepped soft constraints ("soft step", Catto, Box2D v3, 2024) in 3D.
//
// Per step, for each of `substeps` sub-steps of length h = dt / substeps:
//   integrate velocities (gravity, forces, damping, speed clamp) -> warm start (apply the
//   accumulated impulses) -> solve (soft contacts with a position bias) -> integrate positions ->
//   relax (the same constraints without bias, removing the velocity the bias added);
// then restitution for the points that took their first impulse in that sub-step (each point
// bounces once per step, in the sub-step where it hit, so a bouncing body moves away for the rest
// of the step instead of resting on the surface until the step ends); and once per step the
// impulses are stored for the next step's warm start.
//
// Contacts are not re-collided between sub-steps: each point keeps its anchors relative to the two
// bodies, and its separation is updated from the bodies' motion since the start of the step (with
// a small-angle rotation), which is exact for translation and second-order small for rotation.
// Soft constraints act like a damped spring with a stiffness tied to the sub-step rate rather than
// an iteration count, so stacks neither jitter nor explode, and a restitution-1 bounce loses
// almost nothing. Every constraint is solved in contact order (ascending ID pair), point order
// within a contact: the order is part of the result.
#include <algorithm>
#include <vector>

#include <detsim/fixed/decimal.hpp>
#include <detsim/fixed/math.hpp>

#include "world_state.hpp"

namespace detsim::sim_detail {

using namespace detsim::literals;

namespace {

struct SolverPoint {
  Vec3 anchor_a;  // contact point relative to each body's centre at the start of the step
  Vec3 anchor_b;
  Fixed base_separation;
  Fixed separation;  // current_separation at the bodies' present motion (refresh_separations)
  Fixed normal_mass;
  Fixed tangent_mass_1;
  Fixed tangent_mass_2;
  Fixed relative_velocity;  // normal approach speed before the first push (for restitution)
  Fixed normal_impulse;
  Fixed tangent_impulse_1;
  Fixed tangent_impulse_2;
};

struct Constraint {
  std::size_t contact;
  std::size_t a;
  std::size_t b;
  Vec3 normal;
  Vec3 tangent_1;
  Vec3 tangent_2;
  Fixed friction;
  Fixed restitution;
  std::uint8_t count;
  // Whether each body's velocity can change under an impulse, and whether it is still (zero
  // velocity that nothing changes). An impulse on a body of zero inverse mass and zero inverse
  // inertia changes nothing, bit for bit, and a still body adds exactly zero to relative
  // velocities: the solver skips that arithmetic instead of computing zeros.
  bool takes_impulse_a;
  bool takes_impulse_b;
  bool still_a;
  bool still_b;
  bool pushed;   // some point has pushed in this step
  bool bounced;  // restitution applied this step
  std::array<SolverPoint, 4> points;
  SolverPoint centroid;  // the mean of the points' anchors, for restitution
};

// Soft constraint coefficients (Box2D v3 b2MakeSoft): a spring of `hertz` with damping ratio
// `zeta`, discretised implicitly for a time step h.
struct Softness {
  Fixed bias_rate;
  Fixed mass_scale;
  Fixed impulse_scale;
};

Softness make_soft(Fixed hertz, Fixed zeta, Fixed h) {
  const Fixed omega = Fixed::two_pi() * hertz;
  const Fixed a1 = 2_fx * zeta + h * omega;
  const Fixed a2 = h * omega * a1;
  const Fixed a3 = Fixed::one() / (Fixed::one() + a2);
  return {omega / a1, a2 * a3, a3};
}

Vec3 halve(Vec3 v) {
  return {v.x >> 1, v.y >> 1, v.z >> 1};
}

// A unit vector perpendicular to the unit vector n, chosen by n's components only.
Vec3 perpendicular(Vec3 n) {
  const Fixed threshold = Fixed::from_raw(2479700525);  // 0.57735 ~ 1/sqrt(3)
  if (abs(n.x) >= threshold) return normalize(Vec3{n.y, -n.x, Fixed::zero()});
  return normalize(Vec3{Fixed::zero(), n.z, -n.y});
}

// 1 / (m_a^-1 + m_b^-1 + (I_a^-1 (r_a x d)) . (r_a x d) + (I_b^-1 (r_b x d)) . (r_b x d)).
Fixed effective_mass(const Derived& a, const Derived& b, Vec3 ra, Vec3 rb, Vec3 d) {
  const Vec3 ca = cross(ra, d);
  const Vec3 cb = cross(rb, d);
  const Fixed k = a.inverse_mass + b.inverse_mass + dot(a.inverse_inertia_world * ca, ca) +
                  dot(b.inverse_inertia_world * cb, cb);
  return inverse_or_zero(k);
}

struct Velocity {
  Vec3 linear;
  Vec3 angular;
};

class Solver {
 public:
  explicit Solver(WorldState& s) : s_(s) {
    const Fixed substeps = Fixed::from_int(static_cast<std::int32_t>(s.def.substeps));
    h_ = s.def.dt / substeps;
    inv_h_ = substeps / s.def.dt;
    // The contact spring may not be stiffer than a quarter of the sub-step rate (Box2D's bound),
    // or the implicit discretisation stops damping it.
    const Fixed hertz = min(s.def.contact_hertz, inv_h_ >> 2);
    soft_ = make_soft(hertz, s.def.contact_damping_ratio, h_);
    static_soft_ = make_soft(min(hertz << 1, inv_h_ >> 2), s.def.contact_damping_ratio, h_);
    gravity_kick_ = s.def.gravity * h_;
    gravity_half_kick_ = halve(gravity_kick_);
    velocities_.resize(s.bodies.size());
    half_kick_.resize(s.bodies.size());
    in_contact_.assign(s.bodies.size(), false);
    for (std::size_t i = 0; i < s.bodies.size(); ++i) {
      const BodyState& b = s.bodies[i];
      velocities_[i] = {b.linear_velocity, b.angular_velocity};
    }
  }

  void run() {
    prepare_constraints();  // sets every separation to its base (no motion yet)
    for (std::uint32_t sub = 0; sub < s_.def.substeps; ++sub) {
      integrate_velocities();
      warm_start();
      for (std::uint32_t i = 0; i < s_.def.iterations; ++i)
        solve_contacts(true);
      clamp_speeds();  // contact impulses (a crushed light body) can exceed what gravity could
      integrate_positions();
      refresh_separations();
      for (std::uint32_t i = 0; i < s_.def.iterations; ++i)
        solve_contacts(false);
      apply_restitution();
      clamp_speeds();
    }
    store_impulses();
    for (std::size_t i = 0; i < s_.bodies.size(); ++i) {
      BodyState& b = s_.bodies[i];
      if (b.type == BodyType::static_body || !b.awake) continue;
      b.linear_velocity = velocities_[i].linear;
      b.angular_velocity = velocities_[i].angular;
    }
  }

 private:
  bool solvable(const BodyState& b) const { return b.type != BodyType::static_body && b.awake; }

  static bool takes_impulse(const Derived& d) {
    return d.inverse_mass != Fixed::zero() || d.inverse_inertia_world != Mat3::zero();
  }

  // Still: no velocity, and none to come (integrate_velocities and clamp_speeds touch only awake
  // dynamic bodies, apply only bodies that take impulses).
  bool still(std::size_t i) const {
    const BodyState& b = s_.bodies[i];
    return !(b.type == BodyType::dynamic && b.awake) && !takes_impulse(s_.derived[i]) &&
           velocities_[i].linear == Vec3{} && velocities_[i].angular == Vec3{};
  }

  void prepare_constraints() {
    constraints_.clear();
    for (std::size_t ci = 0; ci < s_.contacts.size(); ++ci) {
      const Contact& c = s_.contacts[ci];
      if (c.point_count == 0) continue;
      const std::size_t ia = c.index_a;
      const std::size_t ib = c.index_b;
      const BodyState& a = s_.bodies[ia];
      const BodyState& b = s_.bodies[ib];
      if (a.sensor || b.sensor) continue;
      const bool dynamic_a = a.type == BodyType::dynamic && a.awake;
      const bool dynamic_b = b.type == BodyType::dynamic && b.awake;
      if (!dynamic_a && !dynamic_b) continue;
      const Derived& da = s_.derived[ia];
      const Derived& db = s_.derived[ib];
      Constraint k;
      k.contact = ci;
      k.a = ia;
      k.b = ib;
      k.normal = c.manifold.normal;
      k.tangent_1 = perpendicular(k.normal);
      k.tangent_2 = cross(k.normal, k.tangent_1);
      k.friction = sqrt(a.friction * b.friction);
      k.restitution = max(a.restitution, b.restitution);
      k.count = c.point_count;
      k.takes_impulse_a = takes_impulse(da);
      k.takes_impulse_b = takes_impulse(db);
      k.still_a = still(ia);
      k.still_b = still(ib);
      k.pushed = false;
      k.bounced = false;
      Vec3 sum_a;
      Vec3 sum_b;
      for (std::size_t p = 0; p < c.point_count; ++p) {
        const ContactPoint& mp = c.manifold.points[p];
        SolverPoint& sp = k.points[p];
        sp = {};
        sp.anchor_a = mp.point - a.position;
        sp.anchor_b = mp.point - b.position;
        sp.base_separation = mp.separation;
        sp.separation = mp.separation;
        sp.normal_mass = effective_mass(da, db, sp.anchor_a, sp.anchor_b, k.normal);
        sp.tangent_mass_1 = effective_mass(da, db, sp.anchor_a, sp.anchor_b, k.tangent_1);
        sp.tangent_mass_2 = effective_mass(da, db, sp.anchor_a, sp.anchor_b, k.tangent_2);
        sum_a += sp.anchor_a;
        sum_b += sp.anchor_b;
        sp.normal_impulse = c.cached[p].normal_impulse;
        sp.tangent_impulse_1 = c.cached[p].tangent_impulse_1;
        sp.tangent_impulse_2 = c.cached[p].tangent_impulse_2;
      }
      k.centroid = {};
      if (k.restitution != Fixed::zero()) {  // the centroid serves restitution only
        const Fixed count = Fixed::from_int(c.point_count);
        k.centroid.anchor_a = sum_a / count;
        k.centroid.anchor_b = sum_b / count;
        k.centroid.normal_mass =
            effective_mass(da, db, k.centroid.anchor_a, k.centroid.anchor_b, k.normal);
        k.centroid.relative_velocity = dot(relative_velocity(k, k.centroid), k.normal);
      }
      in_contact_[ia] = true;
      in_contact_[ib] = true;
      constraints_.push_back(k);
    }
  }

  // The velocity of a body's material point at `anchor`; exactly zero for a still body, whose
  // velocities are zero (0 + cross(0, r) is the zero vector).
  Vec3 point_velocity(std::size_t i, bool is_still, Vec3 anchor) const {
    if (is_still) return {};
    const Velocity& v = velocities_[i];
    return v.linear + cross(v.angular, anchor);
  }

  Vec3 relative_velocity(const Constraint& k, const SolverPoint& p) const {
    return point_velocity(k.b, k.still_b, p.anchor_b) - point_velocity(k.a, k.still_a, p.anchor_a);
  }

  // v * m; for m = 1 (a body of unit mass) that is v itself, bit for bit, without three multiplies.
  static Vec3 scaled(Vec3 v, Fixed m) { return m == Fixed::one() ? v : v * m; }

  // A zero impulse, or the side of a body that takes no impulses, would add exact zeros to the
  // velocities (0 * m = 0, M 0 = 0, v - 0 = v): both are skipped, which changes no bit.
  void apply(const Constraint& k, const SolverPoint& p, Vec3 impulse) {
    if (impulse == Vec3{}) return;
    if (k.takes_impulse_a) {
      const Derived& da = s_.derived[k.a];
      Velocity& va = velocities_[k.a];
      va.linear -= scaled(impulse, da.inverse_mass);
      va.angular -= da.inverse_inertia_world * cross(p.anchor_a, impulse);
    }
    if (k.takes_impulse_b) {
      const Derived& db = s_.derived[k.b];
      Velocity& vb = velocities_[k.b];
      vb.linear += scaled(impulse, db.inverse_mass);
      vb.angular += db.inverse_inertia_world * cross(p.anchor_b, impulse);
    }
  }

  Vec3 clamp_speed(Vec3 v, Fixed limit) const {
    if (!length_exceeds(v, limit)) return v;  // length(v) <= limit, most often: no root needed
    return v * (limit / length(v));
  }

  // The speed limits hold for every velocity a body moves with and keeps, not only after forces.
  void clamp_speeds() {
    for (std::size_t i = 0; i < s_.bodies.size(); ++i) {
      const BodyState& b = s_.bodies[i];
      if (b.type != BodyType::dynamic || !b.awake) continue;
      Velocity& v = velocities_[i];
      v.linear = clamp_speed(v.linear, s_.def.max_linear_speed);
      v.angular = clamp_speed(v.angular, s_.def.max_angular_speed);
    }
  }

  void integrate_velocities() {
    const WorldDef& def = s_.def;
    for (std::size_t i = 0; i < s_.bodies.size(); ++i) {
      const BodyState& b = s_.bodies[i];
      if (b.type != BodyType::dynamic || !b.awake) continue;
      const Derived& d = s_.derived[i];
      Velocity& v = velocities_[i];
      // Without a force, the kick is gravity's (g + 0 m = g exactly), the same for every body; a
      // zero torque adds exactly zero (M 0 h = 0).
      if (b.force == Vec3{}) {
        half_kick_[i] = gravity_half_kick_;
        v.linear += gravity_kick_;
      } else {
        const Vec3 kick = (def.gravity + b.force * d.inverse_mass) * h_;
        half_kick_[i] = halve(kick);
        v.linear += kick;
      }
      if (b.torque != Vec3{}) v.angular += (d.inverse_inertia_world * b.torque) * h_;
      // Implicit damping, unconditionally stable: v /= 1 + h c.
      if (b.linear_damping > Fixed::zero()) v.linear /= Fixed::one() + h_ * b.linear_damping;
      if (b.angular_damping > Fixed::zero()) v.angular /= Fixed::one() + h_ * b.angular_damping;
      v.linear = clamp_speed(v.linear, def.max_linear_speed);
      v.angular = clamp_speed(v.angular, def.max_angular_speed);
    }
  }

  // Where the surfaces of a point are now, from the manifold and the motion since the step began.
  Fixed current_separation(const Constraint& k, const SolverPoint& sp) const {
    const Vec3 moved =
        displacement(k.b, k.still_b, sp.anchor_b) - displacement(k.a, k.still_a, sp.anchor_a);
    return sp.base_separation + dot(moved, k.normal);
  }

  // How far a body's material point at `anchor` has moved since the start of the step; exactly
  // zero for a still body, which integrate_positions never moves (0 + cross(0, r) = 0).
  Vec3 displacement(std::size_t i, bool is_still, Vec3 anchor) const {
    if (is_still) return {};
    const Derived& d = s_.derived[i];
    return d.delta_position + cross(d.delta_angle, anchor);
  }

  // The separations depend only on the bodies' motion since the start of the step, which only
  // integrate_positions changes: computed once after it (and before the first sub-step), they
  // serve the warm start, the solve and the relaxation that follow.
  void refresh_separations() {
    for (Constraint& k : constraints_) {
      for (std::size_t p = 0; p < k.count; ++p)
        k.points[p].separation = current_separation(k, k.points[p]);
    }
  }

  void warm_start() {
    for (Constraint& k : constraints_) {
      for (std::size_t p = 0; p < k.count; ++p) {
        SolverPoint& sp = k.points[p];
        // A point whose surfaces have come apart (a bounce, a body lifted off) carries no load:
        // re-applying its old impulse would push the bodies apart a second time and feed energy
        // into whatever else they touch before this point's own solve takes it back.
        if (sp.separation > Fixed::zero()) {
          sp.normal_impulse = Fixed::zero();
          sp.tangent_impulse_1 = Fixed::zero();
          sp.tangent_impulse_2 = Fixed::zero();
          continue;
        }
        const Vec3 impulse = k.normal * sp.normal_impulse + k.tangent_1 * sp.tangent_impulse_1 +
                             k.tangent_2 * sp.tangent_impulse_2;
        apply(k, sp, impulse);
      }
    }
  }

  void solve_contacts(bool use_bias) {
    for (Constraint& k : constraints_) {
      const bool against_static = s_.derived[k.a].inverse_mass == Fixed::zero() ||
                                  s_.derived[k.b].inverse_mass == Fixed::zero();
      const Softness& soft = against_static ? static_soft_ : soft_;
      // Until the contact first pushes, its approach speed (at the centroid, before any point is
      // solved) is what restitution must reverse.
      if (use_bias && !k.pushed && k.restitution != Fixed::zero())
        k.centroid.relative_velocity = dot(relative_velocity(k, k.centroid), k.normal);
      for (std::size_t p = 0; p < k.count; ++p) {
        SolverPoint& sp = k.points[p];
        const Fixed separation = sp.separation;
        Fixed bias;
        bool soft_push = false;  // soft: mass and impulse scaled; else scales 1 and 0
        if (separation > Fixed::zero()) {
          bias = separation * inv_h_;  // speculative: close the gap within this sub-step
        } else if (use_bias) {
          bias = max(soft.bias_rate * min(separation + s_.def.linear_slop, Fixed::zero()),
                     -s_.def.contact_push_max);
          soft_push = true;
        }
        const Fixed vn = dot(relative_velocity(k, sp), k.normal);
        // Scales 1 and 0 need no arithmetic: x * 1 = x and x - 0 * y = x, bit for bit.
        Fixed impulse = soft_push ? -sp.normal_mass * soft.mass_scale * (vn + bias) -
                                        soft.impulse_scale * sp.normal_impulse
                                  : -sp.normal_mass * (vn + bias);
        const Fixed accumulated = max(sp.normal_impulse + impulse, Fixed::zero());
        impulse = accumulated - sp.normal_impulse;
        sp.normal_impulse = accumulated;
        if (impulse > Fixed::zero()) k.pushed = true;
        apply(k, sp, k.normal * impulse);
      }
      // Coulomb friction, each point limited to the disc of radius friction * normal impulse.
      for (std::size_t p = 0; p < k.count; ++p) {
        SolverPoint& sp = k.points[p];
        const Fixed limit = k.friction * sp.normal_impulse;
        // With a zero limit the clamp below gives zero whatever t1 and t2 are (0 / |t| = 0, and
        // |t| = 0 only for t = 0): a point with no friction impulse keeps none.
        if (limit == Fixed::zero() && sp.tangent_impulse_1 == Fixed::zero() &&
            sp.tangent_impulse_2 == Fixed::zero())
          continue;
        const Vec3 dv = relative_velocity(k, sp);
        const Fixed t1 = sp.tangent_impulse_1 - sp.tangent_mass_1 * dot(dv, k.tangent_1);
        const Fixed t2 = sp.tangent_impulse_2 - sp.tangent_mass_2 * dot(dv, k.tangent_2);
        Fixed n1 = t1;
        Fixed n2 = t2;
        if (hypot_exceeds(t1, t2, limit)) {  // hypot(t1, t2) > limit, most often false: no root
          const Fixed scale = limit / hypot(t1, t2);
          n1 = t1 * scale;
          n2 = t2 * scale;
        }
        const Vec3 impulse =
            k.tangent_1 * (n1 - sp.tangent_impulse_1) + k.tangent_2 * (n2 - sp.tangent_impulse_2);
        sp.tangent_impulse_1 = n1;
        sp.tangent_impulse_2 = n2;
        apply(k, sp, impulse);
      }
    }
  }

  void integrate_positions() {
    for (std::size_t i = 0; i < s_.bodies.size(); ++i) {
      BodyState& b = s_.bodies[i];
      if (!solvable(b)) continue;
      Derived& d = s_.derived[i];
      const Velocity& v = velocities_[i];
      // In free flight, x += h (v - a h / 2): with v already including this sub-step's a h, the
      // position moves by the trapezoidal mean velocity, so a body under constant gravity and
      // forces follows the exact parabola (semi-implicit Euler alone loses v h / 2 of height per
      // flight). A body with contact points keeps plain semi-implicit Euler, whose resting
      // equilibrium the soft contacts are tuned for (the shifted one creeps sideways).
      const Vec3 dp = in_contact_[i] ? v.linear * h_ : (v.linear - half_kick_[i]) * h_;
      b.position += dp;
      d.delta_position += dp;
      if (v.angular != Vec3{}) {
        b.orientation = integrate(b.orientation, v.angular, h_);
        d.delta_angle += v.angular * h_;
      }
    }
  }

  // Restitution acts once per contact, at the centroid of its points, reversing the centroid's
  // approach speed: one Newton impulse at one point conserves energy for e = 1, whereas
  // per-point impulses applied one after another over-shoot on a rotating body and can add energy.
  void apply_restitution() {
    const Fixed threshold = s_.def.restitution_threshold;
    for (Constraint& k : constraints_) {
      if (k.restitution == Fixed::zero() || k.bounced || !k.pushed) continue;
      SolverPoint& c = k.centroid;
      if (c.relative_velocity > -threshold) continue;
      k.bounced = true;
      const Fixed vn = dot(relative_velocity(k, c), k.normal);
      const Fixed impulse = -c.normal_mass * (vn + k.restitution * c.relative_velocity);
      if (impulse > Fixed::zero()) apply(k, c, k.normal * impulse);
    }
  }

  void store_impulses() {
    for (const Constraint& k : constraints_) {
      Contact& c = s_.contacts[k.contact];
      c.pushed = k.pushed;
      for (std::size_t p = 0; p < k.count; ++p) {
        c.cached[p].normal_impulse = k.points[p].normal_impulse;
        c.cached[p].tangent_impulse_1 = k.points[p].tangent_impulse_1;
        c.cached[p].tangent_impulse_2 = k.points[p].tangent_impulse_2;
      }
    }
  }

  WorldState& s_;
  Fixed h_;
  Fixed inv_h_;
  Vec3 gravity_kick_;       // gravity * h: the velocity change of a body without forces
  Vec3 gravity_half_kick_;  // halve(gravity_kick_)
  Softness soft_;
  Softness static_soft_;
  std::vector<Velocity> velocities_;
  std::vector<Vec3> half_kick_;   // half of this sub-step's velocity change from gravity and forces
  std::vector<bool> in_contact_;  // the body has contact points this step
  std::vector<Constraint> constraints_;
};

}  // namespace

void solve(WorldState& s) {
  Solver(s).run();
}

}  // namespace detsim::sim_detail
