// The narrowphase's Bullet adapter (bullet_mesh.h): the shape, the registration in both
// dispatch tables, exact contacts on a stack of box meshes and on a triangulated floor, bad
// input, determinism. References are independent of the adapter: Bullet's own box inertia,
// brute-force triangle boxes, and the analytic contact geometry of axis-aligned stacks.
#include "../box_mesh.h"
#include "kolize/narrowphase/bullet_mesh.h"
#include "kolize/narrowphase/mesh_query.h"
#include "kolize/narrowphase/mesh_stages.h"

#include <BulletCollision/CollisionShapes/btHeightfieldTerrainShape.h>
#include <BulletCollision/CollisionShapes/btMultimaterialTriangleMeshShape.h>
#include <BulletCollision/CollisionShapes/btTriangleIndexVertexMaterialArray.h>
#include <btBulletCollisionCommon.h>
#include <btBulletDynamicsCommon.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <random>
#include <set>
#include <string>
#include <vector>

namespace {

using kolize::MeshShape;
using kolize::narrowphase::Index3;
using kolize::narrowphase::MeshError;
using kolize::narrowphase::TriangleMesh;
using kolize::narrowphase::Vec3;

using kolize::testing::boxMesh;
using kolize::testing::gridMesh;

std::shared_ptr<MeshShape> boxShape(const Vec3& h) {
    return std::make_shared<MeshShape>(kolize::makeMeshModel(boxMesh(h)));
}

/// A dispatcher that shows its dispatch tables.
class InspectDispatcher : public btCollisionDispatcher {
  public:
    using btCollisionDispatcher::btCollisionDispatcher;
    btCollisionAlgorithmCreateFunc* contactFunc(int a, int b) const {
        return m_doubleDispatchContactPoints[a][b];
    }
    btCollisionAlgorithmCreateFunc* closestFunc(int a, int b) const {
        return m_doubleDispatchClosestPoints[a][b];
    }
};

/// A dynamics world with kolize's narrowphase registered (or not).
struct World {
    explicit World(bool registerKolize = true) {
        if (registerKolize) {
            kolize::registerNarrowphase(&dispatcher);
        }
        world.setGravity(btVector3(0, 0, -10));
    }
    ~World() {
        for (int i = world.getNumCollisionObjects() - 1; i >= 0; --i) {
            btCollisionObject* object = world.getCollisionObjectArray()[i];
            world.removeCollisionObject(object);
        }
    }
    btRigidBody* add(std::shared_ptr<btCollisionShape> shape, const btTransform& transform,
                     btScalar mass) {
        btVector3 inertia(0, 0, 0);
        if (mass > 0) {
            shape->calculateLocalInertia(mass, inertia);
        }
        btRigidBody::btRigidBodyConstructionInfo info(mass, nullptr, shape.get(), inertia);
        info.m_startWorldTransform = transform;
        auto body = std::make_unique<btRigidBody>(info);
        body->setActivationState(DISABLE_DEACTIVATION);
        world.addRigidBody(body.get());
        shapes.push_back(std::move(shape));
        bodies.push_back(std::move(body));
        return bodies.back().get();
    }
    /// The algorithm Bullet keeps for the pair (a, b), or null.
    btCollisionAlgorithm* algorithm(btCollisionObject* a, btCollisionObject* b) {
        btBroadphasePair* pair =
            world.getPairCache()->findPair(a->getBroadphaseHandle(), b->getBroadphaseHandle());
        return pair ? pair->m_algorithm : nullptr;
    }

    btDefaultCollisionConfiguration configuration;
    InspectDispatcher dispatcher{&configuration};
    btDbvtBroadphase broadphase;
    btSequentialImpulseConstraintSolver solver;
    btDiscreteDynamicsWorld world{&dispatcher, &broadphase, &solver, &configuration};
    std::vector<std::shared_ptr<btCollisionShape>> shapes;
    std::vector<std::unique_ptr<btRigidBody>> bodies;
};

btTransform at(double x, double y, double z, double yaw = 0) {
    btTransform t;
    t.setIdentity();
    t.setOrigin(btVector3(btScalar(x), btScalar(y), btScalar(z)));
    t.setRotation(btQuaternion(btVector3(0, 0, 1), btScalar(yaw)));
    return t;
}

Vec3 toVec3(const btVector3& v) {
    return Vec3(v.x(), v.y(), v.z());
}

// ---------------------------------------------------------------------------------------
// The shape

TEST(BulletMeshShape, TypeAabbAndSharing) {
    auto model = kolize::makeMeshModel(boxMesh(Vec3(1, 2, 3)));
    MeshShape a(model), b(model);
    EXPECT_EQ(a.getShapeType(), CUSTOM_CONCAVE_SHAPE_TYPE);
    EXPECT_TRUE(a.isConcave());
    EXPECT_EQ(a.sharedModel(), b.sharedModel());  // one model, two shapes
    EXPECT_EQ(a.sharedModel().get(), model.get());

    std::mt19937 random(7);
    std::uniform_real_distribution<double> angle(-3.1, 3.1);
    for (int trial = 0; trial < 50; ++trial) {
        btTransform t;
        t.setRotation(btQuaternion(btScalar(angle(random)), btScalar(angle(random)),
                                   btScalar(angle(random))));
        t.setOrigin(btVector3(btScalar(angle(random)), 5, -2));
        btVector3 lo, hi;
        a.getAabb(t, lo, hi);
        for (const Vec3& v : model->mesh().vertices()) {
            const btVector3 w = t(btVector3(btScalar(v.x()), btScalar(v.y()), btScalar(v.z())));
            for (int k = 0; k < 3; ++k) {
                // Bullet's own float transform of the vertex rounds; allow one part in 1e6.
                EXPECT_GE(w[k], lo[k] - 1e-5f) << "trial " << trial;
                EXPECT_LE(w[k], hi[k] + 1e-5f) << "trial " << trial;
            }
        }
    }
    btVector3 lo, hi;
    a.getAabb(at(0, 0, 0), lo, hi);
    EXPECT_LE(lo.x(), -1);
    EXPECT_GE(hi.z(), 3);
    EXPECT_LT(hi.z(), 3 * 1.74);  // the root OBB's box, not unbounded
}

/// processAllTriangles against brute force over the triangles' boxes.
TEST(BulletMeshShape, ProcessAllTrianglesMatchesBruteForce) {
    // A bumpy grid: 20 x 20 quads, 800 triangles.
    std::vector<Vec3> vertices;
    std::vector<Index3> triangles;
    const int n = 20;
    for (int j = 0; j <= n; ++j) {
        for (int i = 0; i <= n; ++i) {
            vertices.emplace_back(i * 0.1, j * 0.1, 0.05 * std::sin(i * 0.7) * std::cos(j * 0.4));
        }
    }
    for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
            const int v = j * (n + 1) + i;
            triangles.push_back({v, v + 1, v + n + 2});
            triangles.push_back({v, v + n + 2, v + n + 1});
        }
    }
    const TriangleMesh mesh("bumps", vertices, triangles);
    MeshShape shape(kolize::makeMeshModel(mesh));
    struct Collect : btTriangleCallback {
        void processTriangle(btVector3*, int part, int index) override {
            EXPECT_EQ(part, 0);
            ids.push_back(index);
        }
        std::vector<int> ids;
    };
    std::mt19937 random(11);
    std::uniform_real_distribution<double> coordinate(-0.2, 2.2);
    std::uniform_real_distribution<double> size(0.0, 0.5);
    int nonEmpty = 0;
    for (int trial = 0; trial < 200; ++trial) {
        const Vec3 lo(coordinate(random), coordinate(random), -0.2 + size(random) * 0.3);
        const Vec3 hi = lo + Vec3(size(random), size(random), size(random));
        Collect collect;
        shape.processAllTriangles(&collect, btVector3(lo.x(), lo.y(), lo.z()),
                                  btVector3(hi.x(), hi.y(), hi.z()));
        std::set<int> got(collect.ids.begin(), collect.ids.end());
        EXPECT_EQ(got.size(), collect.ids.size()) << "a triangle reported twice";
        // The box is given in btScalar: compare against the same rounded box.
        const Vec3 blo(btScalar(lo.x()), btScalar(lo.y()), btScalar(lo.z()));
        const Vec3 bhi(btScalar(hi.x()), btScalar(hi.y()), btScalar(hi.z()));
        std::set<int> expected;
        for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
            const auto tri = mesh.triangle(t);
            const Vec3 tlo = tri[0].cwiseMin(tri[1]).cwiseMin(tri[2]);
            const Vec3 thi = tri[0].cwiseMax(tri[1]).cwiseMax(tri[2]);
            if (!((tlo.array() > bhi.array()).any() || (blo.array() > thi.array()).any())) {
                expected.insert(int(t));
            }
        }
        EXPECT_EQ(got, expected) << "trial " << trial;
        nonEmpty += !expected.empty();
    }
    EXPECT_GT(nonEmpty, 40);   // the sample hits triangles
    EXPECT_LT(nonEmpty, 200);  // and misses some
}

TEST(BulletMeshShape, InertiaOfAClosedBoxIsBulletsBoxInertia) {
    const Vec3 h(0.5, 1.0, 2.0);
    MeshShape shape(kolize::makeMeshModel(boxMesh(h)));
    ASSERT_TRUE(shape.massProperties().closed);
    EXPECT_NEAR(shape.massProperties().volume, 8 * h.prod(), 1e-12);
    btBoxShape reference(btVector3(0.5, 1.0, 2.0));
    btVector3 expected, got;
    reference.calculateLocalInertia(3, expected);
    shape.calculateLocalInertia(3, got);
    for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(got[k], expected[k], 1e-5 * expected[k]) << "axis " << k;
    }
    // Scaled by (2, 1, 0.5): a box of half extents (1, 1, 1).
    shape.setLocalScaling(btVector3(2, 1, 0.5));
    EXPECT_NE(shape.sharedModel(), shape.baseModel());
    btBoxShape scaledReference(btVector3(1, 1, 1));
    scaledReference.calculateLocalInertia(3, expected);
    shape.calculateLocalInertia(3, got);
    for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(got[k], expected[k], 1e-5 * expected[k]) << "axis " << k;
    }
    btVector3 lo, hi;
    shape.getAabb(at(0, 0, 0), lo, hi);
    EXPECT_NEAR(hi.x(), 1, 1e-5);
    EXPECT_NEAR(hi.z(), 1, 1e-5);
    // Back to (1, 1, 1): the shared model again.
    shape.setLocalScaling(btVector3(1, 1, 1));
    EXPECT_EQ(shape.sharedModel(), shape.baseModel());
}

TEST(BulletMeshShape, OpenMeshGetsTheInertiaOfItsRootBox) {
    TriangleMesh box = boxMesh(Vec3(1, 1, 1));
    std::vector<Index3> open(box.triangles().begin(), box.triangles().end() - 2);  // no +x face
    MeshShape shape(kolize::makeMeshModel(TriangleMesh("open box", box.vertices(), open)));
    EXPECT_FALSE(shape.massProperties().closed);
    btVector3 got;
    shape.calculateLocalInertia(6, got);
    btVector3 lo, hi;
    shape.getAabb(at(0, 0, 0), lo, hi);
    const btVector3 size = hi - lo;
    EXPECT_NEAR(got.x(), 6.0 / 12 * (size.y() * size.y() + size.z() * size.z()), 1e-4);
    EXPECT_NEAR(got.z(), 6.0 / 12 * (size.x() * size.x() + size.y() * size.y()), 1e-4);
    EXPECT_GT(got.x(), 0);
}

