// The stage planner of the Bullet mesh algorithms (mesh_stages.h): its choices only skip
// work (contacts and bodies bit for bit as with every stage forced on), the sphere stage's
// rule (off for a resting pair, on for apart ones, the 5% boundary, re-armed after 256
// queries), the no-tree path against the tree and against the brute-force reference, the
// counters' identities, the registration API.
#include "kolize/narrowphase/bullet_mesh.h"
#include "kolize/narrowphase/mesh_stages.h"
#include "kolize/narrowphase/reference.h"

#include <btBulletCollisionCommon.h>
#include <btBulletDynamicsCommon.h>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <random>
#include <vector>

namespace {

using kolize::MeshShape;
using kolize::MeshStageSettings;
using kolize::MeshStageStats;
using kolize::StageMode;
using kolize::narrowphase::Index3;
using kolize::narrowphase::TriangleMesh;
using kolize::narrowphase::Vec3;

/// A box [-h, h] whose faces are n x n grids of quads: 12 n^2 outward-wound triangles.
TriangleMesh gridBoxMesh(const Vec3& h, int n, const std::string& name = "grid box") {
    std::vector<Vec3> vertices;
    std::vector<Index3> triangles;
    for (int axis = 0; axis < 3; ++axis) {
        for (int side = -1; side <= 1; side += 2) {
            const int u = (axis + 1) % 3, v = (axis + 2) % 3;
            const std::int32_t first = std::int32_t(vertices.size());
            for (int j = 0; j <= n; ++j) {
                for (int i = 0; i <= n; ++i) {
                    Vec3 p;
                    p[axis] = side * h[axis];
                    p[u] = h[u] * (-1 + 2.0 * i / n);
                    p[v] = h[v] * (-1 + 2.0 * j / n);
                    vertices.push_back(p);
                }
            }
            for (int j = 0; j < n; ++j) {
                for (int i = 0; i < n; ++i) {
                    const std::int32_t a = first + j * (n + 1) + i, b = a + 1, c = a + n + 2,
                                       d = a + n + 1;
                    // (u, v, axis) is right-handed: counter-clockwise in (u, v) faces +axis.
                    if (side > 0) {
                        triangles.push_back({a, b, c});
                        triangles.push_back({a, c, d});
                    } else {
                        triangles.push_back({a, c, b});
                        triangles.push_back({a, d, c});
                    }
                }
            }
        }
    }
    return TriangleMesh(name, vertices, triangles);
}

std::shared_ptr<MeshShape> boxShape(double h, int n = 1) {
    return std::make_shared<MeshShape>(kolize::makeMeshModel(gridBoxMesh(Vec3::Constant(h), n)));
}

btTransform at(double x, double y, double z, double yaw = 0, double roll = 0) {
    btTransform t;
    t.setIdentity();
    t.setOrigin(btVector3(btScalar(x), btScalar(y), btScalar(z)));
    // Turned by `yaw` about z, after `roll` about x.
    t.setRotation(btQuaternion(btVector3(0, 0, 1), btScalar(yaw)) *
                  btQuaternion(btVector3(1, 0, 0), btScalar(roll)));
    return t;
}

void push(std::vector<unsigned char>& bytes, const void* data, std::size_t size) {
    const auto* p = static_cast<const unsigned char*>(data);
    bytes.insert(bytes.end(), p, p + size);
}

void pushVector(std::vector<unsigned char>& bytes, const btVector3& v) {
    for (int k = 0; k < 3; ++k) {  // x, y, z only: the fourth float is padding
        const btScalar value = v[k];
        push(bytes, &value, sizeof value);
    }
}

// ---------------------------------------------------------------------------------------
// A pile: box meshes of 12 and 108 triangles dropped onto a static triangle-mesh floor and a
// static mesh slab, with a convex sphere among them (every algorithm kind).

struct Pile {
    explicit Pile(const MeshStageSettings& stages) {
        kolize::registerNarrowphase(&dispatcher, stages);
        world.setGravity(btVector3(0, 0, -10));
        floorTriangles = std::make_unique<btTriangleMesh>();
        for (int j = -4; j < 4; ++j) {
            for (int i = -4; i < 4; ++i) {
                const btVector3 a(i, j, 0), b(i + 1, j, 0), c(i + 1, j + 1, 0), d(i, j + 1, 0);
                floorTriangles->addTriangle(a, b, c);
                floorTriangles->addTriangle(a, c, d);
            }
        }
        add(std::make_shared<btBvhTriangleMeshShape>(floorTriangles.get(), true), at(0, 0, 0), 0);
        add(boxShape(0.5, 2), at(-2, 0, 0.5), 0);  // a static mesh slab
        const double spots[][2] = {{0, 0}, {0.3, 0.9}, {-0.8, 0.2}, {1.1, -0.4}, {-2, 0.1}};
        for (int i = 0; i < 10; ++i) {
            const double* s = spots[i % 5];
            add(boxShape(0.3, i % 2 == 0 ? 1 : 3),
                at(s[0], s[1], 0.35 + 0.7 * (i / 5) + 0.1 * i, 0.3 * i, 0.05 * i), 1);
        }
        add(std::make_shared<btSphereShape>(btScalar(0.25)), at(0.5, 0.5, 2.5), 1);
    }
    ~Pile() {
        for (int i = world.getNumCollisionObjects() - 1; i >= 0; --i) {
            world.removeCollisionObject(world.getCollisionObjectArray()[i]);
        }
        kolize::releaseNarrowphaseStages(&dispatcher);
    }
    void add(std::shared_ptr<btCollisionShape> shape, const btTransform& transform, btScalar mass) {
        btVector3 inertia(0, 0, 0);
        if (mass > 0) {
            shape->calculateLocalInertia(mass, inertia);
        }
        btRigidBody::btRigidBodyConstructionInfo info(mass, nullptr, shape.get(), inertia);
        info.m_startWorldTransform = transform;
        bodies.push_back(std::make_unique<btRigidBody>(info));
        world.addRigidBody(bodies.back().get());
        shapes.push_back(std::move(shape));
    }
    int indexOf(const btCollisionObject* object) const {
        for (std::size_t i = 0; i < bodies.size(); ++i) {
            if (bodies[i].get() == object) {
                return int(i);
            }
        }
        return -1;
    }
    /// Every manifold point and every body state, as raw bytes.
    std::vector<unsigned char> state() const {
        std::vector<unsigned char> bytes;
        for (int m = 0; m < dispatcher.getNumManifolds(); ++m) {
            const btPersistentManifold* manifold =
                const_cast<btCollisionDispatcher&>(dispatcher).getManifoldByIndexInternal(m);
            const int ids[3] = {indexOf(manifold->getBody0()), indexOf(manifold->getBody1()),
                                manifold->getNumContacts()};
            push(bytes, ids, sizeof ids);
            for (int k = 0; k < manifold->getNumContacts(); ++k) {
                const btManifoldPoint& p = manifold->getContactPoint(k);
                pushVector(bytes, p.m_localPointA);
                pushVector(bytes, p.m_localPointB);
                pushVector(bytes, p.m_positionWorldOnA);
                pushVector(bytes, p.m_positionWorldOnB);
                pushVector(bytes, p.m_normalWorldOnB);
                push(bytes, &p.m_distance1, sizeof p.m_distance1);
                const int shapeIds[4] = {p.m_partId0, p.m_index0, p.m_partId1, p.m_index1};
                push(bytes, shapeIds, sizeof shapeIds);
            }
        }
        for (const auto& body : bodies) {
            const btTransform& t = body->getWorldTransform();
            for (int r = 0; r < 3; ++r) {
                pushVector(bytes, t.getBasis()[r]);
            }
            pushVector(bytes, t.getOrigin());
            pushVector(bytes, body->getLinearVelocity());
            pushVector(bytes, body->getAngularVelocity());
        }
        return bytes;
    }

