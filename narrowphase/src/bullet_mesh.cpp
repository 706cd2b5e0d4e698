#include "kolize/narrowphase/bullet_mesh.h"

#include "kolize/narrowphase/mesh_ccd.h"
#include "kolize/narrowphase/triangle_test.h"

#include "convex_ccd.h"
#include <BulletCollision/CollisionShapes/btConvexShape.h>
#include <BulletCollision/CollisionShapes/btStaticPlaneShape.h>
#include "mesh_stages_internal.h"

#include <BulletCollision/CollisionDispatch/btCollisionConfiguration.h>
#include <BulletCollision/CollisionDispatch/btCollisionDispatcher.h>
#include <LinearMath/btPoolAllocator.h>
#include <BulletCollision/CollisionDispatch/btCollisionObject.h>
#include <BulletCollision/CollisionDispatch/btCollisionObjectWrapper.h>
#include <BulletCollision/CollisionDispatch/btManifoldResult.h>
#include <BulletCollision/NarrowPhaseCollision/btPersistentManifold.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

namespace kolize {

using narrowphase::Index3;
using narrowphase::MeshModel;
using narrowphase::NearPair;
using narrowphase::ObbNode;
using narrowphase::ObbTree;
using narrowphase::PairContact;
using narrowphase::Pose;
using narrowphase::QueryMode;
using narrowphase::QueryResult;
using narrowphase::QuerySettings;
using narrowphase::RelativePose;
using narrowphase::TriangleIntersection;
using narrowphase::TriangleMesh;
using narrowphase::TrianglePair;
using narrowphase::Vec3;

namespace {

Vec3 toVec3(const btVector3& v) {
    return Vec3(double(v.x()), double(v.y()), double(v.z()));
}

btVector3 toBt(const Vec3& v) {
    return btVector3(btScalar(v.x()), btScalar(v.y()), btScalar(v.z()));
}

/// btScalar at or below x (at or above for `up`): boxes stay conservative after rounding.
btScalar roundOutward(double x, bool up) {
    btScalar r = btScalar(x);
    if (up && double(r) < x) {
        r = std::nextafter(r, std::numeric_limits<btScalar>::infinity());
    } else if (!up && double(r) > x) {
        r = std::nextafter(r, -std::numeric_limits<btScalar>::infinity());
    }
    return r;
}

/// The rigid pose of a Bullet transform in double. Bullet's float bases are orthonormal
/// only to about 1e-7; going through a normalised quaternion makes them orthonormal to
/// double rounding, which the mesh query requires (1e-6), for any build of Bullet.
Pose toPose(const btTransform& t) {
    Eigen::Matrix3d basis;
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) {
            basis(r, c) = double(t.getBasis()[r][c]);
        }
    }
    Pose pose;
    if (basis == Eigen::Matrix3d::Identity()) {
        pose.rotation = basis;
    } else {
        Eigen::Quaterniond q(basis);
        q.normalize();
        pose.rotation = q.toRotationMatrix();
    }
    pose.translation = toVec3(t.getOrigin());
    return pose;
}

bool finitePose(const btTransform& t) {
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) {
            if (!std::isfinite(double(t.getBasis()[r][c]))) {
                return false;
            }
        }
        if (!std::isfinite(double(t.getOrigin()[r]))) {
            return false;
        }
    }
    return true;
}

/// The root OBB's axis-aligned bounds in the model frame (double, from the float box).
void obbBounds(const narrowphase::Obb& box, Vec3& lo, Vec3& hi) {
    const Eigen::Vector3d c = box.center.cast<double>();
    const Eigen::Vector3d h = box.half.cast<double>();
    const Eigen::Vector3d a0 = box.axis0.cast<double>();
    const Eigen::Vector3d a1 = box.axis1.cast<double>();
    const Eigen::Vector3d a2 = box.axis2().cast<double>();
    const Eigen::Vector3d extent =
        a0.cwiseAbs() * h.x() + a1.cwiseAbs() * h.y() + a2.cwiseAbs() * h.z();
    // Double rounding of the sums above: a relative pad far below float resolution.
    const Eigen::Vector3d pad = (c.cwiseAbs() + extent) * 1e-12;
    lo = c - extent - pad;
    hi = c + extent + pad;
}

// ---------------------------------------------------------------------------------------
// Contacts from intersecting triangle pairs (bullet_mesh.h's file comment has the rules).

struct Candidate {
    Vec3 point;
    int patch;
    TrianglePair ids;
    double depth;
};

struct Patch {
    Vec3 normal = Vec3::Zero();
    double depth = 0;
    bool valid = false;
    /// Its vertices inside the other mesh (s.inside) span an area: they are its points.
    bool byVertices = false;
};

int findRoot(std::vector<int>& parent, int i) {
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    return i;
}

/// Unions the pairs that share a vertex index through `vertexOf(pair, k)`: each pair with
/// the last one seen at each of its vertices. A root is always the smallest index of its
/// set, so the sets and their roots do not depend on the order of the unions. `last` maps
/// a vertex to a pair, -1 for none: all -1 on entry, and so again on return.
template <class VertexOf>
void unionByVertex(std::size_t pairCount, VertexOf vertexOf, std::vector<int>& parent,
                   std::vector<int>& last) {
    for (std::size_t i = 0; i < pairCount; ++i) {
        int y = findRoot(parent, int(i));  // i's root, kept current through its unions
        for (int k = 0; k < 3; ++k) {
            int& seen = last[vertexOf(i, k)];
            if (seen >= 0) {
                const int x = findRoot(parent, seen);
                if (x != y) {
                    parent[std::max(x, y)] = std::min(x, y);  // smallest index: deterministic
                    y = std::min(x, y);
                }
            }
            seen = int(i);
        }
    }
    for (std::size_t i = 0; i < pairCount; ++i) {
        for (int k = 0; k < 3; ++k) {
            last[vertexOf(i, k)] = -1;
        }
    }
}

/// Sorts `values` (vertex indices) and drops repeats; `marks` is all 0 on entry and return.
void uniqueSorted(std::vector<std::int32_t>& values, std::vector<unsigned char>& marks) {
    std::size_t kept = 0;
    for (const std::int32_t v : values) {
        if (marks[v] == 0) {
            marks[v] = 1;
            values[kept++] = v;
        }
    }
    values.resize(kept);
    for (const std::int32_t v : values) {
        marks[v] = 0;
    }
    std::sort(values.begin(), values.end());
}

/// Face normals tried per patch (plus the weighted sum), the heaviest first.
constexpr std::size_t kMaxNormalCandidates = 64;

/// Scratch of contact building (reused by an algorithm across frames).
struct ContactScratch {
    std::vector<int> parent;
    std::vector<int> root;                  // each pair's patch (its set's root)
    std::vector<int> lastPair;              // unionByVertex's map, all -1 between calls
    std::vector<unsigned char> marks;       // uniqueSorted's, all 0 between calls
    std::vector<int> normalOfA, normalOfB;  // a triangle's entry in `normals`, -1 between calls
    std::vector<int> order;
    std::vector<int> patchStart;
    std::vector<Patch> patches;
    std::vector<std::int32_t> verticesA, verticesB;
    std::vector<Vec3> pointsA, pointsB;
    std::vector<std::pair<double, Vec3>> normals;
    std::vector<Candidate> candidates;
    std::vector<Candidate> inside;          // vertices inside the other mesh, all patches
    std::vector<int> insideOfA, insideOfB;  // a vertex's entry in `inside`, -1 between calls
    std::vector<double> heights;            // planeContacts' vertex heights
    std::vector<const PairContact*> sorted;
    std::vector<const NearPair*> sortedNear;
    std::vector<Vec3> outA, outB;  // each sorted pair's outward face normals (A's frame)
    // B's vertices in A's frame, each moved once per call: valid where bStamp == stamp.
    std::vector<Vec3> bInAVertices;
    std::vector<std::uint32_t> bStamp;
    std::uint32_t stamp = 0;

    /// Starts a call on a B mesh of `vertexCount` vertices: forgets every moved vertex.
    void newCall(std::size_t vertexCount) {
        if (bStamp.size() < vertexCount) {
            bStamp.resize(vertexCount, 0);
            bInAVertices.resize(vertexCount);
        }
        if (++stamp == 0) {  // wrapped: forget the old stamps once every 2^32 calls
            std::fill(bStamp.begin(), bStamp.end(), 0);
            stamp = 1;
        }
    }
    /// B's vertex v in A's frame, bInA.apply(v) (the same doubles), computed once per call.
    const Vec3& vertexB(std::int32_t v, const TriangleMesh& meshB, const RelativePose& bInA) {
        if (bStamp[v] != stamp) {
            bStamp[v] = stamp;
            bInAVertices[v] = bInA.apply(meshB.vertices()[v]);
        }
        return bInAVertices[v];
    }
};

/// How a mesh's face normals say which side is outside.
enum class Sides : std::uint8_t {
    kWinding,  ///< a closed mesh: the winding's normal points out
    kOpen,     ///< an open mesh: out is away from the body's origin (its centre)
    kScenery,  ///< two-sided scenery: out is towards the other body's origin
};

/// Sides of a MeshShape's mesh.
Sides sidesOf(const MeshShape& shape) {
    return shape.massProperties().closed ? Sides::kWinding : Sides::kOpen;
}

/// The face normal `n` (A's frame) of triangle `t` of `mesh` (its vertices mapped into A's
/// frame by `toA`, null: already there), pointing out of the mesh as `sides` says: for kOpen
/// away from `centre` (the mesh's own origin in A's frame), for kScenery towards A's origin.
Vec3 outward(const Vec3& n, Sides sides, const TriangleMesh& mesh, const Index3& t,
             const RelativePose* toA, const Vec3& centre) {
    if (sides == Sides::kWinding || n.squaredNorm() == 0) {
        return n;
    }
    Vec3 middle = Vec3::Zero();
    for (int k = 0; k < 3; ++k) {
        const Vec3& v = mesh.vertices()[t[k]];
        middle += toA != nullptr ? toA->apply(v) : v;
    }
    middle /= 3;
    const double side = sides == Sides::kOpen ? n.dot(middle - centre) : -n.dot(middle);
    return side < 0 ? Vec3(-n) : n;
}

void patchesOfPairs(const QueryResult& result, const TriangleMesh& meshA, const TriangleMesh& meshB,
                    const RelativePose& bInA, Sides sidesA, Sides sidesB, ContactScratch& s);

/// Whether depthBelow can find a depth along d below a triangle of outward unit normal m:
/// not when the line along d runs within 1e-3 of the plane's direction or leaves it.
bool movesOutThrough(const Vec3& d, const Vec3& m) {
    return !(d.dot(m) > -1e-3);
}

/// How far `v` lies inside a mesh below its triangle (q0, q1, q2) with outward unit normal
/// `m` (either winding), measured along -d (d unit, the direction the mesh moves out;
/// movesOutThrough(d, m)): t >= 0 with v - t d in the closed triangle and v behind or on its
/// plane; -1 when v is in front or the line passes beside the triangle.
double depthBelow(const Vec3& v, const Vec3& d, const Vec3& q0, const Vec3& q1, const Vec3& q2,
                  const Vec3& m) {
    const double behind = (v - q0).dot(m);
    const double along = d.dot(m);
    if (behind > 0) {
        return -1;
    }
    const double t = behind / along;
    const Vec3 p = v - t * d;
    const Vec3* q[3] = {&q0, &q1, &q2};
    // p in the closed triangle: on the inner side of its three edges, for either winding
    // about m (scenery's outward normals are turned towards the body whichever way its
    // triangles are wound: Bullet's plane and a bowl wound outward are wound against them).
    // Within a relative hair of an edge counts as on it (the point's rounding).
    bool innerForWinding = true, innerAgainst = true;
    for (int k = 0; k < 3; ++k) {
        const Vec3 edge = *q[(k + 1) % 3] - *q[k];
        const double side = edge.cross(p - *q[k]).dot(m);
        const double hair = 1e-12 * (edge.squaredNorm() + (p - *q[k]).squaredNorm());
        innerForWinding = innerForWinding && side >= -hair;
        innerAgainst = innerAgainst && side <= hair;
    }
    return innerForWinding || innerAgainst ? t : -1;
}

