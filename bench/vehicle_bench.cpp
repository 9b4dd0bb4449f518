// Vehicles (issue 20, "Performance"): 100 cars driving on a bumpy triangle-mesh ground, detsim's
// World::create_vehicle beside Bullet 3's btRaycastVehicle (if found) with the same set-up, in one
// run.
//
// Method:
// - Ground: a 120 x 120 m triangle mesh of 2 m cells with bumps 0.1 sin(x / 1.7) cos(z / 2.3) m,
//   built in Fixed and handed to Bullet as the same numbers (btBvhTriangleMeshShape).
// - Cars: 100 on a 10 x 10 grid 10 m apart, each a 1.8 x 0.8 x 4 m box of 1200 kg on four
//   wheels (radius 0.35 m, 0.3 m of travel, 40 kN/m and 4 kN s/m per wheel; Bullet's stiffness and
//   damping are per unit of chassis mass: 33.3 and 3.33), the rear two driven, steered 0.15 rad
//   (they drive in circles of about 17 m, 10 m apart, so neighbours brush now and then), at a
//   quarter throttle (detsim: its engine and gearbox; Bullet: the same 1500 N wheel force its
//   first gear gives at the start, constant).
// - detsim at its defaults (4 sub-steps of 1/240 s, 4 iterations); Bullet at its defaults (one
//   internal step of 1/60 s, 10 iterations; the raycast vehicle updates once per internal step).
//   Each engine is timed per step with the thread's CPU clock, 60 steps untimed, then 300.
//   Counters: ms_per_step, us_per_vehicle, mean speed (m/s: a check that both drive alike).
// Bench code is not simulation code: double is used freely here.
#include <benchmark/benchmark.h>

#include <time.h>  // clock_gettime, CLOCK_THREAD_CPUTIME_ID (POSIX)

#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include <detsim/detsim.hpp>

#if DETSIM_BENCH_HAVE_BULLET
#include <BulletDynamics/Vehicle/btRaycastVehicle.h>
#include <btBulletDynamicsCommon.h>
#endif

namespace {

using namespace detsim::literals;
using detsim::Fixed;
using detsim::Vec3;

double thread_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + double(t.tv_nsec) * 1e-9;
}

constexpr int kSide = 61;  // mesh vertices per side: 60 cells of 2 m
constexpr int kCars = 100;
constexpr double kCell = 2;
constexpr double kChassisMass = 1200;
constexpr double kSteer = 0.15;

struct Ground {
  std::vector<Vec3> vertices;
  std::vector<std::uint32_t> indices;
};

const Ground& ground() {
  static const Ground g = [] {
    Ground out;
    for (int i = 0; i < kSide; ++i) {
      for (int j = 0; j < kSide; ++j) {
        const Fixed x = Fixed::from_int(j * 2 - 60);
        const Fixed z = Fixed::from_int(i * 2 - 60);
        const Fixed y = 0.1_fx * detsim::sin(x / 1.7_fx) * detsim::cos(z / 2.3_fx);
        out.vertices.push_back({x, y, z});
      }
    }
    for (std::uint32_t i = 0; i + 1 < kSide; ++i) {
      for (std::uint32_t j = 0; j + 1 < kSide; ++j) {
        const std::uint32_t a = i * kSide + j;
        const std::uint32_t b = (i + 1) * kSide + j;
        out.indices.insert(out.indices.end(), {a, b, a + 1, b, b + 1, a + 1});
      }
    }
    return out;
  }();
  return g;
}

/// Car k's start: x and z on a grid 10 m apart, 1 m up.
double start_x(int k) {
  return (k % 10) * 10.0 - 45;
}
double start_z(int k) {
  return (k / 10) * 10.0 - 45;
}

Fixed fx(double v) {
  return Fixed::from_raw(static_cast<std::int64_t>(std::llround(v * 4294967296.0)));
}

