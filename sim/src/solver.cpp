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
// bodies (in its rows, below), and its separation is updated from the bodies' motion since the
// start of the step (with a small-angle rotation), which is exact for translation and
// second-order small for rotation.
// Soft constraints act like a damped spring with a stiffness tied to the sub-step rate rather than
// an iteration count, so stacks neither jitter nor explode, and a restitution-1 bounce loses
// almost nothing. Every constraint is solved in contact order (ascending ID pair), point order
// within a contact: the order is part of the result.
//
// Each point has three rows (the normal and two tangents), and each row its Jacobian per body,
// computed once per step because the anchors and the world inertia stay fixed for the step: for
// direction d, body a's row is (-d, d x r_a) and body b's (d, r_b x d), with the responses
// M^-1 J^T (the linear part times the inverse mass, the angular part times the world inverse
// inertia). A row's speed J v is one exact sum of every product, rounded once (DotSum), and an
// impulse moves each velocity by v + lambda M^-1 J^T rounded once per component (Vec3Sum), the two
// friction rows of a point together. The sub-steps then need no cross product and no matrix.
#include <algorithm>
#include <vector>

#include <detsim/fixed/decimal.hpp>
#include <detsim/fixed/math.hpp>

#include "world_state.hpp"

namespace detsim::sim_detail {

using namespace detsim::literals;

namespace {

// A row's part for the two bodies' angular velocities, and what a unit impulse along it does to
// them (per point: it depends on the anchors).
struct Row {
  Vec3 angular_a;   // d x r_a
  Vec3 angular_b;   // r_b x d
  Vec3 response_a;  // I_a^-1 angular_a
  Vec3 response_b;  // I_b^-1 angular_b
  Fixed mass;       // 1 / (J M^-1 J^T), the effective mass; zero when nothing can move
};

// A row's part for the two bodies' linear velocities, and their response (per contact: every point
// of a contact shares its directions).
struct Direction {
  Vec3 linear_a;    // -d
  Vec3 linear_b;    // d
  Vec3 response_a;  // -d m_a^-1
  Vec3 response_b;  // d m_b^-1
};

struct SolverPoint {
  Fixed base_separation;
  Fixed separation;  // current_separation at the bodies' present motion (refresh_separations)
  Row normal;
  Row tangent_1;
  Row tangent_2;
  Fixed normal_impulse;
  Fixed tangent_impulse_1;
  Fixed tangent_impulse_2;
};

// Restitution acts once per contact, along the normal at the centroid of its points.
struct Bounce {
  Row normal;
  Fixed relative_velocity;  // normal approach speed before the first push
};

struct Constraint {
  std::size_t contact;
  std::size_t a;
  std::size_t b;
  Direction normal;
  Direction tangent_1;
  Direction tangent_2;
  Fixed friction;
  Fixed restitution;
  std::uint8_t count;
  // Whether each body's velocity can change under an impulse, and whether it is still (zero
  // velocity that nothing changes). An impulse on a body of zero inverse mass and zero inverse
  // inertia changes nothing, bit for bit, and a still body adds exactly zero to a row's speed: the
  // solver skips that arithmetic instead of computing zeros.
  bool takes_impulse_a;
  bool takes_impulse_b;
  bool still_a;
  bool still_b;
  bool pushed;   // some point has pushed in this step
  bool bounced;  // restitution applied this step
  std::array<SolverPoint, 4> points;
  Bounce bounce;  // set only when restitution is not zero
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

Direction make_direction(const Derived& a, const Derived& b, Vec3 d) {
  return {-d, d, -d * a.inverse_mass, d * b.inverse_mass};
}

// The row of direction d at anchors r_a and r_b, with its effective mass
// 1 / (m_a^-1 + m_b^-1 + (d x r_a) . I_a^-1 (d x r_a) + (r_b x d) . I_b^-1 (r_b x d)).
Row make_row(const Derived& a, const Derived& b, Vec3 ra, Vec3 rb, Vec3 d) {
  Row r;
  r.angular_a = cross(d, ra);
  r.angular_b = cross(rb, d);
  r.response_a = a.inverse_inertia_world * r.angular_a;
  r.response_b = b.inverse_inertia_world * r.angular_b;
  const Fixed angular =
      DotSum{}.add(r.response_a, r.angular_a).add(r.response_b, r.angular_b).result();
  r.mass = inverse_or_zero(a.inverse_mass + b.inverse_mass + angular);
  return r;
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
      // Built in place: a Constraint is about 1.5 KB, and a copy per contact per step is waste.
      Constraint& k = constraints_.emplace_back();
      k.contact = ci;
      k.a = ia;
      k.b = ib;
      const Vec3 normal = c.manifold.normal;
      const Vec3 tangent_1 = perpendicular(normal);
      const Vec3 tangent_2 = cross(normal, tangent_1);
      k.normal = make_direction(da, db, normal);
      k.tangent_1 = make_direction(da, db, tangent_1);
      k.tangent_2 = make_direction(da, db, tangent_2);
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
        // The contact point relative to each body's centre at the start of the step.
        const Vec3 anchor_a = mp.point - a.position;
        const Vec3 anchor_b = mp.point - b.position;
        sp.base_separation = mp.separation;
        sp.separation = mp.separation;
        sp.normal = make_row(da, db, anchor_a, anchor_b, normal);
        sp.tangent_1 = make_row(da, db, anchor_a, anchor_b, tangent_1);
        sp.tangent_2 = make_row(da, db, anchor_a, anchor_b, tangent_2);
        sum_a += anchor_a;
        sum_b += anchor_b;
        sp.normal_impulse = c.cached[p].normal_impulse;
        sp.tangent_impulse_1 = c.cached[p].tangent_impulse_1;
        sp.tangent_impulse_2 = c.cached[p].tangent_impulse_2;
      }
      k.bounce = {};
      if (k.restitution != Fixed::zero()) {  // the centroid serves restitution only
        const Fixed count = Fixed::from_int(c.point_count);
        k.bounce.normal = make_row(da, db, sum_a / count, sum_b / count, normal);
        k.bounce.relative_velocity = speed(k, k.normal, k.bounce.normal);
      }
      in_contact_[ia] = true;
      in_contact_[ib] = true;
    }
  }

