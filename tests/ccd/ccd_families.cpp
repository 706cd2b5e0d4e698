#include "ccd_families.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <utility>

namespace kolize::ccd::families {
namespace {

namespace ref = kolize::ccd::reference;

/// SplitMix64: decorrelates (seed, index) pairs into generator seeds.
uint64_t mix(uint64_t x) {
    x += 0x9e3779b97f4a7c15ull;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    return x ^ (x >> 31);
}

class Random {
  public:
    explicit Random(uint64_t seed) : rng_(seed) {}
    int uniform(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }
    bool chance(int percent) { return uniform(0, 99) < percent; }
    template <class T>
    const T& pick(const std::vector<T>& v) {
        return v[uniform(0, static_cast<int>(v.size()) - 1)];
    }
    /// k / 2 for k in [-2 range, 2 range].
    double half(int range = 2) { return 0.5 * uniform(-2 * range, 2 * range); }
    Vec3 halves(int range = 2) { return Vec3(half(range), half(range), half(range)); }
    Vec3 unitGrid() { return Vec3(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)); }
    /// A double in [0, 1) with a full mantissa, and one in [-1, 1).
    double unit() { return std::uniform_real_distribution<double>(0.0, 1.0)(rng_); }
    double real() { return 2.0 * unit() - 1.0; }

