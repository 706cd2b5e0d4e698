#include "ccd_certified.h"

#include <algorithm>
#include <cmath>
#include <string_view>

// The method. Contact needs the four points coplanar: c(t) = det(x1 - x0, x2 - x0, x3 - x0)
// (vertex-face: x0 = a, the others b, c, p; edge-edge: x0 = a0, then a1, b0, b1) vanishes.
// The three difference vectors move linearly, so on a time interval [alpha, beta] the cubic
// c has the Bernstein coefficients of the blossom: c(alpha), the two mixed sums of three
// determinants of the vectors at alpha and beta, c(beta) -- only the vectors at the two ends
// are needed. Likewise every in-plane orientation (a 2D cross product of two moving vectors
// in a coordinate projection) is a quadratic with Bernstein coefficients from the ends.
// Signs of Bernstein coefficients bound a polynomial's sign over the interval, and their
// variations bound its roots there (Descartes), so on [alpha, beta]:
//   - c's coefficients certainly of one sign: never coplanar, no contact;
//   - an orientation certifying "outside" (vertex-face: the projected normal of one sign and
//     the vertex on the other side of an edge; edge-edge: both ends of one edge strictly on
//     one side of the other's line) over the whole interval: no contact at any coplanar time;
//   - c changing sign exactly once (certain coefficients, one variation): the only coplanar
//     time t* is bracketed; after narrowing the bracket to the tolerance, strictly "inside"
//     orientations over it prove a contact at t* (in a projection where the vertex is strictly
//     inside the projected triangle, or the projected edges cross properly, the projection is
//     one to one on the common plane at t*, so the 3D primitives touch there).
// Intervals are examined from the left, split in halves while undecided, within a budget;
// what no certificate decides goes to the exact stage from the first undecided time on.
//
// Error bounds. Coordinates are first turned into difference vectors (x_i - x_0 at t = 0
// and t = 1, one rounding each: relative error u = 2^-53), then every axis is scaled by a
// power of two so its largest difference lies in [1, 2): exact, and it makes the bounds
// below absolute constants (subnormal results of the scaling err by at most 2^-1075, which
// the absolute slack kEta covers). Every later value is a fixed expression of those, so its
// error has a constant bound, computed at compile time by the Bound algebra below (each
// product or sum adds its own rounding, u times a bound on the computed magnitude, plus
// kEta for underflow). A sign is certain when |value| exceeds its bound. Only certain signs
// are used; everything else answers "undecided", which is always safe.

