#pragma once
/// \file
/// MergedPairCache: a btOverlappingPairCache that keeps its pairs in one array sorted by the
/// proxies' unique ids and applies a frame's changes in one merge.
///
/// Bullet's btHashedOverlappingPairCache pays a hash lookup per added or removed pair, and
/// each lookup is a few cache misses once the pairs outgrow the cache (about 200 ns per
/// change at two million pairs). A kolize broadphase knows whether each pair it adds is new
/// and each pair it removes is there; it hands its changes to this cache without a lookup
/// (addAbsentPair, removePresentPair), and the cache sorts them and merges them into the
/// array once, at the end of the pair search (flush). Everyone else uses Bullet's
/// interface, with Bullet's semantics.
///
/// The contract, as btHashedOverlappingPairCache keeps it:
/// - addOverlappingPair evaluates the filters (needsBroadphaseCollision) at once, returns
///   null when they reject the pair, returns the pair already there for a pair already
///   there, and calls the ghost pair callback only for a new pair.
/// - removeOverlappingPair frees the pair's collision algorithm and calls the ghost pair
///   callback at once; a pair that is not there is ignored.
/// - findPair, getNumOverlappingPairs, getOverlappingPairArray and processAllOverlappingPairs
///   see every change made before them.
///
/// Where it differs, by design:
/// - The array is sorted by (smaller uid, larger uid), and processAllOverlappingPairs
///   visits it from the end: always the order Bullet's hashed cache uses in deterministic
///   mode (btDispatcherInfo::m_deterministicOverlappingPairs), whatever the mode.
/// - A pair added through addOverlappingPair enters the array at the next read of it; the
///   pointer addOverlappingPair returns is valid until the next call into the cache (Bullet's
///   is valid until the array grows). removeOverlappingPair returns the removed pair's
///   m_internalInfo1, as Bullet does, for a pair already in the array, else null.
/// - Callbacks of processAllOverlappingPairs may add and remove pairs; the array they
///   iterate does not move under them (removed pairs leave it when the walk ends).
///
/// Reads cost O(log pairs) (findPair) or nothing extra when no change is pending; a flush
/// costs O(changes log changes + the pairs from the first changed one to the end).

#include <BulletCollision/BroadphaseCollision/btOverlappingPairCache.h>

#include <cstdint>
#include <unordered_map>
#include <vector>

namespace kolize {

class MergedPairCache : public btOverlappingPairCache {
  public:
    MergedPairCache() = default;
    ~MergedPairCache() override = default;
    MergedPairCache(const MergedPairCache&) = delete;
    MergedPairCache& operator=(const MergedPairCache&) = delete;

    // --- btOverlappingPairCallback ---
    btBroadphasePair* addOverlappingPair(btBroadphaseProxy* proxy0,
                                         btBroadphaseProxy* proxy1) override;
    void* removeOverlappingPair(btBroadphaseProxy* proxy0, btBroadphaseProxy* proxy1,
                                btDispatcher* dispatcher) override;
    void removeOverlappingPairsContainingProxy(btBroadphaseProxy* proxy,
                                               btDispatcher* dispatcher) override;

    // --- btOverlappingPairCache ---
    btBroadphasePair* getOverlappingPairArrayPtr() override;
    const btBroadphasePair* getOverlappingPairArrayPtr() const override;
    btBroadphasePairArray& getOverlappingPairArray() override;
    /// Frees the pair's collision algorithm (as Bullet's caches do).
    void cleanOverlappingPair(btBroadphasePair& pair, btDispatcher* dispatcher) override;
    /// Exact without a merge (given addAbsentPair's and removePresentPair's preconditions;
    /// a flush makes it exact whatever came before).
    int getNumOverlappingPairs() const override { return static_cast<int>(count_); }
    bool needsBroadphaseCollision(btBroadphaseProxy* proxy0,
                                  btBroadphaseProxy* proxy1) const override;
    btOverlapFilterCallback* getOverlapFilterCallback() override { return filter_; }
    void setOverlapFilterCallback(btOverlapFilterCallback* callback) override {
        filter_ = callback;
    }
    /// Frees the algorithms of the proxy's pairs; the pairs stay. O(pairs), as Bullet's.
    void cleanProxyFromPairs(btBroadphaseProxy* proxy, btDispatcher* dispatcher) override;
    /// Visits every pair, from the largest ids to the smallest; a pair whose processOverlap
    /// returns true is removed (algorithm freed, ghost callback called) at once.
    void processAllOverlappingPairs(btOverlapCallback* callback, btDispatcher* dispatcher) override;
    void processAllOverlappingPairs(btOverlapCallback* callback, btDispatcher* dispatcher,
                                    const btDispatcherInfo& dispatchInfo) override;
    btBroadphasePair* findPair(btBroadphaseProxy* proxy0, btBroadphaseProxy* proxy1) override;
    bool hasDeferredRemoval() override { return false; }
    void setInternalGhostPairCallback(btOverlappingPairCallback* ghostPairCallback) override {
        ghost_ = ghostPairCallback;
    }
    /// The array is always sorted: applies pending changes, nothing else.
    void sortOverlappingPairs(btDispatcher*) override { flush(); }

