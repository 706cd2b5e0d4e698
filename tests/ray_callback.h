#pragma once
/// A broadphase ray callback prepared the way btCollisionWorld::rayTest prepares its own
/// (inverse direction, signs, the ray's length as lambda_max), for tests that call a
/// broadphase's rayTest directly. Derived callbacks say what a hit does.

#include <btBulletCollisionCommon.h>

namespace kolize {

struct PreparedRayCallback : btBroadphaseRayCallback {
    PreparedRayCallback(const btVector3& from, const btVector3& to) {
        const btVector3 direction = (to - from).normalized();
        for (int axis = 0; axis < 3; ++axis) {
            m_rayDirectionInverse[axis] = direction[axis] == btScalar(0)
                                              ? btScalar(BT_LARGE_FLOAT)
                                              : btScalar(1) / direction[axis];
            m_signs[axis] = m_rayDirectionInverse[axis] < 0;
        }
        m_lambda_max = direction.dot(to - from);
    }
};

}  // namespace kolize
