// separationDepth (contact_audit.h), the audit's measure of how deep two meshes interpenetrate,
// checked against an independent reference: for two boxes (convex), the penetration depth is
// the least overlap over the separating-axis candidates (the 6 face normals and the 9 edge
// cross products), computed here plainly in double. separationDepth searches 27 directions,
// so it must lie between that depth and the depth over the cosine of the directions' covering
// angle (27.6 degrees), plus the bisection's resolution; a box inside the other included.

#include "box_mesh.h"

#include <kolize/engine/contact_audit.h>
#include <kolize/narrowphase/mesh_model.h>
#include <kolize/narrowphase/triangle_mesh.h>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <random>

namespace {

using kolize::separationDepth;
using kolize::narrowphase::MeshModel;
using kolize::narrowphase::Pose;
using kolize::narrowphase::TriangleMesh;
using kolize::narrowphase::Vec3;

std::shared_ptr<const MeshModel> boxModel(const Vec3& h) {
    return std::make_shared<const MeshModel>(
        std::make_shared<const TriangleMesh>(kolize::testing::boxMesh(h)));
}

/// The penetration depth of two oriented boxes by the separating-axis theorem: the least
/// overlap of their projections over the face normals and edge cross products (0 if one
/// separates them).
double satDepth(const Vec3& ha, const Pose& a, const Vec3& hb, const Pose& b) {
    std::vector<Vec3> axes;
    for (int i = 0; i < 3; ++i) {
        axes.push_back(a.rotation.col(i));
        axes.push_back(b.rotation.col(i));
        for (int j = 0; j < 3; ++j) {
            const Vec3 cross = a.rotation.col(i).cross(b.rotation.col(j));
            if (cross.norm() > 1e-9) {
                axes.push_back(cross.normalized());
            }
        }
    }
    auto radius = [](const Vec3& h, const Pose& pose, const Vec3& axis) {
        double r = 0;
        for (int i = 0; i < 3; ++i) {
            r += h[i] * std::abs(pose.rotation.col(i).dot(axis));
        }
        return r;
    };
    double best = std::numeric_limits<double>::infinity();
    for (const Vec3& axis : axes) {
        const double distance = std::abs((b.translation - a.translation).dot(axis));
        best = std::min(best, radius(ha, a, axis) + radius(hb, b, axis) - distance);
    }
    return std::max(best, 0.0);
}

Pose randomPose(std::mt19937& rng, double spread) {
    std::normal_distribution<double> normal(0, 1);
    Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
    Pose pose;
    pose.rotation = q.normalized().toRotationMatrix();
    pose.translation = spread * Vec3(normal(rng), normal(rng), normal(rng));
    return pose;
}

TEST(SeparationDepth, AxisAlignedBoxesOverlappingByAKnownDepth) {
    const auto unit = boxModel(Vec3(0.5, 0.5, 0.5));
    for (double depth : {0.001, 0.01, 0.1, 0.3}) {
        Pose a, b;
        b.translation = Vec3(1 - depth, 0.2, -0.1);
        const double measured = separationDepth(*unit, a, *unit, b);
        // Bisection to 2^-14 of 1.01 x the reach (0.87 + 0.87 + 1.03 m): 1.7e-4 m.
        EXPECT_GE(measured, depth) << "overlap " << depth;
        EXPECT_LE(measured, depth + 2e-4) << "overlap " << depth;
    }
}

TEST(SeparationDepth, ApartAndTouchingBoxes) {
    const auto unit = boxModel(Vec3(0.5, 0.5, 0.5));
    Pose a, b;
    b.translation = Vec3(1.01, 0, 0);
    EXPECT_EQ(separationDepth(*unit, a, *unit, b), 0);
    // Touching faces share points: intersecting, with a depth within the resolution.
    b.translation = Vec3(1, 0, 0);
    const double touching = separationDepth(*unit, a, *unit, b);
    EXPECT_GT(touching, 0);
    EXPECT_LE(touching, 2e-4);
}

// A box wholly inside another penetrates it although no triangles meet: the winding number
// finds it (its SAT depth is the distance to push it out).
TEST(SeparationDepth, ABoxWhollyInsideAnotherPenetratesIt) {
    const auto big = boxModel(Vec3(2, 2, 2)), small = boxModel(Vec3(0.5, 0.5, 0.5));
    Pose a, b;
    b.translation = Vec3(0.3, -0.2, 0.1);
    // Out along +x: 2 - 0.3 + 0.5 = 2.2 m.
    const double measured = separationDepth(*big, a, *small, b);
    EXPECT_GE(measured, 2.2);
    EXPECT_LE(measured, 2.2 + 1e-3);
    EXPECT_GE(separationDepth(*small, b, *big, a), 2.2);
}

TEST(SeparationDepth, RandomBoxesLieBetweenTheirDepthAndItsCoveringBound) {
    const std::uint32_t seed = 20261204;
    std::printf("separation depth of random boxes, seed %u\n", seed);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> size(0.1, 1.0);
    const double coveringCosine = std::cos(27.6 * M_PI / 180);
    int measured = 0, deep = 0;
    for (int trial = 0; trial < 300; ++trial) {
        const Vec3 ha(size(rng), size(rng), size(rng)), hb(size(rng), size(rng), size(rng));
        const Pose a = randomPose(rng, 0.3), b = randomPose(rng, 0.6);
        const double expected = satDepth(ha, a, hb, b);
        const double got = separationDepth(*boxModel(ha), a, *boxModel(hb), b);
        const double resolution =
            1.01 * (ha.norm() + hb.norm() + (b.translation - a.translation).norm()) / 16384;
        if (expected == 0) {
            EXPECT_EQ(got, 0) << "trial " << trial;
            continue;
        }
        ++measured;
        deep += expected > 0.1 ? 1 : 0;
        EXPECT_GE(got, expected - 1e-9) << "trial " << trial;
        EXPECT_LE(got, expected / coveringCosine + resolution + 1e-9) << "trial " << trial;
    }
    // The sample means something: most trials overlap, many deeply.
    EXPECT_GT(measured, 150);
    EXPECT_GT(deep, 50);
}

}  // namespace
