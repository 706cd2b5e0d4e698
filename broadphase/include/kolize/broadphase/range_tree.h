#pragma once
/// \file
/// RangeTree<D>: the thesis's method D (broadphase "range-tree"). One segment tree over the
/// cell ranges on the tree axis (x by default); every node keeps its entries sorted by their
/// first cell on the sorted axis (the next one, y for x) and knows the widest entry there.
///
/// Candidates are the same set as SegmentTreeSet's: pairs whose cell boxes overlap on all
/// axes. They are found by stabbing on the tree axis (SegmentTree::forEachStab), but in each
/// node on the path only the window of entries that can overlap on the sorted axis is read:
/// the entries whose first cell lies in [lo - widest, hi], found by binary search. So the
/// work is the pairs overlapping on two axes, not on one. Like the segment-tree set, it keeps
/// the candidate set between frames while few objects change cells (CellCore); its queries
/// of grown slabs use the same windows.
///
/// Upkeep, as the thesis describes: an object that keeps its tree-axis range is edited in
/// place and its nodes are marked for re-sorting; nodes are re-sorted by insertion sort at
/// the next findCandidates (local moves: cheap when objects move little). An object that
/// changes range on the tree axis is removed and re-inserted. Queries treat nodes not yet
/// re-sorted as unsorted and read them whole. The thesis's per-list links to the children's
/// lists (fractional cascading) are replaced by one binary search per node: the lists of a
/// stabbing path are short.