  private:
    std::mt19937_64 rng_;
};

using Points = std::array<Vec3, 4>;

/// End positions: each vertex keeps still, shares the previous vertex's motion or moves
/// anywhere on the grid, so coplanar and parallel motion and shared points are common.
template <class Grid>
Points endsFor(Random& r, const Points& start, Grid&& grid) {
    Points end;
    for (int i = 0; i < 4; ++i) {
        const int motion = r.uniform(0, 3);
        end[i] = motion == 0            ? start[i]
                 : motion == 1 && i > 0 ? Vec3(start[i] + (end[i - 1] - start[i - 1]))
                                        : grid();
    }
    return end;
}

void gridQuery(Random& r, Query& q, bool unit) {
    auto grid = [&] { return unit ? r.unitGrid() : r.halves(); };
    for (Vec3& p : q.start) {
        p = grid();
    }
    q.end = endsFor(r, q.start, grid);
}

void coplanarMotion(Random& r, Query& q) {
    Vec3 u = r.unitGrid(), v = r.unitGrid();
    if (r.chance(80)) {  // mostly a proper plane; sometimes a line or a point
        while (u.cross(v).isZero()) {
            u = r.unitGrid();
            v = r.unitGrid();
        }
    }
    const Vec3 origin = r.halves(), shift = r.chance(50) ? Vec3::Zero() : r.halves();
    for (int i = 0; i < 4; ++i) {
        const double a = r.half(), b = r.half();
        q.start[i] = origin + a * u + b * v;
        const bool still = r.chance(30);
        q.end[i] = origin + shift + (still ? a : r.half()) * u + (still ? b : r.half()) * v;
    }
}

void parallelAtEnd(Random& r, Query& q) {
    for (Vec3& p : q.start) {
        p = r.halves();
    }
    const double k = r.pick(std::vector<double>{-1, -0.5, 0.5, 1, 2, 0});
    if (q.kind == Kind::kEdgeEdge) {
        q.end[0] = r.halves();
        q.end[1] = r.halves();
        q.end[2] = r.chance(30) ? Vec3(q.end[0] + r.half() * (q.end[1] - q.end[0]))
                                : r.halves();  // collinear or merely parallel
        q.end[3] = q.end[2] + k * (q.end[1] - q.end[0]);
    } else {  // the triangle degenerates to a segment (or a point) at the end
        q.end[0] = r.halves();
        q.end[1] = r.halves();
        q.end[2] = r.halves();
        q.end[3] = q.end[1] + k * (q.end[2] - q.end[1]);
    }
    if (r.chance(30)) {
        std::swap(q.start, q.end);  // parallel at the start instead
    }
}

/// Positions touching at time tc (vertex on the closed triangle, or the segments meeting),
/// with grid velocities: start = contact - tc v, end = start + v, all exact.
void touchAt(Random& r, Query& q, double tc, bool zero_motion, int first_still = 4) {
    Points contact;
    if (q.kind == Kind::kVertexFace) {
        for (int i = 1; i < 4; ++i) {
            contact[i] = r.halves();
        }
        static const std::vector<std::array<double, 3>> kWeights{
            {1, 0, 0},         {0, 1, 0},           {0, 0, 1},        {0.5, 0.5, 0},
            {0.25, 0.75, 0},   {0, 0.25, 0.75},     {0.5, 0, 0.5},    {0.25, 0.25, 0.5},
            {0.5, 0.25, 0.25}, {0.125, 0.375, 0.5}, {1.25, -0.25, 0}, {0.5, 0.75, -0.25}};
        const auto& w = r.pick(kWeights);  // the last two: just outside, on an edge's line
        contact[0] = w[0] * contact[1] + w[1] * contact[2] + w[2] * contact[3];
    } else {
        contact[0] = r.halves();
        contact[1] = r.halves();
        const double s = r.pick(std::vector<double>{0, 0.25, 0.5, 0.75, 1, -0.25});
        const Vec3 x = contact[0] + s * (contact[1] - contact[0]);
        const Vec3 d = r.chance(20) ? Vec3(r.half() * (contact[1] - contact[0])) : r.halves();
        const double along = r.pick(std::vector<double>{0, 0.25, 0.5, 1});
        contact[2] = x - along * d;
        contact[3] = x + (1 - along) * d;
    }
    if (zero_motion) {
        q.start = q.end = contact;
        return;
    }
    for (int i = 0; i < 4; ++i) {
        const int motion = i >= first_still ? 0 : r.uniform(0, 3);
        const Vec3 v = motion == 0 ? Vec3::Zero() : r.halves();
        q.start[i] = contact[i] - tc * v;
        q.end[i] = q.start[i] + v;
    }
    if (first_still == 4 && r.chance(25)) {  // several vertices share one motion
        const Vec3 v = q.end[1] - q.start[1];
        for (int i = 2; i < 4; ++i) {
            q.start[i] = contact[i] - tc * v;
            q.end[i] = q.start[i] + v;
        }
    }
}

double eighth(Random& r) {
    const int k = r.chance(40) ? r.pick(std::vector<int>{0, 8}) : r.uniform(0, 8);
    return k / 8.0;
}

void nearMiss(Random& r, Query& q) {
    touchAt(r, q, eighth(r), r.chance(10));
    const int nudges = r.uniform(1, 3);
    for (int n = 0; n < nudges; ++n) {
        const int i = r.uniform(0, 3), k = r.uniform(0, 2), side = r.uniform(0, 2);
        const int ulps = r.uniform(1, 3);
        const double towards = r.chance(50) ? INFINITY : -INFINITY;
        for (int s = 0; s < 2; ++s) {
            if (side == 2 || side == s) {
                double& x = (s ? q.end : q.start)[i][k];
                for (int u = 0; u < ulps; ++u) {
                    x = std::nextafter(x, towards);
                }
            }
        }
    }
}

/// The coplanarity polynomial has a double root at tc: B turns about A (edge-edge), or the
/// triangle turns about its edge ab while the vertex meets its plane tangentially.
void tangential(Random& r, Query& q, double tc) {
    const double sigma = r.pick(std::vector<double>{-2, -1, -0.5, 0.5, 1, 2});
    const double tau = r.pick(std::vector<double>{-2, -1, -0.5, 0.5, 1, 2});
    auto at = [&](const Vec3& base, const Vec3& rate, int side) {
        return Vec3(base + (side - tc) * rate);
    };
    if (q.kind == Kind::kEdgeEdge) {
        // A on the x axis; b0 = (u0, s sigma, h), b1 = (u1, 0, s tau) with s = t - tc:
        // coplanarity sigma tau s^2 (times A's length); b1 meets A's line at tc.
        const double a0 = r.half(), a1 = a0 + r.uniform(1, 4) * 0.5;
        const double u0 = r.half(), u1 = r.half(), h = r.pick(std::vector<double>{-1, 0.5, 1, 2});
        for (int side = 0; side < 2; ++side) {
            Points& p = side ? q.end : q.start;
            p[0] = Vec3(a0, 0, 0);
            p[1] = Vec3(a1, 0, 0);
            p[2] = at(Vec3(u0, 0, h), Vec3(0, sigma, 0), side);
            p[3] = at(Vec3(u1, 0, 0), Vec3(0, 0, tau), side);
        }
    } else {
        // a, b on the x axis, c = (cx, 1, s tau): the plane is z = s tau y. The vertex
        // p = (px, y0 + s sigma, s tau y0) meets it where -tau sigma s^2 = 0.
        const double ax = r.half(), bx = ax + r.uniform(1, 4) * 0.5, cx = r.half();
        const double px = r.half(), y0 = r.pick(std::vector<double>{0, 0.25, 0.5, 1, -0.25});
        for (int side = 0; side < 2; ++side) {
            Points& p = side ? q.end : q.start;
            p[0] = at(Vec3(px, y0, 0), Vec3(0, sigma, tau * y0), side);
            p[1] = Vec3(ax, 0, 0);
            p[2] = Vec3(bx, 0, 0);
            p[3] = at(Vec3(cx, 1, 0), Vec3(0, 0, tau), side);
        }
    }
}

/// Edge A (or the triangle) collapses to a point x at tc; the other primitive passes
/// through x at tc, or beside it.
void hourglass(Random& r, Query& q, double tc) {
    const Vec3 x = r.halves(), miss = r.chance(40) ? Vec3(r.halves(1) * 0.25) : Vec3::Zero();
    std::array<Vec3, 4> rate;
    for (Vec3& v : rate) {
        v = r.halves();
    }
    if (q.kind == Kind::kEdgeEdge) {
        rate[1] = -rate[0];  // a0, a1 swap places through x
        const Vec3 d = r.halves(), v = r.halves();
        const double along = r.pick(std::vector<double>{0, 0.5, 0.25, 1});
        for (int side = 0; side < 2; ++side) {
            Points& p = side ? q.end : q.start;
            p[0] = x + (side - tc) * rate[0];
            p[1] = x + (side - tc) * rate[1];
            p[2] = x + miss - along * d + (side - tc) * v;
            p[3] = x + miss + (1 - along) * d + (side - tc) * v;
        }
    } else {
        for (int side = 0; side < 2; ++side) {
            Points& p = side ? q.end : q.start;
            p[0] = x + miss + (side - tc) * rate[0];
            for (int i = 1; i < 4; ++i) {
                p[i] = x + (side - tc) * rate[i];
            }
        }
    }
}

/// Uniform doubles with full mantissas: contacts and misses the floating-point stage can
/// mostly certify.
void generic(Random& r, Query& q) {
    auto point = [&] { return Vec3(r.real(), r.real(), r.real()); };
    for (Vec3& p : q.start) {
        p = point();
    }
    for (int i = 0; i < 4; ++i) {
        q.end[i] = r.chance(25) ? q.start[i] : Vec3(q.start[i] + 0.75 * point());
    }
}

/// A generic contact at a random time, then moved off it by a relative distance from 1e-6
/// down to 1e-17 (or not at all): the floating-point stage's certificates at their limits.
void genericNear(Random& r, Query& q) {
    const double tc = r.unit();
    Points contact;
    for (Vec3& p : contact) {
        p = Vec3(r.real(), r.real(), r.real());
    }
    if (q.kind == Kind::kVertexFace) {
        double u = r.unit(), v = r.unit();
        if (u + v > 1) {
            u = 1 - u;
            v = 1 - v;
        }
        if (r.chance(20)) {
            v = r.chance(50) ? 0.0 : 1.0 - u;  // on an edge
        }
        contact[0] = contact[1] + u * (contact[2] - contact[1]) + v * (contact[3] - contact[1]);
    } else {
        const double s = r.chance(20) ? 0.0 : r.unit(), w = r.unit();
        const Vec3 x = contact[0] + s * (contact[1] - contact[0]);
        const Vec3 d = contact[3] - contact[2];
        contact[2] = x - w * d;
        contact[3] = x + (1 - w) * d;
    }
    const double distance =
        r.pick(std::vector<double>{0, 1e-6, 1e-9, 1e-12, 1e-14, 1e-15, 1e-16, 1e-17});
    contact[0] += distance * Vec3(r.real(), r.real(), r.real());
    for (int i = 0; i < 4; ++i) {
        const Vec3 v = r.chance(25) ? Vec3::Zero() : Vec3(r.real(), r.real(), r.real());
        q.start[i] = contact[i] - tc * v;
        q.end[i] = q.start[i] + v;
    }
}

/// An exact grid contact at time k/8 with the vertex (vertex-face) or edge B (edge-edge)
/// kept still, moved so that the vertex (or b0) is the origin, and that point moved off by
/// a gap of 2^-30 ... 2^-110 (or not at all): near misses and touches below double and near
/// double-double resolution, exact in the input (a coordinate 0 + 2^-k is a double).
void tinyGap(Random& r, Query& q) {
    const int first_still = q.kind == Kind::kVertexFace ? 0 : 2;
    touchAt(r, q, eighth(r), false, first_still);
    const Vec3 shift = -q.start[first_still];  // a grid point: the shift is exact
    for (Points* side : {&q.start, &q.end}) {
        for (Vec3& p : *side) {
            p += shift;
        }
    }
    const int k = r.pick(std::vector<int>{30, 50, 60, 70, 80, 90, 100, 110});
    if (r.chance(85)) {
        const Vec3 gap(std::ldexp(r.uniform(-1, 1), -k), std::ldexp(r.uniform(-1, 1), -k),
                       std::ldexp(r.uniform(-1, 1), -k));
        q.start[first_still] = q.end[first_still] = gap;
    }
}

/// A random symmetry of the grid (axis permutation and sign flips): exact.
void permuteAxes(Random& r, Query& q) {
    std::array<int, 3> axis{0, 1, 2};
    for (int i = 2; i > 0; --i) {
        std::swap(axis[i], axis[r.uniform(0, i)]);
    }
    const Vec3 sign(r.chance(50) ? 1 : -1, r.chance(50) ? 1 : -1, r.chance(50) ? 1 : -1);
    for (Points* side : {&q.start, &q.end}) {
        for (Vec3& p : *side) {
            p = Vec3(sign[0] * p[axis[0]], sign[1] * p[axis[1]], sign[2] * p[axis[2]]);
        }
    }
}

void scaleBy(Query& q, int exponent) {
    for (Points* side : {&q.start, &q.end}) {
        for (Vec3& p : *side) {
            for (int k = 0; k < 3; ++k) {
                p[k] = std::ldexp(p[k], exponent);
            }
        }
    }
}

RobustSettings withArithmetic(RobustArithmetic arithmetic) {
    RobustSettings s;
    s.arithmetic = arithmetic;
    return s;
}

/// The certified stage brackets contacts more coarsely or as finely as a double allows.
RobustSettings withToiTolerance(double tolerance) {
    RobustSettings s;
    s.toi_tolerance = tolerance;
    return s;
}

/// The inclusion search hands its first box to the exact stage.
RobustSettings withExactHandOff(RobustArithmetic arithmetic) {
    RobustSettings s = withArithmetic(arithmetic);
    s.max_boxes = 1;
    return s;
}

/// The inclusion search goes deep before the exact stage.
RobustSettings withFineSearch() {
    RobustSettings s = withArithmetic(RobustArithmetic::kSearchThenExact);
    s.tolerance = 1e-8;
    return s;
}

}  // namespace

