#pragma once
/// \file
/// Exact truth for a set of Bullet proxies, and comparison of a pair cache against it.
/// Shared by the conformance tests, the pair-stream replay and the demos.

#include <BulletCollision/BroadphaseCollision/btBroadphaseProxy.h>
#include <BulletCollision/BroadphaseCollision/btOverlappingPairCache.h>

#include <cstdint>
#include <map>
#include <utility>
#include <vector>

namespace kolize {

/// An unordered pair of proxies by m_uniqueId, smaller first.
using UidPair = std::pair<int, int>;

inline UidPair uidPair(const btBroadphaseProxy* a, const btBroadphaseProxy* b) {
    return a->m_uniqueId < b->m_uniqueId ? UidPair{a->m_uniqueId, b->m_uniqueId}
                                         : UidPair{b->m_uniqueId, a->m_uniqueId};
}

/// A proxy with the box it should have: what the caller last gave the broadphase. (Not read
/// from the proxy: btAxisSweep3 leaves m_aabbMin/m_aabbMax unset until the first setAabb.)
struct ProxyBox {
    const btBroadphaseProxy* proxy = nullptr;
    btVector3 aabbMin;
    btVector3 aabbMax;
};

/// The pairs whose boxes overlap as closed intervals, tested with Bullet's own
/// TestAabbAgainstAabb2, and that pass `filter`'s needsBroadphaseCollision (skipped when
/// filter is null). Sorted. Sweep on x, so O(N log N + pairs overlapping on x).
std::vector<UidPair> exactPairs(const std::vector<ProxyBox>& boxes,
                                const btOverlappingPairCache* filter);

/// The same by testing every pair: O(N^2). The reference for exactPairs itself.
std::vector<UidPair> exactPairsNaive(const std::vector<ProxyBox>& boxes,
                                     const btOverlappingPairCache* filter);

/// Bullet's filter contract, as a model to test against: a pair's filters are evaluated when
/// its boxes start overlapping, with the filters of that moment, and the verdict holds while
/// the boxes keep overlapping (BroadphaseSettings::filters = WhenAdded; Bullet's own
/// broadphases). Feed it the boxes after every pair search.
class AdmittedPairs {
  public:
    /// The pairs that belong in the cache now, sorted: overlapping, and accepted by
    /// `filter` (none when null) when their current overlap began.
    std::vector<UidPair> update(const std::vector<ProxyBox>& boxes,
                                const btOverlappingPairCache* filter);

  private:
    std::map<UidPair, bool> verdicts_;  ///< overlapping pairs and their filter verdicts
};

/// The pairs held by the cache, sorted.
std::vector<UidPair> cachedPairs(const btOverlappingPairCache& cache);

/// Difference between reported and true pairs (both sorted).
struct PairDifference {
    std::vector<UidPair> missing;  ///< in truth, not reported: false negatives
    std::vector<UidPair> extra;    ///< reported, not in truth: false positives
    bool exact() const { return missing.empty() && extra.empty(); }
};
PairDifference comparePairs(const std::vector<UidPair>& truth,
                            const std::vector<UidPair>& reported);

}  // namespace kolize
