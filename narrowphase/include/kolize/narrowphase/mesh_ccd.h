#pragma once
/// Continuous collision detection between two triangle meshes over one step.
///
/// Each mesh's vertices move linearly from `start` to `end` over t in [0, 1]. Candidate
/// triangle pairs come from a bounding volume hierarchy of swept boxes (the box around a
/// triangle's six positions contains it at every t in [0, 1]); every vertex-face and
/// edge-edge pair of a candidate is tested with the robust primitive, so the result
/// inherits its guarantee: no missed contact, and `toi` never later than the true one.
/// The thesis's "normal facing the motion" culling is available but off by default: it is
/// unsafe (see MeshCcdSettings::cull_back_facing) and voids the guarantee.
#include "kolize/narrowphase/ccd.h"

#include <array>
#include <cstddef>
#include <vector>

namespace kolize::ccd {

/// A triangle mesh whose vertices move linearly over the step.
struct MovingMesh {
    std::vector<Vec3> start;                    ///< vertex positions at t = 0
    std::vector<Vec3> end;                      ///< vertex positions at t = 1 (same size)
    std::vector<std::array<int, 3>> triangles;  ///< vertex indices
};

/// Which features of the two meshes produced the earliest contact.
enum class ContactFeatures {
    kVertexAFaceB,  ///< vertex `a[0]` of mesh A against triangle `b[0]` of mesh B
    kFaceAVertexB,  ///< triangle `a[0]` of mesh A against vertex `b[0]` of mesh B
    kEdgeEdge,      ///< edge (a[0], a[1]) of mesh A against edge (b[0], b[1]) of mesh B
};

/// Earliest contact between two moving meshes, with counters of the work done.
struct MeshContact {
    bool hit = false;
    double toi = 1.0;  ///< no later than the true earliest contact when `hit`
    ContactFeatures features = ContactFeatures::kVertexAFaceB;
    std::array<int, 2> a{-1, -1};       ///< vertex, triangle or edge of mesh A (see features)
    std::array<int, 2> b{-1, -1};       ///< vertex, triangle or edge of mesh B (see features)
    std::size_t triangle_pairs = 0;     ///< candidate pairs whose swept boxes overlap
    std::size_t primitive_queries = 0;  ///< distinct vertex-face and edge-edge tests run
    std::size_t culled = 0;             ///< vertex-face tests skipped by `cull_back_facing`
};

/// Settings of the mesh-mesh test.
struct MeshCcdSettings {
    /// Settings of every vertex-face and edge-edge test (see RobustSettings). Meshes must
    /// have fewer than 2^30 vertices (test bookkeeping packs indices into 32 bits).
    RobustSettings primitive;
    /// The thesis's culling: skip a vertex-face test when the vertex's motion relative to
    /// the face's centroid does not point against the face normal at t = 0 (normal from
    /// the winding, assumed outward). Unsafe: a rotating face can turn towards the vertex
    /// within the step, and the test is skipped for a vertex already behind the face.
    /// kolize-ccd-mesh-demo measures what it saves and what it loses. Default off.
    bool cull_back_facing = false;
};

/// Earliest time of impact between meshes `a` and `b` over the step, and the features
/// involved. Throws std::invalid_argument if a mesh's start and end sizes differ or a
/// triangle indexes outside its vertices.
MeshContact meshCcd(const MovingMesh& a, const MovingMesh& b, const MeshCcdSettings& settings = {});

}  // namespace kolize::ccd
