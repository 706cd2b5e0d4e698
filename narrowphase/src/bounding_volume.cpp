#include "kolize/narrowphase/bounding_volume.h"

#include "bv_internal.h"
#include "rational_internal.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace kolize::narrowphase {

using detail::Rational;

Vec3f Obb::axis2() const {
    return detail::crossFloat(axis0, axis1);
}

template <int K>
const std::array<Eigen::Vector3i, K / 2>& kdopDirections() {
    static const std::array<Eigen::Vector3i, K / 2> directions = [] {
        const Eigen::Vector3i axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
        const Eigen::Vector3i corners[4] = {{1, 1, 1}, {1, -1, 1}, {1, 1, -1}, {1, -1, -1}};
        const Eigen::Vector3i edges[6] = {{1, 1, 0},  {1, 0, 1},  {0, 1, 1},
                                          {1, -1, 0}, {1, 0, -1}, {0, 1, -1}};
        std::array<Eigen::Vector3i, K / 2> out;
        int n = 0;
        for (const Eigen::Vector3i& d : axes) {
            out[n++] = d;
        }
        if (K == 14 || K == 26) {
            for (const Eigen::Vector3i& d : corners) {
                out[n++] = d;
            }
        }
        if (K == 18 || K == 26) {
            for (const Eigen::Vector3i& d : edges) {
                out[n++] = d;
            }
        }
        return out;
    }();
    return directions;
}

Covariance triangleCovariance(const TriangleSpan& triangles) {
    Covariance out;
    const double n = 3.0 * double(triangles.count);
    if (triangles.count == 0) {
        return out;
    }
    triangles.forEachCorner([&](const Vec3& x) { out.mean += x; });
    out.mean /= n;
    triangles.forEachCorner([&](const Vec3& x) {
        const Vec3 p = x - out.mean;
        out.matrix += p * p.transpose();
    });
    out.matrix /= n;
    return out;
}

