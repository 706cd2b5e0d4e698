// The query's behaviour beyond its answers: settings and their defaults, the traversal
// front, no allocation in steady state, the facing filter, bad poses.
#include "query_fixture.h"

#include <atomic>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <cstdlib>
#include <new>

namespace {

std::atomic<long> allocations{0};

}  // namespace

// Counts every allocation of this test program (the tests below read the difference).
void* operator new(std::size_t size) {
    ++allocations;
    if (void* p = std::malloc(size == 0 ? 1 : size)) {
        return p;
    }
    throw std::bad_alloc();
}
void operator delete(void* p) noexcept {
    std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
    std::free(p);
}

namespace {

using namespace kolize::narrowphase;
using namespace kolize::narrowphase::testing;
namespace workload = kolize::workload;

struct Scene {
    workload::WorkloadMesh torus = workload::torus(48, 24, 0.3);
    workload::WorkloadMesh sphere = workload::uvSphere(24, 48);
    MeshModel torusModel{torus.mesh};
    MeshModel sphereModel{sphere.mesh};
};

const Scene& scene() {
    static const Scene s;
    return s;
}

std::vector<workload::WorkloadPose> deepPoses(int count, std::uint32_t seed) {
    const Scene& s = scene();
    return workload::makePoses(s.torus, s.torusModel, s.sphere, s.sphereModel,
                               workload::PoseClass::kDeep, count, seed);
}

TEST(MeshQuery, DefaultsAreTheDocumentedOnes) {
    const QuerySettings q;
    EXPECT_EQ(q.mode, QueryMode::kAllPairs);
    EXPECT_TRUE(q.sphere_pretest);
    EXPECT_EQ(q.descent, Descent::kBoth);
    EXPECT_FALSE(q.use_front);
    EXPECT_FALSE(q.facing_filter);
    EXPECT_EQ(q.margin, 0.0);
    const TreeSettings t;
    EXPECT_EQ(t.kind, TreeKind::kObb);
    EXPECT_EQ(t.leaf_size, 4);
}

TEST(MeshQuery, EverySettingGivesTheSameAnswer) {
    const Scene& s = scene();
    MeshQuery query;
    for (const workload::WorkloadPose& p : deepPoses(scaled(6), 1901)) {
        const auto reference = referencePairs(*s.torus.mesh, p.a, *s.sphere.mesh, p.b);
        ASSERT_FALSE(reference.empty());
        for (bool spheres : {true, false}) {
            for (Descent descent : {Descent::kBoth, Descent::kLarger, Descent::kFirstThenSecond}) {
                QuerySettings settings;
                settings.sphere_pretest = spheres;
                settings.descent = descent;
                std::vector<TrianglePair> got =
                    query.run(s.torusModel, p.a, s.sphereModel, p.b, settings).pairs;
                std::sort(got.begin(), got.end());
                EXPECT_EQ(got, reference) << "spheres " << spheres << " descent " << int(descent);
                EXPECT_EQ(query.result().counters.pairs, reference.size());
                EXPECT_EQ(query.result().counters.node_sphere_tests > 0, spheres);
            }
        }
    }
}

TEST(MeshQuery, CountersAddUp) {
    const Scene& s = scene();
    MeshQuery query;
    const workload::WorkloadPose p = deepPoses(1, 1902)[0];
    const QueryCounters& c = query.run(s.torusModel, p.a, s.sphereModel, p.b).counters;
    EXPECT_EQ(c.object_sphere_tests, 1u);
    EXPECT_EQ(c.node_sphere_tests, c.node_sphere_rejects + c.bv_tests);
    EXPECT_GT(c.bv_rejects, 0u);
    EXPECT_GT(c.leaf_pairs, 0u);
    EXPECT_GE(c.triangle_tests, c.pairs);
    EXPECT_GT(c.triangle_box_rejects, 0u);
    EXPECT_GT(c.predicates.orient3d[0], 0u);
    EXPECT_GT(c.vertices_transformed, 0u);
    EXPECT_LT(c.vertices_transformed, s.sphere.mesh->vertices().size());
}

TEST(MeshQuery, FrontRestartsGiveTheSameAnswerWithFewerTests) {
    const Scene& s = scene();
    MeshQuery query;
    QuerySettings settings;
    settings.use_front = true;
    int fewer = 0, runs = 0;
    for (const workload::WorkloadPose& p : deepPoses(scaled(4), 1903)) {
        query.resetFront();
        Pose pb = p.b;
        std::uint64_t rootTests = 0;
        for (int frame = 0; frame < 6; ++frame) {
            pb.translation.x() += 1e-3;  // slow motion
            const QueryResult& r = query.run(s.torusModel, p.a, s.sphereModel, pb, settings);
            std::vector<TrianglePair> got = r.pairs;
            std::sort(got.begin(), got.end());
            EXPECT_EQ(got, referencePairs(*s.torus.mesh, p.a, *s.sphere.mesh, pb))
                << "frame " << frame;
            const std::uint64_t tests = r.counters.node_sphere_tests + r.counters.bv_tests;
            if (frame == 0) {
                EXPECT_FALSE(r.counters.started_from_front);
                rootTests = tests;
            } else {
                EXPECT_TRUE(r.counters.started_from_front || query.frontSize() == 0);
                ++runs;
                fewer += tests < rootTests;
            }
            EXPECT_GT(query.frontSize(), 0u);
        }
    }
    EXPECT_GT(fewer, runs / 2);
    // Yes/no queries do not keep a front.
    settings.mode = QueryMode::kYesNo;
    const workload::WorkloadPose p = deepPoses(1, 1904)[0];
    query.run(s.torusModel, p.a, s.sphereModel, p.b, settings);
    EXPECT_EQ(query.frontSize(), 0u);
}

TEST(MeshQuery, SteadyStateQueriesDoNotAllocate) {
    const Scene& s = scene();
    const std::vector<workload::WorkloadPose> poses = deepPoses(3, 1905);
    for (QueryMode mode : {QueryMode::kYesNo, QueryMode::kAllPairs, QueryMode::kContacts}) {
        for (bool front : {false, true}) {
            MeshQuery query;
            QuerySettings settings;
            settings.mode = mode;
            settings.use_front = front;
            // Warm-up: grow every buffer. Fronts carried from pose to pose reach their
            // largest sizes only after a few cycles.
            for (int round = 0; round < 3; ++round) {
                for (const workload::WorkloadPose& p : poses) {
                    query.run(s.torusModel, p.a, s.sphereModel, p.b, settings);
                }
            }
            const long before = allocations.load();
            for (int round = 0; round < 2; ++round) {
                for (const workload::WorkloadPose& p : poses) {
                    query.run(s.torusModel, p.a, s.sphereModel, p.b, settings);
                }
            }
            EXPECT_EQ(allocations.load() - before, 0) << "mode " << int(mode) << " front " << front;
        }
    }
    // The sample means something: the counter does count.
    const long before = allocations.load();
    MeshQuery fresh;
    fresh.run(s.torusModel, poses[0].a, s.sphereModel, poses[0].b);
    EXPECT_GT(allocations.load() - before, 0);
}

TEST(MeshQuery, FacingFilterIsOffByDefaultAndItsMissesAreCounted) {
    const Scene& s = scene();
    MeshQuery query;
    std::size_t missed = 0, culled = 0, total = 0;
    for (const workload::WorkloadPose& p : deepPoses(scaled(6), 1906)) {
        const auto reference = referencePairs(*s.torus.mesh, p.a, *s.sphere.mesh, p.b);
        EXPECT_EQ(query.run(s.torusModel, p.a, s.sphereModel, p.b).counters.facing_culled, 0u);
        QuerySettings settings;
        settings.facing_filter = true;
        // B moves towards A: its motion in A's frame points from B's centre to A's.
        const RelativePose bInA(p.a, p.b);
        settings.motion = -(bInA.apply(s.sphere.center) - s.torus.center);
        std::vector<TrianglePair> got =
            query.run(s.torusModel, p.a, s.sphereModel, p.b, settings).pairs;
        std::sort(got.begin(), got.end());
        // The filter only removes: what it reports is true, what it misses is counted.
        EXPECT_TRUE(std::includes(reference.begin(), reference.end(), got.begin(), got.end()));
        missed += reference.size() - got.size();
        culled += query.result().counters.facing_culled;
        total += reference.size();
    }
    EXPECT_GT(culled, 0u);
    EXPECT_GT(missed, 0u) << "the filter is unsafe by design; this sample should show it";
    EXPECT_LT(missed, total);
}

TEST(MeshQuery, RejectsMixedKindsAndBadPoses) {
    const Scene& s = scene();
    const MeshModel aabb(s.sphere.mesh, {TreeKind::kAabb, 4});
    MeshQuery query;
    try {
        query.run(s.torusModel, Pose{}, aabb, Pose{});
        FAIL() << "mixed kinds accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_EQ(std::string(e.what()),
                  "mesh query: 'torus-48x24' has a obb tree and 'uv-sphere-24x48' a aabb "
                  "tree; both must be of one kind");
    }
    Pose scaledPose;
    scaledPose.rotation *= 1.01;
    EXPECT_THROW(query.run(s.torusModel, scaledPose, s.sphereModel, Pose{}), std::invalid_argument);
    Pose nan;
    nan.translation.x() = std::nan("");
    EXPECT_THROW(query.run(s.torusModel, Pose{}, s.sphereModel, nan), std::invalid_argument);
}

