// The game server and its clients (net/server.hpp, net/client.hpp) over the simulated network with
// a cheap game: admission, stamping without waiting, exact reconciliation, joins in progress,
// restarts, bad networks, forged datagrams, and state authority's snapshots.
#include <gtest/gtest.h>

#include <detsim/core/hash.hpp>
#include <detsim/net/client.hpp>
#include <detsim/net/server.hpp>
#include <detsim/net/server_protocol.hpp>
#include <detsim/net/sim_network.hpp>

#include <detsim/replay/scenario_replay.hpp>

#include "support/replay_files.hpp"
#include "support/server_match.hpp"

namespace detsim {
namespace {

namespace sp = net::server_protocol;
using test::ServerMatch;
using test::ServerMatchOptions;

/// Every live client ended on the server's final state: the same hash, no desync.
void expect_all_agree(ServerMatch& m, std::uint32_t clients) {
  const std::uint64_t final_hash = m.server().current_hash();
  for (std::uint32_t c = 0; c < clients; ++c) {
    net::Client* client = m.client(c);
    if (client == nullptr) continue;
    SCOPED_TRACE("client " + std::to_string(c));
    EXPECT_TRUE(client->ended());
    EXPECT_EQ(client->current_frame(), m.server().current_frame());
    EXPECT_EQ(client->server_hash(), final_hash);
    std::vector<std::uint8_t> state;
    EXPECT_EQ(m.game(c)->save(state), final_hash);
    EXPECT_EQ(client->stats().desyncs, 0U);
  }
}

TEST(NetServer, RejectsInvalidConfigsNamingTheField) {
  test::CounterGame game;
  auto network = net::SimNetwork::create(2, 1);
  ASSERT_TRUE(network.ok());
  const auto error_of = [&](auto&& edit) {
    net::ServerConfig c;
    edit(c);
    auto s = net::Server::create(c, game, network->endpoint(0));
    return s.ok() ? std::string() : s.message();
  };
  EXPECT_EQ(error_of([](net::ServerConfig&) {}), "");
  EXPECT_NE(error_of([](net::ServerConfig& c) { c.players = 0; }).find("players"),
            std::string::npos);
  EXPECT_NE(error_of([](net::ServerConfig& c) { c.players = 129; }).find("players"),
            std::string::npos);
  // 128 players of 16 bytes: a frame's inputs would not fit a datagram.
  EXPECT_NE(error_of([](net::ServerConfig& c) {
              c.players = 128;
              c.input_size = 16;
            }).find("players"),
            std::string::npos);
  EXPECT_NE(error_of([](net::ServerConfig& c) { c.input_size = 65; }).find("input_size"),
            std::string::npos);
  EXPECT_NE(error_of([](net::ServerConfig& c) { c.frame_us = 10; }).find("frame_us"),
            std::string::npos);
  EXPECT_NE(error_of([](net::ServerConfig& c) { c.start_clients = 3; }).find("start_clients"),
            std::string::npos);
  EXPECT_NE(error_of([](net::ServerConfig& c) { c.update_interval = 0; }).find("update_interval"),
            std::string::npos);
  EXPECT_NE(error_of([](net::ServerConfig& c) { c.history = 4; }).find("history"),
            std::string::npos);
  EXPECT_NE(
      error_of([](net::ServerConfig& c) { c.description.assign(513, 0); }).find("description"),
      std::string::npos);
  net::ClientConfig cc;
  cc.max_prediction = 0;
  auto client = net::Client::create(cc, network->endpoint(1));
  ASSERT_FALSE(client.ok());
  EXPECT_NE(client.message().find("max_prediction"), std::string::npos);
}

TEST(NetServer, TickLatenessCountsHowLateEachFrameWasSimulated) {
  test::CounterGame game;
  auto network = net::SimNetwork::create(2, 1);
  ASSERT_TRUE(network.ok());
  net::ServerConfig c;
  c.players = 1;
  c.start_clients = 0;  // starts at the first advance
  c.frame_us = 10'000;
  c.frames = 100;
  auto server = net::Server::create(c, game, network->endpoint(0));
  ASSERT_TRUE(server.ok()) << server.message();
  // Frame F is due at start + F × 10 ms. On time: frames 0..9 at their times exactly.
  EXPECT_EQ(server->stats().tick_lateness_percentile_us(990), 0U) << "no frame yet";
  for (std::uint64_t f = 0; f < 10; ++f)
    EXPECT_EQ(server->advance(f * 10'000), 1U);
  // Then the loop wakes 25 ms late: frames 10, 11 and 12 at once, 25, 15 and 5 ms late.
  EXPECT_EQ(server->advance(9 * 10'000 + 35'000), 3U);
  const net::ServerStats& st = server->stats();
  const std::uint64_t bucket = net::ServerStats::tick_lateness_bucket_us;
  EXPECT_EQ(st.tick_lateness[0], 10U);
  EXPECT_EQ(st.tick_lateness[5'000 / bucket], 1U);
  EXPECT_EQ(st.tick_lateness[15'000 / bucket], 1U);
  EXPECT_EQ(st.tick_lateness[25'000 / bucket], 1U);
  EXPECT_EQ(st.tick_lateness_max_us, 25'000U);
  // 13 frames: the median is on time (the first bucket's upper edge), the 99th percentile the
  // latest frame's bucket, 80 % (the 11th of 13 in order) the 5 ms one.
  EXPECT_EQ(st.tick_lateness_percentile_us(500), bucket);
  EXPECT_EQ(st.tick_lateness_percentile_us(990), 25'000 + bucket);
  EXPECT_EQ(st.tick_lateness_percentile_us(800), 5'000 + bucket);
  // Later than the histogram holds: the last bucket, and the percentile is the maximum.
  EXPECT_EQ(server->advance(13 * 10'000 + 900'000, 1), 1U);
  EXPECT_EQ(st.tick_lateness.back(), 1U);
  EXPECT_EQ(st.tick_lateness_percentile_us(1000), 900'000U);
}

TEST(NetServer, ClientsOnAPerfectNetworkEndOnTheServersState) {
  ServerMatchOptions o;
  o.clients = 3;
  o.frames = 300;
  ServerMatch m(o);
  ASSERT_TRUE(m.run());
  EXPECT_EQ(m.server().current_frame(), 300U);
  EXPECT_EQ(m.server_hashes().size(), 300U);
  expect_all_agree(m, 3);
  // The server's game simulated every frame once, and its own hash is its game's.
  EXPECT_EQ(m.server_counter()->simulated, 300U);
  EXPECT_EQ(m.server_counter()->resimulated, 0U);
  for (const net::ServerClientStats& c : m.server().client_stats()) {
    EXPECT_EQ(c.packets_rejected, 0U);
    EXPECT_EQ(c.acknowledged_frame, 300U);
  }
}

TEST(NetServer, RightPredictionsMakeNoCorrection) {
  // Every input zero: what each client predicts for the others (their last input, zero before
  // the first) and what the server stamps for a late or missing one (the last again) is right.
  ServerMatchOptions o;
  o.clients = 3;
  o.frames = 400;
  o.link.latency_us = 40'000;
  o.link.jitter_us = 10'000;
  o.input = [](std::uint32_t, std::uint64_t, std::span<std::uint8_t> out) {
    std::fill(out.begin(), out.end(), std::uint8_t{0});
  };
  ServerMatch m(o);
  ASSERT_TRUE(m.run());
  expect_all_agree(m, 3);
  for (std::uint32_t c = 0; c < 3; ++c) {
    EXPECT_EQ(m.client(c)->stats().mispredictions, 0U);
    EXPECT_EQ(m.client(c)->stats().corrections, 0U);
    EXPECT_EQ(m.counter(c)->resimulated, 0U);
    EXPECT_GT(m.client(c)->stats().checks_passed, 0U);
  }
}

TEST(NetServer, MispredictionsAreCorrectedExactly) {
  // Inputs that change every 8 frames: the others' changes are mispredicted, and each is
  // corrected by re-simulation; every correction has a misprediction behind it.
  ServerMatchOptions o;
  o.clients = 4;
  o.frames = 600;
  o.link.latency_us = 30'000;
  ServerMatch m(o);
  ASSERT_TRUE(m.run());
  expect_all_agree(m, 4);
  for (std::uint32_t c = 0; c < 4; ++c) {
    const net::ClientStats& s = m.client(c)->stats();
    EXPECT_GT(s.mispredictions, 0U);
    EXPECT_GT(s.corrections, 0U);
    EXPECT_LE(s.corrections, s.mispredictions);
    EXPECT_GT(s.resimulated_frames, 0U);
  }
}

TEST(NetServer, ABadNetworkStillEndsOnTheServersState) {
  ServerMatchOptions o;
  o.clients = 4;
  o.frames = 600;
  o.seed = 7;
  o.link.latency_us = 50'000;
  o.link.jitter_us = 20'000;
  o.link.loss_ppm = 100'000;      // 10 %
  o.link.duplicate_ppm = 50'000;  // 5 %
  o.link.reorder_ppm = 50'000;
  o.link.reorder_delay_us = 30'000;
  ServerMatch m(o);
  ASSERT_TRUE(m.run());
  expect_all_agree(m, 4);
  std::uint64_t late = 0;
  for (const net::ServerClientStats& c : m.server().client_stats())
    late += c.inputs_late + c.inputs_missing;
  EXPECT_GT(late, 0U);  // the server never waited for them
}

TEST(NetServer, TheServerNeverWaitsForASlowClient) {
  // Client 2 is 200 ms away: the server runs on the clock regardless, its inputs arrive late
  // at first (stamped to later frames) and the time sync then moves it ahead.
  ServerMatchOptions o;
  o.clients = 3;
  o.frames = 600;
  o.setup = [](net::SimNetwork& n) {
    net::LinkConditions slow;
    slow.latency_us = 200'000;
    ASSERT_TRUE(n.set_link(3, 0, slow).ok());
    ASSERT_TRUE(n.set_link(0, 3, slow).ok());
  };
  ServerMatch m(o);
  ASSERT_TRUE(m.run());
  expect_all_agree(m, 3);
  // 600 frames at 60 Hz, started when the last client joined (about 200 ms in): the server
  // ended close to 10 s after its start, not later.
  EXPECT_LT(m.now_ms(), 10'000U + 2'000U);
  const auto stats = m.server().client_stats();
  EXPECT_GT(stats[2].inputs_late + stats[2].inputs_missing, 0U);
}

TEST(NetServer, ALateJoinerAndARestartedClientPlayOn) {
  ServerMatchOptions o;
  o.clients = 4;
  o.frames = 900;  // 15 s
  o.start_clients = 2;
  o.join_ms = {0, 0, 0, 5'000};      // client 3 joins 5 s late
  o.restarts = {{1, 6'000, 6'500}};  // client 1 killed at 6 s, back at 6.5 s
  o.link.latency_us = 20'000;
  o.link.loss_ppm = 20'000;
  ServerMatch m(o);
  ASSERT_TRUE(m.run());
  expect_all_agree(m, 4);
  // The late one and the restarted one started from snapshots.
  EXPECT_GE(m.client(3)->stats().snapshots_received, 1U);
  EXPECT_GE(m.client(1)->stats().snapshots_received, 1U);
  // Nobody paused: the server simulated its frames on time.
  EXPECT_EQ(m.server_hashes().size(), 900U);
  bool left = false;
  for (const net::ServerEvent& e : m.server().take_events())
    left = left || e.type == net::ServerEventType::left;
  EXPECT_TRUE(left);  // the killed client's seat was freed
}

/// Client 2's transport: it plays honestly, and after every datagram it sends, forges more —
/// another token, another client's seat by guessing, frames far ahead, a server's packet type,
/// garbage.
class Forger final : public net::Transport {
 public:
  explicit Forger(net::Transport& inner) : inner_(inner) {}
  void send(net::PeerId to, std::span<const std::uint8_t> bytes) override {
    inner_.send(to, bytes);
    sp::Packet p;
    if (sp::decode(bytes, {3, 4}, p) != sp::DecodeError::none) return;
    if (p.header.type != sp::PacketType::input) return;
    ++n_;
    std::vector<std::uint8_t> out;
    sp::Packet forged = p;
    forged.header.token = p.header.token + 1 + n_;  // a guessed token
    forged.input.inputs.assign(forged.input.inputs.size(), 0xEE);
    if (sp::encode(forged, {3, 4}, out)) inner_.send(to, out);
    forged = p;
    forged.input.start = p.input.start + 5000;  // far beyond the input window
    forged.input.inputs.assign(forged.input.inputs.size(), 0xDD);
    if (sp::encode(forged, {3, 4}, out)) inner_.send(to, out);
    forged = p;
    forged.input.ack = p.input.ack + 100'000;  // acknowledges what was never sent
    if (sp::encode(forged, {3, 4}, out)) inner_.send(to, out);
    forged = p;
    forged.header.type = sp::PacketType::update;  // a server's packet, from a client
    forged.update.count = 0;
    if (sp::encode(forged, {3, 4}, out)) inner_.send(to, out);
    forged = p;
    forged.header.type = sp::PacketType::connect;  // another game, on its own address
    forged.connect = {0xBAD, 7, 0};
    if (sp::encode(forged, {3, 4}, out)) inner_.send(to, out);
    std::vector<std::uint8_t> garbage(bytes.begin(), bytes.end());
    garbage[garbage.size() / 2] ^= 0x5A;
    inner_.send(to, garbage);
  }
  void receive(std::vector<net::Datagram>& out) override { inner_.receive(out); }

 private:
  net::Transport& inner_;
  std::uint64_t n_ = 0;
};

TEST(NetServer, AForgingClientChangesNothing) {
  ServerMatchOptions o;
  o.clients = 3;
  o.frames = 300;
  ServerMatch honest(o);
  ASSERT_TRUE(honest.run());
  o.wrap = [](std::uint32_t c, net::Transport& inner) -> std::unique_ptr<net::Transport> {
    if (c != 2) return nullptr;
    return std::make_unique<Forger>(inner);
  };
  ServerMatch forged(o);
  ASSERT_TRUE(forged.run());
  // The same frames, bit for bit: nothing forged reached the simulation.
  EXPECT_EQ(forged.server_hashes(), honest.server_hashes());
  expect_all_agree(forged, 3);
  const auto stats = forged.server().client_stats();
  EXPECT_EQ(stats[0].packets_rejected, 0U);
  EXPECT_EQ(stats[1].packets_rejected, 0U);
  EXPECT_GT(stats[2].packets_rejected, 0U);
  EXPECT_GT(forged.server().stats().dropped_unknown, 0U);
  std::uint64_t malformed = 0;
  for (std::uint64_t n : forged.server().stats().dropped_malformed)
    malformed += n;
  EXPECT_GT(malformed, 0U);
}

TEST(NetServer, StateAuthorityReconstructsTheServersStateThroughLoss) {
  ServerMatchOptions o;
  o.clients = 3;
  o.frames = 600;
  o.seed = 3;
  o.authority = sp::Authority::state;
  o.snapshot_interval = 2;
  o.link.latency_us = 20'000;
  o.link.jitter_us = 5'000;
  o.link.loss_ppm = 50'000;
  o.link.duplicate_ppm = 20'000;
  ServerMatch m(o);
  ASSERT_TRUE(m.run());
  expect_all_agree(m, 3);
  for (std::uint32_t c = 0; c < 3; ++c) {
    EXPECT_GT(m.client(c)->stats().snapshots_received, 10U);
    EXPECT_GT(m.client(c)->stats().checks_passed, 0U);
  }
}

/// A scenario's game codes its snapshots as state deltas (ScenarioGame::encode_delta), each
/// against the one sent before it; the clients rebuild them through loss and duplication, load
/// them when they mispredicted, and end on the server's state. Without the chain, every snapshot
/// is coded against the newest the client acknowledged, and every one that arrives decodes.
TEST(NetServer, StateDeltasChainedOrAgainstTheAcknowledgedRebuildTheServersState) {
  for (const bool chain : {true, false}) {
    SCOPED_TRACE(chain ? "chained" : "against the acknowledged");
    ServerMatchOptions o;
    o.scenario = "arena";
    o.clients = 3;
    o.frames = 360;
    o.seed = 5;
    o.authority = sp::Authority::state;
    o.snapshot_interval = 1;
    o.update_interval = 1;
    o.link.latency_us = 30'000;
    o.link.jitter_us = 5'000;
    o.link.loss_ppm = 30'000;
    o.link.duplicate_ppm = 20'000;
    o.configure_server = [chain](net::ServerConfig& c) { c.chain_snapshots = chain; };
    ServerMatch m(o);
    ASSERT_TRUE(m.run());
    expect_all_agree(m, 3);
    const auto stats = m.server().client_stats();
    ASSERT_EQ(stats.size(), 3U);
    for (std::uint32_t c = 0; c < 3; ++c) {
      SCOPED_TRACE("client " + std::to_string(c));
      const net::ServerClientStats& sent = stats[c];
      const net::ClientStats& got = m.client(c)->stats();
      // All but the first (full) snapshot and any full one after a long silence are deltas.
      EXPECT_GT(sent.snapshots_game_coded, sent.snapshots_sent * 9 / 10);
      if (chain) {
        EXPECT_GT(sent.snapshots_chained, sent.snapshots_sent / 2);
      } else {
        EXPECT_EQ(sent.snapshots_chained, 0U);
      }
      EXPECT_GT(got.snapshots_received, sent.snapshots_sent / 2);
      EXPECT_GT(got.corrections, 0U);  // mispredictions, put right by the server's states
    }
  }
}

/// A game with a public part (frame and an accumulator of every input, 16 bytes) and a large
/// cosmetic one (2 KiB that churn every frame, a function of the frame alone): what a view can
/// leave out of the snapshots, since every client computes it alike.
class Churn final : public net::Game {
 public:
  std::uint64_t save(std::vector<std::uint8_t>& state) override {
    state.assign(16 + cosmetic_.size(), 0);
    for (int i = 0; i < 8; ++i) {
      state[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(frame_ >> (8 * i));
      state[static_cast<std::size_t>(8 + i)] = static_cast<std::uint8_t>(acc_ >> (8 * i));
    }
    std::copy(cosmetic_.begin(), cosmetic_.end(), state.begin() + 16);
    return hash_bytes(state);
  }
  void load(std::span<const std::uint8_t> state) override {
    frame_ = acc_ = 0;
    for (int i = 0; i < 8; ++i) {
      frame_ |= std::uint64_t{state[static_cast<std::size_t>(i)]} << (8 * i);
      acc_ |= std::uint64_t{state[static_cast<std::size_t>(8 + i)]} << (8 * i);
    }
    std::copy(state.begin() + 16, state.end(), cosmetic_.begin());
  }
  void advance(const net::FrameInputs& inputs, bool) override {
    for (const std::uint8_t b : inputs.bytes)
      acc_ = acc_ * 1099511628211ULL + b;
    ++frame_;
    std::uint64_t x = frame_ * 0x9E3779B97F4A7C15ULL;
    for (std::uint8_t& b : cosmetic_) {
      x ^= x >> 29;
      x *= 0xBF58476D1CE4E5B9ULL;
      b = static_cast<std::uint8_t>(x >> 56);
    }
  }

 private:
  std::uint64_t frame_ = 0;
  std::uint64_t acc_ = 0;
  std::vector<std::uint8_t> cosmetic_ = std::vector<std::uint8_t>(2048, 0);
};

TEST(NetServer, AViewSendsEachClientOnlyWhatItSelectsAndStillEndsExact) {
  ServerMatchOptions o;
  o.clients = 2;
  o.frames = 300;
  o.authority = sp::Authority::state;
  o.snapshot_interval = 2;
  o.link.latency_us = 20'000;
  o.link.loss_ppm = 20'000;
  o.make_game = [] { return std::make_unique<Churn>(); };
  ServerMatch whole(o);
  ASSERT_TRUE(whole.run());
  expect_all_agree(whole, 2);
  // The view: the public 16 bytes only; a client puts them into its own state.
  o.configure_server = [](net::ServerConfig& c) {
    c.view = [](std::uint32_t, std::span<const std::uint8_t> state,
                std::vector<std::uint8_t>& out) { out.assign(state.begin(), state.begin() + 16); };
  };
  o.configure_client = [](std::uint32_t, net::ClientConfig& c) {
    c.view = [](std::uint32_t, std::span<const std::uint8_t> state,
                std::vector<std::uint8_t>& out) { out.assign(state.begin(), state.begin() + 16); };
    c.merge_view = [](std::span<const std::uint8_t> view, std::vector<std::uint8_t>& state) {
      std::copy(view.begin(), view.end(), state.begin());
    };
  };
  ServerMatch viewed(o);
  ASSERT_TRUE(viewed.run());
  expect_all_agree(viewed, 2);  // the whole states, cosmetic part included, still equal
  std::uint64_t whole_bytes = 0;
  std::uint64_t viewed_bytes = 0;
  for (const net::ServerClientStats& c : whole.server().client_stats())
    whole_bytes += c.snapshot_bytes_sent;
  for (const net::ServerClientStats& c : viewed.server().client_stats())
    viewed_bytes += c.snapshot_bytes_sent;
  EXPECT_LT(viewed_bytes * 4, whole_bytes) << viewed_bytes << " vs " << whole_bytes;
  for (std::uint32_t c = 0; c < 2; ++c)
    EXPECT_GT(viewed.client(c)->stats().snapshots_received, 50U);
  // A view is for state authority, and a client's view comes with its merge.
  test::CounterGame game;
  auto network = net::SimNetwork::create(2, 1).value();
  net::ServerConfig bad;
  bad.view = [](std::uint32_t, std::span<const std::uint8_t>, std::vector<std::uint8_t>&) {};
  auto s = net::Server::create(bad, game, network.endpoint(0));
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("view"), std::string::npos);
  net::ClientConfig half;
  half.view = bad.view;
  auto cl = net::Client::create(half, network.endpoint(1));
  ASSERT_FALSE(cl.ok());
  EXPECT_NE(cl.message().find("merge_view"), std::string::npos);
}

TEST(NetServer, AnArenaMatchOfEightIsRecordedAndTheReplayVerifies) {
  test::TempFile replay("server_arena.dsr");
  ServerMatchOptions o;
  o.scenario = "arena";
  o.record = replay.path();
  o.clients = 8;
  o.frames = 240;
  o.link.latency_us = 30'000;
  o.link.jitter_us = 10'000;
  o.link.loss_ppm = 30'000;
  ServerMatch m(o);
  ASSERT_TRUE(m.run());
  expect_all_agree(m, 8);
  ASSERT_NE(m.recorder(), nullptr);
  ASSERT_TRUE(m.recorder()->finish().ok());
  auto reader = replay::ReplayReader::open(o.record);
  ASSERT_TRUE(reader.ok()) << reader.message();
  auto verified = replay::verify(reader.value());
  ASSERT_TRUE(verified.ok()) << verified.message();
  EXPECT_TRUE(verified->ok) << verified->note;
  EXPECT_EQ(verified->frames, 240U);
  EXPECT_EQ(verified->final_hash, m.server().current_hash());
}

TEST(NetServer, SixtyFourClientsOverABadNetworkEndOnTheServersState) {
  ServerMatchOptions o;
  o.clients = 64;
  o.input_size = 3;
  o.frames = 300;
  o.link.latency_us = 40'000;
  o.link.jitter_us = 10'000;
  o.link.loss_ppm = 20'000;
  ServerMatch m(o);
  ASSERT_TRUE(m.run());
  expect_all_agree(m, 64);
}

TEST(NetServer, AClientWhoseSimulationDiffersReportsADesync) {
  // Client 1's game adds one to its state at frame 50: every input it predicted may be right,
  // and still its state is not the server's — a desync, never a silent correction.
  ServerMatchOptions o;
  o.clients = 3;
  o.frames = 200;
  ServerMatch m(o);
  m.run_for(1);  // the clients connect on the first tick
  ASSERT_NE(m.counter(1), nullptr);
  m.counter(1)->fault_frame = 50;
  ASSERT_TRUE(m.run());
  EXPECT_GT(m.client(1)->stats().desyncs, 0U);
  EXPECT_EQ(m.client(0)->stats().desyncs, 0U);
  EXPECT_EQ(m.client(2)->stats().desyncs, 0U);
  std::optional<std::uint64_t> first;
  for (const net::ClientEvent& e : m.client(1)->take_events())
    if (e.type == net::ClientEventType::desync) {
      if (!first) first = e.frame;
      EXPECT_GE(e.frame, 51U);
      EXPECT_NE(e.local_hash, e.remote_hash);
    }
  ASSERT_TRUE(first.has_value());
  // Its side of the first desync, as a peer session keeps it: the last agreed state, the
  // divergent one, and the server's units of every frame before it.
  const net::DesyncEvidence* e = m.client(1)->desync_evidence();
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->divergent_frame, *first);
  EXPECT_LE(e->agreed_frame, 50U);  // the last check before the fault
  EXPECT_LT(e->agreed_frame, e->divergent_frame);
  EXPECT_EQ(e->player, 3U);  // the server: no seat of its own
  EXPECT_EQ(e->confirmed_frames.size(), *first * net::server_protocol::unit_size(3, 4));
  EXPECT_FALSE(e->agreed_state.empty());
  EXPECT_FALSE(e->divergent_state.empty());
  EXPECT_NE(e->local_hash, e->remote_hash);
  // Re-simulating the evidence from the agreed state with its units reaches the divergent state
  // (the fault is this machine's own, so it repeats), and the server's other clients have none.
  test::CounterGame replay;
  replay.fault_frame = 50;
  replay.load(e->agreed_state);
  const std::size_t unit = net::server_protocol::unit_size(3, 4);
  for (std::uint64_t f = e->agreed_frame; f < e->divergent_frame; ++f) {
    const std::span<const std::uint8_t> u =
        std::span<const std::uint8_t>(e->confirmed_frames).subspan(f * unit, unit);
    std::vector<net::InputStatus> status(3);
    for (std::size_t p = 0; p < 3; ++p)
      status[p] = (u[0] >> p) & 1U ? net::InputStatus::disconnected : net::InputStatus::confirmed;
    replay.advance(net::FrameInputs{f, 4, u.subspan(1), status}, false);
  }
  std::vector<std::uint8_t> state;
  EXPECT_EQ(replay.save(state), e->local_hash);
  EXPECT_EQ(state, e->divergent_state);
  EXPECT_EQ(m.client(0)->desync_evidence(), nullptr);
}

TEST(NetServer, AFullServerTurnsAClientAwayAndASeatCanBeAskedFor) {
  ServerMatchOptions o;
  o.clients = 3;
  o.players = 2;
  o.start_clients = 2;
  o.frames = 60;
  o.join_ms = {0, 0, 200};
  o.max_ms = 3'000;
  o.configure_client = [](std::uint32_t c, net::ClientConfig& config) {
    if (c == 0) config.seat = 1;  // asks for seat 1: client 1 gets seat 0
  };
  ServerMatch m(o);
  EXPECT_FALSE(m.run());  // client 2 never plays
  EXPECT_EQ(m.client(2)->failure(), "the server has no free seat");
  EXPECT_EQ(m.client(0)->welcome()->player, 1);
  EXPECT_EQ(m.client(1)->welcome()->player, 0);
  EXPECT_TRUE(m.client(0)->ended());
  EXPECT_TRUE(m.client(1)->ended());
}

TEST(NetServer, ClientsThatComeAndGoCostABoundedRecord) {
  // 300 clients, one after the other, take the one seat and leave: the server keeps the
  // statistics of the newest 256 and reuses the slot, so memory does not grow with them.
  test::CounterGame game;
  auto network = net::SimNetwork::create(2, 1).value();
  net::ServerConfig config;
  config.players = 1;
  config.game = 9;
  auto server = net::Server::create(config, game, network.endpoint(0)).value();
  std::uint64_t now = 0;
  for (int k = 0; k < 300; ++k) {
    net::ClientConfig cc;
    cc.game = 9;
    auto client = net::Client::create(cc, network.endpoint(1)).value();
    for (int i = 0; i < 50 && client.welcome() == nullptr; ++i) {
      now += 1000;
      network.advance_to(now);
      client.poll(now);
      server.poll(now);
    }
    ASSERT_NE(client.welcome(), nullptr) << k;
    client.leave();
    now += 1000;
    network.advance_to(now);
    server.poll(now);
  }
  EXPECT_EQ(server.stats().connects, 300U);
  EXPECT_EQ(server.stats().clients_left, 300U);
  const std::vector<net::ServerClientStats> stats = server.client_stats();
  EXPECT_EQ(stats.size(), 256U);
  for (const net::ServerClientStats& c : stats)
    EXPECT_FALSE(c.connected);
}

TEST(NetServer, TheCorrectionSmootherHidesAJumpAndDecaysItsOffset) {
  using namespace detsim::literals;
  net::CorrectionSmoother smoother(2_fx);                   // halves every two frames
  smoother.corrected({1_fx, 0_fx, -2_fx});                  // the simulation jumped by +1, 0, -2
  EXPECT_EQ(smoother.offset(), (Vec3{-1_fx, 0_fx, 2_fx}));  // drawn where it was
  smoother.frame();
  smoother.frame();
  // 2^-1/2 squared is a half, to within the rounding of two products.
  EXPECT_NEAR(smoother.offset().x.to_double(), -0.5, 1e-8);
  EXPECT_NEAR(smoother.offset().z.to_double(), 1.0, 1e-8);
  for (int i = 0; i < 80; ++i)
    smoother.frame();
  EXPECT_LT(std::abs(smoother.offset().x.to_double()), 1e-6);
}

TEST(NetServer, AWrongGameIsRejectedWithAReason) {
  ServerMatchOptions o;
  o.clients = 2;
  o.frames = 60;
  o.start_clients = 1;
  o.configure_client = [](std::uint32_t c, net::ClientConfig& config) {
    if (c == 1) config.game = 0xBAD;
  };
  o.max_ms = 500;
  ServerMatch m(o);
  EXPECT_FALSE(m.run());  // client 1 never plays
  EXPECT_EQ(m.client(1)->failure(), "the server runs another game");
  EXPECT_EQ(m.client(1)->welcome(), nullptr);
  EXPECT_EQ(m.server().stats().rejects, 1U);
}

}  // namespace
}  // namespace detsim
