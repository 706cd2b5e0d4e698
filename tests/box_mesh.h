#pragma once
/// A box mesh for tests: [-h, h] as 8 vertices and 12 outward-wound triangles.

#include <kolize/narrowphase/triangle_mesh.h>

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

}  // namespace kolize::testing
