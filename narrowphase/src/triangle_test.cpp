#include "kolize/narrowphase/triangle_test.h"

#include "predicates_internal.h"
#include "triangle_test_internal.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

// Why the decision is complete. Closed triangles P and Q (non-degenerate, not coplanar)
// meet iff their chords on the line plane(P) n plane(Q) overlap; Guigue and Devillers' two
// orientations decide that overlap once each triangle's vertices are named by their sides
// of the other's plane (generalHit). A zero-area triangle is the union of its three edges. Coplanar
// triangles are decided in a coordinate projection in which one of them keeps a nonzero area; that
// projection is injective on the common plane, so the 2D answer is the 3D answer. Everything is a
// sign of orient3d or orient2d of input points, or a comparison of input coordinates: exact.

namespace kolize::narrowphase {

namespace {

using detail::PlaneSide;

/// The two coordinates kept by a projection along axis `drop`.
struct Projection {
    int u, v;
};

Projection dropping(int axis) {
    return {(axis + 1) % 3, (axis + 2) % 3};
}

class Tester {
  public:
    explicit Tester(PredicateStats* stats) : stats_(stats) {}

    int orient2(const Projection& pr, const Vec3& a, const Vec3& b, const Vec3& c) const {
        return orient2d(a[pr.u], a[pr.v], b[pr.u], b[pr.v], c[pr.u], c[pr.v], stats_);
    }
    /// orient3d, its filter inlined here.
    int orient3(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) const {
        return PlaneSide(a, b, c).side(d, stats_);
    }

    /// A projection in which t keeps a nonzero area, or none when t is degenerate.
    std::optional<Projection> areaKeeping(const Triangle& t, const Vec3& normal) const {
        int order[3] = {0, 1, 2};
        std::sort(order, order + 3,
                  [&](int i, int j) { return std::fabs(normal[i]) > std::fabs(normal[j]); });
        for (int axis : order) {
            const Projection pr = dropping(axis);
            if (orient2(pr, t[0], t[1], t[2]) != 0) {
                return pr;
            }
        }
        return std::nullopt;
    }

    /// Closed segments ab and cd, collinear in the projection (all four orientations 0):
    /// they meet iff their boxes overlap in both kept coordinates.
    static bool collinearOverlap(const Projection& pr, const Vec3& a, const Vec3& b, const Vec3& c,
                                 const Vec3& d) {
        for (int k : {pr.u, pr.v}) {
            if (std::max(a[k], b[k]) < std::min(c[k], d[k]) ||
                std::max(c[k], d[k]) < std::min(a[k], b[k])) {
                return false;
            }
        }
        return true;
    }

    /// Closed segments ab and cd in the projection, from o1 = orient(a, b, c),
    /// o2 = orient(a, b, d), o3 = orient(c, d, a), o4 = orient(c, d, b). Correct also when
    /// a segment is a point.
    static bool segmentsFromSigns(const Projection& pr, const Vec3& a, const Vec3& b, const Vec3& c,
                                  const Vec3& d, int o1, int o2, int o3, int o4) {
        if (o1 * o2 > 0 || o3 * o4 > 0) {
            return false;
        }
        if (o1 == 0 && o2 == 0 && o3 == 0 && o4 == 0) {
            return collinearOverlap(pr, a, b, c, d);
        }
        return true;
    }

    bool segments2d(const Projection& pr, const Vec3& a, const Vec3& b, const Vec3& c,
                    const Vec3& d) const {
        const int o1 = orient2(pr, a, b, c), o2 = orient2(pr, a, b, d);
        if (o1 * o2 > 0) {
            return false;
        }
        const int o3 = orient2(pr, c, d, a), o4 = orient2(pr, c, d, b);
        return segmentsFromSigns(pr, a, b, c, d, o1, o2, o3, o4);
    }

    /// Closed segments in 3D: coplanar (orient3d = 0) and meeting in all three coordinate
    /// projections. A projection that is injective on a plane (or line) holding both
    /// exists and separates them when they are apart.
    bool segments3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) const {
        if (orient3(a, b, c, d) != 0) {
            return false;
        }
        for (int axis = 0; axis < 3; ++axis) {
            if (!segments2d(dropping(axis), a, b, c, d)) {
                return false;
            }
        }
        return true;
    }

