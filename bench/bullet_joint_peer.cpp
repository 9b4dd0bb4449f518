// Bullet 3 on the joint scenes: the JointScene that joint_bench read out of a detsim World, built
// with Bullet's own constraint types. Benchmark code, not simulation code: float is Bullet's type.

#include "bullet_joint_peer.hpp"

#include <btBulletDynamicsCommon.h>

#include <cmath>
#include <vector>

namespace detsim_bench {

namespace {

btVector3 vec(const std::array<double, 3>& v) {
  return {static_cast<btScalar>(v[0]), static_cast<btScalar>(v[1]), static_cast<btScalar>(v[2])};
}

btQuaternion quat(const std::array<double, 4>& q) {  // w, x, y, z
  return {static_cast<btScalar>(q[1]), static_cast<btScalar>(q[2]), static_cast<btScalar>(q[3]),
          static_cast<btScalar>(q[0])};
}

// detsim's damping, v *= 1 / (1 + dt c) per step, as Bullet's v *= (1 - d)^dt.
btScalar bullet_damping(double c, double dt) {
  if (c <= 0.0) return 0;
  return static_cast<btScalar>(1.0 - std::pow(1.0 + dt * c, -1.0 / dt));
}

// A world-space frame at `origin` whose x axis is `x` (unit).
btTransform frame_with_x(const btVector3& origin, const btVector3& x) {
  btVector3 y;
  btVector3 z;
  btPlaneSpace1(x, y, z);
  btMatrix3x3 basis(x.x(), y.x(), z.x(), x.y(), y.y(), z.y(), x.z(), y.z(), z.z());
  return btTransform(basis, origin);
}

}  // namespace

struct BulletJointScene::Impl {
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld world{&dispatcher, &broadphase, &solver, &configuration};

  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::vector<std::unique_ptr<btDefaultMotionState>> motion_states;
  std::vector<std::unique_ptr<btRigidBody>> bodies;
  std::vector<std::unique_ptr<btTypedConstraint>> constraints;
  struct Anchors {
    btRigidBody* a;
    btRigidBody* b;
    btVector3 local_a;
    btVector3 local_b;
  };
  std::vector<Anchors> anchors;
  btScalar substep_dt = 0;
  int substeps = 1;

  Impl(const JointScene& scene, int substep_count, int iterations) : substeps(substep_count) {
    substep_dt = static_cast<btScalar>(scene.dt / substeps);
    world.setGravity(btVector3(0, static_cast<btScalar>(scene.gravity_y), 0));
    world.getSolverInfo().m_numIterations = iterations;
    for (const SceneBody& b : scene.bodies)
      add_body(b, scene.dt);
    for (const SceneJoint& j : scene.joints)
      add_joint(j);
  }

  void add_body(const SceneBody& b, double dt) {
    btTransform transform(quat(b.orientation), vec(b.position));
    switch (b.kind) {
      case SceneBody::Kind::sphere:
        shapes.push_back(std::make_unique<btSphereShape>(static_cast<btScalar>(b.radius)));
        break;
      case SceneBody::Kind::box:
        shapes.push_back(std::make_unique<btBoxShape>(vec(b.half_extents)));
        break;
      case SceneBody::Kind::capsule:
        shapes.push_back(std::make_unique<btCapsuleShape>(
            static_cast<btScalar>(b.radius), static_cast<btScalar>(2 * b.half_height)));
        break;
      case SceneBody::Kind::plane: {
        // The plane through the body's position with normal local +y: a static plane shape in
        // world space, on a body at the origin.
        const btVector3 normal = quatRotate(quat(b.orientation), btVector3(0, 1, 0));
        shapes.push_back(std::make_unique<btStaticPlaneShape>(normal, normal.dot(vec(b.position))));
        transform.setIdentity();
        break;
      }
    }
    btCollisionShape* shape = shapes.back().get();
    const btScalar mass = b.dynamic ? static_cast<btScalar>(b.mass) : btScalar(0);
    btVector3 inertia(0, 0, 0);
    if (b.dynamic) shape->calculateLocalInertia(mass, inertia);
    motion_states.push_back(std::make_unique<btDefaultMotionState>(transform));
    btRigidBody::btRigidBodyConstructionInfo info(mass, motion_states.back().get(), shape, inertia);
    info.m_friction = static_cast<btScalar>(std::sqrt(b.friction));
    info.m_restitution = 0;
    info.m_linearDamping = bullet_damping(b.linear_damping, dt);
    info.m_angularDamping = bullet_damping(b.angular_damping, dt);
    bodies.push_back(std::make_unique<btRigidBody>(info));
    btRigidBody* body = bodies.back().get();
    if (b.dynamic) {
      body->setLinearVelocity(vec(b.linear_velocity));
      body->setAngularVelocity(vec(b.angular_velocity));
    }
    world.addRigidBody(body);
  }

