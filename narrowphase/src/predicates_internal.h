#pragma once
// Pieces of the predicates shared with the triangle test (private to the narrowphase core):
// the filters' error constants and the exact stages behind them.

#include "kolize/narrowphase/predicates.h"

#include <cmath>

namespace kolize::narrowphase::detail {

/// Half an ulp of 1: the unit roundoff of double.
constexpr double kEpsilon = 0x1p-53;
/// Shewchuk's a-priori bounds: |computed - exact| <= bound * permanent.
constexpr double kOrient3dBound = (7.0 + 56.0 * kEpsilon) * kEpsilon;
constexpr double kOrient2dBound = (3.0 + 16.0 * kEpsilon) * kEpsilon;
/// Products that underflow lose up to 2^-1075 each, which no relative bound covers. This
/// absolute guard (times 1 + the largest factor sum) is far above that and far below any
/// determinant of coordinates in the expansion's range, so it never costs a decision there.
constexpr double kUnderflowGuard = 0x1p-1000;

/// The exact stages of orient3d (expansion, then GMP), counting the stage that decided.
int orient3dExact(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d,
                  PredicateStats* stats);
/// The exact stages of orient2d.
int orient2dExact(double ax, double ay, double bx, double by, double cx, double cy,
                  PredicateStats* stats);

/// orient3d(a, b, c, d) for one plane (a, b, c) against many points d: the plane's normal
/// minors are computed once. The filter is the same as orient3d's: det = (d - a) . n with
/// n = (b - a) x (c - a), each product rounded once, which has Shewchuk's orient3d shape
/// (a sum of three coordinate-times-2x2-minor terms), so kOrient3dBound holds.
class PlaneSide {
  public:
    /// Uninitialised: to be assigned a plane before use.
    PlaneSide() {}
    PlaneSide(const Vec3& a, const Vec3& b, const Vec3& c) : a_(a), b_(b), c_(c) {
        const double bx = b.x() - a.x(), by = b.y() - a.y(), bz = b.z() - a.z();
        const double cx = c.x() - a.x(), cy = c.y() - a.y(), cz = c.z() - a.z();
        const double p0 = by * cz, q0 = bz * cy;
        const double p1 = bz * cx, q1 = bx * cz;
        const double p2 = bx * cy, q2 = by * cx;
        n_[0] = p0 - q0;
        n_[1] = p1 - q1;
        n_[2] = p2 - q2;
        permanent_[0] = std::fabs(p0) + std::fabs(q0);
        permanent_[1] = std::fabs(p1) + std::fabs(q1);
        permanent_[2] = std::fabs(p2) + std::fabs(q2);
    }

    /// Exact sign of orient3d(a, b, c, d).
    int side(const Vec3& d, PredicateStats* stats) const {
        const double dx = d.x() - a_.x(), dy = d.y() - a_.y(), dz = d.z() - a_.z();
        const double det = (dx * n_[0] + dy * n_[1]) + dz * n_[2];
        const double adx = std::fabs(dx), ady = std::fabs(dy), adz = std::fabs(dz);
        const double permanent = (adx * permanent_[0] + ady * permanent_[1]) + adz * permanent_[2];
        const double bound = kOrient3dBound * permanent + kUnderflowGuard * (1.0 + adx + ady + adz);
        if (det > bound) {
            count(stats);
            return 1;
        }
        if (-det > bound) {
            count(stats);
            return -1;
        }
        return orient3dExact(a_, b_, c_, d, stats);
    }

    /// The normal (b - a) x (c - a) as computed in double (not exact).
    Vec3 normal() const { return {n_[0], n_[1], n_[2]}; }

  private:
    static void count(PredicateStats* stats) {
        if (stats != nullptr) {
            ++stats->orient3d[0];
        }
    }
    Vec3 a_, b_, c_;
    double n_[3];
    double permanent_[3];
};

}  // namespace kolize::narrowphase::detail
