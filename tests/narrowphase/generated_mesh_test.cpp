// Every tree kind and leaf size against the reference on generated meshes (a sphere, a
// torus, a box of coplanar faces, an open sheet with zero-area triangles) at seeded poses
// of every class.
#include "query_fixture.h"

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

}  // namespace
