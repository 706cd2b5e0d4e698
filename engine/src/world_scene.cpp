#include <kolize/engine/world_scene.h>

#include <kolize/narrowphase/mesh_stages.h>

#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

namespace kolize {

namespace {

constexpr double kGravity = 10;

double secondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

bool finite(const btVector3& v) {
    return std::isfinite(double(v.x())) && std::isfinite(double(v.y())) &&
           std::isfinite(double(v.z()));
}

}  // namespace

void TimedDynamicsWorld::performDiscreteCollisionDetection() {
    const auto start = std::chrono::steady_clock::now();
    updateAabbs();
    computeOverlappingPairs();
    lastBroadphaseSeconds_ += secondsSince(start);
    btDispatcher* dispatcher = getDispatcher();
    if (dispatcher != nullptr) {
        const auto narrow = std::chrono::steady_clock::now();
        dispatcher->dispatchAllCollisionPairs(m_broadphasePairCache->getOverlappingPairCache(),
                                              getDispatchInfo(), dispatcher);
        lastNarrowphaseSeconds_ += secondsSince(narrow);
    }
    if (afterNarrowphase_) {
        afterNarrowphase_();
    }
}

void TimedDynamicsWorld::integrateTransforms(btScalar timeStep) {
    const auto start = std::chrono::steady_clock::now();
    if (meshCcd_) {
        MeshCcdWorld::integrateTransforms(timeStep);
    } else {
        btDiscreteDynamicsWorld::integrateTransforms(timeStep);
    }
    lastIntegrateSeconds_ += secondsSince(start);
}

WorldScene::WorldScene(SceneInfo info, std::unique_ptr<btBroadphaseInterface> broadphase,
                       const SceneOptions& options, const btVector3& origin)
    : Scene(std::move(info)), options_(options), origin_(origin) {
    if (!broadphase) {
        throw std::invalid_argument("scene '" + info_.name + "': no broadphase given");
    }
    if (!(options.timeStep > 0) || !std::isfinite(options.timeStep)) {
        throw std::invalid_argument("scene '" + info_.name +
                                    "': the time step must be a positive number of seconds");
    }
    if (options.substeps < 1) {
        throw std::invalid_argument("scene '" + info_.name + "': substeps must be at least 1");
    }
    bulletCcd_ = options.bulletCcd < 0 ? info_.needs.continuous : options.bulletCcd > 0;
    configuration_ = std::make_unique<btDefaultCollisionConfiguration>();
    dispatcher_ = std::make_unique<btCollisionDispatcher>(configuration_.get());
    broadphase_ = std::move(broadphase);
    solver_ = std::make_unique<btSequentialImpulseConstraintSolver>();
    world_ = std::make_unique<TimedDynamicsWorld>(dispatcher_.get(), broadphase_.get(),
                                                  solver_.get(), configuration_.get());
    world_->setGravity(btVector3(0, btScalar(-kGravity), 0));
}

WorldScene::~WorldScene() {
    world_->setAfterNarrowphase(nullptr);
    releaseNarrowphaseStages(dispatcher_.get());  // the stage planner's entry, if any
    for (const std::unique_ptr<btTypedConstraint>& constraint : constraints_) {
        world_->removeConstraint(constraint.get());
    }
    constraints_.clear();
    for (btRigidBody* body : bodies_) {
        world_->removeRigidBody(body);
        delete body->getMotionState();
        delete body;
    }
}

btCollisionShape* WorldScene::own(btCollisionShape* shape) {
    shapes_.emplace_back(shape);
    return shape;
}

btStridingMeshInterface* WorldScene::ownMesh(btStridingMeshInterface* mesh) {
    meshes_.emplace_back(mesh);
    return mesh;
}

btRigidBody* WorldScene::addBody(btCollisionShape* shape, double mass, const btTransform& transform,
                                 const btVector3& linearVelocity) {
    btTransform shifted = transform;
    shifted.setOrigin(transform.getOrigin() + origin_);
    btVector3 inertia(0, 0, 0);
    if (mass > 0) {
        shape->calculateLocalInertia(btScalar(mass), inertia);
    }
    auto* body = new btRigidBody(btScalar(mass), new btDefaultMotionState(shifted), shape, inertia);
    if (mass > 0) {
        body->setLinearVelocity(linearVelocity);
        if (bulletCcd_) {
            btVector3 centre;
            btScalar radius;
            shape->getBoundingSphere(centre, radius);
            body->setCcdMotionThreshold(radius * btScalar(0.5));
            body->setCcdSweptSphereRadius(radius * btScalar(0.4));
        }
        ++dynamicBodies_;
    }
    world_->addRigidBody(body);
    bodies_.push_back(body);
    return body;
}

void WorldScene::removeBody(btRigidBody* body) {
    const auto at = std::find(bodies_.begin(), bodies_.end(), body);
    if (at == bodies_.end()) {
        throw std::invalid_argument("WorldScene::removeBody: not a body of this scene");
    }
    if (!body->isStaticObject()) {
        --dynamicBodies_;
    }
    world_->removeRigidBody(body);
    exactMeshes_.erase(body);
    bodies_.erase(at);
    delete body->getMotionState();
    delete body;
}

btTypedConstraint* WorldScene::addConstraint(btTypedConstraint* constraint,
                                             bool disableCollisions) {
    constraints_.emplace_back(constraint);
    world_->addConstraint(constraint, disableCollisions);
    return constraint;
}

void WorldScene::setContainer(const btVector3& min, const btVector3& max) {
    hasContainer_ = true;
    containerMin_ = min;
    containerMax_ = max;
}

void WorldScene::setExactMesh(const btCollisionObject* body,
                              std::shared_ptr<const narrowphase::MeshModel> model) {
    if (body == nullptr || !model) {
        throw std::invalid_argument("scene '" + info_.name +
                                    "': setExactMesh needs a body and a model");
    }
    exactMeshes_[body] = std::move(model);
}

void WorldScene::setContactAudit(bool on, const AuditSettings& settings) {
    if (!on) {
        world_->setAfterNarrowphase(nullptr);
        return;
    }
    world_->setAfterNarrowphase(
        [this, settings] { audit_ += auditContacts(*world_, exactMeshes_, settings); });
}

void WorldScene::setRays(std::function<std::vector<WorldRay>(int frame)> rays) {
    rays_ = std::move(rays);
}

void WorldScene::step() {
    lastRaySeconds_ = 0;
    rayHits_ = 0;
    if (rays_) {
        const std::vector<WorldRay> rays = rays_(frame_);
        const auto start = std::chrono::steady_clock::now();
        for (const WorldRay& ray : rays) {
            const btVector3 from = ray.first + origin_, to = ray.second + origin_;
            btCollisionWorld::ClosestRayResultCallback callback(from, to);
            world_->rayTest(from, to, callback);
            rayHits_ += callback.hasHit() ? 1 : 0;
        }
        lastRaySeconds_ = secondsSince(start);
    }
    // Substeps as separate variable-size steps of exactly timeStep / substeps: no
    // accumulator, so every run (and every broadphase) takes the same steps.
    const btScalar h = btScalar(options_.timeStep / options_.substeps);
    lastBroadphaseSeconds_ = lastNarrowphaseSeconds_ = lastIntegrateSeconds_ = 0;
    audit_ = ContactAudit();
    for (int i = 0; i < options_.substeps; ++i) {
        world_->resetBroadphaseSeconds();
        world_->stepSimulation(h, 0);
        lastBroadphaseSeconds_ += world_->lastBroadphaseSeconds();
        lastNarrowphaseSeconds_ += world_->lastNarrowphaseSeconds();
        lastIntegrateSeconds_ += world_->lastIntegrateSeconds();
    }
    ++frame_;
}

std::vector<ProxyBox> WorldScene::proxyBoxes() const {
    // Every step's updateAabbs calls setAabb for every object (m_forceUpdateAllAabbs is on
    // by default), so the broadphase's stored box is the one the world gave it.
    std::vector<ProxyBox> out;
    const btCollisionObjectArray& objects = world_->getCollisionObjectArray();
    out.reserve(std::size_t(objects.size()));
    for (int i = 0; i < objects.size(); ++i) {
        ProxyBox box;
        box.proxy = objects[i]->getBroadphaseHandle();
        broadphase_->getAabb(objects[i]->getBroadphaseHandle(), box.aabbMin, box.aabbMax);
        out.push_back(box);
    }
    return out;
}

const btOverlappingPairCache* WorldScene::filter() const {
    return broadphase_->getOverlappingPairCache();
}

SceneState WorldScene::state() const {
    SceneState state;
    state.rayHits = rayHits_;
    for (int i = 0; i < dispatcher_->getNumManifolds(); ++i) {
        const btPersistentManifold* manifold = dispatcher_->getManifoldByIndexInternal(i);
        for (int j = 0; j < manifold->getNumContacts(); ++j) {
            state.maxPenetration =
                std::max(state.maxPenetration, -double(manifold->getContactPoint(j).getDistance()));
        }
    }
    for (const btRigidBody* body : bodies_) {
        if (body->isStaticObject()) {
            continue;
        }
        const btVector3 position = body->getCenterOfMassPosition() - origin_;
        const btVector3& velocity = body->getLinearVelocity();
        const btVector3& spin = body->getAngularVelocity();
        if (!finite(position) || !finite(velocity) || !finite(spin)) {
            ++state.nonFinite;
            continue;
        }
        const double mass = body->getInvMass() > 0 ? 1.0 / double(body->getInvMass()) : 0;
        // Rotational energy in the body frame: 1/2 sum I_i w_i^2 (no inverse of a tensor).
        const btVector3 localSpin = body->getWorldTransform().getBasis().transpose() * spin;
        const btVector3 inertia = body->getLocalInertia();
        state.kineticEnergy += 0.5 * mass * double(velocity.length2()) +
                               0.5 * double((inertia * localSpin).dot(localSpin));
        state.potentialEnergy += mass * kGravity * double(position.y());
        if (hasContainer_) {
            for (int axis = 0; axis < 3; ++axis) {
                if (position[axis] < containerMin_[axis] || position[axis] > containerMax_[axis]) {
                    ++state.escaped;
                    break;
                }
            }
        }
    }
    return state;
}

std::vector<btVector3> WorldScene::positions() const {
    std::vector<btVector3> out;
    for (const btRigidBody* body : bodies_) {
        if (!body->isStaticObject()) {
            out.push_back(body->getCenterOfMassPosition() - origin_);
        }
    }
    return out;
}

std::uint64_t WorldScene::stateHash() const {
    std::uint64_t hash = 1469598103934665603ull;
    auto mix = [&](const btVector3& v) {
        const auto* bytes = reinterpret_cast<const unsigned char*>(v.m_floats);
        for (std::size_t i = 0; i < 3 * sizeof(btScalar); ++i) {
            hash = (hash ^ bytes[i]) * 1099511628211ull;
        }
    };
    for (const btRigidBody* body : bodies_) {
        if (body->isStaticObject()) {
            continue;
        }
        const btTransform& transform = body->getWorldTransform();
        for (int row = 0; row < 3; ++row) {
            mix(transform.getBasis()[row]);
        }
        mix(transform.getOrigin());
        mix(body->getLinearVelocity());
        mix(body->getAngularVelocity());
    }
    return hash;
}

}  // namespace kolize