namespace kolize::ccd::detail {
namespace {

/// Absolute slack per operation: covers underflow (at most 2^-1075 per rounding).
constexpr double kEta = 0x1p-1000;

// ---------------------------------------------------------------------------------------
// Double-double numbers (hi + lo, |lo| <= ulp(hi) / 2) for the second pass: the same
// certificates with errors about 2^-100 relative instead of 2^-50, which settles near misses
// down to ~1e-25 of the scene without exact arithmetic. Exact TwoSum, and Dekker's
// TwoProduct (no FMA needed; exact while |x| < 2^996, the scaled values are below 4); the
// sum is Joldes, Muller and Popescu's AccurateDWPlusDW (relative error below 3u^2 + 13u^3,
// u = 2^-53), the products DWTimesDW1 and its DW-times-double form (below 7u^2; ACM TOMS
// 44(2), 2017). Every operation is charged 16u^2 = 2^-102 (CRlibm's bound for Mul22).
// ---------------------------------------------------------------------------------------

struct DD {
    double hi = 0.0, lo = 0.0;
};

DD twoSum(double a, double b) {
    const double s = a + b, bb = s - a;
    return {s, (a - (s - bb)) + (b - bb)};
}

DD fastTwoSum(double a, double b) {  // |a| >= |b|
    const double s = a + b;
    return {s, b - (s - a)};
}

DD twoProduct(double a, double b) {
    constexpr double kSplit = 134217729.0;  // 2^27 + 1
    const double p = a * b;
    const double ca = kSplit * a, cb = kSplit * b;
    const double ah = ca - (ca - a), al = a - ah, bh = cb - (cb - b), bl = b - bh;
    return {p, ((ah * bh - p) + ah * bl + al * bh) + al * bl};
}

DD operator+(const DD& a, const DD& b) {
    const DD s = twoSum(a.hi, b.hi), t = twoSum(a.lo, b.lo);
    DD r = fastTwoSum(s.hi, s.lo + t.hi);
    return fastTwoSum(r.hi, r.lo + t.lo);
}

DD operator-(const DD& a) {
    return {-a.hi, -a.lo};
}

DD operator-(const DD& a, const DD& b) {
    return a + (-b);
}

DD operator*(const DD& a, const DD& b) {
    const DD c = twoProduct(a.hi, b.hi);
    return fastTwoSum(c.hi, c.lo + (a.hi * b.lo + a.lo * b.hi));
}

DD operator*(double t, const DD& b) {
    const DD c = twoProduct(t, b.hi);
    return fastTwoSum(c.hi, c.lo + t * b.lo);
}

double toDouble(double x) {
    return x;
}

double toDouble(const DD& x) {
    return x.hi;
}

/// x 2^e, as `factor` = 2^e when that is a normal double (a product by a power of two is
/// exact but for subnormal results, like ldexp, and much cheaper).
double scaled(double x, int e, double factor) {
    return factor != 0.0 ? x * factor : std::ldexp(x, e);
}

DD scaled(const DD& x, int e, double factor) {
    return {scaled(x.hi, e, factor), scaled(x.lo, e, factor)};
}

/// The relative rounding error of one operation, per number type.
template <class R>
constexpr double kUnit = 0x1p-53;
template <>
constexpr double kUnit<DD> = 0x1p-102;

/// x - y, exact as a double-double, once rounded as a double.
double difference(double x, double y, double) {
    return x - y;
}

DD difference(double x, double y, DD) {
    return twoSum(x, -y);
}

/// Certainly positive (1), negative (-1), or neither (0) given |x - exact| <= error. A
/// double-double's hi part is within 2^-53 relative of its value, so it decides.
int certainSign(double x, double error) {
    return x > error ? 1 : (x < -error ? -1 : 0);
}

int certainSign(const DD& x, double error) {
    const double e = error * (1.0 + 0x1p-50);
    return x.hi > e ? 1 : (x.hi < -e ? -1 : 0);
}

// ---------------------------------------------------------------------------------------
// Error bounds, at compile time.
// ---------------------------------------------------------------------------------------

/// A computed value's bounds: |exact| <= m and |computed - exact| <= e.
struct Bound {
    double m, e;
};

/// The errors of every certified quantity for operations of relative error u, after the
/// scaling; `exact_inputs`: the difference vectors at t = 0 and 1 carry no rounding.
struct Errors {
    double det, det_sum, cross, cross_sum, diff_cross, diff_cross_sum;

