// The scene plot of bisect_html (bisect.hpp): both sides' bodies at the diff frame, top-down.
//
// The SVG view box is in world metres, x to the right and z downwards (SVG's own y axis points
// down), so shapes are drawn at their world coordinates and no scale factor is computed; strokes
// are non-scaling, so outlines stay one pixel wide whatever the scene's size. Everything is
// computed in Fixed and printed with dec3: no floating point.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/math.hpp>
#include <detsim/fixed/quat.hpp>
#include <detsim/fixed/vec3.hpp>
#include <detsim/replay/bisect.hpp>
#include <detsim/sim/shape_outline.hpp>

#include "bisect_html_detail.hpp"

namespace detsim::replay::html_detail {
namespace {

/// `v` rounded to 3 decimals (half away from zero), trailing zeros dropped: the magnitude's
/// fraction bits times 1000 stay below 2^42, so the rounding is exact integer arithmetic.
std::string dec3(Fixed v) {
  const std::int64_t raw = v.raw();
  const std::uint64_t magnitude =
      raw < 0 ? 0U - static_cast<std::uint64_t>(raw) : static_cast<std::uint64_t>(raw);
  std::uint64_t whole = magnitude >> 32;
  std::uint64_t milli = ((magnitude & 0xFFFFFFFFU) * 1000U + (std::uint64_t{1} << 31)) >> 32;
  if (milli == 1000) {
    ++whole;
    milli = 0;
  }
  std::string out = raw < 0 && (whole != 0 || milli != 0) ? "-" : "";
  out += std::to_string(whole);
  if (milli != 0) {
    char digits[5];
    std::snprintf(digits, sizeof digits, ".%03u", static_cast<unsigned>(milli));
    std::string_view fraction(digits);
    while (fraction.back() == '0')
      fraction.remove_suffix(1);
    out += fraction;
  }
  return out;
}

struct Point {
  Fixed x;
  Fixed z;
};

/// A body's top-down footprint: a circle (centre a), a capsule (core a..b), a polygon, a surface
/// (its triangles, one path) or a compound (its parts' footprints), drawn from its outline
/// (detsim/sim/shape_outline.hpp); a half-space is not drawn.
struct Footprint {
  enum class Kind : std::uint8_t { circle, capsule, polygon, half_space, surface, compound };
  Kind type = Kind::circle;
  Point a;
  Point b;
  Fixed radius;
  std::vector<Point> polygon;
  std::vector<std::array<Point, 3>> triangles;  ///< surface
  std::vector<Footprint> parts;                 ///< compound
};

/// The most triangles a surface is drawn with (some 60 bytes of markup each); a larger surface is
/// drawn as the top-down hull of its bounding box.
constexpr std::size_t kMaxDrawnTriangles = 4096;

Point top_down(Vec3 v) {
  return {v.x, v.z};
}

Fixed cross(Point o, Point a, Point b) {
  return (a.x - o.x) * (b.z - o.z) - (a.z - o.z) * (b.x - o.x);
}

/// Convex hull by Andrew's monotone chain (counter-clockwise in x/z, collinear points dropped).
std::vector<Point> convex_hull(std::vector<Point> points) {
  const auto less = [](Point p, Point q) { return p.x < q.x || (p.x == q.x && p.z < q.z); };
  std::sort(points.begin(), points.end(), less);
  const auto same = [](Point p, Point q) { return p.x == q.x && p.z == q.z; };
  points.erase(std::unique(points.begin(), points.end(), same), points.end());
  if (points.size() < 3) return points;
  std::vector<Point> hull(2 * points.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {  // lower chain
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], points[i]) <= Fixed{})
      --k;
    hull[k++] = points[i];
  }
  for (std::size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {  // upper chain
    while (k >= lower && cross(hull[k - 2], hull[k - 1], points[i]) <= Fixed{})
      --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);  // the last point is the first one again
  return hull;
}

/// The footprint of `outline`, whose centre (for a sphere) is `centre`.
Footprint outline_footprint(const ShapeOutline& outline, Vec3 centre) {
  Footprint f;
  f.radius = outline.radius;
  f.a = top_down(outline.points.size() == 1 ? outline.points[0] : centre);
  if (outline.half_space) {
    f.type = Footprint::Kind::half_space;
  } else if (!outline.parts.empty()) {
    f.type = Footprint::Kind::compound;
    for (const ShapeOutline& part : outline.parts)
      f.parts.push_back(outline_footprint(part, centre));
  } else if (!outline.triangles.empty() && outline.triangles.size() <= kMaxDrawnTriangles) {
    f.type = Footprint::Kind::surface;
    for (const std::array<Vec3, 3>& t : outline.triangles)
      f.triangles.push_back({top_down(t[0]), top_down(t[1]), top_down(t[2])});
  } else if (outline.points.size() == 2) {
    f.type = Footprint::Kind::capsule;
    f.a = top_down(outline.points[0]);
    f.b = top_down(outline.points[1]);
    // Seen along its axis, a capsule is a circle (a core shorter than a thousandth of the radius
    // would only give the path a meaningless direction).
    const Fixed core = hypot(f.b.x - f.a.x, f.b.z - f.a.z);
    if (core == Fixed{} || core <= (f.radius >> 10)) {
      f.type = Footprint::Kind::circle;
      f.a = {(f.a.x >> 1) + (f.b.x >> 1), (f.a.z >> 1) + (f.b.z >> 1)};
    }
  } else if (outline.points.size() > 2) {
    // The hull's own radius (zero for a box) is too small to see at the plot's scale.
    f.type = Footprint::Kind::polygon;
    std::vector<Point> corners;
    for (const Vec3 p : outline.points)
      corners.push_back(top_down(p));
    f.polygon = convex_hull(std::move(corners));
  }
  return f;
}

Footprint footprint(const ScenePose& body) {
  if (body.outline) return outline_footprint(*body.outline, body.position);
  return outline_footprint(shape_outline(body.shape, body.position, body.orientation),
                           body.position);
}

struct Bounds {
  Fixed min_x = Fixed::max(), min_z = Fixed::max(), max_x = Fixed::min(), max_z = Fixed::min();
  void add(Point p, Fixed r) {
    min_x = min(min_x, p.x - r);
    min_z = min(min_z, p.z - r);
    max_x = max(max_x, p.x + r);
    max_z = max(max_z, p.z + r);
  }
  [[nodiscard]] bool empty() const { return min_x > max_x; }
};

void add_bounds(Bounds& b, const Footprint& f) {
  for (const Point p : f.polygon)
    b.add(p, Fixed{});
  for (const std::array<Point, 3>& t : f.triangles)
    for (const Point p : t)
      b.add(p, Fixed{});
  for (const Footprint& part : f.parts)
    add_bounds(b, part);
  if (f.type == Footprint::Kind::half_space || f.type == Footprint::Kind::surface ||
      f.type == Footprint::Kind::compound)
    return;
  if (f.type != Footprint::Kind::polygon) b.add(f.a, f.radius);
  if (f.type == Footprint::Kind::capsule) b.add(f.b, f.radius);
}

std::string point(Point p) {
  return dec3(p.x) + "," + dec3(p.z);
}

/// One footprint's element(s), each with the body's class and title (a compound: one per part,
/// so that every element is styled alike and names its body).
std::string footprint_svg(const std::string& cls, const std::string& title, const Footprint& f) {
  switch (f.type) {
    case Footprint::Kind::compound: {
      std::string out;
      for (const Footprint& part : f.parts)
        out += footprint_svg(cls, title, part);
      return out;
    }
    case Footprint::Kind::surface: {
      // One path of all the triangles: a surface is one body, and one element keeps it small.
      std::string d;
      for (const std::array<Point, 3>& t : f.triangles)
        d.append("M")
            .append(point(t[0]))
            .append("L")
            .append(point(t[1]))
            .append("L")
            .append(point(t[2]))
            .append("Z");
      return "<path " + cls + " d=\"" + d + "\">" + title + "</path>";
    }
    case Footprint::Kind::half_space:
      return "";
    case Footprint::Kind::polygon: {
      std::string points;
      for (const Point p : f.polygon)
        points.append(points.empty() ? "" : " ").append(point(p));
      return "<polygon " + cls + " points=\"" + points + "\">" + title + "</polygon>";
    }
    case Footprint::Kind::capsule: {
      // The core segment offset by +-radius along its normal, joined by two half circles.
      const Fixed dx = f.b.x - f.a.x, dz = f.b.z - f.a.z, length = hypot(dx, dz);
      const Point n{-(dz / length) * f.radius, (dx / length) * f.radius};
      const std::string arc = " A" + dec3(f.radius) + " " + dec3(f.radius) + " 0 0 0 ";
      return "<path " + cls + " d=\"M" + point({f.a.x + n.x, f.a.z + n.z}) + " L" +
             point({f.b.x + n.x, f.b.z + n.z}) + arc + point({f.b.x - n.x, f.b.z - n.z}) + " L" +
             point({f.a.x - n.x, f.a.z - n.z}) + arc + point({f.a.x + n.x, f.a.z + n.z}) + "Z\">" +
             title + "</path>";
    }
    default:
      return "<circle " + cls + " cx=\"" + dec3(f.a.x) + "\" cy=\"" + dec3(f.a.z) + "\" r=\"" +
             dec3(f.radius) + "\">" + title + "</circle>";
  }
}

/// One body's element: a few dozen bytes of markup, since scenes can hold thousands of bodies.
std::string body_svg(const ScenePose& body, const Footprint& f) {
  const char* type = body.type == BodyType::static_body ? "s"
                     : body.type == BodyType::kinematic ? "k"
                                                        : "d";
  const std::string cls = std::string("class=\"") + type + (body.differs ? " x\"" : "\"");
  const std::string what = body.id == 0 ? "particle" : "body " + std::to_string(body.id);
  const std::string title =
      "<title>" + what + " (" + dec3(body.position.x) + ", " + dec3(body.position.z) + ")</title>";
  return footprint_svg(cls, title, f);
}

void scene_panel(std::string& out, const std::string& caption, const std::vector<ScenePose>& scene,
                 const std::vector<Footprint>& prints, const Bounds& view, Fixed font) {
  const Fixed width = view.max_x - view.min_x, height = view.max_z - view.min_z;
  out += "<figure><figcaption>" + caption + "</figcaption><svg class=\"scene\" viewBox=\"" +
         dec3(view.min_x) + " " + dec3(view.min_z) + " " + dec3(width) + " " + dec3(height) +
         "\" font-size=\"" + dec3(font) + "\"><path class=\"axis\" d=\"M" + dec3(view.min_x) +
         " 0H" + dec3(view.max_x) + "M0 " + dec3(view.min_z) + "V" + dec3(view.max_z) + "\"/>";
  std::size_t planes = 0;
  std::string labels;
  for (const bool highlighted : {false, true}) {  // differing bodies on top
    for (std::size_t i = 0; i < scene.size(); ++i) {
      if (scene[i].differs != highlighted) continue;
      if (prints[i].type == Footprint::Kind::half_space) {
        ++planes;
        continue;
      }
      out += body_svg(scene[i], prints[i]);
      if (!highlighted) continue;
      Bounds b;
      add_bounds(b, prints[i]);
      labels += "<text class=\"lbl\" x=\"" + dec3(b.max_x) + "\" y=\"" + dec3(b.min_z) + "\">" +
                std::to_string(scene[i].id) + "</text>";
    }
  }
  out += "<g class=\"lbl\" stroke-width=\"" + dec3(font >> 3) + "\">" + labels + "</g></svg>";
  if (scene.empty()) out += "<p class=\"note\">No bodies.</p>";
  if (planes != 0)
    out += "<p class=\"note\">" + std::to_string(planes) + " plane(s) not drawn.</p>";
  out += "</figure>";
}

}  // namespace

