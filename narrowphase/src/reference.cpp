#include "kolize/narrowphase/reference.h"

#include <algorithm>

namespace kolize::narrowphase {

namespace {

struct Box {
    Vec3 lo, hi;
    std::int32_t triangle;
    bool fromA;
};

std::vector<Vec3> movedVertices(const TriangleMesh& b, const RelativePose& pose) {
    std::vector<Vec3> out(b.vertices().size());
    for (std::size_t i = 0; i < out.size(); ++i) {
        out[i] = pose.apply(b.vertices()[i]);
    }
    return out;
}

Triangle corners(const std::vector<Vec3>& vertices, const Index3& t) {
    return {vertices[t[0]], vertices[t[1]], vertices[t[2]]};
}

}  // namespace

std::vector<TrianglePair> referencePairs(const TriangleMesh& a, const Pose& poseA,
                                         const TriangleMesh& b, const Pose& poseB,
                                         PredicateStats* stats) {
    const std::vector<Vec3> vb = movedVertices(b, RelativePose(poseA, poseB));
    const std::vector<Vec3>& va = a.vertices();
    std::vector<Box> boxes;
    boxes.reserve(a.triangleCount() + b.triangleCount());
    for (int side = 0; side < 2; ++side) {
        const TriangleMesh& mesh = side == 0 ? a : b;
        const std::vector<Vec3>& v = side == 0 ? va : vb;
        for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
            const Triangle c = corners(v, mesh.triangles()[t]);
            boxes.push_back({c[0].cwiseMin(c[1]).cwiseMin(c[2]), c[0].cwiseMax(c[1]).cwiseMax(c[2]),
                             std::int32_t(t), side == 0});
        }
    }
    std::sort(boxes.begin(), boxes.end(),
              [](const Box& x, const Box& y) { return x.lo.x() < y.lo.x(); });
    std::vector<const Box*> activeA, activeB;
    std::vector<TrianglePair> pairs;
    for (const Box& box : boxes) {
        std::vector<const Box*>& others = box.fromA ? activeB : activeA;
        // Boxes that end before this one starts along x are done.
        others.erase(std::remove_if(others.begin(), others.end(),
                                    [&](const Box* o) { return o->hi.x() < box.lo.x(); }),
                     others.end());
        for (const Box* other : others) {
            if (other->hi.y() < box.lo.y() || box.hi.y() < other->lo.y() ||
                other->hi.z() < box.lo.z() || box.hi.z() < other->lo.z()) {
                continue;
            }
            const Box& boxA = box.fromA ? box : *other;
            const Box& boxB = box.fromA ? *other : box;
            if (trianglesIntersect(corners(va, a.triangles()[boxA.triangle]),
                                   corners(vb, b.triangles()[boxB.triangle]), stats)) {
                pairs.push_back({boxA.triangle, boxB.triangle});
            }
        }
        (box.fromA ? activeA : activeB).push_back(&box);
    }
    std::sort(pairs.begin(), pairs.end());
    return pairs;
}

std::vector<TrianglePair> allPairsReference(const TriangleMesh& a, const Pose& poseA,
                                            const TriangleMesh& b, const Pose& poseB) {
    const std::vector<Vec3> vb = movedVertices(b, RelativePose(poseA, poseB));
    std::vector<TrianglePair> pairs;
    for (std::size_t i = 0; i < a.triangleCount(); ++i) {
        const Triangle p = corners(a.vertices(), a.triangles()[i]);
        for (std::size_t j = 0; j < b.triangleCount(); ++j) {
            if (trianglesIntersect(p, corners(vb, b.triangles()[j]))) {
                pairs.push_back({std::int32_t(i), std::int32_t(j)});
            }
        }
    }
    return pairs;  // already sorted
}

std::vector<TrianglePair> referenceNearPairs(const TriangleMesh& a, const Pose& poseA,
                                             const TriangleMesh& b, const Pose& poseB,
                                             double margin) {
    const std::vector<Vec3> vb = movedVertices(b, RelativePose(poseA, poseB));
    std::vector<TrianglePair> pairs;
    for (std::size_t i = 0; i < a.triangleCount(); ++i) {
        const Triangle p = corners(a.vertices(), a.triangles()[i]);
        const Vec3 plo = p[0].cwiseMin(p[1]).cwiseMin(p[2]);
        const Vec3 phi = p[0].cwiseMax(p[1]).cwiseMax(p[2]);
        for (std::size_t j = 0; j < b.triangleCount(); ++j) {
            const Triangle q = corners(vb, b.triangles()[j]);
            const Vec3 qlo = q[0].cwiseMin(q[1]).cwiseMin(q[2]);
            const Vec3 qhi = q[0].cwiseMax(q[1]).cwiseMax(q[2]);
            // Farther apart than the margin along an axis: farther apart than it.
            if (((plo - qhi).array() > margin).any() || ((qlo - phi).array() > margin).any()) {
                continue;
            }
            if (!trianglesIntersect(p, q) && triangleDistance(p, q).distance <= margin) {
                pairs.push_back({std::int32_t(i), std::int32_t(j)});
            }
        }
    }
    return pairs;  // already sorted
}

}  // namespace kolize::narrowphase