/// Whether the points of candidates[first..] span an area: not all within 1e-9 of their
/// extent of the line through the first and the farthest from it.
bool spansArea(const std::vector<Candidate>& candidates, std::size_t first) {
    if (candidates.size() < first + 3) {
        return false;
    }
    const Vec3& p0 = candidates[first].point;
    std::size_t far = first;
    for (std::size_t k = first + 1; k < candidates.size(); ++k) {
        if ((candidates[k].point - p0).squaredNorm() > (candidates[far].point - p0).squaredNorm()) {
            far = k;
        }
    }
    const Vec3 axis = candidates[far].point - p0;
    const double length2 = axis.squaredNorm();
    for (std::size_t k = first + 1; k < candidates.size(); ++k) {
        if (axis.cross(candidates[k].point - p0).squaredNorm() > 1e-18 * length2 * length2) {
            return true;
        }
    }
    return false;
}

/// Adds the vertices of the pair `c` that lie inside the other mesh below the pair's other
/// triangle (depthBelow along the patch normal n, from A towards B) to s.inside, one entry
/// per vertex at its least depth; `bInA` moves B's vertices into A's frame.
void insideVertices(const PairContact& c, int patch, const Vec3& n, const Vec3& normalA,
                    const Vec3& normalB, const TriangleMesh& meshA, const TriangleMesh& meshB,
                    const RelativePose& bInA, ContactScratch& s) {
    // Each direction is tested once per pair: along it every vertex or none can have a depth.
    const bool throughB = movesOutThrough(n, normalB);
    const bool throughA = movesOutThrough(-n, normalA);
    if (!throughA && !throughB) {
        return;
    }
    const Index3& ia = meshA.triangles()[c.pair.a];
    const Index3& ib = meshB.triangles()[c.pair.b];
    const std::array<Vec3, 3> a = {meshA.vertices()[ia[0]], meshA.vertices()[ia[1]],
                                   meshA.vertices()[ia[2]]};
    const std::array<Vec3, 3> b = {s.vertexB(ib[0], meshB, bInA), s.vertexB(ib[1], meshB, bInA),
                                   s.vertexB(ib[2], meshB, bInA)};
    auto keep = [&](int& slot, const Vec3& point, double depth) {
        if (depth < 0) {
            return;
        }
        if (slot < 0) {
            slot = int(s.inside.size());
            s.inside.push_back({point, patch, c.pair, depth});
        } else if (depth < s.inside[slot].depth) {
            s.inside[slot] = {point, patch, c.pair, depth};
        }
    };
    // A moves out of B along -n: A's vertex v meets B's face at v - t n; the contact point
    // is halfway, v - (t/2) n. B moves out along +n.
    for (int k = 0; k < 3; ++k) {
        if (throughB) {
            const double t = depthBelow(a[k], n, b[0], b[1], b[2], normalB);
            keep(s.insideOfA[ia[k]], a[k] - (0.5 * t) * n, t);
        }
        if (throughA) {
            const double u = depthBelow(b[k], -n, a[0], a[1], a[2], normalA);
            keep(s.insideOfB[ib[k]], b[k] + (0.5 * u) * n, u);
        }
    }
}

void chooseContacts(const ContactScratch& s, double separation, std::vector<MeshContact>& out);

/// Up to 4 contacts (in A's frame, X = A) from the query's pairs, no two within `separation`
/// of each other. `bInA` is the pose the query used: B's vertices are classified as
/// bInA.apply(q), and so are they here. The candidate normals point from A towards B; a face
/// normal of a mesh whose winding does not say where its outside is (`sidesA`, `sidesB`) is
/// turned to point out of its triangle as Sides says (an open surface has no inside: a wrong
/// guess would push a body through it).
void buildContacts(const QueryResult& result, const TriangleMesh& meshA, const TriangleMesh& meshB,
                   const RelativePose& bInA, Sides sidesA, Sides sidesB, double separation,
                   ContactScratch& s, std::vector<MeshContact>& out) {
    out.clear();
    const std::size_t count = result.contacts.size();
    s.patches.assign(count, Patch{});
    s.inside.clear();
    if (count > 0) {
        patchesOfPairs(result, meshA, meshB, bInA, sidesA, sidesB, s);
    }
    // Near pairs (a contact margin): one patch each, its normal from A's closest point
    // towards B's, its depth minus the distance; in pair order, as the intersecting pairs.
    std::vector<const NearPair*>& near = s.sortedNear;
    near.clear();
    for (const NearPair& n : result.near) {
        near.push_back(&n);
    }
    std::sort(near.begin(), near.end(),
              [](const NearPair* x, const NearPair* y) { return x->pair < y->pair; });
    for (const NearPair* n : near) {
        Patch patch;
        const Vec3 gap = n->on_b - n->on_a;
        patch.valid = n->distance > 0 && gap.squaredNorm() > 0;
        if (patch.valid) {
            patch.normal = gap / gap.norm();
            patch.depth = -n->distance;
        }
        s.patches.push_back(patch);
    }
    // A patch's points: its vertices inside the other mesh, each at its own depth, where
    // they span an area; otherwise the intersection curve's points at the patch's depth.
    s.candidates.clear();
    for (const Candidate& c : s.inside) {
        if (s.patches[c.patch].byVertices) {
            s.candidates.push_back(c);
        }
    }
    for (std::size_t i = 0; i < count; ++i) {
        const int root = s.root[i];
        const Patch& patch = s.patches[root];
        if (!patch.valid || patch.byVertices) {
            continue;
        }
        const TriangleIntersection& g = s.sorted[i]->geometry;
        for (int k = 0; k < g.count; ++k) {
            s.candidates.push_back({g.points[k], root, s.sorted[i]->pair, patch.depth});
        }
    }
    for (std::size_t j = 0; j < near.size(); ++j) {
        const Patch& patch = s.patches[count + j];
        if (patch.valid) {
            s.candidates.push_back({0.5 * (near[j]->on_a + near[j]->on_b), int(count + j),
                                    near[j]->pair, patch.depth});
        }
    }
    if (s.candidates.empty()) {
        return;
    }
    chooseContacts(s, separation, out);
}

/// The patches of the intersecting pairs (s.sorted in pair order, s.root, s.patches).
void patchesOfPairs(const QueryResult& result, const TriangleMesh& meshA, const TriangleMesh& meshB,
                    const RelativePose& bInA, Sides sidesA, Sides sidesB, ContactScratch& s) {
    const std::size_t count = result.contacts.size();
    // The pairs in (A's triangle, B's triangle) order: the contacts depend on the set of
    // pairs only, not on the order a query found them in (the tree's traversal order, the
    // front's, or the mesh order of a query without tree).
    std::vector<const PairContact*>& pairs = s.sorted;
    pairs.clear();
    for (const PairContact& c : result.contacts) {
        pairs.push_back(&c);
    }
    auto byPair = [](const PairContact* x, const PairContact* y) { return x->pair < y->pair; };
    if (!std::is_sorted(pairs.begin(), pairs.end(), byPair)) {
        std::sort(pairs.begin(), pairs.end(), byPair);
    }
    s.parent.resize(count);
    std::iota(s.parent.begin(), s.parent.end(), 0);
    const std::size_t vertexCount = std::max(meshA.vertices().size(), meshB.vertices().size());
    if (s.lastPair.size() < vertexCount) {
        s.lastPair.resize(vertexCount, -1);
        s.marks.resize(vertexCount, 0);
    }
    if (s.normalOfA.size() < meshA.triangleCount()) {
        s.normalOfA.resize(meshA.triangleCount(), -1);
    }
    if (s.normalOfB.size() < meshB.triangleCount()) {
        s.normalOfB.resize(meshB.triangleCount(), -1);
    }
    if (s.insideOfA.size() < meshA.vertices().size()) {
        s.insideOfA.resize(meshA.vertices().size(), -1);
    }
    if (s.insideOfB.size() < meshB.vertices().size()) {
        s.insideOfB.resize(meshB.vertices().size(), -1);
    }
    // Each pair's face normals, turned outward, once (the patch's normals and its inside
    // vertices both need them); B's origin in A's frame is an open B's centre.
    s.newCall(meshB.vertices().size());
    const Vec3 originB = bInA.apply(Vec3::Zero());
    s.outA.resize(count);
    s.outB.resize(count);
    for (std::size_t i = 0; i < count; ++i) {
        const PairContact& c = *pairs[i];
        s.outA[i] =
            outward(c.normal_a, sidesA, meshA, meshA.triangles()[c.pair.a], nullptr, Vec3::Zero());
        s.outB[i] = outward(c.normal_b, sidesB, meshB, meshB.triangles()[c.pair.b], &bInA, originB);
    }
    unionByVertex(
        count, [&](std::size_t i, int k) { return meshA.triangles()[pairs[i]->pair.a][k]; },
        s.parent, s.lastPair);
    unionByVertex(
        count, [&](std::size_t i, int k) { return meshB.triangles()[pairs[i]->pair.b][k]; },
        s.parent, s.lastPair);
    s.root.resize(count);
    for (std::size_t i = 0; i < count; ++i) {
        s.root[i] = findRoot(s.parent, int(i));
    }

    // Pairs grouped by patch (root), each group in sorted order (a stable counting sort).
    s.patchStart.assign(count + 1, 0);
    for (std::size_t i = 0; i < count; ++i) {
        ++s.patchStart[s.root[i] + 1];
    }
    for (std::size_t r = 0; r < count; ++r) {
        s.patchStart[r + 1] += s.patchStart[r];
    }
    s.order.resize(count);
    for (std::size_t i = 0; i < count; ++i) {
        s.order[s.patchStart[s.root[i]]++] = int(i);
    }
    for (std::size_t begin = 0; begin < count;) {
        const int root = s.root[s.order[begin]];
        std::size_t end = begin;
        while (end < count && s.root[s.order[end]] == root) {
            ++end;
        }
        // The patch's vertices (A's, and B's in A's frame) and its candidate normals, each
        // pointing from A towards B: A's face normals, B's reversed, and the weighted sum.
        s.verticesA.clear();
        s.verticesB.clear();
        s.normals.clear();
        Vec3 sum = Vec3::Zero();
        for (std::size_t k = begin; k < end; ++k) {
            const PairContact& c = *pairs[s.order[k]];
            const Index3& ia = meshA.triangles()[c.pair.a];
            const Index3& ib = meshB.triangles()[c.pair.b];
            s.verticesA.insert(s.verticesA.end(), ia.begin(), ia.end());
            s.verticesB.insert(s.verticesB.end(), ib.begin(), ib.end());
            const double measure = std::max(c.geometry.measure(), 0.0);
            const double weight = c.geometry.kind == TriangleIntersection::Kind::kPolygon
                                      ? std::sqrt(measure)
                                      : measure;
            const Vec3& normalA = s.outA[s.order[k]];
            const Vec3& normalB = s.outB[s.order[k]];
            sum += weight * (normalA - normalB);
            // One entry per triangle, at its heaviest pair's weight (a triangle's normal is
            // the same in every pair it is in).
            auto add = [&](int& slot, const Vec3& n) {
                if (slot >= 0) {
                    s.normals[slot].first = std::max(s.normals[slot].first, weight);
                } else if (n.squaredNorm() > 0) {
                    slot = int(s.normals.size());
                    s.normals.push_back({weight, n});
                }
            };
            add(s.normalOfA[c.pair.a], normalA);
            add(s.normalOfB[c.pair.b], -normalB);
        }
        for (std::size_t k = begin; k < end; ++k) {
            const PairContact& c = *pairs[s.order[k]];
            s.normalOfA[c.pair.a] = -1;
            s.normalOfB[c.pair.b] = -1;
        }
        uniqueSorted(s.verticesA, s.marks);
        uniqueSorted(s.verticesB, s.marks);
        // The heaviest distinct face normals (a deep patch of a fine mesh has thousands):
        // first by weight, so that of equal overlaps the heaviest normal wins.
        std::sort(s.normals.begin(), s.normals.end(), [](const auto& x, const auto& y) {
            if (x.first != y.first) {
                return x.first > y.first;
            }
            return std::lexicographical_compare(x.second.data(), x.second.data() + 3,
                                                y.second.data(), y.second.data() + 3);
        });
        s.normals.erase(
            std::unique(s.normals.begin(), s.normals.end(),
                        [](const auto& x, const auto& y) { return x.second == y.second; }),
            s.normals.end());
        if (s.normals.size() > kMaxNormalCandidates) {
            s.normals.resize(kMaxNormalCandidates);
        }
        if (sum.norm() > 0) {
            s.normals.push_back({0.0, sum.normalized()});
        }
        s.pointsA.clear();
        for (std::int32_t v : s.verticesA) {
            s.pointsA.push_back(meshA.vertices()[v]);
        }
        s.pointsB.clear();
        for (std::int32_t v : s.verticesB) {
            s.pointsB.push_back(s.vertexB(v, meshB, bInA));
        }
        // The candidate along which the patch's pieces overlap least (the separating-axis
        // idea on the touched triangles): its overlap is the depth. The smaller side is
        // scanned whole first; the other side's partial extreme already bounds the overlap
        // from below (max and min are exact, the subtraction monotone), so a candidate stops
        // as soon as it cannot beat the best: the values compared are those of a full scan.
        Patch& patch = s.patches[root];
        double best = std::numeric_limits<double>::infinity();
        const bool aFirst = s.pointsA.size() <= s.pointsB.size();
        for (const auto& candidate : s.normals) {
            const Vec3& d = candidate.second;
            double highestA = -std::numeric_limits<double>::infinity();
            double lowestB = std::numeric_limits<double>::infinity();
            bool beaten = false;
            if (aFirst) {
                for (const Vec3& p : s.pointsA) {
                    highestA = std::max(highestA, p.dot(d));
                }
                for (const Vec3& q : s.pointsB) {
                    lowestB = std::min(lowestB, q.dot(d));
                    if (highestA - lowestB >= best) {
                        beaten = true;
                        break;
                    }
                }
            } else {
                for (const Vec3& q : s.pointsB) {
                    lowestB = std::min(lowestB, q.dot(d));
                }
                for (const Vec3& p : s.pointsA) {
                    highestA = std::max(highestA, p.dot(d));
                    if (highestA - lowestB >= best) {
                        beaten = true;
                        break;
                    }
                }
            }
            if (beaten) {
                continue;
            }
            const double overlap = highestA - lowestB;
            if (overlap < best) {
                best = overlap;
                patch.normal = d;
            }
        }
        patch.valid = std::isfinite(best);
        patch.depth = patch.valid ? std::max(best, 0.0) : 0.0;
        // Inside has a meaning where both meshes are closed (or scenery, two-sided, whose
        // outside faces the mesh body): an open mesh's outward normals are a guess (the
        // wall's and the pile's open models went 2-10 cm deep on vertex points so placed).
        if (patch.valid && sidesA != Sides::kOpen && sidesB != Sides::kOpen) {
            const std::size_t first = s.inside.size();
            for (std::size_t k = begin; k < end; ++k) {
                const PairContact& c = *pairs[s.order[k]];
                insideVertices(c, root, patch.normal, s.outA[s.order[k]], s.outB[s.order[k]], meshA,
                               meshB, bInA, s);
            }
            for (std::size_t k = begin; k < end; ++k) {
                const PairContact& c = *pairs[s.order[k]];
                for (int j = 0; j < 3; ++j) {
                    s.insideOfA[meshA.triangles()[c.pair.a][j]] = -1;
                    s.insideOfB[meshB.triangles()[c.pair.b][j]] = -1;
                }
            }
            for (std::size_t k = first; k < s.inside.size(); ++k) {
                // At most the patch's depth (so by construction; this guards the rounding).
                s.inside[k].depth = std::min(s.inside[k].depth, patch.depth);
            }
            patch.byVertices = spansArea(s.inside, first);
        }
        begin = end;
    }
}

