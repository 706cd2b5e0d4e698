#pragma once
// Bounding-volume arithmetic shared by the public functions, the tree builder and the mesh
// query (private to the narrowphase core). Everything here is inline: the query's inner
// loop calls it per node pair.

#include "kolize/narrowphase/bounding_volume.h"

#include "pose_internal.h"

#include <Eigen/Geometry>
#include <Eigen/LU>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <cmath>
#include <cstdint>
#include <cstring>
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

/// An OBB moved into another frame: centre in double, axes rounded to float and stored
/// transposed (bt[k][j] is coordinate k of axis j, lane 3 zero), ready for SSE rows.
struct alignas(16) ObbInFrame {
    float bt[3][4];
    float hb[4];  // half extents, lane 3 zero
    Vec3 center;
    float radius;
    float extentSum;

    Vec3f axis(int j) const { return Vec3f(bt[0][j], bt[1][j], bt[2][j]); }
    /// A tag kept in lane 3 of bt[0], which no test reads: the query's stamp of the entry,
    /// on the same cache line as the data it validates.
    std::uint32_t tag() const {
        std::uint32_t t;
        std::memcpy(&t, &bt[0][3], sizeof t);
        return t;
    }
    void setTag(std::uint32_t t) { std::memcpy(&bt[0][3], &t, sizeof t); }
};

inline ObbInFrame moveObb(const Obb& b, const Eigen::Matrix3d& r, const Vec3& t) {
    ObbInFrame out;
    out.center = applyFixedOrder(r, t, b.center.cast<double>());
    const Vec3f axes[3] = {b.axis0, b.axis1, crossFloat(b.axis0, b.axis1)};
    for (int j = 0; j < 3; ++j) {
        const double x = axes[j].x(), y = axes[j].y(), z = axes[j].z();
        for (int i = 0; i < 3; ++i) {
            out.bt[i][j] = float((r(i, 0) * x + r(i, 1) * y) + r(i, 2) * z);
        }
    }
    for (int i = 0; i < 3; ++i) {
        out.bt[i][3] = 0.0f;
        out.hb[i] = b.half[i];
    }
    out.hb[3] = 0.0f;
    out.radius = b.radius;
    out.extentSum = (b.half.x() + b.half.y()) + b.half.z();
    return out;
}

/// Index of the separating axis: 0-2 a's faces, 3-5 b's faces, 6-14 edge pairs (3i + j).
constexpr int kNoAxis = 15;

/// The quantities of one box pair in a's frame: T = a's axes . d, R = a's axes . b's axes.
struct SatFrame {
    float T[3], R[3][3], AR[3][3], ha[3], hb[3], eps;
};

/// Axis `axis` (see kNoAxis) separates the boxes.
inline bool separatesOn(const SatFrame& f, int axis) {
    const float(&T)[3] = f.T;
    const float(&R)[3][3] = f.R;
    const float(&AR)[3][3] = f.AR;
    const float(&ha)[3] = f.ha;
    const float(&hb)[3] = f.hb;
    switch (axis) {
        case 0:
        case 1:
        case 2: {
            const int i = axis;
            return std::fabs(T[i]) >
                   ha[i] + ((hb[0] * AR[i][0] + hb[1] * AR[i][1]) + hb[2] * AR[i][2]) + f.eps;
        }
        case 3:
        case 4:
        case 5: {
            const int j = axis - 3;
            const float tb = (T[0] * R[0][j] + T[1] * R[1][j]) + T[2] * R[2][j];
            return std::fabs(tb) >
                   hb[j] + ((ha[0] * AR[0][j] + ha[1] * AR[1][j]) + ha[2] * AR[2][j]) + f.eps;
        }
        case 6:  // a0 x b0
            return std::fabs(T[2] * R[1][0] - T[1] * R[2][0]) >
                   ha[1] * AR[2][0] + ha[2] * AR[1][0] + hb[1] * AR[0][2] + hb[2] * AR[0][1] +
                       f.eps;
        case 7:  // a0 x b1
            return std::fabs(T[2] * R[1][1] - T[1] * R[2][1]) >
                   ha[1] * AR[2][1] + ha[2] * AR[1][1] + hb[0] * AR[0][2] + hb[2] * AR[0][0] +
                       f.eps;
        case 8:  // a0 x b2
            return std::fabs(T[2] * R[1][2] - T[1] * R[2][2]) >
                   ha[1] * AR[2][2] + ha[2] * AR[1][2] + hb[0] * AR[0][1] + hb[1] * AR[0][0] +
                       f.eps;
        case 9:  // a1 x b0
            return std::fabs(T[0] * R[2][0] - T[2] * R[0][0]) >
                   ha[0] * AR[2][0] + ha[2] * AR[0][0] + hb[1] * AR[1][2] + hb[2] * AR[1][1] +
                       f.eps;
        case 10:  // a1 x b1
            return std::fabs(T[0] * R[2][1] - T[2] * R[0][1]) >
                   ha[0] * AR[2][1] + ha[2] * AR[0][1] + hb[0] * AR[1][2] + hb[2] * AR[1][0] +
                       f.eps;
        case 11:  // a1 x b2
            return std::fabs(T[0] * R[2][2] - T[2] * R[0][2]) >
                   ha[0] * AR[2][2] + ha[2] * AR[0][2] + hb[0] * AR[1][1] + hb[1] * AR[1][0] +
                       f.eps;
        case 12:  // a2 x b0
            return std::fabs(T[1] * R[0][0] - T[0] * R[1][0]) >
                   ha[0] * AR[1][0] + ha[1] * AR[0][0] + hb[1] * AR[2][2] + hb[2] * AR[2][1] +
                       f.eps;
        case 13:  // a2 x b1
            return std::fabs(T[1] * R[0][1] - T[0] * R[1][1]) >
                   ha[0] * AR[1][1] + ha[1] * AR[0][1] + hb[0] * AR[2][2] + hb[2] * AR[2][0] +
                       f.eps;
        case 14:  // a2 x b2
            return std::fabs(T[1] * R[0][2] - T[0] * R[1][2]) >
                   ha[0] * AR[1][2] + ha[1] * AR[0][2] + hb[0] * AR[2][1] + hb[1] * AR[2][0] +
                       f.eps;
        default:
            return false;
    }
}

