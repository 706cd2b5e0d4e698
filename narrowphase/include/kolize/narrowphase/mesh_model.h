#pragma once
/// \file
/// A mesh ready for queries: the validated triangles, a bounding-volume tree of one kind,
/// and the object's bounding sphere (thesis stage 2).
#include "kolize/narrowphase/bv_tree.h"
#include "kolize/narrowphase/triangle_mesh.h"

#include <memory>
#include <string>
#include <variant>

namespace kolize::narrowphase {

/// The object's bounding sphere in its model frame (double; contains every vertex).
struct BoundingSphere {
    Vec3 center = Vec3::Zero();
    double radius = 0;
};

/// Shares the mesh (several models, e.g. one per tree kind, or many bodies, may use one)
/// and owns its tree. Immutable after construction; safe to query from several threads.
class MeshModel {
  public:
    /// Builds the tree (O(n log n), see bv_tree.h). Throws std::invalid_argument for a null
    /// mesh or a leaf size outside 1..8.
    explicit MeshModel(std::shared_ptr<const TriangleMesh> mesh, const TreeSettings& settings = {});

    const TriangleMesh& mesh() const { return *mesh_; }
    const std::shared_ptr<const TriangleMesh>& sharedMesh() const { return mesh_; }
    const TreeSettings& settings() const { return settings_; }
    TreeKind kind() const { return settings_.kind; }
    const BoundingSphere& sphere() const { return sphere_; }

    /// The tree, for the kind this model was built with (std::bad_variant_access else).
    template <class Node>
    const BvTree<Node>& tree() const {
        return std::get<BvTree<Node>>(tree_);
    }
    std::size_t nodeCount() const;
    /// sizeof one node of this kind (64 for OBB).
    std::size_t bytesPerNode() const;
    /// Nodes plus the per-triangle slot arrays.
    std::size_t treeBytes() const;
    /// The tree's validate() (see bv_tree.h) plus the object sphere's containment.
    std::string validate() const;

  private:
    std::shared_ptr<const TriangleMesh> mesh_;
    TreeSettings settings_;
    BoundingSphere sphere_;
    std::variant<SphereTree, AabbTree, ObbTree, KdopTree<6>, KdopTree<14>, KdopTree<18>,
                 KdopTree<26>>
        tree_;
};

}  // namespace kolize::narrowphase
