#pragma once
/// \file
/// What SegmentTreeSet and RangeTree share: the cell quantiser and its tuning from the scene
/// (thesis formulas 3.2 and 3.3), and SegmentTree, one axis's growable segment tree over
/// integer cells whose nodes are created lazily from a pool and hold caller-defined entries.
///
/// Cells. A coordinate x lies in cell floor(x / U). The map is monotone, so boxes that
/// overlap have cell ranges that overlap: quantisation only ever adds candidates. Cells are
/// limited to [-kCellLimit, kCellLimit]; coordinates beyond (+-1e18 plane boxes, objects
/// flown very far) saturate, which is monotone too.
///
/// Unbounded. A tree's root covers 2^level cells starting at `first`, and grows (doubling
/// towards the side that needs it, so the nodes already there keep their places) to cover
/// any cell range inside the limits. Nodes are aligned: a node of level l starts at
/// root.first + k * 2^l. Empty leaves are given back to the pool at once, so memory follows the
/// occupied region, not the region ever visited.

#include <kolize/broadphase/aabb.h>
#include <kolize/broadphase/tree_settings.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace kolize {

/// An integer cell index on one axis.
using Cell = std::int32_t;

/// Cells are limited to [-kCellLimit, kCellLimit] (saturating).
constexpr std::int64_t kCellLimit = std::int64_t(1) << 30;

/// Maps coordinates to cells: cell(x) = floor(x / unit), saturated to +-(kCellLimit + 1).
class CellQuantizer {
  public:
    CellQuantizer() = default;
    explicit CellQuantizer(double unit) : unit_(unit), inverse_(1.0 / unit) {}

    double unit() const { return unit_; }

    /// The cell of x; values beyond the limits come back as +-(kCellLimit + 1).
    std::int64_t cellOf(double x) const {
        const double scaled = x * inverse_;
        if (!(scaled >= double(-kCellLimit))) {  // also NaN, which callers never pass
            return -kCellLimit - 1;
        }
        if (scaled >= double(kCellLimit + 1)) {
            return kCellLimit + 1;
        }
        // floor without a libm call (x86-64's baseline has no rounding instruction).
        const auto truncated = static_cast<std::int64_t>(scaled);
        return truncated - (scaled < double(truncated) ? 1 : 0);
    }

  private:
    double unit_ = 1;
    double inverse_ = 1;
};

/// The tuned scene of thesis formula 3.3: the half-extent D and the leaf width U = 2D / S.
struct TunedScene {
    double halfExtent = 0;
    double unit = 1;
};

/// Tunes U for the boxes `ids` of `boxes` (see CellTuning): D = 1.5 x the largest distance
/// of a box centre from the origin, ignoring centres more than twice as far as the 99th
/// percentile (so the thesis's D for its scenes, but a few far objects do not coarsen
/// everyone's cells). The width floor U >= median object width / 16 keeps a scene whose
/// objects all sit near the origin from getting absurdly fine cells. O(N). `scratch` is
/// reused.
template <int D, class Scalar>
TunedScene tuneScene(const std::vector<Aabb<D, Scalar>>& boxes, const std::vector<ObjectId>& ids,
                     const CellTuning& tuning, std::vector<double>& scratch) {
    TunedScene out;
    if (ids.empty()) {
        return out;
    }
    scratch.clear();
    for (ObjectId id : ids) {
        double squared = 0;
        for (int axis = 0; axis < D; ++axis) {
            const double centre =
                0.5 * double(boxes[id].lo[axis]) + 0.5 * double(boxes[id].hi[axis]);
            squared += centre * centre;
        }
        scratch.push_back(std::sqrt(squared));
    }
    const std::size_t at = (scratch.size() - 1) * 99 / 100;
    std::nth_element(scratch.begin(), scratch.begin() + at, scratch.end());
    const double inlierLimit = 2 * scratch[at];
    double farthest = 0;
    for (double distance : scratch) {
        if (distance <= inlierLimit) {
            farthest = std::max(farthest, distance);
        }
    }
    out.halfExtent = 1.5 * farthest;

    scratch.clear();
    for (ObjectId id : ids) {
        double widest = 0;
        for (int axis = 0; axis < D; ++axis) {
            widest = std::max(widest, double(boxes[id].hi[axis]) - double(boxes[id].lo[axis]));
        }
        scratch.push_back(widest);
    }
    const std::size_t middle = scratch.size() / 2;
    std::nth_element(scratch.begin(), scratch.begin() + middle, scratch.end());
    const double widthFloor = scratch[middle] / 16;

    if (tuning.unit > 0) {
        out.unit = tuning.unit;
    } else {
        const int divisions = std::max(tuning.divisions, 1);
        out.unit = std::max(2 * out.halfExtent / divisions, widthFloor);
        if (!(out.unit > 0) || !std::isfinite(out.unit)) {
            out.unit = 1;
        }
    }
    if (!std::isfinite(out.halfExtent)) {
        out.halfExtent = 0;
    }
    return out;
}

