#pragma once
/// \file
/// The one adapter that maps any kolize core onto btBroadphaseInterface.
///
/// BroadphaseAdapter (not a template) owns what every broadphase needs: proxies with
/// stable addresses and deterministic unique ids, the bad-AABB policy, the candidate pairs
/// kept between frames (PairStore, each object's pairs in its own list), and the pair diff,
/// the only code that talks to btOverlappingPairCache. CoreBroadphase<Core> adds the core:
/// new candidates and queries come from it, the exact box test happens here.
///
/// Work per frame is proportional to what changed. A pair search looks only at the objects
/// whose box changed since the last one: an object whose core box changed queries the core
/// for new candidates and drops the candidates it left; every object whose exact box
/// changed re-tests the exact boxes of its own candidate pairs. A pair of two objects whose
/// boxes did not change is not visited, and a frame in which nothing moved (a sleeping
/// world) costs O(1) beyond the setAabb comparisons. When more than a quarter of the
/// objects changed their core boxes the core's own all-pairs search replaces the queries.
///
/// Fat boxes (BroadphaseSettings::fatMargin): the core holds, per object, a box that
/// contains the exact one; slow objects get an enlarged box, so a setAabb inside it changes
/// nothing in the core. Candidate pairs are the pairs whose core boxes overlap.
///
/// Exactness contract: after calculateOverlappingPairs the pair cache holds exactly the
/// pairs whose current AABBs overlap (closed intervals) and whose filters accepted them
/// (see BroadphaseSettings::filters: by default evaluated when a pair starts overlapping,
/// as Bullet's own broadphases do). Only the difference from the previous frame goes
/// through addOverlappingPair / removeOverlappingPair, so ghost callbacks see each change
/// once and cached collision algorithms survive while a pair persists. A pair that someone
/// else removed from the cache (removeOverlappingPairsContainingProxy, a user's
/// removeOverlappingPair) while its boxes still overlap is found missing and added again at
/// the next pair search.

#include <kolize/broadphase/aabb.h>
#include <kolize/broadphase/auto_core.h>
#include <kolize/broadphase/pair_store.h>
#include <kolize/broadphase/settings.h>

#include <BulletCollision/BroadphaseCollision/btBroadphaseInterface.h>
#include <BulletCollision/BroadphaseCollision/btBroadphaseProxy.h>

#include <cmath>
#include <cstdint>
#include <deque>
#include <type_traits>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace kolize {

class MergedPairCache;

