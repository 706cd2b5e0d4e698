// With Bullet's deterministic pair order on, a world over any exact kolize broadphase must
// evolve bit for bit like the same world over btSimpleBroadphase (exact pairs, O(N^2)):
// same pairs, same contacts, same solver order.

#include <kolize/engine/falling_boxes.h>
#include <kolize/kolize.h>

#include <btBulletDynamicsCommon.h>
#include <gtest/gtest.h>

#include <cmath>

#include <string>
#include <vector>

namespace {

std::vector<std::uint64_t> run(const std::string& name, bool planeGround, int frames) {
    kolize::FallingBoxesSettings settings;
    settings.layers = 3;
    settings.boxesPerRow = 5;
    settings.groundIsPlane = planeGround;
    kolize::FallingBoxesWorld scene(kolize::makeBroadphase(name), settings);
    scene.world()->getDispatchInfo().m_deterministicOverlappingPairs = true;
    std::vector<std::uint64_t> hashes;
    for (int frame = 0; frame < frames; ++frame) {
        scene.step();
        hashes.push_back(scene.stateHash());
    }
    // Meaningful: the boxes reached the ground and each other.
    EXPECT_GT(scene.dispatcher().getNumManifolds(), 25) << name;
    return hashes;
}

TEST(Determinism, ExactBroadphasesMatchSimpleBitForBit) {
    constexpr int kFrames = 90;
    for (bool plane : {false, true}) {
        const std::vector<std::uint64_t> simple = run("simple", plane, kFrames);
        // The hash sees the motion: states differ from frame to frame.
        EXPECT_NE(simple.front(), simple.back());
        for (const std::string& name : kolize::broadphaseNames()) {
            if (!kolize::isExactBroadphase(name)) {
                continue;
            }
            const std::vector<std::uint64_t> hashes = run(name, plane, kFrames);
            for (int frame = 0; frame < kFrames; ++frame) {
                ASSERT_EQ(hashes[frame], simple[frame])
                    << name << (plane ? " on a plane" : " on a box")
                    << ": first difference at frame " << frame;
            }
        }
    }
}

TEST(Determinism, HashSeesAOneBitChange) {
    kolize::FallingBoxesSettings settings;
    settings.layers = 1;
    kolize::FallingBoxesWorld scene(kolize::makeBroadphase("grid"), settings);
    const std::uint64_t before = scene.stateHash();
    btRigidBody* body = scene.bodies().back();
    btVector3 velocity = body->getLinearVelocity();
    velocity.setX(std::nextafter(velocity.x(), btScalar(1)));
    body->setLinearVelocity(velocity);
    EXPECT_NE(scene.stateHash(), before);
}

}  // namespace
