#include "kolize/narrowphase/mesh_ccd.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <stdexcept>
#include <unordered_set>
#include <utility>

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

/// What a mesh contributes to the primitive tests, limited to what can reach the other
/// mesh: each vertex used by a triangle, each edge once (shared edges are tested once), each
/// triangle, whose box over the whole step (inflated by the margin) meets `reach`, the
/// other mesh's box over the whole step (inflated). Every slice box lies in its feature's
/// whole-step box and every slice box of the other mesh in `reach`, so a feature left out
/// has no candidate pair in any slice: the candidate pairs are those of the whole meshes.
struct Features {
    std::vector<int> vertices;
    std::vector<std::array<int, 2>> edges;  ///< smaller vertex index first
    std::vector<int> triangles;             ///< indices into MovingMesh::triangles
    /// Each kept feature's box over the whole step (not inflated), in the lists' order;
    /// moved into the hierarchies.
    std::vector<Aabb> vertexBoxes, edgeBoxes, triangleBoxes;
    std::vector<int> touched;  ///< every vertex of a kept triangle (slice boxes)
    std::size_t left_out = 0;  ///< vertices and triangles not kept
};

Features collectFeatures(const MovingMesh& m, const Aabb& reach, double margin) {
    Features f;
    auto meets = [&](Aabb box) {
        box.lo.array() -= margin;
        box.hi.array() += margin;
        return box.overlaps(reach);
    };
    auto sweptBox = [&](std::initializer_list<int> vertices) {
        Aabb box;
        for (int v : vertices) {
            box.grow(m.start[v]);
            box.grow(m.end[v]);
        }
        return box;
    };
    std::vector<char> used(m.start.size(), 0);
    std::unordered_set<uint64_t> seen;
    for (size_t t = 0; t < m.triangles.size(); ++t) {
        const auto& tri = m.triangles[t];
        const Aabb triangleBox = sweptBox({tri[0], tri[1], tri[2]});
        if (!meets(triangleBox)) {
            ++f.left_out;
            for (int v : tri) {
                used[v] = used[v] == 1 ? 1 : 2;  // used by some triangle, maybe not kept
            }
            continue;  // nor can its edges and vertices (their boxes lie in its box)
        }
        f.triangles.push_back(static_cast<int>(t));
        f.triangleBoxes.push_back(triangleBox);
        for (int i = 0; i < 3; ++i) {
            used[tri[i]] = 1;
            const int lo = std::min(tri[i], tri[(i + 1) % 3]);
            const int hi = std::max(tri[i], tri[(i + 1) % 3]);
            if (lo == hi) {
                continue;
            }
            const Aabb edgeBox = sweptBox({lo, hi});
            if (meets(edgeBox) &&
                seen.insert(static_cast<uint64_t>(lo) << 32 | static_cast<uint32_t>(hi)).second) {
                f.edges.push_back({lo, hi});
                f.edgeBoxes.push_back(edgeBox);
            }
        }
    }
    for (size_t v = 0; v < used.size(); ++v) {
        if (used[v] == 1) {
            f.touched.push_back(static_cast<int>(v));
            const Aabb vertexBox = sweptBox({static_cast<int>(v)});
            if (meets(vertexBox)) {
                f.vertices.push_back(static_cast<int>(v));
                f.vertexBoxes.push_back(vertexBox);
                continue;
            }
        }
        f.left_out += used[v] != 0 ? 1 : 0;
    }
    return f;
}

/// Binary hierarchy over boxes that change from one time slice to the next: the topology
/// is built once (median split on the longest axis of the boxes over the whole step) and
/// only the node boxes are recomputed per slice, bottom-up.
class SliceBvh {
  public:
    explicit SliceBvh(std::vector<Aabb> whole_step) : leaf_boxes_(std::move(whole_step)) {
        order_.resize(leaf_boxes_.size());
        for (size_t i = 0; i < order_.size(); ++i) {
            order_[i] = static_cast<int>(i);
        }
        if (!order_.empty()) {
            nodes_.emplace_back();
            build(0, 0, order_.size());
        }
    }

    /// Leaf i's box for the current slice; call refit() after setting them all.
    Aabb& leaf(size_t i) { return leaf_boxes_[i]; }