    static constexpr Errors compute(double u, bool exact_inputs) {
        auto mul = [u](Bound a, Bound b) {
            return Bound{a.m * b.m,
                         a.m * b.e + b.m * a.e + a.e * b.e + u * (a.m + a.e) * (b.m + b.e) + kEta};
        };
        auto add = [u](Bound a, Bound b) {
            return Bound{a.m + b.m, a.e + b.e + u * (a.m + a.e + b.m + b.e) + kEta};
        };
        auto cross2 = [&](Bound a, Bound b) { return add(mul(a, b), mul(a, b)); };
        // A scaled difference component: |value| < 2 by the scaling.
        const Bound input{2.0 * (1.0 + 0x1p-51),
                          (exact_inputs ? 0.0 : 2.0 * u * (1.0 + 4.0 * u)) + kEta};
        const Bound rate = add(input, input);             // x1 - x0
        const Bound scaled = mul(Bound{1.0, 0.0}, rate);  // t (x1 - x0), t in [0, 1]
        // x0 + t (x1 - x0): the exact value is a convex combination, below input.m.
        const Bound at{input.m, input.e + scaled.e + u * (input.m + input.e + scaled.e) + kEta};
        const Bound diff = add(at, at);  // a difference of two vectors at one time
        const Bound c = cross2(at, at);
        const Bound det = add(add(mul(at, c), mul(at, c)), mul(at, c));  // x . (y x z)
        const Bound cross_diff = cross2(diff, diff);
        // The bound is itself computed in rounded arithmetic (a few dozen roundings).
        constexpr double kWiden = 1.0 + 0x1p-20;
        return {det.e * kWiden,        add(add(det, det), det).e * kWiden,
                c.e * kWiden,          add(c, c).e * kWiden,
                cross_diff.e * kWiden, add(cross_diff, cross_diff).e * kWiden};
    }
};

template <class R>
constexpr Errors kErrors = Errors::compute(kUnit<R>, false);
template <>
constexpr Errors kErrors<DD> = Errors::compute(kUnit<DD>, true);
static_assert(kErrors<double>.det < 1e-12 && kErrors<double>.diff_cross_sum < 1e-12,
              "bounds as analysed");
static_assert(kErrors<DD>.det < 1e-26, "bounds as analysed");

/// Intervals examined before the next pass (or the exact stage) takes over, and how often
/// one may be halved.
constexpr int kMaxIntervals = 10;
constexpr int kMaxDoubleDouble = 10;
constexpr int kMaxDepth = 10;

template <class R>
using V3 = std::array<R, 3>;
/// The three difference vectors at one time.
template <class R>
using Frame = std::array<V3<R>, 3>;

template <class R>
V3<R> sub(const V3<R>& a, const V3<R>& b) {
    return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}

template <class R>
R det(const V3<R>& x, const V3<R>& y, const V3<R>& z) {
    const R c0 = y[1] * z[2] - y[2] * z[1];
    const R c1 = y[2] * z[0] - y[0] * z[2];
    const R c2 = y[0] * z[1] - y[1] * z[0];
    return (x[0] * c0 + x[1] * c1) + x[2] * c2;
}

/// The k-th component of u x w: the orientation in the projection that drops axis k.
template <class R>
R cross(const V3<R>& u, const V3<R>& w, int k) {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    return u[i] * w[j] - u[j] * w[i];
}

/// Sign of the quadratic u(t) x w(t) (component k) over the interval whose ends hold (ua,
/// wa) and (ub, wb), if its Bernstein coefficients certify one; else 0.
template <class R>
int quadraticSign(const V3<R>& ua, const V3<R>& wa, const V3<R>& ub, const V3<R>& wb, int k,
                  double error, double sum_error) {
    const int s0 = certainSign(cross(ua, wa, k), error);
    if (s0 == 0) {
        return 0;
    }
    const int s2 = certainSign(cross(ub, wb, k), error);
    if (s2 != s0) {
        return 0;
    }
    const int s1 = certainSign(cross(ua, wb, k) + cross(ub, wa, k), sum_error);
    return s1 == s0 ? s0 : 0;
}

/// The query as three difference vectors from vertex `base`, scaled per axis.
template <class R>
class Motion {
  public:
    /// False when a difference overflows (then only the exact stage can decide).
    bool prepare(const std::array<Vec3, 4>& start, const std::array<Vec3, 4>& end,
                 const std::array<int, 4>& order) {
        std::array<std::array<V3<R>, 3>, 2> d;
        for (int side = 0; side < 2; ++side) {
            const std::array<Vec3, 4>& x = side ? end : start;
            for (int v = 0; v < 3; ++v) {
                for (int k = 0; k < 3; ++k) {
                    d[side][v][k] = difference(x[order[v + 1]][k], x[order[0]][k], R());
                }
            }
        }
        for (int k = 0; k < 3; ++k) {
            double largest = 0.0;
            for (int side = 0; side < 2; ++side) {
                for (int v = 0; v < 3; ++v) {
                    largest = std::max(largest, std::abs(toDouble(d[side][v][k])));
                }
            }
            if (!std::isfinite(largest)) {
                return false;
            }
            // 2^-e with largest * 2^-e in [1, 2); an axis without extent stays as it is.
            const int e = largest > 0.0 ? std::ilogb(largest) : 0;
            const double factor = e > -1000 && e < 1000 ? std::ldexp(1.0, -e) : 0.0;
            for (int v = 0; v < 3; ++v) {
                const R s0 = scaled(d[0][v][k], -e, factor), s1 = scaled(d[1][v][k], -e, factor);
                start_[v][k] = s0;
                rate_[v][k] = s1 - s0;
            }
        }
        return true;
    }

