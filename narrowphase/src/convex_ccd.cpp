#include "convex_ccd.h"

#include <Eigen/Geometry>

#include <BulletCollision/CollisionShapes/btConcaveShape.h>
#include <BulletCollision/CollisionShapes/btConvexShape.h>
#include <BulletCollision/CollisionShapes/btTriangleCallback.h>
#include <BulletCollision/CollisionShapes/btTriangleShape.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpaPenetrationDepthSolver.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkPairDetector.h>
#include <BulletCollision/NarrowPhaseCollision/btPointCollector.h>
#include <BulletCollision/NarrowPhaseCollision/btVoronoiSimplexSolver.h>
#include <LinearMath/btConvexHullComputer.h>
#include <LinearMath/btTransform.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace kolize::detail {

using narrowphase::Index3;
using narrowphase::Vec3;

namespace {

Vec3 support(const btConvexShape& shape, const Vec3& direction) {
    const btVector3 v = shape.localGetSupportingVertex(
        btVector3(btScalar(direction.x()), btScalar(direction.y()), btScalar(direction.z())));
    return Vec3(double(v.x()), double(v.y()), double(v.z()));
}

/// The 26 directions of {-1, 0, 1}^3 and `spread` more on a Fibonacci spiral, unit length.
std::vector<Vec3> directions(int spread) {
    std::vector<Vec3> out;
    for (int x = -1; x <= 1; ++x) {
        for (int y = -1; y <= 1; ++y) {
            for (int z = -1; z <= 1; ++z) {
                if (x || y || z) {
                    out.push_back(Vec3(x, y, z).normalized());
                }
            }
        }
    }
    const double golden = M_PI * (3 - std::sqrt(5.0));
    for (int i = 0; i < spread; ++i) {
        const double z = 1 - (2 * i + 1.0) / spread;
        const double r = std::sqrt(std::max(0.0, 1 - z * z));
        out.emplace_back(r * std::cos(golden * i), r * std::sin(golden * i), z);
    }
    return out;
}

/// Slack on the scale and on the planes' offsets: the supports are btScalar.
constexpr double kSlack = 8 * double(std::numeric_limits<btScalar>::epsilon());

/// The box of the shape's supports along the axes: the fallback for flat shapes.
void supportBox(const btConvexShape& shape, EnclosingPolytope& out) {
    Vec3 lo, hi;
    for (int axis = 0; axis < 3; ++axis) {
        Vec3 d = Vec3::Zero();
        d[axis] = 1;
        hi[axis] = support(shape, d)[axis];
        lo[axis] = support(shape, -d)[axis];
    }
    const Vec3 pad = kSlack * (hi - lo).cwiseAbs().cwiseMax(lo.cwiseAbs()).cwiseMax(hi.cwiseAbs());
    lo -= pad;
    hi += pad;
    out.vertices.clear();
    for (int i = 0; i < 8; ++i) {
        out.vertices.emplace_back(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(),
                                  i & 4 ? hi.z() : lo.z());
    }
    out.triangles = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                     {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
    out.planes.clear();
    for (int axis = 0; axis < 3; ++axis) {
        Vec3 d = Vec3::Zero();
        d[axis] = 1;
        out.planes.emplace_back(d, hi[axis]);
        out.planes.emplace_back(-d, -lo[axis]);
    }
    out.standoff = std::numeric_limits<double>::infinity();  // unknown: always advanced
}

}  // namespace

namespace {

/// The hull of `points` as triangles and face planes (unit outward normal, offset through
/// the face's farthest vertex); false when it has no volume.
bool hullOf(const std::vector<Vec3>& points, EnclosingPolytope& out) {
    out = EnclosingPolytope{};
    std::vector<double> coordinates;
    for (const Vec3& p : points) {
        coordinates.insert(coordinates.end(), {p.x(), p.y(), p.z()});
    }
    btConvexHullComputer hull;
    hull.compute(coordinates.data(), 3 * sizeof(double), int(points.size()), 0, 0);
    if (hull.vertices.size() < 4 || hull.faces.size() < 4) {
        return false;
    }
    for (int i = 0; i < hull.vertices.size(); ++i) {
        const btVector3& v = hull.vertices[i];
        out.vertices.emplace_back(double(v.x()), double(v.y()), double(v.z()));
    }
    for (int f = 0; f < hull.faces.size(); ++f) {
        const btConvexHullComputer::Edge* first = &hull.edges[hull.faces[f]];
        const btConvexHullComputer::Edge* edge = first;
        std::vector<int> polygon;
        do {
            polygon.push_back(edge->getSourceVertex());
            edge = edge->getNextEdgeOfFace();
        } while (edge != first && polygon.size() <= std::size_t(hull.edges.size()));
        Vec3 normal = Vec3::Zero();  // Newell's: twice the area along the normal
        for (std::size_t k = 0; k < polygon.size(); ++k) {
            normal +=
                out.vertices[polygon[k]].cross(out.vertices[polygon[(k + 1) % polygon.size()]]);
        }
        const double length = normal.norm();
        if (!(length > 0)) {
            continue;  // a sliver of zero area: bounds nothing, and its triangles are empty
        }
        normal /= length;
        double offset = -std::numeric_limits<double>::infinity();
        for (int k : polygon) {
            offset = std::max(offset, normal.dot(out.vertices[k]));
        }
        out.planes.emplace_back(normal, offset);
        for (std::size_t k = 1; k + 1 < polygon.size(); ++k) {
            out.triangles.push_back(Index3{polygon[0], polygon[k], polygon[k + 1]});
        }
    }
    return out.planes.size() >= 4;
}

/// How far the shape reaches beyond the worst of `polytope`'s face planes (<= 0: inside).
double overreach(const EnclosingPolytope& polytope, const btConvexShape& shape) {
    double worst = -std::numeric_limits<double>::infinity();
    for (const auto& [normal, offset] : polytope.planes) {
        worst = std::max(worst, normal.dot(support(shape, normal)) - offset);
    }
    return worst;
}

}  // namespace

bool enclosingPolytope(const btConvexShape& shape, EnclosingPolytope& out) {
    out = EnclosingPolytope{};
    // The hull of the supporting vertices lies inside the shape; grown by a cube of half
    // side `grow` at every vertex (the hull of the shifted copies) it contains the shape once
    // the shape's support in each of its face normals is behind that face.
    std::vector<Vec3> supports;
    double extent = 0;
    for (const Vec3& d : directions(96)) {
        const Vec3 p = support(shape, d);
        if (!p.allFinite()) {
            return false;
        }
        supports.push_back(p);
        extent = std::max(extent, p.cwiseAbs().maxCoeff());
    }
    const double tolerance = kSlack * extent;
    if (!hullOf(supports, out)) {
        supportBox(shape, out);  // flat or degenerate: no volume
        return true;
    }
    double grow = std::max(0.0, overreach(out, shape));
    for (int round = 0; round < 8 && grow > tolerance; ++round) {
        std::vector<Vec3> grown;
        for (const Vec3& p : supports) {
            for (int corner = 0; corner < 8; ++corner) {
                grown.push_back(
                    p + grow * Vec3(corner & 1 ? 1 : -1, corner & 2 ? 1 : -1, corner & 4 ? 1 : -1));
            }
        }
        if (!hullOf(grown, out)) {
            supportBox(shape, out);
            return true;
        }
        const double left = overreach(out, shape);
        if (!(left > tolerance)) {
            break;
        }
        grow += 2 * left;
    }
    if (overreach(out, shape) > tolerance) {
        supportBox(shape, out);  // never happened in the tests; the box is always safe
        return true;
    }
    // A vertex of the grown hull is at most a cube's corner beyond the supports' hull,
    // which is inside the shape.
    out.standoff = grow > tolerance ? std::sqrt(3.0) * grow + tolerance : 0;
    // The slack: the planes and the vertices moved out by rounding's worth.
    for (auto& [normal, offset] : out.planes) {
        offset += tolerance;
    }
    Vec3 centroid = Vec3::Zero();
    for (const Vec3& v : out.vertices) {
        centroid += v;
    }
    centroid /= double(out.vertices.size());
    for (Vec3& v : out.vertices) {
        v = centroid + (1 + kSlack) * (v - centroid);
    }
    return true;
}

bool encloses(const EnclosingPolytope& polytope, const btConvexShape& shape) {
    if (polytope.planes.empty()) {
        return false;
    }
    for (const auto& [normal, offset] : polytope.planes) {
        if (!(normal.dot(support(shape, normal)) <= offset)) {
            return false;
        }
    }
    return true;
}

namespace {

constexpr int kMaxAdvances = 256;

btTransform poseAt(const Motion& motion, double t) {
    btTransform pose;
    pose.setOrigin(motion.start->getOrigin().lerp(motion.end->getOrigin(), btScalar(t)));
    pose.setRotation(motion.start->getRotation().slerp(motion.end->getRotation(), btScalar(t)));
    return pose;
}

double turnOf(const Motion& motion) {
    return double(motion.start->getRotation().angleShortestPath(motion.end->getRotation()));
}

/// The smallest GJK distance from the convex (at `convexPose`) to the mesh's triangles in
/// the box `lo`, `hi` (mesh frame); `reach` when there are none.
class NearestTriangle : public btTriangleCallback {
  public:
    NearestTriangle(const btConvexShape& convex, const btTransform& convexPose,
                    const btTransform& meshPose, double reach)
        : nearest(reach), convex_(convex), convexPose_(convexPose), meshPose_(meshPose) {}
    void processTriangle(btVector3* triangle, int, int) override {
        btTriangleShape shape(triangle[0], triangle[1], triangle[2]);
        shape.setMargin(0);
        btVoronoiSimplexSolver simplex;
        btGjkEpaPenetrationDepthSolver penetration;
        btGjkPairDetector gjk(&convex_, &shape, &simplex, &penetration);
        btGjkPairDetector::ClosestPointInput input;
        input.m_transformA = convexPose_;
        input.m_transformB = meshPose_;
        btPointCollector result;
        gjk.getClosestPoints(input, result, nullptr);
        const double distance = result.m_hasResult ? double(result.m_distance) : 0.0;
        nearest = std::min(nearest, std::isfinite(distance) ? distance : 0.0);
    }
    double nearest;

