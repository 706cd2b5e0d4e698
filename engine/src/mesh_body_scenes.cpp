// The mesh-body scenes: rigid bodies whose collision shapes are triangle meshes, colliding
// mesh against mesh in a btDiscreteDynamicsWorld, through kolize's narrowphase
// (kolize::MeshShape, registerNarrowphase, mesh CCD) or Bullet's GImpact, chosen by
// SceneOptions::meshMethod. Every body also gets its exact mesh (WorldScene::setExactMesh) so
// that a contact audit can check any method's contacts against the exact triangle test.

#include "scene_builders.h"

#include <kolize/engine/world_scene.h>
#include <kolize/narrowphase/bullet_mesh.h>
#ifdef KOLIZE_WITH_ASSIMP
#include <kolize/engine/assets.h>
#endif

#include <BulletCollision/Gimpact/btGImpactCollisionAlgorithm.h>
#include <BulletCollision/Gimpact/btGImpactShape.h>
#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <stdexcept>
#include <string>

namespace kolize {

namespace {

using narrowphase::Index3;
using narrowphase::MeshModel;
using narrowphase::TriangleMesh;
using narrowphase::Vec3;
using Model = std::shared_ptr<const MeshModel>;
using Rng = std::mt19937;

constexpr double kFar = 1e9;

enum class MeshMethod { kKolize, kGImpact, kGImpactZeroMargin };

MeshMethod methodOf(const SceneInfo& info, const SceneOptions& options) {
    if (options.meshMethod == "kolize") {
        return MeshMethod::kKolize;
    }
    if (options.meshMethod == "gimpact") {
        return MeshMethod::kGImpact;
    }
    if (options.meshMethod == "gimpact-0") {
        return MeshMethod::kGImpactZeroMargin;
    }
    throw std::invalid_argument("scene '" + info.name + "': unknown mesh method '" +
                                options.meshMethod + "'; valid: kolize, gimpact, gimpact-0");
}

/// A mesh from float coordinates (what Bullet's shapes store), so that every method and the
/// exact check see the same vertices.
Model modelOf(const std::string& name, const std::vector<float>& xyz,
              const std::vector<std::int32_t>& indices) {
    return makeMeshModel(
        TriangleMesh::fromArrays(name, xyz.data(), xyz.size() / 3, indices.data(), indices.size()));
}

/// A box mesh of half extents `half` centred on its origin: 8 vertices, 12 triangles wound
/// outward.
Model boxModel(const Vec3& half) {
    std::vector<float> xyz;
    for (int i = 0; i < 8; ++i) {
        for (int axis = 0; axis < 3; ++axis) {
            xyz.push_back(float((i >> axis & 1) != 0 ? half[axis] : -half[axis]));
        }
    }
    const std::vector<std::int32_t> indices = {0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6,
                                               0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5,
                                               0, 1, 5, 0, 5, 4, 2, 6, 7, 2, 7, 3};
    return modelOf("box", xyz, indices);
}

#ifdef KOLIZE_WITH_ASSIMP
/// A model file's mesh, scaled to `size` along its longest side and centred on its centroid
/// (closed meshes) or on its bounding box (open ones), so that the body's origin is its centre
/// of mass as Bullet assumes.
Model assetModel(const SceneOptions& options, const std::string& file, double size) {
    const LoadedMesh loaded = loadMesh(options.assetDir + "/" + file);
    btVector3 lo = loaded.vertices.front(), hi = lo;
    for (const btVector3& v : loaded.vertices) {
        lo.setMin(v);
        hi.setMax(v);
    }
    const double scale = size / double((hi - lo)[(hi - lo).maxAxis()]);
    std::vector<std::int32_t> indices;
    for (const auto& t : loaded.triangles) {
        indices.insert(indices.end(), t.begin(), t.end());
    }
    auto place = [&](const Vec3& centre) {
        std::vector<float> xyz;
        for (const btVector3& v : loaded.vertices) {
            for (int axis = 0; axis < 3; ++axis) {
                xyz.push_back(float((double(v[axis]) - centre[axis]) * scale));
            }
        }
        return xyz;
    };
    const btVector3 mid = (lo + hi) / 2;
    const Vec3 boxCentre(double(mid.x()), double(mid.y()), double(mid.z()));
    std::vector<float> xyz = place(boxCentre);
    const MeshMassProperties mass = meshMassProperties(
        TriangleMesh::fromArrays(file, xyz.data(), xyz.size() / 3, indices.data(), indices.size()));
    if (mass.closed) {
        xyz = place(boxCentre + mass.centroid / scale);
    }
    return modelOf(file, xyz, indices);
}

const char* const kPileModels[] = {"PLY/Wuson.ply", "Collada/duck.dae", "OBJ/spider.obj",
                                   "ASE/ThreeCubesGreen.ASE"};
#endif

/// Bullet's arrays of a GImpact shape (kept alive by the scene).
struct GImpactData {
    std::vector<btScalar> vertices;
    std::vector<int> indices;
};

/// Makes the shapes of one mesh method and the bodies that use them.
class MeshBodies {
  public:
    MeshBodies(WorldScene& scene, MeshMethod method) : scene_(scene), method_(method) {
        if (method == MeshMethod::kKolize) {
            registerNarrowphase(&scene.dispatcher());
            // kolize's mesh CCD when the scene runs CCD (Bullet's swept sphere never reaches
            // a concave shape).
            scene.world()->setMeshCcd(scene.bulletCcd());
        } else {
            btGImpactCollisionAlgorithm::registerAlgorithm(&scene.dispatcher());
        }
    }

