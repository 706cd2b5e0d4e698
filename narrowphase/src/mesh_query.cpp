#include "kolize/narrowphase/mesh_query.h"

#include "bv_internal.h"
#include "pose_internal.h"
#include "triangle_test_internal.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace kolize::narrowphase {

namespace {

/// A node pair to visit, with the axis that separated it last time (kNoAxis: none), packed
/// into one 8-byte word: A's node in bits 0-29, B's in 30-59, the axis in 60-63 (trees hold
/// fewer than 2^29 nodes). The traversal stack then writes and reads whole words; a
/// 12-byte struct written field by field and read back in one load defeated the CPU's
/// store-to-load forwarding and cost about a quarter of the traversal's time.
class NodePair {
  public:
    NodePair() = default;
    NodePair(std::int32_t a, std::int32_t b, int axis)
        : bits_(std::uint64_t(a) | (std::uint64_t(b) << 30) | (std::uint64_t(axis) << 60)) {}
    std::int32_t a() const { return std::int32_t(bits_ & kMask); }
    std::int32_t b() const { return std::int32_t((bits_ >> 30) & kMask); }
    int axis() const { return int(bits_ >> 60); }

  private:
    static constexpr std::uint64_t kMask = (std::uint64_t(1) << 30) - 1;
    std::uint64_t bits_ = 0;
};

Vec3 unitNormal(const Triangle& t) {
    const Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]);
    const double length = n.norm();
    return length > 0 ? Vec3(n / length) : Vec3::Zero();
}

/// A triangle's unitNormal, computed on first use: a leaf's triangle meets several of the
/// other leaf's, and a contact needs both normals.
class LazyNormal {
  public:
    LazyNormal() = default;
    explicit LazyNormal(const Triangle& t) : t_(&t) {}
    const Vec3& get() {
        if (!known_) {
            normal_ = unitNormal(*t_);
            known_ = true;
        }
        return normal_;
    }

  private:
    const Triangle* t_ = nullptr;
    Vec3 normal_ = Vec3::Zero();
    bool known_ = false;
};

/// A triangle's plane for the exact test (detail::PlaneSide), built on first use: a
/// triangle meets several of the other mesh's in one query.
class LazyPlane {
  public:
    LazyPlane() = default;
    explicit LazyPlane(const Triangle& t) : t_(&t) {}
    void reset(const Triangle& t) {
        t_ = &t;
        known_ = false;
    }
    const detail::PlaneSide& get() {
        if (!known_) {
            plane_ = detail::PlaneSide((*t_)[0], (*t_)[1], (*t_)[2]);
            known_ = true;
        }
        return plane_;
    }

  private:
    const Triangle* t_ = nullptr;
    detail::PlaneSide plane_;
    bool known_ = false;
};

/// What the leaf tests keep of one triangle: its vertices' normal and plane, on first use.
struct LazyTriangle {
    LazyTriangle() = default;
    explicit LazyTriangle(const Triangle& t) : normal(t), plane(t) {}
    /// For triangle t, nothing known yet (reuses the memory of a kept entry).
    void reset(const Triangle& t) {
        normal = LazyNormal(t);
        plane.reset(t);
    }
    LazyNormal normal;
    LazyPlane plane;
};

}  // namespace

struct MeshQuery::Front {
    const void* nodesA = nullptr;  // identity of the trees the entries index
    const void* nodesB = nullptr;
    std::size_t countA = 0, countB = 0;
    Descent descent = Descent::kLarger;
    std::vector<NodePair> entries;
    std::size_t rootSize = 0;  // front size after the last start from the roots
    int sinceRoot = 0;         // front starts since then
};

struct QueryScratch::Impl {
    std::uint32_t stamp = 0;
    std::vector<Vec3> vertices;  // B's vertices in A's frame
    std::vector<std::uint32_t> vertexStamp;
    std::vector<detail::ObbInFrame> obbNodes;  // B's OBB nodes in A's frame, tagged by stamp
    std::vector<Kdop<6>> kdop6;                // B's k-DOP tree refit in A's frame
    std::vector<Kdop<14>> kdop14;
    std::vector<Kdop<18>> kdop18;
    std::vector<Kdop<26>> kdop26;
    std::vector<NodePair> stack;
    std::vector<NodePair> nextFront;
    std::vector<Triangle> directTriangles;  // B's triangles in A's frame (no-tree queries)
    std::vector<LazyTriangle> directLazy;   // their unit normals and planes, on first use
    std::vector<double> directBoxes;        // their boxes: lo x, y, z, hi x, y, z runs
    std::vector<std::int32_t> directMet;    // the B triangles whose boxes meet A's

    std::uint32_t nextStamp() {
        if (++stamp == 0) {  // wrapped: forget every old stamp once every 2^32 queries
            std::fill(vertexStamp.begin(), vertexStamp.end(), 0);
            for (detail::ObbInFrame& node : obbNodes) {
                node.setTag(0);
            }
            stamp = 1;
        }
        return stamp;
    }

