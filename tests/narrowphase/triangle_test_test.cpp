// The exact triangle test against the rational linear-program reference, on seeded
// degenerate families; the intersection geometry against distances to both triangles.
#include "rational.h"
#include "test_scale.h"

#include <kolize/narrowphase/triangle_test.h>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>

namespace {

using namespace kolize::narrowphase;
using kolize::narrowphase::testing::rationalTrianglesIntersect;
using kolize::narrowphase::testing::scaled;

std::string describe(const Triangle& t) {
    std::ostringstream out;
    out.precision(17);
    out << "{";
    for (const Vec3& x : t) {
        out << "(" << x.x() << ", " << x.y() << ", " << x.z() << ")";
    }
    out << "}";
    return out.str();
}

/// Distance from x to the closed triangle t (double; for checking constructed geometry).
double distanceToTriangle(const Vec3& x, const Triangle& t) {
    const Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]);
    double best = 1e300;
    auto segment = [&](const Vec3& a, const Vec3& b) {
        const Vec3 d = b - a;
        const double s =
            d.squaredNorm() > 0 ? std::clamp((x - a).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
        best = std::min(best, (a + s * d - x).norm());
    };
    for (int i = 0; i < 3; ++i) {
        segment(t[i], t[(i + 1) % 3]);
    }
    if (n.squaredNorm() > 0) {
        const Vec3 onPlane = x - n * (n.dot(x - t[0]) / n.squaredNorm());
        bool inside = true;
        for (int i = 0; i < 3; ++i) {
            inside = inside && n.dot((t[(i + 1) % 3] - t[i]).cross(onPlane - t[i])) >= 0;
        }
        if (inside) {
            best = std::min(best, (onPlane - x).norm());
        }
    }
    return best;
}

enum class Family {
    kGrid,          // small integer coordinates: touching, coplanar, collinear everywhere
    kSharedVertex,  // q reuses a vertex of p
    kSharedEdge,    // q reuses an edge of p
    kCoplanar,      // both in one grid plane (overlap, touching, one inside the other)
    kVertexOnEdge,  // a vertex of q at a dyadic point of an edge of p
    kZeroArea,      // q (and sometimes p) a segment or a point
    kSnapped,       // random doubles snapped to multiples of 1/8
    kContinuous,    // random doubles, general position
};

const char* name(Family f) {
    switch (f) {
        case Family::kGrid:
            return "grid";
        case Family::kSharedVertex:
            return "shared-vertex";
        case Family::kSharedEdge:
            return "shared-edge";
        case Family::kCoplanar:
            return "coplanar";
        case Family::kVertexOnEdge:
            return "vertex-on-edge";
        case Family::kZeroArea:
            return "zero-area";
        case Family::kSnapped:
            return "snapped";
        case Family::kContinuous:
            return "continuous";
    }
    return "?";
}

class TriangleSource {
  public:
    explicit TriangleSource(unsigned seed) : rng_(seed) {}