/// Up to 4 of s.candidates (not empty) as contacts, no two within `separation` (the
/// manifold's breaking threshold): Bullet merges a new point into the nearest point within it
/// (getCacheEntry), so of two new points closer than that the second replaced the first.
void chooseContacts(const ContactScratch& s, double separation, std::vector<MeshContact>& out) {
    // Bullet's choice of 4 points: the deepest, the farthest from it, the largest triangle,
    // the largest quadrilateral (diagonal cross products, as in sortCachedPoints).
    std::array<int, 4> chosen{};
    int chosenCount = 0;
    {
        int best = 0;
        for (int i = 1; i < int(s.candidates.size()); ++i) {
            if (s.candidates[i].depth > s.candidates[best].depth) {
                best = i;
            }
        }
        chosen[chosenCount++] = best;
    }
    double scale = 0;
    for (const Candidate& c : s.candidates) {
        scale = std::max(scale, (c.point - s.candidates[chosen[0]].point).squaredNorm());
    }
    // Lengths below 1e-9 of the patch's extent count as zero: the areas must be real (steps 2
    // and 3 compare squared areas), and no point is chosen within that or `separation` of
    // one chosen before.
    const double tinyLength = 1e-18 * scale;
    const double apart = std::max(tinyLength, separation * separation);
    for (int step = 1; step < 4 && scale > 0; ++step) {
        int best = -1;
        double bestValue = step == 1 ? tinyLength : tinyLength * scale;
        for (int i = 0; i < int(s.candidates.size()); ++i) {
            const Vec3& p = s.candidates[i].point;
            const Vec3& p0 = s.candidates[chosen[0]].point;
            double value = 0;
            if (step == 1) {
                value = (p - p0).squaredNorm();
            } else if (step == 2) {
                const Vec3& p1 = s.candidates[chosen[1]].point;
                value = (p1 - p0).cross(p - p0).squaredNorm();
            } else {
                const Vec3& p1 = s.candidates[chosen[1]].point;
                const Vec3& p2 = s.candidates[chosen[2]].point;
                value = std::max({(p0 - p1).cross(p2 - p).squaredNorm(),
                                  (p0 - p2).cross(p1 - p).squaredNorm(),
                                  (p0 - p).cross(p1 - p2).squaredNorm()});
            }
            if (value > bestValue) {
                // Only the points that would win are checked for a chosen one nearby: the same
                // choice as skipping those first.
                bool repeated = false;
                for (int k = 0; k < chosenCount; ++k) {
                    repeated =
                        repeated || (p - s.candidates[chosen[k]].point).squaredNorm() <= apart;
                }
                if (!repeated) {
                    bestValue = value;
                    best = i;
                }
            }
        }
        if (best < 0) {
            break;
        }
        chosen[chosenCount++] = best;
    }
    for (int k = 0; k < chosenCount; ++k) {
        const Candidate& c = s.candidates[chosen[k]];
        const Patch& patch = s.patches[c.patch];
        MeshContact contact;
        contact.point = c.point;
        contact.normal = patch.normal;
        contact.depth = c.depth;
        contact.triangleX = c.ids.a;
        contact.triangleY = c.ids.b;
        out.push_back(contact);
    }
}

/// Moves contacts from A's model frame into the world.
void toWorld(std::vector<MeshContact>& contacts, const Pose& poseA) {
    for (MeshContact& c : contacts) {
        c.point = poseA.rotation * c.point + poseA.translation;
        c.normal = poseA.rotation * c.normal;
    }
}

/// Hands contacts (X, Y) to Bullet, X being body0 of `resultOut` or not.
void emit(const std::vector<MeshContact>& contacts, bool xIsBody0, btManifoldResult* resultOut) {
    for (const MeshContact& c : contacts) {
        // The points straddle the intersection curve by half the depth each: X's deepest
        // point lies along +n (inside Y), Y's along -n.
        const Vec3 onX = c.point + c.normal * (0.5 * c.depth);
        const Vec3 onY = c.point - c.normal * (0.5 * c.depth);
        if (xIsBody0) {
            resultOut->setShapeIdentifiersA(c.partX, c.triangleX);
            resultOut->setShapeIdentifiersB(c.partY, c.triangleY);
            resultOut->addContactPoint(toBt(-c.normal), toBt(onY), btScalar(-c.depth));
        } else {
            resultOut->setShapeIdentifiersA(c.partY, c.triangleY);
            resultOut->setShapeIdentifiersB(c.partX, c.triangleX);
            resultOut->addContactPoint(toBt(c.normal), toBt(onX), btScalar(-c.depth));
        }
    }
}

/// The same contacts with X and Y exchanged (the normal turned, the ids swapped).
void asBody0First(std::vector<MeshContact>& contacts) {
    for (MeshContact& c : contacts) {
        c.normal = -c.normal;
        std::swap(c.partX, c.partY);
        std::swap(c.triangleX, c.triangleY);
    }
}

/// Before new points go in: drops the kept points that the bodies' motion since they were
/// made has parted or slid past the breaking threshold (refreshContactPoints, which runs again
/// after them). Left in, a full manifold's stale points take part in the choice of the point a
/// new one replaces (sortCachedPoints keeps the deepest and the largest area), so the new
/// points replaced each other and the stale ones were dropped only after them: a box sliding
/// 1.1 cm per step over a floor (mesh-floor at 1/120 s, breaking threshold 0.9 cm) kept 2 of
/// its 4 new points, on its shallow side, and sank 1.4-2 mm on the other.
void dropStalePoints(bool ownManifold, btManifoldResult* resultOut) {
    if (ownManifold && resultOut->getPersistentManifold()->getNumContacts() > 0) {
        resultOut->refreshContactPoints();
    }
}

thread_local ContactScratch contactScratch;

/// One query scratch per thread for every pair's queries (a MeshQuery's own would be one per
/// pair): B's moved nodes and vertices then reuse the same, cache-warm memory from pair to
/// pair instead of each pair's own arrays, cold since its last query a frame ago.
thread_local narrowphase::QueryScratch queryScratch;

QuerySettings contactSettings() {
    QuerySettings settings;
    settings.mode = QueryMode::kContacts;
    settings.use_front = true;
    return settings;
}

/// The pair's contact margin: the dispatcher's, at most the manifold's breaking threshold;
/// for Bullet's closest-point queries (contactTest and contactPairTest with the callback's
/// m_closestDistanceThreshold, which hand their points to the callback, not to a manifold)
/// at least that threshold.
double contactMargin(detail::PairStages& stages, const btPersistentManifold* manifold,
                     const btManifoldResult* result) {
    double margin = stages.planner().settings.contact_margin;
    margin = margin > 0 && manifold != nullptr
                 ? std::min(margin, double(manifold->getContactBreakingThreshold()))
                 : 0.0;
    const double asked = result != nullptr ? double(result->m_closestPointDistanceThreshold) : 0.0;
    return std::isfinite(asked) && asked > margin ? asked : margin;
}

/// The manifold's breaking threshold, 0 without one.
double breakingThreshold(const btPersistentManifold* manifold) {
    return manifold != nullptr ? double(manifold->getContactBreakingThreshold()) : 0.0;
}

/// After refreshContactPoints, for two meshes the exact test found apart: the kept points'
/// distances, recomputed from where the points were on the bodies when they were made, are
/// not penetrations (there is none), so they read as touching (0) at most: the solver still
/// holds a resting body on them but pushes nothing apart.
void keptPointsAtMostTouch(btPersistentManifold* manifold) {
    for (int i = 0; i < manifold->getNumContacts(); ++i) {
        btManifoldPoint& point = manifold->getContactPoint(i);
        point.m_distance1 = std::max(point.m_distance1, btScalar(0));
    }
}

std::string formatScale(const btVector3& s) {
    std::ostringstream out;
    out.precision(9);
    out << '(' << double(s.x()) << ", " << double(s.y()) << ", " << double(s.z()) << ')';
    return out.str();
}

}  // namespace

// ---------------------------------------------------------------------------------------

std::shared_ptr<const MeshModel> makeMeshModel(TriangleMesh mesh, int leafSize) {
    narrowphase::TreeSettings settings;
    settings.kind = narrowphase::TreeKind::kObb;
    settings.leaf_size = leafSize != 0                                     ? leafSize
                         : mesh.triangleCount() <= std::size_t(kSmallMesh) ? 1
                                                                           : 4;
    return std::make_shared<const MeshModel>(std::make_shared<const TriangleMesh>(std::move(mesh)),
                                             settings);
}

