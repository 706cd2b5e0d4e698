#pragma once
// Bounding-volume arithmetic shared by the public functions, the tree builder and the mesh
// query (private to the narrowphase core). Everything here is inline: the query's inner
// loop calls it per node pair.

#include "kolize/narrowphase/bounding_volume.h"

#include "pose_internal.h"

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <cmath>
#include <limits>

namespace kolize::narrowphase::detail {

// ---------------------------------------------------------------------------------------
// Rounding and error bounds.
// ---------------------------------------------------------------------------------------

/// The largest float <= x.
inline float roundDown(double x) {
    float f = float(x);
    if (double(f) > x) {
        f = std::nextafter(f, -std::numeric_limits<float>::infinity());
    }
    return f;
}

/// The smallest float >= x.
inline float roundUp(double x) {
    float f = float(x);
    if (double(f) < x) {
        f = std::nextafter(f, std::numeric_limits<float>::infinity());
    }
    return f;
}

/// Fitting computes box coordinates in double with a relative error far below 2^-40 of the
/// point's distance from the centre (a 3x3 inverse and a product, about 1e-15); extents
/// get this much extra before rounding up to float.
constexpr double kFitSlack = 0x1p-40;

/// The float separating-axis test's error bound, relative to |D|_1 + the extent sums.
/// Covers the float products (a few 2^-24 each), the float rounding of orthonormal axes
/// (non-orthogonality ~2^-23) and a pose rotation orthonormal to 1e-6: 2^-16 = 1.5e-5 is
/// about ten times the sum.
constexpr float kObbSlack = 0x1p-16f;

/// Relative bound for double tests that use the pose rotation (non-orthonormal to 1e-6).
constexpr double kPoseSlack = 0x1p-18;

/// Largest accepted |R^T R - I| of a query's relative rotation.
constexpr double kMaxOrthonormalityError = 1e-6;

inline Vec3f crossFloat(const Vec3f& a, const Vec3f& b) {
    return Vec3f(a.y() * b.z() - a.z() * b.y(), a.z() * b.x() - a.x() * b.z(),
                 a.x() * b.y() - a.y() * b.x());
}

inline float dotFloat(const Vec3f& a, const Vec3f& b) {
    return (a.x() * b.x() + a.y() * b.y()) + a.z() * b.z();
}

// ---------------------------------------------------------------------------------------
// OBB against OBB.
// ---------------------------------------------------------------------------------------

/// An OBB moved into another frame: centre in double, axes rounded to float.
struct ObbInFrame {
    Vec3 center;
    Vec3f axis[3];
    Vec3f half;
    float radius;
    float extentSum;
};

inline ObbInFrame moveObb(const Obb& b, const Eigen::Matrix3d& r, const Vec3& t) {
    ObbInFrame out;
    out.center = applyFixedOrder(r, t, b.center.cast<double>());
    const Vec3f axes[3] = {b.axis0, b.axis1, b.axis2()};
    for (int j = 0; j < 3; ++j) {
        out.axis[j] = (r * axes[j].cast<double>()).cast<float>();
    }
    out.half = b.half;
    out.radius = b.radius;
    out.extentSum = (b.half.x() + b.half.y()) + b.half.z();
    return out;
}

/// Index of the separating axis: 0-2 a's faces, 3-5 b's faces, 6-14 edge pairs (3i + j).
constexpr int kNoAxis = 15;

/// Separating-axis test of a (in its frame, third axis a2 = a.axis2()) against b moved into
/// that frame; d = b.center - a.center in double. Returns the separating axis, or kNoAxis
/// when the boxes may overlap. `slack` is an absolute position error to add (the pose's
/// rounding). Tries `hint` first when it is a valid axis.
inline int obbSeparatingAxis(const Obb& a, const Vec3f& a2, const ObbInFrame& b, const Vec3& d,
                             float slack, int hint) {
    const Vec3f df = d.cast<float>();
    const float eps = kObbSlack * ((std::fabs(df.x()) + std::fabs(df.y()) + std::fabs(df.z())) +
                                   ((a.half.x() + a.half.y()) + a.half.z()) + b.extentSum) +
                      slack;
    const Vec3f* ax[3] = {&a.axis0, &a.axis1, &a2};
    const float ha[3] = {a.half.x(), a.half.y(), a.half.z()};
    const float hb[3] = {b.half.x(), b.half.y(), b.half.z()};
    float T[3], R[3][3], AR[3][3];
    auto row = [&](int i) {
        T[i] = dotFloat(*ax[i], df);
        for (int j = 0; j < 3; ++j) {
            R[i][j] = dotFloat(*ax[i], b.axis[j]);
            AR[i][j] = std::fabs(R[i][j]);
        }
    };
    auto faceA = [&](int i) {
        return std::fabs(T[i]) >
               ha[i] + ((hb[0] * AR[i][0] + hb[1] * AR[i][1]) + hb[2] * AR[i][2]) + eps;
    };
    auto faceB = [&](int j) {
        const float tb = dotFloat(b.axis[j], df);
        return std::fabs(tb) >
               hb[j] + ((ha[0] * AR[0][j] + ha[1] * AR[1][j]) + ha[2] * AR[2][j]) + eps;
    };
    // Edge axis a_i x b_j, with (i1, i2) and (j1, j2) the other two indices in cyclic order.
    auto edge = [&](int i, int j) {
        const int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
        const float lhs = std::fabs(T[i2] * R[i1][j] - T[i1] * R[i2][j]);
        const float rhs = (ha[i1] * AR[i2][j] + ha[i2] * AR[i1][j]) +
                          (hb[j1] * AR[i][j2] + hb[j2] * AR[i][j1]) + eps;
        return lhs > rhs;
    };
    auto test = [&](int axis) {
        return axis < 3   ? faceA(axis)
               : axis < 6 ? faceB(axis - 3)
                          : edge((axis - 6) / 3, (axis - 6) % 3);
    };
    if (hint < kNoAxis) {
        row(0);
        row(1);
        row(2);
        if (test(hint)) {
            return hint;
        }
    } else {
        for (int i = 0; i < 3; ++i) {
            row(i);
            if (faceA(i)) {
                return i;
            }
        }
    }
    for (int axis = hint < kNoAxis ? 0 : 3; axis < kNoAxis; ++axis) {
        if (axis != hint && test(axis)) {
            return axis;
        }
    }
    return kNoAxis;
}

// ---------------------------------------------------------------------------------------
// Spheres, in double.
// ---------------------------------------------------------------------------------------

/// Disjoint iff |d| > ra + rb (with the pose's slack), decided on squares without sqrt.
inline bool spheresDisjoint(const Vec3& d, double ra, double rb, double slack) {
    const double reach = (ra + rb) * (1.0 + kPoseSlack) + slack;
    return d.squaredNorm() > reach * reach * (1.0 + 0x1p-40);
}

// ---------------------------------------------------------------------------------------
// Model-space AABBs with the pose rotation (OPCODE's transformed box test), in double.
// ---------------------------------------------------------------------------------------

/// a: centre ca, half extents ea in a's frame; b: centre cb moved into a's frame, half
/// extents eb along b's axes; absR = |R| of the pose rotation. 15 axes, face axes first.
inline bool aabbsDisjoint(const Vec3& ca, const Vec3& ea, const Vec3& cb, const Vec3& eb,
                          const Eigen::Matrix3d& r, const Eigen::Matrix3d& absR, double slack) {
    const Vec3 t = cb - ca;
    const double eps = kPoseSlack * (t.cwiseAbs().sum() + ea.sum() + eb.sum()) + slack;
    for (int i = 0; i < 3; ++i) {
        const double rb = (absR(i, 0) * eb.x() + absR(i, 1) * eb.y()) + absR(i, 2) * eb.z();
        if (std::fabs(t[i]) > ea[i] + rb + eps) {
            return true;
        }
    }
    for (int j = 0; j < 3; ++j) {
        const double tb = (r(0, j) * t.x() + r(1, j) * t.y()) + r(2, j) * t.z();
        const double ra = (absR(0, j) * ea.x() + absR(1, j) * ea.y()) + absR(2, j) * ea.z();
        if (std::fabs(tb) > ra + eb[j] + eps) {
            return true;
        }
    }
    for (int i = 0; i < 3; ++i) {
        const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
        for (int j = 0; j < 3; ++j) {
            const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
            const double lhs = std::fabs(t[i2] * r(i1, j) - t[i1] * r(i2, j));
            const double rhs = (ea[i1] * absR(i2, j) + ea[i2] * absR(i1, j)) +
                               (eb[j1] * absR(i, j2) + eb[j2] * absR(i, j1)) + eps;
            if (lhs > rhs) {
                return true;
            }
        }
    }
    return false;
}

// ---------------------------------------------------------------------------------------
// k-DOPs.
// ---------------------------------------------------------------------------------------

template <int K>
inline bool kdopsDisjoint(const Kdop<K>& a, const Kdop<K>& b) {
    for (int i = 0; i < K / 2; ++i) {
        if (a.hi[i] < b.lo[i] || b.hi[i] < a.lo[i]) {
            return true;
        }
    }
    return false;
}

/// Accumulates points into a k-DOP in double with outward error bounds: d . x for integer
/// d in {-1, 0, 1}^3 costs at most two roundings, 2^-52 |x|_1 each.
template <int K>
struct KdopAccumulator {
    std::array<double, K / 2> lo, hi;
    KdopAccumulator() {
        lo.fill(std::numeric_limits<double>::infinity());
        hi.fill(-std::numeric_limits<double>::infinity());
    }
    void add(const Vec3& x) {
        const std::array<Eigen::Vector3i, K / 2>& dirs = kdopDirections<K>();
        const double error = 0x1p-50 * (std::fabs(x.x()) + std::fabs(x.y()) + std::fabs(x.z()));
        for (int i = 0; i < K / 2; ++i) {
            const double p = (dirs[i].x() * x.x() + dirs[i].y() * x.y()) + dirs[i].z() * x.z();
            lo[i] = std::min(lo[i], p - error);
            hi[i] = std::max(hi[i], p + error);
        }
    }
    Kdop<K> rounded() const {
        Kdop<K> out;
        for (int i = 0; i < K / 2; ++i) {
            out.lo[i] = roundDown(lo[i]);
            out.hi[i] = roundUp(hi[i]);
        }
        return out;
    }
};

template <int K>
inline void unite(Kdop<K>& into, const Kdop<K>& other) {
    for (int i = 0; i < K / 2; ++i) {
        into.lo[i] = std::min(into.lo[i], other.lo[i]);
        into.hi[i] = std::max(into.hi[i], other.hi[i]);
    }
}

// ---------------------------------------------------------------------------------------
// Fitting from a corner visitor (TriangleSpan::forEachCorner or the tree builder's).
// ---------------------------------------------------------------------------------------

template <class Corners>
Aabb fitAabbFrom(const Corners& corners) {
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
    Vec3 hi = -lo;
    corners([&](const Vec3& x) {
        lo = lo.cwiseMin(x);
        hi = hi.cwiseMax(x);
    });
    Aabb out;
    for (int k = 0; k < 3; ++k) {
        out.lo[k] = roundDown(lo[k]);
        out.hi[k] = roundUp(hi[k]);
    }
    return out;
}

/// Radius around a float centre containing every corner, rounded up.
template <class Corners>
float radiusAround(const Corners& corners, const Vec3f& centerFloat) {
    const Vec3 c = centerFloat.cast<double>();
    double r2 = 0;
    corners([&](const Vec3& x) { r2 = std::max(r2, (x - c).squaredNorm()); });
    return roundUp(std::sqrt(r2) * (1.0 + kFitSlack) + std::numeric_limits<double>::denorm_min());
}

template <class Corners>
Sphere fitSphereFrom(const Corners& corners) {
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
    Vec3 hi = -lo;
    Vec3 sum = Vec3::Zero();
    std::size_t n = 0;
    corners([&](const Vec3& x) {
        lo = lo.cwiseMin(x);
        hi = hi.cwiseMax(x);
        sum += x;
        ++n;
    });
    Sphere best;
    best.radius = std::numeric_limits<float>::infinity();
    for (const Vec3& c : {Vec3(0.5 * (lo + hi)), Vec3(sum / double(n))}) {
        const Vec3f cf = c.cast<float>();
        const float r = radiusAround(corners, cf);
        if (r < best.radius) {
            best = {cf, r};
        }
    }
    return best;
}

/// Extents along the float rounding of `axes` (columns), around the centre of the corners'
/// extents, each rounded up after kFitSlack of the corner's distance.
template <class Corners>
Obb fitObbFrom(const Corners& corners, const Eigen::Matrix3d& axes) {
    Obb out;
    out.axis0 = axes.col(0).cast<float>();
    out.axis1 = axes.col(1).cast<float>();
    Eigen::Matrix3d a;
    a.col(0) = out.axis0.cast<double>();
    a.col(1) = out.axis1.cast<double>();
    a.col(2) = out.axis2().cast<double>();
    // Coordinates in the (slightly non-orthonormal) float frame: u = a^-1 x.
    const Eigen::Matrix3d inverse = a.inverse();
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
    Vec3 hi = -lo;
    corners([&](const Vec3& x) {
        const Vec3 u = inverse * x;
        lo = lo.cwiseMin(u);
        hi = hi.cwiseMax(u);
    });
    out.center = (a * (0.5 * (lo + hi))).cast<float>();
    const Vec3 c = out.center.cast<double>();
    Vec3 half = Vec3::Zero();
    double farthest2 = 0;
    corners([&](const Vec3& x) {
        const Vec3 w = x - c;
        half = half.cwiseMax((inverse * w).cwiseAbs());
        farthest2 = std::max(farthest2, w.squaredNorm());
    });
    const double farthest = std::sqrt(farthest2);
    for (int k = 0; k < 3; ++k) {
        out.half[k] =
            roundUp(half[k] + kFitSlack * farthest + std::numeric_limits<double>::denorm_min());
    }
    out.radius = roundUp(farthest * (1.0 + kFitSlack) + std::numeric_limits<double>::denorm_min());
    return out;
}

template <int K, class Corners>
Kdop<K> fitKdopFrom(const Corners& corners) {
    KdopAccumulator<K> acc;
    corners([&](const Vec3& x) { acc.add(x); });
    return acc.rounded();
}

}  // namespace kolize::narrowphase::detail
