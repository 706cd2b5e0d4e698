// The eight scenes of Bullet's own benchmark (examples/Benchmarks/BenchmarkDemo.cpp in
// bullet3), rebuilt from a written description of them (body counts, shapes, sizes,
// layouts, joints, solver settings); no code or data of Bullet's examples is used. The
// landscape and the convex pack are regenerated with the same sizes and counts: the
// landscape from a 16 x 16 map of its mean heights, the pack as the Voronoi cells of the
// same Halton points. The scenes are deterministic (SceneOptions::seed varies the
// landscape's small noise and scene 5's shape kinds only). SceneOptions::objects, when below
// the benchmark's count, keeps the first N bodies of the layout (whole ragdolls).

#include "scene_builders.h"
#include "voronoi_cells.h"

#include <kolize/engine/world_scene.h>

#include <BulletCollision/CollisionShapes/btConvexHullShape.h>
#include <LinearMath/btConvexHullComputer.h>
#include <btBulletDynamicsCommon.h>

#include <array>
#include <cmath>
#include <random>
#include <string>
#include <vector>

namespace kolize {

namespace {

constexpr double kPi = 3.14159265358979323846;

btQuaternion about(const btVector3& axis, double angle) {
    return btQuaternion(axis, btScalar(angle));
}

/// How many moving bodies a scene still adds: SceneOptions::objects, or all of the layout.
/// Tests take the first few bodies of a layout; the benchmark runs them all.
struct Budget {
    int left;
    bool take() { return left-- > 0; }
};

/// The benchmark's solver and sleeping defaults: 5 iterations, SIMD, warm starting, friction
/// direction caching; the per-body thresholds are Bullet's (0.8, 1.0) unless a scene says.
void benchmarkSolver(WorldScene& scene, int iterations) {
    btContactSolverInfo& info = scene.world()->getSolverInfo();
    info.m_numIterations = iterations;
    info.m_solverMode =
        SOLVER_SIMD | SOLVER_USE_WARMSTARTING | SOLVER_ENABLE_FRICTION_DIRECTION_CACHING;
}

/// The ground of scenes 1-4: a static box (250, 50, 250) whose top face is y = 0.
void addGround(WorldScene& scene) {
    scene.addBody(scene.own(new btBoxShape(vec(250, 50, 250))), 0, at(vec(0, -50, 0)));
    scene.setContainer(vec(-260, -10, -260), vec(260, 1e9, 260));
}

/// The "Taru" barrel: three rings of 8 points (45 degree steps from +x) at heights -1.99237,
/// 0 and 1.99237 with radii 1.08664, 1.82224 and 1.08664; margin 0.04.
btConvexHullShape* barrel(bool polyhedral) {
    auto* hull = new btConvexHullShape();
    const double heights[3] = {-1.99237, 0, 1.99237}, radii[3] = {1.08664, 1.82224, 1.08664};
    for (int ring = 0; ring < 3; ++ring) {
        for (int k = 0; k < 8; ++k) {
            const double angle = k * kPi / 4;
            hull->addPoint(
                vec(radii[ring] * std::cos(angle), heights[ring], radii[ring] * std::sin(angle)),
                false);
        }
    }
    hull->recalcLocalAabb();
    hull->setMargin(btScalar(0.04));
    if (polyhedral) {
        hull->initializePolyhedralFeatures();
    }
    return hull;
}

// --- scene 1: 3000 boxes ---

void fillBoxes(WorldScene& scene, Budget budget) {
    benchmarkSolver(scene, 5);
    addGround(scene);
    btCollisionShape* cube = scene.own(new btBoxShape(vec(1, 1, 1)));
    for (int k = 0; k < 47; ++k) {
        const double start = -12 - 0.35 * k;
        for (int i = 0; i < 8; ++i) {
            for (int j = 0; j < 8; ++j) {
                if (budget.take()) {
                    scene.addBody(cube, 2, at(vec(start + 3 * i, 2 + 3 * k, start + 3 * j)));
                }
            }
        }
    }
}

// --- scene 2: the 1000 stack (pyramid, three walls, a round tower) ---

void fillStack(WorldScene& scene, Budget budget) {
    benchmarkSolver(scene, 5);
    addGround(scene);
    // Pyramid: 12 square layers from 12 x 12 to 1 x 1, neighbours 0.0401 apart.
    btCollisionShape* pyramidBox = scene.own(new btBoxShape(vec(1, 1, 1)));
    const double pitch = 2.0401;
    for (int layer = 0; layer < 12; ++layer) {
        const int side = 12 - layer;
        const double x0 = -20 - 12.2406 + 1.02 * layer, z0 = -12.2406 + 1.02 * layer;
        for (int i = 0; i < side; ++i) {
            for (int j = 0; j < side; ++j) {
                if (budget.take()) {
                    scene.addBody(pyramidBox, 1,
                                  at(vec(x0 + pitch * i, 1 + pitch * layer, z0 + pitch * j)));
                }
            }
        }
    }
    // Three brick walls in the y-z plane: rows of 12 down to 1, each shifted by half a box.
    for (double x : {-2.0, 4.0, 10.0}) {
        btCollisionShape* brick = scene.own(new btBoxShape(vec(1, 1, 1)));
        for (int row = 0; row < 12; ++row) {
            for (int i = 0; i < 12 - row; ++i) {
                if (budget.take()) {
                    scene.addBody(brick, 1, at(vec(x, 1 + 2 * row, -12 + row + 2 * i)));
                }
            }
        }
    }
    // Round tower: 8 rings of 24 boxes facing the centre, each ring turned 7.5 degrees.
    btCollisionShape* towerBox = scene.own(new btBoxShape(vec(1, 1, 1)));
    const double radius = 1.3 * 24 / kPi;
    for (int ring = 0; ring < 8; ++ring) {
        for (int k = 0; k < 24; ++k) {
            const double angle = (k * 15.0 + ring * 7.5) * kPi / 180;
            const btQuaternion yaw = about(vec(0, 1, 0), angle + kPi);
            const btVector3 offset = btMatrix3x3(about(vec(0, 1, 0), angle)) * vec(0, 0, -radius);
            if (budget.take()) {
                scene.addBody(towerBox, 1, at(vec(25, 1 + 2 * ring, 0) + offset, yaw));
            }
        }
    }
}

// --- scene 3: 136 ragdolls ---

/// One ragdoll (11 capsules, 10 joints) with its base point at `base`.
void addRagdoll(WorldScene& scene, const btVector3& base) {
    enum Part {
        Pelvis,
        Spine,
        Head,
        LeftUpperLeg,
        LeftLowerLeg,
        RightUpperLeg,
        RightLowerLeg,
        LeftUpperArm,
        LeftLowerArm,
        RightUpperArm,
        RightLowerArm,
        Parts
    };
    struct PartShape {
        double radius, length, x, y;
        int roll;  // arms: -1 / +1 quarter turns about z
    };
    const PartShape parts[Parts] = {
        {0.525, 0.70, 0, 3.5, 0},       {0.525, 0.98, 0, 4.2, 0},
        {0.35, 0.175, 0, 5.6, 0},       {0.245, 1.575, -0.63, 2.275, 0},
        {0.175, 1.295, -0.63, 0.7, 0},  {0.245, 1.575, 0.63, 2.275, 0},
        {0.175, 1.295, 0.63, 0.7, 0},   {0.175, 1.155, -1.225, 5.075, 1},
        {0.14, 0.875, -2.45, 5.075, 1}, {0.175, 1.155, 1.225, 5.075, -1},
        {0.14, 0.875, 2.45, 5.075, -1}};
    btRigidBody* bodies[Parts];
    for (int p = 0; p < Parts; ++p) {
        btCollisionShape* shape =
            scene.own(new btCapsuleShape(btScalar(parts[p].radius), btScalar(parts[p].length)));
        const btQuaternion roll = about(vec(0, 0, 1), parts[p].roll * kPi / 2);
        btRigidBody* body =
            scene.addBody(shape, 1, at(base + vec(parts[p].x, parts[p].y, 0), roll));
        body->setDamping(btScalar(0.05), btScalar(0.85));
        body->setDeactivationTime(btScalar(0.8));
        body->setSleepingThresholds(btScalar(1.6), btScalar(2.5));
        bodies[p] = body;
    }
    auto frame = [](double x, double y, const btQuaternion& rotation) {
        return btTransform(rotation, vec(x, y, 0));
    };
    const btQuaternion hingeTurn = about(vec(0, 1, 0), kPi / 2);
    auto hinge = [&](int a, int b, double ya, double yb, double low, double high) {
        auto* joint = new btHingeConstraint(*bodies[a], *bodies[b], frame(0, ya, hingeTurn),
                                            frame(0, yb, hingeTurn));
        joint->setLimit(btScalar(low), btScalar(high));
        scene.addConstraint(joint, true);
    };
    auto cone = [&](int a, int b, const btTransform& inA, const btTransform& inB, double swing,
                    double twist) {
        auto* joint = new btConeTwistConstraint(*bodies[a], *bodies[b], inA, inB);
        joint->setLimit(btScalar(swing), btScalar(swing), btScalar(twist));
        scene.addConstraint(joint, true);
    };
    const btQuaternion none = btQuaternion::getIdentity();
    auto aboutZ = [](double degrees) { return about(vec(0, 0, 1), degrees * kPi / 180); };
    hinge(Pelvis, Spine, 0.525, -0.525, -kPi / 4, kPi / 2);
    cone(Spine, Head, frame(0, 1.05, aboutZ(90)), frame(0, -0.49, aboutZ(90)), kPi / 4, kPi / 2);
    cone(Pelvis, LeftUpperLeg, frame(-0.63, -0.35, aboutZ(-225)), frame(0, 0.7875, aboutZ(-225)),
         kPi / 4, 0);
    hinge(LeftUpperLeg, LeftLowerLeg, -0.7875, 0.6475, 0, kPi / 2);
    cone(Pelvis, RightUpperLeg, frame(0.63, -0.35, aboutZ(45)), frame(0, 0.7875, aboutZ(45)),
         kPi / 4, 0);
    hinge(RightUpperLeg, RightLowerLeg, -0.7875, 0.6475, 0, kPi / 2);
    cone(Spine, LeftUpperArm, frame(-0.7, 0.525, aboutZ(180)), frame(0, -0.63, aboutZ(90)), kPi / 2,
         0);
    hinge(LeftUpperArm, LeftLowerArm, 0.63, -0.49, -kPi / 2, 0);
    cone(Spine, RightUpperArm, frame(0.7, 0.525, none), frame(0, -0.63, aboutZ(90)), kPi / 2, 0);
    hinge(RightUpperArm, RightLowerArm, 0.63, -0.49, -kPi / 2, 0);
}

void fillRagdolls(WorldScene& scene, Budget budget) {
    benchmarkSolver(scene, 5);
    addGround(scene);
    for (int row = 0; row < 16; ++row) {
        for (int i = 0; i < 16 - row; ++i) {
            budget.left -= 10;  // 11 bodies each
            if (budget.take()) {
                addRagdoll(scene, vec(-3 * (16 - row) + 6 * i, 1 + 7 * row, -2 * row));
            }
        }
    }
}

// --- scene 4: convex stack ---

void fillConvexStack(WorldScene& scene, Budget budget) {
    benchmarkSolver(scene, 5);
    addGround(scene);
    btCollisionShape* hull = scene.own(barrel(true));
    double start = -18, height = 3;
    for (int k = 0; k < 15; ++k) {
        const double gap = 1.5 * std::pow(1.01, k);
        if (k > 0) {
            start -= 0.525 * std::pow(1.01, k - 1);
            height += 3 + gap;
        }
        for (int i = 0; i < 8; ++i) {
            for (int j = 0; j < 8; ++j) {
                if (budget.take()) {
                    scene.addBody(hull, 1,
                                  at(vec(start + (3 + gap) * i, height, start + (3 + gap) * j)));
                }
            }
        }
    }
}

// --- scenes 5-7: bodies raining onto a hilly landscape ---

/// Mean local heights of 16 x 16 blocks of the landscape (rows: z from -250 up; columns: x
/// from -250 right), from the description of Bullet's landscape.
constexpr int kBlocks = 16;
constexpr signed char kBlockHeights[kBlocks][kBlocks] = {
    {17, 14, 13, 19, 22, 21, 18, 12, 10, 10, 11, 14, 13, 8, 3, 6},
    {19, 11, 7, 8, 12, 18, 25, 24, 18, 13, 10, 9, 7, 1, -5, 1},
    {26, 19, 6, 3, 9, 18, 29, 35, 31, 21, 24, 22, 11, -3, -15, -10},
    {31, 27, 14, 7, 10, 23, 35, 44, 42, 30, 33, 36, 23, 3, -12, -12},
    {27, 23, 15, 9, 11, 28, 43, 48, 44, 35, 35, 39, 33, 17, 2, 0},
    {12, 17, 21, 17, 17, 31, 50, 55, 50, 45, 39, 41, 38, 27, 14, 8},
    {5, 15, 26, 26, 24, 30, 43, 57, 59, 56, 50, 44, 38, 30, 18, 10},
    {6, 19, 31, 34, 31, 27, 31, 45, 54, 58, 54, 44, 37, 31, 19, 14},
    {5, 17, 31, 37, 32, 23, 25, 39, 49, 52, 48, 40, 35, 34, 27, 19},
    {6, 14, 27, 34, 33, 22, 16, 26, 36, 40, 37, 33, 39, 43, 33, 19},
    {4, 6, 18, 32, 33, 24, 13, 15, 22, 27, 24, 26, 38, 45, 31, 16},
    {-1, -1, 12, 29, 34, 24, 13, 14, 18, 17, 17, 24, 38, 41, 27, 18},
    {2, 3, 15, 25, 32, 23, 15, 14, 20, 17, 18, 27, 38, 39, 31, 18},
    {7, 8, 14, 16, 22, 19, 18, 17, 16, 17, 18, 22, 32, 36, 29, 19},
    {11, 12, 13, 8, 12, 15, 18, 15, 10, 8, 10, 13, 22, 25, 23, 18},
    {14, 16, 14, 11, 11, 12, 11, 7, 5, 4, 6, 14, 21, 26, 21, 17}};

constexpr int kGrid = 129;  // vertices per side, 500 / 128 m apart over -250..250

/// Local height at grid vertex (ix, iz): the block map interpolated bilinearly between
/// block centres, plus seeded noise of about a metre.
std::vector<double> landscapeHeights(std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0, 0.7);
    std::vector<double> heights(kGrid * kGrid);
    auto block = [](int row, int column) {
        row = std::min(std::max(row, 0), kBlocks - 1);
        column = std::min(std::max(column, 0), kBlocks - 1);
        return double(kBlockHeights[row][column]);
    };
    for (int iz = 0; iz < kGrid; ++iz) {
        for (int ix = 0; ix < kGrid; ++ix) {
            const double u = ix / 8.0 - 0.5, v = iz / 8.0 - 0.5;
            const int c = int(std::floor(u)), r = int(std::floor(v));
            const double fu = u - c, fv = v - r;
            const double h = (1 - fv) * ((1 - fu) * block(r, c) + fu * block(r, c + 1)) +
                             fv * ((1 - fu) * block(r + 1, c) + fu * block(r + 1, c + 1));
            heights[std::size_t(iz) * kGrid + ix] = h + noise(rng);
        }
    }
    return heights;
}

/// The landscape: eight static triangle-mesh tiles that share their borders (vertex ranges
/// as Bullet's), at y = -25, two triangles per grid cell, all facing up.
void addLandscape(WorldScene& scene, std::uint32_t seed) {
    const std::vector<double> heights = landscapeHeights(seed);
    struct Tile {
        int ix0, ix1, iz0, iz1;
    };
    const Tile tiles[8] = {{65, 128, 97, 128}, {0, 65, 65, 94}, {65, 128, 34, 65},
                           {65, 128, 65, 97},  {0, 65, 32, 65}, {0, 65, 94, 128},
                           {65, 128, 0, 34},   {0, 65, 0, 32}};
    const double spacing = 500.0 / (kGrid - 1);
    auto point = [&](int ix, int iz) {
        return vec(-250 + ix * spacing, heights[std::size_t(iz) * kGrid + ix], -250 + iz * spacing);
    };
    for (const Tile& tile : tiles) {
        auto* mesh = new btTriangleMesh();
        scene.ownMesh(mesh);
        for (int iz = tile.iz0; iz < tile.iz1; ++iz) {
            for (int ix = tile.ix0; ix < tile.ix1; ++ix) {
                // Split along the diagonal from (x0, z1) to (x1, z0); wound to face up.
                mesh->addTriangle(point(ix, iz), point(ix, iz + 1), point(ix + 1, iz));
                mesh->addTriangle(point(ix + 1, iz), point(ix, iz + 1), point(ix + 1, iz + 1));
            }
        }
        btRigidBody* body =
            scene.addBody(scene.own(new btBvhTriangleMeshShape(mesh, true)), 0, at(vec(0, -25, 0)));
        body->setFriction(btScalar(0.9));
    }
    scene.setContainer(vec(-260, -80, -260), vec(260, 1e9, 260));
}

/// The 10 layers of 10 x 10 drop positions, widening and rising layer by layer.
template <class Place>
void rainLayout(Place&& place) {
    double start = -125, height = 45;
    for (int k = 0; k < 10; ++k) {
        const double gap = 2 * std::pow(1.1, k);
        if (k > 0) {
            start -= 2.25 * 2 * std::pow(1.1, k - 1);
            height += 3 + gap;
        }
        for (int j = 0; j < 10; ++j) {
            for (int i = 0; i < 10; ++i) {
                place(vec(start + (3 + gap) * i, height, start + (3 + gap) * j));
            }
        }
    }
}

void fillPrimitivesOnMesh(WorldScene& scene, Budget budget, std::uint32_t seed) {
    benchmarkSolver(scene, 5);
    addLandscape(scene, seed);
    std::mt19937 rng(seed);
    rainLayout([&](const btVector3& position) {
        const int kind = std::uniform_int_distribution<int>(0, 8)(rng);
        const int size = kind % 3;  // small, medium, large
        const double scale = 1 + size, mass = 0.5 * scale;
        btCollisionShape* shape;
        if (kind < 3) {
            shape = new btBoxShape(vec(0.75 * scale, 0.75 * scale, 0.75 * scale));
        } else if (kind < 6) {
            shape = new btSphereShape(btScalar(0.75 * scale));
        } else {
            shape = new btCapsuleShape(btScalar(0.5 * scale), btScalar(scale));
        }
        if (budget.take()) {
            scene.addBody(scene.own(shape), mass, at(position));
        } else {
            delete shape;
        }
    });
}

void fillConvexOnMesh(WorldScene& scene, Budget budget, std::uint32_t seed) {
    benchmarkSolver(scene, 5);
    addLandscape(scene, seed);
    btCollisionShape* hull = scene.own(barrel(false));
    rainLayout([&](const btVector3& position) {
        if (budget.take()) {
            scene.addBody(hull, 1, at(position));
        }
    });
}

/// Scene 7's rays: 500 from (0, 50, 0), two turns of directions, each ending 2500 m out
/// (horizontally) at y = -1000. They do not move.
std::vector<WorldRay> landscapeRays(int /*frame*/) {
    std::vector<WorldRay> rays;
    for (int i = 0; i < 500; ++i) {
        const double angle = i * 4 * kPi / 500;
        rays.emplace_back(vec(0, 50, 0),
                          vec(2500 * std::cos(angle), -1000, -2500 * std::sin(angle)));
    }
    return rays;
}

// --- scene 8: a cube cut into 90 convex cells, dropped on a plane ---

void fillConvexPack(WorldScene& scene, Budget budget) {
    benchmarkSolver(scene, 20);
    btContactSolverInfo& info = scene.world()->getSolverInfo();
    info.m_erp = btScalar(0.8);
    info.m_erp2 = btScalar(0.4);
    info.m_globalCfm = btScalar(0.015);
    btRigidBody* ground =
        scene.addBody(scene.own(new btStaticPlaneShape(vec(0, 1, 0), 0)), 0, at(vec(0, 0, 0)));
    ground->setFriction(btScalar(0.5));
    scene.setContainer(vec(-50, -5, -50), vec(50, 1e9, 50));
    // The cells are the same for every scene built: compute them once.
    static const std::vector<std::vector<Point3>> cells = [] {
        std::vector<Point3> sites;
        for (int i = 1; i <= 90; ++i) {
            Point3 p = haltonPoint(i);
            for (double& x : p) {
                x = 2 * x - 1;
            }
            sites.push_back(p);
        }
        return voronoiCells(sites, {-1, -1, -1}, {1, 1, 1});
    }();
    for (const std::vector<Point3>& cell : cells) {
        if (!budget.take()) {
            break;
        }
        // Volume and centroid from the cell's hull (fans from an inner point).
        std::vector<double> coordinates;
        for (const Point3& p : cell) {
            coordinates.insert(coordinates.end(), p.begin(), p.end());
        }
        btConvexHullComputer hull;
        hull.compute(coordinates.data(), 3 * sizeof(double), int(cell.size()), 0, 0);
        btVector3 inner(0, 0, 0);
        for (int v = 0; v < hull.vertices.size(); ++v) {
            inner += hull.vertices[v];
        }
        inner /= btScalar(hull.vertices.size());
        double volume = 0;
        btVector3 moment(0, 0, 0);
        for (int f = 0; f < hull.faces.size(); ++f) {
            const btConvexHullComputer::Edge* first = &hull.edges[hull.faces[f]];
            const btVector3 a = hull.vertices[first->getSourceVertex()];
            for (const btConvexHullComputer::Edge* e = first->getNextEdgeOfFace();
                 e->getTargetVertex() != first->getSourceVertex(); e = e->getNextEdgeOfFace()) {
                const btVector3 b = hull.vertices[e->getSourceVertex()];
                const btVector3 c = hull.vertices[e->getTargetVertex()];
                const double tetra =
                    std::fabs(double((a - inner).dot((b - inner).cross(c - inner)))) / 6;
                volume += tetra;
                moment += (inner + a + b + c) * btScalar(tetra / 4);
            }
        }
        const btVector3 centroid = moment / btScalar(volume);
        auto* shape = new btConvexHullShape();
        for (int v = 0; v < hull.vertices.size(); ++v) {
            shape->addPoint(hull.vertices[v] - centroid, false);
        }
        shape->recalcLocalAabb();
        shape->setMargin(btScalar(0.04));
        shape->initializePolyhedralFeatures();
        btRigidBody* body = scene.addBody(scene.own(shape), volume, at(centroid + vec(0, 3.5, 0)));
        body->setFriction(btScalar(0.6));
    }
}

Budget budgetFor(const SceneInfo& info, const SceneOptions& options) {
    return Budget{options.objects > 0 ? std::min(options.objects, info.defaultObjects)
                                      : info.defaultObjects};
}

template <void (*fill)(WorldScene&, Budget)>
std::unique_ptr<Scene> build(const SceneInfo& info,
                             std::unique_ptr<btBroadphaseInterface> broadphase,
                             const SceneOptions& options) {
    auto scene = std::make_unique<WorldScene>(info, std::move(broadphase), options);
    fill(*scene, budgetFor(info, options));
    return scene;
}

template <void (*fill)(WorldScene&, Budget, std::uint32_t), bool rays>
std::unique_ptr<Scene> buildSeeded(const SceneInfo& info,
                                   std::unique_ptr<btBroadphaseInterface> broadphase,
                                   const SceneOptions& options) {
    auto scene = std::make_unique<WorldScene>(info, std::move(broadphase), options);
    fill(*scene, budgetFor(info, options), options.seed);
    if (rays) {
        scene->setRays(landscapeRays);
    }
    return scene;
}

SceneNeeds benchNeeds(bool rays, bool meshes) {
    SceneNeeds out;
    out.rays = rays;
    out.meshes = meshes;
    return out;
}

}  // namespace

