// Writes the fuzzer's seed corpus: short replays of small scenes, each twice (a leading 0 byte:
// read as is; a leading 1: checksums recomputed; see replay_reader_fuzz.cpp).
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <detsim/replay.hpp>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_seeds DIR\n");
    return 2;
  }
  const std::string dir = argv[1];
  struct Seed {
    const char* scenario;
    detsim::ScenarioParams params;
    std::uint32_t frames;
    std::uint32_t keyframe_interval;
  };
  const Seed seeds[] = {{"arena", {.seed = 2, .players = 2, .count = 0}, 24, 8},
                        {"bounce", {}, 12, 5},
                        {"pile_boxes", {.seed = 1, .players = 0, .count = 8}, 16, 6},
                        {"spray", {.seed = 4, .players = 0, .count = 0}, 30, 10}};
  for (const Seed& s : seeds) {
    auto scenario = detsim::Scenario::create(s.scenario, s.params);
    if (!scenario) return 1;
    const std::string tmp = dir + "/" + s.scenario + ".tmp";
    detsim::replay::RecordOptions options;
    options.frames = s.frames;
    options.keyframe_interval = s.keyframe_interval;
    if (!detsim::replay::record(scenario.value(), tmp, options)) return 1;
    std::ifstream in(tmp, std::ios::binary);
    const std::vector<char> bytes{std::istreambuf_iterator<char>(in), {}};
    std::remove(tmp.c_str());
    for (const char mode : {'\0', '\1'}) {
      std::ofstream out(dir + "/" + s.scenario + (mode == 0 ? ".raw" : ".resealed"),
                        std::ios::binary);
      out.put(mode);
      out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    }
  }
  return 0;
}
