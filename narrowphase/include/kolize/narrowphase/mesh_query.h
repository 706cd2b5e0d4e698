#pragma once
/// \file
/// Mesh A at pose A against mesh B at pose B: the thesis's pipeline after the broadphase.
///
/// Stages (each counted in QueryCounters):
///  1. object bounding spheres (optional, `sphere_pretest` and `object_spheres`);
///  2. tree against tree (or, `use_tree` off, every triangle pair directly): an iterative traversal
///  of the two bounding-volume trees, node
///     pairs tested with the kind's overlap test (OBB: a node-sphere test first, when
///     `sphere_pretest`, then the 15-axis separating-axis test). An A of at most 16
///     triangles is one leaf (its tree is not descended): a box mesh's leaves all have the
///     whole box as their volume, and each would take B's traversal once more;
///  3. leaf pairs: B's leaf vertices transformed into A's frame (once per query, cached),
///     a box test of every triangle pair (exact, on double boxes), the optional facing
///     filter, then the exact triangle test.
///
/// Exactness. The query works in A's model frame. B's vertices there are the doubles
/// `RelativePose(poseA, poseB).apply(q)`; on those doubles the answer is exact, closed
/// (touching counts) and without tolerance: every pair of triangles that shares a point is
/// reported, no other (the bounding-volume stages only ever skip provably disjoint
/// pairs). The facing filter, when on, voids this (it is the thesis's heuristic).
///
/// Costs. No allocation in steady state: a query reuses its result vectors, and the scratch
/// (vertex cache, node cache, traversal stack) is kept in a QueryScratch, stamped per query
/// so that nothing is cleared in O(mesh). k-DOP trees refit B's tree in A's frame per
/// query (O(|B|)); the other kinds touch only what the traversal visits.
#include "kolize/narrowphase/mesh_model.h"
#include "kolize/narrowphase/pose.h"
#include "kolize/narrowphase/predicates.h"
#include "kolize/narrowphase/triangle_test.h"

#include <cstdint>
#include <memory>
#include <vector>