void BM_Vehicles_detsim(benchmark::State& state) {
  detsim::World world;
  const Ground& g = ground();
  detsim::BodyDef floor;
  floor.type = detsim::BodyType::static_body;
  floor.shape = detsim::Shape::mesh(world.create_mesh(g.vertices, g.indices).value());
  floor.friction = 1_fx;
  (void)world.create_body(floor).value();
  std::vector<detsim::VehicleId> cars;
  for (int k = 0; k < kCars; ++k) {
    detsim::BodyDef c;
    c.shape = detsim::Shape::box({0.9_fx, 0.4_fx, 2_fx});
    c.position = {fx(start_x(k)), 1_fx, fx(start_z(k))};
    c.mass = fx(kChassisMass);
    detsim::VehicleDef d;
    d.chassis = world.create_body(c).value();
    for (const Fixed x : {0.8_fx, -0.8_fx}) {
      for (const Fixed z : {1.3_fx, -1.3_fx}) {
        detsim::WheelDef w;
        w.attachment = {x, -0.2_fx, z};
        w.driven = z < 0_fx;
        w.max_steer_angle = z > 0_fx ? fx(kSteer) : 0_fx;
        d.wheels.push_back(w);
      }
    }
    const detsim::VehicleId id = world.create_vehicle(d).value();
    detsim::VehicleInput in;
    in.throttle = 0.25_fx;
    in.steering = fx(1);
    (void)world.set_vehicle_input(id, in);
    cars.push_back(id);
  }
  for (int i = 0; i < 60; ++i)
    world.step();
  double total = 0;
  int steps = 0;
  for (auto _ : state) {
    const double t0 = thread_seconds();
    world.step();
    const double t = thread_seconds() - t0;
    total += t;
    state.SetIterationTime(t);
    ++steps;
  }
  double speed = 0;
  for (const detsim::VehicleId id : cars)
    speed += std::abs(world.vehicle(id)->forward_speed.to_double());
  state.counters["ms_per_step"] = 1e3 * total / steps;
  state.counters["us_per_vehicle"] = 1e6 * total / steps / kCars;
  state.counters["mean_speed"] = speed / kCars;
}

#if DETSIM_BENCH_HAVE_BULLET
struct BulletVehicles {
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld world{&dispatcher, &broadphase, &solver, &configuration};
  std::vector<btScalar> vertices;
  std::vector<int> indices;
  std::unique_ptr<btTriangleIndexVertexArray> mesh;
  std::unique_ptr<btBvhTriangleMeshShape> ground_shape;
  std::unique_ptr<btRigidBody> floor;
  btBoxShape chassis_shape{btVector3(0.9f, 0.4f, 2.0f)};
  std::vector<std::unique_ptr<btDefaultMotionState>> states;
  std::vector<std::unique_ptr<btRigidBody>> chassis;
  std::unique_ptr<btDefaultVehicleRaycaster> raycaster;
  std::vector<std::unique_ptr<btRaycastVehicle>> vehicles;
  btRaycastVehicle::btVehicleTuning tuning;

