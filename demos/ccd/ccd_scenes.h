#pragma once
// Scenes shared by the CCD demos and the query recorder: a box as a mesh, the thin-wall
// trials of the tunneling demo and the mesh demo's copies fired at a fixed model.
#include "kolize/narrowphase/mesh_ccd.h"

#include <Eigen/Geometry>

#include <cmath>
#include <cstdint>
#include <vector>

namespace kolize::ccd::scenes {

/// Axis-aligned box [lo, hi] as a closed 12-triangle mesh, translated by `motion`.
inline MovingMesh boxMesh(const Vec3& lo, const Vec3& hi, const Vec3& motion) {
    MovingMesh m;
    for (int i = 0; i < 8; ++i) {
        const Vec3 p(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(), i & 4 ? hi.z() : lo.z());
        m.start.push_back(p);
        m.end.push_back(p + motion);
    }
    m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                   {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    return m;
}

/// Deterministic uniform numbers in [0, 1) (64-bit LCG, top 53 bits).
struct Random {
    uint64_t state = 0x853c49e6748fea9bull;
    double next() {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return static_cast<double>(state >> 11) * 0x1p-53;
    }
};

/// The thin wall: a plate 2 x 2, 0.01 thick, at x in [0, 0.01].
struct ThinWall {
    static constexpr double kEdge = 0.2;  ///< the fired cube's edge
    Vec3 plate_lo{0, -1, -1}, plate_hi{0.01, 1, 1};
    MovingMesh plate = boxMesh(plate_lo, plate_hi, Vec3::Zero());

    struct Trial {
        Vec3 lo, hi, motion;
    };
    /// A cube moving `speed` along +x whose front face reaches the plate at a uniformly
    /// drawn time of the step: every trial truly hits.
    static Trial trial(double speed, Random& random) {
        const double tau = random.next();
        const Vec3 lo(-kEdge - tau * speed, random.next() - 0.5, random.next() - 0.5);
        return {lo, lo + Vec3::Constant(kEdge), Vec3(speed, 0, 0)};
    }
};

/// The mesh demo's scenarios: a copy of `fixed` fired at it from 12 directions (Fibonacci
/// sphere), starting 2.2 radii away, travelling 1.5 or 2.5 radii, turning by 0 or 0.6
/// radians; calls `f(moving)` for each of the 48.
template <class F>
void forEachFiredCopy(const MovingMesh& fixed, F&& f) {
    constexpr int kDirections = 12;
    const double golden = M_PI * (3.0 - std::sqrt(5.0));
    for (int k = 0; k < kDirections; ++k) {
        const double z = 1.0 - 2.0 * (k + 0.5) / kDirections, r = std::sqrt(1.0 - z * z);
        const Vec3 dir(r * std::cos(golden * k), r * std::sin(golden * k), z);
        for (int s = 0; s < 2; ++s) {
            for (int rot = 0; rot < 2; ++rot) {
                const double travel = 1.5 + 1.0 * s, angle = 0.6 * rot;
                const Eigen::AngleAxisd spin(angle, dir.unitOrthogonal());
                MovingMesh moving = fixed;
                for (size_t v = 0; v < fixed.start.size(); ++v) {
                    moving.start[v] = fixed.start[v] + 2.2 * dir;
                    moving.end[v] = spin * fixed.start[v] + (2.2 - travel) * dir;
                }
                f(moving);
            }
        }
    }
}

}  // namespace kolize::ccd::scenes
