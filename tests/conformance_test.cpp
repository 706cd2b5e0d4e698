// The conformance kit: one parametrised suite that every broadphase name runs through.
// kolize's broadphases must match the exact truth; Bullet's must report supersets (their
// extra pairs are counted and printed, never failed).

#include <kolize/broadphase/bullet_adapter.h>
#include <kolize/engine/falling_boxes.h>
#include <kolize/engine/pair_compare.h>
#include <kolize/kolize.h>

#include "ray_callback.h"

#include <LinearMath/btAabbUtil2.h>
#include <btBulletDynamicsCommon.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <deque>
#include <map>
#include <random>
#include <set>

namespace kolize {
namespace {

constexpr btScalar kPlane = btScalar(1e18);

/// A kit parameter: a broadphase name, or a kolize broadphase name + "+merged" for one
/// that makes a MergedPairCache instead of Bullet's hashed cache.
constexpr std::string_view kMerged = "+merged";
bool mergedParam(const std::string& param) {
    return param.size() > kMerged.size() &&
           param.compare(param.size() - kMerged.size(), kMerged.size(), kMerged) == 0;
}
std::string baseName(const std::string& param) {
    return mergedParam(param) ? param.substr(0, param.size() - kMerged.size()) : param;
}
std::unique_ptr<btBroadphaseInterface> makeFor(const std::string& param) {
    BroadphaseSettings settings;
    settings.ownPairCache = mergedParam(param) ? PairCacheChoice::Merged : PairCacheChoice::Hashed;
    return makeBroadphase(baseName(param), settings);
}
bool exactFor(const std::string& param) {
    return isExactBroadphase(baseName(param));
}

/// Installed like btGhostPairCallback: sees every add and remove the cache makes.
class PairRecorder : public btOverlappingPairCallback {
  public:
    btBroadphasePair* addOverlappingPair(btBroadphaseProxy* a, btBroadphaseProxy* b) override {
        if (!pairs.insert(uidPair(a, b)).second) {
            ++duplicateAdds;
        }
        return nullptr;
    }
    void* removeOverlappingPair(btBroadphaseProxy* a, btBroadphaseProxy* b,
                                btDispatcher*) override {
        if (pairs.erase(uidPair(a, b)) == 0) {
            ++unknownRemoves;
        }
        return nullptr;
    }
    void removeOverlappingPairsContainingProxy(btBroadphaseProxy* proxy, btDispatcher*) override {
        for (auto it = pairs.begin(); it != pairs.end();) {
            it = (it->first == proxy->m_uniqueId || it->second == proxy->m_uniqueId)
                     ? pairs.erase(it)
                     : std::next(it);
        }
    }
    std::set<UidPair> pairs;
    int duplicateAdds = 0;
    int unknownRemoves = 0;
};

/// A user filter on top of groups and masks: drops pairs whose uid sum is divisible by 5.
class UidSumFilter : public btOverlapFilterCallback {
  public:
    bool needBroadphaseCollision(btBroadphaseProxy* a, btBroadphaseProxy* b) const override {
        const bool groups = (a->m_collisionFilterGroup & b->m_collisionFilterMask) != 0 &&
                            (b->m_collisionFilterGroup & a->m_collisionFilterMask) != 0;
        return groups && (a->m_uniqueId + b->m_uniqueId) % 5 != 0;
    }
};

/// Collects a ray's hits.
struct CollectingRayCallback : PreparedRayCallback {
    using PreparedRayCallback::PreparedRayCallback;
    bool process(const btBroadphaseProxy* proxy) override {
        clients.insert(proxy->m_clientObject);
        return true;
    }
    // By client object, as Bullet's callbacks use them: btAxisSweep3's ray accelerator hands
    // out its internal dbvt proxies, whose ids differ from the SAP handles'.
    std::set<const void*> clients;
};

struct CollectingAabbCallback : btBroadphaseAabbCallback {
    bool process(const btBroadphaseProxy* proxy) override {
        clients.insert(proxy->m_clientObject);
        return true;
    }
    std::set<const void*> clients;
};

struct Counts {
    std::size_t extraPairs = 0;
    std::size_t truePairs = 0;
    std::size_t extraQueryHits = 0;
    std::size_t missedNeverMoved = 0;
    double objectsWithPartner = 0;  // summed over frames, as a fraction of live objects
    int frames = 0;
    int raysHitting = 0;
    int rays = 0;
};

/// Drives one broadphase through seeded random operations and checks it after each frame.
class RandomScene {
  public:
    RandomScene(const std::string& name, std::uint32_t seed, bool userFilter)
        : name_(name), exact_(exactFor(name)), random_(seed) {
        broadphase_ = makeFor(name);
        cache_ = broadphase_->getOverlappingPairCache();
        cache_->setInternalGhostPairCallback(&recorder_);
        if (userFilter) {
            cache_->setOverlapFilterCallback(&filter_);
        }
        adapter_ = dynamic_cast<BroadphaseAdapter*>(broadphase_.get());
    }

