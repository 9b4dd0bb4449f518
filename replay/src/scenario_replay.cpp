// Recording, verifying and seeking replays of the registered scenarios.
#include <algorithm>
#include <array>
#include <optional>
#include <utility>

#include <detsim/core/hash.hpp>
#include <detsim/core/version.hpp>
#include <detsim/fixed/decimal.hpp>
#include <detsim/replay/scenario_replay.hpp>

#include "replay_detail.hpp"

namespace detsim::replay {

using detail::hex64;

namespace {

void encode_inputs(std::span<const PlayerInput> inputs, std::vector<std::uint8_t>& out) {
  out.resize(inputs.size() * PlayerInput::encoded_size);
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    encode_input(inputs[i],
                 std::span<std::uint8_t, PlayerInput::encoded_size>(
                     out.data() + i * PlayerInput::encoded_size, PlayerInput::encoded_size));
  }
}

/// What verify keeps to write this machine's side of a frame as a desync report: the state before
/// the current frame and every frame's inputs so far (as a session's confirmed frames: a zero
/// "disconnected" byte, then the inputs).
class ReportBuilder {
 public:
  ReportBuilder(const Fingerprint& fingerprint, bool active)
      : fingerprint_(fingerprint), active_(active) {}

  /// `world`: the scenario's, which also holds the geometry the states name (body_hashes
  /// restores them against it).
  void remember(const World& world) {
    world_ = &world;
    world.save(current_);
  }

  /// After a frame's step: keeps its inputs and state, returns its hashes.
  StateHashes step(const World& world, std::span<const std::uint8_t> inputs) {
    confirmed_.push_back(0);
    confirmed_.insert(confirmed_.end(), inputs.begin(), inputs.end());
    previous_.swap(current_);
    return world.save(current_);
  }

  /// The report of `frame` (the frame last stepped; the steps so far are frames 0 .. frame - 1).
  Expected<DesyncReport> build_checked(std::uint64_t frame, std::uint64_t local,
                                       std::uint64_t remote) const {
    DesyncReport r;
    r.fingerprint = fingerprint_;
    r.origin = ReportOrigin::verify;
    r.agreed_frame = frame - 1;
    r.divergent_frame = frame;
    r.local_hash = local;
    r.remote_hash = remote;
    r.confirmed_frames = confirmed_;  // steps 0 .. frame - 1
    r.agreed_state = previous_;
    r.divergent_state = current_;
    const World geometry = world_ != nullptr ? *world_ : World();
    auto agreed = body_hashes(geometry, r.agreed_state);
    if (!agreed) return agreed.status();
    auto divergent = body_hashes(geometry, r.divergent_state);
    if (!divergent) return divergent.status();
    r.agreed_bodies = std::move(agreed).value();
    r.divergent_bodies = std::move(divergent).value();
    return r;
  }
  std::optional<DesyncReport> build(std::uint64_t frame, std::uint64_t local,
                                    std::uint64_t remote) const {
    if (!active_) return std::nullopt;
    auto r = build_checked(frame, local, remote);
    if (!r) return std::nullopt;  // never: both states were saved by this build's World
    return std::move(r).value();
  }

 private:
  const Fingerprint& fingerprint_;
  bool active_;
  const World* world_ = nullptr;
  std::vector<std::uint8_t> previous_;
  std::vector<std::uint8_t> current_;
  std::vector<std::uint8_t> confirmed_;
};

std::string fixed_text(Fixed v) {
  return to_string(v) + " (raw " + std::to_string(v.raw()) + ")";
}

}  // namespace

void detail::gone_zeroed(std::span<const std::uint8_t> bytes, std::size_t input_size,
                         std::uint8_t gone, std::vector<std::uint8_t>& out) {
  out.assign(bytes.begin(), bytes.end());
  for (std::size_t p = 0; p < 8 && input_size > 0 && (p + 1) * input_size <= out.size(); ++p)
    if (((gone >> p) & 1U) != 0)
      std::fill_n(out.begin() + static_cast<std::ptrdiff_t>(p * input_size), input_size,
                  std::uint8_t{0});
}

Fingerprint fingerprint_of(const Scenario& scenario, std::uint32_t keyframe_interval) {
  Fingerprint f;
  f.detsim_version = std::string(detsim::version);
  f.fixed_fraction_bits = Fixed::fraction_bits;
  f.state_version = state_encoding_version;
  f.scenario = std::string(scenario.info().name);
  f.params = scenario.params();
  const WorldDef& def = scenario.world().def();
  f.dt = def.dt;
  f.substeps = def.substeps;
  f.iterations = def.iterations;
  f.players = scenario.params().players;
  f.input_size = scenario.info().input_size;
  f.keyframe_interval = keyframe_interval;
  const StateHashes initial = scenario.world().hashes();
  f.initial_hash = initial.total;
  for (const SectionHash& h : initial.sections)
    f.state_sections.push_back(h.name);
  return f;
}

Expected<Scenario> scenario_of(const ReplayReader& reader) {
  return scenario_of(reader.fingerprint(), reader.path());
}