TEST(BulletMeshShape, BadInputIsRefusedWithAClearError) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    std::vector<Vec3> vertices = {{0, 0, 0}, {1, 0, 0}, {0, nan, 0}};
    try {
        kolize::makeMeshModel(TriangleMesh("bad-vertex", vertices, {{0, 1, 2}}));
        FAIL() << "a NaN vertex was accepted";
    } catch (const MeshError& e) {
        EXPECT_NE(std::string(e.what()).find("bad-vertex"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("vertex 2"), std::string::npos) << e.what();
    }
    vertices[2] = Vec3(0, 1, 0);
    try {
        kolize::makeMeshModel(TriangleMesh("bad-index", vertices, {{0, 1, 3}}));
        FAIL() << "an index out of range was accepted";
    } catch (const MeshError& e) {
        EXPECT_NE(std::string(e.what()).find("bad-index"), std::string::npos) << e.what();
    }
    EXPECT_THROW(MeshShape(nullptr), std::invalid_argument);
    kolize::narrowphase::TreeSettings sphereTree;
    sphereTree.kind = kolize::narrowphase::TreeKind::kSphere;
    EXPECT_THROW(MeshShape(std::make_shared<const kolize::narrowphase::MeshModel>(
                     std::make_shared<const TriangleMesh>(boxMesh(Vec3(1, 1, 1))), sphereTree)),
                 std::invalid_argument);

    MeshShape shape(kolize::makeMeshModel(boxMesh(Vec3(1, 1, 1), "crate")));
    btVector3 lo0, hi0;
    shape.getAabb(at(0, 0, 0), lo0, hi0);
    for (const btVector3& scale :
         {btVector3(0, 1, 1), btVector3(1, -2, 1), btVector3(1, 1, btScalar(nan)),
          btVector3(1, 1, std::numeric_limits<btScalar>::infinity())}) {
        try {
            shape.setLocalScaling(scale);
            FAIL() << "scale accepted: " << scale.x() << ' ' << scale.y() << ' ' << scale.z();
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find("crate"), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find("scaling"), std::string::npos) << e.what();
        }
        // Nothing changed.
        EXPECT_EQ(shape.getLocalScaling(), btVector3(1, 1, 1));
        EXPECT_EQ(shape.sharedModel(), shape.baseModel());
        btVector3 lo, hi;
        shape.getAabb(at(0, 0, 0), lo, hi);
        EXPECT_EQ(lo, lo0);
        EXPECT_EQ(hi, hi0);
    }
    EXPECT_THROW(kolize::registerNarrowphase(nullptr), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------
// Registration

TEST(BulletMeshRegistration, BothTablesHoldEveryPair) {
    btDefaultCollisionConfiguration configuration;
    InspectDispatcher plain(&configuration);
    InspectDispatcher registered(&configuration);
    kolize::registerNarrowphase(&registered);
    const int mesh = CUSTOM_CONCAVE_SHAPE_TYPE;
    std::vector<std::pair<int, int>> pairs = {{mesh, mesh}};
    for (int type = 0; type < CONCAVE_SHAPES_START_HERE; ++type) {
        if (type != IMPLICIT_CONVEX_SHAPES_START_HERE) {
            pairs.emplace_back(type, mesh);
            pairs.emplace_back(mesh, type);
        }
    }
    pairs.emplace_back(mesh, TRIANGLE_MESH_SHAPE_PROXYTYPE);
    pairs.emplace_back(TRIANGLE_MESH_SHAPE_PROXYTYPE, mesh);
    for (int scenery :
         {int(SCALED_TRIANGLE_MESH_SHAPE_PROXYTYPE), int(MULTIMATERIAL_TRIANGLE_MESH_PROXYTYPE),
          int(TERRAIN_SHAPE_PROXYTYPE), int(STATIC_PLANE_PROXYTYPE)}) {
        pairs.emplace_back(mesh, scenery);
        pairs.emplace_back(scenery, mesh);
    }
    EXPECT_EQ(pairs.size(), 1u + 2 * 19 + 10);  // 19 convex types in Bullet 3.24
    for (auto [a, b] : pairs) {
        EXPECT_NE(registered.contactFunc(a, b), plain.contactFunc(a, b)) << a << ' ' << b;
        EXPECT_NE(registered.closestFunc(a, b), plain.closestFunc(a, b)) << a << ' ' << b;
        EXPECT_NE(registered.contactFunc(a, b), nullptr);
    }
    // One create function per role, the same in both tables.
    EXPECT_EQ(registered.contactFunc(SPHERE_SHAPE_PROXYTYPE, mesh),
              registered.contactFunc(BOX_SHAPE_PROXYTYPE, mesh));
    EXPECT_EQ(registered.closestFunc(mesh, CYLINDER_SHAPE_PROXYTYPE),
              registered.contactFunc(mesh, CONE_SHAPE_PROXYTYPE));
    EXPECT_NE(registered.contactFunc(mesh, SPHERE_SHAPE_PROXYTYPE),
              registered.contactFunc(SPHERE_SHAPE_PROXYTYPE, mesh));
    // Compounds keep Bullet's algorithm.
    EXPECT_EQ(registered.contactFunc(COMPOUND_SHAPE_PROXYTYPE, mesh),
              plain.contactFunc(COMPOUND_SHAPE_PROXYTYPE, mesh));
    EXPECT_EQ(registered.closestFunc(mesh, COMPOUND_SHAPE_PROXYTYPE),
              plain.closestFunc(mesh, COMPOUND_SHAPE_PROXYTYPE));
}

/// What the dispatcher makes for a pair of shapes, in both tables and both orders.
template <class Check>
void forAlgorithms(btCollisionDispatcher& dispatcher, btCollisionShape* a, btCollisionShape* b,
                   Check check) {
    btCollisionObject objectA, objectB;
    objectA.setCollisionShape(a);
    objectB.setCollisionShape(b);
    btCollisionObjectWrapper wrapA(nullptr, a, &objectA, objectA.getWorldTransform(), -1, -1);
    btCollisionObjectWrapper wrapB(nullptr, b, &objectB, objectB.getWorldTransform(), -1, -1);
    for (auto query : {BT_CONTACT_POINT_ALGORITHMS, BT_CLOSEST_POINT_ALGORITHMS}) {
        for (bool swap : {false, true}) {
            btCollisionAlgorithm* algorithm =
                swap ? dispatcher.findAlgorithm(&wrapB, &wrapA, nullptr, query)
                     : dispatcher.findAlgorithm(&wrapA, &wrapB, nullptr, query);
            ASSERT_NE(algorithm, nullptr);
            check(algorithm, query, swap);
            algorithm->~btCollisionAlgorithm();
            dispatcher.freeCollisionAlgorithm(algorithm);
        }
    }
}

TEST(BulletMeshRegistration, ConvexPairsNeverTakeTheSdfPath) {
    auto mesh = boxShape(Vec3(1, 1, 1));
    btSphereShape sphere(0.5);
    btBoxShape box(btVector3(0.5, 0.5, 0.5));
    btCapsuleShapeZ capsule(0.3, 1);
    btConeShapeZ cone(0.4, 1);
    btCylinderShapeZ cylinder(btVector3(0.4, 0.4, 0.5));
    btConvexHullShape hull;
    hull.addPoint(btVector3(0, 0, 0));
    hull.addPoint(btVector3(1, 0, 0));
    hull.addPoint(btVector3(0, 1, 0));
    hull.addPoint(btVector3(0, 0, 1));
    btVector3 centers[2] = {btVector3(0, 0, 0), btVector3(0, 0, 1)};
    btScalar radii[2] = {0.3f, 0.4f};
    btMultiSphereShape multiSphere(centers, radii, 2);
    std::vector<btCollisionShape*> convexes = {&sphere,   &box,  &capsule,    &cone,
                                               &cylinder, &hull, &multiSphere};

    btDefaultCollisionConfiguration configuration;
    // The control: unregistered, Bullet picks its convex-concave algorithm, whose first
    // step for this shape type is the cast to btSdfCollisionShape.
    btCollisionDispatcher plain(&configuration);
    forAlgorithms(plain, &sphere, mesh.get(), [](btCollisionAlgorithm* a, auto, bool) {
        EXPECT_NE(dynamic_cast<btConvexConcaveCollisionAlgorithm*>(a), nullptr);
    });
    btCollisionDispatcher dispatcher(&configuration);
    kolize::registerNarrowphase(&dispatcher);
    for (btCollisionShape* convex : convexes) {
        forAlgorithms(dispatcher, convex, mesh.get(), [&](btCollisionAlgorithm* a, auto, bool) {
            EXPECT_NE(dynamic_cast<kolize::ConvexMeshAlgorithm*>(a), nullptr) << convex->getName();
            EXPECT_EQ(dynamic_cast<btConvexConcaveCollisionAlgorithm*>(a), nullptr);
        });
    }
    auto other = boxShape(Vec3(1, 1, 1));
    forAlgorithms(dispatcher, other.get(), mesh.get(), [](btCollisionAlgorithm* a, auto, bool) {
        EXPECT_NE(dynamic_cast<kolize::MeshMeshAlgorithm*>(a), nullptr);
    });
    btTriangleMesh triangles;
    triangles.addTriangle(btVector3(-1, -1, 0), btVector3(1, -1, 0), btVector3(1, 1, 0));
    btBvhTriangleMeshShape scenery(&triangles, true);
    const float heights[4] = {0, 0, 0, 0};
    btHeightfieldTerrainShape terrain(2, 2, heights, btScalar(-1), btScalar(1), 2, false);
    btStaticPlaneShape plane(btVector3(0, 0, 1), 0);
    for (btCollisionShape* ground : std::vector<btCollisionShape*>{&scenery, &terrain, &plane}) {
        forAlgorithms(dispatcher, ground, mesh.get(), [&](btCollisionAlgorithm* a, auto, bool) {
            EXPECT_NE(dynamic_cast<kolize::BvhMeshAlgorithm*>(a), nullptr) << ground->getName();
        });
    }
}

// ---------------------------------------------------------------------------------------
// Contacts in worlds

/// Collects every contact a contactTest or contactPairTest reports.
struct ContactCollector : btCollisionWorld::ContactResultCallback {
    btScalar addSingleResult(btManifoldPoint& point, const btCollisionObjectWrapper* wrap0, int,
                             int, const btCollisionObjectWrapper* wrap1, int, int) override {
        points.push_back(point);
        objects0.push_back(wrap0->getCollisionObject());
        objects1.push_back(wrap1->getCollisionObject());
        return 0;
    }
    std::vector<btManifoldPoint> points;
    std::vector<const btCollisionObject*> objects0, objects1;
};

TEST(BulletMeshContacts, ContactTestsUseTheClosestPointTable) {
    World w;
    btRigidBody* lower = w.add(boxShape(Vec3(1, 1, 1)), at(0, 0, 0), 0);
    btRigidBody* upper = w.add(boxShape(Vec3(0.5, 0.5, 0.5)), at(0.1, -0.2, 1.4), 1);
    btRigidBody* ball = w.add(std::make_shared<btSphereShape>(btScalar(0.5)), at(3, 0, 1.4), 1);
    btRigidBody* ballOnMesh =
        w.add(std::make_shared<btSphereShape>(btScalar(0.5)), at(-0.5, 0.5, 1.45), 1);
    (void)ball;
    for (bool swap : {false, true}) {
        ContactCollector pair;
        if (swap) {
            w.world.contactPairTest(upper, lower, pair);
        } else {
            w.world.contactPairTest(lower, upper, pair);
        }
        ASSERT_FALSE(pair.points.empty()) << "swap " << swap;
        EXPECT_LE(pair.points.size(), 4u);
        for (std::size_t i = 0; i < pair.points.size(); ++i) {
            const btManifoldPoint& p = pair.points[i];
            // The normal on object 1 points towards object 0; 0.1 deep, exactly.
            const double sign = pair.objects1[i] == upper ? -1 : 1;
            EXPECT_NEAR(p.m_normalWorldOnB.z(), sign, 1e-6);
            EXPECT_NEAR(p.getDistance(), -0.1, 1e-5);
            EXPECT_GE(p.m_index0, 0);
            EXPECT_LT(p.m_index0, 12);
            EXPECT_GE(p.m_index1, 0);
            EXPECT_LT(p.m_index1, 12);
        }
    }
    ContactCollector sphere;
    w.world.contactPairTest(ballOnMesh, lower, sphere);
    ASSERT_FALSE(sphere.points.empty());
    EXPECT_NEAR(sphere.points[0].getDistance(), -0.05, 1e-4);
    EXPECT_NEAR(std::abs(sphere.points[0].m_normalWorldOnB.z()), 1, 1e-4);
    ContactCollector all;
    w.world.contactTest(lower, all);
    std::set<const btCollisionObject*> touching;
    for (std::size_t i = 0; i < all.points.size(); ++i) {
        touching.insert(all.objects0[i] == lower ? all.objects1[i] : all.objects0[i]);
    }
    EXPECT_EQ(touching, (std::set<const btCollisionObject*>{upper, ballOnMesh}));
}

/// A static ground box mesh and three box meshes stacked on it, each smaller than the one
/// below (so no side faces are coplanar), the middle one turned 30 degrees about z.
struct Stack {
    static constexpr double kHalf[3] = {1.0, 0.7, 0.45};
    explicit Stack(World& w) {
        ground = w.add(boxShape(Vec3(5, 5, 0.5)), at(0, 0, -0.5), 0);
        double z = 0;
        for (int i = 0; i < 3; ++i) {
            const double h = kHalf[i];
            boxes[i] =
                w.add(boxShape(Vec3(h, h, h)), at(0, 0, z + h + 0.01, i == 1 ? 0.5236 : 0), 1);
            z += 2 * h + 0.01;
        }
    }
    btRigidBody* ground;
    btRigidBody* boxes[3];
};

/// The world vertices of a box of half extents h at `t`, in double.
std::vector<Vec3> boxVertices(const btTransform& t, const Vec3& h) {
    std::vector<Vec3> out;
    for (int c = 0; c < 8; ++c) {
        out.push_back(
            toVec3(t(btVector3(btScalar(c & 1 ? h.x() : -h.x()), btScalar(c & 2 ? h.y() : -h.y()),
                               btScalar(c & 4 ? h.z() : -h.z())))));
    }
    return out;
}

/// Signed distance-like measure of p from the surface of the box (half extents h) at t:
/// max over the axes of |q_i| - h_i, q = p in the box's frame; 0 on the surface.
double surfaceDistance(const btTransform& t, const Vec3& h, const Vec3& p) {
    const Vec3 q = toVec3(t.invXform(btVector3(btScalar(p.x()), btScalar(p.y()), btScalar(p.z()))));
    return (q.cwiseAbs() - h).maxCoeff();
}

/// How far p (inside the box of half extents h at t, or on it) moves along the unit `dir`
/// until it leaves the box: the slabs' nearest exit, in the box's frame.
double exitDistance(const btTransform& t, const Vec3& h, const Vec3& p, const Vec3& dir) {
    const Vec3 q = toVec3(t.invXform(btVector3(btScalar(p.x()), btScalar(p.y()), btScalar(p.z()))));
    const Vec3 e = toVec3(t.getBasis().transpose() *
                          btVector3(btScalar(dir.x()), btScalar(dir.y()), btScalar(dir.z())));
    double exit = 1e300;
    for (int k = 0; k < 3; ++k) {
        if (e[k] != 0) {
            exit = std::min(exit, ((e[k] > 0 ? h[k] : -h[k]) - q[k]) / e[k]);
        }
    }
    return exit;
}

/// The distance from p to the nearest of `vertices`.
double nearestVertex(const std::vector<Vec3>& vertices, const Vec3& p) {
    double best = 1e300;
    for (const Vec3& v : vertices) {
        best = std::min(best, (v - p).norm());
    }
    return best;
}

/// Checks a contact of box X (pose tx, half extents hx) against box Y, normal from X to Y:
/// either a point of the intersection curve (on both surfaces) at the exact overlap along the
/// normal, or a vertex of one box inside the other: then its ends (point -+ normal * depth/2)
/// are that vertex and the place where it leaves the other box along the normal, at that
/// distance (exitDistance, computed here from the boxes alone). Returns true for a vertex.
bool checkBoxContact(const kolize::MeshContact& c, const btTransform& tx, const Vec3& hx,
                     const btTransform& ty, const Vec3& hy, double overlap,
                     const std::string& where) {
    EXPECT_GE(c.depth, 0) << where;
    EXPECT_LE(c.depth, overlap + 1e-6) << where;
    const Vec3 onX = c.point + 0.5 * c.depth * c.normal;  // X's end: inside Y
    const Vec3 onY = c.point - 0.5 * c.depth * c.normal;
    const bool xVertex = nearestVertex(boxVertices(tx, hx), onX) < 1e-5;
    const bool yVertex = nearestVertex(boxVertices(ty, hy), onY) < 1e-5;
    if (std::abs(c.depth - overlap) <= 1e-6 && std::abs(surfaceDistance(tx, hx, c.point)) < 1e-5 &&
        std::abs(surfaceDistance(ty, hy, c.point)) < 1e-5) {
        return false;  // on the intersection curve
    }
    EXPECT_TRUE(xVertex || yVertex) << where << ": neither on the curve nor at a vertex";
    if (xVertex) {
        EXPECT_LT(surfaceDistance(ty, hy, onX), 1e-5) << where << ": X's vertex outside Y";
        EXPECT_NEAR(exitDistance(ty, hy, onX, -c.normal), c.depth, 1e-5) << where;
    } else if (yVertex) {
        EXPECT_LT(surfaceDistance(tx, hx, onY), 1e-5) << where << ": Y's vertex outside X";
        EXPECT_NEAR(exitDistance(tx, hx, onY, c.normal), c.depth, 1e-5) << where;
    }
    return true;
}

/// How far the vertex sets overlap along d (from `lower` towards `upper`).
double overlapAlong(const std::vector<Vec3>& lower, const std::vector<Vec3>& upper, const Vec3& d) {
    double highest = -1e300, lowest = 1e300;
    for (const Vec3& v : lower) {
        highest = std::max(highest, v.dot(d));
    }
    for (const Vec3& v : upper) {
        lowest = std::min(lowest, v.dot(d));
    }
    return highest - lowest;
}

/// No two contacts within `threshold` of each other (Bullet would merge them).
void expectApart(const std::vector<kolize::MeshContact>& contacts, double threshold,
                 const std::string& where) {
    for (std::size_t k = 0; k < contacts.size(); ++k) {
        for (std::size_t j = 0; j < k; ++j) {
            EXPECT_GT((contacts[j].point - contacts[k].point).norm(), threshold)
                << "points Bullet merges, " << where;
        }
    }
}

TEST(BulletMeshContacts, StackOfBoxMeshesHasTheExactContacts) {
    World w;
    Stack stack(w);
    btRigidBody* levels[4] = {stack.ground, stack.boxes[0], stack.boxes[1], stack.boxes[2]};
    const Vec3 halves[4] = {Vec3(5, 5, 0.5), Vec3::Constant(Stack::kHalf[0]),
                            Vec3::Constant(Stack::kHalf[1]), Vec3::Constant(Stack::kHalf[2])};
    int checkedFrames[3] = {0, 0, 0};
    int areaFrames[3] = {0, 0, 0};
    int vertexPoints = 0;
    for (int step = 0; step < 300; ++step) {
        // The contacts of a step are made at the poses the previous step ended with.
        btTransform poses[4];
        for (int l = 0; l < 4; ++l) {
            poses[l] = levels[l]->getWorldTransform();
        }
        w.world.stepSimulation(btScalar(1.0 / 60), 0);
        for (int i = 0; i < 3; ++i) {
            btRigidBody* lower = levels[i];
            btRigidBody* upper = levels[i + 1];
            auto* algorithm = dynamic_cast<kolize::MeshMeshAlgorithm*>(w.algorithm(lower, upper));
            ASSERT_NE(algorithm, nullptr) << "level " << i;
            btManifoldArray manifolds;
            algorithm->getAllContactManifolds(manifolds);
            ASSERT_EQ(manifolds.size(), 1);
            const bool lowerFirst = manifolds[0]->getBody0() == lower;
            const std::vector<kolize::MeshContact>& contacts = algorithm->lastContacts();
            if (contacts.empty()) {
                continue;  // pushed apart by the solver this step: the manifold holds on
            }
            ++checkedFrames[i];
            // An area's 3 or 4 points, but no two within the breaking threshold (Bullet would
            // merge them): a box resting tilted on a sliver near its corner has 2.
            areaFrames[i] += contacts.size() >= 3 ? 1 : 0;
            ASSERT_LE(contacts.size(), 4u) << "level " << i << " step " << step;
            expectApart(contacts, manifolds[0]->getContactBreakingThreshold(),
                        "level " + std::to_string(i) + " step " + std::to_string(step));
            const std::vector<Vec3> lowerVertices = boxVertices(poses[i], halves[i]);
            const std::vector<Vec3> upperVertices = boxVertices(poses[i + 1], halves[i + 1]);
            // The exact normal is one of the two facing faces' normals: the lower box's top,
            // or the upper box's bottom reversed (the one with the smaller overlap).
            const Vec3 lowerTop = toVec3(poses[i].getBasis().getColumn(2));
            const Vec3 upperBottom = toVec3(poses[i + 1].getBasis().getColumn(2));
            const Vec3 up = contacts[0].normal * (lowerFirst ? 1 : -1);
            const bool isLowerTop = (up - lowerTop).norm() < 1e-6;
            const bool isUpperBottom = (up - upperBottom).norm() < 1e-6;
            EXPECT_TRUE(isLowerTop || isUpperBottom)
                << "level " << i << " normal " << up.transpose();
            // The stack stays upright: the top box rocks by up to 0.6 degrees (steps 64-69,
            // measured) while it settles, since kept points of boxes the exact test finds
            // apart no longer push them apart (keptPointsAtMostTouch).
            EXPECT_LT((up - Vec3(0, 0, 1)).norm(), 2e-2) << "level " << i << " step " << step;
            const double exactDepth = overlapAlong(lowerVertices, upperVertices, up);
            EXPECT_GT(exactDepth, 0);
            EXPECT_LT(exactDepth, 0.02);
            // Every point is on the intersection curve at the exact overlap, or a vertex of one
            // box inside the other at the distance it leaves that box along the normal.
            const int x = lowerFirst ? i : i + 1, y = lowerFirst ? i + 1 : i;
            for (std::size_t k = 0; k < contacts.size(); ++k) {
                const kolize::MeshContact& c = contacts[k];
                EXPECT_LT((c.normal - contacts[0].normal).norm(), 1e-12) << "one patch";
                vertexPoints +=
                    checkBoxContact(c, poses[x], halves[x], poses[y], halves[y], exactDepth,
                                    "level " + std::to_string(i) + " step " + std::to_string(step));
                EXPECT_GE(c.triangleX, 0);
                EXPECT_LT(c.triangleX, 12);
                EXPECT_GE(c.triangleY, 0);
                EXPECT_LT(c.triangleY, 12);
            }
            // What Bullet holds: the same normal, no point deeper than the exact overlap.
            for (int k = 0; k < manifolds[0]->getNumContacts(); ++k) {
                const btManifoldPoint& p = manifolds[0]->getContactPoint(k);
                EXPECT_NEAR(p.m_normalWorldOnB.z(), lowerFirst ? -1 : 1, 1e-3);
                EXPECT_GE(p.getDistance(), -0.02);
                EXPECT_LT(p.getDistance(), manifolds[0]->getContactBreakingThreshold());
            }
        }
    }
    for (int i = 0; i < 3; ++i) {
        // Landing and settling; at rest the bodies sit on their persistent points, at most
        // touching, and an exact test finds nothing new.
        EXPECT_GE(checkedFrames[i], 10) << "level " << i << ": too few frames with contacts";
        EXPECT_GE(2 * areaFrames[i], checkedFrames[i]) << "level " << i << ": too few areas";
    }
    EXPECT_GE(vertexPoints, 20) << "too few vertex points: that kind went unchecked";
    double restTop = 0;
    for (int i = 0; i < 3; ++i) {
        const btRigidBody* body = stack.boxes[i];
        const double h = Stack::kHalf[i];
        const double z = body->getWorldTransform().getOrigin().z();
        EXPECT_NEAR(z, restTop + h, 0.02) << "box " << i;  // resting, slightly sunk
        EXPECT_LT(body->getLinearVelocity().length(), 0.05) << "box " << i;
        EXPECT_LT(body->getAngularVelocity().length(), 0.05) << "box " << i;
        restTop += 2 * h;
    }
}

/// A box mesh on a static, triangulated floor (btBvhTriangleMeshShape, 10 x 10 quads of
/// 1 m, 200 triangles), centred on a grid vertex and a second one turned across diagonals:
/// the internal edges must not make ghost contacts (fcl#106's hanging box).
/// Adds the 10 x 10 quads of 1 m at z = 0 (x, y in -5..5), two triangles each, wound up.
void addUnitQuads(btTriangleMesh& triangles) {
    for (int j = -5; j < 5; ++j) {
        for (int i = -5; i < 5; ++i) {
            const btVector3 a(i, j, 0), b(i + 1, j, 0), c(i + 1, j + 1, 0), d(i, j + 1, 0);
            triangles.addTriangle(a, b, c);
            triangles.addTriangle(a, c, d);
        }
    }
}

struct Floor {
    explicit Floor(World& w) {
        triangles = std::make_unique<btTriangleMesh>();
        addUnitQuads(*triangles);
        floor =
            w.add(std::make_shared<btBvhTriangleMeshShape>(triangles.get(), true), at(0, 0, 0), 0);
        boxes[0] = w.add(boxShape(Vec3(0.5, 0.5, 0.5)), at(0, 0, 0.51), 1);
        boxes[1] = w.add(boxShape(Vec3(0.5, 0.5, 0.5)), at(2.3, 1.7, 0.6, 0.35), 1);
    }
    std::unique_ptr<btTriangleMesh> triangles;
    btRigidBody* floor;
    btRigidBody* boxes[2];
};

/// The one manifold of a pair's algorithm (null unless there is exactly one).
const btPersistentManifold* onlyManifold(btCollisionAlgorithm* algorithm) {
    btManifoldArray manifolds;
    algorithm->getAllContactManifolds(manifolds);
    return manifolds.size() == 1 ? manifolds[0] : nullptr;
}

/// Whether the manifold holds a point whose middle is `point` (within 0.1 mm).
bool holds(const btPersistentManifold& m, const Vec3& point) {
    for (int k = 0; k < m.getNumContacts(); ++k) {
        const btManifoldPoint& p = m.getContactPoint(k);
        const Vec3 middle =
            0.5 * (toVec3(p.getPositionWorldOnA()) + toVec3(p.getPositionWorldOnB()));
        if ((middle - point).norm() < 1e-4) {
            return true;
        }
    }
    return false;
}

/// Regression: a box sliding farther per step than its manifold's breaking threshold (here
/// 3.3 cm against 1.7 cm) lost new points. The manifold was full of the last step's points,
/// stale but dropped only by the refresh after the new ones went in; Bullet's choice of which
/// point a new one replaces keeps the deepest cached point, so the new points replaced each
/// other and about half of each step's were lost (mesh-floor's boxes sank on that side).
TEST(BulletMeshContacts, ABoxSlidingFasterThanTheBreakingThresholdKeepsEveryNewPoint) {
    World w;
    Floor scene(w);
    btRigidBody* box = scene.boxes[0];
    box->setWorldTransform(at(-2, 0, 0.5));
    box->setLinearVelocity(btVector3(2, 0.3, 0));
    int checked = 0;
    for (int step = 0; step < 20; ++step) {
        w.world.stepSimulation(btScalar(1.0 / 60), 0);
        auto* algorithm = dynamic_cast<kolize::BvhMeshAlgorithm*>(w.algorithm(scene.floor, box));
        ASSERT_NE(algorithm, nullptr);
        const btPersistentManifold* m = onlyManifold(algorithm);
        ASSERT_NE(m, nullptr);
        ASSERT_LT(m->getContactBreakingThreshold(), 0.033f) << "the box must slide farther";
        const std::vector<kolize::MeshContact>& contacts = algorithm->lastContacts();
        for (const kolize::MeshContact& c : contacts) {
            EXPECT_TRUE(holds(*m, c.point))
                << "step " << step << ": a point made this step is not held, at "
                << c.point.transpose();
        }
        checked += int(contacts.size());
    }
    const btVector3 v = box->getLinearVelocity();
    EXPECT_LT(v.x(), 2.0f);  // friction slowed it: it slid on its contacts
    EXPECT_GE(checked, 40) << "too few contacts checked";
}

/// Regression (CI, double precision): of two new points closer than the breaking threshold,
/// Bullet merges the second into the first (getCacheEntry), so the pair lost a point it had
/// chosen: on a triangular contact region the largest quadrilateral's 4th point was 0.8 mm
/// from the 2nd (threshold 17 mm), and the box sliding over mesh-floor sank on that side.
/// Boxes tilted at random into a mesh ground and into triangle-mesh scenery, one detection
/// each on an empty manifold: every point made is held, and no two are within the threshold.
TEST(BulletMeshContacts, NoTwoNewPointsAreCloserThanTheBreakingThreshold) {
    const unsigned seed = 20261206;
    std::mt19937 random(seed);
    std::uniform_real_distribution<double> unit(-1, 1), tilt(0.0, 0.4), depth(1e-4, 0.03);
    int points = 0, cases = 0, casesWithMany = 0;
    for (int i = 0; i < 200; ++i) {
        World w;
        std::unique_ptr<Floor> floor;
        btRigidBody* ground = nullptr;
        if (i % 2 == 0) {
            ground = w.add(boxShape(Vec3(5, 5, 0.5)), at(0, 0, -0.5), 0);
        } else {
            floor = std::make_unique<Floor>(w);
            ground = floor->floor;
            w.world.removeRigidBody(floor->boxes[1]);
            w.world.removeRigidBody(floor->boxes[0]);
        }
        btRigidBody* box = w.add(boxShape(Vec3(0.5, 0.5, 0.5)), at(0, 0, 2), 1);
        btVector3 axis(btScalar(unit(random)), btScalar(unit(random)),
                       btScalar(0.2 * unit(random)));
        if (axis.length2() < 1e-6) {
            axis = btVector3(1, 0, 0);
        }
        btTransform pose;
        pose.setIdentity();
        pose.setRotation(btQuaternion(axis.normalized(), btScalar(tilt(random))));
        // The lowest vertex `depth` below the ground's top (z = 0).
        double lowest = 1e9;
        for (const Vec3& v : boxVertices(pose, Vec3::Constant(0.5))) {
            lowest = std::min(lowest, v.z());
        }
        pose.setOrigin(btVector3(btScalar(unit(random)), btScalar(unit(random)),
                                 btScalar(-lowest - depth(random))));
        box->setWorldTransform(pose);
        w.world.performDiscreteCollisionDetection();
        btCollisionAlgorithm* algorithm = w.algorithm(ground, box);
        ASSERT_NE(algorithm, nullptr) << "case " << i << ", seed " << seed;
        const std::vector<kolize::MeshContact>* contacts = nullptr;
        if (auto* meshMesh = dynamic_cast<kolize::MeshMeshAlgorithm*>(algorithm)) {
            contacts = &meshMesh->lastContacts();
        } else if (auto* scenery = dynamic_cast<kolize::BvhMeshAlgorithm*>(algorithm)) {
            contacts = &scenery->lastContacts();
        }
        ASSERT_NE(contacts, nullptr) << "case " << i;
        const btPersistentManifold* m = onlyManifold(algorithm);
        ASSERT_NE(m, nullptr) << "case " << i;
        const std::string where = "case " + std::to_string(i) + ", seed " + std::to_string(seed);
        expectApart(*contacts, m->getContactBreakingThreshold(), where);
        for (const kolize::MeshContact& c : *contacts) {
            EXPECT_TRUE(holds(*m, c.point))
                << where << ": a point made is not held, at " << c.point.transpose();
        }
        points += int(contacts->size());
        cases += contacts->empty() ? 0 : 1;
        casesWithMany += contacts->size() >= 3 ? 1 : 0;
    }
    EXPECT_GE(cases, 190) << "too few boxes touched the ground";
    EXPECT_GE(casesWithMany, 50) << "too few areas";
    EXPECT_GE(points, 400);
}

TEST(BulletMeshContacts, BoxMeshRestsOnATriangleMeshFloorWithoutGhostContacts) {
    World w;
    Floor scene(w);
    double lowest[2] = {1e9, 1e9};
    int checkedFrames[2] = {0, 0};
    int areaFrames[2] = {0, 0};
    int vertexPoints = 0;
    for (int step = 0; step < 300; ++step) {
        btTransform poses[2] = {scene.boxes[0]->getWorldTransform(),
                                scene.boxes[1]->getWorldTransform()};
        w.world.stepSimulation(btScalar(1.0 / 60), 0);
        for (int b = 0; b < 2; ++b) {
            btRigidBody* box = scene.boxes[b];
            lowest[b] = std::min(lowest[b], double(box->getWorldTransform().getOrigin().z()));
            auto* algorithm =
                dynamic_cast<kolize::BvhMeshAlgorithm*>(w.algorithm(scene.floor, box));
            if (algorithm == nullptr || algorithm->lastContacts().empty()) {
                continue;
            }
            ++checkedFrames[b];
            const std::vector<kolize::MeshContact>& contacts = algorithm->lastContacts();
            // An area's 3 or 4 points, but no two within the breaking threshold (Bullet would
            // merge them): a box resting a hair tilted on a sliver at its corner has 1.
            areaFrames[b] += contacts.size() >= 3 ? 1 : 0;
            EXPECT_LE(contacts.size(), 4u) << "box " << b;
            const btPersistentManifold* m = onlyManifold(algorithm);
            ASSERT_NE(m, nullptr);
            expectApart(contacts, m->getContactBreakingThreshold(),
                        "box " + std::to_string(b) + " step " + std::to_string(step));
            const std::vector<Vec3> vertices = boxVertices(poses[b], Vec3::Constant(0.5));
            double exactDepth = 0;
            for (const Vec3& v : vertices) {
                exactDepth = std::max(exactDepth, -v.z());
            }
            for (const kolize::MeshContact& c : contacts) {
                // X is the mesh: the normal points from it down into the floor, exactly.
                EXPECT_LT((c.normal - Vec3(0, 0, -1)).norm(), 1e-12) << "box " << b;
                EXPECT_GE(c.triangleY, 0);
                EXPECT_LT(c.triangleY, 200);
                EXPECT_EQ(c.partY, 0);
                // Not on the intersection curve at the exact depth: a vertex of the box under
                // the floor, or a floor vertex inside the box. The floor's end is on the
                // floor, the box's on the box, the depth the vertex's distance to the other
                // along the normal.
                if (std::abs(c.point.z()) > 1e-6 || std::abs(c.depth - exactDepth) > 1e-6) {
                    ++vertexPoints;
                    const Vec3 onBox = c.point + 0.5 * c.depth * c.normal;
                    const Vec3 onFloor = c.point - 0.5 * c.depth * c.normal;
                    const bool boxVertex = nearestVertex(vertices, onBox) < 1e-5;
                    const bool floorVertex =
                        std::abs(onFloor.x() - std::round(onFloor.x())) < 1e-6 &&
                        std::abs(onFloor.y() - std::round(onFloor.y())) < 1e-6;
                    EXPECT_TRUE(boxVertex || floorVertex) << "box " << b << " step " << step;
                    EXPECT_NEAR(onFloor.z(), 0, 1e-6) << "box " << b;
                    EXPECT_LT(std::abs(surfaceDistance(poses[b], Vec3::Constant(0.5), onBox)), 1e-5)
                        << "box " << b;
                    EXPECT_LE(c.depth, exactDepth + 1e-6) << "box " << b;
                    if (boxVertex) {
                        EXPECT_NEAR(c.depth, -onBox.z(), 1e-6) << "box " << b;
                    } else if (floorVertex) {
                        EXPECT_NEAR(exitDistance(poses[b], Vec3::Constant(0.5), onFloor, c.normal),
                                    c.depth, 1e-5)
                            << "box " << b;
                    }
                    continue;
                }
                // Otherwise on the intersection curve, at the exact depth.
                EXPECT_NEAR(c.point.z(), 0, 1e-6);
                // On the box: within its faces, in its own frame (a disk of the half diagonal
                // around the centre, the check this replaces, is too small by half the
                // height times the tilt of a box that landed a hair tilted).
                const btVector3 local =
                    poses[b].inverse() *
                    btVector3(btScalar(c.point.x()), btScalar(c.point.y()), btScalar(c.point.z()));
                for (int k = 0; k < 3; ++k) {
                    EXPECT_LE(std::fabs(local[k]), 0.5 + 1e-5) << "box " << b;
                }
            }
        }
    }
    for (int b = 0; b < 2; ++b) {
        btRigidBody* box = scene.boxes[b];
        const btTransform& t = box->getWorldTransform();
        EXPECT_GE(checkedFrames[b], 8) << "box " << b << ": too few frames with contacts";
        EXPECT_GE(2 * areaFrames[b], checkedFrames[b]) << "box " << b << ": too few areas";
        EXPECT_GE(vertexPoints, 8) << "too few vertex points: that kind went unchecked";
        EXPECT_GT(lowest[b], 0.47) << "box " << b << " sank";  // no fall-through
        EXPECT_NEAR(t.getOrigin().z(), 0.5, 0.02) << "box " << b;
        EXPECT_LT(box->getLinearVelocity().length(), 0.05) << "box " << b;
        EXPECT_LT(box->getAngularVelocity().length(), 0.05) << "box " << b;
        EXPECT_GT(t.getBasis().getColumn(2).z(), 0.9999) << "box " << b << " tilted";
        auto* algorithm = dynamic_cast<kolize::BvhMeshAlgorithm*>(w.algorithm(scene.floor, box));
        ASSERT_NE(algorithm, nullptr);
        const btPersistentManifold* m = onlyManifold(algorithm);
        ASSERT_NE(m, nullptr);
        // No ghost contacts: every point Bullet holds is under the box, on the floor, with
        // the floor's normal (on body1, towards body0).
        const double expectedZ = m->getBody0() == scene.floor ? -1 : 1;
        ASSERT_GE(m->getNumContacts(), 3);
        for (int k = 0; k < m->getNumContacts(); ++k) {
            const btManifoldPoint& p = m->getContactPoint(k);
            EXPECT_NEAR(p.m_normalWorldOnB.z(), expectedZ, 1e-6) << "ghost normal";
            const btVector3 onFloor =
                m->getBody0() == scene.floor ? p.getPositionWorldOnA() : p.getPositionWorldOnB();
            EXPECT_NEAR(onFloor.z(), 0, 0.02);
            const btVector3 offset = onFloor - t.getOrigin();
            EXPECT_LE(std::hypot(offset.x(), offset.y()), 0.5 * std::sqrt(2.0) + 0.01);
            EXPECT_GT(p.getDistance(), -0.02);
        }
    }
    // Both orders through contactPairTest, the box put 0.01 deep: the normal on object 1
    // points towards object 0.
    scene.boxes[0]->setWorldTransform(at(0, 0, 0.49));
    for (bool floorFirst : {true, false}) {
        ContactCollector collector;
        if (floorFirst) {
            w.world.contactPairTest(scene.floor, scene.boxes[0], collector);
        } else {
            w.world.contactPairTest(scene.boxes[0], scene.floor, collector);
        }
        ASSERT_FALSE(collector.points.empty());
        for (const btManifoldPoint& p : collector.points) {
            EXPECT_NEAR(p.m_normalWorldOnB.z(), floorFirst ? -1 : 1, 1e-4);
            EXPECT_NEAR(p.getDistance(), -0.01, 1e-5);
        }
    }
}

/// The manifold points of the pair (a, b) after one collision pass.
std::vector<btManifoldPoint> manifoldPoints(World& w, btCollisionObject* a, btCollisionObject* b) {
    w.world.performDiscreteCollisionDetection();
    std::vector<btManifoldPoint> out;
    btCollisionAlgorithm* algorithm = w.algorithm(a, b);
    if (algorithm == nullptr) {
        return out;
    }
    btManifoldArray manifolds;
    algorithm->getAllContactManifolds(manifolds);
    for (int m = 0; m < manifolds.size(); ++m) {
        for (int i = 0; i < manifolds[m]->getNumContacts(); ++i) {
            out.push_back(manifolds[m]->getContactPoint(i));
        }
    }
    return out;
}

/// A ground with its top face at z = 0: the Floor scene's btBvhTriangleMeshShape (its two
/// boxes moved out of the way) or a static box mesh offset by `shift` in x and y.
struct FlatGround {
    FlatGround(World& w, bool scenery, double shift) {
        if (scenery) {
            floor = std::make_unique<Floor>(w);
            body = floor->floor;
            for (btRigidBody* box : floor->boxes) {
                box->getWorldTransform().setOrigin(btVector3(40, 0, 5));
            }
        } else {
            body = w.add(boxShape(Vec3(5, 5, 0.5)), at(shift, 0.7 * shift, -0.5), 0);
        }
    }
    std::unique_ptr<Floor> floor;
    btRigidBody* body = nullptr;
};

// The contact margin: a box mesh hovering a known gap g above a box-mesh ground or a
// btBvhTriangleMeshShape floor, turned and a little tilted, gets separated contacts whose
// distances are the exact vertex heights (one of them the gap), never a penetration; none
// beyond the margin, none without a margin, none past the manifold's breaking threshold.
TEST(BulletMeshContacts, ContactMarginMakesSeparatedContactsNeverPenetrations) {
    for (bool scenery : {false, true}) {
        for (double margin : {0.0, 0.01, 1.0}) {
            World w;
            kolize::MeshStageSettings settings;
            settings.contact_margin = margin;
            kolize::registerNarrowphase(&w.dispatcher, settings);
            const FlatGround flat(w, scenery, 0.3);
            btRigidBody* ground = flat.body;
            btRigidBody* box = w.add(boxShape(Vec3(0.5, 0.5, 0.5)), at(0, 0, 5), 1);
            for (double gap : {0.002, 0.006, 0.02, 0.05}) {
                btTransform t = at(0.1, -0.2, 0, 0.4);
                t.setRotation(btQuaternion(btVector3(0, 0, 1), btScalar(0.4)) *
                              btQuaternion(btVector3(1, 0.3, 0).normalized(), btScalar(0.002)));
                // The lowest vertex of the turned box at height `gap` above z = 0.
                double lowest = 1e9;
                for (const Vec3& v : boxVertices(t, Vec3::Constant(0.5))) {
                    lowest = std::min(lowest, v.z());
                }
                t.setOrigin(btVector3(btScalar(0.1), btScalar(-0.2), btScalar(gap - lowest)));
                box->setWorldTransform(t);
                std::vector<double> heights;
                for (const Vec3& v : boxVertices(t, Vec3::Constant(0.5))) {
                    heights.push_back(v.z());
                }
                std::sort(heights.begin(), heights.end());
                const std::vector<btManifoldPoint> points = manifoldPoints(w, ground, box);
                const std::string where = std::string(scenery ? "scenery" : "mesh ground") +
                                          " margin " + std::to_string(margin) + " gap " +
                                          std::to_string(gap);
                btPersistentManifold manifold(ground, box, 0, 0, 0);
                const double threshold =
                    std::min(ground->getCollisionShape()->getContactBreakingThreshold(
                                 gContactBreakingThreshold),
                             box->getCollisionShape()->getContactBreakingThreshold(
                                 gContactBreakingThreshold));
                const double reach = std::min(margin, threshold);
                if (gap > reach) {
                    EXPECT_TRUE(points.empty()) << where << ": " << points.size() << " points";
                    continue;
                }
                ASSERT_GE(points.size(), 3u) << where;
                double closest = 1e9;
                for (const btManifoldPoint& p : points) {
                    const double d = p.getDistance();
                    closest = std::min(closest, d);
                    EXPECT_GT(d, 0) << where << ": a penetration between meshes apart";
                    EXPECT_LE(d, reach + 1e-6) << where;
                    EXPECT_NEAR(std::fabs(p.m_normalWorldOnB.z()), 1, 1e-6) << where;
                    // Each point is a box vertex over the ground: its distance is one of the
                    // bottom vertices' heights.
                    double nearest = 1e9;
                    for (int k = 0; k < 4; ++k) {
                        nearest = std::min(nearest, std::fabs(heights[k] - d));
                    }
                    EXPECT_LT(nearest, 1e-6) << where << " distance " << d;
                }
                EXPECT_NEAR(closest, gap, 1e-6) << where;
            }
        }
    }
}

// Regression: with a margin, a box mesh 1 mm into a box-mesh ground also has near pairs (its
// bottom face 1 mm under the ground's top face, their normal pointing down). Mixed into the
// contacts, those separated points replaced the penetrating ones in Bullet's manifold
// (getCacheEntry matches points within the breaking threshold): mesh-pile had 227 pairs that
// intersected with no penetrating point. Meshes that intersect get only their intersecting
// pairs' contacts.
TEST(BulletMeshContacts, ContactMarginKeepsThePenetratingPointsOfIntersectingMeshes) {
    World w;
    kolize::MeshStageSettings settings;
    settings.contact_margin = 0.005;
    kolize::registerNarrowphase(&w.dispatcher, settings);
    btRigidBody* ground = w.add(boxShape(Vec3(5, 5, 0.5)), at(0, 0, -0.5), 0);
    btRigidBody* box = w.add(boxShape(Vec3(0.5, 0.5, 0.5)), at(0.2, 0.1, 0.5 - 0.001, 0.3), 1);
    const std::vector<btManifoldPoint> points = manifoldPoints(w, ground, box);
    ASSERT_GE(points.size(), 3u);
    for (const btManifoldPoint& p : points) {
        EXPECT_NEAR(p.getDistance(), -0.001, 1e-6);
        EXPECT_NEAR(std::fabs(p.m_normalWorldOnB.z()), 1, 1e-6);
    }
    EXPECT_EQ(kolize::narrowphaseStages(&w.dispatcher).near_pairs, 0u);
}

// Bullet's closest-point queries: contactPairTest with the callback's
// m_closestDistanceThreshold reports mesh pairs apart by up to it (points handed to the
// callback, so the manifold's breaking threshold, 1.7 cm for this box, does not cut them),
// also without a contact margin; without a threshold, nothing.
TEST(BulletMeshContacts, ClosestPointQueriesReportMeshesWithinTheirThreshold) {
    for (bool scenery : {false, true}) {
        World w;
        const FlatGround flat(w, scenery, 0.0);
        btRigidBody* ground = flat.body;
        const double gap = 0.03;
        btRigidBody* box = w.add(boxShape(Vec3(0.5, 0.5, 0.5)), at(0.2, 0.1, 0.5 + gap, 0.3), 1);
        for (double threshold : {0.0, 0.02, 0.05}) {
            ContactCollector points;
            points.m_closestDistanceThreshold = btScalar(threshold);
            w.world.contactPairTest(box, ground, points);
            const std::string where = std::string(scenery ? "scenery" : "mesh ground") +
                                      " threshold " + std::to_string(threshold);
            if (threshold < gap) {
                EXPECT_TRUE(points.points.empty()) << where;
                continue;
            }
            ASSERT_GE(points.points.size(), 3u) << where;
            double closest = 1e9;
            for (const btManifoldPoint& p : points.points) {
                closest = std::min(closest, double(p.getDistance()));
                EXPECT_NEAR(p.getDistance(), gap, 1e-5) << where;  // a flat box: every corner
                EXPECT_NEAR(std::fabs(p.m_normalWorldOnB.z()), 1, 1e-6) << where;
            }
            EXPECT_NEAR(closest, gap, 1e-5) << where;
        }
    }
}

TEST(BulletMeshContacts, ContactMarginCatchesALandingBoxBeforeItSinksIn) {
    // A box mesh dropped 1 cm onto a box-mesh ground (0.45 m/s at landing, 7.5 mm per step):
    // without a margin the exact contacts respond once it is in (6.7 mm deep); with 1 cm of
    // margin the separated contacts slow it before it touches (1.4 mm deep: once the meshes
    // intersect, only the intersecting pairs make contacts).
    double lowest[2] = {1e9, 1e9}, rest[2] = {0, 0};
    std::uint64_t near[2] = {0, 0};
    for (int run = 0; run < 2; ++run) {
        World w;
        kolize::MeshStageSettings settings;
        settings.contact_margin = run == 0 ? 0.0 : 0.01;
        kolize::registerNarrowphase(&w.dispatcher, settings);
        w.add(boxShape(Vec3(5, 5, 0.5)), at(0, 0, -0.5), 0);
        btRigidBody* box = w.add(boxShape(Vec3(0.5, 0.5, 0.5)), at(0, 0, 0.51, 0.3), 1);
        for (int step = 0; step < 240; ++step) {
            w.world.stepSimulation(btScalar(1.0 / 60), 0);
            lowest[run] = std::min(lowest[run], double(box->getWorldTransform().getOrigin().z()));
        }
        rest[run] = box->getWorldTransform().getOrigin().z();
        EXPECT_LT(box->getLinearVelocity().length(), 0.01) << "run " << run;
        const kolize::MeshStageStats stats = kolize::narrowphaseStages(&w.dispatcher);
        near[run] = stats.near_pairs;
        EXPECT_EQ(
            kolize::describeStages(stats).find("within the contact margin") != std::string::npos,
            run == 1);
    }
    EXPECT_EQ(near[0], 0u);
    EXPECT_GT(near[1], 0u);
    EXPECT_LT(lowest[0], 0.5 - 2e-3) << "the exact contacts alone let it in (the comparison)";
    EXPECT_GT(lowest[1], 0.5 - 2.5e-3);
    EXPECT_NEAR(rest[1], 0.5, 0.01);
}

TEST(BulletMeshContacts, BadContactMarginsAreRefused) {
    World w;
    kolize::MeshStageSettings settings;
    for (double bad : {-0.01, std::nan(""), std::numeric_limits<double>::infinity()}) {
        settings.contact_margin = bad;
        EXPECT_THROW(kolize::registerNarrowphase(&w.dispatcher, settings), std::invalid_argument)
            << bad;
    }
}

TEST(BulletMeshContacts, ConvexShapesRestOnAMesh) {
    World w;
    w.add(boxShape(Vec3(5, 5, 0.5)), at(0, 0, -0.5), 0);
    btRigidBody* ball = w.add(std::make_shared<btSphereShape>(btScalar(0.5)), at(0, 0, 0.6), 1);
    btRigidBody* crate =
        w.add(std::make_shared<btBoxShape>(btVector3(0.4, 0.4, 0.4)), at(2, 1, 0.5, 0.3), 1);
    for (int step = 0; step < 240; ++step) {
        w.world.stepSimulation(btScalar(1.0 / 60), 0);
    }
    // Bullet's GJK works with the convex's margin (0.04): rest within it.
    EXPECT_NEAR(ball->getWorldTransform().getOrigin().z(), 0.5, 0.05);
    EXPECT_NEAR(crate->getWorldTransform().getOrigin().z(), 0.4, 0.05);
    EXPECT_LT(ball->getLinearVelocity().length(), 0.05);
    EXPECT_LT(crate->getLinearVelocity().length(), 0.05);
}

/// Compounds keep Bullet's compound algorithm, which hands each child to the pairs above:
/// a convex child and a mesh child, each 0.05 into a mesh ground.
TEST(BulletMeshContacts, CompoundChildrenReachTheMeshAlgorithms) {
    World w;
    btRigidBody* ground = w.add(boxShape(Vec3(5, 5, 0.5)), at(0, 0, -0.5), 0);
    auto compound = std::make_shared<btCompoundShape>();
    auto box = std::make_shared<btBoxShape>(btVector3(0.5, 0.5, 0.5));
    auto mesh = boxShape(Vec3(0.5, 0.5, 0.5));
    compound->addChildShape(at(-1, 0, 0), box.get());
    compound->addChildShape(at(1, 0, 0), mesh.get());
    w.shapes.push_back(box);
    w.shapes.push_back(mesh);
    // Away from the ground's top diagonal: Bullet's per-triangle convex test gives a convex
    // straddling an internal edge a sideways normal (its internal-edge problem, which the
    // convex child inherits; bullet_mesh.h).
    btRigidBody* body = w.add(compound, at(0, 2, 0.45), 1);
    ContactCollector collector;
    w.world.contactPairTest(body, ground, collector);
    bool convexChild = false, meshChild = false;
    for (const btManifoldPoint& p : collector.points) {
        EXPECT_NEAR(p.m_normalWorldOnB.z(), 1, 1e-4);  // on the ground, towards the body
        const btVector3 onGround = p.getPositionWorldOnB();
        convexChild = convexChild || onGround.x() < -0.4;
        meshChild = meshChild || onGround.x() > 0.4;
        if (onGround.x() > 0.4) {
            EXPECT_NEAR(p.getDistance(), -0.05, 1e-5);  // the exact mesh-mesh depth
        }
    }
    EXPECT_TRUE(convexChild);
    EXPECT_TRUE(meshChild);
}

/// Regression: the query takes B's triangles' boxes in A's frame, and the mesh it used as A
/// was Bullet's body0, i.e. whichever was created first. On mesh-wall (bodies resting on a
/// box-mesh ground) the bodies' frame took 14x the exact tests of the ground's (333 133
/// against 23 074 over 2 s at 1/240 s) and 0.69x of GImpact margin 0's narrowphase time
/// against 0.32x; the scene had the good order by chance. The frame is now the mesh with the
/// larger triangles, whatever the order, and lastContacts still names body0's triangles X.
TEST(BulletMeshContacts, TheQueryFrameIsTheCoarserMeshWhateverTheCreationOrder) {
    auto ground = boxShape(Vec3(5, 5, 0.5));
    auto grid = std::make_shared<MeshShape>(kolize::makeMeshModel(gridMesh(20, 0.1)));
    EXPECT_GT(ground->meanTriangleSize(), 50 * grid->meanTriangleSize());
    // The grid tilted through the ground's top face (z = 0).
    btTransform tilted = at(0.3, -0.2, 0.05);
    tilted.setRotation(btQuaternion(btVector3(1, 1, 0).normalized(), btScalar(0.6)));
    std::uint64_t tests[2] = {0, 0};
    for (int groundFirst = 0; groundFirst < 2; ++groundFirst) {
        SCOPED_TRACE(groundFirst ? "ground created first" : "grid created first");
        World w;
        btRigidBody* a = w.add(groundFirst ? std::shared_ptr<btCollisionShape>(ground) : grid,
                               groundFirst ? at(0, 0, -0.5) : tilted, groundFirst ? 0 : 1);
        btRigidBody* b = w.add(groundFirst ? std::shared_ptr<btCollisionShape>(grid) : ground,
                               groundFirst ? tilted : at(0, 0, -0.5), groundFirst ? 1 : 0);
        w.world.performDiscreteCollisionDetection();
        tests[groundFirst] = kolize::narrowphaseStages(&w.dispatcher).triangle_tests;
        auto* algorithm = dynamic_cast<kolize::MeshMeshAlgorithm*>(w.algorithm(a, b));
        ASSERT_NE(algorithm, nullptr);
        // Bullet's body0 of the pair (the smaller proxy id): the body created first.
        btBroadphasePair* pair =
            w.world.getPairCache()->findPair(a->getBroadphaseHandle(), b->getBroadphaseHandle());
        ASSERT_NE(pair, nullptr);
        const bool groundIsBody0 =
            (static_cast<btCollisionObject*>(pair->m_pProxy0->m_clientObject) == a) ==
            bool(groundFirst);
        const std::vector<kolize::MeshContact>& contacts = algorithm->lastContacts();
        ASSERT_FALSE(contacts.empty());
        for (const kolize::MeshContact& c : contacts) {
            // X is body0: the normal points from body0 towards body1 (up, out of the ground's
            // top, when the ground is body0), and X's triangle is one of body0's.
            const double up = c.normal.z();
            EXPECT_GT(groundIsBody0 ? up : -up, 0.9);
            const std::int32_t groundTriangle = groundIsBody0 ? c.triangleX : c.triangleY;
            const std::int32_t gridTriangle = groundIsBody0 ? c.triangleY : c.triangleX;
            EXPECT_LT(groundTriangle, 12);
            EXPECT_GE(gridTriangle, 0);
            EXPECT_LT(gridTriangle, 800);
        }
    }
    EXPECT_GT(tests[0], 0u);
    EXPECT_EQ(tests[0], tests[1]);
    // The algorithm's count is the ground frame's (and not the grid frame's, which differs).
    kolize::narrowphase::Pose groundPose, gridPose;
    groundPose.translation = Vec3(0, 0, -0.5);
    const btMatrix3x3& r = tilted.getBasis();
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            gridPose.rotation(i, j) = r[i][j];
        }
    }
    gridPose.translation = toVec3(tilted.getOrigin());
    kolize::narrowphase::QuerySettings settings;
    settings.mode = kolize::narrowphase::QueryMode::kContacts;
    kolize::narrowphase::MeshQuery query;
    const std::uint64_t inGround =
        query.run(ground->model(), groundPose, grid->model(), gridPose, settings)
            .counters.triangle_tests;
    const std::uint64_t inGrid =
        query.run(grid->model(), gridPose, ground->model(), groundPose, settings)
            .counters.triangle_tests;
    EXPECT_NE(inGrid, inGround);  // the order is seen: the two frames test different pairs
    EXPECT_EQ(tests[0], inGround);
}