    ~RandomScene() {
        // As a world does before deleting its broadphase (dbvt frees proxies only here).
        for (const Object& object : objects_) {
            broadphase_->destroyProxy(object.proxy, nullptr);
        }
    }

    void run(int frames, int initialObjects) {
        for (int i = 0; i < initialObjects; ++i) {
            create();
        }
        for (int frame = 0; frame < frames; ++frame) {
            const int operations = 40;
            for (int op = 0; op < operations; ++op) {
                randomOperation();
                validate();
            }
            broadphase_->calculateOverlappingPairs(nullptr);
            validate();
            checkPairs();
            checkQueries();
            if (::testing::Test::HasFatalFailure()) {
                return;
            }
        }
    }

    const Counts& counts() const { return counts_; }

  private:
    struct Object {
        btBroadphaseProxy* proxy;
        btVector3 aabbMin, aabbMax;
        bool moved = false;  ///< setAabb called since createProxy
    };

    btScalar uniform(double lo, double hi) {
        return btScalar(std::uniform_real_distribution<double>(lo, hi)(random_));
    }
    int pick(int count) { return std::uniform_int_distribution<int>(0, count - 1)(random_); }

    /// A random box: mostly ordinary, plus the shapes that break naive broadphases.
    std::pair<btVector3, btVector3> randomBox() {
        const int kind = pick(100);
        btVector3 centre(uniform(-40, 40), uniform(-40, 40), uniform(-40, 40));
        btVector3 half(uniform(0.2, 4), uniform(0.2, 4), uniform(0.2, 4));
        if (kind < 8 && !objects_.empty()) {  // touching an existing box face to face
            const Object& other = objects_[pick(static_cast<int>(objects_.size()))];
            const int axis = pick(3);
            btVector3 lo = other.aabbMin, hi = other.aabbMax;
            const btScalar size = uniform(0.5, 3);
            lo[axis] = other.aabbMax[axis];
            hi[axis] = other.aabbMax[axis] + size;
            return {lo, hi};
        }
        if (kind < 15) {  // zero extent on one or all axes
            half = kind < 11 ? btVector3(0, 0, 0) : btVector3(half.x(), 0, half.z());
        } else if (kind < 17) {  // huge
            half = btVector3(uniform(20, 100), uniform(20, 100), uniform(20, 100));
        } else if (kind < 19 && planes_ < 2) {  // static plane, as btStaticPlaneShape reports
            ++planes_;
            return {btVector3(-kPlane, -kPlane, -kPlane), btVector3(kPlane, kPlane, kPlane)};
        } else if (kind < 29) {  // far outside any initial bounds
            const btScalar far = uniform(1e4, 1e7);
            centre = btVector3(far * (pick(2) ? 1 : -1), uniform(-1e3, 1e3), far);
            half *= far * btScalar(1e-6) + 1;
        }
        return {centre - half, centre + half};
    }

    void create() {
        const auto [lo, hi] = randomBox();
        const int group = 1 << pick(3);
        const int mask = pick(4) == 0 ? (0x7 & ~group) : -1;
        // Bullet's broadphases skip proxies without a client object, as a world never has them.
        clients_.emplace_back();
        btBroadphaseProxy* proxy = broadphase_->createProxy(lo, hi, BOX_SHAPE_PROXYTYPE,
                                                            &clients_.back(), group, mask, nullptr);
        ASSERT_NE(proxy, nullptr);
        objects_.push_back(Object{proxy, lo, hi, false});
    }

