// The scene registry: every scene over exact and Bullet broadphases against the exact truth,
// the dynamics' health of the stiff and extreme scenes, rays, assimp assets and seeds.

#include <kolize/engine/pair_compare.h>
#include <kolize/engine/scene.h>
#include <kolize/engine/world_scene.h>
#include <kolize/kolize.h>
#ifdef KOLIZE_WITH_ASSIMP
#include <kolize/engine/assets.h>
#endif

#include <btBulletDynamicsCommon.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <stdexcept>
#include <string>

namespace kolize {
namespace {

const char* const kAssetDir = "/usr/share/assimp/models";

std::unique_ptr<Scene> build(const std::string& scene, const std::string& broadphase,
                             const SceneOptions& options) {
    const SceneInfo& info = findScene(scene);
    return makeScene(scene, makeBroadphase(broadphase, broadphaseSettingsFor(info, options)),
                     options);
}

/// Compares the broadphase's pairs with the truth after a frame: equal for an exact
/// broadphase, a superset otherwise. Returns the number of true pairs.
std::size_t checkPairs(Scene& scene, const std::string& broadphase, int frame) {
    const std::vector<UidPair> truth = exactPairs(scene.proxyBoxes(), scene.filter());
    const PairDifference difference =
        comparePairs(truth, cachedPairs(*scene.broadphase().getOverlappingPairCache()));
    EXPECT_EQ(difference.missing.size(), 0u)
        << scene.info().name << " over " << broadphase << ", frame " << frame;
    if (isExactBroadphase(broadphase)) {
        EXPECT_EQ(difference.extra.size(), 0u)
            << scene.info().name << " over " << broadphase << ", frame " << frame;
    }
    return truth.size();
}

bool assetsPresent() {
    return std::ifstream(std::string(kAssetDir) + "/PLY/Wuson.ply").good();
}

// --- the registry ---

TEST(SceneRegistry, HoldsTheNamedScenesWithFilledInfo) {
    std::set<std::string> names;
    for (const SceneInfo& info : sceneList()) {
        EXPECT_TRUE(names.insert(info.name).second) << "duplicate " << info.name;
        EXPECT_FALSE(info.summary.empty()) << info.name;
        EXPECT_FALSE(info.pipelineWhy.empty()) << info.name;
        EXPECT_GT(info.defaultObjects, 0) << info.name;
        EXPECT_GT(info.worldHalfExtent, 0) << info.name;
        const std::set<std::string> groups = {"thesis", "bullet",           "mesh",      "extreme",
                                              "stiff",  "bullet-benchmark", "mesh-world"};
        EXPECT_EQ(groups.count(info.group), 1u) << info.name << ": group " << info.group;
    }
    for (const char* name : {"pyramid", "mixed-terrain", "mixed-plane", "mixed-rays", "offset-1e4",
                             "offset-1e6", "mixed-sizes", "small-region", "escape", "dense-pile",
                             "tall-stack", "mass-ratio-stack"}) {
        EXPECT_EQ(names.count(name), 1u) << name;
    }
    for (const char* name :
         {"bench-3000-boxes", "bench-1000-stack", "bench-ragdolls", "bench-convex-stack",
          "bench-prim-mesh", "bench-convex-mesh", "bench-raycast", "bench-convex-pack"}) {
        EXPECT_EQ(names.count(name), 1u) << name;
    }
    EXPECT_TRUE(findScene("bench-raycast").needs.rays);
    EXPECT_TRUE(findScene("bench-prim-mesh").needs.meshes);
    EXPECT_FALSE(findScene("bench-3000-boxes").needs.meshes);
    EXPECT_EQ(findScene("bench-ragdolls").defaultObjects, 1496);
#ifdef KOLIZE_WITH_ASSIMP
    EXPECT_EQ(names.count("meshes"), 1u);
#else
    EXPECT_EQ(names.count("meshes"), 0u);
#endif
    EXPECT_TRUE(findScene("mixed-rays").needs.rays);
    EXPECT_TRUE(findScene("mixed-terrain").needs.meshes);
    EXPECT_FALSE(findScene("mixed-plane").needs.meshes);
    EXPECT_TRUE(findScene("escape").needs.continuous);
    EXPECT_TRUE(findScene("mixed-sizes").needs.continuous);
    EXPECT_DOUBLE_EQ(findScene("offset-1e6").worldCentre, 1e6);
}

TEST(SceneRegistry, UnknownNameThrowsListingTheNames) {
    try {
        makeScene("nope", makeBroadphase("dbvt"));
        FAIL() << "no exception";
    } catch (const std::invalid_argument& error) {
        const std::string message = error.what();
        EXPECT_NE(message.find("'nope'"), std::string::npos) << message;
        EXPECT_NE(message.find("pyramid"), std::string::npos) << message;
        EXPECT_NE(message.find("mass-ratio-stack"), std::string::npos) << message;
    }
}

// --- every scene against the truth ---

class EveryScene : public ::testing::TestWithParam<std::string> {};

/// Every scene steps 40 frames (enough for the mixed bodies to reach the terrain) over
/// brute-force, dbvt and one more exact broadphase (rotating over the scenes). The thesis
/// scenes spread their cubes over a 1000 m cube: 4000 cubes for 4 frames give a few pairs.
TEST_P(EveryScene, PairsMatchTheTruthEveryFrame) {
    const SceneInfo& info = findScene(GetParam());
    if ((info.name == "meshes" || (info.group == "mesh-world" && info.name != "mesh-box-stack")) &&
        !assetsPresent()) {
        GTEST_SKIP() << "assimp's test models are not installed under " << kAssetDir
                     << " (Debian: assimp-testmodels)";
    }
    static const char* const kExact[] = {"spatial-hash", "grid", "segment-trees", "spatial-tree",
                                         "range-tree"};
    const auto index =
        std::size_t(std::find_if(sceneList().begin(), sceneList().end(),
                                 [&](const SceneInfo& s) { return s.name == info.name; }) -
                    sceneList().begin());
    const bool thesis = info.group == "thesis";
    SceneOptions options;
    options.objects = thesis ? 4000 : 24;
    for (const std::string broadphase : {"brute-force", "dbvt", kExact[index % 5]}) {
        SCOPED_TRACE(info.name + " over " + broadphase);
        auto scene = build(info.name, broadphase, options);
        EXPECT_GT(scene->movingObjects(), 0);
        std::size_t framesWithPairs = 0;
        // The landscape scenes' bodies start 8 m or more above it: 2.5 s to land.
        const bool landscape = info.name == "bench-prim-mesh" || info.name == "bench-convex-mesh" ||
                               info.name == "bench-raycast";
        for (int frame = 0; frame < (thesis ? 4 : landscape ? 150 : 40); ++frame) {
            scene->step();
            framesWithPairs += checkPairs(*scene, broadphase, frame) > 0 ? 1 : 0;
            ASSERT_EQ(scene->state().nonFinite, 0) << "frame " << frame;
        }
        EXPECT_GT(framesWithPairs, 0u) << "no frame had a true pair: the check saw nothing";
    }
}

INSTANTIATE_TEST_SUITE_P(Scenes, EveryScene, ::testing::ValuesIn([] {
                             std::vector<std::string> names;
                             for (const SceneInfo& info : sceneList()) {
                                 names.push_back(info.name);
                             }
                             return names;
                         }()),
                         [](const ::testing::TestParamInfo<std::string>& param) {
                             std::string name = param.param;
                             std::replace(name.begin(), name.end(), '-', '_');
                             return name;
                         });

// --- seeds ---

std::vector<ProxyBox> initialBoxes(const std::string& scene, std::uint32_t seed) {
    SceneOptions options;
    options.objects = 30;
    options.seed = seed;
    auto built = build(scene, "brute-force", options);
    built->step();  // a world gives its proxies their boxes in the first step
    return built->proxyBoxes();
}

bool sameBoxes(const std::vector<ProxyBox>& a, const std::vector<ProxyBox>& b) {
    return a.size() == b.size() &&
           std::equal(a.begin(), a.end(), b.begin(), [](const ProxyBox& x, const ProxyBox& y) {
               return x.aabbMin == y.aabbMin && x.aabbMax == y.aabbMax;
           });
}

TEST(SceneSeeds, SameSeedSameSceneOtherSeedOtherScene) {
    // Scenes without randomness: regular layouts.
    const std::set<std::string> seedless = {"boxes",
                                            "boxes-plane",
                                            "pyramid",
                                            "tall-stack",
                                            "mass-ratio-stack",
                                            "bench-3000-boxes",
                                            "bench-1000-stack",
                                            "bench-ragdolls",
                                            "bench-convex-stack",
                                            "bench-convex-pack",
                                            "mesh-box-stack"};
    for (const SceneInfo& info : sceneList()) {
        if ((info.name == "meshes" ||
             (info.group == "mesh-world" && info.name != "mesh-box-stack")) &&
            !assetsPresent()) {
            continue;
        }
        const auto first = initialBoxes(info.name, 7);
        EXPECT_FALSE(first.empty()) << info.name;
        EXPECT_TRUE(sameBoxes(first, initialBoxes(info.name, 7))) << info.name;
        EXPECT_EQ(sameBoxes(first, initialBoxes(info.name, 8)), seedless.count(info.name) == 1)
            << info.name;
    }
}

// --- health ---

double topHeight(const Scene& scene) {
    double top = -1e30;
    for (const btVector3& position : scene.positions()) {
        top = std::max(top, double(position.y()));
    }
    return top;
}

/// The tall stack at 1/60 s with 4 substeps for 5 s: nobody falls off, the top sinks little,
/// contacts stay shallow. (Measured: with 1 or 2 substeps it falls after about 2.5 s.)
TEST(SceneHealth, TallStackHoldsWithFourSubsteps) {
    SceneOptions options;
    options.substeps = 4;
    auto scene = build("tall-stack", "spatial-hash", options);
    const double startTop = topHeight(*scene);
    EXPECT_DOUBLE_EQ(startTop, 39.5);
    double deepest = 0;
    for (int frame = 0; frame < 300; ++frame) {
        scene->step();
        if (frame >= 60) {  // settled
            deepest = std::max(deepest, scene->state().maxPenetration);
        }
    }
    const SceneState state = scene->state();
    EXPECT_EQ(state.nonFinite, 0);
    EXPECT_EQ(state.escaped, 0);
    EXPECT_LT(deepest, 0.01);                       // measured 0.002
    EXPECT_GT(topHeight(*scene), startTop - 0.05);  // measured 0.011 lower
    checkPairs(*scene, "spatial-hash", 300);
}

/// Bullet's solver (10 iterations) does not hold 1 kg boxes under 1000 kg ones: measured,
/// the 20-box stack sinks deep into its light boxes within a second and half of it falls off
/// (1 substep: 10 escaped, deepest contact 1.0 m). The health metrics must show that.
TEST(SceneHealth, MassRatioStackCollapseIsReported) {
    auto scene = build("mass-ratio-stack", "spatial-hash", {});
    const double startTop = topHeight(*scene);
    double deepest = 0;
    for (int frame = 0; frame < 180; ++frame) {
        scene->step();
        deepest = std::max(deepest, scene->state().maxPenetration);
        checkPairs(*scene, "spatial-hash", frame);
    }
    const SceneState state = scene->state();
    EXPECT_EQ(state.nonFinite, 0);
    EXPECT_GT(state.escaped, 0);
    EXPECT_GT(deepest, 0.2);
    EXPECT_LT(topHeight(*scene), startTop - 1);
}

TEST(SceneHealth, EscapeGetsKilometresOutWithExactPairs) {
    auto scene = build("escape", "grid", {});
    double farthest = 0;
    for (int frame = 0; frame < 60; ++frame) {
        scene->step();
        checkPairs(*scene, "grid", frame);
    }
    for (const btVector3& position : scene->positions()) {
        farthest = std::max(farthest, double(position.length()));
    }
    EXPECT_EQ(scene->state().nonFinite, 0);
    EXPECT_GT(farthest, 2000.0);
}

TEST(SceneHealth, RaysHitTheTerrain) {
    SceneOptions options;
    options.objects = 24;
    auto scene = build("mixed-rays", "dbvt", options);
    for (int frame = 0; frame < 3; ++frame) {
        scene->step();
        // The 400 vertical rays all lie over the terrain; some slanted ones leave it.
        EXPECT_GE(scene->state().rayHits, 400) << "frame " << frame;
        EXPECT_LE(scene->state().rayHits, 500) << "frame " << frame;
        EXPECT_GT(scene->lastRaySeconds(), 0) << "frame " << frame;
    }
    auto noRays = build("mixed-terrain", "dbvt", options);
    noRays->step();
    EXPECT_EQ(noRays->state().rayHits, 0);
    EXPECT_EQ(noRays->lastRaySeconds(), 0);
}

// --- assets ---

#ifdef KOLIZE_WITH_ASSIMP
TEST(SceneAssets, MeshesLoadsTheFourModelsAsSmallHulls) {
    if (!assetsPresent()) {
        GTEST_SKIP() << "assimp's test models are not installed under " << kAssetDir
                     << " (Debian: assimp-testmodels)";
    }
    for (const char* model :
         {"ASE/ThreeCubesGreen.ASE", "ASE/RotatingCube.ASE", "OBJ/spider.obj", "PLY/Wuson.ply"}) {
        const LoadedMesh mesh = loadMesh(std::string(kAssetDir) + "/" + model);
        EXPECT_GE(mesh.vertices.size(), 8u) << model;
        EXPECT_GE(mesh.triangles.size(), 12u) << model;
        for (const auto& triangle : mesh.triangles) {
            for (int index : triangle) {
                ASSERT_TRUE(index >= 0 && index < int(mesh.vertices.size())) << model;
            }
        }
    }
    SceneOptions options;
    options.objects = 8;
    auto scene = build("meshes", "dbvt", options);
    auto* world = dynamic_cast<WorldScene*>(scene.get());
    ASSERT_NE(world, nullptr);
    EXPECT_EQ(world->movingObjects(), 8);
    std::set<const btCollisionShape*> hulls;
    for (const btRigidBody* body : world->bodies()) {
        if (body->isStaticObject()) {
            EXPECT_EQ(body->getCollisionShape()->getShapeType(), TRIANGLE_MESH_SHAPE_PROXYTYPE);
            continue;
        }
        const auto* hull = dynamic_cast<const btConvexHullShape*>(body->getCollisionShape());
        ASSERT_NE(hull, nullptr);
        hulls.insert(hull);
        EXPECT_GE(hull->getNumPoints(), 4);
        EXPECT_LE(hull->getNumPoints(), 64);
        btVector3 lo = hull->getUnscaledPoints()[0], hi = lo;
        for (int i = 0; i < hull->getNumPoints(); ++i) {
            lo.setMin(hull->getUnscaledPoints()[i]);
            hi.setMax(hull->getUnscaledPoints()[i]);
        }
        // The model is scaled to 1.5 m along its longest side; the reduced hull keeps the
        // support points of 42 directions, so its extent is at most that and not far below.
        const btVector3 extent = hi - lo;
        EXPECT_LE(double(extent[extent.maxAxis()]), 1.5 + 1e-4);
        EXPECT_GE(double(extent[extent.maxAxis()]), 1.3);
    }
    EXPECT_EQ(hulls.size(), 4u);  // the four models, cycled
}

TEST(SceneAssets, MissingFileThrowsNamingIt) {
    SceneOptions options;
    options.objects = 4;
    options.assetDir = "/nonexistent-kolize-assets";
    try {
        build("meshes", "dbvt", options);
        FAIL() << "no exception";
    } catch (const std::runtime_error& error) {
        const std::string message = error.what();
        EXPECT_NE(message.find("/nonexistent-kolize-assets/ASE/ThreeCubesGreen.ASE"),
                  std::string::npos)
            << message;
    }
    EXPECT_THROW(loadMesh("/nonexistent-kolize-assets/x.obj"), std::runtime_error);
}
#endif

// --- far from the origin ---

/// offset-1e6: pairs stay exact over the exact broadphases, and the bodies land on the plane
/// without falling through. In float, positions out there are multiples of 1/16 m: measured,
/// resting bodies sit up to one such step below where they would rest at the origin.
TEST(SceneOffsets, FarOutPairsStayExact) {
    SceneOptions options;
    options.objects = 40;
    for (const std::string broadphase : {"spatial-hash", "grid", "segment-trees", "range-tree"}) {
        SCOPED_TRACE(broadphase);
        auto scene = build("offset-1e6", broadphase, options);
        for (int frame = 0; frame < 90; ++frame) {
            scene->step();
            checkPairs(*scene, broadphase, frame);
        }
        const SceneState state = scene->state();
        EXPECT_EQ(state.nonFinite, 0);
        EXPECT_EQ(state.escaped, 0);
        double lowest = 1e30;
        for (const btVector3& position : scene->positions()) {
            lowest = std::min(lowest, double(position.y()));
        }
        EXPECT_GT(lowest, -0.1);  // the smallest body rests 0.06 m up at the origin
        EXPECT_LT(lowest, 0.5);   // landed
    }
}

}  // namespace
}  // namespace kolize
