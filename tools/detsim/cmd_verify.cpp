// detsim verify and detsim info.
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include <detsim/fixed/decimal.hpp>
#include <detsim/replay.hpp>
#include <detsim/sim/state_diff.hpp>

#include "commands.hpp"
#include "output.hpp"
#include "scenario_args.hpp"

namespace detsim::cli {

namespace {

std::string hashes_json(const StateHashes& h) {
  Json json;
  json.hash("total", h.total);
  for (const SectionHash& section : h.sections)
    json.hash(section.name, section.hash);
  return json.text();
}

}  // namespace

std::string describe(const replay::Fingerprint& f) {
  std::string out = f.scenario + " (seed " + std::to_string(f.params.seed);
  if (f.params.players != 0) out += ", " + std::to_string(f.params.players) + " players";
  if (f.params.count != 0) out += ", " + std::to_string(f.params.count) + " bodies";
  return out + ")";
}

int verify_command(const VerifyArgs& args) {
  if (args.bulk()) return verify_many_command(args);
  const std::string& file = args.files.front();
  if (args.at != 0 && args.report.empty())
    return usage_error("verify",
                       "--at needs --report FILE (where to write the state of that frame)");
  auto injections = parse_injections(args.injections);
  if (!injections) return usage_error("verify", injections.message());
  auto reader = replay::ReplayReader::open(file);
  if (!reader) return usage_error("verify", reader.message());
  const replay::Fingerprint& fp = reader->fingerprint();
  for (const Injection& i : injections.value())
    if (i.frame > reader->frame_count())
      return usage_error("verify", "--inject " + i.text() + ": frame " + std::to_string(i.frame) +
                                       " is beyond the replay's " +
                                       std::to_string(reader->frame_count()) + " frames");
  if (args.at > reader->frame_count())
    return usage_error("verify", "--at " + std::to_string(args.at) + ": " + file +
                                     " holds frames 1 to " + std::to_string(reader->frame_count()));
  Progress progress("verify");
  replay::VerifyOptions options;
  options.progress = [&progress](std::uint64_t done, std::uint64_t total) {
    progress.update(done, total);
    return true;
  };
  if (!injections->empty()) {
    options.after_step = [&injections](Scenario& s) {
      return apply_injections(s.world(), injections.value());
    };
  }
  options.report = !args.report.empty();
  if (args.at != 0) options.report_at = args.at;
  const auto start = std::chrono::steady_clock::now();
  auto result = replay::verify(reader.value(), options);
  const double seconds = seconds_since(start);
  progress.done();
  if (!result) return usage_error("verify", result.message());
  const replay::VerifyResult& v = result.value();
  std::string report_line;
  if (v.report) {
    if (Status s = replay::write_desync_report(args.report, *v.report); !s)
      return usage_error("verify", s.message());
    report_line = "this machine's state at frame " + std::to_string(v.report->divergent_frame) +
                  " written to " + args.report;
  } else if (!args.report.empty() && v.first_mismatch == std::optional<std::uint64_t>{0}) {
    report_line = "the initial states differ (different runs, not a desync): no report written";
  } else if (!args.report.empty()) {
    report_line =
        "no mismatch, so no report written (--at FRAME writes this machine's state at "
        "a frame whatever verification finds)";
  }
  const double fps = seconds > 0 ? static_cast<double>(v.frames) / seconds : 0.0;
  const double realtime = fps * fp.dt.to_double();
  const std::vector<std::string> parts = differing_subsystems(v.expected, v.actual);
  if (args.json) {
    std::vector<std::string> quoted;
    for (const std::string& p : parts)
      quoted.push_back(Json::quote(p));
    Json j;
    j.boolean("ok", v.ok)
        .num("frames", v.frames)
        .frame("first_mismatch", v.first_mismatch)
        .str("file", file)
        .str("scenario", fp.scenario)
        .num("recorded_frames", reader->frame_count())
        .boolean("complete", reader->complete())
        .hash("final_hash", v.final_hash);
    if (v.first_mismatch) {
      j.raw("expected", hashes_json(v.expected))
          .raw("actual", hashes_json(v.actual))
          .raw("differing_parts", Json::array(quoted));
    }
    if (v.note.empty()) {
      j.null("note");
    } else {
      j.str("note", v.note);
    }
    if (v.report) {
      j.str("report", args.report).num("report_frame", v.report->divergent_frame);
    } else {
      j.null("report").null("report_frame");
    }
    j.real("seconds", seconds).real("frames_per_second", fps).real("realtime_factor", realtime);
    j.print();
    return v.ok ? exit_ok : exit_check_failed;
  }
  if (v.ok) {
    std::printf("%s: ok: %llu frames of %s reproduce every recorded hash; final hash %s\n",
                file.c_str(), static_cast<unsigned long long>(v.frames), describe(fp).c_str(),
                hex(v.final_hash).c_str());
    std::printf("%.2f s, %.0f frames/s (%.0fx real time)\n", seconds, fps, realtime);
  } else if (v.first_mismatch) {
    const std::uint64_t f = *v.first_mismatch;
    std::printf("%s: MISMATCH at frame %llu of %s\n", file.c_str(),
                static_cast<unsigned long long>(f), describe(fp).c_str());
    std::printf("  recorded hash %s, this machine computes %s\n", hex(v.expected.total).c_str(),
                hex(v.actual.total).c_str());
    std::string list;
    for (const std::string& p : parts)
      list += (list.empty() ? "" : ", ") + p;
    if (!list.empty()) std::printf("  differing parts: %s\n", list.c_str());
    if (f > 0) std::printf("  last agreed frame: %llu\n", static_cast<unsigned long long>(f - 1));
  } else {
    std::printf("%s: FAILED after %llu frames\n", file.c_str(),
                static_cast<unsigned long long>(v.frames));
  }
  if (!v.note.empty()) std::printf("  note: %s\n", v.note.c_str());
  if (!report_line.empty()) std::printf("  %s\n", report_line.c_str());
  return v.ok ? exit_ok : exit_check_failed;
}

int seek_command(const SeekArgs& args) {
  auto reader = replay::ReplayReader::open(args.file);
  if (!reader) return usage_error("seek", reader.message());
  const replay::ReplayReader& r = reader.value();
  if (args.frame > r.frame_count())
    return usage_error("seek", args.file + " has frames 0 .. " + std::to_string(r.frame_count()) +
                                   ", not " + std::to_string(args.frame));
  std::uint64_t resimulated = 0;
  auto scenario = replay::seek(r, args.frame, &resimulated);
  if (!scenario) return usage_error("seek", scenario.message());
  std::vector<std::uint8_t> state;
  const std::uint64_t hash = scenario.value().world().save(state).total;
  // Frame 0 has no record: its hash is the fingerprint's initial hash.
  std::uint64_t recorded = r.fingerprint().initial_hash;
  if (args.frame > 0) {
    auto record = r.frame(args.frame);
    if (!record) return usage_error("seek", record.message());
    recorded = record.value().hashes.total;
  }
  if (!args.save_state.empty() && !write_file(args.save_state, state))
    return usage_error("seek", "cannot write " + args.save_state);
  const bool ok = hash == recorded;
  if (args.json) {
    Json j;
    j.boolean("ok", ok)
        .str("file", args.file)
        .num("frame", args.frame)
        .hash("hash", hash)
        .hash("recorded_hash", recorded)
        .num("resimulated_frames", resimulated);
    if (args.save_state.empty()) {
      j.null("state");
    } else {
      j.str("state", args.save_state);
    }
    j.print();
  } else {
    std::printf("frame %llu of %s: hash %s, %s (re-simulated %llu frames from a keyframe)\n",
                static_cast<unsigned long long>(args.frame), args.file.c_str(), hex(hash).c_str(),
                ok ? "as recorded" : ("RECORDED " + hex(recorded)).c_str(),
                static_cast<unsigned long long>(resimulated));
    if (!args.save_state.empty()) std::printf("state written to %s\n", args.save_state.c_str());
  }
  return ok ? exit_ok : exit_check_failed;
}

int info_command(const InfoArgs& args) {
  auto reader = replay::ReplayReader::open(args.file);
  if (!reader) return usage_error("info", reader.message());
  const replay::ReplayReader& r = reader.value();
  const replay::Fingerprint& f = r.fingerprint();
  if (args.json) {
    std::vector<std::string> keyframes;
    for (const replay::KeyframeInfo& k : r.keyframes())
      keyframes.push_back(Json().num("frame", k.frame).num("bytes", k.size).text());
    Json fingerprint;
    fingerprint.str("detsim_version", f.detsim_version)
        .num("fixed_fraction_bits", f.fixed_fraction_bits)
        .num("state_version", f.state_version)
        .str("scenario", f.scenario)
        .num("seed", f.params.seed)
        .num("players", f.players)
        .num("count", f.params.count)
        .str("dt", to_string(f.dt))
        .num("substeps", f.substeps)
        .num("iterations", f.iterations)
        .num("input_size", f.input_size)
        .num("keyframe_interval", f.keyframe_interval)
        .hash("initial_hash", f.initial_hash);
    Json j;
    j.str("file", args.file)
        .num("format_version", replay::format_version)
        .num("bytes", r.file_size())
        .raw("fingerprint", fingerprint.text())
        .num("frames", r.frame_count())
        .boolean("complete", r.complete());
    if (r.chain_hash()) {
      j.hash("chain_hash", *r.chain_hash());
    } else {
      j.null("chain_hash");
    }
    j.raw("keyframes", Json::array(keyframes)).num("ignored_tail_bytes", r.ignored_tail_bytes());
    j.print();
    return exit_ok;
  }
  std::printf("file              %s (%llu bytes, replay format %u)\n", args.file.c_str(),
              static_cast<unsigned long long>(r.file_size()), replay::format_version);
  std::printf("scenario          %s\n", describe(f).c_str());
  std::printf("recorded by       detsim %s, Q%u.%u, state encoding %u\n", f.detsim_version.c_str(),
              64 - f.fixed_fraction_bits, f.fixed_fraction_bits, f.state_version);
  std::printf("step              dt %s s, %u substeps x %u iterations\n", to_string(f.dt).c_str(),
              f.substeps, f.iterations);
  std::printf("inputs            %u players x %u bytes per frame\n", f.players, f.input_size);
  std::printf("initial hash      %s\n", hex(f.initial_hash).c_str());
  std::printf("frames            %llu%s\n", static_cast<unsigned long long>(r.frame_count()),
              r.complete() ? "" : " (no end marker: the recording stopped early)");
  if (r.chain_hash()) std::printf("chain hash        %s\n", hex(*r.chain_hash()).c_str());
  // The keyframes' frames; a long list shows its first eight and its last.
  std::string frames;
  const auto& keys = r.keyframes();
  for (std::size_t i = 0; i < keys.size(); ++i) {
    if (keys.size() > 10 && i == 8) {
      frames += ", ..., " + std::to_string(keys.back().frame);
      break;
    }
    frames += (frames.empty() ? "" : ", ") + std::to_string(keys[i].frame);
  }
  std::printf("keyframes         %zu every %u frames%s%s\n", r.keyframes().size(),
              f.keyframe_interval, frames.empty() ? "" : ": ", frames.c_str());
  if (r.ignored_tail_bytes() != 0) std::printf("note              %s\n", r.tail_note().c_str());
  return exit_ok;
}

}  // namespace detsim::cli
