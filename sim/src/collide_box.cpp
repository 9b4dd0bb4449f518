// Box pairs: box-box (separating axes, then reference-face clipping, an edge-edge point, or the
// closest features for speculative contacts off the faces) and box-plane (the deepest vertices).
//
// Work is done in one box's frame wherever possible: there the box is axis-aligned, clipping
// planes are coordinate bounds that can be set exactly, and the other shape enters through one
// relative rotation (exact dots, rounded once per entry).
#include <array>
#include <cstdint>

#include <detsim/fixed/mat3.hpp>
#include <detsim/fixed/math.hpp>
#include <detsim/fixed/vec3.hpp>

#include "collide.hpp"
#include "collide_util.hpp"

namespace detsim::sim_detail::narrow {

namespace {

// ---- Box-box ------------------------------------------------------------------------------------

struct Candidate {
  Vec3 point;
  Fixed separation;
  std::uint32_t feature = 0;
};

/// Orders by a value, larger first, then by feature ID, lower first: a total order on the
/// candidates of one manifold (their IDs differ), so ties never depend on the order the points were
/// found in.
bool beats(Fixed value, std::uint32_t feature_id, Fixed best, std::uint32_t best_feature) noexcept {
  return value > best || (value == best && feature_id < best_feature);
}

/// Twice the signed area of (p, q, s) seen from the side `normal` points to.
Fixed area(Vec3 p, Vec3 q, Vec3 s, Vec3 normal) noexcept {
  return dot(cross(q - p, s - p), normal);
}

/// Up to four of n (<= 8) candidates that keep the contact patch stable: the deepest, the farthest
/// from it, then the points that add the most area on each side of that diagonal (Gregorius,
/// "Robust Contact Creation for Physics Simulations", GDC 2015). When all others lie on one side,
/// the fourth is the one that grows the triangle the most.
int reduce_to_four(const std::array<Candidate, 8>& c, int n, Vec3 normal,
                   std::array<Candidate, 4>& out) noexcept {
  std::array<bool, 8> used{};
  const auto take = [&](int i, int slot) {
    used[static_cast<unsigned>(i)] = true;
    out[static_cast<unsigned>(slot)] = c[static_cast<unsigned>(i)];
  };
  const auto pick_deepest = [&]() {  // lowest separation, then lowest feature
    int best = -1;
    for (int i = 0; i < n; ++i) {
      const Candidate& ci = c[static_cast<unsigned>(i)];
      if (used[static_cast<unsigned>(i)]) continue;
      if (best < 0 || beats(-ci.separation, ci.feature, -c[static_cast<unsigned>(best)].separation,
                            c[static_cast<unsigned>(best)].feature)) {
        best = i;
      }
    }
    return best;
  };
  const auto pick = [&](auto&& score) {  // best unused candidate with score > 0, or -1
    int best = -1;
    Fixed best_score;
    for (int i = 0; i < n; ++i) {
      const Candidate& ci = c[static_cast<unsigned>(i)];
      const Fixed s = score(ci);
      if (used[static_cast<unsigned>(i)] || s <= Fixed::zero()) continue;
      if (best < 0 || beats(s, ci.feature, best_score, c[static_cast<unsigned>(best)].feature)) {
        best = i;
        best_score = s;
      }
    }
    return best;
  };
  const int i0 = pick_deepest();
  take(i0, 0);
  const Vec3 p0 = out[0].point;
  const int i1 = pick([&](const Candidate& x) { return length_squared(x.point - p0); });
  if (i1 < 0) return 1;  // all candidates coincide
  take(i1, 1);
  const Vec3 p1 = out[1].point;
  int i2 = pick([&](const Candidate& x) { return area(p0, p1, x.point, normal); });
  int i3 = pick([&](const Candidate& x) { return -area(p0, p1, x.point, normal); });
  if (i2 < 0 && i3 < 0) {  // collinear: the deepest two others
    i2 = pick_deepest();
    if (i2 < 0) return 2;
    take(i2, 2);
    i3 = pick_deepest();
    if (i3 < 0) return 3;
    take(i3, 3);
    return 4;
  }
  if (i2 >= 0 && i3 >= 0) {
    take(i2, 2);
    take(i3, 3);
    return 4;
  }
  // One side only: orient so that (p0, p1, p2) turns positively about `normal`.
  const Vec3 up = i2 >= 0 ? normal : -normal;
  take(i2 >= 0 ? i2 : i3, 2);
  const Vec3 p2 = out[2].point;
  int i4 = pick([&](const Candidate& x) {
    return max(-area(p1, p2, x.point, up), -area(p2, p0, x.point, up));
  });
  if (i4 < 0) i4 = pick_deepest();
  if (i4 < 0) return 3;
  take(i4, 3);
  return 4;
}

/// A vertex of the clipped incident polygon, in the reference box's frame. `in_*` describe the
/// polygon edge that ends at this vertex: a piece of an incident box edge, or a piece of a
/// reference side plane. Clipping only ever creates vertices where such an edge meets a plane,
/// which is what makes the feature IDs a function of the features alone.
struct ClipVertex {
  Vec3 p;
  std::uint16_t on_ref = 0;
  std::uint16_t on_inc = 0;
  bool in_on_plane = false;
  int in_plane = 0;
  std::uint16_t in_edge = 0;
};

using Polygon = std::array<ClipVertex, 8>;  // a quad clipped by 4 planes has at most 8 vertices

/// Reference face `axis`/`positive`; side planes 0..3 bound (u, +), (u, -), (v, +), (v, -), with
/// u = axis + 1, v = axis + 2 (mod 3).
struct ReferenceFace {
  int axis;
  bool positive;
  Vec3 half;

