/// kolize-ccd-mesh-demo [MODEL]
///
/// Mesh against mesh CCD on an assimp-loaded model (default: assimp's cube.ply test
/// model): a moving copy is fired at a static copy from 12 directions, with 2 travel
/// distances and 2 rotation amounts. Each scenario runs with and without the thesis's
/// "normal facing the motion" culling and reports what the culling saves (vertex-face
/// tests, time) and what it loses (contacts missed, times of impact made later).
#include "kolize/narrowphase/mesh_ccd.h"

#include <Eigen/Geometry>
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

namespace {

using namespace kolize::ccd;

/// All meshes of the file merged, centred on the bounding box centre and scaled to unit
/// bounding radius. Returns false (with a message) if the file has no triangles.
bool loadModel(const std::string& path, MovingMesh& mesh) {
    Assimp::Importer importer;
    const aiScene* scene =
        importer.ReadFile(path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                    aiProcess_PreTransformVertices);
    if (!scene) {
        std::fprintf(stderr, "kolize-ccd-mesh-demo: %s\n", importer.GetErrorString());
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
        std::fprintf(stderr, "kolize-ccd-mesh-demo: no triangles in %s\n", path.c_str());
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

}  // namespace

int main(int argc, char** argv) {
    const std::string path = argc > 1 ? argv[1] : "/usr/share/assimp/models/PLY/cube.ply";
    MovingMesh fixed;
    if (!loadModel(path, fixed)) {
        return 1;
    }
    std::printf("model %s: %zu vertices, %zu triangles (scaled to unit radius)\n", path.c_str(),
                fixed.start.size(), fixed.triangles.size());

    MeshCcdSettings full, culled;
    culled.cull_back_facing = true;
    int scenarios = 0, hits = 0, lost = 0, later = 0;
    double max_delay = 0.0;
    size_t queries_full = 0, queries_culled = 0;
    double ms_full = 0, ms_culled = 0;
    constexpr int kDirections = 12;
    const double golden = M_PI * (3.0 - std::sqrt(5.0));
    for (int k = 0; k < kDirections; ++k) {
        // Fibonacci sphere directions; the copy starts 2.2 radii away (bounding spheres
        // apart) and travels 1.5 .. 3 radii towards the fixed copy while rotating.
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
                const auto t0 = std::chrono::steady_clock::now();
                const MeshContact a = meshCcd(moving, fixed, full);
                const auto t1 = std::chrono::steady_clock::now();
                const MeshContact b = meshCcd(moving, fixed, culled);
                const auto t2 = std::chrono::steady_clock::now();
                ms_full += std::chrono::duration<double, std::milli>(t1 - t0).count();
                ms_culled += std::chrono::duration<double, std::milli>(t2 - t1).count();
                ++scenarios;
                hits += a.hit;
                lost += a.hit && !b.hit;
                // Both tois are conservative (up to ~toi_tolerance early), so only a
                // clearly later one means culling skipped the earliest contact.
                later += a.hit && b.hit && b.toi > a.toi + 1e-4;
                if (a.hit && b.hit) {
                    max_delay = std::max(max_delay, b.toi - a.toi);
                }
                queries_full += a.primitive_queries;
                queries_culled += b.primitive_queries;
            }
        }
    }
    std::printf("\n%-26s %12s %12s\n", "", "no culling", "culling");
    std::printf("%-26s %12d %12d\n", "scenarios with contact", hits, hits - lost);
    std::printf("%-26s %12s %12d\n", "contacts lost", "0", lost);
    std::printf("%-26s %12s %12d\n", "toi later by > 1e-4", "-", later);
    std::printf("%-26s %12s %12.2g\n", "largest toi delay", "-", max_delay);
    std::printf("%-26s %12zu %12zu\n", "primitive tests", queries_full, queries_culled);
    std::printf("%-26s %12.1f %12.1f\n", "total time (ms)", ms_full, ms_culled);
    std::printf(
        "\n%d scenarios. Culling is off by default in meshCcd: any lost contact or "
        "later toi is a missed collision.\n",
        scenarios);
    return 0;
}
