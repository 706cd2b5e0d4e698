/// MergedPairCache against Bullet's btHashedOverlappingPairCache: the same seeded random
/// operations go to both, and everything Bullet's interface shows must agree (pairs, their
/// algorithms and user data, return values, ghost callbacks in order, freed algorithms,
/// the deterministic visiting order).

#include <kolize/broadphase/merged_pair_cache.h>
#include <kolize/kolize.h>

#include <btBulletCollisionCommon.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <climits>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <random>
#include <string>
#include <tuple>
#include <vector>

namespace kolize {
namespace {

using Event = std::tuple<char, int, int>;  // 'a' / 'r', uid of proxy0, uid of proxy1

/// Records the ghost pair callbacks a cache makes.
struct GhostRecorder : btOverlappingPairCallback {
    btBroadphasePair* addOverlappingPair(btBroadphaseProxy* a, btBroadphaseProxy* b) override {
        events.emplace_back('a', a->m_uniqueId, b->m_uniqueId);
        return nullptr;
    }
    void* removeOverlappingPair(btBroadphaseProxy* a, btBroadphaseProxy* b,
                                btDispatcher*) override {
        events.emplace_back('r', a->m_uniqueId, b->m_uniqueId);
        return nullptr;
    }
    void removeOverlappingPairsContainingProxy(btBroadphaseProxy*, btDispatcher*) override {}
    std::vector<Event> events;
};

/// An algorithm that notes its id in a log when destroyed.
struct TaggedAlgorithm : btCollisionAlgorithm {
    TaggedAlgorithm(int id, std::vector<int>* log) : id(id), log(log) {}
    ~TaggedAlgorithm() override { log->push_back(id); }
    void processCollision(const btCollisionObjectWrapper*, const btCollisionObjectWrapper*,
                          const btDispatcherInfo&, btManifoldResult*) override {}
    btScalar calculateTimeOfImpact(btCollisionObject*, btCollisionObject*, const btDispatcherInfo&,
                                   btManifoldResult*) override {
        return 1;
    }
    void getAllContactManifolds(btManifoldArray&) override {}
    int id;
    std::vector<int>* log;
};

/// Frees the tagged algorithms' memory.
struct FreeingDispatcher : btCollisionDispatcher {
    explicit FreeingDispatcher(btCollisionConfiguration* configuration)
        : btCollisionDispatcher(configuration) {}
    void freeCollisionAlgorithm(void* memory) override {
        ++freed;
        std::free(memory);
    }
    int freed = 0;
};

/// Visits pairs in order and removes those a rule picks.
struct RecordingVisitor : btOverlapCallback {
    explicit RecordingVisitor(int rule) : rule(rule) {}
    bool processOverlap(btBroadphasePair& pair) override {
        const int a = pair.m_pProxy0->m_uniqueId, b = pair.m_pProxy1->m_uniqueId;
        visited.emplace_back(a, b);
        // In 64 bits: the ids include INT_MAX.
        const std::int64_t mix = std::int64_t(a) * 7 + std::int64_t(b) * 3;
        return rule != 0 && (mix % rule + rule) % rule == 0;
    }
    int rule;
    std::vector<std::pair<int, int>> visited;
};

/// A filter callback that rejects some pairs by their ids.
struct IdFilter : btOverlapFilterCallback {
    bool needBroadphaseCollision(btBroadphaseProxy* a, btBroadphaseProxy* b) const override {
        const std::int64_t sum = std::int64_t(a->m_uniqueId) + b->m_uniqueId;
        return (sum % 4 + 4) % 4 != 1;
    }
};

struct PairView {
    int uid0, uid1;
    int algorithm;  // tag, -1 for none
    void* info;
    bool operator==(const PairView& o) const {
        return uid0 == o.uid0 && uid1 == o.uid1 && algorithm == o.algorithm && info == o.info;
    }
    bool operator<(const PairView& o) const {
        return std::tie(uid0, uid1) < std::tie(o.uid0, o.uid1);
    }
};

PairView viewOf(const btBroadphasePair& pair) {
    const auto* tagged = static_cast<const TaggedAlgorithm*>(pair.m_algorithm);
    return PairView{pair.m_pProxy0->m_uniqueId, pair.m_pProxy1->m_uniqueId,
                    tagged != nullptr ? tagged->id : -1, pair.m_internalInfo1};
}

std::vector<PairView> viewsOf(btOverlappingPairCache& cache, bool sorted) {
    std::vector<PairView> out;
    btBroadphasePairArray& pairs = cache.getOverlappingPairArray();
    for (int i = 0; i < pairs.size(); ++i) {
        out.push_back(viewOf(pairs[i]));
    }
    if (sorted) {
        std::sort(out.begin(), out.end());
    }
    return out;
}

/// One cache and everything that watches it.
struct Side {
    explicit Side(btOverlappingPairCache* cache) : cache(cache), dispatcher(&configuration) {
        cache->setInternalGhostPairCallback(&ghost);
    }
    btOverlappingPairCache* cache;
    btDefaultCollisionConfiguration configuration;
    FreeingDispatcher dispatcher;
    GhostRecorder ghost;
    std::vector<int> destroyed;  // algorithm ids, in the order destroyed
};

class Differential {
  public:
    explicit Differential(std::uint32_t seed) : random_(seed) {
        // Ids as Bullet's broadphases hand them out, and a few extremes for the ordering.
        const int uids[] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 0, -3, INT_MAX, INT_MIN + 1};
        proxies_.resize(std::size(uids));
        for (std::size_t i = 0; i < proxies_.size(); ++i) {
            proxies_[i].m_uniqueId = uids[i];
            proxies_[i].m_collisionFilterGroup = (i % 5 == 4) ? 2 : 1;
            proxies_[i].m_collisionFilterMask = (i % 7 == 6) ? 1 : -1;
        }
        if (random_() % 3 == 0) {
            bullet_.cache->setOverlapFilterCallback(&filter_);
            ours_.cache->setOverlapFilterCallback(&filter_);
        }
    }
    ~Differential() {
        // Free what is left, through each cache.
        for (Side* side : {&bullet_, &ours_}) {
            btBroadphasePairArray& pairs = side->cache->getOverlappingPairArray();
            for (int i = 0; i < pairs.size(); ++i) {
                side->cache->cleanOverlappingPair(pairs[i], &side->dispatcher);
            }
        }
    }