    void destroy(std::size_t index) {
        const Object object = objects_[index];
        const int uid = object.proxy->m_uniqueId;  // the proxy's memory may be freed below
        broadphase_->destroyProxy(object.proxy, nullptr);
        // destroyProxy must take the proxy's pairs out of the cache at once.
        for (const UidPair& pair : cachedPairs(*cache_)) {
            ASSERT_TRUE(pair.first != uid && pair.second != uid)
                << name_ << ": pair of a destroyed proxy left in the cache";
        }
        if (object.aabbMax.x() >= kPlane) {
            --planes_;
        }
        objects_[index] = objects_.back();
        objects_.pop_back();
    }

    void move(std::size_t index, const btVector3& lo, const btVector3& hi) {
        Object& object = objects_[index];
        object.aabbMin = lo;
        object.aabbMax = hi;
        object.moved = true;
        broadphase_->setAabb(object.proxy, lo, hi, nullptr);
    }

    void randomOperation() {
        const int op = pick(100);
        if (op < 10 || objects_.size() < 20) {
            create();
        } else if (op < 18) {
            destroy(pick(static_cast<int>(objects_.size())));
        } else {
            const std::size_t index = pick(static_cast<int>(objects_.size()));
            const Object& object = objects_[index];
            if (object.aabbMax.x() >= kPlane) {
                return;
            }
            if (op < 88) {  // small move
                const btVector3 shift(uniform(-0.5, 0.5), uniform(-0.5, 0.5), uniform(-0.5, 0.5));
                move(index, object.aabbMin + shift, object.aabbMax + shift);
            } else {  // teleport, possibly to a new kind of box
                const auto [lo, hi] = randomBox();
                if (hi.x() >= kPlane) {
                    --planes_;
                    return;
                }
                move(index, lo, hi);
            }
        }
    }

    void validate() {
        if (adapter_ != nullptr) {
            ASSERT_NO_THROW(adapter_->validate());
        }
    }

    std::vector<ProxyBox> liveProxies() const {
        std::vector<ProxyBox> out;
        for (const Object& object : objects_) {
            out.push_back(ProxyBox{object.proxy, object.aabbMin, object.aabbMax});
        }
        return out;
    }

    std::string describe(const UidPair& pair) const {
        std::string out;
        for (const Object& object : objects_) {
            if (object.proxy->m_uniqueId == pair.first || object.proxy->m_uniqueId == pair.second) {
                char line[256];
                std::snprintf(
                    line, sizeof line, " [uid %d: (%g %g %g)-(%g %g %g) group %d mask %d]",
                    object.proxy->m_uniqueId, object.aabbMin.x(), object.aabbMin.y(),
                    object.aabbMin.z(), object.aabbMax.x(), object.aabbMax.y(), object.aabbMax.z(),
                    object.proxy->m_collisionFilterGroup, object.proxy->m_collisionFilterMask);
                out += line;
            }
        }
        return out;
    }

    void checkPairs() {
        const std::vector<UidPair> truth = exactPairs(liveProxies(), cache_);
        const std::vector<UidPair> reported = cachedPairs(*cache_);
        const PairDifference difference = comparePairs(truth, reported);
        ASSERT_TRUE(difference.missing.empty())
            << name_ << ": " << difference.missing.size() << " overlapping pairs missing, first "
            << describe(difference.missing[0]);
        if (exact_) {
            ASSERT_TRUE(difference.extra.empty())
                << name_ << ": " << difference.extra.size() << " extra pairs, first "
                << describe(difference.extra[0]);
        }
        counts_.extraPairs += difference.extra.size();
        counts_.truePairs += truth.size();
        // The ghost callback saw every add and remove exactly once.
        ASSERT_EQ(recorder_.duplicateAdds, 0) << name_;
        ASSERT_EQ(recorder_.unknownRemoves, 0) << name_;
        ASSERT_EQ(std::vector<UidPair>(recorder_.pairs.begin(), recorder_.pairs.end()), reported)
            << name_ << ": ghost callback and cache disagree";

        std::set<int> withPartner;
        std::vector<ProxyBox> finite;
        for (const Object& object : objects_) {
            if (object.aabbMax.x() < kPlane) {
                finite.push_back(ProxyBox{object.proxy, object.aabbMin, object.aabbMax});
            }
        }
        for (const UidPair& pair : exactPairs(finite, nullptr)) {
            withPartner.insert(pair.first);
            withPartner.insert(pair.second);
        }
        counts_.objectsWithPartner += double(withPartner.size()) / double(finite.size());
        ++counts_.frames;
    }

