#pragma once
// The fixed-order transform, inline for the query's hot loop (private to the core). Every
// translation unit of the core is built with -ffp-contract=off, so this yields the same
// doubles as RelativePose::apply.

#include "kolize/narrowphase/pose.h"

namespace kolize::narrowphase::detail {

inline Vec3 applyFixedOrder(const Eigen::Matrix3d& r, const Vec3& t, const Vec3& q) {
    return Vec3(((r(0, 0) * q.x() + r(0, 1) * q.y()) + r(0, 2) * q.z()) + t.x(),
                ((r(1, 0) * q.x() + r(1, 1) * q.y()) + r(1, 2) * q.z()) + t.y(),
                ((r(2, 0) * q.x() + r(2, 1) * q.y()) + r(2, 2) * q.z()) + t.z());
}

}  // namespace kolize::narrowphase::detail
