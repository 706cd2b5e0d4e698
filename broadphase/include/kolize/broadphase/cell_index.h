#pragma once
/// \file
/// Cell indexes for CellGrid: they map a cell's integer coordinates to a cell record.
///
/// - DenseIndex: the uniform grid (thesis method A). Every cell of a box-shaped region
///   exists in one array; a cell is found by arithmetic. Memory grows with the region.
/// - AvlIndex: the regular spatial tree (method B). Only non-empty cells exist, as nodes of
///   an AVL tree ordered by their coordinates. The thesis keyed cells by
///   x*10000 + y*100 + z + 1010100, which orders cells lexicographically by (x, y, z) but
///   only for 0 <= coordinates < 100 (and its grid was at most 12 cells per axis). kolize
///   keeps the lexicographic order with one 64-bit signed integer per axis, so negative
///   coordinates and any cell count work: the world is unbounded. Ordered traversal makes
///   range queries visit only the live cells of an x-slab.
/// - HashIndex: the same sparse cells in an open-addressing hash table (beyond the thesis):
///   O(1) expected lookup, no order.
///
/// Every index hands out stable 32-bit cell handles, keeps a {head, count} record per
/// non-empty cell, and never allocates while the set of live cells stays within its
/// previous peak (node pools and free lists).

#include <kolize/broadphase/aabb.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace kolize {

/// Integer cell coordinates: 64-bit for the unbounded sparse indexes, 32-bit for the dense
/// grid (whose cells are counted in 32 bits anyway), which halves its per-object state.
template <int D, class Coord = std::int64_t>
using CellKey = std::array<Coord, D>;

/// An inclusive box of cells.
template <int D, class Coord = std::int64_t>
struct CellRange {
    using Key = CellKey<D, Coord>;
    Key lo{};
    Key hi{};
    bool operator==(const CellRange& other) const { return lo == other.lo && hi == other.hi; }
    bool operator!=(const CellRange& other) const { return !(*this == other); }
    bool contains(const Key& key) const {
        for (int axis = 0; axis < D; ++axis) {
            if (key[axis] < lo[axis] || key[axis] > hi[axis]) {
                return false;
            }
        }
        return true;
    }
    /// Number of cells, as a double (ranges of huge boxes exceed any integer).
    double cellCount() const {
        double count = 1;
        for (int axis = 0; axis < D; ++axis) {
            count *= double(hi[axis]) - double(lo[axis]) + 1;
        }
        return count;
    }
};

/// Calls visit(key) for every cell of `range`, x slowest. The range must be small.
template <int D, class Coord, class Visit>
void forEachCellIn(const CellRange<D, Coord>& range, Visit&& visit) {
    CellKey<D, Coord> key = range.lo;
    while (true) {
        visit(key);
        int axis = D - 1;
        while (axis >= 0 && key[axis] == range.hi[axis]) {
            key[axis] = range.lo[axis];
            --axis;
        }
        if (axis < 0) {
            return;
        }
        ++key[axis];
    }
}

/// The record every index keeps per cell: the first entry of its object list, and its size.
struct CellRecord {
    std::uint32_t head = 0xffffffffu;
    std::uint32_t count = 0;
};

constexpr std::uint32_t kNoCell = 0xffffffffu;

/// A dense array of cells over [0, dims) on each axis. The array holds only a 4-byte slot
/// number per cell; the records of the non-empty cells live together in a compact slot
/// array, so a pair search walks them sequentially, not the whole region.
template <int D>
class DenseIndex {
  public:
    static constexpr bool kBounded = true;
    static constexpr const char* kName = "dense array";
    using Coord = std::int32_t;
    using Key = CellKey<D, Coord>;
    using Range = CellRange<D, Coord>;

