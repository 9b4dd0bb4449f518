// The point blocks of a tree of joints solved exactly, in time linear in the joints (Baraff,
// "Linear-time dynamics using Lagrange multipliers", SIGGRAPH 1996, in the Schur form on joints).
//
// Why: Gauss-Seidel passes a load along a chain one joint per pass. With the default single
// iteration, a 100 kg ball on ten 1 kg links flailed (links at 27 m/s, anchors 0.53 m apart);
// ragdolls landing on steps came apart by 0.35 m; a 20-plank bridge under a box stretched 8-10 mm
// a joint (docs/SIM.md, "Joints", "Trees").
//
// The system. For the point rows of all the tree's joints together, A lambda = rhs with
// A = J M^-1 J^T: A_jj is joint j's own 3x3 block K_j, A_jk = J_j,P M_P^-1 J_k,P^T for joints j
// and k on one body P, zero for joints that share no body. Soft (solve): each joint keeps its own
// soft constraint, Delta lambda_j = -s K_j^-1 (J_j v + b C_j) - i lambda_j (rows.hpp's
// make_soft), which solved one joint after another converges to the solution of
// (A + D) Delta lambda = rhs with D_j = (1/s - 1) K_j and rhs_j = -(J_j v + b C_j) - (i/s) K_j
// lambda_j. A single joint gives its own block back exactly; at rest every joint holds its load
// at the spring's give F / (m_eff omega^2), as before. Rigid (relax): D = 0, rhs = -J v.
//
// The elimination. The graph of bodies and joints (static and kinematic bodies cut it: a joint
// to one is a leaf) is a tree: rooted at its lowest body index, each joint has a parent body (the
// one toward the root) and at most one child body. A's graph joins every pair of joints on a
// body; eliminating a joint after every joint below it (reverse breadth-first order) leaves its
// remaining neighbours on its parent body, which are already joined to each other: no fill
// beyond A's own blocks (a perfect elimination order of a chordal graph), so LDL^T costs
// O(sum over bodies of degree^2) 3x3 products. Pivots are the Schur complements of a positive
// definite matrix (J has full row rank on a tree): each is inverted with inverse(Mat3) (exact
// cofactors over the exact determinant).
//
// Determinism: the trees, their roots and the order of every joint come from body indices and
// constraint order (ascending joint ID) only; every product is Fixed, each entry rounded once.
#include "joint_tree.hpp"

#include "joint_solver.hpp"

