#pragma once
/// \file
/// A real btDiscreteDynamicsWorld as a Scene: owns the configuration, dispatcher, broadphase,
/// solver, world, shapes and bodies; steps with fixed substeps; casts the scene's rays; and
/// measures the dynamics' health (penetration, escaped bodies, NaN, energy). Scene builders
/// (scene registry, FallingBoxesWorld) fill it with bodies.

#include <kolize/engine/contact_audit.h>
#include <kolize/engine/deterministic_islands.h>
#include <kolize/engine/scene.h>
#include <kolize/narrowphase/bullet_mesh_world.h>

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
/// computeOverlappingPairs) and its narrowphase (dispatchAllCollisionPairs) separately from
/// the rest of each step; its islands do not depend on the pair cache's order when
/// m_deterministicOverlappingPairs is on (deterministic_islands.h). It is a MeshCcdWorld
/// whose mesh CCD is off until setMeshCcd(true): off, integrateTransforms is exactly
/// btDiscreteDynamicsWorld's.
class TimedDynamicsWorld : public WithDeterministicIslands<MeshCcdWorld> {
  public:
    using WithDeterministicIslands<MeshCcdWorld>::WithDeterministicIslands;
    void performDiscreteCollisionDetection() override;
    /// Seconds spent in updateAabbs + computeOverlappingPairs during the last internal step.
    double lastBroadphaseSeconds() const { return lastBroadphaseSeconds_; }
    /// Seconds spent in dispatchAllCollisionPairs (contacts) during the last internal step.
    double lastNarrowphaseSeconds() const { return lastNarrowphaseSeconds_; }
    /// Seconds spent in integrateTransforms during the last internal step (with mesh CCD on:
    /// its times of impact included).
    double lastIntegrateSeconds() const { return lastIntegrateSeconds_; }
    void resetBroadphaseSeconds() {
        lastBroadphaseSeconds_ = lastNarrowphaseSeconds_ = lastIntegrateSeconds_ = 0;
    }
    /// Turns kolize's mesh CCD (MeshCcdWorld::integrateTransforms) on or off. Default off.
    void setMeshCcd(bool on) { meshCcd_ = on; }
    bool meshCcd() const { return meshCcd_; }
    /// Called after each internal step's narrowphase, while the bodies are where the
    /// contacts were made (null: nothing).
    void setAfterNarrowphase(std::function<void()> hook) { afterNarrowphase_ = std::move(hook); }

  protected:
    void integrateTransforms(btScalar timeStep) override;

  private:
    bool meshCcd_ = false;
    std::function<void()> afterNarrowphase_;
    double lastBroadphaseSeconds_ = 0;
    double lastNarrowphaseSeconds_ = 0;
    double lastIntegrateSeconds_ = 0;
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
    /// Seconds of the last frame in the narrowphase (dispatchAllCollisionPairs) and in
    /// integrateTransforms (mesh CCD included), summed over the substeps.
    double lastNarrowphaseSeconds() const { return lastNarrowphaseSeconds_; }
    double lastIntegrateSeconds() const { return lastIntegrateSeconds_; }

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
    /// Keeps `object` alive as long as the scene (mesh data a shape refers to).
    void keep(std::shared_ptr<const void> object) { kept_.push_back(std::move(object)); }
    /// The exact triangle mesh of `body` (in its body frame) for contact audits: the model
    /// the exact check queries, whatever shape the body collides with.
    void setExactMesh(const btCollisionObject* body,
                      std::shared_ptr<const narrowphase::MeshModel> model);
    /// With audits on, every internal step checks each overlapping pair of two bodies with
    /// exact meshes right after its narrowphase (contact_audit.h); lastAudit() sums the last
    /// frame's steps; `settings` says what else it measures (the meshes' penetration).
    void setContactAudit(bool on, const AuditSettings& settings = {});
    const ContactAudit& lastAudit() const { return audit_; }

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
    double lastNarrowphaseSeconds_ = 0;
    double lastIntegrateSeconds_ = 0;
    std::vector<std::shared_ptr<const void>> kept_;
    ExactMeshes exactMeshes_;
    ContactAudit audit_;
};

}  // namespace kolize
