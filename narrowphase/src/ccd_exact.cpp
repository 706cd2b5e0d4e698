#include "ccd_exact.h"

#include <gmp.h>

#include <algorithm>
#include <cassert>
#include <cfenv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <optional>
#include <type_traits>
#include <utility>

// Why this decomposition is complete. Every vertex moves linearly, so every quantity below
// is a polynomial in t whose coefficients are exact sums of products of the input doubles.
//
// * Touching needs the four points coplanar: the coplanarity cubic c(t) vanishes. If c is
//   not identically zero, every contact time is one of its (at most 3) real roots, and the
//   static closed test at each root decides.
// * If c vanishes identically (coplanar motion), the earliest contact in [a, b] is a or a
//   time where contact *begins*. Contact of a vertex with the relative interior of a
//   non-degenerate triangle, or of two non-parallel edges crossing at interior points, is
//   open in time while the motion stays coplanar, so it cannot begin at t > a: contact
//   begins on a closed edge -- a vertex reaching an edge's line (a root of a component of
//   (p - x) x (y - x) that is not identically zero; if all are, the vertex stays on the
//   line and can only enter the edge through an end point) or a vertex meeting a vertex (a
//   root of a component of p - x). Those times, and a, are the candidates; the static test
//   rejects the ones that are not contacts.
//
// A candidate time t* is a rational num / den, or the only root of a squarefree polynomial p
// in an interval (lo, hi) with dyadic ends. The static test evaluates signs of polynomials
// g at t*: homogeneously for a rational; for a root, first by bounding g over (lo, hi)
// while halving it a few times, then by a Tarski query: sign g(t*) = Var(lo) - Var(hi) of
// the signed remainder sequence of (p, p' g mod p), which also decides g(t*) = 0. Nothing
// divides: remainders are pseudo-remainders scaled by positive factors, which keeps every
// sign and every root.
//
// Arithmetic: the same code runs first on double intervals, with the FPU rounding upward
// (results computed without rounding stay exact points, so exact zeros often survive).
// Every branch asks for a sign; an interval that straddles zero throws `Uncertain`, and
// only then the query is redone with exact dyadic numbers (GMP integers times powers of
// two), which still try intervals around their exact values before each exact sign. The
// interval pass isolates roots by Bernstein subdivision, which never divides by a
// coefficient (a nearly vanishing lead costs it nothing); the exact pass by Sturm
// sequences. Interval answers are exact answers, just cheaper; the exact numbers are
// needed for true degeneracies (contact exactly on a boundary, exact double roots) and for
// near-misses closer than double intervals can resolve.

namespace kolize::ccd::detail {
namespace {

// ---------------------------------------------------------------------------------------
// Number types: double intervals (filter) and exact dyadic numbers.
// ---------------------------------------------------------------------------------------

/// Thrown by the interval filter when a sign is not certain.
struct Uncertain {};

double nextUp(double x) {
    if (!(x < std::numeric_limits<double>::infinity())) {
        return x;  // +inf or NaN
    }
    if (x == 0.0) {
        return std::numeric_limits<double>::denorm_min();
    }
    uint64_t bits;
    std::memcpy(&bits, &x, sizeof bits);
    bits += x > 0.0 ? 1 : -1;
    std::memcpy(&x, &bits, sizeof bits);
    return x;
}

double nextDown(double x) {
    return -nextUp(-x);
}

// Interval arithmetic runs with the FPU rounding upward (see UpwardRounding): an upper
// bound is the rounded result, a lower bound the negated rounded result of the negated
// operation. Overflow rounds to infinity on the safe side; an infinite bound is refused
// before it can meet a zero (inf * 0 or inf - inf would be NaN).

/// Rounds upward for the lifetime of the object, from the default environment (so no
/// flush-to-zero or denormals-are-zero mode a caller may have set, under which bounds of
/// tiny values would collapse to zero), then restores the caller's environment.
class UpwardRounding {
  public:
    UpwardRounding() {
        std::fegetenv(&saved_);
        std::fesetenv(FE_DFL_ENV);
        std::fesetround(FE_UPWARD);
    }
    ~UpwardRounding() { std::fesetenv(&saved_); }
    UpwardRounding(const UpwardRounding&) = delete;
    UpwardRounding& operator=(const UpwardRounding&) = delete;

