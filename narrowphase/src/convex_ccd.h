#pragma once
// The time of impact of a mesh against a Bullet convex shape (ConvexMeshAlgorithm): the
// exact mesh CCD against a triangle surface around the shape, then, where that surface
// stands off the shape, conservative advancement with Bullet's GJK distances to the end.
#include "kolize/narrowphase/triangle_mesh.h"

#include <utility>
#include <vector>

class btConcaveShape;
class btConvexShape;
class btTransform;

namespace kolize::detail {

/// A closed triangle surface, in the convex shape's own frame (its local scaling applied),
/// that contains the shape with its collision margin: every point of the shape is inside
/// or on it, so a time of impact against it is never later than against the shape.
struct EnclosingPolytope {
    std::vector<narrowphase::Vec3> vertices;
    std::vector<narrowphase::Index3> triangles;
    /// The face planes (unit outward normal, offset): the polytope is where n.x <= offset.
    std::vector<std::pair<narrowphase::Vec3, double>> planes;
    /// How far the surface may stand off the shape (0 when it is the shape's own faces).
    double standoff = 0;
};

/// Builds the polytope of `shape`: the convex hull of its supporting vertices
/// (localGetSupportingVertex, margin included) in 122 directions (the 26 of the unit
/// lattice and 96 spread over the sphere), scaled about its centroid until each face's
/// plane is at or beyond the shape's support in its normal (which makes it contain the
/// shape: a polytope contains a convex set when every face plane bounds the set's support
/// in the face's normal). Exact for a box; around a sphere the faces are tangent and the
/// vertices within 6% of the radius (5.8% measured). A flat or degenerate shape (a triangle, a
/// segment) gets the box of its supporting vertices in the three axes instead. False when
/// a supporting vertex is not finite (the output is then empty).
bool enclosingPolytope(const btConvexShape& shape, EnclosingPolytope& out);

/// Whether `polytope` still contains `shape` (its support in every face normal at or inside
/// the face's plane): a cached polytope is reused only while this holds.
bool encloses(const EnclosingPolytope& polytope, const btConvexShape& shape);

/// One body's motion over the step: from `start` to `end`, the translation on the segment
/// and the rotation at constant angular velocity (slerp), as Bullet's integrator moves it.
struct Motion {
    const btTransform* start;
    const btTransform* end;
};

/// The smallest GJK distance (margins included) between `convex` at `convexPose` and the
/// triangles of `mesh` at `meshPose` within `reach` of the convex's box; more than `reach`
/// when none is that near.
double nearestDistance(const btConvexShape& convex, const btTransform& convexPose,
                       const btConcaveShape& mesh, const btTransform& meshPose, double reach);

/// The first contact of `convex` and `mesh` at or after `from` (a fraction of the step no
/// later than it, e.g. the time against the surface around `convex`), by conservative
/// advancement: at each time, the distance d between the shape and the mesh's triangles
/// (Bullet's GJK, margins included) lets the step advance by d over a bound on how fast any
/// point of one approaches the other (relative speed of the origins plus each turn times
/// its angular motion disc). Stops within `tolerance` of contact; returns that time, or 1
/// when the bodies do not meet before the end of the step. At most 256 advances: a body
/// gliding past within a few tolerances over a long motion can run out of them, and then
/// gets the time reached (early, never late). Never later than the contact as far as GJK's
/// distances are exact.
double advanceToContact(const btConvexShape& convex, const Motion& convexMotion,
                        const btConcaveShape& mesh, const Motion& meshMotion, double from,
                        double tolerance);

}  // namespace kolize::detail
