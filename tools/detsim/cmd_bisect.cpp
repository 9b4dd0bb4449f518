// detsim bisect: two records of the same match (replays and/or desync reports) to the first
// divergent frame, the differing subsystems, bodies and fields, the last agreed frame and the
// inputs in between (replay/bisect.hpp does the work; this prints it).
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <detsim/replay/bisect.hpp>

#include "commands.hpp"
#include "diff_output.hpp"
#include "output.hpp"

namespace detsim::cli {

namespace {

const char* outcome_name(replay::BisectOutcome o) {
  switch (o) {
    case replay::BisectOutcome::identical:
      return "identical";
    case replay::BisectOutcome::diverged:
      return "diverged";
    case replay::BisectOutcome::inputs_differ:
      return "inputs_differ";
    case replay::BisectOutcome::different_runs:
      return "different_runs";
  }
  return "unknown";
}

const char* span_name(replay::AgreementSpan::State s) {
  switch (s) {
    case replay::AgreementSpan::State::agree:
      return "agree";
    case replay::AgreementSpan::State::differ:
      return "differ";
    case replay::AgreementSpan::State::unknown:
      return "unknown";
  }
  return "unknown";
}

std::string inputs_hex(const replay::BisectResult& r, const replay::FrameInputsRecord& f) {
  static constexpr char digits[] = "0123456789abcdef";
  std::string out;
  for (std::size_t i = 0; i < f.inputs.size(); ++i) {
    if (r.input_size != 0 && i % r.input_size == 0)
      out += (i == 0 ? "p0 " : " p" + std::to_string(i / r.input_size) + " ");
    out += digits[f.inputs[i] >> 4];
    out += digits[f.inputs[i] & 15];
  }
  return out;
}

std::vector<std::string> quoted(const std::vector<std::string>& items) {
  std::vector<std::string> out;
  for (const std::string& s : items)
    out.push_back(Json::quote(s));
  return out;
}

void print_json(const replay::BisectResult& r, const std::string& html, double seconds) {
  std::vector<std::string> diffs;
  for (const FieldDiff& f : r.diffs)
    diffs.push_back(field_json(f));
  std::vector<std::string> inputs;
  for (const replay::FrameInputsRecord& f : r.inputs_between)
    inputs.push_back(Json().num("frame", f.frame).str("inputs", inputs_hex(r, f)).text());
  std::vector<std::string> spans;
  for (const replay::AgreementSpan& s : r.timeline)
    spans.push_back(
        Json().num("first", s.first).num("last", s.last).str("state", span_name(s.state)).text());
  Json j;
  j.str("outcome", outcome_name(r.outcome))
      .str("a", r.a)
      .str("b", r.b)
      .str("a_kind", r.a_kind)
      .str("b_kind", r.b_kind)
      .num("frames_a", r.frames_a)
      .num("frames_b", r.frames_b)
      .frame("first_divergent_frame", r.first_divergent_frame)
      .frame("last_agreed_frame", r.last_agreed_frame)
      .boolean("exact", r.exact)
      .raw("subsystems", Json::array(quoted(r.subsystems)))
      .str("local_agrees_with", r.local_agrees_with)
      .frame("diff_frame", r.diff_frame)
      .frame("healed_frame", r.healed_frame)
      .str("diff_source_a", r.diff_source_a)
      .str("diff_source_b", r.diff_source_b)
      .raw("diffs", Json::array(diffs))
      .num("diffs_omitted", r.diffs_omitted)
      .raw("inputs_between", Json::array(inputs))
      .raw("fingerprint_differences", Json::array(quoted(r.fingerprint_differences)));
  if (r.outcome == replay::BisectOutcome::inputs_differ) {
    j.num("input_frame", r.input_frame)
        .num("input_player", r.input_player)
        .str("input_a", r.input_a)
        .str("input_b", r.input_b);
  }
  j.str("advice", r.advice)
      .raw("notes", Json::array(quoted(r.notes)))
      .raw("timeline", Json::array(spans));
  if (html.empty()) {
    j.null("html");
  } else {
    j.str("html", html);
  }
  j.real("seconds", seconds).print();
}

void print_text(const replay::BisectResult& r, const std::string& html, double seconds) {
  std::printf("A: %s (%s, frames 0 to %llu)\nB: %s (%s, frames 0 to %llu)\n", r.a.c_str(),
              r.a_kind.c_str(), static_cast<unsigned long long>(r.frames_a), r.b.c_str(),
              r.b_kind.c_str(), static_cast<unsigned long long>(r.frames_b));
  switch (r.outcome) {
    case replay::BisectOutcome::different_runs:
      std::printf("DIFFERENT RUNS: the fingerprints differ, these are not records of one match\n");
      for (const std::string& d : r.fingerprint_differences)
        std::printf("  %s\n", d.c_str());
      break;
    case replay::BisectOutcome::inputs_differ:
      std::printf("INPUTS DIFFER (not a desync): the step to frame %llu, player %u: A %s, B %s\n",
                  static_cast<unsigned long long>(r.input_frame), r.input_player, r.input_a.c_str(),
                  r.input_b.c_str());
      break;
    case replay::BisectOutcome::identical:
      std::printf("IDENTICAL: every frame both hold has the same state hash\n");
      break;
    case replay::BisectOutcome::diverged: {
      const auto first = static_cast<unsigned long long>(*r.first_divergent_frame);
      const auto agreed = static_cast<unsigned long long>(*r.last_agreed_frame);
      if (r.exact) {
        std::printf("DIVERGED at frame %llu (last agreed frame %llu)\n", first, agreed);
      } else {
        std::printf(
            "DIVERGED at frame %llu at the latest: agreed at %llu, nothing recorded "
            "between\n",
            first, agreed);
      }
      std::printf("  state hash at %llu: A %s, B %s\n", first, hex(r.hashes_a.total).c_str(),
                  hex(r.hashes_b.total).c_str());
      std::string parts;
      for (const std::string& s : r.subsystems)
        parts += (parts.empty() ? "" : ", ") + s;
      if (!parts.empty()) std::printf("  differing subsystems: %s\n", parts.c_str());
      if (!r.local_agrees_with.empty())
        std::printf("  this machine's re-simulation agrees with: %s\n",
                    r.local_agrees_with.c_str());
      for (const replay::FrameInputsRecord& f : r.inputs_between)
        std::printf("  inputs of the step to frame %llu: %s\n",
                    static_cast<unsigned long long>(f.frame), inputs_hex(r, f).c_str());
      if (r.diff_frame) {
        std::printf("field differences at frame %llu (A: %s, B: %s)%s:\n",
                    static_cast<unsigned long long>(*r.diff_frame), r.diff_source_a.c_str(),
                    r.diff_source_b.c_str(),
                    *r.diff_frame == *r.first_divergent_frame ? ""
                                                              : ", the first frame after "
                                                                "it where both are known");
        for (const FieldDiff& f : r.diffs)
          print_field(f);
        if (r.diffs_omitted != 0)
          std::printf("  ... and %zu more differences (--max shows more)\n", r.diffs_omitted);
      } else if (r.healed_frame) {
        std::printf(
            "the states are equal again at frame %llu (the divergence healed: a field the "
            "next steps overwrote): no field-level diff there\n",
            static_cast<unsigned long long>(*r.healed_frame));
      } else {
        std::printf("no frame from %llu on has both sides' states: no field-level diff\n", first);
      }
      if (!r.advice.empty())
        std::printf("for the exact frame's fields, run %s\n", r.advice.c_str());
      break;
    }
  }
  for (const std::string& n : r.notes)
    std::printf("note: %s\n", n.c_str());
  if (!html.empty()) std::printf("HTML report: %s\n", html.c_str());
  std::printf("%.2f s\n", seconds);
}

}  // namespace

int bisect_command(const BisectArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  replay::BisectOptions options;
  options.max_diffs = args.max_fields;
  auto result = replay::bisect(args.a, args.b, options);
  if (!result) return usage_error("bisect", result.message());
  const replay::BisectResult& r = result.value();
  if (!args.html.empty()) {
    const std::string page = replay::bisect_html(r);
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> out(std::fopen(args.html.c_str(), "wb"),
                                                        &std::fclose);
    if (!out || std::fwrite(page.data(), 1, page.size(), out.get()) != page.size() ||
        std::fflush(out.get()) != 0)
      return usage_error("bisect", "--html " + args.html + ": cannot write the file");
  }
  const double seconds = seconds_since(start);
  if (args.json) {
    print_json(r, args.html, seconds);
  } else {
    print_text(r, args.html, seconds);
  }
  return r.outcome == replay::BisectOutcome::identical ? exit_ok : exit_check_failed;
}

}  // namespace detsim::cli
