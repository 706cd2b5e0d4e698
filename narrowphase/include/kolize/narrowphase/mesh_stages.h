#pragma once
/// \file
/// The stage planner of the Bullet mesh algorithms (bullet_mesh.h): which of the thesis's
/// stages a mesh pair runs (broadphase -> object bounding spheres -> OBB tree -> triangle
/// test), decided per pair from measured data, and the counters that show what ran, what was
/// skipped and why.
///
/// Every decision only skips work: a stage that is left out is one whose answer is implied
/// (the spheres of a resting pair always overlap; a tiny pair's triangles are tested
/// directly, with the same exact test the tree would reach). The contacts are the same bit
/// for bit as with every stage forced on (MeshStageSettings::allOn()).
///
/// Use:
/// \code
///   kolize::MeshStageSettings stages;                   // auto everywhere
///   kolize::registerNarrowphase(&dispatcher, stages);   // bullet_mesh.h
///   world.stepSimulation(dt);
///   std::puts(kolize::describeStages(kolize::narrowphaseStages(&dispatcher)).c_str());
///   kolize::resetNarrowphaseStages(&dispatcher);        // per frame, if wanted
/// \endcode
///
/// The rules (stage by stage):
/// - Broadphase: Bullet's (or kolize's) broadphase makes the pair; the planner never sees
///   the pairs it rejects.
/// - Object bounding spheres (mesh-mesh and mesh-scenery pairs), `sphere_stage`. Auto: each
///   pair measures the test over `sphere_window` queries in a row; when it rejected fewer than
///   `sphere_min_reject_share` of them, the pair skips it for the next `sphere_rearm_after`
///   queries, then is re-armed: it measures a new window (and so on). A pair whose spheres
///   reject often keeps the test.
/// - OBB tree, `tree`. Auto: a pair with triangles(A) * triangles(B) <= `tiny_pair_limit`
///   tests its root volumes and then every triangle pair directly (QuerySettings::use_tree
///   off), touching or not: a resting pair that the solver leaves a hair apart overlaps as
///   deeply as a touching one, and the traversal would visit most of its node pairs to find
///   nothing. Re-decided every query (scenery pairs see a different number of scenery
///   triangles each time). Measured with `kolize-mesh-stages --query-sweep` (two
///   12-triangle boxes, contacts mode): resting 11.1 us with the tree, 5.4 us direct; 0.01
///   apart 0.28 us with the tree (its front keeps the node pair that separated), 0.53 us
///   direct (a cube's root OBB has arbitrary axes and meets the other cube's). Direct also
///   wins up to 108 x 108 triangles on those boxes, but a larger limit (1296 or 11664) made
///   kolize-mesh-world's pile of real meshes about 12% slower: the default stays 144.
/// - Triangle test: every mesh-mesh and mesh-scenery pair that gets past the spheres. A convex
///   shape against a mesh (a primitive pair) never runs kolize's triangle stage: Bullet's
///   convex-triangle algorithm makes its contacts (counted as convex_mesh_queries).
/// - Continuous collision: a time of impact is computed only when one of the bodies exceeds
///   its CCD motion threshold (exceedsCcdMotionThreshold); that is Bullet's rule and part of
///   the answer, so it is counted (toi_skipped_slow) but not a setting.
#include <cstdint>
#include <string>

class btCollisionDispatcher;

namespace kolize {

/// How one stage is chosen.
enum class StageMode : std::uint8_t {
    kAuto,  ///< the planner decides per pair (the rules in the file comment)
    kOn,    ///< the stage always runs
    kOff,   ///< the stage never runs (the answer is the same; only the work changes)
};

/// "auto", "on" or "off".
const char* stageModeName(StageMode mode);

/// The planner's settings for one dispatcher, with their defaults.
struct MeshStageSettings {
    /// The object-bounding-sphere test before the trees (default auto).
    StageMode sphere_stage = StageMode::kAuto;
    /// Auto: queries in a row over which a pair measures its sphere test (>= 1).
    int sphere_window = 64;
    /// Auto: the test is turned off for a pair that rejected fewer than this share of its
    /// window's queries (0..1; 0.05: under 4 of 64).
    double sphere_min_reject_share = 0.05;
    /// Auto: queries a pair skips the test before it is re-armed and measures again (>= 1).
    int sphere_rearm_after = 256;
    /// The OBB tree against tree (default auto).
    StageMode tree = StageMode::kAuto;
    /// Auto: no tree for a touching pair with triangles(A) * triangles(B) at most this
    /// (>= 0). 64 is the thesis design's limit (NARROWPHASE.md section 5); the default 144
    /// includes two 12-triangle boxes, which the direct test handles faster than the trees
    /// when they touch (kolize-mesh-stages --query-sweep).
    std::int64_t tiny_pair_limit = 144;

    /// Not a stage: the contact margin in metres (default 0, off; finite, >= 0). Mesh-mesh
    /// and mesh-scenery pairs that do not intersect then report their triangle pairs apart
    /// by at most this much (QuerySettings::margin) as separated contacts: positive
    /// distance, normal along their closest points, never a penetration. Each pair uses at most its
    /// manifold's contact breaking threshold (Bullet's btManifoldResult drops points farther
    /// apart than that, and refreshContactPoints would drop them next step): about
    /// 0.02 x a shape's bounding-sphere reach (gContactBreakingThreshold), 5 mm for a
    /// 0.5 m mesh. The broadphase finds the pair when the bodies' boxes overlap, and
    /// Bullet's world widens each box by the breaking threshold (updateSingleAabb).
    double contact_margin = 0;

