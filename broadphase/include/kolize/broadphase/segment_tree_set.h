#pragma once
/// \file
/// SegmentTreeSet<D>: the thesis's method C, a set of segment trees, one per axis, over the
/// cell ranges of the objects' boxes (broadphase name "segment-trees").
///
/// Candidates are the pairs whose cell boxes overlap on every axis: a superset of the
/// pairs whose boxes overlap (quantisation only adds), which the adapter's exact test
/// reduces to exactly those. Two traversals return that same set:
/// - Traversal::Stabbing (default): on one axis, every object looks up the objects whose
///   range contains its first cell — one root-to-leaf path (SegmentTree::forEachStab) — and
///   tests their other axes from the entries, which carry them. Each pair is met once, with
///   no flags. The axis is the one with the least stabbing work, re-chosen every 32 frames.
/// - Traversal::ThesisFlags: the thesis's walk. For every object and every axis, all nodes
///   meeting its range are visited and their objects flagged for that axis; objects
///   flagged on all axes are candidates. Visits every 1-D overlap on every axis.
///
/// Unbounded (see CellCore): trees grow to cover any object within +-kCellLimit cells of
/// the origin, so nothing is ever dropped; a +-1e18 plane is clamped to the root's range and
/// sits in the root, a candidate with everything, which is what it is.

#include <kolize/broadphase/aabb.h>
#include <kolize/broadphase/cell_core.h>
#include <kolize/broadphase/segment_tree.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace kolize {

template <int D, class Scalar>
class SegmentTreeSet : public CellCore<SegmentTreeSet<D, Scalar>, D, Scalar> {
    using Base = CellCore<SegmentTreeSet<D, Scalar>, D, Scalar>;
    friend Base;

  public:
    using Box = Aabb<D, Scalar>;
    using Settings = SegmentTreeSettings;
    using Entry = CellEntry<D>;
    using Tree = SegmentTree<Entry>;
    using Index = typename Tree::Index;

    explicit SegmentTreeSet(const Settings& settings = {})
        : Base(settings.cells), settings_(settings) {}

    /// Calls `candidate(a, b)` once for every unordered pair of live objects whose cell
    /// boxes overlap on all axes.
    template <class Sink>
    void findCandidates(Sink&& candidate) {
        if (this->size() < 2) {
            return;
        }
        if (settings_.traversal == Settings::Traversal::ThesisFlags) {
            flagWalk(candidate);
            return;
        }
        if (frame_++ % kAxisReviewFrames == 0) {
            chooseAxis();
        }
        const Tree& tree = trees_[axis_];
        tree.forEachStab(
            [&](const Entry& j, Index at) {
                for (const Entry& e : tree.node(at).entries) {
                    if ((e.lo < j.lo || e.id < j.id) && othersOverlap(e, j)) {
                        candidate(e.id, j.id);
                    }
                }
            },
            path_, spine_);
    }

    /// Calls `visit(id)` once for every live object whose cell box overlaps the cells of
    /// `box`. Walks one tree, on the axis where the query is narrowest.
    template <class Visit>
    void queryBox(const Box& box, Visit&& visit) const {
        if (this->size() == 0) {
            return;
        }
        const CellBox<D> query = this->queryCells(box);
        int axis = 0;
        for (int a = 1; a < D; ++a) {
            if (std::int64_t(query.hi[a]) - query.lo[a] <
                std::int64_t(query.hi[axis]) - query.lo[axis]) {
                axis = a;
            }
        }
        const Entry probe = cellEntry<D>(0, query, axis);
        const Tree& tree = trees_[axis];
        tree.forEachNodeMeeting(query.lo[axis], query.hi[axis], [&](Index at) {
            const auto& node = tree.node(at);
            for (const Entry& e : node.entries) {
                // An object meets the query in several of its nodes; report it from the one
                // holding its first cell inside the query.
                if (node.contains(std::max(e.lo, query.lo[axis])) && othersOverlap(e, probe)) {
                    visit(e.id);
                }
            }
        });
    }

    /// Checks every tree against the objects' cell boxes; throws std::logic_error.
    void validate() const {
        this->validateObjects("SegmentTreeSet");
        if (this->size() == 0 && trees_[0].empty()) {
            return;
        }
        for (int axis = 0; axis < D; ++axis) {
            trees_[axis].validate(
                "SegmentTreeSet axis " + std::to_string(axis), this->live().size(),
                this->storedRangeOn(axis), [&](const Entry& e, Index) {
                    const Entry expected = cellEntry<D>(e.id, this->cells(e.id), axis);
                    if (expected.otherLo != e.otherLo || expected.otherHi != e.otherHi) {
                        throw std::logic_error("SegmentTreeSet axis " + std::to_string(axis) +
                                               ": stale entry of object " + std::to_string(e.id));
                    }
                });
        }
    }

    /// Bytes held by the core.
    std::size_t memoryBytes() const {
        std::size_t bytes = this->objectMemoryBytes() +
                            (stampOf_.capacity() * sizeof(std::uint32_t)) + flags_.capacity() +
                            (path_.capacity() + spine_.capacity()) * sizeof(Index);
        for (const Tree& tree : trees_) {
            bytes += tree.memoryBytes();
        }
        return bytes;
    }

