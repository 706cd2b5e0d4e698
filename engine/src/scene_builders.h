#pragma once
/// \file
/// The scene registry's internals: a builder per scene. scene.cpp registers the thesis and
/// falling-boxes scenes; world_scenes.cpp adds the other world scenes.

#include <kolize/engine/scene.h>

#include <LinearMath/btQuaternion.h>
#include <LinearMath/btTransform.h>

#include <functional>
#include <memory>
#include <random>
#include <vector>

class btRigidBody;

namespace kolize {

using SceneBuilder = std::unique_ptr<Scene> (*)(const SceneInfo& info,
                                                std::unique_ptr<btBroadphaseInterface> broadphase,
                                                const SceneOptions& options);

struct SceneEntry {
    SceneInfo info;
    SceneBuilder build;
};

/// Every scene with its builder, in --help order.
const std::vector<SceneEntry>& sceneEntries();

/// Appends the world scenes of world_scenes.cpp (Bullet-benchmark worlds, meshes, extreme
/// and stiff cases).
void addWorldScenes(std::vector<SceneEntry>& entries);

class WorldScene;

/// Shorthands of the scene builders.
inline btVector3 vec(double x, double y, double z) {
    return btVector3(btScalar(x), btScalar(y), btScalar(z));
}
inline btTransform at(const btVector3& position,
                      const btQuaternion& rotation = btQuaternion::getIdentity()) {
    return btTransform(rotation, position);
}
inline double uniform(std::mt19937& rng, double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng);
}

/// A uniformly distributed rotation (a normalised 4D Gaussian sample).
btQuaternion randomRotation(std::mt19937& rng);

/// A static btBvhTriangleMeshShape (at the identity, shifted by the scene's origin) over a
/// rows x columns grid of quads whose corner (i, j) is point(i, j), i in 0..rows, j in
/// 0..columns. Degenerate triangles (a bowl's pole) are left out. Returns the body.
btRigidBody* addGridMesh(WorldScene& scene, int rows, int columns,
                         const std::function<btVector3(int, int)>& point);

/// A static hemispherical triangle-mesh bowl of `radius` (12 rings of 36 segments): bottom
/// at y = 0, rim at y = radius. Returns the body.
btRigidBody* addBowl(WorldScene& scene, double radius);

/// Appends the world scenes of mesh_body_scenes.cpp: mesh bodies colliding mesh against mesh
/// (kolize's narrowphase or GImpact, SceneOptions::meshMethod).
void addMeshBodyScenes(std::vector<SceneEntry>& entries);

/// Appends the scenes of Bullet's own benchmark (BenchmarkDemo), rebuilt from their
/// description (bullet_benchmark_scenes.cpp).
void addBulletBenchmarkScenes(std::vector<SceneEntry>& entries);

}  // namespace kolize
