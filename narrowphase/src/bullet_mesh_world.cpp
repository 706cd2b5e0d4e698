#include "kolize/narrowphase/bullet_mesh_world.h"

#include "mesh_ccd_pass.h"

#include <BulletCollision/BroadphaseCollision/btBroadphaseInterface.h>
#include <BulletCollision/BroadphaseCollision/btDispatcher.h>
#include <BulletCollision/BroadphaseCollision/btOverlappingPairCache.h>
#include <BulletCollision/CollisionDispatch/btCollisionObjectWrapper.h>
#include <BulletCollision/CollisionDispatch/btManifoldResult.h>
#include <BulletCollision/CollisionShapes/btCompoundShape.h>
#include <LinearMath/btAabbUtil2.h>
#include <BulletDynamics/Dynamics/btRigidBody.h>

#include <algorithm>
#include <map>
#include <cmath>
#include <stdexcept>
#include <string>

namespace kolize {

using detail::Leaf;
using detail::MeshCcdPass;

namespace {

void checkSettings(const MeshCcdWorldSettings& settings) {
    if (!(std::isfinite(settings.penetration) && settings.penetration >= 0)) {
        throw std::invalid_argument("kolize::MeshCcdWorld: penetration " +
                                    std::to_string(settings.penetration) +
                                    " must be finite and >= 0");
    }
}

const MeshShape* meshShape(const btCollisionShape* shape) {
    if (!shape || shape->getShapeType() != CUSTOM_CONCAVE_SHAPE_TYPE) {
        return nullptr;
    }
    return dynamic_cast<const MeshShape*>(shape);
}

const MeshShape* meshShapeOf(const btCollisionObject& object) {
    return meshShape(object.getCollisionShape());
}

/// The shapes that are not compounds in `shape`, with their transforms in its frame
/// (compounds in compounds flattened; `shape` itself when it is not a compound).
void leavesOf(const btCollisionShape* shape, const btTransform& local, std::vector<Leaf>& out,
              int depth = 0) {
    if (!shape) {
        return;
    }
    if (shape->getShapeType() != COMPOUND_SHAPE_PROXYTYPE || depth > 64) {
        out.push_back({shape, local});
        return;
    }
    const auto* compound = static_cast<const btCompoundShape*>(shape);
    for (int i = 0; i < compound->getNumChildShapes(); ++i) {
        leavesOf(compound->getChildShape(i), local * compound->getChildTransform(i), out,
                 depth + 1);
    }
}

bool hasMeshLeaf(const btCollisionShape* shape, std::vector<Leaf>& scratch) {
    scratch.clear();
    btTransform identity;
    identity.setIdentity();
    leavesOf(shape, identity, scratch);
    for (const Leaf& leaf : scratch) {
        if (meshShape(leaf.shape)) {
            return true;
        }
    }
    return false;
}

bool isCompound(const btCollisionObject& object) {
    return object.getCollisionShape() &&
           object.getCollisionShape()->getShapeType() == COMPOUND_SHAPE_PROXYTYPE;
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

/// Whether `object` moves over the step: an active rigid body, neither static nor kinematic
/// (the algorithms' rule for what has an end of the step of its own).
bool movesOverStep(const btCollisionObject& object) {
    return btRigidBody::upcast(&object) && object.isActive() && !object.isStaticOrKinematicObject();
}

/// Where `object` is at the end of the step: its interpolation transform if it moves.
const btTransform& endOfStep(const btCollisionObject& object) {
    return movesOverStep(object) ? object.getInterpolationWorldTransform()
                                 : object.getWorldTransform();
}

/// The box (world frame) around `leaf` of `object` at the start and at the end of the step.
void sweptLeafBox(const btCollisionObject& object, const btTransform& end, const Leaf& leaf,
                  btVector3& lo, btVector3& hi) {
    btVector3 endLo, endHi;
    leaf.shape->getAabb(object.getWorldTransform() * leaf.local, lo, hi);
    leaf.shape->getAabb(end * leaf.local, endLo, endHi);
    lo.setMin(endLo);
    hi.setMax(endHi);
}

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

MeshCcdPass::MeshCcdPass(const MeshCcdWorldSettings& settings) : settings_(settings) {
    checkSettings(settings);
}

void MeshCcdPass::setSettings(const MeshCcdWorldSettings& settings) {
    checkSettings(settings);
    settings_ = settings;
}

void MeshCcdPass::limit(btCollisionObject* a, btCollisionObject* b, btScalar toi) {
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

void MeshCcdPass::ProxyObject::take(const btCollisionObject& object, const Leaf& leaf,
                                    const btTransform& end) {
    setCollisionFlags(object.getCollisionFlags());
    forceActivationState(object.getActivationState());
    setCollisionShape(const_cast<btCollisionShape*>(leaf.shape));
    setWorldTransform(object.getWorldTransform() * leaf.local);
    setInterpolationWorldTransform(end * leaf.local);
    setCcdMotionThreshold(object.getCcdMotionThreshold());
    setHitFraction(1);
}

void MeshCcdPass::compoundTimeOfImpact(btCollisionObject* a, btCollisionObject* b) {
    btTransform identity;
    identity.setIdentity();
    leavesA_.clear();
    leavesB_.clear();
    leavesOf(a->getCollisionShape(), identity, leavesA_);
    leavesOf(b->getCollisionShape(), identity, leavesB_);
    const btTransform& endA = endOfStep(*a);
    const btTransform& endB = endOfStep(*b);
    btScalar earliest = 1;
    for (const Leaf& leafA : leavesA_) {
        btVector3 loA, hiA;
        sweptLeafBox(*a, endA, leafA, loA, hiA);
        for (const Leaf& leafB : leavesB_) {
            // Pairs with a MeshShape and a shape kolize's algorithms take (the mesh
            // algorithms' and ConvexMeshAlgorithm's); convex pairs are Bullet's business.
            if (!meshShape(leafA.shape) && !meshShape(leafB.shape)) {
                continue;
            }
            btVector3 loB, hiB;
            sweptLeafBox(*b, endB, leafB, loB, hiB);
            if (!TestAabbAgainstAabb2(loA, hiA, loB, hiB)) {
                continue;
            }
            proxyA_.take(*a, leafA, endA);
            proxyB_.take(*b, leafB, endB);
            const btCollisionObjectWrapper wrapA(nullptr, proxyA_.getCollisionShape(), &proxyA_,
                                                 proxyA_.getWorldTransform(), -1, -1);
            const btCollisionObjectWrapper wrapB(nullptr, proxyB_.getCollisionShape(), &proxyB_,
                                                 proxyB_.getWorldTransform(), -1, -1);
            btCollisionAlgorithm* algorithm = world_->getDispatcher()->findAlgorithm(
                &wrapA, &wrapB, nullptr, BT_CONTACT_POINT_ALGORITHMS);
            if (!algorithm) {
                continue;
            }
            if (dynamic_cast<MeshContactAlgorithm*>(algorithm) ||
                dynamic_cast<ConvexMeshAlgorithm*>(algorithm)) {
                ++counters_.pairs;
                // The contacts at the start first: a pair that touches is left to them
                // unless it drives in (the algorithms' rule), as for a pair in the cache.
                btManifoldResult result(&wrapA, &wrapB);
                algorithm->processCollision(&wrapA, &wrapB, world_->getDispatchInfo(), &result);
                const btScalar toi = algorithm->calculateTimeOfImpact(
                    &proxyA_, &proxyB_, world_->getDispatchInfo(), nullptr);
                earliest = std::min(earliest, toi);
            }
            algorithm->~btCollisionAlgorithm();
            world_->getDispatcher()->freeCollisionAlgorithm(algorithm);
        }
    }
    if (earliest < 1) {
        for (btCollisionObject* object : {a, b}) {
            if (object->getHitFraction() > earliest && movesOverStep(*object)) {
                object->setHitFraction(earliest);
            }
        }
        limit(a, b, earliest);
    }
}

void MeshCcdPass::timeOfImpact(btCollisionObject* a, btCollisionObject* b) {
    if (isCompound(*a) || isCompound(*b)) {
        compoundTimeOfImpact(a, b);
        return;
    }
    btBroadphasePair* pair =
        world_->getPairCache()->findPair(a->getBroadphaseHandle(), b->getBroadphaseHandle());
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
        algorithm = world_->getDispatcher()->findAlgorithm(&wrapA, &wrapB, nullptr,
                                                           BT_CONTACT_POINT_ALGORITHMS);
        temporary = algorithm != nullptr;
    }
    if (dynamic_cast<MeshContactAlgorithm*>(algorithm) ||
        dynamic_cast<ConvexMeshAlgorithm*>(algorithm)) {
        ++counters_.pairs;
        // Both bodies go `penetration` past the time of impact, to make their contact.
        const btScalar toi =
            algorithm->calculateTimeOfImpact(a, b, world_->getDispatchInfo(), nullptr);
        if (toi < 1) {
            limit(a, b, toi);
        }
    }
    if (temporary) {
        algorithm->~btCollisionAlgorithm();
        world_->getDispatcher()->freeCollisionAlgorithm(algorithm);
    }
}

void MeshCcdPass::before(btDiscreteDynamicsWorld& world, btScalar timeStep) {
    world_ = &world;
    btAlignedObjectArray<btRigidBody*>& bodies = world.getNonStaticRigidBodies();
    counters_ = MeshCcdCounters{};
    clamped_.clear();
    pairs_.clear();
    allowed_.clear();
    if (world_->getDispatchInfo().m_useContinuous) {
        for (int i = 0; i < bodies.size(); ++i) {
            btRigidBody* body = bodies[i];
            body->setHitFraction(1);
            if (body->isActive() && !body->isStaticOrKinematicObject()) {
                btTransform predicted;
                body->predictIntegratedTransform(timeStep, predicted);
                body->setInterpolationWorldTransform(predicted);
            }
        }
        for (int i = 0; i < bodies.size(); ++i) {
            btRigidBody* body = bodies[i];
            const btCollisionShape* shape = body->getCollisionShape();
            if (!shape || !exceedsCcdMotionThreshold(*body) ||
                !(meshShapeOf(*body) || (isCompound(*body) && hasMeshLeaf(shape, leavesA_)))) {
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
            world_->getBroadphase()->aabbTest(lo, hi, collect);
            for (btCollisionObject* other : found_) {
                if (other == body || !filtersPass(*body, *other) ||
                    !world_->getDispatcher()->needsCollision(body, other) ||
                    !world_->getDispatcher()->needsResponse(body, other)) {
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
            timeOfImpact(world_->getCollisionObjectArray()[x],
                         world_->getCollisionObjectArray()[y]);
        }
        for (int i = 0; i < bodies.size(); ++i) {
            btRigidBody* body = bodies[i];
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
        for (int i = 0; i < bodies.size(); ++i) {
            btRigidBody* body = bodies[i];
            const bool isConvex =
                body->getCollisionShape() && body->getCollisionShape()->isConvex();
            if (isConvex == bool(convex)) {
                integrationOrder_.push_back(body);
            }
        }
    }
    worldOrder_.copyFromArray(bodies);
    bodies.copyFromArray(integrationOrder_);
}

void MeshCcdPass::after(btDiscreteDynamicsWorld& world) {
    world.getNonStaticRigidBodies().copyFromArray(worldOrder_);
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

namespace detail {

void MeshCcdPassDeleter::operator()(MeshCcdPass* pass) const {
    delete pass;
}

MeshCcdPassPtr makeMeshCcdPass(const MeshCcdWorldSettings& settings) {
    return MeshCcdPassPtr(new MeshCcdPass(settings));
}

const MeshCcdWorldSettings& settingsOf(const MeshCcdPass& pass) {
    return pass.settings();
}

void setSettingsOf(MeshCcdPass& pass, const MeshCcdWorldSettings& settings) {
    pass.setSettings(settings);
}

const MeshCcdCounters& countersOf(const MeshCcdPass& pass) {
    return pass.counters();
}

void beforeIntegration(MeshCcdPass& pass, btDiscreteDynamicsWorld& world, btScalar timeStep) {
    pass.before(world, timeStep);
}

void afterIntegration(MeshCcdPass& pass, btDiscreteDynamicsWorld& world) {
    pass.after(world);
}

}  // namespace detail

}  // namespace kolize