  [[nodiscard]] int plane_axis(int q) const noexcept { return (axis + (q < 2 ? 1 : 2)) % 3; }
  [[nodiscard]] static bool plane_positive(int q) noexcept { return q % 2 == 0; }
  [[nodiscard]] Signs signs() const noexcept {
    Signs s{};
    s[static_cast<unsigned>(axis)] = positive;
    return s;
  }
  /// The edge of the face that lies in side plane q.
  [[nodiscard]] std::uint16_t side_edge(int q) const noexcept {
    Signs s = signs();
    s[static_cast<unsigned>(plane_axis(q))] = plane_positive(q);
    return box_edge(plane_axis(q ^ 2), s);
  }
  /// The corner of the face where side planes q and q2 (on different axes) meet.
  [[nodiscard]] std::uint16_t corner(int q, int q2) const noexcept {
    Signs s = signs();
    s[static_cast<unsigned>(plane_axis(q))] = plane_positive(q);
    s[static_cast<unsigned>(plane_axis(q2))] = plane_positive(q2);
    return box_vertex(s);
  }
};

/// One Sutherland-Hodgman pass against side plane q (inside: sign * x <= h, on the plane counts
/// as inside). Crossing points get the exact plane coordinate, so no later pass sees them outside.
int clip(const Polygon& in, int n, const ReferenceFace& ref, int q, std::uint16_t inc_face,
         Polygon& out) noexcept {
  const int a = ref.plane_axis(q);
  const bool sp = ReferenceFace::plane_positive(q);
  const Fixed h = component(ref.half, a);
  const auto height = [&](const ClipVertex& v) { return signed_value(sp, component(v.p, a)); };
  const auto crossing = [&](const ClipVertex& p, const ClipVertex& e) {
    // Where the edge p -> e (e the vertex that ends it) crosses the plane; t in [0, 1] since
    // exactly one end is outside, so the denominator is positive.
    const Fixed t = (h - height(p)) / (height(e) - height(p));
    ClipVertex x = e;
    x.p = p.p + (e.p - p.p) * t;
    set_component(x.p, a, signed_value(sp, h));
    if (e.in_on_plane) {  // an edge along another side plane: the reference corner
      x.on_ref = ref.corner(q, e.in_plane);
      x.on_inc = inc_face;
    } else {  // an incident edge through a reference side plane
      x.on_ref = ref.side_edge(q);
      x.on_inc = e.in_edge;
    }
    return x;
  };
  // A convex polygon gains at most one vertex per pass, so 4 + 4 fit. The incident face is the
  // one most facing the reference face (|cos| >= 1/sqrt 3), so its projection is never a sliver
  // that rounding could make non-convex; the bound is kept anyway so that no input writes past it.
  unsigned m = 0;
  const auto emit = [&](const ClipVertex& v) {
    if (m < out.size()) out[m++] = v;
  };
  for (int i = 0; i < n; ++i) {
    const ClipVertex& p = in[static_cast<unsigned>(i)];
    const ClipVertex& e = in[static_cast<unsigned>((i + 1) % n)];
    const bool p_in = height(p) <= h;
    const bool e_in = height(e) <= h;
    if (p_in && e_in) {
      emit(e);
    } else if (p_in) {
      emit(crossing(p, e));  // leaves: keeps e's edge label
    } else if (e_in) {
      ClipVertex x = crossing(p, e);
      x.in_on_plane = true;  // reached along the plane from the leaving point
      x.in_plane = q;
      emit(x);
      emit(e);
    }
  }
  return static_cast<int>(m);
}

/// Face contact: the incident face of `inc` (the face most anti-parallel to the reference normal)
/// clipped against the side planes of the reference face of `ref`. `rel` = R_ref^T R_inc and
/// `inc_center` is the incident centre in the reference frame.
Manifold face_contact(const Shape& ref, const Pose& ref_pose, const Shape& inc, const Mat3& rel,
                      Vec3 inc_center, int axis, bool positive, bool ref_is_a,
                      Fixed margin) noexcept {
  const ReferenceFace face{axis, positive, ref.half_extents};
  const Vec3 hi = inc.half_extents;
  const Vec3 facing = rel.rows[static_cast<unsigned>(axis)];  // R_axis . I_j
  int k = 0;
  if (abs(facing.y) > abs(component(facing, k))) k = 1;
  if (abs(facing.z) > abs(component(facing, k))) k = 2;
  const bool inc_positive = signed_value(positive, component(facing, k)) < Fixed::zero();
  const std::uint16_t inc_face = box_face(k, inc_positive);

  // The incident face's corners in cyclic order (+,+), (-,+), (-,-), (+,-) over axes k+1, k+2.
  const int ka = (k + 1) % 3;
  const int kb = (k + 2) % 3;
  constexpr std::array<std::array<bool, 2>, 4> order{
      {{true, true}, {false, true}, {false, false}, {true, false}}};
  Polygon poly{};
  for (unsigned i = 0; i < 4; ++i) {
    Signs s{};
    s[static_cast<unsigned>(k)] = inc_positive;
    s[static_cast<unsigned>(ka)] = order[i][0];
    s[static_cast<unsigned>(kb)] = order[i][1];
    Vec3 corner;
    for (int j = 0; j < 3; ++j) {
      set_component(corner, j, signed_value(s[static_cast<unsigned>(j)], component(hi, j)));
    }
    ClipVertex& v = poly[i];
    v.p = inc_center + rel * corner;
    v.on_ref = box_face(axis, positive);
    v.on_inc = box_vertex(s);
    // The edge from the previous corner changes the axis kb for even i, ka for odd i.
    v.in_edge = box_edge(i % 2 == 0 ? kb : ka, s);
  }
  int n = 4;
  Polygon scratch{};
  for (int q = 0; q < 4 && n > 0; ++q) {
    n = clip(poly, n, face, q, inc_face, scratch);
    poly = scratch;
  }

  const Fixed top = component(ref.half_extents, axis);
  const Fixed surface = signed_value(positive, top);
  std::array<Candidate, 8> found{};
  int count = 0;
  for (int i = 0; i < n; ++i) {
    const ClipVertex& v = poly[static_cast<unsigned>(i)];
    const Fixed separation = signed_value(positive, component(v.p, axis)) - top;
    if (separation > margin) continue;
    Vec3 point = v.p;  // midway between the incident point and its projection on the face
    set_component(point, axis, surface + signed_value(positive, separation >> 1));
    const std::uint32_t id =
        ref_is_a ? pair_feature(v.on_ref, v.on_inc) : pair_feature(v.on_inc, v.on_ref);
    found[static_cast<unsigned>(count++)] = Candidate{point, separation, id};
  }
  const Vec3 local_normal = axis_vector(axis, positive);
  std::array<Candidate, 4> kept{};
  int kept_count = count;
  if (count > 4) {
    kept_count = reduce_to_four(found, count, local_normal, kept);
  } else {
    for (int i = 0; i < count; ++i)
      kept[static_cast<unsigned>(i)] = found[static_cast<unsigned>(i)];
  }
  Manifold m;
  m.normal = ref_is_a ? local_normal : -local_normal;
  for (int i = 0; i < kept_count; ++i) {
    const Candidate& c = kept[static_cast<unsigned>(i)];
    add_point(m, c.point, c.separation, c.feature, margin);
  }
  return to_world(m, ref_pose);
}

/// The feature of a box at parameter t of the edge along `axis` named by `signs`: the edge, or
/// the vertex at the end t was clamped to.
std::uint16_t edge_point_feature(int axis, Signs signs, Fixed t, Fixed half) noexcept {
  if (t > -half && t < half) return box_edge(axis, signs);
  signs[static_cast<unsigned>(axis)] = t > Fixed::zero();
  return box_vertex(signs);
}

/// The corner of a box of half extents h on the sides given by the bits of v (bit i: +h_i).
Vec3 corner(Vec3 h, unsigned v, Signs& signs) noexcept {
  signs = {(v & 1U) != 0, (v & 2U) != 0, (v & 4U) != 0};
  return {signed_value(signs[0], h.x), signed_value(signs[1], h.y), signed_value(signs[2], h.z)};
}

/// The edge of a box along `axis` on the sides given by the two bits of e, as a segment.
Segment edge_segment(Vec3 h, int axis, unsigned e, Signs& signs) noexcept {
  signs = {};
  signs[static_cast<unsigned>((axis + 1) % 3)] = (e & 1U) != 0;
  signs[static_cast<unsigned>((axis + 2) % 3)] = (e & 2U) != 0;
  Vec3 center;
  for (int j = 0; j < 3; ++j) {
    if (j != axis)
      set_component(center, j, signed_value(signs[static_cast<unsigned>(j)], component(h, j)));
  }
  return {center, axis_vector(axis), component(h, axis)};
}

/// Closest points of two disjoint boxes, in a's frame, as a one-point manifold. For disjoint convex
/// polytopes the closest pair is a vertex of one against the other or a pair of edges, so the
/// search tries all of them (16 vertex clamps, 144 edge pairs; the first strict minimum wins). It
/// serves only the speculative cases the separating axes cannot: corners and edges approaching
/// each other away from any face, where clipping keeps nothing within the margin and the best
/// axis only bounds the distance from below. `rel` = R_a^T R_b, `ta`/`tb` = b's centre seen from
/// a in a's frame / from b's frame.
Manifold closest_features(Vec3 ha, Vec3 hb, const Mat3& rel, Vec3 ta, Vec3 tb,
                          Fixed margin) noexcept {
  const Mat3 rel_t = transpose(rel);
  Fixed best = Fixed::max();
  Vec3 on_a;
  Vec3 on_b;
  std::uint32_t id = 0;
  const auto consider = [&](Vec3 pa, Vec3 pb, std::uint16_t fa, std::uint16_t fb) {
    const Fixed d2 = length_squared(pb - pa);
    if (d2 < best) {
      best = d2;
      on_a = pa;
      on_b = pb;
      id = pair_feature(fa, fb);
    }
  };
  for (unsigned v = 0; v < 8; ++v) {
    Signs s{};
    const Vec3 vb = ta + rel * corner(hb, v, s);  // b's vertex in a's frame
    const BoxPoint q = closest_box_point(vb, ha);
    consider(q.point, vb, q.feature, box_vertex(s));
  }
  for (unsigned v = 0; v < 8; ++v) {
    Signs s{};
    const Vec3 va = corner(ha, v, s);
    const BoxPoint q = closest_box_point(rel_t * va - tb, hb);  // a's vertex in b's frame
    consider(va, ta + rel * q.point, box_vertex(s), q.feature);
  }
  for (int i = 0; i < 3; ++i) {
    for (unsigned ea = 0; ea < 4; ++ea) {
      Signs sa{};
      const Segment edge_a = edge_segment(ha, i, ea, sa);
      for (int j = 0; j < 3; ++j) {
        for (unsigned eb = 0; eb < 4; ++eb) {
          Signs sb{};
          const Segment local_b = edge_segment(hb, j, eb, sb);
          const Segment edge_b{ta + rel * local_b.center, rel.column(static_cast<std::size_t>(j)),
                               local_b.half_length};
          const SegmentParams p = closest_on_segments(edge_a, edge_b);
          consider(edge_a.at(p.s), edge_b.at(p.t),
                   edge_point_feature(i, sa, p.s, edge_a.half_length),
                   edge_point_feature(j, sb, p.t, edge_b.half_length));
        }
      }
    }
  }
  const Vec3 v = on_b - on_a;
  const Fixed distance = length(v);
  Manifold m;
  if (distance == Fixed::zero()) return m;  // touching or overlapping: not this function's case
  m.normal = normalize(v);
  add_point(m, midpoint(on_a, on_b), distance, id, margin);
  return m;
}

}  // namespace

Manifold box_box(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb,
                 Fixed margin) noexcept {
  const Vec3 ha = a.half_extents;
  const Vec3 hb = b.half_extents;
  const Vec3 d = pb.position - pa.position;
  if (length(d) - length(ha) - length(hb) > margin) return {};
  const Mat3 c = transpose(pa.rotation) * pb.rotation;  // c[i][j] = A_i . B_j
  const Mat3 ct = transpose(c);
  const Vec3 ta = to_local(pa.rotation, d);
  const Vec3 tb = to_local(pb.rotation, d);

  // Separating axis test over the 15 axes; each separation is the gap between the projections,
  // a lower bound of the distance, so any axis beyond the margin ends the test. Radii are dots of
  // half extents with |cosines|: exact products, one rounding.
  int face_a = 0;
  int face_b = 0;
  Fixed sep_a = Fixed::min();
  Fixed sep_b = Fixed::min();
  for (int i = 0; i < 3; ++i) {
    const unsigned ui = static_cast<unsigned>(i);
    const Fixed s = abs(component(ta, i)) - component(ha, i) - dot(hb, abs_components(c.rows[ui]));
    if (s > margin) return {};
    if (s > sep_a) {
      sep_a = s;
      face_a = i;
    }
    const Fixed t = abs(component(tb, i)) - component(hb, i) - dot(ha, abs_components(ct.rows[ui]));
    if (t > margin) return {};
    if (t > sep_b) {
      sep_b = t;
      face_b = i;
    }
  }
  bool have_edge = false;
  int edge_a = 0;
  int edge_b = 0;
  Vec3 edge_normal;
  Fixed sep_e = Fixed::min();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      // Near-parallel edges span no direction of their own (and their face axes already cover
      // them); their cross product would also be mostly rounding.
      const Vec3 w = cross(pa.rotation.column(static_cast<std::size_t>(i)),
                           pb.rotation.column(static_cast<std::size_t>(j)));
      if (length_squared(w) < parallel_sin2) continue;
      Vec3 l = normalize(w);
      if (dot(l, d) < Fixed::zero()) l = -l;
      const Fixed s = dot(l, d) - dot(ha, abs_components(to_local(pa.rotation, l))) -
                      dot(hb, abs_components(to_local(pb.rotation, l)));
      if (s > margin) return {};
      if (s > sep_e) {
        have_edge = true;
        sep_e = s;
        edge_a = i;
        edge_b = j;
        edge_normal = l;
      }
    }
  }

  // Prefer a's faces, then b's, then edges, each only when clearly better (see clearly_greater).
  const Fixed scale = max(axis_bias_scale(ha), axis_bias_scale(hb));
  const bool ref_is_b = clearly_greater(sep_b, sep_a, scale);
  const Fixed sep_face = ref_is_b ? sep_b : sep_a;
  if (!have_edge || !clearly_greater(sep_e, sep_face, scale)) {
    const Manifold m = ref_is_b
                           ? face_contact(b, pb, a, ct, -tb, face_b,
                                          component(tb, face_b) <= Fixed::zero(), false, margin)
                           : face_contact(a, pa, b, c, ta, face_a,
                                          component(ta, face_a) >= Fixed::zero(), true, margin);
    if (m.count > 0 || max(sep_face, sep_e) <= Fixed::zero()) return m;
    return to_world(closest_features(ha, hb, c, ta, tb, margin), pa);
  }

  // Edge against edge: one point midway between the closest points of the two supporting edges.
  const BoxEdge ea = supporting_edge(ha, edge_a, to_local(pa.rotation, edge_normal));
  const BoxEdge eb = supporting_edge(hb, edge_b, to_local(pb.rotation, -edge_normal));
  const Segment sa{pa.rotation * ea.segment.center,
                   pa.rotation.column(static_cast<std::size_t>(edge_a)), ea.segment.half_length};
  const Segment sb{d + pb.rotation * eb.segment.center,
                   pb.rotation.column(static_cast<std::size_t>(edge_b)), eb.segment.half_length};
  const SegmentParams p = closest_on_segments(sa, sb);
  const bool crossing = abs(p.s) < sa.half_length && abs(p.t) < sb.half_length;
  if (!crossing && sep_e > Fixed::zero()) {
    // Apart, and the edges pass each other: their axis only bounds the distance from below.
    return to_world(closest_features(ha, hb, c, ta, tb, margin), pa);
  }
  Manifold m;
  m.normal = edge_normal;
  add_point(m, pa.position + midpoint(sa.at(p.s), sb.at(p.t)), sep_e,
            pair_feature(box_edge(edge_a, ea.signs), box_edge(edge_b, eb.signs)), margin);
  return m;
}

