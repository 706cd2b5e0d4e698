#include "kolize/narrowphase/mesh_model.h"

#include "rational_internal.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace kolize::narrowphase {

namespace {

std::variant<SphereTree, AabbTree, ObbTree, KdopTree<6>, KdopTree<14>, KdopTree<18>, KdopTree<26>>
buildTree(const TriangleMesh& mesh, const TreeSettings& settings) {
    switch (settings.kind) {
        case TreeKind::kSphere:
            return SphereTree::build(mesh, settings.leaf_size);
        case TreeKind::kAabb:
            return AabbTree::build(mesh, settings.leaf_size);
        case TreeKind::kObb:
            return ObbTree::build(mesh, settings.leaf_size);
        case TreeKind::kKdop6:
            return KdopTree<6>::build(mesh, settings.leaf_size);
        case TreeKind::kKdop14:
            return KdopTree<14>::build(mesh, settings.leaf_size);
        case TreeKind::kKdop18:
            return KdopTree<18>::build(mesh, settings.leaf_size);
        case TreeKind::kKdop26:
            return KdopTree<26>::build(mesh, settings.leaf_size);
    }
    throw std::invalid_argument("unknown tree kind");
}

const TriangleMesh& checked(const std::shared_ptr<const TriangleMesh>& mesh) {
    if (!mesh) {
        throw std::invalid_argument("MeshModel needs a mesh (got a null pointer)");
    }
    return *mesh;
}

}  // namespace

MeshModel::MeshModel(std::shared_ptr<const TriangleMesh> mesh, const TreeSettings& settings)
    : mesh_(std::move(mesh)), settings_(settings), tree_(buildTree(checked(mesh_), settings)) {
    // Centre of the vertices' box; radius to the farthest vertex, rounded up generously.
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (const Index3& t : mesh_->triangles()) {
        for (int k = 0; k < 3; ++k) {
            lo = lo.cwiseMin(mesh_->vertices()[t[k]]);
            hi = hi.cwiseMax(mesh_->vertices()[t[k]]);
        }
    }
    sphere_.center = 0.5 * (lo + hi);
    double r2 = 0;
    for (const Index3& t : mesh_->triangles()) {
        for (int k = 0; k < 3; ++k) {
            r2 = std::max(r2, (mesh_->vertices()[t[k]] - sphere_.center).squaredNorm());
        }
    }
    sphere_.radius = std::sqrt(r2) * (1 + 0x1p-40) + std::numeric_limits<double>::denorm_min();
}

std::size_t MeshModel::nodeCount() const {
    return std::visit([](const auto& tree) { return tree.nodes().size(); }, tree_);
}

std::size_t MeshModel::bytesPerNode() const {
    return std::visit(
        [](const auto& tree) {
            return sizeof(typename std::decay_t<decltype(tree.nodes())>::value_type);
        },
        tree_);
}

std::size_t MeshModel::treeBytes() const {
    return std::visit([](const auto& tree) { return tree.nodeBytes() + tree.triangleBytes(); },
                      tree_);
}

std::string MeshModel::validate() const {
    std::string problem =
        std::visit([&](const auto& tree) { return tree.validate(*mesh_); }, tree_);
    if (!problem.empty()) {
        return problem;
    }
    // The object sphere contains every used vertex, exactly.
    using detail::Rational;
    const Rational r2 = Rational(sphere_.radius) * Rational(sphere_.radius);
    for (const Index3& t : mesh_->triangles()) {
        for (int k = 0; k < 3; ++k) {
            const Vec3& x = mesh_->vertices()[t[k]];
            if ((x - sphere_.center).norm() < sphere_.radius * (1 - 0x1p-45)) {
                continue;
            }
            Rational d2;
            for (int j = 0; j < 3; ++j) {
                const Rational dj = Rational(x[j]) - Rational(sphere_.center[j]);
                d2 = d2 + dj * dj;
            }
            if (!(d2 <= r2)) {
                return "mesh '" + mesh_->name() + "': object sphere misses vertex " +
                       std::to_string(t[k]);
            }
        }
    }
    return "";
}

}  // namespace kolize::narrowphase