    /// Drops all cells and sizes the array for `dims` cells per axis.
    void reset(const Key& dims) {
        dims_ = dims;
        std::size_t total = 1;
        for (int axis = 0; axis < D; ++axis) {
            total *= static_cast<std::size_t>(dims[axis]);
        }
        slotOf_.assign(total, kNoCell);
        slots_.clear();
    }
    std::uint32_t find(const Key& key) const {
        const std::uint32_t handle = handleOf(key);
        return slotOf_[handle] != kNoCell ? handle : kNoCell;
    }
    /// Finds the cell or makes it live.
    std::uint32_t acquire(const Key& key) {
        const std::uint32_t handle = handleOf(key);
        if (slotOf_[handle] == kNoCell) {
            slotOf_[handle] = static_cast<std::uint32_t>(slots_.size());
            slots_.push_back(Slot{CellRecord{}, handle});
        }
        return handle;
    }
    /// Called when the cell's last object has left.
    void release(std::uint32_t handle) {
        const std::uint32_t at = slotOf_[handle];
        slots_[at] = slots_.back();
        slotOf_[slots_[at].handle] = at;
        slots_.pop_back();
        slotOf_[handle] = kNoCell;
    }
    CellRecord& record(std::uint32_t handle) { return slots_[slotOf_[handle]].record; }
    const CellRecord& record(std::uint32_t handle) const { return slots_[slotOf_[handle]].record; }
    Key key(std::uint32_t handle) const {
        Key out{};
        for (int axis = D - 1; axis >= 0; --axis) {
            out[axis] = handle % static_cast<std::uint32_t>(dims_[axis]);
            handle /= static_cast<std::uint32_t>(dims_[axis]);
        }
        return out;
    }
    std::size_t liveCount() const { return slots_.size(); }
    /// Calls visit(handle, record) for every live cell.
    template <class Visit>
    void forEachLive(Visit&& visit) const {
        for (const Slot& slot : slots_) {
            visit(slot.handle, slot.record);
        }
    }
    /// Calls visit(handle) for every live cell in `range`.
    template <class Visit>
    void forEachLiveIn(const Range& range, Visit&& visit) const {
        if (range.cellCount() <= double(slots_.size())) {
            forEachCellIn(range, [&](const Key& key) {
                const std::uint32_t handle = handleOf(key);
                if (slotOf_[handle] != kNoCell) {
                    visit(handle);
                }
            });
            return;
        }
        for (const Slot& slot : slots_) {
            if (range.contains(key(slot.handle))) {
                visit(slot.handle);
            }
        }
    }
    void validate() const {
        for (std::size_t at = 0; at < slots_.size(); ++at) {
            if (slots_[at].handle >= slotOf_.size() || slotOf_[slots_[at].handle] != at ||
                slots_[at].record.count == 0) {
                throw std::logic_error("DenseIndex: slot " + std::to_string(at) +
                                       " is unreachable or empty");
            }
        }
        std::size_t mapped = 0;
        for (std::uint32_t slot : slotOf_) {
            mapped += slot != kNoCell ? 1 : 0;
        }
        if (mapped != slots_.size()) {
            throw std::logic_error("DenseIndex: a cell maps to a slot that does not map back");
        }
    }
    std::size_t memoryBytes() const {
        return slotOf_.capacity() * sizeof(std::uint32_t) + slots_.capacity() * sizeof(Slot);
    }
    std::size_t cellCount() const { return slotOf_.size(); }

  private:
    struct Slot {
        CellRecord record;
        std::uint32_t handle;
    };
    std::uint32_t handleOf(const Key& key) const {
        std::uint64_t handle = 0;
        for (int axis = 0; axis < D; ++axis) {
            handle = handle * static_cast<std::uint64_t>(dims_[axis]) +
                     static_cast<std::uint64_t>(key[axis]);
        }
        return static_cast<std::uint32_t>(handle);
    }

    Key dims_{};
    std::vector<std::uint32_t> slotOf_;
    std::vector<Slot> slots_;
};

/// Lexicographic order of cell keys: x first, as the thesis's key formula orders them.
template <int D>
inline bool keyLess(const CellKey<D>& a, const CellKey<D>& b) {
    for (int axis = 0; axis < D; ++axis) {
        if (a[axis] != b[axis]) {
            return a[axis] < b[axis];
        }
    }
    return false;
}

/// Common part of the sparse indexes: a pool of live cells with stable handles.
template <int D, class Node>
class SparsePool {
  public:
    /// Sparse cells cover all of space: 64-bit coordinates, no region.
    static constexpr bool kBounded = false;
    using Coord = std::int64_t;
    using Key = CellKey<D>;
    using Range = CellRange<D>;

    CellRecord& record(std::uint32_t handle) { return nodes_[handle].record; }
    const CellRecord& record(std::uint32_t handle) const { return nodes_[handle].record; }
    CellKey<D> key(std::uint32_t handle) const { return nodes_[handle].key; }
    std::size_t liveCount() const { return live_; }
    /// Calls visit(handle, record) for every live cell.
    template <class Visit>
    void forEachLive(Visit&& visit) const {
        for (std::uint32_t handle = 0; handle < nodes_.size(); ++handle) {
            if (nodes_[handle].live) {
                visit(handle, nodes_[handle].record);
            }
        }
    }

