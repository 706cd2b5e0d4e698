// Mesh against mesh over a step: earliest time of impact and the features involved.
#include "kolize/narrowphase/mesh_ccd.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <random>
#include <stdexcept>

namespace {

using namespace kolize::ccd;

/// Box [0, size] + origin (8 vertices, 12 outward-wound triangles), moved by `motion`.
MovingMesh box(const Vec3& origin, const Vec3& size, const Vec3& motion) {
    MovingMesh m;
    for (int i = 0; i < 8; ++i) {
        const Vec3 p = origin + Vec3(i & 1, (i >> 1) & 1, (i >> 2) & 1).cwiseProduct(size);
        m.start.push_back(p);
        m.end.push_back(p + motion);
    }
    m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                   {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    return m;
}

/// Unit cube [0,1]^3 + origin, moved by `motion` over the step.
MovingMesh cube(const Vec3& origin, const Vec3& motion) {
    return box(origin, Vec3::Ones(), motion);
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
    // A slides along y next to B with a gap of 0.25 in x: slice boxes overlap in y and z
    // only, so no candidate pair survives and no contact is reported.
    const MovingMesh a = cube({0, -2, 0}, {0, 4, 0});
    const MovingMesh b = cube({1.25, 0, 0}, {0, 0, 0});
    const MeshContact c = meshCcd(a, b);
    EXPECT_FALSE(c.hit);
    EXPECT_EQ(c.candidate_pairs, 0u);
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
    // A moves +0.6 in x onto a plate 0.05 thick at x = 1.5 (contact at t = 5/6). In the one
    // time slice, A's leading vertices also reach the plate's far face, whose normal points
    // along their motion: those tests are the ones culled.
    const MovingMesh a = cube({0, 0, 0}, {0.6, 0, 0});
    const MovingMesh b = box({1.5, 0.25, 0.25}, {0.05, 1, 1}, {0, 0, 0});
    MeshCcdSettings cull;
    cull.cull_back_facing = true;
    const MeshContact full = meshCcd(a, b);
    const MeshContact culled = meshCcd(a, b, cull);
    EXPECT_GT(culled.culled, 0u);
    EXPECT_LT(culled.primitive_queries, full.primitive_queries);
    ASSERT_TRUE(full.hit);
    ASSERT_TRUE(culled.hit);  // pure translation of convex shapes: culling is safe here
    EXPECT_LE(culled.toi, 5.0 / 6.0);
    EXPECT_GE(culled.toi, 5.0 / 6.0 - 1e-4);
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

namespace {

/// Octahedron of radius r around `center`, outward winding (6 vertices, 8 triangles).
MovingMesh octahedron(const Vec3& center, double r, const Eigen::Matrix3d& rotation) {
    MovingMesh m;
    for (int axis = 0; axis < 3; ++axis) {
        for (double sign : {1.0, -1.0}) {
            Vec3 p = Vec3::Zero();
            p[axis] = sign * r;
            m.start.push_back(center + rotation * p);
        }
    }
    // Vertices: 0 +x, 1 -x, 2 +y, 3 -y, 4 +z, 5 -z.
    m.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                   {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
    m.end = m.start;
    return m;
}

/// Earliest contact over every vertex-face and edge-edge pair of the two meshes, each
/// tested over the whole step: the reference the culling must agree with.
MeshContact bruteForce(const MovingMesh& a, const MovingMesh& b) {
    MeshContact best;
    auto consider = [&](const CcdResult& r) {
        if (r.hit && (!best.hit || r.toi < best.toi)) {
            best.hit = true;
            best.toi = r.toi;
        }
    };
    for (int pass = 0; pass < 2; ++pass) {
        const MovingMesh& vm = pass ? b : a;
        const MovingMesh& fm = pass ? a : b;
        for (size_t v = 0; v < vm.start.size(); ++v) {
            for (const auto& f : fm.triangles) {
                consider(
                    vertexFaceRobust({{vm.start[v], fm.start[f[0]], fm.start[f[1]], fm.start[f[2]]},
                                      {vm.end[v], fm.end[f[0]], fm.end[f[1]], fm.end[f[2]]}}));
            }
        }
    }
    for (const auto& ta : a.triangles) {
        for (const auto& tb : b.triangles) {
            for (int i = 0; i < 3; ++i) {
                for (int j = 0; j < 3; ++j) {
                    const int a0 = ta[i], a1 = ta[(i + 1) % 3], b0 = tb[j], b1 = tb[(j + 1) % 3];
                    consider(edgeEdgeRobust({{a.start[a0], a.start[a1], b.start[b0], b.start[b1]},
                                             {a.end[a0], a.end[a1], b.end[b0], b.end[b1]}}));
                }
            }
        }
    }
    return best;
}

// Differential test of the time slicing and the feature hierarchies: on random moving and
// rotating octahedra, meshCcd finds the same earliest contact as testing every primitive
// pair over the whole step, with many slices and with one.
TEST(CcdMesh, SlicedHierarchiesAgreeWithEveryPairOnRandomMotions) {
    const unsigned seed = 20240611;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    auto randomVector = [&] { return Vec3(unit(rng), unit(rng), unit(rng)); };
    auto randomRotation = [&] {
        return Eigen::AngleAxisd(3.0 * unit(rng), randomVector().normalized()).toRotationMatrix();
    };
    const double slack = RobustSettings{}.toi_tolerance + 1e-15;
    MeshCcdSettings one_slice;
    one_slice.max_time_slices = 1;
    int hits = 0, sliced = 0;
    const int trials = 150;
    for (int trial = 0; trial < trials; ++trial) {
        SCOPED_TRACE("seed " + std::to_string(seed) + ", trial " + std::to_string(trial));
        // A small octahedron flies past or into a big one, turning; B moves a little.
        MovingMesh a = octahedron(Vec3::Zero(), 0.3, randomRotation());
        MovingMesh b = octahedron(Vec3::Zero(), 1.0, randomRotation());
        const Vec3 from = 3.0 * randomVector(), to = -from + 3.0 * randomVector();
        const Eigen::Matrix3d turn = randomRotation();
        for (size_t v = 0; v < a.start.size(); ++v) {
            a.end[v] = turn * a.start[v] + to;
            a.start[v] += from;
        }
        const Vec3 drift = 0.3 * randomVector();
        for (size_t v = 0; v < b.start.size(); ++v) {
            b.end[v] = b.start[v] + drift;
        }
        const MeshContact reference = bruteForce(a, b);
        const MeshContact many = meshCcd(a, b);
        const MeshContact one = meshCcd(a, b, one_slice);
        ASSERT_EQ(many.hit, reference.hit);
        ASSERT_EQ(one.hit, reference.hit);
        if (reference.hit) {
            EXPECT_NEAR(many.toi, reference.toi, slack);
            EXPECT_NEAR(one.toi, reference.toi, slack);
        }
        EXPECT_EQ(one.time_slices, 1u);
        hits += reference.hit;
        sliced += many.time_slices > 1;
    }
    // A meaningful sample: both outcomes common, and the slicing actually used.
    EXPECT_GT(hits, trials / 5) << "seed " << seed;
    EXPECT_LT(hits, trials * 4 / 5) << "seed " << seed;
    EXPECT_GT(sliced, trials / 2) << "seed " << seed;
}

// The reach filter: a small octahedron flying at, past or through a large tessellated sheet
// (200 triangles, bending a little over the step). Only the sheet's features near the
// octahedron's sweep take part, and the earliest contact is still every pair's.
TEST(CcdMesh, ReachFilterAgreesWithEveryPairAgainstALargeSheet) {
    const unsigned seed = 20261203;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    auto randomVector = [&] { return Vec3(unit(rng), unit(rng), unit(rng)); };
    const double slack = RobustSettings{}.toi_tolerance + 1e-15;
    constexpr int kQuads = 10;
    int hits = 0, filtered = 0;
    const int trials = 60;
    for (int trial = 0; trial < trials; ++trial) {
        SCOPED_TRACE("seed " + std::to_string(seed) + ", trial " + std::to_string(trial));
        MovingMesh sheet;
        for (int j = 0; j <= kQuads; ++j) {
            for (int i = 0; i <= kQuads; ++i) {
                const Vec3 p(-4.0 + 8.0 * i / kQuads, -4.0 + 8.0 * j / kQuads, 0.0);
                sheet.start.push_back(p);
                sheet.end.push_back(p + Vec3(0, 0, 0.05 * unit(rng)));
            }
        }
        for (int j = 0; j < kQuads; ++j) {
            for (int i = 0; i < kQuads; ++i) {
                const int v = j * (kQuads + 1) + i;
                sheet.triangles.push_back({v, v + 1, v + kQuads + 2});
                sheet.triangles.push_back({v, v + kQuads + 2, v + kQuads + 1});
            }
        }
        MovingMesh a = octahedron(
            Vec3::Zero(), 0.3,
            Eigen::AngleAxisd(3.0 * unit(rng), randomVector().normalized()).toRotationMatrix());
        const Vec3 from(3.0 * unit(rng), 3.0 * unit(rng), 0.2 + 1.5 * std::abs(unit(rng)));
        const Vec3 to = from + Vec3(unit(rng), unit(rng), -2.0 * std::abs(unit(rng)));
        for (size_t v = 0; v < a.start.size(); ++v) {
            a.end[v] = a.start[v] + to;
            a.start[v] += from;
        }
        const MeshContact reference = bruteForce(a, sheet);
        const MeshContact got = meshCcd(a, sheet);
        const MeshContact swapped = meshCcd(sheet, a);
        ASSERT_EQ(got.hit, reference.hit);
        ASSERT_EQ(swapped.hit, reference.hit);
        if (reference.hit) {
            EXPECT_NEAR(got.toi, reference.toi, slack);
            EXPECT_NEAR(swapped.toi, reference.toi, slack);
        }
        hits += reference.hit;
        filtered += got.out_of_reach > 0 ? 1 : 0;
    }
    // A meaningful sample: hits and misses, and the filter leaving features out.
    EXPECT_GT(hits, trials / 5) << "seed " << seed;
    EXPECT_LT(hits, trials * 4 / 5) << "seed " << seed;
    EXPECT_GT(filtered, trials * 9 / 10) << "seed " << seed;
}

}  // namespace
