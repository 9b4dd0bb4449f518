// Desync bisection (bisect.hpp).
//
// Each record is loaded as one Side: its fingerprint, every step's inputs, the state hashes of the
// frames it holds (a replay: every frame; a desync report: the frames whose states it carries) and
// the states it can give (a report's states, a replay's keyframes). The sides are compared
// fingerprint first, inputs second, hashes third. This machine then re-simulates from the last
// state both sides agree on (a keyframe or a report's agreed state), which (1) fills the frames a
// side has no hash for, on the side it agrees with, and (2) gives that side's state at frames it
// stored none for. The field-level diff is taken at the first frame from the first divergent one
// on where both sides' states are known.
#include <detsim/replay/bisect.hpp>

#include <algorithm>
#include <cstdio>
#include <map>
#include <memory>
#include <set>

#include <detsim/fixed/decimal.hpp>
#include <detsim/replay/desync_report.hpp>
#include <detsim/replay/replay.hpp>
#include <detsim/replay/scenario_replay.hpp>

#include "record.hpp"
#include "replay_detail.hpp"

namespace detsim::replay {
namespace {

using detail::State;
using Side = detail::Record;

std::string hex_bytes(std::span<const std::uint8_t> bytes) {
  static constexpr char digits[] = "0123456789abcdef";
  std::string out;
  for (const std::uint8_t b : bytes) {
    out += digits[b >> 4];
    out += digits[b & 15];
  }
  return out;
}

std::vector<std::string> fingerprint_differences(const Fingerprint& a, const Fingerprint& b) {
  std::vector<std::string> out;
  const auto num = [&](const char* what, std::uint64_t x, std::uint64_t y) {
    if (x != y)
      out.push_back(std::string(what) + ": " + std::to_string(x) + " vs " + std::to_string(y));
  };
  if (a.scenario != b.scenario) out.push_back("scenario: " + a.scenario + " vs " + b.scenario);
  num("seed", a.params.seed, b.params.seed);
  num("players", a.params.players, b.params.players);
  num("count", a.params.count, b.params.count);
  num("fixed fraction bits", a.fixed_fraction_bits, b.fixed_fraction_bits);
  num("state encoding", a.state_version, b.state_version);
  if (a.dt != b.dt) out.push_back("dt: " + to_string(a.dt) + " vs " + to_string(b.dt));
  num("substeps", a.substeps, b.substeps);
  num("iterations", a.iterations, b.iterations);
  num("inputs per frame", a.players, b.players);
  num("input size", a.input_size, b.input_size);
  if (a.initial_hash != b.initial_hash)
    out.push_back("initial hash: " + detail::hex64(a.initial_hash) + " vs " +
                  detail::hex64(b.initial_hash));
  return out;
}

/// This machine's re-simulation, from a state both sides agree on.
class Local {
 public:
  Local(Scenario scenario, const Side& inputs_from)
      : scenario_(std::move(scenario)), in_(inputs_from) {}

  std::uint64_t frame() const { return scenario_.world().frame(); }
  const StateHashes* hashes(std::uint64_t f) const {
    auto it = hashes_.find(f);
    return it == hashes_.end() ? nullptr : &it->second;
  }
  const State* state(std::uint64_t f) const {
    auto it = states_.find(f);
    return it == states_.end() ? nullptr : &it->second;
  }
  /// Steps up to frame `to` (no further than the inputs reach), keeping each frame's hashes and
  /// the states of the frames in `keep`.
  void step_to(std::uint64_t to, const std::set<std::uint64_t>& keep) {
    const std::size_t unit = in_.unit();
    std::vector<std::uint8_t> inputs;
    State bytes;
    while (frame() < to && frame() < in_.last) {
      const std::span<const std::uint8_t> step(in_.inputs.data() + Side::at(frame()) * unit, unit);
      detail::gone_zeroed(step, in_.fp.input_size, in_.gone_at(frame()), inputs);
      scenario_.step_encoded(inputs);
      hashes_[frame()] = scenario_.world().save(bytes);
      if (keep.count(frame()) != 0) states_[frame()] = bytes;
    }
  }

