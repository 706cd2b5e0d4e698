#pragma once
/// \file
/// The one adapter that maps any kolize core onto btBroadphaseInterface.
///
/// BroadphaseAdapter (not a template) owns what every broadphase needs: proxies with
/// stable addresses and deterministic unique ids, the bad-AABB policy, and the pair diff,
/// the only code that talks to btOverlappingPairCache. CoreBroadphase<Core> adds the
/// core: candidates and queries come from it, the exact box test happens here, once per
/// candidate.
///
/// Fat boxes (BroadphaseSettings::fatMargin): the core holds, per object, a box that
/// contains the exact one; slow objects get an enlarged box, so a setAabb inside it changes
/// nothing in the core. The adapter keeps every pair whose core boxes overlap (the
/// candidate pairs) from frame to frame and tests the exact boxes of each one every frame.
///
/// Exactness contract: after calculateOverlappingPairs the pair cache holds exactly the
/// pairs whose current AABBs overlap (closed intervals) and that pass the cache's filters
/// (evaluated every frame, so changed groups, masks or filter callbacks take effect on the
/// next frame). Only the difference from the previous frame goes through
/// addOverlappingPair / removeOverlappingPair, so ghost callbacks see each change once and
/// cached collision algorithms survive while a pair persists. A pair that someone else
/// removes from the cache is not re-added until it stops and starts overlapping again.

#include <kolize/broadphase/aabb.h>
#include <kolize/broadphase/pair_set.h>
#include <kolize/broadphase/settings.h>

#include <BulletCollision/BroadphaseCollision/btBroadphaseInterface.h>
#include <BulletCollision/BroadphaseCollision/btBroadphaseProxy.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace kolize {

/// Counters a kolize broadphase keeps (printStats() prints them).
struct AdapterStats {
    std::size_t proxies = 0;              ///< live proxies
    std::size_t parkedProxies = 0;        ///< live proxies without a valid box yet
    std::size_t slots = 0;                ///< proxy slots allocated: live, free or awaiting reuse
    std::size_t overlappingPairs = 0;     ///< pairs whose AABBs overlapped at the last search
                                          ///< (before filters)
    std::size_t candidatePairs = 0;       ///< pairs whose core (fat) boxes overlap
    std::size_t frames = 0;               ///< calculateOverlappingPairs calls
    std::size_t candidatesLastFrame = 0;  ///< candidate pairs the core produced last frame
    std::size_t incrementalSearches = 0;  ///< frames that queried only the moved objects
    std::size_t movesInsideFatBoxes = 0;  ///< setAabb calls absorbed by a fat box, all time
    std::size_t coreUpdates = 0;          ///< setAabb calls that changed a core box, all time
    std::size_t pairsAdded = 0;           ///< addOverlappingPair calls that added, all frames
    std::size_t pairsRemoved = 0;         ///< removeOverlappingPair calls, all frames
    std::size_t badAabbReports = 0;       ///< rejected boxes, all time
    std::size_t memoryBytes = 0;          ///< adapter + core, approximate
};

class BroadphaseAdapter : public btBroadphaseInterface {
  public:
    using Box = Aabb<3, btScalar>;

    /// Throws std::invalid_argument when settings.pairCache has deferred removal.
    BroadphaseAdapter(std::string name, const BroadphaseSettings& settings);
    ~BroadphaseAdapter() override;
    BroadphaseAdapter(const BroadphaseAdapter&) = delete;
    BroadphaseAdapter& operator=(const BroadphaseAdapter&) = delete;

