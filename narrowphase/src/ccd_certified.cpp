#include "ccd_certified.h"

#include <algorithm>
#include <cmath>

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

constexpr double kU = 0x1p-53;
/// Absolute slack per operation: covers underflow (at most 2^-1075 per rounding).
constexpr double kEta = 0x1p-1000;

/// A computed value's bounds: |exact| <= m and |computed - exact| <= e.
struct Bound {
    double m, e;
};

constexpr Bound mul(Bound a, Bound b) {
    return {a.m * b.m, a.m * b.e + b.m * a.e + a.e * b.e + kU * (a.m + a.e) * (b.m + b.e) + kEta};
}

constexpr Bound add(Bound a, Bound b) {
    return {a.m + b.m, a.e + b.e + kU * (a.m + a.e + b.m + b.e) + kEta};
}

/// The bound itself is computed in rounded arithmetic (a few dozen roundings): widen it.
constexpr double finalError(Bound a) {
    return a.e * (1.0 + 0x1p-20);
}

/// A scaled difference component (|value| < 2 by the scaling, one rounding).
constexpr Bound kInput{2.0 * (1.0 + 4.0 * kU), 2.0 * kU*(1.0 + 4.0 * kU) + kEta};
/// x1 - x0 of a component at the two ends.
constexpr Bound kRate = add(kInput, kInput);
/// t (x1 - x0) for a double t in [0, 1].
constexpr Bound kScaledRate = mul(Bound{1.0, 0.0}, kRate);
/// x0 + t (x1 - x0): the exact value is a convex combination, so still below kInput.m.
constexpr Bound kAt{kInput.m,
                    kInput.e + kScaledRate.e + kU*(kInput.m + kInput.e + kScaledRate.e) + kEta};
/// The difference of two such vectors at one time.
constexpr Bound kDiff = add(kAt, kAt);

constexpr Bound cross2(Bound a, Bound b) {
    return add(mul(a, b), mul(a, b));
}

/// x . (y x z), the cross product first.
constexpr Bound det3(Bound x, Bound y, Bound z) {
    const Bound c = cross2(y, z);
    return add(add(mul(x, c), mul(x, c)), mul(x, c));
}

constexpr Bound kDet = det3(kAt, kAt, kAt);
constexpr Bound kDetSum = add(add(kDet, kDet), kDet);
constexpr Bound kCross = cross2(kAt, kAt);
constexpr Bound kCrossSum = add(kCross, kCross);
constexpr Bound kDiffCross = cross2(kDiff, kDiff);
constexpr Bound kDiffCrossSum = add(kDiffCross, kDiffCross);

constexpr double kDetError = finalError(kDet);
constexpr double kDetSumError = finalError(kDetSum);
constexpr double kCrossError = finalError(kCross);
constexpr double kCrossSumError = finalError(kCrossSum);
constexpr double kDiffCrossError = finalError(kDiffCross);
constexpr double kDiffCrossSumError = finalError(kDiffCrossSum);
static_assert(kDetError < 1e-12 && kDiffCrossSumError < 1e-12, "bounds as analysed");

/// Intervals examined before the exact stage takes over, and how often one may be halved.
constexpr int kMaxIntervals = 24;
constexpr int kMaxDepth = 10;

using V3 = std::array<double, 3>;
/// The three difference vectors at one time.
using Frame = std::array<V3, 3>;

V3 sub(const V3& a, const V3& b) {
    return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}

double det(const V3& x, const V3& y, const V3& z) {
    const double c0 = y[1] * z[2] - y[2] * z[1];
    const double c1 = y[2] * z[0] - y[0] * z[2];
    const double c2 = y[0] * z[1] - y[1] * z[0];
    return (x[0] * c0 + x[1] * c1) + x[2] * c2;
}

/// The k-th component of u x w: the orientation in the projection that drops axis k.
double cross(const V3& u, const V3& w, int k) {
    const int i = k == 0 ? 1 : 0, j = k == 2 ? 1 : 2;
    return u[i] * w[j] - u[j] * w[i];
}

int certainSign(double x, double error) {
    return x > error ? 1 : (x < -error ? -1 : 0);
}

