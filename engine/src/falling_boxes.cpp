#include <kolize/engine/falling_boxes.h>

#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <chrono>

namespace kolize {

void TimedDynamicsWorld::performDiscreteCollisionDetection() {
    const auto start = std::chrono::steady_clock::now();
    updateAabbs();
    computeOverlappingPairs();
    lastBroadphaseSeconds_ =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    btDispatcher* dispatcher = getDispatcher();
    if (dispatcher != nullptr) {
        dispatcher->dispatchAllCollisionPairs(m_broadphasePairCache->getOverlappingPairCache(),
                                              getDispatchInfo(), dispatcher);
    }
}

FallingBoxesWorld::FallingBoxesWorld(std::unique_ptr<btBroadphaseInterface> broadphase,
                                     const FallingBoxesSettings& settings)
    : settings_(settings),
      configuration_(std::make_unique<btDefaultCollisionConfiguration>()),
      dispatcher_(std::make_unique<btCollisionDispatcher>(configuration_.get())),
      broadphase_(std::move(broadphase)),
      solver_(std::make_unique<btSequentialImpulseConstraintSolver>()),
      world_(std::make_unique<TimedDynamicsWorld>(dispatcher_.get(), broadphase_.get(),
                                                  solver_.get(), configuration_.get())) {
    world_->setGravity(btVector3(0, -10, 0));

    const btScalar half = btScalar(settings.boxHalfExtent);
    const btScalar rowWidth = btScalar(settings.boxesPerRow) * (2 * half + btScalar(settings.gap));
    btCollisionShape* ground;
    btTransform groundTransform;
    groundTransform.setIdentity();
    if (settings.groundIsPlane) {
        ground = new btStaticPlaneShape(btVector3(0, 1, 0), 0);
    } else {
        ground = new btBoxShape(btVector3(rowWidth * 4, 1, rowWidth * 4));
        groundTransform.setOrigin(btVector3(0, -1, 0));
    }
    shapes_.emplace_back(ground);
    auto* groundBody = new btRigidBody(0, new btDefaultMotionState(groundTransform), ground);
    world_->addRigidBody(groundBody);
    bodies_.push_back(groundBody);

    auto* box = new btBoxShape(btVector3(half, half, half));
    shapes_.emplace_back(box);
    const btScalar mass = 1;
    btVector3 inertia;
    box->calculateLocalInertia(mass, inertia);
    const btScalar pitch = 2 * half + btScalar(settings.gap);
    const btScalar offset = -rowWidth / 2 + pitch / 2;
    for (int layer = 0; layer < settings.layers; ++layer) {
        for (int row = 0; row < settings.boxesPerRow; ++row) {
            for (int column = 0; column < settings.boxesPerRow; ++column) {
                btTransform transform;
                transform.setIdentity();
                transform.setOrigin(btVector3(offset + column * pitch,
                                              half + pitch / 2 + layer * pitch,
                                              offset + row * pitch));
                auto* body =
                    new btRigidBody(mass, new btDefaultMotionState(transform), box, inertia);
                world_->addRigidBody(body);
                bodies_.push_back(body);
            }
        }
    }
}

FallingBoxesWorld::~FallingBoxesWorld() {
    for (btRigidBody* body : bodies_) {
        world_->removeRigidBody(body);
        delete body->getMotionState();
        delete body;
    }
}

void FallingBoxesWorld::step() {
    world_->stepSimulation(btScalar(settings_.timeStep), 0);
}

std::vector<ProxyBox> FallingBoxesWorld::proxyBoxes() const {
    // Every step's updateAabbs calls setAabb for every object (m_forceUpdateAllAabbs is
    // on by default), so the broadphase's stored box is the one the world gave it.
    std::vector<ProxyBox> out;
    const btCollisionObjectArray& objects = world_->getCollisionObjectArray();
    for (int i = 0; i < objects.size(); ++i) {
        ProxyBox box;
        box.proxy = objects[i]->getBroadphaseHandle();
        broadphase_->getAabb(objects[i]->getBroadphaseHandle(), box.aabbMin, box.aabbMax);
        out.push_back(box);
    }
    return out;
}

void FallingBoxesWorld::removeBody(btRigidBody* body) {
    world_->removeRigidBody(body);
    bodies_.erase(std::find(bodies_.begin(), bodies_.end(), body));
    delete body->getMotionState();
    delete body;
}

}  // namespace kolize
