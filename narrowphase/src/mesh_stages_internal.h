#pragma once
// The stage planner's internals: the per-dispatcher entry (settings, atomic counters) and the
// per-pair decisions of the mesh algorithms (mesh_stages.h has the rules).
#include "kolize/narrowphase/mesh_query.h"
#include "kolize/narrowphase/mesh_stages.h"

#include <atomic>
#include <cstdint>
#include <memory>

class btDispatcher;

namespace kolize::detail {

// Every counter of MeshStageStats, in its order.
#define KOLIZE_STAGE_COUNTERS(X) \
    X(mesh_mesh_queries)         \
    X(mesh_scenery_queries)      \
    X(scenery_models_built)      \
    X(convex_mesh_queries)       \
    X(pairs)                     \
    X(object_sphere_tests)       \
    X(object_sphere_rejects)     \
    X(sphere_skipped_auto)       \
    X(sphere_skipped_off)        \
    X(sphere_skipping_pairs)     \
    X(sphere_turned_off)         \
    X(sphere_rearmed)            \
    X(tree_queries)              \
    X(no_tree_tiny)              \
    X(no_tree_off)               \
    X(tiny_pairs)                \
    X(root_rejects)              \
    X(node_sphere_tests)         \
    X(node_sphere_rejects)       \
    X(node_box_tests)            \
    X(node_box_rejects)          \
    X(leaf_pairs)                \
    X(triangle_box_rejects)      \
    X(triangle_tests)            \
    X(intersecting_pairs)        \
    X(near_pairs)                \
    X(contacts)                  \
    X(toi_calls)                 \
    X(toi_skipped_slow)          \
    X(toi_hits)

/// One dispatcher's planner: settings and counters shared by all of its pairs. Counters are
/// relaxed atomics (Bullet may run pairs on several threads); the settings are written by
/// registerNarrowphase only, between steps.
struct StagePlanner {
    enum Counter : int {
#define KOLIZE_STAGE_ENUM(name) k_##name,
        KOLIZE_STAGE_COUNTERS(KOLIZE_STAGE_ENUM)
#undef KOLIZE_STAGE_ENUM
            kCounterCount
    };
    MeshStageSettings settings;
    std::atomic<std::uint64_t> counters[kCounterCount] = {};
    /// Bumped by every reset: pairs count themselves once per epoch in the distinct-pair
    /// counters.
    std::atomic<std::uint64_t> epoch{1};

    void add(Counter counter, std::uint64_t value) {
        if (value != 0) {
            counters[counter].fetch_add(value, std::memory_order_relaxed);
        }
    }
    MeshStageStats snapshot() const;
    void reset();
};

/// The planner of the dispatcher an algorithm was made by (a default one, counted
/// nowhere, when it has no entry). Cheap: a per-thread cache in front of the registry.
std::shared_ptr<StagePlanner> plannerOf(const btDispatcher* dispatcher);
/// registerNarrowphase's part: the entry of `dispatcher` gets `settings` and zero counters.
void setPlanner(const btDispatcher* dispatcher, const MeshStageSettings& settings);

/// Which kind of pair a query belongs to.
enum class PairKind : std::uint8_t { kMeshMesh, kMeshScenery };

/// One mesh pair's decisions: plan() before each query, report() after it with the
/// query's counters. Used by one thread at a time (Bullet's rule for an algorithm).
class PairStages {
  public:
    explicit PairStages(std::shared_ptr<StagePlanner> planner) : planner_(std::move(planner)) {}
    /// The query settings for the next query of a pair of `trianglesA` and `trianglesB`
    /// triangles: `base` with the sphere and tree stages as planned.
    narrowphase::QuerySettings plan(narrowphase::QuerySettings base, std::int64_t trianglesA,
                                    std::int64_t trianglesB);
    /// Counts the planned query (its counters, the contact points made) and updates the
    /// sphere measurement.
    void report(PairKind kind, const narrowphase::QueryCounters& counters, std::size_t contacts);
    /// Counts a time-of-impact call (`slow`: skipped, neither body past its threshold).
    void countTimeOfImpact(bool slow) {
        planner_->add(StagePlanner::k_toi_calls, 1);
        planner_->add(StagePlanner::k_toi_skipped_slow, slow ? 1 : 0);
    }
    /// Counts a time of impact found below 1.
    void countTimeOfImpactHit() { planner_->add(StagePlanner::k_toi_hits, 1); }
    /// Counts a model built of scenery triangles (a mesh-scenery query that could not reuse
    /// its pair's last one).
    void countSceneryModelBuilt() { planner_->add(StagePlanner::k_scenery_models_built, 1); }
    StagePlanner& planner() { return *planner_; }

  private:
    enum class Sphere : std::uint8_t { kTested, kSkippedAuto, kSkippedOff };
    enum class Tree : std::uint8_t { kUsed, kTiny, kOff };
    void countOncePerEpoch(unsigned flag, StagePlanner::Counter counter);

    std::shared_ptr<StagePlanner> planner_;
    Sphere sphere_ = Sphere::kTested;
    Tree tree_ = Tree::kUsed;
    bool measuring_ = false;  // this query's sphere test belongs to an auto window
    bool offEnded_ = false;   // this query is the last of an off period
    int measured_ = 0;        // queries of the current window
    int rejects_ = 0;
    int offLeft_ = 0;  // queries still to skip the test
    std::uint64_t epoch_ = 0;
    unsigned countedFlags_ = 0;  // distinct-pair counters already counted this epoch
};

}  // namespace kolize::detail
