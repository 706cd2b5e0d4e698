#include <kolize/kolize.h>

#include <kolize/broadphase/brute_force.h>
#include <kolize/broadphase/bullet_adapter.h>
#include <kolize/broadphase/cell_grid.h>
#include <kolize/broadphase/range_tree.h>
#include <kolize/broadphase/segment_tree_set.h>
#include <kolize/broadphase/sweep_and_prune.h>

#include <BulletCollision/BroadphaseCollision/btAxisSweep3.h>
#include <BulletCollision/BroadphaseCollision/btDbvtBroadphase.h>
#include <BulletCollision/BroadphaseCollision/btSimpleBroadphase.h>

#include <cmath>
#include <stdexcept>
#include <string>

namespace kolize {

namespace {

constexpr int kSap16MaxProxies = 32766;

void requireCapacity(std::string_view name, int maxProxies, int limit) {
    if (maxProxies < 2 || maxProxies > limit) {
        throw std::invalid_argument("kolize: broadphase '" + std::string(name) +
                                    "' needs settings.maxProxies in [2, " + std::to_string(limit) +
                                    "], got " + std::to_string(maxProxies));
    }
}

void requireWorldBounds(std::string_view name, const BroadphaseSettings& settings) {
    for (int axis = 0; axis < 3; ++axis) {
        const btScalar lo = settings.worldMin[axis], hi = settings.worldMax[axis];
        if (!(std::isfinite(lo) && std::isfinite(hi) && lo < hi)) {
            throw std::invalid_argument(
                "kolize: broadphase '" + std::string(name) +
                "' quantises to settings.worldMin..worldMax, which must be finite with min < max "
                "on every axis; axis " +
                std::to_string(axis) + " is " + std::to_string(lo) + ".." + std::to_string(hi));
        }
    }
}

}  // namespace

const std::vector<std::string>& broadphaseNames() {
    static const std::vector<std::string> names = {
        "auto",       "grid",  "spatial-tree", "spatial-hash", "segment-trees",
        "range-tree", "sweep", "brute-force",  "dbvt",         "sap",
        "sap-noray",  "sap32", "simple"};
    return names;
}

std::string broadphaseNameList() {
    std::string out;
    for (const std::string& name : broadphaseNames()) {
        out += (out.empty() ? "" : ", ") + name;
    }
    return out;
}

PairCacheChoice pairCacheNamed(std::string_view name) {
    if (name == "merged") {
        return PairCacheChoice::Merged;
    }
    if (name == "hashed") {
        return PairCacheChoice::Hashed;
    }
    throw std::invalid_argument("kolize: unknown pair cache '" + std::string(name) +
                                "'; valid: merged, hashed");
}

bool isExactBroadphase(std::string_view name) {
    return name == "auto" || name == "grid" || name == "spatial-tree" || name == "spatial-hash" ||
           name == "segment-trees" || name == "range-tree" || name == "sweep" ||
           name == "brute-force";
}

std::unique_ptr<btBroadphaseInterface> makeBroadphase(std::string_view name,
                                                      const BroadphaseSettings& settings) {
    if (name == "grid") {
        return std::make_unique<CoreBroadphase<UniformGrid<3, btScalar>>>(std::string(name),
                                                                          settings, settings.cells);
    }
    if (name == "spatial-tree") {
        return std::make_unique<CoreBroadphase<SpatialTree<3, btScalar>>>(std::string(name),
                                                                          settings, settings.cells);
    }
    if (name == "spatial-hash") {
        return std::make_unique<CoreBroadphase<SpatialHash<3, btScalar>>>(std::string(name),
                                                                          settings, settings.cells);
    }
    if (name == "brute-force") {
        return std::make_unique<CoreBroadphase<BruteForce<3, btScalar>>>(std::string(name),
                                                                         settings);
    }
    // The adapter keeps the candidate pairs between frames itself; the tree cores' own
    // kept set would only duplicate that work.
    if (name == "segment-trees") {
        SegmentTreeSettings trees = settings.segmentTrees;
        trees.incremental = false;
        return std::make_unique<CoreBroadphase<SegmentTreeSet<3, btScalar>>>(std::string(name),
                                                                             settings, trees);
    }
    if (name == "range-tree") {
        RangeTreeSettings tree = settings.rangeTree;
        tree.incremental = false;
        return std::make_unique<CoreBroadphase<RangeTree<3, btScalar>>>(std::string(name), settings,
                                                                        tree);
    }
    if (name == "auto") {
        AutoSettings automatic;
        automatic.cells = settings.cells;
        return std::make_unique<CoreBroadphase<AutoCore<3, btScalar>>>(std::string(name), settings,
                                                                       automatic);
    }
    if (name == "sweep") {
        return std::make_unique<CoreBroadphase<SweepAndPrune<3, btScalar>>>(std::string(name),
                                                                            settings);
    }
    if (name == "dbvt") {
        return std::make_unique<btDbvtBroadphase>(settings.pairCache);
    }
    if (name == "sap" || name == "sap-noray") {
        requireCapacity(name, settings.maxProxies, kSap16MaxProxies);
        requireWorldBounds(name, settings);
        return std::make_unique<btAxisSweep3>(
            settings.worldMin, settings.worldMax, static_cast<unsigned short>(settings.maxProxies),
            settings.pairCache, /*disableRaycastAccelerator=*/name == "sap-noray");
    }
    if (name == "sap32") {
        requireCapacity(name, settings.maxProxies, 0x7ffffffe);
        requireWorldBounds(name, settings);
        return std::make_unique<bt32BitAxisSweep3>(settings.worldMin, settings.worldMax,
                                                   static_cast<unsigned>(settings.maxProxies),
                                                   settings.pairCache);
    }
    if (name == "simple") {
        requireCapacity(name, settings.maxProxies, 0x7ffffffe);
        return std::make_unique<btSimpleBroadphase>(settings.maxProxies, settings.pairCache);
    }
    throw std::invalid_argument("kolize: unknown broadphase '" + std::string(name) +
                                "'; valid names: " + broadphaseNameList());
}

}  // namespace kolize
