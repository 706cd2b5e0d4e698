#pragma once
/// \file
/// The lower bound of any drop-in broadphase: StoreOnlyBroadphase receives Bullet's calls
/// and keeps the boxes, nothing else. Timed with the same driver as a real broadphase, it
/// shows what any btBroadphaseInterface must spend just receiving createProxy / setAabb /
/// calculateOverlappingPairs, so other results can be read as multiples of it.

#include <kolize/broadphase/settings.h>

#include <BulletCollision/BroadphaseCollision/btBroadphaseInterface.h>
#include <BulletCollision/BroadphaseCollision/btBroadphaseProxy.h>

#include <memory>
#include <string>
#include <string_view>
#include <vector>

class btOverlappingPairCache;

namespace kolize {

/// A valid btBroadphaseInterface that finds no pairs. Proxies live at stable addresses
/// (a destroyed proxy's slot is reused by a later createProxy); setAabb stores the box;
/// calculateOverlappingPairs does nothing, so its pair cache stays empty (unless someone
/// else adds pairs); aabbTest and rayTest report every live proxy (a valid superset).
class StoreOnlyBroadphase : public btBroadphaseInterface {
  public:
    /// Uses settings.pairCache when given (not owned), else owns a hashed pair cache.
    explicit StoreOnlyBroadphase(const BroadphaseSettings& settings = {});
    ~StoreOnlyBroadphase() override;
    StoreOnlyBroadphase(const StoreOnlyBroadphase&) = delete;
    StoreOnlyBroadphase& operator=(const StoreOnlyBroadphase&) = delete;

    btBroadphaseProxy* createProxy(const btVector3& aabbMin, const btVector3& aabbMax,
                                   int shapeType, void* userPtr, int collisionFilterGroup,
                                   int collisionFilterMask, btDispatcher* dispatcher) override;
    /// Removes the proxy's pairs from the cache and frees its slot. Throws
    /// std::invalid_argument for a foreign or already destroyed proxy.
    void destroyProxy(btBroadphaseProxy* proxy, btDispatcher* dispatcher) override;
    void setAabb(btBroadphaseProxy* proxy, const btVector3& aabbMin, const btVector3& aabbMax,
                 btDispatcher* dispatcher) override;
    void getAabb(btBroadphaseProxy* proxy, btVector3& aabbMin, btVector3& aabbMax) const override;
    void rayTest(const btVector3& rayFrom, const btVector3& rayTo,
                 btBroadphaseRayCallback& rayCallback, const btVector3& aabbMin,
                 const btVector3& aabbMax) override;
    void aabbTest(const btVector3& aabbMin, const btVector3& aabbMax,
                  btBroadphaseAabbCallback& callback) override;
    /// Does nothing: the lower bound finds no pairs.
    void calculateOverlappingPairs(btDispatcher*) override {}
    btOverlappingPairCache* getOverlappingPairCache() override { return pairCache_; }
    const btOverlappingPairCache* getOverlappingPairCache() const override { return pairCache_; }
    /// The union of the live proxies' boxes (a zero box when there are none).
    void getBroadphaseAabb(btVector3& aabbMin, btVector3& aabbMax) const override;
    void resetPool(btDispatcher*) override {}
    void printStats() override;

    /// Live proxies.
    std::size_t size() const { return live_.size(); }

  private:
    struct Slot : btBroadphaseProxy {
        std::size_t livePosition = 0;  ///< index in live_
        bool alive = false;
    };
    Slot& checked(btBroadphaseProxy* proxy) const;

    static constexpr std::size_t kChunk = 1024;
    std::vector<std::unique_ptr<Slot[]>> chunks_;  ///< slots at stable addresses
    std::size_t usedSlots_ = 0;                    ///< slots handed out at least once
    std::vector<Slot*> free_;
    std::vector<Slot*> live_;
    int nextUid_ = 1;
    std::unique_ptr<btOverlappingPairCache> ownedCache_;
    btOverlappingPairCache* pairCache_ = nullptr;
};

/// The broadphases a benchmark can time: "store-only" (StoreOnlyBroadphase) and every name
/// makeBroadphase accepts. Throws std::invalid_argument for an unknown name.
std::unique_ptr<btBroadphaseInterface> makeMeasuredBroadphase(std::string_view name,
                                                              const BroadphaseSettings& settings);

/// Why a benchmark skips broadphase `name` with `proxies` proxies, or empty when it runs:
/// brute-force and simple above 20000 (O(N^2) per frame), sap and sap-noray above 32766
/// (btAxisSweep3's 16-bit handles), sap32 above 50000 (O(N) per createProxy: 1.1 s of init
/// at 10000, over 10 minutes at 100000).
std::string measurementSkipReason(std::string_view name, int proxies);

/// True for "store-only".
bool isStoreOnly(std::string_view name);

}  // namespace kolize