    /// A body of `model` (mass 0: static) at `transform`.
    btRigidBody* add(const Model& model, double mass, const btTransform& transform,
                     const btVector3& velocity = btVector3(0, 0, 0)) {
        btRigidBody* body = scene_.addBody(shapeOf(model), mass, transform, velocity);
        scene_.setExactMesh(body, model);
        return body;
    }

    /// Static triangle-mesh scenery (btBvhTriangleMeshShape): its triangles become its exact
    /// mesh.
    void addScenery(btRigidBody* body) {
        auto* shape = static_cast<btBvhTriangleMeshShape*>(body->getCollisionShape());
        const btStridingMeshInterface* mesh = shape->getMeshInterface();
        std::vector<float> xyz;
        std::vector<std::int32_t> indices;
        struct Collect : btInternalTriangleIndexCallback {
            std::vector<float>* xyz;
            void internalProcessTriangleIndex(btVector3* t, int, int) override {
                for (int k = 0; k < 3; ++k) {
                    for (int axis = 0; axis < 3; ++axis) {
                        xyz->push_back(float(t[k][axis]));
                    }
                }
            }
        } collect;
        collect.xyz = &xyz;
        const btVector3 huge = vec(kFar, kFar, kFar);
        mesh->InternalProcessAllTriangles(&collect, -huge, huge);
        for (std::size_t i = 0; i < xyz.size() / 3; ++i) {
            indices.push_back(std::int32_t(i));
        }
        scene_.setExactMesh(body, modelOf("scenery", xyz, indices));
    }

  private:
    btCollisionShape* shapeOf(const Model& model) {
        const auto known = shapes_.find(model.get());
        if (known != shapes_.end()) {
            return known->second;
        }
        btCollisionShape* shape = nullptr;
        if (method_ == MeshMethod::kKolize) {
            shape = scene_.own(new MeshShape(model));
        } else {
            auto data = std::make_shared<GImpactData>();
            for (const Vec3& v : model->mesh().vertices()) {
                for (int axis = 0; axis < 3; ++axis) {
                    data->vertices.push_back(btScalar(v[axis]));
                }
            }
            for (const Index3& t : model->mesh().triangles()) {
                data->indices.insert(data->indices.end(), t.begin(), t.end());
            }
            auto* array = new btTriangleIndexVertexArray(
                int(model->mesh().triangleCount()), data->indices.data(), int(3 * sizeof(int)),
                int(model->mesh().vertices().size()), data->vertices.data(),
                int(3 * sizeof(btScalar)));
            scene_.ownMesh(array);
            scene_.keep(data);
            auto* gimpact = new btGImpactMeshShape(array);
            if (method_ == MeshMethod::kGImpactZeroMargin) {
                gimpact->setMargin(0);
            }
            gimpact->updateBound();
            shape = scene_.own(gimpact);
        }
        shapes_[model.get()] = shape;
        return shape;
    }