/// Counters a kolize broadphase keeps (printStats() prints them).
struct AdapterStats {
    std::size_t proxies = 0;                   ///< live proxies
    std::size_t parkedProxies = 0;             ///< live proxies without a valid box yet
    std::size_t slots = 0;                     ///< proxy slots allocated: live or free
    std::size_t overlappingPairs = 0;          ///< pairs whose AABBs overlap (before filters)
    std::size_t cachedPairs = 0;               ///< pairs this broadphase put in the pair cache
    std::size_t candidatePairs = 0;            ///< pairs whose core (fat) boxes overlap
    std::size_t frames = 0;                    ///< calculateOverlappingPairs calls
    std::size_t candidatesLastFrame = 0;       ///< candidates the core produced last frame
    std::size_t pairsTestedLastFrame = 0;      ///< exact box tests of kept pairs last frame
    std::size_t objectsLookedAtLastFrame = 0;  ///< objects whose pairs were visited last frame
    std::size_t incrementalSearches = 0;       ///< frames that queried only the moved objects
    std::size_t fullSearches = 0;              ///< frames that ran the core's all-pairs search
    std::size_t idleFrames = 0;                ///< frames in which no box had changed
    std::size_t movesInsideFatBoxes = 0;       ///< setAabb calls absorbed by a fat box, all time
    std::size_t coreUpdates = 0;               ///< setAabb calls that changed a core box, all time
    std::size_t pairsAdded = 0;                ///< addOverlappingPair calls that added, all frames
    std::size_t pairsRemoved = 0;              ///< removeOverlappingPair calls, all frames
    std::size_t pairsRestored = 0;             ///< pairs found removed by others and added again
    std::size_t cacheChecks = 0;               ///< frames that looked up every cached pair
    std::size_t badAabbReports = 0;            ///< rejected boxes, all time
    std::size_t emptyQueries = 0;              ///< inverted or NaN query boxes (answered empty)
    std::size_t memoryBytes = 0;               ///< adapter + core, approximate
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
    /// Removes the proxy's pairs from the cache first (only its own pairs, in O(its pairs),
    /// when every pair in the cache is one this broadphase added; else through
    /// removeOverlappingPairsContainingProxy, which walks the cache). The slot may be
    /// reused by the next createProxy. Throws std::invalid_argument for a proxy this
    /// broadphase does not own or already destroyed.
    void destroyProxy(btBroadphaseProxy* proxy, btDispatcher* dispatcher) override;
    /// A bad box is reported and ignored: the proxy keeps its last valid box. Throws
    /// std::invalid_argument for a proxy this broadphase does not own.
    void setAabb(btBroadphaseProxy* proxy, const btVector3& aabbMin, const btVector3& aabbMax,
                 btDispatcher* dispatcher) override;
    /// The last valid box (for a proxy still waiting for one: the rejected creation box).
    void getAabb(btBroadphaseProxy* proxy, btVector3& aabbMin, btVector3& aabbMax) const override;
    /// Reports every live proxy whose box overlaps [aabbMin, aabbMax] (closed), once each.
    /// An inverted box (min > max on some axis) or a NaN bound is empty: nothing is
    /// reported. Re-entrant: the callback may create, destroy and move proxies and run
    /// queries; the proxies reported are those whose boxes overlapped when the query
    /// began, except any destroyed before its turn.
    void aabbTest(const btVector3& aabbMin, const btVector3& aabbMax,
                  btBroadphaseAabbCallback& callback) override = 0;
    /// Reports every live proxy whose box, swept by [aabbMin, aabbMax], Bullet's own ray
    /// test accepts for the callback's precomputed ray (m_rayDirectionInverse, m_signs,
    /// m_lambda_max), once each. An inverted or NaN swept box is empty. Re-entrant as
    /// aabbTest.
    void rayTest(const btVector3& rayFrom, const btVector3& rayTo,
                 btBroadphaseRayCallback& callback, const btVector3& aabbMin,
                 const btVector3& aabbMax) override = 0;
    btOverlappingPairCache* getOverlappingPairCache() override { return pairCache_; }
    const btOverlappingPairCache* getOverlappingPairCache() const override { return pairCache_; }
    /// The union of all valid proxy boxes (zero box when there are none).
    void getBroadphaseAabb(btVector3& aabbMin, btVector3& aabbMax) const override;
    /// When no proxy is alive, frees all memory (adapter and core) and restarts ids, for
    /// reproducible runs. Does nothing while proxies are alive.
    void resetPool(btDispatcher* dispatcher) override;
    void printStats() override;
    /// The core in use and, for "auto", what it measured and why it chose it.
    virtual std::string coreDescription() const { return name_; }

    const std::string& name() const { return name_; }
    /// True when the core tracks overlaps itself ("sweep"): exact boxes in the core, no fat
    /// boxes, no pair certificates.
    bool coreTracksOverlaps() const { return coreTracksOverlaps_; }
    AdapterStats stats() const;
    /// Checks proxy table, pair store and core invariants; throws std::logic_error.
    void validate() const;

  protected:
    struct Proxy : btBroadphaseProxy {
        ObjectId slot = 0;
    };
    /// A proxy a query reports, remembered by uid so that a callback that destroys it (and
    /// reuses its slot) is noticed.
    struct QueryHit {
        ObjectId slot;
        int uid;
    };

    virtual void coreInsert(ObjectId id, const Box& box) = 0;
    virtual void coreUpdate(ObjectId id, const Box& box) = 0;
    virtual void coreRemove(ObjectId id) = 0;
    /// Frees all the core's memory (a fresh core with the same settings).
    virtual void coreReset() = 0;
    virtual void coreValidate() const = 0;
    virtual std::size_t coreMemoryBytes() const = 0;

    static Box toBox(const btVector3& aabbMin, const btVector3& aabbMax) {
        return Box{{aabbMin.x(), aabbMin.y(), aabbMin.z()},
                   {aabbMax.x(), aabbMax.y(), aabbMax.z()}};
    }
    /// False (and counted) for an inverted or NaN box.
    bool usableQueryBox(const btVector3& aabbMin, const btVector3& aabbMax);
    static Ray<3, btScalar> toRay(const btVector3& rayFrom, const btBroadphaseRayCallback& callback,
                                  const btVector3& aabbMin, const btVector3& aabbMax);

    /// The exact box (the last valid one Bullet gave).
    const Box& boxOf(ObjectId id) const { return boxes_[id]; }
    /// The box the core holds: contains boxOf(id).
    const Box& fatBoxOf(ObjectId id) const { return fat_[id]; }
    Proxy* proxyOf(ObjectId id) const { return &chunks_[id >> kChunkBits][id & kChunkMask]; }