    /// Nodes in all trees.
    std::size_t nodeCount() const {
        std::size_t count = 0;
        for (const Tree& tree : trees_) {
            count += tree.liveNodes();
        }
        return count;
    }

    /// Nodes holding object `id`'s entries on `axis` (its canonical decomposition).
    std::size_t nodesOf(ObjectId id, int axis) const { return trees_[axis].refsOf(id).size(); }

    /// The axis the stabbing traversal uses now.
    int stabbingAxis() const { return axis_; }

  private:
    static constexpr unsigned kAxisReviewFrames = 32;

    bool hasTree(int) const { return true; }
    Tree& treeOf(int axis) { return trees_[axis]; }
    const Tree& treeOf(int axis) const { return trees_[axis]; }

    void resetTrees(const CellBox<D>& root) {
        for (int axis = 0; axis < D; ++axis) {
            trees_[axis].reset(root.lo[axis], levelCovering(root.lo[axis], root.hi[axis]));
        }
        frame_ = 0;
    }

    void store(ObjectId id) {
        for (int axis = 0; axis < D; ++axis) {
            storeOn(axis, id);
        }
    }

    void storeOn(int axis, ObjectId id) {
        const CellBox<D>& cells = this->cells(id);
        trees_[axis].insert(id, cells.lo[axis], cells.hi[axis], cellEntry<D>(id, cells, axis),
                            [](Index) {});
    }

    void unstore(ObjectId id) {
        for (Tree& tree : trees_) {
            tree.remove(id, [](Index) {});
        }
    }

    void restore(ObjectId id, const CellBox<D>& old) {
        const CellBox<D>& cells = this->cells(id);
        for (int axis = 0; axis < D; ++axis) {
            if (cells.lo[axis] != old.lo[axis] || cells.hi[axis] != old.hi[axis]) {
                trees_[axis].remove(id, [](Index) {});
                storeOn(axis, id);
            } else {
                // Same nodes; refresh the other axes the entries carry.
                const Entry fresh = cellEntry<D>(id, cells, axis);
                trees_[axis].editEntries(id, [&](Entry& e, Index) { e = fresh; });
            }
        }
    }

    /// Picks the axis with the least stabbing work: the sum over nodes of entries x first
    /// cells below (each first cell's path scans the node). O(nodes) per axis.
    void chooseAxis() {
        std::int64_t best = -1;
        for (int axis = 0; axis < D; ++axis) {
            std::int64_t work = 0;
            firstsBelow(trees_[axis], trees_[axis].root(), work);
            if (best < 0 || work < best) {
                best = work;
                axis_ = axis;
            }
        }
    }

    static std::int64_t firstsBelow(const Tree& tree, Index at, std::int64_t& work) {
        const auto& node = tree.node(at);
        std::int64_t firsts = 0;
        for (const Entry& e : node.entries) {
            firsts += e.lo == node.first ? 1 : 0;
        }
        for (Index child : node.child) {
            if (child != Tree::kNone) {
                firsts += firstsBelow(tree, child, work);
            }
        }
        work += firsts * std::int64_t(node.entries.size());
        return firsts;
    }

    /// The thesis's walk: per object, per axis, flag the objects of every node meeting its
    /// range; report when the last axis completes the flags.
    template <class Sink>
    void flagWalk(Sink& candidate) {
        const std::vector<ObjectId>& live = this->live();
        ObjectId maxId = 0;
        for (ObjectId id : live) {
            maxId = std::max(maxId, id);
        }
        if (stampOf_.size() <= maxId) {
            stampOf_.resize(maxId + 1, 0);
            flags_.resize(maxId + 1, 0);
        }
        for (ObjectId j : live) {
            if (++stamp_ == 0) {
                std::fill(stampOf_.begin(), stampOf_.end(), 0);
                stamp_ = 1;
            }
            const CellBox<D>& cells = this->cells(j);
            for (int axis = 0; axis < D; ++axis) {
                const Tree& tree = trees_[axis];
                const std::uint8_t before = static_cast<std::uint8_t>((1u << axis) - 1);
                tree.forEachNodeMeeting(cells.lo[axis], cells.hi[axis], [&](Index at) {
                    for (const Entry& e : tree.node(at).entries) {
                        if (axis == 0) {
                            stampOf_[e.id] = stamp_;
                            flags_[e.id] = 1;
                        } else if (stampOf_[e.id] == stamp_ && flags_[e.id] == before) {
                            flags_[e.id] = static_cast<std::uint8_t>(before | (1u << axis));
                            if (axis == D - 1 && e.id > j) {
                                candidate(j, e.id);
                            }
                        }
                    }
                });
            }
        }
    }

    Settings settings_;
    std::array<Tree, D> trees_;
    int axis_ = 0;
    unsigned frame_ = 0;
    std::vector<Index> path_, spine_;
    std::vector<std::uint32_t> stampOf_;
    std::vector<std::uint8_t> flags_;
    std::uint32_t stamp_ = 0;
};

}  // namespace kolize