  private:
    std::fenv_t saved_;
};

/// A closed interval of doubles containing the exact value.
struct Interval {
    double lo = 0.0, hi = 0.0;
    Interval() = default;
    Interval(double x) : lo(x), hi(x) {}  // NOLINT: exact conversion
    Interval(int x) : lo(x), hi(x) {}     // NOLINT: exact conversion
    Interval(double l, double h) : lo(l), hi(h) {}
    bool finite() const { return std::isfinite(lo) && std::isfinite(hi); }
};

void requireFinite(const Interval& a, const Interval& b) {
    if (!a.finite() || !b.finite()) {
        throw Uncertain{};
    }
}

Interval operator+(const Interval& a, const Interval& b) {
    requireFinite(a, b);
    return {-((-a.lo) - b.lo), a.hi + b.hi};
}

Interval operator-(const Interval& a) {
    return {-a.hi, -a.lo};
}

Interval operator-(const Interval& a, const Interval& b) {
    requireFinite(a, b);
    return {-(b.hi - a.lo), a.hi - b.lo};
}

Interval operator*(const Interval& a, const Interval& b) {
    requireFinite(a, b);
    if (a.lo == a.hi) {  // A point times an interval: the sign of the point orders the ends.
        const double x = a.lo;
        return x >= 0.0 ? Interval(-((-x) * b.lo), x * b.hi) : Interval(-((-x) * b.hi), x * b.lo);
    }
    if (b.lo == b.hi) {
        const double y = b.lo;
        return y >= 0.0 ? Interval(-((-a.lo) * y), a.hi * y) : Interval(-((-a.hi) * y), a.lo * y);
    }
    const double lo = -std::max({(-a.lo) * b.lo, (-a.lo) * b.hi, (-a.hi) * b.lo, (-a.hi) * b.hi});
    const double hi = std::max({a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi});
    return {lo, hi};
}

Interval& operator+=(Interval& a, const Interval& b) {
    return a = a + b;
}

Interval& operator-=(Interval& a, const Interval& b) {
    return a = a - b;
}

Interval& operator*=(Interval& a, const Interval& b) {
    return a = a * b;
}

int signOf(const Interval& x) {
    if (x.lo > 0.0) {
        return 1;
    }
    if (x.hi < 0.0) {
        return -1;
    }
    if (x.lo == 0.0 && x.hi == 0.0) {
        return 0;
    }
    throw Uncertain{};  // Straddles zero, or NaN.
}

/// A point strictly between a < b (interval times are single doubles).
Interval midpoint(const Interval& a, const Interval& b) {
    const double m = a.lo + 0.5 * (b.hi - a.lo);
    if (!(a.hi < m && m < b.lo)) {
        throw Uncertain{};  // Not two distinct doubles apart: ask the exact numbers.
    }
    return Interval(m);
}

/// A double no larger than num / den (den > 0, num >= 0).
double lowerQuotient(const Interval& num, const Interval& den) {
    return num.lo <= 0.0 ? 0.0 : -((-num.lo) / den.hi);
}

/// A double no smaller than num / den (den > 0, num >= 0).
double upperQuotient(const Interval& num, const Interval& den) {
    return num.hi / den.lo;
}

/// Whether hi - lo may exceed width (an extra halving is harmless).
bool widerThan(const Interval& lo, const Interval& hi, double width) {
    return hi.hi - lo.lo > width;
}

/// An exact dyadic number (-1)^negative * m * 2^e with m an odd natural number (or m = 0),
/// m in GMP limbs (mpn layer), the first few stored inline: the exact pass needs only ring
/// operations and halving, on numbers of a few limbs, so it neither allocates nor pays for
/// rational canonicalisation (gcd) in the common case.
class Dyadic {
  public:
    Dyadic() = default;
    Dyadic(int x) {  // NOLINT: exact conversion
        if (x != 0) {
            inline_[0] = static_cast<mp_limb_t>(x < 0 ? -static_cast<long>(x) : x);
            size_ = 1;
            negative_ = x < 0;
            normalize();
        }
    }
    Dyadic(double x) {  // NOLINT: exact conversion of a finite double
        int exponent = 0;
        const double fraction = std::frexp(x, &exponent);            // x = fraction 2^exponent
        const double mantissa = std::ldexp(std::abs(fraction), 53);  // an integer < 2^53
        if (mantissa != 0.0) {
            inline_[0] = static_cast<mp_limb_t>(mantissa);
            size_ = 1;
            negative_ = x < 0.0;
            e_ = exponent - 53;
            normalize();
        }
    }
    Dyadic(const Dyadic& o) { copyFrom(o); }
    Dyadic(Dyadic&& o) noexcept { moveFrom(o); }
    Dyadic& operator=(const Dyadic& o) {
        if (this != &o) {
            copyFrom(o);
        }
        return *this;
    }
    Dyadic& operator=(Dyadic&& o) noexcept {
        if (this != &o) {
            moveFrom(o);
        }
        return *this;
    }
    ~Dyadic() { delete[] heap_; }

    int sign() const { return size_ == 0 ? 0 : (negative_ ? -1 : 1); }

    friend Dyadic operator+(const Dyadic& a, const Dyadic& b) { return sum(a, b, false); }
    friend Dyadic operator-(const Dyadic& a, const Dyadic& b) { return sum(a, b, true); }
    friend Dyadic operator-(const Dyadic& a) {
        Dyadic r(a);
        r.negative_ = r.size_ != 0 && !r.negative_;
        return r;
    }
    friend Dyadic operator*(const Dyadic& a, const Dyadic& b) {
        Dyadic r;
        if (a.size_ == 0 || b.size_ == 0) {
            return r;
        }
        const int n = a.size_ + b.size_;
        r.reserve(n);
        if (a.size_ >= b.size_) {
            mpn_mul(r.data(), a.data(), a.size_, b.data(), b.size_);
        } else {
            mpn_mul(r.data(), b.data(), b.size_, a.data(), a.size_);
        }
        r.size_ = n - (r.data()[n - 1] == 0);
        r.negative_ = a.negative_ != b.negative_;
        r.e_ = a.e_ + b.e_;  // odd times odd stays odd
        return r;
    }
    Dyadic& operator+=(const Dyadic& b) { return *this = *this + b; }
    Dyadic& operator-=(const Dyadic& b) { return *this = *this - b; }
    Dyadic& operator*=(const Dyadic& b) { return *this = *this * b; }

    friend Dyadic midpoint(const Dyadic& a, const Dyadic& b) {
        Dyadic r = a + b;
        if (r.size_ != 0) {
            --r.e_;
        }
        return r;
    }

    /// The value as a read-only GMP integer view of m (with its sign) and the exponent e.
    long exponent() const { return e_; }
    mpz_srcptr integer(mpz_t view) const {
        return mpz_roinit_n(view, data(), negative_ ? -size_ : size_);
    }

  private:
    static constexpr int kInline = 6;

    mp_limb_t* data() { return heap_ ? heap_ : inline_; }
    const mp_limb_t* data() const { return heap_ ? heap_ : inline_; }
    int capacity() const { return heap_ ? heap_capacity_ : kInline; }
    /// Room for n limbs; the previous content is lost.
    void reserve(int n) {
        if (n > capacity()) {
            delete[] heap_;
            heap_ = new mp_limb_t[n];
            heap_capacity_ = n;
        }
    }
    void copyFrom(const Dyadic& o) {
        reserve(o.size_);
        std::copy(o.data(), o.data() + o.size_, data());
        size_ = o.size_;
        negative_ = o.negative_;
        e_ = o.e_;
    }
    void moveFrom(Dyadic& o) {
        if (o.heap_) {
            delete[] heap_;
            heap_ = o.heap_;
            heap_capacity_ = o.heap_capacity_;
            o.heap_ = nullptr;
            size_ = o.size_;
            negative_ = o.negative_;
            e_ = o.e_;
        } else {
            copyFrom(o);
        }
    }

    /// |x| against |y| for limb vectors without leading zeros.
    static int compare(const mp_limb_t* x, int xn, const mp_limb_t* y, int yn) {
        if (xn != yn) {
            return xn < yn ? -1 : 1;
        }
        return xn == 0 ? 0 : mpn_cmp(x, y, xn);
    }

