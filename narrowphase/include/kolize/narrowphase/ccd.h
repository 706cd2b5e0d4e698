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
///   with a time of impact never later than the first contact. Stages (RobustArithmetic
///   selects them; all give the same answers):
///
///   1. A certified floating-point decision (ccd_certified.cpp), which decides contacts as
///      well as misses. Touching needs the four points coplanar, i.e. a root of the
///      coplanarity cubic c(t). On a time interval, c and every in-plane orientation (a
///      vertex against an edge's line, in a coordinate projection) have Bernstein
///      coefficients that follow from the vertices' positions at the interval's two ends;
///      each is computed with a rigorous error bound. Coefficients of one sign prove that c
///      has no root there, or that every coplanar time there is a miss; a single sign change
///      of c brackets its only root t*, and strict orientations over a bracket narrower than
///      `toi_tolerance` prove a contact at t*. Intervals are examined from the earliest,
///      halved while undecided, first in doubles (errors about 1e-13 relative), then in
///      double-doubles (about 1e-28), which settles near misses of 1e-17 and closer.
///   2. An exact decision (ccd_exact.cpp) of the rest of the range, for what no certificate
///      can settle: a touch exactly on an edge or a vertex, coplanar motion, a double root, a
///      contact exactly at the start or end of the range. Every contact time is a root of
///      the coplanarity cubic; when that vanishes identically (coplanar motion) contact can
///      only begin where a vertex reaches an edge's line or another vertex. Candidate times
///      are isolated exactly (Bernstein subdivision or Sturm sequences), and the closed
///      static test at each (barycentric signs, segment parameters, degenerate triangles and
///      parallel edges reduced to point-on-segment tests) evaluates signs of polynomials at
///      the candidate with Tarski queries -- no tolerance anywhere. Double intervals with
///      directed rounding decide most signs; the rest are decided with exact dyadic numbers
///      on GMP integers.
///
///   `RobustArithmetic::kSearchThenExact` replaces stage 1 by the previous filter, a
///   conservative inclusion search over (t, u, v) in the spirit of Tight Inclusion (Wang et
///   al., ACM TOG 2021) that can only exclude: boxes of (t, u, v) are evaluated at their
///   corners with a forward error bound, and the first box it cannot exclude (once its F
///   range has shrunk to `tolerance` times the whole domain's) hands [t0, max_time] to the
///   exact stage. It is kept for comparison and as an independent path in the tests.
///
///   Measured on the benchmark (`kolize-ccd-bench`, README): stage 1 decides every query of
///   kolize's own mesh-CCD runs and all but a few percent of the Wang et al. queries, whose
///   colliding ones are mostly exact touches by construction.
///
///   Guarantee, for any finite double coordinates (kMaxCoordinate only bounds where the
///   floating-point stages run; beyond it the exact stage decides alone):
///   - exact: `hit` is true if and only if the closed primitives touch at some t in
///     [min_time, max_time] (default [0, 1]) -- no false negatives and no false
///     positives, whatever the settings;
///   - time of impact: when `hit`, `toi` <= t* <= `toi` + max(`toi_tolerance`, 2^-52),
///     exactly, where t* is the earliest contact time in that range: never late, so moving
///     the objects back to `toi` never leaves them interpenetrating.
///   The floating-point stages assume the default floating-point environment (round to
///   nearest, no flush-to-zero); the exact stage sets its own rounding and restores the
///   caller's.
#include <Eigen/Core>

#include <array>

namespace kolize::ccd {

using Vec3 = Eigen::Vector3d;

/// Largest coordinate magnitude at which the inclusion search (kSearchThenExact) runs; its
/// error bound must stay finite. Beyond it the exact stage decides alone (the certified
/// stage has no such limit: it works on differences and scales them by powers of two).
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
    /// Robust method only: time intervals the certified stage examined, or (t, u, v) boxes
    /// of the inclusion search (kSearchThenExact).
    int boxes = 0;
    /// Robust method, kSearchThenExact only: the inclusion search stopped at its box budget
    /// (or at the 2^-45 resolution limit) and left the decision to the exact stage early.
    /// The answer is exact either way; this only explains the cost.
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
/// reported; `arithmetic`, `tolerance` and `max_boxes` only move work between the stages
/// (the last two belong to the inclusion search of kSearchThenExact).
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