    /// Runs `steps` random operations; returns how many of them changed the pairs.
    int run(int steps) {
        int changes = 0;
        for (int step = 0; step < steps && !::testing::Test::HasFailure(); ++step) {
            SCOPED_TRACE("step " + std::to_string(step));
            changes += operation() ? 1 : 0;
            EXPECT_EQ(bullet_.ghost.events, ours_.ghost.events);
            EXPECT_EQ(bullet_.cache->getNumOverlappingPairs(),
                      ours_.cache->getNumOverlappingPairs());
            EXPECT_NO_THROW(merged().validate());
        }
        return changes;
    }

  private:
    MergedPairCache& merged() { return *static_cast<MergedPairCache*>(ours_.cache); }
    /// Half the time one of the first five proxies: the same pairs come back often, so that
    /// a pair is removed and added again between two reads.
    btBroadphaseProxy* pick() {
        const std::size_t among = random_() % 2 == 0 ? 5 : proxies_.size();
        return &proxies_[random_() % among];
    }

    /// One random operation on both caches; true when it changed the pair set.
    bool operation() {
        btBroadphaseProxy* a = pick();
        btBroadphaseProxy* b = pick();
        const int before = bullet_.cache->getNumOverlappingPairs();
        const bool present = a != b && bullet_.cache->findPair(a, b) != nullptr;
        switch (random_() % 12) {
            case 0:
            case 1: {  // Bullet's add
                if (a == b) {
                    return false;
                }
                const bool bulletAdded = bullet_.cache->addOverlappingPair(a, b) != nullptr;
                const bool ourAdded = ours_.cache->addOverlappingPair(a, b) != nullptr;
                EXPECT_EQ(bulletAdded, ourAdded);
                break;
            }
            case 2:
            case 3: {  // the trusted add, where a broadphase would make it
                if (a == b || present || !ours_.cache->needsBroadphaseCollision(a, b)) {
                    return false;
                }
                EXPECT_NE(bullet_.cache->addOverlappingPair(a, b), nullptr);
                EXPECT_NE(merged().addAbsentPair(a, b), nullptr);
                break;
            }
            case 4: {  // Bullet's remove
                void* bulletInfo = bullet_.cache->removeOverlappingPair(a, b, &bullet_.dispatcher);
                void* ourInfo = ours_.cache->removeOverlappingPair(a, b, &ours_.dispatcher);
                EXPECT_EQ(bulletInfo, ourInfo);
                break;
            }
            case 5:
            case 6: {  // the trusted remove
                if (!present) {
                    return false;
                }
                bullet_.cache->removeOverlappingPair(a, b, &bullet_.dispatcher);
                merged().removePresentPair(a, b, &ours_.dispatcher);
                break;
            }
            case 7: {  // a dispatcher's work: an algorithm and user data on a pair
                btBroadphasePair* bulletPair = bullet_.cache->findPair(a, b);
                btBroadphasePair* ourPair = ours_.cache->findPair(a, b);
                EXPECT_EQ(bulletPair == nullptr, ourPair == nullptr);
                if (bulletPair == nullptr || ourPair == nullptr) {
                    return false;
                }
                EXPECT_TRUE(viewOf(*bulletPair) == viewOf(*ourPair));
                if (bulletPair->m_algorithm == nullptr) {
                    const int id = nextAlgorithm_++;
                    bulletPair->m_algorithm = new (std::malloc(sizeof(TaggedAlgorithm)))
                        TaggedAlgorithm(id, &bullet_.destroyed);
                    ourPair->m_algorithm = new (std::malloc(sizeof(TaggedAlgorithm)))
                        TaggedAlgorithm(id, &ours_.destroyed);
                }
                bulletPair->m_internalInfo1 = ourPair->m_internalInfo1 = &proxies_[id() % 4];
                return false;
            }
            case 8: {                                     // the dispatcher's walk
                const int rule = int(random_() % 4) * 3;  // 0: remove none
                RecordingVisitor bulletVisitor(rule), ourVisitor(rule);
                if (rule == 0) {
                    // In deterministic order. (Bullet's deterministic walk cannot remove: it
                    // stays on the index it removed, which now names another pair.)
                    btDispatcherInfo info;
                    info.m_deterministicOverlappingPairs = true;
                    bullet_.cache->processAllOverlappingPairs(&bulletVisitor, &bullet_.dispatcher,
                                                              info);
                    ours_.cache->processAllOverlappingPairs(&ourVisitor, &ours_.dispatcher, info);
                    EXPECT_EQ(bulletVisitor.visited, ourVisitor.visited);
                    break;
                }
                // Removing the pairs the rule picks; Bullet walks in its own order.
                const std::size_t from = bullet_.ghost.events.size();
                bullet_.cache->processAllOverlappingPairs(&bulletVisitor, &bullet_.dispatcher);
                ours_.cache->processAllOverlappingPairs(&ourVisitor, &ours_.dispatcher);
                std::sort(bulletVisitor.visited.begin(), bulletVisitor.visited.end());
                std::sort(ourVisitor.visited.begin(), ourVisitor.visited.end());
                EXPECT_EQ(bulletVisitor.visited, ourVisitor.visited);
                sortEventsFrom(from);
                break;
            }
            case 9: {  // a destroyed proxy, as a broadphase that shares its cache does it
                // Bullet walks its array in its own order: compare this call's ghost
                // callbacks as sets.
                const std::size_t from = bullet_.ghost.events.size();
                bullet_.cache->removeOverlappingPairsContainingProxy(a, &bullet_.dispatcher);
                ours_.cache->removeOverlappingPairsContainingProxy(a, &ours_.dispatcher);
                sortEventsFrom(from);
                break;
            }
            case 10:  // btCollisionWorld::removeCollisionObject's first step
                bullet_.cache->cleanProxyFromPairs(a, &bullet_.dispatcher);
                ours_.cache->cleanProxyFromPairs(a, &ours_.dispatcher);
                break;
            case 11: {  // a read of the whole array
                EXPECT_EQ(viewsOf(*bullet_.cache, true), viewsOf(*ours_.cache, false))
                    << "ours must be sorted by ids";
                std::vector<int> bulletFreed = bullet_.destroyed, ourFreed = ours_.destroyed;
                std::sort(bulletFreed.begin(), bulletFreed.end());
                std::sort(ourFreed.begin(), ourFreed.end());
                EXPECT_EQ(bulletFreed, ourFreed) << "algorithms freed";
                EXPECT_EQ(bullet_.dispatcher.freed, ours_.dispatcher.freed);
                break;
            }
        }
        return bullet_.cache->getNumOverlappingPairs() != before;
    }
    int id() { return nextAlgorithm_; }
    /// Ghost callbacks of a walk in Bullet's own array order: compared as sets.
    void sortEventsFrom(std::size_t from) {
        for (GhostRecorder* ghost : {&bullet_.ghost, &ours_.ghost}) {
            if (ghost->events.size() >= from) {
                std::sort(ghost->events.begin() + std::ptrdiff_t(from), ghost->events.end());
            }
        }
    }