/// `a` and `b` are one contact with X and Y exchanged: the same point and depth, the normal
/// turned, the triangle ids swapped (bit for bit).
void expectExchanged(const kolize::MeshContact& a, const kolize::MeshContact& b) {
    EXPECT_EQ(a.point, b.point);
    EXPECT_EQ(a.normal, Vec3(-b.normal));
    EXPECT_EQ(a.depth, b.depth);
    EXPECT_EQ(a.triangleX, b.triangleY);
    EXPECT_EQ(a.triangleY, b.triangleX);
}

/// A shape rescaled between two queries can swap the query's frame (the mesh with the larger
/// triangles): the pair's kept traversal front then belongs to the other order. The contacts
/// after the swap are a fresh pair's, and they still name body0 X: those of the same scene
/// created in the other order (no swap), with X and Y exchanged.
TEST(BulletMeshContacts, ARescaledShapeThatSwapsTheQueryFrameGetsAFreshPairsContacts) {
    auto model = kolize::makeMeshModel(gridMesh(20, 0.1));
    btTransform crossing = at(0.13, -0.07, 0.02);
    crossing.setRotation(btQuaternion(btVector3(1, 0.3, 0).normalized(), btScalar(0.9)));
    const btVector3 bigger(1.01f, 1.01f, 1.01f);
    auto contactsOf = [&](bool scaledFirst, bool rescaleLater) {
        World w;
        auto flat = std::make_shared<MeshShape>(model);
        auto tilted = std::make_shared<MeshShape>(model);
        if (!rescaleLater) {
            tilted->setLocalScaling(bigger);
        }
        btRigidBody* a = scaledFirst ? w.add(tilted, crossing, 1) : w.add(flat, at(0, 0, 0), 0);
        btRigidBody* b = scaledFirst ? w.add(flat, at(0, 0, 0), 0) : w.add(tilted, crossing, 1);
        for (int i = 0; i < 3; ++i) {
            w.world.performDiscreteCollisionDetection();  // the front is kept from here on
        }
        if (rescaleLater) {
            EXPECT_EQ(flat->meanTriangleSize(), tilted->meanTriangleSize());  // X = body0
            tilted->setLocalScaling(bigger);
            EXPECT_GT(tilted->meanTriangleSize(), flat->meanTriangleSize());  // now X = body1
            w.world.updateAabbs();
            w.world.performDiscreteCollisionDetection();
        }
        auto* algorithm = dynamic_cast<kolize::MeshMeshAlgorithm*>(w.algorithm(a, b));
        EXPECT_NE(algorithm, nullptr);
        return algorithm ? algorithm->lastContacts() : std::vector<kolize::MeshContact>();
    };
    const std::vector<kolize::MeshContact> swapped = contactsOf(false, true);
    const std::vector<kolize::MeshContact> fresh = contactsOf(false, false);
    const std::vector<kolize::MeshContact> otherOrder = contactsOf(true, false);
    ASSERT_FALSE(swapped.empty());
    ASSERT_EQ(swapped.size(), fresh.size());
    ASSERT_EQ(swapped.size(), otherOrder.size());
    for (std::size_t i = 0; i < swapped.size(); ++i) {
        SCOPED_TRACE("contact " + std::to_string(i));
        const kolize::MeshContact &s = swapped[i], &f = fresh[i], &o = otherOrder[i];
        EXPECT_EQ(s.point, f.point);
        EXPECT_EQ(s.normal, f.normal);
        EXPECT_EQ(s.depth, f.depth);
        EXPECT_EQ(s.triangleX, f.triangleX);
        EXPECT_EQ(s.triangleY, f.triangleY);
        expectExchanged(s, o);
    }
}

