#include "mesh_stages_internal.h"

#include <BulletCollision/CollisionDispatch/btCollisionDispatcher.h>

#include <cmath>
#include <cstdio>
#include <mutex>
#include <stdexcept>
#include <unordered_map>

namespace kolize {

const char* stageModeName(StageMode mode) {
    switch (mode) {
        case StageMode::kAuto:
            return "auto";
        case StageMode::kOn:
            return "on";
        case StageMode::kOff:
            return "off";
    }
    return "?";
}

MeshStageSettings MeshStageSettings::allOn() {
    MeshStageSettings settings;
    settings.sphere_stage = StageMode::kOn;
    settings.tree = StageMode::kOn;
    return settings;
}

namespace detail {

MeshStageStats StagePlanner::snapshot() const {
    MeshStageStats stats;
    stats.settings = settings;
#define KOLIZE_STAGE_COPY(name) stats.name = counters[k_##name].load(std::memory_order_relaxed);
    KOLIZE_STAGE_COUNTERS(KOLIZE_STAGE_COPY)
#undef KOLIZE_STAGE_COPY
    return stats;
}

void StagePlanner::reset() {
    for (std::atomic<std::uint64_t>& counter : counters) {
        counter.store(0, std::memory_order_relaxed);
    }
    epoch.fetch_add(1, std::memory_order_relaxed);
}

namespace {

/// The registry: one planner per registered dispatcher address. `generation` changes with
/// every registration or release, so that the per-thread caches notice.
struct Registry {
    std::mutex mutex;
    std::unordered_map<const btDispatcher*, std::shared_ptr<StagePlanner>> planners;
    std::atomic<std::uint64_t> generation{1};
};

Registry& registry() {
    static Registry instance;
    return instance;
}

std::shared_ptr<StagePlanner> findPlanner(const btDispatcher* dispatcher) {
    Registry& r = registry();
    std::lock_guard<std::mutex> lock(r.mutex);
    const auto it = r.planners.find(dispatcher);
    return it == r.planners.end() ? nullptr : it->second;
}

std::shared_ptr<StagePlanner> registeredPlanner(const btCollisionDispatcher* dispatcher,
                                                const char* function) {
    std::shared_ptr<StagePlanner> planner = findPlanner(dispatcher);
    if (!planner) {
        throw std::invalid_argument(std::string("kolize::") + function +
                                    ": registerNarrowphase was not called on this dispatcher");
    }
    return planner;
}

void checkSettings(const MeshStageSettings& s) {
    auto refuse = [](const std::string& what) {
        throw std::invalid_argument("kolize::registerNarrowphase: MeshStageSettings::" + what);
    };
    if (s.sphere_window < 1) {
        refuse("sphere_window must be at least 1, not " + std::to_string(s.sphere_window));
    }
    if (!(s.sphere_min_reject_share >= 0 && s.sphere_min_reject_share <= 1)) {
        refuse("sphere_min_reject_share must be in 0..1, not " +
               std::to_string(s.sphere_min_reject_share));
    }
    if (s.sphere_rearm_after < 1) {
        refuse("sphere_rearm_after must be at least 1, not " +
               std::to_string(s.sphere_rearm_after));
    }
    if (s.tiny_pair_limit < 0) {
        refuse("tiny_pair_limit must be at least 0, not " + std::to_string(s.tiny_pair_limit));
    }
    if (!(s.contact_margin >= 0) || !std::isfinite(s.contact_margin)) {
        refuse("contact_margin must be finite and at least 0, not " +
               std::to_string(s.contact_margin));
    }
}

}  // namespace

std::shared_ptr<StagePlanner> plannerOf(const btDispatcher* dispatcher) {
    // Algorithms are made often (a pair per broadphase overlap): a one-entry cache per thread
    // keeps the registry's lock off that path.
    struct Cache {
        const btDispatcher* dispatcher = nullptr;
        std::uint64_t generation = 0;
        std::shared_ptr<StagePlanner> planner;
    };
    thread_local Cache cache;
    const std::uint64_t generation = registry().generation.load(std::memory_order_acquire);
    if (cache.dispatcher != dispatcher || cache.generation != generation) {
        std::shared_ptr<StagePlanner> planner = findPlanner(dispatcher);
        if (!planner) {
            static const std::shared_ptr<StagePlanner> unregistered =
                std::make_shared<StagePlanner>();
            planner = unregistered;
        }
        cache = {dispatcher, generation, std::move(planner)};
    }
    return cache.planner;
}

void setPlanner(const btDispatcher* dispatcher, const MeshStageSettings& settings) {
    checkSettings(settings);
    Registry& r = registry();
    std::lock_guard<std::mutex> lock(r.mutex);
    std::shared_ptr<StagePlanner>& planner = r.planners[dispatcher];
    if (!planner) {
        planner = std::make_shared<StagePlanner>();
    }
    planner->settings = settings;
    planner->reset();
    r.generation.fetch_add(1, std::memory_order_release);
}

// ---------------------------------------------------------------------------------------
// Per pair

narrowphase::QuerySettings PairStages::plan(narrowphase::QuerySettings base,
                                            std::int64_t trianglesA, std::int64_t trianglesB) {
    const MeshStageSettings& s = planner_->settings;
    measuring_ = false;
    offEnded_ = false;
    switch (s.sphere_stage) {
        case StageMode::kOn:
            sphere_ = Sphere::kTested;
            break;
        case StageMode::kOff:
            sphere_ = Sphere::kSkippedOff;
            break;
        case StageMode::kAuto:
            if (offLeft_ > 0) {
                --offLeft_;
                sphere_ = Sphere::kSkippedAuto;
                offEnded_ = offLeft_ == 0;
            } else {
                sphere_ = Sphere::kTested;
                measuring_ = true;
            }
            break;
    }
    switch (s.tree) {
        case StageMode::kOn:
            tree_ = Tree::kUsed;
            break;
        case StageMode::kOff:
            tree_ = Tree::kOff;
            break;
        case StageMode::kAuto:
            // Triangle counts are below 2^28 (bv_tree.h): the product fits. A tiny pair's
            // direct query tests the root volumes first: a near miss they part ends there.
            tree_ = trianglesA * trianglesB <= s.tiny_pair_limit ? Tree::kTiny : Tree::kUsed;
            break;
    }
    base.object_spheres = sphere_ == Sphere::kTested;
    base.use_tree = tree_ == Tree::kUsed;
    return base;
}

void PairStages::countOncePerEpoch(unsigned flag, StagePlanner::Counter counter) {
    const std::uint64_t epoch = planner_->epoch.load(std::memory_order_relaxed);
    if (epoch != epoch_) {
        epoch_ = epoch;
        countedFlags_ = 0;
    }
    if (!(countedFlags_ & flag)) {
        countedFlags_ |= flag;
        planner_->add(counter, 1);
    }
}

void PairStages::report(PairKind kind, const narrowphase::QueryCounters& c, std::size_t contacts) {
    using P = StagePlanner;
    P& p = *planner_;
    p.add(kind == PairKind::kMeshMesh ? P::k_mesh_mesh_queries : P::k_mesh_scenery_queries, 1);
    countOncePerEpoch(1u, P::k_pairs);
    const bool rejected = c.object_sphere_rejects > 0;
    switch (sphere_) {
        case Sphere::kTested:
            p.add(P::k_object_sphere_tests, c.object_sphere_tests);
            p.add(P::k_object_sphere_rejects, rejected ? 1 : 0);
            break;
        case Sphere::kSkippedAuto:
            p.add(P::k_sphere_skipped_auto, 1);
            countOncePerEpoch(2u, P::k_sphere_skipping_pairs);
            break;
        case Sphere::kSkippedOff:
            p.add(P::k_sphere_skipped_off, 1);
            countOncePerEpoch(2u, P::k_sphere_skipping_pairs);
            break;
    }
    if (offEnded_) {
        p.add(P::k_sphere_rearmed, 1);
    }
    if (measuring_) {
        ++measured_;
        rejects_ += rejected ? 1 : 0;
        const MeshStageSettings& s = p.settings;
        if (measured_ >= s.sphere_window) {
            if (double(rejects_) < s.sphere_min_reject_share * double(measured_)) {
                offLeft_ = s.sphere_rearm_after;
                p.add(P::k_sphere_turned_off, 1);
            }
            measured_ = 0;
            rejects_ = 0;
        }
    }
    if (!rejected) {
        switch (tree_) {
            case Tree::kUsed:
                p.add(P::k_tree_queries, 1);
                break;
            case Tree::kTiny:
                p.add(P::k_no_tree_tiny, 1);
                countOncePerEpoch(4u, P::k_tiny_pairs);
                break;
            case Tree::kOff:
                p.add(P::k_no_tree_off, 1);
                countOncePerEpoch(4u, P::k_tiny_pairs);
                break;
        }
    }
    p.add(P::k_root_rejects, c.root_rejects);
    p.add(P::k_node_sphere_tests, c.node_sphere_tests);
    p.add(P::k_node_sphere_rejects, c.node_sphere_rejects);
    p.add(P::k_node_box_tests, c.bv_tests);
    p.add(P::k_node_box_rejects, c.bv_rejects);
    p.add(P::k_leaf_pairs, c.leaf_pairs);
    p.add(P::k_triangle_box_rejects, c.triangle_box_rejects);
    p.add(P::k_triangle_tests, c.triangle_tests);
    p.add(P::k_intersecting_pairs, c.pairs);
    p.add(P::k_near_pairs, c.near_pairs);
    p.add(P::k_contacts, contacts);
}

}  // namespace detail

// ---------------------------------------------------------------------------------------

MeshStageStats narrowphaseStages(const btCollisionDispatcher* dispatcher) {
    return detail::registeredPlanner(dispatcher, "narrowphaseStages")->snapshot();
}

void resetNarrowphaseStages(const btCollisionDispatcher* dispatcher) {
    detail::registeredPlanner(dispatcher, "resetNarrowphaseStages")->reset();
}

void releaseNarrowphaseStages(const btCollisionDispatcher* dispatcher) {
    detail::Registry& r = detail::registry();
    std::lock_guard<std::mutex> lock(r.mutex);
    if (r.planners.erase(dispatcher) > 0) {
        r.generation.fetch_add(1, std::memory_order_release);
    }
}

namespace {

std::string percent(std::uint64_t part, std::uint64_t whole) {
    char text[32];
    std::snprintf(text, sizeof text, "%.1f%%", whole ? 100.0 * double(part) / double(whole) : 0.0);
    return text;
}

}  // namespace

std::string describeStages(const MeshStageStats& s) {
    const MeshStageSettings& set = s.settings;
    const std::uint64_t queries = s.mesh_mesh_queries + s.mesh_scenery_queries;
    auto n = [](std::uint64_t value) { return std::to_string(value); };
    std::string out;
    out += "queries: " + n(s.mesh_mesh_queries) + " mesh-mesh, " + n(s.mesh_scenery_queries) +
           " mesh-scenery (" + n(s.scenery_models_built) +
           " built a model of the scenery's triangles, the others reused their pair's) in " +
           n(s.pairs) + " pairs; " + n(s.convex_mesh_queries) +
           " convex-mesh (primitive pairs: Bullet's convex-triangle path, no kolize triangle "
           "stage)\n";
    out += std::string("sphere stage (") + stageModeName(set.sphere_stage) +
           "): " + n(s.object_sphere_tests) + " tests, " + n(s.object_sphere_rejects) +
           " rejected (" + percent(s.object_sphere_rejects, s.object_sphere_tests) + ")";
    if (s.sphere_skipped_auto > 0) {
        char rule[96];
        std::snprintf(rule, sizeof rule, "rejected under %.1f%% of %d queries in a row",
                      100 * set.sphere_min_reject_share, set.sphere_window);
        out += "; skipped in " + n(s.sphere_skipped_auto) + " queries of " +
               n(s.sphere_skipping_pairs) + " of " + n(s.pairs) + " pairs (" + rule +
               "; turned off " + n(s.sphere_turned_off) + " times, re-armed " +
               n(s.sphere_rearmed) + " times after " + std::to_string(set.sphere_rearm_after) +
               " queries)";
    }
    if (s.sphere_skipped_off > 0) {
        out += "; skipped in " + n(s.sphere_skipped_off) + " queries (sphere_stage off)";
    }
    if (s.object_sphere_tests == 0 && queries == 0) {
        out += "; no mesh queries";
    }
    out += "\n";
    out += std::string("tree (") + stageModeName(set.tree) + "): " + n(s.tree_queries) +
           " queries traversed it (" + n(s.node_sphere_tests) + " node-sphere tests, " +
           percent(s.node_sphere_rejects, s.node_sphere_tests) + " rejected; " +
           n(s.node_box_tests) + " box tests, " + percent(s.node_box_rejects, s.node_box_tests) +
           " rejected; " + n(s.leaf_pairs) + " leaf pairs)";
    if (s.no_tree_tiny > 0) {
        out += "; skipped in " + n(s.no_tree_tiny) + " queries of " + n(s.tiny_pairs) +
               " pairs (tiny: triangles(A) * triangles(B) <= " + n(set.tiny_pair_limit) +
               ": the root volumes tested, " + n(s.root_rejects) +
               " of them apart, then every triangle pair directly)";
    }
    if (s.no_tree_off > 0) {
        out += "; skipped in " + n(s.no_tree_off) + " queries (tree off)";
    }
    out += "\n";
    out += "triangle stage: " + n(s.triangle_tests) + " exact tests (" + n(s.triangle_box_rejects) +
           " triangle pairs rejected by their boxes), " + n(s.intersecting_pairs) +
           " intersecting pairs, " + n(s.contacts) + " contact points";
    if (set.contact_margin > 0) {
        char margin[64];
        std::snprintf(margin, sizeof margin, "%g", set.contact_margin);
        out += "; " + n(s.near_pairs) + " pairs apart within the contact margin (" + margin + " m)";
    }
    if (s.convex_mesh_queries > 0) {
        out += "; skipped for the " + n(s.convex_mesh_queries) + " convex-mesh queries";
    }
    out += "\n";
    out += "ccd: " + n(s.toi_calls) + " time-of-impact calls, " + n(s.toi_skipped_slow) +
           " skipped (neither body past its CCD motion threshold), " + n(s.toi_hits) + " hits\n";
    return out;
}

}  // namespace kolize
