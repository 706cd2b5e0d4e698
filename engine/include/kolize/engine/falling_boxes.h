#pragma once
/// \file
/// The falling-boxes world in the spirit of Bullet's own benchmark (3000 unit boxes in 47
/// layers of 8 x 8 falling onto a static ground box or plane), as a real
/// btDiscreteDynamicsWorld over any broadphase. Shared by tests and demos.

#include <kolize/engine/pair_compare.h>

#include <BulletCollision/BroadphaseCollision/btBroadphaseInterface.h>
#include <BulletDynamics/Dynamics/btDiscreteDynamicsWorld.h>

#include <memory>
#include <vector>

class btCollisionShape;
class btRigidBody;
class btCollisionDispatcher;
class btDefaultCollisionConfiguration;
class btSequentialImpulseConstraintSolver;

namespace kolize {

/// A btDiscreteDynamicsWorld that times its broadphase work (updateAabbs +
/// computeOverlappingPairs) separately from the rest of each step.
class TimedDynamicsWorld : public btDiscreteDynamicsWorld {
  public:
    using btDiscreteDynamicsWorld::btDiscreteDynamicsWorld;
    void performDiscreteCollisionDetection() override;
    /// Seconds spent in updateAabbs + computeOverlappingPairs during the last step.
    double lastBroadphaseSeconds() const { return lastBroadphaseSeconds_; }
    void resetBroadphaseSeconds() { lastBroadphaseSeconds_ = 0; }

  private:
    double lastBroadphaseSeconds_ = 0;
};

/// Settings of the falling-boxes world.
struct FallingBoxesSettings {
    int layers = 47;             ///< layers of boxes (47 x 64 = 3008 boxes by default)
    int boxesPerRow = 8;         ///< a layer is boxesPerRow x boxesPerRow
    double boxHalfExtent = 0.5;  ///< unit boxes
    double gap = 0.2;            ///< space between neighbouring boxes at the start
    bool groundIsPlane = false;  ///< static btStaticPlaneShape (AABB +-1e18) instead of a box
    double timeStep = 1.0 / 60.0;
};

/// A world and everything it owns. The broadphase is owned too, and outlives the world.
class FallingBoxesWorld {
  public:
    FallingBoxesWorld(std::unique_ptr<btBroadphaseInterface> broadphase,
                      const FallingBoxesSettings& settings = {});
    ~FallingBoxesWorld();
    FallingBoxesWorld(const FallingBoxesWorld&) = delete;
    FallingBoxesWorld& operator=(const FallingBoxesWorld&) = delete;

    /// One fixed step of settings.timeStep.
    void step();
    TimedDynamicsWorld& world() { return *world_; }
    btBroadphaseInterface& broadphase() { return *broadphase_; }
    btCollisionDispatcher& dispatcher() { return *dispatcher_; }
    const std::vector<btRigidBody*>& bodies() const { return bodies_; }
    /// The broadphase proxy of every collision object with the box the world last gave it.
    std::vector<ProxyBox> proxyBoxes() const;
    /// Removes one body from the world and deletes it.
    void removeBody(btRigidBody* body);

  private:
    FallingBoxesSettings settings_;
    std::unique_ptr<btDefaultCollisionConfiguration> configuration_;
    std::unique_ptr<btCollisionDispatcher> dispatcher_;
    std::unique_ptr<btBroadphaseInterface> broadphase_;
    std::unique_ptr<btSequentialImpulseConstraintSolver> solver_;
    std::unique_ptr<TimedDynamicsWorld> world_;
    std::vector<std::unique_ptr<btCollisionShape>> shapes_;
    std::vector<btRigidBody*> bodies_;
};

}  // namespace kolize