void addBulletBenchmarkScenes(std::vector<SceneEntry>& entries) {
    auto add = [&](SceneInfo info, SceneBuilder builder) {
        info.group = "bullet-benchmark";
        entries.push_back({std::move(info), builder});
    };
    const std::string noMeshes = "no meshes: primitives and a ground box";
    const std::string noCcd = "; no continuous stages: nothing moves its size in a step";
    add({"bench-3000-boxes",
         "Bullet's BenchmarkDemo 1: 3008 boxes (2 m, 2 kg) in 47 leaning layers of 8 x 8 falling "
         "onto a ground box",
         "", 3008, benchNeeds(false, false),
         "dynamics: the tower falls and collapses; no rays: nothing casts; " + noMeshes + noCcd, 0,
         260},
        build<fillBoxes>);
    add({"bench-1000-stack",
         "Bullet's BenchmarkDemo 2: 1076 boxes as a pyramid, three brick walls and a round tower, "
         "at rest in contact (all asleep after about 160 steps)",
         "", 1076, benchNeeds(false, false),
         "dynamics: the structures settle and fall asleep; no rays: nothing casts; " + noMeshes +
             noCcd,
         0, 260},
        build<fillStack>);
    add({"bench-ragdolls",
         "Bullet's BenchmarkDemo 3: 136 ragdolls of 11 capsules and 10 hinge and cone-twist "
         "joints each, on a staircase of rows, falling onto a ground box",
         "", 1496, benchNeeds(false, false),
         "dynamics: the ragdolls fall onto each other, jointed; no rays: nothing casts; no "
         "meshes: capsules and a ground box" +
             noCcd,
         0, 260},
        build<fillRagdolls>);
    add({"bench-convex-stack",
         "Bullet's BenchmarkDemo 4: 960 convex-hull barrels in 15 layers of 8 x 8 falling onto a "
         "ground box",
         "", 960, benchNeeds(false, false),
         "dynamics: the barrels fall and pile up; no rays: nothing casts; no meshes: convex hulls "
         "and a ground box" +
             noCcd,
         0, 260},
        build<fillConvexStack>);
    const std::string landscapeWhy =
        "meshes: a 500 m landscape of 8 static triangle-mesh tiles (32 768 triangles)";
    add({"bench-prim-mesh",
         "Bullet's BenchmarkDemo 5: 1000 boxes, spheres and capsules raining onto a hilly "
         "triangle-mesh landscape",
         "", 1000, benchNeeds(false, true),
         "dynamics: the bodies fall onto the landscape; no rays: nothing casts; " + landscapeWhy +
             noCcd,
         0, 260},
        buildSeeded<fillPrimitivesOnMesh, false>);
    add({"bench-convex-mesh",
         "Bullet's BenchmarkDemo 6: 1000 convex-hull barrels raining onto the landscape", "", 1000,
         benchNeeds(false, true),
         "dynamics: the barrels fall onto the landscape; no rays: nothing casts; " + landscapeWhy +
             noCcd,
         0, 260},
        buildSeeded<fillConvexOnMesh, false>);
    add({"bench-raycast",
         "Bullet's BenchmarkDemo 7: bench-convex-mesh plus 500 closest-hit rays per frame from "
         "one point across the landscape",
         "", 1000, benchNeeds(true, true),
         "dynamics: the barrels fall onto the landscape; rays: 500 closest-hit casts per frame; " +
             landscapeWhy + noCcd,
         0, 260},
        buildSeeded<fillConvexOnMesh, true>);
    add({"bench-convex-pack",
         "Bullet's BenchmarkDemo 8: a 2 m cube cut into the 90 Voronoi cells of Halton points, "
         "convex hulls touching face to face, dropped 2.5 m onto a plane",
         "", 90, benchNeeds(false, false),
         "dynamics: the pack drops and collapses into a pile; no rays: nothing casts; no meshes: "
         "convex hulls and a plane" +
             noCcd,
         0, 60},
        build<fillConvexPack>);
}

}  // namespace kolize
