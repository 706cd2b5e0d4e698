#include <kolize/broadphase/bullet_adapter.h>
#include <kolize/broadphase/merged_pair_cache.h>

#include <BulletCollision/BroadphaseCollision/btOverlappingPairCache.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace kolize {

namespace {

constexpr std::size_t kDefaultReportsPrinted = 16;

void appendVector(std::ostringstream& out, const btVector3& v) {
    out << '(' << v.x() << ", " << v.y() << ", " << v.z() << ')';
}

}  // namespace

// The pair certificates (see travel_ in the header) are decided in double with every
// rounding taken in the safe direction: motion and travel rounded up, slack and shares
// rounded down. Each factor removes more than one rounding step can add.
constexpr double kUp = 1 + 0x1p-51;
constexpr double kDown = 1 - 0x1p-51;

double BroadphaseAdapter::motion(const Box& from, const Box& to) {
    double most = 0;
    for (int axis = 0; axis < 3; ++axis) {
        most = std::max({most, std::fabs(double(to.lo[axis]) - double(from.lo[axis])),
                         std::fabs(double(to.hi[axis]) - double(from.hi[axis]))});
    }
    return most * kUp;
}

bool BroadphaseAdapter::overlapWithSlack(const Box& a, const Box& b, double& slack) {
    // Per axis the overlap of the two intervals (negative: the gap). Overlapping: the pair
    // stays so while every axis' overlap stays >= 0, i.e. while the two boxes' motions sum
    // to less than the smallest overlap. Apart: it stays so while they sum to less than
    // the widest gap. The sign is exact in double (a rounded difference keeps its sign),
    // so the decision is the closed-interval test.
    double least = HUGE_VAL, widestGap = 0;
    for (int axis = 0; axis < 3; ++axis) {
        const double overlap = std::min(double(a.hi[axis]), double(b.hi[axis])) -
                               std::max(double(a.lo[axis]), double(b.lo[axis]));
        if (overlap >= 0) {
            least = std::min(least, overlap);
        } else {
            widestGap = std::max(widestGap, -overlap);
        }
    }
    const bool overlapping = widestGap == 0;
    slack = (overlapping ? least : widestGap) * kDown;
    return overlapping;
}

std::string BadAabbReport::message() const {
    std::ostringstream out;
    out.precision(17);
    out << "kolize " << broadphase << ": " << operation << " rejected the AABB of proxy uid "
        << proxyUid << " (client object " << clientObject << "): min ";
    appendVector(out, aabbMin);
    out << " max ";
    appendVector(out, aabbMax);
    out << ": " << reason
        << (operation == "createProxy" ? "; the proxy waits for a valid setAabb"
                                       : "; the proxy keeps its last valid box");
    return out.str();
}

BroadphaseAdapter::BroadphaseAdapter(std::string name, const BroadphaseSettings& settings)
    : name_(std::move(name)), settings_(settings) {
    if (!(settings.fatMargin >= 0 && settings.fatMargin <= 10)) {
        throw std::invalid_argument("kolize " + name_ +
                                    ": settings.fatMargin must be in [0, 10] (a fraction of each "
                                    "box's largest extent; 0 turns fat boxes off), got " +
                                    std::to_string(settings.fatMargin));
    }
    if (settings.pairCache != nullptr) {
        if (settings.pairCache->hasDeferredRemoval()) {
            throw std::invalid_argument(
                "kolize " + name_ +
                ": the pair cache has deferred removal (e.g. btSortedOverlappingPairCache); kolize "
                "broadphases update pairs incrementally and need immediate removal, e.g. "
                "btHashedOverlappingPairCache");
        }
        pairCache_ = settings.pairCache;
    } else if (settings.ownPairCache == PairCacheChoice::Merged) {
        void* memory = btAlignedAlloc(sizeof(MergedPairCache), 16);
        pairCache_ = new (memory) MergedPairCache();
        ownsPairCache_ = true;
    } else {
        void* memory = btAlignedAlloc(sizeof(btHashedOverlappingPairCache), 16);
        pairCache_ = new (memory) btHashedOverlappingPairCache();
        ownsPairCache_ = true;
    }
    merged_ = dynamic_cast<MergedPairCache*>(pairCache_);
}

BroadphaseAdapter::~BroadphaseAdapter() {
    if (ownsPairCache_) {
        pairCache_->~btOverlappingPairCache();
        btAlignedFree(pairCache_);
    }
}

const char* BroadphaseAdapter::rejectReason(const btVector3& aabbMin, const btVector3& aabbMax) {
    if (goodBox(aabbMin, aabbMax)) {
        return "";
    }
    for (int axis = 0; axis < 3; ++axis) {
        if (std::isnan(aabbMin[axis]) || std::isnan(aabbMax[axis])) {
            return "NaN coordinate";
        }
    }
    for (int axis = 0; axis < 3; ++axis) {
        if (std::isinf(aabbMin[axis]) || std::isinf(aabbMax[axis])) {
            return "infinite coordinate (use a large finite bound such as 1e18, as "
                   "btStaticPlaneShape does)";
        }
    }
    for (int axis = 0; axis < 3; ++axis) {
        if (aabbMin[axis] > aabbMax[axis]) {
            return "min > max";
        }
    }
    return "";
}

void BroadphaseAdapter::reportBadAabb(const char* operation, const Proxy& proxy,
                                      const btVector3& aabbMin, const btVector3& aabbMax,
                                      const char* reason) {
    ++counters_.badAabbReports;
    BadAabbReport report;
    report.broadphase = name_;
    report.operation = operation;
    report.proxyUid = proxy.m_uniqueId;
    report.clientObject = proxy.m_clientObject;
    report.aabbMin = aabbMin;
    report.aabbMax = aabbMax;
    report.reason = reason;
    if (settings_.onBadAabb) {
        settings_.onBadAabb(report);
    } else if (counters_.badAabbReports <= kDefaultReportsPrinted) {
        std::fprintf(stderr, "%s\n", report.message().c_str());
        if (counters_.badAabbReports == kDefaultReportsPrinted) {
            std::fprintf(stderr, "kolize %s: further bad-AABB reports are only counted\n",
                         name_.c_str());
        }
    }
}

btBroadphaseProxy* BroadphaseAdapter::createProxy(const btVector3& aabbMin,
                                                  const btVector3& aabbMax, int /*shapeType*/,
                                                  void* userPtr, int collisionFilterGroup,
                                                  int collisionFilterMask,
                                                  btDispatcher* /*dispatcher*/) {
    ObjectId slot;
    if (!freeSlots_.empty()) {
        slot = freeSlots_.back();
        freeSlots_.pop_back();
    } else {
        slot = static_cast<ObjectId>(boxes_.size());
        if ((slot & kChunkMask) == 0) {
            chunks_.emplace_back(new Proxy[std::size_t(1) << kChunkBits]);
        }
        boxes_.emplace_back();
        fat_.emplace_back();
        state_.push_back(SlotState::Free);
        movedKind_.push_back(0);
        frameKind_.push_back(0);
        travel_.push_back(0);
    }
    Proxy* proxy = proxyOf(slot);
    proxy->m_clientObject = userPtr;
    proxy->m_collisionFilterGroup = collisionFilterGroup;
    proxy->m_collisionFilterMask = collisionFilterMask;
    proxy->m_uniqueId = nextUid_++;
    proxy->m_aabbMin = aabbMin;
    proxy->m_aabbMax = aabbMax;
    proxy->slot = slot;
    ++liveCount_;

    const char* reason = rejectReason(aabbMin, aabbMax);
    if (*reason != '\0') {
        state_[slot] = SlotState::Parked;
        ++parkedCount_;
        reportBadAabb("createProxy", *proxy, aabbMin, aabbMax, reason);
        return proxy;
    }
    state_[slot] = SlotState::Live;
    boxes_[slot] = toBox(aabbMin, aabbMax);
    fat_[slot] = boxes_[slot];
    travel_[slot] = 0;
    coreInsert(slot, fat_[slot]);
    startShadow(slot);
    noteMoved(slot, kExactMoved | kCoreMoved);
    return proxy;
}