  protected:
    std::uint32_t allocate(const CellKey<D>& key) {
        std::uint32_t handle;
        if (!free_.empty()) {
            handle = free_.back();
            free_.pop_back();
        } else {
            handle = static_cast<std::uint32_t>(nodes_.size());
            nodes_.emplace_back();
        }
        nodes_[handle] = Node{};
        nodes_[handle].key = key;
        nodes_[handle].live = true;
        ++live_;
        return handle;
    }
    void deallocate(std::uint32_t handle) {
        nodes_[handle].live = false;
        free_.push_back(handle);
        --live_;
    }
    std::size_t poolBytes() const {
        return nodes_.capacity() * sizeof(Node) + free_.capacity() * sizeof(std::uint32_t);
    }
    void checkRecords() const {
        std::size_t live = 0;
        for (const Node& node : nodes_) {
            if (node.live) {
                ++live;
                if (node.record.count == 0) {
                    throw std::logic_error("sparse cell index: an empty cell is still live");
                }
            }
        }
        if (live != live_ || live + free_.size() != nodes_.size()) {
            throw std::logic_error("sparse cell index: pool counts disagree");
        }
    }

    std::vector<Node> nodes_;
    std::vector<std::uint32_t> free_;
    std::size_t live_ = 0;
};

namespace detail {
template <int D>
struct AvlNode {
    CellKey<D> key{};
    CellRecord record;
    std::uint32_t left = kNoCell;
    std::uint32_t right = kNoCell;
    std::int32_t height = 1;
    bool live = false;
};
template <int D>
struct HashNode {
    CellKey<D> key{};
    CellRecord record;
    bool live = false;
};
}  // namespace detail

/// Non-empty cells as nodes of an AVL tree (kolize's own; nodes come from a pool and are
/// relinked, never copied, so handles stay valid while their cell lives).
template <int D>
class AvlIndex : public SparsePool<D, detail::AvlNode<D>> {
    using Base = SparsePool<D, detail::AvlNode<D>>;
    using Base::nodes_;

  public:
    static constexpr const char* kName = "AVL tree";

    void clear() { *this = AvlIndex{}; }
    std::uint32_t find(const CellKey<D>& key) const {
        std::uint32_t at = root_;
        while (at != kNoCell) {
            const auto& node = nodes_[at];
            if (keyLess<D>(key, node.key)) {
                at = node.left;
            } else if (keyLess<D>(node.key, key)) {
                at = node.right;
            } else {
                return at;
            }
        }
        return kNoCell;
    }
    std::uint32_t acquire(const CellKey<D>& key) {
        std::uint32_t found = kNoCell;
        root_ = insert(root_, key, found);
        return found;
    }
    void release(std::uint32_t handle) {
        root_ = erase(root_, nodes_[handle].key);
        this->deallocate(handle);
    }
    /// Live cells in `range`: either one lookup per cell of the range, or an in-order walk
    /// of the keys between range.lo and range.hi (an x-slab), whichever visits fewer.
    template <class Visit>
    void forEachLiveIn(const CellRange<D>& range, Visit&& visit) const {
        if (range.cellCount() <= double(this->liveCount()) / 8) {
            forEachCellIn(range, [&](const CellKey<D>& key) {
                const std::uint32_t handle = find(key);
                if (handle != kNoCell) {
                    visit(handle);
                }
            });
            return;
        }
        walk(root_, range, visit);
    }
    /// Checks order, heights, balance and the pool; throws std::logic_error.
    void validate() const {
        std::size_t reached = 0;
        const CellKey<D>* previous = nullptr;
        check(root_, reached, previous);
        if (reached != this->liveCount()) {
            throw std::logic_error("AvlIndex: " + std::to_string(reached) + " nodes reachable, " +
                                   std::to_string(this->liveCount()) + " live");
        }
        this->checkRecords();
    }
    std::size_t memoryBytes() const { return this->poolBytes(); }
    /// Height of the tree (0 when empty).
    int height() const { return heightOf(root_); }

