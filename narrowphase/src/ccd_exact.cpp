#include "ccd_exact.h"

#include <gmpxx.h>

#include <algorithm>
#include <optional>
#include <utility>
#include <vector>

// Why this decomposition is complete. Every vertex moves linearly, so every quantity below
// is a polynomial in t with rational coefficients (the inputs are doubles, hence dyadic
// rationals, and GMP holds them exactly).
//
// * Touching needs the four points coplanar: the coplanarity cubic c(t) vanishes. If c is
//   not identically zero, every contact time is one of its (at most 3) real roots, and the
//   static closed test at each root decides.
// * If c vanishes identically (coplanar motion), the earliest contact in [a, b] is a or a
//   time where contact *begins*. Contact of a vertex with the relative interior of a
//   non-degenerate triangle, or of two non-parallel edges crossing at interior points, is
//   open in time while the motion stays coplanar, so it cannot begin at t > a: contact
//   begins on a closed edge -- a vertex reaching an edge's line (a common root of the
//   components of (p - x) x (y - x), unless they vanish identically, in which case the
//   vertex can only enter the edge through an end point) or a vertex meeting a vertex (a
//   common root of the components of p - x). Those times, and a, are the candidates.
//
// The static test at a candidate time t* evaluates the signs of polynomials at t*. A
// candidate is rational or the only root of a squarefree polynomial p in a rational interval
// (Sturm sequences isolate the roots). The sign of g(t*) is zero exactly when
// gcd(p, g mod p) has its root in the interval; otherwise the interval is halved until the
// Bernstein coefficients of g mod p on it share one strict sign.

namespace kolize::ccd::detail {
namespace {

using Rational = mpq_class;

/// c[0] + c[1] t + ... + c[d] t^d with c[d] != 0; no coefficients: the zero polynomial.
struct Poly {
    std::vector<Rational> c;
    int degree() const { return static_cast<int>(c.size()) - 1; }
    bool isZero() const { return c.empty(); }
};

void trim(Poly& p) {
    while (!p.c.empty() && sgn(p.c.back()) == 0) {
        p.c.pop_back();
    }
}

Poly operator+(const Poly& a, const Poly& b) {
    Poly r;
    r.c.resize(std::max(a.c.size(), b.c.size()));
    for (size_t i = 0; i < r.c.size(); ++i) {
        if (i < a.c.size()) {
            r.c[i] += a.c[i];
        }
        if (i < b.c.size()) {
            r.c[i] += b.c[i];
        }
    }
    trim(r);
    return r;
}

Poly operator-(const Poly& a, const Poly& b) {
    Poly r;
    r.c.resize(std::max(a.c.size(), b.c.size()));
    for (size_t i = 0; i < r.c.size(); ++i) {
        if (i < a.c.size()) {
            r.c[i] += a.c[i];
        }
        if (i < b.c.size()) {
            r.c[i] -= b.c[i];
        }
    }
    trim(r);
    return r;
}

Poly operator*(const Poly& a, const Poly& b) {
    Poly r;
    if (a.isZero() || b.isZero()) {
        return r;
    }
    r.c.resize(a.c.size() + b.c.size() - 1);
    for (size_t i = 0; i < a.c.size(); ++i) {
        for (size_t j = 0; j < b.c.size(); ++j) {
            r.c[i + j] += a.c[i] * b.c[j];
        }
    }
    return r;  // The leading coefficient is a product of non-zero rationals.
}

Rational eval(const Poly& p, const Rational& t) {
    Rational r;
    for (int i = p.degree(); i >= 0; --i) {
        r = r * t + p.c[i];
    }
    return r;
}

int signAt(const Poly& p, const Rational& t) {
    return p.isZero() ? 0 : sgn(eval(p, t));
}

Poly derivative(const Poly& p) {
    Poly r;
    for (int i = 1; i <= p.degree(); ++i) {
        r.c.push_back(p.c[i] * i);
    }
    return r;
}

/// Remainder of a divided by the non-zero b; the quotient too when asked.
Poly divide(Poly a, const Poly& b, Poly* quotient = nullptr) {
    const int db = b.degree();
    if (quotient) {
        quotient->c.assign(std::max(a.degree() - db + 1, 0), Rational(0));
    }
    while (a.degree() >= db) {
        const int shift = a.degree() - db;
        const Rational factor = a.c.back() / b.c.back();
        for (int i = 0; i <= db; ++i) {
            a.c[i + shift] -= factor * b.c[i];
        }
        if (quotient) {
            quotient->c[shift] = factor;
        }
        a.c.pop_back();  // Cancelled exactly.
        trim(a);
    }
    return a;
}

/// Monic greatest common divisor; gcd(0, 0) = 0.
Poly gcd(Poly a, Poly b) {
    while (!b.isZero()) {
        Poly r = divide(a, b);
        a = std::move(b);
        b = std::move(r);
    }
    if (!a.isZero()) {
        const Rational lead = a.c.back();
        for (Rational& x : a.c) {
            x /= lead;
        }
    }
    return a;
}

/// p divided by gcd(p, p'): the same roots, each simple. p is not constant.
Poly squarefree(const Poly& p) {
    const Poly g = gcd(p, derivative(p));
    if (g.degree() <= 0) {
        return p;
    }
    Poly q;
    divide(p, g, &q);
    return q;
}

/// Sign of g on [lo, hi] when its Bernstein coefficients there share one strict sign (then
/// g has no root in the interval), else 0.
int signOnInterval(const Poly& g, const Rational& lo, const Rational& hi) {
    const int n = g.degree();
    // Taylor coefficients at lo scaled to s in [0, 1]: g(lo + w s) = sum a_k s^k.
    std::vector<Rational> a(g.c);
    for (int k = 0; k < n; ++k) {
        for (int i = n - 1; i >= k; --i) {
            a[i] += lo * a[i + 1];
        }
    }
    const Rational w = hi - lo;
    Rational scale = 1;
    for (int k = 1; k <= n; ++k) {
        scale *= w;
        a[k] *= scale;
    }
    // Bernstein coefficients b_i = sum_{k <= i} C(i, k) / C(n, k) a_k.
    int sign = 0;
    for (int i = 0; i <= n; ++i) {
        Rational b;
        Rational ratio = 1;  // C(i, k) / C(n, k)
        for (int k = 0; k <= i; ++k) {
            b += ratio * a[k];
            if (k < i) {
                ratio = ratio * (i - k) / (n - k);
            }
        }
        const int s = sgn(b);
        if (s == 0 || (sign != 0 && s != sign)) {
            return 0;
        }
        sign = s;
    }
    return sign;
}

/// A time t*: the rational `lo` when `exact`, otherwise the only root of the squarefree
/// polynomial `p` in the open interval (lo, hi), where p(lo) and p(hi) are not zero.
struct Time {
    Poly p;
    Rational lo, hi;
    bool exact = true;
    int sign_lo = 0;  ///< sign of p(lo) when not exact