MeshMassProperties meshMassProperties(const TriangleMesh& mesh) {
    MeshMassProperties out;
    std::vector<std::pair<std::int32_t, std::int32_t>> edges;
    edges.reserve(mesh.triangleCount() * 3);
    for (const Index3& t : mesh.triangles()) {
        for (int k = 0; k < 3; ++k) {
            edges.emplace_back(t[k], t[(k + 1) % 3]);
        }
    }
    std::sort(edges.begin(), edges.end());
    out.closed = true;
    for (std::size_t i = 0; i < edges.size() && out.closed; ++i) {
        const bool repeated = i + 1 < edges.size() && edges[i + 1] == edges[i];
        const bool matched = std::binary_search(edges.begin(), edges.end(),
                                                std::make_pair(edges[i].second, edges[i].first));
        out.closed = !repeated && matched && edges[i].first != edges[i].second;
    }
    // One signed tetrahedron (origin, a, b, c) per triangle: volume det/6, first moment
    // det (a + b + c) / 24, second moment det/120 (M M^T + s s^T), M = [a b c], s = a + b + c.
    double volume = 0;
    Vec3 moment = Vec3::Zero();
    Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
    for (std::size_t i = 0; i < mesh.triangleCount(); ++i) {
        const narrowphase::Triangle t = mesh.triangle(i);
        Eigen::Matrix3d m;
        m << t[0], t[1], t[2];
        const double det = m.determinant();
        const Vec3 sum = t[0] + t[1] + t[2];
        volume += det / 6;
        moment += det * sum / 24;
        second += det / 120 * (m * m.transpose() + sum * sum.transpose());
    }
    if (volume < 0) {  // consistently inverted winding
        volume = -volume;
        moment = -moment;
        second = -second;
    }
    out.volume = volume;
    if (volume > 0) {
        out.centroid = moment / volume;
        const Eigen::Matrix3d central = second - volume * out.centroid * out.centroid.transpose();
        out.inertia = central.trace() * Eigen::Matrix3d::Identity() - central;
    } else {
        out.closed = false;
    }
    return out;
}

// ---------------------------------------------------------------------------------------
// MeshShape

MeshShape::MeshShape(std::shared_ptr<const MeshModel> model) {
    m_shapeType = CUSTOM_CONCAVE_SHAPE_TYPE;
    if (!model) {
        throw std::invalid_argument("kolize::MeshShape: null mesh model");
    }
    if (model->kind() != narrowphase::TreeKind::kObb) {
        throw std::invalid_argument("kolize::MeshShape: mesh '" + model->mesh().name() +
                                    "' has a " + narrowphase::treeKindName(model->kind()) +
                                    " tree; the Bullet algorithms need an OBB tree");
    }
    base_ = model;
    adoptModel(std::move(model));
}

void MeshShape::adoptModel(std::shared_ptr<const MeshModel> model) {
    root_ = model->tree<ObbNode>().nodes().front().volume;
    const std::vector<Vec3>& vertices = model->mesh().vertices();
    boundsLo_ = boundsHi_ = vertices.front();
    for (const Vec3& v : vertices) {
        boundsLo_ = boundsLo_.cwiseMin(v);
        boundsHi_ = boundsHi_.cwiseMax(v);
    }
    mass_ = meshMassProperties(model->mesh());
    double edges = 0;
    for (const Index3& t : model->mesh().triangles()) {
        double longest = 0;
        for (int k = 0; k < 3; ++k) {
            longest = std::max(longest, (vertices[t[(k + 1) % 3]] - vertices[t[k]]).norm());
        }
        edges += longest;
    }
    const std::size_t count = model->mesh().triangleCount();
    meanTriangleSize_ = count > 0 ? edges / double(count) : 0;
    scaled_ = std::move(model);
}

void MeshShape::getAabb(const btTransform& t, btVector3& aabbMin, btVector3& aabbMax) const {
    Eigen::Matrix3d basis;
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) {
            basis(r, c) = double(t.getBasis()[r][c]);
        }
    }
    const Vec3 origin = toVec3(t.getOrigin());
    // The root OBB moved: centre and half extents along the world axes.
    const Vec3 obbCenter = basis * root_.center.cast<double>() + origin;
    const Vec3 obbHalf = (basis * root_.axis0.cast<double>()).cwiseAbs() * double(root_.half.x()) +
                         (basis * root_.axis1.cast<double>()).cwiseAbs() * double(root_.half.y()) +
                         (basis * root_.axis2().cast<double>()).cwiseAbs() * double(root_.half.z());
    // The vertex box moved.
    const Vec3 boxCenter = basis * (0.5 * (boundsLo_ + boundsHi_)) + origin;
    const Vec3 boxHalf = basis.cwiseAbs() * (0.5 * (boundsHi_ - boundsLo_));
    // Double rounding of the sums above: a relative pad far below float resolution.
    const Vec3 pad = (obbCenter.cwiseAbs() + obbHalf + boxCenter.cwiseAbs() + boxHalf) * 1e-12 +
                     Vec3::Constant(double(getMargin()));
    const Vec3 lo = (obbCenter - obbHalf).cwiseMax(boxCenter - boxHalf) - pad;
    const Vec3 hi = (obbCenter + obbHalf).cwiseMin(boxCenter + boxHalf) + pad;
    aabbMin.setValue(roundOutward(lo.x(), false), roundOutward(lo.y(), false),
                     roundOutward(lo.z(), false));
    aabbMax.setValue(roundOutward(hi.x(), true), roundOutward(hi.y(), true),
                     roundOutward(hi.z(), true));
}

void MeshShape::processAllTriangles(btTriangleCallback* callback, const btVector3& aabbMin,
                                    const btVector3& aabbMax) const {
    const Vec3 lo = toVec3(aabbMin);
    const Vec3 hi = toVec3(aabbMax);
    const ObbTree& tree = model().tree<ObbNode>();
    const std::vector<ObbNode>& nodes = tree.nodes();
    const std::vector<narrowphase::Vec3>& vertices = model().mesh().vertices();
    // Depth-first walk: the first child is the next node, the second `link.right()`.
    std::vector<std::int32_t> stack{0};
    btVector3 triangle[3];
    while (!stack.empty()) {
        const std::int32_t index = stack.back();
        stack.pop_back();
        const ObbNode& node = nodes[index];
        Vec3 nodeLo, nodeHi;
        obbBounds(node.volume, nodeLo, nodeHi);
        if ((nodeLo.array() > hi.array()).any() || (lo.array() > nodeHi.array()).any()) {
            continue;
        }
        if (!node.link.isLeaf()) {
            stack.push_back(node.link.right());
            stack.push_back(index + 1);
            continue;
        }
        for (int k = 0; k < node.link.count(); ++k) {
            const std::int32_t slot = node.link.firstSlot() + k;
            const Index3& t = tree.slotTriangles()[slot];
            const Vec3& p = vertices[t[0]];
            const Vec3& q = vertices[t[1]];
            const Vec3& r = vertices[t[2]];
            const Vec3 tlo = p.cwiseMin(q).cwiseMin(r);
            const Vec3 thi = p.cwiseMax(q).cwiseMax(r);
            if ((tlo.array() > hi.array()).any() || (lo.array() > thi.array()).any()) {
                continue;
            }
            triangle[0] = toBt(p);
            triangle[1] = toBt(q);
            triangle[2] = toBt(r);
            callback->processTriangle(triangle, 0, tree.triangleOrder()[slot]);
        }
    }
}

void MeshShape::calculateLocalInertia(btScalar mass, btVector3& inertia) const {
    if (mass_.closed) {
        const double density = double(mass) / mass_.volume;
        inertia.setValue(btScalar(density * mass_.inertia(0, 0)),
                         btScalar(density * mass_.inertia(1, 1)),
                         btScalar(density * mass_.inertia(2, 2)));
        return;
    }
    const Vec3 size = boundsHi_ - boundsLo_;
    const double m = double(mass) / 12;
    inertia.setValue(btScalar(m * (size.y() * size.y() + size.z() * size.z())),
                     btScalar(m * (size.x() * size.x() + size.z() * size.z())),
                     btScalar(m * (size.x() * size.x() + size.y() * size.y())));
}

void MeshShape::setLocalScaling(const btVector3& scaling) {
    for (int k = 0; k < 3; ++k) {
        if (!(std::isfinite(double(scaling[k])) && scaling[k] > 0)) {
            throw std::invalid_argument("kolize::MeshShape: mesh '" + base_->mesh().name() +
                                        "': local scaling " + formatScale(scaling) +
                                        " must be finite and positive in every component");
        }
    }
    if (scaling == scaling_) {
        return;
    }
    if (scaling == btVector3(1, 1, 1)) {
        adoptModel(base_);
    } else {
        const TriangleMesh& mesh = base_->mesh();
        std::vector<Vec3> vertices = mesh.vertices();
        const Vec3 factor = toVec3(scaling);
        for (Vec3& v : vertices) {
            v = v.cwiseProduct(factor);
        }
        TriangleMesh scaled(mesh.name(), std::move(vertices), mesh.triangles());
        adoptModel(std::make_shared<const MeshModel>(
            std::make_shared<const TriangleMesh>(std::move(scaled)), base_->settings()));
    }
    scaling_ = scaling;
}

// ---------------------------------------------------------------------------------------
// MeshMeshAlgorithm

/// A mesh's step for the time of impact: its vertices (model frame) and its poses at the
/// start and at the end of the step.
struct MeshStep {
    const std::vector<Vec3>* vertices = nullptr;
    Pose start, end;
};

/// The two steps and their moving meshes (buffers reused from call to call).
struct CcdBuffers {
    MeshStep stepA, stepB;
    ccd::MovingMesh movingA, movingB;  ///< the meshCcd input
};

struct MeshContactAlgorithm::State {
    explicit State(std::shared_ptr<detail::StagePlanner> planner) : stages(std::move(planner)) {}
    detail::PairStages stages;  ///< the stage planner's decisions for this pair
    narrowphase::MeshQuery query;
    std::vector<MeshContact> contacts;
    CcdBuffers ccd;                     ///< filled by calculateTimeOfImpact
    std::vector<Vec3> sceneryVertices;  ///< scenery triangles' vertices (world)
    /// BvhMeshAlgorithm's model of the last call's scenery triangles, with their (part,
    /// triangle) ids: the next call reuses it when it collects the same triangles, bit for
    /// bit and in the same order, for the same tree settings (a body resting or sliding on
    /// scenery keeps its triangles for many steps; building the tree was half of such a
    /// call).
    std::shared_ptr<const MeshModel> sceneryModel;
    std::vector<std::pair<int, int>> sceneryIds;
    std::vector<Vec3> sceneryCorners;  ///< their corners (world), three per triangle
};