    btDefaultCollisionConfiguration configuration;
    btCollisionDispatcher dispatcher{&configuration};
    btDbvtBroadphase broadphase;
    btSequentialImpulseConstraintSolver solver;
    btDiscreteDynamicsWorld world{&dispatcher, &broadphase, &solver, &configuration};
    std::unique_ptr<btTriangleMesh> floorTriangles;
    std::vector<std::shared_ptr<btCollisionShape>> shapes;
    std::vector<std::unique_ptr<btRigidBody>> bodies;
};

void expectIdentities(const MeshStageStats& s) {
    const std::uint64_t queries = s.mesh_mesh_queries + s.mesh_scenery_queries;
    EXPECT_EQ(s.object_sphere_tests + s.sphere_skipped_auto + s.sphere_skipped_off, queries);
    EXPECT_EQ(queries - s.object_sphere_rejects, s.tree_queries + s.no_tree_tiny + s.no_tree_off);
    EXPECT_LE(s.object_sphere_rejects, s.object_sphere_tests);
    EXPECT_LE(s.node_sphere_rejects, s.node_sphere_tests);
    EXPECT_LE(s.node_box_rejects, s.node_box_tests);
    EXPECT_LE(s.intersecting_pairs, s.triangle_tests);
    EXPECT_LE(s.sphere_skipping_pairs, s.pairs);
    EXPECT_LE(s.tiny_pairs, s.pairs);
    EXPECT_LE(s.toi_skipped_slow + s.toi_hits, s.toi_calls);
}

TEST(BulletMeshStages, AutoStagesGiveTheContactsOfEveryStageOnBitForBit) {
    Pile automatic{MeshStageSettings()};
    Pile allOn{MeshStageSettings::allOn()};
    MeshStageSettings noneOptional;  // the other extreme: every optional stage off
    noneOptional.sphere_stage = StageMode::kOff;
    noneOptional.tree = StageMode::kOff;
    Pile allOff{noneOptional};
    int framesWithContacts = 0;
    for (int step = 0; step < 240; ++step) {
        automatic.world.stepSimulation(btScalar(1.0 / 60), 0);
        allOn.world.stepSimulation(btScalar(1.0 / 60), 0);
        allOff.world.stepSimulation(btScalar(1.0 / 60), 0);
        const std::vector<unsigned char> reference = allOn.state();
        ASSERT_EQ(automatic.state(), reference) << "step " << step;
        ASSERT_EQ(allOff.state(), reference) << "step " << step;
        int contacts = 0;
        for (int m = 0; m < allOn.dispatcher.getNumManifolds(); ++m) {
            contacts += allOn.dispatcher.getManifoldByIndexInternal(m)->getNumContacts();
        }
        framesWithContacts += contacts > 0;
    }
    EXPECT_GT(framesWithContacts, 150);  // the pile did touch and rest

    // The planner did skip work (else the comparison shows nothing), the forced run none.
    const MeshStageStats a = kolize::narrowphaseStages(&automatic.dispatcher);
    const MeshStageStats on = kolize::narrowphaseStages(&allOn.dispatcher);
    const MeshStageStats off = kolize::narrowphaseStages(&allOff.dispatcher);
    EXPECT_GT(a.sphere_skipped_auto, 0u);
    EXPECT_GT(a.sphere_turned_off, 0u);
    EXPECT_GT(a.no_tree_tiny, 0u);
    EXPECT_GT(a.tree_queries, 0u);  // the 108-triangle boxes keep their trees
    EXPECT_GT(a.mesh_scenery_queries, 0u);
    EXPECT_GT(a.convex_mesh_queries, 0u);
    EXPECT_EQ(on.sphere_skipped_auto + on.sphere_skipped_off + on.no_tree_tiny + on.no_tree_off,
              0u);
    EXPECT_EQ(off.object_sphere_tests + off.tree_queries + off.node_box_tests, 0u);
    EXPECT_EQ(off.sphere_skipped_off, off.mesh_mesh_queries + off.mesh_scenery_queries);
    // Same answers: the same queries, pairs found and contact points.
    for (const MeshStageStats* s : {&on, &off}) {
        EXPECT_EQ(a.mesh_mesh_queries, s->mesh_mesh_queries);
        EXPECT_EQ(a.mesh_scenery_queries, s->mesh_scenery_queries);
        EXPECT_EQ(a.convex_mesh_queries, s->convex_mesh_queries);
        EXPECT_EQ(a.intersecting_pairs, s->intersecting_pairs);
        EXPECT_EQ(a.contacts, s->contacts);
    }
    EXPECT_GT(a.intersecting_pairs, 0u);
    for (const MeshStageStats* s : {&a, &on, &off}) {
        expectIdentities(*s);
    }
}

// ---------------------------------------------------------------------------------------
// One pair in a collision world, one query per performDiscreteCollisionDetection.

struct PairWorld {
    explicit PairWorld(const MeshStageSettings& stages, std::shared_ptr<MeshShape> a,
                       std::shared_ptr<MeshShape> b) {
        kolize::registerNarrowphase(&dispatcher, stages);
        shapes[0] = std::move(a);
        shapes[1] = std::move(b);
        for (int i = 0; i < 2; ++i) {
            objects[i].setCollisionShape(shapes[i].get());
            objects[i].setCollisionFlags(0);
            world.addCollisionObject(&objects[i]);
        }
    }
    ~PairWorld() {
        world.removeCollisionObject(&objects[1]);
        world.removeCollisionObject(&objects[0]);
        kolize::releaseNarrowphaseStages(&dispatcher);
    }
    /// Places the pair and runs one query.
    void query(const btTransform& a, const btTransform& b) {
        objects[0].setWorldTransform(a);
        objects[1].setWorldTransform(b);
        world.performDiscreteCollisionDetection();
    }
    MeshStageStats stats() const { return kolize::narrowphaseStages(&dispatcher); }
    kolize::MeshMeshAlgorithm* algorithm() {
        btBroadphasePair* pair = world.getPairCache()->findPair(objects[0].getBroadphaseHandle(),
                                                                objects[1].getBroadphaseHandle());
        return pair ? dynamic_cast<kolize::MeshMeshAlgorithm*>(pair->m_algorithm) : nullptr;
    }