    /// Recomputes the node boxes from the leaf boxes. Children are stored after their
    /// parent, so one backward pass sees every child before its parent.
    void refit() {
        for (size_t n = nodes_.size(); n-- > 0;) {
            Node& node = nodes_[n];
            node.box = Aabb();
            if (node.count > 0) {
                for (size_t i = node.first; i < node.first + node.count; ++i) {
                    node.box.grow(leaf_boxes_[order_[i]]);
                }
            } else {
                node.box.grow(nodes_[node.left].box);
                node.box.grow(nodes_[node.left + 1].box);
            }
        }
    }

    bool empty() const { return nodes_.empty(); }
    const Aabb& bounds() const { return nodes_.front().box; }

    /// Calls visit(i, j) for every leaf i of `a` and leaf j of `b` whose boxes overlap,
    /// by descending both hierarchies together.
    template <class Visit>
    static void overlapping(const SliceBvh& a, const SliceBvh& b, Visit visit) {
        if (a.empty() || b.empty()) {
            return;
        }
        std::vector<std::pair<int, int>> stack{{0, 0}};
        while (!stack.empty()) {
            const auto [ia, ib] = stack.back();
            stack.pop_back();
            const Node& na = a.nodes_[ia];
            const Node& nb = b.nodes_[ib];
            if (!na.box.overlaps(nb.box)) {
                continue;
            }
            if (na.count > 0 && nb.count > 0) {
                for (size_t i = na.first; i < na.first + na.count; ++i) {
                    const int leaf_a = a.order_[i];
                    const Aabb& box_a = a.leaf_boxes_[leaf_a];
                    if (!box_a.overlaps(nb.box)) {
                        continue;
                    }
                    for (size_t j = nb.first; j < nb.first + nb.count; ++j) {
                        const int leaf_b = b.order_[j];
                        if (box_a.overlaps(b.leaf_boxes_[leaf_b])) {
                            visit(leaf_a, leaf_b);
                        }
                    }
                }
            } else if (nb.count > 0 || (na.count == 0 && na.size >= nb.size)) {
                stack.push_back({na.left, ib});  // descend the larger inner node
                stack.push_back({na.left + 1, ib});
            } else {
                stack.push_back({ia, nb.left});
                stack.push_back({ia, nb.left + 1});
            }
        }
    }

  private:
    struct Node {
        Aabb box;
        int left = -1;  // children at left and left + 1 when count == 0
        size_t first = 0, count = 0, size = 0;
    };

    void build(size_t slot, size_t first, size_t last) {
        Aabb box;
        for (size_t i = first; i < last; ++i) {
            box.grow(leaf_boxes_[order_[i]]);
        }
        nodes_[slot].box = box;
        nodes_[slot].size = last - first;
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
                             return leaf_boxes_[x].lo[axis] + leaf_boxes_[x].hi[axis] <
                                    leaf_boxes_[y].lo[axis] + leaf_boxes_[y].hi[axis];
                         });
        const int left = static_cast<int>(nodes_.size());
        nodes_.emplace_back();
        nodes_.emplace_back();
        nodes_[slot].left = left;
        build(left, first, mid);
        build(left + 1, mid, last);
    }

    std::vector<Aabb> leaf_boxes_;
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

/// The thesis's culling predicate: true when vertex v's motion relative to the triangle's
/// centroid does not point against the triangle's normal at t = 0.
bool facesAway(const MovingMesh& vm, int v, const MovingMesh& fm, const std::array<int, 3>& f) {
    const Vec3 n = (fm.start[f[1]] - fm.start[f[0]]).cross(fm.start[f[2]] - fm.start[f[0]]);
    const Vec3 face_motion = (fm.end[f[0]] + fm.end[f[1]] + fm.end[f[2]] - fm.start[f[0]] -
                              fm.start[f[1]] - fm.start[f[2]]) /
                             3.0;
    return n.dot((vm.end[v] - vm.start[v]) - face_motion) >= 0.0;
}

