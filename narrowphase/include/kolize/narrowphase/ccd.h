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
/// * `robust` -- a conservative inclusion-based root finder over (t, u, v) in the spirit
///   of Tight Inclusion (Wang et al., ACM TOG 2021), written from scratch. The contact
///   function F(t, u, v) (point minus barycentric point of the face, or point on edge A
///   minus point on edge B) is linear in each of t, u, v separately, so its exact range
///   over an axis-aligned box is the hull of its values at the 8 corners. The corners
///   are evaluated in double precision and widened by a per-axis forward error bound
///   derived from the magnitude of the inputs (see ccd.cpp); a box is thrown away only
///   when some coordinate range excludes zero *after* widening, i.e. when it provably
///   holds no root. Boxes are processed in order of their earliest time, so the first box
///   accepted as a collision starts no later than the true time of impact.
///
///   Why this technique: it needs no special case for any degeneracy (coplanar motion,
///   parallel or collinear edges, vanishing cubic coefficients, contact at t = 0 or 1,
///   point-point or point-edge contact all reduce to "is 0 in the range of F on this
///   box"), its only arithmetic is double add/multiply with a bound that is easy to
///   check, and its false positives are controlled by one tolerance measured in scene
///   units. Certified isolation of the cubic's roots would still need a separate,
///   fragile treatment of the cases where the cubic vanishes identically.
///
///   Guarantee, for inputs whose coordinates are finite doubles with magnitude at most
///   kMaxCoordinate (no overflow in the error analysis):
///   - no false negatives: if the closed primitives touch at some t in [0, 1], `hit` is
///     true and `toi` is at most the earliest such t;
///   - bounded false positives: if `hit` is true and the box budget was not exhausted
///     (`budget_exhausted` false), then at some t in [0, 1] the two primitives are within
///     `tolerance + 2 * error_bound` of each other in every coordinate axis (max norm),
///     where error_bound is about 1e-14 times the largest coordinate magnitude;
///   - when the box budget is exhausted the answer is `hit = true` (conservative) with a
///     `toi` that is still no later than the true one.
#include <Eigen/Core>

#include <array>

namespace kolize::ccd {

using Vec3 = Eigen::Vector3d;

/// Largest coordinate magnitude for which the robust method's guarantee holds. Far
/// above any physical scene; it only keeps every intermediate value finite.
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
    /// Robust method only: number of (t, u, v) boxes examined (cost measure).
    int boxes = 0;
    /// Robust method only: the box budget ran out (or a box reached the 2^-45 resolution
    /// limit before the tolerance) and `hit` was set conservatively.
    bool budget_exhausted = false;
};

/// Settings of the thesis baseline (`cubic`).
struct CubicSettings {
    /// One tolerance used three ways, as in the thesis: coefficients smaller than
    /// `tolerance` times the largest one count as zero (lower the cubic's degree); roots
    /// are accepted in [-tolerance, 1 + tolerance]; barycentric (vertex-face) or segment
    /// (edge-edge) parameters are accepted in [-tolerance, 1 + tolerance].
    double tolerance = 1e-6;
};

/// Settings of the conservative inclusion-based method (`robust`).
struct RobustSettings {
    /// A box whose F range is at most this wide in every axis (scene units) is accepted
    /// as a collision: it bounds the false-positive distance. Default 1e-6 suits scenes
    /// of unit scale; scale it with the scene.
    double tolerance = 1e-6;
    /// A box is accepted only once its time range is at most this wide, so a reported
    /// `toi` is at most this much earlier than the start of the accepted box's range.
    /// Matters for slow motions, where F is within `tolerance` over long time ranges.
    double toi_tolerance = 1e-6;
    /// Only contacts at t <= max_time (in (0, 1]) are searched: the guarantees hold on
    /// [0, max_time], later contacts are ignored. Lets a caller that already knows an
    /// earlier contact (e.g. meshCcd) skip work.
    double max_time = 1.0;
    /// Maximum number of boxes examined per query before answering `hit` conservatively.
    /// Bounds the worst-case run time; never causes a false negative. On the benchmark
    /// only 6-7 of 4324 queries (near-collinear sliding edges) reach the default, and
    /// raising it to 20000 turns just one of their false positives into a negative.
    int max_boxes = 2000;
};

/// Thesis baseline: vertex-face CCD via the coplanarity cubic. May miss collisions.
CcdResult vertexFaceCubic(const VertexFaceQuery& q, const CubicSettings& settings = {});

/// Thesis baseline extended to edge-edge (coplanarity cubic, then segment crossing test).
/// Parallel edges at a root are reported as no contact. May miss collisions.
CcdResult edgeEdgeCubic(const EdgeEdgeQuery& q, const CubicSettings& settings = {});

/// Conservative vertex-face CCD: never misses a contact (see the header comment for the
/// exact guarantee); `toi` is never later than the true time of impact.
CcdResult vertexFaceRobust(const VertexFaceQuery& q, const RobustSettings& settings = {});

/// Conservative edge-edge CCD: never misses a contact (see the header comment for the
/// exact guarantee); `toi` is never later than the true time of impact.
CcdResult edgeEdgeRobust(const EdgeEdgeQuery& q, const RobustSettings& settings = {});

}  // namespace kolize::ccd