    Frame<R> at(double t) const {
        Frame<R> f;
        for (int v = 0; v < 3; ++v) {
            for (int k = 0; k < 3; ++k) {
                f[v][k] = start_[v][k] + t * rate_[v][k];
            }
        }
        return f;
    }

  private:
    Frame<R> start_, rate_;  // set by prepare()
};

/// c(t) = det of the frame at one time, with its certain sign (0: uncertain).
template <class R>
int coplanaritySign(const Frame<R>& f) {
    return certainSign(det(f[0], f[1], f[2]), kErrors<R>.det);
}

/// The cubic's Bernstein coefficients on the interval (times 1, 3, 3, 1): their signs, and
/// approximate values for a root guess.
struct Cubic {
    std::array<double, 4> b;
    std::array<int, 4> sign;
    bool oneSign() const {
        return sign[0] != 0 && sign[0] == sign[1] && sign[1] == sign[2] && sign[2] == sign[3];
    }
    /// Certain coefficients with exactly one sign variation: exactly one simple root inside.
    bool oneRoot() const {
        int variations = 0;
        for (int i = 0; i < 4; ++i) {
            if (sign[i] == 0) {
                return false;
            }
            variations += i > 0 && sign[i] != sign[i - 1];
        }
        return variations == 1;
    }
    bool vanishes() const { return sign[0] == 0 && sign[1] == 0 && sign[2] == 0 && sign[3] == 0; }
};

/// y x z, the cross product of det(x, y, z) = x . (y x z).
template <class R>
V3<R> cross3(const V3<R>& y, const V3<R>& z) {
    return {y[1] * z[2] - y[2] * z[1], y[2] * z[0] - y[0] * z[2], y[0] * z[1] - y[1] * z[0]};
}

template <class R>
R dot(const V3<R>& x, const V3<R>& c) {
    return (x[0] * c[0] + x[1] * c[1]) + x[2] * c[2];
}

template <class R>
Cubic coplanarity(const Frame<R>& a, const Frame<R>& b) {
    // The eight determinants share four cross products (same operations as det()).
    const V3<R> aa = cross3(a[1], a[2]), ba = cross3(b[1], a[2]), ab = cross3(a[1], b[2]),
                bb = cross3(b[1], b[2]);
    std::array<R, 4> v;
    v[0] = dot(a[0], aa);
    v[1] = (dot(b[0], aa) + dot(a[0], ba)) + dot(a[0], ab);
    v[2] = (dot(a[0], bb) + dot(b[0], ab)) + dot(b[0], ba);
    v[3] = dot(b[0], bb);
    Cubic c;
    for (int i = 0; i < 4; ++i) {
        c.b[i] = toDouble(v[i]);
        c.sign[i] = certainSign(v[i], i == 0 || i == 3 ? kErrors<R>.det : kErrors<R>.det_sum);
    }
    return c;
}

/// The simple root of the Bernstein cubic (b with b[0], b[3] of opposite signs) in s in
/// [0, 1], to about `accuracy`: safeguarded Newton. Only a guess; it is certified after.
double approximateRoot(const std::array<double, 4>& bern, double accuracy) {
    // Monomial coefficients in s (the middle Bernstein values carry their factor 3).
    const double b0 = bern[0], b1 = bern[1] / 3.0, b2 = bern[2] / 3.0, b3 = bern[3];
    const double m1 = 3.0 * (b1 - b0), m2 = 3.0 * (b2 - 2.0 * b1 + b0);
    const double m3 = b3 - 3.0 * b2 + 3.0 * b1 - b0;
    auto f = [&](double s) { return ((m3 * s + m2) * s + m1) * s + b0; };
    double lo = 0.0, hi = 1.0;
    const bool rising = b0 < 0.0;
    double s = b0 / (b0 - b3);
    for (int it = 0; it < 40; ++it) {
        const double fs = f(s);
        if (fs == 0.0) {
            return s;
        }
        ((fs < 0.0) == rising ? lo : hi) = s;
        const double df = (3.0 * m3 * s + 2.0 * m2) * s + m1;
        double next = s - fs / df;
        if (!(next > lo && next < hi)) {
            next = 0.5 * (lo + hi);
        }
        if (std::abs(next - s) < accuracy || hi - lo < accuracy) {
            return next;
        }
        s = next;
    }
    return s;
}

/// Per kind: which vertex is the base of the three vectors, and the orientation tests.
struct VertexFaceKind {
    // x0 = a (vertex 1); vectors e1 = b - a, e2 = c - a, q = p - a.
    static constexpr std::array<int, 4> kOrder{1, 2, 3, 0};
    /// The normal's direction (approximately, any scale), to choose projections by.
    template <class R>
    static V3<double> normal(const Frame<R>& f) {
        V3<double> n;
        for (int k = 0; k < 3; ++k) {
            n[k] = toDouble(cross(f[0], f[1], k));
        }
        return n;
    }
    /// +1: strictly inside over the interval in projection k; -1: outside at every
    /// coplanar time of it; 0: neither certified.
    template <class R>
    static int classify(const Frame<R>& a, const Frame<R>& b, int k) {
        const Errors& e = kErrors<R>;
        const V3<R>&e1a = a[0], &e2a = a[1], &qa = a[2], &e1b = b[0], &e2b = b[1], &qb = b[2];
        const int n = quadraticSign(e1a, e2a, e1b, e2b, k, e.cross, e.cross_sum);
        const int ab = quadraticSign(e1a, qa, e1b, qb, k, e.cross, e.cross_sum);
        if (n != 0 && ab == -n) {
            return -1;
        }
        const int ca = quadraticSign(qa, e2a, qb, e2b, k, e.cross, e.cross_sum);
        if (n != 0 && ca == -n) {
            return -1;
        }
        const int bc = quadraticSign(sub(e2a, e1a), sub(qa, e1a), sub(e2b, e1b), sub(qb, e1b), k,
                                     e.diff_cross, e.diff_cross_sum);
        if (n != 0 && bc == -n) {
            return -1;
        }
        // Strictly inside the projected triangle (its orientation is then their sum).
        return ab != 0 && ab == ca && ca == bc ? 1 : 0;
    }
};

struct EdgeEdgeKind {
    // x0 = a0 (vertex 0); vectors ea = a1 - a0, r0 = b0 - a0, r1 = b1 - a0.
    static constexpr std::array<int, 4> kOrder{0, 1, 2, 3};
    template <class R>
    static V3<double> normal(const Frame<R>& f) {
        const V3<R> eb = sub(f[2], f[1]);
        V3<double> n;
        for (int k = 0; k < 3; ++k) {
            n[k] = toDouble(cross(f[0], eb, k));
        }
        return n;
    }
    template <class R>
    static int classify(const Frame<R>& a, const Frame<R>& b, int k) {
        const Errors& e = kErrors<R>;
        const V3<R>&eaa = a[0], &r0a = a[1], &r1a = a[2], &eab = b[0], &r0b = b[1], &r1b = b[2];
        // b0, b1 against the line of A.
        const int s0 = quadraticSign(eaa, r0a, eab, r0b, k, e.cross, e.cross_sum);
        const int s1 = quadraticSign(eaa, r1a, eab, r1b, k, e.cross, e.cross_sum);
        if (s0 != 0 && s0 == s1) {
            return -1;  // B strictly on one side of A's line in a projection: no contact
        }
        // a0, a1 against the line of B: (b1 - b0) x (a - b0) for a = a0 (= r0 x r1), a1.
        const int s2 = quadraticSign(r0a, r1a, r0b, r1b, k, e.cross, e.cross_sum);
        const int s3 = quadraticSign(sub(r1a, r0a), sub(eaa, r0a), sub(r1b, r0b), sub(eab, r0b), k,
                                     e.diff_cross, e.diff_cross_sum);
        if (s2 != 0 && s2 == s3) {
            return -1;
        }
        return s0 != 0 && s1 == -s0 && s2 != 0 && s3 == -s2 ? 1 : 0;
    }
};

/// Projections in order of the normal's magnitude along the dropped axis.
std::array<int, 3> projections(V3<double> n) {
    std::array<int, 3> k{0, 1, 2};
    for (double& x : n) {
        x = std::abs(x);
    }
    auto order = [&](int i, int j) {
        if (n[k[j]] > n[k[i]]) {
            std::swap(k[i], k[j]);
        }
    };
    order(0, 1);
    order(1, 2);
    order(0, 1);
    return k;
}

template <class Kind, class R>
int classifyAnyProjection(const Frame<R>& a, const Frame<R>& b, bool want_inside) {
    V3<double> n = Kind::normal(a);
    const V3<double> nb = Kind::normal(b);
    for (int k = 0; k < 3; ++k) {
        n[k] += nb[k];
    }
    for (int k : projections(n)) {
        const int c = Kind::classify(a, b, k);
        if (c == -1 || (c == 1 && want_inside)) {
            return c;
        }
    }
    return 0;
}

template <class R>
struct Interval {
    double lo, hi;
    Frame<R> a, b;  // the frames at lo and hi
    int depth;
};

template <class Kind, class R>
class Certifier {
  public:
    Certifier(const Motion<R>& motion, double t_lo, double t_hi, double tolerance)
        : motion_(motion), t_lo_(t_lo), t_hi_(t_hi), tolerance_(tolerance) {}

