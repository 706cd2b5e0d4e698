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

bool boxesOverlap(const ProxyBox& a, const ProxyBox& b) {
    return TestAabbAgainstAabb2(a.aabbMin, a.aabbMax, b.aabbMin, b.aabbMax);
}

}  // namespace

std::vector<UidPair> exactPairs(const std::vector<ProxyBox>& boxes,
                                const btOverlappingPairCache* filter) {
    std::vector<const ProxyBox*> byMinX;
    byMinX.reserve(boxes.size());
    for (const ProxyBox& box : boxes) {
        byMinX.push_back(&box);
    }
    std::sort(byMinX.begin(), byMinX.end(),
              [](const ProxyBox* a, const ProxyBox* b) { return a->aabbMin.x() < b->aabbMin.x(); });
    std::vector<UidPair> out;
    for (std::size_t i = 0; i < byMinX.size(); ++i) {
        const ProxyBox& a = *byMinX[i];
        // Sorted by min x: only later boxes starting at or before a's max x can overlap a.
        for (std::size_t j = i + 1; j < byMinX.size() && byMinX[j]->aabbMin.x() <= a.aabbMax.x();
             ++j) {
            const ProxyBox& b = *byMinX[j];
            if (boxesOverlap(a, b) && wanted(filter, a.proxy, b.proxy)) {
                out.push_back(uidPair(a.proxy, b.proxy));
            }
        }
    }
    std::sort(out.begin(), out.end());
    return out;
}

std::vector<UidPair> exactPairsNaive(const std::vector<ProxyBox>& boxes,
                                     const btOverlappingPairCache* filter) {
    std::vector<UidPair> out;
    for (std::size_t i = 0; i < boxes.size(); ++i) {
        for (std::size_t j = i + 1; j < boxes.size(); ++j) {
            if (boxesOverlap(boxes[i], boxes[j]) &&
                wanted(filter, boxes[i].proxy, boxes[j].proxy)) {
                out.push_back(uidPair(boxes[i].proxy, boxes[j].proxy));
            }
        }
    }
    std::sort(out.begin(), out.end());
    return out;
}

std::vector<UidPair> AdmittedPairs::update(const std::vector<ProxyBox>& boxes,
                                           const btOverlappingPairCache* filter) {
    std::map<int, const btBroadphaseProxy*> byUid;
    for (const ProxyBox& box : boxes) {
        byUid[box.proxy->m_uniqueId] = box.proxy;
    }
    std::map<UidPair, bool> verdicts;
    std::vector<UidPair> out;
    for (const UidPair& pair : exactPairs(boxes, nullptr)) {
        const auto known = verdicts_.find(pair);
        const bool accepted = known != verdicts_.end()
                                  ? known->second
                                  : wanted(filter, byUid[pair.first], byUid[pair.second]);
        verdicts.emplace(pair, accepted);
        if (accepted) {
            out.push_back(pair);
        }
    }
    verdicts_.swap(verdicts);
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