  private:
    int heightOf(std::uint32_t at) const { return at == kNoCell ? 0 : nodes_[at].height; }
    void refresh(std::uint32_t at) {
        nodes_[at].height = 1 + std::max(heightOf(nodes_[at].left), heightOf(nodes_[at].right));
    }
    std::uint32_t rotateRight(std::uint32_t at) {
        const std::uint32_t pivot = nodes_[at].left;
        nodes_[at].left = nodes_[pivot].right;
        nodes_[pivot].right = at;
        refresh(at);
        refresh(pivot);
        return pivot;
    }
    std::uint32_t rotateLeft(std::uint32_t at) {
        const std::uint32_t pivot = nodes_[at].right;
        nodes_[at].right = nodes_[pivot].left;
        nodes_[pivot].left = at;
        refresh(at);
        refresh(pivot);
        return pivot;
    }
    std::uint32_t rebalance(std::uint32_t at) {
        refresh(at);
        const int balance = heightOf(nodes_[at].left) - heightOf(nodes_[at].right);
        if (balance > 1) {
            const std::uint32_t left = nodes_[at].left;
            if (heightOf(nodes_[left].left) < heightOf(nodes_[left].right)) {
                nodes_[at].left = rotateLeft(left);
            }
            return rotateRight(at);
        }
        if (balance < -1) {
            const std::uint32_t right = nodes_[at].right;
            if (heightOf(nodes_[right].right) < heightOf(nodes_[right].left)) {
                nodes_[at].right = rotateRight(right);
            }
            return rotateLeft(at);
        }
        return at;
    }
    std::uint32_t insert(std::uint32_t at, const CellKey<D>& key, std::uint32_t& found) {
        if (at == kNoCell) {
            found = this->allocate(key);
            return found;
        }
        if (keyLess<D>(key, nodes_[at].key)) {
            const std::uint32_t child = insert(nodes_[at].left, key, found);
            nodes_[at].left = child;
        } else if (keyLess<D>(nodes_[at].key, key)) {
            const std::uint32_t child = insert(nodes_[at].right, key, found);
            nodes_[at].right = child;
        } else {
            found = at;
            return at;
        }
        return rebalance(at);
    }
    /// Unlinks the smallest node of the subtree; returns the new subtree root.
    std::uint32_t unlinkMin(std::uint32_t at, std::uint32_t& minimum) {
        if (nodes_[at].left == kNoCell) {
            minimum = at;
            return nodes_[at].right;
        }
        const std::uint32_t child = unlinkMin(nodes_[at].left, minimum);
        nodes_[at].left = child;
        return rebalance(at);
    }
    std::uint32_t erase(std::uint32_t at, const CellKey<D>& key) {
        if (at == kNoCell) {
            throw std::logic_error("AvlIndex: released a cell that is not in the tree");
        }
        if (keyLess<D>(key, nodes_[at].key)) {
            const std::uint32_t child = erase(nodes_[at].left, key);
            nodes_[at].left = child;
        } else if (keyLess<D>(nodes_[at].key, key)) {
            const std::uint32_t child = erase(nodes_[at].right, key);
            nodes_[at].right = child;
        } else {
            const std::uint32_t left = nodes_[at].left, right = nodes_[at].right;
            if (left == kNoCell || right == kNoCell) {
                return left == kNoCell ? right : left;
            }
            // The successor takes the erased node's place; no payload moves between nodes.
            std::uint32_t successor = kNoCell;
            const std::uint32_t newRight = unlinkMin(right, successor);
            nodes_[successor].left = left;
            nodes_[successor].right = newRight;
            return rebalance(successor);
        }
        return rebalance(at);
    }
    template <class Visit>
    void walk(std::uint32_t at, const CellRange<D>& range, Visit& visit) const {
        if (at == kNoCell) {
            return;
        }
        const auto& node = nodes_[at];
        const bool aboveLo = !keyLess<D>(node.key, range.lo);
        const bool belowHi = !keyLess<D>(range.hi, node.key);
        if (aboveLo) {
            walk(node.left, range, visit);
        }
        if (aboveLo && belowHi && range.contains(node.key)) {
            visit(at);
        }
        if (belowHi) {
            walk(node.right, range, visit);
        }
    }
    int check(std::uint32_t at, std::size_t& reached, const CellKey<D>*& previous) const {
        if (at == kNoCell) {
            return 0;
        }
        const auto& node = nodes_[at];
        if (!node.live || ++reached > nodes_.size()) {
            throw std::logic_error("AvlIndex: a dead node or a cycle in the tree");
        }
        const int left = check(node.left, reached, previous);
        if (previous != nullptr && !keyLess<D>(*previous, node.key)) {
            throw std::logic_error("AvlIndex: keys out of order");
        }
        previous = &node.key;
        const int right = check(node.right, reached, previous);
        if (node.height != 1 + std::max(left, right)) {
            throw std::logic_error("AvlIndex: stored height is wrong");
        }
        if (left - right > 1 || right - left > 1) {
            throw std::logic_error("AvlIndex: node out of balance");
        }
        return node.height;
    }

