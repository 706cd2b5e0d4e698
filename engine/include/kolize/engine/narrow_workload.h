#pragma once
/// \file
/// Workloads of the narrowphase (mesh against mesh) tests and benchmark: meshes from
/// Debian's assimp-testmodels and generated ones, and seeded poses in the pose classes of
/// the anchors' measurements (docs: NARROWPHASE.md): deep, shallow, near, apart, and the
/// exact-contact poses of a mesh against its own copy.
#include <kolize/narrowphase/mesh_model.h>
#include <kolize/narrowphase/pose.h>
#include <kolize/narrowphase/triangle_mesh.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace kolize::workload {

using narrowphase::MeshModel;
using narrowphase::Pose;
using narrowphase::TriangleMesh;
using narrowphase::Vec3;

/// A mesh with its placement: vertices are the file's coordinates times a power of two
/// (exact, so zero-area and coplanar triangles stay exactly so), `center` the centre of the
/// vertices' box and `radius` the largest distance from it, in (0.5, 1].
struct WorkloadMesh {
    std::string name;
    std::shared_ptr<const TriangleMesh> mesh;
    Vec3 center = Vec3::Zero();
    double radius = 1;
};

/// Folder of Debian's assimp-testmodels (KOLIZE_ASSIMP_MODELS overrides), or "" if absent.
std::string assimpModelsDirectory();

/// Loads `relativePath` under assimpModelsDirectory() with the engine's assimp loader.
/// Throws std::runtime_error naming the file (missing package, unreadable file, or an
/// engine built without assimp).
WorkloadMesh loadModel(const std::string& relativePath, const std::string& name);

/// The meshes of the anchors' measurements: spider.obj (56 zero-area triangles),
/// MotionCaptureROM.ase (the thesis's format), WusonOBJ.obj, duck.dae, HUMAN.blend,
/// SphereWithLight.ac; and Wuson.ply for a PLY file.
struct ModelFile {
    const char* name;
    const char* path;
};
const std::vector<ModelFile>& standardModels();

/// Generated meshes (closed unless noted), radius 1 around the origin.
WorkloadMesh uvSphere(int rings, int segments);
WorkloadMesh torus(int rings, int segments, double tube);
/// A cube with every face cut into n x n squares (two triangles each): coplanar faces.
WorkloadMesh subdividedBox(int n);
/// An open, wavy n x n grid sheet with zero-area triangles (collinear and repeated
/// vertices) mixed in every few cells.
WorkloadMesh sheetWithDegenerates(int n);

/// Pose classes. Distances are along a random direction, in units of the mean radius r.
enum class PoseClass {
    kDeep,        ///< centre distance 0.3-0.8 x the touching distance s*
    kShallow,     ///< s* minus 1e-3..1e-2 r: just inside
    kNear,        ///< s* plus a gap of 0.002-0.02 r: just apart
    kApart,       ///< farther apart (gap > 0.02 r), world AABBs still overlap: a pair the
                  ///< broadphase hands to the narrowphase
    kApartObb,    ///< farther apart (gap > 0.02 r), the root OBBs still overlap (harder)
    kCoincident,  ///< a mesh against its own copy at the same pose
    kShifted,     ///< the copy shifted by 2^-8 along x, y or z
};
const char* poseClassName(PoseClass kind);
/// The five random classes, then the two exact-contact ones.
const std::vector<PoseClass>& allPoseClasses();

struct WorkloadPose {
    PoseClass kind;
    Pose a, b;
};

/// `count` seeded poses of one class for meshes a and b (models: OBB trees of their
/// meshes, used to find the touching distance by bisection on yes/no queries). The exact
/// classes need a and b to be the same mesh and give 1 (coincident) or 3 (shifted) poses.
std::vector<WorkloadPose> makePoses(const WorkloadMesh& a, const MeshModel& modelA,
                                    const WorkloadMesh& b, const MeshModel& modelB, PoseClass kind,
                                    int count, std::uint32_t seed);

}  // namespace kolize::workload
