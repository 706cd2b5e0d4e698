#include <kolize/engine/deterministic_islands.h>

#include <BulletCollision/BroadphaseCollision/btOverlappingPairCache.h>
#include <BulletCollision/CollisionDispatch/btCollisionObject.h>
#include <BulletCollision/CollisionDispatch/btCollisionWorld.h>

#include <algorithm>

namespace kolize {

void DeterministicIslandManager::updateActivationState(btCollisionWorld* world,
                                                       btDispatcher* dispatcher) {
    if (!world->getDispatchInfo().m_deterministicOverlappingPairs) {
        btSimulationIslandManager::updateActivationState(world, dispatcher);
        return;
    }
    // Island tags as Bullet's (STATIC_SIMULATION_ISLAND_OPTIMIZATION): the index among the
    // objects that are neither static nor kinematic.
    btCollisionObjectArray& objects = world->getCollisionObjectArray();
    int index = 0;
    for (int i = 0; i < objects.size(); ++i) {
        btCollisionObject* object = objects[i];
        if (!object->isStaticOrKinematicObject()) {
            object->setIslandTag(index++);
        }
        object->setCompanionId(-1);
        object->setHitFraction(btScalar(1));
    }
    initUnionFind(index);
    // The unions of findUnions, in sorted order of the tags instead of the cache's.
    unions_.clear();
    btOverlappingPairCache* cache = world->getPairCache();
    const int count = cache->getNumOverlappingPairs();
    const btBroadphasePair* pairs = count > 0 ? cache->getOverlappingPairArrayPtr() : nullptr;
    for (int i = 0; i < count; ++i) {
        const auto* a = static_cast<const btCollisionObject*>(pairs[i].m_pProxy0->m_clientObject);
        const auto* b = static_cast<const btCollisionObject*>(pairs[i].m_pProxy1->m_clientObject);
        if (a != nullptr && b != nullptr && a->mergesSimulationIslands() &&
            b->mergesSimulationIslands()) {
            const int ta = a->getIslandTag(), tb = b->getIslandTag();
            unions_.emplace_back(std::min(ta, tb), std::max(ta, tb));
        }
    }
    std::sort(unions_.begin(), unions_.end());
    for (const auto& pair : unions_) {
        getUnionFind().unite(pair.first, pair.second);
    }
}

}  // namespace kolize