namespace detsim::sim_detail {

namespace {

bool has_point_block(JointType t) {
  return t == JointType::ball || t == JointType::hinge || t == JointType::fixed ||
         t == JointType::swing_twist;
}

constexpr std::uint32_t none = ~std::uint32_t{0};

// A_jk = J_j,P M_P^-1 J_k,P^T for joints j and k on body P (j_a: P is j's body a). The point
// rows' linear parts on P are -e_i on body a, e_i on body b; their angular parts and responses
// are the rows'.
Mat3 coupling(const JointConstraint& j, bool j_a, const JointConstraint& k, bool k_a,
              const Derived& body) {
  Mat3 m;
  for (std::size_t i = 0; i < 3; ++i) {
    const Vec3 angular = j_a ? j.rows[i].angular_a : j.rows[i].angular_b;
    Fixed entries[3];
    for (std::size_t c = 0; c < 3; ++c) {
      const Vec3 response = k_a ? k.rows[c].response_a : k.rows[c].response_b;
      entries[c] = DotSum{}.add(angular, response).result();
      if (c == i) {
        // The world axis e_i's linear share: m^-1, or 0 along a locked axis (rows.hpp).
        Vec3 e;
        (i == 0 ? e.x : i == 1 ? e.y : e.z) = Fixed::one();
        const Fixed share = linear_share(body, e);
        entries[c] += j_a == k_a ? share : -share;
      }
    }
    m.rows[i] = {entries[0], entries[1], entries[2]};
  }
  return m;
}

}  // namespace

void JointTrees::find(const std::vector<JointConstraint>& constraints, std::size_t body_count) {
  held_.clear();
  nodes_.clear();
  links_.clear();
  // The sides of each point joint that take impulses (the others cut the graph).
  const auto ends = [&](const JointConstraint& k, std::size_t& a, std::size_t& b) {
    a = k.bodies.takes_impulse_a ? k.bodies.a : body_count;
    b = k.bodies.takes_impulse_b ? k.bodies.b : body_count;
  };
  std::size_t candidates = 0;
  for (const JointConstraint& k : constraints)
    candidates += has_point_block(k.type) ? 1U : 0U;
  if (candidates < 2) return;

  // Cycles: union-find over the bodies (the lower index is the root), a joint whose two bodies
  // are already joined closes a cycle; its component is left to Gauss-Seidel.
  std::vector<std::size_t> root(body_count);
  std::vector<bool> cyclic(body_count, false);
  for (std::size_t i = 0; i < body_count; ++i)
    root[i] = i;
  const auto find_root = [&](std::size_t i) {
    while (root[i] != i) {
      root[i] = root[root[i]];
      i = root[i];
    }
    return i;
  };
  for (const JointConstraint& k : constraints) {
    if (!has_point_block(k.type)) continue;
    std::size_t a = 0;
    std::size_t b = 0;
    ends(k, a, b);
    if (a == body_count || b == body_count) continue;  // a leaf: no cycle through it
    const std::size_t ra = find_root(a);
    const std::size_t rb = find_root(b);
    if (ra == rb) {
      cyclic[ra] = true;
      continue;
    }
    const std::size_t lower = ra < rb ? ra : rb;
    const std::size_t upper = ra < rb ? rb : ra;
    root[upper] = lower;
    cyclic[lower] = cyclic[lower] || cyclic[upper];
  }

  // Each body's point joints in ascending constraint order (compressed rows), acyclic only.
  std::vector<std::uint32_t> begin(body_count + 1, 0);
  const auto acyclic = [&](const JointConstraint& k) {
    if (!has_point_block(k.type)) return false;
    std::size_t a = 0;
    std::size_t b = 0;
    ends(k, a, b);
    if (a == body_count && b == body_count) return false;  // nothing moves (prepare skips it)
    return !cyclic[find_root(a != body_count ? a : b)];
  };
  for (const JointConstraint& k : constraints) {
    if (!acyclic(k)) continue;
    if (k.bodies.takes_impulse_a) ++begin[k.bodies.a + 1];
    if (k.bodies.takes_impulse_b) ++begin[k.bodies.b + 1];
  }
  for (std::size_t i = 0; i < body_count; ++i)
    begin[i + 1] += begin[i];
  std::vector<std::uint32_t> incident(begin[body_count]);
  {
    std::vector<std::uint32_t> fill(begin.begin(), begin.end() - 1);
    for (std::size_t c = 0; c < constraints.size(); ++c) {
      const JointConstraint& k = constraints[c];
      if (!acyclic(k)) continue;
      if (k.bodies.takes_impulse_a) incident[fill[k.bodies.a]++] = static_cast<std::uint32_t>(c);
      if (k.bodies.takes_impulse_b) incident[fill[k.bodies.b]++] = static_cast<std::uint32_t>(c);
    }
  }

  // Breadth-first from each tree's lowest body index: the joints in discovery order, each with
  // its parent body, the first of its parent body's children, and for each body the joint it
  // was reached through.
  held_.assign(constraints.size(), false);
  std::vector<bool> seen(constraints.size(), false);
  std::vector<bool> visited(body_count, false);
  std::vector<std::uint32_t> via(body_count, none);
  std::vector<std::size_t> queue;
  struct Found {
    std::uint32_t constraint;
    std::size_t body;
    std::uint32_t first_sibling;
  };
  std::vector<Found> found;
  for (std::size_t start = 0; start < body_count; ++start) {
    if (visited[start] || begin[start] == begin[start + 1]) continue;
    found.clear();
    queue.clear();
    queue.push_back(start);
    visited[start] = true;
    for (std::size_t head = 0; head < queue.size(); ++head) {
      const std::size_t p = queue[head];
      const auto first = static_cast<std::uint32_t>(found.size());
      for (std::uint32_t e = begin[p]; e < begin[p + 1]; ++e) {
        const std::uint32_t c = incident[e];
        if (seen[c]) continue;
        seen[c] = true;
        const JointConstraint& k = constraints[c];
        found.push_back({c, p, first});
        const bool p_is_a = k.bodies.a == p;
        const bool other_takes = p_is_a ? k.bodies.takes_impulse_b : k.bodies.takes_impulse_a;
        const std::size_t q = p_is_a ? k.bodies.b : k.bodies.a;
        if (!other_takes || visited[q]) continue;
        visited[q] = true;
        via[q] = static_cast<std::uint32_t>(found.size() - 1);
        queue.push_back(q);
      }
    }
    if (found.size() < 2) continue;  // a lone joint: its own block is exact
    // Elimination order: reverse discovery (every joint after the joints below it). A joint
    // found at d is node base + n - 1 - d; its later neighbours are its parent body's children
    // found before it (latest first), then the joint its parent body was reached through.
    const auto base = static_cast<std::uint32_t>(nodes_.size());
    const auto n = static_cast<std::uint32_t>(found.size());
    const auto node_of = [&](std::uint32_t d) { return base + n - 1 - d; };
    nodes_.resize(nodes_.size() + n);
    for (std::uint32_t e = 0; e < n; ++e) {
      const std::uint32_t d = n - 1 - e;
      const Found& f = found[d];
      Node& node = nodes_[base + e];
      node.constraint = f.constraint;
      node.body = f.body;
      node.body_is_a = constraints[f.constraint].bodies.a == f.body;
      node.links_begin = static_cast<std::uint32_t>(links_.size());
      for (std::uint32_t s = d; s > f.first_sibling; --s)
        links_.push_back({node_of(s - 1), {}, {}});
      if (via[f.body] != none) links_.push_back({node_of(via[f.body]), {}, {}});
      node.links_end = static_cast<std::uint32_t>(links_.size());
      held_[f.constraint] = true;
    }
  }
}

void JointTrees::update_couplings(const std::vector<JointConstraint>& constraints,
                                  const WorldState& s) {
  for (const Node& node : nodes_) {
    const JointConstraint& k = constraints[node.constraint];
    const Derived& body = s.derived[node.body];
    for (std::uint32_t l = node.links_begin; l < node.links_end; ++l) {
      const JointConstraint& o = constraints[nodes_[links_[l].node].constraint];
      links_[l].coupling = coupling(k, node.body_is_a, o, o.bodies.a == node.body, body);
    }
  }
  soft_factor_.valid = false;
  rigid_factor_.valid = false;
}

// LDL^T from the leaves: each node's pivot inverted, its later neighbours' blocks less its part
// (A_kl -= A_kj pivot^-1 A_jl, all on its parent body). With `soft`, the pivots are the joints'
// soft blocks K_j / mass_scale (A + D); without, K_j.
void JointTrees::factor(const std::vector<JointConstraint>& constraints, const Softness* soft,
                        Factor& f) {
  const Fixed scale = soft ? Fixed::one() / soft->mass_scale : Fixed::one();
  for (Node& node : nodes_) {
    const JointConstraint& k = constraints[node.constraint];
    node.pivot = soft ? k.point_k * scale : k.point_k;
    for (std::uint32_t l = node.links_begin; l < node.links_end; ++l)
      links_[l].block = links_[l].coupling;
  }
  f.inverse.resize(nodes_.size());
  f.gain.resize(links_.size());
  for (std::size_t e = 0; e < nodes_.size(); ++e) {
    const Node& node = nodes_[e];
    f.inverse[e] = inverse(node.pivot);
    for (std::uint32_t l = node.links_begin; l < node.links_end; ++l)
      f.gain[l] = f.inverse[e] * links_[l].block;
    for (std::uint32_t p = node.links_begin; p < node.links_end; ++p) {
      Node& later = nodes_[links_[p].node];
      const Mat3 gain_t = transpose(f.gain[p]);
      later.pivot = later.pivot - gain_t * links_[p].block;
      // later's own links are node's links after p, in the same order (joint_tree.hpp).
      for (std::uint32_t q = p + 1; q < node.links_end; ++q) {
        Link& fill = links_[later.links_begin + (q - p - 1)];
        fill.block = fill.block - gain_t * links_[q].block;
      }
    }
  }
  f.valid = true;
}

void JointTrees::solve(std::vector<JointConstraint>& constraints, SolverBodies& bodies,
                       const Softness* soft) {
  // The factorization depends on the rows and the kind of pass only, not on the velocities:
  // made once per change of the rows (update_couplings) for each kind of pass.
  Factor& f = soft ? soft_factor_ : rigid_factor_;
  if (!f.valid) factor(constraints, soft, f);
  // Every joint's speed before any impulse (one system, solved at once) and its right-hand side.
  const Fixed carry = soft ? soft->impulse_scale / soft->mass_scale : Fixed::zero();
  for (Node& node : nodes_) {
    const JointConstraint& k = constraints[node.constraint];
    const Vec3 cdot{row_speed(bodies.velocities, k.bodies, k.axes[0], k.rows[0]),
                    row_speed(bodies.velocities, k.bodies, k.axes[1], k.rows[1]),
                    row_speed(bodies.velocities, k.bodies, k.axes[2], k.rows[2])};
    node.rhs =
        soft ? -(cdot + k.separation * soft->bias_rate) - (k.point_k * k.impulse) * carry : -cdot;
  }
  // Forward elimination of the right-hand sides, as the factorization eliminated the blocks.
  for (const Node& node : nodes_) {
    for (std::uint32_t p = node.links_begin; p < node.links_end; ++p) {
      Node& later = nodes_[links_[p].node];
      later.rhs = later.rhs - transpose(f.gain[p]) * node.rhs;
    }
  }
  // Back substitution from the roots, then the impulses.
  for (std::size_t e = nodes_.size(); e-- > 0;) {
    Node& node = nodes_[e];
    Vec3 lambda = f.inverse[e] * node.rhs;
    for (std::uint32_t l = node.links_begin; l < node.links_end; ++l)
      lambda = lambda - f.gain[l] * nodes_[links_[l].node].lambda;
    node.lambda = lambda;
  }
  for (const Node& node : nodes_) {
    JointConstraint& k = constraints[node.constraint];
    k.impulse += node.lambda;
    apply_impulses(bodies.velocities, k.bodies, k.axes, k.rows, node.lambda);
  }
}

}  // namespace detsim::sim_detail
