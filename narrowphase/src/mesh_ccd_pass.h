#pragma once
// The continuous-collision pass of kolize's CCD worlds (MeshCcdWorld, MeshCcdWorldMt): what
// runs before and after the world's own integrateTransforms (bullet_mesh_world.h has the
// rules).
#include "kolize/narrowphase/bullet_mesh_world.h"

#include <BulletDynamics/Dynamics/btDiscreteDynamicsWorld.h>
#include <BulletDynamics/Dynamics/btRigidBody.h>

#include <map>
#include <utility>
#include <vector>

namespace kolize::detail {

/// A shape that is not a compound inside a body's shape, with its transform in the body's
/// frame (the body's shape itself when it is not a compound).
struct Leaf {
    const btCollisionShape* shape;
    btTransform local;
};

class MeshCcdPass {
  public:
    /// Throws std::invalid_argument for bad `settings`.
    explicit MeshCcdPass(const MeshCcdWorldSettings& settings);
    const MeshCcdWorldSettings& settings() const { return settings_; }
    void setSettings(const MeshCcdWorldSettings& settings);
    const MeshCcdCounters& counters() const { return counters_; }

    /// Steps 1-3 of the world's comment, then the bodies put in integration order (convex
    /// first); the world's integrateTransforms runs next.
    void before(btDiscreteDynamicsWorld& world, btScalar timeStep);
    /// The world order back, and step 5 (the limited bodies put where they may go).
    void after(btDiscreteDynamicsWorld& world);

  private:
    /// A leaf of a compound as a body of its own, for the algorithms' time of impact (a
    /// btRigidBody: what they read of the real one, a rigid body or not, is copied).
    struct ProxyObject : btRigidBody {
        ProxyObject() : btRigidBody(btRigidBodyConstructionInfo(1, nullptr, nullptr)) {}
        /// Becomes `leaf` of `object` (its flags, activation and CCD threshold), moving from
        /// the object's world transform to `end`.
        void take(const btCollisionObject& object, const Leaf& leaf, const btTransform& end);
    };
    /// One pair's time of impact; lowers the fractions its bodies may move (allowed_).
    void timeOfImpact(btCollisionObject* a, btCollisionObject* b);
    /// The same for a pair with a compound: every pair of their leaves with a MeshShape
    /// whose boxes over the step meet, through an algorithm made for it (contacts at the
    /// start first, then the time of impact).
    void compoundTimeOfImpact(btCollisionObject* a, btCollisionObject* b);
    /// Both bodies may go `penetration` past `toi` (allowed_).
    void limit(btCollisionObject* a, btCollisionObject* b, btScalar toi);

    MeshCcdWorldSettings settings_;
    MeshCcdCounters counters_;
    btDiscreteDynamicsWorld* world_ = nullptr;  ///< the world of the running step
    std::vector<btCollisionObject*> found_;
    std::vector<std::pair<int, int>> pairs_;
    struct Clamp {
        btRigidBody* body;
        btTransform transform;
        btScalar hitFraction;
        double fraction;       ///< of the step
        btVector3 start, end;  ///< the origin at the start and the end of the whole step
    };
    std::vector<Clamp> clamped_;
    std::map<const btCollisionObject*, double> allowed_;
    btAlignedObjectArray<btRigidBody*> integrationOrder_;  ///< convex bodies first
    btAlignedObjectArray<btRigidBody*> worldOrder_;
    std::vector<Leaf> leavesA_, leavesB_;
    ProxyObject proxyA_, proxyB_;
};

}  // namespace kolize::detail