    static Time at(const Rational& t) {
        Time r;
        r.lo = r.hi = t;
        return r;
    }

    /// Halves the interval, or finds t* exactly at its midpoint.
    void bisect() {
        Rational m = (lo + hi) / 2;
        const int s = signAt(p, m);
        if (s == 0) {
            lo = hi = m;
            exact = true;
        } else if (s == sign_lo) {
            lo = std::move(m);
        } else {
            hi = std::move(m);
        }
    }

    void refine(const Rational& width) {
        while (!exact && hi - lo > width) {
            bisect();
        }
    }

    /// Sign of g(t*), exact.
    int sign(const Poly& g) {
        if (exact) {
            return signAt(g, lo);
        }
        const Poly r = divide(g, p);  // r(t*) = g(t*) as p(t*) = 0
        if (r.degree() <= 0) {
            return r.isZero() ? 0 : sgn(r.c[0]);
        }
        const Poly h = gcd(p, r);
        // h divides p, so its roots are simple roots of p and t* is the only one in (lo, hi).
        if (h.degree() >= 1 && signAt(h, lo) != signAt(h, hi)) {
            return 0;
        }
        for (;;) {  // r(t*) != 0: terminates once the interval is small enough.
            if (exact) {
                return signAt(r, lo);
            }
            if (const int s = signOnInterval(r, lo, hi)) {
                return s;
            }
            bisect();
        }
    }
};

/// Sturm sequence of the squarefree p and its sign variations at a rational.
class Sturm {
  public:
    explicit Sturm(const Poly& p) {
        seq_.push_back(p);
        seq_.push_back(derivative(p));
        while (seq_.back().degree() > 0) {
            Poly r = divide(seq_[seq_.size() - 2], seq_.back());
            if (r.isZero()) {
                break;
            }
            for (Rational& x : r.c) {
                x = -x;
            }
            seq_.push_back(std::move(r));
        }
    }
    int variations(const Rational& t) const {
        int count = 0, last = 0;
        for (const Poly& s : seq_) {
            const int sign = signAt(s, t);
            if (sign != 0) {
                count += last != 0 && sign != last;
                last = sign;
            }
        }
        return count;
    }

