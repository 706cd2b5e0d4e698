#include "kolize/narrowphase/predicates.h"

#include "expansion.h"
#include "predicates_internal.h"

#include <gmp.h>

#include <cmath>

namespace kolize::narrowphase {

void PredicateStats::add(const PredicateStats& other) {
    for (int s = 0; s < 3; ++s) {
        orient2d[s] += other.orient2d[s];
        orient3d[s] += other.orient3d[s];
    }
}

std::uint64_t PredicateStats::calls() const {
    return orient2d[0] + orient2d[1] + orient2d[2] + orient3d[0] + orient3d[1] + orient3d[2];
}

std::uint64_t PredicateStats::fallbacks() const {
    return orient2d[1] + orient2d[2] + orient3d[1] + orient3d[2];
}

namespace detail {
namespace {

// ---------------------------------------------------------------------------------------
// Stage 1: filters.
// ---------------------------------------------------------------------------------------

std::optional<int> orient3dFilter(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
    const PlaneSide plane(a, b, c);
    // PlaneSide::side falls through to the exact stages; here only the filter's verdict is
    // wanted, so redo its arithmetic.
    const Vec3 n = plane.normal();
    const double dx = d.x() - a.x(), dy = d.y() - a.y(), dz = d.z() - a.z();
    const double bx = b.x() - a.x(), by = b.y() - a.y(), bz = b.z() - a.z();
    const double cx = c.x() - a.x(), cy = c.y() - a.y(), cz = c.z() - a.z();
    const double det = (dx * n.x() + dy * n.y()) + dz * n.z();
    const double adx = std::fabs(dx), ady = std::fabs(dy), adz = std::fabs(dz);
    const double permanent = (adx * (std::fabs(by * cz) + std::fabs(bz * cy)) +
                              ady * (std::fabs(bz * cx) + std::fabs(bx * cz))) +
                             adz * (std::fabs(bx * cy) + std::fabs(by * cx));
    const double bound = kOrient3dBound * permanent + kUnderflowGuard * (1.0 + adx + ady + adz);
    if (det > bound) {
        return 1;
    }
    if (-det > bound) {
        return -1;
    }
    return std::nullopt;
}

std::optional<int> orient2dFilter(double ax, double ay, double bx, double by, double cx,
                                  double cy) {
    const double left = (bx - ax) * (cy - ay);
    const double right = (by - ay) * (cx - ax);
    const double det = left - right;
    const double bound = kOrient2dBound * (std::fabs(left) + std::fabs(right)) + kUnderflowGuard;
    if (det > bound) {
        return 1;
    }
    if (-det > bound) {
        return -1;
    }
    return std::nullopt;
}

// ---------------------------------------------------------------------------------------
// Stage 2: exact expansions.
// ---------------------------------------------------------------------------------------

/// Nonzero coordinates in [2^-256, 2^256] keep every expansion component a multiple of
/// 2^-924 (differences are multiples of 2^-308, products of three of them of 2^-924) and
/// below 2^800, so every two-sum and two-product is exact: no underflow, no overflow.
bool inExpansionRange(double x) {
    const double m = std::fabs(x);
    return m == 0.0 || (m >= 0x1p-256 && m <= 0x1p256);
}

/// a * b - c * d for 2-component-or-less expansions; h holds 16.
int crossTerm(int alen, const double* a, int blen, const double* b, int clen, const double* c,
              int dlen, const double* d, double* h) {
    double ab[8], cd[8];
    const int ablen = multiplyExpansions(alen, a, blen, b, ab);
    const int cdlen = multiplyExpansions(clen, c, dlen, d, cd);
    negate(cdlen, cd);
    return expansionSum(ablen, ab, cdlen, cd, h);
}

/// Exact sign of det[x, y, z] for double vectors (every product exact by two-product).
/// Straight-line: each 2x2 minor is a 4-term expansion, each term 8, the sum at most 24.
int determinantSign(const double x[3], const double y[3], const double z[3]) {
    double terms[3][8];
    int lengths[3];
    for (int k = 0; k < 3; ++k) {
        const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
        double p1, p0, q1, q0;
        twoProduct(y[k1], z[k2], p1, p0);
        twoProduct(y[k2], z[k1], q1, q0);
        const double left[2] = {p0, p1}, right[2] = {-q0, -q1};
        double minor[4];
        const int minorLength = expansionSum(2, left, 2, right, minor);
        lengths[k] = scaleExpansion(minorLength, minor, x[k], terms[k]);
    }
    double partial[16], total[24];
    const int partialLength = expansionSum(lengths[0], terms[0], lengths[1], terms[1], partial);
    const int totalLength = expansionSum(partialLength, partial, lengths[2], terms[2], total);
    return sign(totalLength, total);
}

std::optional<int> orient3dExpansion(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
    for (const Vec3* p : {&a, &b, &c, &d}) {
        for (int k = 0; k < 3; ++k) {
            if (!inExpansionRange((*p)[k])) {
                return std::nullopt;
            }
        }
    }
    // x = b - a, y = c - a, z = d - a, each coordinate an exact expansion of length <= 2;
    // det = x . (y cross z).
    double x[3][2], y[3][2], z[3][2];
    int xl[3], yl[3], zl[3];
    bool exactDifferences = true;
    for (int k = 0; k < 3; ++k) {
        xl[k] = differenceExpansion(b[k], a[k], x[k]);
        yl[k] = differenceExpansion(c[k], a[k], y[k]);
        zl[k] = differenceExpansion(d[k], a[k], z[k]);
        exactDifferences = exactDifferences && xl[k] == 1 && yl[k] == 1 && zl[k] == 1;
    }
    if (exactDifferences) {
        // Float-derived data (a mesh on its own copy, shifted by a power of two): every
        // difference is a double, and the short fixed-size path decides.
        const double xs[3] = {x[0][0], x[1][0], x[2][0]};
        const double ys[3] = {y[0][0], y[1][0], y[2][0]};
        const double zs[3] = {z[0][0], z[1][0], z[2][0]};
        return determinantSign(xs, ys, zs);
    }
    double total[192];
    int totalLength = 1;
    total[0] = 0.0;
    for (int k = 0; k < 3; ++k) {
        const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
        double minor[16], term[64], next[192];
        const int minorLength =
            crossTerm(yl[k1], y[k1], zl[k2], z[k2], yl[k2], y[k2], zl[k1], z[k1], minor);
        const int termLength = multiplyExpansions(minorLength, minor, xl[k], x[k], term);
        totalLength = expansionSum(totalLength, total, termLength, term, next);
        for (int i = 0; i < totalLength; ++i) {
            total[i] = next[i];
        }
    }
    return sign(totalLength, total);
}

std::optional<int> orient2dExpansion(double ax, double ay, double bx, double by, double cx,
                                     double cy) {
    for (double v : {ax, ay, bx, by, cx, cy}) {
        if (!inExpansionRange(v)) {
            return std::nullopt;
        }
    }
    double ux[2], uy[2], vx[2], vy[2], det[16];
    const int uxl = differenceExpansion(bx, ax, ux), uyl = differenceExpansion(by, ay, uy);
    const int vxl = differenceExpansion(cx, ax, vx), vyl = differenceExpansion(cy, ay, vy);
    if (uxl == 1 && uyl == 1 && vxl == 1 && vyl == 1) {
        double p1, p0, q1, q0;
        twoProduct(ux[0], vy[0], p1, p0);
        twoProduct(uy[0], vx[0], q1, q0);
        const double left[2] = {p0, p1}, right[2] = {-q0, -q1};
        const int length = expansionSum(2, left, 2, right, det);
        return sign(length, det);
    }
    const int length = crossTerm(uxl, ux, vyl, vy, uyl, uy, vxl, vx, det);
    return sign(length, det);
}

// ---------------------------------------------------------------------------------------
// Stage 3: GMP rationals (every finite double is a dyadic rational, set exactly).
// ---------------------------------------------------------------------------------------

class Rational {
  public:
    Rational() { mpq_init(value_); }
    explicit Rational(double x) {
        mpq_init(value_);
        mpq_set_d(value_, x);
    }
    ~Rational() { mpq_clear(value_); }
    Rational(const Rational&) = delete;
    Rational& operator=(const Rational&) = delete;
    mpq_ptr get() { return value_; }