/// The smallest level whose 2^level cells cover [lo, hi].
inline int levelCovering(std::int64_t lo, std::int64_t hi) {
    int level = 0;
    while ((std::int64_t(1) << level) < hi - lo + 1) {
        ++level;
    }
    return level;
}

/// One axis's segment tree over cells. An object's cell range [lo, hi] is stored as one
/// `Entry` in each node of its canonical decomposition (the highest nodes whose cell range
/// the object covers, as in the thesis), at most 2 per level. The tree remembers, per object,
/// where its entries are, so removal and in-place edits cost O(entries).
///
/// `Entry` must have members `ObjectId id` and `Cell lo` (the object's first cell on this
/// axis); the rest is the caller's. A node's entries are in no particular order unless the
/// caller orders them (through reorder()).
template <class Entry>
class SegmentTree {
  public:
    using Index = std::int32_t;
    static constexpr Index kNone = -1;

    struct Node {
        std::int64_t first = 0;  ///< first cell covered
        int level = 0;           ///< covers 2^level cells
        Index parent = kNone;
        Index child[2] = {kNone, kNone};
        std::vector<Entry> entries;

        std::int64_t last() const { return first + (std::int64_t(1) << level) - 1; }
        bool contains(std::int64_t cell) const { return cell >= first && cell <= last(); }
    };

    /// Where one of an object's entries is.
    struct Ref {
        Index node;
        std::uint32_t index;
    };

    /// An object's refs, in left-to-right order of their nodes: the first few inline (a
    /// typical object has at most four canonical nodes per axis), the rest on the heap.
    class RefList {
      public:
        std::size_t size() const { return count_; }
        Ref& operator[](std::size_t k) { return k < kLocal ? local_[k] : spill_[k - kLocal]; }
        const Ref& operator[](std::size_t k) const {
            return k < kLocal ? local_[k] : spill_[k - kLocal];
        }
        void push(const Ref& ref) {
            if (count_ < kLocal) {
                local_[count_] = ref;
            } else {
                spill_.push_back(ref);
            }
            ++count_;
        }
        void clear() {
            count_ = 0;
            spill_.clear();
        }
        std::size_t heapBytes() const { return spill_.capacity() * sizeof(Ref); }

      private:
        static constexpr std::uint32_t kLocal = 4;
        std::array<Ref, kLocal> local_{};
        std::uint32_t count_ = 0;
        std::vector<Ref> spill_;
    };

    /// Drops every node and entry (keeping their memory) and starts over with a root
    /// covering 2^level cells from `first`.
    void reset(std::int64_t first, int level) {
        for (Node& node : nodes_) {
            node.entries.clear();
        }
        freeNodes_.clear();
        for (Index i = static_cast<Index>(nodes_.size()); i-- > 0;) {
            freeNodes_.push_back(i);
        }
        for (RefList& refs : refs_) {
            refs.clear();
        }
        root_ = allocate(first, level, kNone);
    }

    bool empty() const { return root_ == kNone; }
    Index root() const { return root_; }
    const Node& node(Index index) const { return nodes_[index]; }

