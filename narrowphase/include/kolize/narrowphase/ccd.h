#pragma once
/// Continuous collision detection (CCD) primitives for linearly moving vertices.
///
/// Every vertex moves on a straight line from its position at t = 0 to its position at
/// t = 1. A vertex-face query asks whether a point ever lies on a (closed) triangle during
/// t in [0, 1]; an edge-edge query asks whether two (closed) segments ever touch.
///
/// Two methods are provided:
///
/// * `cubic` -- the thesis's method (section 3.2.4): the coefficients of the coplanarity
///   cubic, its real roots in [0, 1], then an inside (vertex-face) or crossing (edge-edge)
///   test at each root, all in plain double precision with one tolerance. It is the
///   baseline; it can miss collisions (rounding, degenerate configurations).
///
/// * `robust` -- exact: it reports a contact if and only if the closed primitives touch,
///   with a time of impact never later than the first contact. Two stages:
///
///   1. A floating-point filter: a conservative inclusion search over (t, u, v) in the
///      spirit of Tight Inclusion (Wang et al., ACM TOG 2021), written from scratch. The
///      contact function F(t, u, v) (point minus barycentric point of the face, or point
///      on edge A minus point on edge B) is linear in each of t, u, v separately, so its
///      exact range over an axis-aligned box is the hull of its values at the 8 corners.
///      The corners are evaluated in double precision and widened by a per-axis forward
///      error bound derived from the magnitude of the inputs (see ccd.cpp); a box is thrown
///      away only when some coordinate range (or its projection on the normal) excludes
///      zero *after* widening, i.e. when it provably holds no root. This stage can only
///      ever answer "no contact". Boxes are processed in order of their earliest time; the
///      first box it cannot exclude, once its F range has shrunk to `tolerance` times the
///      whole domain's, goes to stage 2 with the time range [t0, max_time] (no contact
///      happens before t0: every earlier box was excluded).
///   2. An exact decision (ccd_exact.cpp). Touching needs the four points coplanar, so
///      every contact time is a root of the coplanarity cubic; when that cubic vanishes
///      identically (coplanar motion) contact can only begin where a vertex reaches an
///      edge's line or another vertex, roots of lower-degree polynomials. Candidate times
///      are isolated exactly (Bernstein subdivision or Sturm sequences), and the closed
///      static test at each (barycentric signs, segment parameters, degenerate triangles
///      and parallel edges reduced to point-on-segment tests) evaluates signs of
///      polynomials at the candidate with Tarski queries -- no tolerance anywhere. The
///      arithmetic is filtered: double intervals with directed rounding decide almost
///      every sign; a sign the intervals cannot certify (an exact zero, such as a contact
///      exactly on an edge, or a near-miss closer than about 1e-16 relative) is decided
///      with exact dyadic numbers on GMP integers.
///
///   Why this technique: the benchmark's ground truth is exact (rational coordinates, a
///   touch at distance 0 counts as a collision) and its hard negatives are near-contacts
///   ~1e-17 apart (e.g. erleben-cube-cliff-edges), below anything a double evaluation can
///   separate: the inclusion search alone, accepting boxes within a 1e-6 tolerance,
///   reported 5.4% of the non-colliding queries as collisions. Exact predicates remove
///   the tolerance from the answer altogether; the double filters in front keep the cost
///   of exactness to the few queries that need it (about 5% of the benchmark reach GMP).
///   The inclusion search stays as the first stage because it rejects most degenerate
///   but clearly separated queries faster than building the polynomials would.
///
///   Guarantee, for inputs whose coordinates are finite doubles with magnitude at most
///   kMaxCoordinate (stage 1's error bound must not overflow; stage 2 has no limit):
///   - exact: `hit` is true if and only if the closed primitives touch at some t in
///     [min_time, max_time] (default [0, 1]) -- no false negatives and no false
///     positives, whatever `tolerance`;
///   - time of impact: when `hit`, `toi` <= t* <= `toi` + `toi_tolerance` (plus one
///     rounding to double), where t* is the earliest contact time in that range: never
///     late, so moving the objects back to `toi` never leaves them interpenetrating.
#include <Eigen/Core>

#include <array>