void BroadphaseAdapter::throwForeignProxy(const char* operation) const {
    throw std::invalid_argument("kolize " + name_ + ": " + operation +
                                " called with a proxy this broadphase does not own (or one "
                                "already destroyed)");
}

bool BroadphaseAdapter::cacheHoldsOnlyOurs() const {
    return std::size_t(pairCache_->getNumOverlappingPairs()) == cached_;
}

void BroadphaseAdapter::uncache(std::uint32_t at, btDispatcher* dispatcher) {
    PairStore::Pair& pair = pairs_[at];
    if (pair.status == PairStore::Status::Apart) {
        return;
    }
    const bool wasCached = pair.status == PairStore::Status::InCache;
    pair.status = PairStore::Status::Apart;
    --overlapping_;
    if (wasCached) {
        --cached_;
        ++counters_.pairsRemoved;
        if (merged_ != nullptr && searching_) {
            // Flushed at the end of the search, while both proxies are still alive.
            merged_->removePresentPair(proxyOf(pair.object[0]), proxyOf(pair.object[1]),
                                       dispatcher);
        } else {
            pairCache_->removeOverlappingPair(proxyOf(pair.object[0]), proxyOf(pair.object[1]),
                                              dispatcher);
        }
    }
}

void BroadphaseAdapter::destroyProxy(btBroadphaseProxy* proxy, btDispatcher* dispatcher) {
    Proxy* ours = checkedProxy(proxy, "destroyProxy");
    const ObjectId slot = ours->slot;
    // While this runs, callbacks of the pair cache may destroy other proxies: their pairs
    // are then erased at the end, so that this walk over the slot's pairs stays valid.
    ++deferErasures_;
    indexPairs();
    std::vector<std::uint32_t> own;
    pairs_.appendPairsOf(slot, own);
    if (cacheHoldsOnlyOurs()) {
        for (std::uint32_t at : own) {
            uncache(at, dispatcher);
        }
    } else {
        // Someone else's pairs may name this proxy too: only the cache can find them all.
        for (std::uint32_t at : own) {
            forget(at);
        }
        pairCache_->removeOverlappingPairsContainingProxy(ours, dispatcher);
    }
    if (state_[slot] == SlotState::Live) {
        coreRemove(slot);
    } else {
        --parkedCount_;
    }
    state_[slot] = SlotState::PendingFree;
    pendingFree_.push_back(slot);
    ours->m_clientObject = nullptr;
    --liveCount_;
    --deferErasures_;
    if (deferErasures_ == 0 && !searching_) {
        releasePendingSlots();
    }
}

void BroadphaseAdapter::forget(std::uint32_t at) {
    PairStore::Pair& pair = pairs_[at];
    if (pair.status != PairStore::Status::Apart) {
        const bool cached = pair.status == PairStore::Status::InCache;
        cached_ -= cached ? 1 : 0;
        counters_.pairsRemoved += cached ? 1 : 0;
        --overlapping_;
        pair.status = PairStore::Status::Apart;
    }
}

void BroadphaseAdapter::erasePairs(std::vector<std::uint32_t>& doomed) {
    // Descending: erasing moves the last pair into the hole, never one still to erase.
    std::sort(doomed.begin(), doomed.end(), std::greater<std::uint32_t>());
    doomed.erase(std::unique(doomed.begin(), doomed.end()), doomed.end());
    for (std::uint32_t at : doomed) {
        pairs_.erase(at);
    }
    doomed.clear();
}

void BroadphaseAdapter::releasePendingSlots() {
    if (!pendingFree_.empty()) {
        indexPairs();
    }
    for (ObjectId slot : pendingFree_) {
        pairs_.appendPairsOf(slot, doomed_);  // all Apart by now
        erasePairs(doomed_);
        state_[slot] = SlotState::Free;
        freeSlots_.push_back(slot);
    }
    pendingFree_.clear();
}

void BroadphaseAdapter::setAabb(btBroadphaseProxy* proxy, const btVector3& aabbMin,
                                const btVector3& aabbMax, btDispatcher* /*dispatcher*/) {
    Proxy* ours = checkedProxy(proxy, "setAabb");
    const ObjectId slot = ours->slot;
    if (!goodBox(aabbMin, aabbMax)) {
        reportBadAabb("setAabb", *ours, aabbMin, aabbMax, rejectReason(aabbMin, aabbMax));
        return;
    }
    const Box box = toBox(aabbMin, aabbMax);
    if (state_[slot] == SlotState::Live) {
        if (box == boxes_[slot]) {
            return;  // unchanged (resting and sleeping bodies): nothing to do
        }
        if (searching_ && coreTracksOverlaps_) {
            movedInSearch_.push_back(slot);  // the other cores' certificates see such a move
        }
        ours->m_aabbMin = aabbMin;
        ours->m_aabbMax = aabbMax;
        if ((slot & spreadMask_) == spreadClass_) {
            noteMotion(slot, box);
        }
        if (coreTracksOverlaps_) {
            // The core finds the changed pairs itself: no fat box, no certificate.
            boxes_[slot] = box;  // fat_ is not read while the core tracks overlaps
            coreUpdate(slot, box);
            ++counters_.coreUpdates;
            trackedBoxesChanged_ = true;
            return;
        }
        travel_[slot] = (travel_[slot] + motion(boxes_[slot], box)) * kUp;
        if (contains(fat_[slot], box)) {
            // The core box still holds it: no new candidates. Its pairs need a look only
            // once it has travelled its share of one of their slacks.
            boxes_[slot] = box;
            ++counters_.movesInsideFatBoxes;
            if (travel_[slot] > pairs_.nextTrigger(slot)) {
                noteMoved(slot, kExactMoved);
            }
            return;
        }
        fat_[slot] = fatBox(box, boxes_[slot]);
        boxes_[slot] = box;
        coreUpdate(slot, fat_[slot]);
    } else {
        ours->m_aabbMin = aabbMin;
        ours->m_aabbMax = aabbMax;
        state_[slot] = SlotState::Live;
        --parkedCount_;
        boxes_[slot] = box;
        fat_[slot] = box;
        travel_[slot] = 0;
        coreInsert(slot, fat_[slot]);
    }
    ++counters_.coreUpdates;
    noteMoved(slot, kExactMoved | kCoreMoved);
}

BroadphaseAdapter::Box BroadphaseAdapter::fatBox(const Box& box, const Box& previous) const {
    return coreTracksOverlaps_ ? box : enlargedBox(box, previous);
}

