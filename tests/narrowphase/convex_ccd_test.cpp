// The surface kolize's convex-against-mesh time of impact uses for a Bullet convex shape
// (convex_ccd.h): checked against the shape's own support points, which must all lie
// inside the surface's triangles (a plain point-in-convex test over the output triangles,
// not the planes the builder computed), and for tightness on boxes and spheres.
#include "convex_ccd.h"

#include "test_scale.h"

#include <Eigen/Geometry>
#include <btBulletCollisionCommon.h>
#include <BulletCollision/CollisionShapes/btTriangleShape.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace {

using kolize::detail::EnclosingPolytope;
using kolize::narrowphase::Vec3;

Vec3 toVec3(const btVector3& v) {
    return Vec3(double(v.x()), double(v.y()), double(v.z()));
}

struct Named {
    std::string name;
    std::shared_ptr<btConvexShape> shape;
};

std::vector<Named> shapes(std::mt19937& random) {
    std::vector<Named> out;
    auto add = [&](std::string name, btConvexShape* shape) {
        out.push_back({std::move(name), std::shared_ptr<btConvexShape>(shape)});
    };
    for (double scale : {1e-3, 1.0, 1e3}) {
        const auto s = btScalar(scale);
        const std::string at = " at scale " + std::to_string(scale);
        add("box" + at, new btBoxShape(btVector3(1, 2, 3) * s));
        auto* bare = new btBoxShape(btVector3(1, 0.5, 0.25) * s);
        bare->setMargin(0);
        add("box, margin 0" + at, bare);
        add("sphere" + at, new btSphereShape(s));
        add("capsule" + at, new btCapsuleShape(s, 3 * s));
        add("cylinder" + at, new btCylinderShape(btVector3(1, 2, 1) * s));
        add("cone" + at, new btConeShape(s, 2 * s));
        auto* hull = new btConvexHullShape();
        std::normal_distribution<double> gauss(0, scale);
        for (int i = 0; i < 40; ++i) {
            hull->addPoint(btVector3(btScalar(gauss(random)), btScalar(gauss(random)),
                                     btScalar(gauss(random))),
                           false);
        }
        hull->recalcLocalAabb();
        hull->setMargin(btScalar(0.04 * scale));
        hull->setLocalScaling(btVector3(1, 2, btScalar(0.5)));
        add("convex hull, margin, scaled" + at, hull);
        const btVector3 centres[2] = {btVector3(0, 0, 0), btVector3(s, s, 0)};
        const btScalar radii[2] = {s, btScalar(0.5) * s};
        add("multi-sphere" + at, new btMultiSphereShape(centres, radii, 2));
        add("triangle (flat)" + at,
            new btTriangleShape(btVector3(0, 0, 0), btVector3(s, 0, 0), btVector3(0, s, 0)));
    }
    return out;
}

/// The polytope's triangles, each with its outward plane (oriented away from the centroid of
/// the vertices): a point is inside when it is behind every one, within `tolerance`.
bool inside(const EnclosingPolytope& p, const Vec3& point, double tolerance) {
    Vec3 centroid = Vec3::Zero();
    for (const Vec3& v : p.vertices) {
        centroid += v;
    }
    centroid /= double(p.vertices.size());
    for (const auto& t : p.triangles) {
        const Vec3 &a = p.vertices[t[0]], &b = p.vertices[t[1]], &c = p.vertices[t[2]];
        Vec3 n = (b - a).cross(c - a);
        if (n.norm() == 0) {
            continue;  // a zero-area triangle (the flat fallback) bounds nothing
        }
        n.normalize();
        if (n.dot(a - centroid) < 0) {
            n = -n;
        }
        if (n.dot(point - a) > tolerance) {
            return false;
        }
    }
    return true;
}

