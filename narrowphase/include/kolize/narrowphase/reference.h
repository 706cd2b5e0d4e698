#pragma once
/// \file
/// The reference for mesh queries ("brute force"): plain code that shares nothing with the
/// bounding-volume trees, for tests, benchmarks and anyone who wants to check a result.
#include "kolize/narrowphase/mesh_query.h"
#include "kolize/narrowphase/pose.h"
#include "kolize/narrowphase/triangle_mesh.h"

#include <vector>

namespace kolize::narrowphase {

/// Every intersecting triangle pair of a at poseA and b at poseB, sorted: b's vertices are
/// moved by RelativePose(poseA, poseB).apply (the query's doubles), every pair of triangles
/// whose double bounding boxes overlap (a necessary condition, checked exactly; found by
/// sweeping along x) goes through the exact triangle test. O(n log n + box pairs).
std::vector<TrianglePair> referencePairs(const TriangleMesh& a, const Pose& poseA,
                                         const TriangleMesh& b, const Pose& poseB,
                                         PredicateStats* stats = nullptr);

/// The same from all |a| x |b| pairs, without boxes: the reference's own check, for small
/// meshes. O(|a| |b|).
std::vector<TrianglePair> allPairsReference(const TriangleMesh& a, const Pose& poseA,
                                            const TriangleMesh& b, const Pose& poseB);

/// The pairs a query with QuerySettings::margin `margin` reports as near (QueryResult::near)
/// when no pair intersects, sorted: every pair of triangles that do not intersect (exact
/// test) and whose
/// triangleDistance is at most `margin`, over all |a| x |b| pairs (pairs whose boxes are
/// farther apart than the margin along an axis are skipped: they are farther apart than it).
/// O(|a| |b|).
std::vector<TrianglePair> referenceNearPairs(const TriangleMesh& a, const Pose& poseA,
                                             const TriangleMesh& b, const Pose& poseB,
                                             double margin);

}  // namespace kolize::narrowphase