TEST(MeshQuery, ContactGeometryLiesOnBothTriangles) {
    const Scene& s = scene();
    MeshQuery query;
    QuerySettings settings;
    settings.mode = QueryMode::kContacts;
    const workload::WorkloadPose p = deepPoses(1, 1907)[0];
    const QueryResult& r = query.run(s.torusModel, p.a, s.sphereModel, p.b, settings);
    ASSERT_FALSE(r.contacts.empty());
    const RelativePose bInA(p.a, p.b);
    for (const PairContact& c : r.contacts) {
        const Triangle ta = s.torus.mesh->triangle(c.pair.a);
        Triangle tb = s.sphere.mesh->triangle(c.pair.b);
        for (Vec3& x : tb) {
            x = bInA.apply(x);
        }
        EXPECT_NEAR(c.normal_a.norm(), 1.0, 1e-12);
        EXPECT_NEAR(c.normal_b.norm(), 1.0, 1e-12);
        for (int k = 0; k < c.geometry.count; ++k) {
            const Vec3& x = c.geometry.points[k];
            EXPECT_NEAR(c.normal_a.dot(x - ta[0]), 0.0, 1e-9);
            EXPECT_NEAR(c.normal_b.dot(x - tb[0]), 0.0, 1e-9);
        }
    }
}

