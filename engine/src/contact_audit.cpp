#include <kolize/engine/contact_audit.h>

#include <kolize/narrowphase/mesh_query.h>

#include <btBulletCollisionCommon.h>

#include <algorithm>
#include <utility>

namespace kolize {

namespace {

narrowphase::Pose poseOf(const btTransform& t) {
    narrowphase::Pose pose;
    for (int row = 0; row < 3; ++row) {
        for (int column = 0; column < 3; ++column) {
            pose.rotation(row, column) = double(t.getBasis()[row][column]);
        }
        pose.translation[row] = double(t.getOrigin()[row]);
    }
    return pose;
}

using BodyPair = std::pair<const btCollisionObject*, const btCollisionObject*>;

BodyPair ordered(const btCollisionObject* a, const btCollisionObject* b) {
    return a < b ? BodyPair(a, b) : BodyPair(b, a);
}

}  // namespace

ContactAudit& ContactAudit::operator+=(const ContactAudit& other) {
    pairs += other.pairs;
    intersecting += other.intersecting;
    invented += other.invented;
    missing += other.missing;
    roundingTies += other.roundingTies;
    maxFalseDepth = std::max(maxFalseDepth, other.maxFalseDepth);
    steps += other.steps;
    return *this;
}

ContactAudit auditContacts(const btCollisionWorld& world, const ExactMeshes& meshes) {
    ContactAudit audit;
    audit.steps = 1;
    // The deepest point of every manifold, by body pair (several manifolds per pair are
    // possible, e.g. one per compound child: the deepest of all counts).
    std::map<BodyPair, double> deepest;
    const btDispatcher* dispatcher = world.getDispatcher();
    for (int i = 0; i < dispatcher->getNumManifolds(); ++i) {
        const btPersistentManifold* manifold =
            const_cast<btDispatcher*>(dispatcher)->getManifoldByIndexInternal(i);
        double depth = -1e300;
        for (int j = 0; j < manifold->getNumContacts(); ++j) {
            depth = std::max(depth, -double(manifold->getContactPoint(j).getDistance()));
        }
        if (manifold->getNumContacts() > 0) {
            auto [at, fresh] =
                deepest.emplace(ordered(manifold->getBody0(), manifold->getBody1()), depth);
            if (!fresh) {
                at->second = std::max(at->second, depth);
            }
        }
    }
    narrowphase::QuerySettings yesNo;
    yesNo.mode = narrowphase::QueryMode::kYesNo;
    narrowphase::MeshQuery query;
    btOverlappingPairCache* cache =
        const_cast<btCollisionWorld&>(world).getBroadphase()->getOverlappingPairCache();
    const btBroadphasePairArray& pairs = cache->getOverlappingPairArray();
    for (int i = 0; i < pairs.size(); ++i) {
        const auto* a = static_cast<const btCollisionObject*>(pairs[i].m_pProxy0->m_clientObject);
        const auto* b = static_cast<const btCollisionObject*>(pairs[i].m_pProxy1->m_clientObject);
        const auto meshA = meshes.find(a), meshB = meshes.find(b);
        if (meshA == meshes.end() || meshB == meshes.end()) {
            continue;
        }
        ++audit.pairs;
        const narrowphase::Pose poseA = poseOf(a->getWorldTransform());
        const narrowphase::Pose poseB = poseOf(b->getWorldTransform());
        const bool intersecting =
            query.run(*meshA->second, poseA, *meshB->second, poseB, yesNo).intersecting;
        // The test is exact on the doubles of B's vertices moved into A's frame; the other
        // order rounds differently, and a pair that touches at that rounding's scale can be
        // apart in one order and touching in the other. Such a pair is neither: it is
        // invented only when apart in both orders, missing only when touching in both.
        auto otherOrder = [&] {
            return query.run(*meshB->second, poseB, *meshA->second, poseA, yesNo).intersecting;
        };
        const auto claim = deepest.find(ordered(a, b));
        const bool claimed = claim != deepest.end() && claim->second > kInventedDepth;
        const bool unclaimed = claim == deepest.end() || claim->second < -kInventedDepth;
        if (intersecting) {
            ++audit.intersecting;
            if (unclaimed) {
                const bool both = otherOrder();
                audit.missing += both ? 1 : 0;
                audit.roundingTies += both ? 0 : 1;
            }
        } else if (claimed) {
            const bool neither = !otherOrder();
            audit.invented += neither ? 1 : 0;
            audit.roundingTies += neither ? 0 : 1;
            if (neither) {
                audit.maxFalseDepth = std::max(audit.maxFalseDepth, claim->second);
            }
        }
    }
    return audit;
}

}  // namespace kolize
