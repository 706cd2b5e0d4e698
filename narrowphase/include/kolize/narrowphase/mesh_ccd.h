#pragma once
/// Continuous collision detection between two triangle meshes over one step.
///
/// Each mesh's vertices move linearly from `start` to `end` over t in [0, 1]. The step is
/// cut into time slices (a power of two, at most `max_time_slices`, so that a slice moves
/// the fastest vertices about one mean edge length), processed in time order. In a slice, every
/// feature (vertex, edge, triangle) has a box around its positions at the slice's two ends,
/// which contains it throughout the slice by convexity (inflated to cover rounding). Only
/// the features whose box over the whole step meets the other mesh's box over the whole
/// step take part (no other can have a candidate pair): a small mesh against a large one
/// builds hierarchies over the part of the large one it can reach. A
/// hierarchy per feature kind, built once and refitted per slice, is descended together
/// with the other mesh's to find the vertex-triangle and edge-edge pairs whose boxes
/// overlap, and each is tested with the robust primitive over the slice only. The first
/// slice with a contact holds the earliest one. Every vertex and edge is tested once per
/// slice. The result inherits the primitive's guarantee: a contact is reported if and only
/// if the meshes touch, and `toi` is never later than the first contact.
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
    std::array<int, 2> a{-1, -1};  ///< vertex, triangle or edge of mesh A (see features)
    std::array<int, 2> b{-1, -1};  ///< vertex, triangle or edge of mesh B (see features)
    /// Vertex-triangle and edge-edge pairs whose slice boxes overlap, summed over slices.
    std::size_t candidate_pairs = 0;
    std::size_t primitive_queries = 0;  ///< vertex-face and edge-edge tests run
    std::size_t culled = 0;             ///< vertex-face tests skipped by `cull_back_facing`
    std::size_t time_slices = 0;        ///< slices examined (the step's, up to the contact)
    /// Vertices, edges and triangles of both meshes left out: out of the other's reach.
    std::size_t out_of_reach = 0;
};

/// Settings of the mesh-mesh test.
struct MeshCcdSettings {
    /// Settings of every vertex-face and edge-edge test (see RobustSettings); its
    /// [min_time, max_time] limits the mesh test too. Meshes must have fewer than 2^31
    /// vertices.
    RobustSettings primitive;
    /// The thesis's culling: skip a vertex-face test when the vertex's motion relative to
    /// the face's centroid does not point against the face normal at t = 0 (normal from
    /// the winding, assumed outward). Unsafe: a rotating face can turn towards the vertex
    /// within the step, and the test is skipped for a vertex already behind the face.
    /// kolize-ccd-mesh-demo measures what it saves and what it loses. Default off.
    bool cull_back_facing = false;
    /// Upper bound on the number of time slices (rounded down to a power of two); 1 tests
    /// every pair whose boxes over the whole step overlap (the slicing's reference).
    int max_time_slices = 256;
};

/// Earliest time of impact between meshes `a` and `b` over the step, and the features
/// involved. Throws std::invalid_argument if a mesh's start and end sizes differ or a
/// triangle indexes outside its vertices.
MeshContact meshCcd(const MovingMesh& a, const MovingMesh& b, const MeshCcdSettings& settings = {});

}  // namespace kolize::ccd