Eigen::Matrix3d principalAxes(const Eigen::Matrix3d& covariance) {
    Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
    if (!covariance.allFinite()) {
        return axes;
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    solver.computeDirect(covariance);
    if (solver.info() != Eigen::Success || !solver.eigenvectors().allFinite()) {
        return axes;
    }
    // Eigen orders eigenvalues increasingly; the thesis wants the largest spread first.
    Vec3 e0 = solver.eigenvectors().col(2);
    Vec3 e1 = solver.eigenvectors().col(1);
    // Repeated eigenvalues (a symmetric or degenerate part) leave the vectors only nearly
    // orthonormal: re-orthonormalize, and pick any perpendicular when e1 collapses.
    if (!(e0.norm() > 0.5)) {
        return axes;
    }
    e0.normalize();
    e1 -= e1.dot(e0) * e0;
    if (!(e1.norm() > 1e-6)) {
        e1 = e0.unitOrthogonal();
    }
    e1.normalize();
    axes.col(0) = e0;
    axes.col(1) = e1;
    axes.col(2) = e0.cross(e1);
    return axes;
}

namespace {

template <class Span>
auto cornersOf(const Span& span) {
    return [&span](auto&& f) { span.forEachCorner(f); };
}

}  // namespace

Sphere fitSphere(const TriangleSpan& triangles) {
    return detail::fitSphereFrom(cornersOf(triangles));
}

Aabb fitAabb(const TriangleSpan& triangles) {
    return detail::fitAabbFrom(cornersOf(triangles));
}

Obb fitObb(const TriangleSpan& triangles) {
    return fitObb(triangles, principalAxes(triangleCovariance(triangles).matrix));
}

Obb fitObb(const TriangleSpan& triangles, const Eigen::Matrix3d& axes) {
    return detail::fitObbFrom(cornersOf(triangles), axes);
}

template <int K>
Kdop<K> fitKdop(const TriangleSpan& triangles) {
    return detail::fitKdopFrom<K>(cornersOf(triangles));
}

template <int K>
Kdop<K> fitKdop(const Vec3* points, std::size_t count) {
    detail::KdopAccumulator<K> acc;
    for (std::size_t i = 0; i < count; ++i) {
        acc.add(points[i]);
    }
    return acc.rounded();
}

namespace {

double positionSlack(const Vec3& a, const Vec3& b, const RelativePose& pose) {
    return 0x1p-40 * (a.norm() + b.norm() + pose.translation().norm());
}

}  // namespace

bool overlap(const Sphere& a, const Sphere& b, const RelativePose& bInA) {
    const Vec3 ca = a.center.cast<double>();
    const Vec3 cb = bInA.apply(b.center.cast<double>());
    return !detail::spheresDisjoint(cb - ca, a.radius, b.radius,
                                    positionSlack(ca, b.center.cast<double>(), bInA));
}

bool overlap(const Aabb& a, const Aabb& b) {
    for (int k = 0; k < 3; ++k) {
        if (a.hi[k] < b.lo[k] || b.hi[k] < a.lo[k]) {
            return false;
        }
    }
    return true;
}

bool overlap(const Aabb& a, const Aabb& b, const RelativePose& bInA) {
    const Vec3 ca = 0.5 * (a.lo.cast<double>() + a.hi.cast<double>());
    const Vec3 ea = 0.5 * (a.hi.cast<double>() - a.lo.cast<double>());
    const Vec3 cbModel = 0.5 * (b.lo.cast<double>() + b.hi.cast<double>());
    const Vec3 eb = 0.5 * (b.hi.cast<double>() - b.lo.cast<double>());
    const Vec3 cb = bInA.apply(cbModel);
    const Eigen::Matrix3d absR = bInA.rotation().cwiseAbs();
    return !detail::aabbsDisjoint(ca, ea, cb, eb, bInA.rotation(), absR,
                                  positionSlack(ca, cbModel, bInA));
}

bool overlap(const Obb& a, const Obb& b, const RelativePose& bInA) {
    const detail::ObbInFrame moved = detail::moveObb(b, bInA.rotation(), bInA.translation());
    const Vec3 d = moved.center - a.center.cast<double>();
    const float slack =
        detail::roundUp(positionSlack(a.center.cast<double>(), b.center.cast<double>(), bInA));
    return detail::obbSeparatingAxis(a, a.axis2(), moved, d.x(), d.y(), d.z(), slack,
                                     detail::kNoAxis) == detail::kNoAxis;
}

template <int K>
bool overlap(const Kdop<K>& a, const Kdop<K>& b) {
    return !detail::kdopsDisjoint(a, b);
}

Sphere transformed(const Sphere& s, const RelativePose& pose) {
    const Vec3 c = pose.apply(s.center.cast<double>());
    Sphere out;
    out.center = c.cast<float>();
    const double moved = (c - out.center.cast<double>()).norm();
    out.radius = detail::roundUp(double(s.radius) * (1.0 + detail::kPoseSlack) + moved +
                                 positionSlack(c, s.center.cast<double>(), pose));
    return out;
}

Aabb transformed(const Aabb& box, const RelativePose& pose) {
    const Vec3 cModel = 0.5 * (box.lo.cast<double>() + box.hi.cast<double>());
    const Vec3 e = 0.5 * (box.hi.cast<double>() - box.lo.cast<double>());
    const Vec3 c = pose.apply(cModel);
    const Vec3 extent = (pose.rotation().cwiseAbs() * e) * (1.0 + detail::kPoseSlack) +
                        Vec3::Constant(positionSlack(c, cModel, pose) + e.sum() * 0x1p-50);
    Aabb out;
    for (int k = 0; k < 3; ++k) {
        out.lo[k] = detail::roundDown(c[k] - extent[k]);
        out.hi[k] = detail::roundUp(c[k] + extent[k]);
    }
    return out;
}

Obb transformed(const Obb& box, const RelativePose& pose) {
    const detail::ObbInFrame moved = detail::moveObb(box, pose.rotation(), pose.translation());
    Obb out;
    out.center = moved.center.cast<float>();
    out.axis0 = moved.axis(0);
    out.axis1 = moved.axis(1);
    // The new float axes differ from the exactly rotated ones by a few float ulps, and the
    // centre by its rounding: every point of the moved box lies within `drift` of the new
    // box, which the enlarged extents absorb (the axes are orthonormal to ~1e-6).
    const double drift = (moved.center - out.center.cast<double>()).norm() +
                         0x1p-19 * double(moved.extentSum) +
                         positionSlack(moved.center, box.center.cast<double>(), pose);
    for (int k = 0; k < 3; ++k) {
        out.half[k] = detail::roundUp(double(box.half[k]) * (1.0 + detail::kPoseSlack) + 2 * drift);
    }
    out.radius = detail::roundUp(double(box.radius) * (1.0 + detail::kPoseSlack) + drift);
    return out;
}

// ---------------------------------------------------------------------------------------
// Exact containment.
// ---------------------------------------------------------------------------------------

bool contains(const Sphere& s, const Vec3& x) {
    const Vec3 w = x - s.center.cast<double>();
    const double d2 = w.squaredNorm();
    const double r2 = double(s.radius) * double(s.radius);  // exact: 48 bits
    if (d2 <= r2 * (1 - 0x1p-48)) {
        return true;
    }
    if (d2 >= r2 * (1 + 0x1p-48) && d2 > 0) {
        return false;
    }
    Rational sum;
    for (int k = 0; k < 3; ++k) {
        const Rational dk = Rational(x[k]) - Rational(double(s.center[k]));
        sum = sum + dk * dk;
    }
    return sum <= Rational(r2);
}

bool contains(const Aabb& box, const Vec3& x) {
    for (int k = 0; k < 3; ++k) {
        if (x[k] < double(box.lo[k]) || x[k] > double(box.hi[k])) {
            return false;
        }
    }
    return true;
}

bool contains(const Obb& box, const Vec3& x) {
    // x = c + A u with A = [a0 a1 a2]: u_i = (c_i . w) / det A by Cramer's rule, c_i the
    // cross product of the other two columns (cyclic), w = x - c. Inside iff
    // |c_i . w| <= half_i det A for every i; decided in double when clearly so, else in
    // rationals.
    const Vec3 a[3] = {box.axis0.cast<double>(), box.axis1.cast<double>(),
                       box.axis2().cast<double>()};
    const Vec3 w = x - box.center.cast<double>();
    const double det = a[0].dot(a[1].cross(a[2]));
    bool decided = true, inside = true;
    for (int i = 0; i < 3 && decided && inside; ++i) {
        const Vec3 cofactor = a[(i + 1) % 3].cross(a[(i + 2) % 3]);
        const double lhs = std::fabs(cofactor.dot(w));
        const double rhs = double(box.half[i]) * det;
        const double error = 0x1p-45 * (cofactor.cwiseAbs().dot(w.cwiseAbs()) +
                                        std::fabs(double(box.half[i])) * 3.0);
        if (lhs + error < rhs) {
            continue;
        }
        if (lhs - error > rhs) {
            inside = false;
            continue;
        }
        decided = false;
    }
    if (decided) {
        return inside;
    }
    Rational A[3][3], W[3];
    for (int k = 0; k < 3; ++k) {
        for (int j = 0; j < 3; ++j) {
            A[j][k] = Rational(a[j][k]);
        }
        W[k] = Rational(x[k]) - Rational(double(box.center[k]));
    }
    auto cross = [](const Rational* p, const Rational* q, Rational* out) {
        out[0] = p[1] * q[2] - p[2] * q[1];
        out[1] = p[2] * q[0] - p[0] * q[2];
        out[2] = p[0] * q[1] - p[1] * q[0];
    };
    Rational c12[3];
    cross(A[1], A[2], c12);
    const Rational exactDet = A[0][0] * c12[0] + A[0][1] * c12[1] + A[0][2] * c12[2];
    for (int i = 0; i < 3; ++i) {
        Rational cofactor[3];
        cross(A[(i + 1) % 3], A[(i + 2) % 3], cofactor);
        const Rational lhs = (cofactor[0] * W[0] + cofactor[1] * W[1] + cofactor[2] * W[2]).abs();
        if (!(lhs <= Rational(double(box.half[i])) * exactDet.abs())) {
            return false;
        }
    }
    return exactDet.sign() != 0;
}

template <int K>
bool contains(const Kdop<K>& dop, const Vec3& x) {
    const std::array<Eigen::Vector3i, K / 2>& dirs = kdopDirections<K>();
    for (int i = 0; i < K / 2; ++i) {
        const double p = (dirs[i].x() * x.x() + dirs[i].y() * x.y()) + dirs[i].z() * x.z();
        const double error = 0x1p-50 * x.cwiseAbs().sum();
        if (p - error >= double(dop.lo[i]) && p + error <= double(dop.hi[i])) {
            continue;
        }
        if (p + error < double(dop.lo[i]) || p - error > double(dop.hi[i])) {
            return false;
        }
        const Rational exact = Rational(double(dirs[i].x())) * Rational(x.x()) +
                               Rational(double(dirs[i].y())) * Rational(x.y()) +
                               Rational(double(dirs[i].z())) * Rational(x.z());
        if (!(Rational(double(dop.lo[i])) <= exact && exact <= Rational(double(dop.hi[i])))) {
            return false;
        }
    }
    return true;
}

#define KOLIZE_KDOP_INSTANCES(K)                                            \
    template const std::array<Eigen::Vector3i, K / 2>& kdopDirections<K>(); \
    template Kdop<K> fitKdop<K>(const TriangleSpan&);                       \
    template Kdop<K> fitKdop<K>(const Vec3*, std::size_t);                  \
    template bool overlap<K>(const Kdop<K>&, const Kdop<K>&);               \
    template bool contains<K>(const Kdop<K>&, const Vec3&);
KOLIZE_KDOP_INSTANCES(6)
KOLIZE_KDOP_INSTANCES(14)
KOLIZE_KDOP_INSTANCES(18)
KOLIZE_KDOP_INSTANCES(26)
#undef KOLIZE_KDOP_INSTANCES

}  // namespace kolize::narrowphase