  private:
    mpq_t value_;
};

int orient3dGmp(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
    Rational x[3], y[3], z[3];
    for (int k = 0; k < 3; ++k) {
        Rational ak(a[k]), bk(b[k]), ck(c[k]), dk(d[k]);
        mpq_sub(x[k].get(), bk.get(), ak.get());
        mpq_sub(y[k].get(), ck.get(), ak.get());
        mpq_sub(z[k].get(), dk.get(), ak.get());
    }
    Rational total, left, right, term;
    for (int k = 0; k < 3; ++k) {
        const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
        mpq_mul(left.get(), y[k1].get(), z[k2].get());
        mpq_mul(right.get(), y[k2].get(), z[k1].get());
        mpq_sub(left.get(), left.get(), right.get());
        mpq_mul(term.get(), left.get(), x[k].get());
        mpq_add(total.get(), total.get(), term.get());
    }
    return mpq_sgn(total.get());
}

int orient2dGmp(double ax, double ay, double bx, double by, double cx, double cy) {
    Rational a0(ax), a1(ay), b0(bx), b1(by), c0(cx), c1(cy), u0, u1, v0, v1, left, right;
    mpq_sub(u0.get(), b0.get(), a0.get());
    mpq_sub(u1.get(), b1.get(), a1.get());
    mpq_sub(v0.get(), c0.get(), a0.get());
    mpq_sub(v1.get(), c1.get(), a1.get());
    mpq_mul(left.get(), u0.get(), v1.get());
    mpq_mul(right.get(), u1.get(), v0.get());
    mpq_sub(left.get(), left.get(), right.get());
    return mpq_sgn(left.get());
}

}  // namespace

int orient3dExact(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d,
                  PredicateStats* stats) {
    // Two equal points make the determinant exactly zero (a mesh against its own copy
    // shares every vertex): decided without exact arithmetic, counted with the filter.
    if (d == a || d == b || d == c || a == b || a == c || b == c) {
        if (stats != nullptr) {
            ++stats->orient3d[0];
        }
        return 0;
    }
    // Four points sharing one coordinate lie in a plane normal to that axis: zero, also
    // without exact arithmetic (the touching faces of axis-aligned boxes, a mesh moved
    // along or turned about one of its axes).
    for (int k = 0; k < 3; ++k) {
        if (a[k] == b[k] && a[k] == c[k] && a[k] == d[k]) {
            if (stats != nullptr) {
                ++stats->orient3d[0];
            }
            return 0;
        }
    }
    if (const std::optional<int> s = orient3dExpansion(a, b, c, d)) {
        if (stats != nullptr) {
            ++stats->orient3d[1];
        }
        return *s;
    }
    if (stats != nullptr) {
        ++stats->orient3d[2];
    }
    return orient3dGmp(a, b, c, d);
}

int orient2dExact(double ax, double ay, double bx, double by, double cx, double cy,
                  PredicateStats* stats) {
    if ((ax == bx && ay == by) || (ax == cx && ay == cy) || (bx == cx && by == cy)) {
        if (stats != nullptr) {
            ++stats->orient2d[0];
        }
        return 0;
    }
    if (const std::optional<int> s = orient2dExpansion(ax, ay, bx, by, cx, cy)) {
        if (stats != nullptr) {
            ++stats->orient2d[1];
        }
        return *s;
    }
    if (stats != nullptr) {
        ++stats->orient2d[2];
    }
    return orient2dGmp(ax, ay, bx, by, cx, cy);
}

}  // namespace detail

int orient3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, PredicateStats* stats) {
    return detail::PlaneSide(a, b, c).side(d, stats);
}

