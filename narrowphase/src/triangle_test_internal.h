#pragma once
// The triangle test with each triangle's plane given (private to the narrowphase core): a
// mesh query meets one triangle in several pairs and builds its plane once.

#include "kolize/narrowphase/triangle_test.h"

#include "predicates_internal.h"

namespace kolize::narrowphase::detail {

/// trianglesIntersect(p, q), with planeP = PlaneSide(p[0], p[1], p[2]) and planeQ likewise
/// for q built by the caller: the same answer, the same predicates counted.
bool trianglesIntersect(const Triangle& p, const PlaneSide& planeP, const Triangle& q,
                        const PlaneSide& planeQ, PredicateStats* stats);

/// triangleIntersection(p, q, out) with the planes given as above: the same answer and the
/// same geometry.
bool triangleIntersection(const Triangle& p, const PlaneSide& planeP, const Triangle& q,
                          const PlaneSide& planeQ, TriangleIntersection& out,
                          PredicateStats* stats);

}  // namespace kolize::narrowphase::detail
