#include <kolize/engine/assets.h>

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <stdexcept>

namespace kolize {

LoadedMesh loadMesh(const std::string& path) {
    Assimp::Importer importer;
    // Points and lines are removed (aiProcess_SortByPType + the ignore list) instead of
    // reaching us as one- and two-index faces.
    importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                                aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    const aiScene* scene =
        importer.ReadFile(path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                    aiProcess_PreTransformVertices | aiProcess_SortByPType);
    if (scene == nullptr) {
        throw std::runtime_error("cannot load mesh file '" + path +
                                 "': " + importer.GetErrorString());
    }
    LoadedMesh out;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
        const aiMesh* mesh = scene->mMeshes[m];
        const int base = int(out.vertices.size());
        for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
            const aiVector3D& p = mesh->mVertices[v];
            out.vertices.emplace_back(btScalar(p.x), btScalar(p.y), btScalar(p.z));
        }
        for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
            const aiFace& face = mesh->mFaces[f];
            if (face.mNumIndices != 3) {
                throw std::runtime_error("mesh file '" + path + "': a face with " +
                                         std::to_string(face.mNumIndices) +
                                         " corners after triangulation");
            }
            out.triangles.push_back({base + int(face.mIndices[0]), base + int(face.mIndices[1]),
                                     base + int(face.mIndices[2])});
        }
    }
    if (out.triangles.empty()) {
        throw std::runtime_error("mesh file '" + path + "' holds no triangles");
    }
    return out;
}

}  // namespace kolize
