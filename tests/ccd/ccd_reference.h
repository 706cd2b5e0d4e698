#pragma once
// An independent exact reference for the CCD primitives, for tests only.
//
// It decides vertex-face and edge-edge contact of linearly moving closed primitives with
// GMP rationals (mpq_class), formulated on purpose differently from ccd_exact.cpp:
// - every contact time is a candidate of a finite set: the real roots of the exact
//   coplanarity polynomial when it is not identically zero; under coplanar motion, the
//   start of the range and the roots of *every* polynomial whose sign the static test reads
//   (the contact set is closed and its membership is constant between those roots, so its
//   earliest point is one of them);
// - roots are isolated by Sturm sequences with exact rational division on the squarefree
//   part, and kept as (squarefree polynomial, isolating interval) or an exact rational;
// - the static test at a candidate uses orientation signs: in-plane orientations of the
//   vertex against the triangle's edges (vertex-face), the two edges' endpoints against
//   each other's lines (edge-edge), point-on-segment tests for degenerate and parallel
//   cases; the sign of a polynomial g at an algebraic t* comes from gcd(q, g) (zero) or
//   from refining t*'s interval until a Taylor bound of g excludes zero.
// It is slow (tens of microseconds per query) and meant to be obviously right.
#include "kolize/narrowphase/ccd.h"

#include <gmpxx.h>

#include <string>
#include <vector>

namespace kolize::ccd::reference {

/// c[0] + c[1] t + ...; no trailing zero coefficient (the zero polynomial is empty).
struct Poly {
    std::vector<mpq_class> c;
    int degree() const { return static_cast<int>(c.size()) - 1; }
    bool isZero() const { return c.empty(); }
};

/// A real algebraic number: the rational `value` when `rational`, otherwise the only root of
/// the squarefree `q` in the open interval (lo, hi), where q(lo) and q(hi) are not zero.
struct Algebraic {
    bool rational = true;
    mpq_class value;
    Poly q;
    mpq_class lo, hi;
};

/// Sign (-1, 0, 1) of g at x.
int signAt(const Poly& g, Algebraic& x);
/// Sign of r - x for a rational r.
int compare(const mpq_class& r, Algebraic& x);
/// x to about double precision (for messages); narrows x's interval.
double approximate(Algebraic& x);

/// Every time in [t_min, t_max] at which the candidates are contacts; empty when the
/// primitives never touch in that range. The earliest contact is the smallest of them.
struct Decision {
    std::vector<Algebraic> contacts;
    bool hit() const { return !contacts.empty(); }
    /// r <= t* (the earliest contact); requires hit().
    bool atMostEarliest(const mpq_class& r);
    /// r >= t*; requires hit().
    bool atLeastEarliest(const mpq_class& r);
    /// t* as a double (for messages); requires hit().
    double earliestApproximation();
};

/// Vertex start[0] -> end[0] against the triangle start[1..3] -> end[1..3].
Decision vertexFace(const std::array<Vec3, 4>& start, const std::array<Vec3, 4>& end,
                    const mpq_class& t_min = 0, const mpq_class& t_max = 1);
/// Edge 0-1 against edge 2-3.
Decision edgeEdge(const std::array<Vec3, 4>& start, const std::array<Vec3, 4>& end,
                  const mpq_class& t_min = 0, const mpq_class& t_max = 1);

/// The double x exactly as a rational.
mpq_class exact(double x);

}  // namespace kolize::ccd::reference