    std::pair<Triangle, Triangle> next(Family family) {
        Triangle p, q;
        for (int i = 0; i < 3; ++i) {
            p[i] = gridPoint(2);
            q[i] = gridPoint(2);
        }
        switch (family) {
            case Family::kGrid:
                break;
            case Family::kSharedVertex: {
                const int k = pick();
                q[k] = p[pick()];
                nudgeSometimes(q[k]);
                break;
            }
            case Family::kSharedEdge: {
                const int i = pick();
                q[0] = p[i];
                q[1] = p[(i + 1) % 3];
                if (rng_() % 2 == 0) {  // the whole edge moved off p by 2^-12
                    const Vec3 shift = Vec3::Unit(int(rng_() % 3)) * 0x1p-12;
                    q[0] += shift;
                    q[1] += shift;
                }
                break;
            }
            case Family::kCoplanar: {
                // A random grid plane through the origin: x, y free, z = (a x + b y) / 2.
                const double a = double(int(rng_() % 5) - 2), b = double(int(rng_() % 5) - 2);
                for (Triangle* t : {&p, &q}) {
                    for (Vec3& x : *t) {
                        x = Vec3(double(int(rng_() % 9) - 4), double(int(rng_() % 9) - 4), 0);
                        x.z() = (a * x.x() + b * x.y()) * 0.5;
                    }
                }
                if (rng_() % 4 == 0) {  // q well inside p: p scaled up around q's centroid
                    const Vec3 c = (q[0] + q[1] + q[2]) * 0.25;
                    for (int i = 0; i < 3; ++i) {
                        p[i] = c + 4.0 * (q[i] - c);
                    }
                }
                break;
            }
            case Family::kVertexOnEdge: {
                const int i = pick();
                const double s = double(rng_() % 9) / 8.0;
                const int k = pick();
                q[k] = p[i] + s * (p[(i + 1) % 3] - p[i]);
                nudgeSometimes(q[k]);
                break;
            }
            case Family::kZeroArea:
                q[2] = q[0] + double(int(rng_() % 5) - 2) * 0.5 * (q[1] - q[0]);
                if (rng_() % 3 == 0) {
                    q[1] = q[0];
                    q[2] = q[0];
                    q[0] = p[0] + double(rng_() % 3) * 0.25 * (p[1] - p[0]) +
                           double(rng_() % 3) * 0.25 * (p[2] - p[0]);
                    q[1] = q[2] = q[0];
                }
                if (rng_() % 4 == 0) {
                    p[1] = p[0] + 0.5 * (p[2] - p[0]);
                }
                break;
            case Family::kSnapped:
            case Family::kContinuous: {
                std::uniform_real_distribution<double> u(-1.0, 1.0);
                for (Triangle* t : {&p, &q}) {
                    for (Vec3& x : *t) {
                        x = Vec3(u(rng_), u(rng_), u(rng_));
                        if (family == Family::kSnapped) {
                            x = (x * 8.0).array().round() / 8.0;
                        }
                    }
                }
                break;
            }
        }
        return {p, q};
    }

  private:
    int pick() { return int(rng_() % 3); }
    /// Half of the time, moves x by +-2^-12 along one axis: the shared feature is then
    /// no longer shared, and whether the triangles still meet depends on the rest.
    void nudgeSometimes(Vec3& x) {
        if (rng_() % 2 == 0) {
            x[int(rng_() % 3)] += rng_() % 2 ? 0x1p-12 : -0x1p-12;
        }
    }
    Vec3 gridPoint(int range) {
        auto c = [&] { return double(int(rng_() % (2 * range + 1)) - range); };
        return Vec3(c(), c(), c());
    }
    std::mt19937 rng_;
};

struct FamilyResult {
    int cases = 0, hits = 0, disagreements = 0;
};

/// Runs `count` cases of a family at `scale` (a power of two keeps the degeneracies exact);
/// every case also checks the swapped and permuted calls and the geometry.
FamilyResult runFamily(Family family, double scale, int count, unsigned seed,
                       PredicateStats& stats) {
    TriangleSource source(seed);
    FamilyResult result;
    for (int i = 0; i < count; ++i) {
        auto [p, q] = source.next(family);
        for (int k = 0; k < 3; ++k) {
            p[k] *= scale;
            q[k] *= scale;
        }
        const bool expected = rationalTrianglesIntersect(p, q);
        const bool got = trianglesIntersect(p, q, &stats);
        const bool swapped = trianglesIntersect(q, p, &stats);
        const Triangle permuted = {p[2], p[0], p[1]};
        const Triangle reversed = {q[1], q[0], q[2]};
        const bool shuffled = trianglesIntersect(permuted, reversed, &stats);
        ++result.cases;
        result.hits += expected;
        if (got != expected || swapped != expected || shuffled != expected) {
            ++result.disagreements;
            if (result.disagreements <= 3) {
                ADD_FAILURE() << name(family) << " seed " << seed << " case " << i << " scale "
                              << scale << ": rational " << expected << ", kolize " << got << "/"
                              << swapped << "/" << shuffled << "\n  p = " << describe(p)
                              << "\n  q = " << describe(q);
            }
        }
        TriangleIntersection geometry;
        if (expected && triangleIntersection(p, q, geometry, &stats)) {
            const double tolerance = 1e-9 * scale * 8;
            EXPECT_GE(geometry.count, 1);
            for (int k = 0; k < geometry.count; ++k) {
                EXPECT_LE(distanceToTriangle(geometry.points[k], p), tolerance)
                    << name(family) << " case " << i << " point " << k;
                EXPECT_LE(distanceToTriangle(geometry.points[k], q), tolerance)
                    << name(family) << " case " << i << " point " << k;
            }
        }
    }
    return result;
}

