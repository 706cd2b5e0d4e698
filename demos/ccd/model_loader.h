#pragma once
// Loads an assimp model as a static MovingMesh (shared by the CCD mesh demo and recorder).
#include "kolize/narrowphase/mesh_ccd.h"

#include <Eigen/Geometry>
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <cstdio>
#include <string>

namespace kolize::ccd {

/// All meshes of the file merged, centred on the bounding box centre and scaled to unit
/// bounding radius. Returns false (with a message) if the file has no triangles.
inline bool loadModel(const std::string& path, MovingMesh& mesh, const char* program) {
    Assimp::Importer importer;
    const aiScene* scene =
        importer.ReadFile(path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                    aiProcess_PreTransformVertices);
    if (!scene) {
        std::fprintf(stderr, "%s: %s\n", program, importer.GetErrorString());
        return false;
    }
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
        const aiMesh* in = scene->mMeshes[m];
        const int base = static_cast<int>(mesh.start.size());
        for (unsigned v = 0; v < in->mNumVertices; ++v) {
            mesh.start.emplace_back(in->mVertices[v].x, in->mVertices[v].y, in->mVertices[v].z);
        }
        for (unsigned f = 0; f < in->mNumFaces; ++f) {
            if (in->mFaces[f].mNumIndices == 3) {
                const unsigned* i = in->mFaces[f].mIndices;
                mesh.triangles.push_back({base + static_cast<int>(i[0]),
                                          base + static_cast<int>(i[1]),
                                          base + static_cast<int>(i[2])});
            }
        }
    }
    if (mesh.triangles.empty()) {
        std::fprintf(stderr, "%s: no triangles in %s\n", program, path.c_str());
        return false;
    }
    Eigen::AlignedBox3d box;
    for (const Vec3& p : mesh.start) {
        box.extend(p);
    }
    const double radius = 0.5 * box.diagonal().norm();
    for (Vec3& p : mesh.start) {
        p = (p - box.center()) / radius;
    }
    mesh.end = mesh.start;
    return true;
}

}  // namespace kolize::ccd
