#pragma once
/// \file
/// Bounding-volume trees over a triangle mesh (thesis section 2.2): sphere tree and OBB
/// tree built as the thesis builds them, AABB and k-DOP trees beside them.
///
/// Construction (every kind): a node holds a range of triangles; the range is split by the
/// plane through the triangles' mean vertex mu, normal to the principal axis of their
/// vertex covariance (thesis formula 2.4), each triangle going to the side of its centroid;
/// a split that leaves one side empty falls back to the median centroid along that axis.
/// Ranges of at most `leaf_size` triangles become leaves. Each node's volume is fitted to
/// its own triangles (OBB: the covariance's eigenvectors), rounded outward to float.
/// Cost O(n log n) for balanced splits (O(n^2) worst case for pathological meshes).
///
/// Layout: all nodes in one array in depth-first order. Node 0 is the root; an internal
/// node's first child is the next node, its second child is `link.right()`. Leaves keep a
/// range of "slots": the tree's copy of the triangles, reordered so that every leaf's
/// triangles are contiguous, with `triangleOrder()` mapping a slot back to the mesh's
/// triangle index.
#include "kolize/narrowphase/bounding_volume.h"
#include "kolize/narrowphase/triangle_mesh.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace kolize::narrowphase {

/// Which volume a tree is made of.
enum class TreeKind : std::uint8_t { kSphere, kAabb, kObb, kKdop6, kKdop14, kKdop18, kKdop26 };

/// "sphere", "aabb", "obb", "kdop6", "kdop14", "kdop18", "kdop26".
const char* treeKindName(TreeKind kind);

/// How a tree is built.
struct TreeSettings {
    /// The volume. OBB (default) is the thesis's tree and the query's fastest.
    TreeKind kind = TreeKind::kObb;
    /// Most triangles per leaf, 1..8 (default 4: about n/2 nodes, fewer BV tests for a few
    /// more triangle tests). Values outside 1..8 are refused (std::invalid_argument).
    int leaf_size = 4;
};

/// Child or leaf information of a node, in 4 bytes.
class NodeLink {
  public:
    static NodeLink internal(std::int32_t right) { return NodeLink(right); }
    static NodeLink leaf(std::int32_t firstSlot, int count) {
        return NodeLink(-1 - (firstSlot * 8 + (count - 1)));
    }
    bool isLeaf() const { return value_ < 0; }
    /// Second child's index (internal nodes).
    std::int32_t right() const { return value_; }
    /// First slot and slot count (leaves; 1..8 slots).
    std::int32_t firstSlot() const { return (-1 - value_) >> 3; }
    int count() const { return ((-1 - value_) & 7) + 1; }

  private:
    explicit NodeLink(std::int32_t value) : value_(value) {}
    std::int32_t value_ = 0;
};

struct SphereNode {
    Sphere volume;
    NodeLink link = NodeLink::internal(0);
    /// Model-space size that decides which tree to descend (pose-independent).
    float size() const { return volume.radius; }
};

struct AabbNode {
    Aabb volume;
    NodeLink link = NodeLink::internal(0);
    float size() const { return (volume.hi - volume.lo).sum(); }
};

/// 64 bytes, one cache line: centre, half extents, two axes (the third is their cross
/// product), the radius of a sphere around the centre containing the node's triangles,
/// the extent sum, the link.
struct alignas(64) ObbNode {
    Obb volume;
    float extentSum = 0;
    NodeLink link = NodeLink::internal(0);
    float size() const { return volume.radius; }
};

template <int K>
struct KdopNode {
    Kdop<K> volume;
    NodeLink link = NodeLink::internal(0);
    /// Widths along the three coordinate axes (the first three slabs), summed.
    float size() const {
        return (volume.hi[0] - volume.lo[0]) + (volume.hi[1] - volume.lo[1]) +
               (volume.hi[2] - volume.lo[2]);
    }
};

/// A tree of nodes of type Node over one mesh (the mesh is not owned: it must outlive the
/// tree, and a tree is only meaningful with the mesh it was built from).
template <class Node>
class BvTree {
  public:
    /// Builds over every triangle of `mesh`. Throws std::invalid_argument for a leaf size
    /// outside 1..8 or a mesh of 2^28 triangles or more.
    static BvTree build(const TriangleMesh& mesh, int leafSize);

    const std::vector<Node>& nodes() const { return nodes_; }
    /// Triangles in slot order (vertex indices of the mesh).
    const std::vector<Index3>& slotTriangles() const { return slots_; }
    /// Slot -> triangle index in the mesh.
    const std::vector<std::int32_t>& triangleOrder() const { return order_; }
    int leafSize() const { return leafSize_; }
    /// Bytes of the node array and of the per-triangle arrays (slots and order).
    std::size_t nodeBytes() const { return nodes_.size() * sizeof(Node); }
    std::size_t triangleBytes() const {
        return slots_.size() * sizeof(Index3) + order_.size() * sizeof(std::int32_t);
    }

    /// Checks every invariant against `mesh`, exactly: the depth-first layout and links;
    /// leaves of 1..leaf size slots covering every slot once in order; the order a
    /// permutation of the mesh's triangles matching the slot copies; every node's volume
    /// containing every vertex of every triangle below it (so each child's triangles are
    /// inside its parent's volume); and for AABB and k-DOP trees every child volume inside
    /// its parent's. (An OBB or sphere fitted to a child's own triangles is generally not
    /// inside the parent's volume, and the traversal does not need it to be.) Returns ""
    /// when valid, else a description of the first violation.
    std::string validate(const TriangleMesh& mesh) const;

  private:
    std::vector<Node> nodes_;
    std::vector<Index3> slots_;
    std::vector<std::int32_t> order_;
    int leafSize_ = 4;
};

using SphereTree = BvTree<SphereNode>;
using AabbTree = BvTree<AabbNode>;
using ObbTree = BvTree<ObbNode>;
template <int K>
using KdopTree = BvTree<KdopNode<K>>;

}  // namespace kolize::narrowphase
