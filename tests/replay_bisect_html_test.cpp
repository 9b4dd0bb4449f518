// The bisection report page (replay/bisect.hpp, bisect_html): self-contained, escaped, every
// outcome in words, the timeline's differing spans visible however short, and the scene plot's
// geometry (a rotated box's footprint, a capsule's outline) checked from the printed numbers.
#include <gtest/gtest.h>

#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <detsim/fixed/math.hpp>
#include <detsim/fixed/quat.hpp>
#include <detsim/replay/bisect.hpp>

namespace detsim {
namespace {

using replay::AgreementSpan;
using replay::BisectOutcome;
using replay::BisectResult;
using replay::ScenePose;

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

ScenePose pose(std::uint32_t id, BodyType type, Shape shape, Vec3 position, Quat orientation = {}) {
  ScenePose p;
  p.id = id;
  p.type = type;
  p.shape = shape;
  p.position = position;
  p.orientation = orientation;
  return p;
}

Vec3 at(int x, int y, int z) {
  return {Fixed::from_int(x), Fixed::from_int(y), Fixed::from_int(z)};
}

/// A diverged result at frame 1000 of a 1200-frame match, with a scene of every shape.
BisectResult diverged() {
  BisectResult r;
  r.outcome = BisectOutcome::diverged;
  r.a = "runs/<a&b>.replay";
  r.b = "peer \"B\".report";
  r.a_kind = "replay";
  r.b_kind = "desync report";
  r.players = 2;
  r.input_size = 2;
  r.frames_a = 1200;
  r.frames_b = 1200;
  r.first_divergent_frame = 1000;
  r.last_agreed_frame = 999;
  r.exact = true;
  r.hashes_a.total = 0xDEADBEEF;
  r.hashes_b.total = 0x0123456789ABCDEF;
  r.subsystems = {"bodies", "contacts"};
  r.local_agrees_with = "A";
  r.diff_frame = 1000;
  r.diff_source_a = "keyframe";
  r.diff_source_b = "desync report";
  r.diffs = {{"bodies", 5, "position.y", "0.5 (0x0000000080000000)", "0.25 (0x0000000040000000)"},
             {"contacts", 5, "contact[7].touching", "it's <true>", "false & more"}};
  r.diffs_omitted = 3;
  r.advice = "detsim verify B.replay --at 1000 > out.txt";
  r.notes = {"re-simulated frames 999..1000"};
  r.inputs_between = {{1000, {0x01, 0x02, 0xAB, 0xCD}}};
  r.timeline = {{0, 999, AgreementSpan::State::agree}, {1000, 1200, AgreementSpan::State::differ}};
  const Quat quarter_turn_y = from_axis_angle(Vec3::unit_y(), Fixed::pi() >> 2);
  const Quat half_turn_z = from_axis_angle(Vec3::unit_z(), Fixed::half_pi());
  r.scene_a = {
      pose(1, BodyType::dynamic, Shape::sphere(Fixed::one()), at(0, 1, 0)),
      pose(2, BodyType::kinematic, Shape::box({Fixed::one(), Fixed::half(), Fixed::one()}),
           at(10, 0, 5), quarter_turn_y),
      pose(3, BodyType::dynamic, Shape::capsule(Fixed::half(), Fixed::one()), at(-5, 0, 0),
           half_turn_z),
      pose(4, BodyType::static_body, Shape::plane(), at(0, 0, 0)),
      pose(5, BodyType::dynamic, Shape::sphere(Fixed::half()), at(2, 3, -4)),
      pose(6, BodyType::dynamic, Shape::capsule(Fixed::half(), Fixed::one()), at(3, 0, 3)),
  };
  r.scene_a[4].differs = true;
  r.scene_b = r.scene_a;
  r.scene_b[4].position = at(2, 3, -3);
  return r;
}

/// The opening tag of the body element whose hover title starts "body <id> (" (the title follows
/// its opening tag directly), or "" when there is none.
std::string body_tag(const std::string& html, std::uint32_t id) {
  const std::size_t title = html.find("<title>body " + std::to_string(id) + " (");
  if (title == std::string::npos) return "";
  const std::size_t open = html.rfind('<', title - 1);
  return html.substr(open, title - open);
}

TEST(BisectHtml, IsOneSelfContainedPage) {
  const std::string html = replay::bisect_html(diverged());
  EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0U) << html.substr(0, 40);
  EXPECT_TRUE(contains(html, "<title>detsim bisect</title>"));
  EXPECT_TRUE(contains(html, "</html>"));
  for (const char* outside : {"http://", "https://", "src=", "<link", "<script", "url("})
    EXPECT_FALSE(contains(html, outside)) << outside;
}

TEST(BisectHtml, EscapesEveryTextFromTheResult) {
  const std::string html = replay::bisect_html(diverged());
  EXPECT_TRUE(contains(html, "runs/&lt;a&amp;b&gt;.replay"));
  EXPECT_FALSE(contains(html, "<a&b>"));
  EXPECT_TRUE(contains(html, "peer &quot;B&quot;.report"));
  EXPECT_TRUE(contains(html, "it&#39;s &lt;true&gt;"));
  EXPECT_TRUE(contains(html, "false &amp; more"));
  EXPECT_TRUE(contains(html, "<code>detsim verify B.replay --at 1000 &gt; out.txt</code>"));
}

TEST(BisectHtml, SummaryAndTables) {
  const std::string html = replay::bisect_html(diverged());
  EXPECT_TRUE(contains(html, "Diverged at frame 1000</b> (exact)"));
  EXPECT_TRUE(contains(html, "00000000deadbeef / 0123456789abcdef"));
  EXPECT_TRUE(contains(html, "bodies, contacts"));
  EXPECT_TRUE(contains(html, "re-simulated frames 999..1000"));
  EXPECT_TRUE(contains(html,
                       "<td>bodies</td><td>5</td><td class=\"mono\">position.y</td>"
                       "<td class=\"mono\">0.5 (0x0000000080000000)</td>"
                       "<td class=\"mono\">0.25 (0x0000000040000000)</td>"));
  EXPECT_TRUE(contains(html, "contact[7].touching"));
  EXPECT_TRUE(contains(html, "3 more differences omitted"));
  // One column per player, input_size bytes each, in hex.
  EXPECT_TRUE(contains(html, "<th>Player 1</th>"));
  EXPECT_TRUE(
      contains(html, "<td>1000</td><td class=\"mono\">0102</td><td class=\"mono\">abcd</td>"));
}

TEST(BisectHtml, InexactDivergenceGivesTheRange) {
  BisectResult r = diverged();
  r.exact = false;
  r.last_agreed_frame = 900;
  EXPECT_TRUE(contains(replay::bisect_html(r), "first divergent frame is between 901 and 1000"));
}

TEST(BisectHtml, TimelineShowsTheDifferingSpanAndTheMarker) {
  const std::string html = replay::bisect_html(diverged());
  EXPECT_TRUE(contains(html, "<title>frames 0..999: agree</title>"));
  EXPECT_TRUE(contains(html, "<title>frames 1000..1200: differ</title>"));
  // 1000 of 1201 frames across the 980-pixel bar: x = 10 + 980 * 1000 / 1201 = 825.9 px.
  EXPECT_TRUE(contains(html, "<rect class=\"differ\" x=\"825.9\" y=\"26\" width=\"164.1\""));
  EXPECT_TRUE(contains(html, "first divergent frame 1000</text>"));
  EXPECT_TRUE(contains(html, ">1200</text>"));
}

TEST(BisectHtml, ShortSpansStayVisible) {
  BisectResult r = diverged();
  r.frames_a = r.frames_b = 215999;
  r.first_divergent_frame = 100000;
  r.timeline = {{0, 99999, AgreementSpan::State::agree},
                {100000, 100000, AgreementSpan::State::differ},
                {100001, 215998, AgreementSpan::State::agree},
                {215999, 215999, AgreementSpan::State::unknown}};
  const std::string html = replay::bisect_html(r);
  const std::regex span(
      R"re(<rect class="(differ|unknown)" x="([0-9.]+)" y="26" width="([0-9.]+)")re");
  int found = 0;
  for (std::sregex_iterator it(html.begin(), html.end(), span), end; it != end; ++it, ++found) {
    EXPECT_EQ((*it)[3].str(), "2.5") << (*it)[0].str();
    if ((*it)[1].str() == "unknown") {
      EXPECT_EQ((*it)[2].str(), "987.5") << "kept inside the bar";
    }
  }
  EXPECT_EQ(found, 2);
}

TEST(BisectHtml, SceneDrawsEveryBodyWithItsShape) {
  const std::string html = replay::bisect_html(diverged());
  for (const std::uint32_t id : {1U, 2U, 3U, 5U, 6U}) {
    const std::string title = "<title>body " + std::to_string(id) + " (";
    std::size_t count = 0;
    for (std::size_t at = html.find(title); at != std::string::npos; at = html.find(title, at + 1))
      ++count;
    EXPECT_EQ(count, 2U) << "once in each panel: body " << id;
  }
  EXPECT_EQ(body_tag(html, 4), "") << "planes are not drawn";
  EXPECT_TRUE(contains(html, "1 plane(s) not drawn"));
  EXPECT_EQ(body_tag(html, 1), "<circle class=\"d\" cx=\"0\" cy=\"0\" r=\"1\">");
  EXPECT_TRUE(contains(html, "<title>body 1 (0, 0)</title>"));
  // A capsule standing upright is seen end-on: a circle of its radius.
  EXPECT_EQ(body_tag(html, 6), "<circle class=\"d\" cx=\"3\" cy=\"3\" r=\"0.5\">");
}

// Bodies of registered geometry come with their world's outline (World::body_outline): a surface
// is drawn as its triangles, a compound as its parts, each part with the body's class and title.
TEST(BisectHtml, SurfacesAndCompoundsAreDrawnFromTheirOutlines) {
  BisectResult r = diverged();
  ScenePose mesh = pose(7, BodyType::static_body, Shape{}, at(0, 0, 0));
  ShapeOutline surface;
  surface.triangles = {{at(0, 0, 0), at(4, 0, 0), at(0, 0, 4)},
                       {at(4, 0, 0), at(4, 1, 4), at(0, 0, 4)}};
  surface.surface_triangles = 2;
  surface.points = {at(0, 0, 0), at(4, 1, 4)};
  mesh.outline = surface;
  ScenePose table = pose(8, BodyType::dynamic, Shape{}, at(6, 1, 6));
  ShapeOutline top;
  top.points = {at(5, 1, 5), at(7, 1, 5), at(7, 1, 7), at(5, 1, 7)};
  ShapeOutline leg;
  leg.points = {at(6, 0, 6)};
  leg.radius = Fixed::half();
  table.outline = ShapeOutline{};
  table.outline->parts = {top, leg};
  table.differs = true;
  r.scene_a.push_back(mesh);
  r.scene_a.push_back(table);
  r.scene_b = r.scene_a;
  const std::string html = replay::bisect_html(r);
  EXPECT_EQ(body_tag(html, 7), "<path class=\"s\" d=\"M0,0L4,0L0,4ZM4,0L4,4L0,4Z\">");
  // The compound: its top as a polygon, then its leg as a circle, both titled body 8.
  EXPECT_EQ(body_tag(html, 8).rfind("<polygon class=\"d x\" points=\"", 0), 0U)
      << body_tag(html, 8);
  EXPECT_TRUE(contains(html, "<circle class=\"d x\" cx=\"6\" cy=\"6\" r=\"0.5\"><title>body 8 ("))
      << html;
  std::size_t titles = 0;
  for (std::size_t at = html.find("<title>body 8 ("); at != std::string::npos;
       at = html.find("<title>body 8 (", at + 1))
    ++titles;
  EXPECT_EQ(titles, 4U) << "two parts in each panel";
}

TEST(BisectHtml, RotatedBoxFootprint) {
  // Half extents (1, 0.5, 1) turned 45 degrees about y: a diamond of half diagonal sqrt(2).
  const std::string tag = body_tag(replay::bisect_html(diverged()), 2);
  const std::regex points_attribute(R"re(<polygon class="k" points="([^"]*)">)re");
  std::smatch m;
  ASSERT_TRUE(std::regex_match(tag, m, points_attribute)) << tag;
  std::istringstream in(m[1].str());
  std::set<std::string> corners;
  for (std::string corner; in >> corner;)
    corners.insert(corner);
  EXPECT_EQ(corners, (std::set<std::string>{"8.586,5", "10,3.586", "11.414,5", "10,6.414"}))
      << m[1].str();
}

TEST(BisectHtml, CapsuleLyingAlongX) {
  // Turned 90 degrees about z, the core runs from x = -4 to x = -6 at z = 0: a 0.5-wide stadium.
  EXPECT_EQ(body_tag(replay::bisect_html(diverged()), 3),
            "<path class=\"d\" d=\"M-4,-0.5 L-6,-0.5 A0.5 0.5 0 0 0 -6,0.5 L-4,0.5 A0.5 0.5 0 0 0 "
            "-4,-0.5Z\">");
}

TEST(BisectHtml, DifferingBodyIsHighlightedAndLabelled) {
  const std::string html = replay::bisect_html(diverged());
  EXPECT_EQ(body_tag(html, 5), "<circle class=\"d x\" cx=\"2\" cy=\"-4\" r=\"0.5\">");
  EXPECT_EQ(body_tag(html, 1).find(" x\""), std::string::npos);
  EXPECT_TRUE(contains(html, ".scene .x{stroke:#d00;stroke-width:3}"));
  EXPECT_TRUE(contains(html, "<text class=\"lbl\" x=\"2.5\" y=\"-4.5\">5</text>"));
  // Panel B draws the body where B has it.
  EXPECT_TRUE(contains(html, "<circle class=\"d x\" cx=\"2\" cy=\"-3\" r=\"0.5\">"));
}

TEST(BisectHtml, OneViewFitsBothScenes) {
  // x from -6.5 (capsule end) to 11.414 (box corner), z from -4.5 (body 5 in A) to 6.414.
  const std::string html = replay::bisect_html(diverged());
  const std::regex view_box(R"re(viewBox="(-?[0-9.]+) (-?[0-9.]+) ([0-9.]+) ([0-9.]+)")re");
  std::vector<std::string> boxes;
  for (std::sregex_iterator it(html.begin(), html.end(), view_box), end; it != end; ++it)
    if ((*it)[3].str() != "1000") boxes.push_back((*it)[0].str());
  ASSERT_EQ(boxes.size(), 2U);
  EXPECT_EQ(boxes[0], boxes[1]);
  // Width 17.914 plus a margin of 5% of it each side: 19.706; the height 10.914 gets the same
  // margins: 12.706.
  EXPECT_TRUE(contains(boxes[0], " 19.706 12.706\"")) << boxes[0];
}

TEST(BisectHtml, EmptyAndDegenerateScenes) {
  BisectResult r = diverged();
  r.scene_a = {pose(4, BodyType::static_body, Shape::plane(), at(0, 0, 0))};
  r.scene_b.clear();
  std::string html = replay::bisect_html(r);
  EXPECT_TRUE(contains(html, "viewBox=\"-11 -11 22 22\"")) << "a default view";
  EXPECT_TRUE(contains(html, "1 plane(s) not drawn"));
  EXPECT_TRUE(contains(html, "No bodies."));
  // A point-sized body: a view of finite, nonzero size.
  r.scene_a = {pose(9, BodyType::dynamic, Shape::box({}), at(0, 0, 0))};
  html = replay::bisect_html(r);
  EXPECT_TRUE(contains(html, "viewBox=\"-0.055 -0.055 0.11 0.11\"")) << html;
  EXPECT_FALSE(body_tag(html, 9).empty());
  // No scenes at all: no scene section.
  r.scene_a.clear();
  EXPECT_FALSE(contains(replay::bisect_html(r), "class=\"scene\""));
}

TEST(BisectHtml, OtherOutcomesInWords) {
  BisectResult identical;
  identical.a = "a.replay";
  identical.b = "b.replay";
  identical.frames_a = identical.frames_b = 60;
  identical.timeline = {{0, 60, AgreementSpan::State::agree}};
  const std::string same = replay::bisect_html(identical);
  EXPECT_TRUE(contains(same, "<b>Identical</b>"));
  EXPECT_FALSE(contains(same, "class=\"differ\""));
  EXPECT_FALSE(contains(same, "first divergent frame 0"));

  BisectResult inputs;
  inputs.outcome = BisectOutcome::inputs_differ;
  inputs.input_frame = 77;
  inputs.input_player = 1;
  inputs.input_a = "0a00";
  inputs.input_b = "0b00";
  EXPECT_TRUE(contains(replay::bisect_html(inputs),
                       "Inputs differ at frame 77</b> (player 1: 0a00 vs 0b00)"));

  BisectResult runs;
  runs.outcome = BisectOutcome::different_runs;
  runs.fingerprint_differences = {"seed: 1 vs 2", "scenario: <stack> vs arena"};
  const std::string different = replay::bisect_html(runs);
  EXPECT_TRUE(contains(different, "<b>Different runs</b>"));
  EXPECT_TRUE(contains(different, "<li>seed: 1 vs 2</li>"));
  EXPECT_TRUE(contains(different, "<li>scenario: &lt;stack&gt; vs arena</li>"));
}

}  // namespace
}  // namespace detsim
