// Mesh against mesh over a step: earliest time of impact and the features involved.
#include "kolize/narrowphase/mesh_ccd.h"

#include <gtest/gtest.h>

#include <stdexcept>

namespace {

using namespace kolize::ccd;

/// Unit cube [0,1]^3 + origin (8 vertices, 12 triangles), moved by `motion` over the step.
MovingMesh cube(const Vec3& origin, const Vec3& motion) {
    MovingMesh m;
    for (int i = 0; i < 8; ++i) {
        const Vec3 p = origin + Vec3(i & 1, (i >> 1) & 1, (i >> 2) & 1);
        m.start.push_back(p);
        m.end.push_back(p + motion);
    }
    m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                   {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    return m;
}

TEST(CcdMesh, CubesMeetFaceToFace) {
    // A (x in [0, 1]) moves +1 in x towards B (x in [1.5, 2.5]): contact at t = 1/2.
    const MovingMesh a = cube({0, 0, 0}, {1, 0, 0});
    const MovingMesh b = cube({1.5, 0.25, 0.25}, {0, 0, 0});
    const MeshContact c = meshCcd(a, b);
    ASSERT_TRUE(c.hit);
    EXPECT_LE(c.toi, 0.5);
    EXPECT_GE(c.toi, 0.5 - 1e-4);
    EXPECT_GT(c.primitive_queries, 0u);
    // The contact is on A's x = 1 face (vertices 1, 3, 5, 7) or B's x = 1.5 face.
    const bool a_face_x1 =
        c.features != ContactFeatures::kFaceAVertexB || c.a[0] == 10 || c.a[0] == 11;
    EXPECT_TRUE(a_face_x1);
}

TEST(CcdMesh, CubesPassingBesideDoNotTouch) {
    // A slides along y next to B with a gap of 0.25 in x: swept boxes overlap in y and z
    // only, so no candidate pair survives and no contact is reported.
    const MovingMesh a = cube({0, -2, 0}, {0, 4, 0});
    const MovingMesh b = cube({1.25, 0, 0}, {0, 0, 0});
    const MeshContact c = meshCcd(a, b);
    EXPECT_FALSE(c.hit);
    EXPECT_EQ(c.triangle_pairs, 0u);
}

TEST(CcdMesh, EdgeThroughEdgeIsFoundWhenNoVertexTouchesAFace) {
    // Two thin tetrahedra: A's bottom edge (along x) sweeps down through B's top edge
    // (along y) at the origin at t = 1/2, while no vertex ever reaches a face.
    MovingMesh a, b;
    a.start = {{-1, 0, 1}, {1, 0, 1}, {0, -0.1, 2}, {0, 0.1, 2}};
    for (const Vec3& p : a.start) {
        a.end.push_back(p - Vec3(0, 0, 2));
    }
    a.triangles = {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}};
    b.start = {{0, -1, 0}, {0, 1, 0}, {-0.1, 0, -1}, {0.1, 0, -1}};
    b.end = b.start;
    b.triangles = {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}};
    const MeshContact c = meshCcd(a, b);
    ASSERT_TRUE(c.hit);
    EXPECT_LE(c.toi, 0.5);
    EXPECT_GE(c.toi, 0.5 - 1e-4);
    EXPECT_EQ(c.features, ContactFeatures::kEdgeEdge);
}

TEST(CcdMesh, RejectsInconsistentMeshes) {
    MovingMesh a = cube({0, 0, 0}, {1, 0, 0});
    a.end.pop_back();
    EXPECT_THROW(meshCcd(a, cube({2, 0, 0}, {0, 0, 0})), std::invalid_argument);
}

}  // namespace

namespace {

TEST(CcdMesh, BackFaceCullingSkipsTestsButKeepsThisTranslationContact) {
    const MovingMesh a = cube({0, 0, 0}, {1, 0, 0});
    const MovingMesh b = cube({1.5, 0.25, 0.25}, {0, 0, 0});
    MeshCcdSettings cull;
    cull.cull_back_facing = true;
    const MeshContact full = meshCcd(a, b);
    const MeshContact culled = meshCcd(a, b, cull);
    EXPECT_GT(culled.culled, 0u);
    EXPECT_LT(culled.primitive_queries, full.primitive_queries);
    ASSERT_TRUE(culled.hit);  // pure translation of convex shapes: culling is safe here
    EXPECT_LE(culled.toi, 0.5);
}

}  // namespace

namespace {

TEST(CcdMesh, BackFaceCullingMissesAFaceRotatingOntoAVertexBehindIt) {
    // A's triangle hinges about the y axis (c swings from (1,0,0) down to (0,0,-1)); its
    // normal at t = 0 is +z. B is a small triangle below A's initial plane, i.e. behind
    // the face, which sweeps onto B's vertices -- possible for
    // non-convex meshes. B's vertex (0.35, 0, -0.34) is reached first, at t = 0.34 / 0.69.
    // The culling skips every B-vertex test, so only it misses.
    MovingMesh a;
    a.start = {{0, 1, 0}, {0, -1, 0}, {1, 0, 0}};
    a.end = {{0, 1, 0}, {0, -1, 0}, {0, 0, -1}};
    a.triangles = {{0, 1, 2}};
    MovingMesh b;
    b.start = {{0.3, 0, -0.3}, {0.32, 0.05, -0.35}, {0.35, 0, -0.34}};
    b.end = b.start;
    b.triangles = {{0, 1, 2}};
    const MeshContact full = meshCcd(a, b);
    ASSERT_TRUE(full.hit);
    EXPECT_LE(full.toi, 0.34 / 0.69);
    EXPECT_GE(full.toi, 0.34 / 0.69 - 1e-4);
    EXPECT_EQ(full.features, ContactFeatures::kFaceAVertexB);
    EXPECT_EQ(full.b[0], 2);
    MeshCcdSettings cull;
    cull.cull_back_facing = true;
    EXPECT_FALSE(meshCcd(a, b, cull).hit);
}

}  // namespace