    static int stripped(const mp_limb_t* x, int n) {
        while (n > 0 && x[n - 1] == 0) {
            --n;
        }
        return n;
    }

    static Dyadic sum(const Dyadic& a, const Dyadic& b, bool subtract) {
        const bool b_negative = b.negative_ != subtract;
        if (b.size_ == 0) {
            return a;
        }
        if (a.size_ == 0) {
            Dyadic r(b);
            r.negative_ = b_negative;
            return r;
        }
        // Align to the smaller exponent: `high` is shifted left by the difference, so it
        // only gains trailing zeros and `low` keeps its odd last bit.
        const bool a_low = a.e_ <= b.e_;
        const Dyadic& low = a_low ? a : b;
        const Dyadic& high = a_low ? b : a;
        const bool low_negative = a_low ? a.negative_ : b_negative;
        const bool high_negative = a_low ? b_negative : a.negative_;
        const unsigned long shift = static_cast<unsigned long>(high.e_ - low.e_);
        const int limb_shift = static_cast<int>(shift / GMP_NUMB_BITS);
        const unsigned bit_shift = static_cast<unsigned>(shift % GMP_NUMB_BITS);
        const int n = std::max(high.size_ + limb_shift + 1, low.size_) + 1;
        Dyadic r;
        r.reserve(n);
        mp_limb_t* rp = r.data();
        std::fill(rp, rp + n, mp_limb_t(0));
        if (bit_shift != 0) {
            rp[limb_shift + high.size_] =
                mpn_lshift(rp + limb_shift, high.data(), high.size_, bit_shift);
        } else {
            std::copy(high.data(), high.data() + high.size_, rp + limb_shift);
        }
        if (low_negative == high_negative) {
            mpn_add(rp, rp, n, low.data(), low.size_);  // no carry out: n has a spare limb
            r.negative_ = high_negative;
        } else if (compare(rp, stripped(rp, n), low.data(), low.size_) >= 0) {
            mpn_sub(rp, rp, n, low.data(), low.size_);
            r.negative_ = high_negative;
        } else {
            // |low| > |shifted high|, so shifted high < 2^(64 low.size_): subtract it from
            // low on low.size_ limbs (mpn_sub_n may write over its second operand).
            mpn_sub_n(rp, low.data(), rp, low.size_);
            std::fill(rp + low.size_, rp + n, mp_limb_t(0));
            r.negative_ = low_negative;
        }
        r.size_ = stripped(rp, n);
        r.e_ = low.e_;
        if (shift == 0) {
            r.normalize();  // odd plus odd is even
        } else if (r.size_ == 0) {
            r.negative_ = false;
            r.e_ = 0;
        }
        return r;
    }

    /// Makes m odd (or the canonical zero).
    void normalize() {
        if (size_ == 0) {
            negative_ = false;
            e_ = 0;
            return;
        }
        mp_limb_t* d = data();
        const mp_bitcnt_t zeros = mpn_scan1(d, 0);
        const int limbs = static_cast<int>(zeros / GMP_NUMB_BITS);
        const unsigned bits = static_cast<unsigned>(zeros % GMP_NUMB_BITS);
        if (limbs > 0) {
            std::copy(d + limbs, d + size_, d);
            size_ -= limbs;
        }
        if (bits > 0) {
            mpn_rshift(d, d, size_, bits);
            size_ = stripped(d, size_);
        }
        e_ += static_cast<long>(zeros);
    }

