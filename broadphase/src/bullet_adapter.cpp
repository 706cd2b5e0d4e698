#include <kolize/broadphase/bullet_adapter.h>

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
constexpr std::size_t kMaxPendingFree = 4096;

void appendVector(std::ostringstream& out, const btVector3& v) {
    out << '(' << v.x() << ", " << v.y() << ", " << v.z() << ')';
}

}  // namespace

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
    } else {
        void* memory = btAlignedAlloc(sizeof(btHashedOverlappingPairCache), 16);
        pairCache_ = new (memory) btHashedOverlappingPairCache();
        ownsPairCache_ = true;
    }
}

BroadphaseAdapter::~BroadphaseAdapter() {
    if (ownsPairCache_) {
        pairCache_->~btOverlappingPairCache();
        btAlignedFree(pairCache_);
    }
}

const char* BroadphaseAdapter::rejectReason(const btVector3& aabbMin, const btVector3& aabbMax) {
    // Fast path for every setAabb: finite and ordered (NaN fails every comparison).
    constexpr btScalar kMax = std::numeric_limits<btScalar>::max();
    bool good = true;
    for (int axis = 0; axis < 3; ++axis) {
        good &= aabbMin[axis] <= aabbMax[axis] && aabbMin[axis] >= -kMax && aabbMax[axis] <= kMax;
    }
    if (good) {
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
        movedFlag_.push_back(0);
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
    coreInsert(slot, fat_[slot]);
    noteMoved(slot);
    return proxy;
}

BroadphaseAdapter::Proxy* BroadphaseAdapter::checkedProxy(btBroadphaseProxy* proxy,
                                                          const char* operation) const {
    Proxy* ours = static_cast<Proxy*>(proxy);
    if (proxy == nullptr || ours->slot >= boxes_.size() || proxyOf(ours->slot) != ours ||
        (state_[ours->slot] != SlotState::Live && state_[ours->slot] != SlotState::Parked)) {
        throw std::invalid_argument("kolize " + name_ + ": " + operation +
                                    " called with a proxy this broadphase does not own (or one "
                                    "already destroyed)");
    }
    return ours;
}

void BroadphaseAdapter::destroyProxy(btBroadphaseProxy* proxy, btDispatcher* dispatcher) {
    Proxy* ours = checkedProxy(proxy, "destroyProxy");
    pairCache_->removeOverlappingPairsContainingProxy(ours, dispatcher);
    const ObjectId slot = ours->slot;
    if (state_[slot] == SlotState::Live) {
        coreRemove(slot);
    } else {
        --parkedCount_;
    }
    // The slot's entries in pairs_ go stale at the next frame; keeping the slot out of reuse
    // until then means a new proxy never inherits them.
    state_[slot] = SlotState::PendingFree;
    pendingFree_.push_back(slot);
    ours->m_clientObject = nullptr;
    --liveCount_;
    if (pendingFree_.size() > kMaxPendingFree) {
        // An app that creates and destroys without ever computing pairs must not grow
        // without bound: drop the destroyed slots' pairs now and release the slots.
        pairs_.retainIf([&](const PairSet::Entry& entry) {
            return state_[entry.first()] != SlotState::PendingFree &&
                   state_[entry.second()] != SlotState::PendingFree;
        });
        releasePendingSlots();
    }
}

void BroadphaseAdapter::releasePendingSlots() {
    for (ObjectId slot : pendingFree_) {
        state_[slot] = SlotState::Free;
        freeSlots_.push_back(slot);
    }
    pendingFree_.clear();
}

void BroadphaseAdapter::setAabb(btBroadphaseProxy* proxy, const btVector3& aabbMin,
                                const btVector3& aabbMax, btDispatcher* /*dispatcher*/) {
    Proxy* ours = static_cast<Proxy*>(proxy);
    const ObjectId slot = ours->slot;
    const char* reason = rejectReason(aabbMin, aabbMax);
    if (*reason != '\0') {
        reportBadAabb("setAabb", *checkedProxy(proxy, "setAabb"), aabbMin, aabbMax, reason);
        return;
    }
    const Box box = toBox(aabbMin, aabbMax);
    if (state_[slot] == SlotState::Live && box == boxes_[slot]) {
        return;  // unchanged (resting and sleeping bodies): nothing to do
    }
    if (state_[slot] == SlotState::Live) {
        ours->m_aabbMin = aabbMin;
        ours->m_aabbMax = aabbMax;
        if (contains(fat_[slot], box)) {
            boxes_[slot] = box;  // the core box still holds it: only the exact tests change
            ++counters_.movesInsideFatBoxes;
            return;
        }
        fat_[slot] = fatBox(box, boxes_[slot]);
        boxes_[slot] = box;
        coreUpdate(slot, fat_[slot]);
    } else {
        checkedProxy(proxy, "setAabb");
        ours->m_aabbMin = aabbMin;
        ours->m_aabbMax = aabbMax;
        state_[slot] = SlotState::Live;
        --parkedCount_;
        boxes_[slot] = box;
        fat_[slot] = box;
        coreInsert(slot, fat_[slot]);
    }
    ++counters_.coreUpdates;
    noteMoved(slot);
}

BroadphaseAdapter::Box BroadphaseAdapter::fatBox(const Box& box, const Box& previous) const {
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

Ray<3, btScalar> BroadphaseAdapter::toRay(const btVector3& rayFrom,
                                          const btBroadphaseRayCallback& callback,
                                          const btVector3& aabbMin, const btVector3& aabbMax) {
    Ray<3, btScalar> ray;
    for (int axis = 0; axis < 3; ++axis) {
        ray.origin[axis] = rayFrom[axis];
        ray.inverseDirection[axis] = callback.m_rayDirectionInverse[axis];
        ray.sign[axis] = callback.m_signs[axis];
        ray.expandLo[axis] = aabbMin[axis];
        ray.expandHi[axis] = aabbMax[axis];
    }
    ray.lambdaMax = callback.m_lambda_max;
    return ray;
}

void BroadphaseAdapter::finishPairs(btDispatcher* dispatcher, std::size_t candidates,
                                    bool incremental) {
    const std::uint32_t stamp = stamp_;
    std::size_t overlapping = 0;
    pairs_.retainIf([&](PairSet::Entry& entry) {
        Proxy* a = proxyOf(entry.first());
        Proxy* b = proxyOf(entry.second());
        if (entry.stamp != stamp && incremental && !movedFlag_[entry.first()] &&
            !movedFlag_[entry.second()] && state_[entry.first()] == SlotState::Live &&
            state_[entry.second()] == SlotState::Live) {
            entry.stamp = stamp;  // neither core box changed: still a candidate
        }
        if (entry.stamp != stamp) {
            // Destroyed proxies already had their pairs removed by destroyProxy.
            const bool bothAlive = state_[entry.first()] != SlotState::PendingFree &&
                                   state_[entry.second()] != SlotState::PendingFree;
            if (entry.inCache && bothAlive) {
                pairCache_->removeOverlappingPair(a, b, dispatcher);
                ++counters_.pairsRemoved;
            }
            return false;
        }
        const bool overlap = overlaps(boxes_[entry.first()], boxes_[entry.second()]);
        overlapping += overlap ? 1 : 0;
        const bool wanted = overlap && pairCache_->needsBroadphaseCollision(a, b);
        if (wanted && !entry.inCache) {
            entry.inCache = pairCache_->addOverlappingPair(a, b) != nullptr;
            counters_.pairsAdded += entry.inCache ? 1 : 0;
        } else if (!wanted && entry.inCache) {
            pairCache_->removeOverlappingPair(a, b, dispatcher);
            entry.inCache = false;
            ++counters_.pairsRemoved;
        }
        return true;
    });
    releasePendingSlots();
    for (ObjectId slot : moved_) {
        movedFlag_[slot] = 0;
    }
    moved_.clear();
    framesSinceFullSearch_ = incremental ? framesSinceFullSearch_ + 1 : 0;
    counters_.incrementalSearches += incremental ? 1 : 0;
    ++counters_.frames;
    counters_.candidatesLastFrame = candidates;
    counters_.overlappingPairs = overlapping;
}

void BroadphaseAdapter::resetPool(btDispatcher* /*dispatcher*/) {
    if (liveCount_ != 0) {
        return;
    }
    chunks_.clear();
    boxes_.clear();
    fat_.clear();
    state_.clear();
    freeSlots_.clear();
    pendingFree_.clear();
    pairs_.clear();
    moved_.clear();
    movedFlag_.clear();
    nextUid_ = 1;
}

AdapterStats BroadphaseAdapter::stats() const {
    AdapterStats out = counters_;
    out.proxies = liveCount_;
    out.parkedProxies = parkedCount_;
    out.slots = boxes_.size();
    out.candidatePairs = pairs_.size();
    out.memoryBytes = chunks_.size() * (sizeof(Proxy) << kChunkBits) +
                      (boxes_.capacity() + fat_.capacity()) * sizeof(Box) + state_.capacity() +
                      (freeSlots_.capacity() + pendingFree_.capacity()) * sizeof(ObjectId) +
                      pairs_.memoryBytes() + coreMemoryBytes();
    return out;
}

void BroadphaseAdapter::printStats() {
    const AdapterStats s = stats();
    std::printf(
        "kolize %s: %zu proxies (%zu parked), %zu overlapping pairs (%zu candidate pairs), %zu "
        "frames (%zu incremental), %zu candidates last frame, %zu core updates, %zu moves "
        "inside fat boxes, %zu pairs added, %zu removed, %zu bad AABBs rejected, %zu bytes\n",
        name_.c_str(), s.proxies, s.parkedProxies, s.overlappingPairs, s.candidatePairs, s.frames,
        s.incrementalSearches, s.candidatesLastFrame, s.coreUpdates, s.movesInsideFatBoxes,
        s.pairsAdded, s.pairsRemoved, s.badAabbReports, s.memoryBytes);
}

void BroadphaseAdapter::validate() const {
    auto fail = [&](const std::string& what) {
        throw std::logic_error("kolize " + name_ + ": validate: " + what);
    };
    if (boxes_.size() != state_.size() || chunks_.size() << kChunkBits < boxes_.size()) {
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
                break;
            case SlotState::Parked:
                ++parked;
                break;
            default:
                break;
        }
    }
    if (live + parked != liveCount_ || parked != parkedCount_) {
        fail("live/parked counts disagree with the slot table");
    }
    std::size_t flagged = 0;
    for (std::uint8_t flag : movedFlag_) {
        flagged += flag;
    }
    if (movedFlag_.size() != boxes_.size() || flagged != moved_.size()) {
        fail("moved list and flags disagree");
    }
    for (std::size_t slot = 0; slot < boxes_.size(); ++slot) {
        if (state_[slot] == SlotState::Live && !contains(fat_[slot], boxes_[slot])) {
            fail("core box of slot " + std::to_string(slot) + " does not contain its box");
        }
    }
    pairs_.validate();
    pairs_.forEach([&](const PairSet::Entry& entry) {
        if (entry.second() >= boxes_.size()) {
            fail("pair names a slot out of range");
        }
    });
    coreValidate();
}

}  // namespace kolize
