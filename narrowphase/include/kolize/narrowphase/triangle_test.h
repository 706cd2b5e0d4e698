#pragma once
/// \file
/// Exact intersection test of two closed triangles in 3D, and the intersection's geometry.
///
/// A triangle is the closed convex hull of its three vertices: touching counts. Degenerate
/// triangles are legal: a zero-area triangle is the segment (or point) its vertices span.
/// The decision uses only the exact predicates of predicates.h on the input doubles, so it
/// has no tolerance and no false answers, in every coplanar, collinear, shared-vertex and
/// zero-area configuration. The geometry (segment or polygon) is built afterwards in double.
#include "kolize/narrowphase/predicates.h"

#include <array>
#include <cstdint>

namespace kolize::narrowphase {

/// Three vertices (any order, any of them equal).
using Triangle = std::array<Vec3, 3>;

/// True when the closed triangles p and q share at least one point. Exact. Cost: 6 filtered
/// orient3d for the planes' sides (which reject most separated pairs), then 2 orient3d for
/// the overlap of the two chords on the planes' line (Guigue and Devillers); coplanar and
/// degenerate pairs use orient2d in a projection that keeps them apart exactly. `stats` (optional)
/// counts the predicate stages.
bool trianglesIntersect(const Triangle& p, const Triangle& q, PredicateStats* stats = nullptr);

/// Where two intersecting triangles meet, built in double after the exact decision (so the
/// points are close to, not exactly on, the true intersection).
struct TriangleIntersection {
    enum class Kind : std::uint8_t {
        kSegment,  ///< triangles not coplanar, or a degenerate one: points[0..1] (may be equal)
        kPolygon,  ///< coplanar: the convex overlap polygon, points[0..count-1] in order
    };
    Kind kind = Kind::kSegment;
    std::uint8_t count = 0;  ///< 2 for a segment, 1..6 for a polygon
    std::array<Vec3, 6> points;

    /// Centroid of the points (of the polygon's vertices for a polygon).
    Vec3 centroid() const;
    /// Length of the segment, or area of the polygon.
    double measure() const;
};

/// trianglesIntersect, and when true, the intersection's geometry in `out`.
bool triangleIntersection(const Triangle& p, const Triangle& q, TriangleIntersection& out,
                          PredicateStats* stats = nullptr);

/// Closest points of two triangles that do not intersect, in double (not exact).
struct TriangleDistance {
    double distance = 0;       ///< |on_q - on_p|
    Vec3 on_p = Vec3::Zero();  ///< on p
    Vec3 on_q = Vec3::Zero();  ///< on q
};

/// The distance of two triangles that do not intersect (trianglesIntersect false): the
/// smallest of the 9 edge-edge distances and of the 6 vertex-face distances whose foot lies
/// inside the face (one of these is always the closest pair of disjoint triangles).
/// Degenerate triangles are their segments or points, as for trianglesIntersect. For
/// intersecting triangles the result is that same minimum, which is not 0 in general: ask
/// trianglesIntersect first. Cost: 9 segment-segment and 6 point-plane computations.
TriangleDistance triangleDistance(const Triangle& p, const Triangle& q);

}  // namespace kolize::narrowphase