/// Separating-axis test of a (in its frame, third axis a2 = a.axis2()) against b moved into
/// that frame; d = b.center - a.center in double. Returns the separating axis, or kNoAxis
/// when the boxes may overlap. `slack` is an absolute position error to add (the pose's
/// rounding). Tries `hint` first when it is a valid axis. B's face axes use T and R in a's
/// frame (T . R_j), which assumes a's axes orthonormal: their float rounding is inside eps.
inline int obbSeparatingAxisScalar(const Obb& a, const Vec3f& a2, const ObbInFrame& b, double ddx,
                                   double ddy, double ddz, float slack, int hint) {
    SatFrame f;
    const float dx = float(ddx), dy = float(ddy), dz = float(ddz);
    f.ha[0] = a.half.x();
    f.ha[1] = a.half.y();
    f.ha[2] = a.half.z();
    f.hb[0] = b.hb[0];
    f.hb[1] = b.hb[1];
    f.hb[2] = b.hb[2];
    f.eps = kObbSlack * ((std::fabs(dx) + std::fabs(dy) + std::fabs(dz)) +
                         ((f.ha[0] + f.ha[1]) + f.ha[2]) + b.extentSum) +
            slack;
    const Vec3f* ax[3] = {&a.axis0, &a.axis1, &a2};
    auto row = [&](int i) {
        const Vec3f& u = *ax[i];
        f.T[i] = (u.x() * dx + u.y() * dy) + u.z() * dz;
        for (int j = 0; j < 3; ++j) {
            f.R[i][j] = dotFloat(u, b.axis(j));
            f.AR[i][j] = std::fabs(f.R[i][j]);
        }
    };
    if (hint < kNoAxis) {
        row(0);
        row(1);
        row(2);
        if (separatesOn(f, hint)) {
            return hint;
        }
    } else {
        // Most pairs that reach this test are separated by one of a's face axes: compute
        // each row of R only when its axis is tested.
        row(0);
        if (separatesOn(f, 0))
            return 0;
        row(1);
        if (separatesOn(f, 1))
            return 1;
        row(2);
        if (separatesOn(f, 2))
            return 2;
    }
    // Spelled out so that each call's switch folds away: face axes, then edges.
    if (hint < kNoAxis) {
        if (separatesOn(f, 0))
            return 0;
        if (separatesOn(f, 1))
            return 1;
        if (separatesOn(f, 2))
            return 2;
    }
    if (separatesOn(f, 3))
        return 3;
    if (separatesOn(f, 4))
        return 4;
    if (separatesOn(f, 5))
        return 5;
    if (separatesOn(f, 6))
        return 6;
    if (separatesOn(f, 7))
        return 7;
    if (separatesOn(f, 8))
        return 8;
    if (separatesOn(f, 9))
        return 9;
    if (separatesOn(f, 10))
        return 10;
    if (separatesOn(f, 11))
        return 11;
    if (separatesOn(f, 12))
        return 12;
    if (separatesOn(f, 13))
        return 13;
    if (separatesOn(f, 14))
        return 14;
    return kNoAxis;
}