BroadphaseAdapter::Box BroadphaseAdapter::enlargedBox(const Box& box, const Box& previous) const {
    if (settings_.fatMargin == 0) {
        return box;
    }
    btScalar extent = 0, magnitude = 0, moved = 0;
    for (int axis = 0; axis < 3; ++axis) {
        extent = std::max(extent, box.hi[axis] - box.lo[axis]);
        magnitude = std::max({magnitude, std::abs(box.lo[axis]), std::abs(box.hi[axis])});
        moved = std::max({moved, std::abs(box.lo[axis] - previous.lo[axis]),
                          std::abs(box.hi[axis] - previous.hi[axis])});
    }
    const btScalar margin =
        settings_.fatMargin * extent + 2 * std::numeric_limits<btScalar>::epsilon() * magnitude;
    if (!(4 * moved <= margin)) {
        // Not slow: it would leave an enlarged box within a few frames, and meanwhile the
        // box would add candidate pairs. Falling and flying objects keep exact boxes.
        return box;
    }
    Box fat = box;
    for (int axis = 0; axis < 3; ++axis) {
        fat.lo[axis] -= margin;
        fat.hi[axis] += margin;
        if (!std::isfinite(fat.lo[axis]) || !std::isfinite(fat.hi[axis])) {
            return box;  // near the float range's end: no room to enlarge
        }
    }
    return fat;
}

void BroadphaseAdapter::getAabb(btBroadphaseProxy* proxy, btVector3& aabbMin,
                                btVector3& aabbMax) const {
    aabbMin = proxy->m_aabbMin;
    aabbMax = proxy->m_aabbMax;
}

void BroadphaseAdapter::getBroadphaseAabb(btVector3& aabbMin, btVector3& aabbMax) const {
    bool any = false;
    Box all;
    for (std::size_t slot = 0; slot < boxes_.size(); ++slot) {
        if (state_[slot] != SlotState::Live) {
            continue;
        }
        all = any ? merged(all, boxes_[slot]) : boxes_[slot];
        any = true;
    }
    aabbMin.setValue(all.lo[0], all.lo[1], all.lo[2]);
    aabbMax.setValue(all.hi[0], all.hi[1], all.hi[2]);
}

void BroadphaseAdapter::startShadow(ObjectId slot) {
    // The fat box the object would have if it rested, not its exact box: otherwise its first
    // sampled move, however small, would count as leaving it (a jittering pyramid that took
    // the sweep showed a third of its moves leaving in its first full window, and reached
    // the grid only at frame 96).
    if (coreTracksOverlaps_ && measuring_) {
        fat_[slot] = enlargedBox(boxes_[slot], boxes_[slot]);
    }
}

namespace {

/// A number below `bound` from the generator's high 32 bits, by a multiply and a shift (a
/// 64-bit division per sampled move cost more than the rest of the sample).
std::size_t below(std::uint64_t state, std::size_t bound) {
    if (bound > 0xffffffffu) {
        return std::size_t(state % bound);
    }
    return std::size_t(((state >> 32) * std::uint64_t(bound)) >> 32);
}

}  // namespace

void BroadphaseAdapter::noteMotion(ObjectId slot, const Box& to) {
    // Called for the slots chosen for this frame (chooseExamined); every move is counted at
    // the search.
    const Box& from = boxes_[slot];
    // Would a fat box have held this move? With fat boxes, it is the core box; while the
    // core tracks overlaps, fat_ is a shadow kept up to date only here (when the slot is
    // looked at, once in 8 frames, so a slow drift counts more leavings than the fat boxes
    // would have: the measure errs towards the sweep).
    if (!contains(fat_[slot], to)) {
        measuredFatExits_ += 1;
        if (coreTracksOverlaps_) {
            fat_[slot] = enlargedBox(to, from);
        }
    }
    double size = 0;
    for (int axis = 0; axis < 3; ++axis) {
        size = std::max(size, double(to.hi[axis]) - double(to.lo[axis]));
    }
    measuredChanges_ += 1;
    measuredMotion_ += std::min(1e3, motion(from, to) / std::max(size, 1e-30));
    if (coreTracksOverlaps_) {
        // The tracking core (auto's sweep) counts its own swaps, and auto takes that count
        // (AutoCore::decide): the moves are not sampled for an estimate.
        return;
    }
    // A uniform sample of the moves (reservoir; a fixed-seed generator, so a replayed
    // stream gets the same sample and the same choices).
    const std::size_t seen = std::size_t(measuredChanges_);
    keepSample(sampledMoves_, kSwapSampleMoves, seen, {from, to});
    if (countSwapsThisFrame_) {
        // And a uniform sample of this frame's moves, to count how they pass each other.
        frameExamined_ += 1;
        keepSample(frameMoves_, kFrameSampleMoves, std::size_t(frameExamined_), {from, to});
    }
}

void BroadphaseAdapter::keepSample(std::vector<SampledMove>& sample, std::size_t capacity,
                                   std::size_t seen, const SampledMove& move) {
    if (sample.size() < capacity) {
        sample.push_back(move);
        return;
    }
    const std::size_t at = draw(seen);
    if (at < capacity) {
        sample[at] = move;
    }
}

std::size_t BroadphaseAdapter::draw(std::size_t bound) {
    moveSampleState_ = moveSampleState_ * 6364136223846793005u + 1442695040888963407u;
    return below(moveSampleState_, bound);
}

void BroadphaseAdapter::chooseExamined(std::size_t frames) {
    spreadMask_ = 0;
    spreadClass_ = 1;  // none
    countSwapsThisFrame_ = false;
    if (!measuring_ || (frames > 1 && frames < kMotionSampleEvery) ||
        liveCount_ - parkedCount_ < sampleFrom_) {
        return;
    }
    if (frames == 1 || frames % kMotionSampleEvery == 0) {
        // Each cycle of 8 frames starts the eighths' turns at a random one: a slot is looked
        // at once per cycle, 1 to 15 frames after the last time, so that a steady motion
        // whose fat-box exits recur every 8 frames is not always looked at in the same phase
        // of them (always or never leaving).
        turnOffset_ = draw(kMotionSampleEvery);
        // The next class (set every 8 frames, at its start): about kExaminedMoves of the
        // objects (the stride the power of two at or above the quotient: from half of them
        // to all).
        const std::size_t stride = std::max<std::size_t>(
            1, (liveCount_ - parkedCount_) /
                   (coreTracksOverlaps_ ? kExaminedMovesTracking : kExaminedMoves));
        std::size_t power = 1;
        while (power < stride) {
            power *= 2;
        }
        sampleMask_ = power - 1;
    }
    if (frames == 1) {
        spreadMask_ = sampleMask_;
        spreadClass_ = 0;
        countSwapsThisFrame_ = true;
        return;
    }
    const std::size_t turn = (frames + turnOffset_) % kMotionSampleEvery;
    spreadMask_ = (sampleMask_ + 1) * kMotionSampleEvery - 1;
    spreadClass_ = turn * (sampleMask_ + 1);
    countSwapsThisFrame_ = turn == (frames / kMotionSampleEvery) % kMotionSampleEvery;
}

