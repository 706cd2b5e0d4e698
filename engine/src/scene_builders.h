#pragma once
/// \file
/// The scene registry's internals: a builder per scene. scene.cpp registers the thesis and
/// falling-boxes scenes; world_scenes.cpp adds the other world scenes.

#include <kolize/engine/scene.h>

#include <memory>
#include <vector>

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

/// Appends the scenes of Bullet's own benchmark (BenchmarkDemo), rebuilt from their
/// description (bullet_benchmark_scenes.cpp).
void addBulletBenchmarkScenes(std::vector<SceneEntry>& entries);

}  // namespace kolize