const std::vector<std::string>& familyNames() {
    static const std::vector<std::string> kNames{
        "grid-halves",  "grid-unit",       "coplanar-motion", "parallel-at-end",
        "touch-at-k/8", "zero-motion",     "near-miss-ulps",  "tangential-double-root",
        "hourglass",    "touch-at-0-or-1", "generic",         "generic-near",
        "tiny-gap"};
    return kNames;
}

Query generate(uint64_t seed, uint64_t index, int family) {
    Random r(mix(mix(seed) ^ index));
    Query q;
    q.family = family >= 0 ? family : r.uniform(0, static_cast<int>(familyNames().size()) - 1);
    q.kind = r.chance(50) ? Kind::kVertexFace : Kind::kEdgeEdge;
    switch (q.family) {
        case 0:
            gridQuery(r, q, false);
            break;
        case 1:
            gridQuery(r, q, true);
            break;
        case 2:
            coplanarMotion(r, q);
            break;
        case 3:
            parallelAtEnd(r, q);
            break;
        case 4:
            touchAt(r, q, eighth(r), false);
            break;
        case 5:
            if (r.chance(50)) {
                touchAt(r, q, 0, true);
            } else {
                gridQuery(r, q, r.chance(50));
                q.end = q.start;
            }
            break;
        case 6:
            nearMiss(r, q);
            break;
        case 7:
            tangential(r, q, eighth(r));
            break;
        case 8:
            hourglass(r, q, eighth(r));
            break;
        case 9:
            touchAt(r, q, r.chance(50) ? 0.0 : 1.0, false);
            break;
        case 10:
            generic(r, q);
            break;
        case 11:
            genericNear(r, q);
            break;
        default:
            tinyGap(r, q);
            break;
    }
    permuteAxes(r, q);
    // The time range: mostly the whole step, often one that starts or ends on a k/8.
    const int window = r.uniform(0, 9);
    if (window >= 7) {
        int k0 = r.uniform(0, 8), k1 = r.uniform(0, 8);
        if (k0 > k1) {
            std::swap(k0, k1);
        }
        q.min_time = window == 8 ? 0.0 : k0 / 8.0;
        q.max_time = window == 7 ? 1.0 : k1 / 8.0;
    }
    if (r.chance(15)) {
        q.offset = true;
        const Vec3 offset(r.chance(50) ? 1e10 : -1e10, r.chance(50) ? 1e10 : -1e10,
                          r.chance(50) ? 1e10 : -1e10);
        for (Points* side : {&q.start, &q.end}) {
            for (Vec3& p : *side) {
                p += offset;
            }
        }
    }
    if (r.chance(50)) {
        q.scale_exponent = r.pick(
            std::vector<int>{-1060, -1040, -1000, -700, -300, -60, -30, 30, 60, 300, 500, 600});
        scaleBy(q, q.scale_exponent);
    }
    return q;
}

