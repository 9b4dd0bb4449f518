// The state's container of sections (docs/STATE.md, <detsim/sim/state_sections.hpp>): what
// read_state_sections finds, and what World::restore refuses about the list of sections. Every
// refused state leaves the world as it was.
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <detsim/detsim.hpp>

namespace detsim {
namespace {

using Bytes = std::vector<std::uint8_t>;

// A world with bodies, contacts, forces and a used RNG: every section has content.
World sample_world() {
  auto scenario = Scenario::create("pile_boxes", {.seed = 1, .players = 0, .count = 8}).value();
  for (int i = 0; i < 40; ++i)
    scenario.step();
  World w = scenario.world();
  (void)w.rng().next_u64();
  return w;
}

struct Section {
  std::string name;
  std::uint64_t version;
  Bytes payload;
};

std::vector<Section> sections_of(const Bytes& state) {
  auto found = read_state_sections(state);
  EXPECT_TRUE(found.ok()) << found.message();
  std::vector<Section> out;
  for (const StateSection& s : found.value())
    out.push_back({std::string(s.name), s.version, Bytes(s.payload.begin(), s.payload.end())});
  return out;
}

void put_var(Bytes& out, std::uint64_t v) {
  while (v >= 0x80) {
    out.push_back(static_cast<std::uint8_t>(v | 0x80));
    v >>= 7;
  }
  out.push_back(static_cast<std::uint8_t>(v));
}

// The container as docs/STATE.md specifies it, written here independently of state_io.cpp.
Bytes container(const std::vector<Section>& sections,
                std::uint32_t version = state_encoding_version) {
  Bytes out{'D', 'S', 'I', 'M'};
  for (int i = 0; i < 4; ++i)
    out.push_back(static_cast<std::uint8_t>(version >> (8 * i)));
  put_var(out, sections.size());
  for (const Section& s : sections) {
    put_var(out, s.name.size());
    out.insert(out.end(), s.name.begin(), s.name.end());
    put_var(out, s.version);
    const auto length = static_cast<std::uint32_t>(s.payload.size());
    for (int i = 0; i < 4; ++i)
      out.push_back(static_cast<std::uint8_t>(length >> (8 * i)));
    out.insert(out.end(), s.payload.begin(), s.payload.end());
  }
  return out;
}

// `bad` is refused by restore with a message containing each of `parts`; the world is unchanged.
void expect_refused(const Bytes& bad, std::initializer_list<const char*> parts) {
  World w = sample_world();
  const Bytes before = w.save();
  const Status s = w.restore(bad);
  ASSERT_FALSE(s.ok()) << "accepted";
  for (const char* part : parts)
    EXPECT_NE(s.message().find(part), std::string::npos) << s.message() << "\nmissing: " << part;
  EXPECT_EQ(w.save(), before);
}

TEST(StateSections, AWorldsStateIsItsSevenSectionsAndTheirHashes) {
  const World w = sample_world();
  const Bytes state = w.save();
  auto found = read_state_sections(state);
  ASSERT_TRUE(found.ok()) << found.message();
  const StateHashes h = w.hashes();
  ASSERT_EQ(found->size(), 7U);
  ASSERT_EQ(h.sections.size(), 7U);
  const char* names[] = {"globals", "rng", "geometry", "bodies", "contacts", "joints", "particles"};
  const std::uint32_t versions[] = {1, 1, 1, 2, 2, 1, 1};
  std::size_t next = 9;  // magic, version, the count 7 in one byte
  for (std::size_t i = 0; i < 7; ++i) {
    const StateSection& s = (*found)[i];
    EXPECT_EQ(s.name, names[i]);
    EXPECT_EQ(s.version, versions[i]);
    EXPECT_EQ(s.offset, next);  // the sections follow one another
    EXPECT_EQ(s.payload_offset, s.offset + 1 + s.name.size() + 1 + 4);
    EXPECT_EQ(s.record.size(), s.payload_offset - s.offset + s.payload.size());
    EXPECT_EQ(h.sections[i].name, names[i]);
    EXPECT_EQ(h.sections[i].hash, section_hash(s));
    next = s.offset + s.record.size();
  }
  EXPECT_EQ(next, state.size());
  // The container written from the spec is the state itself.
  EXPECT_EQ(container(sections_of(state)), state);
}

TEST(StateSections, TheListOfSectionsMustBeAWorlds) {
  const Bytes state = sample_world().save();
  const std::vector<Section> good = sections_of(state);

  std::vector<Section> extra = good;
  extra.push_back({"game.score", 1, {1, 2, 3}});
  // Any section is a valid container; only a World refuses what is not its own.
  EXPECT_TRUE(read_state_sections(container(extra)).ok());
  expect_refused(container(extra), {"section \"game.score\"", "the state's end"});

  std::vector<Section> swapped = good;
  std::swap(swapped[0], swapped[1]);
  expect_refused(container(swapped), {"section \"rng\"", "section \"globals\" was expected"});

  std::vector<Section> missing(good.begin(), good.end() - 1);
  expect_refused(container(missing), {"section \"particles\" is missing"});

  std::vector<Section> newer = good;
  newer[3].version = 3;
  expect_refused(container(newer), {"section \"bodies\" version 3, this build reads 2"});

  // A payload must be read to exactly its end.
  std::vector<Section> longer = good;
  longer[1].payload.push_back(0);
  expect_refused(container(longer), {"section \"rng\"", "1 unexpected bytes"});
  std::vector<Section> shorter = good;
  shorter[0].payload.pop_back();
  expect_refused(container(shorter), {"section \"globals\"", "time to sleep"});
}

TEST(StateSections, TheContainerIsChecked) {
  const Bytes state = sample_world().save();
  const std::vector<Section> good = sections_of(state);

  std::vector<Section> twice = good;
  twice.push_back(good[1]);
  expect_refused(container(twice), {"section \"rng\" appears twice"});
  EXPECT_FALSE(read_state_sections(container(twice)).ok());

  for (const char* name : {"Bodies", "bodies!", "", "a_name_that_is_far_longer_than_32_bytes"}) {
    std::vector<Section> bad = good;
    bad[2].name = name;
    expect_refused(container(bad), {"section name"});
  }
  EXPECT_TRUE(valid_section_name("game.score_2"));
  EXPECT_FALSE(valid_section_name("game score"));

  // A length beyond the data.
  Bytes cut = state;
  cut.resize(cut.size() - 1);
  expect_refused(cut, {"section length"});
  // Garbage after the last section; a huge section count.
  Bytes longer = state;
  longer.push_back(0);
  expect_refused(longer, {"unexpected bytes after the last section"});
  Bytes huge(state.begin(), state.begin() + 8);
  put_var(huge, 0xFFFFFFFFFFULL);
  expect_refused(huge, {"section count", "exceeds"});
  expect_refused(container(good, 3), {"state encoding version 3, this build reads 6"});
}

}  // namespace
}  // namespace detsim
