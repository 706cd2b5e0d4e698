// Bounding volumes: fitted float volumes contain their points exactly, and overlap tests
// never reject volumes that share a point -- tested where it is hardest, at touching.
#include "test_scale.h"

#include <kolize/narrowphase/bounding_volume.h>

#include "bv_internal.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <random>

namespace {

using namespace kolize::narrowphase;
using kolize::narrowphase::testing::scaled;

struct Cloud {
    std::vector<Vec3> vertices;
    std::vector<Index3> triangles;
    TriangleSpan span() const {
        return {vertices.data(), triangles.data(), nullptr, triangles.size()};
    }
};

/// A random triangle soup: an elongated, rotated, offset blob; sometimes flat or with
/// zero-area triangles.
Cloud randomCloud(std::mt19937& rng, double offset) {
    std::normal_distribution<double> n(0, 1);
    const Vec3 scale(std::exp(n(rng)), std::exp(n(rng)), rng() % 4 == 0 ? 0.0 : std::exp(n(rng)));
    const Eigen::Matrix3d r =
        Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized().toRotationMatrix();
    const Vec3 center = offset * Vec3(n(rng), n(rng), n(rng));
    Cloud c;
    const int count = 3 + int(rng() % 30);
    for (int i = 0; i < count; ++i) {
        c.vertices.push_back(center + r * Vec3(n(rng), n(rng), n(rng)).cwiseProduct(scale));
    }
    for (int i = 0; i + 2 < count; ++i) {
        c.triangles.push_back({i, i + 1, rng() % 5 == 0 ? i + 1 : i + 2});
    }
    return c;
}

Pose randomPose(std::mt19937& rng, double spread) {
    std::normal_distribution<double> n(0, 1);
    Pose p;
    p.rotation = Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized().toRotationMatrix();
    p.translation = spread * Vec3(n(rng), n(rng), n(rng));
    return p;
}

TEST(BoundingVolumes, FittedVolumesContainEveryCornerExactly) {
    std::mt19937 rng(1501);
    for (int i = 0; i < scaled(400); ++i) {
        const Cloud c = randomCloud(rng, i % 3 == 0 ? 1e3 : 1.0);
        const Sphere s = fitSphere(c.span());
        const Aabb box = fitAabb(c.span());
        const Obb obb = fitObb(c.span());
        const Kdop<14> k14 = fitKdop<14>(c.span());
        const Kdop<26> k26 = fitKdop<26>(c.span());
        for (const Index3& t : c.triangles) {
            for (int k = 0; k < 3; ++k) {
                const Vec3& x = c.vertices[t[k]];
                ASSERT_TRUE(contains(s, x)) << "case " << i;
                ASSERT_TRUE(contains(box, x)) << "case " << i;
                ASSERT_TRUE(contains(obb, x)) << "case " << i;
                ASSERT_TRUE(contains(Sphere{obb.center, obb.radius}, x)) << "case " << i;
                ASSERT_TRUE(contains(k14, x)) << "case " << i;
                ASSERT_TRUE(contains(k26, x)) << "case " << i;
            }
        }
        // The OBB's axes are orthonormal to float precision and ordered by spread.
        EXPECT_NEAR(obb.axis0.norm(), 1.0f, 1e-6f);
        EXPECT_NEAR(obb.axis0.dot(obb.axis1), 0.0f, 1e-6f);
    }
}

TEST(BoundingVolumes, FloatRoundTripsSurvive) {
    // Regression: built by GCC 12.2 at -O2/-O3 with its SLP vectorizer, fitObb stored two
    // axis components as unrounded doubles in its double copy of the float axes, so the
    // extents were measured in a frame slightly different from the box's: vertex 3 lay
    // 1.6e-9 outside. The library is now built with -fno-tree-slp-vectorize.
    const std::vector<Vec3> v = {Vec3(0, 0, 0), Vec3(1, 0.1, 0), Vec3(0.3, 2, 0.5),
                                 Vec3(-1, 0.5, 0.2)};
    const std::vector<Index3> t = {{0, 1, 2}, {1, 2, 3}};
    const Obb box = fitObb({v.data(), t.data(), nullptr, t.size()});
    for (const Vec3& x : v) {
        EXPECT_TRUE(contains(box, x)) << x.transpose();
    }
}

TEST(BoundingVolumes, PrincipalAxesSurviveDegenerateCovariances) {
    for (const Eigen::Matrix3d& c :
         {Eigen::Matrix3d(Eigen::Matrix3d::Zero()), Eigen::Matrix3d(Eigen::Matrix3d::Identity()),
          Eigen::Matrix3d(Vec3(1, 0, 0).asDiagonal()),
          Eigen::Matrix3d(Eigen::Matrix3d::Constant(std::nan("")))}) {
        const Eigen::Matrix3d axes = principalAxes(c);
        EXPECT_TRUE(axes.allFinite());
        EXPECT_LT((axes.transpose() * axes - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(),
                  1e-12);
        EXPECT_NEAR(axes.determinant(), 1.0, 1e-12);
    }
}

/// A point of the OBB's boundary: a corner, an edge point or a face point, chosen at random.
Vec3 boundaryPoint(const Obb& b, std::mt19937& rng) {
    std::uniform_real_distribution<double> u(-1, 1);
    const Vec3f axes[3] = {b.axis0, b.axis1, b.axis2()};
    Vec3 x = b.center.cast<double>();
    const int free = int(rng() % 3);  // coordinates left inside: 0 corner, 1 edge, 2 face
    for (int i = 0; i < 3; ++i) {
        const double s = i < free ? u(rng) : (rng() % 2 ? 1.0 : -1.0);
        x += s * double(b.half[i]) * axes[i].cast<double>();
    }
    return x;
}

TEST(BoundingVolumes, OverlapTestsNeverRejectTouchingVolumes) {
    // b's boundary point y is moved exactly onto a's boundary point x (t = x - R y): the
    // volumes touch there (up to one rounding of the pose), so every test must say overlap.
    std::mt19937 rng(1502);
    int obbAccepted = 0, sphereAccepted = 0, aabbAccepted = 0, cases = 0;
    for (int i = 0; i < scaled(3000); ++i) {
        const Cloud ca = randomCloud(rng, 1.0), cb = randomCloud(rng, 1.0);
        const Obb a = fitObb(ca.span()), b = fitObb(cb.span());
        Pose pa = randomPose(rng, 3.0), pb = randomPose(rng, 0.0);
        const Vec3 x = pa.rotation * boundaryPoint(a, rng) + pa.translation;
        const Vec3 y = boundaryPoint(b, rng);
        pb.translation = x - pb.rotation * y;
        const RelativePose bInA(pa, pb);
        ++cases;
        obbAccepted += overlap(a, b, bInA);
        // Spheres and AABBs around the same clouds contain the boxes' corners' clouds only
        // approximately, so test them at their own boundary points instead.
        const Sphere sa = fitSphere(ca.span()), sb = fitSphere(cb.span());
        Vec3 dir = Vec3::Random().normalized();
        const Vec3 xs =
            pa.rotation * (sa.center.cast<double>() + double(sa.radius) * dir) + pa.translation;
        dir = Vec3::Random().normalized();
        pb.translation = xs - pb.rotation * (sb.center.cast<double>() + double(sb.radius) * dir);
        sphereAccepted += overlap(sa, sb, RelativePose(pa, pb));
        const Aabb ba = fitAabb(ca.span()), bb = fitAabb(cb.span());
        auto corner = [&](const Aabb& box) {
            Vec3 c;
            for (int k = 0; k < 3; ++k) {
                c[k] = rng() % 2 ? box.lo[k] : box.hi[k];
            }
            return c;
        };
        const Vec3 xa = pa.rotation * corner(ba) + pa.translation;
        pb.translation = xa - pb.rotation * corner(bb);
        aabbAccepted += overlap(ba, bb, RelativePose(pa, pb));
    }
    EXPECT_EQ(obbAccepted, cases);
    EXPECT_EQ(sphereAccepted, cases);
    EXPECT_EQ(aabbAccepted, cases);
}

TEST(BoundingVolumes, OverlapTestsRejectSeparatedVolumes) {
    // The sample means something: moved apart along the line of centres by a few sizes,
    // the test rejects.
    std::mt19937 rng(1503);
    int rejected = 0, cases = 0;
    for (int i = 0; i < scaled(1000); ++i) {
        const Cloud ca = randomCloud(rng, 1.0), cb = randomCloud(rng, 1.0);
        const Obb a = fitObb(ca.span()), b = fitObb(cb.span());
        Pose pb = randomPose(rng, 0.0);
        // The boxes' circumscribed spheres (the fitted radius bounds the points, not the
        // corners).
        const double reach = double(a.half.norm() + b.half.norm());
        pb.translation = a.center.cast<double>() - pb.rotation * b.center.cast<double>() +
                         1.01 * reach * Vec3::Random().normalized();
        ++cases;
        rejected += !overlap(a, b, RelativePose(Pose{}, pb));
    }
    EXPECT_EQ(rejected, cases);  // beyond the bounding spheres, the SAT always separates
}

TEST(BoundingVolumes, TransformedVolumesContainTheMovedPoints) {
    std::mt19937 rng(1504);
    for (int i = 0; i < scaled(300); ++i) {
        const Cloud c = randomCloud(rng, i % 2 ? 100.0 : 1.0);
        const RelativePose pose(randomPose(rng, 5.0), randomPose(rng, 5.0));
        const Sphere s = transformed(fitSphere(c.span()), pose);
        const Aabb box = transformed(fitAabb(c.span()), pose);
        const Obb obb = transformed(fitObb(c.span()), pose);
        for (const Index3& t : c.triangles) {
            for (int k = 0; k < 3; ++k) {
                const Vec3 x = pose.apply(c.vertices[t[k]]);
                ASSERT_TRUE(contains(s, x)) << "case " << i;
                ASSERT_TRUE(contains(box, x)) << "case " << i;
                ASSERT_TRUE(contains(obb, x)) << "case " << i;
            }
        }
    }
}

TEST(BoundingVolumes, KdopsOfTouchingPointSetsOverlap) {
    // Two clouds sharing one exact point: their k-DOPs (same frame) must overlap.
    std::mt19937 rng(1505);
    for (int i = 0; i < scaled(500); ++i) {
        Cloud a = randomCloud(rng, 1.0), b = randomCloud(rng, 1.0);
        b.vertices[b.triangles[0][0]] = a.vertices[a.triangles[0][1]];
        EXPECT_TRUE(overlap(fitKdop<6>(a.span()), fitKdop<6>(b.span())));
        EXPECT_TRUE(overlap(fitKdop<18>(a.span()), fitKdop<18>(b.span())));
        EXPECT_TRUE(overlap(fitKdop<26>(a.span()), fitKdop<26>(b.span())));
    }
}

}  // namespace

namespace {

TEST(BoundingVolumes, VectorAndScalarSeparatingAxisTestsAgree) {
    // The query uses the SSE2 test on x86-64 and the scalar one elsewhere: on random box
    // pairs (none within float error of touching) both give the same verdict, and the
    // SSE axis really separates by the scalar arithmetic too.
#if defined(__SSE2__)
    std::mt19937 rng(1506);
    int separated = 0, cases = 0;
    for (int i = 0; i < kolize::narrowphase::testing::scaled(20000); ++i) {
        const Cloud ca = randomCloud(rng, 1.0), cb = randomCloud(rng, 1.0);
        const Obb a = fitObb(ca.span()), b = fitObb(cb.span());
        const RelativePose pose(Pose{}, randomPose(rng, 2.0));
        const detail::ObbInFrame moved = detail::moveObb(b, pose.rotation(), pose.translation());
        const Vec3 d = moved.center - a.center.cast<double>();
        const int scalar = detail::obbSeparatingAxisScalar(a, a.axis2(), moved, d.x(), d.y(), d.z(),
                                                           0.0f, detail::kNoAxis);
        const int vector =
            detail::obbSeparatingAxisSse(a, moved, d.x(), d.y(), d.z(), 0.0f, detail::kNoAxis);
        ++cases;
        separated += scalar != detail::kNoAxis;
        EXPECT_EQ(scalar == detail::kNoAxis, vector == detail::kNoAxis) << "case " << i;
        EXPECT_EQ(scalar, vector) << "case " << i;  // the same first axis, in the same order
    }
    EXPECT_GT(separated, cases / 10);
    EXPECT_LT(separated, cases * 9 / 10);
#else
    GTEST_SKIP() << "no SSE2 on this target";
#endif
}

}  // namespace