/// The contacts of two meshes whose triangles differ in size do not depend on which body was
/// created first (Bullet's body0): the query runs in the coarser mesh's frame either way, and
/// the contacts of one order are the other's with X and Y exchanged. Seeded random poses of
/// three pairs (a box mesh and a fine grid, two boxes of different sizes, two grids).
TEST(BulletMeshContacts, ContactsDoNotDependOnCreationOrder) {
    const unsigned seed = 4242;
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(-1, 1);
    struct Pair {
        std::shared_ptr<MeshShape> first, second;
    };
    const std::vector<Pair> pairs = {
        {boxShape(Vec3(1, 1, 0.5)),
         std::make_shared<MeshShape>(kolize::makeMeshModel(gridMesh(12, 0.15)))},
        {boxShape(Vec3(0.5, 0.5, 0.5)), boxShape(Vec3(2, 1.5, 0.4))},
        {std::make_shared<MeshShape>(kolize::makeMeshModel(gridMesh(10, 0.2))),
         std::make_shared<MeshShape>(kolize::makeMeshModel(gridMesh(16, 0.1)))}};
    auto contactsOf = [](const Pair& p, bool firstFirst, const btTransform& pose) {
        World w;
        btRigidBody* a = firstFirst ? w.add(p.first, at(0, 0, 0), 0) : w.add(p.second, pose, 1);
        btRigidBody* b = firstFirst ? w.add(p.second, pose, 1) : w.add(p.first, at(0, 0, 0), 0);
        w.world.performDiscreteCollisionDetection();
        auto* algorithm = dynamic_cast<kolize::MeshMeshAlgorithm*>(w.algorithm(a, b));
        return algorithm ? algorithm->lastContacts() : std::vector<kolize::MeshContact>();
    };
    int touching = 0;
    for (std::size_t k = 0; k < pairs.size(); ++k) {
        ASSERT_NE(pairs[k].first->meanTriangleSize(), pairs[k].second->meanTriangleSize());
        for (int i = 0; i < 15; ++i) {
            SCOPED_TRACE("pair " + std::to_string(k) + ", pose " + std::to_string(i));
            btTransform pose = at(0.5 * unit(rng), 0.5 * unit(rng), 0.3 * unit(rng));
            pose.setRotation(btQuaternion(
                btVector3(btScalar(unit(rng)), btScalar(unit(rng)), btScalar(unit(rng) + 2))
                    .normalized(),
                btScalar(3 * unit(rng))));
            const std::vector<kolize::MeshContact> one = contactsOf(pairs[k], true, pose);
            const std::vector<kolize::MeshContact> other = contactsOf(pairs[k], false, pose);
            ASSERT_EQ(one.size(), other.size());
            touching += one.empty() ? 0 : 1;
            for (std::size_t c = 0; c < one.size(); ++c) {
                expectExchanged(one[c], other[c]);
            }
        }
    }
    EXPECT_GE(touching, 20);  // the sample is mostly in contact
}