// ---- Box-plane ----------------------------------------------------------------------------------

Manifold box_plane(const Shape& a, const Pose& pa, const Shape&, const Pose& pb,
                   Fixed margin) noexcept {
  const Vec3 h = a.half_extents;
  const Vec3 up = unit_or(pb.rotation.column(1), Vec3::unit_y());
  const Fixed centre_height = dot(pa.position - pb.position, up);
  // rise[k]: how far the +h_k side of the box is above its centre. A vertex's height is the centre
  // height plus or minus each rise, so the four vertices of a face level with the plane get
  // bitwise equal separations.
  const Vec3 rise = {dot(pa.rotation.column(0), up) * h.x, dot(pa.rotation.column(1), up) * h.y,
                     dot(pa.rotation.column(2), up) * h.z};
  std::array<Fixed, 8> height{};
  std::array<unsigned, 8> order{};
  for (unsigned v = 0; v < 8; ++v) {
    height[v] = centre_height + signed_value((v & 1U) != 0, rise.x) +
                signed_value((v & 2U) != 0, rise.y) + signed_value((v & 4U) != 0, rise.z);
    // Insertion sort by (height, vertex index): the deepest four, whatever the orientation.
    unsigned slot = v;
    while (slot > 0 && height[order[slot - 1]] > height[v]) {
      order[slot] = order[slot - 1];
      --slot;
    }
    order[slot] = v;
  }
  Manifold m;
  m.normal = -up;
  for (unsigned i = 0; i < 4; ++i) {
    const unsigned v = order[i];
    const Signs s{(v & 1U) != 0, (v & 2U) != 0, (v & 4U) != 0};
    const Vec3 corner{signed_value(s[0], h.x), signed_value(s[1], h.y), signed_value(s[2], h.z)};
    const Vec3 vertex = pa.rotation * corner;  // relative to the box centre
    add_point(m, pa.position + midpoint(vertex, vertex - up * height[v]), height[v],
              pair_feature(box_vertex(s), plane_face), margin);
  }
  return m;
}

}  // namespace detsim::sim_detail::narrow