    /// Point x in closed triangle t, t of nonzero area in the projection (orientation o).
    bool inside2d(const Projection& pr, const Triangle& t, int o, const Vec3& x) const {
        for (int i = 0; i < 3; ++i) {
            if (orient2(pr, t[i], t[(i + 1) % 3], x) * o < 0) {
                return false;
            }
        }
        return true;
    }

    /// Closed segment ab against closed triangle t in the projection, t of nonzero area.
    bool segmentTriangle2d(const Projection& pr, const Vec3& a, const Vec3& b,
                           const Triangle& t) const {
        const int o = orient2(pr, t[0], t[1], t[2]);
        if (inside2d(pr, t, o, a) || inside2d(pr, t, o, b)) {
            return true;
        }
        for (int i = 0; i < 3; ++i) {
            if (segments2d(pr, a, b, t[i], t[(i + 1) % 3])) {
                return true;
            }
        }
        return false;
    }

    /// Coplanar closed triangles in the projection; p has nonzero area in it, q may not.
    bool triangles2d(const Projection& pr, const Triangle& p, const Triangle& q) const {
        const int op = orient2(pr, p[0], p[1], p[2]);
        // e[i][k]: side of q_k relative to p's edge i, positive inside.
        int e[3][3];
        for (int k = 0; k < 3; ++k) {
            for (int i = 0; i < 3; ++i) {
                e[i][k] = orient2(pr, p[i], p[(i + 1) % 3], q[k]) * op;
            }
            if (e[0][k] >= 0 && e[1][k] >= 0 && e[2][k] >= 0) {
                return true;  // a vertex of q in p
            }
        }
        // f[j][i]: side of p_i relative to q's edge j (0 for every i when q is degenerate).
        int f[3][3];
        for (int j = 0; j < 3; ++j) {
            for (int i = 0; i < 3; ++i) {
                f[j][i] = orient2(pr, q[j], q[(j + 1) % 3], p[i]);
            }
        }
        for (int i = 0; i < 3; ++i) {
            const int i1 = (i + 1) % 3;
            for (int j = 0; j < 3; ++j) {
                const int j1 = (j + 1) % 3;
                if (segmentsFromSigns(pr, p[i], p[i1], q[j], q[j1], e[i][j], e[i][j1], f[j][i],
                                      f[j][i1])) {
                    return true;
                }
            }
        }
        // No vertex of q in p and no edges meeting: only p inside q remains.
        const int oq = orient2(pr, q[0], q[1], q[2]);
        return oq != 0 && f[0][0] * oq >= 0 && f[1][0] * oq >= 0 && f[2][0] * oq >= 0;
    }

    /// Closed segment ab against closed triangle t of nonzero area, with the exact sides
    /// sa, sb of a and b relative to t's plane.
    bool segmentTriangle3d(const Vec3& a, const Vec3& b, int sa, int sb, const Triangle& t,
                           const std::optional<Projection>& prT) const {
        if (sa * sb > 0) {
            return false;
        }
        if (sa == 0 && sb == 0) {
            return segmentTriangle2d(*prT, a, b, t);
        }
        // The line ab crosses t's plane inside the segment; it meets the closed triangle iff
        // it passes on the same (closed) side of the three edges.
        const int o0 = orient3(a, b, t[0], t[1]);
        const int o1 = orient3(a, b, t[1], t[2]);
        if (o0 * o1 < 0) {
            return false;
        }
        const int o2 = orient3(a, b, t[2], t[0]);
        return o0 * o2 >= 0 && o1 * o2 >= 0;
    }