void BroadphaseAdapter::countMovingSwaps(double frameMoves) {
    const std::size_t k = frameMoves_.size();
    if (k >= 2) {
        // Two moved ends swap when their order before the frame and after it differ; a tie
        // counts as ordered by sample index (as the sweep orders ties by id: about half of
        // the ties a move makes or breaks are swaps).
        // Branch-free: the outcomes are coin tosses (a branch per comparison cost 20 us per
        // frame counted).
        auto beforeOf = [](btScalar a, btScalar b, bool firstBefore) {
            return (a < b) | ((a == b) & firstBefore);
        };
        std::uint64_t flips = 0;
        for (std::size_t i = 0; i < k; ++i) {
            const SampledMove& a = frameMoves_[i];
            for (std::size_t j = i + 1; j < k; ++j) {
                const SampledMove& b = frameMoves_[j];
                for (int axis = 0; axis < 3; ++axis) {
                    const btScalar fromA[2] = {a.from.lo[axis], a.from.hi[axis]};
                    const btScalar toA[2] = {a.to.lo[axis], a.to.hi[axis]};
                    const btScalar fromB[2] = {b.from.lo[axis], b.from.hi[axis]};
                    const btScalar toB[2] = {b.to.lo[axis], b.to.hi[axis]};
                    for (int e = 0; e < 2; ++e) {
                        for (int f = 0; f < 2; ++f) {
                            // A min before a max of equal value, as the sweep sorts them.
                            const bool tieFirst = e <= f;
                            flips += std::uint64_t(beforeOf(fromA[e], fromB[f], tieFirst) !=
                                                   beforeOf(toA[e], toB[f], tieFirst));
                        }
                    }
                }
            }
        }
        const double m = frameMoves;
        movingSwaps_ += double(flips) / (double(k) * double(k - 1) / 2) * (m * (m - 1) / 2);
    }
    movingSwapMoves_ += frameMoves;
    frameMoves_.clear();
    frameExamined_ = 0;
}

double BroadphaseAdapter::estimateSwapsPerMove(const std::vector<ObjectId>& sampledSlots,
                                               double movedPerFrame) const {
    const double objects = double(liveCount_ - parkedCount_);
    if (sampledMoves_.empty() || sampledSlots.empty() ||
        liveCount_ - parkedCount_ < kSwapEstimateFrom) {
        return 0;
    }
    // The moved objects passing each other (counted within each frame that fed
    // frameMoves_, where both ends of a swap are known before and after)...
    const double moving = movingSwapMoves_ > 0 ? movingSwaps_ / movingSwapMoves_ : 0;
    // ... and passing the others, which stay where they are: the sampled moves against the
    // sampled boxes' ends, for the share of the objects that did not move. (Against every
    // box, as if all stood still, a world moving together seemed to swap much: escape's
    // bodies flying apart, estimated 2-10 per move where the sweep counted 0.01-2.)
    const double still = std::max(0.0, 1 - movedPerFrame / std::max(1.0, objects));
    if (still < 1.0 / 64) {
        return moving;  // (nearly) everything moved: the still boxes' share is noise
    }
    // Every stride-th of the sampled boxes: the estimate needs a density, not every end.
    const std::size_t stride = sampledSlots.size() / kSwapSampleBoxes + 1;
    const std::size_t boxCount = (sampledSlots.size() + stride - 1) / stride;
    std::vector<btScalar> ends;
    ends.reserve(2 * boxCount);
    double passed = 0;
    for (int axis = 0; axis < 3; ++axis) {
        ends.clear();
        for (std::size_t at = 0; at < sampledSlots.size(); at += stride) {
            ends.push_back(boxes_[sampledSlots[at]].lo[axis]);
            ends.push_back(boxes_[sampledSlots[at]].hi[axis]);
        }
        std::sort(ends.begin(), ends.end());
        // Endpoints between where an end was and where it went: those strictly between,
        // and half of those equal to either value (ties are ordered by id: a moving end
        // passes about half of its old and of its new value's).
        auto between = [&](btScalar a, btScalar b) {
            if (!(a < b || b < a)) {
                return 0.0;
            }
            const btScalar lo = std::min(a, b), hi = std::max(a, b);
            const auto loFirst = std::lower_bound(ends.begin(), ends.end(), lo);
            const auto loLast = std::upper_bound(loFirst, ends.end(), lo);
            const auto hiFirst = std::lower_bound(loLast, ends.end(), hi);
            const auto hiLast = std::upper_bound(hiFirst, ends.end(), hi);
            return double(hiFirst - loLast) + 0.5 * double((loLast - loFirst) + (hiLast - hiFirst));
        };
        for (const SampledMove& move : sampledMoves_) {
            passed += between(move.from.lo[axis], move.to.lo[axis]) +
                      between(move.from.hi[axis], move.to.hi[axis]);
        }
    }
    const double scale = objects / double(boxCount);
    return moving + still * passed * scale / double(sampledMoves_.size());
}

bool BroadphaseAdapter::usableQueryBox(const btVector3& aabbMin, const btVector3& aabbMax) {
    for (int axis = 0; axis < 3; ++axis) {
        if (!(aabbMin[axis] <= aabbMax[axis])) {  // inverted, or NaN
            ++counters_.emptyQueries;
            return false;
        }
    }
    return true;
}

Ray<3, btScalar> BroadphaseAdapter::toRay(const btVector3& rayFrom,
                                          const btBroadphaseRayCallback& callback,
                                          const btVector3& aabbMin, const btVector3& aabbMax) {
    Ray<3, btScalar> ray;
    for (int axis = 0; axis < 3; ++axis) {
        ray.origin[axis] = rayFrom[axis];
        ray.inverseDirection[axis] = callback.m_rayDirectionInverse[axis];
        ray.sign[axis] = callback.m_signs[axis] ? 1u : 0u;
        ray.expandLo[axis] = aabbMin[axis];
        ray.expandHi[axis] = aabbMax[axis];
    }
    ray.lambdaMax = callback.m_lambda_max;
    return ray;
}

std::vector<BroadphaseAdapter::QueryHit>& BroadphaseAdapter::beginQuery(bool ray,
                                                                        double rayLength) {
    if (measuring_) {
        (ray ? measuredRays_ : measuredQueries_) += 1;
        if (ray && std::isfinite(rayLength)) {
            measuredRayLength_ += std::min(std::max(rayLength, 0.0), 1e12);
        }
    }
    // A deque: a nested query's new level does not move the lists of the levels below.
    if (queryDepth_ == queryScratch_.size()) {
        queryScratch_.emplace_back();
    }
    std::vector<QueryHit>& hits = queryScratch_[queryDepth_++];
    hits.clear();
    return hits;
}

