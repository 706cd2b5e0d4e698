#pragma once
// A minimal exact rational (GMP mpq_t) with the operators the containment checks need
// (private to the narrowphase core; the C API keeps the library free of libgmpxx).

#include <gmp.h>

namespace kolize::narrowphase::detail {

class Rational {
  public:
    Rational() { mpq_init(q_); }
    Rational(double x) {  // NOLINT: implicit on purpose, every double is exact
        mpq_init(q_);
        mpq_set_d(q_, x);
    }
    Rational(const Rational& other) {
        mpq_init(q_);
        mpq_set(q_, other.q_);
    }
    Rational& operator=(const Rational& other) {
        mpq_set(q_, other.q_);
        return *this;
    }
    ~Rational() { mpq_clear(q_); }

    friend Rational operator+(const Rational& a, const Rational& b) {
        Rational r;
        mpq_add(r.q_, a.q_, b.q_);
        return r;
    }
    friend Rational operator-(const Rational& a, const Rational& b) {
        Rational r;
        mpq_sub(r.q_, a.q_, b.q_);
        return r;
    }
    friend Rational operator*(const Rational& a, const Rational& b) {
        Rational r;
        mpq_mul(r.q_, a.q_, b.q_);
        return r;
    }
    Rational abs() const {
        Rational r;
        mpq_abs(r.q_, q_);
        return r;
    }
    int sign() const { return mpq_sgn(q_); }
    friend bool operator<=(const Rational& a, const Rational& b) {
        return mpq_cmp(a.q_, b.q_) <= 0;
    }

  private:
    mpq_t q_;
};

}  // namespace kolize::narrowphase::detail