/// One mesh's features with a hierarchy per kind, and their boxes for a time slice.
class SlicedMesh {
  public:
    SlicedMesh(const MovingMesh& m, double margin, const Aabb& reach)
        : mesh_(m),
          features_(collectFeatures(m, reach, margin)),
          margin_(margin),
          vertices_(std::move(features_.vertexBoxes)),  // the features keep their lists only
          edges_(std::move(features_.edgeBoxes)),
          triangles_(std::move(features_.triangleBoxes)) {
        at0_.resize(m.start.size());
        at1_.resize(m.start.size());
    }

    /// Vertex positions at t0 and t1, and the box around them all (inflated).
    Aabb positions(double t0, double t1) {
        Aabb all;
        for (int v : features_.touched) {
            at0_[v] = mesh_.start[v] + t0 * (mesh_.end[v] - mesh_.start[v]);
            at1_[v] = mesh_.start[v] + t1 * (mesh_.end[v] - mesh_.start[v]);
            all.grow(at0_[v]);
            all.grow(at1_[v]);
        }
        inflate(all);
        return all;
    }

    /// Leaf boxes of every hierarchy for the slice whose positions() were computed last.
    void refit() {
        for (size_t i = 0; i < features_.vertices.size(); ++i) {
            Aabb& b = vertices_.leaf(i) = Aabb();
            slice(features_.vertices[i], b);
            inflate(b);
        }
        vertices_.refit();
        for (size_t i = 0; i < features_.edges.size(); ++i) {
            Aabb& b = edges_.leaf(i) = Aabb();
            slice(features_.edges[i][0], b);
            slice(features_.edges[i][1], b);
            inflate(b);
        }
        edges_.refit();
        for (size_t i = 0; i < features_.triangles.size(); ++i) {
            Aabb& b = triangles_.leaf(i) = Aabb();
            for (int v : mesh_.triangles[features_.triangles[i]]) {
                slice(v, b);
            }
            inflate(b);
        }
        triangles_.refit();
    }

    const MovingMesh& mesh() const { return mesh_; }
    const Features& features() const { return features_; }
    const SliceBvh& vertices() const { return vertices_; }
    const SliceBvh& edges() const { return edges_; }
    const SliceBvh& triangles() const { return triangles_; }

  private:
    void slice(int v, Aabb& b) const {
        b.grow(at0_[v]);
        b.grow(at1_[v]);
    }
    void inflate(Aabb& b) const {
        b.lo.array() -= margin_;
        b.hi.array() += margin_;
    }

    const MovingMesh& mesh_;
    Features features_;
    double margin_;
    SliceBvh vertices_, edges_, triangles_;
    std::vector<Vec3> at0_, at1_;
};

/// Time slices: enough that a slice moves the fastest vertex pair by about one mean edge
/// length (a power of two, so slice ends are exact doubles), at most `limit`.
int sliceCount(const MovingMesh& a, const MovingMesh& b, int limit) {
    auto largestMotion = [](const MovingMesh& m) {
        double d = 0.0;
        for (size_t v = 0; v < m.start.size(); ++v) {
            d = std::max(d, (m.end[v] - m.start[v]).norm());
        }
        return d;
    };
    double edge_sum = 0.0;
    size_t edge_count = 0;
    for (const MovingMesh* m : {&a, &b}) {
        for (const auto& tri : m->triangles) {
            for (int i = 0; i < 3; ++i) {
                edge_sum += (m->start[tri[i]] - m->start[tri[(i + 1) % 3]]).norm();
                ++edge_count;
            }
        }
    }
    const double edge = edge_count ? edge_sum / edge_count : 0.0;
    const double motion = largestMotion(a) + largestMotion(b);
    int slices = 1;
    while (2 * slices <= limit && motion > slices * edge) {
        slices *= 2;
    }
    return slices;
}

}  // namespace

