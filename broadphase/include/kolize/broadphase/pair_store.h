#pragma once
/// \file
/// PairStore: the candidate pairs a kolize broadphase keeps from frame to frame. Each pair
/// carries a certificate (the adapter's: how far its two objects may travel before its
/// status could change) and, per object, a trigger: the odometer reading of that object at
/// which the pair needs a look. Every object keeps its pairs in a binary min-heap by that
/// trigger, so a frame looks only at the pairs whose triggers an object's travel passed.
///
/// Pairs live in one dense array (erasing moves the last pair into the hole, so sweeps over
/// all pairs read contiguous memory). A hash index (open addressing, linear probing,
/// backward-shift deletion: no tombstones) finds a pair by its two objects. Expected O(1)
/// for find, O(log degree) for insert, erase and trigger changes.

#include <kolize/broadphase/aabb.h>

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace kolize {

class PairStore {
  public:
    static constexpr std::uint32_t kNone = 0xffffffffu;

    /// What the pair cache knows of a pair, decided by its exact boxes and the filters.
    enum class Status : std::uint8_t {
        Apart,     ///< the exact boxes do not overlap (or were not tested yet): not cached
        InCache,   ///< overlapping, and in Bullet's pair cache
        Rejected,  ///< overlapping, but the filters rejected it when it started overlapping
    };

    struct Pair {
        ObjectId object[2];       ///< object[0] < object[1]
        std::uint32_t heapAt[2];  ///< position in object[side]'s heap
        double slack;             ///< certificate: < 0 not tested yet
        double travelled[2];      ///< certificate: the objects' odometers at the last test
        std::uint32_t stamp;      ///< frame mark of the adapter: a candidate in that frame
        std::uint32_t tested;     ///< frame mark of the adapter: looked at in that frame
        Status status;

        /// 0 when `id` is object[0], else 1.
        int sideOf(ObjectId id) const { return object[0] == id ? 0 : 1; }
        ObjectId other(ObjectId id) const { return object[0] == id ? object[1] : object[0]; }
    };

    /// The pair's index, or kNone.
    std::uint32_t find(ObjectId a, ObjectId b) const {
        if (pairs_.empty()) {
            return kNone;
        }
        const std::uint64_t key = keyOf(a, b);
        for (std::size_t at = homeOf(key);; at = (at + 1) & mask_) {
            const Slot& slot = table_[at];
            if (slot.index == kNone) {
                return kNone;
            }
            if (slot.key == key) {
                return slot.index;
            }
        }
    }

    /// Finds the pair or adds it (status Apart, untested, stamps 0, both triggers
    /// `trigger`: by default -inf, it needs a look); `inserted` tells which. Returns its
    /// index.
    std::uint32_t findOrInsert(ObjectId a, ObjectId b, bool& inserted, double trigger = -HUGE_VAL) {
        if ((pairs_.size() + 1) * 4 > table_.size() * 3) {
            grow();
        }
        const std::uint64_t key = keyOf(a, b);
        std::size_t at = homeOf(key);
        while (table_[at].index != kNone) {
            if (table_[at].key == key) {
                inserted = false;
                return table_[at].index;
            }
            at = (at + 1) & mask_;
        }
        const std::uint32_t index = static_cast<std::uint32_t>(pairs_.size());
        table_[at] = Slot{key, index};
        Pair pair{};
        pair.object[0] = a < b ? a : b;
        pair.object[1] = a < b ? b : a;
        pair.slack = -1;
        pair.status = Status::Apart;
        pairs_.push_back(pair);
        for (int side = 0; side < 2; ++side) {
            const ObjectId id = pair.object[side];
            if (id >= heaps_.size()) {
                heaps_.resize(std::size_t(id) + 1);
            }
            std::vector<HeapEntry>& heap = heaps_[id];
            heap.push_back(HeapEntry{trigger, index, std::uint32_t(side)});
            siftUp(heap, heap.size() - 1);
        }
        inserted = true;
        return index;
    }

    /// Removes pair `index`; the last pair moves into its place (its index becomes `index`).
    /// Erasing several: in descending index order, and no index below changes.
    void erase(std::uint32_t index) {
        for (int side = 0; side < 2; ++side) {
            removeFromHeap(pairs_[index].object[side], pairs_[index].heapAt[side]);
        }
        eraseSlot(keyOf(pairs_[index].object[0], pairs_[index].object[1]));
        const std::uint32_t last = static_cast<std::uint32_t>(pairs_.size() - 1);
        if (index != last) {
            pairs_[index] = pairs_[last];
            const Pair& moved = pairs_[index];
            for (int side = 0; side < 2; ++side) {
                heaps_[moved.object[side]][moved.heapAt[side]].pair = index;
            }
            slotOf(keyOf(moved.object[0], moved.object[1])).index = index;
        }
        pairs_.pop_back();
    }

    /// Object[side]'s trigger of pair `index`: its odometer reading that calls for a look.
    double trigger(std::uint32_t index, int side) const {
        const Pair& pair = pairs_[index];
        return heaps_[pair.object[side]][pair.heapAt[side]].trigger;
    }
    /// Sets object[side]'s trigger of pair `index` and restores its heap.
    void setTrigger(std::uint32_t index, int side, double trigger) {
        const Pair& pair = pairs_[index];
        std::vector<HeapEntry>& heap = heaps_[pair.object[side]];
        const std::size_t at = pair.heapAt[side];
        const double old = heap[at].trigger;
        heap[at].trigger = trigger;
        if (trigger < old) {
            siftUp(heap, at);
        } else if (trigger > old) {
            siftDown(heap, at);
        }
    }

    /// The pair of `id` with the lowest trigger, or kNone.
    std::uint32_t firstDue(ObjectId id) const {
        return id < heaps_.size() && !heaps_[id].empty() ? heaps_[id][0].pair : kNone;
    }
    /// The lowest trigger of `id`'s pairs (+inf when it has none).
    double nextTrigger(ObjectId id) const {
        return id < heaps_.size() && !heaps_[id].empty() ? heaps_[id][0].trigger : HUGE_VAL;
    }

    /// Calls `visit(index)` for every pair of object `id`. `visit` must not change the store.
    template <class Visit>
    void forEachOf(ObjectId id, Visit&& visit) const {
        if (id < heaps_.size()) {
            for (const HeapEntry& entry : heaps_[id]) {
                visit(entry.pair);
            }
        }
    }
    /// Appends the pairs of `id` to `out`.
    void appendPairsOf(ObjectId id, std::vector<std::uint32_t>& out) const {
        forEachOf(id, [&](std::uint32_t index) { out.push_back(index); });
    }
    std::size_t degree(ObjectId id) const { return id < heaps_.size() ? heaps_[id].size() : 0; }

    Pair& operator[](std::uint32_t index) { return pairs_[index]; }
    const Pair& operator[](std::uint32_t index) const { return pairs_[index]; }
    std::size_t size() const { return pairs_.size(); }
    bool empty() const { return pairs_.empty(); }

    /// Drops every pair and frees the memory.
    void clear() {
        std::vector<Pair>().swap(pairs_);
        std::vector<Slot>().swap(table_);
        std::vector<std::vector<HeapEntry>>().swap(heaps_);
        mask_ = 0;
    }

    std::size_t memoryBytes() const {
        std::size_t bytes = pairs_.capacity() * sizeof(Pair) + table_.capacity() * sizeof(Slot) +
                            heaps_.capacity() * sizeof(std::vector<HeapEntry>);
        for (const std::vector<HeapEntry>& heap : heaps_) {
            bytes += heap.capacity() * sizeof(HeapEntry);
        }
        return bytes;
    }

    /// Checks the hash index, the heaps and their back links; throws std::logic_error.
    void validate() const {
        auto fail = [](const std::string& what) { throw std::logic_error("PairStore: " + what); };
        std::size_t indexed = 0;
        for (std::size_t at = 0; at < table_.size(); ++at) {
            const Slot& slot = table_[at];
            if (slot.index == kNone) {
                continue;
            }
            ++indexed;
            if (slot.index >= pairs_.size() ||
                keyOf(pairs_[slot.index].object[0], pairs_[slot.index].object[1]) != slot.key) {
                fail("index slot names the wrong pair");
            }
            for (std::size_t probe = homeOf(slot.key); probe != at; probe = (probe + 1) & mask_) {
                if (table_[probe].index == kNone) {
                    fail("pair unreachable from its home slot");
                }
            }
        }
        if (indexed != pairs_.size()) {
            fail("index and array disagree");
        }
        std::size_t listed = 0;
        for (ObjectId id = 0; id < heaps_.size(); ++id) {
            const std::vector<HeapEntry>& heap = heaps_[id];
            for (std::size_t at = 0; at < heap.size(); ++at) {
                if (heap[at].pair >= pairs_.size() || heap[at].side > 1) {
                    fail("heap of object " + std::to_string(id) + " leaves the array");
                }
                const Pair& pair = pairs_[heap[at].pair];
                if (pair.object[heap[at].side] != id) {
                    fail("heap of object " + std::to_string(id) + " holds a foreign pair");
                }
                if (pair.heapAt[heap[at].side] != at) {
                    fail("broken back link in the heap of object " + std::to_string(id));
                }
                if (at > 0 && heap[(at - 1) / 2].trigger > heap[at].trigger) {
                    fail("heap of object " + std::to_string(id) + " out of order");
                }
                ++listed;
            }
        }
        for (const Pair& pair : pairs_) {
            if (!(pair.object[0] < pair.object[1])) {
                fail("pair not ordered");
            }
        }
        if (listed != 2 * pairs_.size()) {
            fail("heaps hold " + std::to_string(listed) + " entries for " +
                 std::to_string(pairs_.size()) + " pairs");
        }
    }

  private:
    struct Slot {
        std::uint64_t key = 0;
        std::uint32_t index = kNone;
    };

    static std::uint64_t keyOf(ObjectId a, ObjectId b) {
        return a < b ? (std::uint64_t(a) << 32) | b : (std::uint64_t(b) << 32) | a;
    }

    std::size_t homeOf(std::uint64_t key) const {
        // splitmix64's finaliser spreads neighbouring ids over the table.
        key ^= key >> 30;
        key *= 0xbf58476d1ce4e5b9ull;
        key ^= key >> 27;
        key *= 0x94d049bb133111ebull;
        key ^= key >> 31;
        return static_cast<std::size_t>(key) & mask_;
    }

    Slot& slotOf(std::uint64_t key) {
        std::size_t at = homeOf(key);
        while (table_[at].index == kNone || table_[at].key != key) {
            at = (at + 1) & mask_;
        }
        return table_[at];
    }

    /// One entry of an object's heap: the trigger inline, so that sifting reads only the
    /// heap's own memory.
    struct HeapEntry {
        double trigger;
        std::uint32_t pair;
        std::uint32_t side;  ///< the object is pairs_[pair].object[side]
    };

    void place(std::vector<HeapEntry>& heap, std::size_t at, const HeapEntry& entry) {
        heap[at] = entry;
        pairs_[entry.pair].heapAt[entry.side] = static_cast<std::uint32_t>(at);
    }
    void siftUp(std::vector<HeapEntry>& heap, std::size_t at) {
        const HeapEntry entry = heap[at];
        while (at > 0) {
            const std::size_t parent = (at - 1) / 2;
            if (!(heap[parent].trigger > entry.trigger)) {
                break;
            }
            place(heap, at, heap[parent]);
            at = parent;
        }
        place(heap, at, entry);
    }
    void siftDown(std::vector<HeapEntry>& heap, std::size_t at) {
        const HeapEntry entry = heap[at];
        const std::size_t size = heap.size();
        for (;;) {
            std::size_t child = 2 * at + 1;
            if (child >= size) {
                break;
            }
            if (child + 1 < size && heap[child + 1].trigger < heap[child].trigger) {
                ++child;
            }
            if (!(heap[child].trigger < entry.trigger)) {
                break;
            }
            place(heap, at, heap[child]);
            at = child;
        }
        place(heap, at, entry);
    }
    void removeFromHeap(ObjectId id, std::size_t at) {
        std::vector<HeapEntry>& heap = heaps_[id];
        const HeapEntry last = heap.back();
        heap.pop_back();
        if (at == heap.size()) {
            return;
        }
        place(heap, at, last);
        siftUp(heap, at);
        siftDown(heap, pairs_[last.pair].heapAt[last.side]);
    }

    void eraseSlot(std::uint64_t key) {
        std::size_t hole = homeOf(key);
        while (table_[hole].index == kNone || table_[hole].key != key) {
            hole = (hole + 1) & mask_;
        }
        std::size_t next = (hole + 1) & mask_;
        while (table_[next].index != kNone) {
            const std::size_t home = homeOf(table_[next].key);
            // Move `next` into the hole unless its home lies cyclically in (hole, next].
            const bool homeBetween =
                hole <= next ? (home > hole && home <= next) : (home > hole || home <= next);
            if (!homeBetween) {
                table_[hole] = table_[next];
                hole = next;
            }
            next = (next + 1) & mask_;
        }
        table_[hole] = Slot{};
    }

    void grow() {
        std::vector<Slot> old;
        old.swap(table_);
        table_.assign(old.empty() ? 64 : old.size() * 2, Slot{});
        mask_ = table_.size() - 1;
        for (const Slot& slot : old) {
            if (slot.index == kNone) {
                continue;
            }
            std::size_t at = homeOf(slot.key);
            while (table_[at].index != kNone) {
                at = (at + 1) & mask_;
            }
            table_[at] = slot;
        }
    }

    std::vector<Pair> pairs_;
    std::vector<Slot> table_;
    std::vector<std::vector<HeapEntry>> heaps_;
    std::size_t mask_ = 0;
};

}  // namespace kolize
