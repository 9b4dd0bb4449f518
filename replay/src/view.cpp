// Re-simulating records for a viewer (view.hpp).
//
// Data flow: each path is loaded as a Record (record.hpp); two records are first bisected
// (bisect.hpp) for the outcome, the first divergent frame and the bodies its field diff names.
// Each record then gets its own Scenario from its fingerprint, stepped with its own inputs; at a
// frame where the record stores a state, that state is restored instead. Every frame from
// options.first on is read off the worlds into one ViewFrame and handed to the sink.
#include <detsim/replay/view.hpp>

#include <algorithm>
#include <set>
#include <unordered_set>

#include <detsim/replay/bisect.hpp>
#include <detsim/replay/scenario_replay.hpp>

#include "record.hpp"
#include "replay_detail.hpp"

namespace detsim::replay {
namespace {

/// The outline of a body at `position`, `orientation`, moved into the body's own frame.
ShapeOutline to_local(ShapeOutline o, Vec3 position, Quat orientation) {
  const Quat inverse = conjugate(orientation);
  const auto local = [&](Vec3 p) { return rotate(inverse, p - position); };
  for (Vec3& p : o.points)
    p = local(p);
  for (auto& t : o.triangles)
    for (Vec3& p : t)
      p = local(p);
  o.normal = rotate(inverse, o.normal);
  for (ShapeOutline& part : o.parts)
    part = to_local(std::move(part), position, orientation);
  return o;
}

/// One record being re-simulated.
class Track {
 public:
  Track(detail::Record record, Scenario scenario)
      : record_(std::move(record)), scenario_(std::move(scenario)) {
    for (const std::uint64_t f : record_.stored_frames())
      stored_frames_.insert(f);
  }

  [[nodiscard]] const detail::Record& record() const { return record_; }
  [[nodiscard]] const World& world() const { return scenario_.world(); }
  [[nodiscard]] const Scenario& scenario() const { return scenario_; }

  /// Puts the world at frame `start` (0, or a frame the record stores a state for).
  Status start_at(std::uint64_t start) {
    if (start == 0) return Status::success();
    return restore(start);
  }

  /// Steps to the next frame with the record's inputs, or restores the record's state there.
  Status advance() {
    const std::uint64_t f = world().frame();
    if (stored_frames_.count(f + 1) != 0) return restore(f + 1);
    const std::size_t unit = record_.unit();
    const std::span<const std::uint8_t> step(record_.inputs.data() + detail::Record::at(f) * unit,
                                             unit);
    detail::gone_zeroed(step, record_.fp.input_size, record_.gone_at(f), inputs_);
    scenario_.step_encoded(inputs_);
    stored_ = false;
    return Status::success();
  }

  /// This frame as the sink sees it; `differs` marks bodies from the first divergent frame on.
  ViewSide read(const std::set<std::uint32_t>& differs) {
    const World& w = world();
    ViewSide side;
    const std::uint64_t f = w.frame();
    side.hash = w.hashes().total;
    side.stored = stored_;
    if (record_.has(f)) side.recorded_hash = record_.hash(f).total;
    for (const BodyId id : w.body_ids()) {
      const BodyState b = w.body(id).value();
      side.bodies.push_back({id.value, b.position, b.orientation, differs.count(id.value) != 0});
      if (!seen_.insert(id.value).second) continue;
      ViewBody body;
      body.id = id.value;
      body.type = b.type;
      if (auto outline = w.body_outline(id))
        body.outline = to_local(std::move(outline).value(), b.position, b.orientation);
      side.new_bodies.push_back(std::move(body));
    }
    for (const ParticleGroupId id : w.particle_group_ids()) {
      ViewParticles p;
      p.group = id.value;
      p.radius = w.particle_group_stats(id).value().radius;
      p.positions = w.particle_positions(id).value();
      side.particles.push_back(std::move(p));
    }
    return side;
  }

 private:
  Status restore(std::uint64_t f) {
    auto state = record_.stored(f);
    if (!state)
      return Status::error(record_.path + ": no state stored for frame " + std::to_string(f));
    if (Status s = scenario_.world().restore(*state); !s)
      return Status::error(record_.path + ": the state of frame " + std::to_string(f) + ": " +
                           s.message());
    stored_ = true;
    return Status::success();
  }