  BulletVehicles() {
    world.setGravity(btVector3(0, -9.81f, 0));
    const Ground& g = ground();
    for (const Vec3& v : g.vertices) {
      vertices.push_back(btScalar(v.x.to_double()));
      vertices.push_back(btScalar(v.y.to_double()));
      vertices.push_back(btScalar(v.z.to_double()));
    }
    for (const std::uint32_t i : g.indices)
      indices.push_back(static_cast<int>(i));
    mesh = std::make_unique<btTriangleIndexVertexArray>(
        static_cast<int>(indices.size() / 3), indices.data(), 3 * static_cast<int>(sizeof(int)),
        static_cast<int>(g.vertices.size()), vertices.data(),
        3 * static_cast<int>(sizeof(btScalar)));
    ground_shape = std::make_unique<btBvhTriangleMeshShape>(mesh.get(), true);
    btRigidBody::btRigidBodyConstructionInfo ground_info(0, nullptr, ground_shape.get());
    ground_info.m_friction = 1;
    floor = std::make_unique<btRigidBody>(ground_info);
    world.addRigidBody(floor.get());
    raycaster = std::make_unique<btDefaultVehicleRaycaster>(&world);
    tuning.m_suspensionStiffness = btScalar(40000 / kChassisMass);
    tuning.m_suspensionDamping = btScalar(4000 / kChassisMass);
    tuning.m_suspensionCompression = btScalar(4000 / kChassisMass);
    tuning.m_maxSuspensionTravelCm = 30;
    tuning.m_frictionSlip = 1;
    btVector3 inertia;
    chassis_shape.calculateLocalInertia(btScalar(kChassisMass), inertia);
    for (int k = 0; k < kCars; ++k) {
      btTransform t;
      t.setIdentity();
      t.setOrigin(btVector3(btScalar(start_x(k)), 1, btScalar(start_z(k))));
      states.push_back(std::make_unique<btDefaultMotionState>(t));
      btRigidBody::btRigidBodyConstructionInfo info(btScalar(kChassisMass), states.back().get(),
                                                    &chassis_shape, inertia);
      chassis.push_back(std::make_unique<btRigidBody>(info));
      btRigidBody* body = chassis.back().get();
      body->setActivationState(DISABLE_DEACTIVATION);
      world.addRigidBody(body);
      vehicles.push_back(std::make_unique<btRaycastVehicle>(tuning, body, raycaster.get()));
      btRaycastVehicle* v = vehicles.back().get();
      v->setCoordinateSystem(0, 1, 2);
      world.addVehicle(v);
      for (const double x : {0.8, -0.8}) {
        for (const double z : {1.3, -1.3}) {
          btWheelInfo& w =
              v->addWheel(btVector3(btScalar(x), -0.2f, btScalar(z)), btVector3(0, -1, 0),
                          btVector3(-1, 0, 0), 0.3f, 0.35f, tuning, z > 0);
          w.m_rollInfluence = 1;
        }
      }
      for (int i = 0; i < 4; ++i) {
        const bool front = v->getWheelInfo(i).m_bIsFrontWheel;
        v->setSteeringValue(front ? btScalar(kSteer) : 0, i);
        v->applyEngineForce(front ? 0 : 1500, i);
      }
    }
  }
  ~BulletVehicles() {
    for (auto& v : vehicles)
      world.removeVehicle(v.get());
    for (auto& b : chassis)
      world.removeRigidBody(b.get());
    world.removeRigidBody(floor.get());
  }
};

void BM_Vehicles_Bullet(benchmark::State& state) {
  auto b = std::make_unique<BulletVehicles>();
  for (int i = 0; i < 60; ++i)
    b->world.stepSimulation(btScalar(1.0 / 60), 0, btScalar(1.0 / 60));
  double total = 0;
  int steps = 0;
  for (auto _ : state) {
    const double t0 = thread_seconds();
    b->world.stepSimulation(btScalar(1.0 / 60), 0, btScalar(1.0 / 60));
    const double t = thread_seconds() - t0;
    total += t;
    state.SetIterationTime(t);
    ++steps;
  }
  double speed = 0;
  for (auto& v : b->vehicles)
    speed += std::abs(double(v->getCurrentSpeedKmHour())) / 3.6;
  state.counters["ms_per_step"] = 1e3 * total / steps;
  state.counters["us_per_vehicle"] = 1e6 * total / steps / kCars;
  state.counters["mean_speed"] = speed / kCars;
}
#endif

}  // namespace

BENCHMARK(BM_Vehicles_detsim)->Iterations(300)->UseManualTime()->Unit(benchmark::kMillisecond);
#if DETSIM_BENCH_HAVE_BULLET
BENCHMARK(BM_Vehicles_Bullet)->Iterations(300)->UseManualTime()->Unit(benchmark::kMillisecond);
#endif

BENCHMARK_MAIN();
