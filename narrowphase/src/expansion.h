#pragma once
// Floating-point expansion arithmetic (private to the narrowphase core).
//
// An expansion is an array of doubles, sorted by increasing magnitude, whose exact sum is
// the represented number and whose components do not overlap (Priest; Shewchuk, "Adaptive
// Precision Floating-Point Arithmetic and Fast Robust Geometric Predicates", 1997). The
// error-free transformations below (two-sum, two-product by Veltkamp/Dekker splitting) are
// exact under round-to-nearest-even as long as nothing overflows and no product falls into
// the subnormal range; callers check their inputs' range for that. The sign of a
// zero-eliminated expansion is the sign of its last (largest) component.
//
// The code relies on IEEE double operations exactly as written: the library is compiled
// with -ffp-contract=off and must never be built with -ffast-math.

#include <cassert>

namespace kolize::narrowphase::detail {

/// x + y = a + b exactly, x = fl(a + b).
inline void twoSum(double a, double b, double& x, double& y) {
    x = a + b;
    const double bVirtual = x - a;
    const double aVirtual = x - bVirtual;
    const double bRound = b - bVirtual;
    const double aRound = a - aVirtual;
    y = aRound + bRound;
}

/// x + y = a - b exactly, x = fl(a - b).
inline void twoDiff(double a, double b, double& x, double& y) {
    x = a - b;
    const double bVirtual = a - x;
    const double aVirtual = x + bVirtual;
    const double bRound = bVirtual - b;
    const double aRound = a - aVirtual;
    y = aRound + bRound;
}

/// a = hi + lo with hi and lo of at most 26 significant bits each.
inline void split(double a, double& hi, double& lo) {
    const double c = 134217729.0 * a;  // 2^27 + 1
    const double aBig = c - a;
    hi = c - aBig;
    lo = a - hi;
}

/// x + y = a * b exactly, x = fl(a * b).
inline void twoProduct(double a, double b, double& x, double& y) {
    x = a * b;
    double aHi, aLo, bHi, bLo;
    split(a, aHi, aLo);
    split(b, bHi, bLo);
    const double err1 = x - aHi * bHi;
    const double err2 = err1 - aLo * bHi;
    const double err3 = err2 - aHi * bLo;
    y = aLo * bLo - err3;
}

/// The expansion of a - b (1 or 2 components). Returns its length.
inline int differenceExpansion(double a, double b, double* h) {
    double x, y;
    twoDiff(a, b, x, y);
    int n = 0;
    if (y != 0.0) {
        h[n++] = y;
    }
    if (x != 0.0 || n == 0) {
        h[n++] = x;
    }
    return n;
}

/// h = e + f (zero-eliminated). h must hold elen + flen components and not alias e or f.
/// Returns h's length (at least 1; a single 0 for zero).
inline int expansionSum(int elen, const double* e, int flen, const double* f, double* h) {
    // Merge by increasing magnitude, then one chain of two-sums (Shewchuk's fast expansion
    // sum with two-sum in place of the first fast-two-sum, which is exact in any order).
    double g[256];
    assert(elen >= 1 && flen >= 1 && elen + flen <= 256);
    g[0] = 0.0;
    int i = 0, j = 0, n = 0;
    while (i < elen && j < flen) {
        const double ei = e[i], fj = f[j];
        if ((fj > ei) == (fj > -ei)) {  // |ei| < |fj|, or equal magnitudes
            g[n++] = ei;
            ++i;
        } else {
            g[n++] = fj;
            ++j;
        }
    }
    while (i < elen) {
        g[n++] = e[i++];
    }
    while (j < flen) {
        g[n++] = f[j++];
    }
    int hlen = 0;
    double q = g[0];
    for (int k = 1; k < n; ++k) {
        double sum, err;
        twoSum(q, g[k], sum, err);
        q = sum;
        if (err != 0.0) {
            h[hlen++] = err;
        }
    }
    if (q != 0.0 || hlen == 0) {
        h[hlen++] = q;
    }
    return hlen;
}

/// h = e * b (zero-eliminated). h must hold 2 * elen components. Returns h's length.
inline int scaleExpansion(int elen, const double* e, double b, double* h) {
    double q, err;
    twoProduct(e[0], b, q, err);
    int hlen = 0;
    if (err != 0.0) {
        h[hlen++] = err;
    }
    for (int i = 1; i < elen; ++i) {
        double productHi, productLo, sum;
        twoProduct(e[i], b, productHi, productLo);
        twoSum(q, productLo, sum, err);
        if (err != 0.0) {
            h[hlen++] = err;
        }
        // |sum| <= |productHi| up to rounding, so a two-sum keeps this exact in any order.
        twoSum(productHi, sum, q, err);
        if (err != 0.0) {
            h[hlen++] = err;
        }
    }
    if (q != 0.0 || hlen == 0) {
        h[hlen++] = q;
    }
    return hlen;
}

/// h = e * f. h must hold 2 * elen * flen components (at most 128 here). Returns h's length.
inline int multiplyExpansions(int elen, const double* e, int flen, const double* f, double* h) {
    double acc[128], part[128], next[128];
    assert(2 * elen * flen <= 128);
    int alen = scaleExpansion(elen, e, f[0], acc);
    for (int j = 1; j < flen; ++j) {
        const int plen = scaleExpansion(elen, e, f[j], part);
        alen = expansionSum(alen, acc, plen, part, next);
        for (int k = 0; k < alen; ++k) {
            acc[k] = next[k];
        }
    }
    for (int k = 0; k < alen; ++k) {
        h[k] = acc[k];
    }
    return alen;
}

/// Negates e in place.
inline void negate(int elen, double* e) {
    for (int i = 0; i < elen; ++i) {
        e[i] = -e[i];
    }
}

/// Sign of a zero-eliminated expansion.
inline int sign(int elen, const double* e) {
    const double top = e[elen - 1];
    return top > 0.0 ? 1 : (top < 0.0 ? -1 : 0);
}

}  // namespace kolize::narrowphase::detail