/// Scaled scenery (btScaledBvhTriangleMeshShape) goes through the same algorithm.
TEST(BulletMeshContacts, ScaledSceneryIsMeshScenery) {
    World w;
    btTriangleMesh triangles;
    triangles.addTriangle(btVector3(-1, -1, 0), btVector3(1, -1, 0), btVector3(1, 1, 0));
    triangles.addTriangle(btVector3(-1, -1, 0), btVector3(1, 1, 0), btVector3(-1, 1, 0));
    auto floor = std::make_shared<btBvhTriangleMeshShape>(&triangles, true);
    w.shapes.push_back(floor);
    btRigidBody* scenery =
        w.add(std::make_shared<btScaledBvhTriangleMeshShape>(floor.get(), btVector3(3, 3, 1)),
              at(0, 0, 0), 0);
    // Outside the unscaled floor (|x| > 1), inside the scaled one.
    btRigidBody* body = w.add(boxShape(Vec3(0.5, 0.5, 0.5)), at(2, 2, 0.48), 1);
    w.world.performDiscreteCollisionDetection();
    auto* algorithm = dynamic_cast<kolize::BvhMeshAlgorithm*>(w.algorithm(scenery, body));
    ASSERT_NE(algorithm, nullptr);
    EXPECT_EQ(algorithm->lastContacts().size(), 4u);
    ContactCollector collector;
    w.world.contactPairTest(body, scenery, collector);
    ASSERT_FALSE(collector.points.empty());
    for (const btManifoldPoint& p : collector.points) {
        EXPECT_NEAR(p.m_normalWorldOnB.z(), 1, 1e-6);
        EXPECT_NEAR(p.getDistance(), -0.02, 1e-5);
    }
}