    /// Scratch for one query: collect the hits into it, then call reportHits. Queries
    /// nest (a callback may query again); each level has its own list.
    /// `rayLength`: a ray's reach (the callback's lambda_max), measured by "auto".
    std::vector<QueryHit>& beginQuery(bool ray, double rayLength = 0);
    void addHit(std::vector<QueryHit>& hits, ObjectId id) const {
        hits.push_back(QueryHit{id, proxyOf(id)->m_uniqueId});
    }
    template <class Callback>
    void reportHits(std::vector<QueryHit>& hits, Callback& callback) {
        const std::size_t generation = generation_;
        for (std::size_t i = 0; i < hits.size() && generation == generation_; ++i) {
            const QueryHit hit = hits[i];
            if (hit.slot < state_.size() && state_[hit.slot] == SlotState::Live &&
                proxyOf(hit.slot)->m_uniqueId == hit.uid) {
                callback.process(proxyOf(hit.slot));
            }
        }
        endQuery();
    }

    /// One pair search, driven by CoreBroadphase::calculateOverlappingPairs:
    /// `const bool full = beginPairs();` then, when full (a quarter of the objects left their
    /// core boxes, or the first search), bulkCandidate for every pair the core's all-pairs
    /// search finds (whose core boxes overlap) and finishBulkPairs; else, for each object
    /// forEachCoreMoved visits, dropLeftCandidates and keepCandidate for each object its
    /// core query finds, then finishPairs.
    bool beginPairs();
    /// True while a pair search or a destroyProxy of this broadphase is under way: a pair
    /// search started from one of their callbacks does nothing.
    bool busy() const { return searching_ || deferErasures_ != 0; }
    template <class Visit>
    void forEachCoreMoved(Visit&& visit) const {
        for (const Moved& moved : processing_) {
            if ((moved.kind & kCoreMoved) != 0 && state_[moved.slot] == SlotState::Live) {
                visit(moved.slot);
            }
        }
    }
    /// Drops the candidate pairs of `id` whose core boxes no longer overlap.
    void dropLeftCandidates(ObjectId id, btDispatcher* dispatcher);
    /// Keeps (a, b) as a candidate pair: their core boxes overlap.
    void keepCandidate(ObjectId a, ObjectId b) {
        bool inserted = false;
        pairs_[pairs_.findOrInsert(a, b, inserted)].stamp = stamp_;
    }
    /// Incremental search: looks at the due pairs of every moved object.
    void finishPairs(btDispatcher* dispatcher, std::size_t candidates);
    /// Collects (a, b) as a candidate of a full search (repeats allowed).
    void bulkCandidate(ObjectId a, ObjectId b) { bulkKeys_.push_back(PairStore::keyOf(a, b)); }
    /// Full search: the store goes to bulk mode and the sorted candidates are merged with
    /// its sorted pairs in one pass; every candidate gets the exact box test (no
    /// certificates: when most objects moved, they would cost more than they save), the
    /// pairs that left drop out, and only the status changes reach Bullet's cache, in the
    /// order of the pairs' objects.
    void finishBulkPairs(btDispatcher* dispatcher, std::size_t candidates);
    /// The end of every pair search: filters asked again (EveryFrame; the tested stamp
    /// skips pairs already looked at), erasures, released slots, counters.
    void endSearch(btDispatcher* dispatcher, bool full, std::size_t candidates);

    /// For a core that tracks overlaps itself (kTracksOverlaps, "sweep"): exact boxes in
    /// the core (no fat boxes, no certificates, the store holds exactly the overlapping
    /// pairs). After beginPairs, noteCoreChange for every pair whose boxes the core says may
    /// have started or stopped overlapping, then finishTrackedPairs tests only those.
    void noteCoreChange(ObjectId a, ObjectId b) { coreChanges_.emplace_back(a, b); }
    /// For a core that tracks overlaps, after its changes: every pair of a slot moved during
    /// the last search (movedInSearch_), the stored ones and those `query(box, visit)` finds
    /// for its box now, as changed. The core saw such a move after that search had tested
    /// the slot's pairs against it, and a move away and back in one callback is no move
    /// to it at all.
    template <class Query>
    void recheckMovedInSearch(Query&& query) {
        if (recheck_.empty()) {
            return;
        }
        indexPairs();
        for (ObjectId slot : recheck_) {
            if (state_[slot] != SlotState::Live) {
                continue;
            }
            pairs_.forEachOf(slot, [&](std::uint32_t at) {
                coreChanges_.emplace_back(pairs_[at].object[0], pairs_[at].object[1]);
            });
            query(boxes_[slot], [&](ObjectId other) {
                if (other != slot && state_[other] == SlotState::Live) {
                    coreChanges_.emplace_back(slot, other);
                }
            });
        }
        recheck_.clear();
    }
    void finishTrackedPairs(btDispatcher* dispatcher);
    /// Set by CoreBroadphase for a core that tracks overlaps.
    bool coreTracksOverlaps_ = false;
    /// A tracked core's box changed since the last pair search (validate() then cannot
    /// expect the pairs to match the boxes).
    bool trackedBoxesChanged_ = false;