#if defined(__SSE2__)
/// The same test in SSE2, three axes per comparison: a's face axes, b's face axes, then the
/// edge axes a_i x b_j for i = 0, 1, 2. The same float operations up to their order, within
/// the same error bound eps. 68% of the box tests in a traversal find no separating axis
/// (measured, HUMAN and Wuson), so the full 15-axis cost is what matters.
inline int obbSeparatingAxisSse(const Obb& a, const ObbInFrame& b, double ddx, double ddy,
                                double ddz, float slack, int hint) {
    const float dx = float(ddx), dy = float(ddy), dz = float(ddz);
    const __m128 signBit = _mm_set1_ps(-0.0f);
    auto abs = [&](__m128 x) { return _mm_andnot_ps(signBit, x); };
#define KOLIZE_SPLAT(v, i) _mm_shuffle_ps(v, v, _MM_SHUFFLE(i, i, i, i))
#define KOLIZE_YZX(v) _mm_shuffle_ps(v, v, _MM_SHUFFLE(3, 0, 2, 1))
#define KOLIZE_ZXY(v) _mm_shuffle_ps(v, v, _MM_SHUFFLE(3, 1, 0, 2))
    __m128 ax = _mm_setr_ps(a.axis0.x(), a.axis0.y(), a.axis0.z(), 0.0f);
    __m128 ay = _mm_setr_ps(a.axis1.x(), a.axis1.y(), a.axis1.z(), 0.0f);
    // a2 = a0 x a1 lane by lane exactly as crossFloat: (y0 z1 - z0 y1, z0 x1 - x0 z1, ...).
    __m128 az = _mm_sub_ps(_mm_mul_ps(KOLIZE_YZX(ax), KOLIZE_ZXY(ay)),
                           _mm_mul_ps(KOLIZE_ZXY(ax), KOLIZE_YZX(ay)));
    __m128 aw = _mm_setzero_ps();
    _MM_TRANSPOSE4_PS(ax, ay, az, aw);  // now ax = (a0.x, a1.x, a2.x, 0), ...
    const __m128 T =
        _mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_set1_ps(dx), ax), _mm_mul_ps(_mm_set1_ps(dy), ay)),
                   _mm_mul_ps(_mm_set1_ps(dz), az));
    const __m128 bx = _mm_load_ps(b.bt[0]), by = _mm_load_ps(b.bt[1]), bz = _mm_load_ps(b.bt[2]);
    auto column = [&](__m128 x, __m128 y, __m128 z) {  // (a_i . b_j) over i
        return _mm_add_ps(_mm_add_ps(_mm_mul_ps(x, ax), _mm_mul_ps(y, ay)), _mm_mul_ps(z, az));
    };
    __m128 c0 = column(KOLIZE_SPLAT(bx, 0), KOLIZE_SPLAT(by, 0), KOLIZE_SPLAT(bz, 0));
    __m128 c1 = column(KOLIZE_SPLAT(bx, 1), KOLIZE_SPLAT(by, 1), KOLIZE_SPLAT(bz, 1));
    __m128 c2 = column(KOLIZE_SPLAT(bx, 2), KOLIZE_SPLAT(by, 2), KOLIZE_SPLAT(bz, 2));
    const __m128 ha = _mm_setr_ps(a.half.x(), a.half.y(), a.half.z(), 0.0f);
    const __m128 hb = _mm_load_ps(b.hb);
    const float epsScalar = kObbSlack * ((std::fabs(dx) + std::fabs(dy) + std::fabs(dz)) +
                                         ((a.half.x() + a.half.y()) + a.half.z()) + b.extentSum) +
                            slack;
    const __m128 eps = _mm_set1_ps(epsScalar);
    auto faceA = [&] {
        const __m128 rb = _mm_add_ps(_mm_add_ps(_mm_mul_ps(KOLIZE_SPLAT(hb, 0), abs(c0)),
                                                _mm_mul_ps(KOLIZE_SPLAT(hb, 1), abs(c1))),
                                     _mm_mul_ps(KOLIZE_SPLAT(hb, 2), abs(c2)));
        return _mm_movemask_ps(_mm_cmpgt_ps(abs(T), _mm_add_ps(_mm_add_ps(ha, rb), eps))) & 7;
    };
    // Rows of R (over j), from the columns.
    __m128 r0 = c0, r1 = c1, r2 = c2, r3 = _mm_setzero_ps();
    bool rows = false;
    auto makeRows = [&] {
        if (!rows) {
            _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
            rows = true;
        }
    };
    auto faceB = [&] {
        makeRows();
        const __m128 tb = _mm_add_ps(
            _mm_add_ps(_mm_mul_ps(KOLIZE_SPLAT(T, 0), r0), _mm_mul_ps(KOLIZE_SPLAT(T, 1), r1)),
            _mm_mul_ps(KOLIZE_SPLAT(T, 2), r2));
        const __m128 ra = _mm_add_ps(_mm_add_ps(_mm_mul_ps(KOLIZE_SPLAT(ha, 0), abs(r0)),
                                                _mm_mul_ps(KOLIZE_SPLAT(ha, 1), abs(r1))),
                                     _mm_mul_ps(KOLIZE_SPLAT(ha, 2), abs(r2)));
        return _mm_movemask_ps(_mm_cmpgt_ps(abs(tb), _mm_add_ps(_mm_add_ps(hb, ra), eps))) & 7;
    };
    const __m128 hbNext = KOLIZE_YZX(hb), hbAfter = KOLIZE_ZXY(hb);  // hb[j+1], hb[j+2]
    // Edge axes a_i x b_j over j, with (i1, i2) the other two of a's axes in cyclic order.
    auto edges = [&](__m128 ri, __m128 ri1, __m128 ri2, __m128 ti1, __m128 ti2, __m128 hai1,
                     __m128 hai2) {
        const __m128 lhs = abs(_mm_sub_ps(_mm_mul_ps(ti2, ri1), _mm_mul_ps(ti1, ri2)));
        const __m128 ari = abs(ri);
        const __m128 rhs = _mm_add_ps(
            _mm_add_ps(_mm_add_ps(_mm_mul_ps(hai1, abs(ri2)), _mm_mul_ps(hai2, abs(ri1))),
                       _mm_add_ps(_mm_mul_ps(hbNext, KOLIZE_ZXY(ari)),
                                  _mm_mul_ps(hbAfter, KOLIZE_YZX(ari)))),
            eps);
        return _mm_movemask_ps(_mm_cmpgt_ps(lhs, rhs)) & 7;
    };
    auto group = [&](int g) {
        switch (g) {
            case 0:
                return faceA();
            case 1:
                return faceB();
            case 2:
                makeRows();
                return edges(r0, r1, r2, KOLIZE_SPLAT(T, 1), KOLIZE_SPLAT(T, 2),
                             KOLIZE_SPLAT(ha, 1), KOLIZE_SPLAT(ha, 2));
            case 3:
                makeRows();
                return edges(r1, r2, r0, KOLIZE_SPLAT(T, 2), KOLIZE_SPLAT(T, 0),
                             KOLIZE_SPLAT(ha, 2), KOLIZE_SPLAT(ha, 0));
            default:
                makeRows();
                return edges(r2, r0, r1, KOLIZE_SPLAT(T, 0), KOLIZE_SPLAT(T, 1),
                             KOLIZE_SPLAT(ha, 0), KOLIZE_SPLAT(ha, 1));
        }
    };
