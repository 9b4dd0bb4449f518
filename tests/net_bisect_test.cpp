// Desync bisection, net path: eight arena peers in rollback sessions over a simulated network, one
// of them with a field of one body changed at a seeded random frame (of a 10,000-frame match;
// 1,000 in the sanitizer build). The session detects the desync at the next hash check; the
// healthy peer's and the faulty peer's desync reports (with the states between the last agreed
// check and the divergent one, re-simulated by each machine) are bisected, which must name
// exactly the injected frame, body and field — whatever the check interval.
#include <random>

#include <gtest/gtest.h>

#include <detsim/net/session.hpp>
#include <detsim/net/sim_network.hpp>
#include <detsim/replay/bisect.hpp>
#include <detsim/replay/desync_report.hpp>
#include <detsim/scenario_net/scenario_game.hpp>
#include <detsim/scenario_net/scenario_recorder.hpp>

#include "support/injection_cases.hpp"
#include "support/replay_files.hpp"
#include "support/scale.hpp"

namespace detsim {
namespace {

using test::FieldClass;

constexpr std::uint32_t kPlayers = 8;
constexpr std::uint32_t kFaulty = 5;
constexpr std::uint32_t kInterval = 30;

std::uint64_t random_frame(FieldClass c) {
  std::mt19937_64 rng(0x4E7B15 + static_cast<std::uint64_t>(c));
  return 2 + rng() % (test::scaled(10'000) - 2);
}

class NetBisect : public ::testing::TestWithParam<FieldClass> {};

TEST_P(NetBisect, PeersReportsNameTheInjectedFrameBodyAndField) {
  const FieldClass field_class = GetParam();
  const std::uint64_t target = random_frame(field_class);
  SCOPED_TRACE(std::string("class ") + test::class_name(field_class) + ", frame " +
               std::to_string(target));

  // A clean low-latency network: the test is about the reports, not about the network.
  net::LinkConditions link;
  link.latency_us = 8'000;
  auto created = net::SimNetwork::create(kPlayers, 31, link);
  ASSERT_TRUE(created.ok()) << created.message();
  net::SimNetwork network = std::move(created.value());

  // The faulty peer's hook chooses its target from the state it is changing. Rollbacks may
  // simulate the frame more than once; the confirmed state is the last simulation of it.
  std::optional<Injection> injection;
  std::vector<std::unique_ptr<Scenario>> scenarios;
  std::vector<std::unique_ptr<net::ScenarioGame>> games;
  std::vector<net::Session> sessions;
  for (std::uint32_t p = 0; p < kPlayers; ++p) {
    ScenarioParams params;
    params.players = kPlayers;
    params.seed = 5;
    scenarios.push_back(std::make_unique<Scenario>(Scenario::create("arena", params).value()));
    games.push_back(std::make_unique<net::ScenarioGame>(*scenarios.back()));
    if (p == kFaulty) {
      games.back()->set_after_step([&](Scenario& s) -> Status {
        if (s.world().frame() != target) return Status::success();
        injection = test::choose_injection(field_class, s.world());
        if (!injection) return Status::error("no target at this frame");
        return apply_injection(s.world(), *injection);
      });
    }
    net::SessionConfig c;
    c.players = kPlayers;
    c.local_player = p;
    c.input_size = games.back()->input_size();
    c.check_interval = kInterval;
    for (std::uint32_t q = 0; q < kPlayers; ++q)
      if (q != p) c.remotes.push_back({q, q});
    auto s = net::Session::create(c, *games.back(), network.endpoint(p));
    ASSERT_TRUE(s.ok()) << s.message();
    sessions.push_back(std::move(s.value()));
  }
  const replay::Fingerprint fingerprint = replay::fingerprint_of(*scenarios[0]);

  std::array<std::uint8_t, 3> input{};
  const std::uint64_t limit = target + 4 * kInterval + 600;
  for (std::uint64_t tick = 0; tick < limit; ++tick) {
    network.advance_to(tick * 16'667);
    for (std::uint32_t p = 0; p < kPlayers; ++p) {
      sessions[p].poll(tick * 16'667);
      encode_input(scripted_input(11, tick, p), input);
      ASSERT_TRUE(sessions[p].advance_frame(input).ok());
      (void)sessions[p].take_events();
    }
    if (sessions[0].desync_evidence() != nullptr && sessions[kFaulty].desync_evidence() != nullptr)
      break;
  }
  ASSERT_TRUE(games[kFaulty]->after_step_status().ok())
      << games[kFaulty]->after_step_status().message();
  ASSERT_TRUE(injection.has_value());
  const net::DesyncEvidence* healthy = sessions[0].desync_evidence();
  const net::DesyncEvidence* faulty = sessions[kFaulty].desync_evidence();
  ASSERT_NE(healthy, nullptr) << "the healthy peer never saw the desync";
  ASSERT_NE(faulty, nullptr) << "the faulty peer never saw the desync";
  EXPECT_EQ(healthy->player, kFaulty);
  // Detected at the first check after the change.
  EXPECT_EQ(healthy->divergent_frame, (target + kInterval - 1) / kInterval * kInterval);

  test::TempFile healthy_path("healthy.dsd");
  test::TempFile faulty_path("faulty.dsd");
  for (auto [p, path] : {std::pair{0U, &healthy_path}, std::pair{kFaulty, &faulty_path}}) {
    auto report = net::desync_report(fingerprint, p, *sessions[p].desync_evidence(), *games[p]);
    ASSERT_TRUE(report.ok()) << report.message();
    EXPECT_EQ(report->intermediate_states.size(),
              report->divergent_frame - report->agreed_frame - 1)
        << "peer " << p << " re-simulated every frame in between";
    ASSERT_TRUE(replay::write_desync_report(path->path(), report.value()).ok());
  }

  auto r = replay::bisect(healthy_path.path(), faulty_path.path());
  ASSERT_TRUE(r.ok()) << r.message();
  EXPECT_EQ(r->outcome, replay::BisectOutcome::diverged);
  EXPECT_EQ(r->first_divergent_frame, target);
  EXPECT_EQ(r->last_agreed_frame, target - 1);
  EXPECT_TRUE(r->exact);
  ASSERT_EQ(r->diff_frame, target);
  EXPECT_EQ(r->diff_source_a, "desync report");
  EXPECT_EQ(r->diff_source_b, "desync report");
  test::expect_names_injection(r->diffs, field_class, *injection);
}

INSTANTIATE_TEST_SUITE_P(EveryFieldClass, NetBisect, ::testing::ValuesIn(test::all_field_classes()),
                         [](const ::testing::TestParamInfo<FieldClass>& param) {
                           return std::string(test::class_name(param.param));
                         });

}  // namespace
}  // namespace detsim
