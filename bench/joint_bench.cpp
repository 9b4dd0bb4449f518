// Joint benchmarks (issue 17, "Performance"): a 500-link chain and 100 ragdolls falling on a plane,
// 600 steps each, in detsim and in Bullet 3 side by side in one run, with the joint stretch of both
// engines reported beside the times (a faster but stretchier solver is not a win).
//
// Method (docs/BENCHMARKS.md, "Joints", repeats it for readers of the figures):
// - The scenes are built in detsim (the `chain` scenario with 500 links; 100 figures of
//   <detsim/scenes/ragdoll.hpp> on a plane), read back at frame 0 into a JointScene of plain
//   doubles and built from that in Bullet (bullet_joint_peer.cpp): the same bodies, shapes,
//   masses, start velocities, frictions (sqrt per body: Bullet multiplies two, detsim takes the
//   geometric mean), damping and joints (ball, hinge with limits, swing-twist as cone-twist).
// - Engines: detsim with its default WorldDef (60 Hz, 4 sub-steps, 1 iteration: per sub-step one
//   solve and one relax pass over every row); "bullet" = Bullet's default and the project's
//   anchor setting (one 1/60 s step, 10 iterations); "bullet_sub4" = 4 sub-steps of 1/240 s with
//   2 iterations each, the same number of velocity passes per frame as detsim.
// - One iteration is the whole run: building is untimed, each of the steps is timed with the
//   thread's CPU clock (manual time); the stretch is read between steps, untimed. Counters:
//   ms_per_step; stretch at the end (worst and mean anchor separation over the joints, m) and
//   the worst at any step; dynamic bodies awake at the end.
// Bench code is not simulation code: double is used freely here.

#include <benchmark/benchmark.h>

#include <time.h>  // clock_gettime, CLOCK_THREAD_CPUTIME_ID (POSIX)

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include <bench_config.hpp>
#include <detsim/detsim.hpp>

#include "joint_scene.hpp"
#if DETSIM_BENCH_HAVE_BULLET
#include "bullet_joint_peer.hpp"
#endif

namespace {

using namespace detsim::literals;
using detsim_bench::JointScene;
using detsim_bench::SceneBody;
using detsim_bench::SceneJoint;
using detsim_bench::Stretch;

struct Options {
  std::uint32_t steps = 600;
  std::uint32_t chain_links = 500;
  std::uint32_t ragdolls = 100;
};

Options options;

bool parse_options(int& argc, char** argv) {
  struct Flag {
    std::string_view name;
    std::uint32_t* value;
  };
  const Flag flags[] = {{"--joint_steps=", &options.steps},
                        {"--joint_chain_links=", &options.chain_links},
                        {"--joint_ragdolls=", &options.ragdolls}};
  int kept = 1;
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg(argv[i]);
    bool consumed = false;
    for (const Flag& flag : flags) {
      if (arg.substr(0, flag.name.size()) != flag.name) continue;
      const std::string text(arg.substr(flag.name.size()));
      char* end = nullptr;
      const unsigned long v = std::strtoul(text.c_str(), &end, 10);
      if (text.empty() || *end != '\0' || v == 0 || v > 100'000) {
        std::fprintf(stderr, "joint_bench: %s needs a whole number from 1 to 100000\n", argv[i]);
        return false;
      }
      *flag.value = static_cast<std::uint32_t>(v);
      consumed = true;
    }
    if (!consumed) argv[kept++] = argv[i];
  }
  argc = kept;
  return true;
}

double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

[[noreturn]] void fail(const std::string& what) {
  std::fprintf(stderr, "joint_bench: %s\n", what.c_str());
  std::exit(1);
}

// ---- The scenes, built in detsim ----------------------------------------------------------------

enum class Scene { chain, ragdolls };

detsim::World build_chain() {
  auto made = detsim::Scenario::create("chain", {.count = options.chain_links});
  if (!made) fail(made.message());
  return std::move(made.value().world());
}

detsim::World build_ragdolls() {
  auto made = detsim::World::create({});
  if (!made) fail(made.message());
  detsim::World w = std::move(made.value());
  if (!w.create_body({.type = detsim::BodyType::static_body, .shape = detsim::Shape::plane()}))
    fail("plane refused");
  // A square grid 2 m apart, each figure turned about its feet by up to 80 degrees (alternately
  // about z and x, varied by index) and lifted 1.5 to 2.5 m, so that they land in every pose.
  std::uint32_t side = 1;
  while (side * side < options.ragdolls)
    ++side;
  for (std::uint32_t i = 0; i < options.ragdolls; ++i) {
    const auto x = static_cast<std::int32_t>(i % side) * 2 - static_cast<std::int32_t>(side);
    const auto z = static_cast<std::int32_t>(i / side) * 2 - static_cast<std::int32_t>(side);
    const detsim::Fixed angle =
        detsim::Fixed::from_int(static_cast<std::int32_t>(i % 9) - 4) * 0.35_fx;
    const detsim::Vec3 axis =
        i % 2 == 0 ? detsim::Vec3{0_fx, 0_fx, 1_fx} : detsim::Vec3{1_fx, 0_fx, 0_fx};
    auto r = detsim::add_ragdoll(
        w, {.position = {detsim::Fixed::from_int(x),
                         1.5_fx + detsim::Fixed::from_int(static_cast<std::int32_t>(i % 3)) / 2_fx,
                         detsim::Fixed::from_int(z)},
            .orientation = detsim::from_axis_angle(axis, angle),
            .angular_damping = 0.5_fx});
    if (!r) fail(r.message());
  }
  return w;
}