/// Triangle-mesh scenery of 1 m quads (10 x 10, z = 0) at `floorAt` and a unit box mesh at
/// `boxAt`.
struct SceneryAndBox {
    SceneryAndBox(World& w, const btTransform& floorAt, const btTransform& boxAt) {
        addUnitQuads(triangles);
        floor = w.add(std::make_shared<btBvhTriangleMeshShape>(&triangles, true), floorAt, 0);
        box = w.add(boxShape(Vec3(0.5, 0.5, 0.5)), boxAt, 1);
    }
    btTriangleMesh triangles;
    btRigidBody* floor;
    btRigidBody* box;
};

/// A mesh-scenery pair keeps the model (and tree) of the scenery triangles in the mesh's box
/// while they stay the same, bit for bit: a box sliding 1 cm deep across the quads, then the
/// floor raised by 1 mm. Every step's contacts equal those of a fresh pair at the same poses
/// (a new world, whose algorithm builds its model), so a model reused for other triangles or
/// other vertices would show; and the pair built fewer models than it ran queries.
TEST(BulletMeshContacts, SceneryTrianglesAreModelledOnceWhileTheyStayTheSame) {
    World w;
    btTransform floorAt = at(0, 0, 0);
    auto boxAt = [](int step) { return at(-2 + 0.05 * step, 0.3, 0.49, 0.3); };
    SceneryAndBox scene(w, floorAt, boxAt(0));
    const int steps = 81;
    int compared = 0;
    for (int step = 0; step < steps; ++step) {
        SCOPED_TRACE("step " + std::to_string(step));
        if (step == 60) {  // the same triangles under the box, 1 mm higher
            floorAt = at(0, 0, 0.001);
            scene.floor->setWorldTransform(floorAt);
        }
        scene.box->setWorldTransform(boxAt(step));
        w.world.performDiscreteCollisionDetection();
        auto* algorithm =
            dynamic_cast<kolize::BvhMeshAlgorithm*>(w.algorithm(scene.floor, scene.box));
        ASSERT_NE(algorithm, nullptr);
        World fresh;
        const SceneryAndBox again(fresh, floorAt, boxAt(step));
        fresh.world.performDiscreteCollisionDetection();
        EXPECT_EQ(kolize::narrowphaseStages(&fresh.dispatcher).scenery_models_built, 1u);
        auto* reference =
            dynamic_cast<kolize::BvhMeshAlgorithm*>(fresh.algorithm(again.floor, again.box));
        ASSERT_NE(reference, nullptr);
        const std::vector<kolize::MeshContact>& got = algorithm->lastContacts();
        const std::vector<kolize::MeshContact>& want = reference->lastContacts();
        ASSERT_EQ(got.size(), want.size());
        for (std::size_t i = 0; i < got.size(); ++i) {
            EXPECT_EQ(got[i].point, want[i].point) << "contact " << i;
            EXPECT_EQ(got[i].normal, want[i].normal) << "contact " << i;
            EXPECT_EQ(got[i].depth, want[i].depth) << "contact " << i;
            EXPECT_EQ(got[i].triangleX, want[i].triangleX) << "contact " << i;
            EXPECT_EQ(got[i].partY, want[i].partY) << "contact " << i;
            EXPECT_EQ(got[i].triangleY, want[i].triangleY) << "contact " << i;
        }
        compared += got.empty() ? 0 : 1;
    }
    EXPECT_EQ(compared, steps);  // the box touched the floor at every step
    const kolize::MeshStageStats stats = kolize::narrowphaseStages(&w.dispatcher);
    EXPECT_EQ(stats.mesh_scenery_queries, std::uint64_t(steps));
    // Rebuilt as the box's box crossed the quads' edges (4 m over edges 1 m apart) and when
    // the floor moved; reused in between.
    EXPECT_GE(stats.scenery_models_built, 6u);
    EXPECT_LE(stats.scenery_models_built, std::uint64_t(steps / 4));
}