    WorldScene& scene_;
    MeshMethod method_;
    std::map<const MeshModel*, btCollisionShape*> shapes_;
};

/// The lowest y of the model's vertices.
double bottomOf(const Model& model) {
    double bottom = 1e300;
    for (const Vec3& v : model->mesh().vertices()) {
        bottom = std::min(bottom, v.y());
    }
    return bottom;
}

template <void (*fill)(WorldScene&, MeshBodies&, Rng&, int)>
std::unique_ptr<Scene> buildMeshScene(const SceneInfo& info,
                                      std::unique_ptr<btBroadphaseInterface> broadphase,
                                      const SceneOptions& options) {
    const MeshMethod method = methodOf(info, options);
    auto scene = std::make_unique<WorldScene>(info, std::move(broadphase), options);
    MeshBodies bodies(*scene, method);
    Rng rng(options.seed);
    fill(*scene, bodies, rng, options.objects > 0 ? options.objects : info.defaultObjects);
    return scene;
}

#ifdef KOLIZE_WITH_ASSIMP
constexpr double kPileSize = 1.0;    // m, each model's longest side
constexpr double kPilePitch = 1.6;   // m between drop positions (> the bounding sphere)
constexpr double kBowlRadius = 4.0;  // m

void fillPile(WorldScene& scene, MeshBodies& bodies, Rng& rng, int count) {
    std::vector<Model> models;
    for (const char* file : kPileModels) {
        models.push_back(assetModel(scene.options(), file, kPileSize));
    }
    bodies.addScenery(addBowl(scene, kBowlRadius));
    // Layers of 3 x 3 drop positions above the bowl's bottom.
    for (int i = 0; i < count; ++i) {
        const int layer = i / 9, column = i % 9;
        const btVector3 position = vec(kPilePitch * (column % 3 - 1), 1.5 + kPilePitch * layer,
                                       kPilePitch * (column / 3 - 1));
        bodies.add(models[std::size_t(i) % models.size()], 1, at(position, randomRotation(rng)));
    }
    scene.setContainer(vec(-kBowlRadius - 1, -1, -kBowlRadius - 1),
                       vec(kBowlRadius + 1, kFar, kBowlRadius + 1));
}

constexpr double kWallHalfThickness = 0.01;  // m: a 2 cm wall
constexpr double kWallBodySize = 0.5;        // m
constexpr double kWallCcdThreshold = 0.05;   // m per step

void fillWall(WorldScene& scene, MeshBodies& bodies, Rng& rng, int count) {
    std::vector<Model> models;
    for (const char* file : kPileModels) {
        models.push_back(assetModel(scene.options(), file, kWallBodySize));
    }
    // One lane per body, 1 m apart along z, in front of a wall 40 m high and 60 m wider than
    // the lanes on each side (a fast body deflected upwards stays in front of it), standing on
    // a ground (a box mesh, top at y = 0) where the bodies land after the hit.
    const double middle = 0.5 * (count - 1), halfSpan = 0.5 * count + 60;
    bodies.add(boxModel(Vec3(kWallHalfThickness, 20, halfSpan)), 0, at(vec(0, 20, middle)));
    bodies.add(boxModel(Vec3(100, 0.5, halfSpan + 40)), 0, at(vec(0, -0.5, middle)));
    for (int i = 0; i < count; ++i) {
        // Speeds from 1 to 200 m/s, geometrically spaced; every body reaches the wall
        // after about 0.1 s (a few centimetres of fall).
        const double speed = count > 1 ? std::pow(200.0, double(i) / (count - 1)) : 200.0;
        const double start = -(kWallBodySize + 0.05 + 0.1 * speed);
        btRigidBody* body = bodies.add(models[std::size_t(i) % models.size()], 1,
                                       at(vec(start, 2, double(i)), randomRotation(rng)),
                                       vec(speed, 0, 0));
        // CCD (when on) for motions over kWallCcdThreshold per step. The default threshold,
        // half the body's bounding radius (12 cm and more here), let a body moving 18 cm per
        // step (44 m/s at 1/240 s) through the 2 cm wall with no time of impact asked. Half
        // the wall's thickness (1 cm) would exclude tunnelling by construction, but then every
        // sliding or tumbling body computes times of impact against the ground and the wall,
        // and one that turns about its contact is stopped there (a time of impact of 0) every
        // step: 2.9 ms per frame at 1/60 s instead of 0.35, 4-5 of 8 bodies clamped per step.
        if (body->getCcdMotionThreshold() > 0) {
            body->setCcdMotionThreshold(btScalar(kWallCcdThreshold));
        }
    }
    // Escaped: past the wall's mid-plane (x = 0), i.e. tunnelled.
    scene.setContainer(vec(-kFar, -kFar, -kFar), vec(0, kFar, kFar));
}

void fillFloor(WorldScene& scene, MeshBodies& bodies, Rng& rng, int count) {
    const Model box = boxModel(Vec3(0.25, 0.25, 0.25));
    const Model duck = assetModel(scene.options(), "Collada/duck.dae", 0.6);
    // A flat floor of 40 x 40 quads of 0.5 m at y = 0: its internal edges are where convex
    // and mesh contacts get sideways (ghost) normals.
    bodies.addScenery(addGridMesh(scene, 40, 40, [](int i, int j) {
        return vec(0.5 * i - 10, 0, 10 - 0.5 * j);  // wound so that the faces look up
    }));
    for (int i = 0; i < count; ++i) {
        const Model& model = i % 3 == 2 ? duck : box;
        // Resting exactly on the floor (lowest vertex at y = 0), turned about y, sliding.
        const double turn = uniform(rng, 0, 3.14159265358979323846);
        const btQuaternion rotation(btVector3(0, 1, 0), btScalar(turn));
        const btVector3 position = vec(-8 + 1.5 * (i % 6), -bottomOf(model), -6 + 2.0 * (i / 6));
        bodies.add(model, 1, at(position, rotation), vec(1.5, 0, 0.2));
    }
    scene.setContainer(vec(-10, -0.05, -10), vec(10, kFar, 10));
}
#endif

void fillBoxStack(WorldScene& scene, MeshBodies& bodies, Rng&, int count) {
    const Model box = boxModel(Vec3(0.5, 0.5, 0.5));
    bodies.add(boxModel(Vec3(5, 0.5, 5)), 0, at(vec(0, -0.5, 0)));
    // A column, each box exactly on the one below (faces at y = 0, 1, 2, ...), every other
    // one shifted by 0.1 m in x so that the contact patches differ.
    for (int i = 0; i < count; ++i) {
        bodies.add(box, 1, at(vec(i % 2 == 0 ? 0.0 : 0.1, 0.5 + i, 0)));
    }
    scene.setContainer(vec(-5, -0.05, -5), vec(5, kFar, 5));
}

SceneNeeds meshNeeds(bool continuous) {
    SceneNeeds out;
    out.meshes = true;
    out.continuous = continuous;
    return out;
}

const char* const kMethodClause =
    "meshes: every body a triangle mesh colliding mesh against mesh (kolize's narrowphase or "
    "GImpact: --mesh-method)";

}  // namespace

void addMeshBodyScenes(std::vector<SceneEntry>& entries) {
    auto add = [&](SceneInfo info, SceneBuilder builder) {
        entries.push_back({std::move(info), builder});
    };
    const std::string method = kMethodClause;
#ifdef KOLIZE_WITH_ASSIMP
    add({"mesh-pile",
         "N (default 24) mesh bodies (Wuson, duck, spider, ThreeCubesGreen; 1 m, random "
         "orientations) dropped in layers into a triangle-mesh bowl",
         "mesh-world", 24, meshNeeds(false),
         "dynamics: the meshes fall and pile; no rays: nothing casts; " + method +
             ", the bowl a static btBvhTriangleMeshShape; no continuous stages: drops of a few "
             "metres move under 0.2 m per step",
         0, 30},
        buildMeshScene<fillPile>);
    add({"mesh-wall",
         "N (default 8) 0.5 m mesh bodies thrown at a 2 cm mesh wall (40 m high) at 1 to 200 m/s "
         "(geometric steps), one lane each; escaped = tunnelled",
         "mesh-world", 8, meshNeeds(true),
         "dynamics: the bodies hit the wall; no rays: nothing casts; " + method +
             "; continuous: up to 3.3 m per step against a 2 cm wall (kolize: its mesh CCD; "
             "GImpact has none, Bullet's swept sphere is for convex shapes only)",
         0, 1000},
        buildMeshScene<fillWall>);
    add({"mesh-floor",
         "N (default 6) box meshes and ducks resting on and sliding over a flat triangle-mesh "
         "floor (40 x 40 quads): the internal-edge ghost-contact case",
         "mesh-world", 6, meshNeeds(false),
         "dynamics: the bodies slide and stop; no rays: nothing casts; " + method +
             ", the floor a static btBvhTriangleMeshShape; no continuous stages: 1.5 m/s",
         0, 30},
        buildMeshScene<fillFloor>);
#endif
    add({"mesh-box-stack",
         "a column of N (default 5) 1 m box meshes, each exactly on the one below (every other "
         "one shifted by 0.1 m), on a box-mesh ground: contacts with known normals and depths",
         "mesh-world", 5, meshNeeds(false),
         "dynamics: the solver must hold the column; no rays: nothing casts; " + method +
             "; no continuous stages: the boxes start at rest in contact",
         0, 30},
        buildMeshScene<fillBoxStack>);
}

}  // namespace kolize
