// FCL 0.7 (Debian's libfcl-dev) as a benchmark method: fcl::collide() on two BVHModels of
// one bounding volume, as a robotics user calls it.

#include "method.h"

#include <fcl/fcl.h>
#include <fcl/narrowphase/detail/traversal/collision_node.h>

#include <algorithm>
#include <chrono>
#include <limits>
#include <stdexcept>

namespace kolize::narrowbench {

namespace {

template <class BV>
class FclMethod : public Method {
  public:
    explicit FclMethod(std::string name) : name_(std::move(name)) {}
    std::string name() const override { return name_; }
    bool supports(Mode) const override { return true; }

    void prepare(const workload::WorkloadMesh& a, const workload::WorkloadMesh& b) override {
        std::vector<double> seconds;
        for (int i = 0; i < 3; ++i) {
            const auto start = std::chrono::steady_clock::now();
            modelA_ = build(*a.mesh);
            seconds.push_back(
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        }
        std::sort(seconds.begin(), seconds.end());
        build_.microsPerTriangle = seconds[1] * 1e6 / double(a.mesh->triangleCount());
        build_.nodes = std::size_t(modelA_->getNumBVs());
        build_.bytesPerNode = double(sizeof(fcl::BVNode<BV>));
        // A mesh against its own copy: FCL gets two models, as two bodies would have.
        modelB_ = a.mesh == b.mesh ? build(*a.mesh) : build(*b.mesh);
        objectA_ = std::make_unique<fcl::CollisionObjectd>(modelA_);
        objectB_ = std::make_unique<fcl::CollisionObjectd>(modelB_);
    }
    BuildInfo buildInfo() const override { return build_; }

    void run(const Pose& a, const Pose& b, Mode mode) override {
        objectA_->setTransform(a.rotation, a.translation);
        objectB_->setTransform(b.rotation, b.translation);
        request_ = fcl::CollisionRequestd();
        request_.num_max_contacts =
            mode == Mode::kYesNo ? 1 : std::numeric_limits<std::size_t>::max();
        request_.enable_contact = mode == Mode::kContacts;
        result_.clear();
        fcl::collide(objectA_.get(), objectB_.get(), request_, result_);
        poseA_ = a;
        poseB_ = b;
    }

    void collect(Outcome& out) override {
        out.intersecting = result_.isCollision();
        out.pairs.clear();
        for (std::size_t i = 0; i < result_.numContacts(); ++i) {
            const fcl::Contactd& c = result_.getContact(i);
            // b1 belongs to the first object given to collide() (FCL copies AABB and k-DOP
            // models inside collide(), so o1 is not always modelA_; it swaps only when B is
            // the model the contact names first).
            const bool aFirst = c.o1 != modelB_.get();
            out.pairs.push_back(
                {std::int32_t(aFirst ? c.b1 : c.b2), std::int32_t(aFirst ? c.b2 : c.b1)});
        }
        // FCL may report a pair more than once (its contact mode adds one per point).
        std::sort(out.pairs.begin(), out.pairs.end());
        out.pairs.erase(std::unique(out.pairs.begin(), out.pairs.end()), out.pairs.end());
        out.bvTests = out.triangleTests = 0;
        if constexpr (std::is_same_v<BV, fcl::OBBd>) {
            // The same traversal collide() runs, with FCL's statistics on (untimed).
            fcl::detail::MeshCollisionTraversalNodeOBB<double> node;
            fcl::CollisionResultd result;
            fcl::Transform3d tfA = fcl::Transform3d::Identity(), tfB = fcl::Transform3d::Identity();
            tfA.linear() = poseA_.rotation;
            tfA.translation() = poseA_.translation;
            tfB.linear() = poseB_.rotation;
            tfB.translation() = poseB_.translation;
            // Const arguments select the OBB overload (non-const ones also match FCL's
            // generic template, an ambiguity GCC warns about).
            const fcl::BVHModel<BV>& modelA = *modelA_;
            const fcl::BVHModel<BV>& modelB = *modelB_;
            const fcl::Transform3d& poseA = tfA;
            const fcl::Transform3d& poseB = tfB;
            if (fcl::detail::initialize(node, modelA, poseA, modelB, poseB, request_, result)) {
                node.enable_statistics = true;
                fcl::detail::collide(&node);
                out.bvTests = std::uint64_t(node.num_bv_tests);
                out.triangleTests = std::uint64_t(node.num_leaf_tests);
            }
        }
    }

  private:
    static std::shared_ptr<fcl::BVHModel<BV>> build(const narrowphase::TriangleMesh& mesh) {
        std::vector<fcl::Vector3d> vertices(mesh.vertices().begin(), mesh.vertices().end());
        std::vector<fcl::Triangle> triangles;
        triangles.reserve(mesh.triangleCount());
        for (const narrowphase::Index3& t : mesh.triangles()) {
            triangles.emplace_back(std::size_t(t[0]), std::size_t(t[1]), std::size_t(t[2]));
        }
        auto model = std::make_shared<fcl::BVHModel<BV>>();
        model->beginModel(int(triangles.size()), int(vertices.size()));
        model->addSubModel(vertices, triangles);
        model->endModel();
        return model;
    }

    std::string name_;
    std::shared_ptr<fcl::BVHModel<BV>> modelA_, modelB_;
    std::unique_ptr<fcl::CollisionObjectd> objectA_, objectB_;
    fcl::CollisionRequestd request_;
    fcl::CollisionResultd result_;
    Pose poseA_, poseB_;
    BuildInfo build_;
};

}  // namespace

std::unique_ptr<Method> fclMethod(const std::string& bv) {
    const std::string name = "fcl-" + bv;
    if (bv == "obb") {
        return std::make_unique<FclMethod<fcl::OBBd>>(name);
    }
    if (bv == "obbrss") {
        return std::make_unique<FclMethod<fcl::OBBRSSd>>(name);
    }
    if (bv == "rss") {
        return std::make_unique<FclMethod<fcl::RSSd>>(name);
    }
    if (bv == "kios") {
        return std::make_unique<FclMethod<fcl::kIOSd>>(name);
    }
    if (bv == "kdop18") {
        return std::make_unique<FclMethod<fcl::KDOPd<18>>>(name);
    }
    if (bv == "aabb") {
        return std::make_unique<FclMethod<fcl::AABBd>>(name);
    }
    throw std::invalid_argument("unknown FCL bounding volume '" + bv + "'");
}

}  // namespace kolize::narrowbench