  private:
    enum class SlotState : std::uint8_t { Free, Live, Parked, PendingFree };
    static constexpr unsigned kChunkBits = 8;
    static constexpr ObjectId kChunkMask = (1u << kChunkBits) - 1;
    static constexpr std::uint8_t kExactMoved = 1, kCoreMoved = 2;
    struct Moved {
        ObjectId slot;
        std::uint8_t kind;
    };

    Proxy* checkedProxy(btBroadphaseProxy* proxy, const char* operation) const {
        Proxy* ours = static_cast<Proxy*>(proxy);
        if (proxy == nullptr || ours->slot >= state_.size() || proxyOf(ours->slot) != ours ||
            (state_[ours->slot] != SlotState::Live && state_[ours->slot] != SlotState::Parked)) {
            throwForeignProxy(operation);
        }
        return ours;
    }
    [[noreturn]] void throwForeignProxy(const char* operation) const;
    /// Finite and ordered (NaN fails every comparison): the fast path of every setAabb.
    static bool goodBox(const btVector3& aabbMin, const btVector3& aabbMax) {
        constexpr btScalar kMax = std::numeric_limits<btScalar>::max();
        bool good = true;
        for (int axis = 0; axis < 3; ++axis) {
            good &=
                aabbMin[axis] <= aabbMax[axis] && aabbMin[axis] >= -kMax && aabbMax[axis] <= kMax;
        }
        return good;
    }
    /// Erases the pairs of the slots destroyed while erasing had to wait, frees the slots.
    void releasePendingSlots();
    /// Returns an empty string for a valid box, else the reason.
    static const char* rejectReason(const btVector3& aabbMin, const btVector3& aabbMax);
    void reportBadAabb(const char* operation, const Proxy& proxy, const btVector3& aabbMin,
                       const btVector3& aabbMax, const char* reason);
    /// The core box for `box`, which replaces `previous`: enlarged when the object moved
    /// less than the margin, else `box` itself.
    Box fatBox(const Box& box, const Box& previous) const;
    /// The same, whatever the core: the fat box `box` would get (auto's measure uses it as
    /// a shadow while the core tracks overlaps).
    Box enlargedBox(const Box& box, const Box& previous) const;
    /// The largest change of any bound, rounded up.
    static double motion(const Box& from, const Box& to);
    /// Whether the closed boxes overlap, and the motion (rounded down) that could change
    /// that: the least per-axis overlap, or the widest gap.
    static bool overlapWithSlack(const Box& a, const Box& b, double& slack);
    /// Splits `slack` between the pair's two objects: the triggers at which each must look
    /// at the pair again.
    void share(std::uint32_t at, double slack);
    /// Leaves the store's bulk mode (no-op outside it): the pairs of an object noted as
    /// moved (or moved in the search under way) are due at once, the others' once their
    /// object moves.
    void indexPairs() {
        pairs_.index([&](ObjectId id) {
            return (movedKind_[id] | frameKind_[id]) != 0 ? -HUGE_VAL : travel_[id];
        });
    }
    void noteMoved(ObjectId slot, std::uint8_t kind) {
        if (movedKind_[slot] == 0) {
            moved_.push_back(slot);
        }
        movedKind_[slot] |= kind;
    }
    /// Brings pair `at` up to date (once per search): when its objects have travelled its
    /// slack since its last test, tests the exact boxes again and applies the change to the
    /// cache; `retestFilter` re-evaluates the filters of an overlapping pair
    /// (FilterEvaluation::EveryFrame).
    void lookAtPair(std::uint32_t at, btDispatcher* dispatcher, bool retestFilter);
    /// Looks at every pair of `id` whose trigger its odometer has passed.
    void lookAtDuePairs(ObjectId id, btDispatcher* dispatcher, bool retestFilter);
    /// An overlapping pair not in the cache: the cache's filters decide whether it goes in.
    /// One in the cache (`again`): out when the filters now reject it.
    void applyFilter(std::uint32_t at, bool again, btDispatcher* dispatcher);
    /// Takes pair `at` out of the cache if it is there (not erased from the store).
    void uncache(std::uint32_t at, btDispatcher* dispatcher);
    /// Marks pair `at` apart without telling the cache (it was removed there already).
    void forget(std::uint32_t at);
    /// Erases the pairs listed (any order, repeats allowed) and clears the list.
    void erasePairs(std::vector<std::uint32_t>& doomed);
    /// Every cached pair still in Bullet's cache? Re-tests the ones someone removed.
    void checkCacheForLostPairs();
    /// Whether every pair in Bullet's cache is one of ours (then ours can be removed one
    /// by one).
    bool cacheHoldsOnlyOurs() const;