int orient2d(double ax, double ay, double bx, double by, double cx, double cy,
             PredicateStats* stats) {
    const double left = (bx - ax) * (cy - ay);
    const double right = (by - ay) * (cx - ax);
    const double det = left - right;
    const double bound =
        detail::kOrient2dBound * (std::fabs(left) + std::fabs(right)) + detail::kUnderflowGuard;
    if (det > bound || -det > bound) {
        if (stats != nullptr) {
            ++stats->orient2d[0];
        }
        return det > 0.0 ? 1 : -1;
    }
    return detail::orient2dExact(ax, ay, bx, by, cx, cy, stats);
}

std::optional<int> orient3dAt(PredicateStage stage, const Vec3& a, const Vec3& b, const Vec3& c,
                              const Vec3& d) {
    switch (stage) {
        case PredicateStage::kFilter:
            return detail::orient3dFilter(a, b, c, d);
        case PredicateStage::kExpansion:
            return detail::orient3dExpansion(a, b, c, d);
        case PredicateStage::kGmp:
            return detail::orient3dGmp(a, b, c, d);
    }
    return std::nullopt;
}

std::optional<int> orient2dAt(PredicateStage stage, double ax, double ay, double bx, double by,
                              double cx, double cy) {
    switch (stage) {
        case PredicateStage::kFilter:
            return detail::orient2dFilter(ax, ay, bx, by, cx, cy);
        case PredicateStage::kExpansion:
            return detail::orient2dExpansion(ax, ay, bx, by, cx, cy);
        case PredicateStage::kGmp:
            return detail::orient2dGmp(ax, ay, bx, by, cx, cy);
    }
    return std::nullopt;
}

}  // namespace kolize::narrowphase