  private:
    PredicateStats* stats_;
};

int sideCount(const int s[3], int value) {
    return int(s[0] == value) + int(s[1] == value) + int(s[2] == value);
}

bool sameStrictSide(const int s[3]) {
    return (s[0] > 0 && s[1] > 0 && s[2] > 0) || (s[0] < 0 && s[1] < 0 && s[2] < 0);
}

/// The general case of decide (Guigue and Devillers, "Fast and robust triangle-triangle
/// overlap test using orientation predicates", 2003): proper triangles in distinct planes,
/// neither strictly on one side of the other's plane. Each triangle meets the planes' common
/// line in an interval; with each triangle's vertices named so that the first is alone on its
/// side of the other's plane (and the other triangle's last two swapped when that side is the
/// negative one, which reverses its normal), the intervals overlap iff two orientations are
/// not positive. Exact with exact orientations, touching included; 2 orient3d besides the 6
/// plane sides, where testing each edge against the other triangle takes 3 to 9.
///
/// Overlap of the canonical pair: a0 alone on its side of b's plane, b0 alone on its side of
/// a's plane, both on the positive side once the swaps are made.
bool intervalsMeet(const Tester& t, const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0,
                   const Vec3& b1, const Vec3& b2) {
    return t.orient3(a1, b0, a0, b1) <= 0 && t.orient3(a0, b0, a2, b2) <= 0;
}

/// a in canonical order; b named so that s0, s1, s2 are its sides relative to a's plane:
/// renames b so that b0 is alone on its side (and a's last two swapped for the negative side).
bool canonicalB(const Tester& t, const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0,
                const Vec3& b1, const Vec3& b2, int s0, int s1, int s2) {
    if (s0 > 0) {
        if (s1 > 0) {
            return intervalsMeet(t, a0, a2, a1, b2, b0, b1);
        }
        if (s2 > 0) {
            return intervalsMeet(t, a0, a2, a1, b1, b2, b0);
        }
        return intervalsMeet(t, a0, a1, a2, b0, b1, b2);
    }
    if (s0 < 0) {
        if (s1 < 0) {
            return intervalsMeet(t, a0, a1, a2, b2, b0, b1);
        }
        if (s2 < 0) {
            return intervalsMeet(t, a0, a1, a2, b1, b2, b0);
        }
        return intervalsMeet(t, a0, a2, a1, b0, b1, b2);
    }
    if (s1 < 0) {
        return s2 >= 0 ? intervalsMeet(t, a0, a2, a1, b1, b2, b0)
                       : intervalsMeet(t, a0, a1, a2, b0, b1, b2);
    }
    if (s1 > 0) {
        return s2 > 0 ? intervalsMeet(t, a0, a2, a1, b0, b1, b2)
                      : intervalsMeet(t, a0, a1, a2, b1, b2, b0);
    }
    // s1 == 0 (s2 != 0: b is not in a's plane)
    return s2 > 0 ? intervalsMeet(t, a0, a1, a2, b2, b0, b1)
                  : intervalsMeet(t, a0, a2, a1, b2, b0, b1);
}

/// sp: p's vertices relative to q's plane, sq: q's relative to p's (not all zero, not all of
/// one strict sign, either of them).
bool generalHit(const Tester& t, const Triangle& p, const Triangle& q, const int sp[3],
                const int sq[3]) {
    const Vec3 &p0 = p[0], &p1 = p[1], &p2 = p[2];
    const Vec3 &q0 = q[0], &q1 = q[1], &q2 = q[2];
    const int r0 = sp[0], r1 = sp[1], r2 = sp[2];
    const int s0 = sq[0], s1 = sq[1], s2 = sq[2];
    if (r0 > 0) {
        if (r1 > 0) {
            return canonicalB(t, p2, p0, p1, q0, q2, q1, s0, s2, s1);
        }
        if (r2 > 0) {
            return canonicalB(t, p1, p2, p0, q0, q2, q1, s0, s2, s1);
        }
        return canonicalB(t, p0, p1, p2, q0, q1, q2, s0, s1, s2);
    }
    if (r0 < 0) {
        if (r1 < 0) {
            return canonicalB(t, p2, p0, p1, q0, q1, q2, s0, s1, s2);
        }
        if (r2 < 0) {
            return canonicalB(t, p1, p2, p0, q0, q1, q2, s0, s1, s2);
        }
        return canonicalB(t, p0, p1, p2, q0, q2, q1, s0, s2, s1);
    }
    if (r1 < 0) {
        return r2 >= 0 ? canonicalB(t, p1, p2, p0, q0, q2, q1, s0, s2, s1)
                       : canonicalB(t, p0, p1, p2, q0, q1, q2, s0, s1, s2);
    }
    if (r1 > 0) {
        return r2 > 0 ? canonicalB(t, p0, p1, p2, q0, q2, q1, s0, s2, s1)
                      : canonicalB(t, p1, p2, p0, q0, q1, q2, s0, s1, s2);
    }
    // r1 == 0 (r2 != 0: p is not in q's plane)
    return r2 > 0 ? canonicalB(t, p2, p0, p1, q0, q1, q2, s0, s1, s2)
                  : canonicalB(t, p2, p0, p1, q0, q2, q1, s0, s2, s1);
}

/// Which case decided the test, and what the geometry needs from it.
struct Decision {
    enum class Case { kSeparate, kGeneral, kCoplanar, kDegenerateP, kDegenerateQ, kBothDegenerate };
    Case kind = Case::kSeparate;
    int sp[3] = {0, 0, 0};                      ///< sides of p's vertices relative to q's plane
    int sq[3] = {0, 0, 0};                      ///< sides of q's vertices relative to p's plane
    Vec3 np = Vec3::Zero(), nq = Vec3::Zero();  ///< plane normals (double, not unit)
    bool hit = false;
};

/// planeP and planeQ: the planes of p's and q's vertices in their order.
Decision decide(const Triangle& p, const PlaneSide& planeP, const Triangle& q,
                const PlaneSide& planeQ, PredicateStats* stats) {
    Decision d;
    const Tester t(stats);
    for (int k = 0; k < 3; ++k) {
        d.sq[k] = planeP.side(q[k], stats);
    }
    if (sameStrictSide(d.sq)) {
        return d;
    }
    for (int i = 0; i < 3; ++i) {
        d.sp[i] = planeQ.side(p[i], stats);
    }
    if (sameStrictSide(d.sp)) {
        return d;
    }
    d.np = planeP.normal();
    d.nq = planeQ.normal();
    const bool pFlat = sideCount(d.sq, 0) == 3;  // p degenerate, or q in p's plane
    const bool qFlat = sideCount(d.sp, 0) == 3;
    if (pFlat && qFlat) {
        if (const std::optional<Projection> prP = t.areaKeeping(p, d.np)) {
            d.kind = Decision::Case::kCoplanar;
            d.hit = t.triangles2d(*prP, p, q);
            return d;
        }
        if (const std::optional<Projection> prQ = t.areaKeeping(q, d.nq)) {
            d.kind = Decision::Case::kDegenerateP;
            d.hit = t.triangles2d(*prQ, q, p);
            return d;
        }
        d.kind = Decision::Case::kBothDegenerate;
        for (int i = 0; i < 3 && !d.hit; ++i) {
            for (int j = 0; j < 3 && !d.hit; ++j) {
                d.hit = t.segments3d(p[i], p[(i + 1) % 3], q[j], q[(j + 1) % 3]);
            }
        }
        return d;
    }
    if (qFlat) {
        // All of p on q's plane but not all of q on p's: q has zero area (were it a proper
        // triangle, p would lie in its plane, be a proper triangle itself, and share it).
        d.kind = Decision::Case::kDegenerateQ;
        const std::optional<Projection> prP = t.areaKeeping(p, d.np);
        for (int j = 0; j < 3 && !d.hit; ++j) {
            const int j1 = (j + 1) % 3;
            d.hit = t.segmentTriangle3d(q[j], q[j1], d.sq[j], d.sq[j1], p, prP);
        }
        return d;
    }
    if (pFlat) {
        d.kind = Decision::Case::kDegenerateP;
        const std::optional<Projection> prQ = t.areaKeeping(q, d.nq);
        for (int i = 0; i < 3 && !d.hit; ++i) {
            const int i1 = (i + 1) % 3;
            d.hit = t.segmentTriangle3d(p[i], p[i1], d.sp[i], d.sp[i1], q, prQ);
        }
        return d;
    }
    // Both proper, planes distinct, each meeting the other's plane.
    d.kind = Decision::Case::kGeneral;
    d.hit = generalHit(t, p, q, d.sp, d.sq);
    return d;
}

Decision decide(const Triangle& p, const Triangle& q, PredicateStats* stats) {
    return decide(p, PlaneSide(p[0], p[1], p[2]), q, PlaneSide(q[0], q[1], q[2]), stats);
}

// ---------------------------------------------------------------------------------------
// Geometry, in double, after the exact decision.
// ---------------------------------------------------------------------------------------

/// Points of a convex polygon (at most 9 while clipping).
struct Polygon {
    Vec3 points[9];
    int count = 0;
    void add(const Vec3& x) {
        if (count < 9) {
            points[count++] = x;
        }
    }
};

/// Keeps the part of `in` with m . (x - origin) >= -slack.
Polygon clip(const Polygon& in, const Vec3& origin, const Vec3& m, double slack) {
    Polygon out;
    for (int i = 0; i < in.count; ++i) {
        const Vec3& a = in.points[i];
        const Vec3& b = in.points[(i + 1) % in.count];
        const double da = m.dot(a - origin) + slack, db = m.dot(b - origin) + slack;
        if (da >= 0) {
            out.add(a);
        }
        if ((da >= 0) != (db >= 0) && in.count > 1) {
            const double s = da / (da - db);
            out.add(a + std::clamp(s, 0.0, 1.0) * (b - a));
        }
    }
    return out;
}

/// The two vertices of a zero-area triangle farthest apart: its segment.
void extremes(const Triangle& t, Vec3& a, Vec3& b) {
    int best = 0;
    double bestLength = -1;
    for (int i = 0; i < 3; ++i) {
        const double length = (t[(i + 1) % 3] - t[i]).squaredNorm();
        if (length > bestLength) {
            bestLength = length;
            best = i;
        }
    }
    a = t[best];
    b = t[(best + 1) % 3];
}

double scaleOf(const Triangle& p, const Triangle& q) {
    double s = 0;
    for (const Triangle* t : {&p, &q}) {
        for (const Vec3& x : *t) {
            s = std::max(s, x.cwiseAbs().maxCoeff());
        }
    }
    return s;
}

/// Clips `shape` (a polygon, or a segment as a 2-point polygon) to the closed triangle t
/// (nonzero area, normal n) in their common plane; retries with a small slack when rounding
/// empties a touching contact.
Polygon clipToTriangle(const Polygon& shape, const Triangle& t, const Vec3& n, double scale) {
    for (double slackFactor : {0.0, 1e-12, 1e-9}) {
        Polygon result = shape;
        for (int i = 0; i < 3 && result.count > 0; ++i) {
            const Vec3 m = n.cross(t[(i + 1) % 3] - t[i]);
            result = clip(result, t[i], m, slackFactor * m.norm() * scale);
        }
        if (result.count > 0) {
            return result;
        }
    }
    return {};
}

/// Closest points of segments ab and cd; returns their midpoint.
Vec3 segmentsMidpoint(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
    const Vec3 u = b - a, v = d - c, w = a - c;
    const double uu = u.dot(u), uv = u.dot(v), vv = v.dot(v), uw = u.dot(w), vw = v.dot(w);
    const double den = uu * vv - uv * uv;
    double s = den > 0 ? std::clamp((uv * vw - vv * uw) / den, 0.0, 1.0) : 0.0;
    double r = vv > 0 ? std::clamp((uv * s + vw) / vv, 0.0, 1.0) : 0.0;
    s = uu > 0 ? std::clamp((uv * r - uw) / uu, 0.0, 1.0) : 0.0;
    return 0.5 * ((a + s * u) + (c + r * v));
}

/// Where the segment ab crosses the plane (origin, normal n), clamped to the segment.
Vec3 planeCrossing(const Vec3& a, const Vec3& b, const Vec3& origin, const Vec3& n) {
    const double da = n.dot(a - origin), db = n.dot(b - origin);
    const double s = da == db ? 0.0 : std::clamp(da / (da - db), 0.0, 1.0);
    return a + s * (b - a);
}

void setSegment(TriangleIntersection& out, const Vec3& a, const Vec3& b) {
    out.kind = TriangleIntersection::Kind::kSegment;
    out.count = 2;
    out.points[0] = a;
    out.points[1] = b;
}

void setFromPolygon(TriangleIntersection& out, const Polygon& polygon, bool asPolygon,
                    const Vec3& fallback) {
    if (polygon.count == 0) {
        setSegment(out, fallback, fallback);
        return;
    }
    if (!asPolygon) {
        // A clipped segment: its first and farthest points.
        int far = 0;
        for (int i = 1; i < polygon.count; ++i) {
            if ((polygon.points[i] - polygon.points[0]).squaredNorm() >
                (polygon.points[far] - polygon.points[0]).squaredNorm()) {
                far = i;
            }
        }
        setSegment(out, polygon.points[0], polygon.points[far]);
        return;
    }
    out.kind = TriangleIntersection::Kind::kPolygon;
    out.count = std::uint8_t(std::min(polygon.count, 6));
    for (int i = 0; i < out.count; ++i) {
        out.points[i] = polygon.points[i];
    }
}

/// The part of triangle p on the plane of q: one or two points (p proper, planes distinct).
int pointsOnPlane(const Triangle& p, const int sp[3], const Vec3& origin, const Vec3& n,
                  Vec3 points[3]) {
    int count = 0;
    for (int i = 0; i < 3; ++i) {
        const int i1 = (i + 1) % 3;
        if (sp[i] == 0) {
            points[count++] = p[i];
        } else if (sp[i] * sp[i1] < 0) {
            points[count++] = planeCrossing(p[i], p[i1], origin, n);
        }
        if (count == 3) {
            break;
        }
    }
    return count;
}

void generalGeometry(const Triangle& p, const Triangle& q, const Decision& d,
                     TriangleIntersection& out) {
    Vec3 onP[3], onQ[3];
    const int countP = pointsOnPlane(p, d.sp, q[0], d.nq, onP);
    const int countQ = pointsOnPlane(q, d.sq, p[0], d.np, onQ);
    const Vec3 line = d.np.cross(d.nq);
    // Each triangle's chord on the planes' line, as an interval of positions along it.
    auto interval = [&](const Vec3* points, int count, int& lo, int& hi) {
        lo = hi = 0;
        for (int i = 1; i < count; ++i) {
            if (line.dot(points[i]) < line.dot(points[lo])) {
                lo = i;
            }
            if (line.dot(points[i]) > line.dot(points[hi])) {
                hi = i;
            }
        }
    };
    int loP, hiP, loQ, hiQ;
    interval(onP, std::max(countP, 1), loP, hiP);
    interval(onQ, std::max(countQ, 1), loQ, hiQ);
    const Vec3& start = line.dot(onP[loP]) >= line.dot(onQ[loQ]) ? onP[loP] : onQ[loQ];
    const Vec3& end = line.dot(onP[hiP]) <= line.dot(onQ[hiQ]) ? onP[hiP] : onQ[hiQ];
    if (line.dot(start) <= line.dot(end)) {
        setSegment(out, start, end);
    } else {
        const Vec3 middle = 0.5 * (start + end);  // a touch that rounding turned inside out
        setSegment(out, middle, middle);
    }
}

void buildGeometry(const Triangle& p, const Triangle& q, const Decision& d,
                   TriangleIntersection& out) {
    const double scale = scaleOf(p, q);
    switch (d.kind) {
        case Decision::Case::kGeneral:
            generalGeometry(p, q, d, out);
            return;
        case Decision::Case::kCoplanar: {
            Polygon shape;
            for (const Vec3& x : p) {
                shape.add(x);
            }
            Vec3 qa, qb;
            extremes(q, qa, qb);
            const bool qProper = d.nq.squaredNorm() > 0;
            if (qProper) {
                setFromPolygon(out, clipToTriangle(shape, q, d.nq, scale), true, qa);
            } else {  // q is a segment lying in p's plane
                Polygon segment;
                segment.add(qa);
                segment.add(qb);
                setFromPolygon(out, clipToTriangle(segment, p, d.np, scale), false, qa);
            }
            return;
        }
        case Decision::Case::kDegenerateP:
        case Decision::Case::kDegenerateQ: {
            const bool pDegenerate = d.kind == Decision::Case::kDegenerateP;
            const Triangle& flat = pDegenerate ? p : q;
            const Triangle& proper = pDegenerate ? q : p;
            const Vec3& n = pDegenerate ? d.nq : d.np;
            const int* sides = pDegenerate ? d.sp : d.sq;
            Vec3 a, b;
            extremes(flat, a, b);
            if (sideCount(sides, 0) == 3) {  // the segment lies in the plane
                Polygon segment;
                segment.add(a);
                segment.add(b);
                setFromPolygon(out, clipToTriangle(segment, proper, n, scale), false, a);
            } else {
                const Vec3 x = planeCrossing(a, b, proper[0], n);
                setSegment(out, x, x);
            }
            return;
        }
        case Decision::Case::kBothDegenerate: {
            Vec3 a, b, c, e;
            extremes(p, a, b);
            extremes(q, c, e);
            const Vec3 x = segmentsMidpoint(a, b, c, e);
            setSegment(out, x, x);
            return;
        }
        case Decision::Case::kSeparate:
            return;
    }
}

}  // namespace

