#pragma once
/// \file
/// Axis-aligned boxes and rays in D dimensions, independent of Bullet.
///
/// All intervals are closed: two boxes that touch overlap. Boxes may have zero extent, and
/// coordinates as large as +-1e18 (Bullet's static planes) are handled without overflow in
/// both float and double.

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>

namespace kolize {

/// Index of an object inside a core. Dense, small, reused after removal.
using ObjectId = std::uint32_t;

/// A closed axis-aligned box [lo, hi] in D dimensions.
template <int D, class Scalar>
struct Aabb {
    std::array<Scalar, D> lo{};
    std::array<Scalar, D> hi{};

    friend bool operator==(const Aabb& a, const Aabb& b) { return a.lo == b.lo && a.hi == b.hi; }
    friend bool operator!=(const Aabb& a, const Aabb& b) { return !(a == b); }
};

/// True when the closed boxes share at least one point. At most 2*D comparisons.
template <int D, class Scalar>
inline bool overlaps(const Aabb<D, Scalar>& a, const Aabb<D, Scalar>& b) {
    for (int axis = 0; axis < D; ++axis) {
        if (a.lo[axis] > b.hi[axis] || b.lo[axis] > a.hi[axis]) {
            return false;
        }
    }
    return true;
}

/// True when `inner` lies inside the closed box `outer`.
template <int D, class Scalar>
inline bool contains(const Aabb<D, Scalar>& outer, const Aabb<D, Scalar>& inner) {
    for (int axis = 0; axis < D; ++axis) {
        if (inner.lo[axis] < outer.lo[axis] || inner.hi[axis] > outer.hi[axis]) {
            return false;
        }
    }
    return true;
}

/// True when every coordinate is finite and lo <= hi on every axis.
template <int D, class Scalar>
inline bool isValid(const Aabb<D, Scalar>& box) {
    for (int axis = 0; axis < D; ++axis) {
        if (!std::isfinite(box.lo[axis]) || !std::isfinite(box.hi[axis]) ||
            box.lo[axis] > box.hi[axis]) {
            return false;
        }
    }
    return true;
}

/// Smallest box containing both.
template <int D, class Scalar>
inline Aabb<D, Scalar> merged(const Aabb<D, Scalar>& a, const Aabb<D, Scalar>& b) {
    Aabb<D, Scalar> out;
    for (int axis = 0; axis < D; ++axis) {
        out.lo[axis] = a.lo[axis] < b.lo[axis] ? a.lo[axis] : b.lo[axis];
        out.hi[axis] = a.hi[axis] > b.hi[axis] ? a.hi[axis] : b.hi[axis];
    }
    return out;
}

/// A ray query in the form Bullet's broadphases use: the segment from `origin` to
/// `origin + direction * lambdaMax`, with the precomputed inverse direction and its signs
/// (sign[axis] = 1 when inverseDirection[axis] < 0), and a box [expandLo, expandHi] swept
/// along the ray (zero for a plain ray; a convex cast passes its shape's box).
template <int D, class Scalar>
struct Ray {
    std::array<Scalar, D> origin{};
    std::array<Scalar, D> inverseDirection{};
    std::array<unsigned, D> sign{};
    Scalar lambdaMax = 1;
    std::array<Scalar, D> expandLo{};
    std::array<Scalar, D> expandHi{};
};

/// The box a swept query box must reach: [box.lo - expandHi, box.hi - expandLo].
template <int D, class Scalar>
inline Aabb<D, Scalar> expandedForRay(const Aabb<D, Scalar>& box, const Ray<D, Scalar>& ray) {
    Aabb<D, Scalar> out;
    for (int axis = 0; axis < D; ++axis) {
        out.lo[axis] = box.lo[axis] - ray.expandHi[axis];
        out.hi[axis] = box.hi[axis] - ray.expandLo[axis];
    }
    return out;
}

/// Slab test of the ray against the box expanded by the ray's swept box, with the same
/// arithmetic and the same open bounds (0, lambdaMax) as Bullet's btRayAabb2, so that an
/// exact broadphase reports exactly the proxies Bullet's own ray test would accept.
template <int D, class Scalar>
inline bool rayHits(const Aabb<D, Scalar>& box, const Ray<D, Scalar>& ray) {
    const Aabb<D, Scalar> bounds = expandedForRay(box, ray);
    auto bound = [&](unsigned which, int axis) {
        return which ? bounds.hi[axis] : bounds.lo[axis];
    };
    Scalar tmin = (bound(ray.sign[0], 0) - ray.origin[0]) * ray.inverseDirection[0];
    Scalar tmax = (bound(1 - ray.sign[0], 0) - ray.origin[0]) * ray.inverseDirection[0];
    for (int axis = 1; axis < D; ++axis) {
        const Scalar amin =
            (bound(ray.sign[axis], axis) - ray.origin[axis]) * ray.inverseDirection[axis];
        const Scalar amax =
            (bound(1 - ray.sign[axis], axis) - ray.origin[axis]) * ray.inverseDirection[axis];
        if (tmin > amax || amin > tmax) {
            return false;
        }
        if (amin > tmin) {
            tmin = amin;
        }
        if (amax < tmax) {
            tmax = amax;
        }
    }
    return tmin < ray.lambdaMax && tmax > Scalar(0);
}

}  // namespace kolize
