#pragma once
/// \file
/// Settings shared by every broadphase the factory makes, with documented defaults.

#include <kolize/broadphase/cell_grid_settings.h>
#include <kolize/broadphase/tree_settings.h>

#include <LinearMath/btVector3.h>

#include <functional>
#include <string>

class btOverlappingPairCache;

namespace kolize {

/// What a kolize broadphase tells you when it rejects an AABB.
struct BadAabbReport {
    /// Name of the broadphase ("grid", "brute-force", ...).
    std::string broadphase;
    /// "createProxy" or "setAabb".
    std::string operation;
    /// The proxy's m_uniqueId and m_clientObject (Bullet's btCollisionObject*, usually).
    int proxyUid = 0;
    const void* clientObject = nullptr;
    /// The rejected box, as given.
    btVector3 aabbMin;
    btVector3 aabbMax;
    /// Why it was rejected: "NaN coordinate", "infinite coordinate", "min > max".
    std::string reason;
    /// One line naming the broadphase, the proxy, the values and the reason.
    std::string message() const;
};

/// When a kolize broadphase evaluates the collision filters of a pair (the pair cache's
/// needsBroadphaseCollision: groups and masks, and the overlap filter callback).
enum class FilterEvaluation {
    /// When the pair starts overlapping, as Bullet's own broadphases do (the default). A
    /// pair the filters rejected stays out of the cache while its boxes keep overlapping.
    /// To change an object's filters, remove it from the world and add it again, or call
    /// btCollisionWorld::refreshBroadphaseProxy: its new proxy's pairs are evaluated at the
    /// next pair search. Changing m_collisionFilterGroup / Mask in place affects only pairs
    /// that start overlapping later.
    WhenAdded,
    /// At every pair search, for every overlapping pair: groups, masks and the filter
    /// callback may change in place and take effect at the next search. Costs one filter
    /// evaluation per overlapping pair per frame (O(pairs) even when nothing moves).
    EveryFrame,
};

/// The pair cache a kolize broadphase makes for itself when BroadphaseSettings::pairCache
/// is null.
enum class PairCacheChoice {
    /// kolize::MergedPairCache (merged_pair_cache.h): the pair search hands it its changes
    /// without a lookup, and they are merged into one sorted array once per search.
    Merged,
    /// Bullet's btHashedOverlappingPairCache: one hash lookup per added or removed pair.
    Hashed,
};

/// Settings for kolize::makeBroadphase. Every field has a usable default.
struct BroadphaseSettings {
    /// World bounds for Bullet's sweep-and-prune ("sap", "sap-noray", "sap32"). SAP quantises
    /// boxes to this region; objects outside it still get (conservative) pairs. kolize's
    /// own broadphases are unbounded and ignore these.
    btVector3 worldMin{-1000, -1000, -1000};
    btVector3 worldMax{1000, 1000, 1000};
    /// Capacity of the fixed-size Bullet broadphases: "sap" and "sap-noray" (at most 32766,
    /// a limit of btAxisSweep3's 16-bit handles), "sap32" and "simple". Creating more
    /// proxies than this fails inside Bullet. kolize's broadphases and "dbvt" grow freely.
    int maxProxies = 32766;
    /// Pair cache to use instead of a new btHashedOverlappingPairCache. Not owned: it must
    /// outlive the broadphase. kolize's broadphases need immediate removal and reject a
    /// cache with deferred removal (btSortedOverlappingPairCache) with std::invalid_argument.
    btOverlappingPairCache* pairCache = nullptr;
    /// The cache kolize's broadphases make when pairCache is null (Bullet's broadphases
    /// always make Bullet's). Both keep Bullet's contract (merged_pair_cache.h lists the
    /// differences in order and timing).
    PairCacheChoice ownPairCache = PairCacheChoice::Hashed;
    /// Called when a kolize broadphase rejects an AABB (NaN, +-inf, or min > max). The proxy
    /// keeps its last valid box; a proxy created with a bad box takes part in no pair until
    /// its first valid setAabb. Empty (the default): print the report's message() on stderr,
    /// the first 16 times per broadphase, then count silently (see printStats()).
    std::function<void(const BadAabbReport&)> onBadAabb;
    /// Fat boxes for slow objects (kolize's own broadphases). The margin is this fraction of
    /// the box's largest extent plus two float steps of its largest coordinate. An object
    /// whose box moved less than a quarter of its margin since its last setAabb is stored in
    /// the core with its box enlarged by the margin, as Box2D and dbvt keep boxes: while it
    /// jitters inside (resting piles, stacks, slow sliding), setAabb changes nothing in the
    /// core and the pair search skips it; only its candidate pairs get the exact box test.
    /// Faster objects, and every object at creation, keep exact boxes (enlarged boxes would
    /// only add candidates). The pairs reported are exact either way. 0 turns fat boxes off;
    /// the factory accepts 0..10.
    btScalar fatMargin = btScalar(0.05);
    /// When filters are evaluated (kolize's own broadphases); see FilterEvaluation.
    FilterEvaluation filters = FilterEvaluation::WhenAdded;

    /// Cell size, region and overflow rules of "grid", "spatial-tree" and "spatial-hash".
    CellGridSettings cells;

    // --- The segment-tree cores (tree_settings.h documents the fields) ---
    /// "segment-trees": leaf width (S = 1000 by default) and traversal.
    SegmentTreeSettings segmentTrees;
    /// "range-tree": leaf width (S = 1000 by default), tree axis, sorted-list search.
    RangeTreeSettings rangeTree;
};

}  // namespace kolize