Vec3 TriangleIntersection::centroid() const {
    Vec3 sum = Vec3::Zero();
    for (int i = 0; i < count; ++i) {
        sum += points[i];
    }
    return count > 0 ? Vec3(sum / count) : sum;
}

double TriangleIntersection::measure() const {
    if (kind == Kind::kSegment) {
        return count == 2 ? (points[1] - points[0]).norm() : 0.0;
    }
    Vec3 twiceArea = Vec3::Zero();
    for (int i = 1; i + 1 < count; ++i) {
        twiceArea += (points[i] - points[0]).cross(points[i + 1] - points[0]);
    }
    return 0.5 * twiceArea.norm();
}

bool detail::trianglesIntersect(const Triangle& p, const PlaneSide& planeP, const Triangle& q,
                                const PlaneSide& planeQ, PredicateStats* stats) {
    return decide(p, planeP, q, planeQ, stats).hit;
}

bool detail::triangleIntersection(const Triangle& p, const PlaneSide& planeP, const Triangle& q,
                                  const PlaneSide& planeQ, TriangleIntersection& out,
                                  PredicateStats* stats) {
    const Decision d = decide(p, planeP, q, planeQ, stats);
    if (d.hit) {
        buildGeometry(p, q, d, out);
    }
    return d.hit;
}

