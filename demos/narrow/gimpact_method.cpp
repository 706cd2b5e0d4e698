// Bullet's GImpact as a benchmark method: two btGImpactMeshShapes through
// btCollisionWorld::contactPairTest, with margin 0 or GImpact's default margin.

#include "method.h"

#include <BulletCollision/Gimpact/btGImpactCollisionAlgorithm.h>
#include <BulletCollision/Gimpact/btGImpactShape.h>
#include <btBulletCollisionCommon.h>

#include <algorithm>
#include <chrono>

namespace kolize::narrowbench {

namespace {

/// The mesh in Bullet's arrays (btScalar: float in Debian's default build).
struct BulletMesh {
    std::vector<btScalar> vertices;
    std::vector<int> indices;
    std::unique_ptr<btTriangleIndexVertexArray> array;
    std::unique_ptr<btGImpactMeshShape> shape;

    BulletMesh(const narrowphase::TriangleMesh& mesh, bool zeroMargin) {
        for (const narrowphase::Vec3& v : mesh.vertices()) {
            for (int k = 0; k < 3; ++k) {
                vertices.push_back(btScalar(v[k]));
            }
        }
        for (const narrowphase::Index3& t : mesh.triangles()) {
            indices.insert(indices.end(), t.begin(), t.end());
        }
        array = std::make_unique<btTriangleIndexVertexArray>(
            int(mesh.triangleCount()), indices.data(), int(3 * sizeof(int)),
            int(mesh.vertices().size()), vertices.data(), int(3 * sizeof(btScalar)));
        shape = std::make_unique<btGImpactMeshShape>(array.get());
        if (zeroMargin) {
            shape->setMargin(0);
        }
        shape->updateBound();
    }
};

btTransform toBullet(const Pose& p) {
    const btMatrix3x3 basis(
        btScalar(p.rotation(0, 0)), btScalar(p.rotation(0, 1)), btScalar(p.rotation(0, 2)),
        btScalar(p.rotation(1, 0)), btScalar(p.rotation(1, 1)), btScalar(p.rotation(1, 2)),
        btScalar(p.rotation(2, 0)), btScalar(p.rotation(2, 1)), btScalar(p.rotation(2, 2)));
    return btTransform(basis, btVector3(btScalar(p.translation.x()), btScalar(p.translation.y()),
                                        btScalar(p.translation.z())));
}

struct PairCollector : btCollisionWorld::ContactResultCallback {
    const btCollisionObject* a = nullptr;
    std::vector<TrianglePair> pairs;
    btScalar addSingleResult(btManifoldPoint&, const btCollisionObjectWrapper* w0, int, int index0,
                             const btCollisionObjectWrapper*, int, int index1) override {
        if (w0->getCollisionObject() == a) {
            pairs.push_back({index0, index1});
        } else {
            pairs.push_back({index1, index0});
        }
        return 0;
    }
};

class GImpactMethod : public Method {
  public:
    explicit GImpactMethod(bool zeroMargin)
        : zeroMargin_(zeroMargin),
          dispatcher_(&configuration_),
          world_(&dispatcher_, &broadphase_, &configuration_) {
        btGImpactCollisionAlgorithm::registerAlgorithm(&dispatcher_);
        // registerAlgorithm fills only the contact-point table; contactPairTest looks in the
        // closest-point table, and without this finds nothing.
        static btGImpactCollisionAlgorithm::CreateFunc createFunc;
        for (int i = 0; i < MAX_BROADPHASE_COLLISION_TYPES; ++i) {
            dispatcher_.registerClosestPointsCreateFunc(GIMPACT_SHAPE_PROXYTYPE, i, &createFunc);
            dispatcher_.registerClosestPointsCreateFunc(i, GIMPACT_SHAPE_PROXYTYPE, &createFunc);
        }
    }
    std::string name() const override { return zeroMargin_ ? "gimpact-margin0" : "gimpact"; }
    bool supports(Mode) const override { return true; }  // one call answers every mode

    void prepare(const workload::WorkloadMesh& a, const workload::WorkloadMesh& b) override {
        std::vector<double> seconds;
        for (int i = 0; i < 3; ++i) {
            const auto start = std::chrono::steady_clock::now();
            meshA_ = std::make_unique<BulletMesh>(*a.mesh, zeroMargin_);
            seconds.push_back(
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        }
        std::sort(seconds.begin(), seconds.end());
        build_.microsPerTriangle = seconds[1] * 1e6 / double(a.mesh->triangleCount());
        build_.nodes = std::size_t(meshA_->shape->getMeshPart(0)->getBoxSet()->getNodeCount());
        build_.bytesPerNode = double(sizeof(BT_QUANTIZED_BVH_NODE));  // GImpact quantizes its boxes
        meshB_ = std::make_unique<BulletMesh>(*b.mesh, zeroMargin_);
        objectA_.setCollisionShape(meshA_->shape.get());
        objectB_.setCollisionShape(meshB_->shape.get());
    }
    BuildInfo buildInfo() const override { return build_; }

    void run(const Pose& a, const Pose& b, Mode) override {
        objectA_.setWorldTransform(toBullet(a));
        objectB_.setWorldTransform(toBullet(b));
        collector_.a = &objectA_;
        collector_.pairs.clear();
        world_.contactPairTest(&objectA_, &objectB_, collector_);
    }

    void collect(Outcome& out) override {
        out.pairs = collector_.pairs;
        std::sort(out.pairs.begin(), out.pairs.end());
        out.pairs.erase(std::unique(out.pairs.begin(), out.pairs.end()), out.pairs.end());
        out.intersecting = !out.pairs.empty();
    }

  private:
    bool zeroMargin_;
    btDefaultCollisionConfiguration configuration_;
    btCollisionDispatcher dispatcher_;
    btDbvtBroadphase broadphase_;
    btCollisionWorld world_;
    std::unique_ptr<BulletMesh> meshA_, meshB_;
    btCollisionObject objectA_, objectB_;
    PairCollector collector_;
    BuildInfo build_;
};

}  // namespace

std::unique_ptr<Method> gimpactMethod(bool zeroMargin) {
    return std::make_unique<GImpactMethod>(zeroMargin);
}

}  // namespace kolize::narrowbench