    std::mt19937 random_;
    std::vector<btBroadphaseProxy> proxies_;
    IdFilter filter_;
    btHashedOverlappingPairCache bulletCache_;
    MergedPairCache ourCache_;
    Side bullet_{&bulletCache_};
    Side ours_{&ourCache_};
    int nextAlgorithm_ = 1;
};

TEST(MergedPairCache, AgreesWithBulletsHashedCacheOnRandomOperations) {
    const std::uint32_t base = 20261207;
    int changes = 0;
    for (std::uint32_t seed = base; seed < base + 60; ++seed) {
        SCOPED_TRACE("seed " + std::to_string(seed));
        Differential differential(seed);
        changes += differential.run(400);
        if (::testing::Test::HasFailure()) {
            std::printf("MergedPairCache differential failed at seed %u\n", seed);
            return;
        }
    }
    // The sample means something: many operations changed the pairs.
    EXPECT_GT(changes, 4000);
}

/// Boxes on a line of cells, moved at random; `overlapping` counts the true pairs.
struct LineOfBoxes {
    explicit LineOfBoxes(std::uint32_t seed) : random(seed) {}
    btVector3 lo(int i) const { return btVector3(x[std::size_t(i)], 0, 0); }
    btVector3 hi(int i) const { return btVector3(x[std::size_t(i)] + 1, 1, 1); }
    void place(int n) {
        std::uniform_real_distribution<float> at(0, float(n) / 4);
        x.resize(std::size_t(n));
        for (float& v : x) {
            v = at(random);
        }
    }
    int overlapping() const {
        int count = 0;
        for (std::size_t i = 0; i < x.size(); ++i) {
            for (std::size_t j = i + 1; j < x.size(); ++j) {
                count += std::abs(x[i] - x[j]) <= 1 ? 1 : 0;
            }
        }
        return count;
    }
    std::mt19937 random;
    std::vector<float> x;
};

TEST(MergedPairCache, ABroadphaseFlushesItsChangesInItsOwnPairSearch) {
    // The merge is broadphase work: after calculateOverlappingPairs nothing may wait for
    // the dispatcher's first read. A destroyProxy outside the search removes at once.
    for (const char* name : {"sweep", "grid", "segment-trees"}) {
        SCOPED_TRACE(name);
        BroadphaseSettings settings;
        settings.ownPairCache = PairCacheChoice::Merged;
        auto broadphase = makeBroadphase(name, settings);
        auto* cache = dynamic_cast<MergedPairCache*>(broadphase->getOverlappingPairCache());
        ASSERT_NE(cache, nullptr);
        LineOfBoxes boxes(7);
        const int n = 200;
        boxes.place(n);
        std::vector<btBroadphaseProxy*> proxies;
        for (int i = 0; i < n; ++i) {
            proxies.push_back(
                broadphase->createProxy(boxes.lo(i), boxes.hi(i), 0, nullptr, 1, -1, nullptr));
        }
        int seen = 0;
        for (int frame = 0; frame < 20; ++frame) {
            boxes.place(n);
            for (int i = 0; i < n; i += 1 + frame % 3) {
                broadphase->setAabb(proxies[std::size_t(i)], boxes.lo(i), boxes.hi(i), nullptr);
            }
            broadphase->calculateOverlappingPairs(nullptr);
            EXPECT_EQ(cache->pendingChanges(), 0u) << "frame " << frame;
            cache->validate();
            seen += cache->getNumOverlappingPairs();
        }
        EXPECT_GT(seen, 20 * n / 2) << "the frames had pairs";
        btVector3 lo, hi;
        for (int i = 0; i < n; i += 2) {
            broadphase->destroyProxy(proxies[std::size_t(i)], nullptr);
        }
        std::vector<float> left;
        for (int i = 1; i < n; i += 2) {
            broadphase->getAabb(proxies[std::size_t(i)], lo, hi);
            left.push_back(lo.x());
        }
        boxes.x = left;
        EXPECT_EQ(cache->getNumOverlappingPairs(), boxes.overlapping());
        cache->validate();
        EXPECT_EQ(cache->getOverlappingPairArray().size(), boxes.overlapping());
        EXPECT_EQ(cache->pendingChanges(), 0u);
        for (int i = 1; i < n; i += 2) {
            broadphase->destroyProxy(proxies[std::size_t(i)], nullptr);
        }
        EXPECT_EQ(cache->getNumOverlappingPairs(), 0);
    }
}

}  // namespace
}  // namespace kolize
