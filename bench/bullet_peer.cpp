// Bullet 3 on the shared pile scenes: btDiscreteDynamicsWorld with its default collision
// configuration, the dynamic AABB tree broadphase and the sequential impulse solver, as the
// project's Bullet anchor sets it up. Benchmark code, not simulation code: float is Bullet's type.

#include "bullet_peer.hpp"

#include <btBulletDynamicsCommon.h>

#include <cmath>
#include <vector>

namespace detsim_bench {

namespace {

constexpr btScalar kTimeStep = btScalar(1) / btScalar(60);

}  // namespace

struct BulletPile::Impl {
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld world{&dispatcher, &broadphase, &solver, &configuration};

  btStaticPlaneShape ground_shape{btVector3(0, 1, 0), 0};
  btBoxShape box_shape{btVector3(btScalar(0.5), btScalar(0.5), btScalar(0.5))};
  btSphereShape sphere_shape{btScalar(0.5)};

  std::unique_ptr<btRigidBody> ground;
  std::vector<std::unique_ptr<btDefaultMotionState>> motion_states;
  std::vector<std::unique_ptr<btRigidBody>> bodies;

  Impl(std::uint32_t count, bool spheres, double friction) {
    world.setGravity(btVector3(0, btScalar(-9.81), 0));
    world.getSolverInfo().m_numIterations = 10;

    btRigidBody::btRigidBodyConstructionInfo ground_info(0, nullptr, &ground_shape);
    ground_info.m_friction = static_cast<btScalar>(friction);
    ground = std::make_unique<btRigidBody>(ground_info);
    world.addRigidBody(ground.get());

    btCollisionShape* shape = spheres ? static_cast<btCollisionShape*>(&sphere_shape)
                                      : static_cast<btCollisionShape*>(&box_shape);
    btVector3 inertia(0, 0, 0);
    shape->calculateLocalInertia(1, inertia);

    // The smallest side with side^3 >= count, in integers (as the detsim scene computes it).
    std::uint32_t side = 1;
    while (std::uint64_t{side} * side * side < count)
      ++side;
    const auto centred = [side](std::uint32_t k) {
      return static_cast<btScalar>(static_cast<int>(k) - static_cast<int>(side / 2)) *
             btScalar(1.1);
    };
    motion_states.reserve(count);
    bodies.reserve(count);
    for (std::uint32_t i = 0; i < count; ++i) {
      const std::uint32_t x = i % side;
      const std::uint32_t z = (i / side) % side;
      const std::uint32_t y = i / (side * side);
      btTransform transform;
      transform.setIdentity();
      transform.setOrigin(
          btVector3(centred(x), 1 + static_cast<btScalar>(y) * btScalar(1.1), centred(z)));
      motion_states.push_back(std::make_unique<btDefaultMotionState>(transform));
      btRigidBody::btRigidBodyConstructionInfo info(1, motion_states.back().get(), shape, inertia);
      info.m_friction = static_cast<btScalar>(friction);
      info.m_restitution = 0;
      bodies.push_back(std::make_unique<btRigidBody>(info));
      world.addRigidBody(bodies.back().get());
    }
  }

  ~Impl() {
    // The world must not outlive its bodies' registration: remove them first.
    for (auto it = bodies.rbegin(); it != bodies.rend(); ++it)
      world.removeRigidBody(it->get());
    world.removeRigidBody(ground.get());
  }

  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;
};

BulletPile::BulletPile(std::uint32_t count, bool spheres, double friction)
    : impl_(std::make_unique<Impl>(count, spheres, friction)) {}

BulletPile::~BulletPile() = default;

void BulletPile::step() {
  // maxSubSteps = 0: exactly one step of kTimeStep, no interpolation.
  impl_->world.stepSimulation(kTimeStep, 0, kTimeStep);
}

double BulletPile::mean_height() const {
  if (impl_->bodies.empty()) return 0.0;
  double sum = 0.0;
  for (const auto& body : impl_->bodies)
    sum += static_cast<double>(body->getWorldTransform().getOrigin().y());
  return sum / static_cast<double>(impl_->bodies.size());
}

std::uint32_t BulletPile::awake_count() const {
  std::uint32_t n = 0;
  for (const auto& body : impl_->bodies) {
    if (body->isActive()) ++n;
  }
  return n;
}

int BulletPile::version() {
  return btGetVersion();
}

}  // namespace detsim_bench