    template <int K>
    std::vector<Kdop<K>>& kdops() {
        if constexpr (K == 6) {
            return kdop6;
        } else if constexpr (K == 14) {
            return kdop14;
        } else if constexpr (K == 18) {
            return kdop18;
        } else {
            return kdop26;
        }
    }
};

QueryScratch::QueryScratch() : impl_(std::make_unique<Impl>()) {}
QueryScratch::~QueryScratch() = default;

namespace {

/// Everything one query needs, shared by the traversal and the leaf tests.
struct Context {
    const MeshModel& a;
    const MeshModel& b;
    const QuerySettings& settings;
    Eigen::Matrix3d rotation;  // B in A's frame
    Vec3 translation;
    double slack;  // absolute position error bound (pose and centre roundings), plus the margin
    float slackFloat;
    double margin;  // QuerySettings::margin in kContacts mode, else 0
    QueryScratch::Impl& scratch;
    std::uint32_t stamp;
    QueryResult& result;
    QueryCounters counters;  // copied into result at the end (kept out of the result's memory)
    bool stop = false;

    const Vec3& vertexB(std::int32_t index) {
        if (scratch.vertexStamp[index] != stamp) {
            scratch.vertexStamp[index] = stamp;
            scratch.vertices[index] =
                detail::applyFixedOrder(rotation, translation, b.mesh().vertices()[index]);
            ++counters.vertices_transformed;
        }
        return scratch.vertices[index];
    }
};

/// One triangle pair whose boxes overlap: facing filter, exact test; records a hit under the
/// mesh triangle indices (ia, ib). Each triangle's plane is built once per query (lazyP,
/// lazyQ). Returns false when a yes/no query must stop.
bool exactPair(Context& c, const Triangle& p, LazyTriangle& lazyP, const Triangle& q,
               LazyTriangle& lazyQ, std::int32_t ia, std::int32_t ib) {
    if (c.settings.facing_filter) {
        const Vec3 na = (p[1] - p[0]).cross(p[2] - p[0]);
        const Vec3 nb = (q[1] - q[0]).cross(q[2] - q[0]);
        if (!(nb.dot(c.settings.motion) > 0) || !(na.dot(c.settings.motion) < 0)) {
            ++c.counters.facing_culled;
            return true;
        }
    }
    ++c.counters.triangle_tests;
    const QueryMode mode = c.settings.mode;
    PredicateStats* stats = &c.counters.predicates;
    bool hit;
    TriangleIntersection geometry;
    if (mode == QueryMode::kContacts) {
        hit = detail::triangleIntersection(p, lazyP.plane.get(), q, lazyQ.plane.get(), geometry,
                                           stats);
    } else {
        hit = detail::trianglesIntersect(p, lazyP.plane.get(), q, lazyQ.plane.get(), stats);
    }
    if (!hit) {
        if (c.margin > 0 && c.result.pairs.empty()) {  // near pairs only while apart
            const TriangleDistance d = triangleDistance(p, q);
            if (d.distance <= c.margin) {
                c.result.near.push_back({TrianglePair{ia, ib}, d.distance, d.on_p, d.on_q});
            }
        }
        return true;
    }
    const TrianglePair pair{ia, ib};
    c.result.pairs.push_back(pair);
    ++c.counters.pairs;
    if (mode == QueryMode::kContacts) {
        c.result.contacts.push_back({pair, geometry, lazyP.normal.get(), lazyQ.normal.get()});
    }
    if (mode == QueryMode::kYesNo) {
        c.stop = true;
        return false;
    }
    return true;
}

/// B's triangles' boxes, coordinate by coordinate (lo x, y, z, hi x, y, z runs of `stride`),
/// for a box test of one A triangle against all of them without a branch.
struct BoxRuns {
    const double* lo[3];
    const double* hi[3];
    BoxRuns(const double* boxes, std::size_t stride) {
        for (int k = 0; k < 3; ++k) {
            lo[k] = boxes + k * stride;
            hi[k] = boxes + (3 + k) * stride;
        }
    }
    /// Writes to `met` the j < count whose boxes meet [plo, phi] widened by `m` (closed
    /// boxes: apart only when one lies beyond the other along an axis), returns how many.
    std::size_t meeting(const Vec3& plo, const Vec3& phi, double m, std::size_t count,
                        std::int32_t* met) const {
        std::size_t metCount = 0;
        for (std::size_t j = 0; j < count; ++j) {
            const bool apart = (plo.x() - m > hi[0][j]) | (plo.y() - m > hi[1][j]) |
                               (plo.z() - m > hi[2][j]) | (lo[0][j] - m > phi.x()) |
                               (lo[1][j] - m > phi.y()) | (lo[2][j] - m > phi.z());
            met[metCount] = std::int32_t(j);
            metCount += apart ? 0 : 1;
        }
        return metCount;
    }
};

/// A triangle's box outside [lo, hi] widened by `m`: it meets none of the boxes inside.
bool outside(const Vec3& plo, const Vec3& phi, const Vec3& lo, const Vec3& hi, double m) {
    return (plo.array() - m > hi.array()).any() || (lo.array() - m > phi.array()).any();
}

/// Every triangle pair of a leaf pair.
template <class Node>
void leafPair(Context& c, const BvTree<Node>& ta, const BvTree<Node>& tb, std::int32_t firstA,
              int countA, const NodeLink& lb) {
    ++c.counters.leaf_pairs;
    constexpr int kMax = 8;  // BvTree's largest leaf
    Triangle qs[kMax];
    double boxes[6 * kMax];
    LazyTriangle nq[kMax] = {LazyTriangle(qs[0]), LazyTriangle(qs[1]), LazyTriangle(qs[2]),
                             LazyTriangle(qs[3]), LazyTriangle(qs[4]), LazyTriangle(qs[5]),
                             LazyTriangle(qs[6]), LazyTriangle(qs[7])};
    const int countB = lb.count();
    Vec3 allLo = Vec3::Constant(std::numeric_limits<double>::infinity());
    Vec3 allHi = -allLo;
    for (int j = 0; j < countB; ++j) {
        const Index3& t = tb.slotTriangles()[lb.firstSlot() + j];
        for (int k = 0; k < 3; ++k) {
            qs[j][k] = c.vertexB(t[k]);
        }
        const Vec3 lo = qs[j][0].cwiseMin(qs[j][1]).cwiseMin(qs[j][2]);
        const Vec3 hi = qs[j][0].cwiseMax(qs[j][1]).cwiseMax(qs[j][2]);
        allLo = allLo.cwiseMin(lo);
        allHi = allHi.cwiseMax(hi);
        for (int k = 0; k < 3; ++k) {
            boxes[k * kMax + j] = lo[k];
            boxes[(3 + k) * kMax + j] = hi[k];
        }
    }
    const BoxRuns runs(boxes, kMax);
    const double m = c.margin;
    std::int32_t met[kMax];
    const std::vector<Vec3>& va = c.a.mesh().vertices();
    for (int i = 0; i < countA; ++i) {
        const std::int32_t slotA = firstA + i;
        const Index3& ti = ta.slotTriangles()[slotA];
        const Triangle p = {va[ti[0]], va[ti[1]], va[ti[2]]};
        const Vec3 plo = p[0].cwiseMin(p[1]).cwiseMin(p[2]);
        const Vec3 phi = p[0].cwiseMax(p[1]).cwiseMax(p[2]);
        if (outside(plo, phi, allLo, allHi, m)) {
            c.counters.triangle_box_rejects += std::uint64_t(countB);
            continue;
        }
        const std::size_t metCount = runs.meeting(plo, phi, m, std::size_t(countB), met);
        c.counters.triangle_box_rejects += std::uint64_t(countB) - metCount;
        LazyTriangle np(p);
        for (std::size_t k = 0; k < metCount; ++k) {
            const std::int32_t j = met[k];
            if (!exactPair(c, p, np, qs[j], nq[j], ta.triangleOrder()[slotA],
                           tb.triangleOrder()[lb.firstSlot() + j])) {
                return;
            }
        }
    }
}

/// Without trees (QuerySettings::use_tree off): every triangle of A against every triangle
/// of B, in mesh order. The same per-pair tests as leafPair, so the same pairs.
void directPairs(Context& c) {
    const TriangleMesh& ma = c.a.mesh();
    const TriangleMesh& mb = c.b.mesh();
    const std::size_t countB = mb.triangleCount();
    std::vector<Triangle>& qs = c.scratch.directTriangles;
    std::vector<LazyTriangle>& nq = c.scratch.directLazy;
    std::vector<double>& boxes = c.scratch.directBoxes;
    std::vector<std::int32_t>& met = c.scratch.directMet;
    qs.resize(countB);
    nq.resize(countB);
    boxes.resize(6 * countB);
    met.resize(countB);
    // B's whole box in A's frame, widened by the margin: an A triangle outside it meets no
    // B triangle's box (the per-pair test below would reject each pair in turn).
    Vec3 allLo = Vec3::Constant(std::numeric_limits<double>::infinity());
    Vec3 allHi = -allLo;
    for (std::size_t j = 0; j < countB; ++j) {
        const Index3& t = mb.triangles()[j];
        for (int k = 0; k < 3; ++k) {
            qs[j][k] = c.vertexB(t[k]);
        }
        const Vec3 lo = qs[j][0].cwiseMin(qs[j][1]).cwiseMin(qs[j][2]);
        const Vec3 hi = qs[j][0].cwiseMax(qs[j][1]).cwiseMax(qs[j][2]);
        allLo = allLo.cwiseMin(lo);
        allHi = allHi.cwiseMax(hi);
        nq[j].reset(qs[j]);
        for (int k = 0; k < 3; ++k) {
            boxes[k * countB + j] = lo[k];
            boxes[(3 + k) * countB + j] = hi[k];
        }
    }
    const BoxRuns runs(boxes.data(), countB);
    const double m = c.margin;
    const std::vector<Vec3>& va = ma.vertices();
    for (std::size_t i = 0; i < ma.triangleCount(); ++i) {
        const Index3& ti = ma.triangles()[i];
        const Triangle p = {va[ti[0]], va[ti[1]], va[ti[2]]};
        const Vec3 plo = p[0].cwiseMin(p[1]).cwiseMin(p[2]);
        const Vec3 phi = p[0].cwiseMax(p[1]).cwiseMax(p[2]);
        if (outside(plo, phi, allLo, allHi, m)) {
            c.counters.triangle_box_rejects += countB;
            continue;
        }
        // The box test of every B triangle without a branch, then the exact test of those
        // that met.
        const std::size_t metCount = runs.meeting(plo, phi, m, countB, met.data());
        c.counters.triangle_box_rejects += countB - metCount;
        LazyTriangle np(p);
        for (std::size_t k = 0; k < metCount; ++k) {
            const std::int32_t j = met[k];
            if (!exactPair(c, p, np, qs[j], nq[j], std::int32_t(i), j)) {
                return;
            }
        }
    }
}

/// Kind-specific node-pair tests. separated() returns the separating axis (>= 0) or -1.

struct ObbOps {
    ObbOps(Context& context, const ObbNode* a, const ObbNode* b) : c(context), na(a), nb(b) {}
    Context& c;
    const ObbNode* na;
    const ObbNode* nb;
    // Counted here, in the traversal's own frame, and added to the context at the end.
    std::uint64_t sphereTests = 0, sphereRejects = 0, boxTests = 0, boxRejects = 0;
    void prepare() {
        QueryScratch::Impl& s = c.scratch;
        const std::size_t count = c.b.nodeCount();
        if (s.obbNodes.size() < count) {
            s.obbNodes.resize(count);  // value-initialized: tag 0, never a live stamp
        }
    }
    void finish() {
        c.counters.node_sphere_tests += sphereTests;
        c.counters.node_sphere_rejects += sphereRejects;
        c.counters.bv_tests += boxTests;
        c.counters.bv_rejects += boxRejects;
    }
    const detail::ObbInFrame& moved(std::int32_t ib) {
        QueryScratch::Impl& s = c.scratch;
        detail::ObbInFrame& entry = s.obbNodes[ib];
        if (entry.tag() != c.stamp) {
            entry = detail::moveObb(nb[ib].volume, c.rotation, c.translation);
            entry.setTag(c.stamp);
        }
        return entry;
    }
    /// Asks for the memory a later separated(ia, ib) reads: B's node and its moved copy
    /// (each may straddle two cache lines). A front's pairs visit B's nodes in no memory
    /// order, and those loads, not the arithmetic, dominated the traversal's time.
    void prefetch(std::int32_t ia, std::int32_t ib) {
        const char* moved = reinterpret_cast<const char*>(&c.scratch.obbNodes[ib]);
        const char* node = reinterpret_cast<const char*>(&nb[ib]);
        __builtin_prefetch(moved);
        __builtin_prefetch(moved + sizeof(detail::ObbInFrame) - 1);
        __builtin_prefetch(node);
        __builtin_prefetch(node + sizeof(ObbNode) - 1);
        __builtin_prefetch(&na[ia]);
    }
    /// Squared distance of the two nodes' centres, for the yes/no descent order.
    double distance2(std::int32_t ia, std::int32_t ib) {
        const Vec3f& ca = na[ia].volume.center;
        const Vec3& cb = moved(ib).center;
        const double dx = cb.x() - ca.x(), dy = cb.y() - ca.y(), dz = cb.z() - ca.z();
        return (dx * dx + dy * dy) + dz * dz;
    }
    static constexpr bool kOrdersChildren = true;
    int separated(std::int32_t ia, std::int32_t ib, int hint) {
        const Obb& boxA = na[ia].volume;
        const detail::ObbInFrame& boxB = moved(ib);
        // Scalars, not an Eigen temporary: see NodePair on store-to-load forwarding.
        const double dx = boxB.center.x() - double(boxA.center.x());
        const double dy = boxB.center.y() - double(boxA.center.y());
        const double dz = boxB.center.z() - double(boxA.center.z());
        if (c.settings.sphere_pretest) {
            ++sphereTests;
            if (detail::spheresDisjoint(dx, dy, dz, boxA.radius, boxB.radius, c.slack)) {
                ++sphereRejects;
                return detail::kNoAxis;
            }
        }
        ++boxTests;
        const int axis = detail::obbSeparatingAxis(boxA, detail::crossFloat(boxA.axis0, boxA.axis1),
                                                   boxB, dx, dy, dz, c.slackFloat, hint);
        if (axis != detail::kNoAxis) {
            ++boxRejects;
            return axis;
        }
        return -1;
    }
};

struct SphereOps {
    static constexpr bool kOrdersChildren = false;
    void prefetch(std::int32_t, std::int32_t) {}
    double distance2(std::int32_t, std::int32_t) { return 0; }
    SphereOps(Context& context, const SphereNode* a, const SphereNode* b)
        : c(context), na(a), nb(b) {}
    Context& c;
    const SphereNode* na;
    const SphereNode* nb;
    void prepare() {}
    void finish() {}
    int separated(std::int32_t ia, std::int32_t ib, int) {
        ++c.counters.bv_tests;
        const Vec3 cb =
            detail::applyFixedOrder(c.rotation, c.translation, nb[ib].volume.center.cast<double>());
        if (detail::spheresDisjoint(cb - na[ia].volume.center.cast<double>(), na[ia].volume.radius,
                                    nb[ib].volume.radius, c.slack)) {
            ++c.counters.bv_rejects;
            return 0;
        }
        return -1;
    }
};

struct AabbOps {
    static constexpr bool kOrdersChildren = false;
    void prefetch(std::int32_t, std::int32_t) {}
    double distance2(std::int32_t, std::int32_t) { return 0; }
    AabbOps(Context& context, const AabbNode* a, const AabbNode* b) : c(context), na(a), nb(b) {}
    Context& c;
    const AabbNode* na;
    const AabbNode* nb;
    Eigen::Matrix3d absR;
    void prepare() { absR = c.rotation.cwiseAbs(); }
    void finish() {}
    int separated(std::int32_t ia, std::int32_t ib, int) {
        ++c.counters.bv_tests;
        const Aabb& x = na[ia].volume;
        const Aabb& y = nb[ib].volume;
        const Vec3 ca = 0.5 * (x.lo.cast<double>() + x.hi.cast<double>());
        const Vec3 ea = 0.5 * (x.hi.cast<double>() - x.lo.cast<double>());
        const Vec3 cb = detail::applyFixedOrder(c.rotation, c.translation,
                                                0.5 * (y.lo.cast<double>() + y.hi.cast<double>()));
        const Vec3 eb = 0.5 * (y.hi.cast<double>() - y.lo.cast<double>());
        if (detail::aabbsDisjoint(ca, ea, cb, eb, c.rotation, absR, c.slack)) {
            ++c.counters.bv_rejects;
            return 0;
        }
        return -1;
    }
};

template <int K>
struct KdopOps {
    static constexpr bool kOrdersChildren = false;
    void prefetch(std::int32_t, std::int32_t) {}
    double distance2(std::int32_t, std::int32_t) { return 0; }
    KdopOps(Context& context, const KdopNode<K>* a, const KdopNode<K>* b)
        : c(context), na(a), nb(b) {}
    Context& c;
    const KdopNode<K>* na;
    const KdopNode<K>* nb;
    const Kdop<K>* refit = nullptr;
    /// B's tree refit in A's frame from all of B's vertices (a k-DOP cannot be rotated).
    void prepare() {
        const BvTree<KdopNode<K>>& tb = c.b.template tree<KdopNode<K>>();
        std::vector<Kdop<K>>& out = c.scratch.template kdops<K>();
        const std::int32_t count = std::int32_t(tb.nodes().size());
        if (out.size() < std::size_t(count)) {
            out.resize(count);
        }
        for (std::int32_t i = count - 1; i >= 0; --i) {
            const NodeLink link = tb.nodes()[i].link;
            if (link.isLeaf()) {
                detail::KdopAccumulator<K> acc;
                for (int s = 0; s < link.count(); ++s) {
                    const Index3& t = tb.slotTriangles()[link.firstSlot() + s];
                    for (int k = 0; k < 3; ++k) {
                        acc.add(c.vertexB(t[k]));
                    }
                }
                out[i] = acc.rounded();
            } else {
                out[i] = out[i + 1];
                detail::unite(out[i], out[link.right()]);
            }
        }
        refit = out.data();
    }
    void finish() {}
    int separated(std::int32_t ia, std::int32_t ib, int) {
        ++c.counters.bv_tests;
        if (detail::kdopsDisjoint(na[ia].volume, refit[ib])) {
            ++c.counters.bv_rejects;
            return 0;
        }
        return -1;
    }
};

/// The end of a query that got past the object spheres.
const QueryResult& finish(Context& c, QueryResult& result) {
    result.intersecting = !result.pairs.empty();
    if (result.intersecting) {
        result.near.clear();  // those found before the first intersecting pair
    }
    c.counters.near_pairs = result.near.size();
    result.counters = c.counters;
    return result;
}

/// See traverse: meshes of at most this many triangles are one leaf (a box mesh has 12).
constexpr std::size_t kWholeLeaf = 16;

template <class Node, class Ops>
void traverse(Context& c, MeshQuery::Front* front, bool fromFront, bool recordFront) {
    const BvTree<Node>& ta = c.a.template tree<Node>();
    const BvTree<Node>& tb = c.b.template tree<Node>();
    Ops ops(c, ta.nodes().data(), tb.nodes().data());
    ops.prepare();
    const Node* na = ta.nodes().data();
    const Node* nb = tb.nodes().data();
    std::vector<NodePair>& stack = c.scratch.stack;
    std::vector<NodePair>& next = c.scratch.nextFront;
    stack.clear();
    next.clear();
    if (fromFront) {
        for (auto it = front->entries.rbegin(); it != front->entries.rend(); ++it) {
            stack.push_back(*it);
        }
    } else {
        stack.push_back(NodePair(0, 0, detail::kNoAxis));
    }
    c.counters.front_size = stack.size();
    // A mesh of at most kWholeLeaf triangles is one leaf here: its tree is not descended, and
    // each B leaf meets all of its triangles (their boxes first, in A's frame). A box mesh's
    // leaves all have the whole box as their volume, however its 12 triangles are split, so
    // a body resting on a box-mesh ground was traversed once per ground leaf (4 times).
    const bool wholeA = c.a.mesh().triangleCount() <= kWholeLeaf;
    const int countA = int(c.a.mesh().triangleCount());
    const bool larger = c.settings.descent != Descent::kFirstThenSecond;
    const bool both = c.settings.descent == Descent::kBoth;
    const bool yesNo = c.settings.mode == QueryMode::kYesNo;
    constexpr std::size_t kPrefetchAhead = 8;  // pairs popped before a prefetched one's turn
    while (!stack.empty()) {
        const NodePair e = stack.back();
        stack.pop_back();
        if (stack.size() >= kPrefetchAhead) {
            const NodePair later = stack[stack.size() - kPrefetchAhead];
            ops.prefetch(later.a(), later.b());
        }
        const std::int32_t ia = e.a(), ib = e.b();
        const int axis = ops.separated(ia, ib, e.axis());
        if (axis >= 0) {
            if (recordFront) {
                next.push_back(NodePair(ia, ib, axis));
            }
            continue;
        }
        const NodeLink la = na[ia].link, lb = nb[ib].link;
        const bool leafA = wholeA || la.isLeaf();
        if (leafA && lb.isLeaf()) {
            if (recordFront) {
                next.push_back(NodePair(ia, ib, detail::kNoAxis));
            }
            leafPair(c, ta, tb, wholeA ? 0 : la.firstSlot(), wholeA ? countA : la.count(), lb);
            if (c.stop) {
                break;
            }
            continue;
        }
        if (both && !leafA && !lb.isLeaf()) {
            const std::int32_t a2 = la.right(), b2 = lb.right();
            NodePair children[4] = {
                NodePair(ia + 1, ib + 1, detail::kNoAxis), NodePair(ia + 1, b2, detail::kNoAxis),
                NodePair(a2, ib + 1, detail::kNoAxis), NodePair(a2, b2, detail::kNoAxis)};
            if constexpr (Ops::kOrdersChildren) {
                if (yesNo) {  // nearest centres first
                    double d[4];
                    for (int k = 0; k < 4; ++k) {
                        d[k] = ops.distance2(children[k].a(), children[k].b());
                    }
                    for (int k = 1; k < 4; ++k) {
                        for (int m = k; m > 0 && d[m] < d[m - 1]; --m) {
                            std::swap(d[m], d[m - 1]);
                            std::swap(children[m], children[m - 1]);
                        }
                    }
                }
            }
            for (int k = 3; k >= 0; --k) {
                stack.push_back(children[k]);
            }
            continue;
        }
        const bool descendA = !leafA && (lb.isLeaf() || !larger || na[ia].size() >= nb[ib].size());
        NodePair first = descendA ? NodePair(ia + 1, ib, detail::kNoAxis)
                                  : NodePair(ia, ib + 1, detail::kNoAxis);
        NodePair second = descendA ? NodePair(la.right(), ib, detail::kNoAxis)
                                   : NodePair(ia, lb.right(), detail::kNoAxis);
        if constexpr (Ops::kOrdersChildren) {
            // Yes/no stops at the first hit: try the child whose centre is nearer first.
            if (yesNo &&
                ops.distance2(second.a(), second.b()) < ops.distance2(first.a(), first.b())) {
                std::swap(first, second);
            }
        }
        stack.push_back(second);
        stack.push_back(first);
    }
    ops.finish();
}

/// Largest |(R^T R - I)_ij|, NaN when anything is not finite. Scalar: it runs every query.
double orthonormalityError(const Eigen::Matrix3d& r, const Vec3& t) {
    double error = 0;
    bool finite = std::isfinite(t.x() + t.y() + t.z());
    for (int i = 0; i < 3; ++i) {
        for (int j = i; j < 3; ++j) {
            const double dot = (r(0, i) * r(0, j) + r(1, i) * r(1, j)) + r(2, i) * r(2, j);
            const double e = std::fabs(dot - (i == j ? 1.0 : 0.0));
            finite = finite && std::isfinite(dot);
            error = std::max(error, e);
        }
    }
    return finite ? error : std::numeric_limits<double>::quiet_NaN();
}

void checkPose(const Pose& pose, const MeshModel& model, const char* which) {
    const double error = orthonormalityError(pose.rotation, pose.translation);
    if (error <= detail::kMaxOrthonormalityError) {
        return;  // the common case: one scalar pass, no allocation
    }
    if (!pose.rotation.allFinite() || !pose.translation.allFinite()) {
        throw std::invalid_argument(std::string("pose of mesh ") + which + " ('" +
                                    model.mesh().name() + "') is not finite");
    }
    throw std::invalid_argument(std::string("pose of mesh ") + which + " ('" + model.mesh().name() +
                                "') has a rotation that is not orthonormal (|R^T R - I| = " +
                                std::to_string(error) + ", at most 1e-6 accepted)");
}

}  // namespace

