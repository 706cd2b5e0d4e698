#pragma once
/// Meshes for tests: a box mesh ([-h, h] as 8 vertices and 12 outward-wound triangles) and a
/// grid of quads.

#include <kolize/narrowphase/triangle_mesh.h>

#include <cstdint>
#include <string>
#include <vector>

namespace kolize::testing {

inline narrowphase::TriangleMesh boxMesh(const narrowphase::Vec3& h,
                                         const std::string& name = "box") {
    std::vector<narrowphase::Vec3> vertices;
    for (int i = 0; i < 8; ++i) {
        vertices.emplace_back(i & 1 ? h.x() : -h.x(), i & 2 ? h.y() : -h.y(),
                              i & 4 ? h.z() : -h.z());
    }
    std::vector<narrowphase::Index3> triangles = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6},
                                                  {0, 1, 5}, {0, 5, 4}, {2, 6, 7}, {2, 7, 3},
                                                  {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
    return narrowphase::TriangleMesh(name, vertices, triangles);
}

/// A square grid of n x n quads of side `side` in the plane z = 0, centred, facing +z (an
/// open surface of 2 n^2 small triangles).
inline narrowphase::TriangleMesh gridMesh(int n, double side) {
    std::vector<narrowphase::Vec3> vertices;
    std::vector<narrowphase::Index3> triangles;
    for (int i = 0; i <= n; ++i) {
        for (int j = 0; j <= n; ++j) {
            vertices.emplace_back((i - 0.5 * n) * side, (j - 0.5 * n) * side, 0);
        }
    }
    for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
            const std::int32_t v = i * (n + 1) + j;
            triangles.push_back({v, v + n + 1, v + n + 2});
            triangles.push_back({v, v + n + 2, v + 1});
        }
    }
    return narrowphase::TriangleMesh("grid", vertices, triangles);
}

}  // namespace kolize::testing