/// The signed distances of a unit box mesh's corners (half extent 0.5) at `pose` to the plane
/// n.x = d, the lowest first.
std::vector<double> cornerHeights(const btTransform& pose, const Vec3& n, double d) {
    std::vector<double> out;
    for (int i = 0; i < 8; ++i) {
        const btVector3 corner =
            pose * btVector3(i & 1 ? 0.5f : -0.5f, i & 2 ? 0.5f : -0.5f, i & 4 ? 0.5f : -0.5f);
        out.push_back(n.dot(toVec3(corner)) - d);
    }
    std::sort(out.begin(), out.end());
    return out;
}

/// A MeshShape body on Bullet's other static concave grounds: a tilted btStaticPlaneShape and
/// a btHeightfieldTerrainShape ramp (z = 0.1 x, its quads in the ramp's plane). Bullet has
/// no algorithm for two concave shapes (btEmptyAlgorithm): unregistered, the box falls
/// through (the control). Registered, a box put 1 cm deep, its bottom face parallel to the
/// ground, gets 3 or 4 contacts along the ground's normal at exactly that depth, each half
/// the depth above its corner (its corners found inside: the heightfield's triangles are
/// wound against the side facing the box, which the inside test once refused, leaving points
/// on the intersection curve); a box dropped tilted from 20 cm comes to rest on it and stays
/// at rest (Bullet's own plane triangles, centred on the box, kicked it after 3.8 s).
TEST(BulletMeshContacts, MeshesRestOnStaticPlanesAndHeightfields) {
    struct Ground {
        const char* name;
        Vec3 normal;    // unit, up
        double offset;  // the ground is normal . x = offset
    };
    const Vec3 tilted = Vec3(0.1, -0.05, 1).normalized();
    const Vec3 ramp = Vec3(-0.1, 0, 1).normalized();
    const Ground grounds[] = {{"plane", tilted, 0.2}, {"heightfield", ramp, 0.0}};
    const int sticks = 21;  // a 20 m x 20 m heightfield of 1 m quads, heights 0.1 x
    std::vector<float> heights;
    for (int j = 0; j < sticks; ++j) {
        for (int i = 0; i < sticks; ++i) {
            heights.push_back(float(0.1 * (i - (sticks - 1) / 2)));
        }
    }
    auto addGround = [&](World& w, const Ground& g) -> btRigidBody* {
        if (std::string(g.name) == "plane") {
            return w.add(std::make_shared<btStaticPlaneShape>(
                             btVector3(btScalar(g.normal.x()), btScalar(g.normal.y()),
                                       btScalar(g.normal.z())),
                             btScalar(g.offset)),
                         at(0, 0, 0), 0);
        }
        return w.add(std::make_shared<btHeightfieldTerrainShape>(
                         sticks, sticks, heights.data(), btScalar(-1), btScalar(1), 2, false),
                     at(0, 0, 0), 0);
    };
    // The box with its bottom face on the ground's plane moved `lift` along the normal, over
    // the point (x, y) of the ground, turned about the normal by `yaw`.
    auto onGround = [](const Ground& g, double x, double y, double lift, double yaw) {
        const Vec3 up = g.normal;
        const double z = (g.offset - up.x() * x - up.y() * y) / up.z();  // on the plane
        const Vec3 centre = Vec3(x, y, z) + (0.5 + lift) * up;
        const btQuaternion align = shortestArcQuat(
            btVector3(0, 0, 1), btVector3(btScalar(up.x()), btScalar(up.y()), btScalar(up.z())));
        btTransform t;
        t.setRotation(btQuaternion(btVector3(btScalar(up.x()), btScalar(up.y()), btScalar(up.z())),
                                   btScalar(yaw)) *
                      align);
        t.setOrigin(btVector3(btScalar(centre.x()), btScalar(centre.y()), btScalar(centre.z())));
        return t;
    };
    for (const Ground& g : grounds) {
        SCOPED_TRACE(g.name);
        {  // The control: Bullet alone lets the mesh body through.
            World plain(false);
            addGround(plain, g);
            btRigidBody* box =
                plain.add(boxShape(Vec3::Constant(0.5)), onGround(g, 1, 2, 0.2, 0.3), 1);
            for (int step = 0; step < 120; ++step) {
                plain.world.stepSimulation(btScalar(1.0 / 60), 0);
            }
            EXPECT_LT(cornerHeights(box->getWorldTransform(), g.normal, g.offset).back(), -1.0);
        }
        {  // Exact contacts of a box 1 cm deep.
            World w;
            btRigidBody* ground = addGround(w, g);
            const btTransform pose = onGround(g, 1.3, -0.6, -0.01, 0.4);
            btRigidBody* box = w.add(boxShape(Vec3::Constant(0.5)), pose, 1);
            const std::vector<double> corners = cornerHeights(pose, g.normal, g.offset);
            w.world.performDiscreteCollisionDetection();
            auto* algorithm = dynamic_cast<kolize::BvhMeshAlgorithm*>(w.algorithm(ground, box));
            ASSERT_NE(algorithm, nullptr);
            const std::vector<kolize::MeshContact>& contacts = algorithm->lastContacts();
            EXPECT_GE(contacts.size(), 3u);
            EXPECT_LE(contacts.size(), 4u);
            for (const kolize::MeshContact& c : contacts) {
                // X is the mesh: the normal points from it into the ground.
                EXPECT_LT((c.normal + g.normal).norm(), 1e-5);
                EXPECT_NEAR(c.depth, -corners.front(), 1e-5);
                const Vec3 onGroundPoint = c.point - 0.5 * c.depth * c.normal;
                EXPECT_NEAR(g.normal.dot(onGroundPoint) - g.offset, 0, 1e-5);
            }
        }
        {  // Dropped tilted from 20 cm, it comes to rest on the ground and stays there.
            World w;
            addGround(w, g);
            btTransform start = onGround(g, -2, 1, 0.2, 0.7);
            start.setRotation(start.getRotation() *
                              btQuaternion(btVector3(1, 1, 0).normalized(), btScalar(0.3)));
            btRigidBody* box = w.add(boxShape(Vec3::Constant(0.5)), start, 1);
            double lowest = 1e9, lateSpeed = 0;
            for (int step = 0; step < 300; ++step) {
                w.world.stepSimulation(btScalar(1.0 / 60), 0);
                lowest = std::min(
                    lowest, cornerHeights(box->getWorldTransform(), g.normal, g.offset).front());
                if (step >= 120) {  // settled after 2 s
                    lateSpeed = std::max({lateSpeed, double(box->getLinearVelocity().length()),
                                          double(box->getAngularVelocity().length())});
                }
            }
            const std::vector<double> corners =
                cornerHeights(box->getWorldTransform(), g.normal, g.offset);
            // Never through: at most the landing step's travel (2 m/s x 1/60 s) deep.
            EXPECT_GT(lowest, -0.05);
            EXPECT_NEAR(corners.front(), 0, 0.01);
            EXPECT_NEAR(corners[3], 0, 0.01);  // a face down: four corners on the ground
            // No kick at rest (Bullet's own plane triangles, centred on the moving box, gave
            // this box 0.11 m/s and 0.22 rad/s after 3.8 s).
            EXPECT_LT(lateSpeed, 0.05);
        }
    }
}