#undef KOLIZE_SPLAT
#undef KOLIZE_YZX
#undef KOLIZE_ZXY
    const int first = hint < kNoAxis ? hint / 3 : -1;
    if (first >= 0) {
        if (const int mask = group(first)) {
            return 3 * first + __builtin_ctz(unsigned(mask));
        }
    }
    for (int g = 0; g < 5; ++g) {
        if (g == first) {
            continue;
        }
        if (const int mask = group(g)) {
            return 3 * g + __builtin_ctz(unsigned(mask));
        }
    }
    return kNoAxis;
}
#endif

/// The separating-axis test used everywhere: SSE2 where available, else scalar.
inline int obbSeparatingAxis(const Obb& a, const Vec3f& a2, const ObbInFrame& b, double dx,
                             double dy, double dz, float slack, int hint) {
#if defined(__SSE2__)
    (void)a2;
    return obbSeparatingAxisSse(a, b, dx, dy, dz, slack, hint);
#else
    return obbSeparatingAxisScalar(a, a2, b, dx, dy, dz, slack, hint);
#endif
}

// ---------------------------------------------------------------------------------------
// Spheres, in double.
// ---------------------------------------------------------------------------------------

/// Disjoint iff |d| > ra + rb (with the pose's slack), decided on squares without sqrt.
inline bool spheresDisjoint(double dx, double dy, double dz, double ra, double rb, double slack) {
    const double reach = (ra + rb) * (1.0 + kPoseSlack) + slack;
    return (dx * dx + dy * dy) + dz * dz > reach * reach * (1.0 + 0x1p-40);
}
inline bool spheresDisjoint(const Vec3& d, double ra, double rb, double slack) {
    return spheresDisjoint(d.x(), d.y(), d.z(), ra, rb, slack);
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