bool BroadphaseAdapter::beginPairs() {
    searching_ = true;
    trackedBoxesChanged_ = false;
    recheck_.swap(movedInSearch_);
    movedInSearch_.clear();
    if (++stamp_ == 0) {  // wrapped: no pair may look tested in this frame
        for (std::uint32_t at = 0; at < pairs_.size(); ++at) {
            pairs_[at].stamp = 0;
            pairs_[at].tested = 0;
        }
        stamp_ = 1;
    }
    processing_.clear();
    std::size_t coreMoved = 0;
    for (ObjectId slot : moved_) {
        const std::uint8_t kind = movedKind_[slot];
        movedKind_[slot] = 0;
        if (state_[slot] != SlotState::Live) {
            continue;
        }
        processing_.push_back(Moved{slot, kind});
        frameKind_[slot] = kind;
        coreMoved += (kind & kCoreMoved) != 0 ? 1 : 0;
    }
    moved_.clear();
    // The frame's moves: every setAabb that changed a box.
    const std::size_t moves = counters_.coreUpdates + counters_.movesInsideFatBoxes;
    const double frameMoves = double(moves - movesAtSearch_);
    movesAtSearch_ = moves;
    if (measuring_) {
        measuredMoves_ += frameMoves;
        if (countSwapsThisFrame_) {
            countMovingSwaps(frameMoves);  // the frame's moves are all in
        }
    }
    checkCacheForLostPairs();
    if (processing_.empty()) {
        ++counters_.idleFrames;
    }
    ++measuredFrames_;
    // The core's all-pairs search pays when many objects moved (and on the first frame).
    if (forceFullSearch_) {
        forceFullSearch_ = false;
        return true;
    }
    const bool full = counters_.frames == 0 ? liveCount_ > 0 : coreMoved * 4 > liveCount_;
    if (!full) {
        indexPairs();  // certificates and queries need it (a no-op unless after a bulk frame)
    }
    return full;
}

void BroadphaseAdapter::checkCacheForLostPairs() {
    if (cacheHoldsOnlyOurs()) {
        return;
    }
    // Someone else removed (or added) pairs: look ours up, and test again every pair that
    // is gone, so it is added again if its boxes still overlap.
    ++counters_.cacheChecks;
    const bool indexed = pairs_.indexed();  // in bulk mode every trigger counts as -inf
    for (std::uint32_t at = 0; at < pairs_.size(); ++at) {
        PairStore::Pair& pair = pairs_[at];
        if (pair.status != PairStore::Status::InCache ||
            pairCache_->findPair(proxyOf(pair.object[0]), proxyOf(pair.object[1])) != nullptr) {
            continue;
        }
        pair.status = PairStore::Status::Apart;
        pair.slack = -1;  // its status is unknown: test it
        --cached_;
        --overlapping_;
        ++counters_.pairsRestored;
        if (coreTracksOverlaps_) {
            coreChanges_.emplace_back(pair.object[0], pair.object[1]);
            continue;
        }
        for (int side = 0; side < 2; ++side) {
            const ObjectId id = pair.object[side];
            if (indexed) {
                pairs_.setTrigger(at, side, -HUGE_VAL);
            }
            if (frameKind_[id] == 0) {
                processing_.push_back(Moved{id, kExactMoved});
            }
            frameKind_[id] |= kExactMoved;
        }
    }
}

void BroadphaseAdapter::dropLeftCandidates(ObjectId id, btDispatcher* dispatcher) {
    const Box& box = fat_[id];
    // Uncaching calls back into Bullet, whose callbacks may destroy proxies: collect first,
    // erase after.
    pairs_.forEachOf(id, [&](std::uint32_t at) {
        if (!overlaps(box, fat_[pairs_[at].other(id)])) {
            doomed_.push_back(at);
        }
    });
    if (doomed_.empty()) {
        return;
    }
    ++deferErasures_;
    for (std::uint32_t at : doomed_) {
        uncache(at, dispatcher);
    }
    --deferErasures_;
    erasePairs(doomed_);
}

void BroadphaseAdapter::share(std::uint32_t at, double slack) {
    // The objects split what is left in proportion to how far each travelled since the
    // test (an object at rest leaves it to the other); while both stay within their
    // shares, the two travel less than the slack together. Shares are rounded down.
    // (Below 1e-300 the factor could not round down: such a share counts as none.)
    const PairStore::Pair& pair = pairs_[at];
    const double moved[2] = {travel_[pair.object[0]] - pair.travelled[0],
                             travel_[pair.object[1]] - pair.travelled[1]};
    const double floor = (moved[0] + moved[1]) / 8;
    double weight[2] = {moved[0] + floor, moved[1] + floor};
    if (!(weight[0] + weight[1] > 0)) {
        weight[0] = weight[1] = 1;
    }
    for (int side = 0; side < 2; ++side) {
        const ObjectId id = pair.object[side];
        const double part = slack * (weight[side] / (weight[0] + weight[1])) * kDown * kDown;
        // Not below the odometer: a share lost to rounding (a huge odometer) is no share.
        const double trigger = part >= 1e-300 ? (travel_[id] + part) * kDown : travel_[id];
        pairs_.setTrigger(at, side, trigger >= travel_[id] ? trigger : travel_[id]);
    }
}

void BroadphaseAdapter::lookAtPair(std::uint32_t at, btDispatcher* dispatcher, bool retestFilter) {
    PairStore::Pair& pair = pairs_[at];
    pair.tested = stamp_;
    const ObjectId a = pair.object[0], b = pair.object[1];
    if (state_[a] != SlotState::Live || state_[b] != SlotState::Live) {
        // Destroyed during this search: erased at its end; meanwhile never due.
        pairs_.setTrigger(at, 0, HUGE_VAL);
        pairs_.setTrigger(at, 1, HUGE_VAL);
        return;
    }
    const double used = ((travel_[a] - pair.travelled[0]) + (travel_[b] - pair.travelled[1])) * kUp;
    if (pair.slack >= 0 && used < pair.slack) {
        // The certificate holds: the status is what it was. Share what is left afresh.
        share(at, (pair.slack - used) * kDown);
        if (retestFilter && pairs_[at].status != PairStore::Status::Apart) {
            applyFilter(at, true, dispatcher);
        }
        return;
    }
    ++testedThisFrame_;
    double slack = 0;
    const bool overlap = overlapWithSlack(boxes_[a], boxes_[b], slack);
    pair.slack = slack;
    pair.travelled[0] = travel_[a];
    pair.travelled[1] = travel_[b];
    share(at, slack);
    switch (pairs_[at].status) {
        case PairStore::Status::Apart:
            if (overlap) {
                ++overlapping_;
                applyFilter(at, false, dispatcher);
            }
            return;
        case PairStore::Status::InCache:
            if (!overlap) {
                uncache(at, dispatcher);
            } else if (retestFilter) {
                applyFilter(at, true, dispatcher);
            }
            return;
        case PairStore::Status::Rejected:
            if (!overlap) {
                pairs_[at].status = PairStore::Status::Apart;
                --overlapping_;
            } else if (retestFilter) {
                applyFilter(at, true, dispatcher);
            }
            return;
    }
}

void BroadphaseAdapter::lookAtDuePairs(ObjectId id, btDispatcher* dispatcher, bool retestFilter) {
    // The heap's first pair is the one whose trigger the object passed first; a look sets
    // the triggers at or above the odometer, so the loop ends.
    for (std::uint32_t at = pairs_.firstDue(id); at != PairStore::kNone; at = pairs_.firstDue(id)) {
        if (!(pairs_.trigger(at, pairs_[at].sideOf(id)) < travel_[id])) {
            break;
        }
        lookAtPair(at, dispatcher, retestFilter);
    }
}

