#include "kolize/narrowphase/mesh_ccd.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cstdint>
#include <functional>
#include <limits>
#include <utility>
#include <stdexcept>
#include <unordered_set>

namespace kolize::ccd {
namespace {

struct Aabb {
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
    Vec3 hi = Vec3::Constant(-std::numeric_limits<double>::infinity());
    void grow(const Vec3& p) {
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
    }
    void grow(const Aabb& o) {
        lo = lo.cwiseMin(o.lo);
        hi = hi.cwiseMax(o.hi);
    }
    bool overlaps(const Aabb& o) const {
        return (lo.array() <= o.hi.array()).all() && (o.lo.array() <= hi.array()).all();
    }
};

/// Box around a triangle's positions at t = 0 and t = 1; by convexity it contains the
/// triangle at every t in [0, 1]. Comparisons on exact inputs: no rounding involved.
Aabb sweptBox(const MovingMesh& m, const std::array<int, 3>& tri) {
    Aabb box;
    for (int v : tri) {
        box.grow(m.start[v]);
        box.grow(m.end[v]);
    }
    return box;
}

/// Binary hierarchy over swept triangle boxes, built by median split on the longest axis.
class SweptBvh {
  public:
    explicit SweptBvh(const std::vector<Aabb>& boxes) : boxes_(boxes) {
        order_.resize(boxes.size());
        for (size_t i = 0; i < order_.size(); ++i) {
            order_[i] = static_cast<int>(i);
        }
        if (!order_.empty()) {
            nodes_.emplace_back();
            build(0, 0, order_.size());
        }
    }

    /// Calls visit(triangle) for every triangle whose swept box overlaps `query`.
    template <class Visit>
    void query(const Aabb& query, Visit visit) const {
        if (nodes_.empty()) {
            return;
        }
        std::vector<int> stack{0};
        while (!stack.empty()) {
            const Node& n = nodes_[stack.back()];
            stack.pop_back();
            if (!n.box.overlaps(query)) {
                continue;
            }
            if (n.count > 0) {
                for (size_t i = n.first; i < n.first + n.count; ++i) {
                    if (boxes_[order_[i]].overlaps(query)) {
                        visit(order_[i]);
                    }
                }
            } else {
                stack.push_back(n.left);
                stack.push_back(n.left + 1);
            }
        }
    }

  private:
    struct Node {
        Aabb box;
        int left = -1;  // children at left and left + 1 when count == 0
        size_t first = 0, count = 0;
    };

    /// Fills node `slot` with the triangles order_[first, last); children of an inner
    /// node are stored next to each other.
    void build(int slot, size_t first, size_t last) {
        Aabb box;
        for (size_t i = first; i < last; ++i) {
            box.grow(boxes_[order_[i]]);
        }
        nodes_[slot].box = box;
        if (last - first <= 4) {
            nodes_[slot].first = first;
            nodes_[slot].count = last - first;
            return;
        }
        int axis = 0;
        (box.hi - box.lo).maxCoeff(&axis);
        const size_t mid = (first + last) / 2;
        std::nth_element(order_.begin() + first, order_.begin() + mid, order_.begin() + last,
                         [&](int x, int y) {
                             return boxes_[x].lo[axis] + boxes_[x].hi[axis] <
                                    boxes_[y].lo[axis] + boxes_[y].hi[axis];
                         });
        const int left = static_cast<int>(nodes_.size());
        nodes_.emplace_back();
        nodes_.emplace_back();
        nodes_[slot].left = left;
        build(left, first, mid);
        build(left + 1, mid, last);
    }