namespace {

/// Moves over the step in the time of impact's sense (bullet_mesh.h).
bool movesOverStep(const btCollisionObject& object) {
    return object.getInternalType() == btCollisionObject::CO_RIGID_BODY && object.isActive() &&
           !object.isStaticOrKinematicObject();
}

const btTransform& endOfStep(const btCollisionObject& object) {
    return movesOverStep(object) ? object.getInterpolationWorldTransform()
                                 : object.getWorldTransform();
}

/// Turns of more than this (radians) over the step are cut into pieces of at most this
/// turn, each a chord: a vertex at distance r from the axis leaves its arc by at most
/// r (1 - cos(kMaxTurn / 2)), about 1.2e-3 r.
constexpr double kMaxTurn = 0.1;
/// Bullet's integrator turns a body by at most pi/4 per step (ANGULAR_MOTION_THRESHOLD),
/// which is 8 pieces; other ends of a step (a user's transforms) are cut into at most 64.
constexpr int kMaxPieces = 64;

/// The pose at `f` of the step from `start` to `end`: the translation on the segment, the
/// rotation at constant angular velocity (slerp), as Bullet's integrator moves a body.
Pose poseAt(const Pose& start, const Pose& end, double f) {
    if (f <= 0) {
        return start;
    }
    if (f >= 1) {
        return end;
    }
    Pose pose;
    pose.translation = start.translation + f * (end.translation - start.translation);
    const Eigen::Quaterniond q0(start.rotation), q1(end.rotation);
    pose.rotation = q0.slerp(f, q1).normalized().toRotationMatrix();
    return pose;
}

double turnOf(const MeshStep& step) {
    return Eigen::Quaterniond(step.start.rotation)
        .angularDistance(Eigen::Quaterniond(step.end.rotation));
}

/// The step's vertices at fractions f0 and f1 (world frame) into `out`. False when one is
/// not finite (meshCcd refuses those).
bool place(const MeshStep& step, double f0, double f1, ccd::MovingMesh& out) {
    const Pose p0 = poseAt(step.start, step.end, f0);
    const Pose p1 = poseAt(step.start, step.end, f1);
    const std::vector<Vec3>& vertices = *step.vertices;
    out.start.resize(vertices.size());
    out.end.resize(vertices.size());
    bool finite = true;
    for (std::size_t i = 0; i < vertices.size(); ++i) {
        out.start[i] = p0.rotation * vertices[i] + p0.translation;
        out.end[i] = p1.rotation * vertices[i] + p1.translation;
        finite = finite && out.start[i].allFinite() && out.end[i].allFinite();
    }
    return finite;
}

void setTriangles(const std::vector<Index3>& triangles, ccd::MovingMesh& out) {
    out.triangles.assign(triangles.begin(), triangles.end());
}

/// The step of `object` with `vertices`; false for a non-finite transform.
bool stepOf(const btCollisionObject& object, const std::vector<Vec3>& vertices, MeshStep& out) {
    if (!finitePose(object.getWorldTransform()) || !finitePose(endOfStep(object))) {
        return false;
    }
    out.vertices = &vertices;
    out.start = toPose(object.getWorldTransform());
    out.end = toPose(endOfStep(object));
    return true;
}

/// The box (scenery frame) around `shape` at the start and at the end of `mesh`'s step.
void sweptBoxIn(const MeshShape& shape, const btCollisionObject& mesh, const btTransform& scenery,
                btVector3& lo, btVector3& hi) {
    const btTransform inverse = scenery.inverse();
    shape.getAabb(inverse * mesh.getWorldTransform(), lo, hi);
    btVector3 endLo, endHi;
    shape.getAabb(inverse * endOfStep(mesh), endLo, endHi);
    lo.setMin(endLo);
    hi.setMax(endHi);
}

/// The smallest CCD motion threshold of the bodies in the pair that exceed theirs.
double ccdThresholdOfPair(const btCollisionObject& a, const btCollisionObject& b) {
    double threshold = std::numeric_limits<double>::infinity();
    for (const btCollisionObject* body : {&a, &b}) {
        if (exceedsCcdMotionThreshold(*body)) {
            threshold = std::min(threshold, std::sqrt(double(body->getCcdSquareMotionThreshold())));
        }
    }
    return threshold;
}

/// Whether some vertex of `a` moves towards `b` along one of the contact `normals` (from
/// a towards b), relative to b, by more than `limit` over the step.
bool drivesIn(const std::vector<Vec3>& normals, const ccd::MovingMesh& a, const ccd::MovingMesh& b,
              double limit) {
    for (const Vec3& normal : normals) {
        double forwardA = -std::numeric_limits<double>::infinity();
        for (std::size_t i = 0; i < a.start.size(); ++i) {
            forwardA = std::max(forwardA, (a.end[i] - a.start[i]).dot(normal));
        }
        double forwardB = std::numeric_limits<double>::infinity();
        for (std::size_t i = 0; i < b.start.size(); ++i) {
            forwardB = std::min(forwardB, (b.end[i] - b.start[i]).dot(normal));
        }
        if (forwardA - forwardB > limit) {
            return true;
        }
    }
    return false;
}

}  // namespace

bool exceedsCcdMotionThreshold(const btCollisionObject& object) {
    if (!movesOverStep(object)) {
        return false;
    }
    const btScalar threshold = object.getCcdSquareMotionThreshold();
    const btScalar motion = (object.getInterpolationWorldTransform().getOrigin() -
                             object.getWorldTransform().getOrigin())
                                .length2();
    return threshold > 0 && threshold < motion;
}

namespace {

/// The time of impact of the steps in `s` for the bodies `body0` (A) and `body1` (B), as
/// MeshContactAlgorithm's comment says; `normals` are the normals (from A towards B) of the
/// pair's contacts at the start of the step, empty when it did not touch. `hit` tells
/// whether meshCcd found a contact.
/// Whether the steps in `s` cannot give a time (a non-finite vertex) or the pair's contacts
/// at the start hold it: in contact, the contacts hold the pair unless a vertex drives in
/// along their normals by more than a CCD threshold (a body turning about its contact sweeps
/// the rest of itself into, and through, the other; sliding or leaving does not). Places
/// both steps whole.
bool noTimeOrHeld(CcdBuffers& s, const std::vector<Vec3>& normals, btCollisionObject* body0,
                  btCollisionObject* body1) {
    if (!place(s.stepA, 0, 1, s.movingA) || !place(s.stepB, 0, 1, s.movingB)) {
        return true;
    }
    return !normals.empty() &&
           !drivesIn(normals, s.movingA, s.movingB, ccdThresholdOfPair(*body0, *body1));
}

/// The distance between the features of `contact` where the piece starts (movingA and
/// movingB's start positions).
double startDistance(const ccd::MeshContact& contact, const ccd::MovingMesh& a,
                     const ccd::MovingMesh& b) {
    using narrowphase::Triangle;
    auto corners = [](const ccd::MovingMesh& m, int t) {
        const std::array<int, 3>& v = m.triangles[std::size_t(t)];
        return Triangle{m.start[std::size_t(v[0])], m.start[std::size_t(v[1])],
                        m.start[std::size_t(v[2])]};
    };
    auto point = [](const ccd::MovingMesh& m, int v) {
        const Vec3& p = m.start[std::size_t(v)];
        return Triangle{p, p, p};
    };
    auto segment = [](const ccd::MovingMesh& m, const std::array<int, 2>& e) {
        const Vec3& p = m.start[std::size_t(e[0])];
        const Vec3& q = m.start[std::size_t(e[1])];
        return Triangle{p, q, q};
    };
    Triangle p, q;
    switch (contact.features) {
        case ccd::ContactFeatures::kVertexAFaceB:
            p = point(a, contact.a[0]);
            q = corners(b, contact.b[0]);
            break;
        case ccd::ContactFeatures::kFaceAVertexB:
            p = corners(a, contact.a[0]);
            q = point(b, contact.b[0]);
            break;
        case ccd::ContactFeatures::kEdgeEdge:
            p = segment(a, contact.a);
            q = segment(b, contact.b);
            break;
    }
    return narrowphase::trianglesIntersect(p, q) ? 0.0
                                                 : narrowphase::triangleDistance(p, q).distance;
}

/// The fraction of the step handed to Bullet for a contact at `fraction`: rounded down, so
/// no later than the contact; each moving body's hit fraction at most that.
btScalar stopAt(double fraction, btCollisionObject* body0, btCollisionObject* body1) {
    const btScalar toi = std::clamp(roundOutward(fraction, false), btScalar(0), btScalar(1));
    for (btCollisionObject* body : {body0, body1}) {
        if (movesOverStep(*body) && body->getHitFraction() > toi) {
            body->setHitFraction(toi);
        }
    }
    return toi;
}

/// How far the features of `contact` move into the other mesh over the piece: their
/// displacement relative to each other (A's minus B's, each feature's mean) along the
/// contact normal (from A towards B) that it follows most.
double inwardMotion(const ccd::MeshContact& contact, const ccd::MovingMesh& a,
                    const ccd::MovingMesh& b, const std::vector<Vec3>& normals) {
    auto moved = [](const ccd::MovingMesh& m, const int* vertices, int count) {
        Vec3 sum = Vec3::Zero();
        for (int k = 0; k < count; ++k) {
            sum += m.end[std::size_t(vertices[k])] - m.start[std::size_t(vertices[k])];
        }
        return Vec3(sum / count);
    };
    Vec3 relative = Vec3::Zero();
    switch (contact.features) {
        case ccd::ContactFeatures::kVertexAFaceB:
            relative = moved(a, contact.a.data(), 1) -
                       moved(b, b.triangles[std::size_t(contact.b[0])].data(), 3);
            break;
        case ccd::ContactFeatures::kFaceAVertexB:
            relative = moved(a, a.triangles[std::size_t(contact.a[0])].data(), 3) -
                       moved(b, contact.b.data(), 1);
            break;
        case ccd::ContactFeatures::kEdgeEdge:
            relative = moved(a, contact.a.data(), 2) - moved(b, contact.b.data(), 2);
            break;
    }
    double inward = -std::numeric_limits<double>::infinity();
    for (const Vec3& normal : normals) {
        inward = std::max(inward, relative.dot(normal));
    }
    return inward;
}

/// Whether the plane of the features of `contact` where the piece starts (the face's, or
/// the one both edges lie along) is within 45 degrees of one of the contact `normals`: the
/// face or edges of a contact, not of another surface (a wall beside a floor).
bool facesAContact(const ccd::MeshContact& contact, const ccd::MovingMesh& a,
                   const ccd::MovingMesh& b, const std::vector<Vec3>& normals) {
    auto faceNormal = [](const ccd::MovingMesh& m, int t) {
        const std::array<int, 3>& v = m.triangles[std::size_t(t)];
        const Vec3& p = m.start[std::size_t(v[0])];
        return Vec3((m.start[std::size_t(v[1])] - p).cross(m.start[std::size_t(v[2])] - p));
    };
    auto edge = [](const ccd::MovingMesh& m, const std::array<int, 2>& e) {
        return Vec3(m.start[std::size_t(e[1])] - m.start[std::size_t(e[0])]);
    };
    Vec3 across = Vec3::Zero();
    switch (contact.features) {
        case ccd::ContactFeatures::kVertexAFaceB:
            across = faceNormal(b, contact.b[0]);
            break;
        case ccd::ContactFeatures::kFaceAVertexB:
            across = faceNormal(a, contact.a[0]);
            break;
        case ccd::ContactFeatures::kEdgeEdge:
            across = edge(a, contact.a).cross(edge(b, contact.b));
            break;
    }
    const double size = across.norm();
    if (!(size > 0)) {
        return false;
    }
    for (const Vec3& normal : normals) {
        if (std::fabs(across.dot(normal)) >= std::sqrt(0.5) * size * normal.norm()) {
            return true;
        }
    }
    return false;
}

/// Contacts of features that already touch where a piece starts that a pair in contact may
/// skip over the step: at most this many, then the next one counts (a stop too many rather
/// than a body through).
constexpr int kMaxTouchingSkipped = 8;

/// Features of a pair in contact within this distance of each other where the step starts
/// touch (are its contacts'): twice the pair's deepest contact.
double touchingWithin(double deepest) {
    return 2 * deepest + 1e-9;
}

btScalar piecewiseTimeOfImpact(CcdBuffers& s, const std::vector<Vec3>& normals, double touching,
                               btCollisionObject* body0, btCollisionObject* body1, bool& hit) {
    hit = false;
    if (noTimeOrHeld(s, normals, body0, body1)) {
        return btScalar(1);
    }
    const double turn = std::max(turnOf(s.stepA), turnOf(s.stepB));
    const int pieces = std::clamp(int(std::ceil(turn / kMaxTurn)), 1, kMaxPieces);
    int skipped = 0;
    for (int k = 0; k < pieces; ++k) {
        const double f0 = double(k) / pieces, f1 = double(k + 1) / pieces;
        if (pieces > 1 &&
            (!place(s.stepA, f0, f1, s.movingA) || !place(s.stepB, f0, f1, s.movingB))) {
            return btScalar(1);
        }
        // A pair in contact: features that already touch (within `touching`) where the
        // piece starts, lie across one of the contacts' normals and do not move into each
        // other along any of them are the contacts' (a vertex the solver lifts out of the other
        // crosses its face on the way out, a sliding edge crosses the other's inner
        // edges); their crossings are left to the contacts, and the search goes on after
        // them for the first contact of the rest. (Counted as impacts, they stopped a body
        // turning about its contact at once, every step, while its velocity grew.) A
        // touching vertex driven on through a thin wall's far face still counts.
        ccd::MeshCcdSettings settings;
        ccd::MeshContact contact = ccd::meshCcd(s.movingA, s.movingB, settings);
        while (contact.hit && !normals.empty() && skipped < kMaxTouchingSkipped &&
               startDistance(contact, s.movingA, s.movingB) <= touching &&
               !(inwardMotion(contact, s.movingA, s.movingB, normals) > 0) &&
               facesAContact(contact, s.movingA, s.movingB, normals)) {
            ++skipped;
            settings.primitive.min_time = contact.toi + settings.primitive.toi_tolerance;
            if (!(settings.primitive.min_time < 1)) {
                contact.hit = false;  // skipped to the piece's end
                break;
            }
            contact = ccd::meshCcd(s.movingA, s.movingB, settings);
        }
        if (!contact.hit) {
            continue;
        }
        hit = true;
        return stopAt(f0 + contact.toi * (f1 - f0), body0, body1);
    }
    return btScalar(1);
}

/// The plane of `plane` at `planePose` in the world, n . x = c with n unit; false for a
/// normal that is zero or not finite, or a constant that is not finite.
bool worldPlane(const btStaticPlaneShape& plane, const Pose& planePose, Vec3& n, double& c) {
    const Vec3 given = toVec3(plane.getPlaneNormal());
    const double length = given.norm();
    if (!(length > 0) || !std::isfinite(length) ||
        !std::isfinite(double(plane.getPlaneConstant()))) {
        return false;
    }
    n = planePose.rotation * (given / length);
    c = double(plane.getPlaneConstant()) / length + n.dot(planePose.translation);
    return true;
}

/// The normals of a pair's contacts at the start of the step (`normals`), and the distance
/// within which features touch: twice the deepest contact's depth.
double touchingOfContacts(const std::vector<MeshContact>& contacts, std::vector<Vec3>& normals) {
    double deepest = 0;
    for (const MeshContact& contact : contacts) {
        normals.push_back(contact.normal);
        deepest = std::max(deepest, contact.depth);
    }
    return touchingWithin(deepest);
}

/// The time of impact of a mesh body's step (s.stepA, world frame) with a static plane, a
/// half-space as for its contacts (planeContacts): the first time a vertex of its triangles
/// that starts above the plane by more than `touching` reaches it, on the chords of the
/// step (the linear motion of each piece, as for meshCcd). Vertices already in the
/// half-space or touching it are the contacts'; a pair in contact (`normals`, from the mesh
/// into the plane) is left to them unless a vertex drives in along one by more than a CCD
/// threshold.
btScalar planeTimeOfImpact(const btStaticPlaneShape& plane, const btTransform& planeTransform,
                           CcdBuffers& s, const std::vector<Index3>& triangles,
                           const std::vector<Vec3>& normals, double touching,
                           btCollisionObject* body0, btCollisionObject* body1, bool& hit) {
    hit = false;
    Vec3 n;
    double c = 0;
    if (!worldPlane(plane, toPose(planeTransform), n, c) || !place(s.stepA, 0, 1, s.movingA)) {
        return btScalar(1);
    }
    if (!normals.empty()) {
        double forward = -std::numeric_limits<double>::infinity();
        for (const Vec3& normal : normals) {
            for (std::size_t i = 0; i < s.movingA.start.size(); ++i) {
                forward = std::max(forward, (s.movingA.end[i] - s.movingA.start[i]).dot(normal));
            }
        }
        if (!(forward > ccdThresholdOfPair(*body0, *body1))) {
            return btScalar(1);
        }
    }
    const int pieces = std::clamp(int(std::ceil(turnOf(s.stepA) / kMaxTurn)), 1, kMaxPieces);
    for (int k = 0; k < pieces; ++k) {
        const double f0 = double(k) / pieces, f1 = double(k + 1) / pieces;
        if (pieces > 1 && !place(s.stepA, f0, f1, s.movingA)) {
            return btScalar(1);
        }
        double first = 2;
        for (const Index3& t : triangles) {
            for (const std::int32_t v : t) {
                const double h0 = n.dot(s.movingA.start[std::size_t(v)]) - c;
                const double h1 = n.dot(s.movingA.end[std::size_t(v)]) - c;
                if (h0 > touching && h1 <= 0) {
                    first = std::min(first, h0 / (h0 - h1));
                }
            }
        }
        if (first > 1) {
            continue;
        }
        hit = true;
        return stopAt(f0 + first * (1 - 1e-9) * (f1 - f0), body0, body1);  // a hair earlier
    }
    return btScalar(1);
}

}  // namespace