/// A btStaticPlaneShape is a half-space, as Bullet takes it for its convex shapes: a mesh
/// body's vertices on or below it are in it, whatever side its centre is on. As two-sided
/// scenery triangles, a box whose centre had sunk 1 cm below the plane got normals that
/// pushed it down (it fell 5.5 m in 1 s), one wholly below met nothing, and a box dropped at
/// 100 m/s went through; a box at rest on a plane was kicked to 0.04 m/s (0.003 on the same
/// floor as two triangles). The reference for the dynamics is Bullet's own btBoxShape.
TEST(BulletMeshContacts, AStaticPlaneIsAHalfSpace) {
    const Vec3 up(0, 0, 1);
    auto plane = [] { return std::make_shared<btStaticPlaneShape>(btVector3(0, 0, 1), 0); };
    auto tiltedAt = [](double z) {
        btTransform t = at(0.3, -0.2, z);
        t.setRotation(btQuaternion(btVector3(1, 0.5, 0).normalized(), btScalar(0.2)));
        return t;
    };
    for (double z : {0.4, -0.01, -0.2, -0.6}) {  // -0.6: wholly below
        SCOPED_TRACE(z);
        World w;
        btRigidBody* ground = w.add(plane(), at(0, 0, 0), 0);
        const btTransform pose = tiltedAt(z);
        btRigidBody* box = w.add(boxShape(Vec3::Constant(0.5)), pose, 1);
        w.world.performDiscreteCollisionDetection();
        auto* algorithm = dynamic_cast<kolize::BvhMeshAlgorithm*>(w.algorithm(ground, box));
        ASSERT_NE(algorithm, nullptr);
        const std::vector<double> corners = cornerHeights(pose, up, 0);
        const auto below = std::size_t(
            std::count_if(corners.begin(), corners.end(), [](double h) { return h <= 0; }));
        const std::vector<kolize::MeshContact>& contacts = algorithm->lastContacts();
        ASSERT_EQ(contacts.size(), std::min<std::size_t>(below, 4));
        EXPECT_NEAR(contacts.front().depth, -corners.front(), 1e-5);  // the deepest first
        for (const kolize::MeshContact& c : contacts) {
            EXPECT_LT((c.normal + up).norm(), 1e-6);  // from the mesh into the plane
            // The depth of a corner below the plane, the point halfway to its foot.
            const double corner =
                *std::min_element(corners.begin(), corners.end(), [&](double x, double y) {
                    return std::fabs(x + c.depth) < std::fabs(y + c.depth);
                });
            EXPECT_LT(std::fabs(corner + c.depth), 1e-5);
            EXPECT_NEAR(c.point.z(), -0.5 * c.depth, 1e-5);
            EXPECT_EQ(c.triangleY, -1);  // the plane has no triangles
            EXPECT_GE(c.triangleX, 0);
        }
    }
    {  // A plane body turned and moved: the plane n . x = 0.1 of its frame, in the world.
        World w;
        btTransform planeAt = at(1, 2, 3);
        planeAt.setRotation(btQuaternion(btVector3(1, 0.2, 0).normalized(), btScalar(0.3)));
        btRigidBody* ground = w.add(
            std::make_shared<btStaticPlaneShape>(btVector3(0, 0, 1), btScalar(0.1)), planeAt, 0);
        const btVector3 worldUp = planeAt.getBasis() * btVector3(0, 0, 1);
        const Vec3 n = toVec3(worldUp).normalized();
        const double offset = 0.1 + n.dot(toVec3(planeAt.getOrigin()));
        // A box turned as above with its centre 1 cm below the plane.
        btTransform pose = tiltedAt(0);
        pose.setOrigin(btVector3(btScalar(0.5), btScalar(1.5), btScalar(0)));
        const double shift = offset - n.dot(toVec3(pose.getOrigin())) - 0.01;
        pose.setOrigin(pose.getOrigin() + worldUp * btScalar(shift));
        btRigidBody* box = w.add(boxShape(Vec3::Constant(0.5)), pose, 1);
        w.world.performDiscreteCollisionDetection();
        auto* algorithm = dynamic_cast<kolize::BvhMeshAlgorithm*>(w.algorithm(ground, box));
        ASSERT_NE(algorithm, nullptr);
        const std::vector<double> corners = cornerHeights(pose, n, offset);
        const std::vector<kolize::MeshContact>& contacts = algorithm->lastContacts();
        ASSERT_EQ(contacts.size(), 4u);
        EXPECT_NEAR(contacts.front().depth, -corners.front(), 1e-5);
        for (const kolize::MeshContact& c : contacts) {
            EXPECT_LT((c.normal + n).norm(), 1e-5);
            EXPECT_NEAR(n.dot(c.point) - offset, -0.5 * c.depth, 1e-5);
        }
    }
    // Pushed out as Bullet pushes its own box out, from 1 cm, 20 cm and wholly below.
    for (double z : {-0.01, -0.2, -0.6}) {
        SCOPED_TRACE(z);
        for (bool mesh : {true, false}) {
            World w;
            w.add(plane(), at(0, 0, 0), 0);
            std::shared_ptr<btCollisionShape> shape = boxShape(Vec3::Constant(0.5));
            if (!mesh) {
                shape = std::make_shared<btBoxShape>(btVector3(0.5, 0.5, 0.5));
            }
            btRigidBody* box = w.add(shape, tiltedAt(z), 1);
            for (int step = 0; step < 120; ++step) {
                w.world.stepSimulation(btScalar(1.0 / 60), 0);
            }
            EXPECT_NEAR(box->getWorldTransform().getOrigin().z(), 0.5, 0.02) << mesh;
        }
    }
    {  // Dropped at 200 m/s without CCD (3.3 m per step: wholly below after the first step),
       // it is pushed back out and comes to rest on the plane. (Bullet's own btBoxShape from
       // the same pose and speed ends 7.6 m up after 3 s.)
        World w;
        w.add(plane(), at(0, 0, 0), 0);
        btRigidBody* box = w.add(boxShape(Vec3::Constant(0.5)), tiltedAt(1), 1);
        box->setLinearVelocity(btVector3(0, 0, -200));
        for (int step = 0; step < 180; ++step) {
            w.world.stepSimulation(btScalar(1.0 / 60), 0);
        }
        EXPECT_NEAR(box->getWorldTransform().getOrigin().z(), 0.5, 0.01);
        EXPECT_LT(box->getLinearVelocity().length(), 0.05);
    }
    {  // At rest for 20 s after settling for 2 s: no kick.
        World w;
        w.add(plane(), at(0, 0, 0), 0);
        btRigidBody* box = w.add(boxShape(Vec3::Constant(0.5)), at(0.3, 0.2, 0.5005, 0.4), 1);
        for (int step = 0; step < 120; ++step) {
            w.world.stepSimulation(btScalar(1.0 / 60), 0);
        }
        const btVector3 settled = box->getWorldTransform().getOrigin();
        double fastest = 0;
        for (int step = 0; step < 1200; ++step) {
            w.world.stepSimulation(btScalar(1.0 / 60), 0);
            fastest = std::max({fastest, double(box->getLinearVelocity().length()),
                                double(box->getAngularVelocity().length())});
        }
        EXPECT_LT(fastest, 1e-3);
        EXPECT_LT((box->getWorldTransform().getOrigin() - settled).length(), 1e-3);
    }
    {  // A contact margin: a box 2 mm above gets separated contacts, one 1 cm above none.
        for (double gap : {0.002, 0.01}) {
            World w;
            kolize::MeshStageSettings settings;
            settings.contact_margin = 0.005;
            kolize::registerNarrowphase(&w.dispatcher, settings);
            btRigidBody* ground = w.add(plane(), at(0, 0, 0), 0);
            btRigidBody* box = w.add(boxShape(Vec3::Constant(0.5)), at(0, 0, 0.5 + gap), 1);
            w.world.performDiscreteCollisionDetection();
            auto* algorithm = dynamic_cast<kolize::BvhMeshAlgorithm*>(w.algorithm(ground, box));
            ASSERT_NE(algorithm, nullptr);
            const std::vector<kolize::MeshContact>& contacts = algorithm->lastContacts();
            EXPECT_EQ(contacts.size(), gap < 0.005 ? 4u : 0u) << gap;
            for (const kolize::MeshContact& c : contacts) {
                EXPECT_NEAR(c.depth, -gap, 1e-6);  // apart: a negative depth, never penetration
                EXPECT_LT((c.normal + up).norm(), 1e-6);
            }
        }
    }
}

TEST(BulletMeshContacts, MultimaterialSceneryNamesEachContactsTriangleAndMaterial) {
    // Two 2 m x 2 m quads at z = 0, x < 0 of material 0 and x > 0 of material 1, wound up.
    btScalar vertices[] = {-2, -1, 0, 0, -1, 0, 0, 1, 0, -2, 1, 0, 2, -1, 0, 2, 1, 0};
    int indices[] = {0, 1, 2, 0, 2, 3, 1, 4, 5, 1, 5, 2};
    btMaterial materials[] = {btMaterial(btScalar(0.1), btScalar(0)),
                              btMaterial(btScalar(0.9), btScalar(0.5))};
    int materialOf[] = {0, 0, 1, 1};
    btTriangleIndexVertexMaterialArray data(4, indices, 3 * int(sizeof(int)), 6, vertices,
                                            3 * int(sizeof(btScalar)), 2,
                                            reinterpret_cast<unsigned char*>(materials),
                                            int(sizeof(btMaterial)), materialOf, int(sizeof(int)));
    auto multimaterial = [&] {
        return std::make_shared<btMultimaterialTriangleMeshShape>(&data, true);
    };
    {  // The control: unregistered, Bullet has no algorithm and the mesh body falls through.
        World plain(false);
        plain.add(multimaterial(), at(0, 0, 0), 0);
        btRigidBody* box = plain.add(boxShape(Vec3::Constant(0.5)), at(-1, 0, 0.6), 1);
        for (int step = 0; step < 120; ++step) {
            plain.world.stepSimulation(btScalar(1.0 / 60), 0);
        }
        EXPECT_LT(box->getWorldTransform().getOrigin().z(), -1);
    }
    // A box 1 cm deep over the left quad, over the right one, and across both.
    for (double x : {-1.0, 1.0, 0.0}) {
        SCOPED_TRACE(x);
        World w;
        auto shape = multimaterial();
        btRigidBody* floor = w.add(shape, at(0, 0, 0), 0);
        btRigidBody* box = w.add(boxShape(Vec3::Constant(0.5)), at(x, 0, 0.49, 0.3), 1);
        w.world.performDiscreteCollisionDetection();
        auto* algorithm = dynamic_cast<kolize::BvhMeshAlgorithm*>(w.algorithm(floor, box));
        ASSERT_NE(algorithm, nullptr);
        const std::vector<kolize::MeshContact>& contacts = algorithm->lastContacts();
        EXPECT_GE(contacts.size(), 3u);
        std::set<int> seen;
        for (const kolize::MeshContact& c : contacts) {
            EXPECT_LT((c.normal - Vec3(0, 0, -1)).norm(), 1e-5);  // X = the mesh, into the floor
            EXPECT_NEAR(c.depth, 0.01, 1e-5);
            // The floor's triangle holds the point's foot, and its material is the side's.
            ASSERT_GE(c.triangleY, 0);
            ASSERT_LT(c.triangleY, 4);
            EXPECT_EQ(c.partY, 0);
            EXPECT_EQ(materialOf[c.triangleY], c.point.x() < 0 ? 0 : 1) << c.point.x();
            seen.insert(materialOf[c.triangleY]);
        }
        EXPECT_EQ(seen.size(), x == 0.0 ? 2u : 1u);
        // What a contact callback gets: the manifold point's ids on the floor's side name the
        // material of the floor under the point.
        const btPersistentManifold* manifold = onlyManifold(algorithm);
        ASSERT_NE(manifold, nullptr);
        ASSERT_GE(manifold->getNumContacts(), 3);
        for (int k = 0; k < manifold->getNumContacts(); ++k) {
            const btManifoldPoint& p = manifold->getContactPoint(k);
            const bool floorFirst = manifold->getBody0() == floor;
            const int part = floorFirst ? p.m_partId0 : p.m_partId1;
            const int index = floorFirst ? p.m_index0 : p.m_index1;
            ASSERT_EQ(part, 0);
            ASSERT_GE(index, 0);
            ASSERT_LT(index, 4);
            const btMaterial* material = shape->getMaterialProperties(part, index);
            const double pointX = 0.5 * (p.getPositionWorldOnA().x() + p.getPositionWorldOnB().x());
            EXPECT_EQ(material->m_friction, pointX < 0 ? btScalar(0.1) : btScalar(0.9)) << pointX;
        }
    }
    {  // At rest on it: face down on the floor, as on a btBvhTriangleMeshShape.
        World w;
        w.add(multimaterial(), at(0, 0, 0), 0);
        btRigidBody* box = w.add(boxShape(Vec3::Constant(0.5)), at(0.3, 0.2, 0.7, 0.5), 1);
        for (int step = 0; step < 180; ++step) {
            w.world.stepSimulation(btScalar(1.0 / 60), 0);
        }
        EXPECT_NEAR(box->getWorldTransform().getOrigin().z(), 0.5, 0.01);
        EXPECT_LT(box->getLinearVelocity().length(), 0.05);
    }
}

TEST(BulletMeshContacts, NonFiniteSceneryTrianglesAreLeftOut) {
    // A heightfield of 4 x 4 samples (3 x 3 quads of 1 m about the origin), flat at 0, with
    // NaN heights: every one, or the corner sample at (-1.5, -1.5) only. A triangle with a
    // NaN corner made the scenery mesh refuse it (MeshError out of stepSimulation).
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (bool allNan : {true, false}) {
        SCOPED_TRACE(allNan ? "every height NaN" : "one corner NaN");
        std::vector<float> heights(16, 0.0f);
        if (allNan) {
            std::fill(heights.begin(), heights.end(), nan);
        } else {
            heights[0] = nan;
        }
        World w;
        w.add(std::make_shared<btHeightfieldTerrainShape>(4, 4, heights.data(), btScalar(-1),
                                                          btScalar(1), 2, false),
              at(0, 0, 0), 0);
        // Over the far corner's quad, and one across the quads around the NaN sample.
        btRigidBody* far = w.add(boxShape(Vec3::Constant(0.3)), at(0.8, 0.8, 0.35), 1);
        btRigidBody* near = w.add(boxShape(Vec3::Constant(0.3)), at(-1.3, -1.3, 0.35), 1);
        for (int step = 0; step < 120; ++step) {
            ASSERT_NO_THROW(w.world.stepSimulation(btScalar(1.0 / 60), 0)) << step;
        }
        const double z = far->getWorldTransform().getOrigin().z();
        if (allNan) {
            EXPECT_LT(z, -1);  // nothing left to meet, as for Bullet's own shapes
        } else {
            EXPECT_NEAR(z, 0.3, 0.01);  // the finite triangles still hold it
        }
        EXPECT_TRUE(std::isfinite(double(near->getWorldTransform().getOrigin().z())));
    }
}

/// Every body's transform and velocity after `steps` steps of a scene, as raw bytes.
template <class Scene>
std::vector<unsigned char> runScene(int steps) {
    World w;
    Scene scene(w);
    for (int step = 0; step < steps; ++step) {
        w.world.stepSimulation(btScalar(1.0 / 60), 0);
    }
    std::vector<unsigned char> bytes;
    auto push = [&](const btVector3& v) {  // x, y, z only: the fourth float is padding
        for (int k = 0; k < 3; ++k) {
            const btScalar value = v[k];
            const auto* p = reinterpret_cast<const unsigned char*>(&value);
            bytes.insert(bytes.end(), p, p + sizeof(value));
        }
    };
    for (const auto& body : w.bodies) {
        const btTransform& t = body->getWorldTransform();
        for (int r = 0; r < 3; ++r) {
            push(t.getBasis()[r]);
        }
        push(t.getOrigin());
        push(body->getLinearVelocity());
        push(body->getAngularVelocity());
    }
    return bytes;
}

TEST(BulletMeshContacts, IdenticalRunsAreBitIdentical) {
    const auto first = runScene<Stack>(120);
    const auto second = runScene<Stack>(120);
    EXPECT_EQ(first, second);
    EXPECT_NE(first, runScene<Stack>(60));  // the bodies did move: the check can fail
    EXPECT_EQ(runScene<Floor>(120), runScene<Floor>(120));
}

}  // namespace
