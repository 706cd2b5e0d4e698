#pragma once
/// \file
/// SegmentTreeSet<D>: the thesis's method C, a set of segment trees, one per axis, over the
/// cell ranges of the objects' boxes (broadphase name "segment-trees").
///
/// Candidates are the pairs whose cell boxes overlap on every axis: a superset of the
/// pairs whose boxes overlap (quantisation only adds), which the adapter's exact test
/// reduces to exactly those. Three ways give that same set:
/// - Traversal::Stabbing (default): on one axis, every object looks up the objects whose
///   range contains its first cell — one root-to-leaf path — and tests their other axes.
///   Each pair is met once, with no flags. The axis is the one with the least stabbing
///   work, re-chosen every 32 frames. The path's entries are laid out flat, field by field,
///   so the tests run four entries at a time.
/// - Traversal::ThesisFlags: the thesis's walk. For every object and every axis, all nodes
///   meeting its range are visited and their objects flagged for that axis; objects
///   flagged on all axes are candidates. Visits every 1-D overlap on every axis.
/// - incremental (with Stabbing, on by default): the set of the last frame is kept and
///   updated from the objects whose cell box changed (see CellCore), which is most frames
///   when motion is slow relative to the leaf width.
///
/// Updates: an object whose cell box keeps its place costs a few comparisons; one that
/// changes range on an axis is moved in that axis's tree from the lowest node covering its
/// new range. With Stabbing, only the stabbing axis's tree is consulted each frame, so only
/// it is kept current; the other trees note which objects they owe an update and catch up
/// when their axis becomes the stabbing axis (with ThesisFlags all trees stay current).
/// Unbounded (see CellCore): trees grow to cover any object within +-kCellLimit cells
/// of the origin, so nothing is ever dropped; a +-1e18 plane is clamped to the root's range
/// and sits in the root, a candidate with everything, which is what it is.

#include <kolize/broadphase/aabb.h>
#include <kolize/broadphase/cell_core.h>
#include <kolize/broadphase/segment_tree.h>
#include <kolize/broadphase/tree_settings.h>