    std::string name_;
    BroadphaseSettings settings_;
    btOverlappingPairCache* pairCache_ = nullptr;
    /// pairCache_ when it is a MergedPairCache: the pair search hands it its changes
    /// without lookups and flushes it at the end.
    MergedPairCache* merged_ = nullptr;
    bool ownsPairCache_ = false;

    std::vector<std::unique_ptr<Proxy[]>> chunks_;
    std::vector<Box> boxes_;
    std::vector<Box> fat_;
    std::vector<SlotState> state_;
    std::vector<ObjectId> freeSlots_;
    std::vector<ObjectId> pendingFree_;  ///< destroyed during a pair search
    int nextUid_ = 1;
    std::size_t liveCount_ = 0;
    std::size_t parkedCount_ = 0;
    std::size_t generation_ = 0;  ///< counts resetPool calls that freed memory

    PairStore pairs_;
    std::uint32_t stamp_ = 0;
    std::size_t overlapping_ = 0;          ///< pairs with status InCache or Rejected
    std::size_t cached_ = 0;               ///< pairs with status InCache
    std::vector<ObjectId> moved_;          ///< slots whose box changed since the last search
    std::vector<std::uint8_t> movedKind_;  ///< per slot: kExactMoved | kCoreMoved, 0: not in moved_
    std::vector<Moved> processing_;        ///< the moved slots of the search under way
    std::vector<std::uint8_t> frameKind_;  ///< per slot: its kind in processing_, during a search
    /// Pair certificates. travel_: per slot, the largest change of any bound, summed over
    /// its setAabb calls (an odometer, rounded up). A pair remembers its slack at its last
    /// exact test and both odometers then (PairStore::Pair): its status cannot change
    /// before the two have travelled the slack between them. The slack left is split
    /// between them as triggers, odometer readings kept in each object's heap of pairs;
    /// a setAabb whose travel passes the object's lowest trigger notes it, and only its due
    /// pairs are looked at.
    std::vector<double> travel_;
    std::vector<std::uint32_t> doomed_;  ///< scratch: pairs to erase
    /// Scratch of a full search: its candidates' keys, the radix sort's buffer, the merged
    /// pairs, and the merged pairs whose status change goes through Bullet's cache.
    std::vector<std::uint64_t> bulkKeys_, bulkScratch_;
    std::vector<PairStore::Pair> bulkNext_;
    std::vector<std::uint32_t> bulkChanges_;
    std::vector<std::pair<ObjectId, ObjectId>> coreChanges_;  ///< from a core that tracks
    bool searching_ = false;
    /// Slots whose setAabb came while a search ran (from a callback of the pair cache): the
    /// search may have tested their pairs against either box. For a core that tracks
    /// overlaps, the next search tests every pair of theirs again (recheck_: taken from
    /// movedInSearch_ when it begins, see recheckMovedInSearch).
    std::vector<ObjectId> movedInSearch_, recheck_;
    /// > 0 while pair indices must hold (a walk that calls back into Bullet): destroyed
    /// proxies' pairs are erased afterwards.
    int deferErasures_ = 0;
    std::size_t testedThisFrame_ = 0;
    std::deque<std::vector<QueryHit>> queryScratch_;
    std::size_t queryDepth_ = 0;
    AdapterStats counters_;

    void endQuery() { --queryDepth_; }