MeshQuery::MeshQuery() : front_(std::make_unique<Front>()) {}
MeshQuery::~MeshQuery() = default;
MeshQuery::MeshQuery(MeshQuery&&) noexcept = default;
MeshQuery& MeshQuery::operator=(MeshQuery&&) noexcept = default;

void MeshQuery::resetFront() {
    front_->entries.clear();
    front_->nodesA = front_->nodesB = nullptr;
}

std::size_t MeshQuery::frontSize() const {
    return front_->entries.size();
}

const QueryResult& MeshQuery::run(const MeshModel& a, const Pose& poseA, const MeshModel& b,
                                  const Pose& poseB, const QuerySettings& settings) {
    if (!ownScratch_) {
        ownScratch_ = std::make_unique<QueryScratch>();
    }
    return run(a, poseA, b, poseB, settings, *ownScratch_);
}

const QueryResult& MeshQuery::run(const MeshModel& a, const Pose& poseA, const MeshModel& b,
                                  const Pose& poseB, const QuerySettings& settings,
                                  QueryScratch& scratch) {
    if (a.kind() != b.kind()) {
        throw std::invalid_argument("mesh query: '" + a.mesh().name() + "' has a " +
                                    treeKindName(a.kind()) + " tree and '" + b.mesh().name() +
                                    "' a " + treeKindName(b.kind()) +
                                    " tree; both must be of one kind");
    }
    // The query works in A's frame: its soundness needs B's rotation there to be orthonormal
    // (within 3e-6, which two rotations orthonormal within 1e-6 give). Only when it is not
    // are the two poses examined, to name the bad one.
    const RelativePose relative(poseA, poseB);
    if (!(orthonormalityError(relative.rotation(), relative.translation()) <= 3e-6)) {
        checkPose(poseA, a, "A");
        checkPose(poseB, b, "B");
        throw std::invalid_argument("poses of meshes '" + a.mesh().name() + "' and '" +
                                    b.mesh().name() +
                                    "': the relative rotation is not orthonormal");
    }
    result_.intersecting = false;
    result_.pairs.clear();
    result_.contacts.clear();
    result_.near.clear();
    QueryScratch::Impl& s = scratch.impl();
    const std::size_t vertexCount = b.mesh().vertices().size();
    if (s.vertexStamp.size() < vertexCount) {
        s.vertexStamp.resize(vertexCount, 0);
        s.vertices.resize(vertexCount);
    }
    if (!(settings.margin >= 0) || !std::isfinite(settings.margin)) {
        throw std::invalid_argument(
            "mesh query of '" + a.mesh().name() + "' and '" + b.mesh().name() +
            "': the margin must be finite and >= 0, not " + std::to_string(settings.margin));
    }
    const double margin = settings.mode == QueryMode::kContacts ? settings.margin : 0.0;
    const bool kdop =
        a.kind() != TreeKind::kSphere && a.kind() != TreeKind::kAabb && a.kind() != TreeKind::kObb;
    if (margin > 0 && kdop) {
        throw std::invalid_argument("mesh query of '" + a.mesh().name() + "' and '" +
                                    b.mesh().name() + "': k-DOP trees take no margin");
    }
    // Rounding of B's vertices and box centres moved into A's frame, with a wide margin;
    // the contact margin widens every bounding-volume test by as much again.
    const double slack =
        0x1p-40 * (2 * a.mesh().coordinateBound() + 2 * b.mesh().coordinateBound() +
                   relative.translation().norm()) +
        std::numeric_limits<double>::denorm_min() + margin;
    Context c{a,
              b,
              settings,
              relative.rotation(),
              relative.translation(),
              slack,
              detail::roundUp(slack),
              margin,
              s,
              s.nextStamp(),
              result_,
              QueryCounters()};

    Front& front = *front_;
    if (settings.sphere_pretest && settings.object_spheres) {
        ++c.counters.object_sphere_tests;
        const Vec3 cb = detail::applyFixedOrder(c.rotation, c.translation, b.sphere().center);
        if (detail::spheresDisjoint(cb - a.sphere().center, a.sphere().radius, b.sphere().radius,
                                    slack)) {
            ++c.counters.object_sphere_rejects;
            resetFront();
            result_.counters = c.counters;
            return result_;
        }
    }
    if (!settings.use_tree) {
        resetFront();  // a later tree query must start from the roots
        // The root volumes first (OBB trees: one separating-axis test, as the traversal's
        // first step): a near miss ends here instead of after every triangle pair's boxes.
        if (a.kind() == TreeKind::kObb) {
            ObbOps roots(c, a.template tree<ObbNode>().nodes().data(),
                         b.template tree<ObbNode>().nodes().data());
            roots.prepare();
            ++c.counters.root_tests;
            if (roots.separated(0, 0, detail::kNoAxis) >= 0) {
                ++c.counters.root_rejects;
                return finish(c, result_);
            }
        }
        directPairs(c);
        return finish(c, result_);
    }
    const bool recordFront = settings.use_front && settings.mode != QueryMode::kYesNo;
    const void* nodesA = nullptr;
    const void* nodesB = nullptr;
    auto identify = [&](auto* node) {
        using Node = std::remove_pointer_t<decltype(node)>;
        nodesA = a.template tree<Node>().nodes().data();
        nodesB = b.template tree<Node>().nodes().data();
    };
    auto dispatch = [&](auto&& visit) {
        switch (a.kind()) {
            case TreeKind::kSphere:
                return visit(static_cast<SphereNode*>(nullptr));
            case TreeKind::kAabb:
                return visit(static_cast<AabbNode*>(nullptr));
            case TreeKind::kObb:
                return visit(static_cast<ObbNode*>(nullptr));
            case TreeKind::kKdop6:
                return visit(static_cast<KdopNode<6>*>(nullptr));
            case TreeKind::kKdop14:
                return visit(static_cast<KdopNode<14>*>(nullptr));
            case TreeKind::kKdop18:
                return visit(static_cast<KdopNode<18>*>(nullptr));
            case TreeKind::kKdop26:
                return visit(static_cast<KdopNode<26>*>(nullptr));
        }
    };
    dispatch(identify);
    // A front carried across large motions stays valid but can grow past what a start from
    // the roots would test; every 32 front starts, one start from the roots measures that.
    constexpr int kRootEvery = 32;
    const bool fromFront = recordFront && !front.entries.empty() && front.nodesA == nodesA &&
                           front.nodesB == nodesB && front.countA == a.nodeCount() &&
                           front.countB == b.nodeCount() && front.descent == settings.descent &&
                           front.sinceRoot < kRootEvery;
    c.counters.started_from_front = fromFront;
    dispatch([&](auto* node) {
        using Node = std::remove_pointer_t<decltype(node)>;
        if constexpr (std::is_same_v<Node, ObbNode>) {
            traverse<Node, ObbOps>(c, &front, fromFront, recordFront);
        } else if constexpr (std::is_same_v<Node, SphereNode>) {
            traverse<Node, SphereOps>(c, &front, fromFront, recordFront);
        } else if constexpr (std::is_same_v<Node, AabbNode>) {
            traverse<Node, AabbOps>(c, &front, fromFront, recordFront);
        } else {
            constexpr int K = 2 * int(decltype(Node::volume)::kSlabs);
            traverse<Node, KdopOps<K>>(c, &front, fromFront, recordFront);
        }
    });
    if (recordFront) {
        // A front only deepens; once it has grown well past what a start from the roots
        // produced, the next query starts from the roots again.
        if (fromFront && s.nextFront.size() > 2 * front.rootSize + 16) {
            resetFront();
        } else {
            front.entries.assign(s.nextFront.begin(), s.nextFront.end());  // keeps capacity
            front.nodesA = nodesA;
            front.nodesB = nodesB;
            front.countA = a.nodeCount();
            front.countB = b.nodeCount();
            front.descent = settings.descent;
            if (fromFront) {
                ++front.sinceRoot;
            } else {
                front.rootSize = front.entries.size();
                front.sinceRoot = 0;
            }
        }
    } else {
        resetFront();
    }
    return finish(c, result_);
}

QueryResult meshCollide(const MeshModel& a, const Pose& poseA, const MeshModel& b,
                        const Pose& poseB, const QuerySettings& settings) {
    MeshQuery query;
    return query.run(a, poseA, b, poseB, settings);
}

}  // namespace kolize::narrowphase
