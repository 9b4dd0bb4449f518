// Convex hulls dropped on a plane (issue "shapes", "Performance"): N copies of one 12-point rock
// on a cubic lattice, in detsim and in Bullet 3 (btConvexHullShape) side by side in one run.
//
// Method (docs/BENCHMARKS.md, "Convex hulls", repeats it for readers of the figures):
// - The rock: 12 points from detsim's RNG (seed 7) on an ellipsoid of semi-axes 0.5, 0.35, 0.45 m;
//   detsim builds its hull (World::create_convex_hull), Bullet gets the same 12 points as floats
//   (btConvexHullShape with its default collision margin, 0.04 m, which Bullet's GJK needs: its
//   rocks are that much rounder and larger, which the mean heights show).
// - Lattice of side ceil(cbrt(N)), spacing 1.3 m, lowest layer 1 m up; density 1000 kg/m^3 in
//   detsim, the same mass and Bullet's own inertia of the hull in Bullet; friction 0.5 each.
// - Engines: detsim with its default WorldDef (60 Hz, 4 sub-steps, 1 iteration); "bullet" =
//   Bullet's default (one 1/60 s step, 10 iterations).
// - One iteration is the whole run: building is untimed, each of the steps is timed with the
//   thread's CPU clock. Counters: ms_per_step, mean_height (m, a check that both piles settle
//   alike), awake_at_end.
// Bench code is not simulation code: double is used freely here.

#include <benchmark/benchmark.h>

#include <time.h>  // clock_gettime, CLOCK_THREAD_CPUTIME_ID (POSIX)

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <detsim/detsim.hpp>

#if DETSIM_BENCH_HAVE_BULLET
#include <btBulletDynamicsCommon.h>
#endif

namespace {

using namespace detsim::literals;

struct Options {
  std::uint32_t count = 1000;
  std::uint32_t steps = 300;
};

Options options;

bool parse_options(int& argc, char** argv) {
  int kept = 1;
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg(argv[i]);
    std::uint32_t* value = nullptr;
    std::string_view text;
    if (arg.substr(0, 13) == "--hull_count=") {
      value = &options.count;
      text = arg.substr(13);
    } else if (arg.substr(0, 13) == "--hull_steps=") {
      value = &options.steps;
      text = arg.substr(13);
    }
    if (value == nullptr) {
      argv[kept++] = argv[i];
      continue;
    }
    const std::string s(text);
    char* end = nullptr;
    const unsigned long v = std::strtoul(s.c_str(), &end, 10);
    if (s.empty() || *end != '\0' || v == 0 || v > 100'000) {
      std::fprintf(stderr, "hull_bench: %s needs a whole number from 1 to 100000\n", argv[i]);
      return false;
    }
    *value = static_cast<std::uint32_t>(v);
  }
  argc = kept;
  return true;
}

double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

std::vector<detsim::Vec3> rock() {
  detsim::Rng rng(7);
  std::vector<detsim::Vec3> points;
  for (int i = 0; i < 12; ++i) {
    const detsim::Vec3 u = rng.unit_vector();
    points.push_back({u.x * 0.5_fx, u.y * 0.35_fx, u.z * 0.45_fx});
  }
  return points;
}

std::uint32_t lattice_side(std::uint32_t count) {
  std::uint32_t side = 1;
  while (std::uint64_t{side} * side * side < count)
    ++side;
  return side;
}

// A bench-side conversion (the library has none from double, by design): nearest Q32.32.
detsim::Fixed fixed_of(double x) {
  return detsim::Fixed::from_raw(static_cast<std::int64_t>(std::llround(x * 4294967296.0)));
}

// Lattice position k (x, y, z) in metres.
std::array<double, 3> lattice(std::uint32_t k, std::uint32_t side) {
  const auto centred = [side](std::uint32_t i) {
    return (static_cast<double>(i) - static_cast<double>(side / 2)) * 1.3;
  };
  return {centred(k % side), 1.0 + 1.3 * static_cast<double>(k / (side * side)),
          centred((k / side) % side)};
}

class DetsimHulls {
 public:
  DetsimHulls() : world_(detsim::World::create({}).value()) {
    detsim::BodyDef ground;
    ground.type = detsim::BodyType::static_body;
    ground.shape = detsim::Shape::plane();
    ground.friction = 0.5_fx;
    (void)world_.create_body(ground).value();
    const detsim::GeometryId g = world_.create_convex_hull(rock()).value();
    const std::uint32_t side = lattice_side(options.count);
    for (std::uint32_t i = 0; i < options.count; ++i) {
      const auto p = lattice(i, side);
      detsim::BodyDef d;
      d.shape = detsim::Shape::convex(g);
      d.position = {fixed_of(p[0]), fixed_of(p[1]), fixed_of(p[2])};
      d.friction = 0.5_fx;
      (void)world_.create_body(d).value();
    }
  }
  void step() { world_.step(); }
  [[nodiscard]] double mean_height() const {
    double sum = 0;
    std::uint32_t n = 0;
    for (const detsim::BodyId id : world_.body_ids()) {
      const detsim::BodyState b = world_.body(id).value();
      if (b.type != detsim::BodyType::dynamic) continue;
      sum += b.position.y.to_double();
      ++n;
    }
    return n == 0 ? 0.0 : sum / n;
  }
  [[nodiscard]] std::uint32_t awake_count() const {
    std::uint32_t n = 0;
    for (const detsim::BodyId id : world_.body_ids())
      n += world_.body(id).value().awake ? 1U : 0U;
    return n;
  }