class TriangleFamilies : public ::testing::TestWithParam<Family> {};

TEST_P(TriangleFamilies, MatchRationalReference) {
    const Family family = GetParam();
    const unsigned seed = 1400 + unsigned(family);
    PredicateStats stats;
    // Powers of two keep exact degeneracies exact; 1e6 keeps integer grids exact too.
    for (double scale : {1.0, 0x1p-30, 1e6, 0x1p40}) {
        const FamilyResult r = runFamily(family, scale, scaled(1500), seed, stats);
        EXPECT_EQ(r.disagreements, 0) << name(family) << " scale " << scale;
        // The sample means something: neither (almost) always apart nor always touching.
        EXPECT_GT(r.hits, r.cases / 20) << name(family) << " scale " << scale;
        EXPECT_LT(r.hits, r.cases * 19 / 20) << name(family) << " scale " << scale;
    }
    // Degenerate families reach the exact stages; general position does not need them.
    if (family != Family::kContinuous) {
        EXPECT_GT(stats.fallbacks(), 0u) << name(family);
    }
}

INSTANTIATE_TEST_SUITE_P(Degenerate, TriangleFamilies,
                         ::testing::Values(Family::kGrid, Family::kSharedVertex,
                                           Family::kSharedEdge, Family::kCoplanar,
                                           Family::kVertexOnEdge, Family::kZeroArea,
                                           Family::kSnapped, Family::kContinuous),
                         [](const ::testing::TestParamInfo<Family>& info) {
                             std::string n = name(info.param);
                             std::replace(n.begin(), n.end(), '-', '_');
                             return n;
                         });

TEST(TriangleTest, TinyCoordinatesGoThroughGmp) {
    // Coordinates far below the expansion stage's range (2^-256): only GMP can decide.
    PredicateStats stats;
    const FamilyResult r = runFamily(Family::kGrid, 1e-300, scaled(300), 1499, stats);
    EXPECT_EQ(r.disagreements, 0);
    EXPECT_GT(stats.orient3d[2] + stats.orient2d[2], 0u);
}

TEST(TriangleTest, NamedDegenerateCases) {
    const Triangle p = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
    // Touching at a single shared vertex, from above.
    EXPECT_TRUE(trianglesIntersect(p, {Vec3(1, 0, 0), Vec3(2, 0, 1), Vec3(2, 1, 1)}));
    // A point exactly on p's hypotenuse, and one just off it (below the float grid).
    EXPECT_TRUE(trianglesIntersect(p, {Vec3(0.5, 0.5, 0), Vec3(0.5, 0.5, 0), Vec3(0.5, 0.5, 0)}));
    const double off = std::nextafter(0.5, 1.0);
    EXPECT_FALSE(trianglesIntersect(p, {Vec3(off, 0.5, 0), Vec3(off, 0.5, 0), Vec3(off, 0.5, 0)}));
    // Coplanar, sharing only the edge from (1,0,0) to (0,1,0).
    EXPECT_TRUE(trianglesIntersect(p, {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0)}));
    // Coplanar, disjoint by one ulp.
    EXPECT_FALSE(trianglesIntersect(p, {Vec3(off, 0.5, 0), Vec3(1, 1, 0), Vec3(2, 0.5, 0)}));
    // A segment piercing p's interior, and one passing one ulp beside its vertex.
    EXPECT_TRUE(trianglesIntersect(p, {Vec3(0.2, 0.2, -1), Vec3(0.2, 0.2, 1), Vec3(0.2, 0.2, 0)}));
    const double tiny = std::nextafter(0.0, -1.0);
    EXPECT_FALSE(trianglesIntersect(p, {Vec3(tiny, 0, -1), Vec3(tiny, 0, 1), Vec3(tiny, 0, 1)}));
    // Two zero-area triangles (segments) crossing at a point, and skew ones.
    const Triangle s1 = {Vec3(-1, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, 0)};
    EXPECT_TRUE(trianglesIntersect(s1, {Vec3(0, -1, 0), Vec3(0, 1, 0), Vec3(0, 1, 0)}));
    EXPECT_FALSE(
        trianglesIntersect(s1, {Vec3(0, -1, 1e-300), Vec3(0, 1, 1e-300), Vec3(0, 1, 1e-300)}));
    // Identical triangles; a triangle against itself reversed.
    EXPECT_TRUE(trianglesIntersect(p, p));
    EXPECT_TRUE(trianglesIntersect(p, {p[2], p[1], p[0]}));
}