  private:
    std::vector<Poly> seq_;
};

/// Appends the roots of p in (lo, hi] (vlo, vhi: Sturm variations at lo, hi), ascending.
void isolate(const Poly& p, const Sturm& sturm, const Rational& lo, int vlo, const Rational& hi,
             int vhi, std::vector<Time>& out) {
    const int count = vlo - vhi;  // Sturm: roots in (lo, hi], for any lo < hi
    if (count == 0) {
        return;
    }
    if (count == 1) {
        if (signAt(p, hi) == 0) {
            out.push_back(Time::at(hi));
            return;
        }
        if (const int s = signAt(p, lo)) {
            Time t;
            t.p = p;
            t.lo = lo;
            t.hi = hi;
            t.exact = false;
            t.sign_lo = s;
            out.push_back(std::move(t));
            return;
        }
    }
    const Rational mid = (lo + hi) / 2;
    const int vmid = sturm.variations(mid);
    isolate(p, sturm, lo, vlo, mid, vmid, out);
    isolate(p, sturm, mid, vmid, hi, vhi, out);
}

/// Real roots of the non-constant p in [a, b], ascending, each once.
std::vector<Time> roots(const Poly& events, const Rational& a, const Rational& b) {
    std::vector<Time> out;
    const Poly p = squarefree(events);
    if (p.degree() == 1) {
        const Rational t = -p.c[0] / p.c[1];
        if (a <= t && t <= b) {
            out.push_back(Time::at(t));
        }
        return out;
    }
    if (signAt(p, a) == 0) {
        out.push_back(Time::at(a));
    }
    if (a < b) {
        const Sturm sturm(p);
        isolate(p, sturm, a, sturm.variations(a), b, sturm.variations(b), out);
    }
    return out;
}

using PolyVec = std::array<Poly, 3>;

PolyVec motion(const Vec3& x0, const Vec3& x1) {
    PolyVec r;
    for (int k = 0; k < 3; ++k) {
        r[k].c = {Rational(x0[k]), Rational(x1[k]) - Rational(x0[k])};
        trim(r[k]);
    }
    return r;
}

PolyVec operator-(const PolyVec& a, const PolyVec& b) {
    return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}

PolyVec cross(const PolyVec& a, const PolyVec& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

Poly dot(const PolyVec& a, const PolyVec& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

Poly gcd3(const PolyVec& v) {
    return gcd(gcd(v[0], v[1]), v[2]);
}

/// A vertex x against the closed segment [y, z] (static test at one time).
struct PointSegment {
    PolyVec q;     ///< x - y
    PolyVec line;  ///< (x - y) x (z - y): zero when x is on the segment's line
    Poly ee, qe;   ///< |z - y|^2 and (x - y) . (z - y)

    PointSegment(const PolyVec& x, const PolyVec& y, const PolyVec& z) : q(x - y) {
        const PolyVec e = z - y;
        line = cross(q, e);
        ee = dot(e, e);
        qe = dot(q, e);
    }
    bool touches(Time& t) const {
        for (const Poly& l : line) {
            if (t.sign(l) != 0) {
                return false;
            }
        }
        if (t.sign(ee) == 0) {  // Degenerate segment: x must be its point.
            for (const Poly& d : q) {
                if (t.sign(d) != 0) {
                    return false;
                }
            }
            return true;
        }
        return t.sign(qe) >= 0 && t.sign(ee - qe) >= 0;
    }
};

/// Keeps the earliest contact over several candidate times.
class Earliest {
  public:
    Earliest(double a, double b, double tolerance) : a_(a), limit_(b), width_(tolerance) {}

    const Rational& begin() const { return a_; }
    /// Contacts after this time cannot be the earliest.
    const Rational& limit() const { return limit_; }

    /// Tests the candidates (roots of `events` in [a, limit], or a alone when `events` is
    /// identically zero) in ascending order; keeps the first that `touches`.
    template <class Touches>
    void consider(const Poly& events, Touches&& touches) {
        if (events.degree() == 0) {
            return;
        }
        std::vector<Time> times;
        if (events.isZero()) {
            times.push_back(Time::at(a_));
        } else {
            times = roots(events, a_, limit_);
        }
        for (Time& t : times) {
            if (touches(t)) {
                t.refine(width_);
                if (!found_ || t.lo < best_lo_) {
                    best_lo_ = t.lo;
                }
                if (!found_ || t.hi < limit_) {
                    limit_ = t.hi;
                }
                found_ = true;
                return;
            }
        }
    }

    ExactContact result() const {
        ExactContact r;
        r.hit = found_;
        if (found_) {
            // mpq_get_d truncates towards zero: a double no later than best_lo_ >= 0.
            r.toi = best_lo_.get_d();
        }
        return r;
    }

  private:
    Rational a_, limit_, width_, best_lo_;
    bool found_ = false;
};

/// Candidates of coplanar motion: a, vertex-on-edge-line and vertex-on-vertex events.
template <class Touches>
void considerCoplanarMotion(Earliest& earliest, const std::vector<PointSegment>& pairs,
                            const std::vector<PolyVec>& vertex_offsets, Touches&& touches) {
    earliest.consider(Poly{}, touches);
    for (const PointSegment& ps : pairs) {
        const Poly events = gcd3(ps.line);
        if (!events.isZero()) {  // Identically on the line: enters through an end point.
            earliest.consider(events, touches);
        }
    }
    for (const PolyVec& d : vertex_offsets) {
        earliest.consider(gcd3(d), touches);
    }
}

}  // namespace

ExactContact vertexFaceExact(const std::array<Vec3, 4>& start, const std::array<Vec3, 4>& end,
                             double t_lo, double t_hi, double toi_tolerance) {
    const PolyVec p = motion(start[0], end[0]), a = motion(start[1], end[1]),
                  b = motion(start[2], end[2]), c = motion(start[3], end[3]);
    const PolyVec q = p - a, e1 = b - a, e2 = c - a;
    const PolyVec n = cross(e1, e2);
    const Poly coplanar = dot(n, q);
    const Poly nn = dot(n, n);
    const Poly u = dot(cross(q, e2), n), v = dot(cross(e1, q), n);  // barycentrics times nn
    const Poly w = nn - u - v;
    const std::vector<PointSegment> edges{{p, a, b}, {p, b, c}, {p, c, a}};
    auto touches = [&](Time& t) {
        // Called only where p is in the triangle's plane.
        if (t.sign(nn) > 0) {
            return t.sign(u) >= 0 && t.sign(v) >= 0 && t.sign(w) >= 0;
        }
        // Degenerate triangle: a segment (or a point), the union of its edges.
        for (const PointSegment& edge : edges) {
            if (edge.touches(t)) {
                return true;
            }
        }
        return false;
    };
    Earliest earliest(t_lo, t_hi, toi_tolerance);
    if (!coplanar.isZero()) {
        earliest.consider(coplanar, touches);
    } else {
        considerCoplanarMotion(earliest, edges, {p - a, p - b, p - c}, touches);
    }
    return earliest.result();
}

ExactContact edgeEdgeExact(const std::array<Vec3, 4>& start, const std::array<Vec3, 4>& end,
                           double t_lo, double t_hi, double toi_tolerance) {
    const PolyVec a0 = motion(start[0], end[0]), a1 = motion(start[1], end[1]),
                  b0 = motion(start[2], end[2]), b1 = motion(start[3], end[3]);
    const PolyVec ea = a1 - a0, eb = b1 - b0, r = b0 - a0;
    const PolyVec n = cross(ea, eb);
    const Poly coplanar = dot(n, r);
    const Poly nn = dot(n, n);
    // Where coplanar and not parallel: a0 + s ea = b0 + w eb with s = sa / nn, w = sb / nn.
    const Poly sa = dot(cross(r, eb), n), sb = dot(cross(r, ea), n);
    const Poly sa_rest = nn - sa, sb_rest = nn - sb;
    const std::vector<PointSegment> ends{{a0, b0, b1}, {a1, b0, b1}, {b0, a0, a1}, {b1, a0, a1}};
    auto touches = [&](Time& t) {
        // Called only where the edges are coplanar.
        if (t.sign(nn) > 0) {
            return t.sign(sa) >= 0 && t.sign(sa_rest) >= 0 && t.sign(sb) >= 0 &&
                   t.sign(sb_rest) >= 0;
        }
        // Parallel or degenerate: they touch iff an end point lies on the other edge.
        for (const PointSegment& end_point : ends) {
            if (end_point.touches(t)) {
                return true;
            }
        }
        return false;
    };
    Earliest earliest(t_lo, t_hi, toi_tolerance);
    if (!coplanar.isZero()) {
        earliest.consider(coplanar, touches);
    } else {
        considerCoplanarMotion(earliest, ends, {a0 - b0, a0 - b1, a1 - b0, a1 - b1}, touches);
    }
    return earliest.result();
}

}  // namespace kolize::ccd::detail