bool trianglesIntersect(const Triangle& p, const Triangle& q, PredicateStats* stats) {
    return decide(p, q, stats).hit;
}

bool triangleIntersection(const Triangle& p, const Triangle& q, TriangleIntersection& out,
                          PredicateStats* stats) {
    const Decision d = decide(p, q, stats);
    if (d.hit) {
        buildGeometry(p, q, d, out);
    }
    return d.hit;
}

namespace {

/// Closest points of segments [p0, p1] and [q0, q1]: minimises |P(s) - Q(t)| over the unit
/// square, from the unconstrained minimum clamped to an edge of the square and the other
/// parameter re-projected (a convex quadratic: one clamp and one re-projection suffice).
/// A zero-length segment is its point; parallel segments take s = 0 first.
void closestOnSegments(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1,
                       TriangleDistance& best) {
    const Vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
    const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
    auto clamp01 = [](double x) { return x < 0 ? 0.0 : (x > 1 ? 1.0 : x); };
    double s = 0, t = 0;
    if (a > 0 || e > 0) {
        if (a == 0) {
            t = clamp01(f / e);
        } else {
            const double c = d1.dot(r);
            if (e == 0) {
                s = clamp01(-c / a);
            } else {
                const double b = d1.dot(d2);
                const double denom = a * e - b * b;
                s = denom > 0 ? clamp01((b * f - c * e) / denom) : 0.0;
                t = (b * s + f) / e;
                if (t < 0) {
                    t = 0;
                    s = clamp01(-c / a);
                } else if (t > 1) {
                    t = 1;
                    s = clamp01((b - c) / a);
                }
            }
        }
    }
    const Vec3 onP = p0 + s * d1, onQ = q0 + t * d2;
    const double distance = (onQ - onP).norm();
    if (distance < best.distance) {
        best = {distance, onP, onQ};
    }
}

/// Vertex v of one triangle against the face of `t` (skipped when t has no area or v's foot
/// on t's plane lies outside t). `vOnP`: v is p's (the result's on_p), else q's.
void closestVertexFace(const Vec3& v, const Triangle& t, bool vOnP, TriangleDistance& best) {
    const Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]);
    const double n2 = n.squaredNorm();
    if (!(n2 > 0)) {
        return;
    }
    for (int k = 0; k < 3; ++k) {
        if ((t[(k + 1) % 3] - t[k]).cross(v - t[k]).dot(n) < 0) {
            return;
        }
    }
    const Vec3 foot = v - n * ((v - t[0]).dot(n) / n2);
    const double distance = (v - foot).norm();
    if (distance < best.distance) {
        best = vOnP ? TriangleDistance{distance, v, foot} : TriangleDistance{distance, foot, v};
    }
}

}  // namespace

TriangleDistance triangleDistance(const Triangle& p, const Triangle& q) {
    TriangleDistance best;
    best.distance = std::numeric_limits<double>::infinity();
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            closestOnSegments(p[i], p[(i + 1) % 3], q[j], q[(j + 1) % 3], best);
        }
    }
    for (int k = 0; k < 3; ++k) {
        closestVertexFace(p[k], q, true, best);
        closestVertexFace(q[k], p, false, best);
    }
    return best;
}

}  // namespace kolize::narrowphase