/// Sign of the quadratic u(t) x w(t) (component k) over the interval whose ends hold (ua,
/// wa) and (ub, wb), if its Bernstein coefficients certify one; else 0.
int quadraticSign(const V3& ua, const V3& wa, const V3& ub, const V3& wb, int k, double error,
                  double sum_error) {
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
class Motion {
  public:
    /// False when a difference overflows (then only the exact stage can decide).
    bool prepare(const std::array<Vec3, 4>& start, const std::array<Vec3, 4>& end,
                 const std::array<int, 4>& order) {
        std::array<std::array<V3, 3>, 2> d;
        for (int side = 0; side < 2; ++side) {
            const std::array<Vec3, 4>& x = side ? end : start;
            for (int v = 0; v < 3; ++v) {
                for (int k = 0; k < 3; ++k) {
                    d[side][v][k] = x[order[v + 1]][k] - x[order[0]][k];
                }
            }
        }
        for (int k = 0; k < 3; ++k) {
            double largest = 0.0;
            for (int side = 0; side < 2; ++side) {
                for (int v = 0; v < 3; ++v) {
                    largest = std::max(largest, std::abs(d[side][v][k]));
                }
            }
            if (!std::isfinite(largest)) {
                return false;
            }
            // 2^-e with largest * 2^-e in [1, 2); an axis without extent stays as it is.
            const int e = largest > 0.0 ? std::ilogb(largest) : 0;
            for (int v = 0; v < 3; ++v) {
                const double s0 = std::ldexp(d[0][v][k], -e), s1 = std::ldexp(d[1][v][k], -e);
                start_[v][k] = s0;
                rate_[v][k] = s1 - s0;
            }
        }
        return true;
    }

    Frame at(double t) const {
        Frame f;
        for (int v = 0; v < 3; ++v) {
            for (int k = 0; k < 3; ++k) {
                f[v][k] = start_[v][k] + t * rate_[v][k];
            }
        }
        return f;
    }

  private:
    Frame start_{}, rate_{};
};

/// c(t) = det of the frame at one time, with its certain sign (0: uncertain).
int coplanaritySign(const Frame& f) {
    return certainSign(det(f[0], f[1], f[2]), kDetError);
}

/// The cubic's Bernstein coefficients on the interval (times 1, 3, 3, 1) and their signs.
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

Cubic coplanarity(const Frame& a, const Frame& b) {
    Cubic c;
    c.b[0] = det(a[0], a[1], a[2]);
    c.b[1] = (det(b[0], a[1], a[2]) + det(a[0], b[1], a[2])) + det(a[0], a[1], b[2]);
    c.b[2] = (det(a[0], b[1], b[2]) + det(b[0], a[1], b[2])) + det(b[0], b[1], a[2]);
    c.b[3] = det(b[0], b[1], b[2]);
    for (int i = 0; i < 4; ++i) {
        c.sign[i] = certainSign(c.b[i], i == 0 || i == 3 ? kDetError : kDetSumError);
    }
    return c;
}

/// The simple root of the Bernstein cubic (b with b[0], b[3] of opposite signs) in s in
/// [0, 1], approximately: safeguarded Newton. Only a guess; it is certified afterwards.
double approximateRoot(const std::array<double, 4>& bern) {
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
        if (next == s || hi - lo < 0x1p-60) {
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
    /// The normal's direction (any scale), to choose projections by.
    static V3 normal(const Frame& f) {
        return {cross(f[0], f[1], 0), cross(f[0], f[1], 1), cross(f[0], f[1], 2)};
    }
    /// +1: strictly inside over the interval in projection k; -1: outside at every
    /// coplanar time of it; 0: neither certified.
    static int classify(const Frame& a, const Frame& b, int k) {
        const V3 &e1a = a[0], &e2a = a[1], &qa = a[2], &e1b = b[0], &e2b = b[1], &qb = b[2];
        const int n = quadraticSign(e1a, e2a, e1b, e2b, k, kCrossError, kCrossSumError);
        const int ab = quadraticSign(e1a, qa, e1b, qb, k, kCrossError, kCrossSumError);
        if (n != 0 && ab == -n) {
            return -1;
        }
        const int ca = quadraticSign(qa, e2a, qb, e2b, k, kCrossError, kCrossSumError);
        if (n != 0 && ca == -n) {
            return -1;
        }
        const int bc = quadraticSign(sub(e2a, e1a), sub(qa, e1a), sub(e2b, e1b), sub(qb, e1b), k,
                                     kDiffCrossError, kDiffCrossSumError);
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
    static V3 normal(const Frame& f) {
        const V3 eb = sub(f[2], f[1]);
        return {cross(f[0], eb, 0), cross(f[0], eb, 1), cross(f[0], eb, 2)};
    }
    static int classify(const Frame& a, const Frame& b, int k) {
        const V3 &eaa = a[0], &r0a = a[1], &r1a = a[2], &eab = b[0], &r0b = b[1], &r1b = b[2];
        // b0, b1 against the line of A.
        const int s0 = quadraticSign(eaa, r0a, eab, r0b, k, kCrossError, kCrossSumError);
        const int s1 = quadraticSign(eaa, r1a, eab, r1b, k, kCrossError, kCrossSumError);
        if (s0 != 0 && s0 == s1) {
            return -1;  // B strictly on one side of A's line in a projection: no contact
        }
        // a0, a1 against the line of B: (b1 - b0) x (a - b0) for a = a0 (= r0 x r1), a1.
        const int s2 = quadraticSign(r0a, r1a, r0b, r1b, k, kCrossError, kCrossSumError);
        const int s3 = quadraticSign(sub(r1a, r0a), sub(eaa, r0a), sub(r1b, r0b), sub(eab, r0b), k,
                                     kDiffCrossError, kDiffCrossSumError);
        if (s2 != 0 && s2 == s3) {
            return -1;
        }
        return s0 != 0 && s1 == -s0 && s2 != 0 && s3 == -s2 ? 1 : 0;
    }
};

/// Projections in order of the normal's magnitude along the dropped axis.
std::array<int, 3> projections(V3 n) {
    std::array<int, 3> k{0, 1, 2};
    for (double& x : n) {
        x = std::abs(x);
    }
    std::sort(k.begin(), k.end(), [&](int i, int j) { return n[i] > n[j]; });
    return k;
}

template <class Kind>
int classifyAnyProjection(const Frame& a, const Frame& b, bool want_inside) {
    V3 n = Kind::normal(a);
    const V3 nb = Kind::normal(b);
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

struct Interval {
    double lo, hi;
    Frame a, b;  // the frames at lo and hi
    int depth;
};

template <class Kind>
class Certifier {
  public:
    Certifier(const Motion& motion, double tolerance) : motion_(motion), tolerance_(tolerance) {}

    enum class Result { kExcluded, kContact, kUndecided, kGiveUp };

    /// Decides one interval; kContact sets toi_.
    Result examine(const Interval& in) {
        const Cubic c = coplanarity(in.a, in.b);
        if (c.oneSign()) {
            return Result::kExcluded;
        }
        if (!c.oneRoot()) {
            const int o = classifyAnyProjection<Kind>(in.a, in.b, false);
            return o == -1 ? Result::kExcluded : Result::kUndecided;
        }
        // One simple root t*: bracket it within the tolerance, then decide at t*.
        double lo = in.lo, hi = in.hi;
        Frame flo = in.a, fhi = in.b;
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
        // at t* is too close to call in doubles (a touch on a boundary, a near miss).
        reason_ = "at root";
        return o == -1 ? Result::kExcluded : Result::kGiveUp;
    }

    double toi() const { return toi_; }
    const char* reason() const { return reason_; }

  private:
    /// Narrows [lo, hi] (c certainly changing sign once on it) to at most half the
    /// tolerance around the root, with certain signs of c at the new ends.
    bool bracket(const Cubic& c, double& lo, double& hi, Frame& flo, Frame& fhi) const {
        const double width = 0.5 * tolerance_;
        if (hi - lo <= width) {
            return true;
        }
        const int sign_lo = c.sign[0];
        const double guess = lo + approximateRoot(c.b) * (hi - lo);
        const double delta = 0.25 * width;
        const double l = std::max(lo, guess - delta), h = std::min(hi, guess + delta);
        if (h - l <= width && l < h) {
            const Frame fl = l == lo ? flo : motion_.at(l), fh = h == hi ? fhi : motion_.at(h);
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
                const Frame fm = motion_.at(m);
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

    const Motion& motion_;
    double tolerance_;
    double toi_ = 1.0;
    const char* reason_ = "";
};

template <class Kind>
CertifiedOutcome certify(const std::array<Vec3, 4>& start, const std::array<Vec3, 4>& end,
                         double t_lo, double t_hi, double tolerance) {
    CertifiedOutcome out;
    out.resume_from = t_lo;
    Motion motion;
    if (!motion.prepare(start, end, Kind::kOrder)) {
        out.reason = "overflow";
        return out;
    }
    Certifier<Kind> certifier(motion, tolerance);
    // Depth first from the left: when an interval is examined, everything before it is
    // excluded.
    std::array<Interval, kMaxDepth + 2> stack;
    int size = 0;
    stack[size++] = {t_lo, t_hi, motion.at(t_lo), motion.at(t_hi), 0};
    while (size > 0) {
        const Interval in = stack[--size];
        out.resume_from = in.lo;
        if (++out.intervals > kMaxIntervals) {
            out.reason = "budget";
            return out;
        }
        switch (certifier.examine(in)) {
            case Certifier<Kind>::Result::kExcluded:
                continue;
            case Certifier<Kind>::Result::kContact:
                out.verdict = CertifiedOutcome::Verdict::kContact;
                out.toi = certifier.toi();
                return out;
            case Certifier<Kind>::Result::kGiveUp:
                out.reason = certifier.reason();
                return out;
            case Certifier<Kind>::Result::kUndecided:
                break;
        }
        const double mid = in.lo + 0.5 * (in.hi - in.lo);
        if (in.depth >= kMaxDepth || !(in.lo < mid && mid < in.hi)) {
            out.reason = "depth";
            return out;
        }
        const Frame fm = motion.at(mid);
        stack[size++] = {mid, in.hi, fm, in.b, in.depth + 1};
        stack[size++] = {in.lo, mid, in.a, fm, in.depth + 1};
    }
    out.verdict = CertifiedOutcome::Verdict::kNoContact;
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