    enum class Result { kExcluded, kContact, kUndecided, kGiveUp, kTrimmed };

    /// Decides one interval; kContact sets toi_.
    Result examine(const Interval<R>& in) {
        const Cubic c = coplanarity(in.a, in.b);
        if (c.oneSign()) {
            return Result::kExcluded;
        }
        if (!c.oneRoot()) {
            const int o = classifyAnyProjection<Kind>(in.a, in.b, false);
            if (o == -1) {
                return Result::kExcluded;
            }
            // c vanishing at an end of the whole range, to this precision: most likely an
            // exact root there (a contact exactly at the start or the end of the step, or
            // coplanar motion), which no amount of halving settles. A thin slice at that end
            // may still be outside; otherwise hand it on at once.
            // c vanishing on the whole interval (coplanar motion, to this precision): no
            // contact can be certified here, and halving will not change that.
            if (c.vanishes()) {
                reason_ = "coplanar";
                return Result::kGiveUp;
            }
            const bool at_lo = in.lo == t_lo_ && c.sign[0] == 0;
            if (at_lo || (in.hi == t_hi_ && c.sign[3] == 0)) {
                return trimEnd(in, at_lo, c.b[at_lo ? 0 : 3] == 0.0);
            }
            return Result::kUndecided;
        }
        // One simple root t*: bracket it within the tolerance, then decide at t*.
        double lo = in.lo, hi = in.hi;
        Frame<R> flo = in.a, fhi = in.b;
        if (!bracket(c, lo, hi, flo, fhi)) {
            reason_ = "bracket";
            return Result::kGiveUp;
        }
        const int o = classifyAnyProjection<Kind>(flo, fhi, true);
        if (o == 1) {
            toi_ = lo;
            return Result::kContact;
        }
        // Outside: t* is the only coplanar time of the interval. Neither: the static test
        // at t* is too close to call at this precision (a touch on a boundary, a near miss).
        reason_ = "at root";
        return o == -1 ? Result::kExcluded : Result::kGiveUp;
    }

