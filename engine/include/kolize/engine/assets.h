#pragma once
/// \file
/// Triangle meshes from model files through assimp (built when KOLIZE_WITH_ASSIMP is ON).

#include <LinearMath/btVector3.h>

#include <array>
#include <string>
#include <vector>

namespace kolize {

/// Every mesh of a model file merged into one triangle list.
struct LoadedMesh {
    std::vector<btVector3> vertices;
    std::vector<std::array<int, 3>> triangles;  ///< indices into vertices
};

/// Loads all meshes of `path` with assimp: polygons triangulated, identical vertices joined,
/// and the node transforms applied (aiProcess_PreTransformVertices), so a file made of
/// several placed parts (ASE/ThreeCubesGreen.ASE) keeps its layout. Points and lines are
/// dropped by triangulation; faces that stay non-triangular are an error. Coordinates as in
/// the file (no scaling or centring). Throws std::runtime_error naming the file and
/// assimp's error when it cannot be read, or when it holds no triangles.
LoadedMesh loadMesh(const std::string& path);

}  // namespace kolize
