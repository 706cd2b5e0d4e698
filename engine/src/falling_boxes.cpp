#include <kolize/engine/falling_boxes.h>

#include <btBulletDynamicsCommon.h>

namespace kolize {

namespace {

SceneOptions withStep(SceneOptions options, const FallingBoxesSettings& settings) {
    options.timeStep = settings.timeStep;
    return options;
}

}  // namespace

FallingBoxesWorld::FallingBoxesWorld(std::unique_ptr<btBroadphaseInterface> broadphase,
                                     const FallingBoxesSettings& settings,
                                     const SceneOptions& options)
    : WorldScene(findScene(settings.groundIsPlane ? "boxes-plane" : "boxes"), std::move(broadphase),
                 withStep(options, settings)) {
    const btScalar half = btScalar(settings.boxHalfExtent);
    const btScalar pitch = 2 * half + btScalar(settings.gap);
    const btScalar rowWidth = btScalar(settings.boxesPerRow) * pitch;
    btTransform groundTransform;
    groundTransform.setIdentity();
    if (settings.groundIsPlane) {
        addBody(own(new btStaticPlaneShape(btVector3(0, 1, 0), 0)), 0, groundTransform);
    } else {
        groundTransform.setOrigin(btVector3(0, -1, 0));
        addBody(own(new btBoxShape(btVector3(rowWidth * 4, 1, rowWidth * 4))), 0, groundTransform);
    }
    btCollisionShape* box = own(new btBoxShape(btVector3(half, half, half)));
    const btScalar offset = -rowWidth / 2 + pitch / 2;
    for (int layer = 0; layer < settings.layers; ++layer) {
        for (int row = 0; row < settings.boxesPerRow; ++row) {
            for (int column = 0; column < settings.boxesPerRow; ++column) {
                btTransform transform;
                transform.setIdentity();
                transform.setOrigin(btVector3(offset + column * pitch,
                                              half + pitch / 2 + layer * pitch,
                                              offset + row * pitch));
                addBody(box, 1, transform);
            }
        }
    }
    // A box whose centre sinks below the ground's top by more than its half extent has
    // passed through it.
    const btScalar far = btScalar(1e9);
    setContainer(btVector3(-far, -half, -far), btVector3(far, far, far));
}

}  // namespace kolize
