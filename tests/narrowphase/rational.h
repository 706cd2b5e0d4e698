#pragma once
// Independent exact references for the narrowphase tests, in GMP rationals (mpq_class).
// They share no code with the library: determinants by their definition, and triangle
// intersection as the feasibility of a small linear program, decided by enumerating its
// basic solutions.

#include <kolize/narrowphase/predicates.h>
#include <kolize/narrowphase/triangle_test.h>

#include <gmpxx.h>

#include <array>
#include <vector>

namespace kolize::narrowphase::testing {

using RationalPoint = std::array<mpq_class, 3>;

inline RationalPoint rational(const Vec3& x) {
    return {mpq_class(x.x()), mpq_class(x.y()), mpq_class(x.z())};
}

/// Sign of ((b - a) x (c - a)) . (d - a), by the definition.
inline int rationalOrient3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
    const RationalPoint A = rational(a), B = rational(b), C = rational(c), D = rational(d);
    mpq_class u[3], v[3], w[3];
    for (int k = 0; k < 3; ++k) {
        u[k] = B[k] - A[k];
        v[k] = C[k] - A[k];
        w[k] = D[k] - A[k];
    }
    const mpq_class n0 = u[1] * v[2] - u[2] * v[1];
    const mpq_class n1 = u[2] * v[0] - u[0] * v[2];
    const mpq_class n2 = u[0] * v[1] - u[1] * v[0];
    const mpq_class det = n0 * w[0] + n1 * w[1] + n2 * w[2];
    return sgn(det);
}

/// Sign of (b - a) x (c - a) in 2D.
inline int rationalOrient2d(double ax, double ay, double bx, double by, double cx, double cy) {
    const mpq_class det = (mpq_class(bx) - mpq_class(ax)) * (mpq_class(cy) - mpq_class(ay)) -
                          (mpq_class(by) - mpq_class(ay)) * (mpq_class(cx) - mpq_class(ax));
    return sgn(det);
}

/// Closed triangles p and q meet iff some convex combination of p's vertices equals one of
/// q's: {x >= 0 : A x = b} with x = (lambda_0..2, mu_0..2), rows sum(lambda) = 1,
/// sum(mu) = 1 and sum(lambda_i p_i) - sum(mu_j q_j) = 0. A nonempty polyhedron in this
/// form has a basic feasible solution, so trying every basis decides it exactly.
inline bool rationalTrianglesIntersect(const Triangle& p, const Triangle& q) {
    constexpr int kRows = 5, kCols = 6;
    mpq_class a[kRows][kCols + 1];  // augmented with b
    for (int j = 0; j < 3; ++j) {
        a[0][j] = 1;
        a[0][3 + j] = 0;
        a[1][j] = 0;
        a[1][3 + j] = 1;
        const RationalPoint pj = rational(p[j]), qj = rational(q[j]);
        for (int k = 0; k < 3; ++k) {
            a[2 + k][j] = pj[k];
            a[2 + k][3 + j] = -qj[k];
        }
    }
    a[0][kCols] = 1;
    a[1][kCols] = 1;
    for (int k = 0; k < 3; ++k) {
        a[2 + k][kCols] = 0;
    }
    // Row-reduce [A | b] to find independent rows; an inconsistent system has no solution.
    mpq_class r[kRows][kCols + 1];
    for (int i = 0; i < kRows; ++i) {
        for (int j = 0; j <= kCols; ++j) {
            r[i][j] = a[i][j];
        }
    }
    int rank = 0;
    for (int col = 0; col < kCols && rank < kRows; ++col) {
        int pivot = -1;
        for (int i = rank; i < kRows; ++i) {
            if (sgn(r[i][col]) != 0) {
                pivot = i;
                break;
            }
        }
        if (pivot < 0) {
            continue;
        }
        for (int j = 0; j <= kCols; ++j) {
            std::swap(r[rank][j], r[pivot][j]);
        }
        for (int i = 0; i < kRows; ++i) {
            if (i != rank && sgn(r[i][col]) != 0) {
                const mpq_class f = r[i][col] / r[rank][col];
                for (int j = 0; j <= kCols; ++j) {
                    r[i][j] -= f * r[rank][j];
                }
            }
        }
        ++rank;
    }
    for (int i = rank; i < kRows; ++i) {
        if (sgn(r[i][kCols]) != 0) {
            return false;  // 0 = nonzero
        }
    }
    // The first `rank` rows of r span the same system. Try every set of `rank` columns.
    std::vector<int> cols(rank);
    for (int mask = 0; mask < (1 << kCols); ++mask) {
        if (__builtin_popcount(mask) != rank) {
            continue;
        }
        int n = 0;
        for (int j = 0; j < kCols; ++j) {
            if (mask & (1 << j)) {
                cols[n++] = j;
            }
        }
        mpq_class m[kRows][kRows + 1];
        for (int i = 0; i < rank; ++i) {
            for (int k = 0; k < rank; ++k) {
                m[i][k] = r[i][cols[k]];
            }
            m[i][rank] = r[i][kCols];
        }
        bool singular = false;
        for (int col = 0; col < rank && !singular; ++col) {
            int pivot = -1;
            for (int i = col; i < rank; ++i) {
                if (sgn(m[i][col]) != 0) {
                    pivot = i;
                    break;
                }
            }
            if (pivot < 0) {
                singular = true;
                break;
            }
            for (int k = 0; k <= rank; ++k) {
                std::swap(m[col][k], m[pivot][k]);
            }
            for (int i = 0; i < rank; ++i) {
                if (i != col && sgn(m[i][col]) != 0) {
                    const mpq_class f = m[i][col] / m[col][col];
                    for (int k = 0; k <= rank; ++k) {
                        m[i][k] -= f * m[col][k];
                    }
                }
            }
        }
        if (singular) {
            continue;
        }
        bool nonnegative = true;
        for (int i = 0; i < rank && nonnegative; ++i) {
            nonnegative = sgn(m[i][rank] / m[i][i]) >= 0;
        }
        if (nonnegative) {
            return true;
        }
    }
    return false;
}

}  // namespace kolize::narrowphase::testing
