// The store-only lower bound: a valid btBroadphaseInterface that stores boxes and finds no
// pairs; queries report every live proxy; destroyed slots are reused.

#include <kolize/engine/pair_stream.h>
#include <kolize/engine/store_only.h>

#include <btBulletCollisionCommon.h>
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <stdexcept>
#include <vector>

namespace kolize {
namespace {

struct Collect : btBroadphaseAabbCallback {
    std::set<const btBroadphaseProxy*> seen;
    bool process(const btBroadphaseProxy* proxy) override {
        seen.insert(proxy);
        return true;
    }
};

struct CollectRay : btBroadphaseRayCallback {
    std::set<const btBroadphaseProxy*> seen;
    bool process(const btBroadphaseProxy* proxy) override {
        seen.insert(proxy);
        return true;
    }
};

btBroadphaseProxy* create(btBroadphaseInterface& broadphase, float x) {
    static int client = 0;
    return broadphase.createProxy(btVector3(x, 0, 0), btVector3(x + 1, 1, 1), BOX_SHAPE_PROXYTYPE,
                                  &client, 1, -1, nullptr);
}

TEST(StoreOnly, StoresBoxesFindsNoPairsAndReportsEveryProxyToQueries) {
    StoreOnlyBroadphase broadphase;
    std::vector<btBroadphaseProxy*> proxies;
    for (int i = 0; i < 5; ++i) {
        proxies.push_back(create(broadphase, 0.5f * float(i)));  // all overlap their neighbours
    }
    EXPECT_EQ(broadphase.size(), 5u);
    std::set<int> uids;
    for (btBroadphaseProxy* proxy : proxies) {
        uids.insert(proxy->getUid());
    }
    EXPECT_EQ(uids.size(), 5u) << "unique ids";

    broadphase.setAabb(proxies[2], btVector3(-3, -2, -1), btVector3(4, 5, 6), nullptr);
    btVector3 lo, hi;
    broadphase.getAabb(proxies[2], lo, hi);
    EXPECT_EQ(lo, btVector3(-3, -2, -1));
    EXPECT_EQ(hi, btVector3(4, 5, 6));
    broadphase.getBroadphaseAabb(lo, hi);
    EXPECT_EQ(lo, btVector3(-3, -2, -1));
    EXPECT_EQ(hi, btVector3(4, 5, 6));

    broadphase.calculateOverlappingPairs(nullptr);
    EXPECT_EQ(broadphase.getOverlappingPairCache()->getNumOverlappingPairs(), 0);

    Collect box;
    broadphase.aabbTest(btVector3(100, 100, 100), btVector3(101, 101, 101), box);
    EXPECT_EQ(box.seen, std::set<const btBroadphaseProxy*>(proxies.begin(), proxies.end()));
    CollectRay ray;
    btBroadphaseInterface& base = broadphase;  // the default arguments are the base's
    base.rayTest(btVector3(0, 50, 0), btVector3(1, 50, 0), ray);
    EXPECT_EQ(ray.seen, box.seen);
}

TEST(StoreOnly, DestroyFreesTheSlotForReuseAndRejectsForeignProxies) {
    StoreOnlyBroadphase broadphase;
    btBroadphaseProxy* a = create(broadphase, 0);
    btBroadphaseProxy* b = create(broadphase, 2);
    const int oldUid = a->getUid();
    broadphase.destroyProxy(a, nullptr);
    EXPECT_EQ(broadphase.size(), 1u);
    EXPECT_THROW(broadphase.destroyProxy(a, nullptr), std::invalid_argument);
    btBroadphaseProxy foreign;
    EXPECT_THROW(broadphase.destroyProxy(&foreign, nullptr), std::invalid_argument);

    Collect box;
    broadphase.aabbTest(btVector3(-1, -1, -1), btVector3(9, 9, 9), box);
    EXPECT_EQ(box.seen, std::set<const btBroadphaseProxy*>{b}) << "a destroyed proxy is gone";

    btBroadphaseProxy* c = create(broadphase, 4);
    EXPECT_EQ(c, a) << "the freed slot is reused";
    EXPECT_NE(c->getUid(), oldUid) << "with a new unique id";
    btVector3 lo, hi;
    broadphase.getAabb(c, lo, hi);
    EXPECT_EQ(lo, btVector3(4, 0, 0));
    broadphase.destroyProxy(b, nullptr);
    broadphase.destroyProxy(c, nullptr);
    EXPECT_EQ(broadphase.size(), 0u);
}

TEST(StoreOnly, AddressesStayStableAcrossManyCreates) {
    StoreOnlyBroadphase broadphase;
    btBroadphaseProxy* first = create(broadphase, 7);
    for (int i = 0; i < 5000; ++i) {
        create(broadphase, float(i));
    }
    btVector3 lo, hi;
    broadphase.getAabb(first, lo, hi);
    EXPECT_EQ(lo, btVector3(7, 0, 0));
    EXPECT_EQ(broadphase.size(), 5001u);
}

TEST(StoreOnly, FactoryAndReplayKnowIt) {
    EXPECT_NE(dynamic_cast<StoreOnlyBroadphase*>(makeMeasuredBroadphase("store-only", {}).get()),
              nullptr);
    EXPECT_NE(makeMeasuredBroadphase("dbvt", {}), nullptr);
    EXPECT_THROW(makeMeasuredBroadphase("nonsense", {}), std::invalid_argument);

    // Two overlapping boxes over two frames: the replay times store-only and counts every
    // true pair as missing.
    PairStream stream;
    StreamEvent event;
    event.op = StreamEvent::Op::Create;
    event.group = 1;
    event.mask = -1;
    event.aabbMax[0] = event.aabbMax[1] = event.aabbMax[2] = 1;
    stream.events.push_back(event);
    event.object = 1;
    stream.events.push_back(event);
    stream.events.push_back(StreamEvent{});
    stream.events.push_back(StreamEvent{});
    const ReplayResult result = replay(stream, "store-only");
    ASSERT_EQ(result.frames.size(), 2u);
    EXPECT_EQ(result.frames[0].truePairs, 1u);
    EXPECT_EQ(result.frames[0].reportedPairs, 0u);
    EXPECT_EQ(result.totalMissing(), 2u);
    EXPECT_EQ(result.totalExtra(), 0u);
}

TEST(StoreOnly, ReplayCountsTheFramesAtRest) {
    // Frame 0 creates two boxes; frame 1 repeats both boxes (at rest, as Bullet's updateAabbs
    // sends for sleeping bodies); frame 2 moves one by a float ulp; frame 3 repeats again;
    // frame 4 destroys one.
    PairStream stream;
    StreamEvent create;
    create.op = StreamEvent::Op::Create;
    create.group = 1;
    create.mask = -1;
    create.aabbMax[0] = create.aabbMax[1] = create.aabbMax[2] = 1;
    stream.events.push_back(create);
    create.object = 1;
    stream.events.push_back(create);
    stream.events.push_back(StreamEvent{});
    StreamEvent same = create;
    same.op = StreamEvent::Op::SetAabb;
    for (std::uint32_t object : {0u, 1u}) {
        same.object = object;
        stream.events.push_back(same);
    }
    stream.events.push_back(StreamEvent{});
    StreamEvent moved = same;
    moved.aabbMax[1] = double(std::nextafter(1.0f, 2.0f));
    stream.events.push_back(moved);
    stream.events.push_back(StreamEvent{});
    stream.events.push_back(moved);
    stream.events.push_back(StreamEvent{});
    StreamEvent destroy;
    destroy.op = StreamEvent::Op::Destroy;
    destroy.object = 0;
    stream.events.push_back(destroy);
    stream.events.push_back(StreamEvent{});

    const ReplayResult result = replay(stream, "sweep");
    ASSERT_EQ(result.frames.size(), 5u);
    const std::size_t expected[] = {2, 0, 1, 0, 1};
    for (std::size_t frame = 0; frame < 5; ++frame) {
        EXPECT_EQ(result.frames[frame].changedProxies, expected[frame]) << "frame " << frame;
    }
    EXPECT_EQ(result.restingFrames(), 2u);
    EXPECT_GT(result.medianRestingSeconds(), 0.0);
    EXPECT_EQ(result.frames[3].truePairs, 1u);
    EXPECT_EQ(result.totalMissing(), 0u);
}

}  // namespace
}  // namespace kolize