  detail::Record record_;
  Scenario scenario_;
  std::set<std::uint64_t> stored_frames_;
  std::unordered_set<std::uint32_t> seen_;
  std::vector<std::uint8_t> inputs_;
  bool stored_ = false;
};

bool same_body(const World& a, const World& b, BodyId id) {
  auto x = a.body(id);
  auto y = b.body(id);
  if (!x || !y) return static_cast<bool>(x) == static_cast<bool>(y);
  const BodyState& p = x.value();
  const BodyState& q = y.value();
  return p.position == q.position && p.orientation == q.orientation &&
         p.linear_velocity == q.linear_velocity && p.angular_velocity == q.angular_velocity &&
         p.awake == q.awake;
}

}  // namespace

Status view_records(std::span<const std::string> paths, const ViewOptions& options,
                    ViewSink& sink) {
  if (paths.empty() || paths.size() > 2)
    return Status::error("view takes one record, or two records of the same match (got " +
                         std::to_string(paths.size()) + ")");
  ViewInfo info;
  std::set<std::uint64_t> named_by_diff;
  std::optional<std::uint64_t> diff_frame;
  if (paths.size() == 2) {
    auto r = bisect(paths[0], paths[1]);
    if (!r) return r.status();
    const BisectResult& b = r.value();
    switch (b.outcome) {
      case BisectOutcome::different_runs: {
        std::string why;
        for (const std::string& d : b.fingerprint_differences)
          why += (why.empty() ? "" : "; ") + d;
        return Status::error(paths[0] + " and " + paths[1] +
                             " are not records of the same match (" + why + ")");
      }
      case BisectOutcome::identical:
        info.outcome = "identical";
        break;
      case BisectOutcome::inputs_differ:
        info.outcome = "inputs_differ";
        info.notes.push_back(
            "the records' inputs differ from frame " + std::to_string(b.input_frame) + " (player " +
            std::to_string(b.input_player) + "): each side is re-simulated with its own inputs");
        info.first_divergent_frame = b.input_frame;
        break;
      case BisectOutcome::diverged:
        info.outcome = "diverged";
        info.first_divergent_frame = b.first_divergent_frame;
        diff_frame = b.diff_frame;
        for (const FieldDiff& d : b.diffs)
          if (d.subsystem == "bodies" && d.body != 0) named_by_diff.insert(d.body);
        break;
    }
  }

  std::vector<Track> tracks;
  for (const std::string& path : paths) {
    auto record = detail::load_record(path, paths.size() == 2 ? (tracks.empty() ? "A" : "B") : "");
    if (!record) return record.status();
    auto scenario = scenario_of(record->fp, path);
    if (!scenario) return scenario.status();
    info.records.push_back({path, record->kind, record->last});
    tracks.emplace_back(std::move(record).value(), std::move(scenario).value());
  }
  const detail::Record& first = tracks.front().record();
  info.fingerprint = first.fp;
  info.player_inputs = first.fp.input_size == PlayerInput::encoded_size &&
                       tracks.front().scenario().takes_player_input();
  std::uint64_t end = first.last;
  for (const Track& t : tracks)
    end = std::min(end, t.record().last);
  if (tracks.size() == 2 && tracks[0].record().last != tracks[1].record().last)
    info.notes.push_back("the records end at frames " + std::to_string(tracks[0].record().last) +
                         " and " + std::to_string(tracks[1].record().last) +
                         ": both are shown up to frame " + std::to_string(end));
  const std::uint64_t last = options.last.value_or(end);
  if (last > end)
    return Status::error("the last frame asked for, " + std::to_string(last) +
                         ", is past the end of the record" + (tracks.size() == 2 ? "s" : "") +
                         " (frame " + std::to_string(end) + ")");
  if (options.first > last)
    return Status::error("the first frame asked for, " + std::to_string(options.first) +
                         ", is after the last, " + std::to_string(last));
  info.first_frame = options.first;
  info.last_frame = last;

  // Start at the latest frame at or before `first` where every record stores a state (or 0).
  std::uint64_t start = 0;
  for (const std::uint64_t f : tracks.front().record().stored_frames()) {
    if (f > options.first || f <= start) continue;
    bool everywhere = true;
    for (const Track& t : tracks) {
      const auto frames = t.record().stored_frames();
      everywhere = everywhere && std::find(frames.begin(), frames.end(), f) != frames.end();
    }
    if (everywhere) start = f;
  }
  for (Track& t : tracks)
    if (Status s = t.start_at(start); !s) return s;
  if (Status s = sink.begin(info); !s) return s;

  std::set<std::uint32_t> differs;
  for (std::uint64_t f = start; f <= last; ++f) {
    if (f > start)
      for (Track& t : tracks)
        if (Status s = t.advance(); !s) return s;
    if (f < options.first) continue;
    differs.clear();
    if (tracks.size() == 2 && info.first_divergent_frame && f >= *info.first_divergent_frame) {
      const World& a = tracks[0].world();
      const World& b = tracks[1].world();
      std::set<std::uint32_t> ids;
      for (const BodyId id : a.body_ids())
        ids.insert(id.value);
      for (const BodyId id : b.body_ids())
        ids.insert(id.value);
      for (const std::uint32_t id : ids)
        if (!same_body(a, b, BodyId{id})) differs.insert(id);
      // Between the divergence and the first state a side stores after it, this machine's
      // re-simulation cannot show the difference: the bodies bisection named stand for it.
      if (diff_frame && f <= *diff_frame)
        differs.insert(named_by_diff.begin(), named_by_diff.end());
    }
    ViewFrame frame;
    frame.frame = f;
    if (f > 0) {
      const std::size_t unit = first.unit();
      frame.inputs = std::span<const std::uint8_t>(
          first.inputs.data() + detail::Record::at(f - 1) * unit, unit);
      frame.gone = first.gone_at(f - 1);
    }
    for (Track& t : tracks)
      frame.sides.push_back(t.read(differs));
    if (Status s = sink.frame(frame); !s) return s;
  }
  return Status::success();
}

}  // namespace detsim::replay
