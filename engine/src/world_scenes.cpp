// The world scenes beyond the falling boxes: Bullet-benchmark worlds, assimp meshes, extreme
// and stiff cases. Every builder draws its randomness from one std::mt19937 seeded with
// SceneOptions::seed, in a fixed order, so a seed gives the same scene.

#include "scene_builders.h"

#include <kolize/engine/world_scene.h>
#ifdef KOLIZE_WITH_ASSIMP
#include <kolize/engine/assets.h>

#include <BulletCollision/CollisionShapes/btShapeHull.h>
#endif

#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <string>

namespace kolize {

namespace {

using Rng = std::mt19937;

constexpr double kPi = 3.14159265358979323846;
constexpr double kFar = 1e9;  // "unbounded" side of a container

double logUniform(Rng& rng, double lo, double hi) {
    return std::exp(uniform(rng, std::log(lo), std::log(hi)));
}

/// Uniform in the box lo..hi (one coordinate after the other: a fixed draw order).
btVector3 uniformIn(Rng& rng, const btVector3& lo, const btVector3& hi) {
    const double x = uniform(rng, lo.x(), hi.x());
    const double y = uniform(rng, lo.y(), hi.y());
    const double z = uniform(rng, lo.z(), hi.z());
    return vec(x, y, z);
}

/// A uniformly distributed unit vector (a normalised Gaussian sample).
btVector3 randomDirection(Rng& rng) {
    std::normal_distribution<double> normal;
    for (;;) {
        const double x = normal(rng), y = normal(rng), z = normal(rng);
        const double length = std::sqrt(x * x + y * y + z * z);
        if (length > 1e-9) {
            return vec(x / length, y / length, z / length);
        }
    }
}

SceneNeeds needs(bool rays, bool meshes, bool continuous) {
    SceneNeeds out;
    out.rays = rays;
    out.meshes = meshes;
    out.continuous = continuous;
    return out;
}

/// Fills a new world with a scene's bodies: `count` is SceneOptions::objects or the default.
using Filler = void (*)(WorldScene& scene, Rng& rng, int count);

/// A scene's builder: the world (its origin at the scene's world centre: only the offset
/// scenes move it), the seeded random numbers, then `fill`.
template <Filler fill>
std::unique_ptr<Scene> buildWith(const SceneInfo& info,
                                 std::unique_ptr<btBroadphaseInterface> broadphase,
                                 const SceneOptions& options) {
    const btScalar c = btScalar(info.worldCentre);
    auto scene =
        std::make_unique<WorldScene>(info, std::move(broadphase), options, btVector3(c, c, c));
    Rng rng(options.seed);
    fill(*scene, rng, options.objects > 0 ? options.objects : info.defaultObjects);
    return scene;
}

// --- static geometry ---

/// A static box whose top face is at y = 0, centred on x = z = 0.
void addGroundBox(WorldScene& scene, double halfWidth, double halfThickness = 1) {
    scene.addBody(scene.own(new btBoxShape(vec(halfWidth, halfThickness, halfWidth))), 0,
                  at(vec(0, -halfThickness, 0)));
}

/// Static walls of `thickness` around the inner box min..max: the four sides (x and z), and
/// with `closed` also floor and ceiling. Walls reach past the corners.
void addWalls(WorldScene& scene, const btVector3& min, const btVector3& max, double thickness,
              bool closed) {
    const btVector3 centre = (min + max) / 2, half = (max - min) / 2;
    const btScalar t = btScalar(thickness);
    for (int axis : {0, 2, 1}) {
        if (axis == 1 && !closed) {
            continue;
        }
        btVector3 extent = half + btVector3(2 * t, 2 * t, 2 * t);
        extent[axis] = t / 2;
        btCollisionShape* wall = scene.own(new btBoxShape(extent));
        for (int side : {-1, 1}) {
            btVector3 position = centre;
            position[axis] += btScalar(side) * (half[axis] + t / 2);
            scene.addBody(wall, 0, at(position));
        }
    }
}

constexpr int kTerrainQuads = 64;
constexpr double kTerrainQuad = 1.25;  // m: the terrain spans +-40 m
constexpr double kTerrainHalf = kTerrainQuads * kTerrainQuad / 2;
constexpr double kTerrainRelief = 2.2;  // |height| stays below this

/// Gentle hills: two long sine waves, |height| < kTerrainRelief.
double terrainHeight(double x, double z) {
    return 1.5 * std::sin(0.16 * x) * std::cos(0.12 * z) + 0.6 * std::sin(0.05 * x + 0.09 * z);
}

/// The static terrain mesh, centred on x = z = 0.
void addTerrain(WorldScene& scene) {
    addGridMesh(scene, kTerrainQuads, kTerrainQuads, [](int i, int j) {
        const double x = -kTerrainHalf + i * kTerrainQuad, z = -kTerrainHalf + j * kTerrainQuad;
        return vec(x, terrainHeight(x, z), z);
    });
}

// --- moving bodies ---

/// A box, sphere or capsule (one in three each) whose largest extent is `size`, never thinner
/// than half of it: boxes' other extents are 0.6..1 of the largest, capsules' diameter
/// 0.5..0.8 of their length. (Thinner bodies fall through a triangle mesh's zero-thickness
/// triangles once they move their thickness in one step.)
btCollisionShape* randomShape(WorldScene& scene, Rng& rng, double size) {
    const int kind = std::uniform_int_distribution<int>(0, 2)(rng);
    const double half = size / 2;
    if (kind == 0) {
        const double b = uniform(rng, 0.6, 1), c = uniform(rng, 0.6, 1);
        return scene.own(new btBoxShape(vec(half, half * b, half * c)));
    }
    if (kind == 1) {
        return scene.own(new btSphereShape(btScalar(half)));
    }
    const double radius = half * uniform(rng, 0.5, 0.8);
    return scene.own(new btCapsuleShape(btScalar(radius), btScalar(size - 2 * radius)));
}

/// `count` drop positions on a square grid of `perSide` columns at `pitch`, centred on
/// x = z = 0, filled layer after layer upwards from y = bottom.
std::vector<btVector3> dropGrid(int count, int perSide, double pitch, double bottom) {
    std::vector<btVector3> out;
    const double offset = -(perSide - 1) * pitch / 2;
    for (int i = 0; i < count; ++i) {
        const int layer = i / (perSide * perSide), cell = i % (perSide * perSide);
        out.push_back(vec(offset + (cell % perSide) * pitch, bottom + layer * pitch,
                          offset + (cell / perSide) * pitch));
    }
    return out;
}

/// Columns per side of a drop grid: a square block for few objects, at most `limit`.
int gridSide(int count, int limit) {
    return std::min(limit, std::max(1, int(std::ceil(std::sqrt(double(count))))));
}

constexpr double kMixedMin = 0.5, kMixedMax = 1.5;  // sizes of the mixed bodies (m)
constexpr double kDropPitch = 2.8;  // > the largest mixed body's bounding sphere (2.6 m)
constexpr int kMixedGridSide = 20;  // 400 bodies per layer

/// The mixed bodies: `count` random boxes, spheres and capsules of size 0.5..1.5 m (mass:
/// size^3 kg) with random orientations, on the drop grid from y = bottom, at rest.
void addMixedBodies(WorldScene& scene, Rng& rng, int count, double bottom) {
    for (const btVector3& position :
         dropGrid(count, gridSide(count, kMixedGridSide), kDropPitch, bottom)) {
        const double size = uniform(rng, kMixedMin, kMixedMax);
        btCollisionShape* shape = randomShape(scene, rng, size);
        scene.addBody(shape, size * size * size, at(position, randomRotation(rng)));
    }
}

/// `count` random bodies of sizes uniform over minSize..maxSize (mass: size^3 kg) with
/// centres uniform in the box lo..hi and random orientations: they may start overlapping.
void addScatteredBodies(WorldScene& scene, Rng& rng, int count, double minSize, double maxSize,
                        const btVector3& lo, const btVector3& hi) {
    for (int i = 0; i < count; ++i) {
        const double size = uniform(rng, minSize, maxSize);
        btCollisionShape* shape = randomShape(scene, rng, size);
        const btVector3 position = uniformIn(rng, lo, hi);
        scene.addBody(shape, size * size * size, at(position, randomRotation(rng)));
    }
}

/// The frame's rays over the terrain: 400 vertical ones on a 20 x 20 grid that drifts with
/// the frame, and 100 long slanted ones across the whole terrain.
std::vector<WorldRay> terrainRays(int frame) {
    std::vector<WorldRay> rays;
    constexpr int side = 20;
    const double pitch = 2 * kTerrainHalf / side;
    const double driftX = std::fmod(frame * 0.37, pitch), driftZ = std::fmod(frame * 0.23, pitch);
    for (int i = 0; i < side * side; ++i) {
        const double x = -kTerrainHalf + driftX + (i % side) * pitch;
        const double z = -kTerrainHalf + driftZ + (i / side) * pitch;
        rays.emplace_back(vec(x, 40, z), vec(x, -10, z));
    }
    constexpr int slanted = 100;
    for (int i = 0; i < slanted; ++i) {
        const double z = -kTerrainHalf + std::fmod(i * 0.8 + frame * 0.5, 2 * kTerrainHalf);
        rays.emplace_back(vec(-kTerrainHalf, 25, z), vec(kTerrainHalf, -5, kTerrainHalf - z));
    }
    return rays;
}

// --- builders ---

/// mixed-terrain, mixed-rays, mixed-plane and the offset scenes (mixed-plane far out).
void fillMixed(WorldScene& scene, Rng& rng, int count) {
    const bool terrain = scene.info().needs.meshes;
    if (terrain) {
        addTerrain(scene);
        const double margin = 5;
        scene.setContainer(
            vec(-kTerrainHalf - margin, -kTerrainRelief - margin, -kTerrainHalf - margin),
            vec(kTerrainHalf + margin, kFar, kTerrainHalf + margin));
    } else {
        scene.addBody(scene.own(new btStaticPlaneShape(btVector3(0, 1, 0), 0)), 0,
                      at(vec(0, 0, 0)));
        // The smallest body's centre rests 0.25 m up: 1 m down is through the plane.
        scene.setContainer(vec(-kFar, -1, -kFar), vec(kFar, kFar, kFar));
    }
    addMixedBodies(scene, rng, count, (terrain ? kTerrainRelief : 0) + 2);
    if (scene.info().needs.rays) {
        scene.setRays(terrainRays);
    }
}

void fillPyramid(WorldScene& scene, Rng&, int count) {
    // The smallest base whose full pyramid (sum of side^2) holds count; the top is trimmed.
    int base = 1;
    while (base * (base + 1) * (2 * base + 1) / 6 < count) {
        ++base;
    }
    const double pitch = 1.02;  // unit boxes, 2 cm apart within a layer
    const double wall = base * pitch / 2 + 2;
    addGroundBox(scene, wall + 10);
    addWalls(scene, vec(-wall, 0, -wall), vec(wall, 6, wall), 0.5, false);
    btCollisionShape* box = scene.own(new btBoxShape(vec(0.5, 0.5, 0.5)));
    int placed = 0;
    for (int layer = 0; placed < count; ++layer) {
        const int side = base - layer;
        const double offset = -(side - 1) * pitch / 2;
        for (int cell = 0; cell < side * side && placed < count; ++cell, ++placed) {
            scene.addBody(box, 1,
                          at(vec(offset + (cell % side) * pitch, 0.5 + layer,
                                 offset + (cell / side) * pitch)));
        }
    }
    scene.setContainer(vec(-wall, -0.5, -wall), vec(wall, kFar, wall));
}

/// A stack of `count` unit boxes on a ground box; box k (from the bottom) has mass(k).
void addStack(WorldScene& scene, int count, double (*mass)(int)) {
    addGroundBox(scene, 20);
    btCollisionShape* box = scene.own(new btBoxShape(vec(0.5, 0.5, 0.5)));
    for (int k = 0; k < count; ++k) {
        scene.addBody(box, mass(k), at(vec(0, 0.5 + k, 0)));
    }
    // A box whose centre slides 1.5 m sideways has fallen off: the stack did not hold.
    scene.setContainer(vec(-1.5, -0.5, -1.5), vec(1.5, count + 1, 1.5));
}

void fillTallStack(WorldScene& scene, Rng&, int count) {
    addStack(scene, count, [](int) { return 1.0; });
}

void fillMassRatioStack(WorldScene& scene, Rng&, int count) {
    addStack(scene, count, [](int k) { return k % 2 == 0 ? 1.0 : 1000.0; });
}

/// mixed-sizes: sizes log-uniform over 1e-2..1e2 m, shelf-packed (largest first) into
/// layers over a 600 m square so that no two start overlapping.
void fillMixedSizes(WorldScene& scene, Rng& rng, int count) {
    constexpr double half = 300;
    addGroundBox(scene, half + 100, 10);
    std::vector<double> sizes;
    for (int i = 0; i < count; ++i) {
        sizes.push_back(logUniform(rng, 1e-2, 1e2));
    }
    std::sort(sizes.rbegin(), sizes.rend());
    // Each body gets a cube cell of 1.75 x its size (its bounding sphere fits); rows along
    // x, rows of a layer along z, layers upwards; a row's and a layer's depth is their first
    // (largest) cell.
    double x = -half, z = -half, y = 0.5, rowDepth = 0, layerHeight = 0;
    for (double size : sizes) {
        const double cell = 1.75 * size;
        if (x + cell > half) {
            x = -half;
            z += rowDepth;
            rowDepth = 0;
        }
        if (z + cell > half) {
            z = -half;
            y += layerHeight;
            layerHeight = 0;
        }
        rowDepth = std::max(rowDepth, cell);
        layerHeight = std::max(layerHeight, cell);
        btCollisionShape* shape = randomShape(scene, rng, size);
        // Mass in kg equal to the size in m: a 1e4 mass ratio instead of uniform density's 1e12.
        scene.addBody(shape, size,
                      at(vec(x + cell / 2, y + cell / 2, z + cell / 2), randomRotation(rng)));
        x += cell;
    }
    scene.setContainer(vec(-half - 100, -1, -half - 100), vec(half + 100, kFar, half + 100));
}

void fillSmallRegion(WorldScene& scene, Rng& rng, int count) {
    const btVector3 min = vec(-2, 0, -2), max = vec(2, 4, 2);
    addWalls(scene, min, max, 0.5, true);
    const btVector3 inset(0.25, 0.25, 0.25);
    addScatteredBodies(scene, rng, count, 0.15, 0.5, min + inset, max - inset);
    const btVector3 margin(0.5, 0.5, 0.5);
    scene.setContainer(min - margin, max + margin);
}

void fillEscape(WorldScene& scene, Rng& rng, int count) {
    // No container: leaving is the point.
    for (int i = 0; i < count; ++i) {
        const double size = uniform(rng, kMixedMin, kMixedMax);
        btCollisionShape* shape = randomShape(scene, rng, size);
        const btVector3 direction = randomDirection(rng);
        const double distance = uniform(rng, 2, 12);
        // Speeds stratified log-uniformly over 50..5000 m/s: body i in the i-th slice.
        const double speed = 50 * std::pow(100.0, (i + uniform(rng, 0, 1)) / count);
        scene.addBody(shape, size * size * size,
                      at(direction * btScalar(distance), randomRotation(rng)),
                      direction * btScalar(speed));
    }
}

void fillDensePile(WorldScene& scene, Rng& rng, int count) {
    addGroundBox(scene, 100);
    // Sizes 6..10 m with centres in a 3 m cube: every AABB is at least 3 m across, so the
    // boxes overlap nearly pairwise.
    addScatteredBodies(scene, rng, count, 6, 10, vec(-1.5, 10.5, -1.5), vec(1.5, 13.5, 1.5));
    scene.setContainer(vec(-100, -1, -100), vec(100, kFar, 100));
}

#ifdef KOLIZE_WITH_ASSIMP
const char* const kMeshModels[] = {"ASE/ThreeCubesGreen.ASE", "ASE/RotatingCube.ASE",
                                   "OBJ/spider.obj", "PLY/Wuson.ply"};

/// A convex hull of the mesh, centred on its bounding box and scaled to `size` along its
/// longest side, reduced by btShapeHull to the support points of 42 directions.
btCollisionShape* hullShape(WorldScene& scene, const LoadedMesh& mesh, double size) {
    btVector3 lo = mesh.vertices.front(), hi = lo;
    for (const btVector3& v : mesh.vertices) {
        lo.setMin(v);
        hi.setMax(v);
    }
    const btVector3 centre = (lo + hi) / 2;
    const btScalar scale = btScalar(size) / (hi - lo)[(hi - lo).maxAxis()];
    btConvexHullShape full;
    full.setMargin(0);  // btShapeHull samples support points, which include the margin
    for (const btVector3& v : mesh.vertices) {
        full.addPoint((v - centre) * scale, false);
    }
    full.recalcLocalAabb();
    btShapeHull reduced(&full);
    reduced.buildHull(0);
    auto* hull = new btConvexHullShape();
    for (int i = 0; i < reduced.numVertices(); ++i) {
        hull->addPoint(reduced.getVertexPointer()[i], false);
    }
    hull->recalcLocalAabb();
    return scene.own(hull);
}

void fillMeshes(WorldScene& scene, Rng& rng, int count) {
    std::vector<btCollisionShape*> hulls;
    for (const char* model : kMeshModels) {
        hulls.push_back(hullShape(scene, loadMesh(scene.options().assetDir + "/" + model), 1.5));
    }
    const double radius = std::max(6.0, 16 * std::cbrt(count / 200.0));
    addBowl(scene, radius);
    // Drop columns (corners included) within 0.7 of the radius, where the bowl is 0.29 of
    // the radius high; layers from 2 m above that.
    const double reach = 0.7 * radius - kDropPitch / 2;
    const int perSide = gridSide(count, 1 + int(2 * reach / (kDropPitch * std::sqrt(2.0))));
    const double bottom = radius * (1 - std::sqrt(1 - 0.7 * 0.7)) + 2;
    int i = 0;
    for (const btVector3& position : dropGrid(count, perSide, kDropPitch, bottom)) {
        scene.addBody(hulls[std::size_t(i++) % hulls.size()], 1, at(position, randomRotation(rng)));
    }
    const double margin = 1;
    scene.setContainer(vec(-radius - margin, -margin, -radius - margin),
                       vec(radius + margin, kFar, radius + margin));
}
#endif

const char* const kMixedWhy =
    "dynamics: the bodies fall and settle; no rays: nothing casts; %MESH%; no continuous "
    "stages: falls of up to 8 m move under 0.25 m per step, the thinnest body's thickness "
    "(impacts in the piles still push a few bodies through a mesh: state().escaped)";

std::string mixedWhy(const std::string& mesh, bool rays) {
    std::string out = kMixedWhy;
    out.replace(out.find("%MESH%"), 6, mesh);
    if (rays) {
        out.replace(out.find("no rays: nothing casts"), 22,
                    "rays: 500 closest-hit casts per frame");
    }
    return out;
}

}  // namespace

btQuaternion randomRotation(std::mt19937& rng) {
    std::normal_distribution<double> normal;
    for (;;) {
        const double x = normal(rng), y = normal(rng), z = normal(rng), w = normal(rng);
        const double length = std::sqrt(x * x + y * y + z * z + w * w);
        if (length > 1e-9) {
            return btQuaternion(btScalar(x / length), btScalar(y / length), btScalar(z / length),
                                btScalar(w / length));
        }
    }
}

btRigidBody* addGridMesh(WorldScene& scene, int rows, int columns,
                         const std::function<btVector3(int, int)>& point) {
    auto* mesh = new btTriangleMesh();
    scene.ownMesh(mesh);
    auto triangle = [&](const btVector3& a, const btVector3& b, const btVector3& c) {
        if ((b - a).cross(c - a).length2() > btScalar(1e-12)) {
            mesh->addTriangle(a, b, c);
        }
    };
    for (int i = 0; i < rows; ++i) {
        for (int j = 0; j < columns; ++j) {
            const btVector3 a = point(i, j), b = point(i + 1, j), c = point(i + 1, j + 1),
                            d = point(i, j + 1);
            triangle(a, b, c);
            triangle(a, c, d);
        }
    }
    return scene.addBody(scene.own(new btBvhTriangleMeshShape(mesh, true)), 0,
                         btTransform::getIdentity());
}

btRigidBody* addBowl(WorldScene& scene, double radius) {
    constexpr int rings = 12, segments = 36;
    return addGridMesh(scene, rings, segments, [radius](int ring, int segment) {
        const double theta = kPi / 2 * ring / rings, phi = 2 * kPi * segment / segments;
        return vec(radius * std::sin(theta) * std::cos(phi), radius * (1 - std::cos(theta)),
                   radius * std::sin(theta) * std::sin(phi));
    });
}

void addWorldScenes(std::vector<SceneEntry>& entries) {
    auto add = [&](SceneInfo info, SceneBuilder builder) {
        entries.push_back({std::move(info), builder});
    };
    const std::string mixed =
        "N (default 1000) boxes, spheres and capsules of 0.5..1.5 m, random orientations, "
        "dropped from a grid of heights (20 x 20 per layer)";
    const std::string terrainMesh = "meshes: the ground is a static triangle mesh";
    const std::string planeMesh = "no meshes: the ground is a plane";
    add({"pyramid",
         "N (default 1000) unit boxes in a pyramid of square layers (14 x 14 down to the "
         "trimmed top) on a ground box inside four static walls",
         "bullet", 1000, needs(false, false, false),
         "dynamics: the pyramid settles under its weight; no rays: nothing casts; no meshes: "
         "boxes only; no continuous stages: the boxes start at rest in contact",
         0, 20},
        buildWith<fillPyramid>);
    add({"mixed-terrain", mixed + " onto a static triangle-mesh terrain (64 x 64 quads, hills)",
         "bullet", 1000, needs(false, true, false), mixedWhy(terrainMesh, false), 0, 45},
        buildWith<fillMixed>);
    add({"mixed-plane", mixed + " onto a static plane", "bullet", 1000, needs(false, false, false),
         mixedWhy(planeMesh, false), 0, 45},
        buildWith<fillMixed>);
    add({"mixed-rays",
         "mixed-terrain plus 500 rays per frame: 400 vertical ones on a drifting grid, 100 long "
         "slanted ones",
         "bullet", 1000, needs(true, true, false), mixedWhy(terrainMesh, true), 0, 45},
        buildWith<fillMixed>);
#ifdef KOLIZE_WITH_ASSIMP
    add({"meshes",
         "N (default 200) convex hulls of assimp's test models (ThreeCubesGreen, RotatingCube, "
         "spider, Wuson; 1.5 m, random orientations) dropped into a triangle-mesh bowl",
         "mesh", 200, needs(false, true, false),
         "dynamics: the hulls fall into the bowl; no rays: nothing casts; meshes: models loaded "
         "by assimp as convex hulls, the bowl a triangle mesh; no continuous stages: falls of a "
         "few metres move under 0.3 m per step",
         0, 30},
        buildWith<fillMeshes>);
#endif
    add({"offset-1e4", "mixed-plane with every coordinate shifted by (1e4, 1e4, 1e4)", "extreme",
         1000, needs(false, false, false),
         mixedWhy(planeMesh, false) + "; far from the origin: float positions are coarse", 1e4, 45},
        buildWith<fillMixed>);
    add({"offset-1e6",
         "mixed-plane with every coordinate shifted by (1e6, 1e6, 1e6) (float: positions "
         "in steps of 1/16 m)",
         "extreme", 1000, needs(false, false, false),
         mixedWhy(planeMesh, false) + "; far from the origin: float positions are coarse", 1e6, 45},
        buildWith<fillMixed>);
    add({"mixed-sizes",
         "N (default 500) boxes, spheres and capsules with sizes log-uniform over 1 cm..100 m "
         "(mass in kg = size in m) stacked in layers up to a few hundred metres, falling onto "
         "a ground box",
         "extreme", 500, needs(false, false, true),
         "dynamics: bodies of every size fall and land on each other; no rays: nothing casts; "
         "no meshes: primitives and a ground box; continuous: 1 cm bodies falling from hundreds "
         "of metres move far more than their size per step",
         0, 600},
        buildWith<fillMixedSizes>);
    add({"small-region",
         "N (default 500) boxes, spheres and capsules of 0.15..0.5 m placed at random in a "
         "closed 4 m box, overlapping heavily at the start",
         "extreme", 500, needs(false, false, false),
         "dynamics: the solver pushes the overlapping bodies apart; no rays: nothing casts; no "
         "meshes: primitives and wall boxes; no continuous stages: the walls keep the bodies "
         "within a few metres",
         0, 3},
        buildWith<fillSmallRegion>);
    add({"escape",
         "N (default 300) boxes, spheres and capsules launched outward from a 12 m ball at "
         "50..5000 m/s (log-uniform), gravity on, no walls: kilometres out within 60 frames",
         "extreme", 300, needs(false, false, true),
         "dynamics: bodies collide at the start, then fly apart; no rays: nothing casts; no "
         "meshes: primitives only; continuous: up to 80 m per step",
         0, 15},
        buildWith<fillEscape>);
    add({"dense-pile",
         "N (default 200) boxes, spheres and capsules of 6..10 m with centres in one 3 m cube "
         "(AABBs overlapping nearly pairwise) above a ground box",
         "extreme", 200, needs(false, false, false),
         "dynamics: the solver pushes a pile of deep overlaps apart; no rays: nothing casts; no "
         "meshes: primitives and a ground box; no continuous stages: bodies are metres across",
         0, 20},
        buildWith<fillDensePile>);
    add({"tall-stack",
         "a single stack of N (default 40) unit boxes (1 kg) on a ground box (measured: holds "
         "at 1/60 s with 4 substeps, falls after about 2.5 s with 1 or 2)",
         "stiff", 40, needs(false, false, false),
         "dynamics: the solver must hold the stack; no rays: nothing casts; no meshes: boxes "
         "only; no continuous stages: the boxes start at rest in contact",
         0, 45},
        buildWith<fillTallStack>);
    add({"mass-ratio-stack",
         "a stack of N (default 20) unit boxes alternating 1 kg and 1000 kg from the bottom "
         "(1:1000) on a ground box (measured: Bullet's solver lets it collapse)",
         "stiff", 20, needs(false, false, false),
         "dynamics: the solver must hold heavy boxes on light ones; no rays: nothing casts; no "
         "meshes: boxes only; no continuous stages: the boxes start at rest in contact",
         0, 25},
        buildWith<fillMassRatioStack>);
}

}  // namespace kolize