Expected<Scenario> scenario_of(const Fingerprint& f, const std::string& name) {
  const std::string where = name + ": fingerprint: ";
  if (f.fixed_fraction_bits != Fixed::fraction_bits)
    return Status::error(where + "recorded with Q" + std::to_string(64 - f.fixed_fraction_bits) +
                         "." + std::to_string(f.fixed_fraction_bits) +
                         " numbers, this build computes in Q32.32");
  if (f.state_version != state_encoding_version)
    return Status::error(
        where + "recorded with state encoding " + std::to_string(f.state_version) +
        " (its hashes and keyframes are of it), " + "this build writes and reads encoding " +
        std::to_string(state_encoding_version) + "; detsim " + f.detsim_version + " recorded it");
  const ScenarioInfo* info = find_scenario(f.scenario);
  if (info == nullptr)
    return Status::error(where + "scenario \"" + f.scenario +
                         "\" is not one of this program's scenarios (`scenarios` lists them; a "
                         "game's own scenario is known to the program that registers it: its tool "
                         "built on detsim::cli::run_cli)");
  if (f.input_size != info->input_size)
    return Status::error(where + "inputs of " + std::to_string(f.input_size) +
                         " bytes, this build's " + f.scenario + " takes " +
                         std::to_string(info->input_size));
  if (f.players != f.params.players)
    return Status::error(where + std::to_string(f.players) + " inputs per frame for " +
                         std::to_string(f.params.players) + " players");
  auto scenario = Scenario::create(f.scenario, f.params);
  if (!scenario) return Status::error(where + scenario.message());
  if (scenario->params() != f.params)
    return Status::error(where + "the parameters are not the ones this build's scenario fills in");
  const WorldDef& def = scenario->world().def();
  if (def.dt != f.dt)
    return Status::error(where + "dt " + fixed_text(f.dt) + ", this build's " + f.scenario +
                         " steps " + fixed_text(def.dt));
  if (def.substeps != f.substeps || def.iterations != f.iterations)
    return Status::error(where + std::to_string(f.substeps) + " substeps x " +
                         std::to_string(f.iterations) + " iterations, this build's " + f.scenario +
                         " uses " + std::to_string(def.substeps) + " x " +
                         std::to_string(def.iterations));
  return scenario;
}

Expected<RecordResult> record(Scenario& scenario, const std::string& path,
                              const RecordOptions& options) {
  if (scenario.world().frame() != 0)
    return Status::error("record: the scenario is at frame " +
                         std::to_string(scenario.world().frame()) + ", expected frame 0");
  if (options.keyframe_interval == 0)
    return Status::error("record: the keyframe interval must be at least 1");
  const std::uint64_t frames =
      options.frames != 0 ? options.frames : scenario.info().default_frames;
  std::optional<ReplayWriter> writer;
  if (!path.empty()) {
    auto created = ReplayWriter::create(path, fingerprint_of(scenario, options.keyframe_interval));
    if (!created) return created.status();
    writer.emplace(std::move(created.value()));
  }
  const std::uint32_t players = scenario.params().players;
  const std::uint64_t seed = scenario.params().seed;
  const std::size_t size = scenario.info().input_size;
  const bool own_input = !scenario.takes_player_input();
  if (options.inputs && own_input)
    return Status::error("record: " + std::string(scenario.info().name) +
                         " takes its own input of " + std::to_string(size) +
                         " bytes, not PlayerInput: give RecordOptions::input_bytes");
  std::vector<PlayerInput> inputs(players);
  std::vector<std::uint8_t> bytes(players * size);
  HashChain chain;
  RecordResult result;
  std::vector<std::uint8_t> state;  // every frame's encoding, in one reused buffer
  for (std::uint64_t f = 1; f <= frames; ++f) {
    if (options.input_bytes) {
      options.input_bytes(f, bytes);
    } else if (options.inputs) {
      options.inputs(f, inputs);
      encode_inputs(inputs, bytes);
    } else {
      for (std::uint32_t p = 0; p < players; ++p)
        scenario.scripted(seed, f, p, std::span<std::uint8_t>(bytes).subspan(p * size, size));
    }
    scenario.step_encoded(bytes);
    if (options.after_step) {
      if (Status s = options.after_step(scenario); !s) return s;
    }
    const StateHashes hashes = scenario.world().save(state);
    chain.add(hashes.total);
    result.final_hash = hashes.total;
    result.frames = f;
    if (writer) {
      if (Status s = writer->frame(bytes, hashes); !s) return s;
      if (f % options.keyframe_interval == 0) {
        if (Status s = writer->keyframe(f, state); !s) return s;  // this frame's, just saved
      }
    }
    if (options.progress && !options.progress(f, frames)) break;
  }
  if (writer) {
    if (Status s = writer->finish(); !s) return s;
  }
  result.chain_hash = chain.value();
  return result;
}

Expected<VerifyResult> verify(const ReplayReader& reader, const Progress& progress) {
  VerifyOptions options;
  options.progress = progress;
  return verify(reader, options);
}

