#include "kolize/narrowphase/triangle_mesh.h"

#include <algorithm>
#include <charconv>
#include <cmath>

namespace kolize::narrowphase {

namespace {

/// The shortest text that reads back as x ("1e+200", "nan", "-inf").
std::string formatNumber(double x) {
    if (std::isnan(x)) {
        return "nan";
    }
    if (std::isinf(x)) {
        return x > 0 ? "inf" : "-inf";
    }
    char text[32];
    const std::to_chars_result r = std::to_chars(text, text + sizeof text, x);
    return std::string(text, r.ptr);
}

template <class Scalar>
TriangleMesh fromFlat(std::string name, const Scalar* xyz, std::size_t vertexCount,
                      const std::int32_t* indices, std::size_t indexCount) {
    if (indexCount % 3 != 0) {
        throw MeshError("mesh '" + name + "': " + std::to_string(indexCount) +
                        " indices is not a whole number of triangles (3 per triangle)");
    }
    std::vector<Vec3> vertices(vertexCount);
    for (std::size_t i = 0; i < vertexCount; ++i) {
        vertices[i] = Vec3(double(xyz[3 * i]), double(xyz[3 * i + 1]), double(xyz[3 * i + 2]));
    }
    std::vector<Index3> triangles(indexCount / 3);
    for (std::size_t i = 0; i < triangles.size(); ++i) {
        triangles[i] = {indices[3 * i], indices[3 * i + 1], indices[3 * i + 2]};
    }
    return TriangleMesh(std::move(name), std::move(vertices), std::move(triangles));
}

}  // namespace

TriangleMesh::TriangleMesh(std::string name, std::vector<Vec3> vertices,
                           std::vector<Index3> triangles)
    : name_(std::move(name)), vertices_(std::move(vertices)), triangles_(std::move(triangles)) {
    const std::string prefix = "mesh '" + name_ + "': ";
    if (triangles_.empty()) {
        throw MeshError(prefix + "has no triangles (" + std::to_string(vertices_.size()) +
                        " vertices)");
    }
    const char* axis = "xyz";
    for (std::size_t i = 0; i < vertices_.size(); ++i) {
        for (int k = 0; k < 3; ++k) {
            const double x = vertices_[i][k];
            if (!std::isfinite(x)) {
                throw MeshError(prefix + "vertex " + std::to_string(i) +
                                " has a non-finite coordinate (" + axis[k] + " = " +
                                formatNumber(x) + ")");
            }
            if (std::fabs(x) > kMaxCoordinate) {
                throw MeshError(prefix + "vertex " + std::to_string(i) + " has coordinate " +
                                axis[k] + " = " + formatNumber(x) +
                                ", beyond the supported magnitude 2^500");
            }
        }
        coordinateBound_ = std::max(coordinateBound_, vertices_[i].norm());
    }
    const std::int64_t count = std::int64_t(vertices_.size());
    for (std::size_t t = 0; t < triangles_.size(); ++t) {
        for (int k = 0; k < 3; ++k) {
            const std::int32_t index = triangles_[t][k];
            if (index < 0 || index >= count) {
                throw MeshError(prefix + "triangle " + std::to_string(t) + " has vertex index " +
                                std::to_string(index) + " (corner " + std::to_string(k) +
                                "), outside [0, " + std::to_string(count) + ")");
            }
        }
    }
}

TriangleMesh TriangleMesh::fromArrays(std::string name, const double* xyz, std::size_t vertexCount,
                                      const std::int32_t* indices, std::size_t indexCount) {
    return fromFlat(std::move(name), xyz, vertexCount, indices, indexCount);
}

TriangleMesh TriangleMesh::fromArrays(std::string name, const float* xyz, std::size_t vertexCount,
                                      const std::int32_t* indices, std::size_t indexCount) {
    return fromFlat(std::move(name), xyz, vertexCount, indices, indexCount);
}

std::size_t TriangleMesh::zeroAreaTriangles() const {
    std::size_t count = 0;
    for (std::size_t t = 0; t < triangles_.size(); ++t) {
        const Triangle p = triangle(t);
        bool flat = true;
        for (int drop = 0; drop < 3 && flat; ++drop) {
            const int u = (drop + 1) % 3, v = (drop + 2) % 3;
            flat = orient2d(p[0][u], p[0][v], p[1][u], p[1][v], p[2][u], p[2][v]) == 0;
        }
        count += flat;
    }
    return count;
}

}  // namespace kolize::narrowphase