namespace kolize::narrowphase {

/// What a query reports.
enum class QueryMode : std::uint8_t {
    kYesNo,     ///< stops at the first intersecting triangle pair (pairs holds it)
    kAllPairs,  ///< every intersecting triangle pair
    kContacts,  ///< every pair, each with its intersection geometry and face normals
};

/// Which tree a node pair descends.
enum class Descent : std::uint8_t {
    /// Both nodes at once (their four child pairs) while neither is a leaf, then the inner
    /// one: skips the intermediate level, which overlaps in most pairs that reach it.
    /// Default: 5-25% faster than kLarger on the benchmark's meshes.
    kBoth,
    kLarger,           ///< the node with the larger model-space size (FCL's rule)
    kFirstThenSecond,  ///< A to its leaves first, then B (the thesis's wording)
};

/// Settings of a query, with their defaults.
struct QuerySettings {
    QueryMode mode = QueryMode::kAllPairs;
    /// Object bounding spheres before the trees, and (OBB trees) a sphere test before each
    /// node pair's box test. Default on: spheres reject most apart and near node pairs at
    /// a quarter of a box test's cost.
    bool sphere_pretest = true;
    /// Stage 1 alone: off skips the object bounding spheres (the node-sphere tests stay as
    /// `sphere_pretest` says). The test runs when both this and `sphere_pretest` are on.
    /// Same answer either way; off saves the test where the spheres always overlap (a
    /// resting pair), at the cost of a traversal start for pairs they would have rejected.
    bool object_spheres = true;
    /// Stage 2: off tests every triangle of A against every triangle of B directly (exact
    /// boxes, then the exact test), without the trees: O(|A| |B|), for tiny meshes, where
    /// the tree's node tests cost more than they save. Only the root volumes are tested
    /// first (OBB trees: the traversal's first test, counted in root_tests and
    /// root_rejects), so that a near miss ends there. Same pairs as the tree path (the
    /// same per-pair tests on the same doubles), in mesh order (A's triangle, then B's)
    /// instead of traversal order; the other counters of stage 2 stay 0. A query without
    /// tree forgets the traversal front.
    bool use_tree = true;
    Descent descent = Descent::kBoth;
    /// Restart the traversal from the previous query's front (the node pairs where it
    /// stopped) when the models and the descent rule are the same; same answer, fewer
    /// tests when the poses changed little. The front's last separating axis is tried
    /// first. Default off (single queries stay comparable with other libraries). Yes/no
    /// queries neither use nor keep a front.
    bool use_front = false;
    /// The thesis's "facing the motion" filter (stage 4): a triangle pair is tested only if
    /// B's triangle normal (from its winding, in A's frame) points within 90 degrees of
    /// `motion` and A's within 90 degrees of -motion. `motion` is B's motion relative to A
    /// in A's frame. Off by default: in a discrete test it misses real intersections
    /// (rotation, deep penetration); QueryCounters::facing_culled counts what it skipped.
    bool facing_filter = false;
    Vec3 motion = Vec3::Zero();
    /// Contact margin (kContacts only; the other modes ignore it): when no triangle pair
    /// intersects, the pairs at most this far apart are reported in QueryResult::near, with
    /// their distance and closest points (meshes that intersect have contacts; their near
    /// pairs are not collected past the first intersecting pair, and dropped). Default 0. The
    /// bounding-volume stages widen every test by the margin (on top of their rounding slack), so
    /// no pair within the margin is skipped; the distance itself is computed in double
    /// (triangleDistance), not exactly, and a near pair is one whose computed distance is <=
    /// margin. Must be finite and >= 0; k-DOP trees take no margin (std::invalid_argument for
    /// either).
    double margin = 0;
};

/// One intersecting pair: triangle indices into mesh A and mesh B.
struct TrianglePair {
    std::int32_t a = -1;
    std::int32_t b = -1;
    friend bool operator==(const TrianglePair& x, const TrianglePair& y) {
        return x.a == y.a && x.b == y.b;
    }
    friend bool operator<(const TrianglePair& x, const TrianglePair& y) {
        return x.a != y.a ? x.a < y.a : x.b < y.b;
    }
};

/// Contact data of an intersecting pair (kContacts), in A's model frame.
struct PairContact {
    TrianglePair pair;
    TriangleIntersection geometry;
    Vec3 normal_a = Vec3::Zero();  ///< unit face normal of A's triangle (winding), 0 if degenerate
    Vec3 normal_b = Vec3::Zero();  ///< unit face normal of B's triangle in A's frame
};

/// A triangle pair within the contact margin that does not intersect (kContacts with a
/// margin), in A's model frame.
struct NearPair {
    TrianglePair pair;
    double distance = 0;       ///< > 0 up to rounding; <= the margin
    Vec3 on_a = Vec3::Zero();  ///< closest point on A's triangle
    Vec3 on_b = Vec3::Zero();  ///< closest point on B's triangle (in A's frame)
};

/// Work done by one query, per stage.
struct QueryCounters {
    std::uint64_t object_sphere_tests = 0;
    std::uint64_t object_sphere_rejects = 0;  ///< 1 when the query ended at the object spheres
    std::uint64_t node_sphere_tests = 0;      ///< OBB trees with sphere_pretest
    std::uint64_t node_sphere_rejects = 0;
    std::uint64_t bv_tests = 0;  ///< node-pair volume tests (spheres for sphere trees)
    std::uint64_t bv_rejects = 0;
    std::uint64_t leaf_pairs = 0;
    std::uint64_t triangle_box_rejects = 0;  ///< triangle pairs whose exact boxes are disjoint
    std::uint64_t facing_culled = 0;         ///< triangle pairs skipped by the facing filter
    std::uint64_t triangle_tests = 0;        ///< exact triangle tests run
    std::uint64_t pairs = 0;                 ///< intersecting pairs found
    std::uint64_t near_pairs = 0;            ///< QueryResult::near's size
    std::uint64_t vertices_transformed = 0;  ///< B's vertices moved into A's frame
    std::uint64_t front_size = 0;            ///< node pairs the traversal started from
    /// `use_tree` off: 1 when the root volumes were tested first (OBB trees), and rejected.
    std::uint64_t root_tests = 0;
    std::uint64_t root_rejects = 0;
    bool started_from_front = false;
    PredicateStats predicates;
};

/// The result of the last query of a MeshQuery (valid until its next query).
struct QueryResult {
    bool intersecting = false;
    /// kYesNo: the first pair found (or none); else every pair, each once, in traversal order.
    std::vector<TrianglePair> pairs;
    std::vector<PairContact> contacts;  ///< kContacts only, same order as pairs
    std::vector<NearPair> near;         ///< kContacts with a margin, no pair intersecting
    QueryCounters counters;
};

/// Per-thread scratch memory of queries: B's transformed vertices and nodes, the traversal
/// stack, k-DOP refits. One scratch may serve any number of MeshQuery objects, one query
/// at a time. It grows to the largest meshes seen and never shrinks.
class QueryScratch {
  public:
    QueryScratch();
    ~QueryScratch();
    QueryScratch(const QueryScratch&) = delete;
    QueryScratch& operator=(const QueryScratch&) = delete;
    struct Impl;
    Impl& impl() { return *impl_; }

  private:
    std::unique_ptr<Impl> impl_;
};

/// A reusable query: keeps its result and the traversal front between calls (one object per
/// pair of bodies, e.g. per Bullet collision algorithm), and its own scratch unless one is
/// passed in.
class MeshQuery {
  public:
    MeshQuery();
    ~MeshQuery();
    MeshQuery(MeshQuery&&) noexcept;
    MeshQuery& operator=(MeshQuery&&) noexcept;

    /// Runs the query. Both models must have the same tree kind, and the poses must be
    /// finite with rotations orthonormal within 1e-6 (std::invalid_argument otherwise,
    /// naming both meshes). Cost: see the file comment; O(1) for disjoint object spheres.
    const QueryResult& run(const MeshModel& a, const Pose& poseA, const MeshModel& b,
                           const Pose& poseB, const QuerySettings& settings = {});
    /// The same with shared scratch (this object's own scratch is then not allocated).
    const QueryResult& run(const MeshModel& a, const Pose& poseA, const MeshModel& b,
                           const Pose& poseB, const QuerySettings& settings, QueryScratch& scratch);

    const QueryResult& result() const { return result_; }
    /// Forgets the traversal front (the next query starts at the roots).
    void resetFront();
    /// Node pairs in the kept front (0 when none).
    std::size_t frontSize() const;

    struct Front;

  private:
    QueryResult result_;
    std::unique_ptr<Front> front_;
    std::unique_ptr<QueryScratch> ownScratch_;
};

/// One-shot convenience: a fresh MeshQuery's run (allocates; prefer a kept MeshQuery).
QueryResult meshCollide(const MeshModel& a, const Pose& poseA, const MeshModel& b,
                        const Pose& poseB, const QuerySettings& settings = {});

}  // namespace kolize::narrowphase