  protected:
    // --- for "auto": the scene's measure, and a switch of core without losing a pair ---
    /// Starts measuring (motion per setAabb, rays and box queries).
    void startMeasuring() { measuring_ = true; }
    /// Samples no moves while fewer than `objects` valid boxes live (auto decides such
    /// worlds by their count alone: in 40 objects, the moves looked at cost 15-20% of the
    /// sweep's frame).
    void sampleMovesFrom(std::size_t objects) { sampleFrom_ = objects; }
    /// A sampled setAabb of `slot` to `to` (boxes_[slot] still the previous box): its motion
    /// and whether it left the object's fat box.
    void noteMotion(ObjectId slot, const Box& to);
    /// While the core tracks overlaps: starts the shadow fat box of `slot`, just inserted
    /// into the core with its exact box.
    void startShadow(ObjectId slot);
    /// What was measured since the last call; resets the accumulators, but for the move
    /// samples (forgetMoveSamples, after the decision). O(1): the box sample is left to
    /// SceneMeasure::sampleBoxes.
    SceneMeasure takeMeasure();
    /// Fills `out`'s median size, centres, ray length (from the mean ray reach) and swap
    /// estimate from a sample of at most 1024 boxes.
    void sampleBoxes(SceneMeasure& out, double meanRayLength) const;
    /// Drops the move samples of the swap estimate (after each evaluation).
    void forgetMoveSamples();
    /// Before the core is replaced: every pair tested (statuses current, the cache
    /// updated), core boxes made exact; with `tracking` (the new core tracks overlaps) the
    /// apart pairs are erased, without it every pair awaits a test at a full search.
    void prepareCoreSwitch(bool tracking, btDispatcher* dispatcher);
    /// After the core was emptied: inserts every live object again, sets the mode.
    void finishCoreSwitch(bool tracking);
    /// Whether an undecided auto looks again at the pair search after `frame` completed
    /// searches: every 8 frames, at 2 modulo 8 as the first evaluation (the measure then
    /// holds a new cycle of looked-at moves).
    static bool looksAgainUndecided(std::size_t frame) { return frame % kMotionSampleEvery == 2; }
    /// Completed pair searches (stats().frames, without the rest of stats(): auto asks
    /// every frame).
    std::size_t searches() const { return counters_.frames; }
    /// Whether a move, ray or box query was measured since the last measure.
    bool measuredAny() const {
        return measuredMoves_ > 0 || measuredRays_ > 0 || measuredQueries_ > 0;
    }

  private:
    /// The moves of a class of about kExaminedMoves slots are looked at (noteMotion), each
    /// slot every kMotionSampleEvery frames: the frame after search 1 looks at the whole
    /// class (the first decision, at search 2, has a full frame), and from search 8 on every
    /// frame looks at one eighth of it (spreadMask_ / spreadClass_). A sampled frame that
    /// looked at the whole class every 8 frames cost 8-21 us per 1000 moves, so that its
    /// frames stood out of a falling world's cheap ones and moved auto's median frame.
    static constexpr std::size_t kMotionSampleEvery = 8;
    bool measuring_ = false;
    std::size_t sampleFrom_ = 0;  ///< see sampleMovesFrom
    /// The coming frame's moves of the slots with (slot & spreadMask_) == spreadClass_ are
    /// looked at (none: mask 0, class 1).
    std::size_t spreadMask_ = 0, spreadClass_ = 1;
    std::size_t turnOffset_ = 0;  ///< the eighth looked at first in this cycle of 8 frames
    /// The coming frame's examined moves also feed frameMoves_ (one frame in
    /// kMotionSampleEvery, the eighths of the class taking turns), counted at its search.
    bool countSwapsThisFrame_ = false;
    /// Sets the above for the frame after `frames` completed searches.
    void chooseExamined(std::size_t frames);
    bool forceFullSearch_ = false;
    /// measuredMoves_: every move (counted at the searches); measuredChanges_: those looked
    /// at.
    double measuredChanges_ = 0, measuredMoves_ = 0, measuredMotion_ = 0, measuredRays_ = 0,
           measuredQueries_ = 0, measuredRayLength_ = 0, measuredFatExits_ = 0;
    std::size_t measuredFrames_ = 0;
    /// coreUpdates + movesInsideFatBoxes at the last search: the frame's moves.
    std::size_t movesAtSearch_ = 0;
    std::size_t pairChangesSeen_ = 0;  ///< pairsAdded + pairsRemoved at the last measure
    /// At most this many sampled moves per measure are kept for the swap estimate, and at
    /// most kSwapSampleBoxes boxes' endpoints counted against them; below kSwapEstimateFrom
    /// live objects there is no estimate (0: a sweep of so few is cheap whatever it swaps).
    static constexpr std::size_t kSwapSampleMoves = 48;
    static constexpr std::size_t kSwapSampleBoxes = 256;
    static constexpr std::size_t kSwapEstimateFrom = 64;
    struct SampledMove {
        Box from, to;
    };
    std::vector<SampledMove> sampledMoves_;  ///< a uniform sample of the sampled moves
    std::uint64_t moveSampleState_ = 0x9e3779b97f4a7c15u;  ///< the sample's fixed-seed generator
    /// The generator's next number below `bound`.
    std::size_t draw(std::size_t bound);
    /// Endpoints a sorted sweep would pass per move: the moved objects passing each other,
    /// from the order changes within a sample of one frame's moves (movingSwaps_), plus the
    /// sampled moves against the sampled boxes' endpoints for the share of objects that did
    /// not move (fills SceneMeasure::swapsPerMove).
    double estimateSwapsPerMove(const std::vector<ObjectId>& sampledSlots,
                                double movedPerFrame) const;
    /// Reservoir sampling: `move`, the seen-th of its kind, replaces a random member of
    /// `sample` (at most `capacity`) with probability capacity / seen.
    void keepSample(std::vector<SampledMove>& sample, std::size_t capacity, std::size_t seen,
                    const SampledMove& move);
    /// At the search after a frame that fed frameMoves_: the order changes among them (a
    /// uniform sample of that frame's `frameMoves` moves) scaled to all of them, into
    /// movingSwaps_.
    void countMovingSwaps(double frameMoves);
    static constexpr std::size_t kFrameSampleMoves = 32;
    std::vector<SampledMove> frameMoves_;
    double frameExamined_ = 0;  ///< the moves looked at in that frame
    /// The class looked at: the slots divisible by sampleMask_ + 1, a power of two (about
    /// kExaminedMoves of the live objects, at least half as many; set every 8 frames): a
    /// mask, where a division cost more than the rest of a move.
    std::size_t sampleMask_ = 0;
    static constexpr std::size_t kExaminedMoves = 256;
    /// The class while the core tracks overlaps (auto's sweep counts its own swaps: the
    /// looked-at moves feed only the motion and the fat-box exits, not a swap estimate).
    /// Each look is a cache miss or two in a frame that Bullet's narrowphase and solver
    /// leave cold: with 256, auto's median frame was 1.11x the sweep's on mixed-sizes and
    /// escape, with 128 1.05x and 1.08x (their streams replayed with the exact check between
    /// frames, 5 interleaved rounds, in a harness outside the repository). Fewer would thin
    /// the jitter rule's evidence where few objects move (a fifth of 1200 boxes jitter in
    /// Auto.CountsEveryMoveUnderTheGridAndUnderTheSweep: with 128, about 30 looks in its
    /// first full window).
    static constexpr std::size_t kExaminedMovesTracking = 128;
    double movingSwaps_ = 0;      ///< estimated swaps among moved objects, sampled frames
    double movingSwapMoves_ = 0;  ///< the moves of the frames counted in movingSwaps_
};