detsim::World build(Scene scene) {
  return scene == Scene::chain ? build_chain() : build_ragdolls();
}

std::array<double, 3> to3(detsim::Vec3 v) {
  return {v.x.to_double(), v.y.to_double(), v.z.to_double()};
}

/// The World at frame 0 in plain doubles, for the Bullet peer.
JointScene export_scene(const detsim::World& w) {
  JointScene s;
  s.dt = w.def().dt.to_double();
  s.gravity_y = w.def().gravity.y.to_double();
  std::map<std::uint32_t, std::uint32_t> index;
  for (const detsim::BodyId id : w.body_ids()) {
    const detsim::BodyState b = w.body(id).value();
    SceneBody out;
    switch (b.shape.type) {
      case detsim::ShapeType::sphere:
        out.kind = SceneBody::Kind::sphere;
        break;
      case detsim::ShapeType::box:
        out.kind = SceneBody::Kind::box;
        break;
      case detsim::ShapeType::capsule:
        out.kind = SceneBody::Kind::capsule;
        break;
      case detsim::ShapeType::plane:
        out.kind = SceneBody::Kind::plane;
        break;
      default:
        fail("a shape the Bullet peer does not build");
    }
    out.dynamic = b.type == detsim::BodyType::dynamic;
    out.radius = b.shape.radius.to_double();
    out.half_height = b.shape.half_height.to_double();
    out.half_extents = to3(b.shape.half_extents);
    out.position = to3(b.position);
    out.orientation = {b.orientation.w.to_double(), b.orientation.x.to_double(),
                       b.orientation.y.to_double(), b.orientation.z.to_double()};
    out.linear_velocity = to3(b.linear_velocity);
    out.angular_velocity = to3(b.angular_velocity);
    out.mass = b.mass.to_double();
    out.friction = b.friction.to_double();
    out.linear_damping = b.linear_damping.to_double();
    out.angular_damping = b.angular_damping.to_double();
    index[id.value] = static_cast<std::uint32_t>(s.bodies.size());
    s.bodies.push_back(out);
  }
  for (const detsim::JointId id : w.joint_ids()) {
    const detsim::JointDef d = w.joint(id).value().def;
    SceneJoint out;
    switch (d.type) {
      case detsim::JointType::ball:
        out.kind = SceneJoint::Kind::ball;
        break;
      case detsim::JointType::hinge:
        out.kind = SceneJoint::Kind::hinge;
        break;
      case detsim::JointType::fixed:
        out.kind = SceneJoint::Kind::fixed;
        break;
      case detsim::JointType::swing_twist:
        out.kind = SceneJoint::Kind::swing_twist;
        break;
      default:
        fail("a joint type the Bullet peer does not build");
    }
    out.body_a = index.at(d.body_a.value);
    out.body_b = index.at(d.body_b.value);
    out.anchor = to3(d.anchor);
    out.axis = to3(d.axis);
    out.limit_enabled = d.limit_enabled;
    out.limit_lower = d.limit_lower.to_double();
    out.limit_upper = d.limit_upper.to_double();
    out.swing_limit = d.swing_limit.to_double();
    out.motor_enabled = d.motor_enabled;
    out.motor_speed = d.motor_speed.to_double();
    out.motor_max_force = d.motor_max_force.to_double();
    s.joints.push_back(out);
  }
  return s;
}

// ---- The engines behind one shape ---------------------------------------------------------------

