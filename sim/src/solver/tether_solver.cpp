// Rope tethers between two bodies (tether_solver.hpp): one row each, like a distance joint's
// upper end (joint_solver.cpp): speculative while slack, soft at the end while biased, rigid in
// relax; a compliant rope's row is a spring in solve and relax alike.
#include "tether_solver.hpp"

#include <detsim/fixed/math.hpp>

namespace detsim::sim_detail {

namespace {

// The joints' softness for a rigid tether (joint_solver.cpp's joint_hertz and damping ratio).
constexpr Fixed kTetherHertz = Fixed::from_int(60);
constexpr Fixed kTetherDampingRatio = Fixed::from_int(2);

}  // namespace

TetherSolver::TetherSolver(WorldState& s, SolverBodies& bodies) : s_(s), bodies_(bodies) {
  soft_ = make_soft(min(kTetherHertz, bodies.inv_h >> 2), kTetherDampingRatio, bodies.h);
}

void TetherSolver::prepare() {
  constraints_.clear();
  for (std::size_t gi = 0; gi < s_.particle_groups.size(); ++gi) {
    const ParticleGroup& g = s_.particle_groups[gi];
    const auto* rope = std::get_if<RopeDef>(&g.def);
    if (rope == nullptr || !g.awake || g.attachments.size() != 2) continue;
    const std::ptrdiff_t ia = s_.find(g.attachments[0].body);
    const std::ptrdiff_t ib = s_.find(g.attachments[1].body);
    if (ia == ib) continue;
    const BodyState& a = s_.bodies[static_cast<std::size_t>(ia)];
    const BodyState& b = s_.bodies[static_cast<std::size_t>(ib)];
    if (!(a.type == BodyType::dynamic && a.awake) && !(b.type == BodyType::dynamic && b.awake))
      continue;
    TetherConstraint& k = constraints_.emplace_back();
    k.group = gi;
    k.bodies = bodies_.pair(static_cast<std::size_t>(ia), static_cast<std::size_t>(ib));
    k.local_a = g.attachments[0].local;
    k.local_b = g.attachments[1].local;
    k.max_length = rope->length == Fixed::zero() ? length(rope->end - rope->start) : rope->length;
    k.impulse = g.tether_impulse;
    // Held bodies move by plain semi-implicit Euler, whose equilibrium the soft rows are tuned
    // for (SolverBodies::integrate_positions).
    bodies_.in_contact[k.bodies.a] = true;
    bodies_.in_contact[k.bodies.b] = true;
    update(k);
    k.spring = rope->compliance > Fixed::zero();
    if (k.spring) {
      // Stiffness 1 / compliance on the row's effective mass, critically damped.
      const Fixed stiffness = Fixed::one() / rope->compliance;
      const Fixed omega = sqrt(stiffness / max(k.row.mass, Fixed::from_raw(1)));
      k.spring_soft = make_soft(omega / Fixed::two_pi(), Fixed::one(), bodies_.h);
    }
  }
}

void TetherSolver::update(TetherConstraint& k) {
  const BodyState& a = s_.bodies[k.bodies.a];
  const BodyState& b = s_.bodies[k.bodies.b];
  const Derived& da = s_.derived[k.bodies.a];
  const Derived& db = s_.derived[k.bodies.b];
  k.anchor_a = rotate(a.orientation, k.local_a - a.center_of_mass);
  k.anchor_b = rotate(b.orientation, k.local_b - b.center_of_mass);
  const Vec3 separation = (db.center + k.anchor_b) - (da.center + k.anchor_a);
  k.length = length(separation);
  const Vec3 d = k.length > Fixed::zero() ? separation / k.length : Vec3{};
  k.axial = make_direction(da, db, d);
  k.row = make_row(da, db, k.anchor_a, k.anchor_b, d);
}

void TetherSolver::warm_start() {
  for (TetherConstraint& k : constraints_) {
    if (k.length < k.max_length) k.impulse = Fixed::zero();  // slack: carries nothing
    // The row's impulse pulls the bodies together: along -d for b.
    apply_impulse(bodies_.velocities, k.bodies, k.axial, k.row, -k.impulse);
  }
}

void TetherSolver::solve_all(bool use_bias) {
  for (TetherConstraint& k : constraints_) {
    // c >= 0 is held: the rope's length less the distance; cdot its rate, the speed at which
    // the points come together.
    const Fixed c = k.max_length - k.length;
    const Fixed cdot = -row_speed(bodies_.velocities, k.bodies, k.axial, k.row);
    const Fixed mass = k.row.mass;
    Fixed impulse;
    if (c > Fixed::zero()) {
      impulse = -mass * (cdot + c * bodies_.inv_h);
    } else if (k.spring || use_bias) {
      const Softness& soft = k.spring ? k.spring_soft : soft_;
      impulse =
          -mass * soft.mass_scale * (cdot + soft.bias_rate * c) - soft.impulse_scale * k.impulse;
    } else {
      impulse = -mass * cdot;
    }
    const Fixed next = max(k.impulse + impulse, Fixed::zero());
    impulse = next - k.impulse;
    k.impulse = next;
    apply_impulse(bodies_.velocities, k.bodies, k.axial, k.row, -impulse);
  }
}

void TetherSolver::solve() {
  solve_all(true);
}

void TetherSolver::positions_moved() {
  for (TetherConstraint& k : constraints_)
    update(k);
}

void TetherSolver::relax() {
  solve_all(false);
}

void TetherSolver::store_impulses() {
  for (const TetherConstraint& k : constraints_)
    s_.particle_groups[k.group].tether_impulse = k.impulse;
}

}  // namespace detsim::sim_detail
