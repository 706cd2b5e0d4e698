#pragma once
/// \file
/// Bounding volumes over triangles: bounding sphere, AABB, OBB (thesis section 2.2) and
/// k-DOPs for k = 6, 14, 18, 26, each with fitting, an overlap test and a transform.
///
/// Volumes are stored in float (the trees keep millions of them) and **rounded outward**:
/// a fitted float volume contains every point it was fitted to, exactly (validate() in
/// bv_tree.h checks it with exact arithmetic). Overlap tests add an error bound to their
/// float arithmetic, so "disjoint" is never wrong; "overlap" may be reported for volumes a
/// few float ulps apart, which only costs a deeper look.
#include "kolize/narrowphase/pose.h"
#include "kolize/narrowphase/triangle_mesh.h"

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <cstdint>

namespace kolize::narrowphase {

using Vec3f = Eigen::Vector3f;

/// Triangles of a mesh, all of them or the subset `ids[0..count)`.
struct TriangleSpan {
    const Vec3* vertices = nullptr;
    const Index3* triangles = nullptr;
    const std::int32_t* ids = nullptr;  ///< nullptr: triangles[0..count)
    std::size_t count = 0;

    static TriangleSpan all(const TriangleMesh& mesh) {
        return {mesh.vertices().data(), mesh.triangles().data(), nullptr, mesh.triangleCount()};
    }
    const Index3& triangle(std::size_t i) const { return triangles[ids ? ids[i] : i]; }
    /// Calls f(vertex) for the three corners of every triangle (shared vertices repeat).
    template <class F>
    void forEachCorner(F&& f) const {
        for (std::size_t i = 0; i < count; ++i) {
            const Index3& t = triangle(i);
            f(vertices[t[0]]);
            f(vertices[t[1]]);
            f(vertices[t[2]]);
        }
    }
};

/// Thesis formula 2.4: mean mu = (1/3n) sum(p_i + q_i + r_i) of the triangle vertices and
/// covariance C_jk = (1/3n) sum(p'_j p'_k + q'_j q'_k + r'_j r'_k), primes relative to mu.
struct Covariance {
    Vec3 mean = Vec3::Zero();
    Eigen::Matrix3d matrix = Eigen::Matrix3d::Zero();
};
Covariance triangleCovariance(const TriangleSpan& triangles);

/// Orthonormal axes from a covariance: eigenvectors (Eigen's SelfAdjointEigenSolver,
/// computeDirect) ordered from the largest eigenvalue to the smallest, right-handed.
/// Degenerate input (zero-area triangles, a single point, NaN) still gets valid axes.
Eigen::Matrix3d principalAxes(const Eigen::Matrix3d& covariance);

// ---------------------------------------------------------------------------------------

/// Bounding sphere.
struct Sphere {
    Vec3f center = Vec3f::Zero();
    float radius = 0;
};

/// Axis-aligned box [lo, hi] (closed).
struct Aabb {
    Vec3f lo = Vec3f::Zero();
    Vec3f hi = Vec3f::Zero();
};

/// Oriented box {center + sum_i u_i axis_i : |u_i| <= half_i} (closed). The axes are float
/// roundings of orthonormal vectors; the box is defined by these float axes (axis2 =
/// axis0 x axis1 evaluated in float), so nothing about it depends on exact orthonormality.
/// `radius` bounds the distance from `center` to every fitted point (0 if not fitted).
struct Obb {
    Vec3f center = Vec3f::Zero();
    Vec3f half = Vec3f::Zero();
    Vec3f axis0 = Vec3f::UnitX();
    Vec3f axis1 = Vec3f::UnitY();
    float radius = 0;

    Vec3f axis2() const;
};

/// k-DOP: the intersection of K/2 slabs lo_i <= d_i . x <= hi_i with the fixed integer
/// directions d_i of kdopDirections<K>() (6: the axes; 14: + the 4 cube diagonals;
/// 18: + the 6 edge diagonals; 26: all 13).
template <int K>
struct Kdop {
    static_assert(K == 6 || K == 14 || K == 18 || K == 26, "k-DOPs exist for K = 6, 14, 18, 26");
    static constexpr int kSlabs = K / 2;
    std::array<float, K / 2> lo{};
    std::array<float, K / 2> hi{};
};

/// The K/2 directions of a k-DOP, entries in {-1, 0, 1}.
template <int K>
const std::array<Eigen::Vector3i, K / 2>& kdopDirections();

// ---------------------------------------------------------------------------------------
// Fitting. O(corners). The result contains every corner exactly.

/// Centre of the corners' bounding box or their mean, whichever gives the smaller radius
/// ("centre of the part, radius to its farthest vertex", thesis).
Sphere fitSphere(const TriangleSpan& triangles);
Aabb fitAabb(const TriangleSpan& triangles);
/// Axes from triangleCovariance (thesis), extents from the corners.
Obb fitObb(const TriangleSpan& triangles);
/// Extents along given orthonormal axes (columns, largest spread first).
Obb fitObb(const TriangleSpan& triangles, const Eigen::Matrix3d& axes);
template <int K>
Kdop<K> fitKdop(const TriangleSpan& triangles);
/// k-DOP of points given one by one (a k-DOP under a rotation is refit, not rotated).
template <int K>
Kdop<K> fitKdop(const Vec3* points, std::size_t count);

// ---------------------------------------------------------------------------------------
// Overlap: a in its frame, b moved by `bInA` into a's frame (RelativePose(poseA, poseB)).
// Sound: false only when the volumes are disjoint. O(1).

bool overlap(const Sphere& a, const Sphere& b, const RelativePose& bInA);
/// Same frame: exact interval comparisons.
bool overlap(const Aabb& a, const Aabb& b);
/// b's box in its own frame, moved: separating-axis test with 15 axes (face axes first).
bool overlap(const Aabb& a, const Aabb& b, const RelativePose& bInA);
/// Separating-axis test, 15 axes (a's 3 face axes, b's 3, the 9 edge cross products), with
/// early exit and a float error bound.
bool overlap(const Obb& a, const Obb& b, const RelativePose& bInA);
/// Same frame: exact slab comparisons.
template <int K>
bool overlap(const Kdop<K>& a, const Kdop<K>& b);

// ---------------------------------------------------------------------------------------
// Transform into another frame, rounded outward: the result contains the moved volume.

Sphere transformed(const Sphere& s, const RelativePose& pose);
/// The axis-aligned box around the moved box.
Aabb transformed(const Aabb& box, const RelativePose& pose);
Obb transformed(const Obb& box, const RelativePose& pose);

// ---------------------------------------------------------------------------------------
// Containment, exact (double filter, GMP when the filter cannot tell). For validate() and
// tests.

bool contains(const Sphere& s, const Vec3& x);
bool contains(const Aabb& box, const Vec3& x);
bool contains(const Obb& box, const Vec3& x);
template <int K>
bool contains(const Kdop<K>& dop, const Vec3& x);

}  // namespace kolize::narrowphase
