// orient2d / orient3d against rational determinants, per stage and through the filter.
#include "rational.h"
#include "test_scale.h"

#include <kolize/narrowphase/predicates.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

namespace {

using namespace kolize::narrowphase;
using kolize::narrowphase::testing::rationalOrient2d;
using kolize::narrowphase::testing::rationalOrient3d;
using kolize::narrowphase::testing::scaled;

/// Point families that make orient3d exactly zero or nearly so at various scales.
class PointSource {
  public:
    explicit PointSource(unsigned seed) : rng_(seed) {}

    /// Four points: family picks coplanar, collinear, coincident, grid-snapped, or random
    /// near-coplanar; `scale` multiplies everything (powers of two keep exact zeros).
    std::array<Vec3, 4> next(int family, double scale) {
        std::array<Vec3, 4> p;
        for (Vec3& x : p) {
            x = Vec3(grid(), grid(), grid());
        }
        switch (family) {
            case 0:  // d an exact affine combination of a, b, c with dyadic weights
                p[3] = p[0] + 0.5 * (p[1] - p[0]) + 0.25 * (p[2] - p[0]);
                break;
            case 1:  // a, b, c collinear
                p[2] = p[0] + 2.0 * (p[1] - p[0]);
                break;
            case 2:  // coincident points
                p[3] = p[int(rng_() % 3)];
                break;
            case 3:  // continuous, near-coplanar: d on the plane then nudged by one ulp
                p[3] = p[0] + 0.3 * (p[1] - p[0]) + 0.6 * (p[2] - p[0]);
                p[3].x() = std::nextafter(p[3].x(), rng_() % 2 ? 1e300 : -1e300);
                break;
            default:  // plain grid points
                break;
        }
        for (Vec3& x : p) {
            x *= scale;
        }
        return p;
    }

  private:
    double grid() { return double(int(rng_() % 9) - 4) + (rng_() % 4) * 0.125; }
    std::mt19937 rng_;
};

TEST(Predicates, Orient3dSignConvention) {
    const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
    EXPECT_EQ(orient3d(a, b, c, Vec3(0, 0, 1)), 1);
    EXPECT_EQ(orient3d(a, b, c, Vec3(0, 0, -1)), -1);
    EXPECT_EQ(orient3d(a, b, c, Vec3(5, 7, 0)), 0);
    EXPECT_EQ(orient2d(0, 0, 1, 0, 0, 1), 1);
    EXPECT_EQ(orient2d(0, 0, 0, 1, 1, 0), -1);
    EXPECT_EQ(orient2d(0, 0, 1, 1, 3, 3), 0);
}

TEST(Predicates, Orient3dMatchesRationalsOnDegenerateFamilies) {
    const unsigned seed = 1301;
    PointSource source(seed);
    const double scales[] = {1.0, 0x1p-20, 1e6, 1e-6, 0x1p40, 1e-300, 1e200};
    PredicateStats stats;
    int disagreements = 0, zeros = 0, cases = 0;
    for (double scale : scales) {
        for (int family = 0; family < 5; ++family) {
            for (int i = 0; i < scaled(400); ++i) {
                const std::array<Vec3, 4> p = source.next(family, scale);
                const int expected = rationalOrient3d(p[0], p[1], p[2], p[3]);
                const int got = orient3d(p[0], p[1], p[2], p[3], &stats);
                ++cases;
                zeros += expected == 0;
                if (got != expected) {
                    ++disagreements;
                    if (disagreements <= 5) {
                        ADD_FAILURE()
                            << "seed " << seed << " scale " << scale << " family " << family
                            << ": orient3d " << got << ", rational " << expected;
                    }
                }
                // Every stage that answers agrees with the rationals.
                for (PredicateStage stage :
                     {PredicateStage::kFilter, PredicateStage::kExpansion, PredicateStage::kGmp}) {
                    const std::optional<int> s = orient3dAt(stage, p[0], p[1], p[2], p[3]);
                    if (s) {
                        EXPECT_EQ(*s, expected) << "stage " << int(stage) << " scale " << scale;
                    }
                }
                ASSERT_TRUE(orient3dAt(PredicateStage::kGmp, p[0], p[1], p[2], p[3]).has_value());
            }
        }
    }
    EXPECT_EQ(disagreements, 0);
    // The sample means something: many exact zeros, and every stage decided some calls.
    EXPECT_GT(zeros, cases / 5);
    EXPECT_LT(zeros, cases * 4 / 5);
    EXPECT_GT(stats.orient3d[0], 0u);
    EXPECT_GT(stats.orient3d[1], 0u);
    EXPECT_GT(stats.orient3d[2], 0u);
    EXPECT_EQ(stats.orient3d[0] + stats.orient3d[1] + stats.orient3d[2], std::uint64_t(cases));
}

TEST(Predicates, PointsSharingACoordinateAreDecidedWithoutExactArithmetic) {
    // The faces of axis-aligned boxes, a mesh turned about one of its axes: four points with
    // one coordinate equal are coplanar whatever the others (here random doubles, whose
    // differences are not exact). One ulp off that plane, the sign must still be exact.
    const unsigned seed = 1305;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-3, 3);
    int nonzero = 0;
    for (int i = 0; i < scaled(2000); ++i) {
        const int axis = int(rng() % 3);
        const double level = u(rng);
        std::array<Vec3, 4> p;
        for (Vec3& x : p) {
            x = Vec3(u(rng), u(rng), u(rng));
            x[axis] = level;
        }
        PredicateStats one;
        EXPECT_EQ(orient3d(p[0], p[1], p[2], p[3], &one), 0) << "seed " << seed << " case " << i;
        EXPECT_EQ(one.fallbacks(), 0u) << "seed " << seed << " case " << i;
        p[i % 4][axis] = std::nextafter(level, i % 2 ? 1e300 : -1e300);
        const int expected = rationalOrient3d(p[0], p[1], p[2], p[3]);
        EXPECT_EQ(orient3d(p[0], p[1], p[2], p[3]), expected)
            << "seed " << seed << " case " << i << " nudged";
        nonzero += expected != 0;
    }
    EXPECT_GT(nonzero, scaled(2000) * 9 / 10);  // the nudged points are off the plane
}