void scene_section(std::string& out, const BisectResult& r) {
  if (r.scene_a.empty() && r.scene_b.empty()) return;
  std::vector<Footprint> prints_a, prints_b;
  Bounds view;
  for (const auto& [scene, prints] : {std::pair{&r.scene_a, &prints_a}, {&r.scene_b, &prints_b}}) {
    for (const ScenePose& body : *scene) {
      prints->push_back(footprint(body));
      add_bounds(view, prints->back());
    }
  }
  if (view.empty()) view.add({}, Fixed::from_int(10));
  // One view for both panels: a 5% margin, at least 0.1 m, and an aspect between 1:1 and 16:9.
  const Fixed tenth = Fixed::from_raw(Fixed::one_raw / 10);
  Fixed width = max(view.max_x - view.min_x, tenth), height = max(view.max_z - view.min_z, tenth);
  const Fixed margin = max(width, height) / Fixed::from_int(20);
  width = max(width + 2 * margin, height * Fixed::from_int(9) / Fixed::from_int(16));
  height = max(height + 2 * margin, width * Fixed::from_int(9) / Fixed::from_int(16));
  width = max(width, height);
  const Point centre{(view.min_x >> 1) + (view.max_x >> 1), (view.min_z >> 1) + (view.max_z >> 1)};
  view.min_x = centre.x - (width >> 1);
  view.max_x = view.min_x + width;
  view.min_z = centre.z - (height >> 1);
  view.max_z = view.min_z + height;
  const Fixed font = width / Fixed::from_int(45);
  const std::string frame = r.diff_frame ? std::to_string(*r.diff_frame) : "?";
  out += "<h2>Scene at frame " + frame + " (top-down: x right, z down)</h2><div class=\"scenes\">";
  const auto caption = [](const char* side, const std::string& file, const std::string& source) {
    return side + escape(file) + (source.empty() ? "" : " (" + escape(source) + ")");
  };
  scene_panel(out, caption("A: ", r.a, r.diff_source_a), r.scene_a, prints_a, view, font);
  scene_panel(out, caption("B: ", r.b, r.diff_source_b), r.scene_b, prints_b, view, font);
  out += "</div>";
}

}  // namespace detsim::replay::html_detail
