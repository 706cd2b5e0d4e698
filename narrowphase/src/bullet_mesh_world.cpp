#include "kolize/narrowphase/bullet_mesh_world.h"

#include <BulletCollision/BroadphaseCollision/btBroadphaseInterface.h>
#include <BulletCollision/BroadphaseCollision/btDispatcher.h>
#include <BulletCollision/BroadphaseCollision/btOverlappingPairCache.h>
#include <BulletCollision/CollisionDispatch/btCollisionObjectWrapper.h>
#include <BulletDynamics/Dynamics/btRigidBody.h>

#include <algorithm>
#include <map>
#include <cmath>
#include <stdexcept>
#include <string>

namespace kolize {

namespace {

void checkSettings(const MeshCcdWorldSettings& settings) {
    if (!(std::isfinite(settings.penetration) && settings.penetration >= 0)) {
        throw std::invalid_argument("kolize::MeshCcdWorld: penetration " +
                                    std::to_string(settings.penetration) +
                                    " must be finite and >= 0");
    }
}

const MeshShape* meshShapeOf(const btCollisionObject& object) {
    const btCollisionShape* shape = object.getCollisionShape();
    if (!shape || shape->getShapeType() != CUSTOM_CONCAVE_SHAPE_TYPE) {
        return nullptr;
    }
    return dynamic_cast<const MeshShape*>(shape);
}

class CollectObjects : public btBroadphaseAabbCallback {
  public:
    explicit CollectObjects(std::vector<btCollisionObject*>& out) : out_(out) {}
    bool process(const btBroadphaseProxy* proxy) override {
        out_.push_back(static_cast<btCollisionObject*>(proxy->m_clientObject));
        return true;
    }