TEST(TriangleTest, CoplanarOverlapPolygonHasTheRightArea) {
    // Unit right triangle against its copy shifted by (0.5, 0, 0): overlap is the right
    // triangle with legs 0.5, area 1/8.
    const Triangle p = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
    const Triangle q = {Vec3(0.5, 0, 0), Vec3(1.5, 0, 0), Vec3(0.5, 1, 0)};
    TriangleIntersection g;
    ASSERT_TRUE(triangleIntersection(p, q, g));
    EXPECT_EQ(g.kind, TriangleIntersection::Kind::kPolygon);
    EXPECT_NEAR(g.measure(), 0.125, 1e-15);
    // Crossing at right angles: the segment x in [0, 0.5] on the line y = 0.25... here q
    // stands in the plane y = 0.25 and spans x in [0.25, 2], z in [-1, 1].
    const Triangle r = {Vec3(0.25, 0.25, -1), Vec3(0.25, 0.25, 1), Vec3(2, 0.25, 0)};
    ASSERT_TRUE(triangleIntersection(p, r, g));
    EXPECT_EQ(g.kind, TriangleIntersection::Kind::kSegment);
    EXPECT_NEAR(g.measure(), 0.5, 1e-15);  // from x = 0.25 to the hypotenuse at x = 0.75
}