    /// Every stage forced on: the comparison run for the time the planner saves.
    static MeshStageSettings allOn();
};

/// Counters of one dispatcher's mesh algorithms, added over all of its pairs, cumulative
/// from registerNarrowphase or the last resetNarrowphaseStages. A query is one
/// processCollision of a mesh-mesh pair (with finite transforms) or of a mesh-scenery pair
/// that found scenery triangles in the mesh's box (widened by the contact margin). Identities:
/// object_sphere_tests + sphere_skipped_auto + sphere_skipped_off = mesh queries (mesh_mesh +
/// mesh_scenery), and mesh queries - object_sphere_rejects = tree_queries + no_tree_tiny +
/// no_tree_off.
struct MeshStageStats {
    MeshStageSettings settings;  ///< the dispatcher's settings

    std::uint64_t mesh_mesh_queries = 0;     ///< MeshShape against MeshShape
    std::uint64_t mesh_scenery_queries = 0;  ///< MeshShape against btBvhTriangleMeshShape
    /// Mesh-scenery queries that built a model (and its tree) of the scenery's triangles in
    /// the mesh's box; the others reused their pair's last model: the same triangles, bit for
    /// bit.
    std::uint64_t scenery_models_built = 0;
    /// Convex shape against MeshShape: Bullet's convex-triangle path, no kolize triangle
    /// stage (processCollision calls).
    std::uint64_t convex_mesh_queries = 0;
    std::uint64_t pairs = 0;  ///< distinct mesh-mesh and mesh-scenery pairs that ran a query

    std::uint64_t object_sphere_tests = 0;
    std::uint64_t object_sphere_rejects = 0;  ///< queries that ended at the spheres
    std::uint64_t sphere_skipped_auto = 0;    ///< queries without the test: the planner's choice
    std::uint64_t sphere_skipped_off = 0;     ///< queries without the test: sphere_stage off
    std::uint64_t sphere_skipping_pairs = 0;  ///< distinct pairs that skipped it at least once
    std::uint64_t sphere_turned_off = 0;      ///< windows that ended under the share (auto)
    std::uint64_t sphere_rearmed = 0;         ///< off periods that ended (auto)

    std::uint64_t tree_queries = 0;  ///< queries that traversed the trees
    std::uint64_t no_tree_tiny = 0;  ///< queries without tree: auto, a tiny pair
    std::uint64_t no_tree_off = 0;   ///< queries without tree: tree off
    std::uint64_t tiny_pairs = 0;    ///< distinct pairs that ran without tree at least once
    /// Queries without tree that ended at the root volumes (OBB trees), before any triangle.
    std::uint64_t root_rejects = 0;
    std::uint64_t node_sphere_tests = 0;
    std::uint64_t node_sphere_rejects = 0;
    std::uint64_t node_box_tests = 0;  ///< OBB separating-axis tests of node pairs
    std::uint64_t node_box_rejects = 0;
    std::uint64_t leaf_pairs = 0;

    std::uint64_t triangle_box_rejects = 0;  ///< triangle pairs whose exact boxes are disjoint
    std::uint64_t triangle_tests = 0;        ///< exact triangle tests
    std::uint64_t intersecting_pairs = 0;    ///< triangle pairs found
    std::uint64_t near_pairs = 0;            ///< apart, within the contact margin
    std::uint64_t contacts = 0;              ///< contact points handed to Bullet

    std::uint64_t toi_calls = 0;         ///< calculateTimeOfImpact of the mesh algorithms
    std::uint64_t toi_skipped_slow = 0;  ///< neither body exceeded its CCD motion threshold
    std::uint64_t toi_hits = 0;          ///< times of impact below 1
};

/// A few lines for a person: per stage, what ran, what was skipped and why, with the counts
/// and shares, e.g. "sphere stage (auto): 64 tests, 0 rejected (0.0%); skipped in 256
/// queries of 1 of 1 pairs (rejected under 5.0% of 64 queries in a row; re-armed 0 times)".
std::string describeStages(const MeshStageStats& stats);

/// The counters of `dispatcher` (a snapshot). Throws std::invalid_argument when
/// registerNarrowphase was never called on it (or its entry was released).
MeshStageStats narrowphaseStages(const btCollisionDispatcher* dispatcher);
/// Zeroes the counters (pairs keep their measurements and decisions). Call it between
/// steps. Throws as narrowphaseStages.
void resetNarrowphaseStages(const btCollisionDispatcher* dispatcher);
/// Lifetime: registerNarrowphase keeps one small entry (settings and counters) per
/// dispatcher address until this call or the end of the process; registering again at the
/// same address replaces the settings and zeroes the counters. After this call, pairs the
/// dispatcher still makes run with the default settings and count nowhere. No effect for
/// a dispatcher without an entry.
void releaseNarrowphaseStages(const btCollisionDispatcher* dispatcher);

}  // namespace kolize
