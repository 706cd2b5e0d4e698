// The world scenes beyond the falling boxes: Bullet-benchmark worlds, assimp meshes, extreme
// and stiff cases.

#include "scene_builders.h"

#include <kolize/engine/world_scene.h>

#include <btBulletDynamicsCommon.h>

namespace kolize {

void addWorldScenes(std::vector<SceneEntry>& entries) {
    (void)entries;
}

}  // namespace kolize
