#pragma once
/// \file
/// Rigid poses and the relative pose a mesh query works in.
#include "kolize/narrowphase/predicates.h"

#include <Eigen/Core>

namespace kolize::narrowphase {

/// A rigid pose: world = rotation * model + translation. `rotation` must be a rotation
/// matrix up to rounding (columns orthonormal within 1e-6); queries reject anything else.
struct Pose {
    Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
    Vec3 translation = Vec3::Zero();
};

/// Pose of mesh B in mesh A's model frame, computed once per query in double:
/// rotation = Ra^T Rb, translation = Ra^T (tb - ta). A query classifies B's vertices as
/// `apply(q)` gives them, exactly; `apply` evaluates in a fixed order so that every caller
/// (the query, the reference, a user checking a result) gets the same doubles.
class RelativePose {
  public:
    RelativePose() = default;  ///< identity
    RelativePose(const Pose& a, const Pose& b);
    /// ((R00 q0 + R01 q1) + R02 q2) + t0, and likewise for rows 1 and 2.
    Vec3 apply(const Vec3& q) const;
    const Eigen::Matrix3d& rotation() const { return rotation_; }
    const Vec3& translation() const { return translation_; }
    /// Largest |(R^T R - I)_ij|: how far the rotation is from orthonormal.
    double orthonormalityError() const;

  private:
    Eigen::Matrix3d rotation_ = Eigen::Matrix3d::Identity();
    Vec3 translation_ = Vec3::Zero();
};

}  // namespace kolize::narrowphase