const std::vector<Mode>& modes() {
    static const std::vector<Mode> kModes{
        {"certified", RobustSettings{}},
        {"certified-coarse-toi", withToiTolerance(0.25)},
        {"certified-finest-toi", withToiTolerance(0x1p-52)},
        {"search-then-exact", withArithmetic(RobustArithmetic::kSearchThenExact)},
        {"search-exact-hand-off", withExactHandOff(RobustArithmetic::kSearchThenExact)},
        {"search-fine", withFineSearch()},
        {"exact-only", withArithmetic(RobustArithmetic::kExactOnly)}};
    return kModes;
}

reference::Decision decide(const Query& q) {
    // The reference searches the same (clamped) range as the robust method.
    const mpq_class lo = ref::exact(q.min_time), hi = ref::exact(q.max_time);
    if (lo > hi) {
        return {};
    }
    return q.kind == Kind::kVertexFace ? ref::vertexFace(q.start, q.end, lo, hi)
                                       : ref::edgeEdge(q.start, q.end, lo, hi);
}

std::optional<std::string> check(const Query& q, const Mode& mode, reference::Decision& d,
                                 CcdResult* result) {
    RobustSettings s = mode.settings;
    s.min_time = q.min_time;
    s.max_time = q.max_time;
    const CcdResult r = q.kind == Kind::kVertexFace ? vertexFaceRobust({q.start, q.end}, s)
                                                    : edgeEdgeRobust({q.start, q.end}, s);
    if (result) {
        *result = r;
    }
    char buffer[200];
    if (r.hit != d.hit()) {
        std::snprintf(buffer, sizeof buffer, "%s (reference: %s)",
                      r.hit ? "false positive" : "false negative",
                      d.hit() ? "contact" : "no contact");
        return std::string(buffer);
    }
    if (!r.hit) {
        return std::nullopt;
    }
    const double tolerance = std::max(s.toi_tolerance, 0x1p-52);
    const mpq_class toi = ref::exact(r.toi);
    if (!d.atMostEarliest(toi)) {
        std::snprintf(buffer, sizeof buffer, "late: toi %.17g > t* ~ %.17g", r.toi,
                      d.earliestApproximation());
        return std::string(buffer);
    }
    if (!d.atLeastEarliest(toi + ref::exact(tolerance))) {
        std::snprintf(buffer, sizeof buffer, "too early: toi %.17g + %g < t* ~ %.17g", r.toi,
                      tolerance, d.earliestApproximation());
        return std::string(buffer);
    }
    return std::nullopt;
}