/// A btBroadphaseInterface over a kolize core. `Core` provides insert / update / remove,
/// maintain() (re-tuning, called before every pair search), findCandidates(sink) (each
/// unordered candidate pair at most once), queryBox and queryRay (supersets of the
/// answer), validate() and memoryBytes().
template <class Core>
class CoreBroadphase final : public BroadphaseAdapter {
  public:
    CoreBroadphase(std::string name, const BroadphaseSettings& settings,
                   const typename Core::Settings& coreSettings = {})
        : BroadphaseAdapter(std::move(name), settings),
          coreSettings_(coreSettings),
          core_(coreSettings) {
        coreTracksOverlaps_ = tracksNow();
        if constexpr (kAuto) {
            startMeasuring();
            sampleMovesFrom(Core::kFewObjects);
        }
    }

    void calculateOverlappingPairs(btDispatcher* dispatcher) override {
        if (busy()) {
            return;
        }
        if constexpr (kAuto) {
            chooseCore(dispatcher);
        }
        if constexpr (mayTrack()) {
            if (coreTracksOverlaps_) {
                beginPairs();
                core_.maintain();
                core_.drainChanges([&](ObjectId a, ObjectId b) { noteCoreChange(a, b); });
                recheckMovedInSearch(
                    [&](const Box& box, auto&& visit) { core_.queryBox(box, visit); });
                finishTrackedPairs(dispatcher);
                return;
            }
        }
        const bool full = beginPairs();
        core_.maintain();
        std::size_t candidates = 0;
        if (full) {
            core_.findCandidates([&](ObjectId a, ObjectId b) {
                ++candidates;
                if (overlaps(fatBoxOf(a), fatBoxOf(b))) {
                    bulkCandidate(a, b);
                }
            });
            finishBulkPairs(dispatcher, candidates);
            return;
        }
        // All drops first: they erase pairs, which would move the new pairs' indices.
        forEachCoreMoved([&](ObjectId moved) { dropLeftCandidates(moved, dispatcher); });
        forEachCoreMoved([&](ObjectId moved) {
            const Box& box = fatBoxOf(moved);
            core_.queryBox(box, [&](ObjectId id) {
                ++candidates;
                if (id != moved && overlaps(fatBoxOf(id), box)) {
                    keepCandidate(moved, id);
                }
            });
        });
        finishPairs(dispatcher, candidates);
    }