  private:
    const btConvexShape& convex_;
    btTransform convexPose_, meshPose_;
};

}  // namespace

double nearestDistance(const btConvexShape& convex, const btTransform& convexPose,
                       const btConcaveShape& mesh, const btTransform& meshPose, double reach) {
    btVector3 lo, hi;
    convex.getAabb(meshPose.inverse() * convexPose, lo, hi);
    const btScalar r = btScalar(reach);
    const btVector3 pad(r, r, r);
    NearestTriangle nearest(convex, convexPose, meshPose, 2 * reach);
    mesh.processAllTriangles(&nearest, lo - pad, hi + pad);
    return nearest.nearest;
}

double advanceToContact(const btConvexShape& convex, const Motion& convexMotion,
                        const btConcaveShape& mesh, const Motion& meshMotion, double from,
                        double tolerance) {
    const btVector3 relative = (convexMotion.end->getOrigin() - convexMotion.start->getOrigin()) -
                               (meshMotion.end->getOrigin() - meshMotion.start->getOrigin());
    // How far any point of one may approach the other over the whole step.
    const double bound = double(relative.length()) +
                         turnOf(convexMotion) * double(convex.getAngularMotionDisc()) +
                         turnOf(meshMotion) * double(mesh.getAngularMotionDisc());
    if (!std::isfinite(bound)) {
        return from;
    }
    double t = std::max(0.0, from);
    for (int advance = 0; advance < kMaxAdvances && t < 1; ++advance) {
        const double reach = bound * (1 - t) + tolerance;
        const double nearest =
            nearestDistance(convex, poseAt(convexMotion, t), mesh, poseAt(meshMotion, t), reach);
        if (nearest > reach) {
            return 1;  // nothing within reach for the rest of the step
        }
        if (nearest <= tolerance) {
            return t;
        }
        if (!(bound > 0)) {
            return 1;
        }
        // A tenth of the distance and three quarters of the tolerance kept in hand: GJK's
        // distances are not exact (in float, errors of 1e-4 of the shape's size were seen at
        // small gaps, and of several percent of the gap for a cone's tip).
        t += (0.9 * nearest - 0.75 * tolerance) / bound;
    }
    return t < 1 ? t : 1;
}

}  // namespace kolize::detail