    void checkQueries() {
        for (int query = 0; query < 4; ++query) {
            const auto [lo, hi] = randomBox();
            CollectingAabbCallback boxHits;
            broadphase_->aabbTest(lo, hi, boxHits);
            std::set<const void*> boxTruth;
            for (const Object& object : objects_) {
                if (TestAabbAgainstAabb2(object.aabbMin, object.aabbMax, lo, hi)) {
                    boxTruth.insert(object.proxy->m_clientObject);
                }
            }
            compareQuery("aabbTest", boxTruth, boxHits.clients);

            const btVector3 from(uniform(-60, 60), uniform(-60, 60), uniform(-60, 60));
            btVector3 direction(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1));
            if (query == 0) {
                direction = btVector3(0, 1, 0);  // axis-aligned: infinite inverse components
            }
            const btVector3 to = from + direction.normalized() * uniform(2, 30);
            // Half the rays are convex sweeps of a box around the origin.
            const btVector3 sweep = query % 2
                                        ? btVector3(uniform(0, 2), uniform(0, 2), uniform(0, 2))
                                        : btVector3(0, 0, 0);
            CollectingRayCallback rayHits(from, to);
            broadphase_->rayTest(from, to, rayHits, -sweep, sweep);
            std::set<const void*> rayTruth;
            bool rayHitsFiniteBox = false;
            for (const Object& object : objects_) {
                // Bullet's convention (btDbvt::rayTestInternal): [min - aabbMax, max - aabbMin].
                const btVector3 bounds[2] = {object.aabbMin - sweep, object.aabbMax + sweep};
                btScalar tmin;
                if (btRayAabb2(from, rayHits.m_rayDirectionInverse, rayHits.m_signs, bounds, tmin,
                               0, rayHits.m_lambda_max)) {
                    rayTruth.insert(object.proxy->m_clientObject);
                    rayHitsFiniteBox = rayHitsFiniteBox || object.aabbMax.x() < kPlane;
                }
            }
            compareQuery("rayTest", rayTruth, rayHits.clients);
            counts_.raysHitting += rayHitsFiniteBox ? 1 : 0;
            ++counts_.rays;
        }
    }

    void compareQuery(const char* what, const std::set<const void*>& truth,
                      const std::set<const void*>& reported) {
        std::vector<const void*> missing, extra;
        std::set_difference(truth.begin(), truth.end(), reported.begin(), reported.end(),
                            std::back_inserter(missing));
        if (!exact_) {
            // Known Bullet defect, counted not failed: btAxisSweep3 does not store the box
            // given to createProxy (only setAabb's), so its aabbTest without the ray
            // accelerator misses proxies that never moved since creation.
            const auto neverMoved = [&](const void* client) {
                return std::any_of(objects_.begin(), objects_.end(), [&](const Object& object) {
                    return object.proxy->m_clientObject == client && !object.moved;
                });
            };
            const auto tolerated = std::remove_if(missing.begin(), missing.end(), neverMoved);
            counts_.missedNeverMoved += static_cast<std::size_t>(missing.end() - tolerated);
            missing.erase(tolerated, missing.end());
        }
        std::set_difference(reported.begin(), reported.end(), truth.begin(), truth.end(),
                            std::back_inserter(extra));
        ASSERT_TRUE(missing.empty()) << name_ << " " << what << " missed " << missing.size();
        if (exact_) {
            ASSERT_TRUE(extra.empty())
                << name_ << " " << what << " reported " << extra.size() << " extra";
        }
        counts_.extraQueryHits += extra.size();
    }