// triangleDistance against an independent reference: the smallest distance from a dense
// barycentric sample of each triangle to the other (distanceToTriangle above), which is at
// least the true distance and at most it plus the sample's spacing. Seeded families: random
// shapes, parallel faces, coplanar apart, crossed edges, zero-area (segments, points), and
// scales from 1e-6 to 1e6.
TEST(TriangleDistance, MatchesADenseSampleOnDisjointPairs) {
    const unsigned seed = 2081;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    auto point = [&] { return Vec3(u(rng), u(rng), u(rng)); };
    constexpr int kSteps = 60;  // sample spacing: 1/60 of an edge
    auto sampledDistance = [&](const Triangle& p, const Triangle& q) {
        double best = 1e300;
        for (int side = 0; side < 2; ++side) {
            const Triangle& from = side == 0 ? p : q;
            const Triangle& to = side == 0 ? q : p;
            for (int i = 0; i <= kSteps; ++i) {
                for (int j = 0; i + j <= kSteps; ++j) {
                    const double a = double(i) / kSteps, b = double(j) / kSteps;
                    const Vec3 x = (1 - a - b) * from[0] + a * from[1] + b * from[2];
                    best = std::min(best, distanceToTriangle(x, to));
                }
            }
        }
        return best;
    };
    auto diameter = [](const Triangle& t) {
        return std::max({(t[0] - t[1]).norm(), (t[1] - t[2]).norm(), (t[2] - t[0]).norm()});
    };
    int cases = 0, families[6] = {};
    for (int n = 0; cases < scaled(600) && n < 100000; ++n) {
        const int family = n % 6;
        Triangle p = {point(), point(), point()};
        Triangle q = {point(), point(), point()};
        const Vec3 shift = point() * 1.5;
        switch (family) {
            case 0:  // random, shifted
                break;
            case 1:  // parallel faces at a random gap
                p = {Vec3(u(rng), u(rng), 0), Vec3(u(rng), u(rng), 0), Vec3(u(rng), u(rng), 0)};
                q = {Vec3(u(rng), u(rng), 0.05 + 0.2 * std::abs(u(rng))), Vec3(u(rng), u(rng), 0),
                     Vec3(u(rng), u(rng), 0)};
                q[1].z() = q[0].z();
                q[2].z() = q[0].z();
                break;
            case 2:  // coplanar, apart
                for (Vec3& x : p) {
                    x.z() = 0;
                }
                for (Vec3& x : q) {
                    x.z() = 0;
                }
                break;
            case 3:  // crossed edges (thin triangles)
                p = {Vec3(-1, 0, 0), Vec3(1, 0, 0), Vec3(0, 0.02 * u(rng), -1)};
                q = {Vec3(0.3 * u(rng), -1, 0.05), Vec3(0.3 * u(rng), 1, 0.05),
                     Vec3(0, 0.02 * u(rng), 1)};
                break;
            case 4:  // zero area: a segment against a triangle
                p[2] = 0.5 * (p[0] + p[1]);
                break;
            case 5:  // zero area: a point against a segment
                p[1] = p[2] = p[0];
                q[2] = q[1];
                break;
        }
        if (family != 1 && family != 3) {
            for (Vec3& x : q) {
                x += shift;
            }
        }
        const double scale = std::pow(10.0, (n % 13) - 6);  // 1e-6 .. 1e6
        for (Triangle* t : {&p, &q}) {
            for (Vec3& x : *t) {
                x *= scale;
            }
        }
        if (trianglesIntersect(p, q)) {
            continue;
        }
        ++cases;
        ++families[family];
        const TriangleDistance d = triangleDistance(p, q);
        const double sampled = sampledDistance(p, q);
        const double spacing = std::max(diameter(p), diameter(q)) / kSteps;
        const double rounding = 1e-12 * scale;
        SCOPED_TRACE("seed " + std::to_string(seed) + " case " + std::to_string(n) + " p " +
                     describe(p) + " q " + describe(q));
        EXPECT_LE(d.distance, sampled + rounding);
        EXPECT_GE(d.distance, sampled - spacing - rounding);
        EXPECT_NEAR((d.on_q - d.on_p).norm(), d.distance, rounding);
        EXPECT_LE(distanceToTriangle(d.on_p, p), rounding);
        EXPECT_LE(distanceToTriangle(d.on_q, q), rounding);
        EXPECT_GT(d.distance, 0.0);
    }
    EXPECT_EQ(cases, scaled(600));
    for (int f = 0; f < 6; ++f) {
        EXPECT_GT(families[f], 0) << "family " << f;
    }
}

TEST(TriangleDistance, KnownGaps) {
    // Parallel faces 0.25 apart, overlapping in projection: vertex-face, the gap exactly.
    const Triangle floor = {Vec3(-1, -1, 0), Vec3(1, -1, 0), Vec3(0, 1, 0)};
    const Triangle above = {Vec3(-0.2, 0, 0.25), Vec3(0.2, 0, 0.25), Vec3(0, 0.2, 0.25)};
    const TriangleDistance faces = triangleDistance(floor, above);
    EXPECT_DOUBLE_EQ(faces.distance, 0.25);
    EXPECT_DOUBLE_EQ(faces.on_q.z() - faces.on_p.z(), 0.25);
    // Crossed edges: x axis at z = 0 against the y axis at z = 0.5, the common normal's length.
    const Triangle alongX = {Vec3(-1, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, -1)};
    const Triangle alongY = {Vec3(0, -1, 0.5), Vec3(0, 1, 0.5), Vec3(0, 0, 1.5)};
    const TriangleDistance edges = triangleDistance(alongX, alongY);
    EXPECT_DOUBLE_EQ(edges.distance, 0.5);
    EXPECT_LE(edges.on_p.norm(), 1e-15);
    // Two points 3-4-5 apart.
    const Triangle a = {Vec3(0, 0, 0), Vec3(0, 0, 0), Vec3(0, 0, 0)};
    const Triangle b = {Vec3(3, 4, 0), Vec3(3, 4, 0), Vec3(3, 4, 0)};
    EXPECT_DOUBLE_EQ(triangleDistance(a, b).distance, 5.0);
}

}  // namespace