// The contact margin: the near pairs of every tree kind that takes one, with and without
// tree and front, are exactly the plain all-pairs reference's (referenceNearPairs), at poses
// just apart, just inside and farther apart; the intersecting pairs stay the exact ones.
TEST(MeshQuery, MarginReportsTheNearPairsOfTheBruteForce) {
    const Scene& s = scene();
    const MeshModel torusAabb(s.torus.mesh, TreeSettings{TreeKind::kAabb, 4});
    const MeshModel sphereAabb(s.sphere.mesh, TreeSettings{TreeKind::kAabb, 4});
    const MeshModel torusSphere(s.torus.mesh, TreeSettings{TreeKind::kSphere, 2});
    const MeshModel sphereSphere(s.sphere.mesh, TreeSettings{TreeKind::kSphere, 2});
    struct Kind {
        const char* name;
        const MeshModel& a;
        const MeshModel& b;
    };
    const Kind kinds[] = {{"obb", s.torusModel, s.sphereModel},
                          {"aabb", torusAabb, sphereAabb},
                          {"sphere", torusSphere, sphereSphere}};
    std::size_t nearSeen = 0, onlyNear = 0, touching = 0, poses = 0;
    std::uint32_t seed = 1931;
    for (workload::PoseClass kind :
         {workload::PoseClass::kNear, workload::PoseClass::kShallow, workload::PoseClass::kApart}) {
        for (const workload::WorkloadPose& p : workload::makePoses(
                 s.torus, s.torusModel, s.sphere, s.sphereModel, kind, scaled(3), seed++)) {
            ++poses;
            const auto pairs = referencePairs(*s.torus.mesh, p.a, *s.sphere.mesh, p.b);
            for (double margin : {0.004, 0.03}) {
                // Near pairs only while no pair intersects.
                const auto near = pairs.empty() ? referenceNearPairs(*s.torus.mesh, p.a,
                                                                     *s.sphere.mesh, p.b, margin)
                                                : std::vector<TrianglePair>();
                nearSeen += near.size();
                onlyNear += !near.empty() ? 1 : 0;
                touching += pairs.empty() ? 0 : 1;
                for (const Kind& k : kinds) {
                    for (int variant = 0; variant < 3; ++variant) {  // tree, tree twice, none
                        if (variant == 2 && k.name != kinds[0].name) {
                            continue;
                        }
                        MeshQuery query;
                        QuerySettings settings;
                        settings.mode = QueryMode::kContacts;
                        settings.margin = margin;
                        settings.use_front = variant == 1;
                        settings.use_tree = variant != 2;
                        const QueryResult* r = &query.run(k.a, p.a, k.b, p.b, settings);
                        if (variant == 1) {  // the second query starts from the front
                            r = &query.run(k.a, p.a, k.b, p.b, settings);
                            EXPECT_TRUE(r->counters.started_from_front || near.empty());
                        }
                        std::vector<TrianglePair> gotPairs = r->pairs, gotNear;
                        for (const NearPair& n : r->near) {
                            gotNear.push_back(n.pair);
                            EXPECT_LE(n.distance, margin);
                            EXPECT_GE(n.distance, 0.0);
                            EXPECT_NEAR((n.on_b - n.on_a).norm(), n.distance, 1e-12);
                        }
                        std::sort(gotPairs.begin(), gotPairs.end());
                        std::sort(gotNear.begin(), gotNear.end());
                        const std::string where =
                            std::string(k.name) + " variant " + std::to_string(variant) +
                            " margin " + std::to_string(margin) + " class " +
                            workload::poseClassName(kind) + " seed " + std::to_string(seed - 1);
                        EXPECT_EQ(gotPairs, pairs) << where;
                        EXPECT_EQ(gotNear, near) << where;
                        EXPECT_EQ(r->counters.near_pairs, near.size()) << where;
                    }
                }
            }
        }
    }
    // The sample means something: near pairs at poses apart, and poses that intersect (whose
    // near pairs must be dropped).
    EXPECT_GT(nearSeen, 100u) << poses << " poses";
    EXPECT_GT(onlyNear, 0u);
    EXPECT_GT(touching, 0u);
}