void BroadphaseAdapter::applyFilter(std::uint32_t at, bool again, btDispatcher* dispatcher) {
    PairStore::Pair& pair = pairs_[at];
    Proxy* a = proxyOf(pair.object[0]);
    Proxy* b = proxyOf(pair.object[1]);
    if (pair.status == PairStore::Status::InCache) {
        if (again && !pairCache_->needsBroadphaseCollision(a, b)) {
            uncache(at, dispatcher);
            pairs_[at].status = PairStore::Status::Rejected;
            ++overlapping_;
        }
        return;
    }
    // A pair that starts overlapping (or a rejected one, looked at again): the cache
    // evaluates the filters, as Bullet's own broadphases let it.
    pair.status = PairStore::Status::Rejected;
    const bool added =
        merged_ != nullptr && searching_
            ? pairCache_->needsBroadphaseCollision(a, b) && merged_->addAbsentPair(a, b) != nullptr
            : pairCache_->addOverlappingPair(a, b) != nullptr;
    if (added) {
        pairs_[at].status = PairStore::Status::InCache;
        ++cached_;
        ++counters_.pairsAdded;
    }
}

void BroadphaseAdapter::finishPairs(btDispatcher* dispatcher, std::size_t candidates) {
    const bool everyFrame = settings_.filters == FilterEvaluation::EveryFrame;
    testedThisFrame_ = 0;
    // No pair is erased until the end (callbacks may destroy proxies): indices hold.
    ++deferErasures_;
    for (const Moved& moved : processing_) {
        if (state_[moved.slot] == SlotState::Live) {
            lookAtDuePairs(moved.slot, dispatcher, everyFrame);
        }
    }
    endSearch(dispatcher, false, candidates);
}

void BroadphaseAdapter::finishBulkPairs(btDispatcher* dispatcher, std::size_t candidates) {
    const bool everyFrame = settings_.filters == FilterEvaluation::EveryFrame;
    testedThisFrame_ = 0;
    PairStore::sortKeys(bulkKeys_, bulkScratch_);
    pairs_.unindex();
    // 1. The merge, without a call into Bullet. Each candidate gets the exact test; a
    // status change that Bullet's cache must see is listed for step 2. A cached pair
    // whose core boxes left stays (stamp 0) until step 2 has uncached it.
    bulkNext_.clear();
    bulkNext_.reserve(bulkKeys_.size());
    bulkChanges_.clear();
    const std::size_t oldCount = pairs_.size();
    std::size_t old = 0;
    auto leave = [&](const PairStore::Pair& pair) {
        if (pair.status == PairStore::Status::InCache) {
            bulkChanges_.push_back(static_cast<std::uint32_t>(bulkNext_.size()));
            bulkNext_.push_back(pair);
            bulkNext_.back().stamp = 0;
        } else if (pair.status == PairStore::Status::Rejected) {
            --overlapping_;
        }
    };
    for (const std::uint64_t key : bulkKeys_) {
        while (old < oldCount && PairStore::keyOf(pairs_[old]) < key) {
            leave(pairs_[old++]);
        }
        PairStore::Pair pair{};
        if (old < oldCount && PairStore::keyOf(pairs_[old]) == key) {
            pair = pairs_[old++];
        } else {
            pair.object[0] = ObjectId(key >> 32);
            pair.object[1] = ObjectId(key & 0xffffffffu);
            pair.status = PairStore::Status::Apart;
        }
        pair.slack = -1;
        pair.stamp = stamp_;
        pair.tested = stamp_;
        ++testedThisFrame_;
        const bool overlap = overlaps(boxes_[pair.object[0]], boxes_[pair.object[1]]);
        if (overlap != (pair.status != PairStore::Status::Apart)) {
            if (pair.status == PairStore::Status::Rejected) {
                pair.status = PairStore::Status::Apart;
                --overlapping_;
            } else {
                bulkChanges_.push_back(static_cast<std::uint32_t>(bulkNext_.size()));
            }
        } else if (overlap && everyFrame) {
            pair.tested = 0;  // endSearch asks its filters again
        }
        bulkNext_.push_back(pair);
    }
    while (old < oldCount) {
        leave(pairs_[old++]);
    }
    pairs_.replaceAll(bulkNext_);
    bulkKeys_.clear();
    for (const Moved& moved : processing_) {
        frameKind_[moved.slot] = 0;  // every pair tested: none is due
    }
    // 2. The changes, in key order. Callbacks may destroy proxies (their destroyProxy
    // indexes the store, indices hold) or create them (seen at the next search).
    ++deferErasures_;
    for (const std::uint32_t at : bulkChanges_) {
        const PairStore::Pair& pair = pairs_[at];
        if (state_[pair.object[0]] != SlotState::Live ||
            state_[pair.object[1]] != SlotState::Live) {
            continue;  // destroyed meanwhile: its pairs are out of the cache
        }
        if (pair.status == PairStore::Status::Apart) {
            ++overlapping_;
            applyFilter(at, false, dispatcher);
        } else {
            uncache(at, dispatcher);
        }
    }
    // The pairs that left, and those of proxies destroyed meanwhile, are all Apart now.
    auto gone = [&](const PairStore::Pair& pair) {
        return pair.stamp != stamp_ || state_[pair.object[0]] != SlotState::Live ||
               state_[pair.object[1]] != SlotState::Live;
    };
    if (pairs_.indexed()) {
        for (std::uint32_t at = 0; at < pairs_.size(); ++at) {
            if (gone(pairs_[at])) {
                doomed_.push_back(at);
            }
        }
    } else {
        pairs_.eraseIf(gone);
    }
    endSearch(dispatcher, true, candidates);
}

void BroadphaseAdapter::endSearch(btDispatcher* dispatcher, bool full, std::size_t candidates) {
    if (settings_.filters == FilterEvaluation::EveryFrame) {
        // The pairs nobody looked at: their status stands, their filters are asked again.
        for (std::uint32_t at = 0; at < pairs_.size(); ++at) {
            const PairStore::Pair& pair = pairs_[at];
            if (pair.tested != stamp_ && pair.status != PairStore::Status::Apart &&
                state_[pair.object[0]] == SlotState::Live &&
                state_[pair.object[1]] == SlotState::Live) {
                applyFilter(at, true, dispatcher);
            }
        }
    }
    --deferErasures_;
    erasePairs(doomed_);
    for (const Moved& moved : processing_) {
        frameKind_[moved.slot] = 0;
    }
    searching_ = false;
    if (merged_ != nullptr) {
        merged_->flush();  // the merge is part of the pair search's time
    }
    if (deferErasures_ == 0) {
        releasePendingSlots();
    }
    counters_.incrementalSearches += full ? 0 : 1;
    counters_.fullSearches += full ? 1 : 0;
    ++counters_.frames;
    chooseExamined(counters_.frames);
    counters_.candidatesLastFrame = candidates;
    counters_.pairsTestedLastFrame = testedThisFrame_;
    counters_.objectsLookedAtLastFrame = processing_.size();
}

