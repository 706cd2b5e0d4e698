#include "ccd_reference.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

namespace kolize::ccd::reference {
namespace {

// ---------------------------------------------------------------------------------------
// Polynomials over the rationals.
// ---------------------------------------------------------------------------------------

void trim(Poly& p) {
    while (!p.c.empty() && sgn(p.c.back()) == 0) {
        p.c.pop_back();
    }
}

Poly operator+(const Poly& a, const Poly& b) {
    Poly r;
    r.c.resize(std::max(a.c.size(), b.c.size()));
    for (size_t i = 0; i < r.c.size(); ++i) {
        r.c[i] = (i < a.c.size() ? a.c[i] : 0) + (i < b.c.size() ? b.c[i] : 0);
    }
    trim(r);
    return r;
}

Poly operator-(const Poly& a) {
    Poly r = a;
    for (mpq_class& x : r.c) {
        x = -x;
    }
    return r;
}

Poly operator-(const Poly& a, const Poly& b) {
    return a + (-b);
}

Poly operator*(const Poly& a, const Poly& b) {
    Poly r;
    if (a.isZero() || b.isZero()) {
        return r;
    }
    r.c.assign(a.c.size() + b.c.size() - 1, 0);
    for (size_t i = 0; i < a.c.size(); ++i) {
        for (size_t j = 0; j < b.c.size(); ++j) {
            r.c[i + j] += a.c[i] * b.c[j];
        }
    }
    trim(r);
    return r;
}

mpq_class eval(const Poly& p, const mpq_class& x) {
    mpq_class r = 0;
    for (size_t i = p.c.size(); i-- > 0;) {
        r = r * x + p.c[i];
    }
    return r;
}

int signAtRational(const Poly& p, const mpq_class& x) {
    return sgn(eval(p, x));
}

Poly derivative(const Poly& p) {
    Poly r;
    for (size_t i = 1; i < p.c.size(); ++i) {
        r.c.push_back(p.c[i] * static_cast<long>(i));
    }
    trim(r);
    return r;
}

/// a = q b + r with deg r < deg b (b not zero).
void divide(const Poly& a, const Poly& b, Poly& q, Poly& r) {
    assert(!b.isZero());
    r = a;
    q.c.assign(std::max(a.degree() - b.degree() + 1, 0), 0);
    while (!r.isZero() && r.degree() >= b.degree()) {
        const int shift = r.degree() - b.degree();
        const mpq_class f = r.c.back() / b.c.back();
        q.c[shift] = f;
        for (int i = 0; i <= b.degree(); ++i) {
            r.c[i + shift] -= f * b.c[i];
        }
        r.c.pop_back();  // cancelled exactly
        trim(r);
    }
    trim(q);
}

Poly remainder(const Poly& a, const Poly& b) {
    Poly q, r;
    divide(a, b, q, r);
    return r;
}

Poly quotient(const Poly& a, const Poly& b) {
    Poly q, r;
    divide(a, b, q, r);
    assert(r.isZero());
    return q;
}

/// Monic greatest common divisor (zero only if both are zero).
Poly gcd(Poly a, Poly b) {
    while (!b.isZero()) {
        Poly r = remainder(a, b);
        a = std::move(b);
        b = std::move(r);
    }
    if (!a.isZero()) {
        const mpq_class lead = a.c.back();
        for (mpq_class& x : a.c) {
            x /= lead;
        }
    }
    return a;
}

/// p divided by gcd(p, p'): the same roots, each simple.
Poly squarefree(const Poly& p) {
    const Poly g = gcd(p, derivative(p));
    return g.degree() <= 0 ? p : quotient(p, g);
}

/// Sturm sequence of a squarefree p: p, p', -rem, ...
std::vector<Poly> sturm(const Poly& p) {
    std::vector<Poly> s{p, derivative(p)};
    while (!s.back().isZero() && s.back().degree() > 0) {
        Poly r = remainder(s[s.size() - 2], s.back());
        if (r.isZero()) {
            break;
        }
        s.push_back(-r);
    }
    if (s.back().isZero()) {
        s.pop_back();
    }
    return s;
}

int variations(const std::vector<Poly>& s, const mpq_class& x) {
    int count = 0, last = 0;
    for (const Poly& p : s) {
        const int sign = signAtRational(p, x);
        if (sign != 0) {
            count += last != 0 && sign != last;
            last = sign;
        }
    }
    return count;
}

Algebraic rationalRoot(const mpq_class& x) {
    Algebraic a;
    a.value = x;
    return a;
}

/// Appends the roots of the squarefree p in (lo, hi]; vlo, vhi are the Sturm variations.
void isolate(const Poly& p, const std::vector<Poly>& s, const mpq_class& lo, int vlo,
             const mpq_class& hi, int vhi, std::vector<Algebraic>& out) {
    const int count = vlo - vhi;
    if (count <= 0) {
        return;
    }
    if (count == 1) {
        if (signAtRational(p, hi) == 0) {
            out.push_back(rationalRoot(hi));
            return;
        }
        if (signAtRational(p, lo) != 0) {
            Algebraic a;
            if (p.degree() == 1) {
                a.value = -p.c[0] / p.c[1];
            } else {
                a.rational = false;
                a.q = p;
                a.lo = lo;
                a.hi = hi;
            }
            out.push_back(std::move(a));
            return;
        }
    }
    const mpq_class mid = (lo + hi) / 2;
    const int vmid = variations(s, mid);
    isolate(p, s, lo, vlo, mid, vmid, out);
    isolate(p, s, mid, vmid, hi, vhi, out);
}

/// The real roots of the non-zero p in [a, b].
std::vector<Algebraic> roots(const Poly& p, const mpq_class& a, const mpq_class& b) {
    std::vector<Algebraic> out;
    if (p.degree() <= 0 || a > b) {
        return out;
    }
    if (p.degree() == 1) {  // one rational root
        const mpq_class r = -p.c[0] / p.c[1];
        if (a <= r && r <= b) {
            out.push_back(rationalRoot(r));
        }
        return out;
    }
    const Poly q = squarefree(p);
    if (signAtRational(q, a) == 0) {
        out.push_back(rationalRoot(a));
    }
    if (a < b) {
        const std::vector<Poly> s = sturm(q);
        isolate(q, s, a, variations(s, a), b, variations(s, b), out);
    }
    return out;
}

/// Halves x's interval (or finds x at the midpoint).
void bisect(Algebraic& x) {
    const mpq_class mid = (x.lo + x.hi) / 2;
    const int s = signAtRational(x.q, mid);
    if (s == 0) {
        x = rationalRoot(mid);
    } else if (s == signAtRational(x.q, x.lo)) {
        x.lo = mid;
    } else {
        x.hi = mid;
    }
}

/// Sign of g over [c - r, c + r] when its Taylor expansion at c proves it, else 2.
int taylorSign(const Poly& g, const mpq_class& c, const mpq_class& r) {
    // Taylor coefficients at c by repeated synthetic division.
    std::vector<mpq_class> a = g.c;
    const int n = g.degree();
    for (int k = 0; k < n; ++k) {
        for (int i = n - 1; i >= k; --i) {
            a[i] += c * a[i + 1];
        }
    }
    mpq_class rest = 0, power = 1;
    for (int k = 1; k <= n; ++k) {
        power *= r;
        rest += abs(a[k]) * power;
    }
    if (abs(a[0]) > rest) {
        return sgn(a[0]);
    }
    return 2;
}

// ---------------------------------------------------------------------------------------
// Moving points.
// ---------------------------------------------------------------------------------------

using PolyVec = std::array<Poly, 3>;

/// The point moving from x0 (t = 0) to x1 (t = 1).
PolyVec moving(const Vec3& x0, const Vec3& x1) {
    PolyVec r;
    for (int k = 0; k < 3; ++k) {
        const mpq_class a = exact(x0[k]), b = exact(x1[k]);
        r[k].c = {a, b - a};
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

/// A closed static test, written as signs of polynomials read at the candidate time; it
/// also lists every polynomial it may read (for the candidates of coplanar motion).
class SignTest {
  public:
    explicit SignTest(Algebraic* t) : t_(t) {}
    /// Collecting mode: records polynomials, reads no signs.
    SignTest() = default;
    int sign(const Poly& p) {
        if (!t_) {
            if (!p.isZero()) {
                listed_.push_back(p);
            }
            return 0;
        }
        return signAt(p, *t_);
    }
    bool collecting() const { return t_ == nullptr; }
    const std::vector<Poly>& listed() const { return listed_; }

  private:
    Algebraic* t_ = nullptr;
    std::vector<Poly> listed_;
};

/// x on the closed segment [y, z].
bool pointOnSegment(SignTest& s, const PolyVec& x, const PolyVec& y, const PolyVec& z) {
    const PolyVec e = z - y, d = x - y;
    bool on = true;
    for (const Poly& c : cross(e, d)) {
        on = s.sign(c) == 0 && on;
    }
    if (s.sign(dot(e, e)) > 0 || s.collecting()) {
        on = s.sign(dot(d, e)) >= 0 && s.sign(dot(x - z, y - z)) >= 0 && on;
        if (!s.collecting()) {
            return on;
        }
    }
    for (const Poly& c : d) {  // degenerate segment: x must be y
        on = s.sign(c) == 0 && on;
    }
    return on;
}

/// Vertex p in the closed triangle a, b, c, given that the four are coplanar.
bool vertexInTriangle(SignTest& s, const std::array<PolyVec, 4>& x) {
    const PolyVec &p = x[0], &a = x[1], &b = x[2], &c = x[3];
    const PolyVec n = cross(b - a, c - a);
    if (s.sign(dot(n, n)) > 0 || s.collecting()) {
        // Left of every directed edge, seen from n.
        const bool inside = s.sign(dot(n, cross(b - a, p - a))) >= 0 &&
                            s.sign(dot(n, cross(c - b, p - b))) >= 0 &&
                            s.sign(dot(n, cross(a - c, p - c))) >= 0;
        if (!s.collecting()) {
            return inside;
        }
    }
    // Degenerate triangle: the union of its three edges.
    bool on = pointOnSegment(s, p, a, b);
    on = pointOnSegment(s, p, b, c) || on;
    on = pointOnSegment(s, p, c, a) || on;
    return on;
}

/// Closed segments a0 a1 and b0 b1 meet, given that the four points are coplanar.
bool segmentsMeet(SignTest& s, const std::array<PolyVec, 4>& x) {
    const PolyVec &a0 = x[0], &a1 = x[1], &b0 = x[2], &b1 = x[3];
    const PolyVec ea = a1 - a0, eb = b1 - b0;
    const PolyVec n = cross(ea, eb);
    if (s.sign(dot(n, n)) > 0 || s.collecting()) {
        // Not parallel: each segment's ends lie on both sides of (or on) the other's line.
        const int s1 = s.sign(dot(n, cross(ea, b0 - a0)));
        const int s2 = s.sign(dot(n, cross(ea, b1 - a0)));
        const int s3 = s.sign(dot(n, cross(eb, a0 - b0)));
        const int s4 = s.sign(dot(n, cross(eb, a1 - b0)));
        if (!s.collecting()) {
            return s1 * s2 <= 0 && s3 * s4 <= 0;
        }
    }
    // Parallel or degenerate: they meet iff an end point lies on the other segment.
    bool on = pointOnSegment(s, a0, b0, b1);
    on = pointOnSegment(s, a1, b0, b1) || on;
    on = pointOnSegment(s, b0, a0, a1) || on;
    on = pointOnSegment(s, b1, a0, a1) || on;
    return on;
}

template <class StaticTest>
Decision decide(const std::array<PolyVec, 4>& x, const mpq_class& t_min, const mpq_class& t_max,
                StaticTest&& inside) {
    Decision d;
    const PolyVec &x0 = x[0], &x1 = x[1], &x2 = x[2], &x3 = x[3];
    // Coplanarity of the four points: det(x1 - x0, x2 - x0, x3 - x0).
    const Poly coplanar = dot(cross(x1 - x0, x2 - x0), x3 - x0);
    std::vector<Algebraic> candidates;
    if (!coplanar.isZero()) {
        candidates = roots(coplanar, t_min, t_max);
    } else {
        candidates.push_back(rationalRoot(t_min));
        SignTest collect;
        inside(collect, x);
        // Many listed polynomials agree up to a factor (components of the same products):
        // their roots are isolated once, and a rational candidate is tested once.
        std::vector<Poly> distinct;
        for (Poly p : collect.listed()) {
            if (p.degree() <= 0) {
                continue;
            }
            const mpq_class lead = p.c.back();
            for (mpq_class& c : p.c) {
                c /= lead;
            }
            if (std::none_of(distinct.begin(), distinct.end(),
                             [&](const Poly& o) { return o.c == p.c; })) {
                distinct.push_back(std::move(p));
            }
        }
        for (const Poly& p : distinct) {
            for (Algebraic& r : roots(p, t_min, t_max)) {
                const bool repeated =
                    r.rational &&
                    std::any_of(candidates.begin(), candidates.end(), [&](const Algebraic& o) {
                        return o.rational && o.value == r.value;
                    });
                if (!repeated) {
                    candidates.push_back(std::move(r));
                }
            }
        }
    }
    for (Algebraic& t : candidates) {
        SignTest test(&t);
        if (inside(test, x)) {
            d.contacts.push_back(t);
        }
    }
    return d;
}

std::array<PolyVec, 4> movingPoints(const std::array<Vec3, 4>& start,
                                    const std::array<Vec3, 4>& end) {
    std::array<PolyVec, 4> x;
    for (int i = 0; i < 4; ++i) {
        x[i] = moving(start[i], end[i]);
    }
    return x;
}

void checkRange(const mpq_class& t_min, const mpq_class& t_max) {
    if (t_min < 0 || t_max > 1 || t_min > t_max) {
        throw std::invalid_argument("reference: time range must satisfy 0 <= t_min <= t_max <= 1");
    }
}

}  // namespace

mpq_class exact(double x) {
    if (!std::isfinite(x)) {
        throw std::invalid_argument("reference: coordinates must be finite");
    }
    return mpq_class(x);  // mpq_set_d is exact
}

int signAt(const Poly& g, Algebraic& x) {
    if (g.isZero()) {
        return 0;
    }
    if (x.rational) {
        return signAtRational(g, x.value);
    }
    // g(x) = 0 iff x is a root of gcd(q, g), a squarefree divisor of q: its only possible
    // root in (lo, hi) is x, a simple one, so it changes sign there iff g(x) = 0.
    const Poly h = gcd(x.q, g);
    if (h.degree() >= 1 && signAtRational(h, x.lo) != signAtRational(h, x.hi)) {
        return 0;
    }
    // g(x) != 0: shrink the interval until g provably keeps one sign on it.
    while (true) {
        const int s = taylorSign(g, (x.lo + x.hi) / 2, (x.hi - x.lo) / 2);
        if (s != 2) {
            return s;
        }
        bisect(x);
        if (x.rational) {
            return signAtRational(g, x.value);
        }
    }
}

int compare(const mpq_class& r, Algebraic& x) {
    if (x.rational) {
        return sgn(r - x.value);
    }
    if (r <= x.lo) {
        return -1;
    }
    if (r >= x.hi) {
        return 1;
    }
    const int s = signAtRational(x.q, r);
    if (s == 0) {
        return 0;
    }
    return s == signAtRational(x.q, x.lo) ? -1 : 1;  // r in (lo, x) or in (x, hi)
}

double approximate(Algebraic& x) {
    while (!x.rational && x.hi - x.lo > mpq_class(1, 1ul << 62)) {
        bisect(x);
    }
    return x.rational ? x.value.get_d() : mpq_class((x.lo + x.hi) / 2).get_d();
}

bool Decision::atMostEarliest(const mpq_class& r) {
    assert(hit());
    for (Algebraic& t : contacts) {
        if (compare(r, t) > 0) {
            return false;
        }
    }
    return true;
}

bool Decision::atLeastEarliest(const mpq_class& r) {
    assert(hit());
    for (Algebraic& t : contacts) {
        if (compare(r, t) >= 0) {
            return true;
        }
    }
    return false;
}

double Decision::earliestApproximation() {
    double best = std::numeric_limits<double>::infinity();
    for (Algebraic& t : contacts) {
        best = std::min(best, approximate(t));
    }
    return best;
}

Decision vertexFace(const std::array<Vec3, 4>& start, const std::array<Vec3, 4>& end,
                    const mpq_class& t_min, const mpq_class& t_max) {
    checkRange(t_min, t_max);
    return decide(movingPoints(start, end), t_min, t_max, vertexInTriangle);
}

Decision edgeEdge(const std::array<Vec3, 4>& start, const std::array<Vec3, 4>& end,
                  const mpq_class& t_min, const mpq_class& t_max) {
    checkRange(t_min, t_max);
    return decide(movingPoints(start, end), t_min, t_max, segmentsMeet);
}

}  // namespace kolize::ccd::reference