    /// The cells objects may occupy without clamping: the root's range within the limits.
    std::int64_t windowLo() const { return std::max(nodes_[root_].first, -kCellLimit); }
    std::int64_t windowHi() const { return std::min(nodes_[root_].last(), kCellLimit); }

    /// Grows the root until it covers [lo, hi] (both within +-kCellLimit). Returns whether
    /// it grew. O(levels added).
    bool growToCover(std::int64_t lo, std::int64_t hi) {
        bool grew = false;
        Node& root = nodes_[root_];
        if ((lo < root.first || hi > root.last()) && root.entries.empty() &&
            root.child[0] == kNone && root.child[1] == kNone) {
            // Nothing stored: widen the lone root in place rather than leave an empty leaf.
            const std::int64_t first = std::min(lo, root.first);
            root.level = levelCovering(first, std::max(hi, root.last()));
            root.first = first;
            return true;
        }
        while (lo < nodes_[root_].first || hi > nodes_[root_].last()) {
            const Index old = root_;
            const int level = nodes_[old].level;
            const bool growLeft = lo < nodes_[old].first;
            const std::int64_t first =
                growLeft ? nodes_[old].first - (std::int64_t(1) << level) : nodes_[old].first;
            root_ = allocate(first, level + 1, kNone);
            nodes_[root_].child[growLeft ? 1 : 0] = old;
            nodes_[old].parent = root_;
            grew = true;
        }
        return grew;
    }

    /// Stores object `id` with cell range [lo, hi] (inside the root) as copies of `entry`,
    /// one per node of the canonical decomposition. `touched(node)` is called for each node
    /// that gets an entry. The object must not be stored already.
    template <class Touched>
    void insert(ObjectId id, std::int64_t lo, std::int64_t hi, const Entry& entry,
                Touched&& touched) {
        if (id >= refs_.size()) {
            refs_.resize(id + 1);
        }
        insertBelow(root_, id, lo, hi, entry, touched);
    }

    /// Removes all entries of object `id`, giving emptied leaves back to the pool.
    /// `touched(node)` is called for each node that loses an entry and stays.
    template <class Touched>
    void remove(ObjectId id, Touched&& touched) {
        RefList& refs = refs_[id];
        for (std::size_t k = 0; k < refs.size(); ++k) {
            const Index node = refs[k].node;
            takeOut(refs[k]);
            if (!pruneUpwards(node)) {
                touched(node);
            }
        }
        refs.clear();
    }

    /// Moves stored object `id` to the cell range [lo, hi] (inside the root), as remove then
    /// insert would, but descending only from the lowest ancestor of its old first node that
    /// covers the new range: a small move touches only the bottom of the tree.
    template <class Touched>
    void move(ObjectId id, std::int64_t lo, std::int64_t hi, const Entry& entry,
              Touched&& touched) {
        RefList& refs = refs_[id];
        Index start = refs.size() > 0 ? refs[0].node : root_;
        while (start != root_ && (nodes_[start].first > lo || nodes_[start].last() < hi)) {
            start = nodes_[start].parent;
        }
        // Old nodes are pruned only after the insertion: `start` and the nodes below it
        // that the new range reuses must survive.
        oldNodes_.clear();
        for (std::size_t k = 0; k < refs.size(); ++k) {
            oldNodes_.push_back(refs[k].node);
            takeOut(refs[k]);
        }
        refs.clear();
        insertBelow(start, id, lo, hi, entry, touched);
        for (Index node : oldNodes_) {
            if (!pruneUpwards(node)) {
                touched(node);
            }
        }
    }

    /// Calls `edit(entry, node)` for each entry of object `id`.
    template <class Edit>
    void editEntries(ObjectId id, Edit&& edit) {
        const RefList& refs = refs_[id];
        for (std::size_t k = 0; k < refs.size(); ++k) {
            edit(nodes_[refs[k].node].entries[refs[k].index], refs[k].node);
        }
    }