    /// A bad box (NaN, +-inf, min > max) is reported and the proxy is created "parked":
    /// it exists, but takes part in no pair or query until its first valid setAabb.
    btBroadphaseProxy* createProxy(const btVector3& aabbMin, const btVector3& aabbMax,
                                   int shapeType, void* userPtr, int collisionFilterGroup,
                                   int collisionFilterMask, btDispatcher* dispatcher) override;
    /// Removes the proxy's pairs from the cache first; its memory is reused only after the
    /// next calculateOverlappingPairs (or after 4096 destroys without one). Throws
    /// std::invalid_argument for a foreign or already destroyed proxy.
    void destroyProxy(btBroadphaseProxy* proxy, btDispatcher* dispatcher) override;
    /// A bad box is reported and ignored: the proxy keeps its last valid box.
    void setAabb(btBroadphaseProxy* proxy, const btVector3& aabbMin, const btVector3& aabbMax,
                 btDispatcher* dispatcher) override;
    /// The last valid box (for a proxy still waiting for one: the rejected creation box).
    void getAabb(btBroadphaseProxy* proxy, btVector3& aabbMin, btVector3& aabbMax) const override;
    btOverlappingPairCache* getOverlappingPairCache() override { return pairCache_; }
    const btOverlappingPairCache* getOverlappingPairCache() const override { return pairCache_; }
    /// The union of all valid proxy boxes (zero box when there are none).
    void getBroadphaseAabb(btVector3& aabbMin, btVector3& aabbMax) const override;
    /// When no proxy is alive, frees all memory and restarts ids, for reproducible runs.
    void resetPool(btDispatcher* dispatcher) override;
    void printStats() override;

    const std::string& name() const { return name_; }
    AdapterStats stats() const;
    /// Checks proxy table, pair set and core invariants; throws std::logic_error.
    void validate() const;

  protected:
    struct Proxy : btBroadphaseProxy {
        ObjectId slot = 0;
    };

    virtual void coreInsert(ObjectId id, const Box& box) = 0;
    virtual void coreUpdate(ObjectId id, const Box& box) = 0;
    virtual void coreRemove(ObjectId id) = 0;
    virtual void coreValidate() const = 0;
    virtual std::size_t coreMemoryBytes() const = 0;

    static Box toBox(const btVector3& aabbMin, const btVector3& aabbMax) {
        return Box{{aabbMin.x(), aabbMin.y(), aabbMin.z()},
                   {aabbMax.x(), aabbMax.y(), aabbMax.z()}};
    }
    static Ray<3, btScalar> toRay(const btVector3& rayFrom, const btBroadphaseRayCallback& callback,
                                  const btVector3& aabbMin, const btVector3& aabbMax);

    /// The exact box (the last valid one Bullet gave).
    const Box& boxOf(ObjectId id) const { return boxes_[id]; }
    /// The box the core holds: contains boxOf(id).
    const Box& fatBoxOf(ObjectId id) const { return fat_[id]; }
    Proxy* proxyOf(ObjectId id) const { return &chunks_[id >> kChunkBits][id & kChunkMask]; }

    /// True when this pair search may be incremental: only the objects whose core box
    /// changed since the last search (at most a quarter of them) are queried, and the
    /// candidate pairs between unchanged objects are kept. A full search runs at least every
    /// kFullSearchEvery frames (the cores re-tune themselves there).
    bool incrementalSearch() const {
        return counters_.frames > 0 && framesSinceFullSearch_ < kFullSearchEvery &&
               moved_.size() * 4 <= liveCount_;
    }
    /// Visits every live object whose core box changed since the last pair search.
    template <class Visit>
    void forEachMoved(Visit&& visit) const {
        for (ObjectId id : moved_) {
            if (state_[id] == SlotState::Live) {
                visit(id);
            }
        }
    }
    /// Starts a frame of pair finding: call markCandidate for each pair whose core boxes
    /// overlap (at least once), then finishPairs.
    void beginPairs() { ++stamp_; }
    void markCandidate(ObjectId a, ObjectId b) {
        bool inserted = false;
        pairs_.findOrInsert(a, b, inserted).stamp = stamp_;
    }
    /// Tests the exact boxes of every candidate pair and applies the difference from the
    /// previous frame to the pair cache. After an incremental search the candidate pairs
    /// between two live objects whose core boxes did not change are kept without being
    /// marked.
    void finishPairs(btDispatcher* dispatcher, std::size_t candidates, bool incremental);

  private:
    enum class SlotState : std::uint8_t { Free, Live, Parked, PendingFree };
    static constexpr unsigned kChunkBits = 8;
    static constexpr ObjectId kChunkMask = (1u << kChunkBits) - 1;
    static constexpr std::size_t kFullSearchEvery = 64;