  void add_joint(const SceneJoint& j) {
    btRigidBody& a = *bodies[j.body_a];
    btRigidBody& b = *bodies[j.body_b];
    const btTransform ta = a.getWorldTransform();
    const btTransform tb = b.getWorldTransform();
    const btVector3 anchor = vec(j.anchor);
    const btVector3 axis = vec(j.axis);
    const btVector3 pivot_a = ta.inverse() * anchor;
    const btVector3 pivot_b = tb.inverse() * anchor;
    std::unique_ptr<btTypedConstraint> c;
    switch (j.kind) {
      case SceneJoint::Kind::ball:
        c = std::make_unique<btPoint2PointConstraint>(a, b, pivot_a, pivot_b);
        break;
      case SceneJoint::Kind::hinge: {
        const btVector3 axis_a = ta.getBasis().transpose() * axis;
        const btVector3 axis_b = tb.getBasis().transpose() * axis;
        auto hinge = std::make_unique<btHingeConstraint>(a, b, pivot_a, pivot_b, axis_a, axis_b);
        if (j.limit_enabled)
          hinge->setLimit(static_cast<btScalar>(j.limit_lower),
                          static_cast<btScalar>(j.limit_upper));
        if (j.motor_enabled)
          hinge->enableAngularMotor(true, static_cast<btScalar>(j.motor_speed),
                                    static_cast<btScalar>(j.motor_max_force) * substep_dt);
        c = std::move(hinge);
        break;
      }
      case SceneJoint::Kind::swing_twist: {
        const btTransform frame = frame_with_x(anchor, axis);
        auto cone = std::make_unique<btConeTwistConstraint>(a, b, ta.inverse() * frame,
                                                            tb.inverse() * frame);
        if (j.limit_enabled) {
          const double twist = std::max(std::abs(j.limit_lower), std::abs(j.limit_upper));
          cone->setLimit(static_cast<btScalar>(j.swing_limit), static_cast<btScalar>(j.swing_limit),
                         static_cast<btScalar>(twist));
        }
        c = std::move(cone);
        break;
      }
      case SceneJoint::Kind::fixed: {
        btTransform frame;
        frame.setIdentity();
        frame.setOrigin(anchor);
        c = std::make_unique<btFixedConstraint>(a, b, ta.inverse() * frame, tb.inverse() * frame);
        break;
      }
    }
    world.addConstraint(c.get(), true);  // no collisions between joined bodies
    constraints.push_back(std::move(c));
    anchors.push_back({&a, &b, pivot_a, pivot_b});
  }

  ~Impl() {
    for (auto it = constraints.rbegin(); it != constraints.rend(); ++it)
      world.removeConstraint(it->get());
    for (auto it = bodies.rbegin(); it != bodies.rend(); ++it)
      world.removeRigidBody(it->get());
  }

  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;
};

BulletJointScene::BulletJointScene(const JointScene& scene, int substeps, int iterations)
    : impl_(std::make_unique<Impl>(scene, substeps, iterations)) {}

BulletJointScene::~BulletJointScene() = default;

void BulletJointScene::step() {
  // maxSubSteps = 0: exactly one step of the given length each call, no interpolation.
  for (int i = 0; i < impl_->substeps; ++i)
    impl_->world.stepSimulation(impl_->substep_dt, 0, impl_->substep_dt);
}

Stretch BulletJointScene::stretch() const {
  Stretch s;
  for (const Impl::Anchors& a : impl_->anchors) {
    const btVector3 pa = a.a->getWorldTransform() * a.local_a;
    const btVector3 pb = a.b->getWorldTransform() * a.local_b;
    const double gap = static_cast<double>((pb - pa).length());
    s.worst = std::max(s.worst, gap);
    s.mean += gap;
  }
  if (!impl_->anchors.empty()) s.mean /= static_cast<double>(impl_->anchors.size());
  return s;
}

std::uint32_t BulletJointScene::awake_count() const {
  std::uint32_t n = 0;
  for (const auto& body : impl_->bodies) {
    if (body->getInvMass() != 0 && body->isActive()) ++n;
  }
  return n;
}

}  // namespace detsim_bench