Expected<VerifyResult> verify(const ReplayReader& reader, const VerifyOptions& options) {
  const std::uint64_t total = reader.frame_count();
  if (options.report_at && (*options.report_at == 0 || *options.report_at > total))
    return Status::error(reader.path() + ": cannot report frame " +
                         std::to_string(*options.report_at) + ": the replay holds frames 1 to " +
                         std::to_string(total));
  auto created = scenario_of(reader);
  if (!created) return created.status();
  Scenario& scenario = created.value();
  const Fingerprint& fp = reader.fingerprint();
  VerifyResult result;
  const std::uint64_t initial = scenario.world().hashes().total;
  result.final_hash = initial;
  if (initial != fp.initial_hash) {
    result.first_mismatch = 0;
    result.expected.total = fp.initial_hash;
    result.actual = scenario.world().hashes();
    result.note = "the scenario's initial state differs from the recorded one";
    return result;
  }
  const bool reporting = options.report || options.report_at;
  ReportBuilder report(fp, reporting);
  if (reporting) report.remember(scenario.world());
  const std::vector<KeyframeInfo>& keyframes = reader.keyframes();
  std::size_t next_keyframe = 0;
  HashChain chain;
  Status stop_error;
  std::vector<std::uint8_t> encoded;  // every frame's state, in one reused buffer
  const Status read = reader.for_each_frame(1, total, [&](const FrameRecord& record) {
    scenario.step_encoded(record.inputs);
    if (options.after_step) {
      if (Status s = options.after_step(scenario); !s) {
        stop_error = s;
        return false;
      }
    }
    const StateHashes hashes =
        reporting ? report.step(scenario.world(), record.inputs) : scenario.world().save(encoded);
    if (options.report_at && record.frame == *options.report_at)
      result.report = report.build(record.frame, hashes.total, record.hashes.total);
    if (result.first_mismatch) return !options.report_at || record.frame < *options.report_at;
    chain.add(hashes.total);
    result.frames = record.frame;
    result.final_hash = hashes.total;
    if (hashes != record.hashes) {
      result.first_mismatch = record.frame;
      result.expected = record.hashes;
      result.actual = hashes;
      if (options.report && !options.report_at)
        result.report = report.build(record.frame, hashes.total, record.hashes.total);
      return options.report_at && record.frame < *options.report_at;
    }
    if (next_keyframe < keyframes.size() && keyframes[next_keyframe].frame == record.frame) {
      auto state = reader.keyframe_state(keyframes[next_keyframe]);
      if (!state) {
        stop_error = state.status();
        return false;
      }
      if (hash_bytes(state.value()) != record.hashes.total) {
        stop_error = Status::error(reader.path() + ": the keyframe of frame " +
                                   std::to_string(record.frame) +
                                   " does not hash to its frame's recorded hash");
        return false;
      }
      ++next_keyframe;
    }
    return !options.progress || options.progress(record.frame, total);
  });
  if (!read) return read;
  if (!stop_error) return stop_error;
  if (result.first_mismatch) return result;
  if (result.frames != total) {
    result.note =
        "stopped at frame " + std::to_string(result.frames) + " of " + std::to_string(total);
    return result;
  }
  if (reader.complete()) {
    if (chain.value() != *reader.chain_hash()) {
      result.note = "the end marker's chain hash " + hex64(*reader.chain_hash()) +
                    " disagrees with the frames' " + hex64(chain.value());
      return result;
    }
  } else {
    result.note = "the replay has no end marker (the recording stopped early): verified the " +
                  std::to_string(total) + " frames it holds";
  }
  result.ok = true;
  return result;
}

Expected<Scenario> seek(const ReplayReader& reader, std::uint64_t frame,
                        std::uint64_t* resimulated) {
  if (frame > reader.frame_count())
    return Status::error(reader.path() + ": cannot seek to frame " + std::to_string(frame) +
                         ": the replay holds frames 0 to " + std::to_string(reader.frame_count()));
  auto created = scenario_of(reader);
  if (!created) return created.status();
  Scenario& scenario = created.value();
  const std::vector<KeyframeInfo>& keyframes = reader.keyframes();
  // The last keyframe at or before `frame`.
  auto it = std::upper_bound(keyframes.begin(), keyframes.end(), frame,
                             [](std::uint64_t f, const KeyframeInfo& k) { return f < k.frame; });
  std::uint64_t from = 0;
  if (it != keyframes.begin()) {
    const KeyframeInfo& k = *std::prev(it);
    auto state = reader.keyframe_state(k);
    if (!state) return state.status();
    if (Status s = scenario.world().restore(state.value()); !s)
      return Status::error(reader.path() + ": the keyframe of frame " + std::to_string(k.frame) +
                           " does not restore: " + s.message());
    from = k.frame;
  }
  const Status read = reader.for_each_frame(from + 1, frame, [&](const FrameRecord& record) {
    scenario.step_encoded(record.inputs);
    return true;
  });
  if (!read) return read;
  if (resimulated != nullptr) *resimulated = frame - from;
  return created;
}

}  // namespace detsim::replay