    int size_ = 0;
    bool negative_ = false;
    long e_ = 0;
    mp_limb_t inline_[kInline] = {};
    mp_limb_t* heap_ = nullptr;
    int heap_capacity_ = 0;
};

int signOf(const Dyadic& x) {
    return x.sign();
}

bool widerThan(const Dyadic& lo, const Dyadic& hi, double width) {
    return (hi - lo - Dyadic(width)).sign() > 0;
}

/// The exact value of x as a GMP rational (initialised by the caller).
void toRational(const Dyadic& x, mpq_t q) {
    mpz_t view;
    mpq_set_z(q, x.integer(view));
    if (x.exponent() >= 0) {
        mpq_mul_2exp(q, q, static_cast<mp_bitcnt_t>(x.exponent()));
    } else {
        mpq_div_2exp(q, q, static_cast<mp_bitcnt_t>(-x.exponent()));
    }
}

/// num / den as a double rounded down (up = false) or up (den > 0).
double roundQuotient(const Dyadic& num, const Dyadic& den, bool up) {
    mpq_t q, d;
    mpq_init(q);
    mpq_init(d);
    toRational(num, q);
    toRational(den, d);
    mpq_div(q, q, d);
    double x = mpq_get_d(q);  // truncated towards zero
    mpq_set_d(d, x);
    const int c = mpq_cmp(d, q);
    if (up && c < 0) {
        x = nextUp(x);
    } else if (!up && c > 0) {
        x = nextDown(x);
    }
    mpq_clear(q);
    mpq_clear(d);
    return x;
}

double lowerQuotient(const Dyadic& num, const Dyadic& den) {
    return roundQuotient(num, den, false);
}

double upperQuotient(const Dyadic& num, const Dyadic& den) {
    return roundQuotient(num, den, true);
}

/// An interval around x (under upward rounding), or nothing when x is outside the normal
/// double range.
std::optional<Interval> toInterval(const Dyadic& x) {
    if (x.sign() == 0) {
        return Interval(0.0);
    }
    mpz_t view;
    long exponent = 0;
    const double d = mpz_get_d_2exp(&exponent, x.integer(view));  // truncated: widen outwards
    exponent += x.exponent();
    if (exponent > 1000 || exponent < -1000) {
        return std::nullopt;
    }
    const Interval unit = d > 0.0 ? Interval(d, nextUp(d)) : Interval(nextDown(d), d);
    return Interval(std::ldexp(unit.lo, static_cast<int>(exponent)),
                    std::ldexp(unit.hi, static_cast<int>(exponent)));
}

// ---------------------------------------------------------------------------------------
// Polynomials in t of degree at most 4, without division.
// ---------------------------------------------------------------------------------------

constexpr int kMaxTerms = 5;

/// c[0] + c[1] t + ... + c[n - 1] t^(n - 1); c[n - 1] is not (certainly) zero, see trim();
/// n = 0: the zero polynomial.
template <class N>
struct Poly {
    std::array<N, kMaxTerms> c;
    int n = 0;
    int degree() const { return n - 1; }
    bool isZero() const { return n == 0; }
    const N& lead() const { return c[n - 1]; }
};

bool certainlyZero(const Interval& x) {
    return x.lo == 0.0 && x.hi == 0.0;
}

bool certainlyZero(const Dyadic& x) {
    return x.sign() == 0;
}

/// Drops leading coefficients that are certainly zero. An interval lead that straddles zero
/// stays: such a polynomial has an uncertain degree, and every step that depends on the
/// degree (division by the lead, "constant", "identically zero") asks for a sign and so
/// refuses it, while evaluation and Bernstein bounds work regardless.
template <class N>
void trim(Poly<N>& p) {
    while (p.n > 0 && certainlyZero(p.c[p.n - 1])) {
        --p.n;
    }
}

/// A non-zero constant (so it has no root); asks for the sign of an uncertain constant.
template <class N>
bool nonZeroConstant(const Poly<N>& p) {
    return p.n == 1 && signOf(p.c[0]) != 0;
}

template <class N>
Poly<N> operator+(const Poly<N>& a, const Poly<N>& b) {
    Poly<N> r;
    r.n = std::max(a.n, b.n);
    for (int i = 0; i < r.n; ++i) {
        r.c[i] = i < a.n ? (i < b.n ? N(a.c[i] + b.c[i]) : a.c[i]) : b.c[i];
    }
    trim(r);
    return r;
}

template <class N>
Poly<N> operator-(const Poly<N>& a) {
    Poly<N> r;
    r.n = a.n;
    for (int i = 0; i < r.n; ++i) {
        r.c[i] = -a.c[i];
    }
    return r;
}

template <class N>
Poly<N> operator-(const Poly<N>& a, const Poly<N>& b) {
    Poly<N> r;
    r.n = std::max(a.n, b.n);
    for (int i = 0; i < r.n; ++i) {
        r.c[i] = i < a.n ? (i < b.n ? N(a.c[i] - b.c[i]) : a.c[i]) : N(-b.c[i]);
    }
    trim(r);
    return r;
}

template <class N>
Poly<N> operator*(const Poly<N>& a, const Poly<N>& b) {
    Poly<N> r;
    if (a.isZero() || b.isZero()) {
        return r;
    }
    r.n = a.n + b.n - 1;
    assert(r.n <= kMaxTerms);
    for (int i = 0; i < r.n; ++i) {
        r.c[i] = 0;
    }
    for (int i = 0; i < a.n; ++i) {
        for (int j = 0; j < b.n; ++j) {
            r.c[i + j] += a.c[i] * b.c[j];
        }
    }
    trim(r);  // An interval lead may straddle zero (the exact one is not zero).
    return r;
}

template <class N>
N eval(const Poly<N>& p, const N& t) {
    N r = 0;
    for (int i = p.n - 1; i >= 0; --i) {
        r = r * t + p.c[i];
    }
    return r;
}

/// The polynomial with interval coefficients around the exact ones, if all convert.
std::optional<Poly<Interval>> toInterval(const Poly<Dyadic>& p) {
    Poly<Interval> r;
    r.n = p.n;
    for (int i = 0; i < p.n; ++i) {
        const std::optional<Interval> c = toInterval(p.c[i]);
        if (!c) {
            return std::nullopt;
        }
        r.c[i] = *c;
    }
    return r;
}

/// Sign of p over all of [lo, hi] when interval evaluation decides it.
std::optional<int> quickSign(const Poly<Interval>& p, const Interval& lo, const Interval& hi) {
    // This runs on every sign query, so it must not throw: check finiteness first (an
    // overflow would otherwise make the operations refuse).
    const Interval t(lo.lo, hi.hi);
    Interval r;
    for (int i = p.n - 1; i >= 0; --i) {
        if (!r.finite() || !t.finite() || !p.c[i].finite()) {
            return std::nullopt;
        }
        r = r * t + p.c[i];
    }
    if (r.lo > 0.0) {
        return 1;
    }
    if (r.hi < 0.0) {
        return -1;
    }
    if (certainlyZero(r)) {
        return 0;
    }
    return std::nullopt;  // straddles zero, or NaN
}

std::optional<int> quickSign(const Poly<Dyadic>& p, const Dyadic& lo, const Dyadic& hi) {
    const std::optional<Poly<Interval>> q = toInterval(p);
    const std::optional<Interval> l = toInterval(lo), h = toInterval(hi);
    if (!q || !l || !h) {
        return std::nullopt;
    }
    return quickSign(*q, *l, *h);
}

template <class N>
int signAt(const Poly<N>& p, const N& t) {
    if (p.isZero()) {
        return 0;
    }
    if constexpr (std::is_same_v<N, Dyadic>) {
        if (const std::optional<int> s = quickSign(p, t, t)) {  // cheap filter first
            return *s;
        }
    }
    return signOf(eval(p, t));
}

/// Sign of p(num / den) for den > 0: of the homogenised sum p_i num^i den^(n - i).
template <class N>
int signAtQuotient(const Poly<N>& p, const N& num, const N& den) {
    if (p.isZero()) {
        return 0;
    }
    N r = p.c[p.n - 1];
    N den_power = 1;
    for (int i = p.n - 2; i >= 0; --i) {
        den_power *= den;
        r = r * num + p.c[i] * den_power;
    }
    return signOf(r);
}

template <class N>
Poly<N> derivative(const Poly<N>& p) {
    Poly<N> r;
    r.n = std::max(p.n - 1, 0);
    for (int i = 0; i < r.n; ++i) {
        r.c[i] = p.c[i + 1] * N(i + 1);
    }
    return r;
}

/// A positive multiple of the remainder of a divided by the non-zero b (and of the
/// quotient, same factor, when asked): each step scales a by |lead(b)| > 0.
template <class N>
Poly<N> remainder(Poly<N> a, const Poly<N>& b, Poly<N>* quotient = nullptr) {
    const int db = b.degree();
    const int sign_b = signOf(b.lead());
    const N scale = sign_b > 0 ? b.lead() : N(-b.lead());
    if (quotient) {
        quotient->n = std::max(a.degree() - db + 1, 0);
        for (int i = 0; i < quotient->n; ++i) {
            quotient->c[i] = 0;
        }
    }
    while (a.degree() >= db) {
        const int shift = a.degree() - db;
        const N factor = sign_b > 0 ? a.lead() : N(-a.lead());  // a = scale a - factor t^s b
        for (int i = 0; i < a.n - 1; ++i) {
            a.c[i] = a.c[i] * scale;
            if (i >= shift) {
                a.c[i] -= factor * b.c[i - shift];
            }
        }
        if (quotient) {
            for (int i = 0; i < quotient->n; ++i) {
                quotient->c[i] *= scale;
            }
            quotient->c[shift] += factor;
        }
        --a.n;  // The leading term cancels by construction.
        trim(a);
    }
    return a;
}

/// Signed remainder sequence (p, s, -rem, ...) with positive scalings, and its sign
/// variations at a point: Var(lo) - Var(hi) is the Cauchy index of s / p on (lo, hi].
template <class N>
class RemainderSequence {
  public:
    RemainderSequence(const Poly<N>& p, const Poly<N>& s) {
        seq_[0] = p;
        size_ = 1;
        if (s.isZero()) {
            return;
        }
        seq_[size_++] = s;
        while (seq_[size_ - 1].degree() > 0) {
            Poly<N> r = remainder(seq_[size_ - 2], seq_[size_ - 1]);
            if (r.isZero()) {
                break;
            }
            seq_[size_++] = -r;
        }
    }
    const Poly<N>& last() const { return seq_[size_ - 1]; }
    int variations(const N& t) const {
        int count = 0, last = 0;
        for (int i = 0; i < size_; ++i) {
            const int sign = signAt(seq_[i], t);
            if (sign != 0) {
                count += last != 0 && sign != last;
                last = sign;
            }
        }
        return count;
    }

