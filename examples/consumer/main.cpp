// A plain btDiscreteDynamicsWorld app. Its only kolize line is the broadphase.
#include <btBulletDynamicsCommon.h>
#include <kolize/kolize.h>

#include <cstdio>
#include <memory>
#include <vector>

int main(int argc, char** argv) {
    const char* name = argc > 1 ? argv[1] : "brute-force";
    btDefaultCollisionConfiguration configuration;
    btCollisionDispatcher dispatcher(&configuration);
    std::unique_ptr<btBroadphaseInterface> broadphase =
        kolize::makeBroadphase(name);  // was: new btDbvtBroadphase()
    btSequentialImpulseConstraintSolver solver;
    btDiscreteDynamicsWorld world(&dispatcher, broadphase.get(), &solver, &configuration);
    world.setGravity(btVector3(0, -10, 0));

    btStaticPlaneShape groundShape(btVector3(0, 1, 0), 0);
    btRigidBody ground(0, nullptr, &groundShape);
    world.addRigidBody(&ground);
    btSphereShape sphereShape(0.5);
    btVector3 inertia;
    sphereShape.calculateLocalInertia(1, inertia);
    std::vector<std::unique_ptr<btDefaultMotionState>> states;
    std::vector<std::unique_ptr<btRigidBody>> spheres;
    for (int i = 0; i < 10; ++i) {
        states.push_back(std::make_unique<btDefaultMotionState>(
            btTransform(btQuaternion::getIdentity(), btVector3(0, 1 + 1.1 * i, 0))));
        spheres.push_back(
            std::make_unique<btRigidBody>(1, states.back().get(), &sphereShape, inertia));
        world.addRigidBody(spheres.back().get());
    }
    for (int step = 0; step < 240; ++step) {
        world.stepSimulation(1.0 / 60.0, 0);
    }
    const btScalar lowest = spheres.front()->getCenterOfMassPosition().y();
    std::printf("consumer with %s: %d pairs, lowest sphere at y = %.3f\n", name,
                world.getBroadphase()->getOverlappingPairCache()->getNumOverlappingPairs(), lowest);
    for (auto& sphere : spheres) {
        world.removeRigidBody(sphere.get());
    }
    world.removeRigidBody(&ground);
    // The sphere resting on the plane must be held up by it.
    return lowest > 0.4 && lowest < 0.6 ? 0 : 1;
}
