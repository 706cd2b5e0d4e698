#include <kolize/engine/contact_audit.h>

#include <kolize/narrowphase/bullet_mesh.h>
#include <kolize/narrowphase/mesh_query.h>

#include <btBulletCollisionCommon.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <vector>
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

/// The largest distance of a vertex from the model's origin.
double reach(const narrowphase::MeshModel& model) {
    double out = 0;
    for (const narrowphase::Vec3& v : model.mesh().vertices()) {
        out = std::max(out, v.norm());
    }
    return out;
}

/// The generalized winding number of `point` (in the mesh's frame) about the mesh: the
/// triangles' signed solid angles over 4 pi (Van Oosterom and Strackee). 1 inside a closed
/// outward-wound mesh, 0 outside; an open mesh gets fractions.
double windingNumber(const narrowphase::TriangleMesh& mesh, const narrowphase::Vec3& point) {
    double sum = 0;
    for (const narrowphase::Index3& t : mesh.triangles()) {
        const narrowphase::Vec3 a = mesh.vertices()[t[0]] - point;
        const narrowphase::Vec3 b = mesh.vertices()[t[1]] - point;
        const narrowphase::Vec3 c = mesh.vertices()[t[2]] - point;
        const double la = a.norm(), lb = b.norm(), lc = c.norm();
        const double numerator = a.dot(b.cross(c));
        const double denominator = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
        sum += 2 * std::atan2(numerator, denominator);
    }
    return sum / (4 * M_PI);
}

struct WorldBox {
    narrowphase::Vec3 lo, hi;
    bool inside(const WorldBox& other) const {
        return (lo.array() >= other.lo.array()).all() && (hi.array() <= other.hi.array()).all();
    }
};

WorldBox worldBox(const narrowphase::TriangleMesh& mesh, const narrowphase::Pose& pose) {
    WorldBox box{narrowphase::Vec3::Constant(HUGE_VAL), narrowphase::Vec3::Constant(-HUGE_VAL)};
    for (const narrowphase::Vec3& v : mesh.vertices()) {
        const narrowphase::Vec3 w = pose.rotation * v + pose.translation;
        box.lo = box.lo.cwiseMin(w);
        box.hi = box.hi.cwiseMax(w);
    }
    return box;
}

/// Whether meshes A and B (B moved by a shift) overlap as solids: their surfaces share a
/// point (kolize's exact test), or a closed one holds a vertex of the other (winding number
/// at least 1/2; looked at only when the other's vertex box lies inside its own).
class SolidOverlap {
  public:
    SolidOverlap(const narrowphase::MeshModel& a, const narrowphase::Pose& poseA, bool closedA,
                 const narrowphase::MeshModel& b, const narrowphase::Pose& poseB, bool closedB)
        : a_(a),
          b_(b),
          closedA_(closedA),
          closedB_(closedB),
          poseA_(poseA),
          poseB_(poseB),
          boxA_(worldBox(a.mesh(), poseA)),
          boxB_(worldBox(b.mesh(), poseB)) {
        yesNo_.mode = narrowphase::QueryMode::kYesNo;
    }

    bool operator()(const narrowphase::Vec3& shift) {
        narrowphase::Pose moved = poseB_;
        moved.translation += shift;
        if (query_.run(a_, poseA_, b_, moved, yesNo_).intersecting) {
            return true;
        }
        const WorldBox boxB{boxB_.lo + shift, boxB_.hi + shift};
        if (closedA_ && boxB.inside(boxA_) &&
            holds(a_, poseA_, moved.rotation * b_.mesh().vertices()[0] + moved.translation)) {
            return true;
        }
        return closedB_ && boxA_.inside(boxB) &&
               holds(b_, moved, poseA_.rotation * a_.mesh().vertices()[0] + poseA_.translation);
    }

  private:
    static bool holds(const narrowphase::MeshModel& m, const narrowphase::Pose& pose,
                      const narrowphase::Vec3& world) {
        return windingNumber(m.mesh(), pose.rotation.transpose() * (world - pose.translation)) >=
               0.5;
    }