  private:
    std::array<Poly<N>, kMaxTerms + 1> seq_;
    int size_ = 0;
};

/// Halvings of a root's interval tried with interval evaluation before a Tarski query.
constexpr int kQuickHalvings = 16;

/// A time t*: exactly num / den (den > 0) when `exact`, otherwise the only root of the
/// squarefree polynomial `p` in the open interval (lo, hi), where p(lo), p(hi) != 0.
template <class N>
struct Time {
    Poly<N> p;
    N lo, hi;
    N num, den;
    bool exact = true;
    int sign_lo = 0;  ///< sign of p(lo) when not exact

    static Time at(const N& t) {
        Time r;
        r.num = t;
        r.den = 1;
        return r;
    }

    /// Halves the interval, or finds t* exactly at its midpoint.
    void bisect() {
        N m = midpoint(lo, hi);
        const int s = signAt(p, m);
        if (s == 0) {
            *this = at(m);
        } else if (s == sign_lo) {
            lo = std::move(m);
        } else {
            hi = std::move(m);
        }
    }

    /// Shrinks the interval to at most `width`.
    void refine(double width) {
        while (!exact && widerThan(lo, hi, width)) {
            bisect();
        }
        if constexpr (std::is_same_v<N, Interval>) {
            // An exact time of the interval pass is num / den with interval num and den:
            // nearly cancelling coefficients can leave that quotient wide, and toi (its lower
            // end) too early (issue 15's soak: toi 4/15 for a contact at ~2/5). Such a time
            // is refined in exact numbers.
            if (exact && upper() - lower() > width) {
                throw Uncertain{};
            }
        }
    }

    double lower() const { return exact ? lowerQuotient(num, den) : lowerQuotient(lo, N(1)); }
    double upper() const { return exact ? upperQuotient(num, den) : upperQuotient(hi, N(1)); }