TEST(MeshQuery, MarginOnlyInContactsModeAndRefusedWhenBad) {
    const Scene& s = scene();
    const workload::WorkloadPose p = workload::makePoses(
        s.torus, s.torusModel, s.sphere, s.sphereModel, workload::PoseClass::kNear, 1, 1941)[0];
    MeshQuery query;
    QuerySettings settings;
    settings.margin = 0.05;
    settings.mode = QueryMode::kContacts;
    ASSERT_FALSE(query.run(s.torusModel, p.a, s.sphereModel, p.b, settings).near.empty());
    settings.mode = QueryMode::kAllPairs;
    EXPECT_TRUE(query.run(s.torusModel, p.a, s.sphereModel, p.b, settings).near.empty());
    settings.mode = QueryMode::kContacts;
    for (double bad : {-1e-9, std::nan(""), std::numeric_limits<double>::infinity()}) {
        settings.margin = bad;
        EXPECT_THROW(query.run(s.torusModel, p.a, s.sphereModel, p.b, settings),
                     std::invalid_argument)
            << bad;
    }
    const MeshModel torusKdop(s.torus.mesh, TreeSettings{TreeKind::kKdop14, 4});
    const MeshModel sphereKdop(s.sphere.mesh, TreeSettings{TreeKind::kKdop14, 4});
    settings.margin = 0.01;
    EXPECT_THROW(query.run(torusKdop, p.a, sphereKdop, p.b, settings), std::invalid_argument);
    settings.margin = 0;
    EXPECT_NO_THROW(query.run(torusKdop, p.a, sphereKdop, p.b, settings));
}

}  // namespace