    double toi() const { return toi_; }
    const char* reason() const { return reason_; }
    /// After kTrimmed: the interval to examine instead.
    const Interval<R>& trimmed() const { return trimmed_; }

  private:
    /// Excludes a thin slice at the range's start (at_lo) or end by an "outside"
    /// certificate and shrinks the range past it (kTrimmed), or gives up.
    Result trimEnd(const Interval<R>& in, bool at_lo, bool computed_zero) {
        const double width = (in.hi - in.lo) * 0x1p-20;
        const double cut = at_lo ? in.lo + width : in.hi - width;
        if (in.lo < cut && cut < in.hi) {
            const Frame<R> fc = motion_.at(cut);
            const bool outside = at_lo ? classifyAnyProjection<Kind>(in.a, fc, false) == -1
                                       : classifyAnyProjection<Kind>(fc, in.b, false) == -1;
            if (outside) {
                if (at_lo) {
                    trimmed_ = {cut, in.hi, fc, in.b, in.depth};
                    t_lo_ = cut;
                } else {
                    trimmed_ = {in.lo, cut, in.a, fc, in.depth};
                    t_hi_ = cut;
                }
                return Result::kTrimmed;
            }
        }
        // A computed exact zero is almost surely a true one (exact inputs on a grid):
        // say so, and spare the double-double pass.
        reason_ = computed_zero ? "end zero" : "end";
        return Result::kGiveUp;
    }