void BroadphaseAdapter::finishTrackedPairs(btDispatcher* dispatcher) {
    testedThisFrame_ = 0;
    indexPairs();
    // The store holds exactly the overlapping pairs: a changed pair is either overlapping
    // (into the cache, filters permitting) or erased. No erasing until the end (callbacks
    // may destroy proxies): indices hold.
    ++deferErasures_;
    for (const auto& change : coreChanges_) {
        const ObjectId a = change.first, b = change.second;
        if (state_[a] != SlotState::Live || state_[b] != SlotState::Live) {
            continue;  // destroyed meanwhile: erased with its slot
        }
        ++testedThisFrame_;
        if (overlaps(boxes_[a], boxes_[b])) {
            bool inserted = false;
            const std::uint32_t at = pairs_.findOrInsert(a, b, inserted, HUGE_VAL);
            if (pairs_[at].status == PairStore::Status::Apart) {
                ++overlapping_;
                applyFilter(at, false, dispatcher);
            }
        } else {
            const std::uint32_t at = pairs_.find(a, b);
            if (at != PairStore::kNone && pairs_[at].stamp != stamp_) {
                pairs_[at].stamp = stamp_;  // listed once
                uncache(at, dispatcher);
                doomed_.push_back(at);
            }
        }
    }
    coreChanges_.clear();
    endSearch(dispatcher, false, 0);
}

SceneMeasure BroadphaseAdapter::takeMeasure() {
    SceneMeasure out;
    out.objects = liveCount_ - parkedCount_;
    const double frames = std::max<double>(1, double(measuredFrames_));
    out.frames = double(measuredFrames_);
    out.movedPerFrame = measuredMoves_ / frames;
    out.movesLookedAt = measuredChanges_;
    out.relativeMotion = measuredChanges_ > 0 ? measuredMotion_ / measuredChanges_ : 0;
    out.fatExitsPerMove = measuredChanges_ > 0 ? measuredFatExits_ / measuredChanges_ : 0;
    const std::size_t pairChanges = counters_.pairsAdded + counters_.pairsRemoved;
    const double moves = out.movedPerFrame * out.frames;
    const std::size_t newChanges =
        pairChanges >= pairChangesSeen_ ? pairChanges - pairChangesSeen_ : 0;
    out.pairChangesPerMove = moves > 0 ? double(newChanges) / moves : 0;
    pairChangesSeen_ = pairChanges;
    measuredFatExits_ = 0;
    out.raysPerFrame = measuredRays_ / frames;
    const double meanRayLength = measuredRays_ > 0 ? measuredRayLength_ / measuredRays_ : 0;
    out.boxQueriesPerFrame = measuredQueries_ / frames;
    measuredChanges_ = measuredMoves_ = measuredMotion_ = measuredRays_ = measuredQueries_ = 0;
    measuredRayLength_ = 0;
    measuredFrames_ = 0;
    // The box sample only when a rule asks (before the next move: the boxes and the move
    // samples are those of this evaluation).
    out.sampleBoxes = [this, meanRayLength](SceneMeasure& measure) {
        sampleBoxes(measure, meanRayLength);
    };
    return out;
}

void BroadphaseAdapter::sampleBoxes(SceneMeasure& out, double meanRayLength) const {
    // Sizes and centres from a sample of at most 1024 live boxes (planes and other
    // boxes over 1e6 m left out).
    std::vector<double> sizes;
    std::vector<std::array<double, 3>> centres;
    std::vector<ObjectId> sampledSlots;
    const std::size_t stride = boxes_.size() / 1024 + 1;
    for (std::size_t slot = 0; slot < boxes_.size(); slot += stride) {
        if (state_[slot] != SlotState::Live) {
            continue;
        }
        sampledSlots.push_back(ObjectId(slot));
        const Box& box = boxes_[slot];
        double size = 0;
        std::array<double, 3> centre;
        for (int axis = 0; axis < 3; ++axis) {
            size = std::max(size, double(box.hi[axis]) - double(box.lo[axis]));
            centre[axis] = 0.5 * (double(box.lo[axis]) + double(box.hi[axis]));
        }
        if (size < 1e6) {
            sizes.push_back(size);
            centres.push_back(centre);
        }
    }
    out.swapsPerMove = estimateSwapsPerMove(sampledSlots, out.movedPerFrame);
    if (sizes.size() < 8) {
        return;
    }
    // The median size (a selection, not a sort).
    std::nth_element(sizes.begin(), sizes.begin() + long(sizes.size() / 2), sizes.end());
    const double median = sizes[sizes.size() / 2];
    out.rayLength = median > 0 ? meanRayLength / median : (meanRayLength > 0 ? 1e9 : 0);
    out.medianSize = median;
    out.centres = std::move(centres);
}

void BroadphaseAdapter::forgetMoveSamples() {
    sampledMoves_.clear();
    movingSwaps_ = movingSwapMoves_ = 0;
}

void BroadphaseAdapter::prepareCoreSwitch(bool tracking, btDispatcher* dispatcher) {
    // Every pair's status made current by an exact test (a switch is rare: O(pairs) once).
    indexPairs();
    ++deferErasures_;
    for (std::uint32_t at = 0; at < pairs_.size(); ++at) {
        PairStore::Pair& pair = pairs_[at];
        const ObjectId a = pair.object[0], b = pair.object[1];
        if (overlaps(boxes_[a], boxes_[b])) {
            if (pair.status == PairStore::Status::Apart) {
                ++overlapping_;
                applyFilter(at, false, dispatcher);
            }
        } else {
            uncache(at, dispatcher);
            if (tracking) {
                doomed_.push_back(at);  // a tracking core keeps only overlapping pairs
            }
        }
    }
    --deferErasures_;
    erasePairs(doomed_);
    for (std::size_t slot = 0; slot < boxes_.size(); ++slot) {
        if (state_[slot] == SlotState::Live) {
            fat_[slot] = boxes_[slot];
            travel_[slot] = 0;
        }
    }
    // Without tracking: no certificates yet, every pair is tested at the next (full)
    // search. With it: triggers are not used (a tracking core reports the changes).
    const double trigger = tracking ? HUGE_VAL : -HUGE_VAL;
    for (std::uint32_t at = 0; at < pairs_.size(); ++at) {
        pairs_[at].slack = -1;
        pairs_.setTrigger(at, 0, trigger);
        pairs_.setTrigger(at, 1, trigger);
    }
}

void BroadphaseAdapter::finishCoreSwitch(bool tracking) {
    coreTracksOverlaps_ = tracking;
    for (std::size_t slot = 0; slot < boxes_.size(); ++slot) {
        if (state_[slot] == SlotState::Live) {
            coreInsert(ObjectId(slot), fat_[slot]);
            startShadow(ObjectId(slot));
            noteMoved(ObjectId(slot), kExactMoved | kCoreMoved);
        }
    }
    trackedBoxesChanged_ = tracking;
    forceFullSearch_ = !tracking;
}