#include <kolize/broadphase/aabb.h>
#include <kolize/broadphase/cell_core.h>
#include <kolize/broadphase/segment_tree.h>
#include <kolize/broadphase/tree_settings.h>

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace kolize {

template <int D, class Scalar>
class RangeTree : public CellCore<RangeTree<D, Scalar>, D, Scalar> {
    static_assert(D >= 2, "a range tree needs a second axis to sort along");
    using Base = CellCore<RangeTree<D, Scalar>, D, Scalar>;
    friend Base;

  public:
    using Box = Aabb<D, Scalar>;
    using Settings = RangeTreeSettings;
    using Entry = CellEntry<D>;
    using Tree = SegmentTree<Entry>;
    using Index = typename Tree::Index;

    /// Throws std::invalid_argument for a tree axis outside [0, D).
    explicit RangeTree(const Settings& settings = {})
        : Base(settings.cells, settings.incremental),
          settings_(settings),
          treeAxis_(settings.treeAxis) {
        if (treeAxis_ < 0 || treeAxis_ >= D) {
            throw std::invalid_argument("kolize: RangeTreeSettings::treeAxis must be in [0, " +
                                        std::to_string(D) + ")");
        }
    }

    /// Before every pair search: re-tunes the leaf width when the population has grown, and
    /// sorts the node lists that changed (queries read only their windows then).
    void maintain() {
        this->retuneBeforeFrame();
        sortMarkedNodes();
    }

    /// Calls `candidate(a, b)` once for every unordered pair of live objects whose cell
    /// boxes overlap on all axes.
    template <class Sink>
    void findCandidates(Sink&& candidate) {
        sortMarkedNodes();
        this->emitCandidates(candidate);
    }

    /// Checks the tree, the entries, and that every node not awaiting a sort is sorted and
    /// knows its widest entry; throws std::logic_error.
    void validate() const {
        this->validateObjects("RangeTree");
        if (this->size() == 0 && tree_.empty()) {
            return;
        }
        tree_.validate(
            "RangeTree", this->live().size(), this->storedRangeOn(treeAxis_),
            [&](const Entry& e, Index at) {
                const Entry expected = cellEntry<D>(e.id, this->cells(e.id), treeAxis_);
                if (expected.other != e.other) {
                    throw std::logic_error("RangeTree: stale entry of object " +
                                           std::to_string(e.id));
                }
                if (isMarked(at)) {
                    return;
                }
                const std::vector<Entry>& entries = tree_.node(at).entries;
                const std::size_t k = std::size_t(&e - entries.data());
                if (k > 0 && entries[k - 1].otherLo(0) > e.otherLo(0)) {
                    throw std::logic_error("RangeTree: node " + std::to_string(at) + " not sorted");
                }
                if (std::int64_t(e.otherHi(0)) - e.otherLo(0) > order_[at].widest) {
                    throw std::logic_error("RangeTree: node " + std::to_string(at) +
                                           " underestimates its widest entry");
                }
            });
    }

    /// Bytes held by the core.
    std::size_t memoryBytes() const {
        return this->objectMemoryBytes() + tree_.memoryBytes() +
               order_.capacity() * sizeof(NodeOrder) +
               (marked_.capacity() + path_.capacity() + spine_.capacity()) * sizeof(Index);
    }

    /// Nodes in the tree.
    std::size_t nodeCount() const { return tree_.liveNodes(); }

  private:
    /// Per node: the widest entry on the sorted axis (an upper bound), and whether the node
    /// waits for a sort.
    struct NodeOrder {
        std::int64_t widest = 0;
        bool marked = false;
    };

    bool hasTree(int axis) const { return axis == treeAxis_; }

    /// Stabbing on the tree axis (SegmentTree::forEachStab), reading in each node only the
    /// window of entries that can overlap on the sorted axis.
    template <class Sink>
    void enumerateAll(Sink&& candidate) {
        sortMarkedNodes();  // a rebuild in emitCandidates may have marked nodes again
        if (this->size() < 2) {
            return;
        }
        tree_.forEachStab(
            [&](const Entry& j, Index at) {
                const std::vector<Entry>& entries = tree_.node(at).entries;
                const Reach<D> reach = reachOf(j);
                for (std::size_t k = windowStart(entries, at, j.otherLo(0)); k < entries.size();
                     ++k) {
                    const Entry& e = entries[k];
                    if (e.otherLo(0) > j.otherHi(0)) {
                        if (settings_.searchSortedLists) {
                            break;
                        }
                        continue;
                    }
                    if (othersOverlap(e, reach) && (e.lo < j.lo || e.id < j.id)) {
                        candidate(e.id, j.id);
                    }
                }
            },
            path_, spine_);
    }

    template <class Visit>
    void visitCells(const CellBox<D>& query, Visit&& visit) const {
        const Entry probe = cellEntry<D>(0, query, treeAxis_);
        const Reach<D> reach = reachOf(probe);
        const Cell queryLo = query.lo[treeAxis_];
        tree_.forEachNodeMeeting(queryLo, query.hi[treeAxis_], [&](Index at) {
            const auto& node = tree_.node(at);
            const bool sorted = !isMarked(at);
            const std::size_t start = sorted ? windowStart(node.entries, at, probe.otherLo(0)) : 0;
            for (std::size_t k = start; k < node.entries.size(); ++k) {
                const Entry& e = node.entries[k];
                if (sorted && settings_.searchSortedLists && e.otherLo(0) > probe.otherHi(0)) {
                    break;
                }
                // Reported from the node holding its first cell inside the query.
                if (othersOverlap(e, reach) && node.contains(std::max(e.lo, queryLo))) {
                    visit(e.id);
                }
            }
        });
    }
    Tree& treeOf(int) { return tree_; }
    const Tree& treeOf(int) const { return tree_; }

    bool isMarked(Index at) const { return at < Index(order_.size()) && order_[at].marked; }

    void mark(Index at) {
        if (at >= Index(order_.size())) {
            order_.resize(tree_.nodeCapacity());
        }
        if (!order_[at].marked) {
            order_[at].marked = true;
            marked_.push_back(at);
        }
    }

    /// The first entry whose first cell on the sorted axis is >= lo - widest: no entry
    /// before it can reach lo.
    std::size_t windowStart(const std::vector<Entry>& entries, Index at, Cell lo) const {
        if (!settings_.searchSortedLists) {
            return 0;
        }
        const std::int64_t from = std::int64_t(lo) - order_[at].widest;
        return std::size_t(std::partition_point(
                               entries.begin(), entries.end(),
                               [&](const Entry& e) { return std::int64_t(e.otherLo(0)) < from; }) -
                           entries.begin());
    }

    void resetTrees(const CellBox<D>& root) {
        tree_.reset(root.lo[treeAxis_], levelCovering(root.lo[treeAxis_], root.hi[treeAxis_]));
        order_.assign(tree_.nodeCapacity(), NodeOrder{});
        marked_.clear();
    }

    void store(ObjectId id) {
        const CellBox<D>& cells = this->cells(id);
        tree_.insert(id, cells.lo[treeAxis_], cells.hi[treeAxis_],
                     cellEntry<D>(id, cells, treeAxis_), [&](Index at) { mark(at); });
    }

    void unstore(ObjectId id) {
        tree_.remove(id, [&](Index at) { mark(at); });
    }

    void restore(ObjectId id, const CellBox<D>& old) {
        const CellBox<D>& cells = this->cells(id);
        if (cells.lo[treeAxis_] != old.lo[treeAxis_] || cells.hi[treeAxis_] != old.hi[treeAxis_]) {
            unstore(id);
            store(id);
            return;
        }
        const Entry fresh = cellEntry<D>(id, cells, treeAxis_);
        const int sortedAxis = otherAxis(treeAxis_, 0);
        const bool keyMoved = cells.lo[sortedAxis] != old.lo[sortedAxis];
        const std::int64_t width = std::int64_t(fresh.otherHi(0)) - fresh.otherLo(0);
        tree_.editEntries(id, [&](Entry& e, Index at) {
            e = fresh;
            if (keyMoved) {
                mark(at);
            } else {
                order_[at].widest = std::max(order_[at].widest, width);
            }
        });
    }

    /// Re-sorts the marked nodes by insertion sort (falling back to std::sort when the
    /// list turns out far from sorted, e.g. after a rebuild) and recomputes their widest
    /// entry.
    void sortMarkedNodes() {
        for (Index at : marked_) {
            order_[at].marked = false;
            std::int64_t widest = 0;
            tree_.reorder(at, [&](std::vector<Entry>& entries) {
                sortByFirstCell(entries);
                for (const Entry& e : entries) {
                    widest = std::max(widest, std::int64_t(e.otherHi(0)) - e.otherLo(0));
                }
            });
            order_[at].widest = widest;
        }
        marked_.clear();
    }

    static void sortByFirstCell(std::vector<Entry>& entries) {
        const std::size_t budget = 4 * entries.size() + 16;
        std::size_t shifts = 0;
        for (std::size_t i = 1; i < entries.size(); ++i) {
            if (entries[i - 1].otherLo(0) <= entries[i].otherLo(0)) {
                continue;
            }
            const Entry moving = entries[i];
            std::size_t k = i;
            while (k > 0 && entries[k - 1].otherLo(0) > moving.otherLo(0)) {
                entries[k] = entries[k - 1];
                --k;
            }
            entries[k] = moving;
            shifts += i - k;
            if (shifts > budget) {
                std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
                    return a.otherLo(0) < b.otherLo(0);
                });
                return;
            }
        }
    }

    Settings settings_;
    int treeAxis_;
    Tree tree_;
    std::vector<NodeOrder> order_;
    std::vector<Index> marked_;
    std::vector<Index> path_, spine_;
};

}  // namespace kolize