#include <array>
#include <cstdint>
#include <cstring>
#include <stdexcept>
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
        : Base(settings.cells,
               settings.incremental && settings.traversal == Settings::Traversal::Stabbing),
          settings_(settings) {}

    /// Before every pair search: re-tunes the leaf width when the population has grown.
    void maintain() { this->retuneBeforeFrame(); }

    /// Calls `candidate(a, b)` once for every unordered pair of live objects whose cell
    /// boxes overlap on all axes.
    template <class Sink>
    void findCandidates(Sink&& candidate) {
        this->emitCandidates(candidate);
    }

    /// Checks every tree against the objects' cell boxes; throws std::logic_error.
    void validate() const {
        this->validateObjects("SegmentTreeSet");
        if (this->size() == 0 && trees_[0].empty()) {
            return;
        }
        for (int axis = 0; axis < D; ++axis) {
            const std::string what = "SegmentTreeSet axis " + std::to_string(axis);
            const std::vector<std::uint8_t>& owed = owed_[axis];
            for (ObjectId id : owedList_[axis]) {
                if (id >= owed.size() || !owed[id]) {
                    throw std::logic_error(what + ": owed list and flags disagree");
                }
            }
            if (current(axis) && !owedList_[axis].empty()) {
                throw std::logic_error(what + ": a current tree owes updates");
            }
            const auto cellRange = this->storedRangeOn(axis);
            trees_[axis].validate(
                what, this->live().size(),
                [&](ObjectId id, std::int64_t& lo, std::int64_t& hi) {
                    // An object the tree owes an update is where it was: check the structure.
                    return id < owed.size() && owed[id] && this->isLive(id)
                               ? trees_[axis].storedRange(id, lo, hi)
                               : cellRange(id, lo, hi);
                },
                [&](const Entry& e, Index) {
                    const Entry expected = cellEntry<D>(e.id, this->cells(e.id), axis);
                    if (!(e.id < owed.size() && owed[e.id]) && expected.other != e.other) {
                        throw std::logic_error(what + ": stale entry of object " +
                                               std::to_string(e.id));
                    }
                });
        }
    }

    /// Bytes held by the core.
    std::size_t memoryBytes() const {
        std::size_t bytes = this->objectMemoryBytes() +
                            (stampOf_.capacity() * sizeof(std::uint32_t)) + flags_.capacity() +
                            flat_.capacity() * sizeof(Cell) + path_.capacity() * sizeof(Span);
        for (int axis = 0; axis < D; ++axis) {
            bytes += trees_[axis].memoryBytes() + owed_[axis].capacity() +
                     owedList_[axis].capacity() * sizeof(ObjectId);
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
    std::size_t nodesOf(ObjectId id, int axis) const { return trees_[axis].entryCount(id); }

    /// The axis the stabbing traversal uses now.
    int stabbingAxis() const { return axis_; }

  private:
    static constexpr unsigned kAxisReviewFrames = 32;
    /// Fields of the flat layout: id, first cell on the stabbing axis, then the entry's
    /// other-axis values (lo..., -hi...).
    static constexpr int kFields = 2 + 2 * (D - 1);

    /// A node's entries in the flat layout: its first entries in [begin, firstEnd), the
    /// others in [firstEnd, end).
    struct Span {
        std::uint32_t begin, firstEnd, end;
        std::int64_t first;
    };

    bool hasTree(int) const { return true; }
    Tree& treeOf(int axis) { return trees_[axis]; }
    const Tree& treeOf(int axis) const { return trees_[axis]; }

    void resetTrees(const CellBox<D>& root) {
        for (int axis = 0; axis < D; ++axis) {
            trees_[axis].reset(root.lo[axis], levelCovering(root.lo[axis], root.hi[axis]));
            for (ObjectId id : owedList_[axis]) {
                owed_[axis][id] = 0;
            }
            owedList_[axis].clear();
        }
        frame_ = 0;
    }

    /// Whether the tree on `axis` is kept current (else it notes what it owes).
    bool current(int axis) const {
        return settings_.traversal == Settings::Traversal::ThesisFlags || axis == axis_;
    }

    /// Brings object `id`'s entries on `axis` to its cell box.
    void refresh(int axis, ObjectId id) {
        const CellBox<D>& cells = this->cells(id);
        const Entry fresh = cellEntry<D>(id, cells, axis);
        std::int64_t lo = 0, hi = 0;
        trees_[axis].storedRange(id, lo, hi);
        if (lo != cells.lo[axis] || hi != cells.hi[axis]) {
            trees_[axis].move(id, cells.lo[axis], cells.hi[axis], fresh, [](Index) {});
        } else {
            // Same nodes; refresh the other axes the entries carry.
            trees_[axis].editEntries(id, [&](Entry& e, Index) { e = fresh; });
        }
    }

    /// Makes the tree on `axis` current: the updates it owes.
    void catchUp(int axis) {
        for (ObjectId id : owedList_[axis]) {
            owed_[axis][id] = 0;
            if (this->isLive(id)) {
                refresh(axis, id);
            }
        }
        owedList_[axis].clear();
    }

    void store(ObjectId id) {
        const CellBox<D>& cells = this->cells(id);
        for (int axis = 0; axis < D; ++axis) {
            trees_[axis].insert(id, cells.lo[axis], cells.hi[axis], cellEntry<D>(id, cells, axis),
                                [](Index) {});
        }
    }

    void unstore(ObjectId id) {
        for (Tree& tree : trees_) {
            tree.remove(id, [](Index) {});
        }
    }

    void restore(ObjectId id, const CellBox<D>&) {
        for (int axis = 0; axis < D; ++axis) {
            if (current(axis)) {
                if (!(id < owed_[axis].size() && owed_[axis][id])) {
                    refresh(axis, id);
                }
            } else {
                if (id >= owed_[axis].size()) {
                    owed_[axis].resize(id + 1, 0);
                }
                if (!owed_[axis][id]) {
                    owed_[axis][id] = 1;
                    owedList_[axis].push_back(id);
                }
            }
        }
    }

    template <class Visit>
    void visitCells(const CellBox<D>& query, Visit&& visit) const {
        int axis = axis_;
        for (int a = 0; a < D; ++a) {
            if (current(a) && std::int64_t(query.hi[a]) - query.lo[a] <
                                  std::int64_t(query.hi[axis]) - query.lo[axis]) {
                axis = a;
            }
        }
        const Tree& tree = trees_[axis];
        const Reach<D> reach = reachOf(cellEntry<D>(0, query, axis));
        tree.forEachNodeMeeting(query.lo[axis], query.hi[axis], [&](Index at) {
            const auto& node = tree.node(at);
            for (const Entry& e : node.entries) {
                // An object meets the query in several of its nodes; report it from the one
                // holding its first cell inside the query.
                if (othersOverlap(e, reach) && node.contains(std::max(e.lo, query.lo[axis]))) {
                    visit(e.id);
                }
            }
        });
    }

    template <class Sink>
    void enumerateAll(Sink&& candidate) {
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
        flatCount_ = 0;
        path_.clear();
        stabBelow(trees_[axis_].root(), candidate);
    }

    /// Stabbing in tree order. At each node: its first entries against every node on the
    /// path (itself included), and the first entries of the ancestors that start at the
    /// same cell (this node is on their left spine, so on their stabbing paths) against
    /// this node. Together: each entry j against exactly the nodes containing j.lo.
    template <class Sink>
    void stabBelow(Index at, Sink& candidate) {
        const auto& node = trees_[axis_].node(at);
        const bool stored = !node.entries.empty();
        if (stored) {
            Span span;
            span.first = node.first;
            span.begin = static_cast<std::uint32_t>(flatSize());
            for (const Entry& e : node.entries) {
                if (e.lo == node.first) {
                    append(e);
                }
            }
            span.firstEnd = static_cast<std::uint32_t>(flatSize());
            for (const Entry& e : node.entries) {
                if (e.lo != node.first) {
                    append(e);
                }
            }
            span.end = static_cast<std::uint32_t>(flatSize());
            path_.push_back(span);
            for (std::uint32_t j = span.begin; j < span.firstEnd; ++j) {
                for (const Span& up : path_) {
                    scan(j, up.begin, up.end, candidate);
                }
            }
            for (std::size_t k = path_.size() - 1; k-- > 0 && path_[k].first == node.first;) {
                for (std::uint32_t j = path_[k].begin; j < path_[k].firstEnd; ++j) {
                    scan(j, span.begin, span.end, candidate);
                }
            }
        }
        for (Index child : node.child) {
            if (child != Tree::kNone) {
                stabBelow(child, candidate);
            }
        }
        if (stored) {
            path_.pop_back();
            // The flat entries of this subtree are no longer on any path.
            resizeFlat(path_.empty() ? 0 : path_.back().end);
        }
    }

    std::size_t flatSize() const { return flatCount_; }

    void resizeFlat(std::size_t entries) { flatCount_ = entries; }

    /// Appends an entry to the flat layout: fields interleaved in blocks of four entries,
    /// so that each field of four consecutive entries is one vector load.
    void append(const Entry& e) {
        const std::size_t index = flatCount_++;
        const std::size_t blockStart = (index / 4) * 4 * kFields;
        if (blockStart + 4 * kFields > flat_.size()) {
            flat_.resize(blockStart + 4 * kFields);
        }
        Cell* block = &flat_[blockStart];
        const std::size_t lane = index % 4;
        block[0 * 4 + lane] = static_cast<Cell>(e.id);
        block[1 * 4 + lane] = e.lo;
        for (int i = 0; i < 2 * (D - 1); ++i) {
            block[(2 + i) * 4 + lane] = e.other[i];
        }
    }

    Cell field(std::uint32_t index, int f) const {
        return flat_[(index / 4) * 4 * kFields + std::size_t(f) * 4 + index % 4];
    }

    /// Tests entry j (stabbing) against entries [begin, end): reports e when its range
    /// starts before j's (or at the same cell with a smaller id) and it overlaps j on the
    /// other axes.
    template <class Sink>
    void scan(std::uint32_t j, std::uint32_t begin, std::uint32_t end, Sink& candidate) const {
        // The probe: j's id and first cell, then its reach (hi..., -lo...).
        Cell probe[kFields];
        probe[0] = field(j, 0);
        probe[1] = field(j, 1);
        for (int k = 0; k < D - 1; ++k) {
            probe[2 + k] = -field(j, 2 + (D - 1) + k);
            probe[2 + (D - 1) + k] = -field(j, 2 + k);
        }
        std::uint32_t k = begin;
        // Scalar up to a block boundary, four at a time through whole blocks, scalar tail.
        for (; k < end && k % 4 != 0; ++k) {
            scanOne(k, probe, candidate);
        }
        for (; k + 4 <= end; k += 4) {
            const Cell* block = &flat_[(k / 4) * 4 * kFields];
            if (anyMatch(block, probe)) {
                for (std::uint32_t lane = 0; lane < 4; ++lane) {
                    scanOne(k + lane, probe, candidate);
                }
            }
        }
        for (; k < end; ++k) {
            scanOne(k, probe, candidate);
        }
    }

    template <class Sink>
    void scanOne(std::uint32_t k, const Cell* probe, Sink& candidate) const {
        const Cell id = field(k, 0), lo = field(k, 1);
        bool match = lo < probe[1] || id < probe[0];
        for (int f = 2; f < kFields; ++f) {
            match &= field(k, f) <= probe[f];
        }
        if (match) {
            candidate(ObjectId(id), ObjectId(probe[0]));
        }
    }

    static CellLanes broadcast(Cell cell) { return CellLanes{cell, cell, cell, cell}; }

    /// Whether any of the four entries of `block` passes scanOne's test, branch-free.
    static bool anyMatch(const Cell* block, const Cell* probe) {
        CellLanes match =
            (loadLanes(block + 4) < broadcast(probe[1])) | (loadLanes(block) < broadcast(probe[0]));
        for (int f = 2; f < kFields; ++f) {
            match &= loadLanes(block + f * 4) <= broadcast(probe[f]);
        }
        return (match[0] | match[1] | match[2] | match[3]) != 0;
    }

    /// Picks the axis with the least stabbing work: the sum over nodes of entries x first
    /// cells below (each first cell's path scans the node). O(nodes) per axis.
    void chooseAxis() {
        std::int64_t best = -1;
        int choice = axis_;
        for (int axis = 0; axis < D; ++axis) {
            std::int64_t work = 0;
            firstsBelow(trees_[axis], trees_[axis].root(), work);
            if (best < 0 || work < best) {
                best = work;
                choice = axis;
            }
        }
        catchUp(choice);
        axis_ = choice;
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
    /// Per axis, objects whose entries in that (not current) tree are out of date: a flag
    /// per object and their list.
    std::array<std::vector<std::uint8_t>, D> owed_;
    std::array<std::vector<ObjectId>, D> owedList_;
    int axis_ = 0;
    unsigned frame_ = 0;
    std::vector<Cell> flat_;
    std::size_t flatCount_ = 0;
    std::vector<Span> path_;
    std::vector<std::uint32_t> stampOf_;
    std::vector<std::uint8_t> flags_;
    std::uint32_t stamp_ = 0;
};

}  // namespace kolize
