#include "kolize/narrowphase/bv_tree.h"

#include "bv_internal.h"

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <utility>

namespace kolize::narrowphase {

static_assert(sizeof(ObbNode) == 64, "an OBB node is one 64-byte cache line");
static_assert(sizeof(NodeLink) == 4, "links are 4 bytes");

const char* treeKindName(TreeKind kind) {
    switch (kind) {
        case TreeKind::kSphere:
            return "sphere";
        case TreeKind::kAabb:
            return "aabb";
        case TreeKind::kObb:
            return "obb";
        case TreeKind::kKdop6:
            return "kdop6";
        case TreeKind::kKdop14:
            return "kdop14";
        case TreeKind::kKdop18:
            return "kdop18";
        case TreeKind::kKdop26:
            return "kdop26";
    }
    return "?";
}

namespace {

// Per-kind fitting, containment and nesting.

template <class Corners>
void fitNode(SphereNode& node, const Corners& corners, const Eigen::Matrix3d&) {
    node.volume = detail::fitSphereFrom(corners);
}
template <class Corners>
void fitNode(AabbNode& node, const Corners& corners, const Eigen::Matrix3d&) {
    node.volume = detail::fitAabbFrom(corners);
}
/// Half the box's surface area: the measure by which two fits of one node are compared
/// (nonzero for flat parts, and what decides how often a box is met).
double halfArea(const Obb& box) {
    const Vec3 h = box.half.cast<double>();
    return h.x() * h.y() + h.y() * h.z() + h.z() * h.x();
}

template <class Corners>
void fitNode(ObbNode& node, const Corners& corners, const Eigen::Matrix3d& axes) {
    node.volume = detail::fitObbFrom(corners, axes);
    // The principal axes of a box-like part are arbitrary where its spread is equal in two
    // or three directions (a cube, a square slab), and its box then stands askew; the
    // model's own axes fit such parts exactly. The smaller of the two boxes is kept.
    const Obb aligned = detail::fitObbFrom(corners, Eigen::Matrix3d::Identity());
    if (halfArea(aligned) < halfArea(node.volume)) {
        node.volume = aligned;
    }
    node.extentSum = (node.volume.half.x() + node.volume.half.y()) + node.volume.half.z();
}
template <int K, class Corners>
void fitNode(KdopNode<K>& node, const Corners& corners, const Eigen::Matrix3d&) {
    node.volume = detail::fitKdopFrom<K>(corners);
}

bool nodeContains(const SphereNode& node, const Vec3& x) {
    return contains(node.volume, x);
}
bool nodeContains(const AabbNode& node, const Vec3& x) {
    return contains(node.volume, x);
}
bool nodeContains(const ObbNode& node, const Vec3& x) {
    // Both the box and the sphere around its centre are used by the query.
    Sphere sphere{node.volume.center, node.volume.radius};
    return contains(node.volume, x) && contains(sphere, x);
}
template <int K>
bool nodeContains(const KdopNode<K>& node, const Vec3& x) {
    return contains(node.volume, x);
}

/// Child volume inside the parent's, for the kinds whose fit nests (unions of boxes).
bool nested(const SphereNode&, const SphereNode&) {
    return true;  // not a property of fitted spheres; triangle containment is checked
}
bool nested(const ObbNode&, const ObbNode&) {
    return true;  // likewise for fitted boxes
}
bool nested(const AabbNode& child, const AabbNode& parent) {
    return (child.volume.lo.array() >= parent.volume.lo.array()).all() &&
           (child.volume.hi.array() <= parent.volume.hi.array()).all();
}
template <int K>
bool nested(const KdopNode<K>& child, const KdopNode<K>& parent) {
    for (int i = 0; i < K / 2; ++i) {
        if (child.volume.lo[i] < parent.volume.lo[i] || child.volume.hi[i] > parent.volume.hi[i]) {
            return false;
        }
    }
    return true;
}

/// Per-triangle sums for the covariance of any range in O(range): corners relative to a
/// reference point (the mesh's box centre) to keep the one-pass formula well conditioned.
struct TriangleMoments {
    Vec3 centroid;
    Vec3 sum;          // p + q + r - 3 o
    double second[6];  // xx, yy, zz, xy, xz, yz of the three corners, relative to o
};

}  // namespace

template <class Node>
BvTree<Node> BvTree<Node>::build(const TriangleMesh& mesh, int leafSize) {
    if (leafSize < 1 || leafSize > 8) {
        throw std::invalid_argument("mesh '" + mesh.name() + "': leaf size " +
                                    std::to_string(leafSize) + " is outside 1..8");
    }
    const std::size_t n = mesh.triangleCount();
    if (n >= (std::size_t(1) << 28)) {
        throw std::invalid_argument("mesh '" + mesh.name() + "': " + std::to_string(n) +
                                    " triangles; trees hold fewer than 2^28");
    }
    BvTree tree;
    tree.leafSize_ = leafSize;
    const std::vector<Vec3>& vertices = mesh.vertices();
    const std::vector<Index3>& triangles = mesh.triangles();

    Vec3 lo = vertices[triangles[0][0]], hi = lo;
    for (const Index3& t : triangles) {
        for (int k = 0; k < 3; ++k) {
            lo = lo.cwiseMin(vertices[t[k]]);
            hi = hi.cwiseMax(vertices[t[k]]);
        }
    }
    const Vec3 origin = 0.5 * (lo + hi);
    std::vector<TriangleMoments> moments(n);
    for (std::size_t i = 0; i < n; ++i) {
        const Index3& t = triangles[i];
        TriangleMoments& m = moments[i];
        m.sum.setZero();
        std::fill(m.second, m.second + 6, 0.0);
        for (int k = 0; k < 3; ++k) {
            const Vec3 p = vertices[t[k]] - origin;
            m.sum += p;
            m.second[0] += p.x() * p.x();
            m.second[1] += p.y() * p.y();
            m.second[2] += p.z() * p.z();
            m.second[3] += p.x() * p.y();
            m.second[4] += p.x() * p.z();
            m.second[5] += p.y() * p.z();
        }
        m.centroid = origin + m.sum / 3.0;
    }

    tree.order_.resize(n);
    std::iota(tree.order_.begin(), tree.order_.end(), 0);
    tree.nodes_.reserve(2 * (n / std::size_t(leafSize) + 1));
    std::vector<double> keys;

    struct Task {
        std::int32_t begin, end, parent;  // parent >= 0: this is the parent's second child
    };
    std::vector<Task> tasks{{0, std::int32_t(n), -1}};
    while (!tasks.empty()) {
        const Task task = tasks.back();
        tasks.pop_back();
        const std::int32_t index = std::int32_t(tree.nodes_.size());
        tree.nodes_.emplace_back();
        if (task.parent >= 0) {
            tree.nodes_[task.parent].link = NodeLink::internal(index);
        }
        const std::int32_t count = task.end - task.begin;
        std::int32_t* ids = tree.order_.data() + task.begin;

        // Thesis formula 2.4 over the range, from the per-triangle sums.
        Vec3 sum = Vec3::Zero();
        double second[6] = {0, 0, 0, 0, 0, 0};
        for (std::int32_t i = 0; i < count; ++i) {
            const TriangleMoments& m = moments[ids[i]];
            sum += m.sum;
            for (int k = 0; k < 6; ++k) {
                second[k] += m.second[k];
            }
        }
        const double corners = 3.0 * count;
        const Vec3 mean = sum / corners;
        Eigen::Matrix3d covariance;
        covariance(0, 0) = second[0] / corners - mean.x() * mean.x();
        covariance(1, 1) = second[1] / corners - mean.y() * mean.y();
        covariance(2, 2) = second[2] / corners - mean.z() * mean.z();
        covariance(0, 1) = covariance(1, 0) = second[3] / corners - mean.x() * mean.y();
        covariance(0, 2) = covariance(2, 0) = second[4] / corners - mean.x() * mean.z();
        covariance(1, 2) = covariance(2, 1) = second[5] / corners - mean.y() * mean.z();
        const Eigen::Matrix3d axes = principalAxes(covariance);

        auto cornerVisitor = [&](auto&& f) {
            for (std::int32_t i = 0; i < count; ++i) {
                const Index3& t = triangles[ids[i]];
                f(vertices[t[0]]);
                f(vertices[t[1]]);
                f(vertices[t[2]]);
            }
        };
        fitNode(tree.nodes_[index], cornerVisitor, axes);

        if (count <= leafSize) {
            tree.nodes_[index].link = NodeLink::leaf(task.begin, count);
            continue;
        }
        // The plane through the mean vertex, normal to the principal axis (thesis).
        const Vec3 axis = axes.col(0);
        const double threshold = (origin + mean).dot(axis);
        std::int32_t* middle = std::partition(ids, ids + count, [&](std::int32_t t) {
            return moments[t].centroid.dot(axis) < threshold;
        });
        if (middle == ids || middle == ids + count) {
            // Every centroid on one side (coincident or symmetric triangles): median split.
            middle = ids + count / 2;
            std::nth_element(ids, middle, ids + count, [&](std::int32_t a, std::int32_t b) {
                return moments[a].centroid.dot(axis) < moments[b].centroid.dot(axis);
            });
        }
        const std::int32_t split = task.begin + std::int32_t(middle - ids);
        tasks.push_back({split, task.end, index});  // second child, built after the first
        tasks.push_back({task.begin, split, -1});   // first child: the next node
    }
    tree.nodes_.shrink_to_fit();
    tree.slots_.resize(n);
    for (std::size_t s = 0; s < n; ++s) {
        tree.slots_[s] = triangles[tree.order_[s]];
    }
    return tree;
}

template <class Node>
std::string BvTree<Node>::validate(const TriangleMesh& mesh) const {
    const std::size_t n = mesh.triangleCount();
    const std::string prefix = "tree over mesh '" + mesh.name() + "': ";
    if (nodes_.empty()) {
        return prefix + "no nodes";
    }
    if (slots_.size() != n || order_.size() != n) {
        return prefix + "slot arrays hold " + std::to_string(slots_.size()) + " and " +
               std::to_string(order_.size()) + " entries for " + std::to_string(n) + " triangles";
    }
    std::vector<char> seen(n, 0);
    for (std::size_t s = 0; s < n; ++s) {
        const std::int32_t t = order_[s];
        if (t < 0 || std::size_t(t) >= n || seen[t]) {
            return prefix + "slot " + std::to_string(s) + " maps to triangle " + std::to_string(t) +
                   ", not a permutation";
        }
        seen[t] = 1;
        if (slots_[s] != mesh.triangles()[t]) {
            return prefix + "slot " + std::to_string(s) + " is not a copy of triangle " +
                   std::to_string(t);
        }
    }
    // Children have larger indices than their parent, so one backward pass knows every
    // subtree's node range [i, end) and slot range [first, last).
    const std::int32_t count = std::int32_t(nodes_.size());
    std::vector<std::int32_t> end(count), first(count), last(count);
    for (std::int32_t i = count - 1; i >= 0; --i) {
        const NodeLink link = nodes_[i].link;
        const std::string where = prefix + "node " + std::to_string(i) + ": ";
        if (link.isLeaf()) {
            if (link.count() > leafSize_) {
                return where + "leaf of " + std::to_string(link.count()) + " slots, leaf size " +
                       std::to_string(leafSize_);
            }
            end[i] = i + 1;
            first[i] = link.firstSlot();
            last[i] = link.firstSlot() + link.count();
            if (first[i] < 0 || std::size_t(last[i]) > n) {
                return where + "slots outside the triangles";
            }
            continue;
        }
        const std::int32_t left = i + 1, right = link.right();
        if (right <= left || right >= count || end[left] != right) {
            return where + "second child " + std::to_string(right) +
                   " does not follow the first child's subtree";
        }
        if (last[left] != first[right]) {
            return where + "children's slot ranges are not contiguous";
        }
        end[i] = end[right];
        first[i] = first[left];
        last[i] = last[right];
        if (!nested(nodes_[left], nodes_[i]) || !nested(nodes_[right], nodes_[i])) {
            return where + "a child's volume is not inside this node's";
        }
    }
    if (end[0] != count || first[0] != 0 || std::size_t(last[0]) != n) {
        return prefix + "the root does not span every node and every slot";
    }
    const std::vector<Vec3>& vertices = mesh.vertices();
    for (std::int32_t i = 0; i < count; ++i) {
        for (std::int32_t s = first[i]; s < last[i]; ++s) {
            for (int k = 0; k < 3; ++k) {
                if (!nodeContains(nodes_[i], vertices[slots_[s][k]])) {
                    return prefix + "node " + std::to_string(i) + " does not contain vertex " +
                           std::to_string(slots_[s][k]) + " of triangle " +
                           std::to_string(order_[s]);
                }
            }
        }
    }
    return "";
}

template class BvTree<SphereNode>;
template class BvTree<AabbNode>;
template class BvTree<ObbNode>;
template class BvTree<KdopNode<6>>;
template class BvTree<KdopNode<14>>;
template class BvTree<KdopNode<18>>;
template class BvTree<KdopNode<26>>;

}  // namespace kolize::narrowphase
