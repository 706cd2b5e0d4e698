#include "kolize/narrowphase/pose.h"

#include "pose_internal.h"

#include <algorithm>
#include <cmath>

namespace kolize::narrowphase {

RelativePose::RelativePose(const Pose& a, const Pose& b) {
    const Eigen::Matrix3d& ra = a.rotation;
    const Eigen::Matrix3d& rb = b.rotation;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            rotation_(i, j) = (ra(0, i) * rb(0, j) + ra(1, i) * rb(1, j)) + ra(2, i) * rb(2, j);
        }
    }
    const Vec3 d = b.translation - a.translation;
    for (int i = 0; i < 3; ++i) {
        translation_[i] = (ra(0, i) * d.x() + ra(1, i) * d.y()) + ra(2, i) * d.z();
    }
}

Vec3 RelativePose::apply(const Vec3& q) const {
    return detail::applyFixedOrder(rotation_, translation_, q);
}

double RelativePose::orthonormalityError() const {
    const Eigen::Matrix3d e = rotation_.transpose() * rotation_ - Eigen::Matrix3d::Identity();
    return e.cwiseAbs().maxCoeff();
}

}  // namespace kolize::narrowphase
