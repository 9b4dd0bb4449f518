// Loading a record (record.hpp).
#include "record.hpp"

#include <algorithm>
#include <cstdio>
#include <memory>

#include <detsim/replay/desync_report.hpp>
#include <detsim/replay/scenario_replay.hpp>

#include "replay_detail.hpp"

namespace detsim::replay::detail {

bool is_report(const std::string& path) {
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> in(std::fopen(path.c_str(), "rb"), &std::fclose);
  char magic[8] = {};
  return in && std::fread(magic, 1, 8, in.get()) == 8 && std::equal(magic, magic + 8, "DSDESYNC");
}

namespace {

Status load_replay(Record& side) {
  auto reader = ReplayReader::open(side.path);
  if (!reader) return reader.status();
  side.kind = "replay";
  side.fp = reader->fingerprint();
  side.last = reader->frame_count();
  side.hashes.assign(Record::at(side.last) + 1, StateHashes{});
  side.known.assign(Record::at(side.last) + 1, 1);
  side.hashes[0].total = side.fp.initial_hash;
  side.inputs.reserve(Record::at(side.last) * side.unit());
  Status read = reader->for_each_frame(1, side.last, [&](const FrameRecord& r) {
    side.hashes[Record::at(r.frame)] = r.hashes;
    side.inputs.insert(side.inputs.end(), r.inputs.begin(), r.inputs.end());
    return true;
  });
  if (!read) return read;
  side.replay.emplace(std::move(reader.value()));
  return Status::success();
}

}  // namespace

World geometry_world(const Fingerprint& fp, const std::string& path) {
  auto scenario = scenario_of(fp, path);
  return scenario ? scenario.value().world() : World();
}

namespace {

Status load_report(Record& side) {
  auto read = read_desync_report(side.path);
  if (!read) return read.status();
  DesyncReport& r = read.value();
  side.kind = "desync report";
  side.fp = r.fingerprint;
  side.last = r.divergent_frame;  // the reader checked: one confirmed frame per step before it
  side.hashes.assign(Record::at(side.last) + 1, StateHashes{});
  side.known.assign(Record::at(side.last) + 1, 0);
  side.hashes[0].total = side.fp.initial_hash;
  side.known[0] = 1;
  const std::size_t unit = side.unit();
  for (std::size_t at = 0; at < r.confirmed_frames.size(); at += 1 + unit) {
    side.gone.push_back(r.confirmed_frames[at]);
    side.inputs.insert(side.inputs.end(),
                       r.confirmed_frames.begin() + static_cast<std::ptrdiff_t>(at) + 1,
                       r.confirmed_frames.begin() + static_cast<std::ptrdiff_t>(at + 1 + unit));
  }
  side.states[r.agreed_frame] = std::move(r.agreed_state);
  for (FrameState& f : r.intermediate_states)
    side.states[f.frame] = std::move(f.state);
  side.states[r.divergent_frame] = std::move(r.divergent_state);
  World world = geometry_world(side.fp, side.path);
  for (const auto& [frame, state] : side.states) {
    if (Status s = world.restore(state); !s)
      return Status::error("desync report " + side.path + ": the state of frame " +
                           std::to_string(frame) + ": " + s.message());
    if (world.frame() != frame)
      return Status::error("desync report " + side.path + ": the state stored for frame " +
                           std::to_string(frame) + " is of frame " + std::to_string(world.frame()));
    side.set_hash(frame, world.hashes());
  }
  return Status::success();
}

}  // namespace

Expected<Record> load_record(const std::string& path, const char* label) {
  Record side;
  side.path = path;
  side.label = label;
  const Status s = is_report(path) ? load_report(side) : load_replay(side);
  if (!s)
    return label == nullptr || *label == 0
               ? s
               : Status::error(std::string("side ") + label + ": " + s.message());
  return side;
}

}  // namespace detsim::replay::detail
