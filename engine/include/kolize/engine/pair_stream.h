#pragma once
/// \file
/// Pair streams: every createProxy / destroyProxy / setAabb a Bullet world makes, with frame
/// boundaries (calculateOverlappingPairs), recorded to a compact binary file and replayed
/// into any named broadphase, frame by frame compared with the exact truth.

#include <kolize/broadphase/settings.h>
#include <kolize/engine/pair_compare.h>

#include <BulletCollision/BroadphaseCollision/btBroadphaseInterface.h>

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace kolize {

/// One recorded broadphase call.
struct StreamEvent {
    enum class Op : std::uint8_t { Create = 1, Destroy = 2, SetAabb = 3, EndFrame = 4 };
    Op op = Op::EndFrame;
    /// Dense object number, assigned at Create in recording order (never reused).
    std::uint32_t object = 0;
    int group = 0;  ///< Create only
    int mask = 0;   ///< Create only
    double aabbMin[3] = {0, 0, 0};
    double aabbMax[3] = {0, 0, 0};
};

/// A recorded sequence of broadphase calls.
struct PairStream {
    /// Bytes per coordinate in the file: 4 when recorded from a float Bullet, 8 from double.
    std::uint8_t scalarBytes = sizeof(btScalar);
    std::vector<StreamEvent> events;

    std::size_t frames() const;
    /// Writes the stream; throws std::runtime_error naming the file on failure.
    void save(const std::string& path) const;
    /// Reads a stream; throws std::runtime_error naming the file and the problem (missing,
    /// not a kolize stream, truncated at byte N, unknown event, object used before created).
    static PairStream load(const std::string& path);
};

/// A broadphase wrapper that records every call into `stream` and forwards it unchanged.
/// Install it in a world in place of the broadphase it wraps.
class RecordingBroadphase : public btBroadphaseInterface {
  public:
    RecordingBroadphase(btBroadphaseInterface& inner, PairStream& stream);

    btBroadphaseProxy* createProxy(const btVector3& aabbMin, const btVector3& aabbMax,
                                   int shapeType, void* userPtr, int collisionFilterGroup,
                                   int collisionFilterMask, btDispatcher* dispatcher) override;
    void destroyProxy(btBroadphaseProxy* proxy, btDispatcher* dispatcher) override;
    void setAabb(btBroadphaseProxy* proxy, const btVector3& aabbMin, const btVector3& aabbMax,
                 btDispatcher* dispatcher) override;
    void getAabb(btBroadphaseProxy* proxy, btVector3& aabbMin, btVector3& aabbMax) const override {
        inner_.getAabb(proxy, aabbMin, aabbMax);
    }
    void rayTest(const btVector3& rayFrom, const btVector3& rayTo,
                 btBroadphaseRayCallback& rayCallback, const btVector3& aabbMin,
                 const btVector3& aabbMax) override {
        inner_.rayTest(rayFrom, rayTo, rayCallback, aabbMin, aabbMax);
    }
    void aabbTest(const btVector3& aabbMin, const btVector3& aabbMax,
                  btBroadphaseAabbCallback& callback) override {
        inner_.aabbTest(aabbMin, aabbMax, callback);
    }
    void calculateOverlappingPairs(btDispatcher* dispatcher) override;
    btOverlappingPairCache* getOverlappingPairCache() override {
        return inner_.getOverlappingPairCache();
    }
    const btOverlappingPairCache* getOverlappingPairCache() const override {
        return inner_.getOverlappingPairCache();
    }
    void getBroadphaseAabb(btVector3& aabbMin, btVector3& aabbMax) const override {
        inner_.getBroadphaseAabb(aabbMin, aabbMax);
    }
    void resetPool(btDispatcher* dispatcher) override { inner_.resetPool(dispatcher); }
    void printStats() override { inner_.printStats(); }

  private:
    btBroadphaseInterface& inner_;
    PairStream& stream_;
    std::unordered_map<const btBroadphaseProxy*, std::uint32_t> objectOf_;
    std::uint32_t nextObject_ = 0;
};

/// Per-frame result of a replay.
struct ReplayFrame {
    double updateSeconds = 0;  ///< create/destroy/setAabb calls of the frame
    double pairSeconds = 0;    ///< calculateOverlappingPairs
    std::size_t truePairs = 0;
    std::size_t reportedPairs = 0;
    std::size_t missing = 0;  ///< false negatives
    std::size_t extra = 0;    ///< false positives
    /// Proxies created, destroyed or given a different box in the frame (0: a world at rest,
    /// every setAabb repeating the box it had).
    std::size_t changedProxies = 0;
};

struct ReplayResult {
    std::string broadphase;
    std::vector<ReplayFrame> frames;
    std::size_t totalMissing() const;
    std::size_t totalExtra() const;
    /// Median over frames of updateSeconds + pairSeconds.
    double medianFrameSeconds() const;
    /// Frames in which no proxy changed (changedProxies == 0): a world at rest.
    std::size_t restingFrames() const;
    /// Median of updateSeconds + pairSeconds over the resting frames; 0 if there are none.
    double medianRestingSeconds() const;
};

/// Replays `stream` into makeMeasuredBroadphase(name, settings) (any broadphase name or
/// "store-only") with a null dispatcher; after each
/// frame compares the pair cache with exactPairs over the live proxies.
/// Throws std::invalid_argument for an unknown name.
ReplayResult replay(const PairStream& stream, std::string_view name,
                    const BroadphaseSettings& settings = {});

}  // namespace kolize