MeshContact meshCcd(const MovingMesh& a, const MovingMesh& b, const MeshCcdSettings& settings) {
    validate(a);
    validate(b);
    // Slice boxes come from positions x0 + t (x1 - x0) rounded to doubles: inflating every
    // box by a few units in the last place of the largest coordinate keeps it around the
    // exact positions, so the culling never drops a pair that touches.
    // Each mesh's box over the whole step (inflated below): the other's reach.
    Aabb reach[2];
    for (int k = 0; k < 2; ++k) {
        const MovingMesh& m = k == 0 ? a : b;
        for (size_t v = 0; v < m.start.size(); ++v) {
            reach[k].grow(m.start[v]);
            reach[k].grow(m.end[v]);
        }
    }
    double largest = 0.0;
    for (const Aabb& box : reach) {
        if (box.lo.x() <= box.hi.x()) {  // not empty
            largest =
                std::max({largest, box.lo.cwiseAbs().maxCoeff(), box.hi.cwiseAbs().maxCoeff()});
        }
    }
    const double margin = 8.0 * 0x1p-53 * largest + std::numeric_limits<double>::min();
    for (Aabb& box : reach) {
        box.lo.array() -= margin;
        box.hi.array() += margin;
    }
    SlicedMesh sa(a, margin, reach[1]), sb(b, margin, reach[0]);
    MeshContact best;
    best.out_of_reach = sa.features().left_out + sb.features().left_out;
    const int slices = sliceCount(a, b, settings.max_time_slices);

    RobustSettings primitive = settings.primitive;
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
    // Slices in time order: the first slice with a contact holds the earliest one, and
    // every test is limited to its slice, where its features' boxes overlap.
    const double t_begin = std::clamp(settings.primitive.min_time, 0.0, 1.0);
    const double t_end = std::clamp(settings.primitive.max_time, t_begin, 1.0);
    for (int s = 0; s < slices && !best.hit; ++s) {
        const double t0 = std::max(t_begin, double(s) / slices);
        const double t1 = std::min(t_end, double(s + 1) / slices);
        if (t1 < t0 || (t1 == t0 && best.time_slices > 0)) {
            continue;  // outside [t_begin, t_end], or its end instant, already covered
        }
        ++best.time_slices;
        if (!sa.positions(t0, t1).overlaps(sb.positions(t0, t1))) {
            continue;
        }
        sa.refit();
        sb.refit();
        primitive.min_time = t0;
        primitive.max_time = t1;
        // Vertex of A against triangle of B, and triangle of A against vertex of B.
        SliceBvh::overlapping(sa.vertices(), sb.triangles(), [&](int i, int leaf) {
            ++best.candidate_pairs;
            const int v = sa.features().vertices[i];
            const int tb = sb.features().triangles[leaf];
            const auto& tri = b.triangles[tb];
            if (settings.cull_back_facing && facesAway(a, v, b, tri)) {
                ++best.culled;
                return;
            }
            ++best.primitive_queries;
            const VertexFaceQuery q{{a.start[v], b.start[tri[0]], b.start[tri[1]], b.start[tri[2]]},
                                    {a.end[v], b.end[tri[0]], b.end[tri[1]], b.end[tri[2]]}};
            consider(vertexFaceRobust(q, primitive), ContactFeatures::kVertexAFaceB, {v, -1},
                     {tb, -1});
        });
        SliceBvh::overlapping(sa.triangles(), sb.vertices(), [&](int leaf, int j) {
            ++best.candidate_pairs;
            const int v = sb.features().vertices[j];
            const int ta = sa.features().triangles[leaf];
            const auto& tri = a.triangles[ta];
            if (settings.cull_back_facing && facesAway(b, v, a, tri)) {
                ++best.culled;
                return;
            }
            ++best.primitive_queries;
            const VertexFaceQuery q{{b.start[v], a.start[tri[0]], a.start[tri[1]], a.start[tri[2]]},
                                    {b.end[v], a.end[tri[0]], a.end[tri[1]], a.end[tri[2]]}};
            consider(vertexFaceRobust(q, primitive), ContactFeatures::kFaceAVertexB, {ta, -1},
                     {v, -1});
        });
        SliceBvh::overlapping(sa.edges(), sb.edges(), [&](int i, int j) {
            ++best.candidate_pairs;
            ++best.primitive_queries;
            const auto& ea = sa.features().edges[i];
            const auto& eb = sb.features().edges[j];
            const EdgeEdgeQuery q{{a.start[ea[0]], a.start[ea[1]], b.start[eb[0]], b.start[eb[1]]},
                                  {a.end[ea[0]], a.end[ea[1]], b.end[eb[0]], b.end[eb[1]]}};
            consider(edgeEdgeRobust(q, primitive), ContactFeatures::kEdgeEdge, ea, eb);
        });
    }
    return best;
}

}  // namespace kolize::ccd