namespace kolize::ccd {

using Vec3 = Eigen::Vector3d;

/// Largest coordinate magnitude for which the robust method's guarantee holds. Far
/// above any physical scene; it only keeps the floating-point stage's values finite.
inline constexpr double kMaxCoordinate = 1e150;

/// A vertex moving against a triangle. Index 0 is the vertex, 1..3 the triangle corners;
/// `start` holds positions at t = 0 and `end` at t = 1.
struct VertexFaceQuery {
    std::array<Vec3, 4> start;
    std::array<Vec3, 4> end;
};

/// An edge moving against an edge. Indices 0, 1 are edge A's endpoints, 2, 3 edge B's;
/// `start` holds positions at t = 0 and `end` at t = 1.
struct EdgeEdgeQuery {
    std::array<Vec3, 4> start;
    std::array<Vec3, 4> end;
};

/// Outcome of one CCD query.
struct CcdResult {
    bool hit = false;  ///< The primitives (may) touch during t in [0, 1].
    double toi = 1.0;  ///< Time of impact in [0, 1] when `hit`; 1 otherwise.
    /// Robust method only: number of (t, u, v) boxes the floating-point stage examined.
    int boxes = 0;
    /// Robust method only: the floating-point stage stopped at its box budget (or at the
    /// 2^-45 resolution limit) and left the decision to the exact stage early. The answer
    /// is exact either way; this only explains the cost.
    bool budget_exhausted = false;
    /// Robust method only: the exact stage decided (the floating-point stages could not).
    bool decided_exactly = false;
};

/// Settings of the thesis baseline (`cubic`).
struct CubicSettings {
    /// One tolerance used three ways, as in the thesis: coefficients smaller than
    /// `tolerance` times the largest one count as zero (lower the cubic's degree); roots
    /// are accepted in [-tolerance, 1 + tolerance]; barycentric (vertex-face) or segment
    /// (edge-edge) parameters are accepted in [-tolerance, 1 + tolerance].
    double tolerance = 1e-6;
};

/// How `robust` computes. Every mode gives the same answers (the guarantee above); they
/// differ in cost only, and the tests check that they agree.
enum class RobustArithmetic {
    /// Default: the certified floating-point decision, then (where it cannot decide) the
    /// inclusion search and the exact stage.
    kCertified,
    /// Without the certified decision: the inclusion search excludes, the exact stage
    /// decides everything else (double intervals first, GMP where they cannot).
    kSearchThenExact,
    /// No floating-point stage: the exact stage alone, on exact numbers only (no interval
    /// filter), over the whole range. Slow; for tests and measurements.
    kExactOnly,
};

struct RobustSettings;

/// Sees every query the robust method answers (with its settings, e.g. the time range a
/// caller such as meshCcd searched, and the answer): lets a tool record the queries of a
/// real run as benchmark data (kolize-ccd-record). Called on the calling thread, after the
/// answer is computed.
class QueryObserver {
  public:
    virtual ~QueryObserver() = default;
    virtual void observe(bool edge_edge, const std::array<Vec3, 4>& start,
                         const std::array<Vec3, 4>& end, const RobustSettings& settings,
                         const CcdResult& result) = 0;
};

/// Settings of the exact method (`robust`). None of them changes whether a contact is
/// reported; `tolerance`, `max_boxes` and `arithmetic` only move work between the stages.
/// `robust` throws std::invalid_argument when `toi_tolerance` is not > 0 (NaN included)
/// or `min_time` or `max_time` is NaN.
struct RobustSettings {
    /// Hand-off point of the floating-point stage: a box it cannot exclude goes to the exact
    /// stage once its F range is at most `tolerance` times the F range over the whole
    /// (t, u, v) domain (a ratio, so independent of the scene's scale). Smaller values
    /// search longer in doubles before deciding exactly. Default 0.1: fastest on the
    /// benchmark (`kolize-ccd-bench --sweep` runs 1e-8 ... 1e-1).
    double tolerance = 0.1;
    /// The reported `toi` is at most this much earlier than the true first contact (and
    /// never later). Must be > 0 (infinity is allowed: any toi no later than the contact);
    /// values below 2^-52 (the spacing of doubles just below 1) act as 2^-52, since toi is
    /// a double.
    double toi_tolerance = 1e-6;
    /// Only contacts at t in [min_time, max_time] are searched: the guarantees hold on that
    /// range, contacts outside it are ignored. Lets a caller that already knows an earlier
    /// contact, or splits the step into time slices (meshCcd), skip work. Both are clamped
    /// to [0, 1]; min_time > max_time is an empty range (no contact); NaN is refused.
    double min_time = 0.0;
    double max_time = 1.0;
    /// Box budget of the floating-point stage; when it runs out the exact stage decides.
    /// Bounds the stage's worst-case work; never changes the answer.
    int max_boxes = 2000;
    /// Which stages compute (see RobustArithmetic); never changes the answer.
    RobustArithmetic arithmetic = RobustArithmetic::kCertified;
    /// When set, sees every query and its answer (see QueryObserver); not owned.
    QueryObserver* observer = nullptr;
};

/// Thesis baseline: vertex-face CCD via the coplanarity cubic. May miss collisions.
CcdResult vertexFaceCubic(const VertexFaceQuery& q, const CubicSettings& settings = {});

/// Thesis baseline extended to edge-edge (coplanarity cubic, then segment crossing test).
/// Parallel edges at a root are reported as no contact. May miss collisions.
CcdResult edgeEdgeCubic(const EdgeEdgeQuery& q, const CubicSettings& settings = {});

/// Exact vertex-face CCD (see the header comment for the guarantee); `toi` is never later
/// than the true time of impact.
CcdResult vertexFaceRobust(const VertexFaceQuery& q, const RobustSettings& settings = {});

/// Exact edge-edge CCD (see the header comment for the guarantee); `toi` is never later
/// than the true time of impact.
CcdResult edgeEdgeRobust(const EdgeEdgeQuery& q, const RobustSettings& settings = {});

}  // namespace kolize::ccd