Query shrink(const Query& q, const Mode& mode) {
    auto fails = [&](const Query& candidate) {
        try {
            reference::Decision d = decide(candidate);
            return check(candidate, mode, d).has_value();
        } catch (const std::exception&) {
            return false;  // a simplification must stay a valid query
        }
    };
    Query best = q;
    int budget = 400;  // attempts: shrinking is a courtesy, it must not stall a failing run
    auto attempt = [&](Query candidate) {
        if (--budget < 0) {
            return false;
        }
        if (fails(candidate)) {
            best = std::move(candidate);
            return true;
        }
        return false;
    };
    if (best.scale_exponent != 0) {
        Query c = best;
        scaleBy(c, -c.scale_exponent);
        c.scale_exponent = 0;
        attempt(c);
    }
    if (best.min_time != 0.0 || best.max_time != 1.0) {
        Query c = best;
        c.min_time = 0.0;
        c.max_time = 1.0;
        attempt(c);
    }
    for (bool changed = true; changed && budget > 0;) {
        changed = false;
        for (int side = 0; side < 2; ++side) {
            for (int i = 0; i < 4; ++i) {
                for (int k = 0; k < 3; ++k) {
                    const double x = (side ? best.end : best.start)[i][k];
                    const double other = (side ? best.start : best.end)[i][k];
                    for (const double simpler :
                         {0.0, std::round(x), 0.5 * std::round(2 * x), 0.125 * std::round(8 * x),
                          static_cast<double>(static_cast<float>(x)), other}) {
                        if (simpler == x || !std::isfinite(simpler)) {
                            continue;
                        }
                        Query c = best;
                        (side ? c.end : c.start)[i][k] = simpler;
                        if (attempt(c)) {
                            changed = true;
                            break;
                        }
                    }
                }
            }
        }
    }
    return best;
}

std::string describe(const Query& q) {
    std::string text = q.kind == Kind::kVertexFace ? "VertexFaceQuery" : "EdgeEdgeQuery";
    char buffer[128];
    for (int side = 0; side < 2; ++side) {
        text += side ? ",\n  end {" : "{\n  start {";
        for (int i = 0; i < 4; ++i) {
            const Vec3& p = (side ? q.end : q.start)[i];
            std::snprintf(buffer, sizeof buffer, "%sVec3(%a, %a, %a)", i ? ", " : "", p.x(), p.y(),
                          p.z());
            text += buffer;
        }
        text += "}";
    }
    std::snprintf(buffer, sizeof buffer, "}\n  min_time %a, max_time %a (family %s, scale 2^%d%s)",
                  q.min_time, q.max_time, familyNames()[q.family].c_str(), q.scale_exponent,
                  q.offset ? ", offset 1e10" : "");
    return text + buffer;
}

}  // namespace kolize::ccd::families