    const std::vector<Aabb>& boxes_;
    std::vector<int> order_;
    std::vector<Node> nodes_;
};

void validate(const MovingMesh& m) {
    if (m.start.size() != m.end.size()) {
        throw std::invalid_argument("meshCcd: start and end vertex counts differ");
    }
    for (const auto& tri : m.triangles) {
        for (int v : tri) {
            if (v < 0 || static_cast<size_t>(v) >= m.start.size()) {
                throw std::invalid_argument("meshCcd: triangle index out of range");
            }
        }
    }
}

/// Identifies one primitive test: (kind, feature of A, feature of B), each feature packed
/// into 64 bits (a vertex or triangle index, or an edge's two vertex indices).
using TestKey = std::pair<uint64_t, uint64_t>;

struct TestKeyHash {
    size_t operator()(const TestKey& k) const {
        return std::hash<uint64_t>()(k.first * 0x9E3779B97F4A7C15ull ^ k.second);
    }
};

/// The thesis's culling predicate: true when vertex v's motion relative to the triangle's
/// centroid does not point against the triangle's normal at t = 0.
bool facesAway(const MovingMesh& vm, int v, const MovingMesh& fm, const std::array<int, 3>& f) {
    const Vec3 n = (fm.start[f[1]] - fm.start[f[0]]).cross(fm.start[f[2]] - fm.start[f[0]]);
    const Vec3 face_motion = (fm.end[f[0]] + fm.end[f[1]] + fm.end[f[2]] - fm.start[f[0]] -
                              fm.start[f[1]] - fm.start[f[2]]) /
                             3.0;
    return n.dot((vm.end[v] - vm.start[v]) - face_motion) >= 0.0;
}

uint64_t pack(uint64_t x, uint64_t y) {
    return x << 32 | y;
}

TestKey vertexFaceKey(int kind, int vertex, int triangle) {
    return {pack(kind, static_cast<uint32_t>(vertex)), static_cast<uint32_t>(triangle)};
}

TestKey edgeEdgeKey(int a0, int a1, int b0, int b1) {
    return {pack(2ull << 30 | static_cast<uint32_t>(std::min(a0, a1)),
                 static_cast<uint32_t>(std::max(a0, a1))),
            pack(static_cast<uint32_t>(std::min(b0, b1)), static_cast<uint32_t>(std::max(b0, b1)))};
}

}  // namespace

MeshContact meshCcd(const MovingMesh& a, const MovingMesh& b, const MeshCcdSettings& settings) {
    validate(a);
    validate(b);
    std::vector<Aabb> boxes_b;
    boxes_b.reserve(b.triangles.size());
    for (const auto& tri : b.triangles) {
        boxes_b.push_back(sweptBox(b, tri));
    }
    const SweptBvh bvh(boxes_b);

    MeshContact best;
    // Once a contact is known, only earlier ones matter: the primitive tests search
    // [0, best.toi] (the earliest true contact is either found there or is later than a
    // reported toi, so the minimum stays no later than the truth).
    RobustSettings primitive = settings.primitive;
    // Vertices and edges are shared between triangles: test each primitive pair once.
    std::unordered_set<TestKey, TestKeyHash> tested;
    auto consider = [&](const CcdResult& r, ContactFeatures f, std::array<int, 2> fa,
                        std::array<int, 2> fb) {
        if (r.hit && (!best.hit || r.toi < best.toi)) {
            best.hit = true;
            best.toi = r.toi;
            primitive.max_time = std::min(primitive.max_time, r.toi);
            best.features = f;
            best.a = fa;
            best.b = fb;
        }
    };
    for (size_t ta = 0; ta < a.triangles.size(); ++ta) {
        const auto& tri_a = a.triangles[ta];
        bvh.query(sweptBox(a, tri_a), [&](int tb) {
            ++best.triangle_pairs;
            const auto& tri_b = b.triangles[tb];
            for (int i = 0; i < 3; ++i) {
                // Vertex of A against triangle of B, and vertex of B against triangle of A.
                if (tested.insert(vertexFaceKey(0, tri_a[i], tb)).second) {
                    const int v = tri_a[i];
                    if (settings.cull_back_facing && facesAway(a, v, b, tri_b)) {
                        ++best.culled;
                    } else {
                        ++best.primitive_queries;
                        VertexFaceQuery q{
                            {a.start[v], b.start[tri_b[0]], b.start[tri_b[1]], b.start[tri_b[2]]},
                            {a.end[v], b.end[tri_b[0]], b.end[tri_b[1]], b.end[tri_b[2]]}};
                        consider(vertexFaceRobust(q, primitive), ContactFeatures::kVertexAFaceB,
                                 {v, -1}, {tb, -1});
                    }
                }
                if (tested.insert(vertexFaceKey(1, tri_b[i], static_cast<int>(ta))).second) {
                    const int v = tri_b[i];
                    if (settings.cull_back_facing && facesAway(b, v, a, tri_a)) {
                        ++best.culled;
                    } else {
                        ++best.primitive_queries;
                        VertexFaceQuery q{
                            {b.start[v], a.start[tri_a[0]], a.start[tri_a[1]], a.start[tri_a[2]]},
                            {b.end[v], a.end[tri_a[0]], a.end[tri_a[1]], a.end[tri_a[2]]}};
                        consider(vertexFaceRobust(q, primitive), ContactFeatures::kFaceAVertexB,
                                 {static_cast<int>(ta), -1}, {v, -1});
                    }
                }
            }
            for (int i = 0; i < 3; ++i) {
                const int a0 = tri_a[i], a1 = tri_a[(i + 1) % 3];
                for (int j = 0; j < 3; ++j) {
                    const int b0 = tri_b[j], b1 = tri_b[(j + 1) % 3];
                    if (!tested.insert(edgeEdgeKey(a0, a1, b0, b1)).second) {
                        continue;
                    }
                    ++best.primitive_queries;
                    EdgeEdgeQuery q{{a.start[a0], a.start[a1], b.start[b0], b.start[b1]},
                                    {a.end[a0], a.end[a1], b.end[b0], b.end[b1]}};
                    consider(edgeEdgeRobust(q, primitive), ContactFeatures::kEdgeEdge, {a0, a1},
                             {b0, b1});
                }
            }
        });
    }
    return best;
}

}  // namespace kolize::ccd