 private:
  Scenario scenario_;
  const Side& in_;
  std::map<std::uint64_t, StateHashes> hashes_;
  std::map<std::uint64_t, State> states_;
};

std::vector<AgreementSpan> timeline(const Side& a, const Side& b) {
  std::vector<AgreementSpan> out;
  const std::uint64_t end = std::max(a.last, b.last);
  for (std::uint64_t f = 0; f <= end; ++f) {
    AgreementSpan::State s = AgreementSpan::State::unknown;
    if (a.has(f) && b.has(f))
      s = a.hash(f).total == b.hash(f).total ? AgreementSpan::State::agree
                                             : AgreementSpan::State::differ;
    if (!out.empty() && out.back().state == s && out.back().last + 1 == f) {
      out.back().last = f;
    } else {
      out.push_back({f, f, s});
    }
  }
  return out;
}

// Each body with its outline from the world (World::body_outline), which draws the shapes whose
// geometry is registered (hulls, meshes, heightfields, compounds) as well as the primitives.
std::vector<ScenePose> scene_of(const World& geometry, const State& state,
                                const std::set<std::uint32_t>& differing) {
  std::vector<ScenePose> out;
  World w(geometry);
  if (!w.restore(state)) return out;
  for (const BodyId id : w.body_ids()) {
    const BodyState b = w.body(id).value();
    ScenePose pose;
    pose.id = id.value;
    pose.type = b.type;
    pose.shape = b.shape;
    pose.position = b.position;
    pose.orientation = b.orientation;
    pose.differs = differing.count(id.value) != 0;
    if (auto outline = w.body_outline(id)) pose.outline = std::move(outline).value();
    out.push_back(std::move(pose));
  }
  // Particles as balls of their radius (body ID 0, never labelled): at most 1000 a group, every
  // k-th particle of a bigger one, so that a 10k-particle cloth still makes a readable page.
  for (const ParticleGroupId id : w.particle_group_ids()) {
    const ParticleGroupStats st = w.particle_group_stats(id).value();
    const std::vector<Vec3> points = w.particle_positions(id).value();
    const std::size_t every = points.size() / 1000 + 1;
    for (std::size_t i = 0; i < points.size(); i += every) {
      ScenePose pose;
      pose.shape = Shape::sphere(st.radius);
      pose.position = points[i];
      out.push_back(std::move(pose));
    }
  }
  return out;
}

}  // namespace

Expected<BisectResult> bisect(const std::string& path_a, const std::string& path_b,
                              const BisectOptions& options) {
  auto loaded_a = detail::load_record(path_a, "A");
  if (!loaded_a) return loaded_a.status();
  auto loaded_b = detail::load_record(path_b, "B");
  if (!loaded_b) return loaded_b.status();
  const Side& a = loaded_a.value();
  const Side& b = loaded_b.value();

  BisectResult r;
  r.a = a.path;
  r.b = b.path;
  r.a_kind = a.kind;
  r.b_kind = b.kind;
  r.players = a.fp.players;
  r.input_size = a.fp.input_size;
  r.frames_a = a.last;
  r.frames_b = b.last;
  r.fingerprint_differences = fingerprint_differences(a.fp, b.fp);
  if (!r.fingerprint_differences.empty()) {
    r.outcome = BisectOutcome::different_runs;
    return r;
  }
  if (a.fp.detsim_version != b.fp.detsim_version)
    r.notes.push_back("recorded by detsim " + a.fp.detsim_version + " and " + b.fp.detsim_version);

  // Inputs of the steps both hold.
  const std::uint64_t common = std::min(a.last, b.last);
  const std::size_t unit = a.unit();
  for (std::uint64_t step = 0; step < common; ++step) {
    const std::size_t at = static_cast<std::size_t>(step) * unit;
    const bool gone_differs =
        !a.gone.empty() && !b.gone.empty() && a.gone_at(step) != b.gone_at(step);
    const std::span<const std::uint8_t> step_a(a.inputs.data() + at, unit);
    const std::span<const std::uint8_t> step_b(b.inputs.data() + at, unit);
    if (!gone_differs && std::equal(step_a.begin(), step_a.end(), step_b.begin())) continue;
    r.outcome = BisectOutcome::inputs_differ;
    r.input_frame = step + 1;
    for (std::uint32_t p = 0; p < a.fp.players; ++p) {
      const std::size_t pa = at + std::size_t{p} * a.fp.input_size;
      const std::span<const std::uint8_t> ia(a.inputs.data() + pa, a.fp.input_size);
      const std::span<const std::uint8_t> ib(b.inputs.data() + pa, a.fp.input_size);
      const bool flag = gone_differs && (((a.gone_at(step) ^ b.gone_at(step)) >> p) & 1U) != 0;
      if (!flag && std::equal(ia.begin(), ia.end(), ib.begin())) continue;
      r.input_player = p;
      r.input_a = hex_bytes(ia) + (((a.gone_at(step) >> p) & 1U) != 0 ? " (gone)" : "");
      r.input_b = hex_bytes(ib) + (((b.gone_at(step) >> p) & 1U) != 0 ? " (gone)" : "");
      break;
    }
    r.timeline = timeline(a, b);
    return r;
  }

  // The first frame both hold a hash for and disagree on.
  std::uint64_t last_agreed = 0;
  std::optional<std::uint64_t> divergent;
  for (std::uint64_t f = 1; f <= common; ++f) {
    if (!a.has(f) || !b.has(f)) continue;
    if (a.hash(f).total != b.hash(f).total) {
      divergent = f;
      break;
    }
    last_agreed = f;
  }
  r.timeline = timeline(a, b);
  if (!divergent) {
    r.outcome = BisectOutcome::identical;
    if (a.last != b.last)
      r.notes.push_back("A holds frames 0 to " + std::to_string(a.last) + ", B 0 to " +
                        std::to_string(b.last) + "; they agree on every frame both hold");
    return r;
  }
  r.outcome = BisectOutcome::diverged;

  // This machine's re-simulation from the latest stored state both sides agree on.
  auto scenario = scenario_of(a.fp, a.path);
  // The geometry that both sides' states are restored against for the diff and the scene (the
  // fingerprints are equal, so it is the one scenario's).
  const World geometry = scenario ? scenario.value().world() : World();
  std::optional<Local> local;
  std::uint64_t start = 0;
  if (scenario) {
    for (const Side* s : {&a, &b})
      for (const std::uint64_t f : s->stored_frames())
        if (f <= last_agreed && f > start && a.has(f) && b.has(f)) start = f;
    if (start > 0) {
      const Side& from = a.stored(start) ? a : b;
      if (Status st = scenario.value().world().restore(*from.stored(start)); !st)
        return Status::error("side " + from.label + ": the state of frame " +
                             std::to_string(start) + ": " + st.message());
    }
    // The inputs are equal where both have them (checked above): the longer record's reach further.
    local.emplace(std::move(scenario).value(), a.last >= b.last ? a : b);
  } else {
    r.notes.push_back("not re-simulated here: " + scenario.message());
  }

  // Candidate frames for the field-level diff: the divergent frame, then every stored state's.
  std::set<std::uint64_t> candidates{*divergent};
  for (const Side* s : {&a, &b})
    for (const std::uint64_t f : s->stored_frames())
      if (f > *divergent) candidates.insert(f);

  // Which side this machine agrees with at the first frame both recorded as different.
  bool local_is_a = false;
  bool local_is_b = false;
  if (local) {
    std::set<std::uint64_t> keep(candidates);
    for (std::uint64_t f = last_agreed + 1; f < *divergent; ++f)
      keep.insert(f);
    local->step_to(*divergent, keep);
    if (const StateHashes* h = local->hashes(*divergent)) {
      local_is_a = h->total == a.hash(*divergent).total;
      local_is_b = h->total == b.hash(*divergent).total;
      r.local_agrees_with = local_is_a ? "A" : local_is_b ? "B" : "neither";
    }
    // Frames one side has no hash for: that side's hashes are this machine's if it agrees with it.
    const auto hash_of = [&](const Side& s, bool is_local, std::uint64_t f) -> const StateHashes* {
      if (s.has(f)) return &s.hash(f);
      return is_local ? local->hashes(f) : nullptr;
    };
    for (std::uint64_t f = last_agreed + 1; f < *divergent; ++f) {
      const StateHashes* ha = hash_of(a, local_is_a, f);
      const StateHashes* hb = hash_of(b, local_is_b, f);
      if (ha == nullptr || hb == nullptr) continue;
      if (ha->total != hb->total) {
        r.notes.push_back("frames " + std::to_string(last_agreed + 1) + " to " +
                          std::to_string(*divergent - 1) + " of side " + (local_is_a ? "B" : "A") +
                          " have no recorded hash; side " + (local_is_a ? "A" : "B") +
                          "'s were re-simulated here");
        divergent = f;
        break;
      }
      last_agreed = f;
    }
  }
  r.first_divergent_frame = divergent;
  r.last_agreed_frame = last_agreed;
  r.exact = last_agreed + 1 == *divergent;
  candidates.insert(*divergent);
  const auto hashes_at = [&](const Side& s, bool is_local, std::uint64_t f) {
    if (s.has(f)) return s.hash(f);
    const StateHashes* h = is_local && local ? local->hashes(f) : nullptr;
    return h != nullptr ? *h : StateHashes{};
  };
  r.hashes_a = hashes_at(a, local_is_a, *divergent);
  r.hashes_b = hashes_at(b, local_is_b, *divergent);
  if (!r.hashes_a.sections.empty() && !r.hashes_b.sections.empty())
    r.subsystems = differing_subsystems(r.hashes_a, r.hashes_b);
  for (std::uint64_t f = last_agreed;
       f < *divergent && r.inputs_between.size() < options.max_input_frames; ++f) {
    const std::size_t at = static_cast<std::size_t>(f) * unit;
    r.inputs_between.push_back(
        {f + 1,
         std::vector<std::uint8_t>(a.inputs.begin() + static_cast<std::ptrdiff_t>(at),
                                   a.inputs.begin() + static_cast<std::ptrdiff_t>(at + unit))});
  }

  // A side's state at frame f: stored, or this machine's when it agrees with that side there.
  const auto state_of = [&](const Side& s, bool is_local, std::uint64_t f,
                            std::string& source) -> std::optional<State> {
    if (auto stored = s.stored(f)) {
      source = s.kind == "replay" ? "keyframe" : "desync report";
      return stored;
    }
    if (!local || !is_local) return std::nullopt;
    local->step_to(f, candidates);
    const State* mine = local->state(f);
    const StateHashes* h = local->hashes(f);
    if (mine == nullptr || h == nullptr || (s.has(f) && s.hash(f).total != h->total))
      return std::nullopt;
    source = "re-simulated here";
    return *mine;
  };
  for (const std::uint64_t f : candidates) {
    if (f < *divergent) continue;
    std::string source_a;
    std::string source_b;
    auto sa = state_of(a, local_is_a, f, source_a);
    if (!sa) continue;
    auto sb = state_of(b, local_is_b, f, source_b);
    if (!sb) continue;
    auto diff = diff_states(geometry, *sa, *sb, options.max_diffs);
    if (!diff) return diff.status();
    if (diff.value().a.total == diff.value().b.total) {
      // The divergence did not last (a field the next step overwrites, such as the velocity of a
      // character that stands): nothing to list here, so a later known frame is no help either.
      r.healed_frame = f;
      break;
    }
    r.diff_frame = f;
    r.diff_source_a = source_a;
    r.diff_source_b = source_b;
    r.diffs = std::move(diff.value().fields);
    r.diffs_omitted = diff.value().omitted;
    if (!diff.value().note.empty()) r.notes.push_back(diff.value().note);
    std::set<std::uint32_t> bodies;
    for (const FieldDiff& d : r.diffs)
      if (d.body != 0) bodies.insert(d.body);  // whatever the section, a field of a body
    r.scene_a = scene_of(geometry, *sa, bodies);
    r.scene_b = scene_of(geometry, *sb, bodies);
    break;
  }
  if (r.diff_frame != divergent) {
    std::string missing;
    for (const Side* s : {&a, &b}) {
      std::string ignored;
      if (state_of(*s, s == &a ? local_is_a : local_is_b, *divergent, ignored)) continue;
      if (s->kind == "replay") {
        missing = "on the machine that recorded side " + s->label + ": detsim verify " + s->path +
                  " --report " + s->path + "." + std::to_string(*divergent) + ".report --at " +
                  std::to_string(*divergent) + ", then bisect with that report";
      } else if (missing.empty()) {
        missing = "on the machine that wrote side " + s->label +
                  ": detsim verify REPLAY --report OUT --at " + std::to_string(*divergent) +
                  " with its replay of this match, then bisect with that report";
      }
    }
    r.advice = missing;
  }
  return r;
}

}  // namespace detsim::replay
