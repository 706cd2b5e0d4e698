#include <kolize/engine/pair_compare.h>

#include <LinearMath/btAabbUtil2.h>

#include <algorithm>

namespace kolize {

namespace {

bool wanted(const btOverlappingPairCache* filter, const btBroadphaseProxy* a,
            const btBroadphaseProxy* b) {
    return filter == nullptr || filter->needsBroadphaseCollision(const_cast<btBroadphaseProxy*>(a),
                                                                 const_cast<btBroadphaseProxy*>(b));
}

bool boxesOverlap(const btBroadphaseProxy* a, const btBroadphaseProxy* b) {
    return TestAabbAgainstAabb2(a->m_aabbMin, a->m_aabbMax, b->m_aabbMin, b->m_aabbMax);
}

}  // namespace

std::vector<UidPair> exactPairs(const std::vector<const btBroadphaseProxy*>& proxies,
                                const btOverlappingPairCache* filter) {
    std::vector<const btBroadphaseProxy*> byMinX(proxies);
    std::sort(byMinX.begin(), byMinX.end(),
              [](const btBroadphaseProxy* a, const btBroadphaseProxy* b) {
                  return a->m_aabbMin.x() < b->m_aabbMin.x();
              });
    std::vector<UidPair> out;
    for (std::size_t i = 0; i < byMinX.size(); ++i) {
        const btBroadphaseProxy* a = byMinX[i];
        // Sorted by min x: every later box starting at or before a's max x may overlap.
        for (std::size_t j = i + 1;
             j < byMinX.size() && byMinX[j]->m_aabbMin.x() <= a->m_aabbMax.x(); ++j) {
            const btBroadphaseProxy* b = byMinX[j];
            if (boxesOverlap(a, b) && wanted(filter, a, b)) {
                out.push_back(uidPair(a, b));
            }
        }
    }
    std::sort(out.begin(), out.end());
    return out;
}

std::vector<UidPair> exactPairsNaive(const std::vector<const btBroadphaseProxy*>& proxies,
                                     const btOverlappingPairCache* filter) {
    std::vector<UidPair> out;
    for (std::size_t i = 0; i < proxies.size(); ++i) {
        for (std::size_t j = i + 1; j < proxies.size(); ++j) {
            if (boxesOverlap(proxies[i], proxies[j]) && wanted(filter, proxies[i], proxies[j])) {
                out.push_back(uidPair(proxies[i], proxies[j]));
            }
        }
    }
    std::sort(out.begin(), out.end());
    return out;
}

std::vector<UidPair> cachedPairs(const btOverlappingPairCache& cache) {
    std::vector<UidPair> out;
    const int count = cache.getNumOverlappingPairs();
    out.reserve(count);
    const btBroadphasePair* pairs = count > 0 ? cache.getOverlappingPairArrayPtr() : nullptr;
    for (int i = 0; i < count; ++i) {
        out.push_back(uidPair(pairs[i].m_pProxy0, pairs[i].m_pProxy1));
    }
    std::sort(out.begin(), out.end());
    return out;
}

PairDifference comparePairs(const std::vector<UidPair>& truth,
                            const std::vector<UidPair>& reported) {
    PairDifference out;
    std::set_difference(truth.begin(), truth.end(), reported.begin(), reported.end(),
                        std::back_inserter(out.missing));
    std::set_difference(reported.begin(), reported.end(), truth.begin(), truth.end(),
                        std::back_inserter(out.extra));
    return out;
}

}  // namespace kolize