    const narrowphase::MeshModel& a_;
    const narrowphase::MeshModel& b_;
    bool closedA_, closedB_;
    narrowphase::Pose poseA_, poseB_;
    WorldBox boxA_, boxB_;
    narrowphase::QuerySettings yesNo_;
    narrowphase::MeshQuery query_;
};

double separationDepthOf(const narrowphase::MeshModel& a, const narrowphase::Pose& poseA,
                         bool closedA, const narrowphase::MeshModel& b,
                         const narrowphase::Pose& poseB, bool closedB) {
    SolidOverlap overlapsMoved(a, poseA, closedA, b, poseB, closedB);
    if (!overlapsMoved(narrowphase::Vec3::Zero())) {
        return 0;
    }
    // Moved this far in any direction, B's vertices are all beyond A's reach.
    const narrowphase::Vec3 apart = poseB.translation - poseA.translation;
    const double bound = 1.01 * (reach(a) + reach(b) + apart.norm()) + 1e-12;
    // The 26 directions of a cube's faces, edges and corners, once; then the line between
    // the bodies.
    static const std::vector<narrowphase::Vec3> cube = [] {
        std::vector<narrowphase::Vec3> out;
        for (int x = -1; x <= 1; ++x) {
            for (int y = -1; y <= 1; ++y) {
                for (int z = -1; z <= 1; ++z) {
                    if (x != 0 || y != 0 || z != 0) {
                        out.push_back(narrowphase::Vec3(x, y, z).normalized());
                    }
                }
            }
        }
        return out;
    }();
    std::vector<narrowphase::Vec3> directions = cube;
    if (apart.norm() > 0) {
        directions.push_back(apart.normalized());
    }
    double best = bound;
    for (const narrowphase::Vec3& d : directions) {
        if (overlapsMoved(best * d)) {
            continue;  // this direction cannot beat the best
        }
        double inside = 0, outside = best;
        for (int step = 0; step < 14; ++step) {
            const double middle = 0.5 * (inside + outside);
            (overlapsMoved(middle * d) ? inside : outside) = middle;
        }
        best = outside;
    }
    return best;
}

}  // namespace

double separationDepth(const narrowphase::MeshModel& a, const narrowphase::Pose& poseA,
                       const narrowphase::MeshModel& b, const narrowphase::Pose& poseB) {
    return separationDepthOf(a, poseA, meshMassProperties(a.mesh()).closed, b, poseB,
                             meshMassProperties(b.mesh()).closed);
}

ContactAudit& ContactAudit::operator+=(const ContactAudit& other) {
    pairs += other.pairs;
    intersecting += other.intersecting;
    invented += other.invented;
    missing += other.missing;
    roundingTies += other.roundingTies;
    maxFalseDepth = std::max(maxFalseDepth, other.maxFalseDepth);
    maxPenetration = std::max(maxPenetration, other.maxPenetration);
    sumPenetration += other.sumPenetration;
    penetrationPairs += other.penetrationPairs;
    steps += other.steps;
    return *this;
}

ContactAudit auditContacts(const btCollisionWorld& world, const ExactMeshes& meshes,
                           const AuditSettings& settings) {
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
    std::map<const narrowphase::TriangleMesh*, bool> closed;  // closedness, once per mesh
    auto isClosed = [&](const narrowphase::MeshModel& model) {
        const auto [at, fresh] = closed.emplace(&model.mesh(), false);
        if (fresh) {
            at->second = meshMassProperties(model.mesh()).closed;
        }
        return at->second;
    };
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
        if (settings.penetration) {
            // Every pair: one wholly inside the other penetrates without surface contact.
            const double depth = separationDepthOf(*meshA->second, poseA, isClosed(*meshA->second),
                                                   *meshB->second, poseB, isClosed(*meshB->second));
            if (depth > 0) {
                audit.maxPenetration = std::max(audit.maxPenetration, depth);
                audit.sumPenetration += depth;
                ++audit.penetrationPairs;
            }
        }
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