  // The speed of a row, J v: one exact sum rounded once. A still body's velocities are zero and
  // add exact zeros, which are skipped.
  Fixed speed(const Constraint& k, const Direction& d, const Row& r) const {
    DotSum sum;
    if (!k.still_a)
      sum.add(d.linear_a, velocities_[k.a].linear).add(r.angular_a, velocities_[k.a].angular);
    if (!k.still_b)
      sum.add(d.linear_b, velocities_[k.b].linear).add(r.angular_b, velocities_[k.b].angular);
    return sum.result();
  }

  // A body's response to a unit impulse along a row: M^-1 J^T.
  struct Response {
    Vec3 linear;
    Vec3 angular;
  };

  // v += impulse * response (+ impulse_2 * response_2), each velocity component rounded once.
  static void push(Velocity& v, Fixed impulse, Response r) {
    v.linear = Vec3Sum{v.linear}.add(impulse, r.linear).result();
    v.angular = Vec3Sum{v.angular}.add(impulse, r.angular).result();
  }
  static void push(Velocity& v, Fixed impulse_1, Response r1, Fixed impulse_2, Response r2) {
    v.linear = Vec3Sum{v.linear}.add(impulse_1, r1.linear).add(impulse_2, r2.linear).result();
    v.angular = Vec3Sum{v.angular}.add(impulse_1, r1.angular).add(impulse_2, r2.angular).result();
  }

  // An impulse along one row. A zero impulse, or the side of a body that takes no impulses (zero
  // responses), would leave every bit as it is: both are skipped.
  void apply(const Constraint& k, const Direction& d, const Row& r, Fixed impulse) {
    if (impulse == Fixed::zero()) return;
    if (k.takes_impulse_a) push(velocities_[k.a], impulse, {d.response_a, r.response_a});
    if (k.takes_impulse_b) push(velocities_[k.b], impulse, {d.response_b, r.response_b});
  }

  // Both friction rows of a point at once.
  void apply_friction(const Constraint& k, const SolverPoint& p, Fixed impulse_1, Fixed impulse_2) {
    if (impulse_1 == Fixed::zero() && impulse_2 == Fixed::zero()) return;
    if (k.takes_impulse_a) {
      push(velocities_[k.a], impulse_1, {k.tangent_1.response_a, p.tangent_1.response_a}, impulse_2,
           {k.tangent_2.response_a, p.tangent_2.response_a});
    }
    if (k.takes_impulse_b) {
      push(velocities_[k.b], impulse_1, {k.tangent_1.response_b, p.tangent_1.response_b}, impulse_2,
           {k.tangent_2.response_b, p.tangent_2.response_b});
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

  // Where the surfaces of a point are now, from the manifold and the motion since the step began:
  // the separation grows at the normal row's speed, so it has grown by the row's Jacobian times
  // the bodies' displacements (delta position, small-angle delta rotation), one exact sum rounded
  // once. A still body has not moved (integrate_positions never moves it) and adds exact zeros.
  Fixed current_separation(const Constraint& k, const SolverPoint& sp) const {
    DotSum moved;
    if (!k.still_a) {
      const Derived& da = s_.derived[k.a];
      moved.add(k.normal.linear_a, da.delta_position).add(sp.normal.angular_a, da.delta_angle);
    }
    if (!k.still_b) {
      const Derived& db = s_.derived[k.b];
      moved.add(k.normal.linear_b, db.delta_position).add(sp.normal.angular_b, db.delta_angle);
    }
    return sp.base_separation + moved.result();
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
        apply(k, k.normal, sp.normal, sp.normal_impulse);
        apply_friction(k, sp, sp.tangent_impulse_1, sp.tangent_impulse_2);
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
        k.bounce.relative_velocity = speed(k, k.normal, k.bounce.normal);
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
        const Fixed vn = speed(k, k.normal, sp.normal);
        // Scales 1 and 0 need no arithmetic: x * 1 = x and x - 0 * y = x, bit for bit.
        Fixed impulse = soft_push ? -sp.normal.mass * soft.mass_scale * (vn + bias) -
                                        soft.impulse_scale * sp.normal_impulse
                                  : -sp.normal.mass * (vn + bias);
        const Fixed accumulated = max(sp.normal_impulse + impulse, Fixed::zero());
        impulse = accumulated - sp.normal_impulse;
        sp.normal_impulse = accumulated;
        if (impulse > Fixed::zero()) k.pushed = true;
        apply(k, k.normal, sp.normal, impulse);
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
        const Fixed t1 =
            sp.tangent_impulse_1 - sp.tangent_1.mass * speed(k, k.tangent_1, sp.tangent_1);
        const Fixed t2 =
            sp.tangent_impulse_2 - sp.tangent_2.mass * speed(k, k.tangent_2, sp.tangent_2);
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
        apply_friction(k, sp, impulse_1, impulse_2);
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
      const Bounce& c = k.bounce;
      if (c.relative_velocity > -threshold) continue;
      k.bounced = true;
      const Fixed vn = speed(k, k.normal, c.normal);
      const Fixed impulse = -c.normal.mass * (vn + k.restitution * c.relative_velocity);
      if (impulse > Fixed::zero()) apply(k, k.normal, c.normal, impulse);
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