  private:
    std::vector<btCollisionObject*>& out_;
};

bool filtersPass(const btCollisionObject& a, const btCollisionObject& b) {
    const btBroadphaseProxy* pa = a.getBroadphaseHandle();
    const btBroadphaseProxy* pb = b.getBroadphaseHandle();
    return pa && pb && (pa->m_collisionFilterGroup & pb->m_collisionFilterMask) != 0 &&
           (pb->m_collisionFilterGroup & pa->m_collisionFilterMask) != 0;
}

/// How far the farthest point of `object` moves over the step (at most): its origin's
/// motion plus its turn (radians) times the radius of its bounding sphere.
double motionLength(const btCollisionObject& object) {
    const btTransform& start = object.getWorldTransform();
    const btTransform& end = object.getInterpolationWorldTransform();
    const double translation = double((end.getOrigin() - start.getOrigin()).length());
    const btQuaternion turn = end.getRotation() * start.getRotation().inverse();
    btVector3 center;
    btScalar radius = 0;
    object.getCollisionShape()->getBoundingSphere(center, radius);
    return translation + double(turn.getAngleShortestPath()) * double(radius);
}

}  // namespace

MeshCcdWorld::MeshCcdWorld(btDispatcher* dispatcher, btBroadphaseInterface* broadphase,
                           btConstraintSolver* solver, btCollisionConfiguration* configuration,
                           const MeshCcdWorldSettings& settings)
    : btDiscreteDynamicsWorld(dispatcher, broadphase, solver, configuration), settings_(settings) {
    checkSettings(settings);
}

void MeshCcdWorld::setMeshCcdSettings(const MeshCcdWorldSettings& settings) {
    checkSettings(settings);
    settings_ = settings;
}

void MeshCcdWorld::timeOfImpact(btCollisionObject* a, btCollisionObject* b) {
    btBroadphasePair* pair =
        getPairCache()->findPair(a->getBroadphaseHandle(), b->getBroadphaseHandle());
    btCollisionAlgorithm* algorithm = pair ? pair->m_algorithm : nullptr;
    bool temporary = false;
    if (algorithm) {
        a = static_cast<btCollisionObject*>(pair->m_pProxy0->m_clientObject);
        b = static_cast<btCollisionObject*>(pair->m_pProxy1->m_clientObject);
    } else {
        // Not dispatched this step (their boxes before the solver did not meet): an
        // algorithm for the question, which saw no contacts at the start.
        const btCollisionObjectWrapper wrapA(nullptr, a->getCollisionShape(), a,
                                             a->getWorldTransform(), -1, -1);
        const btCollisionObjectWrapper wrapB(nullptr, b->getCollisionShape(), b,
                                             b->getWorldTransform(), -1, -1);
        algorithm =
            m_dispatcher1->findAlgorithm(&wrapA, &wrapB, nullptr, BT_CONTACT_POINT_ALGORITHMS);
        temporary = algorithm != nullptr;
    }
    if (dynamic_cast<MeshContactAlgorithm*>(algorithm) ||
        dynamic_cast<ConvexMeshAlgorithm*>(algorithm)) {
        ++counters_.pairs;
        // Both bodies go `penetration` past the time of impact, to make their contact.
        const btScalar toi = algorithm->calculateTimeOfImpact(a, b, getDispatchInfo(), nullptr);
        if (toi < 1) {
            for (btCollisionObject* object : {a, b}) {
                const double length = motionLength(*object);
                const double fraction =
                    length > 0 ? std::min(1.0, double(toi) + settings_.penetration / length) : 1.0;
                auto [it, inserted] = allowed_.emplace(object, fraction);
                if (!inserted) {
                    it->second = std::min(it->second, fraction);
                }
            }
        }
    }
    if (temporary) {
        algorithm->~btCollisionAlgorithm();
        m_dispatcher1->freeCollisionAlgorithm(algorithm);
    }
}

void MeshCcdWorld::integrateTransforms(btScalar timeStep) {
    counters_ = MeshCcdCounters{};
    clamped_.clear();
    pairs_.clear();
    allowed_.clear();
    if (getDispatchInfo().m_useContinuous) {
        for (int i = 0; i < m_nonStaticRigidBodies.size(); ++i) {
            btRigidBody* body = m_nonStaticRigidBodies[i];
            body->setHitFraction(1);
            if (body->isActive() && !body->isStaticOrKinematicObject()) {
                btTransform predicted;
                body->predictIntegratedTransform(timeStep, predicted);
                body->setInterpolationWorldTransform(predicted);
            }
        }
        for (int i = 0; i < m_nonStaticRigidBodies.size(); ++i) {
            btRigidBody* body = m_nonStaticRigidBodies[i];
            const MeshShape* shape = meshShapeOf(*body);
            if (!shape || !exceedsCcdMotionThreshold(*body)) {
                continue;
            }
            ++counters_.bodies;
            btVector3 lo, hi, endLo, endHi;
            shape->getAabb(body->getWorldTransform(), lo, hi);
            shape->getAabb(body->getInterpolationWorldTransform(), endLo, endHi);
            lo.setMin(endLo);
            hi.setMax(endHi);
            found_.clear();
            CollectObjects collect(found_);
            getBroadphase()->aabbTest(lo, hi, collect);
            for (btCollisionObject* other : found_) {
                if (other == body || !filtersPass(*body, *other) ||
                    !m_dispatcher1->needsCollision(body, other) ||
                    !m_dispatcher1->needsResponse(body, other)) {
                    continue;
                }
                const int x = body->getWorldArrayIndex();
                const int y = other->getWorldArrayIndex();
                pairs_.emplace_back(std::min(x, y), std::max(x, y));
            }
        }
        // Once per pair, in world order: the same answer for any broadphase.
        std::sort(pairs_.begin(), pairs_.end());
        pairs_.erase(std::unique(pairs_.begin(), pairs_.end()), pairs_.end());
        for (const auto& [x, y] : pairs_) {
            timeOfImpact(m_collisionObjects[x], m_collisionObjects[y]);
        }
        for (int i = 0; i < m_nonStaticRigidBodies.size(); ++i) {
            btRigidBody* body = m_nonStaticRigidBodies[i];
            const btScalar hit = body->getHitFraction();
            if (hit >= 1 || !body->isActive() || body->isStaticOrKinematicObject()) {
                continue;
            }
            const auto allowed = allowed_.find(body);
            const double fraction = allowed == allowed_.end() ? 1.0 : allowed->second;
            if (fraction >= 1) {
                continue;  // the whole step: Bullet's integrator moves it there
            }
            btTransform clamped;
            body->predictIntegratedTransform(timeStep * btScalar(fraction), clamped);
            clamped_.push_back({body, clamped, hit, fraction, body->getWorldTransform().getOrigin(),
                                body->getInterpolationWorldTransform().getOrigin()});
        }
    }
    // Convex bodies first: Bullet's swept sphere of a convex body tests the others where
    // they are when it runs, and a mesh body integrated before it would already stand at
    // the end of its step (a box pushing a ball at 50 m/s would be in front of it, and
    // Bullet would stop the ball against the box's back). Mesh bodies' motions are this
    // pass's business (the pairs above, which see both motions). Same order otherwise.
    integrationOrder_.clear();
    for (int convex = 1; convex >= 0; --convex) {
        for (int i = 0; i < m_nonStaticRigidBodies.size(); ++i) {
            btRigidBody* body = m_nonStaticRigidBodies[i];
            const bool isConvex =
                body->getCollisionShape() && body->getCollisionShape()->isConvex();
            if (isConvex == bool(convex)) {
                integrationOrder_.push_back(body);
            }
        }
    }
    worldOrder_.copyFromArray(m_nonStaticRigidBodies);
    m_nonStaticRigidBodies.copyFromArray(integrationOrder_);
    btDiscreteDynamicsWorld::integrateTransforms(timeStep);
    m_nonStaticRigidBodies.copyFromArray(worldOrder_);
    // Bullet's integrator reset every hit fraction and moved these bodies the whole step, or,
    // for a convex body its swept sphere stopped (hit fraction 0 after it), part of it:
    // that body keeps the shorter of the two motions.
    for (const Clamp& clamp : clamped_) {
        if (clamp.body->getHitFraction() == 0) {
            const btScalar whole = (clamp.end - clamp.start).length();
            const btScalar bullet =
                (clamp.body->getWorldTransform().getOrigin() - clamp.start).length();
            if (!(whole > 0) || double(bullet / whole) <= clamp.fraction) {
                continue;
            }
        }
        clamp.body->proceedToTransform(clamp.transform);
        clamp.body->setHitFraction(clamp.hitFraction);
        ++counters_.clamped;
    }
}

}  // namespace kolize
