// Writes the state fuzzer's seed corpus: the saved state of every scenario (small parameters) at a
// few frames, one world whose bodies carry user data, a force and a torque (the optional body
// fields of docs/STATE.md), and the world of geometry_world.hpp, whose geometry the target holds.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <detsim/scenes/scenario.hpp>
#include <detsim/sim/world.hpp>

#include "geometry_world.hpp"

namespace {

void write(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_state_seeds DIR\n");
    return 2;
  }
  const std::string dir = argv[1];
  for (const detsim::ScenarioInfo& info : detsim::scenario_list()) {
    detsim::ScenarioParams params;
    if (info.default_count > 0)
      params.count = std::min(info.max_count, info.count_unit == "rows" ? 4U : 27U);
    auto created = detsim::Scenario::create(info.name, params);
    if (!created) continue;
    detsim::Scenario& scenario = created.value();
    for (const int frame : {0, 20, 90}) {
      while (scenario.world().frame() < static_cast<std::uint64_t>(frame))
        scenario.step();
      write(dir + "/" + std::string(info.name) + "_" + std::to_string(frame),
            scenario.world().save());
    }
  }
  auto created = detsim::World::create({});
  if (!created) return 1;
  detsim::World& w = created.value();
  (void)w.create_body({.type = detsim::BodyType::static_body, .shape = detsim::Shape::plane()});
  const auto box =
      w.create_body({.shape = detsim::Shape::box(
                         {detsim::Fixed::half(), detsim::Fixed::half(), detsim::Fixed::half()}),
                     .position = {{}, detsim::Fixed::one(), {}},
                     .user_data = 42});
  if (!box) return 1;
  (void)w.apply_force(box.value(), {detsim::Fixed::one(), {}, {}});
  (void)w.apply_torque(box.value(), {{}, detsim::Fixed::one(), {}});
  write(dir + "/flags", w.save());
  // The same with a game's own state (the optional "game" section).
  const std::vector<std::uint8_t> scores = {3, 0, 0, 0, 1, 0, 0, 0, 0x5A};
  if (!w.set_game_state(scores)) return 1;
  write(dir + "/game", w.save());
  // The geometry the target world holds, with a body on each kind, at rest and after a fall.
  detsim::World g = fuzz_support::geometry_world(true);
  if (g.geometry_count() == 0) return 1;
  write(dir + "/geometry_0", g.save());
  for (int i = 0; i < 40; ++i)
    g.step();
  write(dir + "/geometry_40", g.save());
  return 0;
}