    Proxy* checkedProxy(btBroadphaseProxy* proxy, const char* operation) const;
    void releasePendingSlots();
    /// Returns an empty string for a valid box, else the reason.
    static const char* rejectReason(const btVector3& aabbMin, const btVector3& aabbMax);
    void reportBadAabb(const char* operation, const Proxy& proxy, const btVector3& aabbMin,
                       const btVector3& aabbMax, const char* reason);
    /// The core box for `box`, which replaces `previous`: enlarged when the object moved
    /// less than the margin, else `box` itself.
    Box fatBox(const Box& box, const Box& previous) const;

    std::string name_;
    BroadphaseSettings settings_;
    btOverlappingPairCache* pairCache_ = nullptr;
    bool ownsPairCache_ = false;

    std::vector<std::unique_ptr<Proxy[]>> chunks_;
    std::vector<Box> boxes_;
    std::vector<Box> fat_;
    std::vector<SlotState> state_;
    std::vector<ObjectId> freeSlots_;
    std::vector<ObjectId> pendingFree_;
    int nextUid_ = 1;
    std::size_t liveCount_ = 0;
    std::size_t parkedCount_ = 0;

    void noteMoved(ObjectId slot) {
        if (!movedFlag_[slot]) {
            movedFlag_[slot] = 1;
            moved_.push_back(slot);
        }
    }

    PairSet pairs_;
    std::uint32_t stamp_ = 0;
    std::vector<ObjectId> moved_;          ///< slots whose box changed since the last search
    std::vector<std::uint8_t> movedFlag_;  ///< per slot: in moved_
    std::size_t framesSinceFullSearch_ = 0;
    AdapterStats counters_;
};

/// A btBroadphaseInterface over a kolize core. `Core` provides insert / update / remove,
/// findCandidates(sink) (each unordered candidate pair at most once), queryBox and
/// queryRay (supersets of the answer), validate() and memoryBytes().
template <class Core>
class CoreBroadphase final : public BroadphaseAdapter {
  public:
    CoreBroadphase(std::string name, const BroadphaseSettings& settings,
                   const typename Core::Settings& coreSettings = {})
        : BroadphaseAdapter(std::move(name), settings), core_(coreSettings) {}

    void calculateOverlappingPairs(btDispatcher* dispatcher) override {
        std::size_t candidates = 0;
        const bool incremental = incrementalSearch();
        beginPairs();
        if (incremental) {
            forEachMoved([&](ObjectId moved) {
                const Box& box = fatBoxOf(moved);
                core_.queryBox(box, [&](ObjectId id) {
                    ++candidates;
                    if (id != moved && overlaps(fatBoxOf(id), box)) {
                        markCandidate(moved, id);
                    }
                });
            });
        } else {
            core_.findCandidates([&](ObjectId a, ObjectId b) {
                ++candidates;
                if (overlaps(fatBoxOf(a), fatBoxOf(b))) {
                    markCandidate(a, b);
                }
            });
        }
        finishPairs(dispatcher, candidates, incremental);
    }

    void aabbTest(const btVector3& aabbMin, const btVector3& aabbMax,
                  btBroadphaseAabbCallback& callback) override {
        const Box query = toBox(aabbMin, aabbMax);
        core_.queryBox(query, [&](ObjectId id) {
            if (overlaps(boxOf(id), query)) {
                callback.process(proxyOf(id));
            }
        });
    }

    void rayTest(const btVector3& rayFrom, const btVector3& /*rayTo*/,
                 btBroadphaseRayCallback& callback, const btVector3& aabbMin,
                 const btVector3& aabbMax) override {
        const Ray<3, btScalar> ray = toRay(rayFrom, callback, aabbMin, aabbMax);
        core_.queryRay(ray, [&](ObjectId id) {
            if (rayHits(boxOf(id), ray)) {
                callback.process(proxyOf(id));
            }
        });
    }

    const Core& core() const { return core_; }

  private:
    void coreInsert(ObjectId id, const Box& box) override { core_.insert(id, box); }
    void coreUpdate(ObjectId id, const Box& box) override { core_.update(id, box); }
    void coreRemove(ObjectId id) override { core_.remove(id); }
    void coreValidate() const override { core_.validate(); }
    std::size_t coreMemoryBytes() const override { return core_.memoryBytes(); }

    Core core_;
};

}  // namespace kolize