    // --- For a caller that knows each pair's state (a kolize broadphase) ---
    /// Adds a pair the caller knows is not in the cache, without evaluating the filters
    /// (ask needsBroadphaseCollision first) and without a lookup. Calls the ghost pair
    /// callback now; the pair enters the array at the next flush. Returns a stand-in for
    /// the pair (a copy, not the pair itself), valid until the next call.
    btBroadphasePair* addAbsentPair(btBroadphaseProxy* proxy0, btBroadphaseProxy* proxy1);
    /// Removes a pair the caller knows is in the cache, without a lookup. Calls the ghost
    /// pair callback now; the pair's algorithm is freed (through `dispatcher`) and the pair
    /// leaves the array at the next flush.
    void removePresentPair(btBroadphaseProxy* proxy0, btBroadphaseProxy* proxy1,
                           btDispatcher* dispatcher);
    /// Applies every pending change: one sort of the changes, one merge into the array.
    /// Every read of the array flushes first; a broadphase calls it at the end of its pair
    /// search, so that the merge counts as broadphase time.
    void flush() const;
    /// Changes waiting for the next flush.
    std::size_t pendingChanges() const { return changes_.size() + added_.size() + tombstones_; }

    /// Checks that the array is sorted, unique and matches its keys and the count; throws
    /// std::logic_error.
    void validate() const;

  private:
    /// A pair added through Bullet's interface, waiting for the next flush (the caller may
    /// have set its algorithm or user data). Null proxies: removed again.
    struct Waiting {
        std::uint64_t key;
        btBroadphasePair pair;
    };
    /// A change by addAbsentPair / removePresentPair: the pair's proxies, ordered by uid.
    struct Change {
        std::uint64_t key;
        btBroadphaseProxy* proxy0;
        btBroadphaseProxy* proxy1;
        btDispatcher* dispatcher;  ///< a removal's; null for an add
        bool add;
    };
    struct Order {
        std::uint64_t key;
        std::uint32_t index;  ///< into added_ then changes_: the order they were made in
    };

    /// The pair's key: (smaller uid, larger uid), ordered as signed ints.
    static std::uint64_t keyOf(const btBroadphaseProxy* proxy0, const btBroadphaseProxy* proxy1);
    /// Index of `key` in the array, or -1.
    int indexOf(std::uint64_t key) const;
    /// Flushes when changes by addAbsentPair / removePresentPair wait: Bullet's interface
    /// then works on the merged array.
    void flushTrustedChanges() const {
        if (!changes_.empty()) {
            flush();
        }
    }
    /// Removes array entry `at` now: frees its algorithm, calls the ghost callback, leaves
    /// a hole that the next flush closes.
    void removeAt(int at, btDispatcher* dispatcher);
    static bool isHole(const btBroadphasePair& pair) { return pair.m_pProxy0 == nullptr; }
    void visitAll(btOverlapCallback* callback, btDispatcher* dispatcher);

    // The sorted array and its keys (parallel). A pair removed through Bullet's interface
    // becomes a hole (null proxies) until the next flush.
    mutable btBroadphasePairArray pairs_;
    mutable std::vector<std::uint64_t> keys_;
    mutable std::size_t tombstones_ = 0;
    /// Where holes were made (a hole revived since stays listed; repeats possible).
    mutable std::vector<std::size_t> holes_;
    /// Pairs added through Bullet's interface, waiting: index by key, for their lookups.
    /// A waiting pair removed again has null proxies.
    mutable std::vector<Waiting> added_;
    mutable std::unordered_map<std::uint64_t, std::uint32_t> addedIndex_;
    /// Changes by addAbsentPair / removePresentPair, in the order made.
    mutable std::vector<Change> changes_;
    mutable std::size_t count_ = 0;  ///< pairs after the pending changes
    mutable int walking_ = 0;        ///< processAllOverlappingPairs under way: no flush
    btOverlapFilterCallback* filter_ = nullptr;
    btOverlappingPairCallback* ghost_ = nullptr;

    /// A pair new to the array, to go in before index `at` (of the array without holes).
    struct Insert {
        std::size_t at;
        std::uint64_t key;
        btBroadphasePair pair;
    };
    /// Sorts by key, stably.
    static void sortByKey(std::vector<Order>& order, std::vector<Order>& scratch);
    /// Fills order_ with the pending changes, sorted.
    void sortChanges() const;
    /// The first array index at or after `from` whose key is not below `key`.
    std::size_t gallop(std::size_t from, std::uint64_t key) const;
    /// Moves array entries [from, to) (keys and pairs) to start at `dest`.
    void moveRun(std::size_t from, std::size_t to, std::size_t dest) const;

    mutable std::vector<Order> order_;
    mutable std::vector<Order> orderScratch_;
    mutable std::vector<Insert> inserts_;
    btBroadphasePair standIn_;  ///< what addAbsentPair returns
};

}  // namespace kolize
