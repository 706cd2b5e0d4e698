#pragma once
/// \file
/// Continuous collision for kolize mesh bodies in a Bullet world: a btDiscreteDynamicsWorld
/// whose integrator stops a fast MeshShape body at its first time of impact, found by the
/// mesh algorithms' calculateTimeOfImpact (kolize::ccd::meshCcd, exact vertex-face and
/// edge-edge tests), where Bullet would sweep a sphere.
///
/// Why a world: Bullet 3.24's btDiscreteDynamicsWorld never calls calculateTimeOfImpact
/// (its dispatcher does so only under DISPATCH_CONTINUOUS, which no world of 3.24 sets), and
/// its own CCD, the swept sphere of integrateTransforms and of createPredictiveContacts,
/// runs only for bodies whose shape isConvex(): a MeshShape body gets no CCD at all, whatever
/// setCcdMotionThreshold and setCcdSweptSphereRadius say. MeshCcdWorld overrides only
/// integrateTransforms; everything else is btDiscreteDynamicsWorld's.
///
/// Use (opt-in: construct it instead of btDiscreteDynamicsWorld, turn CCD on per body as
/// for Bullet's own CCD):
/// \code
///   kolize::registerNarrowphase(&dispatcher);
///   kolize::MeshCcdWorld world(&dispatcher, &broadphase, &solver, &configuration);
///   body->setCcdMotionThreshold(0.05);   // CCD when the body moves more than this per step
///   world.addRigidBody(body);
/// \endcode
#include "kolize/narrowphase/bullet_mesh.h"

#include <BulletDynamics/Dynamics/btDiscreteDynamicsWorld.h>
#include <BulletDynamics/Dynamics/btDiscreteDynamicsWorldMt.h>

#include <cstddef>
#include <memory>

namespace kolize {

namespace detail {
class MeshCcdPass;
}

/// Settings of MeshCcdWorld.
struct MeshCcdWorldSettings {
    /// How far (world units) a stopped body goes past its first contact, along its own
    /// motion in the step. kolize's contacts come from intersecting triangles only, so a
    /// body stopped exactly at the touch would get no contact in the next step, keep its
    /// velocity and be stopped again at once, pinned to the surface; going this far in
    /// gives it a contact of about this depth, which the solver resolves as for a resting
    /// body (Bullet's swept sphere relies on the same: the shape around the sphere is
    /// inside the wall when the sphere touches it). Must be smaller than the thinnest wall a
    /// body must not cross, and >= 0 (0: stop exactly at the first contact). Default 1 mm.
    double penetration = 0.001;
};

/// Counters of the last internal step's mesh CCD (MeshCcdWorld::lastMeshCcd).
struct MeshCcdCounters {
    std::size_t bodies = 0;   ///< MeshShape bodies whose motion exceeded their threshold
    std::size_t pairs = 0;    ///< pairs whose time of impact was computed (mesh algorithms)
    std::size_t clamped = 0;  ///< bodies stopped at a time of impact
};

namespace detail {

struct MeshCcdPassDeleter {
    void operator()(MeshCcdPass* pass) const;
};
using MeshCcdPassPtr = std::unique_ptr<MeshCcdPass, MeshCcdPassDeleter>;
MeshCcdPassPtr makeMeshCcdPass(const MeshCcdWorldSettings& settings);
const MeshCcdWorldSettings& settingsOf(const MeshCcdPass& pass);
void setSettingsOf(MeshCcdPass& pass, const MeshCcdWorldSettings& settings);
const MeshCcdCounters& countersOf(const MeshCcdPass& pass);
void beforeIntegration(MeshCcdPass& pass, btDiscreteDynamicsWorld& world, btScalar timeStep);
void afterIntegration(MeshCcdPass& pass, btDiscreteDynamicsWorld& world);

/// Bullet's `World` (btDiscreteDynamicsWorld or btDiscreteDynamicsWorldMt) with the mesh CCD
/// pass around its integrateTransforms: MeshCcdWorld and MeshCcdWorldMt.
template <class World>
class WithMeshCcd : public World {
  public:
    /// Throws std::invalid_argument for bad `settings`.
    template <class... WorldArguments>
    explicit WithMeshCcd(const MeshCcdWorldSettings& settings, WorldArguments... arguments)
        : World(arguments...), pass_(makeMeshCcdPass(settings)) {}

    const MeshCcdWorldSettings& meshCcdSettings() const { return settingsOf(*pass_); }
    /// Throws std::invalid_argument (the world unchanged) for a negative or non-finite
    /// penetration.
    void setMeshCcdSettings(const MeshCcdWorldSettings& settings) {
        setSettingsOf(*pass_, settings);
    }
    /// What the last internal step's mesh CCD did.
    const MeshCcdCounters& lastMeshCcd() const { return countersOf(*pass_); }

  protected:
    void integrateTransforms(btScalar timeStep) override {
        beforeIntegration(*pass_, *this, timeStep);
        World::integrateTransforms(timeStep);
        afterIntegration(*pass_, *this);
    }