    /// Sign of g(t*), exact (zero included). May narrow the interval.
    int sign(const Poly<N>& g) {
        if (exact) {
            return signAtQuotient(g, num, den);
        }
        // Cheap first: enclose g over the interval, halving it a few times.
        for (int i = 0; i < kQuickHalvings; ++i) {
            if (const std::optional<int> s = quickSign(g, lo, hi)) {
                return *s;
            }
            bisect();
            if (exact) {
                return signAtQuotient(g, num, den);
            }
        }
        const Poly<N> r = remainder(g, p);  // positive multiple of g mod p: r(t*) ~ g(t*)
        if (r.degree() <= 0) {
            return r.isZero() ? 0 : signOf(r.c[0]);
        }
        // Tarski query: t* is the only root of p in (lo, hi).
        const RemainderSequence<N> sequence(p, remainder(derivative(p) * r, p));
        return sequence.variations(lo) - sequence.variations(hi);
    }
};

/// Up to 3 times (the roots of a cubic), ascending.
template <class N>
struct Roots {
    std::array<Time<N>, 3> t;
    int n = 0;
    void push(Time<N>&& x) {
        assert(n < 3);
        t[n++] = std::move(x);
    }
};

/// Appends the roots of p in (lo, hi] (vlo, vhi: Sturm variations at lo, hi), ascending.
template <class N>
void isolate(const Poly<N>& p, const RemainderSequence<N>& sturm, const N& lo, int vlo, const N& hi,
             int vhi, Roots<N>& out) {
    const int count = vlo - vhi;  // Sturm: roots in (lo, hi], for any lo < hi
    if (count <= 0) {
        return;
    }
    if (count == 1) {
        if (signAt(p, hi) == 0) {
            out.push(Time<N>::at(hi));
            return;
        }
        if (const int s = signAt(p, lo)) {
            Time<N> t;
            t.p = p;
            t.lo = lo;
            t.hi = hi;
            t.exact = false;
            t.sign_lo = s;
            out.push(std::move(t));
            return;
        }
    }
    const N mid = midpoint(lo, hi);
    const int vmid = sturm.variations(mid);
    isolate(p, sturm, lo, vlo, mid, vmid, out);
    isolate(p, sturm, mid, vmid, hi, vhi, out);
}

/// Bernstein coefficients of p on [lo, hi], each times the positive C(n, i): the same
/// signs. They bound p on the interval, and their sign variations bound its roots there
/// (Descartes' rule): none means no root, one means exactly one.
template <class N>
std::array<N, kMaxTerms> bernstein(const Poly<N>& p, const N& lo, const N& hi) {
    const int n = p.degree();
    // Taylor coefficients at lo scaled to s in [0, 1]: p(lo + w s) = sum a_k s^k.
    std::array<N, kMaxTerms> a = p.c;
    for (int k = 0; k < n; ++k) {
        for (int i = n - 1; i >= k; --i) {
            a[i] += lo * a[i + 1];
        }
    }
    const N w = hi - lo;
    N scale = 1;
    for (int k = 1; k <= n; ++k) {
        scale *= w;
        a[k] *= scale;
    }
    // C(n, i) b_i = sum_{k <= i} C(n - k, i - k) a_k.
    static constexpr int kBinomial[kMaxTerms][kMaxTerms] = {
        {1, 0, 0, 0, 0}, {1, 1, 0, 0, 0}, {1, 2, 1, 0, 0}, {1, 3, 3, 1, 0}, {1, 4, 6, 4, 1}};
    std::array<N, kMaxTerms> b;
    for (int i = 0; i <= n; ++i) {
        b[i] = 0;
        for (int k = 0; k <= i; ++k) {
            b[i] += N(kBinomial[n - k][i - k]) * a[k];
        }
    }
    return b;
}

/// Appends the roots of p in the open (lo, hi), ascending; p(lo), p(hi) are not zero.
/// Bernstein subdivision: unlike a Sturm sequence it never divides by a coefficient, so it
/// suits interval coefficients (a nearly vanishing lead costs nothing).
void isolateBernstein(const Poly<Interval>& p, const Interval& lo, int sign_lo, const Interval& hi,
                      int sign_hi, int depth, Roots<Interval>& out) {
    const std::array<Interval, kMaxTerms> b = bernstein(p, lo, hi);
    int variations = 0, last = 0;
    bool certain = true;
    for (int i = 0; i <= p.degree() && certain; ++i) {
        if (b[i].lo > 0.0 || b[i].hi < 0.0) {
            const int s = b[i].lo > 0.0 ? 1 : -1;
            variations += last != 0 && s != last;
            last = s;
        } else if (!certainlyZero(b[i])) {
            certain = false;
        }
    }
    if (certain && variations == 0) {
        return;
    }
    if (certain && variations == 1) {
        Time<Interval> t;
        t.p = p;
        t.lo = lo;
        t.hi = hi;
        t.exact = false;
        t.sign_lo = sign_lo;
        out.push(std::move(t));
        return;
    }
    if (depth >= 64) {
        throw Uncertain{};  // Roots too close to separate in doubles.
    }
    // Split at a point where the sign of p is certain (at most 3 roots to avoid).
    for (const double fraction : {0.5, 0.25, 0.75, 0.375}) {
        const Interval m(lo.lo + fraction * (hi.hi - lo.lo));
        if (!(lo.hi < m.lo && m.hi < hi.lo)) {
            break;
        }
        const Interval value = eval(p, m);
        if (value.lo > 0.0 || value.hi < 0.0) {
            const int sign_m = value.lo > 0.0 ? 1 : -1;
            isolateBernstein(p, lo, sign_lo, m, sign_m, depth + 1, out);
            isolateBernstein(p, m, sign_m, hi, sign_hi, depth + 1, out);
            return;
        }
    }
    throw Uncertain{};
}

/// p / (t - r) for a root r of p (synthetic division, exact for exact numbers).
template <class N>
Poly<N> deflate(const Poly<N>& p, const N& r) {
    Poly<N> q;
    q.n = p.n - 1;
    N carry = 0;
    for (int i = p.n - 1; i >= 1; --i) {
        carry = p.c[i] + carry * r;
        q.c[i - 1] = carry;
    }
    trim(q);
    return q;
}

/// Real roots of `events` (neither zero nor constant) in [a, b], ascending, each once.
template <class N>
Roots<N> roots(const Poly<N>& events, const N& a, const N& b) {
    Roots<N> out;
    Poly<N> p = events;
    if (p.n == 2) {
        Time<N> t;
        const bool flip = signOf(p.c[1]) < 0;
        t.num = flip ? p.c[0] : N(-p.c[0]);
        t.den = flip ? N(-p.c[1]) : p.c[1];
        if (signOf(N(t.num - a * t.den)) >= 0 && signOf(N(b * t.den - t.num)) >= 0) {
            out.push(std::move(t));
        }
        return out;
    }
    if constexpr (std::is_same_v<N, Interval>) {
        // Roots exactly at an end are exact candidates; divide them out of the rest.
        int sign_a = signAt(p, a);
        const bool root_at_a = sign_a == 0;
        while (sign_a == 0 && p.n > 1) {
            p = deflate(p, a);
            sign_a = signAt(p, a);
        }
        if (root_at_a) {
            out.push(Time<N>::at(a));
        }
        if (signOf(N(b - a)) <= 0) {
            return out;
        }
        int sign_b = signAt(p, b);
        const bool root_at_b = sign_b == 0;
        while (sign_b == 0 && p.n > 1) {
            p = deflate(p, b);
            sign_b = signAt(p, b);
        }
        if (root_at_b) {
            // Dividing by (t - b), negative on [a, b), flipped the sign at a (issue 15: the
            // stale sign sent the bisection of an interior root to the wrong end).
            sign_a = signAt(p, a);
        }
        if (p.n >= 2) {
            isolateBernstein(p, a, sign_a, b, sign_b, 0, out);
        }
        if (root_at_b) {
            out.push(Time<N>::at(b));
        }
    } else {
        // Exact: a Sturm sequence, on the squarefree part (the sequence ends with
        // gcd(p, p'), constant unless p has a multiple root).
        std::optional<RemainderSequence<N>> sturm(std::in_place, p, derivative(p));
        if (sturm->last().degree() > 0) {
            Poly<N> q;
            remainder(p, sturm->last(), &q);
            p = q;
            if (p.n == 2) {
                return roots(p, a, b);
            }
            sturm.emplace(p, derivative(p));
        }
        if (signAt(p, a) == 0) {
            out.push(Time<N>::at(a));
        }
        if (signOf(N(b - a)) > 0) {
            isolate(p, *sturm, a, sturm->variations(a), b, sturm->variations(b), out);
        }
    }
    return out;
}

template <class N>
using PolyVec = std::array<Poly<N>, 3>;

/// The exact sum of a few doubles: an interval, tight around it (the exact point when it is
/// zero: offsets of vertices that move together must stay exactly constant).
template <class N>
N exactSum(std::initializer_list<double> terms) {
    if constexpr (std::is_same_v<N, Dyadic>) {
        Dyadic r;
        for (double x : terms) {
            r += Dyadic(x);
        }
        return r;
    } else {
        Interval r;
        for (double x : terms) {
            r += Interval(x);
        }
        if (r.lo <= 0.0 && r.hi >= 0.0 && !(r.lo == 0.0 && r.hi == 0.0)) {
            if (const std::optional<Interval> exact = toInterval(exactSum<Dyadic>(terms))) {
                return *exact;
            }
        }
        return r;
    }
}

/// x_j(t) - x_i(t) for vertices moving from i0 to i1 and from j0 to j1.
template <class N>
PolyVec<N> offset(const Vec3& i0, const Vec3& i1, const Vec3& j0, const Vec3& j1) {
    PolyVec<N> r;
    for (int k = 0; k < 3; ++k) {
        r[k].n = 2;
        r[k].c[0] = exactSum<N>({j0[k], -i0[k]});
        r[k].c[1] = exactSum<N>({j1[k], -i1[k], -j0[k], i0[k]});
        trim(r[k]);
    }
    return r;
}

template <class N>
PolyVec<N> cross(const PolyVec<N>& a, const PolyVec<N>& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

template <class N>
Poly<N> dot(const PolyVec<N>& a, const PolyVec<N>& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/// A vertex x against the closed segment [y, z] (static test at one time).
template <class N>
struct PointSegment {
    PolyVec<N> q;     ///< x - y
    PolyVec<N> line;  ///< (x - y) x (z - y): zero when x is on the segment's line
    Poly<N> ee, qe;   ///< |z - y|^2 and (x - y) . (z - y)

    /// q = x - y, e = z - y.
    PointSegment(const PolyVec<N>& x_minus_y, const PolyVec<N>& e) : q(x_minus_y) {
        line = cross(q, e);
        ee = dot(e, e);
        qe = dot(q, e);
    }
    bool touches(Time<N>& t) const {
        for (const Poly<N>& l : line) {
            if (t.sign(l) != 0) {
                return false;
            }
        }
        if (t.sign(ee) == 0) {  // Degenerate segment: x must be its point.
            for (const Poly<N>& d : q) {
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
template <class N>
class Earliest {
  public:
    Earliest(double a, double b, double tolerance) : a_(a), limit_(b), width_(tolerance) {}

    /// Tests the candidates (roots of `events` in [a, limit], or a alone when `events` is
    /// identically zero) in ascending order; keeps the first that `touches`.
    /// A contact at the start of the range was found: nothing can be earlier.
    bool settled() const { return found_ && best_ <= a_; }

    template <class Touches>
    void consider(const Poly<N>& events, Touches&& touches) {
        if (nonZeroConstant(events) || settled()) {
            return;
        }
        Roots<N> times;
        if (events.isZero()) {
            times.push(Time<N>::at(N(a_)));
        } else {
            times = roots(events, N(a_), N(limit_));
        }
        for (int i = 0; i < times.n; ++i) {
            Time<N>& t = times.t[i];
            if (touches(t)) {
                t.refine(width_);
                const double lo = std::max(t.lower(), a_);
                best_ = found_ ? std::min(best_, lo) : lo;
                limit_ = std::min(limit_, t.upper());
                found_ = true;
                return;
            }
        }
    }

    ExactContact result() const {
        ExactContact r;
        r.hit = found_;
        if (found_) {
            r.toi = best_;
        }
        return r;
    }

  private:
    double a_, limit_, width_, best_ = 1.0;
    bool found_ = false;
};

/// The first component that is not identically zero (or zero): its roots include every
/// common root of the components, which is all the candidates need.
template <class N>
Poly<N> firstNonZero(const PolyVec<N>& v) {
    for (const Poly<N>& c : v) {
        if (!c.isZero()) {
            return c;
        }
    }
    return {};
}

/// Candidates of coplanar motion: a, vertex-on-edge-line and vertex-on-vertex events.
template <class N, size_t kPairs, size_t kVertexPairs, class Touches>
void considerCoplanarMotion(Earliest<N>& earliest, const std::array<PointSegment<N>, kPairs>& pairs,
                            const std::array<PolyVec<N>, kVertexPairs>& vertex_offsets,
                            Touches&& touches) {
    earliest.consider(Poly<N>{}, touches);
    for (const PointSegment<N>& ps : pairs) {
        const Poly<N> events = firstNonZero(ps.line);
        if (!events.isZero()) {  // Identically on the line: enters through an end point.
            earliest.consider(events, touches);
        }
    }
    for (const PolyVec<N>& d : vertex_offsets) {
        const Poly<N> events = firstNonZero(d);
        if (!events.isZero()) {  // Identically together: a, considered above.
            earliest.consider(events, touches);
        }
    }
}

template <class N>
[[gnu::noinline]] ExactContact vertexFace(const std::array<Vec3, 4>& start,
                                          const std::array<Vec3, 4>& end, double t_lo, double t_hi,
                                          double toi_tolerance) {
    // p = vertex 0 against the triangle a, b, c = vertices 1, 2, 3.
    auto from = [&](int i, int j) { return offset<N>(start[i], end[i], start[j], end[j]); };
    const PolyVec<N> q = from(1, 0), e1 = from(1, 2), e2 = from(1, 3);
    const Poly<N> coplanar = dot(cross(e1, e2), q);
    Earliest<N> earliest(t_lo, t_hi, toi_tolerance);
    if (nonZeroConstant(coplanar)) {
        return earliest.result();  // Never coplanar.
    }
    // Barycentric coordinates times nn = |e1 x e2|^2, by Binet-Cauchy, when first needed.
    struct Barycentric {
        Poly<N> nn, u, v, w;
    };
    std::optional<Barycentric> barycentric;
    auto makeBarycentric = [&]() -> const Barycentric& {
        if (!barycentric) {
            const Poly<N> d11 = dot(e1, e1), d12 = dot(e1, e2), d22 = dot(e2, e2);
            const Poly<N> dq1 = dot(q, e1), dq2 = dot(q, e2);
            Barycentric b;
            b.nn = d11 * d22 - d12 * d12;
            b.u = dq1 * d22 - dq2 * d12;
            b.v = d11 * dq2 - d12 * dq1;
            b.w = b.nn - b.u - b.v;
            barycentric = std::move(b);
        }
        return *barycentric;
    };
    std::optional<std::array<PointSegment<N>, 3>> edges;
    auto makeEdges = [&]() -> const std::array<PointSegment<N>, 3>& {
        if (!edges) {
            edges.emplace(std::array<PointSegment<N>, 3>{PointSegment<N>(q, e1),
                                                         PointSegment<N>(from(2, 0), from(2, 3)),
                                                         PointSegment<N>(from(3, 0), from(3, 1))});
        }
        return *edges;
    };
    auto touches = [&](Time<N>& t) {
        // Called only where p is in the triangle's plane.
        const Barycentric& b = makeBarycentric();
        if (t.sign(b.nn) > 0) {
            return t.sign(b.u) >= 0 && t.sign(b.v) >= 0 && t.sign(b.w) >= 0;
        }
        // Degenerate triangle: a segment (or a point), the union of its edges.
        for (const PointSegment<N>& edge : makeEdges()) {
            if (edge.touches(t)) {
                return true;
            }
        }
        return false;
    };
    if (!coplanar.isZero()) {
        earliest.consider(coplanar, touches);
    } else {
        const auto& e = makeEdges();
        considerCoplanarMotion(earliest, e, std::array<PolyVec<N>, 3>{e[0].q, e[1].q, e[2].q},
                               touches);
    }
    return earliest.result();
}

template <class N>
[[gnu::noinline]] ExactContact edgeEdge(const std::array<Vec3, 4>& start,
                                        const std::array<Vec3, 4>& end, double t_lo, double t_hi,
                                        double toi_tolerance) {
    // Edge a0 a1 = vertices 0, 1 against edge b0 b1 = vertices 2, 3.
    auto from = [&](int i, int j) { return offset<N>(start[i], end[i], start[j], end[j]); };
    const PolyVec<N> ea = from(0, 1), eb = from(2, 3), r = from(0, 2);
    const Poly<N> coplanar = dot(cross(ea, eb), r);
    Earliest<N> earliest(t_lo, t_hi, toi_tolerance);
    if (nonZeroConstant(coplanar)) {
        return earliest.result();  // Never coplanar.
    }
    // Where coplanar and not parallel: a0 + s ea = b0 + w eb with s = sa / nn, w = sb / nn,
    // nn = |ea x eb|^2, by Binet-Cauchy, when first needed.
    struct Crossing {
        Poly<N> nn, sa, sa_rest, sb, sb_rest;
    };
    std::optional<Crossing> crossing;
    auto makeCrossing = [&]() -> const Crossing& {
        if (!crossing) {
            const Poly<N> daa = dot(ea, ea), dab = dot(ea, eb), dbb = dot(eb, eb);
            const Poly<N> dra = dot(r, ea), drb = dot(r, eb);
            Crossing c;
            c.nn = daa * dbb - dab * dab;
            c.sa = dra * dbb - drb * dab;
            c.sb = dra * dab - drb * daa;
            c.sa_rest = c.nn - c.sa;
            c.sb_rest = c.nn - c.sb;
            crossing = std::move(c);
        }
        return *crossing;
    };
    std::optional<std::array<PointSegment<N>, 4>> ends;
    auto makeEnds = [&]() -> const std::array<PointSegment<N>, 4>& {
        if (!ends) {
            ends.emplace(std::array<PointSegment<N>, 4>{
                PointSegment<N>(from(2, 0), eb), PointSegment<N>(from(2, 1), eb),
                PointSegment<N>(r, ea), PointSegment<N>(from(0, 3), ea)});
        }
        return *ends;
    };
    auto touches = [&](Time<N>& t) {
        // Called only where the edges are coplanar.
        const Crossing& c = makeCrossing();
        if (t.sign(c.nn) > 0) {
            return t.sign(c.sa) >= 0 && t.sign(c.sa_rest) >= 0 && t.sign(c.sb) >= 0 &&
                   t.sign(c.sb_rest) >= 0;
        }
        // Parallel or degenerate: they touch iff an end point lies on the other edge.
        for (const PointSegment<N>& end_point : makeEnds()) {
            if (end_point.touches(t)) {
                return true;
            }
        }
        return false;
    };
    if (!coplanar.isZero()) {
        earliest.consider(coplanar, touches);
    } else {
        considerCoplanarMotion(
            earliest, makeEnds(),
            std::array<PolyVec<N>, 4>{from(2, 0), from(3, 0), from(2, 1), from(3, 1)}, touches);
    }
    return earliest.result();
}

}  // namespace

ExactContact vertexFaceExact(const std::array<Vec3, 4>& start, const std::array<Vec3, 4>& end,
                             double t_lo, double t_hi, double toi_tolerance,
                             Arithmetic arithmetic) {
    assert(0.0 < toi_tolerance && toi_tolerance <= 1.0 && 0.0 <= t_lo && t_lo <= t_hi &&
           t_hi <= 1.0);
    // Both passes need upward rounding (the exact one filters with intervals too); they are
    // not inlined, so no floating-point operation can move across the mode switch.
    const UpwardRounding upward;
    if (arithmetic == Arithmetic::kFiltered) {
        try {
            return vertexFace<Interval>(start, end, t_lo, t_hi, toi_tolerance);
        } catch (const Uncertain&) {
        }
    }
    return vertexFace<Dyadic>(start, end, t_lo, t_hi, toi_tolerance);
}

ExactContact edgeEdgeExact(const std::array<Vec3, 4>& start, const std::array<Vec3, 4>& end,
                           double t_lo, double t_hi, double toi_tolerance, Arithmetic arithmetic) {
    assert(0.0 < toi_tolerance && toi_tolerance <= 1.0 && 0.0 <= t_lo && t_lo <= t_hi &&
           t_hi <= 1.0);
    const UpwardRounding upward;
    if (arithmetic == Arithmetic::kFiltered) {
        try {
            return edgeEdge<Interval>(start, end, t_lo, t_hi, toi_tolerance);
        } catch (const Uncertain&) {
        }
    }
    return edgeEdge<Dyadic>(start, end, t_lo, t_hi, toi_tolerance);
}

}  // namespace kolize::ccd::detail
