// detsim diff: two saved World states (World::save() bytes, e.g. `detsim synctest --dump`, or the
// states of a desync report) compared field by field: subsystem, body, field, both values.
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <detsim/sim/state_diff.hpp>

#include "commands.hpp"
#include "diff_output.hpp"
#include "output.hpp"
#include "scenario_args.hpp"

namespace detsim::cli {

namespace {

/// The largest state file read (about 150,000 bodies).
constexpr std::size_t max_state_file = std::size_t{64} << 20;

Expected<std::vector<std::uint8_t>> read_state(const std::string& path) {
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> in(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!in) return Status::error(path + ": cannot open the file");
  std::vector<std::uint8_t> bytes;
  std::uint8_t buffer[1 << 16];
  std::size_t n = 0;
  while ((n = std::fread(buffer, 1, sizeof buffer, in.get())) > 0) {
    if (bytes.size() + n > max_state_file)
      return Status::error(path + ": larger than 64 MiB, not a saved state");
    bytes.insert(bytes.end(), buffer, buffer + n);
  }
  if (std::ferror(in.get())) return Status::error(path + ": read failed");
  return bytes;
}

}  // namespace

std::string field_json(const FieldDiff& f) {
  return Json()
      .str("subsystem", f.subsystem)
      .num("body", f.body)
      .str("field", f.field)
      .str("a", f.a)
      .str("b", f.b)
      .text();
}

void print_field(const FieldDiff& f) {
  // A field of a body (in any section) is placed by its body; any other by its section.
  const std::string where = f.body != 0 ? "body " + std::to_string(f.body) : f.subsystem;
  std::printf("  %-12s %-22s A %s\n  %-12s %-22s B %s\n", where.c_str(), f.field.c_str(),
              f.a.c_str(), "", "", f.b.c_str());
}

int diff_command(const DiffArgs& args) {
  auto a = read_state(args.a);
  if (!a) return usage_error("diff", a.message());
  auto b = read_state(args.b);
  if (!b) return usage_error("diff", b.message());
  // The states are restored against the scenario's world, which holds the geometry they name.
  World geometry;
  if (!args.scene.scenario.empty()) {
    auto chosen = choose_scenario(args.scene);
    if (!chosen) return usage_error("diff", chosen.message());
    geometry = chosen.value().scenario.world();
  }
  auto diff = diff_states(geometry, a.value(), b.value(), args.max_fields);
  if (!diff) {
    // Name the file rather than the side.
    std::string message = diff.message();
    if (message.rfind("state A: ", 0) == 0) message = args.a + ": " + message.substr(9);
    if (message.rfind("state B: ", 0) == 0) message = args.b + ": " + message.substr(9);
    return usage_error("diff", message);
  }
  const StateDiff& d = diff.value();
  if (args.json) {
    std::vector<std::string> fields;
    for (const FieldDiff& f : d.fields)
      fields.push_back(field_json(f));
    Json j;
    j.boolean("equal", d.equal())
        .num("frame_a", d.frame_a)
        .num("frame_b", d.frame_b)
        .hash("hash_a", d.a.total)
        .hash("hash_b", d.b.total)
        .raw("differences", Json::array(fields))
        .num("omitted", d.omitted);
    if (!d.note.empty()) j.str("note", d.note);
    j.print();
    return d.equal() ? exit_ok : exit_check_failed;
  }
  if (d.equal()) {
    std::printf("equal: frame %llu, hash %s\n", static_cast<unsigned long long>(d.frame_a),
                hex(d.a.total).c_str());
    return exit_ok;
  }
  std::printf("DIFFERENT: A frame %llu hash %s, B frame %llu hash %s\n",
              static_cast<unsigned long long>(d.frame_a), hex(d.a.total).c_str(),
              static_cast<unsigned long long>(d.frame_b), hex(d.b.total).c_str());
  for (const FieldDiff& f : d.fields)
    print_field(f);
  if (d.omitted != 0) std::printf("  ... and %zu more differences (--max shows more)\n", d.omitted);
  if (!d.note.empty()) std::printf("  note: %s\n", d.note.c_str());
  return exit_check_failed;
}

}  // namespace detsim::cli