    /// The cell range object `id` is stored with (its nodes tile it); false when it is not
    /// stored.
    bool storedRange(ObjectId id, std::int64_t& lo, std::int64_t& hi) const {
        if (id >= refs_.size() || refs_[id].size() == 0) {
            return false;
        }
        const RefList& refs = refs_[id];
        lo = nodes_[refs[0].node].first;
        hi = nodes_[refs[refs.size() - 1].node].last();
        return true;
    }

    /// How many nodes hold entries of object `id` (0 when it is not stored).
    std::size_t entryCount(ObjectId id) const { return id < refs_.size() ? refs_[id].size() : 0; }

    /// Lets the caller reorder a node's entries: `reorder(entries)` may permute them; the
    /// tree then records the new positions.
    template <class Reorder>
    void reorder(Index index, Reorder&& reorder) {
        Node& node = nodes_[index];
        reorder(node.entries);
        for (std::uint32_t i = 0; i < node.entries.size(); ++i) {
            refOf(node.entries[i].id, index).index = i;
        }
    }

    /// Pair enumeration by stabbing. For every entry j that sits in its object's first node
    /// (j.lo == node.first), calls scan(j, u) for each non-empty node u on the path from the
    /// root to the leaf of cell j.lo: exactly the nodes holding the objects whose range
    /// contains j.lo, each such object once. A pair of objects whose ranges overlap is met
    /// from the one with the larger lo (from both when the lo are equal), so the caller
    /// reports it when the other's lo is smaller, or equal with a smaller id. Objects are
    /// visited in tree order, so the path's nodes stay in cache. O(nodes + stabbed entries).
    /// `path` and `spine` are scratch.
    template <class Scan>
    void forEachStab(Scan&& scan, std::vector<Index>& path, std::vector<Index>& spine) const {
        path.clear();
        if (root_ != kNone) {
            stabBelow(root_, scan, path, spine);
        }
    }

    /// Calls visit(node) for each node whose range meets [lo, hi], parents first.
    template <class Visit>
    void forEachNodeMeeting(std::int64_t lo, std::int64_t hi, Visit&& visit) const {
        if (root_ != kNone) {
            meetBelow(root_, lo, hi, visit);
        }
    }

    /// Number of pool slots (live and free); node indices are below it.
    std::size_t nodeCapacity() const { return nodes_.size(); }
    std::size_t liveNodes() const { return nodes_.size() - freeNodes_.size(); }

    std::size_t memoryBytes() const {
        std::size_t bytes = nodes_.capacity() * sizeof(Node) +
                            (freeNodes_.capacity() + oldNodes_.capacity()) * sizeof(Index) +
                            refs_.capacity() * sizeof(RefList);
        for (const Node& node : nodes_) {
            bytes += node.entries.capacity() * sizeof(Entry);
        }
        for (const RefList& refs : refs_) {
            bytes += refs.heapBytes();
        }
        return bytes;
    }