    std::uint32_t root_ = kNoCell;
};

/// Non-empty cells in an open-addressing hash table (linear probing, backward-shift
/// deletion, load factor at most 1/2).
template <int D>
class HashIndex : public SparsePool<D, detail::HashNode<D>> {
    using Base = SparsePool<D, detail::HashNode<D>>;
    using Base::nodes_;

  public:
    static constexpr const char* kName = "hash table";

    void clear() { *this = HashIndex{}; }
    std::uint32_t find(const CellKey<D>& key) const {
        if (table_.empty()) {
            return kNoCell;
        }
        for (std::size_t at = slotOf(key);; at = (at + 1) & mask_) {
            const std::uint32_t handle = table_[at];
            if (handle == kNoCell) {
                return kNoCell;
            }
            if (nodes_[handle].key == key) {
                return handle;
            }
        }
    }
    std::uint32_t acquire(const CellKey<D>& key) {
        if ((this->liveCount() + 1) * 2 > table_.size()) {
            grow();
        }
        std::size_t at = slotOf(key);
        for (; table_[at] != kNoCell; at = (at + 1) & mask_) {
            if (nodes_[table_[at]].key == key) {
                return table_[at];
            }
        }
        table_[at] = this->allocate(key);
        return table_[at];
    }
    void release(std::uint32_t handle) {
        std::size_t at = slotOf(nodes_[handle].key);
        while (table_[at] != handle) {
            at = (at + 1) & mask_;
        }
        // Backward shift: pull later members of the probe run into the hole.
        std::size_t hole = at;
        for (std::size_t next = (hole + 1) & mask_; table_[next] != kNoCell;
             next = (next + 1) & mask_) {
            const std::size_t home = slotOf(nodes_[table_[next]].key);
            if (((next - home) & mask_) >= ((next - hole) & mask_)) {
                table_[hole] = table_[next];
                hole = next;
            }
        }
        table_[hole] = kNoCell;
        this->deallocate(handle);
    }
    /// Live cells in `range`: one lookup per cell of the range, or a scan of all live cells
    /// when the range has more cells than there are live ones.
    template <class Visit>
    void forEachLiveIn(const CellRange<D>& range, Visit&& visit) const {
        if (range.cellCount() <= double(this->liveCount())) {
            forEachCellIn(range, [&](const CellKey<D>& key) {
                const std::uint32_t handle = find(key);
                if (handle != kNoCell) {
                    visit(handle);
                }
            });
            return;
        }
        this->forEachLive([&](std::uint32_t handle, const CellRecord&) {
            if (range.contains(nodes_[handle].key)) {
                visit(handle);
            }
        });
    }
    /// Checks that every live cell is found under its key and the table has no strays.
    void validate() const {
        std::size_t stored = 0;
        for (std::uint32_t handle : table_) {
            if (handle == kNoCell) {
                continue;
            }
            ++stored;
            if (handle >= nodes_.size() || !nodes_[handle].live ||
                find(nodes_[handle].key) != handle) {
                throw std::logic_error("HashIndex: a table entry is unreachable or dead");
            }
        }
        if (stored != this->liveCount()) {
            throw std::logic_error("HashIndex: table and pool disagree");
        }
        this->checkRecords();
    }
    std::size_t memoryBytes() const {
        return this->poolBytes() + table_.capacity() * sizeof(std::uint32_t);
    }

  private:
    std::size_t slotOf(const CellKey<D>& key) const {
        std::uint64_t hash = 0x9e3779b97f4a7c15ull;
        for (int axis = 0; axis < D; ++axis) {
            hash ^= static_cast<std::uint64_t>(key[axis]) + 0x9e3779b97f4a7c15ull + (hash << 6) +
                    (hash >> 2);
            hash *= 0xff51afd7ed558ccdull;
        }
        hash ^= hash >> 33;
        return static_cast<std::size_t>(hash) & mask_;
    }
    void grow() {
        const std::size_t size = table_.empty() ? 64 : table_.size() * 2;
        table_.assign(size, kNoCell);
        mask_ = size - 1;
        this->forEachLive([&](std::uint32_t handle, const CellRecord&) {
            std::size_t at = slotOf(nodes_[handle].key);
            while (table_[at] != kNoCell) {
                at = (at + 1) & mask_;
            }
            table_[at] = handle;
        });
    }

    std::vector<std::uint32_t> table_;
    std::size_t mask_ = 0;
};

}  // namespace kolize