btScalar MeshContactAlgorithm::reportTimeOfImpact(btCollisionObject* body0,
                                                  btCollisionObject* body1) {
    State& s = *state_;
    std::vector<Vec3> normals;
    const double touching = touchingOfContacts(s.contacts, normals);
    bool hit = false;
    const btScalar toi = piecewiseTimeOfImpact(s.ccd, normals, touching, body0, body1, hit);
    if (hit) {
        s.stages.countTimeOfImpactHit();
    }
    return toi;
}

MeshContactAlgorithm::MeshContactAlgorithm(const btCollisionAlgorithmConstructionInfo& ci,
                                           const btCollisionObjectWrapper* body0,
                                           const btCollisionObjectWrapper* body1)
    : btActivatingCollisionAlgorithm(ci, body0, body1),
      manifold_(ci.m_manifold),
      state_(std::make_unique<State>(detail::plannerOf(ci.m_dispatcher1))) {
    if (!manifold_) {
        manifold_ =
            m_dispatcher->getNewManifold(body0->getCollisionObject(), body1->getCollisionObject());
        ownManifold_ = true;
    }
}

MeshContactAlgorithm::~MeshContactAlgorithm() {
    if (ownManifold_ && manifold_) {
        m_dispatcher->releaseManifold(manifold_);
    }
}

const std::vector<MeshContact>& MeshContactAlgorithm::lastContacts() const {
    return state_->contacts;
}

void MeshContactAlgorithm::getAllContactManifolds(btManifoldArray& manifolds) {
    if (manifold_ && ownManifold_) {
        manifolds.push_back(manifold_);
    }
}

MeshMeshAlgorithm::MeshMeshAlgorithm(const btCollisionAlgorithmConstructionInfo& ci,
                                     const btCollisionObjectWrapper* body0,
                                     const btCollisionObjectWrapper* body1)
    : MeshContactAlgorithm(ci, body0, body1) {}

void MeshMeshAlgorithm::processCollision(const btCollisionObjectWrapper* body0,
                                         const btCollisionObjectWrapper* body1,
                                         const btDispatcherInfo&, btManifoldResult* resultOut) {
    state_->contacts.clear();
    resultOut->setPersistentManifold(manifold_);
    // The query's frame (its A, the contacts' X) is the mesh with the larger triangles: the
    // other mesh's triangles get their boxes in that frame, where small ones stay tight, while
    // a large triangle turned into a small-triangled mesh's frame gets a box that meets
    // everything (a body resting on a box mesh's face: 14x the exact tests in that order).
    // Bullet's order (body0, body1) follows creation, which says nothing about it.
    const auto* shape0 = static_cast<const MeshShape*>(body0->getCollisionShape());
    const auto* shape1 = static_cast<const MeshShape*>(body1->getCollisionShape());
    const bool xIsBody0 = shape0->meanTriangleSize() >= shape1->meanTriangleSize();
    const btCollisionObjectWrapper* bodyX = xIsBody0 ? body0 : body1;
    const btCollisionObjectWrapper* bodyY = xIsBody0 ? body1 : body0;
    const MeshShape* shapeX = xIsBody0 ? shape0 : shape1;
    const MeshShape* shapeY = xIsBody0 ? shape1 : shape0;
    bool touching = false;
    // A body whose transform went non-finite gets no contacts (the query refuses it).
    if (finitePose(bodyX->getWorldTransform()) && finitePose(bodyY->getWorldTransform())) {
        const Pose poseX = toPose(bodyX->getWorldTransform());
        const Pose poseY = toPose(bodyY->getWorldTransform());
        QuerySettings base = contactSettings();
        base.margin = contactMargin(state_->stages, manifold_, resultOut);
        const QuerySettings settings = state_->stages.plan(
            base, shapeX->model().mesh().triangleCount(), shapeY->model().mesh().triangleCount());
        const QueryResult& result = state_->query.run(shapeX->model(), poseX, shapeY->model(),
                                                      poseY, settings, queryScratch);
        touching = result.intersecting;
        if (result.intersecting || !result.near.empty()) {
            buildContacts(result, shapeX->model().mesh(), shapeY->model().mesh(),
                          RelativePose(poseX, poseY), sidesOf(*shapeX), sidesOf(*shapeY),
                          breakingThreshold(manifold_), contactScratch, state_->contacts);
            toWorld(state_->contacts, poseX);
            dropStalePoints(ownManifold_, resultOut);
            emit(state_->contacts, xIsBody0, resultOut);
            if (!xIsBody0) {
                asBody0First(state_->contacts);  // lastContacts' X is body0
            }
        }
        state_->stages.report(detail::PairKind::kMeshMesh, result.counters,
                              state_->contacts.size());
    }
    if (ownManifold_) {
        resultOut->refreshContactPoints();
        if (!touching) {
            keptPointsAtMostTouch(manifold_);
        }
    }
}

btScalar MeshMeshAlgorithm::calculateTimeOfImpact(btCollisionObject* body0,
                                                  btCollisionObject* body1, const btDispatcherInfo&,
                                                  btManifoldResult*) {
    const bool slow = !exceedsCcdMotionThreshold(*body0) && !exceedsCcdMotionThreshold(*body1);
    state_->stages.countTimeOfImpact(slow);
    if (slow) {
        return btScalar(1);
    }
    const TriangleMesh& meshA =
        static_cast<const MeshShape*>(body0->getCollisionShape())->model().mesh();
    const TriangleMesh& meshB =
        static_cast<const MeshShape*>(body1->getCollisionShape())->model().mesh();
    if (!stepOf(*body0, meshA.vertices(), state_->ccd.stepA) ||
        !stepOf(*body1, meshB.vertices(), state_->ccd.stepB)) {
        return btScalar(1);
    }
    setTriangles(meshA.triangles(), state_->ccd.movingA);
    setTriangles(meshB.triangles(), state_->ccd.movingB);
    return reportTimeOfImpact(body0, body1);
}

btCollisionAlgorithm* MeshMeshAlgorithm::CreateFunc::CreateCollisionAlgorithm(
    btCollisionAlgorithmConstructionInfo& ci, const btCollisionObjectWrapper* body0,
    const btCollisionObjectWrapper* body1) {
    void* memory = ci.m_dispatcher1->allocateCollisionAlgorithm(sizeof(MeshMeshAlgorithm));
    return new (memory) MeshMeshAlgorithm(ci, body0, body1);
}

// ---------------------------------------------------------------------------------------
// ConvexMeshAlgorithm: btConvexConcaveCollisionAlgorithm's triangle path, never its SDF one.

ConvexMeshAlgorithm::ConvexMeshAlgorithm(const btCollisionAlgorithmConstructionInfo& ci,
                                         const btCollisionObjectWrapper* body0,
                                         const btCollisionObjectWrapper* body1, bool meshFirst)
    : btActivatingCollisionAlgorithm(ci, body0, body1),
      triangles_(ci.m_dispatcher1, body0, body1, meshFirst),
      meshFirst_(meshFirst) {}

struct ConvexMeshAlgorithm::Ccd {
    const btCollisionShape* shape = nullptr;  ///< whose surface `polytope` is
    btVector3 scaling, lo, hi;                ///< its scaling and local box then
    btScalar margin = 0;                      ///< its margin then
    detail::EnclosingPolytope polytope;
    CcdBuffers buffers;
    std::vector<Vec3> normals;
};

ConvexMeshAlgorithm::~ConvexMeshAlgorithm() = default;

void ConvexMeshAlgorithm::processCollision(const btCollisionObjectWrapper* body0,
                                           const btCollisionObjectWrapper* body1,
                                           const btDispatcherInfo& info,
                                           btManifoldResult* resultOut) {
    const btCollisionObjectWrapper* convex = meshFirst_ ? body1 : body0;
    const btCollisionObjectWrapper* mesh = meshFirst_ ? body0 : body1;
    const auto* shape = static_cast<const MeshShape*>(mesh->getCollisionShape());
    detail::plannerOf(m_dispatcher)->add(detail::StagePlanner::k_convex_mesh_queries, 1);
    resultOut->setPersistentManifold(triangles_.m_manifoldPtr);
    triangles_.setTimeStepAndCounters(shape->getMargin(), info, convex, mesh, resultOut);
    triangles_.m_manifoldPtr->setBodies(convex->getCollisionObject(), mesh->getCollisionObject());
    shape->processAllTriangles(&triangles_, triangles_.getAabbMin(), triangles_.getAabbMax());
    resultOut->refreshContactPoints();
    triangles_.clearWrapperData();
}