TEST(EnclosingPolytope, ContainsEveryConvexShapeWithItsMargin) {
    std::mt19937 random(20261203);
    std::printf("seed 20261203\n");
    std::normal_distribution<double> gauss(0, 1);
    const int directions = kolize::narrowphase::testing::scaled(3000);
    for (const Named& named : shapes(random)) {
        SCOPED_TRACE(named.name);
        EnclosingPolytope polytope;
        ASSERT_TRUE(kolize::detail::enclosingPolytope(*named.shape, polytope));
        ASSERT_GE(polytope.vertices.size(), 4u);
        ASSERT_GE(polytope.triangles.size(), 4u);
        EXPECT_TRUE(kolize::detail::encloses(polytope, *named.shape));
        // Closed: every edge in exactly two triangles.
        std::map<std::pair<int, int>, int> edges;
        for (const auto& t : polytope.triangles) {
            for (int k = 0; k < 3; ++k) {
                const int u = t[k], v = t[(k + 1) % 3];
                ++edges[{std::min(u, v), std::max(u, v)}];
            }
        }
        for (const auto& [edge, count] : edges) {
            EXPECT_EQ(count, 2) << edge.first << "-" << edge.second;
        }
        btVector3 lo, hi;
        btTransform identity;
        identity.setIdentity();
        named.shape->getAabb(identity, lo, hi);
        const double extent = double((hi - lo).length());
        const double tolerance = 16 * double(std::numeric_limits<btScalar>::epsilon()) * extent;
        int outside = 0;
        for (int i = 0; i < directions; ++i) {
            const Vec3 d = Vec3(gauss(random), gauss(random), gauss(random)).normalized();
            const Vec3 point = toVec3(named.shape->localGetSupportingVertex(
                btVector3(btScalar(d.x()), btScalar(d.y()), btScalar(d.z()))));
            outside += !inside(polytope, point, tolerance);
        }
        EXPECT_EQ(outside, 0);
    }
}

TEST(EnclosingPolytope, IsTheBoxItselfAndHugsASphere) {
    btBoxShape box(btVector3(1, 2, 3));  // margin 0.04, inside the half extents
    EnclosingPolytope p;
    ASSERT_TRUE(kolize::detail::enclosingPolytope(box, p));
    ASSERT_EQ(p.vertices.size(), 8u);
    EXPECT_EQ(p.standoff, 0.0);  // the box's own faces
    for (const Vec3& v : p.vertices) {
        EXPECT_NEAR(std::abs(v.x()), 1, 1e-5);
        EXPECT_NEAR(std::abs(v.y()), 2, 1e-5);
        EXPECT_NEAR(std::abs(v.z()), 3, 1e-5);
    }
    btSphereShape sphere(2);
    ASSERT_TRUE(kolize::detail::enclosingPolytope(sphere, p));
    double farthest = 0;
    for (const Vec3& v : p.vertices) {
        farthest = std::max(farthest, v.norm());
    }
    std::printf("sphere of radius 2: farthest vertex %.4f, standoff %.4f\n", farthest, p.standoff);
    EXPECT_GE(farthest, 2.0);
    EXPECT_LE(farthest, 2 + p.standoff);
    EXPECT_LE(p.standoff, 2 * 0.1);
    EXPECT_GT(p.standoff, 0.0);  // round: the time of impact advances to the shape
}

TEST(EnclosingPolytope, NonFiniteShapesAreRefused) {
    btSphereShape sphere(1);
    sphere.setUnscaledRadius(std::numeric_limits<btScalar>::quiet_NaN());
    EnclosingPolytope p;
    EXPECT_FALSE(kolize::detail::enclosingPolytope(sphere, p));
    EXPECT_TRUE(p.vertices.empty());
    EXPECT_FALSE(kolize::detail::encloses(p, sphere));
}

TEST(EnclosingPolytope, AGrownShapeIsNoLongerEnclosed) {
    btBoxShape box(btVector3(1, 1, 1));
    EnclosingPolytope p;
    ASSERT_TRUE(kolize::detail::enclosingPolytope(box, p));
    EXPECT_TRUE(kolize::detail::encloses(p, box));
    box.setLocalScaling(btVector3(1, btScalar(1.01), 1));
    EXPECT_FALSE(kolize::detail::encloses(p, box));
}

}  // namespace