    btDefaultCollisionConfiguration configuration;
    btCollisionDispatcher dispatcher{&configuration};
    btDbvtBroadphase broadphase;
    btCollisionWorld world{&dispatcher, &broadphase, &configuration};
    std::shared_ptr<MeshShape> shapes[2];
    btCollisionObject objects[2];
};

/// Two unit cubes: resting (one on the other, 0.01 deep) or apart (turned 45 degrees about z
/// and side by side along the diagonal: boxes overlap, spheres do not).
const btTransform kLower = at(0, 0, 0);
const btTransform kResting = at(0, 0, 1.99);
const btTransform kApartA = at(0, 0, 0, M_PI / 4);
const btTransform kApartB = at(2.7, 2.7, 0, M_PI / 4);

TEST(BulletMeshStages, ApartPoseReallyHasOverlappingBoxesAndDisjointSpheres) {
    // The preconditions of the sphere tests below, checked on the shapes themselves.
    const auto cube = boxShape(1);
    const kolize::narrowphase::BoundingSphere& sphere = cube->model().sphere();
    const double distance = (kApartB.getOrigin() - kApartA.getOrigin()).length();
    EXPECT_GT(distance, 2 * sphere.radius);
    btVector3 loA, hiA, loB, hiB;
    cube->getAabb(kApartA, loA, hiA);
    cube->getAabb(kApartB, loB, hiB);
    for (int k = 0; k < 3; ++k) {
        EXPECT_LT(loB[k], hiA[k]);
        EXPECT_LT(loA[k], hiB[k]);
    }
    EXPECT_LT((kResting.getOrigin() - kLower.getOrigin()).length(), 2 * sphere.radius);
}

TEST(BulletMeshStages, SphereStageTurnsOffForARestingPairAndIsReArmedAfter256Queries) {
    PairWorld w(MeshStageSettings(), boxShape(1), boxShape(1));
    for (int q = 1; q <= 64 + 256 + 64 + 10; ++q) {
        w.query(kLower, kResting);
        const MeshStageStats s = w.stats();
        ASSERT_EQ(s.mesh_mesh_queries, std::uint64_t(q));
        ASSERT_EQ(s.pairs, 1u);
        ASSERT_EQ(s.object_sphere_rejects, 0u);
        ASSERT_GT(s.intersecting_pairs, 0u) << "the resting pair touches";
        // 64 measured queries, 256 without the test, 64 measured again, and so on.
        const std::uint64_t tests = q <= 64 ? q : q <= 320 ? 64 : q <= 384 ? q - 256 : 128;
        ASSERT_EQ(s.object_sphere_tests, tests) << "query " << q;
        ASSERT_EQ(s.sphere_skipped_auto, std::uint64_t(q) - tests) << "query " << q;
        ASSERT_EQ(s.sphere_turned_off, std::uint64_t(q < 64 ? 0 : q < 384 ? 1 : 2)) << q;
        ASSERT_EQ(s.sphere_rearmed, std::uint64_t(q < 320 ? 0 : 1)) << "query " << q;
        ASSERT_EQ(s.sphere_skipping_pairs, std::uint64_t(q > 64 ? 1 : 0));
        expectIdentities(s);
    }
}

TEST(BulletMeshStages, SphereStageStaysOnForAnApartPair) {
    PairWorld w(MeshStageSettings(), boxShape(1), boxShape(1));
    for (int q = 1; q <= 300; ++q) {
        w.query(kApartA, kApartB);
    }
    const MeshStageStats s = w.stats();
    EXPECT_EQ(s.mesh_mesh_queries, 300u);
    EXPECT_EQ(s.object_sphere_tests, 300u);
    EXPECT_EQ(s.object_sphere_rejects, 300u);
    EXPECT_EQ(s.sphere_skipped_auto + s.sphere_turned_off, 0u);
    EXPECT_EQ(s.tree_queries + s.no_tree_tiny + s.triangle_tests, 0u);
    expectIdentities(s);
}

/// A pair apart in `apart` of every 64 queries (spread out), resting in the others.
MeshStageStats runMostlyResting(int apart, int queries) {
    PairWorld w(MeshStageSettings(), boxShape(1), boxShape(1));
    for (int q = 0; q < queries; ++q) {
        if (q % 64 < apart) {
            w.query(kApartA, kApartB);
        } else {
            w.query(kLower, kResting);
        }
    }
    return w.stats();
}

TEST(BulletMeshStages, TheFivePercentBoundaryDecides) {
    // 3 of 64 is 4.7%: off after the first window. 4 of 64 is 6.25%: stays on.
    const MeshStageStats three = runMostlyResting(3, 128);
    EXPECT_EQ(three.sphere_turned_off, 1u);
    EXPECT_EQ(three.object_sphere_tests, 64u);
    EXPECT_EQ(three.object_sphere_rejects, 3u);
    EXPECT_EQ(three.sphere_skipped_auto, 64u);
    const MeshStageStats four = runMostlyResting(4, 128);
    EXPECT_EQ(four.sphere_turned_off, 0u);
    EXPECT_EQ(four.object_sphere_tests, 128u);
    EXPECT_EQ(four.object_sphere_rejects, 8u);
    EXPECT_EQ(four.sphere_skipped_auto, 0u);
    expectIdentities(three);
    expectIdentities(four);
}

TEST(BulletMeshStages, ForcedSphereSettingsAreObeyed) {
    MeshStageSettings on;
    on.sphere_stage = StageMode::kOn;
    PairWorld won(on, boxShape(1), boxShape(1));
    MeshStageSettings off;
    off.sphere_stage = StageMode::kOff;
    PairWorld woff(off, boxShape(1), boxShape(1));
    for (int q = 0; q < 100; ++q) {
        won.query(kLower, kResting);
        woff.query(kApartA, kApartB);
    }
    EXPECT_EQ(won.stats().object_sphere_tests, 100u);
    EXPECT_EQ(won.stats().sphere_skipped_auto, 0u);
    // Off: the apart pair (a tiny one: no tree) ends at the root volumes and finds nothing.
    const MeshStageStats s = woff.stats();
    EXPECT_EQ(s.object_sphere_tests, 0u);
    EXPECT_EQ(s.sphere_skipped_off, 100u);
    EXPECT_EQ(s.tree_queries, 0u);
    EXPECT_EQ(s.no_tree_tiny, 100u);
    EXPECT_EQ(s.root_rejects, 100u);
    EXPECT_EQ(s.triangle_tests + s.triangle_box_rejects, 0u);
    EXPECT_EQ(s.intersecting_pairs, 0u);
    expectIdentities(s);
}

// ---------------------------------------------------------------------------------------
// No tree for tiny pairs

/// The contacts of the second of two queries of `a` against `b` at the poses, with `stages`;
/// `stats` counts that query alone.
std::vector<kolize::MeshContact> contactsOf(const MeshStageSettings& stages,
                                            std::shared_ptr<MeshShape> a,
                                            std::shared_ptr<MeshShape> b, const btTransform& pa,
                                            const btTransform& pb, MeshStageStats* stats) {
    PairWorld w(stages, std::move(a), std::move(b));
    w.query(pa, pb);
    kolize::resetNarrowphaseStages(&w.dispatcher);
    w.query(pa, pb);
    *stats = w.stats();
    kolize::MeshMeshAlgorithm* algorithm = w.algorithm();
    return algorithm ? algorithm->lastContacts() : std::vector<kolize::MeshContact>();
}

bool sameBits(const std::vector<kolize::MeshContact>& x,
              const std::vector<kolize::MeshContact>& y) {
    if (x.size() != y.size()) {
        return false;
    }
    for (std::size_t i = 0; i < x.size(); ++i) {
        const kolize::MeshContact& p = x[i];
        const kolize::MeshContact& q = y[i];
        if (std::memcmp(p.point.data(), q.point.data(), sizeof(double) * 3) != 0 ||
            std::memcmp(p.normal.data(), q.normal.data(), sizeof(double) * 3) != 0 ||
            std::memcmp(&p.depth, &q.depth, sizeof(double)) != 0 || p.triangleX != q.triangleX ||
            p.triangleY != q.triangleY || p.partX != q.partX || p.partY != q.partY) {
            return false;
        }
    }
    return true;
}

TEST(BulletMeshStages, TwoTwelveTriangleBoxesTakeTheNoTreePathWithTheTreesContacts) {
    std::mt19937 random(7);
    std::uniform_real_distribution<double> offset(-2.8, 2.8), angle(-M_PI, M_PI);
    int touching = 0;
    for (int trial = 0; trial < 100; ++trial) {
        const btTransform pb =
            at(offset(random), offset(random), offset(random), angle(random), angle(random));
        MeshStageStats tiny, tree;
        const auto direct =
            contactsOf(MeshStageSettings(), boxShape(1), boxShape(1), kLower, pb, &tiny);
        const auto reference =
            contactsOf(MeshStageSettings::allOn(), boxShape(1), boxShape(1), kLower, pb, &tree);
        ASSERT_TRUE(sameBits(direct, reference)) << "seed 7, trial " << trial;
        EXPECT_EQ(tiny.intersecting_pairs, tree.intersecting_pairs) << "trial " << trial;
        EXPECT_EQ(tree.no_tree_tiny, 0u);
        // Never the tree: the spheres, or the root volumes, or every triangle pair directly
        // (or no query at all: the broadphase made no pair).
        EXPECT_EQ(tiny.tree_queries + tiny.node_box_tests + tiny.leaf_pairs, 0u);
        EXPECT_LE(tiny.mesh_mesh_queries, 1u);
        EXPECT_EQ(tiny.no_tree_tiny + tiny.object_sphere_rejects, tiny.mesh_mesh_queries)
            << "trial " << trial;
        if (tiny.intersecting_pairs > 0) {
            EXPECT_EQ(tiny.root_rejects, 0u) << "trial " << trial;
            EXPECT_EQ(tiny.triangle_tests + tiny.triangle_box_rejects, 144u);
        } else if (tiny.root_rejects > 0) {
            EXPECT_EQ(tiny.triangle_tests + tiny.triangle_box_rejects, 0u) << "trial " << trial;
        }
        touching += !reference.empty();
    }
    // A meaningful sample: touching in some poses, apart in others. (Root rejects are rare
    // here, a cube's root OBB having arbitrary axes: ForcedSphereSettingsAreObeyed has them.)
    EXPECT_GT(touching, 20);
    EXPECT_LT(touching, 90);
}

TEST(BulletMeshStages, TheTinyLimitDecidesAndLargerMeshesKeepTheTree) {
    MeshStageSettings limit64;
    limit64.tiny_pair_limit = 64;
    MeshStageSettings limit144;
    limit144.tiny_pair_limit = 144;
    MeshStageStats s;
    contactsOf(limit64, boxShape(1), boxShape(1), kLower, kResting, &s);
    EXPECT_EQ(s.tree_queries, 1u);
    EXPECT_EQ(s.no_tree_tiny, 0u);
    contactsOf(limit144, boxShape(1), boxShape(1), kLower, kResting, &s);
    EXPECT_EQ(s.tree_queries, 0u);
    EXPECT_EQ(s.no_tree_tiny, 1u);
    EXPECT_EQ(s.tiny_pairs, 1u);
    contactsOf(limit144, boxShape(1), boxShape(1, 2), kLower, kResting, &s);  // 12 x 48
    EXPECT_EQ(s.tree_queries, 1u);
    EXPECT_EQ(s.no_tree_tiny, 0u);
}

TEST(BulletMeshStages, NoTreeQueryFindsTheReferencePairs) {
    // The core query without tree against the tree and against the brute-force reference,
    // on meshes of 12 and 108 triangles (the limit is the planner's business, not the query's).
    namespace np = kolize::narrowphase;
    const auto small = kolize::makeMeshModel(gridBoxMesh(Vec3(1, 0.5, 0.7), 1));
    const auto large = kolize::makeMeshModel(gridBoxMesh(Vec3(0.8, 0.8, 0.4), 3));
    std::mt19937 random(11);
    std::uniform_real_distribution<double> offset(-1.5, 1.5), angle(-M_PI, M_PI);
    np::MeshQuery withTree, direct;
    np::QuerySettings treeSettings;
    treeSettings.mode = np::QueryMode::kContacts;
    treeSettings.use_front = true;
    np::QuerySettings directSettings = treeSettings;
    directSettings.use_tree = false;
    int hits = 0;
    for (int trial = 0; trial < 200; ++trial) {
        const np::MeshModel& a = trial % 2 ? *small : *large;
        const np::MeshModel& b = trial % 3 ? *large : *small;
        np::Pose pa, pb;
        pb.translation = Vec3(offset(random), offset(random), offset(random));
        pb.rotation = (Eigen::AngleAxisd(angle(random), Vec3::UnitZ()) *
                       Eigen::AngleAxisd(angle(random), Vec3::UnitX()))
                          .toRotationMatrix();
        const std::vector<np::TrianglePair> reference =
            np::referencePairs(a.mesh(), pa, b.mesh(), pb);
        std::vector<np::TrianglePair> t = withTree.run(a, pa, b, pb, treeSettings).pairs;
        const np::QueryResult& d = direct.run(a, pa, b, pb, directSettings);
        std::vector<np::TrianglePair> dp = d.pairs;
        std::sort(t.begin(), t.end());
        EXPECT_TRUE(std::is_sorted(dp.begin(), dp.end())) << "mesh order";
        EXPECT_EQ(dp, reference) << "seed 11, trial " << trial;
        EXPECT_EQ(t, reference) << "seed 11, trial " << trial;
        EXPECT_EQ(d.counters.bv_tests + d.counters.leaf_pairs, 0u);
        if (d.counters.object_sphere_rejects == 0 && d.counters.root_rejects == 0) {
            EXPECT_EQ(d.counters.triangle_tests + d.counters.triangle_box_rejects,
                      a.mesh().triangleCount() * b.mesh().triangleCount());
        }
        hits += !reference.empty();
    }
    EXPECT_GT(hits, 40);
    EXPECT_LT(hits, 180);
}

TEST(BulletMeshStages, NoObjectSphereQueryFindsTheSamePairs) {
    namespace np = kolize::narrowphase;
    const auto model = kolize::makeMeshModel(gridBoxMesh(Vec3(1, 1, 1), 2));
    np::QuerySettings skip;
    skip.object_spheres = false;
    np::Pose pa, apart, touching;
    apart.translation = Vec3(5, 0, 0);
    touching.translation = Vec3(1.9, 0.3, 0.2);
    const np::QueryResult far = np::meshCollide(*model, pa, *model, apart, skip);
    EXPECT_EQ(far.counters.object_sphere_tests, 0u);
    EXPECT_GT(far.counters.bv_tests + far.counters.node_sphere_tests, 0u);  // went into the tree
    EXPECT_FALSE(far.intersecting);
    std::vector<np::TrianglePair> pairs = np::meshCollide(*model, pa, *model, touching, skip).pairs;
    std::sort(pairs.begin(), pairs.end());
    EXPECT_FALSE(pairs.empty());
    EXPECT_EQ(pairs, np::referencePairs(model->mesh(), pa, model->mesh(), touching));
}

// ---------------------------------------------------------------------------------------
// CCD counters, the API

TEST(BulletMeshStages, TimeOfImpactCallsOfSlowBodiesAreCountedAsSkipped) {
    btDefaultCollisionConfiguration configuration;
    btCollisionDispatcher dispatcher(&configuration);
    kolize::registerNarrowphase(&dispatcher);
    const auto shape = boxShape(0.5);
    btRigidBody::btRigidBodyConstructionInfo info(1, nullptr, shape.get(), btVector3(1, 1, 1));
    btRigidBody moving(info), fixed(info);
    moving.setWorldTransform(at(0, 0, 0));
    moving.setInterpolationWorldTransform(at(0, 0, 0));
    fixed.setWorldTransform(at(3, 0, 0));
    fixed.setInterpolationWorldTransform(at(3, 0, 0));
    btCollisionObjectWrapper w0(nullptr, shape.get(), &moving, moving.getWorldTransform(), -1, -1);
    btCollisionObjectWrapper w1(nullptr, shape.get(), &fixed, fixed.getWorldTransform(), -1, -1);
    btCollisionAlgorithm* algorithm =
        dispatcher.findAlgorithm(&w0, &w1, nullptr, BT_CONTACT_POINT_ALGORITHMS);
    ASSERT_NE(dynamic_cast<kolize::MeshMeshAlgorithm*>(algorithm), nullptr);
    btDispatcherInfo dispatchInfo;
    EXPECT_EQ(algorithm->calculateTimeOfImpact(&moving, &fixed, dispatchInfo, nullptr), 1);
    MeshStageStats s = kolize::narrowphaseStages(&dispatcher);
    EXPECT_EQ(s.toi_calls, 1u);
    EXPECT_EQ(s.toi_skipped_slow, 1u);
    // Fast: through the other box within the step.
    moving.setCcdMotionThreshold(0.1f);
    moving.setInterpolationWorldTransform(at(6, 0, 0));
    EXPECT_LT(algorithm->calculateTimeOfImpact(&moving, &fixed, dispatchInfo, nullptr), 0.5);
    s = kolize::narrowphaseStages(&dispatcher);
    EXPECT_EQ(s.toi_calls, 2u);
    EXPECT_EQ(s.toi_skipped_slow, 1u);
    EXPECT_EQ(s.toi_hits, 1u);
    algorithm->~btCollisionAlgorithm();
    dispatcher.freeCollisionAlgorithm(algorithm);
    kolize::releaseNarrowphaseStages(&dispatcher);
}

TEST(BulletMeshStages, OneArgumentRegistrationRunsTheDefaultPlanner) {
    Pile pile{MeshStageSettings()};
    kolize::registerNarrowphase(&pile.dispatcher);  // again, one argument: defaults, zeroed
    for (int step = 0; step < 120; ++step) {
        pile.world.stepSimulation(btScalar(1.0 / 60), 0);
    }
    const MeshStageStats s = kolize::narrowphaseStages(&pile.dispatcher);
    EXPECT_EQ(s.settings.sphere_stage, StageMode::kAuto);
    EXPECT_EQ(s.settings.tree, StageMode::kAuto);
    EXPECT_EQ(s.settings.sphere_window, 64);
    EXPECT_EQ(s.settings.sphere_rearm_after, 256);
    EXPECT_EQ(s.settings.tiny_pair_limit, MeshStageSettings().tiny_pair_limit);
    EXPECT_EQ(s.settings.contact_margin, 0.0);
    EXPECT_EQ(s.near_pairs, 0u);
    EXPECT_GT(s.mesh_mesh_queries, 0u);
    EXPECT_GT(s.no_tree_tiny, 0u);
    expectIdentities(s);
    // Reset: zero, and pairs are counted again once they query.
    kolize::resetNarrowphaseStages(&pile.dispatcher);
    const MeshStageStats zero = kolize::narrowphaseStages(&pile.dispatcher);
    EXPECT_EQ(zero.mesh_mesh_queries + zero.pairs + zero.triangle_tests + zero.contacts, 0u);
    pile.world.stepSimulation(btScalar(1.0 / 60), 0);
    const MeshStageStats one = kolize::narrowphaseStages(&pile.dispatcher);
    EXPECT_GT(one.pairs, 0u);
    EXPECT_LE(one.pairs, one.mesh_mesh_queries + one.mesh_scenery_queries);
    // Registering with other settings applies to the existing pairs too.
    MeshStageSettings off;
    off.tree = StageMode::kOff;
    kolize::registerNarrowphase(&pile.dispatcher, off);
    pile.world.stepSimulation(btScalar(1.0 / 60), 0);
    const MeshStageStats forced = kolize::narrowphaseStages(&pile.dispatcher);
    EXPECT_EQ(forced.tree_queries, 0u);
    EXPECT_GT(forced.no_tree_off, 0u);
}

TEST(BulletMeshStages, BadSettingsAndUnknownDispatchersAreRefused) {
    btDefaultCollisionConfiguration configuration;
    btCollisionDispatcher dispatcher(&configuration);
    EXPECT_THROW(kolize::narrowphaseStages(&dispatcher), std::invalid_argument);
    EXPECT_THROW(kolize::resetNarrowphaseStages(&dispatcher), std::invalid_argument);
    auto refused = [&](MeshStageSettings s, const char* field) {
        try {
            kolize::registerNarrowphase(&dispatcher, s);
            ADD_FAILURE() << field << " accepted";
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
        }
        // Nothing registered: no entry, and Bullet's own table for mesh pairs.
        EXPECT_THROW(kolize::narrowphaseStages(&dispatcher), std::invalid_argument);
    };
    MeshStageSettings s;
    s.sphere_window = 0;
    refused(s, "sphere_window");
    s = MeshStageSettings();
    s.sphere_min_reject_share = std::nan("");
    refused(s, "sphere_min_reject_share");
    s = MeshStageSettings();
    s.sphere_rearm_after = -1;
    refused(s, "sphere_rearm_after");
    s = MeshStageSettings();
    s.tiny_pair_limit = -5;
    refused(s, "tiny_pair_limit");
    kolize::registerNarrowphase(&dispatcher);
    EXPECT_NO_THROW(kolize::narrowphaseStages(&dispatcher));
    kolize::releaseNarrowphaseStages(&dispatcher);
    EXPECT_THROW(kolize::narrowphaseStages(&dispatcher), std::invalid_argument);
}

TEST(BulletMeshStages, DescribeStagesSaysWhatRanAndWhy) {
    PairWorld w(MeshStageSettings(), boxShape(1), boxShape(1));
    for (int q = 0; q < 64 + 256; ++q) {
        w.query(kLower, kResting);
    }
    const std::string text = kolize::describeStages(w.stats());
    EXPECT_NE(text.find("sphere stage (auto): 64 tests, 0 rejected (0.0%); skipped in 256 "
                        "queries of 1 of 1 pairs (rejected under 5.0% of 64 queries in a row; "
                        "turned off 1 times, re-armed 1 times after 256 queries)"),
              std::string::npos)
        << text;
    EXPECT_NE(text.find("skipped in 320 queries of 1 pairs (tiny: triangles(A) * triangles(B) "
                        "<= 144: the root volumes tested, 0 of them apart, then every triangle "
                        "pair directly)"),
              std::string::npos)
        << text;
    EXPECT_NE(text.find("320 mesh-mesh"), std::string::npos) << text;
}

}  // namespace