  private:
    MeshCcdPassPtr pass_;
};

}  // namespace detail

/// A btDiscreteDynamicsWorld with continuous collision for MeshShape bodies.
///
/// Each internal step, in integrateTransforms (after the solver, before the bodies move):
/// 1. every active dynamic body's interpolation transform becomes its predicted transform
///    (predictIntegratedTransform over the step with its solved velocities), the end of
///    the step that calculateTimeOfImpact reads;
/// 2. every active dynamic body whose collision shape is a MeshShape and whose motion
///    exceeds its CCD motion threshold (exceedsCcdMotionThreshold) asks the broadphase
///    (aabbTest) for the objects in the box around its shape at the start and at the end
///    of the step; pairs pass the broadphase filter (group and mask), the dispatcher's
///    needsCollision and needsResponse, as in Bullet's btClosestNotMeConvexResultCallback;
/// 3. each such pair, once, in world order: the pair's own mesh algorithm when the pair
///    cache holds one (its last processCollision is this step's), else one made for the
///    question and freed, computes calculateTimeOfImpact: MeshMeshAlgorithm,
///    BvhMeshAlgorithm (scenery) and ConvexMeshAlgorithm (a convex body, dynamic or not; its
///    time of impact against a surface enclosing the convex shape); other pairs are
///    skipped. A time of impact toi < 1
///    limits each body of the pair to h' = min(1, toi + penetration / L) of the step, L the
///    body's motion length (its origin's motion plus its turn times its bounding radius):
///    it goes `penetration` past the first contact (settings);
/// 4. btDiscreteDynamicsWorld::integrateTransforms runs as usual (Bullet's swept sphere for
///    convex bodies, unchanged), over the convex bodies first and then the others, each
///    group in world order: a convex body's swept sphere then meets the mesh bodies where
///    they start the step (a mesh box pushing a ball at speed, integrated first, would stand
///    in front of the ball, which Bullet would stop against the box's back);
/// 5. every body limited in 3 to h' < 1 is then put where Bullet's own CCD would put it, its
///    predictIntegratedTransform over h' times the step, via proceedToTransform (a convex
///    body that Bullet's swept sphere stopped in 4 after a shorter motion stays there). Its
///    velocity is kept: the collision response happens in the next step, from the contact
///    made there (as in Bullet's integrateTransforms). Its getHitFraction() holds the
///    smallest toi until the next step.
/// The thesis moved the object back to the time of impact after the step; here the body is
/// not moved past it in the first place, which is what Bullet's integrator does.
///
/// Compounds: a body whose btCompoundShape holds a MeshShape (at any depth) is a mesh body
/// here, and a pair with a compound on either side takes every pair of their leaves (the
/// shapes that are not compounds) with a MeshShape on one side whose boxes over the step
/// meet, each through an algorithm made for it that first makes its contacts at the start
/// (so the in-contact rule holds as for a pair in the cache); the earliest time limits both
/// bodies. MeshCcdWorldMt below is the same in btDiscreteDynamicsWorldMt. Two fast mesh bodies are
/// handled as a pair, each moving. Deterministic: the result does not depend on the broadphase's
/// report order. Cost per fast body: one aabbTest and, per pair found, meshCcd over both whole
/// meshes.
class MeshCcdWorld : public detail::WithMeshCcd<btDiscreteDynamicsWorld> {
  public:
    /// As btDiscreteDynamicsWorld's. Throws std::invalid_argument for bad `settings`.
    MeshCcdWorld(btDispatcher* dispatcher, btBroadphaseInterface* broadphase,
                 btConstraintSolver* solver, btCollisionConfiguration* configuration,
                 const MeshCcdWorldSettings& settings = {})
        : WithMeshCcd(settings, dispatcher, broadphase, solver, configuration) {}
};

/// The same pass in Bullet's multithreaded world (btDiscreteDynamicsWorldMt): everything as
/// MeshCcdWorld's comment says, the pass itself single-threaded (before and after Bullet's
/// parallel integrateTransforms, which integrates the bodies in parallel batches: the convex
/// bodies first holds only when Bullet runs it on one thread, e.g. without BT_THREADSAFE or
/// with the sequential task scheduler).
class MeshCcdWorldMt : public detail::WithMeshCcd<btDiscreteDynamicsWorldMt> {
  public:
    /// As btDiscreteDynamicsWorldMt's. Throws std::invalid_argument for bad `settings`.
    MeshCcdWorldMt(btDispatcher* dispatcher, btBroadphaseInterface* broadphase,
                   btConstraintSolverPoolMt* solverPool, btConstraintSolver* constraintSolverMt,
                   btCollisionConfiguration* configuration,
                   const MeshCcdWorldSettings& settings = {})
        : WithMeshCcd(settings, dispatcher, broadphase, solverPool, constraintSolverMt,
                      configuration) {}
};

}  // namespace kolize
