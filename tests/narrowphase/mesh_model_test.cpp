// Bad meshes get errors that name the mesh and the element; degenerate but legal data is
// accepted; models validate after every build.
#include <kolize/narrowphase/mesh_model.h>
#include <kolize/narrowphase/triangle_mesh.h>

#include "../box_mesh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>

namespace {

using namespace kolize::narrowphase;

std::vector<Vec3> square() {
    return {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
}

/// The MeshError message of constructing the mesh, or "" when it constructs.
std::string errorOf(std::vector<Vec3> vertices, std::vector<Index3> triangles) {
    try {
        TriangleMesh mesh("probe", std::move(vertices), std::move(triangles));
        return "";
    } catch (const MeshError& e) {
        return e.what();
    }
}

TEST(MeshModel, RejectsEmptyMesh) {
    EXPECT_EQ(errorOf(square(), {}), "mesh 'probe': has no triangles (4 vertices)");
    EXPECT_EQ(errorOf({}, {}), "mesh 'probe': has no triangles (0 vertices)");
}

TEST(MeshModel, RejectsNonFiniteVerticesNamingTheVertexAndAxis) {
    std::vector<Vec3> v = square();
    v[2].y() = std::numeric_limits<double>::quiet_NaN();
    EXPECT_EQ(errorOf(v, {{0, 1, 2}}),
              "mesh 'probe': vertex 2 has a non-finite coordinate (y = nan)");
    v = square();
    v[3].z() = -std::numeric_limits<double>::infinity();
    EXPECT_EQ(errorOf(v, {{0, 1, 2}}),
              "mesh 'probe': vertex 3 has a non-finite coordinate (z = -inf)");
    // Unused vertices are checked too: a NaN anywhere is bad data.
}

TEST(MeshModel, RejectsHugeCoordinates) {
    std::vector<Vec3> v = square();
    v[1].x() = 1e200;
    EXPECT_EQ(errorOf(v, {{0, 1, 2}}),
              "mesh 'probe': vertex 1 has coordinate x = 1e+200, beyond the supported "
              "magnitude 2^500");
}

TEST(MeshModel, RejectsIndicesOutOfRangeNamingTheTriangle) {
    EXPECT_EQ(errorOf(square(), {{0, 1, 2}, {0, 2, 4}}),
              "mesh 'probe': triangle 1 has vertex index 4 (corner 2), outside [0, 4)");
    EXPECT_EQ(errorOf(square(), {{-1, 1, 2}}),
              "mesh 'probe': triangle 0 has vertex index -1 (corner 0), outside [0, 4)");
}

TEST(MeshModel, RejectsIndexArraysThatAreNotTriangles) {
    const double xyz[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    const std::int32_t indices[] = {0, 1, 2, 0};
    try {
        TriangleMesh::fromArrays("flat", xyz, 3, indices, 4);
        FAIL() << "4 indices accepted";
    } catch (const MeshError& e) {
        EXPECT_STREQ(e.what(),
                     "mesh 'flat': 4 indices is not a whole number of triangles (3 per triangle)");
    }
    const float xyzf[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    const TriangleMesh ok = TriangleMesh::fromArrays("flat", xyzf, 3, indices, 3);
    EXPECT_EQ(ok.triangleCount(), 1u);
}

TEST(MeshModel, AcceptsZeroAreaTrianglesAndDuplicateVertices) {
    std::vector<Vec3> v = square();
    v.push_back(v[0]);           // duplicate vertex
    v.push_back(Vec3(2, 0, 0));  // collinear with 0 and 1
    const std::vector<Index3> t = {{0, 1, 2}, {0, 2, 3}, {0, 0, 1},
                                   {0, 1, 5}, {4, 4, 4}, {0, 1, 2}};
    ASSERT_EQ(errorOf(v, t), "");
    const auto mesh = std::make_shared<const TriangleMesh>("degenerate", v, t);
    EXPECT_EQ(mesh->zeroAreaTriangles(), 3u);
    for (TreeKind kind : {TreeKind::kSphere, TreeKind::kAabb, TreeKind::kObb, TreeKind::kKdop6,
                          TreeKind::kKdop14, TreeKind::kKdop18, TreeKind::kKdop26}) {
        for (int leaf = 1; leaf <= 8; ++leaf) {
            const MeshModel model(mesh, {kind, leaf});
            EXPECT_EQ(model.validate(), "") << treeKindName(kind) << " leaf " << leaf;
        }
    }
}

TEST(MeshModel, RejectsBadTreeSettings) {
    const auto mesh =
        std::make_shared<const TriangleMesh>("tri", square(), std::vector<Index3>{{0, 1, 2}});
    for (int leaf : {0, 9, -3}) {
        try {
            MeshModel model(mesh, {TreeKind::kObb, leaf});
            FAIL() << "leaf size " << leaf << " accepted";
        } catch (const std::invalid_argument& e) {
            EXPECT_EQ(std::string(e.what()),
                      "mesh 'tri': leaf size " + std::to_string(leaf) + " is outside 1..8");
        }
    }
    EXPECT_THROW(MeshModel(nullptr), std::invalid_argument);
}

TEST(MeshModel, ObbNodesAreOneCacheLine) {
    EXPECT_EQ(sizeof(ObbNode), 64u);
    const auto mesh = std::make_shared<const TriangleMesh>(
        "tri", square(), std::vector<Index3>{{0, 1, 2}, {0, 2, 3}});
    EXPECT_EQ(MeshModel(mesh).bytesPerNode(), 64u);
}

// A cube's principal axes are arbitrary (equal spread every way) and a square slab's are in
// its plane: the root OBB stood askew and up to 1.7 times too wide (the wall scene's ground
// was 1.2 m thick for a 1 m slab). The fit keeps the model's axes where they are tighter.
TEST(MeshModel, RootObbOfABoxMeshIsTheBoxItself) {
    for (const Vec3& h : {Vec3(0.5, 0.5, 0.5), Vec3(100, 0.5, 100), Vec3(0.01, 20, 64)}) {
        for (int leaf : {1, 4}) {
            TreeSettings settings;
            settings.leaf_size = leaf;
            const MeshModel model(std::make_shared<const TriangleMesh>(kolize::testing::boxMesh(h)),
                                  settings);
            EXPECT_EQ(model.validate(), "");
            const Obb& root = model.tree<ObbNode>().nodes()[0].volume;
            // The box's half extents along its axes, whatever their order and sign.
            Vec3 along;
            const Vec3 axes[3] = {root.axis0.cast<double>(), root.axis1.cast<double>(),
                                  root.axis2().cast<double>()};
            for (int k = 0; k < 3; ++k) {
                along[k] = axes[0].cwiseAbs()[k] * root.half.x() +
                           axes[1].cwiseAbs()[k] * root.half.y() +
                           axes[2].cwiseAbs()[k] * root.half.z();
            }
            for (int k = 0; k < 3; ++k) {
                EXPECT_NEAR(along[k], h[k], 1e-5 * h.maxCoeff())
                    << "box " << h.transpose() << ", leaf size " << leaf << ", axis " << k;
            }
        }
    }
}

}  // namespace
