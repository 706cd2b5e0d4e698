#pragma once
/// \file
/// A real btDiscreteDynamicsWorld as a Scene: owns the configuration, dispatcher, broadphase,
/// solver, world, shapes and bodies; steps with fixed substeps; casts the scene's rays; and
/// measures the dynamics' health (penetration, escaped bodies, NaN, energy). Scene builders
/// (scene registry, FallingBoxesWorld) fill it with bodies.

#include <kolize/engine/deterministic_islands.h>
#include <kolize/engine/scene.h>

#include <BulletDynamics/Dynamics/btDiscreteDynamicsWorld.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <utility>
#include <vector>

class btCollisionShape;
class btStridingMeshInterface;
class btRigidBody;
class btCollisionDispatcher;
class btDefaultCollisionConfiguration;
class btSequentialImpulseConstraintSolver;
class btTypedConstraint;

namespace kolize {

/// A btDiscreteDynamicsWorld that times its broadphase work (updateAabbs +
/// computeOverlappingPairs) separately from the rest of each step; its islands do not
/// depend on the pair cache's order when m_deterministicOverlappingPairs is on
/// (deterministic_islands.h).
class TimedDynamicsWorld : public WithDeterministicIslands<btDiscreteDynamicsWorld> {
  public:
    using WithDeterministicIslands<btDiscreteDynamicsWorld>::WithDeterministicIslands;
    void performDiscreteCollisionDetection() override;
    /// Seconds spent in updateAabbs + computeOverlappingPairs during the last internal step.
    double lastBroadphaseSeconds() const { return lastBroadphaseSeconds_; }
    void resetBroadphaseSeconds() { lastBroadphaseSeconds_ = 0; }

  private:
    double lastBroadphaseSeconds_ = 0;
};

/// A ray cast per frame: from, to.
using WorldRay = std::pair<btVector3, btVector3>;

class WorldScene : public Scene {
  public:
    /// Gravity is -10 m/s^2 along y. `origin` shifts everything the builder adds (the
    /// offset scenes); energies, positions and the container are measured relative to it.
    WorldScene(SceneInfo info, std::unique_ptr<btBroadphaseInterface> broadphase,
               const SceneOptions& options, const btVector3& origin = btVector3(0, 0, 0));
    ~WorldScene() override;
    WorldScene(const WorldScene&) = delete;
    WorldScene& operator=(const WorldScene&) = delete;

    /// One frame: the rays (when the scene has any), then options.substeps fixed steps of
    /// timeStep / substeps each.
    void step() override;
    btBroadphaseInterface& broadphase() override { return *broadphase_; }
    TimedDynamicsWorld* world() override { return world_.get(); }
    std::vector<ProxyBox> proxyBoxes() const override;
    const btOverlappingPairCache* filter() const override;
    double lastBroadphaseSeconds() const override { return lastBroadphaseSeconds_; }
    double lastRaySeconds() const override { return lastRaySeconds_; }
    SceneState state() const override;
    std::vector<btVector3> positions() const override;
    int movingObjects() const override { return dynamicBodies_; }

    /// A 64-bit FNV-1a hash of the bytes of every dynamic body's transform and velocities:
    /// equal hashes of two runs mean (up to hash collisions) bit-identical states.
    std::uint64_t stateHash() const;

    btCollisionDispatcher& dispatcher() { return *dispatcher_; }
    const std::vector<btRigidBody*>& bodies() const { return bodies_; }
    const SceneOptions& options() const { return options_; }
    const btVector3& origin() const { return origin_; }

    // --- for builders ---
    /// Takes ownership of a shape; returns it.
    btCollisionShape* own(btCollisionShape* shape);
    /// Takes ownership of a triangle mesh (kept until after every shape is deleted, for the
    /// btBvhTriangleMeshShape that refers to it); returns it.
    btStridingMeshInterface* ownMesh(btStridingMeshInterface* mesh);
    /// Adds a rigid body (mass 0: static) at `transform` shifted by origin(). Dynamic bodies
    /// get Bullet's CCD when it is on (SceneOptions::bulletCcd, or the scene's
    /// SceneNeeds::continuous by default): motion threshold and swept-sphere radius from the
    /// shape's bounding sphere.
    btRigidBody* addBody(btCollisionShape* shape, double mass, const btTransform& transform,
                         const btVector3& linearVelocity = btVector3(0, 0, 0));
    /// Removes one body from the world and deletes it.
    void removeBody(btRigidBody* body);
    /// Adds a joint (owned; deleted before the bodies). `disableCollisions`: the two bodies
    /// it links get no contact pair (btDiscreteDynamicsWorld::addConstraint's flag).
    btTypedConstraint* addConstraint(btTypedConstraint* constraint, bool disableCollisions);
    /// Dynamic bodies whose centre leaves this box (relative to origin()) count as escaped
    /// (tunnelled through the ground or out of a bowl). Without a container none escape.
    void setContainer(const btVector3& min, const btVector3& max);
    /// Rays cast every frame with closest-hit callbacks through the world's rayTest; the
    /// function returns the frame's rays (relative to origin()).
    void setRays(std::function<std::vector<WorldRay>(int frame)> rays);
    bool bulletCcd() const { return bulletCcd_; }

  private:
    SceneOptions options_;
    btVector3 origin_;
    bool bulletCcd_ = false;
    std::unique_ptr<btDefaultCollisionConfiguration> configuration_;
    std::unique_ptr<btCollisionDispatcher> dispatcher_;
    std::unique_ptr<btBroadphaseInterface> broadphase_;
    std::unique_ptr<btSequentialImpulseConstraintSolver> solver_;
    std::unique_ptr<TimedDynamicsWorld> world_;
    std::vector<std::unique_ptr<btStridingMeshInterface>> meshes_;  // before shapes_: outlives them
    std::vector<std::unique_ptr<btCollisionShape>> shapes_;
    std::vector<btRigidBody*> bodies_;
    std::vector<std::unique_ptr<btTypedConstraint>> constraints_;
    int dynamicBodies_ = 0;
    bool hasContainer_ = false;
    btVector3 containerMin_, containerMax_;
    std::function<std::vector<WorldRay>(int)> rays_;
    int frame_ = 0;
    int rayHits_ = 0;
    double lastBroadphaseSeconds_ = 0;
    double lastRaySeconds_ = 0;
};

}  // namespace kolize
