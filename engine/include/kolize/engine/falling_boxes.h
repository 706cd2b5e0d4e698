#pragma once
/// \file
/// The falling-boxes world in the spirit of Bullet's own benchmark (3000 unit boxes in 47
/// layers of 8 x 8 falling onto a static ground box or plane), as a real
/// btDiscreteDynamicsWorld over any broadphase: the scenes "boxes" and "boxes-plane".
/// Shared by tests and demos.

#include <kolize/engine/world_scene.h>

#include <memory>

namespace kolize {

/// Settings of the falling-boxes world.
struct FallingBoxesSettings {
    int layers = 47;             ///< layers of boxes (47 x 64 = 3008 boxes by default)
    int boxesPerRow = 8;         ///< a layer is boxesPerRow x boxesPerRow
    double boxHalfExtent = 0.5;  ///< unit boxes
    double gap = 0.2;            ///< space between neighbouring boxes at the start
    bool groundIsPlane = false;  ///< static btStaticPlaneShape (AABB +-1e18) instead of a box
    double timeStep = 1.0 / 60.0;
};

/// The scene "boxes" (or "boxes-plane"): a WorldScene holding the ground and the boxes.
/// The ground is bodies()[0]. Boxes falling below the ground count as escaped.
class FallingBoxesWorld : public WorldScene {
  public:
    FallingBoxesWorld(std::unique_ptr<btBroadphaseInterface> broadphase,
                      const FallingBoxesSettings& settings = {}, const SceneOptions& options = {});
};

}  // namespace kolize
