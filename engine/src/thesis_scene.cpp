#include <kolize/engine/thesis_scene.h>

#include <cmath>
#include <random>
#include <stdexcept>

namespace kolize {

const char* layoutName(ThesisLayout layout) {
    return layout == ThesisLayout::Uniform ? "A" : "B";
}

const char* motionName(ThesisMotion motion) {
    return motion == ThesisMotion::Slow ? "slow" : "fast";
}

namespace {

constexpr double kPi = 3.14159265358979323846;

/// Rotation by `angle` about the unit `axis` (Rodrigues), row-major.
std::array<double, 9> axisAngle(const std::array<double, 3>& axis, double angle) {
    const double c = std::cos(angle), s = std::sin(angle), t = 1 - c;
    const double x = axis[0], y = axis[1], z = axis[2];
    return {t * x * x + c,     t * x * y - s * z, t * x * z + s * y,
            t * x * y + s * z, t * y * y + c,     t * y * z - s * x,
            t * x * z - s * y, t * y * z + s * x, t * z * z + c};
}

std::array<double, 4> planeRotation(double angle) {
    const double c = std::cos(angle), s = std::sin(angle);
    return {c, -s, s, c};
}

template <int D>
std::array<double, D * D> multiply(const std::array<double, D * D>& a,
                                   const std::array<double, D * D>& b) {
    std::array<double, D * D> out{};
    for (int row = 0; row < D; ++row) {
        for (int column = 0; column < D; ++column) {
            double sum = 0;
            for (int k = 0; k < D; ++k) {
                sum += a[row * D + k] * b[k * D + column];
            }
            out[row * D + column] = sum;
        }
    }
    return out;
}

/// Gram-Schmidt on the rows, so that thousands of frames of products stay a rotation.
template <int D>
void orthonormalise(std::array<double, D * D>& m) {
    for (int row = 0; row < D; ++row) {
        for (int previous = 0; previous < row; ++previous) {
            double dot = 0;
            for (int k = 0; k < D; ++k) {
                dot += m[row * D + k] * m[previous * D + k];
            }
            for (int k = 0; k < D; ++k) {
                m[row * D + k] -= dot * m[previous * D + k];
            }
        }
        double length = 0;
        for (int k = 0; k < D; ++k) {
            length += m[row * D + k] * m[row * D + k];
        }
        length = std::sqrt(length);
        for (int k = 0; k < D; ++k) {
            m[row * D + k] /= length;
        }
    }
}

template <int D>
std::array<double, D> randomDirection(std::mt19937_64& random) {
    std::normal_distribution<double> normal;
    std::array<double, D> v{};
    double length = 0;
    while (length < 1e-6) {
        length = 0;
        for (double& x : v) {
            x = normal(random);
            length += x * x;
        }
        length = std::sqrt(length);
    }
    for (double& x : v) {
        x /= length;
    }
    return v;
}

}  // namespace

template <int D>
ThesisScene<D>::ThesisScene(const ThesisSceneSettings& settings) : settings_(settings) {
    if (settings.objects < 0 || !(settings.halfSpace > 0) || !(settings.cubeEdge > 0) ||
        !(settings.clusterEdge > 0) || settings.clusterFraction < 0 ||
        settings.clusterFraction > 1) {
        throw std::invalid_argument(
            "ThesisScene: needs objects >= 0, positive sizes and clusterFraction in [0, 1]");
    }
    std::mt19937_64 random(settings.seed);
    std::uniform_real_distribution<double> unit(0, 1);
    const bool slow = settings.motion == ThesisMotion::Slow;
    const double speed = slow ? settings.slowSpeed : settings.fastSpeed;
    const double spin = slow ? settings.slowSpin : settings.fastSpin;
    const int clustered =
        settings.layout == ThesisLayout::Clustered
            ? static_cast<int>(std::lround(settings.objects * settings.clusterFraction))
            : 0;
    const int n = settings.objects;
    centres_.resize(n);
    velocities_.resize(n);
    walls_.resize(n);
    orientation_.resize(n);
    spin_.resize(n);
    boxes_.resize(n);
    for (int i = 0; i < n; ++i) {
        // Centres keep half a cube's diagonal away from the walls.
        walls_[i] = (i < clustered ? settings.clusterEdge / 2 : settings.halfSpace);
        const double reach = walls_[i] - settings.cubeEdge * std::sqrt(double(D)) / 2;
        for (int axis = 0; axis < D; ++axis) {
            centres_[i][axis] = (2 * unit(random) - 1) * (reach > 0 ? reach : 0);
        }
        const double magnitude = speed * (0.5 + unit(random));
        const Vec direction = randomDirection<D>(random);
        for (int axis = 0; axis < D; ++axis) {
            velocities_[i][axis] = magnitude * direction[axis];
        }
        const double turn = spin * (0.5 + unit(random));
        if constexpr (D == 3) {
            orientation_[i] = axisAngle(randomDirection<3>(random), 2 * kPi * unit(random));
            spin_[i] = axisAngle(randomDirection<3>(random), turn);
        } else {
            orientation_[i] = planeRotation(2 * kPi * unit(random));
            spin_[i] = planeRotation(unit(random) < 0.5 ? turn : -turn);
        }
        updateBox(i);
    }
}

template <int D>
void ThesisScene<D>::updateBox(int i) {
    const double half = settings_.cubeEdge / 2;
    for (int axis = 0; axis < D; ++axis) {
        double extent = 0;
        for (int k = 0; k < D; ++k) {
            extent += std::fabs(orientation_[i][axis * D + k]);
        }
        boxes_[i].lo[axis] = centres_[i][axis] - half * extent;
        boxes_[i].hi[axis] = centres_[i][axis] + half * extent;
    }
}

template <int D>
void ThesisScene<D>::step() {
    ++frame_;
    const bool renormalise = frame_ % 64 == 0;
    const double halfDiagonal = settings_.cubeEdge * std::sqrt(double(D)) / 2;
    for (int i = 0; i < size(); ++i) {
        const double reach = walls_[i] - halfDiagonal;
        for (int axis = 0; axis < D; ++axis) {
            double& x = centres_[i][axis];
            x += velocities_[i][axis];
            if (x > reach) {
                x = 2 * reach - x;
                velocities_[i][axis] = -velocities_[i][axis];
            } else if (x < -reach) {
                x = -2 * reach - x;
                velocities_[i][axis] = -velocities_[i][axis];
            }
        }
        orientation_[i] = multiply<D>(spin_[i], orientation_[i]);
        if (renormalise) {
            orthonormalise<D>(orientation_[i]);
        }
        updateBox(i);
    }
}

template class ThesisScene<2>;
template class ThesisScene<3>;

}  // namespace kolize