class DetsimRun {
 public:
  explicit DetsimRun(Scene scene) : world_(build(scene)) {}
  void step() { world_.step(); }
  [[nodiscard]] Stretch stretch() const {
    Stretch s;
    std::size_t n = 0;
    for (const detsim::JointId id : world_.joint_ids()) {
      const detsim::JointState j = world_.joint(id).value();
      if (j.broken) continue;
      const detsim::BodyState a = world_.body(j.def.body_a).value();
      const detsim::BodyState b = world_.body(j.def.body_b).value();
      const detsim::Vec3 pa = a.position + detsim::rotate(a.orientation, j.local_anchor_a);
      const detsim::Vec3 pb = b.position + detsim::rotate(b.orientation, j.local_anchor_b);
      const double gap = detsim::length(pb - pa).to_double();
      s.worst = std::max(s.worst, gap);
      s.mean += gap;
      ++n;
    }
    if (n != 0) s.mean /= static_cast<double>(n);
    return s;
  }
  [[nodiscard]] std::uint32_t awake_count() const {
    std::uint32_t n = 0;
    for (const detsim::BodyId id : world_.body_ids()) {
      const detsim::BodyState b = world_.body(id).value();
      if (b.type == detsim::BodyType::dynamic && b.awake) ++n;
    }
    return n;
  }
  [[nodiscard]] std::size_t bodies() const { return world_.body_count(); }
  [[nodiscard]] std::size_t joints() const { return world_.joint_ids().size(); }

 private:
  detsim::World world_;
};

#if DETSIM_BENCH_HAVE_BULLET
template <int Substeps, int Iterations>
class BulletRun {
 public:
  explicit BulletRun(Scene scene) {
    const detsim::World w = build(scene);
    const JointScene s = export_scene(w);
    bodies_ = s.bodies.size();
    joints_ = s.joints.size();
    peer_ = std::make_unique<detsim_bench::BulletJointScene>(s, Substeps, Iterations);
  }
  void step() { peer_->step(); }
  [[nodiscard]] Stretch stretch() const { return peer_->stretch(); }
  [[nodiscard]] std::uint32_t awake_count() const { return peer_->awake_count(); }
  [[nodiscard]] std::size_t bodies() const { return bodies_; }
  [[nodiscard]] std::size_t joints() const { return joints_; }

 private:
  std::unique_ptr<detsim_bench::BulletJointScene> peer_;
  std::size_t bodies_ = 0;
  std::size_t joints_ = 0;
};
#endif

template <class Run>
void whole_run(benchmark::State& state, Scene scene) {
  double worst_during = 0.0;
  double seconds = 0.0;
  std::optional<Run> run;
  for (auto _ : state) {
    run.reset();
    run.emplace(scene);
    worst_during = 0.0;
    seconds = 0.0;
    for (std::uint32_t i = 0; i < options.steps; ++i) {
      const double before = thread_cpu_seconds();
      run->step();
      seconds += thread_cpu_seconds() - before;
      worst_during = std::max(worst_during, run->stretch().worst);
    }
    state.SetIterationTime(seconds);
  }
  const Stretch end = run->stretch();
  state.counters["ms_per_step"] = 1e3 * seconds / static_cast<double>(options.steps);
  state.counters["stretch_end_worst_m"] = end.worst;
  state.counters["stretch_end_mean_m"] = end.mean;
  state.counters["stretch_run_worst_m"] = worst_during;
  state.counters["awake_at_end"] = run->awake_count();
  state.counters["bodies"] = static_cast<double>(run->bodies());
  state.counters["joints"] = static_cast<double>(run->joints());
  state.counters["steps"] = options.steps;
}

void register_benchmarks() {
  for (const Scene scene : {Scene::chain, Scene::ragdolls}) {
    const std::string name = scene == Scene::chain ? "chain" : "ragdolls";
    const auto add = [&](const std::string& engine, auto fn) {
      benchmark::RegisterBenchmark((name + "/" + engine).c_str(), fn)
          ->Iterations(1)
          ->UseManualTime()
          ->Unit(benchmark::kMillisecond);
    };
    add("detsim", [scene](benchmark::State& s) { whole_run<DetsimRun>(s, scene); });
#if DETSIM_BENCH_HAVE_BULLET
    add("bullet", [scene](benchmark::State& s) { whole_run<BulletRun<1, 10>>(s, scene); });
    add("bullet_sub4", [scene](benchmark::State& s) { whole_run<BulletRun<4, 2>>(s, scene); });
#endif
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (!parse_options(argc, argv)) return 2;
  register_benchmarks();
  const detsim::WorldDef def;
  benchmark::AddCustomContext("detsim_compiler", DETSIM_BENCH_COMPILER);
  benchmark::AddCustomContext("detsim_cxx_flags", DETSIM_BENCH_CXX_FLAGS);
  benchmark::AddCustomContext("detsim_build_type", DETSIM_BENCH_BUILD_TYPE);
  benchmark::AddCustomContext("detsim_substeps", std::to_string(def.substeps));
  benchmark::AddCustomContext("detsim_iterations", std::to_string(def.iterations));
  benchmark::AddCustomContext("joint_steps", std::to_string(options.steps));
  benchmark::AddCustomContext("joint_chain_links", std::to_string(options.chain_links));
  benchmark::AddCustomContext("joint_ragdolls", std::to_string(options.ragdolls));
  benchmark::AddCustomContext("bullet", "1 step of 1/60 s, 10 iterations");
  benchmark::AddCustomContext("bullet_sub4", "4 steps of 1/240 s, 2 iterations each");
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