    /// Checks the tree's structure and that `ranges(id, lo, hi)` — the caller's record of
    /// every stored object's range, returning false for objects that are not stored — agrees
    /// with the entries: each stored object's nodes are exactly the canonical decomposition
    /// of its range. `check(entry, node)` validates the caller's part of each entry. Throws
    /// std::logic_error naming the axis.
    template <class Ranges, class Check>
    void validate(const std::string& what, std::size_t objectCount, Ranges&& ranges,
                  Check&& check) const {
        auto fail = [&](const std::string& message) {
            throw std::logic_error(what + ": " + message);
        };
        if (root_ == kNone) {
            fail("no root");
        }
        if (nodes_[root_].parent != kNone) {
            fail("root has a parent");
        }
        std::vector<char> reached(nodes_.size(), 0);
        std::vector<Index> stack{root_};
        std::size_t entryCount = 0;
        while (!stack.empty()) {
            const Index index = stack.back();
            stack.pop_back();
            if (reached[index]) {
                fail("node " + std::to_string(index) + " reached twice");
            }
            reached[index] = 1;
            const Node& node = nodes_[index];
            if (((node.first - nodes_[root_].first) & ((std::int64_t(1) << node.level) - 1)) != 0) {
                fail("node " + std::to_string(index) + " not aligned");
            }
            const bool leaf = node.child[0] == kNone && node.child[1] == kNone;
            if (index != root_ && leaf && node.entries.empty()) {
                fail("empty leaf " + std::to_string(index) + " not pruned");
            }
            for (int side = 0; side < 2; ++side) {
                const Index child = node.child[side];
                if (child == kNone) {
                    continue;
                }
                const Node& c = nodes_[child];
                const std::int64_t expectedFirst =
                    node.first + (side ? std::int64_t(1) << (node.level - 1) : 0);
                if (c.parent != index || c.level != node.level - 1 || c.first != expectedFirst) {
                    fail("child " + std::to_string(child) + " of node " + std::to_string(index) +
                         " has the wrong range or parent");
                }
                stack.push_back(child);
            }
            for (std::uint32_t i = 0; i < node.entries.size(); ++i) {
                const Entry& entry = node.entries[i];
                std::int64_t lo = 0, hi = 0;
                if (!ranges(entry.id, lo, hi)) {
                    fail("entry of object " + std::to_string(entry.id) + " that is not stored");
                }
                if (entry.lo != lo) {
                    fail("entry of object " + std::to_string(entry.id) + " has a stale lo");
                }
                const bool parentCovered = node.parent != kNone &&
                                           lo <= nodes_[node.parent].first &&
                                           hi >= nodes_[node.parent].last();
                if (lo > node.first || hi < node.last() || parentCovered) {
                    fail("object " + std::to_string(entry.id) + " stored in node " +
                         std::to_string(index) + " outside its canonical decomposition");
                }
                if (entry.id >= refs_.size()) {
                    fail("entry of object " + std::to_string(entry.id) + " without refs");
                }
                const RefList& refs = refs_[entry.id];
                bool known = false;
                for (std::size_t k = 0; k < refs.size(); ++k) {
                    known = known || (refs[k].node == index && refs[k].index == i);
                }
                if (!known) {
                    fail("object " + std::to_string(entry.id) + " does not know its entry");
                }
                check(entry, index);
                ++entryCount;
            }
        }
        for (Index index : freeNodes_) {
            if (reached[index]) {
                fail("free node " + std::to_string(index) + " still in the tree");
            }
        }
        if (liveNodes() != std::size_t(std::count(reached.begin(), reached.end(), 1))) {
            fail("pool count disagrees with the reachable nodes");
        }
        std::size_t refCount = 0;
        for (ObjectId id = 0; id < std::max<std::size_t>(objectCount, refs_.size()); ++id) {
            std::int64_t lo = 0, hi = 0;
            const bool stored = ranges(id, lo, hi);
            static const RefList none;
            const RefList& refs = id < refs_.size() ? refs_[id] : none;
            if (!stored) {
                if (refs.size() != 0) {
                    fail("object " + std::to_string(id) + " not stored but has entries");
                }
                continue;
            }
            // The canonical nodes tile [lo, hi] exactly.
            std::int64_t cells = 0;
            for (std::size_t k = 0; k < refs.size(); ++k) {
                cells += std::int64_t(1) << nodes_[refs[k].node].level;
                if (k > 0 && nodes_[refs[k].node].first <= nodes_[refs[k - 1].node].first) {
                    fail("object " + std::to_string(id) + " refs out of order");
                }
            }
            if (refs.size() == 0 || cells != hi - lo + 1) {
                fail("object " + std::to_string(id) + " entries do not tile its range");
            }
            refCount += refs.size();
        }
        if (refCount != entryCount) {
            fail("entry count disagrees with the objects' refs");
        }
    }

  private:
    Index allocate(std::int64_t first, int level, Index parent) {
        if (level > 62) {
            throw std::logic_error("SegmentTree: level overflow");
        }
        Index index;
        if (!freeNodes_.empty()) {
            index = freeNodes_.back();
            freeNodes_.pop_back();
        } else {
            index = static_cast<Index>(nodes_.size());
            nodes_.emplace_back();
        }
        Node& node = nodes_[index];
        node.first = first;
        node.level = level;
        node.parent = parent;
        node.child[0] = node.child[1] = kNone;
        node.entries.clear();
        return index;
    }

