#pragma once
/// \file
/// A validated triangle mesh: the input of bounding-volume trees and mesh queries.
#include "kolize/narrowphase/triangle_test.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace kolize::narrowphase {

/// Vertex indices of one triangle.
using Index3 = std::array<std::int32_t, 3>;

/// Bad mesh data. The message names the mesh and the offending element, e.g.
/// "mesh 'duck': vertex 17 has a non-finite coordinate (y = nan)".
class MeshError : public std::invalid_argument {
  public:
    using std::invalid_argument::invalid_argument;
};

/// Vertices (double) and triangles (indices), checked once at construction and immutable
/// afterwards. Legal: zero-area triangles, duplicate and unused vertices, repeated
/// triangles, any winding. Rejected with MeshError: no triangles, a coordinate that is not
/// finite or whose magnitude exceeds kMaxCoordinate, an index outside [0, vertex count).
class TriangleMesh {
  public:
    /// Coordinates beyond 2^500 are refused: poses and the exact predicates then never
    /// overflow (the predicates stay exact up to there, through GMP).
    static constexpr double kMaxCoordinate = 0x1p500;

    /// Checks and keeps the arrays; O(vertices + triangles). Throws MeshError.
    TriangleMesh(std::string name, std::vector<Vec3> vertices, std::vector<Index3> triangles);

    /// From flat arrays: `xyz` holds 3 * vertexCount coordinates, `indices` 3 per triangle.
    /// Throws MeshError also when indexCount is not a multiple of 3.
    static TriangleMesh fromArrays(std::string name, const double* xyz, std::size_t vertexCount,
                                   const std::int32_t* indices, std::size_t indexCount);
    static TriangleMesh fromArrays(std::string name, const float* xyz, std::size_t vertexCount,
                                   const std::int32_t* indices, std::size_t indexCount);

    const std::string& name() const { return name_; }
    const std::vector<Vec3>& vertices() const { return vertices_; }
    const std::vector<Index3>& triangles() const { return triangles_; }
    std::size_t triangleCount() const { return triangles_.size(); }
    Triangle triangle(std::size_t i) const {
        const Index3& t = triangles_[i];
        return {vertices_[t[0]], vertices_[t[1]], vertices_[t[2]]};
    }
    /// Largest Euclidean norm of a vertex (bounds every coordinate and every box centre).
    double coordinateBound() const { return coordinateBound_; }
    /// Triangles whose vertices are collinear or coincident, exactly (orient2d in all three
    /// projections).
    std::size_t zeroAreaTriangles() const;

  private:
    std::string name_;
    std::vector<Vec3> vertices_;
    std::vector<Index3> triangles_;
    double coordinateBound_ = 0;
};

}  // namespace kolize::narrowphase