void BroadphaseAdapter::resetPool(btDispatcher* /*dispatcher*/) {
    if (liveCount_ != 0 || searching_ || deferErasures_ != 0) {
        return;
    }
    // Swapping with empty vectors frees their memory (clear() would keep the capacity).
    std::vector<std::unique_ptr<Proxy[]>>().swap(chunks_);
    std::vector<Box>().swap(boxes_);
    std::vector<Box>().swap(fat_);
    std::vector<SlotState>().swap(state_);
    std::vector<ObjectId>().swap(freeSlots_);
    std::vector<ObjectId>().swap(pendingFree_);
    std::vector<ObjectId>().swap(moved_);
    std::vector<std::uint8_t>().swap(movedKind_);
    std::vector<std::uint8_t>().swap(frameKind_);
    std::vector<double>().swap(travel_);
    std::vector<std::uint32_t>().swap(doomed_);
    std::vector<std::uint64_t>().swap(bulkKeys_);
    std::vector<std::uint64_t>().swap(bulkScratch_);
    std::vector<PairStore::Pair>().swap(bulkNext_);
    std::vector<std::uint32_t>().swap(bulkChanges_);
    std::vector<Moved>().swap(processing_);
    if (queryDepth_ == 0) {
        queryScratch_.clear();
        queryScratch_.shrink_to_fit();
    }
    pairs_.clear();
    overlapping_ = 0;
    cached_ = 0;
    coreReset();
    nextUid_ = 1;
    ++generation_;
}

AdapterStats BroadphaseAdapter::stats() const {
    AdapterStats out = counters_;
    out.proxies = liveCount_;
    out.parkedProxies = parkedCount_;
    out.slots = boxes_.size();
    out.candidatePairs = pairs_.size();
    out.overlappingPairs = overlapping_;
    out.cachedPairs = cached_;
    std::size_t scratch = 0;
    for (const std::vector<QueryHit>& hits : queryScratch_) {
        scratch += hits.capacity() * sizeof(QueryHit);
    }
    out.memoryBytes =
        chunks_.size() * (sizeof(Proxy) << kChunkBits) +
        (boxes_.capacity() + fat_.capacity()) * sizeof(Box) + state_.capacity() +
        movedKind_.capacity() + frameKind_.capacity() + travel_.capacity() * sizeof(double) +
        doomed_.capacity() * sizeof(std::uint32_t) +
        (freeSlots_.capacity() + pendingFree_.capacity() + moved_.capacity()) * sizeof(ObjectId) +
        processing_.capacity() * sizeof(Moved) + scratch + pairs_.memoryBytes() +
        (bulkKeys_.capacity() + bulkScratch_.capacity()) * sizeof(std::uint64_t) +
        bulkNext_.capacity() * sizeof(PairStore::Pair) +
        bulkChanges_.capacity() * sizeof(std::uint32_t) + coreMemoryBytes();
    return out;
}

void BroadphaseAdapter::printStats() {
    const AdapterStats s = stats();
    std::printf(
        "kolize %s: %zu proxies (%zu parked), %zu overlapping pairs (%zu cached, %zu candidate "
        "pairs), %zu frames (%zu incremental, %zu full, %zu idle), %zu candidates and %zu pair "
        "tests of %zu objects' pairs last frame, %zu core updates, %zu moves inside fat boxes, %zu "
        "pairs added, %zu "
        "removed, %zu restored after outside removal, %zu bad AABBs rejected, %zu empty "
        "queries, %zu bytes\n",
        name_.c_str(), s.proxies, s.parkedProxies, s.overlappingPairs, s.cachedPairs,
        s.candidatePairs, s.frames, s.incrementalSearches, s.fullSearches, s.idleFrames,
        s.candidatesLastFrame, s.pairsTestedLastFrame, s.objectsLookedAtLastFrame, s.coreUpdates,
        s.movesInsideFatBoxes, s.pairsAdded, s.pairsRemoved, s.pairsRestored, s.badAabbReports,
        s.emptyQueries, s.memoryBytes);
}

void BroadphaseAdapter::validate() const {
    auto fail = [&](const std::string& what) {
        throw std::logic_error("kolize " + name_ + ": validate: " + what);
    };
    if (boxes_.size() != state_.size() || chunks_.size() << kChunkBits < boxes_.size() ||
        movedKind_.size() != boxes_.size() || frameKind_.size() != boxes_.size() ||
        travel_.size() != boxes_.size()) {
        fail("slot arrays disagree");
    }
    std::size_t live = 0, parked = 0;
    for (std::size_t slot = 0; slot < boxes_.size(); ++slot) {
        const Proxy* proxy = proxyOf(static_cast<ObjectId>(slot));
        switch (state_[slot]) {
            case SlotState::Live:
                ++live;
                if (proxy->slot != slot) {
                    fail("proxy at slot " + std::to_string(slot) + " names another slot");
                }
                if (!isValid(boxes_[slot]) || boxes_[slot].lo[0] != proxy->m_aabbMin.x() ||
                    boxes_[slot].hi[2] != proxy->m_aabbMax.z()) {
                    fail("box of slot " + std::to_string(slot) + " invalid or out of sync");
                }
                if (movedKind_[slot] == 0 && !searching_ && pairs_.indexed() &&
                    travel_[slot] > pairs_.nextTrigger(static_cast<ObjectId>(slot))) {
                    fail("slot " + std::to_string(slot) +
                         " travelled past its trigger without being noted");
                }
                if (!coreTracksOverlaps_ && !contains(fat_[slot], boxes_[slot])) {
                    fail("core box of slot " + std::to_string(slot) + " does not contain its box");
                }
                break;
            case SlotState::Parked:
                ++parked;
                break;
            default:
                if (pairs_.indexed() && pairs_.degree(static_cast<ObjectId>(slot)) != 0 &&
                    !searching_) {
                    fail("dead slot " + std::to_string(slot) + " still has pairs");
                }
                break;
        }
        if (frameKind_[slot] != 0 && !searching_) {
            fail("frame mark of slot " + std::to_string(slot) + " left behind");
        }
    }
    if (live + parked != liveCount_ || parked != parkedCount_) {
        fail("live/parked counts disagree with the slot table");
    }
    std::size_t flagged = 0;
    for (std::uint8_t kind : movedKind_) {
        flagged += kind != 0 ? 1 : 0;
    }
    if (flagged != moved_.size()) {
        fail("moved list and marks disagree");
    }
    pairs_.validate();
    std::size_t overlapping = 0, cached = 0;
    for (std::uint32_t at = 0; at < pairs_.size(); ++at) {
        const PairStore::Pair& pair = pairs_[at];
        const ObjectId a = pair.object[0], b = pair.object[1];
        if (b >= boxes_.size() || state_[a] != SlotState::Live || state_[b] != SlotState::Live) {
            if (!searching_) {
                fail("pair names a slot that is not live");
            }
            continue;
        }
        const bool pending = movedKind_[a] != 0 || movedKind_[b] != 0 ||
                             (coreTracksOverlaps_ && trackedBoxesChanged_);
        if (!coreTracksOverlaps_ && !overlaps(fat_[a], fat_[b]) && !pending) {
            fail("candidate pair whose core boxes do not overlap");
        }
        if (pair.status != PairStore::Status::Apart) {
            ++overlapping;
            cached += pair.status == PairStore::Status::InCache ? 1 : 0;
        }
        // The slack budgets promise that a pair neither of whose objects awaits a test
        // still has the status of its last test.
        if (!pending &&
            (pair.status != PairStore::Status::Apart) != overlaps(boxes_[a], boxes_[b])) {
            fail("pair " + std::to_string(a) + "-" + std::to_string(b) +
                 " has a stale status: its objects moved past their slack unnoticed");
        }
    }
    if (overlapping != overlapping_ || cached != cached_) {
        fail("pair status counts disagree");
    }
    coreValidate();
}

}  // namespace kolize