    /// Narrows [lo, hi] (c certainly changing sign once on it) to at most half the
    /// tolerance around the root, with certain signs of c at the new ends.
    bool bracket(const Cubic& c, double& lo, double& hi, Frame<R>& flo, Frame<R>& fhi) const {
        const double width = 0.5 * tolerance_;
        if (hi - lo <= width) {
            return true;
        }
        const int sign_lo = c.sign[0];
        const double delta = 0.25 * width;
        const double guess = lo + approximateRoot(c.b, 0x1p-4 * delta / (hi - lo)) * (hi - lo);
        const double l = std::max(lo, guess - delta), h = std::min(hi, guess + delta);
        if (h - l <= width && l < h) {
            const Frame<R> fl = l == lo ? flo : motion_.at(l);
            const Frame<R> fh = h == hi ? fhi : motion_.at(h);
            if ((l == lo || coplanaritySign(fl) == sign_lo) &&
                (h == hi || coplanaritySign(fh) == -sign_lo)) {
                lo = l;
                hi = h;
                flo = fl;
                fhi = fh;
                return true;
            }
        }
        // The guess failed: bisect on certain signs.
        while (hi - lo > width) {
            bool moved = false;
            for (const double fraction : {0.5, 0.25, 0.75}) {
                const double m = lo + fraction * (hi - lo);
                if (!(lo < m && m < hi)) {
                    break;
                }
                const Frame<R> fm = motion_.at(m);
                const int s = coplanaritySign(fm);
                if (s != 0) {
                    (s == sign_lo ? lo : hi) = m;
                    (s == sign_lo ? flo : fhi) = fm;
                    moved = true;
                    break;
                }
            }
            if (!moved) {
                return false;
            }
        }
        return true;
    }

