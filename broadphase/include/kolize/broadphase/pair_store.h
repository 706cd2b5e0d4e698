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
///
/// Bulk mode, for frames in which most objects moved (a full pair search): the index (hash
/// table and heaps) is dropped and the pairs are kept sorted by their two objects, so that
/// the adapter can merge a frame's sorted candidates with them in one sequential pass and
/// no pair pays for hashing, heap sifts or certificates. In bulk mode every pair's slack is
/// < 0 (untested) and every trigger counts as -inf (nextTrigger says so): any motion of an
/// object calls for a look at its pairs. index() rebuilds the index (O(pairs)) before the
/// operations that need it (find, insert, erase, triggers, an object's pairs).

#include <kolize/broadphase/aabb.h>

#include <algorithm>
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

    /// The pair's index, or kNone. Needs the index.
    std::uint32_t find(ObjectId a, ObjectId b) const {
        requireIndex("find");
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
        requireIndex("findOrInsert");
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
        sorted_ = sorted_ && (pairs_.empty() || keyOf(pairs_.back()) < key);
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
        requireIndex("erase");
        for (int side = 0; side < 2; ++side) {
            removeFromHeap(pairs_[index].object[side], pairs_[index].heapAt[side]);
        }
        eraseSlot(keyOf(pairs_[index].object[0], pairs_[index].object[1]));
        const std::uint32_t last = static_cast<std::uint32_t>(pairs_.size() - 1);
        if (index != last) {
            sorted_ = false;
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
    /// The lowest trigger of `id`'s pairs (+inf when it has none; -inf in bulk mode).
    double nextTrigger(ObjectId id) const {
        if (!indexed_) {
            return -HUGE_VAL;
        }
        return id < heaps_.size() && !heaps_[id].empty() ? heaps_[id][0].trigger : HUGE_VAL;
    }

    /// Calls `visit(index)` for every pair of object `id`. `visit` must not change the store.
    template <class Visit>
    void forEachOf(ObjectId id, Visit&& visit) const {
        requireIndex("forEachOf");
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
    std::size_t degree(ObjectId id) const {
        requireIndex("degree");
        return id < heaps_.size() ? heaps_[id].size() : 0;
    }

    // --- bulk mode ---
    bool indexed() const { return indexed_; }
    /// Enters bulk mode: sorts the pairs by their objects (if an insert or erase disturbed
    /// the order) and frees the hash table and the heaps. Every pair's slack becomes < 0.
    /// No-op in bulk mode.
    void unindex() {
        if (!indexed_) {
            return;
        }
        if (!sorted_) {
            std::sort(pairs_.begin(), pairs_.end(),
                      [](const Pair& x, const Pair& y) { return keyOf(x) < keyOf(y); });
            sorted_ = true;
        }
        for (Pair& pair : pairs_) {
            pair.slack = -1;
        }
        std::vector<Slot>().swap(table_);
        std::vector<std::vector<HeapEntry>>().swap(heaps_);
        mask_ = 0;
        indexed_ = false;
    }
    /// Leaves bulk mode: rebuilds the hash table and the heaps, object `id`'s triggers all
    /// `triggerOf(id)` (its odometer: its pairs need a look once it moves; -inf: at once).
    /// Pair indices do not change. O(pairs log degree).
    template <class TriggerOf>
    void index(TriggerOf&& triggerOf) {
        if (indexed_) {
            return;
        }
        std::size_t size = 64;
        while (pairs_.size() * 4 > size * 3) {
            size *= 2;
        }
        table_.assign(size, Slot{});
        mask_ = size - 1;
        std::vector<std::uint32_t> degree;
        for (const Pair& pair : pairs_) {
            if (pair.object[1] >= degree.size()) {
                degree.resize(std::size_t(pair.object[1]) + 1, 0);
            }
            ++degree[pair.object[0]];
            ++degree[pair.object[1]];
        }
        heaps_.resize(degree.size());
        for (std::size_t id = 0; id < degree.size(); ++id) {
            heaps_[id].reserve(degree[id]);
        }
        for (std::uint32_t index = 0; index < pairs_.size(); ++index) {
            Pair& pair = pairs_[index];
            const std::uint64_t key = keyOf(pair);
            std::size_t at = homeOf(key);
            while (table_[at].index != kNone) {
                at = (at + 1) & mask_;
            }
            table_[at] = Slot{key, index};
            for (int side = 0; side < 2; ++side) {
                std::vector<HeapEntry>& heap = heaps_[pair.object[side]];
                heap.push_back(
                    HeapEntry{double(triggerOf(pair.object[side])), index, std::uint32_t(side)});
                siftUp(heap, heap.size() - 1);
            }
        }
        indexed_ = true;
    }
    /// Bulk mode: replaces the pairs by `next` (sorted by their objects, no repeats, every
    /// slack < 0; the old pairs are left in `next`). Throws std::logic_error when indexed.
    void replaceAll(std::vector<Pair>& next) {
        if (indexed_) {
            throw std::logic_error("PairStore: replaceAll needs bulk mode");
        }
        pairs_.swap(next);
    }
    /// Bulk mode: erases every pair for which `doomed(pair)` holds, keeping the order.
    template <class Doomed>
    void eraseIf(Doomed&& doomed) {
        if (indexed_) {
            throw std::logic_error("PairStore: eraseIf needs bulk mode");
        }
        pairs_.erase(std::remove_if(pairs_.begin(), pairs_.end(), doomed), pairs_.end());
    }
    /// The pair's key: its two objects, the lower in the high half (the sort order).
    static std::uint64_t keyOf(const Pair& pair) { return keyOf(pair.object[0], pair.object[1]); }
    static std::uint64_t keyOf(ObjectId a, ObjectId b) {
        return a < b ? (std::uint64_t(a) << 32) | b : (std::uint64_t(b) << 32) | a;
    }
    /// Sorts keys ascending (LSD radix sort by bytes, skipping the bytes that are the same in
    /// every key) and removes repeats. `scratch` is working memory. O(n) per varying byte.
    static void sortKeys(std::vector<std::uint64_t>& keys, std::vector<std::uint64_t>& scratch) {
        // A byte that is the same in every key (set in all, or in none) needs no pass.
        std::uint64_t all = ~std::uint64_t(0), any = 0;
        for (std::uint64_t key : keys) {
            all &= key;
            any |= key;
        }
        const std::uint64_t varying = keys.empty() ? 0 : any & ~all;
        scratch.resize(keys.size());
        for (int shift = 0; shift < 64; shift += 8) {
            if (((varying >> shift) & 0xff) == 0) {
                continue;
            }
            std::size_t count[257] = {};
            for (std::uint64_t key : keys) {
                ++count[((key >> shift) & 0xff) + 1];
            }
            for (int digit = 0; digit < 256; ++digit) {
                count[digit + 1] += count[digit];
            }
            for (std::uint64_t key : keys) {
                scratch[count[(key >> shift) & 0xff]++] = key;
            }
            keys.swap(scratch);
        }
        keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    }

    Pair& operator[](std::uint32_t index) { return pairs_[index]; }
    const Pair& operator[](std::uint32_t index) const { return pairs_[index]; }
    std::size_t size() const { return pairs_.size(); }
    bool empty() const { return pairs_.empty(); }

    /// Drops every pair and frees the memory.
    void clear() {
        indexed_ = true;
        sorted_ = true;
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

    /// Checks the hash index, the heaps and their back links (bulk mode: the order and every
    /// slack < 0); throws std::logic_error.
    void validate() const {
        auto fail = [](const std::string& what) { throw std::logic_error("PairStore: " + what); };
        for (std::size_t at = 0; at < pairs_.size(); ++at) {
            if (!(pairs_[at].object[0] < pairs_[at].object[1])) {
                fail("pair not ordered");
            }
            if ((!indexed_ || sorted_) && at > 0 && !(keyOf(pairs_[at - 1]) < keyOf(pairs_[at]))) {
                fail("pairs out of order or repeated");
            }
            if (!indexed_ && !(pairs_[at].slack < 0)) {
                fail("bulk mode holds a tested pair");
            }
        }
        if (!indexed_) {
            if (!table_.empty() || !heaps_.empty()) {
                fail("bulk mode keeps an index");
            }
            return;
        }
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

    void requireIndex(const char* operation) const {
        if (!indexed_) {
            throw std::logic_error(std::string("PairStore: ") + operation +
                                   " needs the index (bulk mode)");
        }
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
    bool indexed_ = true;  ///< false: bulk mode
    bool sorted_ = true;   ///< pairs_ ascending by key
};

}  // namespace kolize
