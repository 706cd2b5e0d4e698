// Every tree kind and leaf size against the reference on generated meshes (a sphere, a
// torus, a box of coplanar faces, an open sheet with zero-area triangles) at seeded poses
// of every class.
#include "query_fixture.h"

#include "../box_mesh.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <random>
#include <string>
#include <vector>

namespace {

using namespace kolize::narrowphase;
using namespace kolize::narrowphase::testing;
namespace workload = kolize::workload;

struct Generated {
    workload::WorkloadMesh mesh;
    std::unique_ptr<ModelSet> models;
};

const std::vector<Generated>& generated() {
    static const std::vector<Generated> meshes = [] {
        std::vector<Generated> out;
        for (workload::WorkloadMesh m :
             {workload::uvSphere(16, 32), workload::torus(32, 16, 0.3), workload::subdividedBox(8),
              workload::sheetWithDegenerates(20)}) {
            auto models = std::make_unique<ModelSet>(m.mesh);
            out.push_back({std::move(m), std::move(models)});
        }
        return out;
    }();
    return meshes;
}

TEST(GeneratedMeshes, HaveTheDegeneraciesTheyClaim) {
    EXPECT_GT(generated()[3].mesh.mesh->zeroAreaTriangles(), 50u);
    for (const Generated& g : generated()) {
        EXPECT_GE(g.mesh.mesh->triangleCount(), 700u) << g.mesh.name;
        EXPECT_GT(g.mesh.radius, 0.5);
        EXPECT_LE(g.mesh.radius, 1.0);
    }
}

TEST(GeneratedMeshes, ReferenceAgreesWithAllPairs) {
    // The reference's sweep against all |a| x |b| pairs, on the smaller meshes.
    const Generated& sheet = generated()[3];
    const Generated& box = generated()[2];
    const std::vector<workload::WorkloadPose> poses = workload::makePoses(
        sheet.mesh, sheet.models->get(TreeKind::kObb, 4), box.mesh,
        box.models->get(TreeKind::kObb, 4), workload::PoseClass::kDeep, scaled(3), 1601);
    for (const workload::WorkloadPose& p : poses) {
        const auto swept = referencePairs(*sheet.mesh.mesh, p.a, *box.mesh.mesh, p.b);
        EXPECT_EQ(swept, allPairsReference(*sheet.mesh.mesh, p.a, *box.mesh.mesh, p.b));
        EXPECT_FALSE(swept.empty());
    }
}

class GeneratedPairs : public ::testing::TestWithParam<std::pair<int, int>> {};

TEST_P(GeneratedPairs, EveryTreeMatchesTheReference) {
    const auto [i, j] = GetParam();
    const Generated& a = generated()[i];
    const Generated& b = generated()[j];
    const std::uint32_t seed = 1700 + 10 * i + j;
    const auto tally = compareEverywhere(a.mesh, *a.models, b.mesh, *b.models, scaled(3), seed);
    expectMeaningfulClasses(tally, a.mesh.name + " x " + b.mesh.name);
}

INSTANTIATE_TEST_SUITE_P(Pairs, GeneratedPairs,
                         ::testing::Values(std::make_pair(0, 0), std::make_pair(1, 1),
                                           std::make_pair(2, 2), std::make_pair(3, 3),
                                           std::make_pair(0, 1), std::make_pair(2, 3)),
                         [](const ::testing::TestParamInfo<std::pair<int, int>>& info) {
                             return std::to_string(info.param.first) + "_" +
                                    std::to_string(info.param.second);
                         });

/// Regression: every leaf of a box mesh's tree has the whole box as its volume (however its
/// 12 triangles are split), so a fine mesh lying across the box's face was traversed once per
/// box leaf (4 times; mesh-wall's bodies resting on their box-mesh ground: 483 043 node tests
/// over 2 s at 1/240 s, now 178 587). A query's A of at most 16 triangles is one leaf: each
/// of B's leaves is visited at most once, and the pairs are still the reference's.
TEST(MeshQuery, ASmallMeshIsOneLeafForTheTraversal) {
    const auto box =
        std::make_shared<const TriangleMesh>(kolize::testing::boxMesh(Vec3(5, 5, 0.5)));
    const auto grid = std::make_shared<const TriangleMesh>(kolize::testing::gridMesh(20, 0.1));
    const MeshModel boxModel(box), gridModel(grid);
    std::size_t boxLeaves = 0, gridLeaves = 0;
    for (const ObbNode& node : boxModel.tree<ObbNode>().nodes()) {
        boxLeaves += node.link.isLeaf() ? 1 : 0;
    }
    for (const ObbNode& node : gridModel.tree<ObbNode>().nodes()) {
        gridLeaves += node.link.isLeaf() ? 1 : 0;
    }
    ASSERT_GT(boxLeaves, 1u);  // else there was nothing to traverse more than once
    const unsigned seed = 2026;
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(-1, 1);
    Pose boxPose;
    boxPose.translation = Vec3(0, 0, -0.5);  // its top face at z = 0
    MeshQuery query;
    std::size_t hits = 0;
    for (int k = 0; k < 20; ++k) {
        // The grid lying across the top face, a little turned and tilted.
        Pose gridPose;
        gridPose.rotation = (Eigen::AngleAxisd(0.05 * unit(rng), Vec3::UnitX()) *
                             Eigen::AngleAxisd(0.05 * unit(rng), Vec3::UnitY()) *
                             Eigen::AngleAxisd(3 * unit(rng), Vec3::UnitZ()))
                                .toRotationMatrix();
        gridPose.translation = Vec3(2 * unit(rng), 2 * unit(rng), 0.02 * unit(rng));
        std::vector<TrianglePair> got = query.run(boxModel, boxPose, gridModel, gridPose).pairs;
        std::sort(got.begin(), got.end());
        EXPECT_EQ(got, referencePairs(*box, boxPose, *grid, gridPose)) << "pose " << k;
        EXPECT_LE(query.result().counters.leaf_pairs, gridLeaves) << "pose " << k;
        hits += got.empty() ? 0 : 1;
    }
    EXPECT_GE(hits, 10u);  // the sample crosses the face
}

}  // namespace
