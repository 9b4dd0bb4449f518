// bisect_html (bisect.hpp): one self-contained HTML page of a bisection result.
//
// Everything is inline (CSS, SVG; no scripts, fonts or links) so the page opens offline and can be
// attached to a bug report. The outcome, summary, timeline and tables are built here; the scene
// plot is in bisect_html_scene.cpp. No floating point: the timeline's coordinates are integer
// tenths of a pixel, the scene's are Fixed printed to 3 decimals.
#include <algorithm>
#include <cinttypes>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <string_view>

#include <detsim/replay/bisect.hpp>

#include "bisect_html_detail.hpp"

namespace detsim::replay {

namespace html_detail {

std::string escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    const std::string_view entity = c == '&'    ? "&amp;"
                                    : c == '<'  ? "&lt;"
                                    : c == '>'  ? "&gt;"
                                    : c == '"'  ? "&quot;"
                                    : c == '\'' ? "&#39;"
                                                : std::string_view(&c, 1);
    out += entity;
  }
  return out;
}

}  // namespace html_detail

namespace {

using html_detail::escape;

constexpr std::string_view kStyle = R"(
body{font:14px/1.4 system-ui,sans-serif;margin:24px auto;max-width:1300px;padding:0 16px;color:#222}
h1{margin:0 0 8px}h2{margin:28px 0 8px;font-size:18px;border-bottom:1px solid #ddd}
table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:3px 8px;text-align:left;
vertical-align:top}th{background:#f2f2f2}.kv th{white-space:nowrap}td ul{margin:0;padding-left:18px}
code,.mono{font-family:monospace}
.outcome{font-size:16px;padding:8px 12px;border-radius:4px;background:#eef6ee;border:1px solid #9c9}
.o-bad{background:#fbeeee;border-color:#d99}.note{color:#666}
.timeline,.scene{width:100%;height:auto;display:block}.scene{background:#fcfcfc;border:1px solid #ccc}
.scenes{display:flex;gap:16px}.scenes figure{flex:1;margin:0;min-width:0}
figcaption{font-weight:bold;margin-bottom:4px}
.s,.k,.d,.axis{vector-effect:non-scaling-stroke;fill-opacity:.85}
.s{fill:#bbb;stroke:#777}.k{fill:#e8c36a;stroke:#a07a1a}.d{fill:#8fb4e6;stroke:#2c5d99}
.scene .x{stroke:#d00;stroke-width:3}.axis{stroke:#ddd;fill:none}
.lbl{fill:#b00;font-weight:bold;paint-order:stroke;stroke:#fff}
.agree{fill:#4a4}.differ{fill:#d33}.unknown{fill:#bbb}
.sw{display:inline-block;width:14px;height:14px;vertical-align:middle;margin:0 4px 0 14px;
border:1px solid #777}.sw.x{border:3px solid #d00;background:#8fb4e6}
)";

std::string html_hex(std::uint64_t v) {
  char buffer[17];
  std::snprintf(buffer, sizeof buffer, "%016" PRIx64, v);
  return buffer;
}

std::string frame_or_dash(const std::optional<std::uint64_t>& frame) {
  return frame ? std::to_string(*frame) : "&mdash;";
}

// ---- Outcome and summary ----------------------------------------------------------------------

std::string outcome_html(const BisectResult& r) {
  switch (r.outcome) {
    case BisectOutcome::identical:
      return "<b>Identical</b>: every frame both sides hold agrees.";
    case BisectOutcome::diverged: {
      const std::string f = frame_or_dash(r.first_divergent_frame);
      if (r.exact) return "<b>Diverged at frame " + f + "</b> (exact).";
      const std::string from =
          r.last_agreed_frame ? std::to_string(*r.last_agreed_frame + 1) : std::string("0");
      return "<b>Diverged</b>: the first divergent frame is between " + from + " and " + f +
             " (frames between have no hash on one side).";
    }
    case BisectOutcome::inputs_differ:
      return "<b>Inputs differ at frame " + std::to_string(r.input_frame) + "</b> (player " +
             std::to_string(r.input_player) + ": " + escape(r.input_a) + " vs " +
             escape(r.input_b) + "): the two records are not the same match, not a desync.";
    case BisectOutcome::different_runs: {
      std::string out = "<b>Different runs</b>: the fingerprints differ.<ul>";
      for (const std::string& d : r.fingerprint_differences)
        out += "<li>" + escape(d) + "</li>";
      return out + "</ul>";
    }
  }
  return "unknown outcome";
}

void row(std::string& out, std::string_view name, const std::string& value_html) {
  out.append("<tr><th>").append(name).append("</th><td>").append(value_html).append("</td></tr>");
}

void summary(std::string& out, const BisectResult& r) {
  out += "<h2>Summary</h2><table class=\"kv\">";
  row(out, "Frames held",
      "A: 0.." + std::to_string(r.frames_a) + ", B: 0.." + std::to_string(r.frames_b));
  row(out, "First divergent frame",
      frame_or_dash(r.first_divergent_frame) +
          (r.first_divergent_frame && r.exact ? " (exact)" : ""));
  row(out, "Last agreed frame", frame_or_dash(r.last_agreed_frame));
  std::string subsystems;
  for (const std::string& s : r.subsystems)
    subsystems += (subsystems.empty() ? "" : ", ") + escape(s);
  row(out, "Differing subsystems", subsystems.empty() ? "&mdash;" : subsystems);
  row(out, "State hashes A / B",
      "<span class=\"mono\">" + html_hex(r.hashes_a.total) + " / " + html_hex(r.hashes_b.total) +
          "</span>");
  row(out, "Local re-simulation agrees with",
      r.local_agrees_with.empty() ? "(nothing re-simulated)" : escape(r.local_agrees_with));
  row(out, "Diff frame", frame_or_dash(r.diff_frame));
  if (!r.diff_source_a.empty() || !r.diff_source_b.empty())
    row(out, "Diff sources", "A: " + escape(r.diff_source_a) + ", B: " + escape(r.diff_source_b));
  if (!r.advice.empty()) row(out, "Advice", "<code>" + escape(r.advice) + "</code>");
  if (!r.notes.empty()) {
    std::string notes = "<ul>";
    for (const std::string& n : r.notes)
      notes += "<li>" + escape(n) + "</li>";
    row(out, "Notes", notes + "</ul>");
  }
  out += "</table>";
}

// ---- Timeline ---------------------------------------------------------------------------------

constexpr std::uint64_t kBarLeft = 100;  // tenths of a pixel in a 1000-pixel-wide drawing
constexpr std::uint64_t kBarRight = 9900;
constexpr std::uint64_t kMinSpan = 25;  // a differ/unknown span is at least 2.5 px wide

/// Frame `f` of `total` frames as an x coordinate in tenths of a pixel.
std::uint64_t frame_x(std::uint64_t f, std::uint64_t total) {
  while (total > (std::uint64_t{1} << 40)) {  // keeps f * width within 64 bits
    total >>= 1;
    f >>= 1;
  }
  return kBarLeft + std::min(f, total) * (kBarRight - kBarLeft) / total;
}

std::string tenths(std::uint64_t v) {
  std::string out = std::to_string(v / 10);
  if (v % 10 != 0) out.append(1, '.').append(1, static_cast<char>('0' + v % 10));
  return out;
}

void timeline(std::string& out, const BisectResult& r) {
  out += "<h2>Agreement timeline</h2>";
  if (r.timeline.empty()) {
    out += "<p class=\"note\">No frames to show.</p>";
    return;
  }
  const std::uint64_t last = std::max(r.frames_a, r.frames_b);
  const std::uint64_t total = last == std::numeric_limits<std::uint64_t>::max() ? last : last + 1;
  out += "<svg class=\"timeline\" viewBox=\"0 0 1000 70\" font-size=\"12\">";
  // Agreeing spans first, so that a widened differ/unknown span is drawn over its neighbours.
  for (const int pass : {0, 1}) {
    for (const AgreementSpan& s : r.timeline) {
      if ((s.state == AgreementSpan::State::agree) != (pass == 0)) continue;
      std::uint64_t x0 = frame_x(s.first, total);
      std::uint64_t x1 = std::max(frame_x(s.last + 1, total), x0);
      if (pass == 1 && x1 - x0 < kMinSpan) {
        x1 = std::min(x0 + kMinSpan, kBarRight);
        x0 = x1 - kMinSpan;
      }
      const char* state = s.state == AgreementSpan::State::agree    ? "agree"
                          : s.state == AgreementSpan::State::differ ? "differ"
                                                                    : "unknown";
      out += "<rect class=\"" + std::string(state) + "\" x=\"" + tenths(x0) +
             "\" y=\"26\" width=\"" + tenths(x1 - x0) + "\" height=\"20\"><title>frames " +
             std::to_string(s.first) + ".." + std::to_string(s.last) + ": " + state +
             "</title></rect>";
    }
  }
  out +=
      "<text x=\"10\" y=\"64\" text-anchor=\"start\">0</text><text x=\"990\" y=\"64\" "
      "text-anchor=\"end\">" +
      std::to_string(last) + "</text>";
  if (r.first_divergent_frame) {
    const std::uint64_t x = frame_x(*r.first_divergent_frame, total);
    const char* anchor = x < 2000 ? "start" : x > 8000 ? "end" : "middle";
    out += "<path d=\"M" + tenths(x) + " 20V52\" stroke=\"#000\" stroke-width=\"2\"/><text x=\"" +
           tenths(x) + "\" y=\"15\" text-anchor=\"" + anchor + "\">first divergent frame " +
           std::to_string(*r.first_divergent_frame) + "</text>";
  }
  out += "</svg>";
}

// ---- Tables -----------------------------------------------------------------------------------

void diff_table(std::string& out, const BisectResult& r) {
  out += "<h2>Field differences" +
         (r.diff_frame ? " at frame " + std::to_string(*r.diff_frame) : std::string()) + "</h2>";
  if (r.diffs.empty()) {
    out += "<p class=\"note\">No field-level diff.</p>";
    return;
  }
  out += "<table><tr><th>Subsystem</th><th>Body</th><th>Field</th><th>A</th><th>B</th></tr>";
  for (const FieldDiff& d : r.diffs) {
    out += "<tr><td>" + escape(d.subsystem) + "</td><td>" +
           (d.body != 0 ? std::to_string(d.body) : std::string()) + "</td><td class=\"mono\">" +
           escape(d.field) + "</td><td class=\"mono\">" + escape(d.a) + "</td><td class=\"mono\">" +
           escape(d.b) + "</td></tr>";
  }
  out += "</table>";
  if (r.diffs_omitted != 0)
    out +=
        "<p class=\"note\">" + std::to_string(r.diffs_omitted) + " more differences omitted.</p>";
}

void inputs_table(std::string& out, const BisectResult& r) {
  if (r.inputs_between.empty()) return;
  out +=
      "<h2>Inputs between the last agreed and the first divergent frame</h2><table><tr>"
      "<th>Frame</th>";
  const std::size_t size = r.input_size;
  const bool split = r.players != 0 && size != 0;
  for (std::uint32_t p = 0; split && p < r.players; ++p)
    out += "<th>Player " + std::to_string(p) + "</th>";
  out += split ? "</tr>" : "<th>Inputs</th></tr>";
  for (const FrameInputsRecord& f : r.inputs_between) {
    out += "<tr><td>" + std::to_string(f.frame) + "</td><td class=\"mono\">";
    for (std::size_t i = 0; i < f.inputs.size(); ++i) {
      if (split && i != 0 && i % size == 0) out += "</td><td class=\"mono\">";
      char byte[3];
      std::snprintf(byte, sizeof byte, "%02x", f.inputs[i]);
      out += byte;
    }
    out += "</td></tr>";
  }
  out += "</table>";
}

void legend(std::string& out) {
  out +=
      "<h2>Legend</h2><p>Timeline:<span class=\"sw\" style=\"background:#4a4\"></span>hashes "
      "agree<span class=\"sw\" style=\"background:#d33\"></span>differ<span class=\"sw\" "
      "style=\"background:#bbb\"></span>unknown (a side holds no hash)</p><p>Scene:"
      "<span class=\"sw\" style=\"background:#bbb\"></span>static<span class=\"sw\" "
      "style=\"background:#e8c36a\"></span>kinematic<span class=\"sw\" style=\"background:"
      "#8fb4e6\"></span>dynamic<span class=\"sw x\"></span>differs (labelled with its ID). "
      "Hover a body for its ID and position.</p>";
}

}  // namespace

std::string bisect_html(const BisectResult& result) {
  std::string out =
      "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
      "<title>detsim bisect</title><style>";
  out += kStyle;
  out += "</style></head><body><h1>detsim bisect</h1><p>A: <b class=\"mono\">" + escape(result.a) +
         "</b> (" + escape(result.a_kind) + ")<br>B: <b class=\"mono\">" + escape(result.b) +
         "</b> (" + escape(result.b_kind) + ")</p>";
  const bool bad = result.outcome != BisectOutcome::identical;
  out += std::string("<div class=\"outcome") + (bad ? " o-bad" : "") + "\">" +
         outcome_html(result) + "</div>";
  summary(out, result);
  timeline(out, result);
  diff_table(out, result);
  inputs_table(out, result);
  html_detail::scene_section(out, result);
  legend(out);
  out += "</body></html>\n";
  return out;
}

}  // namespace detsim::replay
