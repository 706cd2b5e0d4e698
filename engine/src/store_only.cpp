#include <kolize/engine/store_only.h>

#include <kolize/kolize.h>

#include <BulletCollision/BroadphaseCollision/btOverlappingPairCache.h>

#include <algorithm>
#include <cstdio>
#include <functional>
#include <stdexcept>
#include <string>

namespace kolize {

StoreOnlyBroadphase::StoreOnlyBroadphase(const BroadphaseSettings& settings) {
    if (settings.pairCache != nullptr) {
        pairCache_ = settings.pairCache;
    } else {
        ownedCache_ = std::make_unique<btHashedOverlappingPairCache>();
        pairCache_ = ownedCache_.get();
    }
}

StoreOnlyBroadphase::~StoreOnlyBroadphase() = default;

StoreOnlyBroadphase::Slot& StoreOnlyBroadphase::checked(btBroadphaseProxy* proxy) const {
    // The slot's fields are read only once the address is known to be one of ours.
    const std::less<const btBroadphaseProxy*> before;
    const bool ours = std::any_of(chunks_.begin(), chunks_.end(), [&](const auto& chunk) {
        const Slot* first = chunk.get();
        return !before(proxy, first) && before(proxy, first + kChunk);
    });
    auto* slot = static_cast<Slot*>(proxy);
    if (!ours || !slot->alive) {
        throw std::invalid_argument(
            "kolize store-only: a proxy that is not alive in this broadphase");
    }
    return *slot;
}

btBroadphaseProxy* StoreOnlyBroadphase::createProxy(const btVector3& aabbMin,
                                                    const btVector3& aabbMax, int /*shapeType*/,
                                                    void* userPtr, int collisionFilterGroup,
                                                    int collisionFilterMask,
                                                    btDispatcher* /*dispatcher*/) {
    Slot* slot = nullptr;
    if (!free_.empty()) {
        slot = free_.back();
        free_.pop_back();
    } else {
        if (usedSlots_ == chunks_.size() * kChunk) {
            chunks_.push_back(std::make_unique<Slot[]>(kChunk));
        }
        slot = &chunks_[usedSlots_ / kChunk][usedSlots_ % kChunk];
        ++usedSlots_;
    }
    static_cast<btBroadphaseProxy&>(*slot) =
        btBroadphaseProxy(aabbMin, aabbMax, userPtr, collisionFilterGroup, collisionFilterMask);
    slot->m_uniqueId = nextUid_++;
    slot->alive = true;
    slot->livePosition = live_.size();
    live_.push_back(slot);
    return slot;
}

void StoreOnlyBroadphase::destroyProxy(btBroadphaseProxy* proxy, btDispatcher* dispatcher) {
    Slot& slot = checked(proxy);
    pairCache_->removeOverlappingPairsContainingProxy(proxy, dispatcher);
    Slot* last = live_.back();
    live_[slot.livePosition] = last;
    last->livePosition = slot.livePosition;
    live_.pop_back();
    slot.alive = false;
    slot.m_clientObject = nullptr;
    free_.push_back(&slot);
}

void StoreOnlyBroadphase::setAabb(btBroadphaseProxy* proxy, const btVector3& aabbMin,
                                  const btVector3& aabbMax, btDispatcher* /*dispatcher*/) {
    // No check here: the lower bound is the bare store a caller cannot avoid.
    proxy->m_aabbMin = aabbMin;
    proxy->m_aabbMax = aabbMax;
}

void StoreOnlyBroadphase::getAabb(btBroadphaseProxy* proxy, btVector3& aabbMin,
                                  btVector3& aabbMax) const {
    aabbMin = proxy->m_aabbMin;
    aabbMax = proxy->m_aabbMax;
}

void StoreOnlyBroadphase::rayTest(const btVector3& /*rayFrom*/, const btVector3& /*rayTo*/,
                                  btBroadphaseRayCallback& rayCallback,
                                  const btVector3& /*aabbMin*/, const btVector3& /*aabbMax*/) {
    for (Slot* slot : live_) {
        rayCallback.process(slot);
    }
}

void StoreOnlyBroadphase::aabbTest(const btVector3& /*aabbMin*/, const btVector3& /*aabbMax*/,
                                   btBroadphaseAabbCallback& callback) {
    for (Slot* slot : live_) {
        callback.process(slot);
    }
}

void StoreOnlyBroadphase::getBroadphaseAabb(btVector3& aabbMin, btVector3& aabbMax) const {
    aabbMin.setValue(0, 0, 0);
    aabbMax.setValue(0, 0, 0);
    for (std::size_t i = 0; i < live_.size(); ++i) {
        if (i == 0) {
            aabbMin = live_[i]->m_aabbMin;
            aabbMax = live_[i]->m_aabbMax;
        } else {
            aabbMin.setMin(live_[i]->m_aabbMin);
            aabbMax.setMax(live_[i]->m_aabbMax);
        }
    }
}

void StoreOnlyBroadphase::printStats() {
    std::printf("kolize store-only: %zu live proxies, %zu slots\n", live_.size(), usedSlots_);
}

bool isStoreOnly(std::string_view name) {
    return name == "store-only";
}

std::string measurementSkipReason(std::string_view name, int proxies) {
    if ((name == "brute-force" || name == "simple") && proxies > 20000) {
        return "O(N^2) per frame above 20000 objects";
    }
    if ((name == "sap" || name == "sap-noray") && proxies > 32766) {
        return "btAxisSweep3 holds at most 32766 proxies";
    }
    if (name == "sap32" && proxies > 50000) {
        return "bt32BitAxisSweep3's createProxy is O(N): minutes of init";
    }
    return {};
}

std::unique_ptr<btBroadphaseInterface> makeMeasuredBroadphase(std::string_view name,
                                                              const BroadphaseSettings& settings) {
    if (isStoreOnly(name)) {
        return std::make_unique<StoreOnlyBroadphase>(settings);
    }
    const auto& names = broadphaseNames();
    if (std::find(names.begin(), names.end(), name) == names.end()) {
        throw std::invalid_argument("kolize: unknown broadphase '" + std::string(name) +
                                    "'; valid names: " + broadphaseNameList() + ", store-only");
    }
    return makeBroadphase(name, settings);
}

}  // namespace kolize