    Ref& refOf(ObjectId id, Index node) {
        RefList& refs = refs_[id];
        for (std::size_t k = 0; k < refs.size(); ++k) {
            if (refs[k].node == node) {
                return refs[k];
            }
        }
        throw std::logic_error("SegmentTree: entry without a ref");
    }

    /// Removes the entry at `ref` by moving the node's last entry into its place.
    void takeOut(const Ref& ref) {
        Node& node = nodes_[ref.node];
        if (ref.index + 1 != node.entries.size()) {
            node.entries[ref.index] = node.entries.back();
            refOf(node.entries[ref.index].id, ref.node).index = ref.index;
        }
        node.entries.pop_back();
    }

    template <class Touched>
    void insertBelow(Index index, ObjectId id, std::int64_t lo, std::int64_t hi, const Entry& entry,
                     Touched& touched) {
        const std::int64_t first = nodes_[index].first;
        const std::int64_t last = nodes_[index].last();
        if (lo <= first && hi >= last) {
            Node& node = nodes_[index];
            refs_[id].push(Ref{index, static_cast<std::uint32_t>(node.entries.size())});
            node.entries.push_back(entry);
            touched(index);
            return;
        }
        const int level = nodes_[index].level;
        const std::int64_t middle = first + (std::int64_t(1) << (level - 1));
        if (lo < middle) {
            insertBelow(childOf(index, 0, first, level), id, lo, hi, entry, touched);
        }
        if (hi >= middle) {
            insertBelow(childOf(index, 1, middle, level), id, lo, hi, entry, touched);
        }
    }

    template <class Scan>
    void stabBelow(Index index, Scan& scan, std::vector<Index>& path,
                   std::vector<Index>& spine) const {
        const Node& node = nodes_[index];
        const bool stored = !node.entries.empty();
        if (stored) {
            path.push_back(index);
            // Below this node, the path to its first cell runs down the left children.
            spine.clear();
            for (Index down = node.child[0]; down != kNone; down = nodes_[down].child[0]) {
                if (!nodes_[down].entries.empty()) {
                    spine.push_back(down);
                }
            }
            for (const Entry& entry : node.entries) {
                if (entry.lo != node.first) {
                    continue;
                }
                for (Index up : path) {
                    scan(entry, up);
                }
                for (Index down : spine) {
                    scan(entry, down);
                }
            }
        }
        for (Index child : node.child) {
            if (child != kNone) {
                stabBelow(child, scan, path, spine);
            }
        }
        if (stored) {
            path.pop_back();
        }
    }

    template <class Visit>
    void meetBelow(Index index, std::int64_t lo, std::int64_t hi, Visit& visit) const {
        const Node& node = nodes_[index];
        if (node.last() < lo || node.first > hi) {
            return;
        }
        visit(index);
        for (Index child : node.child) {
            if (child != kNone) {
                meetBelow(child, lo, hi, visit);
            }
        }
    }

    Index childOf(Index index, int side, std::int64_t first, int level) {
        Index child = nodes_[index].child[side];
        if (child == kNone) {
            child = allocate(first, level - 1, index);  // may move nodes_: index, not reference
            nodes_[index].child[side] = child;
        }
        return child;
    }

    /// Frees `index` and then its ancestors while they are empty leaves (never the root).
    /// Returns whether `index` itself was freed.
    bool pruneUpwards(Index index) {
        const Index start = index;
        bool freedStart = false;
        while (index != root_) {
            const Node& node = nodes_[index];
            if (!node.entries.empty() || node.child[0] != kNone || node.child[1] != kNone) {
                break;
            }
            const Index parent = node.parent;
            Node& up = nodes_[parent];
            up.child[up.child[0] == index ? 0 : 1] = kNone;
            freeNodes_.push_back(index);
            freedStart = freedStart || index == start;
            index = parent;
        }
        return freedStart;
    }

    std::vector<Node> nodes_;
    std::vector<Index> freeNodes_;
    std::vector<RefList> refs_;
    std::vector<Index> oldNodes_;
    Index root_ = kNone;
};

}  // namespace kolize