 private:
  detsim::World world_;
};

#if DETSIM_BENCH_HAVE_BULLET
class BulletHulls {
 public:
  BulletHulls() {
    world_.setGravity(btVector3(0, btScalar(-9.81), 0));
    world_.getSolverInfo().m_numIterations = 10;
    btRigidBody::btRigidBodyConstructionInfo ground_info(0, nullptr, &ground_shape_);
    ground_info.m_friction = btScalar(0.5);
    ground_ = std::make_unique<btRigidBody>(ground_info);
    world_.addRigidBody(ground_.get());
    for (const detsim::Vec3 p : rock())
      hull_.addPoint(btVector3(static_cast<btScalar>(p.x.to_double()),
                               static_cast<btScalar>(p.y.to_double()),
                               static_cast<btScalar>(p.z.to_double())));
    // The mass detsim gives the rock (its volume at 1000 kg/m^3), Bullet's own inertia for it.
    detsim::World probe = detsim::World::create({}).value();
    const detsim::GeometryId g = probe.create_convex_hull(rock()).value();
    const double mass = 1000.0 * volume_of(probe, g);
    btVector3 inertia(0, 0, 0);
    hull_.calculateLocalInertia(static_cast<btScalar>(mass), inertia);
    const std::uint32_t side = lattice_side(options.count);
    for (std::uint32_t i = 0; i < options.count; ++i) {
      const auto p = lattice(i, side);
      btTransform t;
      t.setIdentity();
      t.setOrigin(btVector3(static_cast<btScalar>(p[0]), static_cast<btScalar>(p[1]),
                            static_cast<btScalar>(p[2])));
      states_.push_back(std::make_unique<btDefaultMotionState>(t));
      btRigidBody::btRigidBodyConstructionInfo info(static_cast<btScalar>(mass),
                                                    states_.back().get(), &hull_, inertia);
      info.m_friction = btScalar(0.5);
      bodies_.push_back(std::make_unique<btRigidBody>(info));
      world_.addRigidBody(bodies_.back().get());
    }
  }
  ~BulletHulls() {
    for (auto it = bodies_.rbegin(); it != bodies_.rend(); ++it)
      world_.removeRigidBody(it->get());
    world_.removeRigidBody(ground_.get());
  }
  BulletHulls(const BulletHulls&) = delete;
  BulletHulls& operator=(const BulletHulls&) = delete;
  void step() { world_.stepSimulation(btScalar(1) / btScalar(60), 0); }
  [[nodiscard]] double mean_height() const {
    double sum = 0;
    for (const auto& b : bodies_)
      sum += static_cast<double>(b->getCenterOfMassPosition().y());
    return bodies_.empty() ? 0.0 : sum / static_cast<double>(bodies_.size());
  }
  [[nodiscard]] std::uint32_t awake_count() const {
    std::uint32_t n = 0;
    for (const auto& b : bodies_)
      n += b->isActive() ? 1U : 0U;
    return n;
  }

 private:
  // The rock's volume (m^3): the mass detsim gives a body of it at density 1 kg/m^3.
  static double volume_of(detsim::World& w, detsim::GeometryId g) {
    detsim::BodyDef d;
    d.shape = detsim::Shape::convex(g);
    d.density = 1_fx;
    const detsim::BodyId id = w.create_body(d).value();
    return w.body(id).value().mass.to_double();
  }

  btDefaultCollisionConfiguration configuration_;
  btCollisionDispatcher dispatcher_{&configuration_};
  btDbvtBroadphase broadphase_;
  btSequentialImpulseConstraintSolver solver_;
  btDiscreteDynamicsWorld world_{&dispatcher_, &broadphase_, &solver_, &configuration_};
  btStaticPlaneShape ground_shape_{btVector3(0, 1, 0), 0};
  btConvexHullShape hull_;
  std::unique_ptr<btRigidBody> ground_;
  std::vector<std::unique_ptr<btDefaultMotionState>> states_;
  std::vector<std::unique_ptr<btRigidBody>> bodies_;
};
#endif

template <class Engine>
void whole_run(benchmark::State& state) {
  std::unique_ptr<Engine> engine;
  double seconds = 0;
  for (auto _ : state) {
    state.PauseTiming();
    engine.reset();
    engine = std::make_unique<Engine>();
    state.ResumeTiming();
    const double before = thread_cpu_seconds();
    for (std::uint32_t i = 0; i < options.steps; ++i)
      engine->step();
    seconds = thread_cpu_seconds() - before;
  }
  state.counters["ms_per_step"] = 1e3 * seconds / options.steps;
  state.counters["bodies"] = options.count;
  state.counters["mean_height"] = engine->mean_height();
  state.counters["awake_at_end"] = engine->awake_count();
}

void BM_hulls_detsim(benchmark::State& state) {
  whole_run<DetsimHulls>(state);
}
BENCHMARK(BM_hulls_detsim)->Unit(benchmark::kMillisecond)->Iterations(1)->Repetitions(3);

#if DETSIM_BENCH_HAVE_BULLET
void BM_hulls_bullet(benchmark::State& state) {
  whole_run<BulletHulls>(state);
}
BENCHMARK(BM_hulls_bullet)->Unit(benchmark::kMillisecond)->Iterations(1)->Repetitions(3);
#endif

}  // namespace

int main(int argc, char** argv) {
  if (!parse_options(argc, argv)) return 2;
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