    std::string name_;
    bool exact_;
    std::mt19937 random_;
    std::unique_ptr<btBroadphaseInterface> broadphase_;
    btOverlappingPairCache* cache_ = nullptr;
    BroadphaseAdapter* adapter_ = nullptr;
    PairRecorder recorder_;
    UidSumFilter filter_;
    std::vector<Object> objects_;
    int planes_ = 0;
    Counts counts_;
    std::deque<char> clients_;  // one stable, unique address per proxy ever created
};

class Conformance : public ::testing::TestWithParam<std::string> {};

void runRandomScenes(const std::string& name, bool userFilter) {
    Counts total;
    for (std::uint32_t seed : {1u, 2u, 3u}) {
        SCOPED_TRACE("broadphase " + name + ", seed " + std::to_string(seed) +
                     (userFilter ? ", user filter" : ""));
        RandomScene scene(name, seed, userFilter);
        scene.run(/*frames=*/40, /*initialObjects=*/150);
        if (::testing::Test::HasFatalFailure()) {
            return;
        }
        const Counts& counts = scene.counts();
        total.extraPairs += counts.extraPairs;
        total.truePairs += counts.truePairs;
        total.extraQueryHits += counts.extraQueryHits;
        total.missedNeverMoved += counts.missedNeverMoved;
        total.objectsWithPartner += counts.objectsWithPartner;
        total.frames += counts.frames;
        total.raysHitting += counts.raysHitting;
        total.rays += counts.rays;
    }
    // The sample means something: a fair share of objects overlap, and of rays hit.
    const double partnerRate = total.objectsWithPartner / total.frames;
    EXPECT_GT(partnerRate, 0.3) << "random scenes too sparse";
    EXPECT_LT(partnerRate, 0.9) << "random scenes too dense";
    const double hitRate = double(total.raysHitting) / total.rays;
    EXPECT_GT(hitRate, 0.3);
    EXPECT_LT(hitRate, 0.98);
    std::printf(
        "[ %s%s ] true pairs %zu, extra pairs %zu (%.1f%%), extra query hits %zu, query "
        "misses of never-moved proxies %zu, objects with a partner %.0f%%, rays hitting "
        "%.0f%%\n",
        name.c_str(), userFilter ? " + user filter" : "", total.truePairs, total.extraPairs,
        100.0 * double(total.extraPairs) / double(std::max<std::size_t>(total.truePairs, 1)),
        total.extraQueryHits, total.missedNeverMoved, 100 * partnerRate, 100 * hitRate);
    if (exactFor(name)) {
        EXPECT_EQ(total.missedNeverMoved, 0u);
    }
}

TEST_P(Conformance, RandomOperationsMatchTheOracle) {
    runRandomScenes(GetParam(), false);
}

TEST_P(Conformance, RandomOperationsWithUserFilterMatchTheOracle) {
    runRandomScenes(GetParam(), true);
}

TEST_P(Conformance, DestroyRemovesPairsAtOnceAndAddressesAreStable) {
    auto broadphase = makeFor(GetParam());
    btOverlappingPairCache* cache = broadphase->getOverlappingPairCache();
    char clients[2];
    btBroadphaseProxy* a = broadphase->createProxy(btVector3(0, 0, 0), btVector3(1, 1, 1), 0,
                                                   &clients[0], 1, -1, nullptr);
    btBroadphaseProxy* b = broadphase->createProxy(btVector3(1, 1, 1), btVector3(2, 2, 2), 0,
                                                   &clients[1], 1, -1, nullptr);
    broadphase->calculateOverlappingPairs(nullptr);
    ASSERT_EQ(cache->getNumOverlappingPairs(), 1) << "touching boxes overlap";
    const int uidA = a->m_uniqueId;
    broadphase->destroyProxy(b, nullptr);
    EXPECT_EQ(cache->getNumOverlappingPairs(), 0);
    // A's proxy has not moved and kept its id.
    broadphase->calculateOverlappingPairs(nullptr);
    EXPECT_EQ(a->m_uniqueId, uidA);
    if (exactFor(GetParam())) {
        // (btAxisSweep3 fails this: it keeps only boxes given to setAabb, not to createProxy.)
        btVector3 lo, hi;
        broadphase->getAabb(a, lo, hi);
        EXPECT_EQ(lo, btVector3(0, 0, 0));
        EXPECT_EQ(hi, btVector3(1, 1, 1));
    }
    broadphase->destroyProxy(a, nullptr);
}

TEST_P(Conformance, RunsInsideADiscreteDynamicsWorld) {
    FallingBoxesSettings settings;
    settings.layers = 4;
    settings.boxesPerRow = 4;
    for (bool plane : {false, true}) {
        SCOPED_TRACE(plane ? "ground plane" : "ground box");
        settings.groundIsPlane = plane;
        FallingBoxesWorld scene(makeFor(GetParam()), settings);
        btOverlappingPairCache* cache = scene.broadphase().getOverlappingPairCache();
        std::map<UidPair, const btCollisionAlgorithm*> algorithms;
        std::size_t keptAlgorithms = 0;
        std::size_t replacedAlgorithms = 0;
        for (int step = 0; step < 150; ++step) {
            scene.step();
            const PairDifference difference =
                comparePairs(exactPairs(scene.proxyBoxes(), cache), cachedPairs(*cache));
            ASSERT_TRUE(difference.missing.empty()) << "step " << step;
            if (exactFor(GetParam())) {
                ASSERT_TRUE(difference.extra.empty()) << "step " << step;
            }
            // Pairs that persist keep their collision algorithm: pairs are not re-created.
            std::map<UidPair, const btCollisionAlgorithm*> now;
            const btBroadphasePairArray& pairs = cache->getOverlappingPairArray();
            for (int i = 0; i < pairs.size(); ++i) {
                const UidPair key = uidPair(pairs[i].m_pProxy0, pairs[i].m_pProxy1);
                now[key] = pairs[i].m_algorithm;
                const auto before = algorithms.find(key);
                if (before != algorithms.end() && before->second != nullptr) {
                    if (before->second == pairs[i].m_algorithm) {
                        ++keptAlgorithms;
                    } else {
                        ++replacedAlgorithms;
                    }
                }
            }
            algorithms.swap(now);
        }
        EXPECT_GT(keptAlgorithms, 100u) << "the stack should rest with persistent contacts";
        if (exactFor(GetParam())) {
            EXPECT_EQ(replacedAlgorithms, 0u) << "a persisting pair was removed and re-added";
        }
        std::printf(
            "[ %s, %s ] persisting pairs kept their algorithm %zu times, lost it %zu times\n",
            GetParam().c_str(), plane ? "plane" : "box", keptAlgorithms, replacedAlgorithms);
        EXPECT_GT(scene.dispatcher().getNumManifolds(), 16) << "boxes rest on each other";
        for (btRigidBody* body : scene.bodies()) {
            if (body->getInvMass() == 0) {
                continue;
            }
            EXPECT_GT(body->getCenterOfMassPosition().y(), -0.1) << "a box fell through the ground";
        }
        // Removing every dynamic body removes its pairs and frees their algorithms.
        const std::vector<btRigidBody*> bodies = scene.bodies();
        for (btRigidBody* body : bodies) {
            if (body->getInvMass() > 0) {
                scene.removeBody(body);
            }
        }
        EXPECT_EQ(cache->getNumOverlappingPairs(), 0);
        EXPECT_EQ(scene.dispatcher().getNumManifolds(), 0);
    }
}

std::string paramName(const ::testing::TestParamInfo<std::string>& info) {
    std::string out;
    for (char c : info.param) {
        out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
    }
    return out;
}

INSTANTIATE_TEST_SUITE_P(AllBroadphases, Conformance, ::testing::ValuesIn(broadphaseNames()),
                         paramName);

/// kolize's broadphases again, each with a MergedPairCache of its own.
std::vector<std::string> mergedParams() {
    std::vector<std::string> out;
    for (const std::string& name : broadphaseNames()) {
        if (isExactBroadphase(name)) {
            out.push_back(name + std::string(kMerged));
        }
    }
    return out;
}

INSTANTIATE_TEST_SUITE_P(MergedPairCache, Conformance, ::testing::ValuesIn(mergedParams()),
                         paramName);

}  // namespace
}  // namespace kolize
