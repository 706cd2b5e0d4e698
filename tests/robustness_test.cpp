// Regression tests for what an adversarial Bullet user broke (issue: broadphase robustness):
// nonsense queries, callbacks that re-enter the broadphase, pairs removed by others, far
// rays, memory kept after resetPool, bad settings and foreign proxies. Each test names what
// broke; every kolize broadphase runs each, against a plain brute-force answer.

#include <kolize/broadphase/bullet_adapter.h>
#include <kolize/broadphase/cell_grid.h>
#include <kolize/kolize.h>

#include "ray_callback.h"

#include <LinearMath/btAabbUtil2.h>
#include <btBulletDynamicsCommon.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <vector>

namespace kolize {
namespace {

std::vector<std::string> exactNames() {
    std::vector<std::string> out;
    for (const std::string& name : broadphaseNames()) {
        if (isExactBroadphase(name)) {
            out.push_back(name);
        }
    }
    return out;
}

/// A broadphase with `count` boxes on a lattice (unit boxes, 1.5 apart), pairs computed.
struct Lattice {
    /// Boxes of edge `size` at pitch 1.5: apart for size 1, overlapping their neighbours
    /// for size 2.
    explicit Lattice(const std::string& name, int count = 64, btScalar size = 1)
        : broadphase(makeBroadphase(name)) {
        clients.resize(std::size_t(count) + 1024);
        for (int i = 0; i < count; ++i) {
            const btVector3 lo(btScalar(1.5 * (i % 4)), btScalar(1.5 * (i / 4 % 4)),
                               btScalar(1.5 * (i / 16)));
            add(lo, lo + btVector3(size, size, size));
        }
        broadphase->calculateOverlappingPairs(nullptr);
    }
    btBroadphaseProxy* add(const btVector3& lo, const btVector3& hi) {
        btBroadphaseProxy* proxy =
            broadphase->createProxy(lo, hi, 0, &clients[proxies.size()], 1, -1, nullptr);
        proxies.push_back(proxy);
        boxes.push_back({lo, hi});
        return proxy;
    }
    /// The clients of the proxies (of `alive`) whose boxes overlap lo..hi, by a plain loop.
    std::set<const void*> truth(const btVector3& lo, const btVector3& hi,
                                const std::set<const void*>& dead = {}) const {
        std::set<const void*> out;
        for (std::size_t i = 0; i < proxies.size(); ++i) {
            if (!dead.count(&clients[i]) &&
                TestAabbAgainstAabb2(boxes[i].first, boxes[i].second, lo, hi)) {
                out.insert(&clients[i]);
            }
        }
        return out;
    }
    ~Lattice() {
        for (btBroadphaseProxy* proxy : proxies) {
            if (proxy != nullptr) {
                broadphase->destroyProxy(proxy, nullptr);
            }
        }
    }
    std::unique_ptr<btBroadphaseInterface> broadphase;
    std::vector<btBroadphaseProxy*> proxies;
    std::vector<std::pair<btVector3, btVector3>> boxes;
    std::vector<char> clients;
};

struct AabbCallback : btBroadphaseAabbCallback {
    std::function<void(const btBroadphaseProxy*)> onHit;
    std::vector<const void*> hits;
    bool process(const btBroadphaseProxy* proxy) override {
        hits.push_back(proxy->m_clientObject);
        if (onHit) {
            onHit(proxy);
        }
        return true;
    }
};

/// Collects a ray's hits and calls onHit for each.
struct RayCallback : PreparedRayCallback {
    using PreparedRayCallback::PreparedRayCallback;
    std::function<void(const btBroadphaseProxy*)> onHit;
    std::vector<const void*> hits;
    bool process(const btBroadphaseProxy* proxy) override {
        hits.push_back(proxy->m_clientObject);
        if (onHit) {
            onHit(proxy);
        }
        return true;
    }
};

std::set<const void*> unique(const std::vector<const void*>& hits, bool& repeated) {
    std::set<const void*> out(hits.begin(), hits.end());
    repeated = out.size() != hits.size();
    return out;
}

// Broke: grid read past its cell array (SIGSEGV), spatial-tree and spatial-hash looped for
// ever, the segment trees missed boxes. An inverted box is now empty, on every core.
TEST(RobustQueries, InvertedQueryBoxIsEmptyAndNeitherCrashesNorHangs) {
    for (const std::string& name : exactNames()) {
        SCOPED_TRACE(name);
        Lattice lattice(name);
        AabbCallback inverted;
        lattice.broadphase->aabbTest(btVector3(0, 0, 8), btVector3(10, 10, 0), inverted);
        EXPECT_TRUE(inverted.hits.empty());
        const btScalar nan = std::numeric_limits<btScalar>::quiet_NaN();
        AabbCallback withNan;
        lattice.broadphase->aabbTest(btVector3(nan, 0, 0), btVector3(10, 10, 10), withNan);
        EXPECT_TRUE(withNan.hits.empty());
        RayCallback ray(btVector3(-5, 2, 2), btVector3(20, 2, 2));
        lattice.broadphase->rayTest(btVector3(-5, 2, 2), btVector3(20, 2, 2), ray,
                                    btVector3(1, 1, 1), btVector3(-1, -1, -1));
        EXPECT_TRUE(ray.hits.empty()) << "an inverted swept box is empty too";
        EXPECT_EQ(dynamic_cast<BroadphaseAdapter&>(*lattice.broadphase).stats().emptyQueries, 3u);
        // Sanity: the same queries put right do find boxes.
        AabbCallback upright;
        lattice.broadphase->aabbTest(btVector3(0, 0, 0), btVector3(10, 10, 8), upright);
        EXPECT_EQ(upright.hits.size(), 64u);
    }
}

// Broke: queries with coordinates around 1e30 crashed grid and hung the sparse cells.
TEST(RobustQueries, HugeQueryBoxesAndRaysMatchTheTruth) {
    for (const std::string& name : exactNames()) {
        SCOPED_TRACE(name);
        Lattice lattice(name);
        for (const double big : {1e30, 3e38}) {
            const btScalar b = btScalar(big);
            const btVector3 lo(-b, -b, -b), hi(b, b, b);
            AabbCallback all;
            lattice.broadphase->aabbTest(lo, hi, all);
            bool repeated = false;
            EXPECT_EQ(unique(all.hits, repeated), lattice.truth(lo, hi));
            EXPECT_FALSE(repeated);
            AabbCallback beyond;
            lattice.broadphase->aabbTest(hi * btScalar(0.5), hi, beyond);
            EXPECT_TRUE(beyond.hits.empty());
            RayCallback ray(lo, hi);
            lattice.broadphase->rayTest(lo, hi, ray, btVector3(0, 0, 0), btVector3(0, 0, 0));
            (void)unique(ray.hits, repeated);
            EXPECT_FALSE(repeated);
        }
    }
}

// Broke: a proxy created inside an aabbTest (segment-trees, brute-force) or rayTest (grid,
// spatial-tree, spatial-hash) callback corrupted memory. The query now reports the proxies
// that existed when it began, each once.
TEST(ReentrantQueries, CallbacksThatCreateProxiesSeeTheProxiesOfTheStart) {
    for (const std::string& name : exactNames()) {
        SCOPED_TRACE(name);
        Lattice lattice(name);
        const btVector3 lo(-1, -1, -1), hi(3, 3, 3);
        const std::set<const void*> before = lattice.truth(lo, hi);
        AabbCallback creating;
        creating.onHit = [&](const btBroadphaseProxy*) {
            lattice.add(btVector3(0, 0, 0), btVector3(2, 2, 2));  // overlaps the query
        };
        lattice.broadphase->aabbTest(lo, hi, creating);
        bool repeated = false;
        EXPECT_EQ(unique(creating.hits, repeated), before);
        EXPECT_FALSE(repeated);
        RayCallback ray(btVector3(-5, 0.5, 0.5), btVector3(20, 0.5, 0.5));
        const std::size_t created = lattice.proxies.size();
        ray.onHit = [&](const btBroadphaseProxy*) {
            lattice.add(btVector3(-1, 0, 0), btVector3(9, 1, 1));
        };
        lattice.broadphase->rayTest(btVector3(-5, 0.5, 0.5), btVector3(20, 0.5, 0.5), ray,
                                    btVector3(0, 0, 0), btVector3(0, 0, 0));
        EXPECT_FALSE(ray.hits.empty());
        for (std::size_t i = created; i < lattice.proxies.size(); ++i) {
            EXPECT_EQ(std::count(ray.hits.begin(), ray.hits.end(), &lattice.clients[i]), 0);
        }
        (void)unique(ray.hits, repeated);
        EXPECT_FALSE(repeated);
        dynamic_cast<BroadphaseAdapter&>(*lattice.broadphase).validate();
        lattice.broadphase->calculateOverlappingPairs(nullptr);
        dynamic_cast<BroadphaseAdapter&>(*lattice.broadphase).validate();
    }
}

// Broke: destroying a proxy inside an aabbTest callback made spatial-tree skip 124 of 456
// boxes and range-tree 17. Every other proxy of the start is still reported; the destroyed
// ones are not reported after their destruction.
TEST(ReentrantQueries, CallbacksThatDestroyProxiesDoNotMakeTheQuerySkipOthers) {
    for (const std::string& name : exactNames()) {
        SCOPED_TRACE(name);
        Lattice lattice(name, 456);
        const btVector3 lo(-1, -1, -1), hi(100, 100, 100);
        std::set<const void*> destroyed;
        AabbCallback destroying;
        destroying.onHit = [&](const btBroadphaseProxy* hit) {
            // Destroy the hit one every third time, and some other proxy every fifth.
            const std::size_t index =
                std::size_t(static_cast<const char*>(hit->m_clientObject) - lattice.clients.data());
            const std::size_t victim = destroying.hits.size() % 5 == 0
                                           ? (index * 7 + 3) % lattice.proxies.size()
                                       : destroying.hits.size() % 3 == 0 ? index
                                                                         : SIZE_MAX;
            if (victim != SIZE_MAX && lattice.proxies[victim] != nullptr) {
                lattice.broadphase->destroyProxy(lattice.proxies[victim], nullptr);
                lattice.proxies[victim] = nullptr;
                destroyed.insert(&lattice.clients[victim]);
            }
        };
        const std::set<const void*> all = lattice.truth(lo, hi);
        lattice.broadphase->aabbTest(lo, hi, destroying);
        bool repeated = false;
        const std::set<const void*> reported = unique(destroying.hits, repeated);
        EXPECT_FALSE(repeated);
        for (const void* client : all) {
            EXPECT_TRUE(reported.count(client) || destroyed.count(client))
                << "a proxy alive to the end was skipped";
        }
        EXPECT_GT(destroyed.size(), 100u);
        lattice.broadphase->calculateOverlappingPairs(nullptr);
        dynamic_cast<BroadphaseAdapter&>(*lattice.broadphase).validate();
    }
}

// Broke: a contactTest callback that adds a body per contact corrupted grid's and
// segment-trees' memory (use after free under ASan).
TEST(ReentrantQueries, ContactTestCallbackThatAddsBodies) {
    struct Adding : btCollisionWorld::ContactResultCallback {
        btCollisionWorld* world = nullptr;
        btCollisionShape* shape = nullptr;
        std::vector<std::unique_ptr<btCollisionObject>>* added = nullptr;
        int contacts = 0;
        btScalar addSingleResult(btManifoldPoint&, const btCollisionObjectWrapper*, int, int,
                                 const btCollisionObjectWrapper*, int, int) override {
            ++contacts;
            added->push_back(std::make_unique<btCollisionObject>());
            added->back()->setCollisionShape(shape);
            added->back()->getWorldTransform().setOrigin(btVector3(0.5, 0.5, btScalar(contacts)));
            world->addCollisionObject(added->back().get());
            return 0;
        }
    };
    for (const std::string& name : exactNames()) {
        SCOPED_TRACE(name);
        auto broadphase = makeBroadphase(name);
        btDefaultCollisionConfiguration configuration;
        btCollisionDispatcher dispatcher(&configuration);
        btCollisionWorld world(&dispatcher, broadphase.get(), &configuration);
        btBoxShape shape(btVector3(1, 1, 1));
        std::vector<std::unique_ptr<btCollisionObject>> objects;
        for (int i = 0; i < 20; ++i) {
            objects.push_back(std::make_unique<btCollisionObject>());
            objects.back()->setCollisionShape(&shape);
            objects.back()->getWorldTransform().setOrigin(
                btVector3(btScalar(i % 5), 0, btScalar(i / 5)));
            world.addCollisionObject(objects.back().get());
        }
        world.performDiscreteCollisionDetection();
        Adding adding;
        adding.world = &world;
        adding.shape = &shape;
        adding.added = &objects;
        world.contactTest(objects[7].get(), adding);
        EXPECT_GT(adding.contacts, 0);
        EXPECT_EQ(objects.size(), 20u + std::size_t(adding.contacts));
        world.performDiscreteCollisionDetection();
        dynamic_cast<BroadphaseAdapter&>(*broadphase).validate();
        for (auto& object : objects) {
            world.removeCollisionObject(object.get());
        }
    }
}

// Broke: after removeOverlappingPairsContainingProxy (or a user's removeOverlappingPair) a
// pair whose boxes still overlapped was never found again: a box resting on the ground fell
// through, on every kolize broadphase. The next pair search now adds it again.
TEST(ForeignRemoval, PairsRemovedByOthersAreAddedAgainAtTheNextSearch) {
    for (const std::string& name : exactNames()) {
        SCOPED_TRACE(name);
        Lattice lattice(name, 8, 2);
        btOverlappingPairCache* cache = lattice.broadphase->getOverlappingPairCache();
        const int pairs = cache->getNumOverlappingPairs();
        ASSERT_GT(pairs, 0);
        cache->removeOverlappingPairsContainingProxy(lattice.proxies[0], nullptr);
        cache->removeOverlappingPair(lattice.proxies[5], lattice.proxies[6], nullptr);
        ASSERT_LT(cache->getNumOverlappingPairs(), pairs);
        lattice.broadphase->calculateOverlappingPairs(nullptr);
        EXPECT_EQ(cache->getNumOverlappingPairs(), pairs);
        EXPECT_NE(cache->findPair(lattice.proxies[5], lattice.proxies[6]), nullptr);
        EXPECT_GT(dynamic_cast<BroadphaseAdapter&>(*lattice.broadphase).stats().pairsRestored, 0u);
        dynamic_cast<BroadphaseAdapter&>(*lattice.broadphase).validate();
    }
}

TEST(ForeignRemoval, BoxOnTheGroundStaysUpWhenItsPairIsRemovedEveryStep) {
    for (const std::string& name : exactNames()) {
        SCOPED_TRACE(name);
        auto broadphase = makeBroadphase(name);
        btDefaultCollisionConfiguration configuration;
        btCollisionDispatcher dispatcher(&configuration);
        btSequentialImpulseConstraintSolver solver;
        btDiscreteDynamicsWorld world(&dispatcher, broadphase.get(), &solver, &configuration);
        world.setGravity(btVector3(0, -10, 0));
        btBoxShape groundShape(btVector3(10, 1, 10)), boxShape(btVector3(0.5, 0.5, 0.5));
        btRigidBody ground(0, nullptr, &groundShape);
        ground.getWorldTransform().setOrigin(btVector3(0, -1, 0));
        world.addRigidBody(&ground);
        btVector3 inertia;
        boxShape.calculateLocalInertia(1, inertia);
        btRigidBody box(1, nullptr, &boxShape, inertia);
        box.getWorldTransform().setOrigin(btVector3(0, 0.5, 0));
        box.setActivationState(DISABLE_DEACTIVATION);
        world.addRigidBody(&box);
        for (int step = 0; step < 60; ++step) {
            world.stepSimulation(btScalar(1.0 / 60), 0);
            // As a user's code does it, between steps.
            broadphase->getOverlappingPairCache()->removeOverlappingPairsContainingProxy(
                box.getBroadphaseHandle(), &dispatcher);
        }
        EXPECT_GT(box.getWorldTransform().getOrigin().y(), btScalar(0.3)) << "fell through";
        world.removeRigidBody(&box);
        world.removeRigidBody(&ground);
    }
}

// Broke: the cell broadphases' rayTest missed proxies that Bullet's own ray-box test accepts
// from about 3e7 units out, and rays spanning a static plane's +-1e18 box missed boxes they
// crossed. Checked against btRayAabb2 over every box (Bullet's acceptance).
TEST(FarRays, RaysFromFarAwayReportEveryBoxBulletsTestAccepts) {
    std::mt19937 random(5);
    std::uniform_real_distribution<double> unit(-1, 1);
    for (const std::string& name : exactNames()) {
        SCOPED_TRACE(name);
        Lattice lattice(name, 200);
        lattice.add(btVector3(-1e18f, -1e18f, -1e18f), btVector3(1e18f, btScalar(-10), 1e18f));
        lattice.broadphase->calculateOverlappingPairs(nullptr);
        std::size_t hits = 0;
        for (int r = 0; r < 300; ++r) {
            const double distance = std::pow(10.0, 3 + 15 * (r % 16) / 15.0);  // 1e3 .. 1e18
            btVector3 target(btScalar(3 + 3 * unit(random)), btScalar(3 + 3 * unit(random)),
                             btScalar(7 + 7 * unit(random)));
            btVector3 direction(btScalar(unit(random)), btScalar(unit(random)),
                                btScalar(unit(random)));
            direction.normalize();
            const btVector3 from = target - direction * btScalar(distance);
            const btVector3 to = target + direction * btScalar(r % 3 == 0 ? distance : 20);
            RayCallback ray(from, to);
            lattice.broadphase->rayTest(from, to, ray, btVector3(0, 0, 0), btVector3(0, 0, 0));
            std::set<const void*> expected;
            for (std::size_t i = 0; i < lattice.proxies.size(); ++i) {
                const btVector3 bounds[2] = {lattice.boxes[i].first, lattice.boxes[i].second};
                btScalar lambda;
                if (btRayAabb2(from, ray.m_rayDirectionInverse, ray.m_signs, bounds, lambda, 0,
                               ray.m_lambda_max)) {
                    expected.insert(&lattice.clients[i]);
                }
            }
            bool repeated = false;
            ASSERT_EQ(unique(ray.hits, repeated), expected)
                << "ray " << r << " from " << distance << " away";
            EXPECT_FALSE(repeated);
            hits += expected.size();
        }
        EXPECT_GT(hits, 300u) << "the rays must hit something to mean anything";
    }
}

// Broke: resetPool kept 4-35 MB in the core although the README said it frees all memory.
TEST(ResetPool, FreesTheMemoryOfAdapterAndCore) {
    for (const std::string& name : exactNames()) {
        SCOPED_TRACE(name);
        auto broadphase = makeBroadphase(name);
        auto& adapter = dynamic_cast<BroadphaseAdapter&>(*broadphase);
        static char client;
        std::vector<btBroadphaseProxy*> proxies;
        std::mt19937 random(3);
        std::uniform_real_distribution<double> position(-100, 100);
        for (int i = 0; i < 20000; ++i) {
            const btVector3 lo(btScalar(position(random)), btScalar(position(random)),
                               btScalar(position(random)));
            proxies.push_back(
                broadphase->createProxy(lo, lo + btVector3(3, 3, 3), 0, &client, 1, -1, nullptr));
        }
        broadphase->calculateOverlappingPairs(nullptr);
        const std::size_t full = adapter.stats().memoryBytes;
        broadphase->resetPool(nullptr);  // proxies alive: nothing happens
        EXPECT_EQ(adapter.stats().proxies, 20000u);
        for (btBroadphaseProxy* proxy : proxies) {
            broadphase->destroyProxy(proxy, nullptr);
        }
        broadphase->resetPool(nullptr);
        const std::size_t after = adapter.stats().memoryBytes;
        EXPECT_GT(full, 1000000u);
        EXPECT_LT(after, 4096u) << "kept " << after << " bytes of " << full;
        // Still usable, ids restarted.
        btBroadphaseProxy* again = broadphase->createProxy(btVector3(0, 0, 0), btVector3(1, 1, 1),
                                                           0, &client, 1, -1, nullptr);
        EXPECT_EQ(again->m_uniqueId, 1);
        broadphase->calculateOverlappingPairs(nullptr);
        adapter.validate();
        broadphase->destroyProxy(again, nullptr);
    }
}

// Broke: setAabb with another broadphase's proxy silently moved one of this broadphase's
// own proxies (destroyProxy already refused it).
TEST(ForeignProxies, SetAabbWithAnotherBroadphasesProxyThrows) {
    for (const std::string& name : exactNames()) {
        SCOPED_TRACE(name);
        auto ours = makeBroadphase(name);
        auto other = makeBroadphase("dbvt");
        static char client;
        btBroadphaseProxy* mine =
            ours->createProxy(btVector3(0, 0, 0), btVector3(1, 1, 1), 0, &client, 1, -1, nullptr);
        btBroadphaseProxy* foreign =
            other->createProxy(btVector3(5, 5, 5), btVector3(6, 6, 6), 0, &client, 1, -1, nullptr);
        EXPECT_THROW(ours->setAabb(foreign, btVector3(0, 0, 0), btVector3(1, 1, 1), nullptr),
                     std::invalid_argument);
        btVector3 lo, hi;
        ours->getAabb(mine, lo, hi);
        EXPECT_EQ(lo, btVector3(0, 0, 0));
        EXPECT_EQ(hi, btVector3(1, 1, 1));
        ours->destroyProxy(mine, nullptr);
        other->destroyProxy(foreign, nullptr);
    }
}

// Broke: the factory accepted SAP world bounds with min > max (SAP then found no pairs).
TEST(FactorySettings, RefusesInvertedOrNonFiniteSapWorldBounds) {
    for (const char* name : {"sap", "sap-noray", "sap32"}) {
        BroadphaseSettings inverted;
        inverted.worldMin = btVector3(10, 0, 0);
        inverted.worldMax = btVector3(-10, 10, 10);
        EXPECT_THROW(makeBroadphase(name, inverted), std::invalid_argument) << name;
        BroadphaseSettings infinite;
        infinite.worldMax = btVector3(std::numeric_limits<btScalar>::infinity(), 10, 10);
        EXPECT_THROW(makeBroadphase(name, infinite), std::invalid_argument) << name;
    }
}

// Broke: a bad cell setting's error listed every rule instead of naming the field.
TEST(FactorySettings, BadCellSettingNamesTheField) {
    BroadphaseSettings settings;
    settings.cells.maxCellsPerObject = 0;
    try {
        makeBroadphase("grid", settings);
        FAIL() << "no error";
    } catch (const std::invalid_argument& error) {
        const std::string message = error.what();
        EXPECT_NE(message.find("maxCellsPerObject"), std::string::npos) << message;
        EXPECT_EQ(message.find("sizeFactor"), std::string::npos) << message;
    }
}

// destroyProxy removes only the proxy's own pairs when every pair in the cache is ours, and
// falls back to the cache's full walk when someone else added a pair naming the proxy.
TEST(DestroyProxy, RemovesOwnPairsAndForeignOnesNamingTheProxy) {
    for (const std::string& name : exactNames()) {
        SCOPED_TRACE(name);
        Lattice lattice(name, 16, 2);
        btOverlappingPairCache* cache = lattice.broadphase->getOverlappingPairCache();
        // A pair added by the user between two boxes that do not overlap.
        cache->addOverlappingPair(lattice.proxies[0], lattice.proxies[15]);
        const int before = cache->getNumOverlappingPairs();
        lattice.broadphase->destroyProxy(lattice.proxies[0], nullptr);
        const btBroadphaseProxy* gone = lattice.proxies[0];
        lattice.proxies[0] = nullptr;
        for (int i = 0; i < cache->getNumOverlappingPairs(); ++i) {
            const btBroadphasePair& pair = cache->getOverlappingPairArray()[i];
            EXPECT_TRUE(pair.m_pProxy0 != gone && pair.m_pProxy1 != gone);
        }
        EXPECT_LT(cache->getNumOverlappingPairs(), before);
        lattice.broadphase->calculateOverlappingPairs(nullptr);
        dynamic_cast<BroadphaseAdapter&>(*lattice.broadphase).validate();
    }
}

}  // namespace
}  // namespace kolize