btScalar ConvexMeshAlgorithm::calculateTimeOfImpact(btCollisionObject* body0,
                                                    btCollisionObject* body1,
                                                    const btDispatcherInfo&, btManifoldResult*) {
    if (!exceedsCcdMotionThreshold(*body0) && !exceedsCcdMotionThreshold(*body1)) {
        return btScalar(1);
    }
    btCollisionObject* meshObject = meshFirst_ ? body0 : body1;
    btCollisionObject* convexObject = meshFirst_ ? body1 : body0;
    const btCollisionShape* convexShape = convexObject->getCollisionShape();
    if (!convexShape || !convexShape->isConvex()) {
        return btScalar(1);
    }
    const auto& convex = *static_cast<const btConvexShape*>(convexShape);
    if (!ccd_) {
        ccd_ = std::make_unique<Ccd>();
    }
    Ccd& c = *ccd_;
    btTransform identity;
    identity.setIdentity();
    btVector3 lo, hi;
    convex.getAabb(identity, lo, hi);
    // Rebuilt for another shape, or one that changed (scaled, margin, box), or no longer fits.
    if (c.shape != convexShape || c.scaling != convex.getLocalScaling() ||
        c.margin != convex.getMargin() || c.lo != lo || c.hi != hi ||
        !detail::encloses(c.polytope, convex)) {
        c.shape = nullptr;
        if (!detail::enclosingPolytope(convex, c.polytope)) {
            return btScalar(1);
        }
        c.shape = convexShape;
        c.scaling = convex.getLocalScaling();
        c.margin = convex.getMargin();
        c.lo = lo;
        c.hi = hi;
    }
    const TriangleMesh& mesh =
        static_cast<const MeshShape*>(meshObject->getCollisionShape())->model().mesh();
    if (!stepOf(*meshObject, mesh.vertices(), c.buffers.stepA) ||
        !stepOf(*convexObject, c.polytope.vertices, c.buffers.stepB)) {
        return btScalar(1);
    }
    setTriangles(mesh.triangles(), c.buffers.movingA);
    setTriangles(c.polytope.triangles, c.buffers.movingB);
    // The manifold's bodies are (convex, mesh): its normals on B point from the mesh (A
    // here) towards the convex (B here).
    c.normals.clear();
    double deepest = 0;
    if (const btPersistentManifold* manifold = triangles_.m_manifoldPtr) {
        for (int i = 0; i < manifold->getNumContacts(); ++i) {
            c.normals.push_back(toVec3(manifold->getContactPoint(i).m_normalWorldOnB));
            deepest = std::max(deepest, -double(manifold->getContactPoint(i).getDistance()));
        }
    }
    const double touching = touchingWithin(deepest);
    const btScalar fractionMesh = meshObject->getHitFraction();
    const btScalar fractionConvex = convexObject->getHitFraction();
    if (!(c.polytope.standoff > 0)) {
        bool hit = false;  // the surface is the shape's own faces
        return piecewiseTimeOfImpact(c.buffers, c.normals, touching, meshObject, convexObject, hit);
    }
    // The surface stands off a round shape: advance to the shape itself, from the time
    // against the surface, or from the start when the mesh may start inside the surface
    // (nearer the shape than the standoff: the surface then has no entering event).
    const auto* meshShape = static_cast<const btConcaveShape*>(meshObject->getCollisionShape());
    // 5e-4 of the convex shape's angular motion disc: Bullet's float GJK errs by about 1e-4
    // of a cone's or cylinder's size at small gaps (a tolerance of the mesh's size, smaller,
    // made times against them up to 1.2 mm late).
    const double tolerance = 5e-4 * double(convex.getAngularMotionDisc());
    const btTransform& convexStart = convexObject->getWorldTransform();
    const btTransform& meshStart = meshObject->getWorldTransform();
    const double reach = c.polytope.standoff + tolerance;
    btScalar from = 0;
    if (detail::nearestDistance(convex, convexStart, *meshShape, meshStart, reach) <= reach) {
        if (noTimeOrHeld(c.buffers, c.normals, meshObject, convexObject)) {
            return btScalar(1);
        }
    } else {
        bool hit = false;
        from = piecewiseTimeOfImpact(c.buffers, c.normals, touching, meshObject, convexObject, hit);
        if (!hit) {
            return from;
        }
    }
    const double advanced =
        detail::advanceToContact(convex, {&convexStart, &endOfStep(*convexObject)}, *meshShape,
                                 {&meshStart, &endOfStep(*meshObject)}, double(from), tolerance);
    const btScalar toi = std::clamp(roundOutward(advanced, false), from, btScalar(1));
    meshObject->setHitFraction(std::min(fractionMesh, toi));
    convexObject->setHitFraction(std::min(fractionConvex, toi));
    if (!movesOverStep(*meshObject)) {
        meshObject->setHitFraction(fractionMesh);
    }
    if (!movesOverStep(*convexObject)) {
        convexObject->setHitFraction(fractionConvex);
    }
    return toi;
}

void ConvexMeshAlgorithm::getAllContactManifolds(btManifoldArray& manifolds) {
    if (triangles_.m_manifoldPtr) {
        manifolds.push_back(triangles_.m_manifoldPtr);
    }
}

btCollisionAlgorithm* ConvexMeshAlgorithm::CreateFunc::CreateCollisionAlgorithm(
    btCollisionAlgorithmConstructionInfo& ci, const btCollisionObjectWrapper* body0,
    const btCollisionObjectWrapper* body1) {
    void* memory = ci.m_dispatcher1->allocateCollisionAlgorithm(sizeof(ConvexMeshAlgorithm));
    return new (memory) ConvexMeshAlgorithm(ci, body0, body1, false);
}

btCollisionAlgorithm* ConvexMeshAlgorithm::SwappedCreateFunc::CreateCollisionAlgorithm(
    btCollisionAlgorithmConstructionInfo& ci, const btCollisionObjectWrapper* body0,
    const btCollisionObjectWrapper* body1) {
    void* memory = ci.m_dispatcher1->allocateCollisionAlgorithm(sizeof(ConvexMeshAlgorithm));
    return new (memory) ConvexMeshAlgorithm(ci, body0, body1, true);
}

// ---------------------------------------------------------------------------------------
// BvhMeshAlgorithm

namespace {

/// Collects scenery triangles in world coordinates: their corners, three per triangle, and
/// their (part, triangle) ids; weld() makes a mesh of them.
class SceneryCollector : public btTriangleCallback {
  public:
    explicit SceneryCollector(const Pose& scenery) : pose_(scenery) {}
    void processTriangle(btVector3* triangle, int partId, int triangleIndex) override {
        const Vec3 local[3] = {toVec3(triangle[0]), toVec3(triangle[1]), toVec3(triangle[2])};
        add(local, partId, triangleIndex);
    }
    /// A triangle of corners in the scenery's frame. One with a corner that is not finite
    /// there or in the world (a heightfield's NaN height), or beyond the mesh's coordinate
    /// range, is left out, as Bullet's own algorithms leave it: it meets nothing, and a mesh
    /// of it would be refused (MeshError, which would unwind through Bullet's step).
    void add(const Vec3 (&local)[3], int partId, int triangleIndex) {
        Vec3 world[3];
        for (int k = 0; k < 3; ++k) {
            world[k] = pose_.rotation * local[k] + pose_.translation;
            if (!world[k].allFinite() ||
                world[k].cwiseAbs().maxCoeff() > TriangleMesh::kMaxCoordinate) {
                return;
            }
        }
        corners.insert(corners.end(), world, world + 3);
        ids.emplace_back(partId, triangleIndex);
    }
    /// The corners as a mesh: vertices welded where exactly equal, in the order of their
    /// first use, and the triangles indexing them.
    void weld(std::vector<Vec3>& vertices, std::vector<Index3>& triangles) const {
        std::map<std::array<double, 3>, std::int32_t> index;
        vertices.clear();
        triangles.clear();
        for (std::size_t i = 0; i < ids.size(); ++i) {
            Index3 t;
            for (int k = 0; k < 3; ++k) {
                const Vec3& corner = corners[3 * i + std::size_t(k)];
                const std::array<double, 3> key{corner.x(), corner.y(), corner.z()};
                auto [it, inserted] = index.emplace(key, std::int32_t(vertices.size()));
                if (inserted) {
                    vertices.push_back(corner);
                }
                t[k] = it->second;
            }
            triangles.push_back(t);
        }
    }
    std::vector<Vec3> corners;
    std::vector<std::pair<int, int>> ids;

  private:
    Pose pose_;
};

/// The scenery's triangles that may meet the box [lo, hi] (its own frame) into `collector`
/// (not a static plane's: a plane is a half-space, see planeContacts and planeTimeOfImpact).
void collectScenery(const btConcaveShape& scenery, const btVector3& lo, const btVector3& hi,
                    SceneryCollector& collector) {
    scenery.processAllTriangles(&collector, lo, hi);
}

/// A static plane is a half-space, as Bullet's own algorithms take it for convex shapes:
/// every vertex of the mesh on or below the plane is in it, whatever the body's side (its
/// two triangles as two-sided scenery pushed a body whose centre had sunk below the plane
/// further down, and one wholly below met nothing). The candidates are those vertices (or,
/// when none is, the ones within `margin` above), each at its own depth below the plane,
/// normal -n (from the mesh into the plane), the point halfway to the vertex's foot on the
/// plane; up to 4 chosen as for two meshes. In the mesh's frame (X = the mesh; the plane
/// has no triangle: Y's ids -1). Returns whether a vertex is in the half-space.
bool planeContacts(const btStaticPlaneShape& plane, const Pose& planePose, const MeshShape& shape,
                   const Pose& meshPose, double margin, double separation, ContactScratch& s,
                   std::vector<MeshContact>& out) {
    // The plane n . x = c in the world, then in the mesh's frame.
    Vec3 worldNormal;
    double worldConstant = 0;
    if (!worldPlane(plane, planePose, worldNormal, worldConstant)) {
        return false;  // no plane
    }
    const Vec3 n = meshPose.rotation.transpose() * worldNormal;
    const double c = worldConstant - worldNormal.dot(meshPose.translation);
    const narrowphase::MeshModel& model = shape.model();
    const std::vector<Index3>& triangles = model.mesh().triangles();
    if (triangles.empty() || n.dot(model.sphere().center) - c - model.sphere().radius > margin) {
        return false;  // every vertex above the plane by more than the margin
    }
    // The vertices of the triangles only (a vertex no triangle uses is no part of the
    // body, nor in its bounding sphere). s.insideOfA marks them: -2 seen, -3 not a
    // candidate, >= 0 the candidate's index; all -1 again on return.
    const std::vector<Vec3>& vertices = model.mesh().vertices();
    if (s.insideOfA.size() < vertices.size()) {
        s.insideOfA.resize(vertices.size(), -1);
    }
    if (s.heights.size() < vertices.size()) {
        s.heights.resize(vertices.size());
    }
    double lowest = std::numeric_limits<double>::infinity();
    for (const Index3& t : triangles) {
        for (const std::int32_t v : t) {
            if (s.insideOfA[v] == -1) {
                s.insideOfA[v] = -2;
                s.heights[v] = n.dot(vertices[v]) - c;
                lowest = std::min(lowest, s.heights[v]);
            }
        }
    }
    const bool inside = lowest <= 0;
    const double reach = inside ? 0.0 : margin;
    // Each point's triangle: the first of the mesh's triangles at its vertex.
    s.candidates.clear();
    for (std::size_t t = 0; t < triangles.size(); ++t) {
        for (const std::int32_t v : triangles[t]) {
            if (s.insideOfA[v] == -2) {
                const double height = s.heights[v];
                if (height <= reach) {
                    s.insideOfA[v] = int(s.candidates.size());
                    s.candidates.push_back({vertices[v] - (0.5 * height) * n, 0,
                                            TrianglePair{std::int32_t(t), -1}, -height});
                } else {
                    s.insideOfA[v] = -3;
                }
            }
        }
    }
    for (const Index3& t : triangles) {
        for (const std::int32_t v : t) {
            s.insideOfA[v] = -1;
        }
    }
    if (s.candidates.empty()) {
        return false;  // lowest above the margin
    }
    Patch patch;
    patch.normal = -n;
    patch.depth = -lowest;
    patch.valid = true;
    s.patches.assign(1, patch);
    chooseContacts(s, separation, out);
    for (MeshContact& contact : out) {
        contact.partY = -1;
        contact.triangleY = -1;
    }
    return inside;
}

}  // namespace