TEST(Predicates, Orient2dMatchesRationalsOnDegenerateFamilies) {
    const unsigned seed = 1302;
    PointSource source(seed);
    PredicateStats stats;
    int disagreements = 0, zeros = 0, cases = 0;
    for (double scale : {1.0, 0x1p-30, 1e6, 1e-6, 1e-290, 1e250}) {
        for (int family = 0; family < 5; ++family) {
            for (int i = 0; i < scaled(400); ++i) {
                const std::array<Vec3, 4> p = source.next(family, scale);
                // Project onto xy; family 1 makes (a, b, c) collinear in every projection.
                const int expected =
                    rationalOrient2d(p[0].x(), p[0].y(), p[1].x(), p[1].y(), p[2].x(), p[2].y());
                const int got =
                    orient2d(p[0].x(), p[0].y(), p[1].x(), p[1].y(), p[2].x(), p[2].y(), &stats);
                ++cases;
                zeros += expected == 0;
                disagreements += got != expected;
                for (PredicateStage stage :
                     {PredicateStage::kFilter, PredicateStage::kExpansion, PredicateStage::kGmp}) {
                    const std::optional<int> s = orient2dAt(stage, p[0].x(), p[0].y(), p[1].x(),
                                                            p[1].y(), p[2].x(), p[2].y());
                    if (s) {
                        EXPECT_EQ(*s, expected) << "stage " << int(stage) << " scale " << scale;
                    }
                }
            }
        }
    }
    EXPECT_EQ(disagreements, 0) << "seed " << seed;
    EXPECT_GT(zeros, cases / 10);
    EXPECT_GT(stats.orient2d[0], 0u);
    EXPECT_GT(stats.orient2d[1], 0u);
    EXPECT_GT(stats.orient2d[2], 0u);
}

TEST(Predicates, FilterDecidesRandomInput) {
    // Random points in general position: the filter alone decides (fallback rate ~0).
    std::mt19937 rng(1303);
    std::uniform_real_distribution<double> u(-1, 1);
    PredicateStats stats;
    for (int i = 0; i < 20000; ++i) {
        const Vec3 a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng)), c(u(rng), u(rng), u(rng)),
            d(u(rng), u(rng), u(rng));
        orient3d(a, b, c, d, &stats);
    }
    EXPECT_LT(stats.fallbacks(), 5u);
}

TEST(Predicates, UnderflowingProductsAreNotTrustedToTheFilter) {
    // Regression guard for the filter's absolute term: 2x2 minors around 1e-170^2 underflow
    // to zero in double, which a relative bound alone would take as an exact zero times a
    // huge factor; the answer must still be the exact one.
    const double t = 1e-170;
    const Vec3 a(0, 0, 0), b(t, 0, 0), c(0, t, 0), d(1e150, 1e150, 3 * t);
    EXPECT_EQ(orient3d(a, b, c, d), rationalOrient3d(a, b, c, d));
    EXPECT_EQ(orient3d(a, b, c, d), 1);
}

}  // namespace