    void aabbTest(const btVector3& aabbMin, const btVector3& aabbMax,
                  btBroadphaseAabbCallback& callback) override {
        if (!usableQueryBox(aabbMin, aabbMax)) {
            return;
        }
        const Box query = toBox(aabbMin, aabbMax);
        std::vector<QueryHit>& hits = beginQuery(false);
        core_.queryBox(query, [&](ObjectId id) {
            if (overlaps(boxOf(id), query)) {
                addHit(hits, id);
            }
        });
        reportHits(hits, callback);
    }

    void rayTest(const btVector3& rayFrom, const btVector3& /*rayTo*/,
                 btBroadphaseRayCallback& callback, const btVector3& aabbMin,
                 const btVector3& aabbMax) override {
        if (!usableQueryBox(aabbMin, aabbMax)) {
            return;
        }
        const Ray<3, btScalar> ray = toRay(rayFrom, callback, aabbMin, aabbMax);
        std::vector<QueryHit>& hits = beginQuery(true, double(callback.m_lambda_max));
        core_.queryRay(ray, [&](ObjectId id) {
            if (rayHits(boxOf(id), ray)) {
                addHit(hits, id);
            }
        });
        reportHits(hits, callback);
    }

    const Core& core() const { return core_; }

    std::string coreDescription() const override {
        if constexpr (kAuto) {
            return name() + ": " + Core::kindName(core_.kind()) + " (" + core_.reason() + "; " +
                   std::to_string(core_.switches()) + " switches)";
        } else {
            return name();
        }
    }

  private:
    static constexpr bool kAuto = std::is_same_v<Core, AutoCore<3, btScalar>>;
    /// The evaluation after the first full window of "auto" (see chooseCore).
    static constexpr std::size_t kFirstWindowEnd = 18;
    /// A core whose tracksOverlaps() may be true provides drainChanges.
    template <class C>
    static constexpr auto tracks(int)
        -> decltype(std::declval<const C&>().tracksOverlaps(), bool()) {
        return true;
    }
    template <class C>
    static constexpr bool tracks(long) {
        return false;
    }
    static constexpr bool mayTrack() { return tracks<Core>(0); }
    bool tracksNow() const {
        if constexpr (mayTrack()) {
            return core_.tracksOverlaps();
        } else {
            return false;
        }
    }

    /// "auto": measure, decide, and switch the core when the decision changed.
    void chooseCore(btDispatcher* dispatcher) {
        if constexpr (kAuto) {
            const std::size_t frame = searches();
            const std::size_t every = std::size_t(std::max(1, coreSettings_.evaluateEvery));
            // Undecided, it looks again every 8 frames once a move, a ray or a query was seen
            // (a world at rest from the start pays only the regular evaluations). Frame 18
            // closes the first full window (frames 2-17): the guess
            // from two frames is corrected there, not at frame 32 (a pyramid that jitters
            // spent frames 2-31 on the sweep at 2.5x the grid's time).
            const bool due = frame == 2 || frame == kFirstWindowEnd || frame % every == 0 ||
                             (core_.undecided() && looksAgainUndecided(frame) && measuredAny());
            if (frame == 0 || !due) {
                return;
            }
            const typename Core::Kind wanted = core_.decide(takeMeasure());
            forgetMoveSamples();
            if (wanted == core_.kind()) {
                return;
            }
            const bool tracking = wanted == Core::Kind::Sweep;
            prepareCoreSwitch(tracking, dispatcher);
            core_.switchTo(wanted, core_.lastRuleReason());
            finishCoreSwitch(tracking);
        }
    }

    void coreInsert(ObjectId id, const Box& box) override { core_.insert(id, box); }
    void coreUpdate(ObjectId id, const Box& box) override { core_.update(id, box); }
    void coreRemove(ObjectId id) override { core_.remove(id); }
    void coreReset() override {
        core_ = Core(coreSettings_);
        coreTracksOverlaps_ = tracksNow();  // "auto" starts again on its first core
    }
    void coreValidate() const override { core_.validate(); }
    std::size_t coreMemoryBytes() const override { return core_.memoryBytes(); }

    typename Core::Settings coreSettings_;
    Core core_;
};

}  // namespace kolize