BvhMeshAlgorithm::BvhMeshAlgorithm(const btCollisionAlgorithmConstructionInfo& ci,
                                   const btCollisionObjectWrapper* body0,
                                   const btCollisionObjectWrapper* body1, bool meshFirst)
    : MeshContactAlgorithm(ci, body0, body1), meshFirst_(meshFirst) {}

void BvhMeshAlgorithm::processCollision(const btCollisionObjectWrapper* body0,
                                        const btCollisionObjectWrapper* body1,
                                        const btDispatcherInfo&, btManifoldResult* resultOut) {
    state_->contacts.clear();
    resultOut->setPersistentManifold(manifold_);
    const btCollisionObjectWrapper* meshWrap = meshFirst_ ? body0 : body1;
    const btCollisionObjectWrapper* sceneryWrap = meshFirst_ ? body1 : body0;
    const auto* shape = static_cast<const MeshShape*>(meshWrap->getCollisionShape());
    const auto* scenery = static_cast<const btConcaveShape*>(sceneryWrap->getCollisionShape());
    bool touching = false;
    if (scenery->getShapeType() == STATIC_PLANE_PROXYTYPE &&
        finitePose(meshWrap->getWorldTransform()) && finitePose(sceneryWrap->getWorldTransform())) {
        const Pose meshPose = toPose(meshWrap->getWorldTransform());
        const double margin = contactMargin(state_->stages, manifold_, resultOut);
        touching = planeContacts(static_cast<const btStaticPlaneShape&>(*scenery),
                                 toPose(sceneryWrap->getWorldTransform()), *shape, meshPose, margin,
                                 breakingThreshold(manifold_), contactScratch, state_->contacts);
        if (!state_->contacts.empty()) {
            toWorld(state_->contacts, meshPose);
            dropStalePoints(ownManifold_, resultOut);
            emit(state_->contacts, meshFirst_, resultOut);
        }
        state_->stages.report(detail::PairKind::kMeshScenery, narrowphase::QueryCounters{},
                              state_->contacts.size());
    } else if (finitePose(meshWrap->getWorldTransform()) &&
               finitePose(sceneryWrap->getWorldTransform())) {
        // The mesh's box in the scenery's frame, and the scenery's triangles in it.
        const btTransform meshInScenery =
            sceneryWrap->getWorldTransform().inverse() * meshWrap->getWorldTransform();
        btVector3 lo, hi;
        shape->getAabb(meshInScenery, lo, hi);
        const double margin = contactMargin(state_->stages, manifold_, resultOut);
        lo -= btVector3(1, 1, 1) * btScalar(margin);
        hi += btVector3(1, 1, 1) * btScalar(margin);
        SceneryCollector collector(toPose(sceneryWrap->getWorldTransform()));
        collectScenery(*scenery, lo, hi, collector);
        if (!collector.ids.empty()) {
            const narrowphase::TreeSettings& tree = shape->model().settings();
            const MeshModel* cached = state_->sceneryModel.get();
            if (cached == nullptr || cached->settings().kind != tree.kind ||
                cached->settings().leaf_size != tree.leaf_size ||
                state_->sceneryIds != collector.ids ||
                state_->sceneryCorners != collector.corners) {
                std::vector<Vec3> vertices;
                std::vector<Index3> triangles;
                collector.weld(vertices, triangles);
                state_->sceneryModel = std::make_shared<const MeshModel>(
                    std::make_shared<const TriangleMesh>("bullet scenery", std::move(vertices),
                                                         std::move(triangles)),
                    tree);
                state_->sceneryIds = std::move(collector.ids);
                state_->sceneryCorners = std::move(collector.corners);
                state_->stages.countSceneryModelBuilt();
                state_->query.resetFront();  // it held node pairs of the last model's tree
            }
            const MeshModel& sceneryModel = *state_->sceneryModel;
            const std::vector<std::pair<int, int>>& ids = state_->sceneryIds;
            const Pose meshPose = toPose(meshWrap->getWorldTransform());
            const Pose identity;
            QuerySettings settings = contactSettings();
            settings.margin = margin;
            settings = state_->stages.plan(settings, shape->model().mesh().triangleCount(),
                                           sceneryModel.mesh().triangleCount());
            const QueryResult& result = state_->query.run(shape->model(), meshPose, sceneryModel,
                                                          identity, settings, queryScratch);
            touching = result.intersecting;
            if (result.intersecting || !result.near.empty()) {
                buildContacts(result, shape->model().mesh(), sceneryModel.mesh(),
                              RelativePose(meshPose, identity), sidesOf(*shape), Sides::kScenery,
                              breakingThreshold(manifold_), contactScratch, state_->contacts);
                toWorld(state_->contacts, meshPose);
                for (MeshContact& c : state_->contacts) {
                    c.partY = ids[c.triangleY].first;
                    c.triangleY = ids[c.triangleY].second;
                }
                dropStalePoints(ownManifold_, resultOut);
                emit(state_->contacts, meshFirst_, resultOut);
            }
            state_->stages.report(detail::PairKind::kMeshScenery, result.counters,
                                  state_->contacts.size());
        }
    }
    if (ownManifold_) {
        resultOut->refreshContactPoints();
        if (!touching) {
            keptPointsAtMostTouch(manifold_);
        }
    }
}

btScalar BvhMeshAlgorithm::calculateTimeOfImpact(btCollisionObject* body0, btCollisionObject* body1,
                                                 const btDispatcherInfo&, btManifoldResult*) {
    const bool slow = !exceedsCcdMotionThreshold(*body0) && !exceedsCcdMotionThreshold(*body1);
    state_->stages.countTimeOfImpact(slow);
    if (slow) {
        return btScalar(1);
    }
    btCollisionObject* meshObject = meshFirst_ ? body0 : body1;
    btCollisionObject* sceneryObject = meshFirst_ ? body1 : body0;
    const auto* shape = static_cast<const MeshShape*>(meshObject->getCollisionShape());
    const auto* scenery = static_cast<const btConcaveShape*>(sceneryObject->getCollisionShape());
    const btTransform& sceneryPose = sceneryObject->getWorldTransform();
    if (!finitePose(meshObject->getWorldTransform()) || !finitePose(endOfStep(*meshObject)) ||
        !finitePose(sceneryPose)) {
        return btScalar(1);
    }
    if (scenery->getShapeType() == STATIC_PLANE_PROXYTYPE) {
        const TriangleMesh& mesh = shape->model().mesh();
        if (!stepOf(*meshObject, mesh.vertices(), state_->ccd.stepA)) {
            return btScalar(1);
        }
        std::vector<Vec3> normals;
        const double touching = touchingOfContacts(state_->contacts, normals);
        bool hit = false;
        const btScalar toi =
            planeTimeOfImpact(static_cast<const btStaticPlaneShape&>(*scenery), sceneryPose,
                              state_->ccd, mesh.triangles(), normals, touching, body0, body1, hit);
        if (hit) {
            state_->stages.countTimeOfImpactHit();
        }
        return toi;
    }
    btVector3 lo, hi;
    sweptBoxIn(*shape, *meshObject, sceneryPose, lo, hi);
    SceneryCollector collector(toPose(sceneryPose));
    collectScenery(*scenery, lo, hi, collector);
    if (collector.ids.empty()) {
        return btScalar(1);
    }
    std::vector<Index3> triangles;
    collector.weld(state_->sceneryVertices, triangles);
    const TriangleMesh& mesh = shape->model().mesh();
    if (!stepOf(*meshObject, mesh.vertices(), state_->ccd.stepA)) {
        return btScalar(1);
    }
    setTriangles(mesh.triangles(), state_->ccd.movingA);
    // The scenery's triangles are already in the world, where they stay.
    state_->ccd.stepB.vertices = &state_->sceneryVertices;
    state_->ccd.stepB.start = Pose();
    state_->ccd.stepB.end = Pose();
    setTriangles(triangles, state_->ccd.movingB);
    return reportTimeOfImpact(body0, body1);
}

btCollisionAlgorithm* BvhMeshAlgorithm::CreateFunc::CreateCollisionAlgorithm(
    btCollisionAlgorithmConstructionInfo& ci, const btCollisionObjectWrapper* body0,
    const btCollisionObjectWrapper* body1) {
    void* memory = ci.m_dispatcher1->allocateCollisionAlgorithm(sizeof(BvhMeshAlgorithm));
    return new (memory) BvhMeshAlgorithm(ci, body0, body1, true);
}

btCollisionAlgorithm* BvhMeshAlgorithm::SwappedCreateFunc::CreateCollisionAlgorithm(
    btCollisionAlgorithmConstructionInfo& ci, const btCollisionObjectWrapper* body0,
    const btCollisionObjectWrapper* body1) {
    void* memory = ci.m_dispatcher1->allocateCollisionAlgorithm(sizeof(BvhMeshAlgorithm));
    return new (memory) BvhMeshAlgorithm(ci, body0, body1, false);
}

// ---------------------------------------------------------------------------------------

void registerNarrowphase(btCollisionDispatcher* dispatcher) {
    registerNarrowphase(dispatcher, MeshStageSettings());
}

void registerNarrowphase(btCollisionDispatcher* dispatcher, const MeshStageSettings& stages) {
    if (!dispatcher) {
        throw std::invalid_argument("kolize::registerNarrowphase: null dispatcher");
    }
    if (btCollisionConfiguration* configuration = dispatcher->getCollisionConfiguration()) {
        const std::size_t largest = std::max(
            {sizeof(MeshMeshAlgorithm), sizeof(ConvexMeshAlgorithm), sizeof(BvhMeshAlgorithm)});
        const btPoolAllocator* pool = configuration->getCollisionAlgorithmPool();
        if (pool && std::size_t(pool->getElementSize()) < largest) {
            throw std::invalid_argument(
                "kolize::registerNarrowphase: the collision configuration's algorithm pool "
                "holds " +
                std::to_string(pool->getElementSize()) +
                "-byte elements, kolize's algorithms need " + std::to_string(largest));
        }
    }
    detail::setPlanner(dispatcher, stages);
    static MeshMeshAlgorithm::CreateFunc meshMesh;
    static ConvexMeshAlgorithm::CreateFunc convexMesh;
    static ConvexMeshAlgorithm::SwappedCreateFunc meshConvex;
    static BvhMeshAlgorithm::CreateFunc meshScenery;
    static BvhMeshAlgorithm::SwappedCreateFunc sceneryMesh;
    const int mesh = CUSTOM_CONCAVE_SHAPE_TYPE;
    auto both = [&](int type0, int type1, btCollisionAlgorithmCreateFunc* create) {
        dispatcher->registerCollisionCreateFunc(type0, type1, create);
        dispatcher->registerClosestPointsCreateFunc(type0, type1, create);
    };
    both(mesh, mesh, &meshMesh);
    for (int type = 0; type < CONCAVE_SHAPES_START_HERE; ++type) {
        if (type == IMPLICIT_CONVEX_SHAPES_START_HERE) {
            continue;  // a marker, not a shape type
        }
        both(type, mesh, &convexMesh);
        both(mesh, type, &meshConvex);
    }
    for (int scenery :
         {int(TRIANGLE_MESH_SHAPE_PROXYTYPE), int(SCALED_TRIANGLE_MESH_SHAPE_PROXYTYPE),
          int(MULTIMATERIAL_TRIANGLE_MESH_PROXYTYPE), int(TERRAIN_SHAPE_PROXYTYPE),
          int(STATIC_PLANE_PROXYTYPE)}) {
        both(mesh, scenery, &meshScenery);
        both(scenery, mesh, &sceneryMesh);
    }
}

}  // namespace kolize