    const Motion<R>& motion_;
    double t_lo_, t_hi_, tolerance_;
    double toi_ = 1.0;
    Interval<R> trimmed_;
    const char* reason_ = "";
};

/// One pass of the certified search at the precision of R, over [t_lo, t_hi].
template <class Kind, class R>
CertifiedOutcome certifyPass(const std::array<Vec3, 4>& start, const std::array<Vec3, 4>& end,
                             double t_lo, double t_hi, double tolerance, int max_intervals) {
    CertifiedOutcome out;
    out.resume_from = t_lo;
    Motion<R> motion;
    if (!motion.prepare(start, end, Kind::kOrder)) {
        out.reason = "overflow";
        return out;
    }
    Certifier<Kind, R> certifier(motion, t_lo, t_hi, tolerance);
    using Result = typename Certifier<Kind, R>::Result;
    // Depth first from the left: when an interval is examined, everything before it is
    // excluded.
    std::array<Interval<R>, kMaxDepth + 2> stack;
    int size = 0;
    stack[size++] = {t_lo, t_hi, motion.at(t_lo), motion.at(t_hi), 0};
    while (size > 0) {
        const Interval<R> in = stack[--size];
        out.resume_from = in.lo;
        if (++out.intervals > max_intervals) {
            out.reason = "budget";
            return out;
        }
        switch (certifier.examine(in)) {
            case Result::kExcluded:
                continue;
            case Result::kContact:
                out.verdict = CertifiedOutcome::Verdict::kContact;
                out.toi = certifier.toi();
                return out;
            case Result::kGiveUp:
                out.reason = certifier.reason();
                return out;
            case Result::kTrimmed:
                stack[size++] = certifier.trimmed();
                continue;
            case Result::kUndecided:
                break;
        }
        const double mid = in.lo + 0.5 * (in.hi - in.lo);
        if (in.depth >= kMaxDepth || !(in.lo < mid && mid < in.hi)) {
            out.reason = "depth";
            return out;
        }
        const Frame<R> fm = motion.at(mid);
        stack[size++] = {mid, in.hi, fm, in.b, in.depth + 1};
        stack[size++] = {in.lo, mid, in.a, fm, in.depth + 1};
    }
    out.verdict = CertifiedOutcome::Verdict::kNoContact;
    return out;
}

/// Doubles first; where they cannot decide, double-doubles from there on.
template <class Kind>
CertifiedOutcome certify(const std::array<Vec3, 4>& start, const std::array<Vec3, 4>& end,
                         double t_lo, double t_hi, double tolerance) {
    CertifiedOutcome out =
        certifyPass<Kind, double>(start, end, t_lo, t_hi, tolerance, kMaxIntervals);
    const std::string_view reason = out.reason;
    if (out.verdict != CertifiedOutcome::Verdict::kUndecided || reason == "overflow" ||
        reason == "end zero") {
        return out;
    }
    const int intervals = out.intervals;
    out = certifyPass<Kind, DD>(start, end, out.resume_from, t_hi, tolerance, kMaxDoubleDouble);
    out.intervals += intervals;
    return out;
}

}  // namespace

CertifiedOutcome vertexFaceCertified(const std::array<Vec3, 4>& start,
                                     const std::array<Vec3, 4>& end, double t_lo, double t_hi,
                                     double tolerance) {
    return certify<VertexFaceKind>(start, end, t_lo, t_hi, tolerance);
}

CertifiedOutcome edgeEdgeCertified(const std::array<Vec3, 4>& start, const std::array<Vec3, 4>& end,
                                   double t_lo, double t_hi, double tolerance) {
    return certify<EdgeEdgeKind>(start, end, t_lo, t_hi, tolerance);
}

}  // namespace kolize::ccd::detail
